"""MTG parameter identification for the child (thesis Sec 5.1.1, Eqs 5.11–5.23, Table 5.2).

The 42 fitting parameters Γ = {s^τ, s^A, λ^A, s^V, λ^V, Δ^P, λ^P} (Eq 5.9) of the six
right-leg generators (hip, knee, ankle × extensor, flexor; the left leg uses the same
values, Sec 5.1.1) are identified by a direct-collocation optimal control problem on the
joint motion of our Free-speed data, as the thesis does on its child data:

states    x = [θ, θ̇] of the right hip, knee and ankle (Eq 5.11), 6
controls  u = θ̈ (Eq 5.12), 3;      dynamics ẋ = [θ̇, u] (Eq 5.14)
parameters Γ (42), bounds Table 5.1, initial values Eq 5.22 (the adult Gymnast curves)
path constraints at every collocation node, for each generator g (Eqs 5.15–5.17)::

    τ^M_g(a = 1, θ, θ̇, Γ_g) − τ^M_exp,g(t) ≥ 0           (5.15: strong enough)
    τ^M_exp,g(t) − τ^M_g(a = 0, θ, θ̇, Γ_g) ≥ 0           (5.16: passive not too strong)
    t^P_max − t^P(θ, Δ^P, λ^P) ≥ 0,   t^P_max = 1.4        (5.17)

with τ^M_exp,g the flexor/extensor share of the demanded joint torque (Eqs 5.18–5.20, in
the model's sign convention: :func:`split` — the generator whose torque is positive in the
model's convention takes max(τ, 0), the other max(−τ, 0));
cost (Eq 5.23)::

    J = w1 Σ_42 ((Γ − Γ_initial)/(Γ_max − Γ_min))² + w2 ∫ Σ_6 ((x − x_exp)/(x_max − x_min))² dt

w1 = 0.001, w2 = 1. Mesh 20 intervals × 5 LGR points (the thesis's 100 collocation points),
exact Hessian from CasADi's AD (the thesis: first derivative mode).

Tolerance. The objective is tiny (≈ 1e-5: w1 = 0.001 times squared deviations normalised
by the wide Table 5.1 ranges; the angles are tracked almost exactly), while the 1,800
inequality constraints are in N·m. At the thesis's IPOPT tolerance 1e-5, IPOPT stops
while its log-barrier terms −μ Σ log(g) still outweigh the objective's gradient: the
barrier pushes every generator away from its constraints (s^τ, s^A, s^V grow for all six,
λ's leave their lower bounds), and the returned point's Eq 5.23 cost is ≈ 25× the
optimum's. Our default is therefore ``tol=1e-10``, which resolves the optimum of Eq 5.23
(parameters of generators whose constraints are inactive stay at Γ_initial to ~1e-4);
``IdentSpec(tol=1e-5)`` reproduces the thesis's setting, and the book shows both.

Demanded torque. The model's joints carry passive spring–dampers (thesis Table 4.2,
:meth:`gaitlib.model.ChildModel.function` ``"passive"``) in parallel with the MTGs, and the
MSK/NMSK problems track the *net* joint torque (MTGs + spring–damper,
:mod:`gaitlib.problems.gait`). What the MTG pair must supply is therefore the data's net
torque minus the spring–damper torque, evaluated on the tracked motion:
``demand="actuator"`` (default). ``demand="net"`` uses the data's net torque as the
thesis's text literally reads (its model has the same spring–dampers, so this leaves the
generators short wherever the damper works against the motion — at push-off the ankle
damper alone is ≈ 20 N·m). The hip angle is the tracked one (the thigh in the
laboratory: data hip + pelvic tilt, :func:`gaitlib.problems.gait.reference`), the angle the
MSK model's hip generators see.

Result and file. :func:`identify` returns an :class:`MTGIdentification` (identified
table beside Table 5.2, IPOPT stats, constraint margins, tracking RMSE, the feasibility
curves of Figs 5.1–5.2); :func:`save_params` writes ``data/identified/ch5_mtg.json``
(parameters by generator + provenance: spec, gaitlib version, status, iterations), which
``GaitSpec(mtg_params="ch5")`` loads (:func:`gaitlib.problems.gait.mtg_params_of`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import casadi as ca
import numpy as np
import pandas as pd

from .. import conventions as cv
from .. import data as data_mod
from .. import mtg
from .. import ocp
from . import gait as gait_ocp
from ..collocation import Mesh
from ..model import ChildModel
from .. import params as params_mod

__all__ = ["IdentSpec", "MTGIdentification", "chapter_spec", "GAMMA", "W1", "W2", "THESIS_RMSE_DEG", "PARAMS_FILE",
           "split", "demanded_torques", "build", "identify"]

#: Fitting-parameter names in the order of Eq 5.9 (and of Table 5.2's columns).
GAMMA = mtg.MTGParams._fields
#: Weights of Eq 5.23.
W1, W2 = 1e-3, 1.0
#: Thesis Sec 5.1.2: tracking RMSE of the identification (hip, knee, ankle), deg.
THESIS_RMSE_DEG = {"hip": 0.46, "knee": 0.81, "ankle": 0.45}
#: Where the identified set lives (read by ``GaitSpec(mtg_params="ch5")``).
PARAMS_FILE = Path(data_mod.DATA_DIR) / "identified" / "ch5_mtg.json"
_JOINTS = ("hip", "knee", "ankle")


@dataclass(frozen=True)
class IdentSpec:
    """What to identify (defaults: the thesis's Sec 5.1.1 set-up on our Free data).

    Parameters
    ----------
    speed_class, source : the data (:func:`gaitlib.data.load_gait_data`).
    side : the leg whose motion and torques are fitted (thesis: right, ``"r"``).
    n_intervals, degree : LGR mesh (thesis: 20 × 5 = 100 collocation points).
    tol, max_iter : IPOPT; default tol 1e-10 (the thesis: 1e-5; module docstring).
    w1, w2 : weights of Eq 5.23 (thesis: 0.001, 1).
    demand : ``"actuator"`` (net data torque − joint spring–damper; module docstring) or
        ``"net"`` (the data's net torque).
    body_params : the body parameter set whose joint spring–dampers define the actuator
        demand (see :class:`~gaitlib.problems.gait.GaitSpec`). Default ``"thesis"`` (Tables
        4.15–4.16: the thesis built Ch 5 on its Ch 4 identified body, whose knee and ankle
        dampers are ≈ 0); :func:`chapter_spec` uses ``"ch4"`` (ours) when that file exists.
    """

    speed_class: str = "Free"
    source: str = "schwartz2008"
    side: str = "r"
    n_intervals: int = 20
    degree: int = 5
    tol: float = 1e-10
    max_iter: int = 3000
    w1: float = W1
    w2: float = W2
    demand: str = "actuator"
    body_params: str = "thesis"

    def __post_init__(self):
        if self.demand not in ("actuator", "net"):
            raise ValueError(f"demand must be 'actuator' or 'net', got {self.demand!r}")
        if self.side not in cv.SIDES:
            raise ValueError(f"side must be one of {cv.SIDES}, got {self.side!r}")


def chapter_spec(**kw) -> IdentSpec:
    """The book's identification spec: the defaults, with the body parameters the Ch 5 gait
    solves use — ours from Ch 4 (``"ch4"``, ``data/identified/ch4_child.json``) if that file
    exists, else the thesis's identified ones (``"thesis"``). ``kw`` override fields."""
    body = "ch4" if params_mod.identified_path("ch4_child").is_file() else "thesis"
    return IdentSpec(**{"body_params": body, **kw})


def split(joint: str, tau):
    """Eqs 5.18–5.19 in the model's convention: the joint torque τ (N·m; numpy or CasADi)
    → ``{generator: share ≥ 0}`` for the joint's two generators, with
    share_pos − share_neg = τ exactly (Eq 5.20) and share_pos · share_neg = 0 (no
    co-contraction). The generator whose torque is positive in the model's convention
    (hip flexor, knee extensor, ankle flexor) takes max(τ, 0)."""
    pos = mtg._positive_generator(joint)
    j = mtg._joint_key(joint)
    neg = f"{j}_ext" if pos.endswith("_flex") else f"{j}_flex"
    if isinstance(tau, (ca.SX, ca.MX, ca.DM)):
        return {pos: ca.fmax(tau, 0.0), neg: ca.fmax(-tau, 0.0)}
    t = np.asarray(tau, float)
    return {pos: np.maximum(t, 0.0), neg: np.maximum(-t, 0.0)}


def _body_params(model: ChildModel, name: str) -> np.ndarray:
    return np.asarray(params_mod.body_params(name, model), float)


def demanded_torques(spec: IdentSpec = IdentSpec(), n: int = 401) -> pd.DataFrame:
    """The tracked motion and the torque the MTGs must supply, on ``n`` points over one
    cycle (index: time, s).

    Columns: ``q_<joint>`` (rad; hip = thigh in the laboratory), ``qd_<joint>`` (rad/s),
    ``tau_net_<joint>`` (the data's net torque, N·m, model convention),
    ``tau_passive_<joint>`` (the joint spring–damper on the motion, N·m) and ``tau_<joint>``
    (the demand: net − passive, or net with ``demand="net"``).
    """
    model = ChildModel()
    gait = data_mod.load_gait_data(spec.speed_class, spec.source)
    ref = gait_ocp.reference(gait, model)
    T = gait.cycle_time
    t = np.linspace(0.0, T, n)
    Q = np.array([ref.deriv[c](t)[0] for c in cv.COORDS])
    QD = np.array([ref.deriv[c](t)[1] for c in cv.COORDS])
    pb = _body_params(model, spec.body_params)
    pas = np.asarray(model.function("passive").map(n)(Q, QD, np.tile(pb[:, None], n)))
    out = {}
    for j in _JOINTS:
        c = f"{j}_{spec.side}"
        i = cv.COORDS.index(c)
        out[f"q_{j}"] = Q[i]
        out[f"qd_{j}"] = QD[i]
        out[f"tau_net_{j}"] = np.interp(t, gait.time, gait.mean[f"tau_{c}"])
        out[f"tau_passive_{j}"] = pas[cv.JOINTS.index(c)]
        out[f"tau_{j}"] = out[f"tau_net_{j}"] - (out[f"tau_passive_{j}"] if spec.demand == "actuator" else 0.0)
    return pd.DataFrame(out, index=pd.Index(t, name="time"))


def _pname(g: str, k: str) -> str:
    return f"{g}.{k}"


def _params_named(p) -> dict[str, mtg.MTGParams]:
    return {g: mtg.MTGParams(*[p[_pname(g, k)] for k in GAMMA]) for g in mtg.GENERATORS}


def _constraints(joint: str, q, qd, tau_demand, params: dict, cas: bool):
    """Eqs 5.15, 5.16, 5.17 for both generators of ``joint``: dict name → expression."""
    shares = split(joint, tau_demand)
    out = {}
    for g in (f"{joint}_ext", f"{joint}_flex"):
        th, om = mtg.fibre_kinematics(g, q, qd)
        # one evaluation of the curves: τ^M(a) = a · active(a = 1) + passive (Eq 5.8)
        _, comp = mtg.generator_torque(g, th, om, 1.0, params, components=True)
        out[f"{g}.5.15"] = comp["active"] + comp["passive"] - shares[g]  # τ^M(a_max = 1) − share
        out[f"{g}.5.16"] = shares[g] - comp["passive"]  # share − τ^M(a_min = 0)
        out[f"{g}.5.17"] = mtg.TP_MAX - comp["tP"]
    return out


def build(spec: IdentSpec = IdentSpec()):
    """The identification as an :class:`gaitlib.ocp.Problem`; returns (problem, mesh,
    options, guess, reference frame, ranges)."""
    dem = demanded_torques(spec)
    t = dem.index.to_numpy()
    T = float(t[-1])
    states = tuple(f"q_{j}" for j in _JOINTS) + tuple(f"qd_{j}" for j in _JOINTS)
    controls = tuple(f"qdd_{j}" for j in _JOINTS)
    ranges = {c: float(np.ptp(dem[c])) for c in states}
    data = pd.DataFrame({**{f"ref_{c}": dem[c].to_numpy() for c in states},
                         **{f"tau_{j}": dem[f"tau_{j}"].to_numpy() for j in _JOINTS}}, index=t / T)

    params = []
    for g in mtg.GENERATORS:
        p0 = mtg.DEFAULT_PARAMS
        for k in GAMMA:
            lo, hi = mtg.PARAM_BOUNDS[k]
            params.append(ocp.Parameter(_pname(g, k), float(lo), float(hi), float(getattr(p0, k))))

    def dynamics(x, u, p, t_):
        return ca.vertcat(*[x[f"qd_{j}"] for j in _JOINTS], *[u[f"qdd_{j}"] for j in _JOINTS])

    def path_fun(x, u, p, t_, d):
        P = _params_named(p)
        rows = []
        for j in _JOINTS:
            c = _constraints(j, x[f"q_{j}"], x[f"qd_{j}"], d[f"tau_{j}"], P, True)
            rows += list(c.values())
        return ca.vertcat(*rows)

    def tracking(x, u, p, t_, d):
        return sum(((x[c] - d[f"ref_{c}"]) / ranges[c]) ** 2 for c in states)

    g0 = {(g, k): float(getattr(mtg.DEFAULT_PARAMS, k)) for g in mtg.GENERATORS for k in GAMMA}
    rng = {k: float(mtg.PARAM_BOUNDS[k][1] - mtg.PARAM_BOUNDS[k][0]) for k in GAMMA}

    def param_term(x0, xf, p, t0, tf):
        return sum(((p[_pname(g, k)] - g0[(g, k)]) / rng[k]) ** 2 for g in mtg.GENERATORS for k in GAMMA)

    # state bounds from the data ("considering the experimental data", Sec 5.1.1)
    bounds = {}
    for c in states:
        lo, hi = float(dem[c].min()), float(dem[c].max())
        pad = 0.25 * (hi - lo)
        bounds[c] = (lo - pad, hi + pad)
    for j in _JOINTS:
        bounds[f"qdd_{j}"] = (-500.0, 500.0)
    phase = ocp.Phase(
        name="cycle", states=states, controls=controls, dynamics=dynamics, t0=0.0, tf=T, bounds=bounds,
        path_constraints=(ocp.PathConstraint("Eqs5.15-5.17", path_fun, 0.0, np.inf),),
        goals=(ocp.Goal("Gamma", weight=spec.w1, endpoint=param_term),
               ocp.Goal("x", weight=spec.w2, integrand=tracking)),
        data=data,
    )
    problem = ocp.Problem(phases=(phase,), parameters=tuple(params), name="mtg_identification")
    mesh = Mesh(spec.n_intervals, "lgr", spec.degree)
    options = ocp.SolverOptions(tol=spec.tol, max_iter=spec.max_iter)
    # guess: the data (Fourier-fit angles, velocities, accelerations), Γ_initial (Eq 5.22)
    gait = data_mod.load_gait_data(spec.speed_class, spec.source)
    ref = gait_ocp.reference(gait, ChildModel())
    S = {f"q_{j}": dem[f"q_{j}"].to_numpy() for j in _JOINTS}
    S.update({f"qd_{j}": dem[f"qd_{j}"].to_numpy() for j in _JOINTS})
    C = {f"qdd_{j}": ref.deriv[f"{j}_{spec.side}"](t)[2] for j in _JOINTS}
    guess = ocp.Guess(phases={"cycle": ocp.PhaseGuess(time=t, states=S, controls=C)},
                      parameters={p_.name: p_.guess for p_ in params})
    return problem, mesh, options, guess, dem, ranges


@dataclass(eq=False)
class MTGIdentification:
    """Result of :func:`identify`.

    Attributes
    ----------
    spec : IdentSpec
    params : generator → identified :class:`~gaitlib.mtg.MTGParams` (Δ^P in rad).
    stats : IPOPT status, success, iterations, solve/build time (s), time per iteration,
        objective and its two terms (``cost_Gamma`` = w1 Σ(...)², ``cost_x`` = w2 ∫...), max
        constraint violation, sizes.
    states : the solved θ, θ̇ (index time, s; rad, rad/s) on the state nodes.
    demand : :func:`demanded_torques` (fine grid).
    rmse_deg : tracking RMSE of the angles (deg) at the collocation nodes.
    solution : the raw :class:`gaitlib.ocp.Solution`.
    """

    spec: IdentSpec
    params: dict
    stats: dict
    states: pd.DataFrame
    demand: pd.DataFrame
    rmse_deg: dict
    solution: ocp.Solution = field(repr=False, default=None)

    @property
    def success(self) -> bool:
        return bool(self.stats["success"])


def identify(spec: IdentSpec = IdentSpec()) -> MTGIdentification:
    """Solve the identification NLP (module docstring) from Γ_initial; never hides a failure
    (``stats['status']``)."""
    t0 = time.perf_counter()
    problem, mesh, options, guess, dem, _ = build(spec)
    sol = ocp.solve(problem, mesh, options, guess)
    P = {g: mtg.MTGParams(*[sol.parameters[_pname(g, k)] for k in GAMMA]) for g in mtg.GENERATORS}
    X = sol.phase("cycle").states
    tc = sol.phase("cycle").controls.index.to_numpy()
    Xc = sol.phase("cycle").interpolate(tc)
    rmse = {j: float(np.sqrt(np.mean((Xc[f"q_{j}"].to_numpy() - np.interp(tc, dem.index, dem[f"q_{j}"])) ** 2))
                     ) / cv.DEG for j in _JOINTS}
    stats = {"status": sol.status, "success": sol.success, "iterations": sol.iterations,
             "solve_time_s": sol.solve_time, "build_time_s": sol.build_time,
             "time_per_iteration_s": sol.time_per_iteration, "objective": sol.objective,
             "cost_Gamma": sol.cost("Gamma"), "cost_x": sol.cost("x"),
             "max_violation": sol.max_violation, "worst_constraint": sol.worst_constraint,
             "n_variables": sol.info.get("n_variables"), "n_constraints": sol.info.get("n_constraints"),
             "wall_s": time.perf_counter() - t0}
    return MTGIdentification(spec, P, stats, X, dem, rmse, sol)
