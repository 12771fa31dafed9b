"""Multi-phase optimal control problems → direct-collocation NLP → :class:`Solution`.

*What* to solve (:class:`Problem`, :class:`Phase`, :class:`Goal`, …: frozen, declarative,
everything by name) is separate from *how* (:class:`~gaitlib.collocation.Mesh` and
:class:`SolverOptions`), as in OpenSim Moco. :func:`solve` (or :func:`transcribe` followed
by :meth:`Transcription.solve`, to reuse one NLP for several guesses or data sets) returns a
:class:`Solution` with frames by name, cost terms by name, status and timings.

Symbol legend
-------------
x (n_x)   states of a phase, by name          u (n_u)   controls of a phase, by name
p (n_p)   static parameters (NLP variables shared by all phases), by name
t         absolute time (s); t0, tf phase start and end (fixed or free)
d (n_d)   per-node data of a phase (e.g. tracking references), by name
n_s, n_c  state and collocation (control) nodes of the phase's mesh (see collocation.py)

Goal weights and per-node data are NLP *parameters*: one :class:`Transcription` is
re-solved with other weights (another cost function) or data without rebuilding.

User functions
--------------
Dynamics, path constraints and integrands are called **once per phase** on symbolic
CasADi SX arguments, giving one per-node ``casadi.Function`` ``node(x, u, p, t, d) →
(ẋ, g, L)``; it is then evaluated at all collocation nodes with ``Function.map``. With the
default ``SolverOptions(graph="sx")`` the NLP is one SX graph (mapped calls are inlined),
which is what was measured fastest to evaluate here (performance-notes.md). Its derivatives
are either CasADi's of the whole graph (``derivatives="graph"``) or assembled from per-node
derivative functions (``derivatives="nodes"``, :meth:`Transcription._node_derivatives`: the
same derivatives to round-off, built in a fraction of the time). With ``graph="mx"`` the NLP
is an MX graph with a single mapped call per phase, expanded to SX by ``nlpsol``
(``expand=True``, the default: same speed as SX). ``graph="mx", expand=False`` keeps the
mapped MX graph: building is much faster but each iteration's function evaluations are
slower (environment.md, "Measured choices") — for quick low-resolution runs and tests, not for
production solves.

Callables receive :class:`Named` views: ``x["knee_r"]``, ``x[["hip_r", "knee_r"]]``,
``x.vec`` (the whole column); an unknown name raises ``KeyError``. Callables of the node
data accept an optional fifth argument ``d`` (also a :class:`Named`). A ``casadi.Function``
given as dynamics is called with the leading ``n_in`` of ``(x, u, p, t)`` as plain vectors.
"""

from __future__ import annotations

import hashlib
import inspect
import json
import math
import os
import time
import warnings
from collections import OrderedDict
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Union

import casadi as ca
import numpy as np
import pandas as pd
import scipy.sparse as sp

from gaitlib import compiled
from gaitlib.collocation import Mesh

__all__ = [
    "Bounds",
    "EndpointConstraint",
    "Goal",
    "Guess",
    "Linkage",
    "MUMPS_MEM_PERCENT",
    "Named",
    "Parameter",
    "Periodic",
    "Phase",
    "PhaseGuess",
    "PhaseSolution",
    "PathConstraint",
    "Problem",
    "Solution",
    "SolveFailedError",
    "SolveFailedWarning",
    "SolverOptions",
    "Transcription",
    "solve",
    "transcribe",
]

Number = Union[float, int]
#: A bound given as a fixed value ``v`` or a pair ``(lower, upper)``; each entry may be a
#: scalar or (for state/control path bounds) an array with one value per node.
Bounds = Union[Number, tuple[Any, Any]]


# ======================================================================================
# Named views
# ======================================================================================
class Named:
    """A symbolic column vector whose entries are addressed by name.

    ``v["a"]`` → scalar; ``v[["a", "b"]]`` → column; ``v[0]``/``v[1:3]`` → by position;
    ``v.vec`` → the whole column. Unknown names raise ``KeyError`` listing the valid ones.
    """

    def __init__(self, vec, names: Sequence[str], kind: str = "variable", where: str = ""):
        self.vec = vec
        self.names = tuple(names)
        self.kind = kind
        self.where = where
        self._index = {n: i for i, n in enumerate(self.names)}

    def index(self, name: str) -> int:
        try:
            return self._index[name]
        except KeyError:
            raise KeyError(
                f"unknown {self.kind} {name!r}{' in ' + self.where if self.where else ''}; "
                f"known: {', '.join(self.names) or '(none)'}"
            ) from None

    def __getitem__(self, key):
        if isinstance(key, str):
            return self.vec[self.index(key)]
        if isinstance(key, (list, tuple)) and all(isinstance(k, str) for k in key):
            return ca.vertcat(*[self.vec[self.index(k)] for k in key])
        return self.vec[key]

    def __contains__(self, name) -> bool:
        return name in self._index

    def __len__(self) -> int:
        return len(self.names)

    def __repr__(self) -> str:
        return f"Named({self.kind}: {', '.join(self.names)})"


# ======================================================================================
# Problem specification (frozen dataclasses)
# ======================================================================================
def _freeze_map(m: Mapping | None) -> Mapping:
    return MappingProxyType(dict(m or {}))


@dataclass(frozen=True)
class Parameter:
    """A static parameter: an NLP variable shared by all phases (e.g. a contact stiffness).

    ``lower == upper`` fixes it. ``guess`` defaults to the midpoint of finite bounds, else 0.
    """

    name: str
    lower: float = -math.inf
    upper: float = math.inf
    guess: float | None = None

    def initial(self) -> float:
        if self.guess is not None:
            return float(self.guess)
        return _mid(self.lower, self.upper)


@dataclass(frozen=True)
class Goal:
    """A named, weighted cost term (Moco's ``MocoGoal``; the thesis's Jrk, Rsd, Trq, …).

    Exactly one of ``integrand`` (Lagrange term, ``integrand(x, u, p, t[, d]) → scalar``,
    integrated over the phase with the mesh's quadrature) or ``endpoint`` (Mayer term,
    ``endpoint(x0, xf, p, t0, tf) → scalar``) is given. Its contribution to the objective
    is ``weight · value``, with ``value = term / normalization`` and additionally divided by
    the phase duration when ``divide_by_duration``.

    Examples
    --------
    >>> jerk = Goal("Jrk", weight=1 / 40, integrand=lambda x, u, p, t: ca.sumsqr(u["jerk"]))
    """

    name: str
    weight: float = 1.0
    integrand: Callable | None = None
    endpoint: Callable | None = None
    normalization: float = 1.0
    divide_by_duration: bool = False

    def __post_init__(self):
        if (self.integrand is None) == (self.endpoint is None):
            raise ValueError(f"goal {self.name!r}: give exactly one of integrand, endpoint")
        if not self.normalization or not math.isfinite(self.normalization):
            raise ValueError(f"goal {self.name!r}: normalization must be finite and non-zero")


@dataclass(frozen=True)
class PathConstraint:
    """``lower ≤ fun(x, u, p, t[, d]) ≤ upper`` at every collocation node.

    ``lower``/``upper``: scalars or arrays of the function's length. Implicit dynamics
    (e.g. the multibody equations M q̈ + c − τ = 0) are path constraints with 0 bounds.
    """

    name: str
    fun: Callable
    lower: Any = 0.0
    upper: Any = 0.0


@dataclass(frozen=True)
class EndpointConstraint:
    """``lower ≤ fun(x0, xf, p, t0, tf) ≤ upper`` for one phase (Named x0, xf, p)."""

    name: str
    fun: Callable
    lower: Any = 0.0
    upper: Any = 0.0


@dataclass(frozen=True)
class Periodic:
    """x(tf) − x(t0) = offset for the named states (offset 0 unless given).

    ``offsets[name]`` is a number or ``callable(p, t0, tf)`` — e.g. the pelvis advancing
    by one stride: ``{"pelvis_tx": lambda p, t0, tf: speed * (tf - t0)}``.
    """

    states: tuple[str, ...]
    offsets: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        object.__setattr__(self, "states", tuple(self.states))
        object.__setattr__(self, "offsets", _freeze_map(self.offsets))
        extra = set(self.offsets) - set(self.states)
        if extra:
            raise ValueError(f"Periodic offsets for states not listed: {sorted(extra)}")


@dataclass(frozen=True, eq=False)
class Phase:
    """One phase of a problem: states, controls, dynamics, bounds, constraints, goals.

    Parameters
    ----------
    name : str
    states, controls : tuple of str
        Names, in vector order. Names must be unique across states and controls.
    dynamics : callable or casadi.Function
        ẋ = f(x, u, p, t[, d]) returning n_x values (column or list).
    t0, tf : float or (lower, upper)
        Fixed value or bounds of the phase's start/end time (s).
    bounds : mapping name → value or (lower, upper)
        Path bounds of states and controls. Each bound may be a scalar or an array with
        one value per node (n_s for states, n_c for controls). Unbounded if omitted.
    initial, final : mapping state name → value or (lower, upper)
        Bounds on x(t0) and x(tf).
    path_constraints, endpoint_constraints : tuple
    goals : tuple of Goal
    periodic : Periodic, optional
    data : pandas.DataFrame, optional
        Per-node data (tracking references) indexed by normalised time τ ∈ [0, 1],
        one column per channel, linearly interpolated to the collocation nodes. Passed to
        callables that take a fifth argument ``d``.
    duration : (lower, upper), optional
        Bounds on tf − t0 (a linear constraint), for free times.
    """

    name: str
    states: tuple[str, ...]
    controls: tuple[str, ...]
    dynamics: Callable | ca.Function
    t0: Bounds = 0.0
    tf: Bounds = 1.0
    bounds: Mapping[str, Bounds] = field(default_factory=dict)
    initial: Mapping[str, Bounds] = field(default_factory=dict)
    final: Mapping[str, Bounds] = field(default_factory=dict)
    path_constraints: tuple[PathConstraint, ...] = ()
    endpoint_constraints: tuple[EndpointConstraint, ...] = ()
    goals: tuple[Goal, ...] = ()
    periodic: Periodic | None = None
    data: pd.DataFrame | None = None
    duration: tuple[float, float] | None = None

    def __post_init__(self):
        for attr in ("states", "controls", "path_constraints", "endpoint_constraints", "goals"):
            object.__setattr__(self, attr, tuple(getattr(self, attr)))
        for attr in ("bounds", "initial", "final"):
            object.__setattr__(self, attr, _freeze_map(getattr(self, attr)))
        names = self.states + self.controls
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ValueError(f"phase {self.name!r}: duplicate names {sorted(dup)}")
        for n in self.bounds:
            if n not in names:
                raise KeyError(f"phase {self.name!r}: bounds for unknown name {n!r}")
        for attr in ("initial", "final"):
            for n in getattr(self, attr):
                if n not in self.states:
                    raise KeyError(f"phase {self.name!r}: {attr} bound for unknown state {n!r}")
        if self.periodic is not None:
            for n in self.periodic.states:
                if n not in self.states:
                    raise KeyError(f"phase {self.name!r}: periodic unknown state {n!r}")
        for kind in ("path_constraints", "endpoint_constraints", "goals"):
            seen = [c.name for c in getattr(self, kind)]
            dup = {n for n in seen if seen.count(n) > 1}
            if dup:
                raise ValueError(f"phase {self.name!r}: duplicate {kind} names {sorted(dup)}")
        if self.data is not None:
            if not isinstance(self.data, pd.DataFrame):
                raise TypeError("Phase.data must be a DataFrame indexed by normalised time")
            tau = np.asarray(self.data.index, dtype=float)
            if tau.min() > 0.0 or tau.max() < 1.0 or np.any(np.diff(tau) <= 0):
                raise ValueError("Phase.data index must increase and cover τ ∈ [0, 1]")

    @property
    def data_names(self) -> tuple[str, ...]:
        return () if self.data is None else tuple(str(c) for c in self.data.columns)

    def state_index(self, name: str) -> int:
        return Named(None, self.states, "state", f"phase {self.name!r}").index(name)

    def control_index(self, name: str) -> int:
        return Named(None, self.controls, "control", f"phase {self.name!r}").index(name)


@dataclass(frozen=True)
class Linkage:
    """Continuity from the end of phase ``before`` to the start of phase ``after``.

    x_after(t0) − x_before(tf) = offset for ``states`` (default: all states the two phases
    share by name), and t0_after = tf_before when ``time``. ``offsets`` as in
    :class:`Periodic`. A linkage from the last phase to the first (with ``time=False``)
    makes a multi-phase cycle periodic.
    """

    before: str
    after: str
    states: tuple[str, ...] | None = None
    time: bool = True
    offsets: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        if self.states is not None:
            object.__setattr__(self, "states", tuple(self.states))
        object.__setattr__(self, "offsets", _freeze_map(self.offsets))


@dataclass(frozen=True, eq=False)
class Problem:
    """A multi-phase optimal control problem: phases, static parameters, linkages."""

    phases: tuple[Phase, ...]
    parameters: tuple[Parameter, ...] = ()
    linkages: tuple[Linkage, ...] = ()
    name: str = "problem"

    def __post_init__(self):
        if isinstance(self.phases, Phase):
            object.__setattr__(self, "phases", (self.phases,))
        for attr in ("phases", "parameters", "linkages"):
            object.__setattr__(self, attr, tuple(getattr(self, attr)))
        if not self.phases:
            raise ValueError("a problem needs at least one phase")
        names = [ph.name for ph in self.phases]
        if len(set(names)) != len(names):
            raise ValueError(f"duplicate phase names {names}")
        pnames = [p.name for p in self.parameters]
        if len(set(pnames)) != len(pnames):
            raise ValueError(f"duplicate parameter names {pnames}")
        for lk in self.linkages:
            a, b = self.phase(lk.before), self.phase(lk.after)
            states = lk.states if lk.states is not None else [s for s in a.states if s in b.states]
            for s in states:
                if s not in a.states or s not in b.states:
                    raise KeyError(f"linkage {lk.before}->{lk.after}: state {s!r} not in both")
            for s in lk.offsets:
                if s not in states:
                    raise KeyError(f"linkage offset for unlinked state {s!r}")

    def phase(self, name: str) -> Phase:
        for ph in self.phases:
            if ph.name == name:
                return ph
        raise KeyError(f"unknown phase {name!r}; known: {[p.name for p in self.phases]}")

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)


# ======================================================================================
# Solver options
# ======================================================================================
#: The default of :attr:`SolverOptions.derivatives`. "graph" while the solution store holds
#: solutions made with it: per-node derivatives are the same functions to round-off, but
#: IPOPT's path from them can end in another local optimum, so switching the default means
#: re-solving the store (tools/store_solutions.py) for a from-scratch run to reproduce it.
DEFAULT_DERIVATIVES = "graph"

#: ``GAITLIB_COMPILE=1``: the default of :attr:`SolverOptions.compiled` (an environment
#: variable, so sweep workers inherit it; the CLI's ``--compiled`` sets it). It changes how
#: fast the per-node functions are evaluated, not what they compute (the same bits), so it is
#: no part of any cache key.
COMPILE_ENV = "GAITLIB_COMPILE"


def _default_compiled() -> bool:
    return os.environ.get(COMPILE_ENV, "0") not in ("", "0")


#: MUMPS's working space above its own estimate, % (IPOPT's default 1000: ten times the
#: estimate, allocated and released at every factorisation; see :class:`SolverOptions`).
MUMPS_MEM_PERCENT = 100


@dataclass(frozen=True)
class SolverOptions:
    """How to solve: IPOPT settings and NLP graph type (separate from the problem).

    Parameters
    ----------
    tol : float
        IPOPT ``tol`` (the thesis used 1e-5 with GPOPS-II).
    constr_viol_tol : float
        IPOPT ``constr_viol_tol`` (absolute constraint violation for convergence).
    max_iter : int
    hessian : {"exact", "limited-memory"}
        Exact Hessian of the Lagrangian (fast here) or L-BFGS (GPOPS-II's "first
        derivative mode"; did not converge on the gait problem, performance-notes.md).
    linear_solver : {"mumps", "spral"}
    print_level : int
        IPOPT print level (0 silent, 5 the usual iteration log).
    graph : {"sx", "mx"}
        Build the NLP as one SX graph, or as MX with mapped per-node calls.
    expand : bool
        With ``graph="mx"``: expand to SX inside nlpsol (recommended: unexpanded MX
        evaluates far slower per iteration on the gait problem).
    derivatives : {"graph", "nodes"}
        How the NLP's exact derivatives are built (with ``graph="sx"``; an MX graph is
        always differentiated by CasADi); default :data:`DEFAULT_DERIVATIVES`.
        ``"graph"``: CasADi differentiates the
        whole NLP graph (one SX graph of every node; the Hessian of the Lagrangian of the
        MSK gait problem is ≈ 12 million instructions, built symbolically before the first
        iteration). ``"nodes"``: each phase's per-node function is differentiated once (its
        Jacobian and the Hessian of a weighted sum of its outputs), evaluated at every
        collocation node in one mapped call, and assembled by the chain rule with the
        derivatives of the rest of the NLP (collocation defects, quadrature, endpoints: a
        small graph with the node outputs as symbols). The same exact derivatives, to
        round-off (tests/test_node_derivatives.py), built in a fraction of the time
        (benchmarks/bench_build.py). IPOPT's path can still differ at round-off level, and
        on the non-convex gait problems that can mean another local optimum.
    compiled : bool
        With ``derivatives="nodes"``: evaluate the per-node functions (values, Jacobians,
        Hessians) as compiled C (:func:`gaitlib.compiled.compiled`, cached on disk: the first
        use on a machine compiles, later ones load). The same operations in the same order
        as CasADi's SX virtual machine, compiled without fast-math or FMA contraction: the
        same numbers to the last bit, so IPOPT takes the same path
        (tests/test_compiled.py). Ignored with ``derivatives="graph"`` (one whole-NLP graph
        is too large to compile).
    ipopt : mapping
        Further IPOPT options, applied last (e.g. ``{"nlp_scaling_method": "none"}``).

    With MUMPS, ``mumps_mem_percent`` is :data:`MUMPS_MEM_PERCENT` instead of IPOPT's 1000:
    MUMPS's working space, allocated at every factorisation, is its estimate plus this
    percentage (IPOPT enlarges it and factorises again should MUMPS report too little). It
    changes the time, not the result: the same pivots and numbers, so IPOPT's path is the
    same to the last bit (benchmarks/README.md, "MUMPS's working space").

    Fixed for determinism: ``mu_strategy="monotone"`` (IPOPT's default; "adaptive" was 3×
    slower here), no timing-dependent options. Use one BLAS thread
    (``OPENBLAS_NUM_THREADS=1``) — with more, IPOPT took a different path on 2 cores.
    """

    tol: float = 1e-6
    constr_viol_tol: float = 1e-6
    max_iter: int = 3000
    hessian: str = "exact"
    linear_solver: str = "mumps"
    print_level: int = 0
    graph: str = "sx"
    expand: bool = True
    derivatives: str = field(default_factory=lambda: DEFAULT_DERIVATIVES)
    compiled: bool = field(default_factory=_default_compiled)
    ipopt: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        object.__setattr__(self, "ipopt", _freeze_map(self.ipopt))
        if self.hessian not in ("exact", "limited-memory"):
            raise ValueError("hessian must be 'exact' or 'limited-memory'")
        if self.graph not in ("sx", "mx"):
            raise ValueError("graph must be 'sx' or 'mx'")
        if self.derivatives not in ("graph", "nodes"):
            raise ValueError("derivatives must be 'graph' or 'nodes'")

    def nlpsol_options(self) -> dict:
        ipopt = {
            "tol": self.tol,
            "constr_viol_tol": self.constr_viol_tol,
            "max_iter": int(self.max_iter),
            "hessian_approximation": self.hessian,
            "linear_solver": self.linear_solver,
            "print_level": int(self.print_level),
            "mu_strategy": "monotone",
            "sb": "yes",
        }
        if self.linear_solver == "mumps":
            ipopt["mumps_mem_percent"] = MUMPS_MEM_PERCENT
        ipopt.update(dict(self.ipopt))
        opts = {"ipopt": ipopt, "print_time": False, "error_on_fail": False}
        if self.graph == "mx":
            opts["expand"] = bool(self.expand)
        return opts


# ======================================================================================
# Reusing built solvers (whole-graph derivatives)
# ======================================================================================
#: ``GAITLIB_BUILD_REUSE_MB``: how much memory (MB, estimated) a process may keep in built
#: whole-graph solvers for reuse (:func:`_graph_solver`); ``0`` turns reuse off.
BUILD_REUSE_ENV = "GAITLIB_BUILD_REUSE_MB"
#: Its default: a quarter of the machine's memory, at most this (MB). Solvers at 20 × 5 hold
#: ≈ 0.6 GB (SK), 1.5 GB (MSK; contact identification (b)) and 2.4 GB (contact
#: identification (c), free body) of resident memory.
BUILD_REUSE_MB = 6000
#: Estimated memory of a built SX solver per instruction of its functions (bytes): the
#: growth of the process's resident memory over the build of SK 10 × 3, SK 20 × 5, MSK 20 × 5
#: and contact-identification solvers was 59–84 B per instruction; the larger value.
_BYTES_PER_INSTRUCTION = 85
_SOLVERS: "OrderedDict[str, tuple[ca.Function, float]]" = OrderedDict()
_DERIVATIVE_FUNCTIONS = ("nlp_f", "nlp_g", "nlp_grad_f", "nlp_jac_g", "nlp_hess_l", "nlp_grad")


def _machine_mb() -> float:
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 1e6
    except (ValueError, OSError, AttributeError):
        return 4.0 * BUILD_REUSE_MB


def _reuse_budget_mb() -> float:
    raw = os.environ.get(BUILD_REUSE_ENV, "")
    try:
        return float(raw) if raw.strip() else min(float(BUILD_REUSE_MB), 0.25 * _machine_mb())
    except ValueError:
        raise ValueError(f"${BUILD_REUSE_ENV}={raw!r}: expected a number of MB (0 turns reuse off)") from None


def _structure_key(name: str, nlp: Mapping[str, Any], opts: Mapping[str, Any]) -> str:
    """SHA-256 of the NLP's objective and constraints as one function of (x, p) — its
    serialised SX graph, which fixes every derivative CasADi builds from it — with the
    solver's name, options and CasADi's version. Bounds, guesses, data and weights are
    arguments of each solve, not part of the solver, so they are no part of the key."""
    h = hashlib.sha256()
    fg = ca.Function("fg", [nlp["x"], nlp["p"]], [nlp["f"], nlp["g"]])
    for part in (name, json.dumps(opts, sort_keys=True, default=str), ca.__version__, fg.serialize()):
        h.update(part.encode())
        h.update(b"\0")
    return h.hexdigest()


def _graph_solver(name: str, nlp: Mapping[str, Any], opts: Mapping[str, Any]) -> tuple[ca.Function, bool]:
    """IPOPT's solver for an SX NLP with whole-graph derivatives: the one this process built
    for the same NLP before (the same graph, options and name: identical functions, so the
    same iterates to the last bit), or a new one. Building differentiates the whole graph
    (seconds for SK, ≈ 30 s for MSK at 20 × 5), so a process that solves one structure with
    other data, weights, bounds or guesses (continuation stages over bounds, multistarts,
    restarts) builds it once; speed classes and cost functions are other graphs. Kept
    least-recently-used within ``$GAITLIB_BUILD_REUSE_MB`` of estimated memory (default a
    quarter of the machine's, at most :data:`BUILD_REUSE_MB`). Returns (solver, reused)."""
    budget = _reuse_budget_mb()
    if budget <= 0:
        return ca.nlpsol(name, "ipopt", nlp, dict(opts)), False
    key = _structure_key(name, nlp, opts)
    hit = _SOLVERS.get(key)
    if hit is not None:
        _SOLVERS.move_to_end(key)
        return hit[0], True
    solver = ca.nlpsol(name, "ipopt", nlp, dict(opts))
    mb = sum(solver.get_function(f).n_instructions() for f in _DERIVATIVE_FUNCTIONS) * _BYTES_PER_INSTRUCTION / 1e6
    if mb <= budget:
        _SOLVERS[key] = (solver, mb)
        while sum(v[1] for v in _SOLVERS.values()) > budget:
            _SOLVERS.popitem(last=False)
    return solver, False


def clear_built_solvers() -> None:
    """Forget every solver kept for reuse (frees their memory once no Transcription holds them)."""
    _SOLVERS.clear()


# ======================================================================================
# Initial guess
# ======================================================================================
@dataclass(frozen=True, eq=False)
class PhaseGuess:
    """A guess for one phase from arrays over time, interpolated to the mesh.

    ``states``/``controls``: DataFrame (index = time) or mapping name → array over
    ``time`` (s). Names not given keep the default guess; unknown names are an error.
    Values are interpolated linearly in normalised time ``(t − t0) / (tf − t0)``, with
    ``t0``/``tf`` defaulting to ``time[0]``/``time[-1]`` (the guess for free times).
    """

    time: Any = None
    states: Any = None
    controls: Any = None
    t0: float | None = None
    tf: float | None = None


@dataclass(frozen=True, eq=False)
class Guess:
    """An initial guess: per-phase :class:`PhaseGuess` by phase name, parameters by name."""

    phases: Mapping[str, PhaseGuess] = field(default_factory=dict)
    parameters: Mapping[str, float] = field(default_factory=dict)

    @classmethod
    def from_solution(cls, sol: "Solution") -> "Guess":
        """Warm start from a previous solution (any mesh; interpolated to the new one)."""
        phases = {}
        for name, ps in sol.phases.items():
            phases[name] = PhaseGuess(
                time=None,
                states=ps.states,
                controls=ps.controls,
                t0=ps.t0,
                tf=ps.tf,
            )
        return cls(phases=phases, parameters=dict(sol.parameters))


def _series(obj, name, time):
    """Return (times, values) of one channel from a DataFrame or mapping."""
    if isinstance(obj, pd.DataFrame):
        t = np.asarray(obj.index, dtype=float) if time is None else np.asarray(time, float)
        return t, np.asarray(obj[name], dtype=float)
    return np.asarray(time, dtype=float), np.asarray(obj[name], dtype=float)


# ======================================================================================
# Solution
# ======================================================================================
class SolveFailedError(RuntimeError):
    """Raised by :meth:`Solution.require_success` for a failed solve."""


class SolveFailedWarning(UserWarning):
    """Issued when a solve ends without IPOPT reporting success."""


@dataclass(eq=False)
class PhaseSolution:
    """One phase of a solution.

    ``states``: DataFrame (n_s rows, one column per state) indexed by time (s) on the
    state nodes; ``controls``: DataFrame (n_c rows) on the collocation nodes.
    """

    name: str
    states: pd.DataFrame
    controls: pd.DataFrame
    t0: float
    tf: float

    def interpolate(self, t) -> pd.DataFrame:
        """States and controls at times ``t`` (s), linear; controls held at the ends."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        cols = {}
        for frame in (self.states, self.controls):
            tt = np.asarray(frame.index, dtype=float)
            for c in frame.columns:
                cols[c] = np.interp(t, tt, frame[c].to_numpy())
        return pd.DataFrame(cols, index=pd.Index(t, name="time"))


@dataclass(eq=False)
class Solution:
    """Result of :func:`solve`.

    Attributes
    ----------
    phases : dict name → PhaseSolution
    parameters : dict name → float
    goals : DataFrame
        One row per (phase, goal): columns ``phase, goal, weight, value, weighted``
        (``weighted = weight · value``, their sum is the objective).
    objective : float
    status : str
        IPOPT's return status (e.g. ``"Solve_Succeeded"``, ``"Maximum_Iterations_Exceeded"``).
    success : bool
        IPOPT's own verdict; never inferred.
    iterations : int
    solve_time, build_time : float
        Wall-clock seconds of the IPOPT call and of building the NLP (symbolic graph and
        nlpsol with its derivative functions).
    max_violation : float
        Largest violation of any constraint or variable bound at the returned point.
    worst_constraint : str
        Name of the constraint block with that violation.
    info : dict
        Problem sizes, mesh, options and IPOPT's timing breakdown (JSON-serialisable).
    """

    phases: dict[str, PhaseSolution]
    parameters: dict[str, float]
    goals: pd.DataFrame
    objective: float
    status: str
    success: bool
    iterations: int
    solve_time: float
    build_time: float
    max_violation: float
    worst_constraint: str = ""
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        if not self.success:
            warnings.warn(
                f"solve FAILED: {self.status} after {self.iterations} iterations "
                f"(max violation {self.max_violation:.3g})",
                SolveFailedWarning,
                stacklevel=3,
            )

    # -- access -------------------------------------------------------------------
    @property
    def time_per_iteration(self) -> float:
        return self.solve_time / max(self.iterations, 1)

    def phase(self, name: str | None = None) -> PhaseSolution:
        if name is None:
            if len(self.phases) != 1:
                raise ValueError(f"several phases, name one of {list(self.phases)}")
            return next(iter(self.phases.values()))
        try:
            return self.phases[name]
        except KeyError:
            raise KeyError(f"unknown phase {name!r}; known: {list(self.phases)}") from None

    @property
    def states(self) -> pd.DataFrame:
        """States of a single-phase solution."""
        return self.phase().states

    @property
    def controls(self) -> pd.DataFrame:
        """Controls of a single-phase solution."""
        return self.phase().controls

    def cost(self, goal: str) -> float:
        """Weighted contribution of a goal (summed over phases)."""
        rows = self.goals[self.goals["goal"] == goal]
        if rows.empty:
            raise KeyError(f"unknown goal {goal!r}; known: {sorted(set(self.goals['goal']))}")
        return float(rows["weighted"].sum())

    def interpolate(self, t, phase: str | None = None) -> pd.DataFrame:
        """States and controls at times ``t`` (s) of one phase (for warm starts, plots)."""
        return self.phase(phase).interpolate(t)

    def require_success(self) -> "Solution":
        """Return self, or raise :class:`SolveFailedError` with IPOPT's status."""
        if not self.success:
            raise SolveFailedError(
                f"IPOPT did not succeed: {self.status} ({self.iterations} iterations, "
                f"max violation {self.max_violation:.3g} in {self.worst_constraint!r})"
            )
        return self

    def summary(self) -> str:
        flag = "ok" if self.success else "FAILED"
        lines = [
            f"{flag}: {self.status}, objective {self.objective:.6g}, {self.iterations} it, "
            f"solve {self.solve_time:.3f} s ({1e3 * self.time_per_iteration:.1f} ms/it), "
            f"build {self.build_time:.3f} s, max violation {self.max_violation:.2e}"
        ]
        for _, r in self.goals.iterrows():
            lines.append(f"  {r['phase']}/{r['goal']}: {r['weighted']:.6g} (w={r['weight']:g})")
        return "\n".join(lines)

    def __repr__(self) -> str:
        return f"<Solution {self.summary().splitlines()[0]}>"

    # -- persistence ----------------------------------------------------------------
    def save(self, path) -> Path:
        """Write a directory: ``solution.json`` plus ``<phase>_states.csv`` and
        ``<phase>_controls.csv`` (17 significant digits: floats round-trip exactly)."""
        path = Path(path)
        path.mkdir(parents=True, exist_ok=True)
        meta = {
            "format": "gaitlib.ocp.Solution/1",
            "phases": [],
            "parameters": self.parameters,
            "goals": self.goals.to_dict(orient="records"),
            "objective": self.objective,
            "status": self.status,
            "success": self.success,
            "iterations": self.iterations,
            "solve_time": self.solve_time,
            "build_time": self.build_time,
            "max_violation": self.max_violation,
            "worst_constraint": self.worst_constraint,
            "info": self.info,
        }
        for name, ps in self.phases.items():
            meta["phases"].append({"name": name, "t0": ps.t0, "tf": ps.tf})
            ps.states.to_csv(path / f"{name}_states.csv", float_format="%.17g")
            ps.controls.to_csv(path / f"{name}_controls.csv", float_format="%.17g")
        (path / "solution.json").write_text(json.dumps(meta, indent=1, default=_json_default))
        return path

    @classmethod
    def load(cls, path) -> "Solution":
        path = Path(path)
        meta = json.loads((path / "solution.json").read_text())
        phases = {}
        for ph in meta["phases"]:
            n = ph["name"]
            read = dict(index_col=0)  # pandas' default parser reads %.17g exactly
            states = pd.read_csv(path / f"{n}_states.csv", **read)
            controls = pd.read_csv(path / f"{n}_controls.csv", **read)
            phases[n] = PhaseSolution(n, states, controls, ph["t0"], ph["tf"])
        goals = pd.DataFrame(meta["goals"], columns=["phase", "goal", "weight", "value", "weighted"])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SolveFailedWarning)
            return cls(
                phases=phases,
                parameters=meta["parameters"],
                goals=goals,
                objective=meta["objective"],
                status=meta["status"],
                success=meta["success"],
                iterations=meta["iterations"],
                solve_time=meta["solve_time"],
                build_time=meta["build_time"],
                max_violation=meta["max_violation"],
                worst_constraint=meta["worst_constraint"],
                info=meta["info"],
            )


def _json_default(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)


# ======================================================================================
# Transcription (Problem + Mesh + SolverOptions → NLP)
# ======================================================================================
def _mid(lo, hi) -> float:
    lo, hi = float(lo), float(hi)
    if math.isfinite(lo) and math.isfinite(hi):
        return 0.5 * (lo + hi)
    if math.isfinite(lo):
        return max(lo, 0.0)
    if math.isfinite(hi):
        return min(hi, 0.0)
    return 0.0


def _lohi(b: Bounds):
    """(lower, upper) from a value or a pair (each may be an array)."""
    if isinstance(b, tuple):
        if len(b) != 2:
            raise ValueError(f"a bound is a value or (lower, upper), got {b!r}")
        lo = -np.inf if b[0] is None else b[0]
        hi = np.inf if b[1] is None else b[1]
        return lo, hi
    return b, b


def _accepts_data(fun) -> bool:
    """Whether a user callable takes the optional fifth argument ``d``."""
    if isinstance(fun, ca.Function):
        return fun.n_in() >= 5
    try:
        params = inspect.signature(fun).parameters.values()
    except (TypeError, ValueError):
        return False
    if any(p.kind == p.VAR_POSITIONAL for p in params):
        return True
    positional = [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    return len(positional) >= 5


def _column(expr, what: str):
    """User return value → casadi column (SX/MX/DM, list or number)."""
    if isinstance(expr, (list, tuple)):
        expr = ca.vertcat(*expr)
    if isinstance(expr, (int, float, np.floating, np.ndarray)):
        expr = ca.DM(expr)
    if not hasattr(expr, "is_column"):
        raise TypeError(f"{what} returned {type(expr).__name__}, expected a casadi expression")
    if not expr.is_column():
        expr = ca.vec(expr)
    return expr


def _csr(m) -> "sp.csr_matrix":
    """A constant CasADi matrix (DM or SX without symbols) as a SciPy CSR matrix."""
    m = ca.DM(ca.evalf(m)) if isinstance(m, ca.SX) else ca.DM(m)
    r, c = m.sparsity().get_triplet()
    return sp.csr_matrix((np.asarray(m.nonzeros(), float), (r, c)), shape=m.shape)


def _bilinear_map(A, ra, B, rb, shape, triu=False):
    """The constant linear map from values v_k to the non-zeros of Σ_k v_k·A[ra_k]ᵀ·B[rb_k]
    (A, B SciPy CSR; ra, rb row indices; ``triu``: the upper triangle only, for a symmetric
    sum). Returns (M as a sparse DM, the result's sparsity): the result's non-zeros are
    M @ v. Used to assemble per-node derivative blocks into the NLP's matrices by one
    constant sparse product instead of sparse-by-sparse products at every evaluation."""
    ra, rb = np.asarray(ra, int), np.asarray(rb, int)
    la, lb = np.diff(A.indptr)[ra], np.diff(B.indptr)[rb]
    k_a = np.repeat(np.arange(ra.size), la)  # one entry per non-zero of A[ra_k]
    ea = np.repeat(A.indptr[ra], la) + (np.arange(la.sum()) - np.repeat(np.cumsum(la) - la, la))
    n_pairs = lb[k_a]
    ia = np.repeat(ea, n_pairs)
    kk = np.repeat(k_a, n_pairs)
    first = np.repeat(np.cumsum(n_pairs) - n_pairs, n_pairs)
    eb = B.indptr[rb[kk]] + (np.arange(n_pairs.sum()) - first)
    i, j, coef = A.indices[ia], B.indices[eb], A.data[ia] * B.data[eb]
    if triu:
        keep = i <= j
        i, j, coef, kk = i[keep], j[keep], coef[keep], kk[keep]
    key = j.astype(np.int64) * shape[0] + i  # column-major: CasADi's order of non-zeros
    uniq, out = np.unique(key, return_inverse=True)
    M = sp.csc_matrix((coef, (out, kk)), shape=(uniq.size, ra.size))
    M.sum_duplicates()
    M.sort_indices()
    spM = ca.Sparsity(uniq.size, ra.size, M.indptr.tolist(), M.indices.tolist())
    pattern = ca.Sparsity.triplet(shape[0], shape[1], (uniq % shape[0]).tolist(), (uniq // shape[0]).tolist())
    return ca.DM(spM, M.data), pattern


class _Block:
    """Book-keeping for one named constraint block (for violation reports)."""

    def __init__(self, name, start, size):
        self.name, self.start, self.size = name, start, size


class _PhaseLayout:
    """Indices of one phase's variables in the NLP vector."""

    def __init__(self, phase: Phase, mesh: Mesh):
        self.phase, self.mesh = phase, mesh
        self.nx, self.nu = len(phase.states), len(phase.controls)
        self.ns, self.nc = mesh.n_state_nodes, mesh.n_colloc_nodes
        self.ix = np.zeros((self.nx, self.ns), dtype=int)
        self.iu = np.zeros((self.nu, self.nc), dtype=int)
        self.it0 = self.itf = None  # index in w, or None when fixed
        t0, tf = _lohi(phase.t0), _lohi(phase.tf)
        self.t0_fixed = np.isscalar(phase.t0) or t0[0] == t0[1]
        self.tf_fixed = np.isscalar(phase.tf) or tf[0] == tf[1]
        self.t0_bounds, self.tf_bounds = t0, tf


class _Lazy(dict):
    """A dict whose missing entries are made by ``make(key)`` when first looked up."""

    def __init__(self, make):
        super().__init__()
        self._make = make

    def __missing__(self, key):
        self[key] = value = self._make(key)
        return value


@dataclass
class _NodePhase:
    """One phase's per-node functions for :meth:`Transcription._node_derivatives`: the
    mapped node values and Jacobians by part ("all", "fg": ẋ and path rows, "l": integrand
    rows), the mapped node Hessian, the node inputs as a function of (w, p), sizes (n_c
    nodes, n_z differentiated inputs, n_y outputs per node) and offsets into Y and Z."""

    nc: int
    nz: int
    ny: int
    y_off: int
    z_off: int
    inputs: ca.Function
    hess: ca.Function
    rows: dict = field(default_factory=dict)
    values: dict = field(default_factory=dict)
    jacobians: dict = field(default_factory=dict)


class Transcription:
    """A problem transcribed on a mesh: the NLP, its IPOPT solver and its layout.

    Build once, solve many times (:meth:`solve` with different guesses or
    ``data=`` for phases with per-node data).

    Attributes
    ----------
    n_variables, n_constraints : int
    build_time : float
        Seconds to build the symbolic NLP and the IPOPT solver (with derivatives).
    symbolic_time : float
        Of which: seconds to build the symbolic NLP graph only.
    reused : bool
        The solver is one this process had built for an identical NLP (whole-graph
        derivatives; :func:`_graph_solver`): ``build_time`` is then the symbolic graph and
        the key's hash only.
    """

    def __init__(self, problem: Problem, mesh: Mesh | Mapping[str, Mesh], options: SolverOptions):
        t_start = time.perf_counter()
        self.problem, self.options = problem, options
        if isinstance(mesh, Mesh):
            self.meshes = {ph.name: mesh for ph in problem.phases}
        else:
            self.meshes = {ph.name: mesh[ph.name] for ph in problem.phases}
        self._sym = ca.SX if options.graph == "sx" else ca.MX
        self._path_sizes: dict[str, list[int]] = {}
        self._by_nodes = options.derivatives == "nodes" and options.graph == "sx"
        self._node_outputs: dict[str, tuple] = {}  # by_nodes: phase → (node inputs, output symbols)
        self._build()
        functions = self._node_derivatives() if self._by_nodes else {}
        self.symbolic_time = time.perf_counter() - t_start
        name, opts = f"{problem.name}_nlp", {**options.nlpsol_options(), **functions}
        if self._by_nodes:  # its derivatives take seconds to build: nothing to reuse
            self.solver, self.reused = ca.nlpsol(name, "ipopt", self.nlp, opts), False
        else:
            self.solver, self.reused = _graph_solver(name, self.nlp, opts)
        self.build_time = time.perf_counter() - t_start

    # -- construction ------------------------------------------------------------------
    def _build(self):
        S = self._sym
        pr = self.problem
        w_parts, lbw, ubw, w0 = [], [], [], []
        n_w = 0

        def add_var(name, size):
            nonlocal n_w
            v = S.sym(name, size)
            w_parts.append(v)
            start = n_w
            n_w += size
            lbw.append(np.full(size, -np.inf))
            ubw.append(np.full(size, np.inf))
            w0.append(np.zeros(size))
            return v, np.arange(start, start + size)

        self.layouts: dict[str, _PhaseLayout] = {}
        sym_X, sym_U, sym_T = {}, {}, {}
        # Variables: per phase, node by node (x_k then u_k) for a banded KKT system.
        for ph in pr.phases:
            mesh = self.meshes[ph.name]
            lay = _PhaseLayout(ph, mesh)
            colloc_of_state = {s: c for c, s in enumerate(mesh.colloc_state_nodes)}
            xs, us = [None] * lay.ns, [None] * lay.nc
            for k in range(lay.ns):
                xs[k], lay.ix[:, k] = add_var(f"{ph.name}_x{k}", lay.nx)
                c = colloc_of_state.get(k)
                if c is not None and lay.nu:
                    us[c], lay.iu[:, c] = add_var(f"{ph.name}_u{c}", lay.nu)
            X = ca.horzcat(*xs)
            U = ca.horzcat(*us) if lay.nu else S(0, lay.nc)
            if lay.t0_fixed:
                t0 = float(_lohi(ph.t0)[0])
            else:
                t0, idx = add_var(f"{ph.name}_t0", 1)
                lay.it0 = int(idx[0])
            if lay.tf_fixed:
                tf = float(_lohi(ph.tf)[0])
            else:
                tf, idx = add_var(f"{ph.name}_tf", 1)
                lay.itf = int(idx[0])
            sym_X[ph.name], sym_U[ph.name], sym_T[ph.name] = X, U, (t0, tf)
            self.layouts[ph.name] = lay
        self.ip = np.zeros(len(pr.parameters), dtype=int)
        if pr.parameters:
            P, self.ip = add_var("p", len(pr.parameters))
        else:
            P = S(0, 1)
        self._n_w = n_w
        lbw, ubw, w0 = np.concatenate(lbw), np.concatenate(ubw), np.concatenate(w0)

        # NLP parameters: per-node data of all phases.
        d_parts, self._data_slices = [], {}
        n_d = 0
        for ph in pr.phases:
            nd, nc = len(ph.data_names), self.layouts[ph.name].nc
            dvec = S.sym(f"{ph.name}_data", nd * nc)
            d_parts.append(dvec)
            D = ca.reshape(dvec, nd, nc)
            self._data_slices[ph.name] = (n_d, nd, nc)
            n_d += nd * nc
            sym_T[ph.name] = sym_T[ph.name] + (D,)
        Pdata = ca.vertcat(*d_parts) if d_parts else S(0, 1)

        g, lbg, ubg, blocks = [], [], [], []
        n_g = 0

        def add_con(name, expr, lo, hi):
            nonlocal n_g
            expr = _column(expr, name)
            size = expr.numel()
            if size == 0:
                return
            lo = np.broadcast_to(np.asarray(lo, dtype=float), (size,)).copy()
            hi = np.broadcast_to(np.asarray(hi, dtype=float), (size,)).copy()
            g.append(expr)
            lbg.append(lo)
            ubg.append(hi)
            blocks.append(_Block(name, n_g, size))
            n_g += size

        p_named = Named(P, pr.parameter_names, "parameter")
        objective = 0
        goal_exprs, goal_rows = [], []
        n_goals = sum(len(ph.goals) for ph in pr.phases)
        weights = S.sym("weights", n_goals)  # NLP parameters: re-weigh without rebuilding
        self._node_functions = {}
        endpoints = {}
        for ph in pr.phases:
            lay, mesh = self.layouts[ph.name], self.meshes[ph.name]
            X, U = sym_X[ph.name], sym_U[ph.name]
            t0, tf, D = sym_T[ph.name]
            dur = tf - t0
            node = self._node_function(ph, len(pr.parameters))
            self._node_functions[ph.name] = node
            Xc = X[:, list(mesh.colloc_state_nodes)] if mesh.n_colloc_nodes < lay.ns else X
            Tc = t0 + dur * ca.DM(mesh.tau_colloc).T
            if self._by_nodes:  # node outputs as symbols; the nodes are evaluated in _node_derivatives
                sizes = [node.size1_out(i) for i in range(3)]
                Y = S.sym(f"{ph.name}_node_outputs", sum(sizes), lay.nc)
                F, G, L = Y[:sizes[0], :], Y[sizes[0]:sizes[0] + sizes[1], :], Y[sizes[0] + sizes[1]:, :]
                self._node_outputs[ph.name] = ((Xc, U, P, S(Tc), D), Y)
            else:
                F, G, L = node.map(lay.nc)(Xc, U, P, Tc, D)
            # Dynamics defects and path constraints, interval by interval.
            Def = mesh.defects(X, F, dur)
            nd = mesh.interval.n_defects
            owner = mesh.interval_of_colloc
            n_path = node.size1_out(1)
            pc_lo, pc_hi = self._path_bounds(ph)
            for i in range(mesh.n_intervals):
                add_con(f"{ph.name}/defects[{i}]", ca.vec(Def[:, i * nd:(i + 1) * nd]), 0, 0)
                if n_path:
                    for c in np.flatnonzero(owner == i):
                        add_con(f"{ph.name}/path[{c}]", G[:, c], pc_lo, pc_hi)
            C = mesh.hs_midpoint_matrix
            if C is not None and lay.nu:
                add_con(f"{ph.name}/hs_control_midpoints",
                        ca.vec(ca.mtimes(U, ca.sparsify(ca.DM(C.T)))), 0, 0)
            # Bounds on states and controls.
            self._variable_bounds(ph, lay, lbw, ubw, w0)
            # Time.
            if lay.it0 is not None:
                lbw[lay.it0], ubw[lay.it0] = lay.t0_bounds
                w0[lay.it0] = _mid(*lay.t0_bounds)
            if lay.itf is not None:
                lbw[lay.itf], ubw[lay.itf] = lay.tf_bounds
                w0[lay.itf] = _mid(*lay.tf_bounds)
            if ph.duration is not None:
                add_con(f"{ph.name}/duration", dur, *ph.duration)
            elif lay.it0 is not None or lay.itf is not None:
                add_con(f"{ph.name}/duration", dur, 0.0, np.inf)
            # Endpoints.
            x0 = Named(X[:, 0], ph.states, "state", f"phase {ph.name!r}")
            xf = Named(X[:, -1], ph.states, "state", f"phase {ph.name!r}")
            endpoints[ph.name] = (x0, xf, t0, tf)
            for ec in ph.endpoint_constraints:
                add_con(f"{ph.name}/{ec.name}", ec.fun(x0, xf, p_named, t0, tf), ec.lower, ec.upper)
            if ph.periodic is not None:
                offs = [self._offset(ph.periodic.offsets.get(s, 0.0), p_named, t0, tf)
                        for s in ph.periodic.states]
                add_con(f"{ph.name}/periodic",
                        xf[list(ph.periodic.states)] - x0[list(ph.periodic.states)]
                        - ca.vertcat(*offs), 0, 0)
            # Goals.
            integrals = mesh.integrate(L, dur) if L.numel() else None
            k_int = 0
            for gl in ph.goals:
                if gl.integrand is not None:
                    term = integrals[k_int]
                    k_int += 1
                else:
                    term = _column(gl.endpoint(x0, xf, p_named, t0, tf), gl.name)
                    if term.numel() != 1:
                        raise ValueError(f"goal {gl.name!r}: endpoint must return a scalar")
                value = term / gl.normalization
                if gl.divide_by_duration:
                    value = value / dur
                goal_exprs.append(value)
                objective = objective + weights[len(goal_rows)] * value
                goal_rows.append((ph.name, gl.name, float(gl.weight)))

        # Linkages.
        for lk in pr.linkages:
            a, b = pr.phase(lk.before), pr.phase(lk.after)
            states = lk.states if lk.states is not None else [s for s in a.states if s in b.states]
            _, xa_f, _, ta_f = endpoints[a.name]
            xb_0, _, tb_0, _ = endpoints[b.name]
            if states:
                offs = [self._offset(lk.offsets.get(s, 0.0), p_named, tb_0, ta_f) for s in states]
                add_con(f"link {a.name}->{b.name}/states",
                        xb_0[list(states)] - xa_f[list(states)] - ca.vertcat(*offs), 0, 0)
            if lk.time:
                add_con(f"link {a.name}->{b.name}/time", tb_0 - ta_f, 0, 0)

        # Parameter bounds and guesses.
        for j, par in enumerate(pr.parameters):
            lbw[self.ip[j]], ubw[self.ip[j]] = par.lower, par.upper
            w0[self.ip[j]] = par.initial()

        bad = np.flatnonzero(lbw > ubw)
        if bad.size:
            raise ValueError(f"conflicting bounds (lower > upper) on {self._describe_w(bad[0])}")

        self.w = ca.vertcat(*w_parts)
        self.g = ca.vertcat(*g) if g else S(0, 1)
        self.lbw, self.ubw, self.w0_default = lbw, ubw, np.clip(w0, lbw, ubw)
        self.lbg = np.concatenate(lbg) if lbg else np.zeros(0)
        self.ubg = np.concatenate(ubg) if ubg else np.zeros(0)
        self.blocks = blocks
        self.goal_rows = goal_rows
        f = objective if goal_exprs else S(0)
        if not isinstance(f, (ca.SX, ca.MX)):
            f = S(f)
        self.nlp = {"x": self.w, "f": f, "g": self.g, "p": ca.vertcat(Pdata, weights)}
        self._goal_exprs = ca.vertcat(*goal_exprs) if goal_exprs else S(0, 1)
        if not self._by_nodes:  # by nodes: made in _node_derivatives
            self._goal_fun = ca.Function("goals", [self.w, self.nlp["p"]], [self._goal_exprs])
        self._n_pdata = n_d
        self.n_variables, self.n_constraints = n_w, n_g

    def _node_derivatives(self) -> dict:
        """``derivatives="nodes"``: the NLP as an MX graph of one mapped node call per phase,
        with IPOPT's gradient, constraint Jacobian and Lagrangian Hessian assembled from
        per-node derivative functions (the nlpsol options ``grad_f``, ``jac_g``, ``hess_lag``).

        Notation: w the NLP variables, p the NLP parameters (data, goal weights), Y the node
        outputs of all phases (one column of (ẋ, path, integrand) per collocation node), z_c
        = (x_c, u_c, p_static, t_c) node c's differentiated inputs — affine in w (t_c = t0 +
        (tf − t0)·τ_c), so ∂z/∂w = Z is a constant matrix. The outer functions f(w, p, Y),
        g(w, p, Y) (defects, quadrature, endpoints) are small SX graphs. With J = ∂Y/∂w =
        blockdiag(∂Y_c/∂z_c)·Z and Φ = σ·f + λᵀg, μ = ∂Φ/∂Y:

            ∇f = f_w + Jᵀ f_Y,    ∂g/∂w = g_w + g_Y·J,
            ∇²L = Φ_ww + Jᵀ Φ_Yw + Φ_wY J + Jᵀ Φ_YY J + Zᵀ blockdiag(∇²_z (μ_cᵀ Y_c)) Z.

        Terms whose pattern is empty are left out (for fixed phase times every term but the
        last and g_Y·J is zero)."""
        S = ca.SX
        native = compiled.compiled if self.options.compiled else (lambda fun, reverse=False: fun)
        w_sx, p_sx = self.w, self.nlp["p"]
        W, Pm = ca.MX.sym("x", self._n_w), ca.MX.sym("p", p_sx.shape[0])
        sig, lam = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", self.n_constraints)
        nodes, Y_sx, Z_parts = [], [], []
        y_off = z_off = 0
        for ph in self.problem.phases:
            (Xc, U, P, Tc, D), Y = self._node_outputs[ph.name]
            node, nc = self._node_functions[ph.name], self.layouts[ph.name].nc
            x, u, p, t, d = (S.sym(n, node.size1_in(i)) for i, n in enumerate(("x", "u", "p", "t", "d")))
            z = ca.vertcat(x, u, p, t)
            y = ca.vertcat(*node(x, u, p, t, d))
            m = S.sym("m", y.numel())
            n_fg = node.size1_out(0) + node.size1_out(1)
            nd = _NodePhase(nc=nc, nz=z.numel(), ny=y.numel(), y_off=y_off, z_off=z_off,
                            inputs=ca.Function(f"{ph.name}_node_inputs", [w_sx, p_sx], [Xc, U, P, Tc, D]),
                            hess=native(ca.Function(f"{ph.name}_node_hess", [x, u, p, t, d, m],
                                                    [ca.hessian(ca.dot(m, y), z)[0]])).map(nc))
            # the constraints' rows (ẋ, path) and the objective's (integrands) separately, so
            # that IPOPT's f and g (and their derivatives) evaluate only what each uses
            nd.rows.update({"all": slice(0, nd.ny), "fg": slice(0, n_fg), "l": slice(n_fg, nd.ny)})
            # made when first used (a compiled function is compiled only if the NLP uses it);
            # nlpsol differentiates f and g once at set-up (its nlp_grad), so the values
            # carry their reverse derivative
            nd.values = _Lazy(lambda part, ph=ph, y=y, nd=nd, args=(x, u, p, t, d): native(
                ca.Function(f"{ph.name}_node_{part}", list(args), [y[nd.rows[part]]]), reverse=True).map(nd.nc))
            nd.jacobians = _Lazy(lambda part, ph=ph, y=y, z=z, nd=nd, args=(x, u, p, t, d): native(
                ca.Function(f"{ph.name}_node_jac_{part}", list(args),
                            [y[nd.rows[part]], ca.jacobian(y[nd.rows[part]], z)])).map(nd.nc))
            Zw = ca.jacobian(ca.vec(ca.vertcat(Xc, U, ca.repmat(P, 1, nc), Tc)), w_sx)
            if ca.depends_on(Zw, ca.vertcat(w_sx, p_sx)):
                raise AssertionError(f"phase {ph.name!r}: node inputs are not affine in the variables")
            Z_parts.append(ca.DM(ca.evalf(Zw)))
            Y_sx.append(ca.vec(Y))
            nodes.append(nd)
            y_off += nd.ny * nc
            z_off += nd.nz * nc
        n_y = y_off
        Yv = ca.vertcat(*Y_sx)
        Z = ca.vertcat(*Z_parts)  # node inputs of all phases stacked: (Σ n_z·n_c) × n_w

        def place(nd, part, yv):
            """A part's rows of one phase's node outputs, as that phase's slice of Y (MX)."""
            if part == "all":
                return ca.vec(yv)
            v = ca.MX(nd.ny, nd.nc)
            v[nd.rows[part], :] = yv
            return ca.vec(v)

        def values(Wx, Px, part="all"):
            """Node outputs Y at all nodes of all phases (MX); only the rows of ``part``
            ("all"; "fg": ẋ and path; "l": integrands) are computed, the others are zero."""
            return ca.vertcat(*[place(nd, part, nd.values[part](*nd.inputs(Wx, Px))) for nd in nodes])

        def values_and_jacobian(Wx, Px, part="all"):
            """Y (the rows of ``part`` computed, the others zero) and the block-diagonal ∂Y/∂z
            of ``part``'s rows at all nodes of all phases (MX)."""
            ys, js = [], []
            for nd in nodes:
                yv, jv = nd.jacobians[part](*nd.inputs(Wx, Px))
                ys.append(place(nd, part, yv))
                js.extend(ca.horzsplit(jv, nd.nz))
            return ca.vertcat(*ys), ca.diagcat(*js)

        def rows(part):
            """The elements of the symbols Yv that ``part`` computes."""
            idx = []
            for nd in nodes:
                r = np.arange(nd.ny)[nd.rows[part]]
                idx.extend(int(i) for c in range(nd.nc) for i in nd.y_off + c * nd.ny + r)
            return Yv[idx]

        f_sx, g_sx, goals_sx = self.nlp["f"], self.g, self._goal_exprs
        outer = ca.Function("outer", [w_sx, p_sx, Yv], [f_sx, g_sx, goals_sx])
        Ym = values(W, Pm)
        f_mx = outer(W, Pm, Ym if ca.depends_on(f_sx, rows("fg")) else values(W, Pm, "l"))[0]
        g_mx = outer(W, Pm, Ym if ca.depends_on(g_sx, rows("l")) else values(W, Pm, "fg"))[1]
        goals_mx = outer(W, Pm, Ym)[2]
        self.w, self.g = W, g_mx
        self.nlp = {"x": W, "f": f_mx, "g": g_mx, "p": Pm}
        self._goal_fun = ca.Function("goals", [W, Pm], [goals_mx])

        def nz(e):
            return e.nnz() > 0

        # Where each per-node derivative's non-zeros sit: node c of a phase differentiates
        # with respect to the rows z_off + c·n_z + (0 … n_z−1) of Z, and its outputs are the
        # rows y_off + c·n_y + (0 … n_y−1) of Y (restricted to a part's rows for f and g).
        Zs = ca.sparsify(Z)
        Zcsr = _csr(Z)

        def nonzeros(mx):
            return ca.sparsity_cast(mx, ca.Sparsity.dense(mx.nnz(), 1))

        def first_order(expr, part, fun_name, out_names):
            """(expr, ∂expr/∂w) as an MX Function of (x, p), with ``part``'s rows of Y:
            ∂expr/∂w = e_w + e_Y·blockdiag(∂Y_c/∂z_c)·Z."""
            Yp = rows(part)
            e_w, e_Y = ca.jacobian(expr, w_sx), ca.jacobian(expr, Yp)
            d_outer = ca.Function("outer_" + fun_name, [w_sx, p_sx, Yv], [expr, e_w, e_Y])
            ys, jvals, r_y, r_z = [], [], [], []
            y_part = 0
            for nd in nodes:
                yv, jv = nd.jacobians[part](*nd.inputs(W, Pm))
                n_part = len(range(nd.ny)[nd.rows[part]])
                ys.append(place(nd, part, yv))
                jvals.append(nonzeros(jv))
                rr, cc = (np.asarray(a) for a in nd.jacobians[part].sparsity_out(1).get_triplet())  # n_part × (n_z·n_c)
                r_y.append(y_part + (cc // nd.nz) * n_part + rr)
                r_z.append(nd.z_off + cc)
                y_part += n_part * nd.nc
            e, ew, eY = d_outer(W, Pm, ca.vertcat(*ys))
            d = ew
            if nz(e_Y):
                jb = ca.vertcat(*jvals)
                if not ca.depends_on(e_Y, ca.vertcat(w_sx, p_sx, Yv)):  # constant: one sparse product
                    M, pattern = _bilinear_map(_csr(e_Y.T), np.concatenate(r_y), Zcsr, np.concatenate(r_z),
                                               (e_Y.shape[0], self._n_w))
                    d = ew + ca.sparsity_cast(ca.mtimes(M, jb), pattern)
                else:
                    M, pattern = _bilinear_map(sp.identity(y_part, format="csr"), np.concatenate(r_y), Zcsr,
                                               np.concatenate(r_z), (y_part, self._n_w))
                    d = ew + ca.mtimes(eY, ca.sparsity_cast(ca.mtimes(M, jb), pattern))
            if fun_name == "grad_f":  # a dense column, as CasADi's own
                d = ca.densify(d.T)
            return ca.Function("nlp_" + fun_name, [W, Pm], [e, d], ["x", "p"], out_names)

        grad_f = first_order(f_sx, "all" if ca.depends_on(f_sx, rows("fg")) else "l", "grad_f", ["f", "grad_f_x"])
        jac_g = first_order(g_sx, "all" if ca.depends_on(g_sx, rows("l")) else "fg", "jac_g", ["g", "jac_g_x"])

        # Hessian of the Lagrangian.
        sig_s, lam_s = S.sym("sigma"), S.sym("lambda", self.n_constraints)
        phi = sig_s * f_sx + ca.dot(lam_s, g_sx)
        phi_Y = ca.gradient(phi, Yv)
        phi_ww = ca.hessian(phi, w_sx)[0]
        phi_Yw, phi_YY = ca.jacobian(phi_Y, w_sx), ca.jacobian(phi_Y, Yv)
        d2_outer = ca.Function("outer_second", [w_sx, p_sx, Yv, sig_s, lam_s], [phi_Y, phi_ww, phi_Yw, phi_YY])
        need_y = any(ca.depends_on(nonzeros(e), Yv) for e in (phi_Y, phi_ww, phi_Yw, phi_YY))
        need_j = nz(phi_Yw) or nz(phi_YY)
        Yh, Jh = ca.MX.zeros(n_y), None
        if need_j:
            Yh, Jh = values_and_jacobian(W, Pm, "all")
        elif need_y:
            Yh = values(W, Pm)
        mu, Hww, HYw, HYY = d2_outer(W, Pm, Yh, sig, lam)
        hvals, r_a, r_b = [], [], []
        for nd in nodes:
            mu_c = ca.reshape(mu[nd.y_off:nd.y_off + nd.ny * nd.nc], nd.ny, nd.nc)
            hvals.append(nonzeros(nd.hess(*nd.inputs(W, Pm), mu_c)))
            rr, cc = (np.asarray(v) for v in nd.hess.sparsity_out(0).get_triplet())  # n_z × (n_z·n_c)
            r_a.append(nd.z_off + (cc // nd.nz) * nd.nz + rr)
            r_b.append(nd.z_off + cc)
        M, pattern = _bilinear_map(Zcsr, np.concatenate(r_a), Zcsr, np.concatenate(r_b),
                                   (self._n_w, self._n_w), triu=True)
        H = ca.sparsity_cast(ca.mtimes(M, ca.vertcat(*hvals)), pattern)  # triu(Zᵀ·blockdiag(H_c)·Z)
        extra = None
        if nz(phi_ww):
            extra = Hww
        if need_j:
            JYh = ca.mtimes(Jh, Zs)
            if nz(phi_Yw):
                cross = ca.mtimes(JYh.T, HYw)
                extra = cross + cross.T if extra is None else extra + cross + cross.T
            if nz(phi_YY):
                quad = ca.mtimes([JYh.T, HYY, JYh])
                extra = quad if extra is None else extra + quad
        if extra is not None:
            H = H + ca.triu(extra)
        hess = ca.Function("nlp_hess_l", [W, Pm, sig, lam], [H],
                           ["x", "p", "lam_f", "lam_g"], ["triu_hess_gamma_x_x"])
        return {"grad_f": grad_f, "jac_g": jac_g, "hess_lag": hess}

    def _describe_w(self, j: int) -> str:
        """Name of NLP variable ``j`` (for error messages)."""
        for name, lay in self.layouts.items():
            for arr, names in ((lay.ix, lay.phase.states), (lay.iu, lay.phase.controls)):
                hit = np.argwhere(arr == j)
                if hit.size:
                    i, k = hit[0]
                    return f"{names[i]!r} at node {k} of phase {name!r}"
        return f"variable {j}"

    def _node_function(self, ph: Phase, n_p: int) -> ca.Function:
        """Per-node SX function node(x, u, p, t, d) → (ẋ, path g, integrands)."""
        x = ca.SX.sym("x", len(ph.states))
        u = ca.SX.sym("u", len(ph.controls))
        p = ca.SX.sym("p", n_p)
        t = ca.SX.sym("t")
        d = ca.SX.sym("d", len(ph.data_names))
        xn = Named(x, ph.states, "state", f"phase {ph.name!r}")
        un = Named(u, ph.controls, "control", f"phase {ph.name!r}")
        pn = Named(p, self.problem.parameter_names, "parameter")
        dn = Named(d, ph.data_names, "data channel", f"phase {ph.name!r}")

        def call(fun, what):
            if isinstance(fun, ca.Function):
                args = [x, u, p, t, d][: fun.n_in()]
                out = fun(*args)
                return _column(out[0] if isinstance(out, (list, tuple)) else out, what)
            if _accepts_data(fun):
                return _column(fun(xn, un, pn, t, dn), what)
            return _column(fun(xn, un, pn, t), what)

        f = call(ph.dynamics, f"phase {ph.name!r} dynamics")
        if f.numel() != len(ph.states):
            raise ValueError(
                f"phase {ph.name!r}: dynamics returned {f.numel()} values for "
                f"{len(ph.states)} states"
            )
        gs = [call(pc.fun, f"path constraint {pc.name!r}") for pc in ph.path_constraints]
        self._path_sizes[ph.name] = [gi.numel() for gi in gs]
        ls = []
        for gl in ph.goals:
            if gl.integrand is not None:
                li = call(gl.integrand, f"goal {gl.name!r}")
                if li.numel() != 1:
                    raise ValueError(f"goal {gl.name!r}: integrand must return a scalar")
                ls.append(li)
        return ca.Function(
            f"{ph.name}_node",
            [x, u, p, t, d],
            [f, ca.vertcat(*gs) if gs else ca.SX(0, 1), ca.vertcat(*ls) if ls else ca.SX(0, 1)],
            ["x", "u", "p", "t", "d"],
            ["xdot", "path", "integrand"],
        )

    def _path_bounds(self, ph: Phase):
        lo, hi = [], []
        for pc, size in zip(ph.path_constraints, self._path_sizes[ph.name]):
            lo.append(np.broadcast_to(np.asarray(pc.lower, float), (size,)))
            hi.append(np.broadcast_to(np.asarray(pc.upper, float), (size,)))
        if not lo:
            return np.zeros(0), np.zeros(0)
        return np.concatenate(lo), np.concatenate(hi)

    @staticmethod
    def _offset(off, p_named, t0, tf):
        return off(p_named, t0, tf) if callable(off) else off

    @staticmethod
    def _variable_bounds(ph: Phase, lay: _PhaseLayout, lbw, ubw, w0):
        def per_node(val, n, name):
            arr = np.asarray(val, dtype=float)
            if arr.ndim == 0:
                return np.full(n, float(arr))
            if arr.shape != (n,):
                raise ValueError(
                    f"phase {ph.name!r}: bound of {name!r} has shape {arr.shape}, "
                    f"expected a scalar or ({n},) (one value per node)"
                )
            return arr

        for name, b in ph.bounds.items():
            lo, hi = _lohi(b)
            if name in ph.states:
                idx, n = lay.ix[ph.states.index(name)], lay.ns
            else:
                idx, n = lay.iu[ph.controls.index(name)], lay.nc
            lbw[idx] = np.maximum(lbw[idx], per_node(lo, n, name))
            ubw[idx] = np.minimum(ubw[idx], per_node(hi, n, name))
        for col, spec in ((0, ph.initial), (-1, ph.final)):
            for name, b in spec.items():
                lo, hi = _lohi(b)
                j = lay.ix[ph.states.index(name), col]
                lbw[j], ubw[j] = max(lbw[j], float(lo)), min(ubw[j], float(hi))
        # Default guess: fixed initial/final values interpolated linearly, else mid-bounds.
        for i, name in enumerate(ph.states):
            idx = lay.ix[i]
            guess = np.array([_mid(lo, hi) for lo, hi in zip(lbw[idx], ubw[idx])])
            a, b = _lohi(ph.initial.get(name, np.nan)), _lohi(ph.final.get(name, np.nan))
            if np.isfinite(a[0]) and a[0] == a[1] and np.isfinite(b[0]) and b[0] == b[1]:
                guess = a[0] + (b[0] - a[0]) * lay.mesh.tau
            w0[idx] = guess
        for i in range(lay.nu):
            idx = lay.iu[i]
            w0[idx] = [_mid(lo, hi) for lo, hi in zip(lbw[idx], ubw[idx])]

    # -- guesses and data -----------------------------------------------------------
    def initial_point(self, guess: "Guess | Solution | None" = None) -> np.ndarray:
        """The NLP starting point for ``guess`` (defaults where the guess is silent)."""
        w0 = self.w0_default.copy()
        if guess is None:
            return w0
        if isinstance(guess, Solution):
            guess = Guess.from_solution(guess)
        for pname, pg in guess.phases.items():
            ph = self.problem.phase(pname)
            lay, mesh = self.layouts[pname], self.meshes[pname]
            times = []
            for obj in (pg.states, pg.controls):
                if obj is None:
                    continue
                if isinstance(obj, pd.DataFrame) and pg.time is None:
                    times.append(np.asarray(obj.index, dtype=float))
            tgrid = np.asarray(pg.time, float) if pg.time is not None else None
            ref = tgrid if tgrid is not None else (times[0] if times else None)
            g_t0 = pg.t0 if pg.t0 is not None else (ref[0] if ref is not None else None)
            g_tf = pg.tf if pg.tf is not None else (ref[-1] if ref is not None else None)
            if lay.it0 is not None and g_t0 is not None:
                w0[lay.it0] = g_t0
            if lay.itf is not None and g_tf is not None:
                w0[lay.itf] = g_tf
            for obj, names, tau_nodes, index, kind in (
                (pg.states, ph.states, mesh.tau, lay.ix, "state"),
                (pg.controls, ph.controls, mesh.tau_colloc, lay.iu, "control"),
            ):
                if obj is None:
                    continue
                keys = list(obj.columns) if isinstance(obj, pd.DataFrame) else list(obj)
                for name in keys:
                    if name not in names:
                        raise KeyError(f"guess for unknown {kind} {name!r} of phase {pname!r}")
                    t, v = _series(obj, name, pg.time)
                    a = t[0] if g_t0 is None else g_t0
                    b = t[-1] if g_tf is None else g_tf
                    tau = (t - a) / (b - a) if b > a else np.zeros_like(t)
                    w0[index[names.index(name)]] = np.interp(tau_nodes, tau, v)
        for name, val in guess.parameters.items():
            if name not in self.problem.parameter_names:
                raise KeyError(f"guess for unknown parameter {name!r}")
            w0[self.ip[self.problem.parameter_names.index(name)]] = val
        return w0

    def data_vector(self, data: Mapping[str, pd.DataFrame] | None = None) -> np.ndarray:
        """NLP parameter vector: each phase's data interpolated to its collocation nodes."""
        out = np.zeros(self._n_pdata)
        for ph in self.problem.phases:
            start, nd, nc = self._data_slices[ph.name]
            frame = (data or {}).get(ph.name, ph.data)
            if nd == 0:
                continue
            if frame is None or list(map(str, frame.columns)) != list(ph.data_names):
                raise ValueError(f"phase {ph.name!r}: data must have columns {ph.data_names}")
            tau = np.asarray(frame.index, dtype=float)
            vals = np.stack(
                [np.interp(self.meshes[ph.name].tau_colloc, tau, frame[c].to_numpy(float))
                 for c in frame.columns]
            )  # (nd, nc)
            out[start:start + nd * nc] = vals.ravel(order="F")
        return out

    # -- solving --------------------------------------------------------------------
    def goal_weights(self, weights: Mapping[str, float] | None = None) -> np.ndarray:
        """Goal weights in NLP order: the goals' own, overridden by name (all phases)."""
        known = {name for _, name, _ in self.goal_rows}
        for name in weights or {}:
            if name not in known:
                raise KeyError(f"weight for unknown goal {name!r}; known: {sorted(known)}")
        return np.array([float((weights or {}).get(name, wt)) for _, name, wt in self.goal_rows])

    def solve(self, guess: "Guess | Solution | None" = None,
              data: Mapping[str, pd.DataFrame] | None = None,
              weights: Mapping[str, float] | None = None) -> Solution:
        """Run IPOPT from ``guess`` and return a :class:`Solution` (failed ones included).

        ``data`` replaces phases' per-node data and ``weights`` goals' weights (by goal
        name) for this solve only: both are NLP parameters, so nothing is rebuilt.
        """
        w0 = np.clip(self.initial_point(guess), self.lbw, self.ubw)
        wts = self.goal_weights(weights)
        pvec = np.concatenate([self.data_vector(data), wts])
        t_start = time.perf_counter()
        res = self.solver(x0=w0, lbx=self.lbw, ubx=self.ubw, lbg=self.lbg, ubg=self.ubg, p=pvec)
        solve_time = time.perf_counter() - t_start
        stats = self.solver.stats()
        w = np.asarray(res["x"]).ravel()
        gval = np.asarray(res["g"]).ravel()
        viol_g = np.maximum(np.maximum(self.lbg - gval, gval - self.ubg), 0.0)
        viol_w = np.maximum(np.maximum(self.lbw - w, w - self.ubw), 0.0)
        max_v, worst = 0.0, ""
        for blk in self.blocks:
            v = float(viol_g[blk.start:blk.start + blk.size].max(initial=0.0))
            if v > max_v:
                max_v, worst = v, blk.name
        if viol_w.size and viol_w.max() > max_v:
            max_v, worst = float(viol_w.max()), "variable bounds"

        phases = {}
        for ph in self.problem.phases:
            lay, mesh = self.layouts[ph.name], self.meshes[ph.name]
            t0 = w[lay.it0] if lay.it0 is not None else float(_lohi(ph.t0)[0])
            tf = w[lay.itf] if lay.itf is not None else float(_lohi(ph.tf)[0])
            ts = pd.Index(t0 + (tf - t0) * mesh.tau, name="time")
            tc = pd.Index(t0 + (tf - t0) * mesh.tau_colloc, name="time")
            states = pd.DataFrame(w[lay.ix].T, index=ts, columns=list(ph.states))
            controls = pd.DataFrame(w[lay.iu].T if lay.nu else np.zeros((lay.nc, 0)),
                                    index=tc, columns=list(ph.controls))
            phases[ph.name] = PhaseSolution(ph.name, states, controls, float(t0), float(tf))
        params = {n: float(w[self.ip[j]]) for j, n in enumerate(self.problem.parameter_names)}
        gvals = np.asarray(self._goal_fun(w, pvec)).ravel()
        goals = pd.DataFrame(
            [(ph, name, wt, float(v), wt * float(v))
             for (ph, name, _), wt, v in zip(self.goal_rows, wts, gvals)],
            columns=["phase", "goal", "weight", "value", "weighted"],
        )
        iterations = int(stats.get("iter_count", 0))
        info = {
            "n_variables": self.n_variables,
            "n_constraints": self.n_constraints,
            "meshes": {k: m.describe() for k, m in self.meshes.items()},
            "options": {k: v for k, v in self.options.nlpsol_options()["ipopt"].items()},
            "graph": self.options.graph,
            "derivatives": "nodes" if self._by_nodes else "graph",
            "compiled": bool(self._by_nodes and self.options.compiled),
            "symbolic_time": self.symbolic_time,
            "solver_reused": bool(self.reused),
            "ipopt_t_wall": {k: float(v) for k, v in stats.items()
                             if k.startswith("t_wall_") and isinstance(v, (int, float))},
            "n_call_nlp_hess_l": int(stats.get("n_call_nlp_hess_l", 0)),
        }
        return Solution(
            phases=phases,
            parameters=params,
            goals=goals,
            objective=float(res["f"]),
            status=str(stats.get("return_status", "unknown")),
            success=bool(stats.get("success", False)),
            iterations=iterations,
            solve_time=solve_time,
            build_time=self.build_time,
            max_violation=max_v,
            worst_constraint=worst,
            info=info,
        )


def transcribe(problem: Problem, mesh: Mesh | Mapping[str, Mesh],
               options: SolverOptions | None = None) -> Transcription:
    """Build the NLP and IPOPT solver of ``problem`` on ``mesh`` (one Mesh or one per phase)."""
    return Transcription(problem, mesh, options or SolverOptions())


def solve(problem: Problem, mesh: Mesh | Mapping[str, Mesh],
          options: SolverOptions | None = None,
          guess: Guess | Solution | None = None) -> Solution:
    """Transcribe ``problem`` on ``mesh`` and solve it with IPOPT.

    A failed solve returns a :class:`Solution` with ``success=False`` and IPOPT's status
    (and issues :class:`SolveFailedWarning`); call :meth:`Solution.require_success` where
    failure must stop the caller.
    """
    return transcribe(problem, mesh, options).solve(guess)
