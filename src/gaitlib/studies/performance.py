"""The Performance page's readers: the stored benchmark results as tables, figures and
findings, and the growth-exponent fit.

Nothing here solves or times anything: the functions read the JSON files that the scripts in
``benchmarks/`` write (``scaling.json`` — :file:`benchmarks/bench_scaling.py`, ``gait.json``
— :file:`benchmarks/bench_gait.py`, ``moco_t9track.json`` —
:file:`benchmarks/bench_moco_t9track.py`, ``thesis_times.json`` —
:file:`benchmarks/bench_thesis_times.py`, and the profiles of the MSK solve and the KKT
system), each of which records when and on which machine it was measured. The writers
(timing, machine, report files, the thesis's reference times) live with the scripts in
``benchmarks/``.

Functions
---------
:func:`results_dir`        where the benchmark results are (``benchmarks/results``).
:func:`load`, :func:`load_optional`  one results file as a dict.
:func:`fit_power_law`      least-squares fit of ``y = c · n^b`` on log–log axes.
:func:`scaling_table`      per model × mesh: iterations, wall times, time per iteration.
:func:`scaling_fits`       the growth exponents of time per iteration (and its parts) vs nodes.
:func:`scaling_figure`     time per iteration, solve and build time vs nodes, with the fits.
:func:`hessian_table`, :func:`linear_solver_table`, :func:`moco_table`, :func:`gait_table`,
:func:`msk_profile_tables`, :func:`eval_floor_table`, :func:`eval_floor_frames`,
:func:`kkt_scaling_tables`
:func:`measured_on`        one sentence: date, machine, load, from a file's metadata.
:func:`thesis_times_table`, :func:`thesis_times_summary`, :func:`thesis_times_by_chapter`,
:func:`thesis_times_figure`  the stored thesis-times table.

Findings (lists of sentences, computed from the results; the targets are the constants below):
:func:`msk_profile_findings`, :func:`eval_floor_findings`, :func:`compiled_solve_finding`,
:func:`thesis_times_findings`, :func:`mumps_orderings_findings`, :func:`findings` (the
page's summary: scaling per model, the machine's share, the KKT system at a fixed point, its
fill, the thesis mesh, Hessian, linear solvers, Moco).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = ["results_dir", "load", "load_optional", "fit_power_law", "scaling_table", "scaling_fits",
           "scaling_figure", "hessian_table", "linear_solver_table", "moco_table", "gait_table",
           "msk_profile_tables", "eval_floor_table", "eval_floor_frames", "kkt_scaling_tables", "measured_on",
           "NOT_COMPUTED", "NO_CACHE", "FINISHED", "thesis_times_table", "thesis_times_summary",
           "thesis_times_by_chapter", "thesis_times_figure", "LINEAR_GROWTH", "LINEAR_TOLERANCE",
           "MSK_SOLVE_TARGET_S", "CONVERGED", "THESIS_MESH_NODES", "MUMPS_AUTO_ORDERING",
           "SAME_OBJECTIVE_RTOL", "msk_profile_findings", "eval_floor_findings", "compiled_solve_finding",
           "thesis_times_findings", "mumps_orderings_findings", "fatrop_table", "fatrop_findings", "defect_form_findings", "book_budget_table",
           "book_budget_findings", "book_floor_s", "BOOK_TARGET_S", "workers_table", "workers_findings", "warm_chain_table",
           "warm_chain_findings", "targets_table", "findings"]

#: Runs of the scaling benchmark whose time per iteration is a measurement (the solver ran
#: to the end: converged or stopped by its own criterion), as opposed to "timeout"/"error".
FINISHED = "finished"

#: The target of the mesh-scaling study: time per iteration grows no faster than linearly
#: with the number of collocation nodes N (exponent b of ``t ∝ N^b`` at most 1).
LINEAR_GROWTH = 1.0
#: Work that is proportional to N by construction (the NLP evaluations at a fixed point) is
#: read as linear up to an exponent of ``LINEAR_GROWTH + LINEAR_TOLERANCE``.
LINEAR_TOLERANCE = 0.02
#: The target for the MSK data-tracking solve at the full mesh (s), met only by a run that
#: converged (:data:`CONVERGED`).
MSK_SOLVE_TARGET_S = 20.0
#: Issue 22's target 1: the whole book from an empty cache on this 2-core machine (s).
BOOK_TARGET_S = 45 * 60
#: The IPOPT status of a converged run in the profiles.
CONVERGED = "Solve_Succeeded"
#: Collocation nodes of the thesis's mesh (20 intervals × 5 LGR points).
THESIS_MESH_NODES = 100
#: ``mumps_pivot_order`` value of IPOPT's default: MUMPS chooses the ordering itself.
MUMPS_AUTO_ORDERING = 7
#: Two solves of the same problem end in the same solution when they take the same
#: iterations and their objectives agree to this relative tolerance.
SAME_OBJECTIVE_RTOL = 1e-6

#: Status of a thesis-times row whose optimisation is not in the cache (``--cached-only``).
NOT_COMPUTED = "not computed yet"
#: Status of a thesis-times row of a study that has no solution cache.
NO_CACHE = "not measured (no solution cache)"


def results_dir() -> Path:
    """``$GAITLIB_BENCHMARK_RESULTS`` if set, else ``benchmarks/results`` of the source
    checkout this package is imported from."""
    if os.environ.get("GAITLIB_BENCHMARK_RESULTS"):
        return Path(os.environ["GAITLIB_BENCHMARK_RESULTS"])
    here = Path(__file__).resolve()
    for parent in here.parents:
        cand = parent / "benchmarks" / "results"
        if cand.is_dir():
            return cand
    raise FileNotFoundError("benchmarks/results not found above " + str(here) +
                            " (gaitlib must be used from its source checkout to read the benchmarks)")


def load(name: str, root=None) -> dict:
    """The results file ``<name>.json`` (e.g. ``"scaling"``, ``"gait"``, ``"moco_t9track"``)."""
    path = Path(root) if root is not None else results_dir()
    f = path / f"{name}.json"
    if not f.is_file():
        raise FileNotFoundError(f"{f}: benchmark results missing — run benchmarks/bench_{name}.py")
    return json.loads(f.read_text())


def load_optional(name: str, root=None) -> dict | None:
    """:func:`load`, or ``None`` (with the reason printed) when the results file is missing —
    for page sections whose benchmark may not have been run yet."""
    try:
        return load(name, root)
    except FileNotFoundError as e:
        print(e)
        return None


def fit_power_law(n, y) -> dict:
    """Fit ``y = c · n^b`` by least squares on ``log y = log c + b log n``.

    Returns ``{"exponent": b, "prefactor": c, "r2": R², "n_points": k, "exponent_se": standard
    error of b}`` (NaN entries with fewer than two points; ``exponent_se`` NaN with two).
    A time per iteration growing no worse than linearly with the number of nodes has
    ``b ≤ 1``.
    """
    n, y = np.asarray(n, float), np.asarray(y, float)
    ok = np.isfinite(n) & np.isfinite(y) & (n > 0) & (y > 0)
    n, y = n[ok], y[ok]
    k = len(n)
    if k < 2 or np.ptp(n) == 0:
        return {"exponent": np.nan, "prefactor": np.nan, "r2": np.nan, "n_points": k, "exponent_se": np.nan}
    X = np.column_stack([np.ones(k), np.log(n)])
    coef, *_ = np.linalg.lstsq(X, np.log(y), rcond=None)
    res = np.log(y) - X @ coef
    ss_tot = float(np.sum((np.log(y) - np.log(y).mean()) ** 2))
    r2 = 1.0 - float(np.sum(res ** 2)) / ss_tot if ss_tot > 0 else np.nan
    se = np.nan
    if k > 2:
        s2 = float(np.sum(res ** 2)) / (k - 2)
        se = float(np.sqrt(s2 * np.linalg.inv(X.T @ X)[1, 1]))
    return {"exponent": float(coef[1]), "prefactor": float(np.exp(coef[0])), "r2": r2, "n_points": k,
            "exponent_se": se}


def _runs(res: dict, group: str) -> pd.DataFrame:
    rows = [r for r in res["runs"] if r.get("group") == group]
    return pd.DataFrame(rows)


def scaling_table(res: dict | None = None) -> pd.DataFrame:
    """Mesh-scaling runs (exact Hessian, MUMPS): one row per model × mesh, times in s and
    ms per iteration."""
    res = load("scaling") if res is None else res
    df = _runs(res, "mesh")
    cols = ["model", "n_intervals", "degree", "nodes", "n_variables", "status", "iterations", "solve_s",
            "ms_per_iteration", "function_evals_ms_per_iteration", "ipopt_rest_ms_per_iteration", "build_s",
            "setup_s", "objective", "max_violation", "peak_rss_mb", "loadavg_start"]
    out = df[[c for c in cols if c in df.columns]].reset_index(drop=True)
    if "loadavg_start" in out:  # the 1-minute load average when the run started
        out["loadavg_start"] = [v[0] if isinstance(v, (list, tuple)) else v for v in out["loadavg_start"]]
        out = out.rename(columns={"loadavg_start": "load (1 min) at start"})
    return out


def scaling_fits(res: dict | None = None) -> pd.DataFrame:
    """Per model: the fitted exponent b of ``quantity ∝ nodes^b`` for time per iteration
    (and its function-evaluation and IPOPT/MUMPS parts), iterations, solve and build time —
    over the runs that finished (converged or stopped by IPOPT itself)."""
    res = load("scaling") if res is None else res
    df = _runs(res, "mesh")
    rows = []
    if df.empty:
        return pd.DataFrame(rows)
    for model, g in df[df["outcome"] == FINISHED].groupby("model", sort=False):
        for q, label in (("ms_per_iteration", "time per iteration"),
                         ("function_evals_ms_per_iteration", "function evaluations per iteration"),
                         ("ipopt_rest_ms_per_iteration", "IPOPT + MUMPS per iteration"),
                         ("iterations", "iterations"), ("solve_s", "solve time"), ("build_s", "build time")):
            f = fit_power_law(g["nodes"], g[q])
            rows.append({"model": model, "quantity": label, "exponent": f["exponent"], "±": f["exponent_se"],
                         "R²": f["r2"], "points": f["n_points"],
                         "nodes": ", ".join(str(int(v)) for v in sorted(g["nodes"]))})
    return pd.DataFrame(rows)


def hessian_table(res: dict | None = None) -> pd.DataFrame:
    """Exact Hessian vs limited-memory (L-BFGS) on the same problem and mesh."""
    res = load("scaling") if res is None else res
    df = _runs(res, "hessian")
    cols = ["model", "n_intervals", "degree", "hessian", "outcome", "status", "iterations", "solve_s",
            "ms_per_iteration", "build_s", "objective", "max_violation", "measured_in"]
    return df[[c for c in cols if c in df.columns]].reset_index(drop=True)


def linear_solver_table(res: dict | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(availability of each IPOPT linear solver in this casadi build, with the loading
    error; timings of the loadable ones on the same problem)."""
    res = load("scaling") if res is None else res
    avail = pd.DataFrame(res.get("linear_solvers_available", []))
    df = _runs(res, "linear_solver")
    cols = ["model", "n_intervals", "degree", "linear_solver", "outcome", "status", "iterations", "solve_s",
            "ms_per_iteration", "function_evals_ms_per_iteration", "ipopt_rest_ms_per_iteration", "objective",
            "measured_in"]
    return avail, df[[c for c in cols if c in df.columns]].reset_index(drop=True)


def moco_table(res: dict | None = None) -> pd.DataFrame:
    """T9-track, gaitlib vs OpenSim Moco: per scheme the medians of solve time and the
    speed-up (Moco / gaitlib), also with IPOPT's default options, with per-node derivatives
    compiled, and against the fastest gaitlib variant that converged in every repeat; end to
    end (setup + solve) likewise. Columns of variants a results file lacks are NaN."""
    res = load("moco_t9track") if res is None else res
    rows = []
    for scheme, s in res["speedups"].items():
        e2e = s.get("end_to_end_median", {})
        rows.append({"scheme": scheme, "Moco solve (s)": s["moco_solve_median"],
                     "gaitlib solve (s)": s["gaitlib_solve_median"], "speed-up": s["speedup"],
                     "speed-up, gaitlib with IPOPT defaults": s.get("speedup_ipopt_defaults", np.nan),
                     "speed-up, gaitlib per-node compiled": s.get("speedup_nodes_compiled", np.nan),
                     "speed-up, solve (best converged gaitlib variant)": s.get("speedup_best", {}).get("speedup", np.nan),
                     "Moco setup + solve (s)": e2e.get("moco", np.nan),
                     "gaitlib setup + solve (s)": e2e.get("gaitlib", np.nan),
                     "gaitlib per-node derivatives, setup + solve (s)":
                         e2e.get("gaitlib (per-node derivatives)", np.nan),
                     "gaitlib per-node compiled, setup + solve (s)":
                         e2e.get("gaitlib (per-node derivatives, compiled)", np.nan),
                     "speed-up, setup + solve (best converged gaitlib variant)":
                         s.get("speedup_e2e", {}).get("speedup", np.nan),
                     "all converged": s.get("all_succeeded")})
    return pd.DataFrame(rows)


def gait_table(res: dict | None = None) -> pd.DataFrame:
    """The full-mesh natural-gait solves of ``bench_gait.py`` (thesis times beside, labelled)."""
    res = load("gait") if res is None else res
    cols = ["run", "status", "iterations", "solve_s", "ms_per_iteration", "function_evals_s", "ipopt_rest_s",
            "build_s", "objective", "thesis"]
    df = pd.DataFrame(res["rows"])
    return df[[c for c in cols if c in df.columns]].rename(columns={"thesis": "thesis time (GPOPS-II, labelled)"})


def build_table(res: dict) -> pd.DataFrame:
    """``bench_build.py``: per model and derivative path ("graph": CasADi differentiates the
    whole NLP graph; "nodes": per-node derivative functions assembled by the chain rule),
    the build split (problem, symbolic NLP, solver with derivatives; s), the solve (status,
    iterations, s, ms per iteration, evaluations vs IPOPT's rest) and end to end (s)."""
    cols = {"model": "model", "derivatives": "derivatives", "problem_s": "problem (s)", "symbolic_s": "symbolic NLP (s)",
            "solver_s": "solver + derivatives (s)", "build_s": "build (s)", "status": "status",
            "iterations": "iterations", "solve_s": "solve (s)", "ms_per_iteration": "ms / iteration",
            "evals_s": "evaluations (s)", "ipopt_rest_s": "IPOPT rest (s)", "e2e_s": "build + solve (s)",
            "objective": "objective"}
    df = pd.DataFrame(res["rows"])
    return df[[c for c in cols if c in df.columns]].rename(columns=cols)


def build_findings(res: dict) -> list[str]:
    """What ``bench_build.py`` measured, in sentences computed from its rows: the build
    speed-up per model, per-iteration evaluation cost of both paths and end to end."""
    df = pd.DataFrame(res["rows"])
    out = []
    for model, g in df.groupby("model", sort=False):
        a, b = (g[g.derivatives == d].iloc[0] if (g.derivatives == d).any() else None for d in ("graph", "nodes"))
        if a is None or b is None:
            continue
        line = (f"{model}: build {a.build_s:.1f} s with whole-graph derivatives, {b.build_s:.1f} s with per-node "
                f"derivatives ({a.build_s / b.build_s:.0f}× faster)")
        if "solve_s" in g and pd.notna(a.get("solve_s")) and pd.notna(b.get("solve_s")):
            ea, eb = 1e3 * a.evals_s / max(a.iterations, 1), 1e3 * b.evals_s / max(b.iterations, 1)
            line += (f"; evaluations {ea:.0f} vs {eb:.0f} ms per iteration; the solves took {a.iterations} vs "
                     f"{b.iterations} iterations ({a.status} / {b.status}, objectives {a.objective:.4g} vs "
                     f"{b.objective:.4g}): build + solve {a.e2e_s:.0f} s vs {b.e2e_s:.0f} s")
        out.append(line + ".")
    return out


#: Issue 22's end-to-end targets (s, this 2-core machine): ``gaitlib run gait --model MSK --cost
#: DT --speed Free`` (20 × 5) from an empty cache, build included; ``gaitlib gap`` on a new CSV at
#: its default mesh.
E2E_TARGETS = {"gait": 20.0, "gap": 60.0}


def e2e_tables(res: dict) -> tuple[pd.DataFrame, pd.DataFrame]:
    """``bench_e2e.py``: (the MSK DT Free command, ``gaitlib gap`` on a new CSV), one row per
    derivative path (graph; nodes; nodes compiled, first use and with the libraries cached):
    process wall time from an empty solution cache beside build, solve, iterations, ms per
    iteration and the split of the IPOPT call (evaluations / IPOPT's own work)."""
    cols = {"variant": "variant", "status": "status", "iterations": "iterations", "e2e_s": "end to end (s)",
            "build_s": "build (s)", "solve_s": "solve (s)", "ms_per_iteration": "ms / iteration",
            "evals_s": "evaluations (s)", "ipopt_rest_s": "IPOPT rest (s)", "objective": "objective",
            "same_as_nodes": "same iterates as nodes", "verdict": "verdict", "candidates": "candidates",
            "baseline_iterations": "baseline iterations",
            "load_at_start": "load at start"}
    out = []
    for key in ("gait", "gap"):
        df = pd.DataFrame(res.get(key, []))
        out.append(df[[c for c in cols if c in df.columns]].rename(columns=cols) if len(df) else df)
    return out[0], out[1]


def e2e_findings(res: dict) -> list[str]:
    """What ``bench_e2e.py`` measured, in sentences computed from its rows: each path's end
    to end time against :data:`E2E_TARGETS`, what compiling changed (and whether the
    iterates stayed the same), and where the remaining time goes."""
    out = []
    rows = {r["variant"]: r for r in res.get("gait", []) if "iterations" in r}
    tgt = E2E_TARGETS["gait"]
    if rows:
        best = min(rows.values(), key=lambda r: r["e2e_s"])
        out.append(f"• MSK DT Free, 20 × 5, from an empty cache: "
                   + "; ".join(f"{name} {r['e2e_s']:.0f} s ({r['iterations']} iterations, {r['ms_per_iteration']:.0f} ms "
                               f"each)" for name, r in rows.items())
                   + f". Fastest: {best['variant']}, {best['e2e_s']:.0f} s against the target of {tgt:.0f} s — "
                   + ("met." if best["e2e_s"] <= tgt else f"not met ({best['e2e_s'] / tgt:.1f}× over)."))
        nodes, comp = rows.get("nodes"), rows.get("nodes, compiled")
        first = rows.get("nodes, compiled (first use)")
        if nodes and comp:
            same = comp["iterations"] == nodes["iterations"] and comp["objective"] == nodes["objective"]
            out.append(f"• Compiling the per-node functions cut the evaluations from {nodes['evals_s']:.1f} to "
                       f"{comp['evals_s']:.1f} s ({nodes['evals_s'] / comp['evals_s']:.1f}×) and the solve from "
                       f"{nodes['solve_s']:.1f} to {comp['solve_s']:.1f} s; "
                       + ("the same iterations and the same objective to the last digit (the same numbers)."
                          if same else "the iterates differ (not the same numbers: a defect to investigate)."))
            if first:
                out.append(f"• The first use on a machine compiles: build {first['build_s']:.0f} s instead of "
                           f"{comp['build_s']:.1f} s (end to end {first['e2e_s']:.0f} s); later processes load the "
                           f"libraries.")
            out.append(f"• What is left of the compiled solve is IPOPT's own work, {comp['ipopt_rest_s']:.1f} of "
                       f"{comp['solve_s']:.1f} s ({1e3 * comp['ipopt_rest_s'] / max(comp['iterations'], 1):.0f} ms per "
                       f"iteration, mostly MUMPS factorising the KKT matrix — more than once in an iteration that needs "
                       f"an inertia correction). At the compiled path's {comp['ms_per_iteration']:.0f} ms per iteration the "
                       f"{tgt:.0f}-s target allows {tgt / (comp['ms_per_iteration'] / 1e3):.0f} iterations; this path took "
                       f"{comp['iterations']}.")
    gap = [r for r in res.get("gap", []) if r.get("status") == "ok"]
    if gap:
        best = min(gap, key=lambda r: r["e2e_s"])
        out.append("• gaitlib gap on a new CSV, default mesh: "
                   + "; ".join(f"{r['variant']} {r['e2e_s']:.0f} s ({r.get('verdict', '?')})" for r in gap)
                   + f". Fastest {best['e2e_s']:.0f} s against the target of {E2E_TARGETS['gap']:.0f} s — "
                   + ("met." if best["e2e_s"] <= E2E_TARGETS["gap"] else
                      f"not met ({best['e2e_s'] / E2E_TARGETS['gap']:.1f}× over)."))
    return out


def ipopt_options_table(res: dict) -> pd.DataFrame:
    """``bench_ipopt_options.py``: one row per IPOPT option variant on the MSK gait problem —
    status, iterations, solve time, objective, the iterations that needed an inertia
    correction, and the RMS distance of its joint angles from the default variant's."""
    cols = {"variant": "variant", "options": "options", "status": "status", "iterations": "iterations",
            "solve_s": "solve (s)", "ms_per_iteration": "ms / iteration", "objective": "objective",
            "inertia_corrections": "inertia corrections", "median_lg_dw": "median log10 δ_w",
            "restoration_iterations": "restoration iterations", "rms_vs_default_deg": "RMS from default (deg)"}
    df = pd.DataFrame(res.get("rows", []))
    df["options"] = df["options"].map(lambda d: ", ".join(f"{k}={v}" for k, v in dict(d).items()) or "—")
    return df[[c for c in cols if c in df.columns]].rename(columns=cols).set_index("variant")


#: A variant lands on "the same solution" as the default within this RMS of the joint angles.
SAME_SOLUTION_DEG = 1.0


def ipopt_options_findings(res: dict, target_s: float = E2E_TARGETS["gait"]) -> list[str]:
    """What the option screen says, computed from its rows: how often the Hessian needed an
    inertia correction, which variants cut the iterations and whether they kept the default's
    solution (within :data:`SAME_SOLUTION_DEG`) and objective, and the best such variant
    against the iterations ``target_s`` allows."""
    rows = [r for r in res.get("rows", []) if "iterations" in r]
    d = next((r for r in rows if r["variant"] == "default"), None)
    if d is None:
        return []
    conv = [r for r in rows if r["status"] in ("Solve_Succeeded", "Solved_To_Acceptable_Level")]
    share = [100.0 * r["inertia_corrections"] / max(r["iterations"], 1) for r in conv]
    curv = any("neg_curv_test_tol" in dict(r.get("options", {})) for r in conv)
    spread = f"{min(share):.0f} %" if round(min(share)) == round(max(share)) else f"{min(share):.0f}–{max(share):.0f} %"
    out = [f"• The default needed {d['iterations']} iterations ({d['solve_s']:.1f} s), {d['inertia_corrections']} of "
           f"them with an inertia correction; in the converged variants {spread} of the iterations did"
           + (" (the fewest with the curvature test that replaces the inertia test)." if curv else ".")]
    stuck = [r for r in rows if r not in conv]
    if stuck:
        out.append("• Not converged: " + "; ".join(f"{r['variant']} ({r['status']} after {r['iterations']} iterations, "
                                                    f"largest violation {r.get('max_violation', np.nan):.1e})"
                                                    for r in stuck) + ".")
    fewer = [r for r in conv if r["variant"] != "default" and r["iterations"] < d["iterations"]]
    same = [r for r in fewer if r["rms_vs_default_deg"] <= SAME_SOLUTION_DEG]
    other = [r for r in fewer if r["rms_vs_default_deg"] > SAME_SOLUTION_DEG]
    if other:
        out.append("• Fewer iterations, another solution: " + "; ".join(
            f"{r['variant']} {r['iterations']} it, objective {r['objective']:.4g} ({100 * (r['objective'] / d['objective'] - 1):+.0f} %), "
            f"{r['rms_vs_default_deg']:.1f}° from the default's" for r in other) + f" (default objective {d['objective']:.4g}).")
    if same:
        b = min(same, key=lambda r: r["iterations"])
        allowed = target_s / (d["ms_per_iteration"] / 1e3)
        loads = [r.get("load_at_start", np.nan) for r in rows]
        out.append(f"• Fewer iterations, the same solution (within {SAME_SOLUTION_DEG:g}°): " + "; ".join(
            f"{r['variant']} {r['iterations']} it, objective {r['objective']:.4g} "
            f"({100 * (r['objective'] / d['objective'] - 1):+.1f} %)" for r in same)
            + f". The best, {b['variant']}, takes {100 * (1 - b['iterations'] / d['iterations']):.0f} % fewer iterations; "
              f"at the default's {d['ms_per_iteration']:.0f} ms per iteration the {target_s:.0f}-s target would allow "
              f"{allowed:.0f} iterations, against its {b['iterations']}. (Times per iteration are not compared here: "
              f"the variants ran one after another with the 1-minute load at start between {np.nanmin(loads):.1f} and "
              f"{np.nanmax(loads):.1f} on 2 cores.)")
    else:
        out.append(f"• No variant cut the iterations and kept the default's solution (within {SAME_SOLUTION_DEG:g}°).")
    return out


def msk_profile_tables(res: dict | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """``bench_msk_profile.py``: (runs, graph sizes). Runs: per IPOPT option variant, status,
    iterations, solve time (s), ms per iteration, IPOPT's split of the solve (Lagrangian
    Hessian, the other function/derivative evaluations, the linear systems — MUMPS — and
    the rest, s), iterations that needed a Hessian perturbation, objective. Graph sizes: SX
    instructions of the constraints and of the Lagrangian's Hessian, SK beside MSK."""
    res = load("msk_profile") if res is None else res
    cols = {"variant": "variant", "status": "status", "iterations": "iterations", "solve_s": "solve (s)",
            "ms_per_iteration": "ms / iteration", "hessian_s": "Hessian (s)", "other_evals_s": "other evaluations (s)",
            "linear_systems_s": "linear systems, MUMPS (s)",
            "linear_systems_sys_s": "of which system time (s)", "rest_s": "rest (s)",
            "perturbed_iterations": "iterations with Hessian perturbation", "objective": "objective"}
    runs = pd.DataFrame(res["runs"])
    runs = runs[[c for c in cols if c in runs.columns]].rename(columns=cols)
    sizes = pd.DataFrame(res["graph_sizes"]).rename(columns={
        "n_variables": "variables", "n_constraints": "constraints", "constraint_instructions": "constraint SX instructions",
        "hessian_instructions": "Hessian SX instructions", "hessian_nnz": "Hessian non-zeros"})
    return runs, sizes


def eval_floor_table(res: dict) -> pd.DataFrame:
    """``bench_eval_floor.py``: the MSK solve time at best on the default run's iteration path
    (s), under three assumptions about the function evaluations, beside the measured solve and
    the :data:`MSK_SOLVE_TARGET_S` target. Rows: measured; evaluations free (linear systems + rest); Hessian
    compiled to C (per-node, measured C/VM speed), the other evaluations as measured; every
    evaluation at the Hessian's C/VM ratio."""
    f = res["floors"]
    ratio = f["compiled_to_vm_hessian_ratio"]
    rows = [("measured (book options, SX virtual machine)", f["solve_s"]),
            ("evaluations free: linear systems + rest", f["floor_evaluations_free_s"]),
            (f"Hessian compiled (C/VM {ratio:.2f}), other evaluations as measured", f["floor_hessian_compiled_s"]),
            (f"every evaluation compiled at the Hessian's ratio {ratio:.2f}", f["floor_all_compiled_s"])]
    return pd.DataFrame([{"assumption": a, "solve time (s)": v, f"≤ {MSK_SOLVE_TARGET_S:g} s": v <= MSK_SOLVE_TARGET_S}
                         for a, v in rows])


def kkt_scaling_tables(res: dict | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """``bench_kkt_scaling.py``: (sizes, fits). Sizes: per model and mesh, the KKT matrix's
    dimension and non-zeros and the median times (ms) of one iteration's pieces at a fixed
    point — the NLP functions' evaluations, one MUMPS numeric factorisation, factorisation +
    solve, and their sum (``iteration_ms``). Fits: exponent b of ``t ∝ nodes^b`` per model and
    quantity."""
    res = load("kkt_scaling") if res is None else res
    rows = pd.DataFrame([r for r in res["rows"] if "error" not in r])
    cols = ["model", "n_intervals", "nodes", "kkt_dim", "kkt_nnz", "hessian_ms", "jacobian_ms", "other_evals_ms",
            "evaluations_ms", "factorisation_ms", "factor_solve_ms", "iteration_ms"]
    fits = pd.DataFrame(res["fits"])
    return rows[[c for c in cols if c in rows.columns]], fits


def measured_on(res: dict) -> str:
    """"measured <date> on <machine> …" from a results file's metadata (any of the three
    formats)."""
    meta = res.get("meta", res)
    when = meta.get("measured") or meta.get("started_utc") or "unknown date"
    m = meta.get("machine", "unknown machine")
    if isinstance(m, dict):
        m = f"{m.get('cpu', '')} ({m.get('cores', '?')} cores), {m.get('platform', '')}".strip()
    load_ = meta.get("load_average_start") or meta.get("loadavg_start")
    s = f"measured {when} on {m}"
    if load_:
        s += f"; load average at start {', '.join(f'{v:.2f}' for v in load_)}"
    if meta.get("note"):
        s += f" — {meta['note']}"
    return s


def thesis_times_table(res: dict | None = None) -> pd.DataFrame:
    """The stored thesis-times table (``thesis_times.json``) for display: one row per
    optimisation, times in s, the thesis's time with its label, the speed-up (converged
    runs only) and whether the row came from the solution cache."""
    res = load("thesis_times") if res is None else res
    df = pd.DataFrame(res["rows"])
    cols = {"chapter": "chapter", "run": "run", "status": "status", "iterations": "iterations",
            "n_solves": "NLP solves", "build_s": "build (s)", "solve_s": "solve (s)",
            "wall_s": "wall (s)", "ms_per_iteration": "ms/iteration", "thesis_time": "thesis time (labelled)",
            "speedup": "speed-up (thesis / ours)", "from_cache": "from cache", "solved_at": "solved at"}
    out = df[[c for c in cols if c in df.columns]].rename(columns=cols)
    return out


def thesis_times_summary(res: dict | None = None) -> dict:
    """Counts and speed-up range of the stored table: ``n_rows``, ``n_converged``,
    ``n_not_converged`` (finished with another IPOPT status or error), ``n_missing``
    (:data:`NOT_COMPUTED` / :data:`NO_CACHE`), ``n_with_thesis`` (converged rows with a
    thesis time), ``speedup_min``/``_median``/``_max`` over those, ``n_from_cache``,
    ``total_wall_s`` (sum of our wall times, every measured row)."""
    res = load("thesis_times") if res is None else res
    df = pd.DataFrame(res["rows"])
    missing = _missing_mask(df)
    conv = df["converged"].astype(bool) & ~missing
    sp = pd.to_numeric(df.loc[conv, "speedup"], errors="coerce").dropna()
    measured = df[~missing]
    return {"n_rows": int(len(df)), "n_converged": int(conv.sum()), "n_not_converged": int((~conv & ~missing).sum()),
            "n_missing": int(missing.sum()), "n_with_thesis": int(len(sp)),
            "speedup_min": float(sp.min()) if len(sp) else float("nan"),
            "speedup_median": float(sp.median()) if len(sp) else float("nan"),
            "speedup_max": float(sp.max()) if len(sp) else float("nan"),
            "n_from_cache": int(measured["from_cache"].fillna(False).astype(bool).sum()),
            "total_wall_s": float(pd.to_numeric(measured["wall_s"], errors="coerce").sum())}


def _missing_mask(df: pd.DataFrame) -> pd.Series:
    return df["status"].isin([NOT_COMPUTED, NO_CACHE])


def thesis_times_by_chapter(res: dict | None = None) -> pd.DataFrame:
    """Per chapter: optimisations, how many converged / did not / were not collected, the sum
    of our wall times (h, every measured row) and the speed-up range over the converged rows
    that have a thesis time."""
    res = load("thesis_times") if res is None else res
    df = pd.DataFrame(res["rows"])
    rows = []
    for ch, g in df.groupby("chapter", sort=True):
        miss = _missing_mask(g)
        conv = g["converged"].astype(bool) & ~miss
        sp = pd.to_numeric(g.loc[conv, "speedup"], errors="coerce").dropna()
        rows.append({"chapter": ch, "optimisations": len(g), "converged": int(conv.sum()),
                     "not converged": int((~conv & ~miss).sum()), "not collected": int(miss.sum()),
                     "our wall, sum (h)": float(pd.to_numeric(g.loc[~miss, "wall_s"], errors="coerce").sum()) / 3600,
                     "with a thesis time": int(len(sp)),
                     "speed-up min": float(sp.min()) if len(sp) else np.nan,
                     "speed-up median": float(sp.median()) if len(sp) else np.nan,
                     "speed-up max": float(sp.max()) if len(sp) else np.nan})
    return pd.DataFrame(rows).set_index("chapter")


def thesis_times_figure(res: dict | None = None):
    """Horizontal log-scale bars, one pair per optimisation with a thesis time: our wall
    time (build + solve) and the thesis's. A run that did not converge is drawn hatched and
    grey with its IPOPT status; a run not collected has no bar of ours. Returns the figure."""
    import matplotlib.pyplot as plt

    res = load("thesis_times") if res is None else res
    df = pd.DataFrame(res["rows"])
    df = df[df["thesis_time_s"].notna()].reset_index(drop=True)
    n = len(df)
    fig, ax = plt.subplots(figsize=(10, 0.26 * n + 1.8))
    y = np.arange(n)[::-1]
    h = 0.38
    ax.barh(y + h / 2, df["thesis_time_s"].astype(float), h, color="0.75", label="thesis (GPOPS-II, i7-6700; printed)")
    miss = _missing_mask(df)
    conv = df["converged"].astype(bool) & ~miss
    wall = pd.to_numeric(df["wall_s"], errors="coerce")
    ax.barh(y[conv] - h / 2, wall[conv], h, color="C0", label="ours, converged (wall = build + solve)")
    bad = ~conv & ~miss & wall.notna()
    if bad.any():
        ax.barh(y[bad] - h / 2, wall[bad], h, color="white", edgecolor="C3", hatch="///",
                label="ours, did NOT converge (IPOPT status at the bar)")
        for yi, w, st in zip(y[bad], wall[bad], df.loc[bad, "status"]):
            ax.text(w * 1.15, yi - h / 2, st, va="center", fontsize=6, color="C3")
    for yi, r in zip(y[miss], df.loc[miss, "status"]):
        ax.text(1.0, yi - h / 2, r, va="center", fontsize=6, color="0.4")
    for yi, sp, w in zip(y[conv], df.loc[conv, "speedup"], wall[conv]):
        ax.text(w * 1.15, yi - h / 2, f"{sp:.0f}×" if sp >= 10 else f"{sp:.1f}×", va="center", fontsize=6)
    ax.set_yticks(y)
    short = df["run"].str.replace(", rerun max_iter=3000 (investigation)", ", rerun at 3000 it", regex=False)
    ax.set_yticklabels([f"{c} {r}" for c, r in zip(df["chapter"], short)], fontsize=6)
    ax.set_xscale("log")
    ax.set_xlabel("time (s), log scale")
    for t, lab in ((60, "1 min"), (3600, "1 h"), (36000, "10 h")):
        ax.axvline(t, color="0.85", lw=0.6, zorder=0)
        ax.text(t, n - 0.3, lab, fontsize=6, color="0.5", ha="center")
    ax.set_ylim(-0.8, n)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.9 / (0.26 * n + 1.8)), ncol=2)
    ax.set_title("Every optimisation with a thesis time: ours vs the thesis's (speed-up at our bar)", fontsize=9)
    fig.tight_layout()
    return fig


# --------------------------------------------------------------------------------------
# Figures and findings of the page
# --------------------------------------------------------------------------------------
def scaling_figure(res: dict | None = None):
    """Three log–log panels over the finished mesh runs of each model: time per iteration
    (converged runs as dots, the others as crosses, the fitted power law, for SK also its
    function-evaluation and IPOPT + MUMPS parts and a linear reference through the smallest
    SK mesh), solve time and build time (s), against the collocation nodes. Returns the figure."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter, ScalarFormatter

    res = load("scaling") if res is None else res
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    colors = {"SK": "C0", "MSK": "C1", "NMSK": "C2"}
    fin = pd.DataFrame([r for r in res["runs"] if r["group"] == "mesh" and r["outcome"] == FINISHED])
    for model, g in fin.groupby("model", sort=False):
        g = g.sort_values("nodes")
        f = fit_power_law(g["nodes"], g["ms_per_iteration"])
        conv = g["success"].astype(bool)
        axes[0].loglog(g["nodes"][conv], g["ms_per_iteration"][conv], "o", color=colors[model])
        axes[0].loglog(g["nodes"][~conv], g["ms_per_iteration"][~conv], "x", color=colors[model], ms=9)
        if np.isfinite(f["exponent"]):
            n = np.geomspace(g["nodes"].min(), g["nodes"].max(), 20)
            axes[0].loglog(n, f["prefactor"] * n ** f["exponent"], "-", color=colors[model],
                           label=f"{model}: b = {f['exponent']:.2f}")
        else:
            axes[0].plot([], [], "o", color=colors[model], label=f"{model}: one size")
        axes[1].loglog(g["nodes"], g["solve_s"], "o-", color=colors[model], label=model)
        axes[2].loglog(g["nodes"], g["build_s"], "o-", color=colors[model], label=model)
        if model == "SK":
            axes[0].loglog(g["nodes"], g["function_evals_ms_per_iteration"], "v:", color=colors[model], ms=4,
                           label="SK: function evaluations")
            axes[0].loglog(g["nodes"], g["ipopt_rest_ms_per_iteration"], "s:", color=colors[model], ms=4,
                           label="SK: IPOPT + MUMPS")
    if len(fin):
        n = np.geomspace(fin["nodes"].min(), fin["nodes"].max(), 20)
        sk = fin[fin["model"] == "SK"].sort_values("nodes")
        if len(sk):
            ref = sk["ms_per_iteration"].iloc[0] * n / sk["nodes"].iloc[0]
            axes[0].loglog(n, ref, "k--", lw=0.8, label="linear (b = 1)")
    axes[0].set(xlabel="collocation nodes N", ylabel="ms per iteration",
                title="Time per iteration (× = did not converge)")
    axes[1].set(xlabel="collocation nodes N", ylabel="s", title="Solve time (IPOPT call)")
    axes[2].set(xlabel="collocation nodes N", ylabel="s", title="Build time (NLP + exact derivatives)")
    for ax in axes:
        if len(fin):
            ax.set_xticks(sorted(fin["nodes"].unique()))
            ax.xaxis.set_major_formatter(ScalarFormatter())
            ax.xaxis.set_minor_formatter(NullFormatter())
        ax.legend(fontsize=7)
        ax.grid(True, which="both", lw=0.3)
    fig.tight_layout()
    return fig


def msk_profile_findings(res: dict) -> list[str]:
    """``bench_msk_profile.py`` in three sentences: the book options' run (status,
    iterations, solve time against :data:`MSK_SOLVE_TARGET_S` — met only if it converged —
    and the shares of the Hessian, the other evaluations and the linear systems); the MSK
    graph's size relative to SK's; the option variants that converged (fastest, objective
    range). The first run is the book's options."""
    runs, sizes = msk_profile_tables(res)
    d = runs.iloc[0]
    sz = sizes.set_index("model")
    met = d["solve (s)"] <= MSK_SOLVE_TARGET_S and d["status"] == CONVERGED
    ok = runs[runs["status"] == CONVERGED]
    return [
        f"• Book options: {d['status']}, {d['iterations']} iterations, {d['solve (s)']:.1f} s "
        f"({d['ms / iteration']:.0f} ms per iteration) — the ≤ {MSK_SOLVE_TARGET_S:g} s target is "
        f"{'met' if met else 'NOT met'}. Of the solve, "
        f"{100 * d['Hessian (s)'] / d['solve (s)']:.0f} % is the Hessian, "
        f"{100 * d['other evaluations (s)'] / d['solve (s)']:.0f} % the other evaluations, "
        f"{100 * d['linear systems, MUMPS (s)'] / d['solve (s)']:.0f} % the linear systems; "
        f"{d['iterations with Hessian perturbation']} of {d['iterations']} iterations needed a Hessian perturbation.",
        f"• The MSK constraints are "
        f"{sz.loc['MSK', 'constraint SX instructions'] / sz.loc['SK', 'constraint SX instructions']:.0f}× "
        f"the SK constraints in SX instructions and the Hessian "
        f"{sz.loc['MSK', 'Hessian SX instructions'] / sz.loc['SK', 'Hessian SX instructions']:.1f}×: "
        f"the muscle torque generators' piecewise-quintic curves (≈ 60 pieces per generator, each piece "
        f"selected by a chain of if_else nodes at every node) are most of the difference.",
        f"• Option variants that converged: {len(ok) - 1}; fastest {ok['solve (s)'].min():.1f} s "
        f"({ok.loc[ok['solve (s)'].idxmin(), 'variant']}); objectives of the converged runs "
        f"{ok['objective'].min():.3f}–{ok['objective'].max():.3f} (different local optima)."]


def eval_floor_frames(res: dict) -> tuple[pd.DataFrame, pd.DataFrame]:
    """``bench_eval_floor.py``: (ms per call of the solver's own functions on CasADi's SX
    virtual machine, one row; per-node functions mapped over all nodes, virtual machine vs
    compiled C, ms)."""
    fn = pd.DataFrame([res["solver_function_ms"]]).rename(index={0: "ms per call (SX virtual machine)"})
    mapped = pd.DataFrame({"SX virtual machine (ms)": res["mapped_vm_ms"],
                           "compiled C (ms)": res["mapped_compiled_ms"]}).rename_axis(
        f"per-node, mapped over {res['collocation_nodes']} nodes")
    return fn, mapped


def eval_floor_findings(res: dict) -> list[str]:
    """``bench_eval_floor.py``'s floors in two sentences: the solver's Hessian is a sum of
    per-node Hessians (non-zeros outside the nodes' blocks, SX instructions per node × nodes
    against the solver's); the compiled per-node Hessian's time and the solve-time floors on
    the default path, with the evaluation budget per iteration that :data:`MSK_SOLVE_TARGET_S`
    leaves."""
    fl = res["floors"]
    return [
        f"• The solver's Hessian has {res['hessian_nnz']:,} non-zeros, "
        f"{res['hessian_nnz_outside_node_blocks']} outside the nodes' (x, u) blocks; per node "
        f"{res['node_hessian_instructions']:,} SX instructions × {res['collocation_nodes']} nodes = "
        f"{res['nodes_x_node_hessian_instructions']:,}, against {res['solver_hessian_instructions']:,} in the "
        f"solver's Hessian: the same work, evaluated per node.",
        f"• Compiled with gcc {res['gcc']} ({res['compile_s']:.0f} s), the per-node Hessian over all nodes "
        f"takes {res['mapped_compiled_ms']['hessian']:.1f} ms against the solver's "
        f"{res['solver_function_ms']['nlp_hess_l']:.1f} ms ({fl['compiled_to_vm_hessian_ratio']:.2f}×). On the "
        f"default path ({fl['iterations']} iterations) the solve would take at best "
        f"{fl['floor_hessian_compiled_s']:.1f} s with the Hessian compiled and "
        f"{fl['floor_all_compiled_s']:.1f} s with every evaluation equally faster; the linear systems and "
        f"IPOPT's own work alone take {fl['floor_evaluations_free_s']:.1f} s. Reaching {MSK_SOLVE_TARGET_S:g} s "
        f"on this path would need all evaluations together in ≤ {fl['evaluation_budget_ms_per_iteration']:.1f} ms "
        f"per iteration."]


def compiled_solve_finding(res: dict) -> str:
    """``bench_eval_floor.py``'s solve with the assembled compiled Hessian beside the book's
    solver (first row of ``compiled_solve.solves``) from the same start, in one sentence; the
    two are the same path when iterations match and the objectives agree to
    :data:`SAME_OBJECTIVE_RTOL`."""
    cs = res["compiled_solve"]
    sv = pd.DataFrame(cs["solves"])
    bk, cp = sv.iloc[0], sv.iloc[1]
    same = (bk["iterations"] == cp["iterations"]
            and abs(bk["objective"] - cp["objective"]) <= SAME_OBJECTIVE_RTOL * abs(bk["objective"]))
    return (f"• Assembled from the compiled per-node Hessians, IPOPT's exact Hessian equals the solver's to "
            f"{cs['hessian_check_max_rel_diff']:.0e} (relative) and costs {cs['hessian_ms']['assembled_compiled']:.1f} ms "
            f"instead of {cs['hessian_ms']['solver']:.1f} ms. Solved with it: {cp['status']}, {cp['iterations']} "
            f"iterations, {cp['solve_s']:.1f} s ({cp['ms_per_iteration']:.0f} ms per iteration), objective "
            f"{cp['objective']:.4f}; the book's solver in the same run: {bk['status']}, {bk['iterations']} iterations, "
            f"{bk['solve_s']:.1f} s ({bk['ms_per_iteration']:.0f} ms per iteration), objective {bk['objective']:.4f}. "
            + ("Same path, same solution." if same else
               "Round-off differences alone (the same Hessian summed in another order) send IPOPT down another "
               "path to another local optimum: a faster Hessian does not give the book's solve faster."))


def thesis_times_findings(res: dict | None = None) -> list[str]:
    """The stored thesis-times table in sentences: counts (converged, not, not collected,
    reloaded from the cache) and our total wall time; the speed-up range over the converged
    rows with a thesis time, with the smallest and largest; the runs that did not converge;
    the rows not collected."""
    res = load("thesis_times") if res is None else res
    ts = thesis_times_summary(res)
    rows = pd.DataFrame(res["rows"])
    out = [f"• {ts['n_rows']} optimisations: {ts['n_converged']} converged, {ts['n_not_converged']} did not, "
           f"{ts['n_missing']} not collected; {ts['n_from_cache']} of the measured ones reloaded from the cache with "
           f"the times of their solve. Our wall times add up to {ts['total_wall_s'] / 3600:.1f} h."]
    if ts["n_with_thesis"]:
        conv = rows[rows["speedup"].notna()]
        lo, hi = conv.loc[conv["speedup"].idxmin()], conv.loc[conv["speedup"].idxmax()]
        out.append(f"• Over the {ts['n_with_thesis']} converged optimisations with a thesis time the speed-up is "
                   f"{ts['speedup_min']:.1f}–{ts['speedup_max']:.0f}× (median {ts['speedup_median']:.0f}×). Smallest: "
                   f"{lo['chapter']} {lo['run']} — {lo['wall_s'] / 60:.1f} min here vs {lo['thesis_time']}; largest: "
                   f"{hi['chapter']} {hi['run']} — {hi['wall_s'] / 60:.1f} min vs {hi['thesis_time']}.")
    missing = _missing_mask(rows)
    not_conv = rows[~rows["converged"].astype(bool) & ~missing]
    if len(not_conv):
        out.append("• Did not converge (no speed-up given): " + "; ".join(
            f"{r.chapter} {r.run}: {r.status} after {_count(r.iterations)} iterations"
            for r in not_conv.itertuples()) + ".")
    if missing.any():
        out.append("• Not collected: " + "; ".join(
            f"{r.chapter} {r.run} ({r.status})" for r in rows[missing].itertuples()) + ".")
    return out


def _count(x) -> str:
    """An integer count that may have become a float (a column with missing values), or "?"."""
    return "?" if x is None or pd.isna(x) else f"{int(x)}"


def mumps_orderings_findings(res: dict) -> list[str]:
    """``bench_mumps_orderings.py`` in sentences: the orderings this MUMPS build lacks (MUMPS
    used another one instead; their fits mix two orderings and are left out), then per model
    the range of the flops exponents over the orderings, the slowest-growing ordering against
    IPOPT's default (:data:`MUMPS_AUTO_ORDERING`) at the largest mesh, and whether any
    ordering grows no faster than linearly (:data:`LINEAR_GROWTH`)."""
    rows, fits = pd.DataFrame(res["rows"]), pd.DataFrame(res["fits"])
    fl_fits = fits[fits["quantity"] == "flops"]
    fallback = rows[rows["requested_name"].str.split().str[0] != rows["ordering_name"]]
    fallback = fallback[fallback["requested"] != MUMPS_AUTO_ORDERING]
    out = []
    if len(fallback):
        out.append("• Not in this MUMPS build (MUMPS used another ordering instead): " + "; ".join(
            f"{name} → {', '.join(f'{u} (KKT of {g2.kkt_n.min():,}–{g2.kkt_n.max():,} rows)' for u, g2 in g.groupby('ordering_name'))}"
            for name, g in fallback.groupby("requested_name", sort=False)) + ". Their fitted exponents mix two "
            "orderings and are left out below.")
    mixed = set(fallback["requested_name"])
    for model, g in fl_fits[~fl_fits["requested_name"].isin(mixed)].groupby("model", sort=False):
        best = g.loc[g["exponent"].idxmin()]
        at = rows[rows["model"] == model]
        at = at[at["nodes"] == at["nodes"].max()]
        auto = at.loc[at["requested"] == MUMPS_AUTO_ORDERING, "flops"].iloc[0]
        at = at.set_index("requested_name")["flops"]
        used = rows[(rows["model"] == model) & (rows["requested"] == MUMPS_AUTO_ORDERING)]["ordering_name"].unique()
        is_default = best["used"] in used
        out.append(f"• {model}: one factorisation's operations grow as nodes^{g['exponent'].min():.2f}–"
                   f"{g['exponent'].max():.2f} over the orderings; the slowest growth is {best['requested_name']}'s "
                   f"(nodes^{best['exponent']:.2f} ± {best['exponent_se']:.2f})"
                   + (", which is what IPOPT's default (MUMPS's automatic choice) uses. " if is_default else
                      f", but at the largest mesh its count is {at[best['requested_name']] / auto:.2f}× that of "
                      f"IPOPT's default (MUMPS's automatic choice: {', '.join(used)}). ")
                   + ("No ordering MUMPS offers grows linearly or slower." if g["exponent"].min() > LINEAR_GROWTH else
                      "At least one ordering grows no faster than linearly."))
    return out


FATROP_COLUMNS = ["model", "mesh", "solver", "status", "iterations", "build_s", "solve_s", "ms_per_iteration", "objective",
                  "max_violation", "n_variables", "n_constraints"]


def fatrop_table(res: dict) -> pd.DataFrame:
    """``bench_fatrop.py``'s rows: one per model, mesh and solver (IPOPT on gaitlib's NLP, on
    its integral form, on the stage-wise rewrite; FATROP on the rewrite)."""
    df = pd.DataFrame(res["rows"])
    return df[[c for c in FATROP_COLUMNS if c in df.columns]]


def fatrop_findings(res: dict) -> list[str]:
    """``bench_fatrop.py`` in sentences, per model: FATROP's time per iteration against
    IPOPT's on the same problem, the time FATROP would take at IPOPT's iteration count (to
    match IPOPT it would have to converge in 1/ratio of IPOPT's iterations), and the IPOPT runs on the
    integral form and on the stage-wise rewrite beside the book's differential form."""
    out = []
    for (model, mesh), g in pd.DataFrame(res["rows"]).groupby(["model", "mesh"], sort=False):
        r = g.set_index("solver")
        if "ipopt" not in r.index:
            continue
        ip = r.loc["ipopt"]
        line = (f"• {model} {mesh}: IPOPT + MUMPS on gaitlib's NLP, {ip['status']} in {int(ip['iterations'])} "
                f"iterations, {ip['solve_s']:.1f} s ({ip['ms_per_iteration']:.0f} ms per iteration).")
        if "fatrop" in r.index:
            fa = r.loc["fatrop"]
            if int(fa["iterations"]) > 0:
                ratio = fa["ms_per_iteration"] / ip["ms_per_iteration"]
                floor = fa["ms_per_iteration"] * ip["iterations"] / 1e3
                line += (f" FATROP on the same problem laid out in {int(fa['N'])} stages ({int(fa['stage_nx'])} "
                         f"states, {int(fa['stage_nu'])} controls and {int(fa['stage_ng'])} constraints per "
                         f"stage): {fa['status']} after {int(fa['iterations'])} iterations, "
                         f"{fa['ms_per_iteration']:.0f} ms per iteration, {ratio:.1f}× IPOPT's; at IPOPT's "
                         f"iteration count that is {floor:.0f} s against IPOPT's {ip['solve_s']:.0f} s.")
            else:
                line += f" FATROP: {fa['status']}."
        for name, what in (("ipopt (integral form)", "its defects in integral form"),
                           ("ipopt (stage-wise)", "the stage-wise rewrite")):
            if name in r.index:
                o = r.loc[name]
                line += (f" IPOPT on {what}: {o['status']} in {int(o['iterations'])} iterations, "
                         f"{o['solve_s']:.1f} s ({o['ms_per_iteration']:.0f} ms per iteration), objective "
                         f"{o['objective']:.4f} against {ip['objective']:.4f}.")
        out.append(line)
    return out


_BUDGET_COLS = {"chapter": "chapter", "solves": "solves", "converged": "converged", "iterations": "iterations",
                "build_s": "build (h)", "solve_s": "IPOPT (h)", "recorded_s": "recorded (h)",
                "paced_s": "at the fastest recorded pace (h)", "compiled_s": "per-node builds, compiled (h)", "evals_free_s": "evaluations free (h)",
                "evals_free_2_workers_s": "evaluations free, 2 workers (h)"}


def book_budget_table(res: dict) -> pd.DataFrame:
    """``bench_book_budget.py``: per chapter, the stored solutions the book reads — solves,
    converged, IPOPT iterations, build and IPOPT time as recorded at their solve, and the
    levers' projections (each solve at its class's fastest recorded time per iteration; then
    per-node builds and compiled evaluations; evaluations free; the latter on two workers) — in
    hours, with a last row for the whole book."""
    rows = [r for r in res["rows"] if r["solves"]]
    df = pd.DataFrame(rows)[list(_BUDGET_COLS)]
    total = df.drop(columns="chapter").sum()
    df = pd.concat([df, pd.DataFrame([{"chapter": "whole book", **total.to_dict()}])], ignore_index=True)
    for c in [c for c in _BUDGET_COLS if c.endswith("_s")]:
        df[c] = df[c] / 3600
    df[["solves", "converged", "iterations"]] = df[["solves", "converged", "iterations"]].astype(int)
    return df.rename(columns=_BUDGET_COLS).set_index("chapter")


def book_floor_s(budget: dict, workers: dict | None = None) -> tuple[float, float]:
    """The whole book's floor (s) from ``bench_book_budget.py``'s results: every measured lever
    applied, the evaluations free, split over two workers — at the best two-worker speed-up
    ``bench_workers.py`` measured, or perfectly (2×) without ``workers``; and that speed-up."""
    speed = max((s["speed-up"] for s in workers["summary"]), default=2.0) if workers else 2.0
    return sum(r["evals_free_s"] for r in budget["rows"]) / speed, speed


def book_budget_findings(res: dict, target_s: float = BOOK_TARGET_S) -> list[str]:
    """What ``bench_book_budget.py`` found, in sentences computed from its rows: what the book
    solves from scratch, its largest chapters, and the time left once every measured lever is
    applied at once, against issue 22's target 1."""
    rows = res["rows"]
    tot = {k: sum(r[k] for r in rows) for k in _BUDGET_COLS if k != "chapter"}
    floor, _ = book_floor_s(res)
    big = sorted(rows, key=lambda r: -r["recorded_s"])[:3]
    share = ", ".join(f"{m} {v:.0%}" for m, v in res["ratios"]["eval_share"].items())
    return [
        f"• From scratch the book solves {tot['solves']:,.0f} optimisations ({tot['converged']:,.0f} converged), {tot['iterations']:,.0f} IPOPT iterations: recorded "
        f"{tot['recorded_s'] / 3600:.1f} h of build + solve ({tot['build_s'] / 3600:.1f} h building, "
        f"{tot['solve_s'] / 3600:.1f} h in IPOPT), one solve at a time.",
        "• The largest chapters: " + "; ".join(f"{r['chapter']} {r['recorded_s'] / 3600:.1f} h ({r['solves']} solves)"
                                              for r in big) + ".",
        f"• Every solve at the fastest time per iteration recorded for its kind of problem (the recorded times carry "
        f"the load each solve shared the machine with; this is a lower estimate for an unloaded machine): "
        f"{tot['paced_s'] / 3600:.1f} h. From there, per-node builds with "
        f"compiled evaluations: {tot['compiled_s'] / 3600:.1f} h; with the evaluations free "
        f"(their share of a whole-graph solve: {share}): {tot['evals_free_s'] / 3600:.1f} h; on two workers splitting "
        f"every chapter perfectly: {floor / 3600:.1f} h — {floor / target_s:.1f}× the target of "
        f"{target_s / 60:.0f} min, which is " + ("met." if floor <= target_s else "not reachable with these levers: "
                                                 "it needs fewer solves or fewer iterations per solve, and every "
                                                 "measured way to fewer iterations ended in other local optima."),
    ]


def workers_table(res: dict) -> pd.DataFrame:
    """``bench_workers.py``: per workload, the median wall time on one worker process and on
    two (a ``dask scheduler`` + ``dask worker`` cluster), the speed-up and the parallel
    efficiency (speed-up ÷ 2)."""
    return pd.DataFrame(res["summary"]).set_index("workload")


def workers_findings(res: dict, budget: dict | None = None, target_s: float = BOOK_TARGET_S) -> list[str]:
    """The measured two-worker speed-ups, and (with ``budget``: ``bench_book_budget.py``'s
    results) the book's floor on two workers at the measured efficiency instead of a perfect
    split."""
    summ = res["summary"]
    out = ["• Two worker processes instead of one: " + "; ".join(
        f"{s['workload']} {s['1 worker (s)']:.0f} → {s['2 workers (s)']:.0f} s ({s['speed-up']:.2f}×, efficiency "
        f"{s['efficiency']:.0%})" for s in summ) + "."]
    if budget is not None and summ:
        floor, best = book_floor_s(budget, res)
        out.append(f"• At the best measured speed-up ({best:.2f}×) the book's floor with the evaluations free is "
                   f"{floor / 3600:.1f} h on two workers ({floor / target_s:.1f}× the target of "
                   f"{target_s / 60:.0f} min).")
    return out


def warm_chain_table(res: dict) -> pd.DataFrame:
    """``bench_warm_chain.py``: each Ch 7 run as the book starts it beside the same spec
    started from the neighbouring speed's solution — status, iterations, times, objective,
    validity gates and the RMS distance of its joint angles from the book's run (deg)."""
    return pd.DataFrame(res["rows"]).set_index(["model", "class", "start"])


def warm_chain_findings(res: dict) -> list[str]:
    """Per model: converged and valid runs, iterations and IPOPT time in all, book's start vs
    the chain; and how many chained runs reached another solution (joint angles ≥ 1° RMS from
    the book's)."""
    out = []
    summ = {(s["model"], s["start"]): s for s in res["summary"]}
    for m in dict.fromkeys(s["model"] for s in res["summary"]):
        b, c = summ[(m, "book")], summ[(m, "chain")]
        chain = [r for r in res["rows"] if r["model"] == m and r["start"].startswith("chain")]
        ok = [r for r in chain if r["status"] == CONVERGED]
        other = [f"{r['class']} ({r['rms_from_book_deg']:.1f}°)" for r in ok if r["rms_from_book_deg"] >= 1.0]
        failed = [f"{r['class']} ({r['status']})" for r in chain if r["status"] != CONVERGED]
        out.append(f"• {m}: the book's starts {b['converged']}/{b['runs']} converged, {b['valid']} valid, "
                   f"{b['iterations']} iterations, {b['solve_s']:.0f} s in IPOPT (as recorded); the chain "
                   f"{c['converged']}/{c['runs']} converged, {c['valid']} valid, {c['iterations']} iterations, "
                   f"{c['solve_s']:.0f} s. "
                   + (f"Converged to another solution (joint angles ≥ 1° RMS from the book's run): "
                      f"{', '.join(other)}. " if other else "Every converged chained run within 1° RMS of the book's. ")
                   + (f"Not converged: {', '.join(failed)}." if failed else ""))
    return out


def targets_table(e2e: dict | None, moco: dict | None, budget: dict | None, workers: dict | None) -> pd.DataFrame:
    """Issue 22's time targets beside what the benchmarks measured (any results file may be
    None): the whole book from scratch (``bench_book_budget.py``: the floor every measured
    lever leaves, on two workers at the best measured speed-up of ``bench_workers.py``, else a
    perfect split), the MSK command and the gap diagnosis end to end (``bench_e2e.py``,
    fastest path), and the ratios to Moco (``bench_moco_t9track.py``)."""
    rows = []
    if budget is not None:
        floor, speed = book_floor_s(budget, workers)
        rows.append({"target": "the whole book from an empty cache", "threshold": f"≤ {BOOK_TARGET_S / 60:.0f} min",
                     "measured": f"floor {floor / 3600:.1f} h (every lever, two workers at {speed:.2f}×)",
                     "met": floor <= BOOK_TARGET_S})
    if e2e is not None:
        for key, what in (("gait", "MSK DT Free, build + solve"), ("gap", "gaitlib gap on a new CSV")):
            ok = [r for r in e2e.get(key, []) if r.get("status") in (CONVERGED, "ok")]
            if ok:
                best = min(ok, key=lambda r: r["e2e_s"])
                rows.append({"target": what, "threshold": f"≤ {E2E_TARGETS[key]:.0f} s",
                             "measured": f"{best['e2e_s']:.1f} s ({best['variant']})",
                             "met": best["e2e_s"] <= E2E_TARGETS[key]})
    if moco is not None:
        for scheme, s in moco.get("speedups", {}).items():
            for kind, key in (("setup + solve", "speedup_e2e"), ("solve", "speedup_best")):
                if key in s:
                    v = s[key]["speedup"]
                    rows.append({"target": f"T9-track vs Moco, {scheme}, {kind}",
                                 "threshold": f"≥ {MOCO_TARGETS[kind]:g}×", "measured": f"{v:.1f}× ({s[key]['tool']})",
                                 "met": v >= MOCO_TARGETS[kind]})
    return pd.DataFrame(rows, columns=["target", "threshold", "measured", "met"])


def build_reuse_findings(res: dict) -> list[str]:
    """``bench_build_reuse.py`` in sentences: the same solves with a process's whole-graph
    solvers built anew for every solve and reused where the NLP is identical — how many
    builds, their time, the solves' time and the process's wall time, and whether every solve
    took the same path (iterations and objective to the last bit)."""
    runs = {("on" if r["reuse"] else "off"): r for r in res["runs"]}
    if set(runs) != {"on", "off"}:
        return []
    off, on = runs["off"], runs["on"]
    n, d = res["mesh"]
    builds = sum(not row.get("reused", False) for row in on["rows"])
    return [f"• Contact identification (b), {n} × {d}, starts {', '.join(res.get('starts', ['all']))}: "
            f"{len(off['rows'])} solves; identical with and without reuse (iterations and objective to the "
            f"last bit) in {res['identical_solves']}. Built anew every time: {len(off['rows'])} builds, "
            f"{off['build_s']:.1f} s; reused: {builds} build{'' if builds == 1 else 's'}, {on['build_s']:.1f} s. Solving took "
            f"{off['solve_s']:.0f} s and {on['solve_s']:.0f} s, the whole process {off['e2e_s']:.0f} s and "
            f"{on['e2e_s']:.0f} s."]


def defect_form_findings(res: dict) -> list[str]:
    """``bench_defect_form.py`` in sentences: per problem, the integral form's iterations,
    solve time and objective against the differential form's (the book's); a lower
    objective is another local optimum reached, not a property of the form. The time ratio is
    given only when both runs converged."""
    out = []
    for prob, g in pd.DataFrame(res["rows"]).groupby("problem", sort=False):
        r = g.set_index("form")
        if not {"differential", "integral"} <= set(r.index):
            continue
        d, i = r.loc["differential"], r.loc["integral"]
        out.append(f"• {prob} ({d['mesh']}): differential {d['status']}, {int(d['iterations'])} iterations, "
                   f"{d['solve_s']:.1f} s ({d['ms_per_iteration']:.0f} ms each), objective {d['objective']:.4f}; "
                   f"integral {i['status']}, {int(i['iterations'])} iterations, {i['solve_s']:.1f} s "
                   f"({i['ms_per_iteration']:.0f} ms each), objective {i['objective']:.4f} — "
                   + (f"{i['solve_s'] / d['solve_s']:.2f}× the time." if d["status"] == i["status"] == CONVERGED else
                      "no time ratio: the " + " and the ".join(f for f, x in (("differential", d), ("integral", i))
                                                              if x["status"] != CONVERGED)
                      + " form did not converge."))
    return out


def _fit(fits: pd.DataFrame, model: str, quantity: str = "time per iteration"):
    """The row of :func:`scaling_fits` for ``model`` and ``quantity``, or None (no row or no
    exponent fitted)."""
    if fits.empty:
        return None
    r = fits[(fits["model"] == model) & (fits["quantity"] == quantity)]
    return None if r.empty or not np.isfinite(r["exponent"].iloc[0]) else r.iloc[0]


def _scaling_lines(table: pd.DataFrame, fits: pd.DataFrame) -> list[str]:
    """Per model: the exponent of time per iteration against :data:`LINEAR_GROWTH`, its two
    parts, the iterations' exponent and every run's status."""
    out = []
    for model in ("SK", "MSK", "NMSK"):
        g = table[table["model"] == model]
        if g.empty:
            continue
        f = _fit(fits, model)
        statuses = ", ".join(f"{int(r.n_intervals)} intervals: {r.status} ({int(r.iterations)} it, "
                             f"{r.ms_per_iteration:.0f} ms/it)" for r in g.itertuples() if isinstance(r.status, str))
        if f is None:
            out.append(f"• {model}: {statuses}; one mesh size only, no exponent fitted.")
            continue
        verdict = "meets" if f["exponent"] <= LINEAR_GROWTH else "does NOT meet"
        parts = [p for p in (_fit(fits, model, "function evaluations per iteration"),
                             _fit(fits, model, "IPOPT + MUMPS per iteration")) if p is not None]
        split = (f" (function evaluations b = {parts[0]['exponent']:.2f}, IPOPT + MUMPS b = {parts[1]['exponent']:.2f})"
                 if len(parts) == 2 else "")
        it = _fit(fits, model, "iterations")
        its = f"; iterations ∝ N^{it['exponent']:.2f}" if it is not None else ""
        out.append(f"• {model}: time per iteration grows as N^{f['exponent']:.2f} over N = {f['nodes']} nodes{split}, "
                   f"which {verdict} the target of at most linear growth{its}. Runs: {statuses}.")
    return out


def _machine_share_lines(table: pd.DataFrame, fits: pd.DataFrame) -> list[str]:
    """SK: the excess exponent of the CasADi evaluations (exactly proportional work) read as
    the machine's share, and IPOPT + MUMPS's exponent corrected by it."""
    sk_runs = table[table["model"] == "SK"].sort_values("nodes")
    sk_f, sk_fe = _fit(fits, "SK"), _fit(fits, "SK", "function evaluations per iteration")
    sk_mu = _fit(fits, "SK", "IPOPT + MUMPS per iteration")
    if len(sk_runs) < 2 or sk_f is None or sk_fe is None or sk_mu is None:
        return []
    excess, b_mu = sk_fe["exponent"] - LINEAR_GROWTH, sk_mu["exponent"]
    load_col = "load (1 min) at start"
    return [f"• How much of that is the machine: the CasADi evaluations do exactly proportional work (the same "
            f"per-node expressions at every node), yet measure b = {sk_fe['exponent']:.2f} for SK; the 1-minute load "
            f"average was {sk_runs[load_col].iloc[0]:.1f} at the smallest SK mesh and "
            f"{sk_runs[load_col].iloc[-1]:.1f} at the largest (2 cores). If contention and cache "
            f"effects inflate every exponent by that {excess:+.2f}, IPOPT + MUMPS per iteration "
            f"(b = {b_mu:.2f}) still grows "
            f"{'faster than linearly' if b_mu - excess > LINEAR_GROWTH else 'no faster than linearly'} "
            f"(b ≈ {b_mu - excess:.2f})."]


def _kkt_lines(res: dict) -> list[str]:
    """Per model of ``bench_kkt_scaling.py``: the evaluations' exponent (linear up to
    :data:`LINEAR_TOLERANCE`), one MUMPS factorisation + solve's exponent and the largest
    rise of its cost per KKT row from one mesh to the next."""
    rows, fits = kkt_scaling_tables(res)
    kf = fits.set_index(["model", "quantity"])["exponent"]
    out = []
    for model in dict.fromkeys(fits["model"]):
        b_ev, b_fa = kf[(model, "evaluations_ms")], kf[(model, "factor_solve_ms")]
        kr = rows[rows["model"] == model].sort_values("nodes")
        jump = (kr["factorisation_ms"] / kr["kkt_dim"]).pct_change().max()
        out.append(f"• {model} at a fixed point: the NLP evaluations of one iteration grow as N^{b_ev:.2f} "
                   f"({'linear' if b_ev <= LINEAR_GROWTH + LINEAR_TOLERANCE else 'superlinear'}); one MUMPS "
                   f"factorisation + solve through CasADi's interface as N^{b_fa:.2f}, with its cost per KKT row "
                   f"rising by up to {100 * jump:.0f} % from one mesh to the next — MUMPS's own choices at CasADi's "
                   f"default settings, not IPOPT's (IPOPT's linear-system time per iteration is the 'IPOPT + MUMPS' "
                   f"exponent above).")
    return out


def _fill_lines(res: dict, fits: pd.DataFrame) -> list[str]:
    """Per model of ``bench_kkt_fill.py``: the factor's and the flops' exponents (with and
    without the periodic constraint) beside IPOPT + MUMPS's measured exponent."""
    ff = pd.DataFrame(res["fits"])
    b = ff.set_index(["model", "periodic", "quantity"])["exponent"]
    out = []
    for model in dict.fromkeys(ff["model"]):
        b_fl, b_np, b_L = b[(model, True, "flops_proxy")], b[(model, False, "flops_proxy")], b[(model, True, "L_nnz")]
        mu = _fit(fits, model, "IPOPT + MUMPS per iteration")
        out.append(f"• {model}, counted rather than timed: a minimum-degree LDLᵀ of the KKT matrix has a factor growing "
                   f"as N^{b_L:.2f} but flops growing as N^{b_fl:.2f} (N^{b_np:.2f} without the periodic constraint)"
                   + (f", beside IPOPT + MUMPS's measured N^{mu['exponent']:.2f}" if mu is not None else "")
                   + ": the superlinear part of the linear algebra is the fill of the minimum-degree ordering, not "
                     "the machine (MUMPS's own counts for every ordering it offers are in the section above).")
    return out


def _thesis_mesh_lines(table: pd.DataFrame) -> list[str]:
    """Time per iteration of each model at :data:`THESIS_MESH_NODES`, and the build times."""
    by_model = table[table["nodes"] == THESIS_MESH_NODES].set_index("model")
    if not {"SK", "MSK"} <= set(by_model.index):
        return []
    msg = (f"• At the thesis mesh ({THESIS_MESH_NODES} nodes) one iteration costs "
           f"{by_model.loc['SK', 'ms_per_iteration']:.0f} ms (SK), {by_model.loc['MSK', 'ms_per_iteration']:.0f} ms (MSK)")
    if "NMSK" in by_model.index:
        msg += f", {by_model.loc['NMSK', 'ms_per_iteration']:.0f} ms (NMSK)"
    return [msg + f"; building the NLP takes {by_model['build_s'].min():.0f}–{by_model['build_s'].max():.0f} s."]


def _hessian_lines(hess: pd.DataFrame) -> list[str]:
    """Exact Hessian vs L-BFGS on the same problem: statuses, iterations, solve times,
    objectives and the cost of an L-BFGS iteration relative to an exact one."""
    done = hess[hess["outcome"] == FINISHED]
    if done["hessian"].nunique() < 2:
        return [f"• Exact Hessian vs L-BFGS: not measured ({', '.join(hess['outcome'].astype(str))})."]
    ex = done[done["hessian"] == "exact"].iloc[0]
    lm = done[done["hessian"] == "limited-memory"].iloc[0]
    return [f"• Exact Hessian vs L-BFGS ({ex['model']}, {int(ex['n_intervals'])} intervals): {ex['status']} in "
            f"{int(ex['iterations'])} iterations / {ex['solve_s']:.0f} s vs {lm['status']} in {int(lm['iterations'])} "
            f"iterations / {lm['solve_s']:.0f} s (objective {ex['objective']:.4g} vs {lm['objective']:.4g}); an L-BFGS "
            f"iteration costs {lm['ms_per_iteration'] / ex['ms_per_iteration']:.2f}× an exact one."]


def _linear_solver_lines(avail: pd.DataFrame, lin: pd.DataFrame) -> list[str]:
    """The linear solvers that load in this casadi build, and each finished one's time per
    iteration and objective against MUMPS's."""
    loads = avail[avail["loads"]]["linear_solver"].tolist() if not avail.empty else []
    fails = avail[~avail["loads"]]["linear_solver"].tolist() if not avail.empty else []
    out = [f"• Linear solvers that load in this casadi build: {', '.join(loads)}; "
           f"{len(avail) - len(loads)} others fail to load ({', '.join(fails)})."]
    done = lin[lin["outcome"] == FINISHED] if len(lin) else lin
    if len(done) and (done["linear_solver"] == "mumps").any():
        mu = done[done["linear_solver"] == "mumps"].iloc[0]
        for r in done[done["linear_solver"] != "mumps"].itertuples():
            out.append(f"  {r.linear_solver}: {r.status}, {r.iterations} iterations, {r.ms_per_iteration:.0f} "
                       f"ms/iteration ({r.ms_per_iteration / mu['ms_per_iteration']:.1f}× MUMPS's "
                       f"{mu['ms_per_iteration']:.0f} ms), objective {r.objective:.4g} (MUMPS {mu['objective']:.4g}).")
    return out


#: Issue 22's T9-track targets: Moco's time over gaitlib's, solve only and setup + solve.
MOCO_TARGETS = {"solve": 20.0, "setup + solve": 5.0}


def _moco_lines(mt: pd.DataFrame) -> list[str]:
    """The T9-track side by side: per scheme the median solve times and the speed-ups, the
    compiled per-node variant and the best converged variant against :data:`MOCO_TARGETS`
    (when the results file has them)."""
    def best(r):
        b, e = r.get("speed-up, solve (best converged gaitlib variant)", np.nan), \
            r.get("speed-up, setup + solve (best converged gaitlib variant)", np.nan)
        if not (np.isfinite(b) and np.isfinite(e)):
            return ""
        return (f"; the fastest converged gaitlib variant {b:.1f}× solve only (target ≥ {MOCO_TARGETS['solve']:g}×: "
                f"{'met' if b >= MOCO_TARGETS['solve'] else 'not met'}), {e:.1f}× setup + solve (target ≥ "
                f"{MOCO_TARGETS['setup + solve']:g}×: {'met' if e >= MOCO_TARGETS['setup + solve'] else 'not met'})")

    return ["• Against OpenSim Moco (T9-track), median solve times: " + "; ".join(
        f"{r['scheme']}: Moco {r['Moco solve (s)']:.2f} s, gaitlib {r['gaitlib solve (s)']:.2f} s = "
        f"{r['speed-up']:.1f}× (with IPOPT's default options {r['speed-up, gaitlib with IPOPT defaults']:.1f}×; "
        f"setup + solve {r['Moco setup + solve (s)']:.1f} s vs {r['gaitlib setup + solve (s)']:.1f} s{best(r)})"
        for _, r in mt.iterrows()) + "."]


def findings(scaling: dict, moco: dict, kkt: dict | None = None, fill: dict | None = None) -> list[str]:
    """The page's summary, one sentence per finding, computed from the stored results: the
    mesh scaling of each model against :data:`LINEAR_GROWTH` and the machine's share of it
    (``scaling``); one iteration's pieces at a fixed point (``kkt``, optional); the counted
    fill of the factorisation (``fill``, optional); the thesis mesh; exact Hessian vs L-BFGS
    and the linear solvers (``scaling``); OpenSim Moco (``moco``)."""
    table, fits = scaling_table(scaling), scaling_fits(scaling)
    out = _scaling_lines(table, fits) + _machine_share_lines(table, fits)
    if kkt is not None:
        out += _kkt_lines(kkt)
    if fill is not None:
        out += _fill_lines(fill, fits)
    out += _thesis_mesh_lines(table)
    out += _hessian_lines(hessian_table(scaling))
    out += _linear_solver_lines(*linear_solver_table(scaling))
    out += _moco_lines(moco_table(moco))
    return out
