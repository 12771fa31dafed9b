"""Natural-gait data tracking (thesis Secs 4.3.2, 5.2 and 5.3): SK, MSK and NMSK models.

Functions
---------
:func:`natural_gait`   the Free-speed data-tracking solve of a model (SK: Eq 4.11 with the
                       contact parameters free, as Sec 4.3.2; MSK: Eq 5.33; NMSK: Eq 5.55).
:func:`rmse_beside_thesis`  our RMSEs beside the thesis's Table 4.9 / 5.4 / 5.11 (labelled).
:func:`write_outputs`  frames, ``summary.json`` and figures into a directory (the CLI).

Thesis values are references on *different data* (Bovi 2011 vs our Schwartz 2008 Free
class) and appear only in columns labelled with their table.
"""

from __future__ import annotations

import json
from pathlib import Path
from dataclasses import replace

import numpy as np
import pandas as pd

from .. import contact as contact_mod
from .. import kinematics
from .. import conventions as cv
from ..problems import gait as gait_ocp
from ..problems.gait import solve_cached, tracking_data
from .. import marks
from .. import data as data_mod
from .. import plots
from .. import validity
from ..model import ELLIPSOID_LABELS, ChildModel

__all__ = ["READINGS", "reading_options", "THESIS_RMSE", "natural_gait", "natural_gait_spec", "rmse_beside_thesis",
           "channels_frame", "sims_and_marks", "write_outputs", "stats_table", "SLIP_V", "SLIP_COLUMN", "foot_slip",
           "foot_sink", "reference_slip", "static_support", "FRICTION_FLOOR"]

#: Thesis RMSEs (different data, Bovi 2011): (kind, joint/component, side) → value.
#: Table 4.9, optimal control row (SK, contact parameters identified), torques N·m, GRF N.
#: Table 5.4 (MSK, Eq 5.33): angles deg, torques N·m, GRF N (tangential = x, normal = y).
THESIS_RMSE = {
    "SK": {("torque", "hip", "r"): 0.42, ("torque", "hip", "l"): 0.42,
           ("torque", "knee", "r"): 0.35, ("torque", "knee", "l"): 0.35,
           ("torque", "ankle", "r"): 0.66, ("torque", "ankle", "l"): 0.66,
           ("grf", "x", "r"): 19.81, ("grf", "x", "l"): 8.33,
           ("grf", "y", "r"): 26.49, ("grf", "y", "l"): 26.38},
    "MSK": {("angle", "hip", "r"): 0.6, ("angle", "knee", "r"): 1.1, ("angle", "ankle", "r"): 1.0,
            ("angle", "hip", "l"): 0.6, ("angle", "knee", "l"): 1.2, ("angle", "ankle", "l"): 0.9,
            ("torque", "hip", "r"): 3.1, ("torque", "knee", "r"): 1.8, ("torque", "ankle", "r"): 3.9,
            ("torque", "hip", "l"): 2.3, ("torque", "knee", "l"): 1.1, ("torque", "ankle", "l"): 3.8,
            ("grf", "x", "r"): 7.2, ("grf", "y", "r"): 24.2, ("grf", "x", "l"): 4.6, ("grf", "y", "l"): 19.7},
    # Table 5.11 (NMSK, Eq 5.55), as printed
    "NMSK": {("angle", "hip", "r"): 0.6, ("angle", "knee", "r"): 1.1, ("angle", "ankle", "r"): 1.0,
             ("angle", "hip", "l"): 0.6, ("angle", "knee", "l"): 1.2, ("angle", "ankle", "l"): 0.9,
             ("torque", "hip", "r"): 2.3, ("torque", "knee", "r"): 1.1, ("torque", "ankle", "r"): 3.8,
             ("torque", "hip", "l"): 2.3, ("torque", "knee", "l"): 1.1, ("torque", "ankle", "l"): 3.8,
             ("grf", "x", "r"): 7.2, ("grf", "y", "r"): 24.1, ("grf", "x", "l"): 4.6, ("grf", "y", "l"): 19.8},
}
THESIS_TABLE = {"SK": "thesis, Table 4.9 (optimal control)", "MSK": "thesis, Table 5.4",
                "NMSK": "thesis, Table 5.11"}


#: The two readings of the data-tracking problem the book shows side by side. ``"thesis"``:
#: as printed — the Jrk term's denominators are the ranges of the reference's jerks (the
#: HAT's horizontal position and tilt have none, so they fall back to 1: the HAT is pinned to
#: a constant speed), and nothing keeps a swinging foot off the ground. ``"book"``: those two
#: denominators from the data (:func:`gaitlib.problems.gait.data_jerk_ranges`) and each foot's
#: vertical force bounded by :func:`gaitlib.validity.swing_bound` (1 % of body weight) while
#: the data say it swings. In the thesis's reading the tracking solutions load a swinging
#: foot and fail the validity gate; the chapters that have moved to the book's reading say so.
READINGS = ("book", "thesis")


def reading_options(reading: str = "book") -> dict:
    """The :class:`~gaitlib.problems.gait.GaitSpec` fields of a reading (:data:`READINGS`)."""
    if reading == "thesis":
        return {}
    if reading == "book":
        return {"jerk_ranges": "data", "swing_load_max": validity.swing_bound()}
    raise ValueError(f"reading must be one of {READINGS}, got {reading!r}")


def natural_gait_spec(model: str = "SK", cost: str | None = None, speed: str = "Free", reading: str = "thesis",
                      **kw) -> gait_ocp.GaitSpec:
    """The natural-gait data-tracking spec: SK → Eq 4.11 (Table 4.8 weights, Sec 4.3.2),
    MSK → Eq 5.33 (Table 5.3), NMSK → Eq 5.55 (Table 5.9), all with the thesis's identified
    contact parameters fixed (Tables 4.17/4.18) unless ``free_contact=True`` (the
    identification of Ch 4), in ``reading`` (:data:`READINGS`; ``kw`` overrides its fields)."""
    if cost is None:
        cost = {"SK": "Eq4.11", "MSK": "Eq5.33", "NMSK": "Eq5.55"}.get(model, "Eq5.33")
    return gait_ocp.GaitSpec(model=model, cost=cost, speed_class=speed, **{**reading_options(reading), **kw})


def natural_gait(model: str = "SK", cost: str | None = None, speed: str = "Free", *, use_cache: bool = True,
                 root=None, guess=None, progress: bool = False, **kw) -> gait_ocp.GaitSolution:
    """Solve (or reload) :func:`natural_gait_spec`; keyword arguments go to the spec."""
    return solve_cached(natural_gait_spec(model, cost, speed, **kw), use_cache=use_cache, root=root,
                        guess=guess, progress=progress)


def rmse_beside_thesis(sol: gait_ocp.GaitSolution) -> pd.DataFrame:
    """Our RMSE per channel (angles deg, torques N·m, GRFs N) beside the thesis's table
    for the same model (NaN where the thesis did not report a channel)."""
    ref = THESIS_RMSE[sol.spec.model]
    rows = []
    for _, r in sol.rmse.iterrows():
        ch = r["channel"]
        side = ch[-1]
        part = ch.split("_")[1] if r["kind"] == "grf" else ch.rsplit("_", 1)[0]
        rows.append({"kind": r["kind"], "channel": part, "side": side, "unit": r["unit"],
                     "ours": r["rmse"], THESIS_TABLE[sol.spec.model]: ref.get((r["kind"], part, side), np.nan)})
    return pd.DataFrame(rows)


def channels_frame(sol: gait_ocp.GaitSolution) -> pd.DataFrame:
    """The solution on the data's channel names (SI, model signs; index time s): joint
    angles ``hip_r`` …, torques ``tau_hip_r`` …, and foot forces ``grf_x_r`` …"""
    out = pd.DataFrame(index=sol.q.index)
    for c in cv.JOINTS:
        out[c] = sol.q[c]
        out[f"tau_{c}"] = sol.torques[c]
    for g in gait_ocp.GRF_CHANNELS:
        out[g] = sol.grf[g]
    out["pelvis_tilt"] = sol.q["pelvis_tilt"]
    return out


def sims_and_marks(solutions: dict) -> tuple[dict, dict]:
    """``{label: GaitSolution}`` → (``{label: channels_frame}``, ``{label: failure label}``):
    the ``sims`` and ``marks`` arguments of :func:`gaitlib.plots.tracking_figure`
    (:func:`gaitlib.marks.failure_label`; None for a converged solve)."""
    return ({k: channels_frame(s) for k, s in solutions.items()},
            {k: marks.failure_label(s) for k, s in solutions.items()})


def stats_table(solutions: dict) -> pd.DataFrame:
    """One row of solver statistics per labelled solution; ``mark`` is its failure label
    (:func:`gaitlib.marks.failure_label`, empty when converged)."""
    rows = []
    for label, s in solutions.items():
        st = s.stats
        rows.append({"run": label, "mark": marks.failure_label(s) or "", "status": st["status"], "iterations": st["iterations"],
                     "solve (s)": st["solve_time_s"], "ms/iteration": 1e3 * st["time_per_iteration_s"],
                     "build (s)": st["build_time_s"], "objective": st["objective"],
                     "max violation": st["max_violation"], "variables": st["n_variables"],
                     "constraints": st["n_constraints"]})
    return pd.DataFrame(rows).set_index("run")


def write_outputs(sol: gait_ocp.GaitSolution, out, figures: bool = True) -> Path:
    """Write ``sol`` (frames, ``summary.json``, ``rmse_vs_thesis.csv``) and, with
    ``figures``, ``tracking.png`` (angles, torques, GRFs vs the data's ±1 SD bands; a solve
    that did not converge is marked in it, :mod:`gaitlib.marks`)."""
    out = Path(out)
    sol.save(out)
    rmse_beside_thesis(sol).to_csv(out / "rmse_vs_thesis.csv", index=False, float_format="%.6g")
    if figures:
        import matplotlib

        matplotlib.use("Agg")

        gait = tracking_data(data_mod.load_gait_data(sol.spec.speed_class, sol.spec.source))
        sims, marks = sims_and_marks({f"{sol.spec.model} {sol.spec.cost}": sol})
        fig = plots.tracking_figure(gait, sims, marks=marks)
        fig.savefig(out / "tracking.png", dpi=110)
    summary = json.loads((out / "summary.json").read_text())
    summary["files"] = sorted(p.name for p in out.iterdir())
    (out / "summary.json").write_text(json.dumps(summary, indent=1, default=str))
    return out


# ======================================================================================
# Do the loaded feet stand still? (a measurement; Ch 4–7 and the card read it)
# ======================================================================================

#: The slip speed above which the friction law models sliding, m/s: its transition velocity
#: v_tr (:class:`gaitlib.contact.Smoothing`; Brown & McPhee's 0.1 m/s, thesis Sec 3.4.3).
SLIP_V = contact_mod.Smoothing.v_transition


#: The tables' column of the force-weighted foot slip (m/s, :func:`foot_slip`).
SLIP_COLUMN = "foot slip (m/s)"


def cycle_weights(t, tf: float) -> np.ndarray:
    """Each node's share of the cycle [t₀, t_f] (s → 1): the interval to the next node, the
    last node's to ``tf`` (collocation nodes may stop short of t_f). Weights of a time mean
    over a solution's node-indexed frames."""
    t = np.asarray(t, float)
    return np.diff(np.append(t, tf)) / (tf - t[0])


def foot_slip(sol, v: float = SLIP_V) -> dict:
    """How fast a gait solution's loaded feet slide (a measurement, not a validity gate).

    From ``sol.ellipsoids`` (``fn_<label>``, N; ``vs_<label>``: the tangential velocity of
    the body point the friction law reads, m/s — :meth:`gaitlib.model.ChildModel.slip`),
    each node weighted by the share of the cycle it stands for: ``slip`` — the mean of |vs|
    weighted by the normal force (m/s); ``sliding`` — the share of the load (force × time)
    carried while sliding faster than ``v`` (0…1); ``speed`` — the walking speed the spec's
    data give (m/s), for scale; ``worst`` — the ellipsoid carrying the most slip × load;
    ``ball`` — the share of the load (force × time) on the two ball ellipsoids (0…1). A
    stance foot stands still: in the friction law anything slower than v_tr is sticking."""
    e = sol.ellipsoids
    cols = [c for c in e.columns if c.startswith("vs_")]
    if not cols:
        raise ValueError(f"{getattr(sol, 'name', 'solution')}: no slip velocities (vs_ columns) in its ellipsoids frame")
    fn = np.clip(e[["fn_" + c[3:] for c in cols]].to_numpy(float), 0.0, None)
    vs = np.abs(e[cols].to_numpy(float))
    t = e.index.to_numpy(float)
    w = cycle_weights(t, float(sol.stats.get("tf_s", t[-1])))[:, None]
    load = float((w * fn).sum())
    gd = gait_ocp.spec_gait_data(sol.spec)[0] if getattr(sol.spec, "leg_scale", None) is not None else \
        data_mod.load_gait_data(sol.spec.speed_class, sol.spec.source)
    return {"slip": float((w * fn * vs).sum() / load), "sliding": float((w * fn * (vs > v)).sum() / load),
            "speed": float(gd.speed), "worst": cols[int(np.argmax((w * fn * vs).sum(axis=0)))][3:],
            "ball": float(sum((w * fn[:, [j]]).sum() for j, c in enumerate(cols) if c.startswith("vs_ball")) / load)}


#: The friction floor of the sliding ablations (:attr:`~gaitlib.problems.gait.GaitSpec.friction_floor`; Ch 4, 5, 7): the largest
#: dynamic friction coefficient the thesis's final identification gives any ellipsoid
#: (Table 4.18: the toe's μ_d), read from the thesis's contact set.
FRICTION_FLOOR = max(float(contact_mod.default_params()[contact_mod.param_index(e, "mu_d")]) for e in cv.ELLIPSOIDS)


def foot_sink(q: pd.DataFrame, p_contact, model: ChildModel | None = None) -> float:
    """The deepest any ellipsoid sinks into the ground over a motion (m, ≥ 0): the largest
    depth of an ellipsoid's lowest point below y = 0 at the rows of ``q`` (time × the 11
    coordinates, SI) with the contact parameters ``p_contact`` (39,). Volumetric contact
    carries load by penetration; a soft set that stops the feet sliding may sink them.
    ``model``: the model the motion is of (default the thesis's; :func:`gaitlib.problems.gait.spec_model`)."""
    m = ChildModel() if model is None else model
    Q = q[list(cv.COORDS)].to_numpy(float)
    return float(max(0.0, -kinematics.ellipsoid_bottoms_rows(m, Q, p_contact).min()))


def pelvic_hip_velocity(gd: data_mod.GaitData, hip_width: float, speed_class: str = "Free",
                        source: str = "schwartz2008") -> dict[str, np.ndarray]:
    """The forward velocity (m/s) each hip gets from the pelvis's rotation about the vertical,
    which the 2-D model lacks, at the instants ``gd.time``: with the hip joint centres
    ``hip_width`` (m) apart and the data's pelvic rotation θ(t) (:func:`gaitlib.data.context_curve`,
    positive = the ipsilateral (right) side forward), the right hip sits (w/2)·sin θ ahead of the
    pelvis's centre and the left one as far behind, so their velocities are ±(w/2)·cos θ·θ̇
    (a rigid pelvis). θ on the cycle fraction ``gd.time / gd.cycle_time`` (Fourier fit of order
    12, the reference's own); ``speed_class``: whose rotation (Ch 7's time-scaled data: the tracked class's)."""
    c = data_mod.context_curve("pelvis_rotation", speed_class, source)
    T = float(gd.cycle_time)
    th = gait_ocp.fourier_derivatives(c["mean"].to_numpy(float) * cv.DEG, T, order=12, n_der=1)(np.asarray(gd.time, float))
    v = 0.5 * float(hip_width) * np.cos(th[0]) * th[1]
    return {"r": v, "l": -v}


def reference_slip(spec: gait_ocp.GaitSpec, v: float = SLIP_V, hip_width: float = 0.0) -> dict:
    """How fast the loaded feet of a spec's tracking reference itself slide: the data the
    spec tracks as its Q term tracks them (:func:`gaitlib.problems.gait.reference`: the data's
    joint angles, the HAT upright, moving at the walking speed, at the height where the
    contact carries the data's vertical load at rest) with the spec's contact set
    (:func:`gaitlib.problems.gait.contact_params_of`), each ellipsoid weighted by its normal
    force at rest in that pose. No solve: what a gait that tracked its reference exactly
    would ask of its feet. Returns ``slip`` (force-weighted mean |v_slip|, m/s), ``sliding``
    (share of the load on ellipsoids sliding faster than ``v``, 0…1), the same two
    (``anchored_slip``, ``anchored_sliding``) with the HAT's horizontal speed changed at every
    instant so that the load-weighted mean slip is zero — what is left cannot come from the
    constant-speed HAT reference — that speed's range (``hat_speed_min``, ``hat_speed_max``)
    and the walking speed (``speed``), m/s; ``by_ellipsoid``: the force-weighted slip of each
    ellipsoid kind (toe, ball, heel; both feet), m/s; ``mean_slip``: the force-weighted mean
    of the signed slip (m/s, > 0: the loaded feet move forward — the HAT outruns the legs'
    sweep, the data's stride is longer than the angles carry the model's legs). ``hip_width``
    (m, ≥ 0): each ellipsoid also moves with its hip's forward velocity from the data's pelvic
    rotation (:func:`pelvic_hip_velocity`, a 3-D motion the 2-D model lacks; 0: none)."""
    if not float(hip_width) >= 0.0:
        raise ValueError(f"hip_width must be a distance ≥ 0 m, got {hip_width!r}")
    m = gait_ocp.spec_model(spec)
    pc = gait_ocp.contact_params_of(spec)
    _, gd = gait_ocp.spec_gait_data(spec)
    ref = gait_ocp.reference(gd, m, pc)
    der = {c: ref.deriv[c](gd.time) for c in cv.COORDS}
    q = np.array([der[c][0] for c in cv.COORDS]).T
    qd = np.array([der[c][1] for c in cv.COORDS]).T
    vs = gait_ocp.slip_velocities(m, q, qd, pc)
    if float(hip_width) > 0.0:
        hv = pelvic_hip_velocity(gd, hip_width, getattr(spec, "track_class", "") or spec.speed_class, spec.source)
        vs = vs + np.array([hv[lab.rsplit("_", 1)[1]] for lab in ELLIPSOID_LABELS])
    f_ct = m.function("contact")
    fn = np.clip(np.array([np.asarray(f_ct(q=row, qd=np.zeros(len(cv.COORDS)), p_contact=pc)["fn"]).ravel()
                           for row in q]).T, 0.0, None)
    tot = fn.sum(axis=0)
    dv = np.where(tot > 0, (fn * vs).sum(axis=0) / np.where(tot > 0, tot, 1.0), 0.0)
    anchored = vs - dv[None, :]
    load = fn.sum()
    hat = qd[:, 0] - dv
    return {"slip": float((fn * np.abs(vs)).sum() / load), "sliding": float((fn * (np.abs(vs) > v)).sum() / load),
            "anchored_slip": float((fn * np.abs(anchored)).sum() / load),
            "anchored_sliding": float((fn * (np.abs(anchored) > v)).sum() / load),
            "mean_slip": float((fn * vs).sum() / load),
            "hat_speed_min": float(hat.min()), "hat_speed_max": float(hat.max()), "speed": float(gd.speed),
            "by_ellipsoid": {e: float(sum((fn[i] * np.abs(vs[i])).sum() for i in idx) / max(sum(fn[i].sum() for i in idx), 1e-12))
                             for e in cv.ELLIPSOIDS
                             for idx in [[i for i, lab in enumerate(ELLIPSOID_LABELS) if lab.startswith(e)]]}}


#: The leg scales of :func:`leg_scale_slip` (thigh and shank × each; 1: Table 4.1).
LEG_SCALES = (0.95, 1.0, 1.05, 1.1, 1.15, 1.2)
#: The thigh and shank scale the Ch 4 identification and the Ch 5 ablation solve with (our
#: choice, a round value read off the scan: there the Ch 4 (c) reference's signed mean slip
#: with our contact set is within 0.01 m/s of zero — it changes sign a little above, see
#: :func:`gaitlib.studies.contact_id.leg_scale_findings` — and its slip about half the
#: thesis legs').
LEG_SCALE = 1.1


def leg_scale_slip(spec: gait_ocp.GaitSpec, scales=LEG_SCALES) -> pd.DataFrame:
    """:func:`reference_slip` of ``spec`` with the thigh and shank × each of ``scales``
    (:attr:`~gaitlib.problems.gait.GaitSpec.leg_scale`; the walking speed and cycle time
    follow the longer leg through the data's dimensionless values). No solve: whether the
    data's joint angles stop sliding the loaded feet on longer legs. One row per scale: the
    thigh + shank length (m), the walking speed (m/s), the reference's force-weighted slip,
    the same anchored (the HAT's speed changed at every instant), the signed mean (m/s) and
    the share of the load sliding faster than ``SLIP_V``; ``note``: why a scale has no
    reference (its contact cannot carry the data's load at rest in some pose), else ''."""
    rows = []
    for s in scales:
        sp = replace(spec, leg_scale=None if float(s) == 1.0 else float(s))
        m = gait_ocp.spec_model(sp)
        row = {"leg scale": float(s), "thigh + shank (m)": m.lengths["thigh"] + m.lengths["shank"]}
        try:
            r = reference_slip(sp)
        except kinematics.LoadNotCarried as e:
            rows.append({**row, "note": f"no reference: {e}"})
            continue
        rows.append({**row, "speed (m/s)": r["speed"], "reference slip (m/s)": r["slip"],
                     "anchored slip (m/s)": r["anchored_slip"], "signed mean slip (m/s)": r["mean_slip"],
                     f"load sliding > {SLIP_V} m/s (%)": 100 * r["sliding"], "note": ""})
    return pd.DataFrame(rows).set_index("leg scale")


#: A hip-joint-centre separation beyond this × the body height is out of any body's reach
#: (the verdict of the pelvic-rotation sentences; the pelvis is far narrower than half the height).
HIP_WIDTH_OUT_OF_REACH_BH = 0.5
#: Hip-joint-centre separations of :func:`pelvic_rotation_slip`, m (0: the 2-D model).
HIP_WIDTHS = (0.0, 0.10, 0.15, 0.20, 0.30)


def pelvic_rotation_slip(spec: gait_ocp.GaitSpec, widths=HIP_WIDTHS) -> tuple[pd.DataFrame, float]:
    """Whether the pelvis's rotation about the vertical — a 3-D motion the 2-D model lacks,
    which moves the stance hip back relative to the pelvis's centre while the body moves on —
    is what the data's stride has beyond the model's legs' sweep: :func:`reference_slip` of
    ``spec`` with its hips moving with the data's pelvic rotation (:func:`pelvic_hip_velocity`)
    at each hip-joint-centre separation of ``widths`` (m). No solve. Returns ``(table,
    w_zero)``: one row per width (force-weighted, signed mean and anchored slip, m/s; share of
    the load sliding faster than ``SLIP_V``, %), and the separation (m) at which the signed mean
    slip would vanish — exact, because each slip velocity is linear in the width and the loads
    are not (``inf`` if the rotation does not move it)."""
    rows = {}
    for w in widths:
        r = reference_slip(spec, hip_width=float(w))
        rows[float(w)] = {"reference slip (m/s)": r["slip"], "signed mean slip (m/s)": r["mean_slip"],
                          "anchored slip (m/s)": r["anchored_slip"], f"load sliding > {SLIP_V} m/s (%)": 100 * r["sliding"]}
    t = pd.DataFrame.from_dict(rows, orient="index")
    t.index.name = "hip centres apart (m)"
    m0 = reference_slip(spec)["mean_slip"]
    m1 = reference_slip(spec, hip_width=1.0)["mean_slip"]
    w_zero = float(-m0 / (m1 - m0)) if m1 != m0 else float("inf")
    return t, w_zero


def stride_sweep(spec: gait_ocp.GaitSpec) -> dict:
    """How much of the data's stride the data's angles carry the model's legs, from
    :func:`reference_slip` (no solve). Every slip velocity of the reference is (D + c(τ))/T on
    the normalised cycle τ: D the stride the data's dimensionless speed and cadence give
    (v*/f*·L, m), T the cycle time (s), c fixed by the angles, the legs and the feet. So the
    force-weighted mean slip m gives the legs' force-weighted sweep per cycle exactly,
    ``sweep = D − m·T`` (m), and the conversion length at which the data's stride equals it,
    ``L · sweep / D`` (m: the leg length Schwartz's normalisation would have to have used for
    this model's legs). Returns ``stride``, ``sweep``, ``ratio`` (sweep / stride), ``cycle_time``,
    ``mean_slip``, ``leg_length`` (the book's conversion length, hip to ground),
    ``conversion_length`` and ``hip_to_ankle`` (the model's thigh + shank, m)."""
    r = reference_slip(spec)
    _, gd = gait_ocp.spec_gait_data(spec)
    T, D = float(gd.cycle_time), float(gd.speed) * float(gd.cycle_time)
    sweep = D - r["mean_slip"] * T
    L = cv.leg_length(cv.BODY_HEIGHT, 1.0 if getattr(spec, "leg_scale", None) is None else float(spec.leg_scale))
    m = gait_ocp.spec_model(spec)
    return {"stride": D, "sweep": sweep, "ratio": sweep / D, "cycle_time": T, "mean_slip": r["mean_slip"],
            "leg_length": L, "conversion_length": L * sweep / D, "hip_to_ankle": m.lengths["thigh"] + m.lengths["shank"]}


def static_support(p_contact, speed_class: str = "Free", model: ChildModel | None = None) -> str | None:
    """Whether a contact set (39,) carries the data's vertical load at rest in the data's
    poses, as the tracking reference's HAT height needs (:func:`gaitlib.kinematics.
    height_for_load` inside :func:`gaitlib.problems.gait.reference`): None if it does, else
    why not (the pose and load it cannot carry). A set that cannot has no Ch 5 reference.
    ``model``: default the thesis's (:func:`gaitlib.problems.gait.spec_model`)."""
    model = ChildModel() if model is None else model
    try:
        gait_ocp.reference(data_mod.load_gait_data(speed_class, leg_scale=model.leg_scale), model, p_contact)
    except kinematics.LoadNotCarried as e:
        return str(e)
    return None
