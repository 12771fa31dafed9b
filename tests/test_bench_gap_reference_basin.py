"""benchmarks/gap_reference_basin.py's counts and table, and Chapter 8's sentence on its
result, by hand on made-up draws."""

from __future__ import annotations

import gap_reference_basin as grb

from gaitlib.studies import gap as G


def _c(case, named, back, obj=0.7669):
    return {"case": case, "named": named, "reference_start": "grf", "objective_reference": obj,
            "objective_reference_from_data": back, "objective_data": 0.74, "rss_relative": 12.0}


RES = {"cases": [_c("null_0", "ankle_offset", 0.7480), _c("null_1", "unexplained", 0.7669 - 6e-9),
                 _c("null_2", "unexplained", 0.7700), _c("null_3", "unexplained", 0.7630)]}


def test_summary_counts_lower_reference_fits_beyond_the_tolerance():
    # null_1 is lower by 6e-9 only (the same optimum): not counted
    assert grb.summary(RES) == {"draws": 4, "lower": 2, "lower_named": 1, "named": 1}
    t = grb.table(RES).splitlines()
    assert len(t) == 2 + 4 and t[2] == "| null_0 | ankle_offset | 0.7669 (grf) | 0.7480 | 0.7400 | 12.0 |"


def test_chapter_sentence_names_the_draws_that_left_the_basin():
    (line,) = G.reference_basin_lines(RES)
    assert "in 2 of 4 null draws (null_0: 0.7480, named ankle_offset; null_3: 0.7630, named unexplained)" in line
    assert "objective 0.7669" in line
    (none,) = G.reference_basin_lines({"cases": [_c("null_1", "unexplained", 0.7669)]})
    assert none.startswith("Re-solving the reference from the data's continuation fit never reached")
