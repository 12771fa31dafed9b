"""Refresh the repository's solution store (``solutions/``) from a run of the book.

Usage: python tools/store_solutions.py [--fresh] [book/chNN_x.ipynb ...]   (default: every notebook
in book/_toc.yml order)

Every notebook is executed with the usual writable cache (``$GAITLIB_SOLUTIONS`` or
~/.cache/gaitlib/solutions; ``--fresh``: an empty temporary one, which measures the
from-scratch time) and the current store as read-only fallback. Afterwards the store is
replaced by exactly the entries the run used: those it reloaded and those it had to solve.
Stale entries (older code or data) are never hit, so they drop out. Prints the wall time
per notebook.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from gaitlib import blas

# the Makefile's BLAS settings, for the notebooks this runs (keys of gap solutions hash the
# data's numbers, which depend on OpenBLAS's kernel: see environment.md)
blas.pin()

REPO = Path(__file__).resolve().parents[1]
STORE = REPO / "solutions"


def notebooks(argv) -> list[Path]:
    if argv:
        return [Path(a).resolve() for a in argv]
    import yaml

    toc = yaml.safe_load((REPO / "book" / "_toc.yml").read_text())
    files = [c["file"] for c in toc.get("chapters", [])]
    return [REPO / "book" / f"{f}.ipynb" for f in files if (REPO / "book" / f"{f}.ipynb").exists()]


#: nbval's per-cell limit for a refresh, s (Ch 6's sweep cell, solving on 2 workers beside
#: another refresh, was stopped at nbval's default of 2,000 s).
CELL_TIMEOUT_S = 4 * 3600


def main(argv) -> int:
    fresh = "--fresh" in argv
    nbs = notebooks([a for a in argv if a != "--fresh"])
    tmp = Path(tempfile.mkdtemp(prefix="gaitlib-store-"))
    log = tmp / "used.log"
    env = dict(os.environ, GAITLIB_CACHE_LOG=str(log), GAITLIB_STORE=str(STORE) if STORE.is_dir() else "")
    if fresh:
        env["GAITLIB_SOLUTIONS"] = str(tmp / "cache")
    times = {}
    failed = []
    for nb in nbs:
        t0 = time.time()
        # executed as CI does (nbval), so a store built here is what `make test` reads; a cell
        # that solves a sweep from an empty cache may take longer than nbval's 2000 s default
        r = subprocess.run([sys.executable, "-m", "pytest", "-q", "--nbval-lax", "-p", "no:cacheprovider",
                            f"--nbval-cell-timeout={CELL_TIMEOUT_S}", str(nb)], env=env, cwd=REPO)
        times[nb.name] = time.time() - t0
        print(f"{nb.name}: {times[nb.name]:.0f} s{'' if r.returncode == 0 else ' — FAILED'}", flush=True)
        if r.returncode:
            failed.append(nb.name)
    if failed:
        print(f"not refreshing the store: {failed} failed", file=sys.stderr)
        return 1
    used = {Path(p) for p in log.read_text().split()} if log.exists() else set()
    new = tmp / "store"
    for entry in used:  # looked up (solved here or reloaded) or served from the store
        src = entry if entry.is_dir() else STORE / entry.parent.name / entry.name
        dest = new / entry.parent.name / entry.name
        if src.is_dir() and not dest.exists():
            shutil.copytree(src, dest)
    new.mkdir(parents=True, exist_ok=True)
    subset = any(a != "--fresh" for a in argv)
    if subset and STORE.exists():  # some notebooks only: keep the other chapters' entries
        for kind in STORE.iterdir():
            if kind.is_dir():
                for e in kind.iterdir():
                    if not (new / kind.name / e.name).exists():
                        shutil.copytree(e, new / kind.name / e.name)
    if subset and (STORE / "README.md").exists():  # keep the other notebooks' times, in book order
        old = dict(line[2:].rsplit(": ", 1) for line in (STORE / "README.md").read_text().splitlines()
                   if line.startswith("- ") and ": " in line)
        order = [p.name for p in notebooks([])]
        merged = {k: float(v.rstrip(" s")) for k, v in old.items()}
        merged.update(times)
        times = {k: merged[k] for k in sorted(merged, key=lambda k: order.index(k) if k in order else len(order))}
    if STORE.exists():
        shutil.rmtree(STORE)
    shutil.move(str(new), STORE)
    (STORE / "README.md").write_text(
        "Solutions the book loads instead of re-solving, keyed by spec + formulation version + data\n"
        "(gaitlib.cache). Written by tools/store_solutions.py; never edit by hand. The notebooks listed\n"
        "run from the store (their time from it); `make test` skips a notebook not listed (book/conftest.py).\n\n"
        + "\n".join(f"- {k}: {v:.0f} s" for k, v in times.items()) + "\n")
    print(f"store: {len(used)} entries used by this run; times (s): {times}")
    shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
