"""Reading stored solutions (issue 22: the book and CI from the repository's store).

    .venv/bin/python benchmarks/bench_load.py                       # this tree, 2 repeats
    git worktree add /tmp/before <rev>                               # a tree to compare with
    .venv/bin/python benchmarks/bench_load.py --src /tmp/before/src --src src --repeats 3

Three workloads that only load what ``solutions/`` holds (``GAITLIB_CACHE_ONLY=1``, an empty
user cache, so nothing is solved), each in a fresh process, for every source tree given
(``--src``, alternated run by run so that both see the same machine load): the SK diagnosis of
the Schwartz data that Chapter 8 opens with (``gaitlib.studies.gap.sk_diagnosis``; 26 gap
re-solves loaded), the muscle-level twins (``muscle_twin_validation``: 123 MSK re-solves
loaded and located) and the card's Ch 7 curve on longer legs (``card._legs_curve``: 12 NMSK
and MSK solutions loaded, their problems rebuilt). Per run: the process's wall time
(interpreter start to exit) and the workload's own time in the process. Writes
``results/load.json`` and ``.md``.
"""

from __future__ import annotations

import argparse
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

WORKLOADS = {
    "SK diagnosis (Ch 8)": "from gaitlib.studies import gap as m\nm.sk_diagnosis('schwartz2008')",
    "muscle-level twins (Ch 8)": "from gaitlib.studies import gap as m\nm.muscle_twin_validation()",
    "Ch 7 curve on longer legs (card)": "from gaitlib.studies import card as m\nm._legs_curve()",
}

WORKER = """
import time, sys
t0 = time.perf_counter()
exec(sys.argv[1])
print("WORK", time.perf_counter() - t0)
"""


def run(src: Path, code: str) -> dict:
    """One workload in a fresh process on the source tree ``src``: its wall time and the
    workload's own time (s)."""
    with tempfile.TemporaryDirectory(prefix="gaitlib-load-") as tmp:
        env = {**os.environ, "GAITLIB_SOLUTIONS": tmp, "GAITLIB_CACHE_ONLY": "1", "OPENBLAS_NUM_THREADS": "1",
               "OMP_NUM_THREADS": "1", "OPENBLAS_CORETYPE": "Haswell", "PYTHONPATH": str(src)}
        t0 = time.perf_counter()
        p = subprocess.run([sys.executable, "-c", WORKER, code], env=env, capture_output=True, text=True,
                           cwd=str(ROOT))
        wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{src}: {code!r} failed:\n{p.stderr[-2000:]}")
    work = float([line for line in p.stdout.splitlines() if line.startswith("WORK ")][-1].split()[1])
    return {"wall_s": wall, "work_s": work}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--src", action="append", type=Path, help="a gaitlib source tree (repeatable; default src/)")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--out", type=Path, default=OUT)
    a = ap.parse_args(argv)
    srcs = [s.resolve() for s in (a.src or [ROOT / "src"])]
    rows = []
    for name, code in WORKLOADS.items():
        for rep in range(a.repeats):
            for src in srcs:
                r = run(src, code)
                rows.append({"workload": name, "src": str(src), "repeat": rep, **r})
                print(f"{name:35s} {src}  wall {r['wall_s']:.1f} s  work {r['work_s']:.1f} s", flush=True)
    summary = []
    for name in WORKLOADS:
        for src in srcs:
            w = sorted(r["work_s"] for r in rows if r["workload"] == name and r["src"] == str(src))
            e = sorted(r["wall_s"] for r in rows if r["workload"] == name and r["src"] == str(src))
            summary.append({"workload": name, "src": str(src), "runs": len(w), "work_s (min)": w[0],
                            "work_s (max)": w[-1], "wall_s (min)": e[0]})
    doc = {"when": datetime.now(timezone.utc).isoformat(timespec="seconds"), "machine": machine_info(),
           "repeats": a.repeats, "srcs": [str(s) for s in srcs], "runs": rows, "summary": summary}
    m = doc["machine"]
    md = [f"# Reading stored solutions ({doc['when']}, {m['cpu']}, {m['cores']} cores)", "",
          "Each run a fresh process with `GAITLIB_CACHE_ONLY=1` and an empty user cache (everything from "
          "`solutions/`), source trees alternated; `work_s` = the workload's call, `wall_s` = the process. "
          "`python benchmarks/bench_load.py --src <before>/src --src src`.", "",
          *md_table(["workload", "src", "runs", "work_s (min)", "work_s (max)", "wall_s (min)"], summary)]
    write_report(a.out, "load", doc, md)


if __name__ == "__main__":
    main()
