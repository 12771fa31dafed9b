"""T9-track side by side: OpenSim Moco vs gaitlib, trapezoidal and Hermite–Simpson.

One command (from the repository root, with gaitlib's venv)::

    .venv/bin/python benchmarks/bench_moco_t9track.py

creates ``benchmarks/.venv-moco`` (``python3 -m venv`` + ``pip install opensim==4.6``) on
first use, then for each scheme runs, each in its own process with one BLAS thread:

1. Moco (``moco/moco_side.py`` with the Moco venv's python), as MocoTrack configures it;
2. gaitlib (``t9track.py``), the benchmark configuration (μ_init = 1e-3);
3. gaitlib with IPOPT's default options (μ_init = 0.1), for reference;
4. gaitlib with per-node derivatives (``--derivatives nodes``), and the same with the
   per-node functions compiled to C (``--compiled``, :mod:`gaitlib.compiled`: the same
   numbers, so the same iterations). The libraries are compiled once per machine: a first,
   untimed run of the compiled variant per scheme compiles them (its setup time, compile
   included, is recorded as ``compile_first_use_setup_s``), so the timed repeats load them;
5. gaitlib with an unexpanded MX graph (builds in a fraction of a second, evaluates slower);
6. the compiled per-node variant with MUMPS's scaling switched off (:data:`MUMPS_UNSCALED`).

It prints one table (setup time, solve time, iterations, time per iteration, objective,
max constraint violation, RMS per coordinate), writes ``results/moco_t9track.json`` and
``results/moco_t9track.md`` (date, machine, versions), appends the table to
``results/moco_t9track_history.md``, keeps each run's raw JSON, IPOPT log and trajectory
CSV in ``results/moco_raw/``, and ends with one line per scheme::

    speedup_vs_moco SCHEME X
    speedup_vs_moco_best SCHEME Z  (gaitlib variant)
    speedup_vs_moco_e2e SCHEME Y  (gaitlib variant)

Z = Moco's solve / the fastest gaitlib variant's solve; Y = Moco's setup + solve / the fastest gaitlib variant's setup + solve (medians), among the
variants that converged in every repeat; the variant is named.

X = Moco solve time / gaitlib solve time, both measured in this run (medians over
``--repeats``). *Solve time* is the wall time of the IPOPT call (CasADi ``nlpsol``) in
both tools; for Moco it is read from CasADi's timing table in Moco's log (Moco builds its
CasADi problem inside ``MocoStudy.solve()``; that part is counted as Moco setup).
*Setup time* is everything before the IPOPT call after the imports: model and problem
construction, and for gaitlib the symbolic NLP with its exact derivatives.
"""

from __future__ import annotations

import argparse
import datetime as dt
import importlib.util
import json
import math
import os
import platform
import statistics
import subprocess
import sys
from pathlib import Path

import pandas as pd

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
MOCO_VENV = HERE / ".venv-moco"
MOCO_PY = MOCO_VENV / "bin" / "python"
RESULTS = HERE / "results"
RAW = RESULTS / "moco_raw"
SCHEMES = ("trapezoidal", "hermite-simpson")
COORDS = ("pelvis_tilt", "pelvis_tx", "pelvis_ty", "hip_flexion_l", "hip_flexion_r",
          "knee_angle_l", "knee_angle_r", "ankle_angle_l", "ankle_angle_r")
ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")


#: The compiled per-node variant with MUMPS's row/column scaling and its permuting scaling
#: switched off (IPOPT's ``mumps_scaling``, ``mumps_permuting_scaling``): a linear-solver
#: setting, measured on the MSK gait problem in results/ipopt_options_mumps_scaling.md.
MUMPS_UNSCALED = {"mumps_scaling": 0, "mumps_permuting_scaling": 0}
UNSCALED = "gaitlib (per-node derivatives, compiled, MUMPS unscaled)"


def ensure_moco_venv():
    if MOCO_PY.exists():
        return
    print(f"creating {MOCO_VENV} (python3 -m venv; pip install opensim==4.6) ...", flush=True)
    subprocess.run(["python3", "-m", "venv", str(MOCO_VENV)], check=True)
    subprocess.run([str(MOCO_PY), "-m", "pip", "install", "--quiet", "opensim==4.6"],
                   check=True)


def _load(name, path):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def run(cmd, label) -> None:
    print(f"  {label}: {' '.join(Path(c).name if i < 2 else c for i, c in enumerate(cmd))}",
          flush=True)
    p = subprocess.run(cmd, env=ENV, cwd=ROOT, capture_output=True, text=True)
    if p.returncode != 0:
        sys.stderr.write(p.stdout[-3000:] + p.stderr[-3000:])
        raise RuntimeError(f"{label} failed (exit {p.returncode})")


def machine() -> dict:
    cpu = ""
    try:
        for ln in Path("/proc/cpuinfo").read_text().splitlines():
            if ln.startswith("model name"):
                cpu = ln.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"platform": platform.platform(), "cpu": cpu, "cores": os.cpu_count(),
            "python": sys.version.split()[0], "node": platform.node()}


def versions() -> dict:
    import casadi

    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                            capture_output=True, text=True).stdout.strip()
    return {"casadi": casadi.__version__, "gaitlib_commit": commit}


def fmt_rms(r: dict) -> dict:
    """rad → deg for angles, m → mm for translations (display only)."""
    return {c: (v * 1000.0 if c in ("pelvis_tx", "pelvis_ty") else math.degrees(v))
            for c, v in r.items()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--schemes", nargs="+", default=list(SCHEMES), choices=SCHEMES)
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--no-defaults-variant", action="store_true",
                    help="skip the gaitlib run with IPOPT's default options")
    ap.add_argument("--no-mx-variant", action="store_true",
                    help="skip the gaitlib run with an unexpanded MX graph (fast setup)")
    ap.add_argument("--out", default=str(RESULTS / "moco_t9track"))
    args = ap.parse_args(argv)

    ensure_moco_venv()
    t9 = _load("t9track", HERE / "t9track.py")
    moco_side = _load("moco_side", HERE / "moco" / "moco_side.py")
    RAW.mkdir(parents=True, exist_ok=True)
    started = dt.datetime.now(dt.timezone.utc)
    load_start = os.getloadavg()
    _, spline = t9.reference()

    first_use = {}
    for scheme in args.schemes:  # compile the per-node functions once (not a timed repeat)
        stem = f"gaitlib_{scheme}_nodes_compiled"
        run([sys.executable, str(HERE / "t9track.py"), "--scheme", scheme, "--derivatives", "nodes",
             "--compiled", "--out", str(RAW)], "gaitlib (per-node derivatives, compiled): first use, compiles")
        first_use[scheme] = json.loads((RAW / f"{stem}.json").read_text())["setup_time"]
    runs = []
    for rep in range(args.repeats):
        for scheme in args.schemes:
            print(f"[repeat {rep + 1}/{args.repeats}] {scheme}", flush=True)
            variants = [("moco", [str(MOCO_PY), str(HERE / "moco" / "moco_side.py"),
                                  "--scheme", scheme, "--out", str(RAW)], f"moco_{scheme}"),
                        ("gaitlib", [sys.executable, str(HERE / "t9track.py"), "--scheme",
                                     scheme, "--out", str(RAW)], f"gaitlib_{scheme}")]
            if not args.no_defaults_variant:
                variants.append(("gaitlib (IPOPT defaults)",
                                 [sys.executable, str(HERE / "t9track.py"), "--scheme", scheme,
                                  "--ipopt-defaults", "--out", str(RAW)],
                                 f"gaitlib_{scheme}_ipoptdefaults"))
            variants.append(("gaitlib (per-node derivatives)",
                             [sys.executable, str(HERE / "t9track.py"), "--scheme", scheme,
                              "--derivatives", "nodes", "--out", str(RAW)],
                             f"gaitlib_{scheme}_nodes"))
            variants.append(("gaitlib (per-node derivatives, compiled)",
                             [sys.executable, str(HERE / "t9track.py"), "--scheme", scheme,
                              "--derivatives", "nodes", "--compiled", "--out", str(RAW)],
                             f"gaitlib_{scheme}_nodes_compiled"))
            variants.append((UNSCALED, [sys.executable, str(HERE / "t9track.py"), "--scheme", scheme,
                                        "--derivatives", "nodes", "--compiled", "--ipopt", json.dumps(MUMPS_UNSCALED),
                                        "--tag", f"{scheme}_nodes_compiled_unscaled", "--out", str(RAW)],
                             f"gaitlib_{scheme}_nodes_compiled_unscaled"))
            if not args.no_mx_variant:
                variants.append(("gaitlib (MX, not expanded)",
                                 [sys.executable, str(HERE / "t9track.py"), "--scheme", scheme,
                                  "--graph", "mx-noexpand", "--out", str(RAW)],
                                 f"gaitlib_{scheme}_mx-noexpand"))
            for tool, cmd, stem in variants:
                run(cmd, tool)
                res = json.loads((RAW / f"{stem}.json").read_text())
                log = (RAW / res["ipopt_log"]).read_text(errors="replace")
                ip = moco_side.parse_ipopt_log(log)
                traj = pd.read_csv(RAW / res["trajectory_csv"])
                rms = t9.rms_vs_reference(traj.set_index("time"), spline)
                if tool == "moco":
                    solve = ip.get("casadi_t_wall_total", res["solve_time"])
                    setup = res["setup_time"] + (res["solve_time"] - solve)
                else:
                    solve = res["solve_time"]
                    setup = res["setup_time"]
                row = {
                    "repeat": rep + 1, "scheme": scheme, "tool": tool,
                    "success": res["success"], "status": res["status"],
                    "iterations": res["iterations"], "setup_time": setup,
                    "solve_time": solve, "time_per_iteration": solve / max(res["iterations"], 1),
                    "objective": res["objective"], "objective_terms": res["objective_terms"],
                    "max_violation": ip.get("constraint_violation_unscaled"),
                    "n_variables": ip.get("n_variables"),
                    "n_equality_constraints": ip.get("n_equality_constraints"),
                    "iter0_objective": ip.get("iter0_objective"),
                    "rms": rms, "raw": res,
                }
                if tool == "moco":
                    row["moco_solve_wall"] = res["solve_time"]
                    row["cpu_time_solve"] = res["cpu_time_solve"]
                    # Moco's solution in gaitlib's NLP: same objective, same defects?
                    row["cross_check_in_gaitlib_nlp"] = t9.evaluate_trajectory(
                        RAW / res["trajectory_csv"], scheme)
                else:
                    row["cpu_time_solve"] = res["cpu_time_solve"]
                    row["function_t_wall"] = res["function_t_wall"]
                runs.append(row)
                flag = "" if row["success"] else f"  ** FAILED: {row['status']} **"
                print(f"    {row['iterations']} it, solve {solve:.2f} s, setup {setup:.2f} s, "
                      f"objective {row['objective']:.6f}{flag}", flush=True)

    # ------------------------------------------------------------------ summary
    tools = ["moco", "gaitlib"] + ([] if args.no_defaults_variant else
                                   ["gaitlib (IPOPT defaults)"]) + ["gaitlib (per-node derivatives)",
                                                                     "gaitlib (per-node derivatives, compiled)",
                                                                     UNSCALED] + (
        [] if args.no_mx_variant else ["gaitlib (MX, not expanded)"])
    speedups, lines = {}, []
    head = ("| scheme | tool | rep | status | setup s | solve s | it | ms/it | objective | "
            "max viol | " + " | ".join(COORDS) + " |")
    lines.append(head)
    lines.append("|" + "---|" * (10 + len(COORDS)))
    for r in runs:
        rm = fmt_rms(r["rms"])
        lines.append(
            f"| {r['scheme']} | {r['tool']} | {r['repeat']} | {r['status']} | "
            f"{r['setup_time']:.2f} | {r['solve_time']:.2f} | {r['iterations']} | "
            f"{1e3 * r['time_per_iteration']:.1f} | {r['objective']:.5f} | "
            f"{(r['max_violation'] if r['max_violation'] is not None else float('nan')):.1e} | "
            + " | ".join(f"{rm[c]:.2f}" for c in COORDS) + " |")
    for scheme in args.schemes:
        med = {}
        for tool in tools:
            ts = [r["solve_time"] for r in runs if r["scheme"] == scheme and r["tool"] == tool]
            med[tool] = statistics.median(ts) if ts else float("nan")
        ok = all(r["success"] for r in runs if r["scheme"] == scheme and r["tool"] in
                 ("moco", "gaitlib"))
        speedups[scheme] = {"speedup": med["moco"] / med["gaitlib"],
                            "moco_solve_median": med["moco"],
                            "gaitlib_solve_median": med["gaitlib"],
                            "all_succeeded": ok}
        for tool, key in (("gaitlib (IPOPT defaults)", "speedup_ipopt_defaults"),
                          ("gaitlib (per-node derivatives)", "speedup_nodes"),
                          ("gaitlib (per-node derivatives, compiled)", "speedup_nodes_compiled"),
                          (UNSCALED, "speedup_nodes_compiled_unscaled"),
                          ("gaitlib (MX, not expanded)", "speedup_mx_noexpand")):
            if tool in med:
                speedups[scheme][key] = med["moco"] / med[tool]
        # end to end (setup + solve), medians
        e2e = {}
        for tool in tools:
            ts = [r["setup_time"] + r["solve_time"] for r in runs
                  if r["scheme"] == scheme and r["tool"] == tool]
            e2e[tool] = statistics.median(ts) if ts else float("nan")
        speedups[scheme]["end_to_end_median"] = e2e
        # setup + solve against the fastest gaitlib variant that converged in every repeat
        ok = {t: v for t, v in e2e.items() if t != "moco" and all(
            r["success"] for r in runs if r["scheme"] == scheme and r["tool"] == t)}
        best = min(ok, key=ok.get) if ok else "gaitlib"
        speedups[scheme]["speedup_e2e"] = {"tool": best, "speedup": e2e["moco"] / e2e[best]}
        # solve only, against the fastest gaitlib variant that converged in every repeat
        ok = {t: v for t, v in med.items() if t != "moco" and all(
            r["success"] for r in runs if r["scheme"] == scheme and r["tool"] == t)}
        best = min(ok, key=ok.get) if ok else "gaitlib"
        speedups[scheme]["speedup_best"] = {"tool": best, "speedup": med["moco"] / med[best]}
    finished = dt.datetime.now(dt.timezone.utc)
    meta = {"started_utc": started.isoformat(timespec="seconds"),
            "finished_utc": finished.isoformat(timespec="seconds"),
            "machine": machine(), "versions": versions(),
            "opensim": next((r["raw"].get("opensim_version") for r in runs
                             if r["tool"] == "moco"), None),
            "load_average_start": load_start, "load_average_end": os.getloadavg(),
            "compile_first_use_setup_s": first_use,
            "note": "other processes may share this 2-core machine: absolute times can be "
                    "inflated; ratios are measured within one run",
            "units": {"time": "s", "rms": "rad (angles), m (pelvis_tx, pelvis_ty)",
                      "rms_in_markdown": "deg (angles), mm (pelvis_tx, pelvis_ty)"},
            "definitions": {
                "solve_time": "wall time of the IPOPT call (CasADi nlpsol); Moco: CasADi's "
                              "'total' t_wall from Moco's log",
                "setup_time": "model + problem construction until the IPOPT call (gaitlib: "
                              "incl. symbolic NLP and derivative functions; Moco: incl. its "
                              "CasADi problem construction inside MocoStudy.solve())",
                "max_violation": "IPOPT's final unscaled constraint violation",
                "rms": "state-node values vs the 6 Hz filtered reference (natural quintic "
                       "spline, Moco's GCVSpline), computed by the same code for both tools"}}
    out = {"meta": meta, "speedups": speedups,
           "runs": [{k: v for k, v in r.items() if k != "raw"} for r in runs]}
    Path(args.out).with_suffix(".json").write_text(json.dumps(out, indent=1, default=str))
    md = [f"# T9-track: OpenSim Moco vs gaitlib ({meta['started_utc']})", "",
          f"Machine: {meta['machine']['cpu']} ({meta['machine']['cores']} cores), "
          f"{meta['machine']['platform']}; load average at start "
          f"{', '.join(f'{x:.2f}' for x in load_start)}. opensim {meta['opensim']}; "
          f"casadi {meta['versions']['casadi']}; gaitlib {meta['versions']['gaitlib_commit']}.",
          "", "Times in s; RMS in deg (angles) and mm (pelvis_tx, pelvis_ty) vs the filtered "
          "reference. Definitions in the JSON's `meta.definitions` and benchmarks/README.md.",
          "", *lines, ""]
    for scheme, s in speedups.items():
        md.append(f"- {scheme}: Moco {s['moco_solve_median']:.2f} s / gaitlib "
                  f"{s['gaitlib_solve_median']:.2f} s = **{s['speedup']:.1f}×**"
                  + (f"; gaitlib with IPOPT defaults {s['speedup_ipopt_defaults']:.1f}×"
                     if "speedup_ipopt_defaults" in s else "")
                  + (f"; gaitlib with per-node derivatives {s['speedup_nodes']:.1f}×"
                     if "speedup_nodes" in s else "")
                  + (f"; gaitlib with per-node derivatives, compiled {s['speedup_nodes_compiled']:.1f}×"
                     if "speedup_nodes_compiled" in s else "")
                  + (f"; the same with MUMPS's scaling off {s['speedup_nodes_compiled_unscaled']:.1f}×"
                     if "speedup_nodes_compiled_unscaled" in s else "")
                  + (f"; gaitlib MX not expanded {s['speedup_mx_noexpand']:.1f}×"
                     if "speedup_mx_noexpand" in s else "")
                  + "; setup + solve: " + ", ".join(
                      f"{k} {v:.1f} s" for k, v in s["end_to_end_median"].items()))
    for scheme, t in first_use.items():
        md.append(f"- {scheme}: the compiled variant's first use on this machine (compiling its per-node "
                  f"functions) took {t:.1f} s of setup; the timed repeats load the compiled libraries")
    for r in runs:
        if r["tool"] == "moco":
            cc = r["cross_check_in_gaitlib_nlp"]
            md.append(f"- {r['scheme']} (repeat {r['repeat']}): Moco's solution in gaitlib's "
                      f"NLP: objective {cc['objective']:.10f} (Moco: {r['objective']:.10f}), "
                      f"max defect {cc['max_violation_by_kind'].get('defects', float('nan')):.1e}")
    Path(args.out).with_suffix(".md").write_text("\n".join(md) + "\n")
    # every invocation is also appended to a history file (repeated measurements)
    hist = Path(args.out).parent / (Path(args.out).name + "_history.md")
    entry = [f"## {meta['started_utc']} (load average at start "
             f"{', '.join(f'{x:.2f}' for x in load_start)}; repeats {args.repeats})", "",
             *lines, "", *[ln for ln in md if ln.startswith("- ")], ""]
    with hist.open("a") as fh:
        if hist.stat().st_size == 0:
            fh.write("# T9-track benchmark history (appended by bench_moco_t9track.py)\n\n")
        fh.write("\n".join(entry) + "\n")

    print()
    print("\n".join(lines))
    print()
    print(f"results: {Path(args.out).with_suffix('.json')} and .md")
    for scheme, s in speedups.items():
        if not s["all_succeeded"]:
            print(f"WARNING: a {scheme} solve did not succeed (see the table's status column)")
    for scheme, s in speedups.items():
        print(f"speedup_vs_moco {scheme} {s['speedup']:.2f}")
    for scheme, s in speedups.items():
        print(f"speedup_vs_moco_best {scheme} {s['speedup_best']['speedup']:.2f}  ({s['speedup_best']['tool']})")
    for scheme, s in speedups.items():
        print(f"speedup_vs_moco_e2e {scheme} {s['speedup_e2e']['speedup']:.2f}  ({s['speedup_e2e']['tool']})")


if __name__ == "__main__":
    main()
