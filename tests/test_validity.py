"""Physical validity gates (gaitlib.validity) on hand-made cases.

A synthetic, clean gait cycle (t_f = 1 s, 100 uniform nodes; right foot loaded 400 N from
0 to 60 % of the cycle, left foot from 50 % to 110 %, so 20 % double support; the data's
foot off at 60 %, left leg shifted by 50 %) passes every gate; each test then breaks one
thing and checks that exactly that gate fails, with the number computed here by hand.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from gaitlib import conventions as cv
from gaitlib import validity as V

T = np.linspace(0.0, 1.0, 100, endpoint=False)  # cycle fraction = time (t_f = 1 s)
EVENTS = {"foot_off": 0.6, "opposite_foot_contact": 0.5, "double_support": 0.2}
STRENGTH = {"hip": (-100.0, 100.0), "knee": (-100.0, 100.0), "ankle": (-100.0, 100.0), "mtp": (-100.0, 100.0)}
BW_2PCT = 0.02 * 41.4 * 9.81  # 8.123 N


def frames():
    idx = pd.Index(T, name="time")
    right = np.where(T < 0.6, 400.0, 0.0)
    left = np.where((T >= 0.5) | (T < 0.1), 400.0, 0.0)
    grf = pd.DataFrame({"grf_x_r": 0.0, "grf_y_r": right, "grf_x_l": 0.0, "grf_y_l": left}, index=idx)
    q = pd.DataFrame({j: np.full(T.size, math.radians(-10.0 if j.startswith("knee") else 10.0)) for j in cv.JOINTS},
                     index=idx)
    tq = pd.DataFrame({j: 10.0 * np.sin(2 * np.pi * T) for j in cv.JOINTS}, index=idx)
    res = pd.DataFrame({"R_x": 1.0, "R_y": -1.0, "R_z": 0.1}, index=idx)
    return {"q": q, "torques": tq, "grf": grf, "residuals": res}


def gates(status="Solve_Succeeded", kind="tracking", periodicity=0.0, **over):
    f = frames()
    f.update(over)
    return V.check_frames(status=status, tf=1.0, kind=kind, events=EVENTS, left_shift=0.5, strength=STRENGTH,
                          com_height=0.9, periodicity=periodicity, **f)


def row(g, name):
    return g.table.set_index("check").loc[name]


def test_clean_cycle_passes():
    g = gates()
    assert g.passed and g.failed == [] and g.label() == "valid"
    assert list(g.table["check"]) == list(V.CHECKS)
    assert row(g, "double_support")["value"] == pytest.approx(20.0)  # 0–10 % and 50–60 %
    assert row(g, "swing_load")["value"] == 0.0
    assert row(g, "swing_load")["threshold"] == pytest.approx(BW_2PCT)
    # peak external force 800 N (both feet 400 N): 5 % = 40 N, 1 % × 0.9 m × 800 N = 7.2 N·m
    assert row(g, "residual_force")["threshold"] == pytest.approx(40.0)
    assert row(g, "residual_moment")["threshold"] == pytest.approx(7.2)


def test_foot_loaded_in_swing_fails():
    f = frames()
    grf = f["grf"].copy()
    grf.loc[np.isclose(grf.index, 0.80), "grf_y_r"] = 55.0  # right foot swings 60–100 %
    g = gates(grf=grf)
    assert g.failed == ["swing_load"]
    assert row(g, "swing_load")["value"] == pytest.approx(55.0)
    assert g.label() == "invalid: swing load 55 N > 8.12 N (2 % BW)"
    # the left foot swings 10–50 %: a load there fails too; at 61 % (inside the 2 % margin
    # after the right foot's foot-off) it does not
    grf2 = f["grf"].copy()
    grf2.loc[np.isclose(grf2.index, 0.30), "grf_y_l"] = 9.0
    assert gates(grf=grf2).failed == ["swing_load"]
    grf3 = f["grf"].copy()
    grf3.loc[np.isclose(grf3.index, 0.61), "grf_y_r"] = 50.0
    assert gates(grf=grf3).passed
    # 8 N < 2 % BW is allowed
    grf4 = f["grf"].copy()
    grf4.loc[np.isclose(grf4.index, 0.80), "grf_y_r"] = 8.0
    assert gates(grf=grf4).passed


def test_both_feet_loaded_is_not_walking():
    f = frames()
    grf = f["grf"].assign(grf_y_r=300.0, grf_y_l=300.0)
    g = gates(grf=grf, kind="predictive")
    assert g.failed == ["double_support"]  # predictive: no data-event swing check
    assert row(g, "double_support")["value"] == pytest.approx(100.0)
    assert row(g, "swing_load")["passed"] is None
    # 45 % both loaded: right 0–60 %, left 15–100 % → 15–60 %
    grf = f["grf"].assign(grf_y_l=np.where(T >= 0.15, 400.0, 0.0))
    g = gates(grf=grf, kind="predictive")
    assert row(g, "double_support")["value"] == pytest.approx(45.0)
    assert g.failed == ["double_support"]


def test_residuals_above_guideline_fail():
    f = frames()
    g = gates(residuals=f["residuals"].assign(R_x=50.0))
    assert g.failed == ["residual_force"] and row(g, "residual_force")["value"] == 50.0
    assert gates(residuals=f["residuals"].assign(R_y=-39.0)).passed
    g = gates(residuals=f["residuals"].assign(R_z=-8.0))
    assert g.failed == ["residual_moment"]
    assert "residual moment 8 N·m > 7.2 N·m" in g.label()


def test_torque_above_strength_fails():
    f = frames()
    tq = f["torques"].copy()
    tq.iloc[10, tq.columns.get_loc("knee_r")] = 120.0
    g = gates(torques=tq)
    assert g.failed == ["strength"]
    assert row(g, "strength")["value"] == 120.0 and row(g, "strength")["threshold"] == 100.0
    assert g.label().startswith("invalid: torque 120 N·m > 100 N·m")
    tq = f["torques"].copy()
    tq.iloc[10, tq.columns.get_loc("ankle_l")] = -99.0
    assert gates(torques=tq).passed


def test_angle_out_of_rom_fails():
    f = frames()
    q = f["q"].copy()
    q["knee_r"] = math.radians(5.0)  # 5° of knee hyperextension; Table 3.5: knee ≤ 0°
    g = gates(q=q)
    assert g.failed == ["rom"] and row(g, "rom")["value"] == pytest.approx(5.0)
    q["knee_r"] = math.radians(-10.0)
    q["ankle_r"] = math.radians(-35.0)  # 35° plantarflexion: inside either reading's union
    assert gates(q=q).passed
    q["ankle_r"] = math.radians(-45.0)
    g = gates(q=q)
    assert g.failed == ["rom"] and g.label() == "invalid: angle -45 deg < -40 deg (ankle_r, thesis Table 3.5)"
    # an angle the data's children show (mean + 1 SD) is inside their range
    q = f["q"].copy()
    q["knee_r"] = math.radians(2.0)
    f2 = frames()
    f2["q"] = q
    g = V.check_frames(status="Solve_Succeeded", tf=1.0, events=EVENTS, left_shift=0.5, strength=STRENGTH,
                       com_height=0.9, periodicity=0.0, rom_data={"knee": (-65.0, 2.5)}, **f2)
    assert g.passed


def test_not_converged_fails_and_acceptable_passes():
    g = gates(status="Maximum_Iterations_Exceeded")
    assert g.failed == ["converged"] and not g.converged
    assert g.label() == "not converged (Maximum_Iterations_Exceeded)"
    assert gates(status="Solved_To_Acceptable_Level").passed
    f = frames()
    grf = f["grf"].copy()
    grf.loc[np.isclose(grf.index, 0.80), "grf_y_r"] = 55.0
    lab = gates(status="Infeasible_Problem_Detected", grf=grf).label()
    assert lab.startswith("not converged (Infeasible_Problem_Detected); invalid: swing load 55 N")


def test_periodicity():
    g = gates(periodicity=0.05)
    assert g.failed == ["periodicity"]
    assert gates(periodicity=1e-9).passed


def test_strength_limits_by_hand():
    """Eq 5.21 scaling and the eccentric plateau E of the Gymnast table (typed here)."""
    f = 41.4 * 1.47 / (69.6 * 1.732)
    lim = V.strength_limits(None)
    assert lim["knee"][1] == pytest.approx(285.619 * f * 1.13292)  # knee extensor: positive
    assert lim["knee"][0] == pytest.approx(-98.7579 * f * 1.12)  # knee flexor
    assert lim["hip"][1] == pytest.approx(157.293 * f * 1.11905)  # hip flexor: positive
    assert lim["hip"][0] == pytest.approx(-175.746 * f * 1.1)
    assert lim["ankle"][0] == pytest.approx(-127.561 * f * 1.159)  # plantarflexor: negative
    assert lim["ankle"][1] == pytest.approx(44.3106 * f * 1.2656)
    assert lim["mtp"] == (lim["ankle"][0], -lim["ankle"][0])
    two = V.strength_limits(None, body_mass=73.8, body_height=1.66, legs=2)
    assert two["knee"][1] == pytest.approx(2 * 285.619 * 73.8 * 1.66 / (69.6 * 1.732) * 1.13292)


def test_rom_is_table_3_5():
    from gaitlib.studies import jump as J

    for j in ("hip", "knee", "mtp"):
        assert np.allclose(np.rad2deg(J.joint_bounds(j)["q"]), V.ROM_DEG[j])
    lo, hi = np.rad2deg(J.joint_bounds("ankle")["q"])  # the jump's reading, −20…40°
    assert V.ROM_DEG["ankle"][0] <= lo and hi <= V.ROM_DEG["ankle"][1]
    assert V.ROM_DEG["ankle"] == (-40.0, 40.0)  # the other reading's −40…20° included


def test_check_reads_a_jump_like_solution():
    idx = pd.Index(np.linspace(0, 1, 11), name="time")
    traj = pd.DataFrame({"phase": "thrust", "mtp": 0.0, "ankle": 0.1, "knee": -1.0, "hip": 1.0,
                         "tau_mtp": 10.0, "tau_ankle": -50.0, "tau_knee": 1500.0, "tau_hip": -100.0,
                         "grf_x": 0.0, "grf_y": 700.0}, index=idx)
    model = SimpleNamespace(joints=("mtp", "ankle", "knee", "hip"), total_mass=73.8, incline=math.radians(28.8),
                            standing_top=0.116 * math.sin(math.radians(28.8)) + 0.503 + 0.440 + 0.660)  # Table 3.1 by hand
    sol = SimpleNamespace(trajectory=traj, jump_height={}, model=model, status="Solve_Succeeded")
    g = V.check(sol)
    assert g.failed == ["strength"]
    h = 0.116 * math.sin(math.radians(28.8)) + 0.503 + 0.440 + 0.660
    knee_peak = 2 * 285.619 * 73.8 * h / (69.6 * 1.732) * 1.13292
    assert row(g, "strength")["threshold"] == pytest.approx(knee_peak)
    assert {r.check for r in g.table.itertuples() if r.passed is None} == {
        "swing_load", "double_support", "residual_force", "residual_moment", "periodicity"}


def test_book_gates_table_from_given_solutions():
    """The study's long table and matrix on hand-made solutions (no store needed): a jump
    over strength and a run that returned no solution."""
    from gaitlib.studies import validity as SV

    idx = pd.Index(np.linspace(0, 1, 5), name="time")
    traj = pd.DataFrame({"phase": "thrust", "ankle": 0.0, "knee": -0.5, "hip": 0.5, "tau_ankle": -10.0,
                         "tau_knee": 900.0, "tau_hip": -10.0, "grf_x": 0.0, "grf_y": 700.0}, index=idx)
    model = SimpleNamespace(joints=("ankle", "knee", "hip"), total_mass=72.0, incline=math.radians(28.8),
                            standing_top=0.116 * math.sin(math.radians(28.8)) + 0.503 + 0.440 + 0.660)
    jump = SimpleNamespace(trajectory=traj, jump_height={}, model=model, status="Solve_Succeeded")
    lost = SimpleNamespace(ok=False, status="error", value=None)
    g = SV.book_gates(solutions={"jump": jump, "lost": lost})
    assert set(g["solution"]) == {"jump", "lost"} and len(g) == 2 * len(V.CHECKS)
    v = g.drop_duplicates("solution").set_index("solution")
    assert not v.loc["jump", "valid"] and v.loc["lost", "label"] == "not converged (error)"
    m = SV.gates_matrix(g)
    assert m.loc["jump", "strength"].startswith("✗ 900") and m.loc["jump", "swing_load"] == "–"
    s = SV.summary(g)
    assert s.loc["strength", "failed"] == 1 and s.loc["converged", "failed"] == 1
    assert V.label(jump).startswith("invalid: torque 900 N·m")


def test_a_torque_at_its_strength_bound_within_round_off_passes():
    """A jump bounded by the same strength ends at the bound within IPOPT's tolerance: 1e-9
    relative above it passes, 1e-4 above it fails."""
    h = 0.116 * math.sin(math.radians(28.8)) + 0.503 + 0.440 + 0.660
    model = SimpleNamespace(joints=("ankle", "knee", "hip"), total_mass=73.8, incline=math.radians(28.8), standing_top=h)
    lim = V.strength_limits(None, body_mass=73.8, body_height=h, legs=2)
    idx = pd.Index(np.linspace(0, 1, 5), name="time")
    for excess, ok in ((1e-9, True), (1e-4, False)):
        traj = pd.DataFrame({"phase": "thrust", "ankle": 0.0, "knee": -0.5, "hip": 0.5, "tau_ankle": -10.0,
                             "tau_knee": 10.0, "tau_hip": lim["hip"][0] * (1 + excess), "grf_x": 0.0,
                             "grf_y": 700.0}, index=idx)
        sol = SimpleNamespace(trajectory=traj, jump_height={}, model=model, status="Solve_Succeeded")
        assert ("strength" not in V.check(sol).failed) is ok
