"""Fewer iterations from a warm-start chain? Chapter 7's speed classes started from the
neighbouring speed's solution (issue 22, lever "warm-start chains: Ch 7 from the
neighbouring speed").

    .venv/bin/python benchmarks/bench_warm_chain.py                 # MSK and NMSK, 20 × 5, ≈ 10 min on 2 workers
    .venv/bin/python benchmarks/bench_warm_chain.py --reading thesis   # the same for the thesis's reading
    .venv/bin/python benchmarks/bench_warm_chain.py --quick         # 5 × 3 mesh: checks the script

The book's Chapter 7 runs (its reading: the swing foot unloaded; ``--reading thesis``: the
problem as printed, which the chapter shows beside them) start from their model's Ch 5
solution (the Free data tracked), time-scaled to the class's cycle (:data:`gaitlib.studies.predictive.GUESS_POLICY_CH7`: NMSK
from the whole solution, MSK from the thesis's partial guess). The chain starts the classes
next to Free from the whole Ch 5 solution (Slow, Fast) and each outer class from its
neighbour's solution (VerySlow from Slow, VeryFast from Fast), time-scaled the same way
(:func:`gaitlib.studies.predictive.run_guess`). Same specs as the book (Table 7.1's DT, the
time-scaled Free data), same solver; only the start differs. Per run: IPOPT status,
iterations, solve and build time as recorded, objective, the validity gates, and the RMS
distance of the joint angles from the book's run of the same class (degrees; another local
optimum shows as a distance of degrees, the same solution as ≈ 0).

The book's runs are read from the solution store (``solutions/``); the chained runs are
solved on a dask LocalCluster (2 workers) and kept in the user cache. Writes
``results/warm_chain.json`` / ``.md``.
"""

from __future__ import annotations

import argparse
import sys
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from report import machine_info, md_table, write_report  # noqa: E402

from gaitlib import blas, data as data_mod, validity  # noqa: E402
from gaitlib import conventions as cv  # noqa: E402
from gaitlib.problems import gait as gait_ocp  # noqa: E402
from gaitlib.studies import predictive as pr  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
#: class → the class whose solution starts it (None: the model's Ch 5 solution)
CHAIN = {"Slow": None, "Fast": None, "VerySlow": "Slow", "VeryFast": "Fast"}


def _row(model: str, cls: str, start: str, sol, book=None) -> dict:
    st = sol.stats
    rms = None
    if book is not None:
        joints = list(cv.JOINTS)
        t = np.linspace(0.0, 1.0, 101)
        a = np.column_stack([np.interp(t, sol.q.index / sol.q.index[-1], sol.q[j]) for j in joints])
        b = np.column_stack([np.interp(t, book.q.index / book.q.index[-1], book.q[j]) for j in joints])
        rms = float(np.rad2deg(np.sqrt(np.mean((a - b) ** 2))))
    return {"model": model, "class": cls, "start": start, "status": st["status"], "iterations": int(st["iterations"]),
            "solve_s": float(st["solve_time_s"]), "build_s": float(st.get("build_time_s") or 0.0),
            "objective": float(st["objective"]), "gates": validity.check(sol).label(), "rms_from_book_deg": rms}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="5 × 3 mesh (the book's runs are then solved too)")
    ap.add_argument("--models", default="MSK,NMSK")
    ap.add_argument("--reading", choices=("book", "thesis"), default="book",
                    help="the book's reading of the Ch 7 runs (the swing unloaded; Chapter 7's main runs) or the "
                         "thesis's (the problem as printed)")
    args = ap.parse_args(argv)
    blas.pin()
    mesh = dict(n_intervals=5, degree=3) if args.quick else dict(n_intervals=20, degree=5)
    models = args.models.split(",")
    book = {m: pr.speed_study((m,), **mesh, progress=False, reading=args.reading) for m in models}  # the store's runs (or solved: --quick)
    gaits = {c: data_mod.load_gait_data(c) for c in pr.CH7_CLASSES}
    rows = []
    chained: dict = {}
    for wave in ([c for c, s in CHAIN.items() if s is None], [c for c, s in CHAIN.items() if s is not None]):
        specs, guesses = {}, {}
        for m in models:
            res = book[m]
            for c in wave:
                name = f"{m} {c}"
                src = res.baselines[m] if CHAIN[c] is None else chained[f"{m} {CHAIN[c]}"]
                g = gaits[c]
                specs[name] = res.specs[name]
                guesses[name] = pr.run_guess(src, "ch5", cycle_time=g.cycle_time, stride=g.speed * g.cycle_time)
        recs = gait_ocp.solve_specs(specs, guesses=guesses, n_workers=2, progress=True)
        for name, r in recs.items():
            if r.value is None:
                raise RuntimeError(f"{name}: {r.status}: {r.error}")
            chained[name] = r.value
    for m in models:
        res = book[m]
        for c in pr.CH7_CLASSES:
            name = f"{m} {c}"
            ref = res.solutions[name]
            rows.append(_row(m, c, f"book ({res.guess[m]} guess)", ref))
            start = "the Ch 5 solution (whole)" if CHAIN[c] is None else f"the {CHAIN[c]} run's solution"
            rows.append(_row(m, c, f"chain: {start}", chained[name], ref))
    summary = []
    for m in models:
        for kind in ("book", "chain"):
            rs = [r for r in rows if r["model"] == m and r["start"].startswith(kind)]
            summary.append({"model": m, "start": kind, "converged": sum(r["status"] == "Solve_Succeeded" for r in rs),
                            "valid": sum(r["gates"] == "valid" for r in rs), "runs": len(rs),
                            "iterations": sum(r["iterations"] for r in rs), "solve_s": sum(r["solve_s"] for r in rs)})
    doc = {"measured": datetime.now(timezone.utc).isoformat(timespec="seconds"), "machine": machine_info(),
           "quick": args.quick, "mesh": mesh, "reading": args.reading, "rows": rows, "summary": summary}
    md = [f"# Ch 7 from the neighbouring speed: a warm-start chain, {args.reading}'s reading ({doc['measured']})", "",
          f"Machine: {doc['machine']['cpu']}, {doc['machine']['cores']} cores; mesh {mesh['n_intervals']} × "
          f"{mesh['degree']}. The book's runs as stored (their times as recorded at their solve); the chained runs "
          "solved here on 2 workers.", ""]
    md += md_table(list(rows[0]), rows) + [""] + md_table(list(summary[0]), summary)
    write_report(OUT, "warm_chain" + ("_quick" if args.quick else "") + ("" if args.reading == "book" else "_thesis"),
                 doc, md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
