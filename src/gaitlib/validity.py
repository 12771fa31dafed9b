"""Physical validity gates: is a solved motion a physically plausible child gait (or jump)?

:func:`check` reads a solution — a gait solution (:class:`gaitlib.problems.gait.GaitSolution`,
SK/MSK/NMSK, data tracking or predictive), a jump (``gaitlib.studies.jump.JumpSolution``)
or a contact identification (``gaitlib.studies.contact_id.ApproachResult``) — and returns
:class:`Gates`: a table of named checks, each with the measured value, its threshold, unit,
verdict and a note. A solution passes when every applicable check passes; a check that
does not apply to a kind of solution is listed with ``passed = None`` and says why.
:func:`check_frames` runs the same checks on plain frames (hand-made cases, other tools).
Nothing here solves; it only reads.

The checks (thresholds are the module constants below, with their sources)
--------------------------------------------------------------------------
``converged``      IPOPT's return status is ``Solve_Succeeded`` or
                   ``Solved_To_Acceptable_Level`` (:data:`CONVERGED_STATUSES`, the sweep's
                   rule). An acceptable-level stop met IPOPT's ``acceptable_*`` tolerances
                   over several iterations, not the requested ``tol``; it counts as
                   converged and its status is kept in the note.
``swing_load``     (data tracking: the cost tracks GRFs, angles, coordinates or torques,
                   so the run keeps the data's timing) the largest vertical force on a
                   foot while the *data* say that foot swings ≤ :data:`SWING_LOAD_BW` ×
                   body weight (2 % BW,
                   8.1 N for the 41.4 kg child). Right foot: swing from the data's foot-off
                   (fraction of the cycle, ``GaitData.events["foot_off"]``) to the end of
                   the cycle; left foot: the same window shifted by the data's left-leg
                   phase shift (``GaitData.left_shift``, the thesis's T_sh = opposite foot
                   contact). Each window is shortened by :data:`SWING_MARGIN` (2 % of the
                   cycle, the events' SD in Schwartz et al. 2008) at both ends. Time is
                   normalised by the solution's final time.
``double_support`` (every gait) fraction of the cycle with both feet loaded above
                   2 % BW ≤ :data:`DOUBLE_SUPPORT_MAX` (40 %). Walking has ≈ 20–25 %
                   double support in total (two phases of ≈ 10–12 %; Schwartz 2008 Free
                   speed: 19 %, Very Slow: 36 %); more than 40 % of the cycle with both feet
                   on the ground is not walking. For predictive runs this is the contact
                   check: their swing is their own, so the data's events do not apply.
``residual_force`` peak |R_x|, |R_y| on the HAT ≤ :data:`RESIDUAL_FORCE_FRACTION` (5 %) ×
                   the peak magnitude of the external (ground) force.
``residual_moment`` peak |R_z| ≤ :data:`RESIDUAL_MOMENT_FRACTION` (1 %) × COM height ×
                   peak external force.
                   Source: Hicks JL, Uchida TK, Seth A, Rajagopal A, Delp SL (2015) "Is my
                   model good enough? Best practices for verification and validation of
                   musculoskeletal models and simulations of movement", J Biomech Eng
                   137(2):020905 — its residual guideline, relative to the maximum external
                   force and (moments) the COM height. The text of the paper was not
                   available to us; the OpenSim documentation's checklist we could read
                   ("Simulation with OpenSim – Best Practices" and "Reserves and
                   Residuals", simtk-confluence OpenSim pages) gives the absolute
                   adult-gait forms: peak residual forces < 10–20 N (RRA: 10–25 N, RMS
                   5–15 N), peak residual moments < 75 N·m. The peak external force is
                   the solution's own (both feet): for the 41.4 kg child ≈ 450–750 N, so
                   5 % is ≈ 22–37 N, inside those ranges; the moment bound, ≈ 4–6 N·m at
                   a COM height of ≈ 0.84 m, is far stricter than 75 N·m. Our gait
                   problems bound the residuals to 1 N, 1 N, 0.1 N·m (thesis Eq 4.8),
                   so a converged gait passes by construction; trajectory optimisation
                   on the data's kinematics (Ch 4 (a)) does not.
``strength``       joint torques within the child's strength: per joint and direction the
                   peak active torque of the muscle torque generator that produces it,
                   s^τ τ0 E (thesis Eq 5.8 at a = 1, t^A = 1 and the eccentric plateau
                   t^V = E; τ0 scaled to the body by Eq 5.21). MSK/NMSK: the solution's own
                   MTG parameters (the Ch 5 identified set in the book). SK: the Ch 5
                   identified set too (:data:`SK_STRENGTH_PARAMS`): the pediatric strength
                   studies we found (isokinetic knee, Pediatr Phys Ther 18:3–18, 2006;
                   isokinetic ankle dorsiflexors, Scand J Rehabil Med 21:97–103, 1989;
                   hand-held dynamometry at 6–8 years, Pediatr Phys Ther 20:128–136, 2008)
                   miss the hip or give their values only in tables we could not read, so
                   no per-joint N·m/kg limit is stated here. Jump: the
                   adult Gymnast set (the jump model is the adult of thesis Table 3.1,
                   73.8 kg) scaled by Eq 5.21 to the model's mass and standing height, × 2
                   (the legs are doubled). Metatarsal joint (no MTG): bounded by the
                   ankle plantarflexor's peak in both directions, a generous bound (the
                   toe flexors are far weaker). The torque compared is the actuator's share
                   (SK controls, MSK/NMSK MTG torques incl. their passive part; the joint
                   spring–dampers of Table 4.2 are passive tissue, not strength).
``rom``            joint angles within the thesis's "maximum possible ranges of human
                   joint angles", Table 3.5 (from its refs [25, 104]): hip −30…100°, knee
                   −150…0°, metatarsal −45…80°, and the ankle row 50…110° (90° standing)
                   under either reading of its sign, −40…40° in ours (:data:`ROM_DEG`;
                   :func:`gaitlib.studies.jump.joint_bounds` reads it as −20…40°). For a
                   gait with data, a bound is widened to the tracked data's mean ± 1 SD
                   where the measured children go beyond it (the knee: +2.0° extension at
                   Free speed, +7.1° at Very Fast), since an angle the children show is
                   within their range. The thesis states no other joint range; its gait
                   bounds are "based on the standard deviation" of its data (Sec 4.3.2;
                   ours: mean ± 3 SD ± 15°, :func:`gaitlib.problems.gait.build`), which
                   every solution meets by construction. :data:`ROM_TOL_DEG` allows for
                   IPOPT's bound tolerance.
``periodicity``    (gait) max over the 11 coordinates of |q(t_f) − q(0) − offset| (m or rad;
                   offset = the stride on pelvis_tx), the transcription's periodicity
                   x(t_f) = x(0) over a whole cycle (no left/right mirror: the cycle is
                   a full stride of both legs) ≤ :data:`PERIODICITY_TOL`. Solved as a
                   constraint, so it measures the constraint's residual.

Units: SI inside (N, N·m, rad, m); tables show degrees where the unit says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import pandas as pd

from . import conventions as cv
from .mtg import strength_limits
from .sweep import ACCEPTED_STATUSES
from . import data as data_mod
from . import params as params_mod
from .model import ChildModel
from .problems import gait as gait_ocp

__all__ = ["CONVERGED_STATUSES", "SWING_LOAD_BW", "SWING_MARGIN", "DOUBLE_SUPPORT_MAX", "DOUBLE_SUPPORT_WALKING",
           "RESIDUAL_FORCE_FRACTION", "RESIDUAL_MOMENT_FRACTION", "ROM_DEG", "ROM_TOL_DEG", "PERIODICITY_TOL",
           "SK_STRENGTH_PARAMS", "DATA_TERMS", "CHECKS", "Gates", "strength_limits", "data_rom", "check",
           "check_frames", "label", "SWING_BOUND_BW", "swing_bound"]

#: IPOPT statuses counted as converged (the sweep's rule, :data:`gaitlib.sweep.ACCEPTED_STATUSES`).
CONVERGED_STATUSES = ACCEPTED_STATUSES
#: Vertical load a swinging foot may carry, fraction of body weight.
SWING_LOAD_BW = 0.02
#: The bound a problem may put on a swinging foot's vertical force
#: (:attr:`gaitlib.problems.gait.GaitSpec.swing_load_max`): half the gate's limit, so a
#: solution meeting it passes the gate with a margin. Fraction of body weight.
SWING_BOUND_BW = 0.5 * SWING_LOAD_BW


def swing_bound(bound_bw: float = SWING_BOUND_BW) -> float:
    """A bound on a swinging foot's vertical force, N (``bound_bw`` × body weight, rounded to
    1 mN: it is part of the spec, hence of the cache key)."""
    return round(bound_bw * cv.BODY_MASS * cv.G, 3)


#: Margin at each end of the data's swing window, fraction of the cycle
#: (:data:`gaitlib.data.SWING_MARGIN`, the events' SD).
SWING_MARGIN = data_mod.SWING_MARGIN
#: A torque counts as within its strength up to this relative excess: a solve whose torques
#: are bounded by the same strength (a jump with ``torque_limits``) ends at its bound within
#: IPOPT's constraint tolerance, i.e. round-off above it (measured: 1.2e-9 relative).
STRENGTH_RTOL = 1e-6
#: Largest fraction of the cycle with both feet loaded (> SWING_LOAD_BW) that is still walking.
DOUBLE_SUPPORT_MAX = 0.40
#: Double support of walking, fraction of the cycle (total of both phases): ≈ 20–25 %
#: (Schwartz 2008 Free: 0.19 ± 0.02; the thesis's Sec 4.2: t_DSP ≈ 10 % each).
DOUBLE_SUPPORT_WALKING = (0.20, 0.25)
#: Hicks et al. 2015 (module docstring): peak residual force / peak external force.
RESIDUAL_FORCE_FRACTION = 0.05
#: Hicks et al. 2015: peak residual moment / (COM height × peak external force).
RESIDUAL_MOMENT_FRACTION = 0.01
#: Thesis Table 3.5 joint angle ranges in our convention (deg): joint → (lo, hi).
#: The ankle row (50…110°, 90° standing) is read both ways — angle decreasing with
#: dorsiflexion (ours −20…40°, the jump study's reading) or increasing (−40…20°, the
#: anatomical dorsiflexion 20° / plantarflexion 40° pattern) — and the gate takes their
#: union, −40…40°: with the first reading alone the Schwartz 2008 mean at Fast speed
#: (−22°) would be out of range.
ROM_DEG = {"hip": (-30.0, 100.0), "knee": (-150.0, 0.0), "ankle": (-40.0, 40.0), "mtp": (-45.0, 80.0)}
#: Tolerance on the ROM bounds, deg (IPOPT satisfies bounds to ≈ 1e-8 relative; a solution
#: on a bound must not fail).
ROM_TOL_DEG = 0.1
#: Largest periodicity error, m or rad (1 cm, 0.57°).
PERIODICITY_TOL = 0.01
#: MTG parameter set whose envelope bounds the SK model's torques (Ch 5 identified).
SK_STRENGTH_PARAMS = "ch5"

#: The checks in table order, with the short text :meth:`Gates.label` uses.
CHECKS = {"converged": "not converged", "swing_load": "swing load", "double_support": "double support",
          "residual_force": "residual force", "residual_moment": "residual moment", "strength": "torque",
          "rom": "angle", "periodicity": "periodicity"}


@dataclass
class Gates:
    """The validity checks of one solution.

    ``table``: one row per check of :data:`CHECKS` — ``check, value, threshold, unit,
    passed, note, basis`` (``passed`` True/False, or None where the check does not apply;
    ``basis`` what the threshold is, e.g. "2 % BW"); ``name``: what was checked (for
    reports)."""

    table: pd.DataFrame
    name: str = ""

    @property
    def passed(self) -> bool:
        """True when no applicable check failed."""
        return not self.failed

    @property
    def failed(self) -> list[str]:
        """Names of the failed checks, in table order."""
        return [r.check for r in self.table.itertuples() if _failed(r.passed)]

    @property
    def converged(self) -> bool:
        return "converged" not in self.failed

    def label(self) -> str:
        """Short text: ``"valid"``, or ``"not converged (status)"`` and/or
        ``"invalid: swing load 55 N > 8.12 N (2 % BW); …"``."""
        if self.passed:
            return "valid"
        parts = []
        for r in self.table.itertuples():
            if not _failed(r.passed):
                continue
            if r.check == "converged":
                parts.insert(0, f"not converged ({r.value})")
                continue
            op = "<" if float(r.value) < float(r.threshold) else ">"  # a lower bound (angles)
            parts.append(f"{CHECKS[r.check]} {_fmt(r.value)} {r.unit} {op} {_fmt(r.threshold)} {r.unit}"
                         .replace(" %", "%") + (f" ({r.basis})" if getattr(r, "basis", "") else ""))
        conv = [p for p in parts if p.startswith("not converged")]
        rest = [p for p in parts if not p.startswith("not converged")]
        return "; ".join(conv + (["invalid: " + "; ".join(rest)] if rest else []))


def _failed(passed) -> bool:
    """A table's ``passed`` cell says the check failed (None/NaN: not applicable)."""
    return passed is not None and not (isinstance(passed, float) and math.isnan(passed)) and not bool(passed)


def _fmt(v) -> str:
    if isinstance(v, (int, float, np.floating)) and math.isfinite(v):
        return f"{v:.0f}" if abs(v) >= 100 else f"{v:.3g}"
    return str(v)


def _row(check, value, threshold, unit, passed, note, basis=""):
    return {"check": check, "value": value, "threshold": threshold, "unit": unit,
            "passed": None if passed is None else bool(passed), "note": note, "basis": basis}


def _na(check, why):
    return _row(check, np.nan, np.nan, "", None, f"not applicable: {why}")


# --------------------------------------------------------------------------------------
# Strength
# --------------------------------------------------------------------------------------


# --------------------------------------------------------------------------------------
# Checks on frames
# --------------------------------------------------------------------------------------


def _weights(t: np.ndarray, tf: float) -> np.ndarray:
    """Fraction of the cycle each node stands for (left rectangles up to ``tf``)."""
    edges = np.append(t, tf)
    return np.diff(edges) / (tf - t[0])


def _joint_type(col: str) -> str:
    return col.split("_")[0] if "_" in col else col


def check_frames(*, status: str, q: pd.DataFrame | None = None, torques: pd.DataFrame | None = None,
                 grf: pd.DataFrame | None = None, residuals: pd.DataFrame | None = None, tf: float | None = None,
                 kind: str = "tracking", events: dict | None = None, left_shift: float | None = None,
                 strength: dict | None = None, strength_source: str = "", body_mass: float = cv.BODY_MASS,
                 com_height: float | None = None, periodicity: float | None = None,
                 periodicity_note: str = "", rom_data: dict | None = None, name: str = "",
                 notes: dict | None = None) -> Gates:
    """The gates on plain frames (SI; index time, s).

    status : IPOPT return status.
    q : joint angles (rad) on columns ``hip_r … mtp_l`` (gait) or ``hip, knee, ankle, mtp``.
    torques : actuator torques (N·m), same joint columns (a ``tau_`` prefix is dropped).
    grf : ``grf_x_r, grf_y_r, grf_x_l, grf_y_l`` (gait, N), or ``grf_x, grf_y``.
    residuals : ``R_x, R_y`` (N), ``R_z`` (N·m) on the HAT; None: not applicable.
    tf : final time of the cycle (s); default the last time of ``grf``.
    kind : ``"tracking"`` (swing by the data's events), ``"predictive"`` (by the
        solution's own contact pattern: double support only) or ``"jump"`` (no gait checks).
    events : the data's events (fractions of the cycle), needs ``foot_off``; ``left_shift``
        the left leg's phase shift (fraction of the cycle).
    strength : :func:`strength_limits` output (None: not checked).
    com_height : m, for the residual moment (default 0.55 × body height, the standing COM).
    periodicity : measured periodicity error (m or rad), None: not applicable.
    rom_data : joint type → (lo, hi) deg the data reach (mean ± 1 SD); widens :data:`ROM_DEG`.
    notes : check name → text replacing a not-applicable reason.
    """
    notes = notes or {}
    bw = body_mass * cv.G
    rows = []
    ok = status in CONVERGED_STATUSES
    rows.append(_row("converged", status, " | ".join(sorted(CONVERGED_STATUSES)), "", ok,
                     "acceptable-level stop (IPOPT's acceptable tolerances) counted as converged"
                     if status == "Solved_To_Acceptable_Level" else ("" if ok else "IPOPT did not converge")))
    gait = kind in ("tracking", "predictive")
    feet = [s for s in cv.SIDES if grf is not None and f"grf_y_{s}" in grf.columns]
    lim_load = SWING_LOAD_BW * bw
    # ---- swing load (data events)
    if kind == "tracking" and grf is not None and feet and events and "foot_off" in events:
        t = grf.index.to_numpy(float)
        T = float(tf) if tf is not None else float(t[-1])
        tau = (t - t[0]) / (T - t[0])
        fo = float(events["foot_off"])
        shift = float(left_shift if left_shift is not None else events.get("opposite_foot_contact", 0.5))
        windows = data_mod.swing_windows(events, shift, SWING_MARGIN)
        worst, parts = -np.inf, []
        for s in feet:
            lo, hi = windows[s]  # swing window, cycle fractions
            sel = data_mod.in_window(tau, (lo, hi))
            fy = grf[f"grf_y_{s}"].to_numpy(float)[sel]
            peak = float(fy.max()) if fy.size else 0.0
            at = float(np.mod(tau[sel][np.argmax(fy)], 1.0)) if fy.size else float("nan")
            mean = float(fy.mean()) if fy.size else 0.0
            parts.append(f"{s}: peak {peak:.1f} N at {100 * at:.0f} %, mean {mean:.1f} N (swing "
                         f"{100 * np.mod(lo, 1):.0f}–{100 * np.mod(hi, 1):.0f} % of the cycle)")
            worst = max(worst, peak)
        rows.append(_row("swing_load", worst, lim_load, "N", worst <= lim_load,
                         "; ".join(parts) + f"; data events: foot off {100 * fo:.0f} %, left shift "
                         f"{100 * shift:.0f} %, ±{100 * SWING_MARGIN:.0f} % margin", basis="2 % BW"))
    elif gait and kind == "predictive":
        rows.append(_na("swing_load", notes.get("swing_load", "predictive run: its swing is its own "
                                                              "(see double_support)")))
    else:
        rows.append(_na("swing_load", notes.get("swing_load", "no data events" if gait else "not a gait")))
    # ---- double support
    if gait and grf is not None and len(feet) == 2:
        t = grf.index.to_numpy(float)
        T = float(tf) if tf is not None else float(t[-1])
        w = _weights(t, T)
        loaded = {s: grf[f"grf_y_{s}"].to_numpy(float) > lim_load for s in feet}
        both = float(np.sum(w[loaded["r"] & loaded["l"]]))
        heavy = {s: grf[f"grf_y_{s}"].to_numpy(float) > 0.1 * bw for s in feet}
        both10 = float(np.sum(w[heavy["r"] & heavy["l"]]))
        single = {s: float(np.sum(w[loaded[s]])) for s in feet}
        exp = (f"walking ≈ {100 * DOUBLE_SUPPORT_WALKING[0]:.0f}–{100 * DOUBLE_SUPPORT_WALKING[1]:.0f} %"
               + (f", data {100 * events['double_support']:.0f} %" if events and "double_support" in events else ""))
        rows.append(_row("double_support", 100 * both, 100 * DOUBLE_SUPPORT_MAX, "%", both <= DOUBLE_SUPPORT_MAX,
                         f"both feet > 2 % BW; {exp}; loaded: right {100 * single['r']:.0f} %, "
                         f"left {100 * single['l']:.0f} % of the cycle; both > 10 % BW: {100 * both10:.0f} %",
                         basis="of the cycle"))
    else:
        rows.append(_na("double_support", notes.get("double_support", "not a gait")))
    # ---- residuals
    if residuals is not None and grf is not None:
        if feet:
            fx = sum(grf[f"grf_x_{s}"].to_numpy(float) for s in feet)
            fy = sum(grf[f"grf_y_{s}"].to_numpy(float) for s in feet)
        else:
            fx, fy = grf["grf_x"].to_numpy(float), grf["grf_y"].to_numpy(float)
        f_ext = float(np.max(np.hypot(fx, fy)))
        h = float(com_height) if com_height is not None else 0.55 * cv.BODY_HEIGHT
        rf = float(np.max(np.abs(residuals[["R_x", "R_y"]].to_numpy(float))))
        rm = float(np.max(np.abs(residuals["R_z"].to_numpy(float))))
        rf_lim, rm_lim = RESIDUAL_FORCE_FRACTION * f_ext, RESIDUAL_MOMENT_FRACTION * h * f_ext
        rms = np.sqrt(np.mean(residuals.to_numpy(float) ** 2, axis=0))
        rows.append(_row("residual_force", rf, rf_lim, "N", rf <= rf_lim,
                         f"peak |R_x|, |R_y|; RMS {rms[0]:.2f} / {rms[1]:.2f} N; peak external force {f_ext:.0f} N "
                         "(Hicks et al. 2015)", basis="5 % of peak external force"))
        rows.append(_row("residual_moment", rm, rm_lim, "N·m", rm <= rm_lim,
                         f"peak |R_z|; RMS {rms[2]:.3f} N·m; COM height {h:.3f} m (Hicks et al. 2015)",
                         basis="1 % of COM height × peak external force"))
    else:
        why = notes.get("residual", "no residual actuators")
        rows += [_na("residual_force", why), _na("residual_moment", why)]
    # ---- strength
    if strength is not None and torques is not None:
        worst = None
        over = []
        for c in torques.columns:
            j = _joint_type(c[4:] if c.startswith("tau_") else c)
            if j not in strength:
                continue
            lo, hi = strength[j]
            v = torques[c].to_numpy(float)
            for val, lim in ((float(v.max()), hi), (float(v.min()), lo)):
                ratio = val / lim if lim else np.inf
                if worst is None or ratio > worst[0]:
                    worst = (ratio, c, val, lim)
                if ratio > 1 + STRENGTH_RTOL:
                    over.append(f"{c} {val:.0f} N·m (limit {lim:.0f})")
        if worst is not None:
            ratio, c, val, lim = worst
            rows.append(_row("strength", abs(val), abs(lim), "N·m", ratio <= 1 + STRENGTH_RTOL,
                             f"worst {c}: {val:.1f} N·m = {100 * ratio:.0f} % of its peak {lim:.1f} N·m"
                             + (f"; over: {', '.join(over)}" if over else "") + f"; {strength_source}",
                             basis=f"{c} peak"))
        else:
            rows.append(_na("strength", "no torque columns"))
    else:
        rows.append(_na("strength", notes.get("strength", "no torques or strength model")))
    # ---- ROM
    if q is not None:
        worst = None
        out = []
        for c in q.columns:
            j = _joint_type(c)
            if j not in ROM_DEG:
                continue
            lo, hi = ROM_DEG[j]
            if rom_data and j in rom_data:
                lo, hi = min(lo, rom_data[j][0]), max(hi, rom_data[j][1])
            v = np.rad2deg(q[c].to_numpy(float))
            for val, excess in ((float(v.max()), float(v.max()) - hi), (float(v.min()), lo - float(v.min()))):
                if worst is None or excess > worst[0]:
                    worst = (excess, c, val, hi if val > 0.5 * (lo + hi) else lo)
                if excess > ROM_TOL_DEG:
                    out.append(f"{c} {val:.1f}°")
        excess, c, val, bound = worst
        rows.append(_row("rom", val, bound, "deg", excess <= ROM_TOL_DEG,
                         f"worst {c}: {val:.1f}° vs bound {bound:.0f}° (excess {excess:.1f}°)"
                         + (f"; outside: {', '.join(out)}" if out else "") + "; thesis Table 3.5"
                         + (" widened to the data's mean ± 1 SD" if rom_data else ""),
                         basis=f"{c}, thesis Table 3.5"))
    else:
        rows.append(_na("rom", "no joint angles"))
    # ---- periodicity
    if periodicity is not None:
        rows.append(_row("periodicity", float(periodicity), PERIODICITY_TOL, "m|rad", periodicity <= PERIODICITY_TOL,
                         periodicity_note))
    else:
        rows.append(_na("periodicity", notes.get("periodicity", "not a gait cycle")))
    return Gates(pd.DataFrame(rows), name)


# --------------------------------------------------------------------------------------
# Solutions
# --------------------------------------------------------------------------------------


#: Cost terms that track data channels: a run with any of them follows the data's timing.
DATA_TERMS = ("GRF", "Ang", "Q", "Trq")


def _gait_kind(spec) -> str:
    """``"tracking"`` when the cost tracks any data channel (:data:`DATA_TERMS`: the data's
    events then time the swing), else ``"predictive"`` (thesis FP: HAT, effort and
    dynamics terms only)."""
    return "tracking" if any(spec.term_weights.get(k, 0) for k in DATA_TERMS) else "predictive"


@lru_cache(maxsize=16)
def _gait_data(speed_class: str, source: str = "schwartz2008"):
    return data_mod.load_gait_data(speed_class, source)


def _tracked_data(spec, data=None):
    """(events, left shift, stride m, data ROM) of the data a gait spec tracks (``data``
    overrides the events' source: a :class:`gaitlib.data.GaitData`)."""
    own = _gait_data(spec.speed_class, spec.source)
    tracked = data if data is not None else (_gait_data(spec.track_class, spec.source) if spec.track_class else own)
    if spec.leg_scale is not None:  # the longer legs' speed and cycle time (the events are fractions)
        own = gait_ocp.spec_gait_data(spec)[0]
    return dict(tracked.events), float(tracked.left_shift), float(own.speed * own.cycle_time), data_rom(tracked)


def data_rom(gait) -> dict:
    """Joint type → (lo, hi) deg reached by a :class:`gaitlib.data.GaitData`'s mean ± 1 SD
    over both legs (hip as measured, relative to the pelvis)."""
    out = {}
    for j in ("hip", "knee", "ankle"):
        cols = [f"{j}_{s}" for s in cv.SIDES if f"{j}_{s}" in gait.mean.columns]
        if cols:
            m, sd = gait.mean[cols].to_numpy(float), gait.sd[cols].to_numpy(float)
            out[j] = (float(np.rad2deg((m - sd).min())), float(np.rad2deg((m + sd).max())))
    return out


def _com_height(q: pd.DataFrame, body_params: str = "default", model: ChildModel | None = None) -> float:
    """Mean COM height over the frames (m), model COM with the spec's body parameters (and
    the spec's model, :func:`gaitlib.problems.gait.spec_model`; default the thesis's)."""
    m = ChildModel() if model is None else model
    pb = params_mod.body_params(body_params, m)
    f = m.function("com").map(len(q))
    Q = q[list(cv.COORDS)].to_numpy(float).T
    out = f(Q, np.zeros_like(Q), np.tile(np.asarray(pb, float)[:, None], len(q)))
    return float(np.mean(np.asarray(out[0])[1]))


def _gait_periodicity(sol, stride: float) -> tuple[float, str]:
    st = sol.solution.phase("cycle").states
    x0, xf = st.iloc[0], st.iloc[-1]
    err = {c: abs(float(xf[c] - x0[c]) - (stride if c == "pelvis_tx" else 0.0)) for c in cv.COORDS}
    errd = max(abs(float(xf[f"qd_{c}"] - x0[f"qd_{c}"])) for c in cv.COORDS)
    c = max(err, key=err.get)
    note = (f"worst {c}: {err[c]:.2g}; max |q̇(t_f) − q̇(0)| {errd:.2g} rad/s or m/s; "
            f"{'imposed as a constraint' if sol.spec.periodic else 'not imposed (spec.periodic=False)'}")
    return err[c], note


def _check_gait(sol, kind, data, name) -> Gates:
    spec = sol.spec
    kind = kind or _gait_kind(spec)
    events, shift, stride, rom = _tracked_data(spec, data)
    if spec.model == "SK":
        params, src = gait_ocp.mtg_params_of(SK_STRENGTH_PARAMS), f"SK: MTG envelope, '{SK_STRENGTH_PARAMS}' set"
    else:
        params, src = gait_ocp.mtg_params_of(spec), f"{spec.model}: its MTG set '{spec.mtg_params}'"
    torques = sol.torques_active if sol.torques_active is not None else sol.torques
    per, per_note = _gait_periodicity(sol, stride)
    return check_frames(status=sol.stats["status"], q=sol.q[list(cv.JOINTS)], torques=torques, grf=sol.grf,
                        residuals=sol.residuals, tf=float(sol.stats["tf_s"]), kind=kind, events=events,
                        left_shift=shift, strength=strength_limits(params), strength_source=src,
                        com_height=_com_height(sol.q, spec.body_params, gait_ocp.spec_model(spec)), periodicity=per,
                        periodicity_note=per_note, rom_data=rom, name=name)


def _check_contact_a(res, name) -> Gates:
    g = _gait_data("Free")

    return check_frames(status=res.stats["status"] if res.stats["success"] else f"{res.stats['status']} "
                        "(no converged local solve meets Eq 4.4)",
                        q=res.q[list(cv.JOINTS)], torques=res.torques, grf=res.grf, residuals=res.residuals,
                        tf=g.cycle_time, kind="tracking", events=g.events, left_shift=g.left_shift,
                        strength=strength_limits(gait_ocp.mtg_params_of(SK_STRENGTH_PARAMS)),
                        strength_source=f"SK: MTG envelope, '{SK_STRENGTH_PARAMS}' set; net inverse-dynamics torques",
                        com_height=_com_height(res.q), periodicity=None, rom_data=data_rom(g), name=name,
                        notes={"periodicity": "kinematics fixed to the data's periodic Fourier fit"})


def _check_jump(sol, name) -> Gates:
    model = sol.model
    tr_ = sol.trajectory
    joints = list(model.joints)
    h = model.standing_top
    lim = strength_limits(None, body_mass=model.total_mass, body_height=h, legs=2)
    return check_frames(status=sol.status, q=tr_[joints], torques=tr_[[f"tau_{j}" for j in joints]],
                        grf=tr_[["grf_x", "grf_y"]], residuals=None, kind="jump", strength=lim,
                        strength_source=(f"adult Gymnast MTGs scaled (Eq 5.21) to {model.total_mass:.1f} kg, "
                                         f"{h:.2f} m, × 2 legs"), body_mass=model.total_mass, name=name,
                        notes={"residual": "no residual actuators (free root, zero root wrench)",
                               "swing_load": "a jump", "double_support": "a jump", "periodicity": "a jump"})


def check(solution, *, kind: str | None = None, data=None, name: str = "") -> Gates:
    """The validity gates of a solution (module docstring).

    ``solution``: a :class:`~gaitlib.problems.gait.GaitSolution`, a jump solution (has
    ``trajectory`` and ``jump_height``) or a contact-identification result (has
    ``p_contact`` and ``key``; (b)/(c) are checked through their gait solution).
    ``kind``: ``"tracking"`` or ``"predictive"`` for a gait (default: tracking when the cost
    tracks any data channel — GRFs, angles, coordinates or torques — else predictive).
    ``data``: the :class:`gaitlib.data.GaitData` whose events define the swing (default:
    the data the spec tracks). ``name``: carried into :attr:`Gates.name`."""
    if hasattr(solution, "trajectory") and hasattr(solution, "jump_height"):
        return _check_jump(solution, name)
    if hasattr(solution, "p_contact") and hasattr(solution, "key"):
        if getattr(solution, "solution", None) is not None:
            return _check_gait(solution.solution, kind, data, name)
        return _check_contact_a(solution, name)
    if hasattr(solution, "spec") and hasattr(solution, "grf"):
        return _check_gait(solution, kind, data, name)
    raise TypeError(f"check: cannot read a {type(solution).__name__} (need a gait, jump or contact-id solution)")


def label(solution, **kw) -> str:
    """:meth:`Gates.label` of :func:`check` (``"valid"``, ``"not converged (…)"``,
    ``"invalid: …"``): the mark for a figure or table."""
    return check(solution, **kw).label()
