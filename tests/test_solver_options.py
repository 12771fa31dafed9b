"""IPOPT options that gaitlib sets beside the problem's own (``SolverOptions.nlpsol_options``):
MUMPS's working space changes the time, not the result — the same path to the last bit."""

from __future__ import annotations

import numpy as np

from gaitlib import ocp
from gaitlib.collocation import Mesh
from gaitlib.ocp import Goal, Phase, Problem, SolverOptions, transcribe


def _van_der_pol() -> Problem:
    """Van der Pol oscillator steered from (1, 0) to rest in 4 s with bounded control:
    nonlinear dynamics and a non-quadratic cost, so IPOPT needs several iterations."""
    ph = Phase(name="vdp", states=("x", "v"), controls=("u",),
               dynamics=lambda x, u, p, t: [x["v"], (1 - x["x"] ** 2) * x["v"] - x["x"] + u["u"]],
               t0=0.0, tf=4.0, initial={"x": 1.0, "v": 0.0}, final={"x": 0.0, "v": 0.0},
               bounds={"u": (-0.8, 0.8)},
               goals=(Goal("effort", 1.0, integrand=lambda x, u, p, t: u["u"] ** 2 + x["x"] ** 4),))
    return Problem(ph)


def test_mumps_working_space_is_ours_unless_overridden():
    assert SolverOptions().nlpsol_options()["ipopt"]["mumps_mem_percent"] == ocp.MUMPS_MEM_PERCENT == 100
    assert SolverOptions(ipopt={"mumps_mem_percent": 1000}).nlpsol_options()["ipopt"]["mumps_mem_percent"] == 1000
    assert "mumps_mem_percent" not in SolverOptions(linear_solver="spral").nlpsol_options()["ipopt"]


def test_mumps_working_space_changes_the_time_not_the_path():
    """IPOPT's default (1000 %) against ours, and a working space too small at first (1 %:
    IPOPT enlarges it and factorises again): the same iterations, objective and trajectories,
    bit for bit."""
    sols = [transcribe(_van_der_pol(), Mesh(12, "lgr", 4), SolverOptions(ipopt=extra)).solve()
            for extra in ({"mumps_mem_percent": 1000}, {}, {"mumps_mem_percent": 1})]
    assert sols[0].success and sols[0].iterations > 5
    for s in sols[1:]:
        assert s.iterations == sols[0].iterations
        assert s.objective == sols[0].objective
        assert np.array_equal(s.states.to_numpy(), sols[0].states.to_numpy())
        assert np.array_equal(s.controls.to_numpy(), sols[0].controls.to_numpy())
