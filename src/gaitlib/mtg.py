"""Muscle torque generators (MTGs): Millard et al. 2017 / RBDL "Gymnast" curves (thesis Ch 5).

Each of the hip, knee and ankle joints of each leg is driven by an agonist–antagonist pair of
MTGs (extensor and flexor), 6 generators per leg, 12 in the model (thesis Sec 5.2.1). The
metatarsal joints stay torque driven (Sec 5.1.1).

Single generator (thesis Eqs 5.1–5.8, RBDL ``Millard2016TorqueMuscle``)
-----------------------------------------------------------------------
In the generator's own ("fibre") frame the torque is never negative (Eq 5.1 text)::

    τ^M = s^τ τ0 [ a t^A(θ_A) t^V(ω̂) + t^P(θ_f − Δ^P) (1 − β^P ω̂) ]            (5.8)
    θ_A = (θ_f − θ*) / s^A + θ*,     ω̂ = ω_f / (s^V ω_max),     β^P = 0.1

with the blended curves (Eqs 5.5–5.7, RBDL form)::

    t^A ← (1 − λ^A) t^A + λ^A
    t^V ← (1 − λ^V) t^V + λ^V t^V(−1)      (RBDL blends towards t^V(−1) = E; see below)
    t^P ← (1 − λ^P) t^P

Joint ↔ fibre mapping (model-facts Sec 2, :mod:`gaitlib.conventions`)
---------------------------------------------------------------------
The Gymnast curves take a fibre angle θ_f whose zero is the anatomical neutral posture
(= the model's 0) and which is positive in hip flexion, knee flexion and ankle
dorsiflexion. With the model's joint angle q (CCW positive: hip > 0 flexion, knee < 0
flexion, ankle > 0 dorsiflexion)::

    θ_f = s_θ q          s_θ = +1 (hip), −1 (knee), +1 (ankle)        (JOINT_ANGLE_SIGN)
    ω_f = σ_τ q̇          (positive when the generator shortens)
    τ_joint = σ_τ τ^M    σ_τ = −s_θ for extensors, +s_θ for flexors   (TORQUE_SIGN)

so in the model's convention the hip extensor torque is ≤ 0, the knee extensor torque ≥ 0
(knee extension is CCW), the ankle extensor (plantarflexor) torque ≤ 0, and the flexors the
opposite. A joint's torque is the sum of its two signed generator torques (Eq 5.32, written
in the thesis as τ_flx − τ_ext in its own sign convention).

Characteristic curves
---------------------
The curves are RBDL's segmented quintic Bézier curves, rebuilt here exactly from the
Gymnast table with RBDL's ``TorqueMuscleFunctionFactory`` algorithm (control points,
curviness, the bisection fit of the concentric side to Hill's hyperbola), and extended
linearly outside their domain, as RBDL does. Evaluating a parametric Bézier curve needs a
Newton inversion x → u, which does not suit CasADi, so each Bézier segment is bisected
adaptively (in the Bézier parameter) into pieces, each replaced by
the quintic Hermite polynomial y(x) that matches the Bézier curve's value, slope and
curvature at both ends. The result is C2 everywhere (RBDL's curves have zero curvature at
every segment end and at the domain ends, where the linear extension starts), hits every
knot value and slope exactly, and differs from the Bézier curve by < 1e-5 in value and
< 2e-3 max|y'| in slope (checked in the tests). On CasADi symbols the piece's constants are
selected exactly with ``if_else`` on x ≥ break, whose derivative is zero, so the AD graph
sees one quintic polynomial: first and second derivatives are exact (SX and MX; MX graphs
expand to SX). Cost: ≈ 2,000 SX instructions per generator (≈ 4,100 per joint pair).

Known differences from the thesis's printed equations are flagged where they occur:
t^V blending towards t^V(−1) = E (RBDL) rather than towards 1 (thesis Eq 5.6), and Table
5.2's Δ^P read in degrees.

Units: angles rad, angular velocities rad/s, torques N·m, activations dimensionless in
[0, 1]. Every function accepts floats, numpy arrays (elementwise) and CasADi SX/MX/DM
(elementwise on column vectors); fitting parameters may be CasADi symbols too.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple

import casadi as ca
import numpy as np

from gaitlib.conventions import BODY_HEIGHT, BODY_MASS, SIDES

__all__ = [
    "strength_limits",
    "GENERATORS",
    "MTG_JOINTS",
    "MTG_NAMES",
    "GYMNAST",
    "REF_MASS",
    "REF_HEIGHT",
    "BETA_P",
    "TP_MAX",
    "JOINT_ANGLE_SIGN",
    "TORQUE_SIGN",
    "MTGParams",
    "DEFAULT_PARAMS",
    "PARAM_BOUNDS",
    "THESIS_PARAMS",
    "tau0",
    "curve",
    "curve_knots",
    "t_active",
    "t_velocity",
    "t_passive",
    "fibre_kinematics",
    "generator_torque",
    "generator_joint_torque",
    "joint_torque",
    "pair_activations",
    "pair_torque",
    "split_joint_torque",
    "activation_for_torque",
    "isometric_envelope",
    "max_joint_torque",
    "torque_velocity",
    "demanded_active_torque",
]

# --------------------------------------------------------------------------------------
# Names, data and constants
# --------------------------------------------------------------------------------------

#: The six generator types, in the order of thesis Eq 5.13 / Table 5.2.
GENERATORS = ("hip_ext", "hip_flex", "knee_ext", "knee_flex", "ankle_ext", "ankle_flex")
#: MTG-driven joints (the metatarsal joints are torque driven).
MTG_JOINTS = ("hip", "knee", "ankle")
#: The 12 generators of the model: right leg then left leg (same sides as conventions.SIDES).
MTG_NAMES = tuple(f"{g}_{s}" for s in SIDES for g in GENERATORS)

#: Reference subject of the Gymnast data set (one male gymnast), kg and m.
REF_MASS = 69.6
REF_HEIGHT = 1.732
#: Passive damping coefficient β^P (thesis Sec 5.1.1, RBDL ``mBetaMax``).
BETA_P = 0.1
#: Upper bound of the normalised passive curve used in thesis Eq 5.17.
TP_MAX = 1.4
_EPS = 2.22e-16


class GymnastRow(NamedTuple):
    """One row of RBDL's ``GymnastWholeBody`` table (model-facts Sec 2)."""

    tau0: float  #: maximum active isometric torque of the adult, N·m
    omega_max: float  #: maximum angular velocity, rad/s (thesis Eq 5.13)
    theta_star: float  #: fibre angle of peak active torque θ*, rad
    sigma: float  #: angular "standard deviation" of the active curve, rad
    E: float  #: t^V at the maximum eccentric velocity (ω̂ = −1)
    v_half: float  #: t^V at half the maximum concentric velocity (ω̂ = 0.5)
    theta_p0: float  #: fibre angle where the passive curve leaves 0, rad
    theta_p1: float  #: fibre angle where the passive curve reaches 1, rad


#: RBDL Gymnast data set (Millard2016TorqueMuscle.cc, ``GymnastWholeBody``), adult values.
GYMNAST: dict[str, GymnastRow] = {
    "hip_ext": GymnastRow(175.746, 9.02335, 1.06465, 1.05941, 1.1, 0.163849, 0.79158, 1.5708),
    "hip_flex": GymnastRow(
        157.293, 9.18043, 0.733038, 1.21999, 1.11905, 0.25, -0.0888019, -0.515207
    ),
    "knee_ext": GymnastRow(
        285.619, 19.2161, 0.942478, 0.509636, 1.13292, 0.115304, 2.00713, 2.70526
    ),
    "knee_flex": GymnastRow(98.7579, 16.633, 1.02974, 1.11003, 1.12, 0.19746, 0.0, -0.174533),
    "ankle_ext": GymnastRow(
        127.561, 11.7646, 0.408, 0.660752, 1.159, 0.410591, 0.0292126, 0.785398
    ),
    "ankle_flex": GymnastRow(
        44.3106, 17.2746, -0.187, 0.60868, 1.2656, 0.112303, -0.523599, -1.0472
    ),
}

#: s_θ: fibre angle = s_θ × model joint angle (fibre angle > 0 = hip/knee flexion, ankle
#: dorsiflexion; the model's knee angle is negative in flexion).
JOINT_ANGLE_SIGN = {"hip": 1.0, "knee": -1.0, "ankle": 1.0}
#: σ_τ: model-convention joint torque = σ_τ × generator torque (extensors −s_θ, flexors +s_θ).
TORQUE_SIGN = {
    f"{j}_{d}": (-1.0 if d == "ext" else 1.0) * JOINT_ANGLE_SIGN[j]
    for j in MTG_JOINTS
    for d in ("ext", "flex")
}


class MTGParams(NamedTuple):
    """The seven fitting parameters Γ of one generator (thesis Eq 5.9, Sec 5.1.1).

    Fields may be floats or CasADi symbols. ``to_vector``/``from_vector`` give the order
    of Eq 5.9.

    Attributes
    ----------
    s_tau : scale of the maximum isometric torque τ0 (Eq 5.8), 1.
    s_A : angle scaling of the active-torque–angle curve about θ* (Eq 5.5), 1.
    lambda_A : blending of t^A towards 1 (Eq 5.5), 1.
    s_V : scaling of the maximum angular velocity, ω_max → s_V ω_max (Eqs 5.6, 5.8), 1.
    lambda_V : blending of t^V towards t^V(−1) (Eq 5.6, RBDL form), 1.
    delta_P : shift of the passive curve along the fibre angle (Eq 5.7), rad.
    lambda_P : blending of t^P towards 0 (Eq 5.7), 1.
    """

    s_tau: Any = 1.0
    s_A: Any = 1.0
    lambda_A: Any = _EPS**0.25
    s_V: Any = 1.0
    lambda_V: Any = _EPS**0.25
    delta_P: Any = 0.0
    lambda_P: Any = 0.0

    def to_vector(self) -> np.ndarray:
        """Parameters as a length-7 float array in Eq 5.9 order."""
        return np.array([float(v) for v in self], dtype=float)

    @classmethod
    def from_vector(cls, v) -> MTGParams:
        """Build from a length-7 sequence, numpy array or CasADi column (Eq 5.9 order)."""
        if isinstance(v, (ca.SX, ca.MX, ca.DM)):
            if v.numel() != 7:
                raise ValueError("need 7 fitting parameters")
            return cls(*[v[i] for i in range(7)])
        v = list(np.asarray(v, dtype=float).ravel()) if not isinstance(v, Sequence) else list(v)
        if len(v) != 7:
            raise ValueError("need 7 fitting parameters")
        return cls(*v)


#: Initial/default fitting parameters, thesis Eq 5.22: {1, 1, ε^¼, 1, ε^¼, 0, 0}. With these
#: the curves are the adult Gymnast curves (λ = ε^¼ ≈ 1.2e-4 keeps t^A, t^V > 0).
DEFAULT_PARAMS = MTGParams()

#: Bounds of the fitting parameters, thesis Table 5.1 (Δ^P in rad).
PARAM_BOUNDS: dict[str, tuple[float, float]] = {
    "s_tau": (1e-4, 2.0),
    "s_A": (0.1, 10.0),
    "lambda_A": (1e-6, 0.99),
    "s_V": (0.1, 10.0),
    "lambda_V": (1e-6, 0.99),
    "delta_P": (-1.0, 1.0),
    "lambda_P": (0.0, 0.99),
}

#: The child's identified parameters, thesis Table 5.2. The table's Δ^P column is headed
#: "(0°)", so its values are read as degrees and converted to rad here (0.2292° and
#: 4.2571°); λ values are absolute (0.0042 etc., above the 1e-6 lower bound).
THESIS_PARAMS: dict[str, MTGParams] = {
    "hip_ext": MTGParams(0.9995, 0.9801, 0.0042, 1.0915, 0.0078, 0.0, 0.0032),
    "hip_flex": MTGParams(1.0067, 1.0013, 0.0037, 1.3149, 0.0118, math.radians(0.2292), 0.0032),
    "knee_ext": MTGParams(1.0012, 0.9159, 0.0045, 1.1222, 0.0111, 0.0, 0.0032),
    "knee_flex": MTGParams(1.0026, 0.9765, 0.0036, 1.0505, 0.0049, 0.0, 0.0032),
    "ankle_ext": MTGParams(0.9999, 1.0032, 0.0036, 1.0301, 0.0034, math.radians(4.2571), 0.0030),
    "ankle_flex": MTGParams(1.0015, 1.0127, 0.0034, 1.0246, 0.0044, 0.0, 0.0032),
}



# --------------------------------------------------------------------------------------
# Backend helpers (numpy or CasADi)
# --------------------------------------------------------------------------------------


def _is_ca(*xs) -> bool:
    return any(isinstance(x, (ca.SX, ca.MX, ca.DM)) for x in xs)


def _num(x):
    """Numeric input → float ndarray (0-d for scalars)."""
    return np.asarray(x, dtype=float)


def _out(x):
    """0-d arrays back to Python floats."""
    if isinstance(x, np.ndarray) and x.ndim == 0:
        return float(x)
    return x


def _gen_key(name: str) -> str:
    """'hip_ext_r' → 'hip_ext'; validates."""
    for g in GENERATORS:
        if name == g or (name.startswith(g + "_") and name[len(g) + 1 :] in SIDES):
            return g
    raise KeyError(f"unknown generator {name!r}; expected one of {GENERATORS} (+ _r/_l)")


def _joint_key(name: str) -> str:
    """'knee_r' → 'knee'; validates."""
    base = name
    for s in SIDES:
        if name.endswith("_" + s):
            base = name[: -len(s) - 1]
    if base not in MTG_JOINTS:
        raise KeyError(f"{name!r} is not an MTG joint {MTG_JOINTS} (+ _r/_l)")
    return base


def _params_for(params, gen: str) -> MTGParams:
    """Resolve the ``params`` argument for one generator type.

    ``params`` may be None (→ :data:`DEFAULT_PARAMS`), an :class:`MTGParams` used for every
    generator, a mapping from generator name (``'hip_ext'`` or ``'hip_ext_r'``) to an
    MTGParams or a length-7 vector, or a length-7 vector.
    """
    if params is None:
        return DEFAULT_PARAMS
    if isinstance(params, MTGParams):
        return params
    if isinstance(params, Mapping):
        for k, v in params.items():
            if _gen_key(k) == gen:
                return v if isinstance(v, MTGParams) else MTGParams.from_vector(v)
        return DEFAULT_PARAMS
    return MTGParams.from_vector(params)


# --------------------------------------------------------------------------------------
# RBDL segmented quintic Bézier curves (exact port of the construction)
# --------------------------------------------------------------------------------------

_BINOM5 = np.array([1.0, 5.0, 10.0, 10.0, 5.0, 1.0])


def _scale_curviness(c: float) -> float:
    return 0.1 + 0.8 * c


def _corner_control_points(x0, y0, dydx0, x1, y1, dydx1, curviness) -> np.ndarray:
    """RBDL ``calcQuinticBezierCornerControlPoints`` with zero end curvature; (6, 2)."""
    root_eps = math.sqrt(np.finfo(float).eps)
    if abs(dydx0 - dydx1) > root_eps:
        xc = (y1 - y0 - x1 * dydx1 + x0 * dydx0) / (dydx0 - dydx1)
    else:
        xc = 0.5 * (x1 + x0)
    yc = (xc - x1) * dydx1 + y1
    a = (xc - x0) ** 2 + (yc - y0) ** 2
    b = (xc - x1) ** 2 + (yc - y1) ** 2
    c = (x1 - x0) ** 2 + (y1 - y0) ** 2
    if not (c > a and c > b):
        raise ValueError("corner control points: lines do not intersect inside the segment")
    p = np.zeros((6, 2))
    p[0] = (x0, y0)
    p[5] = (x1, y1)
    p[1] = (x0 + curviness * (xc - x0), y0 + curviness * (yc - y0))
    p[4] = (x1 + curviness * (xc - x1), y1 + curviness * (yc - y1))
    # middle points: zero second derivative d2y/dx2 at both ends
    dxdu0 = 5.0 * (p[1, 0] - p[0, 0])
    p[2, 0] = p[1, 0] + 0.5 * (xc - p[1, 0])
    d2xdu20 = 20.0 * (p[2, 0] - 2.0 * p[1, 0] + p[0, 0])
    d2ydu20 = dxdu0 * dxdu0 * 0.0 + d2xdu20 * dydx0
    p[2, 1] = d2ydu20 / 20.0 + 2.0 * p[1, 1] - p[0, 1]
    dxdu1 = 5.0 * (p[5, 0] - p[4, 0])
    p[3, 0] = p[4, 0] + 0.5 * (xc - p[4, 0])
    d2xdu21 = 20.0 * (p[3, 0] - 2.0 * p[4, 0] + p[5, 0])
    d2ydu21 = dxdu1 * dxdu1 * 0.0 + d2xdu21 * dydx1
    p[3, 1] = d2ydu21 / 20.0 + 2.0 * p[4, 1] - p[5, 1]
    return p


def _bezier_power_coeffs(pts: np.ndarray) -> np.ndarray:
    """Control points (6,) → power-basis coefficients c[k] of u^k."""
    c = np.zeros(6)
    for k in range(6):  # Bernstein B_k(u) = C(5,k) u^k (1-u)^(5-k)
        for j in range(6 - k):  # (1-u)^(5-k) = Σ_j C(5-k, j) (-u)^j
            c[k + j] += _BINOM5[k] * math.comb(5 - k, j) * (-1.0) ** j * pts[k]
    return c


class _BezierCurve:
    """A chain of quintic Bézier segments with linear extrapolation (RBDL
    ``SmoothSegmentedFunction``); numeric evaluation only (exact, via u-inversion)."""

    def __init__(self, segments: list[np.ndarray]):
        self.segments = [np.asarray(s, float) for s in segments]  # each (6, 2)
        self.cx = [_bezier_power_coeffs(s[:, 0]) for s in self.segments]
        self.cy = [_bezier_power_coeffs(s[:, 1]) for s in self.segments]
        self.x0 = self.segments[0][0, 0]
        self.x1 = self.segments[-1][5, 0]
        self.y0 = self.segments[0][0, 1]
        self.y1 = self.segments[-1][5, 1]
        s0, s1 = self.segments[0], self.segments[-1]
        self.dydx0 = (s0[1, 1] - s0[0, 1]) / (s0[1, 0] - s0[0, 0])
        self.dydx1 = (s1[5, 1] - s1[4, 1]) / (s1[5, 0] - s1[4, 0])

    @staticmethod
    def _poly(c, u, der=0):
        c = np.asarray(c)
        for _ in range(der):
            c = c[1:] * np.arange(1, len(c))
        return np.polynomial.polynomial.polyval(u, c)

    def point(self, i: int, u):
        """x, dx/du, d²x/du², y, dy/du, d²y/du² of segment i at parameter u."""
        return tuple(
            self._poly(c, u, d) for c in (self.cx[i], self.cy[i]) for d in (0, 1, 2)
        )

    def _u_of_x(self, i: int, x: np.ndarray) -> np.ndarray:
        lo = np.zeros_like(x)
        hi = np.ones_like(x)
        for _ in range(60):  # bisection (x(u) is monotone on every corner segment)
            mid = 0.5 * (lo + hi)
            left = self._poly(self.cx[i], mid) < x
            lo = np.where(left, mid, lo)
            hi = np.where(left, hi, mid)
        return 0.5 * (lo + hi)

    def value(self, x, der: int = 0):
        x = np.atleast_1d(np.asarray(x, float))
        out = np.empty_like(x)
        left, right = x < self.x0, x > self.x1
        if der == 0:
            out[left] = self.y0 + self.dydx0 * (x[left] - self.x0)
            out[right] = self.y1 + self.dydx1 * (x[right] - self.x1)
        else:
            out[left] = self.dydx0 if der == 1 else 0.0
            out[right] = self.dydx1 if der == 1 else 0.0
        inside = ~(left | right)
        bounds = [s[0, 0] for s in self.segments] + [self.x1]
        idx = np.clip(np.searchsorted(bounds, x[inside], side="right") - 1, 0, len(self.segments) - 1)
        xi = x[inside]
        res = np.empty_like(xi)
        for i in range(len(self.segments)):
            m = idx == i
            if not np.any(m):
                continue
            u = self._u_of_x(i, xi[m])
            _, xu, xuu, y, yu, yuu = self.point(i, u)
            if der == 0:
                res[m] = y
            elif der == 1:
                res[m] = yu / xu
            else:
                res[m] = (yuu * xu - yu * xuu) / xu**3
        out[inside] = res
        return out


def _gaussian_active_curve(theta_star: float, sigma: float) -> _BezierCurve:
    """RBDL ``createGaussianShapedActiveTorqueAngleCurve`` (min value/slope 0, curviness ½)."""
    ta_cutoff = 1e-3
    sig2 = sigma * sigma
    width = math.sqrt(-math.log(ta_cutoff) * 2.0 * sig2)
    theta_min, theta_max = theta_star - width, theta_star + width
    c = _scale_curviness(0.5)
    x0, x1, x2, x3, x4 = theta_min, theta_star - sigma, theta_star, theta_star + sigma, theta_max
    if (theta_star - theta_min) < (theta_star - sigma):  # RBDL's guard, kept verbatim
        x1 = theta_star - 0.5 * theta_min
        x3 = theta_star + 0.5 * theta_min

    def g(x):
        return math.exp(-((x - theta_star) ** 2) / (2.0 * sig2))

    def dg(x):
        return -(2.0 * (x - theta_star) / (2.0 * sig2)) * g(x)

    y = [0.0, g(x1), g(x2), g(x3), 0.0]
    d = [0.0, dg(x1), dg(x2), dg(x3), 0.0]
    xs = [x0, x1, x2, x3, x4]
    segs = [
        _corner_control_points(xs[k], y[k], d[k], xs[k + 1], y[k + 1], d[k + 1], c)
        for k in range(4)
    ]
    return _BezierCurve(segs)


def _passive_curve(angle_zero: float, angle_one: float) -> _BezierCurve:
    """RBDL ``createPassiveTorqueAngleCurve`` (default stiffness and curviness ½)."""
    k1 = 4.6 / (angle_one - angle_zero)
    k_low = 0.01 * k1
    if angle_zero < angle_one:
        x0, x1, y0, y1, d0, d1 = angle_zero, angle_one, 0.0, 1.0, 0.0, k1
    else:
        x0, x1, y0, y1, d0, d1 = angle_one, angle_zero, 1.0, 0.0, k1, 0.0
    c = _scale_curviness(0.5)
    delta = min(0.1 * (1.0 - abs(1.0 / k1)), 0.05 * abs(x1 - x0))
    if k1 < 0.0:
        delta = -delta
    x_low = angle_zero + delta
    x_foot = angle_zero + 0.5 * (x_low - angle_zero)
    y_low = 0.0 + k_low * (x_low - x_foot)
    segs = [
        _corner_control_points(x0, y0, d0, x_low, y_low, k_low, c),
        _corner_control_points(x_low, y_low, k_low, x1, y1, d1, c),
    ]
    return _BezierCurve(segs)


def _velocity_curve(E: float, v_half: float) -> _BezierCurve:
    """RBDL ``createTorqueVelocityCurve`` with its default slopes and curviness."""
    slope_c, slope_e, ecc_curviness = 0.0, 0.0, 0.75
    wmax_c, wmax_e, fiso = 1.0, -1.0, 1.0
    w = 0.5 * wmax_c
    a = -v_half * w * fiso / (wmax_c * v_half - fiso * wmax_c + fiso * w)
    b = a * wmax_c / fiso

    def hill(w):
        return (b * fiso - a * w) / (b + w)

    def dhill(w):
        return (-a * (b + w) - (b * fiso - a * w)) / ((b + w) ** 2)

    x_iso, y_iso, d_iso = 0.0, 1.0, dhill(0.0)
    x_near_c = 0.9 * wmax_c
    y_near_c, d_near_c = hill(x_near_c), dhill(x_near_c)

    def err(cc):
        f = _BezierCurve(
            [_corner_control_points(x_iso, y_iso, d_iso, x_near_c, y_near_c, d_near_c, cc)]
        )
        ws = np.array([(j - 1) * wmax_c / 9.0 for j in range(10)])  # RBDL's samples, verbatim
        return float(np.sum(np.abs(f.value(ws) - hill(ws))))

    c_best, f_best, h = 0.5, err(0.5), 0.25
    for _ in range(10):  # RBDL's bisection on the concentric curviness
        cl, cr = c_best - h, c_best + h
        fl, fr = err(cl), err(cr)
        if abs(fl) < abs(f_best):
            f_best, c_best = fl, cl
        if abs(fr) < abs(f_best):
            f_best, c_best = fr, cr
        h /= 2.0
    cc = c_best
    ce = _scale_curviness(ecc_curviness)
    x_e, y_e = wmax_e, E
    x_near_e = 0.9 * wmax_e
    d_near_e = slope_e  # RBDL uses slopeAtEccentricOmegaMax here (plateau at E)
    y_near_e = y_e + 0.5 * d_near_e * (x_near_e - x_e) + 0.5 * slope_e * (x_near_e - x_e)
    segs = [
        _corner_control_points(x_e, y_e, slope_e, x_near_e, y_near_e, d_near_e, ce),
        _corner_control_points(x_near_e, y_near_e, d_near_e, x_iso, y_iso, d_iso, ce),
        _corner_control_points(x_iso, y_iso, d_iso, x_near_c, y_near_c, d_near_c, cc),
        _corner_control_points(x_near_c, y_near_c, d_near_c, wmax_c, 0.0, slope_c, cc),
    ]
    return _BezierCurve(segs)


# --------------------------------------------------------------------------------------
# C2 piecewise-quintic representation usable in CasADi
# --------------------------------------------------------------------------------------


class Curve:
    """A C2 piecewise quintic y(x) with linear extension, evaluable on numbers and CasADi.

    Built from an RBDL Bézier chain: each segment is bisected (in the Bézier parameter)
    until every piece's quintic Hermite interpolant of the Bézier curve's (y, y', y'') at
    its ends is within ``tol`` in value and ``slope_tol`` × max|y'| in slope.

    Attributes
    ----------
    breaks : (N+1,) ndarray
        Piece boundaries, ascending; ``breaks[0]``/``breaks[-1]`` are the curve's domain.
    bezier : _BezierCurve
        The exact RBDL curve (numeric, for checks and plots).
    knots : dict
        ``x``, ``y``, ``dydx`` at the Bézier segment ends (the curve's defining knots).
    """

    def __init__(self, bezier: _BezierCurve, tol: float = 1e-5, slope_tol: float = 2e-3):
        self.bezier = bezier
        seg_ends = np.array([s[0, 0] for s in bezier.segments] + [bezier.x1])

        def end_data(i, u):
            x, xu, xuu, y, yu, yuu = bezier.point(i, np.asarray(u, float))
            return x, y, yu / xu, (yuu * xu - yu * xuu) / xu**3

        slope_scale = max(
            1.0, max(np.max(np.abs(end_data(i, np.linspace(0, 1, 201))[2])) for i in range(len(bezier.segments)))
        )
        # adaptive bisection (in the Bézier parameter) of every segment until the quintic
        # Hermite piece is within tol (value) and slope_tol*max|y'| (slope) of the Bézier
        pieces = []
        for i in range(len(bezier.segments)):
            todo = [(0.0, 1.0)]
            while todo:
                ua, ub = todo.pop()
                xa, ya, da, ca_ = end_data(i, ua)
                xb, yb, db, cb = end_data(i, ub)
                coef = self._hermite(xa, ya, da, ca_, xb, yb, db, cb, ua == 0.0, ub == 1.0)
                us = np.linspace(ua, ub, 26)[1:-1]
                xs, ys, ds, _ = end_data(i, us)
                t = xs - xa
                e0 = np.max(np.abs(np.polynomial.polynomial.polyval(t, coef) - ys))
                dcoef = coef[1:] * np.arange(1, 6)
                e1 = np.max(np.abs(np.polynomial.polynomial.polyval(t, dcoef) - ds))
                if (e0 > tol or e1 > slope_tol * slope_scale) and ub - ua > 1e-3:
                    um = 0.5 * (ua + ub)
                    todo += [(um, ub), (ua, um)]
                else:
                    pieces.append((float(xa), coef))
        pieces.sort(key=lambda pc: pc[0])
        x = np.array([pc[0] for pc in pieces] + [bezier.x1])
        y0, yp0 = bezier.y0, end_data(0, 0.0)[2]
        y1, yp1 = bezier.y1, end_data(len(bezier.segments) - 1, 1.0)[2]
        n = len(x) - 1
        coef = np.zeros((n + 2, 6))
        origin = np.zeros(n + 2)
        coef[0, :2] = (y0, yp0)  # left linear extension, origin breaks[0]
        origin[0] = x[0]
        for k, (xa, c) in enumerate(pieces):
            coef[k + 1] = c
            origin[k + 1] = xa
        coef[n + 1, :2] = (y1, yp1)  # right linear extension, origin breaks[-1]
        origin[n + 1] = x[-1]
        self.breaks = x
        self._coef = coef
        self._origin = origin
        self.knots = {
            "x": seg_ends,
            "y": np.array([s[0, 1] for s in bezier.segments] + [bezier.y1]),
            "dydx": self._end_slopes(),
        }

    @staticmethod
    def _hermite(xa, ya, da, ca_, xb, yb, db, cb, start_of_segment, end_of_segment):
        """Quintic in t = x − xa matching (y, y', y'') at both ends; RBDL's Bézier corners
        have exactly zero curvature at segment ends (round-off removed here)."""
        if start_of_segment:
            ca_ = 0.0
        if end_of_segment:
            cb = 0.0
        h = xb - xa
        c0, c1, c2 = ya, da, 0.5 * ca_
        A = np.array(
            [[h**3, h**4, h**5], [3 * h**2, 4 * h**3, 5 * h**4], [6 * h, 12 * h**2, 20 * h**3]]
        )
        rhs = np.array([yb - c0 - c1 * h - c2 * h**2, db - c1 - 2 * c2 * h, cb - 2 * c2])
        return np.array([c0, c1, c2, *np.linalg.solve(A, rhs)])

    def _end_slopes(self) -> np.ndarray:
        out = []
        for s in self.bezier.segments:
            out.append((s[1, 1] - s[0, 1]) / (s[1, 0] - s[0, 0]))
        s = self.bezier.segments[-1]
        out.append((s[5, 1] - s[4, 1]) / (s[5, 0] - s[4, 0]))
        return np.array(out)

    def one_sided_limits(self, der: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """Left and right limits of the ``der``-th derivative at every break (the two
        adjacent polynomial pieces evaluated at the break), for continuity checks."""
        left, right = [], []
        for i, b in enumerate(self.breaks):
            for k, out in ((i, left), (i + 1, right)):
                c = self._coef[k]
                for _ in range(der):
                    c = c[1:] * np.arange(1, len(c))
                out.append(np.polynomial.polynomial.polyval(b - self._origin[k], c))
        return np.array(left), np.array(right)

    @property
    def domain(self) -> tuple[float, float]:
        return float(self.breaks[0]), float(self.breaks[-1])

    def __call__(self, x, der: int = 0):
        """Value (``der=0``) or derivative (1, 2) at x (float, ndarray or CasADi)."""
        if der not in (0, 1, 2):
            raise ValueError("der must be 0, 1 or 2")
        if _is_ca(x):
            # exact selection of the piece's constants (no arithmetic on them, so no
            # round-off); the selectors are piecewise constant: zero derivative
            c = [float(self._coef[0, j]) + 0 * x for j in range(6)]
            o = float(self._origin[0]) + 0 * x
            for i, b in enumerate(self.breaks):
                step = x >= float(b)
                for j in range(6):
                    if self._coef[i + 1, j] != self._coef[i, j]:
                        c[j] = ca.if_else(step, float(self._coef[i + 1, j]), c[j])
                if self._origin[i + 1] != self._origin[i]:
                    o = ca.if_else(step, float(self._origin[i + 1]), o)
            t = x - o
        else:
            xn = _num(x)
            idx = np.searchsorted(self.breaks, xn, side="right")
            cc = self._coef[idx]
            c = [cc[..., j] for j in range(6)]
            t = xn - self._origin[idx]
        if der == 0:
            r = c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * c[5]))))
        elif der == 1:
            r = c[1] + t * (2 * c[2] + t * (3 * c[3] + t * (4 * c[4] + t * 5 * c[5])))
        else:
            r = 2 * c[2] + t * (6 * c[3] + t * (12 * c[4] + t * 20 * c[5]))
        return r if _is_ca(x) else _out(r)


_CURVES: dict[tuple[str, str], Curve] = {}


def curve(generator: str, kind: str) -> Curve:
    """The (cached) characteristic curve of a generator.

    Parameters
    ----------
    generator : str
        One of :data:`GENERATORS` (a ``_r``/``_l`` suffix is accepted).
    kind : {'active', 'velocity', 'passive'}
        t^A(θ_f) [rad → 1], t^V(ω̂) [1 → 1] or t^P(θ_f) [rad → 1].
    """
    g = _gen_key(generator)
    key = (g, kind)
    if key not in _CURVES:
        row = GYMNAST[g]
        if kind == "active":
            bz = _gaussian_active_curve(row.theta_star, row.sigma)
        elif kind == "velocity":
            bz = _velocity_curve(row.E, row.v_half)
        elif kind == "passive":
            bz = _passive_curve(row.theta_p0, row.theta_p1)
        else:
            raise ValueError("kind must be 'active', 'velocity' or 'passive'")
        _CURVES[key] = Curve(bz)
    return _CURVES[key]


def t_active(generator: str, theta_f):
    """Normalised active-torque–angle curve t^A(θ_f) (unblended), 1; θ_f in rad (fibre)."""
    return curve(generator, "active")(theta_f)


def t_velocity(generator: str, w):
    """Normalised torque–velocity curve t^V(ω̂) (unblended), 1; ω̂ = ω_f/ω_max, >0 concentric."""
    return curve(generator, "velocity")(w)


def t_passive(generator: str, theta_f):
    """Normalised passive-torque–angle curve t^P(θ_f) (unblended), 1; θ_f in rad (fibre)."""
    return curve(generator, "passive")(theta_f)


def curve_knots(generator: str) -> dict[str, dict[str, np.ndarray]]:
    """Knots, values and slopes that define a generator's three curves (for plots/tests).

    Returns
    -------
    dict
        ``{'active'|'velocity'|'passive': {'x', 'y', 'dydx', 'control_points', 'domain'}}``:
        Bézier segment ends ``x`` (fibre angle rad, or ω̂), values ``y`` and slopes
        ``dydx`` there (the curvature is 0 at every knot), the RBDL control points as a
        list of (6, 2) arrays, and the curve domain (linear extension outside). Also
        ``'named'``: the model-facts landmarks, e.g. θ*, θ*±σ, θ*±w with
        w = σ sqrt(−2 ln 1e−3); ω̂ = −1, −0.9, 0, 0.5, 1 with E, 1, v½, 0; θ_P0, θ_P1.
    """
    g = _gen_key(generator)
    row = GYMNAST[g]
    out: dict[str, Any] = {}
    for kind in ("active", "velocity", "passive"):
        c = curve(g, kind)
        out[kind] = {
            "x": c.knots["x"].copy(),
            "y": c.knots["y"].copy(),
            "dydx": c.knots["dydx"].copy(),
            "control_points": [s.copy() for s in c.bezier.segments],
            "domain": c.domain,
        }
    w = row.sigma * math.sqrt(-2.0 * math.log(1e-3))
    out["named"] = {
        "active": {
            "theta_star": (row.theta_star, 1.0),
            "theta_star-sigma": (row.theta_star - row.sigma, math.exp(-0.5)),
            "theta_star+sigma": (row.theta_star + row.sigma, math.exp(-0.5)),
            "theta_star-w": (row.theta_star - w, 0.0),
            "theta_star+w": (row.theta_star + w, 0.0),
        },
        "velocity": {
            "w=-1": (-1.0, row.E),
            "w=-0.9": (-0.9, row.E),
            "w=0": (0.0, 1.0),
            "w=0.5": (0.5, row.v_half),
            "w=1": (1.0, 0.0),
        },
        "passive": {
            "theta_p0": (row.theta_p0, 0.0, 0.0),  # (x, value, slope)
            "theta_p1": (row.theta_p1, 1.0, 4.6 / (row.theta_p1 - row.theta_p0)),
        },
    }
    return out


# --------------------------------------------------------------------------------------
# Generator and joint torques
# --------------------------------------------------------------------------------------


def tau0(generator: str, body_mass: float = BODY_MASS, body_height: float = BODY_HEIGHT) -> float:
    """Child's maximum isometric torque τ0 (N·m), thesis Eq 5.21.

    τ0_child = (m_c h_c) / (69.6 kg × 1.732 m) × τ0_Gymnast. Defaults: the thesis subject
    (:data:`gaitlib.conventions.BODY_MASS`, ``BODY_HEIGHT``) → factor 0.505.
    """
    return GYMNAST[_gen_key(generator)].tau0 * body_mass * body_height / (REF_MASS * REF_HEIGHT)


def fibre_kinematics(generator: str, q, qd):
    """Fibre angle θ_f (rad) and fibre angular velocity ω_f (rad/s, > 0 shortening).

    θ_f = s_θ q, ω_f = σ_τ q̇ with q, q̇ the model's joint angle/velocity (conventions).
    """
    g = _gen_key(generator)
    j = g.split("_")[0]
    return JOINT_ANGLE_SIGN[j] * q, TORQUE_SIGN[g] * qd


def _generator_parts(generator, theta_f, omega_f, params, body_mass, body_height):
    g = _gen_key(generator)
    row = GYMNAST[g]
    p = _params_for(params, g)
    T0 = p.s_tau * tau0(g, body_mass, body_height)
    theta_a = (theta_f - row.theta_star) / p.s_A + row.theta_star
    w = omega_f / (p.s_V * row.omega_max)
    tA = (1.0 - p.lambda_A) * t_active(g, theta_a) + p.lambda_A
    tV = (1.0 - p.lambda_V) * t_velocity(g, w) + p.lambda_V * row.E
    tP = (1.0 - p.lambda_P) * t_passive(g, theta_f - p.delta_P)
    return T0, tA, tV, tP, w


def generator_torque(
    generator: str,
    theta_f,
    omega_f,
    a,
    params=None,
    *,
    body_mass: float = BODY_MASS,
    body_height: float = BODY_HEIGHT,
    components: bool = False,
):
    """Torque of one generator in its own (fibre) frame, N·m, thesis Eq 5.8.

    Parameters
    ----------
    generator : str
        Generator type, one of :data:`GENERATORS` (``_r``/``_l`` suffix accepted).
    theta_f : float, ndarray or CasADi
        Fibre angle, rad (see :func:`fibre_kinematics`).
    omega_f : float, ndarray or CasADi
        Fibre angular velocity, rad/s, positive when shortening (concentric).
    a : float, ndarray or CasADi
        Activation in [0, 1].
    params : see module docstring / :class:`MTGParams`; None → :data:`DEFAULT_PARAMS`.
    body_mass, body_height : float
        Subject size for τ0 scaling (Eq 5.21), kg and m.
    components : bool
        Also return ``{'active', 'passive', 'tA', 'tV', 'tP', 'w', 'tau0'}``.

    Returns
    -------
    tau : same type as the inputs
        s^τ τ0 [a t^A t^V + t^P (1 − β^P ω̂)] ≥ 0 for a ≥ 0 and ω̂ < 10.
    """
    T0, tA, tV, tP, w = _generator_parts(generator, theta_f, omega_f, params, body_mass, body_height)
    active = T0 * a * tA * tV
    passive = T0 * tP * (1.0 - BETA_P * w)
    tau = active + passive
    if components:
        return tau, {
            "active": active,
            "passive": passive,
            "tA": tA,
            "tV": tV,
            "tP": tP,
            "w": w,
            "tau0": T0,
        }
    return tau


def generator_joint_torque(
    generator: str, q, qd, a, params=None, *, body_mass=BODY_MASS, body_height=BODY_HEIGHT
):
    """One generator's torque on its joint in the model's convention (N·m, CCW positive).

    = σ_τ × :func:`generator_torque` (s_θ q, σ_τ q̇, a). Extensors: hip ≤ 0, knee ≥ 0,
    ankle ≤ 0; flexors the opposite.
    """
    g = _gen_key(generator)
    th, om = fibre_kinematics(g, q, qd)
    return TORQUE_SIGN[g] * generator_torque(
        g, th, om, a, params, body_mass=body_mass, body_height=body_height
    )


def joint_torque(
    joint: str,
    q,
    qd,
    a_ext,
    a_flex,
    params=None,
    *,
    body_mass: float = BODY_MASS,
    body_height: float = BODY_HEIGHT,
):
    """Net MTG torque on a joint in the model convention, N·m (thesis Eq 5.32).

    Parameters
    ----------
    joint : {'hip', 'knee', 'ankle'} (``_r``/``_l`` suffix accepted)
    q, qd : joint angle (rad) and velocity (rad/s), model convention (conventions.py).
    a_ext, a_flex : extensor and flexor activations in [0, 1].
    params : fitting parameters (see :func:`generator_torque`).

    Returns
    -------
    tau : τ_ext + τ_flex with each term signed by σ_τ; positive = CCW (hip flexion,
        knee extension, ankle dorsiflexion).
    """
    j = _joint_key(joint)
    kw = dict(body_mass=body_mass, body_height=body_height)
    return generator_joint_torque(f"{j}_ext", q, qd, a_ext, params, **kw) + generator_joint_torque(
        f"{j}_flex", q, qd, a_flex, params, **kw
    )


def _positive_generator(joint: str) -> str:
    """The generator of a joint whose model-convention torque is positive."""
    j = _joint_key(joint)
    return f"{j}_flex" if TORQUE_SIGN[f"{j}_flex"] > 0 else f"{j}_ext"


def pair_activations(joint: str, u, eps: float = 1e-3):
    """Split one signed activation into (a_ext, a_flex) without co-contraction (Eq 5.32).

    u ∈ [−1, 1] is signed like the model's joint torque: u > 0 activates the generator
    whose torque is CCW positive (hip flexor, knee extensor, ankle flexor). Smooth split:
    a₊ = ½(u + sqrt(u² + ε²)), a₋ = ½(−u + sqrt(u² + ε²)), so a₊ − a₋ = u exactly,
    both ≥ 0, and the residual co-contraction is ε/2 at u = 0 (≤ ε²/(4|u|) elsewhere);
    a ≤ 1 + ε²/8. ``eps=0`` gives the exact (non-smooth) split.
    """
    if _is_ca(u):
        r = ca.sqrt(u * u + eps * eps)
    else:
        r = np.sqrt(_num(u) ** 2 + eps * eps)
    a_pos, a_neg = 0.5 * (u + r), 0.5 * (-u + r)
    a_pos, a_neg = (a_pos, a_neg) if _is_ca(u) else (_out(a_pos), _out(a_neg))
    if _positive_generator(joint).endswith("_flex"):
        return a_neg, a_pos
    return a_pos, a_neg


def pair_torque(joint: str, q, qd, u, params=None, *, eps: float = 1e-3, **kw):
    """Joint torque (model convention, N·m) from one signed activation u (see
    :func:`pair_activations`)."""
    a_ext, a_flex = pair_activations(joint, u, eps)
    return joint_torque(joint, q, qd, a_ext, a_flex, params, **kw)


def split_joint_torque(joint: str, tau) -> dict[str, Any]:
    """Thesis Eqs 5.18–5.20 in the model's convention: a joint torque τ (N·m) split into
    the non-negative generator torques τ^M of its two generators (no co-contraction).

    The generator with σ_τ = +1 takes max(τ, 0), the other max(−τ, 0). Numeric only.
    """
    j = _joint_key(joint)
    t = _num(tau)
    pos = _positive_generator(j)
    neg = f"{j}_ext" if pos.endswith("_flex") else f"{j}_flex"
    return {pos: _out(np.maximum(t, 0.0)), neg: _out(np.maximum(-t, 0.0))}


def activation_for_torque(
    joint: str,
    tau,
    q,
    qd,
    params=None,
    *,
    body_mass: float = BODY_MASS,
    body_height: float = BODY_HEIGHT,
) -> dict[str, Any]:
    """Activations that produce a demanded joint torque (closed form; initial guesses).

    Thesis Sec 5.2.1: the MTG torque is affine in the activation, so with the passive
    torques of both generators τ_P(q, q̇) (a = 0) the active torque needed is
    τ − τ_P; it is produced by the generator acting in its direction (no
    co-contraction): a = |τ − τ_P| / (s^τ τ0 t^A t^V). Results are clipped to [0, 1].
    Numeric inputs only (floats/arrays, broadcast).

    Returns
    -------
    dict
        ``a_ext``, ``a_flex`` (clipped, in [0, 1]); ``a_ext_raw``, ``a_flex_raw``
        (unclipped, may exceed 1 where the demand is infeasible); ``clipped`` (bool,
        where clipping changed a value); ``tau_achieved`` (N·m, model convention, with
        the clipped activations); ``residual`` = tau − tau_achieved.
    """
    j = _joint_key(joint)
    kw = dict(body_mass=body_mass, body_height=body_height)
    tau, q, qd = _num(tau), _num(q), _num(qd)
    tau_p = _num(joint_torque(j, q, qd, 0.0, 0.0, params, **kw))
    need = tau - tau_p
    raw = {}
    for d in ("ext", "flex"):
        g = f"{j}_{d}"
        th, om = fibre_kinematics(g, q, qd)
        T0, tA, tV, _, _ = _generator_parts(g, th, om, params, body_mass, body_height)
        gain = T0 * tA * tV  # > 0 N·m per unit activation (in fibre frame)
        demand = np.maximum(TORQUE_SIGN[g] * need, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            raw[d] = np.where(demand > 0.0, demand / np.maximum(gain, 1e-300), 0.0)
    a_ext, a_flex = np.clip(raw["ext"], 0.0, 1.0), np.clip(raw["flex"], 0.0, 1.0)
    achieved = _num(joint_torque(j, q, qd, a_ext, a_flex, params, **kw))
    return {
        "a_ext": _out(a_ext),
        "a_flex": _out(a_flex),
        "a_ext_raw": _out(raw["ext"]),
        "a_flex_raw": _out(raw["flex"]),
        "clipped": _out((raw["ext"] > 1.0) | (raw["flex"] > 1.0)),
        "tau_achieved": _out(achieved),
        "residual": _out(tau - achieved),
    }


# --------------------------------------------------------------------------------------
# Envelopes for plots (thesis Figs 5.1, 5.2)
# --------------------------------------------------------------------------------------


def isometric_envelope(
    generator: str, q, params=None, *, qd=0.0, body_mass=BODY_MASS, body_height=BODY_HEIGHT
) -> dict[str, Any]:
    """Isometric envelope of one generator vs the model's joint angle q (rad), N·m ≥ 0.

    Returns ``{'active': s^τ τ0 t^A(θ) (Eq 5.24, upper limit), 'passive': s^τ τ0 t^P(θ)
    (1 − β^P ω̂) (Eq 5.25, lower limit; ω̂ from ``qd``), 'total': active + passive
    (a = 1, q̇ = ``qd``), 'theta_f': fibre angle}`` as magnitudes in the generator frame.
    """
    g = _gen_key(generator)
    th, om = fibre_kinematics(g, q, qd)
    T0, tA, tV, tP, w = _generator_parts(g, th, om, params, body_mass, body_height)
    active = T0 * tA
    passive = T0 * tP * (1.0 - BETA_P * w)
    total = T0 * tA * tV + passive
    f = (lambda x: x) if _is_ca(q, qd) else _out
    return {"active": f(active), "passive": f(passive), "total": f(total), "theta_f": f(th)}


def max_joint_torque(joint: str, q, qd=0.0, params=None, **kw):
    """Extreme net joint torques (model convention, N·m) at (q, q̇): returns
    (τ_min, τ_max) = torque with only the negative-direction generator fully active, and
    with only the positive-direction one (a = 1; the other at a = 0, passive included)."""
    j = _joint_key(joint)
    pos = _positive_generator(j)
    if pos.endswith("_flex"):
        return joint_torque(j, q, qd, 1.0, 0.0, params, **kw), joint_torque(
            j, q, qd, 0.0, 1.0, params, **kw
        )
    return joint_torque(j, q, qd, 0.0, 1.0, params, **kw), joint_torque(
        j, q, qd, 1.0, 0.0, params, **kw
    )


def torque_velocity(generator: str, qd, params=None, *, body_mass=BODY_MASS, body_height=BODY_HEIGHT):
    """Fitted torque–velocity limit s^τ τ0 t^V(ω̂) (thesis Eq 5.27), N·m ≥ 0, vs the
    model's joint velocity q̇ (rad/s); ω̂ = σ_τ q̇ / (s^V ω_max)."""
    g = _gen_key(generator)
    _, om = fibre_kinematics(g, 0.0, qd)
    T0, _, tV, _, _ = _generator_parts(g, 0.0, om, params, body_mass, body_height)
    r = T0 * tV
    return r if _is_ca(qd) else _out(r)


def demanded_active_torque(
    generator: str, tau_m, q, qd, params=None, *, body_mass=BODY_MASS, body_height=BODY_HEIGHT
):
    """Active torque a generator must supply (thesis Eq 5.26), N·m: τ^M_exp − passive, with
    τ^M_exp ≥ 0 the generator's share of the joint torque (:func:`split_joint_torque`)."""
    g = _gen_key(generator)
    th, om = fibre_kinematics(g, q, qd)
    T0, _, _, tP, w = _generator_parts(g, th, om, params, body_mass, body_height)
    r = tau_m - T0 * tP * (1.0 - BETA_P * w)
    return r if _is_ca(tau_m, q, qd) else _out(r)


def strength_limits(mtg_params=None, *, body_mass: float = BODY_MASS, body_height: float = BODY_HEIGHT,
                    legs: int = 1) -> dict[str, tuple[float, float]]:
    """Peak active torque per joint and direction, model convention (N·m):
    ``{"hip": (τ_min < 0, τ_max > 0), "knee": …, "ankle": …, "mtp": …}``.

    Each bound is the peak of the generator that produces that sign, s^τ τ0 E (thesis
    Eq 5.8 with a = 1, t^A = 1, t^V = E the eccentric plateau; τ0 by Eq 5.21 for
    ``body_mass`` kg × ``body_height`` m), times ``legs``. ``mtg_params``: generator →
    :class:`MTGParams` (None: Eq 5.22 defaults, s^τ = 1). The metatarsal joint
    has no MTG: the ankle plantarflexor's peak bounds it in both directions."""
    out = {}
    for j in MTG_JOINTS:
        lim = {}
        for d in ("ext", "flex"):
            g = f"{j}_{d}"
            p = (mtg_params or {}).get(g, DEFAULT_PARAMS)
            peak = float(p.s_tau) * tau0(g, body_mass, body_height) * max(1.0, GYMNAST[g].E) * legs
            lim[TORQUE_SIGN[g] > 0] = peak
        out[j] = (-lim[False], lim[True])
    pf = out["ankle"][0]  # plantarflexion is negative
    out["mtp"] = (pf, -pf)
    return out
