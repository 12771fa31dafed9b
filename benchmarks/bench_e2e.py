"""End to end, as a user runs it: the CLI command in a fresh process, from an empty solution
cache, timed from the shell (interpreter start, imports, build, solve, writing the outputs).

    .venv/bin/python benchmarks/bench_e2e.py                 # MSK DT Free 20 × 5, ≈ 7 min
    .venv/bin/python benchmarks/bench_e2e.py --gap           # and `gaitlib gap` on a new CSV, ≈ +20 min
    .venv/bin/python benchmarks/bench_e2e.py --quick         # 4 × 3 mesh (checks the script)

Issue 22's targets 2 and 3: ``gaitlib run gait --model MSK --cost DT --speed Free`` (20 × 5)
in ≤ 20 s including the build, and ``gaitlib gap`` on a new CSV at its default mesh in
≤ 60 s. Each command runs once per variant, one after another, each in its own process with
one BLAS thread and ``--no-cache`` (nothing is read from or written to a solution cache):

* ``graph``: the default derivative path (CasADi differentiates the whole NLP graph);
* ``nodes``: ``--derivatives nodes`` (per-node derivative functions, chain rule);
* ``nodes, compiled (first use)``: ``--derivatives nodes --compiled`` with an empty library
  cache (``GAITLIB_COMPILED`` a fresh directory): the per-node functions are compiled to C
  during the build;
* ``nodes, compiled``: the same command again: the libraries are loaded.

``gaitlib gap`` runs as a user runs it: its default LocalCluster (one worker per core), the
SK baseline at its default 10 × 3 mesh and every applicable candidate.

The compiled rows must reproduce the ``nodes`` row's iterations and objective exactly
(``same_as_nodes``): compiled evaluation changes the time, not the numbers. ``graph`` and
``nodes`` are the same NLP with derivatives equal to round-off; IPOPT's path (iterations,
local optimum) can differ between them.

Per row: process wall time (``e2e_s``), build and solve time as gaitlib records them,
iterations, ms per iteration, IPOPT's function-evaluation time (``evals_s``, the sum of its
``t_wall_nlp_*``) and the rest of the IPOPT call (``ipopt_rest_s``: its own linear algebra,
MUMPS's factorisations). Writes ``results/e2e.json`` and ``e2e.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
OUT = HERE / "results"
ENV1 = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
VARIANTS = (("graph", []), ("nodes", ["--derivatives", "nodes"]),
            ("nodes, compiled (first use)", ["--derivatives", "nodes", "--compiled"]),
            ("nodes, compiled", ["--derivatives", "nodes", "--compiled"]))


def _run(cmd: list[str], env: dict) -> tuple[float, subprocess.CompletedProcess]:
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=ROOT)
    return time.perf_counter() - t0, p


def _gait_row(sol: dict) -> dict:
    tw = sol.get("info", {}).get("ipopt_t_wall", {})
    evals = sum(v for k, v in tw.items() if k.startswith("t_wall_nlp"))
    its = int(sol["iterations"])
    return {"status": sol["status"], "iterations": its, "build_s": sol["build_time"], "solve_s": sol["solve_time"],
            "ms_per_iteration": 1e3 * sol["solve_time"] / max(its, 1), "evals_s": evals,
            "ipopt_rest_s": sol["solve_time"] - evals, "objective": sol["objective"]}


def _timed(label: str, args: list[str], libs: Path, parse) -> list[dict]:
    """``gaitlib <args> --out <tmp>/out <variant flags>`` for every variant, each timed from
    the shell in a fresh process; ``parse(out_dir)`` turns its outputs into row fields."""
    rows = []
    for name, extra in VARIANTS:
        with tempfile.TemporaryDirectory(prefix="bench-e2e-") as tmp:
            cmd = [sys.executable, "-m", "gaitlib", *args, "--out", f"{tmp}/out", *extra]
            load = os.getloadavg()[0]
            wall, p = _run(cmd, {**os.environ, **ENV1, "GAITLIB_COMPILED": str(libs)})
            row = {"command": label, "variant": name, "flags": " ".join(extra), "e2e_s": wall, "load_at_start": load}
            if p.returncode != 0:
                rows.append({**row, "status": "error: " + " ".join((p.stderr or p.stdout)[-300:].split())})
            else:
                rows.append({**row, **parse(Path(tmp) / "out")})
        print(f"{label} — {name}: {rows[-1].get('status')}, e2e {wall:.1f} s", flush=True)
    return rows


def gait_rows(quick: bool, libs: Path) -> list[dict]:
    mesh = ["--intervals", "4", "--degree", "3"] if quick else []
    return _timed("gaitlib run gait --model MSK --cost DT --speed Free",
                  ["run", "gait", "--model", "MSK", "--cost", "DT", "--speed", "Free", "--no-cache", "--no-figures",
                   "--quiet", *mesh], libs,
                  lambda out: _gait_row(json.loads((out / "ocp" / "solution.json").read_text())))


def gap_rows(quick: bool, libs: Path, work: Path) -> list[dict]:
    """``gaitlib gap`` on a new CSV: a twin of the Free data with a knee-angle offset of
    0.1 rad (``gaitlib gap-twin``, made first and not timed)."""
    csv = work / "twin_knee_offset.csv"
    twin = [sys.executable, "-m", "gaitlib", "gap-twin", "--effect", "knee_offset", "--magnitude", "0.1", "--seed", "1",
            "--out", str(csv)]
    _, p = _run(twin, {**os.environ, **ENV1})
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(twin)}: {p.stderr[-500:]}")
    mesh = ["--intervals", "4", "--degree", "3"] if quick else []

    def parse(out: Path) -> dict:
        d = json.loads((out / "diagnosis.json").read_text())
        return {"status": "ok", "verdict": d.get("verdict", d.get("top")), **_gap_solves(d)}

    return _timed("gaitlib gap --data twin_knee_offset.csv",
                  ["gap", "--data", str(csv), "--no-cache", "--no-figures", *mesh], libs, parse)


def _gap_solves(d: dict) -> dict:
    """The candidates a diagnosis re-solved (its ranking) and the baseline fit's iterations."""
    base = d.get("baseline", {}).get("stats", {})
    return {"candidates": len(d.get("ranking", [])), "baseline_iterations": base.get("iterations"),
            "top_effect": d.get("top_effect")}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--gap", action="store_true", help="also time `gaitlib gap` on a new CSV")
    args = ap.parse_args(argv)
    stem = "e2e_quick" if args.quick else "e2e"
    with tempfile.TemporaryDirectory(prefix="bench-e2e-libs-") as libs:
        rows = gait_rows(args.quick, Path(libs))
        _write(args, stem, rows, [])  # kept if the gap part fails
        gap = gap_rows(args.quick, Path(libs), Path(libs)) if args.gap else []
    _write(args, stem, rows, gap)
    return 0


def _write(args, stem: str, rows: list[dict], gap: list[dict]) -> None:
    nodes = next((r for r in rows if r["variant"] == "nodes"), {})
    for r in rows:
        if "compiled" in r["variant"] and "iterations" in r:
            r["same_as_nodes"] = (r["iterations"] == nodes.get("iterations") and r["objective"] == nodes.get("objective"))
    from report import machine_info, md_table, write_report

    doc = {"measured": datetime.now(timezone.utc).isoformat(timespec="seconds"), "machine": machine_info(),
           "quick": args.quick, "gait": rows, "gap": gap}
    m = doc["machine"]
    md = [f"# End to end, from an empty solution cache ({doc['measured']}, {m['cpu']}, {m['cores']} cores)", "",
          "Each command in a fresh process, `--no-cache`, one BLAS thread; `e2e_s` = process wall time "
          "(interpreter start, imports, build, solve, outputs). `python benchmarks/bench_e2e.py"
          + (" --gap" if gap else "") + "`.", ""]
    md += md_table(["variant", "flags", "status", "iterations", "e2e_s", "build_s", "solve_s", "ms_per_iteration",
                    "evals_s", "ipopt_rest_s", "objective", "same_as_nodes", "load_at_start"], rows)
    if gap:
        md += ["", "`gaitlib gap` on a new CSV (a twin of the Free data with a knee-angle offset, "
               "`gaitlib gap-twin --effect knee_offset --magnitude 0.1 --seed 1`), default mesh, LocalCluster (one worker per core):", ""]
        md += md_table(["variant", "flags", "status", "verdict", "candidates", "baseline_iterations", "e2e_s",
                        "load_at_start"], gap)
    write_report(OUT, stem, doc, md)


if __name__ == "__main__":
    sys.exit(main())
