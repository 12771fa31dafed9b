"""Natural-gait data tracking (issue 4; thesis Secs 4.3.2, 5.2 and 5.3): SK, MSK and NMSK models.

Functions
---------
:func:`solve_cached`   solve a :class:`~gaitlib.problems.gait.GaitSpec`, or reload the
                       solution stored under its key (spec + code + data hash).
:func:`natural_gait`   the Free-speed data-tracking solve of a model (SK: Eq 4.11 with the
                       contact parameters free, as Sec 4.3.2; MSK: Eq 5.33; NMSK: Eq 5.55).
:func:`rmse_beside_thesis`  our RMSEs beside the thesis's Table 4.9 / 5.4 / 5.11 (labelled).
:func:`write_outputs`  frames, ``summary.json`` and figures into a directory (the CLI).

Thesis values are references on *different data* (Bovi 2011 vs our Schwartz 2008 Free
class) and appear only in columns labelled with their table.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from .. import cache
from .. import conventions as cv
from ..problems import gait as gait_ocp
from ..problems.gait import tracking_data

__all__ = ["THESIS_RMSE", "solve_cached", "natural_gait", "natural_gait_spec", "rmse_beside_thesis",
           "channels_frame", "sims_and_marks", "write_outputs", "stats_table", "tracking_data"]

#: Thesis RMSEs (different data, Bovi 2011): (kind, joint/component, side) → value.
#: Table 4.9, optimal control row (SK, contact parameters identified), torques N·m, GRF N.
#: Table 5.4 (MSK, Eq 5.33): angles deg, torques N·m, GRF N (tangential = x, normal = y).
THESIS_RMSE = {
    "SK": {("torque", "hip", "r"): 0.42, ("torque", "hip", "l"): 0.42,
           ("torque", "knee", "r"): 0.35, ("torque", "knee", "l"): 0.35,
           ("torque", "ankle", "r"): 0.66, ("torque", "ankle", "l"): 0.66,
           ("grf", "x", "r"): 19.81, ("grf", "x", "l"): 8.33,
           ("grf", "y", "r"): 26.49, ("grf", "y", "l"): 26.38},
    "MSK": {("angle", "hip", "r"): 0.6, ("angle", "knee", "r"): 1.1, ("angle", "ankle", "r"): 1.0,
            ("angle", "hip", "l"): 0.6, ("angle", "knee", "l"): 1.2, ("angle", "ankle", "l"): 0.9,
            ("torque", "hip", "r"): 3.1, ("torque", "knee", "r"): 1.8, ("torque", "ankle", "r"): 3.9,
            ("torque", "hip", "l"): 2.3, ("torque", "knee", "l"): 1.1, ("torque", "ankle", "l"): 3.8,
            ("grf", "x", "r"): 7.2, ("grf", "y", "r"): 24.2, ("grf", "x", "l"): 4.6, ("grf", "y", "l"): 19.7},
    # Table 5.11 (NMSK, Eq 5.55), as printed
    "NMSK": {("angle", "hip", "r"): 0.6, ("angle", "knee", "r"): 1.1, ("angle", "ankle", "r"): 1.0,
             ("angle", "hip", "l"): 0.6, ("angle", "knee", "l"): 1.2, ("angle", "ankle", "l"): 0.9,
             ("torque", "hip", "r"): 2.3, ("torque", "knee", "r"): 1.1, ("torque", "ankle", "r"): 3.8,
             ("torque", "hip", "l"): 2.3, ("torque", "knee", "l"): 1.1, ("torque", "ankle", "l"): 3.8,
             ("grf", "x", "r"): 7.2, ("grf", "y", "r"): 24.1, ("grf", "x", "l"): 4.6, ("grf", "y", "l"): 19.8},
}
THESIS_TABLE = {"SK": "thesis, Table 4.9 (optimal control)", "MSK": "thesis, Table 5.4",
                "NMSK": "thesis, Table 5.11"}


def cache_dir(spec: gait_ocp.GaitSpec, *, guess=None, root=None) -> Path:
    """Where :func:`solve_cached` stores (or finds) the solution of ``spec`` from ``guess``:
    keyed by the spec, the warm start's identity, the gait formulation's version and the
    data and identified sets the spec reads."""
    desc = {"kind": "gait", **spec.to_dict()}
    if guess is not None:
        desc["warm_start"] = gait_ocp.guess_signature(guess)
    return cache.lookup("gait", desc, root, formulation=gait_ocp.FORMULATION, identified=spec.identified_sets())


def load_cached(where) -> gait_ocp.GaitSolution | None:
    """The gait solution stored at a :func:`gaitlib.cache.lookup` directory (or the same
    entry in the repository's store), with ``stats["from_cache"] = True``; None if absent.
    A failed solve reloads as failed (its warning silenced: the status is the result)."""
    found = cache.find(where, "spec.json")
    return None if found is None else gait_ocp.GaitSolution.from_cache(found)


def solve_cached(spec: gait_ocp.GaitSpec, *, use_cache: bool = True, root=None, guess=None,
                 progress: bool = False) -> gait_ocp.GaitSolution:
    """Solve ``spec`` or reload it from the cache (never a stale entry: the key hashes the
    spec, the library's sources and the data). Failed solves are stored and reloaded as
    failed — their status is the result. ``guess``: a :class:`~gaitlib.ocp.Guess` or
    another :class:`~gaitlib.ocp.Solution` (warm start; part of the cache key via its
    objective and status only if given, so warm-started runs are cached separately)."""
    def solve():
        sol = gait_ocp.solve(spec, guess=guess, progress=progress)
        sol.stats["from_cache"] = False
        return sol

    return cache.solve_or_load(cache_dir(spec, guess=guess, root=root), solve, gait_ocp.GaitSolution.from_cache,
                               marker="spec.json", use_cache=use_cache)


def natural_gait_spec(model: str = "SK", cost: str | None = None, speed: str = "Free", **kw) -> gait_ocp.GaitSpec:
    """The natural-gait data-tracking spec: SK → Eq 4.11 (Table 4.8 weights, Sec 4.3.2),
    MSK → Eq 5.33 (Table 5.3), NMSK → Eq 5.55 (Table 5.9), all with the thesis's identified
    contact parameters fixed (Tables 4.17/4.18) unless ``free_contact=True`` (the
    identification of Ch 4)."""
    if cost is None:
        cost = {"SK": "Eq4.11", "MSK": "Eq5.33", "NMSK": "Eq5.55"}.get(model, "Eq5.33")
    return gait_ocp.GaitSpec(model=model, cost=cost, speed_class=speed, **kw)


def natural_gait(model: str = "SK", cost: str | None = None, speed: str = "Free", *, use_cache: bool = True,
                 root=None, guess=None, progress: bool = False, **kw) -> gait_ocp.GaitSolution:
    """Solve (or reload) :func:`natural_gait_spec`; keyword arguments go to the spec."""
    return solve_cached(natural_gait_spec(model, cost, speed, **kw), use_cache=use_cache, root=root,
                        guess=guess, progress=progress)


def rmse_beside_thesis(sol: gait_ocp.GaitSolution) -> pd.DataFrame:
    """Our RMSE per channel (angles deg, torques N·m, GRFs N) beside the thesis's table
    for the same model (NaN where the thesis did not report a channel)."""
    ref = THESIS_RMSE[sol.spec.model]
    rows = []
    for _, r in sol.rmse.iterrows():
        ch = r["channel"]
        side = ch[-1]
        part = ch.split("_")[1] if r["kind"] == "grf" else ch.rsplit("_", 1)[0]
        rows.append({"kind": r["kind"], "channel": part, "side": side, "unit": r["unit"],
                     "ours": r["rmse"], THESIS_TABLE[sol.spec.model]: ref.get((r["kind"], part, side), np.nan)})
    return pd.DataFrame(rows)


def channels_frame(sol: gait_ocp.GaitSolution) -> pd.DataFrame:
    """The solution on the data's channel names (SI, model signs; index time s): joint
    angles ``hip_r`` …, torques ``tau_hip_r`` …, and foot forces ``grf_x_r`` …"""
    out = pd.DataFrame(index=sol.q.index)
    for c in cv.JOINTS:
        out[c] = sol.q[c]
        out[f"tau_{c}"] = sol.torques[c]
    for g in gait_ocp.GRF_CHANNELS:
        out[g] = sol.grf[g]
    out["pelvis_tilt"] = sol.q["pelvis_tilt"]
    return out


def sims_and_marks(solutions: dict) -> tuple[dict, dict]:
    """``{label: GaitSolution}`` → (``{label: channels_frame}``, ``{label: failure label}``):
    the ``sims`` and ``marks`` arguments of :func:`gaitlib.plots.tracking_figure`
    (:func:`gaitlib.marks.failure_label`; None for a converged solve)."""
    from .. import marks

    return ({k: channels_frame(s) for k, s in solutions.items()},
            {k: marks.failure_label(s) for k, s in solutions.items()})


def stats_table(solutions: dict) -> pd.DataFrame:
    """One row of solver statistics per labelled solution; ``mark`` is its failure label
    (:func:`gaitlib.marks.failure_label`, empty when converged)."""
    from .. import marks

    rows = []
    for label, s in solutions.items():
        st = s.stats
        rows.append({"run": label, "mark": marks.failure_label(s) or "", "status": st["status"], "iterations": st["iterations"],
                     "solve (s)": st["solve_time_s"], "ms/iteration": 1e3 * st["time_per_iteration_s"],
                     "build (s)": st["build_time_s"], "objective": st["objective"],
                     "max violation": st["max_violation"], "variables": st["n_variables"],
                     "constraints": st["n_constraints"]})
    return pd.DataFrame(rows).set_index("run")


def write_outputs(sol: gait_ocp.GaitSolution, out, figures: bool = True) -> Path:
    """Write ``sol`` (frames, ``summary.json``, ``rmse_vs_thesis.csv``) and, with
    ``figures``, ``tracking.png`` (angles, torques, GRFs vs the data's ±1 SD bands; a solve
    that did not converge is marked in it, :mod:`gaitlib.marks`)."""
    out = Path(out)
    sol.save(out)
    rmse_beside_thesis(sol).to_csv(out / "rmse_vs_thesis.csv", index=False, float_format="%.6g")
    if figures:
        import matplotlib

        matplotlib.use("Agg")
        from .. import data as data_mod
        from .. import plots

        gait = tracking_data(data_mod.load_gait_data(sol.spec.speed_class, sol.spec.source))
        sims, marks = sims_and_marks({f"{sol.spec.model} {sol.spec.cost}": sol})
        fig = plots.tracking_figure(gait, sims, marks=marks)
        fig.savefig(out / "tracking.png", dpi=110)
    summary = json.loads((out / "summary.json").read_text())
    summary["files"] = sorted(p.name for p in out.iterdir())
    (out / "summary.json").write_text(json.dumps(summary, indent=1, default=str))
    return out
