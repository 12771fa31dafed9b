"""Diagnose a change against a reference data set, not a whole gap.

The gap diagnosis (:mod:`gaitlib.gap.diagnose`) asks which unmodelled effect explains the
model's misfit to *one* data set. On real data that misfit is large and mostly the model's
own (Schwartz 2008 *Free*: baseline RSS ≈ 650 on n_eff ≈ 270), so a laboratory effect of
middle size adds a few per cent to it and cannot stand out (Chapter 8's validation). A
laboratory usually has a second question that does not carry the model's own gap: *what
changed between two data sets* — this laboratory's children and the normative set, one
marker protocol and another, before and after a plate recalibration.

Relative data
-------------
With R the reference data, N the new data and, for each model k (the baseline and every
candidate), F_k(R) its fit of R (the absolute diagnosis's fits, every start) and F_k(N) its
fit of N *continued from F_k(R)* (one warm start: the same basin, so the two fits differ by
the change, not by the local optimum a multistart lands in), model k's located gap is

    [F_k(N) − N_k] − [F_k(R) − R_k]

channel by channel on the data's time grid, as the gait problem tracks them (the hip as
the thigh in the laboratory, :func:`gaitlib.problems.gait.tracking_data`; model units), with
N's SD; N_k, R_k are the data as model k reads them at its parameters on each (a data-model
effect — offset, plate bias, left-leg shift — adjusts the data before the background
F_k(R) − R_k is subtracted). Implemented as a background added to N where the gap is
located (:func:`relative_data`, :attr:`gaitlib.gap.io.DataSet.background`); the fits never
see it. So when nothing changed the baseline's relative gap is its response to sampling
error; when N is R with an effect the library represents exactly (a marker offset c), that
effect's fit reads N − c = R and continues to F_k(R), a relative gap of zero; the model's
own misfit to R, which swamps a middle-sized laboratory effect in the absolute diagnosis,
cancels. Each candidate's parameter change from R to N is reported. The sampling error of a
difference of two independent group means of n_N and n_R subjects is SD·√(1/n_N + 1/n_R),
so the relative data have ``n = round(1 / (1/n_N + 1/n_R))`` subjects.

The HAT tilt
------------
Relative, the located channels include the HAT's tilt against the data's pelvic tilt
(:data:`gaitlib.gap.locate.RELATIVE_ONLY`; RELATIVE ``tilt_channel``): the model's upright
HAT against the data's forward-tilted pelvis is a constant misfit that cancels in
[F_k(N) − N] − [F_k(R) − R], and without the tilt a hip-angle offset and a HAT COM offset
are the same change on the other channels (the HAT tilts by the offset with its COM kept
over the hips; Chapter 8: ΔBIC equal to 0.1 in both hip-offset cases of revision 2).

Self-consistent reference fits
------------------------------
A multistart does not always find the reference's best basin, and the continuation from it
can move into a better one on a small data change: the relative gap then carries a change of
the fit, not of the data (Chapter 8: re-solved from a null draw's fit, the reference reached
a lower objective than its kept fit in 2 of 4 draws). So each model's F_k(R) is re-solved
from its F_k(N); where that is lower it replaces F_k(R) for this data set and N is continued
again from it (:func:`gaitlib.gap.diagnose.consistent_fits`, RELATIVE ``reference_rounds``).
Before that, the baseline's F(N) is also re-solved from every nested candidate's F_k(N) and
the lowest kept (RELATIVE ``baseline_from_candidates``): a baseline continuation stopped in
a worse optimum than its own extensions reach would credit every candidate with the
difference (Chapter 8, revision 3's null draws). From revision 7 the baseline's F(R) is
re-solved the same way, from every nested candidate's F_k(R), before N is continued from it
(RELATIVE ``reference_from_candidates``): the reference's multistart was not the lowest
optimum the baseline reaches on R, and where the rounds kept it, every candidate was
credited alike (Chapter 8, "Where the tail comes from").

Null calibration
----------------
On this clean background a free parameter absorbs a share of pure sampling error that the
criterion (ΔBIC with n_eff the resels of the baseline's residual) counts as very strong
evidence: in the first relative validation (Chapter 8), draws in which nothing changed
reached ΔBIC −134. So the reference is redrawn K times within the sampling error of the
difference (:func:`null_draw`; K and the seeds from
:data:`gaitlib.gap.method.RELATIVE`), each draw diagnosed relative to the reference exactly
as the data are; each draw's statistic is the lowest ΔBIC any candidate reached on it (a
max statistic over the candidates), and the top effect must also beat the r-th lowest of
the K statistics (:func:`gaitlib.gap.diagnose.null_calibration`,
:func:`gaitlib.gap.method.null_threshold`): a rank test at level r/(K + 1) (revision 5:
r = 2 of K = 19; revisions 1–4: the lowest of 9).

Quiet points
------------
Where neither data set has variance — both SDs below :func:`gaitlib.gap.locate.locate`'s floor:
the GRFs in each foot's swing, zero in every child — nothing in the data can change, and a
located change there is the model's own misfit changing with a candidate (revision 4's
replicates: a heavier model presses its swing foot's load, 70–76 N where the data carry none,
harder; ``benchmarks/gap_load_confusion.py``). From revision 6 (RELATIVE ``quiet_points``) those
points are not located: the reference's SD travels with the relative data set
(``DataSet.reference_sd``) and :func:`gaitlib.gap.locate.locate` leaves out the points where
both SDs are below the floor (their RSS and resels).

Assumptions, stated: the model's own misfit F_k(R) − R does not change with the effect (first
order: an effect that changes the gait changes the misfit too; the quiet points above are
where it fails most visibly); both data sets have the same
time grid, cycle time and speed (a change of cadence is not a curve offset: refused with a
one-line error). Channels the reference fit does not simulate (EMG for SK) get no background.
"""

from __future__ import annotations

import dataclasses
import hashlib

import numpy as np
import pandas as pd

from .. import effects as effects_mod
from ..problems import gait as gait_ocp
from . import io as gio
from . import locate
from .method import RELATIVE
from .noise import smooth_noise

__all__ = ["relative_data", "relative_n", "check_same_grid", "offset_channels", "background", "null_draw",
           "null_seed"]


def relative_n(n_new: int, n_ref: int) -> int:
    """Subjects of a difference of two independent group means (its SE is SD/√n)."""
    if n_new < 1 or n_ref < 1:
        raise ValueError(f"relative_n: subjects must be >= 1, got {n_new} and {n_ref}")
    return max(1, int(round(1.0 / (1.0 / n_new + 1.0 / n_ref))))


def check_same_grid(ds: gio.DataSet, ref: gio.DataSet) -> None:
    """ValueError (one line, naming both data sets) unless ``ds`` and ``ref`` share the time
    grid, cycle time and speed."""
    g, g0 = ds.gait, ref.gait
    what = None
    if abs(float(g.cycle_time) - float(g0.cycle_time)) > 1e-9:
        what = f"cycle time {g.cycle_time:.4f} s vs {g0.cycle_time:.4f} s"
    elif abs(float(g.speed) - float(g0.speed)) > 1e-9:
        what = f"speed {g.speed:.4f} m/s vs {g0.speed:.4f} m/s"
    elif len(g.time) != len(g0.time) or not np.allclose(g.time, g0.time, atol=1e-9):
        what = f"time grids of {len(g.time)} and {len(g0.time)} points differ"
    if what:
        raise ValueError(f"reference: {ds.label} and {ref.label} differ in {what}; a change relative to a reference "
                         "needs the same speed class and time grid")


def offset_channels(gait, sim, tilt: bool | None = None) -> list:
    """The channels N' replaces: those the fit tracks or locates (angles, net torques, GRFs,
    EMG) that both the data and the reference fit have, and (``tilt``, default
    ``RELATIVE.tilt_channel``) the HAT tilt (:data:`gaitlib.gap.locate.RELATIVE_ONLY`),
    which :func:`gaitlib.gap.locate.locate` then locates."""
    tilt = RELATIVE.tilt_channel if tilt is None else tilt
    cols = [j for j in gait_ocp.LEG_JOINTS] + [f"tau_{j}" for j in gait_ocp.LEG_JOINTS] + list(gait_ocp.GRF_CHANNELS)
    cols += sorted(c for c in sim.columns if c.startswith("emg_"))
    cols += list(locate.RELATIVE_ONLY) if tilt else []
    return [c for c in cols if c in gait.mean.columns and c in sim.columns]


def background(ref: gio.DataSet, ref_fit, thetas: dict | None = None, tilt: bool | None = None):
    """S_R − R (module docstring) on the reference's time grid, one column per
    :func:`offset_channels` (model units, the tracked representation; ``tilt`` as there);
    ``thetas``: the fit's effect parameters, for the data-model effects that change how R
    is read (:func:`gaitlib.effects.adjust_data`)."""
    sim = ref_fit if hasattr(ref_fit, "columns") else locate.sim_channels(ref_fit, ref.gait.source)
    g0 = effects_mod.adjust_data(ref.gait, thetas) if thetas else ref.gait
    view0 = gait_ocp.tracking_data(g0)
    t = np.asarray(view0.time, float) / float(view0.cycle_time)
    tau_src = sim.index.to_numpy(float)
    cols = offset_channels(ref.gait, sim, tilt)
    return pd.DataFrame({c: locate.periodic(tau_src, sim[c].to_numpy(), t) - view0.mean[c].to_numpy() for c in cols},
                        index=view0.mean.index)


def relative_data(ds: gio.DataSet, ref: gio.DataSet, ref_fit, tilt: bool | None = None) -> gio.DataSet:
    """``ds`` (N) located relative to ``ref`` (R): the same data and fits, with the background
    S_R − R (:func:`background`; ``ref_fit``, the baseline's fit of R: a GaitSolution or its
    :func:`gaitlib.gap.locate.sim_channels` frame; ``tilt`` as there) that
    :func:`gaitlib.gap.locate.locate` adds to the data it locates against."""
    check_same_grid(ds, ref)
    bg = background(ref, ref_fit, tilt=tilt)
    note = (f"located relative to {ref.label}: {bg.shape[1]} channels carry the reference fit's residual "
            f"(N' = N + S_R - R, gaitlib.gap.reference)")
    ref_sd = gait_ocp.tracking_data(ref.gait).sd[list(bg.columns)] if RELATIVE.quiet_points else None
    return dataclasses.replace(ds, background=bg, reference_sd=ref_sd, label=f"{ds.label} − {ref.label}",
                               n=relative_n(ds.n, ref.n),
                               notes=tuple(ds.notes) + (note,),
                               n_source=f"1/(1/{ds.n} + 1/{ref.n}) (difference of two group means)")


def null_seed(ref: gio.DataSet, draw: int, method_hash: str) -> int:
    """The seed of null draw ``draw`` of reference ``ref`` under a relative method's hash."""
    return int(hashlib.sha256(f"{method_hash}|{ref.signature}|null|{draw}".encode()).hexdigest()[:12], 16) % 2**31


def null_draw(ref: gio.DataSet, n: int, seed: int) -> gio.DataSet:
    """Another group like ``ref`` with nothing changed: every channel's mean + SD/√n · g(τ)
    (g: :func:`gaitlib.gap.noise.smooth_noise`, one curve per channel; ``n``: the subjects
    of the difference, :func:`relative_n`), the left leg regenerated from the right when
    ``ref``'s is generated (as the reader does), SDs unchanged."""
    if n < 1:
        raise ValueError(f"null_draw: n (subjects) must be >= 1, got {n}")
    g = ref.gait
    generated = effects_mod.left_generated(g)
    rng = np.random.default_rng(int(seed))
    t = np.asarray(g.time, float) / float(g.cycle_time)
    cols = [c for c in g.mean.columns if not (generated and c.endswith("_l"))]
    eps = smooth_noise(rng, len(cols))(t)
    mean = g.mean.copy()
    for i, c in enumerate(cols):
        mean[c] = g.mean[c].to_numpy() + g.sd[c].to_numpy() / np.sqrt(n) * eps[i]
    g2 = dataclasses.replace(g, mean=mean, notes=tuple(g.notes) + (f"null draw (seed {seed}, n {n})",))
    if generated:
        g2 = effects_mod.regenerate_left(g2, float(g.left_shift))
    return dataclasses.replace(ref, gait=g2, label=f"{ref.label} null draw {seed}", path=None)
