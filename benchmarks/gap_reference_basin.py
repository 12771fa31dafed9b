"""Does the data's continuation leave the reference fit's basin? An experiment on Chapter 8's
relative validation of relative method revision 1 (issue 25), outside the frozen method; its
answer is revision 2's self-consistent reference fit.

    GAITLIB_SOLUTIONS=<cache> .venv/bin/python benchmarks/gap_reference_basin.py   # reloads the validation's solves

For each ``null`` draw of the stored relative validation (the unedited data resampled,
nothing changed; regenerated exactly as ``gaitlib gap-validate --relative`` makes them, with
its reference): the baseline's kept fit of the reference S_R (its best start), the data's
continuation fit F(N) from S_R (as the relative diagnosis fits it) with its relative RSS, and
the reference re-solved from F(N): if that reaches a lower objective on the reference than
S_R, the reference's kept fit was not the best of the basins within reach, and the
continuation moved to another basin — a change of the fit, not of the data, which the
relative gap then carries.

Writes ``results/gap_validation/reference_basin.json`` and ``.md``.
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
OUT = HERE / "results" / "gap_validation" / "reference_basin.json"


#: The stored validation whose null draws are re-solved: relative method revision 1 (the
#: self-consistent reference fit of revision 2 re-solves the reference inside the method).
VALIDATION = "relative_rev1"

#: Relative objective decrease below which two fits count as the same optimum.
TOL = 1e-6


def summary(res: dict) -> dict:
    """Counts over the draws: the reference re-solved from the data's fit reached a lower
    objective than its kept fit, by more than :data:`TOL` relative (``lower``), and among
    those, the draws a library effect was named for (``lower_named``)."""
    cs = res["cases"]
    lower = [c for c in cs
             if c["objective_reference_from_data"] < c["objective_reference"] * (1.0 - TOL)]
    return {"draws": len(cs), "lower": len(lower), "lower_named": sum(c["named"] != "unexplained" for c in lower),
            "named": sum(c["named"] != "unexplained" for c in cs)}


def table(res: dict) -> str:
    lines = ["| draw | named | reference fit objective (kept start) | reference re-solved from the data's fit | "
             "data fit objective | relative RSS |", "|---|---|---|---|---|---|"]
    for c in res["cases"]:
        lines.append(f"| {c['case']} | {c['named']} | {c['objective_reference']:.4f} ({c['reference_start']}) | "
                     f"{c['objective_reference_from_data']:.4f} | {c['objective_data']:.4f} | {c['rss_relative']:.1f} |")
    return "\n".join(lines)


def main() -> int:
    from gaitlib.gap import diagnose as D
    from gaitlib.gap import locate as L
    from gaitlib.gap import reference as R
    from gaitlib.gap import validate as V
    from gaitlib.gap.solve import solve_on
    from gaitlib.studies import gap as gap_study

    val = gap_study.superseded_validation(VALIDATION)  # revision 1: the false name revision 2 answers
    base = val.settings["base"]
    spec0 = D.base_spec(base)
    res = {"method_hash": V.METHOD.hash(), "relative_method_hash": val.settings["relative_method_hash"],
           "validation": VALIDATION, "base": base,
           "cases": []}
    with tempfile.TemporaryDirectory() as td:
        ref, nulls = V.relative_null_sets(val, td)
        s_r = D.baseline_fits(spec0, {"reference": ref}, None, serial=True)["reference"]
        for c, ds in nulls:
            f_n = solve_on(spec0, ds.gait, s_r)
            back = solve_on(spec0, ref.gait, f_n)
            row = {"case": str(c["case"]), "named": str(c["named"]), "reference_start": s_r.stats.get("start"),
                   "objective_reference": float(s_r.stats["objective"]), "objective_data": float(f_n.stats["objective"]),
                   "objective_reference_from_data": float(back.stats["objective"]),
                   "status_reference_from_data": back.stats["status"],
                   "rss_relative": float(L.locate(f_n, R.relative_data(ds, ref, s_r, tilt=False)).rss)}  # rev. 1: no tilt
            res["cases"].append(row)
            print(json.dumps(row), flush=True)
    res["summary"] = summary(res)
    OUT.write_text(json.dumps(res, indent=1))
    s = res["summary"]
    OUT.with_suffix(".md").write_text(
        f"# Does the data's continuation leave the reference fit's basin? (relative method "
        f"{res['relative_method_hash']})\n\nNull draws: {s['draws']}; the reference re-solved from the data's fit "
        f"reached a lower objective than its kept fit in {s['lower']} (named a library effect: {s['lower_named']} of "
        f"those, {s['named']} in all).\n\n" + table(res) + "\n")
    print(json.dumps(s), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
