"""gaitlib side of the T9-track benchmark: Moco's 2D walking tracking problem, torque-driven.

The same optimal control problem as ``moco/moco_side.py`` builds with OpenSim Moco, built
with gaitlib's own layers: the 9-DOF model is read from ``moco/2D_gait.osim`` by
:func:`moco.peers.osim_planar_model` (``moco/peers.py``: a gaitlib PlanarTree, Simbody's
smooth sphere contact), the reference is filtered and splined as Moco 4.6 does
(:func:`moco.peers.opensim_lowpass`, :class:`moco.peers.NaturalQuinticSpline`), and the
problem is transcribed and solved by :mod:`gaitlib.ocp` (exact Hessian, CasADi SX).

Problem (one phase, t ∈ [0, T], T = 0.470089 s)
------------------------------------------------
states    q (9: pelvis_tx, pelvis_ty, pelvis_tilt, hip/knee/ankle l/r; m, rad) and their
          speeds ``<name>_speed`` (m/s, rad/s)
controls  ``tau_<coordinate>`` ∈ [−1, 1] for the six leg joints; joint torque = 150 N·m × u
dynamics  explicit (as Moco's default): q̇ = speeds, speeds' = M⁻¹(τ + Q_contact − h);
          or ``--dynamics implicit``: accelerations are extra controls and the inverse
          dynamics residual is a path constraint
cost      w_track ∫ Σ_i (q_i − q_ref,i)² + (q̇_i − q̇_ref,i)² dt   (q̇_ref: the reference
          spline's derivative; ``--no-track-speeds`` drops the speed terms)
          + w_effort ∫ Σ_j u_j² dt           (Moco's MocoStateTrackingGoal/MocoControlGoal:
          no division by duration, mass or displacement; weights per state/control 1)
endpoints q_r(0) = q_l(T), q_l(0) = q_r(T) (values and speeds), pelvis tilt, ty and all
          pelvis speeds periodic (Moco's example2DWalking symmetry goal)
bounds    as in Moco's example; speeds ±50 (Moco's default)
mesh      50 intervals, trapezoidal or Hermite–Simpson (midpoint controls interpolated)
solver    IPOPT + MUMPS, tol = constr_viol_tol = 1e-4 with the same acceptable-level
          options Moco sets; exact Hessian; μ_init = 1e-3 (:data:`GAITLIB_IPOPT`;
          ``--ipopt-defaults`` keeps IPOPT's 0.1)
guess     Moco's ``apply_tracked_states_to_guess``: the filtered reference's rows placed at
          uniform times on [0, T], splined to the mesh; speeds the reference spline's
          derivative (zero with ``--no-track-speeds``), controls zero

Run ``python benchmarks/t9track.py --scheme trapezoidal`` (writes JSON + CSV like
``moco_side.py``); ``benchmarks/bench_moco_t9track.py`` runs both tools.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import platform
import resource
import sys
import time
from pathlib import Path

import casadi as ca
import numpy as np
import pandas as pd

from gaitlib import ocp
from gaitlib.collocation import Mesh

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:  # benchmarks/ (loaded by path from bench_moco_t9track.py)
    sys.path.insert(0, str(HERE))
from moco.peers import NaturalQuinticSpline, opensim_lowpass, osim_planar_model, read_sto  # noqa: E402
MOCO_DIR = HERE / "moco"
T_FINAL = 0.470089
OPTIMAL_FORCE = 150.0
ACTUATED = ("hip_flexion_r", "hip_flexion_l", "knee_angle_r", "knee_angle_l",
            "ankle_angle_r", "ankle_angle_l")
DEG = np.pi / 180.0
BOUNDS = {
    "pelvis_tilt": (-20 * DEG, -10 * DEG),
    "pelvis_tx": (0.0, 1.0),
    "pelvis_ty": (0.75, 1.25),
    "hip_flexion_l": (-10 * DEG, 60 * DEG),
    "hip_flexion_r": (-10 * DEG, 60 * DEG),
    "knee_angle_l": (-50 * DEG, 0.0),
    "knee_angle_r": (-50 * DEG, 0.0),
    "ankle_angle_l": (-15 * DEG, 25 * DEG),
    "ankle_angle_r": (-15 * DEG, 25 * DEG),
}
SPEED_BOUNDS = (-50.0, 50.0)
MOCO_PATHS = {  # coordinate -> column of referenceCoordinates.sto
    "pelvis_tilt": "/jointset/groundPelvis/pelvis_tilt/value",
    "pelvis_tx": "/jointset/groundPelvis/pelvis_tx/value",
    "pelvis_ty": "/jointset/groundPelvis/pelvis_ty/value",
    "hip_flexion_l": "/jointset/hip_l/hip_flexion_l/value",
    "hip_flexion_r": "/jointset/hip_r/hip_flexion_r/value",
    "knee_angle_l": "/jointset/knee_l/knee_angle_l/value",
    "knee_angle_r": "/jointset/knee_r/knee_angle_r/value",
    "ankle_angle_l": "/jointset/ankle_l/ankle_angle_l/value",
    "ankle_angle_r": "/jointset/ankle_r/ankle_angle_r/value",
}


def speed(c: str) -> str:
    return f"{c}_speed"


def reference():
    """Moco's processed reference: the 6 Hz filtered table (DataFrame, columns by coordinate)
    and its natural quintic spline (Moco's GCVSpline)."""
    raw = read_sto(MOCO_DIR / "referenceCoordinates.sto")
    filt = opensim_lowpass(raw, 6.0)
    filt = filt.rename(columns={v: k for k, v in MOCO_PATHS.items()})[list(MOCO_PATHS)]
    spline = NaturalQuinticSpline(filt.index.to_numpy(), filt.to_numpy())
    return filt, spline


#: gaitlib's IPOPT setting for this benchmark beyond Moco's: the solve starts at the tracked
#: reference (a near-optimal point), so the barrier parameter starts small (IPOPT default
#: 0.1). ``--ipopt-defaults`` drops it; the benchmark reports both (README).
GAITLIB_IPOPT = {"mu_init": 1e-3}


def ipopt_options(tol: float, max_iter: int, extra: dict | None = None) -> ocp.SolverOptions:
    """IPOPT settings equal to the ones Moco sets for optim_convergence_tolerance and
    optim_constraint_tolerance = tol (MocoCasADiSolver; printed as user options in its log)."""
    ip = {"dual_inf_tol": tol, "compl_inf_tol": tol, "acceptable_tol": tol,
          "acceptable_dual_inf_tol": tol, "acceptable_compl_inf_tol": tol,
          "acceptable_constr_viol_tol": tol}
    ip.update(extra or {})
    return ocp.SolverOptions(tol=tol, constr_viol_tol=tol, max_iter=max_iter, ipopt=ip)


def build(scheme: str = "trapezoidal", n_mesh: int = 50, tracking_weight: float = 1.0,
          track_speeds: bool = True, effort_weight: float = 10.0,
          dynamics: str = "explicit"):
    """The T9-track problem: ``(problem, mesh, guess, model, reference)``."""
    model = osim_planar_model(MOCO_DIR / "2D_gait.osim", weld=("lumbar",))
    coords = tuple(MOCO_PATHS)
    states = coords + tuple(speed(c) for c in coords)
    controls = tuple(f"tau_{c}" for c in ACTUATED)
    acc_names = tuple(f"{c}_acc" for c in coords)
    if dynamics == "implicit":
        controls = controls + acc_names
    mesh = Mesh(n_mesh, scheme)
    filt, spline = reference()

    fd = model.function("forward_dynamics")
    idyn = model.function("inverse_dynamics")
    act_idx = [model.coord_index(c) for c in ACTUATED]

    def q_of(x):
        return ca.vertcat(*[x[c] for c in model.coords])

    def qd_of(x):
        return ca.vertcat(*[x[speed(c)] for c in model.coords])

    def tau_of(u):
        tau = [0.0] * model.n
        for c, i in zip(ACTUATED, act_idx):
            tau[i] = OPTIMAL_FORCE * u[f"tau_{c}"]
        return ca.vertcat(*tau)

    if dynamics == "explicit":
        def f(x, u, p, t):
            qdd = fd(q_of(x), qd_of(x), tau_of(u))
            acc = {c: qdd[i] for i, c in enumerate(model.coords)}
            return ca.vertcat(*[x[speed(c)] for c in coords], *[acc[c] for c in coords])
        path = ()
    elif dynamics == "implicit":
        def f(x, u, p, t):
            return ca.vertcat(*[x[speed(c)] for c in coords], *[u[f"{c}_acc"] for c in coords])

        def residual(x, u, p, t):
            qdd = ca.vertcat(*[u[f"{c}_acc"] for c in model.coords])
            return idyn(q_of(x), qd_of(x), qdd) - tau_of(u)
        path = (ocp.PathConstraint("multibody", residual, 0.0, 0.0),)
    else:
        raise ValueError(f"dynamics must be 'explicit' or 'implicit', got {dynamics!r}")

    # Reference at the collocation nodes (Moco evaluates its spline at the mesh points).
    tc = mesh.tau_colloc * T_FINAL
    data = {f"ref_{c}": spline(tc)[:, j] for j, c in enumerate(coords)}
    if track_speeds:
        # Moco appends the spline's derivative at the table times as speed columns and
        # splines those columns again (MocoTrack::configureStateTracking).
        tt = filt.index.to_numpy()
        dv = NaturalQuinticSpline(tt, spline(tt, 1))(tc)
        data.update({f"ref_{speed(c)}": dv[:, j] for j, c in enumerate(coords)})
    data = pd.DataFrame(data, index=pd.Index(mesh.tau_colloc, name="tau"))

    tracked = coords + (tuple(speed(c) for c in coords) if track_speeds else ())

    def tracking(x, u, p, t, d):
        return sum((x[s] - d[f"ref_{s}"]) ** 2 for s in tracked)

    def effort(x, u, p, t):
        return sum(u[f"tau_{c}"] ** 2 for c in ACTUATED)

    # Symmetry (Moco's MocoPeriodicityGoal pairs): final of one = initial of the other.
    pairs = []
    for c in coords:
        side = c[-2:]
        partner = c[:-2] + {"_r": "_l", "_l": "_r"}[side] if side in ("_r", "_l") else c
        if c != "pelvis_tx":
            pairs.append((c, partner))
        pairs.append((speed(c), speed(partner)))

    def symmetry(x0, xf, p, t0, tf):
        return ca.vertcat(*[xf[b] - x0[a] for a, b in pairs])

    bounds = {c: BOUNDS[c] for c in coords}
    bounds.update({speed(c): SPEED_BOUNDS for c in coords})
    bounds.update({f"tau_{c}": (-1.0, 1.0) for c in ACTUATED})
    if dynamics == "implicit":
        bounds.update({a: (-1000.0, 1000.0) for a in acc_names})  # Moco's implicit bounds

    phase = ocp.Phase(
        name="walk", states=states, controls=controls, dynamics=f, t0=0.0, tf=T_FINAL,
        bounds=bounds, path_constraints=path,
        endpoint_constraints=(ocp.EndpointConstraint("symmetry", symmetry),),
        goals=(ocp.Goal("state_tracking", tracking_weight, integrand=tracking),
               ocp.Goal("control_effort", effort_weight, integrand=effort)),
        data=data,
    )
    problem = ocp.Problem((phase,), name="t9track")

    # Guess as Moco's apply_tracked_states_to_guess: table rows at uniform times on [0, T].
    tg = np.linspace(0.0, T_FINAL, len(filt))
    gspline = NaturalQuinticSpline(tg, filt.to_numpy())
    tn = mesh.tau * T_FINAL
    gq = gspline(tn)
    gstates = {c: gq[:, j] for j, c in enumerate(coords)}
    if track_speeds:
        dref = spline(filt.index.to_numpy(), 1)  # the speed columns Moco appends
        gd = NaturalQuinticSpline(tg, dref)(tn)
        gstates.update({speed(c): gd[:, j] for j, c in enumerate(coords)})
    else:
        gstates.update({speed(c): np.zeros_like(tn) for c in coords})
    guess = ocp.Guess({"walk": ocp.PhaseGuess(
        time=tn, states=gstates, controls=None, t0=0.0, tf=T_FINAL)})
    return problem, mesh, guess, model, (filt, spline)


def rms_vs_reference(states: pd.DataFrame, spline) -> dict:
    """RMS (rad or m) of each coordinate against the reference spline at the state nodes."""
    t = np.asarray(states.index, dtype=float)
    ref = spline(t)
    return {c: float(np.sqrt(np.mean((states[c].to_numpy() - ref[:, j]) ** 2)))
            for j, c in enumerate(MOCO_PATHS)}


def evaluate_trajectory(csv_path, scheme: str, n_mesh: int = 50, tracking_weight: float = 1.0,
                        track_speeds: bool = True, effort_weight: float = 10.0) -> dict:
    """gaitlib's NLP (explicit dynamics) evaluated at a trajectory written by either tool.

    The CSV must hold the mesh's state nodes (Moco writes exactly those). Returns the
    objective and its terms and the largest violation per constraint kind — for Moco's
    solution this checks that both tools pose the same problem (same cost, same dynamics).
    """
    problem, mesh, guess, model, _ = build(scheme, n_mesh, tracking_weight, track_speeds,
                                           effort_weight, "explicit")
    traj = pd.read_csv(csv_path)
    t = traj["time"].to_numpy()
    if len(t) != mesh.n_state_nodes or np.max(np.abs(t - mesh.tau * T_FINAL)) > 1e-9:
        raise ValueError(f"{csv_path}: times do not match the {mesh.describe()} mesh")
    tr = ocp.transcribe(problem, mesh, ocp.SolverOptions(graph="mx", expand=False))
    lay = tr.layouts["walk"]
    w = np.zeros(tr.n_variables)
    ph = problem.phases[0]
    for i, name in enumerate(ph.states):
        col = name if not name.endswith("_speed") else name
        w[lay.ix[i]] = traj[col].to_numpy()
    for i, name in enumerate(ph.controls):
        w[lay.iu[i]] = traj[name].to_numpy()[mesh.colloc_state_nodes]
    p = np.concatenate([tr.data_vector(), tr.goal_weights()])
    g = np.asarray(ca.Function("g", [tr.w, tr.nlp["p"]], [tr.g])(w, p)).ravel()
    viol = np.maximum(np.maximum(tr.lbg - g, g - tr.ubg), 0.0)
    kinds = {}
    for blk in tr.blocks:
        kind = blk.name.split("/")[-1].split("[")[0]
        kinds[kind] = max(kinds.get(kind, 0.0), float(viol[blk.start:blk.start + blk.size].max()))
    bound_viol = float(np.max(np.maximum(np.maximum(tr.lbw - w, w - tr.ubw), 0.0)))
    terms = np.asarray(tr._goal_fun(w, p)).ravel() * tr.goal_weights()
    return {"objective": float(terms.sum()),
            "objective_terms": {name: float(v) for (_, name, _), v in zip(tr.goal_rows, terms)},
            "max_violation_by_kind": kinds, "max_bound_violation": bound_viol}


def run(args) -> dict:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    tag = args.tag or (args.scheme + ("" if args.dynamics == "explicit" else "_implicit")
                       + ("_ipoptdefaults" if args.ipopt_defaults else "")
                       + ("" if args.graph == "sx" else "_" + args.graph)
                       + ("_nodes" if args.graph == "sx" and args.derivatives == "nodes" else "")
                       + ("_compiled" if args.compiled else ""))
    log_path = out / f"gaitlib_{tag}_ipopt.log"
    t0 = time.perf_counter()
    problem, mesh, guess, model, (filt, spline) = build(
        args.scheme, args.mesh, args.tracking_weight, args.track_speeds, args.effort_weight,
        args.dynamics)
    t_problem = time.perf_counter() - t0
    extra = {} if args.ipopt_defaults else dict(GAITLIB_IPOPT)
    extra.update({"output_file": str(log_path), "file_print_level": 5,
                  "print_user_options": "yes"})
    extra.update(dict(args.ipopt or {}))
    opts = ipopt_options(args.tol, args.max_iter, extra)
    if args.graph == "mx-noexpand":
        opts = dataclasses.replace(opts, graph="mx", expand=False)
    opts = dataclasses.replace(opts, derivatives=args.derivatives, compiled=args.compiled)
    tr = ocp.transcribe(problem, mesh, opts)
    setup_time = time.perf_counter() - t0
    w0 = tr.initial_point(guess)
    pvec = np.concatenate([tr.data_vector(), tr.goal_weights()])
    f0 = float(ca.Function("f", [tr.w, tr.nlp["p"]], [tr.nlp["f"]])(w0, pvec))
    ru0 = resource.getrusage(resource.RUSAGE_SELF)
    sol = tr.solve(guess)
    ru1 = resource.getrusage(resource.RUSAGE_SELF)
    stats = tr.solver.stats()
    st = sol.states
    cols = {"time": np.asarray(st.index, float)}
    for c in MOCO_PATHS:
        cols[c] = st[c].to_numpy()
    for c in MOCO_PATHS:
        cols[f"{c}_speed"] = st[speed(c)].to_numpy()
    ctrl = sol.controls
    for c in ACTUATED:
        cols[f"tau_{c}"] = np.interp(cols["time"], np.asarray(ctrl.index, float),
                                     ctrl[f"tau_{c}"].to_numpy())
    pd.DataFrame(cols).to_csv(out / f"gaitlib_{tag}.csv", index=False, float_format="%.17g")
    fun_t = {k[len("t_wall_"):]: float(v) for k, v in stats.items()
             if k.startswith("t_wall_nlp_") and isinstance(v, (int, float))}
    res = {
        "tool": "gaitlib",
        "scheme": args.scheme,
        "tag": tag,
        "ipopt_extra": {k: v for k, v in extra.items() if k not in ("output_file",
                                                                     "file_print_level",
                                                                     "print_user_options")},
        "dynamics": args.dynamics,
        "graph": args.graph,
        "success": sol.success,
        "status": sol.status,
        "iterations": sol.iterations,
        "setup_time": setup_time,
        "setup_breakdown": {"model_problem": t_problem, "symbolic_nlp": tr.symbolic_time,
                            "nlpsol": tr.build_time - tr.symbolic_time},
        "solve_time": sol.solve_time,
        "solve_time_definition": "wall time of the IPOPT call (Transcription.solve)",
        "function_t_wall": fun_t,
        "cpu_time_solve": (ru1.ru_utime - ru0.ru_utime) + (ru1.ru_stime - ru0.ru_stime),
        "time_per_iteration": sol.solve_time / max(sol.iterations, 1),
        "objective": sol.objective,
        "objective_terms": {r["goal"]: float(r["weighted"]) for _, r in sol.goals.iterrows()},
        "objective_at_guess": f0,
        "max_violation": sol.max_violation,
        "worst_constraint": sol.worst_constraint,
        "max_violation_definition": "largest violation of any constraint or bound at the "
                                    "returned point",
        "rms": rms_vs_reference(st, spline),
        "rms_units": "rad for angles, m for pelvis_tx/ty; vs the reference spline at the "
                     "state nodes",
        "n_variables": tr.n_variables,
        "n_constraints": tr.n_constraints,
        "model": {"total_mass_kg": model.total_mass(), "gravity": model.gravity,
                  "welded": list(model.welded), "n_coordinates": model.n},
        "config": {"mesh": mesh.describe(), "tol": args.tol, "max_iter": args.max_iter,
                   "tracking_weight": args.tracking_weight, "track_speeds": args.track_speeds,
                   "effort_weight": args.effort_weight,
                   "ipopt": {k: (str(v) if not isinstance(v, (int, float)) else v)
                             for k, v in opts.nlpsol_options()["ipopt"].items()}},
        "machine": {"platform": platform.platform(), "cpu_count": os.cpu_count(),
                    "python": sys.version.split()[0], "casadi": ca.__version__,
                    "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS"),
                    "OMP_NUM_THREADS": os.environ.get("OMP_NUM_THREADS")},
        "trajectory_csv": f"gaitlib_{tag}.csv",
        "ipopt_log": log_path.name,
    }
    (out / f"gaitlib_{tag}.json").write_text(json.dumps(res, indent=1, default=str))
    return res


def main(argv=None):
    ap = argparse.ArgumentParser(description="gaitlib side of T9-track")
    ap.add_argument("--scheme", choices=("trapezoidal", "hermite-simpson"),
                    default="trapezoidal")
    ap.add_argument("--mesh", type=int, default=50)
    ap.add_argument("--tol", type=float, default=1e-4)
    ap.add_argument("--max-iter", type=int, default=1000)
    ap.add_argument("--tracking-weight", type=float, default=1.0)
    ap.add_argument("--track-speeds", action=argparse.BooleanOptionalAction, default=True,
                    help="also track the reference spline's derivatives (speeds), as Moco's "
                         "example does (track_reference_position_derivatives; default on)")
    ap.add_argument("--effort-weight", type=float, default=10.0)
    ap.add_argument("--dynamics", choices=("explicit", "implicit"), default="explicit")
    ap.add_argument("--ipopt", type=json.loads, default=None,
                    help='extra IPOPT options as JSON, e.g. \'{"linear_solver": "spral"}\'')
    ap.add_argument("--ipopt-defaults", action="store_true",
                    help=f"do not add gaitlib's benchmark IPOPT setting {GAITLIB_IPOPT}")
    ap.add_argument("--graph", choices=("sx", "mx-noexpand"), default="sx",
                    help="NLP graph: one SX graph (default) or MX with mapped per-node calls, "
                         "not expanded (fast to build, slower to evaluate)")
    ap.add_argument("--derivatives", choices=("graph", "nodes"), default=ocp.DEFAULT_DERIVATIVES,
                    help="with --graph sx: CasADi's derivatives of the whole NLP graph, or per-node "
                         "derivative functions assembled by the chain rule (fast to build)")
    ap.add_argument("--compiled", action="store_true",
                    help="with --derivatives nodes: per-node functions as compiled C (gaitlib.compiled; "
                         "the same numbers as the SX virtual machine)")
    ap.add_argument("--tag", default=None, help="output file stem (default from options)")
    ap.add_argument("--out", default=str(HERE / "results" / "moco_raw"))
    args = ap.parse_args(argv)
    res = run(args)
    print(json.dumps({k: res[k] for k in ("scheme", "success", "status", "iterations",
                                          "setup_time", "solve_time", "objective",
                                          "max_violation")}))


if __name__ == "__main__":
    main()
