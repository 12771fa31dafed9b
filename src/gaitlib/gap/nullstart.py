"""The null start: re-solve a nested candidate from the baseline fit itself.

A candidate effect *nests* the baseline when its null parameter values reproduce the
baseline model exactly (every NLP-identified effect of :data:`gaitlib.effects.EFFECTS`:
body and contact parameters scaled by 1 + 0 or shifted by 0, root loads that vanish at 0,
the left leg's Fourier terms multiplied by cos 0 − 1 and sin 0). The baseline fit, with the
effect's parameters at their null values, is then a feasible point of the candidate's NLP
with exactly the baseline's objective.

:func:`null_start_many` starts IPOPT at that point: the baseline solution's own states,
controls and parameters on the same mesh (:meth:`gaitlib.ocp.Guess.from_solution`; the
ordinary warm start, :func:`gaitlib.problems.gait.warm_start`, passes them through the
data-based guess's time grid, which is not exact on the collocation nodes) and the
effect's parameters at their NLP initial values, which :func:`gaitlib.effects.bind`
sets to the null values. IPOPT's initial barrier parameter and bound pushes are made small
(:data:`NULL_START_IPOPT`) so that the start is not moved into the interior of the bounds
(the ordinary warm start uses ``mu_init`` 1e-4 and IPOPT's default pushes of 1e-2, which
can move it far enough to end in a worse local optimum). IPOPT's filter line search does
not guarantee a monotone objective, so the caller checks the result against the baseline
(:func:`gaitlib.gap.diagnose.candidate_fits`).

Solutions are cached under ``<root>/gap/<key>`` like :mod:`gaitlib.gap.solve`'s, the key
hashing the spec, the data's numbers, the baseline solution, the IPOPT options, the kind
``"gap-null-start"`` and the formulation versions (the gait's, the gap re-solve's and this
start's :data:`FORMULATION`).
"""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

from .. import cache
from .. import ocp
from ..problems import gait as gait_ocp
from .solve import FORMULATION as FIT_FORMULATION
from .solve import Lazy, Runner, _check_same_cycle, solve_or_load, sweep_groups
from .io import signature

__all__ = ["NULL_START_IPOPT", "FORMULATION", "null_start_on", "null_start_many", "null_guess"]

#: IPOPT options of the null start (on top of the spec's own): a small initial barrier
#: parameter and small pushes of the start away from the variable bounds and the
#: inequality slacks, so that IPOPT starts at the baseline point.
NULL_START_IPOPT = {"mu_init": 1e-8, "bound_push": 1e-10, "bound_frac": 1e-10, "slack_bound_push": 1e-10,
                    "slack_bound_frac": 1e-10}
#: Version of the null start (the exact baseline point as the guess, :data:`NULL_START_IPOPT`)
#: on top of the gap re-solve's: part of its cache keys; bump it when the start changes.
FORMULATION = "gap-null-start-1"


def null_guess(base) -> ocp.Guess:
    """The baseline solution (GaitSolution or ocp.Solution) as an exact NLP start: its
    states, controls and parameters on its own mesh; parameters it does not have (an
    effect's) keep their NLP initial values."""
    sol = base.solution if isinstance(base, gait_ocp.GaitSolution) else base
    return ocp.Guess.from_solution(sol)


def _where(spec, gait, base, root, objective) -> Path:
    desc = {"kind": "gap-null-start", "spec": spec.to_dict(), "data": signature(gait),
            "guess": gait_ocp.guess_signature(base), "objective": objective, "ipopt": dict(NULL_START_IPOPT)}
    return cache.lookup("gap", desc, root, formulation=(gait_ocp.FORMULATION, FIT_FORMULATION, FORMULATION)
                        + spec.effect_versions(),
                        identified=spec.identified_sets())


def _mesh_of(sol) -> str | None:
    info = (sol.solution.info if isinstance(sol, gait_ocp.GaitSolution) else sol.info) or {}
    return (info.get("meshes") or {}).get("cycle")


class _NullRunner(Runner):
    """A :class:`~gaitlib.gap.solve.Runner` whose solve starts exactly at a baseline solution."""

    def null_transcription(self) -> ocp.Transcription:
        if "null" not in self._T:
            opts = self.gp.options
            opts = dataclasses.replace(opts, ipopt={**dict(opts.ipopt), **NULL_START_IPOPT})
            self._T["null"] = ocp.transcribe(self.problem, self.gp.mesh, opts)
        return self._T["null"]

    def solve_null(self, gait, base) -> gait_ocp.GaitSolution:
        _check_same_cycle(self.gp, gait)
        T = self.null_transcription()
        mesh = _mesh_of(base)
        if mesh is not None and mesh != T.meshes["cycle"].describe():
            raise ValueError("the null start needs the baseline solution on the candidate's own mesh")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ocp.SolveFailedWarning)
            sol = T.solve(null_guess(base), data={"cycle": self.frame(gait)})
        out = gait_ocp.postprocess(self.gp, sol)
        out.stats["from_cache"] = False
        out.stats["objective_kind"] = self.objective
        return out


def null_start_on(spec: gait_ocp.GaitSpec, gait, base, *, root=None, use_cache: bool = True, objective: str = "fit",
                  runner=None) -> gait_ocp.GaitSolution:
    """Solve ``spec`` (the baseline spec plus free effects) tracking ``gait`` from the
    baseline solution ``base`` with the effects at their null values, or reload it."""
    runner = runner or Lazy(lambda: _NullRunner(spec, objective))
    return solve_or_load(_where(spec, gait, base, root, objective), lambda: runner.solve_null(gait, base),
                         use_cache=use_cache, objective=objective)


def _work(arg):
    spec, jobs, root, use_cache, objective = arg
    runner = Lazy(lambda: _NullRunner(spec, objective))
    return {key: null_start_on(spec, gait, base, root=root, use_cache=use_cache, objective=objective, runner=runner)
            for key, gait, base in jobs}


def null_start_many(groups: dict, *, root=None, use_cache: bool = True, objective: str = "fit", **sweep_kw) -> dict:
    """:func:`null_start_on` for groups of jobs, as :func:`gaitlib.gap.solve.solve_many`:
    ``groups`` name → (spec, [(key, gait, baseline solution), ...]); returns key →
    GaitSolution plus ``"__records__"``."""
    return sweep_groups(_work, groups, root=root, use_cache=use_cache, objective=objective, where=_where, **sweep_kw)
