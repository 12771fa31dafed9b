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
from gaitlib.studies import gap as G
from gaitlib.studies import msk


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
    assert not w.loc["a@0#1", "true_not_named"]  # −12 ≤ −10 and nothing named
    assert D.BIC_THRESHOLD == -10.0


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
