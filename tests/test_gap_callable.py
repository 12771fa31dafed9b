"""``gaitlib.gap.locate`` / ``gaitlib.gap.diagnose`` are the functions the package documents,
also after their submodules were imported (which binds the module to the package name)."""

import importlib

import gaitlib.gap as gap


def test_callable_after_submodule_import():
    loc_mod = importlib.import_module("gaitlib.gap.locate")
    diag_mod = importlib.import_module("gaitlib.gap.diagnose")
    assert callable(gap.locate) and callable(gap.diagnose)
    # the module's own attributes are still reachable (studies use locate.Located)
    assert gap.locate.Located is loc_mod.Located
    assert gap.diagnose.Diagnosis is diag_mod.Diagnosis


def test_call_reaches_the_function(monkeypatch):
    loc_mod = importlib.import_module("gaitlib.gap.locate")
    seen = {}
    monkeypatch.setattr(loc_mod, "locate", lambda *a, **k: seen.setdefault("args", (a, k)))
    gap.locate(1, 2, exclude=("x",))
    assert seen["args"] == ((1, 2), {"exclude": ("x",)})
