"""Ch 4: foot–ground contact parameter identification (thesis Secs 4.3–4.4) on our data.

Three approaches identify the 39 contact parameters of the left foot's toe, ball and heel
ellipsoids (Table 4.5; the right foot is the mirror image) on the Free-speed data of
Schwartz et al. 2008, both legs (left leg by the Fourier phase shift of Eqs 4.1–4.3):

(a) :func:`trajectory_optimization` — Sec 4.3.1. The kinematics are fixed to the data (our
    reference coordinates and their analytic Fourier derivatives); inverse dynamics gives
    the joint torques and pelvis residual loads, the contact model the GRFs, and the 39
    parameters minimise Eq 4.5 (weights Table 4.8: w1 = w2 = 1/4) within the Table 4.7
    bounds and the friction-ratio constraint Eq 4.4 (0.55 ≤ μ_d/μ_s ≤ 0.99). The thesis used
    MATLAB's GlobalSearch; we use a multistart in its spirit (:class:`TrajOptSpec`): one
    local solve from a neutral start x0, then local solves from the best-scoring points of a
    seeded Latin-hypercube scatter of trial points. Each local solve is IPOPT with exact
    first and second derivatives (CasADi AD) in scaled variables z ∈ [0, 1]³⁹ (k_v
    log-scaled: it spans three decades).
(b) :func:`optimal_control` — Sec 4.3.2. The SK data-tracking optimal control problem
    (Eqs 4.6–4.11, Table 4.8 weights, Eq 4.8 residual bounds) with the 39 parameters as
    static NLP variables within Table 4.7 (verbatim) and Eq 4.4.
(c) :func:`optimal_control_body` — Sec 4.4. As (b) plus the 25 mass and joint parameters
    (Table 4.14 bounds), a non-negative normal force at each of the six ellipsoids
    (Sec 4.4.1), and the Imp and Rsd cost terms (Eqs 4.12–4.13, w5 = w6 = 1/4).

Starting points (our choice; the thesis started (a) and (b) from Brown & McPhee's published
parameters, which we could not obtain — ``shared/design/model-facts.md``): the *neutral*
start :func:`neutral_start` — the centre of each Table 4.7 box (k_v at its geometric
centre, 3.2·10⁶ N/m³) with the thesis's friction guess μ_s = 0.40, μ_d = 0.35 (Sec 4.3.1) —
is (a)'s first start and one of (b)'s three (:data:`B_STARTS`, with the data-based guess of
Sec 4.3.2 for the states and controls; :func:`optimal_control_multistart` keeps the converged,
valid run of lowest objective). (b) is reached through a continuation on the residual bounds
(:data:`CONTINUATION`), because from the neutral start the exact problem stopped at IPOPT's
iteration limit, infeasible. (c) is warm-started from
(b)'s solution (states, controls and contact parameters; the body parameters start at their
Sec 4.1.1 values).
The thesis's identified values (Tables 4.17–4.18) are one of (b)'s starts; they also enter
through the HAT-height reference of the tracked kinematics (the height at which that
contact, at rest, carries the data's vertical GRF — the public data have no pelvis marker),
which is also (a)'s fixed pelvis trajectory.

(b) and (c) are solved in the book's reading of the problem (:data:`READINGS`: the data's Jrk
denominators, the swinging foot unloaded) unless ``reading="thesis"``.

Every solve is cached (:mod:`gaitlib.cache`; key = spec + start + code + data), so a rerun
reloads. :func:`save_identified` writes (c)'s parameters with their provenance to
``data/identified/ch4_child.json`` (:mod:`gaitlib.params`), the values later chapters load
with ``GaitSpec(contact_params="ch4", body_params="ch4")``.

Thesis values appear only as labelled references (:data:`THESIS_RMSE`,
:data:`THESIS_GEOMETRY`, :data:`THESIS_CONTACT`, :data:`THESIS_TIME`); they were obtained on
different data (Bovi et al. 2011, 0.98 s cycle).
"""

from __future__ import annotations

import datetime as _dt
import json
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd

from .. import __version__
from .. import cache
from .. import contact as contact_mod
from .. import conventions as cv
from .. import data as data_mod
from .. import params as params_mod
from ..problems import gait as gait_ocp
from ..model import P_BODY_NAMES, P_BODY_UNITS, ChildModel
from .. import validity
from . import gait as gait_study
from ..problems import contact_id as cid_ocp
from ..problems.contact_id import (CONTINUATION, FORMULATION, GUESS_METHOD, MU_RATIO,  # noqa: F401  (API)
                                   TRAJOPT_FORMULATION, InverseDynamicsID, TrajOptSpec, solve_continued,
                                   solve_stage, neutral_start)

__all__ = [
    "APPROACHES", "THESIS_RMSE", "THESIS_GEOMETRY", "THESIS_CONTACT", "THESIS_TIME",
    "TrajOptSpec", "InverseDynamicsID", "ApproachResult",
    "neutral_start", "thesis_params", "trajectory_optimization", "spec_b", "spec_c", "optimal_control",
    "optimal_control_body", "run_all", "READINGS", "reading_options", "B_STARTS", "start_params",
    "optimal_control_multistart", "starts_table", "reading_table", "reading_findings",
    "rmse_table", "rmse_beside_thesis", "solver_table", "geometry_table", "contact_table",
    "body_table", "at_bounds", "friction_ratios", "residual_rms", "grf_fit", "dynamic_consistency", "grf_error_by_phase",
    "save_identified", "identified_vs_result", "THESIS_RANKING", "ranking", "findings",
    "C_TARGET_FACTOR", "C_BASE_ROW", "C_GRF_SCAN", "C_GRF_LEFT", "c_changes", "c_ablation_specs", "c_ablation", "c_ablation_table",
    "c_ablation_findings", "SINK_LIMIT", "friction_label", "friction_identification", "friction_table", "friction_findings", "friction_starts_findings", "reference_slip_findings",
    "left_leg_table", "LEFT_SHIFTED_ROW", "left_leg_findings",
]


#: The three approaches: key → label used in tables and figures.
APPROACHES = {"a": "(a) trajectory optimisation", "b": "(b) optimal control",
              "c": "(c) optimal control + body parameters",
              "c_wide": "(c′) = (c) with Table 4.7 widened to the thesis's (c) values"}


# --------------------------------------------------------------------------------------
# Thesis values (references, on Bovi 2011 data)
# --------------------------------------------------------------------------------------

#: Thesis RMSEs: approach → {(quantity, side): value}. Table 4.9 for (a) and (b) (torques
#: N·m, GRFs N, residuals R_x, R_y N, R_z N·m; side "" for the residuals); Sec 4.4.2 for (c)
#: (GRFs only: "3.37 N and 2.71 N" tangential, "9.94 N and 10.72 N" normal, right and left).
THESIS_RMSE = {
    "a": {("tau_hip", "r"): 16.46, ("tau_hip", "l"): 18.07, ("tau_knee", "r"): 11.06, ("tau_knee", "l"): 11.18,
          ("tau_ankle", "r"): 17.29, ("tau_ankle", "l"): 17.09, ("grf_x", "r"): 36.42, ("grf_x", "l"): 36.60,
          ("grf_y", "r"): 234.67, ("grf_y", "l"): 232.46, ("R_x", ""): 94.35, ("R_y", ""): 349.03,
          ("R_z", ""): 18.12},
    "b": {("tau_hip", "r"): 0.42, ("tau_hip", "l"): 0.42, ("tau_knee", "r"): 0.35, ("tau_knee", "l"): 0.35,
          ("tau_ankle", "r"): 0.66, ("tau_ankle", "l"): 0.66, ("grf_x", "r"): 19.81, ("grf_x", "l"): 8.33,
          ("grf_y", "r"): 26.49, ("grf_y", "l"): 26.38, ("R_x", ""): 0.0, ("R_y", ""): 0.0, ("R_z", ""): 0.0},
    "c": {("grf_x", "r"): 3.37, ("grf_x", "l"): 2.71, ("grf_y", "r"): 9.94, ("grf_y", "l"): 10.72},
}
THESIS_RMSE_SOURCE = {"a": "thesis Table 4.9", "b": "thesis Table 4.9", "c": "thesis Sec 4.4.2"}

#: Thesis identified geometry of the left foot, table units (mm, deg), Table 4.5 order
#: (a, b, c, r_x, r_y, r_z, γ, β, α): Table 4.10 (a), 4.11 (b), 4.17 (c; printed in m there).
THESIS_GEOMETRY = {
    "a": {"toe": (11.4, 46.4, 14.8, 153.5, 10.0, 23.5, -46.3, -21.4, 151.3),
          "ball": (137.7, 22.6, 3.9, 88.2, 4.2, -6.0, -74.6, -3.9, -89.2),
          "heel": (37.4, 35.8, 21.3, -4.7, -3.7, 0.0, -79.1, -28.3, -91.7)},
    "b": {"toe": (11.8, 20.0, 11.0, 145.4, 18.3, 23.5, -47.3, -29.5, 152.5),
          "ball": (80.0, 21.8, 17.9, 67.5, 8.9, -6.0, -57.0, -18.0, -95.5),
          "heel": (24.5, 30.0, 13.5, -21.2, 11.6, 0.0, -68.9, -17.2, -91.6)},
    "c": {"toe": (17.7, 30.0, 16.5, 163.2, 4.1, 23.5, -33.38, -28.89, 155.39),
          "ball": (80.0, 20.6, 17.9, 67.5, 8.9, -6.0, -58.49, -12.45, -89.10),
          "heel": (30.9, 40.0, 13.5, -25.6, 3.5, 0.3, -83.00, -20.36, -91.08)},
}
THESIS_GEOMETRY_SOURCE = {"a": "thesis Table 4.10", "b": "thesis Table 4.11", "c": "thesis Table 4.17"}

#: Thesis identified k_v (N/m³), a_v (s/m), μ_s, μ_d: Table 4.12 (a), 4.13 (b), 4.18 (c).
THESIS_CONTACT = {
    "a": {"toe": (1.67e7, 0.9161, 0.0200, 0.0139), "ball": (1.04e7, 0.6881, 0.6256, 0.4245),
          "heel": (0.07e7, 1.4732, 0.2207, 0.1592)},
    "b": {"toe": (4.60e7, 0.0654, 0.0102, 0.0100), "ball": (0.12e7, 3.0000, 1.2000, 1.1871),
          "heel": (0.95e7, 2.1490, 0.1765, 0.1121)},
    "c": {"toe": (0.75e7, 1.1355, 0.3404, 0.2819), "ball": (2.40e7, 1.89e-5, 0.0101, 0.0100),
          "heel": (1.54e7, 2.4271, 0.1703, 0.1686)},
}
THESIS_CONTACT_SOURCE = {"a": "thesis Table 4.12", "b": "thesis Table 4.13", "c": "thesis Table 4.18"}

#: Thesis compute times (Intel i7-6700, MATLAB): Sec 4.3.3 and Sec 4.4.2.
THESIS_TIME = {"a": "6 min (Sec 4.3.3, GlobalSearch)", "b": "11 min (Sec 4.3.3, GPOPS-II)",
               "c": "5 h (Sec 4.4.2, GPOPS-II)"}

# (c′) is approach (c) with other bounds: the thesis's (c) is its reference
for _d in (THESIS_RMSE, THESIS_RMSE_SOURCE, THESIS_GEOMETRY, THESIS_GEOMETRY_SOURCE, THESIS_CONTACT,
           THESIS_CONTACT_SOURCE, THESIS_TIME):
    _d["c_wide"] = _d["c"]

_GEOM = ("a", "b", "c", "r_x", "r_y", "r_z", "gamma", "beta", "alpha")
_GEOM_UNIT = ("mm",) * 6 + ("deg",) * 3
_FRIC = ("k_v", "a_v", "mu_s", "mu_d")
_FRIC_UNIT = ("N/m^3", "s/m", "-", "-")


#: The readings of (b)/(c) the chapter shows side by side
#: (:data:`gaitlib.studies.gait.READINGS`); in the book's, (b) and (c) may also take up to
#: 3,000 iterations (the constrained swing takes (c) past 1,000).
READINGS = gait_study.READINGS


def reading_options(reading: str = "book") -> dict:
    """The :class:`~gaitlib.problems.gait.GaitSpec` fields of a reading for (b)/(c)
    (:func:`gaitlib.studies.gait.reading_options`, plus ``max_iter`` 3,000 in the book's)."""
    return {**gait_study.reading_options(reading), **({"max_iter": 3000} if reading == "book" else {})}


def spec_b(n_intervals: int = 20, degree: int = 5, contact_bounds: str = "table4.7", reading: str = "book",
           **kw) -> gait_ocp.GaitSpec:
    """Approach (b) (:func:`gaitlib.problems.contact_id.spec_b`) in ``reading``
    (:data:`READINGS`); ``kw`` overrides the reading's fields."""
    return cid_ocp.spec_b(n_intervals, degree, contact_bounds, **{**reading_options(reading), **kw})


def spec_c(n_intervals: int = 20, degree: int = 5, contact_bounds: str = "table4.7", reading: str = "book",
           **kw) -> gait_ocp.GaitSpec:
    """Approach (c) (:func:`gaitlib.problems.contact_id.spec_c`) in ``reading``
    (:data:`READINGS`); ``kw`` overrides the reading's fields."""
    return cid_ocp.spec_c(n_intervals, degree, contact_bounds, **{**reading_options(reading), **kw})


#: (b)'s starting contact parameters (:func:`start_params`), tried in turn; the result kept is
#: the converged, valid one with the lowest objective (:func:`optimal_control_multistart`).
#: The thesis started from Brown & McPhee's published set, which we could not obtain.
B_STARTS = ("neutral", "thesis (c)", "ch4_child")


def start_params(name: str) -> np.ndarray:
    """A start of :data:`B_STARTS` (39,), SI: ``"neutral"`` — :func:`neutral_start`;
    ``"thesis (c)"`` — the thesis's identified set (Tables 4.17–4.18); ``"ch4_child"`` — the
    set stored in ``data/identified/ch4_child.json`` (an earlier identification of ours, so
    the start, and the key, change when that file is re-saved)."""
    if name == "neutral":
        return neutral_start()
    if name == "thesis (c)":
        return thesis_params("c")
    if name == "ch4_child":
        return params_mod.contact_params("ch4")
    raise ValueError(f"start must be one of {B_STARTS}, got {name!r}")


def thesis_params(key: str) -> np.ndarray:
    """The thesis's identified contact parameters of approach ``key`` as a 39-vector (SI,
    left foot): geometry from Table 4.10 / 4.11 / 4.17, k_v, a_v, μ_s, μ_d from
    Table 4.12 / 4.13 / 4.18 (a reference for figures and tables)."""
    p = np.zeros(39)
    for e in cv.ELLIPSOIDS:
        for n, v in zip(_GEOM, THESIS_GEOMETRY[key][e]):
            p[contact_mod.param_index(e, n)] = v / _table_scale(n)
        for n, v in zip(_FRIC, THESIS_CONTACT[key][e]):
            p[contact_mod.param_index(e, n)] = v
    return p


def _table_scale(name: str) -> float:
    """SI → table units (mm, deg) for a contact parameter name."""
    if name in ("a", "b", "c", "r_x", "r_y", "r_z"):
        return 1e3
    if name in ("gamma", "beta", "alpha"):
        return 1 / cv.DEG
    return 1.0


# --------------------------------------------------------------------------------------
# Results
# --------------------------------------------------------------------------------------


@dataclass(eq=False)
class ApproachResult:
    """One identification: parameters, frames on the data's channels, RMSEs, solver stats.

    Attributes
    ----------
    key : ``"a"``, ``"b"`` or ``"c"`` (:data:`APPROACHES`).
    p_contact : (39,) identified contact parameters, SI (left foot).
    p_body : (25,) body/joint parameters used or identified, SI.
    q, torques, residuals, grf, ellipsoids : frames indexed by time (s): coordinates,
        net joint torques (N·m), pelvis residual loads (N, N, N·m), foot forces (N),
        per-ellipsoid normal and friction forces (N).
    rmse : RMSE per channel (format of :attr:`gaitlib.problems.gait.GaitSolution.rmse`).
    stats : ``status``, ``success``, ``iterations``, ``wall_s`` (build + solve),
        ``solve_s``, ``time_per_iteration_s``, ``objective``, ``eq4_5`` (the Eq 4.5 part:
        ¼ Trq + ¼ GRF), ``from_cache``; (a) also ``n_local``, ``n_trial``, ``best_start``.
    solution : the :class:`~gaitlib.problems.gait.GaitSolution` of (b)/(c), else None.
    starts : (a) one row per local solve (start, score at start, cost, status, iterations, s).
    stages : (b)/(c) one row per solve on the way (continuation stages, then the problem
        itself): residual bounds, cost terms, status, iterations, times.
    """

    key: str
    p_contact: np.ndarray
    p_body: np.ndarray
    q: pd.DataFrame
    torques: pd.DataFrame
    residuals: pd.DataFrame
    grf: pd.DataFrame
    ellipsoids: pd.DataFrame
    rmse: pd.DataFrame
    stats: dict
    solution: gait_ocp.GaitSolution | None = None
    starts: pd.DataFrame | None = None
    stages: pd.DataFrame | None = None

    @property
    def label(self) -> str:
        return APPROACHES[self.key]

    @property
    def success(self) -> bool:
        return bool(self.stats["success"])

    def channels(self) -> pd.DataFrame:
        """Angles, net torques and foot forces on the data's channel names (as
        :func:`gaitlib.studies.gait.channels_frame`) for :func:`gaitlib.plots.tracking_figure`."""
        out = pd.DataFrame(index=self.q.index)
        for c in cv.JOINTS:
            out[c] = self.q[c]
            out[f"tau_{c}"] = self.torques[c]
        for g in gait_ocp.GRF_CHANNELS:
            out[g] = self.grf[g]
        return out


def _result_from_gait(key: str, sol: gait_ocp.GaitSolution) -> ApproachResult:
    gp_spec = sol.spec
    pars = sol.solution.parameters
    pc = np.array([pars[f"c.{n}"] for n in contact_mod.param_names()])
    pb = (np.array([pars[f"b.{n}"] for n in P_BODY_NAMES]) if gp_spec.free_body
          else params_mod.body_params(gp_spec.body_params))
    st = sol.stats
    goals = sol.solution.goals.set_index("goal")["value"]
    stats = {"status": st["status"], "success": bool(st["success"]), "iterations": int(st["iterations"]),
             "solve_s": float(st["solve_time_s"]), "build_s": float(st["build_time_s"]),
             "wall_s": float(st["solve_time_s"]) + float(st["build_time_s"]),
             "time_per_iteration_s": float(st["time_per_iteration_s"]), "objective": float(st["objective"]),
             "eq4_5": 0.25 * float(goals.get("Trq", np.nan)) + 0.25 * float(goals.get("GRF", np.nan)),
             "max_violation": float(st["max_violation"]), "n_variables": st["n_variables"],
             "n_constraints": st["n_constraints"], "from_cache": bool(st.get("from_cache", False)),
             "goals": {k: float(v) for k, v in goals.items()}}
    return ApproachResult(key, pc, pb, sol.q, sol.torques, sol.residuals, sol.grf, sol.ellipsoids, sol.rmse,
                          stats, solution=sol)


def trajectory_optimization(spec: TrajOptSpec = TrajOptSpec(), *, use_cache: bool = True, root=None,
                            problem: InverseDynamicsID | None = None) -> ApproachResult:
    """Approach (a): multistart identification on fixed kinematics (Sec 4.3.1; class docs).

    Search (GlobalSearch in spirit): stage 1, a local solve from :func:`neutral_start`;
    stage 2, the ``n_local`` best-scoring of ``n_trial`` Latin-hypercube trial points
    (score = cost + 1000 × Eq 4.4 violation) as starts of further local solves. The result
    is the lowest-cost converged local solution. Cached on the spec and this module's code.
    """
    desc = {"kind": "contact_id_a", **spec.to_dict()}
    # fixed kinematics, the model's default body parameters: no identified set is read
    where = cache.lookup("contact_id", desc, root, formulation=TRAJOPT_FORMULATION, identified=())
    prob = problem or InverseDynamicsID(spec)  # cheap: the solver is built on first use

    def write(rec_and_flag):
        return lambda d: (d / "result.json").write_text(json.dumps(rec_and_flag[0], indent=1))

    rec, from_cache = cache.solve_or_load(
        where, lambda: (_multistart_a(spec, prob), False),
        lambda found: (json.loads((found / "result.json").read_text()), True),
        marker="result.json", use_cache=use_cache, write=write)
    return _result_a(prob, rec, from_cache=from_cache)


def _multistart_a(spec, prob: "InverseDynamicsID") -> dict:
    """Approach (a)'s search itself (:func:`identify_a`): the record of every local solve."""
    t_wall = time.perf_counter()
    t0 = time.perf_counter()
    _ = prob.solver  # symbolic Hessian, IPOPT set-up
    build_s = time.perf_counter() - t0
    starts = [("x0 (neutral)", neutral_start())]
    trial = prob.scatter()
    scores = np.array([prob.score(p) for p in trial])
    order = np.argsort(scores, kind="stable")[:spec.n_local]
    starts += [(f"scatter #{int(i)}", trial[i]) for i in order]
    rows = []
    for name, p0 in starts:
        r = prob.local_solve(p0)
        rows.append({"start": name, "score at start": prob.score(np.clip(p0, prob.lo, prob.hi)),
                     "cost": r["cost"], "status": r["status"], "success": r["success"],
                     "iterations": r["iterations"], "time (s)": r["time_s"],
                     "Eq 4.4 violation": r["ratio_violation"], "p": [float(v) for v in r["p"]]})
    rec = {"rows": rows, "build_s": build_s, "wall_s": time.perf_counter() - t_wall,
           "trial_scores": [float(s) for s in scores], "spec": spec.to_dict()}
    return rec


def _result_a(prob: InverseDynamicsID, rec: dict, from_cache: bool) -> ApproachResult:
    rows = rec["rows"]
    ok = [i for i, r in enumerate(rows) if r["success"] and r["Eq 4.4 violation"] <= 1e-6]
    pool = ok if ok else list(range(len(rows)))
    best = min(pool, key=lambda i: rows[i]["cost"])
    p = np.array(rows[best]["p"])
    fr = prob.frames(p)
    rmse = gait_ocp.rmse_table(fr["q"], fr["torques"], fr["grf"], prob.ref)
    c = prob.cost_function(p)
    its = int(sum(r["iterations"] for r in rows))
    solve_s = float(sum(r["time (s)"] for r in rows))
    stats = {"status": rows[best]["status"], "success": bool(ok), "iterations": its,
             "iterations_best": int(rows[best]["iterations"]), "solve_s": solve_s, "build_s": rec["build_s"],
             "wall_s": rec["wall_s"], "time_per_iteration_s": solve_s / max(its, 1),
             "objective": float(c[0]), "eq4_5": float(c[0]), "goals": {"Trq": float(c[1]), "GRF": float(c[2])},
             "n_local": len(rows), "n_converged": len(ok), "n_trial": len(rec["trial_scores"]),
             "best_start": rows[best]["start"], "from_cache": from_cache, "max_violation": rows[best]["Eq 4.4 violation"]}
    starts = pd.DataFrame([{k: v for k, v in r.items() if k != "p"} for r in rows])
    return ApproachResult("a", p, prob.p_body.copy(), fr["q"], fr["torques"], fr["residuals"], fr["grf"],
                          fr["ellipsoids"], rmse, stats, starts=starts)


def _stages_frame(stages: list, final: gait_ocp.GaitSolution) -> pd.DataFrame:
    rows = []
    for s in list(stages) + [final]:
        st = s.stats
        rows.append({"residual bounds (N, N, N·m)": tuple(s.spec.residual_bounds),
                     "cost": "+".join(sorted(s.spec.term_weights)), "status": st["status"],
                     "iterations": st["iterations"], "solve (s)": st["solve_time_s"], "build (s)": st["build_time_s"],
                     "objective": st["objective"], "max violation": st["max_violation"],
                     "from cache": st.get("from_cache", False)})
    return pd.DataFrame(rows)


def _with_stages(res: ApproachResult, stages: list) -> ApproachResult:
    """Attach the continuation record; wall time, iterations cover all stages."""
    final = res.solution
    res.stages = _stages_frame(stages, final)
    if stages:
        its = int(res.stages["iterations"].sum())
        solve = float(res.stages["solve (s)"].sum())
        build = float(res.stages["build (s)"].sum())
        res.stats.update(iterations_final=res.stats["iterations"], iterations=its, solve_s=solve, build_s=build,
                         wall_s=solve + build, time_per_iteration_s=solve / max(its, 1),
                         n_stages=len(stages) + 1)
    return res


def optimal_control(spec: gait_ocp.GaitSpec | None = None, start=None, stages=CONTINUATION, *, use_cache: bool = True,
                    root=None, progress: bool = False) -> ApproachResult:
    """Approach (b) (Sec 4.3.2): :func:`spec_b` from the data-based guess (Sec 4.3.2) with
    the contact parameters starting at ``start`` (39,) SI (default :func:`neutral_start`),
    reached through the residual-bound continuation ``stages`` (:data:`CONTINUATION`;
    ``()``: solve :func:`spec_b` directly from the start). The result is the solution of
    :func:`spec_b` itself; ``stages`` of the result records every stage."""
    spec = spec or spec_b()
    p0 = neutral_start() if start is None else np.asarray(start, float)
    st = {f"c.{n}": float(v) for n, v in zip(contact_mod.param_names(), p0)}
    final, sols = solve_continued(spec, st, None, stages, use_cache, root, progress)
    return _with_stages(_result_from_gait("b", final), sols)


def optimal_control_multistart(spec: gait_ocp.GaitSpec | None = None, starts=B_STARTS, *, use_cache: bool = True,
                               root=None, progress: bool = False) -> ApproachResult:
    """Approach (b) from each of ``starts`` (:func:`start_params`), each through the
    continuation (:func:`optimal_control`); returns the converged run that passes the validity
    gates with the lowest objective (else the lowest objective of all, marked by its status
    and gates), with every start's record in ``starts`` (:func:`starts_table`)."""
    runs = {name: optimal_control(spec, start=start_params(name), use_cache=use_cache, root=root, progress=progress)
            for name in starts}
    table = starts_table(runs)
    ok = table[table["converged"] & table["valid"]]
    best = (ok if len(ok) else table)["objective"].idxmin()
    res = runs[best]
    res.starts = table.assign(kept=table.index == best)
    res.stats["start"] = best
    return res


def starts_table(runs: dict[str, ApproachResult]) -> pd.DataFrame:
    """One row per start of (b): status, converged, valid (:func:`gaitlib.validity.check`) —
    of the final stage — and how many of the continuation's stages converged, iterations (all stages), objective, the Eq 4.5 part, the force-weighted foot slip (m/s,
    :func:`gaitlib.studies.gait.foot_slip`), the deepest sink (mm,
    :func:`gaitlib.studies.gait.foot_sink`), each ellipsoid's k_v (N/m³)."""
    rows = {}
    for name, r in runs.items():
        g = validity.check(r.solution)
        stg = r.stages if isinstance(r.stages, pd.DataFrame) and len(r.stages) else None
        row = {"status": r.stats["status"], "converged": bool(r.success), "valid": bool(g.passed), "gates": g.label(),
               "stages converged": (f"{int(stg['status'].isin(validity.CONVERGED_STATUSES).sum())} of {len(stg)}"
                                    if stg is not None else ""),
               "iterations": r.stats["iterations"], "objective": r.stats["objective"], "Eq 4.5 part": r.stats["eq4_5"],
               gait_study.SLIP_COLUMN: gait_study.foot_slip(r.solution)["slip"],
               "deepest sink (mm)": 1e3 * gait_study.foot_sink(r.q, r.p_contact, _model_of(r))}
        for e in cv.ELLIPSOIDS:
            row[f"k_v {e} (N/m³)"] = float(r.p_contact[contact_mod.param_index(e, "k_v")])
        rows[name] = row
    return pd.DataFrame.from_dict(rows, orient="index").rename_axis("start")


def reading_table(runs: dict[tuple[str, str], ApproachResult]) -> pd.DataFrame:
    """(b)/(c) in each reading side by side: ``runs`` maps (approach key, reading) to its
    result. Columns: status, gates (:func:`gaitlib.validity.check`), the largest vertical force
    on a foot the data say swings (N), iterations, mean GRF RMSE (N), each ellipsoid's k_v
    (N/m³)."""
    rows = []
    for (key, reading), r in runs.items():
        g = validity.check(r.solution)
        t = g.table.set_index("check")
        rm = r.rmse.set_index("channel")["rmse"]
        row = {"approach": APPROACHES[key], "reading": reading, "status": r.stats["status"], "gates": g.label(),
               "swing load (N)": float(t.loc["swing_load", "value"]), "iterations": r.stats["iterations"],
               "mean GRF RMSE (N)": float(np.mean([rm[c] for c in gait_ocp.GRF_CHANNELS]))}
        for e in cv.ELLIPSOIDS:
            row[f"k_v {e} (N/m³)"] = float(r.p_contact[contact_mod.param_index(e, "k_v")])
        rows.append(row)
    return pd.DataFrame(rows).set_index(["approach", "reading"])


def optimal_control_body(spec: gait_ocp.GaitSpec | None = None, warm: ApproachResult | None = None, start=None, *,
                         use_cache: bool = True, root=None, progress: bool = False) -> ApproachResult:
    """Approach (c) (Sec 4.4): :func:`spec_c`, warm-started from (b)'s solution ``warm``
    (states, controls, contact parameters; body parameters from their Sec 4.1.1 values), or
    — without ``warm`` — from the data-based guess with contact parameters ``start``
    (default :func:`neutral_start`). The result's key is ``"c"``, or ``"c_wide"`` for a spec
    with ``contact_bounds="widened"`` (:func:`spec_c`)."""
    spec = spec or spec_c()
    if warm is not None:
        if warm.solution is None:
            raise ValueError("optimal_control_body: warm must be an optimal-control result ((b))")
        sol = solve_stage(spec, {}, warm.solution, use_cache, root, progress)
    else:
        p0 = neutral_start() if start is None else np.asarray(start, float)
        st = {f"c.{n}": float(v) for n, v in zip(contact_mod.param_names(), p0)}
        sol = solve_stage(spec, st, None, use_cache, root, progress)
    key = "c" if spec.contact_bounds == "table4.7" else "c_wide"
    return _with_stages(_result_from_gait(key, sol), [])


def run_all(n_intervals: int = 20, degree: int = 5, traj: TrajOptSpec = TrajOptSpec(), *, use_cache: bool = True,
            root=None, progress: bool = False) -> dict[str, ApproachResult]:
    """The chapter's three identifications: ``{"a": …, "b": …, "c": …}`` ((c) warm-started
    from (b))."""
    a = trajectory_optimization(traj, use_cache=use_cache, root=root)
    b = optimal_control_multistart(spec_b(n_intervals, degree), use_cache=use_cache, root=root, progress=progress)
    c = optimal_control_body(spec_c(n_intervals, degree), warm=b, use_cache=use_cache, root=root, progress=progress)
    return {"a": a, "b": b, "c": c}


# --------------------------------------------------------------------------------------
# Tables
# --------------------------------------------------------------------------------------


def _kinematics(res: ApproachResult):
    """(t, Q, QD, QDD) of a result at its frame times (arrays 11 × n)."""
    t = res.q.index.to_numpy(dtype=float)
    if res.solution is None:  # (a): the fixed reference kinematics of the problem
        gait = data_mod.load_gait_data("Free")
        ref = gait_ocp.reference(gait, ChildModel(), contact_mod.default_params())
        d = {c: ref.deriv[c](t) for c in cv.COORDS}
        return t, *(np.array([d[c][k] for c in cv.COORDS]) for k in range(3))
    X = res.solution.solution.phase("cycle").interpolate(t)
    return (t, X[list(cv.COORDS)].to_numpy().T, X[[f"qd_{c}" for c in cv.COORDS]].to_numpy().T,
            X[[f"qdd_{c}" for c in cv.COORDS]].to_numpy().T)


def dynamic_consistency(results: dict[str, ApproachResult]) -> pd.DataFrame:
    """How far the data's GRFs are from what each approach's *kinematics* require.

    For the floating base, inverse dynamics with no ground load gives the total external
    force the motion needs: F_x = m ẍ_com, F_y = m (ÿ_com + g). With the pelvis residuals
    (near) zero, as in (b) and (c), the two feet's simulated forces must add up to it, so the
    mismatch E(t) = F(t) − (GRF_r + GRF_l)_data(t) is an error no contact parameters can
    remove: the two feet's errors add up to E, hence the quadratic mean of their RMSEs is at
    least RMS(E) / 2 (a floor). For (a) (kinematics = the data reference, residuals free)
    E is what its residuals would be if its contact reproduced the data's GRFs exactly.

    Returns one row per approach: RMS(E_x), RMS(E_y) (N), the floors RMS(E)/2 and the
    achieved quadratic-mean RMSE of the two feet (N), per direction.
    """
    m = ChildModel()
    f = m.function("inverse_dynamics_grf")
    rows = []
    for k, res in results.items():
        # the data the result tracked (a left leg generated with another order: its own)
        order = getattr(getattr(res.solution, "spec", None), "fourier_order", None)
        gait = data_mod.load_gait_data("Free", **({"fourier_order": order} if order else {}))
        t, Q, QD, QDD = _kinematics(res)
        n = t.size
        _, F = f.map(n)(Q, QD, QDD, np.tile(res.p_body[:, None], n), np.zeros((6, n)))
        F = np.asarray(F)
        row = {"approach": APPROACHES[k]}
        rm = res.rmse.set_index("channel")["rmse"]
        for i, d in ((0, "x"), (1, "y")):
            data_sum = sum(np.interp(t, gait.time, gait.mean[f"grf_{d}_{s}"]) for s in cv.SIDES)
            E = F[i] - data_sum
            rms = float(np.sqrt(np.mean(E**2)))
            row[f"RMS E_{d} (N)"] = rms
            row[f"floor per foot, {d} (N)"] = rms / 2
            row[f"achieved per foot, {d} (N)"] = float(np.sqrt((rm[f"grf_{d}_r"] ** 2 + rm[f"grf_{d}_l"] ** 2) / 2))
        rows.append(row)
    return pd.DataFrame(rows).set_index("approach")


def grf_error_by_phase(results: dict[str, ApproachResult], threshold: float = 20.0) -> pd.DataFrame:
    """Where the vertical GRF error is: each foot's squared error split between the data's
    swing (data vertical force < ``threshold`` N) and stance, and the mean simulated vertical
    force during the data's swing (a foot touching the ground when it should be in the air).

    Returns one row per approach and foot: RMSE (N), share of the squared error in swing
    (%), RMSE over the swing and over the stance samples (N), mean simulated force in swing (N).
    """
    gait = data_mod.load_gait_data("Free")
    rows = []
    for k, res in results.items():
        t = res.grf.index.to_numpy(dtype=float)
        for s in cv.SIDES:
            d = np.interp(t, gait.time, gait.mean[f"grf_y_{s}"])
            e = res.grf[f"grf_y_{s}"].to_numpy() - d
            sw = d < threshold
            rows.append({"approach": APPROACHES[k], "foot": {"r": "right", "l": "left"}[s],
                         "RMSE (N)": float(np.sqrt(np.mean(e**2))),
                         "share of squared error in swing (%)": float(100 * np.sum(e[sw] ** 2) / np.sum(e**2)),
                         "RMSE in swing (N)": float(np.sqrt(np.mean(e[sw] ** 2))) if sw.any() else np.nan,
                         "RMSE in stance (N)": float(np.sqrt(np.mean(e[~sw] ** 2))),
                         "mean simulated force in swing (N)": float(np.mean(res.grf[f"grf_y_{s}"].to_numpy()[sw]))
                         if sw.any() else np.nan})
    return pd.DataFrame(rows).set_index(["approach", "foot"])


def left_leg_table(results: dict[str, ApproachResult], speed_class: str = "Free") -> pd.DataFrame:
    """The left leg's GRF data as Eqs 4.1–4.3 generate them from the right leg (five
    harmonics, what every approach tracks) beside the right leg's samples shifted
    (:data:`~gaitlib.problems.gait.EXACT_FOURIER_ORDER` harmonics), N.

    First row ``data``: the RMS difference of the two curves and the generated vertical
    force's minimum (the measured curve's is ≥ 0). Then one row per approach: its left-foot
    RMSE against each curve (on its own samples, as :func:`rmse_table`), and how far its own
    left vertical force is from its right one shifted by the data's left shift (RMS, N; 0
    for a gait as symmetric as the shifted data)."""
    g5 = data_mod.load_gait_data(speed_class, fourier_order=gait_ocp.FOURIER_ORDER)
    gx = data_mod.load_gait_data(speed_class, fourier_order=gait_ocp.EXACT_FOURIER_ORDER)
    chans = ("grf_x_l", "grf_y_l")
    row = {"run": "data: generated − shifted"}
    for ch in chans:
        row[f"{ch} vs generated (N)"] = float(np.sqrt(np.mean((g5.mean[ch].to_numpy() - gx.mean[ch].to_numpy()) ** 2)))
        row[f"{ch} vs shifted (N)"] = np.nan
    row["generated grf_y_l minimum (N)"] = float(g5.mean["grf_y_l"].min())
    rows = [row]
    for k, res in results.items():
        t = res.grf.index.to_numpy(dtype=float)
        row = {"run": APPROACHES.get(k, k)}
        for ch in chans:
            sim = res.grf[ch].to_numpy()
            for lab, g in (("generated", g5), ("shifted", gx)):
                row[f"{ch} vs {lab} (N)"] = float(np.sqrt(np.mean((sim - np.interp(t, g.time, g.mean[ch])) ** 2)))
        T = g5.cycle_time
        right = np.interp((t + g5.left_shift * T) % T, t, res.grf["grf_y_r"].to_numpy(), period=T)
        row["own grf_y_l vs own grf_y_r shifted (N)"] = float(np.sqrt(np.mean((res.grf["grf_y_l"].to_numpy() - right) ** 2)))
        rows.append(row)
    return pd.DataFrame(rows).set_index("run")


#: The (c) ablation's row that tracks the left leg as the right leg's samples shifted.
LEFT_SHIFTED_ROW = "left leg: the right leg's samples shifted"


def left_leg_findings(left: pd.DataFrame, ablation: pd.DataFrame | None = None) -> list[str]:
    """What the left leg's generation does to (c)'s left-foot GRF error, every number from
    ``left`` (:func:`left_leg_table`) and, when given and usable, the (c) ablation's row
    :data:`LEFT_SHIFTED_ROW` (``ablation``: :func:`c_ablation_table`)."""
    d = left.loc["data: generated − shifted"]
    c = left.loc[APPROACHES["c"]]
    out = [f"The generated left leg differs from the right leg's samples shifted by {d['grf_y_l vs generated (N)']:.1f} N "
           f"(vertical) and {d['grf_x_l vs generated (N)']:.1f} N (horizontal) RMS; its vertical force dips to "
           f"{d['generated grf_y_l minimum (N)']:.1f} N in swing. (c)'s left foot scores grf_y "
           f"{c['grf_y_l vs generated (N)']:.1f} N against it and {c['grf_y_l vs shifted (N)']:.1f} N against the shifted "
           f"curve (grf_x {c['grf_x_l vs generated (N)']:.1f} vs {c['grf_x_l vs shifted (N)']:.1f} N), without a re-solve."]
    if ablation is not None and LEFT_SHIFTED_ROW in ablation.index:
        r = ablation.loc[LEFT_SHIFTED_ROW]
        if r["status"] in validity.CONVERGED_STATUSES and r["gates"] == "valid":
            base = ablation.loc[C_BASE_ROW]
            out.append(f"Re-solved tracking the shifted curve ((c) ablation): grf_y L {r['grf_y L (N)']:.1f} N (book's (c) "
                       f"{base['grf_y L (N)']:.1f} N), grf_x L {r['grf_x L (N)']:.1f} N ({base['grf_x L (N)']:.1f} N).")
        else:
            out.append(f"Re-solved tracking the shifted curve: {r['status']}, {r['gates']} — no number used.")
    out.append(f"(c)'s own left and right vertical forces, half a cycle apart, differ by "
               f"{c['own grf_y_l vs own grf_y_r shifted (N)']:.1f} N RMS, although the tracked data are the right leg "
               "shifted and the two legs' parameters the same: the solution is not a symmetric gait.")
    return out


def residual_rms(res: ApproachResult) -> dict:
    """RMS of the pelvis residual loads over the cycle (R_x, R_y N; R_z N·m)."""
    return {r: float(np.sqrt(np.mean(res.residuals[r].to_numpy() ** 2))) for r in cv.RESIDUALS}


def rmse_table(results: dict[str, ApproachResult]) -> pd.DataFrame:
    """Tidy RMSE table: approach, quantity (``tau_hip``, ``grf_x``, ``R_x`` …), side, unit,
    ours, thesis (labelled source)."""
    rows = []
    for k, res in results.items():
        th = THESIS_RMSE.get(k, {})
        for _, r in res.rmse.iterrows():
            if r["kind"] == "angle":
                continue
            ch = r["channel"]
            side = ch[-1]
            qty = ("tau_" + ch.rsplit("_", 1)[0]) if r["kind"] == "torque" else ch[:-2]
            rows.append({"approach": k, "quantity": qty, "side": side, "unit": r["unit"], "ours": r["rmse"],
                         "thesis": th.get((qty, side), np.nan), "thesis source": THESIS_RMSE_SOURCE[k]})
        for r, v in residual_rms(res).items():
            qty = {"pelvis_fx": "R_x", "pelvis_fy": "R_y", "pelvis_mz": "R_z"}.get(r, r)
            rows.append({"approach": k, "quantity": qty, "side": "", "unit": "N·m" if qty == "R_z" else "N",
                         "ours": v, "thesis": th.get((qty, ""), np.nan), "thesis source": THESIS_RMSE_SOURCE[k]})
    return pd.DataFrame(rows)


def rmse_beside_thesis(results: dict[str, ApproachResult]) -> pd.DataFrame:
    """Table 4.9 layout: one row per approach and source (ours / thesis), one column per
    quantity and side (torques N·m, GRFs N, residuals N, N·m)."""
    t = rmse_table(results)
    t["column"] = t["quantity"] + np.where(t["side"] != "", " " + t["side"].str.upper(), "")
    cols = list(dict.fromkeys(t["column"]))
    ours = t.pivot(index="approach", columns="column", values="ours")[cols]
    ours.index = [f"{APPROACHES[k]} — ours" for k in ours.index]
    th = t.pivot(index="approach", columns="column", values="thesis")[cols]
    th.index = [f"{APPROACHES[k]} — {THESIS_RMSE_SOURCE[k]}" for k in th.index]
    out = pd.concat([ours, th]).sort_index(key=lambda s: s.str[:3], kind="stable")
    return out


def grf_fit(results: dict[str, ApproachResult]) -> pd.DataFrame:
    """How well each approach fits the GRFs: RMSE per foot force (N), their mean, and the
    GRF term of Eq 4.5 (mean squared range-normalised error)."""
    rows = []
    for k, res in results.items():
        r = res.rmse.set_index("channel")["rmse"]
        row = {"approach": APPROACHES[k]}
        for g in gait_ocp.GRF_CHANNELS:
            row[f"{g} (N)"] = float(r[g])
        row["mean GRF RMSE (N)"] = float(np.mean([r[g] for g in gait_ocp.GRF_CHANNELS]))
        row["GRF term (Eq 4.5, unweighted)"] = res.stats["goals"].get("GRF", np.nan)
        rows.append(row)
    return pd.DataFrame(rows).set_index("approach")


def solver_table(results: dict[str, ApproachResult]) -> pd.DataFrame:
    """Status, iterations, wall time and time per iteration of each approach beside the
    thesis's compute times (different machine and software: labelled)."""
    rows = []
    for k, res in results.items():
        s = res.stats
        rows.append({"approach": APPROACHES[k], "status": s["status"], "iterations": s["iterations"],
                     "build (s)": s["build_s"], "solve (s)": s["solve_s"], "wall (s)": s["wall_s"],
                     "ms / iteration": 1e3 * s["time_per_iteration_s"], "objective": s["objective"],
                     "Eq 4.5 part": s["eq4_5"], "from cache": s["from_cache"],
                     "thesis time": THESIS_TIME[k]})
    return pd.DataFrame(rows).set_index("approach")


def geometry_table(results: dict[str, ApproachResult]) -> pd.DataFrame:
    """Tables 4.10 / 4.11 / 4.17: left-foot ellipsoid geometry (mm, deg), ours beside the
    thesis's, rows (approach, ellipsoid, source)."""
    rows = []
    for k, res in results.items():
        for e in cv.ELLIPSOIDS:
            ours = {f"{n} ({u})": res.p_contact[contact_mod.param_index(e, n)] * _table_scale(n)
                    for n, u in zip(_GEOM, _GEOM_UNIT)}
            rows.append({"approach": APPROACHES[k], "ellipsoid": e, "source": "ours", **ours})
            th = dict(zip([f"{n} ({u})" for n, u in zip(_GEOM, _GEOM_UNIT)], THESIS_GEOMETRY[k][e]))
            rows.append({"approach": APPROACHES[k], "ellipsoid": e, "source": THESIS_GEOMETRY_SOURCE[k], **th})
    return pd.DataFrame(rows).set_index(["approach", "ellipsoid", "source"])


def contact_table(results: dict[str, ApproachResult]) -> pd.DataFrame:
    """Tables 4.12 / 4.13 / 4.18: k_v, a_v, μ_s, μ_d per ellipsoid, ours beside the thesis's."""
    rows = []
    for k, res in results.items():
        for e in cv.ELLIPSOIDS:
            ours = {f"{n} ({u})" if u != "-" else n: res.p_contact[contact_mod.param_index(e, n)]
                    for n, u in zip(_FRIC, _FRIC_UNIT)}
            rows.append({"approach": APPROACHES[k], "ellipsoid": e, "source": "ours", **ours})
            th = dict(zip([f"{n} ({u})" if u != "-" else n for n, u in zip(_FRIC, _FRIC_UNIT)], THESIS_CONTACT[k][e]))
            rows.append({"approach": APPROACHES[k], "ellipsoid": e, "source": THESIS_CONTACT_SOURCE[k], **th})
    return pd.DataFrame(rows).set_index(["approach", "ellipsoid", "source"])


def body_table(res: ApproachResult) -> pd.DataFrame:
    """Tables 4.15 / 4.16: the 25 body/joint parameters — initial (Sec 4.1.1, ours), ours
    identified, Table 4.14 bounds, and the thesis's initial/tuned values (Tables 4.15–4.16;
    the thesis does not report the HAT COM, which is not identified)."""
    m = ChildModel()
    p0 = m.default_p_body()
    lo, hi = m.p_body_bounds()
    th = m.p_body_identified()
    th_init = _thesis_body_initial()
    rows = []
    for i, (n, u) in enumerate(zip(P_BODY_NAMES, P_BODY_UNITS)):
        rows.append({"parameter": n, "unit": u.replace(" ", "·"), "initial (Sec 4.1.1)": p0[i],
                     "ours identified": res.p_body[i], "lower (Table 4.14)": lo[i], "upper (Table 4.14)": hi[i],
                     "thesis initial (Tables 4.15–4.16)": th_init[i], "thesis tuned (Tables 4.15–4.16)": th[i]})
    return pd.DataFrame(rows).set_index("parameter")


def _thesis_body_initial() -> np.ndarray:
    """Thesis Tables 4.15–4.16 'initial' rows, as printed (COMs in mm → m)."""
    return np.array([28.1, 4.14, 1.93, 0.0858, 0.257, 0.257,
                     1.24, 0.0494, 0.0230, 0.32e-4, 4e-4, 4e-4,
                     0.1559, 0.1566, 0.0316, 0.0477, 0.0320,
                     2.89, 1.59, 6.039, 6.039,
                     3e-4, 2.98, 3.68, 3.68])


def at_bounds(res: ApproachResult, rtol: float = 1e-3) -> pd.DataFrame:
    """Identified parameters within ``rtol`` × (box width) of a bound (contact: Table 4.7;
    body: Table 4.14)."""
    rows = []
    lo, hi = contact_mod.bounds()
    for i, n in enumerate(contact_mod.param_names()):
        w = hi[i] - lo[i]
        v = res.p_contact[i]
        for side, b in (("lower", lo[i]), ("upper", hi[i])):
            if abs(v - b) <= rtol * w:
                rows.append({"parameter": n, "bound": side, "value (SI)": v})
    if res.key in ("c", "c_wide"):
        m = ChildModel()
        blo, bhi = m.p_body_bounds()
        for i, n in enumerate(P_BODY_NAMES):
            w = bhi[i] - blo[i]
            for side, b in (("lower", blo[i]), ("upper", bhi[i])):
                if abs(res.p_body[i] - b) <= rtol * w:
                    rows.append({"parameter": n, "bound": side, "value (SI)": res.p_body[i]})
    return pd.DataFrame(rows, columns=["parameter", "bound", "value (SI)"])


def friction_ratios(results: dict[str, ApproachResult]) -> pd.DataFrame:
    """μ_d / μ_s per ellipsoid and approach (Eq 4.4: within [0.55, 0.99])."""
    return pd.DataFrame({APPROACHES[k]: {e: r.p_contact[contact_mod.param_index(e, "mu_d")]
                                        / r.p_contact[contact_mod.param_index(e, "mu_s")] for e in cv.ELLIPSOIDS}
                         for k, r in results.items()})


# --------------------------------------------------------------------------------------
# Identified parameters for later chapters
# --------------------------------------------------------------------------------------


def save_identified(res: ApproachResult, path=None, name: str = "ch4_child") -> Path:
    """Write (c)'s identified parameters with their provenance (:mod:`gaitlib.params` format).

    Refuses a result that did not converge (IPOPT status other than Solve_Succeeded).
    ``path`` default: :func:`gaitlib.params.identified_path` of ``name`` (``data/identified/
    <name>.json``; ``"ch4_child"``, or ``"ch4_legs"`` for a (c) on longer legs, whose file
    also records its ``leg_scale``).
    Note: data JSON files are part of the solution-cache fingerprint, so writing this file
    makes every stored solution unreachable (they are recomputed on next use).
    """
    if res.key != "c" or res.solution is None:
        raise ValueError("save_identified: expects the approach (c) result")
    if not res.success:
        raise ValueError(f"save_identified: approach (c) did not converge ({res.stats['status']}); not saving")
    path = Path(path) if path is not None else params_mod.identified_path(name)
    m = gait_ocp.spec_model(res.solution.spec)
    clo, chi = contact_mod.bounds()
    blo, bhi = m.p_body_bounds()
    st = res.stats
    legs = (f" The model's thigh and shank are {m.leg_scale:g} x Table 4.1's (GaitSpec.leg_scale); the body "
            "parameters are for those legs." if res.solution.spec.leg_scale is not None else "")
    out = {
        "name": name,
        "description": ("Contact (39, left foot) and body/joint (25) parameters identified by approach (c) of "
                        "thesis Sec 4.4 (optimal control, Eq 4.13, per-ellipsoid normal force >= 0, Table 4.7 and "
                        "Table 4.14 bounds) on the Schwartz 2008 Free-speed data, both legs." + legs),
        **({"leg_scale": float(m.leg_scale)} if res.solution.spec.leg_scale is not None else {}),
        "p_contact": {n: float(v) for n, v in zip(contact_mod.param_names(), res.p_contact)},
        "p_body": {n: float(v) for n, v in zip(P_BODY_NAMES, res.p_body)},
        "units": {"p_contact": {n: u for n, u in zip(contact_mod.param_names(),
                                                     contact_mod.PARAM_UNITS * len(cv.ELLIPSOIDS))},
                  "p_body": dict(zip(P_BODY_NAMES, P_BODY_UNITS))},
        "bounds": {"p_contact": {n: [float(a), float(b)] for n, a, b in zip(contact_mod.param_names(), clo, chi)},
                   "p_body": {n: [float(a), float(b)] for n, a, b in zip(P_BODY_NAMES, blo, bhi)}},
        "provenance": {
            "study": "gaitlib.studies.contact_id.optimal_control_body (warm start: approach (b))",
            "method": ("approach (b) from the neutral start (Table 4.7 box centres, k_v geometric centre, "
                       "mu_s 0.40, mu_d 0.35) through the residual-bound continuation CONTINUATION; approach (c) "
                       "warm-started from (b)'s solution; IPOPT (MUMPS), exact Hessian, tol 1e-5, 20 x 5 LGR"),
            "data": "Schwartz et al. 2008, Free speed class (data/schwartz2008_curves.csv), both legs",
            "spec": res.solution.spec.to_dict(),
            "gaitlib_version": __version__,
            "cache_fingerprint": cache.fingerprint((gait_ocp.FORMULATION, FORMULATION),
                                                   identified=res.solution.spec.identified_sets()),
            "spec_key": res.solution.stats.get("spec_key"),
            "ipopt_status": st["status"],
            "iterations": st["iterations"],
            "objective": st["objective"],
            "solve_time_s": st["solve_s"],
            "date": _dt.date.today().isoformat(),
        },
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(out, indent=1) + "\n")
    return path


def identified_vs_result(res: ApproachResult, name: str = "ch4_child") -> dict:
    """Compare the stored identified set with a (c) result: max relative difference of the
    contact and body parameters (relative to each parameter's bound width) and the stored
    provenance."""
    stored = params_mod.load_identified(name)
    m = _model_of(res)
    clo, chi = contact_mod.bounds()
    blo, bhi = m.p_body_bounds()
    dc = np.max(np.abs(stored["p_contact"] - res.p_contact) / (chi - clo))
    db = np.max(np.abs(stored["p_body"] - res.p_body) / np.maximum(bhi - blo, 1e-12))
    return {"max_rel_diff_contact": float(dc), "max_rel_diff_body": float(db), "provenance": stored["provenance"],
            "path": str(stored["path"])}


def identified_note(cmp: dict, res: ApproachResult, tol: float = 1e-6) -> str:
    """One sentence on whether the stored identified set (``cmp`` =
    :func:`identified_vs_result`) is ``res``'s: if not, which spec fields of the solve it
    was written from differ from ``res``'s (absent fields: the spec's default of that time)."""
    worst = max(cmp["max_rel_diff_contact"], cmp["max_rel_diff_body"])
    if worst <= tol:
        return f"The stored file is this page's (c) (largest difference {worst:.1e} of the bound widths)."
    old = cmp["provenance"].get("spec") or {}
    new = res.solution.spec.to_dict()
    diff = {k: (old.get(k, "unset"), new.get(k, "unset")) for k in sorted(set(old) | set(new))
            if old.get(k, "unset") != new.get(k, "unset")}
    what = ", ".join(f"{k}: {a!r} there, {b!r} here" for k, (a, b) in diff.items()) or "no spec field (the code)"
    return (f"**The stored file is not this page's (c)** (largest difference {worst:.2f} of the bound widths): it "
            f"was written on {cmp['provenance'].get('date', '?')} from a (c) solved with a different problem — {what}. "
            "Later chapters load the stored file, so they use that earlier identification.")


# --------------------------------------------------------------------------------------
# What the chapter found
# --------------------------------------------------------------------------------------

#: The thesis's ranking of the approaches by mean GRF RMSE, best first (Sec 4.5).
THESIS_RANKING = ("(c)", "(b)", "(a)")


def ranking(fit: pd.DataFrame) -> list[str]:
    """The approaches' short labels ("(a)", "(b)", …) ordered by mean GRF RMSE, best first
    (``fit`` = :func:`grf_fit`, rows labelled as :data:`APPROACHES`)."""
    return list(fit["mean GRF RMSE (N)"].sort_values().index.str[:3])


def reading_findings(b: ApproachResult, readings: pd.DataFrame) -> list[str]:
    """Sentences on (b)'s multistart (``b.starts``, :func:`optimal_control_multistart`) and on
    the two readings (:func:`reading_table`), every number from them."""
    out = []
    if b.starts is not None:
        st = b.starts.sort_values("objective")
        runs = "; ".join(f"{name}: {r.objective:.4g} ({r.iterations} iterations, "
                         f"{'converged' if r.converged else 'NOT converged'}, {'valid' if r.valid else 'invalid'})"
                         for name, r in st.iterrows())
        out.append(f"(b) from {len(st)} starts, objective lowest first — {runs}. Kept: {b.stats['start']}.")
    for lab in dict.fromkeys(readings.index.get_level_values(0)):
        t, o = readings.loc[(lab, "thesis")], readings.loc[(lab, "book")]
        ratios = ", ".join(f"{e} ×{o[f'k_v {e} (N/m³)'] / t[f'k_v {e} (N/m³)']:.2f}" for e in cv.ELLIPSOIDS)
        out.append(f"{lab}: in the thesis's reading a swinging foot carries up to {t['swing load (N)']:.0f} N "
                   f"({t['gates']}); in the book's {o['swing load (N)']:.1f} N ({o['gates']}). Mean GRF RMSE "
                   f"{t['mean GRF RMSE (N)']:.1f} N → {o['mean GRF RMSE (N)']:.1f} N; k_v book / thesis: {ratios}.")
    return out


#: The Fidelity II target for (c)'s GRF rows: each within this factor of the thesis's Sec 4.4.2
#: value (:data:`THESIS_RMSE`, labelled reference).
C_TARGET_FACTOR = 1.5
#: The base row of the (c) ablation: the book's (c).
C_BASE_ROW = "(c), book's reading"


#: The GRF weights of the (c) ablation's scan beyond Table 4.8's ¼ → 1 (×16, ×64).
C_GRF_SCAN = (4.0, 16.0)
#: The GRF weights combined with the shifted left leg (×16, ×32: ×64 alone did not converge).
C_GRF_LEFT = (4.0, 8.0)


def c_changes() -> dict[str, dict]:
    """The (c) ablation's changes, each a set of :class:`~gaitlib.problems.gait.GaitSpec`
    fields applied to (c) in the book's reading (:func:`spec_c`). One at a time: each tracking
    weight of Eq 4.13 (Table 4.8's ¼ → 1), the Jrk denominators of the HAT's horizontal
    position and tilt as printed (the reference's, so 1), the swinging foot unbounded (as
    printed), the mesh (40 × 5 instead of 20 × 5), and the left leg's data generated from the
    right with every harmonic the data carry (:data:`LEFT_SHIFTED_ROW`: the right leg's
    samples shifted) instead of Eqs 4.1–4.3's five. Then the GRF weight raised further
    (:data:`C_GRF_SCAN`: the vertical error's trade-off against the other terms), and raised
    weights combined with the shifted left leg (:data:`C_GRF_LEFT`). (The friction bound is
    its own experiment, (b) included: :func:`friction_identification`.)"""
    w = dict(gait_ocp.COST_FUNCTIONS["SK"][spec_c().cost])
    exact = gait_ocp.EXACT_FOURIER_ORDER
    return {
        f"GRF weight ×{1 / w['GRF']:g}": {"weights": (("GRF", 1.0),)},
        f"coordinate weight ×{1 / w['Q']:g}": {"weights": (("Q", 1.0),)},
        f"torque weight ×{1 / w['Trq']:g}": {"weights": (("Trq", 1.0),)},
        "Jrk denominators as printed": {"jerk_ranges": None},
        "swinging foot unbounded (as printed)": {"swing_load_max": None},
        "mesh 40 × 5": {"n_intervals": 40},
        LEFT_SHIFTED_ROW: {"fourier_order": exact},
        **{f"GRF weight ×{f / w['GRF']:g}": {"weights": (("GRF", f),)} for f in C_GRF_SCAN},
        **{f"GRF weight ×{f / w['GRF']:g} + {LEFT_SHIFTED_ROW}": {"weights": (("GRF", f),), "fourier_order": exact}
           for f in C_GRF_LEFT},
    }


def c_ablation_specs() -> dict[str, gait_ocp.GaitSpec]:
    """Row → the spec of each :func:`c_changes` entry."""
    base = spec_c()
    return {k: replace(base, **ch) for k, ch in c_changes().items()}


def c_ablation(b: ApproachResult | None = None, *, use_cache: bool = True, root=None,
               progress: bool = False) -> tuple[pd.DataFrame, dict[str, ApproachResult]]:
    """Each :func:`c_changes` entry applied to approach (c), warm-started from (b)'s
    solution ``b`` as (c) is (:func:`optimal_control_body`; (b) solved or reloaded when not
    given). Returns (:func:`c_ablation_table`, the results by row, the book's (c) first as
    :data:`C_BASE_ROW`)."""
    b = b if b is not None else optimal_control_multistart(use_cache=use_cache, root=root)
    runs = {C_BASE_ROW: optimal_control_body(warm=b, use_cache=use_cache, root=root)}
    for k, sp in c_ablation_specs().items():
        runs[k] = _result_from_gait("c", solve_stage(sp, {}, b.solution, use_cache, root, progress))
    return c_ablation_table(runs), runs


def c_ablation_table(runs: dict[str, ApproachResult]) -> pd.DataFrame:
    """One row per (c) ablation run: status, iterations, objective, the validity gates, each
    foot's GRF RMSE (N) beside its target (:data:`C_TARGET_FACTOR` × the thesis's Sec 4.4.2
    value), whether all four meet it, the worst angle (deg) and torque (N·m) RMSE, and the
    vertical floor the run's own kinematics put under the GRF error (:func:`dynamic_consistency`)."""
    rows = []
    th = THESIS_RMSE["c"]
    for k, r in runs.items():
        rm = r.rmse.set_index("channel")
        row = {"run": k, "status": r.stats["status"], "iterations": r.stats["iterations"],
               "objective": r.stats["objective"], "gates": validity.label(r)}
        met = True
        for q in ("grf_x", "grf_y"):
            for s in cv.SIDES:
                v = float(rm.loc[f"{q}_{s}", "rmse"])
                row[f"{q} {s.upper()} (N)"] = v
                met &= v <= C_TARGET_FACTOR * th[(q, s)]
        row["GRF targets met"] = bool(met)
        kinds = rm.groupby("kind")["rmse"].max()
        row["worst angle RMSE (deg)"] = float(kinds.get("angle", np.nan))
        row["worst torque RMSE (N·m)"] = float(kinds.get("torque", np.nan))
        row["vertical floor per foot (N)"] = float(dynamic_consistency({"c": r}).iloc[0]["floor per foot, y (N)"])
        row[gait_study.SLIP_COLUMN] = gait_study.foot_slip(r.solution)["slip"]
        rows.append(row)
    return pd.DataFrame(rows).set_index("run")


def c_ablation_findings(table: pd.DataFrame) -> list[str]:
    """What the (c) ablation measured, every number from ``table`` (:func:`c_ablation_table`):
    the targets, which run meets all four GRF targets (converged and valid only), and for
    each run its vertical errors beside its kinematics' floor."""
    th = THESIS_RMSE["c"]
    tgt = {(q, s): C_TARGET_FACTOR * th[(q, s)] for q in ("grf_x", "grf_y") for s in cv.SIDES}
    ok = table[table["status"].isin(validity.CONVERGED_STATUSES) & (table["gates"] == "valid")]
    out = [f"Targets ({C_TARGET_FACTOR:g} × the thesis's Sec 4.4.2 values): grf_x R/L "
           f"{tgt[('grf_x', 'r')]:.3f} / {tgt[('grf_x', 'l')]:.3f} N, grf_y R/L {tgt[('grf_y', 'r')]:.2f} / "
           f"{tgt[('grf_y', 'l')]:.2f} N."]
    bad = table.index[~table.index.isin(ok.index)]
    if len(bad):
        out.append("Not converged or not valid (no number used): "
                   + "; ".join(f"{k} ({table.loc[k, 'status']}, {table.loc[k, 'gates']})" for k in bad) + ".")
    met = ok.index[ok["GRF targets met"]]
    out.append("Every GRF target at once: " + (", ".join(
        f"{k} (grf_y {ok.loc[k, 'grf_y R (N)']:.1f} / {ok.loc[k, 'grf_y L (N)']:.1f} N, worst angle "
        f"{ok.loc[k, 'worst angle RMSE (deg)']:.1f}°)" for k in met) if len(met) else "no run") + ".")
    if len(ok) and not len(met):
        ratio = pd.DataFrame({f"{q} {s_.upper()}": ok[f"{q} {s_.upper()} (N)"] / tgt[(q, s_)] for (q, s_) in tgt})
        worst = ratio.max(axis=1)
        k = worst.idxmin()
        over = [f"{c} {ok.loc[k, c + ' (N)']:.3f} N vs {tgt[(c.split()[0], c.split()[1].lower())]:.3f} N"
                for c in ratio.columns if ratio.loc[k, c] > 1.0]
        out.append(f"Closest to every target: {k}, its worst channel {100 * (worst[k] - 1):.1f} % over "
                   f"({'; '.join(over)}).")
    for k, r in ok.iterrows():
        out.append(f"{k}: grf_y R/L {r['grf_y R (N)']:.1f} / {r['grf_y L (N)']:.1f} N, of which its kinematics "
                   f"force at least {r['vertical floor per foot (N)']:.1f} N per foot; worst angle "
                   f"{r['worst angle RMSE (deg)']:.1f}°, worst torque {r['worst torque RMSE (N·m)']:.1f} N·m.")
    return out


# --------------------------------------------------------------------------------------
# Do the identified feet stand still? (b) and (c) again with a friction lower bound
# --------------------------------------------------------------------------------------


#: The sink bound (m) of the friction experiment's second variant: our choice, about the
#: deepest the book's own (c) sinks (its table shows it), so that the friction bound cannot
#: be met by softer, deeper-sinking ellipsoids instead (:attr:`GaitSpec.max_sink`).
SINK_LIMIT = 0.018


#: The friction table's column: does the identified set carry the data's load at rest?
REST_COLUMN = "data's load at rest"


def friction_label(key: str, floor: float, max_sink: float | None = None) -> str:
    """The row label of approach ``key`` ("b"/"c") identified with every μ ≥ ``floor`` (and no
    ellipsoid deeper than ``max_sink`` m)."""
    return f"{APPROACHES[key]}, friction ≥ {floor:g}" + (f", sink ≤ {1e3 * max_sink:g} mm" if max_sink else "")


def _model_of(r: ApproachResult) -> ChildModel:
    """The model a (b)/(c) result was solved on (:func:`gaitlib.problems.gait.spec_model`)."""
    spec = getattr(r.solution, "spec", None)  # (a) has no solution: the thesis's model
    return gait_ocp.spec_model(spec) if isinstance(spec, gait_ocp.GaitSpec) else ChildModel()


def leg_label(key: str, scale: float) -> str:
    """The row label of approach ``key`` ("b"/"c") identified with the thigh and shank × ``scale``."""
    return f"{APPROACHES[key]}, thigh and shank ×{scale:g}"


def leg_identification(scale: float | None = None, *, use_cache: bool = True, root=None,
                       progress: bool = False) -> dict[str, ApproachResult]:
    """(b) and (c) as the book identifies them, and again on legs × ``scale`` (default
    :data:`~gaitlib.studies.gait.LEG_SCALE`; :attr:`~gaitlib.problems.gait.GaitSpec.leg_scale`:
    the thigh and shank longer, the data's speed and cycle time following): the reference's
    loaded feet slide half as fast there (:func:`gaitlib.studies.gait.leg_scale_slip`) — does
    the identified ball still take Table 4.7's lowest friction, and do the feet still slide?
    (b) by the same multistart (:data:`B_STARTS`, each through the continuation), (c)
    warm-started from its (b), as the book's. Returns label → result: the book's (b), the
    longer legs' (b), the book's (c), the longer legs' (c)."""
    scale = gait_study.LEG_SCALE if scale is None else float(scale)
    kw = {"use_cache": use_cache, "root": root, "progress": progress}
    b = optimal_control_multistart(**kw)
    lb = optimal_control_multistart(replace(spec_b(), leg_scale=scale), **kw)
    return {APPROACHES["b"]: b, leg_label("b", scale): lb, APPROACHES["c"]: optimal_control_body(warm=b, **kw),
            leg_label("c", scale): optimal_control_body(replace(spec_c(), leg_scale=scale), warm=lb, **kw)}


def friction_identification(floor: float | None = None, max_sinks: tuple = (None, SINK_LIMIT), *,
                            use_cache: bool = True, root=None, progress: bool = False) -> dict[str, ApproachResult]:
    """(b) and (c) as the book identifies them, and again with every ellipsoid's μ_s and μ_d
    bounded below by ``floor`` (default :data:`~gaitlib.studies.gait.FRICTION_FLOOR`, Table
    4.18's largest coefficient) instead of Table 4.7's 0.01
    (:attr:`~gaitlib.problems.gait.GaitSpec.friction_floor` with ``free_contact``) — once for
    each of ``max_sinks``: ``None`` that change alone; a depth (m) with every ellipsoid also
    kept that shallow at every node (:attr:`~gaitlib.problems.gait.GaitSpec.max_sink`). Each
    bounded (b) is the same multistart (:data:`B_STARTS`, each through the continuation, the
    converged valid start with the lowest objective kept); each bounded (c) is warm-started
    from its (b), as (c) from (b). Returns label → result (:func:`friction_label`): the book's
    (b), the bounded (b)s, the book's (c), the bounded (c)s."""
    floor = gait_study.FRICTION_FLOOR if floor is None else float(floor)
    kw = {"use_cache": use_cache, "root": root, "progress": progress}
    b = optimal_control_multistart(**kw)
    out_b, out_c = {APPROACHES["b"]: b}, {APPROACHES["c"]: optimal_control_body(warm=b, **kw)}
    for sink in max_sinks:
        ch = {"friction_floor": floor, "max_sink": sink}
        fb = optimal_control_multistart(replace(spec_b(), **ch), **kw)
        out_b[friction_label("b", floor, sink)] = fb
        out_c[friction_label("c", floor, sink)] = optimal_control_body(replace(spec_c(), **ch), warm=fb, **kw)
    return {**out_b, **out_c}


def friction_table(runs: dict[str, ApproachResult]) -> pd.DataFrame:
    """One row per run of :func:`friction_identification`: status, gates, iterations,
    objective, the (b) start kept, each foot force's RMSE and their mean (N), the worst angle
    (deg) and torque (N·m) RMSE, the force-weighted foot slip (m/s) and the share of the load
    carried sliding faster than v_tr (%; :func:`gaitlib.studies.gait.foot_slip`), the deepest
    any ellipsoid sinks into the ground (mm, :func:`gaitlib.studies.gait.foot_sink`), whether
    the identified set carries the data's load at rest in the data's poses (what the Ch 5
    reference needs, :func:`gaitlib.studies.gait.static_support`), and the ball's μ_s, μ_d."""
    rows = {}
    for k, r in runs.items():
        rm = r.rmse.set_index("channel")
        fs = gait_study.foot_slip(r.solution)
        row = {"status": r.stats["status"], "gates": validity.label(r), "iterations": r.stats["iterations"],
               "objective": r.stats["objective"], "start kept": r.stats.get("start", "(b)'s solution")}
        for g in gait_ocp.GRF_CHANNELS:
            row[f"{g} (N)"] = float(rm.loc[g, "rmse"])
        row["mean GRF RMSE (N)"] = float(np.mean([row[f"{g} (N)"] for g in gait_ocp.GRF_CHANNELS]))
        kinds = rm.groupby("kind")["rmse"].max()
        row["worst angle RMSE (deg)"] = float(kinds.get("angle", np.nan))
        row["worst torque RMSE (N·m)"] = float(kinds.get("torque", np.nan))
        row[gait_study.SLIP_COLUMN] = fs["slip"]
        row[f"load sliding > {gait_study.SLIP_V:g} m/s (%)"] = 100 * fs["sliding"]
        row["deepest sink (mm)"] = 1e3 * gait_study.foot_sink(r.q, r.p_contact, _model_of(r))
        row[REST_COLUMN] = gait_study.static_support(r.p_contact, model=_model_of(r)) or "carried"
        for m in ("mu_s", "mu_d"):
            row[f"ball {m}"] = float(r.p_contact[contact_mod.param_index("ball", m)])
        rows[k] = row
    return pd.DataFrame.from_dict(rows, orient="index").rename_axis("run")


def friction_findings(table: pd.DataFrame) -> list[str]:
    """What the friction bound measured, every number from ``table`` (:func:`friction_table`
    of :func:`friction_identification` — or of :func:`leg_identification`, the same columns):
    each variant run (a row "(b), …" / "(c), …") beside the book's run of its approach — mean
    GRF RMSE, worst angle and torque RMSE, objective, foot slip, the ball's μ_d and the
    deepest sink — or why it is not compared (not converged / not valid)."""
    v = gait_study.SLIP_V
    out = []
    for key in ("b", "c"):
        base = APPROACHES[key]
        if base not in table.index:
            continue
        r0 = table.loc[base]
        for bound in [k for k in table.index if k.startswith(base + ", ")]:
            r1 = table.loc[bound]
            bad = [f"{k} ({r['status']}, {r['gates']})" for k, r in ((base, r0), (bound, r1))
                   if r["status"] not in validity.CONVERGED_STATUSES or r["gates"] != "valid"]
            if bad:
                out.append(f"{bound}: not compared — {'; '.join(bad)}.")
                continue
            g0, g1 = r0["mean GRF RMSE (N)"], r1["mean GRF RMSE (N)"]
            out.append(f"{bound} (start kept: {r1['start kept']}): mean GRF RMSE {g0:.1f} → {g1:.1f} N "
                       f"({100 * (g1 / g0 - 1):+.0f} %), worst angle {r0['worst angle RMSE (deg)']:.2f} → "
                       f"{r1['worst angle RMSE (deg)']:.2f}°, worst torque {r0['worst torque RMSE (N·m)']:.2f} → "
                       f"{r1['worst torque RMSE (N·m)']:.2f} N·m, objective {r0['objective']:.4f} → "
                       f"{r1['objective']:.4f}; the feet slide {r0[gait_study.SLIP_COLUMN]:.3f} → "
                       f"{r1[gait_study.SLIP_COLUMN]:.3f} m/s (force-weighted; load carried sliding > {v:g} m/s "
                       f"{r0[f'load sliding > {v:g} m/s (%)']:.0f} → {r1[f'load sliding > {v:g} m/s (%)']:.0f} %), "
                       f"the ball's μ_d {r0['ball mu_d']:.4f} → {r1['ball mu_d']:.4f}; the deepest an ellipsoid sinks "
                       f"{r0['deepest sink (mm)']:.1f} → {r1['deepest sink (mm)']:.1f} mm"
                       + ("." if r1[REST_COLUMN] == "carried" else
                          f"; at rest in the data's poses the set cannot carry the data's load ({r1[REST_COLUMN]}), "
                          "so no tracking reference (Ch 5) can be built on it."))
    return out


def friction_starts_findings(runs: dict[str, ApproachResult], floor: float | None = None,
                             max_sink: float = SINK_LIMIT) -> list[str]:
    """Local optima of the bounded identifications (``runs``: :func:`friction_identification`):
    a start of the friction-only (b) whose converged, valid solution already sinks no deeper
    than ``max_sink`` (m) yet has a lower objective than the one the sink-bounded multistart
    kept is a feasible point of the sink-bounded problem that its own starts did not reach —
    named with both objectives. Empty when there is none (or a run is missing)."""
    floor = gait_study.FRICTION_FLOOR if floor is None else float(floor)
    only, both = runs.get(friction_label("b", floor)), runs.get(friction_label("b", floor, max_sink))
    if only is None or both is None or only.starts is None or both.starts is None:
        return []
    st, kept = only.starts, both.starts[both.starts["kept"]].iloc[0]
    ok = st[st["converged"] & st["valid"] & (st["deepest sink (mm)"] <= 1e3 * max_sink)
            & (st["objective"] < kept["objective"])]
    return [f"Local optima: from the start '{k}' the friction-only (b) reaches objective {r['objective']:.4f} with its "
            f"feet sinking {r['deepest sink (mm)']:.1f} mm (within the {1e3 * max_sink:g} mm bound) and sliding "
            f"{r[gait_study.SLIP_COLUMN]:.3f} m/s — a feasible point of the sink-bounded problem below the "
            f"{kept['objective']:.4f} its multistart kept ('{both.starts.index[both.starts['kept']][0]}'), so the "
            "sink-bounded rows overstate what the bound costs." for k, r in ok.iterrows()]


def reference_slip_findings(refs: dict[str, dict]) -> list[str]:
    """One sentence per contact set (label → :func:`gaitlib.studies.gait.reference_slip`): how
    fast the feet of the tracking reference itself slide — the data's kinematics on this
    model, no solve — and what is left with the HAT's speed free to anchor the loaded feet."""
    v = gait_study.SLIP_V

    def parts(r):
        b = r.get("by_ellipsoid")
        return ("; by ellipsoid " + ", ".join(f"{e} {x:.2f}" for e, x in b.items()) + " m/s") if b else ""

    def most(r):
        b = r.get("by_ellipsoid")
        return f" (most at the {max(b, key=b.get)} ellipsoids)" if b else ""

    return [f"The tracking reference itself ({k} contact set): its loaded feet slide {r['slip']:.3f} m/s "
            f"(force-weighted{parts(r)}; {100 * r['sliding']:.0f} % of the load sliding > {v:g} m/s) while the HAT moves at a "
            f"constant {r['speed']:.2f} m/s; with the HAT's speed changed at every instant so that the loaded feet's "
            f"load-weighted mean slip is zero "
            f"(it then ranges {r['hat_speed_min']:.2f}–{r['hat_speed_max']:.2f} m/s) the slip is {r['anchored_slip']:.3f} m/s "
            f"({100 * r['anchored_sliding']:.0f} %)"
            + (f": the data's joint angles on this model's legs move the loaded feet over the ground{most(r)}, so a "
               "gait that tracked them exactly would slide." if r["anchored_slip"] > v else
               ": the constant-speed HAT reference is what asks the feet to slide.") for k, r in refs.items()]


def leg_scale_findings(tables: dict[str, pd.DataFrame]) -> list[str]:
    """One sentence per contact set (label → :func:`gaitlib.studies.gait.leg_scale_slip`):
    the reference's slip at the thesis's legs and at the scan's lowest, where its signed mean
    slip changes sign (linear interpolation between the two scan scales around it: there
    the data's stride and the legs' sweep agree), and the scales with no reference."""
    out = []
    for k, t in tables.items():
        ok = t[t["note"] == ""]
        if 1.0 not in ok.index:
            out.append(f"{k} contact set: no reference at the thesis's legs ({t.loc[1.0, 'note'] if 1.0 in t.index else 'not scanned'}).")
            continue
        s0, best = ok.loc[1.0], ok["reference slip (m/s)"].idxmin()
        sm = ok["signed mean slip (m/s)"]
        cross = [(a, b) for a, b in zip(ok.index[:-1], ok.index[1:]) if sm[a] * sm[b] <= 0 and sm[a] != sm[b]]
        if cross:
            a, b = cross[0]
            x = a + (b - a) * sm[a] / (sm[a] - sm[b])
            agree = (f"its signed mean slip changes sign between ×{a:g} and ×{b:g} (≈ ×{x:.2f} by interpolation: there "
                     f"the data's stride and the legs' sweep agree)")
        else:
            agree = f"its signed mean slip keeps one sign over the scan ({sm.min():+.3f} to {sm.max():+.3f} m/s)"
        missing = [f"×{s:g}" for s in t.index if t.loc[s, "note"]]
        out.append(f"{k} contact set: the reference slides {s0['reference slip (m/s)']:.3f} m/s with the thesis's legs "
                   f"(thigh + shank {s0['thigh + shank (m)']:.3f} m; signed mean {s0['signed mean slip (m/s)']:+.3f} m/s, "
                   f"anchored {s0['anchored slip (m/s)']:.3f}); lowest in the scan {ok.loc[best, 'reference slip (m/s)']:.3f} m/s "
                   f"at ×{best:g} ({ok.loc[best, 'thigh + shank (m)']:.3f} m, anchored {ok.loc[best, 'anchored slip (m/s)']:.3f}, "
                   f"{100 * (ok.loc[best, 'reference slip (m/s)'] / s0['reference slip (m/s)'] - 1):+.0f} %); {agree}"
                   + (f"; no reference at {', '.join(missing)} (the set cannot carry the data's load at rest)" if missing else "")
                   + ".")
    return out


def stride_sweep_findings(sweeps: dict[str, dict]) -> str:
    """The sentence on :func:`gaitlib.studies.gait.stride_sweep` of each contact set (label →
    its dict, the thesis's legs): what share of the data's stride the data's angles carry the
    model's loaded feet, and the leg length the dimensionless data would have to be converted
    with for the two to agree, beside the model's hip-to-ground and hip-to-ankle lengths."""
    d0 = next(iter(sweeps.values()))
    hip_ankle = d0["hip_to_ankle"]
    parts = "; ".join(f"{k} contact set: {d['sweep']:.3f} m ({100 * d['ratio']:.0f} %), agreeing at a conversion length of "
                      f"{d['conversion_length']:.3f} m" for k, d in sweeps.items())
    longest = max(d["conversion_length"] for d in sweeps.values())
    return (f"Per cycle the data's stride is {d0['stride']:.3f} m (v*/f*·L with L = {d0['leg_length']:.3f} m, the model's "
            f"hip-to-ground length). The data's angles carry the model's loaded feet (force-weighted; exact: the mean "
            f"slip is (stride − sweep)/T; `gait.stride_sweep`): {parts}. "
            + (f"Every one is shorter than the model's hip-to-ankle length ({hip_ankle:.3f} m), the shortest of the "
               "usual leg-length definitions (hip, trochanter or ASIS to the ankle or the floor): the normalising "
               "length does not explain the difference."
               if longest < hip_ankle else
               f"The model's hip-to-ankle length is {hip_ankle:.3f} m."))


def pelvic_rotation_findings(table: pd.DataFrame, w_zero: float, rotation: pd.DataFrame,
                             body_height: float = cv.BODY_HEIGHT) -> str:
    """The sentence on :func:`gaitlib.studies.gait.pelvic_rotation_slip`'s ``(table, w_zero)``
    (rows: hip-joint-centre separations, m; 0 included): how much of the reference's signed mean
    slip and of its force-weighted slip the data's pelvic rotation (``rotation``:
    :func:`gaitlib.data.context_curve` of ``pelvis_rotation``, deg) removes at each width, and
    the separation it would take to remove the signed mean (× ``body_height``)."""
    sm, sl = table["signed mean slip (m/s)"], table["reference slip (m/s)"]
    w = [x for x in table.index if x > 0]
    pts = ", ".join(f"{x:.2f} m: {sm[x]:+.3f} ({100 * (sm[x] / sm[0.0] - 1):+.0f} %), force-weighted {sl[x]:.3f}" for x in w)
    th = rotation["mean"]
    verdict = (f"It would take the hip centres {w_zero:.2f} m apart ({w_zero / body_height:.2f} × the body height) to "
               "remove the signed mean: the missing pelvic rotation is not what makes the data's stride too long "
               "for the model's legs." if w_zero > gait_study.HIP_WIDTH_OUT_OF_REACH_BH * body_height else
               f"It would take the hip centres {w_zero:.2f} m apart ({w_zero / body_height:.2f} × the body height) to remove "
               "the signed mean.")
    return (f"The data's pelvis turns about the vertical between {th.min():+.1f}° and {th.max():+.1f}° (the ipsilateral "
            "side forward at its foot's contact), which the 2-D model cannot; it moves the stance hip back relative to "
            f"the pelvis as the body moves on. With it added to the reference's hips (no solve; `gait.pelvic_rotation_slip`), "
            f"the signed mean slip goes from {sm[0.0]:+.3f} m/s (no rotation) to {pts}. {verdict}")


def findings(results: dict[str, ApproachResult], widened: ApproachResult, fit: pd.DataFrame,
             consistency: pd.DataFrame, by_phase: pd.DataFrame) -> list[str]:
    """The chapter's findings, one sentence group per item, every number from the results:
    each approach's solve (``results`` keyed "a", "b", "c"), the GRF fit (:func:`grf_fit`)
    and whether the thesis's ranking :data:`THESIS_RANKING` holds, the floor the kinematics
    put under (b)'s and (c)'s GRF error (:func:`dynamic_consistency`) and the swing-phase
    share of it (:func:`grf_error_by_phase`), the pelvis residuals, (c) re-identified within
    widened bounds (``widened``), and (c)'s body mass and parameters at a bound."""
    out = []
    for k, r in results.items():
        s = r.stats
        ok = "converged (Optimal Solution Found)" if s["success"] else f"did NOT converge ({s['status']})"
        extra = ""
        if k == "a":
            extra = f" — {s['n_converged']} of {s['n_local']} local solves converged, best from {s['best_start']}"
        if k == "b":
            bad = r.stages[r.stages["status"] != "Solve_Succeeded"]
            extra = (f" — final problem {s['iterations_final']} iterations; continuation stages not converged: "
                     + (", ".join(f"{tuple(x)} ({y})" for x, y in zip(bad["residual bounds (N, N, N·m)"], bad["status"]))
                        or "none"))
        out.append(f"{APPROACHES[k]} {ok}: {s['iterations']} iterations, {s['wall_s'] / 60:.1f} min wall "
                   f"({1e3 * s['time_per_iteration_s']:.0f} ms/iteration); thesis {THESIS_TIME[k]}{extra}.")
    m = fit["mean GRF RMSE (N)"]
    order = " < ".join(f"{lab.split(' ')[0]} {v:.1f} N" for lab, v in m.sort_values().items())
    out.append(f"Mean GRF RMSE, best first: {order}. Thesis (Sec 4.5, tangential / normal): (a) 36.5 / 234.6 N, "
               f"(b) 14.1 / 26.4 N, (c) 3.0 / 10.3 N.")
    ranked = ranking(fit)
    out.append(f"The thesis's ranking {' better than '.join(THESIS_RANKING)} "
               + ("holds on our data." if ranked == list(THESIS_RANKING) else f"does NOT hold on our data: {ranked}."))
    for k in ("b", "c"):
        lab = APPROACHES[k]
        out.append(f"{lab}: vertical GRF error per foot {consistency.loc[lab, 'achieved per foot, y (N)']:.1f} N, of "
                   f"which the kinematics force at least {consistency.loc[lab, 'floor per foot, y (N)']:.1f} N "
                   f"(total-force mismatch); tangential {consistency.loc[lab, 'achieved per foot, x (N)']:.1f} N vs a "
                   f"floor of {consistency.loc[lab, 'floor per foot, x (N)']:.1f} N. Share of the vertical squared "
                   "error in the data's swing: "
                   + ", ".join(f"{f} {by_phase.loc[(lab, f), 'share of squared error in swing (%)']:.0f} % "
                               f"(mean {by_phase.loc[(lab, f), 'mean simulated force in swing (N)']:.0f} N carried in swing)"
                               for f in ("right", "left")) + ".")
    for k, r in results.items():
        rr = residual_rms(r)
        out.append(f"{APPROACHES[k]}: pelvis residual RMS R_x {rr['R_x']:.1f} N, R_y {rr['R_y']:.1f} N, "
                   f"R_z {rr['R_z']:.2f} N·m (thesis Table 4.9: (a) 94.4 N, 349.0 N, 18.1 N·m; (b) 0).")
    mw = grf_fit({"c_wide": widened})["mean GRF RMSE (N)"].iloc[0]
    mb, c = m[APPROACHES["b"]], results["c"]
    out.append(f"With Table 4.7 widened to contain the thesis's (c) values, (c′) {widened.stats['status']} reaches a "
               f"mean GRF RMSE of {mw:.1f} N ({'better' if mw < mb else 'not better'} than (b)'s {mb:.1f} N), "
               f"objective {widened.stats['objective']:.4f} vs (c) {c.stats['objective']:.4f}.")
    out.append(f"(c) total body mass {ChildModel().total_mass(c.p_body):.2f} kg (thesis 41.80 kg); "
               f"{len(at_bounds(c))} of {len(c.p_contact) + len(c.p_body)} parameters at a bound.")
    return out
