"""Chapter "Where the model misses reality": the studies behind the gap diagnosis.

Functions
---------
:func:`effect_table`        the effect library (:data:`gaitlib.gap.EFFECTS`) as a table.
:func:`twin_validation`     the diagnosis on twins (every SK effect × three magnitudes ×
                            seeds) with the coarse SK baseline of :data:`TWIN_BASE`.
:func:`sk_diagnosis`        the diagnosis of a real data set with the SK baseline.
:func:`nmsk_attribution`    the muscle-level candidates (co-contraction, joint stiffness,
                            activation timing) re-solved from the Ch 5 NMSK solution.
:func:`emg_gap_table`       the EMG part of the gap (TA, medial gastrocnemius …) before and
                            after each muscle-level candidate.
:func:`exact_left_leg`      a data set whose generated left leg is the right leg shifted
                            exactly instead of through the Fourier fit.
:func:`left_leg_check`      how much of a located gap is the left leg's generation from the
                            right (the thesis's 5th-order Fourier fit, Eqs 4.1–4.3) rather
                            than the model.
:func:`book_gaps`           the located gap of the book's own Ch 5–7 solutions.
:func:`twin_validation_full_mesh`  the twin check on the 20 × 5 mesh (middle magnitude).
:func:`twin_full_mesh_lines`, :func:`twin_full_mesh_verdict`  that check in words.
:func:`co_contraction_text` the thesis's co-contraction suspicion tested on the NMSK solution.
:func:`findings`            the chapter's findings, every number and verdict from the results.

All solutions go through :mod:`gaitlib.gap.solve` (cached under ``<cache>/gap``); the
functions run serially (one process) unless ``serial=False`` is passed.
"""

from __future__ import annotations

import contextlib
import json
from dataclasses import replace

import numpy as np
import pandas as pd

from ..problems import gait as gait_ocp
from ..gap import diagnose
from .. import effects as effects_mod
from ..gap import io as gio
from ..gap import locate
from ..gap import twin
from ..gap import validate as gval
from ..gap import method as gap_method
from . import performance as perf
from .. import data as data_mod
from . import msk
from ..gap.solve import solve_many, solve_on
from ..marks import failure_label
from .. import validity
from . import predictive as pr

__all__ = ["TWIN_BASE", "TWIN_SEEDS", "SK_BASE", "MUSCLE_TWIN_BASE", "MUSCLE_TWIN_MAGNITUDES", "muscle_twin_validation", "muscle_twin_lines", "NMSK_CANDIDATES", "effect_table", "twin_validation",
           "sk_diagnosis", "nmsk_attribution", "ch5_attribution", "ch5_profile", "emg_gap_table", "exact_left_leg", "left_leg_check",
           "book_gaps", "twin_validation_full_mesh", "twin_full_mesh_lines", "twin_full_mesh_verdict",
           "left_leg_flips", "co_contraction_text", "findings",
           "validation_cases", "validation_lines", "visibility_text", "null_tables", "null_lines", "stored_null_refit", "null_refit_lines",
           "VALIDATION_RUNS", "stored_validation", "calibration_threshold", "replayed_threshold", "centred_replay",
           "centred_lines", "target_table", "TARGET_NAMED_PCT", "case_statistic", "case_share", "revision_table", "REVISION_CHANGES", "wilson", "TARGET_GROUPS",
           "replicate_table", "replicate_lines", "named_at", "rule_table", "threshold_sweep", "ranking_misses", "threshold_lines",
           "threshold_draw_lines", "common_mode_table", "common_mode_lines", "stored_baseline_pair", "baseline_pair_lines", "experiment_draws_table", "stored_candidate_baseline", "candidate_baseline_lines", "null_tail_table", "null_tail_lines", "stored_paired", "paired_lines", "PAIRED", "pair_counts", "case_change_lines",
           "stored_load_confusion", "load_confusion_lines", "LOAD_CONFUSION_FILE", "SUPERSEDED_VALIDATIONS", "superseded_validation", "effect_naming",
           "SHARE_FLOORS", "with_share_floor", "share_floor_sweep", "floor_held_lines", "share_floor_lines",
           "revision_lines", "stored_experiment", "normative_start_lines", "pair_test_lines",
           "relative_cases", "relative_lines", "relative_magnitudes", "calibration_lines", "consistency_lines", "tie_lines",
           "stored_reference_basin", "reference_basin_lines", "REFERENCE_BASIN_FILE", "stored_baseline_basin",
           "baseline_basin_lines", "BASELINE_BASIN_FILE"]

#: Baseline of the twin study: SK, data tracking (Eq 4.11), 10 × 3 LGR — the coarse mesh (the full 20 × 5 mesh costs ≈ 10× per solve and the twin study
#: needs ≈ 170 solves per seed).
TWIN_BASE = dict(model="SK", cost="DT", n_intervals=10, degree=3)
#: Baseline of the SK diagnoses of the real data sets: the thesis's full 20 × 5 LGR mesh.
SK_BASE = dict(model="SK", cost="DT", n_intervals=20, degree=5)
#: Noise seeds of the twin study.
TWIN_SEEDS = (1, 2)
#: Candidates tested on the NMSK baseline (the effects whose signature is muscle-level).
NMSK_CANDIDATES = ("co_contraction", "joint_stiffness", "activation_timing")


def effect_table() -> pd.DataFrame:
    """One row per effect: name, title, parameters (with units and bounds), models, where it
    shows, how it is identified, twin magnitudes."""
    rows = []
    for n, e in effects_mod.EFFECTS.items():
        rows.append({"effect": n, "title": e.title, "k (parameters)": e.n_params,
                     "parameters": ", ".join(f"{p.name} [{p.unit}] in [{p.lower:g}, {p.upper:g}]" for p in e.params),
                     "models": "/".join(e.models), "signature": e.signature,
                     "identified by": {"nlp": "NLP variable", "profile": "profile of the gap"}[e.identify]
                     + ("" if e.resolve else " (comparison only)"),
                     "twin magnitudes": ", ".join(f"{m:g}" for m in e.twin_magnitudes) if n in effects_mod.TWIN_EFFECTS else "—"})
    return pd.DataFrame(rows)


def twin_validation(seeds=TWIN_SEEDS, base: dict | None = None, serial: bool = True, **kw):
    """:func:`gaitlib.gap.twin.validate_twins` over every SK twin effect × its three
    magnitudes × ``seeds`` with the coarse SK baseline (:data:`TWIN_BASE`)."""
    return twin.validate_twins(seeds=tuple(seeds), base=dict(base or TWIN_BASE), serial=serial, progress=False, **kw)


#: Muscle-level twins (issue 25): the MSK baseline at the twins' coarse mesh, per-node derivatives.
MUSCLE_TWIN_BASE = dict(model="MSK", cost="DT", n_intervals=10, degree=3, derivatives="nodes")
#: The muscle-level effects (signature: EMG) and the magnitude of each twin — between the
#: points of the profile grids (:data:`gaitlib.gap.method.PROFILE_GRID`), so that a grid point
#: cannot hit the truth exactly; activation timing is fitted by a scalar search.
MUSCLE_TWIN_MAGNITUDES = {"co_contraction": (0.27,), "joint_stiffness": (1.5,), "activation_timing": (0.05,)}


def muscle_twin_validation(seeds=TWIN_SEEDS, serial: bool = False, **kw):
    """Twins of the MSK model with one muscle-level effect (co-contraction, joint stiffness,
    activation timing: :data:`MUSCLE_TWIN_MAGNITUDES`) and the effect-free twin per seed,
    each diagnosed with the MSK baseline (:data:`MUSCLE_TWIN_BASE`) against its EMG, the three
    muscle-level effects as candidates (:func:`gaitlib.gap.twin.validate_twins`)."""
    return twin.validate_twins(tuple(MUSCLE_TWIN_MAGNITUDES), magnitudes=MUSCLE_TWIN_MAGNITUDES, seeds=tuple(seeds),
                               base=dict(MUSCLE_TWIN_BASE), serial=serial, progress=False, **kw)


def muscle_twin_lines(tv) -> list[str]:
    """The muscle-level twins (:func:`muscle_twin_validation`) in sentences computed from the
    rows: named right per effect, the effect-free twins, the identified magnitudes, what the
    misnamed twins were called."""
    r = tv.rows
    inj = r[r["injected"] != "none"]
    free = r[r["injected"] == "none"]
    per = []
    for e, g in inj.groupby("injected", sort=False):
        mags = ", ".join(f"{m:.3g}" for m in g["identified_magnitude"] if np.isfinite(m))
        per.append(f"{e} ({g['magnitude'].iloc[0]:g}): {int(g['correct'].sum())} of {len(g)}"
                   + (f", identified {mags}" if mags else ""))
    n_ok = int(inj["correct"].sum())
    out = [f"**Muscle-level twins: {n_ok} of {len(inj)} named right ({100 * n_ok / max(len(inj), 1):.0f} %)** — "
           + "; ".join(per) + f". Effect-free twins read \"unexplained\": {int(free['correct'].sum())} of {len(free)}."]

    def why(w):
        if w.injected == "none":
            return f"{w.twin} (no effect) → {w.top} ({w.verdict}; ΔBIC {w.dBIC_top:.1f})"
        if np.isfinite(w.dBIC_top):
            return f"{w.twin} → {w.top} ({w.verdict}; ΔBIC named {w.dBIC_top:.1f}, injected {w.dBIC_true:.1f})"
        return f"{w.twin} → {w.top} (ΔBIC injected {w.dBIC_true:.1f})"

    wrong = r[~r["correct"]]
    if len(wrong):
        out.append("Misnamed: " + "; ".join(why(w) for w in wrong.itertuples()) + ".")
    if len(free) and "rss_gen" in free:
        ratio = free["rss_base"] / free["rss_gen"]
        fp = free[~free["correct"]]
        out.append(f"**The MSK baseline fit stops far above the noise.** On the effect-free twins, whose generating "
                   f"solution is a member of the baseline model, the kept baseline fit has an RSS of "
                   + ", ".join(f"{x:.0f}" for x in free["rss_base"]) + " against the generating solution's "
                   + ", ".join(f"{x:.0f}" for x in free["rss_gen"])
                   + f" ({ratio.min():.0f}–{ratio.max():.0f}×): a local optimum, not the model's limit"
                   + (". A candidate that does not nest the baseline (profiled on a grid without its null value) can "
                      "close part of that shortfall by landing in a better optimum: " + "; ".join(
                          f"on {w.twin}, {w.top} closed {100 * (1 - w.rss_top / w.rss_base):.0f} % with no effect "
                          "injected" for w in fp.itertuples()) if len(fp) else "") + ".")
    return out


def sk_diagnosis(source: str = "schwartz2008", speed_class: str = "Free", resamples: int = 200,
                 serial: bool = True, mesh: tuple | None = None, derivatives: str | None = None,
                 **kw) -> diagnose.Diagnosis:
    """The SK diagnosis (:func:`gaitlib.gap.diagnose`) of a committed data set. gaitutils has
    no GRFs: they are taken from Schwartz 2008 (same class) to make the problem complete and
    excluded from the gap (:func:`gaitlib.gap.io.load_real` ``fill_from``). ``mesh``:
    ``(intervals, degree)``, default :data:`SK_BASE`'s (the thesis's 20 × 5).
    ``derivatives``: the NLP derivative path of every solve (``GaitSpec.derivatives``;
    None: the default)."""
    fill = "schwartz2008" if source == "gaitutils" else None
    ds = gio.load_real(speed_class, source, fill_from=fill)
    base = dict(SK_BASE, speed_class=speed_class, source=source)
    if mesh is not None:
        base.update(n_intervals=int(mesh[0]), degree=int(mesh[1]))
    if derivatives is not None:
        base["derivatives"] = derivatives
    if not serial and ds.filled:
        raise ValueError("a filled data set is solved in this process only (serial=True): see own_data")
    with own_data(ds.gait if ds.filled else None):
        return diagnose.diagnose(ds, base=base, resamples=resamples, serial=serial, progress=False, **kw)


@contextlib.contextmanager
def own_data(gait):
    """While active, :func:`gaitlib.data.load_gait_data` returns ``gait`` for its own speed
    class and source (defaults of the other arguments only) — so that a gait problem of a
    source whose committed data lack quantities the problem needs (gaitutils: no GRFs) is
    built, solved and reloaded on the data set completed by ``fill_from``. In this process
    only (serial solves). ``gait=None``: no change.

    The solutions' cache keys hash the spec (source ``gaitutils``) and the completed data
    set's numbers; the committed gaitutils data alone cannot build a gait problem, so a key
    has only this one meaning."""
    if gait is None:
        yield
        return

    orig = data_mod.load_gait_data

    def patched(speed_class="Free", source="schwartz2008", *a, **k):
        if speed_class == gait.speed_class and source == gait.source and not a and not k:
            return gait
        return orig(speed_class, source, *a, **k)

    data_mod.load_gait_data = patched
    try:
        yield
    finally:
        data_mod.load_gait_data = orig


def nmsk_attribution(candidates=NMSK_CANDIDATES, resamples: int = 200, serial: bool = True,
                     root=None, reading: str = "thesis") -> diagnose.Diagnosis:
    """Muscle-level candidates on the Ch 5 NMSK solution (thesis Sec 5.3.5's question: does
    co-contraction close the TA/GAM gap?): :func:`ch5_attribution` of ``"NMSK"``."""
    return ch5_attribution("NMSK", candidates, resamples=resamples, serial=serial, root=root, reading=reading)


def ch5_attribution(model: str, candidates=None, resamples: int = 200, serial: bool = True,
                    root=None, reading: str = "thesis") -> diagnose.Diagnosis:
    """Candidate effects on the Ch 5 solution of ``model`` ("MSK" or "NMSK").

    Baseline: the Ch 5 data-tracking solution (:func:`gaitlib.studies.msk.solve`, Eq 5.33 /
    5.55 on the full 20 × 5 mesh) — not re-fitted. Candidates (``None``: every library effect
    that applies to the model, :func:`gaitlib.gap.diagnose.candidates`) are re-solved with the
    spec's own cost function (``objective="cost"``: the thesis's problem plus the effect),
    warm-started from it, on the same mesh; profiled effects on their grid
    (:data:`gaitlib.gap.diagnose.PROFILE_GRID`), activation timing on the comparison only.
    Ranked as :func:`gaitlib.gap.diagnose.assemble` does. ``reading``: the Ch 5 solution's
    (:data:`gaitlib.studies.gait.READINGS`)."""
    base_sol = msk.solve(model, root=root, reading=reading)
    spec0 = base_sol.spec
    ds = gio.load_real(spec0.speed_class, spec0.source)
    names, skipped = diagnose.candidates(spec0, ds.gait, candidates)
    fits = diagnose.candidate_fits(spec0, {"data": ds}, {"data": base_sol}, names, objective="cost", root=root,
                            serial=serial, progress=False)["data"]
    return diagnose.assemble(ds, spec0, base_sol, fits, objective="cost", resamples=resamples, skipped=skipped,
                      settings={"objective": "cost", "candidates": names,
                                "baseline": f"Ch 5 {model} solution, {reading}'s reading"})


def ch5_profile(model: str, effect: str, magnitudes, reading: str = "book", root=None,
                serial: bool = True) -> pd.DataFrame:
    """A profiled effect on the Ch 5 solution of ``model`` at ``magnitudes`` of our choosing
    — outside the frozen method's grid (:data:`gaitlib.gap.diagnose.PROFILE_GRID`), so it
    changes no verdict: each point is re-solved as :func:`ch5_attribution` re-solves it (the
    spec's own cost function plus the effect at that magnitude, warm-started from the Ch 5
    solution, same mesh) and its located gap measured. Rows: magnitude, status, RSS of the
    located gap, % of the baseline's RSS closed and the share of that closing that comes from
    the EMG channels; the baseline (magnitude = the effect's null value) first."""
    base_sol = msk.solve(model, root=root, reading=reading)
    spec0 = base_sol.spec
    ds = gio.load_real(spec0.speed_class, spec0.source)
    groups = {f"{effect}@{m}": (diagnose.with_effects(spec0, ((effect, m),)), [(f"data|{effect}@{m}", ds.gait, base_sol)])
              for m in magnitudes}
    res = solve_many(groups, root=root, objective="cost", serial=serial)
    loc0 = locate.locate(base_sol, ds)
    rss0, ch0 = loc0.rss, loc0.channels.set_index("channel")["rss"]
    null = effects_mod.EFFECTS[effect].params[0].null
    rows = [{"magnitude": null, "status": base_sol.stats["status"], "RSS": rss0, "% closed": 0.0,
             "EMG share of the closed gap (%)": np.nan}]
    for m in magnitudes:
        sol = res.get(f"data|{effect}@{m}")
        if sol is None:
            rows.append({"magnitude": m, "status": "error", "RSS": np.nan, "% closed": np.nan,
                         "EMG share of the closed gap (%)": np.nan})
            continue
        loc = locate.locate(sol, ds, thetas=sol.stats.get("effects", {}))
        drop = ch0 - loc.channels.set_index("channel")["rss"]
        emg = float(drop[drop.index.str.startswith("emg:")].sum())
        rows.append({"magnitude": m, "status": sol.stats["status"], "RSS": loc.rss,
                     "% closed": 100 * (rss0 - loc.rss) / rss0,
                     "EMG share of the closed gap (%)": 100 * emg / (rss0 - loc.rss) if rss0 != loc.rss else np.nan})
    return pd.DataFrame(rows)


def _emg_rss(loc: locate.Located, stems) -> dict:
    ch = loc.channels
    out = {}
    for s in stems:  # channel names of EMG are "<stem without emg_>_<side>", e.g. "TA_r"
        sel = ch[(ch["kind"] == "emg") & ch["name"].str.startswith(s[4:] + "_")]
        out[s] = float(sel["rss"].sum()) if len(sel) else np.nan
    return out


def emg_gap_table(diag: diagnose.Diagnosis, stems=("emg_TA", "emg_MG", "emg_RF", "emg_LH")) -> pd.DataFrame:
    """The EMG channels' RSS (both legs, SD-standardised, :mod:`gaitlib.gap.locate`) of the
    baseline and of each candidate's best fit, with the identified magnitude and status;
    ``mean_z`` of TA and MG tells the sign (model below/above the EMG)."""
    rows = []
    base = _emg_rss(diag.located, stems)

    def mean_z(loc, s):
        m = loc.points.groupby("channel")["z"].mean()
        v = [m[c] for c in m.index if c.startswith(f"emg:{s[4:]}_")]
        return float(np.mean(v)) if v else np.nan

    rows.append({"model": "baseline", "parameters": "", "status": diag.baseline.stats["status"],
                 **{f"RSS {s[4:]}": base[s] for s in stems},
                 "mean z TA": mean_z(diag.located, "emg_TA"), "mean z MG": mean_z(diag.located, "emg_MG")})
    for n, f in diag.fits.items():
        if f.located is None:
            rows.append({"model": n, "parameters": "", "status": f.status})
            continue
        r = _emg_rss(f.located, stems)
        th = f.thetas.get(n, {})
        rows.append({"model": n, "parameters": ", ".join(f"{k} = {v:.3g}" for k, v in th.items()), "status": f.status,
                     **{f"RSS {s[4:]}": r[s] for s in stems},
                     "mean z TA": mean_z(f.located, "emg_TA"), "mean z MG": mean_z(f.located, "emg_MG")})
    return pd.DataFrame(rows)


def top_cells(loc: locate.Located, n: int = 6) -> pd.DataFrame:
    """The ``n`` channel × phase cells with the largest RMS SD-standardised residual."""
    t = loc.table.sort_values("rms_z", ascending=False).head(n)
    return t[["channel", "phase", "rms_z", "mean_z", "frac_out", "p_min", "significant"]].reset_index(drop=True)


def ranking_table(diag: diagnose.Diagnosis) -> pd.DataFrame:
    """The ranking for printing: effect, k, identified values, where the kept fit started,
    whether the effect nests the baseline, status, % closed (with its 95 % resampling
    interval where computed), ΔAIC, ΔBIC. Unranked rows (no rank: failed search, a nested
    fit with a located gap above the baseline's) come last, without % closed."""
    r = diag.ranking.copy()
    r["identified"] = r["parameters"].map(lambda th: ", ".join(f"{k} = {v:.3g}" for k, v in (th or {}).items()))
    cols = ["rank", "effect", "n_params", "identified", "start", "nests_baseline", "status", "rss_after", "pct_closed"]
    cols += [c for c in ("pct_closed_lo", "pct_closed_hi") if c in r.columns] + ["dAIC", "dBIC"]
    return r[cols]


def summary(diag: diagnose.Diagnosis) -> dict:
    """Numbers for the text: baseline RSS, n_eff, significant cells, top effect, verdict, its
    % closed and interval."""
    s = {"label": diag.data.label, "rss": diag.located.rss, "n_eff": diag.located.n_eff,
         "rms_z": diag.located.rms_z, "significant_cells": int(diag.located.table["significant"].sum()),
         "cells": int(len(diag.located.table)), "top": diag.top_effect, "verdict": diag.verdict,
         "best": None, "best_pct": np.nan, "best_dBIC": np.nan, "interval": [np.nan, np.nan],
         "baseline_status": diag.baseline.stats.get("status")}
    ok = diag.ranking[diag.ranking["ok"] & np.isfinite(diag.ranking["dBIC"])]
    if len(ok):
        b = ok.iloc[0]
        s.update(best=str(b["effect"]), best_pct=float(b["pct_closed"]), best_dBIC=float(b["dBIC"]),
                 interval=list(diag.intervals.get(str(b["effect"]), [np.nan, np.nan])))
        if len(ok) > 1:
            s.update(second=str(ok.iloc[1]["effect"]), second_dBIC=float(ok.iloc[1]["dBIC"]))
    s["contenders"] = list(diag.settings.get("contenders", []))
    s["held_by_share_floor"] = diag.settings.get("held_by_share_floor")
    s["min_share_closed"] = diag.settings.get("min_share_closed", 0.0)
    s["centred"] = bool(diag.settings.get("centred", False))
    s["share_closed"] = diag.settings.get("share_closed")
    return s


def circularity(tv_full, diag) -> str:
    """What the twin check cannot show, measured: the twins are made by the same model and
    effect code the diagnosis searches, and their misfit is far smaller than the real data's
    (``tv_full``: :func:`twin_validation_full_mesh`; ``diag``: the real-data diagnosis on
    the same mesh). Compares the baseline fit's RSS on the twins (median, range) with the
    real data's."""
    r = tv_full.rows
    rss = r["rss_base"].astype(float).dropna()
    real = float(diag.located.rss)
    return (f"**What the twin check cannot show.** Every twin is generated by the same model and effect code "
            f"that the diagnosis then searches, so the right answer is always in the library; and the twins' "
            f"misfit is small: the baseline fit leaves a median RSS of {rss.median():.1f} on the {len(rss)} "
            f"twins of the 20 × 5 check (range {rss.min():.1f}–{rss.max():.1f}) against {real:.1f} on the real Schwartz "
            f"data, {real / rss.median():.0f}× more. The accuracy above is therefore an upper bound for real "
            "data. Effects injected by manipulating the real data (no gaitlib code) and manipulations outside "
            "the library are tested in Section 3b; data from another model variant and muscle-level twins are "
            "not yet tested in this chapter.")


#: Where the validation's results are stored (under the benchmark results folder,
#: :func:`gaitlib.studies.performance.results_dir`), and the commands that wrote them.
VALIDATION_RUNS = {
    "real": "gaitlib gap-validate --set independent,out-of-library --derivatives nodes --out "
            "benchmarks/results/gap_validation/real",
    "variants": "gaitlib gap-validate --set model-variant --derivatives nodes --out "
                "benchmarks/results/gap_validation/variants",
    "null": "gaitlib gap-validate --set null --derivatives nodes --out benchmarks/results/gap_validation/null",
    "relative": "gaitlib gap-validate --relative --set independent,out-of-library,null --per-band 2 --derivatives nodes "
                "--out benchmarks/results/gap_validation/relative",
    "relative_r1": "gaitlib gap-validate --relative --set independent,out-of-library,null --per-band 2 --replicate 1 "
                   "--derivatives nodes --out benchmarks/results/gap_validation/relative_r1",
}


def stored_validation(name: str = "real") -> gval.Validation:
    """The stored result of one validation run (:data:`VALIDATION_RUNS`), refused if it was
    made with another method than :data:`gaitlib.gap.method.METHOD` (its draws and verdicts
    would not be this method's)."""
    folder = perf.results_dir() / "gap_validation" / name
    v = gval.Validation.load(folder)
    now = gap_method.METHOD.hash()
    if v.settings.get("method_hash") != now:
        raise RuntimeError(f"{folder}: a validation of method {v.settings.get('method_hash')}, the method is now "
                           f"{now}: rerun `{VALIDATION_RUNS[name]}`")
    if v.settings.get("relative") and v.settings.get("relative_method_hash") != gap_method.RELATIVE.hash():
        raise RuntimeError(f"{folder}: a relative validation of relative method "
                           f"{v.settings.get('relative_method_hash')}, it is now {gap_method.RELATIVE.hash()}: rerun "
                           f"`{VALIDATION_RUNS[name]}`")
    return v


#: A validation made by an earlier method, kept as the "before" of a method change:
#: folder under ``gap_validation`` → the method revision that made it.
SUPERSEDED_VALIDATIONS = {"real_rev1": 1, "relative_rev0": 0, "relative_rev1": 1, "relative_rev2": 2,
                          "relative_rev3": 3, "relative_rev4": 4, "relative_rev4_r1": 4, "relative_rev5": 5,
                          "relative_rev6": 6, "relative_rev6_r1": 6, "relative_rev7": 7, "relative_rev8": 8,
                          "relative_rev8_r1": 8, "relative_rev9": 9, "relative_rev9_r1": 9}


def superseded_validation(name: str = "real_rev1") -> gval.Validation:
    """A stored validation of an earlier method (:data:`SUPERSEDED_VALIDATIONS`), loaded
    without the hash check — for the side-by-side of a method change only, never as a result
    of the current method."""
    if name not in SUPERSEDED_VALIDATIONS:
        raise ValueError(f"unknown superseded validation {name!r}; known: {', '.join(SUPERSEDED_VALIDATIONS)}")
    return gval.Validation.load(perf.results_dir() / "gap_validation" / name)


def effect_naming(v: gval.Validation, effect: str) -> dict:
    """How often ``effect`` was named and ranked first in ``v`` (every case), and in how many
    cases it was the expected answer: ``{"cases", "named", "named_right", "ranked_first",
    "expected", "unedited_named", "unedited_rank1"}``."""
    r = v.rows
    exp = r["expected"].astype(str).str.split("|").apply(lambda x: effect in x)
    return {"cases": len(r), "named": int((r["named"] == effect).sum()),
            "named_right": int(((r["named"] == effect) & exp).sum()), "ranked_first": int((r["rank1"] == effect).sum()),
            "expected": int(exp.sum()), "unedited_named": v.unedited.get("named"),
            "unedited_rank1": v.unedited.get("rank1")}


def revision_lines(old: gval.Validation, new: gval.Validation, effect: str = "grf_scale") -> list[str]:
    """The validation before and after a method change, for the effect the change concerns:
    each revision's counts (:func:`effect_naming`) and unedited verdict, every number from
    the two results. The two draw different magnitudes (the draws follow the method's
    hash), so the comparison is of rates, not of paired cases."""
    out = []
    for label, v in (("before", old), ("after", new)):
        c = effect_naming(v, effect)
        out.append(f"{label} (method {v.settings.get('method_hash')}, revision "
                   f"{v.settings.get('method', {}).get('revision', 1)}): `{effect}` named in {c['named']} of "
                   f"{c['cases']} cases ({c['named_right']} of them right; it was the expected answer in "
                   f"{c['expected']}), ranked first in {c['ranked_first']}; the unedited data: {c['unedited_named']}, "
                   f"ranked first {c['unedited_rank1']}.")
    return out


def validation_cases(v: gval.Validation) -> pd.DataFrame:
    """The validation's cases for printing: manipulation, band, magnitude (its unit), the
    expected answer, the named effect and verdict, the top two ranked candidates."""
    r = v.rows.copy()
    r["magnitude"] = [f"seed {int(m)}" if u == "seed" else f"{m:+.3g} {u}" for m, u in zip(r["magnitude"], r["unit"])]
    r["right"] = np.where(r["correct"], "yes", "no")
    r["ranked first (ΔBIC, % closed)"] = [f"{a} ({b:.1f}, {c:.1f})" if isinstance(a, str) else "—"
                                          for a, b, c in zip(r["rank1"], r["rank1_dBIC"], r["rank1_pct"])]
    r["second"] = [f"{a} ({b:.1f}, {c:.1f})" if isinstance(a, str) else "—"
                   for a, b, c in zip(r["rank2"], r["rank2_dBIC"], r["rank2_pct"])]
    return r[["set", "injection", "band", "magnitude", "expected", "named", "verdict", "right",
              "ranked first (ΔBIC, % closed)", "second"]]


def _small_line(small: pd.DataFrame) -> str:
    return (f"Small magnitudes: {int(small['correct'].sum())} of {len(small)} named right "
            f"({int((small['named'] == 'unexplained').sum())} unexplained).")


def _ool_line(ool: pd.DataFrame, target: float) -> str:
    un = 100.0 * (ool["named"] == "unexplained").mean()
    named = ool[ool["named"] != "unexplained"]
    return (f"**Out-of-library manipulations: {int((ool['named'] == 'unexplained').sum())} of {len(ool)} "
            f"read \"unexplained\" ({un:.0f} %; target ≥ {target:g} %).**"
            + (" A library effect was named for: " + "; ".join(
                f"{a} {b} ({n}, {vd})" for a, b, n, vd in zip(named["injection"], named["band"], named["named"],
                                                               named["verdict"])) + "." if len(named) else ""))


def validation_lines(v: gval.Validation, target: float = 90.0) -> list[str]:
    """The validation in words, every number from ``v``: top-1 at middle magnitudes and
    above (independent set), the "unexplained" rate (out-of-library set), against the
    targets; the unedited data's own verdict."""
    r = v.rows
    ind = r[(r["set"] == "independent") & r["band"].isin(["middle", "large"])]
    ool = r[r["set"] == "out-of-library"]
    small = r[(r["set"] == "independent") & (r["band"] == "small")]
    u = v.unedited
    out = []
    if len(ind):
        top1 = 100.0 * ind["correct"].mean()
        wrong = ind[~ind["correct"]]
        out.append(f"**Independent injections, middle and large magnitudes: {int(ind['correct'].sum())} of {len(ind)} "
                   f"named right ({top1:.0f} %; target ≥ {target:g} %).**"
                   + (" Misnamed: " + "; ".join(f"{a} {b} ({m:+.3g} {un}) named {n}" for a, b, m, un, n in
                                              zip(wrong["injection"], wrong["band"], wrong["magnitude"], wrong["unit"],
                                                  wrong["named"])) + "." if len(wrong) else ""))
    if len(small):
        out.append(_small_line(small))
    if len(ool):
        out.append(_ool_line(ool, target))
    var = r[r["set"] == "model-variant"]
    if len(var):
        out.append(f"**Model-variant twins: {int(var['correct'].sum())} of {len(var)} named within the stated family "
                   f"({100.0 * var['correct'].mean():.0f} %).** " + "; ".join(
                       f"{a} (seed {int(m)}): {n} ({vd}; expected one of {e.replace('|', ', ')})"
                       for a, m, n, vd, e in zip(var["injection"], var["magnitude"], var["named"], var["verdict"],
                                                 var["expected"])) + ".")
    out.append(f"The unedited data, diagnosed the same way: {u['named']} ({u['verdict']}); ranked first "
               f"{u.get('rank1')} at ΔBIC {u.get('rank1_dBIC', float('nan')):.1f}, second {u.get('rank2')} at "
               f"{u.get('rank2_dBIC', float('nan')):.1f}. Every injection sits on top of this gap of the real data.")
    return out


def _same_draws(rel: gval.Validation, absolute: gval.Validation) -> pd.Series:
    """case → the absolute diagnosis's named effect, for the cases drawn at the same
    magnitude in both runs (a relative method of its own draws other magnitudes)."""
    a = absolute.rows.set_index("case")
    m = rel.rows.set_index("case")["magnitude"]
    same = [c for c in m.index if c in a.index and np.isclose(float(a.loc[c, "magnitude"]), float(m[c]))]
    return a.loc[same, "named"]


def relative_cases(rel: gval.Validation, absolute: gval.Validation) -> pd.DataFrame:
    """The relative validation's cases beside the absolute one's where they share the draw
    (same case at the same magnitude; else "—"): manipulation, band, magnitude, expected, named (absolute), named and verdict
    (relative), right (relative), the relative run's first two ranked with ΔBIC and % closed,
    and the change's RSS as % of the reference's own gap (``added_pct``)."""
    r = validation_cases(rel).assign(case=rel.rows["case"].to_numpy(), added_pct=rel.rows["added_pct"].to_numpy())
    a = _same_draws(rel, absolute)
    r.insert(5, "named (absolute)", [str(a[c]) if c in a.index else "—" for c in r["case"]])
    return r.drop(columns=["case"]).rename(columns={"named": "named (relative)", "verdict": "verdict (relative)",
                                                    "right": "right (relative)",
                                                    "added_pct": "change RSS (% of the reference's gap)"})


def relative_magnitudes(rel: gval.Validation, gait=None) -> pd.DataFrame:
    """Per independent case of a relative validation: the change that undoes the manipulation
    in the expected effect's parameter (:func:`gaitlib.gap.validate.effect_magnitude`, on
    the unedited data), the change the expected effect's fit identified between the
    reference and the data (``expected_change``, whether or not it was named), and their
    ratio."""
    gait = gait if gait is not None else gio.load_real(rel.settings.get("speed_class", "Free")).gait
    rows = []
    for _, r in rel.rows[rel.rows["set"] == "independent"].iterrows():
        p, v = gval.effect_magnitude(r["injection"], r["magnitude"], gait)
        ch = r.get("expected_change")
        got = float(ch[p]) if isinstance(ch, dict) and p in ch else np.nan
        rows.append({"injection": r["injection"], "band": r["band"], "effect": r["expected"], "parameter": p,
                     "injected": v, "identified change": got, "ratio": got / v if v else np.nan,
                     "named": r["named"]})
    return pd.DataFrame(rows)


def relative_lines(rel: gval.Validation, absolute: gval.Validation, target: float = 90.0) -> list[str]:
    """The relative validation in words beside the absolute one, every number from the two
    runs: top-1 on independent injections at middle and large magnitudes, small ones, the
    out-of-library "unexplained" rate, and the null draws (nothing changed: the right answer
    is "unexplained")."""
    if not rel.settings.get("relative"):
        raise ValueError("relative_lines: the first validation is not a relative one (gap-validate --relative)")
    r, a = rel.rows, absolute.rows.set_index("case")

    def sel(x, band=None, s="independent"):
        m = x["set"] == s
        return x[m & x["band"].isin(band)] if band else x[m]

    out = []
    ind = sel(r, ["middle", "large"])
    if len(ind):
        wrong = ind[~ind["correct"].astype(bool)]
        paired = _same_draws(rel, absolute).index.intersection(ind["case"])
        a_right = int(a.loc[paired, "correct"].astype(bool).sum())
        out.append(f"**Relative to the unedited data: independent injections at middle and large magnitudes "
                   f"{int(ind['correct'].sum())} of {len(ind)} named right ({100.0 * ind['correct'].mean():.0f} %; "
                   f"target ≥ {target:g} %)**"
                   + (f" — the absolute diagnosis of the same manipulations: {a_right} of {len(paired)}."
                      if len(paired) == len(ind) else
                      f" (other draws than the absolute validation's: the relative method draws from its own hash; "
                      f"the absolute diagnosis named {int(sel(a.reset_index(), ['middle', 'large'])['correct'].sum())} "
                      f"of {len(sel(a.reset_index(), ['middle', 'large']))} of its own).")
                   + (" Misnamed: " + "; ".join(f"{x} {b} ({m:+.3g} {u}) named {n}" for x, b, m, u, n in
                                              zip(wrong["injection"], wrong["band"], wrong["magnitude"], wrong["unit"],
                                                  wrong["named"])) + "." if len(wrong) else "")
                   + _against_expected(wrong))
    small = sel(r, ["small"])
    if len(small):
        out.append(_small_line(small))
    if "expected_change" in r.columns and len(ind):
        mg = relative_magnitudes(rel)
        mm = mg[mg["band"].isin(["middle", "large"])]["ratio"].dropna()
        if len(mm):
            out.append(f"The expected effect's fit recovers the injected change — named or not: identified / "
                       f"injected {mm.min():.2f} to {mm.max():.2f} (median {mm.median():.2f}) over the "
                       f"{len(mm)} middle and large injections.")
    ool = sel(r, s="out-of-library")
    if len(ool):
        out.append(_ool_line(ool, target))
    nul = sel(r, s="null")
    if len(nul):
        fp = nul[nul["named"] != "unexplained"]
        best = nul.loc[nul["rank1_dBIC"].astype(float).idxmin()]
        out.append(f"Nothing changed (the unedited data resampled against the resampled reference): "
                   f"{len(nul) - len(fp)} of {len(nul)} read \"unexplained\""
                   + (" — named: " + ", ".join(f"{n} ({vd})" for n, vd in zip(fp["named"], fp["verdict"])) + "."
                      if len(fp) else ".")
                   + (f" Yet the first-ranked candidate of these draws reached ΔBIC {nul['rank1_dBIC'].max():.0f} to "
                      f"{best['rank1_dBIC']:.0f} ({best['rank1']}, closing {best['rank1_pct']:.0f} % of a gap that is "
                      f"sampling error only), beyond the threshold ({diagnose.BIC_THRESHOLD:g}): on this clean "
                      f"background a free parameter absorbs a share of the noise that the criterion's effective "
                      f"sample size (the resels of the baseline's residual, {nul['n_eff'].min():.0f}–"
                      f"{nul['n_eff'].max():.0f}) counts as very strong evidence"
                      if best["rank1_dBIC"] <= diagnose.BIC_THRESHOLD else
                      f" The first-ranked candidate of these draws reached ΔBIC {nul['rank1_dBIC'].max():.0f} to "
                      f"{best['rank1_dBIC']:.0f} ({best['rank1']}, closing {best['rank1_pct']:.0f} %): within the "
                      f"threshold ({diagnose.BIC_THRESHOLD:g}) even without a calibration")
                   + (f"; the null calibration's threshold ({float(nul['threshold_used'].iloc[0]):.0f}) "
                      + (f"did not hold {len(fp)} of them" + _change_clause(fp) + "." if len(fp) else "held them.")
                      if "threshold_used" in nul.columns and nul["threshold_used"].notna().all() else
                      f"; what keeps these draws unexplained is the runner-up margin ({diagnose.RUNNER_UP_MARGIN:g}): "
                      "several candidates absorb noise alike."))
    return out


def _against_expected(wrong: pd.DataFrame) -> str:
    """For misnamed cases: the first-ranked candidate's ΔBIC and % closed against the
    expected effect's (from the stored rows)."""
    if wrong.empty or "expected_dBIC" not in wrong.columns:
        return ""
    bits = []
    for _, r in wrong.iterrows():
        if not (isinstance(r["rank1"], str) and np.isfinite(float(r["expected_dBIC"]))):
            continue
        if r["rank1"] == r["expected"]:  # first, but not named: the runner-up or the threshold
            bits.append(f"{r['injection']} {r['band']}: {r['expected']} first at {r['expected_dBIC']:.0f} "
                        f"({r['expected_pct']:.0f} %), {r.get('rank2')} at {float(r.get('rank2_dBIC', np.nan)):.0f} "
                        f"({float(r.get('rank2_pct', np.nan)):.0f} %)")
        else:
            bits.append(f"{r['injection']} {r['band']}: {r['rank1']} {r['rank1_dBIC']:.0f} ({r['rank1_pct']:.0f} %) vs "
                        f"{r['expected']} {r['expected_dBIC']:.0f} ({r['expected_pct']:.0f} %)")
    return (" First-ranked against the expected effect (ΔBIC, % closed): " + "; ".join(bits) + ".") if bits else ""


def _change_text(effect: str, change: dict) -> str:
    """A candidate's identified change in words: each parameter with its unit (rad also in °)."""
    e = effects_mod.EFFECTS[effect]
    parts = []
    for p in e.params:
        if p.name in change:
            v = float(change[p.name])
            parts.append(f"{p.name} {v:+.3g} {p.unit}" + (f" ({np.degrees(v):+.2f}°)" if p.unit == "rad" else ""))
    return ", ".join(parts)


def _change_clause(named: pd.DataFrame) -> str:
    """', although <effect>'s identified change was only …' for null draws named an effect
    (relative validations that store ``rank1_change``)."""
    if "rank1_change" not in named.columns:
        return ""
    bits = [f"{r['named']} {_change_text(r['named'], r['rank1_change'])}" for _, r in named.iterrows()
            if isinstance(r["rank1_change"], dict) and r["rank1"] == r["named"]]
    return (" — with a parameter change of only " + "; ".join(bits) + " between the reference and the draw: its fit "
            "of the draw absorbs the sampling error differently from the baseline's, not a change") if bits else ""


def calibration_threshold(rel: gval.Validation) -> float | None:
    """The ΔBIC a relative validation's null calibration set (the fixed threshold or the
    calibration's, :func:`gaitlib.gap.diagnose.calibration_dBIC`, whichever is lower); None
    without one."""
    c = (rel.unedited or {}).get("null_calibration")
    if not c:
        return None
    lo = diagnose.calibration_dBIC(c)
    return diagnose.BIC_THRESHOLD if lo is None else min(diagnose.BIC_THRESHOLD, lo)


def wilson(k: int, n: int, z: float = 1.959964) -> tuple[float, float]:
    """Wilson's score interval of a proportion k/n (95 % for the default z), in %."""
    if n <= 0:
        return (float("nan"), float("nan"))
    p = k / n
    d = 1.0 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (100.0 * max(0.0, c - h), 100.0 * min(1.0, c + h))


#: The groups the validation's targets are stated on: label → (set, bands or None for all).
TARGET_GROUPS = {"independent, middle + large": ("independent", ("middle", "large")),
                 "independent, small": ("independent", ("small",)),
                 "out-of-library": ("out-of-library", None),
                 "null (nothing changed)": ("null", None)}


def replicate_table(reps: dict) -> pd.DataFrame:
    """Named right per target group (:data:`TARGET_GROUPS`) in each replicate of a validation
    (label → :class:`~gaitlib.gap.validate.Validation`, the same method on other draws) and
    pooled over them, with Wilson's 95 % interval of the pooled rate; the threshold each
    replicate's null calibration set is the last row."""
    rows, counts = [], {lab: _group_counts(v.rows) for lab, v in reps.items()}
    for g in TARGET_GROUPS:
        row, k_all, n_all = {"group": g}, 0, 0
        for lab in reps:
            k, n = counts[lab][g]
            row[lab] = f"{k}/{n}" if n else "—"
            k_all, n_all = k_all + k, n_all + n
        lo, hi = wilson(k_all, n_all)
        row.update({"pooled": f"{k_all}/{n_all}" if n_all else "—",
                    "pooled %": 100.0 * k_all / n_all if n_all else np.nan, "95 % interval": (
                        f"{lo:.0f}–{hi:.0f} %" if n_all else "—")})
        rows.append(row)
    thr = {lab: calibration_threshold(v) for lab, v in reps.items()}
    rows.append({"group": "threshold (ΔBIC ≤)", **{lab: (f"{t:.0f}" if t is not None else "—") for lab, t in thr.items()},
                 "pooled": "", "pooled %": np.nan, "95 % interval": ""})
    return pd.DataFrame(rows).set_index("group")


#: Issue 25's targets for the validated relative method, in %: named right among independent
#: injections of middle and large magnitude, and "unexplained" among out-of-library manipulations.
TARGET_NAMED_PCT = 90.0


def target_table(tv, tv_full, reps: dict, mesh_tab: pd.DataFrame) -> pd.DataFrame:
    """The diagnosis's targets side by side with what was measured, every number from the
    results: the in-model twins on 10 × 3 (``tv``) and 20 × 5 (``tv_full``,
    :class:`gaitlib.gap.twin.TwinValidation`) against :data:`gaitlib.gap.twin.TARGET_TOP1_PCT`
    (top-1 at the middle magnitude) and :data:`~gaitlib.gap.twin.TARGET_SHRINK_PCT` (mean
    shrink), with the effect-free twins' answers beside; the relative method's independent
    injections (middle + large) and out-of-library manipulations pooled over its replicates
    ``reps`` (label → validation, :func:`replicate_table`, with Wilson's 95 % interval)
    against :data:`TARGET_NAMED_PCT`; and whether the real data's verdict is the same on the
    meshes of ``mesh_tab`` (:func:`mesh_table`). ``met`` is "yes"/"no" on the stated number."""
    yes = {True: "yes", False: "no"}
    rows = []
    for lab, t in (("10 × 3", tv), ("20 × 5", tv_full)):
        s = t.summary()
        rows.append({"target": f"in-model twins ({lab}): top-1 at the middle magnitude",
                     "required": f"≥ {twin.TARGET_TOP1_PCT:g} %", "measured": f"{s['top1_pct']:.0f} %",
                     "met": yes[bool(s["top1_met"])]})
        rows.append({"target": f"in-model twins ({lab}): mean shrink of the injected gap",
                     "required": f"≥ {twin.TARGET_SHRINK_PCT:g} %", "measured": f"{s['shrink_pct']:.0f} %",
                     "met": yes[bool(s["shrink_met"])]})
        rows.append({"target": f"in-model twins ({lab}): effect-free twins \"unexplained\"",
                     "required": "all", "measured": f"{s['free_unexplained']} of {s['free_twins']}",
                     "met": yes[s["free_unexplained"] == s["free_twins"]]})
    tab = replicate_table(reps)
    sets = f"pooled over {len(reps)} sets of draws" if len(reps) > 1 else "one set of draws"
    for g, what in (("independent, middle + large", "independent injections, middle + large: named right"),
                    ("out-of-library", "out-of-library manipulations: \"unexplained\" (or the stated family)")):
        r = tab.loc[g]
        ok = bool(r["pooled %"] >= TARGET_NAMED_PCT) if r["pooled"] not in ("—", "") else False
        rows.append({"target": f"{what} (relative method, {sets})",
                     "required": f"≥ {TARGET_NAMED_PCT:g} %",
                     "measured": f"{r['pooled']} = {r['pooled %']:.0f} % (95 % interval {r['95 % interval']})",
                     "met": yes[ok]})
    verdicts = [v + (f" ({t})" if t not in ("—", v) else "") for v, t in zip(mesh_tab["verdict"], mesh_tab["top effect"])]
    same = len(set(verdicts)) == 1
    rows.append({"target": "real data: the same verdict at " + " and ".join(map(str, mesh_tab.index)),
                 "required": "same, or the dependence explained",
                 "measured": f"{verdicts[0]} at both" if same and len(verdicts) == 2 else "; ".join(verdicts),
                 "met": yes[same]})
    return pd.DataFrame(rows).set_index("target")


#: What each relative method revision changed, in a few words (Chapter 8's revision table;
#: :class:`gaitlib.gap.method.RelativeMethod` says why and what it measured).
REVISION_CHANGES = {0: "relative to the reference, uncalibrated", 1: "null calibration (lowest of 9 draws)",
                    2: "self-consistent reference fit", 3: "the HAT's tilt located",
                    4: "baseline also from the candidates' fits", 5: "threshold: second lowest of 19 draws",
                    6: "quiet points left out", 7: "reference's baseline fit from the candidates'",
                    8: "fallback baseline; lower of two located pairs", 9: "share floor: closes ≥ 20 %",
                    10: "statistic relative to the median candidate"}


def revision_table(vals: dict) -> pd.DataFrame:
    """Every stored relative validation at a glance (label → (revision, validation)): the
    revision and its change (:data:`REVISION_CHANGES`), the set of draws (its replicate), the
    statistic it decided on, the threshold its null calibration set, how many of its null draws were common-mode (the
    median candidate's ΔBIC ≤ −20, :func:`common_mode_table`), and named right per target
    group as the validation decided."""
    rows = []
    for lab, (rev, v) in vals.items():
        t = calibration_threshold(v)
        d = _draw_modes(v, -20.0)
        rows.append({"validation": lab, "revision": rev, "change": REVISION_CHANGES.get(rev, ""),
                     "draws": int((v.settings or {}).get("replicate") or 0),
                     "statistic": "ΔBIC − median candidate's" if _centred(v) else "ΔBIC",
                     "threshold (ΔBIC ≤)": f"{t:.0f}" if t is not None else f"{diagnose.BIC_THRESHOLD:.0f} (fixed)",
                     "common-mode null draws": f"{sum(x[1] for x in d)}/{len(d)}" if d else "—",
                     **{g: (f"{k}/{n}" if n else "—") for g, (k, n) in _group_counts(v.rows).items()}})
    return pd.DataFrame(rows).set_index("validation")


def _stored_floor(v: gval.Validation) -> float:
    """The share floor (%) of the relative method that made ``v`` (``min_share_closed``,
    revision 9 on); 0 for a validation made without one."""
    return float(((v.settings or {}).get("relative_method") or {}).get("min_share_closed", 0.0))


def _centred(v: gval.Validation) -> bool:
    """Whether the relative method that made ``v`` decided on the centred statistic
    (:attr:`gaitlib.gap.method.RelativeMethod.centred`, revision 10 on)."""
    return bool(((v.settings or {}).get("relative_method") or {}).get("centred", False))


def _ranked(x) -> dict:
    """A stored case's ranked candidates' ΔBIC (``{effect: ΔBIC}``; {} if none was ranked)."""
    return {str(k): float(b) for k, b in x.items()} if isinstance(x, dict) else {}


def case_statistic(v: gval.Validation, centred: bool | None = None) -> pd.Series:
    """Per case of a relative validation, the statistic its first-ranked effect is held to the
    threshold with (:func:`gaitlib.gap.method.draw_statistic` of the stored ranking): its
    ΔBIC, or with ``centred`` its ΔBIC minus the median ranked candidate's (None: as the
    validation's own method decided). Without a stored ranking, the raw statistic is the
    stored ``rank1_dBIC`` and the centred one NaN."""
    c = _centred(v) if centred is None else centred
    r = v.rows
    raw = pd.to_numeric(r["rank1_dBIC"], errors="coerce")
    per = r["dBIC"] if "dBIC" in r else pd.Series([None] * len(r), index=r.index)
    return pd.Series([gap_method.draw_statistic(_ranked(x), c) if _ranked(x) else (np.nan if c else b)
                      for x, b in zip(per, raw)], index=r.index, dtype=float)


def case_share(v: gval.Validation, centred: bool | None = None) -> pd.Series:
    """Per case of a relative validation, the share (%) of the gap its first-ranked effect
    closes that the share floor is held to (:func:`gaitlib.gap.method.share_beyond_median`):
    the stored ``rank1_pct``, or with ``centred`` the share of what the median ranked
    candidate leaves open (None: as the validation's own method decided). NaN without a
    stored ranking where centred."""
    c = _centred(v) if centred is None else centred
    r = v.rows
    raw = pd.to_numeric(r["rank1_pct"], errors="coerce")
    if not c:
        return raw
    per = r["pct_closed"] if "pct_closed" in r else pd.Series([None] * len(r), index=r.index)
    return pd.Series([gap_method.share_beyond_median(p, _ranked(x).values()) if _ranked(x) and np.isfinite(p)
                      else np.nan for x, p in zip(per, raw)], index=r.index, dtype=float)


def _lone(v: gval.Validation) -> pd.Series:
    """Per case, whether no runner-up is within :data:`gaitlib.gap.method.RUNNER_UP_MARGIN` of
    the first-ranked effect — recomputed from the stored ranking (the stored ``contenders``
    are empty where nothing passed the case's own threshold, so they do not hold at another);
    without a stored ranking, from the stored ``contenders``."""
    def one(x, c):
        d = _ranked(x)
        if not d:
            return len(c) <= 1 if isinstance(c, (list, tuple)) else True
        return len(diagnose.contenders_of(pd.DataFrame({"effect": list(d), "dBIC": list(d.values()),
                                                        "ok": True}))) <= 1
    r = v.rows
    per = r["dBIC"] if "dBIC" in r else [None] * len(r)
    cont = r["contenders"] if "contenders" in r else [None] * len(r)
    return pd.Series([one(x, c) for x, c in zip(per, cont)], index=r.index, dtype=bool)


def named_at(v: gval.Validation, threshold: float, centred: bool | None = None,
             floor: float | None = None) -> pd.DataFrame:
    """The cases of a relative validation decided again at another threshold: a case names
    its first-ranked effect if its statistic (:func:`case_statistic`: its ΔBIC, or with
    ``centred`` its ΔBIC minus the median candidate's; None: the validation's own) is at or
    below ``threshold`` and its ΔBIC at or below the fixed :data:`gaitlib.gap.method.
    BIC_THRESHOLD`, no runner-up is within the margin (:func:`_lone`) and it closes at least
    ``floor`` % (:func:`case_share`, centred alike) of the gap (None: the validation's own
    ``min_share_closed``, revision 9 on),
    else "unexplained" — :func:`gaitlib.gap.diagnose.assemble`'s rule replayed on the stored
    ranking. Returns the rows with ``named`` and ``correct`` replaced; a failed baseline
    stays as stored."""
    thr = min(diagnose.BIC_THRESHOLD, float(threshold))
    fl = _stored_floor(v) if floor is None else float(floor)
    r = v.rows.copy()
    st = case_statistic(v, centred)
    dbic = pd.to_numeric(r["rank1_dBIC"], errors="coerce")
    ok = (st <= thr) & (dbic <= diagnose.BIC_THRESHOLD) & _lone(v)
    if fl > 0:
        ok &= case_share(v, centred) >= fl
    r["named"] = np.where(r["verdict"] == "baseline failed", r["named"],
                          np.where(ok, r["rank1"].astype(str), "unexplained"))
    r["correct"] = [n in str(e).split("|") for n, e in zip(r["named"], r["expected"])]
    return r


def replayed_threshold(v: gval.Validation, centred: bool = True) -> float | None:
    """The threshold ``v``'s null calibration sets on the centred statistic (with ``centred``
    False on the raw one), whichever statistic the validation's own method used:
    :func:`gaitlib.gap.method.null_threshold` of its stored draws at its own rank, or the
    fixed threshold if that is lower; None without a calibration."""
    c = (v.unedited or {}).get("null_calibration") or {}
    t = gap_method.null_threshold(c.get("dBIC") or [], int(c.get("rank", 1)), centred=centred)
    return None if t is None else min(diagnose.BIC_THRESHOLD, t)


def centred_replay(reps: dict, floor: float | None = None) -> pd.DataFrame:
    """Revision 10's statistic replayed on stored rankings (label → relative validation): per
    validation, named right per target group decided on the raw statistic and share and on
    the centred ones (:func:`case_statistic`, :func:`case_share`), each at the threshold the
    same null draws set for it (:func:`replayed_threshold`), both with share floor ``floor``
    (None: each validation's own) — the same fits, rankings and draws, only the statistic and
    the share differ — and the pooled counts."""
    rules = (("raw ΔBIC", False), ("centred", True))
    rows = []
    for lab, v in reps.items():
        for rule, c in rules:
            t = replayed_threshold(v, c)
            k = _group_counts(named_at(v, t, centred=c, floor=floor)) if t is not None else {}
            rows.append({"validation": lab, "statistic": rule, "threshold": None if t is None else round(t, 1),
                         **{g: f"{a}/{n}" for g, (a, n) in k.items()}})
    for rule, c in rules:
        calibrated = {lab: v for lab, v in reps.items() if replayed_threshold(v, c) is not None}
        tot = _pooled_counts(calibrated, lambda v, c=c: named_at(v, replayed_threshold(v, c), centred=c, floor=floor))
        rows.append({"validation": "pooled", "statistic": rule, "threshold": np.nan,
                     **{g: f"{a}/{n} ({100.0 * a / n:.0f} %)" for g, (a, n) in tot.items() if n}})
    return pd.DataFrame(rows).set_index(["validation", "statistic"])


def centred_lines(reps: dict, floor: float | None = None) -> list[str]:
    """:func:`centred_replay` in words, every number from the stored rankings: each
    validation's threshold on both statistics, the pooled counts, and the cases of the target
    groups whose answer the statistic changes."""
    t = centred_replay(reps, floor)
    g_in, g_ool, g_null = "independent, middle + large", "out-of-library", "null (nothing changed)"
    thr = "; ".join(f"{lab} {t.loc[(lab, 'raw ΔBIC'), 'threshold']:.0f} → {t.loc[(lab, 'centred'), 'threshold']:.0f}"
                    for lab in reps)
    pooled = ", ".join(f"{g} {t.loc[('pooled', 'raw ΔBIC'), g]} → {t.loc[('pooled', 'centred'), g]}"
                       for g in (g_in, "independent, small", g_ool, g_null))
    changed = []
    for lab, v in reps.items():
        a = named_at(v, replayed_threshold(v, False), centred=False, floor=floor)
        b = named_at(v, replayed_threshold(v), centred=True, floor=floor)
        keep = ~((b["set"] == "independent") & (b["band"] == "small"))
        for i in b.index[(a["named"] != b["named"]) & keep]:
            changed.append((lab, b.loc[i, "case"], a.loc[i, "named"], b.loc[i, "named"], b.loc[i, "expected"],
                            bool(b.loc[i, "correct"])))
    fl = "each validation's own share floor" if floor is None else f"a {floor:g} % share floor"
    line = (f"Decided relative to the median candidate — the first-ranked effect's ΔBIC minus the median candidate's "
            f"instead of its ΔBIC, and {fl} on the share of what the median candidate leaves open instead of the "
            f"whole gap — the same null draws set the thresholds {thr}; "
            + (f"pooled over the {len(reps)} sets: " if len(reps) > 1 else "") + f"{pooled}.")
    if changed:
        right = {}
        for lab, *_, ok in changed:
            right[lab] = right.get(lab, 0) + int(ok)
        wrong = [x for x in changed if not x[-1]]
        noun = "cases change their" if len(changed) > 1 else "case changes its"
        line += (f" {len(changed)} middle, large, out-of-library or null {noun} answer; to the right one "
                 + ", ".join(f"{k} on {lab}" for lab, k in right.items() if k)
                 + ("; to a wrong one " + "; ".join(f"{c} ({lab}) {x} → {y}, right answer {e}"
                                                   for lab, c, x, y, e, _ in wrong) if wrong else "") + ".")
    return [line]


def _group_counts(rows: pd.DataFrame) -> dict:
    """Named right / cases per target group (:data:`TARGET_GROUPS`): group → (k, n)."""
    out = {}
    for g, (st, bands) in TARGET_GROUPS.items():
        r = rows[rows["set"] == st]
        if bands is not None:
            r = r[r["band"].isin(bands)]
        out[g] = (int(r["correct"].astype(bool).sum()), len(r))
    return out


def rule_table(v: gval.Validation) -> pd.DataFrame:
    """One relative validation's cases decided by the null threshold of revisions 1–4 (the
    lowest statistic of the calibration's first 9 draws — the draws a K = 9 calibration of
    this method would have made, the seeds being per draw) and by its own rule
    (:func:`gaitlib.gap.method.null_threshold`, ``rank`` of all its draws): per target group,
    named right / cases, and each rule's threshold. Paired: the same cases, the same
    rankings, only the threshold differs (:func:`named_at`)."""
    c = (v.unedited or {}).get("null_calibration") or {}
    per, rank, cen = c.get("dBIC") or [], int(c.get("rank", 1)), _centred(v)
    rules = {f"lowest of the first {min(9, len(per))} draws (revisions 1–4)":
             gap_method.null_threshold(per[:9], 1, cen),
             f"{_ORDINAL.get(rank, f'{rank}th')} of {len(per)} draws (this revision)":
             gap_method.null_threshold(per, rank, cen)}
    rows = []
    for lab, t in rules.items():
        k = _group_counts(named_at(v, t)) if t is not None else {}
        rows.append({"rule": lab, "threshold (ΔBIC ≤)": t,
                     **{g: (f"{a}/{n}" if n else "—") for g, (a, n) in k.items()}})
    return pd.DataFrame(rows).set_index("rule")


#: The fixed thresholds (ΔBIC ≤) :func:`threshold_sweep` decides every case at.
SWEEP_THRESHOLDS = (-10, -20, -30, -40, -50, -60, -80, -100, -150)


def _pooled_counts(reps: dict, decide) -> dict:
    """Target group → [named right, cases] over the validations of ``reps``, each decided again
    by ``decide(validation)`` (its rows with ``correct`` replaced)."""
    tot = {g: [0, 0] for g in TARGET_GROUPS}
    for v in reps.values():
        for g, (k, n) in _group_counts(decide(v)).items():
            tot[g][0] += k
            tot[g][1] += n
    return tot


def _sweep_counts(reps: dict, thresholds=SWEEP_THRESHOLDS) -> dict:
    """threshold → target group → [named right, cases], pooled over ``reps``."""
    return {t: _pooled_counts(reps, lambda v, t=t: named_at(v, t)) for t in thresholds}


def threshold_sweep(reps: dict, thresholds=SWEEP_THRESHOLDS) -> pd.DataFrame:
    """Named right per target group, pooled over the replicates ``reps`` (label →
    :class:`~gaitlib.gap.validate.Validation`), had every case been decided at each of
    ``thresholds`` (ΔBIC ≤) instead of its own calibration's (:func:`named_at`): what the
    threshold alone can trade between naming an injected effect and saying "unexplained"."""
    rows = [{"threshold (ΔBIC ≤)": t, **{g: (f"{k}/{n} ({100.0 * k / n:.0f} %)" if n else "—")
                                          for g, (k, n) in tot.items()}}
            for t, tot in _sweep_counts(reps, thresholds).items()]
    out = pd.DataFrame(rows).set_index("threshold (ΔBIC ≤)")
    if reps and all(_centred(v) for v in reps.values()):  # revision 10 on: the statistic is centred
        out.index.name = "threshold (ΔBIC − median candidate's ≤)"
    return out


def ranking_misses(reps: dict, bands=("middle", "large")) -> pd.DataFrame:
    """The independent injections (in ``bands``) that no threshold names right: the expected
    effect not ranked first, or a runner-up within the margin (:func:`_lone`) — with the
    first two ranked effects and their ΔBIC. The ceiling of :func:`threshold_sweep`."""
    out = []
    for lab, v in reps.items():
        sel = (v.rows["set"] == "independent") & v.rows["band"].isin(bands)
        r, lone = v.rows[sel], _lone(v)[sel]
        for i, x in r.iterrows():
            if x["rank1"] == x["expected"] and lone[i]:
                continue
            out.append({"replicate": lab, "case": x["case"], "expected": x["expected"], "magnitude": x["magnitude"],
                        "rank1": x["rank1"], "rank1_dBIC": x["rank1_dBIC"], "rank2": x["rank2"],
                        "rank2_dBIC": x["rank2_dBIC"], "expected_rank": x["expected_rank"],
                        "why": "baseline fit failed: nothing ranked" if x["named"] == "baseline failed"
                        else "ranked first, runner-up within the margin" if x["rank1"] == x["expected"]
                        else "another effect ranked first"})
    return pd.DataFrame(out)


#: Floors on the share of the relative gap the named effect closes (%) that
#: :func:`share_floor_sweep` replays.
SHARE_FLOORS = (0.0, 10.0, 15.0, 20.0, 25.0, 30.0)


def _floor_held(v: gval.Validation) -> pd.Series:
    """The cases of ``v`` its own method's share floor (``min_share_closed``, revision 9 on)
    read "unexplained": the first-ranked effect within the case's threshold (and the fixed
    :data:`gaitlib.gap.method.BIC_THRESHOLD`), no runner-up within the margin, but closing
    less than the floor — :func:`gaitlib.gap.diagnose.assemble`'s rule read back from the
    stored ranking. All False for a validation made without a floor."""
    r = v.rows
    floor = _stored_floor(v)
    if floor <= 0:
        return pd.Series(False, index=r.index)
    dbic = pd.to_numeric(r["rank1_dBIC"], errors="coerce")
    thr = pd.to_numeric(r["threshold_used"], errors="coerce").clip(upper=diagnose.BIC_THRESHOLD)
    return ((r["named"] == "unexplained") & (r["verdict"] != "baseline failed") & (case_statistic(v) <= thr)
            & (dbic <= diagnose.BIC_THRESHOLD) & _lone(v) & (case_share(v) < floor))


def with_share_floor(v: gval.Validation, floor: float) -> pd.DataFrame:
    """The cases of a relative validation decided again with another floor on the share of the
    relative gap the named effect closes, post hoc: a named effect that closes less than
    ``floor`` % (:func:`case_share`, as the validation's method measured it; the named effect
    is the first-ranked one) is read "unexplained"; a case the validation's own floor held
    (:func:`_floor_held`) names its first-ranked effect again if it closes ``floor`` % or more
    (so 0: the method without a floor); everything else as stored. Returns the rows with
    ``named`` and ``correct`` replaced."""
    r = v.rows.copy()
    pct = case_share(v)
    back = _floor_held(v) & (pct >= floor)
    r.loc[back, "named"] = r.loc[back, "rank1"]
    held = (r["named"] != "unexplained") & (r["named"] == r["rank1"]) & (pct < floor)
    r.loc[held, "named"] = "unexplained"
    r["correct"] = [n in str(e).split("|") for n, e in zip(r["named"], r["expected"])]
    return r


def share_floor_sweep(reps: dict, floors=SHARE_FLOORS) -> pd.DataFrame:
    """Named right per target group, pooled over ``reps`` (label → validation), had a named
    effect also had to close at least each of ``floors`` % of the relative gap
    (:func:`with_share_floor`; 0: the method as it is) — a replay on the stored rankings, not a
    method: a floor chosen here would have to be validated on fresh draws."""
    rows = []
    for f in floors:
        tot = _pooled_counts(reps, lambda v, f=f: with_share_floor(v, f))
        rows.append({"share closed ≥ (%)": f, **{g: (f"{k}/{n} ({100.0 * k / n:.0f} %)" if n else "—")
                                                  for g, (k, n) in tot.items()}})
    return pd.DataFrame(rows).set_index("share closed ≥ (%)")


def share_floor_lines(reps: dict, floor: float | None = None) -> list[str]:
    """What the wrongly named out-of-library cases and the rightly named middle+large
    injections of ``reps`` closed of their relative gap (stored ``rank1_pct``), in words; with
    ``floor`` (a method's ``min_share_closed``), what that floor gives on the same rankings
    (:func:`share_floor_sweep`) instead of the sentence calling a floor a lead."""
    wrong, right = [], []
    for lab, v in reps.items():
        r = v.rows
        named = r["named"] != "unexplained"
        wrong += [(lab, x) for _, x in r[(r["set"] == "out-of-library") & named].iterrows()]
        right += [(lab, x) for _, x in r[(r["set"] == "independent") & r["band"].isin(["middle", "large"])
                                          & r["correct"].astype(bool)].iterrows()]
    if not wrong or not right:
        return []
    lo = min(right, key=lambda t: float(t[1]["rank1_pct"]))
    return [f"The out-of-library cases named an effect closed {min(float(x['rank1_pct']) for _, x in wrong):.0f}–"
            f"{max(float(x['rank1_pct']) for _, x in wrong):.0f} % of their relative gap ("
            + ", ".join(f"{x['case']} ({lab}): {x['named']} {float(x['rank1_pct']):.0f} %" for lab, x in wrong)
            + f"); the middle and large injections named right closed {float(lo[1]['rank1_pct']):.0f} % or more "
            f"(the least: {lo[1]['case']}, {lo[0]}). "
            + ("A floor on the share closed is a lead for the next revision, read here on the draws that suggested "
               "it: not adopted, not validated." if floor is None else
               f"With a {floor:g} % floor the same rankings give " + ", ".join(
                   f"{g} {x}" for g, x in share_floor_sweep(reps, (floor,)).iloc[0].items())
               + " — on the draws that suggested the floor, so fresh draws are its test.")]


def floor_held_lines(v: gval.Validation, label: str) -> list[str]:
    """What ``v``'s own share floor did on its draws, in words: the cases it read
    "unexplained" (:func:`_floor_held`; first-ranked effect, ΔBIC, % closed, the right
    answer) and each target group's count without the floor and with it."""
    floor = _stored_floor(v)
    if floor <= 0:
        return []
    mask = _floor_held(v)
    held, share = v.rows[mask], case_share(v)[mask]
    sw = share_floor_sweep({label: v}, (0.0, floor))
    counts = "; ".join(f"{g} {sw.iloc[0][g]} → {sw.iloc[1][g]}" for g in sw.columns)
    if held.empty:
        return [f"On {label}'s draws the {floor:g} % floor held no case: every named effect closed more."]
    of = " of what the median candidate leaves" if _centred(v) else ""
    return [f"On {label}'s draws the {floor:g} % floor held {len(held)} case{'s' if len(held) > 1 else ''} "
            "(read \"unexplained\" though ranked first within the threshold): "
            + "; ".join(f"{x['case']} ({x['rank1']}, ΔBIC {float(x['rank1_dBIC']):.0f}, "
                        f"{float(share[i]):.0f} % closed{of}; right answer {x['expected']})"
                        for i, x in held.iterrows())
            + f". Without the floor → with it: {counts}."]


def threshold_lines(reps: dict, target: float = 90.0) -> list[str]:
    """:func:`threshold_sweep` and :func:`ranking_misses` in words, every number from the
    stored results: the best rate any threshold gives the independent middle+large group,
    the thresholds at which the out-of-library group reaches the target, and the cases no
    threshold names right."""
    sw = _sweep_counts(reps)
    g_in, g_ool = "independent, middle + large", "out-of-library"

    def pct(t, g):
        k, n = sw[t][g]
        return 100.0 * k / n if n else np.nan

    k_in = max(sw[t][g_in][0] for t in sw)
    at_best = [t for t in sw if sw[t][g_in][0] == k_in]
    n_in = sw[at_best[0]][g_in][1]
    ool_ok = [t for t in sw if pct(t, g_ool) >= target]
    miss = ranking_misses(reps)
    fams = miss["expected"].value_counts() if len(miss) else pd.Series(dtype=int)
    line = (f"Decided again at fixed thresholds ({len(reps)} replicates pooled, the same rankings): the independent "
            f"middle+large group reaches at best {k_in}/{n_in} ({pct(at_best[0], g_in):.0f} %) (at any threshold from "
            f"{max(at_best):g} to {min(at_best):g}); the out-of-library group reaches "
            f"{target:.0f} % " + (f"only at ΔBIC ≤ {max(ool_ok):g} or lower" if ool_ok else "at no threshold tried")
            + f". {len(miss)} cases no threshold names right")
    if len(miss):
        line += (" — " + ", ".join(f"{k} of the {e} injections" for e, k in fams.items()) + ": "
                 + "; ".join(f"{r['case']} ({r['replicate']}): " + (
                     "the baseline fit failed, nothing ranked" if r["why"].startswith("baseline fit failed")
                     else f"{r['rank1']} {r['rank1_dBIC']:.0f}, {r['rank2']} {r['rank2_dBIC']:.0f}")
                             for _, r in miss.iterrows())
                 + ". These are the target's ceiling under this ranking: a threshold cannot move it.")
    else:
        line += "."
    return [line]


def threshold_draw_lines(v: gval.Validation, label: str = "") -> list[str]:
    """The null draw whose statistic is the lowest of a relative validation's calibration, in
    words computed from the stored calibration: its first-ranked effect and ΔBIC, how many of
    the ranked candidates reached at least half that ΔBIC (a shift shared by unrelated
    candidates rather than one effect absorbing noise), and the baseline's fit of the
    reference in that draw (its objective after the self-consistency rounds) against the
    other draws' median."""
    c = (v.unedited or {}).get("null_calibration") or {}
    per, cen = c.get("dBIC") or [], _centred(v)
    stats = [(gap_method.draw_statistic(p, cen), j) for j, p in enumerate(per) if p]
    if not stats:
        return ["(no ranked null draw stored)"]
    st, j = min(stats)
    vals = per[j]
    eff = min(vals, key=vals.get)
    lo = vals[eff]
    near = sorted(x for x in vals.values() if x <= lo / 2)
    line = (f"The draw that sets {label or 'this calibration'}'s lowest statistic (null{j}): {eff} at ΔBIC {lo:.0f}"
            + (f" ({st:.0f} from the median candidate's)" if cen else "") + "; "
            f"{len(near)} of its {len(vals)} ranked candidates reached ΔBIC ≤ {lo / 2:.0f} (half of it), from "
            f"{near[-1]:.0f} to {near[0]:.0f}")
    moved = c.get("moved") or {}

    def ref_after(k):
        b = (moved.get(k) or {}).get("baseline") or {}
        return b["reference"][1] if b.get("reference") else None

    mine = ref_after(f"null{j}")
    others = [x for k in moved if k != f"null{j}" and (x := ref_after(k)) is not None]
    if mine is not None and others:
        line += (f"; in it the baseline's fit of the reference reached objective {mine:.3f}, against a median of "
                 f"{float(np.median(others)):.3f} in the other {len(others)} draws where it moved")
    return [line + "."]


def _draw_modes(v: gval.Validation, cut: float) -> list:
    """Per ranked calibration draw of ``v``: (its statistic — the lowest ΔBIC over the
    candidates, common-mode — the median candidate's ΔBIC ≤ ``cut``, kept — the baseline's
    fit of the reference not re-solved lower in the self-consistency rounds)."""
    c = (v.unedited or {}).get("null_calibration") or {}
    moved = c.get("moved") or {}
    return [(min(p.values()), bool(np.median(list(p.values())) <= cut),
             not ((moved.get(f"null{j}") or {}).get("baseline") or {}).get("reference"))
            for j, p in enumerate(c.get("dBIC") or []) if p]


def common_mode_table(vals: dict, cut: float = -20.0) -> pd.DataFrame:
    """The calibration draws of relative validations (label → Validation) where the
    candidates gained *alike*: the median ranked candidate's ΔBIC at or below ``cut`` — a
    shift of the baseline's relative fit that every candidate is credited with, not one
    effect absorbing noise. Per validation: its draws; the common-mode ones; of those, how
    many kept the baseline's starting fit of the reference through the self-consistency
    rounds (not re-solved lower; ``moved`` has no ``reference`` for the baseline) against
    the same count in the other draws; the lowest statistic of each kind; the threshold."""
    rows = []
    for lab, v in vals.items():
        d = _draw_modes(v, cut)
        cm, other = [x for x in d if x[1]], [x for x in d if not x[1]]
        rows.append({"validation": lab, "draws": len(d), f"common-mode (median ≤ {cut:g})": len(cm),
                     "of which the reference's baseline fit kept": sum(k for *_, k in cm),
                     "other draws": len(other), "of which kept": sum(k for *_, k in other),
                     "common-mode lowest": min((x for x, *_ in cm), default=np.nan),
                     "other draws' lowest": min((x for x, *_ in other), default=np.nan),
                     "threshold": calibration_threshold(v)})
    return pd.DataFrame(rows).set_index("validation")


def common_mode_lines(vals: dict, cut: float = -20.0) -> list[str]:
    """:func:`common_mode_table` pooled over ``vals`` in words, every number from the draws."""
    d = [x for v in vals.values() for x in _draw_modes(v, cut)]
    cm, other = [x for x in d if x[1]], [x for x in d if not x[1]]
    line = (f"Over {', '.join(vals)}: {len(cm)} of {len(d)} calibration draws were common-mode (the median "
            f"candidate's ΔBIC ≤ {cut:g}: every candidate credited alike)")
    if cm:
        st = sorted(x for x, *_ in cm)
        line += (f", their statistics from {st[-1]:.0f} to {st[0]:.0f}; in {sum(k for *_, k in cm)} of the {len(cm)} "
                 "the baseline's fit of the reference kept its start through the self-consistency rounds, against "
                 f"{sum(k for *_, k in other)} of the {len(other)} other draws")
    if other:
        line += f". The other draws' statistics reached at most {min(x for x, *_ in other):.0f}"
    return [line + "."]


#: ``benchmarks/gap_load_confusion.py``'s result, under the validation's folder.
LOAD_CONFUSION_FILE = "load_confusion.json"


def stored_load_confusion() -> dict | None:
    """``benchmarks/gap_load_confusion.py``'s result (:func:`stored_experiment`), refused if a
    validation it names was made under another relative method than the stored one."""
    r = stored_experiment(f"gap_validation/{LOAD_CONFUSION_FILE}", "gap_load_confusion.py")
    if r is None:
        return r
    for name, h in r["validations"].items():
        if superseded_validation(name).settings.get("relative_method_hash") != h:
            raise RuntimeError(f"{LOAD_CONFUSION_FILE}: {name} was re-diagnosed under relative method {h}, it is "
                               f"stored under another: rerun benchmarks/gap_load_confusion.py")
    return r


def load_confusion_lines(res: dict) -> list[str]:
    """``benchmarks/gap_load_confusion.py``'s result in words, every number from it: per
    manipulation, the share of the baseline's located change in the torque channels, what
    ``body_mass`` and ``grf_scale`` leave in the GRF and torque channels (medians), and how
    often each was ranked first."""
    cs = pd.DataFrame(res["cases"])
    out = []
    for inj, g in cs.groupby("injection", sort=False):
        def med(m, k):
            return float(np.median([x[m][k] for _, x in g.iterrows()]))

        tq = [x["baseline"]["torque"] / (x["baseline"]["torque"] + x["baseline"]["grf"] + x["baseline"]["angle"])
              for _, x in g.iterrows()]
        first = g["rank1"].value_counts()
        exp = str(g["expected"].iloc[0])
        chg = [(x["magnitude"], x[exp]["change"]) for _, x in g.iterrows()]
        out.append(
            f"`{inj}` (expected `{exp}`, {len(g)} middle/large cases): the torque channels carry "
            f"{100 * min(tq):.0f}–{100 * max(tq):.0f} % of the baseline's located change. Median RSS left in the "
            f"GRF channels: body_mass {med('body_mass', 'grf'):.1f}, grf_scale {med('grf_scale', 'grf'):.1f} "
            f"(baseline {med('baseline', 'grf'):.1f}); in the torque channels: body_mass "
            f"{med('body_mass', 'torque'):.1f}, grf_scale {med('grf_scale', 'torque'):.1f} (baseline "
            f"{med('baseline', 'torque'):.1f}). Ranked first: " + ", ".join(f"{e} {k}×" for e, k in first.items())
            + f". `{exp}`'s identified change against the injected magnitude: "
            + ", ".join(f"{c:+.3f} for {m:+.3f}" for m, c in chg) + ".")
    bm = cs.apply(lambda x: x["body_mass"]["grf"] - x["grf_scale"]["grf"], axis=1)
    tq = cs.apply(lambda x: x["grf_scale"]["torque"] - x["body_mass"]["torque"], axis=1)
    ls = cs["injection"] == "load_scale"
    if ls.any():
        g = cs[ls]
        err = [abs(x["body_mass"]["change"] / x["magnitude"] - 1.0) for _, x in g.iterrows()]
        line = (f"So on a normalising-mass error the model's `body_mass` — the dynamic body made heavier, contact and "
                f"data unchanged — identifies the injected magnitude (within {100 * max(err):.0f} %) but does not fit the "
                f"scaled GRFs as a plate gain does: it leaves {bm[ls].median():.1f} more GRF RSS than `grf_scale` "
                f"(median; more in {int((bm[ls] > 0).sum())} of {int(ls.sum())} cases)")
        if "grf_swing" in g["body_mass"].iloc[0]:
            sw = {m: [x[m]["grf_swing"] for x in g.to_dict("records")] for m in ("body_mass", "grf_scale")}
            load = {m: [max(x[m]["swing_load_N"].values()) for x in g.to_dict("records")]
                    for m in ("baseline", "body_mass", "grf_scale")}
            share = [(a - b) / e for a, b, e in zip(sw["body_mass"], sw["grf_scale"], bm[ls]) if e > 0]
            line += (f"; {100 * np.median(share):.0f} % of that excess (median) lies in the swing phases, where "
                     f"body_mass leaves {np.median(sw['body_mass']):.1f} and grf_scale {np.median(sw['grf_scale']):.1f}"
                     f" (medians). In the data's swing the model's feet "
                     f"carry load — the larger foot's peak vertical GRF {np.median(load['baseline']):.0f} N in the "
                     f"baseline's fit, {np.median(load['body_mass']):.0f} N in body_mass's, "
                     f"{np.median(load['grf_scale']):.0f} N in grf_scale's (medians; the data: none): a heavier model "
                     "presses that misfit harder, and the relative method's assumption that the model's own misfit "
                     "does not change with the effect fails there")
        out.append(line + f". In the torque channels, where a gain and a mass differ, body_mass leaves {tq[ls].median():.1f}"
                   f" less (median), more than its GRF excess in {int((tq[ls] > bm[ls]).sum())} of {int(ls.sum())} cases. "
                   "The library has no effect that scales the data's loads as a normalising mass does, so the choice "
                   "between a mass and a plate gain rests on that balance: with the runner-up margin, this family is "
                   "the ceiling of the threshold sweep.")
    return out


#: ``benchmarks/gap_paired.py``'s experiments: a relative-method change on a stored
#: validation's own draws, name → what changed (in words).
PAIRED = {"quiet_points_rev5": "located with the quiet points left out",
          "reference_fit_rev6": "with the baseline's fit of the reference re-solved from the candidates'",
          "lowest_pair_rev7": "with a failed baseline continuation's fallback and each model's lower located pair"}


def pair_counts(v: gval.Validation) -> pd.DataFrame:
    """How often a relative validation (:class:`gaitlib.gap.method.RelativeMethod`
    ``lowest_pair``) located the continuation pair instead of the final one: per set, the
    cases whose baseline and whose first-ranked candidate were located on it; the same for the
    null calibration's draws. Columns missing from a validation that did not record them
    read NaN."""
    r = v.rows
    out = []

    def n_cont(col, rows):
        return int((rows[col] == "continuation").sum()) if col in rows else np.nan

    for st, g in r.groupby("set", sort=False):
        out.append({"cases": st, "n": len(g), "baseline on the continuation pair": n_cont("baseline_pair", g),
                    "first-ranked on the continuation pair": n_cont("rank1_pair", g)})
    calib = v.unedited.get("null_calibration") or {}
    if calib:
        bp, best = calib.get("baseline_pair"), calib.get("best") or []
        out.append({"cases": "null calibration draws", "n": len(best),
                    "baseline on the continuation pair": (sum(x == "continuation" for x in bp.values())
                                                          if bp is not None else np.nan),
                    "first-ranked on the continuation pair": (sum(b.get("pair") == "continuation" for b in best)
                                                              if any("pair" in b for b in best) else np.nan)})
    return pd.DataFrame(out).set_index("cases")


def stored_paired(name: str) -> gval.Validation | None:
    """``benchmarks/gap_paired.py``'s validation ``name`` (:data:`PAIRED`: a stored
    validation's draws diagnosed again with a field of the method changed), or None if not
    run; refused if made with another method or on other draws than the stored validation
    it pairs with."""
    folder = perf.results_dir() / "gap_validation" / name
    if name not in PAIRED:
        raise ValueError(f"unknown paired experiment {name!r}; known: {', '.join(PAIRED)}")
    if not (folder / "validation.json").is_file():
        return None
    v = gval.Validation.load(folder)
    pair = superseded_validation(v.settings["pairs_with"])
    for k in ("method_hash", "relative_method_hash"):
        if v.settings.get(k) != pair.settings.get(k):
            raise RuntimeError(f"{folder}: its {k} {v.settings.get(k)} is not {v.settings['pairs_with']}'s "
                               f"{pair.settings.get(k)}: rerun benchmarks/gap_paired.py {name}")
    return v


def case_change_lines(before: gval.Validation, after: gval.Validation, cases) -> list[str]:
    """One sentence per named case of a paired run (:func:`stored_paired`): the injection,
    then before and after the change what was named, the expected effect's identified change
    (:func:`_change_text`), % closed and ΔBIC — or the baseline's failure — and, after, the
    fallback start and the located pair where recorded."""
    import ast

    b, a = before.rows.set_index("case"), after.rows.set_index("case")

    def side(r) -> str:
        if r["named"] == "baseline failed":
            return f"baseline failed ({r.get('error')})"
        ch = r.get("expected_change")
        ch = ast.literal_eval(ch) if isinstance(ch, str) else ch
        txt = (f"named {r['named']}; {r['expected_effect']}"
               + (f" identified {_change_text(r['expected_effect'], ch)}" if isinstance(ch, dict) and ch else "")
               + f", {float(r['expected_pct']):.0f} % closed, ΔBIC {float(r['expected_dBIC']):.0f}")
        extra = []
        if isinstance(r.get("baseline_fallback"), str):
            extra.append(f"baseline from the {r['baseline_fallback']}")
        if r.get("rank1") == r["expected_effect"] and isinstance(r.get("rank1_pair"), str):
            extra.append(f"located on its {r['rank1_pair']} pair")
        return txt + (f" ({'; '.join(extra)})" if extra else "")

    out = []
    for c in cases:
        rb, ra = b.loc[c], a.loc[c]
        out.append(f"{c} ({rb['injection']} {float(rb['magnitude']):+.3g} {rb['unit']}): before, {side(rb)}; "
                   f"after, {side(ra)}.")
    return out


def paired_lines(before: gval.Validation, after: gval.Validation, what: str) -> list[str]:
    """The same draws diagnosed before and after a change of the method (:func:`stored_paired`;
    ``what``: the change in words, :data:`PAIRED`), every number from the two results: each
    target group's count in both, each calibration's threshold, the cases ranked right with
    no runner-up within the margin (what a threshold can reach), and the cases whose verdict
    changed."""
    cb, ca = _group_counts(before.rows), _group_counts(after.rows)
    tb, ta = calibration_threshold(before), calibration_threshold(after)
    parts = [f"{g}: {cb[g][0]}/{cb[g][1]} → {ca[g][0]}/{ca[g][1]}" for g in TARGET_GROUPS if cb[g][1]]
    nb, na = (len(ranking_misses({"x": v})) for v in (before, after))
    n_ind = int(((before.rows["set"] == "independent") & before.rows["band"].isin(("middle", "large"))).sum())
    b, a = before.rows.set_index("case"), after.rows.set_index("case")
    changed = [c for c in b.index if c in a.index and b.loc[c, "named"] != a.loc[c, "named"]]
    line = (f"The same draws, {what}: " + "; ".join(parts)
            + f" (thresholds ΔBIC ≤ {tb:.0f} → {ta:.0f}). Independent middle+large injections ranked right with no "
            f"runner-up within the margin — the most any threshold can name: {n_ind - nb} → {n_ind - na} of {n_ind}. ")
    line += ("Verdicts changed: " + "; ".join(f"{c} {b.loc[c, 'named']} → {a.loc[c, 'named']} (expected "
                                              f"{b.loc[c, 'expected']})" for c in changed) + "."
             if changed else "No verdict changed.")
    return [line]


def null_tail_table(vals: dict, cut: float = -50.0) -> pd.DataFrame:
    """The null side of every relative validation (label → Validation): its calibration's
    draws (each draw's lowest ΔBIC over the candidates: how many, their median and lowest, how
    many at or below ``cut``), the threshold it set, and its ``null`` cases' first-ranked ΔBIC
    (the unedited data resampled, nothing changed: named beyond the threshold = a false
    name) — the two kinds of draw of the same null, side by side."""
    rows = []
    for lab, v in vals.items():
        c = (v.unedited or {}).get("null_calibration") or {}
        st = np.array(sorted(min(p.values()) for p in (c.get("dBIC") or []) if p), float)
        r = v.rows[v.rows["set"] == "null"]
        d = r["rank1_dBIC"].astype(float)
        rows.append({"validation": lab, "calibration draws": len(st),
                     "their median": float(np.median(st)) if len(st) else np.nan,
                     "their lowest": float(st[0]) if len(st) else np.nan,
                     f"draws ≤ {cut:g}": int((st <= cut).sum()), "threshold": calibration_threshold(v),
                     "null cases": len(r), "null cases' first-ranked ΔBIC": ", ".join(
                         "—" if not np.isfinite(x) else f"{x:.0f}" for x in d),
                     f"null cases ≤ {cut:g}": int((d <= cut).sum()),
                     "named (false)": int((r["named"] != "unexplained").sum())})
    return pd.DataFrame(rows).set_index("validation")


def null_tail_lines(vals: dict, cut: float = -50.0) -> list[str]:
    """:func:`null_tail_table` pooled in words: how often a draw of the null reached ``cut``
    among the calibrations' draws and among the validations' null cases."""
    t = null_tail_table(vals, cut)
    k_c, n_c = int(t[f"draws ≤ {cut:g}"].sum()), int(t["calibration draws"].sum())
    k_n, n_n = int(t[f"null cases ≤ {cut:g}"].sum()), int(t["null cases"].sum())
    lo_c, hi_c = wilson(k_c, n_c)
    lo_n, hi_n = wilson(k_n, n_n)
    nulls = [float(x) for cell in t["null cases' first-ranked ΔBIC"] for x in cell.split(", ") if x != "—"]
    return [f"Over {', '.join(t.index)} the null reached ΔBIC ≤ {cut:g} in {k_c} of {n_c} calibration draws "
            f"({lo_c:.0f}–{hi_c:.0f} %) and in {k_n} of {n_n} null cases ({lo_n:.0f}–{hi_n:.0f} %); the lowest values: "
            f"calibration draws {t['their lowest'].min():.0f}, null cases {min(nulls):.0f}. The null's tail is long: a "
            f"calibration of 9 or 19 draws sees such a draw or not by chance, and a threshold set above it names the "
            f"null cases that reach it ({int(t['named (false)'].sum())} of {n_n} null cases named an effect)."]


def replicate_lines(reps: dict, target: float = 90.0) -> list[str]:
    """The replicates of a validation in words, every number from their stored results: the
    threshold each null calibration set, the pooled rate of each target group against the
    target with its 95 % interval, and the cases the further replicates got wrong."""
    if len(reps) < 2:
        return ["(one replicate only)"]
    tab = replicate_table(reps)
    labs = list(reps)
    thr = [calibration_threshold(reps[x]) for x in labs]
    out = ["The same method on other draws: " + "; ".join(
        f"{x}: threshold ΔBIC ≤ {t:.0f}" if t is not None else f"{x}: no calibration" for x, t in zip(labs, thr))
        + (f" — the threshold moves by {max(thr) - min(thr):.0f} with the draws alone (the reference and its "
           "null draws), the method unchanged." if None not in thr else ".")]
    for g in ("independent, middle + large", "out-of-library", "null (nothing changed)", "independent, small"):
        r = tab.loc[g]
        if r["pooled"] in ("—", ""):
            continue
        line = (f"{g}: " + ", ".join(f"{x} {r[x]}" for x in labs) + f"; pooled {r['pooled']} = {r['pooled %']:.0f} % "
                f"(95 % interval {r['95 % interval']})")
        if g != "independent, small":
            met = r["pooled %"] >= target
            line += f" — the ≥ {target:g} % target {'met' if met else 'not met'} on the pooled rate"
            lo = float(r["95 % interval"].split("–")[0])
            if met and lo < target:
                line += f", though the interval reaches below it ({lo:.0f} %)"
        out.append(line + ".")
    ranked = []
    for x in labs:  # the right effect ranked first, whatever the threshold said
        v = reps[x].rows
        v = v[(v["set"] == "independent") & v["band"].isin(["middle", "large"])]
        if "rank1" in v.columns and len(v):
            first = v["rank1"] == v["expected"]
            miss = ~v["correct"].astype(bool)
            unex = miss & first & (v["named"] == "unexplained")
            thr = calibration_threshold(reps[x])
            within = unex & (v["rank1_dBIC"].astype(float) > (thr if thr is not None else diagnose.BIC_THRESHOLD))
            ranked.append(f"{x} {int(first.sum())}/{len(v)}; of its {int(miss.sum())} misses {int(unex.sum())} had "
                          f"it ranked first and were read \"unexplained\" — {int(within.sum())} with the first-ranked "
                          f"ΔBIC within that replicate's threshold"
                          + (f", {int((unex & ~within).sum())} beyond it (held by the method's other tests)"
                             if (unex & ~within).any() else ""))
    if ranked:
        out.append("Independent injections at middle and large magnitudes with the injected effect ranked first, "
                   "named or not: " + "; ".join(ranked) + ".")
    for x in labs[1:]:
        v = reps[x].rows
        wrong = v[(v["set"] != "independent") | v["band"].isin(["middle", "large"])]
        wrong = wrong[~wrong["correct"].astype(bool)]
        if len(wrong):
            out.append(f"Wrong in {x}: " + "; ".join(
                f"{c} ({m:+.3g} {u}) named {n}" for c, m, u, n in zip(wrong["case"], wrong["magnitude"],
                                                                       wrong["unit"], wrong["named"])) + ".")
    return out


_ORDINAL = {1: "the lowest", 2: "the second lowest", 3: "the third lowest"}


def calibration_lines(rel: gval.Validation) -> list[str]:
    """The relative validation's null calibration in words (every number from its stored
    result): the draws, their first-ranked candidates and ΔBIC, the threshold it set."""
    c = (rel.unedited or {}).get("null_calibration")
    if not c:
        return ["(no null calibration stored with this validation)"]
    best = [b for b in c["best"] if b.get("dBIC") is not None]
    vals = sorted(best, key=lambda b: b["dBIC"])
    eff = pd.Series([b["effect"] for b in best]).value_counts()
    thr, r = calibration_threshold(rel), int(c.get("rank", 1))
    out = [f"The reference redrawn {c['draws']} times within the sampling error of a difference of two group means "
           f"(n = {c['n_subjects']}), each diagnosed relative to it: first-ranked ΔBIC from {vals[-1]['dBIC']:.0f} to "
           f"{vals[0]['dBIC']:.0f} (" + ", ".join(f"{e} ×{k}" for e, k in eff.items()) + f"); so an effect is named only "
           f"at ΔBIC ≤ {thr:.0f} ({_ORDINAL.get(r, f'{r}th')} of the draws, level {r}/{c['draws'] + 1}; "
           f"the threshold alone: {diagnose.BIC_THRESHOLD:g})."
           + (f" Draws without a converged baseline: {', '.join(c['baseline_failed'])}." if c["baseline_failed"] else "")]
    return out


def consistency_lines(rel: gval.Validation) -> list[str]:
    """What the self-consistent reference fit (relative method revision 2,
    :func:`gaitlib.gap.diagnose.consistent_fits`) did in a relative validation, every number
    from its stored result: in how many null-calibration draws and validation cases a model's
    fit of the reference moved to a lower objective, which models, by how much."""
    c = (rel.unedited or {}).get("null_calibration") or {}
    moved = c.get("moved")
    if moved is None:
        return ["(no self-consistent reference fit in this validation: relative method revision < 2)"]
    ref_moved = {k: {m: x for m, x in d.items() if x.get("reference")} for k, d in moved.items()}
    drops = [100.0 * (1.0 - m["reference"][1] / m["reference"][0]) for d in ref_moved.values() for m in d.values()
             if m["reference"][0]]
    models = pd.Series([k for d in ref_moved.values() for k in d]).value_counts()
    n_draw = sum(1 for d in ref_moved.values() if d)
    out = (f"The self-consistent reference fit: re-solved from each model's fit of the draw, a model's fit of the "
           f"reference reached a lower objective in {n_draw} of {len(moved)} null draws "
           f"({sum(1 for d in ref_moved.values() if 'baseline' in d)} of them the baseline's; {len(drops)} model fits "
           f"in all: " + (", ".join(f"{m} ×{k}" for m, k in models.items()) if len(models) else "none") + ")")
    if drops:
        out += f", lower by {min(drops):.2g}–{max(drops):.2g} %"
    r = rel.rows
    if "reference_moved" in r.columns:
        mv = r["reference_moved"].apply(lambda x: list(x) if isinstance(x, (list, tuple)) else [])
        out += (f"; in {int((mv.str.len() > 0).sum())} of {len(r)} validation cases "
                f"({int(mv.apply(lambda x: 'baseline' in x).sum())} of them the baseline's)")
    out = [out + "."]
    frm = [d["baseline"]["data_from"] for d in moved.values() if (d.get("baseline") or {}).get("data_from")]
    if "baseline_from" in r.columns or frm:
        bf = r["baseline_from"].dropna() if "baseline_from" in r.columns else pd.Series(dtype=object)
        cnt = pd.Series(frm + list(bf)).value_counts()
        out.append(f"The baseline's fit of the data, re-solved from each nested candidate's, was lower than its "
                   f"continuation in {len(frm)} of {len(moved)} null draws and {len(bf)} of {len(r)} validation cases"
                   + (" (from " + ", ".join(f"{m} ×{k}" for m, k in cnt.items()) + ")." if len(cnt) else "."))
    return out


def tie_lines(v: gval.Validation, effect: str = "hip_offset", other: str = "hat_com") -> list[str]:
    """How close ``other`` came to ``effect`` in the cases whose expected effect is
    ``effect`` (middle and large), from each stored case's ΔBIC of every candidate."""
    r = v.rows
    r = r[(r["expected"] == effect) & r["band"].isin(["middle", "large"])]
    pairs = [(c, d[effect], d[other]) for c, d in zip(r["case"], r["dBIC"])
             if isinstance(d, dict) and effect in d and other in d]
    if not pairs:
        return [f"(no {effect} case with both {effect} and {other} ranked)"]
    gap = max(abs(a - b) for _, a, b in pairs)
    return [f"In the {len(pairs)} {effect} injections at middle and large magnitudes, {other}'s ΔBIC differs from "
            f"{effect}'s by at most {gap:.2g} (" + "; ".join(f"{c}: {a:.1f} vs {b:.1f}" for c, a, b in pairs)
            + f"), while the runner-up margin is {diagnose.RUNNER_UP_MARGIN:g}."]


def visibility_text(v: gval.Validation) -> str:
    """Why injections are (not) named, from ``v``'s independent set: the RSS each adds to the
    baseline fit (% of the unedited data's), for the cases named right and the others;
    how often the injected effect itself passed the threshold, and what outranked it."""
    r = v.rows[v.rows["set"] == "independent"]
    if r.empty:
        return ""
    right, wrong = r[r["correct"]], r[~r["correct"]]

    def rng(x):
        x = x.dropna()
        return f"median {x.median():.1f} % (range {x.min():.1f} to {x.max():.1f} %)" if len(x) else "none"

    passed = r[np.isfinite(r["expected_dBIC"]) & (r["expected_dBIC"] <= diagnose.BIC_THRESHOLD)]
    beaten = passed[~passed["correct"]]
    out = (f"The manipulations named right made the baseline fit worse by {rng(right['added_pct'])} of the unedited "
           f"data's RSS ({v.unedited['rss_baseline']:.0f}); those not named right by {rng(wrong['added_pct'])}. "
           f"The injected effect itself reached the naming threshold in {len(passed)} of {len(r)} cases")
    if len(beaten):
        def why(x):
            if x["rank1"] == x["expected"]:
                return (f"{x['injection']} {x['band']}: ranked first but within the runner-up margin of "
                        f"{x['rank2']} (ΔBIC {x['rank1_dBIC']:.1f} vs {x['rank2_dBIC']:.1f})")
            return (f"{x['injection']} {x['band']}: outranked by {x['rank1']} (ΔBIC {x['rank1_dBIC']:.1f} vs "
                    f"{x['expected_dBIC']:.1f})")

        out += "; where it did but was not named — " + "; ".join(why(x) for _, x in beaten.iterrows())
    return out + "."


def null_tables(null: gval.Validation, real: gval.Validation) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(every candidate's ΔBIC on the unedited data and over ``null``'s draws; each
    independent injection of ``real`` against that spread): :func:`gaitlib.gap.validate.null_spread`,
    :func:`gaitlib.gap.validate.visibility`."""
    sp = gval.null_spread(null)
    return sp["candidates"], gval.visibility(real, sp)


def null_lines(null: gval.Validation, real: gval.Validation, top: int = 4) -> list[str]:
    """What the diagnosis does with nothing injected (``null``'s draws: the unedited data
    resampled within SD/√n), and each independent injection of ``real`` against that spread
    (:func:`gaitlib.gap.validate.visibility`), in sentences computed from the two runs."""
    sp = gval.null_spread(null)
    c = sp["candidates"]
    k = sp["draws"]
    others = {n: m for n, m in sp["verdicts"].items() if n != null.unedited["named"]}
    rss = sp["rss_pct"]
    lines = [f"**With nothing injected** ({k} draws of the unedited data's means within SD/√n): the baseline fit's "
             f"RSS moved by {min(rss):+.1f} to {max(rss):+.1f} % of the unedited data's "
             f"({null.unedited['rss_baseline']:.0f}), and the verdict was the unedited data's "
             f"({null.unedited['named']}) in {sp['same_verdict']} of {k} draws"
             + (" (otherwise: " + ", ".join(f"{n} {m}×" for n, m in others.items()) + ")" if others else "") + ". "
             "The candidates that close the most of the data's own gap, ΔBIC on the unedited data and over the draws "
             "(mean ± SD, range): "
             + "; ".join(f"{e} {r['unedited']:.1f}, {r['mean']:.1f} ± {r['sd']:.1f} ({r['min']:.1f} to {r['max']:.1f})"
                         for e, r in c.head(top).iterrows()) + "."]
    v = gval.visibility(real, sp)
    if v.empty:
        return lines
    mid = v[v["band"].isin(["middle", "large"])]

    def part(d):
        moved = d[d["z"] <= -2.0]
        return (f"the injected effect's ΔBIC moved beyond twice its null SD in {len(moved)} of {len(d)} (z ≤ −2), "
                f"reached what naming needs against the other candidates' null ΔBIC in {int(d['reaches'].sum())}, "
                f"and the baseline's RSS changed by more than the null draws' largest change "
                f"({d['null_rss_pct_max'].iloc[0]:.1f} %) in {int((d['added_pct'].abs() > d['null_rss_pct_max']).sum())}; "
                f"named right: {int(d['correct'].sum())}")

    lines.append(f"**Against this spread**, of the {len(mid)} independent injections at middle and large magnitudes "
                 + part(mid) + ". At small magnitudes: " + part(v[v["band"] == "small"]) + ".")
    named_unreached = mid[mid["correct"] & ~mid["reaches"]]
    missed_reached = mid[~mid["correct"] & mid["reaches"]]
    if len(missed_reached):
        lines.append("Reached what naming needs but not named right: " + "; ".join(
            f"{r.injection} {r.band} (ΔBIC {r.dBIC:.1f}, needed {r.needed:.1f}; named {r.named})"
            for r in missed_reached.itertuples()) + ".")
    if len(named_unreached):
        lines.append("Named right without reaching it (another candidate fell short of its null mean): " + "; ".join(
            f"{r.injection} {r.band}" for r in named_unreached.itertuples()) + ".")
    return lines


#: The stored result of ``benchmarks/gap_null_refit.py`` (the null set's baselines re-fitted).
NULL_REFIT_FILE = "null_refit.json"


def stored_experiment(relpath: str, script: str) -> dict | None:
    """A gap experiment's JSON result under the benchmark results folder (``relpath``,
    written by ``benchmarks/<script>``), or None if absent; refused if made with another
    method than the current one."""
    f = perf.results_dir() / relpath
    if not f.is_file():
        return None
    r = json.loads(f.read_text())
    if r.get("method_hash") != gap_method.METHOD.hash():
        raise RuntimeError(f"{f}: made with method {r.get('method_hash')}, the method is now "
                           f"{gap_method.METHOD.hash()}: rerun benchmarks/{script}")
    return r


def _stored_run_experiment(name: str) -> dict | None:
    """``benchmarks/gap_<name>.py``'s result on a paired run (:func:`stored_experiment`,
    ``results/gap_validation/<name>.json``), refused if the run it re-diagnosed was made under
    another relative method than the stored one."""
    r = stored_experiment(f"gap_validation/{name}.json", f"gap_{name}.py")
    if r is not None and stored_paired(r["run"]).settings.get("relative_method_hash") != r["relative_method_hash"]:
        raise RuntimeError(f"{name}.json: {r['run']} is no longer the run it re-diagnosed: rerun "
                           f"benchmarks/gap_{name}.py")
    return r


def stored_baseline_pair() -> dict | None:
    """``benchmarks/gap_baseline_pair.py``'s result (:func:`_stored_run_experiment`)."""
    return _stored_run_experiment("baseline_pair")


def experiment_draws_table(r: dict, runs=("as_run", "pair")) -> pd.DataFrame:
    """A ranking experiment's draws (``gap_baseline_pair.py``, ``gap_candidate_baseline.py``)
    as a table: per draw and run, the first-ranked effect and ΔBIC, the median candidate's
    ΔBIC, how many candidates were compared and, where stored, the baseline's objectives."""
    rows = []
    for d in r["draws"]:
        for lab in runs:
            x = d[lab]
            rows.append({"draw": d["draw"], "run": lab, "first ranked": x["rank1"] or "— (none ranked)",
                         "ΔBIC": x["rank1_dBIC"], "median candidate ΔBIC": x["median_dBIC"],
                         "compared": x.get("ranked"), **({"baseline objective N": x["objective_N"],
                                                          "baseline objective R": x["objective_R"]}
                                                         if "objective_N" in x else {})})
    return pd.DataFrame(rows)


def baseline_pair_lines(r: dict, cut: float = -20.0) -> list[str]:
    """``benchmarks/gap_baseline_pair.py``'s result in words, every number from it: per
    common-mode draw (the run's median candidate ΔBIC ≤ ``cut``), its statistic and median
    with the baseline's two fits as the run chose them and as a pair; the other draws' largest
    change of the first-ranked ΔBIC."""
    cm = [d for d in r["draws"] if d["as_run"]["median_dBIC"] <= cut]
    other = [d for d in r["draws"] if d["as_run"]["median_dBIC"] > cut]
    fixed = [d for d in cm if d["pair"]["median_dBIC"] > cut]
    parts = [f"{d['draw']} {d['as_run']['rank1_dBIC']:.0f} (median {d['as_run']['median_dBIC']:.0f}) → "
             f"{d['pair']['rank1_dBIC']:.0f} (median {d['pair']['median_dBIC']:.0f})" for d in cm]
    line = (f"The baseline's fits of the draw and of the reference chosen as a pair (the lower sum of the two "
            f"objectives, each pair reached from one start; `benchmarks/gap_baseline_pair.py`, ranking only): of "
            f"{len(cm)} common-mode draws, {len(fixed)} lost the common mode — " + "; ".join(parts))
    if other:
        ch = max(abs(d["pair"]["rank1_dBIC"] - d["as_run"]["rank1_dBIC"]) for d in other)
        line += f"; the first-ranked ΔBIC of the {len(other)} other draws moved by at most {ch:.1f}"
    rest = [d for d in cm if d not in fixed]
    if rest:
        dobj = max(abs(d["pair"][f"objective_{x}"] - d["as_run"][f"objective_{x}"]) for d in rest for x in "NR")
        line += (f". In {', '.join(d['draw'] for d in rest)} the pair moved the baseline's objectives by at most "
                 f"{dobj:.4f} and every candidate still gained alike: a mismatch of the baseline's two optima explains "
                 "part of the common mode, not all of it")
    return [line + "."]


def stored_candidate_baseline() -> dict | None:
    """``benchmarks/gap_candidate_baseline.py``'s result (:func:`_stored_run_experiment`)."""
    return _stored_run_experiment("candidate_baseline")


def candidate_baseline_lines(r: dict, cut: float = -20.0) -> list[str]:
    """``benchmarks/gap_candidate_baseline.py``'s result in words, every number from it: the
    medians and first-ranked ΔBIC of the draws with every candidate against the one baseline
    and against the baseline re-solved from its own fits."""
    one = [d["one_baseline"] for d in r["draws"] if d["one_baseline"]["ranked"]]
    own = [d["own_baseline"] for d in r["draws"] if d["own_baseline"]["ranked"]]
    med1, med2 = (sorted(x["median_dBIC"] for x in v) for v in (one, own))
    f1, f2 = (sorted(x["rank1_dBIC"] for x in v) for v in (one, own))
    return [f"Each candidate against the baseline re-solved from its own fits of the draw and the reference "
            f"(`benchmarks/gap_candidate_baseline.py`, {len(r['draws'])} draws, ranking only): the median candidate's "
            f"ΔBIC fell within {med2[0]:.0f} to {med2[-1]:.0f} (against the one baseline: {med1[0]:.0f} to "
            f"{med1[-1]:.0f}; ≤ {cut:g} in {sum(m <= cut for m in med2)} draws against {sum(m <= cut for m in med1)}), "
            f"but the first-ranked ΔBIC spread to {f2[0]:.0f} to {f2[-1]:.0f} (against {f1[0]:.0f} to {f1[-1]:.0f}): "
            "each draw's extreme now comes from one candidate whose own re-solved baseline fits the relative gap "
            "worse, not from all alike. A per-candidate baseline moves the tail, it does not remove it; it is not "
            "adopted."]


#: ``benchmarks/gap_reference_basin.py``'s result, under the validation's folder.
REFERENCE_BASIN_FILE = "reference_basin.json"


def stored_reference_basin() -> dict | None:
    """``benchmarks/gap_reference_basin.py``'s result (:func:`stored_experiment`): an
    experiment on the stored validation it names (``"validation"``: the superseded
    ``relative_rev1``, whose false name it explains and which the self-consistent reference
    fit of revision 2 answers), refused if made under another relative method than that
    validation's."""
    r = stored_experiment(f"gap_validation/{REFERENCE_BASIN_FILE}", "gap_reference_basin.py")
    if r is None:
        return r
    name = r.get("validation", "relative")
    v = superseded_validation(name) if name in SUPERSEDED_VALIDATIONS else stored_validation(name)
    if r.get("relative_method_hash") != v.settings.get("relative_method_hash"):
        raise RuntimeError(f"{REFERENCE_BASIN_FILE}: made under relative method {r.get('relative_method_hash')}, the "
                           f"validation {name} under {v.settings.get('relative_method_hash')}: rerun "
                           f"benchmarks/gap_reference_basin.py")
    return r


def reference_basin_lines(res: dict, tol: float = 1e-6) -> list[str]:
    """``benchmarks/gap_reference_basin.py``'s result in a sentence computed from it."""
    cs = res["cases"]
    low = [c for c in cs if c["objective_reference_from_data"] < c["objective_reference"] * (1.0 - tol)]
    if not low:
        return [f"Re-solving the reference from the data's continuation fit never reached a lower objective than the "
                f"reference's kept fit ({len(cs)} null draws): the continuation stayed in its basin."]
    return [f"**Why a null draw can be named.** Re-solving the reference from the data's continuation fit reached a "
            f"lower objective than the reference's kept fit (best of its starts, objective "
            f"{cs[0]['objective_reference']:.4f}) in {len(low)} of {len(cs)} null draws ("
            + "; ".join(f"{c['case']}: {c['objective_reference_from_data']:.4f}, named {c['named']}" for c in low)
            + "): the reference's kept fit is not the best basin within reach, and the data's continuation can move "
              "to another one — the relative gap then carries a change of the fit, not of the data, which a "
              "candidate that stays put is credited with closing (`benchmarks/gap_reference_basin.py`)."]


#: ``benchmarks/gap_baseline_basin.py``'s result, under the validation's folder.
BASELINE_BASIN_FILE = "baseline_basin.json"


def stored_baseline_basin() -> dict | None:
    """``benchmarks/gap_baseline_basin.py``'s result (:func:`stored_experiment`): an
    experiment on the superseded validation it names (``relative_rev3``), refused if made
    under another relative method than that validation's."""
    r = stored_experiment(f"gap_validation/{BASELINE_BASIN_FILE}", "gap_baseline_basin.py")
    if r is None:
        return r
    v = superseded_validation(r["validation"])
    if r.get("relative_method_hash") != v.settings.get("relative_method_hash"):
        raise RuntimeError(f"{BASELINE_BASIN_FILE}: made under relative method {r.get('relative_method_hash')}, the "
                           f"validation {r['validation']} under {v.settings.get('relative_method_hash')}: rerun "
                           f"benchmarks/gap_baseline_basin.py")
    return r


def baseline_basin_lines(res: dict) -> list[str]:
    """``benchmarks/gap_baseline_basin.py``'s result in a sentence computed from it: per null
    draw, the first-ranked ΔBIC and the % closed by the ranked candidates as run and with the
    baseline re-fitted from the candidates' fits, and the baseline's worst channel."""
    bits = []
    for c in res["cases"]:
        a, b = c["as_run"], c["from_candidates"]
        bits.append(f"{c['case']}: {a['rank1']} {a['rank1_dBIC']:.0f}, the {a['ranked']} ranked candidates closing "
                    f"{a['pct_closed_min']:.0f}–{a['pct_closed_max']:.0f} % (the baseline's {a['worst_channel']} "
                    f"{a['worst_rss_baseline']:.2f} against the candidates' median {a['worst_rss_candidates_median']:.2f})"
                    f" → {b['rank1']} {b['rank1_dBIC']:.0f}, {b['pct_closed_min']:.0f}–{b['pct_closed_max']:.0f} % "
                    + (f"(baseline from {b['baseline_from']})" if b["baseline_from"] else "(baseline unchanged)"))
    moved = sum(1 for c in res["cases"] if c["from_candidates"]["baseline_from"])
    rev = SUPERSEDED_VALIDATIONS.get(res.get("validation"), "?")
    return [f"**Why revision {rev}'s null draws reached so far.** Re-diagnosed without the calibration "
            f"(`benchmarks/gap_baseline_basin.py`), as run → with the baseline's fit of the draw re-solved from every "
            f"nested candidate's fit (first-ranked ΔBIC, % closed by the ranked candidates): " + "; ".join(bits)
            + f". The re-fit found a lower baseline in {moved} of {len(res['cases'])} draws: where the baseline's "
              "relative RSS on one channel is many times the candidates' median, its continuation had stopped in a "
              "worse optimum than its own extensions reach, and every candidate that reached a better one was "
              "credited with the difference."]


def stored_null_refit() -> dict | None:
    """``benchmarks/gap_null_refit.py``'s result (:func:`stored_experiment`)."""
    return stored_experiment(f"gap_validation/{NULL_REFIT_FILE}", "gap_null_refit.py")


def normative_start_lines(res: dict) -> list[str]:
    """``benchmarks/gap_normative_start.py``'s result in a sentence computed from it."""
    c = res["cases"]
    right = {k: sum(x[k]["named"] == x["expected"] for x in c) for k in ("without", "with")}
    better = [x for x in c if x["with"]["start"] == "warm" and x["with"]["objective"] < x["without"]["objective"]]
    changed = [x for x in c if x["with"]["named"] != x["without"]["named"]]
    return [f"**The baseline from the unedited data's fit.** Given the fit of the unedited data as one more start "
            f"(the most favourable start a baseline could get: the data differ by the injection only), the "
            f"{len(c)} independent injections at middle and large magnitudes are named right in {right['with']} "
            f"(without it: {right['without']}); the kept baseline came from that start, with a lower objective, in "
            f"{len(better)}" + (" (" + "; ".join(f"{x['injection']} {x['band']}: RSS {x['without']['rss_baseline']:.0f} "
                                                 f"→ {x['with']['rss_baseline']:.0f}" for x in better) + ")" if better else "")
            + f"; the named effect changed in {len(changed)}" + (" (" + "; ".join(
                f"{x['injection']} {x['band']}: {x['without']['named']} → {x['with']['named']}" for x in changed) + ")"
                if changed else "") + " (`benchmarks/gap_normative_start.py`)."]


def pair_test_lines(res: dict) -> list[str]:
    """``benchmarks/gap_pair_test.py``'s result in sentences computed from it."""
    c = res["cases"]
    done = [x for x in c if "rule_names" in x]
    passed = [x for x in done if x["cond_top"] <= res["threshold"]]
    both = [x for x in passed if x["cond_second"] <= res["threshold"]]
    out = [f"**The top effect given the runner-up.** In {len(c)} cases (the unedited data and the manipulations) the "
           f"top effect passed the threshold ({res['threshold']:g}) but not the runner-up margin ({res['margin']:g}); "
           f"the pair of effects fitted together converged in {len(done)}. The top effect's ΔBIC given the runner-up "
           f"still passed the threshold in {len(passed)} of them (both effects given the other in {len(both)}: two "
           f"causes rather than one gap absorbed twice)."]
    if done:
        out.append(f"A rule naming the top effect whenever its ΔBIC given the runner-up passes would be right in "
                   f"{sum(x['rule_right'] for x in done)} of these {len(done)} cases, the method in "
                   f"{sum(x['method_right'] for x in done)}: " + "; ".join(
                       f"{x['case']} ({x['top']} | {x['second']} {x['cond_top']:.1f}; would name {x['rule_names']}, "
                       f"expected {x['expected']})" for x in done) + " (`benchmarks/gap_pair_test.py`; not part of "
                   f"the method).")
    return out


def null_refit_lines(refit: dict, top: int = 4) -> list[str]:
    """The refit experiment (:func:`stored_null_refit`) in sentences computed from it: how
    often a top candidate's solution gave a better baseline, the verdicts before and after,
    and the candidates' ΔBIC spread between the draws before and after."""
    cases = refit["cases"]
    draws = [k for k in cases if k != "unedited"]
    better = [k for k, c in cases.items() if c["source"] != "kept"]
    drops = [100.0 * (1 - cases[k]["rss1"] / cases[k]["rss0"]) for k in better]
    sd = {}
    for when in ("0", "1"):
        df = pd.DataFrame({k: cases[k][f"dBIC{when}"] for k in draws})
        sd[when] = pd.DataFrame({"mean": df.mean(axis=1), "sd": df.std(axis=1)})
    lead = list(dict.fromkeys(list(sd["0"].sort_values("mean").index[:top]) + list(sd["1"].sort_values("mean").index[:top])))
    changed = [f"{k}: {c['named0']} → {c['named1']}" for k, c in cases.items() if c["named0"] != c["named1"]]
    named = {w: sum(cases[k][f"named{w}"] != "unexplained" for k in draws) for w in ("0", "1")}
    worst = sd["1"]["sd"].idxmax()
    return [f"**Is the spread the baseline's local optimum?** An experiment outside the frozen method "
            f"(`benchmarks/gap_null_refit.py`): the baseline re-fitted from each of the top {refit['top']} candidates' "
            f"solutions (their effect parameters dropped), and, where that gave a lower objective, every candidate "
            f"re-fitted from the new baseline and ranked again. A better baseline was found in {len(better)} of "
            f"{len(cases)} cases"
            + (f" (RSS lower by {min(drops):.1f}–{max(drops):.1f} %)" if drops else "")
            + f"; verdicts changed in {len(changed)}" + (f" ({'; '.join(changed)})" if changed else "")
            + f", and an effect was named in {named['1']} of {len(draws)} draws after against {named['0']} before. "
            "The candidates' ΔBIC SD between the draws, before → after: "
            + "; ".join(f"{e} {sd['0'].loc[e, 'sd']:.1f} → {sd['1'].loc[e, 'sd']:.1f}" for e in lead
                        if e in sd["0"].index and e in sd["1"].index)
            + f". One round of re-fitting moves which candidate looks best but does not steady the ranking (the "
              f"largest SD after it: {worst}, {sd['1'].loc[worst, 'sd']:.1f}, against a runner-up margin of "
              f"{gap_method.RUNNER_UP_MARGIN:g}): a change of the data within its sampling error still moves the "
              "candidates' ΔBIC by more than the method's margins."]


def mesh_table(diags: dict, index: str = "mesh") -> pd.DataFrame:
    """The same data diagnosed on several meshes (``diags``: mesh label → Diagnosis; or
    other variants, named by ``index``): the baseline's status, RMS z and significant cells,
    the verdict, the top effect and the best converged candidate with its ΔBIC and % closed
    (:func:`summary`)."""
    rows = []
    for lab, d in diags.items():
        s = summary(d)
        rows.append({index: lab, "baseline": s["baseline_status"], "RMS z": s["rms_z"],
                     "significant cells": f"{s['significant_cells']} of {s['cells']}", "verdict": s["verdict"],
                     "top effect": s["top"] or "—", "best candidate": s["best"] or "—",
                     "its ΔBIC": s["best_dBIC"], "its % closed": s["best_pct"]})
    return pd.DataFrame(rows).set_index(index)


def mesh_verdict(table: pd.DataFrame, threshold: float, null: gval.Validation | None = None) -> str:
    """One sentence: whether the verdict on the real data depends on the mesh
    (:func:`mesh_table`), with the numbers; ``threshold``: the ΔBIC naming threshold;
    ``null``: the null draws (:func:`gaitlib.gap.validate.null_spread`, 10 × 3), whose
    verdict changes measure how stable a verdict is at one mesh."""
    verdicts = {f"{v} ({t})" if t != "—" else v for v, t in zip(table["verdict"], table["top effect"])}
    parts = "; ".join(f"{m}: {r['verdict']}" + (f", top {r['top effect']}" if r["top effect"] != "—" else "")
                      + (f", best candidate {r['best candidate']} at ΔBIC {r['its ΔBIC']:.1f}" if r["best candidate"] != "—" else "")
                      for m, r in table.iterrows())
    if len(verdicts) == 1:
        return f"**The real-data verdict does not depend on the mesh** ({parts}; naming threshold ΔBIC ≤ {threshold:g})."
    head = (f"**The real-data verdict depends on the mesh** ({parts}; naming threshold ΔBIC ≤ {threshold:g}): "
            "a user running `gaitlib gap` at its default coarse mesh would read another verdict than this "
            "chapter's.")
    if null is None:
        return head + " The cause of the difference is not measured here."
    sp = gval.null_spread(null)
    top = sp["candidates"].head(4)
    return (head + f" The verdict is not stable at one mesh either: on the 10 × 3 mesh, redrawing the data's means "
            f"within their sampling error changed it in {sp['draws'] - sp['same_verdict']} of {sp['draws']} draws, "
            f"and the leading candidates' ΔBIC moved with an SD of {top['sd'].min():.1f}–{top['sd'].max():.1f} between "
            f"draws, against a naming threshold and runner-up margin of {abs(threshold):g} and "
            f"{gap_method.RUNNER_UP_MARGIN:g}. A change of mesh is a change of that size; whether the 20 × 5 verdict is "
            "steadier is not measured (its draws would cost ≈ 10× as much).")


def path_verdict(table: pd.DataFrame, pairs: list, threshold: float) -> str:
    """Whether the real-data verdict survives a change of the NLP derivative path alone
    (``pairs``: (label on one path, label on the other) rows of a :func:`mesh_table` with
    ``index="run"``, each pair the same mesh): the same problem, derivatives equal to
    round-off (tests/test_node_derivatives.py), so a different verdict is a different local
    optimum of the fits, not a different model."""
    def word(r):
        return r["verdict"] + (f" ({r['top effect']})" if r["top effect"] != "—" else "") + (
            f", best candidate {r['best candidate']} at ΔBIC {r['its ΔBIC']:.1f}" if r["best candidate"] != "—" else "")

    same, parts = [], []
    for a, b in pairs:
        ra, rb = table.loc[a], table.loc[b]
        same.append((ra["verdict"], ra["top effect"]) == (rb["verdict"], rb["top effect"]))
        parts.append(f"{a}: {word(ra)}; {b}: {word(rb)}")
    head = ("**The real-data verdict survives the change of derivative path**" if all(same) else
            "**The real-data verdict changes with the derivative path alone**")
    tail = ("" if all(same) else
            " The two paths differ by round-off in the derivatives only; the fits end in different local "
            "optima, so the ranking of close candidates is not a property of the data alone. A verdict that "
            "flips under round-off should not be read as a diagnosis.")
    return f"{head} (naming threshold ΔBIC ≤ {threshold:g}) — " + " | ".join(parts) + "." + tail


def profile_table(diag: diagnose.Diagnosis, effect: str, stems=("emg_TA", "emg_MG", "emg_RF", "emg_LH")) -> pd.DataFrame:
    """Every profile point of a profiled effect (``identify="profile"``) of ``diag``: its
    magnitude, IPOPT status and iterations, the whole gap's RSS and the EMG channels' RSS
    and mean z — the solutions reloaded from the cache (:func:`gaitlib.gap.solve.solve_on`
    with the same warm start; nothing is solved if :func:`nmsk_attribution` ran)."""
    f = diag.fits[effect]
    rows = [{"magnitude": 0.0, "status": diag.baseline.stats["status"], "iterations": diag.baseline.stats.get("iterations"),
             "RSS (all)": diag.located.rss, **_emg_cols(diag.located, stems)}]
    for m, _, _ in f.profile:
        spec = diagnose.with_effects(diag.spec, ((effect, m),))
        sol = solve_on(spec, diag.data.gait, diag.baseline, objective=diag.objective)
        loc = locate.locate(sol, diag.data, thetas=sol.stats.get("effects"))
        rows.append({"magnitude": m, "status": sol.stats["status"], "iterations": sol.stats.get("iterations"),
                     "RSS (all)": loc.rss, **_emg_cols(loc, stems)})
    return pd.DataFrame(rows)


def _emg_cols(loc: locate.Located, stems) -> dict:
    r = _emg_rss(loc, stems)
    out = {f"RSS {s[4:]}": r[s] for s in stems}
    m = loc.points.groupby("channel")["z"].mean()
    for s in ("emg_TA", "emg_MG"):
        v = [m[c] for c in m.index if c.startswith(f"emg:{s[4:]}_")]
        out[f"mean z {s[4:]}"] = float(np.mean(v)) if v else np.nan
    return out


def exact_left_leg(gait, order: int | None = None):
    """``gait`` with every left-leg channel that was generated from the right one by the
    Fourier fit (:func:`gaitlib.data.fourier_shift`, thesis Eqs 4.1–4.3, order ``order``,
    default the loader's) replaced by the right leg shifted **exactly** — periodic linear
    interpolation of the right leg's mean and SD at τ + ``left_shift`` on the data's own
    grid, with no smoothing. Left channels that are the source's own (gaitutils EMG) and the
    planned metatarsal trajectory are kept.

    Returns ``(gait_exact, replaced)``: a new GaitData and the replaced column names.
    """
    order = effects_mod.FOURIER_ORDER if order is None else order
    tau = gait.time / float(gait.cycle_time)
    shift = float(gait.left_shift)
    mean, sd, replaced = gait.mean.copy(), gait.sd.copy(), []
    for c in gait.channels:
        if not c.endswith("_l") or c.startswith("mtp_") or f"{c[:-2]}_r" not in gait.mean.columns:
            continue
        r = c[:-2] + "_r"
        xr = gait.mean[r].to_numpy(float)
        if not np.allclose(gait.mean[c].to_numpy(float), data_mod.fourier_shift(xr, shift, order), atol=1e-9):
            continue  # not generated by the Fourier fit (the source's own left leg)
        src = np.mod(tau + shift, 1.0)
        mean[c] = np.interp(src, tau, xr)
        sd[c] = np.interp(src, tau, gait.sd[r].to_numpy(float))
        replaced.append(c)
    note = f"left leg = right leg shifted exactly by {shift:.3f} of the cycle (no Fourier fit): {len(replaced)} channels"
    return replace(gait, mean=mean, sd=sd, notes=tuple(gait.notes) + (note,)), replaced


def left_leg_check(diag: diagnose.Diagnosis) -> dict:
    """How much of ``diag``'s located gap is the left leg's generation rather than the model.

    The data's left leg is the right leg phase-shifted through a 5th-order Fourier fit
    (thesis Eqs 4.1–4.3; :func:`gaitlib.data.load_gait_data`). Such a fit cannot follow a
    GRF that is zero for 40 % of the cycle: it rings (± a few N) where the foot is in the
    air. Here the same solutions — nothing is re-solved — are located against the data with
    the left leg shifted exactly (:func:`exact_left_leg`):

    ``generation``  the Fourier-generated left leg itself located against the exact shift
                    (per channel: RSS, RMS z, significant) — the data pipeline's own gap;
    ``cells``       per channel × phase, RMS z of the baseline against the data as tracked
                    and against the exact shift;
    ``ranking``     each candidate's RSS and % closed against both;
    ``rss``         the baseline's RSS against both; ``replaced`` the replaced columns.
    """
    ds = diag.data
    gait_x, replaced = exact_left_leg(ds.gait)
    ds_x = replace(ds, gait=gait_x)
    loc_x = locate.locate(diag.baseline, ds_x)
    view = gait_ocp.tracking_data(ds.gait)
    gen_sim = view.mean.set_axis(pd.Index(view.time / float(view.cycle_time), name="tau"), axis=0)
    gen = locate.locate(gen_sim, ds_x)
    g = gen.channels[gen.channels["side"] == "l"][["channel", "rss", "rms_z", "significant"]]
    cells = diag.located.table[["channel", "phase", "rms_z", "significant"]].merge(
        loc_x.table[["channel", "phase", "rms_z", "significant"]], on=["channel", "phase"],
        suffixes=(" (data as tracked)", " (left leg shifted exactly)"))
    rows = []
    for n, f in diag.fits.items():
        if f.located is None or f.solution is None:
            continue
        # data-model effects (left_shift) read the data differently: adjust, then shift exactly
        gait_f = effects_mod.adjust_data(ds.gait, f.thetas) if f.thetas else ds.gait
        lx = locate.locate(f.solution, replace(ds, gait=exact_left_leg(gait_f)[0]))
        rows.append({"effect": n, "status": f.status,
                     "RSS (data as tracked)": f.located.rss,
                     "% closed (data as tracked)": 100 * (1 - f.located.rss / diag.located.rss),
                     "RSS (left leg shifted exactly)": lx.rss,
                     "% closed (left leg shifted exactly)": 100 * (1 - lx.rss / loc_x.rss)})
    ranking = pd.DataFrame(rows)
    if len(ranking):
        ranking = ranking.sort_values("% closed (left leg shifted exactly)", ascending=False).reset_index(drop=True)
    return {"replaced": replaced, "generation": g.reset_index(drop=True), "cells": cells, "ranking": ranking,
            "located_exact": loc_x, "rss": {"data as tracked": diag.located.rss, "left leg shifted exactly": loc_x.rss}}


def _rms(ch: pd.DataFrame) -> float:
    n = float(ch["n"].sum())
    return float(np.sqrt(ch["rss"].sum() / n)) if n else np.nan


def book_gaps(root=None) -> pd.DataFrame:
    """The located gap of the book's own Ch 5–7 solutions (nothing is re-solved: every
    solution is reloaded through its study function).

    Ch 5: the MSK and NMSK data-tracking solutions in the book's and in the thesis's reading
    (:data:`gaitlib.studies.gait.READINGS`); Ch 6: the 16 cost-function runs and Ch 7: the 8
    speed runs (both in the book's reading) — each located against **its own speed class's data** (Schwartz 2008),
    which Ch 7 never tracked (it tracks the Free data scaled in time). One row per solution:
    chapter, model, case (cost function or class), mark (:func:`gaitlib.marks.failure_label`),
    IPOPT status, RMS z of the angles, torques
    and GRFs (against the data as tracked and with the left leg shifted exactly,
    :func:`exact_left_leg`), RMS z of the EMG channels (muscle models), the number of
    significant channel × phase cells (non-EMG) and the largest such cell.
    """
    items = [("Ch 5", m, ("DT (Eq 5.33)" if m == "MSK" else "DT (Eq 5.55)") + f", {reading}'s reading",
              msk.solve(m, root=root, reading=reading)) for reading in ("book", "thesis") for m in ("MSK", "NMSK")]
    r6 = pr.cost_function_study(("MSK", "NMSK"), pr.CH6_COSTS, progress=False, root=root, reading="book")
    items += [("Ch 6", r6.specs[k].model, r6.specs[k].cost, s) for k, s in r6.solutions.items()]
    r7 = pr.speed_study(("MSK", "NMSK"), pr.CH7_CLASSES, progress=False, root=root, reading="book")
    items += [("Ch 7", r7.specs[k].model, r7.specs[k].speed_class, s) for k, s in r7.solutions.items()]
    data, rows = {}, []
    for chapter, model, case, sol in items:
        cls = sol.spec.speed_class
        if cls not in data:
            ds = gio.load_real(cls, "schwartz2008")
            data[cls] = (ds, replace(ds, gait=exact_left_leg(ds.gait)[0]))
        ds, ds_x = data[cls]
        loc, loc_x = locate.locate(sol, ds), locate.locate(sol, ds_x)
        ch, chx = loc.channels, loc_x.channels
        t = loc.table[loc.table["kind"] != "emg"]
        top = t.sort_values("rms_z", ascending=False).iloc[0]
        rows.append({"chapter": chapter, "model": model, "case": case, "speed class (data)": cls,
                     "mark": failure_label(sol) or "", "status": sol.stats["status"],
                     "RMS z, angles/torques/GRFs": _rms(ch[ch["kind"] != "emg"]),
                     "RMS z, same, left leg shifted exactly": _rms(chx[chx["kind"] != "emg"]),
                     "RMS z, EMG": _rms(ch[ch["kind"] == "emg"]),
                     "significant cells (non-EMG)": int(t["significant"].sum()), "cells (non-EMG)": int(len(t)),
                     "largest cell": f"{top['channel']} {top['phase']}", "its RMS z": float(top["rms_z"])})
    return pd.DataFrame(rows)


def twin_validation_full_mesh(seeds=TWIN_SEEDS, serial: bool = True):
    """The twin check repeated on the thesis's 20 × 5 mesh (:data:`SK_BASE`, the mesh of the
    real-data diagnoses): every SK twin effect at its **middle** magnitude and the
    effect-free twin, for each noise seed. Rows are labelled with the middle level (``level`` 1,
    twin names ``effect@1#seed``) so that :meth:`TwinValidation.accuracy` reads "middle"."""
    effects = tuple(twin.TWIN_EFFECTS_DEFAULT())
    mags = {e: (effects_mod.EFFECTS[e].twin_magnitudes[1],) for e in effects}
    tv = twin.validate_twins(effects, magnitudes=mags, seeds=tuple(seeds), base=dict(SK_BASE), serial=serial,
                             progress=False)
    inj = tv.rows["injected"] != "none"
    tv.rows.loc[inj, "level"] = 1
    tv.rows.loc[inj, "twin"] = tv.rows.loc[inj, "twin"].str.replace("@0#", "@1#", regex=False)
    return tv


# --------------------------------------------------------------------------------------
# The chapter's text: every number and verdict from the results
# --------------------------------------------------------------------------------------


def twin_full_mesh_lines(tv) -> list[str]:
    """The 20 × 5 twin check (:func:`twin_validation_full_mesh`) in one line, then one line
    per misnamed twin: what was named and the RSS of the fits that explain why."""
    s = tv.summary()
    by_seed = ", ".join(f"seed {k}: {v:.0f} %" for k, v in s["top1_by_seed"].items())
    out = [f"20 × 5 mesh, middle magnitude: top-1 accuracy {s['top1_pct']:.0f} % ({s['correct']} of {s['injected']}; "
           f"{by_seed}); mean shrink of the injected gap (capped at 100 %) {s['shrink_pct']:.0f} % "
           f"({s['shrink_defined']} defined), against the noise floor {s['shrink_vs_noise_pct']:.0f} %; effect-free "
           f"twin named 'unexplained': {s['free_unexplained']} of {s['free_twins']}; twin generation "
           f"{s['gen_converged']} of {s['gen_total']} converged"]
    for r in tv.misses().itertuples():
        if r.injected == "none":
            out.append(f"{r.twin}: named {r.top} (ΔBIC {r.dBIC_top:.1f}) on a baseline fit with RSS {r.rss_base:.1f}, "
                       f"{r.rss_base / r.rss_gen:.1f}× the generating solution's own RSS on its twin")
        else:
            out.append(f"{r.twin}: named {r.top}; the injected effect's own candidate fit reaches RSS {r.rss_true:.1f} "
                       f"(ΔBIC {r.dBIC_true:+.1f}), the true model with its magnitude fixed {r.rss_true_fixed:.1f}, "
                       f"against the baseline's {r.rss_base:.1f} (start: {r.base_start}) and the generating "
                       f"solution's {r.rss_gen:.1f}")
    return out


def twin_full_mesh_verdict(tv) -> list[str]:
    """Paragraphs on the 20 × 5 twin check: which starts the kept fits came from, whether
    the check is passed (targets :data:`gaitlib.gap.twin.TARGET_TOP1_PCT` and
    :data:`~gaitlib.gap.twin.TARGET_SHRINK_PCT`, every effect-free twin 'unexplained'),
    and why each injected twin was missed."""
    s = tv.summary()
    out = [f"Baseline fits kept, by start: {', '.join(f'{k} {v}' for k, v in s['base_starts'].items())}. "
           f"Twins with at least one candidate re-solved from another start: {s['retried_twins']} of {s['twins']} "
           f"({s['retried_fits']} candidate fits); the injected effect's kept fit came from another start "
           f"than the baseline fit in {s['true_other_start']} of {s['injected']} twins."]
    if s["passed"]:
        out.append(f"On the 20 × 5 mesh the check **is passed**: {s['top1_pct']:.0f} % top-1 at the middle magnitude "
                   f"(target ≥ {twin.TARGET_TOP1_PCT:.0f} %), {s['shrink_pct']:.0f} % mean shrink (target ≥ "
                   f"{twin.TARGET_SHRINK_PCT:.0f} %), every effect-free twin 'unexplained'.")
    else:
        out.append(f"On the 20 × 5 mesh the check is **not passed** ({s['top1_pct']:.0f} % top-1 at the middle "
                   f"magnitude, target ≥ {twin.TARGET_TOP1_PCT:.0f} %; {s['shrink_pct']:.0f} % mean shrink, target ≥ "
                   f"{twin.TARGET_SHRINK_PCT:.0f} %; effect-free twins 'unexplained' {s['free_unexplained']} of "
                   f"{s['free_twins']}); the real-data results of Sec. 4 are on 20 × 5 and carry this caveat.")
    for r in tv.misses().itertuples():
        if r.injected != "none":
            why = ("its own candidate fit ends above the baseline's even after the retry" if r.fit_failed else
                   "its own fit closes less of the gap, by the criterion, than the named effect's")
            out.append(f"The miss {r.twin} (named {r.top}): {why} (RSS {r.rss_true:.1f} against the baseline's "
                       f"{r.rss_base:.1f}; the true model with its magnitude fixed {r.rss_true_fixed:.1f}).")
    return out


def _diagnosis_text(s: dict, full: bool) -> str:
    """What a diagnosis (``s`` = :func:`summary`) names, or that it names nothing."""
    if s["top"] != "unexplained":
        if full:
            return (f"The diagnosis names **{s['top']}** ({s['verdict']}): it closes {s['best_pct']:.0f} % of the RSS "
                    f"(95 % interval {s['interval'][0]:.0f}–{s['interval'][1]:.0f} %, ΔBIC = {s['best_dBIC']:.1f}).")
        return (f"the diagnosis names **{s['top']}** ({s['verdict']}, {s['best_pct']:.0f} % closed, "
                f"interval {s['interval'][0]:.0f}–{s['interval'][1]:.0f} %).")
    what = f"best {s['best']}, {s['best_pct']:.0f} % closed, ΔBIC = {s['best_dBIC']:.1f}; threshold {diagnose.BIC_THRESHOLD:g}"
    if s.get("held_by_share_floor"):  # a relative diagnosis's share floor (revision 9 on)
        if s.get("centred") and s.get("share_closed") is not None:  # revision 10 on
            why = (f"{s['best']} passes the threshold but closes {s['share_closed']:.0f} % of what the median candidate "
                   f"leaves of the gap, less than the {s['min_share_closed']:g} % a named effect must close")
        else:
            why = (f"{s['best']} passes the threshold but closes less than the {s['min_share_closed']:g} % of the gap "
                   "a named effect must close")
        return (f"No candidate explains enough of the change: **unexplained** ({what}; {why})." if full
                else f"**unexplained** ({what}; {why}).")
    if len(s.get("contenders", [])) > 1:  # passes the threshold, but does not stand out
        others = ", ".join(s["contenders"][1:])
        why = (f"{s['best']} passes the threshold but not the out-of-library test: {others} "
               f"{'is' if len(s['contenders']) == 2 else 'are'} within the runner-up margin of "
               f"{gap_method.RUNNER_UP_MARGIN:g} (second {s.get('second')} at ΔBIC {s.get('second_dBIC', np.nan):.1f})")
        return (f"No candidate stands out: **unexplained** ({what}; {why})." if full
                else f"**unexplained** ({what}; {why}).")
    return (f"No candidate passes the criterion: **unexplained** ({what})." if full else f"**unexplained** ({what}).")


def left_leg_flips(check: dict, min_closed: float = 5.0) -> list[str]:
    """Candidates of a :func:`left_leg_check` that close at least ``min_closed`` % of the gap
    as tracked but nothing (≤ 0 %) against the exactly shifted left leg: they were fitting
    the generated left leg."""
    r = check["ranking"]
    if not len(r):
        return []
    return list(r[(r["% closed (data as tracked)"] >= min_closed) & (r["% closed (left leg shifted exactly)"] <= 0)]["effect"])


def _left_line(lab: str, c: dict) -> str:
    r = c["ranking"]
    top_x, top_t = r.iloc[0], r.sort_values("% closed (data as tracked)", ascending=False).iloc[0]
    gen_share = 100 * (1 - c["rss"]["left leg shifted exactly"] / c["rss"]["data as tracked"])
    return (f"{lab}: against the exactly shifted left leg the baseline's RSS is "
            f"{c['rss']['left leg shifted exactly']:.0f} instead of {c['rss']['data as tracked']:.0f} "
            f"({'−' if gen_share > 0 else '+'}{abs(gen_share):.0f} %); the best candidate fit is then "
            f"{top_x['effect']} ({top_x['% closed (left leg shifted exactly)']:.0f} % closed), against "
            f"{top_t['effect']} ({top_t['% closed (data as tracked)']:.0f} %) on the data as tracked")


def findings(tv, tv_full, diag_s: diagnose.Diagnosis, diag_u: diagnose.Diagnosis, diag_n: diagnose.Diagnosis, check_s: dict,
             check_u: dict, gaps: pd.DataFrame, emg: pd.DataFrame, val: gval.Validation | None = None,
             valv: gval.Validation | None = None, diag_m: diagnose.Diagnosis | None = None,
             profile_m: pd.DataFrame | None = None, valn: gval.Validation | None = None, tv_muscle=None,
             valr: gval.Validation | None = None, valr_reps: dict | None = None,
             load_confusion: dict | None = None, quiet_pair: tuple | None = None,
             null_tail: dict | None = None, valr_now_reps: dict | None = None, common_mode: dict | None = None,
             ref_pair: tuple | None = None, baseline_pair: dict | None = None,
             candidate_baseline: dict | None = None, pair_rev8: tuple | None = None,
             current_reps: dict | list | None = None, floor_reps: dict | None = None,
             centred_reps: dict | None = None) -> list[str]:
    """The chapter's findings as Markdown paragraphs, every number and verdict from the
    results: the twin checks (``tv`` on the coarse mesh, :func:`twin_validation`;
    ``tv_full`` on 20 × 5, :func:`twin_validation_full_mesh`), the SK diagnoses of Schwartz
    2008 (``diag_s``) and gaitutils (``diag_u``) with their :func:`left_leg_check`, the
    book's own solutions (:func:`book_gaps`) and the NMSK attribution (``diag_n``,
    :func:`nmsk_attribution`, with its :func:`emg_gap_table` ``emg``) and, if given, the
    validation on manipulated real data (``val``) and on model-variant twins (``valv``), both
    :func:`stored_validation`, and the library's candidates on the Ch 5 MSK solution
    (``diag_m``, :func:`ch5_attribution`, with its top effect profiled beyond the grid,
    ``profile_m``, :func:`ch5_profile`); ``valn``: the null draws (why the manipulated data's
    injections are or are not named, :func:`null_lines`); ``valr``: the same manipulations
    diagnosed relative to the unedited data (:func:`relative_lines`, with the two threshold
    rules on its cases, :func:`rule_table`), ``valr_reps`` an earlier revision's replicates on
    other draws (label → validation, :func:`replicate_lines`, with what a fixed threshold
    gives on them, :func:`threshold_lines`); ``load_confusion``: why the load family holds
    that ceiling (:func:`load_confusion_lines`); ``quiet_pair``: (revision 5's validation, the
    same draws with the quiet points left out or None, :func:`paired_lines`); ``null_tail``:
    relative validations of the same fits and ranking (:func:`null_tail_lines`);
    ``valr_now_reps``: the previous revision's replicates (label → validation,
    :func:`replicate_lines`, :func:`threshold_lines`); ``common_mode``: relative validations
    whose calibration draws are split by common mode (:func:`common_mode_lines`);
    ``ref_pair``: (revision 6's validation, its draws with the baseline's fit of the reference
    from the candidates' or None, :func:`paired_lines`); ``baseline_pair``:
    ``benchmarks/gap_baseline_pair.py``'s result (:func:`baseline_pair_lines`);
    ``candidate_baseline``: ``benchmarks/gap_candidate_baseline.py``'s
    (:func:`candidate_baseline_lines`);
    ``pair_rev8``: (revision 7's validation, its draws with revision 8's fallback and lower
    located pair or None, :func:`paired_lines`);
    ``current_reps``: the latest revision's replicates (label → validation, or a list of such,
    one per revision,
    :func:`replicate_lines`, :func:`threshold_lines`; "the method in use" when they are
    :data:`gaitlib.gap.method.RELATIVE`'s); ``floor_reps``: the earlier revision's replicates
    the share floor :attr:`gaitlib.gap.method.RelativeMethod.min_share_closed` was chosen on
    (:func:`share_floor_lines` at that floor); ``centred_reps``: the earlier revisions'
    validations the centred statistic (:attr:`gaitlib.gap.method.RelativeMethod.centred`) is
    replayed on (:func:`centred_lines`, at the method's share floor);
    ``tv_muscle``: the muscle-level twins (:func:`muscle_twin_validation`)."""
    s, sf = tv.summary(), tv_full.summary()
    acc = tv.accuracy()
    sS, sU = summary(diag_s), summary(diag_u)
    top1 = top_cells(diag_s.located, 1).iloc[0]
    met = {True: "met", False: "not met"}
    out = [
        f"**Twins.** Over {s['twins']} twins ({s['twins'] - s['free_twins']} with an injected effect), the diagnosis "
        f"named the injected effect in {s['top1_pct']:.0f} % of the middle-magnitude twins "
        f"({', '.join(f'{k}: {v:.0f} %' for k, v in acc['top-1 accuracy (%)'].items())} by magnitude) — the target of "
        f"{twin.TARGET_TOP1_PCT:.0f} % is {met[s['top1_met']]} — and said 'unexplained' for {s['free_unexplained']} of "
        f"{s['free_twins']} effect-free twins. The named effects closed on average {s['shrink_pct']:.0f} % of the "
        f"injected gap (against the true model fitted the same way, each twin capped at 100 %, {s['shrink_defined']} "
        f"twins; target {twin.TARGET_SHRINK_PCT:.0f} %: {met[s['shrink_met']]}; median {s['shrink_median_pct']:.0f} %), "
        f"but only {s['shrink_vs_noise_pct']:.0f} % of the gap down to the noise floor, which also counts the coarse "
        f"mesh's own residual: on the 10 × 3 mesh the true model itself does not reach the noise.",
        f"**Twins on the thesis's 20 × 5 mesh** (middle magnitude, two seeds): top-1 accuracy {sf['top1_pct']:.0f} % — "
        f"the {twin.TARGET_TOP1_PCT:.0f} % target is {'met' if sf['top1_met'] else '**not met** on this mesh'} — "
        f"effect-free twin 'unexplained' {sf['free_unexplained']} of {sf['free_twins']}, mean shrink of the injected "
        f"gap {sf['shrink_pct']:.0f} % (capped), {sf['shrink_vs_noise_pct']:.0f} % against the noise floor. "
        + ("The method is validated on both meshes, including the one of the real-data diagnoses below."
           if sf["passed"] else
           "The validated configuration is the 10 × 3 mesh; on 20 × 5 the fits, not the criterion, limit the "
           "diagnosis, and the real-data findings below carry that caveat."),
        f"**Schwartz 2008 Free.** The SK baseline fit leaves {sS['significant_cells']} of {sS['cells']} channel × phase "
        f"cells significantly outside the band (RMS z = {sS['rms_z']:.2f}); the largest cell is "
        f"{top1['channel']} in {top1['phase']}. " + _diagnosis_text(sS, full=True),
        f"**gaitutils.** On angles and moments only, RMS z = {sU['rms_z']:.2f}; " + _diagnosis_text(sU, full=False),
        "**The generated left leg.** " + _left_line("Schwartz 2008 Free", check_s) + "; "
        + _left_line("gaitutils", check_u) + ". "
        + " ".join(f"On {lab}, {', '.join(left_leg_flips(c))} closes ≥ 5 % of the gap as tracked but nothing against "
                   f"the exact shift: it was fitting the generated left leg, not a property of the children."
                   for lab, c in (("Schwartz 2008", check_s), ("gaitutils", check_u)) if left_leg_flips(c))
        + " The data's left leg is part of what any tracking study measures; this diagnosis makes it visible."]
    if val is not None:
        out.append("**Manipulated real data (not circular).** " + " ".join(validation_lines(val)[:-1])
                   + " " + visibility_text(val))
    if valn is not None and val is not None:
        sp = gval.null_spread(valn)
        vis = gval.visibility(val, sp)
        mid = vis[vis["band"].isin(["middle", "large"])]
        top = sp["candidates"].head(4)
        out.append(f"**Why the injections are rarely named.** With nothing injected, the verdict changed in "
                   f"{sp['draws'] - sp['same_verdict']} of {sp['draws']} redraws of the data within their sampling "
                   f"error, and the leading candidates' ΔBIC moved with an SD of {top['sd'].min():.1f}–"
                   f"{top['sd'].max():.1f} around means of {top['mean'].max():.1f} to {top['mean'].min():.1f}. The "
                   f"injected effect's ΔBIC moved beyond twice its null SD in {int((mid['z'] <= -2).sum())} of "
                   f"{len(mid)} middle and large injections, but reached what naming needs against the other "
                   f"candidates' background in {int(mid['reaches'].sum())}: the real data's own gap, absorbed by "
                   "flexible candidates with a spread larger than the method's margins, hides laboratory-sized "
                   "effects.")
    if valr is not None and val is not None:
        out.append("**The same manipulations as a change relative to the unedited data** (`gaitlib gap "
                   "--reference`: each model's own residual on the reference subtracted). "
                   + " ".join(relative_lines(valr, val)))
    if valr is not None:
        rt = rule_table(valr)
        g = "independent, middle + large"
        out.append(f"**The relative method's threshold rule** (revision {valr.settings['relative_method']['revision']}"
                   f"): on its own cases, " + "; ".join(
                       f"{lab}: ΔBIC ≤ {r['threshold (ΔBIC ≤)']:.0f}, {g} {r[g]}, out-of-library {r['out-of-library']}"
                       for lab, r in rt.iterrows()) + "."
                   + "".join(" " + x for x in floor_held_lines(
                       valr, f"revision {valr.settings['relative_method']['revision']}")))
    if valr_reps is not None and len(valr_reps) > 1:
        rev = next(iter(valr_reps.values())).settings["relative_method"]["revision"]
        out.append(f"**Revision {rev} on a second set of draws.** " + " ".join(replicate_lines(valr_reps))
                   + " " + " ".join(threshold_lines(valr_reps)))
    if load_confusion is not None:
        out.append(" ".join(load_confusion_lines(load_confusion)))
    if null_tail:
        out.append("**The null's tail.** " + " ".join(null_tail_lines(null_tail)))
    if quiet_pair is not None and quiet_pair[1] is not None:
        out.append("**The quiet points, paired on revision 5's draws.** "
                   + " ".join(paired_lines(*quiet_pair, PAIRED["quiet_points_rev5"])))
    if valr_now_reps is not None and len(valr_now_reps) > 1:
        rev = next(iter(valr_now_reps.values())).settings["relative_method"]["revision"]
        out.append(f"**Revision {rev} on two sets of draws.** " + " ".join(replicate_lines(valr_now_reps)[:-1])
                   + " " + " ".join(threshold_lines(valr_now_reps)))
    if common_mode:
        out.append("**Common-mode null draws.** " + " ".join(common_mode_lines(common_mode)))
    if ref_pair is not None and ref_pair[1] is not None:
        out.append("**The baseline's fit of the reference from the candidates', paired on revision 6's draws.** "
                   + " ".join(paired_lines(*ref_pair, PAIRED["reference_fit_rev6"])))
    if pair_rev8 is not None and pair_rev8[1] is not None:
        out.append("**The fallback and the lower located pair, paired on revision 7's draws.** "
                   + " ".join(paired_lines(*pair_rev8, PAIRED["lowest_pair_rev7"])))
    for reps in (current_reps if isinstance(current_reps, list) else [current_reps]):
        if reps is None or len(reps) < 2:
            continue
        rev = next(iter(reps.values())).settings["relative_method"]["revision"]
        now = ", the method in use," if rev == gap_method.RELATIVE.revision else ""
        out.append(f"**Revision {rev}{now} on two sets of draws.** " + " ".join(replicate_lines(reps))
                   + " " + " ".join(threshold_lines(reps)))
    if floor_reps:
        rev = next(iter(floor_reps.values())).settings["relative_method"]["revision"]
        out.append(f"**The share floor, replayed on revision {rev}'s two sets of draws.** "
                   + " ".join(share_floor_lines(floor_reps, floor=gap_method.RELATIVE.min_share_closed)))
    if centred_reps:
        out.append("**The statistic relative to the median candidate, replayed on "
                   f"{len(centred_reps)} earlier sets of draws.** "
                   + " ".join(centred_lines(centred_reps, floor=gap_method.RELATIVE.min_share_closed)))
    if baseline_pair is not None:
        out.append("**What remains of the common mode.** " + " ".join(baseline_pair_lines(baseline_pair))
                   + (" " + " ".join(candidate_baseline_lines(candidate_baseline)) if candidate_baseline else ""))
    if valv is not None:
        out.append(" ".join(validation_lines(valv)[:-1]))
    if tv_muscle is not None:
        out.append(" ".join(muscle_twin_lines(tv_muscle)))
    conv = gaps[gaps["mark"] == ""]  # converged and valid (a marked solution carries no sentence)
    left_top = conv["largest cell"].str.contains("_l ").mean() * 100
    c = conv.sort_values("RMS z, angles/torques/GRFs")
    lo, hi = c.iloc[0], c.iloc[-1]
    out.append(
        f"**The book's Ch 5–7 solutions.** {len(conv)} of {len(gaps)} converged and pass the validity gates. Their RMS z over angles, torques and "
        f"GRFs runs from {lo['RMS z, angles/torques/GRFs']:.1f} ({lo['chapter']} {lo['model']} {lo['case']}) to "
        f"{hi['RMS z, angles/torques/GRFs']:.1f} ({hi['chapter']} {hi['model']} {hi['case']}), against "
        f"{sS['rms_z']:.2f} for the SK model fitted by the diagnosis's SD-standardised objective: the thesis's cost "
        f"functions normalise each channel's error by its range (max − min), not by the data's SD, so their fits "
        f"leave the band where the band is narrow. The largest cell is a left-leg channel in {left_top:.0f} % of them.")
    cc = co_contraction_text(diag_n, emg)
    if cc:
        out.append(cc)
    if diag_m is not None:
        out.append(msk_diagnosis_text(diag_m, profile=profile_m))
    return out


def msk_diagnosis_text(diag: diagnose.Diagnosis, top: int = 3, profile: pd.DataFrame | None = None) -> str:
    """One paragraph on the library's candidates on the Ch 5 MSK solution
    (:func:`ch5_attribution` of "MSK"): the verdict, and the ranked candidates' share of the
    gap closed and ΔBIC (the ``top`` first); how many candidates widened the gap or ended
    above the baseline's located gap; and, with ``profile`` (:func:`ch5_profile` of the top
    effect), each converged point beyond the grid with its share of the gap closed and the
    EMG channels' part in it."""
    rk = diag.ranking
    ranked = rk[rk["rank"].notna()].sort_values("rank")
    lines = [f"{r['effect']} {r['pct_closed']:.1f} % (ΔBIC {r['dBIC']:.0f}"
             + (", comparison only" if "comparison only" in str(r["status"]) else "") + ")"
             for _, r in ranked.head(top).iterrows()]
    worse = int((ranked["pct_closed"] < 0).sum())
    above = int(rk["rank"].isna().sum())
    edge = ""
    fit = diag.fits.get(diag.top_effect)
    if fit is not None and fit.profile:  # a profiled top effect at the end of its grid: the optimum may lie beyond
        grid = [m for m, _, _ in fit.profile]
        best = min(fit.profile, key=lambda t: t[1])[0]
        if best in (min(grid), max(grid)):
            edge = (f" (its best magnitude, {best:g}, is the {'lowest' if best == min(grid) else 'highest'} point of its "
                    f"profile grid {', '.join(f'{m:g}' for m in grid)}: the best fit may lie beyond it)")
    return (f"**The Ch 5 MSK solution, the library's {len(rk)} candidates.** Verdict **{diag.verdict}**"
            + (f", top effect {diag.top_effect}{edge}" if diag.top_effect != "unexplained" else "")
            + f"; closing the most: {', '.join(lines)}. {worse} ranked candidate(s) widen the gap; {above} end "
              f"above the baseline's located gap and are not ranked." + _profile_sentence(diag, profile))


def _profile_sentence(diag, profile: pd.DataFrame | None) -> str:
    if profile is None or fit_grid(diag) is None:
        return ""
    grid = fit_grid(diag)
    pts = profile.iloc[1:]  # the first row is the baseline
    ok = pts[pts["status"].isin(list(validity.CONVERGED_STATUSES))
             & ~pts["magnitude"].isin(grid) & pts["% closed"].notna()]
    if ok.empty:
        return ""
    return (f" Beyond the grid (outside the frozen method): "
            + ", ".join(f"{r['magnitude']:g} closes {r['% closed']:.1f} % ({r['EMG share of the closed gap (%)']:.1f} % "
                        f"of that in the EMG channels)" for _, r in ok.iterrows()) + ".")


def fit_grid(diag) -> list | None:
    """The profile grid of the diagnosis's top effect (None if it was not profiled)."""
    fit = diag.fits.get(diag.top_effect)
    return [m for m, _, _ in fit.profile] if fit is not None and fit.profile else None


def co_contraction_text(diag_n: diagnose.Diagnosis, emg: pd.DataFrame, closes_most: float = 0.5) -> str | None:
    """The thesis's co-contraction suspicion (Sec 5.3.5) tested on the NMSK solution: how far
    the TA and MG excitations sit from their EMG (mean z), and whether the best
    co-contraction fit closes most — more than ``closes_most`` of the TA + MG RSS — of the
    TA/GAM gap (``emg`` = :func:`emg_gap_table` of ``diag_n``). None when there is no
    co-contraction fit with a finite TA RSS."""
    e0 = emg.set_index("model")
    if "co_contraction" not in e0.index or not np.isfinite(e0.loc["co_contraction"].get("RSS TA", np.nan)):
        return None
    cc = e0.loc["co_contraction"]
    ta0, mg0 = float(e0.loc["baseline", "RSS TA"]), float(e0.loc["baseline", "RSS MG"])
    ta1, mg1 = float(cc["RSS TA"]), float(cc["RSS MG"])
    closes = (ta1 + mg1) < closes_most * (ta0 + mg0)
    rk = diag_n.ranking.set_index("effect")
    zt, zm = e0.loc["baseline", "mean z TA"], e0.loc["baseline", "mean z MG"]
    return (
        f"**Co-contraction (thesis Sec 5.3.5).** On the Ch 5 NMSK solution the TA excitation is on average "
        f"{abs(float(zt)):.1f} SD {'below' if zt < 0 else 'above'} its EMG and the MG/GAM excitation "
        f"{abs(float(zm)):.1f} SD {'below' if zm < 0 else 'above'}. The best co-contraction "
        f"({cc['parameters']}, {cc['status']}) changes the TA + MG RSS from {ta0 + mg0:.0f} to {ta1 + mg1:.0f} "
        f"({100 * (1 - (ta1 + mg1) / (ta0 + mg0)):.0f} % closed) and the whole gap by "
        f"{float(rk.loc['co_contraction', 'pct_closed']):.0f} % (ΔBIC = {float(rk.loc['co_contraction', 'dBIC']):.0f}): "
        + ("co-contraction **does** close most of the TA/GAM gap, as the thesis suspected."
           if closes else "co-contraction does **not** close the TA/GAM gap — the thesis's suspicion is not borne out "
                          "on these data.")
        + (f" The NMSK diagnosis names **{diag_n.top_effect}** ({diag_n.verdict})." if diag_n.top_effect != "unexplained"
           else " No muscle-level candidate passes the criterion on the NMSK solution: its gap stays **unexplained**."))
