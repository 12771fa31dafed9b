"""Candidate unmodelled effects: small, documented extensions the gait transcription can
switch on (``GaitSpec.effects``), each with one magnitude and few parameters.

A :class:`~gaitlib.problems.gait.GaitSpec` carries ``effects = ((name, magnitude), ...)``:
``magnitude`` a float fixes the effect's first parameter (the *magnitude*; its other
parameters, if any, keep their null values) — this is how :mod:`gaitlib.gap.twin` injects
an effect; ``None`` makes every parameter of the effect an NLP variable within its bounds
(``fx.<effect>.<parameter>``), identified by the optimisation together with the motion —
this is how :func:`gaitlib.gap.diagnose` tests it. Magnitude 0 (the null value of every
effect) reproduces the baseline model exactly.

Where an effect acts (hooks called by :func:`gaitlib.problems.gait.build`)
---------------------------------------------------------------------------
``body``        the 25 body/joint parameters p_body (masses, MOIs, joint K and B)
``contact``     the 39 contact parameters p_contact (friction, ellipsoid positions)
``root_load``   an extra generalised force on the HAT's coordinates (pelvis_tx, pelvis_ty:
                N; pelvis_tilt: N·m about the hip joint centre) that the HAT/residual
                equations must supply — a load the rigid HAT does not have
``reference``   the tracked left-leg references (a data model, not physics: the left leg
                of the public data is generated from the right one)
``path``        extra path constraints, expr ≥ 0 (co-contraction)
``adjust_data`` how the *data* are read when the effect is on (left leg regenerated with
                the identified time shift; EMG compared at a shifted time) — applied by the
                gap computation (:mod:`gaitlib.gap.locate`) to the effect's own solution

Observability. The tracked channels (joint angles, *net* joint torques, GRFs) satisfy the
model's inverse dynamics whatever actuates the joints: the net torque equals M q̈ + h − Q_c
for the leg's segments. Effects that change only *how* the net torque is produced (joint
stiffness and damping, co-contraction, activation timing) therefore leave angles, torques
and GRFs unchanged in the SK model; they are visible only through muscle-level channels
(MSK generator activations, NMSK excitations) against EMG. :attr:`Effect.models` lists the
models in which an effect can be switched on, :attr:`Effect.signature` where it shows.

Laboratory effects (:data:`LAB_EFFECTS`: joint-angle offsets, force-plate gain and AP
bias) are data-model effects like ``left_shift``: they change how the data are read
(``reference`` and ``adjust_data``), not the physics; :data:`MODEL_EFFECTS` are the others.

Units are SI; every effect documents its physics, parameters and bounds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import casadi as ca
import numpy as np

from . import conventions as cv
from .model import P_BODY_NAMES
from .contact import param_index
from . import data as data_mod
from .ocp import Parameter

__all__ = ["EffectParam", "Effect", "EFFECTS", "TWIN_EFFECTS", "LAB_EFFECTS", "MODEL_EFFECTS", "PLATE_THRESHOLD_N", "Context", "Bound", "bind", "validate", "formulation_versions",
           "data_columns", "adjust_data", "theta_of", "ARM"]


@dataclass(frozen=True)
class EffectParam:
    """One parameter of an effect: name, unit, bounds, null value (= baseline model)."""

    name: str
    unit: str
    lower: float
    upper: float
    null: float = 0.0
    doc: str = ""


@dataclass(frozen=True)
class Context:
    """What an effect's hooks may read: the spec, the model, the tracked reference
    (:class:`gaitlib.problems.gait.Reference`), the data's cycle time ``T`` (s), and the
    nominal body/contact parameter vectors."""

    spec: Any
    model: Any
    ref: Any
    T: float
    p_body: np.ndarray
    p_contact: np.ndarray


@dataclass(frozen=True)
class Effect:
    """A candidate unmodelled effect.

    Attributes
    ----------
    name : registry key (:data:`EFFECTS`).
    title : short human-readable name.
    doc : physics, units, parameters and bounds (numpydoc-style text).
    params : its parameters; ``params[0]`` is the magnitude a twin injects.
    models : models in which it can be switched on.
    signature : the channels in which it can show (``"angles torques grf"``, ``"emg"``).
    resolve : False — the effect changes only how the data are compared (no re-solve is
        needed; its magnitude is fitted on the comparison alone).
    identify : ``"nlp"`` — parameters are NLP variables when the magnitude is None;
        ``"profile"`` — the cost function cannot see the effect's signature (EMG), so the
        magnitude is fitted by minimising the located gap over a grid of fixed values.
    twin_magnitudes : magnitudes used by the twin validation (small, middle, large).
    version : the effect's formulation version (``""``: its first). Cache keys of solves with
        the effect switched on name it when set (:func:`formulation_versions`), so a change
        of what the effect solves re-keys only those solves.
    """

    name: str
    title: str
    doc: str
    params: tuple
    models: tuple = ("SK", "MSK", "NMSK")
    signature: str = "angles torques grf"
    resolve: bool = True
    identify: str = "nlp"
    twin_magnitudes: tuple = ()
    body: Callable | None = None         # (pb: list, th: dict, ctx) -> list
    contact: Callable | None = None      # (pc: list, th: dict, ctx) -> list
    root_load: Callable | None = None    # (x: Named, th: dict, ctx) -> SX (3,)
    reference: Callable | None = None    # (d: Named, th, ctx, t) -> dict name -> expr
    columns: Callable | None = None      # (ref, tau_grid) -> dict name -> array
    path: Callable | None = None         # (node_out: dict, th, ctx) -> expr, constrained ≥ 0
    data_adjust: Callable | None = None  # (gait, th) -> gait
    version: str = ""

    @property
    def n_params(self) -> int:
        return len(self.params)

    @property
    def magnitude(self) -> EffectParam:
        return self.params[0]

    def null_theta(self) -> dict:
        return {p.name: p.null for p in self.params}


# ======================================================================================
# Helpers
# ======================================================================================

def _idx(name: str) -> int:
    return P_BODY_NAMES.index(name)


def _contact_idx(ell: str, name: str) -> int:
    return param_index(ell, name)


def _rot(th):
    c, s = ca.cos(th), ca.sin(th)
    return c, s


def hat_body_wrench(x, m, I, s, sd, sdd, alpha_rel, g=cv.G):
    """Root wrench (F_x, F_y: N; M about the HAT origin = hip joint centre: N·m) needed to
    move a rigid body of mass ``m`` (kg) and MOI ``I`` about its COM (kg·m²) whose COM is at
    ``s`` (m, HAT frame, with HAT-frame rates ``sd``, ``sdd``) and which turns with the
    HAT plus ``alpha_rel`` (rad/s², relative angular acceleration), under gravity ``g``.

    r = R(θ) s; r̈ = R̈ s + 2 Ṙ ṡ + R s̈ with Ṙ = θ̇ R J, R̈ = θ̈ R J − θ̇² R (J the 90°
    rotation); F = m (a_o + r̈ + g ŷ); M = I (θ̈ + α_rel) + r × F. ``x`` is the state
    (Named) with the HAT's ``pelvis_*`` coordinates and their rates.
    """
    th, thd, thdd = x["pelvis_tilt"], x["qd_pelvis_tilt"], x["qdd_pelvis_tilt"]
    ax, ay = x["qdd_pelvis_tx"], x["qdd_pelvis_ty"]
    c, sn = _rot(th)

    def R(v):
        return (c * v[0] - sn * v[1], sn * v[0] + c * v[1])

    def RJ(v):  # R J v, J v = (−v_y, v_x)
        return R((-v[1], v[0]))

    r = R(s)
    t1 = RJ(s)
    t2 = RJ(sd)
    t3 = R(sdd)
    rdd = tuple(thdd * t1[i] - thd**2 * r[i] + 2 * thd * t2[i] + t3[i] for i in range(2))
    Fx = m * (ax + rdd[0])
    Fy = m * (ay + rdd[1] + g)
    M = I * (thdd + alpha_rel) + r[0] * Fy - r[1] * Fx
    return ca.vertcat(Fx, Fy, M)


# ---- arms (Winter 2009, Table 4.1: segment mass / BM, length / BH, COM from the proximal
# joint / length, radius of gyration about the COM / length)
_ARM_SEGMENTS = (  # upper arm, forearm, hand (elbow and wrist straight)
    (0.028, 0.186, 0.436, 0.322),
    (0.016, 0.146, 0.430, 0.303),
    (0.006, 0.108, 0.506, 0.297),
)


def _arm_properties(body_mass=cv.BODY_MASS, body_height=cv.BODY_HEIGHT) -> dict:
    """One straight arm as a rigid pendulum: mass (kg), COM distance from the shoulder (m),
    MOI about its COM (kg·m²), shoulder height above the hip joint centre (m: the HAT's
    length 0.288 BH, Table 4.1, i.e. Winter's shoulder 0.818 BH − hip 0.530 BH)."""
    m = sum(s[0] for s in _ARM_SEGMENTS) * body_mass
    start, parts = 0.0, []
    for mf, lf, cf, rg in _ARM_SEGMENTS:
        L = lf * body_height
        parts.append((mf * body_mass, start + cf * L, (rg * L) ** 2 * mf * body_mass))
        start += L
    lc = sum(mi * di for mi, di, _ in parts) / m
    I = sum(Ii + mi * (di - lc) ** 2 for mi, di, Ii in parts)
    return {"mass": m, "com": lc, "moi": I, "shoulder": 0.288 * body_height}


#: Arm pendulum properties used by ``arm_swing`` (kg, m, kg·m², m).
ARM = _arm_properties()


# ======================================================================================
# The effects
# ======================================================================================

_LEG_SEGMENTS = ("thigh", "shank", "toe", "forefoot", "hindfoot")


def _segment_inertia_body(pb, th, ctx):
    k = th["k"]
    pb = list(pb)
    leg = 0
    for s in _LEG_SEGMENTS:
        i_m, i_i = _idx(f"mass_{s}"), _idx(f"moi_{s}")
        leg = leg + 2 * pb[i_m] * k  # both legs
        pb[i_m] = pb[i_m] * (1 + k)
        pb[i_i] = pb[i_i] * (1 + k)
    ih = _idx("mass_hat")
    pb[ih] = pb[ih] - leg  # total body mass unchanged
    return pb


SEGMENT_INERTIA = Effect(
    name="segment_inertia",
    title="leg segment mass and inertia error",
    doc="""Leg segments heavier or lighter than the scaled adult anthropometrics (thesis Sec
    4.1.1, Tables 4.1–4.3; a child's mass distribution differs from an adult's).

    Every leg segment's mass and moment of inertia (thigh, shank, toe, fore- and hind-foot,
    both legs) is multiplied by (1 + k); the HAT's mass changes by minus the legs' total
    change so that the body mass (which the data are normalised by) is unchanged.
    Shows in the swing-phase hip and knee torques (inertial loads of the swinging leg).

    Parameters
    ----------
    k : relative change of leg segment mass and MOI, 1; bounds [−0.5, 0.5]; null 0.
    """,
    params=(EffectParam("k", "1", -0.5, 0.5, 0.0, "relative leg mass/MOI change"),),
    twin_magnitudes=(0.15, 0.3, 0.45),
    body=_segment_inertia_body,
)


def _body_mass_body(pb, th, ctx):
    k = th["k"]
    pb = list(pb)
    for s in ("hat",) + _LEG_SEGMENTS:
        for pre in ("mass", "moi"):
            i = _idx(f"{pre}_{s}")
            pb[i] = pb[i] * (1 + k)
    return pb


BODY_MASS = Effect(
    name="body_mass",
    title="body mass differing from the data's normalising mass",
    doc="""The data are group means of mass-normalised curves (N/kg, body weights) scaled by
    one child's mass (41.4 kg, thesis Sec 4.1.1); the model's segment masses (Table 4.1
    fractions, 1.001 BM in total) are its dynamic mass. If the two differ — a heavier or
    lighter dynamic body, or a force-plate/normalisation error — the vertical GRF no longer
    averages to the model's weight. Every segment's mass and moment of inertia is
    multiplied by (1 + k); the data stay as they are.

    Parameters
    ----------
    k : relative change of the whole body's mass and MOIs, 1; bounds [−0.3, 0.3]; null 0.
    """,
    params=(EffectParam("k", "1", -0.3, 0.3, 0.0, "relative body mass change"),),
    twin_magnitudes=(0.02, 0.04, 0.08),
    body=_body_mass_body,
)


def _hat_com_load(x, th, ctx):
    """Root wrench of the COM offset, written linear in d so that d = 0 is exactly zero:
    Δr = d R(θ) x̂; ΔF = m d e with e = θ̈ J R x̂ − θ̇² R x̂; ΔM = Δr × m (a_c + g ŷ) +
    (r + Δr) × ΔF, a_c the HAT COM acceleration of the model (COM at r = R(θ) (0, h))."""
    d = th["d"]
    m = ctx.p_body[_idx("mass_hat")]
    h = ctx.model.hat_com_height
    th_, thd, thdd = x["pelvis_tilt"], x["qd_pelvis_tilt"], x["qdd_pelvis_tilt"]
    c, s = ca.cos(th_), ca.sin(th_)
    r = (-h * s, h * c)
    ac = (x["qdd_pelvis_tx"] - thdd * h * c - thd**2 * r[0], x["qdd_pelvis_ty"] - thdd * h * s - thd**2 * r[1])
    e = (-thdd * s - thd**2 * c, thdd * c - thd**2 * s)
    dF = (m * d * e[0], m * d * e[1])
    F = (m * ac[0], m * (ac[1] + cv.G))
    dM = d * (c * F[1] - s * F[0]) + (r[0] + d * c) * dF[1] - (r[1] + d * s) * dF[0]
    return ca.vertcat(dF[0], dF[1], dM)


HAT_COM = Effect(
    name="hat_com",
    title="HAT centre of mass fore–aft offset",
    doc="""The head–arms–trunk centre of mass lies ``d`` in front of (d > 0) the hip–HAT axis
    of the model (thesis Table 4.1 puts it on the axis, 0.626 of the HAT length above the
    hip); e.g. a trunk mass distribution or a habitual trunk lean that the upright HAT
    does not have.

    Implemented as the extra root wrench of the offset: the HAT's required force and moment
    about the hip joint centre with the COM at (d, h) minus those at (0, h) (HAT frame),
    exact rigid-body terms (gravity moment m g d cos θ plus the inertial terms of the
    offset), :func:`hat_body_wrench`; HAT mass and MOI unchanged.

    Parameters
    ----------
    d : fore–aft COM offset in the HAT frame, m (forward positive); bounds [−0.1, 0.1]; null 0.
    """,
    params=(EffectParam("d", "m", -0.1, 0.1, 0.0, "HAT COM forward offset"),),
    twin_magnitudes=(0.01, 0.02, 0.04),
    root_load=_hat_com_load,
)


def _arm_angles(x, th, ctx):
    """Arm swing angles (rad, forward positive) of the right and left arm, and their first
    and second time derivatives: each arm follows the contralateral thigh,
    φ_r = G (q_hip_l − c_l), φ_l = G (q_hip_r − c_r), c = the reference's mean hip angle."""
    G = th["G"]
    out = {}
    for arm, leg in (("r", "l"), ("l", "r")):
        c = float(np.mean(ctx.ref.q[f"hip_{leg}"]))
        out[arm] = (G * (x[f"hip_{leg}"] - c), G * x[f"qd_hip_{leg}"], G * x[f"qdd_hip_{leg}"])
    return out


def _arm_swing_load(x, th, ctx):
    m, lc, I, h = ARM["mass"], ARM["com"], ARM["moi"], ARM["shoulder"]
    z = (0.0, 0.0)
    total = ca.DM.zeros(3)
    for phi, phid, phidd in _arm_angles(x, th, ctx).values():
        s = (lc * ca.sin(phi), h - lc * ca.cos(phi))
        sd = (lc * phid * ca.cos(phi), lc * phid * ca.sin(phi))
        sdd = (lc * (phidd * ca.cos(phi) - phid**2 * ca.sin(phi)), lc * (phidd * ca.sin(phi) + phid**2 * ca.cos(phi)))
        total = total + hat_body_wrench(x, m, I, s, sd, sdd, phidd) - hat_body_wrench(x, m, I, (0.0, h - lc), z, z, 0.0)
    return total


ARM_SWING = Effect(
    name="arm_swing",
    title="arm swing acting on the HAT",
    doc=f"""The model has no arms (thesis Sec 4.1.1: their mass is in the HAT; Sec 8.2 suggests
    adding them). Here two straight arms (Winter's segment data: {ARM['mass']:.2f} kg each,
    COM {ARM['com']:.3f} m from the shoulder, MOI {ARM['moi']:.4f} kg·m² about the COM;
    shoulder {ARM['shoulder']:.3f} m above the hip joint centre) swing in the sagittal plane
    relative to the HAT, each following the *contralateral* thigh with gain G:
    φ_r = G (q_hip_l − c_l), φ_l = G (q_hip_r − c_r) (c: mean reference hip angle). The HAT
    must supply the arms' wrench at φ(t) minus that of the hanging arms already inside
    the rigid HAT (:func:`hat_body_wrench`, exact: gravity, relative and HAT-induced
    accelerations).

    Physics note: in a sagittal-plane model an antiphase, symmetric swing cancels to first
    order — the two arms' pitch moments and horizontal forces are equal and opposite; what
    remains is a vertical force at twice the stride frequency (second order in the swing
    amplitude) and the part of the hip motion that is not antiphase (even harmonics). The
    effect is therefore small in this 2-D model whatever G is; its validation on twins shows
    how small.

    Parameters
    ----------
    G : arm swing angle per contralateral hip angle, 1; bounds [0, 3]; null 0
        (typical walking: arm excursion ≈ 0.5–1 × hip excursion).
    """,
    params=(EffectParam("G", "1", 0.0, 3.0, 0.0, "arm angle per contralateral hip angle"),),
    twin_magnitudes=(0.75, 1.5, 2.5),
    root_load=_arm_swing_load,
)


def _friction_contact(pc, th, ctx):
    k = th["k"]
    pc = list(pc)
    for e in cv.ELLIPSOIDS:
        for n in ("mu_s", "mu_d"):
            i = _contact_idx(e, n)
            pc[i] = pc[i] * (1 + k)
    return pc


FRICTION = Effect(
    name="friction",
    title="foot–ground friction (stick/slip) coefficients",
    doc="""A different friction: the static and dynamic friction coefficients μ_s, μ_d of all
    six contact ellipsoids (Brown–McPhee continuous model, thesis Table 4.5,
    :func:`gaitlib.contact.friction_coefficient`) multiplied by (1 + k). With the thesis's
    identified coefficients (heel μ ≈ 0.17, toe ≈ 0.3, Table 4.18) friction limits the
    braking and propulsive GRF peaks, so k changes the attainable F_x / F_y.

    Parameters
    ----------
    k : relative change of μ_s and μ_d, 1; bounds [−0.6, 1.5]; null 0.
    """,
    params=(EffectParam("k", "1", -0.6, 1.5, 0.0, "relative friction change"),),
    twin_magnitudes=(-0.15, -0.3, -0.45),
    contact=_friction_contact,
)


def _foot_contact(pc, th, ctx):
    dx = th["dx"]
    pc = list(pc)
    for e in cv.ELLIPSOIDS:
        i = _contact_idx(e, "r_x")
        pc[i] = pc[i] + dx
    return pc


FOOT_CONTACT = Effect(
    name="foot_contact",
    title="foot contact geometry (centre of pressure) shift",
    doc="""The contact ellipsoids (toe, ball, heel) sit ``dx`` further forward (dx > 0) along
    the foot than identified (thesis Table 4.17; a child's foot and shoe differ from the
    scaled geometry). Moves the centre of pressure along the foot: the ankle moment of a
    given GRF changes by ≈ F_y dx in stance.

    Parameters
    ----------
    dx : shift of every ellipsoid centre along the foot (its r_x), m; bounds [−0.04, 0.04];
        null 0.
    """,
    params=(EffectParam("dx", "m", -0.04, 0.04, 0.0, "ellipsoid centres forward shift"),),
    twin_magnitudes=(0.005, 0.01, 0.02),
    contact=_foot_contact,
)


# ---- left leg: data generated from the right leg with an assumed time shift ----------

#: Left-leg reference channels that are generated from the right leg (name in the
#: transcription's data frame → stem of the data channel).
_LEFT_REFS = {"ref_hip_l": "hip", "ref_knee_l": "knee", "ref_ankle_l": "ankle",
              "ref_tau_hip_l": "tau_hip", "ref_tau_knee_l": "tau_knee", "ref_tau_ankle_l": "tau_ankle",
              "ref_grf_x_l": "grf_x", "ref_grf_y_l": "grf_y"}
FOURIER_ORDER = 5  # thesis Eqs 4.1–4.3 / gaitlib.data.fourier_shift


def _fourier_coefficients(x: np.ndarray, order: int = FOURIER_ORDER):
    """(c0, a_k, b_k) of the least-squares fit of gaitlib.data.fourier_shift (samples on
    t_j = j/(n−1), both ends included)."""
    x = np.asarray(x, float)
    t = np.linspace(0.0, 1.0, x.size)
    k = np.arange(1, order + 1)
    w = 2 * np.pi * np.outer(t, k)
    B = np.hstack([np.ones((t.size, 1)), np.cos(w), np.sin(w)])
    c = np.linalg.pinv(B) @ x
    return c[0], c[1:order + 1], c[order + 1:]


def _left_shift_columns(ref, tau_grid):
    """Per-node data: C_k(τ), S_k(τ) of each right-leg channel at τ + shift, so that the
    left leg at shift + δ is ref_l + Σ_k (cos 2πkδ − 1) C_k + sin 2πkδ S_k."""
    gait = ref.gait
    shift = float(gait.left_shift)
    out = {}
    for col, stem in _LEFT_REFS.items():
        _, a, b = _fourier_coefficients(gait.mean[f"{stem}_r"].to_numpy())
        for k in range(1, FOURIER_ORDER + 1):
            ph = 2 * np.pi * k * (np.asarray(tau_grid, float) + shift)
            out[f"fx.left_shift.C{k}.{col}"] = a[k - 1] * np.cos(ph) + b[k - 1] * np.sin(ph)
            out[f"fx.left_shift.S{k}.{col}"] = -a[k - 1] * np.sin(ph) + b[k - 1] * np.cos(ph)
    return out


def _left_shift_reference(d, th, ctx, t):
    delta = th["delta"]
    out = {}
    for col in _LEFT_REFS:
        v = d[col]
        for k in range(1, FOURIER_ORDER + 1):
            v = v + (ca.cos(2 * np.pi * k * delta) - 1) * d[f"fx.left_shift.C{k}.{col}"] \
                + ca.sin(2 * np.pi * k * delta) * d[f"fx.left_shift.S{k}.{col}"]
        out[col] = v
    return out


def regenerate_left(gait, shift: float, emg: bool | None = None):
    """``gait`` with its left-leg channels regenerated from the right leg at ``shift``
    (fraction of the cycle; :func:`gaitlib.data.fourier_shift`, order 5, on the data's own
    51-point grid as :func:`gaitlib.data.load_gait_data` does). EMG channels are
    regenerated only where the data's left EMG was itself generated (``emg=None``: detected
    by comparing with the right leg shifted by the data's own shift)."""
    import dataclasses

    mean, sd = gait.mean.copy(), gait.sd.copy()
    n = len(mean)
    for c in gait.mean.columns:
        if not c.endswith("_l"):
            continue
        cr = c[:-2] + "_r"
        if cr not in mean.columns:
            continue
        if c.startswith("emg_"):
            gen = emg
            if gen is None:
                test = data_mod.fourier_shift(gait.mean[cr].to_numpy(), gait.left_shift, FOURIER_ORDER)
                gen = bool(np.allclose(test, gait.mean[c].to_numpy(), atol=1e-9))
            if not gen:
                continue
        if c.startswith("mtp_"):
            continue
        mean[c] = data_mod.fourier_shift(gait.mean[cr].to_numpy(), shift, FOURIER_ORDER)
        sd[c] = np.abs(data_mod.fourier_shift(gait.sd[cr].to_numpy(), shift, FOURIER_ORDER))
    assert len(mean) == n
    return dataclasses.replace(gait, mean=mean, sd=sd, left_shift=float(shift),
                               notes=tuple(gait.notes) + (f"left leg regenerated at shift {shift:.4f}",))


def left_generated(gait) -> bool:
    """Whether ``gait``'s left-leg angles are the right leg's shifted by ``left_shift``
    (order-5 Fourier, as :func:`gaitlib.data.load_gait_data` generates them)."""
    for stem in ("hip", "knee", "ankle"):
        test = data_mod.fourier_shift(gait.mean[f"{stem}_r"].to_numpy(), gait.left_shift, FOURIER_ORDER)
        if not np.allclose(test, gait.mean[f"{stem}_l"].to_numpy(), atol=1e-9):
            return False
    return True


def _left_shift_adjust(gait, th):
    return regenerate_left(gait, float(gait.left_shift) + float(th["delta"]))


LEFT_SHIFT = Effect(
    name="left_shift",
    title="left/right asymmetry: the left leg's time shift",
    doc="""The public data (like the thesis's, Sec 4.2.3 and 6.2.3) have one leg; the left leg
    is the right leg shifted by T_sh = t_DSP + t_SSP (the opposite-foot-contact event,
    ≈ 50 % of the cycle; Eqs 4.1–4.3, order-5 Fourier fit). Real gait is not exactly
    symmetric: here the left leg lags by T_sh + δ·T.

    A data-model effect, not physics: the tracked left-leg references (angles, net torques,
    GRFs) become the right leg's order-5 Fourier series evaluated at τ + shift + δ — exact
    in δ inside the NLP (per-node Fourier terms C_k, S_k as data, cos/sin of 2πkδ
    symbolic) — and the gap of a solution with this effect is computed against the data
    with the left leg regenerated at shift + δ (:func:`regenerate_left`). The metatarsal
    and HAT references are not re-shifted.

    Applies only to data whose left leg *is* generated from the right one
    (:func:`left_generated`); for data with both legs measured it is not a candidate.

    Parameters
    ----------
    delta : extra left-leg lag, fraction of the cycle; bounds [−0.06, 0.06]; null 0.
    """,
    params=(EffectParam("delta", "cycle", -0.06, 0.06, 0.0, "extra left-leg time shift"),),
    twin_magnitudes=(0.01, 0.02, 0.03),
    reference=_left_shift_reference,
    columns=_left_shift_columns,
    data_adjust=_left_shift_adjust,
)


# ---- muscle level ---------------------------------------------------------------------

def _co_contraction_path(out, th, ctx):
    c = th["c"]
    ag = out["a_gen"]
    ex = []
    for s in cv.SIDES:
        for j in ("hip", "knee", "ankle"):
            e, f = ag[f"{j}_ext_{s}"], ag[f"{j}_flex_{s}"]
            ex += [f - c * e, e - c * f]
    return ca.vertcat(*ex)


CO_CONTRACTION = Effect(
    name="co_contraction",
    title="agonist–antagonist co-contraction",
    doc="""The MTGs of the thesis work without co-contraction (Secs 5.1, 5.3.1: "agonist and
    antagonist pairs of MTGs that have no co-contraction"); Sec 5.3.5 suspects that this is
    why the predicted ankle flexor (TA) excitation is below its EMG and the ankle extensor
    (GAM) above. Here each generator pair (hip, knee, ankle; both legs) must co-activate:
    a_flex ≥ c a_ext and a_ext ≥ c a_flex at every node (generator activations: MSK controls,
    NMSK Eq 5.54 from the muscles), i.e. a co-contraction index of at least c.

    Its signature is muscle-level only (the net torques are unchanged by construction), and
    the thesis's cost functions penalise activation, so an NLP would set c = 0: c is
    identified by profiling the located gap (EMG channels) over fixed values
    (``identify="profile"``), as Sec 8.2 proposes ("tune them using an
    experimental-data-tracking parameter identification").

    Parameters
    ----------
    c : minimum antagonist/agonist activation ratio, 1; bounds [0, 0.9]; null 0.
    """,
    params=(EffectParam("c", "1", 0.0, 0.9, 0.0, "minimum co-activation ratio"),),
    models=("MSK", "NMSK"),
    signature="emg",
    identify="profile",
    twin_magnitudes=(0.1, 0.2, 0.35),
    path=_co_contraction_path,
)


def _joint_stiffness_body(pb, th, ctx):
    k = th["k"]
    pb = list(pb)
    for j in ("hip", "knee", "ankle"):
        for pre in ("K", "B"):
            i = _idx(f"{pre}_{j}")
            pb[i] = pb[i] * (1 + k)
    return pb


JOINT_STIFFNESS = Effect(
    name="joint_stiffness",
    title="child-specific joint stiffness and damping",
    doc="""The joints' passive spring–dampers (thesis Table 4.2: K, B of hip, knee, ankle) are
    adult values (Sec 4.4); a child's joints are more compliant or stiffer. K and B of the
    hip, knee and ankle (both legs) are multiplied by (1 + k).

    The data's joint moments are *net* moments (actuator + passive = inverse dynamics), so
    k cannot show in angles, torques or GRFs of any model; it changes how much the
    actuators must supply — visible in MSK/NMSK activations against EMG. Identified by
    profiling (see ``co_contraction``).

    Parameters
    ----------
    k : relative change of K and B, 1; bounds [−0.9, 4]; null 0.
    """,
    params=(EffectParam("k", "1", -0.9, 4.0, 0.0, "relative joint K and B change"),),
    models=("MSK", "NMSK"),
    signature="emg",
    identify="profile",
    twin_magnitudes=(1.0, 2.0, 3.0),
    body=_joint_stiffness_body,
)


def _activation_timing_adjust(gait, th):
    """EMG delayed by Δd: compared at t, the data's EMG at t − Δd (periodic)."""
    import dataclasses

    dd = float(th["dd"])
    if dd == 0.0:
        return gait
    T = float(gait.cycle_time)
    t = gait.time
    mean, sd = gait.mean.copy(), gait.sd.copy()
    for c in gait.mean.columns:
        if c.startswith("emg_"):
            for frame, src in ((mean, gait.mean), (sd, gait.sd)):
                y = src[c].to_numpy()
                # periodic samples 0..T with a repeated end point
                frame[c] = np.interp(np.mod(t - dd, T), t, y)
    return dataclasses.replace(gait, mean=mean, sd=sd, notes=tuple(gait.notes) + (f"EMG delayed by {dd:.3f} s",))


ACTIVATION_TIMING = Effect(
    name="activation_timing",
    title="activation timing (electromechanical delay)",
    doc="""The NMSK model's electromechanical delay is d = 50 ms (thesis Eq 5.34) and the MSK
    activations act instantly; a child's delay between EMG and force may differ. With an
    extra delay Δd the force a muscle makes at t follows the EMG at t − Δd: the model's
    excitation (NMSK) or generator activation (MSK) at t is compared with the data's EMG at
    t − Δd (periodic).

    A comparison-only effect: the optimal motion does not change (``resolve=False``), Δd is
    fitted on the EMG channels of the baseline solution.

    Parameters
    ----------
    dd : extra electromechanical delay, s; bounds [−0.1, 0.1]; null 0.
    """,
    params=(EffectParam("dd", "s", -0.1, 0.1, 0.0, "extra electromechanical delay"),),
    models=("MSK", "NMSK"),
    signature="emg",
    resolve=False,
    identify="profile",
    twin_magnitudes=(0.02, 0.04, 0.07),
    data_adjust=_activation_timing_adjust,
)


# ---- laboratory effects: how the data were measured and processed ---------------------
#
# Data-model effects like ``left_shift``: the motion is the model's, the *data* are read
# differently. Each changes the tracked references inside the NLP (``reference``) and, for
# the gap of its solution, the data the same way (``data_adjust``); the SDs are left as
# they are (they describe the subjects' spread, not the error). The left/right step-time
# asymmetry of a laboratory is ``left_shift`` (an extra lag of the left leg).

#: Vertical force (N) above which a foot counts as on the force plate (a typical plate
#: threshold; :data:`GRF_AP_BIAS` acts only there, as a plate's offset is zeroed in swing).
PLATE_THRESHOLD_N = 10.0


def _replace_gait(gait, mean, note, sd=None):
    import dataclasses

    extra = {} if sd is None else {"sd": sd}
    return dataclasses.replace(gait, mean=mean, notes=tuple(gait.notes) + (note,), **extra)


def _offset_reference(joint):
    def reference(d, th, ctx, t):
        return {f"ref_{joint}_{s}": d[f"ref_{joint}_{s}"] - th["c"] for s in cv.SIDES}

    return reference


def _offset_adjust(joint):
    def adjust(gait, th):
        c = float(th["c"])
        if c == 0.0:
            return gait
        mean = gait.mean.copy()
        for s in cv.SIDES:
            mean[f"{joint}_{s}"] = mean[f"{joint}_{s}"] - c
        return _replace_gait(gait, mean, f"{joint} angle offset {c:+.4f} rad removed")

    return adjust


def _angle_offset(joint: str, label: str) -> Effect:
    return Effect(
        name=f"{joint}_offset",
        title=f"{label} angle offset (marker placement)",
        doc=f"""A constant offset of the measured {label} angle: markers placed a little off the
    anatomical landmarks (or a joint centre estimated off) shift a joint angle by a roughly
    constant amount over the cycle (Della Croce et al. 2005 report several degrees). The data
    are read as the true angle plus c: the NLP tracks the data's {label} angle minus c (both
    legs: the public data's left leg is generated from the right one, so it carries the same
    offset), and the gap of its solution is computed against the data minus c.

    A data-model effect (no physics changes); its null value c = 0 is the baseline. The
    offset is in the model's sign convention for the {label} coordinate
    (:data:`gaitlib.conventions.DATA_SIGN`: the data's {label} angle times
    {cv.DATA_SIGN[joint]:+g}).

    Parameters
    ----------
    c : offset of the measured {label} angle, rad (model convention); bounds [−0.26, 0.26]
        (±15°); null 0.
    """,
        params=(EffectParam("c", "rad", -0.26, 0.26, 0.0, f"{label} angle offset"),),
        twin_magnitudes=(0.035, 0.07, 0.14),
        reference=_offset_reference(joint),
        data_adjust=_offset_adjust(joint),
    )


HIP_OFFSET = _angle_offset("hip", "hip")
KNEE_OFFSET = _angle_offset("knee", "knee")
ANKLE_OFFSET = _angle_offset("ankle", "ankle")

_GRF_REFS = tuple(f"grf_{a}_{s}" for s in cv.SIDES for a in ("x", "y"))


def _grf_scale_reference(d, th, ctx, t):
    out = {f"ref_{g}": d[f"ref_{g}"] / (1 + th["s"]) for g in _GRF_REFS}
    # the SD-standardised fit (gaitlib.gap.solve): the SD is the gain's too
    out.update({f"sd_{g}": d[f"sd_{g}"] / (1 + th["s"]) for g in _GRF_REFS if f"sd_{g}" in d})
    return out


def _grf_scale_adjust(gait, th):
    s = float(th["s"])
    if s == 0.0:
        return gait
    mean, sd = gait.mean.copy(), gait.sd.copy()
    for g in _GRF_REFS:
        mean[g] = mean[g] / (1 + s)
        sd[g] = sd[g] / (1 + s)
    return _replace_gait(gait, mean, f"force-plate gain {1 + s:.4f} removed (mean and SD)", sd=sd)


GRF_SCALE = Effect(
    name="grf_scale",
    title="force-plate gain (calibration)",
    doc="""A force plate whose calibration is off by a factor reports (1 + s) times the true
    ground reaction force. The NLP tracks the data's GRFs divided by (1 + s) (both
    components, both feet), and the gap of its solution is computed against the data so
    corrected. The data's joint moments are left as published: a laboratory's inverse
    dynamics would carry part of the gain into them, which this effect does not model.

    The gain scales every child's force, so the data's SD too: the corrected data are
    mean/(1 + s) ± SD/(1 + s), and the standardised residual of a GRF channel is
    ((1 + s)·sim − mean)/SD — the same data on the same scale as the baseline's residual
    (sim − mean)/SD. (Version 2; version 1 divided the mean only, so a gain s > 0 shrank
    every GRF residual by 1/(1 + s) whatever the cause of the misfit — a gain that
    "closed" part of any gap in which the model's forces fall short of the data's.) Under the spec's own cost function
    (``objective="cost"``) the GRF tracking term's normalising range is the spec's and is
    not rescaled.

    A data-model effect; its null value s = 0 is the baseline.

    Parameters
    ----------
    s : relative gain error of the plates, 1; bounds [−0.2, 0.2]; null 0.
    """,
    params=(EffectParam("s", "1", -0.2, 0.2, 0.0, "relative force-plate gain error"),),
    twin_magnitudes=(0.03, 0.06, 0.1),
    reference=_grf_scale_reference,
    data_adjust=_grf_scale_adjust,
    version="2",
)


def _on_plate(gait) -> dict:
    """Per side, 1 where the foot is on the plate (vertical force above
    :data:`PLATE_THRESHOLD_N`), else 0, on the data's grid. A left leg generated from the
    right one (:func:`left_generated`) gets the right leg's indicator through the same
    order-5 Fourier shift (so its bias is what the generation made of the right leg's)."""
    on = {s: (gait.mean[f"grf_y_{s}"].to_numpy(float) > PLATE_THRESHOLD_N).astype(float) for s in cv.SIDES}
    if left_generated(gait):
        on["l"] = data_mod.fourier_shift(on["r"], gait.left_shift, FOURIER_ORDER)
    return on


def _grf_ap_bias_columns(ref, tau_grid):
    gait = ref.gait
    t = np.linspace(0.0, 1.0, len(gait.mean))
    return {f"fx.grf_ap_bias.on_{s}": np.interp(np.mod(np.asarray(tau_grid, float), 1.0), t, v)
            for s, v in _on_plate(gait).items()}


def _grf_ap_bias_reference(d, th, ctx, t):
    return {f"ref_grf_x_{s}": d[f"ref_grf_x_{s}"] - th["b"] * d[f"fx.grf_ap_bias.on_{s}"] for s in cv.SIDES}


def _grf_ap_bias_adjust(gait, th):
    b = float(th["b"])
    if b == 0.0:
        return gait
    mean = gait.mean.copy()
    for s, on in _on_plate(gait).items():
        mean[f"grf_x_{s}"] = mean[f"grf_x_{s}"] - b * on
    return _replace_gait(gait, mean, f"force-plate AP bias {b:+.3f} N removed")


GRF_AP_BIAS = Effect(
    name="grf_ap_bias",
    title="force-plate anterior–posterior bias",
    doc=f"""A force plate whose anterior–posterior channel has an offset (zero drift, cross-talk
    from the vertical channel at rest) adds a constant b to the AP force while the foot is
    on the plate (vertical force above {PLATE_THRESHOLD_N:g} N, :data:`PLATE_THRESHOLD_N`;
    in swing the plate is zeroed by processing). The NLP tracks the data's AP force minus b
    in stance (both feet; the stance indicator comes from the data's own vertical force, and
    for a left leg generated from the right one it is the right leg's indicator shifted by
    the same order-5 Fourier fit), and the gap of its solution is computed against the data
    so corrected.

    A data-model effect; its null value b = 0 is the baseline.

    Parameters
    ----------
    b : AP force offset in stance, N (+ forward, the model's x); bounds [−20, 20]; null 0.
    """,
    params=(EffectParam("b", "N", -20.0, 20.0, 0.0, "AP force offset in stance"),),
    twin_magnitudes=(4.0, 8.0, 16.0),
    reference=_grf_ap_bias_reference,
    columns=_grf_ap_bias_columns,
    data_adjust=_grf_ap_bias_adjust,
)


#: The registry of candidate effects by name.
EFFECTS: dict[str, Effect] = {e.name: e for e in (
    SEGMENT_INERTIA, BODY_MASS, HAT_COM, ARM_SWING, FRICTION, FOOT_CONTACT, LEFT_SHIFT,
    CO_CONTRACTION, JOINT_STIFFNESS, ACTIVATION_TIMING,
    HIP_OFFSET, KNEE_OFFSET, ANKLE_OFFSET, GRF_SCALE, GRF_AP_BIAS)}

#: The laboratory (measurement and processing) effects: how the data were recorded, not
#: what the body does.
LAB_EFFECTS = ("hip_offset", "knee_offset", "ankle_offset", "grf_scale", "grf_ap_bias")
#: The model effects: what the body does that the model lacks (and ``left_shift``, how the
#: public data's left leg was made).
MODEL_EFFECTS = tuple(n for n in EFFECTS if n not in LAB_EFFECTS)

#: Effects validated on twins of the SK model: those of physics whose signature lies in the
#: angles, torques and GRFs. (``left_shift`` concerns data whose left leg is generated from
#: the right one; twins carry both legs, see :mod:`gaitlib.gap.twin`.)
TWIN_EFFECTS = tuple(n for n, e in EFFECTS.items() if "SK" in e.models and e.data_adjust is None)


# ======================================================================================
# Binding effects to a problem (used by gaitlib.problems.gait.build / postprocess)
# ======================================================================================

def validate(effects, model: str) -> tuple:
    """Check ``GaitSpec.effects``: a tuple of ``(name, magnitude or None)`` pairs with known,
    distinct names applicable to ``model``; magnitudes within the magnitude's bounds.
    Returns the normalised tuple (names str, magnitudes float or None)."""
    out, seen = [], set()
    for item in effects:
        if not (isinstance(item, (tuple, list)) and len(item) == 2):
            raise ValueError(f"effects must be (name, magnitude or None) pairs, got {item!r}")
        name, mag = item
        if name not in EFFECTS:
            raise ValueError(f"unknown effect {name!r}; known: {sorted(EFFECTS)}")
        if name in seen:
            raise ValueError(f"effect {name!r} given twice")
        seen.add(name)
        eff = EFFECTS[name]
        if model not in eff.models:
            raise ValueError(f"effect {name!r} applies to models {eff.models}, not {model!r}")
        if mag is not None:
            mag = float(mag)
            p = eff.magnitude
            if not (p.lower <= mag <= p.upper) or not math.isfinite(mag):
                raise ValueError(f"effect {name!r}: magnitude {mag} outside [{p.lower}, {p.upper}] {p.unit}")
        out.append((str(name), mag))
    return tuple(out)


@dataclass
class Bound:
    """Effects of a spec bound to a built problem: their NLP parameters and hooks."""

    items: list  # [(Effect, magnitude or None)]
    ctx: Context
    parameters: list = field(default_factory=list)  # ocp.Parameter

    def theta(self, eff: Effect, mag, p=None) -> dict:
        """Parameter values of ``eff``: NLP symbols from ``p`` (free) or numbers (fixed)."""
        if mag is None:
            if p is None:
                raise ValueError("free effect parameters need the NLP parameters")
            return {q.name: p[f"fx.{eff.name}.{q.name}"] for q in eff.params}
        th = eff.null_theta()
        th[eff.magnitude.name] = float(mag)
        return th

    def body(self, pb, p):
        items = [(e, m) for e, m in self.items if e.body is not None]
        if not items:
            return pb
        v = [pb[i] for i in range(pb.shape[0])]
        for e, m in items:
            v = e.body(v, self.theta(e, m, p), self.ctx)
        return ca.vertcat(*v)

    def contact(self, pc, p):
        items = [(e, m) for e, m in self.items if e.contact is not None]
        if not items:
            return pc
        v = [pc[i] for i in range(pc.shape[0])]
        for e, m in items:
            v = e.contact(v, self.theta(e, m, p), self.ctx)
        return ca.vertcat(*v)

    def root_load(self, x, p):
        """Extra root wrench (3,) the HAT/residual equations must supply, or None."""
        total = None
        for e, m in self.items:
            if e.root_load is not None:
                w = e.root_load(x, self.theta(e, m, p), self.ctx)
                total = w if total is None else total + w
        return total

    def wrap_data(self, d, p, t):
        """The per-node data ``d`` with references overridden by effects (left_shift)."""
        over = {}
        for e, m in self.items:
            if e.reference is not None:
                over.update(e.reference(d, self.theta(e, m, p), self.ctx, t))
        return _DataView(d, over) if over else d


class _DataView:
    """A :class:`gaitlib.ocp.Named`-like view of per-node data with some names overridden."""

    def __init__(self, d, over: dict):
        self._d, self._over = d, over

    def __getitem__(self, key):
        if isinstance(key, str) and key in self._over:
            return self._over[key]
        return self._d[key]

    def __contains__(self, key):
        return key in self._over or key in self._d


def bind(spec, ctx: Context) -> Bound:
    """Bind ``spec.effects`` to a problem: NLP parameters for free effects (``fx.<effect>.
    <param>`` within the parameter's bounds, starting at its null value)."""
    items = [(EFFECTS[n], m) for n, m in validate(spec.effects, spec.model)]
    # an effect fixed at its null value is the baseline model: leave it out entirely, so the
    # NLP is the baseline's (not merely equal in value)
    items = [(e, m) for e, m in items if not (m is not None and m == e.magnitude.null and e.n_params == 1)]
    params = []
    for e, m in items:
        if m is None:
            for q in e.params:
                params.append(Parameter(f"fx.{e.name}.{q.name}", float(q.lower), float(q.upper), float(q.null)))
    return Bound(items, ctx, params)


def data_columns(spec, ref, tau_grid) -> dict:
    """Extra per-node data columns the spec's effects need (left_shift: Fourier terms)."""
    out = {}
    for n, _ in spec.effects:
        e = EFFECTS[n]
        if e.columns is not None:
            out.update(e.columns(ref, tau_grid))
    return out


def theta_of(spec, parameters: dict | None = None) -> dict:
    """Numeric parameter values of every effect of ``spec``: fixed magnitudes, or the
    identified values from a solution's ``parameters`` (``fx.<effect>.<param>``)."""
    out = {}
    for n, m in spec.effects:
        e = EFFECTS[n]
        if m is None:
            if parameters is None:
                raise ValueError(f"effect {n!r} is free: pass the solution's parameters")
            out[n] = {q.name: float(parameters[f"fx.{n}.{q.name}"]) for q in e.params}
        else:
            th = e.null_theta()
            th[e.magnitude.name] = float(m)
            out[n] = th
    return out


def adjust_data(gait, thetas: dict):
    """The data as compared with a solution whose effects have parameter values ``thetas``
    (effect → {param: value}): data-model effects applied (left_shift, activation_timing)."""
    for n, th in thetas.items():
        e = EFFECTS[n]
        if e.data_adjust is not None:
            gait = e.data_adjust(gait, th)
    return gait


def numeric_body_contact(spec, ctx: Context, parameters: dict, pb, pc):
    """p_body and p_contact (numpy) with the spec's effects applied at the solution's
    parameter values (for post-processing)."""
    th = theta_of(spec, parameters)
    pb, pc = list(np.asarray(pb, float)), list(np.asarray(pc, float))
    for n, _ in spec.effects:
        e = EFFECTS[n]
        if e.body is not None:
            pb = e.body(pb, th[n], ctx)
        if e.contact is not None:
            pc = e.contact(pc, th[n], ctx)
    return np.array([float(v) for v in pb]), np.array([float(v) for v in pc])


def formulation_versions(effects) -> tuple[str, ...]:
    """The formulation versions a solve with ``effects`` ((name, magnitude), …) adds to its
    cache key: ``"effect:<name>-<version>"`` for each effect with a :attr:`Effect.version`
    (none for an effect in its first formulation, so those keys stay)."""
    return tuple(f"effect:{n}-{EFFECTS[n].version}" for n in sorted({n for n, _ in effects}) if EFFECTS[n].version)
