"""Reusing a built solver within a process (issue 22, lever "build once per problem structure").

    .venv/bin/python benchmarks/bench_build_reuse.py            # Ch 4 (b) at 20 × 5, ≈ 1 h 20 min
    .venv/bin/python benchmarks/bench_build_reuse.py --quick    # 6 × 3, one start, ≈ 7 min
    .venv/bin/python benchmarks/bench_build_reuse.py --start "thesis (c)"   # 20 × 5, one start (four solves)

Contact identification (b) of Ch 4 (``gaitlib.studies.contact_id.optimal_control_multistart``:
three starts, each through three continuation stages and the final problem — twelve solves)
from an empty solution cache, twice, each in a fresh process: with whole-graph solvers reused
within the process (``ocp._graph_solver``, the default) and with reuse off
(``GAITLIB_BUILD_REUSE_MB=0``). Per solve: build and solve time, iterations, objective (the
two runs must agree to the last bit: the same functions); per run: the process's wall time
(interpreter start to exit). Writes ``results/build_reuse.json`` and ``.md``. ``--quick``: the
6 × 3 mesh and the start "thesis (c)" only (four solves; a check of the script — at 6 × 3 a
build takes seconds; all three starts at 6 × 3 take ≈ 40 min, many stages stopping at 3000
iterations).
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

sys.path.insert(0, str(Path(__file__).resolve().parent))
from report import machine_info, md_table, write_report  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
ROOT = Path(__file__).resolve().parents[1]

WORKER = """
import json, sys
from pathlib import Path
from gaitlib.studies import contact_id as ci
n, d, root, starts = int(sys.argv[1]), int(sys.argv[2]), Path(sys.argv[3]), tuple(sys.argv[4].split(","))
ci.optimal_control_multistart(ci.spec_b(n, d), starts=starts, use_cache=True, root=root)
rows = []
for f in sorted(root.glob("contact_id/*/summary.json"), key=lambda f: f.stat().st_mtime):
    s = json.loads(f.read_text()); st = s["stats"]; spec = s.get("spec", {})
    rows.append({"key": f.parent.name, "residual_bounds": spec.get("residual_bounds"),
                 "status": st["status"], "iterations": st["iterations"], "reused": st.get("solver_reused", False),
                 "build_s": st["build_time_s"],
                 "solve_s": st["solve_time_s"], "objective": repr(st["objective"])})
print("ROWS " + json.dumps(rows))
"""


def run(n: int, d: int, reuse: bool, starts) -> dict:
    env = {**os.environ, "GAITLIB_STORE": "", "OPENBLAS_NUM_THREADS": "1",
           "PYTHONPATH": str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")}
    if not reuse:
        env["GAITLIB_BUILD_REUSE_MB"] = "0"
    with tempfile.TemporaryDirectory(prefix="gaitlib-reuse-") as tmp:
        t0 = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", WORKER, str(n), str(d), tmp, ",".join(starts)], env=env, capture_output=True,
                             text=True, check=True)
        e2e = time.perf_counter() - t0
    rows = json.loads(next(line for line in out.stdout.splitlines() if line.startswith("ROWS "))[5:])
    return {"reuse": reuse, "e2e_s": e2e, "rows": rows,
            "build_s": sum(r["build_s"] for r in rows), "solve_s": sum(r["solve_s"] for r in rows),
            "iterations": sum(r["iterations"] for r in rows)}


def ci_starts() -> tuple:
    sys.path.insert(0, str(ROOT / "src"))
    from gaitlib.studies import contact_id as ci

    return tuple(ci.B_STARTS)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="6 × 3 mesh (a check of the script, not the result)")
    ap.add_argument("--start", action="append", default=None,
                    help="a start of the multistart (repeatable; default all, or 'thesis (c)' with --quick)")
    ap.add_argument("--stem", default=None)
    args = ap.parse_args(argv)
    n, d = (6, 3) if args.quick else (20, 5)
    starts = tuple(args.start) if args.start else ("thesis (c)",) if args.quick else ci_starts()
    one = "" if args.start is None else f"_{len(starts)}start{'s' if len(starts) > 1 else ''}"
    stem = args.stem or ("build_reuse_quick" if args.quick else "build_reuse") + one
    load = list(os.getloadavg())
    runs = [run(n, d, reuse, starts) for reuse in (False, True)]
    off, on = runs
    same = [a["key"] == b["key"] and a["iterations"] == b["iterations"] and a["objective"] == b["objective"]
            for a, b in zip(sorted(off["rows"], key=lambda r: r["key"]), sorted(on["rows"], key=lambda r: r["key"]))]
    doc = {"measured": datetime.now(timezone.utc).isoformat(timespec="seconds"), "machine": machine_info(),
           "load_average_start": load,
           "mesh": [n, d], "starts": list(starts), "runs": runs, "identical_solves": f"{sum(same)} of {len(same)}",
           "command": "python benchmarks/bench_build_reuse.py" + (" --quick" if args.quick else "")
                      + "".join(f' --start "{x}"' for x in (args.start or ()))}
    cols = ["reuse", "solves", "builds", "e2e_s", "build_s", "solve_s", "iterations"]
    table = [{"reuse": "on" if r["reuse"] else "off", "solves": len(r["rows"]),
              "builds": sum(not row["reused"] for row in r["rows"]),
              "e2e_s": r["e2e_s"], "build_s": r["build_s"], "solve_s": r["solve_s"], "iterations": r["iterations"]}
             for r in runs]
    md = [f"# Reusing built solvers: Ch 4 (b) from an empty cache, {n} × {d}, starts {', '.join(starts)} ({doc['measured']}, "
          f"{doc['machine'].get('cpu', '')}, {doc['machine'].get('cores', '')} cores)", "",
          f"`{doc['command']}`; each run a fresh process, one BLAS thread. Solves identical (key, iterations, "
          f"objective to the last bit): {doc['identical_solves']}.", "",
          *md_table(cols, table), "",
          "Per solve (reuse on):", "",
          *md_table(["residual_bounds", "status", "iterations", "reused", "build_s", "solve_s", "objective"], on["rows"])]
    write_report(OUT, stem, doc, md)
    return 0 if all(same) else 1


if __name__ == "__main__":
    raise SystemExit(main())
