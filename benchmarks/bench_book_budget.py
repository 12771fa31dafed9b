"""The whole book from scratch: what it solves, chapter by chapter, and how far each lever of
issue 22 could take it (target 1: ≤ 45 min on this 2-core machine).

    .venv/bin/python benchmarks/bench_book_budget.py            # ≈ 6 min: every notebook from the store, nothing solved
    .venv/bin/python benchmarks/bench_book_budget.py --reuse    # recompute from results/book_budget.json

A from-scratch ``make book`` solves exactly the optimisations whose solutions the book reads
from ``solutions/``. This script finds them the way ``tools/store_solutions.py`` does: every
notebook (book order) runs under nbval from the store only (``GAITLIB_CACHE_ONLY=1``, an empty
user cache, so nothing is solved) with ``$GAITLIB_CACHE_LOG`` recording each entry it looks
up. An entry belongs to the first chapter that reads it (the chapters before the report card
and the performance page, which only gather). Each stored entry keeps the statistics of its
own solve: status, iterations, build and IPOPT times **as recorded when it was solved**, under
whatever load the shared 2-core machine had then (not re-measured here).

Per chapter it adds up solves, iterations and the recorded build + solve time, and projects
the levers of issue 22, each with the ratio a benchmark measured (read from ``results/``):

- *the fastest recorded pace*: every solve's iterations at the fastest time per iteration
  recorded by any solve of its class (kind, model, mesh; solves of 50 iterations or more,
  classes of three or more) — what the recorded paths would take on an unloaded machine,
  roughly; the levers below start from this;
- *builds on the per-node path*: every build replaced by the per-node build measured for
  its model (``results/build.json``, SK / MSK / NMSK at 20 × 5; jumps and contact
  identification count as SK);
- *evaluations compiled*: IPOPT's time × (1 − e + e·c), with e the evaluations' share of the
  whole-graph solve of the entry's model (``results/build.json``) and c the compiled
  evaluations' time over the uncompiled per-node evaluations' (``results/e2e.json``, MSK DT
  Free);
- *evaluations free*: IPOPT's time × (1 − e) — IPOPT's own work (MUMPS's factorisations
  and the rest) on the recorded path, the floor of any evaluation speed-up;
- *two workers*: the above ÷ 2, as if every chapter's solves were independent and split
  perfectly.

Every projection keeps the recorded iterations: the measured levers that cut iterations
(IPOPT's options, the integral defects) end in other local optima (``benchmarks/README.md``).
Writes ``results/book_budget.json`` / ``.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from datetime import datetime, timezone
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from report import machine_info, md_table, write_report  # noqa: E402

from gaitlib.studies import performance as perf  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
STORE = ROOT / "solutions"
#: the order in which an entry read by several notebooks is attributed: the chapters first,
#: then the pages that only gather results from them
ATTRIBUTION = ["ch01_data", "ch02_gait", "ch03_jump", "ch04_contact", "ch05_msk", "ch06_costfun", "ch07_speed",
               "ch08_gap", "appendix_physics", "performance", "card"]


def notebooks() -> list[str]:
    import yaml

    toc = yaml.safe_load((ROOT / "book" / "_toc.yml").read_text())
    return [c["file"] for c in toc.get("chapters", []) if (ROOT / "book" / f"{c['file']}.ipynb").exists()]


def collect() -> dict:
    """Run every notebook from the store only; the entries each looked up, and its wall time."""
    used, wall = {}, {}
    with tempfile.TemporaryDirectory(prefix="gaitlib-budget-") as tmp:
        for nb in notebooks():
            log = Path(tmp) / f"{nb}.log"
            env = {**os.environ, "GAITLIB_SOLUTIONS": str(Path(tmp) / "cache"), "GAITLIB_CACHE_ONLY": "1",
                   "GAITLIB_STORE": str(STORE), "GAITLIB_CACHE_LOG": str(log), "OPENBLAS_NUM_THREADS": "1",
                   "OMP_NUM_THREADS": "1", "OPENBLAS_CORETYPE": "Haswell",
                   "PYTHONPATH": str(ROOT / "src")}
            t0 = time.perf_counter()
            r = subprocess.run([sys.executable, "-m", "pytest", "-q", "--nbval-lax", "-p", "no:cacheprovider",
                                str(ROOT / "book" / f"{nb}.ipynb")], env=env, cwd=ROOT, capture_output=True,
                               text=True)
            wall[nb] = time.perf_counter() - t0
            if r.returncode:
                raise RuntimeError(f"{nb}: nbval failed from the store:\n{r.stdout[-3000:]}")
            paths = sorted(set(log.read_text().split())) if log.exists() else []
            used[nb] = sorted({f"{Path(p).parent.name}/{Path(p).name}" for p in paths
                               if (STORE / Path(p).parent.name / Path(p).name).is_dir()})
            print(f"{nb}: {len(used[nb])} entries, {wall[nb]:.0f} s", flush=True)
    return {"used": used, "wall_from_store_s": wall}


def entry_stats(entry: str) -> list[dict]:
    """The recorded statistics of one stored solution (``kind/key``), one dict per NLP solve
    (a multistart entry — Ch 4 (a)'s local solves — holds several)."""
    d = STORE / entry
    kind = entry.split("/")[0]
    base = {"entry": entry, "kind": kind}
    if (d / "summary.json").exists():
        s = json.loads((d / "summary.json").read_text())
        st, spec = s["stats"], s.get("spec", {})
        return [{**base, "model": spec.get("model", "SK"), "mesh": f"{spec.get('n_intervals')} × {spec.get('degree')}",
                 "status": st["status"], "success": bool(st["success"]), "iterations": int(st["iterations"]),
                 "build_s": float(st.get("build_time_s") or 0.0), "solve_s": float(st["solve_time_s"])}]
    if (d / "result.json").exists():  # multistart local solves sharing one build
        s = json.loads((d / "result.json").read_text())
        return [{**base, "model": "SK", "mesh": "local (multistart)", "status": r["status"],
                 "success": bool(r["success"]), "iterations": int(r["iterations"]),
                 "build_s": float(s["build_s"]) if i == 0 else 0.0, "solve_s": float(r["time (s)"])}
                for i, r in enumerate(s["rows"])]
    s = json.loads((d / "solution.json").read_text())  # a multi-phase jump: the ocp.Solution itself
    nodes = sum(len(f.read_text().splitlines()) - 1 for f in d.glob("*_states.csv"))
    return [{**base, "model": "SK", "mesh": f"jump, {nodes} nodes", "status": s["status"], "success": bool(s["success"]),
             "iterations": int(s["iterations"]), "build_s": float(s.get("build_time") or 0.0),
             "solve_s": float(s["solve_time"])}]


def ratios() -> dict:
    """The levers' measured ratios, from the benchmarks' own results."""
    build = json.loads((OUT / "build.json").read_text())
    e2e = json.loads((OUT / "e2e.json").read_text())
    rows = {(r["model"], r["derivatives"]): r for r in build["rows"]}
    models = sorted({m for m, _ in rows})
    gait = {r["variant"]: r for r in e2e["gait"]}
    c = gait["nodes, compiled"]["evals_s"] / gait["nodes"]["evals_s"]
    return {"node_build_s": {m: rows[(m, "nodes")]["build_s"] for m in models},
            "eval_share": {m: rows[(m, "graph")]["evals_s"] / rows[(m, "graph")]["solve_s"] for m in models},
            "compiled_eval_ratio": c,
            "sources": {"build.json": build["measured"], "e2e.json": e2e["measured"]}}


#: a class's fastest recorded pace counts solves of at least this many iterations, and only
#: classes with at least :data:`PACE_MIN_SOLVES` of them (else the solve's own recorded time)
PACE_MIN_ITERATIONS, PACE_MIN_SOLVES = 50, 3


def fastest_pace(entries: list[dict]) -> dict:
    """Per class of problem (kind, model, mesh): the fastest time per iteration recorded by any
    of its solves (s) — the pace the least loaded machine gave; the recorded times carry
    whatever load each solve shared the machine with."""
    per = defaultdict(list)
    for e in entries:
        if e["iterations"] >= PACE_MIN_ITERATIONS:
            per[(e["kind"], e["model"], e["mesh"])].append(e["solve_s"] / e["iterations"])
    return {k: min(v) for k, v in per.items() if len(v) >= PACE_MIN_SOLVES}


def budget(used: dict, rat: dict) -> list[dict]:
    owner = {}
    for nb in sorted(used, key=lambda n: ATTRIBUTION.index(n) if n in ATTRIBUTION else len(ATTRIBUTION)):
        for e in used[nb]:
            owner.setdefault(e, nb)
    per = defaultdict(list)
    for e, nb in owner.items():
        per[nb].extend(entry_stats(e))
    pace = fastest_pace([e for es in per.values() for e in es])
    c = rat["compiled_eval_ratio"]
    out = []
    for nb in notebooks():
        es = per.get(nb, [])
        for e in es:
            p = pace.get((e["kind"], e["model"], e["mesh"]))
            e["paced_s"] = min(e["solve_s"], e["iterations"] * p) if p else e["solve_s"]
            e["share"] = rat["eval_share"].get(e["model"], rat["eval_share"]["SK"])
            e["nodes_build_s"] = rat["node_build_s"].get(e["model"], rat["node_build_s"]["SK"]) if e["build_s"] else 0.0
        r = {"chapter": nb, "solves": len(es), "converged": sum(e["success"] for e in es),
             "iterations": sum(e["iterations"] for e in es), "build_s": sum(e["build_s"] for e in es),
             "solve_s": sum(e["solve_s"] for e in es)}
        r["recorded_s"] = r["build_s"] + r["solve_s"]
        r["paced_s"] = r["build_s"] + sum(e["paced_s"] for e in es)
        nodes_build = sum(e["nodes_build_s"] for e in es)
        r["compiled_s"] = nodes_build + sum(e["paced_s"] * (1 - e["share"] + e["share"] * c) for e in es)
        r["evals_free_s"] = nodes_build + sum(e["paced_s"] * (1 - e["share"]) for e in es)
        r["evals_free_2_workers_s"] = r["evals_free_s"] / 2
        r["problems"] = _problems(es)
        out.append(r)
    return out


def _problems(es: list[dict]) -> str:
    counts = defaultdict(int)
    for e in es:
        counts[f"{e['kind']} {e['model']} {e['mesh']}"] += 1
    return "; ".join(f"{n} {k}" for k, n in sorted(counts.items(), key=lambda kv: -kv[1]))


def report(doc: dict) -> list[str]:
    rat = doc["ratios"]
    table = perf.book_budget_table(doc)
    md = [f"# The whole book from scratch: solves and levers ({doc['measured']})", "",
          f"Machine: {doc['machine']['cpu']}, {doc['machine']['cores']} cores. Times are **as recorded** when each "
          "stored solution was solved (the machine's load then is not known); the projections keep the recorded "
          "iterations.", "",
          f"Ratios: per-node builds {', '.join(f'{m} {v:.1f} s' for m, v in rat['node_build_s'].items())}; "
          f"evaluations' share of the whole-graph solve {', '.join(f'{m} {v:.0%}' for m, v in rat['eval_share'].items())}"
          f" (build.json, {rat['sources']['build.json']}); compiled / uncompiled per-node evaluations "
          f"{rat['compiled_eval_ratio']:.2f} (e2e.json, {rat['sources']['e2e.json']}).", ""]
    table = table.reset_index()
    md += md_table(list(table.columns), table.to_dict("records"))
    md += ["", "What each chapter solves (kind, model, mesh):", ""]
    md += [f"- {r['chapter']}: {r['problems']}" for r in doc["rows"] if r["solves"]]
    md += ["", "From the store (nothing solved), per notebook: "
           + ", ".join(f"{k} {v:.0f} s" for k, v in doc["wall_from_store_s"].items()) + ".", ""]
    return md + perf.book_budget_findings(doc)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--reuse", action="store_true", help="recompute from results/book_budget.json's entry lists")
    args = ap.parse_args(argv)
    if args.reuse:
        f = OUT / "book_budget.json"
        old = json.loads((f if f.exists() else OUT / "book_budget.partial.json").read_text())
        coll = {"used": old["used"], "wall_from_store_s": old["wall_from_store_s"]}
        measured, machine = old.get("measured", "unknown"), old.get("machine", machine_info())
    else:
        measured, machine = datetime.now(timezone.utc).isoformat(timespec="seconds"), machine_info()
        coll = collect()
        (OUT / "book_budget.partial.json").write_text(  # kept if the analysis below fails
            json.dumps({"measured": measured, "machine": machine, **coll}, indent=1))
    rat = ratios()
    doc = {"measured": measured, "machine": machine, "ratios": rat,
           "rows": budget(coll["used"], rat), **coll}
    write_report(OUT, "book_budget", doc, report(doc))
    (OUT / "book_budget.partial.json").unlink(missing_ok=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
