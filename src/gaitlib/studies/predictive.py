"""Chapters 6 and 7: from data tracking to prediction, and to other walking speeds.

Ch 6 (thesis Sec 6.1) — natural-speed gait with the MSK and NMSK models under eight cost
functions (Tables 6.1–6.2: ``DT SDT1 SDT2 SDT3 SP1 SP2 SP3 FP``), i.e. 16 optimal control
problems. As in the thesis:

- the HAT term (Eq 6.4) tracks the HAT motion of the model's Ch 5 data-tracking solution
  (MSK Eq 5.33, NMSK Eq 5.55), not the data's pelvis estimate (``GaitSpec.hat_reference``);
- the initial guess of the MSK runs is the data-based guess with the HAT coordinates, the
  metatarsal angles and torques and the 12 MTG activations taken from that Ch 5 solution
  (:func:`thesis_guess`); NMSK excitations would start from the EMG where the data have
  the muscle (``excitation_guess="emg"``, Sec 5.3.4). **Departure:** the Ch 6 runs of both
  models and the Ch 7 NMSK runs start from the whole Ch 5 solution (:data:`GUESS_POLICY`,
  :data:`GUESS_POLICY_CH7`, :func:`run_guess`), because from the thesis's partial guess
  several stop at the iteration limit (the chapters show those runs' statuses);
- no parameter is identified (contact, MTG and activation parameters fixed).

Ch 7 (thesis Sec 7.1) — semi-predictive slow and fast gaits: the DT cost function (Table
7.1 = the DT row of Table 6.2) of each model for the four non-natural speed classes. The
*Free* data scaled in time to the class's cycle time are tracked and give the guess
(``GaitSpec.track_class="Free"``); the class's own data give only the final time, the
stride and the state bounds, and are used afterwards to score (NRMSE, thesis Figs 7.1–7.4).
The cost of transport (Eq 5.57) of the NMSK solutions against speed is the thesis's Fig 7.5.

Our speed classes are Schwartz et al. (2008)'s (Very Slow … Very Fast); the thesis used the
XS/S/M/L classes of its own reference [18] at 0.9/1.09/1.29/1.58 m/s. Thesis numbers appear
only in columns labelled with their table or figure.

All runs go through :func:`gaitlib.problems.gait.solve_specs` (dask.distributed; ``serial=True``
in-process) and the solution cache, so a rerun only reloads.
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from .. import conventions as cv
from .. import data as data_mod
from .. import ocp
from ..problems import gait as gait_ocp
from . import gait as sg
from . import msk
from .. import marks
from .. import validity
from ..marks import failure_label

__all__ = ["CH6_COSTS", "CH7_CLASSES", "THESIS_CLASS", "THESIS_HOURS_TABLE_6_3", "THESIS_HOURS_TABLE_7_2",
           "THESIS_COT_FIG_7_5", "THESIS_FP_GAIN_PCT", "THESIS_FP_EXCITATION_GAIN_PCT",
           "THESIS_TORQUE_GAIN_PCT_CH7", "BASELINE_COST", "GUESS_POLICY", "GUESS_POLICY_CH7", "START_COLUMNS", "solve_row", "thesis_guess_runs", "baseline", "default_params", "thesis_guess", "run_guess", "ch6_specs", "ch7_specs",
           "score", "excitation_score", "StudyResult", "cost_function_study", "speed_study", "cot_table", "u_breaks",
           "times_table", "guess_lines", "SDT3_ENOUGH_FACTOR", "COT_CURVE_MIN_POINTS", "kind_nrmse", "mean_nrmse", "ch6_findings",
           "ch7_findings", "cot_figure", "Runs", "DATA_STARTS", "CH7_OWN_START", "data_start_runs",
           "data_start_study", "start_table", "start_findings"]

CH6_COSTS = ("DT", "SDT1", "SDT2", "SDT3", "SP1", "SP2", "SP3", "FP")
CH7_CLASSES = ("VerySlow", "Slow", "Fast", "VeryFast")
#: Our Schwartz 2008 class beside the thesis's class of the same rank (Ch 7).
THESIS_CLASS = {"VerySlow": "XS", "Slow": "S", "Free": "N", "Fast": "M", "VeryFast": "L"}
#: Ch 5 data-tracking cost function whose solution supplies the HAT reference and guess.
BASELINE_COST = {"MSK": "Eq5.33", "NMSK": "Eq5.55"}
#: Thesis Table 6.3, hours (GPOPS-II, i7-6700).
THESIS_HOURS_TABLE_6_3 = {
    "MSK": dict(zip(CH6_COSTS, (2, 10, 8, 3, 14, 3, 15, 10))),
    "NMSK": dict(zip(CH6_COSTS, (2, 3, 3, 1, 2, 2, 2, 6))),
}
#: Thesis Table 7.2, hours, by the thesis's class.
THESIS_HOURS_TABLE_7_2 = {"MSK": {"XS": 18, "S": 12, "M": 10, "L": 12}, "NMSK": {"XS": 8, "S": 6, "M": 4, "L": 5}}
#: Thesis Sec 6.3: the fully predictive (FP) NMSK gait's RMSEs lower than the MSK FP's by
#: (angles, torques, GRFs), per cent.
THESIS_FP_GAIN_PCT = {"angle": 20.0, "torque": 16.0, "grf": 8.0}
#: Thesis Sec 6.2.4: mean excitation RMSE of the NMSK FP gait lower than that of the Ch 5
#: data tracking (Eq 5.55) by, per cent.
THESIS_FP_EXCITATION_GAIN_PCT = 12.0
#: Thesis Secs 7.2–7.3: NMSK joint-torque NRMSE lower than the MSK's by, per cent, per class.
THESIS_TORQUE_GAIN_PCT_CH7 = {"XS": 17.0, "S": 12.0, "M": 10.0, "L": 2.0}
#: Thesis Sec 5.3.5 / 7.2 and Fig 7.5: (class, speed m/s, COT J kg⁻¹ m⁻¹).
THESIS_COT_FIG_7_5 = (("XS", 0.90, 2.18), ("S", 1.09, 1.99), ("N", 1.26, 1.53), ("M", 1.29, 1.96), ("L", 1.58, 1.99))

_HAT = cv.COORDS[:3]


def _mesh(n_intervals, degree):
    return dict(n_intervals=n_intervals, degree=degree)


def baseline(model: str, *, n_intervals: int = 20, degree: int = 5, root=None, progress: bool = False,
             reading: str = "thesis", **kw) -> gait_ocp.GaitSolution:
    """The model's Ch 5 natural-gait data-tracking solution (MSK Eq 5.33; NMSK Eq 5.55 with
    the activation parameters identified, warm-started from the MSK one) in ``reading``
    (:data:`gaitlib.studies.gait.READINGS`): :func:`gaitlib.studies.msk.solve`, solved or
    reloaded from the cache; ``kw`` override spec fields."""
    return msk.solve(model, root=root, progress=progress, reading=reading, **_mesh(n_intervals, degree), **kw)


def reading_fields(reading: str, cost: str) -> dict:
    """The :class:`~gaitlib.problems.gait.GaitSpec` fields of a Ch 6/7 run with ``cost`` in
    ``reading`` (:func:`gaitlib.studies.gait.reading_options`). FP tracks no data, so nothing
    times its swing: it keeps the data's Jrk denominators but no swing bound."""
    fields = sg.reading_options(reading)
    if cost == "FP":
        fields.pop("swing_load_max", None)
    return fields


def variant_study(models=("MSK", "NMSK"), costs=CH6_COSTS, *, n_intervals: int = 20, degree: int = 5, root=None,
                  scheduler: str | None = None, n_workers: int | None = None, serial: bool = False,
                  progress: bool = False, **changes) -> StudyResult:
    """Ch 6 runs in the book's reading with GaitSpec fields ``changes`` on top (one experiment
    of the Fidelity II work: everything else — weights, guesses, HAT reference, parameter
    sets — as :func:`cost_function_study`). Scored against the Free data."""
    params = default_params()
    how = dict(GUESS_POLICY)
    bases = {m: baseline(m, n_intervals=n_intervals, degree=degree, root=root, reading="book", **params) for m in models}
    specs, guesses = {}, {}
    for m in models:
        sp = ch6_specs(m, bases[m], costs, n_intervals=n_intervals, degree=degree, reading="book",
                       **{**params, **changes})
        specs.update(sp)
        guesses.update({k: run_guess(bases[m], how[m]) for k in sp})
    recs, sols = _run(specs, guesses, root=root, scheduler=scheduler, n_workers=n_workers, serial=serial,
                      progress=progress)
    free = data_mod.load_gait_data("Free")
    return StudyResult(specs, recs, sols, bases, _scores(sols, {"Free": free}, lambda s: "Free"), guess=how,
                       guesses=guesses)


def fp_timed_study(models=("MSK", "NMSK"), **kw) -> StudyResult:
    """The FP runs of Ch 6 in the book's reading with the swing bound timed by the data's
    events (:func:`gaitlib.validity.swing_bound` while the data say a foot swings): the
    book's FP has no swing bound (:func:`reading_fields`) and can end as a shuffle with both
    feet loaded; this experiment gives it the gait's phase timing — two event times and the
    left leg's shift, no data curve — and nothing else (:func:`variant_study`)."""
    return variant_study(models, ("FP",), swing_load_max=validity.swing_bound(), **kw)


def activation_study(costs=("DT",), **kw) -> StudyResult:
    """The NMSK Ch 6 runs in the book's reading with the activation parameters (τ_act, c3, s1,
    s2) identified with the run (``free_activation``, as Ch 5's Eq 5.55 does) instead of fixed
    to the thesis's Table 5.10 (:func:`variant_study`): how much of the NMSK runs' misfit the
    thesis's activation parameters cause on our data."""
    return variant_study(("NMSK",), costs, free_activation=True, **kw)


def ch5_activation_study(costs=CH6_COSTS, **kw) -> StudyResult:
    """The NMSK Ch 6 runs in the book's reading with the activation parameters fixed to those
    our Ch 5 NMSK solve identified on our data (``activation_params="ch5"``) instead of the
    thesis's Table 5.10 values (:func:`variant_study`): the thesis's procedure — carry Ch 5's
    identified γ into Ch 6 — applied to our data, everything else unchanged."""
    return variant_study(("NMSK",), costs, activation_params="ch5", **kw)


def activation_table(res: StudyResult, res_act: StudyResult, costs=("DT",)) -> pd.DataFrame:
    """The NMSK runs of ``costs`` with the thesis's activation parameters (``res``, the Ch 6
    study) beside the same runs with them identified (``res_act``, :func:`activation_study`),
    and the MSK run of the same cost: mark, mean NRMSE per kind and overall, and the
    activation parameters each NMSK run used (τ_act s; c3, s1, s2 dimensionless)."""
    rows = {}
    for c in costs:
        items = [(f"MSK {c}", res.solutions.get(f"MSK {c}"), "—"),
                 (f"NMSK {c}, Table 5.10's activation parameters", res.solutions.get(f"NMSK {c}"), "Table 5.10"),
                 (f"NMSK {c}, activation parameters identified", res_act.solutions.get(f"NMSK {c}"), "identified")]
        for label, sol, how in items:
            if sol is None:
                continue
            sc = score(sol, data_mod.load_gait_data("Free"))
            k = sc[sc["kind"].isin(_KINDS)].groupby("kind")["nrmse"].mean()
            ap = sol.stats.get("activation_parameters") or {}
            rows[label] = {"mark": marks.failure_label(sol) or "", "iterations": sol.stats["iterations"],
                           **{f"NRMSE {kk}": float(v) for kk, v in k.items()}, "mean NRMSE": float(k.mean()),
                           "activation parameters": how,
                           **{p: float(v) for p, v in ap.items()}}
    return pd.DataFrame(rows).T


def default_params() -> dict:
    """The parameter sets the thesis carries into Chs 6–7: those of the Ch 5 solves
    (:func:`gaitlib.studies.msk.parameter_sets`). The NMSK runs use the activation
    parameters of thesis Table 5.10 (ours, carried from Ch 5: :func:`ch5_activation_study`)."""
    return msk.parameter_sets()


#: How the runs of each model are started (see :func:`run_guess`): ``"thesis"`` — the
#: thesis's partial guess of Sec 6.1 (:func:`thesis_guess`); ``"ch5"`` — the whole Ch 5
#: solution (every state and control, time-scaled for Ch 7). The Ch 6 runs of both models
#: use ``"ch5"``: from the thesis's partial guess, several runs of either model at the full
#: mesh stop at IPOPT's 1000-iteration limit (NMSK: environment.md, "Measured choices"; MSK:
#: SDT3 and SP3) — the chapter shows the runs from the thesis's guess, with their statuses,
#: beside the runs it reports. Ch 7: :data:`GUESS_POLICY_CH7`.
GUESS_POLICY = {"MSK": "ch5", "NMSK": "ch5"}
#: The start of the Ch 7 runs: NMSK ``"ch5"`` (from the thesis's guess all four NMSK classes
#: stopped at the limit); MSK the thesis's guess — from the whole Ch 5 solution scaled in
#: time the MSK VerySlow run stops at the limit and its 3000-iteration rerun does too, while
#: from the thesis's guess only VeryFast stops at 1000 and its rerun converges (Ch 7 shows
#: both starts).
GUESS_POLICY_CH7 = {"MSK": "thesis", "NMSK": "ch5"}
GUESSES = ("thesis", "ch5")


def run_guess(base: gait_ocp.GaitSolution, how: str, *, cycle_time: float | None = None,
              stride: float | None = None) -> ocp.Solution:
    """The initial guess of a Ch 6/7 run from its model's Ch 5 solution ``base``:
    ``how="thesis"`` → :func:`thesis_guess`; ``"ch5"`` → all of ``base``'s states and
    controls (same time scaling), static parameters left to the target problem."""
    if how not in GUESSES:
        raise ValueError(f"guess must be one of {GUESSES}, got {how!r}")
    return thesis_guess(base, cycle_time=cycle_time, stride=stride, full=(how == "ch5"))


def thesis_guess(base: gait_ocp.GaitSolution, *, cycle_time: float | None = None, stride: float | None = None,
                 full: bool = False) -> ocp.Solution:
    """The part of a Ch 5 solution the thesis carries into Chs 6–7 as initial guess.

    States: HAT coordinates and metatarsal angles with their velocities and accelerations;
    controls: metatarsal torques and, for an MSK source, the 12 MTG activations (Sec 6.1).
    Everything else comes from the target problem's own data-based guess
    (:func:`gaitlib.problems.gait.warm_start` overrides by name).

    With ``cycle_time`` (s) the guess is scaled in time to that cycle (Sec 7.1: "scaled
    ... while keeping the magnitudes unchanged"): times × k, k = cycle_time / t_f, with
    velocities ÷ k and accelerations ÷ k² so the guess stays a consistent trajectory; the
    horizontal pelvis position is rescaled to ``stride`` (m) so it meets the periodic
    offset of the target problem.

    ``full=True``: every state and control of ``base`` (not the thesis's partial guess;
    see :data:`GUESS_POLICY`).
    """
    sol = base.solution
    ph = sol.phase("cycle")
    coords = list(_HAT) + ["mtp_r", "mtp_l"]
    if full:
        xs, us = list(ph.states.columns), list(ph.controls.columns)
    else:
        xs = [c for c in ph.states.columns if any(c in (k, f"qd_{k}", f"qdd_{k}") for k in coords)]
        us = [c for c in ph.controls.columns if c.startswith("tau_mtp_") or c in gait_ocp.MTG_CONTROLS]
    X, U = ph.states[xs].copy(), ph.controls[us].copy()
    tf = float(ph.tf)
    if cycle_time is not None:
        k = float(cycle_time) / tf
        X.index = X.index * k
        U.index = U.index * k
        for c in xs:
            if c.startswith("qdd_"):
                X[c] = X[c] / k**2
            elif c.startswith("qd_"):
                X[c] = X[c] / k
        for c in us:  # jerks (d³q/dt³); torques, activations and excitations keep their values
            if c.startswith("jerk_") or c.startswith("qddd_"):
                U[c] = U[c] / k**3
        tf = tf * k
    if stride is not None:
        g = gait_ocp.spec_gait_data(base.spec)[0]  # the stride base walks (on its legs)
        s0 = g.speed * g.cycle_time
        x0 = X["pelvis_tx"].iloc[0]
        X["pelvis_tx"] = x0 + (X["pelvis_tx"] - x0) * (stride / s0)
        for c in ("qd_pelvis_tx", "qdd_pelvis_tx"):
            X[c] = X[c] * (stride / s0)
        for c in us:
            if c in ("jerk_pelvis_tx", "qddd_pelvis_tx"):
                U[c] = U[c] * (stride / s0)
    phase = ocp.PhaseSolution("cycle", X, U, float(ph.t0), tf)
    f = lambda v: "None" if v is None else f"{float(v):.12g}"  # noqa: E731
    how = f"thesis_guess(full={bool(full)}, cycle_time={f(cycle_time)}, stride={f(stride)})"
    # the derivation is part of the warm start's cache signature (problems.gait.guess_signature)
    return replace(sol, phases={"cycle": phase}, parameters={}, info={**(sol.info or {}), "guess_derivation": how})


def ch6_specs(model: str, base: gait_ocp.GaitSolution, costs=CH6_COSTS, *, n_intervals: int = 20, degree: int = 5,
              reading: str = "thesis", **kw) -> dict[str, gait_ocp.GaitSpec]:
    """The Ch 6 problems of ``model`` (Table 6.2 weights), HAT reference from ``base``, in
    ``reading`` (:func:`reading_fields`)."""
    hat = gait_ocp.hat_reference_of(base)
    extra = {"excitation_guess": "emg"} if model == "NMSK" else {}
    return {f"{model} {c}": gait_ocp.GaitSpec(model=model, cost=c, speed_class="Free", hat_reference=hat,
                                        **_mesh(n_intervals, degree), **extra, **{**reading_fields(reading, c), **kw})
            for c in costs}


def ch7_specs(model: str, base: gait_ocp.GaitSolution, classes=CH7_CLASSES, *, n_intervals: int = 20, degree: int = 5,
              reading: str = "thesis", track_class: str = "Free", **kw) -> dict[str, gait_ocp.GaitSpec]:
    """The Ch 7 problems of ``model``: DT (Eqs 7.1–7.2, Table 7.1) per speed class on the
    Free data scaled in time; HAT reference = ``base``'s HAT on normalised time; in
    ``reading`` (:func:`reading_fields`). ``track_class``: ``""`` — each class tracks its own
    data instead (:attr:`GaitSpec.track_class`; not the thesis's Ch 7, a probe)."""
    hat = gait_ocp.hat_reference_of(base)
    extra = {"excitation_guess": "emg"} if model == "NMSK" else {}
    return {f"{model} {c}": gait_ocp.GaitSpec(model=model, cost="DT", speed_class=c, track_class=track_class,
                                        hat_reference=hat, **_mesh(n_intervals, degree), **extra,
                                        **{**reading_fields(reading, "DT"), **kw})
            for c in classes}


# ======================================================================================
# Scoring against a data set (any class), independent of what was tracked
# ======================================================================================
def score(sol: gait_ocp.GaitSolution, gait: data_mod.GaitData) -> pd.DataFrame:
    """RMSE and NRMSE (RMSE / data range, thesis Ch 7) of angles, net torques and foot
    forces against ``gait``'s mean, on normalised time (so a solution of another cycle
    time is compared phase by phase). Hip = thigh in the laboratory, as tracked
    (:func:`gaitlib.studies.gait.tracking_data`). Also the mean |error| in SD units.

    Returns a DataFrame with columns ``kind, channel, side, unit, rmse, nrmse, mean_z``
    (angles in deg, torques N·m, forces N; nrmse dimensionless)."""
    g = sg.tracking_data(gait)
    sim = sg.channels_frame(sol)
    tau = sim.index.to_numpy() / float(sol.stats["tf_s"])
    tg = g.time / g.cycle_time
    rows = []
    chans = [("angle", j, j, 1 / cv.DEG, "deg") for j in gait_ocp.LEG_JOINTS]
    chans += [("torque", j, f"tau_{j}", 1.0, "N*m") for j in gait_ocp.LEG_JOINTS]
    chans += [("grf", f"{ch.split('_')[1]}_{ch[-1]}", ch, 1.0, "N") for ch in gait_ocp.GRF_CHANNELS]
    for kind, name, col, scale, unit in chans:
        d = np.interp(tau, tg, g.mean[col].to_numpy())
        sd = np.interp(tau, tg, g.sd[col].to_numpy())
        e = sim[col].to_numpy() - d
        rmse = float(np.sqrt(np.mean(e**2)))
        rows.append({"kind": kind, "channel": name.rsplit("_", 1)[0], "side": name[-1], "unit": unit,
                     "rmse": rmse * scale, "nrmse": rmse / float(np.ptp(g.mean[col])),
                     "mean_z": float(np.mean(np.abs(e) / np.maximum(sd, 1e-9)))})
    return pd.DataFrame(rows)


def excitation_score(sol: gait_ocp.GaitSolution, gait: data_mod.GaitData) -> pd.DataFrame:
    """RMSE and NRMSE of the NMSK excitations e(t) against ``gait``'s EMG envelopes (both
    dimensionless, on normalised time) for the muscles that data set has (mapping
    :data:`gaitlib.studies.msk.EMG_MAP`: e.g. BF ↔ Schwartz's lateral hamstrings)."""
    if sol.excitations is None:
        raise ValueError("excitation_score needs an NMSK solution")
    col = 0 if gait.source == "schwartz2008" else 1
    tau = sol.excitations.index.to_numpy() / float(sol.stats["tf_s"])
    tg = gait.time / gait.cycle_time
    rows = []
    for m, stems in msk.EMG_MAP.items():
        stem = stems[col]
        for s in cv.SIDES:
            if stem is None or f"{stem}_{s}" not in gait.mean.columns:
                continue
            d = np.interp(tau, tg, gait.mean[f"{stem}_{s}"].to_numpy())
            e = sol.excitations[f"{m}_{s}"].to_numpy() - d
            rmse = float(np.sqrt(np.mean(e**2)))
            rows.append({"kind": "excitation", "channel": m, "side": s, "emg": stem, "unit": "1", "rmse": rmse,
                         "nrmse": rmse / max(float(np.ptp(gait.mean[f"{stem}_{s}"])), 1e-9)})
    return pd.DataFrame(rows)


# ======================================================================================
# Studies
# ======================================================================================
@dataclass
class StudyResult:
    """Runs of a Ch 6 or Ch 7 study.

    ``records``: name → :class:`gaitlib.sweep.RunRecord` (status of every run, failed ones
    included); ``solutions``: name → GaitSolution (every run that returned one, converged
    or not — check ``stats["success"]``); ``specs``: name → GaitSpec; ``baselines``: model →
    the Ch 5 solution used for HAT reference and guess; ``scores``: long table (run, model,
    case = cost/class, mark, kind, channel, side, rmse, nrmse, mean_z) against the scoring
    data; ``mark`` is the run's :func:`gaitlib.marks.failure_label` (None when converged) —
    figures hatch marked runs, headlines use :meth:`converged_scores`."""

    specs: dict
    records: dict
    solutions: dict
    baselines: dict
    scores: pd.DataFrame = field(default_factory=pd.DataFrame)
    guess: dict = field(default_factory=dict)  # model → "thesis" | "ch5" (run_guess)
    guesses: dict = field(default_factory=dict, repr=False)  # run → the initial guess used
    rerun_used: tuple = ()  # runs whose converged rerun stands in for them (:meth:`with_reruns`)
    restart_used: tuple = ()  # runs whose restart from another run's solution stands in (fidelity.with_restarts)
    restart_from: dict = field(default_factory=dict)  # run of restart_used → the start whose solution stands in

    def rerun(self, name: str, *, root=None, progress: bool = False, **changes) -> gait_ocp.GaitSolution:
        """Run ``name`` again from the same initial guess with spec fields changed (e.g.
        ``max_iter=3000`` to see where a run that hit the iteration limit ends); cached like
        every solve. A separate, labelled result — the study's record keeps its own status."""
        spec = replace(self.specs[name], **changes)
        return gait_ocp.solve_cached(spec, guess=self.guesses.get(name), root=root, progress=progress)

    def rerun_failed(self, max_iter: int = 3000, **kw) -> dict:
        """:meth:`rerun` every run whose record is not ok with ``max_iter`` iterations:
        name → GaitSolution (the investigation of runs that stopped at the limit)."""
        return {k: self.rerun(k, max_iter=max_iter, **kw) for k, r in self.records.items() if not r.ok}

    def with_reruns(self, reruns: dict) -> "StudyResult":
        """This study with each run that is marked (did not converge, or fails the validity
        gates) replaced by its rerun in ``reruns`` (:meth:`rerun_failed`) where that rerun
        converged and passes the gates: its record, solution, spec and scores.
        :attr:`rerun_used` names the replaced runs (every use is labelled by the caller).
        The book's rule for results built on several runs (Chs 6–7): a run that stopped at
        the 1000-iteration limit is represented by its converged 3000-iteration rerun, from
        the same start, rather than left out; a rerun that did not converge or is invalid
        changes nothing."""
        use = {k: s for k, s in reruns.items()
               if k in self.records and s is not None and s.stats.get("success") and not marks.failure_label(s)
               and marks.failure_label(self.solutions.get(k, self.records[k]))}
        if not use:
            return self
        recs, sols, specs = dict(self.records), dict(self.solutions), dict(self.specs)
        for k, s in use.items():
            recs[k] = replace(recs[k], ok=True, status=s.stats["status"], value=s, error=None)
            sols[k], specs[k] = s, s.spec
        key = lambda s: (s.spec.speed_class, s.spec.source, s.spec.leg_scale)  # noqa: E731
        gaits = {key(s): data_mod.load_gait_data(s.spec.speed_class, s.spec.source,
                                                 **({} if s.spec.leg_scale is None else {"leg_scale": s.spec.leg_scale}))
                 for s in use.values()}
        new = _scores(use, gaits, key)
        sc = self.scores[~self.scores["run"].isin(list(use))] if not self.scores.empty else self.scores
        order = {k: i for i, k in enumerate(self.records)}
        sc = pd.concat([sc, new], ignore_index=True).sort_values("run", key=lambda r: r.map(order), kind="stable")
        return replace(self, specs=specs, records=recs, solutions=sols, scores=sc.reset_index(drop=True),
                       rerun_used=tuple(self.rerun_used) + tuple(use))

    def rerun_table(self, reruns: dict) -> pd.DataFrame:
        """The study's own status and objective of each rerun run beside the rerun's."""
        rows = {}
        for k, s in reruns.items():
            own = self.solutions.get(k)
            rows[k] = {"mark (rerun)": marks.failure_label(s) or "", "status (study)": self.records[k].status,
                       "objective (study)": own.stats["objective"] if own is not None else np.nan,
                       "max_iter (rerun)": s.spec.max_iter, "status (rerun)": s.stats["status"],
                       "iterations (rerun)": s.stats["iterations"], "objective (rerun)": s.stats["objective"],
                       "max violation (rerun)": s.stats["max_violation"], "solve (s, rerun)": s.stats["solve_time_s"]}
        return pd.DataFrame(rows).T

    def marks(self) -> dict:
        """Run name → failure label (:func:`gaitlib.marks.failure_label`; None when converged)."""
        return {k: marks.failure_label(self.solutions.get(k, rec)) for k, rec in self.records.items()}

    def converged_scores(self) -> pd.DataFrame:
        """:attr:`scores` of the unmarked runs only (converged and passing the validity gates,
        :func:`gaitlib.marks.failure_label`) — what a headline may use."""
        return marks.unmarked(self.scores)

    def stats(self) -> pd.DataFrame:
        rows = []
        for name, rec in self.records.items():
            sol = self.solutions.get(name)
            rows.append({"run": name, "mark": marks.failure_label(sol if sol is not None else rec) or "",
                         "guess": self.guess.get(name.split(" ", 1)[0]), "status": rec.status,
                         **solve_row(sol), "error": rec.error})
        return pd.DataFrame(rows).set_index("run")


def solve_row(sol) -> dict:
    """What a solve reports, as one table row: converged, iterations, solve and build time (s),
    ms per iteration, objective, max violation, whether it came from the cache and the COT
    (J kg⁻¹ m⁻¹; NaN for MSK). ``sol`` None (the run raised) → the same keys, empty."""
    st = sol.stats if sol is not None else {}
    return {"converged": bool(st.get("success", False)), "iterations": st.get("iterations"),
            "solve (s)": st.get("solve_time_s"), "ms/iteration": 1e3 * st["time_per_iteration_s"] if st else np.nan,
            "build (s)": st.get("build_time_s"), "objective": st.get("objective"),
            "max violation": st.get("max_violation"), "from cache": st.get("from_cache"),
            "COT (J/kg/m)": st.get("COT", np.nan)}


def _run(specs: dict, guesses: dict, *, root, scheduler, n_workers, serial, progress) -> tuple[dict, dict]:

    recs = gait_ocp.solve_specs(specs, guesses=guesses, cache_root=root, scheduler=scheduler, n_workers=n_workers,
                             serial=serial, progress=progress)
    sols = {k: r.value for k, r in recs.items() if r.value is not None}
    return recs, sols


def _scores(sols: dict, gaits: dict, key_of) -> pd.DataFrame:
    parts = []
    for name, sol in sols.items():
        model, label = name.split(" ", 1)
        g = gaits[key_of(sol)]
        df = score(sol, g)
        if model == "NMSK":
            df = pd.concat([df, excitation_score(sol, g)], ignore_index=True)
        df.insert(0, "run", name)
        df.insert(1, "model", model)
        df.insert(2, "case", label)
        df.insert(3, "mark", marks.failure_label(sol))
        parts.append(df)
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame()


def cost_function_study(models=("MSK", "NMSK"), costs=CH6_COSTS, *, n_intervals: int = 20, degree: int = 5,
                        root=None, scheduler: str | None = None, n_workers: int | None = None, serial: bool = False,
                        progress: bool = True, source: str = "schwartz2008", params: dict | None = None,
                        guess: dict | None = None, reading: str = "thesis") -> StudyResult:
    """Thesis Ch 6: the ``models`` × ``costs`` runs, scored against the Free data, in
    ``reading`` (:data:`gaitlib.studies.gait.READINGS`: the runs, :func:`reading_fields`, and
    the Ch 5 baselines they start from).

    ``guess``: model → ``"thesis"`` | ``"ch5"`` overriding :data:`GUESS_POLICY` (how each
    model's runs are started, :func:`run_guess`).

    ``params``: GaitSpec fields naming the parameter sets of every run and of the Ch 5
    baselines (e.g. ``{"mtg_params": "ch5", "body_params": "ch4", "contact_params": "ch4"}``
    — the thesis carries the identified values of Chs 4–5 into Ch 6); default
    :func:`default_params`."""
    params = default_params() if params is None else dict(params)
    how = {**GUESS_POLICY, **(guess or {})}
    bases = {m: baseline(m, n_intervals=n_intervals, degree=degree, root=root, source=source, reading=reading,
                         **params)
             for m in models}
    specs, guesses = {}, {}
    for m in models:
        sp = ch6_specs(m, bases[m], costs, n_intervals=n_intervals, degree=degree, source=source, reading=reading,
                       **params)
        specs.update(sp)
        guesses.update({k: run_guess(bases[m], how[m]) for k in sp})
    recs, sols = _run(specs, guesses, root=root, scheduler=scheduler, n_workers=n_workers, serial=serial,
                      progress=progress)
    gaits = {"Free": data_mod.load_gait_data("Free", source)}
    return StudyResult(specs, recs, sols, bases, _scores(sols, gaits, lambda s: "Free"), guess=how,
                       guesses=guesses)


def speed_study(models=("MSK", "NMSK"), classes=CH7_CLASSES, *, n_intervals: int = 20, degree: int = 5,
                root=None, scheduler: str | None = None, n_workers: int | None = None, serial: bool = False,
                progress: bool = True, source: str = "schwartz2008", params: dict | None = None,
                guess: dict | None = None, reading: str = "thesis", weights: tuple = ()) -> StudyResult:
    """Thesis Ch 7: DT per model and speed class on time-scaled Free data, scored against
    each class's own data (never tracked). ``params``, ``guess`` and ``reading`` as
    :func:`cost_function_study`; ``weights``: ``(term, weight)`` overrides of Table 7.1's
    (:attr:`gaitlib.problems.gait.GaitSpec.weights`; e.g. :data:`LOOSE_TRACKING`)."""
    if weights:
        params = {**(default_params() if params is None else params), "weights": tuple(weights)}
    params = default_params() if params is None else dict(params)
    how = {**GUESS_POLICY_CH7, **(guess or {})}
    base_params = {k: v for k, v in params.items() if k not in _RUN_ONLY}
    bases = {m: baseline(m, n_intervals=n_intervals, degree=degree, root=root, source=source, reading=reading,
                         **base_params)
             for m in models}
    # the guess's cycle time and stride: on longer legs the data's speed and cadence give other ones
    legs = {} if params.get("leg_scale") is None else {"leg_scale": float(params["leg_scale"])}
    gaits = {c: data_mod.load_gait_data(c, source, **legs) for c in classes}
    specs, guesses = {}, {}
    for m in models:
        sp = ch7_specs(m, bases[m], classes, n_intervals=n_intervals, degree=degree, source=source, reading=reading,
                       **params)
        specs.update(sp)
        for k, s in sp.items():
            g = gaits[s.speed_class]
            guesses[k] = run_guess(bases[m], how[m], cycle_time=g.cycle_time, stride=g.speed * g.cycle_time)
    recs, sols = _run(specs, guesses, root=root, scheduler=scheduler, n_workers=n_workers, serial=serial,
                      progress=progress)
    return StudyResult(specs, recs, sols, bases, _scores(sols, gaits, lambda s: s.spec.speed_class),
                       guess=how, guesses=guesses)


#: ``params`` of :func:`speed_study` that set the runs only, not the Ch 5 baseline they start
#: from (the baseline identifies its own activation parameters, Eq 5.55).
_RUN_ONLY = ("weights", "activation_params", "track_class")


def ch5_activation_speed_study(**kw) -> StudyResult:
    """The NMSK Ch 7 runs in the book's reading with our Ch 5 activation parameters
    (:func:`ch5_activation_study`'s change) instead of Table 5.10's, everything else as
    :func:`speed_study`."""
    return speed_study(("NMSK",), reading="book", params={**default_params(), "activation_params": "ch5"}, **kw)


#: The Ch 7 pin experiment: Table 7.1's three data-tracking weights (Trq, Ang, GRF; 1/4
#: each) divided by 10, every other term unchanged — does a prediction held less tightly to
#: the time-scaled Free data move towards the untracked class data?
LOOSE_TRACKING = (("Trq", 1 / 40), ("Ang", 1 / 40), ("GRF", 1 / 40))
#: Its opposite: the three data-tracking weights × 10 (10/4 each) — with each class's own data
#: as the input (``fidelity.consistent_speed_study(own_data=True)``), how does a gait held
#: close to the children's gait at each speed cost per metre?
TIGHT_TRACKING = (("Trq", 10 / 4), ("Ang", 10 / 4), ("GRF", 10 / 4))


class Runs:
    """Solutions by run name as a study's ``solutions`` (what :func:`input_pull` and
    :func:`cot_table` read), for runs gathered outside a :class:`StudyResult`; None values
    (runs that raised or are not stored) left out."""

    def __init__(self, runs: dict):
        self.solutions = {k: s for k, s in runs.items() if s is not None}


def input_pull(res: StudyResult, gaits: dict) -> pd.DataFrame:
    """Where each Ch 7 prediction sits between what it tracked and what it should predict:
    per run and kind (angles, torques, GRFs; mean NRMSE over the kind's channels), its NRMSE
    against the class's own data (untracked), against the time-scaled *Free* data it tracked,
    and the control (that scaled data against the class data). ``gaits``: class → GaitData
    (the *Free* class included). A prediction pinned to its input has a small NRMSE against
    the input and about the control's against the class."""
    rows = []
    for name, sol in res.solutions.items():
        c = sol.spec.speed_class
        scaled = data_mod.time_scaled(gaits["Free"], gaits[c])
        vs_class, vs_input = score(sol, gaits[c]), score(sol, scaled)
        for kind in _KINDS:
            rows.append({"run": name, "kind": kind, "mark": marks.failure_label(sol) or "",
                         "vs class data": float(vs_class.loc[vs_class["kind"] == kind, "nrmse"].mean()),
                         "vs tracked input": float(vs_input.loc[vs_input["kind"] == kind, "nrmse"].mean()),
                         "control: input vs class": _input_vs_class(scaled, gaits[c], kind)})
    return pd.DataFrame(rows).set_index(["run", "kind"])


def _input_vs_class(scaled: data_mod.GaitData, cls: data_mod.GaitData, kind: str) -> float:
    """Mean NRMSE over ``kind``'s channels of the time-scaled Free data against the class's
    data (each channel's RMSE over the class's range; the channels :func:`score` scores)."""
    f, g = sg.tracking_data(scaled), sg.tracking_data(cls)
    chans = {"angle": list(gait_ocp.LEG_JOINTS), "torque": [f"tau_{j}" for j in gait_ocp.LEG_JOINTS],
             "grf": list(gait_ocp.GRF_CHANNELS)}[kind]
    out = []
    for ch in chans:
        d = np.interp(f.time / f.cycle_time, g.time / g.cycle_time, g.mean[ch].to_numpy())
        out.append(np.sqrt(np.mean((f.mean[ch].to_numpy() - d) ** 2)) / float(np.ptp(g.mean[ch])))
    return float(np.mean(out))


def closer_cells(pull: pd.DataFrame) -> tuple[int, int]:
    """(cells, of) — the unmarked run × kind cells of :func:`input_pull` whose prediction is
    closer to the class data than the control (the scaled input)."""
    ok = pull[pull["mark"] == ""]
    return int((ok["vs class data"] < ok["control: input vs class"]).sum()), len(ok)


def pin_findings(pull: pd.DataFrame, loose: pd.DataFrame | None = None) -> list[str]:
    """What holds the Ch 7 predictions to their input, from :func:`input_pull` of the study
    (``pull``) and of the loosened-tracking runs (``loose``, :data:`LOOSE_TRACKING`); unmarked
    cells only (converged and valid), per model."""
    out = []
    for model in ("MSK", "NMSK"):
        p = pull[(pull["mark"] == "") & pull.index.get_level_values("run").str.startswith(f"{model} ")]
        if p.empty:
            continue
        n = len(p)
        near_input = int((p["vs tracked input"] < p["vs class data"]).sum())
        own = int((p["vs tracked input"] >= p["control: input vs class"]).sum())
        closer, _ = closer_cells(p)
        line = (f"- {model}, Table 7.1's weights: closer to the class data than the scaled input in {closer} of {n} "
                f"cells; closer to its tracked input than to the class data in {near_input} of {n}; its own error "
                f"against the input it tracked (median NRMSE {p['vs tracked input'].median():.3f}) is at least the "
                f"class–input distance it would have to beat (median {p['control: input vs class'].median():.3f}) in "
                f"{own} of {n} cells.")
        if loose is not None:
            q = loose[(loose["mark"] == "") & loose.index.get_level_values("run").str.startswith(f"{model} ")]
            lq, nq = closer_cells(q)
            dropped = sorted({r for r, _ in loose.index} - {r for r, _ in q.index})
            dropped = [r for r in dropped if r.startswith(f"{model} ")]
            line += (f" With the three data-tracking weights ÷ 10: closer in {lq} of {nq} cells"
                     + (f" (left out, marked: {', '.join(dropped)})" if dropped else "")
                     + (f"; median NRMSE against the class data {q['vs class data'].median():.3f} "
                        f"(Table 7.1's weights: {p['vs class data'].median():.3f})." if nq else "."))
            if nq:
                away = q["vs class data"].median() > p["vs class data"].median()
                line += (" Loosened, the predictions moved " + ("away from" if away else "towards")
                         + " the class data: " + ("the data terms are not what holds them from it." if away else
                                                  "the data terms hold them to their input."))
        out.append(line)
    return out


#: The starts of :func:`data_start_study`: the problem's own data-based guess (thesis Sec 4.3.2)
#: on the data it tracks (the time-scaled *Free* data) and the same guess built on the class's
#: own data, which no Ch 7 problem tracks.
DATA_STARTS = ("tracked input", "class data")
#: The label of the chapter's own Ch 7 runs (started from the Ch 5 solution) beside
#: :data:`DATA_STARTS` in :func:`start_table`.
CH7_OWN_START = "the Ch 5 solution (the chapter's)"


def data_start_runs(specs: Mapping[str, gait_ocp.GaitSpec], start: str, max_iter: int = 3000) -> tuple[dict, dict]:
    """The runs of :func:`data_start_study`: ``(specs, guesses)`` — the NMSK ``specs`` with the
    iteration limit ``max_iter`` and, for ``start="class data"``, each one's data-based guess
    built on its class's own data (``"tracked input"``: no guess, the problem's own)."""
    if start not in DATA_STARTS:
        raise ValueError(f"start must be one of {DATA_STARTS}, got {start!r}")
    specs = {k: replace(s, max_iter=max_iter) for k, s in specs.items() if k.startswith("NMSK ")}
    guesses = {}
    if start == "class data":
        for k, s in specs.items():
            guesses[k] = gait_ocp.data_guess_on(gait_ocp.build(s), data_mod.load_gait_data(s.speed_class, s.source))
    return specs, guesses


def data_start_study(res: StudyResult, start: str, *, max_iter: int = 3000, root=None, scheduler: str | None = None,
                     n_workers: int | None = None, serial: bool = False, progress: bool = True) -> StudyResult:
    """Does the start pin a Ch 7 prediction to its input? The NMSK runs of ``res`` (each spec
    unchanged but its iteration limit, ``max_iter``: the chapter's rerun limit) solved from the
    data-based guess (:func:`gaitlib.problems.gait.data_guess_on`) built on ``start`` (one of
    :data:`DATA_STARTS`): ``"class data"`` — the class's own data, a start only (the problem
    still tracks the scaled Free data; its objective decides where the run ends) — or
    ``"tracked input"`` — the problem's own data-based guess, the control
    (:func:`data_start_runs`). ``res``'s runs start from the Ch 5 solution
    (:data:`GUESS_POLICY_CH7`); the objectives of the three starts of a class are the same
    problem's, so comparable."""
    specs, guesses = data_start_runs(res.specs, start, max_iter)
    gaits = {c: data_mod.load_gait_data(c, s.source) for s in specs.values() for c in (s.speed_class, "Free")}
    recs, sols = _run(specs, guesses, root=root, scheduler=scheduler, n_workers=n_workers, serial=serial,
                      progress=progress)
    return StudyResult(specs, recs, sols, res.baselines, _scores(sols, gaits, lambda s: s.spec.speed_class),
                       guess={"NMSK": start}, guesses=guesses)


def start_table(studies: Mapping[str, StudyResult], gaits: dict) -> pd.DataFrame:
    """One row per class and start of the Ch 7 NMSK runs (``studies``: start label → study —
    the chapter's runs first, then :func:`data_start_study` of each start): the run's mark,
    iterations, objective (the same problem at every start of a class), COT, its mean NRMSE
    over the three kinds against the class data and against the input it tracked
    (:func:`input_pull`), and in how many of its three cells it is closer to the class data
    than the scaled input (:func:`closer_cells`)."""
    rows = {}
    for lab, st in studies.items():
        nm = {k: v for k, v in st.solutions.items() if k.startswith("NMSK ")}
        pull = input_pull(Runs(nm), gaits)
        for name, sol in nm.items():
            p = pull.loc[name]
            rows[(sol.spec.speed_class, lab)] = {
                "mark": marks.failure_label(sol) or "", "iterations": sol.stats.get("iterations"),
                "objective": sol.stats.get("objective"), "COT (J/kg/m)": sol.stats.get("COT", np.nan),
                "vs class data": float(p["vs class data"].mean()), "vs tracked input": float(p["vs tracked input"].mean()),
                "cells closer than the input": int((p["vs class data"] < p["control: input vs class"]).sum())}
    t = pd.DataFrame.from_dict(rows, orient="index").rename_axis(["class", "start"])
    order = [c for c in CH7_CLASSES if c in t.index.get_level_values("class")]
    return t.reindex(order, level="class")


#: Objectives of two starts within this many per cent: the same optimum (:func:`start_findings`).
SAME_OPTIMUM_PCT = 1.0


def start_findings(table: pd.DataFrame, own: str, probe: str = "class data",
                   tol: float = SAME_OPTIMUM_PCT) -> list[str]:
    """The sentences on :func:`start_table`: per start, how many unmarked cells come closer to
    the class data than the scaled input; then, per class where the ``own`` start's run (the
    chapter's) and the ``probe`` start's are both converged and valid, the objective's change
    (the same problem: lower is a better optimum; within ``tol`` % the same one), the NRMSE
    against the class data and the closer cells at each start; last, where the probe's runs
    end: nearer the input they track or nearer the class data they started from."""
    out = []
    for lab in table.index.get_level_values("start").unique():
        t = table.xs(lab, level="start")
        ok = t[t["mark"] == ""]
        bad = [f"{c} ({m})" for c, m in t["mark"].items() if m]
        out.append(f"From {lab}: closer to the class data than the scaled input in "
                   f"{int(ok['cells closer than the input'].sum())} of {3 * len(ok)} cells"
                   + (f" (left out, marked: {'; '.join(bad)})" if bad else "")
                   + (f"; mean NRMSE against the class data {ok['vs class data'].mean():.3f}, against the tracked "
                      f"input {ok['vs tracked input'].mean():.3f}." if len(ok) else "."))
    both = [c for c in table.index.get_level_values("class").unique()
            if (c, own) in table.index and (c, probe) in table.index
            and not table.loc[(c, own), "mark"] and not table.loc[(c, probe), "mark"]]
    if not both:
        return out + [f"No class has both its {own} and its {probe} run converged and valid: no comparison."]
    cells = "cells closer than the input"
    parts, lower, same = [], [], []
    for c in both:
        o, p = table.loc[(c, own)], table.loc[(c, probe)]
        d = 100 * (p["objective"] / o["objective"] - 1)
        (same if abs(d) <= tol else lower if d < 0 else []).append(c)
        parts.append(f"{c}: objective {d:+.1f} %, NRMSE against the class data {o['vs class data']:.3f} → "
                     f"{p['vs class data']:.3f}, cells closer {o[cells]} → {p[cells]}")
    out.append(f"Started on the {probe} (a start only; the problem still tracks the scaled Free data), against "
               f"{own}: " + "; ".join(parts) + ".")
    p = table.loc[[(c, probe) for c in both]]
    near = int((p["vs tracked input"] < p["vs class data"]).sum())
    k_o = int(table.loc[[(c, own) for c in both], cells].sum())
    k_p = int(p[cells].sum())
    line = (f"**Where the runs started on the {probe} end:** nearer the input they track than the class data they "
            f"started from in {near} of {len(both)} (mean NRMSE {p['vs tracked input'].mean():.3f} against "
            f"{p['vs class data'].mean():.3f}), closer to the class data than the input in {k_p} of {3 * len(both)} "
            f"cells ({k_o} from {own})")
    if lower:
        line += (f"; in {', '.join(lower)} they find a better optimum of the same problem — the chapter's run "
                 "there is a local optimum, held by its start")
    if same:
        line += (f"; in {', '.join(same)} both starts end at the same objective (within {tol:g} %) — there the "
                 "problem, not the start, sets the prediction")
    out.append(line + (f". The problem's cost pulls its optima to the input it tracks: the start does not "
                       f"explain the cells that stay near it." if near > len(both) / 2 else "."))
    return out


def cot_table(ch7: StudyResult, natural=None) -> pd.DataFrame:
    """COT (Eq 5.57) of the NMSK runs against walking speed, ours beside the thesis's
    Fig 7.5 point of the class of the same rank (labelled; different classes and speeds).

    ``natural``: the natural-speed (*Free*) point(s) — a GaitSolution (row ``Free``) or
    ``{row label: GaitSolution}``, e.g. the like-for-like Ch 6 NMSK DT run (same cost
    function and activation parameters as the Ch 7 runs) and, labelled apart, the Ch 5
    NMSK solution. Columns ``source`` (the run), ``mark``
    (:func:`gaitlib.marks.failure_label`) and ``converged`` say what each point is."""
    thesis = {c: (v, cot) for c, v, cot in THESIS_COT_FIG_7_5}
    rows = []
    items = [(s.spec.speed_class, k, s) for k, s in ch7.solutions.items() if k.startswith("NMSK ")]
    if isinstance(natural, dict):
        items += [(lab, f"{s.spec.model} {s.spec.cost}", s) for lab, s in natural.items() if s is not None]
    elif natural is not None:
        items.append(("Free", f"{natural.spec.model} {natural.spec.cost}", natural))
    for row, src, s in items:
        cls = s.spec.speed_class
        g = gait_ocp.spec_gait_data(s.spec)[0]  # the speed the run walks (on longer legs, theirs)
        tc = THESIS_CLASS[cls]
        rows.append({"class": row, "speed (m/s)": g.speed, "source": src,
                     "mark": marks.failure_label(s) or "", "converged": bool(s.stats.get("success")),
                     "COT (J/kg/m)": s.stats.get("COT", np.nan), "thesis class": tc,
                     "thesis speed (m/s, Fig 7.5)": thesis[tc][0], "thesis COT (Fig 7.5)": thesis[tc][1]})
    return pd.DataFrame(rows).sort_values("speed (m/s)", kind="stable").set_index("class")


def times_table(result: StudyResult, thesis_hours: dict, label_of=lambda spec: spec.cost) -> pd.DataFrame:
    """Our times (build = symbolic graph + derivatives + nlpsol; solve = IPOPT), iterations
    and time per iteration per run beside the thesis's hours (Table 6.3 or 7.2; labelled)
    and the speed-up (thesis hours / our build + solve)."""
    rows = []
    for name, spec in result.specs.items():
        sol = result.solutions.get(name)
        lab = label_of(spec)
        h = thesis_hours.get(spec.model, {}).get(lab, np.nan)
        st = sol.stats if sol is not None else {}
        t = st.get("solve_time_s", np.nan) + st.get("build_time_s", np.nan)
        rows.append({"model": spec.model, "case": lab, "status": result.records[name].status,
                     "mark": failure_label(sol if sol is not None else result.records[name]) or "",
                     "iterations": st.get("iterations"), "build (s)": st.get("build_time_s", np.nan),
                     "solve (s)": st.get("solve_time_s", np.nan), "total (s)": t,
                     "ms/iteration": 1e3 * st.get("time_per_iteration_s", np.nan), "thesis (h)": h,
                     "speed-up": 3600 * h / t if t and np.isfinite(t) else np.nan})
    return pd.DataFrame(rows)


# ======================================================================================
# What the chapters found
# ======================================================================================
#: The thesis's claim "SDT3 (torques + angles) is enough for NMSK" counts as holding when the
#: NMSK SDT3 run's mean NRMSE is at most this factor times the NMSK DT run's (within 10 %).
SDT3_ENOUGH_FACTOR = 1.1
#: The COT curve needs at least this many converged points to speak of its minimum.
COT_CURVE_MIN_POINTS = 3
#: Scored kinds of the headline NRMSEs.
_KINDS = ["angle", "torque", "grf"]


def kind_nrmse(scores: pd.DataFrame) -> pd.DataFrame:
    """Mean NRMSE per run and kind: rows (model, case), columns angle, grf, torque (the
    kinds present), from a :attr:`StudyResult.scores`-like long table."""
    return scores[scores["kind"].isin(_KINDS)].groupby(["model", "case", "kind"])["nrmse"].mean().unstack("kind")


def mean_nrmse(scores: pd.DataFrame) -> pd.Series:
    """(model, case) → the mean over angles, torques and GRFs of their mean NRMSE (every
    kind weighs the same, whatever its number of channels)."""
    return kind_nrmse(scores).mean(axis=1)


def _pct(x: float) -> str:
    """A signed whole per cent (no "-0 %")."""
    return f"{int(round(x)) + 0:+d} %"


def torque_gain(nmsk, msk_sol, cls: str) -> float:
    """Thesis Secs 7.2–7.3's measure: 100 (1 − NMSK ÷ MSK mean joint-torque NRMSE), %, both runs
    scored against speed class ``cls``'s own data (positive: the NMSK torques are closer)."""
    g = data_mod.load_gait_data(cls, msk_sol.spec.source)
    tn, tm = (kind_nrmse(score(x, g).assign(model="x", case="y"))["torque"].iloc[0] for x in (nmsk, msk_sol))
    return 100 * (1 - tn / tm)


def torque_gain_lines(book: StudyResult, ours: StudyResult) -> list[str]:
    """Thesis Secs 7.2–7.3 ("NMSK joint torques more accurate than MSK's by …"), per class:
    100 (1 − NMSK ÷ MSK mean torque NRMSE) against each class's own data, with the NMSK runs of
    ``book`` (Table 5.10's activation parameters) and of ``ours`` (another set, e.g.
    :func:`ch5_activation_speed_study`), the MSK runs of ``book`` in both; only unmarked runs
    count (:func:`gaitlib.marks.failure_label`), a class without both is skipped."""
    parts = []
    for cls, tc in ((c, THESIS_CLASS[c]) for c in CH7_CLASSES):
        m, nb, no = (r.solutions.get(f"{k} {cls}") for r, k in ((book, "MSK"), (book, "NMSK"), (ours, "NMSK")))
        if any(x is None or marks.failure_label(x) for x in (m, nb, no)):
            continue
        parts.append(f"{cls} {_pct(torque_gain(nb, m, cls))} → {_pct(torque_gain(no, m, cls))} (thesis {tc}: "
                     f"{_pct(THESIS_TORQUE_GAIN_PCT_CH7[tc])})")
    if not parts:
        return []
    return ["**NMSK torque NRMSE below MSK's** (Table 5.10's activation parameters → ours): " + "; ".join(parts) + "."]


def readings_table(results: dict, columns=("mark", "status", "iterations")) -> pd.DataFrame:
    """The same study in several readings side by side: label → :class:`StudyResult`; per
    reading ``columns`` of :meth:`StudyResult.stats` and the run's :func:`mean_nrmse`."""
    parts = {}
    for label, r in results.items():
        nr = mean_nrmse(r.scores)
        nr.index = [" ".join(i) for i in nr.index]
        parts[label] = r.stats()[list(columns)].assign(**{"mean NRMSE": nr})
    return pd.concat(parts, axis=1)


def _converged_line(stats: pd.DataFrame, extra: str = "") -> str:
    ok = stats["converged"]
    return (f"- {int(ok.sum())} of {len(ok)} runs converged{extra}"
            + ("" if ok.all() else "; not converged: " + ", ".join(f"{k} ({v})" for k, v in stats.loc[~ok, 'status'].items())))


_START_WORDS = {"ch5": "the whole Ch 5 solution", "thesis": "the thesis's partial guess"}


def _starts_text(how: Mapping[str, str], lead: bool = True) -> str:
    """How a study's runs were started (model → ``"thesis"`` | ``"ch5"``), in words
    (``lead``: as the start of a sentence)."""
    the = "The" if lead else "the"
    if len(set(how.values())) == 1:
        return f"{the} runs of {' and '.join(how)} start from {_START_WORDS[next(iter(how.values()))]} of their model"
    return "; ".join(f"{the if i == 0 else 'the'} {m} runs start from {_START_WORDS[h]}"
                     for i, (m, h) in enumerate(how.items()))


def guess_lines(by_guess: Mapping[str, StudyResult], model: str, limit: int = 1000) -> list[str]:
    """One sentence per start (``by_guess``: label → a study of the same runs from that
    start): how many of ``model``'s runs converged within ``limit`` iterations, their
    iterations, which did not (with IPOPT's status) and which converged but fail a validity
    gate (their mark)."""
    out = []
    for label, res in by_guess.items():
        st = res.stats()
        st = st[st.index.str.startswith(f"{model} ")]
        if st.empty:
            continue
        ok = st["converged"].astype(bool)
        span = (f" ({int(st.loc[ok, 'iterations'].min())}–{int(st.loc[ok, 'iterations'].max())} iterations)"
                if ok.any() else "")
        line = f"- {label}: {model} " + _converged_line(st, f" within {limit} iterations{span}")[2:]
        bad = st[ok & st["mark"].astype(bool)]
        if len(bad):
            line += "; converged but invalid: " + ", ".join(f"{k} ({v})" for k, v in bad["mark"].items())
        out.append(line + ".")
    return out


#: Columns of :func:`thesis_guess_runs`'s table.
START_COLUMNS = ["mark", "status", "iterations", "solve (s)", "objective", "max violation"]


def thesis_guess_runs(res: StudyResult, from_thesis: Mapping[str, StudyResult],
                      label: str = "from the thesis's partial guess") -> tuple[list[str], pd.DataFrame]:
    """The runs from the thesis's guess (model → the study of that model's runs from it)
    beside the page's ``res`` (started as its ``guess`` says): :func:`guess_lines` per model
    and one table of their statuses (:data:`START_COLUMNS`)."""
    lines = []
    for m, r in from_thesis.items():
        lines += guess_lines({f"from {_START_WORDS[res.guess[m]]} (the page's runs)": res, label: r}, m)
    return lines, pd.concat([r.stats()[START_COLUMNS] for r in from_thesis.values()])


def ch6_findings(res: StudyResult, thesis_guess_stats: pd.DataFrame, reruns: dict,
                 gait: data_mod.GaitData) -> list[str]:
    """Ch 6's findings as Markdown list items, every number from the runs: convergence and
    times, mean NRMSE (:func:`mean_nrmse` of the converged and valid runs only) per model and
    cost function, the thesis's claims (NMSK more accurate than MSK per cost function, NMSK FP
    more accurate and faster than MSK FP, SDT3 enough for NMSK — within
    :data:`SDT3_ENOUGH_FACTOR`, using the converged 3000-iteration rerun of ``reruns`` when the
    study's own run did not converge), and the excitation RMSE against the EMG.
    ``thesis_guess_stats``: :meth:`StudyResult.stats` of the runs from the thesis's partial
    guess (either model or both); ``gait``: the data the runs are scored against."""
    stats, run_marks = res.stats(), res.marks()
    csc = res.converged_scores()
    nr = mean_nrmse(csc)

    def _nr(model, case):
        return nr.get((model, case), np.nan)

    def _f(model, case):
        v = _nr(model, case)
        return f"{v:.3f}" if np.isfinite(v) else f"— ({run_marks.get(f'{model} {case}') or 'no result'})"

    tg = thesis_guess_stats
    tg_ok = tg["status"] == "Solve_Succeeded"
    lines = [_converged_line(stats, " (IPOPT Solve_Succeeded)")
             + f". IPOPT solve time per run {stats['solve (s)'].min():.0f}–{stats['solve (s)'].max():.0f} s here, "
             f"against 1–15 h in the thesis (Table 6.3). " + _starts_text(res.guess)
             + f"; from the thesis's partial guess {int(tg_ok.sum())} of {len(tg)} "
             + " and ".join(dict.fromkeys(k.split(" ", 1)[0] for k in tg.index)) + " runs converged"
             + ("" if tg_ok.all() else " (not: " + ", ".join(f"{k} {v}" for k, v in tg.loc[~tg_ok, 'status'].items()) + ")")
             + ".",
             f"- Mean NRMSE over angles, torques and forces: MSK DT {_f('MSK', 'DT')} → FP {_f('MSK', 'FP')}; "
             f"NMSK DT {_f('NMSK', 'DT')} → FP {_f('NMSK', 'FP')}."]
    both = [c for c in CH6_COSTS if np.isfinite(_nr("NMSK", c)) and np.isfinite(_nr("MSK", c))]
    better = [c for c in both if _nr("NMSK", c) < _nr("MSK", c)]
    skipped = [c for c in CH6_COSTS if c not in both]
    lines.append(f"- NMSK is more accurate than MSK (mean NRMSE) for {', '.join(better) if better else 'no cost function'}"
                 + (f" (of {len(both)} cost functions where both runs converged and pass the validity gates; not "
                    f"compared: {', '.join(skipped)})" if skipped else "")
                 + "; the thesis found NMSK better for SDT1, SP2 and FP, MSK better for SDT2 and SP3, similar for DT, "
                   "SDT3 and SP1 (Sec 6.2.3).")
    if "FP" in both:
        t_n, t_m = stats.loc["NMSK FP", "solve (s)"], stats.loc["MSK FP", "solve (s)"]
        lines.append(f"- Thesis claim *NMSK FP more accurate than MSK FP*: "
                     f"{'holds' if _nr('NMSK', 'FP') < _nr('MSK', 'FP') else 'does not hold'} on our data "
                     f"({_f('NMSK', 'FP')} vs {_f('MSK', 'FP')}). *NMSK FP faster than MSK FP*: "
                     f"{'holds' if t_n < t_m else 'does not hold'} ({t_n:.0f} s vs {t_m:.0f} s"
                     + ("" if res.guess.get("MSK") == res.guess.get("NMSK") else
                        "; not a like-for-like comparison: " + _starts_text(res.guess, lead=False)) + ").")
    else:
        lines.append("- Thesis claims *NMSK FP more accurate / faster than MSK FP*: not tested — "
                     f"MSK FP {_f('MSK', 'FP')}, NMSK FP {_f('NMSK', 'FP')}.")
    sdt3_val, note = _nr("NMSK", "SDT3"), ""
    if not stats.loc["NMSK SDT3", "converged"]:
        r = reruns.get("NMSK SDT3")
        if r is not None and r.stats["success"]:
            d = score(r, gait)
            sdt3_val = d[d["kind"].isin(_KINDS)].groupby("kind")["nrmse"].mean().mean()
            note = (f" (the study's 1000-iteration run did not converge; this is its converged 3000-iteration rerun, "
                    f"{r.stats['iterations']} iterations)")
    if np.isfinite(sdt3_val) and np.isfinite(_nr("NMSK", "DT")):
        holds = sdt3_val <= _nr("NMSK", "DT") * SDT3_ENOUGH_FACTOR
        lines.append(f"- Thesis claim *SDT3 (Trq + Ang) is enough for NMSK*: NMSK SDT3 mean NRMSE {sdt3_val:.3f}{note} "
                     f"vs DT {_nr('NMSK', 'DT'):.3f} — "
                     f"{f'holds (within {100 * (SDT3_ENOUGH_FACTOR - 1):.0f} %)' if holds else 'does not hold'}.")
    else:
        lines.append(f"- Thesis claim *SDT3 (Trq + Ang) is enough for NMSK*: not tested — NMSK SDT3 {_f('NMSK', 'SDT3')}, "
                     f"DT {_f('NMSK', 'DT')}.")
    exc = csc[csc["kind"] == "excitation"].groupby("case")["rmse"].mean()
    not_conv = [c for c in CH6_COSTS if run_marks.get(f"NMSK {c}")]
    if len(exc):
        lines.append("- Excitation RMSE vs EMG (mean over mapped muscles, converged and valid NMSK runs"
                     + (f"; {', '.join(not_conv)} left out: not converged or invalid" if not_conv else "") + "): "
                     f"best {exc.idxmin()} {exc.min():.3f}, worst {exc.idxmax()} {exc.max():.3f}; "
                     f"FP {exc.get('FP', np.nan):.3f} vs DT {exc.get('DT', np.nan):.3f} (thesis: FP "
                     f"{THESIS_FP_EXCITATION_GAIN_PCT:.0f} % better than DT).")
    return lines


def u_breaks(points: dict) -> list[str]:
    """Where a COT curve is not U-shaped: ``points`` label → (speed, COT); the steps (in
    order of speed) that rise before the minimum or fall after it, as ``"A 3.83 → B 4.08"``;
    empty for a U (or a monotone curve's one arm)."""
    order = sorted(points, key=lambda k: points[k][0])
    cots = [points[k][1] for k in order]
    i = int(np.argmin(cots))
    return [f"{order[j]} {cots[j]:.2f} → {order[j + 1]} {cots[j + 1]:.2f}" for j in range(len(cots) - 1)
            if (j < i and cots[j + 1] > cots[j]) or (j >= i and cots[j + 1] < cots[j])]


def _cot_minimum_text(imin: str, curve: pd.DataFrame) -> str:
    """What the COT minimum ``imin`` of the unmarked points says; with a speed left out
    (marked: not converged or invalid) the U-curve claim is not tested; with the minimum at
    Free but a step the wrong way (:func:`u_breaks`), it is not a U."""
    left = [c for c, m in curve["mark"].items() if m]
    if imin != "Free":
        return "not at the natural speed — no U-curve with the minimum at Free"
    if left:
        return (f"the natural speed among these points, but the U-curve claim is not tested: {', '.join(left)} "
                "left out (not converged or invalid)")
    ok = curve[curve["mark"] == ""]
    breaks = u_breaks({c: (r["speed (m/s)"], r["COT (J/kg/m)"]) for c, r in ok.iterrows()})
    if breaks:
        return "the natural speed, but not a U: the COT moves the wrong way between " + "; ".join(breaks)
    return "the natural speed — a U-curve as the thesis reports"


def ch7_findings(res: StudyResult, classes, control: pd.DataFrame, cot: pd.DataFrame, reruns: dict,
                 ch5_row: str | None = None) -> list[str]:
    """Ch 7's findings as Markdown list items, every number from the runs: convergence and
    times; torque NRMSE of NMSK against MSK per class (converged and valid runs only);
    how often the NMSK predictions are closer to the untracked class data than the
    time-scaled Free data they tracked (``control``: class × kind NRMSE of that data against
    the class's); the COT curve (:func:`cot_table`; its minimum, with at least
    :data:`COT_CURVE_MIN_POINTS` converged points; row ``ch5_row`` is the Ch 5 solution,
    off the curve); and the 3000-iteration ``reruns`` of the runs that stopped at the limit
    (those in ``res.rerun_used`` stand in for them, :meth:`StudyResult.with_reruns`)."""
    stats = res.stats()
    pred_ok = kind_nrmse(res.converged_scores())
    used, rerun_used = "", tuple(getattr(res, "rerun_used", ()))
    if rerun_used:
        used = (f" ({len(stats) - len(rerun_used)} within 1000 iterations; "
                + ", ".join(f"{k} in its 3000-iteration rerun" for k in rerun_used) + ")")
    lines = [_converged_line(stats, used)
             + f"; IPOPT solve time {stats['solve (s)'].min():.0f}–{stats['solve (s)'].max():.0f} s per run here vs "
               "4–18 h in the thesis (Table 7.2)."]
    both = [c for c in classes if ("NMSK", c) in pred_ok.index and ("MSK", c) in pred_ok.index]
    if both:
        tq = pred_ok["torque"]
        better = [c for c in both if tq[("NMSK", c)] < tq[("MSK", c)]]
        lines.append(f"- Torque NRMSE: NMSK below MSK for {', '.join(better) if better else 'no class'} of the "
                     f"{len(both)} classes where both runs converged and pass the validity gates"
                     + (f" (not compared: {', '.join(c for c in classes if c not in both)})" if len(both) < len(classes) else "")
                     + " (thesis: NMSK 2–17 % better at every speed).")
    nm = [c for c in classes if ("NMSK", c) in pred_ok.index]
    beat = [(c, k) for c in nm for k in _KINDS if pred_ok.loc[("NMSK", c), k] < control.loc[c, k]]
    lines.append(f"- The converged NMSK predictions are closer to the untracked class data than the scaled Free data "
                 f"they tracked in {len(beat)} of {3 * len(nm)} class × kind cells"
                 + (f" ({', '.join(c for c in classes if c not in nm)} left out: not converged)" if len(nm) < len(classes) else "")
                 + ".")
    curve = cot.drop(index=ch5_row, errors="ignore") if ch5_row else cot
    cc = curve[curve["mark"] == ""]
    r5 = cot.loc[ch5_row] if ch5_row and ch5_row in cot.index else None
    if len(cc) >= COT_CURVE_MIN_POINTS:
        imin = cc["COT (J/kg/m)"].idxmin()
        thesis = ", ".join(f"{c:.2f}" for _, _, c in THESIS_COT_FIG_7_5)
        thesis_classes = ", ".join(k for k, _, _ in THESIS_COT_FIG_7_5)
        lines.append(f"- COT (NMSK DT, converged runs; Free = the Ch 6 NMSK DT run): "
                     f"{', '.join(f'{i} {v:.2f}' for i, v in cc['COT (J/kg/m)'].items())} J/(kg·m); minimum at {imin} "
                     f"({_cot_minimum_text(imin, curve)}). "
                     f"Thesis (Fig 7.5): {thesis} at {thesis_classes}."
                     + (f" The Ch 5 NMSK solution (Eq 5.55, its own activation parameters) has {r5['COT (J/kg/m)']:.2f}"
                        + (f" ({r5['mark']})" if r5["mark"] else "") + "; it is not on the curve." if r5 is not None else ""))
    for k, r in reruns.items():
        cot_text = f" with COT {r.stats['COT']:.2f} J/(kg·m)" if np.isfinite(r.stats.get("COT", np.nan)) else ""
        if k in rerun_used:
            lines.append(f"- {k} stopped at 1000 iterations; its 3000-iteration rerun converged ({r.stats['status']}, "
                         f"{r.stats['iterations']} iterations){cot_text}, passes the validity gates and stands in "
                         "for it in every result on this page except the compute times.")
        else:
            lines.append(f"- {k} stopped at 1000 iterations; rerun at 3000 it "
                         f"{'converged' if r.stats['success'] else 'did NOT converge'} ({r.stats['status']}, "
                         f"{r.stats['iterations']} iterations){cot_text}; "
                         + ("it fails a validity gate, so " if r.stats['success'] else "")
                         + "it is not used: the run stays marked and out of the findings.")
    return lines


def cot_figure(cot: pd.DataFrame, ch5_row: str | None = None,
               label: str = "ours (NMSK DT, converged; Free = Ch 6 DT)", others: dict | None = None):
    """Thesis Fig 7.5: COT (J kg⁻¹ m⁻¹) against walking speed (m/s) from :func:`cot_table` —
    the converged points joined, the marked ones as labelled crosses, the ``ch5_row`` point
    (the Ch 5 solution) apart, and the thesis's points at their own speeds. ``others``: label →
    another :func:`cot_table` whose unmarked points are drawn joined and dotted, for comparison."""
    import matplotlib.pyplot as plt

    curve = cot.drop(index=ch5_row, errors="ignore") if ch5_row else cot
    fig, ax = plt.subplots(figsize=(8.0, 3.6), layout="constrained")
    okc = curve[curve["mark"] == ""]
    wrap = lambda s: textwrap.fill(s, 52)  # noqa: E731 (a long legend entry would squeeze the axes)
    ax.plot(okc["speed (m/s)"], okc["COT (J/kg/m)"], "o-", color="C1", label=wrap(label))
    bad = curve[curve["mark"] != ""]
    if len(bad):
        ax.plot(bad["speed (m/s)"], bad["COT (J/kg/m)"], "x", color=marks.MARK_COLOR, ms=9, mew=2,
                label=f"{marks.DAGGER} ours, marked (not converged or invalid)")
        for name, r in bad.iterrows():
            # the kind of each mark (its first words; the table beside has the whole mark), kept out of the
            # layout: a long mark pushed left of the axes collapses a constrained layout
            kinds = " + ".join(marks.mark_kinds(r["mark"]))
            ax.annotate(f"{marks.DAGGER} {kinds}", (r["speed (m/s)"], r["COT (J/kg/m)"]), fontsize=6,
                        color=marks.MARK_COLOR, textcoords="offset points", xytext=(-4, -12),
                        ha="right").set_in_layout(False)
    if ch5_row and ch5_row in cot.index:
        r5 = cot.loc[ch5_row]
        ax.plot([r5["speed (m/s)"]], [r5["COT (J/kg/m)"]], "D", mfc="none", color="C2", ms=7,
                label=marks.run_label("Ch 5 NMSK Eq 5.55 (own activation params)", r5["mark"]))
    for i, (lab, other) in enumerate((others or {}).items()):
        ok_o = other[other["mark"] == ""]
        ax.plot(ok_o["speed (m/s)"], ok_o["COT (J/kg/m)"], "o:", color=f"C{4 + i}", mfc="none", label=wrap(lab))
    th = pd.DataFrame(THESIS_COT_FIG_7_5, columns=["class", "speed", "COT"])
    ax.plot(th["speed"], th["COT"], "s--", color="0.5", label="thesis, Fig 7.5 (different data)")
    for name, r in curve.iterrows():
        ax.annotate(name, (r["speed (m/s)"], r["COT (J/kg/m)"]), fontsize=7, textcoords="offset points", xytext=(4, 4))
    ax.margins(x=0.1, y=0.1)  # room inside the axes for the class names beside the outermost points
    ax.set_xlabel("walking speed (m/s)")
    ax.set_ylabel("COT (J kg⁻¹ m⁻¹)")
    ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.01, 0.5))
    return fig
