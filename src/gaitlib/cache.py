"""Solution cache keyed by *what* was solved and *with which code*.

A key is the SHA-256 of a spec (any JSON-able mapping) together with :func:`fingerprint` —
the library version plus a hash of every ``.py`` file of the installed package that can
change a solution (all but the presentation-only modules in :data:`PRESENTATION_ONLY`:
plotting, command line, sweep engine, peer-model import) and of the data files (CSV and
JSON, e.g. identified parameters). Editing any such file changes every key, so a cached
solution is never served for code or data it was not computed with (stale entries are
simply never hit again; ``clear`` removes them).

Default location: ``$GAITLIB_SOLUTIONS`` or ``~/.cache/gaitlib/solutions``.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from functools import lru_cache
from pathlib import Path

from . import __version__

__all__ = ["fingerprint", "key", "default_dir", "lookup", "clear"]

_PKG = Path(__file__).resolve().parent

#: Modules that never change what a solve returns (drawing, CLI parsing, scheduling runs,
#: the Moco peer model): editing them keeps the cache valid.
PRESENTATION_ONLY = frozenset({"plots.py", "cli.py", "__main__.py", "sweep.py", "peers.py"})


@lru_cache(maxsize=1)
def fingerprint() -> str:
    """Version + hash of the solver-relevant package sources and the data files (16 hex digits)."""
    from . import data

    h = hashlib.sha256(__version__.encode())
    files = [(f"gaitlib/{f.relative_to(_PKG).as_posix()}", f) for f in sorted(_PKG.rglob("*.py"))
             if f.relative_to(_PKG).as_posix() not in PRESENTATION_ONLY]
    data_dir = Path(data.DATA_DIR)
    if data_dir.is_dir():
        files += [(f"data/{f.relative_to(data_dir).as_posix()}", f) for f in sorted(data_dir.rglob("*"))
                  if f.suffix in (".csv", ".json") and f.name != "PROVENANCE.json"]
    for name, f in files:
        h.update(name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:16]


def key(spec: dict) -> str:
    """Cache key of a JSON-able spec under the current code and data (16 hex digits)."""
    blob = json.dumps({"spec": spec, "code": fingerprint()}, sort_keys=True, default=str)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def default_dir() -> Path:
    return Path(os.environ.get("GAITLIB_SOLUTIONS", Path.home() / ".cache" / "gaitlib" / "solutions"))


def lookup(kind: str, spec: dict, root=None) -> Path:
    """Directory where a solution of ``spec`` is (or would be) stored."""
    root = Path(root) if root is not None else default_dir()
    return root / kind / key(spec)


def clear(root=None) -> None:
    root = Path(root) if root is not None else default_dir()
    if root.exists():
        shutil.rmtree(root)
