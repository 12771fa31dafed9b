"""Muscle activation dynamics and the 16 excitations of the NMSK model (thesis Sec 5.3).

Excitations, muscles and generators (thesis Sec 5.3.1, Table 5.5, Eq 5.54)
-------------------------------------------------------------------------
The NMSK model has 16 excitations: the 8 EMG muscles of Bovi et al. 2011 on each leg
(:data:`EXCITATIONS`, right leg first). Each muscle is treated as mono-articular and
drives one generator of :mod:`gaitlib.mtg`:

=====  ========================  ==============  ===================  ====================
name   muscle                    MTG             gaitutils EMG        Schwartz 2008 EMG
=====  ========================  ==============  ===================  ====================
GM     gluteus maximus           hip_ext         ``RGlut``/``LGlut``  –
RF     rectus femoris            hip_flex        ``RRec``/``LRec``    rectus femoris
VM     vastus medialis           knee_ext        ``RVas``/``LVas``    –
BF     biceps femoris            knee_flex       ``RHam``/``LHam``    lateral hamstrings
SOL    soleus                    ankle_ext (s1)  ``RSol``/``LSol``    –
PL     peroneus longus           ankle_ext (s2)  ``RPer``/``LPer``    –
GAM    gastrocnemius medialis    ankle_ext       ``RGas``/``LGas``    medial gastrocnemius
TA     tibialis anterior         ankle_flex      ``RTibA``/``LTibA``  tibialis anterior
=====  ========================  ==============  ===================  ====================

Five of the six generator activations are the activation of one muscle; the ankle
extensor's is the synergy (Eq 5.54) a = s1 a_SOL + s2 a_PL + (1 − s1 − s2) a_GAM, with the
same s1, s2 on both legs (thesis identified s1 = s2 = 0.25, bounds [0, 0.5]).

Activation dynamics (thesis Eqs 5.34–5.37)
------------------------------------------
Excitation e → neural activation u → muscle activation a::

    u̇ = (c1 e_d + c2)(e_d − u),  c1 = 1/τ_act − 1/τ_deact,  c2 = 1/τ_deact,  τ_deact = 4 τ_act
    a = c3 √u + (1 − c3) u,      e_d(t) = e(t − d),  d = 50 ms

The rate constant c1 e_d + c2 = e_d/τ_act + (1 − e_d)/τ_deact blends the activation and
deactivation time constants through the excitation itself, so the right-hand side is a
polynomial in (e, u): there is no switch, nothing to smooth for IPOPT. A full step
e: 0 → 1 from u = 0 gives u(t) = 1 − exp(−t/τ_act) (63.2 % at τ_act); e: 1 → 0 from u = 1
gives u = exp(−t/τ_deact). For e ∈ [0, 1] the state stays in [0, 1] (convex combination).

The √u of Eq 5.37 has an infinite slope at u = 0, which IPOPT cannot handle; it is
replaced by the normalised (√(u + δ) − √δ)/(√(1 + δ) − √δ) (δ = 1e-4 by default: exact
at u = 0 and u = 1, slope ≤ 1/(2√δ) = 50, same shape elsewhere within ~1e-2).

The 50 ms electromechanical delay on a periodic cycle
----------------------------------------------------
In a periodic gait cycle a delay is a pure time shift. The recommended transcription is to
make the *delayed* excitation ẽ(t) = e(t − d) the control variable: the dynamics above then
need no delay at all, the metabolic cost integrated over a cycle is unchanged by a shift,
and only the comparison with EMG needs it — shift the EMG instead, EMG_d(t) = EMG(t − d),
with :func:`delay_periodic` (exact trigonometric interpolation on a uniform grid), and
report e(t) = ẽ(t + d). If the shift must act on decision variables (e.g. a uniform grid
of controls), :func:`periodic_delay_matrix` gives the linear map (constant if the cycle
time is fixed; a CasADi expression of the shift if the cycle time is a variable).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import casadi as ca
import numpy as np

from gaitlib.conventions import SIDES
from gaitlib.mtg import GENERATORS

__all__ = [
    "MUSCLES",
    "MUSCLE_NAMES",
    "EXCITATIONS",
    "MUSCLE_GENERATOR",
    "EMG_CHANNELS",
    "DELAY",
    "DEACTIVATION_RATIO",
    "ACTIVATION_BOUNDS",
    "ACTIVATION_INITIAL",
    "ACTIVATION_IDENTIFIED",
    "EXCITATION_BOUNDS",
    "activation_rate",
    "neural_to_muscle_activation",
    "ankle_extensor_activation",
    "generator_activations",
    "simulate_activation",
    "periodic_delay_matrix",
    "delay_periodic",
]

#: The 8 EMG muscles per leg (thesis Sec 5.3.1), in the order of the thesis's tables.
MUSCLES = ("GM", "RF", "VM", "BF", "SOL", "PL", "GAM", "TA")
MUSCLE_NAMES = {
    "GM": "gluteus maximus",
    "RF": "rectus femoris",
    "VM": "vastus medialis",
    "BF": "biceps femoris",
    "SOL": "soleus",
    "PL": "peroneus longus",
    "GAM": "gastrocnemius medialis",
    "TA": "tibialis anterior",
}
#: The 16 excitations (controls u4 of thesis Eq 5.52): right-leg muscles, then left.
EXCITATIONS = tuple(f"{m}_{s}" for s in SIDES for m in MUSCLES)
#: Muscle → generator it drives (thesis Table 5.5).
MUSCLE_GENERATOR = {
    "GM": "hip_ext",
    "RF": "hip_flex",
    "VM": "knee_ext",
    "BF": "knee_flex",
    "SOL": "ankle_ext",
    "PL": "ankle_ext",
    "GAM": "ankle_ext",
    "TA": "ankle_flex",
}
#: Model-view EMG channel (``gaitlib.data.GaitData`` column stem, add ``_r``/``_l``) of each
#: muscle per data source; None where the source has no such muscle. gaitutils has the
#: thesis's eight (``data.GAITUTILS_EMG``); Schwartz 2008 has five, of which BF is matched to
#: its lateral hamstrings (LH) and GAM to its medial gastrocnemius (MG); its medial
#: hamstrings (MH) channel has no thesis counterpart.
EMG_CHANNELS = {
    m: {"gaitutils": f"emg_{m}",
        "schwartz2008": {"RF": "emg_RF", "BF": "emg_LH", "GAM": "emg_MG", "TA": "emg_TA"}.get(m)}
    for m in MUSCLES
}

#: Electromechanical delay d, s (thesis Eq 5.34).
DELAY = 0.050
#: τ_deact / τ_act (thesis Sec 5.3.2).
DEACTIVATION_RATIO = 4.0
#: Bounds of the identified activation parameters (thesis Sec 5.3.4).
ACTIVATION_BOUNDS = {"tau_act": (0.005, 0.035), "c3": (0.0, 0.75), "s1": (0.0, 0.5), "s2": (0.0, 0.5)}
#: Initial guesses and identified values, thesis Table 5.10.
ACTIVATION_INITIAL = {"tau_act": 0.015, "c3": 0.3, "s1": 0.33, "s2": 0.33}
ACTIVATION_IDENTIFIED = {"tau_act": 0.006, "c3": 0.0001, "s1": 0.25, "s2": 0.25}
#: Bounds on the excitations used in the NMSK simulation (thesis Sec 5.3.4).
EXCITATION_BOUNDS = (0.0, 0.8)


def _is_ca(*xs) -> bool:
    return any(isinstance(x, (ca.SX, ca.MX, ca.DM)) for x in xs)


def activation_rate(u, e_delayed, tau_act, deactivation_ratio: float = DEACTIVATION_RATIO):
    """du/dt of the neural activation, 1/s (thesis Eqs 5.34–5.36).

    Parameters
    ----------
    u : neural activation, 1 (float, ndarray or CasADi).
    e_delayed : excitation at t − d, 1 (see module docstring for the delay).
    tau_act : activation time constant τ_act, s (may be a CasADi symbol).
    deactivation_ratio : τ_deact / τ_act (thesis: 4).

    Returns
    -------
    (c1 e_d + c2)(e_d − u) with c1 = 1/τ_act − 1/τ_deact, c2 = 1/τ_deact.
    """
    tau_deact = deactivation_ratio * tau_act
    c1 = 1.0 / tau_act - 1.0 / tau_deact
    c2 = 1.0 / tau_deact
    return (c1 * e_delayed + c2) * (e_delayed - u)


def neural_to_muscle_activation(u, c3, delta: float = 1e-4):
    """Muscle activation a from neural activation u (thesis Eq 5.37, smoothed), 1.

    a = c3 g(u) + (1 − c3) u with g(u) = (√(u + δ) − √δ)/(√(1 + δ) − √δ) ≈ √u; δ = 0 gives
    the thesis's √u exactly (not twice differentiable at u = 0). g(0) = 0, g(1) = 1, so
    a ∈ [0, 1] for u ∈ [0, 1] and c3 ∈ [0, 1].
    """
    sq = ca.sqrt if _is_ca(u, c3) else np.sqrt
    sd = math.sqrt(delta)
    g = (sq(u + delta) - sd) / (math.sqrt(1.0 + delta) - sd)
    r = c3 * g + (1.0 - c3) * u
    if not _is_ca(u, c3) and np.ndim(r) == 0:
        return float(r)
    return r


def ankle_extensor_activation(a_sol, a_pl, a_gam, s1, s2):
    """Ankle-extensor generator activation from its three muscles (thesis Eq 5.54), 1.

    a = s1 a_SOL + s2 a_PL + (1 − s1 − s2) a_GAM; with s1, s2 ∈ [0, 0.5] the weights are
    non-negative and sum to 1, so a ∈ [0, 1].
    """
    return s1 * a_sol + s2 * a_pl + (1.0 - s1 - s2) * a_gam


def generator_activations(a_muscles, s1, s2, side: str | None = None) -> dict:
    """The 6 generator activations of one leg from its 8 muscle activations.

    Parameters
    ----------
    a_muscles : mapping muscle → activation (keys ``'GM'`` … or ``'GM_r'`` … with ``side``),
        or a sequence of 8 in :data:`MUSCLES` order.
    s1, s2 : synergy weights of Eq 5.54.
    side : 'r' or 'l' when the mapping's keys carry a side suffix.

    Returns
    -------
    dict generator type (:data:`gaitlib.mtg.GENERATORS`) → activation.
    """
    if isinstance(a_muscles, Mapping):
        suf = f"_{side}" if side else ""
        a = {m: a_muscles[m + suf] for m in MUSCLES}
    else:
        a = dict(zip(MUSCLES, [a_muscles[i] for i in range(8)], strict=True))
    out = {}
    for g in GENERATORS:
        if g == "ankle_ext":
            out[g] = ankle_extensor_activation(a["SOL"], a["PL"], a["GAM"], s1, s2)
        else:
            (m,) = [k for k, v in MUSCLE_GENERATOR.items() if v == g]
            out[g] = a[m]
    return out


def simulate_activation(
    t,
    e,
    tau_act: float = ACTIVATION_IDENTIFIED["tau_act"],
    c3: float = ACTIVATION_IDENTIFIED["c3"],
    *,
    delay: float = DELAY,
    periodic: bool = False,
    period: float | None = None,
    u0: float | None = None,
    substeps: int = 10,
    delta: float = 1e-4,
):
    """Numerically integrate Eqs 5.34–5.37 for a sampled excitation (numeric path).

    Each step of length h/``substeps`` uses the exact solution of Eq 5.34 with the
    (delayed, linearly interpolated) excitation held at the sub-step midpoint:
    u ← e + (u − e) exp(−(c1 e + c2) h).

    Parameters
    ----------
    t : (n,) sample times, s, ascending.
    e : (n,) or (n, k) excitations in [0, 1].
    tau_act, c3 : activation parameters (defaults: thesis Table 5.10 identified values).
    delay : electromechanical delay d, s.
    periodic : treat e as one period (of length ``period``, default t[-1] − t[0] + the mean
        step, i.e. samples without the repeated end point) and return the periodic steady
        state (found by iterating cycles).
    u0 : initial neural activation (non-periodic); default e(t0 − d) ≈ e[0], as thesis.

    Returns
    -------
    u, a : arrays shaped like ``e`` (neural and muscle activation).
    """
    t = np.asarray(t, float)
    e = np.asarray(e, float)
    squeeze = e.ndim == 1
    E = e[:, None] if squeeze else e
    if periodic:
        T = period if period is not None else (t[-1] - t[0]) + np.mean(np.diff(t))
        tt = np.concatenate([t, [t[0] + T]])
        EE = np.vstack([E, E[:1]])

        def e_at(s):
            s = t[0] + np.mod(s - t[0], T)
            return np.stack([np.interp(s, tt, EE[:, j]) for j in range(E.shape[1])], axis=-1)
    else:

        def e_at(s):
            return np.stack([np.interp(s, t, E[:, j]) for j in range(E.shape[1])], axis=-1)

    tau_deact = DEACTIVATION_RATIO * tau_act
    c1, c2 = 1.0 / tau_act - 1.0 / tau_deact, 1.0 / tau_deact
    # every sub-step's midpoint and the delayed excitation there, once for all cycles (the
    # same numbers as evaluating e_at point by point: interpolation is elementwise)
    k = np.arange(substeps) + 0.5
    H = np.diff(t) / substeps
    mids = [t[:-1, None] + k[None, :] * H[:, None] - delay]
    if periodic:  # close the cycle: last sample → t0 + T
        h_close = (t[0] + T - t[-1]) / substeps
        mids.append(t[-1] + k[None, :] * h_close - delay)
    ED = e_at(np.concatenate(mids).ravel()).reshape(-1, substeps, E.shape[1])

    def run(u_start):
        U = np.empty_like(E)
        u = u_start.copy()
        U[0] = u
        for i in range(len(t) - 1):
            h = (t[i + 1] - t[i]) / substeps
            for ed in ED[i]:
                u = ed + (u - ed) * np.exp(-(c1 * ed + c2) * h)
            U[i + 1] = u
        if periodic:
            for ed in ED[-1]:
                u = ed + (u - ed) * np.exp(-(c1 * ed + c2) * h_close)
        return U, u

    u_init = e_at(t[0] - delay) if u0 is None else np.full(E.shape[1], float(u0))
    U, u_end = run(u_init)
    if periodic:
        for _ in range(200):
            if np.max(np.abs(u_end - U[0])) < 1e-12:
                break
            U, u_end = run(u_end)
    A = neural_to_muscle_activation(U, c3, delta)
    if squeeze:
        return U[:, 0], A[:, 0]
    return U, A


def periodic_delay_matrix(n: int, shift):
    """Linear map D (n × n) with (D x)_j = x(t_j − shift·T) for x sampled on a uniform
    periodic grid t_j = j T / n (no repeated end point); exact for trigonometric
    polynomials of degree < n/2 (band-limited interpolation).

    Parameters
    ----------
    n : number of samples per period.
    shift : delay as a fraction of the period, d / T (float or CasADi scalar, e.g.
        ``DELAY / t_f`` with a free cycle time).

    Returns
    -------
    ndarray (n, n), or CasADi matrix if ``shift`` is symbolic. D = I for shift = 0.
    """
    j = np.arange(n)[:, None]
    k = np.arange(n)[None, :]
    if _is_ca(shift):
        D = ca.SX.zeros(n, n) if isinstance(shift, ca.SX) else ca.MX.zeros(n, n)
        for a in range(n):
            for b in range(n):
                D[a, b] = _dirichlet(a - b - n * shift, n, ca.cos)
        return D
    return _dirichlet(j - k - n * float(shift), n, np.cos)


def _dirichlet(x, n, cos):
    """(1/n) Σ_m exp(2πi m x / n) over the symmetric band (real form, Nyquist split)."""
    s = 1.0
    for m in range(1, (n - 1) // 2 + 1):
        s = s + 2.0 * cos(2.0 * math.pi * m * x / n)
    if n % 2 == 0:
        s = s + cos(math.pi * x)
    return s / n


def delay_periodic(x, delay: float, period: float, axis: int = 0):
    """Delay a periodic signal sampled uniformly over one period: returns x(t − delay).

    Exact band-limited (FFT phase-shift) interpolation. ``x`` holds n samples at
    t_j = j·period/n (drop a repeated end point first, e.g. 51-point data at 0..100 %
    → the first 50). Use it to shift EMG to compare with the delayed-excitation controls.
    """
    x = np.asarray(x, float)
    n = x.shape[axis]
    X = np.fft.rfft(x, axis=axis)
    f = np.fft.rfftfreq(n, d=period / n)
    ph = np.exp(-2j * np.pi * f * delay)
    if n % 2 == 0:  # Nyquist term: keep it real (cos part of the shift)
        ph[-1] = np.cos(np.pi * n * delay / period)
    shape = [1] * x.ndim
    shape[axis] = len(f)
    return np.fft.irfft(X * ph.reshape(shape), n=n, axis=axis)
