"""The README's examples run as written.

Rule: every ```python and ```bash block of README.md is preceded by a marker line,
``<!-- example: run -->`` (cheap: no solve, or a coarse mesh) or ``<!-- example: skip (why) -->``
(the full mesh, the book, the whole test suite). The ``run`` blocks are executed in README
order in one fresh folder with a fresh solutions cache: a python block as a script of its
own (``python block.py`` — as a user would save it, so the dask sweep needs its
``__main__`` guard), a bash block line by line with ``gaitlib`` on the PATH."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
MARKER = re.compile(r"<!--\s*example:\s*(run|skip)\b.*-->")


def blocks() -> list[tuple[str, str, str]]:
    """(marker, language, code) of every python/bash block, in order."""
    lines = README.read_text().splitlines()
    out, i = [], 0
    while i < len(lines):
        m = re.match(r"^```(\w+)\s*$", lines[i])
        if not m:
            i += 1
            continue
        j = next(k for k in range(i + 1, len(lines)) if lines[k].startswith("```"))
        if m.group(1) in ("python", "bash"):
            prev = next((lines[k] for k in range(i - 1, -1, -1) if lines[k].strip()), "")
            mk = MARKER.search(prev)
            assert mk, f"README.md line {i + 1}: a {m.group(1)} block without '<!-- example: run|skip (why) -->'"
            out.append((mk.group(1), m.group(1), "\n".join(lines[i + 1:j]) + "\n"))
        i = j + 1
    return out


def test_every_example_is_marked_and_some_run():
    b = blocks()
    assert sum(mk == "run" for mk, _, _ in b) >= 3 and any(mk == "skip" for mk, _, _ in b)


@pytest.mark.slow
def test_readme_examples_run_as_written(tmp_path):
    """The cheap examples (``run``), in README order, each in a fresh process; exit 0."""
    work, cache = tmp_path / "work", tmp_path / "cache"
    work.mkdir()
    bindir = os.path.dirname(sys.executable)
    env = dict(os.environ, GAITLIB_SOLUTIONS=str(cache), OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               MPLBACKEND="Agg", PATH=bindir + os.pathsep + os.environ.get("PATH", ""))
    ran = 0
    for n, (mk, lang, code) in enumerate(blocks()):
        if mk != "run":
            continue
        if lang == "python":
            script = work / f"readme_example_{n}.py"
            script.write_text(code)
            cmds = [[sys.executable, script.name]]
        else:
            cmds = [["bash", "-c", ln] for ln in code.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
        for cmd in cmds:
            # a guard against a hang, not a speed claim
            p = subprocess.run(cmd, cwd=work, env=env, capture_output=True, text=True, timeout=900)
            assert p.returncode == 0, f"README example {cmd[-1]!r} failed:\n{p.stdout[-2000:]}\n{p.stderr[-3000:]}"
            ran += 1
    assert ran >= 3
    # the coarse run wrote its outputs; the sweep reused its solution and solved the other
    assert (work / "out" / "sk_coarse" / "summary.json").is_file()
    assert len(list((cache / "gait").iterdir())) == 2


if __name__ == "__main__":  # pragma: no cover
    pytest.main([__file__, "-q"])
