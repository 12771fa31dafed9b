"""Fewer iterations? IPOPT's options screened on the MSK gait problem (issue 22's lever
"fewer iterations": scaling, barrier start, Hessian regularisation).

    .venv/bin/python benchmarks/bench_ipopt_options.py            # MSK DT Free 20 × 5, ≈ 10 min
    .venv/bin/python benchmarks/bench_ipopt_options.py --quick    # 4 × 3 mesh (checks the script)
    .venv/bin/python benchmarks/bench_ipopt_options.py --model NMSK --only default "bound_push/frac 1e-6" "mu_init 1e-2"
    .venv/bin/python benchmarks/bench_ipopt_options.py --only default "mumps_pivtol 1e-4" "mumps_pivtol 1e-2" --stem ipopt_options_mumps
    .venv/bin/python benchmarks/bench_ipopt_options.py --only default "mumps_mem_percent 100" "mumps_mem_percent 20" --stem ipopt_options_mumps_mem
    .venv/bin/python benchmarks/bench_ipopt_options.py --only default "no MUMPS scaling" "no MUMPS scaling or permuting" --stem ipopt_options_mumps_scaling

The problem of ``gaitlib run gait --model MSK --cost DT --speed Free`` (the book's Ch 5 MSK
data-tracking solve's spec, from its data-based guess), built once on the per-node path with
compiled functions, then solved once per variant, one after another in this process with
one BLAS thread. Each variant adds IPOPT options to the spec's own (``SolverOptions.ipopt``).

Per row: status, iterations, solve time, ms per iteration, objective, constraint
violation; from IPOPT's own iteration log (``file_print_level`` 5, parsed): the iterations
whose Hessian needed an inertia correction (``lg(rg)`` not ``-``), their median and
largest log10 δ_w, and the iterations with a restoration phase; and how far the solution
is from the default variant's (RMS of the joint angles' difference, degrees): a variant that
is faster but lands in another local optimum is another result, not the same one faster.
Writes ``results/ipopt_options.json`` and ``.md``.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile
import time
from dataclasses import replace
from datetime import datetime, timezone
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
OUT = HERE / "results"

#: (name, extra IPOPT options). The first is the reference.
VARIANTS = (
    ("default", {}),
    ("mu_init 1e-3", {"mu_init": 1e-3}),
    ("mu_init 1e-2", {"mu_init": 1e-2}),
    ("no NLP scaling", {"nlp_scaling_method": "none"}),
    ("equilibration scaling", {"nlp_scaling_method": "equilibration-based"}),
    ("bound_push/frac 1e-6", {"bound_push": 1e-6, "bound_frac": 1e-6}),
    ("first δ_w 1e-2", {"first_hessian_perturbation": 1e-2}),
    ("δ_w decrease ÷1.5", {"perturb_dec_fact": 0.667}),
    ("δ_c always 1e-8", {"perturb_always_cd": "yes", "jacobian_regularization_value": 1e-8}),
    ("curvature test (no inertia)", {"neg_curv_test_tol": 1e-12}),
    ("mu_oracle loqo, adaptive", {"mu_strategy": "adaptive", "mu_oracle": "loqo"}),
    ("mumps_pivtol 1e-4", {"mumps_pivtol": 1e-4}),
    ("mumps_pivtol 1e-2", {"mumps_pivtol": 1e-2}),
    ("mumps_mem_percent 100", {"mumps_mem_percent": 100}),
    ("mumps_mem_percent 20", {"mumps_mem_percent": 20}),
    ("no MUMPS scaling", {"mumps_scaling": 0}),
    ("no MUMPS scaling or permuting", {"mumps_scaling": 0, "mumps_permuting_scaling": 0}),
)

_ITER = re.compile(r"^\s*(\d+)(r?)\s+(-?\d\.\d+e[+-]\d+)\s+\S+\s+\S+\s+\S+\s+\S+\s+(\S+)\s+\S+\s+\S+")


def parse_log(text: str) -> dict:
    """Inertia corrections and restoration iterations from IPOPT's iteration log."""
    rg, resto, its = [], 0, 0
    for line in text.splitlines():
        m = _ITER.match(line)
        if not m:
            continue
        its += 1
        resto += bool(m.group(2))
        if m.group(4) != "-":
            try:
                rg.append(float(m.group(4)))
            except ValueError:
                pass
    return {"log_iterations": its, "inertia_corrections": len(rg), "restoration_iterations": resto,
            "median_lg_dw": float(np.median(rg)) if rg else np.nan, "max_lg_dw": float(max(rg)) if rg else np.nan}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--only", nargs="*", help="variant names (default: all)")
    ap.add_argument("--model", default="MSK", choices=["SK", "MSK", "NMSK"], help="gait model (default MSK)")
    ap.add_argument("--stem", help="results file stem (default ipopt_options[_model][_quick]): a subset of "
                                   "variants written beside the full run instead of over it")
    args = ap.parse_args(argv)
    from gaitlib import conventions as cv, ocp
    from gaitlib.problems import gait as gait_ocp

    mesh = dict(n_intervals=4, degree=3) if args.quick else {}
    spec = gait_ocp.GaitSpec(model=args.model, cost="DT", speed_class="Free", derivatives="nodes", **mesh)
    t0 = time.perf_counter()
    gp = gait_ocp.build(spec)
    gp = replace(gp, options=replace(gp.options, compiled=True))
    build_s = time.perf_counter() - t0
    guess = gait_ocp.warm_start(gp, None)
    rows, ref_q = [], None
    variants = [v for v in VARIANTS if not args.only or v[0] in args.only]
    for name, extra in variants:
        with tempfile.TemporaryDirectory(prefix="bench-ipopt-") as tmp:
            log = Path(tmp) / "ipopt.log"
            opts = replace(gp.options, ipopt={**dict(gp.options.ipopt), **extra, "output_file": str(log),
                                              "file_print_level": 5})
            load = os.getloadavg()[0]
            t1 = time.perf_counter()
            try:
                sol = ocp.solve(gp.problem, gp.mesh, opts, guess)
            except Exception as exc:  # an option IPOPT rejects is a row, not a crash
                rows.append({"variant": name, "options": extra, "status": f"error: {exc}"[:200]})
                print(name, rows[-1]["status"], flush=True)
                continue
            wall = time.perf_counter() - t1
            if sol.status == "Invalid_Option":  # e.g. equilibration scaling needs HSL's MC19
                rows.append({"variant": name, "options": extra, "status": "Invalid_Option (not in this IPOPT build)"})
                print(name, rows[-1]["status"], flush=True)
                continue
            its = sol.iterations
            row = {"variant": name, "options": extra, "status": sol.status, "iterations": its,
                   "solve_s": sol.solve_time, "wall_s": wall, "ms_per_iteration": 1e3 * sol.solve_time / max(its, 1),
                   "objective": sol.objective, "max_violation": sol.max_violation, "load_at_start": load,
                   **parse_log(log.read_text(errors="replace"))}
        q = np.concatenate([ph.states[list(cv.JOINTS)].to_numpy().ravel() for ph in sol.phases.values()])
        if ref_q is None and name == "default":
            ref_q = q
        row["rms_vs_default_deg"] = (float(np.degrees(np.sqrt(np.mean((q - ref_q) ** 2))))
                                     if ref_q is not None and q.shape == ref_q.shape else np.nan)
        rows.append(row)
        print(f"{name}: {row['status']} {its} it, {row['solve_s']:.1f} s, obj {row['objective']:.5g}, "
              f"inertia corr {row['inertia_corrections']}, rms {row['rms_vs_default_deg']:.3g}°", flush=True)
        _write(args, spec, build_s, rows)
    return 0


def _write(args, spec, build_s, rows):
    sys.path.insert(0, str(HERE))
    from report import machine_info, md_table, write_report

    doc = {"measured": datetime.now(timezone.utc).isoformat(timespec="seconds"), "machine": machine_info(),
           "spec": spec.to_dict(), "build_s": build_s, "quick": args.quick, "rows": rows}
    m = doc["machine"]
    md = [f"# IPOPT options on the {spec.model} gait problem ({doc['measured']}, {m['cpu']}, {m['cores']} cores)", "",
          f"{spec.model} DT Free, {spec.n_intervals} × {spec.degree} LGR, per-node derivatives, compiled; one build "
          f"({build_s:.1f} s), one solve per variant from the data-based guess, one BLAS thread. "
          "`inertia_corrections`: iterations whose Hessian IPOPT regularised (δ_w > 0); `rms_vs_default_deg`: RMS "
          "difference of the solution's joint angles from the default variant's. "
          "`python benchmarks/bench_ipopt_options.py`.", ""]
    md += md_table(["variant", "options", "status", "iterations", "solve_s", "ms_per_iteration", "objective",
                    "max_violation", "inertia_corrections", "median_lg_dw", "max_lg_dw", "restoration_iterations",
                    "rms_vs_default_deg", "load_at_start"], rows)
    stem = args.stem or ("ipopt_options" + ("" if args.model == "MSK" else f"_{args.model.lower()}")
                         + ("_quick" if args.quick else ""))
    write_report(OUT, stem, doc, md)


if __name__ == "__main__":
    sys.exit(main())
