"""Solving gait problems on any data set, cached, and as sweeps.

Objective. ``objective="fit"`` (the diagnosis's default) replaces the spec's tracking terms
(Trq, Ang, GRF and the joint part of Q) by one SD-standardised tracking term over the
located channels, ``Fit = (1/16) Σ_c ((sim_c − mean_c) / SD*_c)²`` (angles, net torques,
GRFs, both legs; SD* as :mod:`gaitlib.gap.locate`, weight 1/4 as the thesis's tracking
terms), and keeps the rest of the spec's cost (Jrk, Rsd, Imp, Act, Mtb, HAT; Q's HAT and
metatarsal part as ``Qrest``). The re-solves then minimise the same measure the gap is
ranked by — an effect's free parameters are identified by the data's likelihood rather
than by range-normalised costs, which otherwise pull parameters to their bounds while the
gap grows. ``objective="cost"`` keeps the spec's own cost function.

A :class:`Runner` builds a spec's NLP once and re-solves it on other data sets: the
references are NLP parameters (:func:`gaitlib.problems.gait.tracking_frame`), so a twin or
a resampled data set needs no rebuild. The normalising ranges of the cost terms, the state
bounds and the data-based part of the initial guess stay those of the spec's own data set
(``speed_class``/``source``), which must have the same speed and cycle time; so does the
HAT reference (pelvis height from the vertical GRF, an estimate rather than data — it
cannot be computed for every synthetic GRF).

Solutions are cached under ``<root>/gap/<key>``, the key hashing the spec, the data set's
numbers (:func:`gaitlib.gap.io.signature`), the warm start, and the formulation versions
(:data:`gaitlib.problems.gait.FORMULATION`, this module's :data:`FORMULATION` and those of
the spec's effects, :func:`gaitlib.effects.formulation_versions`).
Failed solves are cached and returned as failed (their IPOPT status is the result).
"""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

import numpy as np

from .. import cache
from .. import ocp
from ..problems import gait as gait_ocp
from .io import signature
from .locate import SD_FLOOR
from .. import sweep

__all__ = ["Runner", "Lazy", "solve_on", "solve_or_load", "solve_many", "FORMULATION", "OBJECTIVES", "FIT_WEIGHT",
           "fit_problem"]

OBJECTIVES = ("fit", "cost")
#: IPOPT's initial barrier parameter for warm-started solves (default 0.1 would push the
#: warm start far into the interior and often end in another local optimum).
MU_WARM = 1e-4
#: Weight of the SD-standardised tracking term (the thesis's tracking terms have 1/4).
FIT_WEIGHT = 1.0
#: Factor on the spec's non-tracking terms (Jrk, Rsd, Imp, Act, Mtb) under the Fit objective.
REG_FACTOR = 0.1
_KEEP = ("Jrk", "Rsd", "Imp", "Act", "Mtb")

#: Version of the gap's re-solve formulation (the Fit objective, the Runner's parameters and
#: warm starts) on top of :data:`gaitlib.problems.gait.FORMULATION`: part of every gap cache
#: key. Bump it when a change alters what is solved (tests/test_formulation_versions.py).
FORMULATION = "gap-fit-1"


def _where(spec: gait_ocp.GaitSpec, gait, guess, root, objective="fit") -> Path:
    desc = {"kind": "gap-solve", "spec": spec.to_dict(), "data": signature(gait), "guess": gait_ocp.guess_signature(guess),
            "objective": objective}
    return cache.lookup("gap", desc, root, formulation=(gait_ocp.FORMULATION, FORMULATION) + spec.effect_versions(),
                        identified=spec.identified_sets())


def _check_same_cycle(gp, gait):
    g0 = gp.ref.gait
    if abs(float(g0.cycle_time) - float(gait.cycle_time)) > 1e-9 or abs(float(g0.speed) - float(gait.speed)) > 1e-9:
        raise ValueError(f"data set has cycle time {gait.cycle_time:.4f} s / speed {gait.speed:.4f} m/s, the spec's "
                         f"data {g0.cycle_time:.4f} s / {g0.speed:.4f} m/s: build a spec of that speed class")


def _fit_channels():
    ch = [(j, "x", j) for j in gait_ocp.LEG_JOINTS]
    ch += [(f"tau_{j}", "tau_net", gait_ocp.cv.JOINTS.index(j)) for j in gait_ocp.LEG_JOINTS]
    ch += [(g, "grf", i) for i, g in enumerate(gait_ocp.GRF_CHANNELS)]
    return ch


def sd_columns(gait, tau_grid) -> dict:
    """``sd_<channel>`` columns (SD* of :mod:`gaitlib.gap.locate`) on ``tau_grid``."""
    view = gait_ocp.tracking_data(gait)
    t = np.asarray(view.time, float) / float(view.cycle_time)
    out = {}
    for name, _, _ in _fit_channels():
        sd = view.sd[name].to_numpy()
        floor = SD_FLOOR * float(np.sqrt(np.mean(sd**2)))
        if floor <= 0:
            raise ValueError(f"data channel {name!r} has no SD: cannot standardise its residual")
        out[f"sd_{name}"] = np.maximum(np.interp(tau_grid, t, sd), floor)
    return out


def fit_problem(gp) -> ocp.Problem:
    """``gp``'s problem with the Fit objective (module docstring)."""
    ph = gp.problem.phases[0]
    node, fx = gp.node, gp.effects
    chans = _fit_channels()

    def fit(x, u, p, t, d):
        dd = fx.wrap_data(d, p, t) if fx is not None else d
        n = node(x, u, p)
        tot = 0
        for name, src, i in chans:
            sim = x[i] if src == "x" else n[src][i]
            tot = tot + ((sim - dd[f"ref_{name}"]) / dd[f"sd_{name}"]) ** 2  # an effect may rescale both
        return tot / len(chans)

    goals = [dataclasses.replace(g, weight=g.weight * REG_FACTOR) for g in ph.goals if g.name in _KEEP]
    goals.append(ocp.Goal("Fit", weight=FIT_WEIGHT, integrand=fit, divide_by_duration=True))
    frame = ph.data.copy()
    for k, v in sd_columns(gp.ref.gait, frame.index.to_numpy(float)).items():
        frame[k] = v
    new = dataclasses.replace(ph, goals=tuple(goals), data=frame)
    return dataclasses.replace(gp.problem, phases=(new,), name=gp.problem.name + "_fit")


class Runner:
    """A spec built (and transcribed, on first use) once; :meth:`solve` on any data set."""

    def __init__(self, spec: gait_ocp.GaitSpec, objective: str = "fit"):
        if objective not in OBJECTIVES:
            raise ValueError(f"objective must be one of {OBJECTIVES}, got {objective!r}")
        self.spec, self.objective = spec, objective
        self.gp = gait_ocp.build(spec)
        self.problem = fit_problem(self.gp) if objective == "fit" else self.gp.problem
        self._T = {}

    def transcription(self, warm: bool = False) -> ocp.Transcription:
        """The NLP (built once); ``warm``: with IPOPT's ``mu_init`` = :data:`MU_WARM`."""
        if warm not in self._T:
            opts = self.gp.options
            if warm:
                opts = dataclasses.replace(opts, ipopt={**dict(opts.ipopt), "mu_init": MU_WARM})
            self._T[warm] = ocp.transcribe(self.problem, self.gp.mesh, opts)
        return self._T[warm]

    def reference(self, gait):
        """:func:`gaitlib.problems.gait.reference_on` of the built spec."""
        return gait_ocp.reference_on(self.gp, gait)

    def data_guess(self, gait) -> ocp.Guess:
        """:func:`gaitlib.problems.gait.data_guess_on` of the built spec."""
        return gait_ocp.data_guess_on(self.gp, gait)

    def frame(self, gait):
        frame = gait_ocp.tracking_frame(self.spec, self.reference(gait))
        if self.objective == "fit":
            for k, v in sd_columns(gait, frame.index.to_numpy(float)).items():
                frame[k] = v
        return frame

    def solve(self, gait, guess=None) -> gait_ocp.GaitSolution:
        """Solve on ``gait``: from its data-based guess (``guess=None``) or warm-started
        (IPOPT ``mu_init`` :data:`MU_WARM`) from a solution."""
        _check_same_cycle(self.gp, gait)
        g = self.data_guess(gait) if guess is None else gait_ocp.warm_start(self.gp, guess)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ocp.SolveFailedWarning)
            sol = self.transcription(guess is not None).solve(g, data={"cycle": self.frame(gait)})
        out = gait_ocp.postprocess(self.gp, sol)
        out.stats["from_cache"] = False
        out.stats["objective_kind"] = self.objective
        return out


def solve_or_load(where: Path, solve, *, use_cache: bool = True, objective: str = "fit") -> gait_ocp.GaitSolution:
    """:func:`gaitlib.cache.solve_or_load` for a gap re-solve: the solution cached at
    ``where`` (tagged with its ``objective`` kind), or ``solve()``'s, then stored there."""
    return cache.solve_or_load(where, solve, lambda found: gait_ocp.GaitSolution.from_cache(found, objective_kind=objective),
                               marker="spec.json", use_cache=use_cache)


class Lazy:
    """A runner built on first use (a fully cached group builds nothing): ``factory()``
    makes it; attribute access builds it once."""

    def __init__(self, factory):
        self._factory, self._obj = factory, None

    def __getattr__(self, name):
        if self._obj is None:
            self._obj = self._factory()
        return getattr(self._obj, name)


def solve_on(spec: gait_ocp.GaitSpec, gait, guess=None, *, root=None, use_cache: bool = True,
             runner: Runner | None = None, objective: str = "fit") -> gait_ocp.GaitSolution:
    """Solve ``spec`` tracking ``gait`` (a GaitData) with ``objective``, warm-started from
    ``guess``, or reload it from the cache."""
    runner = runner or Lazy(lambda: Runner(spec, objective))
    return solve_or_load(_where(spec, gait, guess, root, objective), lambda: runner.solve(gait, guess),
                         use_cache=use_cache, objective=objective)


def _work(arg):
    """Sweep worker: one spec, several data sets → {key: GaitSolution}. Builds lazily (a
    fully cached item builds nothing)."""
    spec, jobs, root, use_cache, objective = arg
    runner = Lazy(lambda: Runner(spec, objective))
    return {key: solve_on(spec, gait, guess, root=root, use_cache=use_cache, runner=runner, objective=objective)
            for key, gait, guess in jobs}


def solve_many(groups: dict, *, root=None, use_cache: bool = True, objective: str = "fit", **sweep_kw) -> dict:
    """Solve groups of jobs through :func:`gaitlib.sweep.sweep` (one item per group: its
    spec is built once and solved on each of its data sets).

    Parameters
    ----------
    groups : name → (spec, [(key, gait, guess), ...]); keys unique over all groups.
    root : solutions cache (default :func:`gaitlib.cache.default_dir` of this process,
        passed to the workers explicitly).
    **sweep_kw : ``scheduler``, ``n_workers``, ``serial``, ``progress``.

    Returns
    -------
    dict key → GaitSolution, plus ``"__records__"`` → {group: RunRecord} (failed groups:
    ``ok=False`` with the traceback; a non-converged solve is a solution with its status).
    """
    return sweep_groups(_work, groups, root=root, use_cache=use_cache, objective=objective, **sweep_kw)


def sweep_groups(work, groups: dict, *, root=None, use_cache: bool = True, objective: str = "fit", where=None,
                 **sweep_kw) -> dict:
    """``work((spec, jobs, root, use_cache, objective))`` per group through
    :func:`gaitlib.sweep.sweep`; key → GaitSolution plus ``"__records__"``. ``where(spec,
    gait, guess, root, objective)``: a job's cache entry (default this module's re-solves');
    when every job's entry is there the groups are only loaded, in this process (``serial``):
    no cluster is started for reading files."""
    root = str(Path(root if root is not None else cache.default_dir()).resolve())
    where = where or _where
    if use_cache and groups and not sweep_kw.get("serial") and all(
            cache.find(where(spec, gait, guess, root, objective), "spec.json", to_solve=False) is not None
            for spec, jobs in groups.values() for _, gait, guess in jobs):
        sweep_kw = {**sweep_kw, "serial": True}
    items = {name: (spec, jobs, root, use_cache, objective) for name, (spec, jobs) in groups.items()}
    recs = sweep.sweep(work, items, **sweep_kw)
    out: dict = {"__records__": {r.name: r for r in recs}}
    for r in recs:
        if r.value is not None:
            out.update(r.value)
    return out
