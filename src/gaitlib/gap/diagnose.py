"""Attribute and shrink the gap: re-solve with each candidate effect, rank, report.

:func:`diagnose` takes a data set (a tidy CSV, a :class:`~gaitlib.gap.io.DataSet` or
GaitData) and a baseline model, and

1. fits the baseline (objective ``"fit"``, :mod:`gaitlib.gap.solve`: the SD-standardised
   tracking error of the located channels plus the spec's regularisation) from several
   starts (:data:`BASELINE_STARTS`: the data's own data-based guess, a given solution, and
   continuations from the spec's own cost function, from a coarse mesh and from the fit
   with the GRFs weighted up), keeps the converged fit with the lowest objective, and
   locates its gap
   (:func:`gaitlib.gap.locate.locate`); if no start converged it stops
   (:class:`BaselineFailed`): a gap located on a non-converged fit is not a result;
2. re-solves with every applicable candidate effect (:data:`gaitlib.effects.EFFECTS`),
   warm-started from the baseline fit, through :func:`gaitlib.sweep.sweep`:
   ``identify="nlp"`` effects with their parameters free in the NLP; ``"profile"`` effects
   (signature in EMG only) on a grid of fixed magnitudes, keeping the one with the smallest
   gap; an NLP candidate that does not converge, or ends above the baseline's objective
   although it contains the baseline model (a worse local optimum), is re-solved from each
   of the baseline's other starts, then (if still so) from the *null start* — the baseline
   fit itself with the effect at its null value, a point with exactly the baseline's
   objective (:mod:`gaitlib.gap.nullstart`) — and the best converged fit kept; if it still
   ends above the baseline, it is a *failed search*; comparison-only effects
   (``resolve=False``) by a bounded scalar search of the gap on the baseline's solution
   (the null value kept when the search does no better);
3. ranks the effects by a criterion that pays for parameters and says "unexplained" when
   none is good enough. Failed searches are not ranked (no % closed), nor is a candidate
   that nests the baseline (:func:`nesting`) but whose located gap ends above the
   baseline's; a ranked nested candidate therefore never shows a negative % closed beyond
   the tolerance :data:`RETRY_MARGIN` — only a non-nesting one (the profiled effects) can.
   Each candidate's row names the start of its kept fit and whether it nests the baseline;
   ``diagnosis.json`` counts them (:meth:`Diagnosis.summary`);
4. for the top effects: the gap before/after per channel and phase, % closed, and an
   interval from resampling the data within SD/√n.

Criterion
---------
With z the SD-standardised residual (:mod:`gaitlib.gap.locate`) and RSS = Σ z² over the
located channels and points, each model is scored as a Gaussian likelihood with unknown
variance on n_eff effectively independent samples (the resel count of the baseline's
residual, :func:`gaitlib.gap.locate.resels`): ΔAIC = n_eff ln(RSS_k / RSS_0) + 2 k and
ΔBIC = n_eff ln(RSS_k / RSS_0) + k ln n_eff (k = parameters added; for profiled effects the
magnitude counts as one). Raw figures (% of the RSS closed) are reported beside them.
Effects are ranked by ΔBIC; the top effect must have ΔBIC ≤ :data:`BIC_THRESHOLD`
("very strong" evidence on Kass & Raftery's scale) and a converged solve, and (the
out-of-library test, :attr:`gaitlib.gap.method.Method.runner_up_margin`) a ΔBIC below
every other ranked candidate's by the margin, else the diagnosis is ``"unexplained"``
(``contenders``: the candidates within the margin of the best). Verdict ``"explained"`` if it also closes ≥ 50 % of the
RSS, ``"partial"`` otherwise.

Interval: the data's means are redrawn B times as mean + SD*/√n · g(τ) (g: smooth unit
noise, :func:`gaitlib.gap.noise.smooth_noise`; a generated left leg gets the right leg's
noise at its shifted time), the solutions held fixed, and % closed recomputed; the 2.5 and
97.5 percentiles are reported. The solutions are not re-solved per draw (cost), so the
interval covers the data's uncertainty, not the re-identification's.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..problems import gait as gait_ocp
from ..ocp import _json_default  # the same JSON encoding as saved solutions
from .. import effects as effects_mod
from .. import sweep as sweep_mod
from . import io as gio
from . import locate
from . import reference as gref
from .method import (BIC_THRESHOLD, DEFAULT_BASE, EXPLAINED_PCT, METHOD, PROFILE_GRID, RELATIVE, RUNNER_UP_MARGIN,
                     null_threshold, share_beyond_median)
from .noise import smooth_noise
from .nullstart import null_start_many
from .solve import solve_many
from .. import marks
from . import figures as gap_figures

__all__ = ["BIC_THRESHOLD", "PROFILE_GRID", "DEFAULT_BASE", "Fit", "Diagnosis", "diagnose", "assemble",
           "candidates", "base_spec", "as_dataset", "baseline_fits", "pick_best", "BASELINE_STARTS",
           "COARSE_MESH", "GRF_SD_FACTOR", "RETRY_MARGIN", "grf_weighted", "candidate_fits", "needs_retry",
           "alternates_of", "lowest_objective", "BaselineFailed", "nesting", "ABOVE_LOCATED", "FIT_STARTS",
           "with_effects", "contenders_of", "relative_fits", "consistent_fits",
           "continuation_pairs", "lowest_baseline_pair", "fallback_baselines",
           "null_calibration", "calibration_dBIC"]


def base_spec(base=None) -> gait_ocp.GaitSpec:
    if isinstance(base, gait_ocp.GaitSpec):
        if base.effects:
            raise ValueError("the baseline spec must have no effects")
        return base
    return gait_ocp.GaitSpec(**dict(DEFAULT_BASE if base is None else base))


def as_dataset(data, like=None, fill_from=None, n_subjects=None) -> gio.DataSet:
    if isinstance(data, gio.DataSet):
        return data
    if isinstance(data, (str, Path)):
        return gio.read_data(data, like=like, fill_from=fill_from, n_subjects=n_subjects)
    if hasattr(data, "mean") and hasattr(data, "sd"):
        frame = pd.DataFrame({"source": [data.source]})
        n, n_source = gio.subject_count(frame, data.speed_class, n_subjects, f"GaitData {data.source}")
        return gio.DataSet(gait=data, label=f"{data.source} {data.speed_class}", base=data.source, n=n,
                           n_source=n_source)
    raise TypeError(f"data must be a CSV path, DataSet or GaitData, got {type(data).__name__}")


def candidates(spec0: gait_ocp.GaitSpec, gait, effects=None) -> tuple[list, dict]:
    """(applicable effect names, {name: reason} of those left out)."""
    names = list(effects_mod.EFFECTS) if effects is None else list(effects)
    ok, skipped = [], {}
    for n in names:
        e = effects_mod.EFFECTS[n]
        if spec0.model not in e.models:
            skipped[n] = f"not applicable to the {spec0.model} model (signature: {e.signature})"
        elif n == "left_shift" and not effects_mod.left_generated(gait):
            skipped[n] = "the data's left leg is measured, not generated from the right one"
        elif e.identify == "profile" and e.resolve and n not in PROFILE_GRID:
            skipped[n] = "no profile grid"
        else:
            ok.append(n)
    return ok, skipped


@dataclass
class Fit:
    """One candidate's re-solve: its solution, identified parameters, located gap."""

    effect: str
    solution: object | None
    thetas: dict
    located: locate.Located | None
    n_params: int
    identify: str
    status: str
    ok: bool
    profile: list = field(default_factory=list)  # [(magnitude, rss, status)]
    start: str = "baseline"  # where the kept fit started (:data:`FIT_STARTS`)
    search: str = "ok"  # "ok" or "failed search" (:func:`candidate_fits`)
    reference_thetas: dict = field(default_factory=dict)  # its fit of a reference (:func:`relative_fits`)
    # relative: the first solve from its fit of the reference (``warms``), kept when another start won
    continuation: object | None = None
    pair: str = "final"  # relative: which (reference fit, data fit) pair is located (:func:`relative_fits`)


def _status(sol) -> tuple[str, bool]:
    if sol is None:
        return "error", False
    st = sol.stats["status"]
    return st, st in ("Solve_Succeeded", "Solved_To_Acceptable_Level")


def pick_best(sols: list):
    """The converged solution with the lowest objective; None if none converged (a
    non-converged solve is never kept as a baseline)."""
    conv = [s for s in sols if s is not None and _status(s)[1]]
    return min(conv, key=lambda s: s.stats["objective"]) if conv else None


def lowest_objective(sols: list):
    """The solution with the lowest objective, converged or not (None if there is none): a
    candidate none of whose starts converged is reported by this fit, with its status and
    ``ok=False`` (never eligible for the verdict)."""
    sols = [s for s in sols if s is not None]
    return min(sols, key=lambda s: s.stats["objective"]) if sols else None


class BaselineFailed(RuntimeError):
    """No start of the baseline fit converged: there is no baseline to locate a gap on.
    ``statuses``: start → IPOPT status of every start that returned a solution."""

    def __init__(self, statuses: dict):
        self.statuses = dict(statuses)
        text = ", ".join(f"{k} {v}" for k, v in self.statuses.items()) or "no start returned a solution"
        super().__init__(f"baseline failed: {text}")


# ======================================================================================
# Ranking
# ======================================================================================

def _noise_fns(located_list, rng, B: int) -> dict:
    """Smooth unit noise draws per channel id: id → callable(τ) → (B, len τ)."""
    ids = sorted({c for loc in located_list for c in loc.channels["channel"]})
    return {c: smooth_noise(rng, B) for c in ids}


def _root(ch: str) -> str:
    return ch[:-2] + "_r" if ch.endswith("_l") else ch


def _resampled_rss(loc: locate.Located, ds, fns: dict, left_shift: float, generated: bool) -> np.ndarray:
    """RSS of ``loc`` for each noise draw (B,): data mean + SD*/√n · g; a generated left
    leg takes its right leg's draw at τ + ``left_shift``."""
    n = max(ds.n, 1)
    tot = None
    for ch, g in loc.points.groupby("channel", sort=False):
        tau = g["tau"].to_numpy()
        se = g["sd_eff"].to_numpy() / np.sqrt(n)
        if ch.endswith("_l") and generated and _root(ch) in fns:
            eps = fns[_root(ch)](tau + left_shift)
        else:
            eps = fns[ch](tau)
        z = (g["sim"].to_numpy() - (g["mean"].to_numpy() + se * eps)) / g["sd_eff"].to_numpy()
        r = np.sum(z**2, axis=1)
        tot = r if tot is None else tot + r
    return tot


def _criteria(rss0, rssk, k, n_eff):
    lr = n_eff * math.log(max(rssk, 1e-300) / max(rss0, 1e-300))
    return lr + 2 * k, lr + k * math.log(max(n_eff, 1.0))


@dataclass
class Diagnosis:
    """The result of :func:`diagnose` (see the module docstring)."""

    data: gio.DataSet
    spec: gait_ocp.GaitSpec
    objective: str
    baseline: object
    located: locate.Located
    fits: dict
    ranking: pd.DataFrame
    top_effect: str
    verdict: str
    shrink: dict
    intervals: dict
    skipped: dict
    settings: dict
    solution_located: locate.Located | None = None  # the gap of a given (e.g. thesis) solution
    reference_fit: object | None = None  # the baseline's fit of the reference data (``reference=``)

    def to_dict(self) -> dict:
        def rec(df):
            return json.loads(df.to_json(orient="records")) if df is not None else None

        out = {
            "data": {"label": self.data.label, "base_source": self.data.base, "speed_class": self.data.gait.speed_class,
                     "n_subjects": self.data.n, "n_subjects_source": self.data.n_source,
                     "signature": self.data.signature, "filled": list(self.data.filled),
                     "path": self.data.path, "notes": list(self.data.notes) + list(self.data.gait.notes)},
            "baseline": {"spec": self.spec.to_dict(), "objective": self.objective,
                         "stats": _stats(self.baseline)},
            "criterion": {"rss": "sum of squared SD-standardised residuals over located channels and points",
                          "n_eff": self.located.n_eff, "n_points": self.located.n_points,
                          "dAIC": "n_eff ln(RSS_k/RSS_0) + 2k", "dBIC": "n_eff ln(RSS_k/RSS_0) + k ln n_eff",
                          "threshold_dBIC": BIC_THRESHOLD, "explained_pct": EXPLAINED_PCT},
            "located": {"summary": self.located.summary(), "table": rec(self.located.table),
                        "channels": rec(self.located.channels), "residuals": rec(self.located.residuals)},
            "ranking": rec(self.ranking),
            "top_effect": self.top_effect,
            "contenders": self.settings.get("contenders", []),
            "verdict": self.verdict,
            "shrink": {k: {"table": rec(v), "pct_closed": float(self.ranking.set_index("effect").loc[k, "pct_closed"]),
                           "interval_95": self.intervals.get(k)} for k, v in self.shrink.items()},
            "skipped": self.skipped,
            "summary": self.summary(),
            "effects": {n: {"title": e.title, "n_params": e.n_params, "identify": e.identify,
                            "params": [p.__dict__ for p in e.params], "nests_baseline": nesting(n)[0],
                            "nesting": nesting(n)[1]} for n, e in effects_mod.EFFECTS.items()},
            "settings": self.settings,
        }
        if self.solution_located is not None:
            out["solution_located"] = {"summary": self.solution_located.summary(),
                                       "table": rec(self.solution_located.table)}
        return out

    def summary(self) -> dict:
        """Counts of the candidates: tried, ranked, failed searches (named), nested ones with
        a located gap above the baseline's, re-solved from the null start, not nesting."""
        r = self.ranking
        if r.empty:
            r = pd.DataFrame(columns=["rank", "effect", "search", "start"])

        def sel(mask):
            return [str(e) for e in r.loc[mask, "effect"]]

        failed, above = sel(r["search"] == "failed search"), sel(r["search"] == ABOVE_LOCATED)
        return {"candidates": len(r), "ranked": int(r["rank"].notna().sum()),
                "failed_search": len(failed), "failed_search_effects": failed,
                "located_above_baseline": len(above), "located_above_baseline_effects": above,
                "null_start": sel(r["start"] == "null"),
                "not_nesting": {n: nesting(n)[1] for n in r["effect"] if not nesting(n)[0]},
                "retry_margin": RETRY_MARGIN}

    def save(self, out, figures: bool = True) -> Path:
        """Write ``diagnosis.json``, ``located.csv``, ``ranking.csv``, ``shrink_<effect>.csv``
        and (``figures``) ``gap_heatmap.png``, ``ranking.png``, ``shrink.png``."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "diagnosis.json").write_text(json.dumps(self.to_dict(), indent=1, default=_json_default))
        self.located.table.to_csv(out / "located.csv", index=False, float_format="%.6g")
        dicts = [c for c in ("parameters", "parameters_reference", "parameter_change") if c in self.ranking.columns]
        self.ranking.drop(columns=dicts).to_csv(out / "ranking.csv", index=False, float_format="%.6g")
        for k, v in self.shrink.items():
            v.to_csv(out / f"shrink_{k}.csv", index=False, float_format="%.6g")
        if figures:
            import matplotlib

            matplotlib.use("Agg")

            m0 = marks.failure_label(self.baseline)
            gap_figures.gap_heatmap(self.located, title=f"gap of the baseline fit — {self.data.label}", mark=m0).savefig(
                out / "gap_heatmap.png", dpi=110)
            gap_figures.ranking_bars(self.ranking, top=self.top_effect, mark=m0).savefig(out / "ranking.png", dpi=110)
            if self.shrink:
                first = next(iter(self.shrink))
                m1 = marks.failure_label(self.fits[first].solution or self.fits[first].status)
                gap_figures.shrink_heatmaps(self.located, self.fits[first].located, first, marks=(m0, m1)).savefig(
                    out / "shrink.png", dpi=110)
        return out


def _stats(sol) -> dict:
    if sol is None:
        return {}
    keys = ("status", "iterations", "solve_time_s", "build_time_s", "time_per_iteration_s", "objective",
            "max_violation", "from_cache", "objective_kind", "effects", "start")
    return {k: sol.stats.get(k) for k in keys if k in sol.stats}


#: ``search`` of a nested candidate whose fit is no failed search (its objective is not above
#: the baseline's) but whose located gap (RSS) is above the baseline's by more than
#: :data:`RETRY_MARGIN` (relative): the fit moved misfit from the located channels to what
#: the objective counts besides them (regularisation; channels filled from another data
#: set). Not ranked: the candidate model contains the baseline, so this is not its best
#: member by the ranking's criterion.
ABOVE_LOCATED = "located gap above the baseline's"


def nesting(name: str) -> tuple[bool, str]:
    """(whether the candidate's kept fit can always reproduce the baseline, why)."""
    e = effects_mod.EFFECTS[name]
    if not e.resolve:
        return True, "comparison on the baseline solution; the null value is kept unless a value does better"
    if _nested(e):
        return True, "its null parameter values are the baseline model (an NLP start with the baseline's objective)"
    if e.identify == "profile":
        return False, "fitted on a grid of fixed magnitudes without the null value"
    return False, "its null value lies outside its parameters' bounds"


def assemble(ds: gio.DataSet, spec0, base_sol, fits: dict, *, objective="fit", resamples: int = 200, seed: int = 0,
             top: int = 3, skipped=None, settings=None, solution=None, threshold: float | None = None,
             min_share: float = 0.0, centred: bool = False) -> Diagnosis:
    """Rank fitted candidates against the baseline fit and build the :class:`Diagnosis`.

    Ranked (``rank`` 1, 2, …, by ΔBIC): candidates with a located fit whose ``search`` is
    ``"ok"``. Not ranked (``rank`` missing; no % closed, ΔAIC, ΔBIC): no fit, a failed
    search (:func:`candidate_fits`), or a nested candidate whose located gap ends above the
    baseline's (:data:`ABOVE_LOCATED`). So a ranked candidate that nests the baseline
    (``nests_baseline``, :func:`nesting`) closes ≥ −100 :data:`RETRY_MARGIN` % of the RSS;
    only a non-nesting one can show a negative % closed. ``threshold``: the ΔBIC the top
    effect must reach (default :data:`BIC_THRESHOLD`; a relative diagnosis's null
    calibration lowers it). ``min_share``: the % of the located RSS the top effect must also
    close to be named (a relative diagnosis: :attr:`gaitlib.gap.method.RelativeMethod.
    min_share_closed`; 0: no such test) — below it the diagnosis is "unexplained", and the
    settings' ``held_by_share_floor`` names the effect it held. ``centred`` (a relative
    diagnosis: :attr:`gaitlib.gap.method.RelativeMethod.centred`): the top effect's ΔBIC must
    reach :data:`BIC_THRESHOLD`, and its ΔBIC minus the median ranked candidate's (settings
    ``median_dBIC``) must reach ``threshold``; ``min_share`` applies to the share of the gap
    the median candidate leaves open that it closes (:func:`gaitlib.gap.method.
    share_beyond_median`; settings ``share_closed``)."""
    thr = BIC_THRESHOLD if threshold is None else float(threshold)
    loc0 = locate.locate(base_sol, ds)
    n_eff = loc0.n_eff
    rows = []
    for name, f in fits.items():
        e = effects_mod.EFFECTS[name]
        nests, _ = nesting(name)
        th_r = f.reference_thetas.get(name, {})
        th = f.thetas.get(name, {})
        row = {"effect": name, "title": e.title, "n_params": f.n_params, "identify": f.identify,
               "parameters": th, "parameters_reference": th_r,
               "parameter_change": {k: float(v) - float(th_r[k]) for k, v in th.items() if k in th_r},
               "status": f.status, "ok": f.ok, "start": f.start, "pair": f.pair,
               "nests_baseline": nests, "search": f.search, "rss_before": loc0.rss, "rss_after": np.nan,
               "pct_closed": np.nan, "dAIC": np.nan, "dBIC": np.nan, "residual_ratio": np.nan}
        if f.located is not None and f.located.residuals is not None:
            row["residual_ratio"] = float(f.located.residuals["peak_ratio"].max())
        if f.located is not None:
            row["rss_after"] = rk = f.located.rss
            if nests and f.search == "ok" and rk > loc0.rss * (1.0 + RETRY_MARGIN):
                row["search"] = ABOVE_LOCATED
        if f.located is None:
            row["ok"] = False
        elif row["search"] != "ok":
            row["ok"] = False
            row["status"] = f"{row['search']} ({f.status})"
        else:
            row["dAIC"], row["dBIC"] = _criteria(loc0.rss, rk, f.n_params, n_eff)
            row["pct_closed"] = 100.0 * (1.0 - rk / loc0.rss)
        rows.append(row)
    ranking = pd.DataFrame(rows)
    if not ranking.empty:
        ranked = ranking["search"].eq("ok") & np.isfinite(ranking["dBIC"].astype(float))
        ranking = ranking.assign(_r=~ranked).sort_values(["_r", "dBIC"], na_position="last", kind="stable")
        ranking = ranking.drop(columns="_r").reset_index(drop=True)
        rank = pd.array([pd.NA] * len(ranking), dtype="Int64")
        m = int(ranked.sum())
        rank[:m] = np.arange(1, m + 1)
        ranking.insert(0, "rank", rank)
    med, share = None, None  # the median ranked candidate's ΔBIC; the top effect's share closed
    if ranking.empty:
        elig = ranking
    elif centred:
        dbic = ranking["dBIC"].astype(float)
        ranked = ranking["ok"].astype(bool) & np.isfinite(dbic)
        med = float(np.median(dbic[ranked])) if ranked.any() else None
        elig = ranking[ranked & (dbic <= BIC_THRESHOLD) & (dbic - med <= thr)] if med is not None else ranking[ranked]
    else:
        elig = ranking[(ranking["ok"]) & (ranking["dBIC"] <= thr)]
    if len(elig):
        pcts = ranking.loc[ranking["ok"].astype(bool) & np.isfinite(ranking["dBIC"].astype(float)), "pct_closed"]
        share = share_beyond_median(float(elig.iloc[0]["pct_closed"]), pcts, centred)
    contenders = contenders_of(ranking)
    held = None  # the top effect the share floor held, if it did
    if len(elig) and len(contenders) <= 1 and share >= min_share:
        top_effect = str(elig.iloc[0]["effect"])
        verdict = "explained" if float(elig.iloc[0]["pct_closed"]) >= EXPLAINED_PCT else "partial"
    else:
        top_effect, verdict = "unexplained", "unexplained"
        if len(elig) and len(contenders) <= 1:
            held = str(elig.iloc[0]["effect"])
    # shrink tables and intervals for the top effects
    shrink, intervals = {}, {}
    tops = [r["effect"] for _, r in ranking.iterrows() if r["ok"] and np.isfinite(r["dBIC"])][:top]
    rng = np.random.default_rng(seed)
    generated = effects_mod.left_generated(ds.gait)
    shift0 = float(ds.gait.left_shift)
    fns = _noise_fns([loc0] + [fits[k].located for k in tops], rng, resamples) if resamples and tops else None
    r0 = _resampled_rss(loc0, ds, fns, shift0, generated) if fns else None
    for k in tops:
        lk = fits[k].located
        shrink[k] = _shrink_table(loc0, lk)
        if fns:
            delta = float(fits[k].thetas.get("left_shift", {}).get("delta", 0.0))
            rk_b = _resampled_rss(lk, ds, fns, shift0 + delta, generated)
            pc = 100.0 * (1.0 - rk_b / r0)
            intervals[k] = [float(np.percentile(pc, 2.5)), float(np.percentile(pc, 97.5))]
    if intervals:
        ranking["pct_closed_lo"] = ranking["effect"].map(lambda k: intervals.get(k, [np.nan, np.nan])[0])
        ranking["pct_closed_hi"] = ranking["effect"].map(lambda k: intervals.get(k, [np.nan, np.nan])[1])
    sol_loc = locate.locate(solution, ds) if solution is not None else None
    st = dict(settings or {})
    st.update({"resamples": resamples, "seed": seed, "bic_threshold": BIC_THRESHOLD, "threshold_used": thr,
               "runner_up_margin": RUNNER_UP_MARGIN, "contenders": contenders if len(elig) else [],
               "min_share_closed": float(min_share), "held_by_share_floor": held,
               "centred": bool(centred), "median_dBIC": med, "share_closed": share,
               "method": METHOD.to_dict(), "method_hash": METHOD.hash()})
    return Diagnosis(ds, spec0, objective, base_sol, loc0, fits, ranking, top_effect, verdict, shrink, intervals,
                     dict(skipped or {}), st, sol_loc)


def contenders_of(ranking: pd.DataFrame, margin: float = RUNNER_UP_MARGIN) -> list:
    """The ranked, converged candidates whose ΔBIC is within ``margin`` of the best one's
    (the best one first); with ``margin`` 0 (no out-of-library test) only the best one."""
    if ranking.empty:
        return []
    r = ranking[ranking["ok"] & np.isfinite(ranking["dBIC"].astype(float))]
    if r.empty:
        return []
    best = float(r["dBIC"].min())
    if margin <= 0:
        return [str(r.loc[r["dBIC"].idxmin(), "effect"])]
    return [str(e) for e in r.loc[r["dBIC"] < best + margin, "effect"]]


def _shrink_table(loc0: locate.Located, lk: locate.Located) -> pd.DataFrame:
    a = loc0.table[["channel", "kind", "side", "phase", "n", "rms_z", "mean_z", "significant"]].rename(
        columns={"rms_z": "rms_before", "mean_z": "mean_before", "significant": "significant_before"})
    b = lk.table[["channel", "phase", "rms_z", "mean_z", "significant"]].rename(
        columns={"rms_z": "rms_after", "mean_z": "mean_after", "significant": "significant_after"})
    t = a.merge(b, on=["channel", "phase"], how="left")
    ss0, ss1 = t["n"] * t["rms_before"] ** 2, t["n"] * t["rms_after"] ** 2
    t["pct_closed"] = 100.0 * (1.0 - ss1 / ss0.where(ss0 > 0))
    return t


# ======================================================================================
# Solving: baseline fits and candidates
# ======================================================================================

#: Starts of the baseline fit; the converged fit with the lowest objective is kept
#: (:func:`pick_best`). ``cold``: the data's own data-based guess; ``warm``: the given
#: solution; ``dt``: the spec's own cost function (e.g. the thesis's DT, Eq 4.11) solved
#: from the data-based guess, then the fit warm-started from it; ``coarse``: the fit on the
#: :data:`COARSE_MESH`, then the fit on the spec's mesh warm-started from it (only when the
#: spec's mesh is finer); ``grf``: the fit with the GRF channels' SDs multiplied by
#: :data:`GRF_SD_FACTOR` (their weight by its inverse square) from the data-based guess,
#: then the fit of the data as they are warm-started from it — a continuation that first
#: finds the contact pattern (e.g. a brief second contact after toe-off) and then the
#: kinematics. On the 20 × 5 mesh a single start often stops in a local optimum far from
#: the data (twins: an RSS 3–120× the noise's); the three continuation starts cost six more
#: solves per data set (two of them on the coarse mesh).
BASELINE_STARTS = ("cold", "warm", "dt", "coarse", "grf")
#: (intervals, degree) of the ``coarse`` start.
COARSE_MESH = (10, 3)
#: Factor on the GRF channels' SDs in the first stage of the ``grf`` start.
GRF_SD_FACTOR = 0.1
#: Where a candidate's kept fit started (``Fit.start``): ``"baseline"`` the kept baseline fit
#: (the first solve; profiled effects); one of :data:`BASELINE_STARTS` the baseline's fit
#: from that start (the retry); ``"null"`` the null start (:mod:`gaitlib.gap.nullstart`);
#: ``"baseline (no re-solve)"`` comparison-only effects; in a relative diagnosis
#: (:func:`consistent_fits`) ``"data"`` a fit of the reference re-solved from the model's fit
#: of the data, ``"reference (consistent)"`` a fit of the data continued again from it,
#: ``"reference"`` the data's first fit, continued from the model's first fit of the reference
#: (the continuation pair, :func:`relative_fits` ``alternates``).
FIT_STARTS = ("baseline", *BASELINE_STARTS, "null", "baseline (no re-solve)", "data", "reference (consistent)",
              "reference")
#: A nested candidate (its null parameters are the baseline model) whose fit ends with an
#: objective above the baseline fit's by more than this relative margin has stopped in a
#: worse local optimum; :func:`candidate_fits` then re-solves it from the baseline's other
#: starts.
RETRY_MARGIN = 1e-3


def grf_weighted(gait, factor: float = GRF_SD_FACTOR):
    """A copy of ``gait`` whose GRF channels' SDs are multiplied by ``factor`` (the Fit
    objective then weights their residual by 1/factor²); means, time and events unchanged.
    Its numbers differ, so its solutions get their own cache keys."""
    import dataclasses

    sd = gait.sd.copy()
    cols = [c for c in gait_ocp.GRF_CHANNELS if c in sd.columns]
    if not cols:
        raise ValueError("grf_weighted: the data set has no GRF channels " + repr(list(gait_ocp.GRF_CHANNELS)))
    sd[cols] = sd[cols] * float(factor)
    return dataclasses.replace(gait, sd=sd)


def _coarse_spec(spec0):
    import dataclasses

    n, d = COARSE_MESH
    if spec0.n_intervals * spec0.degree <= n * d:
        return None
    return dataclasses.replace(spec0, n_intervals=n, degree=d)


def baseline_fits(spec0, datasets: dict, warm=None, *, objective="fit", root=None, use_cache=True, chunks: int = 2,
                  starts=BASELINE_STARTS, detail: bool = False, **sweep_kw) -> dict:
    """Baseline fits of several data sets (key → DataSet) from each of ``starts``
    (:data:`BASELINE_STARTS`; ``warm`` only with a ``warm`` solution, ``coarse`` only on a
    mesh finer than :data:`COARSE_MESH`, ``grf`` only for the ``"fit"`` objective); the
    converged fit with the lowest objective is kept. Returns key → GaitSolution, None where
    no start converged (``detail``: key → {start: GaitSolution}, the kept one under
    ``"best"``); each kept solution's ``stats["start"]`` names its start."""
    unknown = set(starts) - set(BASELINE_STARTS)
    if unknown:
        raise ValueError(f"unknown baseline start(s) {sorted(unknown)}; expected some of {BASELINE_STARTS}")
    keys = list(datasets)
    parts = [p for p in (keys[i::chunks] for i in range(chunks)) if p]
    coarse = _coarse_spec(spec0) if "coarse" in starts else None
    kw = dict(root=root, use_cache=use_cache, **sweep_kw)
    # round 1: the single-stage fits and the first stage of the continuations
    groups = {}
    for i, part in enumerate(parts):
        if "cold" in starts:
            groups[f"baseline-cold-{i}"] = (spec0, [(f"{k}|cold", datasets[k].gait, None) for k in part])
        if "warm" in starts and warm is not None:
            groups[f"baseline-warm-{i}"] = (spec0, [(f"{k}|warm", datasets[k].gait, warm) for k in part])
        if coarse is not None:
            groups[f"baseline-coarse1-{i}"] = (coarse, [(f"{k}|coarse1", datasets[k].gait, None) for k in part])
        if "grf" in starts and objective == "fit":
            groups[f"baseline-grf1-{i}"] = (spec0, [(f"{k}|grf1", grf_weighted(datasets[k].gait), None)
                                                    for k in part])
    res = solve_many(groups, objective=objective, **kw) if groups else {}
    if "dt" in starts and objective != "cost":
        res.update(solve_many({f"baseline-dt1-{i}": (spec0, [(f"{k}|dt1", datasets[k].gait, None) for k in part])
                               for i, part in enumerate(parts)}, objective="cost", **kw))
    # round 2: the fits warm-started from the first stages
    groups = {}
    for i, part in enumerate(parts):
        for st in ("dt", "coarse", "grf"):
            jobs = [(f"{k}|{st}", datasets[k].gait, res[f"{k}|{st}1"]) for k in part
                    if res.get(f"{k}|{st}1") is not None]
            if jobs:
                groups[f"baseline-{st}-{i}"] = (spec0, jobs)
    if groups:
        res.update(solve_many(groups, objective=objective, **kw))
    out = {}
    for k in keys:
        per = {st: res.get(f"{k}|{st}") for st in BASELINE_STARTS if res.get(f"{k}|{st}") is not None}
        best = pick_best(list(per.values()))
        if best is not None:
            best.stats["start"] = next(st for st, s in per.items() if s is best)
        out[k] = dict(per, best=best) if detail else best
    return out


def _nested(e) -> bool:
    """An NLP-identified effect whose null parameters lie inside its bounds: the baseline
    model is one of its members, so its fit can reach the baseline's objective."""
    return e.identify == "nlp" and all(p.lower <= p.null <= p.upper for p in e.params)


def _nlp_fit(n: str, sol, ds, error: bool = False) -> Fit:
    e = effects_mod.EFFECTS[n]
    st, ok = _status(sol)
    if sol is None and error:
        st = "error"
    th = sol.stats.get("effects", {}) if sol is not None else {}
    loc = locate.locate(sol, ds, thetas=th) if sol is not None else None
    return Fit(n, sol, th, loc, e.n_params, e.identify, st, ok)


def needs_retry(n: str, sol, base_sol) -> bool:
    """A candidate fit to re-solve from the baseline's other starts: it did not converge, or
    (a nested effect, :func:`_nested`) it ends with an objective above the baseline fit's by
    more than :data:`RETRY_MARGIN` (relative) — a worse local optimum than the model it
    contains."""
    if sol is None or not _status(sol)[1]:
        return True
    if not _nested(effects_mod.EFFECTS[n]) or base_sol is None:
        return False
    f0, f1 = float(base_sol.stats["objective"]), float(sol.stats["objective"])
    return f1 > f0 + RETRY_MARGIN * abs(f0)


def candidate_fits(spec0, datasets: dict, bases: dict, names, *, objective="fit", root=None, use_cache=True,
                   alternates: dict | None = None, null_start: bool = True, warms: dict | None = None,
                   **sweep_kw) -> dict:
    """Fits of every candidate on every data set: key → {effect: Fit}.

    Each candidate is warm-started from ``bases[key]`` (the baseline fit). ``alternates``
    (key → {start: solution}: the baseline's fits from its other starts, see
    :func:`baseline_fits` ``detail``) enables the retry: an NLP-identified candidate whose
    fit :func:`needs_retry` is re-solved warm-started from each of them. A nested candidate
    (:func:`_nested`) whose best fit still :func:`needs_retry` is then (``null_start``)
    re-solved from the baseline fit itself with its parameters at their null values
    (:mod:`gaitlib.gap.nullstart`: a start with exactly the baseline's objective). The
    converged fit with the lowest objective (:func:`pick_best`) is kept — if none converged,
    the one with the lowest objective (:func:`lowest_objective`), reported with its status
    and never eligible; ``Fit.start``
    names where it started (:data:`FIT_STARTS`; ``stats["retry_start"]`` too, ``"best"``
    for the first solve, when more than one was tried). A nested candidate whose kept fit
    still :func:`needs_retry` is a failed local search: ``Fit.search = "failed search"``
    (:func:`assemble` does not rank it). ``warms`` (key → {effect: solution}): the first
    solve of an NLP-identified effect starts from that solution instead of the baseline fit
    (a change relative to a reference continues each candidate's fit of the reference)."""
    groups = {}
    for n in names:
        e = effects_mod.EFFECTS[n]
        if not e.resolve:
            continue
        if e.identify == "nlp":
            spec = with_effects(spec0, ((n, None),))
            groups[n] = (spec, [(f"{k}|{n}", ds.gait, ((warms or {}).get(k) or {}).get(n) or bases[k])
                                for k, ds in datasets.items() if bases[k] is not None])
        else:
            for m in PROFILE_GRID[n]:
                spec = with_effects(spec0, ((n, m),))
                groups[f"{n}@{m}"] = (spec, [(f"{k}|{n}@{m}", ds.gait, bases[k]) for k, ds in datasets.items()
                                             if bases[k] is not None])
    kw = dict(root=root, use_cache=use_cache, objective=objective, **sweep_kw)
    res = solve_many(groups, **kw) if groups else {}
    recs = res.get("__records__", {})
    # the retry: failed or worse-than-baseline nested candidates from the other starts
    retry = {}
    if alternates:
        for n in names:
            e = effects_mod.EFFECTS[n]
            if not (e.resolve and e.identify == "nlp"):
                continue
            spec = with_effects(spec0, ((n, None),))
            jobs = [(f"{k}|{n}|{st}", ds.gait, alt) for k, ds in datasets.items()
                    if bases[k] is not None and needs_retry(n, res.get(f"{k}|{n}"), bases[k])
                    for st, alt in (alternates.get(k) or {}).items() if alt is not None and alt is not bases[k]]
            if jobs:
                retry[f"{n}|retry"] = (spec, jobs)
    if retry:
        res.update({k: v for k, v in solve_many(retry, **kw).items() if k != "__records__"})

    def tried(k, n):
        t = {"best": res.get(f"{k}|{n}")}
        for st in list((alternates or {}).get(k) or {}) + ["null"]:
            if res.get(f"{k}|{n}|{st}") is not None:
                t[st] = res[f"{k}|{n}|{st}"]
        return t

    # the null start: a nested candidate still failed or above the baseline after every start
    null = {}
    if null_start:
        for n in names:
            e = effects_mod.EFFECTS[n]
            if not (e.resolve and _nested(e)):
                continue
            jobs = [(f"{k}|{n}|null", ds.gait, bases[k]) for k, ds in datasets.items()
                    if bases[k] is not None and needs_retry(n, pick_best(list(tried(k, n).values())), bases[k])]
            if jobs:
                null[f"{n}|null"] = (with_effects(spec0, ((n, None),)), jobs)
    if null:
        res.update({k: v for k, v in null_start_many(null, **kw).items() if k != "__records__"})
    out = {}
    for k, ds in datasets.items():
        fits = {}
        for n in names:
            e = effects_mod.EFFECTS[n]
            if not e.resolve:
                fits[n] = _comparison_fit(n, bases[k], ds)
            elif e.identify == "nlp":
                t = tried(k, n)
                sol = pick_best(list(t.values())) or lowest_objective(list(t.values()))
                start = "baseline"
                if sol is not None:
                    key = next(st for st, s in t.items() if s is sol)
                    if len(t) > 1:
                        sol.stats["retry_start"] = key
                    start = "baseline" if key == "best" else key
                fits[n] = _nlp_fit(n, sol, ds, error=n in recs and bool(recs[n].error))
                fits[n].start = start
                if ((warms or {}).get(k) or {}).get(n) is not None:
                    fits[n].continuation = t["best"]
                if _nested(e) and bases[k] is not None and needs_retry(n, sol, bases[k]):
                    fits[n].search = "failed search"
            else:
                prof, best = [], None
                for m in PROFILE_GRID[n]:
                    sol = res.get(f"{k}|{n}@{m}")
                    st, ok = _status(sol)
                    if sol is None:
                        prof.append((m, np.nan, st))
                        continue
                    th = sol.stats.get("effects", {})
                    loc = locate.locate(sol, ds, thetas=th)
                    prof.append((m, loc.rss, st))
                    if ok and (best is None or loc.rss < best[2].rss):
                        best = (sol, th, loc, st)
                if best is None:
                    fits[n] = Fit(n, None, {}, None, e.n_params, e.identify, "no converged profile point", False, prof)
                else:
                    fits[n] = Fit(n, best[0], best[1], best[2], e.n_params, e.identify, best[3], True, prof)
        out[k] = fits
    return out


def alternates_of(detail: dict) -> dict:
    """key → {start: solution} of the baseline's starts other than the kept one, from
    :func:`baseline_fits` with ``detail=True``."""
    return {k: {st: s for st, s in per.items() if st != "best" and s is not None and s is not per.get("best")}
            for k, per in detail.items()}


def with_effects(spec0, effects) -> gait_ocp.GaitSpec:
    import dataclasses

    return dataclasses.replace(spec0, effects=tuple(effects))


def _comparison_fit(name: str, base_sol, ds) -> Fit:
    """Comparison-only effect: bounded scalar search of the gap on the baseline solution."""
    from scipy.optimize import minimize_scalar

    e = effects_mod.EFFECTS[name]
    p = e.magnitude
    sim = locate.sim_channels(base_sol, ds.gait.source)

    def rss(v):
        th = e.null_theta()
        th[p.name] = float(v)
        return locate.locate(sim, ds, thetas={name: th}).rss

    r = minimize_scalar(rss, bounds=(p.lower, p.upper), method="bounded", options={"xatol": 1e-4})
    # the null value is a member of the search range: kept when the search ends above it
    x = float(r.x) if float(r.fun) <= rss(p.null) else float(p.null)
    th = e.null_theta()
    th[p.name] = x
    loc = locate.locate(sim, ds, thetas={name: th})
    return Fit(name, base_sol, {name: th}, loc, e.n_params, e.identify, "Solve_Succeeded (comparison only)", True,
               start="baseline (no re-solve)")


# ======================================================================================
# The entry point
# ======================================================================================

def diagnose(data, *, base=None, effects=None, objective: str = "fit", warm=None, solution=None, like=None,
             fill_from=None, n_subjects: int | None = None, resamples: int = 200, seed: int = 0, root=None,
             use_cache: bool = True, reference=None, calibration: dict | None = None, **sweep_kw) -> Diagnosis:
    """Diagnose the sim-to-real gap of a baseline model on a data set.

    Parameters
    ----------
    data : a tidy CSV (``gaitlib.data`` format; read by :func:`gaitlib.gap.io.read_data`),
        a :class:`~gaitlib.gap.io.DataSet` or a :class:`~gaitlib.data.GaitData`.
    base : baseline :class:`~gaitlib.problems.gait.GaitSpec` or its fields (default
        :data:`DEFAULT_BASE`: SK, DT, 10 × 3 LGR); its speed class must match the data's
        speed and cycle time.
    effects : candidate names (default: every applicable effect of :data:`EFFECTS`).
    objective : ``"fit"`` (default) or ``"cost"`` (the spec's cost function), see
        :mod:`gaitlib.gap.solve`.
    warm : a solution to warm-start the baseline fit from (one of :data:`BASELINE_STARTS`).
    solution : a solution (e.g. a thesis chapter's) whose own gap is also located and reported.
    like, fill_from, n_subjects : passed to :func:`gaitlib.gap.io.read_data` (``n_subjects``:
        the subjects behind the data's means; required for a CSV of a source the project
        does not know unless it has an ``n_subjects`` column).
    resamples, seed : data resampling for the % closed intervals.
    root, use_cache : the solutions cache.
    reference : a reference data set (CSV, DataSet or GaitData; same speed class and time
        grid): diagnose the *change* from it instead of the whole gap
        (:mod:`gaitlib.gap.reference`) — the baseline and every candidate are fitted to the
        reference as in an absolute diagnosis (every start of :data:`BASELINE_STARTS`, the
        retries); the data are fitted as their continuation (the baseline from the
        reference's fit only, each candidate from its own fit of the reference), and each
        located gap has that model's own residual on the reference subtracted; the top
        effect must also beat every candidate's ΔBIC on the reference's null draws
        (:func:`null_calibration`, :data:`gaitlib.gap.method.RELATIVE`).
        ``settings["reference"]`` names the reference, its multistart fit (``"fit"``), the
        self-consistent fit the data were located against (``"consistent_fit"``), the fits
        :func:`consistent_fits` moved (``"moved"``) and the null calibration;
        :attr:`Diagnosis.reference_fit` is the self-consistent fit.
    calibration : a ``null_calibration`` of an earlier diagnosis against the same reference,
        spec, candidates and subjects (checked), used instead of redoing it.
    **sweep_kw : ``scheduler``, ``n_workers``, ``serial``, ``progress`` of :func:`gaitlib.sweep.sweep`.

    Raises :class:`BaselineFailed` (with every start's IPOPT status) when no start of the
    baseline fit converged.
    """
    ds = as_dataset(data, like, fill_from, n_subjects)
    spec0 = base_spec(base)
    ref_info, ref_fit, ref = None, None, None
    if reference is not None:
        ref = as_dataset(reference, like, fill_from)
        gref.check_same_grid(ds, ref)  # before any solve
    kw = dict(sweep_kw)
    with sweep_mod.local_cluster(kw.pop("n_workers", None), scheduler=kw.pop("scheduler", None),
                                 serial=kw.get("serial", False)) as scheduler:  # one cluster for every sweep
        if ref is not None:
            rb = baseline_fits(spec0, {"reference": ref}, warm, objective=objective, root=root, use_cache=use_cache,
                               detail=True, scheduler=scheduler, **kw)
            ref_fit = rb["reference"]["best"]
            if ref_fit is None:
                raise BaselineFailed({f"reference {st}": s.stats["status"] for st, s in rb["reference"].items()
                                      if st != "best" and s is not None})
            ref_info = {"label": ref.label, "n_subjects": ref.n, "signature": ref.signature,
                        "fit": _stats(ref_fit), "data_label": ds.label, "data_n_subjects": ds.n}
        names, skipped = candidates(spec0, ds.gait, effects)
        if ref is None:
            b = baseline_fits(spec0, {"data": ds}, warm, objective=objective, root=root, use_cache=use_cache,
                              detail=True, scheduler=scheduler, **kw)
            base_sol = b["data"]["best"]
            if base_sol is None:
                raise BaselineFailed({st: s.stats["status"] for st, s in b["data"].items()
                                      if st != "best" and s is not None})
            all_fits = candidate_fits(spec0, {"data": ds}, {"data": base_sol}, names, objective=objective, root=root,
                                      use_cache=use_cache, alternates=alternates_of(b), scheduler=scheduler, **kw)
        else:
            for n, why in candidates(spec0, ref.gait, names)[1].items():  # both data sets must admit it
                skipped[n] = f"the reference: {why}"
            names = [n for n in names if n not in skipped]
            # the reference: every candidate fitted as in an absolute diagnosis (every start) …
            ref_fits = candidate_fits(spec0, {"reference": ref}, {"reference": ref_fit}, names, objective=objective,
                                      root=root, use_cache=use_cache, alternates=alternates_of(rb),
                                      scheduler=scheduler, **kw)["reference"]
            if RELATIVE.reference_from_candidates:
                # the baseline's fit of the reference from every nested candidate's: its
                # multistart can stop in a worse optimum than they reach (RELATIVE)
                mv = baseline_from_candidates(spec0, {"reference": ref.gait}, {"reference": ref_fit},
                                              {"reference": ref_fits}, _nlp_names(names), RELATIVE.consistency_margin,
                                              "reference-baseline-from", objective=objective, root=root,
                                              use_cache=use_cache, scheduler=scheduler, **kw)
                if "reference" in mv:
                    best, n = mv["reference"]
                    ref_info["fit_from_candidates"] = {"objective": [float(ref_fit.stats["objective"]),
                                                                     float(best.stats["objective"])], "from": n}
                    ref_fit = best
            ref_info["rss_reference"] = locate.locate(ref_fit, ref).rss
            # … and the data as its continuation: the baseline from the reference's fit only,
            # each candidate from its own fit of the reference (the same basin, so the fits
            # differ by the change, not by the local optimum a multistart lands in)
            b = baseline_fits(spec0, {"data": ds}, ref_fit, objective=objective, root=root, use_cache=use_cache,
                              detail=True, starts=("warm",), scheduler=scheduler, **kw)
            base_sol = b["data"]["best"]
            if base_sol is None and RELATIVE.baseline_fallback:  # the continuation failed
                fb = fallback_baselines(spec0, {"data": ds}, {"data": ref_fits}, names, objective=objective,
                                        root=root, use_cache=use_cache, scheduler=scheduler, **kw)
                base_sol = fb.get("data")
                ref_info["baseline_fallback"] = base_sol.stats["start"] if base_sol is not None else "failed"
            if base_sol is None:
                raise BaselineFailed({st: s.stats["status"] for st, s in b["data"].items()
                                      if st != "best" and s is not None})
            warms = {"data": {n: f.solution for n, f in ref_fits.items() if f.solution is not None}}
            all_fits = candidate_fits(spec0, {"data": ds}, {"data": base_sol}, names, objective=objective, root=root,
                                      use_cache=use_cache, warms=warms, scheduler=scheduler, **kw)
            base_cont, fits_cont = base_sol, all_fits["data"]  # the continuations, before the rounds
            # the self-consistent reference fit (RELATIVE.reference_rounds): each model's
            # reference fit re-solved from its data fit, the lower kept, the data continued again
            cons = consistent_fits(spec0, ref, ref_fit, ref_fits, {"data": ds}, {"data": base_sol}, all_fits, names,
                                   objective=objective, root=root, use_cache=use_cache, scheduler=scheduler,
                                   **kw)["data"]
            base_sol, all_fits["data"], all_fits["reference"] = cons["base"], cons["fits"], cons["ref_fits"]
            ref_info["moved"] = cons["moved"]
            ref_info["consistent_fit"] = _stats(cons["ref_fit"])
            ref_fit_start, ref_fit = ref_fit, cons["ref_fit"]  # the null draws start where the data did
            n_rel = gref.relative_n(ds.n, ref.n)
            if calibration is not None:  # computed before for this reference: checked, not redone
                want = {"relative_method_hash": RELATIVE.hash(), "reference_signature": ref.signature,
                        "n_subjects": n_rel, "spec": spec0.to_dict(), "candidates": list(names)}
                bad = [k for k, v in want.items() if calibration.get(k) != v]
                if bad:
                    raise ValueError(f"calibration= was made for another {', '.join(bad)}: not this diagnosis's")
                calib = calibration
            else:
                calib = null_calibration(spec0, ref, ref_fit_start, ref_fits, names, n_rel, warms,
                                         objective=objective,
                                         root=root, use_cache=use_cache, scheduler=scheduler,
                                         **kw) if RELATIVE.null_draws > 0 else None
    fits = all_fits["data"]
    threshold, min_share, centred = None, 0.0, False
    if ref is not None:
        alternates = None
        min_share, centred = RELATIVE.min_share_closed, RELATIVE.centred
        if RELATIVE.lowest_pair:  # each model's located pair: the final or the continuation, the lower
            pair, ref_fit, base_sol = lowest_baseline_pair(ds, ref, [("final", ref_fit, base_sol),
                                                                     ("continuation", ref_fit_start, base_cont)])
            ref_info["baseline_pair"] = pair
            alternates = continuation_pairs(ref_fits, fits_cont)
        ds = gref.relative_data(ds, ref, ref_fit)  # the same data and fits; the gap located relative to R
        fits = relative_fits(fits, all_fits["reference"], ds, ref, base_sol, alternates)
        ref_info["relative_method"] = RELATIVE.to_dict()
        ref_info["relative_method_hash"] = RELATIVE.hash()
        ref_info["null_calibration"] = calib
        t = calibration_dBIC(calib)
        if t is not None:
            threshold = min(BIC_THRESHOLD, t)
    settings = {"objective": objective, "candidates": names, "warm": warm is not None, "reference": ref_info}
    d = assemble(ds, spec0, base_sol, fits, objective=objective, resamples=resamples, seed=seed, skipped=skipped,
                 settings=settings, solution=solution, threshold=threshold, min_share=min_share, centred=centred)
    d.reference_fit = ref_fit
    return d


def calibration_dBIC(calib: dict | None) -> float | None:
    """The ΔBIC a stored null calibration sets as the threshold: its ``threshold_dBIC``
    (revision 5 on, :func:`gaitlib.gap.method.null_threshold`), or for a calibration made
    before it, the lowest ΔBIC of its draws (revisions 1–4's rule); None without one."""
    if not calib:
        return None
    return calib["threshold_dBIC"] if "threshold_dBIC" in calib else calib.get("lowest_dBIC")


def null_calibration(spec0, ref: gio.DataSet, ref_fit, ref_fits: dict, names, n: int, warms: dict, *,
                     objective="fit", root=None, use_cache=True, method=None, **sweep_kw) -> dict:
    """The relative diagnosis's null calibration (:class:`gaitlib.gap.method.RelativeMethod`):
    the reference redrawn ``method.null_draws`` times within the sampling error of a
    difference of two group means of ``n`` subjects (:func:`gaitlib.gap.reference.null_draw`),
    each draw fitted and located relative to the reference exactly as the data are (the
    baseline from the reference's fit, each candidate from its own fit of the reference),
    and every ranked candidate's ΔBIC kept. Returns ``{"draws", "seeds", "n_subjects",
    "best" (per draw: its first-ranked effect, ΔBIC and located pair, or its failure), "dBIC" (per draw:
    effect → ΔBIC), "lowest_dBIC" (over draws and candidates; None if no draw was ranked),
    "rank", "centred" and "threshold_dBIC" (:func:`gaitlib.gap.method.null_threshold`),
    "baseline_failed" (draws none of whose baseline fits converged), "baseline_fallback" (draw →
    the fallback start of a failed continuation) and "baseline_pair" (draw → the baseline's
    located pair, ``method.lowest_pair``)}``."""
    method = method or RELATIVE
    seeds = [gref.null_seed(ref, j, method.hash()) for j in range(method.null_draws)]
    draws = {f"null{j}": gref.null_draw(ref, n, sd) for j, sd in enumerate(seeds)}
    kw = dict(objective=objective, root=root, use_cache=use_cache, **sweep_kw)
    bases = baseline_fits(spec0, draws, ref_fit, starts=("warm",), **kw)
    failed = {k: draws[k] for k in draws if bases[k] is None}
    fallback = {}
    if failed and method.baseline_fallback:  # as the data's (diagnose)
        fb = fallback_baselines(spec0, failed, {k: ref_fits for k in failed}, names, **kw)
        bases.update(fb)
        fallback = {k: s.stats["start"] for k, s in fb.items()}
    ok = {k: v for k, v in draws.items() if bases[k] is not None}
    nf = candidate_fits(spec0, ok, bases, names, warms={k: warms["data"] for k in ok}, **kw) if ok else {}
    cons = consistent_fits(spec0, ref, ref_fit, ref_fits, ok, bases, nf, names, method=method, **kw) if ok else {}
    best, per, pairs = [], [], {}
    for k, dk in draws.items():
        if bases[k] is None:
            best.append({"draw": k, "effect": "baseline failed", "dBIC": None})
            per.append({})
            continue
        c = cons[k]
        rf, base, alt = c["ref_fit"], c["base"], None
        if method.lowest_pair:  # as the data's (diagnose)
            pairs[k], rf, base = lowest_baseline_pair(dk, ref, [("final", rf, base),
                                                                ("continuation", ref_fit, bases[k])])
            alt = continuation_pairs(ref_fits, nf[k])
        rel = gref.relative_data(dk, ref, rf)
        d = assemble(rel, spec0, base, relative_fits(c["fits"], c["ref_fits"], rel, ref, base, alt),
                     objective=objective, resamples=0)
        r = d.ranking[d.ranking["ok"].astype(bool) & np.isfinite(d.ranking["dBIC"].astype(float))]
        per.append({str(e): float(v) for e, v in zip(r["effect"], r["dBIC"])})
        best.append({"draw": k, "effect": str(r.iloc[0]["effect"]) if len(r) else None,
                     "dBIC": float(r.iloc[0]["dBIC"]) if len(r) else None,
                     "pair": str(r.iloc[0]["pair"]) if len(r) else None})
    vals = [v for p in per for v in p.values()]
    return {"relative_method_hash": method.hash(), "reference_signature": ref.signature, "spec": spec0.to_dict(),
            "candidates": list(names), "draws": method.null_draws, "seeds": seeds, "n_subjects": n, "best": best,
            "dBIC": per,
            "lowest_dBIC": min(vals) if vals else None, "rank": method.null_rank,
            "threshold_dBIC": null_threshold(per, method.null_rank, method.centred),
            "centred": method.centred,
            "baseline_failed": [b["draw"] for b in best if b["effect"] == "baseline failed"],
            "baseline_fallback": fallback,
            "baseline_pair": pairs,  # RELATIVE.lowest_pair: per draw, the baseline's located pair
            "moved": {k: c["moved"] for k, c in cons.items()}}


def _better(new, old, margin: float) -> bool:
    """``new`` converged with an objective below ``old``'s by more than ``margin`` (relative);
    any converged ``new`` is better than a missing or non-converged ``old``."""
    if new is None or not _status(new)[1]:
        return False
    if old is None or not _status(old)[1]:
        return True
    f0 = float(old.stats["objective"])
    return float(new.stats["objective"]) < f0 - margin * abs(f0)


def _nlp_names(names) -> list:
    """The candidates among ``names`` whose parameters the NLP identifies (a profile or
    comparison-only effect has no fit of its own to start from)."""
    return [n for n in names if effects_mod.EFFECTS[n].resolve and effects_mod.EFFECTS[n].identify == "nlp"]


def baseline_from_candidates(spec0, gaits: dict, bases: dict, fits: dict, names, margin: float, label: str,
                             **kw) -> dict:
    """The baseline re-solved from its nested candidates' fits (:func:`_nested`: the baseline
    is a member of each, so a candidate's optimum with its parameter at the null value is a
    start the baseline can reach). For each key of ``gaits`` (key → gait data, with the
    baseline's fit ``bases[key]`` and the candidates' fits ``fits[key]``, name → :class:`Fit`),
    the baseline is solved on the gait from every converged fit of ``names`` and the lowest
    kept where it is below ``bases[key]``'s objective by more than ``margin`` (relative,
    :func:`_better`). Returns key → (solution, the candidate it started from), only for the
    keys that moved. ``label``: the sweep group's name."""
    jobs = [(f"{k}|{n}", g, fits[k][n].solution) for k, g in gaits.items() if bases.get(k) is not None
            for n in names if _nested(effects_mod.EFFECTS[n]) and (fits.get(k) or {}).get(n) is not None
            and fits[k][n].solution is not None and _status(fits[k][n].solution)[1]]
    res = solve_many({label: (spec0, jobs)}, **kw) if jobs else {}
    out = {}
    for k in gaits:
        tried = {n: res[f"{k}|{n}"] for n in names if res.get(f"{k}|{n}") is not None}
        best = pick_best(list(tried.values()))
        if _better(best, bases.get(k), margin):
            out[k] = (best, next(n for n, s in tried.items() if s is best))
    return out


def fallback_baselines(spec0, datasets: dict, ref_fits: dict, names, **kw) -> dict:
    """The baseline's fit of data sets whose continuation from the reference's fit did not
    converge (:class:`gaitlib.gap.method.RelativeMethod` ``baseline_fallback``): for each key
    of ``datasets`` (key → DataSet, with ``ref_fits[key]``, name → :class:`Fit`, the
    candidates' fits of the reference) the baseline is solved on the data from every nested
    candidate's converged fit of the reference (:func:`_nested`: starts in the reference's
    basin, as the continuation was) and the lowest converged kept; where none converges, from
    the absolute multistart's starts (:data:`BASELINE_STARTS` but ``warm``). Returns key →
    solution for the keys a fallback reached, ``stats["start"]`` naming it (``"reference
    fit of <candidate>"`` or ``"multistart <start>"``); keys with no converged fallback are
    left out."""
    nlp = _nlp_names(names)
    jobs = [(f"{k}|{n}", ds.gait, ref_fits[k][n].solution) for k, ds in datasets.items() for n in nlp
            if _nested(effects_mod.EFFECTS[n]) and (ref_fits.get(k) or {}).get(n) is not None
            and ref_fits[k][n].solution is not None and _status(ref_fits[k][n].solution)[1]]
    res = solve_many({"baseline-fallback": (spec0, jobs)}, **kw) if jobs else {}
    out, left = {}, {}
    for k, ds in datasets.items():
        tried = {n: res[f"{k}|{n}"] for n in nlp if res.get(f"{k}|{n}") is not None}
        best = pick_best(list(tried.values()))
        if best is None:
            left[k] = ds
            continue
        best.stats["start"] = "reference fit of " + next(n for n, s in tried.items() if s is best)
        out[k] = best
    if left:
        multi = baseline_fits(spec0, left, None, starts=tuple(s for s in BASELINE_STARTS if s != "warm"), **kw)
        for k, s in multi.items():
            if s is not None:
                s.stats["start"] = "multistart " + s.stats["start"]
                out[k] = s
    return out


def consistent_fits(spec0, ref: gio.DataSet, ref_fit, ref_fits: dict, datasets: dict, bases: dict, fits: dict,
                    names, *, method=None, **kw) -> dict:
    """The self-consistent reference fit of a relative diagnosis
    (:class:`gaitlib.gap.method.RelativeMethod` ``reference_rounds``).

    For every data set (key → DataSet, with its baseline fit ``bases[key]`` and candidate fits
    ``fits[key]``, both continued from the reference's fits ``ref_fit``/``ref_fits``), each
    model's fit of the reference is re-solved from its fit of the data — the baseline and
    every NLP-identified candidate (a profile candidate keeps its grid fits). Where that
    reaches a lower objective on the reference by more than ``method.consistency_margin``
    (relative), it replaces the model's fit of the reference *for that data set*, and the
    data are continued again from it; the lower of the two data fits is kept. A further
    round re-solves only the models whose data fit moved. First (``method.
    baseline_from_candidates``), the baseline's fit of the data is re-solved from every
    nested candidate's fit of it (:func:`_nested`: the baseline is a member of each) and the
    lowest kept if lower than the continuation's — a baseline stopped in a worse optimum
    than its own extensions reach would credit every candidate with closing the difference.

    Returns key → ``{"ref_fit", "ref_fits", "base", "fits", "moved"}``: the baseline's and
    the candidates' fits of the reference and of the data after the rounds, and per model
    that moved, ``{"reference": [objective before, after], "data": [before, after]}`` (the
    baseline re-fitted from a candidate's fit: ``"data"`` and ``"data_from"``, the candidate;
    a later move of its data fit: ``"data_again"``)."""
    method = method or RELATIVE
    margin = method.consistency_margin
    nlp = _nlp_names(names)
    out = {k: {"ref_fit": ref_fit, "ref_fits": dict(ref_fits), "base": bases.get(k), "fits": dict(fits.get(k) or {}),
               "moved": {}} for k in datasets}

    def spec_of(m):
        return spec0 if m == "baseline" else with_effects(spec0, ((m, None),))

    def data_sol(o, m):
        return o["base"] if m == "baseline" else (o["fits"][m].solution if o["fits"].get(m) is not None else None)

    def ref_sol(o, m):
        return o["ref_fit"] if m == "baseline" else (o["ref_fits"][m].solution if o["ref_fits"].get(m) is not None
                                                     else None)

    if method.baseline_from_candidates:
        # the baseline's fit of the data from every nested candidate's (a member of each):
        # the continuation from the reference's fit can stop in a worse optimum than they reach
        moved = baseline_from_candidates(spec0, {k: datasets[k].gait for k in out}, {k: o["base"] for k, o in out.items()},
                                         {k: o["fits"] for k, o in out.items()}, nlp, margin,
                                         "consistency-N-baseline-from", **kw)
        for k, (best, n) in moved.items():
            o = out[k]
            o["moved"]["baseline"] = {"data": [float(o["base"].stats["objective"]), float(best.stats["objective"])],
                                      "data_from": n}
            o["base"] = best
    todo = {(k, m) for k in datasets for m in ["baseline", *nlp]}
    for _ in range(method.reference_rounds):
        groups: dict = {}
        for k, m in sorted(todo):
            if data_sol(out[k], m) is not None and ref_sol(out[k], m) is not None:
                groups.setdefault(m, (spec_of(m), []))[1].append((f"{k}|{m}", ref.gait, data_sol(out[k], m)))
        res = solve_many({f"consistency-R-{m}": g for m, g in groups.items()}, **kw) if groups else {}
        again: dict = {}
        for k, m in sorted(todo):
            new, o = res.get(f"{k}|{m}"), out[k]
            if not _better(new, ref_sol(o, m), margin):
                continue
            o["moved"].setdefault(m, {})["reference"] = [float(ref_sol(o, m).stats["objective"]),
                                                         float(new.stats["objective"])]
            if m == "baseline":
                o["ref_fit"] = new
            else:
                o["ref_fits"][m] = _nlp_fit(m, new, ref)
                o["ref_fits"][m].start = "data"
            again.setdefault(m, (spec_of(m), []))[1].append((f"{k}|{m}", datasets[k].gait, new))
        res = solve_many({f"consistency-N-{m}": g for m, g in again.items()}, **kw) if again else {}
        todo = set()
        for m, (_, jobs) in again.items():
            for key, _, _ in jobs:
                k = key.rsplit("|", 1)[0]
                new, o = res.get(key), out[k]
                if not _better(new, data_sol(o, m), margin):
                    continue
                o["moved"][m]["data" if "data" not in o["moved"][m] else "data_again"] = [
                    float(data_sol(o, m).stats["objective"]), float(new.stats["objective"])]
                if m == "baseline":
                    o["base"] = new
                else:
                    o["fits"][m] = _nlp_fit(m, new, datasets[k])
                    o["fits"][m].start = "reference (consistent)"
                todo.add((k, m))
        if not todo:
            break
    return out


def relative_fits(fits: dict, ref_fits: dict, ds: gio.DataSet, ref: gio.DataSet, base_sol,
                  alternates: dict | None = None) -> dict:
    """The candidates' fits of the data located relative to the reference, each against its
    *own* fit of the reference (:mod:`gaitlib.gap.reference`): candidate k's located gap is
    [F_k(N) − N_k] − [F_k(R) − R_k] (N_k, R_k: the data as k reads them at its parameters on
    each), so an effect that explains part of the reference's own gap is not credited with it,
    and an effect whose parameter change is the whole change between R and N closes the gap.
    A candidate without a fit of the reference is not located (``located=None``, not ranked).
    ``Fit.reference_thetas``: the candidate's parameters on the reference, so the ranking's
    ``parameter_change`` is the change the candidate identifies between R and N.
    Comparison-only effects are searched again on the relative data (on ``base_sol``).
    ``alternates`` (name → [(label, its fit of the reference (:class:`Fit`), a converged fit
    of the data)]; :func:`continuation_pairs`): other pairs of the candidate's fits, each
    located the same way; the pair with the lowest RSS is kept (``Fit.pair`` names it;
    :class:`gaitlib.gap.method.RelativeMethod` ``lowest_pair``)."""
    import dataclasses

    out = {}
    for n, f in fits.items():
        fr = ref_fits.get(n)
        f = dataclasses.replace(f)
        if fr is None or fr.solution is None:
            f.located, f.ok = None, False
            f.status = f"{f.status}; no fit of the reference"
            out[n] = f
            continue
        bg = gref.background(ref, fr.solution, fr.thetas)
        dk = dataclasses.replace(ds, background=bg)
        if not effects_mod.EFFECTS[n].resolve:
            out[n] = dataclasses.replace(_comparison_fit(n, base_sol, dk), reference_thetas=fr.thetas)
            continue
        f.reference_thetas = fr.thetas
        f.located = locate.locate(f.solution, dk, thetas=f.thetas) if f.solution is not None else None
        if not fr.ok:
            f.ok = False
            f.status = f"{f.status}; reference fit {fr.status}"
        for label, ar, asol in (alternates or {}).get(n, ()):
            if f.located is None or not (f.ok and ar.ok):
                break
            if asol is f.solution and ar.solution is fr.solution:  # the final pair itself
                continue
            th = asol.stats.get("effects", {})
            loc = locate.locate(asol, dataclasses.replace(ds, background=gref.background(ref, ar.solution, ar.thetas)),
                                thetas=th)
            if loc.rss < f.located.rss:
                f = dataclasses.replace(f, solution=asol, thetas=th, located=loc, reference_thetas=ar.thetas,
                                        pair=label, start="reference")
        out[n] = f
    return out


def continuation_pairs(ref_fits: dict, fits: dict) -> dict:
    """The continuation pair of every NLP candidate of a relative diagnosis, for
    :func:`relative_fits` ``alternates``: its first fit of the reference (``ref_fits``,
    before the self-consistency rounds) and the data's fit continued from it
    (``Fit.continuation`` of ``fits``, the data's fits before the rounds) — where that fit
    converged (the same data fit as the final pair's counts: the rounds may have moved only
    the fit of the reference). name → [("continuation", Fit, solution)]."""
    out = {}
    for n, f in fits.items():
        c, fr = f.continuation, ref_fits.get(n)
        if c is None or fr is None or fr.solution is None or not _status(c)[1]:
            continue
        out[n] = [("continuation", fr, c)]
    return out


def lowest_baseline_pair(ds: gio.DataSet, ref: gio.DataSet, pairs: list) -> tuple:
    """Of the baseline's (label, fit of the reference, fit of the data) ``pairs`` (the first
    the final pair), the one whose gap located relative to the reference
    (:func:`gaitlib.gap.reference.relative_data`) has the lowest RSS; pairs with a missing
    or non-converged fit are skipped. Returns (label, reference fit, data fit)."""
    best = None
    for label, rf, bs in pairs:
        if rf is None or bs is None or not (_status(bs)[1] and _status(rf)[1]):
            continue
        rss = locate.locate(bs, gref.relative_data(ds, ref, rf)).rss
        if best is None or rss < best[0]:
            best = (rss, label, rf, bs)
    return best[1:]


# ``gaitlib.gap.diagnose(...)`` calls :func:`diagnose` even after this submodule was imported
# (gaitlib.gap._CallableModule).
from . import _callable  # noqa: E402

_callable("diagnose")
