"""Chapter 5 gait studies: the MSK (Sec 5.2) and NMSK (Sec 5.3) data-tracking solves with the
identified MTGs, the EMG mapping and comparison, and the metabolic cost.

Functions
---------
:func:`ch5_spec`            the Ch 5 specs: MSK Eq 5.33 (Table 5.3) and NMSK Eq 5.55
                            (Table 5.9, τ_act, c3, s1, s2 identified, EMG guess), with our
                            identified MTG set (``mtg_params="ch5"``) and the Ch 4 body and
                            contact sets when they exist (:func:`parameter_sets`).
:func:`solve`               solve or reload one of them (:func:`gaitlib.problems.gait.solve_cached`).
:func:`emg_table`           the muscle ↔ EMG-channel mapping (thesis Table 5.5 muscles;
                            Schwartz 2008 and gaitutils channels).
:func:`emg_reference`       the EMG of both sources on the 16 excitations' names.
:func:`excitation_scores`   predicted excitations against the EMG (shape and level).
:func:`activation_table`    τ_act, c3, s1, s2: ours beside thesis Table 5.10.
:func:`cot_breakdown`       the cost of transport (Eq 5.57) by term of Eq 5.38, and with the
                            two readings of the shortening heat.
:func:`cot_readings`        the COT under each open reading of Eqs 5.38, 5.47, 5.48 and 5.57,
                            one change at a time (same trajectory, not re-optimised).
:func:`mtb_scale_table`     the size of the Mtb term under its normalisation (Eq 5.56).
:func:`excitation_figure`   thesis Fig 5.11.
:func:`angle_errors`        the largest angle error per joint and where in the cycle.
:func:`findings`            the chapter's findings as sentences, every number from the results.

EMG: our data are not the thesis's (Bovi 2011, eight muscles with SD). Schwartz et al.
2008 give rectus femoris, medial and lateral hamstrings, tibialis anterior and medial
gastrocnemius with SD; the gaitutils normal envelopes give all eight of the thesis's
muscles (gluteus maximus, rectus femoris, vasti, hamstrings, soleus, peronei,
gastrocnemius, tibialis anterior) without SD, normalised to their peak — of which
gluteus maximus and soleus are on/off activity windows (values 0 and 0.95), not envelopes
(:func:`emg_reference` reports the kind). The mapping is
:data:`EMG_MAP`; the NMSK guess uses the Schwartz EMG where it has the muscle (the
transcription's ``excitation_guess="emg"``) and the inverse-MTG excitations elsewhere.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from .. import activation
from .. import conventions as cv
from .. import data as data_mod
from .. import marks
from .. import metabolics
from .. import params as params_mod
from ..problems import gait as gait_ocp
from . import gait as sg

__all__ = ["EMG_MAP", "THESIS_TABLE_5_10", "THESIS_COT", "CHILD_COT_GROSS", "THESIS_HOURS", "STRIDE_COST", "parameter_sets", "ch5_spec", "solve",
           "save_activation", "activation_sets",
           "emg_table", "emg_reference", "excitation_scores", "activation_table", "cot_breakdown",
           "cot_readings", "cot_ranges", "pelvis_travel", "min_generator_torque", "THESIS_DISTANCE_M", "OPENSIM_BASAL_W_PER_KG",
           "mtb_scale_table", "excitation_figure", "saturation", "synergy_cost_table", "MOVED_TOL",
           "verdict_text", "range_text", "thesis_rmse_range", "moved_parameters", "short_generators",
           "angle_errors", "findings"]

#: Thesis muscle → (Schwartz 2008 channel stem, gaitutils channel stem, note). Channel stems
#: are :class:`gaitlib.data.GaitData` columns without ``_r``/``_l``.
EMG_MAP = {
    "GM": (None, "emg_GM", "gaitutils 'Glut' (gluteus maximus)"),
    "RF": ("emg_RF", "emg_RF", "rectus femoris in both"),
    "VM": (None, "emg_VM", "gaitutils 'Vas' (vasti)"),
    "BF": ("emg_LH", "emg_BF", "Schwartz lateral hamstrings (= biceps femoris); gaitutils 'Ham'"),
    "SOL": (None, "emg_SOL", "gaitutils 'Sol'"),
    "PL": (None, "emg_PL", "gaitutils 'Per' (peronei)"),
    "GAM": ("emg_MG", "emg_GAM", "medial gastrocnemius in both"),
    "TA": ("emg_TA", "emg_TA", "tibialis anterior in both"),
}
#: Thesis Table 5.10 (initial and identified activation parameters).
THESIS_TABLE_5_10 = {"initial": dict(activation.ACTIVATION_INITIAL), "identified": dict(activation.ACTIVATION_IDENTIFIED)}
#: Thesis Sec 5.3.5: COT of the NMSK natural-speed solve, J kg⁻¹ m⁻¹ (Eq 5.57).
THESIS_COT = 1.53
#: Measured gross cost of transport of children walking at their free speed, J kg⁻¹ m⁻¹:
#: Waters RL, Hislop HJ, Thomas L, Campbell J (1983) "Energy cost of walking in normal
#: children and teenagers", Dev Med Child Neurol 25:184–188 — 6–12 years, oxygen cost
#: 0.22 mL O₂ kg⁻¹ m⁻¹ (15.3 mL kg⁻¹ min⁻¹ at ≈ 70 m/min), times :data:`J_PER_ML_O2`.
#: Gross: it includes the whole body's resting rate (the model's Eq 5.48 basal term covers
#: its muscles only).
CHILD_COT_GROSS_ML_O2 = 0.22
#: Energy equivalent of oxygen, J per mL O₂ (≈ 20.1 at a respiratory exchange ratio ≈ 0.85).
J_PER_ML_O2 = 20.1
CHILD_COT_GROSS = CHILD_COT_GROSS_ML_O2 * J_PER_ML_O2
#: Metabolic cost per stride of walkers at their most economical speed, J kg⁻¹ stride⁻¹, mean
#: and SD: Weyand PG, Smith BR, Puyau MR, Butte NF (2010) "The mass-specific energy cost of
#: human walking is set by stature", J Exp Biol 213:3972–3979 — 48 subjects aged 5–32 years,
#: statures 1.07–1.83 m, treadmill, 2.74 ± 0.12 (abstract). "Largely invariant" with size, so it
#: applies to a child within those statures; the abstract does not say whether it is gross or net.
STRIDE_COST = (2.74, 0.12)
#: Thesis computation times (GPOPS-II, i7-6700): MSK Sec 5.2.2, NMSK Sec 5.3.5, hours.
THESIS_HOURS = {"MSK": 2.0, "NMSK": 2.0}


def parameter_sets() -> dict[str, str]:
    """Body, contact and MTG parameter sets of the Ch 5 solves. The thesis builds Ch 5 on
    its Ch 4 identified body and contact parameters: ours (``"ch4"``,
    ``data/identified/ch4_child.json``) if that file exists, else the thesis's identified
    values (body ``"thesis"``: Tables 4.15–4.16; contact ``"default"``: Tables 4.17–4.18).
    MTGs: our Ch 5 identified set (``"ch5"``)."""
    ch4 = params_mod.identified_path("ch4_child").is_file()
    return {"body_params": "ch4" if ch4 else "thesis", "contact_params": "ch4" if ch4 else "default",
            "mtg_params": "ch5"}


def ch5_spec(model: str = "MSK", **kw) -> gait_ocp.GaitSpec:
    """The Ch 5 data-tracking spec of ``model``: MSK → Eq 5.33 (Table 5.3); NMSK → Eq 5.55
    (Table 5.9) with the activation parameters identified (``free_activation``, Eq 5.53,
    Table 5.10 initial values), the EMG guess (Sec 5.3.4) and at most 3,000 iterations. Parameter sets from
    :func:`parameter_sets`; ``kw`` override any field; ``reading="book"``
    (:data:`gaitlib.studies.gait.READINGS`; default the thesis's) also gives MSK 3,000 iterations."""
    base = dict(parameter_sets())
    if model == "NMSK":
        # max_iter 3000: from the thesis's data-based guess IPOPT needs ≈ 2,100 iterations
        base.update(free_activation=True, excitation_guess="emg", max_iter=3000)
    elif kw.get("reading") == "book":
        # the swinging foot unloaded takes MSK past 1,000 iterations (measured on 2026-12-02)
        base.update(max_iter=3000)
    base.update(kw)
    return sg.natural_gait_spec(model, **base)


#: Spec fields that only the NMSK model takes (dropped for its MSK warm start).
_NMSK_ONLY = ("free_activation", "excitation_guess", "t_stim", "cost", "weights", "max_iter", "isometric_torque")


def solve(model: str = "MSK", *, guess: str = "msk", root=None, progress: bool = False, **kw) -> gait_ocp.GaitSolution:
    """Solve or reload :func:`ch5_spec` (solution cache keyed by spec, code, data and guess).

    MSK: from the data-based guess (Sec 5.2.1). NMSK: ``guess="msk"`` (default) — warm
    start from the Ch 5 MSK solution (solved or reloaded first with the same ``kw``): its
    states, jerks, residuals and metatarsal torques, its MTG activations turned into
    excitations through the inverted activation dynamics for GM, VM, SOL and PL, and the
    delayed Schwartz EMG for RF, BF, GAM and TA (:func:`gaitlib.problems.gait.warm_start`);
    ``guess="data"`` — the thesis's guess (Sec 5.3.4: states from the data, excitations from
    the EMG where we have it). From ``"data"`` IPOPT needs about nine times the iterations
    and stops at a higher objective (measurements: environment.md, "Measured choices").
    """
    spec = ch5_spec(model, **kw)
    if model == "NMSK" and guess == "msk":
        base = solve("MSK", root=root, progress=progress, **{k: v for k, v in kw.items() if k not in _NMSK_ONLY})
        return gait_ocp.solve_cached(spec, guess=base, root=root, progress=progress)
    if guess not in ("msk", "data"):
        raise ValueError(f"guess must be 'msk' or 'data', got {guess!r}")
    return gait_ocp.solve_cached(spec, root=root, progress=progress)


def save_activation(sol: gait_ocp.GaitSolution, path=None) -> Path:
    """Write the activation parameters γ (τ_act s; c3, s1, s2 dimensionless, Eq 5.53) that the
    Ch 5 NMSK solve ``sol`` identified (``free_activation``), with their provenance, to
    ``data/identified/ch5_activation.json`` (default; the set ``GaitSpec(activation_params="ch5")``
    reads). Refuses a solve that did not converge or did not identify γ. The file is part of
    the cache keys of exactly the specs that read it."""
    if not sol.spec.free_activation or not sol.stats.get("activation_parameters"):
        raise ValueError("save_activation: expects an NMSK solve that identified its activation parameters")
    if sol.stats["status"] not in ("Solve_Succeeded", "Solved_To_Acceptable_Level"):
        raise ValueError(f"save_activation: the solve did not converge ({sol.stats['status']}); not saving")
    path = Path(path) if path is not None else params_mod.identified_path(gait_ocp.ACTIVATION_SET)
    ap = sol.stats["activation_parameters"]
    out = {
        "name": gait_ocp.ACTIVATION_SET,
        "description": ("Activation parameters (Eq 5.53) identified by the Ch 5 NMSK data-tracking solve (Eq 5.55, "
                        "free_activation) on the Schwartz 2008 Free-speed data; tau_act in s, c3, s1, s2 "
                        "dimensionless."),
        "params": {k: float(ap[k]) for k in gait_ocp.ACTIVATION_PARAMS},
        "bounds": {k: [float(a), float(b)] for k, (a, b) in activation.ACTIVATION_BOUNDS.items()},
        "provenance": {"study": "gaitlib.studies.msk.solve('NMSK', reading=...)", "spec": sol.spec.to_dict(),
                       "spec_key": sol.spec.key(), "ipopt_status": sol.stats["status"],
                       "iterations": int(sol.stats["iterations"]), "objective": float(sol.stats["objective"])},
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(out, indent=1) + "\n")
    return path


def activation_sets() -> pd.DataFrame:
    """The activation parameters γ the NMSK runs of Chs 6–7 can carry: Table 5.10's identified
    values (the thesis's, on its data) and ours (:func:`save_activation`, the Ch 5 NMSK solve on
    our data), with their bounds (Sec 5.3.4). τ_act in s; c3, s1, s2 dimensionless."""
    ours = gait_ocp.load_activation_params(params_mod.identified_path(gait_ocp.ACTIVATION_SET))
    rows = {"Table 5.10 (thesis)": dict(activation.ACTIVATION_IDENTIFIED), "Ch 5 (ours, our data)": ours,
            "lower bound": {k: v[0] for k, v in activation.ACTIVATION_BOUNDS.items()},
            "upper bound": {k: v[1] for k, v in activation.ACTIVATION_BOUNDS.items()}}
    return pd.DataFrame(rows).T[list(gait_ocp.ACTIVATION_PARAMS)].astype(float)


# --------------------------------------------------------------------------------------
# EMG
# --------------------------------------------------------------------------------------


def emg_table() -> pd.DataFrame:
    """The mapping of the thesis's eight muscles (Table 5.5) to our EMG channels."""
    rows = []
    for m, (sch, gu, note) in EMG_MAP.items():
        rows.append({"muscle": m, "name": activation.MUSCLE_NAMES[m],
                     "MTG (Table 5.5)": activation.MUSCLE_GENERATOR[m],
                     "Schwartz 2008 (mean ± SD)": sch or "—", "gaitutils (mean, no SD)": gu,
                     "in the NMSK guess": "Schwartz EMG" if sch else "inverse MTG", "note": note})
    return pd.DataFrame(rows).set_index("muscle")


def emg_reference(speed_class: str = "Free") -> dict:
    """EMG of both sources on the excitations' names (``GM_r`` … ``TA_l``), on the Schwartz
    data's time grid (s).

    Returns ``{'schwartz': (mean, sd), 'gaitutils': (mean, None), 'gaitutils_scale': k,
    'gaitutils_kind': {muscle: 'envelope' | 'on/off'}}``; absent muscles are missing
    columns. gaitutils's gluteus maximus and soleus entries take only a few values (0 and
    0.95 with interpolated steps): they are on/off activity windows, not envelopes. The left leg is the right leg's envelope shifted by
    the data's left-leg phase (for gaitutils, whose envelopes are each on their own leg's
    cycle; Schwartz's left is already shifted by the loader). gaitutils envelopes (peak ≈ 1)
    are multiplied by one factor k — the mean ratio of the Schwartz to the gaitutils peak over
    the four muscles both sources have — so both are on the Schwartz scale.
    """
    sch = data_mod.load_gait_data(speed_class)
    gu = data_mod.load_gait_data("Free", "gaitutils")
    t = np.asarray(sch.time, float)
    frac = t / sch.cycle_time
    mean_s, sd_s, mean_g = {}, {}, {}
    for m, (cs, cg, _) in EMG_MAP.items():
        for side in cv.SIDES:
            if cs:
                mean_s[f"{m}_{side}"] = sch.mean[f"{cs}_{side}"].to_numpy()
                sd_s[f"{m}_{side}"] = sch.sd[f"{cs}_{side}"].to_numpy()
        fg = np.asarray(gu.time, float) / gu.cycle_time
        yr = np.interp(frac, fg, gu.mean[f"{cg}_r"].to_numpy())
        mean_g[f"{m}_r"] = yr
        mean_g[f"{m}_l"] = np.interp(np.mod(frac - sch.left_shift, 1.0), frac, yr, period=1.0)
    kind = {m: ("on/off" if np.unique(np.round(gu.mean[f"{cg}_r"].to_numpy(), 6)).size <= 5 else "envelope")
            for m, (_, cg, _) in EMG_MAP.items()}
    ratios = [np.max(mean_s[f"{m}_r"]) / np.max(mean_g[f"{m}_r"]) for m, (cs, _, _) in EMG_MAP.items() if cs]
    k = float(np.mean(ratios))
    idx = pd.Index(t, name="time")
    return {"schwartz": (pd.DataFrame(mean_s, index=idx), pd.DataFrame(sd_s, index=idx)),
            "gaitutils": (pd.DataFrame({c: k * v for c, v in mean_g.items()}, index=idx), None),
            "gaitutils_scale": k, "gaitutils_kind": kind}


def excitation_scores(sol: gait_ocp.GaitSolution) -> pd.DataFrame:
    """Predicted excitations e(t) (NMSK) against the EMG, per muscle (both legs pooled):
    Pearson correlation of the time courses (shape; for gaitutils's on/off windows, of the
    timing) and mean levels, for each source; the share of the cycle inside the Schwartz
    ±1 SD band; and the mean node-to-node change |Δe| beside the EMG's on the same nodes
    (roughness)."""
    if sol.excitations is None:
        raise ValueError("excitation_scores needs an NMSK solution")
    ref = emg_reference(sol.spec.speed_class)
    ex = sol.excitations
    tf = float(sol.stats["tf_s"])
    rows = []
    for m in activation.MUSCLES:
        row = {"muscle": m}
        sims, refs = {}, {}
        for side in cv.SIDES:
            c = f"{m}_{side}"
            ts = ex.index.to_numpy() / tf
            sims[side] = ex[c].to_numpy()
            for src in ("schwartz", "gaitutils"):
                mean = ref[src][0]
                if c in mean:
                    tr_ = mean.index.to_numpy() / mean.index[-1]
                    refs.setdefault(src, {})[side] = np.interp(ts, tr_, mean[c].to_numpy())
            if c in ref["schwartz"][0]:
                mean, sd = ref["schwartz"][0][c], ref["schwartz"][1][c]
                tr_ = mean.index.to_numpy() / mean.index[-1]
                mu, s = np.interp(ts, tr_, mean.to_numpy()), np.interp(ts, tr_, sd.to_numpy())
                row.setdefault("_band", []).append(np.abs(sims[side] - mu) <= s)
        e = np.concatenate([sims[s] for s in cv.SIDES])
        row["mean e (ours)"] = float(np.mean(e))
        for src, lab in (("schwartz", "Schwartz"), ("gaitutils", "gaitutils")):
            if src in refs:
                r = np.concatenate([refs[src][s] for s in cv.SIDES])
                row[f"r ({lab})"] = float(np.corrcoef(e, r)[0, 1]) if np.std(e) > 0 else np.nan
                row[f"mean EMG ({lab})"] = float(np.mean(r))
            else:
                row[f"r ({lab})"] = np.nan
                row[f"mean EMG ({lab})"] = np.nan
        band = row.pop("_band", None)
        row["% in Schwartz ±1 SD"] = 100 * float(np.mean(np.concatenate(band))) if band else np.nan
        row["gaitutils kind"] = ref["gaitutils_kind"][m]
        row["mean |Δe| per node (ours)"] = float(np.mean([np.mean(np.abs(np.diff(sims[s]))) for s in cv.SIDES]))
        src = "schwartz" if "schwartz" in refs else "gaitutils"
        row["mean |Δ| per node (EMG)"] = float(np.mean([np.mean(np.abs(np.diff(refs[src][s]))) for s in cv.SIDES]))
        rows.append(row)
    return pd.DataFrame(rows).set_index("muscle")


def excitation_figure(sol: gait_ocp.GaitSolution, side: str = "r"):
    """Thesis Fig 5.11: predicted excitations e(t) of one leg's eight muscles, with the
    Schwartz EMG (mean ± 1 SD) where it has the muscle and the scaled gaitutils envelope."""
    import matplotlib.pyplot as plt

    ref = emg_reference(sol.spec.speed_class)
    fig, axes = plt.subplots(2, 4, figsize=(13, 5), constrained_layout=True, sharex=True)
    tf = float(sol.stats["tf_s"])
    for ax, m in zip(axes.flat, activation.MUSCLES):
        c = f"{m}_{side}"
        mean, sd = ref["schwartz"]
        if c in mean:
            pct = 100 * mean.index / mean.index[-1]
            ax.fill_between(pct, mean[c] - sd[c], mean[c] + sd[c], color="0.85", label="Schwartz EMG ±1 SD")
            ax.plot(pct, mean[c], ":", color="0.3", label="Schwartz EMG mean")
        g = ref["gaitutils"][0]
        pg = 100 * g.index / g.index[-1]
        if ref["gaitutils_kind"][m] == "on/off":
            on = g[c].to_numpy() > 0.5 * g[c].max()
            ax.fill_between(pg, 0, 1, where=on, transform=ax.get_xaxis_transform(), color="tab:green", alpha=0.12,
                            label="gaitutils on window")
        else:
            ax.plot(pg, g[c], "--", color="tab:green", lw=1, label=f"gaitutils × {ref['gaitutils_scale']:.2f}")
        ax.plot(100 * sol.excitations.index / tf, sol.excitations[c], color="tab:red", lw=1.6,
                label="NMSK e(t)")
        ax.set_title(f"{m} ({activation.MUSCLE_GENERATOR[m].replace('_', ' ')})")
        ax.set_ylim(0, max(0.85, ax.get_ylim()[1]))
    for ax in axes[1]:
        ax.set_xlabel("% gait cycle")
    handles = {}
    for ax in axes.flat:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    fig.legend(handles.values(), handles.keys(), loc="lower center", ncols=len(handles), fontsize=8,
               bbox_to_anchor=(0.5, -0.06))
    return fig


# --------------------------------------------------------------------------------------
# Activation parameters, saturation, metabolics
# --------------------------------------------------------------------------------------


def activation_table(sol: gait_ocp.GaitSolution) -> pd.DataFrame:
    """τ_act (s), c3, s1, s2: Table 5.10's initial values, ours (identified when the spec
    frees them), the thesis's identified values (labelled), the bounds (Sec 5.3.4) and
    whether ours sit at a bound (within 1 % of the range)."""
    ours = sol.stats["activation_parameters"]
    rows = []
    for k in gait_ocp.ACTIVATION_PARAMS:
        lo, hi = activation.ACTIVATION_BOUNDS[k]
        v = ours[k]
        at = "lower" if v - lo < 0.01 * (hi - lo) else ("upper" if hi - v < 0.01 * (hi - lo) else "")
        rows.append({"parameter": k, "initial (Table 5.10)": THESIS_TABLE_5_10["initial"][k], "ours": v,
                     "thesis, Table 5.10": THESIS_TABLE_5_10["identified"][k], "bounds": (lo, hi),
                     "ours at bound": at})
    return pd.DataFrame(rows).set_index("parameter")


def synergy_cost_table(sol: gait_ocp.GaitSolution | None = None) -> pd.DataFrame:
    """Why the synergy weights s1, s2 (Eq 5.54) run to a corner: for a given ankle-extensor
    activation A = s1 a_SOL + s2 a_PL + (1 − s1 − s2) a_GAM, the least Act cost
    a_SOL² + a_PL² + a_GAM² (Eq 5.55's fifth term) is A² / |w|² with w = (s1, s2, 1 − s1 − s2)
    (Cauchy–Schwarz; attained at a ∝ w). The factor 1/|w|² is largest (3) at the thesis's
    initial guess (1/3, 1/3) — a stationary point — and falls towards every corner of the
    bounds [0, 0.5]². Nothing else in Eq 5.55 involves s1, s2 (no EMG term), so they are
    not identified by data. Rows: Table 5.10's initial and identified values, ours (if
    ``sol``), the corners."""
    rows = {"initial (Table 5.10)": (1 / 3, 1 / 3), "thesis, Table 5.10": (0.25, 0.25)}
    if sol is not None:
        ap = sol.stats["activation_parameters"]
        rows["ours"] = (ap["s1"], ap["s2"])
    rows.update({"corner (0.5, 0.5)": (0.5, 0.5), "corner (0.5, 0)": (0.5, 0.0), "corner (0, 0): GAM only": (0.0, 0.0)})
    out = []
    for lab, (s1, s2) in rows.items():
        w = np.array([s1, s2, 1 - s1 - s2])
        out.append({"weights": lab, "s1": s1, "s2": s2, "GAM weight": 1 - s1 - s2, "Act cost / A²": 1 / float(w @ w)})
    return pd.DataFrame(out).set_index("weights")


def saturation(sol: gait_ocp.GaitSolution, level: float = 0.99) -> pd.Series:
    """Share of nodes at which each of the 12 generator activations is ≥ ``level``."""
    return (sol.activations >= level).mean()


def _nmsk_rate(sol: gait_ocp.GaitSolution, **kw) -> dict:
    """:func:`gaitlib.metabolics.nmsk_metabolic_rate` on an NMSK solution's control nodes, in the
    reading its NLP minimised (the spec's ``isometric_torque``) unless ``kw`` says otherwise."""
    kw.setdefault("isometric_torque", getattr(getattr(sol, "spec", None), "isometric_torque", None) or "thesis")
    U = sol.solution.phase("cycle").controls
    q = {j: sol.q[j].to_numpy() for j in cv.JOINTS}
    qd = {j: sol.qd[j].to_numpy() for j in cv.JOINTS}
    ed = {m: U[f"ed_{m}"].to_numpy() for m in gait_ocp.NMSK_MUSCLES}
    am = {m: sol.muscle_activations[m].to_numpy() for m in gait_ocp.NMSK_MUSCLES}
    ap = sol.stats["activation_parameters"]
    ts = dict(zip(gait_ocp.NMSK_MUSCLES, sol.stats["t_stim_s"]))
    mtp = {f"mtp_{s}": U[f"tau_mtp_{s}"].to_numpy() for s in cv.SIDES}
    return metabolics.nmsk_metabolic_rate(q, qd, ed, am, gait_ocp.mtg_params_of(sol.spec), s1=ap["s1"], s2=ap["s2"],
                                          mtp_torques=mtp, t_stim=ts, **kw)


def _recompute_edot(sol: gait_ocp.GaitSolution, **kw) -> dict:
    """Ė (W) of an NMSK solution's trajectory with :func:`gaitlib.metabolics.nmsk_metabolic_rate`
    options ``kw`` (e.g. ``isometric_torque="bhargava"``), at the control nodes."""
    r = _nmsk_rate(sol, **kw)
    return {k: np.asarray(r[k], float) * np.ones(len(sol.q)) for k in
            ("total", "activation", "maintenance", "shortening", "basal", "work")}


def _stride(sol) -> float:
    """The data's stride D = speed × cycle time, m (the distance of Eq 5.57 the NLP uses: the
    spec's speed class's data as the spec reads it, :func:`gaitlib.problems.gait.spec_gait_data`
    — on longer legs their speed and cycle time)."""
    g = gait_ocp.spec_gait_data(sol.spec)[0]
    return g.speed * g.cycle_time


def _cot_of(sol, edot, distance: float | None = None) -> float:
    t = sol.q.index.to_numpy()
    tf = float(sol.stats["tf_s"])
    per = t < tf - 1e-12
    tt = np.append(t[per], tf)
    ee = np.append(np.asarray(edot)[per], np.asarray(edot)[per][0])
    return metabolics.cost_of_transport(tt, ee, distance=_stride(sol) if distance is None else distance)


#: The two readings of Eq 5.47's F0 (:func:`gaitlib.metabolics.nmsk_metabolic_rate`'s
#: ``isometric_torque``) → their column label in :func:`cot_breakdown`.
F0_READINGS = {"thesis": "F0 = s^τ τ0 (thesis)", "bhargava": "Bhargava F_iso = a τ0 t^A"}


def cot_breakdown(sol: gait_ocp.GaitSolution) -> pd.DataFrame:
    """Cost of transport (Eq 5.57, J kg⁻¹ m⁻¹) of an NMSK solution by term of Eq 5.38
    (each term integrated alone; 'total' includes the clipping of negative non-basal
    power, so the terms need not add up to it), for two readings of the shortening heat:
    the thesis's F0 in Eq 5.47 (isometric term 0.16 s^τ τ0 ω_f even for a relaxed
    generator; the heat's sign is Bhargava's, :func:`cot_readings`) and Bhargava's
    (0.16 a s^τ τ0 t^A(θ) ω_f). The reading the NLP minimised (its spec's
    ``isometric_torque``) is the first column, labelled "NLP: …"; the other is the same
    trajectory, recomputed, not re-optimised."""
    nlp = getattr(getattr(sol, "spec", None), "isometric_torque", None) or "thesis"
    out = {}
    for k in [nlp] + [r for r in F0_READINGS if r != nlp]:
        e = _recompute_edot(sol, isometric_torque=k)
        out[("NLP: " if k == nlp else "") + F0_READINGS[k]] = {t: _cot_of(sol, v) for t, v in e.items()}
    df = pd.DataFrame(out)
    df.index.name = "term of Eq 5.38"
    return df


#: Thesis Sec 5.3.4 (text after Eq 5.56): "D is 1.24 (m) that is the distance the child subject
#: travelled" — the thesis's own subjects' distance, m.
THESIS_DISTANCE_M = 1.24
#: OpenSim's Bhargava2004MuscleMetabolicsProbe default ``basal_coefficient``, W/kg body mass.
OPENSIM_BASAL_W_PER_KG = 1.2
_TERMS = ("activation", "maintenance", "shortening", "basal", "work")


def pelvis_travel(sol: gait_ocp.GaitSolution) -> float:
    """pelvis_tx(t_f) − pelvis_tx(t_0) of a gait solution's states, m (the distance the model
    itself travels over the cycle)."""
    x = sol.solution.phase("cycle").states["pelvis_tx"]
    return float(x.iloc[-1] - x.iloc[0])


def min_generator_torque(sol: gait_ocp.GaitSolution) -> float:
    """Smallest generator torque τ^M (N·m, ≥ 0) over the 12 MTGs and the control nodes of an
    NMSK solution: Eq 5.47's printed case split differs from the split on ω_f only where
    τ^M = 0."""
    return float(min(np.min(np.asarray(v, float)) for v in _nmsk_rate(sol)["generator_torques"].values()))


def cot_readings(sol: gait_ocp.GaitSolution) -> pd.DataFrame:
    """Cost of transport (Eq 5.57, J kg⁻¹ m⁻¹) of an NMSK solution under each reading of the
    metabolic model the thesis leaves open, one change at a time from the NLP's own reading.

    Same stored trajectory (states, controls, activation parameters, t_stim of the NLP),
    Ė recomputed with :func:`gaitlib.metabolics.nmsk_metabolic_rate`; **not re-optimised**:
    the motion would change if the NLP minimised another reading.

    Rows (``reading``): the NLP's reading first (Bhargava's sign with ω_f, split on ω_f,
    F0 = s^τ τ0, basal Eq 5.48, non-basal part smoothly clipped at 0, D = the data's stride
    speed × cycle time), then Eq 5.47's sign as printed; its case split τ^M θ̇ ≥ 0 as printed;
    Bhargava's F_iso = a s^τ τ0 t^A; Eq 5.38's plain sum (no clipping); OpenSim's whole-body
    basal rate 1.2 W/kg × BM; D = the solution's pelvis_tx travel over the cycle; D = the
    thesis's 1.24 m. Last, the thesis's value (Sec 5.3.5, reference only; the thesis prints
    no breakdown).

    Columns: ``what changes`` (one line, with its equation), ``COT`` (total), ``change vs
    NLP reading (%)``, and each term of Eq 5.38 integrated alone (``activation``,
    ``maintenance``, ``shortening``, ``basal``, ``work``; the total includes the clipping,
    so the terms need not add up to it).
    """
    if getattr(getattr(sol, "spec", None), "isometric_torque", None):
        raise ValueError("cot_readings: its rows change one thing from the thesis's F0 reading; this solve minimised "
                         f"isometric_torque={sol.spec.isometric_torque!r} (use cot_breakdown or cot_ranges)")
    D = _stride(sol)
    rec = [
        ("NLP's reading (default)", ("Ṡ = α ω_f (> 0 shortening), split on ω_f, F0 = s^τ τ0; Ḃ = 0.0225 m; "
                                     "Ė = ΣḂ + smax(rest) (Eq 5.38 clipped); D = speed × T"), {}, D),
        ("Eq 5.47 sign as printed", ("Ṡ = −(0.16 s^τ τ0 + 0.18 τ^M) θ̇ concentric, −0.157 τ^M θ̇ eccentric, "
                                     "θ̇ ≡ ω_f (Eq 5.47 literal: negative heat when shortening)"), {"shortening_sign": "printed"}, D),
        ("Eq 5.47 case split as printed", ("concentric case where τ^M θ̇ ≥ 0 (Eq 5.47), i.e. also where "
                                           "τ^M = 0 and lengthening"), {"shortening_split": "printed"}, D),
        ("F0 Bhargava", "Eq 5.47's 0.16 s^τ τ0 → 0.16 a s^τ τ0 t^A(θ) (Bhargava 2004 / OpenSim F_iso)",
         {"isometric_torque": "bhargava"}, D),
        ("negative totals: plain sum", "Ė = Σ(Ȧ + Ṁ + Ḃ) + ΣṠ + ΣẆ without clipping (Eq 5.38 as printed)",
         {"forbid_negative": False}, D),
        ("basal whole-body (OpenSim)", (f"Ḃ = {OPENSIM_BASAL_W_PER_KG:g} W/kg × BM instead of Eq 5.48's "
                                        "0.0225 W/kg × muscle mass"), {"basal_whole_body": OPENSIM_BASAL_W_PER_KG}, D),
        ("D = pelvis travel", "Eq 5.57's D = pelvis_tx(t_f) − pelvis_tx(t_0) of the solution", {}, pelvis_travel(sol)),
        ("D = thesis 1.24 m", "Eq 5.57's D = 1.24 m (thesis Sec 5.3.4: its subjects' distance)", {}, THESIS_DISTANCE_M),
    ]
    cache: dict = {}
    rows = []
    for lab, what, kw, dist in rec:
        key = tuple(sorted(kw.items()))
        if key not in cache:
            cache[key] = _recompute_edot(sol, **kw)
        e = cache[key]
        row = {"reading": lab, "what changes": what, "COT": _cot_of(sol, e["total"], dist)}
        row.update({k: _cot_of(sol, e[k], dist) for k in _TERMS})
        rows.append(row)
    df = pd.DataFrame(rows).set_index("reading")
    df.insert(2, "change vs NLP reading (%)", 100.0 * (df["COT"] / df["COT"].iloc[0] - 1.0))
    df.loc["thesis, Sec 5.3.5 (reference)"] = {"what changes": "printed value; no breakdown printed",
                                                "COT": THESIS_COT}
    return df


def cot_ranges(solutions: dict, readings: dict | None = None) -> pd.DataFrame:
    """The cost of transport of NMSK solutions against children's measured costs.

    ``solutions``: label → NMSK solution; ``readings``: label → keyword arguments of
    :func:`gaitlib.metabolics.nmsk_metabolic_rate` to recompute that solution's Ė in another
    reading than its NLP's (e.g. ``{"isometric_torque": "bhargava"}``: not re-optimised).

    Columns, all at the data's stride D (Eq 5.57): ``COT`` — the model's own (Eq 5.38, muscle-only
    basal rate Eq 5.48: a net cost, J kg⁻¹ m⁻¹); ``COT gross`` — the same with OpenSim's
    whole-body resting rate (:data:`OPENSIM_BASAL_W_PER_KG`) in place of Eq 5.48's; ``per stride``
    and ``per stride gross`` — both × D (J kg⁻¹ stride⁻¹); ``gross ÷ Waters`` — ``COT gross`` over
    the gross COT of 6–12-year-olds at free speed (:data:`CHILD_COT_GROSS`); ``z (net)`` and
    ``z (gross)`` — (per stride − mean) / SD of :data:`STRIDE_COST` (Weyand et al. 2010)."""
    readings = dict(readings or {})
    mean, sd = STRIDE_COST
    rows = []
    for lab, sol in solutions.items():
        kw = dict(readings.get(lab, {}))
        D = _stride(sol)
        net = _cot_of(sol, _recompute_edot(sol, **kw)["total"])
        gross = _cot_of(sol, _recompute_edot(sol, basal_whole_body=OPENSIM_BASAL_W_PER_KG, **kw)["total"])
        rows.append({"run": lab, "D (m)": D, "COT": net, "COT gross": gross, "per stride": net * D,
                     "per stride gross": gross * D, "gross ÷ Waters": gross / CHILD_COT_GROSS,
                     "z (net)": (net * D - mean) / sd, "z (gross)": (gross * D - mean) / sd})
    return pd.DataFrame(rows).set_index("run")


def mtb_scale_table(sol: gait_ocp.GaitSolution) -> pd.DataFrame:
    """How big the Mtb term (Eq 5.55's 8th term, Eq 5.56 normalisation) is: mean Ė, the
    normalising range Ė_max − Ė_min, the factor t_f⁶/(BM² D⁴) with D the stride (our
    reading of the thesis's "d") and with d = 50 ms (the delay, the other symbol named d),
    and the resulting weighted term beside the objective."""
    D = _stride(sol)
    tf = float(sol.stats["tf_s"])
    ebar = float(sol.stats["mean_metabolic_rate_W"])
    de = gait_ocp.MTB_COT_N * (gait_ocp.MTB_BM_MAX - gait_ocp.MTB_BM_MIN) * D / tf
    w = sol.spec.term_weights.get("Mtb", 0.0)
    rows = []
    for lab, d in (("d = stride D (ours)", D), ("d = delay 0.05 s", activation.DELAY)):
        f = tf**6 / (cv.BODY_MASS**2 * d**4)
        rms = float(np.sqrt(np.mean(sol.metabolic["total"].to_numpy() ** 2)))
        term = f * (rms / de) ** 2  # (1/t_f)∫ … dt ≈ mean of the integrand
        rows.append({"reading": lab, "mean Ė (W)": ebar, "Ė_max − Ė_min (W)": de, "t_f⁶/(BM² d⁴)": f,
                     "w·Mtb (approx.)": w * term, "objective": float(sol.stats["objective"])})
    return pd.DataFrame(rows).set_index("reading")


# --------------------------------------------------------------------------------------
# What the chapter found
# --------------------------------------------------------------------------------------

#: A parameter counts as moved by the data when it leaves Eq 5.22's adult value by more than
#: this (Table 5.2's units: Δ^P in degrees, the rest dimensionless).
MOVED_TOL = 1e-2
#: Thesis Table 5.10's identified activation parameters, as the chapter quotes them.
THESIS_ACTIVATION_TEXT = "τ_act 0.006 s, c3 0.0001, s1 = s2 = 0.25"


def verdict_text(stats: dict) -> str:
    """``"converged"`` or ``"did NOT converge (<IPOPT status>)"`` from a solve's stats."""
    return "converged" if stats["success"] else f"did NOT converge ({stats['status']})"


def range_text(values) -> str:
    """``"min–max"`` of ``values`` with one decimal (e.g. an RMSE range)."""
    v = pd.Series(list(values), dtype=float)
    return f"{v.min():.1f}–{v.max():.1f}"


def thesis_rmse_range(model: str, kind: str) -> str:
    """Range of the thesis's RMSEs of ``model`` (Table 5.4: MSK, 5.11: NMSK) for one
    ``kind`` (``"angle"`` deg, ``"torque"`` N·m, ``"grf"`` N)."""
    return range_text(x for (k, _, _), x in sg.THESIS_RMSE[model].items() if k == kind)


def moved_parameters(table: pd.DataFrame, tol: float = MOVED_TOL, ours: str = "ours",
                     initial: str = "initial (Eq 5.22)") -> pd.Series:
    """The identified parameters (rows of :func:`gaitlib.studies.mtg_id.table_beside_thesis`)
    that differ from the adult value by more than ``tol``: (generator, parameter) → ours."""
    return table.loc[(table[ours] - table[initial]).abs() > tol, ours]


def short_generators(margins: pd.DataFrame, label: str, equation: str = "Eq 5.15") -> pd.Series:
    """Generators whose smallest margin of ``equation`` (N·m, :func:`mtg_id.margins_table`)
    is negative for parameter set ``label``: generator → margin (< 0)."""
    m = margins[label][equation]
    return m[m < 0]


def angle_errors(q: pd.DataFrame, ref_time, ref_mean, cycle_time: float) -> pd.DataFrame:
    """Largest |q − data mean| per joint of a gait solution's angles ``q`` (rad, index time s)
    against the tracked mean ``ref_mean[joint]`` (rad at ``ref_time``, interpolated to the
    solution's times): ``max error (deg)`` and where, ``at (% cycle)`` (0 % = right heel
    strike, cycle ``cycle_time`` s). Rows: the six leg joints."""
    rows = {}
    for j in ("hip_r", "knee_r", "ankle_r", "hip_l", "knee_l", "ankle_l"):
        e = (q[j] - np.interp(q.index, ref_time, ref_mean[j])).abs() / cv.DEG
        rows[j] = {"max error (deg)": e.max(), "at (% cycle)": 100 * e.idxmax() / cycle_time}
    return pd.DataFrame.from_dict(rows, orient="index")


def findings(ident, ident_thesis_tol, params_table: pd.DataFrame, margins: pd.DataFrame, msk_sol, nmsk_sol,
             angle_err: pd.DataFrame, cot: pd.DataFrame, scores: pd.DataFrame) -> list[str]:
    """The chapter's findings, one sentence group per item, every number from the results:
    the MTG identifications (``ident`` at tol 1e-10, ``ident_thesis_tol`` at 1e-5), their
    parameter table (:func:`mtg_id.table_beside_thesis` of ``ident``) and constraint margins
    (:func:`mtg_id.margins_table` with sets "Gymnast (Eq 5.22)", "thesis Table 5.2",
    "ours"), the MSK and NMSK solutions, the MSK's :func:`angle_errors`, the NMSK's
    :func:`cot_breakdown`, and its :func:`excitation_scores` (marked or not). Rows of a
    failed or invalid NMSK solve carry its mark (:func:`gaitlib.marks.mark_rows`)."""
    s0, s1 = ident.stats, ident_thesis_tol.stats
    out = [(f"MTG identification {verdict_text(s0)} in {s0['iterations']} iterations "
            f"({s0['solve_time_s']:.1f} s solve + {s0['build_time_s']:.1f} s build). "
            f"Eq 5.23 objective {s0['objective']:.3g}; at the thesis's tolerance 1e-5 the solve "
            f"({verdict_text(s1)}, {s1['iterations']} it) stops at {s1['objective']:.3g}, "
            f"{s1['cost_Gamma'] / s0['cost_Gamma']:.0f}× our parameter term.")]
    out.append("Parameters the data move by more than 0.01 (tol 1e-10): "
               + ", ".join(f"{g} {k} = {v:.3g}" for (g, k), v in moved_parameters(params_table).items())
               + "; all others stay at the adult values.")
    short = short_generators(margins, "Gymnast (Eq 5.22)")
    short_th = short_generators(margins, "thesis Table 5.2")
    out.append("With the adult curves, Eq 5.15 fails for "
               + ", ".join(f"{g} (short by {-v:.1f} N·m)" for g, v in short.items()) + "; thesis Table 5.2 leaves "
               + (", ".join(f"{g} short by {-v:.1f} N·m" for g, v in short_th.items())
                  or "no generator short on our data")
               + f"; ours: worst Eq 5.15 margin on the fine grid {margins['ours']['Eq 5.15'].min():.2f} N·m "
               "(constraints hold at the collocation points; between them the push-off peak is sampled more finely).")
    for lab, s, th in (("MSK", msk_sol, "Table 5.4"), ("NMSK", nmsk_sol, "Table 5.11")):
        st = s.stats

        def rng(kind, s=s):
            return range_text(s.rmse.loc[s.rmse["kind"] == kind, "rmse"])

        out.append(f"{lab} {verdict_text(st)}: {st['iterations']} iterations, {st['solve_time_s']:.0f} s solve + "
                   f"{st['build_time_s']:.0f} s build ({1e3 * st['time_per_iteration_s']:.0f} ms/iteration; thesis: "
                   f"{THESIS_HOURS[lab]:g} h). RMSE angles {rng('angle')} deg, torques {rng('torque')} N·m, "
                   f"GRFs {rng('grf')} N (thesis, {th}: angles {thesis_rmse_range(lab, 'angle')} deg, torques "
                   f"{thesis_rmse_range(lab, 'torque')} N·m, GRFs {thesis_rmse_range(lab, 'grf')} N).")
    act = marks.mark_rows(activation_table(nmsk_sol), marks.failure_label(nmsk_sol))
    out.append("Activation parameters (ours): " + ", ".join(
        f"{k} = {v:.4g}" + (f" (at its {b} bound)" if b else "") for k, v, b in
        zip(act.index, act["ours"], act["ours at bound"])) + f" — thesis Table 5.10: {THESIS_ACTIVATION_TEXT}.")
    c, cb = cot["NLP: " + F0_READINGS["thesis"]], cot[F0_READINGS["bhargava"]]
    out.append(f"COT {c['total']:.2f} J/(kg·m) (thesis {THESIS_COT:g}): shortening heat {c['shortening']:.2f}, "
               f"activation {c['activation']:.2f}, maintenance {c['maintenance']:.2f}, work {c['work']:.2f}, "
               f"basal {c['basal']:.3f}; with Bhargava's isometric force the same motion costs {cb['total']:.2f}.")
    out.append("Excitation–EMG correlation (Schwartz): "
               + ", ".join(f"{m} {v:+.2f}" for m, v in scores["r (Schwartz)"].dropna().items())
               + "; gaitutils: " + ", ".join(f"{m} {v:+.2f}" for m, v in scores["r (gaitutils)"].items()) + ".")
    e = angle_err["max error (deg)"]
    worst = e.idxmax()
    out.append(f"The MSK's largest angle error: {worst} {e[worst]:.0f} deg at "
               f"{angle_err.loc[worst, 'at (% cycle)']:.0f} % of the cycle (right heel strike at 0 %); errors per "
               "joint (max deg @ % cycle): "
               + ", ".join(f"{k} {v:.0f} @ {p:.0f}" for k, v, p in zip(angle_err.index, e, angle_err["at (% cycle)"]))
               + ".")
    ap = nmsk_sol.stats["activation_parameters"]
    out.append(f"GAM's weight in the ankle extensor (1 − s1 − s2) = {1 - ap['s1'] - ap['s2']:.2g}; mean node-to-node "
               f"|Δe| of our excitations {scores['mean |Δe| per node (ours)'].mean():.3f} vs "
               f"{scores['mean |Δ| per node (EMG)'].mean():.3f} for the EMG.")
    mt, obj = mtb_scale_table(nmsk_sol)["w·Mtb (approx.)"], nmsk_sol.stats["objective"]
    out.append(f"The Mtb term is {100 * mt.iloc[0] / obj:.1f} % of the NMSK objective with d read as the stride; "
               f"read as the 50 ms delay it would be {mt.iloc[1] / obj:.0f}× the whole objective.")
    return out
