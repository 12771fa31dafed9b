"""Revision 6's quiet points on revision 5's own draws: the paired side of the change. An
experiment on Chapter 8's relative validation of relative method revision 5 (issue 25).

    GAITLIB_SOLUTIONS=<cache> .venv/bin/python benchmarks/gap_quiet_points.py   # reloads the validation's solves

Revision 6 leaves out of the relative located gap the points where neither data set has
variance (the GRFs in swing, :mod:`gaitlib.gap.reference`). Its own validation is on fresh
draws (its hash seeds them); this experiment runs the whole relative validation again on
revision 5's draws — the same reference, null draws, manipulations and resampling seeds, so
the same fits, from the cache — with the quiet points left out, everything else revision 5's
(its null threshold rule included, recomputed on its null draws so located). The two are
then paired case by case: only the location differs.

Writes ``results/gap_validation/quiet_points_rev5/`` (the four files of ``gaitlib
gap-validate``), its settings naming the validation it pairs with.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
OUT = HERE / "results" / "gap_validation" / "quiet_points_rev5"

#: The stored validation whose draws are diagnosed again: relative method revision 5.
VALIDATION = "relative_rev5"


def main() -> int:
    from gaitlib.gap import diagnose as D
    from gaitlib.gap import method as M
    from gaitlib.gap import reference as R
    from gaitlib.gap import validate as V
    from gaitlib.studies import gap as gap_study

    val = gap_study.superseded_validation(VALIDATION)
    h5 = val.settings["relative_method_hash"]
    fields = {k: v for k, v in val.settings["relative_method"].items() if k in M.RelativeMethod.__dataclass_fields__}

    @dataclasses.dataclass(frozen=True)
    class Rev5Draws(M.RelativeMethod):
        """Revision 5's fields with the quiet points left out, seeded as revision 5 (its hash):
        the same draws, the same null draws, so the same fits."""

        def hash(self) -> str:
            return h5

    method = Rev5Draws(**{**fields, "quiet_points": True})
    saved = {m: m.RELATIVE for m in (D, R, V)}
    try:
        for m in saved:
            m.RELATIVE = method
        v = V.run(tuple(val.settings["sets"]), per_band=int(val.settings["per_band"]),
                  speed_class=val.settings["speed_class"], base=dict(val.settings["base"]), relative=True,
                  replicate=int(val.settings.get("replicate", 0)), progress=True)
    finally:
        for m, r in saved.items():
            m.RELATIVE = r
    v.settings.update(pairs_with=VALIDATION, experiment="benchmarks/gap_quiet_points.py")
    v.save(OUT)
    print(v.scores().to_string(index=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
