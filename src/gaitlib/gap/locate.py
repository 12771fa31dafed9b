"""Locate the gap: SD-standardised residual of every channel, by gait phase, with a test of
where the simulation leaves the data's ±1 SD band.

Channels (each leg): joint angles (hip as the thigh's angle in the laboratory — data hip
+ data pelvic tilt — as the gait problem tracks it), net joint torques, GRFs (anterior,
vertical), in a change relative to a reference the HAT tilt (:data:`RELATIVE_ONLY`) and,
for solutions with muscle-level outputs, EMG: NMSK excitations e(t), MSK generator
activations (the muscle's generator, thesis Table 5.5), against the data's EMG
envelope of the same muscle (:data:`gaitlib.activation.EMG_CHANNELS`; Schwartz 2008: RF, BF
↔ lateral hamstrings, GAM ↔ medial gastrocnemius, TA).

Residual and standardisation
----------------------------
On the data's grid τ_j = j/50 (j = 0…49; 2 % steps, the duplicate 100 % point dropped) the
solution (its nodes read on normalised time t / t_f, periodic linear interpolation) gives
z_j = (sim_j − mean_j) / SD*_j with SD* = max(SD, 0.1 · RMS over the cycle of the channel's
SD) — a floor, because GRF SDs vanish in swing. A channel whose SD is zero everywhere (the
gaitutils EMG) cannot be standardised and is excluded (listed in ``Located.excluded``).

Phases (from the data's cycle events, right leg; the left leg's are shifted by the data's
left-leg shift): loading response LR [0, opposite foot off), mid/terminal stance MSt/TSt
[opposite foot off, opposite foot contact), pre-swing PSw [opposite foot contact, foot off),
initial, mid and terminal swing ISw, MSw, TSw (thirds of [foot off, 1)).

Leaving the band: a pointwise test with stated assumptions
----------------------------------------------------------
spm1d (statistical parametric mapping) needs each subject's curve to estimate the
field's smoothness and variance; the public data give only the group mean and SD, so it
cannot be applied. Instead, at every point: the data mean is normal with standard error
SE = SD*/√n (n subjects; gaitutils: n unknown → 1, conservative), the simulation is a
fixed curve, and H0 is "the simulation lies inside the population band" |sim − μ| ≤ SD*.
At the band edge Z = (|sim − mean| − SD*) / SE is standard normal, so p = 1 − Φ(Z) is a
valid (conservative inside the band) one-sided p-value. Multiple comparisons: Bonferroni
over the 50 points of the channel (no smoothness assumption; conservative for smooth
curves). A channel × phase cell is significant if any of its points is at α = 0.05.

Residual loads. The HAT's residual forces and moment (the generalised forces on the
pelvis coordinates that no actuator supplies) are located too, against OpenSim's residual
guidelines (:func:`residual_thresholds`) rather than a data SD: an effect the residual
actuators absorb (a load the model lacks) would show there. They are not part of the RSS
(a guideline is not a noise model). The gait problem bounds them (thesis Eq 4.8: 1 N,
1 N, 0.1 N·m), far below the guidelines for a child (≈ 20 N and ≈ 3 N·m), so residuals
cannot absorb an effect of this library: its loads show in the tracked channels.

Effective sample size (for the information criteria of :mod:`gaitlib.gap.diagnose`):
the residual curves are smooth, so their 50 points are not independent. Per channel we
count resels as spm1d does for 1-D fields: FWHM = √(4 ln 2 / λ) samples with λ =
Σ (Δz)² / Σ (z − z̄)² (periodic), resels = 50 / FWHM, clipped to [1, 50]; n_eff = Σ resels
over the included channels (estimated once, on the baseline's residual).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.stats import norm

from .. import activation
from .. import conventions as cv
from ..problems import gait as gait_ocp
from .. import effects as effects_mod
from .io import DataSet, filled_channels
from ..validity import RESIDUAL_FORCE_FRACTION, RESIDUAL_MOMENT_FRACTION

__all__ = ["PHASES", "PHASE_NAMES", "N_GRID", "phase_edges", "phase_of", "sim_channels", "Located", "locate",
           "resels", "periodic", "ALPHA", "SD_FLOOR", "residual_thresholds", "residual_table",
           "COM_HEIGHT_FRACTION", "RELATIVE_ONLY"]

PHASES = ("LR", "MSt/TSt", "PSw", "ISw", "MSw", "TSw")
#: COM height as a fraction of body height in standing (as :func:`gaitlib.validity.check`'s
#: default): ≈ 0.55, just above the hip joint (which Winter 2009, Table 4.1, puts at 0.530).
COM_HEIGHT_FRACTION = 0.55
PHASE_NAMES = {"LR": "loading response", "MSt/TSt": "mid/terminal stance", "PSw": "pre-swing",
               "ISw": "initial swing", "MSw": "mid swing", "TSw": "terminal swing"}
N_GRID = 50
ALPHA = 0.05
SD_FLOOR = 0.1
KINDS = ("angle", "torque", "grf", "emg")
#: Channels located only against a background that carries them (a change relative to a
#: reference, :mod:`gaitlib.gap.reference`): the HAT's tilt against the data's pelvic tilt.
#: Absolute, the model's upright HAT against the data's ≈ 11° forward pelvis is a constant
#: misfit of the model (why the hip is tracked as the thigh in the laboratory); relative, that
#: constant cancels and the tilt's *change* is located — without it a hip-angle offset and a
#: HAT COM offset are the same change on the located channels (the HAT tilts by the offset,
#: its COM kept over the hips).
RELATIVE_ONLY = ("pelvis_tilt",)
UNITS = {"angle": "rad", "torque": "N*m", "grf": "N", "emg": "1"}


def phase_edges(events: dict) -> np.ndarray:
    """Phase boundaries (fractions of the cycle, 7 values from 0 to 1) of the reference leg."""
    ofo = float(events.get("opposite_foot_off", 0.1))
    ofc = float(events.get("opposite_foot_contact", 0.5))
    fo = float(events.get("foot_off", 0.6))
    if not 0 < ofo < ofc < fo < 1:
        raise ValueError(f"cycle events not ordered 0 < opposite foot off < opposite foot contact < foot off < 1: {events}")
    sw = 1.0 - fo
    return np.array([0.0, ofo, ofc, fo, fo + sw / 3, fo + 2 * sw / 3, 1.0])


def phase_of(tau, events: dict, shift: float = 0.0) -> np.ndarray:
    """Phase label of each normalised time τ (leg shifted by ``shift`` of the cycle)."""
    e = phase_edges(events)
    tt = np.mod(np.asarray(tau, float) - shift, 1.0)
    i = np.clip(np.searchsorted(e, tt, side="right") - 1, 0, len(PHASES) - 1)
    return np.array(PHASES, dtype=object)[i]


def _emg_map(source: str) -> dict:
    """muscle → data EMG stem (``emg_TA``) for the muscles the source has."""
    return {m: d[source] for m, d in activation.EMG_CHANNELS.items() if d.get(source)}


def sim_channels(sol: "gait_ocp.GaitSolution", source: str = "schwartz2008") -> pd.DataFrame:
    """The solution's channels on normalised time τ = t / t_f (index, one period, sorted):
    angles ``hip_r`` …, net torques ``tau_hip_r`` …, GRFs ``grf_x_r`` …, pelvis tilt, the
    HAT residual loads ``res_R_x``, ``res_R_y`` (N), ``res_R_z`` (N·m) and,
    for NMSK (excitations) or MSK (generator activations), ``emg_<stem>_<side>`` on the
    data's EMG channel names."""
    tf = float(sol.stats["tf_s"])
    t = sol.q.index.to_numpy(float)
    out = {}
    for j in gait_ocp.LEG_JOINTS:
        out[j] = sol.q[j].to_numpy()
        out[f"tau_{j}"] = sol.torques[j].to_numpy()
    for g in gait_ocp.GRF_CHANNELS:
        out[g] = sol.grf[g].to_numpy()
    out["pelvis_tilt"] = sol.q["pelvis_tilt"].to_numpy()
    if getattr(sol, "residuals", None) is not None:
        for r in cv.RESIDUALS:
            out[f"res_{r}"] = sol.residuals[r].to_numpy()
    for m, stem in _emg_map(source).items():
        for s in cv.SIDES:
            if sol.excitations is not None:
                out[f"{stem}_{s}"] = sol.excitations[f"{m}_{s}"].to_numpy()
            elif sol.activations is not None:
                out[f"{stem}_{s}"] = sol.activations[f"a_{activation.MUSCLE_GENERATOR[m]}_{s}"].to_numpy()
    df = pd.DataFrame(out, index=pd.Index(np.mod(t / tf, 1.0), name="tau"))
    df = df[~df.index.duplicated(keep="first")].sort_index()
    return df


def periodic(tau_src, y, tau):
    """``y`` (one period on ``tau_src`` ⊂ [0, 1)) read at ``tau`` by periodic linear interpolation."""
    ts = np.concatenate([tau_src - 1.0, tau_src, tau_src + 1.0])
    return np.interp(np.mod(tau, 1.0), ts, np.tile(y, 3))


def resels(z: np.ndarray, keep: np.ndarray | None = None) -> float:
    """Resels of a periodic 1-D residual curve (module docstring), in [1, len(z)]; ``keep``
    (bool, same length): only those points count — the roughness from the pairs of
    neighbours both kept, the variance over the kept points, resels = kept / FWHM."""
    z = np.asarray(z, float)
    keep = np.ones(z.size, bool) if keep is None else np.asarray(keep, bool)
    n = int(keep.sum())
    if n < 2:
        return float(max(n, 1))
    zk = z[keep]
    v = float(np.sum((zk - zk.mean()) ** 2))
    d2 = ((np.roll(z, -1) - z) ** 2)[keep & np.roll(keep, -1)]
    if v <= 1e-300 or not d2.size:
        return 1.0
    lam = float(np.sum(d2)) / v * (n / d2.size)  # the mean squared difference × n
    if lam <= 0:
        return 1.0
    fwhm = np.sqrt(4 * np.log(2) / lam)
    return float(np.clip(n / fwhm, 1.0, n))


def _channels(gait, sim_cols, exclude=(), extra=()) -> tuple[list, list]:
    """(included, excluded) channel descriptors: dict(id, kind, name, side, col); ``extra``:
    angle channels of neither leg (side ``"-"``, the right leg's phases), e.g. the HAT tilt
    of a relative location (:data:`RELATIVE_ONLY`)."""
    inc, exc = [], []
    cand = [("angle", j, j) for j in gait_ocp.LEG_JOINTS] + [("torque", j, f"tau_{j}") for j in gait_ocp.LEG_JOINTS] \
        + [("grf", g, g) for g in gait_ocp.GRF_CHANNELS]
    emg_cols = sorted(c for c in sim_cols if c.startswith("emg_"))
    cand += [("emg", c[4:], c) for c in emg_cols]
    cand += [("angle", c, c) for c in extra]
    for kind, name, col in cand:
        d = {"id": f"{kind}:{name}", "kind": kind, "name": name, "side": "-" if name in extra else name[-1],
             "col": col}
        if col not in gait.mean.columns or col not in sim_cols:
            d["reason"] = "not in the data" if col not in gait.mean.columns else "not in the solution"
            exc.append(d)
        elif col in exclude:
            d["reason"] = "data filled from another data set"
            exc.append(d)
        elif not np.any(gait.sd[col].to_numpy() > 0):
            d["reason"] = "no SD in the data"
            exc.append(d)
        else:
            inc.append(d)
    return inc, exc


@dataclass
class Located:
    """The located gap of one solution against one data set.

    ``points``: long table per channel and grid point (tau, phase, sim, mean, sd, sd_eff,
    z, p_bonf, out_of_band); ``table``: channel × phase (n, mean_z, rms_z, frac_out, p_min,
    significant); ``channels``: per channel (rss, n, resels, rms_z, significant);
    ``excluded``: channels not standardised and why.
    """

    points: pd.DataFrame
    table: pd.DataFrame
    channels: pd.DataFrame
    excluded: list = field(default_factory=list)
    n_subjects: int = 1
    residuals: pd.DataFrame | None = None  # :func:`residual_table`; not in the RSS

    @property
    def rss(self) -> float:
        return float(self.channels["rss"].sum())

    @property
    def n_points(self) -> int:
        return int(self.channels["n"].sum())

    @property
    def n_eff(self) -> float:
        return float(self.channels["resels"].sum())

    @property
    def rms_z(self) -> float:
        return float(np.sqrt(self.rss / max(self.n_points, 1)))

    def heat(self, value: str = "rms_z") -> pd.DataFrame:
        """Channel × phase matrix of ``value`` (rows in channel order)."""
        order = list(dict.fromkeys(self.table["channel"]))
        return self.table.pivot(index="channel", columns="phase", values=value).reindex(index=order, columns=list(PHASES))

    def summary(self) -> dict:
        return {"rss": self.rss, "n_points": self.n_points, "n_eff": self.n_eff, "rms_z": self.rms_z,
                "n_subjects": self.n_subjects,
                "significant_cells": int(self.table["significant"].sum()), "cells": int(len(self.table)),
                "excluded": [{"channel": d["id"], "reason": d["reason"]} for d in self.excluded],
                "residuals_over_guideline": (None if self.residuals is None
                                             else [str(c) for c in self.residuals.loc[self.residuals["over"], "channel"]])}


def locate(sim, ds, thetas: dict | None = None, exclude=(), background=None) -> Located:
    """Locate the gap of a solution (a GaitSolution or its :func:`sim_channels` frame)
    against a data set (:class:`gaitlib.gap.io.DataSet` or GaitData).

    ``thetas``: effect → parameter values of the solution's effects, for the data-model
    effects (left-leg shift, EMG timing) that change how the data are read
    (:func:`gaitlib.effects.adjust_data`). ``exclude``: model channels not to count
    (default: those a DataSet filled from another data set). ``background`` (default: a
    DataSet's own): per channel, a curve on the data's time grid added to the data (after
    the data-model effects) — a reference fit's residual (:mod:`gaitlib.gap.reference`).
    """
    n, ref_sd = 1, None
    if isinstance(ds, DataSet):
        exclude = set(exclude) | filled_channels(ds)
        n, gait = ds.n, ds.gait
        background = ds.background if background is None else background
        ref_sd = ds.reference_sd
    else:
        gait = ds
    if not isinstance(sim, pd.DataFrame):
        sim = sim_channels(sim, gait.source)
    if thetas:
        gait = effects_mod.adjust_data(gait, thetas)
    view = gait_ocp.tracking_data(gait)
    if background is not None:
        mean = view.mean.copy()
        for c in background.columns:
            mean[c] = mean[c].to_numpy() + background[c].to_numpy()
        view = dataclasses.replace(view, mean=mean)
    tau = np.arange(N_GRID) / N_GRID
    t_data = np.asarray(view.time, float) / float(view.cycle_time)
    extra = [c for c in RELATIVE_ONLY if background is not None and c in background.columns]
    inc, exc = _channels(view, set(sim.columns), exclude, extra)
    tau_src = sim.index.to_numpy(float)
    rows, chans = [], []
    for ch in inc:
        col = ch["col"]
        m = np.interp(tau, t_data, view.mean[col].to_numpy())
        sd = np.interp(tau, t_data, view.sd[col].to_numpy())
        floor = SD_FLOOR * float(np.sqrt(np.mean(sd**2)))
        sde = np.maximum(sd, floor)
        s = periodic(tau_src, sim[col].to_numpy(), tau)
        z = (s - m) / sde
        se = sde / np.sqrt(max(n, 1))
        Z = (np.abs(s - m) - sde) / se
        p = np.minimum(1.0, norm.sf(Z) * N_GRID)
        shift = float(gait.left_shift) if ch["side"] == "l" else 0.0
        ph = phase_of(tau, gait.events, shift)
        keep = np.ones(N_GRID, bool)
        if ref_sd is not None and col in ref_sd.columns:  # relative: points where neither set has variance
            sd_r = np.interp(tau, t_data, ref_sd[col].to_numpy())
            keep = ~((sd < floor) & (sd_r < SD_FLOOR * float(np.sqrt(np.mean(sd_r**2)))))
            if not keep.any():
                exc.append({**ch, "reason": "no variance in the data or the reference"})
                continue
        rows.append(pd.DataFrame({"channel": ch["id"], "kind": ch["kind"], "name": ch["name"], "side": ch["side"],
                                  "tau": tau, "phase": ph, "sim": s, "mean": m, "sd": sd, "sd_eff": sde, "z": z,
                                  "p_bonf": p, "out_of_band": np.abs(z) > 1})[keep])
        zk = z[keep]
        chans.append({"channel": ch["id"], "kind": ch["kind"], "name": ch["name"], "side": ch["side"],
                      "rss": float(np.sum(zk**2)), "n": int(keep.sum()),
                      "resels": resels(z, keep),
                      "rms_z": float(np.sqrt(np.mean(zk**2))), "significant": bool(np.any(p[keep] < ALPHA))})
    points = pd.concat(rows, ignore_index=True) if rows else pd.DataFrame()
    table = _aggregate(points)
    res = residual_table(sim, gait) if all(f"res_{r}" in sim.columns for r in cv.RESIDUALS) else None
    return Located(points, table, pd.DataFrame(chans), exc, n, res)


def residual_thresholds(gait) -> dict:
    """OpenSim's residual guidelines (Hicks et al. 2015, J Biomech Eng 137:020905; the same
    fractions as the validity gates, :data:`gaitlib.validity.RESIDUAL_FORCE_FRACTION` and
    :data:`~gaitlib.validity.RESIDUAL_MOMENT_FRACTION`: peak residual force ≤ 5 % of the peak
    external force, peak residual moment ≤ 1 % of COM height × that force) for the data's
    child: peak external force = the
    peak magnitude of the data's total GRF (both feet), COM height = :data:`COM_HEIGHT_FRACTION`
    × body height. Returns channel → threshold (N, N, N·m)."""
    m = gait.mean
    fx = m["grf_x_r"].to_numpy(float) + m["grf_x_l"].to_numpy(float)
    fy = m["grf_y_r"].to_numpy(float) + m["grf_y_l"].to_numpy(float)
    f_peak = float(np.max(np.hypot(fx, fy)))
    return {"R_x": RESIDUAL_FORCE_FRACTION * f_peak, "R_y": RESIDUAL_FORCE_FRACTION * f_peak,
            "R_z": RESIDUAL_MOMENT_FRACTION * COM_HEIGHT_FRACTION * float(gait.body_height) * f_peak}


def residual_table(sim: pd.DataFrame, gait) -> pd.DataFrame:
    """The HAT residual loads as located channels: per residual, its peak and RMS over the
    cycle, the guideline threshold (:func:`residual_thresholds`), peak/threshold and whether
    it is over. The residuals have no data SD: they are compared with the guideline, not
    standardised, and are not part of the RSS (they are bounded by the problem, Eq 4.8)."""
    thr = residual_thresholds(gait)
    rows = []
    for r in cv.RESIDUALS:
        v = sim[f"res_{r}"].to_numpy(float)
        peak = float(np.max(np.abs(v)))
        rows.append({"channel": f"residual:{r}", "unit": "N*m" if r == "R_z" else "N", "peak": peak,
                     "rms": float(np.sqrt(np.mean(v**2))), "threshold": thr[r], "peak_ratio": peak / thr[r],
                     "over": peak > thr[r]})
    return pd.DataFrame(rows)


def _aggregate(points: pd.DataFrame) -> pd.DataFrame:
    if points.empty:
        return pd.DataFrame(columns=["channel", "kind", "side", "phase", "n", "mean_z", "rms_z", "frac_out",
                                     "p_min", "significant"])
    g = points.groupby(["channel", "phase"], sort=False)
    t = g.agg(kind=("kind", "first"), side=("side", "first"), n=("z", "size"), mean_z=("z", "mean"),
              frac_out=("out_of_band", "mean"), p_min=("p_bonf", "min")).reset_index()
    # RMS per cell over the cell's points in their order (numpy's sum, as over a column)
    z, at = points["z"].to_numpy(float), g.indices
    t.insert(t.columns.get_loc("mean_z") + 1, "rms_z",
             [float(np.sqrt(np.mean(np.square(z[at[k]])))) for k in zip(t["channel"], t["phase"])])
    t["significant"] = t["p_min"] < ALPHA
    t["phase"] = pd.Categorical(t["phase"], categories=list(PHASES), ordered=True)
    order = {c: i for i, c in enumerate(dict.fromkeys(points["channel"]))}
    t = t.sort_values(["channel", "phase"], key=lambda s: s.map(order) if s.name == "channel" else s)
    t["phase"] = t["phase"].astype(str)
    return t.reset_index(drop=True)


# ``gaitlib.gap.locate(...)`` calls :func:`locate` even after this submodule was imported
# (gaitlib.gap._CallableModule).
from . import _callable  # noqa: E402

_callable("locate")
