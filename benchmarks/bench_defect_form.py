"""The collocation defects in differential vs integral form on the book's gait problems.

    .venv/bin/python benchmarks/bench_defect_form.py             # the problems below, 20 × 5, ≈ 30 min
    .venv/bin/python benchmarks/bench_defect_form.py --quick     # SK Eq 4.11 on 4 × 5 (checks the script)

``GaitSpec(defects="integral")`` (:func:`gaitlib.collocation.integral_form`) multiplies each
interval's defects X Aᵀ − h F Bᵀ by the inverse of their end columns: the same equations and
optimum set, another row scaling — and denser rows (each row reads every collocation node's
dynamics of its interval instead of one). IPOPT's path changes: iterations, time per
iteration and, on these non-convex problems, possibly the local optimum reached. Each problem
is solved from the same data-based guess in both forms, on the per-node derivative path with
compiled node functions (the fastest path, ``benchmarks/results/e2e.md``), in one process,
one BLAS thread. The first solve of a structure compiles its node functions (not timed: the
solve time is IPOPT's call). Writes ``benchmarks/results/defect_form.json`` and ``.md``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
from datetime import datetime, timezone
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import casadi as ca  # noqa: E402

from gaitlib.problems import gait as gait_ocp  # noqa: E402
from gaitlib.studies import gait as gait_study  # noqa: E402
from report import machine_info, write_report  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
#: (label, spec keyword arguments): the CLI's MSK DT Free, and the book's natural-gait problems
PROBLEMS = (
    ("SK Eq4.11 (book)", dict(model="SK", reading="book")),
    ("MSK DT (gaitlib run gait)", dict(model="MSK", cost="DT", reading="thesis")),
    ("MSK Eq5.33 (book)", dict(model="MSK", reading="book")),
    ("NMSK Eq5.55 (book)", dict(model="NMSK", reading="book")),
)
FORMS = ("differential", "integral")


def solve(label: str, kw: dict, form: str, n_intervals: int) -> dict:
    kw = dict(kw)
    model, cost, reading = kw.pop("model"), kw.pop("cost", None), kw.pop("reading")
    spec = gait_study.natural_gait_spec(model, cost, "Free", reading=reading, n_intervals=n_intervals,
                                        derivatives="nodes", defects=None if form == "differential" else form)
    gp = gait_ocp.build(spec)
    gp = dataclasses.replace(gp, options=dataclasses.replace(gp.options, compiled=True))
    sol = gait_ocp.solve(gp)
    st = sol.stats
    row = {"problem": label, "form": form, "mesh": f"{n_intervals} x {spec.degree}", "status": st["status"],
           "iterations": st["iterations"], "solve_s": round(st["solve_time_s"], 2),
           "ms_per_iteration": round(1e3 * st["solve_time_s"] / max(st["iterations"], 1), 1),
           "objective": st["objective"], "max_violation": st["max_violation"],
           "n_variables": st["n_variables"], "n_constraints": st["n_constraints"]}
    print(json.dumps(row), flush=True)
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--intervals", type=int, default=20)
    ap.add_argument("--only", nargs="+", default=None, help="labels (prefixes) of PROBLEMS to run")
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    problems = PROBLEMS if not args.quick else PROBLEMS[:1]
    if args.only:
        problems = [p for p in problems if any(p[0].startswith(o) for o in args.only)]
    n = 4 if args.quick else args.intervals
    started, load_start = datetime.now(timezone.utc).isoformat(timespec="seconds"), list(os.getloadavg())
    rows = [solve(label, kw, form, n) for label, kw in problems for form in FORMS]
    if args.quick:
        return rows
    machine = machine_info()
    meta = {"measured": started, "load_average_start": load_start, "machine": machine,
            "casadi": ca.__version__, "python": sys.version.split()[0],
            "command": "python benchmarks/bench_defect_form.py " + " ".join(argv if argv is not None else sys.argv[1:])}
    cols = ["problem", "form", "mesh", "status", "iterations", "solve_s", "ms_per_iteration", "objective",
            "max_violation"]
    lines = [f"# Defects in differential vs integral form ({started}, {machine['cpu']}; load average at start "
             f"{load_start[0]:.2f})", "", f"`{meta['command']}`. Method: the module docstring of "
             "`benchmarks/bench_defect_form.py`.", "", "| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    lines += ["| " + " | ".join(f"{r[c]:.4g}" if isinstance(r[c], float) else str(r[c]) for c in cols) + " |"
              for r in rows]
    write_report(OUT, "defect_form", {"meta": meta, "rows": rows}, lines)
    return rows


if __name__ == "__main__":
    main()
