"""Test configuration: the Makefile's BLAS settings (:func:`gaitlib.blas.pin`, before any test
module imports numpy) when pytest is run without ``make``, and ``benchmarks/`` on the import
path for the tests of the benchmarks' own modules (``moco.peers``, ``report``)."""

import sys
from pathlib import Path

from gaitlib import blas

blas.pin()

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"
if str(BENCHMARKS) not in sys.path:
    sys.path.insert(0, str(BENCHMARKS))
