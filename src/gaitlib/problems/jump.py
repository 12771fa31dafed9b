"""The vertical-jump problems of thesis Ch 3 (Sec 3.3) on :mod:`gaitlib.ocp`.

Three jumps, each a frozen :class:`JumpSpec` (:data:`SPECS`):

``"toeless"``   toeless model, kinematically constrained contact: preflight (foot welded,
                DOF 3) + flight (DOF 6);
``"toe"``       toe-included model, kinematically constrained contact: preflight (toe
                welded, DOF 4) + flight (DOF 7);
``"ellipsoid"`` toe-included model with three contact ellipsoids per (doubled) foot: crouch +
                thrust + flight, DOF 7 in every phase.

Every problem has the phases ``crouch``, ``thrust``, ``flight``: for the kinematic models
crouch + thrust are the thesis's single preflight phase, split at a free instant with no
constraint at the split (a mesh device, so that the short thrust gets its own intervals).

:func:`solve` builds the :class:`gaitlib.ocp.Problem` (:func:`build`), solves it with IPOPT
and returns a :class:`JumpSolution` with tidy frames, jump heights, the required static
friction (Eq 3.6) and the solver's statistics. A solve that does not converge is returned
with IPOPT's status and ``success=False``; nothing here retries or falls back silently.

Formulation (thesis Sec 3.3)
----------------------------
states    x = [q, q̇, τ]                               (Eq 3.4)
controls  u = τ̇                                       (Eq 3.5)
dynamics  M(q) q̈ + F(q, q̇) = τ (Eqs 3.1–3.2; :class:`gaitlib.jump.JumpModel`, exact SX
          derivatives). Default ``dynamics="implicit"``: q̈ are extra controls and the
          inverse dynamics − τ = 0 (plus a zero root wrench for the free model) are path
          constraints — the same continuous problem as the thesis's explicit q̈ = M⁻¹F
          (``dynamics="explicit"``), far better conditioned with the light toe as root.
bounds    Table 3.5 (angles, angular velocities, torques; :func:`joint_bounds`), τ̇ bounded
          by ``taud_max`` ("considerably greater than joint torque ranges", Sec 3.3)
events    Table 3.7: a_COM = 0 at the start (static equilibrium), F_y = 0 at take-off (end
          of the preflight / thrust), v_y,COM = 0 at the end of the flight (apex);
          continuity of time and shared states between phases
path      Table 3.8: |x_COM(t) − x_COM(0)| ≤ Δx in every phase
cost      Table 3.9 with the weights of Table 3.10:
          kinematic  w1 (v_des / v_y,COM(t_TO))² + w2 (y_des / y_COM(t_apex))²
          ellipsoid  w1 (θ_knee − θ_des)² + w2 θ̇_knee² (end of crouch)
                     + w3 (v_des / v_y,COM(t_TO))² + w4 (y_des / y_COM(t_apex))²
          v_des = 10 m/s, y_des = 1 m, θ_des = −110° (Sec 3.3)

Our choices where Ch 3 is silent (each one a field of :class:`JumpSpec`)
------------------------------------------------------------------------
* The jump starts from the standing posture (all joint angles 0) at rest (q̇ = 0); the
  thesis's Table 3.7 states only a_COM = 0 ("static equilibrium").
* Table 3.5's ankle angle (50–110°) is read as the shank–foot angle, 90° when standing,
  decreasing with dorsiflexion: ours (> 0 dorsiflexion) = 90° − thesis, i.e. [−20°, 40°];
  the ankle's angular-velocity and torque bounds change sign with it (the other reading,
  [−40°, 20°], would allow only 20° of dorsiflexion, little for the deep crouches with
  the heels down of Sec 3.4.1). The other joints' bounds are used as printed (their signs match
  :mod:`gaitlib.conventions`).
* Phase durations (``durations``): crouch 0.1–1 s, thrust 0.05–0.5 s, flight 0.05–1.5 s.
* Kinematic contact: the welded ground may only push (F_y ≥ 0 in preflight,
  ``unilateral``), the heel may not go below the ground (mtp ≥ 0 while the toe is welded),
  and in flight the ankle and toe tip stay above the ground (``flight_clearance``; the MTP
  point is bounded y ≥ 0).
* Ellipsoid contact: the feet stay on the ground during the crouch (F_y ≥ 2 % of the
  weight at its collocation nodes, ``contact_fy_min``; without it the optimum hops during
  the "crouch"); take-off is ``0 ≤ F_y ≤ fy_takeoff`` (1 N), and F_y ≤ ``flight_fy_max``
  (7 N, 1 % of the weight) in flight (the feet must not touch down again) — the smoothed contact law
  (:class:`gaitlib.contact.Smoothing`) never gives exactly 0; the contact parameters are
  the child foot's (:func:`gaitlib.contact.default_params`) on both (doubled) feet, see
  :mod:`gaitlib.jump` (Ch 3 used Brown & McPhee's adult values, not printed).
* The knee terms of the crouch are in rad and rad/s (SI).
* Ballistic apex (``ballistic_flight="apex"``): the apex node's COM height and vertical
  velocity are tied to the take-off COM state by the exact flight parabola (no external
  force). Without it IPOPT "gains" metres of height in flight from the collocation error
  of the light, fast-spinning toe (the root segment). ``"nodes"`` imposes the parabola at
  every collocation node too (nearly redundant constraints: IPOPT converges badly).
* A small regularisation ``w_reg ∫ Σ_j (τ̇_j / taud_max)² dt`` in every phase (reported as
  goal ``reg_taud``, a few per cent of the objective): the flight's torques do not enter
  the thesis's cost at all, and without it the torques ring from node to node.
* Mesh: GPOPS-II's hp-adaptive mesh (Table 3.11: "30 meshes", 4–20 collocation points per
  interval) is replaced by fixed LGR meshes, ``degree`` = 4 points (their minimum) ×
  ``n_intervals`` per phase, the thrust's intervals shrinking towards take-off
  (:func:`meshes`). Torque states are scaled by ``tau_scale`` inside the NLP only.

Jump height: the thesis does not define it. We report the COM rise during flight
(``com_rise_flight``, the biomechanical jump height; equals v_y,TO² / 2g), the COM rise
from standing (``com_rise_standing``) and the lift of the MTP point at the apex
(``foot_lift``, what Fig 3.8 plots).

Symbol legend: q (rad; root x, y in m), q̇ (rad/s, m/s), q̈, τ (N·m), τ̇ (N·m/s), F (N),
t (s); SI everywhere, degrees only in :data:`TABLE_3_5` and in figures.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass, replace
from typing import Any

import casadi as ca

import numpy as np
import pandas as pd

from .. import cache
from .. import contact as contact_mod
from .. import conventions as cv
from .. import mtg
from .. import ocp
from ..collocation import Mesh
from ..jump import JumpModel

__all__ = [
    "TABLE_3_5",
    "THESIS",
    "SPECS",
    "JumpSpec",
    "TORQUE_LIMITS",
    "strength_envelope",
    "JumpProblem",
    "JumpSolution",
    "joint_bounds",
    "spec",
    "build",
    "guess_across",
    "initial_guess",
    "solve",
    "meshes",
    "cache_location",
    "FORMULATION",
    "LABELS",
]

#: Thesis Table 3.5, as printed (thesis convention): joint → ((angle lo, hi) deg,
#: (velocity lo, hi) deg/s, (torque lo, hi) N·m).
TABLE_3_5 = {
    "mtp": ((-45.0, 80.0), (-1200.0, 1500.0), (-4000.0, 2000.0)),
    "ankle": ((50.0, 110.0), (-1200.0, 1500.0), (-4000.0, 2000.0)),
    "knee": ((-150.0, 0.0), (-1200.0, 1500.0), (-2000.0, 1500.0)),
    "hip": ((-30.0, 100.0), (-1200.0, 1500.0), (-2000.0, 1500.0)),
}

#: Version of the jump formulation (:mod:`gaitlib.jump`, this module's problems, guesses,
#: continuation and solver options with the physics below): part of every jump cache key.
#: Bump it when a change alters what is solved (tests/test_formulation_versions.py).
FORMULATION = "jump-1"

#: The thesis's reported results (references only; never "ours"): jump height (cm,
#: Sec 3.4.4), required static friction μ_s ≥ max |F_x/F_y| (Sec 3.4.3, Fig 3.7), most
#: flexed knee angle (deg, Sec 3.4.1). Its keys are the jumps' names.
THESIS = {
    "toeless": {"jump_height_cm": 14.0, "mu_s": 1.4, "knee_min_deg": -94.0},
    "toe": {"jump_height_cm": 66.0, "mu_s": 1.0, "knee_min_deg": -122.0},
    "ellipsoid": {"jump_height_cm": 89.0, "mu_s": 0.12, "knee_min_deg": -150.0},
}

#: The jump's torque limits (:class:`JumpSpec` ``torque_limits``).
TORQUE_LIMITS = ("table3.5", "strength_peak", "strength")

LABELS = {
    "toeless": "toeless, kinematic contact",
    "toe": "toe-included, kinematic contact",
    "ellipsoid": "toe-included, ellipsoid contact",
}


def joint_bounds(joint: str) -> dict[str, tuple[float, float]]:
    """Bounds of one joint in our convention and SI: ``{"q": (rad), "qd": (rad/s),
    "tau": (N·m)}`` from :data:`TABLE_3_5` (the ankle mapped as ``90° − θ_thesis``, which
    flips its velocity and torque bounds; see the module docstring)."""
    (a0, a1), (v0, v1), (t0, t1) = TABLE_3_5[joint]
    if joint == "ankle":
        a0, a1 = 90.0 - a1, 90.0 - a0
        v0, v1 = -v1, -v0
        t0, t1 = -t1, -t0
    return {"q": (a0 * cv.DEG, a1 * cv.DEG), "qd": (v0 * cv.DEG, v1 * cv.DEG), "tau": (t0, t1)}


# ======================================================================================
# Spec
# ======================================================================================
@dataclass(frozen=True)
class JumpSpec:
    """What to solve: one predictive vertical jump of thesis Ch 3 (and how finely).

    Parameters
    ----------
    name : ``"toeless"``, ``"toe"`` or ``"ellipsoid"`` (the three models of Ch 3).
    weights : (w1, w2[, w3, w4]) — Table 3.10.
    dx_com : horizontal COM band half-width Δx, m (Table 3.8).
    v_des, y_des : m/s, m — the "desired" take-off velocity and apex height of Table 3.9.
    knee_des_deg : θ_des of the crouch term, deg (ellipsoid model).
    n_intervals, degree : LGR mesh per phase (see the module docstring).
    thrust_refine : ratio of the thrust's first to last interval width (:func:`meshes`).
    continuation : coarser ``n_intervals`` solved first, each solution the initial guess of
        the next and the last of the final mesh (a deterministic procedure, part of the
        spec; every step's status is kept in ``solution.info["continuation"]``). A failed
        step is still used as the next guess and shows in that record.
    durations : per phase (lower, upper) bounds of its duration, s.
    taud_max : |τ̇| bound, N·m/s.
    unilateral : F_y ≥ 0 in the welded preflight (kinematic contact).
    fy_takeoff : take-off F_y upper bound, N (ellipsoid contact; 0 is imposed exactly for
        the kinematic contact).
    flight_fy_max : F_y upper bound, N, at the flight's collocation nodes (ellipsoid
        contact: the feet must not touch down again; 7 N ≈ 1 % of the weight — with 1 N the
        10-interval solve did not converge in 5000 iterations); None switches it off.
    contact_fy_min : ellipsoid contact: F_y ≥ this fraction of the weight at every collocation
        node of the crouch (without it the optimum hops during the "crouch"); None
        switches it off.
    fy_min_fraction : |F_x/F_y| (Eq 3.6) is evaluated where F_y ≥ this fraction of the
        body weight (the ratio is undefined at take-off, where F_y → 0).
    w_reg : weight of our regularisation ``∫ Σ_j (τ̇_j / taud_max)² dt`` in every phase
        (not in the thesis; 0 switches it off — see the module docstring).
    ballistic_flight : impose the flight's exact COM parabola at the collocation nodes
        (our addition, see :func:`build`).
    damping : joint dampers, N·m·s/rad (:class:`gaitlib.jump.JumpModel`).
    dynamics : ``"implicit"`` (default) or ``"explicit"``, see :func:`build`.
    qdd_max : bound on the q̈ controls of the implicit form, rad/s² (m/s² for x, y).
    tau_scale : N·m per NLP unit of the torque states and τ̇ controls (variable scaling
        for IPOPT only; every frame is in N·m).
    tol, max_iter : IPOPT (Table 3.11: 1e-6, 5000).
    ipopt : further IPOPT options as ``(name, value)`` pairs.
    friction_max : ``None`` (the thesis: a welded foot transmits any horizontal force) or μ:
        kinematic contact only — |F_x| ≤ μ F_y at every collocation node of the preflight
        (ours; Sec 3.4.3 reports the μ_s a jump *requires* instead of bounding it).
    torque_limits : ``"table3.5"`` (the thesis: Table 3.5's torque bounds, up to 4000 N·m)
        or ``"strength"`` (ours, the physiological version): the joint torques are also
        bounded by the body's strength — at hip, knee and ankle a path constraint
        τ_min(q, q̇) ≤ τ ≤ τ_max(q, q̇) in every phase, the envelope of the Ch 5 muscle
        torque generators with the agonist fully active (:func:`gaitlib.mtg.max_joint_torque`:
        torque–angle × torque–velocity + passive, Eq 5.8), scaled by Eq 5.21 to this
        model's mass and standing height, × 2 legs; at the metatarsal joint (no MTG) a box
        of ± the ankle plantarflexors' peak (:func:`gaitlib.mtg.strength_limits`).
        ``"strength_peak"``: only boxes, each joint's peak (the eccentric plateau) in each
        direction. A ``"strength"`` solve without a guess starts its mesh continuation from
        the ``"strength_peak"`` solution on the continuation's first (coarsest) mesh
        (solved, or reloaded from the cache): part of the procedure, recorded in
        ``solution.info["continuation"]``.
    start_from : ``None`` (the mesh continuation above) or the name of another jump of
        :data:`SPECS` (ours, a procedure): start the full mesh from that jump's solution with
        this spec's ``torque_limits`` (reloaded from the cache, or solved) instead of the
        continuation — its states and controls per phase, the coordinates it lacks (the
        toeless jump has no metatarsal joint) at 0, the static parameters at their defaults.
        Recorded in ``solution.info["continuation"]``.
    start_weights : ``None`` or cost weights like ``weights`` (ours, a procedure): start the
        full mesh from this same spec's solution with ``start_weights`` as its weights
        (reloaded from the cache, or solved by its own procedure) instead of the mesh
        continuation — e.g. a change of the cost (:func:`gaitlib.studies.jump.apex_cost_spec`)
        solved from the optimum of the thesis's cost. Recorded in ``solution.info["continuation"]``.
    """

    name: str = "toe"
    weights: tuple = (1.0, 1.0)
    dx_com: float = 0.06
    v_des: float = 10.0
    y_des: float = 1.0
    knee_des_deg: float = -110.0
    n_intervals: int = 10
    degree: int = 4
    thrust_refine: float = 8.0
    continuation: tuple = (5,)
    durations: tuple = ((0.1, 1.0), (0.05, 0.5), (0.05, 1.5))
    taud_max: float = 3.0e4
    unilateral: bool = True
    fy_takeoff: float = 1.0
    contact_fy_min: float | None = 0.02
    flight_fy_max: float | None = 7.0
    fy_min_fraction: float = 0.05
    w_reg: float = 0.1
    ballistic_flight: str = "apex"
    flight_clearance: bool = True
    damping: float = 0.1
    tau_scale: float = 100.0
    dynamics: str = "implicit"
    qdd_max: float = 1000.0
    tol: float = 1e-6
    max_iter: int = 5000
    ipopt: tuple = ()
    print_level: int = 0
    torque_limits: str = "table3.5"
    friction_max: float | None = None
    start_from: str | None = None
    start_weights: tuple | None = None

    def __post_init__(self):
        if self.start_from is not None and (self.start_from not in SPECS or self.start_from == self.name):
            raise ValueError(f"start_from: another jump of {tuple(SPECS)}, got {self.start_from!r} for {self.name!r}")
        if self.torque_limits not in TORQUE_LIMITS:
            raise ValueError(f"torque_limits must be one of {TORQUE_LIMITS}, got {self.torque_limits!r}")
        if self.name not in THESIS:
            raise ValueError(f"unknown jump {self.name!r}; known {tuple(THESIS)}")
        if self.friction_max is not None and (self.contact != "kinematic" or not self.unilateral
                                              or not self.friction_max > 0):
            raise ValueError(f"friction_max: a positive μ for a kinematic-contact jump with unilateral=True, got "
                             f"{self.friction_max!r} for {self.name!r}")
        n_w = 4 if self.name == "ellipsoid" else 2
        if len(self.weights) != n_w:
            raise ValueError(f"{self.name}: {n_w} weights expected (Table 3.10)")
        if self.start_weights is not None and (len(self.start_weights) != n_w
                                               or tuple(self.start_weights) == tuple(self.weights)):
            raise ValueError(f"start_weights: {n_w} weights other than the spec's own, got {self.start_weights!r}")
        if len(self.durations) != len(self.phases):
            raise ValueError(f"{self.name}: one duration range per phase {self.phases}")

    @property
    def toe(self) -> bool:
        return self.name != "toeless"

    @property
    def contact(self) -> str:
        return "ellipsoid" if self.name == "ellipsoid" else "kinematic"

    @property
    def phases(self) -> tuple[str, ...]:
        return ("crouch", "thrust", "flight")

    @property
    def label(self) -> str:
        return LABELS[self.name]

    def to_dict(self) -> dict:
        """The spec as a dict; ``torque_limits`` at its default (the thesis's bounds) and
        ``friction_max``, ``start_from`` and ``start_weights`` while unset are left out, so the
        keys of the jumps stored before they existed stay."""
        d = asdict(self)
        if d["torque_limits"] == "table3.5":
            d.pop("torque_limits")
        for k in ("friction_max", "start_from", "start_weights"):
            if d[k] is None:
                d.pop(k)
        return d


#: The thesis's three jumps (Tables 3.8, 3.10) at our production mesh.
SPECS = {
    "toeless": JumpSpec("toeless", weights=(1.0, 12.0), dx_com=0.01),
    "toe": JumpSpec("toe", weights=(1.0, 1.0), dx_com=0.06),
    "ellipsoid": JumpSpec("ellipsoid", weights=(2.0, 1.0, 1.0, 5.0), dx_com=0.002),
}


def spec(name: str, **overrides) -> JumpSpec:
    """The thesis spec of jump ``name`` with fields replaced (e.g. ``n_intervals=5``)."""
    return replace(SPECS[name], **overrides)


# ======================================================================================
# Problem
# ======================================================================================
@dataclass(eq=False)
class JumpProblem:
    """A built jump: spec, model, the :class:`ocp.Problem`, mesh, options and guess."""

    spec: JumpSpec
    model: JumpModel
    problem: ocp.Problem
    mesh: dict
    options: ocp.SolverOptions
    guess: ocp.Guess
    p_contact: np.ndarray | None
    y_stand: float  # root height of the initial standing posture, m


def strength_envelope(model: JumpModel, legs: int = 2) -> dict:
    """The body's strength for :class:`JumpSpec` ``torque_limits="strength"``: the adult
    Gymnast MTGs scaled (Eq 5.21) to ``model``'s mass and standing height (its top,
    :attr:`JumpModel.standing_top`), × ``legs`` (the jump's legs are doubled).

    Returns ``{"peak": joint → (τ_min, τ_max) N·m`` (:func:`gaitlib.mtg.strength_limits`:
    the eccentric plateau; the metatarsal joint ± the ankle plantarflexors' peak),
    ``"envelope": joint → f(q, q̇) → (τ_min, τ_max)`` for hip, knee and ankle
    (:func:`gaitlib.mtg.max_joint_torque`, CasADi or float)}``."""
    kw = dict(body_mass=model.total_mass, body_height=model.standing_top)
    peak = mtg.strength_limits(None, legs=legs, **kw)

    def envelope_of(j):
        def f(q, qd):
            lo, hi = mtg.max_joint_torque(j, q, qd, None, **kw)
            return legs * lo, legs * hi
        return f
    return {"peak": peak, "envelope": {j: envelope_of(j) for j in mtg.MTG_JOINTS}}


def _names(model: JumpModel, free: bool):
    coords = list(model.coords if free else model.joints)
    return (coords, [f"qd_{c}" for c in coords], [f"tau_{j}" for j in model.joints],
            [f"taud_{j}" for j in model.joints])


def _full(x, names_q, names_qd, free):
    """Full (q, q̇) columns of a phase's Named state (welded: root at rest at 0)."""
    if free:
        return x[names_q], x[names_qd]
    z = ca.DM.zeros(3, 1)
    return ca.vertcat(z, x[names_q]), ca.vertcat(z, x[names_qd])


def standing_height(model: JumpModel, p_contact) -> float:
    """Root (MTP point) height, m, at which the standing posture at rest is carried by the
    ellipsoid contact alone (F_y = weight); negative: the MTP point is below the ground
    line because the ellipsoids penetrate."""
    from scipy.optimize import brentq

    W = model.total_mass * model.g
    z, zj = np.zeros(model.n), np.zeros(len(model.joints))
    f = model.function("contact")

    def excess(y):
        q = z.copy()
        q[1] = y
        return float(f(q, z, zj, p_contact)[3]) - W

    return brentq(excess, -0.03, 0.05, xtol=1e-12)


def build(sp: JumpSpec) -> JumpProblem:
    """Turn a :class:`JumpSpec` into an :class:`ocp.Problem` with mesh, options and guess.

    Phases, constraints and goals as in the module docstring. Dynamics: ``"explicit"``
    (thesis Eq 3.2, q̈ = M⁻¹F as a function of the states) or ``"implicit"`` (q̈ are extra
    controls and inverse dynamics − τ = 0, plus a zero root residual for the free model,
    are path constraints: the same continuous problem, sparser and much better conditioned
    with the light toe as root segment). Take-off and static-start events use the explicit
    functions at the phase's end node (they need the ground reaction of the states).
    """
    model = JumpModel(toe=sp.toe, damping=sp.damping)
    g = model.g
    W = model.total_mass * g
    joints = list(model.joints)
    com_f = model.function("com")
    pts_f = model.function("points")
    p_contact = contact_mod.default_params() if sp.contact == "ellipsoid" else None
    y_stand = standing_height(model, p_contact) if sp.contact == "ellipsoid" else 0.0
    pc = ca.DM(p_contact) if p_contact is not None else None
    TS = sp.tau_scale
    implicit = sp.dynamics == "implicit"
    jb = {j: joint_bounds(j) for j in joints}
    if sp.torque_limits in ("strength", "strength_peak"):
        peak = strength_envelope(model)["peak"]
        for j in joints:
            lo, hi = jb[j]["tau"]
            jb[j] = {**jb[j], "tau": (max(lo, peak[j][0]), min(hi, peak[j][1]))}

    def names(free):
        qn, qdn, taun, udn = _names(model, free)
        qddn = [f"qdd_{c}" for c in qn] if implicit else []
        return qn, qdn, taun, udn, qddn

    def bounds(free: bool, welded_heel: bool) -> dict:
        qn, qdn, taun, udn, qddn = names(free)
        b = {}
        for j in joints:
            lo, hi = jb[j]["q"]
            if welded_heel and j == "mtp":
                lo = max(lo, 0.0)  # the heel may not go through the ground
            b[j], b[f"qd_{j}"] = (lo, hi), jb[j]["qd"]
            b[f"tau_{j}"] = tuple(v / TS for v in jb[j]["tau"])
            b[f"taud_{j}"] = (-sp.taud_max / TS, sp.taud_max / TS)
        for c in qddn:
            b[c] = (-sp.qdd_max, sp.qdd_max)
        if free:
            b.update({"x": (-0.5, 0.5), "y": (-0.1 if sp.contact == "ellipsoid" else 0.0, 10.0),
                      "theta_z": (-math.pi / 2, math.pi / 2), "qd_x": (-5.0, 5.0),
                      "qd_y": (-20.0, 20.0), "qd_theta_z": (-30.0, 30.0)})
        return b

    def com(x, free):
        qn, qdn, _, _, _ = names(free)
        q, qd = _full(x, qn, qdn, free)
        return com_f(q, qd)

    # --- dynamics of the three kinds of phase ----------------------------------------
    def phase_model(kind):
        """(states, controls, dynamics, [path constraints]) of a 'welded' / 'flight' /
        'contact' phase; the τ states and τ̇ controls are in units of ``tau_scale``."""
        free = kind != "welded"
        qn, qdn, taun, udn, qddn = names(free)
        states, controls = tuple(qn + qdn + taun), tuple(udn + qddn)
        if not implicit:
            if kind == "welded":
                f = model.function("stance")

                def dyn(x, u, p, t):
                    return ca.vertcat(x[qdn], f(x[qn], x[qdn], TS * x[taun])[0], u[udn])
            elif kind == "flight":
                f = model.function("flight")

                def dyn(x, u, p, t):
                    return ca.vertcat(x[qdn], f(x[qn], x[qdn], TS * x[taun]), u[udn])
            else:
                f = model.function("contact")

                def dyn(x, u, p, t):
                    return ca.vertcat(x[qdn], f(x[qn], x[qdn], TS * x[taun], pc)[0], u[udn])
            return states, controls, dyn, []

        def dyn(x, u, p, t):
            return ca.vertcat(x[qdn], u[qddn], u[udn])

        if kind == "welded":
            fid = model.function("stance_id")

            def id_err(x, u, p, t):
                return (fid(x[qn], x[qdn], u[qddn])[0] - TS * x[taun]) / TS
        elif kind == "flight":
            fid = model.function("flight_id")

            def id_err(x, u, p, t):
                tau, res = fid(x[qn], x[qdn], u[qddn])
                return ca.vertcat((tau - TS * x[taun]) / TS, res / TS)
        else:
            fid = model.function("contact_id")

            def id_err(x, u, p, t):
                r = fid(x[qn], x[qdn], u[qddn], pc)
                return ca.vertcat((r[0] - TS * x[taun]) / TS, r[1] / TS)
        return states, controls, dyn, [ocp.PathConstraint("inverse_dynamics", id_err)]

    # --- ground reaction at a node (explicit functions of the states) -----------------
    if sp.contact == "kinematic":
        stance = model.function("stance")
        qn_w, qdn_w, taun, _, _ = names(False)

        def grf_end(x):  # welded phase: (F_x, F_y) from the root reaction
            return stance(x[qn_w], x[qdn_w], TS * x[taun])[1][:2]
    else:
        contact_f = model.function("contact")
        qn_f, qdn_f, taun, _, _ = names(True)

        def grf_end(x):  # ellipsoids: (F_x, F_y), functions of q, q̇ only
            r = contact_f(x[qn_f], x[qdn_f], TS * x[taun], pc)
            return ca.vertcat(r[2], r[3])

    # --- pieces shared by the phases ---------------------------------------------------
    x_ref = "x_com0"  # static parameter: the COM's initial horizontal position, m
    contact_free = sp.contact == "ellipsoid"

    def com_band(free):
        return ocp.PathConstraint("com_x_band", lambda x, u, p, t: com(x, free)[0][0] - p[x_ref],
                                  -sp.dx_com, sp.dx_com)

    def com_start(free):
        return ocp.EndpointConstraint("x_com0", lambda x0, xf, p, t0, tf: com(x0, free)[0][0] - p[x_ref])

    static_start = ocp.EndpointConstraint(  # Table 3.7: a_COM = 0 ⟺ GRF = (0, W)
        "static_start_a_com", lambda x0, xf, p, t0, tf: grf_end(x0) - ca.DM([0.0, W]))
    takeoff_goal = ocp.Goal("v_takeoff", weight=sp.weights[-2], endpoint=lambda x0, xf, p, t0, tf:
                            (sp.v_des / com(xf, contact_free)[1][1]) ** 2)
    apex_goal = ocp.Goal("apex_height", weight=sp.weights[-1], endpoint=lambda x0, xf, p, t0, tf:
                         (sp.y_des / com(xf, True)[0][1]) ** 2)
    vy_up = ocp.EndpointConstraint("vy_takeoff_positive",
                                   lambda x0, xf, p, t0, tf: com(xf, contact_free)[1][1], 0.1, np.inf)
    apex = ocp.EndpointConstraint("apex_vy_zero", lambda x0, xf, p, t0, tf: com(xf, True)[1][1])

    # Ballistic flight (our addition; exact physics): with no external force the COM's
    # height is y0 + vy0 s − g s²/2 and its vertical velocity vy0 − g s, s = t − t_TO.
    # Imposed at the apex node (``"apex"``) or at every collocation node too (``"nodes"``),
    # with (t_TO, y0, vy0) static parameters tied to the flight's first node. Without it
    # IPOPT can "gain" height in flight from the collocation error of the light, fast
    # spinning root segment (the toe).
    def ballistic(x, t, p):
        s_ = t - p["t_to"]
        c, v = com(x, True)
        return ca.vertcat(c[1] - (p["y_to"] + p["vy_to"] * s_ - 0.5 * g * s_**2),
                          v[1] - (p["vy_to"] - g * s_))

    flight_path = [com_band(True)]
    flight_ends = [apex, ocp.EndpointConstraint(  # the last node is not a collocation node
        "com_x_band_end", lambda x0, xf, p, t0, tf: com(xf, True)[0][0] - p[x_ref],
        -sp.dx_com, sp.dx_com)]
    if sp.ballistic_flight == "nodes":
        flight_path.append(ocp.PathConstraint("ballistic_com", lambda x, u, p, t: ballistic(x, t, p)))
    if sp.ballistic_flight in ("nodes", "apex"):
        flight_ends += [
            ocp.EndpointConstraint("takeoff_state", lambda x0, xf, p, t0, tf: ca.vertcat(
                p["t_to"] - t0, p["y_to"] - com(x0, True)[0][1], p["vy_to"] - com(x0, True)[1][1])),
            ocp.EndpointConstraint("ballistic_apex", lambda x0, xf, p, t0, tf: ballistic(xf, tf, p)),
        ]

    d = sp.durations
    t_max = sum(hi for _, hi in d)
    qn_f, qdn_f, _, _, _ = names(True)
    qn_w, qdn_w, _, _, _ = names(False)
    if sp.contact == "kinematic":
        st, ct, dyn, pcs = phase_model("welded")
        path_pre = [com_band(False)] + pcs
        if sp.unilateral:
            stance_id = model.function("stance_id")
            if implicit:  # the welded foot's (F_x, F_y)
                fxy = lambda x, u, p, t: stance_id(x[qn_w], x[qdn_w], u[names(False)[4]])[1]  # noqa: E731
            else:
                fxy = lambda x, u, p, t: stance(x[qn_w], x[qdn_w], TS * x[names(False)[2]])[1]  # noqa: E731
            path_pre.append(ocp.PathConstraint("unilateral_fy", lambda x, u, p, t: fxy(x, u, p, t)[1], 0.0, np.inf))
            if sp.friction_max is not None:  # ours: |F_x| ≤ μ F_y, two smooth rows
                def cone(x, u, p, t):
                    f = fxy(x, u, p, t)
                    return ca.vertcat(sp.friction_max * f[1] - f[0], sp.friction_max * f[1] + f[0])
                path_pre.append(ocp.PathConstraint("friction_cone", cone, 0.0, np.inf))
        # The thesis's preflight phase, split into crouch + thrust at a free instant for
        # the mesh only (states continuous, no constraint at the split): the thrust, a
        # few tenths of a second, gets its own intervals (GPOPS-II refined its mesh there).
        welded_b = bounds(False, sp.toe)
        crouch = ocp.Phase(
            "crouch", st, ct, dyn, t0=0.0, tf=d[0], bounds=welded_b,
            initial={**{j: 0.0 for j in qn_w}, **{v: 0.0 for v in qdn_w}},
            path_constraints=tuple(path_pre),
            endpoint_constraints=(com_start(False), static_start),
        )
        thrust = ocp.Phase(
            "thrust", st, ct, dyn, t0=(0.0, t_max), tf=(0.0, t_max), duration=d[1],
            bounds=welded_b, path_constraints=tuple(path_pre),
            endpoint_constraints=(
                ocp.EndpointConstraint("takeoff_fy_zero", lambda x0, xf, p, t0, tf: grf_end(xf)[1]),
                vy_up),
            goals=(takeoff_goal,),
        )
        st, ct, dyn, pcs = phase_model("flight")
        clearance = []
        if sp.flight_clearance:
            def above_ground(x, u, p, t):
                P = pts_f(x[qn_f])
                out = [P[pts_f.name_out().index("ankle")][1]]
                if sp.toe:
                    out.append(P[pts_f.name_out().index("toe_tip")][1])
                return ca.vertcat(*out)
            clearance = [ocp.PathConstraint("above_ground", above_ground, 0.0, np.inf)]
        fl = ocp.Phase(
            "flight", st, ct, dyn, t0=(0.0, t_max), tf=(0.0, t_max), duration=d[2],
            bounds=bounds(True, False),
            initial={"x": 0.0, "y": 0.0, "theta_z": 0.0, "qd_x": 0.0, "qd_y": 0.0,
                     "qd_theta_z": 0.0},
            path_constraints=tuple(flight_path + pcs + clearance),
            endpoint_constraints=tuple(flight_ends),
            goals=(apex_goal,),
        )
        phases = [crouch, thrust, fl]
    else:
        st, ct, dyn, pcs = phase_model("contact")
        b = bounds(True, False)
        on_ground = pcs
        if sp.contact_fy_min is not None:  # the feet stay on the ground until take-off
            on_ground = pcs + [ocp.PathConstraint(
                "feet_on_ground", lambda x, u, p, t: grf_end(x)[1], sp.contact_fy_min * W, np.inf)]
        knee_des = sp.knee_des_deg * cv.DEG
        w = sp.weights
        crouch = ocp.Phase(
            "crouch", st, ct, dyn, t0=0.0, tf=d[0], bounds=b,
            initial={"x": 0.0, **{j: 0.0 for j in joints}, **{v: 0.0 for v in qdn_f}},
            path_constraints=tuple([com_band(True)] + on_ground),
            endpoint_constraints=(com_start(True), static_start),
            goals=(
                ocp.Goal("knee_angle", weight=w[0],
                         endpoint=lambda x0, xf, p, t0, tf: (xf["knee"] - knee_des) ** 2),
                ocp.Goal("knee_velocity", weight=w[1],
                         endpoint=lambda x0, xf, p, t0, tf: xf["qd_knee"] ** 2),
            ),
        )
        thrust = ocp.Phase(
            "thrust", st, ct, dyn, t0=(0.0, t_max), tf=(0.0, t_max), duration=d[1], bounds=b,
            path_constraints=tuple([com_band(True)] + pcs),
            endpoint_constraints=(
                ocp.EndpointConstraint("takeoff_fy", lambda x0, xf, p, t0, tf: grf_end(xf)[1],
                                       0.0, sp.fy_takeoff),
                vy_up),
            goals=(takeoff_goal,),
        )
        fl = ocp.Phase(
            "flight", st, ct, dyn, t0=(0.0, t_max), tf=(0.0, t_max), duration=d[2], bounds=b,
            path_constraints=tuple(flight_path + pcs + ([] if sp.flight_fy_max is None else [
                ocp.PathConstraint("feet_off_ground", lambda x, u, p, t: grf_end(x)[1], 0.0,
                                   sp.flight_fy_max)])),
            endpoint_constraints=tuple(flight_ends),
            goals=(apex_goal,),
        )
        phases = [crouch, thrust, fl]

    if sp.torque_limits == "strength":  # the MTG envelope at every node of every phase
        env = strength_envelope(model)["envelope"]
        mtg_joints = [j for j in joints if j in env]

        def strength(x, u, p, t):
            rows = []
            for j in mtg_joints:
                lo, hi = env[j](x[j], x[f"qd_{j}"])
                rows += [(TS * x[f"tau_{j}"] - hi) / TS, (TS * x[f"tau_{j}"] - lo) / TS]
            return ca.vertcat(*rows)
        n = len(mtg_joints)
        lb = np.tile([-np.inf, 0.0], n)
        ub = np.tile([0.0, np.inf], n)
        phases = [replace(ph, path_constraints=ph.path_constraints + (
            ocp.PathConstraint("strength", strength, lb, ub),)) for ph in phases]

    if sp.w_reg:
        def reg(x, u, p, t):
            return ca.sumsqr(TS * u[[f"taud_{j}" for j in joints]]) / sp.taud_max**2
        phases = [replace(ph, goals=ph.goals + (ocp.Goal("reg_taud", weight=sp.w_reg, integrand=reg),))
                  for ph in phases]
    linkages = tuple(ocp.Linkage(a.name, b.name) for a, b in zip(phases[:-1], phases[1:]))
    params = [ocp.Parameter(x_ref, -1.0, 1.0)]
    if sp.ballistic_flight in ("nodes", "apex"):
        params += [ocp.Parameter("t_to", 0.0, t_max), ocp.Parameter("y_to", -1.0, 5.0),
                   ocp.Parameter("vy_to", -20.0, 20.0)]
    problem = ocp.Problem(tuple(phases), parameters=tuple(params), linkages=linkages,
                          name=f"jump_{sp.name}")
    mesh = meshes(sp)
    options = ocp.SolverOptions(tol=sp.tol, constr_viol_tol=sp.tol, max_iter=sp.max_iter,
                                print_level=sp.print_level, ipopt=dict(sp.ipopt))
    jp = JumpProblem(sp, model, problem, mesh, options, ocp.Guess(), p_contact, y_stand)
    jp.guess = initial_guess(jp)
    return jp


def meshes(sp: JumpSpec) -> dict[str, Mesh]:
    """Per-phase LGR meshes: ``n_intervals`` × ``degree`` each; the thrust's interval widths
    shrink geometrically towards take-off (first / last = ``thrust_refine``), where the
    ground force falls to zero within a few hundredths of a second (GPOPS-II's hp mesh
    refined there adaptively)."""
    n = sp.n_intervals
    out = {p: Mesh(n, "lgr", sp.degree) for p in sp.phases}
    if sp.thrust_refine != 1.0 and n > 1:
        r = sp.thrust_refine ** (-1.0 / (n - 1))
        out["thrust"] = Mesh(n, "lgr", sp.degree, fractions=tuple(r**k for k in range(n)))
    return out


# ======================================================================================
# Initial guess
# ======================================================================================
#: Guess postures (deg, our convention) standing → bottom of the crouch → take-off, in the
#: spirit of the thesis's Table 3.6 guess points (which came from experimental jumps,
#: Pandy et al. 1990, and are only drawn). The hip is then adjusted so that the COM stays
#: above its standing position.
GUESS_POSTURES = {
    "crouch": {"mtp": 0.0, "ankle": 30.0, "knee": -90.0, "hip": 70.0},
    "takeoff": {"mtp": 30.0, "ankle": -10.0, "knee": -10.0, "hip": 10.0},
    "takeoff_toeless": {"ankle": -15.0, "knee": -10.0, "hip": 10.0},
}
#: Guess phase durations, s.
GUESS_TIMES = {"crouch": 0.55, "thrust": 0.35, "flight": 0.35}


def _balanced_hip(model: JumpModel, qj: dict, x_target: float) -> dict:
    """Adjust the hip angle (rad) so that the welded model's COM x equals ``x_target``."""
    from scipy.optimize import brentq

    joints = list(model.joints)

    def err(h):
        v = dict(qj, hip=h)
        q = np.r_[0.0, 0.0, 0.0, [v[j] for j in joints]]
        return float(model.com(q)[0][0]) - x_target

    try:
        h = brentq(err, -0.5, 2.0)
    except ValueError:
        h = qj["hip"]
    return dict(qj, hip=h)


def initial_guess(jp: JumpProblem) -> ocp.Guess:
    """A guess from :data:`GUESS_POSTURES` (clamped cubic splines through standing, crouch
    and take-off), torques from inverse dynamics of the welded model along it, a flight
    with the take-off posture and a rising root."""
    from scipy.interpolate import CubicSpline

    sp, model = jp.spec, jp.model
    joints = list(model.joints)
    x0 = float(model.com(np.zeros(model.n))[0][0])
    crouch = {j: GUESS_POSTURES["crouch"][j] * cv.DEG for j in joints}
    key = "takeoff" if sp.toe else "takeoff_toeless"
    take = {j: GUESS_POSTURES[key][j] * cv.DEG for j in joints}
    crouch = _balanced_hip(model, crouch, x0)
    take = _balanced_hip(model, take, x0)
    t1, t2 = GUESS_TIMES["crouch"], GUESS_TIMES["thrust"]
    T = t1 + t2
    knots = np.array([0.0, t1, T])
    Qk = np.array([[0.0] * len(joints), [crouch[j] for j in joints], [take[j] for j in joints]])
    zj = np.zeros(len(joints))
    spl = CubicSpline(knots, Qk, axis=0, bc_type=((1, zj), (2, zj)))
    n = 60
    tt = np.linspace(0.0, T, n)
    qj, qdj, qddj = spl(tt), spl(tt, 1), spl(tt, 2)
    sid = model.function("stance_id")
    tau = np.array([np.asarray(sid(qj[k], qdj[k], qddj[k])[0]).ravel() for k in range(n)])
    taud = np.gradient(tau, tt, axis=0)
    lim = sp.taud_max
    taud = np.clip(taud, -lim, lim)

    def frame(t, cols):
        return pd.DataFrame(cols, index=pd.Index(t, name="time"))

    qn_f, qdn_f, taun, udn = _names(model, True)
    jcols = {j: qj[:, i] for i, j in enumerate(joints)}
    jvel = {f"qd_{j}": qdj[:, i] for i, j in enumerate(joints)}
    TS = sp.tau_scale
    tcols = {f"tau_{j}": tau[:, i] / TS for i, j in enumerate(joints)}
    ucols = {f"taud_{j}": taud[:, i] / TS for i, j in enumerate(joints)}
    implicit = sp.dynamics == "implicit"
    if implicit:
        ucols.update({f"qdd_{j}": qddj[:, i] for i, j in enumerate(joints)})

    # flight: take-off posture held, root rising smoothly by 0.3 m
    Tf = GUESS_TIMES["flight"]
    tf_ = np.linspace(0.0, Tf, 30)
    rise = 0.15 * (1 - np.cos(np.pi * tf_ / Tf)) * 2
    rise_d = 0.3 * np.pi / Tf * 0.5 * np.sin(np.pi * tf_ / Tf) * 2
    fl = {j: np.full_like(tf_, qj[-1, i]) for i, j in enumerate(joints)}
    fl.update({"x": 0 * tf_, "y": jp.y_stand + rise, "theta_z": 0 * tf_,
               "qd_x": 0 * tf_, "qd_y": rise_d, "qd_theta_z": 0 * tf_})
    fl.update({f"qd_{j}": 0 * tf_ for j in joints})
    fl.update({f"tau_{j}": np.full_like(tf_, tau[-1, i] / TS) for i, j in enumerate(joints)})
    fl_u = {f"taud_{j}": 0 * tf_ for j in joints}
    if implicit:
        fl_u.update({f"qdd_{c}": 0 * tf_ for c in model.coords})
        fl_u["qdd_y"] = 0.3 * (np.pi / Tf) ** 2 * np.cos(np.pi * tf_ / Tf)
    phases = {}
    allc = {**jcols, **jvel, **tcols}
    if sp.contact == "ellipsoid":
        allc.update({"x": 0 * tt, "y": np.full_like(tt, jp.y_stand), "theta_z": 0 * tt,
                     "qd_x": 0 * tt, "qd_y": 0 * tt, "qd_theta_z": 0 * tt})
        if implicit:
            ucols.update({"qdd_x": 0 * tt, "qdd_y": 0 * tt, "qdd_theta_z": 0 * tt})
    i1 = tt <= t1 + 1e-12
    i2 = tt >= tt[i1][-1] - 1e-12
    for name, i in (("crouch", i1), ("thrust", i2)):
        phases[name] = ocp.PhaseGuess(
            states=frame(tt[i], {k: v[i] for k, v in allc.items()}),
            controls=frame(tt[i], {k: v[i] for k, v in ucols.items()}))
    phases["flight"] = ocp.PhaseGuess(states=frame(T + tf_, fl), controls=frame(T + tf_, fl_u))
    return ocp.Guess(phases=phases, parameters={"x_com0": x0})


# ======================================================================================
# Solution
# ======================================================================================
@dataclass(eq=False)
class JumpSolution:
    """A solved jump.

    Attributes
    ----------
    spec : JumpSpec
    solution : gaitlib.ocp.Solution
        The raw solution: ``status`` (IPOPT's), ``success``, ``iterations``, ``solve_time``…
    trajectory : DataFrame
        One row per state node of every phase (the node shared by two phases appears in
        both), index ``time`` (s). Columns: ``phase``; root ``x, y`` (MTP point, m) and
        ``theta_z`` (root segment angle, rad; 0 for the welded phase); joint angles (rad);
        ``qd_*``; ``tau_*`` (N·m); ``grf_x, grf_y`` (N, both feet; 0 in the kinematic
        flight); ``cop_x`` (m: the welded phase's centre of pressure; for the ellipsoids
        the normal-force-weighted mean of the ellipsoid centres' x, a drawing aid);
        ``friction_ratio`` = |F_x/F_y| (Eq 3.6; NaN where
        F_y < ``fy_min_fraction`` × weight); ``com_x, com_y`` (m), ``com_vx, com_vy``
        (m/s); ``ankle_x, ankle_y`` (m); ``foot_angle`` (absolute angle of the foot
        segment relative to standing, rad, CCW +: negative when the heel is raised).
    jump_height : dict
        ``com_rise_flight``, ``ballistic`` (v_y,TO² / 2g), ``com_rise_standing``,
        ``foot_lift``, all m; ``takeoff_time`` s, ``takeoff_vy`` m/s.
    required_friction : float
        max |F_x/F_y| over the contact phases (Eq 3.6).
    """

    spec: JumpSpec
    model: JumpModel
    solution: ocp.Solution
    trajectory: pd.DataFrame
    jump_height: dict
    required_friction: float
    p_contact: Any = None
    from_cache: bool = False

    @property
    def success(self) -> bool:
        return self.solution.success

    @property
    def status(self) -> str:
        return self.solution.status

    @property
    def angles(self) -> pd.DataFrame:
        """Joint angles, rad (index time, plus ``phase``)."""
        return self.trajectory[["phase"] + list(self.model.joints)]

    @property
    def torques(self) -> pd.DataFrame:
        """Joint torques, N·m."""
        return self.trajectory[["phase"] + [f"tau_{j}" for j in self.model.joints]]

    @property
    def grf(self) -> pd.DataFrame:
        """Ground reaction force of both feet, N, and |F_x/F_y|."""
        return self.trajectory[["phase", "grf_x", "grf_y", "friction_ratio"]]

    @property
    def foot(self) -> pd.DataFrame:
        """MTP point position (m), toe (root) angle and foot angle (rad)."""
        return self.trajectory[["phase", "x", "y", "theta_z", "foot_angle"]]

    @property
    def stats(self) -> dict:
        s = self.solution
        return {"status": s.status, "success": s.success, "iterations": s.iterations,
                "solve_time_s": s.solve_time, "time_per_iteration_ms": 1e3 * s.time_per_iteration,
                "build_time_s": s.build_time, "objective": s.objective,
                "max_violation": s.max_violation, "n_variables": s.info.get("n_variables"),
                "n_constraints": s.info.get("n_constraints"),
                "mesh": f"{self.spec.n_intervals} x {self.spec.degree} LGR per phase",
                "continuation": " → ".join(
                    f"{'the ' + c['start_from'] + ' jump, ' if 'start_from' in c else ''}{c['n_intervals']}"
                    f"{' (' + c['torque_limits'] + ')' if 'torque_limits' in c else ''}: "
                    f"{c['status']} ({c['iterations']} it, "
                    f"{c['solve_time']:.1f} s)" for c in s.info.get("continuation", [])) or "–",
                "from_cache": self.from_cache}

    def poses(self) -> tuple[np.ndarray, np.ndarray]:
        """(t (n,), Q (n, n_coords)) free coordinates over the whole jump (for animation),
        the duplicated phase-boundary nodes dropped."""
        tr = self.trajectory
        keep = ~pd.Index(tr.index).duplicated(keep="last")
        tr = tr[keep]
        return tr.index.to_numpy(float), tr[list(self.model.coords)].to_numpy(float)


def _trajectory(sp: JumpSpec, model: JumpModel, p_contact, sol: ocp.Solution) -> pd.DataFrame:
    """The tidy frame of :class:`JumpSolution` (see there) from a raw solution."""
    joints = list(model.joints)
    coords = list(model.coords)
    W = model.total_mass * model.g
    com_f, pts_f = model.function("com"), model.function("points")
    frames = []
    for name in sp.phases:
        st = sol.phases[name].states
        n = len(st)
        free = all(c in st.columns for c in ("x", "y", "theta_z"))
        Q = np.zeros((n, model.n))
        QD = np.zeros((n, model.n))
        for i, c in enumerate(coords):
            if c in st.columns:
                Q[:, i] = st[c].to_numpy()
                QD[:, i] = st[f"qd_{c}"].to_numpy()
        TAU = sp.tau_scale * st[[f"tau_{j}" for j in joints]].to_numpy()
        if sp.contact == "kinematic" and not free:
            f = model.function("stance")
            R = [f(Q[k, 3:], QD[k, 3:], TAU[k]) for k in range(n)]
            G = np.array([np.asarray(r[1]).ravel() for r in R])
            fx, fy = G[:, 0], G[:, 1]
            cop = np.array([float(r[2]) for r in R])
        elif sp.contact == "kinematic":
            fx = fy = np.zeros(n)
            cop = np.full(n, np.nan)
        else:
            f = model.function("contact")
            ell = model.function("ellipsoids")
            R = [f(Q[k], QD[k], TAU[k], p_contact) for k in range(n)]
            fx = np.array([float(r[2]) for r in R])
            fy = np.array([float(r[3]) for r in R])
            fn = np.array([np.asarray(r[1]).ravel() for r in R])
            cx = np.array([np.asarray(ell(Q[k], p_contact)[0])[:, 0] for k in range(n)])
            with np.errstate(divide="ignore", invalid="ignore"):
                cop = np.where(fn.sum(1) > 0, (fn * cx).sum(1) / fn.sum(1), np.nan)
        C = [com_f(Q[k], QD[k]) for k in range(n)]
        com = np.array([np.asarray(c[0]).ravel() for c in C])
        comv = np.array([np.asarray(c[1]).ravel() for c in C])
        ank = np.array([np.asarray(pts_f(Q[k])[1]).ravel() for k in range(n)])
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(fy >= sp.fy_min_fraction * W, np.abs(fx / fy), np.nan)
        foot_angle = Q[:, 2] - (Q[:, coords.index("mtp")] if "mtp" in coords else 0.0)
        df = pd.DataFrame({"phase": name}, index=pd.Index(st.index.to_numpy(float), name="time"))
        for i, c in enumerate(coords):
            df[c] = Q[:, i]
        for i, c in enumerate(coords):
            df[f"qd_{c}"] = QD[:, i]
        for i, j in enumerate(joints):
            df[f"tau_{j}"] = TAU[:, i]
        df["grf_x"], df["grf_y"], df["friction_ratio"] = fx, fy, ratio
        df["cop_x"] = cop
        df["com_x"], df["com_y"], df["com_vx"], df["com_vy"] = com[:, 0], com[:, 1], comv[:, 0], comv[:, 1]
        df["ankle_x"], df["ankle_y"] = ank[:, 0], ank[:, 1]
        df["foot_angle"] = foot_angle
        frames.append(df)
    return pd.concat(frames)


def _heights(sp: JumpSpec, tr: pd.DataFrame, g: float) -> dict:
    to_phase = sp.phases[-2]
    to = tr[tr["phase"] == to_phase].iloc[-1]
    ap = tr[tr["phase"] == "flight"].iloc[-1]
    st = tr.iloc[0]
    return {
        "com_rise_flight": float(ap["com_y"] - to["com_y"]),
        "ballistic": float(to["com_vy"] ** 2 / (2 * g)),
        "com_rise_standing": float(ap["com_y"] - st["com_y"]),
        "foot_lift": float(ap["y"] - st["y"]),
        "takeoff_time": float(to.name),
        "takeoff_vy": float(to["com_vy"]),
        "apex_time": float(ap.name),
    }


def _result(sp: JumpSpec, model: JumpModel, p_contact, sol: ocp.Solution) -> JumpSolution:
    tr = _trajectory(sp, model, p_contact, sol)
    contact = tr[tr["phase"] != "flight"]
    req = (float(np.nanmax(contact["friction_ratio"])) if contact["friction_ratio"].notna().any()
           else float("nan"))
    return JumpSolution(sp, model, sol, tr, _heights(sp, tr, model.g), req, p_contact)


def cache_location(sp: "JumpSpec", root=None):
    """Where the solution of ``sp`` is (or would be) cached: keyed by the spec, the core
    sources, the jump model and this study (:mod:`gaitlib.cache`)."""
    return cache.lookup("jump", {"kind": "jump", **sp.to_dict()}, root, formulation=FORMULATION, identified=())


def solve(sp: JumpSpec | str, guess: ocp.Guess | ocp.Solution | None = None, *,
          use_cache: bool = False, root=None) -> JumpSolution:
    """Build and solve one jump; returns a :class:`JumpSolution` whatever IPOPT's verdict
    (check ``.success`` / ``.status``).

    ``use_cache``: reload the solution stored under the key of this spec *and* of the
    library's code and data (:mod:`gaitlib.cache`: never a stale entry), or solve and
    store it. Failed solves are stored and reloaded as failed. ``from_cache`` in
    :attr:`JumpSolution.stats` says which; times are those of the original solve.
    """
    if isinstance(sp, str):
        sp = SPECS[sp]
    cached = use_cache and guess is None  # a warm-started solve is not the spec's solution

    def load(found):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ocp.SolveFailedWarning)
            return ocp.Solution.load(found), True

    sol, from_cache = cache.solve_or_load(cache_location(sp, root) if cached else None,
                                          lambda: (_solve_continued(sp, guess, root), False), load,
                                          marker="solution.json", use_cache=cached,
                                          write=lambda s_f: s_f[0].save)
    model = JumpModel(toe=sp.toe, damping=sp.damping)
    p_contact = contact_mod.default_params() if sp.contact == "ellipsoid" else None
    out = _result(sp, model, p_contact, sol)
    out.from_cache = from_cache
    return out


def _solve_continued(sp: JumpSpec, guess, root=None) -> ocp.Solution:
    """Solve ``sp`` from ``guess``, or, without one, through its mesh continuation
    (:attr:`JumpSpec.continuation`: each coarser mesh warm-starts the next)."""
    record, start = [], None
    own_start = guess is None and sp.start_from is None and sp.start_weights is None
    steps = [n for n in sp.continuation if n < sp.n_intervals] if own_start else []
    if sp.start_weights is not None and guess is None:  # from this jump's solution with other weights (see JumpSpec)
        src = solve(replace(sp, weights=tuple(sp.start_weights), start_weights=None), use_cache=True, root=root)
        record.append({"start_weights": list(sp.start_weights), "n_intervals": src.spec.n_intervals,
                       "torque_limits": sp.torque_limits, "status": src.status, "iterations": src.solution.iterations,
                       "solve_time": src.solution.solve_time, "build_time": src.solution.build_time,
                       "objective": src.solution.objective,
                       **src.jump_height, "required_friction": src.required_friction})
        guess = src.solution
    elif sp.start_from is not None and guess is None:  # from another jump's solution (see JumpSpec)
        src = solve(replace(SPECS[sp.start_from], torque_limits=sp.torque_limits), use_cache=True, root=root)
        record.append({"start_from": sp.start_from, "n_intervals": src.spec.n_intervals,
                       "torque_limits": sp.torque_limits, "status": src.status, "iterations": src.solution.iterations,
                       "solve_time": src.solution.solve_time, "build_time": src.solution.build_time,
                       "objective": src.solution.objective,
                       **src.jump_height, "required_friction": src.required_friction})
        start = src.solution
    if sp.torque_limits == "strength" and guess is None and steps:  # from the box-limited jump (see JumpSpec)
        pre = solve(replace(sp, torque_limits="strength_peak", n_intervals=steps[0], continuation=()),
                    use_cache=True, root=root)
        record.append({"n_intervals": steps[0], "torque_limits": "strength_peak", "status": pre.status,
                       "iterations": pre.solution.iterations, "solve_time": pre.solution.solve_time,
                       "build_time": pre.solution.build_time, "objective": pre.solution.objective,
                       **pre.jump_height, "required_friction": pre.required_friction})
        guess = pre.solution
    for n in steps:
        coarse = solve(replace(sp, n_intervals=n, continuation=()), guess)
        c = coarse.solution
        record.append({"n_intervals": n, "status": c.status, "iterations": c.iterations,
                       "solve_time": c.solve_time, "build_time": c.build_time,
                       "objective": c.objective, **coarse.jump_height,
                       "required_friction": coarse.required_friction})
        guess = c
    jp = build(sp)
    if start is not None:
        guess = guess_across(start, jp.problem)
    tx = ocp.transcribe(jp.problem, jp.mesh, jp.options)
    sol = tx.solve(jp.guess if guess is None else guess)
    sol.info["continuation"] = record
    return sol


def guess_across(sol: ocp.Solution, problem: ocp.Problem) -> ocp.Guess:
    """A guess for ``problem`` from a solution of another jump model (:attr:`JumpSpec.start_from`):
    per phase of the same name, the states and controls both have, those ``sol`` lacks at 0
    (for the toeless → toe-included model: the metatarsal angle, rate, torque and their
    derivatives, i.e. the foot flat on its toe); names ``problem`` lacks are dropped; the
    static parameters keep their defaults."""
    phases = {}
    for ph in problem.phases:
        ps = sol.phases.get(ph.name)
        if ps is None:
            continue
        st = ps.states.reindex(columns=list(ph.states), fill_value=0.0)
        co = ps.controls.reindex(columns=list(ph.controls), fill_value=0.0)
        phases[ph.name] = ocp.PhaseGuess(time=None, states=st, controls=co, t0=ps.t0, tf=ps.tf)
    return ocp.Guess(phases=phases)
