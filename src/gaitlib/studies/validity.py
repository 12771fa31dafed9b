"""The physical validity gates (:mod:`gaitlib.validity`) of every stored solution the book uses.

:func:`book_solutions` loads them through the chapters' own study functions (from the
solution store: nothing is solved when the store is current), :func:`book_gates` checks
each and returns one row per solution × check; :func:`gates_matrix` pivots it to one row
per solution and one column per check (value, with ✗ where it fails).

Run as a script (``python -m gaitlib.studies.validity [--out CSV]``) to print the summary.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterable

import pandas as pd

from .. import validity
from . import gait
from . import jump
from . import contact_id as ci
from . import msk
from . import predictive as pr

__all__ = ["CHAPTERS", "book_solutions", "book_gates", "gates_matrix", "summary"]

#: The chapters whose solutions :func:`book_solutions` loads.
CHAPTERS = ("ch2", "ch3", "ch4", "ch5", "ch6", "ch7")


def book_solutions(chapters: Iterable[str] = CHAPTERS) -> dict[str, object]:
    """Label → solution for the runs the book's chapters show, loaded the way each notebook
    loads them (``progress=False``, ``serial=True`` for the sweeps, so cache hits stay in
    this process). Labels: ``"ch2 SK"``, ``"ch3 toe"``, ``"ch4 (b)"``, ``"ch6 NMSK FP"``,
    ``"ch7 MSK DT_Fast"``, …; ``"… [thesis guess]"`` for the runs the chapters show from
    the thesis's partial NMSK guess, ``"… [thesis's reading]"`` for the problem as printed
    beside the book's reading (:data:`gaitlib.studies.gait.READINGS`)."""
    chapters = set(chapters)
    out: dict[str, object] = {}
    if "ch2" in chapters:
        for m, eq in (("SK", "Eq4.11"), ("MSK", "Eq5.33")):
            out[f"ch2 {m} {eq}"] = gait.natural_gait(m, reading="book")
            out[f"ch2 {m} {eq} [thesis's reading]"] = gait.natural_gait(m, reading="thesis")
    if "ch3" in chapters:
        for n in ("toeless", "toe", "ellipsoid"):
            out[f"ch3 {n}"] = jump.solve(n, use_cache=True)
    if "ch4" in chapters:
        a = ci.trajectory_optimization()
        b = ci.optimal_control_multistart()
        c = ci.optimal_control_body(warm=b)
        cw = ci.optimal_control_body(spec=ci.spec_c(contact_bounds="widened"), warm=b)
        bt = ci.optimal_control(ci.spec_b(reading="thesis"))
        ct = ci.optimal_control_body(ci.spec_c(reading="thesis"), warm=bt)
        out.update({"ch4 (a)": a, "ch4 (b)": b, "ch4 (c)": c, "ch4 (c) widened": cw,
                    "ch4 (b) [thesis's reading]": bt, "ch4 (c) [thesis's reading]": ct})
    if "ch5" in chapters:
        for m, eq in (("MSK", "Eq5.33"), ("NMSK", "Eq5.55")):
            out[f"ch5 {m} {eq}"] = msk.solve(m, reading="book")
            out[f"ch5 {m} {eq} [thesis's reading]"] = msk.solve(m, reading="thesis")
    if "ch6" in chapters or "ch7" in chapters:
        runs = []
        if "ch6" in chapters:
            runs += [("ch6", pr.cost_function_study(("MSK", "NMSK"), pr.CH6_COSTS, progress=False, serial=True), ""),
                     ("ch6", pr.cost_function_study(("NMSK",), pr.CH6_COSTS, progress=False, serial=True,
                                                    guess={"NMSK": "thesis"}), " [thesis guess]")]
        if "ch7" in chapters:
            runs += [("ch7", pr.speed_study(("MSK", "NMSK"), pr.CH7_CLASSES, progress=False, serial=True), ""),
                     ("ch7", pr.speed_study(("NMSK",), pr.CH7_CLASSES, progress=False, serial=True,
                                            guess={"NMSK": "thesis"}), " [thesis guess]")]
        for ch, res, tag in runs:
            for name, rec in res.records.items():
                sol = res.solutions.get(name)
                out[f"{ch} {name}{tag}"] = sol if sol is not None else rec
    return out


def _gates(label: str, sol) -> validity.Gates:
    if hasattr(sol, "ok") and hasattr(sol, "status") and not hasattr(sol, "spec"):  # a run that returned nothing
        return validity.check_frames(status=str(sol.status), kind="predictive", name=label,
                                     notes={"strength": "no solution", "swing_load": "no solution",
                                            "double_support": "no solution", "residual": "no solution",
                                            "periodicity": "no solution"})
    return validity.check(sol, name=label)


def book_gates(chapters: Iterable[str] = CHAPTERS, solutions: dict | None = None) -> pd.DataFrame:
    """One row per (solution, check): ``solution, check, value, threshold, unit, passed,
    note`` plus ``valid`` (the solution's overall verdict) and ``label``
    (:meth:`gaitlib.validity.Gates.label`)."""
    sols = book_solutions(chapters) if solutions is None else solutions
    parts = []
    for label, sol in sols.items():
        g = _gates(label, sol)
        t = g.table.copy()
        t.insert(0, "solution", label)
        t["valid"] = g.passed
        t["label"] = g.label()
        parts.append(t)
    return pd.concat(parts, ignore_index=True)


def gates_matrix(gates: pd.DataFrame) -> pd.DataFrame:
    """Solution × check: the measured value (rounded, with its unit; ``✗`` prefix where the
    check fails, ``–`` where it does not apply) and the solution's label."""
    def cell(r):
        if r.passed is None or (isinstance(r.passed, float) and pd.isna(r.passed)):
            return "–"
        v = r.value if isinstance(r.value, str) else validity._fmt(r.value)
        return ("✗ " if validity._failed(r.passed) else "") + (f"{v} {r.unit}".strip() if not isinstance(r.value, str)
                                                     else ("ok" if r.passed else v))
    m = gates.assign(cell=[cell(r) for r in gates.itertuples()]).pivot(index="solution", columns="check",
                                                                        values="cell")
    m = m[[c for c in validity.CHECKS if c in m.columns]]
    labels = gates.drop_duplicates("solution").set_index("solution")["label"]
    m["verdict"] = labels
    return m.loc[list(dict.fromkeys(gates["solution"]))]


def summary(gates: pd.DataFrame) -> pd.DataFrame:
    """Per check: how many solutions it applies to, pass, fail."""
    g = gates[gates["passed"].notna()]
    return g.groupby("check", sort=False)["passed"].agg(applies="size", passed="sum").assign(
        failed=lambda d: d["applies"] - d["passed"])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description="Validity gates of the book's stored solutions")
    ap.add_argument("--chapters", default=",".join(CHAPTERS))
    ap.add_argument("--out", default=None, help="CSV of the long table (solution × check)")
    args = ap.parse_args(argv)
    gates = book_gates(args.chapters.split(","))
    if args.out:
        gates.to_csv(args.out, index=False)
    with pd.option_context("display.width", 250, "display.max_columns", 20, "display.max_colwidth", 60,
                           "display.max_rows", 200):
        print(gates_matrix(gates).drop(columns="verdict"))
        print()
        print(gates_matrix(gates)["verdict"].to_string())
        print()
        print(summary(gates))


if __name__ == "__main__":
    main()
