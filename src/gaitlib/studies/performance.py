"""Performance (issue 8): the stored benchmark results as tables, and the growth-exponent fit.

Nothing here solves anything: the functions read the JSON files that the scripts in
``benchmarks/`` write (``scaling.json`` — :file:`benchmarks/bench_scaling.py`, ``gait.json``
— :file:`benchmarks/bench_gait.py`, ``moco_t9track.json`` —
:file:`benchmarks/bench_moco_t9track.py`), each of which records when and on which machine
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
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = ["results_dir", "load", "fit_power_law", "scaling_table", "scaling_fits", "hessian_table",
           "linear_solver_table", "moco_table", "gait_table", "measured_on"]

#: Runs of the scaling benchmark whose time per iteration is a measurement (the solver ran
#: to the end: converged or stopped by its own criterion), as opposed to "timeout"/"error".
FINISHED = "finished"


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
