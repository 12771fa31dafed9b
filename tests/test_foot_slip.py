"""Foot slip (gaitlib.studies.fidelity.foot_slip, a measurement) and the friction floor
(GaitSpec.friction_floor): the model's slip velocity on a translating pose by hand, the
same velocity the friction law reads, the force-weighted mean slip by hand, and the
floor's effect on the contact parameters and keys."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from gaitlib import contact, kinematics
from gaitlib import conventions as cv
from gaitlib import data as data_mod
from gaitlib.model import ChildModel
from gaitlib.problems import gait as gait_ocp
from gaitlib.studies import contact_id as ci_study
from gaitlib.studies import fidelity
from gaitlib.studies import gait as gait_study


def _standing(model, sink=0.004):
    q = np.zeros(len(cv.COORDS))
    q[1] = kinematics.settle_height(model, q) - sink  # feet a few mm in the ground
    return q


def test_a_translating_pose_slips_at_its_speed_and_the_friction_law_reads_that_slip():
    model = ChildModel()
    q = _standing(model)
    v = 0.37
    qd = np.zeros(len(cv.COORDS))
    qd[0] = v  # the whole body moves forward, nothing rotates
    r = model.slip(q, qd)
    fn = np.ravel(r["fn"])
    assert (fn > 1.0).sum() >= 2  # some ellipsoids carry load
    np.testing.assert_allclose(np.ravel(r["v_slip"]), v, atol=1e-12)
    # the contact function's friction force is −μ(v_slip) fn with the same v_slip
    ct = model.contact(q, qd)
    p = contact.default_params()
    for i, e in enumerate(cv.ELLIPSOIDS * 2):
        mu = contact.friction_coefficient(v, p[contact.param_index(e, "mu_s")], p[contact.param_index(e, "mu_d")])
        assert float(np.ravel(ct["fx"])[i]) == pytest.approx(-mu * fn[i], rel=1e-9, abs=1e-12)
    # standing still: no slip
    np.testing.assert_allclose(np.ravel(model.slip(q, np.zeros(len(cv.COORDS)))["v_slip"]), 0.0, atol=1e-12)


def _solution(vs, fn, t, tf=1.0):
    """A stand-in solution: two ellipsoids' normal forces and slip velocities, Free data."""
    labs = [f"{e}_{s}" for s in cv.SIDES for e in cv.ELLIPSOIDS][:2]
    ell = pd.DataFrame({**{f"fn_{lab}": fn[:, j] for j, lab in enumerate(labs)},
                        **{f"vs_{lab}": vs[:, j] for j, lab in enumerate(labs)}}, index=pd.Index(t, name="time"))
    return SimpleNamespace(ellipsoids=ell, stats={"tf_s": tf}, spec=gait_ocp.GaitSpec(model="SK"))


def test_foot_slip_is_the_force_weighted_mean_slip_by_hand():
    t = np.array([0.0, 0.25, 0.5, 0.75])  # four equal quarters of a 1-s cycle
    fn = np.array([[100.0, 0.0], [300.0, 100.0], [0.0, 200.0], [100.0, 100.0]])
    vs = np.array([[0.0, 5.0], [0.2, -0.1], [9.0, 0.05], [0.0, 0.0]])
    # Σ fn|vs| = 300·0.2 + 100·0.1 + 200·0.05 = 80; Σ fn = 900 → 0.0889 m/s (equal time weights)
    f = fidelity.foot_slip(_solution(vs, fn, t))
    assert f["slip"] == pytest.approx(80.0 / 900.0)
    assert f["sliding"] == pytest.approx(300.0 / 900.0)  # the load carried faster than 0.1 m/s
    assert f["worst"] == "toe_r" and fidelity.SLIP_V == 0.1
    assert f["ball"] == pytest.approx(400.0 / 900.0)  # ball_r (second column) carries 0 + 100 + 200 + 100 of 900
    assert f["speed"] == pytest.approx(data_mod.load_gait_data("Free").speed)
    # unequal time weights: the last node stands for half the cycle
    f2 = fidelity.foot_slip(_solution(vs, fn, t, tf=1.25))
    w = np.array([0.2, 0.2, 0.2, 0.4])
    num = (w[:, None] * fn * np.abs(vs)).sum()
    assert f2["slip"] == pytest.approx(num / (w[:, None] * fn).sum())
    with pytest.raises(ValueError, match="no slip velocities"):
        fidelity.foot_slip(SimpleNamespace(ellipsoids=_solution(vs, fn, t).ellipsoids.filter(like="fn_"),
                                           stats={}, spec=gait_ocp.GaitSpec(model="SK")))


def test_friction_floor_raises_only_the_coefficients_below_it_and_keeps_keys():
    spec = gait_ocp.GaitSpec(model="MSK", cost="Eq5.33", n_intervals=2, degree=2)
    assert "friction_floor" not in spec.to_dict()
    fl = replace(spec, friction_floor=0.2819)
    assert fl.key() != spec.key() and replace(spec, friction_floor=None).key() == spec.key()
    assert gait_ocp.GaitSpec.from_dict(fl.to_dict()) == fl
    base, raised = gait_ocp.contact_params_of(spec), gait_ocp.contact_params_of(fl)
    changed = {i for i in range(base.size) if base[i] != raised[i]}
    # Table 4.18: ball μ_s 0.0101, μ_d 0.0100 and heel μ_s 0.1703, μ_d 0.1686 are below it; toe (0.3404, 0.2819) is not
    expect = {contact.param_index(e, k) for e in ("ball", "heel") for k in ("mu_s", "mu_d")}
    assert changed == expect and all(raised[i] == 0.2819 for i in expect)
    for bad in (0.0, -1.0, 3.0, "0.3", True):
        with pytest.raises(ValueError, match="friction_floor"):
            replace(spec, friction_floor=bad)


def test_friction_floor_with_free_contact_raises_the_identification_lower_bounds():
    # Ch 4 (b)/(c): Table 4.7's friction lower bound is 0.01 for every ellipsoid (contact.bounds);
    # with the floor every μ_s and μ_d parameter's lower bound is the floor, nothing else moves
    sb = ci_study.spec_b(n_intervals=2, degree=2)
    lo, hi = contact.bounds()
    fr = [contact.param_index(e, k) for e in cv.ELLIPSOIDS for k in ("mu_s", "mu_d")]
    assert all(lo[i] == 0.01 for i in fr)
    base = {p.name: p for p in gait_ocp.build(sb).problem.parameters}
    floored = {p.name: p for p in gait_ocp.build(replace(sb, friction_floor=0.2819)).problem.parameters}
    names = contact.param_names()
    moved = {n for n in base if (base[n].lower, base[n].upper) != (floored[n].lower, floored[n].upper)}
    assert moved == {f"c.{names[i]}" for i in fr}
    for i in fr:
        f = floored[f"c.{names[i]}"]
        assert f.lower == 0.2819 and f.upper == max(hi[i], 0.2819)


def test_friction_floor_and_ball_friction_read_the_parameter_sets():
    # Table 4.18 (the thesis's set): ball μ_s 0.0101, μ_d 0.0100; the largest μ_d is the toe's 0.2819
    assert fidelity.ball_friction("default") == (0.0101, 0.0100)
    assert fidelity.FRICTION_FLOOR == 0.2819


def _friction_row(status, gates, grf, angle, torque, obj, slip, sliding, mu_d, start="neutral", sink=20.0,
                  rest="carried"):
    v = gait_study.SLIP_V
    return {"status": status, "gates": gates, "iterations": 1, "objective": obj, "start kept": start,
            "mean GRF RMSE (N)": grf, "worst angle RMSE (deg)": angle, "worst torque RMSE (N·m)": torque,
            "foot slip (m/s)": slip, f"load sliding > {v:g} m/s (%)": sliding, "ball mu_s": mu_d, "ball mu_d": mu_d,
            "deepest sink (mm)": sink, ci_study.REST_COLUMN: rest}


def test_friction_findings_compare_the_bounded_identification_by_hand():
    f = 0.2819
    t = pd.DataFrame.from_dict({
        ci_study.APPROACHES["b"]: _friction_row("Solve_Succeeded", "valid", 12.5, 2.0, 1.0, 0.013, 0.115, 35.0, 0.0261),
        ci_study.friction_label("b", f): _friction_row("Solve_Succeeded", "valid", 15.0, 3.0, 1.5, 0.026, 0.013, 1.0, 0.2819,
                                                       sink=40.25, rest="row 6: a load of 444.1 N needs more"),
        ci_study.APPROACHES["c"]: _friction_row("Solve_Succeeded", "valid", 10.0, 2.0, 1.0, 0.014, 0.114, 30.0, 0.01,
                                                "(b)'s solution"),
        ci_study.friction_label("c", f): _friction_row("Maximum_Iterations_Exceeded", "not converged", 99.0, 9.0, 9.0,
                                                       1.0, 0.0, 0.0, 0.2819, "warm: (b)")}, orient="index")
    out = ci_study.friction_findings(t)
    assert len(out) == 2
    # (b): 12.5 → 15.0 N is +20 %; slip 0.115 → 0.013 m/s; load sliding 35 → 1 %
    assert "12.5 → 15.0 N (+20 %)" in out[0] and "0.115 → 0.013 m/s" in out[0] and "35 → 1 %" in out[0]
    assert "start kept: neutral" in out[0] and "0.0261 → 0.2819" in out[0] and "20.0 → 40.2 mm" in out[0]
    assert "cannot carry the data's load (row 6: a load of 444.1 N needs more)" in out[0]
    assert out[1].startswith(ci_study.friction_label("c", f) + ": not compared") and "99.0" not in out[1]


def test_foot_sink_is_the_lowest_ellipsoid_depth_by_construction():
    # pose_from_data puts the lowest ellipsoid `penetration` below the ground at every row;
    # lowering the pelvis by 3 mm more sinks it 3 mm deeper; raising it 1 m lifts every foot
    gd = data_mod.load_gait_data("Free")
    m, p = ChildModel(), contact.default_params()
    t = gd.time[::10]
    q = pd.DataFrame(kinematics.pose_from_data(m, gd, t, p, penetration=0.002), columns=list(cv.COORDS))
    assert gait_study.foot_sink(q, p) == pytest.approx(0.002, abs=1e-9)
    assert gait_study.foot_sink(q.assign(pelvis_ty=q["pelvis_ty"] - 0.003), p) == pytest.approx(0.005, abs=1e-9)
    assert gait_study.foot_sink(q.assign(pelvis_ty=q["pelvis_ty"] + 1.0), p) == 0.0


def test_max_sink_bounds_every_ellipsoid_depth_at_every_node():
    # GaitSpec.max_sink adds the path constraint depth ≤ max_sink (the contact law's depth of
    # each of the six ellipsoids); the depth is the lowest point's distance below y = 0
    sp = gait_ocp.GaitSpec(model="SK", n_intervals=2, degree=2)
    assert "max_sink" not in sp.to_dict()
    gp = gait_ocp.build(replace(sp, max_sink=0.018))
    (c,) = [c for c in gp.problem.phases[0].path_constraints if c.name == "sink"]
    assert c.upper == 0.018 and c.lower == -np.inf
    assert not [c for c in gait_ocp.build(sp).problem.phases[0].path_constraints if c.name == "sink"]
    m, p = ChildModel(), contact.default_params()
    gd = data_mod.load_gait_data("Free")
    q = kinematics.pose_from_data(m, gd, gd.time[:3], p, penetration=0.004)[1]
    depth = np.asarray(m.function("contact")(q=q, qd=np.zeros(11), p_contact=p)["depth"]).ravel()
    np.testing.assert_allclose(depth, -kinematics.ellipsoid_bottoms(m, q, p), atol=1e-12)
    assert depth.max() == pytest.approx(0.004, abs=1e-9)
    for bad in (0.0, -0.01, 0.2, "0.01", True):
        with pytest.raises(ValueError, match="max_sink"):
            replace(sp, max_sink=bad)


def test_reference_slip_findings_name_the_cause_by_the_anchored_slip():
    r = {"slip": 0.228, "sliding": 0.38, "anchored_slip": 0.209, "anchored_sliding": 0.40, "hat_speed_min": 0.34,
         "hat_speed_max": 1.46, "speed": 1.178}
    (a,) = ci_study.reference_slip_findings({"ours": r})
    assert "slide 0.228 m/s" in a and "38 %" in a and "0.34–1.46 m/s" in a and "the slip is 0.209 m/s (40 %)" in a
    assert "move the loaded feet over the ground, so a gait" in a
    (c,) = ci_study.reference_slip_findings({"ours": {**r, "by_ellipsoid": {"toe": 0.29, "ball": 0.25, "heel": 0.04}}})
    assert "by ellipsoid toe 0.29, ball 0.25, heel 0.04 m/s; 38 %" in c and "(most at the toe ellipsoids)" in c
    (b,) = ci_study.reference_slip_findings({"ours": {**r, "anchored_slip": 0.05}})
    assert "constant-speed HAT reference is what asks the feet to slide" in b


def test_friction_starts_findings_name_a_feasible_better_start_by_hand():
    f, sink = 0.2819, 0.018
    cols = ["converged", "valid", "objective", "deepest sink (mm)", gait_study.SLIP_COLUMN, "kept"]
    only = pd.DataFrame([[True, True, 0.026, 40.3, 0.013, True], [True, True, 0.039, 17.6, 0.024, False],
                         [True, False, 0.030, 10.0, 0.01, False]], index=["neutral", "ch4_child", "bad"], columns=cols)
    both = pd.DataFrame([[True, True, 0.36, 18.0, 0.14, False], [True, True, 0.101, 13.5, 0.017, True]],
                        index=["neutral", "ch4_child"], columns=cols)
    runs = {ci_study.friction_label("b", f): SimpleNamespace(starts=only),
            ci_study.friction_label("b", f, sink): SimpleNamespace(starts=both)}
    (line,) = ci_study.friction_starts_findings(runs, f, sink)
    # neutral sinks 40.3 mm > 18; 'bad' is not valid; ch4_child: 17.6 mm ≤ 18 and 0.039 < 0.101
    assert "start 'ch4_child'" in line and "objective 0.0390" in line and "sinking 17.6 mm (within the 18 mm bound)" in line
    assert "below the 0.1010 its multistart kept ('ch4_child')" in line
    both.loc["ch4_child", "objective"] = 0.03
    assert ci_study.friction_starts_findings(runs, f, sink) == []


def test_static_support_names_the_pose_a_soft_set_cannot_carry():
    # the thesis's set carries the data's load at rest; at 2 % of its stiffness the first
    # pose's 413 N (data: total vertical GRF at 0 % of the Free cycle) needs > 6 cm of penetration
    p = contact.default_params()
    assert gait_study.static_support(p) is None
    soft = p.copy()
    for e in cv.ELLIPSOIDS:
        soft[contact.param_index(e, "k_v")] *= 0.02
    gd = data_mod.load_gait_data("Free")
    load0 = float(gd.mean["grf_y_r"].iloc[0] + gd.mean["grf_y_l"].iloc[0])
    assert gait_study.static_support(soft) == f"row 0: a load of {load0:.1f} N needs more than 0.06 m of penetration"
