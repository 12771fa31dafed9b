"""Solution cache keyed by *what* was solved: the spec, the formulation's version and the data.

Keys
----
A key is the SHA-256 of

- the spec (any JSON-able mapping the caller builds: a problem spec, the data set's numbers,
  the warm start's identity …);
- the **formulation version(s)** the solution was computed with — a string such as
  ``"gait-1"`` that the module defining the formulation declares
  (:data:`gaitlib.problems.gait.FORMULATION`, :data:`gaitlib.gap.solve.FORMULATION`, …) and
  bumps whenever a change alters the problem that is solved (equations, bounds, initial
  guess, solver options). ``tests/test_formulation_versions.py`` evaluates every
  formulation's NLP on a small mesh and fails when the numbers change under an unchanged
  version, so a forgotten bump is caught before it could serve a stale solution;
- CasADi's version (IPOPT and its linear solvers come with it);
- the data *files* (CSV and JSON under ``data/``, not ``PROVENANCE.json``). Identified
  parameter sets (``data/identified/<name>.json``) are outputs of some studies and inputs of
  others: a caller that knows which sets its spec reads passes their names (``identified=``)
  and only those are hashed; ``identified=None`` hashes them all.

Source text is not hashed: a refactor, a docstring or another CPU's BLAS kernel keeps every
key, and a stored solution stays reachable until its formulation's version changes.

Entries
-------
An entry is a directory ``<root>/<kind>/<key>`` written by :func:`save`: the caller's files
are written into a private temporary directory next to it, a ``MANIFEST.json`` with the
SHA-256 of every file is added, and the directory is renamed into place in one step. Two
writers of one key never mix their files (each has its own temporary name; the second
finds the first's complete entry and drops its own). :func:`find` verifies the manifest
before an entry is served: a missing manifest, a missing, truncated or altered file makes
the entry *corrupt* — it is reported (a :class:`CacheWarning` naming its path), never
served, and the caller re-solves (and :func:`save` replaces it). ``gaitlib cache verify
[--remove]`` checks a whole cache.

Default location: ``$GAITLIB_SOLUTIONS`` or ``~/.cache/gaitlib/solutions``. Read-only
fallback: the solutions stored in the repository (:func:`store_dir`), so that the book
builds from a clean clone without re-solving; refresh them with ``tools/store_solutions.py``
after a formulation's version changes.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import uuid
import warnings
from functools import lru_cache
from pathlib import Path
from . import data

__all__ = ["fingerprint", "key", "default_dir", "store_dir", "find", "lookup", "save", "verify", "scan",
           "clear", "only", "solve_or_load", "MANIFEST", "CacheWarning", "CorruptEntry", "NotCached"]

_PKG = Path(__file__).resolve().parent

#: The checksum file of an entry.
MANIFEST = "MANIFEST.json"
_MANIFEST_FORMAT = "gaitlib.cache.entry/1"
IDENTIFIED = "identified"  # data/identified/: identified parameter sets (see the module doc)


class CacheWarning(UserWarning):
    """A cache entry was found corrupt or incomplete and was not served."""


class CorruptEntry(Exception):
    """Raised by :func:`verify`: the entry's files do not match its manifest."""


class NotCached(LookupError):
    """Raised by :func:`find` inside :func:`only` when a solution is neither cached nor
    stored: the caller would have to solve it."""


#: ``GAITLIB_CACHE_ONLY=1``: :func:`find` raises :class:`NotCached` instead of returning None
#: (set by :func:`only`; an environment variable, so sweep workers inherit it).
ONLY_ENV = "GAITLIB_CACHE_ONLY"


@contextlib.contextmanager
def only(reason: str = "solving is disabled (cached solutions only)"):
    """Within the block, a solution that is neither cached nor stored raises
    :class:`NotCached` (naming its path) where it would otherwise be solved: every cached
    solve of gaitlib looks its entry up with :func:`find` first. Worker processes started
    inside the block (dask LocalCluster, subprocesses) inherit it."""
    old = os.environ.get(ONLY_ENV)
    os.environ[ONLY_ENV] = reason or "1"
    try:
        yield
    finally:
        if old is None:
            os.environ.pop(ONLY_ENV, None)
        else:
            os.environ[ONLY_ENV] = old


@lru_cache(maxsize=4096)
def _file_digest(path: str, mtime_ns: int, size: int) -> str:
    """SHA-256 of a file's bytes (memoised on path, mtime and size: a rewritten file is
    re-read, so a set written during a session changes the keys at once)."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _digest(f: Path) -> str:
    st = f.stat()
    return _file_digest(str(f), st.st_mtime_ns, st.st_size)


def _solver_version() -> str:
    import casadi

    return f"casadi-{casadi.__version__}"


def _formulations(formulation) -> list[str]:
    if formulation is None:
        raise TypeError("cache: a formulation version is required (e.g. gaitlib.problems.gait.FORMULATION)")
    return [formulation] if isinstance(formulation, str) else list(formulation)


def _data_digest(identified: tuple | None) -> str:
    h = hashlib.sha256()
    data_dir = Path(data.DATA_DIR)
    files = []
    if data_dir.is_dir():
        for f in sorted(data_dir.rglob("*")):
            rel = f.relative_to(data_dir)
            if not f.is_file() or f.suffix not in (".csv", ".json") or f.name == "PROVENANCE.json":
                continue
            if rel.parts[0] == IDENTIFIED and identified is not None:
                continue  # only the named sets, below
            if rel.parts[0] == data.CONTEXT:
                continue  # curves no solve reads (data.CONTEXT_FILES)
            files.append((f"data/{rel.as_posix()}", f))
    for name, f in files:
        h.update(name.encode())
        h.update(_digest(f).encode())
    for name in identified or ():
        f = data_dir / IDENTIFIED / f"{name}.json"
        h.update(f"data/{IDENTIFIED}/{name}.json".encode())
        h.update(_digest(f).encode() if f.is_file() else b"<missing>")
    return h.hexdigest()[:16]


def fingerprint(formulation=(), identified=None) -> str:
    """The non-spec part of a key (16 hex digits): the formulation version(s), CasADi's
    version and the data files (``identified``: names of the ``data/identified`` sets the
    solution reads; None: all of them)."""
    ident = None if identified is None else tuple(sorted(set(identified)))
    forms = [] if formulation in ((), None) else _formulations(formulation)
    blob = json.dumps({"formulation": forms, "solver": _solver_version(), "data": _data_digest(ident)})
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def key(spec: dict, formulation, identified=None) -> str:
    """Cache key of a JSON-able spec solved with ``formulation`` (a version string or a
    sequence of them) on the current data (``identified``: see :func:`fingerprint`)."""
    blob = json.dumps({"spec": spec, "code": fingerprint(_formulations(formulation), identified)},
                      sort_keys=True, default=str)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def store_dir() -> Path | None:
    """The read-only store of solutions shipped with the repository (``<repo>/solutions``,
    or ``$GAITLIB_STORE``; ``GAITLIB_STORE=""`` disables it), or None. Entries there carry
    the same keys; :func:`find` falls back to it."""
    env = os.environ.get("GAITLIB_STORE")
    if env is not None:
        return Path(env) if env else None
    repo = _PKG.parents[1] / "solutions"
    return repo if repo.is_dir() else None


def _manifest_of(path: Path) -> dict:
    files = {}
    for f in sorted(path.rglob("*")):
        if f.is_file() and f.name != MANIFEST:
            files[f.relative_to(path).as_posix()] = {"sha256": hashlib.sha256(f.read_bytes()).hexdigest(),
                                                      "bytes": f.stat().st_size}
    return {"format": _MANIFEST_FORMAT, "files": files}


def write_manifest(path) -> Path:
    """Write ``MANIFEST.json`` (SHA-256 and size of every file) into an entry directory."""
    path = Path(path)
    (path / MANIFEST).write_text(json.dumps(_manifest_of(path), indent=1, sort_keys=True))
    return path / MANIFEST


def verify(path, marker: str | None = None) -> None:
    """Raise :class:`CorruptEntry` (with the path and the first fault) unless every file of
    the entry at ``path`` matches its manifest and no file was added (and ``marker``, when
    given, is one of them)."""
    path = Path(path)
    mf = path / MANIFEST
    if not mf.is_file():
        raise CorruptEntry(f"{path}: no {MANIFEST} (incomplete write, or written by an older gaitlib)")
    try:
        man = json.loads(mf.read_text())
        want = man["files"]
    except (ValueError, KeyError, TypeError) as e:
        raise CorruptEntry(f"{mf}: unreadable manifest ({e})") from None
    if marker is not None and marker not in want:
        raise CorruptEntry(f"{path}: {marker} is not part of the entry")
    have = {f.relative_to(path).as_posix() for f in path.rglob("*") if f.is_file() and f.name != MANIFEST}
    for name, meta in want.items():
        f = path / name
        if not f.is_file():
            raise CorruptEntry(f"{f}: missing")
        if f.stat().st_size != meta["bytes"]:
            raise CorruptEntry(f"{f}: {f.stat().st_size} bytes, the manifest says {meta['bytes']}")
        if hashlib.sha256(f.read_bytes()).hexdigest() != meta["sha256"]:
            raise CorruptEntry(f"{f}: checksum differs from the manifest")
    extra = sorted(have - set(want))
    if extra:
        raise CorruptEntry(f"{path}: files not in the manifest: {', '.join(extra[:3])}")


def _valid(path: Path, marker: str) -> bool:
    try:
        verify(path, marker)
        return True
    except CorruptEntry as e:
        warnings.warn(f"gaitlib cache: corrupt entry not served (the solution is recomputed): {e}", CacheWarning, stacklevel=3)
        return False


def find(where: Path, marker: str, *, to_solve: bool = True) -> Path | None:
    """``where`` (a :func:`lookup` result) if it holds a verified entry with ``marker``;
    else the same entry in :func:`store_dir` if present and verified there; else None.
    A corrupt entry is reported (:class:`CacheWarning`) and skipped, never served.
    ``to_solve``: the caller solves when nothing is found (inside :func:`only` a miss then
    raises :class:`NotCached`); False for a caller that only reads what is there."""
    where = Path(where)
    found = None
    if where.exists() and _valid(where, marker):
        found = where
    else:
        store = store_dir()
        if store is not None:
            cand = store / where.parent.name / where.name
            if cand.exists() and _valid(cand, marker):
                found = cand
    if found is not None:
        _log_use(found)
    elif to_solve and os.environ.get(ONLY_ENV):
        raise NotCached(f"{where}: not cached or stored ({os.environ[ONLY_ENV]})")
    return found


def solve_or_load(where, solve, load, *, marker: str, use_cache: bool = True, write=None):
    """The one cached-solve path: the entry at ``where`` (a :func:`lookup` directory) loaded
    by ``load(found)`` when :func:`find` serves it (verified; from the repository's store as
    a fallback), else ``solve()``'s result, stored there atomically by :func:`save` with
    ``write(result)`` as the writer (default ``result.save``). ``marker``: a file every
    complete entry of this kind has. ``use_cache=False`` solves and stores nothing.
    Failed solves are stored like any other: their status is the result."""
    found = find(where, marker) if use_cache else None
    if found is not None:
        return load(found)
    result = solve()
    if use_cache:
        save(where, (write or (lambda r: r.save))(result))
    return result


def save(where, write) -> Path:
    """Write an entry atomically: ``write(tmp)`` fills a private temporary directory next to
    ``where``; its manifest is added and it is renamed to ``where``. An existing entry there
    is replaced (a repaired or re-solved entry), unless another writer has just put a
    valid one in place, which is then kept. Returns ``where``."""
    where = Path(where)
    where.parent.mkdir(parents=True, exist_ok=True)
    tmp = where.parent / f".tmp-{where.name}-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    try:
        tmp.mkdir()
        write(tmp)
        write_manifest(tmp)
        try:
            os.rename(tmp, where)  # atomic when ``where`` does not exist
        except OSError:
            # ``where`` exists: move it aside and put ours in its place. Another writer of
            # the same key may move it first, or put its own entry there between the two
            # renames; then its (complete, verified-on-read) entry is kept and ours dropped.
            old = where.parent / f".old-{where.name}-{os.getpid()}-{uuid.uuid4().hex[:8]}"
            try:
                os.rename(where, old)
            except OSError:  # another writer moved it first
                old = None
            try:
                os.rename(tmp, where)
            except OSError:
                if not where.exists():  # not a race: a real failure
                    raise
            finally:
                if old is not None:
                    shutil.rmtree(old, ignore_errors=True)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    return where


def _log_use(path: Path) -> None:
    """tools/store_solutions.py: record which entries a build looked up or used
    (``$GAITLIB_CACHE_LOG``; entries solved during the build are logged at lookup)."""
    log = os.environ.get("GAITLIB_CACHE_LOG")
    if log:
        with open(log, "a") as f:
            f.write(f"{path}\n")


def default_dir() -> Path:
    return Path(os.environ.get("GAITLIB_SOLUTIONS", Path.home() / ".cache" / "gaitlib" / "solutions"))


def lookup(kind: str, spec: dict, root=None, *, formulation, identified=None) -> Path:
    """Directory where a solution of ``spec`` is (or would be) stored: ``<root>/<kind>/<key>``.

    ``formulation``: the version string(s) of the formulation(s) that produce it;
    ``identified``: the identified parameter sets the solution reads (None: all; see
    :func:`fingerprint`)."""
    root = Path(root) if root is not None else default_dir()
    where = root / kind / key(spec, formulation, identified)
    _log_use(where)
    return where


def scan(root=None) -> list[tuple[Path, str | None]]:
    """Every entry under ``root`` (default: :func:`default_dir`) with its fault (None: valid).
    Leftover temporary directories of interrupted writes are listed as faults too."""
    root = Path(root) if root is not None else default_dir()
    out = []
    if not root.is_dir():
        return out
    for kind in sorted(p for p in root.iterdir() if p.is_dir()):
        for e in sorted(p for p in kind.iterdir() if p.is_dir()):
            if e.name.startswith((".tmp-", ".old-")):
                out.append((e, "leftover of an interrupted write"))
                continue
            try:
                verify(e)
                out.append((e, None))
            except CorruptEntry as err:
                out.append((e, str(err)))
    return out


def clear(root=None) -> None:
    root = Path(root) if root is not None else default_dir()
    if root.exists():
        shutil.rmtree(root)
