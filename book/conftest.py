"""nbval over the book: a notebook whose solutions the repository's store does not hold is
skipped, with the reason and the command that re-solves it, instead of silently solving for
hours inside ``make test``.

``solutions/README.md`` lists the notebooks whose solutions ``tools/store_solutions.py``
stored (with their times from the store); a notebook not listed there would re-solve from
scratch. Set ``GAITLIB_BOOK_SOLVE=1`` to execute it anyway (``make book`` always does).

The notebooks' kernels inherit this process's environment: the Makefile's BLAS settings are
set here (:func:`gaitlib.blas.pin`) for nbval runs outside ``make``.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from gaitlib import blas

blas.pin()

STORE_README = Path(__file__).resolve().parents[1] / "solutions" / "README.md"


def stored_notebooks() -> set[str]:
    if not STORE_README.is_file():
        return set()
    return {line[2:].split(":", 1)[0].strip() for line in STORE_README.read_text().splitlines()
            if line.startswith("- ") and ".ipynb:" in line}


def pytest_collection_modifyitems(config, items):
    if os.environ.get("GAITLIB_BOOK_SOLVE"):
        return
    stored = stored_notebooks()
    for item in items:
        nb = Path(str(item.fspath))
        if nb.suffix == ".ipynb" and nb.name not in stored:
            item.add_marker(pytest.mark.skip(
                reason=f"{nb.name}: its solutions are not in the repository's store (solutions/README.md); "
                       f"`python tools/store_solutions.py book/{nb.name}` re-solves and stores them, "
                       f"GAITLIB_BOOK_SOLVE=1 runs it here anyway"))
