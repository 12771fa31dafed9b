"""Fidelity II: measured causes of the replication gap, one change at a time.

The first cause measured here is why every tracking solution loads a swinging foot (the
validity gate ``swing_load``):

* :func:`data_clearance` — no solve: the data's own joint angles put on the child model
  (:func:`gaitlib.kinematics.pose_from_data`, the pose the tracking reference uses) and, at
  every instant, each foot's lowest point above the lower of the two feet. Where a foot
  the data say swings sits at 0 mm, tracking the data's angles exactly *requires* that
  foot on the ground: the tracking cost then trades angle error against swing load.
* :func:`swing_ablation` — the same tracking problem solved again with one change: the
  vertical force of a foot the data say swings bounded (``GaitSpec.swing_load_max``). It
  measures what an unloaded swing costs in tracking (RMSE per channel kind) and whether
  the other gates then pass.

Units: SI inside (m, N, s); tables say their unit in the column name.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from .. import conventions as cv
from .. import data as data_mod
from .. import kinematics
from .. import validity
from ..model import ChildModel
from ..problems import gait as gait_ocp
from . import gait as gait_study

#: The ablation's bound on a swinging foot's vertical force: half the validity gate's limit
#: (:data:`gaitlib.validity.SWING_LOAD_BW` × body weight), so a solution meeting it passes
#: the gate with a margin.
SWING_BOUND_BW = 0.5 * validity.SWING_LOAD_BW
#: A swing foot closer to the ground than this is counted as touching, m (the contact
#: model's ellipsoids penetrate ≈ 1–2 mm under body weight).
TOUCH = 0.002


def data_clearance(speed_class: str = "Free", source: str = "schwartz2008", n: int = 200,
                   thigh: str = "lab", ankle_offset_deg: float = 0.0) -> pd.DataFrame:
    """Each foot's lowest point above the lower foot (m) when the model follows the data's
    joint angles, on ``n`` instants of the cycle.

    Returns a frame indexed by the cycle fraction ``tau`` (0 ≤ τ < 1) with columns
    ``clear_r``, ``clear_l`` (m, ≥ 0: the lower foot is at 0) and ``swing_r``, ``swing_l``
    (bool: the data say that foot swings, :func:`gaitlib.data.swing_windows`).
    ``thigh``: how the data's hip angle becomes the model's (see
    :func:`~gaitlib.kinematics.pose_from_data`; ``"lab"`` is what the tracking uses).
    ``ankle_offset_deg``: added to both ankles (dorsiflexion > 0), a sensitivity probe."""
    gd = data_mod.load_gait_data(speed_class, source)
    model = ChildModel()
    T = gd.cycle_time
    tau = np.arange(n) / n
    Q = kinematics.pose_from_data(model, gd, tau * T, None, penetration=0.0, thigh=thigh)
    if ankle_offset_deg:
        for s in cv.SIDES:
            Q[:, cv.COORDS.index(f"ankle_{s}")] += np.deg2rad(ankle_offset_deg)
    bottoms = np.array([kinematics.ellipsoid_bottoms(model, q) for q in Q])
    k = len(cv.ELLIPSOIDS)
    foot = {"r": bottoms[:, :k].min(axis=1), "l": bottoms[:, k:].min(axis=1)}
    low = np.minimum(foot["r"], foot["l"])
    windows = data_mod.swing_windows(gd.events, gd.left_shift)
    out = pd.DataFrame({f"clear_{s}": foot[s] - low for s in cv.SIDES}, index=pd.Index(tau, name="tau"))
    for s in cv.SIDES:
        out[f"swing_{s}"] = data_mod.in_window(tau, windows[s])
    return out


def clearance_summary(clear: pd.DataFrame, touch: float = TOUCH) -> pd.DataFrame:
    """Per foot, over the data's swing window: the smallest clearance (mm) and where it is
    (% of the cycle), the mean clearance (mm), and the share of the swing window in which
    the foot is within ``touch`` of the ground (%)."""
    rows = []
    for s in cv.SIDES:
        sw = clear[f"swing_{s}"].to_numpy(bool)
        c = clear[f"clear_{s}"].to_numpy(float)[sw]
        tau = clear.index.to_numpy(float)[sw]
        rows.append({"foot": s, "min clearance (mm)": 1e3 * c.min(), "at (% cycle)": 100 * tau[np.argmin(c)],
                     "mean clearance (mm)": 1e3 * c.mean(),
                     f"swing within {1e3 * touch:.0f} mm of the ground (%)": 100 * float(np.mean(c < touch))})
    return pd.DataFrame(rows).set_index("foot")


def ablation_specs(model: str = "MSK", bound_bw: float = SWING_BOUND_BW) -> dict[str, gait_ocp.GaitSpec]:
    """The swing-load ablation: the chapter's tracking spec, and the same with each foot's
    vertical force bounded by ``bound_bw`` × body weight while the data say it swings."""
    base = gait_study.natural_gait_spec(model)
    bound = round(bound_bw * cv.BODY_MASS * cv.G, 3)
    return {f"{model} {base.cost}": base,
            f"{model} {base.cost}, swing load ≤ {bound:.2f} N": replace(base, swing_load_max=bound)}


def ablation_row(label: str, sol: gait_ocp.GaitSolution) -> dict:
    """One row of the ablation table: convergence, the gates that the swing concerns, and
    the worst RMSE per channel kind (deg, N·m, N)."""
    g = validity.check(sol)
    tab = g.table.set_index("check")
    worst = sol.rmse.groupby("kind")["rmse"].max()
    return {"run": label, "status": sol.stats["status"], "iterations": sol.stats["iterations"],
            "objective": sol.stats["objective"],
            "swing load (N)": float(tab.loc["swing_load", "value"]),
            "double support (%)": float(tab.loc["double_support", "value"]),
            "worst angle RMSE (deg)": float(worst.get("angle", np.nan)),
            "worst torque RMSE (N·m)": float(worst.get("torque", np.nan)),
            "worst GRF RMSE (N)": float(worst.get("grf", np.nan)),
            "gates": g.label()}


def swing_ablation(model: str = "MSK", *, bound_bw: float = SWING_BOUND_BW, use_cache: bool = True,
                   solutions: dict | None = None) -> tuple[pd.DataFrame, dict]:
    """Solve (or reload) :func:`ablation_specs` and tabulate :func:`ablation_row` of each.
    Returns ``(table, solutions)``."""
    specs = ablation_specs(model, bound_bw)
    if solutions is None:
        solutions = {k: r.value for k, r in gait_ocp.solve_specs(specs, use_cache=use_cache).items()}
    sols = solutions
    return pd.DataFrame([ablation_row(k, sols[k]) for k in specs]).set_index("run"), sols
