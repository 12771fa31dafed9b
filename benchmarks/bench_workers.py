"""One worker vs two: the book's sweeps on a dask cluster of separate processes (issue 22,
target 1: "measure 1 vs 2 workers").

    .venv/bin/python benchmarks/bench_workers.py              # ≈ 15 min
    .venv/bin/python benchmarks/bench_workers.py --quick      # 4 × 3 meshes: checks the script

Each workload is a user's command sent to a cluster started the way the README shows —
``dask scheduler`` and ``dask worker --nworkers N --nthreads 1`` as separate processes, one
BLAS thread each — with ``--no-cache`` (everything solved) and timed from the shell:

* ``gaitlib gap`` on a new CSV (the twin of the Free data with a 0.1 rad knee offset that
  ``bench_e2e.py`` uses), its default 10 × 3 SK mesh: the kind of solve Chapter 8 runs by the
  hundred (a baseline fit, then one re-solve per candidate effect);
* ``gaitlib sweep --model MSK --costs DT,SDT1,SDT2,SP1 --speeds Free`` (20 × 5): four of
  Chapter 6's runs, independent solves of a few minutes each.

The cluster is started anew for every run (one worker process, or two), the two worker
counts alternating run by run so that both see the same machine. Writes
``results/workers.json`` / ``.md``: wall time per run, the speed-up of two workers over one
(median over repeats) and the parallel efficiency (speed-up ÷ 2).
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from report import machine_info, md_table, write_report  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
OUT = HERE / "results"
ENV1 = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
        "OPENBLAS_CORETYPE": "Haswell"}
BIN = Path(sys.executable).parent


def _cluster(n: int, tmp: Path, env: dict):
    """A scheduler and ``n`` worker processes; returns (scheduler file, [processes])."""
    sf = tmp / f"scheduler-{n}-{time.monotonic_ns()}.json"
    kw = {"env": env, "stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "start_new_session": True}
    sched = subprocess.Popen([str(BIN / "dask"), "scheduler", "--port", "0", "--dashboard-address", ":0",
                              "--scheduler-file", str(sf)], **kw)
    for _ in range(300):
        if sf.exists() and sf.stat().st_size:
            break
        time.sleep(0.1)
    work = subprocess.Popen([str(BIN / "dask"), "worker", "--scheduler-file", str(sf), "--nworkers", str(n),
                             "--nthreads", "1", "--no-dashboard", "--local-directory", str(tmp)], **kw)
    from distributed import Client

    with Client(scheduler_file=str(sf), timeout=60) as c:
        c.wait_for_workers(n, timeout=120)
    return sf, [work, sched]


def _stop(procs) -> None:
    for p in procs:
        try:
            os.killpg(p.pid, signal.SIGTERM)
            p.wait(timeout=30)
        except (ProcessLookupError, subprocess.TimeoutExpired):
            os.killpg(p.pid, signal.SIGKILL)


def _ran_on(out: Path) -> dict:
    """A sweep's ``sweep.csv``: how many distinct worker processes ran its solves, and their
    iterations in all (the same work on one worker and on two); empty for other commands."""
    f = out / "sweep.csv"
    if not f.exists():
        return {}
    import pandas as pd

    df = pd.read_csv(f)
    return {"ran_on": int(df["worker"].nunique()), "iterations": int(df["iterations"].sum())}


def workloads(quick: bool, tmp: Path, env: dict) -> dict[str, list[str]]:
    csv = tmp / "twin_knee_offset.csv"
    subprocess.run([sys.executable, "-m", "gaitlib", "gap-twin", "--effect", "knee_offset", "--magnitude", "0.1",
                    "--seed", "1", "--out", str(csv)], env=env, check=True, capture_output=True, cwd=ROOT)
    mesh = ["--intervals", "4", "--degree", "3"] if quick else []
    return {"gaitlib gap (new CSV, 10 × 3)": ["gap", "--data", str(csv), "--no-cache", "--no-figures", *mesh],
            "gaitlib sweep MSK DT,SDT1,SDT2,SP1 Free (20 × 5)":
                ["sweep", "--model", "MSK", "--costs", "DT,SDT1,SDT2,SP1", "--speeds", "Free", "--no-cache",
                 "--no-figures", *mesh]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--repeats", type=int, default=None, help="runs per worker count (default 2 gap, 1 sweep)")
    args = ap.parse_args(argv)
    env = {**os.environ, **ENV1, "PYTHONPATH": str(ROOT / "src")}
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench-workers-") as t:
        tmp = Path(t)
        env["GAITLIB_SOLUTIONS"] = str(tmp / "cache")
        for label, cmd in workloads(args.quick, tmp, env).items():
            reps = args.repeats or (2 if label.startswith("gaitlib gap") else 1)
            for rep in range(reps):
                for n in ((1, 2) if rep % 2 == 0 else (2, 1)):
                    sf, procs = _cluster(n, tmp, env)
                    try:
                        out = tmp / f"out-{n}-{rep}-{len(rows)}"
                        load = os.getloadavg()[0]
                        t0 = time.perf_counter()
                        p = subprocess.run([sys.executable, "-m", "gaitlib", *cmd, "--scheduler", str(sf),
                                            "--out", str(out)], env=env, capture_output=True, text=True, cwd=ROOT)
                        wall = time.perf_counter() - t0
                    finally:
                        _stop(procs)
                    status = "ok" if p.returncode in (0, 2) else "error: " + " ".join(p.stderr[-300:].split())
                    rows.append({"workload": label, "workers": n, "repeat": rep, "wall_s": wall,
                                 "exit": p.returncode, "status": status, "load_at_start": load,
                                 **_ran_on(out)})
                    print(f"{label} — {n} worker(s), repeat {rep}: {wall:.1f} s (exit {p.returncode})", flush=True)
    summary = []
    for label in dict.fromkeys(r["workload"] for r in rows):
        med = {n: statistics.median(r["wall_s"] for r in rows if r["workload"] == label and r["workers"] == n
                                    and r["status"] == "ok") for n in (1, 2)}
        summary.append({"workload": label, "1 worker (s)": med[1], "2 workers (s)": med[2],
                        "speed-up": med[1] / med[2], "efficiency": med[1] / med[2] / 2})
    doc = {"measured": datetime.now(timezone.utc).isoformat(timespec="seconds"), "machine": machine_info(),
           "quick": args.quick, "rows": rows, "summary": summary}
    md = [f"# One worker vs two on a dask cluster of separate processes ({doc['measured']})", "",
          f"Machine: {doc['machine']['cpu']}, {doc['machine']['cores']} cores; `dask scheduler` + `dask worker "
          "--nworkers N --nthreads 1`, each command with `--no-cache --scheduler FILE`, timed from the shell.", ""]
    md += md_table(["workload", "workers", "repeat", "wall_s", "exit", "status", "load_at_start", "ran_on", "iterations"], rows)
    md += ["", *md_table(list(summary[0]), summary)]
    write_report(OUT, "workers", doc, md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
