"""The chapters' findings: numbers, verdicts and targets computed by study functions from
results (hand-built results here; nothing is solved)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from gaitlib import conventions as cv
from gaitlib.gap import diagnose as D
from gaitlib.gap import twin
from gaitlib.studies import contact_id as ci
from gaitlib.studies import gap as G
from gaitlib.studies import jump
from gaitlib.studies import msk
from gaitlib.studies import predictive as pr


# ------------------------------------------------------------------------------ Ch 5

def test_msk_angle_errors_find_the_largest_error_and_where():
    t = np.linspace(0.0, 1.0, 11)  # cycle 1 s → % of cycle = 100 t
    ref = {j: np.zeros_like(t) for j in ("hip_r", "knee_r", "ankle_r", "hip_l", "knee_l", "ankle_l")}
    q = pd.DataFrame({j: np.zeros_like(t) for j in ref}, index=t)
    q.loc[0.3, "knee_r"] = -10 * cv.DEG      # |error| 10 deg at 30 %
    q.loc[0.7, "hip_l"] = 25 * cv.DEG        # 25 deg at 70 %
    ref["ankle_r"] = np.full_like(t, 2 * cv.DEG)  # 2 deg everywhere: first maximum at 0 %
    e = msk.angle_errors(q, t, ref, cycle_time=1.0)
    assert list(e.index) == ["hip_r", "knee_r", "ankle_r", "hip_l", "knee_l", "ankle_l"]
    assert e.loc["knee_r", "max error (deg)"] == pytest.approx(10.0)
    assert e.loc["knee_r", "at (% cycle)"] == pytest.approx(30.0)
    assert e.loc["hip_l", "max error (deg)"] == pytest.approx(25.0)
    assert e.loc["hip_l", "at (% cycle)"] == pytest.approx(70.0)
    assert e.loc["ankle_r", "max error (deg)"] == pytest.approx(2.0)
    assert e.loc["ankle_r", "at (% cycle)"] == pytest.approx(0.0)
    assert e["max error (deg)"].idxmax() == "hip_l"


def test_msk_moved_parameters_and_short_generators():
    idx = pd.MultiIndex.from_tuples([("hip_ext", "s_tau"), ("hip_ext", "delta_P"), ("ankle_ext", "s_A")])
    tab = pd.DataFrame({"initial (Eq 5.22)": [1.0, 0.0, 1.0], "ours": [1.005, -0.5, 1.41]}, index=idx)
    moved = msk.moved_parameters(tab)  # tolerance 0.01: 0.005 stays, 0.5 and 0.41 move
    assert list(moved.index) == [("hip_ext", "delta_P"), ("ankle_ext", "s_A")]
    assert moved.tolist() == [-0.5, 1.41]
    margins = pd.DataFrame({("adult", "Eq 5.15"): {"ankle_ext": -20.2, "knee_ext": 3.0, "ankle_flex": -3.6},
                            ("adult", "Eq 5.16"): {"ankle_ext": 1.0, "knee_ext": -1.0, "ankle_flex": 1.0}})
    short = msk.short_generators(margins, "adult")
    assert short.to_dict() == {"ankle_ext": -20.2, "ankle_flex": -3.6}


def test_msk_text_helpers():
    assert msk.verdict_text({"success": True, "status": "Solve_Succeeded"}) == "converged"
    assert msk.verdict_text({"success": False, "status": "Maximum_Iterations_Exceeded"}) == \
        "did NOT converge (Maximum_Iterations_Exceeded)"
    assert msk.range_text([3.44, np.nan, 7.46, 5.0]) == "3.4–7.5"   # NaN skipped
    # Table 5.4 (MSK) angles: 0.6, 1.1, 1.0, 0.6, 1.2, 0.9 deg
    assert msk.thesis_rmse_range("MSK", "angle") == "0.6–1.2"


# ------------------------------------------------------------------------------ Ch 8: twins

def _twin_rows():
    """Six injected twins (four middle: three right; two small: one right) and two effect-free
    twins (one 'unexplained'), seeds 1 and 2."""
    r = [
        # twin, injected, level, seed, top, correct, shrink, shrink vs noise, rss_base, rss_true, dBIC_true, dBIC_top
        ("a@1#1", "a", 1, 1, "a", True, 80.0, 40.0, 100.0, 50.0, -30.0, -30.0),
        ("b@1#1", "b", 1, 1, "b", True, 150.0, 60.0, 100.0, 20.0, -50.0, -50.0),
        ("a@1#2", "a", 1, 2, "a", True, 40.0, 20.0, 100.0, 60.0, -20.0, -20.0),
        ("b@1#2", "b", 1, 2, "a", False, np.nan, np.nan, 100.0, 120.0, 5.0, -15.0),
        ("a@0#1", "a", 0, 1, "unexplained", False, 10.0, 5.0, 100.0, 95.0, -12.0, np.nan),
        ("b@0#2", "b", 0, 2, "b", True, 50.0, 30.0, 100.0, 70.0, -14.0, -14.0),
        ("none#1", "none", 0, 1, "unexplained", True, np.nan, np.nan, 10.0, np.nan, np.nan, np.nan),
        ("none#2", "none", 0, 2, "a", False, np.nan, np.nan, 30.0, np.nan, np.nan, -11.0),
    ]
    cols = ["twin", "injected", "level", "seed", "top", "correct", "shrink_injected_top", "shrink_vs_noise_top",
            "rss_base", "rss_true", "dBIC_true", "dBIC_top"]
    rows = pd.DataFrame(r, columns=cols)
    rows["base_start"] = ["best", "best", "moved", "best", "best", "best", "best", "moved"]
    rows["retried"] = [0, 2, 0, 1, 0, 0, 0, 0]
    rows["true_start"] = [None, "moved", None, "best", None, None, None, None]
    rows["rss_true_fixed"] = rows["rss_base"] / 2
    rows["rss_gen"] = 10.0
    # the best ΔBIC among the other ranked candidates (the runner-up margin's comparison)
    rows["dBIC_best_other"] = [0.0, 0.0, 0.0, -15.0, 0.0, 0.0, np.nan, -11.0]
    gen = {k: {"status": "Solve_Succeeded" if k != "x" else "Infeasible_Problem_Detected"} for k in "abcx"}
    return twin.TwinValidation(rows, {}, gen, {"effects": ("a", "b")})


def test_twin_summary_numbers_and_verdicts():
    s = _twin_rows().summary()
    assert (s["twins"], s["injected"], s["free_twins"], s["free_unexplained"]) == (8, 6, 2, 1)
    assert (s["gen_converged"], s["gen_total"]) == (3, 4)
    assert s["top1_pct"] == pytest.approx(75.0)                        # 3 of 4 middle twins
    assert s["top1_by_seed"] == pytest.approx({1: 200 / 3, 2: 200 / 3})  # 2 of 3 injected twins per seed
    assert s["correct"] == 4
    # shrink over all magnitudes, capped at 100: (80 + 100 + 40 + 10 + 50) / 5 = 56; uncapped 66
    assert s["shrink_pct"] == pytest.approx(56.0)
    assert s["shrink_uncapped_pct"] == pytest.approx(66.0)
    assert s["shrink_median_pct"] == pytest.approx(50.0)
    assert s["shrink_defined"] == 5
    assert s["shrink_vs_noise_pct"] == pytest.approx(31.0)            # (40 + 60 + 20 + 5 + 30) / 5
    assert not s["top1_met"] and not s["shrink_met"] and not s["passed"]
    assert s["base_starts"] == {"best": 6, "moved": 2}
    assert (s["retried_twins"], s["retried_fits"], s["true_other_start"]) == (2, 3, 1)


def test_twin_targets_decide_the_verdict():
    tv = _twin_rows()
    tv.rows["correct"] = True                 # every twin right, every free twin 'unexplained'
    tv.rows["shrink_injected_top"] = tv.rows["shrink_injected_top"].clip(lower=twin.TARGET_SHRINK_PCT)
    s = tv.summary()
    assert s["top1_pct"] == 100.0 >= twin.TARGET_TOP1_PCT
    assert s["shrink_met"] and s["top1_met"] and s["passed"]
    tv.rows.loc[tv.rows["twin"] == "none#2", "correct"] = False  # one free twin misnamed: not passed
    assert not tv.summary()["passed"]


def test_twin_misses_say_why():
    w = _twin_rows().misses().set_index("twin")
    assert list(w.index) == ["b@1#2", "a@0#1", "none#2"]
    assert w.loc["b@1#2", "fit_failed"]          # its own fit (120) ends above the baseline's (100)
    assert not w.loc["a@0#1", "fit_failed"]
    assert not w.loc["none#2", "fit_failed"]     # nothing injected
    # true model named only if ΔBIC ≤ threshold and below the named effect's
    assert w.loc["b@1#2", "true_not_named"]      # +5 is above the threshold
    assert not w.loc["a@0#1", "true_not_named"]  # −12 ≤ −10, and 10 below the best other (0)
    assert D.BIC_THRESHOLD == -10.0
    # with another candidate within the runner-up margin (−5 > −12 + 10), it would not be named
    tv = _twin_rows()
    tv.rows.loc[tv.rows["twin"] == "a@0#1", "dBIC_best_other"] = -5.0
    assert D.RUNNER_UP_MARGIN == 10.0
    assert tv.misses().set_index("twin").loc["a@0#1", "true_not_named"]


def test_twin_full_mesh_text():
    tv = _twin_rows()
    head, *miss = G.twin_full_mesh_lines(tv)
    assert head.startswith("20 × 5 mesh, middle magnitude: top-1 accuracy 75 % (4 of 6; seed 1: 67 %, seed 2: 67 %)")
    assert "effect-free twin named 'unexplained': 1 of 2; twin generation 3 of 4 converged" in head
    assert len(miss) == 3 and miss[2].startswith("none#2: named a (ΔBIC -11.0) on a baseline fit with RSS 30.0, 3.0×")
    v = G.twin_full_mesh_verdict(tv)
    assert v[0].startswith("Baseline fits kept, by start: best 6, moved 2. Twins with at least one candidate "
                           "re-solved from another start: 2 of 8 (3 candidate fits)")
    assert "is **not passed** (75 % top-1 at the middle magnitude, target ≥ 90 %; 56 % mean shrink, target ≥ 60 %" in v[1]
    assert "The miss b@1#2 (named a): its own candidate fit ends above the baseline's" in v[2]
    assert "The miss a@0#1 (named unexplained): its own fit closes less" in v[3]


# ------------------------------------------------------------------------------ Ch 8: real data

def test_left_leg_flips():
    r = pd.DataFrame({"effect": ["a", "b", "c"], "% closed (data as tracked)": [20.0, 4.0, 6.0],
                      "% closed (left leg shifted exactly)": [-1.0, -3.0, 2.0]})
    assert G.left_leg_flips({"ranking": r}) == ["a"]   # b closes < 5 % as tracked; c still closes 2 %
    assert G.left_leg_flips({"ranking": pd.DataFrame()}) == []


def test_co_contraction_text():
    emg = pd.DataFrame([
        {"model": "baseline", "parameters": "", "status": "Solve_Succeeded", "RSS TA": 300.0, "RSS MG": 100.0,
         "mean z TA": -2.04, "mean z MG": 1.5},
        {"model": "co_contraction", "parameters": "c = 0.3", "status": "Solve_Succeeded", "RSS TA": 100.0,
         "RSS MG": 60.0, "mean z TA": -0.5, "mean z MG": 0.2}])
    diag = SimpleNamespace(ranking=pd.DataFrame({"effect": ["co_contraction"], "pct_closed": [12.4], "dBIC": [-40.2]}),
                           top_effect="co_contraction", verdict="named")
    t = G.co_contraction_text(diag, emg)
    assert "the TA excitation is on average 2.0 SD below its EMG and the MG/GAM excitation 1.5 SD above" in t
    assert "changes the TA + MG RSS from 400 to 160 (60 % closed) and the whole gap by 12 % (ΔBIC = -40)" in t
    assert "co-contraction **does** close most" in t          # 160 < 0.5 × 400
    assert t.endswith("The NMSK diagnosis names **co_contraction** (named).")
    emg.loc[1, "RSS TA"] = 250.0                                # 310 ≥ 200: does not close most
    assert "does **not** close" in G.co_contraction_text(diag, emg)
    emg.loc[1, "RSS TA"] = np.nan
    assert G.co_contraction_text(diag, emg) is None


def test_msk_diagnosis_text():
    rk = pd.DataFrame({"rank": [1, 2, 3, 4, np.nan], "effect": ["joint_stiffness", "activation_timing", "arm_swing",
                                                                 "co_contraction", "friction"],
                       "pct_closed": [33.6, 31.5, 4.6, -12.1, np.nan], "dBIC": [-143.7, -132.5, -11.4, 47.6, np.nan],
                       "status": ["Solve_Succeeded", "Solve_Succeeded (comparison only)", "Solve_Succeeded",
                                  "Solve_Succeeded", "located gap above the baseline's (Solve_Succeeded)"]})
    fit = SimpleNamespace(profile=[(-0.5, 1614.7, "ok"), (1.0, 3880.2, "ok"), (2.0, 4564.0, "ok")])
    diag = SimpleNamespace(ranking=rk, verdict="partial", top_effect="joint_stiffness", fits={"joint_stiffness": fit})
    t = G.msk_diagnosis_text(diag)
    assert t.startswith("**The Ch 5 MSK solution, the library's 5 candidates.** Verdict **partial**, top effect "
                        "joint_stiffness (its best magnitude, -0.5, is the lowest point of its profile grid -0.5, 1, 2")
    assert ("closing the most: joint_stiffness 33.6 % (ΔBIC -144), activation_timing 31.5 % (ΔBIC -132, comparison "
            "only), arm_swing 4.6 % (ΔBIC -11). 1 ranked candidate(s) widen the gap; 1 end above") in t
    prof = pd.DataFrame({"magnitude": [0.0, -0.5, -0.9], "status": ["Solve_Succeeded"] * 3,
                         "RSS": [2432.0, 1615.0, 1405.0], "% closed": [0.0, 33.6, 42.2],
                         "EMG share of the closed gap (%)": [np.nan, 99.5, 99.57]})
    # the grid's own point (-0.5) and the baseline are not "beyond the grid"
    assert G.msk_diagnosis_text(diag, profile=prof).endswith(
        " Beyond the grid (outside the frozen method): -0.9 closes 42.2 % (99.6 % of that in the EMG channels).")
    fit.profile = [(-0.5, 3000.0, "ok"), (1.0, 1000.0, "ok"), (2.0, 4564.0, "ok")]  # interior best: no caveat
    assert "profile grid" not in G.msk_diagnosis_text(diag)


# ------------------------------------------------------------------------------ Ch 3

def _jump_sol(label, rise, mu, knee_min_deg, tau_knee, success=True):
    t = pd.DataFrame({"knee": np.radians([0.0, knee_min_deg, 0.0]), "tau_knee": tau_knee,
                      "grf_y": [0.0, 2 * 10.0 * cv.G, 0.0]})
    return SimpleNamespace(spec=SimpleNamespace(label=label), success=success,
                           stats={"success": success, "status": "Solve_Succeeded" if success else "Infeasible",
                                  "iterations": 10, "solve_time_s": 1.0},
                           jump_height={"com_rise_flight": rise, "takeoff_vy": 1.0, "foot_lift": rise},
                           required_friction=mu, trajectory=t,
                           model=SimpleNamespace(joints=("knee",), total_mass=10.0),
                           solution=SimpleNamespace(info={}))


def test_jump_torques_at_bound_either_sign():
    lo, hi = jump.joint_bounds("knee")["tau"]
    near = _jump_sol("x", 0.1, 1.0, -90, [0.0, 0.995 * hi, 0.0])
    far = _jump_sol("x", 0.1, 1.0, -90, [0.0, 0.98 * hi, 0.5 * lo])
    neg = _jump_sol("x", 0.1, 1.0, -90, [0.0, 0.0, 0.999 * lo])
    assert jump.torques_at_bound(near) == ["knee"]
    assert jump.torques_at_bound(far) == []
    assert jump.torques_at_bound(neg) == ["knee"]


def test_jump_findings_order_and_friction_verdicts():
    sols = {"toeless": _jump_sol("A", 0.10, 1.5, -90, [0, 100.0, 0]),
            "toe": _jump_sol("B", 0.50, 1.0, -120, [0, 200.0, 0]),
            "ellipsoid": _jump_sol("C", 0.30, 0.5, -140, [0, 300.0, 0], success=False)}
    params = np.zeros(39)
    params[[2, 15, 28]] = (0.4, 0.9, 0.6)          # μ_s of the three ellipsoids
    f = jump.findings(sols, params)
    assert f[0].startswith("A: converged in 10 iterations, 1 s. COM rise in flight 10 cm")
    assert "— thesis 14 cm; required μ_s 1.50 — thesis 1.4; deepest knee -90° — thesis -94°." in f[0]
    assert f[2] == "C: did NOT converge (Infeasible) in 10 iterations, 1 s. COM rise in flight 30 cm (take-off v_y " \
                   "1.00 m/s), MTP lift 30 cm — thesis 89 cm; required μ_s 0.50 — thesis 0.12; deepest knee -140° — " \
                   "thesis -150°."
    assert f[3].startswith("NOT every solve converged")
    assert f[4] == "Order of jump heights (COM rise): toeless < ellipsoid < toe; thesis: toeless < toe < ellipsoid " \
                   "— a DIFFERENT order."
    assert f[5] == "Our COM rise ÷ the thesis's jump height: toeless 0.7×, toe 0.8×, ellipsoid 0.3×"
    assert "the ellipsoid contact needs LESS than either welded contact" in f[6]
    assert f[6].endswith("Largest μ_s of its ellipsoids: 0.90.")
    assert f[7].startswith("Largest joint torque: toeless 100 N·m, toe 200 N·m, ellipsoid 300 N·m")
    assert "peak F_y toeless 2.0×, toe 2.0×, ellipsoid 2.0× the body weight." in f[7]
    assert f[8] == "Joint torques at (≥ 99 % of) their Table 3.5 bound: toeless: none; toe: none; ellipsoid: none."


# ------------------------------------------------------------------------------ Ch 4

def test_contact_ranking():
    fit = pd.DataFrame({"mean GRF RMSE (N)": [30.0, 12.0, 20.0]},
                       index=[ci.APPROACHES["a"], ci.APPROACHES["b"], ci.APPROACHES["c"]])
    assert ci.ranking(fit) == ["(b)", "(c)", "(a)"]
    fit.iloc[1, 0] = 25.0
    assert ci.ranking(fit) == list(ci.THESIS_RANKING)


# ------------------------------------------------------------------------------ Ch 6 and 7

def _scores(rows):
    return pd.DataFrame(rows, columns=["model", "case", "kind", "nrmse", "rmse"])


def test_mean_nrmse_weighs_kinds_equally():
    sc = _scores([("MSK", "DT", "angle", 0.1, 1.0), ("MSK", "DT", "angle", 0.3, 1.0),   # angle mean 0.2
                  ("MSK", "DT", "torque", 0.4, 1.0), ("MSK", "DT", "grf", 0.6, 1.0),
                  ("MSK", "DT", "excitation", 9.0, 9.0)])                              # not a headline kind
    assert pr.kind_nrmse(sc).loc[("MSK", "DT"), "angle"] == pytest.approx(0.2)
    assert pr.mean_nrmse(sc)[("MSK", "DT")] == pytest.approx((0.2 + 0.4 + 0.6) / 3)


def _study(stats, scores, marks_, guess=None):
    return SimpleNamespace(stats=lambda: stats, marks=lambda: marks_, converged_scores=lambda: scores,
                           guess=guess or {"MSK": "ch5", "NMSK": "ch5"})


def test_ch6_findings_verdicts():
    runs = [f"{m} {c}" for m in ("MSK", "NMSK") for c in ("DT", "SDT3", "FP")]
    stats = pd.DataFrame({"converged": True, "status": "Solve_Succeeded",
                          "solve (s)": [10.0, 20.0, 30.0, 40.0, 50.0, 25.0]}, index=runs)
    rows = []
    for (m, c), v in {("MSK", "DT"): 0.2, ("MSK", "SDT3"): 0.3, ("MSK", "FP"): 0.5,
                      ("NMSK", "DT"): 0.25, ("NMSK", "SDT3"): 0.27, ("NMSK", "FP"): 0.4}.items():
        rows += [(m, c, k, v, v) for k in ("angle", "torque", "grf")]
    rows += [("NMSK", "DT", "excitation", np.nan, 0.5), ("NMSK", "FP", "excitation", np.nan, 0.3)]
    tg = pd.DataFrame({"status": ["Solve_Succeeded", "Maximum_Iterations_Exceeded"]}, index=["NMSK DT", "NMSK FP"])
    f = pr.ch6_findings(_study(stats, _scores(rows), {r: None for r in runs}), tg, {}, None)
    assert f[0].startswith("- 6 of 6 runs converged (IPOPT Solve_Succeeded). IPOPT solve time per run 10–50 s here")
    assert f[0].endswith("(Table 6.3). The runs of MSK and NMSK start from the whole Ch 5 solution of their model; "
                         "from the thesis's partial guess 1 of 2 NMSK runs converged "
                         "(not: NMSK FP Maximum_Iterations_Exceeded).")
    assert f[1] == "- Mean NRMSE over angles, torques and forces: MSK DT 0.200 → FP 0.500; NMSK DT 0.250 → FP 0.400."
    assert f[2].startswith("- NMSK is more accurate than MSK (mean NRMSE) for SDT3, FP (of 3 cost functions where both "
                           "runs converged and pass the validity gates; not compared: SDT1, SDT2, SP1, SP2, SP3); the "
                           "thesis")
    assert "*NMSK FP more accurate than MSK FP*: holds on our data (0.400 vs 0.500)" in f[3]
    assert "*NMSK FP faster than MSK FP*: holds (25 s vs 30 s)." in f[3]  # both from the same start
    mixed = pr.ch6_findings(_study(stats, _scores(rows), {r: None for r in runs}, {"MSK": "thesis", "NMSK": "ch5"}),
                            tg, {}, None)
    assert "holds (25 s vs 30 s; not a like-for-like comparison: the MSK runs start from the thesis's partial " \
           "guess; the NMSK runs start from the whole Ch 5 solution)." in mixed[3]
    assert "The MSK runs start from the thesis's partial guess; the NMSK runs start from the whole Ch 5 " \
           "solution; from the thesis's partial guess 1 of 2 NMSK runs" in mixed[0]
    # SDT3 0.27 ≤ 1.1 × 0.25 = 0.275: holds
    assert f[4] == "- Thesis claim *SDT3 (Trq + Ang) is enough for NMSK*: NMSK SDT3 mean NRMSE 0.270 vs DT 0.250 — " \
                   "holds (within 10 %)."
    assert f[5].startswith("- Excitation RMSE vs EMG (mean over mapped muscles, converged and valid NMSK runs): best FP "
                           "0.300, "
                           "worst DT 0.500; FP 0.300 vs DT 0.500 (thesis: FP 12 % better than DT).")


def test_ch7_findings_verdicts():
    classes = ("Slow", "Fast")
    runs = [f"{m} {c}" for m in ("MSK", "NMSK") for c in classes]
    stats = pd.DataFrame({"converged": [True, True, True, False],
                          "status": ["Solve_Succeeded"] * 3 + ["Maximum_Iterations_Exceeded"],
                          "solve (s)": [10.0, 20.0, 30.0, 40.0]}, index=runs)
    rows = []
    for (m, c), (a, t, g) in {("MSK", "Slow"): (0.2, 0.3, 0.2), ("MSK", "Fast"): (0.2, 0.3, 0.2),
                              ("NMSK", "Slow"): (0.1, 0.2, 0.4)}.items():   # NMSK Fast: not converged
        rows += [(m, c, "angle", a, a), (m, c, "torque", t, t), (m, c, "grf", g, g)]
    control = pd.DataFrame({"angle": [0.15, 0.1], "torque": [0.25, 0.2], "grf": [0.3, 0.3]}, index=list(classes))
    cot = pd.DataFrame({"mark": ["", "", "", "NOT CONVERGED: x"], "COT (J/kg/m)": [2.0, 1.5, 1.6, 3.0],
                        "speed (m/s)": [0.8, 1.2, 1.2, 1.5]}, index=["Slow", "Free", "Ch5", "Fast"])
    f = pr.ch7_findings(_study(stats, _scores(rows), {}), classes, control, cot, {}, "Ch5")
    assert f[0] == "- 3 of 4 runs converged; not converged: NMSK Fast (Maximum_Iterations_Exceeded); IPOPT solve " \
                   "time 10–40 s per run here vs 4–18 h in the thesis (Table 7.2)."
    assert f[1].startswith("- Torque NRMSE: NMSK below MSK for Slow of the 1 classes where both runs converged and pass "
                           "the validity gates (not compared: Fast)")
    # NMSK Slow beats the control in angle (0.1 < 0.15) and torque (0.2 < 0.25), not GRF (0.4 > 0.3)
    assert f[2] == "- The converged NMSK predictions are closer to the untracked class data than the scaled Free data " \
                   "they tracked in 2 of 3 class × kind cells (Fast left out: not converged)."
    assert len(f) == 3          # two converged points on the curve: fewer than COT_CURVE_MIN_POINTS, no COT claim
    cot.loc["Fast", "mark"] = ""
    f = pr.ch7_findings(_study(stats, _scores(rows), {}), classes, control, cot, {}, "Ch5")
    assert f[3].startswith("- COT (NMSK DT, converged runs; Free = the Ch 6 NMSK DT run): Slow 2.00, Free 1.50, Fast "
                           "3.00 J/(kg·m); minimum at Free (the natural speed — a U-curve as the thesis reports). "
                           "Thesis (Fig 7.5): 2.18, 1.99, 1.53, 1.96, 1.99 at XS, S, N, M, L.")
    assert f[3].endswith("The Ch 5 NMSK solution (Eq 5.55, its own activation parameters) has 1.60; it is not on the curve.")
    # minimum at Free but a step the wrong way after it: not a U
    cot.loc["VeryFast"] = ["", 2.5, 1.9]
    f = pr.ch7_findings(_study(stats, _scores(rows), {}), classes, control, cot, {}, "Ch5")
    assert "minimum at Free (the natural speed, but not a U: the COT moves the wrong way between Fast 3.00 → " \
           "VeryFast 2.50)." in f[3]
    assert pr.u_breaks({"a": (1.0, 3.0), "b": (2.0, 2.0), "c": (3.0, 2.5)}) == []
    assert pr.u_breaks({"a": (1.0, 3.0), "b": (2.0, 3.5), "c": (3.0, 2.0)}) == ["a 3.00 → b 3.50"]


def test_mesh_verdict_says_whether_the_real_data_verdict_depends_on_the_mesh():
    import pandas as pd
    from gaitlib.studies import gap as gs

    def table(top2, verdict2="partial"):
        return pd.DataFrame({"verdict": ["partial", verdict2], "top effect": ["left_shift", top2],
                             "best candidate": ["left_shift", top2], "its ΔBIC": [-21.7, -14.0]},
                            index=pd.Index(["10 × 3", "20 × 5"], name="mesh"))

    same = gs.mesh_verdict(table("left_shift"), -10)
    assert same.startswith("**The real-data verdict does not depend on the mesh**")
    other = gs.mesh_verdict(table("arm_swing"), -10)
    assert other.startswith("**The real-data verdict depends on the mesh**")
    assert "top arm_swing" in other and "ΔBIC -14.0" in other and "not measured" in other
    assert gs.mesh_verdict(table("left_shift", "explained"), -10).startswith("**The real-data verdict depends")
    # with the null draws: how often the verdict changed at one mesh, the candidates' ΔBIC spread
    from gaitlib.gap import validate as V

    null = V.Validation(pd.DataFrame([
        {"set": "null", "named": "unexplained", "rss_baseline": 100.0, "dBIC": {"a": -20.0, "b": -2.0}},
        {"set": "null", "named": "a", "rss_baseline": 100.0, "dBIC": {"a": -30.0, "b": 2.0}},
        {"set": "null", "named": "b", "rss_baseline": 100.0, "dBIC": {"a": -25.0, "b": 0.0}},
    ]), {"named": "unexplained", "rss_baseline": 100.0, "dBIC": {}}, {})
    t = gs.mesh_verdict(table("arm_swing"), -10, null)
    assert "changed it in 2 of 3 draws" in t and "SD of 2.0–5.0" in t and "not measured" not in t.split("chapter's.")[0]


def test_ch5_profile_rows_and_emg_share(monkeypatch):
    """The profile's % closed and the EMG channels' share of it, on hand-made located gaps."""
    base = SimpleNamespace(spec=SimpleNamespace(speed_class="Free", source="schwartz2008"),
                           stats={"status": "Solve_Succeeded"})
    sol = SimpleNamespace(stats={"status": "Solve_Succeeded", "effects": {"joint_stiffness": {"k": -0.7}}})
    monkeypatch.setattr(G.msk, "solve", lambda model, **kw: base)
    monkeypatch.setattr(G.gio, "load_real", lambda *a: SimpleNamespace(gait="g"))
    monkeypatch.setattr(G.diagnose, "with_effects", lambda spec, eff: ("spec", eff))
    monkeypatch.setattr(G, "solve_many", lambda groups, **kw: {"data|joint_stiffness@-0.7": sol})

    def loc(s, ds, thetas=None):
        rss = {"emg:TA_r": 100.0, "angle:knee_r": 50.0} if s is base else {"emg:TA_r": 40.0, "angle:knee_r": 30.0}
        return SimpleNamespace(rss=sum(rss.values()),
                               channels=pd.DataFrame({"channel": list(rss), "rss": list(rss.values())}))

    monkeypatch.setattr(G.locate, "locate", loc)
    t = G.ch5_profile("MSK", "joint_stiffness", (-0.7,))
    assert list(t["magnitude"]) == [0.0, -0.7]
    # 150 → 70: 53.3 % closed, of which the EMG's 60 of 80 = 75 %
    assert t["% closed"].iloc[1] == pytest.approx(100 * 80 / 150)
    assert t["EMG share of the closed gap (%)"].iloc[1] == pytest.approx(75.0)


def test_thesis_guess_runs_beside_the_page_runs():
    def st(status):
        idx = [f"{m} {c}" for m in ("MSK", "NMSK") for c in ("DT", "SP3")]
        return pd.DataFrame({"mark": ["" if s == "Solve_Succeeded" else "NOT CONVERGED" for s in status],
                             "status": status, "converged": [s == "Solve_Succeeded" for s in status],
                             "iterations": [300, 400, 500, 1000], "solve (s)": 1.0, "objective": 0.1,
                             "max violation": 0.0}, index=idx)

    page = SimpleNamespace(stats=lambda: st(["Solve_Succeeded"] * 4), guess={"MSK": "ch5", "NMSK": "ch5"})
    tg_msk = SimpleNamespace(stats=lambda: st(["Solve_Succeeded", "Maximum_Iterations_Exceeded"] + ["x"] * 2)
                             .loc[["MSK DT", "MSK SP3"]])
    tg_nmsk = SimpleNamespace(stats=lambda: st(["x"] * 2 + ["Solve_Succeeded", "Maximum_Iterations_Exceeded"])
                              .loc[["NMSK DT", "NMSK SP3"]])
    lines, tab = pr.thesis_guess_runs(page, {"MSK": tg_msk, "NMSK": tg_nmsk})
    assert lines[0] == "- from the whole Ch 5 solution (the page's runs): MSK 2 of 2 runs converged within 1000 " \
                       "iterations (300–400 iterations)."
    assert lines[1] == "- from the thesis's partial guess: MSK 1 of 2 runs converged within 1000 iterations " \
                       "(300–300 iterations); not converged: MSK SP3 (Maximum_Iterations_Exceeded)."
    assert len(lines) == 4 and lines[3].endswith("not converged: NMSK SP3 (Maximum_Iterations_Exceeded).")
    assert list(tab.index) == ["MSK DT", "MSK SP3", "NMSK DT", "NMSK SP3"]
    assert list(tab.columns) == pr.START_COLUMNS


def test_diagnosis_text_says_when_the_share_floor_held_the_top_effect():
    """A relative diagnosis whose first-ranked effect passed the threshold alone but closed
    less than the share floor reads "unexplained" with that reason, not "no candidate passes"."""
    s = {"top": "unexplained", "verdict": "unexplained", "best": "hip_offset", "best_pct": 18.2, "best_dBIC": -41.7,
         "contenders": ["hip_offset"], "held_by_share_floor": "hip_offset", "min_share_closed": 20.0}
    t = G._diagnosis_text(s, full=True)
    assert t.startswith("No candidate explains enough of the change: **unexplained** (best hip_offset, 18 % closed, "
                        "ΔBIC = -41.7")
    assert t.endswith("hip_offset passes the threshold but closes less than the 20 % of the gap a named effect must "
                      "close).")
    s.update(centred=True, share_closed=7.6)  # revision 10: the share of what the median candidate leaves
    assert G._diagnosis_text(s, full=True).endswith(
        "hip_offset passes the threshold but closes 8 % of what the median candidate leaves of the gap, less than "
        "the 20 % a named effect must close).")
    s.update(held_by_share_floor=None)
    assert G._diagnosis_text(s, full=True).startswith("No candidate passes the criterion")
