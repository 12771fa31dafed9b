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
                     ranking of candidate effects, shrink; ``diagnosis.json`` + figures (gaitlib.gap);
                     ``--reference REF``: the change from a reference data set (gaitlib.gap.reference)
``gap-twin --effect NAME --magnitude X --seed N --out CSV``   a twin data set with a known
                     injected effect, in the tidy format
``gap-validate --out DIR``   the gap diagnosis on real data manipulated by known amounts
                     (in-library and out-of-library; gaitlib.gap.validate): ``validation.json``,
                     ``cases.csv``, ``scores.csv``, ``confusion.csv``; ``--relative``: each set
                     diagnosed relative to the unedited data
``cache verify [--remove] [--root DIR]``   check every cached solution against its checksums;
                     ``--remove`` deletes the corrupt or incomplete ones (they are re-solved on use)

Exit status: 0 when every solve the reported result rests on converged (IPOPT
``Solve_Succeeded`` or ``Solved_To_Acceptable_Level``); 2 otherwise — a run that did not
converge (its outputs are written, with its status), a sweep with a failed run, a gap
diagnosis with a candidate that did not converge — and on every error or refusal (one line
``gaitlib <command>: <message>`` on stderr; ``--debug`` shows the traceback): bad options
(checked before any solve), an output that exists (``--overwrite``) or cannot be written,
a gap baseline none of whose starts converged (``baseline failed: <statuses>``), a twin
whose generating solve did not converge (nothing written).

Outputs: ``--out`` and the solutions cache are checked for writability before any solve.
Results are written to a temporary folder next to ``--out`` (``.<name>.partial-*``) and
moved into place at the end, so an interrupted command leaves no half-written result. An
existing non-empty ``--out`` is refused unless ``--overwrite``, which replaces only the
files the command owns: ``run`` — the files its new ``summary.json`` lists and those the
old one listed; ``sweep`` — ``sweep.csv`` and the run folders of the new and the old
``sweep.csv``; ``gap`` — ``diagnosis.json``, ``located.csv``, ``ranking.csv``,
``shrink_*.csv`` and its figures; ``gap-twin`` — the CSV and its ``.truth.json``;
``gap-validate`` — its four files. Other
files in the folder are kept.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path

from .. import blas
from .common import EXIT_FAILED, CLIError, Output, _add_output_options, _defects_option, _int_options, _Parser, check_cache, int_at_least

#: gaitlib.ocp.COMPILE_ENV (tests/test_compiled.py checks they agree)
COMPILE_ENV = "GAITLIB_COMPILE"


def _listed_files(summary: Path) -> set:
    """The ``files`` a previous run's ``summary.json`` lists (none if unreadable)."""
    try:
        files = json.loads(summary.read_text()).get("files", [])
        return {str(n) for n in files if isinstance(n, str) and "/" not in n and n not in ("", ".", "..")}
    except (OSError, ValueError, AttributeError):
        return set()


# -- commands -----------------------------------------------------------------------

def _cmd_data(args) -> int:
    from .. import data

    paths = data.build(args.out, cache_dir=args.cache)
    for name, p in paths.items():
        print(f"wrote {p}")
    return 0


def _cmd_run(args) -> int:
    import warnings

    from ..ocp import SolveFailedWarning
    from ..problems import gait as gait_ocp
    from ..studies import gait

    kw = dict(n_intervals=args.intervals, degree=args.degree, scheme=args.scheme, max_iter=args.max_iter)
    if args.derivatives:
        kw["derivatives"] = args.derivatives
    if args.defects == "integral":
        kw["defects"] = "integral"
    if args.free_contact is not None:
        kw["free_contact"] = args.free_contact
    spec = gait.natural_gait_spec(args.model, args.cost, args.speed, **kw)
    root = check_cache(args.cache, not args.no_cache)
    out = Path(args.out)
    with Output(out, overwrite=args.overwrite, owned=_listed_files(out / "summary.json") | {"summary.json"},
                last=("summary.json",), what="the files the previous run listed in summary.json") as o:
        print(f"gaitlib run gait: {spec.model} {spec.cost} {spec.speed_class}, {spec.n_intervals} x {spec.degree} "
              f"{spec.scheme}, key {spec.key()}", flush=True)
        with warnings.catch_warnings():  # a failed solve is reported below, with its status
            warnings.simplefilter("ignore", SolveFailedWarning)
            sol = gait_ocp.solve_cached(spec, use_cache=not args.no_cache, root=root, progress=not args.quiet)
        if sol.stats.get("from_cache") and not sol.success:
            print(f"note: a cached failed solve ({sol.stats['status']}), loaded from "
                  f"{sol.stats.get('cache_path')}; --no-cache solves it again", file=sys.stderr)
        gait.write_outputs(sol, o.tmp, figures=not args.no_figures)
    st = sol.stats
    print(json.dumps({k: st[k] for k in ("status", "iterations", "solve_time_s", "time_per_iteration_s",
                                         "objective", "max_violation")}, indent=1))
    print(f"wrote {out}")
    if not sol.success:
        print(f"gaitlib run: the solve did not converge ({st['status']}, {st['iterations']} iterations); "
              f"its outputs carry that status", file=sys.stderr)
        return EXIT_FAILED
    return 0


def _split(text: str) -> list:
    return [c.strip() for c in text.split(",") if c.strip()]


def _cmd_sweep(args) -> int:
    """``gaitlib sweep``: cost functions × speed classes of one model as one sweep."""
    import pandas as pd

    from ..problems import gait as gait_ocp
    from ..studies import gait

    costs, speeds = _split(args.costs), _split(args.speeds)
    if not costs or not speeds:
        raise CLIError("--costs and --speeds need at least one comma-separated name each")
    kw = dict(n_intervals=args.intervals, degree=args.degree, max_iter=args.max_iter)
    if args.derivatives:
        kw["derivatives"] = args.derivatives
    if args.defects == "integral":
        kw["defects"] = "integral"
    specs = {f"{args.model}_{c}_{s}": gait_ocp.GaitSpec(model=args.model, cost=c, speed_class=s, **kw)
             for c in costs for s in speeds}
    root = check_cache(args.cache, not args.no_cache)
    out = Path(args.out)
    old = set()
    try:
        old = {str(n) for n in pd.read_csv(out / "sweep.csv")["name"] if "/" not in str(n)}
    except (OSError, ValueError, KeyError, pd.errors.ParserError):
        pass
    with Output(out, overwrite=args.overwrite, owned=old | {"sweep.csv"}, last=("sweep.csv",),
                what="sweep.csv and the run folders it lists") as o:
        recs = gait_ocp.solve_specs(specs, use_cache=not args.no_cache, cache_root=root, scheduler=args.scheduler,
                              n_workers=args.workers, serial=args.serial, progress=True)
        rows = []
        for name, r in recs.items():
            st = r.value.stats if r.value is not None else {}
            rows.append({"name": name, "status": r.status, "ok": r.ok, "iterations": st.get("iterations"),
                         "wall": r.wall_s, "solve_time_s": st.get("solve_time_s"),
                         "time_per_iteration_s": st.get("time_per_iteration_s"),
                         "objective": st.get("objective", math.nan), "from_cache": st.get("from_cache"),
                         "worker": r.worker, "error": (r.error or "").strip().splitlines()[-1] if r.error else ""})
            if r.value is not None:
                gait.write_outputs(r.value, o.tmp / name, figures=not args.no_figures)
            elif r.error:
                (o.tmp / name).mkdir(parents=True, exist_ok=True)
                (o.tmp / name / "error.txt").write_text(r.error)
        pd.DataFrame(rows).to_csv(o.tmp / "sweep.csv", index=False)
    n_ok = sum(r.ok for r in recs.values())
    print(f"wrote {out / 'sweep.csv'} ({n_ok}/{len(recs)} ok)")
    if n_ok < len(recs):
        bad = ", ".join(f"{n} {r.status}" for n, r in recs.items() if not r.ok)
        print(f"gaitlib sweep: {len(recs) - n_ok} of {len(recs)} runs did not converge: {bad}", file=sys.stderr)
        return EXIT_FAILED
    return 0


def _cmd_cache(args) -> int:
    """``gaitlib cache verify``: every entry of a cache checked against its manifest."""
    import shutil

    from .. import cache

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
    from ..studies import card

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
    _int_options(w, (20, 5))
    _defects_option(w)
    w.add_argument("--scheduler", default=None,
                   help="address (tcp://host:port) or scheduler file of an existing dask cluster "
                        "(default: a LocalCluster over the machine's cores)")
    w.add_argument("--workers", type=int_at_least(1), default=None,
                   help="LocalCluster worker processes (default: cores)")
    w.add_argument("--serial", action="store_true", help="run in this process without dask")
    w.add_argument("--no-figures", action="store_true")
    w.add_argument("--out", required=True, help="output directory")
    _add_output_options(w)
    w.set_defaults(func=_cmd_sweep)


def _add_debug(p, top: bool = False):
    p.add_argument("--debug", action="store_true", default=False if top else argparse.SUPPRESS,
                   help="show the traceback of an error")


def build_parser() -> argparse.ArgumentParser:
    from .. import __version__

    p = _Parser(prog="gaitlib", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"gaitlib {__version__}")
    _add_debug(p, top=True)
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    d = sub.add_parser("data", help="fetch the public data archives and write tidy CSVs")
    d.add_argument("--out", default="data", help="output directory (default: data)")
    d.add_argument("--cache", default=None, help="archive cache (default: $GAITLIB_CACHE or ~/.cache/gaitlib)")
    d.set_defaults(func=_cmd_data)

    r = sub.add_parser("run", help="run a study (gait) and write frames, figures and summary.json")
    r.add_argument("study", choices=["gait"], help="study name: gait")
    r.add_argument("--out", required=True, help="output directory")
    r.add_argument("--model", default="MSK", choices=["SK", "MSK", "NMSK"])
    r.add_argument("--cost", default=None, help="cost function (default: Eq4.11 for SK, Eq5.33 for MSK, "
                                                 "Eq5.55 for NMSK; also DT, SDT1..3, SP1..3, FP)")
    r.add_argument("--speed", default="Free", help="speed class (VerySlow, Slow, Free, Fast, VeryFast)")
    _int_options(r, (20, 5))
    _defects_option(r)
    r.add_argument("--scheme", default="lgr", choices=["lgr", "trapezoidal", "hermite-simpson"])
    fc = r.add_mutually_exclusive_group()
    fc.add_argument("--free-contact", dest="free_contact", action="store_true", default=None,
                    help="identify the 39 contact parameters (Ch 4; default: fixed, thesis Tables 4.17/4.18)")
    fc.add_argument("--fixed-contact", dest="free_contact", action="store_false")
    r.add_argument("--no-figures", action="store_true")
    r.add_argument("--quiet", action="store_true", help="no IPOPT progress log")
    _add_output_options(r)
    r.set_defaults(func=_cmd_run)
    _add_sweep_parser(sub)
    _add_cache_parser(sub)
    _add_card_parser(sub)
    from .gap import add_parsers as _add_gap_parsers  # gaitlib gap, gaitlib gap-twin

    _add_gap_parsers(sub)
    for sp in sub.choices.values():
        _add_debug(sp)
    return p


def _expected() -> tuple:
    """Exception types whose message is the whole story (no "--debug" hint)."""
    from ..gap.diagnose import BaselineFailed
    from ..ocp import SolveFailedError

    return (CLIError, ValueError, OSError, BaselineFailed, SolveFailedError)


def main(argv: list[str] | None = None) -> int:
    blas.pin()  # the Makefile's BLAS settings unless set; numpy is not imported yet
    args = build_parser().parse_args(argv)
    if getattr(args, "compiled", False):
        if args.derivatives != "nodes":  # the whole-graph derivatives are too large to compile
            print(f"gaitlib {args.command}: --compiled needs --derivatives nodes", file=sys.stderr)
            return EXIT_FAILED
        os.environ[COMPILE_ENV] = "1"  # the environment, so sweep workers inherit it
    if args.debug:
        return args.func(args)
    try:
        return args.func(args)
    except KeyboardInterrupt:
        print(f"gaitlib {args.command}: interrupted", file=sys.stderr)
        return 130
    except Exception as e:  # noqa: BLE001 — one line for the user; --debug re-raises
        msg = " ".join(str(e).split()) or type(e).__name__
        if not isinstance(e, _expected()):
            msg = f"{type(e).__name__}: {msg} (--debug shows the traceback)"
        print(f"gaitlib {args.command}: {msg}", file=sys.stderr)
        return EXIT_FAILED


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
