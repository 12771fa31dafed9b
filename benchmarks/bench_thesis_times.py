"""Thesis times: every optimisation the book runs — its wall time,
iterations and time per iteration here — beside the compute time the thesis prints for it,
and the speed-up (thesis time / our wall time, converged runs only).

    .venv/bin/python benchmarks/bench_thesis_times.py                 # collect (solve what is missing)
    .venv/bin/python benchmarks/bench_thesis_times.py --cached-only   # never solve: missing runs listed
    .venv/bin/python benchmarks/bench_thesis_times.py --resolve       # re-solve everything (hours)
    .venv/bin/python benchmarks/bench_thesis_times.py --chapters ch03 ch04

The optimisations are enumerated chapter by chapter by calling the *same study functions
the book's notebooks call* (book/src/ch02_gait.py … ch07_speed.py):

  ch02  studies.gait.natural_gait("SK"), ("MSK")
  ch03  studies.jump.solve(name, use_cache=True) for the three jumps (the coarse
        continuation solve + the final solve)
  ch04  studies.contact_id: (a) trajectory_optimization() (multistart), (b)
        optimal_control_multistart() (each start: 3 continuation stages + the problem), (c)
        optimal_control_body(warm=b), (c') the same with widened contact bounds
  ch05  studies.mtg_id.identify (tol 1e-10 and 1e-5), studies.msk.solve("MSK"), ("NMSK")
  ch06  studies.predictive.cost_function_study (16 runs), its runs from the thesis's
        partial guess (16), and the 3000-iteration reruns of the runs that stopped at the limit
  ch07  studies.predictive.speed_study (8 runs), NMSK from the thesis's guess (4), reruns
  ch08  studies.gap (our chapter, not in the thesis): twin_validation(),
        twin_validation_full_mesh(), sk_diagnosis
        ("schwartz2008"), ("gaitutils"), nmsk_attribution() — one row per study, summed
        over its NLP solves (the gap cache entries the study used)

Modes
-----
default        The study functions reload cached solutions (the key hashes spec, code and
               data; never a stale entry). A cached solution keeps the statistics recorded
               when it was solved (build and IPOPT time, iterations, status), so the times
               are *as measured when solved, on this machine shared with other jobs*;
               ``from_cache`` says which rows were reloaded, ``solved_at`` is the file time
               of the cache entry (for entries of the repository's store: unknown). Runs
               not in the cache are solved now (serially, in this process) and cached.
--cached-only  Never solve (gaitlib.cache.only): an optimisation that
               is not in the cache becomes a "not computed yet" row saying what to run.
               The Ch 5 MTG identification has no solution cache (the book re-solves it at
               every build, ≈ 10 s each); it is skipped unless ``--measure-uncached``.
--resolve      Clean timings: every optimisation is solved again in this process, one
               after the other, with an empty temporary solution cache and the repository
               store disabled (``GAITLIB_SOLUTIONS``=tmp, ``GAITLIB_STORE``=""), which
               is ``use_cache=False`` for every study — including Chs 6/7, whose study
               functions have no such argument. A solve that a later one depends on (Ch 4
               (b) → (c); Ch 5 MSK → NMSK; the Ch 5 solutions Chs 6/7 start from) is solved
               once and reused within the run. Expected duration: the sum of the wall times
               of the table (``total_wall_s`` printed at the end; the script prints the
               estimate from the previous table before starting) — several hours on 2 cores
               for all chapters, dominated by Chs 4 (c) and 6/7; Chs 2–3 take minutes.

Output: ``benchmarks/results/thesis_times.json`` and ``.md``. With ``--chapters`` the rows
of the other chapters are kept from the existing file (each row records the mode and the
time of the collection it came from). The script sets the Makefile's BLAS settings
(:mod:`gaitlib.blas`) unless they are set; run it niced on a shared machine.
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime as _dt
import json
import os
import subprocess
import sys
import tempfile
import time
import traceback
from contextlib import nullcontext
from pathlib import Path

from gaitlib.problems import gait as gait_ocp
from gaitlib import blas

# before numpy loads OpenBLAS: the Makefile's settings (the gap solutions' cache keys hash
# the data's numbers, which depend on OpenBLAS's kernel; environment.md)
blas.pin()

import thesis_times as tt  # noqa: E402  (benchmarks/thesis_times.py)
from report import machine_info  # noqa: E402
from gaitlib import cache  # noqa: E402
from gaitlib.studies import performance  # noqa: E402

#: Why a solve is refused under ``--cached-only`` (the message of :class:`gaitlib.cache.NotCached`).
NO_SOLVING = "solving is disabled (--cached-only)"

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
CHAPTERS = ("ch02", "ch03", "ch04", "ch05", "ch06", "ch07", "ch08")
NOTEBOOK = {"ch02": "ch02_gait", "ch03": "ch03_jump", "ch04": "ch04_contact", "ch05": "ch05_msk",
            "ch06": "ch06_costfun", "ch07": "ch07_speed", "ch08": "ch08_gap"}


def _now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def _how_to(ch: str) -> str:
    return (f"not computed yet — run `python benchmarks/bench_thesis_times.py --chapters {ch}` (solves the "
            f"missing runs) or execute book/{NOTEBOOK[ch]}.ipynb")


# --------------------------------------------------------------------------------------
# Cache entries: where a row's solution is stored and when it was written
# --------------------------------------------------------------------------------------
def _entry(where, marker: str) -> dict:
    """``cache_entry`` ("cache:<kind>/<key>" or "store:<kind>/<key>") and ``solved_at`` (the
    file time of the entry's marker file, UTC; None for the repository's store, whose file
    times are checkout times)."""
    from gaitlib import cache

    found = cache.find(Path(where), marker)
    if found is None:
        return {"cache_entry": None, "solved_at": None}
    store = cache.store_dir()
    in_store = store is not None and Path(store).resolve() in Path(found).resolve().parents
    rel = f"{Path(found).parent.name}/{Path(found).name}"
    if in_store:
        return {"cache_entry": f"store:{rel}", "solved_at": None}
    t = (Path(found) / marker).stat().st_mtime
    return {"cache_entry": f"cache:{rel}",
            "solved_at": _dt.datetime.fromtimestamp(t, _dt.timezone.utc).isoformat(timespec="seconds")}


class _CacheLog:
    """Collect the cache entries a block of study calls used (``GAITLIB_CACHE_LOG``), for
    studies that build their cache keys internally (Ch 4). Lines are passed on to a log the
    caller had set."""

    def __enter__(self):
        self.prev = os.environ.get("GAITLIB_CACHE_LOG")
        fd, self.path = tempfile.mkstemp(prefix="gaitlib-cachelog-")
        os.close(fd)
        os.environ["GAITLIB_CACHE_LOG"] = self.path
        return self

    def __exit__(self, *exc):
        lines = Path(self.path).read_text().splitlines()
        os.unlink(self.path)
        if self.prev is None:
            os.environ.pop("GAITLIB_CACHE_LOG", None)
        else:
            os.environ["GAITLIB_CACHE_LOG"] = self.prev
            with open(self.prev, "a") as f:
                f.writelines(line + "\n" for line in lines)
        self.lines = lines
        return False

    def entries(self, marker: str) -> list[dict]:
        seen, out = set(), []
        for line in self.lines:
            p = Path(line)
            if p in seen or not (p / marker).exists():
                continue
            seen.add(p)
            out.append(_entry(p, marker))
        return out


def _merge_entries(entries: list[dict]) -> dict:
    """One row's cache entries (several NLP solves): the latest file time, the entries joined."""
    if not entries:
        return {"cache_entry": None, "solved_at": None}
    times = [e["solved_at"] for e in entries if e["solved_at"]]
    return {"cache_entry": ", ".join(e["cache_entry"] for e in entries),
            "solved_at": max(times) if times else None}


# --------------------------------------------------------------------------------------
# Chapters
# --------------------------------------------------------------------------------------
def _gait_row(chapter, run, sol, where, *, thesis_key=None, call="", note=""):
    st = sol.stats
    return tt.time_row(chapter, run, status=st["status"], converged=bool(st["success"]),
                         iterations=st["iterations"], build_s=st["build_time_s"], solve_s=st["solve_time_s"],
                         from_cache=bool(st.get("from_cache", False)), thesis_key=thesis_key, study_call=call,
                         note=note, **_entry(where, "spec.json"))


def ch02(ctx):
    from gaitlib.studies import gait

    rows = []
    for model in ("SK", "MSK"):
        call = f'studies.gait.natural_gait("{model}")'
        run = f"{model} natural gait, {gait.natural_gait_spec(model).cost} (thesis's parameter sets)"
        try:
            sol = gait.natural_gait(model)
        except cache.NotCached:
            rows.append(tt.missing_row("ch02", run, _how_to("ch02"), thesis_key=f"ch02 {model}", study_call=call))
            continue
        note = tt.THESIS_SILENT.get(f"ch02 {model}", "")
        rows.append(_gait_row("ch02", run, sol, gait_ocp.cache_dir(sol.spec), thesis_key=f"ch02 {model}",
                              call=call, note=note))
    return rows


def ch03(ctx):
    from gaitlib.studies import jump

    rows = []
    for name in ("toeless", "toe", "ellipsoid"):
        call = f'studies.jump.solve("{name}", use_cache=True)'
        run = f"jump: {jump.SPECS[name].label}"
        try:
            s = jump.solve(name, use_cache=True)
        except cache.NotCached:
            rows.append(tt.missing_row("ch03", run, _how_to("ch03"), study_call=call))
            continue
        sol = s.solution
        steps = sol.info.get("continuation", [])
        its = sol.iterations + sum(int(c["iterations"]) for c in steps)
        build = sol.build_time + sum(float(c["build_time"]) for c in steps)
        solve = sol.solve_time + sum(float(c["solve_time"]) for c in steps)
        cont = "; ".join(f"{c['n_intervals']}-interval continuation: {c['status']}, {c['iterations']} it"
                         for c in steps)
        note = (f"{cont}; {s.spec.n_intervals}-interval solve: {sol.iterations} it. "
                if cont else "") + tt.THESIS_SILENT["ch03"]
        rows.append(tt.time_row("ch03", run, status=sol.status, converged=bool(sol.success), iterations=its,
                                  build_s=build, solve_s=solve, n_solves=1 + len(steps),
                                  from_cache=bool(s.from_cache), study_call=call, note=note,
                                  **_entry(jump.cache_location(s.spec), "solution.json")))
    return rows


def _approach_row(key, r, log, call, run):
    st = r.stats
    if key == "a":
        marker, n = "result.json", st["n_local"]
        note = (f"{st['n_converged']} of {st['n_local']} local solves converged, best from {st['best_start']}; "
                f"wall includes scoring {st['n_trial']} trial points")
        from_cache = bool(st["from_cache"])
        wall = st["wall_s"]
    else:
        marker = "spec.json"
        n = int(st.get("n_stages", 1))
        from_cache = bool(r.stages["from cache"].all()) if r.stages is not None else bool(st["from_cache"])
        wall = None
        note = ""
        if n > 1:
            sts = ", ".join(f"{tuple(b)}: {s} ({i} it)" for b, s, i in
                            zip(r.stages["residual bounds (N, N, N·m)"], r.stages["status"], r.stages["iterations"]))
            note = f"{n - 1} continuation stages + the problem (residual bounds N, N, N·m): {sts}"
        if key == "c_wide":
            note = "our variant of (c): Table 4.7 contact bounds widened to contain the thesis's (c) values"
    return tt.time_row("ch04", run, status=st["status"], converged=bool(st["success"]), iterations=st["iterations"],
                         build_s=st["build_s"], solve_s=st["solve_s"], wall_s=wall, n_solves=n, from_cache=from_cache,
                         thesis_key=f"ch04 {key}", study_call=call, note=note,
                         **_merge_entries(log.entries(marker)))


def ch04(ctx):
    from gaitlib.studies import contact_id as ci

    rows = []
    calls = {"a": "studies.contact_id.trajectory_optimization()", "b": "studies.contact_id.optimal_control_multistart()",
             "c": "studies.contact_id.optimal_control_body(warm=b)",
             "c_wide": 'studies.contact_id.optimal_control_body(spec=spec_c(contact_bounds="widened"), warm=b)'}
    runs = {k: f"contact identification {ci.APPROACHES[k]}" for k in ("a", "b", "c")}
    runs["c_wide"] = "contact identification (c') widened contact bounds"
    funcs = {"a": lambda: ci.trajectory_optimization(),
             "b": lambda: (ci.optimal_control_multistart(),  # the book's (b); each start's run for the sums
                           {n: ci.optimal_control(start=ci.start_params(n)) for n in ci.B_STARTS})}
    done = {}
    for key in ("a", "b", "c", "c_wide"):
        if key in ("c", "c_wide") and "b" not in done:
            rows.append(tt.missing_row("ch04", runs[key], _how_to("ch04") + " ((b) first: it is the warm start)",
                                         thesis_key=f"ch04 {key}", study_call=calls[key]))
            continue
        if key == "c":
            f = lambda: ci.optimal_control_body(warm=done["b"])  # noqa: E731
        elif key == "c_wide":
            f = lambda: ci.optimal_control_body(spec=ci.spec_c(contact_bounds="widened"), warm=done["b"])  # noqa: E731
        else:
            f = funcs[key]
        try:
            with _CacheLog() as log:
                r = f()
        except cache.NotCached:
            rows.append(tt.missing_row("ch04", runs[key], _how_to("ch04"), thesis_key=f"ch04 {key}",
                                         study_call=calls[key]))
            continue
        if key == "b":
            r, per_start = r
            done[key] = r
            rows.append(_multistart_row(r, per_start, log, calls[key], runs[key]))
            continue
        done[key] = r
        rows.append(_approach_row(key, r, log, calls[key], runs[key]))
    return rows


def _multistart_row(kept, per_start: dict, log, call, run):
    """(b) as the book solves it (:func:`gaitlib.studies.contact_id.optimal_control_multistart`):
    every start through the continuation, summed — iterations, build and solve time, NLP
    solves — with the kept start's status."""
    st = kept.stats
    n = sum(int(x.stats.get("n_stages", 1)) for x in per_start.values())
    cached = all(bool(x.stages["from cache"].all()) if x.stages is not None else bool(x.stats["from_cache"])
                 for x in per_start.values())
    note = (f"{len(per_start)} starts, each through the continuation (" + "; ".join(
        f"{k}: {x.stats['status']}, {x.stats['iterations']} it" for k, x in per_start.items())
            + f"); kept: {st['start']}")
    return tt.time_row("ch04", run, status=st["status"], converged=bool(st["success"]),
                       iterations=sum(int(x.stats["iterations"]) for x in per_start.values()),
                       build_s=sum(float(x.stats["build_s"]) for x in per_start.values()),
                       solve_s=sum(float(x.stats["solve_s"]) for x in per_start.values()), wall_s=None, n_solves=n,
                       from_cache=cached, thesis_key="ch04 b", study_call=call, note=note,
                       **_merge_entries(log.entries("spec.json")))


def ch05(ctx):
    from gaitlib.studies import msk, mtg_id

    rows = []
    for lab, kw in (("tol 1e-10 (ours)", {}), ("tol 1e-5 (the thesis's)", {"tol": 1e-5})):
        call = f"studies.mtg_id.identify(chapter_spec({', '.join(f'{k}={v}' for k, v in kw.items())}))"
        run = f"MTG parameter identification, {lab}"
        if ctx["cached_only"] and not ctx["measure_uncached"]:
            rows.append(tt.missing_row("ch05", run, "studies.mtg_id.identify has no solution cache (the book "
                                         "re-solves it at every build, ≈ 10 s); run without --cached-only or with "
                                         "--measure-uncached", status=tt.NO_CACHE, study_call=call))
            continue
        r = mtg_id.identify(mtg_id.chapter_spec(**kw))  # no cache: solved here (main lifts the guard)
        st = r.stats
        rows.append(tt.time_row("ch05", run, status=st["status"], converged=bool(st["success"]),
                                  iterations=st["iterations"], build_s=st["build_time_s"], solve_s=st["solve_time_s"],
                                  from_cache=False, solved_at=_now(), cache_entry=None, study_call=call,
                                  note=tt.THESIS_SILENT["ch05 MTG"] + "; not cached: measured in this run"))
    base = None
    for model in ("MSK", "NMSK"):
        call = f'studies.msk.solve("{model}")'
        spec = msk.ch5_spec(model)
        run = f"{model} natural gait, {spec.cost} (Ch 4/5 parameter sets)"
        try:
            with cache.only(NO_SOLVING) if ctx["cached_only"] else nullcontext():
                sol = msk.solve(model)
        except cache.NotCached:
            rows.append(tt.missing_row("ch05", run, _how_to("ch05"), thesis_key=f"ch05 {model}", study_call=call))
            continue
        if model == "MSK":
            base = sol
            where, note = gait_ocp.cache_dir(sol.spec), ""
        else:
            where = gait_ocp.cache_dir(sol.spec, guess=base)
            note = "warm-started from the Ch 5 MSK solution (the thesis: data and EMG guess)"
        rows.append(_gait_row("ch05", run, sol, where, thesis_key=f"ch05 {model}", call=call, note=note))
    return rows


def _study_rows(chapter, res, call, item_of, label_of, guess_note=""):
    """Rows of a Ch 6/7 StudyResult (and a list of the runs that stopped at an IPOPT status
    other than success, to be rerun at 3000 iterations as the book does)."""

    rows, failed = [], []
    for name, spec in res.specs.items():
        rec = res.records[name]
        sol = res.solutions.get(name)
        run = label_of(spec.model, item_of(spec)) + guess_note
        key = f"{chapter} {spec.model} {item_of(spec)}"
        if sol is None:
            if rec.error and "NotInCache" in rec.error:
                rows.append(tt.missing_row(chapter, run, _how_to(chapter), thesis_key=key, study_call=call))
            else:
                err = (rec.error or "").strip().splitlines()[-1:] or [""]
                rows.append(tt.time_row(chapter, run, status=rec.status, converged=False, iterations=None,
                                          build_s=None, solve_s=None, thesis_key=key, study_call=call,
                                          note=f"error: {err[0]}"))
            continue
        if not rec.ok:
            failed.append(name)
        rows.append(_gait_row(chapter, run, sol, gait_ocp.cache_dir(spec, guess=res.guesses.get(name)),
                              thesis_key=key, call=call))
    return rows, failed


def _reruns(chapter, res, failed, call, item_of, label_of):

    rows = []
    for name in failed:
        spec = dataclasses.replace(res.specs[name], max_iter=3000)
        run = label_of(spec.model, item_of(spec)) + ", rerun max_iter=3000 (investigation)"
        key = f"{chapter} {spec.model} {item_of(spec)}"
        c = f'{call}.rerun("{name}", max_iter=3000)'
        try:
            sol = res.rerun(name, max_iter=3000)
        except cache.NotCached:
            rows.append(tt.missing_row(chapter, run, _how_to(chapter), thesis_key=key, study_call=c))
            continue
        rows.append(_gait_row(chapter, run, sol, gait_ocp.cache_dir(spec, guess=res.guesses.get(name)),
                              thesis_key=key, call=c,
                              note=f"the 1000-iteration run stopped with {res.records[name].status}"))
    return rows


def _predictive(chapter, study, items, item_of, label_of):
    """Ch 6/7: the study as the book calls it (serial), from the thesis's guess, reruns."""
    from gaitlib.studies import predictive as pr

    fn = getattr(pr, study)
    rows = []
    call = f"studies.predictive.{study}"
    try:
        res = fn(("MSK", "NMSK"), items, progress=False, serial=True)
    except cache.NotCached:
        missing = [(m, i) for m in ("MSK", "NMSK") for i in items]
        return [tt.missing_row(chapter, label_of(m, i), _how_to(chapter) + " (the Ch 5 solutions it starts from "
                                 "are not in the cache either)", thesis_key=f"{chapter} {m} {i}", study_call=call)
                for m, i in missing]
    r, failed = _study_rows(chapter, res, f"{call}(('MSK', 'NMSK'))", item_of, label_of)
    rows += r
    rows += _reruns(chapter, res, failed, "res", item_of, label_of)
    # the models whose runs the book starts elsewhere, from the thesis's guess
    models = tuple(m for m, h in res.guess.items() if h != "thesis")
    tg = fn(models, items, progress=False, serial=True, guess={m: "thesis" for m in models})
    r, _ = _study_rows(chapter, tg, f"{call}({models!r}, guess={ {m: 'thesis' for m in models}!r})", item_of,
                       label_of, guess_note=" (thesis's partial guess)")
    rows += r
    return rows


def ch06(ctx):
    from gaitlib.studies import predictive as pr

    return _predictive("ch06", "cost_function_study", pr.CH6_COSTS, lambda s: s.cost,
                       lambda model, cost: f"{model} {cost}")


def ch07(ctx):
    from gaitlib.studies import predictive as pr

    return _predictive("ch07", "speed_study", pr.CH7_CLASSES, lambda s: s.speed_class,
                       lambda model, cls: f"{model} {cls} (thesis class {pr.THESIS_CLASS[cls]})")


def ch08(ctx):
    """Our gap chapter: one row per study, summed over the NLP solves it used (the ``gap``
    cache entries, each with the statistics of its solve). Not in the thesis: no thesis time."""
    from gaitlib.studies import gap as G

    studies = (("twin validation (38 twins, coarse 10 × 3 mesh)", "studies.gap.twin_validation()",
                G.twin_validation),
               ("twin check on 20 × 5 (middle magnitude, 2 seeds, 14 twins)", "studies.gap.twin_validation_full_mesh()",
                G.twin_validation_full_mesh),
               ("SK diagnosis, Schwartz 2008 Free (20 × 5)", 'studies.gap.sk_diagnosis("schwartz2008")',
                lambda: G.sk_diagnosis("schwartz2008")),
               ("SK diagnosis, gaitutils (20 × 5)", 'studies.gap.sk_diagnosis("gaitutils")',
                lambda: G.sk_diagnosis("gaitutils")),
               ("NMSK attribution from the Ch 5 NMSK solution (20 × 5)", "studies.gap.nmsk_attribution()",
                G.nmsk_attribution))
    rows = []
    for run, call, fn in studies:
        try:
            with _CacheLog() as log:
                fn()
        except cache.NotCached:
            rows.append(tt.missing_row("ch08", run, _how_to("ch08"), study_call=call))
            continue
        paths = [Path(p) for p in dict.fromkeys(log.lines)
                 if Path(p).parent.name == "gap" and (Path(p) / "summary.json").is_file()]
        stats = [json.loads((p / "summary.json").read_text())["stats"] for p in paths]
        ok = sum(bool(st.get("success")) for st in stats)
        n = len(stats)
        status = "Solve_Succeeded (all)" if ok == n else f"{ok} of {n} NLP solves succeeded"
        ents = _merge_entries([_entry(p, "summary.json") for p in paths])
        rows.append(tt.time_row(
            "ch08", run, status=status, converged=(ok == n), n_solves=n,
            iterations=sum(int(st.get("iterations") or 0) for st in stats),
            build_s=sum(float(st.get("build_time_s") or 0.0) for st in stats),
            solve_s=sum(float(st.get("solve_time_s") or 0.0) for st in stats),
            from_cache=None, study_call=call, solved_at=ents["solved_at"],
            cache_entry=f"{n} gap entries",
            note="not in the thesis (our chapter); build time as recorded with each solve (an NLP re-solved on "
                 "another data set carries its one build in each record)"))
    return rows


COLLECT = {"ch02": ch02, "ch03": ch03, "ch04": ch04, "ch05": ch05, "ch06": ch06, "ch07": ch07, "ch08": ch08}


# --------------------------------------------------------------------------------------
# Machine, output
# --------------------------------------------------------------------------------------
def _machine() -> dict:
    return machine_info()


def _versions() -> dict:
    import casadi

    from gaitlib import __version__, cache

    try:
        commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                                text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = None
    return {"gaitlib": __version__, "gaitlib_commit": commit, "casadi": casadi.__version__,
            "cache_fingerprint": cache.fingerprint()}


def _fmt(v, col):
    if v is None or (isinstance(v, float) and v != v):
        return ""
    if col in ("build_s", "solve_s", "wall_s"):
        return f"{v:.1f}"
    if col == "ms_per_iteration":
        return f"{v:.0f}"
    if col == "speedup":
        return f"{v:.0f}×" if v >= 10 else f"{v:.1f}×"
    if isinstance(v, bool):
        return "yes" if v else "no"
    return str(v).replace("|", "/")


def write_markdown(doc: dict, path: Path) -> None:
    cols = [("chapter", "ch"), ("run", "run"), ("status", "status"), ("iterations", "it"),
            ("n_solves", "NLPs"), ("build_s", "build s"), ("solve_s", "solve s"), ("wall_s", "wall s"),
            ("ms_per_iteration", "ms/it"), ("thesis_time", "thesis (labelled)"), ("speedup", "speed-up"),
            ("from_cache", "from cache"), ("solved_at", "solved at (UTC)")]
    meta = doc["meta"]
    m = meta["machine"]
    lines = [f"# Thesis times — every optimisation of the book beside the thesis's time", "",
             f"Written {meta['written']} by `benchmarks/bench_thesis_times.py`; machine: {m['cpu']}, "
             f"{m['cores']} cores, {m['memory_gb']} GB, {m['platform']}, Python {m['python']}; "
             f"casadi {meta['versions']['casadi']}, gaitlib {meta['versions']['gaitlib_commit']}.", "",
             "Times are **as measured when each solution was solved** (rows `from cache` = yes: the statistics "
             "stored with the cached solution; this machine, 2 cores shared with other jobs — the load is not "
             "recorded per solve). wall = build (symbolic graph, exact derivatives, IPOPT set-up) + solve (IPOPT), "
             "summed over the NLP solves of the optimisation (continuation stages, multistart local solves); "
             "ms/it = solve / iterations. Thesis times: GPOPS-II/MATLAB on an i7-6700 as printed (labelled; empty "
             "where the thesis prints none). Speed-up = thesis time / our wall, converged runs only.", ""]
    for when, c in meta["collections"].items():
        lines.append(f"- collection {when}: mode `{c['mode']}`, chapters {', '.join(c['chapters'])}, "
                     f"{c['elapsed_s']:.0f} s, load average at start {', '.join(f'{x:.2f}' for x in c['loadavg_start'])}")
    lines += ["", "| " + " | ".join(h for _, h in cols) + " |", "|" + "---|" * len(cols)]
    for r in doc["rows"]:
        lines.append("| " + " | ".join(_fmt(r.get(c), c) for c, _ in cols) + " |")
    notes = [(r["chapter"], r["run"], r["note"]) for r in doc["rows"] if r.get("note")]
    if notes:
        lines += ["", "Notes:", ""] + [f"- {ch} {run}: {n}" for ch, run, n in notes]
    s = doc["summary"]
    lines += ["", f"{s['n_rows']} rows: {s['n_converged']} converged, {s['n_not_converged']} not converged, "
              f"{s['n_missing']} not collected; speed-up over the {s['n_with_thesis']} converged rows with a thesis "
              f"time: {_fmt(s['speedup_min'], 'speedup')}–{_fmt(s['speedup_max'], 'speedup')} (median "
              f"{_fmt(s['speedup_median'], 'speedup')}); "
              f"sum of our wall times {s['total_wall_s'] / 3600:.2f} h."]
    path.write_text("\n".join(lines) + "\n")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--cached-only", action="store_true", help="never solve; missing runs become rows saying so")
    mode.add_argument("--resolve", action="store_true", help="re-solve everything with an empty cache (hours)")
    ap.add_argument("--measure-uncached", action="store_true",
                    help="with --cached-only: still solve the studies without a solution cache (Ch 5 MTG, ≈ 20 s)")
    ap.add_argument("--chapters", nargs="+", choices=CHAPTERS, default=list(CHAPTERS))
    ap.add_argument("--out", type=Path, default=OUT, help="results directory (default benchmarks/results)")
    args = ap.parse_args(argv)
    chapters = [c for c in CHAPTERS if c in args.chapters]
    mode_name = "cached-only" if args.cached_only else "resolve" if args.resolve else "cached"
    if args.cached_only and args.measure_uncached:
        mode_name += " + measure-uncached"
    out_json = args.out / "thesis_times.json"
    previous = json.loads(out_json.read_text()) if out_json.is_file() else None

    tmp = None
    if args.resolve:
        if previous:
            est = sum((r.get("wall_s") or 0) for r in previous["rows"] if r["chapter"] in chapters)
            print(f"--resolve: the previous table's wall times for {', '.join(chapters)} sum to {est / 3600:.2f} h "
                  f"(expected duration, serial)", flush=True)
        tmp = tempfile.TemporaryDirectory(prefix="gaitlib-resolve-")
        os.environ["GAITLIB_SOLUTIONS"] = tmp.name
        os.environ["GAITLIB_STORE"] = ""

    ctx = {"cached_only": args.cached_only, "measure_uncached": args.measure_uncached}
    started, t0, load0 = _now(), time.perf_counter(), list(os.getloadavg())
    rows = []
    for ch in chapters:
        tc = time.perf_counter()
        print(f"[{ch}] collecting ({mode_name}) …", flush=True)
        # --cached-only: nothing is solved; with --measure-uncached, Ch 5 guards its cached
        # solves itself and solves the (uncached) MTG identification
        lift = ch == "ch05" and args.measure_uncached
        guard = cache.only(NO_SOLVING) if args.cached_only and not lift else nullcontext()
        try:
            with guard:
                new = COLLECT[ch](ctx)
        except Exception:  # noqa: BLE001 — a chapter that fails is reported, not dropped
            tb = traceback.format_exc()
            print(tb, file=sys.stderr)
            new = [tt.time_row(ch, f"{ch}: collection failed", status="error", converged=False, iterations=None,
                                 build_s=None, solve_s=None, note=tb.strip().splitlines()[-1])]
        for r in new:
            r["mode"], r["collected"] = mode_name, started
            if args.resolve and r["cache_entry"]:  # the temporary cache is discarded at the end
                r["cache_entry"] = "temporary cache of this --resolve run (discarded)"
                if r["from_cache"]:
                    r["note"] = (r["note"] + "; " if r["note"] else "") + "solved earlier in this --resolve run"
            print(f"  {r['run'][:60]:60s} {r['status'][:28]:28s} it {r['iterations'] or '':>5} "
                  f"wall {_fmt(r['wall_s'], 'wall_s'):>8} s  thesis {r['thesis_time'] or '–'}  "
                  f"speed-up {_fmt(r['speedup'], 'speedup') or '–'}  cache {r['from_cache']}", flush=True)
        rows += new
        print(f"[{ch}] {len(new)} rows, {time.perf_counter() - tc:.0f} s", flush=True)
    if tmp is not None:
        tmp.cleanup()

    collection = {"mode": mode_name, "chapters": chapters, "elapsed_s": time.perf_counter() - t0,
                  "loadavg_start": load0, "loadavg_end": list(os.getloadavg()), "command": " ".join(sys.argv)}
    collections = {started: collection}
    if previous and set(chapters) != set(CHAPTERS):  # keep the other chapters' rows
        kept = [r for r in previous["rows"] if r["chapter"] not in chapters]
        used = {r["collected"] for r in kept}
        collections = {**{k: v for k, v in previous["meta"]["collections"].items() if k in used}, **collections}
        rows = sorted(kept + rows, key=lambda r: CHAPTERS.index(r["chapter"]))
    doc = {"meta": {"written": _now(), "measured": started, "machine": _machine(), "versions": _versions(),
                    "collections": collections,
                    "note": "times as measured when each solution was solved (cache) or in the collection "
                            "(from_cache false); 2-core machine shared with other jobs"},
           "thesis_silent": tt.THESIS_SILENT, "rows": rows}
    doc["summary"] = performance.thesis_times_summary(doc)
    args.out.mkdir(parents=True, exist_ok=True)
    out_json.write_text(json.dumps(doc, indent=1, default=str) + "\n")
    write_markdown(doc, args.out / "thesis_times.md")
    s = doc["summary"]
    print(f"wrote {out_json} and thesis_times.md: {s['n_rows']} rows, {s['n_converged']} converged, "
          f"{s['n_not_converged']} not converged, {s['n_missing']} not collected; total wall "
          f"{s['total_wall_s'] / 3600:.2f} h (total_wall_s {s['total_wall_s']:.0f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
