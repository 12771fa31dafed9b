"""Peer models for side-by-side benchmarks: planar OpenSim models read from ``.osim`` files.

:func:`osim_planar_model` parses an OpenSim model file (XML; OpenSim itself is never
imported) whose joints are a root ``PlanarJoint``, ``PinJoint`` s and ``WeldJoint`` s, merges
welded bodies, and builds a :class:`gaitlib.model.PlanarTree` with the file's masses,
centres of mass, moments of inertia and joint locations, plus the file's
``SmoothSphereHalfSpaceForce`` foot–ground contacts with Simbody's smooth Hunt–Crossley
formulas (:func:`smooth_sphere_halfspace_force`). Everything is CasADi SX, so optimal
control problems built on it have exact derivatives.

The module also replicates the two reference-data operations of OpenSim Moco 4.6 that a
tracking problem depends on: ``TabOpLowPassFilter`` (:func:`opensim_lowpass`) and the
interpolating ``GCVSpline`` of degree 5 (:class:`NaturalQuinticSpline`). Both were checked
against opensim 4.6 (``benchmarks/moco/moco_side.py --export-reference``): filtered table
to 1e-14, spline values to 1e-14.

Symbol legend
-------------
==========  ============================================================  =========
symbol      meaning                                                       unit
==========  ============================================================  =========
q           generalised coordinates, order :attr:`OsimPlanarModel.coords`  m, rad
qd, qdd     their first and second time derivatives                       /s, /s²
tau         applied generalised forces, one per coordinate (0 on the       N, N·m
            unactuated root coordinates)
Q           generalised forces the motion requires: M qdd + h − Q_contact  N, N·m
M, h        mass matrix; bias (Coriolis, centrifugal and gravity)
d           sphere indentation into the ground, ``radius − height``        m
v_n         normal velocity of the contact point, positive *into* ground   m/s
v_t         tangential (forward) velocity of the contact point             m/s
==========  ============================================================  =========

Frames and signs follow OpenSim: ground X forward, Y up, Z to the right; every joint of a
planar model rotates about Z; angles are counter-clockwise positive seen from +Z. A tree
body's frame is its joint frame (the child offset frame of its joint), which for the
``2D_gait.osim`` of Moco's 2D walking example coincides with the OpenSim body frame.
Lateral (Z) offsets do not enter planar dynamics and are ignored; so are the inertia
tensor's Ixx, Iyy and products (a body rotating about Z only needs Izz about its COM).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import casadi as ca
import numpy as np
import pandas as pd

from gaitlib.model import Inertia, Load, PlanarBody, PlanarTree, _call, solve_spd

__all__ = [
    "OSIM_GRAVITY",
    "SphereContact",
    "OsimPlanarModel",
    "osim_planar_model",
    "smooth_sphere_halfspace_force",
    "read_sto",
    "NaturalQuinticSpline",
    "opensim_lowpass",
]

#: OpenSim's default gravity magnitude (``Model.gravity`` = (0, −9.80665, 0) m/s²).
OSIM_GRAVITY = 9.80665

# OpenSim SmoothSphereHalfSpaceForce property defaults (OpenSim 4.x constructProperties).
_SSHS_DEFAULTS = {
    "stiffness": 1.0,
    "dissipation": 0.0,
    "static_friction": 0.0,
    "dynamic_friction": 0.0,
    "viscous_friction": 0.0,
    "transition_velocity": 0.01,
    "constant_contact_force": 1e-5,
    "hertz_smoothing": 300.0,
    "hunt_crossley_smoothing": 50.0,
}


# =====================================================================================
# Contact: Simbody's SmoothSphereHalfSpaceForce in the plane
# =====================================================================================
@dataclass(frozen=True)
class SphereContact:
    """One ``SmoothSphereHalfSpaceForce``: a sphere on a tree body against the ground y = 0.

    Attributes
    ----------
    name : str
        The force's name in the ``.osim`` file.
    body : str
        Tree body carrying the sphere (after welds are merged).
    center : (float, float)
        Sphere centre in that body's frame, m.
    z : float
        Lateral coordinate of the centre, m (does not enter the planar model).
    radius : float
        m.
    stiffness : float
        Plane-strain modulus E, N/m² (Hertz: k = ½ E^(2/3)).
    dissipation : float
        Hunt–Crossley dissipation c, s/m.
    static_friction, dynamic_friction : float
        μ_s, μ_d (1).
    viscous_friction : float
        μ_v, s/m.
    transition_velocity : float
        v_t at which the Stribeck-type friction coefficient peaks, m/s.
    constant_contact_force : float
        c_f, the small constant that keeps derivatives non-zero (Simbody's name; the XML
        tag is ``constant_contact_force`` or ``derivative_smoothing``); units m² in the
        depth term and m²/s² in the slip-speed term, as Simbody adds it to both.
    hertz_smoothing, hunt_crossley_smoothing : float
        b_d (1/m) and b_v (s/m) of the two tanh switches.
    """

    name: str
    body: str
    center: tuple[float, float]
    z: float
    radius: float
    stiffness: float
    dissipation: float
    static_friction: float
    dynamic_friction: float
    viscous_friction: float
    transition_velocity: float
    constant_contact_force: float
    hertz_smoothing: float
    hunt_crossley_smoothing: float


def smooth_sphere_halfspace_force(height, vx, vy, s: SphereContact):
    """Ground force on a sphere, Simbody's ``SmoothSphereHalfSpaceForce`` in the X–Y plane.

    Simbody (``SmoothSphereHalfSpaceForce.cpp``, Falisse, Serrancolí, Eastman), with the
    half-space's outward normal +Y (the floor of ``2D_gait.osim``)::

        d      = r − y_c                                     indentation
        k      = ½ E^(2/3)
        f_H    = 4/3 k √(r k) (√(d² + c_f))^(3/2) · (½ + ½ tanh(b_d d))
        f_HC   = f_H (1 + 3/2 c v_n) · (½ + ½ tanh(b_v (v_n + 2/(3c))))
        v_s    = √(v_t² + c_f),  ν = v_s / v_t,trans
        f_f    = f_HC (min(ν, 1) (μ_d + 2 (μ_s − μ_d)/(1 + ν²)) + μ_v v_s)
        F      = (−f_f v_t / v_s,  f_HC)                      force on the sphere's body

    The force acts at the point midway between the sphere's lowest point and the ground
    surface, ``(x_c, −d/2)``; ``v_n = −v_y`` and ``v_t = v_x`` are the velocity of the body
    point there (positive ``v_n`` = moving into the ground). ``min`` is kept as in Simbody
    (``casadi.fmin``: exact derivatives on either side of ν = 1).

    Parameters
    ----------
    height : scalar
        Height y_c of the sphere centre above the ground, m.
    vx, vy : scalar
        Ground-frame velocity of the body point at the contact point, m/s.
    s : SphereContact

    Returns
    -------
    dict with ``fx``, ``fy`` (N, on the body), ``depth`` d (m), ``point_y`` (m),
    ``fn`` (N, normal force f_HC) — CasADi expressions (or floats for float inputs).
    """
    d = s.radius - height
    cf = s.constant_contact_force
    k = 0.5 * s.stiffness ** (2.0 / 3.0)
    fh_pos = (4.0 / 3.0) * k * math.sqrt(s.radius * k) * ca.power(ca.sqrt(d * d + cf), 1.5)
    fh = fh_pos * (0.5 + 0.5 * ca.tanh(s.hertz_smoothing * d))
    vn = -vy
    c = s.dissipation
    fhc_pos = fh * (1.0 + 1.5 * c * vn)
    fhc = fhc_pos * (0.5 + 0.5 * ca.tanh(s.hunt_crossley_smoothing * (vn + 2.0 / (3.0 * c))))
    vslip = ca.sqrt(vx * vx + cf)
    vrel = vslip / s.transition_velocity
    us, ud, uv = s.static_friction, s.dynamic_friction, s.viscous_friction
    ff = fhc * (ca.fmin(vrel, 1.0) * (ud + 2.0 * (us - ud) / (1.0 + vrel * vrel)) + uv * vslip)
    return {"fx": -ff * vx / vslip, "fy": fhc, "depth": d, "point_y": -0.5 * d, "fn": fhc}


# =====================================================================================
# .osim parsing
# =====================================================================================
def _vec(text: str | None, n: int = 3) -> np.ndarray:
    if text is None:
        return np.zeros(n)
    v = np.array([float(x) for x in text.split()], dtype=float)
    if v.shape != (n,):
        raise ValueError(f"expected {n} numbers, got {text!r}")
    return v


def _osim_body_name(path: str) -> str:
    """'/bodyset/calcn_r' or 'calcn_r' → 'calcn_r'; '/ground' or 'ground' → 'ground'."""
    return path.strip().rstrip("/").split("/")[-1]


@dataclass
class _Frame:
    body: str  # OpenSim body (or 'ground')
    translation: np.ndarray  # in the body frame, m
    orientation: np.ndarray  # body-fixed XYZ, rad


def _check_planar(orientation: np.ndarray, what: str):
    if np.any(np.abs(orientation) > 0.0):
        raise NotImplementedError(
            f"{what}: non-zero frame orientation {orientation.tolist()} is not supported "
            "(planar tree bodies have no fixed rotation offsets)")


@dataclass(frozen=True, eq=False)
class OsimPlanarModel:
    """A planar OpenSim model as a gaitlib :class:`PlanarTree` with smooth sphere contact.

    Build with :func:`osim_planar_model`. All functions are CasADi SX, built once and
    cached; numeric inputs give numpy outputs.

    Attributes
    ----------
    name : str
    coords : tuple of str
        Coordinate names (OpenSim's), tree order: the root's ``(tx, ty, tilt)``, then one
        revolute coordinate per non-root tree body.
    tree : PlanarTree
    inertia : tuple of Inertia
        Per tree body: mass (kg), COM in the body frame (m), Izz about the COM (kg m²).
    parts : dict tree body → tuple of OpenSim bodies merged into it
    contacts : tuple of SphereContact
    gravity : float
        Magnitude of gravity along −Y, m/s².
    welded : tuple of str
        Joints treated as welds (WeldJoints of the file and pins welded on request).
    ignored : tuple of str
        Components of the file not represented (muscles, actuators, ...): the optimal
        control problem supplies its own actuation.
    source : str
        Path of the ``.osim`` file.
    """

    name: str
    coords: tuple[str, ...]
    tree: PlanarTree
    inertia: tuple[Inertia, ...]
    parts: dict
    contacts: tuple[SphereContact, ...]
    gravity: float
    welded: tuple[str, ...] = ()
    ignored: tuple[str, ...] = ()
    source: str = ""
    _cache: dict = field(default_factory=dict, repr=False)

    # ------------------------------------------------------------------ properties
    @property
    def n(self) -> int:
        return len(self.coords)

    @property
    def root_coords(self) -> tuple[str, ...]:
        return self.coords[:3]

    @property
    def joint_coords(self) -> tuple[str, ...]:
        return self.coords[3:]

    def total_mass(self) -> float:
        """Sum of all body masses, kg."""
        return float(sum(i.mass for i in self.inertia))

    def body_table(self) -> pd.DataFrame:
        """One row per tree body: parent, coordinate, joint location, mass, COM, Izz, parts."""
        rows = []
        for b, ine in zip(self.tree.bodies, self.inertia):
            rows.append({
                "body": b.name, "parent": b.parent or "ground", "coordinate": b.coord or "(root)",
                "joint_x": b.joint[0], "joint_y": b.joint[1], "mass": ine.mass,
                "com_x": ine.com[0], "com_y": ine.com[1], "izz": ine.moi,
                "parts": "+".join(self.parts[b.name]),
            })
        return pd.DataFrame(rows).set_index("body")

    # ------------------------------------------------------------------ symbolic core
    @cached_property
    def _sym(self):
        return {k: ca.SX.sym(k, self.n) for k in ("q", "qd", "qdd", "tau")}

    def _contact_loads(self, st):
        """Per-sphere outputs and the :class:`Load` list for tree kinematics ``st``."""
        out, loads = [], []
        for s in self.contacts:
            i = self.tree.index[s.body]
            b = st[i]
            centre = PlanarTree.point(b, s.center)
            point = (centre[0], -0.5 * (s.radius - centre[1]))  # midway in the overlap
            # velocity of the body point coinciding with the contact point
            r = (point[0] - b.o[0], point[1] - b.o[1])
            v = (b.v[0] - b.w * r[1], b.v[1] + b.w * r[0])
            f = smooth_sphere_halfspace_force(centre[1], v[0], v[1], s)
            f["px"], f["py"] = point
            out.append(f)
            loads.append(Load(i, point, (f["fx"], f["fy"])))
        return out, loads

    def _build(self, name: str) -> ca.Function:
        S = self._sym
        q, qd, qdd, tau = S["q"], S["qd"], S["qdd"], S["tau"]
        qs, qds, qdds = ca.vertsplit(q), ca.vertsplit(qd), ca.vertsplit(qdd)
        tree, ine, g = self.tree, list(self.inertia), self.gravity
        if name == "inverse_dynamics":
            st = tree.kinematics(qs, qds, qdds)
            _, loads = self._contact_loads(st)
            Q = tree.generalized_forces(qs, qds, qdds, ine, loads, g, states=st)
            return ca.Function(name, [q, qd, qdd], [ca.vertcat(*Q)], ["q", "qd", "qdd"], ["Q"])
        if name == "mass_matrix":
            Q = tree.generalized_forces(qs, None, qdds, ine, (), 0.0)
            M = ca.jacobian(ca.vertcat(*Q), qdd)
            M = 0.5 * (M + M.T)
            return ca.Function(name, [q], [M], ["q"], ["M"])
        if name == "bias":
            h = tree.generalized_forces(qs, qds, None, ine, (), g)
            return ca.Function(name, [q, qd], [ca.vertcat(*h)], ["q", "qd"], ["h"])
        if name == "forward_dynamics":
            st = tree.kinematics(qs, qds)
            _, loads = self._contact_loads(st)
            # M qdd = tau − (h − Q_contact): the inverse dynamics at qdd = 0 is h − Q_contact
            b = tree.generalized_forces(qs, qds, None, ine, loads, g, states=st)
            M = self.function("mass_matrix")(q)
            rhs = tau - ca.vertcat(*b)
            # LDLᵀ in children-before-parents order: no fill-in for a tree's mass matrix
            perm = list(reversed(range(self.n)))
            x = solve_spd(M[perm, perm], rhs[perm])
            acc = [None] * self.n
            for k, j in enumerate(perm):
                acc[j] = x[k]
            return ca.Function(name, [q, qd, tau], [ca.vertcat(*acc)], ["q", "qd", "tau"],
                               ["qdd"])
        if name == "contact":
            st = tree.kinematics(qs, qds)
            res, loads = self._contact_loads(st)
            zero = [Inertia(0.0, (0.0, 0.0), 0.0)] * len(tree.bodies)
            Qc = tree.generalized_forces(qs, None, None, zero, loads, 0.0, states=st)
            outs = {k: ca.vertcat(*[r[k] for r in res]) for k in ("fx", "fy", "depth", "px",
                                                                    "py")}
            outs["Q"] = -ca.vertcat(*Qc)
            names = list(outs)
            return ca.Function(name, [q, qd], [outs[k] for k in names], ["q", "qd"], names)
        if name == "points":
            st = tree.kinematics(qs)
            pts = {}
            for b, s in zip(tree.bodies, st):
                pts[f"origin_{b.name}"] = s.o
            for ct in self.contacts:
                pts[f"sphere_{ct.name}"] = PlanarTree.point(st[tree.index[ct.body]], ct.center)
            for b, s, i in zip(tree.bodies, st, ine):
                pts[f"com_{b.name}"] = PlanarTree.point(s, i.com)
            names = list(pts)
            return ca.Function(name, [q], [ca.vertcat(*pts[k]) for k in names], ["q"], names)
        if name == "com":
            st = tree.kinematics(qs, qds)
            c, v, mt = tree.com(st, ine)
            return ca.Function(name, [q, qd], [ca.vertcat(*c), ca.vertcat(*v), mt],
                               ["q", "qd"], ["com", "com_vel", "mass"])
        raise KeyError(f"unknown function {name!r}")

    def function(self, name: str) -> ca.Function:
        """The cached SX :class:`casadi.Function` ``name``.

        * ``inverse_dynamics``: (q, qd, qdd) → Q (n,) = M qdd + h − Q_contact, the
          generalised forces the motion needs (root entries: force along X, Y in N and
          moment in N·m on the root; joints: N·m).
        * ``forward_dynamics``: (q, qd, tau (n,)) → qdd (n,) from M qdd + h = tau + Q_contact.
        * ``mass_matrix``: (q) → M (n, n); ``bias``: (q, qd) → h (n,) (no contact).
        * ``contact``: (q, qd) → fx, fy, depth, px, py (one per sphere, order
          :attr:`contacts`; N, N, m, m, m) and Q (n,) the contact generalised force.
        * ``points``: (q) → ``origin_<body>``, ``sphere_<name>``, ``com_<body>`` (2,), m.
        * ``com``: (q, qd) → com (2,), com_vel (2,), mass.
        """
        if name not in self._cache:
            self._cache[name] = self._build(name)
        return self._cache[name]

    # ------------------------------------------------------------------ numeric helpers
    def inverse_dynamics(self, q, qd, qdd):
        """Q (n,) = M qdd + h − Q_contact (numbers → numpy, SX → SX)."""
        return _call(self.function("inverse_dynamics"), [q, qd, qdd])["Q"]

    def forward_dynamics(self, q, qd, tau):
        """qdd (n,) from M(q) qdd + h(q, qd) = tau + Q_contact(q, qd)."""
        return _call(self.function("forward_dynamics"), [q, qd, tau])["qdd"]

    def mass_matrix(self, q):
        return _call(self.function("mass_matrix"), [q])["M"]

    def bias(self, q, qd):
        return _call(self.function("bias"), [q, qd])["h"]

    def contact(self, q, qd) -> dict:
        return _call(self.function("contact"), [q, qd])

    def coord_index(self, name: str) -> int:
        try:
            return self.coords.index(name)
        except ValueError:
            raise KeyError(f"unknown coordinate {name!r}; known: {self.coords}") from None


def osim_planar_model(path, weld: Sequence[str] = ("lumbar",)) -> OsimPlanarModel:
    """Read a planar ``.osim`` file into an :class:`OsimPlanarModel`.

    Parameters
    ----------
    path : path-like
        OpenSim model file (XML). Supported joints: one ``PlanarJoint`` from ground (the
        root: coordinates rotation, X, Y translation), ``PinJoint`` (rotation about Z) and
        ``WeldJoint``; joint frames must not be rotated. Contact: ``ContactSphere`` s,
        one ``ContactHalfSpace`` on ground (the floor y = 0, normal +Y) and
        ``SmoothSphereHalfSpaceForce`` s (in ``<components>`` or the ``ForceSet``).
    weld : sequence of str
        Names of PinJoints to weld at zero angle (Moco's ``ModOpReplaceJointsWithWelds``).
        Default: ``("lumbar",)``, the torso–pelvis joint of Moco's ``2D_gait.osim``.

    Returns
    -------
    OsimPlanarModel
        Welded bodies merged (mass summed, COM mass-weighted, Izz by the parallel-axis
        theorem). Muscles and actuators are listed in ``ignored``.

    Examples
    --------
    >>> m = osim_planar_model("benchmarks/moco/2D_gait.osim")  # doctest: +SKIP
    >>> m.coords[:3], round(m.total_mass(), 6)                   # doctest: +SKIP
    (('pelvis_tx', 'pelvis_ty', 'pelvis_tilt'), 62.0)
    """
    path = Path(path)
    root = ET.parse(path).getroot()
    model = root.find("Model")
    if model is None:
        raise ValueError(f"{path}: no <Model> element")
    weld = tuple(weld)

    # ---- gravity
    gtext = model.findtext("gravity")
    gvec = _vec(gtext) if gtext is not None else np.array([0.0, -OSIM_GRAVITY, 0.0])
    if abs(gvec[0]) > 0 or abs(gvec[2]) > 0 or gvec[1] >= 0:
        raise NotImplementedError(f"gravity {gvec.tolist()} is not along −Y")
    gravity = float(-gvec[1])

    # ---- bodies
    bodies = {}
    for b in model.iterfind("BodySet/objects/Body"):
        inertia = _vec(b.findtext("inertia"), 6)
        bodies[b.get("name")] = {
            "mass": float(b.findtext("mass")),
            "com": _vec(b.findtext("mass_center")),
            "izz": float(inertia[2]),
        }

    # ---- joints
    joints = []
    for j in model.find("JointSet/objects"):
        frames = {}
        for f in j.iterfind("frames/PhysicalOffsetFrame"):
            frames[f.get("name")] = _Frame(_osim_body_name(f.findtext("socket_parent")),
                                           _vec(f.findtext("translation")),
                                           _vec(f.findtext("orientation")))

        def frame(sock, frames=frames):
            name = j.findtext(sock).strip()
            if name in frames:
                return frames[name]
            return _Frame(_osim_body_name(name), np.zeros(3), np.zeros(3))

        coords = [c.get("name") for c in j.iterfind("coordinates/Coordinate")]
        joints.append({"type": j.tag, "name": j.get("name"), "parent": frame("socket_parent_frame"),
                       "child": frame("socket_child_frame"), "coords": coords})
    for nm in weld:
        if nm not in [jt["name"] for jt in joints]:
            raise KeyError(f"weld: no joint {nm!r} in {path}")

    roots = [jt for jt in joints if jt["parent"].body == "ground"]
    if len(roots) != 1 or roots[0]["type"] != "PlanarJoint":
        raise NotImplementedError("expected exactly one PlanarJoint from ground as the root")
    rj = roots[0]
    for fr, what in ((rj["parent"], "ground frame"), (rj["child"], "root child frame")):
        _check_planar(fr.orientation, f"joint {rj['name']} {what}")
    if np.any(rj["parent"].translation != 0):
        raise NotImplementedError("root joint's ground frame must be the ground origin")
    rot, tx, ty = rj["coords"]

    # tree body of each OpenSim body and the body→tree-frame offset (no rotations)
    where = {rj["child"].body: (rj["child"].body, -rj["child"].translation[:2])}
    tree_bodies = [PlanarBody(rj["child"].body)]
    parts = {rj["child"].body: [rj["child"].body]}
    welded = []
    pending = [jt for jt in joints if jt is not rj]
    while pending:
        progress = False
        for jt in list(pending):
            pb = jt["parent"].body
            if pb not in where:
                continue
            _check_planar(jt["parent"].orientation, f"joint {jt['name']} parent frame")
            _check_planar(jt["child"].orientation, f"joint {jt['name']} child frame")
            tb, off = where[pb]
            loc = jt["parent"].translation[:2] + off  # joint centre in the tree body frame
            cb = jt["child"].body
            if jt["type"] == "WeldJoint" or jt["name"] in weld:
                # child body frame = joint frame − child offset, all in tb's frame
                where[cb] = (tb, loc - jt["child"].translation[:2])
                parts[tb].append(cb)
                welded.append(jt["name"])
            elif jt["type"] == "PinJoint":
                if len(jt["coords"]) != 1:
                    raise ValueError(f"PinJoint {jt['name']} needs one coordinate")
                tree_bodies.append(PlanarBody(cb, tb, (float(loc[0]), float(loc[1])),
                                              jt["coords"][0]))
                where[cb] = (cb, -jt["child"].translation[:2])
                parts[cb] = [cb]
            else:
                raise NotImplementedError(f"joint type {jt['type']} ({jt['name']})")
            pending.remove(jt)
            progress = True
        if not progress:
            raise ValueError(f"joints not connected to the root: {[j['name'] for j in pending]}")
    missing = set(bodies) - set(where)
    if missing:
        raise ValueError(f"bodies without a joint path to ground: {sorted(missing)}")

    tree = PlanarTree(tree_bodies, root_coords=(tx, ty, rot))

    # composite inertias
    inertia = []
    for b in tree.bodies:
        ms, cs, izz = [], [], []
        for ob in parts[b.name]:
            _, off = where[ob]
            ms.append(bodies[ob]["mass"])
            cs.append(bodies[ob]["com"][:2] + off)
            izz.append(bodies[ob]["izz"])
        m = float(sum(ms))
        c = sum(mi * ci for mi, ci in zip(ms, cs)) / m
        I = sum(Ii + mi * float(np.sum((ci - c) ** 2)) for mi, ci, Ii in zip(ms, cs, izz))
        inertia.append(Inertia(m, (float(c[0]), float(c[1])), float(I)))

    # ---- contact geometry and forces
    geoms = {}
    for gset in model.iterfind("ContactGeometrySet/objects"):
        for gm in gset:
            geoms[gm.get("name")] = gm
    floor = [g for g in geoms.values() if g.tag == "ContactHalfSpace"]
    contacts = []
    force_elems = list(model.iterfind("components/SmoothSphereHalfSpaceForce")) + list(
        model.iterfind("ForceSet/objects/SmoothSphereHalfSpaceForce"))
    for fe in force_elems:
        sph = geoms[_osim_body_name(fe.findtext("socket_sphere"))]
        hs = geoms[_osim_body_name(fe.findtext("socket_half_space"))]
        if sph.tag != "ContactSphere" or hs.tag != "ContactHalfSpace":
            raise NotImplementedError(f"{fe.get('name')}: expected a sphere and a half space")
        if _osim_body_name(hs.findtext("socket_frame")) != "ground" or np.any(
                _vec(hs.findtext("location")) != 0) or not np.allclose(
                _vec(hs.findtext("orientation")), [0.0, 0.0, -math.pi / 2], atol=1e-12):
            raise NotImplementedError(f"{fe.get('name')}: half space must be the floor y = 0 "
                                      "(ground, orientation 0 0 -pi/2)")
        _check_planar(_vec(sph.findtext("orientation")), f"sphere {sph.get('name')}")
        tb, off = where[_osim_body_name(sph.findtext("socket_frame"))]
        loc = _vec(sph.findtext("location"))
        par = dict(_SSHS_DEFAULTS)
        for k in par:
            txt = fe.findtext(k)
            if txt is None and k == "constant_contact_force":
                txt = fe.findtext("derivative_smoothing")
            if txt is not None:
                par[k] = float(txt)
        c2 = loc[:2] + off
        contacts.append(SphereContact(fe.get("name"), tb, (float(c2[0]), float(c2[1])),
                                      float(loc[2]), float(sph.findtext("radius")), **par))
    if contacts and len(floor) < 1:
        raise ValueError("contact forces but no ContactHalfSpace")

    ignored = [c.get("name") for c in model.iterfind("components/*")
               if c.tag != "SmoothSphereHalfSpaceForce"]
    ignored += [c.get("name") for c in model.iterfind("ForceSet/objects/*")
                if c.tag != "SmoothSphereHalfSpaceForce"]

    return OsimPlanarModel(
        name=model.get("name") or path.stem,
        coords=tree.coords,
        tree=tree,
        inertia=tuple(inertia),
        parts={k: tuple(v) for k, v in parts.items()},
        contacts=tuple(contacts),
        gravity=gravity,
        welded=tuple(welded),
        ignored=tuple(ignored),
        source=str(path),
    )


# =====================================================================================
# Reference data as OpenSim Moco 4.6 processes it
# =====================================================================================
def read_sto(path) -> pd.DataFrame:
    """Read an OpenSim ``.sto`` / ``.mot`` table (tab-separated, header up to
    ``endheader``) into a DataFrame indexed by ``time`` (s). Units as in the file; a
    header line ``inDegrees=yes`` is reported in ``frame.attrs['inDegrees']``."""
    lines = Path(path).read_text().splitlines()
    end = next(i for i, ln in enumerate(lines) if ln.strip() == "endheader")
    header = {ln.split("=", 1)[0].strip(): ln.split("=", 1)[1].strip()
              for ln in lines[:end] if "=" in ln}
    frame = pd.read_csv(path, sep="\t", skiprows=end + 1)
    frame = frame.loc[:, [c for c in frame.columns if not str(c).startswith("Unnamed")]]
    frame = frame.set_index("time")
    frame.attrs["inDegrees"] = header.get("inDegrees", "no")
    return frame


class NaturalQuinticSpline:
    """Interpolating natural quintic spline: OpenSim's ``GCVSpline`` (degree 5, error
    variance 0), which Moco's ``MocoStateTrackingGoal`` and ``TableUtilities::resample``
    use. Knots at the data times; third and fourth derivatives vanish at both ends.

    ``spline(t, nu=0)`` evaluates the ``nu``-th derivative; ``y`` may be (n,) or (n, k).
    """

    def __init__(self, x, y):
        from scipy.interpolate import make_interp_spline

        y = np.asarray(y, dtype=float)
        self._two = y.ndim == 2
        Y = y if self._two else y[:, None]
        bc = ([(3, 0.0), (4, 0.0)], [(3, 0.0), (4, 0.0)])
        self.x = np.asarray(x, dtype=float)
        self._s = [make_interp_spline(self.x, Y[:, j], k=5, bc_type=bc) for j in
                   range(Y.shape[1])]

    def __call__(self, t, nu: int = 0):
        out = np.stack([s(np.asarray(t, float), nu) for s in self._s], axis=-1)
        return out if self._two else out[..., 0]


def _pad(n: int, a: np.ndarray) -> np.ndarray:
    """OpenSim ``Signal::Pad``: n points reflected and negated about each end."""
    pre = 2.0 * a[0] - a[n:0:-1]
    post = 2.0 * a[-1] - a[len(a) - 2:len(a) - 2 - n:-1]
    return np.concatenate([pre, a, post])


def _lowpass_iir(T: float, fc: float, sig: np.ndarray) -> np.ndarray:
    """OpenSim ``Signal::LowpassIIR``: 3rd-order Butterworth, forward then backward."""
    if fc >= 0.5 / T:
        fc = 0.49 / T
    wa = math.tan(2.0 * math.pi * fc * T / 2.0)
    wa2, wa3 = wa * wa, wa * wa * wa
    den = (wa + 1.0) * (wa * wa + wa + 1.0)
    a = (wa3 / den, 3 * wa3 / den, 3 * wa3 / den, wa3 / den)
    b = (1.0, (3 * wa3 + 2 * wa2 - 2 * wa - 3) / den, (3 * wa3 - 2 * wa2 - 2 * wa + 3) / den,
         (wa - 1) * (wa2 - wa + 1) / den)

    def once(s):
        f = s.copy()
        for i in range(3, len(s)):
            f[i] = (a[0] * s[i] + a[1] * s[i - 1] + a[2] * s[i - 2] + a[3] * s[i - 3]
                    - b[1] * f[i - 1] - b[2] * f[i - 2] - b[3] * f[i - 3])
        return f

    return once(once(sig)[::-1].copy())[::-1].copy()


def opensim_lowpass(frame: pd.DataFrame, cutoff: float) -> pd.DataFrame:
    """Moco 4.6's ``TabOpLowPassFilter(cutoff)`` (``TableUtilities::filterLowpass`` with
    padding), replicated.

    If the sampling is not uniform (mean interval − smallest interval > machine epsilon)
    the table is first resampled at the smallest interval with :class:`NaturalQuinticSpline`
    (times accumulated by repeated addition from the first time, as OpenSim does); then
    each column is padded by half its length (:func:`_pad`), filtered with the 3rd-order
    IIR Butterworth forward and backward, and the padding removed.

    Parameters
    ----------
    frame : DataFrame indexed by time (s)
    cutoff : float
        Hz.
    """
    t = np.asarray(frame.index, dtype=float)
    Y = frame.to_numpy(dtype=float)
    dt = np.diff(t)
    dtmin = float(dt.min())
    dtavg = (t[-1] - t[0]) / (len(t) - 1)
    if dtavg - dtmin > np.finfo(float).eps:
        tt, x = [], t[0]
        while x <= t[-1]:
            tt.append(x)
            x += dtmin
        tt = np.array(tt)
        Y = NaturalQuinticSpline(t, Y)(tt)
        t = tt
    n = len(t) // 2
    out = np.empty_like(Y)
    for j in range(Y.shape[1]):
        out[:, j] = _lowpass_iir(dtmin, cutoff, _pad(n, Y[:, j]))[n:n + len(t)]
    return pd.DataFrame(out, index=pd.Index(t, name="time"), columns=frame.columns)

