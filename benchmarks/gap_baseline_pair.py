"""Why do some null draws still credit every candidate alike after revision 7? An experiment on
Chapter 8's paired run of revision 7 on revision 6's draws (``gap_paired.py
reference_fit_rev6``; issue 25), outside the frozen method.

    GAITLIB_SOLUTIONS=<cache> .venv/bin/python benchmarks/gap_baseline_pair.py   # reloads the run's solves

The baseline's relative gap is [F(N) − N] − [F(R) − R]: the model's own misfit cancels only
if its fit of the draw N and its fit of the reference R stand in the same optimum. The
method keeps, on each side, the lowest objective it reaches (the reference from the
candidates' fits, the draw from the candidates' fits, then the self-consistency rounds),
and the two sides' lowest optima need not be the same one. Hypothesis: in a common-mode
draw they are not. Test: each calibration draw named in :data:`DRAWS` is regenerated from
its stored seed and diagnosed relative to the reference (ranking only, no calibration) as
the run made it (``as_run``), and with the baseline's two fits chosen as a *pair*
(``pair``): of (F(N), R re-solved from F(N)) and (N re-solved from F(R), F(R)), the pair
with the lower sum of the two objectives — each pair one optimum reached from one start.
Reported per draw and run: the first-ranked effect and ΔBIC, the median ranked candidate's
ΔBIC (≤ −20: common mode), the baseline's objectives on N and R.

Writes ``results/gap_validation/baseline_pair.json`` and ``.md``.
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
OUT = HERE / "results" / "gap_validation" / "baseline_pair.json"

#: The paired run whose calibration draws are re-diagnosed, and the draws: its four
#: common-mode draws (median candidate ΔBIC ≤ −20) and four others.
RUN = "reference_fit_rev6"
DRAWS = ("null0", "null7", "null11", "null15", "null1", "null2", "null6", "null16")


def summary(d) -> dict:
    r = d.ranking[d.ranking["ok"].astype(bool) & np.isfinite(d.ranking["dBIC"].astype(float))]
    dbic = {str(e): float(v) for e, v in zip(r["effect"], r["dBIC"])}
    rf = d.reference_fit
    return {"rank1": str(r.iloc[0]["effect"]) if len(r) else None, "rank1_dBIC": min(dbic.values()) if dbic else None,
            "median_dBIC": float(np.median(list(dbic.values()))) if dbic else None, "ranked": len(dbic),
            "dBIC": dbic, "objective_N": float(d.baseline.stats["objective"]),
            "objective_R": float(rf.stats["objective"]) if rf is not None else None}


def paired_consistent(original):
    """``consistent_fits`` with the baseline's two fits then chosen as a pair (module docstring)."""
    from gaitlib.gap import diagnose as D

    def wrapped(spec0, ref, ref_fit, ref_fits, datasets, bases, fits, names, **kw):
        out = original(spec0, ref, ref_fit, ref_fits, datasets, bases, fits, names, **kw)
        kw = {k: v for k, v in kw.items() if k != "method"}
        for k, o in out.items():
            n_fit, r_fit = o["base"], o["ref_fit"]
            res = D.solve_many({"pair-R": (spec0, [(f"{k}|R", ref.gait, n_fit)]),
                                "pair-N": (spec0, [(f"{k}|N", datasets[k].gait, r_fit)])}, **kw)
            r_of_n, n_of_r = res.get(f"{k}|R"), res.get(f"{k}|N")
            pairs = [("data's", n_fit, r_of_n), ("reference's", n_of_r, r_fit)]
            ok = [(a, n, r) for a, n, r in pairs if n is not None and r is not None and D._status(n)[1]
                  and D._status(r)[1]]
            side, n_best, r_best = min(ok, key=lambda p: p[1].stats["objective"] + p[2].stats["objective"])
            o["moved"]["baseline_pair"] = {
                "from": side, "sums": {a: float(n.stats["objective"] + r.stats["objective"]) for a, n, r in ok}}
            o["base"], o["ref_fit"] = n_best, r_best
        return out

    return wrapped


def main() -> int:
    from gap_paired import calibration_draws, stored_method, using

    from gaitlib.gap import diagnose as D
    from gaitlib.gap import method as M
    from gaitlib.studies import gap as gap_study

    run = gap_study.stored_paired(RUN)
    calib = run.unedited["null_calibration"]
    base = run.settings["base"]
    orig = D.consistent_fits
    res = {"method_hash": M.METHOD.hash(), "run": RUN, "relative_method_hash": run.settings["relative_method_hash"],
           "base": base, "draws": []}
    with tempfile.TemporaryDirectory() as td, using(stored_method(run, {"null_draws": 0})):  # ranking only
        ref, draws = calibration_draws(run, DRAWS, td)
        try:
            for name, ds in draws:
                row = {"draw": name, "stored": calib["dBIC"][int(name[4:])]}
                for label, fn in (("as_run", orig), ("pair", paired_consistent(orig))):
                    D.consistent_fits = fn
                    d = D.diagnose(ds, base=base, resamples=0, reference=ref, serial=True)
                    row[label] = summary(d)
                    row[label]["moved"] = (d.settings["reference"].get("moved") or {}).get("baseline_pair")
                res["draws"].append(row)
                print(json.dumps({k: (v if k == "draw" else {q: v[q] for q in ("rank1", "rank1_dBIC", "median_dBIC")}
                                      if isinstance(v, dict) and "rank1" in v else None)
                                  for k, v in row.items() if k != "stored"}), flush=True)
        finally:
            D.consistent_fits = orig
    OUT.write_text(json.dumps(res, indent=1))
    lines = ["| draw | run | first ranked (ΔBIC) | median candidate ΔBIC | ranked | baseline objective N / R | pair from |",
             "|---|---|---|---|---|---|---|"]
    for row in res["draws"]:
        for label in ("as_run", "pair"):
            x = row[label]
            lines.append(f"| {row['draw']} | {label} | {x['rank1']} ({x['rank1_dBIC']:.1f}) | {x['median_dBIC']:.1f} | "
                         f"{x['ranked']} | {x['objective_N']:.4f} / {x['objective_R']:.4f} | "
                         f"{(x['moved'] or {}).get('from', '—')} |")
    OUT.with_suffix(".md").write_text(
        f"# The baseline's fits of the draw and of the reference as a pair ({RUN}, relative method "
        f"{res['relative_method_hash']})\n\nEach calibration draw diagnosed as the run made it (`as_run`) and with the "
        "baseline's two fits chosen as the pair with the lower sum of objectives (`pair`); ranking only.\n\n"
        + "\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
