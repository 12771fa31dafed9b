"""The jerk normalisation (GaitSpec.jerk_ranges) and the kinematic angle floor
(gaitlib.studies.fidelity): the data-derived ranges by hand on sinusoids, the key
stability of the new option, which denominators it changes, and the floor's poses against
the foot constraints computed by the NumPy kinematics (an independent path)."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import casadi as ca
import numpy as np
import pandas as pd
import pytest

from gaitlib import conventions as cv
from gaitlib import data as data_mod
from gaitlib import kinematics
from gaitlib.model import ChildModel
from gaitlib.problems import gait as gait_ocp
from gaitlib.studies import fidelity


def _sine_gait(A=60.0, B=0.02, T=1.0, n=101):
    t = np.linspace(0.0, T, n)
    w = 2 * np.pi / T
    mean = pd.DataFrame({"grf_x_r": A * np.sin(w * t), "grf_x_l": 0.0 * t, "pelvis_tilt": B * np.sin(w * t)})
    return SimpleNamespace(time=t, cycle_time=T, mean=mean), w


def test_data_jerk_ranges_by_hand_on_sinusoids():
    A, B = 60.0, 0.02
    gait, w = _sine_gait(A, B)
    r = gait_ocp.data_jerk_ranges(gait)
    # m ẍ = A sin(ωt) → jerk = A ω cos(ωt) / m, range 2 A ω / m
    assert r["jerk_pelvis_tx"] == pytest.approx(2 * A * w / cv.BODY_MASS, rel=1e-4)
    # tilt = B sin(ωt) → third derivative −B ω³ cos(ωt), range 2 B ω³
    assert r["jerk_pelvis_tilt"] == pytest.approx(2 * B * w**3, rel=1e-4)


def test_com_speed_range_by_hand():
    A = 60.0
    gait, w = _sine_gait(A, n=2001)
    # v = −A cos(ωt) / (m ω) + c → range 2 A / (m ω)
    assert fidelity.com_speed_range(gait) == pytest.approx(2 * A / (cv.BODY_MASS * w), rel=1e-4)


def test_jerk_ranges_option_keeps_keys_and_changes_only_the_two_hat_denominators():
    spec = gait_ocp.GaitSpec(model="SK", cost="Eq4.11")
    assert "jerk_ranges" not in spec.to_dict()
    data = replace(spec, jerk_ranges="data")
    assert data.key() != spec.key() and replace(spec, jerk_ranges=None).key() == spec.key()
    assert gait_ocp.GaitSpec.from_dict(data.to_dict()) == data
    with pytest.raises(ValueError, match="jerk_ranges"):
        replace(spec, jerk_ranges="thesis")
    gait = data_mod.load_gait_data("Free")
    model = ChildModel()
    a = gait_ocp.reference(gait, model).ranges
    b = gait_ocp.reference(gait, model, jerk_ranges="data").ranges
    changed = {k for k in a if a[k] != b[k]}
    assert changed == {"jerk_pelvis_tx", "jerk_pelvis_tilt"}
    assert a["jerk_pelvis_tx"] == 1.0 and a["jerk_pelvis_tilt"] == 1.0  # the book's fallback
    assert b["jerk_pelvis_tx"] == pytest.approx(gait_ocp.data_jerk_ranges(gait)["jerk_pelvis_tx"])


def test_ellipsoid_bottoms_sx_equals_the_numpy_kinematics():
    model = ChildModel()
    x = ca.SX.sym("q", len(cv.COORDS))
    f = ca.Function("b", [x], [kinematics.ellipsoid_bottoms_sx(model, x)])
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.normal(0.0, 0.4, len(cv.COORDS))
        np.testing.assert_allclose(np.asarray(f(q)).ravel(), kinematics.ellipsoid_bottoms(model, q), atol=1e-12)


def test_kinematic_floor_poses_meet_the_foot_constraints():
    clearance, depth = 0.002, fidelity.STANCE_DEPTH
    table, poses = fidelity.kinematic_floor(n=20, clearance=clearance)
    gait = data_mod.load_gait_data("Free")
    model = ChildModel()
    tau = poses.index.to_numpy()
    swing = {s: data_mod.in_window(tau, data_mod.swing_windows(gait.events, gait.left_shift)[s]) for s in cv.SIDES}
    k = len(cv.ELLIPSOIDS)
    checked = {"swing": 0, "stance": 0}
    for i, q in enumerate(poses.to_numpy()):
        b = kinematics.ellipsoid_bottoms(model, q)
        for j, s in enumerate(cv.SIDES):
            foot = b[j * k:(j + 1) * k]
            if swing[s][i]:
                assert foot.min() >= clearance - 1e-7
                checked["swing"] += 1
            elif fidelity._stance(tau[i:i + 1], gait, s)[0]:
                assert -depth[1] - 1e-7 <= foot.min() <= -depth[0] + 1e-7
                checked["stance"] += 1
    assert checked["swing"] > 0 and checked["stance"] > 0
    # the HAT's horizontal position and tilt are held at the reference
    ref = gait_ocp.reference(gait, model)
    T = gait.cycle_time
    np.testing.assert_allclose(poses["pelvis_tilt"], 0.0, atol=1e-12)
    np.testing.assert_allclose(poses["pelvis_tx"], np.interp(tau * T, ref.q.index, ref.q["pelvis_tx"], period=T))
    assert list(table.index) == list(gait_ocp.LEG_JOINTS)
    assert (table["largest change (deg)"] >= table["RMSE (deg)"] - 1e-12).all()
