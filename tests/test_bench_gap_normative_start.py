"""benchmarks/gap_normative_start.py's counts and table, by hand on made-up cases."""

from __future__ import annotations

import gap_normative_start as gns


def _r(named, start, obj, rss, top2, e):
    return {"named": named, "verdict": "x", "start": start, "objective": obj, "rss_baseline": rss, "top2": top2,
            "expected_dBIC": e}


def test_summary_counts_right_names_better_baselines_and_changes():
    res = {"cases": [
        {"injection": "load_scale", "band": "middle", "magnitude": 0.1, "unit": "1", "expected": "body_mass",
         "without": _r("unexplained", "grf", 0.83, 713.2, [("foot_contact", -11.1)], -5.7),
         "with": _r("body_mass", "warm", 0.79, 692.2, [("body_mass", -25.0), ("grf_scale", -12.0)], -25.0)},
        {"injection": "knee_offset", "band": "large", "magnitude": 4.4, "unit": "deg", "expected": "knee_offset",
         "without": _r("unexplained", "grf", 0.9, 830.7, [], None),
         "with": _r("left_shift", "warm", 0.95, 652.4, [], 2.3)},  # from the start but not lower
        {"injection": "plate_gain", "band": "large", "magnitude": 0.12, "unit": "1", "expected": "grf_scale",
         "without": _r("grf_scale", "grf", 0.8, 690.2, [], -16.9), "with": _r("grf_scale", "grf", 0.8, 690.2, [], -16.9)},
    ]}
    assert gns.summary(res) == {"cases": 3, "right_without": 1, "right_with": 2, "baseline_from_start": 1,
                                "named_changed": 2}
    t = gns.table(res).splitlines()
    assert len(t) == 2 + 2 * 3
    assert "| load_scale | middle | +0.1 1 | body_mass | with: warm | 692.2 | body_mass | body_mass -25.0, grf_scale -12.0 | -25.0 |" in t
    assert t[4].endswith("| — |")  # no expected ΔBIC: a dash
