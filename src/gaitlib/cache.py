"""Solution cache keyed by *what* was solved and *with which code*.

A key is the SHA-256 of a spec (any JSON-able mapping) together with :func:`fingerprint` —
the library version plus a hash of the source files that can change a solution and of the
data files (CSV and JSON; not ``PROVENANCE.json``). Identified parameter sets
(``data/identified/<name>.json``) are outputs of some studies and inputs of others: a
caller that knows which sets its spec reads passes their names (``identified=``, e.g.
:meth:`gaitlib.transcription.GaitSpec.identified_sets`) and only those are hashed, so a
study's own output, or a set it does not read, never invalidates it; ``identified=None``
(the default) hashes them all. The sources
are the :data:`CORE` modules (physics, collocation, the gait transcription) plus the modules
the caller declares — by default the module that calls :func:`lookup` (so a study that
builds its own problem, e.g. the jump, keys on its own code too). Editing any such file
changes the key, so a cached solution is never served for code or data it was not computed
with (stale entries are simply never hit again; ``clear`` removes them). Editing a
presentation module (plots, CLI, sweep engine, another chapter's study) keeps entries valid.

Default location: ``$GAITLIB_SOLUTIONS`` or ``~/.cache/gaitlib/solutions``. Read-only
fallback: the solutions stored in the repository (:func:`store_dir`), so that the book
builds from a clean clone without re-solving; refresh them with ``tools/store_solutions.py``
after a change to the CORE sources (stale entries are ignored, never served).
"""

from __future__ import annotations

import hashlib
import inspect
import json
import os
import shutil
from functools import lru_cache
from pathlib import Path

from . import __version__

__all__ = ["CORE", "fingerprint", "key", "default_dir", "store_dir", "find", "lookup", "clear"]

_PKG = Path(__file__).resolve().parent

#: Modules every solution depends on (paths relative to the package).
CORE = ("__init__.py", "cache.py", "conventions.py", "data.py", "model.py", "kinematics.py", "contact.py",
        "mtg.py", "activation.py", "metabolics.py", "collocation.py", "ocp.py", "transcription.py", "params.py")


def _module_path(m) -> str:
    """Package-relative path of a module given as a relative path or an absolute file."""
    p = Path(m)
    if p.is_absolute():
        p = p.resolve().relative_to(_PKG)
    return p.as_posix()


@lru_cache(maxsize=256)
def _file_digest(path: str, mtime_ns: int, size: int) -> bytes:
    """SHA-256 of a file's bytes (memoised on path, mtime and size: a rewritten file is
    re-read, so a set written during a session changes the keys at once)."""
    return hashlib.sha256(Path(path).read_bytes()).digest()


def _digest(f: Path) -> bytes:
    st = f.stat()
    return _file_digest(str(f), st.st_mtime_ns, st.st_size)


IDENTIFIED = "identified"  # data/identified/: identified parameter sets (see the module doc)


def _fingerprint(modules: tuple, identified: tuple | None) -> str:
    from . import data

    h = hashlib.sha256(__version__.encode())
    files = [(f"gaitlib/{m}", _PKG / m) for m in sorted(set(CORE) | set(modules))]
    data_dir = Path(data.DATA_DIR)
    if data_dir.is_dir():
        for f in sorted(data_dir.rglob("*")):
            rel = f.relative_to(data_dir)
            if f.suffix not in (".csv", ".json") or f.name == "PROVENANCE.json":
                continue
            if rel.parts[0] == IDENTIFIED and identified is not None:
                continue  # only the named sets, below
            files.append((f"data/{rel.as_posix()}", f))
    for name, f in files:
        if not f.is_file():
            raise FileNotFoundError(f"cache.fingerprint: module {name} not found in the package")
        h.update(name.encode())
        h.update(_digest(f))
    for name in identified or ():
        f = data_dir / IDENTIFIED / f"{name}.json"
        h.update(f"data/{IDENTIFIED}/{name}.json".encode())
        h.update(_digest(f) if f.is_file() else b"<missing>")
    return h.hexdigest()[:16]


def fingerprint(modules=(), identified=None) -> str:
    """Version + hash of the :data:`CORE` sources, ``modules`` (package-relative paths or
    absolute files inside the package) and the data files (16 hex digits). ``identified``:
    names of the ``data/identified`` sets the solution reads (None: all of them)."""
    ident = None if identified is None else tuple(sorted(set(identified)))
    return _fingerprint(tuple(sorted(_module_path(m) for m in modules)), ident)


def key(spec: dict, modules=(), identified=None) -> str:
    """Cache key of a JSON-able spec under the current code (CORE + ``modules``) and data
    (``identified``: see :func:`fingerprint`)."""
    blob = json.dumps({"spec": spec, "code": fingerprint(modules, identified)}, sort_keys=True, default=str)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def store_dir() -> Path | None:
    """The read-only store of solutions shipped with the repository (``<repo>/solutions``,
    or ``$GAITLIB_STORE``; ``GAITLIB_STORE=""`` disables it), or None. Entries there carry
    the same keys, so a stale one is never hit; :func:`find` falls back to it."""
    env = os.environ.get("GAITLIB_STORE")
    if env is not None:
        return Path(env) if env else None
    repo = _PKG.parents[1] / "solutions"
    return repo if repo.is_dir() else None


def find(where: Path, marker: str) -> Path | None:
    """``where`` (a :func:`lookup` result) if it holds ``marker``; else the same entry in
    :func:`store_dir` if present there; else None."""
    where = Path(where)
    found = None
    if (where / marker).exists():
        found = where
    else:
        store = store_dir()
        if store is not None:
            cand = store / where.parent.name / where.name
            if (cand / marker).exists():
                found = cand
    if found is not None:
        _log_use(found)
    return found


def _log_use(path: Path) -> None:
    """tools/store_solutions.py: record which entries a build looked up or used
    (``$GAITLIB_CACHE_LOG``; entries solved during the build are logged at lookup)."""
    log = os.environ.get("GAITLIB_CACHE_LOG")
    if log:
        with open(log, "a") as f:
            f.write(f"{path}\n")


def default_dir() -> Path:
    return Path(os.environ.get("GAITLIB_SOLUTIONS", Path.home() / ".cache" / "gaitlib" / "solutions"))


def lookup(kind: str, spec: dict, root=None, modules=None, identified=None) -> Path:
    """Directory where a solution of ``spec`` is (or would be) stored.

    ``modules``: the sources (besides :data:`CORE`) the solution depends on; ``None`` — the
    calling module if it is part of gaitlib. ``identified``: the identified parameter sets
    the solution reads (None: all; see :func:`fingerprint`)."""
    if modules is None:
        caller = Path(inspect.stack()[1].filename).resolve()
        modules = (caller,) if _PKG in caller.parents else ()
    root = Path(root) if root is not None else default_dir()
    where = root / kind / key(spec, modules, identified)
    _log_use(where)
    return where


def clear(root=None) -> None:
    root = Path(root) if root is not None else default_dir()
    if root.exists():
        shutil.rmtree(root)
