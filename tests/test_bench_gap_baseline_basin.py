"""benchmarks/gap_baseline_basin.py's table, and Chapter 8's sentence on its result, by hand
on made-up draws."""

from __future__ import annotations

import gap_baseline_basin as gbb

from gaitlib.studies import gap as G


def _run(rank1, dbic, lo, hi, worst, rb, rc, obj, frm=None, ranked=11):
    return {"rank1": rank1, "rank1_dBIC": dbic, "ranked": ranked, "pct_closed_min": lo, "pct_closed_max": hi,
            "worst_channel": worst, "worst_rss_baseline": rb, "worst_rss_candidates_median": rc,
            "rss_baseline": 20.0, "objective_baseline": obj, "baseline_from": frm}


RES = {"validation": "relative_rev3", "cases": [
    {"case": "null_3", "named": "unexplained",
     "as_run": _run("hip_offset", -136.4, 30.6, 38.3, "grf:grf_x_r", 7.49, 0.59, 0.7208),
     "from_candidates": _run("hip_offset", -10.9, 0.8, 6.2, "angle:pelvis_tilt", 1.71, 1.68, 0.7171, "grf_scale", 5)},
    {"case": "null_0", "named": "unexplained",
     "as_run": _run("foot_contact", -2.7, 0.1, 1.0, "angle:knee_r", 0.9, 0.8, 0.70),
     "from_candidates": _run("foot_contact", -2.7, 0.1, 1.0, "angle:knee_r", 0.9, 0.8, 0.70)}]}


def test_table_has_a_row_per_draw_and_run():
    t = gbb.table(RES).splitlines()
    assert len(t) == 2 + 4
    assert t[2] == ("| null_3 | as_run | hip_offset (-136.4) | 31–38 % (11) | grf:grf_x_r: 7.49 vs 0.59 | 0.7208 | — |")
    assert t[3].endswith("| 0.7171 | grf_scale |")


def test_chapter_sentence_gives_both_runs_per_draw():
    (line,) = G.baseline_basin_lines(RES)
    assert ("null_3: hip_offset -136, the 11 ranked candidates closing 31–38 % (the baseline's grf:grf_x_r 7.49 "
            "against the candidates' median 0.59) → hip_offset -11, 1–6 % (baseline from grf_scale)") in line
    assert "null_0: foot_contact -3" in line and "(baseline unchanged)" in line
    assert "found a lower baseline in 1 of 2 draws" in line and line.startswith("**Why revision 3's null draws")
