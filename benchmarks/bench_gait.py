"""Natural-gait solve times: SK Eq 4.11 and MSK Eq 5.33
at the full mesh (20 × 5 LGR), from the data-based guess and warm-started, with the exact
Hessian and with L-BFGS.

    .venv/bin/python benchmarks/bench_gait.py [--repeats N] [--skip-lbfgs]

Writes ``benchmarks/results/gait.json`` and ``gait.md``: per run IPOPT status, iterations,
solve and build wall time, time per iteration, objective, max violation, and IPOPT's own
split of the solve time (function/derivative evaluation vs the rest, i.e. mostly MUMPS).
Thesis times beside ours: Sec 4.3.3 (11 min, SK with contact identification), Sec 5.2.2
(2 h, MSK). Nothing is cached: every run is solved here.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import platform
import time
from datetime import datetime, timezone
from pathlib import Path

from gaitlib import blas

blas.pin()  # the Makefile's BLAS settings (unless set), before numpy is imported

from gaitlib import ocp  # noqa: E402
from gaitlib.problems import gait as gait_ocp  # noqa: E402
from gaitlib.studies import gait  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"


def _row(label, sol, thesis, note=""):
    st = sol.stats
    t = sol.solution.info.get("ipopt_t_wall", {})
    evals = sum(v for k, v in t.items() if k.startswith("t_wall_nlp_"))
    return {"run": label, "status": st["status"], "iterations": st["iterations"],
            "solve_s": round(st["solve_time_s"], 2), "build_s": round(st["build_time_s"], 2),
            "ms_per_iteration": round(1e3 * st["time_per_iteration_s"], 1),
            "function_evals_s": round(evals, 2), "ipopt_rest_s": round(st["solve_time_s"] - evals, 2),
            "objective": st["objective"], "max_violation": st["max_violation"],
            "n_variables": st["n_variables"], "thesis": thesis, "note": note}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--skip-lbfgs", action="store_true")
    args = ap.parse_args(argv)
    rows = []
    for rep in range(args.repeats):
        sk_spec = gait.natural_gait_spec("SK")
        sk = gait_ocp.solve(sk_spec)
        rows.append(_row("SK Eq4.11, data guess", sk, "11 min (Sec 4.3.3; 39 contact parameters identified)"))
        msk_spec = gait.natural_gait_spec("MSK")
        gp = gait_ocp.build(msk_spec)
        t0 = time.perf_counter()
        nlp = ocp.transcribe(gp.problem, gp.mesh, gp.options)
        build = time.perf_counter() - t0
        for label, guess in (("MSK Eq5.33, data guess", gp.guess),
                             ("MSK Eq5.33, warm start from SK", gait_ocp.warm_start(gp, sk))):
            sol = gait_ocp.postprocess(gp, nlp.solve(guess))
            sol.stats["build_time_s"] = build
            rows.append(_row(label, sol, "2 h (Sec 5.2.2)", "same NLP object: built once"))
        if not args.skip_lbfgs and rep == 0:
            lm = dataclasses.replace(msk_spec, hessian="limited-memory", max_iter=3000)
            sol = gait_ocp.solve(lm)
            rows.append(_row("MSK Eq5.33, data guess, L-BFGS", sol, "2 h (Sec 5.2.2)"))
        for r in rows[-4:]:
            print(r)
    OUT.mkdir(exist_ok=True)
    meta = {"measured": datetime.now(timezone.utc).isoformat(timespec="seconds"),
            "machine": f"{platform.machine()}, {platform.processor() or ''} {__import__('os').cpu_count()} cores, "
                       f"Python {platform.python_version()}",
            "code": __import__("gaitlib.cache").cache.fingerprint(), "rows": rows}
    (OUT / "gait.json").write_text(json.dumps(meta, indent=1, default=str))
    cols = ["run", "status", "iterations", "solve_s", "ms_per_iteration", "function_evals_s", "ipopt_rest_s",
            "build_s", "objective", "thesis"]
    md = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        md.append("| " + " | ".join(f"{r[c]:.4g}" if isinstance(r[c], float) else str(r[c]) for c in cols) + " |")
    (OUT / "gait.md").write_text(f"Measured {meta['measured']} on {meta['machine']}\n\n" + "\n".join(md) + "\n")
    print("\n".join(md))


if __name__ == "__main__":
    main()
