"""Twins: synthetic data sets with a known, injected effect, in the tidy format.

A twin of a real data set (default Schwartz 2008 *Free*) is the baseline model with one
effect (or two) switched on at a chosen magnitude, solved tracking the real data: its
channels become the synthetic group mean, the real data's SD its SD, and smooth noise of
standard deviation SD/√n (n: the real data's subjects) is added — the uncertainty of a
group mean of n children. Like the real data it has one leg (``ipsilateral``: the right
leg of the solution); the reader generates the left leg from it with the data's time shift
(thesis Sec 4.2.3), exactly as for the real data.

Quantities written: pelvic tilt (the real data's: the model's upright HAT has no anatomical
pelvis angle), hip/knee/ankle angles (the hip as the data's hip angle = thigh angle in the
laboratory − pelvic tilt), the three net joint moments, the two GRF components and, for
MSK/NMSK baselines, the EMG channels of the real data set's muscles (NMSK excitations, MSK
generator activations). ``source`` is ``twin(<real source>)``; the truth (effect,
magnitude, seed) goes to a separate JSON file that the diagnosis never reads.

Noise: a periodic Gaussian process per quantity with a squared-exponential correlation of
length :data:`NOISE_LENGTH` (fraction of the cycle; group-mean curves are smooth) and
marginal SD = SD(τ)/√n — :func:`smooth_noise`.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from .. import conventions as cv
from .method import DEFAULT_BASE  # the twins' baseline is the diagnosis's
from .noise import NOISE_LENGTH, smooth_noise
from ..problems import gait as gait_ocp
from . import io as gio
from . import locate
from ..effects import EFFECTS
from .locate import sim_channels
from .solve import solve_on
from ..ocp import SolveFailedError
from ..sweep import ACCEPTED_STATUSES
from . import diagnose
from .solve import solve_many
from ..effects import TWIN_EFFECTS
from .diagnose import BIC_THRESHOLD
from .method import RUNNER_UP_MARGIN

__all__ = ["NOISE_LENGTH", "smooth_noise", "twin_spec", "twin_frame", "make_twin", "write_twin", "DEFAULT_BASE"]


def twin_spec(effects: tuple, base: dict | None = None) -> gait_ocp.GaitSpec:
    """The spec that generates a twin: the baseline with ``effects`` ((name, magnitude), …)."""
    base = dict(DEFAULT_BASE if base is None else base)
    return gait_ocp.GaitSpec(**base, effects=tuple(effects))


_ANGLE_Q = {"hip": "hip_flexion", "knee": "knee_flexion", "ankle": "ankle_dorsiflexion"}
_MOMENT_Q = {"hip": "hip_extensor_moment", "knee": "knee_extensor_moment", "ankle": "ankle_plantarflexor_moment"}


def twin_frame(sol: gait_ocp.GaitSolution, real: gio.DataSet, seed: int | None, *, noise: bool = True,
               length: float = NOISE_LENGTH) -> pd.DataFrame:
    """The tidy rows of a twin from a solved model (both legs, sides ``R``/``L``; 51 points;
    data units and signs).

    SD = the real data's SD of the same channel (left leg: the real data's, as generated);
    noise as :func:`smooth_noise` × SD/√n (``seed``; ``noise=False``: the clean curves)."""
    gait = real.gait
    sim = sim_channels(sol, gait.source)
    tau = np.linspace(0.0, 1.0, 51)
    ts = sim.index.to_numpy(float)
    t_data = np.asarray(gait.time, float) / float(gait.cycle_time)

    # a comparison-only effect changes no solution, only how the data relate to it: the twin
    # carries it in its data — activation timing Δd: the model's activation at t is the
    # data's EMG at t − Δd, so the twin's EMG at t is the activation at t + Δd
    lead = sum(float(m) for n, m in getattr(sol.spec, "effects", ()) if n == "activation_timing" and m is not None)
    lead /= float(gait.cycle_time)

    def at(col, shift=0.0):
        ext = np.concatenate([ts - 1.0, ts, ts + 1.0])
        return np.interp(np.mod(tau + shift, 1.0), ext, np.tile(sim[col].to_numpy(), 3))

    def real_sd(col):
        return np.interp(tau, t_data, gait.sd[col].to_numpy())

    pelvis_model = np.interp(tau, t_data, gait.mean["pelvis_tilt"].to_numpy())
    values, sd = {}, {}
    stems = [(j, q) for j, q in _ANGLE_Q.items()] + [(f"tau_{j}", q) for j, q in _MOMENT_Q.items()] \
        + [("grf_x", "grf_anterior"), ("grf_y", "grf_vertical")]
    for s_, side in (("r", "R"), ("l", "L")):
        for stem, q in stems:
            v = at(f"{stem}_{s_}")
            if stem == "hip":  # q_hip is the thigh in the laboratory; the data's hip is relative to the pelvis
                v = cv.hip_from_thigh(v, pelvis_model)
            values[(q, side)] = gio.model_to_data_units(stem, v, gait.body_mass)
            sd[(q, side)] = np.abs(gio.model_to_data_units(stem, real_sd(f"{stem}_{s_}"), gait.body_mass))
        for c in sim.columns:
            if c.startswith("emg_") and c.endswith(f"_{s_}") and c in gait.sd.columns:
                values[(c[:-2], side)] = at(c, lead)
                sd[(c[:-2], side)] = real_sd(c)
    if noise:
        rng = np.random.default_rng(seed)
        keys = list(values)
        g = smooth_noise(rng, len(keys), length)(tau)
        g[:, -1] = g[:, 0]  # 100 % = 0 %
        for i, k in enumerate(keys):
            values[k] = values[k] + g[i] * sd[k] / np.sqrt(max(real.n, 1))
    values[("pelvis_anterior_tilt", "ipsilateral")] = gio.model_to_data_units("pelvis_tilt", pelvis_model,
                                                                               gait.body_mass)
    sd[("pelvis_anterior_tilt", "ipsilateral")] = np.abs(gio.model_to_data_units(
        "pelvis_tilt", real_sd("pelvis_tilt"), gait.body_mass))
    return gio.to_tidy(values, sd, f"twin({real.base})", gait.speed_class, tau * 100)


def make_twin(effects, seed: int = 0, *, base: dict | None = None, real: gio.DataSet | None = None,
              root=None, use_cache: bool = True, noise: bool = True,
              objective: str = "fit") -> tuple[pd.DataFrame, dict]:
    """A twin data set: (tidy DataFrame, truth dict).

    Parameters
    ----------
    effects : ((name, magnitude), …) — one effect, two, or none (the baseline's own twin).
    seed : noise seed.
    base : baseline spec fields (default :data:`DEFAULT_BASE`: SK, DT, 10 × 3 LGR).
    real : the real data set (default Schwartz 2008 of the baseline's speed class).
    objective : ``"fit"`` (the model with the effect fitted to the real data) or ``"cost"``
        (the spec's cost function), :mod:`gaitlib.gap.solve`.
    """
    spec = twin_spec(effects, base)
    real = real or gio.load_real(spec.speed_class, spec.source)
    sol = solve_on(spec, real.gait, root=root, use_cache=use_cache, objective=objective)
    frame = twin_frame(sol, real, seed, noise=noise)
    truth = {"effects": [[n, m] for n, m in effects], "seed": seed, "base": spec.to_dict(),
             "real": real.label, "n_subjects": real.n, "noise_length": NOISE_LENGTH,
             "status": sol.stats["status"], "iterations": sol.stats["iterations"],
             "objective": sol.stats["objective"], "objective_kind": objective}
    return frame, truth


def write_twin(path, effects, seed: int = 0, **kw) -> Path:
    """Write a twin's tidy CSV to ``path`` and its truth to ``<path stem>.truth.json``.
    Raises :class:`gaitlib.ocp.SolveFailedError` (nothing written) when the generating solve
    did not converge: its curves are not the model's gait."""
    frame, truth = make_twin(effects, seed, **kw)
    if truth["status"] not in ACCEPTED_STATUSES:
        raise SolveFailedError(f"the twin's generating solve did not converge ({truth['status']}, "
                               f"{truth['iterations']} iterations): no twin written")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    frame.to_csv(path, index=False, float_format="%.8g")
    path.with_suffix(".truth.json").write_text(json.dumps(truth, indent=1, default=str))
    return path


# ======================================================================================
# Validation: the diagnosis on twins whose effect is withheld
# ======================================================================================

#: Objective that generates twins: the spec's own cost function (a smooth, thesis-like gait
#: of the model with the effect on the real data).
GEN_OBJECTIVE = "cost"


def validate_twins(effects=None, *, magnitudes: dict | None = None, seeds=(1,), base: dict | None = None,
                   real: gio.DataSet | None = None, objective: str = "fit", gen_objective: str = GEN_OBJECTIVE,
                   out_dir=None, root=None, use_cache: bool = True, resamples: int = 0, **sweep_kw):
    """Generate twins (each effect × magnitude × seed, plus the effect-free twin of each
    seed), diagnose each with the baseline model only, and score the diagnosis.

    Returns a :class:`TwinValidation`; a twin none of whose baseline starts converged is not
    diagnosed: its row says ``top = "baseline failed"`` (a miss) and
    ``settings["baseline_failed"]`` lists its starts' statuses. Cost: (#twins + #seeds)
    twin solves, the baseline fits per twin (:data:`gaitlib.gap.diagnose.BASELINE_STARTS`:
    up to 8 solves), one re-solve per candidate per twin (and, for a candidate that fails
    or ends above the baseline, one per other baseline start), all through
    :func:`gaitlib.sweep.sweep` (one item per spec, built once and re-solved on every twin
    by swapping the NLP's data).
    """
    effects = tuple(effects or TWIN_EFFECTS_DEFAULT())
    base = dict(DEFAULT_BASE if base is None else base)
    spec0 = gait_ocp.GaitSpec(**base)
    real = real or gio.load_real(spec0.speed_class, spec0.source)
    mags = {e: tuple(magnitudes[e]) if magnitudes and e in magnitudes else EFFECTS[e].twin_magnitudes for e in effects}
    # 1. generate: one solve per (effect, magnitude) and the effect-free one
    gen = {"none": ()}
    for e in effects:
        for i, m in enumerate(mags[e]):
            gen[f"{e}@{i}"] = ((e, m),)
    groups = {k: (twin_spec(v, base), [(f"gen|{k}", real.gait, None)]) for k, v in gen.items()}
    res = solve_many(groups, root=root, use_cache=use_cache, objective=gen_objective, **sweep_kw)
    out_dir = Path(out_dir) if out_dir is not None else None
    datasets, truth = {}, {}
    gen_stats = {}
    for k, v in gen.items():
        sol = res.get(f"gen|{k}")
        gen_stats[k] = {"status": sol.stats["status"] if sol is not None else "error",
                        "iterations": sol.stats.get("iterations") if sol is not None else None,
                        "solve_time_s": sol.stats.get("solve_time_s") if sol is not None else None}
        if sol is None:
            continue
        for seed in seeds:
            key = f"{k}#{seed}"
            frame = twin_frame(sol, real, seed)
            if out_dir is not None:
                out_dir.mkdir(parents=True, exist_ok=True)
                p = out_dir / f"twin_{k.replace('@', '_m')}_s{seed}.csv"
                frame.to_csv(p, index=False, float_format="%.8g")
                datasets[key] = gio.read_data(p)
            else:
                import tempfile

                with tempfile.TemporaryDirectory() as td:
                    p = Path(td) / "twin.csv"
                    frame.to_csv(p, index=False, float_format="%.8g")
                    datasets[key] = gio.read_data(p)
            truth[key] = {"effects": v, "seed": seed, "level": (int(k.split("@")[1]) if "@" in k else None)}
    # 2. the baseline fits (every start of diagnose.BASELINE_STARTS; warm: the baseline's fit of the real data)
    warm = solve_on(spec0, real.gait, root=root, use_cache=use_cache, objective=objective)
    detail = diagnose.baseline_fits(spec0, datasets, warm, objective=objective, root=root, use_cache=use_cache, detail=True,
                             **sweep_kw)
    bases = {k: v["best"] for k, v in detail.items()}
    # twins none of whose baseline starts converged have no baseline: no diagnosis, listed
    # in settings["baseline_failed"] with every start's status
    base_failed = {k: {st: s.stats["status"] for st, s in v.items() if st != "best" and s is not None}
                   for k, v in detail.items() if v["best"] is None}
    fitted = {k: ds for k, ds in datasets.items() if bases[k] is not None}
    # 3. candidates: every twin effect, re-solved on every twin (a failed or worse-than-
    #    baseline fit again from the baseline's other starts)
    names, _ = diagnose.candidates(spec0, next(iter(datasets.values())).gait, effects)
    fits = diagnose.candidate_fits(spec0, fitted, bases, names, objective=objective, root=root, use_cache=use_cache,
                            alternates=diagnose.alternates_of({k: detail[k] for k in fitted}), **sweep_kw) if fitted else {}
    # 4. the reference of the shrink: the true model (injected effect fixed at its injected
    #    magnitude) fitted by the same method (warm-started from the baseline fit), and the
    #    generating solution's own RSS (noise only)
    ref_groups = {}
    for key, ds in datasets.items():
        eff = truth[key]["effects"]
        if eff and bases[key] is not None:
            g = "true|" + key.split("#")[0]
            ref_groups.setdefault(g, (diagnose.with_effects(spec0, eff), []))[1].append((f"true|{key}", ds.gait, bases[key]))
    ref = solve_many(ref_groups, root=root, use_cache=use_cache, objective=objective, **sweep_kw) if ref_groups else {}
    diags, refs = {}, {}
    for key, ds in datasets.items():
        if bases[key] is None:
            continue
        diags[key] = diagnose.assemble(ds, spec0, bases[key], fits[key], objective=objective, resamples=resamples,
                                settings={"twin": key})
        sol_t = ref.get(f"true|{key}")
        gen_sol = res.get(f"gen|{key.split('#')[0]}")
        refs[key] = {"rss_gen": locate.locate(gen_sol, _as_generated(ds, truth[key]["effects"])).rss
                     if gen_sol is not None else np.nan,
                     "rss_true_fixed": locate.locate(sol_t, ds).rss if sol_t is not None else np.nan,
                     "status_true_fixed": sol_t.stats["status"] if sol_t is not None else ("n/a" if not truth[key]["effects"] else "error")}
    return TwinValidation.build(diags, truth, mags, gen_stats, refs=refs, settings={
        "base": spec0.to_dict(), "objective": objective, "gen_objective": gen_objective, "seeds": list(seeds),
        "effects": list(effects), "magnitudes": {e: list(v) for e, v in mags.items()}, "real": real.label,
        "n_subjects": real.n, "noise_length": NOISE_LENGTH, "baseline_failed": base_failed})


def _as_generated(ds: gio.DataSet, effects) -> gio.DataSet:
    """``ds`` read as its generating model sees it: a comparison-only effect (activation
    timing) is in the twin's data, not in the generating solution, so its data adjustment
    at the injected magnitude is applied before the generating solution's RSS is taken."""
    import dataclasses

    gait = ds.gait
    for n, m in effects or ():
        e = EFFECTS[n]
        if not e.resolve and e.data_adjust is not None and m is not None:
            gait = e.data_adjust(gait, {e.magnitude.name: float(m)})
    return ds if gait is ds.gait else dataclasses.replace(ds, gait=gait)


def _best_other(rk: pd.DataFrame, inj: str) -> float:
    """The lowest ΔBIC of the ranked, converged candidates other than ``inj`` (NaN: none)."""
    o = rk[(rk.index != inj) & rk["ok"].astype(bool) & np.isfinite(rk["dBIC"].astype(float))]
    return float(o["dBIC"].min()) if len(o) else np.nan


#: Target of the twin check: top-1 accuracy (%) at the middle magnitude.
TARGET_TOP1_PCT = 90.0
#: Target of the twin check: mean shrink of the injected gap (%, each twin capped at 100 %).
TARGET_SHRINK_PCT = 60.0


def TWIN_EFFECTS_DEFAULT():
    return TWIN_EFFECTS


class TwinValidation:
    """Scores of the diagnosis on twins.

    ``rows``: one per twin — injected effect and magnitude (level 0/1/2 = small/middle/
    large), seed, the diagnosis's top effect and verdict, correct (top = injected; for the
    effect-free twin: "unexplained"), the RSS of the baseline fit (``rss_base``), of the top
    effect's fit (``rss_top``), of the true effect's fit with its magnitude free
    (``rss_true``), and two references:

    ``rss_true_fixed``  the true model — the injected effect fixed at the injected magnitude
                        — fitted by the same method (same objective, mesh and warm start);
    ``rss_gen``         the generating solution itself against its twin (noise only,
                        ≈ N_points / n).

    Shrink of the injected gap (the measure of the issue's "done" criterion):
    ``shrink_injected_top`` = (RSS_base − RSS_top) / (RSS_base − RSS_true_fixed), the part
    of the gap that the true model closes under the same fitting method that the named
    effect closes (undefined — NaN — when the true model does not improve on the baseline
    fit, i.e. no gap was injected as far as the method can tell); ``shrink_vs_noise_top`` =
    (RSS_base − RSS_top) / (RSS_base − RSS_gen), a stricter figure that also counts the
    fitting method's own shortfall (coarse mesh, local optima) as unclosed gap;
    ``shrink_vs_free_twin`` = (RSS_base − RSS_top) / (RSS_base − RSS_0) with RSS_0 the
    baseline fit of the effect-free twin of the same seed (a different gait: noisy, kept
    for reference). ``_true`` variants use the true effect's fit instead of the top one.
    ``identified_magnitude``: the true effect's fitted magnitude. ``base_start``: the start
    of the kept baseline fit (:data:`gaitlib.gap.diagnose.BASELINE_STARTS`). ``retried``: how
    many candidate fits were re-solved from the baseline's other starts
    (:func:`gaitlib.gap.diagnose.candidate_fits`); ``true_start``: the start the injected
    effect's kept fit came from (``"best"``: the baseline fit itself). ``confusion``: injected
    × named counts.
    """

    def __init__(self, rows: pd.DataFrame, diags: dict, gen_stats: dict, settings: dict):
        self.rows, self.diags, self.gen_stats, self.settings = rows, diags, gen_stats, settings

    @classmethod
    def build(cls, diags, truth, mags, gen_stats, settings, refs=None):
        refs = refs or {}

        def pct(num, den):
            return 100.0 * num / den if np.isfinite(den) and den > 0 else np.nan

        rows = []
        for key, d in diags.items():
            t = truth[key]
            inj = t["effects"][0][0] if t["effects"] else "none"
            mag = t["effects"][0][1] if t["effects"] else 0.0
            seed = t["seed"]
            d0 = diags.get(f"none#{seed}")
            rss0 = d0.located.rss if d0 is not None else np.nan
            rk = d.ranking.set_index("effect")
            rss_b = d.located.rss
            rss_top = float(rk.loc[d.top_effect, "rss_after"]) if d.top_effect in rk.index else rss_b
            rss_true = float(rk.loc[inj, "rss_after"]) if inj in rk.index else np.nan
            r = refs.get(key, {})
            rss_tf, rss_gen = r.get("rss_true_fixed", np.nan), r.get("rss_gen", np.nan)
            true_mag = np.nan
            if inj in d.fits and d.fits[inj].thetas.get(inj):
                true_mag = float(next(iter(d.fits[inj].thetas[inj].values())))
            inj_ = inj != "none"
            rows.append({
                "twin": key, "injected": inj, "magnitude": mag, "level": t["level"], "seed": seed,
                "top": d.top_effect, "verdict": d.verdict,
                "correct": (d.top_effect == inj) if inj_ else (d.top_effect == "unexplained"),
                "rss_base": rss_b, "rss_top": rss_top, "rss_true": rss_true, "rss_true_fixed": rss_tf,
                "status_true_fixed": r.get("status_true_fixed", "n/a"), "rss_gen": rss_gen, "rss_0": rss0,
                "pct_closed_top": 100.0 * (1 - rss_top / rss_b),
                "shrink_injected_top": pct(rss_b - rss_top, rss_b - rss_tf) if inj_ else np.nan,
                "shrink_injected_true": pct(rss_b - rss_true, rss_b - rss_tf) if inj_ else np.nan,
                "shrink_vs_noise_top": pct(rss_b - rss_top, rss_b - rss_gen) if inj_ else np.nan,
                "shrink_vs_free_twin": pct(rss_b - rss_top, rss_b - rss0) if inj_ else np.nan,
                "identified_magnitude": true_mag,
                "dBIC_top": float(rk.loc[d.top_effect, "dBIC"]) if d.top_effect in rk.index else np.nan,
                "dBIC_true": float(rk.loc[inj, "dBIC"]) if inj in rk.index else np.nan,
                "dBIC_best_other": _best_other(rk, inj), "contenders": list(d.settings.get("contenders", [])),
                "n_eff": d.located.n_eff, "base_start": d.baseline.stats.get("start"),
                "retried": sum(f.solution is not None and "retry_start" in f.solution.stats for f in d.fits.values()),
                "true_start": (d.fits[inj].solution.stats.get("retry_start", "best")
                               if inj in d.fits and d.fits[inj].solution is not None else None),
            })
        for key in (settings or {}).get("baseline_failed", {}):  # no baseline: a miss, never dropped
            t = truth[key]
            rows.append({"twin": key, "injected": t["effects"][0][0] if t["effects"] else "none",
                         "magnitude": t["effects"][0][1] if t["effects"] else 0.0, "level": t["level"],
                         "seed": t["seed"], "top": "baseline failed", "verdict": "baseline failed", "correct": False,
                         "shrink_injected_top": np.nan, "shrink_injected_true": np.nan,
                         "shrink_vs_noise_top": np.nan})
        return cls(pd.DataFrame(rows), diags, gen_stats, settings)

    @property
    def confusion(self) -> pd.DataFrame:
        r = self.rows
        labels = list(dict.fromkeys(list(self.settings["effects"]) + ["none"]))
        cols = list(dict.fromkeys(list(self.settings["effects"]) + ["unexplained"]))
        c = pd.crosstab(r["injected"], r["top"]).reindex(index=labels, columns=cols, fill_value=0)
        extra = [x for x in r["top"].unique() if x not in cols]
        for x in extra:
            c[x] = pd.crosstab(r["injected"], r["top"]).reindex(index=labels, fill_value=0)[x]
        return c.fillna(0).astype(int)

    def accuracy(self) -> pd.DataFrame:
        """Per magnitude level: twins, top-1 accuracy, and the shrink of the injected gap —
        mean over twins where it is defined (the true model improves on the baseline fit;
        ``defined`` counts them), the same mean with each twin capped at 100 % (a named
        effect whose free fit beats the true model fitted with its magnitude fixed — a local
        optimum of that fit — closes "more than the gap"; the cap counts it as closing all of
        it), median, and the stricter shrink against the noise floor."""
        r = self.rows[self.rows["injected"] != "none"]
        g = r.groupby("level")
        out = pd.DataFrame({"twins": g.size(), "top-1 accuracy (%)": 100 * g["correct"].mean(),
                            "shrink defined": g["shrink_injected_top"].count(),
                            "mean shrink of injected gap (%)": g["shrink_injected_top"].mean(),
                            "mean shrink, capped at 100 % (%)":
                                g["shrink_injected_top"].apply(lambda v: v.clip(upper=100.0).mean()),
                            "median shrink of injected gap (%)": g["shrink_injected_top"].median(),
                            "mean shrink, true effect (%)": g["shrink_injected_true"].mean(),
                            "mean shrink vs noise floor (%)": g["shrink_vs_noise_top"].mean()})
        out.index = out.index.map({0: "small", 1: "middle", 2: "large"})
        return out

    def summary(self) -> dict:
        """The twin check's numbers and verdicts for the text (percentages in %).

        ``twins``, ``injected`` (twins with an effect); ``gen_converged`` of ``gen_total``
        twin-generating solves converged; ``top1_pct`` top-1 accuracy at the middle
        magnitude (level 1) and ``top1_by_seed`` (seed → % over every injected twin of that
        seed); ``shrink_pct`` the mean shrink of the injected gap over every magnitude,
        each twin capped at 100 %, over ``shrink_defined`` twins, ``shrink_uncapped_pct``,
        ``shrink_median_pct``, ``shrink_vs_noise_pct``; ``free_unexplained`` of
        ``free_twins`` effect-free twins named "unexplained"; ``top1_met``
        (≥ :data:`TARGET_TOP1_PCT`), ``shrink_met`` (≥ :data:`TARGET_SHRINK_PCT`) and
        ``passed`` (both, and every effect-free twin "unexplained"); ``base_starts`` (start
        → baseline fits kept from it), ``retried_twins`` / ``retried_fits`` (candidate fits
        re-solved from another start) and ``true_other_start`` (injected twins whose
        injected effect's kept fit came from another start than the baseline fit)."""
        r = self.rows
        inj = r[r["injected"] != "none"]
        free = r.loc[r["injected"] == "none", "correct"]
        shr = inj["shrink_injected_top"]
        top1 = 100 * float(inj.loc[inj["level"] == 1, "correct"].mean())
        shrink = float(shr.clip(upper=100.0).mean())
        retried = r["retried"] if "retried" in r else pd.Series(0, index=r.index)
        true_start = inj["true_start"] if "true_start" in inj else pd.Series(None, index=inj.index, dtype=object)
        out = {"twins": len(r), "injected": len(inj),
               "gen_converged": sum(v["status"] == "Solve_Succeeded" for v in self.gen_stats.values()),
               "gen_total": len(self.gen_stats), "top1_pct": top1,
               "top1_by_seed": {k: 100 * v for k, v in inj.groupby("seed")["correct"].mean().items()},
               "correct": int(inj["correct"].sum()),
               "shrink_pct": shrink, "shrink_defined": int(shr.count()), "shrink_uncapped_pct": float(shr.mean()),
               "shrink_median_pct": float(shr.median()),
               "shrink_vs_noise_pct": float(inj["shrink_vs_noise_top"].mean()),
               "free_unexplained": int(free.sum()), "free_twins": len(free),
               "top1_met": top1 >= TARGET_TOP1_PCT, "shrink_met": shrink >= TARGET_SHRINK_PCT,
               "base_starts": r["base_start"].value_counts().to_dict() if "base_start" in r else {},
               "retried_twins": int((retried > 0).sum()), "retried_fits": int(retried.sum()),
               "true_other_start": int((true_start.fillna("best") != "best").sum())}
        out["passed"] = bool(out["top1_met"] and out["shrink_met"] and bool(free.all()))
        return out

    def misses(self) -> pd.DataFrame:
        """The misnamed twins (rows of :attr:`rows` with ``correct`` False) with two
        diagnoses of why: ``fit_failed`` — an injected effect whose own candidate fit ends at
        or above the baseline fit's RSS (the fit, not the criterion, failed);
        ``true_not_named`` — the injected effect would not have been named even with its own
        fit's ΔBIC (not below :data:`gaitlib.gap.diagnose.BIC_THRESHOLD`, or not below every
        other ranked candidate's by the runner-up margin,
        :data:`gaitlib.gap.method.RUNNER_UP_MARGIN`)."""
        w = self.rows[~self.rows["correct"].astype(bool)].copy()
        inj = w["injected"] != "none"
        rt, rb = w["rss_true"].astype(float), w["rss_base"].astype(float)
        w["fit_failed"] = inj & np.isfinite(rt) & (rt >= rb)
        bt, bo = w["dBIC_true"].astype(float), w["dBIC_best_other"].astype(float)
        clear = (bt <= bo - RUNNER_UP_MARGIN) if RUNNER_UP_MARGIN > 0 else (bt < bo)
        w["true_not_named"] = ~(np.isfinite(bt) & (bt <= BIC_THRESHOLD) & (~np.isfinite(bo) | clear))
        return w

    def to_dict(self) -> dict:
        return {"rows": json.loads(self.rows.to_json(orient="records")),
                "confusion": json.loads(self.confusion.to_json()),
                "accuracy": json.loads(self.accuracy().to_json()),
                "generation": self.gen_stats, "settings": self.settings}
