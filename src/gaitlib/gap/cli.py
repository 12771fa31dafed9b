"""Command-line subcommands ``gaitlib gap`` and ``gaitlib gap-twin`` (:mod:`gaitlib.cli`)."""

from __future__ import annotations

import json


def _base(args, speed_class: str) -> dict:
    return dict(model=args.model, cost=args.cost, speed_class=speed_class, n_intervals=args.intervals,
                degree=args.degree, max_iter=args.max_iter)


def cmd_gap(args) -> int:
    """``gaitlib gap --data CSV --out DIR``: diagnose the gap; writes diagnosis.json + figures."""
    from . import diagnose as D
    from . import io as gio

    from ..data import DataError

    try:
        ds = gio.read_data(args.data, like=args.like, fill_from=args.fill_from, n_subjects=args.n_subjects)
    except DataError as e:
        raise SystemExit(f"gaitlib gap: {e}") from None
    effects = [e.strip() for e in args.effects.split(",")] if args.effects else None
    print(f"gaitlib gap: {ds.label} ({ds.base}, {ds.gait.speed_class}, n = {ds.n} from {ds.n_source}); "
          f"baseline {args.model} "
          f"{args.cost} {args.intervals} x {args.degree}, objective {args.objective}", flush=True)
    d = D.diagnose(ds, base=_base(args, ds.gait.speed_class), effects=effects, objective=args.objective,
                   resamples=args.resamples, seed=args.seed, root=args.cache, use_cache=not args.no_cache,
                   serial=args.serial, n_workers=args.workers, scheduler=args.scheduler, progress=True)
    out = d.save(args.out, figures=not args.no_figures)
    cols = ["rank", "effect", "n_params", "start", "nests_baseline", "status", "pct_closed", "dAIC", "dBIC"]
    print(d.ranking[cols].to_string(index=False, float_format=lambda v: f"{v:.2f}"))
    print(json.dumps({"top_effect": d.top_effect, "verdict": d.verdict, "rss_baseline": d.located.rss,
                      "n_eff": d.located.n_eff}, indent=1))
    print(f"wrote {out / 'diagnosis.json'}")
    return 0


def cmd_gap_twin(args) -> int:
    """``gaitlib gap-twin --effect NAME --magnitude X --seed N --out CSV``."""
    from .twin import write_twin

    effects = [(args.effect, args.magnitude)] if args.effect != "none" else []
    if args.effect2:
        if args.magnitude2 is None:
            raise SystemExit("--effect2 needs --magnitude2")
        effects.append((args.effect2, args.magnitude2))
    try:
        path = write_twin(args.out, tuple(effects), args.seed, base=_base(args, args.speed),
                          root=args.cache, use_cache=not args.no_cache, noise=not args.no_noise)
    except ValueError as e:
        raise SystemExit(f"gaitlib gap-twin: {e}") from None
    print(f"wrote {path} (truth: {path.with_suffix('.truth.json')})")
    return 0


def _common(p, mesh=(10, 3)):
    p.add_argument("--model", default="SK", choices=["SK", "MSK", "NMSK"], help="baseline model (default SK)")
    p.add_argument("--cost", default="DT", help="baseline cost function (default DT)")
    p.add_argument("--intervals", type=int, default=mesh[0], help=f"mesh intervals (default {mesh[0]})")
    p.add_argument("--degree", type=int, default=mesh[1], help=f"LGR points per interval (default {mesh[1]})")
    p.add_argument("--max-iter", type=int, default=1000)
    p.add_argument("--cache", default=None, help="solutions cache (default $GAITLIB_SOLUTIONS or ~/.cache/gaitlib/solutions)")
    p.add_argument("--no-cache", action="store_true")


def add_parsers(sub) -> None:
    from .effects import EFFECTS

    g = sub.add_parser("gap", help="sim-to-real gap diagnosis of a tidy data CSV (diagnosis.json + figures)")
    g.add_argument("--data", required=True, help="tidy CSV (gaitlib.data format)")
    g.add_argument("--out", required=True, help="output directory")
    g.add_argument("--like", default=None, help="base data set for speed, cycle time and events only "
                                                "(schwartz2008|gaitutils; default: the CSV's source)")
    g.add_argument("--n-subjects", type=int, default=None,
                   help="subjects behind the CSV's means (SD/sqrt(n) is their standard error); required unless "
                        "the CSV has an n_subjects column or its source is schwartz2008/gaitutils")
    g.add_argument("--fill-from", default=None, help="take quantities the problem needs but the CSV lacks from "
                                                     "this data set (e.g. schwartz2008); excluded from the gap")
    g.add_argument("--effects", default=None, help=f"comma-separated candidates (default all applicable: "
                                                   f"{','.join(EFFECTS)})")
    g.add_argument("--objective", default="fit", choices=["fit", "cost"])
    g.add_argument("--resamples", type=int, default=200, help="data resamples for the %% closed interval")
    g.add_argument("--seed", type=int, default=0)
    g.add_argument("--serial", action="store_true", help="solve in this process without dask")
    g.add_argument("--workers", type=int, default=None, help="LocalCluster workers (default: cores)")
    g.add_argument("--scheduler", default=None, help="existing dask scheduler address")
    g.add_argument("--no-figures", action="store_true")
    _common(g)
    g.set_defaults(func=cmd_gap)

    t = sub.add_parser("gap-twin", help="write a twin data set (baseline model + an injected effect + noise)")
    t.add_argument("--effect", required=True, help=f"effect name ({', '.join(EFFECTS)}) or 'none'")
    t.add_argument("--magnitude", type=float, default=0.0, help="the effect's magnitude (its first parameter)")
    t.add_argument("--effect2", default=None)
    t.add_argument("--magnitude2", type=float, default=None)
    t.add_argument("--seed", type=int, default=0, help="noise seed")
    t.add_argument("--speed", default="Free", help="speed class of the real data the twin is made from")
    t.add_argument("--no-noise", action="store_true")
    t.add_argument("--out", required=True, help="output CSV")
    _common(t)
    t.set_defaults(func=cmd_gap_twin)
