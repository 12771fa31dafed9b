"""OpenSim Moco side of the T9-track benchmark (run with the Moco venv's python).

T9-track: torque-driven, 9-DOF, half gait cycle tracking of Moco's 2D walking example
(``2D_gait.osim``, ``referenceCoordinates.sto``). Configuration (see
``../README.md`` for the full list and the gaitlib twin in ``../t9track.py``):

* the 18 muscles and ``lumbarAct`` are deleted from a temporary copy of the XML (Moco's
  ``ModOpRemoveMuscles`` does not see muscles listed under ``<components>``);
  ``ModOpReplaceJointsWithWelds(["lumbar"])`` → 9 DOF; six ``CoordinateActuator`` s (hips,
  knees, ankles), optimal force 150 N·m, controls in [−1, 1];
* ``MocoTrack``: states reference ``referenceCoordinates.sto`` with ``TabOpLowPassFilter(6)``,
  global tracking weight 1, coordinate values *and* speeds tracked
  (``track_reference_position_derivatives``, as in Moco's example; without it the optimum
  is standing still, see ``../README.md``), control effort weight 10,
  ``apply_tracked_states_to_guess`` (reference values and spline-derivative speeds, zero
  controls), t ∈ [0, 0.470089] s fixed;
* ``MocoPeriodicityGoal`` as in Moco's example: q_r(0) = q_l(T) and q_l(0) = q_r(T) for the
  leg coordinates (values and speeds), pelvis tilt/ty values and all pelvis speeds periodic;
* state bounds as in the example (pelvis tilt [−20°, −10°], tx [0, 1] m, ty [0.75, 1.25] m,
  hips [−10°, 60°], knees [−50°, 0°], ankles [−15°, 25°]; speeds Moco's default [−50, 50]);
* ``MocoCasADiSolver``: 50 mesh intervals, scheme from ``--scheme``, convergence and
  constraint tolerance 1e-4, everything else as ``MocoTrack`` leaves it (explicit multibody
  dynamics, limited-memory Hessian, forward finite differences, parallel evaluation on all
  cores).

Writes ``<out>/moco_<scheme>.json`` (timings, iterations, objective and its terms, IPOPT
status and constraint violation, RMS per coordinate vs Moco's own reference spline) and
``<out>/moco_<scheme>.csv`` (the solution: time, q, qd, controls, SI units).

Other modes: ``--export-reference`` writes Moco's processed reference and its spline at
test times; ``--check-dynamics N`` writes OpenSim's accelerations and sphere forces at N
random states (used to check gaitlib's model of the same file).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import re
import resource
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
T_FINAL = 0.470089  # s, half gait cycle (the filtered reference ends at 0.47008934 s)
COORDS = {  # short name -> OpenSim joint/coordinate path
    "pelvis_tilt": "/jointset/groundPelvis/pelvis_tilt",
    "pelvis_tx": "/jointset/groundPelvis/pelvis_tx",
    "pelvis_ty": "/jointset/groundPelvis/pelvis_ty",
    "hip_flexion_l": "/jointset/hip_l/hip_flexion_l",
    "hip_flexion_r": "/jointset/hip_r/hip_flexion_r",
    "knee_angle_l": "/jointset/knee_l/knee_angle_l",
    "knee_angle_r": "/jointset/knee_r/knee_angle_r",
    "ankle_angle_l": "/jointset/ankle_l/ankle_angle_l",
    "ankle_angle_r": "/jointset/ankle_r/ankle_angle_r",
}
ACTUATED = ("hip_flexion_r", "hip_flexion_l", "knee_angle_r", "knee_angle_l",
            "ankle_angle_r", "ankle_angle_l")
OPTIMAL_FORCE = 150.0  # N·m per unit control
DEG = math.pi / 180.0
BOUNDS = {  # as in Moco's example2DWalking (rad, m)
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
SPEED_BOUNDS = (-50.0, 50.0)  # Moco's default speed bounds


def _import_opensim():
    import opensim as osim  # noqa: PLC0415 - only in the Moco venv

    osim.Logger.setLevelString("error")
    return osim


def torque_driven_model(osim, workdir: Path):
    """The T9 model: muscles and lumbarAct deleted, lumbar welded, 6 CoordinateActuators."""
    tree = ET.parse(HERE / "2D_gait.osim")
    comps = tree.getroot().find("Model/components")
    removed = []
    for c in list(comps):
        if c.tag.endswith("Muscle") or c.get("name") == "lumbarAct":
            comps.remove(c)
            removed.append(c.get("name"))
    tmp = workdir / "T9_no_muscles.osim"
    tree.write(tmp)
    proc = osim.ModelProcessor(str(tmp))
    proc.append(osim.ModOpReplaceJointsWithWelds(osim.StdVectorString(["lumbar"])))
    model = proc.process()
    for c in ACTUATED:
        a = osim.CoordinateActuator(c)
        a.setName(f"tau_{c}")
        a.setOptimalForce(OPTIMAL_FORCE)
        a.setMinControl(-1.0)
        a.setMaxControl(1.0)
        model.addForce(a)
    model.finalizeConnections()
    state = model.initSystem()
    n_act = model.getActuators().getSize()
    n_mus = model.getMuscles().getSize()
    if n_act != 6 or n_mus != 0 or state.getNQ() != 9:
        raise RuntimeError(f"T9 model check failed: {n_act} actuators, {n_mus} muscles, "
                           f"{state.getNQ()} coordinates")
    info = {"removed_components": removed, "n_actuators": n_act, "n_muscles": n_mus,
            "n_coordinates": state.getNQ(), "total_mass_kg": model.getTotalMass(state),
            "gravity": [model.getGravity()[i] for i in range(3)]}
    return model, info


def _parallel_setting(solver):
    try:
        return int(solver.get_parallel())
    except Exception:  # noqa: BLE001 - unset optional property
        return "default (all cores)"


def build_study(osim, model, scheme: str, n_mesh: int, tol: float, max_iter: int,
                parallel: int | None, workdir: Path, tracking_weight: float = 1.0,
                track_speeds: bool = True, effort_weight: float = 10.0,
                dynamics: str = "explicit"):
    track = osim.MocoTrack()
    track.setName("t9track")
    ref = osim.TableProcessor(str(HERE / "referenceCoordinates.sto"))
    ref.append(osim.TabOpLowPassFilter(6))
    track.setModel(osim.ModelProcessor(model))
    track.setStatesReference(ref)
    track.set_states_global_tracking_weight(tracking_weight)
    track.set_track_reference_position_derivatives(track_speeds)
    track.set_allow_unused_references(True)  # the reference's lumbar column
    track.set_apply_tracked_states_to_guess(True)
    track.set_minimize_control_effort(True)
    track.set_control_effort_weight(effort_weight)
    track.set_initial_time(0.0)
    track.set_final_time(T_FINAL)
    cwd = os.getcwd()
    os.chdir(workdir)  # MocoTrack writes t9track_tracked_states.sto into the cwd
    try:
        study = track.initialize()
    finally:
        os.chdir(cwd)
    problem = study.updProblem()

    # Periodicity as in Moco's example2DWalking (an endpoint constraint).
    sym = osim.MocoPeriodicityGoal("symmetryGoal")
    problem.addGoal(sym)
    proc_model = osim.Model(model)
    proc_model.initSystem()
    names = [proc_model.getStateVariableNames().getitem(i)
             for i in range(proc_model.getNumStateVariables())]
    pairs = []
    for s in names:
        if not s.startswith("/jointset"):
            continue
        if "_r/" in s:
            pairs.append((s, s.replace("_r/", "_l/")))
        elif "_l/" in s:
            pairs.append((s, s.replace("_l/", "_r/")))
        elif "pelvis_tx/value" not in s:
            pairs.append((s, s))
    for a, b in pairs:
        sym.addStatePair(osim.MocoPeriodicityGoalPair(a, b))

    for c, (lo, hi) in BOUNDS.items():
        problem.setStateInfo(f"{COORDS[c]}/value", [lo, hi])
    problem.setStateInfoPattern("/jointset/.*/speed", list(SPEED_BOUNDS))

    solver = osim.MocoCasADiSolver.safeDownCast(study.updSolver())
    solver.set_num_mesh_intervals(n_mesh)
    solver.set_transcription_scheme(scheme)
    solver.set_optim_convergence_tolerance(tol)
    solver.set_optim_constraint_tolerance(tol)
    solver.set_optim_max_iterations(max_iter)
    solver.set_verbosity(2)
    solver.set_multibody_dynamics_mode(dynamics)
    if parallel is not None:
        solver.set_parallel(parallel)
    config = {
        "transcription_scheme": solver.get_transcription_scheme(),
        "num_mesh_intervals": solver.get_num_mesh_intervals(),
        "multibody_dynamics_mode": solver.get_multibody_dynamics_mode(),
        "optim_hessian_approximation": solver.get_optim_hessian_approximation(),
        "optim_finite_difference_scheme": solver.get_optim_finite_difference_scheme(),
        "optim_sparsity_detection": solver.get_optim_sparsity_detection(),
        "optim_convergence_tolerance": solver.get_optim_convergence_tolerance(),
        "optim_constraint_tolerance": solver.get_optim_constraint_tolerance(),
        "optim_max_iterations": solver.get_optim_max_iterations(),
        "interpolate_control_mesh_interior_points":
            solver.get_interpolate_control_mesh_interior_points(),
        "parallel": _parallel_setting(solver),
        "OPENSIM_MOCO_PARALLEL": os.environ.get("OPENSIM_MOCO_PARALLEL"),
        "periodicity_pairs": pairs,
        "goals": {},
    }
    for gname in ("state_tracking", "control_effort", "symmetryGoal"):
        g = problem.getPhase(0).getGoal(gname)
        config["goals"][g.getName()] = {
            "type": g.getConcreteClassName(), "weight": g.getWeight(),
            "divide_by_duration": g.getDivideByDuration(),
            "divide_by_displacement": g.getDivideByDisplacement(),
            "divide_by_mass": g.getDivideByMass()}
    return study, config


class _CaptureFD:
    """Redirect the C-level stdout (IPOPT, CasADi, Moco print from C++) into a file."""

    def __init__(self, path: Path):
        self.path = path

    def __enter__(self):
        sys.stdout.flush()
        self._saved = os.dup(1)
        self._f = open(self.path, "w")
        os.dup2(self._f.fileno(), 1)
        return self

    def __exit__(self, *exc):
        sys.stdout.flush()
        try:
            import ctypes

            ctypes.CDLL(None).fflush(None)
        except Exception:  # noqa: BLE001
            pass
        os.dup2(self._saved, 1)
        os.close(self._saved)
        self._f.close()
        return False


def parse_ipopt_log(text: str) -> dict:
    """Numbers from IPOPT's and CasADi's console output."""
    out = {}
    m = re.findall(r"Total seconds in IPOPT\s*(?:\(w/o function evaluations\))?\s*=\s*([0-9.eE+-]+)",
                   text)
    if m:
        out["ipopt_total_seconds"] = float(m[-1])
    m = re.findall(r"Constraint violation\.*:\s*([0-9.eE+-]+)\s+([0-9.eE+-]+)", text)
    if m:
        out["constraint_violation_scaled"] = float(m[-1][0])
        out["constraint_violation_unscaled"] = float(m[-1][1])
    m = re.findall(r"Objective\.*:\s*([0-9.eE+-]+)\s+([0-9.eE+-]+)", text)
    if m:
        out["objective_unscaled"] = float(m[-1][1])
    m = re.findall(r"Number of Iterations\.*:\s*(\d+)", text)
    if m:
        out["iterations"] = int(m[-1])
    m = re.search(r"EXIT:\s*(.*)", text)
    if m:
        out["exit"] = m.group(1).strip()
    it0 = re.search(r"^\s*0\s+([0-9.eE+-]+)\s+([0-9.eE+-]+)\s+([0-9.eE+-]+)", text, re.M)
    if it0:
        out["iter0_objective"] = float(it0.group(1))
        out["iter0_inf_pr"] = float(it0.group(2))
        out["iter0_inf_du"] = float(it0.group(3))
    total = re.search(r"Total number of variables\.*:\s*(\d+)", text)
    if total:
        out["n_variables"] = int(total.group(1))
    eq = re.search(r"Total number of equality constraints\.*:\s*(\d+)", text)
    if eq:
        out["n_equality_constraints"] = int(eq.group(1))
    ineq = re.search(r"Total number of inequality constraints\.*:\s*(\d+)", text)
    if ineq:
        out["n_inequality_constraints"] = int(ineq.group(1))
    # CasADi's timing table: "      total  |  X s ( Y ms)  Z s ( W ms)   n" (t_proc, t_wall)
    tot = re.findall(r"^\s*total\s*\|\s*([0-9.]+)\s*(m?s)\s*\(.*?\)\s*([0-9.]+)\s*(m?s)", text, re.M)
    if tot:
        v, u = float(tot[-1][2]), tot[-1][3]
        out["casadi_t_wall_total"] = v / 1000.0 if u == "ms" else v
    fun = {}
    for name, v, u in re.findall(
            r"^\s*(nlp_f|nlp_g|nlp_grad_f|nlp_grad|nlp_jac_g|nlp_hess_l)\s*\|\s*[0-9.]+\s*m?s\s*\(.*?\)"
            r"\s*([0-9.]+)\s*(m?s)", text, re.M):
        fun[name] = float(v) / 1000.0 if u == "ms" else float(v)
    if fun:
        out["casadi_function_t_wall"] = fun
    uo = re.findall(r"^\s*(\w+)\s*=\s*(\S+)\s*$", text.split("List of user-set options:")[-1]
                    .split("*****")[0], re.M) if "List of user-set options:" in text else []
    if uo:
        out["ipopt_user_options"] = dict(uo)
    return out


def solve(args) -> dict:
    t_start = time.perf_counter()
    osim = _import_opensim()
    t_import = time.perf_counter() - t_start
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix="moco_t9_"))
    tag = args.scheme + ("" if args.dynamics == "explicit" else "_implicit")
    t0 = time.perf_counter()
    model, model_info = torque_driven_model(osim, work)
    study, config = build_study(osim, model, args.scheme, args.mesh, args.tol, args.max_iter,
                                args.parallel, work, args.tracking_weight, args.track_speeds,
                                args.effort_weight, args.dynamics)
    setup_time = time.perf_counter() - t0
    log_path = out / f"moco_{tag}_ipopt.log"
    # Moco exposes no generic IPOPT options; IPOPT itself reads ./ipopt.opt if present.
    extra = dict(args.ipopt or {})
    cwd = os.getcwd()
    os.chdir(work)
    if extra:
        (work / "ipopt.opt").write_text("".join(f"{k} {v}\n" for k, v in extra.items()))
    ru0 = resource.getrusage(resource.RUSAGE_SELF)
    t1 = time.perf_counter()
    try:
        with _CaptureFD(log_path):
            solution = study.solve()
    finally:
        wall_solve = time.perf_counter() - t1
        os.chdir(cwd)
    ru1 = resource.getrusage(resource.RUSAGE_SELF)
    log = log_path.read_text(errors="replace")
    parsed = parse_ipopt_log(log)

    success = bool(solution.success())
    status = solution.getStatus()
    if not success:
        solution.unseal()
    iters = int(solution.getNumIterations())
    objective = float(solution.getObjective())
    terms = {}
    try:
        for nm in solution.getObjectiveTermNames():
            terms[nm] = float(solution.getObjectiveTerm(nm))
    except Exception as e:  # noqa: BLE001
        terms["error"] = repr(e)

    # Trajectory (SI) and RMS against Moco's own reference spline.
    times = np.array(solution.getTimeMat()).ravel()
    states = solution.getStatesTrajectoryMat()
    controls = solution.getControlsTrajectoryMat()
    snames = list(solution.getStateNames())
    cnames = list(solution.getControlNames())
    S = np.array(states)
    C = np.array(controls)
    cols = {"time": times}
    for c, p in COORDS.items():
        cols[c] = S[:, snames.index(f"{p}/value")]
    for c, p in COORDS.items():
        cols[f"{c}_speed"] = S[:, snames.index(f"{p}/speed")]
    for c in ACTUATED:
        cols[f"tau_{c}"] = C[:, cnames.index(f"/forceset/tau_{c}")]
    header = ",".join(cols)
    np.savetxt(out / f"moco_{tag}.csv", np.column_stack(list(cols.values())), delimiter=",",
               header=header, comments="", fmt="%.17g")
    tracked = osim.TimeSeriesTable(str(work / "t9track_tracked_states.sto"))
    splines = osim.GCVSplineSet(tracked)
    rms = {}
    for c, p in COORDS.items():
        sp = splines.get(f"{p}/value")
        ref = np.array([sp.calcValue(osim.Vector(1, float(t))) for t in times])
        rms[c] = float(np.sqrt(np.mean((cols[c] - ref) ** 2)))

    result = {
        "tool": "opensim-moco",
        "opensim_version": osim.GetVersionAndDate(),
        "scheme": args.scheme,
        "tag": tag,
        "dynamics": args.dynamics,
        "success": success,
        "status": status,
        "iterations": iters,
        "setup_time": setup_time,
        "import_time": t_import,
        "solve_time": wall_solve,
        "solve_time_definition": "wall time of MocoStudy.solve() (builds Moco's CasADi "
                                 "problem, then runs IPOPT)",
        "solver_duration": float(solution.getSolverDuration()),
        "cpu_time_solve": (ru1.ru_utime - ru0.ru_utime) + (ru1.ru_stime - ru0.ru_stime),
        "time_per_iteration": wall_solve / max(iters, 1),
        "objective": objective,
        "objective_terms": terms,
        "max_violation": parsed.get("constraint_violation_unscaled"),
        "max_violation_definition": "IPOPT's final unscaled constraint violation",
        "rms": rms,
        "rms_units": "rad for angles, m for pelvis_tx/ty; vs Moco's GCVSpline of its "
                     "filtered reference at the solution's times",
        "ipopt": parsed,
        "ipopt_opt_file": extra,
        "model": model_info,
        "config": config,
        "machine": {"platform": platform.platform(), "processor": platform.processor(),
                    "cpu_count": os.cpu_count(), "python": sys.version.split()[0],
                    "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS"),
                    "OMP_NUM_THREADS": os.environ.get("OMP_NUM_THREADS")},
        "trajectory_csv": f"moco_{tag}.csv",
        "ipopt_log": log_path.name,
    }
    (out / f"moco_{tag}.json").write_text(json.dumps(result, indent=1))
    return result


def export_reference(args):
    """Moco's processed reference table and its spline values (for gaitlib's replication)."""
    osim = _import_opensim()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    tp = osim.TableProcessor(str(HERE / "referenceCoordinates.sto"))
    tp.append(osim.TabOpLowPassFilter(6))
    tab = tp.process()
    t = np.array(tab.getIndependentColumn())
    labels = list(tab.getColumnLabels())
    Y = np.array([tab.getDependentColumnAtIndex(k).to_numpy() for k in range(len(labels))]).T
    sp = osim.GCVSplineSet(tab)
    tq = np.linspace(0.0, T_FINAL, 201)
    V = np.array([[sp.get(k).calcValue(osim.Vector(1, float(x))) for k in range(sp.getSize())]
                  for x in tq])
    res = {"opensim_version": osim.GetVersionAndDate(), "labels": labels,
           "time": t.tolist(), "filtered": Y.tolist(), "spline_time": tq.tolist(),
           "spline_values": V.tolist()}
    (out / "moco_reference.json").write_text(json.dumps(res))
    print(f"wrote {out / 'moco_reference.json'}")


def check_dynamics(args):
    """OpenSim accelerations and sphere forces at random states (model-equivalence data)."""
    osim = _import_opensim()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix="moco_t9_"))
    model, info = torque_driven_model(osim, work)
    state = model.initSystem()
    rng = np.random.default_rng(args.seed)
    cs = model.getCoordinateSet()
    acts = [osim.CoordinateActuator.safeDownCast(model.getActuators().get(f"tau_{c}"))
            for c in ACTUATED]
    contacts = ["contactHeel_r", "contactHeel_l", "contactFront_r", "contactFront_l"]
    samples = []
    for k in range(args.check_dynamics):
        q = {c: float(rng.uniform(*BOUNDS[c])) for c in COORDS}
        # pelvis height so that some spheres touch the ground
        q["pelvis_ty"] = float(rng.uniform(0.80, 0.95))
        q["pelvis_tx"] = float(rng.uniform(0.0, 1.0))
        qd = {c: float(rng.normal(scale=0.5 if c in ("pelvis_tx", "pelvis_ty") else 2.0))
              for c in COORDS}
        u = {c: float(rng.uniform(-1, 1)) for c in ACTUATED}
        for c in COORDS:
            cs.get(c).setValue(state, q[c], False)
        for c in COORDS:
            cs.get(c).setSpeedValue(state, qd[c])
        for a, c in zip(acts, ACTUATED):
            a.overrideActuation(state, True)
            a.setOverrideActuation(state, OPTIMAL_FORCE * u[c])
        model.realizeAcceleration(state)
        qdd = {c: float(cs.get(c).getAccelerationValue(state)) for c in COORDS}
        forces = {}
        for nm in contacts:
            f = osim.SmoothSphereHalfSpaceForce.safeDownCast(model.getComponent(nm))
            vals = f.getRecordValues(state)
            forces[nm] = [vals.get(i) for i in range(vals.size())]
        samples.append({"q": q, "qd": qd, "u": u, "qdd": qdd, "sphere_record": forces})
    res = {"opensim_version": osim.GetVersionAndDate(), "model": info,
           "record_labels": "per sphere: force on sphere X Y Z, torque on sphere X Y Z, "
                            "force on half space X Y Z, torque on half space X Y Z "
                            "(ground frame, about body origins)",
           "samples": samples}
    (out / "moco_dynamics_check.json").write_text(json.dumps(res, indent=1))
    print(f"wrote {out / 'moco_dynamics_check.json'} ({len(samples)} states)")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scheme", choices=("trapezoidal", "hermite-simpson"),
                    default="trapezoidal")
    ap.add_argument("--mesh", type=int, default=50, help="mesh intervals (default 50)")
    ap.add_argument("--tol", type=float, default=1e-4, help="convergence and constraint "
                    "tolerance (default 1e-4)")
    ap.add_argument("--max-iter", type=int, default=1000)
    ap.add_argument("--parallel", type=int, default=None,
                    help="MocoCasADiSolver 'parallel' (default: Moco's default, all cores)")
    ap.add_argument("--tracking-weight", type=float, default=1.0)
    ap.add_argument("--track-speeds", action=argparse.BooleanOptionalAction, default=True,
                    help="also track the reference spline's derivatives (speeds), as Moco's "
                         "example does (track_reference_position_derivatives; default on)")
    ap.add_argument("--effort-weight", type=float, default=10.0)
    ap.add_argument("--dynamics", choices=("explicit", "implicit"), default="explicit",
                    help="multibody_dynamics_mode (MocoTrack sets 'explicit')")
    ap.add_argument("--ipopt", type=json.loads, default=None,
                    help="extra IPOPT options as JSON, written to ./ipopt.opt for the solve "
                         "(IPOPT reads that file; Moco has no generic option setter)")
    ap.add_argument("--out", default=str(HERE.parent / "results" / "moco_raw"))
    ap.add_argument("--export-reference", action="store_true")
    ap.add_argument("--check-dynamics", type=int, default=0, metavar="N")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    if args.export_reference:
        return export_reference(args)
    if args.check_dynamics:
        return check_dynamics(args)
    res = solve(args)
    print(json.dumps({k: res[k] for k in ("scheme", "success", "status", "iterations",
                                          "setup_time", "solve_time", "objective",
                                          "max_violation")}))


if __name__ == "__main__":
    main()
