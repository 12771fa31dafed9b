"""Would the baseline find a better basin from the library's own fit of the reference data?
An experiment on Chapter 8's independent injections (issue 25), outside the frozen method.

    GAITLIB_SOLUTIONS=<cache> .venv/bin/python benchmarks/gap_normative_start.py   # reloads the validation's solves

For each independent injection of the current method's draws at middle and large
magnitudes (:func:`gaitlib.gap.validate.draws`, the manipulations of ``gaitlib gap-validate``):
the diagnosis as the method runs it (the stored validation's baseline settings, so with the
cache ``gaitlib gap-validate`` wrote to it only reloads), and the diagnosis with one more
baseline start — the fit of the unedited data (``warm``: what a "normative start", the
library's fit of its own reference data of the speed class, would give every user's data
set). A manipulated data set differs from the unedited one by the injection only, so this
start is the most favourable one the baseline could get.

Writes ``results/gap_normative_start.json`` and ``.md``: per case the kept baseline's start
and RSS, the named effect, the two best-ranked candidates and the expected effect's ΔBIC,
without and with the start.
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
OUT = HERE / "results" / "gap_normative_start.json"
BANDS = ("middle", "large")


def _row(d, expected: str) -> dict:
    rk = d.ranking[d.ranking["rank"].notna()]
    e = rk[rk["effect"] == expected]
    top = [(str(a), float(b)) for a, b in zip(rk["effect"].head(2), rk["dBIC"].head(2))]
    return {"named": d.top_effect, "verdict": d.verdict, "start": d.baseline.stats.get("start"),
            "rss_baseline": float(d.located.rss), "objective": float(d.baseline.stats["objective"]),
            "top2": top, "expected_dBIC": float(e["dBIC"].iloc[0]) if len(e) else None}


def table(res: dict) -> str:
    lines = ["| injection | band | magnitude | expected | start | baseline RSS | named | first two (ΔBIC) | "
             "expected ΔBIC |", "|---|---|---|---|---|---|---|---|---|"]
    for c in res["cases"]:
        for k in ("without", "with"):
            r = c[k]
            top = ", ".join(f"{a} {b:.1f}" for a, b in r["top2"])
            ed = "—" if r["expected_dBIC"] is None else f"{r['expected_dBIC']:.1f}"
            lines.append(f"| {c['injection']} | {c['band']} | {c['magnitude']:+.3g} {c['unit']} | {c['expected']} | "
                         f"{k}: {r['start']} | {r['rss_baseline']:.1f} | {r['named']} | {top} | {ed} |")
    return "\n".join(lines)


def summary(res: dict) -> dict:
    """Counts over the cases: named right without / with the start, cases whose kept baseline
    came from the start and had a lower objective, cases whose verdict changed."""
    cs = res["cases"]
    right = {k: sum(c[k]["named"] == c["expected"] for c in cs) for k in ("without", "with")}
    better = sum(c["with"]["start"] == "warm" and c["with"]["objective"] < c["without"]["objective"] for c in cs)
    changed = sum(c["with"]["named"] != c["without"]["named"] for c in cs)
    return {"cases": len(cs), "right_without": right["without"], "right_with": right["with"],
            "baseline_from_start": better, "named_changed": changed}


def main() -> int:
    from gaitlib import sweep as sweep_mod
    from gaitlib.gap import diagnose as D
    from gaitlib.gap import io as gio
    from gaitlib.gap import validate as V
    from gaitlib.studies import gap as gap_study

    base = gap_study.stored_validation("real").settings["base"]
    frame = V.real_frame(base.get("speed_class", "Free"))
    res = {"method_hash": V.METHOD.hash(), "base": base, "cases": []}
    draws = V.draws(("independent",))
    draws = draws[draws["band"].isin(BANDS)]
    with tempfile.TemporaryDirectory() as td, sweep_mod.local_cluster(None) as sch:
        p0 = Path(td) / "unedited.csv"
        frame.to_csv(p0, index=False)
        d0 = D.diagnose(gio.read_data(p0), base=base, resamples=0, scheduler=sch)
        for _, c in draws.iterrows():
            p = Path(td) / f"{c['case']}.csv"
            V.inject(frame, c["injection"], c["magnitude"]).to_csv(p, index=False)
            ds = gio.read_data(p)
            row = {k: (float(c[k]) if k == "magnitude" else str(c[k]))
                   for k in ("injection", "band", "magnitude", "unit", "expected")}
            for k, warm in (("without", None), ("with", d0.baseline)):
                row[k] = _row(D.diagnose(ds, base=base, resamples=0, warm=warm, scheduler=sch), c["expected"])
            res["cases"].append(row)
            print(f"{c['case']}: {row['without']['named']} -> {row['with']['named']} (expected {c['expected']}); "
                  f"baseline RSS {row['without']['rss_baseline']:.1f} -> {row['with']['rss_baseline']:.1f}", flush=True)
            OUT.write_text(json.dumps(res, indent=1))
    res["summary"] = summary(res)
    OUT.write_text(json.dumps(res, indent=1))
    s = res["summary"]
    OUT.with_suffix(".md").write_text(
        f"# The baseline from the unedited data's fit (method {res['method_hash']})\n\n"
        f"Independent injections at {' and '.join(BANDS)} magnitudes, {s['cases']} cases: named right "
        f"{s['right_without']} without the start, {s['right_with']} with it; the kept baseline came from the "
        f"start with a lower objective in {s['baseline_from_start']}; the named effect changed in "
        f"{s['named_changed']}.\n\n" + table(res) + "\n")
    print(json.dumps(s), flush=True)
    return 0 if np.isfinite(s["cases"]) else 1


if __name__ == "__main__":
    sys.exit(main())
