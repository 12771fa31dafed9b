"""Why did revision 3's null draws reach ΔBIC −130 and beyond? An experiment on Chapter 8's
relative validation of relative method revision 3 (issue 25), outside the frozen method; its
answer is revision 4's baseline re-fitted from the candidates' fits.

    GAITLIB_SOLUTIONS=<cache> .venv/bin/python benchmarks/gap_baseline_basin.py   # reloads the validation's solves

For each ``null`` draw of the stored revision-3 validation (the unedited data resampled,
nothing changed; regenerated exactly as ``gaitlib gap-validate --relative`` makes them, with
its reference), the relative diagnosis is run twice without the null calibration (the
ranking only): as revision 3 ran it, and with the baseline's fit of the data re-solved
from every nested candidate's fit (``RelativeMethod.baseline_from_candidates``, the rest
unchanged). Reported per draw and run: the first-ranked candidate and its ΔBIC, the range
of % closed over the ranked candidates (a baseline stopped in a worse optimum makes every
candidate close about the same share), the channel where the baseline's relative RSS
exceeds the candidates' median most, and the baseline's objective.

Writes ``results/gap_validation/baseline_basin.json`` and ``.md``.
"""

from __future__ import annotations

import dataclasses
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
OUT = HERE / "results" / "gap_validation" / "baseline_basin.json"

#: The stored validation whose null draws are re-diagnosed: relative method revision 3.
VALIDATION = "relative_rev3"


def run_summary(d) -> dict:
    """One diagnosis's numbers: first-ranked effect and ΔBIC, % closed range over the ranked
    candidates, the baseline's worst channel against the candidates' median, its objective."""
    r = d.ranking[d.ranking["rank"].notna()]
    base = d.located.channels.set_index("channel")["rss"]
    cand = [f.located.channels.set_index("channel")["rss"] for n, f in d.fits.items()
            if f.located is not None and n in set(r["effect"])]
    med = np.median(np.vstack([c.reindex(base.index).to_numpy() for c in cand]), axis=0) if cand else base * np.nan
    excess = base - med
    worst = str(excess.idxmax()) if cand else None
    return {"rank1": str(r.iloc[0]["effect"]) if len(r) else None,
            "rank1_dBIC": float(r.iloc[0]["dBIC"]) if len(r) else None,
            "ranked": int(len(r)),
            "pct_closed_min": float(r["pct_closed"].min()) if len(r) else None,
            "pct_closed_max": float(r["pct_closed"].max()) if len(r) else None,
            "worst_channel": worst, "worst_rss_baseline": float(base[worst]) if worst else None,
            "worst_rss_candidates_median": float(med[list(base.index).index(worst)]) if worst else None,
            "rss_baseline": float(d.located.rss), "objective_baseline": float(d.baseline.stats["objective"]),
            "baseline_from": ((d.settings["reference"].get("moved") or {}).get("baseline") or {}).get("data_from")}


def table(res: dict) -> str:
    lines = ["| draw | run | first ranked (ΔBIC) | % closed, ranked candidates | baseline's worst channel: RSS vs "
             "candidates' median | baseline objective | baseline from |", "|---|---|---|---|---|---|---|"]
    for c in res["cases"]:
        for run in ("as_run", "from_candidates"):
            x = c[run]
            lines.append(f"| {c['case']} | {run} | {x['rank1']} ({x['rank1_dBIC']:.1f}) | {x['pct_closed_min']:.0f}–"
                         f"{x['pct_closed_max']:.0f} % ({x['ranked']}) | {x['worst_channel']}: "
                         f"{x['worst_rss_baseline']:.2f} vs {x['worst_rss_candidates_median']:.2f} | "
                         f"{x['objective_baseline']:.4f} | {x['baseline_from'] or '—'} |")
    return "\n".join(lines)


def main() -> int:
    from gaitlib.gap import diagnose as D
    from gaitlib.gap import validate as V
    from gaitlib.studies import gap as gap_study

    val = gap_study.superseded_validation(VALIDATION)
    base = val.settings["base"]
    rel0 = D.RELATIVE
    res = {"method_hash": V.METHOD.hash(), "relative_method_hash": val.settings["relative_method_hash"],
           "validation": VALIDATION, "base": base, "cases": []}
    with tempfile.TemporaryDirectory() as td:
        ref, nulls = V.relative_null_sets(val, td)
        try:
            for c, ds in nulls:
                row = {"case": str(c["case"]), "named": str(c["named"])}
                for run, flag in (("as_run", False), ("from_candidates", True)):
                    # revision 3's relative method, the ranking only (no null calibration)
                    D.RELATIVE = dataclasses.replace(rel0, null_draws=0, tilt_channel=True, reference_rounds=2,
                                                     baseline_from_candidates=flag)
                    d = D.diagnose(ds, base=base, resamples=0, reference=ref, serial=True)
                    row[run] = run_summary(d)
                res["cases"].append(row)
                print(json.dumps(row), flush=True)
        finally:
            D.RELATIVE = rel0
    OUT.write_text(json.dumps(res, indent=1))
    OUT.with_suffix(".md").write_text(
        f"# The baseline's continuation and the candidates' fits (relative method {res['relative_method_hash']}, "
        f"{VALIDATION})\n\nEach null draw diagnosed as revision 3 ran it (`as_run`) and with the baseline re-fitted "
        f"from every nested candidate's fit (`from_candidates`); ranking only, no null calibration.\n\n"
        + table(res) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
