"""gaitlib — predictive simulation of child gait with direct collocation optimal control.

Modules (one-way flow): :mod:`gaitlib.data` → :mod:`gaitlib.model` →
:mod:`gaitlib.contact` / :mod:`gaitlib.mtg` / :mod:`gaitlib.metabolics` →
:mod:`gaitlib.problems.gait` → :mod:`gaitlib.studies` → the book's notebooks.
Units, axes and sign conventions: :mod:`gaitlib.conventions`.
"""

import os as _os

# One BLAS thread for IPOPT's linear algebra (MUMPS on casadi's own OpenBLAS, loaded when
# the first solver is created, so this takes effect even after numpy is imported). On this
# 2-core machine more threads only added system time, and IPOPT then took a different,
# timing-dependent path: the same SK problem converged in 224 iterations with one thread
# and stopped at 1000 without. Set the variables yourself before importing gaitlib to
# override.
for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    _os.environ.setdefault(_v, "1")

__version__ = "0.1.0"
