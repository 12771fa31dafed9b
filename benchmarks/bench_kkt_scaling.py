"""Cost of one interior-point iteration vs mesh size, measured at a fixed point.

    .venv/bin/python benchmarks/bench_kkt_scaling.py            # SK 5–80, MSK and NMSK 5–20 intervals, ≈ 10 min
    .venv/bin/python benchmarks/bench_kkt_scaling.py --quick    # SK 2–4 intervals (checks the script)

IPOPT's average time per iteration (``bench_scaling.py``) mixes the cost of one iteration
with how many times IPOPT factorises per iteration, which depends on the path it takes
(every inertia correction is another factorisation; a run far from its solution corrects
more often). This benchmark measures the pieces of one iteration at a fixed point — the
data-based initial guess of the natural-gait problem (``natural_gait_spec``, LGR with 5
points per interval) — so that only the mesh size changes:

* ``evaluations``: one call of each NLP function IPOPT calls per iteration — Lagrangian
  Hessian, constraint Jacobian, objective gradient, constraints, objective (the functions
  of the ``nlpsol`` object itself, exact derivatives by CasADi AD); multipliers fixed
  (seeded random, 0.01 scale);
* ``factorisation``: one numeric LDLᵀ factorisation of the KKT matrix
  [[H + Σ, Jᵀ], [J, −δ I]] (Σ = 1 on the diagonal, standing in for the barrier term;
  δ = 1e-8) by MUMPS through CasADi's ``Linsol`` in symmetric mode (the same MUMPS library
  as IPOPT's; CasADi's other MUMPS settings, e.g. ordering and pivoting, are its defaults,
  not IPOPT's), after one symbolic analysis
  (``nfact``); and ``Linsol.solve`` for one right-hand side, which in CasADi's interface
  factorises again and back-solves — the linear-algebra cost of one IPOPT search direction
  without inertia correction (``factor_solve_ms``).

Median of ``--repeats`` timings per quantity; each problem size in its own process (one BLAS
thread). The growth exponent b of ``t ∝ nodes^b`` is fitted per model and quantity
(:func:`gaitlib.studies.performance.fit_power_law`). Writes
``benchmarks/results/kkt_scaling.json`` and ``kkt_scaling.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

OUT = Path(__file__).resolve().parent / "results"
ENV1 = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
SIZES = {"SK": (5, 10, 20, 40, 80), "MSK": (5, 10, 20), "NMSK": (5, 10, 20)}
QUICK = {"SK": (2, 4)}
QUANTITIES = ("hessian_ms", "jacobian_ms", "other_evals_ms", "evaluations_ms", "factorisation_ms",
              "factor_solve_ms", "iteration_ms")


def _median_ms(fn, repeats: int) -> float:
    import numpy as np

    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(ts))


def child(model: str, n: int, repeats: int) -> dict:
    import casadi as ca
    import dataclasses

    import numpy as np
    import scipy.sparse as sp

    from gaitlib import blas

    blas.pin()  # the Makefile's BLAS settings (unless set)
    from gaitlib import ocp
    from gaitlib.problems import gait as gait_ocp
    from gaitlib.studies import gait

    spec = dataclasses.replace(gait.natural_gait_spec(model), n_intervals=n, degree=5)
    gp = gait_ocp.build(spec)
    t0 = time.perf_counter()
    nlp = ocp.transcribe(gp.problem, gp.mesh, gp.options)
    build = time.perf_counter() - t0
    w = np.clip(nlp.initial_point(gp.guess), nlp.lbw, nlp.ubw)
    p = np.concatenate([nlp.data_vector(None), nlp.goal_weights(None)])
    ng = int(nlp.lbg.size)
    lam = 0.01 * np.random.default_rng(0).standard_normal(ng)
    S = nlp.solver
    f_hess, f_jac = S.get_function("nlp_hess_l"), S.get_function("nlp_jac_g")
    f_grad, f_g, f_f = S.get_function("nlp_grad_f"), S.get_function("nlp_g"), S.get_function("nlp_f")

    def call(fn, *args):
        return fn(*args)

    hess_args = [w, p, 1.0, lam]
    H = f_hess(*hess_args)
    H = H[0] if isinstance(H, (list, tuple)) else H
    J = f_jac(w, p)
    J = J[1] if isinstance(J, (list, tuple)) else J
    t = {"hessian_ms": _median_ms(lambda: call(f_hess, *hess_args), repeats),
         "jacobian_ms": _median_ms(lambda: call(f_jac, w, p), repeats)}
    t["other_evals_ms"] = (_median_ms(lambda: call(f_grad, w, p), repeats) + _median_ms(lambda: call(f_g, w, p), repeats)
                           + _median_ms(lambda: call(f_f, w, p), repeats))
    t["evaluations_ms"] = t["hessian_ms"] + t["jacobian_ms"] + t["other_evals_ms"]

    def to_sp(m):
        m = ca.DM(m)
        r, c = m.sparsity().get_triplet()
        return sp.csc_matrix((np.asarray(m.nonzeros()).ravel(), (r, c)), shape=m.shape)

    Hs, Js = to_sp(H), to_sp(J)
    Hs = sp.triu(Hs) + sp.triu(Hs, 1).T  # nlp_hess_l gives the upper triangle
    nw = Hs.shape[0]
    K = sp.bmat([[Hs + sp.identity(nw), Js.T], [Js, -1e-8 * sp.identity(ng)]], format="csc")
    Kd = ca.DM(ca.Sparsity(K.shape[0], K.shape[1], K.indptr.tolist(), K.indices.tolist()), K.data)
    L = ca.Linsol("kkt", "mumps", Kd.sparsity(), {"symmetric": True})  # LDLᵀ, as IPOPT uses MUMPS
    t0 = time.perf_counter()
    L.sfact(Kd)
    symbolic = 1e3 * (time.perf_counter() - t0)
    t["factorisation_ms"] = _median_ms(lambda: L.nfact(Kd), repeats)
    rhs = ca.DM(np.ones(K.shape[0]))
    L.nfact(Kd)
    t["factor_solve_ms"] = _median_ms(lambda: L.solve(Kd, rhs), repeats)
    t["iteration_ms"] = t["evaluations_ms"] + t["factor_solve_ms"]
    x = np.asarray(L.solve(Kd, rhs)).ravel()
    # the factorisation is a real one: relative residual ‖Kx − b‖∞ / (‖K‖∞ ‖x‖∞ + ‖b‖∞)
    t["solve_residual"] = float(np.max(np.abs(K @ x - 1.0)) / (abs(K).sum(axis=1).max() * np.max(np.abs(x)) + 1.0))
    return {"model": model, "n_intervals": n, "degree": 5, "nodes": 5 * n, "n_variables": nw, "n_constraints": ng,
            "kkt_dim": int(K.shape[0]), "kkt_nnz": int(K.nnz), "hessian_nnz": int(Hs.nnz), "jacobian_nnz": int(Js.nnz),
            "symbolic_ms": symbolic, "build_s": build, "repeats": repeats, **t}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--child", nargs=2, default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print("RESULT " + json.dumps(child(args.child[0], int(args.child[1]), args.repeats)), flush=True)
        return 0
    from report import md_table, write_report

    from gaitlib.studies import performance as perf

    env = {**os.environ, **ENV1}
    rows = []
    for model, ns in (QUICK if args.quick else SIZES).items():
        for n in ns:
            load = os.getloadavg()[0]
            p = subprocess.run([sys.executable, __file__, "--child", model, str(n), "--repeats", str(args.repeats)],
                               env=env, capture_output=True, text=True)
            res = [ln for ln in p.stdout.splitlines() if ln.startswith("RESULT ")]
            if p.returncode or not res:
                print(f"{model} {n}: error\n{p.stderr[-1500:]}", flush=True)
                rows.append({"model": model, "n_intervals": n, "error": p.stderr[-500:], "load_at_start": load})
                continue
            r = {**json.loads(res[-1][7:]), "load_at_start": load}
            rows.append(r)
            print(f"{model} {n:3d} × 5: evaluations {r['evaluations_ms']:8.1f} ms, factorisation "
                  f"{r['factorisation_ms']:8.1f} ms, factorisation + solve {r['factor_solve_ms']:6.1f} ms, KKT {r['kkt_dim']} "
                  f"({r['kkt_nnz']} nnz), load {load:.2f}", flush=True)
    ok = [r for r in rows if "error" not in r]
    fits = []
    for model in dict.fromkeys(r["model"] for r in ok):
        rr = [r for r in ok if r["model"] == model]
        for q in QUANTITIES:
            f = perf.fit_power_law([r["nodes"] for r in rr], [r[q] for r in rr])
            fits.append({"model": model, "quantity": q, **f, "nodes": ", ".join(str(r["nodes"]) for r in rr)})
    doc = {"measured": datetime.now(timezone.utc).isoformat(timespec="seconds"),
           "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
           "code": __import__("gaitlib.cache").cache.fingerprint(), "quick": args.quick,
           "note": ("loads at start " + ", ".join(f"{r['load_at_start']:.2f}" for r in rows)),
           "rows": rows, "fits": fits}
    stem = "kkt_scaling_quick" if args.quick else "kkt_scaling"
    cols = ["model", "n_intervals", "nodes", "kkt_dim", "kkt_nnz", *QUANTITIES, "load_at_start"]
    md = [f"# One iteration's pieces at a fixed point vs mesh size ({doc['measured']}, {doc['machine']})", ""]
    md += md_table(cols, rows)
    md += ["", "| model | quantity | exponent b | ± | R² | nodes |", "|---|---|---|---|---|---|"]
    md += [f"| {f['model']} | {f['quantity']} | {f['exponent']:.3f} | {f.get('exponent_se', float('nan')):.3f} | "
           f"{f['r2']:.4f} | {f['nodes']} |" for f in fits]
    write_report(OUT, stem, doc, md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
