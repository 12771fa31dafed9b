"""Command line: ``python -m gaitlib <command>`` (also installed as ``gaitlib``).

Commands
--------
``data --out DIR``   fetch the pinned archives and (re)write the tidy CSVs (gaitlib.data.build)
``run STUDY --out DIR [options]``   run a study and write its frames, figures and
                     ``summary.json`` (stats, RMSEs, parameters). Studies: ``gait`` —
                     natural-gait data tracking, e.g.
                     ``gaitlib run gait --model MSK --cost DT --speed Free --out DIR``
                     (full mesh 20 × 5 LGR unless ``--intervals/--degree`` say otherwise).
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
    out = gait.write_outputs(sol, args.out, figures=not args.no_figures)
    st = sol.stats
    print(json.dumps({k: st[k] for k in ("status", "iterations", "solve_time_s", "time_per_iteration_s",
                                         "objective", "max_violation")}, indent=1))
    print(f"wrote {out}")
    return 0 if sol.success else 2


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
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return args.func(args)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
