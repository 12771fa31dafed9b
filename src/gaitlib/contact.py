"""Ellipsoid–plane volumetric foot–ground contact (thesis Sec 4.1.2, Tables 4.5, 4.7, 4.17, 4.18).

Each foot carries three ellipsoids (:data:`gaitlib.conventions.ELLIPSOIDS` =
``("toe", "ball", "heel")``): the toe ellipsoid is fixed to the toe segment, the ball and
heel ellipsoids to the hind-fore-foot. Every ellipsoid has the 13 parameters of thesis
Table 4.5 (:data:`PARAM_NAMES`); the 39-vector of a foot is ellipsoid-major (toe's 13,
ball's 13, heel's 13). Identified values are the thesis's left-foot values (Tables 4.17 and
4.18); the right foot is the mirror image about the sagittal plane (:func:`mirror`,
thesis Sec 4.1.2).

Physics (Gonthier et al. 2004; Brown & McPhee; closed forms in
``shared/design/model-facts.md`` Sec 1 — the thesis cites but does not print them)
-------------------------------------------------------------------------------------
Ground plane ``y = 0`` with normal ``+Y`` (:mod:`gaitlib.conventions`). Work in the
ellipsoid's principal frame with radii ``a, b, c`` (along the ellipsoid's own x, y, z axes),
``D = diag(a, b, c)`` and ``n = Rᵀ ŷ`` the ground normal in that frame:

* support half-height ``h = |D n|``; depth ``δ = h − y_c``; normalised cap height
  ``t = δ / h`` (contact for ``t > 0``; the formulas hold for ``0 ≤ t ≤ 2``);
* penetrated volume ``V = π a b c t² (3 − t) / 3``;
* volume centroid relative to the centre ``r_c = −(z̄ / h) D² n`` with
  ``z̄ = 3 (2 − t)² / (4 (3 − t))`` (on the conjugate diameter ``D² n``, not along ``n``);
* normal force (thesis Table 4.4 No. 5) ``F_n = k_v V (1 + a_v δ̇)``, ``δ̇ = −v_p,y`` the
  penetration rate of the body material point at the centroid (positive pressing in);
* friction (Brown–McPhee continuous model, :func:`friction_coefficient`)
  ``F_x = −μ(v_p,x) F_n``;
* rolling resistance (2D) ``τ = −k_v |a_v| J ω`` with ``J = x̂ᵀ S x̂``,
  ``S = a b c I⊥(t) [D² − (D² n)(D² n)ᵀ / h²]``, ``I⊥ = π t³ (3t² − 15t + 20) / 60`` and
  ``x̂ = Rᵀ X̂`` the ground's forward axis in the ellipsoid frame (Brown's version: the
  second moment of the cap volume with points projected along the conjugate diameter onto
  the central plane parallel to the ground; it is the exact ``∫ (x − p_x)² dV`` whenever
  ``n`` is a principal axis, e.g. a sphere);
* spinning friction is zero in the sagittal plane.

The force is applied at the volume centroid ``p``; :func:`ellipsoid_plane` returns its
moment about the ellipsoid centre plus the rolling couple.

Smoothing for gradient-based optimal control (:class:`Smoothing`): ``t`` is replaced by the
smooth max ``½ (t + sqrt(t² + ε_t²))`` (``V`` has a jump in its second derivative at
``t = 0``), and the normal force by ``½ (F_raw + sqrt(F_raw² + ε_F²))`` (``F_raw`` goes
negative when separating faster than ``1 / a_v``). The unclamped ``fn_raw`` is exposed so
that an optimiser can constrain it ``≥ 0`` as the thesis does (Sec 4.4.1).

Everything is built once with CasADi SX; numeric calls go through a cached
:class:`casadi.Function` (:func:`contact_function`), so floats (plots) and SX/MX
(optimisation) give identical results.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from gaitlib.conventions import DEG, ELLIPSOIDS

__all__ = [
    "PARAM_NAMES",
    "PARAM_UNITS",
    "N_PER_ELLIPSOID",
    "TABLE_4_17_OUTSIDE_TABLE_4_7",
    "param_names",
    "param_index",
    "with_friction_floor",
    "ellipsoid_slice",
    "default_params",
    "bounds",
    "params_table",
    "euler_321",
    "mirror",
    "Smoothing",
    "friction_coefficient",
    "ellipsoid_plane",
    "contact_function",
    "CONTACT_INPUTS",
    "CONTACT_OUTPUTS",
]

#: The 13 parameters of one ellipsoid, thesis Table 4.5 order.
PARAM_NAMES = (
    "k_v", "a_v", "mu_s", "mu_d", "a", "b", "c", "r_x", "r_y", "r_z", "gamma", "beta", "alpha"
)  # fmt: skip
#: SI unit of each entry of :data:`PARAM_NAMES`.
PARAM_UNITS = ("N/m^3", "s/m", "-", "-", "m", "m", "m", "m", "m", "m", "rad", "rad", "rad")
N_PER_ELLIPSOID = len(PARAM_NAMES)

# Table units -> SI: the thesis tables give lengths in mm and angles in degrees.
_TABLE_UNITS = ("N/m^3", "s/m", "-", "-", "mm", "mm", "mm", "mm", "mm", "mm", "deg", "deg", "deg")
_TO_SI = np.array([1.0, 1.0, 1.0, 1.0] + [1e-3] * 6 + [DEG] * 3)

# Identified left-foot values, in table units (Table 4.5 order).
# k_v, a_v, mu_s, mu_d: thesis Table 4.18. a, b, c, r, angles: Table 4.17 (printed there in
# metres; written here in mm so that they convert exactly like the Table 4.7 bounds).
_DEFAULT_TABLE = {
    #        k_v     a_v      mu_s    mu_d    a     b     c     r_x    r_y  r_z   gamma   beta    alpha
    "toe": (0.75e7, 1.1355, 0.3404, 0.2819, 17.7, 30.0, 16.5, 163.2, 4.1, 23.5, -33.38, -28.89, 155.39),
    "ball": (2.40e7, 1.89e-5, 0.0101, 0.0100, 80.0, 20.6, 17.9, 67.5, 8.9, -6.0, -58.49, -12.45, -89.10),
    "heel": (1.54e7, 2.4271, 0.1703, 0.1686, 30.9, 40.0, 13.5, -25.6, 3.5, 0.3, -83.00, -20.36, -91.08),
}  # fmt: skip

# Thesis Table 4.7 bounds, table units (Table 4.5 order; the table prints the columns as
# a b c | gamma beta alpha | r_x r_y r_z, re-ordered here).
_LOWER_TABLE = {
    "toe": (1e5, 0.0, 0.01, 0.01, 11.3, 10.0, 10.0, 115.4, 6.7, 21.1, -50.8, -54.0, 143.9),
    "ball": (1e5, 0.0, 0.01, 0.01, 30.0, 14.6, 3.0, 62.9, 4.0, -6.6, -75.2, -18.0, -97.5),
    "heel": (1e5, 0.0, 0.01, 0.01, 23.0, 25.0, 12.0, -24.2, -3.0, -0.2, -91.8, -28.5, -99.3),
}
_UPPER_TABLE = {
    "toe": (1e8, 3.0, 1.3, 1.3, 17.7, 50.0, 16.5, 153.5, 20.0, 25.8, -39.8, -14.5, 154.3),
    "ball": (1e8, 3.0, 1.3, 1.3, 140.0, 23.0, 18.0, 99.0, 11.4, -5.4, -41.1, -3.2, -83.6),
    "heel": (1e8, 3.0, 1.3, 1.3, 40.0, 40.0, 22.0, -4.4, 12.6, 0.3, -59.7, -16.9, -84.2),
}

#: Entries of the thesis's identified values (Table 4.17, Sec 4.4) that lie outside the
#: Table 4.7 bounds (which were stated for the Sec 4.3 identifications). Sec 4.4 must have
#: used wider, unreported bounds; ``bounds(include_defaults=True)`` widens to cover them.
TABLE_4_17_OUTSIDE_TABLE_4_7 = ("toe.r_x", "toe.r_y", "toe.gamma", "toe.alpha", "heel.r_x")


def param_names() -> list[str]:
    """Names of the 39 contact parameters, ellipsoid-major: ``"toe.k_v", …, "heel.alpha"``."""
    return [f"{e}.{p}" for e in ELLIPSOIDS for p in PARAM_NAMES]


def param_index(ellipsoid: str, name: str) -> int:
    """Index of parameter ``name`` of ``ellipsoid`` in the 39-vector."""
    return ELLIPSOIDS.index(ellipsoid) * N_PER_ELLIPSOID + PARAM_NAMES.index(name)


def with_friction_floor(p, floor: float) -> np.ndarray:
    """A copy of the 39-vector ``p`` (parameters or their bounds) with every ellipsoid's μ_s
    and μ_d raised to at least ``floor`` (dimensionless); the other entries unchanged."""
    out = np.array(p, dtype=float)
    for e in ELLIPSOIDS:
        for k in ("mu_s", "mu_d"):
            i = param_index(e, k)
            out[i] = max(out[i], float(floor))
    return out


def ellipsoid_slice(ellipsoid: str) -> slice:
    """Slice of the 39-vector holding ``ellipsoid``'s 13 parameters (works on numpy and SX)."""
    i = ELLIPSOIDS.index(ellipsoid) * N_PER_ELLIPSOID
    return slice(i, i + N_PER_ELLIPSOID)


def _table_to_si(table: dict) -> np.ndarray:
    return np.concatenate([np.asarray(table[e], dtype=float) * _TO_SI for e in ELLIPSOIDS])


def default_params() -> np.ndarray:
    """Identified contact parameters of the **left** foot, SI, shape (39,).

    Geometry (a, b, c, r_x, r_y, r_z, γ, β, α) from thesis Table 4.17, stiffness, damping
    and friction (k_v, a_v, μ_s, μ_d) from Table 4.18 (the Sec 4.4 "new approach").
    Units: N/m³, s/m, –, –, m ×6, rad ×3 per ellipsoid (:data:`PARAM_UNITS`). Positions
    and Euler angles are relative to the carrying segment's frame (toe ellipsoid: toe
    segment; ball and heel: hind-fore-foot), which in the standing posture is parallel to
    the ground frame (thesis Sec 4.1.2).

    Notes
    -----
    * Five entries lie outside the Table 4.7 bounds, see
      :data:`TABLE_4_17_OUTSIDE_TABLE_4_7`.
    * Orientation convention: the Euler angles are read as a direction cosine matrix
      (:func:`ellipsoid_to_segment`, ellipsoid → segment = ``(Rz Ry Rx)ᵀ``). In that
      reading the lowest points of the toe, ball and heel ellipsoids lie 19, 12 and
      15 mm below the foot-frame origin, so a standing foot loads all three once the
      body settles ≈ 1–2 cm above the geometric foot (the pelvis height is a free
      coordinate). Read actively (``Rz Ry Rx``) the ball would sink 58 mm and carry the
      body alone. The thesis does not state its convention or the frame origin.
    """
    return _table_to_si(_DEFAULT_TABLE)


def bounds(include_defaults: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds of the 39 contact parameters, SI, thesis Table 4.7.

    Parameters
    ----------
    include_defaults : bool, optional
        If True, widen each bound just enough to contain :func:`default_params` (the
        Table 4.17 identified values violate five Table 4.7 bounds,
        :data:`TABLE_4_17_OUTSIDE_TABLE_4_7`). Default False: Table 4.7 verbatim.

    Returns
    -------
    lower, upper : numpy.ndarray, shape (39,)
        Same order and units as :func:`default_params`.
    """
    lo, up = _table_to_si(_LOWER_TABLE), _table_to_si(_UPPER_TABLE)
    if include_defaults:
        p = default_params()
        lo, up = np.minimum(lo, p), np.maximum(up, p)
    return lo, up


def params_table(p) -> "pandas.DataFrame":  # noqa: F821
    """Contact parameters as an ellipsoid × parameter table for the book.

    Parameters
    ----------
    p : array_like, shape (39,)
        Parameter vector in SI (:func:`default_params` order).

    Returns
    -------
    pandas.DataFrame
        Index: ellipsoids; columns labelled with units, lengths in mm and angles in
        degrees as in thesis Tables 4.7/4.17.
    """
    import pandas as pd

    p = np.asarray(p, dtype=float).reshape(len(ELLIPSOIDS), N_PER_ELLIPSOID) / _TO_SI
    cols = [
        f"{n} ({u})" if u != "-" else n for n, u in zip(PARAM_NAMES, _TABLE_UNITS, strict=True)
    ]
    return pd.DataFrame(p, index=pd.Index(ELLIPSOIDS, name="ellipsoid"), columns=cols)


# --------------------------------------------------------------------------------------
# Kinematics helpers
# --------------------------------------------------------------------------------------


def _is_symbolic(*xs) -> bool:
    return any(isinstance(x, (ca.SX, ca.MX)) for x in xs)


def euler_321(gamma, beta, alpha):
    """Rotation matrix of 3-2-1 body-fixed Euler angles (thesis Table 4.5).

    ``R = Rz(γ) @ Ry(β) @ Rx(α)``: rotate by γ about z, then by β about the new y, then by
    α about the newest x. Maps ellipsoid-frame coordinates to segment-frame coordinates
    (``x_segment = R @ x_ellipsoid``). Right-handed, positive angles counter-clockwise.

    Parameters
    ----------
    gamma, beta, alpha : float or casadi.SX/MX
        Angles, rad.

    Returns
    -------
    numpy.ndarray or casadi.SX/MX, shape (3, 3)
        numpy for numeric input, CasADi for symbolic input.
    """
    if _is_symbolic(gamma, beta, alpha):
        cg, sg, cb, sb = ca.cos(gamma), ca.sin(gamma), ca.cos(beta), ca.sin(beta)
        cal, sal = ca.cos(alpha), ca.sin(alpha)
        return ca.vertcat(
            ca.horzcat(cg * cb, cg * sb * sal - sg * cal, cg * sb * cal + sg * sal),
            ca.horzcat(sg * cb, sg * sb * sal + cg * cal, sg * sb * cal - cg * sal),
            ca.horzcat(-sb, cb * sal, cb * cal),
        )
    cg, sg, cb, sb = math.cos(gamma), math.sin(gamma), math.cos(beta), math.sin(beta)
    cal, sal = math.cos(alpha), math.sin(alpha)
    return np.array(
        [
            [cg * cb, cg * sb * sal - sg * cal, cg * sb * cal + sg * sal],
            [sg * cb, sg * sb * sal + cg * cal, sg * sb * cal - cg * sal],
            [-sb, cb * sal, cb * cal],
        ]
    )


def ellipsoid_to_segment(gamma, beta, alpha):
    """Rotation taking ellipsoid-frame coordinates to segment-frame coordinates.

    The thesis's Euler angles (Table 4.5, Tables 4.10–4.17) are read as a **direction
    cosine matrix** (passive, MapleSim-style): ``euler_321(γ, β, α)`` maps *segment* to
    *ellipsoid* coordinates, so the ellipsoid → segment rotation is its transpose,
    ``R = (Rz(γ) Ry(β) Rx(α))ᵀ``.

    Why this reading (and not the active ``Rz Ry Rx``): with the identified values of
    Table 4.17 it puts the ball ellipsoid's 80 mm semi-axis nearly horizontal and oblique
    across the forefoot (the line of the metatarsal heads), the heel's 40 mm axis along the
    foot, and the lowest points of the toe, ball and heel ellipsoids within 8 mm of each
    other (−19, −12, −15 mm in the foot frame), so that a standing foot loads all three.
    Read actively, the ball's long axis points 58° downwards and the ball alone would sink
    58 mm, more than any foot pad. The thesis does not state its convention; this is our
    interpretation, stated in the book.

    Parameters
    ----------
    gamma, beta, alpha : float or casadi.SX/MX, rad.

    Returns
    -------
    (3, 3) numpy.ndarray or casadi matrix.
    """
    R = euler_321(gamma, beta, alpha)
    return R.T


_S = np.array([1.0, 1.0, -1.0])


def mirror(R, r):
    """Mirror a left-foot ellipsoid to the right foot about the sagittal (X–Y) plane.

    The reflection ``S = diag(1, 1, −1)`` maps the ellipsoid ``{r + R D u : |u| ≤ 1}`` to
    ``{S r + (S R S) D u}``: same radii, orientation ``S R S`` (still a proper rotation),
    centre ``S r`` (thesis Sec 4.1.2: "We reflected the three ellipsoids of the left foot
    with respect to the sagittal plane").

    Parameters
    ----------
    R : array_like or casadi.SX/MX, shape (3, 3)
        Ellipsoid-to-segment rotation of the left-foot ellipsoid.
    r : array_like or casadi.SX/MX, shape (3,)
        Ellipsoid centre in the left segment's frame, m.

    Returns
    -------
    R_mirrored, r_mirrored
        Same types as the inputs (numpy for numeric input).
    """
    ss = np.outer(_S, _S)
    if isinstance(R, (ca.SX, ca.MX, ca.DM)):
        Rm = R * ca.DM(ss)
    else:
        Rm = np.asarray(R, dtype=float) * ss
    if isinstance(r, (ca.SX, ca.MX, ca.DM)):
        rm = ca.reshape(r, 3, 1) * ca.DM(_S)
    else:
        rm = np.asarray(r, dtype=float).reshape(3) * _S
    return Rm, rm


# --------------------------------------------------------------------------------------
# Contact law
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Smoothing:
    """Smoothing constants of the contact law (not given by the thesis; our choice).

    Attributes
    ----------
    v_transition : float
        Brown–McPhee friction transition velocity ``v_tr``, m/s: μ peaks (≈ μ_s) at
        ``|v| = v_tr`` and tends to μ_d for ``|v| ≫ v_tr``. Default 0.1 m/s as in Brown &
        McPhee (thesis Sec 4.1.2). Smaller values are stiffer (0.05 m/s is a good
        performance/accuracy trade-off in practice).
    eps_t : float
        Smooth-max width for the normalised cap height ``t`` (dimensionless):
        ``t_s = ½ (t + sqrt(t² + eps_t²))``. At ``t = 0`` this adds ``eps_t / 2`` (0.5e-3 of
        the half-height ``h``, i.e. ≈ 10 µm of depth for the foot ellipsoids). Out of
        contact ``t_s ≈ eps_t² / (4 |t|)``, a volume of order ``π a b c eps_t⁴ / (16 t²)``:
        below 1e-17 m³ (≪ 1 µN) once the ellipsoid is one half-height above the ground.
    eps_force : float
        Smooth-max width for clamping the normal force, N:
        ``F_n = ½ (F_raw + sqrt(F_raw² + eps_force²))``. ``F_n ≥ 0`` always, and
        ``F_n ≥ eps_force / 2`` (= 0.5 mN by default) out of contact, which bounds the
        spurious out-of-contact load to ``(1 + μ_s) eps_force / 2`` per ellipsoid — five
        orders of magnitude below a foot's weight. The true unilateral constraint is the
        optimiser's ``fn_raw ≥ 0`` (thesis Sec 4.4.1).
    """

    v_transition: float = 0.1
    eps_t: float = 1e-3
    eps_force: float = 1e-3


def _smax(x, eps):
    """Smooth max(x, 0): ½ (x + sqrt(x² + eps²)); ≥ 0, → max(x, 0) as eps → 0."""
    return 0.5 * (x + ca.sqrt(x * x + eps * eps))


def friction_coefficient(v, mu_s, mu_d, v_transition=Smoothing.v_transition):
    """Brown–McPhee continuous friction coefficient μ(v) (model-facts Sec 1).

    ``μ(v) = μ_d tanh(4 v / v_tr) + (μ_s − μ_d) (v / v_tr) / (¼ (v / v_tr)² + ¾)²``.
    Odd and smooth; the Stribeck term peaks at exactly ``v = v_tr`` with value
    ``μ_s − μ_d``, so ``μ(v_tr) = μ_s − μ_d (1 − tanh 4) ≈ μ_s``; ``μ → μ_d`` for
    ``|v| ≫ v_tr``. The friction force on the body is ``F_x = −μ(v_x) F_n``.

    Parameters
    ----------
    v : float, numpy.ndarray or casadi.SX/MX
        Slip velocity, m/s (any shape for numpy).
    mu_s, mu_d : float or casadi
        Static and dynamic friction coefficients, dimensionless.
    v_transition : float
        Transition velocity, m/s.

    Returns
    -------
    Same type as ``v``: μ, dimensionless, signed like ``v``.
    """
    xp = ca if _is_symbolic(v, mu_s, mu_d, v_transition) else np
    x = v / v_transition
    return mu_d * xp.tanh(4.0 * x) + (mu_s - mu_d) * x / (0.25 * x * x + 0.75) ** 2


#: Named inputs of :func:`contact_function` (and arguments of :func:`ellipsoid_plane`).
CONTACT_INPUTS = (
    "R", "centre", "vel_centre", "omega_z", "k_v", "a_v", "mu_s", "mu_d", "a", "b", "c"
)  # fmt: skip
#: Named outputs of :func:`contact_function`, all scalars (see :func:`ellipsoid_plane`).
CONTACT_OUTPUTS = (
    "fx", "fy", "mz", "px", "py", "fn", "fn_raw", "volume", "depth", "t",
    "depth_rate", "v_slip", "mu", "m_roll", "J",
)  # fmt: skip


def _contact_expressions(R, centre, vel_centre, omega_z, k_v, a_v, mu_s, mu_d, a, b, c, sm):
    """Contact law on CasADi SX/MX symbols; returns dict of CONTACT_OUTPUTS expressions."""
    # ground normal +Y and forward axis +X, expressed in the ellipsoid frame: rows of R
    n = [R[1, 0], R[1, 1], R[1, 2]]
    xh = [R[0, 0], R[0, 1], R[0, 2]]
    d2 = [a * a, b * b, c * c]
    d2n = [d2[i] * n[i] for i in range(3)]
    h = ca.sqrt(d2n[0] * n[0] + d2n[1] * n[1] + d2n[2] * n[2])  # |D n|
    depth = h - centre[1]
    t = _smax(depth / h, sm.eps_t)
    abc = a * b * c
    volume = math.pi * abc * t * t * (3.0 - t) / 3.0
    zbar = 3.0 * (2.0 - t) ** 2 / (4.0 * (3.0 - t))
    rc_e = [-(zbar / h) * d2n[i] for i in range(3)]  # centroid - centre, ellipsoid frame
    # centroid - centre in the ground frame (x, y components suffice in 2D)
    rcx = R[0, 0] * rc_e[0] + R[0, 1] * rc_e[1] + R[0, 2] * rc_e[2]
    rcy = R[1, 0] * rc_e[0] + R[1, 1] * rc_e[1] + R[1, 2] * rc_e[2]
    px, py = centre[0] + rcx, centre[1] + rcy
    # velocity of the body material point at the centroid: v_c + ω ẑ × (p − c)
    v_slip = vel_centre[0] - omega_z * rcy
    vpy = vel_centre[1] + omega_z * rcx
    depth_rate = -vpy
    fn_raw = k_v * volume * (1.0 + a_v * depth_rate)
    fn = _smax(fn_raw, sm.eps_force)
    mu = friction_coefficient(v_slip, mu_s, mu_d, sm.v_transition)
    fx = -mu * fn
    fy = fn
    # rolling resistance (Brown): J = x̂ᵀ S x̂, S = abc I⊥ [D² − (D²n)(D²n)ᵀ / h²]
    i_perp = math.pi * t**3 * (3.0 * t * t - 15.0 * t + 20.0) / 60.0
    xd2x = d2[0] * xh[0] ** 2 + d2[1] * xh[1] ** 2 + d2[2] * xh[2] ** 2
    xd2n = xh[0] * d2n[0] + xh[1] * d2n[1] + xh[2] * d2n[2]
    J = abc * i_perp * (xd2x - xd2n * xd2n / (h * h))
    m_roll = -k_v * ca.fabs(a_v) * J * omega_z
    mz = rcx * fy - rcy * fx + m_roll
    out = dict(
        fx=fx, fy=fy, mz=mz, px=px, py=py, fn=fn, fn_raw=fn_raw, volume=volume, depth=depth,
        t=t, depth_rate=depth_rate, v_slip=v_slip, mu=mu, m_roll=m_roll, J=J,
    )  # fmt: skip
    return out


@functools.lru_cache(maxsize=16)
def contact_function(smoothing: Smoothing = Smoothing()) -> ca.Function:
    """The contact law as a :class:`casadi.Function` (SX, cached per ``smoothing``).

    Inputs (names :data:`CONTACT_INPUTS`): ``R`` (3×3), ``centre`` (3×1), ``vel_centre``
    (3×1), ``omega_z``, ``k_v``, ``a_v``, ``mu_s``, ``mu_d``, ``a``, ``b``, ``c`` (scalars);
    meanings and units as in :func:`ellipsoid_plane`. Outputs (names
    :data:`CONTACT_OUTPUTS`) are scalars. Call with keywords, e.g.
    ``contact_function()(R=R, centre=c, ...)["fx"]``, or positionally, or ``.map(N)`` for
    many poses at once.
    """
    sym = {
        "R": ca.SX.sym("R", 3, 3),
        "centre": ca.SX.sym("centre", 3),
        "vel_centre": ca.SX.sym("vel_centre", 3),
    }
    for name in CONTACT_INPUTS[3:]:
        sym[name] = ca.SX.sym(name)
    out = _contact_expressions(*(sym[k] for k in CONTACT_INPUTS), smoothing)
    return ca.Function(
        "ellipsoid_plane",
        [sym[k] for k in CONTACT_INPUTS],
        [out[k] for k in CONTACT_OUTPUTS],
        list(CONTACT_INPUTS),
        list(CONTACT_OUTPUTS),
    )


def _prep(x, shape):
    if isinstance(x, (ca.SX, ca.MX, ca.DM)):
        return x
    if isinstance(x, (list, tuple)) and _is_symbolic(*x):
        return ca.vertcat(*x)
    if isinstance(x, np.ndarray) and x.dtype == object:
        flat = list(x.reshape(-1))
        if _is_symbolic(*flat):
            m = ca.vertcat(*flat)
            return ca.reshape(m, shape[1], shape[0]).T if len(shape) == 2 else m
    return np.asarray(x, dtype=float).reshape(shape)


def ellipsoid_plane(
    R, centre, vel_centre, omega_z, k_v, a_v, mu_s, mu_d, a, b, c, smoothing=Smoothing()
) -> dict:
    """Contact load of one ellipsoid on the ground plane ``y = 0`` (normal +Y).

    Parameters
    ----------
    R : array_like or casadi, shape (3, 3)
        Rotation ellipsoid frame → ground frame (``x_ground = centre + R @ x_ellipsoid``),
        i.e. segment orientation @ :func:`euler_321` of the ellipsoid.
    centre : array_like or casadi, shape (3,)
        Ellipsoid centre in the ground frame, m.
    vel_centre : array_like or casadi, shape (3,)
        Velocity of the centre (a material point of the carrying body), m/s.
    omega_z : float or casadi
        Angular velocity of the carrying body about +Z, rad/s (CCW positive; sagittal
        motion only).
    k_v : float or casadi
        Volumetric stiffness, N/m³.
    a_v : float or casadi
        Volumetric damping coefficient, s/m (≥ 0; F_n grows when pressing in).
    mu_s, mu_d : float or casadi
        Static and dynamic friction coefficients.
    a, b, c : float or casadi
        Radii along the ellipsoid's x, y, z axes, m.
    smoothing : Smoothing or None, optional
        Smoothing constants (None: ``Smoothing()``).

    Returns
    -------
    dict of scalars (float for numeric input, CasADi SX/MX for symbolic input)
        ``fx``, ``fy``
            Force on the body by the ground, ground frame, N (``fy = fn``,
            ``fx = −μ(v_slip) fn``, friction opposes slip).
        ``mz``
            Moment about +Z of the contact load about the ellipsoid **centre**, N·m:
            ``(p − centre) × F`` plus the rolling-resistance couple ``m_roll``. To move it
            to another point o of the body add ``(centre − o) × F``.
        ``px``, ``py``
            Volume centroid p in the ground frame, m (point of application).
        ``fn``
            Normal force, smoothly clamped ≥ 0, N.
        ``fn_raw``
            Unclamped ``k_v V (1 + a_v δ̇)``, N (constrain ≥ 0 in an optimiser,
            thesis Sec 4.4.1).
        ``volume``
            Penetrated volume V, m³ (uses the smoothed t: ≈ 0 but > 0 out of contact).
        ``depth``
            Penetration depth δ = h − y_c, m (unsmoothed; negative out of contact).
        ``t``
            Smoothed normalised cap height, dimensionless.
        ``depth_rate``
            δ̇ = −v_p,y, m/s, positive pressing in.
        ``v_slip``
            Tangential (x) velocity of the body point at the centroid, m/s.
        ``mu``
            Friction coefficient μ(v_slip).
        ``m_roll``
            Rolling-resistance couple −k_v |a_v| J ω, N·m.
        ``J``
            Rolling "inertia" x̂ᵀ S x̂, m⁵.
    """
    args = [
        _prep(R, (3, 3)),
        _prep(centre, (3,)),
        _prep(vel_centre, (3,)),
        omega_z, k_v, a_v, mu_s, mu_d, a, b, c,
    ]  # fmt: skip
    f = contact_function(Smoothing() if smoothing is None else smoothing)
    res = f(**dict(zip(CONTACT_INPUTS, args, strict=True)))
    if any(isinstance(v, (ca.SX, ca.MX)) for v in res.values()):
        return dict(res)
    return {k: float(v) for k, v in res.items()}
