"""Building the NLP: whole-graph derivatives vs per-node derivatives, end to end.

    .venv/bin/python benchmarks/bench_build.py                    # SK, MSK, NMSK at 20 × 5, ≈ 20 min
    .venv/bin/python benchmarks/bench_build.py --models MSK       # one model
    .venv/bin/python benchmarks/bench_build.py --no-solve         # build times only

For each model, the book's natural-gait problem (SK Eq 4.11, MSK Eq 5.33, NMSK Eq 5.55, Free
speed, 20 × 5 LGR) is built twice in one process, one after the other, with
``SolverOptions(derivatives="graph")`` (CasADi differentiates the whole SX graph of the NLP:
the old default) and ``derivatives="nodes"`` (the per-node derivative functions assembled by
the chain rule: the default). Each NLP is then solved from the data-based guess. Per run:
the problem's own construction (model, data, reference), the symbolic NLP, the solver
construction, the solve (IPOPT status, iterations, ms per iteration, IPOPT's split of its
time between each function's evaluations and the rest, i.e. mostly MUMPS) and the end-to-end
sum. The two derivative paths give the same functions to round-off
(tests/test_node_derivatives.py); IPOPT may still take another path, so iterations and
objectives are reported, not assumed equal. Nothing is cached. Writes
``benchmarks/results/build.json`` and ``build.md``.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

from gaitlib import blas

blas.pin()  # the Makefile's BLAS settings (unless set), before numpy is imported

from gaitlib import cache, ocp  # noqa: E402
from gaitlib.problems import gait as gait_ocp  # noqa: E402
from gaitlib.studies import gait  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from report import machine_info, md_table, write_report  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
EVALS = ("nlp_f", "nlp_g", "nlp_grad_f", "nlp_jac_g", "nlp_hess_l")


def run(model: str, derivatives: str, solve: bool) -> dict:
    t0 = time.perf_counter()
    gp = gait_ocp.build(gait.natural_gait_spec(model))
    problem_s = time.perf_counter() - t0
    opts = dataclasses.replace(gp.options, derivatives=derivatives)
    tr = ocp.transcribe(gp.problem, gp.mesh, opts)
    row = {"model": model, "derivatives": derivatives, "problem_s": problem_s,
           "symbolic_s": tr.symbolic_time, "solver_s": tr.build_time - tr.symbolic_time,
           "build_s": problem_s + tr.build_time, "n_variables": tr.n_variables}
    if solve:
        sol = tr.solve(gp.guess)
        t = sol.info["ipopt_t_wall"]
        evals = {k: t.get("t_wall_" + k, 0.0) for k in EVALS}
        row.update(status=sol.status, iterations=sol.iterations, solve_s=sol.solve_time,
                   ms_per_iteration=1e3 * sol.solve_time / max(sol.iterations, 1),
                   evals_s=sum(evals.values()), **{k + "_s": v for k, v in evals.items()},
                   ipopt_rest_s=sol.solve_time - sum(evals.values()), objective=sol.objective,
                   e2e_s=problem_s + tr.build_time + sol.solve_time)
    print({k: (round(v, 3) if isinstance(v, float) else v) for k, v in row.items()}, flush=True)
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--models", default="SK,MSK,NMSK")
    ap.add_argument("--no-solve", action="store_true")
    args = ap.parse_args(argv)
    load = os.getloadavg()[0]
    rows = [run(m, d, not args.no_solve) for m in args.models.split(",") for d in ("graph", "nodes")]
    doc = {"measured": datetime.now(timezone.utc).isoformat(timespec="seconds"), "machine": machine_info(),
           "load_at_start": load, "code": cache.fingerprint(), "rows": rows}
    cols = ["model", "derivatives", "problem_s", "symbolic_s", "solver_s", "build_s"]
    if not args.no_solve:
        cols += ["status", "iterations", "solve_s", "ms_per_iteration", "evals_s", "nlp_hess_l_s", "ipopt_rest_s",
                 "e2e_s", "objective"]
    m = doc["machine"]
    md = [f"# Building the NLP: whole-graph vs per-node derivatives ({doc['measured']}, "
          f"{m.get('cpu', '')}, {m.get('cores', '')} cores, load {load:.2f})", "",
          "Book problems at 20 × 5 LGR from the data-based guess, nothing cached; build = the problem's "
          "construction + the symbolic NLP + the solver's construction (with derivatives); e2e = build + solve. "
          "`python benchmarks/bench_build.py`.", ""]
    md += md_table(cols, rows)
    write_report(OUT, "build", doc, md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
