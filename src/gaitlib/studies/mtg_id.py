"""Chapter 5, MTG identification for the child: the problem (:mod:`gaitlib.problems.mtg_id`,
whose names this module re-exports for the book) solved, any parameter set evaluated on the
demanded motion, the identified set beside the thesis's Table 5.2 (labelled reference), saved
for later chapters, and its figures.
"""

from __future__ import annotations

import json
from dataclasses import asdict
import math
from pathlib import Path

import numpy as np
import pandas as pd

from .. import __version__
from .. import conventions as cv
from .. import mtg
from ..problems import gait as gait_ocp
from ..problems.mtg_id import (_JOINTS, GAMMA, PARAMS_FILE, THESIS_RMSE_DEG, W1, W2, IdentSpec,  # noqa: F401  (API)
                               MTGIdentification, _constraints, _params_named, build, chapter_spec,
                               demanded_torques, identify, split)

__all__ = ["IdentSpec", "MTGIdentification", "chapter_spec", "GAMMA", "W1", "W2", "THESIS_RMSE_DEG", "PARAMS_FILE",
           "split", "demanded_torques", "build", "identify", "save_params", "load_params",
           "evaluate", "table_beside_thesis", "margins_table", "envelope_figure", "velocity_figure"]


# --------------------------------------------------------------------------------------
# Evaluation (cost, constraints) of any parameter set on the demanded motion
# --------------------------------------------------------------------------------------


def _as_params(params) -> dict[str, mtg.MTGParams]:
    if params is None:
        return {g: mtg.DEFAULT_PARAMS for g in mtg.GENERATORS}
    return {g: mtg._params_for(params, g) for g in mtg.GENERATORS}


def evaluate(params, demand: pd.DataFrame | None = None, spec: IdentSpec = IdentSpec()) -> dict:
    """Constraints 5.15–5.17 and the parameter term of Eq 5.23 for a parameter set
    (None = Γ_initial, a mapping generator → MTGParams, e.g. ``mtg.THESIS_PARAMS``) on the
    data's motion (``demand``, default :func:`demanded_torques`).

    Returns ``{'constraints': DataFrame (index time; columns '<gen>.5.15' …, N·m or 1),
    'min_margin': {column: min}, 'param_cost': w1 Σ((Γ − Γ0)/range)²}``.
    """
    dem = demanded_torques(spec) if demand is None else demand
    P = _as_params(params)
    cols = {}
    for j in _JOINTS:
        c = _constraints(j, dem[f"q_{j}"].to_numpy(), dem[f"qd_{j}"].to_numpy(), dem[f"tau_{j}"].to_numpy(), P,
                         False)
        cols.update({k: np.asarray(v, float) for k, v in c.items()})
    frame = pd.DataFrame(cols, index=dem.index)
    rng = {k: float(mtg.PARAM_BOUNDS[k][1] - mtg.PARAM_BOUNDS[k][0]) for k in GAMMA}
    pc = spec.w1 * sum(((float(getattr(P[g], k)) - float(getattr(mtg.DEFAULT_PARAMS, k))) / rng[k]) ** 2
                       for g in mtg.GENERATORS for k in GAMMA)
    return {"constraints": frame, "min_margin": frame.min().to_dict(), "param_cost": pc}


def margins_table(sets: dict, demand: pd.DataFrame | None = None, spec: IdentSpec = IdentSpec()) -> pd.DataFrame:
    """Smallest margin of each constraint (rows: generator; columns: Eq 5.15 [N·m], 5.16
    [N·m], 5.17 [1]) for each labelled parameter set; negative = violated on the data."""
    dem = demanded_torques(spec) if demand is None else demand
    out = {}
    for lab, p in sets.items():
        mm = evaluate(p, dem, spec)["min_margin"]
        for g in mtg.GENERATORS:
            for e in ("5.15", "5.16", "5.17"):
                out.setdefault((lab, f"Eq {e}"), {})[g] = mm[f"{g}.{e}"]
    return pd.DataFrame(out)


# --------------------------------------------------------------------------------------
# Tables and the parameter file
# --------------------------------------------------------------------------------------


def table_beside_thesis(res: MTGIdentification) -> pd.DataFrame:
    """Identified Γ (ours) beside thesis Table 5.2, one row per generator and parameter.
    Δ^P in degrees (Table 5.2's unit), the rest dimensionless; ``initial`` = Eq 5.22."""
    rows = []
    for g in mtg.GENERATORS:
        for k in GAMMA:
            f = (lambda v: math.degrees(v)) if k == "delta_P" else float
            rows.append({"generator": g, "parameter": k, "unit": "deg" if k == "delta_P" else "1",
                         "initial (Eq 5.22)": f(getattr(mtg.DEFAULT_PARAMS, k)),
                         "ours": f(getattr(res.params[g], k)),
                         "thesis, Table 5.2": f(getattr(mtg.THESIS_PARAMS[g], k)),
                         "bounds (Table 5.1)": tuple(f(b) for b in mtg.PARAM_BOUNDS[k])})
    return pd.DataFrame(rows).set_index(["generator", "parameter"])


def save_params(res: MTGIdentification, path=PARAMS_FILE) -> Path:
    """Write the identified set with provenance (spec, gaitlib version, IPOPT status,
    iterations, objective) as JSON; Δ^P in rad."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    doc = {
        "description": "MTG fitting parameters identified for the child (thesis Sec 5.1.1, Eqs 5.15-5.23) "
                       "on the Schwartz 2008 data; generator -> Eq 5.9 parameters; delta_P in rad. "
                       "Written by gaitlib.studies.mtg_id.save_params.",
        "params": {g: {k: float(getattr(res.params[g], k)) for k in GAMMA} for g in mtg.GENERATORS},
        "provenance": {"spec": asdict(res.spec), "gaitlib_version": __version__,
                       "status": res.stats["status"], "success": bool(res.stats["success"]),
                       "iterations": int(res.stats["iterations"]), "objective": float(res.stats["objective"]),
                       "max_violation": float(res.stats["max_violation"]),
                       "rmse_deg": {k: float(v) for k, v in res.rmse_deg.items()}},
    }
    path.write_text(json.dumps(doc, indent=1) + "\n")
    return path


def load_params(path=PARAMS_FILE) -> dict[str, mtg.MTGParams]:
    """Read a parameter file written by :func:`save_params` (generator → MTGParams)."""
    return gait_ocp.load_mtg_params(path)


# --------------------------------------------------------------------------------------
# Figures 5.1 and 5.2
# --------------------------------------------------------------------------------------


def envelope_figure(res: MTGIdentification, sets: dict | None = None):
    """Thesis Fig 5.1: each generator's demanded torque τ^M_exp (its share, Eqs 5.18–5.19)
    against the joint angle, inside the isometric envelope of each parameter set — upper
    limit s^τ τ0 t^A (Eq 5.24), lower limit s^τ τ0 t^P (1 − β^P ω̂) (Eq 5.25, at θ̇ = 0).
    Angles in degrees (model convention; hip = thigh in the laboratory)."""
    import matplotlib.pyplot as plt

    sets = sets or {"Gymnast (Eq 5.22)": None, "identified (ours)": res.params}
    dem = res.demand
    fig, axes = plt.subplots(2, 3, figsize=(12, 6), constrained_layout=True)
    for col, j in enumerate(_JOINTS):
        q = dem[f"q_{j}"].to_numpy()
        sh = split(j, dem[f"tau_{j}"].to_numpy())
        lo, hi = q.min(), q.max()
        pad = 0.35 * (hi - lo)
        qq = np.linspace(lo - pad, hi + pad, 300)
        for row, d in enumerate(("ext", "flex")):
            g = f"{j}_{d}"
            ax = axes[row, col]
            for (lab, p), ls in zip(sets.items(), ("--", "-", ":")):
                env = mtg.isometric_envelope(g, qq, _as_params(p))
                ax.plot(qq / cv.DEG, env["active"], ls, color="0.35", lw=1.2,
                        label=rf"$s^\tau\tau_0 t^A$ (Eq 5.24), {lab}")
                ax.plot(qq / cv.DEG, env["passive"], ls, color="0.6", lw=1.2, label=rf"passive (Eq 5.25), {lab}")
            ax.plot(q / cv.DEG, sh[g], "k", lw=1.6, label=r"demanded $\tau^M_{exp}$")
            ax.set_title(g.replace("_", " "))
            ax.set_xlabel(f"{j} angle (deg)")
            ax.set_ylabel("N·m")
    axes[0, 0].legend(fontsize=7)
    return fig


def velocity_figure(res: MTGIdentification, sets: dict | None = None):
    """Thesis Fig 5.2: each generator's demanded active torque (Eq 5.26: share − passive)
    against the joint velocity, under the torque–velocity limit s^τ τ0 t^V (Eq 5.27) of
    each parameter set. Velocities in deg/s (model convention)."""
    import matplotlib.pyplot as plt

    sets = sets or {"Gymnast (Eq 5.22)": None, "identified (ours)": res.params}
    dem = res.demand
    fig, axes = plt.subplots(2, 3, figsize=(12, 6), constrained_layout=True)
    for col, j in enumerate(_JOINTS):
        q, qd = dem[f"q_{j}"].to_numpy(), dem[f"qd_{j}"].to_numpy()
        sh = split(j, dem[f"tau_{j}"].to_numpy())
        lo, hi = qd.min(), qd.max()
        pad = 0.35 * (hi - lo)
        vv = np.linspace(lo - pad, hi + pad, 300)
        for row, d in enumerate(("ext", "flex")):
            g = f"{j}_{d}"
            ax = axes[row, col]
            for (lab, p), ls in zip(sets.items(), ("--", "-", ":")):
                ax.plot(vv / cv.DEG, mtg.torque_velocity(g, vv, _as_params(p)), ls, color="0.35", lw=1.2,
                        label=rf"$s^\tau\tau_0 t^V$ (Eq 5.27), {lab}")
            act = mtg.demanded_active_torque(g, sh[g], q, qd, _as_params(res.params))
            ax.plot(qd / cv.DEG, act, "k.", ms=2.5, label="demanded active torque (identified)")
            ax.set_title(g.replace("_", " "))
            ax.set_xlabel(f"{j} velocity (deg/s)")
            ax.set_ylabel("N·m")
    axes[0, 0].legend(fontsize=7)
    return fig


if __name__ == "__main__":  # python -m gaitlib.studies.mtg_id → solve and write the file
    r = identify(chapter_spec())
    print(r.solution.summary())
    print(table_beside_thesis(r).to_string())
    if r.success:
        print("wrote", save_params(r))
