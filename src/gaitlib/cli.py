"""Command line: ``python -m gaitlib <command>`` (also installed as ``gaitlib``).

Commands
--------
``data --out DIR``   fetch the pinned archives and (re)write the tidy CSVs (gaitlib.data.build)
``run STUDY --out DIR [options]``   run a study and write its frames, figures and
                     ``summary.json`` (stats, RMSEs, parameters). Studies: ``gait`` —
                     natural-gait data tracking, e.g.
                     ``gaitlib run gait --model MSK --cost DT --speed Free --out DIR``
                     (full mesh 20 × 5 LGR unless ``--intervals/--degree`` say otherwise).
``sweep --model M --costs C1,C2 --speeds S1,S2 --out DIR``   solve every cost × speed
                     class on dask.distributed (gaitlib.sweep; a LocalCluster, or an existing
                     cluster with ``--scheduler tcp://host:port``; ``--serial`` without dask)
                     and write ``sweep.csv`` plus each run's outputs in ``DIR/<model>_<cost>_<speed>``.
``card --out DIR``   the replication report card: ``card.csv``, one row per thesis headline
                     number with ours, the verdict and the solution's validity (gaitlib.studies.card)
``gap --data CSV --out DIR``   sim-to-real gap diagnosis of a tidy data CSV: located gap,
                     ranking of candidate effects, shrink; ``diagnosis.json`` + figures (gaitlib.gap)
``gap-twin --effect NAME --magnitude X --seed N --out CSV``   a twin data set with a known
                     injected effect, in the tidy format
``cache verify [--remove] [--root DIR]``   check every cached solution against its checksums;
                     ``--remove`` deletes the corrupt or incomplete ones (they are re-solved on use)
"""

from __future__ import annotations

import argparse
import sys


def _cmd_data(args) -> int:
    from . import data

    paths = data.build(args.out, cache_dir=args.cache)
    for name, p in paths.items():
        print(f"wrote {p}")
    return 0


def _cmd_run(args) -> int:
    import json

    if args.study != "gait":
        raise SystemExit(f"unknown study {args.study!r}; known: gait")
    from .studies import gait

    kw = dict(n_intervals=args.intervals, degree=args.degree, scheme=args.scheme, max_iter=args.max_iter)
    if args.free_contact is not None:
        kw["free_contact"] = args.free_contact
    spec = gait.natural_gait_spec(args.model, args.cost, args.speed, **kw)
    print(f"gaitlib run gait: {spec.model} {spec.cost} {spec.speed_class}, {spec.n_intervals} x {spec.degree} "
          f"{spec.scheme}, key {spec.key()}", flush=True)
    sol = gait.solve_cached(spec, use_cache=not args.no_cache, progress=not args.quiet)
    if sol.stats.get("from_cache") and not sol.success:
        print(f"note: a cached failed solve ({sol.stats['status']}), loaded from {sol.stats.get('cache_path')}; "
              f"--no-cache solves it again", file=sys.stderr)
    out = gait.write_outputs(sol, args.out, figures=not args.no_figures)
    st = sol.stats
    print(json.dumps({k: st[k] for k in ("status", "iterations", "solve_time_s", "time_per_iteration_s",
                                         "objective", "max_violation")}, indent=1))
    print(f"wrote {out}")
    return 0 if sol.success else 2


def _cmd_sweep(args) -> int:
    """``gaitlib sweep``: cost functions × speed classes of one model as one sweep."""
    import math

    import pandas as pd

    from . import sweep as sw
    from . import transcription as tr
    from .studies import gait

    costs = [c.strip() for c in args.costs.split(",") if c.strip()]
    speeds = [s.strip() for s in args.speeds.split(",") if s.strip()]
    if not costs or not speeds:
        raise SystemExit("--costs and --speeds need at least one comma-separated name each")
    kw = dict(n_intervals=args.intervals, degree=args.degree, max_iter=args.max_iter)
    try:
        specs = {f"{args.model}_{c}_{s}": tr.GaitSpec(model=args.model, cost=c, speed_class=s, **kw)
                 for c in costs for s in speeds}
    except ValueError as e:
        raise SystemExit(f"gaitlib sweep: {e}") from None
    recs = sw.solve_specs(specs, use_cache=not args.no_cache, cache_root=args.cache, scheduler=args.scheduler,
                          n_workers=args.workers, serial=args.serial, progress=True)
    from pathlib import Path

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for name, r in recs.items():
        st = r.value.stats if r.value is not None else {}
        rows.append({"name": name, "status": r.status, "ok": r.ok, "iterations": st.get("iterations"),
                     "wall": r.wall_s, "solve_time_s": st.get("solve_time_s"),
                     "time_per_iteration_s": st.get("time_per_iteration_s"), "objective": st.get("objective", math.nan),
                     "from_cache": st.get("from_cache"), "worker": r.worker,
                     "error": (r.error or "").strip().splitlines()[-1] if r.error else ""})
        if r.value is not None:
            gait.write_outputs(r.value, out / name, figures=not args.no_figures)
        elif r.error:
            (out / name).mkdir(parents=True, exist_ok=True)
            (out / name / "error.txt").write_text(r.error)
    pd.DataFrame(rows).to_csv(out / "sweep.csv", index=False)
    print(f"wrote {out / 'sweep.csv'} ({sum(r.ok for r in recs.values())}/{len(recs)} ok)")
    return 0 if all(r.ok for r in recs.values()) else 2


def _cmd_cache(args) -> int:
    """``gaitlib cache verify``: every entry of a cache checked against its manifest."""
    import shutil

    from . import cache

    rows = cache.scan(args.root)
    bad = [(p, fault) for p, fault in rows if fault]
    for p, fault in bad:
        print(f"{'removed' if args.remove else 'corrupt'}: {p}: {fault}")
        if args.remove:
            shutil.rmtree(p, ignore_errors=True)
    print(f"{len(rows) - len(bad)} valid, {len(bad)} corrupt entries under {args.root or cache.default_dir()}")
    return 0 if args.remove or not bad else 1


def _add_cache_parser(sub) -> None:
    c = sub.add_parser("cache", help="check (and clean) the solutions cache")
    c.add_argument("action", choices=["verify"], help="verify: check every entry against its checksums")
    c.add_argument("--root", default=None, help="cache directory (default: $GAITLIB_SOLUTIONS or "
                                                "~/.cache/gaitlib/solutions)")
    c.add_argument("--remove", action="store_true", help="delete corrupt or incomplete entries")
    c.set_defaults(func=_cmd_cache)


def _cmd_card(args) -> int:
    """``gaitlib card``: the replication report card from the stored solutions."""
    from .studies import card

    f = card.write(args.out)
    import pandas as pd

    c = pd.read_csv(f)
    print(card.counts(c).to_string())
    print(f"wrote {f} ({len(c)} rows)")
    return 0


def _add_card_parser(sub) -> None:
    c = sub.add_parser("card", help="the replication report card (card.csv) from the stored solutions")
    c.add_argument("--out", required=True, help="output directory (card.csv is written there)")
    c.set_defaults(func=_cmd_card)


def _add_sweep_parser(sub) -> None:
    w = sub.add_parser("sweep", help="solve cost functions x speed classes as one (distributed) sweep")
    w.add_argument("--model", default="MSK", choices=["SK", "MSK", "NMSK"])
    w.add_argument("--costs", required=True, help="comma-separated cost functions, e.g. DT,SDT1,SP1")
    w.add_argument("--speeds", default="Free", help="comma-separated speed classes, e.g. VerySlow,Slow,Free")
    w.add_argument("--intervals", type=int, default=20, help="mesh intervals (thesis: 20)")
    w.add_argument("--degree", type=int, default=5, help="collocation points per interval (thesis: 5)")
    w.add_argument("--max-iter", type=int, default=1000)
    w.add_argument("--scheduler", default=None,
                   help="address (tcp://host:port) or scheduler file of an existing dask cluster "
                        "(default: a LocalCluster over the machine's cores)")
    w.add_argument("--workers", type=int, default=None, help="LocalCluster worker processes (default: cores)")
    w.add_argument("--serial", action="store_true", help="run in this process without dask")
    w.add_argument("--cache", default=None, help="solutions cache (default: $GAITLIB_SOLUTIONS or "
                                                 "~/.cache/gaitlib/solutions), passed to every worker")
    w.add_argument("--no-cache", action="store_true", help="solve even if cached solutions exist")
    w.add_argument("--no-figures", action="store_true")
    w.add_argument("--out", required=True, help="output directory")
    w.set_defaults(func=_cmd_sweep)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="gaitlib", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    d = sub.add_parser("data", help="fetch the public data archives and write tidy CSVs")
    d.add_argument("--out", default="data", help="output directory (default: data)")
    d.add_argument("--cache", default=None, help="archive cache (default: $GAITLIB_CACHE or ~/.cache/gaitlib)")
    d.set_defaults(func=_cmd_data)

    r = sub.add_parser("run", help="run a study (gait) and write frames, figures and summary.json")
    r.add_argument("study", help="study name: gait")
    r.add_argument("--out", required=True, help="output directory")
    r.add_argument("--model", default="MSK", choices=["SK", "MSK", "NMSK"])
    r.add_argument("--cost", default=None, help="cost function (default: Eq4.11 for SK, Eq5.33 for MSK, "
                                                 "Eq5.55 for NMSK; also DT, SDT1..3, SP1..3, FP)")
    r.add_argument("--speed", default="Free", help="speed class (VerySlow, Slow, Free, Fast, VeryFast)")
    r.add_argument("--intervals", type=int, default=20, help="mesh intervals (thesis: 20)")
    r.add_argument("--degree", type=int, default=5, help="collocation points per interval (thesis: 5)")
    r.add_argument("--scheme", default="lgr", choices=["lgr", "trapezoidal", "hermite-simpson"])
    r.add_argument("--max-iter", type=int, default=1000)
    fc = r.add_mutually_exclusive_group()
    fc.add_argument("--free-contact", dest="free_contact", action="store_true", default=None,
                    help="identify the 39 contact parameters (Ch 4; default: fixed, thesis Tables 4.17/4.18)")
    fc.add_argument("--fixed-contact", dest="free_contact", action="store_false")
    r.add_argument("--no-cache", action="store_true", help="solve even if a cached solution exists")
    r.add_argument("--no-figures", action="store_true")
    r.add_argument("--quiet", action="store_true", help="no IPOPT progress log")
    r.set_defaults(func=_cmd_run)
    _add_sweep_parser(sub)
    _add_cache_parser(sub)
    _add_card_parser(sub)
    from .gap.cli import add_parsers as _add_gap_parsers  # gaitlib gap, gaitlib gap-twin (issue 7)

    _add_gap_parsers(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return args.func(args)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
