"""Tests of the generic direct-collocation layer (gaitlib.collocation, gaitlib.ocp).

Analytic optima, convergence orders fitted from mesh refinement, multi-phase linkage,
parameter identification, visible failures and save/load. All solves are tiny (< 1 s).
"""

from __future__ import annotations

import math
import warnings

import casadi as ca
import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

from gaitlib.collocation import Mesh, differentiation_matrix, integral_form, lgr_points, lgr_scheme, lgr_weights
from gaitlib.ocp import (
    EndpointConstraint,
    Goal,
    Guess,
    Linkage,
    Parameter,
    PathConstraint,
    Periodic,
    Phase,
    PhaseGuess,
    Problem,
    Solution,
    SolveFailedError,
    SolveFailedWarning,
    SolverOptions,
    solve,
    transcribe,
)

TIGHT = SolverOptions(tol=1e-12, constr_viol_tol=1e-12)
ALL_MESHES = [
    Mesh(10, "lgr", 3),
    Mesh(10, "lgr", 3, lgr_side="right"),
    Mesh(10, "hermite-simpson"),
    Mesh(10, "hermite-simpson", hs_control_midpoints="free"),
    Mesh(10, "trapezoidal"),
]


# ======================================================================================
# Schemes
# ======================================================================================
@pytest.mark.parametrize("side", ["left", "right"])
@pytest.mark.parametrize("d", [1, 2, 3, 4, 5, 7])
def test_lgr_quadrature_exact_to_degree_2d_minus_2(d, side):
    sch = lgr_scheme(d, side)
    tc = sch.nodes[sch.colloc]
    for k in range(2 * d - 1):
        assert sch.weights @ tc**k == pytest.approx(1.0 / (k + 1), abs=1e-13)
    # ... and not beyond: degree 2d − 1 is not integrated exactly.
    assert abs(sch.weights @ tc ** (2 * d - 1) - 1.0 / (2 * d)) > 1e-10


@pytest.mark.parametrize("side", ["left", "right"])
@pytest.mark.parametrize("d", [1, 2, 3, 4, 5, 7])
def test_lgr_differentiation_exact_to_degree_d(d, side):
    sch = lgr_scheme(d, side)
    tc = sch.nodes[sch.colloc]
    assert sch.A.shape == (d, d + 1)
    for k in range(d + 1):
        exact = k * tc ** (k - 1) if k else np.zeros(d)
        np.testing.assert_allclose(sch.A @ sch.nodes**k, exact, atol=1e-11)
    # A random polynomial of degree d, too.
    c = np.random.default_rng(d).normal(size=d + 1)
    p = np.polynomial.Polynomial(c)
    np.testing.assert_allclose(sch.A @ p(sch.nodes), p.deriv()(tc), atol=1e-11)


def test_lgr_points_match_casadi_and_gpops_convention():
    np.testing.assert_allclose(lgr_points(5, "right"), ca.collocation_points(5, "radau"))
    left = lgr_points(5, "left")
    assert left[0] == 0.0 and left[-1] < 1.0  # GPOPS-II: includes the start, not the end
    assert lgr_weights(5, "left")[0] == pytest.approx(0.5 * 2 / 25)
    D = differentiation_matrix(np.array([0.0, 0.3, 1.0]))
    np.testing.assert_allclose(D @ np.array([0.0, 0.09, 1.0]), [0.0, 0.6, 2.0], atol=1e-14)


@pytest.mark.parametrize("mesh", ALL_MESHES + [Mesh(4, "lgr", 4, fractions=(1, 2, 3, 4))],
                         ids=lambda m: m.describe())
def test_mesh_grids_and_quadrature(mesh):
    assert mesh.tau[0] == 0.0 and mesh.tau[-1] == 1.0 and np.all(np.diff(mesh.tau) > 0)
    assert mesh.quadrature_weights.sum() == pytest.approx(1.0, abs=1e-13)
    # Exact for a cubic on every scheme except trapezoidal (linear).
    deg = 1 if mesh.scheme == "trapezoidal" else 3
    tc = mesh.tau_colloc
    for k in range(deg + 1):
        assert mesh.quadrature_weights @ tc**k == pytest.approx(1 / (k + 1), abs=1e-13)
    A, B = mesh.defect_matrices
    assert A.shape[1] == mesh.n_state_nodes and B.shape[1] == mesh.n_colloc_nodes


def test_thesis_mesh_size():
    mesh = Mesh(20, "lgr", 5)
    assert (mesh.n_state_nodes, mesh.n_colloc_nodes) == (101, 100)
    assert Mesh(20, "lgr", 5, lgr_side="right").tau_colloc[-1] == 1.0


# ======================================================================================
# Double integrator: analytic optimum u = 6 − 12 t, J = 12
# ======================================================================================
def double_integrator(**kw) -> Phase:
    spec = dict(
        name="move",
        states=("x", "v"),
        controls=("u",),
        dynamics=lambda x, u, p, t: [x["v"], u["u"]],
        t0=0.0,
        tf=1.0,
        initial={"x": 0.0, "v": 0.0},
        final={"x": 1.0, "v": 0.0},
        goals=(Goal("effort", 1.0, integrand=lambda x, u, p, t: u["u"] ** 2),),
    )
    spec.update(kw)
    return Phase(**spec)


@pytest.mark.parametrize("graph", ["sx", "mx"])
@pytest.mark.parametrize("mesh", ALL_MESHES[:4], ids=lambda m: m.describe())
def test_double_integrator_exact_schemes(mesh, graph):
    sol = solve(Problem(double_integrator()), mesh, SolverOptions(graph=graph))
    assert sol.success and sol.status == "Solve_Succeeded"
    assert sol.objective == pytest.approx(12.0, abs=1e-8)
    assert sol.cost("effort") == pytest.approx(12.0, abs=1e-8)
    u = sol.controls["u"]
    np.testing.assert_allclose(u.to_numpy(), 6 - 12 * u.index.to_numpy(), atol=1e-7)
    x = sol.states["x"]
    t = x.index.to_numpy()
    np.testing.assert_allclose(x.to_numpy(), 3 * t**2 - 2 * t**3, atol=1e-8)
    assert sol.max_violation < 1e-8


def test_goal_weights_are_parameters_of_one_nlp():
    ph = double_integrator(goals=(
        Goal("effort", 1.0, integrand=lambda x, u, p, t: u["u"] ** 2),
        Goal("speed", 0.0, integrand=lambda x, u, p, t: x["v"] ** 2),
    ))
    tr = transcribe(Problem(ph), Mesh(8, "lgr", 4))
    base = tr.solve().require_success()
    assert base.objective == pytest.approx(12.0, abs=1e-8)
    heavy = tr.solve(weights={"speed": 10.0}).require_success()
    assert heavy.goals.set_index("goal").loc["speed", "weight"] == 10.0
    # More weight on speed → lower ∫v², more effort.
    assert heavy.cost("speed") / 10.0 < base.goals.set_index("goal").loc["speed", "value"]
    assert heavy.cost("effort") > 12.0
    assert heavy.objective == pytest.approx(heavy.goals["weighted"].sum(), rel=1e-12)
    with pytest.raises(KeyError, match="unknown goal"):
        tr.solve(weights={"Speed": 1.0})


def test_double_integrator_trapezoidal_second_order():
    errs = []
    for n in (10, 20, 40, 80):
        sol = solve(Problem(double_integrator()), Mesh(n, "trapezoidal"))
        assert sol.success
        errs.append(sol.objective - 12.0)
    slope = np.polyfit(np.log([10, 20, 40, 80]), np.log(errs), 1)[0]
    assert slope == pytest.approx(-2.0, abs=0.1)
    assert errs[-1] < 0.01


# ======================================================================================
# Convergence orders: min ∫ x² + u² dt, ẋ = u, x(0) = 1, x(1) free
# x* = cosh(1 − t)/cosh 1, u* = −sinh(1 − t)/cosh 1, J* = tanh 1
# ======================================================================================
def exponential_problem() -> Problem:
    ph = Phase(
        "p", states=("x",), controls=("u",), dynamics=lambda x, u, p, t: u["u"],
        initial={"x": 1.0},
        goals=(Goal("J", integrand=lambda x, u, p, t: x["x"] ** 2 + u["u"] ** 2),),
    )
    return Problem(ph)


def errors(mesh):
    sol = solve(exponential_problem(), mesh, TIGHT).require_success()
    x = sol.states["x"]
    t = x.index.to_numpy()
    err_x = np.abs(x.to_numpy() - np.cosh(1 - t) / np.cosh(1)).max()
    return abs(sol.objective - math.tanh(1.0)), err_x


def fitted_orders(meshes):
    n = np.array([m.n_intervals for m in meshes], dtype=float)
    e = np.array([errors(m) for m in meshes])
    return [-np.polyfit(np.log(n), np.log(e[:, k]), 1)[0] for k in range(2)]


@pytest.mark.parametrize(
    "scheme, kw, ns, order_J, order_x",
    [
        ("trapezoidal", {}, (4, 8, 16, 32), 2, 2),
        ("hermite-simpson", {}, (2, 4, 8, 16), 4, 4),
        ("hermite-simpson", {"hs_control_midpoints": "free"}, (2, 4, 8, 16), 4, 4),
        ("lgr", {"degree": 2}, (2, 4, 8, 16), 3, 3),  # objective 2d − 1, state d + 1
        ("lgr", {"degree": 3}, (1, 2, 4, 8), 5, 4),
        ("lgr", {"degree": 3, "lgr_side": "right"}, (1, 2, 4, 8), 5, 4),
    ],
)
def test_convergence_order(scheme, kw, ns, order_J, order_x):
    oJ, ox = fitted_orders([Mesh(n, scheme, **kw) for n in ns])
    assert oJ == pytest.approx(order_J, abs=0.3)
    assert ox == pytest.approx(order_x, abs=0.3)


def test_lgr_p_convergence_is_geometric():
    errs = [errors(Mesh(2, "lgr", d))[0] for d in (2, 3, 4, 5)]
    ratios = np.array(errs[:-1]) / np.array(errs[1:])
    assert np.all(ratios > 100), ratios  # each extra point gains > 2 digits
    assert errs[-1] < 1e-11


# ======================================================================================
# Phases, linkage, periodicity, endpoint and path constraints
# ======================================================================================
def test_two_phase_linkage_reproduces_single_phase():
    a = double_integrator(name="a", tf=0.5, final={})
    b = double_integrator(name="b", t0=(0.0, 1.0), tf=1.0, initial={})
    pr = Problem((a, b), linkages=(Linkage("a", "b"),))
    sol = solve(pr, Mesh(4, "lgr", 3)).require_success()
    assert sol.objective == pytest.approx(12.0, abs=1e-8)
    assert sol.phases["b"].t0 == pytest.approx(0.5, abs=1e-9)
    assert set(sol.goals["phase"]) == {"a", "b"}
    for name in ("a", "b"):
        u = sol.phases[name].controls["u"]
        np.testing.assert_allclose(u.to_numpy(), 6 - 12 * u.index.to_numpy(), atol=1e-7)
    # The two single-phase halves carry the analytic split of the cost: ∫(6 − 12t)² on [0, ½].
    assert sol.goals.set_index("phase").loc["a", "value"] == pytest.approx(6.0, abs=1e-8)


def test_periodic_offset_path_and_endpoint_constraints():
    # x advances by 2 per unit time with v periodic: optimum u = 0, v = 2, J = 0 plus the
    # endpoint goal; a path constraint v ≤ 2.5 stays inactive; an endpoint constraint
    # fixes v(0) = 2 redundantly.
    ph = double_integrator(
        initial={"x": 0.0}, final={},
        periodic=Periodic(("x", "v"), {"x": lambda p, t0, tf: 2.0 * (tf - t0)}),
        path_constraints=(PathConstraint("vmax", lambda x, u, p, t: x["v"], -np.inf, 2.5),),
        endpoint_constraints=(EndpointConstraint("v0", lambda x0, xf, p, t0, tf: x0["v"], 2.0, 2.0),),
        goals=(
            Goal("effort", 1.0, integrand=lambda x, u, p, t: u["u"] ** 2),
            Goal("end", 0.5, endpoint=lambda x0, xf, p, t0, tf: xf["x"]),
        ),
    )
    sol = solve(Problem(ph), Mesh(5, "hermite-simpson")).require_success()
    assert sol.states["x"].iloc[-1] == pytest.approx(2.0, abs=1e-8)
    np.testing.assert_allclose(sol.states["v"], 2.0, atol=1e-8)
    assert sol.cost("end") == pytest.approx(1.0, abs=1e-8)
    assert sol.cost("effort") == pytest.approx(0.0, abs=1e-10)


def test_free_final_time_minimum_time():
    # Minimum time to move 1 with |u| ≤ 1 from rest to rest: tf = 2 (bang-bang).
    ph = double_integrator(
        tf=(0.5, 5.0), bounds={"u": (-1.0, 1.0)},
        goals=(Goal("time", endpoint=lambda x0, xf, p, t0, tf: tf),),
    )
    sol = solve(Problem(ph), Mesh(20, "trapezoidal")).require_success()
    assert sol.phase().tf == pytest.approx(2.0, rel=2e-2)
    assert sol.states.index[-1] == pytest.approx(sol.phase().tf)


def test_per_node_bounds_and_unknown_names():
    mesh = Mesh(4, "trapezoidal")
    upper = np.full(mesh.n_colloc_nodes, 10.0)
    upper[0] = 1.0  # u(0) ≤ 1 only at the first node
    sol = solve(Problem(double_integrator(bounds={"u": (-np.inf, upper)})), mesh)
    assert sol.controls["u"].iloc[0] <= 1.0 + 1e-8
    with pytest.raises(ValueError, match="one value per node"):
        solve(Problem(double_integrator(bounds={"u": (0.0, np.ones(3))})), mesh)
    with pytest.raises(KeyError, match="unknown name 'uu'"):
        double_integrator(bounds={"uu": (0, 1)})
    with pytest.raises(KeyError, match="unknown state 'vv'"):
        double_integrator(initial={"vv": 0})
    bad = double_integrator(goals=(Goal("g", integrand=lambda x, u, p, t: x["vel"] ** 2),))
    with pytest.raises(KeyError, match="unknown state 'vel'.*known: x, v"):
        transcribe(Problem(bad), mesh)
    with pytest.raises(ValueError, match="exactly one"):
        Goal("g")


# ======================================================================================
# Static parameters and per-node data: identify a damping coefficient
# ======================================================================================
K, C_TRUE, T_END = 4.0, 0.7, 3.0


def oscillator_data() -> pd.DataFrame:
    t = np.linspace(0.0, T_END, 301)
    sim = solve_ivp(lambda t, y: [y[1], -K * y[0] - C_TRUE * y[1]], (0, T_END), [1.0, 0.0],
                    t_eval=t, rtol=1e-12, atol=1e-12)
    return pd.DataFrame({"x_meas": sim.y[0]}, index=pd.Index(t / T_END, name="tau"))


def identification_problem(data=None) -> Problem:
    ph = Phase(
        "osc", states=("x", "v"), controls=(),
        dynamics=lambda x, u, p, t: [x["v"], -K * x["x"] - p["c"] * x["v"]],
        tf=T_END, initial={"x": 1.0, "v": 0.0},
        data=oscillator_data() if data is None else data,
        goals=(Goal("track", integrand=lambda x, u, p, t, d: (x["x"] - d["x_meas"]) ** 2),),
    )
    return Problem(ph, parameters=(Parameter("c", 0.0, 5.0, guess=0.1),))


def test_parameter_identification_recovers_damping():
    tr = transcribe(identification_problem(), Mesh(15, "lgr", 4))
    sol = tr.solve().require_success()
    assert sol.parameters["c"] == pytest.approx(C_TRUE, abs=1e-4)
    assert sol.objective < 1e-8
    # The same NLP re-solved with other data (no rebuild) finds the other damping.
    other = oscillator_data() * 0.0 + np.exp(-np.linspace(0, T_END, 301))[:, None]
    sol2 = tr.solve(data={"osc": other})
    assert sol2.success and sol2.parameters["c"] != pytest.approx(C_TRUE, abs=1e-2)
    # Warm start from the solution on another mesh: fewer iterations than cold.
    warm = solve(identification_problem(), Mesh(20, "hermite-simpson"), guess=sol)
    cold = solve(identification_problem(), Mesh(20, "hermite-simpson"))
    assert warm.success and cold.success
    assert warm.iterations < cold.iterations
    assert warm.parameters["c"] == pytest.approx(C_TRUE, abs=1e-4)


def test_guess_from_arrays_is_interpolated_to_the_mesh():
    mesh = Mesh(3, "lgr", 3)
    tr = transcribe(Problem(double_integrator(initial={}, final={})), mesh)
    t = np.linspace(0, 1, 11)
    w0 = tr.initial_point(Guess({"move": PhaseGuess(time=t, states={"x": t**2},
                                                   controls={"u": 1 - t})}))
    lay = tr.layouts["move"]
    np.testing.assert_allclose(w0[lay.ix[0]], np.interp(mesh.tau, t, t**2))
    np.testing.assert_allclose(w0[lay.iu[0]], 1 - mesh.tau_colloc)
    with pytest.raises(KeyError, match="unknown state"):
        tr.initial_point(Guess({"move": PhaseGuess(time=t, states={"y": t})}))


# ======================================================================================
# Failures are visible; save/load
# ======================================================================================
def test_max_iter_failure_is_reported():
    with pytest.warns(SolveFailedWarning, match="Maximum_Iterations_Exceeded"):
        sol = solve(identification_problem(), Mesh(10, "lgr", 3), SolverOptions(max_iter=2))
    assert not sol.success
    assert sol.status == "Maximum_Iterations_Exceeded"
    assert sol.iterations == 2
    with pytest.raises(SolveFailedError, match="Maximum_Iterations_Exceeded"):
        sol.require_success()
    assert "FAILED" in repr(sol)


def test_infeasible_problem_is_reported():
    with pytest.raises(ValueError, match="conflicting bounds.*'x' at node 4"):
        transcribe(Problem(double_integrator(bounds={"x": (-1.0, 0.5)})), Mesh(4, "trapezoidal"))
    ph = double_integrator(  # x ≤ 0.5 on the path, but x(1) = 1
        path_constraints=(PathConstraint("xmax", lambda x, u, p, t: x["x"], -np.inf, 0.5),))
    with pytest.warns(SolveFailedWarning):
        sol = solve(Problem(ph), Mesh(4, "trapezoidal"))
    assert not sol.success
    assert sol.status == "Infeasible_Problem_Detected"
    assert sol.max_violation > 0.1
    with pytest.raises(SolveFailedError, match="Infeasible_Problem_Detected"):
        sol.require_success()


def test_save_load_round_trip(tmp_path):
    sol = solve(identification_problem(), Mesh(5, "lgr", 3))
    sol2 = solve(Problem(double_integrator()), Mesh(3, "hermite-simpson"))
    for s, name in ((sol, "ident"), (sol2, "di")):
        loaded = Solution.load(s.save(tmp_path / name))
        for ph in s.phases:
            pd.testing.assert_frame_equal(loaded.phases[ph].states, s.phases[ph].states,
                                          check_exact=True)
            pd.testing.assert_frame_equal(loaded.phases[ph].controls, s.phases[ph].controls,
                                          check_exact=True, check_column_type=False,
                                          check_index_type=False)
            assert loaded.phases[ph].tf == s.phases[ph].tf
        pd.testing.assert_frame_equal(loaded.goals, s.goals, check_exact=True)
        for attr in ("parameters", "objective", "status", "success", "iterations",
                     "solve_time", "build_time", "max_violation", "worst_constraint"):
            assert getattr(loaded, attr) == getattr(s, attr), attr
    # A failed solution stays failed after a round trip.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SolveFailedWarning)
        bad = solve(identification_problem(), Mesh(5, "lgr", 3), SolverOptions(max_iter=1))
        loaded = Solution.load(bad.save(tmp_path / "bad"))
    assert not loaded.success and loaded.status == "Maximum_Iterations_Exceeded"
    with pytest.raises(SolveFailedError):
        loaded.require_success()


def test_interpolate_and_stats():
    sol = solve(Problem(double_integrator()), Mesh(10, "lgr", 3)).require_success()
    frame = sol.interpolate([0.25, 0.5])
    np.testing.assert_allclose(frame["x"], [3 * 0.25**2 - 2 * 0.25**3, 0.5], atol=1e-3)
    assert list(frame.columns) == ["x", "v", "u"]
    assert sol.iterations >= 1 and sol.solve_time > 0 and sol.build_time > 0
    assert sol.time_per_iteration == pytest.approx(sol.solve_time / sol.iterations)
    assert sol.info["n_variables"] == 2 * 31 + 30


# ======================================================================================
# Defects in integral form: the same equations, x_j − x_0 = ∫ f over [τ_0, τ_j]
# ======================================================================================
@pytest.mark.parametrize("scheme,kw", [("lgr", dict(degree=3)), ("lgr", dict(degree=5)),
                                       ("lgr", dict(degree=4, lgr_side="right")), ("trapezoidal", {}),
                                       ("hermite-simpson", {})])
def test_integral_form_integrates_the_interpolant_exactly(scheme, kw):
    """Row j of the integral form is x(τ_j) − x(0) − Σ_l M_jl x'(τ_l): zero for every state
    polynomial the scheme represents exactly (LGR d points: degree ≤ d; trapezoidal: 1;
    Hermite–Simpson: 3), checked against the polynomial's own values."""
    sch = Mesh(1, scheme, **kw).interval
    Ai, M = integral_form(sch)
    n = sch.m
    assert np.array_equal(Ai, np.hstack([-np.ones((n, 1)), np.eye(n)]))
    np.testing.assert_allclose(np.linalg.solve(sch.A[:, 1:], sch.A), Ai, atol=1e-12)
    deg = {"lgr": kw.get("degree", 5), "trapezoidal": 1, "hermite-simpson": 3}[scheme]
    rng = np.random.default_rng(deg)
    for _ in range(3):
        p = np.polynomial.Polynomial(rng.normal(size=deg + 1))
        x, dx = p(sch.nodes), p.deriv()(sch.nodes[sch.colloc])
        np.testing.assert_allclose(x[1:] - x[0], M @ dx, atol=1e-11)


def test_integral_defects_are_the_differential_ones_mapped_interval_by_interval():
    rng = np.random.default_rng(1)
    for kw in (dict(scheme="lgr", degree=5), dict(scheme="hermite-simpson")):
        diff, integ = Mesh(3, **kw), Mesh(3, defect_form="integral", **kw)
        X = rng.normal(size=(2, diff.n_state_nodes))
        F = rng.normal(size=(2, diff.n_colloc_nodes))
        d0 = np.asarray(diff.defects(ca.DM(X), ca.DM(F), 0.7))
        d1 = np.asarray(integ.defects(ca.DM(X), ca.DM(F), 0.7))
        nd = diff.interval.n_defects
        Ahat = diff.interval.A[:, 1:]
        for i in range(3):
            blk = slice(i * nd, (i + 1) * nd)
            np.testing.assert_allclose(d1[:, blk], np.linalg.solve(Ahat, d0[:, blk].T).T, atol=1e-12)
    assert "integral defects" in Mesh(20, defect_form="integral").describe()
    with pytest.raises(ValueError, match="defect_form"):
        Mesh(4, defect_form="spectral")


@pytest.mark.parametrize("mesh", [Mesh(8, "lgr", 4, defect_form="integral"),
                                  Mesh(40, "hermite-simpson", defect_form="integral")],
                         ids=lambda m: m.describe())
def test_double_integrator_integral_form(mesh):
    sol = solve(Problem(double_integrator()), mesh, SolverOptions())
    assert sol.success and sol.objective == pytest.approx(12.0, abs=1e-8)
