"""Command-line subcommands ``gaitlib gap`` and ``gaitlib gap-twin`` (:mod:`gaitlib.cli`;
exit status and outputs as described there)."""

from __future__ import annotations

import json
import sys
from pathlib import Path


def _base(args, speed_class: str) -> dict:
    base = dict(model=args.model, cost=args.cost, speed_class=speed_class, n_intervals=args.intervals,
                degree=args.degree, max_iter=args.max_iter)
    if args.derivatives:
        base["derivatives"] = args.derivatives
    return base


def _spec(base: dict):
    """The baseline spec (its options checked before any solve)."""
    from ..problems import gait as gait_ocp

    return gait_ocp.GaitSpec(**base)


def effect_names(text: str | None) -> list | None:
    """``--effects`` as a list of known effect names (None: all); ``CLIError`` naming the
    known ones otherwise."""
    from .common import CLIError
    from ..effects import EFFECTS

    if text is None:
        return None
    names = [e.strip() for e in text.split(",") if e.strip()]
    unknown = [n for n in names if n not in EFFECTS]
    if unknown or not names:
        what = f"unknown effect(s) {', '.join(unknown)}" if unknown else "no effect named"
        raise CLIError(f"--effects: {what}; known: {', '.join(EFFECTS)}")
    return list(dict.fromkeys(names))


GAP_FILES = ("diagnosis.json", "located.csv", "ranking.csv", "gap_heatmap.png", "ranking.png", "shrink.png")


def cmd_gap(args) -> int:
    """``gaitlib gap --data CSV --out DIR``: diagnose the gap; writes diagnosis.json + figures.
    Data that fail the reader's checks (:func:`gaitlib.gap.io.read_data`,
    :mod:`gaitlib.plausibility`): one line on stderr, exit 2, nothing built or written."""
    from . import common as cli
    from ..gap import diagnose
    from ..gap import io as gio
    from ..gap import reference

    effects = effect_names(args.effects)
    # the data gates (gaitlib.plausibility) run here, before any problem is built
    ds = gio.read_data(args.data, like=args.like, speed_class=args.speed_class, fill_from=args.fill_from,
                       allow_no_sd=args.allow_no_sd, n_subjects=args.n_subjects)
    ref = None
    if args.reference is not None:
        ref = gio.read_data(args.reference, like=args.like, speed_class=ds.gait.speed_class, fill_from=args.fill_from,
                            allow_no_sd=args.allow_no_sd, n_subjects=args.reference_n_subjects)
        try:
            reference.check_same_grid(ds, ref)
        except ValueError as e:
            raise cli.CLIError(str(e)) from None
    base = _base(args, ds.gait.speed_class)
    _spec(base)
    root = cli.check_cache(args.cache, not args.no_cache)
    out = Path(args.out)
    owned = set(GAP_FILES) | ({p.name for p in out.glob("shrink_*.csv")} if out.is_dir() else set())
    with cli.Output(out, overwrite=args.overwrite, owned=owned, last=("diagnosis.json",),
                    what="the diagnosis's files (diagnosis.json, located.csv, ranking.csv, shrink_*.csv, "
                         "figures)") as o:
        print(f"gaitlib gap: {ds.label} ({ds.base}, {ds.gait.speed_class}, n = {ds.n} from {ds.n_source}); "
              f"baseline {args.model} {args.cost} {args.intervals} x {args.degree}, objective {args.objective}"
              + (f"; the change relative to {ref.label} (n = {ref.n})" if ref is not None else ""), flush=True)
        d = diagnose.diagnose(ds, base=base, effects=effects, objective=args.objective, resamples=args.resamples,
                       seed=args.seed, root=root, use_cache=not args.no_cache, serial=args.serial,
                       n_workers=args.workers, scheduler=args.scheduler, progress=True, reference=ref)
        d.save(o.tmp, figures=not args.no_figures)
    cols = ["rank", "effect", "n_params", "start", "nests_baseline", "status", "pct_closed", "dAIC", "dBIC",
            "residual_ratio"] + (["parameter_change"] if ref is not None else [])
    print(d.ranking[[c for c in cols if c in d.ranking.columns]].to_string(index=False,
                                                                         float_format=lambda v: f"{v:.2f}"))
    summary = {"top_effect": d.top_effect, "verdict": d.verdict, "rss_baseline": d.located.rss,
               "n_eff": d.located.n_eff, "baseline_status": d.baseline.stats["status"]}
    calib = ((getattr(d, "settings", None) or {}).get("reference") or {}).get("null_calibration")
    if calib is not None:  # the relative diagnosis's null calibration
        summary.update(null_draws=calib["draws"], null_lowest_dBIC=calib["lowest_dBIC"],
                       null_rank=calib.get("rank", 1),
                       threshold_used=d.settings.get("threshold_used"),
                       min_share_closed=d.settings.get("min_share_closed"),
                       held_by_share_floor=d.settings.get("held_by_share_floor"),
                       centred=d.settings.get("centred"), median_dBIC=d.settings.get("median_dBIC"),
                       share_closed=d.settings.get("share_closed"))
    print(json.dumps(summary, indent=1))
    print(f"wrote {out / 'diagnosis.json'}")
    failed = [(f.effect, f.status) for f in d.fits.values() if not f.ok]
    if failed:
        print(f"gaitlib gap: {len(failed)} of {len(d.fits)} candidates did not converge "
              f"({', '.join(f'{n} {s}' for n, s in failed)}): the ranking does not test them", file=sys.stderr)
        return cli.EXIT_FAILED
    return 0


def twin_effects(args) -> tuple:
    """``--effect/--magnitude`` (and ``--effect2/--magnitude2``) as ((name, magnitude), …),
    checked against the effect registry and its bounds (:func:`gaitlib.effects.validate`)
    before any solve; ``CLIError`` otherwise."""
    from .common import CLIError
    from ..effects import EFFECTS, validate

    pairs = []
    for opt, eff, mag in (("", args.effect, args.magnitude), ("2", args.effect2, args.magnitude2)):
        if eff is None or eff == "none":
            if mag is not None:
                raise CLIError(f"--magnitude{opt} given without an effect (--effect{opt} {eff or 'none'})")
            continue
        if eff not in EFFECTS:
            raise CLIError(f"--effect{opt}: unknown effect {eff!r}; known: {', '.join(EFFECTS)} (or none)")
        p = EFFECTS[eff].magnitude
        if mag is None:
            unit = "" if p.unit in ("", "1") else f" {p.unit}"
            raise CLIError(f"--effect{opt} {eff} needs --magnitude{opt} ({p.name} in [{p.lower:g}, {p.upper:g}]"
                           f"{unit}; {p.null:g} is no effect)")
        pairs.append((eff, mag))
    try:
        return validate(tuple(pairs), args.model)
    except ValueError as e:
        raise CLIError(str(e)) from None


def cmd_gap_twin(args) -> int:
    """``gaitlib gap-twin --effect NAME --magnitude X --seed N --out CSV``."""
    from . import common as cli
    from ..gap.twin import write_twin

    effects = twin_effects(args)
    base = _base(args, args.speed)
    _spec(base)
    root = cli.check_cache(args.cache, not args.no_cache)
    out = Path(args.out)
    truth = out.with_suffix(".truth.json")
    with cli.Output(out.parent if str(out.parent) else Path("."), overwrite=args.overwrite,
                    files=(out.name, truth.name), last=(truth.name,),
                    what=f"{out.name} and {truth.name}") as o:
        write_twin(o.tmp / out.name, effects, args.seed, base=base, root=root, use_cache=not args.no_cache,
                   noise=not args.no_noise)
    print(f"wrote {out} (truth: {truth})")
    return 0


VALIDATE_FILES = ("validation.json", "cases.csv", "scores.csv", "confusion.csv")


def cmd_gap_validate(args) -> int:
    """``gaitlib gap-validate --out DIR``: the non-circular validation (:mod:`gaitlib.gap.validate`):
    manipulated real data diagnosed as a user's CSV; writes validation.json, cases.csv,
    scores.csv, confusion.csv."""
    from . import common as cli
    from ..gap import validate as V

    known = tuple(x for x in V.ALL_SETS if not (args.relative and x == "model-variant"))
    sets = known if args.set == "all" else tuple(dict.fromkeys(x.strip() for x in args.set.split(",")))
    bad = [x for x in sets if x not in known]
    if bad or not sets:
        raise cli.CLIError(f"--set: unknown set(s) {', '.join(bad) or '(none)'}; known"
                           f"{' with --relative' if args.relative else ''}: all, {', '.join(known)}")
    base = _base(args, args.speed)
    _spec(base)
    root = cli.check_cache(args.cache, not args.no_cache)
    out = Path(args.out)
    table = V.draws(sets, args.per_band)
    print(f"gaitlib gap-validate: {len(table)} manipulated data sets + {'a reference' if args.relative else 'the unedited one'} ({', '.join(sets)}; "
          f"method {V.METHOD.hash()}" + (f", relative method {V.RELATIVE.hash()}" if args.relative else "")
          + f"); baseline {args.model} {args.cost} {args.intervals} x {args.degree}", flush=True)
    with cli.Output(out, overwrite=args.overwrite, files=VALIDATE_FILES, last=("validation.json",),
                    what="the validation's files (validation.json, cases.csv, scores.csv, confusion.csv)") as o:
        v = V.run(sets, per_band=args.per_band, speed_class=args.speed, base=base, root=root,
                  use_cache=not args.no_cache, serial=args.serial, n_workers=args.workers, scheduler=args.scheduler,
                  progress=True, relative=args.relative, replicate=args.replicate, checkpoint=args.checkpoint)
        v.save(o.tmp)
    print(v.scores().to_string(index=False, float_format=lambda x: f"{x:.0f}"))
    print(f"wrote {out / 'validation.json'}")
    return 0


def _common(p, mesh=(10, 3)):
    from .common import _add_output_options, _int_options

    p.add_argument("--model", default="SK", choices=["SK", "MSK", "NMSK"], help="baseline model (default SK)")
    p.add_argument("--cost", default="DT", help="baseline cost function (default DT)")
    _int_options(p, mesh)
    _add_output_options(p)


def add_parsers(sub) -> None:
    from .common import finite_float, int_at_least
    from ..effects import EFFECTS

    g = sub.add_parser("gap", help="sim-to-real gap diagnosis of a tidy data CSV (diagnosis.json + figures)")
    g.add_argument("--data", required=True, help="tidy CSV (gaitlib.data format)")
    g.add_argument("--out", required=True, help="output directory")
    g.add_argument("--like", default=None, help="base data set for speed, cycle time and events only "
                                                "(schwartz2008|gaitutils; default: the CSV's source)")
    g.add_argument("--n-subjects", type=int_at_least(1), default=None,
                   help="subjects behind the CSV's means (SD/sqrt(n) is their standard error); required unless "
                        "the CSV has an n_subjects column or its source is schwartz2008/gaitutils")
    g.add_argument("--fill-from", default=None, help="take quantities the problem needs but the CSV lacks from "
                                                     "this data set (e.g. schwartz2008); excluded from the gap")
    g.add_argument("--speed-class", default=None, help="the speed class to diagnose if the CSV has several "
                                                       "(VerySlow|Slow|Free|Fast|VeryFast)")
    g.add_argument("--reference", default=None,
                   help="a reference tidy CSV of the same speed class: diagnose the change from it (each model's "
                        "own residual on the reference subtracted; gaitlib.gap.reference) instead of the whole gap")
    g.add_argument("--reference-n-subjects", type=int_at_least(1), default=None,
                   help="subjects behind the reference's means (as --n-subjects)")
    g.add_argument("--allow-no-sd", action="store_true", help="accept curves whose SD is 0 everywhere: tracked, "
                                                              "but left out of the located gap")
    g.add_argument("--effects", default=None, help=f"comma-separated candidates (default all applicable: "
                                                   f"{','.join(EFFECTS)})")
    g.add_argument("--objective", default="fit", choices=["fit", "cost"])
    g.add_argument("--resamples", type=int_at_least(0), default=200,
                   help="data resamples for the %% closed interval (0: no interval)")
    g.add_argument("--seed", type=int_at_least(0), default=0)
    g.add_argument("--serial", action="store_true", help="solve in this process without dask")
    g.add_argument("--workers", type=int_at_least(1), default=None, help="LocalCluster workers (default: cores)")
    g.add_argument("--scheduler", default=None, help="existing dask scheduler address")
    g.add_argument("--no-figures", action="store_true")
    _common(g)
    g.set_defaults(func=cmd_gap)

    t = sub.add_parser("gap-twin", help="write a twin data set (baseline model + an injected effect + noise)")
    t.add_argument("--effect", required=True, help=f"effect name ({', '.join(EFFECTS)}) or 'none'")
    t.add_argument("--magnitude", type=finite_float, default=None,
                   help="the effect's magnitude (its first parameter, within its bounds); required with --effect")
    t.add_argument("--effect2", default=None)
    t.add_argument("--magnitude2", type=finite_float, default=None)
    t.add_argument("--seed", type=int_at_least(0), default=0, help="noise seed")
    t.add_argument("--speed", default="Free", help="speed class of the real data the twin is made from")
    t.add_argument("--no-noise", action="store_true")
    t.add_argument("--out", required=True, help="output CSV (its truth goes to <stem>.truth.json beside it)")
    _common(t)
    t.set_defaults(func=cmd_gap_twin)

    v = sub.add_parser("gap-validate", help="validate the gap diagnosis on real data manipulated by known amounts "
                                            "(in-library and out-of-library effects)")
    v.add_argument("--out", required=True, help="output directory")
    v.add_argument("--set", default="all", help="all (default) or a comma-separated list of: independent, "
                                                "out-of-library, model-variant, null")
    v.add_argument("--relative", action="store_true",
                   help="diagnose each manipulated data set relative to the unedited data (gaitlib gap --reference), "
                        "both resampled within their sampling error")
    v.add_argument("--per-band", type=int_at_least(1), default=1, help="draws per manipulation and magnitude band")
    v.add_argument("--replicate", type=int_at_least(0), default=0,
                   help="0 (default): the method's own draws; k > 0: every draw (magnitudes, signs, resampling "
                        "seeds, the reference) afresh, the method unchanged")
    v.add_argument("--checkpoint", default=None,
                   help="JSON file the finished cases are written to after each case; a rerun given the same file "
                        "diagnoses only the cases not in it (resumes a run cut short, also without the solution cache)")
    v.add_argument("--speed", default="Free", help="speed class of the real data (default Free)")
    v.add_argument("--serial", action="store_true", help="solve in this process without dask")
    v.add_argument("--workers", type=int_at_least(1), default=None, help="LocalCluster workers (default: cores)")
    v.add_argument("--scheduler", default=None, help="existing dask scheduler address")
    _common(v)
    v.set_defaults(func=cmd_gap_validate)
