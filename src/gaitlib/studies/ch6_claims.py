"""The thesis's Ch 6 conclusions (Secs 6.2.2–6.3), re-derived from valid runs only.

Each claim of the chapter's text becomes one row: what the thesis says, the test we apply,
our numbers and the verdict — ``holds``, ``does not hold`` or ``not tested`` (a run the
claim needs did not converge or fails a validity gate; the row names it). Accuracy claims
are tested twice, on two scalings of a channel's misfit, because the thesis compares RMSEs
of channels with different units (Figs 6.1–6.3) without saying how it weighs them:

* ``NRMSE`` — RMSE / range of the data mean (the book's headline metric, thesis Ch 7);
* ``SD units`` — mean |error| / data SD (how far outside the normal corridor the run is).

A run's accuracy is the mean over the kinds (angles, torques, GRFs; each kind the mean of
its channels, so every kind weighs the same). A claim whose verdict differs between the two
metrics is marked ``depends on the metric``. Excitation claims (Fig 6.4) use the RMSE vs EMG
(dimensionless, the thesis's) and the NRMSE (RMSE / EMG range).

Thresholds the thesis does not give are ours and stated: "similar accuracy" is a relative
difference of at most :data:`SIMILAR_TOL`; "SDT3 is enough" is NMSK SDT3 within
:data:`gaitlib.studies.predictive.SDT3_ENOUGH_FACTOR` of NMSK DT.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitlib import data as data_mod, marks
from gaitlib.studies import predictive as pr

#: "Similar accuracy" (Sec 6.2.3, DT / SDT3 / SP1): |a − b| / min(a, b) ≤ this (ours; the
#: thesis gives no threshold).
SIMILAR_TOL = 0.10
#: Accuracy metrics: label → column of :func:`gaitlib.studies.predictive.score`.
METRICS = {"NRMSE": "nrmse", "SD units": "mean_z"}
#: Excitation metrics: label → column of :func:`gaitlib.studies.predictive.excitation_score`.
EXC_METRICS = {"RMSE": "rmse", "NRMSE": "nrmse"}
VERDICTS = ("holds", "does not hold", "depends on the metric", "not tested")
_KINDS = ("angle", "torque", "grf")
_DATA_COSTS = tuple(c for c in pr.CH6_COSTS if c != "FP")
#: The name of the Ch 5 NMSK solution in the accuracy table.
CH5_NMSK = "Ch 5 NMSK"
_ANG_OR_TRQ = ("DT", "SDT1", "SDT2", "SDT3", "SP2", "SP3")  # the runs tracking angles or torques


def _acc_table(runs: dict, gait: data_mod.GaitData) -> pd.DataFrame:
    """(run, kind) → mean over the kind's channels, one column per metric (accuracy kinds)
    and per excitation metric (kind ``excitation``)."""
    rows = []
    for name, sol in runs.items():
        sc = pr.score(sol, gait)
        for kind, g in sc.groupby("kind"):
            rows.append({"run": name, "kind": kind, **{m: float(g[c].mean()) for m, c in METRICS.items()}})
        if getattr(sol, "excitations", None) is not None:
            ex = pr.excitation_score(sol, gait)
            rows.append({"run": name, "kind": "excitation", **{m: float(ex[c].mean()) for m, c in EXC_METRICS.items()}})
    return pd.DataFrame(rows).set_index(["run", "kind"]) if rows else pd.DataFrame()


class _Acc:
    """Accuracy lookups on the usable runs; NaN when a run is not usable."""

    def __init__(self, table: pd.DataFrame, excluded: dict):
        self.t, self.excluded = table, excluded

    def has(self, name: str) -> bool:
        return not self.t.empty and name in self.t.index.get_level_values("run")

    def __call__(self, name: str, metric: str, kinds=_KINDS) -> float:
        if not self.has(name):
            return np.nan
        return float(np.mean([self.t.loc[(name, k), metric] for k in kinds]))

    def missing(self, names) -> list[str]:
        return [f"{n} ({_short(self.excluded.get(n))})" for n in names if not self.has(n)]


def _short(mark: str | None) -> str:
    """``"NOT CONVERGED: …; INVALID: …"`` → ``"not converged, invalid"``."""
    if not mark:
        return "no result"
    return ", ".join(k.lower() for k in marks.mark_kinds(mark))


def _by(pct: float, down: str, up: str) -> str:
    """``"lower by 12 %"`` for a positive gain, ``"higher by 4 %"`` for a negative one."""
    return f"{down if pct >= 0 else up} by {abs(pct):.0f} %"


def _fmt(v: float) -> str:
    return f"{v:.3f}" if np.isfinite(v) else "—"


def _pair(acc, a, b, metric, kinds=_KINDS) -> tuple[float, float, str]:
    va, vb = acc(a, metric, kinds), acc(b, metric, kinds)
    return va, vb, f"{a.split()[0]} {_fmt(va)}, {b.split()[0]} {_fmt(vb)}"


def _better(c, who):
    other = "NMSK" if who == "MSK" else "MSK"

    def test(acc, metric):
        va, vb, txt = _pair(acc, f"{who} {c}", f"{other} {c}", metric)
        return va < vb, txt
    return (f"{c}: {who} more accurate than {other}", "6.2.3", f"{who} mean score < {other}'s",
            [f"MSK {c}", f"NMSK {c}"], test)


def _sdt3_enough(acc, metric):
    s, d = acc("NMSK SDT3", metric), acc("NMSK DT", metric)
    return s <= pr.SDT3_ENOUGH_FACTOR * d, f"NMSK SDT3 {_fmt(s)}, DT {_fmt(d)} (ratio {s / d:.2f})"


def _extremum(test, required):
    """Mark ``test`` as a claim about the most / least accurate run: only ``required`` must be
    usable; with comparators left out, a claim that fails on the usable runs fails (more
    runs can only add rivals), and one that holds on them stays untested."""
    test.required = list(required)
    return test


def _worst_of(model_case_sets, kinds):
    """``label`` run least accurate (on ``kinds``) among the others, per model."""
    def test(acc, metric):
        ok, parts = True, []
        for model, worst, others in model_case_sets:
            vw = acc(f"{model} {worst}", metric, kinds)
            vo = {c: acc(f"{model} {c}", metric, kinds) for c in others if acc.has(f"{model} {c}")}
            worst_other = max(vo, key=vo.get)
            ok &= vw > vo[worst_other]
            parts.append(f"{model} {worst} {_fmt(vw)} vs worst other {worst_other} {_fmt(vo[worst_other])}")
        return ok, "; ".join(parts)
    return _extremum(test, [f"{model} {worst}" for model, worst, _ in model_case_sets])


def _fp_gain_claim(kind: str) -> str:
    return f"FP: NMSK {kind}s more accurate than MSK's"


_FP_CH5_CLAIM = "NMSK FP excitations more accurate than the Ch 5 data tracking's"
_TIME_ALL_CLAIM = "NMSK optimisations are computationally more efficient than MSK's"
_TIME_FP_CLAIM = "FP: NMSK faster than MSK"
#: Claims whose thesis statement is a number (a per-cent gain or a time ratio): the report
#: card carries them as numeric rows of their own.
_NUMERIC = frozenset([*(_fp_gain_claim(k) for k in pr.THESIS_FP_GAIN_PCT), _FP_CH5_CLAIM, _TIME_ALL_CLAIM,
                      _TIME_FP_CLAIM])


def _fp_gain(kind, thesis_pct):
    def test(acc, metric):
        m, n = acc("MSK FP", metric, (kind,)), acc("NMSK FP", metric, (kind,))
        g = 100 * (1 - n / m)
        return g > 0, f"MSK {_fmt(m)}, NMSK {_fmt(n)}: NMSK {_by(g, 'lower', 'higher')} (thesis {thesis_pct:.0f} % lower)"
    return (_fp_gain_claim(kind), "6.2.4, 6.3", "NMSK FP score < MSK FP's",
            ["MSK FP", "NMSK FP"], test)


def _exc_rank(case, where):
    def test(acc, metric):
        ex = {c: acc(f"NMSK {c}", metric, ("excitation",)) for c in pr.CH6_COSTS if acc.has(f"NMSK {c}")}
        order = sorted(ex, key=ex.get)
        rank = order.index(case) + 1
        ok = {"best": rank == 1, "worst": rank == len(order), "worse half": rank > len(order) / 2}[where]
        return ok, (f"NMSK {case} {_fmt(ex[case])}, rank {rank} of {len(order)} "
                    f"(best {order[0]} {_fmt(ex[order[0]])}, worst {order[-1]} {_fmt(ex[order[-1]])})")
    return _extremum(test, [f"NMSK {case}"]) if where in ("best", "worst") else test


def _claims(ch5_nmsk: str | None) -> list:
    """(claim, thesis section, test, runs needed, test(metric) → (holds, text), kind)."""
    nmsk_all = [f"NMSK {c}" for c in pr.CH6_COSTS]
    acc_claims = [
        *[_similar_row(c) for c in ("DT", "SDT3", "SP1")],
        *[_better(c, "MSK") for c in ("SDT2", "SP3")],
        *[_better(c, "NMSK") for c in ("SDT1", "SP2", "FP")],
        ("NMSK: tracking angles and torques (SDT3) is enough", "6.2.3, 6.3",
         f"NMSK SDT3 ≤ {pr.SDT3_ENOUGH_FACTOR:.1f} × NMSK DT (ours)", ["NMSK SDT3", "NMSK DT"], _sdt3_enough),
        ("SP1 (GRF only): the least accurate angles and torques of the runs tracking angles or torques",
         "6.2.3, 6.3", "per model, SP1's angle+torque score > every DT/SDT/SP2/SP3 run's",
         [f"{m} {c}" for m in ("MSK", "NMSK") for c in ("SP1", *_ANG_OR_TRQ)],
         _worst_of([(m, "SP1", _ANG_OR_TRQ) for m in ("MSK", "NMSK")], ("angle", "torque"))),
        ("FP: less accurate than every cost function with a data term", "6.2.3",
         "per model, FP's score > every other run's",
         [f"{m} {c}" for m in ("MSK", "NMSK") for c in pr.CH6_COSTS],
         _worst_of([(m, "FP", _DATA_COSTS) for m in ("MSK", "NMSK")], _KINDS)),
        *[_fp_gain(k, v) for k, v in pr.THESIS_FP_GAIN_PCT.items()],
    ]
    exc_claims = [
        ("NMSK SDT3 predicts the most accurate excitations", "6.2.3, 6.3", "lowest excitation score of the 8",
         nmsk_all, _exc_rank("SDT3", "best")),
        ("NMSK SP1 predicts the least accurate excitations", "6.2.3, 6.3", "highest excitation score of the 8",
         nmsk_all, _exc_rank("SP1", "worst")),
        ("NMSK DT is among the least accurate in excitations", "6.2.3", "in the worse half of the 8",
         nmsk_all, _exc_rank("DT", "worse half")),
    ]
    if ch5_nmsk is not None:
        def fp_vs_ch5(acc, metric):
            f, c5 = acc("NMSK FP", metric, ("excitation",)), acc(ch5_nmsk, metric, ("excitation",))
            return f < c5, (f"FP {_fmt(f)}, Ch 5 {_fmt(c5)}: FP {_by(100 * (1 - f / c5), 'lower', 'higher')} "
                            f"(thesis {pr.THESIS_FP_EXCITATION_GAIN_PCT:.0f} % lower)")
        exc_claims.append((_FP_CH5_CLAIM, "6.2.4, 6.3",
                           "FP excitation score < Ch 5 NMSK's", ["NMSK FP", ch5_nmsk], fp_vs_ch5))
    return [(*c, METRICS) for c in acc_claims] + [(*c, EXC_METRICS) for c in exc_claims]


def _similar_row(c):
    def test(acc, metric):
        va, vb, txt = _pair(acc, f"MSK {c}", f"NMSK {c}", metric)
        d = abs(va - vb) / min(va, vb)
        return d <= SIMILAR_TOL, f"{txt} (differ by {100 * d:.0f} %)"
    return (f"{c}: MSK and NMSK similarly accurate", "6.2.3",
            f"mean scores differ by ≤ {100 * SIMILAR_TOL:.0f} % (ours)", [f"MSK {c}", f"NMSK {c}"], test)


def _time_claims(times: dict, acc: _Acc) -> list[dict]:
    """The compute-time claims (no metric): NMSK optimisations faster than MSK's overall
    (Secs 6.2.2, 6.3) and NMSK FP 40 % faster than MSK FP (Sec 6.2.4)."""
    rows = []
    need = [f"{m} {c}" for m in ("MSK", "NMSK") for c in pr.CH6_COSTS]
    miss = acc.missing(need)
    if miss:
        verdict, ours = "not tested", "not usable: " + ", ".join(miss)
    else:
        tm = sum(times[f"MSK {c}"] for c in pr.CH6_COSTS)
        tn = sum(times[f"NMSK {c}"] for c in pr.CH6_COSTS)
        verdict, ours = ("holds" if tn < tm else "does not hold"), f"MSK {tm:.0f} s, NMSK {tn:.0f} s (solve, 8 runs each)"
    rows.append({"claim": _TIME_ALL_CLAIM, "thesis": "6.2.2, 6.3", "runs": ", ".join(need), "numeric": True,
                 "test": "sum of the 8 solve times, NMSK < MSK", "ours": ours, "verdict": verdict})
    miss = acc.missing(["MSK FP", "NMSK FP"])
    th = pr.THESIS_HOURS_TABLE_6_3
    if miss:
        verdict, ours = "not tested", "not usable: " + ", ".join(miss)
    else:
        g = 100 * (1 - times["NMSK FP"] / times["MSK FP"])
        verdict = "holds" if g > 0 else "does not hold"
        ours = (f"MSK {times['MSK FP']:.0f} s, NMSK {times['NMSK FP']:.0f} s: NMSK {_by(g, 'faster', 'slower')} "
                f"(thesis {100 * (1 - th['NMSK']['FP'] / th['MSK']['FP']):.0f} % faster)")
    rows.append({"claim": _TIME_FP_CLAIM, "thesis": "6.2.4, 6.3", "test": "solve time NMSK FP < MSK FP",
                 "runs": "MSK FP, NMSK FP", "numeric": True,
                 "ours": ours, "verdict": verdict})
    return rows


def conclusions(runs: dict, gait: data_mod.GaitData, *, excluded: dict | None = None, ch5_nmsk=None,
                notes: dict | None = None) -> pd.DataFrame:
    """The Ch 6 conclusions table.

    ``runs``: name (``"MSK DT"`` …) → a converged solution that passes the validity gates
    (only these are scored); ``excluded``: name → the mark of a run left out (named in the
    rows that need it); ``ch5_nmsk``: the Ch 5 NMSK solution (the FP-vs-data-tracking
    excitation claim); ``notes``: name → a note on where a run comes from (e.g. a
    3000-iteration rerun), appended to the rows that use it.

    Columns: ``claim, thesis`` (section), ``test``, one text and one verdict column per metric,
    ``ours`` (reruns used, or the runs not usable), ``verdict``, ``depends on metric``,
    ``runs`` (the runs the claim needs, comma-separated), ``used`` (those usable, which the
    verdict is computed from) and ``numeric`` (the thesis states a
    number: a per-cent gain or a time). Compute-time rows have no metric."""
    all_runs = dict(runs)
    if ch5_nmsk is not None:
        all_runs[CH5_NMSK] = ch5_nmsk
    times = {k: float(s.stats["solve_time_s"]) for k, s in runs.items()}
    return table_conclusions(_acc_table(all_runs, gait), times, excluded=excluded, notes=notes,
                             with_ch5=ch5_nmsk is not None)


def table_conclusions(scores: pd.DataFrame, times: dict, *, excluded: dict | None = None, notes: dict | None = None,
                      with_ch5: bool = False) -> pd.DataFrame:
    """:func:`conclusions` from the accuracy table ``scores`` ((run, kind) → one column per
    metric of :data:`METRICS` / :data:`EXC_METRICS`; a run's rows are absent when it is not
    usable) and ``times`` (run → solve time, s)."""
    excluded, notes = dict(excluded or {}), dict(notes or {})
    c5 = CH5_NMSK if with_ch5 else None
    acc = _Acc(scores, excluded)
    rows = []
    for claim, sec, test_text, need, test, metrics in _claims(c5):
        row = {"claim": claim, "thesis": sec, "test": test_text, "runs": ", ".join(need),
               "used": ", ".join(n for n in need if acc.has(n)), "numeric": claim in _NUMERIC}
        required = getattr(test, "required", need)
        miss = acc.missing(required)
        rivals_out = acc.missing([n for n in need if n not in required])
        used = [n for n in need if n in notes and acc.has(n)]
        verdicts = []
        for label in metrics:
            col = label
            if miss:
                row[col], v = "—", "not tested"
            else:
                ok, txt = test(acc, label)
                # an extremum that holds without all its rivals is not established
                v = "does not hold" if not ok else ("not tested" if rivals_out else "holds")
                row[col] = txt
            row[f"{col}: verdict"] = v
            verdicts.append(v)
        if miss:
            verdict = "not tested"
            row["ours"] = "not usable: " + ", ".join(miss + rivals_out)
        else:
            verdict = verdicts[0] if len(set(verdicts)) == 1 else "depends on the metric"
            if "not tested" in verdicts and verdict == "depends on the metric":
                verdict = "not tested"  # fails on one metric, undecided on the other
            row["ours"] = "; ".join([f"{n}: {notes[n]}" for n in used]
                                    + ([f"left out: {', '.join(rivals_out)} (compared among the usable runs)"]
                                       if rivals_out else []))
        row["verdict"] = verdict
        row["depends on metric"] = verdict == "depends on the metric"
        rows.append(row)
    rows += _time_claims(times, acc)
    cols = ["claim", "thesis", "test", "NRMSE", "NRMSE: verdict", "SD units", "SD units: verdict", "RMSE",
            "RMSE: verdict", "ours", "verdict", "depends on metric", "runs", "used", "numeric"]
    return pd.DataFrame(rows).reindex(columns=cols)


def usable(res: pr.StudyResult, reruns: dict | None = None) -> tuple[dict, dict, dict]:
    """The runs a conclusion may use: each study run that converged and passes the validity
    gates; for one that did not, its rerun in ``reruns`` if that converged and is valid.
    Returns (name → solution, name → mark of a run left out, name → note on a rerun used)."""
    runs, excluded, notes = {}, {}, {}
    own = res.marks()
    for name in res.records:
        sol = res.solutions.get(name)
        if sol is not None and not own.get(name):
            runs[name] = sol
            continue
        r = (reruns or {}).get(name)
        if r is not None and not marks.failure_label(r):
            runs[name] = r
            notes[name] = f"its {r.spec.max_iter}-iteration rerun ({r.stats['iterations']} iterations)"
        else:
            excluded[name] = own.get(name) or "no result"
    return runs, excluded, notes


def changed(before: pd.DataFrame, after: pd.DataFrame) -> pd.DataFrame:
    """The claims whose verdict differs between two :func:`conclusions` tables of the same
    claims (e.g. two sets of runs): claim, verdict and NRMSE text before and after."""
    a, b = before.set_index("claim"), after.set_index("claim")
    common = [c for c in a.index if c in b.index and a.loc[c, "verdict"] != b.loc[c, "verdict"]]
    return pd.DataFrame({"verdict before": a.loc[common, "verdict"], "verdict after": b.loc[common, "verdict"],
                         "NRMSE before": a.loc[common, "NRMSE"], "NRMSE after": b.loc[common, "NRMSE"]},
                        index=pd.Index(common, name="claim"))


def summary(table: pd.DataFrame) -> str:
    """One sentence: how many claims hold, do not hold, depend on the metric, are not tested."""
    n = table["verdict"].value_counts().reindex(list(VERDICTS), fill_value=0)
    return (f"Of the thesis's {len(table)} Ch 6 claims tested here: {n['holds']} hold{'s' if n['holds'] == 1 else ''}, {n['does not hold']} do{'es' if n['does not hold'] == 1 else ''} not, "
            f"{n['depends on the metric']} depend{'s' if n['depends on the metric'] == 1 else ''} on the metric (NRMSE "
            f"vs SD units), {n['not tested']} {'is' if n['not tested'] == 1 else 'are'} not "
            "tested (a run they need did not converge or fails a validity gate).")


def excitation_scores(variants: dict[str, dict], gait: data_mod.GaitData, metric: str = "RMSE") -> pd.DataFrame:
    """The excitation accuracy (``metric`` of :data:`EXC_METRICS`, mean over the muscles with
    EMG) of each NMSK run in each of several sets of usable runs: rows the Ch 6 cost functions
    (``NMSK <cost>``), one column per set (``variants``: label → name → solution, e.g. the two
    starts, the two sets of activation parameters); NaN where a set has no usable run."""
    out = {}
    for label, runs in variants.items():
        col = {}
        for c in pr.CH6_COSTS:
            sol = runs.get(f"NMSK {c}")
            if sol is not None and getattr(sol, "excitations", None) is not None:
                col[c] = float(pr.excitation_score(sol, gait)[EXC_METRICS[metric]].mean())
        out[label] = pd.Series(col, dtype=float)
    return pd.DataFrame(out).reindex([c for c in pr.CH6_COSTS]).dropna(how="all").rename_axis("cost function")


def excitation_resolution(scores: pd.DataFrame) -> str:
    """How finely the runs rank by excitation accuracy (:func:`excitation_scores`; the first
    column the book's runs): the spread over the cost functions in the first column beside how
    far changing only the start or the activation parameters (each other column) moves one
    run's score beyond the shift common to all runs (their median change, which leaves the
    ranking as it is), and how well the ranks agree (Spearman ρ over the runs usable in both). The
    two excitation claims of Sec 6.2.3 decide between neighbours in that ranking."""
    base = scores.columns[0]
    b = scores[base].dropna()
    parts, moves = [], {}
    for other in scores.columns[1:]:
        both = scores[[base, other]].dropna()
        if len(both) < 3:
            continue
        shift = float((both[other] - both[base]).median())  # moves every run alike: no effect on the ranking
        d = (both[other] - both[base] - shift).abs()
        rho = both[base].rank().corr(both[other].rank())
        moves[other] = float(d.median())
        parts.append(f"{other}: beyond a common shift of {shift:+.3f}, a run's score moves by a median "
                     f"{d.median():.3f} (largest {d.max():.3f}, {d.idxmax()}) over {len(both)} runs; ranks agree at "
                     f"Spearman ρ = {rho:.2f}")
    if not parts:
        return ""
    gap = float(np.median(np.diff(np.sort(b.to_numpy()))))
    big = [k for k, m in moves.items() if m > gap]
    small = [k for k, m in moves.items() if m <= gap]
    tail = ((f" What moves a run relative to the others by more than the median gap between neighbours "
             f"({gap:.3f}): {', '.join(f'{k} ({moves[k]:.3f})' for k in big)}" if big else
             f" No single change moves a run relative to the others by more than the median gap between neighbours "
             f"({gap:.3f})")
            + (f"; by less: {', '.join(f'{k} ({moves[k]:.3f})' for k in small)}" if big and small else "") + ".")
    return (f"Over the {len(b)} cost functions the book's runs span {b.min():.3f}–{b.max():.3f} "
            f"(range {b.max() - b.min():.3f}; median gap between neighbours in the ranking {gap:.3f}). "
            f"Changing one thing at a time — " + "; ".join(parts) + "." + tail)
