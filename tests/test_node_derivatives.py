"""The NLP derivatives assembled from per-node functions (``SolverOptions(derivatives=
"nodes")``) are the exact derivatives of the NLP that IPOPT solves.

Every formulation the store holds is built on a small mesh as its cached-solve path builds
it (the probes of test_formulation_versions.py), the solver construction is intercepted, and
the gradient, constraint Jacobian and Lagrangian Hessian handed to IPOPT are compared with
CasADi's own differentiation of the same NLP (f and g), at a perturbed initial point with
random multipliers — and, independently of any automatic differentiation, the Jacobian with
central finite differences. The free-time, multi-phase jumps and the problems with static
parameters (contact identification) exercise the chain-rule terms that a fixed-time gait does
not.
"""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from gaitlib import ocp
from test_formulation_versions import PROBES, _Intercepted, _FakeSolver


def _intercept(run, monkeypatch) -> dict:
    rec = {}

    def fake(name, solver, nlp, opts=None, *a, **k):
        rec.update(nlp=nlp, opts=opts or {})
        return _FakeSolver(rec)

    monkeypatch.setattr(ca, "nlpsol", fake)
    monkeypatch.setenv(ocp.BUILD_REUSE_ENV, "0")  # a solver built earlier in the session would skip nlpsol
    with pytest.raises(_Intercepted):
        run()
    return rec


def _dense(v) -> np.ndarray:
    return np.asarray(ca.densify(ca.DM(v)), float)


def _rel(a, b) -> float:
    a, b = _dense(a), _dense(b)
    return float(np.max(np.abs(a - b), initial=0.0) / max(np.max(np.abs(b), initial=0.0), 1.0))


@pytest.mark.parametrize("version,name,run", PROBES, ids=[f"{v}:{n}" for v, n, _ in PROBES])
def test_node_derivatives_are_the_nlps_derivatives(version, name, run, monkeypatch):
    monkeypatch.setattr(ocp, "DEFAULT_DERIVATIVES", "nodes")
    assert ocp.SolverOptions().derivatives == "nodes"
    rec = _intercept(run, monkeypatch)
    nlp, opts, args = rec["nlp"], rec["opts"], rec["args"]
    if "hess_lag" not in opts:
        pytest.skip(f"{name}: not an IPOPT solve of a gaitlib transcription")
    x, p, f, g = nlp["x"], nlp["p"], nlp["f"], nlp["g"]
    rng = np.random.default_rng(7)
    lbx, ubx = (np.broadcast_to(np.asarray(ca.DM(args[b]), float).ravel(), (x.numel(),)) for b in ("lbx", "ubx"))
    x0 = np.clip(np.asarray(ca.DM(args["x0"]), float).ravel(), lbx, ubx)
    scale = np.where(np.isfinite(ubx - lbx), 0.02 * np.minimum(ubx - lbx, 1.0), 0.02)
    xr = np.clip(x0 + scale * rng.standard_normal(x0.size), lbx, ubx)
    pv = np.asarray(ca.DM(args.get("p", [])), float).ravel()
    lam = rng.standard_normal(g.numel())
    sigma = 0.7

    lf, lg = ca.MX.sym("lf"), ca.MX.sym("lg", g.numel())
    ref = ca.Function("ref", [x, p, lf, lg],
                      [f, ca.gradient(f, x), g, ca.jacobian(g, x), ca.triu(ca.hessian(lf * f + ca.dot(lg, g), x)[0])])
    f_r, gf_r, g_r, jg_r, h_r = ref(xr, pv, sigma, lam)
    f_n, gf_n = opts["grad_f"](xr, pv)
    g_n, jg_n = opts["jac_g"](xr, pv)
    h_n = opts["hess_lag"](xr, pv, sigma, lam)
    assert _rel(f_n, f_r) < 1e-12 and _rel(g_n, g_r) < 1e-12
    assert _rel(gf_n, gf_r) < 1e-10, f"{name}: gradient"
    assert _rel(jg_n, jg_r) < 1e-10, f"{name}: constraint Jacobian"
    assert _rel(h_n, h_r) < 1e-10, f"{name}: Hessian of the Lagrangian"
    # the pattern handed to IPOPT holds every non-zero of the exact Hessian's upper triangle
    hr = _dense(h_r)
    assert not np.any(hr[~(_dense(ca.DM(ca.DM.ones(h_n.sparsity()))) > 0)] != 0)

    # finite differences, independent of automatic differentiation: J·v for random directions
    gfun = ca.Function("g", [x, p], [g])
    jg = _dense(jg_n)
    for _ in range(3):
        v = rng.standard_normal(x0.size)
        h = 1e-6
        fd = (_dense(gfun(xr + h * v, pv)) - _dense(gfun(xr - h * v, pv))).ravel() / (2 * h)
        an = jg @ v
        assert np.max(np.abs(fd - an)) <= 1e-5 * max(1.0, np.max(np.abs(an))), f"{name}: J·v vs finite differences"


def test_graph_and_node_derivatives_give_the_same_functions():
    """The two derivative paths of one small problem with a free final time, a static
    parameter and per-node data: IPOPT's five functions agree to round-off."""
    import pandas as pd

    ph = ocp.Phase(
        name="move",
        states=("q", "v"), controls=("u",),
        dynamics=lambda x, u, p, t, d: ca.vertcat(x["v"], p["k"] * u["u"] - ca.sin(x["q"]) + d["a"]),
        t0=0.0, tf=(0.5, 3.0),
        bounds={"u": (-5, 5), "q": (-2, 2), "v": (-5, 5)},
        initial={"q": 0.0, "v": 0.0}, final={"q": 1.0, "v": 0.0},
        path_constraints=(ocp.PathConstraint("energy", lambda x, u, p, t: x["v"] ** 2 * x["q"], -10, 10),),
        goals=(ocp.Goal("effort", integrand=lambda x, u, p, t: u["u"] ** 2 * (1 + x["q"] ** 2)),
               ocp.Goal("time", endpoint=lambda x0, xf, p, t0, tf: tf, weight=0.1)),
        data=pd.DataFrame({"a": np.linspace(0.0, 0.2, 11)}, index=np.linspace(0, 1, 11)),
    )
    problem = ocp.Problem(name="toy", phases=(ph,), parameters=(ocp.Parameter("k", 0.5, 2.0),))
    from gaitlib.collocation import Mesh

    mesh = Mesh(n_intervals=4, degree=3)
    a = ocp.transcribe(problem, mesh, ocp.SolverOptions(derivatives="graph"))
    b = ocp.transcribe(problem, mesh, ocp.SolverOptions(derivatives="nodes"))
    rng = np.random.default_rng(3)
    w = a.initial_point() + 0.1 * rng.standard_normal(a.n_variables)
    pv = np.concatenate([a.data_vector(), a.goal_weights()])
    lam = rng.standard_normal(a.n_constraints)
    for fn, extra in (("nlp_f", []), ("nlp_g", []), ("nlp_grad_f", []), ("nlp_jac_g", []),
                      ("nlp_hess_l", [0.3, lam])):
        oa = a.solver.get_function(fn)(w, pv, *extra)
        ob = b.solver.get_function(fn)(w, pv, *extra)
        for u, v in zip(oa if isinstance(oa, (list, tuple)) else [oa], ob if isinstance(ob, (list, tuple)) else [ob]):
            assert _rel(v, u) < 1e-12, fn
    sa, sb = a.solve(), b.solve()
    assert sa.success and sb.success
    assert sb.objective == pytest.approx(sa.objective, rel=1e-6)
    assert sb.info["derivatives"] == "nodes" and sa.info["derivatives"] == "graph"


def test_the_spec_carries_the_derivative_path_and_keeps_every_existing_key():
    """``GaitSpec.derivatives``: unset, the spec (and every cache key) is what it was; set,
    it is part of the key and reaches the solver's options — in any process, since it
    travels with the spec."""
    from dataclasses import replace

    from gaitlib.problems import gait as gait_ocp

    spec = gait_ocp.GaitSpec(model="SK", cost="DT", n_intervals=3, degree=2)
    assert "derivatives" not in spec.to_dict()
    nodes = replace(spec, derivatives="nodes")
    assert nodes.to_dict()["derivatives"] == "nodes" and nodes.key() != spec.key()
    assert gait_ocp.GaitSpec.from_dict(nodes.to_dict()) == nodes
    assert gait_ocp.build(nodes).options.derivatives == "nodes"
    assert gait_ocp.build(spec).options.derivatives == ocp.DEFAULT_DERIVATIVES
    with pytest.raises(ValueError, match="derivatives"):
        gait_ocp.GaitSpec(model="SK", cost="DT", derivatives="symbolic")
