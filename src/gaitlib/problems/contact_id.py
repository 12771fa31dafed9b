"""The contact-identification problem of thesis Ch 4's approach (a) (Sec 4.3.1): the 39
contact parameters of the left foot's ellipsoids fitted with the kinematics fixed to the data.

Inverse dynamics gives the joint torques and pelvis residual loads, the contact model the
GRFs, and the parameters minimise Eq 4.5 (weights Table 4.8: w1 = w2 = 1/4) within the
Table 4.7 bounds and the friction-ratio constraint Eq 4.4 (0.55 ≤ μ_d/μ_s ≤ 0.99). Each local
solve is IPOPT with exact first and second derivatives (CasADi AD) in scaled variables
z ∈ [0, 1]³⁹ (k_v log-scaled: it spans three decades). The multistart around it is
:mod:`gaitlib.studies.contact_id`'s.

Approaches (b)/(c) are the gait problem (:mod:`gaitlib.problems.gait`) with the parameters
free (:func:`spec_b`, :func:`spec_c`), solved from a start parameter set through a
continuation on the residual bounds (:data:`CONTINUATION`, :func:`solve_continued`), each
stage cached (:func:`solve_stage`, version :data:`FORMULATION`).
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from dataclasses import dataclass
from functools import cached_property

import casadi as ca
import numpy as np
import pandas as pd

from .. import cache
from .. import contact as contact_mod
from .. import conventions as cv
from .. import data as data_mod
from .. import ocp
from ..model import ChildModel
from . import gait as gait_ocp
from ..model import ELLIPSOID_LABELS

__all__ = ["TRAJOPT_FORMULATION", "MU_RATIO", "TrajOptSpec", "InverseDynamicsID", "neutral_start",
           "FORMULATION", "GUESS_METHOD", "CONTINUATION", "spec_b", "spec_c", "stage_spec", "solve_stage",
           "solve_continued"]

#: Version of approach (a)'s trajectory-optimisation problem (:class:`InverseDynamicsID`, its
#: multistart and solver options): part of its cache keys.
TRAJOPT_FORMULATION = "contact-trajopt-1"

#: Friction-ratio bounds of Eq 4.4 (μ_d / μ_s), thesis Sec 4.3.1.
MU_RATIO = (0.55, 0.99)

#: Version of approaches (b)/(c) on top of :data:`gaitlib.problems.gait.FORMULATION` (their
#: starts, guesses and continuation): part of their cache keys. Bump either when a change
#: alters what is solved (tests/test_formulation_versions.py).
FORMULATION = "contact-id-1"


# --------------------------------------------------------------------------------------
# Starting point
# --------------------------------------------------------------------------------------


def neutral_start() -> np.ndarray:
    """The neutral start (39,), SI: the centre of each Table 4.7 box, k_v at the geometric
    centre of its box (√(10⁵·10⁸) ≈ 3.16·10⁶ N/m³), μ_s = 0.40 and μ_d = 0.35 (the thesis's
    friction guess, Sec 4.3.1: "the required friction coefficient for walking is 0.3")."""
    lo, hi = contact_mod.bounds()
    p = 0.5 * (lo + hi)
    for e in cv.ELLIPSOIDS:
        i = contact_mod.param_index(e, "k_v")
        p[i] = float(np.sqrt(lo[i] * hi[i]))
        p[contact_mod.param_index(e, "mu_s")] = 0.40
        p[contact_mod.param_index(e, "mu_d")] = 0.35
    return p


# --------------------------------------------------------------------------------------
# Approach (a): trajectory optimisation on fixed kinematics
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class TrajOptSpec:
    """Approach (a): what to solve and how to search.

    Parameters
    ----------
    speed_class, source : the data (:func:`gaitlib.data.load_gait_data`).
    n_time : samples of the cycle, uniform on [0, T) (T the data's cycle time); Eq 4.5's
        (1/t_f)∫ dt is their mean (exact for the periodic trigonometric polynomials the
        kinematics are). The thesis sampled 101 points.
    n_trial : Latin-hypercube trial points scored by the cost (+ a penalty on Eq 4.4).
    n_local : local solves from the best-scoring trial points (after the one from x0).
    seed : seed of the scatter (reproducible).
    tol, max_iter : IPOPT settings of each local solve.
    """

    speed_class: str = "Free"
    source: str = "schwartz2008"
    n_time: int = 100
    n_trial: int = 200
    n_local: int = 10
    seed: int = 0
    tol: float = 1e-8
    max_iter: int = 1000

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


class InverseDynamicsID:
    """The inverse-dynamics identification problem of approach (a) (Sec 4.3.1).

    With the kinematics fixed to the data, for contact parameters p (39,) at each of the
    ``n_time`` samples t_k: GRFs from the contact model, joint torques τ and pelvis residuals
    R from inverse dynamics (:meth:`gaitlib.model.ChildModel.function` ``"inverse_dynamics"``)
    with the default body parameters (Sec 4.1.1); the net joint torque (actuator + the
    joints' spring–damper, what the data report) is compared with the data.

    Cost Eq 4.5: ``J(p) = (1/N) Σ_k [¼ Σ_6 ((τ_net − τ_exp)/range)² + ¼ Σ_4 ((GRF − GRF_exp)/range)²]``
    (ranges = max − min of the data; 6 = hip, knee, ankle of both legs; 4 = tangential and
    normal force of both feet).

    Scaled variables z ∈ [0, 1]³⁹ (:meth:`p_of_z`): p = lo + (hi − lo) z, except
    k_v = lo (hi/lo)^z. Constraint Eq 4.4: μ_d − 0.55 μ_s ≥ 0 and 0.99 μ_s − μ_d ≥ 0 per
    ellipsoid (linear in p).
    """

    def __init__(self, spec: TrajOptSpec = TrajOptSpec()):
        self.spec = spec
        self.model = ChildModel()
        self.gait = data_mod.load_gait_data(spec.speed_class, spec.source)
        self.ref = gait_ocp.reference(self.gait, self.model, contact_mod.default_params())
        T = self.gait.cycle_time
        N = spec.n_time
        self.t = np.arange(N) * T / N
        d = {c: self.ref.deriv[c](self.t) for c in cv.COORDS}
        self.Q = np.array([d[c][0] for c in cv.COORDS])
        self.QD = np.array([d[c][1] for c in cv.COORDS])
        self.QDD = np.array([d[c][2] for c in cv.COORDS])
        self.p_body = self.model.default_p_body()
        g = self.gait
        self.tau_data = np.array([np.interp(self.t, g.time, g.mean[f"tau_{j}"]) for j in gait_ocp.LEG_JOINTS])
        self.grf_data = np.array([np.interp(self.t, g.time, g.mean[c]) for c in gait_ocp.GRF_CHANNELS])
        self.tau_range = np.array([self.ref.ranges[f"tau_{j}"] for j in gait_ocp.LEG_JOINTS])
        self.grf_range = np.array([self.ref.ranges[c] for c in gait_ocp.GRF_CHANNELS])
        self.lo, self.hi = contact_mod.bounds()
        self.log = np.zeros(39, bool)
        for e in cv.ELLIPSOIDS:
            self.log[contact_mod.param_index(e, "k_v")] = True

    # ---- scaling
    def p_of_z(self, z):
        """Parameters (SI) of scaled variables z (numpy or CasADi)."""
        lo, hi = self.lo, self.hi
        llo, lhi = np.log(np.where(self.log, lo, 1.0)), np.log(np.where(self.log, hi, 1.0))
        if isinstance(z, (ca.SX, ca.MX)):
            lin = ca.DM(lo) + ca.DM(hi - lo) * z
            ex = ca.exp(ca.DM(llo) + ca.DM(lhi - llo) * z)
            return ca.vertcat(*[ex[i] if self.log[i] else lin[i] for i in range(39)])
        z = np.asarray(z, float)
        return np.where(self.log, np.exp(llo + (lhi - llo) * z), lo + (hi - lo) * z)

    def z_of_p(self, p) -> np.ndarray:
        """Scaled variables of parameters p (SI)."""
        p = np.asarray(p, float)
        lo, hi = self.lo, self.hi
        z = (p - lo) / (hi - lo)
        with np.errstate(divide="ignore", invalid="ignore"):
            zl = np.log(p / lo) / np.log(hi / lo)
        return np.where(self.log, zl, z)

    # ---- symbolic functions
    @cached_property
    def _expressions(self) -> dict:
        N = self.spec.n_time
        p = ca.SX.sym("p", 39)
        P = ca.repmat(p, 1, N)
        f_id = self.model.function("inverse_dynamics").map(N)
        f_ct = self.model.function("contact").map(N)
        f_pas = self.model.function("passive").map(N)
        tau, R = f_id(self.Q, self.QD, self.QDD, self.p_body, P)
        ct = dict(zip(self.model.function("contact").name_out(), f_ct(self.Q, self.QD, P)))
        grf = ca.vertcat(ct["grf_x"][0, :], ct["grf_y"][0, :], ct["grf_x"][1, :], ct["grf_y"][1, :])
        net = tau + f_pas(self.Q, self.QD, self.p_body)
        rows = [cv.JOINTS.index(j) for j in gait_ocp.LEG_JOINTS]
        e_tau = (net[rows, :] - ca.DM(self.tau_data)) / ca.repmat(ca.DM(self.tau_range), 1, N)
        e_grf = (grf - ca.DM(self.grf_data)) / ca.repmat(ca.DM(self.grf_range), 1, N)
        j_trq = ca.sumsqr(e_tau) / N
        j_grf = ca.sumsqr(e_grf) / N
        return {"p": p, "J": 0.25 * j_trq + 0.25 * j_grf, "Trq": j_trq, "GRF": j_grf, "net": net, "R": R,
                "grf": grf, "fn": ct["fn"], "fx": ct["fx"], "fn_raw": ct["fn_raw"]}

    @cached_property
    def cost_function(self) -> ca.Function:
        """p (39,) SI → J (Eq 4.5), Trq and GRF (the unweighted mean squared normalised errors)."""
        E = self._expressions
        return ca.Function("eq4_5", [E["p"]], [E["J"], E["Trq"], E["GRF"]], ["p"], ["J", "Trq", "GRF"])

    @cached_property
    def gradient_function(self) -> ca.Function:
        """p (39,) SI → dJ/dp (39,), exact (algorithmic differentiation)."""
        E = self._expressions
        return ca.Function("eq4_5_grad", [E["p"]], [ca.gradient(E["J"], E["p"])], ["p"], ["dJdp"])

    @cached_property
    def frames_function(self) -> ca.Function:
        E = self._expressions
        return ca.Function("frames", [E["p"]], [E["net"], E["R"], E["grf"], E["fn"], E["fx"], E["fn_raw"]],
                           ["p"], ["tau_net", "R", "grf", "fn", "fx", "fn_raw"])

    def cost(self, p) -> float:
        """Eq 4.5 at p (SI)."""
        return float(self.cost_function(np.asarray(p, float))[0])

    def ratio_violation(self, p) -> float:
        """Total violation of Eq 4.4 at p (0 when satisfied)."""
        p = np.asarray(p, float)
        v = 0.0
        for e in cv.ELLIPSOIDS:
            ms, md = p[contact_mod.param_index(e, "mu_s")], p[contact_mod.param_index(e, "mu_d")]
            v += max(0.0, MU_RATIO[0] * ms - md) + max(0.0, md - MU_RATIO[1] * ms)
        return v

    @cached_property
    def solver(self) -> ca.Function:
        """IPOPT on z ∈ [0, 1]³⁹ with the Eq 4.4 constraints (exact Hessian)."""
        z = ca.SX.sym("z", 39)
        p = self.p_of_z(z)
        J = ca.substitute(self._expressions["J"], self._expressions["p"], p)
        g = []
        for e in cv.ELLIPSOIDS:
            ms, md = p[contact_mod.param_index(e, "mu_s")], p[contact_mod.param_index(e, "mu_d")]
            g += [md - MU_RATIO[0] * ms, MU_RATIO[1] * ms - md]
        opts = {"ipopt": {"tol": self.spec.tol, "max_iter": self.spec.max_iter, "print_level": 0, "sb": "yes",
                          "mu_strategy": "monotone", "linear_solver": "mumps"},
                "print_time": False, "error_on_fail": False}
        return ca.nlpsol("traj_opt", "ipopt", {"x": z, "f": J, "g": ca.vertcat(*g)}, opts)

    def local_solve(self, p0) -> dict:
        """One local solve from p0 (SI, clipped into the bounds): p, cost, status, iterations, s."""
        z0 = np.clip(self.z_of_p(np.clip(p0, self.lo, self.hi)), 0.0, 1.0)
        t0 = time.perf_counter()
        r = self.solver(x0=z0, lbx=0.0, ubx=1.0, lbg=0.0, ubg=np.inf)
        dt = time.perf_counter() - t0
        st = self.solver.stats()
        p = self.p_of_z(np.clip(np.asarray(r["x"]).ravel(), 0.0, 1.0))
        return {"p": p, "cost": self.cost(p), "status": str(st["return_status"]), "success": bool(st["success"]),
                "iterations": int(st["iter_count"]), "time_s": dt, "ratio_violation": self.ratio_violation(p)}

    def scatter(self) -> np.ndarray:
        """The seeded Latin-hypercube trial points (n_trial, 39), SI. The μ_d coordinate is
        sampled as the ratio μ_d/μ_s within Eq 4.4's bounds (then clipped to μ_d's box), so
        that trial points respect Eq 4.4 where the box allows."""
        from scipy.stats import qmc

        U = qmc.LatinHypercube(d=39, seed=self.spec.seed).random(self.spec.n_trial)
        P = np.array([self.p_of_z(u) for u in U])
        for e in cv.ELLIPSOIDS:
            i_s, i_d = contact_mod.param_index(e, "mu_s"), contact_mod.param_index(e, "mu_d")
            ratio = MU_RATIO[0] + (MU_RATIO[1] - MU_RATIO[0]) * U[:, i_d]
            P[:, i_d] = np.clip(ratio * P[:, i_s], self.lo[i_d], self.hi[i_d])
        return P

    def score(self, p) -> float:
        """GlobalSearch-style score: cost + 1000 × Eq 4.4 violation."""
        return self.cost(p) + 1e3 * self.ratio_violation(p)

    def frames(self, p) -> dict:
        """Frames at p (SI): ``q``, ``torques`` (8 net), ``residuals``, ``grf``, ``ellipsoids``."""
        out = self.frames_function(np.asarray(p, float))
        idx = pd.Index(self.t, name="time")
        net, R, grf, fn, fx = (np.asarray(v) for v in out[:5])
        q = pd.DataFrame(self.Q.T, index=idx, columns=list(cv.COORDS))
        torques = pd.DataFrame(net.T, index=idx, columns=list(cv.JOINTS))
        residuals = pd.DataFrame(R.T, index=idx, columns=list(cv.RESIDUALS))
        grf_f = pd.DataFrame(grf.T, index=idx, columns=list(gait_ocp.GRF_CHANNELS))
        ell = {}
        for i, lab in enumerate(ELLIPSOID_LABELS):
            ell[f"fn_{lab}"] = fn[i]
            ell[f"fx_{lab}"] = fx[i]
        return {"q": q, "torques": torques, "residuals": residuals, "grf": grf_f,
                "ellipsoids": pd.DataFrame(ell, index=idx)}


# --------------------------------------------------------------------------------------
# Approaches (b)/(c): the gait problem with the parameters free
# --------------------------------------------------------------------------------------


def spec_b(n_intervals: int = 20, degree: int = 5, contact_bounds: str = "table4.7", **kw) -> gait_ocp.GaitSpec:
    """Approach (b): SK, Eq 4.11 (Table 4.8 weights), 39 contact parameters free within
    Table 4.7 verbatim and Eq 4.4; Eq 4.8 residual bounds; thesis mesh 20 × 5 LGR."""
    return gait_ocp.GaitSpec(model="SK", cost="Eq4.11", free_contact=True, contact_bounds=contact_bounds,
                       n_intervals=n_intervals, degree=degree, **kw)


def spec_c(n_intervals: int = 20, degree: int = 5, contact_bounds: str = "table4.7", **kw) -> gait_ocp.GaitSpec:
    """Approach (c): (b) + the 25 body/joint parameters free (Table 4.14), per-ellipsoid
    normal force ≥ 0 (Sec 4.4.1), cost Eq 4.13 (Eq 4.11 + Imp Eq 4.12 + Rsd Eq 4.13,
    w5 = w6 = 1/4). ``contact_bounds="widened"``: Table 4.7 widened to contain the thesis's
    own (c) values (Table 4.17, five of which lie outside Table 4.7 — the bounds the thesis
    must have used in Sec 4.4, unreported)."""
    return gait_ocp.GaitSpec(model="SK", cost="Eq4.13", free_contact=True, free_body=True,
                       normal_force_constraint=True, contact_bounds=contact_bounds,
                       n_intervals=n_intervals, degree=degree, **kw)


#: How a cold-started (b)/(c) guess is built; part of the cache key of those solves: change it
#: with the method.
GUESS_METHOD = "data-based guess of the spec (states, jerks, data torques, zero residuals) + start parameters (v1)"


def solve_stage(spec: gait_ocp.GaitSpec, start: dict, warm: gait_ocp.GaitSolution | None, use_cache: bool, root,
                       progress: bool = False) -> gait_ocp.GaitSolution:
    """Solve ``spec`` from the data-based guess with the parameters ``start`` (name → value)
    or warm-started from ``warm``; cached on spec + start + warm start's identity + code."""
    desc = {"kind": "contact_id_gait", **spec.to_dict(), "guess": GUESS_METHOD,
            "start": {k: float(np.format_float_positional(v, 12)) for k, v in sorted(start.items())}}
    if warm is not None:
        ws = warm.solution
        desc["warm_start"] = {"spec": warm.spec.to_dict(), "status": ws.status,
                              "objective": float(f"{ws.objective:.12g}"), "iterations": ws.iterations}
    where = cache.lookup("contact_id", desc, root, formulation=(gait_ocp.FORMULATION, FORMULATION),
                         identified=spec.identified_sets())

    def solve():
        gp = gait_ocp.build(spec)
        if warm is not None:
            g = gait_ocp.warm_start(gp, warm)
            guess = ocp.Guess(phases=g.phases, parameters={**dict(g.parameters), **start})
        else:
            guess = ocp.Guess(phases=gp.guess.phases, parameters=dict(start))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ocp.SolveFailedWarning)
            sol = gait_ocp.solve(gp, guess=guess, progress=progress)
        sol.stats["from_cache"] = False
        return sol

    return cache.solve_or_load(where, solve, gait_ocp.GaitSolution.from_cache, marker="spec.json",
                               use_cache=use_cache)


#: Continuation towards approach (b) from a start far from dynamic consistency (our device):
#: the pelvis residual bounds (R_x, R_y N; R_z N·m) of the stages before the final problem,
#: each stage with the Rsd term (Eq 4.13, weight 1/4) added and warm-started from the last.
CONTINUATION = ((1000.0, 1000.0, 100.0), (100.0, 100.0, 10.0), (10.0, 10.0, 1.0))


def stage_spec(spec: gait_ocp.GaitSpec, bounds) -> gait_ocp.GaitSpec:
    w = tuple(spec.weights) if "Rsd" in spec.term_weights else tuple(spec.weights) + (("Rsd", 0.25),)
    return dataclasses.replace(spec, residual_bounds=tuple(float(b) for b in bounds), weights=w)


def solve_continued(spec: gait_ocp.GaitSpec, start: dict, warm, stages, use_cache, root, progress):
    """Solve the ``stages`` (residual bounds) then ``spec`` itself, each warm-started from the
    previous solution (whatever its status: every stage's status is kept and reported)."""
    sols = []
    prev = warm
    for b in stages:
        sol = solve_stage(stage_spec(spec, b), start if prev is None else {}, prev, use_cache, root, progress)
        sols.append(sol)
        prev = sol
    final = solve_stage(spec, start if prev is None else {}, prev, use_cache, root, progress)
    return final, sols
