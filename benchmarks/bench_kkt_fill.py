"""Why the linear algebra grows faster than the mesh: the symbolic fill of
the KKT matrix's factorisation, mesh by mesh.

    .venv/bin/python benchmarks/bench_kkt_fill.py            # SK and MSK, 5–80 intervals × 5, ≈ 8 min
    .venv/bin/python benchmarks/bench_kkt_fill.py --quick    # SK, 2–8 intervals × 3 (checks the script)

For the natural-gait problems (``gaitlib.studies.gait.natural_gait_spec``: SK Eq 4.11, MSK
Eq 5.33, LGR degree 5) the NLP is transcribed and IPOPT's KKT pattern assembled from the
solver's own derivative functions, [[H, Jᵀ], [J, 0]] (H: the Lagrangian's Hessian pattern,
J: the constraint Jacobian's, plus the diagonal IPOPT regularises). Its LDLᵀ factor is
computed *symbolically* (CasADi ``Sparsity.ldl`` with an approximate-minimum-degree
ordering — the family of MUMPS's default orderings, not MUMPS itself) with and without the
periodic-gait constraint. Per mesh: KKT rows and non-zeros, non-zeros of L (strictly lower:
CasADi does not store the unit diagonal), the largest column of L, and Σ_j c_j² over L's
column counts c_j — the flop count of the numeric factorisation up to a constant. Each quantity's growth exponent b (∝ nodes^b) is fitted
(:func:`gaitlib.studies.performance.fit_power_law`). No solve, no timing: the numbers are
exact and machine-independent.

Writes ``benchmarks/results/kkt_fill.json`` and ``kkt_fill.md``.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parent / "results"
QUANTITIES = ("kkt_nnz", "L_nnz", "L_max_column", "flops_proxy")


def kkt_pattern(transcription):
    """IPOPT's KKT pattern (symmetric, with the diagonal) of a :class:`gaitlib.ocp.Transcription`."""
    import casadi as ca

    s = transcription.solver
    H = s.get_function("nlp_hess_l").sparsity_out(0)
    J = s.get_function("nlp_jac_g").sparsity_out(1)
    nx, ng = J.size2(), J.size1()
    Jb = ca.horzcat(ca.vertcat(ca.Sparsity(nx, nx), J), ca.Sparsity(nx + ng, ng))
    return ca.diagcat(H + H.T, ca.Sparsity(ng, ng)) + Jb + Jb.T + ca.Sparsity.diag(nx + ng)


def fill(K) -> dict:
    """Symbolic LDLᵀ of pattern ``K`` with AMD ordering: non-zeros, largest column, flop proxy."""
    L, _ = K.ldl(True)
    cc = np.diff(np.asarray(L.colind())).astype(float)
    return {"kkt_rows": int(K.size1()), "kkt_nnz": int(K.nnz()), "L_nnz": int(L.nnz()),
            "L_max_column": int(cc.max()), "flops_proxy": float(np.sum(cc ** 2))}


def measure(model: str, n_intervals: int, degree: int, periodic: bool) -> dict:
    from gaitlib import ocp
    from gaitlib.problems import gait as gait_ocp
    from gaitlib.studies import gait

    spec = dataclasses.replace(gait.natural_gait_spec(model), n_intervals=n_intervals, degree=degree,
                               periodic=periodic)
    gp = gait_ocp.build(spec)
    t0 = time.perf_counter()
    T = ocp.transcribe(gp.problem, gp.mesh, gp.options)
    row = {"model": model, "periodic": periodic, "n_intervals": n_intervals, "degree": degree,
           "nodes": n_intervals * degree, "build_s": time.perf_counter() - t0}
    row.update(fill(kkt_pattern(T)))
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)

    from gaitlib import blas

    blas.pin()  # the Makefile's BLAS settings (unless set)

    from report import machine_info, md_table, write_report

    from gaitlib.studies.performance import fit_power_law

    if args.quick:
        grid, degree, models = (2, 4, 8), 3, ("SK",)
    else:
        grid, degree, models = (5, 10, 20, 40, 80), 5, ("SK", "MSK")
    rows = []
    for model in models:
        for periodic in (True, False):
            for n in grid:
                rows.append(measure(model, n, degree, periodic))
                print({k: rows[-1][k] for k in ("model", "periodic", "nodes", "L_nnz", "flops_proxy")}, flush=True)
    fits = []
    for model in models:
        for periodic in (True, False):
            sel = [r for r in rows if r["model"] == model and r["periodic"] == periodic]
            for q in QUANTITIES:
                f = fit_power_law([r["nodes"] for r in sel], [r[q] for r in sel])
                fits.append({"model": model, "periodic": periodic, "quantity": q, "exponent": f["exponent"],
                             "±": f["exponent_se"], "R²": f["r2"], "points": f["n_points"]})
    when = datetime.now(timezone.utc).isoformat(timespec="seconds")
    doc = {"measured": when, "machine": machine_info(), "quick": args.quick, "rows": rows, "fits": fits}
    md = [f"# Symbolic fill of the KKT factorisation ({when})", "",
          "Exact counts (no timing): CasADi `Sparsity.ldl` with AMD ordering on IPOPT's KKT pattern of the "
          "natural-gait problem; `flops_proxy` = Σ over L's columns of (column count)², the numeric "
          "factorisation's flops up to a constant." + (" **Quick run (script check), not the benchmark.**"
                                                        if args.quick else ""), "",
          *md_table(["model", "periodic", "n_intervals", "degree", "nodes", "kkt_rows", "kkt_nnz", "L_nnz",
                     "L_max_column", "flops_proxy", "build_s"], rows), "",
          "Growth exponents (quantity ∝ nodes^b):", "",
          *md_table(["model", "periodic", "quantity", "exponent", "±", "R²", "points"], fits)]
    write_report(OUT, "kkt_fill_quick" if args.quick else "kkt_fill", doc, md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
