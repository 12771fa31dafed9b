"""Ch 6/7 study (gaitlib.studies.predictive): guesses, specs and scoring, on coarse meshes."""

import dataclasses

import numpy as np
import pandas as pd
import pytest

from gaitlib import data
from gaitlib.problems import gait as gait_ocp
from gaitlib.studies import fidelity
from gaitlib.studies import gait as sg
from gaitlib.studies import predictive as pr

MESH = dict(n_intervals=5, degree=3)


@pytest.fixture(scope="module")
def root(tmp_path_factory):
    return tmp_path_factory.mktemp("sol")


@pytest.fixture(scope="module")
def base(root):
    b = pr.baseline("MSK", root=root, **MESH)
    assert b.stats["status"] == "Solve_Succeeded"
    return b


def test_specs_follow_tables_6_2_and_7_1(base):
    s6 = pr.ch6_specs("MSK", base, **MESH)
    assert list(s6) == [f"MSK {c}" for c in pr.CH6_COSTS]
    fp = s6["MSK FP"].term_weights
    assert not {"Trq", "Ang", "GRF", "Q"} & set(fp) and fp["HAT"] == 1 / 4 and fp["Imp"] == 1 / 4
    assert s6["MSK DT"].term_weights == gait_ocp.COST_FUNCTIONS["MSK"]["DT"]
    s7 = pr.ch7_specs("MSK", base, **MESH)
    for name, sp in s7.items():
        assert sp.cost == "DT" and sp.track_class == "Free" and sp.speed_class == name.split()[1]
        assert sp.hat_reference == s6["MSK DT"].hat_reference


def test_thesis_guess_keeps_only_hat_mtp_and_activations(base):
    g = pr.thesis_guess(base)
    ph = g.phase("cycle")
    assert set(ph.states.columns) == {f"{p}{c}" for p in ("", "qd_", "qdd_")
                                      for c in ("pelvis_tx", "pelvis_ty", "pelvis_tilt", "mtp_r", "mtp_l")}
    assert set(ph.controls.columns) == set(gait_ocp.MTG_CONTROLS) | {"tau_mtp_r", "tau_mtp_l"}
    assert g.parameters == {}


def test_time_scaled_guess_is_a_consistent_trajectory(base):
    """Scaling time by k divides velocities by k and accelerations by k² — the scaled
    positions' derivative is the scaled velocity — and the pelvis advances one target stride."""
    slow = data.load_gait_data("VerySlow")
    stride = slow.speed * slow.cycle_time
    src = base.solution.phase("cycle").states
    ph = pr.thesis_guess(base, cycle_time=slow.cycle_time, stride=stride).phase("cycle")
    k = slow.cycle_time / base.solution.phase("cycle").tf
    assert ph.tf == pytest.approx(slow.cycle_time)
    np.testing.assert_allclose(ph.states.index, src.index * k)
    np.testing.assert_allclose(ph.states["qd_pelvis_ty"], src["qd_pelvis_ty"] / k)
    np.testing.assert_allclose(ph.states["qdd_mtp_r"], src["qdd_mtp_r"] / k**2)
    # mean horizontal speed of the guess = stride / cycle time
    x = ph.states["pelvis_tx"]
    s0 = data.load_gait_data("Free").speed * data.load_gait_data("Free").cycle_time
    np.testing.assert_allclose(x - x.iloc[0], (src["pelvis_tx"] - src["pelvis_tx"].iloc[0]) * stride / s0)


def test_guess_of_a_longer_legs_start_rescales_from_the_stride_it_walked(base):
    """A start solved on legs × 1.1 walks the longer legs' stride (speed and cycle time follow
    √(L1/L0), data.load_gait_data(leg_scale=)): rescaled to that same stride its pelvis path is
    unchanged (ratio 1), not stretched by the ratio to the book's legs' stride (≈ 1.1)."""
    legs = dataclasses.replace(base, spec=dataclasses.replace(base.spec, leg_scale=1.1))
    g = data.load_gait_data(base.spec.speed_class, leg_scale=1.1)
    src = base.solution.phase("cycle").states
    ph = pr.run_guess(legs, "ch5", stride=g.speed * g.cycle_time).phase("cycle")
    np.testing.assert_allclose(ph.states["pelvis_tx"], src["pelvis_tx"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(ph.states["qd_pelvis_tx"], src["qd_pelvis_tx"], rtol=0, atol=1e-12)


def test_full_guess_scales_every_state_and_control_consistently(base):
    """run_guess(…, "ch5"): all of the Ch 5 solution; in scaled time t' = k t the jerks are
    ÷ k³ (the horizontal pelvis jerk also × stride ratio), torques and activations unchanged."""
    slow = data.load_gait_data("VerySlow")
    stride = slow.speed * slow.cycle_time
    src = base.solution.phase("cycle")
    ph = pr.run_guess(base, "ch5", cycle_time=slow.cycle_time, stride=stride).phase("cycle")
    k = slow.cycle_time / src.tf
    s0 = data.load_gait_data("Free").speed * data.load_gait_data("Free").cycle_time
    assert list(ph.states.columns) == list(src.states.columns)
    assert list(ph.controls.columns) == list(src.controls.columns)
    np.testing.assert_allclose(ph.controls["jerk_knee_r"], src.controls["jerk_knee_r"] / k**3)
    np.testing.assert_allclose(ph.controls["jerk_pelvis_tx"], src.controls["jerk_pelvis_tx"] / k**3 * stride / s0)
    np.testing.assert_allclose(ph.states["qd_knee_r"], src.states["qd_knee_r"] / k)
    for c in ("tau_mtp_r", "R_y", gait_ocp.MTG_CONTROLS[0]):
        np.testing.assert_array_equal(ph.controls[c], src.controls[c])
    assert pr.GUESS_POLICY == {"MSK": "ch5", "NMSK": "ch5"}
    assert pr.GUESS_POLICY_CH7 == {"MSK": "thesis", "NMSK": "ch5"}
    # guesses derived differently from one solution are cached under different keys
    spec = pr.ch6_specs("MSK", base, ("DT",), **MESH)["MSK DT"]
    dirs = {gait_ocp.cache_dir(spec, guess=g) for g in (pr.run_guess(base, "thesis"), pr.run_guess(base, "ch5"),
                                                   pr.run_guess(base, "thesis", cycle_time=1.0, stride=1.0), base)}
    assert len(dirs) == 4
    assert gait_ocp.cache_dir(spec, guess=pr.run_guess(base, "ch5")) == gait_ocp.cache_dir(spec, guess=pr.run_guess(base, "ch5"))
    with pytest.raises(ValueError, match="guess must be"):
        pr.run_guess(base, "data")


def test_score_is_zero_against_its_own_channels_and_grows_with_an_offset(base):
    """score() of a solution against data built from that solution's own channels is 0;
    a constant offset of 5° on one angle gives RMSE 5° and NRMSE 5°/range on it only."""
    free = data.load_gait_data("Free")
    sim = sg.channels_frame(base)
    idx = pd.Index(sim.index.to_numpy() / base.stats["tf_s"] * free.cycle_time, name="time")
    mean = sim.set_axis(idx, axis=0)
    for s in "rl":  # score() converts data hip to thigh-in-lab by adding pelvic tilt: undo it
        mean[f"hip_{s}"] = mean[f"hip_{s}"] - mean["pelvis_tilt"]
    sd = mean * 0 + 1.0
    g = dataclasses.replace(free, mean=mean, sd=sd)
    sc = pr.score(base, g)
    assert sc["rmse"].abs().max() < 1e-9
    off = mean.copy()
    off["knee_r"] += np.deg2rad(5.0)
    sc2 = pr.score(base, dataclasses.replace(free, mean=off, sd=sd)).set_index(["kind", "channel", "side"])
    sc1 = sc.set_index(["kind", "channel", "side"])
    assert sc2.loc[("angle", "knee", "r"), "rmse"] == pytest.approx(5.0, abs=1e-9)
    diff = (sc2["rmse"] - sc1["rmse"]).drop(("angle", "knee", "r"))
    assert np.abs(diff).max() < 1e-9


def test_fully_predictive_fits_the_data_worse_than_data_tracking(base, root):
    """Direction of change: dropping the data terms (FP) cannot fit the data better than DT.
    Both start from the whole baseline solution (from the thesis's partial guess, DT at 5 x 3
    stopped at the iteration limit on an AVX2-only EPYC and converged elsewhere)."""
    specs = pr.ch6_specs("MSK", base, ("DT", "FP"), **MESH)
    sols = {k: gait_ocp.solve_cached(s, guess=pr.run_guess(base, "ch5"), root=root) for k, s in specs.items()}
    for s in sols.values():
        assert s.stats["status"] == "Solve_Succeeded"
    free = data.load_gait_data("Free")
    nr = {k: pr.score(s, free).groupby("kind")["nrmse"].mean() for k, s in sols.items()}
    assert nr["MSK DT"]["angle"] < nr["MSK FP"]["angle"]
    assert nr["MSK DT"]["torque"] < nr["MSK FP"]["torque"]
    assert set(sols["MSK FP"].solution.goals["goal"]) == {"Jrk", "Rsd", "Imp", "HAT", "Act"}


def test_reading_of_the_ch6_ch7_runs(monkeypatch):
    """The thesis's reading leaves every Ch 6/7 spec (hence every stored key) as it was; the
    book's adds the data's Jrk denominators everywhere and the swing bound wherever data time
    the swing (not FP)."""
    from gaitlib.problems import gait as gait_ocp
    from gaitlib.studies import predictive as pr
    monkeypatch.setattr(gait_ocp, "hat_reference_of", lambda base: ())
    for model in ("MSK", "NMSK"):
        old6 = {f"{model} {c}": gait_ocp.GaitSpec(model=model, cost=c, speed_class="Free", n_intervals=3, degree=2,
                                                  **({"excitation_guess": "emg"} if model == "NMSK" else {}))
                for c in pr.CH6_COSTS}
        assert pr.ch6_specs(model, None, n_intervals=3, degree=2) == old6
        book6 = pr.ch6_specs(model, None, n_intervals=3, degree=2, reading="book")
        for k, s in book6.items():
            assert s.jerk_ranges == "data"
            assert (s.swing_load_max is None) == (s.cost == "FP"), k
        book7 = pr.ch7_specs(model, None, n_intervals=3, degree=2, reading="book")
        assert all(s.swing_load_max > 0 and s.jerk_ranges == "data" for s in book7.values())
        assert all(s.swing_load_max is None for s in pr.ch7_specs(model, None, n_intervals=3, degree=2).values())
    # a field given explicitly wins over the reading's
    assert pr.ch7_specs("MSK", None, ("Fast",), n_intervals=3, degree=2, reading="book",
                        swing_load_max=1.0)["MSK Fast"].swing_load_max == 1.0


def test_cot_minimum_text_needs_every_speed():
    import pandas as pd
    from gaitlib.studies import predictive as pr
    full = pd.DataFrame({"mark": ["", "", ""], "speed (m/s)": [0.8, 1.2, 1.5], "COT (J/kg/m)": [2.0, 1.5, 1.8]},
                        index=["Slow", "Free", "Fast"])
    assert "a U-curve as the thesis reports" in pr._cot_minimum_text("Free", full)
    gap = pd.DataFrame({"mark": ["NOT CONVERGED: x", "", ""]}, index=["Slow", "Free", "Fast"])
    t = pr._cot_minimum_text("Free", gap)
    assert "not tested" in t and "Slow" in t and "as the thesis reports" not in t
    assert pr._cot_minimum_text("Fast", full).startswith("not at the natural speed")


def test_input_vs_class_control_by_hand():
    """The Ch 7 control (time-scaled Free data against a class's data): zero against itself;
    a constant c added to one torque channel of the class gives c / (that channel's range)
    / 6 (the mean over the six torque channels), computed here without the code under test."""
    from dataclasses import replace as _replace
    from gaitlib import data as data_mod
    free = data_mod.load_gait_data("Free")
    same = data_mod.time_scaled(free, free)
    for kind in ("angle", "torque", "grf"):
        assert pr._input_vs_class(same, free, kind) == pytest.approx(0.0, abs=1e-12)
    c = 3.0  # N·m on the right knee
    mean = free.mean.copy()
    mean["tau_knee_r"] = mean["tau_knee_r"] + c
    shifted = _replace(free, mean=mean)
    hand = c / float(mean["tau_knee_r"].max() - mean["tau_knee_r"].min()) / 6
    assert pr._input_vs_class(same, shifted, "torque") == pytest.approx(hand, rel=1e-9)
    assert pr._input_vs_class(same, shifted, "angle") == pytest.approx(0.0, abs=1e-12)


def test_loose_tracking_divides_the_three_data_terms_by_ten():
    dt = gait_ocp.COST_FUNCTIONS["NMSK"]["DT"]
    loose = dict(pr.LOOSE_TRACKING)
    assert set(loose) == {"Trq", "Ang", "GRF"}
    assert all(loose[k] == pytest.approx(dt[k] / 10) for k in loose)


def test_fp_may_be_timed_by_the_data_swing_but_not_with_a_free_final_time():
    """The FP-timed experiment: an FP spec accepts the swing bound (the data's event times,
    no curve tracked); a free final time has no data swing windows and is refused."""
    from gaitlib import validity
    b = validity.swing_bound()
    assert b == pytest.approx(0.01 * 41.4 * 9.81, abs=1e-3)
    s = gait_ocp.GaitSpec(model="MSK", cost="FP", swing_load_max=b)
    assert s.swing_load_max == b and "Ang" not in s.term_weights and "Trq" not in s.term_weights
    with pytest.raises(ValueError, match="fixed final time"):
        gait_ocp.GaitSpec(model="MSK", cost="FP", swing_load_max=b, tf_bounds=(0.8, 1.2))


def test_own_data_probe_tracks_each_class_and_keeps_the_baseline(monkeypatch):
    """consistent_speed_study(own_data=True): every class's run tracks its own data
    (track_class ""), the Ch 5 start is the one of the Free-input study (track_class never
    reaches the baseline), and the default study keeps tracking Free scaled in time."""
    pr_mod = pr
    seen = []

    def fake_baseline(model, **kw):
        seen.append(("baseline", kw))
        return None

    monkeypatch.setattr(pr_mod, "baseline", fake_baseline)
    monkeypatch.setattr(pr_mod, "run_guess", lambda *a, **kw: None)
    monkeypatch.setattr(pr_mod, "_run", lambda specs, guesses, **kw: (seen.append(("runs", specs)) or ({}, {})))
    monkeypatch.setattr(pr_mod, "_scores", lambda *a, **kw: None)
    monkeypatch.setattr(pr_mod.gait_ocp, "hat_reference_of", lambda base: ())
    fidelity.consistent_speed_study(own_data=True, progress=False)
    fidelity.consistent_speed_study(progress=False)
    (_, b_own), (_, own), (_, b_free), (_, free) = seen
    assert b_own == b_free and "track_class" not in b_own  # one Ch 5 start for both
    assert {k: s.track_class for k, s in own.items()} == {f"NMSK {c}": "" for c in pr_mod.cv.SPEED_CLASSES}
    assert {s.track_class for s in free.values()} == {"Free"}
    for k in own:  # the one change: the tracked data
        assert dataclasses.replace(own[k], track_class="Free") == free[k]


def test_ch7_runs_carry_activation_params_but_their_ch5_baseline_does_not(monkeypatch):
    """ch5_activation_speed_study: the Ch 5 NMSK baseline identifies its own γ (free_activation),
    so activation_params="ch5" reaches the four NMSK runs only (GaitSpec forbids both at once)."""
    from gaitlib.studies import predictive as pr_mod

    seen = {}

    def fake_baseline(model, **kw):
        seen["baseline"] = kw
        return "base"

    def fake_specs(model, base, classes, **kw):
        seen["runs"] = kw
        return {}

    monkeypatch.setattr(pr_mod, "baseline", fake_baseline)
    monkeypatch.setattr(pr_mod, "ch7_specs", fake_specs)
    monkeypatch.setattr(pr_mod, "_run", lambda specs, guesses, **kw: ({}, {}))
    monkeypatch.setattr(pr_mod, "_scores", lambda *a, **kw: None)
    pr_mod.ch5_activation_speed_study()
    assert "activation_params" not in seen["baseline"] and seen["baseline"]["reading"] == "book"
    assert seen["runs"]["activation_params"] == "ch5" and seen["runs"]["reading"] == "book"


def test_torque_gain_lines_by_hand(monkeypatch):
    """MSK torque NRMSE 0.10, NMSK 0.12 with Table 5.10's γ, 0.08 with ours: the NMSK gain is
    100 (1 − 0.12/0.10) = −20 % → 100 (1 − 0.08/0.10) = +20 %; a class with a marked run is skipped."""
    from types import SimpleNamespace

    from gaitlib.studies import predictive as pr_mod

    def sol(t, mark=""):
        return SimpleNamespace(t=t, mark=mark, spec=SimpleNamespace(source="x"))

    monkeypatch.setattr(pr_mod, "score", lambda s, g: pd.DataFrame({"kind": ["torque", "torque"], "nrmse": [s.t, s.t]}))
    monkeypatch.setattr(pr_mod.data_mod, "load_gait_data", lambda c, src: None)
    monkeypatch.setattr(pr_mod.marks, "failure_label", lambda s: s.mark)
    book = SimpleNamespace(solutions={"MSK Slow": sol(0.10), "NMSK Slow": sol(0.12),
                                      "MSK Fast": sol(0.10), "NMSK Fast": sol(0.12, "†")})
    ours = SimpleNamespace(solutions={"NMSK Slow": sol(0.08), "NMSK Fast": sol(0.08)})
    (line,) = pr_mod.torque_gain_lines(book, ours)
    assert "Slow -20 % → +20 % (thesis S: +12 %)" in line and "Fast" not in line


def test_guess_lines_count_converged_and_invalid_runs_per_start():
    from types import SimpleNamespace

    def study(rows):
        df = pd.DataFrame(rows, columns=["run", "mark", "status", "converged", "iterations"]).set_index("run")
        return SimpleNamespace(stats=lambda: df)

    a = study([("MSK DT", "", "Solve_Succeeded", True, 500), ("MSK SP3", "NOT CONVERGED", "Maximum_Iterations_Exceeded",
                                                              False, 1000),
               ("MSK FP", "INVALID: double support", "Solve_Succeeded", True, 900), ("NMSK DT", "", "x", False, 3)])
    b = study([("MSK DT", "", "Solve_Succeeded", True, 450), ("MSK SP3", "", "Solve_Succeeded", True, 201)])
    la, lb = pr.guess_lines({"partial": a, "whole": b}, "MSK")
    assert la == ("- partial: MSK 2 of 3 runs converged within 1000 iterations (500–900 iterations); not converged: "
                  "MSK SP3 (Maximum_Iterations_Exceeded); converged but invalid: MSK FP (INVALID: double support).")
    assert lb == "- whole: MSK 2 of 2 runs converged within 1000 iterations (201–450 iterations)."


def test_data_start_runs_rejects_an_unknown_start():
    with pytest.raises(ValueError, match="start must be one of"):
        pr.data_start_runs({}, "free data")


def _start_rows(rows):
    t = pd.DataFrame.from_dict(rows, orient="index", columns=["mark", "objective", "vs class data", "vs tracked input",
                                                              "cells closer than the input"])
    t.index = pd.MultiIndex.from_tuples(t.index, names=["class", "start"])
    return t


def test_start_findings_by_hand():
    """pr.start_findings: cells summed per start over unmarked runs; the per-class comparison
    only where the own and the probe start are both unmarked: objective change, NRMSE, cells;
    then where the probe's runs end (nearer the input or the class data)."""
    own, probe = pr.CH7_OWN_START, "class data"
    rows = {("Slow", own): ["", 0.30, 0.20, 0.10, 0], ("Slow", probe): ["", 0.15, 0.15, 0.10, 2],
            ("Fast", own): ["", 0.40, 0.30, 0.10, 1], ("Fast", probe): ["", 0.402, 0.20, 0.10, 1],
            ("VeryFast", own): ["", 0.50, 0.30, 0.10, 0], ("VeryFast", probe): ["NOT CONVERGED", 0.10, 0.10, 0.3, 3]}
    t = _start_rows(rows)
    out = pr.start_findings(t, own, probe)
    assert out[0].startswith(f"From {own}: closer to the class data than the scaled input in 1 of 9 cells;")
    assert "in 3 of 6 cells (left out, marked: VeryFast (NOT CONVERGED))" in out[1]
    assert "mean NRMSE against the class data 0.175" in out[1]  # (0.15 + 0.20) / 2
    assert "Slow: objective -50.0 %, NRMSE against the class data 0.200 → 0.150, cells closer 0 → 2" in out[2]
    assert "Fast: objective +0.5 %" in out[2] and "VeryFast" not in out[2]
    assert out[3].startswith("**Where the runs started on the class data end:** nearer the input they track than "
                             "the class data they started from in 2 of 2 (mean NRMSE 0.100 against 0.175)")
    assert "in 3 of 6 cells (1 from" in out[3]
    assert "in Slow they find a better optimum" in out[3] and "in Fast both starts end at the same objective" in out[3]
    assert out[3].endswith("the start does not explain the cells that stay near it.")
    # nothing comparable
    t2 = t.copy()
    t2["mark"] = ["", "x", "", "x", "", "x"]
    assert pr.start_findings(t2, own, probe)[-1].startswith("No class has both")
