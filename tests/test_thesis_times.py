"""Thesis-times table: the rows ``benchmarks/bench_thesis_times.py`` writes
(``benchmarks/thesis_times.py``: the thesis's printed times as labelled references, the
speed-up only for converged runs), the stored table as the book reads it
(:mod:`gaitlib.studies.performance`), and the no-solving guard of ``--cached-only``
(:func:`gaitlib.cache.only`)."""

from __future__ import annotations

import math

import pytest

import thesis_times as tt  # benchmarks/ is on sys.path (tests/conftest.py)
from gaitlib import cache
from gaitlib.studies import contact_id, msk, predictive
from gaitlib.studies import performance as perf


def test_parse_duration():
    assert tt.parse_duration("6 min (Sec 4.3.3, GlobalSearch)") == 360.0
    assert tt.parse_duration("11 min") == 660.0
    assert tt.parse_duration("5 h (Sec 4.4.2, GPOPS-II)") == 5 * 3600.0
    assert tt.parse_duration("2 hrs") == 7200.0
    assert tt.parse_duration("30 s") == 30.0
    with pytest.raises(ValueError):
        tt.parse_duration("about two hours")


def test_thesis_reference_times_are_the_printed_ones_with_their_source():
    ref = tt.thesis_reference_times()
    # Sec 4.3.3: 6 min / 11 min; Sec 4.4.2: 5 h — from contact_id.THESIS_TIME, not retyped
    assert ref["ch04 a"].seconds == 360 and "Sec 4.3.3" in ref["ch04 a"].label
    assert ref["ch04 b"].seconds == 660 and "Sec 4.3.3" in ref["ch04 b"].label
    assert ref["ch04 c"].seconds == 5 * 3600 and "Sec 4.4.2" in ref["ch04 c"].label
    assert ref["ch04 c_wide"].seconds == ref["ch04 c"].seconds
    for k in contact_id.THESIS_TIME:
        assert ref[f"ch04 {k}"].label.startswith(contact_id.THESIS_TIME[k])
    # Secs 5.2.2 / 5.3.5: 2 h
    assert ref["ch05 MSK"].seconds == 3600 * msk.THESIS_HOURS["MSK"] == 7200 and "Sec 5.2.2" in ref["ch05 MSK"].label
    assert ref["ch05 NMSK"].seconds == 7200 and "Sec 5.3.5" in ref["ch05 NMSK"].label
    # Table 6.3: all 16; Table 7.2: all 8, through the class of the same rank
    for m, row in predictive.THESIS_HOURS_TABLE_6_3.items():
        for cost, h in row.items():
            t = ref[f"ch06 {m} {cost}"]
            assert t.seconds == 3600 * h and "Table 6.3" in t.label and f"{m} {cost}" in t.label
    for m, row in predictive.THESIS_HOURS_TABLE_7_2.items():
        for ours, theirs in predictive.THESIS_CLASS.items():
            if theirs in row:
                t = ref[f"ch07 {m} {ours}"]
                assert t.seconds == 3600 * row[theirs] and "Table 7.2" in t.label and theirs in t.label
    assert ref["ch07 MSK VerySlow"].seconds == 18 * 3600 and ref["ch07 NMSK Fast"].seconds == 4 * 3600
    assert len([k for k in ref if k.startswith("ch06")]) == 16 and len([k for k in ref if k.startswith("ch07")]) == 8
    # where the thesis prints nothing there is no reference
    assert "ch02 SK" not in ref and not any(k.startswith("ch03") for k in ref)
    assert "ch02 SK" in tt.THESIS_SILENT and "ch03" in tt.THESIS_SILENT


def test_speedup_only_for_converged_rows():
    ok = tt.time_row("ch06", "MSK DT", status="Solve_Succeeded", converged=True, iterations=500, build_s=30.0,
                       solve_s=90.0, thesis_key="ch06 MSK DT")
    assert ok["wall_s"] == 120.0 and ok["ms_per_iteration"] == pytest.approx(180.0)
    assert ok["speedup"] == pytest.approx(7200 / 120.0) and ok["thesis_time"].startswith("2 h (Table 6.3")
    bad = tt.time_row("ch06", "NMSK SDT3", status="Maximum_Iterations_Exceeded", converged=False, iterations=1000,
                        build_s=30.0, solve_s=300.0, thesis_key="ch06 NMSK SDT3")
    assert bad["status"] == "Maximum_Iterations_Exceeded" and bad["speedup"] is None
    assert bad["thesis_time_s"] == 3600 and bad["wall_s"] == 330.0  # the time is still reported
    silent = tt.time_row("ch03", "jump", status="Solve_Succeeded", converged=True, iterations=10, build_s=1.0,
                           solve_s=2.0)
    assert silent["thesis_time"] is None and silent["speedup"] is None
    # a multistart search: its wall time (scoring the starts included) is given explicitly
    a = tt.time_row("ch04", "(a)", status="Solve_Succeeded", converged=True, iterations=800, build_s=9.0,
                      solve_s=15.0, wall_s=30.0, n_solves=11, thesis_key="ch04 a")
    assert a["wall_s"] == 30.0 and a["speedup"] == pytest.approx(12.0) and a["n_solves"] == 11
    miss = tt.missing_row("ch07", "MSK Fast", "not computed yet — run X", thesis_key="ch07 MSK Fast")
    assert miss["status"] == perf.NOT_COMPUTED and miss["wall_s"] is None and miss["speedup"] is None
    assert miss["thesis_time_s"] == 10 * 3600 and miss["note"].endswith("run X")
    assert set(tt.TIME_COLUMNS) <= set(ok)


def test_summary_and_table_of_a_document():
    rows = [tt.time_row("ch06", "MSK DT", status="Solve_Succeeded", converged=True, iterations=500, build_s=20.0,
                          solve_s=80.0, thesis_key="ch06 MSK DT", from_cache=True),
            tt.time_row("ch06", "MSK FP", status="Solve_Succeeded", converged=True, iterations=500, build_s=20.0,
                          solve_s=380.0, thesis_key="ch06 MSK FP", from_cache=False),
            tt.time_row("ch06", "NMSK SDT3", status="Maximum_Iterations_Exceeded", converged=False,
                          iterations=1000, build_s=20.0, solve_s=280.0, thesis_key="ch06 NMSK SDT3", from_cache=True),
            tt.time_row("ch03", "jump", status="Solve_Succeeded", converged=True, iterations=10, build_s=1.0,
                          solve_s=9.0, from_cache=True),
            tt.missing_row("ch07", "MSK Fast", "run X", thesis_key="ch07 MSK Fast")]
    doc = {"meta": {"measured": "2026-11-22T13:00:00+00:00"}, "rows": rows}
    s = perf.thesis_times_summary(doc)
    assert (s["n_rows"], s["n_converged"], s["n_not_converged"], s["n_missing"]) == (5, 3, 1, 1)
    assert s["n_with_thesis"] == 2  # the jump has no thesis time; the non-converged run no speed-up
    assert s["speedup_min"] == pytest.approx(7200 / 100) and s["speedup_max"] == pytest.approx(36000 / 400)
    assert s["n_from_cache"] == 3 and s["total_wall_s"] == pytest.approx(100 + 400 + 300 + 10)
    t = perf.thesis_times_table(doc)
    assert list(t["status"]) == [r["status"] for r in rows]
    assert t["speed-up (thesis / ours)"].isna().tolist() == [False, False, True, True, True]
    assert "thesis time (labelled)" in t.columns


def test_stored_table_is_consistent():
    """The committed benchmarks/results/thesis_times.json: speed-ups only on converged rows,
    equal to thesis time / wall time; every thesis label one of the references."""
    try:
        doc = perf.load("thesis_times")
    except FileNotFoundError:
        pytest.skip("thesis_times.json not written yet")
    labels = {t.label for t in tt.thesis_reference_times().values()}
    assert doc["meta"]["machine"]["cores"] and doc["meta"]["collections"]
    for r in doc["rows"]:
        if r["speedup"] is not None:
            assert r["converged"] and r["status"] in ("Solve_Succeeded", "Solved_To_Acceptable_Level")
            assert r["speedup"] == pytest.approx(r["thesis_time_s"] / r["wall_s"])
        if r["thesis_time"] is not None:
            assert r["thesis_time"] in labels
        if r["status"] in (perf.NOT_COMPUTED, perf.NO_CACHE):
            assert r["wall_s"] is None and r["note"]
        elif r["wall_s"] is not None:
            assert r["iterations"] > 0
            if r["n_solves"] == 1:  # (a multistart search's wall also includes scoring the starts)
                assert r["wall_s"] == pytest.approx(r["build_s"] + r["solve_s"])
            else:
                assert r["wall_s"] >= r["build_s"] + r["solve_s"] - 1e-6
            assert math.isclose(r["ms_per_iteration"], 1e3 * r["solve_s"] / r["iterations"], rel_tol=1e-9)


def test_cached_only_refuses_a_solve_and_patches_nothing(tmp_path, monkeypatch):
    """Inside cache.only (the guard of --cached-only) a study that would solve raises
    NotCached before any symbolic work (no entry written); afterwards the same call solves."""
    from gaitlib.studies import gait

    monkeypatch.setenv("GAITLIB_STORE", "")
    with cache.only("cached only"):
        with pytest.raises(cache.NotCached, match="cached only"):
            gait.natural_gait("SK", root=tmp_path, n_intervals=2, degree=2)  # empty cache: would solve
    assert not any(tmp_path.rglob("spec.json"))  # nothing stored
    sol = gait.natural_gait("SK", root=tmp_path, n_intervals=2, degree=2, max_iter=3)
    assert sol.stats["iterations"] <= 3 and any(tmp_path.rglob("spec.json"))
