"""MUMPS's own analysis of IPOPT's KKT matrix, ordering by ordering and mesh by mesh.

    .venv/bin/python benchmarks/bench_mumps_orderings.py           # SK 5–80, MSK 5–40 intervals × 5, ≈ 8 min
    .venv/bin/python benchmarks/bench_mumps_orderings.py --quick   # SK 2 and 4 intervals × 3 (checks the script)

``bench_kkt_fill.py`` counts the fill of a minimum-degree ordering on IPOPT's KKT pattern with
CasADi's symbolic LDLᵀ — a model of MUMPS. This script asks MUMPS itself: for the natural-gait
problems (``gaitlib.studies.gait.natural_gait_spec``: SK Eq 4.11, MSK Eq 5.33; LGR degree 5),
IPOPT is started (``max_iter`` = 0) once per value of ``mumps_pivot_order`` (ICNTL(7): 0 AMD,
2 AMF, 3 SCOTCH, 4 PORD, 5 METIS, 6 QAMD, 7 MUMPS's automatic choice, IPOPT's default) with
``mumps_print_level`` = 2, and MUMPS's analysis report is parsed: the ordering it actually
used (INFOG(7)), the estimated entries in the factors (INFOG(20)), the largest frontal
matrix (INFOG(5)) and the estimated floating-point operations of one factorisation
(RINFOG(1)). The analysis is done once per solve on the KKT pattern, which does not change
between iterations, so these are the figures of every factorisation of a solve (before
delayed pivots, which the estimate excludes). Deterministic counts, no timing. Each mesh
runs in its own process; the NLP is built once per mesh and the solvers of the orderings
share its derivative functions (``hess_lag``, ``jac_g``, ``grad_f`` options of ``nlpsol``).

Per model and ordering, the growth exponent b of each count ∝ nodes^b is fitted
(:func:`gaitlib.studies.performance.fit_power_law`). Writes
``benchmarks/results/mumps_orderings.json`` and ``mumps_orderings.md``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import platform
import re
import subprocess
import sys
from datetime import datetime, timezone
from pathlib import Path

OUT = Path(__file__).resolve().parent / "results"
ORDERINGS = {0: "AMD", 2: "AMF", 3: "SCOTCH", 4: "PORD", 5: "METIS", 6: "QAMD", 7: "auto (IPOPT default)"}
MESHES = {"SK": (5, 10, 20, 40, 80), "MSK": (5, 10, 20, 40)}
QUICK_MESHES = {"SK": (2, 4)}
COUNTS = {"factor_entries": r"\(20\) Number of entries in factors \(estim\.\)\s*=\s*(\d+)",
          "max_front": r"\(5\) Maximum frontal size\s+\(estimated\)\s*=\s*(\d+)",
          "ordering_used": r"\(7\) Ordering option effectively used\s*=\s*(\d+)",
          "flops": r"RINFOG\(1\) Operations during elimination \(estim\)\s*=\s*([\d.D+-]+)",
          "kkt_n": r"JOB, N, NNZ =\s+1\s+(\d+)", "kkt_nnz_lower": r"JOB, N, NNZ =\s+1\s+\d+\s+(\d+)"}
ENV1 = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}


def parse_analyses(log: str) -> list[dict]:
    """MUMPS analysis reports in ``log`` (one per ``JOB = 1`` call), in order."""
    starts = [m.start() for m in re.finditer(r"Entering DMUMPS [\d.]+ from C interface with JOB, N, NNZ =\s+1\s", log)]
    out = []
    for a, b in zip(starts, starts[1:] + [len(log)]):
        block, rec = log[a:b], {}
        for key, pat in COUNTS.items():
            m = re.search(pat, block)
            if m is None:
                raise ValueError(f"MUMPS analysis report without {key!r}: {block[:300]!r}")
            rec[key] = float(m.group(1).replace("D", "e")) if key == "flops" else int(m.group(1))
        name = re.search(r"Ordering based on (\w+)", block)
        rec["ordering_name"] = name.group(1) if name else ""
        out.append(rec)
    return out


def child(model: str, n_intervals: int, degree: int) -> None:
    """Build one mesh, start IPOPT once per ordering; MUMPS writes its reports to stdout."""
    import casadi as ca
    import numpy as np

    from gaitlib import blas

    blas.pin()  # the Makefile's BLAS settings (unless set)
    from gaitlib import ocp
    from gaitlib.problems import gait as gait_ocp
    from gaitlib.studies import gait

    spec = dataclasses.replace(gait.natural_gait_spec(model), n_intervals=n_intervals, degree=degree)
    gp = gait_ocp.build(spec)
    nlp = ocp.transcribe(gp.problem, gp.mesh, gp.options)
    s = nlp.solver
    shared = {k: s.get_function(f) for k, f in (("hess_lag", "nlp_hess_l"), ("jac_g", "nlp_jac_g"),
                                                ("grad_f", "nlp_grad_f"))}
    w0 = np.clip(nlp.initial_point(gp.guess), nlp.lbw, nlp.ubw)
    pv = np.concatenate([nlp.data_vector(), nlp.goal_weights()])
    for order in ORDERINGS:
        o = gp.options.nlpsol_options()
        o["ipopt"] = {**o["ipopt"], "max_iter": 0, "print_level": 0, "mumps_print_level": 2,
                      "mumps_pivot_order": order}
        solver = ca.nlpsol(f"orderings_{order}", "ipopt", nlp.nlp, {**o, **shared})
        solver(x0=w0, lbx=nlp.lbw, ubx=nlp.ubw, lbg=nlp.lbg, ubg=nlp.ubg, p=pv)
    sys.stdout.flush()
    print("\nMESH " + json.dumps({"n_variables": int(nlp.n_variables), "n_constraints": int(nlp.n_constraints),
                                  "nodes": int(gp.mesh.n_colloc_nodes)}), flush=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--child", nargs=3, default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child is not None:
        child(args.child[0], int(args.child[1]), int(args.child[2]))
        return 0
    from report import md_table, write_report

    from gaitlib.studies.performance import fit_power_law

    degree = 3 if args.quick else 5
    rows = []
    for model, meshes in (QUICK_MESHES if args.quick else MESHES).items():
        for n in meshes:
            p = subprocess.run([sys.executable, __file__, "--child", model, str(n), str(degree)],
                               env={**os.environ, **ENV1}, capture_output=True, text=True)
            mesh = [ln for ln in p.stdout.splitlines() if ln.startswith("MESH ")]
            if p.returncode or not mesh:
                raise RuntimeError(f"{model} {n} intervals failed:\n{(p.stderr or p.stdout)[-2000:]}")
            info = json.loads(mesh[-1][5:])
            analyses = parse_analyses(p.stdout)
            if len(analyses) != len(ORDERINGS):
                raise RuntimeError(f"{model} {n}: {len(analyses)} MUMPS analyses for {len(ORDERINGS)} orderings")
            for (order, name), a in zip(ORDERINGS.items(), analyses):
                rows.append({"model": model, "n_intervals": n, "degree": degree, **info, "requested": order,
                             "requested_name": name, **a})
            print(f"{model} {n}: " + ", ".join(f"{r['requested_name']}→{r['ordering_name']} {r['flops']:.3g}"
                                               for r in rows[-len(ORDERINGS):]), flush=True)
    fits = []
    for model in dict.fromkeys(r["model"] for r in rows):
        for order, name in ORDERINGS.items():
            sel = [r for r in rows if r["model"] == model and r["requested"] == order]
            for q in ("factor_entries", "flops", "max_front"):
                f = fit_power_law([r["nodes"] for r in sel], [r[q] for r in sel])
                fits.append({"model": model, "requested": order, "requested_name": name, "quantity": q,
                             "exponent": f["exponent"], "exponent_se": f["exponent_se"], "r2": f["r2"],
                             "n_points": f["n_points"],
                             "used": ", ".join(sorted({r["ordering_name"] for r in sel}))})
    doc = {"measured": datetime.now(timezone.utc).isoformat(timespec="seconds"),
           "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
           "code": __import__("gaitlib.cache").cache.fingerprint(), "quick": args.quick,
           "orderings": {str(k): v for k, v in ORDERINGS.items()}, "rows": rows, "fits": fits}
    md = [f"# MUMPS's analysis of IPOPT's KKT matrix by ordering ({doc['measured']})", "",
          "Counts from MUMPS's own analysis report (no timing): `flops` = RINFOG(1), estimated operations of one "
          "factorisation; `factor_entries` = INFOG(20); `max_front` = INFOG(5); `ordering_name` = the ordering "
          "MUMPS used for the requested `mumps_pivot_order`.", ""]
    md += md_table(["model", "n_intervals", "nodes", "kkt_n", "requested_name", "ordering_name", "factor_entries",
                    "max_front", "flops"], rows)
    md += ["", "Growth exponents (count ∝ nodes^b):", ""]
    md += md_table(["model", "requested_name", "used", "quantity", "exponent", "exponent_se", "r2", "n_points"], fits)
    write_report(OUT, "mumps_orderings_quick" if args.quick else "mumps_orderings", doc, md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
