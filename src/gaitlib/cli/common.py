"""What every ``gaitlib`` subcommand shares: the error type and exit status, option types
checked at parse time, the cache option, and :class:`Output` (staged outputs moved into place
only when a command succeeds). Imports only the standard library, so ``gaitlib --help`` stays
fast and numpy is not loaded before :func:`gaitlib.blas.pin`."""

from __future__ import annotations

import argparse
import math
import os
import shutil
import tempfile
from pathlib import Path

#: Exit status of errors, refusals and results that rest on a solve that did not converge.
EXIT_FAILED = 2


class CLIError(Exception):
    """A user-facing error: printed as one line ``gaitlib <command>: <message>``, exit 2."""


# -- option types (checked at parse time, before anything is read or solved) ----------

def int_at_least(lo: int):
    """argparse type: an integer ≥ ``lo``."""

    def parse(text: str) -> int:
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer >= {lo}, got {text!r}") from None
        if v < lo:
            raise argparse.ArgumentTypeError(f"expected an integer >= {lo}, got {v}")
        return v

    parse.__name__ = f"integer >= {lo}"
    return parse


def finite_float(text: str) -> float:
    """argparse type: a finite number."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return v


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line (``gaitlib <command>: <message>``)."""

    def error(self, message):  # noqa: D102 — argparse's hook
        self.exit(EXIT_FAILED, f"{self.prog}: {message} (see {self.prog} --help)\n")


# -- outputs ------------------------------------------------------------------------

def check_cache(root, use_cache: bool) -> str | None:
    """The solutions cache folder (``root`` or :func:`gaitlib.cache.default_dir`), created
    and checked for writability when it will be written (``use_cache``); ``CLIError`` if
    it cannot be. Returns ``root`` as given (None: the default)."""
    if not use_cache:
        return root
    from .. import cache

    folder = Path(root) if root is not None else cache.default_dir()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=".write-test-", dir=folder)
        os.close(fd)
        os.unlink(probe)
    except OSError as e:
        raise CLIError(f"the solutions cache {folder} is not writable ({e.strerror or e}); "
                       "pass --cache DIR or --no-cache") from None
    return root


def _umask() -> int:
    m = os.umask(0)
    os.umask(m)
    return m


class Output:
    """A command's outputs, written to a fresh folder next to their destination and moved
    into place when the command succeeds (``with Output(...) as o: ... write into o.tmp``).

    Created (before any solve) it checks the destination: ``folder`` is refused if it exists
    and is not empty (``files=None``: the command writes the whole folder) or if any of
    ``files`` exists in it, unless ``overwrite``; the temporary folder is made next to it
    (which proves it writable). On success the entries of ``folder`` the command owns —
    those it writes now and ``owned`` (e.g. the files a previous run listed) — are removed
    and the new ones moved in, the names in ``last`` (the files that say "done", e.g.
    ``summary.json``) last; an absent or empty ``folder`` is replaced in one rename. On an
    exception nothing is moved and the temporary folder is removed."""

    def __init__(self, folder, *, overwrite: bool = False, owned=(), files=None, last=(), option: str = "--out",
                 what: str = "the files this command writes"):
        self.folder = Path(folder)
        self.owned, self.files, self.last = set(owned), None if files is None else tuple(files), tuple(last)
        f = self.folder
        if f.exists() and not f.is_dir():
            raise CLIError(f"{option} {f}: exists and is not a folder")
        if f.is_dir():
            clash = [n for n in self.files if (f / n).exists()] if self.files is not None else \
                sorted(p.name for p in f.iterdir())
            if clash and not overwrite:
                target = f / clash[0] if self.files is not None else f
                raise CLIError(f"{option} {target} exists{'' if self.files is not None else ' and is not empty'}: "
                               f"pass --overwrite to replace {what}, or choose another path")
            if not os.access(f, os.W_OK | os.X_OK):
                raise CLIError(f"{option} {f}: the folder is not writable")
        parent = f.absolute().parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
            self.tmp = Path(tempfile.mkdtemp(prefix=f".{f.name}.partial-", dir=parent))
        except OSError as e:
            if not f.is_dir():
                raise CLIError(f"{option} {f}: cannot write in {parent} ({e.strerror or e})") from None
            try:  # a writable folder in a read-only one: stage inside it
                self.tmp = Path(tempfile.mkdtemp(prefix=".partial-", dir=f))
            except OSError as e2:
                raise CLIError(f"{option} {f}: cannot write in it ({e2.strerror or e2})") from None
        os.chmod(self.tmp, 0o777 & ~_umask())

    def __enter__(self) -> "Output":
        return self

    def __exit__(self, exc_type, exc, tb):
        try:
            if exc_type is None:
                self._commit()
        finally:
            shutil.rmtree(self.tmp, ignore_errors=True)
        return False

    def _commit(self):
        f = self.folder
        new = sorted(p.name for p in self.tmp.iterdir())
        inside = self.tmp.parent == f
        if not inside and (not f.exists() or (self.files is None and not any(f.iterdir()))):
            os.replace(self.tmp, f)
            return
        f.mkdir(exist_ok=True)
        for name in sorted(set(new) | self.owned):
            old = f / name
            if old.is_dir() and not old.is_symlink():
                shutil.rmtree(old)
            elif old.exists() or old.is_symlink():
                old.unlink()
        for name in sorted(new, key=lambda n: (n in self.last, self.last.index(n) if n in self.last else 0)):
            os.replace(self.tmp / name, f / name)


def _add_output_options(p, cache: bool = True):
    p.add_argument("--overwrite", action="store_true",
                   help="replace the files this command owns in an existing --out (others are kept)")
    if cache:
        p.add_argument("--cache", default=None, help="solutions cache (default: $GAITLIB_SOLUTIONS or "
                                                     "~/.cache/gaitlib/solutions)")
        p.add_argument("--no-cache", action="store_true", help="solve even if cached solutions exist")


def _defects_option(p):
    p.add_argument("--defects", choices=("differential", "integral"), default=None,
                   help="the collocation defects' form: 'differential' (the default, as GPOPS-II) or 'integral' "
                        "(the same equations times the inverse of their end columns: another row scaling, "
                        "another IPOPT path; a separate cache entry)")


def _int_options(p, mesh, max_iter: int = 1000):
    p.add_argument("--intervals", type=int_at_least(1), default=mesh[0],
                   help=f"mesh intervals (default {mesh[0]}; thesis: 20)")
    p.add_argument("--degree", type=int_at_least(1), default=mesh[1],
                   help=f"collocation points per interval (default {mesh[1]}; thesis: 5)")
    p.add_argument("--max-iter", type=int_at_least(1), default=max_iter, help="IPOPT iteration limit")
    p.add_argument("--derivatives", choices=("graph", "nodes"), default=None,
                   help="how the NLP's exact derivatives are built: 'graph' (CasADi differentiates the whole "
                        "NLP; the default) or 'nodes' (per-node derivatives, built in seconds; a separate "
                        "cache entry, IPOPT may reach another local optimum)")
    p.add_argument("--compiled", action="store_true",
                   help="with --derivatives nodes: evaluate the per-node functions as compiled C (a C compiler; "
                        "compiled once per machine into $GAITLIB_COMPILED or ~/.cache/gaitlib/compiled). The same "
                        "numbers to the last bit, so the same solution and cache entry, in less time")
