"""The Ch 6 conclusions table (gaitlib.studies.ch6_claims) on a hand-made accuracy table:
each verdict below is worked out by hand from the numbers put in."""
import numpy as np
import pandas as pd
import pytest

from gaitlib.studies import ch6_claims as cc
from gaitlib.studies import predictive as pr

KINDS = ("angle", "torque", "grf")


def _table(acc: dict, exc: dict) -> pd.DataFrame:
    """run → (NRMSE, SD units) on every accuracy kind; NMSK run → (RMSE, NRMSE) of excitations."""
    rows = [{"run": r, "kind": k, "NRMSE": a, "SD units": z} for r, (a, z) in acc.items() for k in KINDS]
    rows += [{"run": r, "kind": "excitation", "RMSE": e, "NRMSE": n} for r, (e, n) in exc.items()]
    return pd.DataFrame(rows).set_index(["run", "kind"])


def _case():
    # (NRMSE, SD units) per run
    acc = {"MSK DT": (0.100, 1.00), "NMSK DT": (0.105, 1.05),      # similar on both (5 %)
           "MSK SDT3": (0.100, 1.00), "NMSK SDT3": (0.200, 1.05),  # NRMSE differ 100 %, SD units 5 %
           "MSK SP1": (0.300, 3.00), "NMSK SP1": (0.300, 3.00),
           "MSK SDT2": (0.120, 1.20), "NMSK SDT2": (0.150, 1.50),  # MSK better
           "MSK SP3": (0.150, 1.50), "NMSK SP3": (0.120, 1.20),    # NMSK better: claim fails
           "MSK SDT1": (0.150, 1.50), "NMSK SDT1": (0.120, 1.20),
           "MSK SP2": (0.150, 1.50), "NMSK SP2": (0.120, 1.20),
           "MSK FP": (0.400, 4.00), "NMSK FP": (0.350, 3.20)}
    exc = {"NMSK DT": (0.30, 0.5), "NMSK SDT1": (0.20, 0.4), "NMSK SDT2": (0.20, 0.4), "NMSK SDT3": (0.10, 0.2),
           "NMSK SP1": (0.40, 0.6), "NMSK SP2": (0.20, 0.4), "NMSK SP3": (0.20, 0.4), "NMSK FP": (0.25, 0.45),
           cc.CH5_NMSK: (0.50, 0.7)}
    times = {f"{m} {c}": 10.0 for m in ("MSK", "NMSK") for c in pr.CH6_COSTS}
    times["MSK FP"], times["NMSK FP"] = 100.0, 60.0
    return acc, exc, times


def _row(t, start):
    r = t[t["claim"].str.startswith(start)]
    assert len(r) == 1, start
    return r.iloc[0]


def test_verdicts_by_hand():
    acc, exc, times = _case()
    t = cc.table_conclusions(_table(acc, exc), times, with_ch5=True)
    assert _row(t, "DT: MSK and NMSK similar")["verdict"] == "holds"
    r = _row(t, "SDT3: MSK and NMSK similar")
    assert (r["NRMSE: verdict"], r["SD units: verdict"]) == ("does not hold", "holds")
    assert r["verdict"] == "depends on the metric" and r["depends on metric"]
    assert _row(t, "SDT2: MSK more accurate")["verdict"] == "holds"
    assert _row(t, "SP3: MSK more accurate")["verdict"] == "does not hold"
    assert _row(t, "FP: NMSK more accurate")["verdict"] == "holds"
    # SDT3 enough: NRMSE 0.200 > 1.1 × 0.105; SD units 1.05 ≤ 1.1 × 1.05
    assert _row(t, "NMSK: tracking angles and torques")["verdict"] == "depends on the metric"
    assert _row(t, "SP1 (GRF only)")["verdict"] == "holds"     # 0.3 > every Ang/Trq run, both models
    assert _row(t, "FP: less accurate")["verdict"] == "holds"
    r = _row(t, "FP: NMSK angles")  # SD units 1 − 3.2/4 = 20 %; NRMSE 1 − 0.35/0.4 = 12.5 %
    assert "NMSK lower by 12 %" in r["NRMSE"] or "NMSK lower by 13 %" in r["NRMSE"]
    assert "lower by 20 %" in r["SD units"]
    assert _row(t, "NMSK SDT3 predicts the most")["verdict"] == "holds"
    assert _row(t, "NMSK SP1 predicts the least")["verdict"] == "holds"
    # DT excitation 0.30: rank 7 of 8 on RMSE, 7 of 8 on NRMSE → worse half
    assert "rank 7 of 8" in _row(t, "NMSK DT is among")["RMSE"]
    assert _row(t, "NMSK FP excitations")["verdict"] == "holds"  # 0.25 < 0.50: 50 % lower
    assert "lower by 50 %" in _row(t, "NMSK FP excitations")["RMSE"]
    # compute time: sums 8 × 10 + 90 = 170 s (MSK) vs 130 s (NMSK); FP 40 % faster
    r = _row(t, "NMSK optimisations")
    assert r["verdict"] == "holds" and "MSK 170 s, NMSK 130 s" in r["ours"]
    assert "faster by 40 %" in _row(t, "FP: NMSK faster")["ours"]


def test_an_unusable_run_makes_its_claims_untested():
    acc, exc, times = _case()
    del acc["NMSK SP3"], exc["NMSK SP3"]
    mark = "NOT CONVERGED: Maximum_Iterations_Exceeded; INVALID: swing load 9 N > 8.12 N"
    t = cc.table_conclusions(_table(acc, exc), times, excluded={"NMSK SP3": mark})
    r = _row(t, "SP3: MSK more accurate")
    assert r["verdict"] == "not tested" and "NMSK SP3 (not converged, invalid)" in r["ours"]
    # the card hands over the validity gates' own label: named the same, never "()"
    t2 = cc.table_conclusions(_table(acc, exc), times, excluded={"NMSK SP3": "invalid: double support 96% > 40%"})
    assert "NMSK SP3 (invalid)" in _row(t2, "SP3: MSK more accurate")["ours"]
    # every claim needing all NMSK runs is untested; the Ch 5 claim is absent without the Ch 5 run
    assert _row(t, "NMSK SDT3 predicts the most")["verdict"] == "not tested"
    assert not t["claim"].str.contains("Ch 5").any()
    assert _row(t, "SDT2: MSK more accurate")["verdict"] == "holds"
    assert cc.summary(t).startswith(f"Of the thesis's {len(t)} Ch 6 claims")


@pytest.mark.parametrize("metric", list(cc.METRICS))
def test_similar_threshold_is_relative(metric):
    acc, exc, times = _case()
    tol = cc.SIMILAR_TOL
    acc["MSK DT"], acc["NMSK DT"] = (1.0, 1.0), (1.0 + 0.99 * tol, 1.0 + 0.99 * tol)
    t = cc.table_conclusions(_table(acc, exc), times)
    assert _row(t, "DT: MSK and NMSK similar")[f"{metric}: verdict"] == "holds"
    acc["NMSK DT"] = (1.0 + 1.01 * tol, 1.0 + 1.01 * tol)
    t = cc.table_conclusions(_table(acc, exc), times)
    assert _row(t, "DT: MSK and NMSK similar")[f"{metric}: verdict"] == "does not hold"
    assert np.isfinite(tol)


def test_an_extremum_claim_fails_on_the_usable_runs_or_stays_untested():
    """'SDT3 has the most accurate excitations' with NMSK FP left out: decided only when it
    fails among the usable runs (a left-out run can only add a rival)."""
    acc, exc, times = _case()
    del acc["NMSK FP"], exc["NMSK FP"]
    t = cc.table_conclusions(_table(acc, exc), times, excluded={"NMSK FP": "INVALID: double support"})
    r = _row(t, "NMSK SDT3 predicts the most")  # 0.10 is the best of the 7 left: holds there, untested
    assert r["verdict"] == "not tested" and "left out: NMSK FP (invalid)" in r["ours"]
    exc["NMSK SDT2"] = (0.05, 0.1)  # now SDT2 beats SDT3 among the usable runs
    t = cc.table_conclusions(_table(acc, exc), times, excluded={"NMSK FP": "INVALID: double support"})
    assert _row(t, "NMSK SDT3 predicts the most")["verdict"] == "does not hold"
    # "worse half" is no extremum: it needs all eight
    assert _row(t, "NMSK DT is among")["verdict"] == "not tested"


def test_changed_lists_only_the_claims_whose_verdict_moves():
    import pandas as pd

    from gaitlib.studies import ch6_claims

    before = pd.DataFrame({"claim": ["a", "b", "c"], "verdict": ["holds", "does not hold", "not tested"],
                           "NRMSE": ["0.1 vs 0.2", "0.3 vs 0.1", "—"]})
    after = pd.DataFrame({"claim": ["a", "b", "d"], "verdict": ["holds", "holds", "holds"],
                          "NRMSE": ["0.1 vs 0.2", "0.1 vs 0.1", "x"]})
    t = ch6_claims.changed(before, after)
    assert list(t.index) == ["b"]
    assert t.loc["b"].tolist() == ["does not hold", "holds", "0.3 vs 0.1", "0.1 vs 0.1"]


def test_excitation_resolution_hand_numbers():
    """Spread, common shift and relative move worked by hand on a 4-run table: book
    0.10/0.12/0.15/0.20 (gaps 0.02, 0.03, 0.05 → median 0.03); variant A adds 0.05 to every
    run (shift +0.05, relative moves 0, ranks identical); variant B changes the runs by
    0.00/+0.04/−0.04/+0.10 (median of the four changes +0.02, relative moves 0.02, 0.02,
    0.06, 0.08 → median 0.04 > 0.03)."""
    t = pd.DataFrame({"book": [0.10, 0.12, 0.15, 0.20], "A": [0.15, 0.17, 0.20, 0.25],
                      "B": [0.10, 0.16, 0.11, 0.30]}, index=["DT", "SDT1", "SDT2", "SDT3"])
    s = cc.excitation_resolution(t)
    assert "span 0.100–0.200 (range 0.100; median gap between neighbours in the ranking 0.030)" in s
    assert "A: beyond a common shift of +0.050, a run's score moves by a median 0.000 (largest 0.000" in s
    assert "ranks agree at Spearman ρ = 1.00" in s
    assert "B: beyond a common shift of +0.020, a run's score moves by a median 0.040 (largest 0.080, SDT3)" in s
    assert s.endswith("(0.030): B (0.040); by less: A (0.000).")
