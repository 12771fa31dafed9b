"""Which of the gap chapter's solves are missing from the cache and the store — nothing is solved.

Usage: python tools/gap_dry_run.py [S] [U] [N] [tv] [tvf]
(S: Schwartz 2008 SK diagnosis, U: gaitutils, N: NMSK attribution, tv: twin check 10 × 3,
tvf: twin check 20 × 5; default all)

Runs the chapter's study functions (:mod:`gaitlib.studies.gap`) with every solve replaced by
a refusal that is recorded, and the null-start re-solves of
:func:`gaitlib.gap.diagnose.candidate_fits` recorded instead of run. Prints, per
diagnosis, the candidates that are not ranked (failed search or a located gap above the
baseline's), then every missing solve and every null-start job: what a book run would have
to solve. An empty writable cache is used, so only the repository's store counts.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile

from gaitlib import blas

blas.pin()  # the Makefile's BLAS settings, before numpy is imported
os.environ["GAITLIB_SOLUTIONS"] = tempfile.mkdtemp(prefix="gap-dry-run-")


def main(which) -> int:
    from gaitlib.gap import diagnose as D
    from gaitlib.gap import solve as S
    from gaitlib.studies import gap as G

    misses, nulls = [], []

    def refuse(self, gait, guess=None):
        misses.append((self.spec.model, self.spec.n_intervals, self.spec.degree, self.spec.effects, gait.source,
                       "warm" if guess is not None else "cold"))
        raise RuntimeError("not in the store (dry run: not solved)")

    def record(groups, **kw):
        for g, (spec, jobs) in groups.items():
            nulls.extend((g, k, spec.n_intervals, spec.degree) for k, _, _ in jobs)
        return {"__records__": {}}

    S.Runner.solve = refuse
    D.null_start_many = record

    def show(label, d):
        s = d.summary()
        print(f"{label}: top {d.top_effect} ({d.verdict}); {json.dumps(s)}", flush=True)

    runs = {"S": ("Schwartz 2008 SK", lambda: G.sk_diagnosis("schwartz2008")),
            "U": ("gaitutils SK", lambda: G.sk_diagnosis("gaitutils")),
            "N": ("NMSK attribution", G.nmsk_attribution)}
    for k in which:
        if k in runs:
            label, fn = runs[k]
            try:
                show(label, fn())
            except RuntimeError as e:
                print(f"{label}: {e}", flush=True)
    for k, fn in (("tv", G.twin_validation), ("tvf", G.twin_validation_full_mesh)):
        if k in which:
            tv = fn()
            for key, d in tv.diags.items():
                if d.summary()["failed_search"] or d.summary()["located_above_baseline"]:
                    show(f"{k} {key}", d)
    print(f"missing solves: {len(misses)}")
    for m in misses:
        print("  ", m)
    print(f"null-start jobs: {len(nulls)}")
    for n in nulls:
        print("  ", n)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:] or ["S", "U", "N", "tv", "tvf"]))
