"""The thesis's gait optimal control formulation, on top of :mod:`gaitlib.ocp`.

A :class:`GaitSpec` (frozen, hashable: *what* to solve — model, actuation, data, speed
class, cost function and weights, mesh, free parameters) becomes an
:class:`gaitlib.ocp.Problem` with :func:`build`; :func:`solve` returns a
:class:`GaitSolution` with tidy frames (q, torques, GRFs per foot and per ellipsoid,
activations, residuals), RMSE/NRMSE against the data and the solver's stats.

Formulation (thesis Secs 4.3.2, 5.2.1, 6.1)
-------------------------------------------
states   x = [q, q̇, q̈]                                         (Eq 4.6 / 5.28 / 5.51), 33
         NMSK: + u (16 neural activations, Eq 5.34), 49
controls u = [jerk (11), R_pelvis (3), actuation]                (Eq 4.7 / 5.29 / 5.52)
         actuation SK: τ (8 joint torques); MSK: τ_mtp (2) + a (12 MTG activations);
         NMSK: τ_mtp (2) + ẽ (16 delayed muscle excitations ``ed_<muscle>_<side>``)
         [+ ``edot_rest`` (lifted metabolic rate, W) when Mtb is weighted]
dynamics ẋ = [q̇, q̈, jerk]                                        (Eq 4.9)
         NMSK: u̇ = (c1 ẽ + c2)(ẽ − u)                             (Eqs 5.34–5.36)
implicit dynamics, path constraint: inverse_dynamics(q, q̇, q̈) − [R; τ_input] = 0 (11)
         (Eq 4.10/5.30 bound the square of this difference to [0, 1e-12]; we impose the
         equality directly — the same set, better conditioned for IPOPT)
residual bounds |R_x|, |R_y| ≤ 1 N, |R_z| ≤ 0.1 N·m              (Eq 4.8)
per-ellipsoid normal force ≥ 0 (optional, Sec 4.4.1)
μ_d/μ_s ∈ [0.55, 0.99] when contact parameters are free          (Eq 4.4)
fixed final time = the data's cycle time; **periodic** gait: x(t_f) = x(0) except
pelvis_tx, which advances by speed × cycle time. The thesis bounds the initial and final
states by the data instead of imposing periodicity; periodicity is our departure (a
steady gait cycle, no drift), stated in the book.

Cost terms (Eqs 4.11–4.13, 5.33, 6.1–6.10), each ``(1/t_f) ∫ Σ_i (e_i / range_i)² dt``
with ranges (max − min) of the data:
``Jrk`` t_f⁶ Σ (jerk/range)², ``Rsd`` residuals (ranges from their bounds), ``Imp``
(τ_inv − τ_input) on the 8 leg joints (≈ 0 under the equality constraint), ``HAT`` the 3
HAT coordinates vs a reference, ``Act`` activations (range 1), ``Trq`` hip/knee/ankle
*net* torques (6: actuator + the joint spring–damper of Table 4.2 — gait laboratories
report net joint moments, so the actuator torque alone is not comparable; with the
thesis's knee/ankle damping of ≈ 3 N·m·s/rad the difference reaches 10–18 N·m in swing),
``Ang`` hip/knee/ankle angles (6), ``GRF`` the 4 foot forces, and ``Q`` —
the motion term of Eqs 4.11 and 5.33 over all 11 coordinates (HAT, joints and the planned
metatarsal angles).

NMSK (Secs 5.3.2–5.3.4, 6.1)
----------------------------
The thesis solved Eq 5.34 "recursively over all time steps" from the excitation controls;
in a collocation NLP the neural activations u are states with Eq 5.34 as dynamics (one
more set of collocation defects, exact derivatives, and u(t_f) = u(0) on the periodic
cycle). The electromechanical delay d = 50 ms is handled by making the **delayed**
excitation ẽ(t) = e(t − d) — the signal that reaches the activation dynamics — the
control, bounded to [0, 0.8] (Sec 5.3.4). On a periodic cycle e and ẽ are the same
periodic signal shifted by d, so nothing is lost, the dynamics need no delay and no
coupling across nodes (a delay operator on node values, e.g.
:func:`gaitlib.activation.periodic_delay_matrix`, would need a uniform grid and, with a free
final time, a t_f-dependent dense matrix; LGR nodes are not uniform). The solution reports
e(t) = ẽ(t + d) (``GaitSolution.excitations``), comparable with EMG. Muscle activations
a = c3 √u + (1 − c3) u (Eq 5.37, smoothed √, :func:`gaitlib.activation.neural_to_muscle_activation`);
the 12 MTG activations follow Table 5.5 / Eq 5.54 (ankle extensor = s1 a_SOL + s2 a_PL +
(1 − s1 − s2) a_GAM, :func:`gaitlib.activation.generator_activations`) and drive
:func:`gaitlib.mtg.joint_torque`. γ = (τ_act, c3, s1, s2) (Eq 5.53): Table 5.10's
identified values (0.006 s, 0.0001, 0.25, 0.25), or NLP parameters within Sec 5.3.4's
bounds from Table 5.10's initial values with ``free_activation`` (the identification of
Sec 5.3.4).

``Act`` for NMSK is Act_NMSK (Eq 6.6): Σ of the 16 muscle activations squared (range 1).
``Mtb`` (Eq 6.7 = the 8th term of Eq 5.55): t_f⁶/(BM² D⁴) (Ė/(Ė_max − Ė_min))² with
Ė_max − Ė_min = COT_N (BM_max − BM_min) D / t_f (Eq 5.56: COT_N = 1.6 J kg⁻¹ m⁻¹,
BM_max = 56.9 kg, BM_min = 25.9 kg), BM = the model's body mass (41.4 kg) and D = the
data's stride length (the thesis: 1.24 m, its subjects' distance). The thesis writes the
scaling as t_f⁶ BM⁻² d⁻⁴ without defining d; we read d as the distance D — the only reading
that makes t_f⁶/(BM² d⁴) the inverse square of a power, as the text's motivation ("the
magnitude of energy rate is considerably greater than the other cost terms") implies (the
delay d = 0.05 s would make the term ≈ 4·10⁵ times larger). Ė is
:func:`gaitlib.metabolics.nmsk_metabolic_rate` (Eq 5.38; its documented smoothing and
sign conventions) with the heats from ẽ — the excitation the activation dynamics receive,
Bhargava's "excitation" — the MTG torques from the muscle activations, and the
metatarsal torques' work (Eq 5.50). Ė is *lifted*: a control ``edot_rest`` (W) equals
Ȧ + Ṁ + Ṡ + Ẇ through an equality path constraint (``metabolic_rate``), and Mtb integrates
k (B + smax(edot_rest))² (B the basal rate, smax as in :func:`gaitlib.metabolics.metabolic_rate`).
This is the same NLP optimum, but the square and the smooth max no longer couple all ≈ 50
variables Ė depends on at a node in the Hessian (dense rank-one blocks): on an 8 × 3 mesh
the Lagrangian Hessian has 19,824 instead of 42,072 non-zeros (without Mtb: 19,800).
t_stim (Eq 5.40) is the time a muscle's excitation
exceeds 10 % of its maximum; the thesis re-estimated it "constantly" during the
optimisation, which is piecewise constant in the decision variables (no derivative). We
fix it per muscle from the initial (data-based) guess's excitations (or to
``GaitSpec.t_stim``); ``GaitSolution.stats`` reports the COT with it and with t_stim
re-estimated from the solution. The thesis defines Mtb for NMSK only (Sec 6.1), so MSK
has no Mtb term and no metabolic frame.

Initial guess (NMSK): states as for MSK (data); the thesis used the processed EMG for
the excitations (Sec 5.3.4). Our default (``excitation_guess="mtg"``) maps the MSK guess's
inverse-MTG activations (Sec 5.2.1) to muscles (Table 5.5) and inverts Eqs 5.37 and 5.34
for the excitations; ``"emg"`` uses the data's EMG where the source has the muscle
(Schwartz 2008: RF, BF ≈ lateral hamstrings, GAM ≈ medial gastrocnemius, TA; the
gaitutils data have all eight muscles but no GRFs, which the gait problem needs). :func:`warm_start` maps an MSK solution's MTG
activations the same way (Sec 6.1 warm-starts NMSK from Ch 5's results).

Final time
----------
Fixed to the data's cycle time T by default; ``GaitSpec.tf_bounds = (lo, hi)`` makes it
free within bounds. The stride length stays the data's D = speed × T (periodic pelvis
offset and HAT reference), so the speed is D / t_f; the data are tracked on normalised
time t / t_f; the Jrk and Mtb t_f⁶ factors use the variable t_f (a static parameter
``t_f`` tied to the phase's final time by an endpoint constraint, because integrands see
only (x, u, p, t)).

HAT reference: pelvis_tx = speed·t; pelvis_ty such that the contact of the data's pose,
at rest, carries the data's total vertical GRF (:func:`kinematics.height_for_load`,
smoothed by an 8th-order Fourier fit; the thesis used a pelvis marker, which the public
data lack); pelvis_tilt = 0 (thesis Sec 4.2.1: negligible
variation, set to zero). Hip reference: the data's hip angle plus the data's pelvic tilt
(the thigh's orientation in the laboratory), because the data's hip angle is measured from
a pelvis tilted ≈ 11° forward while the model's HAT is upright; tracking the raw hip angle
with an upright HAT lifts the leading heel ≈ 9 cm off the ground at heel strike.
"""

from __future__ import annotations

import json
import math
import os
import socket
import time
from dataclasses import asdict, dataclass, replace
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np
import pandas as pd

from .. import cache
from .. import contact as contact_mod
from .. import conventions as cv
from .. import data as data_mod
from .. import kinematics
from .. import params as params_mod
from ..collocation import Mesh
from ..model import ChildModel
from ..ocp import Goal, Guess, Named, Parameter, PathConstraint, Periodic, Phase, PhaseGuess, Problem, SolverOptions
from .. import ocp
from .. import sweep
from .. import mtg
from .. import activation
from .. import effects as effects_mod
from .. import metabolics

#: Version of the gait formulation (this module with the physics, the collocation engine, the
#: data references, the effect library, bounds, initial guesses and solver options): part of
#: every cache key of a gait solution (:mod:`gaitlib.cache`). Bump it when a change alters
#: what is solved; ``tests/test_formulation_versions.py`` fails when the problem's numbers
#: change under an unchanged version.
FORMULATION = "gait-1"

MODELS = ("SK", "MSK", "NMSK")
TERMS = ("Jrk", "Rsd", "Imp", "HAT", "Act", "Trq", "Ang", "GRF", "Q", "Mtb")
LEG_JOINTS = tuple(f"{j}_{s}" for s in cv.SIDES for j in ("hip", "knee", "ankle"))  # 6 tracked
MTG_CONTROLS = tuple(f"a_{j}_{d}_{s}" for s in cv.SIDES for j in ("hip", "knee", "ankle") for d in ("ext", "flex"))
GRF_CHANNELS = ("grf_x_r", "grf_y_r", "grf_x_l", "grf_y_l")
#: R_max − R_min of thesis Eq 4.8 (N, N, N·m): the Rsd normalisation.
RESIDUAL_RANGE = (2.0, 2.0, 0.2)
#: NMSK (Sec 5.3.4): the 16 muscles (``GM_r`` … ``TA_l``, :data:`gaitlib.activation.EXCITATIONS`).
NMSK_MUSCLES = ("GM_r", "RF_r", "VM_r", "BF_r", "SOL_r", "PL_r", "GAM_r", "TA_r",
                "GM_l", "RF_l", "VM_l", "BF_l", "SOL_l", "PL_l", "GAM_l", "TA_l")
#: NMSK controls: the *delayed* excitations ẽ(t) = e(t − d) of Eq 5.34, 1 (module docstring).
EXCITATION_CONTROLS = tuple(f"ed_{m}" for m in NMSK_MUSCLES)
#: NMSK states: the neural activations u of Eq 5.34, 1.
NEURAL_STATES = tuple(f"u_{m}" for m in NMSK_MUSCLES)
#: Activation parameters γ of Eq 5.53, in NLP order (names of the free Parameters: ``act.<name>``).
ACTIVATION_PARAMS = ("tau_act", "c3", "s1", "s2")
#: MTG fitting-parameter sets of ``GaitSpec.mtg_params`` (:func:`mtg_params_of`).
MTG_PARAM_SETS = ("default", "ch5", "thesis")
#: Mtb normalisation (Eq 5.56): COT_N (J kg⁻¹ m⁻¹, adult natural speed) and the thesis's
#: subjects' largest and smallest body masses BM_max, BM_min (kg).
MTB_COT_N = 1.6
MTB_BM_MAX = 56.9
MTB_BM_MIN = 25.9

#: Cost functions: model → name → weights (thesis Tables 4.8, 5.3, 6.2).
COST_FUNCTIONS: dict[str, dict[str, dict[str, float]]] = {
    "SK": {
        # Eq 4.11, Table 4.8 (optimal control contact identification, Sec 4.3.2)
        "Eq4.11": {"Trq": 1 / 4, "GRF": 1 / 4, "Q": 1 / 4, "Jrk": 1 / 40},
        # Eq 4.11 + 4.12 + 4.13 (Sec 4.4: w5 = w6 = 1/4)
        "Eq4.13": {"Trq": 1 / 4, "GRF": 1 / 4, "Q": 1 / 4, "Jrk": 1 / 40, "Imp": 1 / 4, "Rsd": 1 / 4},
    },
    "MSK": {
        # Eq 5.33, Table 5.3 (natural gait, Sec 5.2)
        "Eq5.33": {"Trq": 1 / 4, "GRF": 1 / 4, "Q": 1 / 4, "Jrk": 1 / 40, "Act": 1 / 100,
                   "Rsd": 1 / 4, "Imp": 1 / 40},
    },
}
# Table 6.2, MSK rows (Ch 6); HAT tracks a reference, Act = Act_MSK
_T62 = {
    "DT": (1 / 40, 1 / 4, 1 / 40, 1 / 4, 1 / 100, 1 / 4, 1 / 4, 1 / 4),
    "SDT1": (1 / 40, 1 / 4, 1 / 4, 1 / 4, 1 / 100, 0, 1 / 4, 1 / 4),
    "SDT2": (1 / 40, 1 / 4, 1 / 4, 1 / 4, 1 / 100, 1 / 4, 0, 1 / 4),
    "SDT3": (1 / 40, 1 / 4, 1 / 4, 1 / 4, 1 / 100, 1 / 4, 1 / 4, 0),
    "SP1": (1 / 40, 1 / 10, 1 / 3, 1 / 2, 1 / 100, 0, 0, 1 / 4),
    "SP2": (1 / 40, 1 / 4, 1 / 4, 1 / 4, 1 / 100, 0, 1 / 4, 0),
    "SP3": (1 / 40, 1 / 4, 1 / 4, 1 / 4, 1 / 100, 1 / 4, 0, 0),
    "FP": (1 / 40, 1 / 4, 1 / 4, 1 / 4, 1 / 100, 0, 0, 0),
}
for _name, _w in _T62.items():
    COST_FUNCTIONS["MSK"][_name] = {k: v for k, v in zip(("Jrk", "Rsd", "Imp", "HAT", "Act", "Trq", "Ang", "GRF"), _w) if v}
# SK data tracking "DT" = the Ch 4 cost (Eq 4.11) for convenience in the CLI
COST_FUNCTIONS["SK"]["DT"] = COST_FUNCTIONS["SK"]["Eq4.11"]
COST_FUNCTIONS["NMSK"] = {
    # Eq 5.55, Table 5.9 (natural gait, Sec 5.3.4); Act = Act_NMSK (muscle activations)
    "Eq5.55": {"Trq": 1 / 4, "GRF": 1 / 4, "Q": 1 / 4, "Jrk": 1 / 40, "Act": 1 / 100,
               "Rsd": 1 / 4, "Imp": 1 / 40, "Mtb": 1 / 5},
}
# Table 6.2, NMSK rows (Ch 6): Jrk Rsd Imp HAT Act_NMSK Mtb Trq Ang GRF
_T62_NMSK = {
    "DT": (1 / 40, 1 / 4, 1 / 40, 1 / 4, 1 / 100, 1 / 5, 1 / 4, 1 / 4, 1 / 4),
    "SDT1": (1 / 40, 1 / 4, 1 / 10, 1 / 4, 1 / 100, 1 / 5, 0, 1 / 4, 1 / 4),
    "SDT2": (1 / 40, 1 / 4, 1 / 10, 1 / 4, 1 / 100, 1 / 5, 1 / 4, 0, 1 / 4),
    "SDT3": (1 / 40, 1 / 4, 1 / 20, 1 / 4, 1 / 100, 1 / 5, 1 / 4, 1 / 4, 0),
    "SP1": (1 / 40, 1 / 10, 1 / 20, 1 / 2, 1 / 100, 1 / 5, 0, 0, 1 / 4),
    "SP2": (1 / 40, 1 / 4, 1 / 10, 1 / 4, 1 / 100, 1 / 5, 0, 1 / 4, 0),
    "SP3": (1 / 40, 1 / 4, 1 / 10, 1 / 4, 1 / 100, 1 / 5, 1 / 4, 0, 0),
    "FP": (1 / 40, 1 / 10, 1 / 4, 1, 1 / 100, 1 / 5, 0, 0, 0),
}
for _name, _w in _T62_NMSK.items():
    COST_FUNCTIONS["NMSK"][_name] = {
        k: v for k, v in zip(("Jrk", "Rsd", "Imp", "HAT", "Act", "Mtb", "Trq", "Ang", "GRF"), _w) if v}


#: Spec options that are left out of :meth:`GaitSpec.to_dict` (hence of every cache key)
#: while unset: added after the store was written, they must not change existing keys.
KEY_STABLE_OPTIONS = ("swing_load_max", "derivatives", "jerk_ranges", "track_mtp", "activation_params",
                      "fourier_order", "defects", "track_norm", "friction_floor", "max_sink",
                      "leg_scale", "isometric_torque")
#: Readings of the concentric shortening heat's isometric term other than the thesis's
#: (``None``, Eq 5.47 as printed; :func:`gaitlib.metabolics.nmsk_metabolic_rate`'s ``isometric_torque``).
ISOMETRIC_TORQUES = ("bhargava",)
#: The Fourier order of the left leg generated from the right (thesis Eqs 4.1–4.3: 5).
FOURIER_ORDER = 5
#: The highest order a cycle of the data's 51 samples (50 distinct) carries: the left leg is
#: then the right leg's samples shifted (to the least-squares fit's round-off).
EXACT_FOURIER_ORDER = 25

#: How the Jrk term (Eq 4.11) normalises the jerk of each coordinate (:class:`GaitSpec`
#: ``jerk_ranges``; :func:`reference`).
JERK_RANGES = ("reference", "data")
#: How the data-tracking terms normalise each measured channel (:class:`GaitSpec`
#: ``track_norm``; :func:`reference`): the data's range (Eqs 4.9–4.11) or its SD.
TRACK_NORMS = ("range", "sd")
#: The measured channels :func:`sd_ranges` re-normalises, one group per tracking term (the
#: leg angles of Ang and Q, the net torques of Trq, the foot forces of GRF).
SD_GROUPS = (LEG_JOINTS, tuple(f"tau_{j}" for j in LEG_JOINTS), GRF_CHANNELS)


@dataclass(frozen=True)
class GaitSpec:
    """What to solve: a natural-gait (or speed-class) optimal control problem.

    Parameters
    ----------
    model : ``"SK"`` (joint torques), ``"MSK"`` (12 MTG activations + metatarsal torques) or
        ``"NMSK"`` (16 muscle excitations + metatarsal torques, activation dynamics).
    cost : a key of ``COST_FUNCTIONS[model]`` (e.g. ``"Eq4.11"``, ``"Eq5.33"``,
        ``"Eq5.55"``, ``"DT"``).
    weights : optional overrides, a tuple of ``(term, weight)`` pairs.
    speed_class, source : the data (:func:`gaitlib.data.load_gait_data`).
    n_intervals, degree, scheme : the mesh (thesis: 20 × 5 LGR = 100 nodes).
    periodic : impose a periodic cycle (our departure, see module docstring).
    normal_force_constraint : each ellipsoid's normal force ≥ 0 (Sec 4.4.1).
    free_contact, free_body : identify the 39 contact / 25 body parameters (Ch 4).
    body_params : ``"default"`` (Tables 4.1–4.3 scaled), ``"thesis"`` (Tables 4.15–4.16) or
        ``"ch4"`` (ours, Ch 4 approach (c), ``data/identified/ch4_child.json``,
        :func:`gaitlib.params.load_identified`), or ``"ch4_legs"`` (ours, the same on
        thigh and shank × :data:`gaitlib.studies.gait.LEG_SCALE`, ``data/identified/
        ch4_legs.json``; only with ``leg_scale``). The fixed values, or the guess when free.
    contact_params : ``"default"`` (the thesis's Tables 4.17–4.18), ``"ch4"`` or
        ``"ch4_legs"`` (ours, as ``body_params``). The fixed values, or the guess when free; also the geometry of the
        HAT-height reference.
    mtg_params : MSK/NMSK MTG fitting parameters (Eq 5.9) of the 12 generators (left leg =
        right leg): ``"default"`` — Eq 5.22, the adult Gymnast curves scaled to the child
        (Eq 5.21); ``"ch5"`` — ours, identified on our data (Sec 5.1.1,
        ``data/identified/ch5_mtg.json``, :mod:`gaitlib.studies.mtg_id`); ``"thesis"`` —
        Table 5.2. See :func:`mtg_params_of`.
    contact_bounds : with ``free_contact``: ``"widened"`` — Table 4.7 widened to contain the
        guess (Table 4.17 lies partly outside Table 4.7); ``"table4.7"`` — Table 4.7 verbatim.
    tol, max_iter : IPOPT settings (thesis: tol 1e-5).
    tf_bounds : ``()`` — final time fixed to the data's cycle time T; ``(lo, hi)`` (s) — free
        final time within the bounds. The stride length stays the data's (speed × T) in the
        periodic pelvis offset, so the walking speed becomes stride / t_f; the data are
        tracked on normalised time t / t_f; the Jrk (and Mtb) t_f⁶ scaling uses the
        variable t_f.
    free_activation : NMSK only — identify the activation parameters γ = (τ_act, c3, s1,
        s2) (Eq 5.53; bounds Sec 5.3.4, guess Table 5.10 "initial"); otherwise they are
        fixed to Table 5.10's identified values (as in Ch 6), or to ``activation_params``'s.
    activation_params : NMSK with fixed γ only — ``None`` (Table 5.10's identified values, the
        thesis's own) or ``"ch5"``: the values our Ch 5 NMSK solve identified on our data
        (``data/identified/ch5_activation.json``, :func:`gaitlib.studies.msk.save_activation`):
        the thesis's procedure — Ch 5's identified γ carried into Chs 6–7 — on our data.
    excitation_guess : NMSK only — ``"mtg"``: excitations from the inverse-MTG activations
        of the data (the MSK guess of Sec 5.2.1) through the inverted activation dynamics;
        ``"emg"``: the data's processed EMG where the source has the muscle (thesis Sec
        5.3.4), ``"mtg"`` elsewhere.
    t_stim : NMSK Mtb — the stimulation time of Eq 5.40 (s), one value for every muscle;
        ``None``: per muscle from the initial guess's excitations (time above 10 % of the
        maximum, Sec 5.3.3), held constant in the NLP (module docstring).
    track_class : ``""`` — the data tracked (and used for the guess and the normalising
        ranges) are ``speed_class``'s own; a speed class name (e.g. ``"Free"``) — that
        class's data scaled in time to ``speed_class``'s cycle time, magnitudes unchanged
        (:func:`gaitlib.data.time_scaled`; thesis Ch 7, Eqs 7.1–7.2). ``speed_class`` then
        supplies only the final time, the stride (speed × cycle time) and the state bounds
        (thesis Sec 7.1); its curves are never tracked.
    hat_reference : ``()`` — the HAT term (Eq 6.4) tracks the data's HAT estimate
        (module docstring); otherwise ``(tau, dx, y, tilt)``: four equal-length tuples
        sampling, on normalised time τ = t / T ∈ [0, 1), the HAT motion to track
        (thesis Sec 6.1: the Ch 5 solution's) — ``dx`` = pelvis_tx − stride·τ (m),
        ``y`` = pelvis_ty (m), ``tilt`` = pelvis_tilt (rad). Tracked on τ, so it scales with
        the cycle time (Ch 7). Build one with :func:`hat_reference_of`.
    effects : candidate unmodelled effects switched on (:data:`gaitlib.gap.EFFECTS`), a
        tuple of ``(name, magnitude)`` pairs: a float fixes the effect's magnitude (its
        first parameter), ``None`` makes its parameters NLP variables ``fx.<name>.<param>``
        (identified with the motion). Magnitude 0 is the baseline model. See
        :mod:`gaitlib.effects`.
    swing_load_max : ``None`` (the thesis: no such constraint) or a bound, N, on each foot's
        vertical GRF while the *data* say that foot swings (the validity gate's window:
        foot off + margin to the next foot contact − margin, :func:`swing_windows`). An
        ablation of the Fidelity II study (:mod:`gaitlib.studies.fidelity`): it measures what
        an unloaded swing foot costs in tracking. Runs with a fixed final time only (FP
        included: then the data's event times — foot off, foot contact, the left leg's
        shift — time the bound, and no data curve is tracked).
    jerk_ranges : ``None`` / ``"reference"`` (the book so far) or ``"data"``: the
        denominators of the Jrk term (Eq 4.11: "the minimum and maximum values of … jerks
        … were obtained from the experimental data"). ``"reference"``: the range of each
        coordinate's reference jerk — for pelvis_tx (speed × t) and the HAT tilt (0), which
        have no measured jerk, a fallback of 1 m/s³ / 1 rad/s³, which pins the HAT to a
        constant speed and tilt. ``"data"``: those two from the data instead — pelvis_tx
        from the data's horizontal GRF (the centre of mass's jerk Σ Ḟ_x / m), the tilt from
        the data's pelvic tilt; the others as ``"reference"``. See :func:`reference`.
    derivatives : ``None`` (:data:`gaitlib.ocp.DEFAULT_DERIVATIVES`) or ``"graph"`` /
        ``"nodes"`` (:class:`gaitlib.ocp.SolverOptions`): how the NLP's exact derivatives are
        built. The same problem; set explicitly it is part of the cache key, because IPOPT's
        path (and so the local optimum) can differ between the two. It travels with the spec,
        so sweep workers and a gap diagnosis's fits use it too.
    track_mtp : ``None`` / ``True`` (the thesis) or ``False``: whether the Q term tracks the
        two metatarsal angles. Their reference is not measured: it is the thesis's planned
        trajectory (Table 4.6), so ``False`` leaves the metatarsal joints to the dynamics — an
        ablation of the Fidelity II study (:func:`gaitlib.studies.fidelity.ch5_changes`).
    track_norm : ``None`` / ``"range"`` (the thesis, Eqs 4.9–4.11: each tracked channel's
        error divided by the data's range, max − min) or ``"sd"``: the measured channels
        divided by the data's between-subject SD instead, scaled per term so that a uniform
        error costs the term what it costs under ``"range"`` (:func:`sd_ranges`) — the term
        weights unchanged, only the split between the channels of a term moves. The HAT
        and metatarsal references (estimated or planned, no SD) keep their ranges; Imp,
        which borrows the torque ranges, follows them. An ablation of the Fidelity II study
        (:func:`gaitlib.studies.fidelity.ch5_changes`).
    friction_floor : ``None`` (the identified friction coefficients) or a lower bound on every
        ellipsoid's μ_s and μ_d (:func:`contact_params_of`). Both the thesis's Table 4.18 and
        our Ch 4 identification put the ball ellipsoid — the one that carries most of the
        load — at μ ≈ 0.01, so a loaded foot can slide almost for free; an ablation of the
        Fidelity II study measures what a floor on the friction changes. With
        ``free_contact`` (Ch 4 (b)/(c)): the lower bound of every μ_s and μ_d raised from
        Table 4.7's 0.01 to the floor (the identification experiment of
        :func:`gaitlib.studies.contact_id.friction_identification`).
    max_sink : ``None`` (the thesis: no such constraint) or a bound, m, on how deep any
        ellipsoid sinks into the ground at every node (the contact law's penetration depth δ
        of its lowest point, :func:`gaitlib.contact.ellipsoid_plane`). Volumetric contact
        carries load by penetration; an identification free to choose soft ellipsoids can
        trade a sliding foot for a sinking one (the Ch 4 friction experiment,
        :func:`gaitlib.studies.contact_id.friction_identification`).
    leg_scale : ``None`` (the thesis's Table 4.1 legs) or a factor in [0.8, 1.3] on the thigh
        and shank lengths (:attr:`gaitlib.model.ChildModel.leg_scale`: their COM distances and
        inertias follow, masses unchanged); the data's dimensionless speed and cadence are
        turned into m/s and s with the longer leg (:func:`gaitlib.data.speed_and_cycle_time`).
        A kinematic probe of the Fidelity study: how far the data's joint angles on the
        model's legs slide the loaded feet (:func:`gaitlib.studies.gait.leg_scale_slip`).
    fourier_order : ``None`` (the thesis's Eqs 4.1–4.3: :data:`FOURIER_ORDER`, 5) or the order
        of the least-squares Fourier series that generates the left leg's data from the right
        leg's (:func:`gaitlib.data.fourier_shift`); :data:`EXACT_FOURIER_ORDER` reproduces the
        right leg's samples shifted. Five harmonics round the vertical GRF's loading and
        unloading and ring below zero in swing; an ablation of the Fidelity II study
        (:func:`gaitlib.studies.contact_id.c_changes`). Not with ``effects`` (the effects
        assume the thesis's generation).
    defects : ``None`` (the differential form, X Aᵀ − h F Bᵀ, as GPOPS-II by default) or
        ``"integral"``: the same defects multiplied by the inverse of their end columns
        (:func:`gaitlib.collocation.integral_form`) — the same problem, other row scaling,
        another path for IPOPT (measured: ``benchmarks/bench_defect_form.py``).
    isometric_torque : NMSK only — ``None`` (Eq 5.47 as printed: the concentric
        shortening heat's isometric term is 0.16 s^τ τ0 ω_f, the generator's maximum isometric
        torque, even for a relaxed generator) or ``"bhargava"`` (Bhargava et al. 2004 / OpenSim:
        0.16 a s^τ τ0 t^A(θ) ω_f, the isometric torque at the current activation and angle).
        The Ė the Mtb term minimises and the reported COT follow it
        (:func:`gaitlib.metabolics.nmsk_metabolic_rate`); an ablation of the Fidelity II study
        (:func:`gaitlib.studies.msk.cot_ranges`).
    """

    model: str = "SK"
    cost: str = "DT"
    weights: tuple = ()
    speed_class: str = "Free"
    source: str = "schwartz2008"
    n_intervals: int = 20
    degree: int = 5
    scheme: str = "lgr"
    periodic: bool = True
    normal_force_constraint: bool = False
    free_contact: bool = False
    free_body: bool = False
    body_params: str = "default"
    contact_params: str = "default"
    mtg_params: str = "default"
    contact_bounds: str = "widened"
    residual_bounds: tuple = (1.0, 1.0, 0.1)
    tol: float = 1e-5
    max_iter: int = 1000
    hessian: str = "exact"
    tf_bounds: tuple = ()
    free_activation: bool = False
    excitation_guess: str = "mtg"
    t_stim: float | None = None
    track_class: str = ""
    hat_reference: tuple = ()
    effects: tuple = ()
    swing_load_max: float | None = None
    derivatives: str | None = None
    jerk_ranges: str | None = None
    track_mtp: bool | None = None
    activation_params: str | None = None
    fourier_order: int | None = None
    defects: str | None = None
    track_norm: str | None = None
    friction_floor: float | None = None
    max_sink: float | None = None
    leg_scale: float | None = None
    isometric_torque: str | None = None

    def __post_init__(self):
        if self.fourier_order is not None:
            if not (isinstance(self.fourier_order, int) and 1 <= self.fourier_order <= EXACT_FOURIER_ORDER):
                raise ValueError(f"fourier_order must be None or an integer in [1, {EXACT_FOURIER_ORDER}], "
                                 f"got {self.fourier_order!r}")
            if self.effects:
                raise ValueError("fourier_order cannot be combined with effects (they assume the thesis's order 5)")
        if self.jerk_ranges not in (None,) + JERK_RANGES:
            raise ValueError(f"jerk_ranges must be None or one of {JERK_RANGES}, got {self.jerk_ranges!r}")
        if self.friction_floor is not None:
            if (isinstance(self.friction_floor, bool) or not isinstance(self.friction_floor, (int, float))
                    or not 0.0 < float(self.friction_floor) <= 2.0):
                raise ValueError(f"friction_floor must be None or a friction coefficient in (0, 2], "
                                 f"got {self.friction_floor!r}")
        if self.max_sink is not None and (isinstance(self.max_sink, bool) or not isinstance(self.max_sink, (int, float))
                                          or not 0.0 < float(self.max_sink) <= 0.1):
            raise ValueError(f"max_sink must be None or a depth in (0, 0.1] m, got {self.max_sink!r}")
        if self.leg_scale is not None and (isinstance(self.leg_scale, bool) or not isinstance(self.leg_scale, (int, float))
                                           or not 0.8 <= float(self.leg_scale) <= 1.3):
            raise ValueError(f"leg_scale must be None or a factor in [0.8, 1.3], got {self.leg_scale!r}")
        if self.isometric_torque not in (None,) + ISOMETRIC_TORQUES:
            raise ValueError(f"isometric_torque must be None or one of {ISOMETRIC_TORQUES}, got {self.isometric_torque!r}")
        if self.isometric_torque is not None and self.model != "NMSK":
            raise ValueError("isometric_torque applies to the NMSK model's metabolic rate only")
        if self.track_norm not in (None,) + TRACK_NORMS:
            raise ValueError(f"track_norm must be None or one of {TRACK_NORMS}, got {self.track_norm!r}")
        if self.derivatives not in (None, "graph", "nodes"):
            raise ValueError(f"derivatives must be None, 'graph' or 'nodes', got {self.derivatives!r}")
        if self.model not in MODELS:
            raise ValueError(f"unknown model {self.model!r}; known {MODELS}")
        if self.tf_bounds:
            lo, hi = self.tf_bounds
            if not 0.0 < float(lo) <= float(hi):
                raise ValueError(f"tf_bounds must be () or (lo, hi) with 0 < lo <= hi, got {self.tf_bounds!r}")
        if self.model != "NMSK" and (self.free_activation or self.excitation_guess != "mtg" or self.t_stim is not None
                                     or self.activation_params is not None):
            raise ValueError("free_activation, activation_params, excitation_guess and t_stim apply to the NMSK model only")
        if self.activation_params not in (None, "ch5"):
            raise ValueError(f"activation_params must be None or 'ch5', got {self.activation_params!r}")
        if self.activation_params is not None and self.free_activation:
            raise ValueError("activation_params fixes γ; free_activation identifies it: choose one")
        if self.body_params not in ("default", "thesis", *params_mod.IDENTIFIED_SETS):
            raise ValueError(f"body_params must be 'default', 'thesis' or one of {list(params_mod.IDENTIFIED_SETS)}, "
                             f"got {self.body_params!r}")
        if self.mtg_params not in MTG_PARAM_SETS:
            raise ValueError(f"mtg_params must be one of {MTG_PARAM_SETS}, got {self.mtg_params!r}")
        if self.contact_params not in ("default", *params_mod.IDENTIFIED_SETS):
            raise ValueError(f"contact_params must be 'default' or one of {list(params_mod.IDENTIFIED_SETS)}, "
                             f"got {self.contact_params!r}")
        if "ch4_legs" in (self.contact_params, self.body_params) and self.leg_scale is None:
            raise ValueError("the 'ch4_legs' set was identified on longer legs: give leg_scale too")
        if self.contact_bounds not in ("widened", "table4.7"):
            raise ValueError(f"contact_bounds must be 'widened' or 'table4.7', got {self.contact_bounds!r}")
        if self.excitation_guess not in ("mtg", "emg"):
            raise ValueError(f"excitation_guess must be 'mtg' or 'emg', got {self.excitation_guess!r}")
        if self.cost not in COST_FUNCTIONS[self.model]:
            raise ValueError(f"unknown cost {self.cost!r} for {self.model}; known {sorted(COST_FUNCTIONS[self.model])}")
        for k, _ in self.weights:
            if k not in TERMS:
                raise ValueError(f"unknown cost term {k!r}; known {TERMS}")
        if self.speed_class not in cv.SPEED_CLASSES:
            raise ValueError(f"unknown speed class {self.speed_class!r}; known {cv.SPEED_CLASSES}")
        if self.track_class and self.track_class not in cv.SPEED_CLASSES:
            raise ValueError(f"unknown track_class {self.track_class!r}; known '' or {cv.SPEED_CLASSES}")
        if self.hat_reference:
            if len(self.hat_reference) != 4 or len({len(v) for v in self.hat_reference}) != 1:
                raise ValueError("hat_reference must be () or four equal-length tuples (tau, dx, y, tilt)")
        if self.effects:
            object.__setattr__(self, "effects", effects_mod.validate(self.effects, self.model))
        if self.swing_load_max is not None:
            if not float(self.swing_load_max) >= 0.0:
                raise ValueError(f"swing_load_max must be None or >= 0 N, got {self.swing_load_max!r}")
            if self.tf_bounds:
                raise ValueError("swing_load_max needs the data's swing windows (a run with fixed final time)")

    @property
    def term_weights(self) -> dict[str, float]:
        w = dict(COST_FUNCTIONS[self.model][self.cost])
        w.update(dict(self.weights))
        return {k: v for k, v in w.items() if v}

    def identified_sets(self) -> tuple[str, ...]:
        """Names of the identified parameter sets (``data/identified/<name>.json``) this spec
        reads: ``"ch4_child"`` for ``contact_params``/``body_params`` ``"ch4"`` (``"ch4_legs"``
        for ``"ch4_legs"``, :data:`gaitlib.params.IDENTIFIED_SETS`), ``"ch5_mtg"`` for
        ``mtg_params="ch5"``. Cache keys hash exactly these (:func:`gaitlib.cache.fingerprint`)."""
        sets = []
        for k, name in params_mod.IDENTIFIED_SETS.items():
            if k in (self.contact_params, self.body_params):
                sets.append(name)
        if self.mtg_params == "ch5":
            sets.append("ch5_mtg")
        if self.activation_params == "ch5":
            sets.append(ACTIVATION_SET)
        return tuple(sets)

    def effect_versions(self) -> tuple[str, ...]:
        """The formulation versions of the spec's effects that cache keys add
        (:func:`gaitlib.effects.formulation_versions`; empty for most specs)."""
        return effects_mod.formulation_versions(self.effects)

    def key(self) -> str:
        """Cache key: hash of the full spec, :data:`FORMULATION` (and its effects'
        versions) and the data (:func:`gaitlib.cache.key`)."""
        return cache.key({"kind": "gait", **self.to_dict()}, (FORMULATION,) + self.effect_versions(),
                         identified=self.identified_sets())

    def to_dict(self) -> dict:
        """The spec as plain JSON values; options added after the store was written are
        left out while unset (:data:`KEY_STABLE_OPTIONS`), so every existing key stays."""
        d = json.loads(json.dumps(asdict(self)))
        for k in KEY_STABLE_OPTIONS:
            if d.get(k) is None:
                d.pop(k, None)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "GaitSpec":
        d = dict(d)
        d["weights"] = tuple(tuple(w) for w in d.get("weights", ()))
        d["residual_bounds"] = tuple(d.get("residual_bounds", (1.0, 1.0, 0.1)))
        d["tf_bounds"] = tuple(d.get("tf_bounds", ()))
        d["hat_reference"] = tuple(tuple(v) for v in d.get("hat_reference", ()))
        d["effects"] = tuple((n, m) for n, m in d.get("effects", ()))
        return cls(**d)


# ======================================================================================
# Reference data on the model's channels
# ======================================================================================


def _fourier_derivatives(y: np.ndarray, T: float, order: int = 12, n_der: int = 3):
    """Least-squares Fourier fit of a periodic sample on t_j = j T/(n−1), j = 0..n−1, and
    its analytic time derivatives; returns a callable t → (n_der+1, len(t))."""
    n = y.size
    t = np.linspace(0.0, T, n)
    k = np.arange(1, order + 1)
    w = 2 * np.pi * k / T

    def basis(tt, der):
        tt = np.atleast_1d(tt)
        cols = [np.ones_like(tt) if der == 0 else np.zeros_like(tt)]
        ph = np.outer(tt, w)
        # d^der/dt^der of cos(w t) and sin(w t)
        c = np.cos(ph + der * np.pi / 2) * w**der
        s = np.sin(ph + der * np.pi / 2) * w**der
        return np.column_stack(cols + [c, s])

    coef = np.linalg.lstsq(basis(t[:-1], 0), y[:-1], rcond=None)[0]  # drop duplicate end point
    return lambda tt: np.vstack([basis(tt, d) @ coef for d in range(n_der + 1)])


#: The periodic Fourier fit with analytic time derivatives the references use (public name).
fourier_derivatives = _fourier_derivatives


@dataclass(frozen=True, eq=False)
class Reference:
    """Data (and derived references) on the model's channels, SI, on a time grid."""

    gait: data_mod.GaitData
    q: pd.DataFrame  # reference coordinates (11), incl. HAT estimate and planned mtp
    deriv: dict  # name → callable t → (4, n): q, q̇, q̈, jerk from Fourier fits
    tau: pd.DataFrame  # 6 joint torques
    grf: pd.DataFrame  # 4 foot forces
    ranges: dict  # channel → (max − min) for normalisation


def reference(gait: data_mod.GaitData, model: ChildModel, p_contact=None, order: int = 12,
              jerk_ranges: str = "reference", track_norm: str = "range") -> Reference:
    """Model-channel references from data: joint angles (data), metatarsal (planned), HAT
    (pelvis_tx = speed·t, pelvis_ty from the lowest ellipsoid at 2 mm penetration,
    pelvis_tilt = 0); torques; GRFs; Fourier-fit derivatives for the guess and jerk ranges.
    ``jerk_ranges``: :data:`JERK_RANGES` (:class:`GaitSpec`); ``"data"`` replaces the jerk
    ranges of pelvis_tx and pelvis_tilt by :func:`data_jerk_ranges`. ``track_norm``:
    :data:`TRACK_NORMS`; ``"sd"`` replaces the measured channels' ranges by :func:`sd_ranges`."""
    T = gait.cycle_time
    t = gait.time
    # thigh="lab": hip reference = data hip + data pelvic tilt, so that with an upright HAT
    # each thigh keeps its measured orientation in the laboratory (kinematics.pose_from_data)
    Q = kinematics.pose_from_data(model, gait, t, p_contact, penetration=0.002, thigh="lab")
    # pelvis height: the contact (at rest) carries the data's total vertical GRF, then a
    # Fourier fit smooths it (the lowest-ellipsoid rule leaves the feet almost unloaded
    # and its height has kinks where the lowest ellipsoid changes)
    load = (gait.mean["grf_y_r"] + gait.mean["grf_y_l"]).to_numpy()
    ty = kinematics.height_for_load(model, Q, load, p_contact)
    Q[:, 1] = _fourier_derivatives(ty, T, order=8, n_der=0)(t)[0]
    qd = {c: Q[:, i] for i, c in enumerate(cv.COORDS)}
    qref = pd.DataFrame({c: qd[c] for c in cv.COORDS}, index=pd.Index(t, name="time"))
    deriv = {}
    for c in cv.COORDS:
        y = qref[c].to_numpy()
        if c == "pelvis_tx":
            deriv[c] = (lambda tt, v=gait.speed: np.vstack([v * np.atleast_1d(tt), v + 0 * np.atleast_1d(tt),
                                                            0 * np.atleast_1d(tt), 0 * np.atleast_1d(tt)]))
        else:
            deriv[c] = _fourier_derivatives(y, T, order)
    tau = gait.mean[[f"tau_{j}" for j in LEG_JOINTS]].copy()
    tau.columns = list(LEG_JOINTS)
    grf = gait.mean[list(GRF_CHANNELS)].copy()
    ranges = {}
    fine = np.linspace(0, T, 401)
    for c in cv.COORDS:
        vals = deriv[c](fine)
        ranges[c] = float(np.ptp(qref[c])) if c != "pelvis_tx" else float(gait.speed * T)
        ranges[f"jerk_{c}"] = float(np.ptp(vals[3])) if np.ptp(vals[3]) > 0 else 1.0
    for c in LEG_JOINTS:
        ranges[f"tau_{c}"] = float(np.ptp(tau[c]))
    for c in GRF_CHANNELS:
        ranges[c] = float(np.ptp(grf[c]))
    for c in ("mtp_r", "mtp_l", "pelvis_tilt"):
        ranges[c] = max(ranges[c], 10 * cv.DEG)  # planned / zero references: avoid 1/0
    if jerk_ranges == "data":
        ranges.update(data_jerk_ranges(gait, order))
    elif jerk_ranges != "reference":
        raise ValueError(f"jerk_ranges must be one of {JERK_RANGES}, got {jerk_ranges!r}")
    if track_norm == "sd":
        ranges.update(sd_ranges(gait, ranges))
    elif track_norm != "range":
        raise ValueError(f"track_norm must be one of {TRACK_NORMS}, got {track_norm!r}")
    return Reference(gait=gait, q=qref, deriv=deriv, tau=tau, grf=grf, ranges=ranges)


def joint_angle_bounds(gait: data_mod.GaitData) -> dict[str, tuple[float, float]]:
    """Bounds of the eight joint angles (rad): the data's mean ± 3 SD over the cycle, widened
    by 15° (thesis: "based on the standard deviation")."""
    return {c: (float((gait.mean[c] - 3 * gait.sd[c]).min()) - 15 * cv.DEG,
                float((gait.mean[c] + 3 * gait.sd[c]).max()) + 15 * cv.DEG) for c in cv.COORDS[3:]}


def contact_params_of(spec: GaitSpec) -> np.ndarray:
    """The 39 contact parameters a spec solves with (SI, left foot order): the set
    ``spec.contact_params`` names (:func:`gaitlib.params.contact_params`), with every
    ellipsoid's μ_s and μ_d raised to at least ``spec.friction_floor`` when it is set."""
    p = np.array(params_mod.contact_params(spec.contact_params), dtype=float)
    return p if spec.friction_floor is None else contact_mod.with_friction_floor(p, spec.friction_floor)


def solved_contact_params(sol) -> np.ndarray:
    """The 39 contact parameters a solved gait ran with (SI): the identified ones when its
    spec left them free (``c.<name>`` static parameters of ``sol.solution``), else
    :func:`contact_params_of` its spec. (Effects that change the contact are not applied.)"""
    if sol.spec.free_contact:
        return np.array([sol.solution.parameters[f"c.{n}"] for n in contact_mod.param_names()], dtype=float)
    return contact_params_of(sol.spec)


def slip_velocities(model: ChildModel, q: np.ndarray, qd: np.ndarray, p_contact) -> np.ndarray:
    """Each ellipsoid's slip velocity (m/s, +x forward; :meth:`gaitlib.model.ChildModel.slip`)
    at every row of ``q``, ``qd`` (n, 11; SI) → (6, n), order :data:`gaitlib.model.ELLIPSOID_LABELS`."""
    n = q.shape[0]
    return np.asarray(model.function("slip").map(n)(np.asarray(q, float).T, np.asarray(qd, float).T,
                                                    ca.repmat(ca.DM(p_contact), 1, n))[0])


def sd_ranges(gait: data_mod.GaitData, ranges: dict) -> dict[str, float]:
    """The denominators of the measured channels under ``track_norm="sd"``: per group of
    :data:`SD_GROUPS` (one tracking term's channels, one unit), k·σ_c with σ_c the RMS over
    the cycle of channel c's between-subject SD and k such that Σ_c 1/(k σ_c)² =
    Σ_c 1/range_c² — a uniform error e costs the term e² Σ 1/range² either way; only the
    weight of each channel relative to the others of its term becomes 1/σ_c² instead of
    1/range_c². Units those of the channel (rad, N·m, N)."""
    out = {}
    for group in SD_GROUPS:
        sd = {}
        for c in group:
            v = np.sqrt(np.mean(np.square(gait.sd[c].to_numpy(float)))) if c in gait.sd else np.nan
            if not np.isfinite(v) or v <= 0:
                raise ValueError(f"track_norm='sd': the data's SD of channel {c!r} is {v!r}; expected a positive "
                                 "between-subject SD (a source without SDs can only be normalised by range)")
            sd[c] = float(v)
        k = np.sqrt(sum(1 / s**2 for s in sd.values()) / sum(1 / ranges[c]**2 for c in group))
        out.update({c: float(k * s) for c, s in sd.items()})
    return out


def data_jerk_ranges(gait: data_mod.GaitData, order: int = 12, n: int = 401) -> dict[str, float]:
    """Jrk denominators (max − min over the cycle) of the two HAT coordinates whose
    reference has no jerk, from the data: ``jerk_pelvis_tx`` (m/s³) — the centre of mass's
    horizontal jerk, the time derivative of the total horizontal GRF over the body mass
    (Newton: m ẍ_COM = Σ F_x); ``jerk_pelvis_tilt`` (rad/s³) — the third derivative of the
    data's pelvic tilt. Derivatives of the order-``order`` Fourier fit, on ``n`` points."""
    T = gait.cycle_time
    fine = np.linspace(0.0, T, n)
    fx = (gait.mean["grf_x_r"] + gait.mean["grf_x_l"]).to_numpy()
    jerk_x = _fourier_derivatives(fx, T, order, n_der=1)(fine)[1] / cv.BODY_MASS
    jerk_tilt = _fourier_derivatives(gait.mean["pelvis_tilt"].to_numpy(), T, order)(fine)[3]
    return {"jerk_pelvis_tx": float(np.ptp(jerk_x)), "jerk_pelvis_tilt": float(np.ptp(jerk_tilt))}


def _with_hat_reference(ref: Reference, hat: tuple) -> Reference:
    """``ref`` with its HAT coordinates (and their Fourier derivatives) replaced by ``hat``
    = (τ, pelvis_tx − stride·τ, pelvis_ty, pelvis_tilt) on normalised time (GaitSpec)."""
    T = ref.gait.cycle_time
    stride = ref.gait.speed * T
    tau_h = np.asarray(hat[0], float)
    t = ref.q.index.to_numpy()
    q = ref.q.copy()
    deriv = dict(ref.deriv)
    for c, vals in zip(cv.COORDS[:3], hat[1:]):
        v = np.asarray(vals, float)
        # periodic samples on [0, 1): close the loop for the Fourier fit on [0, T]
        tt = np.append(tau_h, 1.0) * T
        vv = np.append(v, v[0])
        f = _fourier_derivatives(np.interp(t, tt, vv), T, order=12)
        if c == "pelvis_tx":
            deriv[c] = (lambda x, f=f, v_=stride / T: f(x) + np.vstack([v_ * np.atleast_1d(x), v_ + 0 * np.atleast_1d(x),
                                                                          0 * np.atleast_1d(x), 0 * np.atleast_1d(x)]))
        else:
            deriv[c] = f
        q[c] = deriv[c](t)[0]
    return replace(ref, q=q, deriv=deriv)


def hat_reference_of(sol: "GaitSolution", n: int = 100) -> tuple:
    """The HAT motion of a solved gait as a :attr:`GaitSpec.hat_reference` (n samples)."""
    if not sol.spec.periodic:
        raise ValueError("hat_reference_of needs a periodic gait solution")
    from scipy.interpolate import CubicHermiteSpline

    X = sol.solution.phase("cycle").states
    tf = float(sol.stats["tf_s"])
    g = spec_gait_data(sol.spec)[0]  # the class's data on the spec's legs (its stride)
    stride = g.speed * g.cycle_time  # the periodic pelvis offset (build)
    t = X.index.to_numpy(dtype=float)
    x0 = X.iloc[0]
    if t[-1] < tf - 1e-9:  # nodes stop short of t_f: close the cycle with the periodic end state
        X = pd.concat([X, X.iloc[[0]].set_axis([tf])])
        X.loc[tf, "pelvis_tx"] += stride
        t = X.index.to_numpy(dtype=float)
    tau = np.arange(n) / n

    def at(c):  # cubic Hermite on the node values and velocities (both states)
        return CubicHermiteSpline(t, X[c].to_numpy(), X[f"qd_{c}"].to_numpy())(tau * tf)

    dx = at("pelvis_tx") - x0["pelvis_tx"] - stride * tau
    ys = at("pelvis_ty")
    tilt = at("pelvis_tilt")
    r = lambda a: tuple(round(float(v), 9) for v in a)  # noqa: E731 (JSON-stable key)
    return (r(tau), r(dx), r(ys), r(tilt))


# ======================================================================================
# Problem
# ======================================================================================


@dataclass(eq=False)
class GaitProblem:
    """A built gait problem: the spec, the ocp Problem, mesh, options and guess.

    The formulation's per-node pieces, for goals added outside it (:mod:`gaitlib.gap`):

    ``node``: the closure (x, u, p) → dict of the node's expressions (``tau_id``, ``R_id``,
    ``tau_in``, ``R_in``, ``tau_net``, ``grf`` …; :class:`~gaitlib.ocp.Named` views in);
    ``effects``: the spec's bound effects (:class:`gaitlib.effects.Bound`) or None;
    ``edot`` (NMSK): CasADi (x, u, p, t_stim) → Ė and its components (total, activation,
    maintenance, shortening, basal, work; W), else None; ``t_stim`` (NMSK): the stimulation
    time per muscle (s, :data:`NMSK_MUSCLES` order) held constant in the Mtb term.
    """

    spec: GaitSpec
    model: ChildModel
    ref: Reference
    problem: Problem
    mesh: Mesh
    options: SolverOptions
    guess: Guess
    p_body: np.ndarray
    p_contact: np.ndarray
    t_stim: tuple = ()
    node: Any = None
    effects: Any = None
    edot: Any = None

    @property
    def stride(self) -> float:
        """Stride length D = data speed × data cycle time (m): the periodic pelvis offset."""
        return float(self.ref.gait.speed * self.ref.gait.cycle_time)


def _controls(spec: GaitSpec) -> tuple[str, ...]:
    jerk = tuple(f"jerk_{c}" for c in cv.COORDS)
    if spec.model == "SK":
        act = tuple(f"tau_{j}" for j in cv.JOINTS)
    elif spec.model == "NMSK":
        act = ("tau_mtp_r", "tau_mtp_l") + EXCITATION_CONTROLS
        if "Mtb" in spec.term_weights:
            act = act + ("edot_rest",)  # lifted non-basal metabolic rate, W (module docstring)
    else:
        act = ("tau_mtp_r", "tau_mtp_l") + MTG_CONTROLS
    return jerk + cv.RESIDUALS + act


def _states(spec: GaitSpec) -> tuple[str, ...]:
    x = tuple(cv.COORDS) + tuple(f"qd_{c}" for c in cv.COORDS) + tuple(f"qdd_{c}" for c in cv.COORDS)
    return x + NEURAL_STATES if spec.model == "NMSK" else x


def _params_json(path: Path, what: str, writer: str) -> dict:
    """The parsed JSON of an identified parameter file with ``params`` and ``provenance``
    entries; errors name the file (``what``: the kind of file; ``writer``: what writes it)."""
    if not path.is_file():
        raise FileNotFoundError(f"{what} file {path} not found: it is written by {writer}")
    try:
        raw = json.loads(path.read_text())
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not valid JSON ({e})") from None
    if "params" not in raw or "provenance" not in raw:
        raise ValueError(f"{path}: needs 'params' and 'provenance' entries")
    return raw


def load_mtg_params(path) -> dict:
    """MTG fitting parameters from a JSON file ``{"params": {generator: {Eq 5.9 name: value}},
    "provenance": …}`` (written by :func:`gaitlib.studies.mtg_id.save_params`; Δ^P in rad)
    → generator → :class:`gaitlib.mtg.MTGParams`. Errors name the file and the entry."""
    path = Path(path)
    raw = _params_json(path, "MTG parameter", "gaitlib.studies.mtg_id.save_params (python -m gaitlib.studies.mtg_id)")
    out = {}
    for g in mtg.GENERATORS:
        d = raw["params"].get(g)
        if d is None or set(d) != set(mtg.MTGParams._fields):
            raise ValueError(f"{path}: params[{g!r}] must have exactly {mtg.MTGParams._fields}")
        v = [float(d[k]) for k in mtg.MTGParams._fields]
        if not all(math.isfinite(x) for x in v):
            raise ValueError(f"{path}: params[{g!r}] has non-finite values")
        out[g] = mtg.MTGParams(*v)
    return out


def mtg_params_of(spec_or_name) -> dict | None:
    """The MTG fitting parameters of a spec (or a :data:`MTG_PARAM_SETS` name), in the form
    :func:`gaitlib.mtg.joint_torque` takes: None for ``"default"`` (Eq 5.22), else
    generator → MTGParams (``"ch5"``: ``data/identified/ch5_mtg.json``; ``"thesis"``:
    Table 5.2). A missing file is an error (no fallback)."""
    name = spec_or_name.mtg_params if isinstance(spec_or_name, GaitSpec) else spec_or_name
    if name == "default":
        return None
    if name == "thesis":
        return dict(mtg.THESIS_PARAMS)
    if name == "ch5":
        return load_mtg_params(Path(data_mod.DATA_DIR) / "identified" / "ch5_mtg.json")
    raise ValueError(f"mtg_params must be one of {MTG_PARAM_SETS}, got {name!r}")


def activation_values(spec: GaitSpec) -> dict[str, float]:
    """Numeric activation parameters γ (Eq 5.53) of an NMSK spec: Table 5.10's identified
    values, ours (``activation_params="ch5"``, :func:`load_activation_params`), or Table
    5.10's initial guesses when ``free_activation`` (then they are NLP variables)."""
    if spec.activation_params == "ch5":
        return load_activation_params(params_mod.identified_path(ACTIVATION_SET))
    src = activation.ACTIVATION_INITIAL if spec.free_activation else activation.ACTIVATION_IDENTIFIED
    return {k: float(src[k]) for k in ACTIVATION_PARAMS}


#: The identified parameter set of :attr:`GaitSpec.activation_params` ``"ch5"``.
ACTIVATION_SET = "ch5_activation"


def load_activation_params(path) -> dict[str, float]:
    """Activation parameters γ from a JSON file ``{"params": {τ_act (s), c3, s1, s2}, "provenance":
    …}`` (written by :func:`gaitlib.studies.msk.save_activation`), each checked against its
    bounds (:data:`gaitlib.activation.ACTIVATION_BOUNDS`, Sec 5.3.4). Errors name the file and
    the entry."""
    path = Path(path)
    d = _params_json(path, "activation parameter",
                     "gaitlib.studies.msk.save_activation (the Ch 5 NMSK solve's identified γ)")["params"]
    if set(d) != set(ACTIVATION_PARAMS):
        raise ValueError(f"{path}: params must have exactly {ACTIVATION_PARAMS}, got {sorted(d)}")
    out = {}
    for k in ACTIVATION_PARAMS:
        lo, hi = activation.ACTIVATION_BOUNDS[k]
        v = float(d[k])
        if not (math.isfinite(v) and lo - 1e-9 <= v <= hi + 1e-9):
            raise ValueError(f"{path}: params[{k!r}] = {v!r} outside its bounds [{lo}, {hi}] (Sec 5.3.4)")
        out[k] = v
    return out


def mtb_scale(t_f, stride: float, body_mass: float = cv.BODY_MASS):
    """Factor k of the Mtb integrand k Ė² (Eqs 5.55–5.56 / 6.7), 1/W².

    Mtb = ∫ t_f⁶/(BM² D⁴) (Ė / (Ė_max − Ė_min))² dt with Ė_max − Ė_min =
    COT_N (BM_max − BM_min) D / t_f: k = t_f⁸ / (BM² D⁶ (COT_N (BM_max − BM_min))²).
    ``t_f`` (s) may be a CasADi symbol (free final time); ``stride`` D (m), ``body_mass``
    BM (kg). The thesis's "d" of the t_f⁶ BM⁻² d⁻⁴ factor is read as the distance D of
    Eq 5.56 (module docstring).
    """
    d_edot = MTB_COT_N * (MTB_BM_MAX - MTB_BM_MIN) * stride / t_f
    return t_f**6 / (body_mass**2 * stride**4) / d_edot**2


# -- cost terms ---------------------------------------------------------------------------
# Every thesis cost term is a named goal factory: GoalContext → integrand (x, u, p, t[, d]) or
# None where the term is not defined for the model. build() adds, in COST_TERMS's order, the
# terms the cost function weights (COST_FUNCTIONS), each divided by the duration.


@dataclass(frozen=True)
class GoalContext:
    """What the cost terms read from a built problem: ``model``; ``ranges`` (the data's range
    per channel, :attr:`Reference.ranges`, the normalisation of Eqs 4.9-4.11); ``node`` (the
    per-node closure, :attr:`GaitProblem.node`); ``tf_of`` (p → final time, s); ``stride``
    (m); NMSK: ``muscle_activations`` (x, p → the 16 activations) and ``basal`` (W)."""

    model: str
    ranges: Any
    node: Any
    tf_of: Any
    stride: float
    muscle_activations: Any = None
    basal: float = 0.0
    q_tracked: tuple = cv.COORDS


def _sq(e, r):
    return (e / r) ** 2


def goal_jrk(c: GoalContext):
    """Jrk (Eq 4.10): jerks of every coordinate, × t_f⁶ (Eq 5.55's time scaling)."""
    return lambda x, u, p, t: c.tf_of(p)**6 * sum(_sq(u[f"jerk_{k}"], c.ranges[f"jerk_{k}"]) for k in cv.COORDS)


def goal_rsd(c: GoalContext):
    """Rsd (Eq 4.13): HAT residual loads, normalised by the thesis's residual range (Eq 4.8:
    ±1 N, ±0.1 N·m) even when the bounds are relaxed (continuation), so relaxing never makes
    residuals cheap."""
    rn = dict(zip(cv.RESIDUALS, RESIDUAL_RANGE))
    return lambda x, u, p, t: sum(_sq(u[r], rn[r]) for r in cv.RESIDUALS)


def goal_imp(c: GoalContext):
    """Imp (Eq 6.3): inverse-dynamics minus input torques over the 8 joints; the metatarsal
    joints have no data, so their differences are normalised by the same side's ankle range."""
    rg, node = c.ranges, c.node
    imp_range = {j: rg[f"tau_{j}"] if f"tau_{j}" in rg else rg[f"tau_{j.replace('mtp', 'ankle')}"]
                 for j in cv.JOINTS}
    return lambda x, u, p, t: sum(_sq(node(x, u, p)["tau_id"][i] - node(x, u, p)["tau_in"][i], imp_range[j])
                                  for i, j in enumerate(cv.JOINTS))


def goal_hat(c: GoalContext):
    """HAT: the pelvis (HAT) coordinates tracking their reference."""
    rg = c.ranges
    return lambda x, u, p, t, d: sum(_sq(x[k] - d[f"ref_{k}"], rg[k]) for k in cv.COORDS[:3])


def goal_act(c: GoalContext):
    """Act: MSK, the 12 MTG activations (Eq 5.33); NMSK, the 16 muscle activations (Eq 6.6,
    range a_max − a_min = 1, Sec 5.3.4); not defined for SK."""
    if c.model == "MSK":
        return lambda x, u, p, t: sum(u[a] ** 2 for a in MTG_CONTROLS)
    if c.model == "NMSK":
        return lambda x, u, p, t: sum(a_**2 for a_ in c.muscle_activations(x, p).values())
    return None


def goal_mtb(c: GoalContext):
    """Mtb (Eq 6.7 with Eq 5.56), NMSK only: Ė = B + smax(Ȧ + Ṁ + Ṡ + Ẇ) as
    :func:`gaitlib.metabolics.metabolic_rate`, with Ȧ + Ṁ + Ṡ + Ẇ the lifted control
    ``edot_rest``."""
    if c.model != "NMSK":
        return None
    return lambda x, u, p, t: mtb_scale(c.tf_of(p), c.stride) * (c.basal + metabolics.smooth_max0(u["edot_rest"], 0.1)) ** 2


def goal_trq(c: GoalContext):
    """Trq (Eq 4.11): net joint torques of the 6 leg joints tracking the data."""
    rg, node = c.ranges, c.node
    return lambda x, u, p, t, d: sum(_sq(node(x, u, p)["tau_net"][cv.JOINTS.index(j)] - d[f"ref_tau_{j}"],
                                         rg[f"tau_{j}"]) for j in LEG_JOINTS)


def goal_ang(c: GoalContext):
    """Ang (Eq 4.9): the 6 leg joint angles tracking the data."""
    rg = c.ranges
    return lambda x, u, p, t, d: sum(_sq(x[j] - d[f"ref_{j}"], rg[j]) for j in LEG_JOINTS)


def goal_grf(c: GoalContext):
    """GRF (Eq 4.11): the foot forces tracking the data."""
    rg, node = c.ranges, c.node
    return lambda x, u, p, t, d: sum(_sq(node(x, u, p)["grf"][i] - d[f"ref_{g}"], rg[g])
                                     for i, g in enumerate(GRF_CHANNELS))


def goal_q(c: GoalContext):
    """Q: every coordinate tracking its reference (``c.q_tracked``: all but the metatarsal
    angles when :attr:`GaitSpec.track_mtp` is ``False``)."""
    rg = c.ranges
    return lambda x, u, p, t, d: sum(_sq(x[k] - d[f"ref_{k}"], rg[k]) for k in c.q_tracked)


#: Cost term name → goal factory, in the order build() adds them.
COST_TERMS = {"Jrk": goal_jrk, "Rsd": goal_rsd, "Imp": goal_imp, "HAT": goal_hat, "Act": goal_act,
              "Mtb": goal_mtb, "Trq": goal_trq, "Ang": goal_ang, "GRF": goal_grf, "Q": goal_q}


def spec_gait_data(spec: GaitSpec) -> tuple[data_mod.GaitData, data_mod.GaitData]:
    """(the speed class's data, the data the spec tracks): the same unless ``track_class``
    is set (then that class's data scaled in time to the speed class's cycle)."""
    # the default call unless the spec asks for another order (a gap diagnosis on a user's
    # data set substitutes load_gait_data for its default arguments: gaitlib.studies.gap.own_data)
    order = {"fourier_order": spec.fourier_order} if spec.fourier_order else {}
    if spec.leg_scale is not None:
        order["leg_scale"] = float(spec.leg_scale)
    gait_class = data_mod.load_gait_data(spec.speed_class, spec.source, **order)
    gait = (data_mod.time_scaled(data_mod.load_gait_data(spec.track_class, spec.source, **order), gait_class)
            if spec.track_class else gait_class)
    return gait_class, gait


def spec_model(spec: GaitSpec) -> ChildModel:
    """The child model a spec is solved on (the thesis's, or its legs × ``spec.leg_scale``)."""
    return ChildModel() if spec.leg_scale is None else ChildModel(leg_scale=float(spec.leg_scale))


def spec_mass(spec: GaitSpec) -> float:
    """The body mass a spec is solved with (kg): :func:`spec_model`'s segment masses with the
    spec's body parameters (both legs)."""
    model = spec_model(spec)
    return model.total_mass(params_mod.body_params(spec.body_params, model))


def build(spec: GaitSpec) -> GaitProblem:
    """Turn a :class:`GaitSpec` into an :class:`ocp.Problem` with mesh, options, guess."""
    model = spec_model(spec)
    gait_class, gait = spec_gait_data(spec)
    p_body = params_mod.body_params(spec.body_params, model)
    p_contact = contact_params_of(spec)
    ref = reference(gait, model, p_contact, jerk_ranges=spec.jerk_ranges or "reference",
                    track_norm=spec.track_norm or "range")
    if spec.hat_reference:
        ref = _with_hat_reference(ref, spec.hat_reference)
    T = gait.cycle_time
    stride = gait.speed * T  # fixed stride length, also with a free final time
    w = spec.term_weights
    nmsk = spec.model == "NMSK"
    free_tf = bool(spec.tf_bounds)
    mtgp = mtg_params_of(spec) if spec.model != "SK" else None

    states = _states(spec)
    controls = _controls(spec)
    Qn, QDn, QDDn = list(cv.COORDS), [f"qd_{c}" for c in cv.COORDS], [f"qdd_{c}" for c in cv.COORDS]
    JRK = [f"jerk_{c}" for c in cv.COORDS]

    # ---- static parameters
    params: list[Parameter] = []
    if spec.free_contact:
        lo, hi = contact_mod.bounds()  # Table 4.7
        if spec.contact_bounds == "widened":  # … widened to contain the guess
            lo, hi = np.minimum(lo, p_contact), np.maximum(hi, p_contact)
        if spec.friction_floor is not None:  # the friction coefficients' lower bound raised
            lo = contact_mod.with_friction_floor(lo, spec.friction_floor)
            hi = np.maximum(hi, lo)
        for n_, l_, h_, g_ in zip(contact_mod.param_names(), lo, hi, p_contact):
            params.append(Parameter(f"c.{n_}", float(l_), float(h_), float(g_)))
    if spec.free_body:
        lo, hi = model.p_body_bounds()
        for n_, l_, h_, g_ in zip(model.p_body_names, lo, hi, p_body):
            params.append(Parameter(f"b.{n_}", float(l_), float(h_), float(g_)))
    if free_tf:
        # t_f as a static parameter too, so that integrands (Jrk, Mtb) can use it; an
        # endpoint constraint ties it to the phase's final time
        params.append(Parameter("t_f", float(spec.tf_bounds[0]), float(spec.tf_bounds[1]),
                                float(np.clip(T, *spec.tf_bounds))))
    if nmsk:
        act_fixed = activation_values(spec)
        if spec.free_activation:
            for k in ACTIVATION_PARAMS:
                params.append(Parameter(f"act.{k}", *map(float, activation.ACTIVATION_BOUNDS[k]), act_fixed[k]))

    fx = None  # candidate unmodelled effects (gaitlib.effects)
    if spec.effects:
        fx = effects_mod.bind(spec, effects_mod.Context(spec, model, ref, T, p_body, p_contact))
        params += fx.parameters

    def pvec(p: Named):
        pc = ca.vertcat(*[p[f"c.{n}"] for n in contact_mod.param_names()]) if spec.free_contact else ca.DM(p_contact)
        pb = ca.vertcat(*[p[f"b.{n}"] for n in model.p_body_names]) if spec.free_body else ca.DM(p_body)
        if fx is not None:
            pb, pc = fx.body(pb, p), fx.contact(pc, p)
        return pb, pc

    def tf_of(p: Named):
        return p["t_f"] if free_tf else T

    def act_of(p: Named) -> dict:
        """Activation parameters γ (Eq 5.53): NLP variables or Table 5.10 values."""
        return {k: (p[f"act.{k}"] if spec.free_activation else act_fixed[k]) for k in ACTIVATION_PARAMS}

    def muscle_activations(x: Named, p: Named) -> dict:
        """a = c3 √u + (1 − c3) u (Eq 5.37, smoothed √, activation.neural_to_muscle_activation)."""
        c3 = act_of(p)["c3"]
        return {m: activation.neural_to_muscle_activation(x[f"u_{m}"], c3) for m in NMSK_MUSCLES}

    f_id = model.function("inverse_dynamics")
    f_ct = model.function("contact")
    f_pas = model.function("passive")
    cache: dict = {}

    def node(x: Named, u: Named, p: Named):
        """Inverse dynamics, contact and input torques at a node, computed once per trace."""
        key = (id(x), id(u), id(p))
        if key in cache:
            return cache[key]
        q, qd, qdd = x[Qn], x[QDn], x[QDDn]
        pb, pc = pvec(p)
        tau_id, R_id = f_id(q, qd, qdd, pb, pc)
        ct = f_ct(q=q, qd=qd, p_contact=pc)
        extra = {}
        if spec.model == "SK":
            tau_in = ca.vertcat(*[u[f"tau_{j}"] for j in cv.JOINTS])
        elif spec.model == "MSK":
            tin = {}
            for s in cv.SIDES:
                for j in ("hip", "knee", "ankle"):
                    c = f"{j}_{s}"
                    tin[c] = mtg.joint_torque(j, x[c], x[f"qd_{c}"], u[f"a_{j}_ext_{s}"], u[f"a_{j}_flex_{s}"], mtgp)
                tin[f"mtp_{s}"] = u[f"tau_mtp_{s}"]
            tau_in = ca.vertcat(*[tin[j] for j in cv.JOINTS])
            extra["a_gen"] = {k[2:]: u[k] for k in MTG_CONTROLS}
        else:  # NMSK: muscle activations → 12 generator activations (Eq 5.54) → MTGs

            am = muscle_activations(x, p)
            ap = act_of(p)
            tin, extra["a_gen"] = {}, {}
            for s in cv.SIDES:
                ag = activation.generator_activations(am, ap["s1"], ap["s2"], side=s)
                extra["a_gen"].update({f"{g}_{s}": v for g, v in ag.items()})
                for j in ("hip", "knee", "ankle"):
                    c = f"{j}_{s}"
                    tin[c] = mtg.joint_torque(j, x[c], x[f"qd_{c}"], ag[f"{j}_ext"], ag[f"{j}_flex"], mtgp)
                tin[f"mtp_{s}"] = u[f"tau_mtp_{s}"]
            tau_in = ca.vertcat(*[tin[j] for j in cv.JOINTS])
            extra["a_muscle"] = am
        R_in = ca.vertcat(*[u[r] for r in cv.RESIDUALS])
        load = fx.root_load(x, p) if fx is not None else None
        if load is not None:
            R_id = R_id + load  # an effect's extra load on the HAT (gaitlib.effects)
        # net joint torque = actuators + joint spring–dampers: what the data report
        tau_net = tau_in + f_pas(q, qd, pb)
        out = {"tau_id": tau_id, "R_id": R_id, "tau_in": tau_in, "R_in": R_in, "tau_net": tau_net,
               "grf": ca.vertcat(ct["grf_x"][0], ct["grf_y"][0], ct["grf_x"][1], ct["grf_y"][1]),
               "fn_raw": ct["fn_raw"], "depth": ct["depth"], **extra}
        cache[key] = out
        return out

    rg = ref.ranges
    path = [PathConstraint("dynamics", lambda x, u, p, t: ca.vertcat(node(x, u, p)["R_id"] - node(x, u, p)["R_in"],
                                                                        node(x, u, p)["tau_id"] - node(x, u, p)["tau_in"]),
                           0.0, 0.0)]
    if spec.normal_force_constraint:
        path.append(PathConstraint("normal_force", lambda x, u, p, t: node(x, u, p)["fn_raw"], 0.0, np.inf))
    if spec.max_sink is not None:  # ablation: no ellipsoid deeper than max_sink in the ground
        path.append(PathConstraint("sink", lambda x, u, p, t: node(x, u, p)["depth"], -np.inf, float(spec.max_sink)))
    if spec.swing_load_max is not None:  # ablation: no vertical load on a foot the data say swings
        windows = data_mod.swing_windows(gait.events, gait.left_shift)

        def swinging(t, window):
            """1 at times in the window (cycle fraction t / T, wrapped), else 0 (t is SX)."""
            lo, hi = window
            tau = t / T
            return ca.logic_or(ca.logic_and(tau >= lo, tau <= hi),
                               ca.logic_and(tau + 1.0 >= lo, tau + 1.0 <= hi))

        path.append(PathConstraint(
            "swing_load",
            lambda x, u, p, t: ca.vertcat(swinging(t, windows["r"]) * node(x, u, p)["grf"][1],
                                          swinging(t, windows["l"]) * node(x, u, p)["grf"][3]),
            -np.inf, float(spec.swing_load_max)))
    if fx is not None:  # effects' path constraints, each expr ≥ 0 (co-contraction)
        def fx_path(e_, m_):
            return lambda x, u, p, t: e_.path(node(x, u, p), fx.theta(e_, m_, p), fx.ctx)

        for e_, m_ in fx.items:
            if e_.path is not None:
                path.append(PathConstraint(f"fx_{e_.name}", fx_path(e_, m_), 0.0, np.inf))
    endpoint = []
    if spec.free_contact:
        def ratio(x0, xf, p, t0, tf):
            out = []
            for e in cv.ELLIPSOIDS:
                out += [p[f"c.{e}.mu_d"] - 0.55 * p[f"c.{e}.mu_s"], 0.99 * p[f"c.{e}.mu_s"] - p[f"c.{e}.mu_d"]]
            return ca.vertcat(*out)
        endpoint.append(ocp.EndpointConstraint("friction_ratio", ratio, 0.0, np.inf))
    if free_tf:
        endpoint.append(ocp.EndpointConstraint("t_f", lambda x0, xf, p, t0, tf: tf - p["t_f"], 0.0, 0.0))
    endpoint = tuple(endpoint)

    # ---- initial guess (before the goals: the NMSK Mtb term's t_stim comes from it)
    guess = initial_guess(spec, model, ref, p_body, p_contact)
    edot = None  # NMSK: the metabolic rate per node (GaitProblem.edot)
    t_stim: tuple = ()
    if nmsk:
        if spec.t_stim is not None:
            t_stim = tuple(float(spec.t_stim) for _ in NMSK_MUSCLES)
        else:
            g0 = guess.phases["cycle"]
            tg = np.asarray(g0.time, float)
            t_stim = tuple(metabolics.stimulation_time(tg[:-1], np.asarray(g0.controls[f"ed_{m}"], float)[:-1],
                                                       period=T) for m in NMSK_MUSCLES)
        # Ė at a node (Eq 5.38, metabolics.nmsk_metabolic_rate): heats from the excitation
        # that drives the activation dynamics (ẽ = e(t − d)), MTG torques from the muscle
        # activations, work of the MTG and metatarsal joints
        xs_, us_ = ca.SX.sym("x", len(states)), ca.SX.sym("u", len(controls))
        ps_, ts_ = ca.SX.sym("p", len(params)), ca.SX.sym("t_stim", len(NMSK_MUSCLES))
        xn_, un_ = Named(xs_, states, "state"), Named(us_, controls, "control")
        pn_ = Named(ps_, tuple(p_.name for p_ in params), "parameter")
        ap_ = act_of(pn_)
        r = metabolics.nmsk_metabolic_rate(
            {j: xn_[j] for j in cv.JOINTS}, {j: xn_[f"qd_{j}"] for j in cv.JOINTS},
            {m: un_[f"ed_{m}"] for m in NMSK_MUSCLES}, muscle_activations(xn_, pn_), mtgp,
            s1=ap_["s1"], s2=ap_["s2"], mtp_torques={f"mtp_{s}": un_[f"tau_mtp_{s}"] for s in cv.SIDES},
            t_stim={m: ts_[i] for i, m in enumerate(NMSK_MUSCLES)},
            isometric_torque=spec.isometric_torque or "thesis")
        parts = ("total", "activation", "maintenance", "shortening", "basal", "work")
        edot = ca.Function("edot", [xs_, us_, ps_, ts_], [r[k] for k in parts],
                                        ["x", "u", "p", "t_stim"], list(parts))
        basal = float(sum(metabolics.basal_rate(m) for m in NMSK_MUSCLES))
        if "Mtb" in w:
            guess = _with_edot_rest_guess(guess, states, controls, params, edot, t_stim)
    t_stim_dm = ca.DM(list(t_stim)) if t_stim else None

    def edot_rest(x: Named, u: Named, p: Named):
        """Ȧ + Ṁ + Ṡ + Ẇ (Eq 5.38 without the basal rate), W."""
        out = edot(x.vec, u.vec, p.vec, t_stim_dm)
        return out[1] + out[2] + out[3] + out[5]

    if nmsk and "Mtb" in w:
        # Ė lifted: edot_rest = Ȧ + Ṁ + Ṡ + Ẇ as a path constraint, Mtb on B + smax(edot_rest)
        path.append(PathConstraint("metabolic_rate", lambda x, u, p, t: u["edot_rest"] - edot_rest(x, u, p),
                                   0.0, 0.0))

    goals = []
    ctx = GoalContext(model=spec.model, ranges=rg, node=node, tf_of=tf_of, stride=stride,
                      muscle_activations=muscle_activations if nmsk else None, basal=basal if nmsk else 0.0,
                      q_tracked=tuple(k for k in cv.COORDS if spec.track_mtp is not False or not k.startswith("mtp")))
    for name, factory in COST_TERMS.items():
        f = factory(ctx) if name in w else None
        if f is None:
            continue
        if fx is not None and ocp._accepts_data(f):  # effects may override references
            f = (lambda f_: lambda x, u, p, t, d: f_(x, u, p, t, fx.wrap_data(d, p, t)))(f)
        goals.append(Goal(name, weight=w[name], integrand=f, divide_by_duration=True))
    rb = dict(zip(cv.RESIDUALS, spec.residual_bounds))
    unused = set(w) - {g.name for g in goals}
    if unused:
        raise ValueError(f"cost terms {sorted(unused)} are not defined for model {spec.model}")

    # ---- data on normalised time τ ∈ [0, 1]
    data_frame = tracking_frame(spec, ref)

    # ---- bounds (generous, from the data; thesis: "based on the standard deviation")
    bounds = joint_angle_bounds(gait_class)  # speed_class's own data, also when tracking another class's
    bounds["pelvis_tilt"] = (-30 * cv.DEG, 30 * cv.DEG)
    bounds["pelvis_ty"] = (0.5, 1.0)
    bounds["pelvis_tx"] = (-0.5, stride + 0.5)
    for c in cv.COORDS:
        bounds[f"qd_{c}"] = (-20.0, 20.0)
        bounds[f"qdd_{c}"] = (-500.0, 500.0)
        bounds[f"jerk_{c}"] = (-2e4, 2e4)
    for r, b in rb.items():
        bounds[r] = (-b, b)
    if spec.model == "SK":
        for j in cv.JOINTS:
            bounds[f"tau_{j}"] = (-250.0, 250.0)
    else:
        if nmsk:
            for m in NMSK_MUSCLES:
                bounds[f"ed_{m}"] = tuple(map(float, activation.EXCITATION_BOUNDS))  # [0, 0.8], Sec 5.3.4
                bounds[f"u_{m}"] = (0.0, 1.0)
            if "edot_rest" in controls:
                bounds["edot_rest"] = (-1e4, 1e4)
        else:
            for a in MTG_CONTROLS:
                bounds[a] = (0.0, 1.0)
        for s in cv.SIDES:
            bounds[f"tau_mtp_{s}"] = (-150.0, 150.0)

    periodic = None
    if spec.periodic:
        periodic = Periodic(states, offsets={"pelvis_tx": stride})

    def dynamics(x, u, p, t):
        xdot = [x[QDn], x[QDDn], u[JRK]]
        if nmsk:  # Eq 5.34 on the delayed excitation ẽ = e(t − d) (module docstring)
            tau_act = act_of(p)["tau_act"]
            xdot += [activation.activation_rate(x[f"u_{m}"], u[f"ed_{m}"], tau_act) for m in NMSK_MUSCLES]
        return ca.vertcat(*xdot)

    phase = Phase(
        name="cycle", states=states, controls=controls,
        dynamics=dynamics,
        t0=0.0, tf=tuple(map(float, spec.tf_bounds)) if free_tf else T, bounds=bounds, initial={"pelvis_tx": 0.0},
        path_constraints=tuple(path), endpoint_constraints=endpoint, goals=tuple(goals),
        periodic=periodic, data=data_frame,
    )
    problem = Problem(phases=(phase,), parameters=tuple(params), name=f"gait_{spec.model}_{spec.cost}".replace(".", ""))
    mesh = Mesh(spec.n_intervals, spec.scheme, spec.degree, defect_form=spec.defects or "differential")
    options = SolverOptions(tol=spec.tol, max_iter=spec.max_iter, hessian=spec.hessian,
                            **({"derivatives": spec.derivatives} if spec.derivatives else {}))
    return GaitProblem(spec, model, ref, problem, mesh, options, guess, p_body, p_contact, t_stim,
                       node=node, effects=fx, edot=edot)


def tracking_frame(spec: GaitSpec, ref: Reference) -> pd.DataFrame:
    """The phase's per-node data (NLP parameters) on normalised time τ = t / T: the
    references ``ref_<coordinate>``, ``ref_tau_<joint>``, ``ref_<grf>`` and any columns
    the spec's effects need. ``Transcription.solve(data={"cycle": frame})`` with the frame
    of another data set re-solves the same NLP on it (:func:`gaitlib.gap.diagnose`)."""
    tau_grid = ref.q.index.to_numpy() / ref.gait.cycle_time
    dat = {f"ref_{c}": ref.q[c].to_numpy() for c in cv.COORDS}
    dat.update({f"ref_tau_{j}": ref.tau[j].to_numpy() for j in LEG_JOINTS})
    dat.update({f"ref_{g}": ref.grf[g].to_numpy() for g in GRF_CHANNELS})
    if spec.effects:
        dat.update(effects_mod.data_columns(spec, ref, tau_grid))
    return pd.DataFrame(dat, index=tau_grid)


def initial_guess(spec: GaitSpec, model: ChildModel, ref: Reference, p_body, p_contact) -> Guess:
    """Data-based guess (thesis Sec 4.3.2): states and jerks from Fourier fits of the
    reference; actuator torques = data (net) torques − joint spring–dampers (metatarsal 0) or, for MSK, activations from the
    inverse MTG (Sec 5.2.1); residuals 0."""
    T = ref.gait.cycle_time
    t = np.linspace(0.0, T, 201)
    S, C = {}, {}
    for c in cv.COORDS:
        v = ref.deriv[c](t)
        S[c], S[f"qd_{c}"], S[f"qdd_{c}"] = v[0], v[1], v[2]
        C[f"jerk_{c}"] = v[3]
    for r in cv.RESIDUALS:
        C[r] = np.zeros_like(t)
    # the data's torques are net joint torques; the actuators supply net − passive
    Qg = np.array([S[c] for c in cv.COORDS])
    Qdg = np.array([S[f"qd_{c}"] for c in cv.COORDS])
    pas = np.asarray(model.function("passive").map(t.size)(Qg, Qdg, np.tile(np.asarray(p_body)[:, None], t.size)))
    tau = {j: np.interp(t, ref.tau.index, ref.tau[j]) - pas[cv.JOINTS.index(j)] for j in LEG_JOINTS}
    if spec.model == "SK":
        for j in cv.JOINTS:
            C[f"tau_{j}"] = tau.get(j, np.zeros_like(t))
    else:
        for s in cv.SIDES:
            C[f"tau_mtp_{s}"] = np.zeros_like(t)
            for j in ("hip", "knee", "ankle"):
                c = f"{j}_{s}"
                a = mtg.activation_for_torque(j, tau[c], S[c], S[f"qd_{c}"], mtg_params_of(spec))
                C[f"a_{j}_ext_{s}"] = np.asarray(a["a_ext"], float)
                C[f"a_{j}_flex_{s}"] = np.asarray(a["a_flex"], float)
        if spec.model == "NMSK":
            Sx, Cx = _nmsk_guess(spec, ref, t, {k: C.pop(k) for k in MTG_CONTROLS})
            S.update(Sx)
            C.update(Cx)
    return Guess(phases={"cycle": PhaseGuess(time=t, states=S, controls=C)})


def _invert_muscle_activation(a, c3: float, delta: float = 1e-4):
    """u with neural_to_muscle_activation(u, c3) = a (Eq 5.37 inverted; monotone), 1."""
    ug = np.linspace(0.0, 1.0, 20001)
    return np.interp(a, activation.neural_to_muscle_activation(ug, c3, delta), ug)


def _periodic_interp(t_src, y, period: float, t):
    """Linear interpolation of periodic samples ``y`` at ``t_src`` (one period, no repeated
    end point) to times ``t`` (any, wrapped)."""
    t_src = np.asarray(t_src, float)
    ts = np.concatenate([t_src - period, t_src, t_src + period])
    return np.interp(np.mod(np.asarray(t, float) - t_src[0], period) + t_src[0], ts, np.tile(y, 3))


def _nmsk_guess(spec: GaitSpec, ref: Reference, t, a_gen: dict):
    """NMSK guess (states ``u_*``, controls ``ed_*``) on ``t`` (0 … T, end point included)
    from generator activations ``a_gen`` (names :data:`MTG_CONTROLS`, arrays over ``t``).

    Each muscle takes its generator's activation (Table 5.5; SOL, PL and GAM all take the
    ankle extensor's, which Eq 5.54 then reproduces exactly because s1 + s2 + (1 − s1 − s2)
    = 1), capped at the activation reachable with ẽ ≤ 0.8; Eq 5.37 is inverted for u and
    Eq 5.34 for the excitation, ẽ = the root ≥ 0 of c1 ẽ² + (c2 − c1 u) ẽ − (c2 u + u̇) = 0
    (u̇ from a periodic Fourier fit; ẽ = 0 where even ẽ = 0 cannot deactivate that fast),
    clipped to the bounds [0, 0.8]. With ``excitation_guess="emg"`` the data's processed EMG,
    delayed by d (the controls are ẽ(t) = e(t − d)), replaces this where the source has the
    muscle. The states are then the periodic solution of Eq 5.34 for these excitations
    (:func:`gaitlib.activation.simulate_activation`), so the guess satisfies the activation
    dynamics.
    """
    t = np.asarray(t, float)
    T = ref.gait.cycle_time
    ap = activation_values(spec)
    tau_act, c3 = ap["tau_act"], ap["c3"]
    tau_deact = activation.DEACTIVATION_RATIO * tau_act
    c1, c2 = 1.0 / tau_act - 1.0 / tau_deact, 1.0 / tau_deact
    e_lo, e_hi = map(float, activation.EXCITATION_BOUNDS)
    a_hi = activation.neural_to_muscle_activation(e_hi, c3)
    emg = {}
    if spec.excitation_guess == "emg":
        gait = ref.gait
        tg = np.asarray(gait.time, float)
        n = len(tg) - 1 if np.isclose(tg[-1] - tg[0], T) else len(tg)  # drop a repeated end point
        for m in NMSK_MUSCLES:
            base, side = m.rsplit("_", 1)
            stem = activation.EMG_CHANNELS[base].get(gait.source)
            col = f"{stem}_{side}" if stem else None
            if col and col in gait.mean.columns:
                y = activation.delay_periodic(gait.mean[col].to_numpy(float)[:n], activation.DELAY, T)
                emg[m] = _periodic_interp(tg[:n], y, T, t)
    S, C = {}, {}
    for m in NMSK_MUSCLES:
        if m in emg:
            ed = emg[m]
        else:
            base, side = m.rsplit("_", 1)
            a = np.clip(a_gen[f"a_{activation.MUSCLE_GENERATOR[base]}_{side}"], 0.0, a_hi)
            u = _invert_muscle_activation(a, c3)
            du = _fourier_derivatives(u, T, order=12, n_der=1)(t)[1]
            b = c2 - c1 * u
            rhs = c2 * u + du
            ed = np.where(rhs > 0, (-b + np.sqrt(np.maximum(b * b + 4 * c1 * rhs, 0.0))) / (2 * c1), 0.0)
        C[f"ed_{m}"] = np.clip(ed, e_lo, e_hi)
    E = np.column_stack([C[f"ed_{m}"][:-1] for m in NMSK_MUSCLES])
    U, _ = activation.simulate_activation(t[:-1], E, tau_act, c3, delay=0.0, periodic=True, period=T)
    for i, m in enumerate(NMSK_MUSCLES):
        S[f"u_{m}"] = np.append(U[:, i], U[0, i])
    return S, C


def _with_edot_rest_guess(guess: Guess, states, controls, params, f_edot, t_stim) -> Guess:
    """``guess`` with the lifted control ``edot_rest`` = Ȧ + Ṁ + Ṡ + Ẇ evaluated on it."""
    g = guess.phases["cycle"]
    n = len(np.asarray(g.time))
    X = np.array([np.asarray(g.states[k], float) for k in states])
    U = np.array([np.asarray(g.controls[k], float) if k in g.controls else np.zeros(n) for k in controls])
    pv = np.array([guess.parameters.get(p_.name, p_.initial()) for p_ in params], float).reshape(-1, 1)
    out = f_edot.map(n)(X, U, np.tile(pv, n), np.tile(np.reshape(np.asarray(t_stim, float), (-1, 1)), n))
    rest = np.asarray(out[1] + out[2] + out[3] + out[5], float).ravel()
    C = {**dict(g.controls), "edot_rest": rest}
    return Guess(phases={"cycle": PhaseGuess(time=g.time, states=g.states, controls=C, t0=g.t0, tf=g.tf)},
                 parameters=dict(guess.parameters))


# ======================================================================================
# Solution
# ======================================================================================


@dataclass(eq=False)
class GaitSolution:
    """A solved gait: the raw :class:`ocp.Solution` plus tidy, named results.

    Frames are indexed by time (s) at the collocation nodes: ``q`` (11 coordinates, SI),
    ``torques`` (8 net joint torques, N·m: actuators + joint spring–dampers, comparable
    with the data), ``torques_active`` (the actuators' share: SK controls, MSK MTGs), ``residuals`` (3), ``grf`` (per foot
    grf_x_r, grf_y_r, grf_x_l, grf_y_l, N), ``ellipsoids`` (fn/fx per ellipsoid, N; vs: its slip velocity, m/s),
    ``activations`` (MSK: the controls; NMSK: the 12 generator activations of Eq 5.54, same
    column names). ``rmse`` is a table per channel against the data mean (on normalised time
    when the final time is free).

    NMSK only: ``excitations`` (16 muscles, e(t) = ẽ(t + d): the neural command, comparable
    with EMG; the controls ``ed_*`` in ``solution`` are the delayed ẽ), ``muscle_activations``
    (16, Eq 5.37) and ``metabolic`` (Ė and its components of Eq 5.38, W, with the NLP's
    t_stim). ``stats`` then also has ``COT`` (Eq 5.57, J kg⁻¹ m⁻¹, with the NLP's t_stim),
    ``COT_t_stim_solution`` (t_stim re-estimated from the solution's excitations, as the
    thesis's definition of t_stim reads), ``t_stim_s`` and ``activation_parameters``.
    """

    spec: GaitSpec
    solution: ocp.Solution
    q: pd.DataFrame
    qd: pd.DataFrame
    torques: pd.DataFrame
    residuals: pd.DataFrame
    grf: pd.DataFrame
    ellipsoids: pd.DataFrame
    activations: pd.DataFrame | None
    rmse: pd.DataFrame
    stats: dict
    torques_active: pd.DataFrame | None = None
    excitations: pd.DataFrame | None = None
    muscle_activations: pd.DataFrame | None = None
    metabolic: pd.DataFrame | None = None

    @property
    def success(self) -> bool:
        return self.solution.success

    def summary(self) -> dict:
        """JSON-able summary: spec, solver stats, cost terms, RMSE table, parameters."""
        return {
            "spec": self.spec.to_dict(),
            "stats": {k: (float(v) if isinstance(v, (np.floating, float)) else v) for k, v in self.stats.items()},
            "goals": self.solution.goals.to_dict(orient="records"),
            "rmse": self.rmse.to_dict(orient="records"),
            "parameters": self.solution.parameters,
        }

    def save(self, path) -> Path:
        """Directory with the raw solution (``ocp/``), ``spec.json``, ``summary.json`` and
        the tidy frames as CSV (``q.csv``, ``torques.csv``, ``grf.csv`` …)."""
        path = Path(path)
        self.solution.save(path / "ocp")
        (path / "spec.json").write_text(json.dumps(self.spec.to_dict(), indent=1))
        (path / "summary.json").write_text(json.dumps(self.summary(), indent=1, default=str))
        for name in ("q", "qd", "torques", "torques_active", "residuals", "grf", "ellipsoids", "activations",
                     "excitations", "muscle_activations", "metabolic"):
            frame = getattr(self, name)
            if frame is not None:
                frame.to_csv(path / f"{name}.csv", float_format="%.10g")
        self.rmse.to_csv(path / "rmse.csv", index=False, float_format="%.6g")
        return path

    @classmethod
    def load(cls, path) -> "GaitSolution":
        """Reload a saved solution: the frames are recomputed from the raw solution with
        the current code (:func:`postprocess`)."""
        path = Path(path)
        spec = GaitSpec.from_dict(json.loads((path / "spec.json").read_text()))
        return postprocess(build(spec), ocp.Solution.load(path / "ocp"))

    @classmethod
    def from_cache(cls, path, **stats) -> "GaitSolution":
        """:meth:`load` of a cache entry, with ``stats["from_cache"] = True``, its path and
        ``stats`` added; a failed solve reloads as failed without a warning (its status is
        the result)."""
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ocp.SolveFailedWarning)
            sol = cls.load(path)
        sol.stats.update(from_cache=True, cache_path=str(path), **stats)
        return sol


def rmse_table(sol_q, torques, grf, ref: Reference, time_scale: float = 1.0) -> pd.DataFrame:
    """RMSE per channel; the data are read at ``time_scale`` × the solution's times (T / t_f
    with a free final time: comparison on normalised time)."""
    gait = ref.gait
    t = sol_q.index.to_numpy() * time_scale
    rows = []

    def add(kind, ch, sim, dat, sd, unit, scale=1.0):
        err = sim - dat
        rmse = float(np.sqrt(np.mean(err**2)))
        rng = float(np.ptp(dat)) or 1.0
        rows.append({"kind": kind, "channel": ch, "rmse": rmse * scale, "nrmse (% range)": 100 * rmse / rng,
                     "mean |z| (SD units)": float(np.mean(np.abs(err) / np.maximum(sd, 1e-9))) if np.any(sd > 0) else np.nan,
                     "unit": unit})

    for j in LEG_JOINTS:  # against the tracked reference (hip: thigh in the laboratory)
        add("angle", j, sol_q[j].to_numpy(), np.interp(t, ref.q.index, ref.q[j]), np.interp(t, gait.time, gait.sd[j]),
            "deg", 1 / cv.DEG)
    for j in LEG_JOINTS:
        add("torque", j, torques[j].to_numpy(), np.interp(t, gait.time, gait.mean[f"tau_{j}"]),
            np.interp(t, gait.time, gait.sd[f"tau_{j}"]), "N*m")
    for g in GRF_CHANNELS:
        add("grf", g, grf[g].to_numpy(), np.interp(t, gait.time, gait.mean[g]), np.interp(t, gait.time, gait.sd[g]), "N")
    return pd.DataFrame(rows)


def solve(spec: GaitSpec | GaitProblem, guess: "Guess | ocp.Solution | GaitSolution | None" = None,
          progress: bool = False) -> GaitSolution:
    """Build (if needed) and solve; never hides a failure (``success``/``stats['status']``).

    ``guess``: default the data-based guess; or a :class:`~gaitlib.ocp.Guess`, or another
    solution (warm start; variables of the same name are interpolated in normalised time,
    the others keep the data-based guess). ``progress``: print IPOPT's iteration log every
    10 iterations (stdout).
    """
    gp = build(spec) if isinstance(spec, GaitSpec) else spec
    options = gp.options
    if progress:
        options = replace(options, print_level=5, ipopt={**dict(options.ipopt), "print_frequency_iter": 10})
    sol = ocp.solve(gp.problem, gp.mesh, options, warm_start(gp, guess))
    return postprocess(gp, sol)


def reference_on(gp: GaitProblem, gait) -> Reference:
    """``gp``'s reference with another data set's joint angles (hip: the thigh in the
    laboratory, :func:`gaitlib.kinematics.pose_from_data`), net torques and GRFs, on the same
    time grid; the HAT reference (an estimate from the spec's own data, not data) is kept.
    ``gait``: a :class:`~gaitlib.data.GaitData` with the spec's cycle (same time grid)."""
    base = gp.ref
    t = np.asarray(base.q.index, float)
    if len(t) != len(gait.time) or not np.allclose(t, gait.time):
        raise ValueError("data set's time grid differs from the spec's data (load it with gaitlib.gap.io)")
    Q = kinematics.pose_from_data(gp.model, gait, t, gp.p_contact, penetration=0.002, thigh="lab")
    q = base.q.copy()
    for c in cv.JOINTS:
        q[c] = Q[:, cv.COORDS.index(c)]
    tau = gait.mean[[f"tau_{j}" for j in LEG_JOINTS]].copy()
    tau.columns = list(LEG_JOINTS)
    grf = gait.mean[list(GRF_CHANNELS)].copy()
    deriv = dict(base.deriv)
    T = float(gait.cycle_time)
    for c in cv.JOINTS:
        deriv[c] = _fourier_derivatives(q[c].to_numpy(), T, 12)
    return replace(base, gait=gait, q=q, tau=tau, grf=grf, deriv=deriv)


def data_guess_on(gp: GaitProblem, gait) -> Guess:
    """The data-based initial guess (thesis Sec 4.3.2) of ``gp`` built from another data set's
    curves (:func:`reference_on`; HAT: the spec's reference)."""
    g = initial_guess(gp.spec, gp.model, reference_on(gp, gait), gp.p_body, gp.p_contact)
    ph0 = gp.problem.phases[0]
    if "edot_rest" in ph0.controls:
        g = _with_edot_rest_guess(g, ph0.states, ph0.controls, gp.problem.parameters, gp.edot, gp.t_stim)
    return g


def warm_start(gp: GaitProblem, guess) -> Guess:
    """The data-based guess of ``gp`` overridden by ``guess`` where names match.

    A solution of another model (e.g. SK for an MSK problem) contributes its states and
    its shared controls (jerks, residuals; SK joint torques become MSK metatarsal torques
    and, through the inverse MTG, activations) and its parameters of the same name.
    For an NMSK problem, an MSK solution's 12 MTG activations (or an SK solution's torques
    through the inverse MTG) become muscle activations, neural activations and delayed
    excitations by :func:`_nmsk_guess` (Table 5.5 muscle ↔ generator map, Eqs 5.37 and 5.34
    inverted); an NMSK solution contributes its own states and excitations. Solutions are
    read on normalised time t / t_f; with a free final time the guess's t_f is the
    solution's."""
    if guess is None:
        return gp.guess
    if isinstance(guess, Guess):
        return guess
    if isinstance(guess, GaitSolution):
        guess = guess.solution
    base = gp.guess.phases["cycle"]
    ph = guess.phase("cycle")
    T = float(base.time[-1])
    # the source's times mapped onto this problem's guess grid (0 … T): normalised time
    ts = ph.states.index.to_numpy() * (T / ph.tf) if gp.spec.tf_bounds else ph.states.index
    tc = ph.controls.index.to_numpy() * (T / ph.tf) if gp.spec.tf_bounds else ph.controls.index
    names_x = set(gp.problem.phases[0].states)
    names_u = set(gp.problem.phases[0].controls)
    S = {k: np.interp(base.time, ts, ph.states[k]) for k in ph.states.columns if k in names_x}
    C = dict(base.controls)
    for k in ph.controls.columns:
        if k in names_u:
            C[k] = np.interp(base.time, tc, ph.controls[k])
    if gp.spec.model in ("MSK", "NMSK") and "tau_hip_r" in ph.controls.columns:
        for s_ in cv.SIDES:
            C[f"tau_mtp_{s_}"] = np.interp(base.time, tc, ph.controls[f"tau_mtp_{s_}"])
            for j in ("hip", "knee", "ankle"):
                c = f"{j}_{s_}"
                tq = np.interp(base.time, tc, ph.controls[f"tau_{c}"])
                a = mtg.activation_for_torque(j, tq, S[c], S[f"qd_{c}"], mtg_params_of(gp.spec))
                C[f"a_{j}_ext_{s_}"] = np.asarray(a["a_ext"], float)
                C[f"a_{j}_flex_{s_}"] = np.asarray(a["a_flex"], float)
    src_drives = set(MTG_CONTROLS) <= set(ph.controls.columns) or "tau_hip_r" in ph.controls.columns
    if gp.spec.model == "NMSK" and src_drives and not set(EXCITATION_CONTROLS) <= set(ph.controls.columns):
        a_gen = {}
        for k in MTG_CONTROLS:
            v = C.pop(k, None)
            a_gen[k] = v if v is not None else np.interp(base.time, tc, ph.controls[k])
        Sx, Cx = _nmsk_guess(gp.spec, gp.ref, base.time, a_gen)
        S.update(Sx)
        C.update(Cx)
    params = {k: v for k, v in guess.parameters.items() if k in gp.problem.parameter_names}
    time = base.time
    if gp.spec.tf_bounds:
        tf_g = float(np.clip(ph.tf, *gp.spec.tf_bounds))
        time = np.asarray(base.time, float) * (tf_g / T)
        params["t_f"] = tf_g
    out = Guess(phases={"cycle": PhaseGuess(time=time, states={**dict(base.states), **S}, controls=C)},
                parameters=params)
    ph0 = gp.problem.phases[0]
    if "edot_rest" in ph0.controls and "edot_rest" not in ph.controls.columns:
        out = _with_edot_rest_guess(out, ph0.states, ph0.controls, gp.problem.parameters, gp.edot, gp.t_stim)
    return out


def _activation_solution(gp: GaitProblem, sol: ocp.Solution) -> dict[str, float]:
    """Activation parameters γ of an NMSK solution: identified (free) or the spec's fixed."""
    if gp.spec.free_activation:
        return {k: float(sol.parameters[f"act.{k}"]) for k in ACTIVATION_PARAMS}
    return activation_values(gp.spec)


def postprocess(gp: GaitProblem, sol: ocp.Solution) -> GaitSolution:
    spec, model = gp.spec, gp.model
    ph = sol.phase("cycle")
    X, U = ph.states, ph.controls
    t_u = U.index.to_numpy()
    Xu = ph.interpolate(t_u) if len(X) != len(U) else X
    if hasattr(Xu, "columns") and not set(cv.COORDS) <= set(Xu.columns):
        Xu = X.reindex(t_u)
    pb = np.array([sol.parameters[f"b.{n}"] for n in model.p_body_names]) if spec.free_body else gp.p_body
    pc = np.array([sol.parameters[f"c.{n}"] for n in contact_mod.param_names()]) if spec.free_contact else gp.p_contact
    if spec.effects:  # effects acting on body/contact parameters, at the solution's values

        ctx = effects_mod.Context(spec, model, gp.ref, gp.ref.gait.cycle_time, gp.p_body, gp.p_contact)
        pb, pc = effects_mod.numeric_body_contact(spec, ctx, sol.parameters, pb, pc)
    q = Xu[list(cv.COORDS)]
    qd = Xu[[f"qd_{c}" for c in cv.COORDS]]
    qd.columns = list(cv.COORDS)
    f_ct = model.function("contact").map(len(t_u))
    ct = f_ct(q.to_numpy().T, qd.to_numpy().T, ca.repmat(ca.DM(pc), 1, len(t_u)))
    ct = {k: np.asarray(v) for k, v in zip(model.function("contact").name_out(), ct)}
    grf = pd.DataFrame({"grf_x_r": ct["grf_x"][0], "grf_y_r": ct["grf_y"][0],
                        "grf_x_l": ct["grf_x"][1], "grf_y_l": ct["grf_y"][1]}, index=q.index)
    vs = slip_velocities(model, q.to_numpy(), qd.to_numpy(), pc)
    ell = {}
    for i, lab in enumerate(model.ellipsoid_labels):
        ell[f"fn_{lab}"] = ct["fn"][i]
        ell[f"fx_{lab}"] = ct["fx"][i]
    for i, lab in enumerate(model.ellipsoid_labels):
        ell[f"vs_{lab}"] = vs[i]  # slip velocity of the body point the friction law reads, m/s
    ellipsoids = pd.DataFrame(ell, index=q.index)
    nmsk_frames: dict = {}
    nmsk_stats: dict = {}
    if spec.model == "SK":
        torques = pd.DataFrame({j: U[f"tau_{j}"].to_numpy() for j in cv.JOINTS}, index=q.index)
        acts = None
    elif spec.model == "MSK":
        tq = {}
        for s in cv.SIDES:
            for j in ("hip", "knee", "ankle"):
                c = f"{j}_{s}"
                tq[c] = np.asarray(mtg.joint_torque(j, q[c].to_numpy(), qd[c].to_numpy(),
                                                    U[f"a_{j}_ext_{s}"].to_numpy(), U[f"a_{j}_flex_{s}"].to_numpy(),
                                                    mtg_params_of(spec)), float).ravel()
            tq[f"mtp_{s}"] = U[f"tau_mtp_{s}"].to_numpy()
        torques = pd.DataFrame({j: tq[j] for j in cv.JOINTS}, index=q.index)
        acts = U[list(MTG_CONTROLS)].copy()
    else:
        torques, acts, nmsk_frames, nmsk_stats = _postprocess_nmsk(gp, sol, Xu, U, q, qd)
    pas = np.asarray(model.function("passive").map(len(t_u))(q.to_numpy().T, qd.to_numpy().T,
                                                               np.tile(np.asarray(pb)[:, None], len(t_u))))
    active = torques
    torques = active + pd.DataFrame(pas.T, index=q.index, columns=list(cv.JOINTS))
    residuals = U[list(cv.RESIDUALS)].copy()
    time_scale = gp.ref.gait.cycle_time / ph.tf if spec.tf_bounds else 1.0
    rmse = rmse_table(q, torques, grf, gp.ref, time_scale)
    stats = {
        "status": sol.status, "success": sol.success, "iterations": sol.iterations,
        "solve_time_s": sol.solve_time, "build_time_s": sol.build_time,
        "solver_reused": bool(sol.info.get("solver_reused", False)),
        "time_per_iteration_s": sol.time_per_iteration, "objective": sol.objective,
        "max_violation": sol.max_violation, "n_variables": sol.info.get("n_variables"),
        "n_constraints": sol.info.get("n_constraints"), "spec_key": spec.key(),
        "tf_s": float(ph.tf),
        **nmsk_stats,
        **({"effects": _effects_values(spec, sol)} if spec.effects else {}),
    }
    return GaitSolution(spec, sol, q, qd, torques, residuals, grf, ellipsoids, acts, rmse, stats, active,
                        **nmsk_frames)


def _effects_values(spec: GaitSpec, sol: ocp.Solution) -> dict:
    return effects_mod.theta_of(spec, sol.parameters)


def _postprocess_nmsk(gp: GaitProblem, sol: ocp.Solution, Xu, U, q, qd):
    """NMSK frames: MTG torques from the states' muscle activations, generator activations,
    excitations e(t) = ẽ(t + d), muscle activations, metabolic rate and COT."""
    ph = sol.phase("cycle")
    tf = float(ph.tf)
    t_u = U.index.to_numpy()
    ap = _activation_solution(gp, sol)
    am = {m: np.asarray(activation.neural_to_muscle_activation(Xu[f"u_{m}"].to_numpy(), ap["c3"]), float)
          for m in NMSK_MUSCLES}
    tq, acts = {}, {}
    for s in cv.SIDES:
        ag = activation.generator_activations(am, ap["s1"], ap["s2"], side=s)
        for j in ("hip", "knee", "ankle"):
            c = f"{j}_{s}"
            acts[f"a_{j}_ext_{s}"], acts[f"a_{j}_flex_{s}"] = ag[f"{j}_ext"], ag[f"{j}_flex"]
            tq[c] = np.asarray(mtg.joint_torque(j, q[c].to_numpy(), qd[c].to_numpy(), ag[f"{j}_ext"],
                                                ag[f"{j}_flex"], mtg_params_of(gp.spec)), float).ravel()
        tq[f"mtp_{s}"] = U[f"tau_mtp_{s}"].to_numpy()
    torques = pd.DataFrame({j: tq[j] for j in cv.JOINTS}, index=q.index)
    acts = pd.DataFrame({k: acts[k] for k in MTG_CONTROLS}, index=q.index)
    # one period of control samples (drop a node at t_f that repeats t = 0, e.g. trapezoidal)
    per = t_u < tf - 1e-12 * max(tf, 1.0)
    tp = t_u[per]
    ed = {m: U[f"ed_{m}"].to_numpy()[per] for m in NMSK_MUSCLES}
    exc = pd.DataFrame({m: _periodic_interp(tp, ed[m], tf, t_u + activation.DELAY) for m in NMSK_MUSCLES},
                       index=q.index)
    mus = pd.DataFrame(am, index=q.index)
    # metabolic rate with the NLP's own function (the Mtb term's Ė)
    f = gp.edot
    names_x = list(gp.problem.phases[0].states)
    Xn = Xu[names_x].to_numpy().T
    Un = U[list(gp.problem.phases[0].controls)].to_numpy().T
    pv = np.array([sol.parameters[n] for n in gp.problem.parameter_names], float).reshape(-1, 1)

    def edot(t_stim):
        out = f.map(len(t_u))(Xn, Un, np.tile(pv, len(t_u)), np.tile(np.reshape(t_stim, (-1, 1)), len(t_u)))
        return {k: np.asarray(v, float).ravel() for k, v in zip(f.name_out(), out)}

    def cot(e_total):
        tt = np.append(tp, tf)  # close the cycle: Ė(t_f) = Ė(0) on a periodic gait
        ee = np.append(e_total[per], e_total[per][0])
        return metabolics.cost_of_transport(tt, ee, distance=gp.stride)

    E = edot(np.asarray(gp.t_stim, float))
    metab = pd.DataFrame(E, index=q.index)
    metab["per_kg"] = metab["total"] / cv.BODY_MASS
    ts_sol = [metabolics.stimulation_time(tp, ed[m], period=tf) for m in NMSK_MUSCLES]
    cot_nlp = cot(E["total"])
    stats = {
        "COT": cot_nlp,
        "COT_t_stim_solution": cot(edot(np.asarray(ts_sol))["total"]),
        "mean_metabolic_rate_W": cot_nlp * cv.BODY_MASS * gp.stride / tf,  # ∫Ė dt / t_f
        "t_stim_s": [float(v) for v in gp.t_stim],
        "t_stim_solution_s": [float(v) for v in ts_sol],
        "activation_parameters": {k: float(v) for k, v in ap.items()},
    }
    frames = {"excitations": exc, "muscle_activations": mus, "metabolic": metab}
    return torques, acts, frames, stats


def tracking_data(gait):
    """The data as the gait problem tracks them: the hip channels become the thigh's angle
    in the laboratory (:func:`gaitlib.conventions.thigh_in_lab`: data hip + data pelvic tilt,
    model signs; SD unchanged), because the model's HAT is upright while the data's pelvis
    tilts forward (:func:`gaitlib.kinematics.pose_from_data`)."""
    mean = gait.mean.copy()
    for s in cv.SIDES:
        mean[f"hip_{s}"] = cv.thigh_in_lab(mean[f"hip_{s}"], mean["pelvis_tilt"])
    return replace(gait, mean=mean, notes=tuple(getattr(gait, "notes", ()) or ()) +
                   ("hip = thigh in the laboratory (data hip + pelvic tilt)",))


def guess_signature(guess) -> str | None:
    """The identity of a warm start, as it enters a cache key (None for no warm start).

    A solution (:class:`GaitSolution` or :class:`~gaitlib.ocp.Solution`) is named by its
    status, objective and iterations, plus the ``guess_derivation`` its ``info`` records when
    the guess was derived from it (part of it, time-scaled …), so that two derivations of one
    solution never share a key. An :class:`~gaitlib.ocp.Guess` built from arrays is named by
    the SHA-256 of its content."""
    if guess is None:
        return None
    if isinstance(guess, GaitSolution):
        guess = guess.solution
    if isinstance(guess, ocp.Solution):
        sig = f"solution:{guess.status}:{guess.objective:.12g}:{guess.iterations}"
        derived = (getattr(guess, "info", None) or {}).get("guess_derivation")
        return f"{sig}:{derived}" if derived else sig
    if isinstance(guess, ocp.Guess):
        return "guess:" + _content_digest(guess)
    raise TypeError(f"warm start must be a GaitSolution, ocp.Solution or ocp.Guess, got {type(guess).__name__}")


def _content_digest(obj) -> str:
    """SHA-256 (16 hex digits) of a guess's numbers: frames, arrays, mappings, scalars."""
    import hashlib

    h = hashlib.sha256()

    def feed(o):
        if o is None or isinstance(o, (str, bool, int, float)):
            h.update(repr(o).encode())
        elif isinstance(o, pd.DataFrame):
            feed(list(map(str, o.columns)))
            feed(o.index.to_numpy(float))
            feed(o.to_numpy(float))
        elif isinstance(o, np.ndarray) or isinstance(o, (list, tuple)) and all(
                isinstance(v, (int, float)) for v in o):
            a = np.ascontiguousarray(np.asarray(o, float))
            h.update(repr(a.shape).encode())
            h.update(a.tobytes())
        elif isinstance(o, dict) or hasattr(o, "items"):
            for k in sorted(o, key=str):
                feed(str(k))
                feed(o[k])
        elif isinstance(o, (list, tuple)):
            for v in o:
                feed(v)
        elif hasattr(o, "__dataclass_fields__"):
            for k in o.__dataclass_fields__:
                feed(k)
                feed(getattr(o, k))
        else:
            raise TypeError(f"cannot fingerprint a {type(o).__name__} in a warm start")

    feed(obj)
    return h.hexdigest()[:16]


# -- cached solves -----------------------------------------------------------------------

def cache_dir(spec: GaitSpec, *, guess=None, root=None) -> Path:
    """Where :func:`solve_cached` stores (or finds) the solution of ``spec`` from ``guess``:
    keyed by the spec, the warm start's identity, the gait formulation's version and the
    data and identified sets the spec reads."""
    desc = {"kind": "gait", **spec.to_dict()}
    if guess is not None:
        desc["warm_start"] = guess_signature(guess)
    return cache.lookup("gait", desc, root, formulation=(FORMULATION,) + spec.effect_versions(),
                        identified=spec.identified_sets())


def load_cached(where) -> GaitSolution | None:
    """The gait solution stored at a :func:`gaitlib.cache.lookup` directory (or the same
    entry in the repository's store), with ``stats["from_cache"] = True``; None if absent.
    A failed solve reloads as failed (its warning silenced: the status is the result)."""
    found = cache.find(where, "spec.json")
    return None if found is None else GaitSolution.from_cache(found)


def solve_cached(spec: GaitSpec, *, use_cache: bool = True, root=None, guess=None,
                 progress: bool = False) -> GaitSolution:
    """Solve ``spec`` or reload it from the cache (never a stale entry: the key is the
    spec, the warm start, the formulation's version and the data). Failed solves are stored and reloaded as
    failed — their status is the result. ``guess``: a :class:`~gaitlib.ocp.Guess` or
    another :class:`~gaitlib.ocp.Solution` (warm start; part of the cache key via its
    objective and status only if given, so warm-started runs are cached separately)."""
    def fresh():
        sol = solve(spec, guess=guess, progress=progress)
        sol.stats["from_cache"] = False
        return sol

    return cache.solve_or_load(cache_dir(spec, guess=guess, root=root), fresh, GaitSolution.from_cache,
                               marker="spec.json", use_cache=use_cache)


def _solve_spec(arg):
    """Worker side of :func:`solve_specs`: ``(spec, guess, use_cache, root)`` → GaitSolution."""
    spec, guess, use_cache, root = arg
    return solve_cached(spec, use_cache=use_cache, root=root, guess=guess)


def solve_specs(specs: Mapping[str, Any], *, guesses: Mapping[str, Any] | None = None, use_cache: bool = True,
                cache_root=None, **sweep_kw) -> dict[str, sweep.RunRecord]:
    """Solve (or reload from the cache) named :class:`~gaitlib.problems.gait.GaitSpec` s as one
    sweep; ``value`` of each record is the :class:`~gaitlib.problems.gait.GaitSolution`.

    Parameters
    ----------
    specs : name → GaitSpec.
    guesses : optional name → warm start (a :class:`~gaitlib.ocp.Guess`, an
        :class:`~gaitlib.ocp.Solution` or a GaitSolution) for some of the specs.
    use_cache : reuse stored solutions and store new ones (:func:`solve_cached`).
    cache_root : the solutions cache; default :func:`gaitlib.cache.default_dir` *of this
        process*, resolved here and passed to every worker explicitly (workers of an
        existing cluster may have another ``GAITLIB_SOLUTIONS``).
    **sweep_kw : ``scheduler``, ``n_workers``, ``serial``, ``progress`` of :func:`gaitlib.sweep.sweep`.

    Returns
    -------
    dict name → :class:`~gaitlib.sweep.RunRecord` in the order of ``specs``; ``status`` is IPOPT's return
    status (``"error"`` if the run raised), ``ok`` True only for ``Solve_Succeeded`` or
    ``Solved_To_Acceptable_Level``. Cached failures come back as failures.
    """
    guesses = dict(guesses or {})
    unknown = sorted(set(guesses) - set(specs))
    if unknown:
        raise ValueError(f"guesses given for unknown runs: {unknown}")
    for name, spec in specs.items():
        if not isinstance(spec, GaitSpec):
            raise TypeError(f"specs[{name!r}] must be a GaitSpec, got {type(spec).__name__}")
    root = str(Path(cache_root if cache_root is not None else cache.default_dir()).resolve())
    items = {name: (spec, guesses.get(name), bool(use_cache), root) for name, spec in specs.items()}
    # runs already in the cache are reloaded here (no cluster is started for them)
    done = {}
    if use_cache:
        host = f"cache:{socket.gethostname()}:{os.getpid()}"
        for name, (spec, guess, _, _) in items.items():
            t0 = time.perf_counter()
            sol = load_cached(cache_dir(spec, guess=guess, root=root))
            if sol is not None:
                ok, status = sweep._status_of(sol)
                done[name] = sweep.RunRecord(name, ok, status, sol, None, time.perf_counter() - t0, host)
    todo = {k: v for k, v in items.items() if k not in done}
    ran = {r.name: r for r in sweep.sweep(_solve_spec, todo, **sweep_kw)} if todo else {}
    return {name: done[name] if name in done else ran[name] for name in items}
