"""The BLAS settings gaitlib's solves run under: the Makefile's (see environment.md).

One BLAS/OpenMP thread per process, and OpenBLAS's Haswell (AVX2) kernel on every x86-64
machine. On 2 cores BLAS threading only added system time, and IPOPT then took a
timing-dependent path (the SK Eq 4.11 problem converged with one thread and stopped at the
iteration limit without the setting). The kernel decides the last bits of numpy's results,
and with them the cache keys of the stored solutions (environment.md).

``import gaitlib`` sets nothing. The entry points that solve call :func:`pin` first: the
command line (:func:`gaitlib.cli.main`), ``tools/*.py``, the benchmarks, and the test and
book configurations (``tests/conftest.py``, ``book/conftest.py``); the Makefile exports the
same variables and installs the notebook kernel with them. numpy's OpenBLAS reads the
variables when numpy is imported; casadi loads its own OpenBLAS (MUMPS's, inside IPOPT)
when the first IPOPT solver is created, so for IPOPT a later call still takes effect.
A variable already set in the environment is left as it is.
"""

from __future__ import annotations

import os
from collections.abc import MutableMapping

__all__ = ["SETTINGS", "pin"]

#: Environment variable → value, as the Makefile exports them.
SETTINGS = {
    "OPENBLAS_NUM_THREADS": "1",
    "OMP_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "OPENBLAS_CORETYPE": "Haswell",
}


def pin(environ: MutableMapping[str, str] | None = None) -> dict[str, str]:
    """Set every variable of :data:`SETTINGS` that ``environ`` (default ``os.environ``)
    does not have yet. Returns the variables this call set (name → value)."""
    env = os.environ if environ is None else environ
    new = {k: v for k, v in SETTINGS.items() if k not in env}
    env.update(new)
    return new
