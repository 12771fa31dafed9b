"""Cache keys name a formulation's version, not its source text (gaitlib.cache): these tests
catch a change to what is solved under an unchanged version.

Each probe builds one formulation on a small mesh exactly as its cached-solve path does,
intercepts the IPOPT solver at its first call and records the NLP there: the objective and
constraints at the initial guess, the guess, the bounds, the parameters and the solver
options. The numbers are summarised (count, sum, absolute sum and a position-weighted sum of
each vector) and compared, to a relative 1e-7, with ``tests/formulation_probes.json`` under
the formulation's current version string. A mismatch means the problem changed: bump the
version (``gaitlib.problems.gait.FORMULATION`` …) and record the probe anew with

    GAITLIB_RECORD_PROBES=1 python -m pytest tests/test_formulation_versions.py

then refresh the solution store (``python tools/store_solutions.py``). A refactor that keeps
the numbers keeps every key and the store.
"""

from __future__ import annotations

import json
import os
from dataclasses import replace
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from gaitlib import cache, ocp
from gaitlib import effects as effects_mod
from gaitlib.problems import gait as gait_ocp
from gaitlib.gap import solve as gsolve
from gaitlib.studies import contact_id as ci
from gaitlib.studies import jump

RECORD = Path(__file__).with_name("formulation_probes.json")
RTOL = 1e-7
#: IPOPT options left out of the probe: MUMPS's working space (gaitlib.ocp.MUMPS_MEM_PERCENT)
PATH_NEUTRAL = frozenset({"mumps_mem_percent"})


class _Intercepted(Exception):
    pass


class _FakeSolver:
    def __init__(self, rec):
        self.rec = rec

    def __call__(self, **kw):
        self.rec["args"] = kw
        raise _Intercepted


def _summary(v) -> list[float]:
    v = np.asarray(ca.DM(v) if not isinstance(v, (np.ndarray, float, int)) else v, float).ravel()
    v = np.where(np.isinf(v), np.sign(v) * 1e30, v)
    w = np.sin(np.arange(1, v.size + 1))
    return [float(v.size), float(v.sum()), float(np.abs(v).sum()), float(w @ v)]


def _probe(run, monkeypatch) -> dict:
    """Run ``run()`` with casadi.nlpsol intercepted; the first IPOPT call's NLP, summarised."""
    rec = {}

    def fake(name, solver, nlp, opts=None, *a, **k):
        rec.update(nlp=nlp, opts=opts or {}, solver=solver)
        return _FakeSolver(rec)

    monkeypatch.setattr(ca, "nlpsol", fake)
    monkeypatch.setenv(ocp.BUILD_REUSE_ENV, "0")  # a solver built earlier in the session would skip nlpsol
    with pytest.raises(_Intercepted):
        run()
    nlp, args = rec["nlp"], rec["args"]
    ins = [nlp["x"]] + ([nlp["p"]] if "p" in nlp else [])
    F = ca.Function("probe", ins, [nlp["f"], nlp.get("g", ca.DM())])
    x0 = np.asarray(ca.DM(args["x0"]), float).ravel()
    p = np.asarray(ca.DM(args.get("p", [])), float).ravel()
    f, g = F(x0, p) if "p" in nlp else F(x0)
    n_x = nlp["x"].numel()
    out = {"f": _summary(f), "g": _summary(g), "x0": _summary(x0), "p": _summary(p)}
    for b in ("lbx", "ubx", "lbg", "ubg"):
        val = args.get(b, 0.0)
        val = np.broadcast_to(np.asarray(ca.DM(val), float).ravel(), (n_x,) if b in ("lbx", "ubx")
                              else (nlp.get("g", ca.DM()).numel(),)) if np.size(val) == 1 else val
        out[b] = _summary(val)
    # the derivative functions are how the NLP is differentiated, not what is solved: that
    # they are the NLP's exact derivatives is test_node_derivatives.py's business
    opts = {k: v for k, v in rec["opts"].items() if k not in ("iteration_callback", "grad_f", "jac_g", "hess_lag")}
    # IPOPT options that change the time, not the path: test_solver_options.py shows the
    # same iterations and solution to the bit with each of their values
    opts["ipopt"] = {k: v for k, v in opts.get("ipopt", {}).items() if k not in PATH_NEUTRAL}
    out["options"] = json.dumps({"solver": rec["solver"], **opts}, sort_keys=True, default=str)
    return out


def _gait(spec):
    return lambda: gait_ocp.solve(spec)


def _gap(effects=()):
    from gaitlib import data

    spec = gait_ocp.GaitSpec(model="SK", cost="DT", n_intervals=3, degree=2, effects=tuple(effects))
    return lambda: gsolve.Runner(spec).solve(data.load_gait_data("Free"))


def _jump(name):
    sp = replace(jump.SPECS[name], n_intervals=3, continuation=())
    return lambda: jump.solve(sp)


def _trajopt():
    spec = ci.TrajOptSpec(n_time=8, n_trial=2, n_local=0)
    return lambda: ci.InverseDynamicsID(spec).local_solve(ci.neutral_start())


#: (formulation version, probe name, what is solved). Each formulation's versions are the
#: strings its cache keys use.
PROBES = [
    (gait_ocp.FORMULATION, "SK Eq4.11", _gait(gait_ocp.GaitSpec(model="SK", cost="Eq4.11", n_intervals=3, degree=2))),
    (gait_ocp.FORMULATION, "MSK DT", _gait(gait_ocp.GaitSpec(model="MSK", cost="DT", n_intervals=3, degree=2))),
    (gait_ocp.FORMULATION, "NMSK Eq5.55", _gait(gait_ocp.GaitSpec(model="NMSK", cost="Eq5.55", n_intervals=3, degree=2))),
    (gait_ocp.FORMULATION, "SK DT + effect", _gait(gait_ocp.GaitSpec(model="SK", cost="DT", n_intervals=3, degree=2,
                                                          effects=(("body_mass", None),)))),
    # the probe of the printed problem: the book's reading only sets GaitSpec fields
    (gait_ocp.FORMULATION, "contact (b)", _gait(ci.spec_b(3, 2, reading="thesis"))),
    (gsolve.FORMULATION, "SK fit", _gap()),
    # an effect with its own version (gaitlib.effects.formulation_versions): the Fit with it free. The probe
    # reads the NLP at its guess, s = 0, where versions 1 and 2 agree; the SD scaling itself is checked by
    # hand in tests/test_lab_effects.py
    (effects_mod.formulation_versions((("grf_scale", None),))[0], "SK fit + grf_scale", _gap((("grf_scale", None),))),
    (jump.FORMULATION, "toeless", _jump("toeless")),
    (jump.FORMULATION, "ellipsoid", _jump("ellipsoid")),
    (ci.TRAJOPT_FORMULATION, "trajopt", _trajopt()),
]


def _close(a, b) -> bool:
    if isinstance(a, str) or isinstance(b, str):
        return a == b
    a, b = np.asarray(a, float), np.asarray(b, float)
    return a.shape == b.shape and bool(np.all(np.abs(a - b) <= RTOL * np.maximum(1.0, np.abs(b))))


@pytest.mark.parametrize("version,name,run", PROBES, ids=[f"{v}:{n}" for v, n, _ in PROBES])
def test_formulation_is_what_its_version_says(version, name, run, monkeypatch):
    got = _probe(run, monkeypatch)
    records = json.loads(RECORD.read_text()) if RECORD.exists() else {}
    if os.environ.get("GAITLIB_RECORD_PROBES"):
        records.setdefault(version, {})[name] = got
        RECORD.write_text(json.dumps(records, indent=1, sort_keys=True) + "\n")
        return
    want = records.get(version, {}).get(name)
    assert want is not None, (f"no recorded probe for {version!r} / {name!r}: a new version? record it "
                              f"(GAITLIB_RECORD_PROBES=1, see the module docstring)")
    diff = [k for k in want if not _close(got.get(k), want[k])]
    assert not diff, (f"{name}: the NLP's {', '.join(diff)} changed under the unchanged version {version!r}. "
                      f"If the problem is meant to change, bump the version (cache keys, store refresh); "
                      f"if not, find why it changed. got {[got.get(k) for k in diff]}, recorded "
                      f"{[want[k] for k in diff]}")


def test_every_cached_formulation_has_a_probe():
    versions = {v for v, _, _ in PROBES}
    # contact (b)/(c) are gait problems with their own starts: probed as "contact (b)"
    assert {gait_ocp.FORMULATION, gsolve.FORMULATION, jump.FORMULATION, ci.TRAJOPT_FORMULATION} <= versions


def test_a_key_depends_on_the_formulation_version_not_the_source_text():
    spec = {"kind": "test", "x": 1}
    k = cache.key(spec, "gait-1", identified=())
    assert cache.key(spec, "gait-2", identified=()) != k
    assert cache.key(spec, ("gait-1", "gap-fit-1"), identified=()) != k
    assert cache.key(spec, "gait-1", identified=()) == k


def test_a_key_reads_no_source_file(monkeypatch):
    """A refactor or a docstring edit keeps every key: computing one reads no source file."""
    read = []
    real = Path.read_bytes

    def spy(self):
        read.append(self)
        return real(self)

    monkeypatch.setattr(Path, "read_bytes", spy)
    cache._file_digest.cache_clear()
    cache.key({"kind": "test"}, gait_ocp.FORMULATION, identified=("ch4_child",))
    assert read and not [f for f in read if f.suffix == ".py"], read
