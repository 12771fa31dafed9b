"""Command line: ``python -m gaitlib <command>`` (also installed as ``gaitlib``).

Commands
--------
``data --out DIR``   fetch the pinned archives and (re)write the tidy CSVs (gaitlib.data.build)
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


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="gaitlib", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    d = sub.add_parser("data", help="fetch the public data archives and write tidy CSVs")
    d.add_argument("--out", default="data", help="output directory (default: data)")
    d.add_argument("--cache", default=None, help="archive cache (default: $GAITLIB_CACHE or ~/.cache/gaitlib)")
    d.set_defaults(func=_cmd_data)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return args.func(args)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
