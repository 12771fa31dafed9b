"""gaitlib — predictive simulation of child gait with direct collocation optimal control.

Modules (one-way flow): :mod:`gaitlib.data` → :mod:`gaitlib.model` →
:mod:`gaitlib.contact` / :mod:`gaitlib.mtg` / :mod:`gaitlib.metabolics` →
:mod:`gaitlib.problems.gait` → :mod:`gaitlib.studies` → the book's notebooks.
Units, axes and sign conventions: :mod:`gaitlib.conventions`. Importing gaitlib sets no
environment variables: the BLAS settings solves run under are :mod:`gaitlib.blas`'s.
"""

__version__ = "0.1.0"
