"""CasADi functions compiled to C once and kept on disk (the per-node functions of an NLP).

:func:`compiled` takes an SX :class:`casadi.Function`, generates its C code
(``casadi.CodeGenerator``), compiles it with the system's C compiler into a shared library and
returns ``casadi.external`` of that library: a function with the same inputs, outputs and
sparsity that evaluates the same operations, in the same order, as CasADi's SX virtual
machine. It is compiled without ``-ffast-math`` or contraction to fused multiply-adds
(``-ffp-contract=off``), so each operation rounds as the virtual machine's does and the
values are the same to the last bit (``tests/test_compiled.py`` checks this, and that IPOPT's
iterates are identical).

Libraries are cached under ``$GAITLIB_COMPILED`` (default ``~/.cache/gaitlib/compiled``),
named by the SHA-256 of the function's serialisation, CasADi's version, the compiler's
version and its flags: a function is compiled once per machine and reused by every later
process. A library is written to a private temporary name and renamed into place, so
concurrent processes (dask workers) never load a half-written file.

No compiler (``cc`` not found): :func:`available` is False and :func:`compiled` raises
:class:`CompilerMissing`, naming the command it tried.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
import uuid
from functools import lru_cache
from pathlib import Path

import casadi as ca

__all__ = ["compiled", "available", "cache_dir", "FLAGS", "CompilerMissing"]

#: The C compiler's flags: optimised, position-independent, IEEE arithmetic as written
#: (no fast-math, no fused multiply-add contraction), so results equal the SX VM's.
FLAGS = ("-O1", "-fPIC", "-shared", "-ffp-contract=off", "-fno-fast-math")


class CompilerMissing(RuntimeError):
    """No C compiler was found (``$CC`` or ``cc``)."""


def _compiler() -> str:
    return os.environ.get("CC", "cc")


@lru_cache(maxsize=None)
def _compiler_version(cc: str) -> str | None:
    exe = shutil.which(cc)
    if exe is None:
        return None
    try:
        out = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.SubprocessError):
        return None
    return (out.stdout or out.stderr).splitlines()[0] if out.returncode == 0 else None


def available() -> bool:
    """Whether a C compiler is there to use."""
    return _compiler_version(_compiler()) is not None


def cache_dir() -> Path:
    return Path(os.environ.get("GAITLIB_COMPILED", Path.home() / ".cache" / "gaitlib" / "compiled"))


def _key(fun: ca.Function, cc_version: str, reverse: bool) -> str:
    h = hashlib.sha256()
    for part in (fun.serialize(), ca.__version__, cc_version, " ".join(FLAGS), f"reverse={reverse}"):
        h.update(part.encode())
        h.update(b"\0")
    return h.hexdigest()[:24]


def compiled(fun: ca.Function, reverse: bool = False) -> ca.Function:
    """``fun`` (an SX Function) evaluated by compiled C: loaded from the cache, or generated
    and compiled now (seconds to a minute, once per machine). The returned function has
    ``fun``'s name, inputs, outputs and sparsity patterns. ``reverse``: the library also
    holds ``fun``'s first-order reverse derivative (CasADi's ``adj1_<name>``), so the
    compiled function can be differentiated once in reverse mode (a gradient); without it
    it cannot be differentiated at all."""
    cc = _compiler()
    version = _compiler_version(cc)
    if version is None:
        raise CompilerMissing(f"gaitlib.compiled: no C compiler found (tried {cc!r}; set $CC)")
    name = fun.name()
    key = _key(fun, version, reverse)
    lib = cache_dir() / f"{name}-{key}.so"
    if not lib.is_file():
        lib.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(prefix="gaitlib-cc-") as tmp:
            gen = ca.CodeGenerator(f"{name}.c", {"with_header": False})
            gen.add(fun)
            if reverse:
                gen.add(fun.reverse(1))
            gen.generate(f"{tmp}/")
            part = lib.parent / f".tmp-{lib.name}-{os.getpid()}-{uuid.uuid4().hex[:8]}"
            cmd = [shutil.which(cc), *FLAGS, str(Path(tmp) / f"{name}.c"), "-o", str(part), "-lm"]
            out = subprocess.run(cmd, capture_output=True, text=True)
            if out.returncode != 0:
                part.unlink(missing_ok=True)
                raise RuntimeError(f"gaitlib.compiled: {' '.join(cmd)} failed:\n{out.stderr[-2000:]}")
            os.replace(part, lib)
    return ca.external(name, str(lib))
