"""Ch 6/7 references: the Ch 5 HAT motion as the HAT term's reference (Eq 6.4) and the
natural-speed data scaled in time to another speed class (Eqs 7.1–7.2)."""

import numpy as np
import pytest

from gaitlib import data
from gaitlib.problems import gait as gait_ocp

COARSE = dict(model="SK", cost="DT", n_intervals=8, degree=3)


def test_time_scaled_keeps_magnitudes_and_takes_target_timing():
    free, slow = data.load_gait_data("Free"), data.load_gait_data("VerySlow")
    g = data.time_scaled(free, slow)
    assert g.cycle_time == slow.cycle_time and g.speed == slow.speed
    k = slow.cycle_time / free.cycle_time
    # the same curve value at the scaled instant, for every channel
    t = np.linspace(0, free.cycle_time, 37)[:-1]
    np.testing.assert_allclose(g.at(t * k).to_numpy(), free.at(t).to_numpy(), atol=1e-12)
    np.testing.assert_allclose(g.sd.to_numpy(), free.sd.to_numpy())
    assert g.events == free.events
    with pytest.raises(data.DataError):
        data.time_scaled(free, data.load_gait_data("Free", "gaitutils"))


@pytest.fixture(scope="module")
def coarse_sk(tmp_path_factory):
    root = tmp_path_factory.mktemp("sol")
    sol = gait_ocp.solve_cached(gait_ocp.GaitSpec(**COARSE), root=root)
    assert sol.stats["status"] == "Solve_Succeeded"
    return sol, root


def test_hat_reference_reproduces_the_solution_hat(coarse_sk):
    sol, _ = coarse_sk
    h = gait_ocp.hat_reference_of(sol)
    gp = gait_ocp.build(gait_ocp.GaitSpec(**COARSE, hat_reference=h))
    T = gp.ref.gait.cycle_time
    t = sol.q.index.to_numpy()
    ref = gp.ref.q
    for c, tol in (("pelvis_ty", 1e-3), ("pelvis_tilt", 0.1 * np.pi / 180), ("pelvis_tx", 1e-3)):
        r = np.interp(t, ref.index.to_numpy(), ref[c].to_numpy())
        assert np.max(np.abs(r - sol.q[c].to_numpy())) < tol, c
    # the tracked data frame carries it on normalised time
    d = gp.problem.phases[0].data
    np.testing.assert_allclose(d["ref_pelvis_ty"].to_numpy(), ref["pelvis_ty"].to_numpy())
    assert np.isclose(d.index[-1], ref.index[-1] / T)
    # JSON round trip keeps the key
    sp = gait_ocp.GaitSpec(**COARSE, hat_reference=h)
    assert gait_ocp.GaitSpec.from_dict(sp.to_dict()).key() == sp.key()


def test_track_class_solves_at_the_target_timing_on_scaled_data(coarse_sk):
    _, root = coarse_sk
    sp = gait_ocp.GaitSpec(**COARSE, speed_class="Slow", track_class="Free")
    gp = gait_ocp.build(sp)
    slow, free = data.load_gait_data("Slow"), data.load_gait_data("Free")
    # tracked: Free's knee torque on normalised time; never Slow's
    d = gp.problem.phases[0].data
    np.testing.assert_allclose(d["ref_tau_knee_r"].to_numpy(), free.mean["tau_knee_r"].to_numpy())
    assert not np.allclose(d["ref_tau_knee_r"].to_numpy(), np.interp(
        d.index.to_numpy() * slow.cycle_time, slow.time, slow.mean["tau_knee_r"].to_numpy()))
    sol = gait_ocp.solve_cached(sp, root=root)
    assert sol.stats["status"] == "Solve_Succeeded"
    assert np.isclose(sol.stats["tf_s"], slow.cycle_time)
    # the pelvis advances one Slow stride per cycle (periodic offset)
    ph = sol.solution.phase("cycle")
    x = ph.states["pelvis_tx"]
    v_mean = (x.iloc[-1] - x.iloc[0]) / (x.index[-1] - x.index[0])
    assert abs(v_mean - slow.speed) < 0.25 * slow.speed
    with pytest.raises(ValueError):
        gait_ocp.GaitSpec(**COARSE, track_class="Jogging")
