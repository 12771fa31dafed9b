"""A process reuses the solver it built for an identical NLP (whole-graph derivatives,
``ocp._graph_solver``): the same functions, so the same iterates to the last bit; anything that
changes the graph or the solver's options builds anew; bounds, guesses, data and weights are
arguments of each solve and may differ."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from gaitlib import ocp
from gaitlib.collocation import Mesh
from gaitlib.ocp import Goal, Phase, Problem, SolverOptions, transcribe


@pytest.fixture(autouse=True)
def _fresh(monkeypatch):
    monkeypatch.delenv(ocp.BUILD_REUSE_ENV, raising=False)
    ocp.clear_built_solvers()
    yield
    ocp.clear_built_solvers()


def _swing_up(tau_max=15.0, damping=0.1, effort_norm=1.0) -> Problem:
    """A pendulum swung up by a bounded torque in fixed time (nonlinear dynamics)."""
    ph = Phase(name="swing", states=("th", "om"), controls=("tau",),
               dynamics=lambda x, u, p, t: [x["om"], -9.81 * ca.sin(x["th"]) - damping * x["om"] + u["tau"]],
               t0=0.0, tf=2.0, initial={"th": 0.0, "om": 0.0}, final={"th": np.pi, "om": 0.0},
               bounds={"tau": (-tau_max, tau_max)},
               goals=(Goal("effort", 1.0, integrand=lambda x, u, p, t: u["tau"] ** 2 + 0.1 * ca.cos(x["th"]) ** 2,
                           normalization=effort_norm),))
    return Problem(ph)


MESH = Mesh(8, "lgr", 3)


def _arrays(sol):
    return np.concatenate([sol.states.to_numpy().ravel(), sol.controls.to_numpy().ravel()])


def test_the_same_nlp_is_built_once_and_solves_to_the_same_bits(monkeypatch):
    first = transcribe(_swing_up(), MESH, SolverOptions())
    second = transcribe(_swing_up(), MESH, SolverOptions())
    assert not first.reused and second.reused
    assert second.solver is first.solver
    # bounds are the solve's arguments: a tighter torque bound on the reused solver …
    tight = transcribe(_swing_up(tau_max=12.0), MESH, SolverOptions())
    assert tight.reused
    a = tight.solve()
    # … equals a solver built for it alone
    monkeypatch.setenv(ocp.BUILD_REUSE_ENV, "0")
    fresh = transcribe(_swing_up(tau_max=12.0), MESH, SolverOptions())
    assert not fresh.reused and fresh.solver is not first.solver
    b = fresh.solve()
    assert a.success and b.success and a.iterations > 5
    assert a.iterations == b.iterations and a.objective == b.objective
    assert np.array_equal(_arrays(a), _arrays(b))
    assert a.controls["tau"].abs().max() <= 12.0 + 1e-6
    assert a.info["solver_reused"] and not b.info["solver_reused"]


def test_what_changes_the_graph_or_the_options_builds_anew():
    base = transcribe(_swing_up(), MESH, SolverOptions())
    others = [transcribe(_swing_up(damping=0.2), MESH, SolverOptions()),        # a constant in the dynamics
              transcribe(_swing_up(effort_norm=2.0), MESH, SolverOptions()),    # a goal's normalisation
              transcribe(_swing_up(), Mesh(9, "lgr", 3), SolverOptions()),      # the mesh
              transcribe(_swing_up(), MESH, SolverOptions(max_iter=50)),        # an IPOPT option
              transcribe(_swing_up(), MESH, SolverOptions(ipopt={"mu_init": 1e-2}))]
    assert not any(t.reused for t in others)
    assert len({id(t.solver) for t in [base, *others]}) == 6


def test_per_node_derivatives_are_not_kept():
    a = transcribe(_swing_up(), MESH, SolverOptions(derivatives="nodes"))
    b = transcribe(_swing_up(), MESH, SolverOptions(derivatives="nodes"))
    assert not a.reused and not b.reused and a.solver is not b.solver


def test_the_memory_budget(monkeypatch):
    monkeypatch.setenv(ocp.BUILD_REUSE_ENV, "1e-9")  # smaller than any solver: nothing is kept
    transcribe(_swing_up(), MESH, SolverOptions())
    assert not transcribe(_swing_up(), MESH, SolverOptions()).reused
    monkeypatch.setenv(ocp.BUILD_REUSE_ENV, "0")
    assert not transcribe(_swing_up(), MESH, SolverOptions()).reused
    monkeypatch.setenv(ocp.BUILD_REUSE_ENV, "lots")
    with pytest.raises(ValueError, match=r"GAITLIB_BUILD_REUSE_MB='lots'.*number of MB"):
        transcribe(_swing_up(), MESH, SolverOptions())


def test_least_recently_used_is_dropped_first(monkeypatch):
    t1 = transcribe(_swing_up(), MESH, SolverOptions())
    mb = next(iter(ocp._SOLVERS.values()))[1]
    assert mb > 0
    # room for two solvers of this size: the third evicts the least recently used
    monkeypatch.setenv(ocp.BUILD_REUSE_ENV, str(2.5 * mb))
    transcribe(_swing_up(damping=0.2), MESH, SolverOptions())
    assert transcribe(_swing_up(), MESH, SolverOptions()).reused  # t1's solver, now most recent
    transcribe(_swing_up(damping=0.3), MESH, SolverOptions())      # evicts damping 0.2
    assert transcribe(_swing_up(), MESH, SolverOptions()).solver is t1.solver
    assert not transcribe(_swing_up(damping=0.2), MESH, SolverOptions()).reused


def test_default_budget_is_a_quarter_of_the_machine_at_most_the_cap(monkeypatch):
    monkeypatch.setattr(ocp, "_machine_mb", lambda: 8000.0)
    assert ocp._reuse_budget_mb() == 2000.0
    monkeypatch.setattr(ocp, "_machine_mb", lambda: 64000.0)
    assert ocp._reuse_budget_mb() == ocp.BUILD_REUSE_MB
    monkeypatch.setenv(ocp.BUILD_REUSE_ENV, "123")
    assert ocp._reuse_budget_mb() == 123.0
