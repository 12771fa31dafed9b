"""Two solution caches side by side: the entries with the same key (the same problem, start
and data) solved on two derivative paths (or two machines, two code versions).

    .venv/bin/python benchmarks/compare_stores.py A_ROOT B_ROOT --labels graph nodes --out NAME

For every key present in both roots (``<root>/gait/<key>/summary.json``, and the jumps'
``<root>/jump/<key>/solution.json``, their final continuation stage): IPOPT status,
iterations, build and solve time (s, as recorded when each was solved) and objective of each.
The keys of warm-started solves include their start's content, so a chain that diverges
early has different keys further down and is not compared. Writes
``benchmarks/results/NAME.json`` and ``.md``; times are as measured at solve time (the load
then is not recorded), iterations and statuses are what the comparison rests on.
"""

from __future__ import annotations

import argparse
import json
import sys
from datetime import datetime, timezone
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from report import md_table, write_report  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"


def entries(root: Path) -> dict:
    out = {}
    for f in sorted(Path(root).glob("jump/*/solution.json")):  # a jump: its final continuation stage
        d = json.loads(f.read_text())
        out[f.parent.name] = {"status": d.get("status"), "iterations": d.get("iterations"),
                              "build_s": d.get("build_time"), "solve_s": d.get("solve_time"),
                              "objective": d.get("objective"), "run": "jump (final stage)"}
    for f in sorted(Path(root).glob("gait/*/summary.json")):
        s = json.loads(f.read_text())
        st = s.get("stats", s)
        spec = json.loads((f.parent / "spec.json").read_text()) if (f.parent / "spec.json").exists() else {}
        out[f.parent.name] = {"status": st.get("status"), "iterations": st.get("iterations"),
                              "build_s": st.get("build_time_s"), "solve_s": st.get("solve_time_s"),
                              "objective": st.get("objective"),
                              "run": " ".join(str(spec.get(k, "")) for k in ("model", "cost", "speed_class")).strip()}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--labels", nargs=2, default=("a", "b"))
    ap.add_argument("--out", required=True)
    args = ap.parse_args(argv)
    la, lb = args.labels
    A, B = entries(Path(args.a)), entries(Path(args.b))
    rows = []
    for key in sorted(set(A) & set(B)):
        a, b = A[key], B[key]
        rows.append({"key": key, "run": a["run"], f"{la} status": a["status"], f"{lb} status": b["status"],
                     f"{la} iterations": a["iterations"], f"{lb} iterations": b["iterations"],
                     f"{la} build_s": a["build_s"], f"{lb} build_s": b["build_s"],
                     f"{la} solve_s": a["solve_s"], f"{lb} solve_s": b["solve_s"],
                     f"{la} objective": a["objective"], f"{lb} objective": b["objective"]})
    tot = {f"{lab} {q}": sum(float(r[f"{lab} {q}"] or 0) for r in rows)
           for lab in (la, lb) for q in ("iterations", "build_s", "solve_s")}
    conv = {lab: sum(r[f"{lab} status"] == "Solve_Succeeded" for r in rows) for lab in (la, lb)}
    doc = {"written": datetime.now(timezone.utc).isoformat(timespec="seconds"), "roots": [args.a, args.b],
           "labels": [la, lb], "keys_a": len(A), "keys_b": len(B), "rows": rows, "totals": tot, "converged": conv}
    md = [f"# Same keys, two caches: {la} ({args.a}) vs {lb} ({args.b})", "",
          f"{len(rows)} keys in both ({len(A)} in {la}, {len(B)} in {lb}); converged: {la} {conv[la]}, {lb} {conv[lb]}. "
          f"Totals: iterations {tot[f'{la} iterations']:.0f} vs {tot[f'{lb} iterations']:.0f}; build "
          f"{tot[f'{la} build_s']:.0f} vs {tot[f'{lb} build_s']:.0f} s; solve {tot[f'{la} solve_s']:.0f} vs "
          f"{tot[f'{lb} solve_s']:.0f} s (as recorded at solve time).", ""]
    md += md_table(list(rows[0]) if rows else ["key"], rows)
    write_report(OUT, args.out, doc, md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
