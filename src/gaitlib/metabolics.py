"""Metabolic energy rate of the MTG-based NMSK model and cost of transport (thesis Sec 5.3.3).

The thesis adapts Bhargava et al. 2004 to muscle torque generators: the total rate is
(Eq 5.38)::

    Ė = Σ_muscles (Ȧ + Ṁ + Ḃ) + Σ_generators Ṡ + Σ_joints Ẇ        (W)

- activation heat  Ȧ = φ m (f_fast 133 e_fast + f_slow 40 e_slow)            (5.39)
  with φ = 0.06 + exp(−t_stim e / τ_φ), τ_φ = 45 ms (5.40),
  e_fast = 1 − cos(π e / 2), e_slow = sin(π e / 2) (5.43, 5.44);
- maintenance heat Ṁ = m (f_fast 111 e_fast + f_slow 74 e_slow)              (5.45)
- basal            Ḃ = 0.0225 m                                             (5.48)
- shortening heat  Ṡ per generator, from its torque τ^M ≥ 0 and fibre speed ω_f (Eq 5.47)
- work rate        Ẇ = τ q̇ per joint, net MTG torque (and torque-driven mtp joints) (5.50)

with muscle mass m = ρ PCSA l_opt, ρ = 1060 kg/m³ (5.41) and the child's l_opt, PCSA and
f_fast of Tables 5.6–5.8 (:data:`MUSCLE_TABLE`). Units: W, kg, s, rad, N·m.

Sign of the shortening heat (Eq 5.47)
-------------------------------------
Bhargava: Ṡ = −α v_CE, α = 0.16 F0 + 0.18 F when shortening (v_CE ≤ 0), α = 0.157 F when
lengthening (v_CE > 0): positive heat in concentric, negative in eccentric work (as in
OpenSim's Bhargava probe). The thesis's MTG version writes −(…)θ̇ with the concentric case
τθ̇ ≥ 0; taken literally with τ^M ≥ 0 that would make concentric heat negative. Here the
generator's fibre velocity ω_f (> 0 shortening, :func:`gaitlib.mtg.fibre_kinematics`) plays
−v_CE: Ṡ = α ω_f with α = 0.16 s^τ τ0 + 0.18 τ^M for ω_f ≥ 0 and 0.157 τ^M for ω_f < 0
(the sign the thesis's own case split and Bhargava imply). The switch is smoothed with
tanh(ω_f / ω_s) (ω_s = 0.01 rad/s by default); since Ṡ ∝ ω_f it is continuous anyway.

Negative totals
---------------
Negative (eccentric) work and heat can make Ė < 0, which is not physical. As OpenSim's
``forbid_negative_total_power`` does, the non-basal part is clipped at zero with a smooth
max: Ė = ΣḂ + smax(Σ(Ȧ + Ṁ) + ΣṠ + ΣẆ), smax(x) = ½(x + √(x² + ε²)) − ε/2 (ε = 0.1 W),
so Ė = ΣḂ exactly at rest and Ė ≥ ΣḂ − ε/2. ``forbid_negative=False`` gives the thesis's
plain sum.

Caveat (RBDL's own note on torque generators)
---------------------------------------------
An MTG has no tendon and no fibre: its "work" is the joint's net work, the shortening
heat uses joint angular velocity for fibre velocity and joint torque for fibre force, and
activation/maintenance heats use lumped muscle masses. Work and heat estimates from MTGs
are approximations; state this next to every COT figure.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, NamedTuple

import casadi as ca
import numpy as np

from gaitlib.activation import EXCITATIONS, generator_activations
from gaitlib.conventions import BODY_HEIGHT, BODY_MASS, SIDES
from gaitlib.mtg import TORQUE_SIGN, fibre_kinematics, generator_torque

__all__ = [
    "RHO",
    "MUSCLE_TABLE",
    "MuscleData",
    "muscle_mass",
    "decay_factor",
    "activation_heat_rate",
    "maintenance_heat_rate",
    "basal_rate",
    "shortening_heat_rate",
    "work_rate",
    "metabolic_rate",
    "nmsk_metabolic_rate",
    "stimulation_time",
    "cost_of_transport",
]

#: Muscle density, kg/m³ (thesis Eq 5.41).
RHO = 1060.0
A_FAST, A_SLOW = 133.0, 40.0  # activation heat constants, W/kg (Eq 5.39)
M_FAST, M_SLOW = 111.0, 74.0  # maintenance heat constants, W/kg (Eq 5.45)
B_RATE = 0.0225  # basal rate per muscle mass, W/kg (Eq 5.48)
TAU_PHI = 0.045  # decay time constant, s (Eq 5.40)


class MuscleData(NamedTuple):
    """Child muscle data (thesis Tables 5.6–5.8), SI."""

    l_opt: float  #: optimal fibre length, m (Table 5.6)
    pcsa: float  #: physiological cross-sectional area, m² (Table 5.7)
    f_fast: float  #: mass fraction of fast-twitch fibres (Table 5.8)

    @property
    def mass(self) -> float:
        """m = ρ PCSA l_opt, kg (Eq 5.41)."""
        return RHO * self.pcsa * self.l_opt


#: Tables 5.6 (l_opt cm → m), 5.7 (PCSA cm² → m²), 5.8 (f_fast % → fraction).
MUSCLE_TABLE: dict[str, MuscleData] = {
    m: MuscleData(l * 1e-2, p * 1e-4, f * 1e-2)
    for m, l, p, f in [
        ("GM", 12.39, 9.53, 45),
        ("RF", 10.32, 20.68, 65),
        ("VM", 8.14, 32.02, 50),
        ("BF", 12.66, 8.51, 35),
        ("SOL", 4.16, 89.28, 20),
        ("PL", 3.92, 24.20, 50),
        ("GAM", 5.03, 11.79, 19),
        ("TA", 7.99, 8.09, 25),
    ]
}


def _is_ca(*xs) -> bool:
    return any(isinstance(x, (ca.SX, ca.MX, ca.DM)) for x in xs)


def _fn(name, *xs):
    return getattr(ca if _is_ca(*xs) else np, name)


def _muscle(name: str) -> MuscleData:
    base = name
    for s in SIDES:
        if name.endswith("_" + s):
            base = name[: -len(s) - 1]
    return MUSCLE_TABLE[base]


def muscle_mass(muscle: str) -> float:
    """Muscle mass m = ρ PCSA l_opt, kg (Eq 5.41); ``'SOL'`` or ``'SOL_r'``."""
    return _muscle(muscle).mass


def decay_factor(e, t_stim=0.0):
    """φ = 0.06 + exp(−t_stim e / τ_φ) (Eq 5.40), 1; t_stim in s (0 → φ = 1.06)."""
    return 0.06 + _fn("exp", e, t_stim)(-t_stim * e / TAU_PHI)


def _recruit(e):
    c, s = _fn("cos", e), _fn("sin", e)
    return 1.0 - c(0.5 * math.pi * e), s(0.5 * math.pi * e)  # e_fast, e_slow (5.43–5.44)


def activation_heat_rate(muscle: str, e, t_stim=0.0):
    """Activation heat rate Ȧ of one muscle, W (Eqs 5.39, 5.40, 5.43, 5.44).

    Parameters
    ----------
    muscle : one of :data:`gaitlib.activation.MUSCLES` (side suffix accepted).
    e : excitation in [0, 1] (float, ndarray or CasADi).
    t_stim : time the muscle is excited above 10 % of its maximum, s (thesis: one value
        per muscle and cycle, :func:`stimulation_time`); default 0 (φ = 1.06).
    """
    d = _muscle(muscle)
    e_fast, e_slow = _recruit(e)
    return decay_factor(e, t_stim) * d.mass * (
        d.f_fast * A_FAST * e_fast + (1.0 - d.f_fast) * A_SLOW * e_slow
    )


def maintenance_heat_rate(muscle: str, e):
    """Maintenance heat rate Ṁ of one muscle, W (Eq 5.45; length dependence ignored)."""
    d = _muscle(muscle)
    e_fast, e_slow = _recruit(e)
    return d.mass * (d.f_fast * M_FAST * e_fast + (1.0 - d.f_fast) * M_SLOW * e_slow)


def basal_rate(muscle: str) -> float:
    """Basal rate Ḃ = 0.0225 W/kg × m of one muscle, W (Eq 5.48)."""
    return B_RATE * _muscle(muscle).mass


def shortening_heat_rate(tau_m, omega_f, tau_max, omega_smooth: float = 0.01, *, sign: str = "bhargava",
                         split: str = "fibre"):
    """Shortening heat rate Ṡ of one generator, W (Eq 5.47, sign as in the module doc).

    Parameters
    ----------
    tau_m : generator torque τ^M ≥ 0 (its own frame), N·m.
    omega_f : fibre angular velocity, rad/s, > 0 shortening (concentric).
    tau_max : isometric torque term, N·m: s^τ τ0 in the thesis's Eq 5.47 (Bhargava's
        F_iso is the isometric force at the current activation and length instead).
    omega_smooth : ω_s of the tanh switch between the two cases, rad/s (0 → exact switch).
    sign : {'bhargava', 'printed'}
        'bhargava' (default, what the NLPs use): α ω_f, heat ≥ 0 when shortening.
        'printed': Eq 5.47 as printed, −α θ̇ with θ̇ ≡ ω_f, i.e. the negative of the default.
    split : {'fibre', 'printed'}
        'fibre' (default): concentric case where ω_f ≥ 0 (tanh-smoothed). 'printed': Eq 5.47's
        τ^M θ̇ ≥ 0, which differs only where τ^M = 0: there the concentric case applies
        even when lengthening (0.16 τ_max ω_f instead of 0.157 × 0 × ω_f = 0).

    Returns
    -------
    α ω_f, α = 0.16 τ_max + 0.18 τ^M (ω_f ≥ 0) or 0.157 τ^M (ω_f < 0): ≥ 0 concentric,
    ≤ 0 eccentric (defaults; the opposite signs with ``sign='printed'``).
    """
    alpha_c = 0.16 * tau_max + 0.18 * tau_m
    alpha_e = 0.157 * tau_m
    if omega_smooth > 0:
        s = 0.5 * (1.0 + _fn("tanh", omega_f)(omega_f / omega_smooth))
    else:
        s = (omega_f >= 0) * 1.0 if _is_ca(omega_f) else np.where(np.asarray(omega_f) >= 0, 1.0, 0.0)
    if split == "printed":  # τ^M θ̇ ≥ 0 with τ^M ≥ 0: concentric wherever τ^M = 0
        s = ca.if_else(tau_m <= 0, 1.0, s) if _is_ca(tau_m, s) else np.where(np.asarray(tau_m) <= 0, 1.0, s)
    elif split != "fibre":
        raise ValueError("split must be 'fibre' or 'printed'")
    out = (s * alpha_c + (1.0 - s) * alpha_e) * omega_f
    if sign == "printed":
        return -out
    if sign != "bhargava":
        raise ValueError("sign must be 'bhargava' or 'printed'")
    return out


def work_rate(tau, qd):
    """Mechanical work rate of a joint, W (Eq 5.50): τ q̇, net joint torque (model
    convention, N·m) × joint velocity (rad/s); > 0 when the joint generates power."""
    return tau * qd


def smooth_max0(x, eps):
    """max(x, 0) smoothed: ½(x + √(x² + ε²)) − ε/2 (0 at x = 0; x − ε/2 for x ≫ ε), numpy or
    CasADi; the clipping of negative totals (Eq 5.38) and of the Mtb term's rate."""
    sq = _fn("sqrt", x)
    return 0.5 * (x + sq(x * x + eps * eps)) - 0.5 * eps


def metabolic_rate(
    excitations,
    generator_torques,
    generator_speeds,
    generator_tau_max,
    joint_torques,
    joint_speeds,
    *,
    t_stim=0.0,
    omega_smooth: float = 0.01,
    forbid_negative: bool = True,
    eps: float = 0.1,
    body_mass: float = BODY_MASS,
    shortening_sign: str = "bhargava",
    shortening_split: str = "fibre",
    basal_whole_body: float | None = None,
) -> dict[str, Any]:
    """Total metabolic rate Ė (thesis Eq 5.38) from per-muscle, per-generator and per-joint
    quantities at one instant (or elementwise over time samples).

    Parameters
    ----------
    excitations : mapping muscle name (``'GM_r'`` …, :data:`EXCITATIONS`) → excitation
        (float/array/CasADi). Muscles may be omitted (no heat, but basal still counted
        only for those given).
    generator_torques, generator_speeds, generator_tau_max : mappings generator name
        (``'hip_ext_r'`` …) → τ^M ≥ 0 (N·m), ω_f (rad/s, > 0 shortening), s^τ τ0 (N·m).
    joint_torques, joint_speeds : mappings joint name → net torque (N·m, model
        convention) and velocity (rad/s); include torque-driven mtp joints here.
    t_stim : float or mapping muscle → t_stim (s), see :func:`activation_heat_rate`.
    forbid_negative, eps : smooth clipping of the non-basal part (module docstring);
        ``forbid_negative=False`` is Eq 5.38's plain sum.
    body_mass : kg, for the per-kg rate (and the whole-body basal rate).
    shortening_sign, shortening_split : ``sign`` and ``split`` of
        :func:`shortening_heat_rate` (defaults: Bhargava's sign, split on ω_f).
    basal_whole_body : None (default) → Eq 5.48, 0.0225 W/kg × the given muscles' mass;
        a number c (W/kg) → c × ``body_mass`` for the whole body (OpenSim's Bhargava probe:
        ``basal_coefficient`` 1.2 W/kg).

    Returns
    -------
    dict with ``'total'`` (W), ``'per_kg'`` (W/kg) and the summed components
    ``'activation'``, ``'maintenance'``, ``'basal'``, ``'shortening'``, ``'work'`` (W).
    """
    A = M = S = W = 0.0
    B = 0.0
    for m, e in excitations.items():
        ts = t_stim[m] if isinstance(t_stim, Mapping) else t_stim
        A = A + activation_heat_rate(m, e, ts)
        M = M + maintenance_heat_rate(m, e)
        B = B + basal_rate(m)
    if basal_whole_body is not None:
        B = basal_whole_body * body_mass
    for g, tq in generator_torques.items():
        S = S + shortening_heat_rate(tq, generator_speeds[g], generator_tau_max[g], omega_smooth,
                                     sign=shortening_sign, split=shortening_split)
    for j, tq in joint_torques.items():
        W = W + work_rate(tq, joint_speeds[j])
    rest = A + M + S + W
    total = B + (smooth_max0(rest, eps) if forbid_negative else rest)
    return {
        "total": total,
        "per_kg": total / body_mass,
        "activation": A,
        "maintenance": M,
        "basal": B,
        "shortening": S,
        "work": W,
    }


def nmsk_metabolic_rate(
    q,
    qd,
    excitations,
    activations=None,
    params=None,
    *,
    s1: float = 0.25,
    s2: float = 0.25,
    mtp_torques=None,
    t_stim=0.0,
    use_active_torque: bool = False,
    isometric_torque: str = "thesis",
    body_mass: float = BODY_MASS,
    body_height: float = BODY_HEIGHT,
    **kw,
) -> dict[str, Any]:
    """Metabolic rate of the 12-MTG NMSK model from joint kinematics and muscle states.

    Parameters
    ----------
    q, qd : mappings joint name (``'hip_r'``, …, ``'mtp_l'``) → angle (rad) and velocity
        (rad/s), model convention; hip/knee/ankle of both sides are required, mtp only
        with ``mtp_torques``.
    excitations : mapping of the 16 :data:`EXCITATIONS` → excitation in [0, 1], or a
        length-16 sequence/CasADi vector in that order.
    activations : same layout, muscle activations (drive the MTGs through Eq 5.54);
        None → use the excitations (quasi-static).
    params : MTG fitting parameters (see :func:`gaitlib.mtg.generator_torque`).
    s1, s2 : ankle-extensor synergy weights (Eq 5.54; thesis identified 0.25, 0.25).
    mtp_torques : mapping ``'mtp_r'``/``'mtp_l'`` → torque (N·m), torque-driven joints'
        work rate (Eq 5.50, second case).
    use_active_torque : use only the active generator torque in the shortening heat
        (Bhargava's contractile-element force) instead of the thesis's total τ^M.
    isometric_torque : {'thesis', 'bhargava'}
        The "F_iso" of the concentric shortening heat. 'thesis' (Eq 5.47 as printed):
        s^τ τ0, the maximum isometric torque, so a relaxed generator that shortens still
        produces 0.16 s^τ τ0 ω_f of heat. 'bhargava' (Bhargava 2004 / OpenSim): the
        isometric torque at the current activation and angle, a s^τ τ0 t^A(θ).
    **kw : passed to :func:`metabolic_rate` (``omega_smooth``, ``forbid_negative``, ``eps``,
        ``shortening_sign``, ``shortening_split``, ``basal_whole_body``).

    Returns
    -------
    dict as :func:`metabolic_rate`, plus ``'generator_torques'`` (N·m, ≥ 0).
    """

    def as_map(x):
        if x is None:
            return None
        if isinstance(x, Mapping):
            return dict(x)
        return {n: x[i] for i, n in enumerate(EXCITATIONS)}

    ex = as_map(excitations)
    act = as_map(activations) if activations is not None else ex
    gt, gs, gm, jt, js = {}, {}, {}, {}, {}
    for side in SIDES:
        a_gen = generator_activations(act, s1, s2, side=side)
        for jn in ("hip", "knee", "ankle"):
            jname = f"{jn}_{side}"
            tq = 0.0
            for g in (f"{jn}_ext", f"{jn}_flex"):
                th, om = fibre_kinematics(g, q[jname], qd[jname])
                tm, parts = generator_torque(
                    g, th, om, a_gen[g], params,
                    body_mass=body_mass, body_height=body_height, components=True,
                )
                name = f"{g}_{side}"
                gt[name] = parts["active"] if use_active_torque else tm
                gs[name] = om
                if isometric_torque == "thesis":
                    gm[name] = parts["tau0"]
                elif isometric_torque == "bhargava":
                    gm[name] = a_gen[g] * parts["tau0"] * parts["tA"]
                else:
                    raise ValueError("isometric_torque must be 'thesis' or 'bhargava'")
                tq = tq + TORQUE_SIGN[g] * tm
            jt[jname] = tq
            js[jname] = qd[jname]
    if mtp_torques:
        for jname, tq in mtp_torques.items():
            jt[jname] = tq
            js[jname] = qd[jname]
    out = metabolic_rate(ex, gt, gs, gm, jt, js, t_stim=t_stim, body_mass=body_mass, **kw)
    out["generator_torques"] = gt
    return out


def stimulation_time(t, e, threshold: float = 0.1, period: float | None = None) -> float:
    """t_stim of one muscle (thesis Sec 5.3.3): total time within the samples during which
    e(t) exceeds ``threshold`` × max e, s (numeric; rectangle rule on each sample's share
    of the grid, periodic if ``period`` is given)."""
    t = np.asarray(t, float)
    e = np.asarray(e, float)
    if period is not None:  # each sample owns the interval to the next (wrapping)
        w = np.diff(np.concatenate([t, [t[0] + period]]))
    else:  # trapezoidal weights
        h = np.diff(t)
        w = 0.5 * (np.concatenate([[0.0], h]) + np.concatenate([h, [0.0]]))
    return float(np.sum(w * (e > threshold * np.max(e))))


def cost_of_transport(t, edot, distance: float, body_mass: float = BODY_MASS) -> float:
    """Cost of transport (thesis Eq 5.57), J/(kg·m): ∫ Ė dt / (BM × D).

    Parameters
    ----------
    t : (n,) times, s (the cycle, end point included; trapezoidal rule).
    edot : (n,) metabolic rate Ė, W.
    distance : distance D travelled over [t0, t_n], m.
    body_mass : kg.
    """
    t = np.asarray(t, float)
    edot = np.asarray(edot, float)
    energy = float(np.sum(0.5 * (edot[1:] + edot[:-1]) * np.diff(t)))
    return energy / (body_mass * distance)
