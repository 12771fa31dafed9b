"""Performance (issue 8): the stored benchmark results as tables, and the growth-exponent fit.

Nothing here solves anything: the functions read the JSON files that the scripts in
``benchmarks/`` write (``scaling.json`` — :file:`benchmarks/bench_scaling.py`, ``gait.json``
— :file:`benchmarks/bench_gait.py`, ``moco_t9track.json`` —
:file:`benchmarks/bench_moco_t9track.py`, ``thesis_times.json`` —
:file:`benchmarks/bench_thesis_times.py`), each of which records when and on which machine
it was measured.

Functions
---------
:func:`results_dir`        where the benchmark results are (``benchmarks/results``).
:func:`load`               one results file as a dict.
:func:`fit_power_law`      least-squares fit of ``y = c · n^b`` on log–log axes.
:func:`scaling_table`      per model × mesh: iterations, wall times, time per iteration.
:func:`scaling_fits`       the growth exponents of time per iteration (and its parts) vs nodes.
:func:`hessian_table`, :func:`linear_solver_table`, :func:`moco_table`, :func:`gait_table`
:func:`measured_on`        one sentence: date, machine, load, from a file's metadata.

Thesis times (issue 8 item 1; :file:`benchmarks/bench_thesis_times.py`):

:func:`thesis_reference_times`  every compute time the thesis prints, as labelled references.
:func:`parse_duration`     "6 min (…)" → 360 s.
:func:`time_row`, :func:`missing_row`  one row of the table (speed-up only for converged runs).
:func:`thesis_times_table`, :func:`thesis_times_summary`, :func:`thesis_times_by_chapter`,
:func:`thesis_times_figure`  the stored table for the page.
:func:`no_solving`         context manager: any attempt to solve raises :class:`NotInCache`.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = ["results_dir", "load", "load_optional", "fit_power_law", "scaling_table", "scaling_fits", "hessian_table",
           "linear_solver_table", "moco_table", "gait_table", "msk_profile_tables", "eval_floor_table", "kkt_scaling_tables", "measured_on", "ThesisTime", "THESIS_SILENT",
           "thesis_reference_times", "parse_duration", "time_row", "missing_row", "NOT_COMPUTED", "NO_CACHE",
           "TIME_COLUMNS", "thesis_times_table", "thesis_times_summary", "thesis_times_by_chapter",
           "thesis_times_figure", "NotInCache", "no_solving", "md_table", "write_report"]

#: Runs of the scaling benchmark whose time per iteration is a measurement (the solver ran
#: to the end: converged or stopped by its own criterion), as opposed to "timeout"/"error".
FINISHED = "finished"

#: Status of a thesis-times row whose optimisation is not in the cache (``--cached-only``).
NOT_COMPUTED = "not computed yet"
#: Status of a thesis-times row of a study that has no solution cache.
NO_CACHE = "not measured (no solution cache)"


def results_dir() -> Path:
    """``$GAITLIB_BENCHMARK_RESULTS`` if set, else ``benchmarks/results`` of the source
    checkout this package is imported from."""
    import os

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
    speed-up (Moco / gaitlib), also with IPOPT's default options and end to end."""
    res = load("moco_t9track") if res is None else res
    rows = []
    for scheme, s in res["speedups"].items():
        e2e = s.get("end_to_end_median", {})
        rows.append({"scheme": scheme, "Moco solve (s)": s["moco_solve_median"],
                     "gaitlib solve (s)": s["gaitlib_solve_median"], "speed-up": s["speedup"],
                     "speed-up, gaitlib with IPOPT defaults": s.get("speedup_ipopt_defaults", np.nan),
                     "Moco setup + solve (s)": e2e.get("moco", np.nan),
                     "gaitlib setup + solve (s)": e2e.get("gaitlib", np.nan),
                     "all converged": s.get("all_succeeded")})
    return pd.DataFrame(rows)


def gait_table(res: dict | None = None) -> pd.DataFrame:
    """The full-mesh natural-gait solves of ``bench_gait.py`` (thesis times beside, labelled)."""
    res = load("gait") if res is None else res
    cols = ["run", "status", "iterations", "solve_s", "ms_per_iteration", "function_evals_s", "ipopt_rest_s",
            "build_s", "objective", "thesis"]
    df = pd.DataFrame(res["rows"])
    return df[[c for c in cols if c in df.columns]].rename(columns={"thesis": "thesis time (GPOPS-II, labelled)"})


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
    the ≤ 20 s target. Rows: measured; evaluations free (linear systems + rest); Hessian
    compiled to C (per-node, measured C/VM speed), the other evaluations as measured; every
    evaluation at the Hessian's C/VM ratio."""
    f = res["floors"]
    ratio = f["compiled_to_vm_hessian_ratio"]
    rows = [("measured (book options, SX virtual machine)", f["solve_s"]),
            ("evaluations free: linear systems + rest", f["floor_evaluations_free_s"]),
            (f"Hessian compiled (C/VM {ratio:.2f}), other evaluations as measured", f["floor_hessian_compiled_s"]),
            (f"every evaluation compiled at the Hessian's ratio {ratio:.2f}", f["floor_all_compiled_s"])]
    return pd.DataFrame([{"assumption": a, "solve time (s)": v, "≤ 20 s": v <= 20.0} for a, v in rows])


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
