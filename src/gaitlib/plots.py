"""Figures every chapter reuses: ±1 SD bands of data against simulated curves.

Degrees, % of the gait cycle and body-weight-normalised units appear only here, at the
edge; every input is SI (see :mod:`gaitlib.conventions`).
"""

from __future__ import annotations

import numpy as np

from . import conventions as cv

#: How a model channel is shown: (label, scale from SI, display unit).
DISPLAY = {
    "pelvis_tilt": ("HAT / pelvis tilt", 1 / cv.DEG, "deg"),
    "hip": ("hip angle (+ flexion)", 1 / cv.DEG, "deg"),
    "knee": ("knee angle (− flexion)", 1 / cv.DEG, "deg"),
    "ankle": ("ankle angle (+ dorsiflexion)", 1 / cv.DEG, "deg"),
    "mtp": ("metatarsal angle (+ toe extension)", 1 / cv.DEG, "deg"),
    "tau_hip": ("hip torque (+ flexor)", 1.0, "N·m"),
    "tau_knee": ("knee torque (+ extensor)", 1.0, "N·m"),
    "tau_ankle": ("ankle torque (+ dorsiflexor)", 1.0, "N·m"),
    "tau_mtp": ("metatarsal torque", 1.0, "N·m"),
    "pow_hip": ("hip power", 1.0, "W"),
    "pow_knee": ("knee power", 1.0, "W"),
    "pow_ankle": ("ankle power", 1.0, "W"),
    "grf_x": ("GRF anterior–posterior", 1.0, "N"),
    "grf_y": ("GRF vertical", 1.0, "N"),
}


def channel_display(channel: str) -> tuple[str, float, str]:
    """(label, scale, unit) for a model channel such as ``knee_r`` or ``emg_TA_l``."""
    stem = channel[:-2] if channel.endswith(("_r", "_l")) else channel
    if stem in DISPLAY:
        return DISPLAY[stem]
    if stem.startswith("emg_"):
        return (f"EMG {stem[4:]}", 1.0, "normalised")
    return (stem, 1.0, "")


def band(ax, x, mean, sd, color="0.6", label=None, alpha=0.35, line=True):
    """Draw mean ± 1 SD as a shaded band (and the mean as a dotted line)."""
    x, mean, sd = (np.asarray(v, dtype=float) for v in (x, mean, sd))
    ax.fill_between(x, mean - sd, mean + sd, color=color, alpha=alpha, lw=0, label=label)
    if line:
        ax.plot(x, mean, color=color, lw=1.0, ls=":")


def data_bands(datasets: dict, channels, ncols: int = 3, colors=None, figsize_per=(3.6, 2.4),
               title=None):
    """One panel per channel with a ±1 SD band for each data set.

    Parameters
    ----------
    datasets : ``{label: GaitData}``; x axis is % of the gait cycle, so data sets with
        different cycle times share it.
    channels : model channel names (e.g. ``"knee_r"``), drawn in display units.
    """
    import matplotlib.pyplot as plt

    channels = list(channels)
    nrows = int(np.ceil(len(channels) / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(figsize_per[0] * ncols, figsize_per[1] * nrows),
                             squeeze=False, constrained_layout=True)
    cmap = plt.get_cmap("viridis")
    labels = list(datasets)
    if colors is None:
        colors = {lab: cmap(i / max(1, len(labels) - 1)) for i, lab in enumerate(labels)}
    for ax, ch in zip(axes.flat, channels):
        name, scale, unit = channel_display(ch)
        for lab, d in datasets.items():
            if ch not in d.mean:
                continue
            pct = 100 * d.time / d.cycle_time
            band(ax, pct, scale * d.mean[ch], scale * d.sd[ch], color=colors[lab], label=lab, alpha=0.25)
        side = {"_r": " (right)", "_l": " (left)"}.get(ch[-2:], "")
        ax.set_title(name + side, fontsize=9)
        ax.set_ylabel(unit, fontsize=8)
        ax.set_xlim(0, 100)
        ax.tick_params(labelsize=7)
    for ax in axes.flat[len(channels):]:
        ax.axis("off")
    for ax in axes[-1]:
        ax.set_xlabel("% gait cycle", fontsize=8)
    handles, labs = axes.flat[0].get_legend_handles_labels()
    if handles:
        fig.legend(handles, labs, loc="outside lower center", ncols=min(len(labs), 5), fontsize=8)
    if title:
        fig.suptitle(title, fontsize=10)
    return fig
