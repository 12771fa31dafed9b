"""The Performance page's arithmetic (gaitlib.studies.performance): the power-law fit
recovers known exponents, the tables keep failed runs visible and fit finished runs only."""

from __future__ import annotations

import numpy as np
import pytest

from gaitlib.studies import performance as perf


def test_power_law_fit_recovers_exponent_and_prefactor():
    n = np.array([25, 50, 100, 200, 400])
    f = perf.fit_power_law(n, 0.7 * n ** 1.0)
    assert f["exponent"] == pytest.approx(1.0, abs=1e-12) and f["prefactor"] == pytest.approx(0.7, rel=1e-12)
    assert f["r2"] == pytest.approx(1.0) and f["n_points"] == 5
    rng = np.random.default_rng(0)
    y = 3.0 * n ** 1.3 * np.exp(rng.normal(0, 0.05, n.size))
    f = perf.fit_power_law(n, y)
    assert abs(f["exponent"] - 1.3) < 3 * f["exponent_se"] + 1e-3 and 0 < f["exponent_se"] < 0.1
    # fewer than two usable points: no exponent; non-positive values are ignored
    assert np.isnan(perf.fit_power_law([100], [1.0])["exponent"])
    assert perf.fit_power_law([10, 20, 40], [1.0, 0.0, 4.0])["exponent"] == pytest.approx(1.0)


def _doc():
    def run(model, n, ms, outcome="finished", status="Solve_Succeeded", group="mesh", **kw):
        it = 100
        return {"group": group, "model": model, "n_intervals": n, "degree": 5, "nodes": 5 * n, "outcome": outcome,
                "status": status, "success": status == "Solve_Succeeded", "iterations": it,
                "solve_s": ms * it / 1e3, "ms_per_iteration": ms, "function_evals_ms_per_iteration": ms / 2,
                "ipopt_rest_ms_per_iteration": ms / 2, "build_s": 1e-3 * n ** 2, "loadavg_start": [2.0, 1.0, 1.0],
                "hessian": "exact", "linear_solver": "mumps", **kw}

    return {"meta": {"measured": "2026-11-22T09:00:00+00:00", "machine": {"cpu": "AMD EPYC", "cores": 2},
                     "loadavg_start": [2.5, 2.0, 1.5], "note": "shared machine"},
            "runs": [run("SK", 10, 20.0), run("SK", 20, 40.0), run("SK", 40, 80.0),
                     run("SK", 80, float("nan"), outcome="timeout", status=None),
                     run("MSK", 10, 30.0, status="Maximum_Iterations_Exceeded"), run("MSK", 20, 60.0 * 2 ** 0.5),
                     run("SK", 20, 20.0, group="hessian", hessian="limited-memory")],
            "linear_solvers_available": [{"linear_solver": "mumps", "loads": True}]}


def test_scaling_fits_use_finished_runs_and_report_linear_growth():
    doc = _doc()
    fits = perf.scaling_fits(doc).set_index(["model", "quantity"])
    sk = fits.loc[("SK", "time per iteration")]
    assert sk["exponent"] == pytest.approx(1.0) and sk["points"] == 3 and sk["nodes"] == "50, 100, 200"
    assert fits.loc[("SK", "build time"), "exponent"] == pytest.approx(2.0)
    # a run stopped by IPOPT (max iterations) is a timing measurement; a timeout is not
    assert fits.loc[("MSK", "time per iteration"), "exponent"] == pytest.approx(1.5)
    table = perf.scaling_table(doc)
    assert len(table) == 6 and table["load (1 min) at start"].eq(2.0).all()  # the timeout stays listed
    assert list(perf.hessian_table(doc)["hessian"]) == ["limited-memory"]
    assert "2026-11-22" in perf.measured_on(doc) and "AMD EPYC (2 cores)" in perf.measured_on(doc)
    assert "2.50" in perf.measured_on(doc) and "shared machine" in perf.measured_on(doc)


def test_missing_results_name_the_file_and_the_script(tmp_path):
    with pytest.raises(FileNotFoundError, match="bench_scaling.py"):
        perf.load("scaling", root=tmp_path)


def test_load_note_says_shared_only_when_the_machine_was_busy():
    """bench_scaling's note follows the recorded load averages: quiet only if every run
    started below QUIET_LOAD."""
    bs = _bench("bench_scaling")
    doc = {"meta": {"loadavg_start": [0.9, 0.8, 0.7]}, "runs": [{"loadavg_start": [1.05, 1, 1]}, {"loadavg_start": [0.97, 1, 1]}]}
    assert "no other job" in bs._load_note(doc) and "1.05" in bs._load_note(doc)
    doc["runs"].append({"loadavg_start": [2.4, 2, 2]})
    assert bs._load_note(doc) == bs.SHARED_NOTE


def test_kkt_and_msk_profile_tables_keep_errors_out_and_units_in_names():
    kkt = {"rows": [{"model": "SK", "n_intervals": 5, "nodes": 25, "kkt_dim": 100, "kkt_nnz": 900, "hessian_ms": 1.0,
                     "jacobian_ms": 0.5, "other_evals_ms": 0.5, "evaluations_ms": 2.0, "factorisation_ms": 1.0,
                     "factor_solve_ms": 1.2, "iteration_ms": 3.2},
                    {"model": "SK", "n_intervals": 10, "error": "boom"}],
           "fits": [{"model": "SK", "quantity": "iteration_ms", "exponent": 1.0}]}
    rows, fits = perf.kkt_scaling_tables(kkt)
    assert list(rows["n_intervals"]) == [5] and "iteration_ms" in rows.columns and len(fits) == 1
    prof = {"runs": [{"variant": "default", "status": "Solve_Succeeded", "iterations": 10, "solve_s": 2.0,
                      "ms_per_iteration": 200.0, "hessian_s": 0.5, "other_evals_s": 0.3, "linear_systems_s": 1.0,
                      "rest_s": 0.2, "perturbed_iterations": 4, "objective": 1.0}],
            "graph_sizes": [{"model": "SK", "n_variables": 10, "n_constraints": 8, "constraint_instructions": 100,
                             "hessian_instructions": 1000, "hessian_nnz": 30}]}
    runs, sizes = perf.msk_profile_tables(prof)
    assert runs.loc[0, "solve (s)"] == 2.0 and runs.loc[0, "iterations with Hessian perturbation"] == 4
    assert sizes.loc[0, "Hessian SX instructions"] == 1000


def _bench(name):
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_kkt_fill_counts_of_known_patterns():
    """bench_kkt_fill's symbolic counts (strictly lower L; the unit diagonal is not stored) on
    patterns with a known factor: a tridiagonal (path) matrix factorises without fill (n − 1
    entries; columns of at most 2, as the ordering picks the elimination order); closing the path into a cycle (the
    periodic constraint's shape) adds fill, linear in n; a dense arrow (one row coupled to
    all) adds none when that row is eliminated last."""
    import casadi as ca

    kf = _bench("bench_kkt_fill")
    n = 40
    path = ca.Sparsity.band(n, 1) + ca.Sparsity.band(n, -1) + ca.Sparsity.diag(n)
    f = kf.fill(path)
    assert f["L_nnz"] == n - 1 and f["L_max_column"] <= 2 and n - 1 <= f["flops_proxy"] <= 4 * (n - 1)
    r, c = path.get_triplet()
    cyc = ca.Sparsity.triplet(n, n, list(r) + [0, n - 1], list(c) + [n - 1, 0])
    g = kf.fill(cyc)
    assert g["L_nnz"] > f["L_nnz"] and g["flops_proxy"] > f["flops_proxy"]
    assert g["L_nnz"] <= 2 * n  # a cycle's minimum-degree fill is linear: one extra entry per column at most
    arrow = ca.Sparsity.diag(n) + ca.Sparsity.triplet(n, n, [0] * n + list(range(n)), list(range(n)) + [0] * n)
    a = kf.fill(arrow)
    assert a["L_nnz"] == n - 1


def test_eval_floor_per_node_hessian_blocks_and_floors():
    """bench_eval_floor: the per-node Hessian of μᵀẋ + νᵀg + aᵀL equals the analytic one; the
    block check accepts a node-block-diagonal pattern and counts a coupling between nodes;
    the floors are the profile's linear systems + rest plus the (scaled) evaluations."""
    from types import SimpleNamespace

    import casadi as ca

    ef = _bench("bench_eval_floor")
    x, u, p, t, d = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 0), ca.SX.sym("t"), ca.SX.sym("d", 1)
    node = ca.Function("node", [x, u, p, t, d], [ca.vertcat(x[1], x[0] * u), u ** 3, (x[0] - d) ** 2 * t])
    hess, jac = ef.per_node_functions(node)
    xv, uv, tv, dv, mu, nu, a = np.array([0.3, -1.2]), 0.7, 2.0, 0.1, np.array([5.0, -2.0]), 3.0, 0.5
    H = np.asarray(ca.DM(hess(xv, uv, [], tv, dv, mu, nu, a))).copy()
    # z = (x0, x1, u): ∂²/∂x0² = 2 a t; ∂²/∂x0∂u = μ2; ∂²/∂u² = 6 ν u; upper triangle only
    expected = np.array([[2 * a * tv, 0, mu[1]], [0, 0, 0], [0, 0, 6 * nu * uv]])
    assert np.allclose(H, expected, rtol=1e-14, atol=0)
    Y, J = jac(xv, uv, [], tv, dv)
    assert np.allclose(np.asarray(J), [[0, 1, 0], [uv, 0, xv[0]], [0, 0, 3 * uv ** 2], [2 * (xv[0] - dv) * tv, 0, 0]])

    # two collocation nodes (state nodes 1, 2; node 0 is the Radau start), 1 state and 1 control each
    lay = SimpleNamespace(ix=np.array([[0, 1, 3]]), iu=np.array([[2, 4]]))
    mesh = SimpleNamespace(colloc_state_nodes=[1, 2])
    ok = ca.Sparsity.triplet(5, 5, [1, 1, 2, 3, 3, 4], [1, 2, 2, 3, 4, 4])
    assert ef.hessian_blocks(ok, lay, mesh) == {"hessian_nnz": 6, "hessian_nnz_outside_node_blocks": 0,
                                                "hessian_nnz_per_node_block_max": 3}
    bad = ca.Sparsity.triplet(5, 5, [1, 1, 0], [1, 3, 0])  # x1–x3 couples nodes; x0 is in no block
    assert ef.hessian_blocks(bad, lay, mesh)["hessian_nnz_outside_node_blocks"] == 2

    m = {"mapped_compiled_ms": {"hessian": 10.0}, "solver_function_ms": {"nlp_hess_l": 40.0}}
    prof = {"measured": "x", "runs": [{"variant": "default", "iterations": 200, "solve_s": 30.0, "hessian_s": 8.0,
                                       "other_evals_s": 6.0, "linear_systems_s": 13.0, "rest_s": 3.0}]}
    fl = ef.floors(m, prof)
    assert fl["floor_evaluations_free_s"] == 16.0
    assert fl["floor_hessian_compiled_s"] == pytest.approx(16.0 + 6.0 + 200 * 0.010)
    assert fl["floor_all_compiled_s"] == pytest.approx(16.0 + 14.0 * 0.25)
    assert fl["evaluation_budget_ms_per_iteration"] == pytest.approx(1e3 * 4.0 / 200)
    tab = perf.eval_floor_table({"floors": fl})
    assert list(tab["≤ 20 s"]) == [False, True, False, True]


def test_mumps_orderings_parses_mumps_analysis_reports():
    """bench_mumps_orderings reads MUMPS's analysis report (format of MUMPS 5.8.2, as printed
    through IPOPT with mumps_print_level 2): one record per JOB = 1 call, in order; factor and
    solve calls (JOB = 2, 3) are not analyses; a report missing a count is an error."""
    mo = _bench("bench_mumps_orderings")

    def block(n, nnz, name, used, entries, front, flops):
        return (f"\nEntering DMUMPS 5.8.2 from C interface with JOB, N, NNZ =   1        {n}          {nnz}\n"
                f" Ordering based on {name} \n -- (20) Number of entries in factors (estim.)  =          {entries}\n"
                f" --  (5) Maximum frontal size      (estimated)  =             {front}\n"
                f" --  (7) Ordering option effectively used       =               {used}\n"
                f" RINFOG(1) Operations during elimination (estim)= {flops}\n"
                f"Entering DMUMPS 5.8.2 from C interface with JOB, N, NNZ =   2        {n}          {nnz}\n")

    log = block(2540, 21574, "AMD", 0, 260837, 281, "3.602D+07") + block(2540, 21574, "METIS", 5, 250000, 120, "4.198D+07")
    a = mo.parse_analyses(log)
    assert [r["ordering_name"] for r in a] == ["AMD", "METIS"] and [r["ordering_used"] for r in a] == [0, 5]
    assert a[0]["flops"] == 3.602e7 and a[1]["max_front"] == 120 and a[0]["factor_entries"] == 260837
    assert a[0]["kkt_n"] == 2540 and a[0]["kkt_nnz_lower"] == 21574
    with pytest.raises(ValueError, match="RINFOG|flops"):
        mo.parse_analyses(log.replace("RINFOG(1)", "RINFOG(9)"))


def test_fatrop_findings_compare_time_per_iteration_and_the_floor():
    """bench_fatrop.py's rows in sentences: FATROP's time per iteration against IPOPT's and
    the time at IPOPT's iteration count, computed by hand here."""
    rows = [
        {"model": "SK", "mesh": "20 x 5", "solver": "ipopt", "status": "Solve_Succeeded", "iterations": 500,
         "solve_s": 40.0, "ms_per_iteration": 80.0, "objective": 0.2, "max_violation": 1e-8},
        {"model": "SK", "mesh": "20 x 5", "solver": "ipopt (integral form)", "status": "Solve_Succeeded",
         "iterations": 400, "solve_s": 44.0, "ms_per_iteration": 110.0, "objective": 0.19, "max_violation": 1e-8},
        {"model": "SK", "mesh": "20 x 5", "solver": "fatrop", "status": "Maximum_Iterations_Exceeded",
         "iterations": 21, "solve_s": 42.0, "ms_per_iteration": 2000.0, "objective": 7.0, "max_violation": 300.0,
         "N": 20, "stage_nx": 66, "stage_nu": 242, "stage_ng": 187},
    ]
    (line,) = perf.fatrop_findings({"rows": rows})
    assert "500 iterations, 40.0 s (80 ms per iteration)" in line
    assert "20 stages (66 states, 242 controls and 187 constraints per stage)" in line
    assert "2000 ms per iteration, 25.0× IPOPT's" in line
    assert "that is 1000 s against IPOPT's 40 s" in line  # 2.0 s × 500 iterations
    assert "integral form: Solve_Succeeded in 400 iterations, 44.0 s (110 ms per iteration), objective 0.1900 " \
           "against 0.2000" in line
    assert list(perf.fatrop_table({"rows": rows}).columns[:4]) == ["model", "mesh", "solver", "status"]


def test_defect_form_findings_pair_the_forms_per_problem():
    rows = [{"problem": "MSK DT", "form": f, "mesh": "20 x 5", "status": "Solve_Succeeded", "iterations": it,
             "solve_s": t, "ms_per_iteration": 1e3 * t / it, "objective": o}
            for f, it, t, o in (("differential", 500, 50.0, 0.11), ("integral", 400, 60.0, 0.10))]
    rows.append({**rows[0], "problem": "lonely"})
    rows += [{**rows[0], "problem": "stuck"}, {**rows[1], "problem": "stuck", "status": "Maximum_Iterations_Exceeded"}]
    line, stuck = perf.defect_form_findings({"rows": rows})
    assert stuck.endswith("no time ratio: the integral form did not converge.") and "× the time" not in stuck
    assert line.startswith("• MSK DT (20 x 5): differential Solve_Succeeded, 500 iterations, 50.0 s (100 ms each)")
    assert "integral Solve_Succeeded, 400 iterations, 60.0 s (150 ms each), objective 0.1000 — 1.20× the time." in line
