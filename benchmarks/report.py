"""Writing a benchmark's results: the machine it ran on and its ``results/<name>.json`` +
``.md`` pair. Used by the ``bench_*.py`` scripts (run from this folder, which is then on
the import path); the book reads the files with :mod:`gaitlib.studies.performance`."""

from __future__ import annotations

import json
import os
import platform
from pathlib import Path

__all__ = ["md_table", "write_report", "machine_info"]


def md_table(cols, rows) -> list[str]:
    """A markdown table of ``rows`` (dicts) over ``cols``: floats to 4 significant digits,
    missing values empty. Returns its lines (header, separator, one per row)."""
    def cell(v):
        return f"{v:.4g}" if isinstance(v, float) else ("" if v is None else str(v))

    return ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)] + [
        "| " + " | ".join(cell(r.get(c)) for c in cols) + " |" for r in rows]


def write_report(out: Path, stem: str, doc: dict, md: list[str]) -> None:
    """A benchmark's results: ``<out>/<stem>.json`` (``doc``) and ``<out>/<stem>.md``
    (``md`` lines, also printed)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{stem}.json").write_text(json.dumps(doc, indent=1, default=str))
    (out / f"{stem}.md").write_text("\n".join(md) + "\n")
    print("\n".join(md))


def machine_info() -> dict:
    """The machine a benchmark ran on: CPU model, cores, memory (GiB), platform, Python, host."""
    cpu = platform.processor() or ""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    mem = None
    try:
        mem = round(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2 ** 30, 1)
    except (ValueError, OSError, AttributeError):
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "memory_gb": mem, "platform": platform.platform(),
            "python": platform.python_version(), "node": platform.node()}
