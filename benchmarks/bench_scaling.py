"""Scaling of the gait OCP: solve time and time per iteration vs mesh size
and model; exact Hessian vs limited-memory; the linear solvers casadi's IPOPT can load.

    .venv/bin/python benchmarks/bench_scaling.py              # the full benchmark, ≈ 20–30 min
    .venv/bin/python benchmarks/bench_scaling.py --quick      # coarse meshes, ≈ 1 min (checks the script)

What runs (natural-gait data tracking, Free speed, fixed thesis contact parameters, the
data-based guess; ``gaitlib.studies.gait.natural_gait_spec``: SK Eq 4.11, MSK Eq 5.33, NMSK
Eq 5.55; LGR with ``--degree`` points per interval; nothing cached, every run solved here):

* ``mesh``: exact Hessian, MUMPS — SK at ``--sk`` intervals (default 5, 10, 20, 40, 80), MSK at
  ``--msk`` (5, 10, 20), NMSK at ``--nmsk`` (5, 10, 20);
* ``hessian``: the same problem with ``hessian="limited-memory"`` (IPOPT's L-BFGS) at
  ``--hessian-at`` (default SK, 20 intervals; ``--lbfgs-max-iter`` 3000), beside the exact run;
* ``linear_solver``: every ``linear_solver`` value of IPOPT 3.14 is first tried on a 2-variable
  NLP in its own process (which loads, which fails and IPOPT's message), then each loadable one
  other than MUMPS solves the problem at ``--linear-at`` (default SK, 20 intervals).

Every solve runs in its own process (fresh memory, one BLAS thread, ``--timeout`` s per run),
one after another — never two at once. The growth exponent b of ``time per iteration ∝
nodes^b`` (nodes = intervals × degree collocation points) is fitted per model on log–log
axes (:func:`gaitlib.studies.performance.fit_power_law`), as are its parts (CasADi function
and derivative evaluations — IPOPT's ``t_wall_nlp_*`` — and the rest, mostly MUMPS).

Writes ``benchmarks/results/scaling.json`` (after every run, so a partial run is kept;
``complete`` says whether all runs were attempted) and ``scaling.md``. The metadata record
the date, machine, casadi version, git commit, the load average before and after every run
and a note that the machine was shared: on this 2-core machine other engineers' solves were
running at the same time, so absolute times are inflated by an unknown, varying factor.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import resource
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

HERE = Path(__file__).resolve().parent
OUT = HERE / "results"
LINEAR_SOLVERS = ("mumps", "ma27", "ma57", "ma77", "ma86", "ma97", "pardiso", "pardisomkl", "spral", "wsmp")
SHARED_NOTE = ("measured on a 2-core machine shared with 3-4 other engineers' jobs (optimal-control solves, "
               "tests, book builds) running at the same time: absolute times are inflated by an unknown, "
               "varying factor (see the load averages per run); ratios and exponents are less affected")
ENV1 = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


# -- child side: one solve ----------------------------------------------------------------

def _one(case: dict) -> dict:
    from gaitlib import blas

    blas.pin()  # the Makefile's BLAS settings (unless set)
    from gaitlib.problems import gait as gait_ocp
    from gaitlib.studies import gait

    spec = gait.natural_gait_spec(case["model"], n_intervals=case["n_intervals"], degree=case["degree"],
                                  hessian=case.get("hessian", "exact"), max_iter=case.get("max_iter", 1000))
    t0 = time.perf_counter()
    gp = gait_ocp.build(spec)
    setup = time.perf_counter() - t0
    ls = case.get("linear_solver", "mumps")
    if ls != "mumps":
        gp = dataclasses.replace(gp, options=dataclasses.replace(gp.options, linear_solver=ls))
    sol = gait_ocp.solve(gp)
    st = sol.stats
    tw = sol.solution.info.get("ipopt_t_wall", {})
    evals = sum(v for k, v in tw.items() if k.startswith("t_wall_nlp_"))
    it = max(int(st["iterations"]), 1)
    return {"status": st["status"], "success": bool(st["success"]), "iterations": int(st["iterations"]),
            "solve_s": st["solve_time_s"], "build_s": st["build_time_s"],
            "symbolic_s": sol.solution.info.get("symbolic_time"), "setup_s": setup,
            "ms_per_iteration": 1e3 * st["solve_time_s"] / it,
            "function_evals_s": evals, "function_evals_ms_per_iteration": 1e3 * evals / it,
            "ipopt_rest_ms_per_iteration": 1e3 * (st["solve_time_s"] - evals) / it,
            "ipopt_t_wall": tw, "objective": st["objective"], "max_violation": st["max_violation"],
            "n_variables": st["n_variables"], "n_constraints": st["n_constraints"],
            "n_hessian_calls": sol.solution.info.get("n_call_nlp_hess_l"),
            "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def _probe(ls: str) -> None:
    """Try ``ls`` on a 2-variable NLP; print IPOPT's output and a RESULT line."""
    import casadi as ca

    x = ca.SX.sym("x", 2)
    nlp = {"x": x, "f": (x[0] - 1) ** 2 + 100 * (x[1] - x[0] ** 2) ** 2, "g": x[0] + x[1]}
    try:
        s = ca.nlpsol("probe", "ipopt", nlp, {"ipopt": {"linear_solver": ls, "print_level": 5},
                                              "print_time": False, "error_on_fail": False})
        s(x0=[0.5, 0.5], lbg=-10, ubg=10)
        st = s.stats()
        print("RESULT " + json.dumps({"status": st["return_status"], "success": bool(st["success"])}), flush=True)
    except RuntimeError as e:
        print("RESULT " + json.dumps({"status": "nlpsol error", "success": False, "exception": str(e)}), flush=True)


# -- parent side ----------------------------------------------------------------------------

def _machine() -> dict:
    from report import machine_info

    return machine_info()


def _versions() -> dict:
    import casadi

    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=HERE, capture_output=True, text=True).stdout
    from gaitlib import cache

    return {"casadi": casadi.__version__, "gaitlib_commit": commit.strip(), "gaitlib_code": cache.fingerprint()}


def _child(args: list[str], timeout: float):
    env = {**os.environ, **ENV1}
    t0 = time.perf_counter()
    try:
        p = subprocess.run([sys.executable, __file__, *args], capture_output=True, text=True, timeout=timeout,
                           env=env)
    except subprocess.TimeoutExpired as e:
        return None, f"timeout after {timeout:.0f} s", (e.stdout or b"")[-2000:] if isinstance(e.stdout, bytes) \
            else (e.stdout or "")[-2000:], time.perf_counter() - t0
    wall = time.perf_counter() - t0
    res = None
    for line in p.stdout.splitlines():
        if line.startswith("RESULT "):
            res = json.loads(line[7:])
    err = None if res is not None else f"exit code {p.returncode}: {p.stderr.strip()[-1500:]}"
    return res, err, p.stdout, wall


def probe_linear_solvers(timeout: float = 120) -> list[dict]:
    out = []
    for ls in LINEAR_SOLVERS:
        res, err, stdout, _ = _child(["--probe", ls], timeout)
        msg = ""
        for line in (stdout or "").splitlines():
            s = line.strip()
            if s.startswith("Exception message:") or "is not a valid setting" in s:
                msg = s
                break
        if res is None:
            out.append({"linear_solver": ls, "loads": False, "status": "probe failed", "message": err})
            continue
        loads = bool(res["success"])
        if not msg and res.get("exception"):
            msg = res["exception"].strip().splitlines()[-1]
        out.append({"linear_solver": ls, "loads": loads, "status": res["status"], "message": msg if not loads else ""})
        print(f"linear solver {ls:<11} {'loads' if loads else 'FAILS'}  {res['status']}  {msg}", flush=True)
    return out


QUIET_LOAD = 1.6  # 1-min load average with only the benchmark's own solve running is ≈ 1


def _load_note(doc: dict) -> str:
    """The note on machine load: SHARED_NOTE unless every run (and the supplement) started with
    the 1-min load average below QUIET_LOAD (the benchmark's own solve counts ≈ 1)."""
    loads = [r["loadavg_start"][0] for r in doc["runs"] if "loadavg_start" in r]
    loads += [doc["meta"]["loadavg_start"][0]]
    if doc["meta"].get("supplement"):
        loads.append(doc["meta"]["supplement"]["loadavg_start"][0])
    if max(loads) < QUIET_LOAD:
        return (f"measured with no other job on the machine: the 1-min load average at the start of every run was "
                f"≤ {max(loads):.2f} (the benchmark's own previous solve counts ≈ 1)")
    return SHARED_NOTE


def _write(doc: dict) -> None:
    from gaitlib.studies import performance as perf

    OUT.mkdir(exist_ok=True)
    doc["meta"]["note"] = _load_note(doc)
    doc["fits"] = perf.scaling_fits(doc).to_dict(orient="records") if doc["runs"] else []
    (OUT / "scaling.json").write_text(json.dumps(doc, indent=1, default=str))
    md = [f"# Scaling of the gait OCP ({doc['meta']['measured']})", "",
          f"{perf.measured_on(doc)}.", "",
          f"casadi {doc['meta']['versions']['casadi']}, gaitlib {doc['meta']['versions']['gaitlib_commit']}; "
          f"{'complete' if doc['complete'] else 'INCOMPLETE (interrupted or over budget)'}; "
          f"total benchmark wall time {doc['meta'].get('total_wall_s', float('nan')):.0f} s.", "",
          *([f"Supplement {doc['meta']['supplement']['started']}: {doc['meta']['supplement']['reason']} "
             f"({len(doc['meta']['supplement']['runs'])} runs, {doc['meta']['supplement'].get('wall_s', 0):.0f} s, "
             f"load average at start {doc['meta']['supplement']['loadavg_start'][0]:.2f}).", ""]
            if doc["meta"].get("supplement") else []),
          "## Mesh size and model (exact Hessian, MUMPS)", "", perf.scaling_table(doc).to_markdown(index=False),
          "", "Fitted growth exponents (quantity ∝ nodes^b, finished runs only):", "",
          perf.scaling_fits(doc).to_markdown(index=False) if doc["runs"] else "(none)", "",
          "## Exact Hessian vs limited-memory (L-BFGS)", "", perf.hessian_table(doc).to_markdown(index=False), "",
          "## Linear solvers", ""]
    avail, lin = perf.linear_solver_table(doc)
    md += [avail.to_markdown(index=False) if not avail.empty else "(not probed)", "",
           lin.to_markdown(index=False) if not lin.empty else "(no run)", ""]
    md += ["## All runs", "", "| group | model | intervals | hessian | linear solver | outcome | status | "
           "it | wall s | load avg at start |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in doc["runs"]:
        md.append(f"| {r['group']} | {r['model']} | {r['n_intervals']} | {r['hessian']} | {r['linear_solver']} | "
                  f"{r['outcome']} | {r.get('status', '')} | {r.get('iterations', '')} | {r['child_wall_s']:.0f} | "
                  f"{r['loadavg_start'][0]:.2f} |")
    (OUT / "scaling.md").write_text("\n".join(md) + "\n")


def _measure(c: dict, rec: dict, timeout: float) -> dict:
    one = {k: c[k] for k in ("model", "n_intervals", "degree", "hessian", "linear_solver")}
    if "max_iter" in c:
        one["max_iter"] = c["max_iter"]
    res, err, _, wall = _child(["--one", json.dumps(one)], timeout)
    rec.update(res or {})
    rec.update(outcome="finished" if res is not None else ("timeout" if err.startswith("timeout") else "error"),
               error=err, child_wall_s=wall, loadavg_end=list(os.getloadavg()))
    return rec


def _print_run(c: dict, rec: dict) -> None:
    print(f"{c['group']:<13} {c['model']:<4} {c['n_intervals']:>3} x {c['degree']} {c['hessian']:<14} "
          f"{c['linear_solver']:<6} {rec.get('status', rec['outcome']):<28} it {rec.get('iterations', '-'):>5}  "
          f"{rec.get('ms_per_iteration', float('nan')):8.1f} ms/it  solve {rec.get('solve_s', float('nan')):7.1f} s"
          f"  build {rec.get('build_s', float('nan')):6.1f} s  load {rec['loadavg_start'][0]:.2f}", flush=True)


def _resume_skipped(args) -> int:
    """Measure the runs of ``scaling.json`` that the main run skipped (over budget), each
    group (hessian, linear_solver) together with a fresh MUMPS / exact-Hessian reference run
    in the same period, so the comparison is made under the same load."""
    doc = json.loads((OUT / "scaling.json").read_text())
    sup = {"started": datetime.now(timezone.utc).isoformat(timespec="seconds"), "loadavg_start": list(os.getloadavg()),
           "reason": "runs skipped by the main run's --budget, measured in a second invocation "
                     "(bench_scaling.py --resume-skipped) with fresh reference runs", "runs": []}
    t0 = time.perf_counter()
    skipped = [r for r in doc["runs"] if str(r.get("outcome", "")).startswith("skipped")]
    groups = []
    for r in skipped:
        if r["group"] not in groups:
            groups.append(r["group"])
    # keep every finished run except the old references of the groups re-measured here
    new_runs = [r for r in doc["runs"] if not str(r.get("outcome", "")).startswith("skipped")
                and (r["group"] not in groups or r["group"] == "mesh")]
    for g in groups:
        todo = [r for r in skipped if r["group"] == g]
        ref = dict(todo[0], hessian="exact", linear_solver="mumps")
        ref.pop("max_iter", None)
        for c in (todo if g == "mesh" else [*todo, ref]):
            c = {k: c[k] for k in ("group", "model", "n_intervals", "degree", "hessian", "linear_solver", "max_iter")
                 if k in c}
            rec = {**c, "nodes": c["n_intervals"] * c["degree"], "loadavg_start": list(os.getloadavg()),
                   "measured_in": "supplement"}
            rec = _measure(c, rec, args.timeout)
            new_runs.append(rec)
            sup["runs"].append(f"{g} {c['model']} {c['n_intervals']} {c['hessian']} {c['linear_solver']}")
            _print_run(c, rec)
            doc["runs"] = new_runs + [r for r in skipped if r["group"] in groups[groups.index(g) + 1:]]
            _write(doc)
    sup["wall_s"] = time.perf_counter() - t0
    sup["loadavg_end"] = list(os.getloadavg())
    doc["meta"]["supplement"] = sup
    doc["runs"] = new_runs
    _write(doc)
    print((OUT / "scaling.md").read_text())
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sk", default="5,10,20,40,80", help="SK mesh intervals")
    ap.add_argument("--msk", default="5,10,20", help="MSK mesh intervals ('' for none)")
    ap.add_argument("--nmsk", default="5,10,20", help="NMSK mesh intervals ('' for none)")
    ap.add_argument("--degree", type=int, default=5, help="LGR points per interval (thesis: 5)")
    ap.add_argument("--hessian-at", default="SK:20", help="MODEL:INTERVALS for exact vs L-BFGS ('' for none)")
    ap.add_argument("--lbfgs-max-iter", type=int, default=3000)
    ap.add_argument("--linear-at", default="SK:20", help="MODEL:INTERVALS for the linear solvers ('' for none)")
    ap.add_argument("--timeout", type=float, default=900, help="per run (s)")
    ap.add_argument("--budget", type=float, default=1800, help="start no new run after this many s")
    ap.add_argument("--quick", action="store_true", help="SK 4, 8 intervals × 3 (checks the script)")
    ap.add_argument("--out", default=None, help="results directory (default benchmarks/results)")
    ap.add_argument("--resume-skipped", action="store_true",
                    help="measure the runs results/scaling.json marks as skipped (over budget), with fresh references")
    ap.add_argument("--one", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--probe", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.one:
        print("RESULT " + json.dumps(_one(json.loads(args.one)), default=float), flush=True)
        return 0
    if args.probe:
        _probe(args.probe)
        return 0
    global OUT
    if args.out:
        OUT = Path(args.out)
    if args.quick:
        args.sk, args.msk, args.nmsk, args.degree = "4,8", "", "", 3
        args.hessian_at, args.linear_at, args.lbfgs_max_iter = "SK:4", "SK:4", 1000

    def sizes(s):
        return [int(v) for v in s.split(",") if v.strip()]

    def at(s):
        if not s:
            return None
        m, n = s.split(":")
        return m, int(n)

    cases = [{"group": "mesh", "model": m, "n_intervals": n} for m, ns in
             (("SK", sizes(args.sk)), ("MSK", sizes(args.msk)), ("NMSK", sizes(args.nmsk))) for n in ns]
    if at(args.hessian_at):
        m, n = at(args.hessian_at)
        cases.append({"group": "hessian", "model": m, "n_intervals": n, "hessian": "limited-memory",
                      "max_iter": args.lbfgs_max_iter})
    for c in cases:
        c.setdefault("hessian", "exact")
        c.setdefault("linear_solver", "mumps")
        c["degree"] = args.degree

    t_start = time.perf_counter()
    doc = {"meta": {"measured": datetime.now(timezone.utc).isoformat(timespec="seconds"), "machine": _machine(),
                    "versions": _versions(), "loadavg_start": list(os.getloadavg()), "note": SHARED_NOTE,
                    "command": " ".join([Path(sys.argv[0]).name, *(argv if argv is not None else sys.argv[1:])]),
                    "problem": "natural-gait data tracking, Free speed, fixed contact parameters, data-based "
                               "guess (gaitlib.studies.gait.natural_gait_spec), LGR",
                    "definitions": {
                        "nodes": "collocation nodes = intervals x degree",
                        "solve_s": "wall time of the IPOPT call",
                        "build_s": "building the NLP: symbolic graph + nlpsol with its exact derivatives",
                        "setup_s": "gaitlib.problems.gait.build: data, reference, bounds, guess (before build_s)",
                        "function_evals": "IPOPT's t_wall_nlp_* (CasADi function and derivative evaluations)",
                        "ipopt_rest": "solve_s minus function evaluations: IPOPT's own work, mostly MUMPS",
                        "outcome": "finished = IPOPT returned (any status); timeout; error"}},
           "runs": [], "linear_solvers_available": [], "complete": False}

    if args.resume_skipped:
        return _resume_skipped(args)

    def run_case(c):
        rec = {**c, "nodes": c["n_intervals"] * c["degree"], "loadavg_start": list(os.getloadavg())}
        if time.perf_counter() - t_start > args.budget:
            rec.update(outcome="skipped (over budget)", child_wall_s=0.0, loadavg_end=list(os.getloadavg()))
            doc["runs"].append(rec)
            print(f"skip {c}", flush=True)
            return
        rec = _measure(c, rec, args.timeout)
        doc["runs"].append(rec)
        doc["meta"]["total_wall_s"] = time.perf_counter() - t_start
        _write(doc)
        _print_run(c, rec)

    for c in cases:
        run_case(c)
    doc["linear_solvers_available"] = probe_linear_solvers()
    if at(args.linear_at):
        m, n = at(args.linear_at)
        for a in doc["linear_solvers_available"]:
            if a["loads"] and a["linear_solver"] != "mumps":
                run_case({"group": "linear_solver", "model": m, "n_intervals": n, "degree": args.degree,
                          "hessian": "exact", "linear_solver": a["linear_solver"]})
    # the reference rows (MUMPS, exact Hessian) for the hessian and linear-solver tables
    for grp, spec in (("hessian", at(args.hessian_at)), ("linear_solver", at(args.linear_at))):
        if spec is None:
            continue
        ref = [r for r in doc["runs"] if r["group"] == "mesh" and (r["model"], r["n_intervals"]) == spec]
        if ref:
            doc["runs"].append({**ref[0], "group": grp, "reference": "the mesh run (same process setup)"})
        else:
            run_case({"group": grp, "model": spec[0], "n_intervals": spec[1], "degree": args.degree,
                      "hessian": "exact", "linear_solver": "mumps"})
    doc["complete"] = True
    doc["meta"]["total_wall_s"] = time.perf_counter() - t_start
    doc["meta"]["loadavg_end"] = list(os.getloadavg())
    _write(doc)
    print((OUT / "scaling.md").read_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
