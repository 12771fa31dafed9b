"""Where the model misses reality: the sim-to-real gap diagnosis.

``gaitlib.gap.EFFECTS``            the registry of candidate unmodelled effects (:mod:`gaitlib.effects`)
``gaitlib.gap.locate(sol, data)``  SD-standardised residual by channel and gait phase (:mod:`.locate`)
``gaitlib.gap.diagnose(data, …)``  re-solve with each effect, rank, shrink (:mod:`.diagnose`)
``gaitlib.gap.make_twin(…)``       synthetic data with a known effect (:mod:`.twin`)
``gaitlib.gap.validate_twins(…)``  the diagnosis scored on twins
``gaitlib.gap.read_data(csv)``     any tidy CSV as a data set (:mod:`.io`)
``gaitlib.gap.METHOD``             the diagnosis's settings, frozen, with a hash (:mod:`.method`)
``gaitlib.gap.validate_on_real()`` the diagnosis on real data manipulated by known amounts
                                   (:mod:`.validate`)

Shell: ``gaitlib gap --data CSV --out DIR``, ``gaitlib gap-twin --effect NAME
--magnitude X --seed N --out CSV`` and ``gaitlib gap-validate --out DIR``. Attributes load lazily (importing the package is cheap).
"""

from __future__ import annotations

import importlib
import sys
import types

_LAZY = {
    "EFFECTS": ("gaitlib.effects", "EFFECTS"), "TWIN_EFFECTS": ("gaitlib.effects", "TWIN_EFFECTS"),
    "Effect": ("gaitlib.effects", "Effect"),
    "locate": ("locate", "locate"), "Located": ("locate", "Located"),
    "diagnose": ("diagnose", "diagnose"), "Diagnosis": ("diagnose", "Diagnosis"),
    "make_twin": ("twin", "make_twin"), "write_twin": ("twin", "write_twin"),
    "validate_twins": ("twin", "validate_twins"), "read_data": ("io", "read_data"), "load_real": ("io", "load_real"),
    "METHOD": ("method", "METHOD"), "Method": ("method", "Method"), "validate_on_real": ("validate", "run"),
}

__all__ = list(_LAZY)


def __getattr__(name):
    if name in _LAZY:
        mod, attr = _LAZY[name]
        return getattr(importlib.import_module(mod if "." in mod else f".{mod}", __name__ if "." not in mod else None), attr)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class _CallableModule(types.ModuleType):
    """A submodule that is also its namesake function: importing ``gaitlib.gap.locate`` (or
    ``.diagnose``) makes Python bind the *module* to that package attribute, so without this
    ``gaitlib.gap.locate(sol, data)`` would raise "module object is not callable" once anything
    had imported the submodule."""

    def __call__(self, *args, **kwargs):
        return getattr(self, self.__name__.rsplit(".", 1)[1])(*args, **kwargs)


def _callable(name: str) -> None:
    sys.modules[f"{__name__}.{name}"].__class__ = _CallableModule
