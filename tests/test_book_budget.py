"""``benchmarks/bench_book_budget.py``: the stored solutions' statistics read from each of the
store's formats, the fastest recorded pace per class of problem, and the per-chapter table's
arithmetic checked by hand on made-up rows."""

import json

import pytest

import bench_book_budget as bb
from gaitlib.studies import performance as perf


def _first(kind: str, marker: str) -> str:
    for d in sorted((bb.STORE / kind).iterdir()):
        if (d / marker).exists():
            return f"{kind}/{d.name}"
    pytest.skip(f"no {kind} entry with {marker} in the store")


@pytest.mark.parametrize("kind, marker", [("gait", "summary.json"), ("gap", "summary.json"),
                                          ("contact_id", "summary.json"), ("contact_id", "result.json"),
                                          ("jump", "solution.json")])
def test_entry_stats_reads_every_store_format(kind, marker):
    entry = _first(kind, marker)
    solves = bb.entry_stats(entry)
    raw = json.loads((bb.STORE / entry / marker).read_text())
    if marker == "summary.json":
        assert len(solves) == 1
        assert solves[0]["iterations"] == raw["stats"]["iterations"]
        assert solves[0]["solve_s"] == raw["stats"]["solve_time_s"]
    elif marker == "result.json":  # one solve per local start, the build counted once
        assert [s["iterations"] for s in solves] == [r["iterations"] for r in raw["rows"]]
        assert sum(s["build_s"] for s in solves) == raw["build_s"]
    else:
        assert solves[0]["iterations"] == raw["iterations"] and solves[0]["solve_s"] == raw["solve_time"]
    assert all(s["kind"] == kind and s["solve_s"] >= 0 for s in solves)


def test_fastest_pace_counts_long_solves_of_large_classes_only():
    def e(kind, its, t):
        return {"kind": kind, "model": "SK", "mesh": "10 × 3", "iterations": its, "solve_s": t}

    entries = [e("gap", 100, 5.0), e("gap", 200, 6.0), e("gap", 50, 4.0), e("gap", 10, 0.01),  # 0.001 s/it: too short
               e("gait", 100, 1.0), e("gait", 100, 2.0)]                                     # only two solves
    pace = bb.fastest_pace(entries)
    assert pace == {("gap", "SK", "10 × 3"): pytest.approx(0.03)}  # 6 s / 200 it


def test_budget_table_sums_and_hours():
    rows = [{"chapter": "a", "solves": 2, "converged": 1, "iterations": 300, "build_s": 3600.0, "solve_s": 7200.0,
             "recorded_s": 10800.0, "paced_s": 9000.0, "compiled_s": 5400.0, "evals_free_s": 3600.0,
             "evals_free_2_workers_s": 1800.0},
            {"chapter": "b", "solves": 0, "converged": 0, "iterations": 0, "build_s": 0.0, "solve_s": 0.0,
             "recorded_s": 0.0, "paced_s": 0.0, "compiled_s": 0.0, "evals_free_s": 0.0,
             "evals_free_2_workers_s": 0.0},
            {"chapter": "c", "solves": 1, "converged": 1, "iterations": 100, "build_s": 0.0, "solve_s": 1800.0,
             "recorded_s": 1800.0, "paced_s": 1800.0, "compiled_s": 900.0, "evals_free_s": 900.0,
             "evals_free_2_workers_s": 450.0}]
    res = {"rows": rows, "ratios": {"eval_share": {"SK": 0.3}}}
    t = perf.book_budget_table(res)
    assert list(t.index) == ["a", "c", "whole book"]  # chapters that solve nothing are left out
    total = t.iloc[-1]
    assert total["solves"] == 3 and total["iterations"] == 400 and t["solves"].dtype.kind == "i"
    assert total["recorded (h)"] == pytest.approx(3.5) and total["evaluations free, 2 workers (h)"] == pytest.approx(0.625)
    text = "\n".join(perf.book_budget_findings(res, target_s=45 * 60))
    assert "0.6 h — 0.8× the target of 45 min, which is met." in text
    assert "not reachable" in "\n".join(perf.book_budget_findings(res, target_s=30 * 60))


def test_workers_findings_scale_the_floor_by_the_measured_speed_up():
    res = {"summary": [{"workload": "w", "1 worker (s)": 100.0, "2 workers (s)": 62.5, "speed-up": 1.6,
                        "efficiency": 0.8}]}
    budget = {"rows": [{"evals_free_s": 3600.0 * 8}]}
    text = "\n".join(perf.workers_findings(res, budget, target_s=3600.0))
    assert "w 100 → 62 s (1.60×, efficiency 80%)" in text
    assert "floor with the evaluations free is 5.0 h on two workers (5.0× the target of 60 min)" in text


def test_warm_chain_findings_separate_other_optima_from_failures():
    def row(cls, start, status, its, rms=None):
        return {"model": "MSK", "class": cls, "start": start, "status": status, "iterations": its, "solve_s": 10.0,
                "build_s": 1.0, "objective": 0.1, "gates": "valid", "rms_from_book_deg": rms}

    res = {"rows": [row("Slow", "book", "Solve_Succeeded", 800), row("Slow", "chain: x", "Solve_Succeeded", 400, 2.26),
                    row("Fast", "book", "Solve_Succeeded", 700), row("Fast", "chain: y", "Solve_Succeeded", 600, 0.2),
                    row("VeryFast", "book", "Solve_Succeeded", 900),
                    row("VeryFast", "chain: z", "Infeasible_Problem_Detected", 165, 30.0)],
           "summary": [{"model": "MSK", "start": "book", "converged": 3, "valid": 3, "runs": 3, "iterations": 2400,
                        "solve_s": 30.0},
                       {"model": "MSK", "start": "chain", "converged": 2, "valid": 2, "runs": 3, "iterations": 1165,
                        "solve_s": 30.0}]}
    (line,) = perf.warm_chain_findings(res)
    assert "another solution (joint angles ≥ 1° RMS from the book's run): Slow (2.3°)." in line
    assert "Not converged: VeryFast (Infeasible_Problem_Detected)." in line and "Fast (0.2" not in line
    assert "the chain 2/3 converged, 2 valid, 1165 iterations" in line


def test_targets_table_marks_each_target_from_its_results():
    e2e = {"gait": [{"variant": "graph", "status": "Solve_Succeeded", "e2e_s": 30.0},
                    {"variant": "nodes", "status": "Maximum_Iterations_Exceeded", "e2e_s": 5.0}],  # not a result
           "gap": [{"variant": "graph", "status": "ok", "e2e_s": 59.0}]}
    moco = {"speedups": {"trapezoidal": {"speedup_e2e": {"tool": "a", "speedup": 5.0},
                                         "speedup_best": {"tool": "b", "speedup": 19.9}}}}
    budget = {"rows": [{"evals_free_s": 2 * 45 * 60.0}]}
    workers = {"summary": [{"speed-up": 1.5}, {"speed-up": 2.0}]}
    t = perf.targets_table(e2e, moco, budget, workers).set_index("target")
    assert bool(t.loc["the whole book from an empty cache", "met"])  # 90 min / 2.0 = 45 min
    assert "two workers at 2.00×" in t.loc["the whole book from an empty cache", "measured"]
    assert not t.loc["MSK DT Free, build + solve", "met"] and "30.0 s (graph)" in t.loc["MSK DT Free, build + solve", "measured"]
    assert bool(t.loc["gaitlib gap on a new CSV", "met"])
    assert bool(t.loc["T9-track vs Moco, trapezoidal, setup + solve", "met"])
    assert not t.loc["T9-track vs Moco, trapezoidal, solve", "met"]
