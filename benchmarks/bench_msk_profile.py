"""Where the MSK data-tracking solve spends its time (its target: ≤ 20 s).

    .venv/bin/python benchmarks/bench_msk_profile.py            # full mesh, ≈ 10 min
    .venv/bin/python benchmarks/bench_msk_profile.py --quick    # 4 × 3 mesh, ≈ 1 min (checks the script)

The natural-gait MSK problem (``gaitlib.studies.gait.natural_gait_spec("MSK")``: Eq 5.33,
Free speed, 20 × 5 LGR, the data-based guess) is solved with IPOPT's own timing statistics
(``print_timing_statistics``) and iteration log, each run in its own process (one BLAS
thread), one after another:

* ``default``: the book's solver options;
* IPOPT option variants that might cut iterations or factorisations (initial barrier
  parameter, NLP scaling, bound push, Hessian-perturbation decrease factor) or the cost of
  a factorisation (MUMPS's fill-reducing ordering; IPOPT's default lets MUMPS choose), how
  fast the barrier parameter falls, IPOPT's inertia-free curvature test instead of inertia
  corrections, and (not an IPOPT option, key ``_env``) glibc's malloc settings. They are
  **measurements, not tuning**: a variant that is faster but lands in a different local
  optimum (objective) is not the same solve.

Per run: status, iterations, solve time, time per iteration, IPOPT's split — Lagrangian
Hessian, the other function/derivative evaluations, the linear systems (MUMPS: symbolic +
numeric factorisation + back-solves, "StdAugSystemSolverMultiSolve"), the rest — and how
many iterations needed a Hessian perturbation (the ``lg(rg)`` column: each such iteration
factorises the KKT matrix at least twice). Also, for SK and MSK at the same mesh, the size
of the expression graphs (SX instructions of the constraints and of the Lagrangian's
Hessian; ``ca.hessian`` on the NLP, as IPOPT's exact Hessian evaluates).

Writes ``benchmarks/results/msk_profile.json`` and ``msk_profile.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

OUT = Path(__file__).resolve().parent / "results"
ENV1 = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
VARIANTS = {
    "default": {},
    "mu_init = 1e-2": {"mu_init": 1e-2},
    "mu_init = 1e-3": {"mu_init": 1e-3},
    "nlp_scaling_max_gradient = 10": {"nlp_scaling_max_gradient": 10.0},
    "nlp_scaling_method = none": {"nlp_scaling_method": "none"},
    "bound_push = bound_frac = 1e-6": {"bound_push": 1e-6, "bound_frac": 1e-6},
    "perturb_dec_fact = 0.6": {"perturb_dec_fact": 0.6},
    "mumps_pivot_order = 0 (AMD)": {"mumps_pivot_order": 0},
    "mumps_pivot_order = 2 (AMF)": {"mumps_pivot_order": 2},
    "mumps_pivot_order = 6 (QAMD)": {"mumps_pivot_order": 6},
    "barrier_tol_factor = 100": {"barrier_tol_factor": 100.0},
    "barrier_tol_factor = 1000": {"barrier_tol_factor": 1000.0},
    "barrier_tol_factor = 100, mu_init = 1e-2": {"barrier_tol_factor": 100.0, "mu_init": 1e-2},
    "mu_linear_decrease_factor = 0.1": {"mu_linear_decrease_factor": 0.1},
    "neg_curv_test_tol = 1e-12 (inertia-free)": {"neg_curv_test_tol": 1e-12},
    # not an IPOPT option: glibc's malloc told not to return MUMPS's work arrays to the
    # system (no mmap/munmap per factorisation); the same arithmetic, so the same path
    "default, glibc malloc without mmap/trim": {"_env": {
        "GLIBC_TUNABLES": "glibc.malloc.mmap_threshold=4294967296:glibc.malloc.trim_threshold=4294967296"}},
}
TIMING = {"Lagrangian Hessian": "hessian_s", "Function Evaluations": "function_evals_s",
          "StdAugSystemSolverMultiSolve": "linear_systems_s", "OverallAlgorithm": "overall_s",
          "CheckConvergence": "check_convergence_s"}


def _spec(quick: bool, model: str = "MSK"):
    import dataclasses

    from gaitlib.studies import gait

    s = gait.natural_gait_spec(model)
    return dataclasses.replace(s, n_intervals=4, degree=3) if quick else s


def child(args) -> None:
    """One solve, IPOPT's log on stdout; the result as the last line (JSON)."""
    import dataclasses

    from gaitlib import blas

    blas.pin()  # the Makefile's BLAS settings (unless set)
    from gaitlib import ocp
    from gaitlib.problems import gait as gait_ocp

    gp = gait_ocp.build(_spec(args.quick))
    opts = dataclasses.replace(gp.options, print_level=5,
                               ipopt={**dict(gp.options.ipopt), "print_timing_statistics": "yes",
                                      **json.loads(args.child)})
    t0 = time.perf_counter()
    nlp = ocp.transcribe(gp.problem, gp.mesh, opts)
    build = time.perf_counter() - t0
    sol = nlp.solve(gp.guess)
    sys.stdout.flush()
    print("\nRESULT " + json.dumps({"status": sol.status, "iterations": sol.iterations,
                                    "solve_s": sol.solve_time, "build_s": build, "objective": sol.objective,
                                    "max_violation": sol.max_violation, "n_variables": int(nlp.lbw.size)}), flush=True)


def parse(log: str) -> dict:
    out = {}
    for line in log.splitlines():
        m = re.match(r"\s*([A-Za-z ]+?)\.*:\s+([\d.]+) \(sys:\s+([\d.]+) wall:\s+([\d.]+)\)", line)
        if m and m.group(1).strip() in TIMING:
            out[TIMING[m.group(1).strip()]] = float(m.group(4))
            if TIMING[m.group(1).strip()] == "linear_systems_s":  # system time: page faults of MUMPS's allocations
                out["linear_systems_sys_s"] = float(m.group(3))
    its = [ln.split() for ln in log.splitlines() if re.match(r"^\s*\d+r?\s+[-+\d.e]+\s+[\d.e+-]+\s", ln)]
    out["perturbed_iterations"] = sum(1 for t in its if len(t) > 6 and t[6] != "-")
    out["logged_iterations"] = len(its)
    return out


def graph_sizes(quick: bool) -> list[dict]:
    import casadi as ca

    from gaitlib import blas

    blas.pin()  # the Makefile's BLAS settings (unless set)
    from gaitlib import ocp
    from gaitlib.problems import gait as gait_ocp

    rows = []
    for model in ("SK", "MSK"):
        gp = gait_ocp.build(_spec(quick, model))
        nlp = ocp.transcribe(gp.problem, gp.mesh, gp.options)
        w, p, f, g = nlp.nlp["x"], nlp.nlp["p"], nlp.nlp["f"], nlp.nlp["g"]
        lam = ca.SX.sym("lam", g.shape[0])
        H = ca.Function("H", [w, p, lam], [ca.triu(ca.hessian(f + ca.dot(lam, g), w)[0])])
        G = ca.Function("G", [w, p], [g])
        rows.append({"model": model, "n_variables": int(w.shape[0]), "n_constraints": int(g.shape[0]),
                     "constraint_instructions": int(G.n_instructions()),
                     "hessian_instructions": int(H.n_instructions()), "hessian_nnz": int(H.sparsity_out(0).nnz())})
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--child", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child is not None:
        child(args)
        return 0
    env = {**os.environ, **ENV1}
    rows = []
    for name, opts in VARIANTS.items():
        ipopt = {k: v for k, v in opts.items() if k != "_env"}
        cmd = [sys.executable, __file__, "--child", json.dumps(ipopt)] + (["--quick"] if args.quick else [])
        load = os.getloadavg()[0]
        p = subprocess.run(cmd, env={**env, **opts.get("_env", {})}, capture_output=True, text=True)
        res = [ln for ln in p.stdout.splitlines() if ln.startswith("RESULT ")]
        if p.returncode or not res:
            rows.append({"variant": name, "ipopt_options": opts, "status": "error",
                         "error": (p.stderr or p.stdout)[-500:], "load_at_start": load})
            print(name, "error", flush=True)
            continue
        r = {"variant": name, "ipopt_options": opts, **json.loads(res[-1][7:]), **parse(p.stdout), "load_at_start": load}
        r["ms_per_iteration"] = 1e3 * r["solve_s"] / max(r["iterations"], 1)
        other = r.get("function_evals_s", 0.0) - r.get("hessian_s", 0.0)
        r["other_evals_s"] = other
        r["rest_s"] = r["solve_s"] - r.get("function_evals_s", 0.0) - r.get("linear_systems_s", 0.0)
        rows.append(r)
        print(f"{name}: {r['status']}, {r['iterations']} it, {r['solve_s']:.1f} s, objective {r['objective']:.4f}",
              flush=True)
    sizes = graph_sizes(args.quick)
    doc = {"measured": datetime.now(timezone.utc).isoformat(timespec="seconds"),
           "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
           "code": __import__("gaitlib.cache").cache.fingerprint(), "quick": args.quick,
           "runs": rows, "graph_sizes": sizes}
    from report import md_table, write_report

    stem = "msk_profile_quick" if args.quick else "msk_profile"
    cols = ["variant", "status", "iterations", "solve_s", "ms_per_iteration", "hessian_s", "other_evals_s",
            "linear_systems_s", "linear_systems_sys_s", "rest_s", "perturbed_iterations", "objective", "load_at_start"]
    md = [f"# MSK data tracking (Eq 5.33), full mesh: where the time goes ({doc['measured']}, {doc['machine']})", ""]
    md += md_table(cols, rows)
    md += ["", "Expression graphs (SX instructions; ca.hessian of the Lagrangian):", "",
           "| model | variables | constraints | constraint instructions | Hessian instructions | Hessian nnz |",
           "|---|---|---|---|---|---|"]
    md += [f"| {s['model']} | {s['n_variables']} | {s['n_constraints']} | {s['constraint_instructions']:,} | "
           f"{s['hessian_instructions']:,} | {s['hessian_nnz']:,} |" for s in sizes]
    write_report(OUT, stem, doc, md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
