"""Figures of the gap diagnosis: channel × phase heat maps, rankings, confusion matrices.

A figure of a solve that did not converge carries its failure label
(:func:`gaitlib.marks.failure_label`, argument ``mark``/``marks``) as a red watermark and a
red title prefix; a ranking bar of a candidate whose re-solve failed is hatched red."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import marks as mk
from .locate import PHASES
from .method import BIC_THRESHOLD

__all__ = ["gap_heatmap", "ranking_bars", "shrink_heatmaps", "confusion_plot", "channel_curves", "validation_plot"]


def _label(ch: str) -> str:
    kind, name = ch.split(":", 1)
    return f"{name} ({kind})"


def _heat(ax, loc, value="rms_z", vmax=None, cmap="magma_r", title="", colorbar=True):
    H = loc.heat(value)
    S = loc.heat("significant").fillna(False).astype(bool)
    data = H.to_numpy(float)
    vmax = vmax or max(float(np.nanmax(data)) if data.size else 1.0, 1.0)
    im = ax.imshow(data, aspect="auto", cmap=cmap, vmin=0, vmax=vmax)
    ax.set_xticks(range(len(PHASES)), PHASES, fontsize=8)
    ax.set_yticks(range(len(H.index)), [_label(c) for c in H.index], fontsize=7)
    for i in range(data.shape[0]):
        for j in range(data.shape[1]):
            v = data[i, j]
            if np.isfinite(v):
                ax.text(j, i, f"{v:.1f}{'*' if S.iloc[i, j] else ''}", ha="center", va="center", fontsize=6,
                        color="white" if v > 0.6 * vmax else "black")
    ax.set_title(title, fontsize=9)
    if colorbar:
        ax.figure.colorbar(im, ax=ax, shrink=0.8, label="RMS of z (SD units)")
    return im


def gap_heatmap(loc, title: str = "", ax=None, mark: str | None = None):
    """Channel × phase heat map of the RMS SD-standardised residual; * = leaves the ±1 SD
    band significantly somewhere in the cell (:mod:`gaitlib.gap.locate`). ``mark``: the
    located solve's failure label (None when it converged)."""
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(figsize=(6.5, 0.28 * len(loc.channels) + 1.6))
    _heat(ax, loc, title=title)
    _mark_title(ax, mark)
    ax.figure.tight_layout()
    mk.mark_axes(ax, mark)
    return ax.figure


def _mark_title(ax, mark):
    if mark:
        ax.set_title(f"{mark}\n{ax.get_title()}", fontsize=9, color=mk.MARK_COLOR, fontweight="bold")


def shrink_heatmaps(loc0, loc1, effect: str, title: str = "", marks=(None, None)):
    """Before/after heat maps (same colour scale) for one effect; ``marks``: the failure
    labels of the two solves (baseline, with the effect)."""
    import matplotlib.pyplot as plt

    vmax = max(float(np.nanmax(loc0.heat().to_numpy(float))), 1.0)
    fig, axs = plt.subplots(1, 2, figsize=(11, 0.28 * len(loc0.channels) + 1.8), sharey=True)
    _heat(axs[0], loc0, vmax=vmax, title="baseline", colorbar=False)
    im = _heat(axs[1], loc1, vmax=vmax, title=f"with {effect}", colorbar=False)
    fig.colorbar(im, ax=axs, shrink=0.8, label="RMS of z (SD units)")
    if title:
        fig.suptitle(title, fontsize=10)
    for ax, m in zip(axs, marks):
        _mark_title(ax, m)
        mk.mark_axes(ax, m)
    return fig


def _rank_label(row) -> str:
    """``effect (k=1)``, plus where the kept fit started when not from the baseline fit and
    "does not nest the baseline" where so (a negative % closed is then possible)."""
    extra = [f"k={int(row['n_params'])}"]
    start = row.get("start")
    if isinstance(start, str) and not start.startswith("baseline"):
        extra.append(f"from {start}")
    if row.get("nests_baseline") is False or row.get("nests_baseline") is np.False_:
        extra.append("not nesting")
    return f"{row['effect']} ({', '.join(extra)})"


def ranking_bars(ranking: pd.DataFrame, top: str | None = None, threshold: float | None = None,
                 mark: str | None = None):
    """% of the RSS closed (raw, with interval where computed) and ΔBIC per ranked effect
    (unranked ones — no ΔBIC: failed searches, nested fits with a located gap above the
    baseline's — are left out); labels name the start of a fit not from the baseline fit
    and the effects that do not nest the baseline.

    A candidate whose re-solve did not converge (``ok`` False) is hatched red with ``†`` and
    its status after its name; ``mark``: the baseline fit's failure label (every number here
    is relative to it)."""
    import matplotlib.pyplot as plt

    threshold = BIC_THRESHOLD if threshold is None else threshold
    r = ranking.dropna(subset=["dBIC"]).iloc[::-1]
    fig, axs = plt.subplots(1, 2, figsize=(10, 0.35 * len(r) + 1.5), sharey=True)
    y = np.arange(len(r))
    colors = ["tab:green" if e == top else ("tab:gray" if not ok else "tab:blue") for e, ok in zip(r["effect"], r["ok"])]
    bad = [i for i, ok in enumerate(r["ok"]) if not ok]
    bars0 = axs[0].barh(y, r["pct_closed"], color=colors)
    if "pct_closed_lo" in r.columns:
        lo, hi = r["pct_closed_lo"].to_numpy(), r["pct_closed_hi"].to_numpy()
        m = np.isfinite(lo) & np.isfinite(hi)
        # the interval as drawn from the resampled data: it need not contain the point
        # estimate (the redrawn noise raises every RSS), so it is a segment, not ± errors
        axs[0].hlines(y[m], lo[m], hi[m], color="k", lw=1.2)
        axs[0].plot(np.r_[lo[m], hi[m]], np.r_[y[m], y[m]], "k|", ms=7)
    axs[0].axvline(0, color="k", lw=0.8)
    axs[0].set_xlabel("RSS closed (%) — raw")
    names = [_rank_label(row) for _, row in r.iterrows()]
    if "status" in r.columns:
        names = [f"{n} {mk.DAGGER} {st}" if i in bad else n for i, (n, st) in enumerate(zip(names, r["status"]))]
    axs[0].set_yticks(y, names, fontsize=8)
    bars1 = axs[1].barh(y, r["dBIC"], color=colors)
    for i in bad:
        mk.mark_bars([bars0[i], bars1[i]], "not converged")
    for i, lab in enumerate(axs[0].get_yticklabels()):
        if i in bad:
            lab.set_color(mk.MARK_COLOR)
    axs[1].axvline(threshold, color="tab:red", ls="--", lw=1, label=f"threshold {threshold:g}")
    axs[1].axvline(0, color="k", lw=0.8)
    axs[1].set_xlabel("ΔBIC — penalised (lower is better)")
    h, lab = axs[1].get_legend_handles_labels()
    if bad:
        h.append(mk.bar_legend_handle())
        lab.append(h[-1].get_label())
    axs[1].legend(h, lab, fontsize=8)
    if mark:
        mk.mark_all(fig, f"baseline fit {mark}")
    fig.tight_layout()
    return fig


def confusion_plot(conf: pd.DataFrame, title: str = ""):
    """Injected (rows) × named (columns) counts."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(0.7 * conf.shape[1] + 2.5, 0.5 * conf.shape[0] + 1.8))
    ax.imshow(conf.to_numpy(), cmap="Blues")
    ax.set_xticks(range(conf.shape[1]), conf.columns, rotation=40, ha="right", fontsize=8)
    ax.set_yticks(range(conf.shape[0]), conf.index, fontsize=8)
    for i in range(conf.shape[0]):
        for j in range(conf.shape[1]):
            v = conf.iat[i, j]
            if v:
                ax.text(j, i, str(v), ha="center", va="center", fontsize=8,
                        color="white" if v > 0.6 * conf.to_numpy().max() else "black")
    ax.set_xlabel("named by the diagnosis")
    ax.set_ylabel("injected")
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    return fig


def channel_curves(loc0, loc1, channels, labels=("baseline", "with effect"), marks=(None, None)):
    """Data ±1 SD band with the baseline's and an effect's curves for a few channels;
    ``marks``: the failure labels of the two solves (a marked curve is dashed, named in the
    legend and written across the panels)."""
    import matplotlib.pyplot as plt

    n = len(channels)
    fig, axs = plt.subplots(1, n, figsize=(3.3 * n, 2.8), squeeze=False)
    for ax, ch in zip(axs[0], channels):
        p0 = loc0.points[loc0.points["channel"] == ch]
        ax.fill_between(100 * p0["tau"], p0["mean"] - p0["sd"], p0["mean"] + p0["sd"], color="0.85", label="data ±1 SD")
        ax.plot(100 * p0["tau"], p0["mean"], color="k", lw=1)
        ax.plot(100 * p0["tau"], p0["sim"], color="tab:red", lw=1.3, ls=":" if marks[0] else "-",
                label=mk.run_label(labels[0], marks[0]))
        if loc1 is not None:
            p1 = loc1.points[loc1.points["channel"] == ch]
            ax.plot(100 * p1["tau"], p1["sim"], color="tab:blue", lw=1.3, ls="--",
                    label=mk.run_label(labels[1], marks[1]))
        ax.set_title(_label(ch), fontsize=9)
        ax.set_xlabel("% cycle")
    axs[0][0].legend(fontsize=7)
    fig.tight_layout()
    shown = dict(zip(labels, marks)) if loc1 is not None else {labels[0]: marks[0]}
    joint = mk.joint_label(shown)
    for ax in axs[0]:
        mk.mark_axes(ax, joint)
    mk.mark_figure(fig, joint)
    return fig


def data_views(loc_a, loc_b, channels, labels=("data as tracked", "left leg shifted exactly"), sim_label="simulation",
               mark: str | None = None):
    """One solution located against two views of the data (e.g. the Fourier-generated left
    leg and the exactly shifted one, :func:`gaitlib.studies.gap.left_leg_check`): both data
    means, the first view's ±1 SD band, and the (same) simulated curve; ``mark``: the
    solution's failure label."""
    import matplotlib.pyplot as plt

    n = len(channels)
    fig, axs = plt.subplots(1, n, figsize=(3.3 * n, 2.8), squeeze=False)
    for ax, ch in zip(axs[0], channels):
        pa = loc_a.points[loc_a.points["channel"] == ch]
        pb = loc_b.points[loc_b.points["channel"] == ch]
        ax.fill_between(100 * pa["tau"], pa["mean"] - pa["sd_eff"], pa["mean"] + pa["sd_eff"], color="0.85",
                        label=f"{labels[0]} ±1 SD*")
        ax.plot(100 * pa["tau"], pa["mean"], color="k", lw=1, label=labels[0])
        ax.plot(100 * pb["tau"], pb["mean"], color="tab:green", lw=1.3, ls="--", label=labels[1])
        ax.plot(100 * pa["tau"], pa["sim"], color="tab:red", lw=1.1, label=mk.run_label(sim_label, mark))
        ax.set_title(_label(ch), fontsize=9)
        ax.set_xlabel("% cycle")
    axs[0][0].legend(fontsize=7)
    fig.tight_layout()
    return mk.mark_all(fig, mark)


def validation_plot(rows, threshold: float | None = None, title: str = ""):
    """The non-circular validation (:class:`gaitlib.gap.validate.Validation` ``rows``): for
    each manipulation of the independent set, how much worse the baseline fits after it
    (``added_pct``, % of the unedited data's RSS; x) against the injected effect's own ΔBIC
    (y; dashed: the naming threshold); filled markers named right, open ones not."""
    import matplotlib.pyplot as plt

    threshold = BIC_THRESHOLD if threshold is None else threshold
    r = rows[rows["set"] == "independent"]
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    for i, (inj, g) in enumerate(r.groupby("injection", sort=False)):
        col, ok = f"C{i}", g["correct"].astype(bool)
        ax.scatter(g.loc[ok, "added_pct"], g.loc[ok, "expected_dBIC"], s=46, color=col)
        ax.scatter(g.loc[~ok, "added_pct"], g.loc[~ok, "expected_dBIC"], s=46, facecolors="none", edgecolors=col)
        ax.plot([], [], "o", color=col, label=inj)
    ax.axhline(threshold, ls="--", color="0.4", lw=1)
    ax.set_xlabel("baseline RSS added by the manipulation (% of the unedited data's)")
    ax.set_ylabel("ΔBIC of the injected effect")
    ax.legend(fontsize=7, loc="best", title="filled: named right", title_fontsize=7)
    ax.set_title(title or "manipulated real data: visibility of the injection vs evidence for the injected effect",
                 fontsize=9)
    fig.tight_layout()
    return fig
