"""Poses of the child model from data, and the exact geometry of the contact ellipsoids.

Used by the figures (:mod:`gaitlib.plots`) and reusable by the transcription layer (initial
guesses from data). SI units, signs of :mod:`gaitlib.conventions`.

Ellipsoid geometry
------------------
An ellipsoid with centre ``c``, rotation ``R`` (ellipsoid → ground) and radii
``D = diag(a, b, c)`` is ``{c + R D u : |u| ≤ 1}`` = ``{x : (x − c)ᵀ M⁻¹ (x − c) ≤ 1}``
with ``M = R D² Rᵀ``. Its support function in the direction ``e`` is ``sqrt(eᵀ M e)``, so its
lowest point lies at ``y = c_y − sqrt(e_yᵀ M e_y)`` (:func:`ellipsoid_bottom`), and its
orthographic projection on the X–Y plane is the ellipse whose 2×2 shape matrix is the
top-left block of ``M`` (:func:`gaitlib.plots.ellipse_outline`).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from gaitlib import conventions as cv
from gaitlib import contact
from gaitlib.model import ELLIPSOID_LABELS

__all__ = [
    "ellipsoid_bottoms_sx",
    "shape_matrix",
    "ellipsoid_bottom",
    "ellipsoid_radii",
    "ellipsoid_bottoms",
    "ellipsoid_bottoms_rows",
    "pose_from_data",
    "settle_height",
    "height_for_load",
    "LoadNotCarried",
]


def shape_matrix(R, radii) -> np.ndarray:
    """``M = R D² Rᵀ`` (3, 3) of an ellipsoid with rotation ``R``, radii ``(a, b, c)``; m²."""
    R = np.asarray(R, dtype=float)
    d2 = np.asarray(radii, dtype=float) ** 2
    return (R * d2) @ R.T


def ellipsoid_bottom(centre, R, radii) -> float:
    """Height of the lowest point of an ellipsoid, m: ``c_y − sqrt(e_yᵀ R D² Rᵀ e_y)``."""
    M = shape_matrix(R, radii)
    return float(np.asarray(centre, dtype=float)[1] - np.sqrt(M[1, 1]))


def ellipsoid_radii(p_contact=None) -> np.ndarray:
    """Radii (a, b, c) of the six ellipsoids of the child model, (6, 3) m, in the order
    :data:`gaitlib.model.ELLIPSOID_LABELS` (right foot first; the mirror keeps the radii)."""
    p = contact.default_params() if p_contact is None else np.asarray(p_contact, dtype=float)
    abc = np.array([p[contact.param_index(e, "a"):contact.param_index(e, "c") + 1]
                    for e in cv.ELLIPSOIDS])
    return np.vstack([abc, abc])


def ellipsoid_bottoms(model, q, p_contact=None) -> np.ndarray:
    """Lowest point (y, m) of each of the six ellipsoids at pose ``q`` (11,) → (6,)."""
    centres, Rs = model.ellipsoid_poses(np.asarray(q, dtype=float), p_contact)
    radii = ellipsoid_radii(p_contact)
    return np.array([ellipsoid_bottom(c, R, r) for c, R, r in zip(centres, Rs, radii)])


def ellipsoid_bottoms_rows(model, Q, p_contact=None) -> np.ndarray:
    """:func:`ellipsoid_bottoms` of every row of ``Q`` (n, 11) → (n, 6) m, the model's
    ``ellipsoid_poses`` evaluated for all rows in one mapped call (the same numbers as row
    by row: each column runs the same function)."""
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    if Q.shape[0] == 0:
        return np.empty((0, len(ELLIPSOID_LABELS)))
    p = contact.default_params() if p_contact is None else np.asarray(p_contact, dtype=float)
    f = model.function("ellipsoid_poses")
    out = dict(zip(f.name_out(), (np.asarray(o.full()) for o in f.map(Q.shape[0]).call([Q.T, p]))))
    centres, Rs = out["centres"], [out[f"R_{e}"] for e in ELLIPSOID_LABELS]
    radii = ellipsoid_radii(p)
    return np.array([[ellipsoid_bottom(centres[k, 3 * i:3 * i + 3], R[:, 3 * i:3 * i + 3], radii[k])
                      for k, R in enumerate(Rs)] for i in range(Q.shape[0])])


def ellipsoid_bottoms_sx(model, q, p_contact=None):
    """:func:`ellipsoid_bottoms` as a CasADi expression of ``q`` (SX/MX, 11) → (6, 1) m:
    ``c_y − sqrt(e_yᵀ R D² Rᵀ e_y)`` per ellipsoid, from the model's ``ellipsoid_poses``."""
    p = contact.default_params() if p_contact is None else np.asarray(p_contact, dtype=float)
    out = model.function("ellipsoid_poses")(q, p)
    radii = ellipsoid_radii(p)
    rows = []
    for i in range(len(radii)):
        R = out[1 + i]
        rows.append(out[0][i, 1] - ca.sqrt(ca.sumsqr(R[1, :] * ca.DM(radii[i]).T)))
    return ca.vertcat(*rows)


def pose_from_data(model, gait_data, times, p_contact=None, penetration: float = 0.002,
                   x0: float = 0.0, thigh: str = "lab") -> np.ndarray:
    """Generalised coordinates of the child model following a data set's joint angles.

    Parameters
    ----------
    model : gaitlib.model.ChildModel
    gait_data : gaitlib.data.GaitData
        Its ``hip, knee, ankle, mtp`` channels (both legs, rad, model signs) are used,
        interpolated periodically at ``times``.
    times : (n,) s
    p_contact : (39,) contact parameters, default ``contact.default_params()``.
    penetration : float
        Depth of the lowest of the six ellipsoids below the ground, m (≥ 0 loads the foot).
    x0 : pelvis_tx at t = 0, m.
    thigh : ``"lab"`` (default) or ``"pelvis"``
        How the data's hip angle (thigh relative to the CGM pelvis) becomes the model's.
        The HAT is kept upright (``pelvis_tilt = 0``: the data's pelvic tilt, ≈ 11° anterior
        for *Free*, contains an anatomical offset and is not the model's HAT angle).
        ``"lab"``: keep the thigh's orientation in the laboratory, ``hip = hip_data +
        pelvis_tilt_data`` (model signs), so leading and trailing legs are placed as
        measured. ``"pelvis"``: ``hip = hip_data`` (the thigh rotates forward by the
        pelvic tilt, ≈ 11°; at heel strike the leading heel then floats ≈ 9 cm above the
        ground while the trailing toe touches it). Knee, ankle and metatarsal angles are
        the data's in both cases.

    Returns
    -------
    q : (n, 11) in the order :data:`gaitlib.conventions.COORDS`, with
        ``pelvis_tx = x0 + speed · t``, ``pelvis_tilt = 0``, and ``pelvis_ty`` such that
        the lowest point of the six ellipsoids is exactly ``penetration`` below the ground
        (computed from the ellipsoid geometry, see :func:`ellipsoid_bottom`; a vertical
        shift moves every ellipsoid rigidly).
    """
    times = np.atleast_1d(np.asarray(times, dtype=float))
    if thigh not in ("lab", "pelvis"):
        raise ValueError("thigh must be 'lab' or 'pelvis'")
    ang = gait_data.at(times, channels=list(cv.JOINTS) + ["pelvis_tilt"])
    q = np.zeros((times.size, len(cv.COORDS)))
    q[:, 0] = x0 + gait_data.speed * times
    for j in cv.JOINTS:
        q[:, cv.COORDS.index(j)] = ang[j].to_numpy()
        if thigh == "lab" and j.startswith("hip_"):
            q[:, cv.COORDS.index(j)] = cv.thigh_in_lab(q[:, cv.COORDS.index(j)], ang["pelvis_tilt"].to_numpy())
    q[:, 1] = 0.0
    q[:, 1] = -ellipsoid_bottoms_rows(model, q, p_contact).min(axis=1) - penetration
    return q


def settle_height(model, q, p_body=None, p_contact=None, below: float = 0.04,
                  above: float = 0.002) -> float:
    """``pelvis_ty`` at which the contact carries the body weight at rest, m.

    The root of the vertical residual ``R_y(pelvis_ty)`` of ``model.inverse_dynamics(q, 0,
    0)`` (the other coordinates of ``q`` fixed) — the static equilibrium height of the
    pose. Bracketed between ``above`` m above the height at which the lowest ellipsoid
    touches the ground (no contact: ``R_y`` = weight > 0) and ``below`` m under it.
    """
    from scipy.optimize import brentq

    q = np.array(q, dtype=float)
    q[1] = 0.0
    touch = -ellipsoid_bottoms(model, q, p_contact).min()
    zero = np.zeros_like(q)

    def R_y(ty):
        q[1] = ty
        return float(model.inverse_dynamics(q, zero, zero, p_body, p_contact)[1][1])

    return float(brentq(R_y, touch - below, touch + above, xtol=1e-12))


class LoadNotCarried(ValueError):
    """A contact set cannot carry a pose's load at rest within the searched penetration."""


def height_for_load(model, Q, load, p_contact=None, below: float = 0.06, above: float = 0.002) -> np.ndarray:
    """``pelvis_ty`` (m) of each pose at which the six ellipsoids carry a given vertical load.

    For every row of ``Q`` (n, 11; ``pelvis_ty`` ignored) the root of
    ``Σ fy(pelvis_ty) − load`` with the model at rest (``q̇ = 0``: the elastic part of the
    contact force only), where ``load`` (n,) N is, e.g., the data's total vertical GRF of
    both feet. The contact force falls monotonically as the body rises, so the root is
    unique; it is bracketed between ``above`` m over the height where the lowest ellipsoid
    touches the ground (no load) and ``below`` m under it. A load that needs more than
    ``below`` of penetration raises :class:`LoadNotCarried` (a ``ValueError``) naming the row.

    This estimates the HAT height that the thesis took from a pelvis marker (Sec 4.2.1),
    which the public data do not include.
    """
    from scipy.optimize import brentq

    Q = np.array(Q, dtype=float)
    load = np.broadcast_to(np.asarray(load, dtype=float), (Q.shape[0],))
    key = (model, Q.tobytes(), Q.shape, load.tobytes(), contact_default(p_contact).tobytes(), below, above)
    if key in _HEIGHTS:
        return _HEIGHTS[key].copy()
    f_ct = model.function("contact")
    out = np.empty(Q.shape[0])
    zero = np.zeros(Q.shape[1])
    for i, q in enumerate(Q):
        q = q.copy()
        q[1] = 0.0
        touch = -ellipsoid_bottoms(model, q, p_contact).min()
        if load[i] <= 0:
            out[i] = touch
            continue

        def excess(ty):
            q[1] = ty
            fy = f_ct(q=q, qd=zero, p_contact=contact_default(p_contact))["grf_y"]
            return float(np.sum(np.asarray(fy))) - load[i]

        lo, hi = touch - below, touch + above
        if excess(lo) < 0:
            raise LoadNotCarried(f"row {i}: a load of {load[i]:.1f} N needs more than {below} m of penetration")
        out[i] = brentq(excess, lo, hi, xtol=1e-13)
    if len(_HEIGHTS) >= _HEIGHTS_KEPT:  # the oldest first
        del _HEIGHTS[next(iter(_HEIGHTS))]
    _HEIGHTS[key] = out.copy()
    return out


#: :func:`height_for_load`'s results by their inputs (the model, the poses, loads and contact
#: parameters to the last bit): a problem rebuilt on the same data — each cached gap solution
#: loaded — finds the same heights without the root searches.
_HEIGHTS: dict = {}
_HEIGHTS_KEPT = 256


def contact_default(p_contact):
    """``p_contact`` or the default contact parameters (39,)."""
    return contact.default_params() if p_contact is None else np.asarray(p_contact, dtype=float)
