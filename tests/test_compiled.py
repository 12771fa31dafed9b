"""Per-node functions compiled to C (``gaitlib.compiled``, ``SolverOptions(compiled=True)``)
compute the same numbers as CasADi's SX virtual machine, to the last bit, so IPOPT takes the
same path: the same iterations and the same solution."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from gaitlib import compiled, ocp
from gaitlib.collocation import Mesh
from gaitlib.ocp import Goal, Phase, Problem, SolverOptions, transcribe

pytestmark = pytest.mark.skipif(not compiled.available(), reason="no C compiler")


@pytest.fixture(autouse=True)
def _own_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("GAITLIB_COMPILED", str(tmp_path / "compiled"))


def _fun():
    x, y = ca.SX.sym("x", 3), ca.SX.sym("y", 2)
    e = ca.vertcat(ca.sin(x[0]) * ca.exp(x[1] * y[0]) + x[2] ** 3 / ca.cos(x[0]) - ca.sqrt(1 + y[1] ** 2),
                   ca.atan2(x[1], y[1]) * ca.tanh(x[2]))
    return ca.Function("probe", [x, y], [e, ca.jacobian(e, x)])


def test_compiled_values_are_the_virtual_machines_to_the_bit():
    f = _fun()
    g = compiled.compiled(f, reverse=True)
    assert g.name() == "probe" and g.sparsity_out(1) == f.sparsity_out(1)
    rng = np.random.default_rng(3)
    for _ in range(50):
        a, b = rng.normal(size=3), rng.normal(size=2)
        for u, v in zip(f(a, b), g(a, b)):
            assert np.array_equal(np.asarray(u), np.asarray(v))
    # mapped over nodes, and its reverse derivative (what nlpsol's set-up differentiates)
    A, B = rng.normal(size=(3, 7)), rng.normal(size=(2, 7))
    assert all(np.array_equal(np.asarray(u), np.asarray(v)) for u, v in zip(f.map(7)(A, B), g.map(7)(A, B)))
    X = ca.MX.sym("X", 3)
    grad = [ca.Function("gr", [X], [ca.gradient(ca.sum1(h(X, b)[0]), X)]) for h in (f, g)]
    assert np.array_equal(np.asarray(grad[0](a)), np.asarray(grad[1](a)))


def test_compiled_library_is_cached_by_content(tmp_path):
    f = _fun()
    compiled.compiled(f)
    libs = sorted(compiled.cache_dir().glob("*.so"))
    assert len(libs) == 1
    stamp = libs[0].stat().st_mtime_ns
    compiled.compiled(f)  # loaded, not compiled again
    assert sorted(compiled.cache_dir().glob("*.so")) == libs and libs[0].stat().st_mtime_ns == stamp
    x = ca.SX.sym("x", 3)
    compiled.compiled(ca.Function("probe", [x, ca.SX.sym("y", 2)], [ca.cos(x)]))  # same name, other function
    assert len(list(compiled.cache_dir().glob("*.so"))) == 2


def test_missing_compiler_is_named(monkeypatch):
    monkeypatch.setenv("CC", "no-such-cc")
    with pytest.raises(compiled.CompilerMissing, match="no-such-cc"):
        compiled.compiled(_fun())


def _swing_up() -> Problem:
    """A pendulum swung up by a bounded torque in fixed time: nonlinear dynamics, so the
    per-node Jacobians and Hessians are not constant."""
    ph = Phase(name="swing", states=("th", "om"), controls=("tau",),
               dynamics=lambda x, u, p, t: [x["om"], -9.81 * ca.sin(x["th"]) - 0.1 * x["om"] + u["tau"]],
               t0=0.0, tf=2.0, initial={"th": 0.0, "om": 0.0}, final={"th": np.pi, "om": 0.0},
               bounds={"tau": (-15.0, 15.0)},
               goals=(Goal("effort", 1.0, integrand=lambda x, u, p, t: u["tau"] ** 2 + 0.1 * ca.cos(x["th"]) ** 2),))
    return Problem(ph)


def test_compiled_nlp_takes_the_same_path():
    sols = [transcribe(_swing_up(), Mesh(10, "lgr", 4), SolverOptions(derivatives="nodes", compiled=c)).solve()
            for c in (False, True)]
    assert sols[0].success and sols[0].iterations > 5
    assert sols[1].iterations == sols[0].iterations
    assert sols[1].objective == sols[0].objective
    assert np.array_equal(sols[1].states.to_numpy(), sols[0].states.to_numpy())
    assert np.array_equal(sols[1].controls.to_numpy(), sols[0].controls.to_numpy())


def test_compiled_default_from_the_environment(monkeypatch):
    monkeypatch.delenv(ocp.COMPILE_ENV, raising=False)
    assert SolverOptions().compiled is False
    monkeypatch.setenv(ocp.COMPILE_ENV, "1")
    assert SolverOptions().compiled is True


def test_cli_flag_sets_the_environment(monkeypatch):
    from gaitlib import cli

    assert cli.COMPILE_ENV == ocp.COMPILE_ENV
    monkeypatch.delenv(ocp.COMPILE_ENV, raising=False)
    args = cli.build_parser().parse_args(["run", "gait", "--out", "x", "--derivatives", "nodes", "--compiled"])
    assert args.compiled is True
    assert cli.main(["run", "gait", "--out", "x", "--compiled"]) != 0  # needs --derivatives nodes
    assert ocp.COMPILE_ENV not in __import__("os").environ
