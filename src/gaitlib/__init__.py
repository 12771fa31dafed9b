"""gaitlib — predictive simulation of child gait with direct collocation optimal control.

Layers, lowest first (each imports only its own or lower ones; ARCHITECTURE.md, checked by
tests/test_architecture.py): base (:mod:`gaitlib.conventions`) → data (:mod:`gaitlib.data`)
→ physics (:mod:`gaitlib.model`, :mod:`gaitlib.contact`, :mod:`gaitlib.mtg`,
:mod:`gaitlib.metabolics` …) → engine (:mod:`gaitlib.ocp`, :mod:`gaitlib.cache`,
:mod:`gaitlib.sweep`) → :mod:`gaitlib.effects` → :mod:`gaitlib.problems` → checks
(:mod:`gaitlib.validity`, :mod:`gaitlib.marks`, :mod:`gaitlib.plots`) → :mod:`gaitlib.gap`
→ :mod:`gaitlib.studies` → :mod:`gaitlib.cli` and the book's notebooks. Importing gaitlib
sets no environment variables: the BLAS settings solves run under are :mod:`gaitlib.blas`'s.
"""

__version__ = "0.1.0"
