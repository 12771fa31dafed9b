"""Vertical-jump models of thesis Ch 3.1-3.2 on the generic planar tree of :mod:`gaitlib.model`.

Two skeletons (thesis Fig 3.1, Table 3.1 -- legs already doubled):

* toeless: foot, shank, thigh, head-trunk (HT); joints ankle, knee, hip;
* toe-included: toe, foot, shank, thigh, HT; joints mtp, ankle, knee, hip.

and two contact descriptions:

(a) kinematically constrained (Sec 3.1): in the preflight phase (crouch + thrust) the foot
    (toeless) or the toe (toe-included) is welded to the ground -- DOF 3 / 4, coordinates
    = joint angles (Tables 3.2, 3.3); in the flight phase the model is free -- DOF 6 / 7,
    coordinates ``(x, y, theta_z, joint angles)``. The ground reaction of the welded phase
    (needed for the take-off event ``F_y = 0``) is the root reaction wrench.
(b) compliant ellipsoid contact (Sec 3.2, toe-included only): the free 7-DOF model in all
    three phases (crouch, thrust, flight) with three ellipsoids (toe on the toe; ball and
    heel on the foot) from :mod:`gaitlib.contact`.

Symbol legend: as :mod:`gaitlib.model` (q, qd, qdd, tau, p_contact; SI units).

Geometry and conventions (our choices where Ch 3 is silent)
-----------------------------------------------------------
* The chain runs from the ground up: root = toe (toe-included) or foot (toeless). The root
  frame origin is the metatarsal (MTP) point; ``(x, y, theta_z)`` are its position and the
  root segment's absolute angle (CCW, 0 in the standing posture).
* Joint angles are "distal relative to proximal", CCW positive, 0 in the standing posture,
  exactly as :mod:`gaitlib.conventions` (hip > 0 flexion, knee < 0 flexion, ankle > 0
  dorsiflexion, mtp > 0 toe extension). Because the chain runs distal -> proximal, the tree
  uses ``sign = -1`` on every joint. Joint torques: proximal on distal, positive in the
  angle's sense (``conventions``).
* Standing posture: toe horizontal on the ground forward of the MTP point; the foot is the
  straight line MTP -> ankle (length 0.116 m) rising backwards at ``foot_incline_deg``
  (default: the child model's fore-foot angle phi1 = 28.8 deg from beta = 106 deg, thesis
  Sec 4.1.1), shank, thigh and HT vertical.
* Table 3.1's "Center of Mass" is measured from the segment's *lower* joint (the joint
  nearer the ground in the standing chain: MTP for toe and foot, ankle for the shank, knee
  for the thigh, hip for HT). This reproduces Winter's ratios (shank 0.285/0.503 = 0.567
  from the ankle = 0.433 from the knee; thigh 0.568 from the knee; HT 0.612 from the hip).
* Dampers across every joint (Sec 3.1.2 mentions them; no value given): ``damping =
  0.1 N m s/rad`` by default (small against the child gait model's knee/ankle 3 N m s/rad,
  enough to take the edge off numerical integration).
* Ellipsoid contact: parameters are ``contact.default_params()`` (the thesis's identified
  left child foot, Tables 4.17/4.18) -- Ch 3 used Brown & McPhee's adult values with
  manually adjusted a_v and mu, which are not printed. Positions are read in a foot frame
  whose origin is the ground point below the ankle in standing (as in the child model).
  Because the legs are doubled, the loads of the three (left-foot) ellipsoids are
  multiplied by ``contact_feet = 2`` (the mirrored right foot gives identical sagittal
  loads).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import casadi as ca
import numpy as np

from gaitlib import conventions as cv
from gaitlib.model import (
    Inertia,
    Load,
    PlanarBody,
    PlanarTree,
    _call,
    ellipsoid_contact,
    ellipsoid_frame,
    foot_angles,
    solve_spd,
)
from gaitlib import contact

__all__ = ["JUMP_SEGMENTS", "JumpModel"]

#: Thesis Table 3.1 (legs doubled): mass (kg), length (m), COM (m, from the lower joint),
#: moment of inertia about the COM (kg m²).
JUMP_SEGMENTS = {
    "toe": (0.59, 0.080, 0.040, 1.867e-3),
    "foot": (1.78, 0.116, 0.077, 9.626e-3),
    "shank": (7.63, 0.503, 0.285, 1.760e-1),
    "thigh": (16.40, 0.440, 0.250, 3.313e-1),
    "ht": (47.40, 0.660, 0.404, 3.361),
}


@dataclass(frozen=True)
class JumpModel:
    """Vertical-jump model of thesis Ch 3 (toe-included by default).

    Parameters
    ----------
    toe : bool
        True: 5 bodies (toe, foot, shank, thigh, HT), DOF 4 (welded) / 7 (free);
        False: 4 bodies, DOF 3 / 6.
    damping : float
        Viscous damper across every joint, N m s/rad (torque ``-damping * qd_j``).
    foot_incline_deg : float or None
        Angle of the MTP -> ankle line above the horizontal in standing, deg (None: the
        child model's phi1 for beta = 106 deg, 28.8 deg).
    contact_feet : int
        Multiplier of the ellipsoid loads (2: both feet, as the legs are doubled).
    smoothing : gaitlib.contact.Smoothing or None
    g : float
        Gravity, m/s².

    Coordinates: :attr:`coords` (free) and :attr:`joints` (welded phase); see the module
    docstring for the geometry.
    """

    toe: bool = True
    damping: float = 0.1
    foot_incline_deg: float | None = None
    contact_feet: int = 2
    smoothing: Any = None
    g: float = cv.G

    # ------------------------------------------------------------ structure
    @cached_property
    def segments(self) -> tuple[str, ...]:
        return (("toe",) if self.toe else ()) + ("foot", "shank", "thigh", "ht")

    @cached_property
    def joints(self) -> tuple[str, ...]:
        return (("mtp",) if self.toe else ()) + ("ankle", "knee", "hip")

    @cached_property
    def coords(self) -> tuple[str, ...]:
        return ("x", "y", "theta_z") + self.joints

    @property
    def n(self) -> int:
        return len(self.coords)

    @cached_property
    def incline(self) -> float:
        if self.foot_incline_deg is None:
            return foot_angles()[0]
        return self.foot_incline_deg * cv.DEG

    @cached_property
    def _foot_dir(self):
        return (-math.cos(self.incline), math.sin(self.incline))  # MTP -> ankle

    @cached_property
    def ankle_offset(self) -> tuple[float, float]:
        """Ankle position relative to the MTP point in standing, m."""
        L = JUMP_SEGMENTS["foot"][1]
        return (L * self._foot_dir[0], L * self._foot_dir[1])

    @cached_property
    def tree(self) -> PlanarTree:
        ank = self.ankle_offset
        b = []
        if self.toe:
            b.append(PlanarBody("toe"))
            b.append(PlanarBody("foot", "toe", (0.0, 0.0), "mtp", -1.0))
        else:
            b.append(PlanarBody("foot"))
        b += [
            PlanarBody("shank", "foot", ank, "ankle", -1.0),
            PlanarBody("thigh", "shank", (0.0, JUMP_SEGMENTS["shank"][1]), "knee", -1.0),
            PlanarBody("ht", "thigh", (0.0, JUMP_SEGMENTS["thigh"][1]), "hip", -1.0),
        ]
        return PlanarTree(b, root_coords=("x", "y", "theta_z"))

    @cached_property
    def inertias(self) -> list[Inertia]:
        out = []
        for s in self.segments:
            m, _, c, I = JUMP_SEGMENTS[s]
            if s == "toe":
                com = (c, 0.0)
            elif s == "foot":
                com = (c * self._foot_dir[0], c * self._foot_dir[1])
            else:
                com = (0.0, c)
            out.append(Inertia(m, com, I))
        return out

    @cached_property
    def total_mass(self) -> float:
        """kg (73.80 toe-included, 73.21 toeless)."""
        return float(sum(JUMP_SEGMENTS[s][0] for s in self.segments))

    @cached_property
    def standing_top(self) -> float:
        """Standing height of the model's top, m: the ankle's height above the MTP point
        (foot length × sin incline) + shank + thigh + HT (thesis Table 3.1) — the body
        height the MTG strength scaling (Eq 5.21) uses for this model."""
        L = {k: v[1] for k, v in JUMP_SEGMENTS.items()}
        return float(L["foot"] * math.sin(self.incline) + L["shank"] + L["thigh"] + L["ht"])

    def standing_q(self) -> np.ndarray:
        """Free coordinates of the standing posture with the MTP point at the origin."""
        return np.zeros(self.n)

    @cached_property
    def _smoothing(self):
        return self.smoothing if self.smoothing is not None else contact.Smoothing()

    # ------------------------------------------------------------ graph
    @cached_property
    def _sym(self):
        n, nj = self.n, len(self.joints)
        return {
            "q": ca.SX.sym("q", n), "qd": ca.SX.sym("qd", n), "qdd": ca.SX.sym("qdd", n),
            "qj": ca.SX.sym("qj", nj), "qdj": ca.SX.sym("qdj", nj),
            "qddj": ca.SX.sym("qddj", nj), "tau": ca.SX.sym("tau", nj),
            "p_contact": ca.SX.sym("p_contact", 39),
        }

    def _loads(self, st, pc):
        """Ellipsoid loads (toe-included model): frames, contact outputs, Load list."""
        if not self.toe:
            raise ValueError("the ellipsoid contact is defined for the toe-included model")
        off = (self.ankle_offset[0], 0.0)  # ground point below the ankle, in MTP frames
        frames, res, loads = [], [], []
        k = float(self.contact_feet)
        for i, e in enumerate(cv.ELLIPSOIDS):
            body = self.tree.index["toe" if e == "toe" else "foot"]
            fr = ellipsoid_frame(st[body], body, off, pc[13 * i:13 * i + 13])
            o = ellipsoid_contact(fr, self._smoothing)
            frames.append(fr)
            res.append(o)
            loads.append(Load(body, fr["centre"][:2], (k * o["fx"], k * o["fy"]), k * o["mz"]))
        return frames, res, loads

    def _dyn(self, qs, qds, qdds, loads=()):
        return self.tree.generalized_forces(qs, qds, qdds, self.inertias, loads, self.g)

    def _build(self, name):
        S = self._sym
        tree = self.tree
        B = self.damping
        if name in ("flight", "contact"):
            q, qd = S["q"], S["qd"]
            qs, qds = ca.vertsplit(q), ca.vertsplit(qd)
            inputs, names = [q, qd, S["tau"]], ["q", "qd", "tau"]
            loads, extra = (), {}
            if name == "contact":
                st = tree.kinematics(qs, qds)
                frames, res, loads = self._loads(st, ca.vertsplit(S["p_contact"]))
                inputs.append(S["p_contact"])
                names.append("p_contact")
                k = float(self.contact_feet)
                extra = {
                    "fn": k * ca.vertcat(*[r["fn"] for r in res]),
                    "grf_x": sum(ld.force[0] for ld in loads),
                    "grf_y": sum(ld.force[1] for ld in loads),
                }
            M = ca.jacobian(ca.vertcat(*self._dyn(qs, None, ca.vertsplit(S["qdd"]))), S["qdd"])
            h = ca.vertcat(*self._dyn(qs, qds, None, loads))
            Q = ca.vertcat(0, 0, 0, S["tau"] - B * qd[3:])
            qdd = solve_spd(M, Q - h)
            outs = {"qdd": qdd, **extra}
            return ca.Function(name, inputs, list(outs.values()), names, list(outs))
        if name == "contact_id":
            q, qd, qdd = S["q"], S["qd"], S["qdd"]
            qs, qds = ca.vertsplit(q), ca.vertsplit(qd)
            st = tree.kinematics(qs, qds, ca.vertsplit(qdd))
            _, res, loads = self._loads(st, ca.vertsplit(S["p_contact"]))
            Q = self._dyn(qs, qds, ca.vertsplit(qdd), loads)
            k = float(self.contact_feet)
            tau = ca.vertcat(*Q[3:]) + B * qd[3:]
            outs = {"tau": tau, "residual": ca.vertcat(*Q[:3]),
                    "fn": k * ca.vertcat(*[r["fn"] for r in res]),
                    "grf_x": sum(ld.force[0] for ld in loads),
                    "grf_y": sum(ld.force[1] for ld in loads)}
            return ca.Function(name, [q, qd, qdd, S["p_contact"]], list(outs.values()),
                               ["q", "qd", "qdd", "p_contact"], list(outs))
        if name == "flight_id":
            q, qd, qdd = S["q"], S["qd"], S["qdd"]
            Q = self._dyn(ca.vertsplit(q), ca.vertsplit(qd), ca.vertsplit(qdd))
            tau = ca.vertcat(*Q[3:]) + B * qd[3:]
            return ca.Function(name, [q, qd, qdd], [tau, ca.vertcat(*Q[:3])],
                               ["q", "qd", "qdd"], ["tau", "residual"])
        if name in ("stance", "stance_id"):
            qj, qdj = S["qj"], S["qdj"]
            root = [0.0, 0.0, 0.0]
            qs = root + ca.vertsplit(qj)
            qds = root + ca.vertsplit(qdj)
            if name == "stance":
                M = ca.jacobian(ca.vertcat(*self._dyn(qs, None, root + ca.vertsplit(S["qddj"]))),
                                S["qddj"])[3:, :]
                h = ca.vertcat(*self._dyn(qs, qds, None))[3:]
                qddj = solve_spd(M, S["tau"] - B * qdj - h)
                inputs, names = [qj, qdj, S["tau"]], ["qj", "qdj", "tau"]
            else:
                qddj = S["qddj"]
                inputs, names = [qj, qdj, qddj], ["qj", "qdj", "qddj"]
            Q = self._dyn(qs, qds, root + ca.vertsplit(qddj))
            Fx, Fy, Mz = Q[0], Q[1], Q[2]
            outs = {
                "qddj" if name == "stance" else "tau":
                    qddj if name == "stance" else ca.vertcat(*Q[3:]) + B * qdj,
                "grf": ca.vertcat(Fx, Fy, Mz),
                # point on the ground (y = 0) where the reaction has no moment
                "cop_x": Mz / ca.fmax(Fy, 1e-6),
            }
            return ca.Function(name, inputs, list(outs.values()), names, list(outs))
        if name in ("com", "energies", "points"):
            q, qd = S["q"], S["qd"]
            st = tree.kinematics(ca.vertsplit(q), ca.vertsplit(qd))
            if name == "com":
                c, v, _ = tree.com(st, self.inertias)
                return ca.Function(name, [q, qd], [ca.vertcat(*c), ca.vertcat(*v)],
                                   ["q", "qd"], ["com", "com_vel"])
            if name == "energies":
                T, V = tree.energies(st, self.inertias, self.g)
                return ca.Function(name, [q, qd], [T, V], ["q", "qd"],
                                   ["kinetic", "potential_gravity"])
            ix = tree.index
            pts = {"mtp": st[ix["foot"]].o, "ankle": st[ix["shank"]].o,
                   "knee": st[ix["thigh"]].o, "hip": st[ix["ht"]].o,
                   "head": PlanarTree.point(st[ix["ht"]], (0.0, JUMP_SEGMENTS["ht"][1]))}
            if self.toe:
                pts["toe_tip"] = PlanarTree.point(st[0], (JUMP_SEGMENTS["toe"][1], 0.0))
            return ca.Function(name, [q], [ca.vertcat(*v) for v in pts.values()], ["q"],
                               list(pts))
        if name == "ellipsoids":
            q, pc = S["q"], S["p_contact"]
            frames, _, _ = self._loads(self.tree.kinematics(ca.vertsplit(q)), ca.vertsplit(pc))
            C = ca.horzcat(*[ca.vertcat(*f["centre"]) for f in frames]).T
            return ca.Function(name, [q, pc], [C] + [f["R"] for f in frames],
                               ["q", "p_contact"], ["centres"] + [f"R_{e}" for e in cv.ELLIPSOIDS])
        raise KeyError(name)

    def function(self, name: str) -> ca.Function:
        """Cached SX functions (inputs -> outputs):

        * ``flight``: (q, qd, tau) -> qdd -- free model, no contact (DOF 6 / 7)
        * ``flight_id``: (q, qd, qdd) -> tau, residual (root wrench, zero if consistent)
        * ``stance``: (qj, qdj, tau) -> qddj, grf (Fx, Fy N; Mz N m about the MTP point),
          cop_x -- root welded at the standing pose (DOF 3 / 4)
        * ``stance_id``: (qj, qdj, qddj) -> tau, grf, cop_x
        * ``contact``: (q, qd, tau, p_contact) -> qdd, fn (3,), grf_x, grf_y (toe model)
        * ``contact_id``: (q, qd, qdd, p_contact) -> tau, residual (root wrench the contact
          and gravity leave unbalanced: zero if consistent), fn (3,), grf_x, grf_y
        * ``com``: (q, qd) -> com (2,), com_vel (2,); ``energies``: (q, qd) -> kinetic,
          potential_gravity; ``points``: (q) -> mtp, ankle, knee, hip, head, [toe_tip]
        * ``ellipsoids``: (q, p_contact) -> centres (3, 3: toe, ball, heel × x, y, z, m) and
          each ellipsoid's rotation matrix (toe model; for drawing)
        """
        cache = self.__dict__.setdefault("_functions", {})
        if name not in cache:
            cache[name] = self._build(name)
        return cache[name]

    # ------------------------------------------------------------ convenience
    def flight_dynamics(self, q, qd, tau):
        """Free-flight accelerations (n,)."""
        return _call(self.function("flight"), [q, qd, tau])["qdd"]

    def stance_dynamics(self, qj, qdj, tau) -> dict:
        """Welded-root phase: ``qddj`` and the ground reaction ``grf`` = (Fx, Fy, Mz)."""
        return _call(self.function("stance"), [qj, qdj, tau])

    def stance_inverse_dynamics(self, qj, qdj, qddj) -> dict:
        """Welded-root phase inverse dynamics: ``tau`` and ``grf``."""
        return _call(self.function("stance_id"), [qj, qdj, qddj])

    def contact_dynamics(self, q, qd, tau, p_contact=None) -> dict:
        """Free model with ellipsoid contact: ``qdd``, ``fn`` (3,), ``grf_x``, ``grf_y``."""
        if p_contact is None:
            p_contact = contact.default_params()
        return _call(self.function("contact"), [q, qd, tau, p_contact])

    def com(self, q, qd=None):
        qd = np.zeros(self.n) if qd is None else qd
        r = _call(self.function("com"), [q, qd])
        return r["com"], r["com_vel"]

    def energies(self, q, qd) -> dict:
        return _call(self.function("energies"), [q, qd])

    def points(self, q) -> dict:
        return _call(self.function("points"), [q])

