"""A relative-method change on a stored validation's own draws: the paired side of a change
(issue 25). A new revision of the relative method is validated on fresh draws (its hash seeds
them); this runs the whole stored relative validation again on *its* draws — the same
reference, null draws, manipulations and resampling seeds, so mostly the same fits, from the
cache — with only the named fields of the method changed (its null threshold rule kept,
recomputed on its null draws), so the two can be paired case by case.

    GAITLIB_SOLUTIONS=<cache> .venv/bin/python benchmarks/gap_paired.py reference_fit_rev6
    GAITLIB_SOLUTIONS=<cache> .venv/bin/python benchmarks/gap_paired.py quiet_points_rev5
    GAITLIB_SOLUTIONS=<cache> .venv/bin/python benchmarks/gap_paired.py lowest_pair_rev7

Each experiment (:data:`EXPERIMENTS`) writes ``results/gap_validation/<name>/`` (the four
files of ``gaitlib gap-validate``), its settings naming the validation it pairs with and the
fields it changed. A field the stored validation's method did not have yet (added by a later
revision) must be set by the experiment: it was off then.
"""

from __future__ import annotations

import contextlib
import dataclasses
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results" / "gap_validation"

#: The fields revisions 9 and 10 added, as they were before (off): every experiment on an
#: earlier revision's draws sets them.
_LATER_OFF = {"min_share_closed": 0.0, "centred": False}

#: name → (the stored validation whose draws are diagnosed again, the fields changed).
EXPERIMENTS = {
    # revision 6: the quiet points left out, on revision 5's draws
    "quiet_points_rev5": ("relative_rev5", {"quiet_points": True, "reference_from_candidates": False,
                                            "baseline_fallback": False, "lowest_pair": False, **_LATER_OFF}),
    # revision 7: the baseline's fit of the reference from the candidates', on revision 6's draws
    "reference_fit_rev6": ("relative_rev6", {"reference_from_candidates": True, "baseline_fallback": False,
                                            "lowest_pair": False, **_LATER_OFF}),
    # revision 8: the fallback baseline and the lower of two located pairs, on revision 7's draws
    "lowest_pair_rev7": ("relative_rev7", {"baseline_fallback": True, "lowest_pair": True, **_LATER_OFF}),
}


def stored(name: str):
    """A stored relative validation by folder name: the current one (``relative``) or a
    superseded one."""
    from gaitlib.studies import gap as gap_study

    if name in gap_study.SUPERSEDED_VALIDATIONS:
        return gap_study.superseded_validation(name)
    return gap_study.stored_validation(name)


def stored_method(val, changes: dict):
    """The relative method ``val`` (a stored relative validation) was made with, its fields
    ``changes`` changed, hashing as the stored method — so its draws, null draws and seeds,
    and the fits nothing changed, are the stored ones. A field the stored method did not have
    yet must be in ``changes``."""
    from gaitlib.gap import method as M

    h = val.settings["relative_method_hash"]
    fields = {k: v for k, v in val.settings["relative_method"].items() if k in M.RelativeMethod.__dataclass_fields__}
    unset = sorted(set(M.RelativeMethod.__dataclass_fields__) - set(fields) - set(changes))
    if unset:
        raise ValueError(f"the stored method has no {', '.join(unset)}: the experiment must set it")

    @dataclasses.dataclass(frozen=True)
    class StoredDraws(M.RelativeMethod):
        """The stored method's fields with ``changes``, seeded as the stored method (its hash)."""

        def hash(self) -> str:
            return h

    return StoredDraws(**{**fields, **changes})


@contextlib.contextmanager
def using(method):
    """The relative method of :mod:`gaitlib.gap` (diagnose, reference, validate) replaced by
    ``method`` for the block."""
    from gaitlib.gap import diagnose as D
    from gaitlib.gap import reference as R
    from gaitlib.gap import validate as V

    saved = {m: m.RELATIVE for m in (D, R, V)}
    try:
        for m in saved:
            m.RELATIVE = method
        yield method
    finally:
        for m, r in saved.items():
            m.RELATIVE = r


def calibration_draws(val, names, folder) -> tuple:
    """A stored relative validation's reference and the named null-calibration draws
    (``"null<j>"``), regenerated from its stored seeds: ``(reference, [(name, DataSet), …])``."""
    from gaitlib.gap import reference as R
    from gaitlib.gap import validate as V

    calib = val.unedited["null_calibration"]
    ref, _ = V.relative_null_sets(val, folder)
    return ref, [(n, R.null_draw(ref, int(calib["n_subjects"]), int(calib["seeds"][int(n[4:])]))) for n in names]


def run(name: str):
    """Run experiment ``name`` and save it; returns the Validation."""
    from gaitlib.gap import validate as V

    validation, changes = EXPERIMENTS[name]
    val = stored(validation)
    with using(stored_method(val, changes)):
        v = V.run(tuple(val.settings["sets"]), per_band=int(val.settings["per_band"]),
                  speed_class=val.settings["speed_class"], base=dict(val.settings["base"]), relative=True,
                  replicate=int(val.settings.get("replicate", 0)), progress=True)
    v.settings.update(pairs_with=validation, changed=changes, experiment=f"benchmarks/gap_paired.py {name}")
    v.save(RESULTS / name)
    print(v.scores().to_string(index=False))
    return v


def main(argv: list[str]) -> int:
    names = argv or list(EXPERIMENTS)
    bad = [n for n in names if n not in EXPERIMENTS]
    if bad:
        print(f"unknown experiment {', '.join(bad)}; known: {', '.join(EXPERIMENTS)}", file=sys.stderr)
        return 2
    for n in names:
        run(n)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
