"""Each candidate against the baseline in its own optimum: an experiment on Chapter 8's paired
run of revision 7 on revision 6's draws (``gap_paired.py reference_fit_rev6``; issue 25),
outside the frozen method.

    GAITLIB_SOLUTIONS=<cache> .venv/bin/python benchmarks/gap_candidate_baseline.py   # reloads the run's solves

In some calibration draws every candidate gains alike (common mode), in others every
candidate's relative gap is *above* the baseline's, so none is ranked: the baseline's
relative gap [F(N) − N] − [F(R) − R] carries a shift of its own that no candidate's
parameter causes. ``gap_baseline_pair.py`` showed that choosing the baseline's two fits as a
pair removes it in one of four common-mode draws. Here each candidate k is compared with the
baseline re-solved from k's *own* fits — of the draw from F_k(N), of the reference from
F_k(R), the baseline being k with its parameter at the null value — so that k's ΔBIC counts
only what k's parameter adds within k's optimum:
ΔBIC_k = n_eff·ln(RSS_k / RSS_0k) + p_k·ln(n_eff), with RSS_0k and n_eff the relative gap
of that baseline pair. Reported per draw: as the run ranked it (first-ranked ΔBIC, median,
ranked count), the same with every candidate compared against the one baseline (those above
it with ΔBIC > 0), and with each candidate's own baseline, for the draws in :data:`DRAWS`.

Writes ``results/gap_validation/candidate_baseline.json`` and ``.md``.
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
OUT = HERE / "results" / "gap_validation" / "candidate_baseline.json"

#: The paired run whose calibration draws are re-diagnosed and the draws: its four
#: common-mode draws, the one with no candidate ranked, and five others.
RUN = "reference_fit_rev6"
DRAWS = ("null0", "null7", "null11", "null15", "null5", "null1", "null2", "null3", "null6", "null16")


def stats(dbic: dict) -> dict:
    v = sorted(dbic.values())
    return {"rank1": min(dbic, key=dbic.get) if dbic else None, "rank1_dBIC": v[0] if v else None,
            "median_dBIC": float(np.median(v)) if v else None, "ranked": len(v), "dBIC": dbic}


def main() -> int:
    from gap_paired import calibration_draws, stored_method, using

    from gaitlib.gap import diagnose as D
    from gaitlib.gap import locate as L
    from gaitlib.gap import method as M
    from gaitlib.gap import reference as R
    from gaitlib.studies import gap as gap_study

    run = gap_study.stored_paired(RUN)
    calib = run.unedited["null_calibration"]
    base = run.settings["base"]
    orig = D.consistent_fits
    captured = {}

    def capture(*a, **kw):
        out = orig(*a, **kw)
        captured.update(out["data"])
        return out

    res = {"method_hash": M.METHOD.hash(), "run": RUN, "relative_method_hash": run.settings["relative_method_hash"],
           "base": base, "draws": []}
    with tempfile.TemporaryDirectory() as td, using(stored_method(run, {"null_draws": 0})):  # ranking only
        ref, draws = calibration_draws(run, DRAWS, td)
        try:
            D.consistent_fits = capture
            for name, ds in draws:
                j = int(name[4:])
                captured.clear()
                d = D.diagnose(ds, base=base, resamples=0, reference=ref, serial=True, progress=False)
                r = d.ranking[d.ranking["ok"].astype(bool) & np.isfinite(d.ranking["dBIC"].astype(float))]
                as_run = {str(e): float(v) for e, v in zip(r["effect"], r["dBIC"])}
                spec0 = d.spec
                ks = [n for n, f in d.fits.items() if f.located is not None and f.solution is not None
                      and captured["ref_fits"].get(n) is not None and D._nested(D.effects_mod.EFFECTS[n])
                      and D._status(f.solution)[1]]
                sols = D.solve_many({"own-baseline-N": (spec0, [(f"N|{n}", ds.gait, d.fits[n].solution) for n in ks]),
                                     "own-baseline-R": (spec0, [(f"R|{n}", ref.gait, captured["ref_fits"][n].solution)
                                                                for n in ks])}, serial=True, progress=False)
                own, one, why = {}, {}, {}
                for n in ks:
                    bn, br = sols.get(f"N|{n}"), sols.get(f"R|{n}")
                    if bn is None or br is None or not (D._status(bn)[1] and D._status(br)[1]):
                        why[n] = "baseline re-solve did not converge"
                        continue
                    loc0 = L.locate(bn, R.relative_data(ds, ref, br))
                    rk = float(d.fits[n].located.rss)
                    own[n] = D._criteria(loc0.rss, rk, d.fits[n].n_params, loc0.n_eff)[1]
                    one[n] = D._criteria(d.located.rss, rk, d.fits[n].n_params, d.located.n_eff)[1]
                row = {"draw": name, "stored": calib["dBIC"][j], "as_run": stats(as_run), "one_baseline": stats(one),
                       "own_baseline": stats(own),
                       "not_compared": why, "candidates": len(d.fits)}
                res["draws"].append(row)
                print(json.dumps({"draw": name, **{k: {q: row[k][q] for q in ("rank1", "rank1_dBIC", "median_dBIC",
                                                                                  "ranked")}
                                                   for k in ("as_run", "one_baseline", "own_baseline")}}), flush=True)
        finally:
            D.consistent_fits = orig
    OUT.write_text(json.dumps(res, indent=1))
    lines = ["| draw | run | first ranked (ΔBIC) | median candidate ΔBIC | candidates compared |", "|---|---|---|---|---|"]
    for row in res["draws"]:
        for label in ("as_run", "one_baseline", "own_baseline"):
            x = row[label]
            first = f"{x['rank1']} ({x['rank1_dBIC']:.1f})" if x["rank1"] else "—"
            med = f"{x['median_dBIC']:.1f}" if x["median_dBIC"] is not None else "—"
            lines.append(f"| {row['draw']} | {label} | {first} | {med} | {x['ranked']} of {row['candidates']} |")
    OUT.with_suffix(".md").write_text(
        f"# Each candidate against the baseline in its own optimum ({RUN}, relative method "
        f"{res['relative_method_hash']})\n\nEach calibration draw ranked as the run ranked it (`as_run`: every "
        "candidate against the one baseline; a candidate whose relative gap is above the baseline's is not ranked), "
        "the same with every candidate compared (`one_baseline`: ΔBIC > 0 where its gap is above the baseline's) "
        "and against the baseline re-solved from the candidate's own fits of the draw and the reference "
        "(`own_baseline`); ranking only.\n\n" + "\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
