"""The rows of the thesis-times table that ``bench_thesis_times.py`` writes: every
optimisation the book runs beside the compute time the thesis prints for it.

:func:`thesis_reference_times`  every compute time the thesis prints, as labelled references.
:func:`parse_duration`          "6 min (…)" → 360 s.
:func:`time_row`, :func:`missing_row`  one row of the table (speed-up only for converged runs).

The book reads the stored table with :mod:`gaitlib.studies.performance`, whose status
values :data:`NOT_COMPUTED` and :data:`NO_CACHE` these rows use.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from gaitlib.studies import contact_id, msk, predictive
from gaitlib.studies.performance import NO_CACHE, NOT_COMPUTED

__all__ = ["ThesisTime", "THESIS_SILENT", "thesis_reference_times", "parse_duration", "time_row", "missing_row",
           "TIME_COLUMNS", "NOT_COMPUTED", "NO_CACHE"]


@dataclass(frozen=True)
class ThesisTime:
    """A compute time the thesis prints: ``seconds`` (s) and ``label`` (the value as printed,
    with its section or table). GPOPS-II / MATLAB on an Intel i7-6700 (3.4 GHz, 16 GB),
    IPOPT in first-derivative mode, tolerance 1e-5 (thesis Secs 4.3.2, 5.2.1, 6.1, 7.1)."""

    seconds: float
    label: str


#: Optimisations for which the thesis prints no compute time (the thesis column stays empty).
THESIS_SILENT = {
    "ch02 SK": "the thesis prints no time for SK tracking with the contact parameters fixed; its 11 min "
               "(Sec 4.3.3) is with the 39 contact parameters identified — the Ch 4 (b) row",
    "ch03": "Ch 3 prints no solve times for the jumps",
    "ch05 MTG": "Sec 5.1 prints no time for the MTG parameter identification",
}

#: Where Ch 5's hours (:data:`gaitlib.studies.msk.THESIS_HOURS`) are printed.
_CH5_SOURCE = {"MSK": "Sec 5.2.2", "NMSK": "Sec 5.3.5"}

_DURATION = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*(s|min|h|hrs?|hours?)\b", re.IGNORECASE)

#: Columns of the thesis-times table, in order.
TIME_COLUMNS = ("chapter", "run", "study_call", "n_solves", "status", "converged", "iterations", "build_s",
                "solve_s", "wall_s", "ms_per_iteration", "thesis_time", "thesis_time_s", "speedup", "from_cache",
                "solved_at", "cache_entry", "note")


def parse_duration(text: str) -> float:
    """Seconds of a printed duration at the start of ``text`` ("6 min (Sec 4.3.3, …)" → 360,
    "5 h (…)" → 18000, "30 s" → 30). Raises ValueError if ``text`` does not start with one."""
    m = _DURATION.match(text)
    if m is None:
        raise ValueError(f"no duration at the start of {text!r}")
    unit = m.group(2).lower()
    scale = 1.0 if unit == "s" else 60.0 if unit == "min" else 3600.0
    return float(m.group(1)) * scale


def _hours(h: float) -> str:
    return f"{h:g} h"


def thesis_reference_times() -> dict[str, ThesisTime]:
    """Every compute time the thesis prints, keyed by the book's optimisation:

    ``"ch04 a"``, ``"ch04 b"``, ``"ch04 c"``, ``"ch04 c_wide"`` — Sec 4.3.3 (6 min GlobalSearch,
    11 min GPOPS-II) and Sec 4.4.2 (5 h), from :data:`gaitlib.studies.contact_id.THESIS_TIME`
    ((c′) is our variant of (c): the thesis's (c) is its reference);
    ``"ch05 MSK"``, ``"ch05 NMSK"`` — Secs 5.2.2 and 5.3.5 (2 h each,
    :data:`gaitlib.studies.msk.THESIS_HOURS`); ``"ch02 MSK"`` — the same MSK Eq 5.33 problem
    (Ch 2 solves it with the thesis's parameter sets);
    ``"ch06 <model> <cost>"`` — Table 6.3 (:data:`~gaitlib.studies.predictive.THESIS_HOURS_TABLE_6_3`);
    ``"ch07 <model> <our class>"`` — Table 7.2 for the thesis's class of the same rank
    (:data:`~gaitlib.studies.predictive.THESIS_HOURS_TABLE_7_2`, :data:`~gaitlib.studies.predictive.THESIS_CLASS`).

    Nothing else: where the thesis prints no time (:data:`THESIS_SILENT`) there is no key."""
    out: dict[str, ThesisTime] = {}
    for k, lab in contact_id.THESIS_TIME.items():
        out[f"ch04 {k}"] = ThesisTime(parse_duration(lab), lab if k != "c_wide" else f"{lab}; thesis's (c)")
    for m, h in msk.THESIS_HOURS.items():
        out[f"ch05 {m}"] = ThesisTime(3600.0 * h, f"{_hours(h)} ({_CH5_SOURCE[m]}, GPOPS-II)")
    out["ch02 MSK"] = out["ch05 MSK"]  # the same MSK Eq 5.33 problem (Ch 2: the thesis's parameter sets)
    for m, row in predictive.THESIS_HOURS_TABLE_6_3.items():
        for cost, h in row.items():
            out[f"ch06 {m} {cost}"] = ThesisTime(3600.0 * h, f"{_hours(h)} (Table 6.3, {m} {cost})")
    for m, row in predictive.THESIS_HOURS_TABLE_7_2.items():
        for ours, theirs in predictive.THESIS_CLASS.items():
            if theirs in row:
                h = row[theirs]
                out[f"ch07 {m} {ours}"] = ThesisTime(3600.0 * h, f"{_hours(h)} (Table 7.2, {m} {theirs})")
    return out


def _num(x):
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def time_row(chapter: str, run: str, *, status: str, converged: bool, iterations, build_s, solve_s,
             wall_s=None, n_solves: int = 1, from_cache=None, solved_at=None, cache_entry=None,
             thesis_key: str | None = None, study_call: str = "", note: str = "", thesis=None) -> dict:
    """One optimisation of the book as a row of the thesis-times table.

    ``build_s`` (s): symbolic graph, exact derivatives and IPOPT set-up; ``solve_s`` (s): the
    IPOPT call(s); ``wall_s`` defaults to ``build_s + solve_s`` (given explicitly for
    multi-start searches whose wall time includes scoring the start points);
    ``iterations`` summed over the ``n_solves`` NLP solves of the optimisation (continuation
    stages included). ``ms_per_iteration`` = 1000 · solve_s / iterations.

    The thesis's time (``thesis_key`` in :func:`thesis_reference_times`, or ``thesis`` given
    as a :class:`ThesisTime`) is carried as a labelled reference; ``speedup`` = thesis time /
    our wall time, **only for a converged run** (``converged``): a run IPOPT did not finish
    keeps its status and has no speed-up."""
    ref = thesis if thesis is not None else (thesis_reference_times().get(thesis_key) if thesis_key else None)
    build, solve = _num(build_s), _num(solve_s)
    wall = _num(wall_s) if wall_s is not None else (build + solve if build is not None and solve is not None else None)
    its = int(iterations) if iterations is not None else None
    mspi = 1e3 * solve / its if (solve is not None and its) else None
    speedup = ref.seconds / wall if (converged and ref is not None and wall) else None
    return {"chapter": chapter, "run": run, "study_call": study_call, "n_solves": int(n_solves),
            "status": str(status), "converged": bool(converged), "iterations": its, "build_s": build,
            "solve_s": solve, "wall_s": wall, "ms_per_iteration": mspi,
            "thesis_time": ref.label if ref is not None else None,
            "thesis_time_s": ref.seconds if ref is not None else None, "speedup": speedup,
            "from_cache": from_cache, "solved_at": solved_at, "cache_entry": cache_entry, "note": note}


def missing_row(chapter: str, run: str, reason: str, *, status: str = NOT_COMPUTED, thesis_key: str | None = None,
                study_call: str = "") -> dict:
    """A row for an optimisation that was not collected (not in the cache under
    ``--cached-only``, or a study without a cache): no times, no speed-up, ``reason`` as note
    (what to run to compute it). The thesis's time, if any, is still shown."""
    row = time_row(chapter, run, status=status, converged=False, iterations=None, build_s=None, solve_s=None,
                   thesis_key=thesis_key, study_call=study_call, note=reason)
    row["n_solves"] = 0
    return row
