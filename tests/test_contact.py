"""Physics tests of the ellipsoid–plane volumetric contact (gaitlib.contact)."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from gaitlib import contact as C
from gaitlib.conventions import DEG, ELLIPSOIDS

# Essentially unsmoothed law, for comparisons with exact geometry.
SHARP = C.Smoothing(eps_t=1e-12, eps_force=1e-12)


def _rz(theta):
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _half_height(R, a, b, c):
    n = R.T @ np.array([0.0, 1.0, 0.0])
    return float(np.linalg.norm(np.array([a, b, c]) * n))


def _cap_quadrature(R, centre, a, b, c, n_grid=600):
    """Volume, centroid (x, y) and ∫(x − p_x)² dV of the part of the ellipsoid below y = 0.

    Independent of the closed forms: midpoint rule over the ellipsoid's shadow on the
    X–Z plane, integrating the exact length of each vertical chord below the ground.
    """
    D2 = np.diag([a * a, b * b, c * c])
    M = R @ D2 @ R.T  # ellipsoid: (x − c)ᵀ M⁻¹ (x − c) ≤ 1
    Q = np.linalg.inv(M)
    ex, ez = math.sqrt(M[0, 0]), math.sqrt(M[2, 2])  # shadow half-extents
    xs = ((np.arange(n_grid) + 0.5) / n_grid * 2.0 - 1.0) * ex
    zs = ((np.arange(n_grid) + 0.5) / n_grid * 2.0 - 1.0) * ez
    dx, dz = np.meshgrid(xs, zs, indexing="ij")
    qa = Q[1, 1]
    qb = Q[0, 1] * dx + Q[1, 2] * dz
    qc = Q[0, 0] * dx**2 + 2.0 * Q[0, 2] * dx * dz + Q[2, 2] * dz**2 - 1.0
    disc = np.maximum(qb * qb - qa * qc, 0.0)
    y1 = (-qb - np.sqrt(disc)) / qa + centre[1]
    y2 = np.minimum((-qb + np.sqrt(disc)) / qa + centre[1], 0.0)
    length = np.where(disc > 0.0, np.maximum(y2 - y1, 0.0), 0.0)
    dA = (2.0 * ex / n_grid) * (2.0 * ez / n_grid)
    V = length.sum() * dA
    x = dx + centre[0]
    px = (x * length).sum() * dA / V
    py = (0.5 * (y1 + y2) * length).sum() * dA / V
    Jx = ((x - px) ** 2 * length).sum() * dA
    return V, px, py, Jx


def _call(R, centre, vel=(0.0, 0.0, 0.0), omega=0.0, k_v=1e7, a_v=1.0, mu_s=0.5, mu_d=0.4,
          a=0.03, b=0.02, c=0.015, smoothing=C.Smoothing()):  # fmt: skip
    return C.ellipsoid_plane(R, centre, vel, omega, k_v, a_v, mu_s, mu_d, a, b, c, smoothing)


# --------------------------------------------------------------------------------------
# parameters
# --------------------------------------------------------------------------------------


def test_param_names_order_and_roundtrip():
    names = C.param_names()
    assert len(names) == 39 == len(ELLIPSOIDS) * C.N_PER_ELLIPSOID
    assert names[0] == "toe.k_v" and names[13] == "ball.k_v" and names[-1] == "heel.alpha"
    assert C.PARAM_NAMES == (
        "k_v", "a_v", "mu_s", "mu_d", "a", "b", "c", "r_x", "r_y", "r_z",
        "gamma", "beta", "alpha",
    )  # fmt: skip
    p = C.default_params()
    for i, name in enumerate(names):
        e, q = name.split(".")
        assert C.param_index(e, q) == i
        assert p[C.ellipsoid_slice(e)][C.PARAM_NAMES.index(q)] == p[i]
    # table round trip (mm / deg in the table, SI in the vector)
    tab = C.params_table(p)
    assert list(tab.index) == list(ELLIPSOIDS)
    back = (tab.to_numpy() * np.array([1, 1, 1, 1] + [1e-3] * 6 + [DEG] * 3)).reshape(-1)
    np.testing.assert_allclose(back, p, rtol=1e-14)


def test_default_values_units():
    p = C.default_params()
    assert p.shape == (39,)
    assert p[C.param_index("ball", "a")] == pytest.approx(0.0800)  # Table 4.17, m
    assert p[C.param_index("toe", "k_v")] == pytest.approx(0.75e7)  # Table 4.18, N/m^3
    assert p[C.param_index("heel", "a_v")] == pytest.approx(2.4271)  # s/m
    assert p[C.param_index("toe", "r_x")] == pytest.approx(0.1632)  # m
    assert p[C.param_index("ball", "gamma")] == pytest.approx(-58.49 * math.pi / 180)  # rad
    assert p[C.param_index("heel", "r_z")] == pytest.approx(0.0003)


def test_default_params_within_bounds():
    p = C.default_params()
    lo, up = C.bounds()
    assert lo.shape == up.shape == (39,) and np.all(lo < up)
    assert lo[C.param_index("ball", "a")] == pytest.approx(0.030)  # Table 4.7, 30 mm
    assert up[C.param_index("toe", "alpha")] == pytest.approx(154.3 * DEG)
    outside = {n for n, x, lo_, up_ in zip(C.param_names(), p, lo, up) if not lo_ <= x <= up_}
    # The thesis's Sec 4.4 values (Table 4.17) violate exactly these Table 4.7 bounds.
    assert outside == set(C.TABLE_4_17_OUTSIDE_TABLE_4_7)
    lo2, up2 = C.bounds(include_defaults=True)
    assert np.all((lo2 <= p) & (p <= up2))
    assert np.all(lo2 <= lo) and np.all(up2 >= up)


# --------------------------------------------------------------------------------------
# geometry
# --------------------------------------------------------------------------------------


def test_volume_and_centroid_match_quadrature():
    """Closed-form V and centroid vs direct quadrature, 24 random poses and depths."""
    rng = np.random.default_rng(20240501)
    err_v, err_p = [], []
    for _ in range(24):
        R = Rotation.random(random_state=rng).as_matrix()
        a, b, c = rng.uniform(0.01, 0.08, 3)
        h = _half_height(R, a, b, c)
        t = rng.uniform(0.05, 1.8)
        centre = np.array([rng.uniform(-0.1, 0.1), h * (1.0 - t), rng.uniform(-0.1, 0.1)])
        out = _call(R, centre, a=a, b=b, c=c, smoothing=SHARP)
        V, px, py, _ = _cap_quadrature(R, centre, a, b, c)
        assert out["depth"] == pytest.approx(t * h, rel=1e-12)
        err_v.append(abs(out["volume"] / V - 1.0))
        err_p.append(math.hypot(out["px"] - px, out["py"] - py) / (t * h))
    # midpoint quadrature on a 600² grid: observed max ≈ 1e-5 (volume), ≈ 3e-5 (centroid)
    assert max(err_v) < 2e-4, max(err_v)
    assert max(err_p) < 2e-4, max(err_p)


@pytest.mark.parametrize("case", ["sphere", "vertical_axis"])
def test_rolling_inertia_matches_quadrature(case):
    """J = ∫ (x − p_x)² dV exactly when n is a principal axis (sphere; R about Y)."""
    rng = np.random.default_rng(7)
    for _ in range(4):
        if case == "sphere":
            R = Rotation.random(random_state=rng).as_matrix()
            a = b = c = rng.uniform(0.01, 0.05)
        else:
            phi = rng.uniform(-np.pi, np.pi)
            R = Rotation.from_euler("y", phi).as_matrix()
            a, b, c = rng.uniform(0.01, 0.08, 3)
        h = _half_height(R, a, b, c)
        t = rng.uniform(0.1, 1.5)
        centre = np.array([0.02, h * (1.0 - t), 0.0])
        out = _call(R, centre, a=a, b=b, c=c, smoothing=SHARP)
        *_, Jx = _cap_quadrature(R, centre, a, b, c)
        assert out["J"] == pytest.approx(Jx, rel=5e-4)


def test_centroid_below_centre_and_on_conjugate_diameter():
    R = Rotation.from_euler("zx", [30.0, 50.0], degrees=True).as_matrix()
    a, b, c = 0.06, 0.02, 0.015
    h = _half_height(R, a, b, c)
    out = _call(R, [0.0, 0.5 * h, 0.0], a=a, b=b, c=c, smoothing=SHARP)
    n = R.T @ [0.0, 1.0, 0.0]
    conj = R @ (np.array([a, b, c]) ** 2 * n)  # conjugate diameter direction in ground
    d = np.array([out["px"], out["py"] - 0.5 * h])
    assert out["py"] < 0.5 * h
    assert abs(d[0] * conj[1] - d[1] * conj[0]) < 1e-12  # parallel to D² n


# --------------------------------------------------------------------------------------
# normal force
# --------------------------------------------------------------------------------------


def test_normal_force_static_and_monotone():
    R = _rz(0.3) @ C.euler_321(0.1, -0.2, 0.4)
    a, b, c, k_v = 0.04, 0.02, 0.015, 2e7
    h = _half_height(R, a, b, c)
    fns = []
    for depth in np.linspace(0.0005, 0.02, 12):
        out = _call(R, [0.0, h - depth, 0.0], k_v=k_v, a=a, b=b, c=c)
        assert out["fn_raw"] == pytest.approx(k_v * out["volume"], rel=1e-12)
        # the smooth clamp adds ≈ eps_force² / (4 fn), here < 1 µN
        assert out["fn"] == pytest.approx(out["fn_raw"], abs=1e-6)
        assert out["fx"] == 0.0 and out["fy"] == out["fn"]
        fns.append(out["fn"])
    assert np.all(np.diff(fns) > 0)


def test_damping_sign_and_fn_raw():
    R = C.euler_321(0.2, 0.1, -0.3)
    h = _half_height(R, 0.03, 0.02, 0.015)
    centre = [0.0, h - 0.005, 0.0]
    static = _call(R, centre, a_v=1.5)
    pressing = _call(R, centre, vel=(0.0, -0.2, 0.0), a_v=1.5)
    separating = _call(R, centre, vel=(0.0, +0.2, 0.0), a_v=1.5)
    assert pressing["depth_rate"] == pytest.approx(0.2)
    assert pressing["fn"] > static["fn"] > separating["fn"] > 0
    assert pressing["fn_raw"] == pytest.approx(static["fn_raw"] * (1 + 1.5 * 0.2), rel=1e-12)
    fast = _call(R, centre, vel=(0.0, +2.0, 0.0), a_v=1.5)  # separating faster than 1/a_v
    assert fast["fn_raw"] < 0.0 <= fast["fn"] < 1e-3


def test_out_of_contact_is_negligible():
    sm = C.Smoothing()
    p = C.default_params()
    for e in ELLIPSOIDS:
        q = dict(zip(C.PARAM_NAMES, p[C.ellipsoid_slice(e)], strict=True))
        R = C.euler_321(q["gamma"], q["beta"], q["alpha"])
        h = _half_height(R, q["a"], q["b"], q["c"])
        for lift in (h, 0.05, 0.3):  # lowest point 1 half-height, 5 cm, 30 cm above ground
            out = C.ellipsoid_plane(
                R, [0.1, h + lift, 0.0], [1.0, -0.5, 0.0], 3.0,
                *(q[k] for k in ("k_v", "a_v", "mu_s", "mu_d", "a", "b", "c")),
            )  # fmt: skip
            assert out["volume"] < 1e-16
            assert 0.0 < out["fn"] <= 0.5 * sm.eps_force * (1 + 1e-6)
            assert abs(out["fx"]) <= q["mu_s"] * out["fn"] * 1.01
            assert abs(out["mz"]) < 1e-4  # N·m


# --------------------------------------------------------------------------------------
# friction and moments
# --------------------------------------------------------------------------------------


def test_friction_coefficient_shape():
    mu_s, mu_d, vtr = 0.8, 0.5, 0.1
    f = C.friction_coefficient
    # Stribeck term peaks at exactly v_tr; tanh(4) ≠ 1 costs μ_d (1 − tanh 4) ≈ 3.4e-4
    assert f(vtr, mu_s, mu_d, vtr) == pytest.approx(mu_s, abs=mu_d * (1 - math.tanh(4)) * 1.01)
    v = np.linspace(0.0, 0.5, 5001)
    assert abs(v[np.argmax(f(v, mu_s, mu_d, vtr))] - vtr) < 0.005
    assert f(100 * vtr, mu_s, mu_d, vtr) == pytest.approx(mu_d, abs=2e-4)
    vv = np.linspace(-1, 1, 41)
    np.testing.assert_allclose(f(-vv, mu_s, mu_d, vtr), -f(vv, mu_s, mu_d, vtr), atol=1e-15)
    assert f(0.0, mu_s, mu_d, vtr) == 0.0
    x = ca.SX.sym("x")
    ff = ca.Function("f", [x], [f(x, mu_s, mu_d, vtr)])
    assert float(ff(0.037)) == pytest.approx(f(0.037, mu_s, mu_d, vtr), rel=1e-14)


def test_friction_opposes_slip_at_centroid():
    R = C.euler_321(0.4, -0.3, 0.2)
    h = _half_height(R, 0.03, 0.02, 0.015)
    centre = np.array([0.0, h - 0.006, 0.0])
    for vx in (-0.5, -0.05, 0.02, 0.3):
        out = _call(R, centre, vel=(vx, 0.0, 0.0))
        assert out["v_slip"] == pytest.approx(vx)
        assert np.sign(out["fx"]) == -np.sign(vx)
    # rolling without slip at the centroid: v_c = −ω ẑ × (p − c) → no friction
    omega = 2.0
    base = _call(R, centre, smoothing=SHARP)
    rcx, rcy = base["px"] - centre[0], base["py"] - centre[1]
    out = _call(R, centre, vel=(omega * rcy, -omega * rcx, 0.0), omega=omega, smoothing=SHARP)
    assert abs(out["v_slip"]) < 1e-15 and abs(out["depth_rate"]) < 1e-15
    assert abs(out["fx"]) < 1e-9 * out["fn"]


def test_moment_about_centre_and_rolling_resistance():
    R = C.euler_321(0.3, 0.2, -0.1)
    a, b, c, k_v, a_v = 0.03, 0.02, 0.015, 1e7, 1.2
    h = _half_height(R, a, b, c)
    centre = np.array([0.05, h - 0.008, 0.0])
    for omega in (-3.0, 0.0, 2.0):
        out = _call(R, centre, vel=(0.3, 0.0, 0.0), omega=omega, k_v=k_v, a_v=a_v, a=a, b=b, c=c)
        lever = (out["px"] - centre[0]) * out["fy"] - (out["py"] - centre[1]) * out["fx"]
        assert out["mz"] == pytest.approx(lever + out["m_roll"], rel=1e-12, abs=1e-15)
        assert out["m_roll"] == pytest.approx(-k_v * a_v * out["J"] * omega)
        assert out["J"] > 0 and out["m_roll"] * omega <= 0  # opposes rotation


# --------------------------------------------------------------------------------------
# mirror
# --------------------------------------------------------------------------------------


def test_euler_321_and_mirror_properties():
    rng = np.random.default_rng(3)
    g, b_, a_ = rng.uniform(-np.pi, np.pi, 3)
    R = C.euler_321(g, b_, a_)
    ref = Rotation.from_euler("ZYX", [g, b_, a_]).as_matrix()  # intrinsic z-y'-x''
    np.testing.assert_allclose(R, ref, atol=1e-14)
    s = ca.SX.sym("s", 3)
    Rs = ca.Function("R", [s], [C.euler_321(s[0], s[1], s[2])])
    np.testing.assert_allclose(np.array(Rs([g, b_, a_])), R, atol=1e-14)
    Rm, rm = C.mirror(R, [0.1, 0.02, 0.03])
    assert np.linalg.det(Rm) == pytest.approx(1.0)
    np.testing.assert_allclose(rm, [0.1, 0.02, -0.03])
    Rm_sx, _ = C.mirror(C.euler_321(s[0], s[1], s[2]), ca.vertcat(s[0], 0, 1))
    np.testing.assert_allclose(np.array(ca.Function("m", [s], [Rm_sx])([g, b_, a_])), Rm)


def test_mirrored_ellipsoid_gives_same_in_plane_load():
    rng = np.random.default_rng(11)
    p = C.default_params()
    for e in ELLIPSOIDS:
        q = dict(zip(C.PARAM_NAMES, p[C.ellipsoid_slice(e)], strict=True))
        Rl = C.euler_321(q["gamma"], q["beta"], q["alpha"])
        rl = np.array([q["r_x"], q["r_y"], q["r_z"]])
        Rr, rr = C.mirror(Rl, rl)
        for _ in range(5):
            theta, omega = rng.uniform(-0.6, 0.6), rng.uniform(-4, 4)
            origin = np.array([rng.uniform(-1, 1), rng.uniform(0.0, 0.03), 0.0])
            v0 = np.array([rng.uniform(-0.5, 0.5), rng.uniform(-0.3, 0.3), 0.0])
            loads = []
            for R_e, r_e in ((Rl, rl), (Rr, rr)):
                arm = _rz(theta) @ r_e
                vel = v0 + np.array([-omega * arm[1], omega * arm[0], 0.0])
                out = C.ellipsoid_plane(
                    _rz(theta) @ R_e, origin + arm, vel, omega,
                    *(q[k] for k in ("k_v", "a_v", "mu_s", "mu_d", "a", "b", "c")),
                )  # fmt: skip
                loads.append(np.array([out[k] for k in ("fx", "fy", "mz", "px", "py", "fn")]))
            np.testing.assert_allclose(loads[1], loads[0], rtol=1e-10, atol=1e-12)


# --------------------------------------------------------------------------------------
# derivatives
# --------------------------------------------------------------------------------------


def _segment_contact_function():
    """Loads as a function of z = [X, Y, θ, vX, vY, ω, 13 parameters] (segment pose)."""
    z = ca.SX.sym("z", 6 + C.N_PER_ELLIPSOID)
    X, Y, th, vX, vY, om = (z[i] for i in range(6))
    q = dict(zip(C.PARAM_NAMES, (z[6 + i] for i in range(C.N_PER_ELLIPSOID)), strict=True))
    Rz = ca.vertcat(
        ca.horzcat(ca.cos(th), -ca.sin(th), 0), ca.horzcat(ca.sin(th), ca.cos(th), 0),
        ca.horzcat(0, 0, 1),
    )  # fmt: skip
    R = Rz @ C.euler_321(q["gamma"], q["beta"], q["alpha"])
    arm = Rz @ ca.vertcat(q["r_x"], q["r_y"], q["r_z"])
    centre = ca.vertcat(X, Y, 0) + arm
    vel = ca.vertcat(vX - om * arm[1], vY + om * arm[0], 0)
    out = C.ellipsoid_plane(
        R, centre, vel, om, *(q[k] for k in ("k_v", "a_v", "mu_s", "mu_d", "a", "b", "c"))
    )
    assert isinstance(out["fx"], ca.SX)
    y = ca.vertcat(out["fx"], out["fy"], out["mz"], out["fn"])
    return ca.Function("f", [z], [y]), ca.Function("J", [z], [ca.jacobian(y, z)])


def test_ad_gradients_match_finite_differences():
    f, jac = _segment_contact_function()
    rng = np.random.default_rng(5)
    p = C.default_params()
    worst = 0.0
    for k in range(12):
        e = ELLIPSOIDS[k % 3]
        q = p[C.ellipsoid_slice(e)].copy()
        q[:4] = [rng.uniform(5e6, 3e7), rng.uniform(0.2, 2.5), 0.6, 0.4]  # in-range k_v, a_v, μ
        R = _rz(0.0) @ C.euler_321(q[10], q[11], q[12])
        arm_y = q[8]
        h = _half_height(R, *q[4:7])
        theta = rng.uniform(-0.05, 0.05)
        # put the segment so that the ellipsoid is 2–8 mm deep
        Y = h - rng.uniform(0.002, 0.008) - arm_y
        z0 = np.concatenate([[0.1, Y, theta, rng.uniform(-0.3, 0.3), rng.uniform(-0.1, 0.1),
                              rng.uniform(-2, 2)], q])  # fmt: skip
        Ja = np.array(jac(z0))
        scale = np.maximum(np.abs(z0), np.r_[[0.1] * 6, [1.0] * 4, [0.01] * 6, [0.1] * 3])
        Jf = np.zeros_like(Ja)
        for i in range(z0.size):
            dz = 1e-6 * scale[i]
            zp, zm = z0.copy(), z0.copy()
            zp[i] += dz
            zm[i] -= dz
            Jf[:, i] = (np.array(f(zp)) - np.array(f(zm))).ravel() / (2 * dz)
        y = np.abs(np.array(f(z0))).ravel()
        # relative to each output's natural scale (|value| / input scale), column-wise
        tol_scale = (np.maximum(y, 1e-3)[:, None] / scale[None, :]) + np.abs(Ja)
        worst = max(worst, float(np.max(np.abs(Ja - Jf) / tol_scale)))
    assert worst < 1e-5, worst


def test_numeric_sx_mx_paths_agree():
    R = C.euler_321(0.3, -0.4, 1.1)
    h = _half_height(R, 0.03, 0.02, 0.015)
    args = (R, [0.01, h - 0.004, 0.02], [0.2, -0.1, 0.0], 1.5, 1e7, 1.0, 0.5, 0.4, 0.03, 0.02, 0.015)
    ref = C.ellipsoid_plane(*args)
    assert all(isinstance(v, float) for v in ref.values())
    assert set(ref) == set(C.CONTACT_OUTPUTS)
    for sym in (ca.SX, ca.MX):
        w = sym.sym("w")
        out = C.ellipsoid_plane(args[0], args[1], args[2], w, *args[4:])
        f = ca.Function("f", [w], [out[k] for k in C.CONTACT_OUTPUTS])
        vals = [float(v) for v in f(args[3])]
        np.testing.assert_allclose(vals, [ref[k] for k in C.CONTACT_OUTPUTS], rtol=1e-13)
