"""Numbers behind the figures: ellipsoid outlines, data poses, stick figures, animation."""

from __future__ import annotations

import math
import re

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402

from gaitlib import contact, data, kinematics, plots  # noqa: E402
from gaitlib import conventions as cv  # noqa: E402
from gaitlib.jump import JumpModel  # noqa: E402
from gaitlib.model import ELLIPSOID_LABELS, ChildModel  # noqa: E402


@pytest.fixture(scope="module")
def model():
    return ChildModel()


@pytest.fixture(scope="module")
def free():
    return data.load_gait_data("Free")


def _random_rotation(seed):
    return Rotation.random(random_state=seed).as_matrix()


def test_sphere_outline_is_circle_of_its_radius():
    c = np.array([0.3, -0.1, 0.05])
    for seed in range(3):
        pts = plots.ellipse_outline(c, _random_rotation(seed), (0.04, 0.04, 0.04), n=50)
        np.testing.assert_allclose(np.hypot(*(pts - c[:2]).T), 0.04, rtol=1e-12)


def test_outline_extremes_are_support_function():
    """Lowest/highest/left/right of the outline = c ± sqrt(eᵀ R D² Rᵀ e) (and the sampled
    outline lies inside, touching within the sampling error)."""
    c = np.array([0.1, 0.02, -0.03])
    radii = (0.08, 0.0206, 0.0179)
    for seed in range(4):
        R = _random_rotation(seed)
        M = R @ np.diag(np.square(radii)) @ R.T
        pts = plots.ellipse_outline(c, R, radii, n=4001)
        bottom = c[1] - math.sqrt(M[1, 1])
        assert kinematics.ellipsoid_bottom(c, R, radii) == pytest.approx(bottom, abs=1e-15)
        assert pts[:, 1].min() == pytest.approx(bottom, abs=1e-7)
        assert pts[:, 1].max() == pytest.approx(c[1] + math.sqrt(M[1, 1]), abs=1e-7)
        assert pts[:, 0].max() == pytest.approx(c[0] + math.sqrt(M[0, 0]), abs=1e-7)
        # every outline point satisfies the projected ellipse equation with equality
        A = M[:2, :2]
        d = pts - c[:2]
        np.testing.assert_allclose(np.einsum("ij,jk,ik->i", d, np.linalg.inv(A), d), 1.0,
                                   rtol=1e-10)


def test_bottom_matches_brute_force_over_the_surface():
    radii = np.array([0.0309, 0.040, 0.0135])
    p_heel = contact.default_params()[contact.ellipsoid_slice("heel")]
    R = contact.ellipsoid_to_segment(*p_heel[10:])
    c = np.array([0.0, 0.05, 0.0])
    u = np.random.default_rng(1).normal(size=(200_000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    y = c[1] + (u * radii) @ R.T[:, 1]
    b = kinematics.ellipsoid_bottom(c, R, radii)
    assert b <= y.min() + 1e-12
    assert y.min() - b < 2e-5


def test_model_outline_bottom_matches_contact_depth(model):
    """The drawn outline's lowest point is the contact law's depth: δ = −bottom."""
    q = np.zeros(11)
    q[1] = model.standing_leg_length + 0.004
    fr = plots.model_frame(model, q)
    c = model.contact(q, np.zeros(11))
    for lab, bottom in zip(ELLIPSOID_LABELS, fr["bottoms"]):
        assert fr["ellipses"][lab][:, 1].min() == pytest.approx(bottom, abs=5e-5)
    # the contact law's penetrated volume is zero exactly when the bottom is above ground
    pc = contact.default_params()
    centres, Rs = model.ellipsoid_poses(q)
    for k, (cen, R) in enumerate(zip(centres, Rs)):
        e = cv.ELLIPSOIDS[k % 3]
        p = pc[contact.ellipsoid_slice(e)]
        out = contact.ellipsoid_plane(R, cen, [0, 0, 0], 0.0, *p[:7])
        assert out["depth"] == pytest.approx(-fr["bottoms"][k], abs=1e-12)
    assert np.all((c["fn_raw"] > 1e-2) == (fr["bottoms"] < 0))


@pytest.mark.parametrize("penetration", [0.0, 0.002, 0.01])
def test_pose_from_data_puts_lowest_ellipsoid_at_penetration(model, free, penetration):
    t = np.linspace(0.0, free.cycle_time, 13)
    Q = kinematics.pose_from_data(model, free, t, penetration=penetration)
    assert Q.shape == (13, 11)
    lows = np.array([kinematics.ellipsoid_bottoms(model, q).min() for q in Q])
    np.testing.assert_allclose(lows, -penetration, atol=1e-12)
    np.testing.assert_allclose(Q[:, 0], free.speed * t)
    np.testing.assert_array_equal(Q[:, 2], 0.0)
    ang = free.at(t)
    for j in ("knee_r", "ankle_l", "mtp_r"):
        np.testing.assert_allclose(Q[:, cv.COORDS.index(j)], ang[j].to_numpy())
    np.testing.assert_allclose(Q[:, cv.COORDS.index("hip_l")],
                               ang["hip_l"].to_numpy() + ang["pelvis_tilt"].to_numpy())
    Qp = kinematics.pose_from_data(model, free, t, penetration=penetration, thigh="pelvis")
    np.testing.assert_allclose(Qp[:, cv.COORDS.index("hip_r")], ang["hip_r"].to_numpy())


@pytest.mark.parametrize("p_contact", [None, "scaled"])
def test_ellipsoid_bottoms_of_all_rows_at_once_are_the_row_by_row_numbers(model, free, p_contact):
    # the mapped call evaluates the same function per row: equal to the last bit, so the
    # tracking references built on it (pose_from_data) keep every solution's numbers
    rng = np.random.default_rng(4)
    p = None if p_contact is None else contact.default_params() * rng.uniform(0.9, 1.1, contact.default_params().size)
    Q = kinematics.pose_from_data(model, free, np.linspace(0.0, free.cycle_time, 17), p) + rng.normal(0, 0.05, (17, 11))
    rows = kinematics.ellipsoid_bottoms_rows(model, Q, p)
    assert rows.shape == (17, 6)
    assert kinematics.ellipsoid_bottoms_rows(model, np.empty((0, 11)), p).shape == (0, 6)
    np.testing.assert_array_equal(rows, np.array([kinematics.ellipsoid_bottoms(model, q, p) for q in Q]))
    # pose_from_data against its former row-by-row construction
    t = np.linspace(0.0, free.cycle_time, 9)
    Q = kinematics.pose_from_data(model, free, t, p, penetration=0.002)
    for q in Q:
        q0 = q.copy()
        q0[1] = 0.0
        assert q[1] == -kinematics.ellipsoid_bottoms(model, q0, p).min() - 0.002


def test_settle_height_balances_body_weight(model, free):
    q = kinematics.pose_from_data(model, free, [0.25 * free.cycle_time])[0]
    q[1] = kinematics.settle_height(model, q)
    c = model.contact(q, np.zeros(11))
    assert c["grf_y"].sum() == pytest.approx(model.total_mass() * model.g, rel=1e-9)


def test_draw_model_artists_and_grf(model):
    q = np.zeros(11)
    q[1] = kinematics.settle_height(model, q)
    fig, ax = plt.subplots()
    art = plots.draw_model(ax, model, q)
    assert set(art["ellipsoids"]) == set(ELLIPSOID_LABELS)
    assert set(art["chains"]) == {"hat", "leg_r", "toe_r", "leg_l", "toe_l"}
    scale = plots.default_grf_scale(model)
    for s in cv.SIDES:
        arrow = art["grf"][s]
        assert arrow.get_visible()
        (x0, y0), (x1, y1) = arrow._posA_posB
        assert y0 == 0.0 and y1 == pytest.approx(scale * model.total_mass() * model.g / 2, rel=1e-6)
        assert x0 == pytest.approx(art["frame"]["contact"]["cop_x"][0])
    # lift the model: no contact, arrows hidden
    q[1] += 0.1
    plots.update_model(art, model, q)
    assert not any(a.get_visible() for a in art["grf"].values())
    leg = art["chains"]["leg_r"].get_xydata()
    np.testing.assert_allclose(leg[0], [0.0, q[1]])  # starts at the hip
    plt.close(fig)


def test_draw_jump_uses_points():
    jm = JumpModel()
    fig, ax = plt.subplots()
    art = plots.draw_jump(ax, jm, [0.0, 0.5, -1.1, 0.9])
    P = jm.points(np.r_[0.0, 0.0, 0.0, 0.0, 0.5, -1.1, 0.9])
    body = art["chains"]["body"].get_xydata()
    np.testing.assert_allclose(body[0], P["toe_tip"])
    np.testing.assert_allclose(body[-1], P["head"])
    assert set(art["ellipsoids"]) == set(cv.ELLIPSOIDS)
    art2 = plots.draw_jump(ax, JumpModel(toe=False), np.zeros(6))
    assert art2["ellipsoids"] == {}
    plt.close(fig)


@pytest.mark.parametrize("n, max_frames, expected", [(12, 50, 12), (90, 30, 30)])
def test_animate_gait_frame_count(model, free, n, max_frames, expected):
    t = np.linspace(0.0, free.cycle_time, n, endpoint=False)
    Q = kinematics.pose_from_data(model, free, t)
    anim = plots.animate_gait(model, t, Q, max_frames=max_frames, figsize=(3, 2), dpi=40)
    assert len(anim.frame_indices) == expected
    html = plots.animation_html(anim)
    assert len(re.findall(r"frames\[\d+\] = ", html)) == expected  # one image per frame
    assert len(html) < 3e6
    # offline: no stylesheet from a CDN (matplotlib links Font Awesome 4); the buttons stay
    assert not re.search(r"""(?:href|src)=["'](?:https?:)?//""", html)
    assert 'class="fa fa-play"' in html
