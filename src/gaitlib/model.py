"""Planar multibody models: a generic planar-tree builder and the 11-DOF child gait model.

Everything here is a CasADi SX expression built **once per model instance** and exposed
through cached :class:`casadi.Function` objects. The public methods accept numbers (return
numpy arrays) or CasADi SX/MX expressions (return CasADi expressions); the raw functions are
available from :meth:`ChildModel.function` for ``map``-ing over collocation nodes.

Symbol legend
-------------
==========  ======================================================  =========
symbol      meaning                                                 unit
==========  ======================================================  =========
q           generalised coordinates, order ``conventions.COORDS``   m, rad
qd, qdd     their first and second time derivatives                 /s, /s²
tau         the 8 joint torques, order ``conventions.JOINTS``       N·m
R           pelvis residual loads ``conventions.RESIDUALS``         N, N, N·m
p_body      the 25 body/joint parameters (:data:`P_BODY_NAMES`)     SI
p_contact   the 39 contact parameters, left foot (gaitlib.contact)  SI
M, h        mass matrix and bias (Coriolis, centrifugal, gravity)
Q_*         generalised forces (n,) conjugate to q
==========  ======================================================  =========

Equation of motion (thesis Eq. 3.1 / 4.10)::

    M(q) qdd + h(q, qd) = [R; tau] + Q_passive + Q_contact,
    Q_passive = [0, 0, 0, -K q_j - B qd_j],
    Q_contact = sum_e J_c,e^T [fx_e, fy_e] + J_theta,e^T mz_e.

Inverse dynamics returns ``[R; tau] = M qdd + h - Q_passive - Q_contact`` computed by a
planar recursive Newton-Euler pass (no mass matrix, no inversion), which is the cheap
implicit-dynamics path constraint of the optimal control problem.

Geometry of the child model (thesis Sec 4.1.1, Tables 4.1-4.3, Fig 4.1)
------------------------------------------------------------------------
Every body frame has its origin at the body's proximal joint (HAT: the hip joint centre)
and, in the standing posture (all q = 0), axes parallel to the ground frame (X forward,
Y up). Segment lengths are fractions of body height BH, masses fractions of body mass BM,
``MOI = SM (ROG SL)^2``.

* HAT: hip -> top, length 0.288 BH, COM 0.626 SL *above* the hip (fixed, not identified).
* thigh, shank: vertical, COM measured *down* from the proximal joint (0.433 SL).
* hind-fore-foot: one rigid body, origin at the ankle A, carrying the fore-foot piece AM
  (ankle -> metatarsal point M) and the hind-foot piece HA (heel H -> ankle), the two at the
  fixed angle beta = 106 deg. In standing both H and M are on the ground, so AM is
  ``phi1`` below the horizontal and AH is ``phi2 = 180 - beta - phi1`` below the horizontal
  (backwards); the ankle height is :func:`gaitlib.conventions.ankle_height`. The piece COMs
  lie on the pieces at distances ``com_forefoot`` (from A towards M) and ``com_hindfoot``
  (from A towards H) -- both measured from the ankle, the hind-fore-foot's joint; with the
  default fraction 0.5 this is the midpoint either way. Masses add; the inertia about the
  combined COM is ``I_ff + I_hf + sum m_i |c_i - c|^2`` (parallel axis).
* toe: origin at the metatarsal (MTP) joint M, horizontal on the ground in standing, tip at
  ``MT = 0.043 BH`` forward, COM at ``com_toe`` from M.

Contact ellipsoid placement (interpretation of thesis Sec 4.1.2)
----------------------------------------------------------------
"The parameters are expressed with respect to segment-fixed local coordinate systems ...
in standing posture the segment-fixed local coordinate systems have the same position and
orientation as the GCS." We read this as: ``r = (r_x, r_y, r_z)`` is the ellipsoid centre
in a *foot frame* whose origin is the ground point directly below the ankle in the standing
posture, axes parallel to the ground frame (X forward, Y up, Z lateral). The toe ellipsoid
rides on the toe segment, ball and heel on the hind-fore-foot; ``r`` is converted to the
carrying segment's body frame with that segment's standing pose (subtract the segment
origin's standing position in the foot frame). The ellipsoid rotation in the ground frame is
``Rz(theta_segment) @ R_local`` with ``R_local = contact.ellipsoid_to_segment(gamma, beta, alpha)`` (the
direction-cosine reading of the Euler angles, see that function for why).
The parameters are the LEFT foot's; the right foot uses ``contact.mirror`` (reflection in
the sagittal plane: ``S R S``, ``S r`` with ``S = diag(1, 1, -1)``). The lateral coordinate
of a centre is ``r_z`` (``-r_z`` on the right) with zero velocity: the model is planar. The
contact loads ``(fx, fy)`` act at the ellipsoid centre and ``mz`` (about the centre) on the
carrying segment.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Sequence

import casadi as ca
import numpy as np

from gaitlib import conventions as cv
from gaitlib import contact

__all__ = [
    "PlanarBody",
    "PlanarTree",
    "Inertia",
    "Load",
    "ChildModel",
    "P_BODY_NAMES",
    "P_BODY_UNITS",
    "BODIES",
    "ELLIPSOID_LABELS",
    "foot_angles",
    "ellipsoid_frame",
    "ellipsoid_contact",
    "solve_spd",
]

# =====================================================================================
# Small 2-D helpers on tuples of scalar expressions (keeps the SX graph lean)
# =====================================================================================


def _rotate(c, s, v):
    """Rotate the local 2-vector ``v`` by the angle whose cosine/sine are ``c, s``."""
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def _cross(a, b):
    """z-component of the 2-D cross product ``a x b``."""
    return a[0] * b[1] - a[1] * b[0]


def _wx(w, d):
    """``w e_z x d`` for a scalar angular rate ``w`` and a 2-vector ``d``."""
    return (-w * d[1], w * d[0])


def _add(a, b):
    return (a[0] + b[0], a[1] + b[1])


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1])


def _scale(k, a):
    return (k * a[0], k * a[1])


def solve_spd(M, b):
    """Solve ``M x = b`` for a symmetric positive definite ``M`` by symbolic LDLᵀ.

    Works on SX (and DM); structurally zero entries are skipped, so the branch-induced
    sparsity of a tree's mass matrix is exploited. Backward stable for SPD matrices (unlike
    CasADi's symbolic QR, whose Gram-Schmidt loses accuracy on ill-conditioned ``M``).
    """
    n = M.shape[0]

    def nz(x):
        return not (isinstance(x, (int, float)) and x == 0.0) and not (
            hasattr(x, "is_zero") and x.is_zero())

    A = [[M[i, j] for j in range(n)] for i in range(n)]
    L = [[0.0] * n for _ in range(n)]
    D = [0.0] * n
    for j in range(n):
        d = A[j][j]
        for k in range(j):
            if nz(L[j][k]):
                d = d - L[j][k] * L[j][k] * D[k]
        D[j] = d
        for i in range(j + 1, n):
            v = A[i][j]
            for k in range(j):
                if nz(L[i][k]) and nz(L[j][k]):
                    v = v - L[i][k] * L[j][k] * D[k]
            L[i][j] = v / d if nz(v) else 0.0
    y = [b[i] for i in range(n)]
    for i in range(n):
        for k in range(i):
            if nz(L[i][k]):
                y[i] = y[i] - L[i][k] * y[k]
    x = [y[i] / D[i] for i in range(n)]
    for i in reversed(range(n)):
        for k in range(i + 1, n):
            if nz(L[k][i]):
                x[i] = x[i] - L[k][i] * x[k]
    return ca.vertcat(*x)


# =====================================================================================
# Generic planar tree
# =====================================================================================


@dataclass(frozen=True)
class PlanarBody:
    """One rigid body of a planar tree.

    Parameters
    ----------
    name : str
    parent : str or None
        Parent body; ``None`` for the root (which has three free coordinates x, y, theta of
        its frame origin).
    joint : (float, float)
        Position of this body's frame origin (its joint with the parent) in the parent's
        body frame, m.
    coord : str or None
        Name of the revolute joint coordinate (``None`` for the root).
    sign : float
        ``theta_body = theta_parent + sign * q_joint`` (``-1`` lets a chain run from distal
        to proximal while keeping "distal relative to proximal" joint angles).
    """

    name: str
    parent: str | None = None
    joint: tuple[float, float] = (0.0, 0.0)
    coord: str | None = None
    sign: float = 1.0


@dataclass(frozen=True)
class Inertia:
    """Inertial parameters of one body: mass (kg), COM ``(cx, cy)`` in the body frame (m),
    moment of inertia about the COM (kg m²). Entries may be CasADi expressions."""

    mass: Any
    com: tuple[Any, Any]
    moi: Any


@dataclass(frozen=True)
class Load:
    """An external load on body ``body``: force ``(fx, fy)`` (N, ground frame) applied at the
    ground-frame point ``point`` (m) plus a free moment ``mz`` (N m, +Z)."""

    body: int
    point: tuple[Any, Any]
    force: tuple[Any, Any]
    mz: Any = 0.0


@dataclass
class _BodyState:
    o: tuple  # origin position
    th: Any  # absolute angle
    c: Any  # cos th
    s: Any  # sin th
    v: tuple  # origin velocity
    w: Any  # angular velocity
    a: tuple  # origin acceleration
    al: Any  # angular acceleration
    d: tuple  # world offset of the origin from the parent's origin


class PlanarTree:
    """A planar kinematic tree with a free (3-DOF) root and 1-DOF revolute joints.

    The generalised coordinates are ``root_coords + (coord of each non-root body)`` in body
    order. Bodies must be listed parents-first. A *fixed* root (a body welded to the ground)
    is the same tree evaluated with the root coordinates held constant; the root generalised
    forces are then the reaction wrench of the ground (see :meth:`generalized_forces`).

    All methods work on sequences of scalar expressions (floats or CasADi SX/MX scalars).
    """

    def __init__(self, bodies: Sequence[PlanarBody], root_coords=("x", "y", "theta")):
        bodies = tuple(bodies)
        if bodies[0].parent is not None:
            raise ValueError("the first body must be the root (parent=None)")
        index = {}
        parents = []
        for i, b in enumerate(bodies):
            if b.name in index:
                raise ValueError(f"duplicate body {b.name!r}")
            if i == 0:
                parents.append(-1)
            else:
                if b.parent not in index:
                    raise ValueError(f"parent {b.parent!r} of {b.name!r} must come first")
                if b.coord is None:
                    raise ValueError(f"body {b.name!r} needs a joint coordinate name")
                parents.append(index[b.parent])
            index[b.name] = i
        self.bodies = bodies
        self.index = index
        self.parents = tuple(parents)
        self.coords = tuple(root_coords) + tuple(b.coord for b in bodies[1:])
        self.n = len(self.coords)
        self.children = tuple(
            tuple(j for j, p in enumerate(self.parents) if p == i) for i in range(len(bodies))
        )

    # ---------------------------------------------------------------- kinematics
    def kinematics(self, q, qd=None, qdd=None) -> list[_BodyState]:
        """Forward kinematics of every body frame (position, angle, velocities, accels)."""
        zero = [0.0] * self.n
        qd = zero if qd is None else qd
        qdd = zero if qdd is None else qdd
        th0 = q[2]
        out = [
            _BodyState(
                o=(q[0], q[1]),
                th=th0,
                c=ca.cos(th0) if not isinstance(th0, (int, float)) else math.cos(th0),
                s=ca.sin(th0) if not isinstance(th0, (int, float)) else math.sin(th0),
                v=(qd[0], qd[1]),
                w=qd[2],
                a=(qdd[0], qdd[1]),
                al=qdd[2],
                d=(0.0, 0.0),
            )
        ]
        for i in range(1, len(self.bodies)):
            b, p = self.bodies[i], out[self.parents[i]]
            k = 2 + i
            d = _rotate(p.c, p.s, b.joint)
            wd = _wx(p.w, d)
            th = p.th + b.sign * q[k]
            out.append(
                _BodyState(
                    o=_add(p.o, d),
                    th=th,
                    c=ca.cos(th),
                    s=ca.sin(th),
                    v=_add(p.v, wd),
                    w=p.w + b.sign * qd[k],
                    a=_add(_add(p.a, _wx(p.al, d)), _wx(p.w, wd)),
                    al=p.al + b.sign * qdd[k],
                    d=d,
                )
            )
        return out

    @staticmethod
    def point(st: _BodyState, r) -> tuple:
        """Ground-frame position of the body-frame point ``r``."""
        return _add(st.o, _rotate(st.c, st.s, r))

    @staticmethod
    def point_velocity(st: _BodyState, r) -> tuple:
        """Ground-frame velocity of the body-frame point ``r``."""
        return _add(st.v, _wx(st.w, _rotate(st.c, st.s, r)))

    # ---------------------------------------------------------------- dynamics
    def generalized_forces(self, q, qd, qdd, inertia: Sequence[Inertia], loads=(), g=cv.G,
                           states=None) -> list:
        """Recursive Newton-Euler: ``M(q) qdd + h(q, qd) - Q_loads`` as a list of n scalars.

        ``h`` includes gravity (``-g`` along Y). ``loads`` are :class:`Load` objects. For the
        root, the three entries are the force (N) and the moment about the root frame origin
        (N m) that the root joint must supply -- with a welded root (root q constant, qd and
        qdd zero) they are the ground reaction wrench. For a revolute joint the entry is the
        generalised force of its coordinate (``sign`` x moment about the joint of the
        subtree), i.e. the joint torque needed.

        ``qd`` / ``qdd`` may be ``None`` (zeros); ``states`` may pass precomputed
        :meth:`kinematics` to share sub-expressions.
        """
        st = self.kinematics(q, qd, qdd) if states is None else states
        nb = len(self.bodies)
        F = [None] * nb
        Mo = [None] * nb
        by_body = [[] for _ in range(nb)]
        for ld in loads:
            by_body[ld.body].append(ld)
        for i in reversed(range(nb)):
            s, ine = st[i], inertia[i]
            dc = _rotate(s.c, s.s, ine.com)
            ac = _add(_add(s.a, _wx(s.al, dc)), _wx(s.w, _wx(s.w, dc)))
            f = (ine.mass * ac[0], ine.mass * (ac[1] + g))
            m = ine.moi * s.al + _cross(dc, f)
            for ld in by_body[i]:
                f = _sub(f, ld.force)
                m = m - _cross(_sub(ld.point, s.o), ld.force) - ld.mz
            for j in self.children[i]:
                f = _add(f, F[j])
                m = m + Mo[j] + _cross(st[j].d, F[j])
            F[i], Mo[i] = f, m
        Q = [F[0][0], F[0][1], Mo[0]]
        for i in range(1, nb):
            Q.append(self.bodies[i].sign * Mo[i])
        return Q

    def com(self, states, inertia: Sequence[Inertia]):
        """Whole-body COM position and velocity (ground frame) and total mass."""
        mt = 0.0
        px = py = vx = vy = 0.0
        for s, ine in zip(states, inertia):
            dc = _rotate(s.c, s.s, ine.com)
            c = _add(s.o, dc)
            v = _add(s.v, _wx(s.w, dc))
            mt = mt + ine.mass
            px, py = px + ine.mass * c[0], py + ine.mass * c[1]
            vx, vy = vx + ine.mass * v[0], vy + ine.mass * v[1]
        return (px / mt, py / mt), (vx / mt, vy / mt), mt

    def energies(self, states, inertia: Sequence[Inertia], g=cv.G):
        """Kinetic and gravitational potential energy (J), datum y = 0."""
        T = V = 0.0
        for s, ine in zip(states, inertia):
            dc = _rotate(s.c, s.s, ine.com)
            v = _add(s.v, _wx(s.w, dc))
            T = T + 0.5 * ine.mass * (v[0] ** 2 + v[1] ** 2) + 0.5 * ine.moi * s.w**2
            V = V + ine.mass * g * (s.o[1] + dc[1])
        return T, V


# =====================================================================================
# Numeric / symbolic calling helper
# =====================================================================================


def _is_numeric(x) -> bool:
    if isinstance(x, (ca.SX, ca.MX)):
        return False
    if isinstance(x, (list, tuple)):
        return all(_is_numeric(e) for e in x)
    return True


def _to_np(x):
    a = np.asarray(ca.DM(x).full())
    if a.shape[1] == 1:
        a = a[:, 0]
        if a.shape[0] == 1:
            return float(a[0])
    return a


def _call(fun: ca.Function, args):
    """Call ``fun``; numeric inputs give numpy outputs, symbolic inputs CasADi outputs.

    Returns a dict by output name.
    """
    args = [ca.DM(a) if _is_numeric(a) and not isinstance(a, ca.DM) else a for a in args]
    numeric = all(isinstance(a, ca.DM) for a in args)
    res = fun.call(args)
    names = fun.name_out()
    if numeric:
        return {n: _to_np(r) for n, r in zip(names, res)}
    return dict(zip(names, res))


# =====================================================================================
# Contact ellipsoids on a body of a planar tree
# =====================================================================================


def ellipsoid_frame(state: _BodyState, body: int, offset, params, right: bool = False) -> dict:
    """Pose and velocity of one contact ellipsoid riding on a planar body.

    Parameters
    ----------
    state : body state from :meth:`PlanarTree.kinematics`
    body : int
        Index of the carrying body.
    offset : (float, float)
        Origin of the foot frame in which the contact parameters are expressed, given in
        the carrying body's frame, m (see the module docstring).
    params : sequence of 13 scalars
        One ellipsoid's parameters (``gaitlib.contact.PARAM_NAMES`` order), left foot.
    right : bool
        Mirror the ellipsoid to the right foot with ``contact.mirror``.

    Returns
    -------
    dict with ``body``, ``R`` (3x3, ellipsoid -> ground), ``centre`` (x, y, z), ``vel``
    (vx, vy, 0), ``omega`` and ``params`` (the first 7 parameters: k_v ... c).
    """
    gam, bet, alp = params[10], params[11], params[12]
    r = ca.vertcat(params[7], params[8], params[9])
    R_loc = contact.ellipsoid_to_segment(gam, bet, alp)
    if right:
        R_loc, r = contact.mirror(R_loc, r)
    rb = (r[0] + offset[0], r[1] + offset[1])
    centre = PlanarTree.point(state, rb)
    vel = PlanarTree.point_velocity(state, rb)
    Rz = ca.vertcat(ca.horzcat(state.c, -state.s, 0.0), ca.horzcat(state.s, state.c, 0.0),
                    ca.horzcat(0.0, 0.0, 1.0))
    return {
        "body": body,
        "R": ca.mtimes(Rz, R_loc),
        "centre": (centre[0], centre[1], r[2]),
        "vel": (vel[0], vel[1], 0.0),
        "omega": state.w,
        "params": tuple(params[:7]),
    }


def ellipsoid_contact(frame: dict, smoothing) -> dict:
    """``gaitlib.contact.ellipsoid_plane`` outputs for an :func:`ellipsoid_frame`."""
    k_v, a_v, mu_s, mu_d, a, b, c = frame["params"]
    return contact.ellipsoid_plane(
        frame["R"], ca.vertcat(*frame["centre"]), ca.vertcat(*frame["vel"]), frame["omega"],
        k_v, a_v, mu_s, mu_d, a, b, c, smoothing)


# =====================================================================================
# Child gait model (thesis Ch 4.1)
# =====================================================================================

#: Body names of the child model, in tree order (generalised coordinates follow COORDS).
BODIES = ("hat", "thigh_r", "shank_r", "foot_r", "toe_r", "thigh_l", "shank_l", "foot_l",
          "toe_l")

#: The 25 identifiable body and joint parameters (thesis Sec 4.4.1, Tables 4.14-4.16).
P_BODY_NAMES = (
    "mass_hat", "mass_thigh", "mass_shank", "mass_toe", "mass_forefoot", "mass_hindfoot",
    "moi_hat", "moi_thigh", "moi_shank", "moi_toe", "moi_forefoot", "moi_hindfoot",
    "com_thigh", "com_shank", "com_toe", "com_forefoot", "com_hindfoot",
    "K_hip", "K_knee", "K_ankle", "K_mtp",
    "B_hip", "B_knee", "B_ankle", "B_mtp",
)
#: SI units of :data:`P_BODY_NAMES`.
P_BODY_UNITS = ("kg",) * 6 + ("kg m^2",) * 6 + ("m",) * 5 + ("N m/rad",) * 4 + (
    "N m s/rad",) * 4

#: Contact ellipsoids of the child model, in output order (right foot first).
ELLIPSOID_LABELS = tuple(f"{e}_{s}" for s in cv.SIDES for e in cv.ELLIPSOIDS)

# Anthropometrics (Tables 4.1, 4.3): (SM / BM, SL / BH, ROG / SL, COM / SL)
_ANTHRO = {
    "hat": (0.678, 0.288, 0.496, 0.626),
    "thigh": (0.100, 0.245, 0.323, 0.433),
    "shank": (0.047, 0.246, 0.302, 0.433),
    "toe": (2.1e-3, 4.3e-2, 1.32e-2, 0.5),  # MT
    "forefoot": (6.2e-3, 6.5e-2, 2.74e-2, 0.5),  # AM
    "hindfoot": (6.2e-3, 4.4e-2, 2.74e-2, 0.5),  # HA
}
# Table 4.2 (metatarsal = ankle): K (N m/rad), B (N m s/rad) for hip, knee, ankle, mtp
_K = (2.8762, 1.5928, 6.0390, 6.0390)
_B = (0.0003, 2.9794, 3.6841, 3.6841)

_P = {n: i for i, n in enumerate(P_BODY_NAMES)}
#: The segments :attr:`ChildModel.leg_scale` lengthens.
_LEG_SEGMENTS = ("thigh", "shank")


def foot_angles(body_height: float = cv.BODY_HEIGHT, beta_deg: float = 106.0):
    """Standing foot geometry: ``(phi1, phi2)`` in rad.

    ``phi1``: fore-foot AM below the horizontal; ``phi2``: hind-foot AH below the horizontal
    (pointing backwards); ``phi1 + phi2 + beta = pi`` and ``|AM| sin phi1 = |AH| sin phi2``
    (same construction as :func:`gaitlib.conventions.ankle_height`).
    """
    l_am, l_ha = 0.065 * body_height, 0.044 * body_height
    total = math.pi - beta_deg * cv.DEG
    phi1 = math.atan2(l_ha * math.sin(total), l_am + l_ha * math.cos(total))
    return phi1, total - phi1


#: The SX functions built so far, shared by equal models: a :class:`ChildModel`'s functions
#: depend only on its fields (``p_body`` and ``p_contact`` are their inputs), so every model
#: built with the same fields — e.g. each cached gap solution's rebuilt problem — reuses them.
_FUNCTIONS: dict = {}
_FUNCTIONS_KEPT = 256


@dataclass(frozen=True)
class ChildModel:
    """The 2-D, 9-body, 11-DOF child gait model with 6 contact ellipsoids (thesis Ch 4.1).

    Parameters
    ----------
    body_mass, body_height : float
        kg, m (defaults: :data:`gaitlib.conventions.BODY_MASS`, ``BODY_HEIGHT``).
    beta_deg : float
        Fixed angle between fore-foot AM and hind-foot AH, deg (Table 4.3 / Fig 4.1: 106).
    smoothing : gaitlib.contact.Smoothing or None
        Smoothing of the contact model (``None``: ``contact.Smoothing()``).
    g : float
        Gravity, m/s².
    leg_scale : float
        The thigh and shank lengths of Table 4.1 × this (1: the thesis's proportions; 0.5–2).
        Their COM distances scale with it and their moments of inertia with its square
        (:meth:`leg_scaled`); masses, the feet and the HAT are unchanged. A kinematic probe of
        the Fidelity study (:attr:`gaitlib.problems.gait.GaitSpec.leg_scale`).

    Segment lengths, beta and the HAT COM are fixed per instance; the 25 body/joint
    parameters ``p_body`` and the 39 contact parameters ``p_contact`` are inputs of every
    function (so they can be optimisation variables).

    Total default mass: HAT 0.678 + 2 x (thigh 0.100 + shank 0.047 + toe 0.0021 +
    fore-foot 0.0062 + hind-foot 0.0062) = 1.0010 BM (41.44 kg for BM 41.4 kg; Table 4.3's
    foot pieces sum to 0.0145 BM, the whole foot of [186]).
    """

    body_mass: float = cv.BODY_MASS
    body_height: float = cv.BODY_HEIGHT
    beta_deg: float = 106.0
    smoothing: Any = None
    g: float = cv.G
    leg_scale: float = 1.0

    coords = cv.COORDS
    joints = cv.JOINTS
    residuals = cv.RESIDUALS
    bodies = BODIES
    p_body_names = P_BODY_NAMES
    ellipsoid_labels = ELLIPSOID_LABELS

    # ------------------------------------------------------------ fixed geometry
    @cached_property
    def lengths(self) -> dict:
        """Segment lengths, m: hat, thigh, shank, toe (MT), forefoot (AM), hindfoot (HA)."""
        return {k: v[1] * self.body_height * (self.leg_scale if k in _LEG_SEGMENTS else 1.0)
                for k, v in _ANTHRO.items()}

    def __post_init__(self):
        if not 0.5 <= self.leg_scale <= 2.0:
            raise ValueError(f"ChildModel: leg_scale {self.leg_scale!r} outside 0.5–2")

    def leg_scaled(self, p_body, from_scale: float = 1.0) -> np.ndarray:
        """A ``p_body`` (25,) given for legs × ``from_scale`` (1: the thesis's), with the
        thigh's and shank's COM distances × :attr:`leg_scale` / ``from_scale`` and their
        moments of inertia × its square (a copy)."""
        p = np.array(p_body, dtype=float)
        r = self.leg_scale / float(from_scale)
        for seg in _LEG_SEGMENTS:
            p[_P[f"com_{seg}"]] *= r
            p[_P[f"moi_{seg}"]] *= r ** 2
        return p

    @cached_property
    def foot_geometry(self) -> dict:
        """Standing foot geometry in the hind-fore-foot frame (origin: ankle), m / rad."""
        L = self.lengths
        phi1, phi2 = foot_angles(self.body_height, self.beta_deg)
        u_am = (math.cos(phi1), -math.sin(phi1))
        u_ah = (-math.cos(phi2), -math.sin(phi2))
        mtp = (L["forefoot"] * u_am[0], L["forefoot"] * u_am[1])
        heel = (L["hindfoot"] * u_ah[0], L["hindfoot"] * u_ah[1])
        return {
            "phi1": phi1,
            "phi2": phi2,
            "u_am": u_am,
            "u_ah": u_ah,
            "mtp": mtp,
            "heel": heel,
            "ankle_height": -mtp[1],
        }

    @cached_property
    def hat_com_height(self) -> float:
        """HAT COM above the hip joint centre, m (0.626 SL, fixed)."""
        return _ANTHRO["hat"][3] * self.lengths["hat"]

    @cached_property
    def standing_leg_length(self) -> float:
        """Hip joint centre height in the standing posture with the feet on the ground, m."""
        return self.lengths["thigh"] + self.lengths["shank"] + self.foot_geometry[
            "ankle_height"]

    # ------------------------------------------------------------ parameters
    def default_p_body(self) -> np.ndarray:
        """Default ``p_body`` (25,): Tables 4.1-4.3 scaled by BM/BH, ``MOI = SM (ROG SL)^2``,
        COM = fraction x SL, K and B from Table 4.2 (metatarsal = ankle)."""
        BM, BH = self.body_mass, self.body_height
        seg = ("hat", "thigh", "shank", "toe", "forefoot", "hindfoot")
        mass = [_ANTHRO[s][0] * BM for s in seg]
        moi = [m * (_ANTHRO[s][2] * _ANTHRO[s][1] * BH) ** 2 for m, s in zip(mass, seg)]
        com = [_ANTHRO[s][3] * _ANTHRO[s][1] * BH for s in seg[1:]]
        return self.leg_scaled(np.array(mass + moi + com + list(_K) + list(_B), dtype=float))

    def p_body_bounds(self, p0=None) -> tuple[np.ndarray, np.ndarray]:
        """Bounds of Table 4.14 around ``p0`` (default :meth:`default_p_body`):
        0.5x-1.5x for mass, MOI and COM; 0-3x for K and B."""
        p0 = self.default_p_body() if p0 is None else np.asarray(p0, float)
        lb, ub = 0.5 * p0.copy(), 1.5 * p0.copy()
        lb[17:], ub[17:] = 0.0, 3.0 * p0[17:]
        return lb, ub

    @staticmethod
    def p_body_identified() -> np.ndarray:
        """Identified values of thesis Tables 4.15 and 4.16 ("tuned", BM 41.4 kg, BH 1.47 m).

        Table 4.15 does not report a HAT COM (fixed); MOIs in Table 4.15 are used as printed
        (note: its "initial" foot/thigh MOIs differ from ``SM (ROG SL)^2`` of Tables 4.1/4.3).
        """
        return np.array([
            26.2, 6.21, 1.21, 0.0429, 0.224, 0.129,
            1.24, 0.0247, 0.0184, 0.32e-4, 4e-4, 4e-4,
            0.1338, 0.0916, 0.0188, 0.0669, 0.0217,
            2.96, 1.77, 6.596, 9.031,
            4e-4, 0.189, 0.0, 5.51,
        ])

    def p_body_dict(self, p) -> dict:
        """Named view of a ``p_body`` vector."""
        return {n: p[i] for i, n in enumerate(P_BODY_NAMES)}

    # ------------------------------------------------------------ tree + inertias
    @cached_property
    def tree(self) -> PlanarTree:
        L, fg = self.lengths, self.foot_geometry
        bodies = [PlanarBody("hat")]
        for s in cv.SIDES:
            bodies += [
                PlanarBody(f"thigh_{s}", "hat", (0.0, 0.0), f"hip_{s}"),
                PlanarBody(f"shank_{s}", f"thigh_{s}", (0.0, -L["thigh"]), f"knee_{s}"),
                PlanarBody(f"foot_{s}", f"shank_{s}", (0.0, -L["shank"]), f"ankle_{s}"),
                PlanarBody(f"toe_{s}", f"foot_{s}", fg["mtp"], f"mtp_{s}"),
            ]
        tree = PlanarTree(bodies, root_coords=cv.COORDS[:3])
        assert tree.coords == cv.COORDS
        assert tuple(b.name for b in tree.bodies) == BODIES
        return tree

    def _inertias(self, p) -> list[Inertia]:
        """Per-body :class:`Inertia` (tree order) from a symbolic/numeric ``p_body``."""
        fg = self.foot_geometry
        P = lambda n: p[_P[n]]  # noqa: E731
        m_ff, m_hf = P("mass_forefoot"), P("mass_hindfoot")
        c_ff = _scale(P("com_forefoot"), fg["u_am"])
        c_hf = _scale(P("com_hindfoot"), fg["u_ah"])
        m_f = m_ff + m_hf
        c_f = ((m_ff * c_ff[0] + m_hf * c_hf[0]) / m_f, (m_ff * c_ff[1] + m_hf * c_hf[1]) / m_f)
        # parallel axis: sum m_i |c_i - c|^2 = m_ff m_hf / m_f |c_ff - c_hf|^2
        dff = _sub(c_ff, c_hf)
        I_f = P("moi_forefoot") + P("moi_hindfoot") + m_ff * m_hf / m_f * (
            dff[0] ** 2 + dff[1] ** 2)
        hat = Inertia(P("mass_hat"), (0.0, self.hat_com_height), P("moi_hat"))
        leg = [
            Inertia(P("mass_thigh"), (0.0, -P("com_thigh")), P("moi_thigh")),
            Inertia(P("mass_shank"), (0.0, -P("com_shank")), P("moi_shank")),
            Inertia(m_f, c_f, I_f),
            Inertia(P("mass_toe"), (P("com_toe"), 0.0), P("moi_toe")),
        ]
        return [hat] + leg + leg

    # ------------------------------------------------------------ contact geometry
    def _contact_module(self):
        return contact

    @cached_property
    def _smoothing(self):
        return self.smoothing if self.smoothing is not None else (
            self._contact_module().Smoothing())

    def _ellipsoid_frames(self, st, pc):
        """Pose and kinematics of the 6 ellipsoids (order :data:`ELLIPSOID_LABELS`)."""
        fg = self.foot_geometry
        out = []
        for s in cv.SIDES:
            for k, e in enumerate(cv.ELLIPSOIDS):
                body = self.tree.index[f"{'toe' if e == 'toe' else 'foot'}_{s}"]
                # foot-frame origin (ground below the ankle, standing) in the body frame
                off = (-fg["mtp"][0], 0.0) if e == "toe" else (0.0, -fg["ankle_height"])
                out.append(ellipsoid_frame(st[body], body, off, pc[13 * k:13 * k + 13],
                                           right=(s == "r")))
        return out

    def _contact(self, st, pc):
        """Contact outputs for all 6 ellipsoids plus the :class:`Load` list."""
        frames = self._ellipsoid_frames(st, pc)
        res = [ellipsoid_contact(fr, self._smoothing) for fr in frames]
        loads = [Load(fr["body"], fr["centre"][:2], (o["fx"], o["fy"]), o["mz"])
                 for fr, o in zip(frames, res)]
        return frames, res, loads

    # ------------------------------------------------------------ the SX graph
    @cached_property
    def _sym(self) -> dict:
        """Symbols and shared expressions (built once)."""
        n = len(cv.COORDS)
        S = {
            "q": ca.SX.sym("q", n),
            "qd": ca.SX.sym("qd", n),
            "qdd": ca.SX.sym("qdd", n),
            "p_body": ca.SX.sym("p_body", len(P_BODY_NAMES)),
            "p_contact": ca.SX.sym("p_contact", 39),
            "tau": ca.SX.sym("tau", len(cv.JOINTS)),
            "R": ca.SX.sym("R", 3),
            "grf": ca.SX.sym("grf", 6),
        }
        return S

    def _passive(self, q, qd, p):
        """Passive joint torques (8,): ``-K q_j - B qd_j`` (Table 4.2)."""
        out = []
        for s in cv.SIDES:
            for j, jn in enumerate(("hip", "knee", "ankle", "mtp")):
                k = cv.COORDS.index(f"{jn}_{s}")
                out.append(-p[17 + j] * q[k] - p[21 + j] * qd[k])
        return out

    def _build(self, name: str) -> ca.Function:
        S = self._sym
        q, qd, qdd, pb, pc = S["q"], S["qd"], S["qdd"], S["p_body"], S["p_contact"]
        tree, ine = self.tree, self._inertias(pb)
        qs, qds, qdds = ca.vertsplit(q), ca.vertsplit(qd), ca.vertsplit(qdd)
        g = self.g

        if name == "inverse_dynamics":
            st = tree.kinematics(qs, qds, qdds)
            _, _, loads = self._contact(st, ca.vertsplit(pc))
            Q = tree.generalized_forces(qs, qds, qdds, ine, loads, g, states=st)
            pas = self._passive(qs, qds, pb)
            tau = ca.vertcat(*[Q[3 + i] - pas[i] for i in range(8)])
            return ca.Function(name, [q, qd, qdd, pb, pc], [tau, ca.vertcat(*Q[:3])],
                               ["q", "qd", "qdd", "p_body", "p_contact"], ["tau", "R"])
        if name == "inverse_dynamics_grf":
            st = tree.kinematics(qs, qds, qdds)
            G = ca.vertsplit(S["grf"])
            loads = [
                Load(tree.index[f"foot_{s}"], (G[3 * i + 2], 0.0), (G[3 * i], G[3 * i + 1]))
                for i, s in enumerate(cv.SIDES)
            ]
            Q = tree.generalized_forces(qs, qds, qdds, ine, loads, g, states=st)
            pas = self._passive(qs, qds, pb)
            tau = ca.vertcat(*[Q[3 + i] - pas[i] for i in range(8)])
            return ca.Function(name, [q, qd, qdd, pb, S["grf"]], [tau, ca.vertcat(*Q[:3])],
                               ["q", "qd", "qdd", "p_body", "grf"], ["tau", "R"])
        if name == "passive":
            pas = self._passive(qs, qds, ca.vertsplit(pb))
            return ca.Function(name, [q, qd, pb], [ca.vertcat(*pas)], ["q", "qd", "p_body"], ["tau_passive"])
        if name == "mass_matrix":
            Q = tree.generalized_forces(qs, None, qdds, ine, (), 0.0)
            M = ca.jacobian(ca.vertcat(*Q), qdd)
            M = 0.5 * (M + M.T)  # exact symmetry (entries are identical expressions)
            return ca.Function(name, [q, pb], [ca.densify(M)], ["q", "p_body"], ["M"])
        if name == "bias":
            h = tree.generalized_forces(qs, qds, None, ine, (), g)
            return ca.Function(name, [q, qd, pb], [ca.vertcat(*h)],
                               ["q", "qd", "p_body"], ["h"])
        if name == "contact":
            st = tree.kinematics(qs, qds)
            frames, res, loads = self._contact(st, ca.vertsplit(pc))
            Qc = tree.generalized_forces(qs, None, None,
                                         [Inertia(0.0, (0.0, 0.0), 0.0)] * len(BODIES),
                                         loads, 0.0, states=st)
            outs = {k: ca.vertcat(*[r[k] for r in res])
                    for k in ("fx", "fy", "fn", "fn_raw", "px", "py", "mz", "depth")}
            grf_x, grf_y, cop_x = [], [], []
            for i in range(2):
                sl = slice(3 * i, 3 * i + 3)
                mom = fx = fy = 0.0
                for fr, r in zip(frames[sl], res[sl]):
                    fx, fy = fx + r["fx"], fy + r["fy"]
                    mom = mom + _cross(fr["centre"][:2], (r["fx"], r["fy"])) + r["mz"]
                grf_x.append(fx)
                grf_y.append(fy)
                # moment-based CoP on the ground (y = 0); meaningless when unloaded
                cop_x.append(mom / ca.fmax(fy, 1e-3))
            outs.update(grf_x=ca.vertcat(*grf_x), grf_y=ca.vertcat(*grf_y),
                        cop_x=ca.vertcat(*cop_x), Q=-ca.vertcat(*Qc))
            names = list(outs)
            return ca.Function(name, [q, qd, pc], [outs[k] for k in names],
                               ["q", "qd", "p_contact"], names)
        if name == "forward_dynamics":
            M = self.function("mass_matrix")(q, pb)
            h = self.function("bias")(q, qd, pb)
            Qc = self.function("contact")(q=q, qd=qd, p_contact=pc)["Q"]
            pas = self._passive(qs, qds, pb)
            rhs = ca.vertcat(S["R"], S["tau"] + ca.vertcat(*pas)) + Qc - h
            acc = solve_spd(M, rhs)
            return ca.Function(name, [q, qd, S["tau"], S["R"], pb, pc], [acc],
                               ["q", "qd", "tau", "R", "p_body", "p_contact"], ["qdd"])
        if name == "com":
            st = tree.kinematics(qs, qds)
            c, v, mt = tree.com(st, ine)
            return ca.Function(name, [q, qd, pb], [ca.vertcat(*c), ca.vertcat(*v), mt],
                               ["q", "qd", "p_body"], ["com", "com_vel", "mass"])
        if name == "energies":
            st = tree.kinematics(qs, qds)
            T, V = tree.energies(st, ine, g)
            Ve = 0.0
            for s in cv.SIDES:
                for j, jn in enumerate(("hip", "knee", "ankle", "mtp")):
                    Ve = Ve + 0.5 * pb[17 + j] * qs[cv.COORDS.index(f"{jn}_{s}")] ** 2
            return ca.Function(name, [q, qd, pb], [T, V, Ve], ["q", "qd", "p_body"],
                               ["kinetic", "potential_gravity", "potential_spring"])
        if name == "points":
            return self._build_points()
        if name == "slip":
            st = tree.kinematics(qs, qds)
            frames = self._ellipsoid_frames(st, ca.vertsplit(pc))
            res = [ellipsoid_contact(fr, self._smoothing) for fr in frames]
            return ca.Function(name, [q, qd, pc], [ca.vertcat(*[r[k] for r in res]) for k in ("v_slip", "fn")],
                               ["q", "qd", "p_contact"], ["v_slip", "fn"])
        if name == "ellipsoid_poses":
            st = tree.kinematics(qs)
            frames = self._ellipsoid_frames(st, ca.vertsplit(pc))
            C = ca.horzcat(*[ca.vertcat(*f["centre"]) for f in frames]).T
            Rs = [f["R"] for f in frames]
            return ca.Function(name, [q, pc], [C] + Rs, ["q", "p_contact"],
                               ["centres"] + [f"R_{e}" for e in ELLIPSOID_LABELS])
        raise KeyError(name)

    def _build_points(self) -> ca.Function:
        S = self._sym
        q, pb = S["q"], S["p_body"]
        st = self.tree.kinematics(ca.vertsplit(q))
        ine = self._inertias(ca.vertsplit(pb))
        L, fg = self.lengths, self.foot_geometry
        ix = self.tree.index
        pts = {"hip": st[0].o, "hat_top": PlanarTree.point(st[0], (0.0, L["hat"]))}
        for s in cv.SIDES:
            pts[f"knee_{s}"] = st[ix[f"shank_{s}"]].o
            pts[f"ankle_{s}"] = st[ix[f"foot_{s}"]].o
            pts[f"mtp_{s}"] = st[ix[f"toe_{s}"]].o
            pts[f"heel_{s}"] = PlanarTree.point(st[ix[f"foot_{s}"]], fg["heel"])
            pts[f"toe_tip_{s}"] = PlanarTree.point(st[ix[f"toe_{s}"]], (L["toe"], 0.0))
        for b, i in ix.items():
            pts[f"com_{b}"] = PlanarTree.point(st[i], ine[i].com)
        names = list(pts)
        outs = [ca.vertcat(*pts[k]) for k in names]
        names.append("angles")
        outs.append(ca.vertcat(*[s.th for s in st]))
        return ca.Function("points", [q, pb], outs, ["q", "p_body"], names)

    # ------------------------------------------------------------ public API
    def function(self, name: str) -> ca.Function:
        """The cached SX :class:`casadi.Function` ``name``.

        Names and signatures (inputs -> outputs):

        * ``inverse_dynamics``: (q, qd, qdd, p_body, p_contact) -> (tau (8,), R (3,))
        * ``inverse_dynamics_grf``: (q, qd, qdd, p_body, grf (6,)) -> (tau, R)
        * ``passive``: (q, qd, p_body) -> tau_passive (8,): the joints' spring–damper
          torques ``−K q − B q̇`` (Table 4.2). ``inverse_dynamics``' ``tau`` is the torque
          the actuators must add to them; the net joint torque (what gait laboratories
          report) is ``tau + tau_passive``.
        * ``mass_matrix``: (q, p_body) -> M (11, 11)
        * ``bias``: (q, qd, p_body) -> h (11,)
        * ``forward_dynamics``: (q, qd, tau, R, p_body, p_contact) -> qdd (11,)
        * ``contact``: (q, qd, p_contact) -> fx, fy, fn, fn_raw, px, py, mz, depth (6,) each,
          grf_x, grf_y, cop_x (2,) each (right, left), Q (11,)
        * ``com``: (q, qd, p_body) -> com (2,), com_vel (2,), mass
        * ``energies``: (q, qd, p_body) -> kinetic, potential_gravity, potential_spring
        * ``points``: (q, p_body) -> named points (2,) and ``angles`` (9,)
        * ``ellipsoid_poses``: (q, p_contact) -> centres (6, 3), R_<label> (3, 3)
        * ``slip``: (q, qd, p_contact) -> v_slip (6,), m/s: the ground-tangential (x)
          velocity of each ellipsoid's body material point at its penetration centroid, the
          velocity the friction law reads (:func:`gaitlib.contact.friction_coefficient`);
          fn (6,), N: its normal force
        """
        key = (type(self), self, name)
        f = _FUNCTIONS.get(key)
        if f is None:
            if len(_FUNCTIONS) >= _FUNCTIONS_KEPT:  # the oldest first: a sweep over many models stays bounded
                del _FUNCTIONS[next(iter(_FUNCTIONS))]
            f = _FUNCTIONS[key] = self._build(name)
        return f

    def inverse_dynamics(self, q, qd, qdd, p_body=None, p_contact=None):
        """Joint torques and pelvis residuals needed for the motion (thesis Eq. 4.10).

        Contact loads come from the state through the ellipsoid model.

        Parameters
        ----------
        q, qd, qdd : (11,) -- m, rad; /s; /s²
        p_body : (25,), default :meth:`default_p_body`
        p_contact : (39,), default ``contact.default_params()``

        Returns
        -------
        tau : (8,) N m, order ``conventions.JOINTS``
        R : (3,) residual loads R_x, R_y (N), R_z (N m)
        """
        r = _call(self.function("inverse_dynamics"),
                  [q, qd, qdd, self._pb(p_body), self._pc(p_contact)])
        return r["tau"], r["R"]

    def inverse_dynamics_grf(self, q, qd, qdd, grf, p_body=None):
        """Inverse dynamics with given foot loads instead of the contact model.

        ``grf`` (6,) = (grf_x_r, grf_y_r, cop_x_r, grf_x_l, grf_y_l, cop_x_l): the force
        (N) of the ground on each hind-fore-foot, applied at the ground point (cop_x, 0), no
        free moment. Returns ``(tau, R)``.
        """
        r = _call(self.function("inverse_dynamics_grf"), [q, qd, qdd, self._pb(p_body), grf])
        return r["tau"], r["R"]

    def forward_dynamics(self, q, qd, tau, R=None, p_body=None, p_contact=None):
        """Accelerations ``qdd`` (11,) from ``M qdd + h = [R; tau] + Q_passive + Q_contact``.

        ``R`` (3,) defaults to zeros (no residual loads).
        """
        R = np.zeros(3) if R is None else R
        return _call(self.function("forward_dynamics"),
                     [q, qd, tau, R, self._pb(p_body), self._pc(p_contact)])["qdd"]

    def mass_matrix(self, q, p_body=None):
        """Mass matrix M(q) (11, 11)."""
        return _call(self.function("mass_matrix"), [q, self._pb(p_body)])["M"]

    def bias(self, q, qd, p_body=None):
        """Bias h(q, qd) (11,): Coriolis/centrifugal + gravity (``M qdd + h = Q``)."""
        return _call(self.function("bias"), [q, qd, self._pb(p_body)])["h"]

    def contact(self, q, qd, p_contact=None) -> dict:
        """Contact outputs, see :meth:`function` ('contact'). Per-ellipsoid arrays (6,) in
        the order :data:`ELLIPSOID_LABELS`; per-foot arrays (2,) are (right, left); ``Q``
        (11,) is the contact generalised force."""
        return _call(self.function("contact"), [q, qd, self._pc(p_contact)])

    def slip(self, q, qd, p_contact=None) -> dict:
        """Each ellipsoid's slip velocity ``v_slip`` (6,), m/s (+x forward), and normal force
        ``fn`` (6,), N, in the order :data:`ELLIPSOID_LABELS` (see :meth:`function`, 'slip')."""
        return _call(self.function("slip"), [q, qd, self._pc(p_contact)])

    def com(self, q, qd=None, p_body=None):
        """Whole-body COM position (2,) and velocity (2,), m and m/s."""
        qd = np.zeros(11) if qd is None else qd
        r = _call(self.function("com"), [q, qd, self._pb(p_body)])
        return r["com"], r["com_vel"]

    def energies(self, q, qd, p_body=None) -> dict:
        """Kinetic, gravitational (datum y = 0) and joint-spring potential energy, J."""
        return _call(self.function("energies"), [q, qd, self._pb(p_body)])

    def points(self, q, p_body=None) -> dict:
        """Named ground-frame points (2,): hip, hat_top, knee_s, ankle_s, mtp_s, heel_s,
        toe_tip_s, com_<body>; and ``angles`` (9,) absolute segment angles (tree order)."""
        return _call(self.function("points"), [q, self._pb(p_body)])

    def segments(self, q, p_body=None) -> dict:
        """Stick-figure segments: name -> ((x0, y0), (x1, y1)) arrays of shape (2, 2) (numeric
        ``q``; CasADi (2, 2) matrices for symbolic ``q``)."""
        P = self.points(q, p_body)
        pairs = {"hat": ("hip", "hat_top")}
        for s in cv.SIDES:
            pairs.update({
                f"thigh_{s}": ("hip", f"knee_{s}"),
                f"shank_{s}": (f"knee_{s}", f"ankle_{s}"),
                f"forefoot_{s}": (f"ankle_{s}", f"mtp_{s}"),
                f"hindfoot_{s}": (f"ankle_{s}", f"heel_{s}"),
                f"sole_{s}": (f"heel_{s}", f"mtp_{s}"),
                f"toe_{s}": (f"mtp_{s}", f"toe_tip_{s}"),
            })
        if isinstance(P["hip"], np.ndarray):
            return {k: np.vstack([P[a], P[b]]) for k, (a, b) in pairs.items()}
        return {k: ca.horzcat(P[a], P[b]).T for k, (a, b) in pairs.items()}

    def ellipsoid_poses(self, q, p_contact=None):
        """Ellipsoid centres (6, 3) and rotations ellipsoid -> ground (list of 6 (3, 3)),
        order :data:`ELLIPSOID_LABELS`."""
        r = _call(self.function("ellipsoid_poses"), [q, self._pc(p_contact)])
        return r["centres"], [r[f"R_{e}"] for e in ELLIPSOID_LABELS]

    def total_mass(self, p_body=None) -> float:
        """Sum of segment masses (both legs), kg."""
        p = self._pb(p_body)
        return float(p[0] + 2 * sum(p[1:6]))

    # ------------------------------------------------------------ defaults
    def _pb(self, p):
        return self.default_p_body() if p is None else p

    def _pc(self, p):
        return self._contact_module().default_params() if p is None else p
