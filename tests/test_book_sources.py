"""Every notebook the book executes is its ``book/src/*.py`` source, cell for cell
(``python tools/nbbuild.py book/src/X.py book/X.ipynb`` after editing the source)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import nbformat
import pytest

REPO = Path(__file__).resolve().parents[1]
SOURCES = sorted((REPO / "book" / "src").glob("*.py"))


def _nbbuild():
    spec = importlib.util.spec_from_file_location("nbbuild", REPO / "tools" / "nbbuild.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("src", SOURCES, ids=[p.stem for p in SOURCES])
def test_notebook_matches_its_source(src):
    nb_path = REPO / "book" / f"{src.stem}.ipynb"
    assert nb_path.exists(), f"{nb_path} missing: python tools/nbbuild.py {src} {nb_path}"
    want = [(c.cell_type, c.source) for c in _nbbuild().parse(src.read_text())]
    have = [(c.cell_type, c.source) for c in nbformat.read(nb_path, as_version=4).cells]
    assert have == want, f"{nb_path.name} differs from {src.name}: python tools/nbbuild.py {src} {nb_path}"
