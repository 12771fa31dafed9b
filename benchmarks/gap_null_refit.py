"""Does the ranking's spread under the data's sampling error come from the baseline's local
optimum? An experiment on Chapter 8's null set (issue 25), outside the frozen method.

    GAITLIB_SOLUTIONS=<cache> .venv/bin/python benchmarks/gap_null_refit.py   # ≈ 15 min, 1 worker

For the unedited Schwartz 2008 Free data and each draw of the null set
(:data:`gaitlib.gap.validate.NULL_DRAWS` redraws of the means within SD/√n, the seeds of
``gaitlib gap-validate --set null``): the diagnosis as the method runs it (10 × 3, per-node
derivatives); then the baseline re-fitted from each of the top three candidates' solutions
(their effect parameters dropped: ``gaitlib.gap.diagnose.baseline_fits`` with that solution
as the ``warm`` start); if one of those fits has a lower objective than the kept baseline,
it becomes the baseline, every candidate is re-fitted from it and ranked again. If the
candidates' closures were a better basin the baseline could reach as well, this round
would shrink the spread of their ΔBIC between draws.

Writes ``results/gap_validation/null_refit.json``: per case the baseline's RSS before and
after, the verdicts, the refit objectives and every ranked candidate's ΔBIC before and
after. (Run with the cache ``gaitlib gap-validate --set null`` wrote to, the first part
only reloads.)
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
OUT = HERE / "results" / "gap_validation" / "null_refit.json"
TOP = 3


def _dbic(d) -> dict:
    return {str(k): float(v) for k, v in zip(d.ranking["effect"], d.ranking["dBIC"]) if np.isfinite(v)}


def refit(ds, d, scheduler) -> dict:
    from gaitlib.gap import diagnose as D

    r = d.ranking[d.ranking["rank"].notna()].head(TOP)
    best, src, tries = d.baseline, "kept", {}
    for e in r["effect"]:
        sol = d.fits[e].solution
        if sol is None:
            continue
        b = D.baseline_fits(d.spec, {"data": ds}, warm=sol, starts=("warm",), scheduler=scheduler)["data"]
        tries[str(e)] = None if b is None else float(b.stats["objective"])
        if b is not None and b.stats["objective"] < best.stats["objective"] * (1 - D.RETRY_MARGIN):
            best, src = b, str(e)
    out = {"named0": d.top_effect, "rss0": float(d.located.rss), "dBIC0": _dbic(d),
           "objective0": float(d.baseline.stats["objective"]), "refits": tries, "source": src}
    if src == "kept":
        return {**out, "named1": d.top_effect, "rss1": out["rss0"], "dBIC1": out["dBIC0"]}
    names, skipped = D.candidates(d.spec, ds.gait, None)
    fits = D.candidate_fits(d.spec, {"data": ds}, {"data": best}, names, scheduler=scheduler)["data"]
    d1 = D.assemble(ds, d.spec, best, fits, resamples=0, skipped=skipped)
    return {**out, "named1": d1.top_effect, "rss1": float(d1.located.rss), "dBIC1": _dbic(d1)}


def main() -> int:
    from gaitlib import sweep as sweep_mod
    from gaitlib.gap import diagnose as D
    from gaitlib.gap import io as gio
    from gaitlib.gap import validate as V

    frame = V.real_frame("Free")
    res = {"method_hash": V.METHOD.hash(), "top": TOP, "cases": {}}
    with tempfile.TemporaryDirectory() as td, sweep_mod.local_cluster(1) as sch:
        p0 = Path(td) / "unedited.csv"
        frame.to_csv(p0, index=False)
        n = gio.read_data(p0).n
        cases = [("unedited", p0)]
        for _, c in V.draws(("null",)).iterrows():
            p = Path(td) / f"{c['case']}.csv"
            V.resample(frame, int(c["magnitude"]), n).to_csv(p, index=False)
            cases.append((c["case"], p))
        for name, p in cases:
            ds = gio.read_data(p)
            d = D.diagnose(ds, base=dict(D.DEFAULT_BASE, derivatives="nodes"), resamples=0, scheduler=sch)
            res["cases"][name] = refit(ds, d, sch)
            c = res["cases"][name]
            print(f"{name}: baseline from {c['source']}, RSS {c['rss0']:.0f} -> {c['rss1']:.0f}, "
                  f"{c['named0']} -> {c['named1']}", flush=True)
            OUT.write_text(json.dumps(res, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
