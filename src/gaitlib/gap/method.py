"""The gap diagnosis's settings in one frozen object: the thresholds and grids
:mod:`gaitlib.gap.diagnose` decides with and its figures draw.

:data:`METHOD` is the method in use; :meth:`Method.hash` names it. The validation of
:mod:`gaitlib.gap.validate` derives its draws (effects, magnitudes, seeds) from that hash,
so any change of the method redraws the validation instead of re-scoring the draws the
method was tuned on. The module-level names (``BIC_THRESHOLD`` …) are the fields of
:data:`METHOD`.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass

import numpy as np

__all__ = ["Method", "METHOD", "RelativeMethod", "RELATIVE", "BIC_THRESHOLD", "PROFILE_GRID", "DEFAULT_BASE", "EXPLAINED_PCT", "RUNNER_UP_MARGIN",
           "draw_statistic", "share_beyond_median", "null_threshold"]


@dataclass(frozen=True)
class Method:
    """How the diagnosis decides.

    Attributes
    ----------
    bic_threshold : ΔBIC a top effect must reach (≤) to be named ("very strong" evidence on
        Kass & Raftery's scale).
    explained_pct : % of the RSS a named effect must close for the verdict "explained"
        (else "partial").
    profile_grid : fixed magnitudes tried for ``identify="profile"`` effects that need a
        re-solve, ((effect, (magnitudes …)), …).
    base : the default baseline, ((field, value), …) of a
        :class:`~gaitlib.problems.gait.GaitSpec`: SK, data tracking (Eq 4.11), 10 × 3 LGR.
    runner_up_margin : the out-of-library test (0: off). The top effect is named only if its
        ΔBIC is below every other ranked candidate's by at least this much (a Bayes factor
        of the top effect *over the runner-up*, not only over the baseline); otherwise the
        diagnosis is "unexplained" and names the contenders. When the data hold a gap no
        library effect represents, several effects each absorb a part of it and none stands
        out; when one effect is the cause, it does.
    revision : bumped when the diagnosis decides differently for a reason outside these
        fields, so that the validation is redrawn. 1: the first frozen method; 2: the
        force-plate gain effect scales the data's SD with its mean (``grf_scale`` version 2,
        :mod:`gaitlib.effects`) and the validation's gain manipulations do too.
    """

    bic_threshold: float = -10.0
    explained_pct: float = 50.0
    profile_grid: tuple = (("co_contraction", (0.1, 0.2, 0.35, 0.5)), ("joint_stiffness", (-0.5, 1.0, 2.0, 3.0)))
    base: tuple = (("model", "SK"), ("cost", "DT"), ("n_intervals", 10), ("degree", 3))
    runner_up_margin: float = 10.0
    revision: int = 2

    def to_dict(self) -> dict:
        return json.loads(json.dumps(asdict(self)))

    def hash(self) -> str:
        """16 hex digits of the SHA-256 of the method's fields (canonical JSON)."""
        text = json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:16]


#: The method in use.
METHOD = Method()

#: ΔBIC a top effect must reach (≤) to be named.
BIC_THRESHOLD = METHOD.bic_threshold
#: Fixed magnitudes tried for ``identify="profile"`` effects that need a re-solve.
PROFILE_GRID = {k: tuple(v) for k, v in METHOD.profile_grid}
#: Default baseline: SK, data-tracking cost (Eq 4.11), 10 × 3 LGR.
DEFAULT_BASE = dict(METHOD.base)
#: % of the RSS a named effect must close for the verdict "explained" (else "partial").
EXPLAINED_PCT = METHOD.explained_pct
#: ΔBIC by which the named effect must beat the runner-up (0: no such test).
RUNNER_UP_MARGIN = METHOD.runner_up_margin


@dataclass(frozen=True)
class RelativeMethod:
    """How a change relative to a reference is decided (:mod:`gaitlib.gap.reference`), on
    top of :data:`METHOD` (its threshold, margin and verdicts).

    Attributes
    ----------
    null_draws : K. On the clean background of a relative diagnosis a free parameter absorbs
        a share of pure sampling error that the criterion counts as very strong evidence (the
        first relative validation, Chapter 8: draws with nothing changed reached ΔBIC −134).
        So the reference is redrawn K times within the sampling error of a difference of two
        group means (:func:`gaitlib.gap.reference.null_draw`, seeds from this hash and the
        reference's signature), each draw diagnosed relative to the reference exactly as the
        data are, and each draw's lowest ΔBIC over the candidates kept (a max statistic,
        family-wise over the candidates). 0: no calibration.
    null_rank : r. A top effect is named only if its ΔBIC is also below the r-th lowest of the
        K draws' statistics (:func:`null_threshold`): a rank test at level r/(K + 1). Up to
        revision 4, r = 1 of K = 9 (level 0.1): the threshold was one extreme of 9 draws, and
        it moved from −27 to −82 with the draws alone (Chapter 8, replicate 1 of revision 4,
        where one draw's baseline reached a better fit of the reference than the candidates'
        and every candidate gained 46–82); revision 5 keeps the level, 2 of 19, so that one
        such draw does not set the threshold.
    reference_rounds : rounds of the self-consistent reference fit (0: off). A multistart
        does not always find the reference's best basin, and the data's continuation can move
        into a better one: the relative gap then carries a change of the fit, not of the data
        (Chapter 8: re-solved from a null draw's fit, the reference reached a lower objective
        than its kept fit in 2 of 4 draws, one of them the draw named ``ankle_offset``). So
        each model's fit of the reference is re-solved from its fit of the data; where that
        reaches a lower objective (by more than ``consistency_margin``, relative) it replaces
        the reference's fit, and the data are continued again from it (the lower of the two
        data fits kept); a further round re-solves only the models whose data fit moved
        (:func:`gaitlib.gap.diagnose.consistent_fits`). The null draws are fitted the same way.
    consistency_margin : relative objective decrease that counts as a better fit of the
        reference (below it, the same optimum reached again).
    tilt_channel : locate the HAT's tilt against the data's pelvic tilt too
        (:data:`gaitlib.gap.locate.RELATIVE_ONLY`): relative, the model's constant misfit of
        the tilt cancels, and without it a hip-angle offset and a HAT COM offset are the same
        change on the located channels (the HAT tilts by the offset, its COM kept over the
        hips; revision 2's validation: ΔBIC equal to 0.1 in both hip-offset cases).
    baseline_from_candidates : before the rounds, the baseline's fit of the data is also
        re-solved from every nested candidate's fit of it and the lowest kept (revision 3's
        validation, ``benchmarks/gap_baseline_basin.py``: in two null draws the baseline's
        continuation carried an anterior-GRF misfit the candidates' fits lacked, so candidates
        were credited with closing up to 38 % of the difference, first-ranked ΔBIC down to −136).
    quiet_points : leave out of the relative located gap the points where neither the data
        nor the reference have variance (both SDs below the locate floor: the GRFs in swing,
        zero in every child; :mod:`gaitlib.gap.reference`, "Quiet points"). On revision 4's
        replicates no threshold named more than 42 of 48 middle/large injections: the six
        others were all a normalising-mass error named a plate gain or the reverse, and 86 %
        of ``body_mass``'s GRF excess over ``grf_scale`` lay in the swing phases, where the
        model's feet carry load the data do not (``benchmarks/gap_load_confusion.py``).
    reference_from_candidates : the baseline's fit of the reference is also re-solved from
        every nested candidate's fit of the reference and the lowest kept, before the data are
        continued from it. Revision 6's calibrations had draws in which every candidate gained
        alike (the median candidate's ΔBIC ≤ −20; 5 of 19 and 3 of 19 in its two replicates,
        statistics to −236, thresholds −206 and −78); in 4 of those 8 the baseline's fit of the
        reference had kept the reference's multistart through the self-consistency rounds,
        against 1 of the 30 other draws, where re-solving it from the draw's fit went lower.
        Paired on revision 6's draws (``benchmarks/gap_paired.py reference_fit_rev6``) the
        threshold moved from −206 to −101 and the independent middle+large injections named
        from 17 to 24 of 24, out-of-library and null unchanged (16/16, 4/4); on its own fresh
        draws: threshold −60 (still three common-mode draws), 20 of 24, 16/16, 3/4.
    baseline_fallback : where the baseline's continuation from the reference's fit does not
        converge on the data (or on a null draw), the baseline is solved from each nested
        candidate's fit of the reference, and where none of those converges from the absolute
        multistart's starts (:func:`gaitlib.gap.diagnose.fallback_baselines`). Up to revision
        7 such a case had no baseline and nothing was ranked (revision 7's fresh draws: the
        large knee offset ``knee_offset_large_1``, IPOPT at its iteration limit).
    lowest_pair : each model's gap relative to the reference is located for two pairs of its
        fits — the final one (after the self-consistency rounds and the other starts) and the
        continuation (its first fit of the reference and the data's fit continued from it) —
        and the pair with the lower RSS kept, for the baseline and every NLP candidate alike
        (:func:`gaitlib.gap.diagnose.relative_fits`, :func:`~gaitlib.gap.diagnose.
        lowest_baseline_pair`); the null draws the same way. A pair whose two fits sit in
        different optima carries that difference as a change: in revision 7's
        ``ankle_offset_middle_1`` the ankle offset's kept fit of the data came from the null
        start (its continuation ended above the baseline's fit), identified the injected
        −2.7° as −3.0°, and closed the ankle channels but opened the right anterior GRF: 6 %
        of the gap closed; its continuation pair closes 56 %.
        Paired on revision 7's draws with ``baseline_fallback`` (``benchmarks/gap_paired.py
        lowest_pair_rev7``): independent middle + large injections named 20 → 22 of 24, small
        4 → 5 of 12, out-of-library and null unchanged (16/16, 3/4); the null draws' lowest
        statistic −237 → −77, the threshold −60 → −64. On revision 8's own fresh draws: no
        common-mode draw among the 19 (revision 7: 3; revision 6: 5 and 3), threshold −20
        (revision 7: −60), independent middle + large 21 of 24 (two of the three misses a
        body-mass injection ranked first with ``grf_scale`` within the margin, the third a hip
        offset at ΔBIC −18), small 8 of 12, out-of-library 15 of 16, null 4 of 4. On a second
        set of draws (``--replicate 1``): threshold −24, middle + large 23 of 24 (the miss again
        a body-mass injection with ``grf_scale`` within the margin), small 9 of 12,
        out-of-library 13 of 16, null 4 of 4 — pooled, middle + large 44 of 48.
    min_share_closed : % of the relative located gap the top effect must also close to be
        named (0: no such test; from revision 10, ``centred``, % of what the median ranked
        candidate leaves open). On revision 8's two sets of draws the four out-of-library
        cases named an effect (a swing-phase hip bump named ``hip_offset`` twice, an ankle
        moment gain ``foot_contact``, a loading-peak bump ``hip_offset``) closed 14–19 % of
        their relative gap, the middle and large injections named right 12 % or more, all but
        one of them 35 % or more: an effect that explains the change closes much of it, one
        that absorbs a part of a change it does not represent closes a little. Replayed on
        those rankings (Chapter 8, ``gaitlib.studies.gap.share_floor_sweep``), a 20 % floor
        gives out-of-library 32 of 32 and middle + large 43 of 48 — chosen on those draws, so
        revision 9's own fresh draws are its test. On them: threshold −38, middle + large 21
        of 24 (all three misses the ``body_mass``/``grf_scale`` pair: one ranked the other
        first, two with the other within the margin), small 6 of 12, out-of-library 15 of 16
        (the floor held one, ``ankle_moment_gain_middle_1``: ``hip_offset`` at ΔBIC −42
        closing 18 %; the miss, ``impact_peak_large_0``, named ``grf_scale`` closing 23 %),
        null 4 of 4; no case named right was held. On a second set of draws (``--replicate
        1``) the floor held nothing, but 7 of the 19 null draws were common-mode (median
        statistic ≤ −20, in all 7 the baseline's fit of the reference kept; lowest −634), so
        the threshold fell to −570 and middle + large were named right in 4 of 24 (the
        injected effect ranked first in 22), small 1 of 12, out-of-library 16 of 16, null 4
        of 4 — pooled, middle + large 25 of 48: the common mode of the calibration, not the
        floor, is what this revision leaves open.
    centred : decide relative to the median ranked candidate, in the null draws and the data
        alike. The statistic (:func:`draw_statistic`): a top effect is named only if its ΔBIC
        is at or below :data:`BIC_THRESHOLD` and its ΔBIC minus the median candidate's at or
        below the null threshold, each null draw's statistic being its lowest ΔBIC minus its
        median one. The share (:func:`share_beyond_median`): the ``min_share_closed`` floor
        applies to the share of the gap the median candidate leaves open that the top effect
        closes. A shift every candidate is credited with alike — the baseline's fit of the
        reference in a worse optimum than the candidates' fits of it (the common mode of
        revisions 6, 7 and 9) — moves the median with the best and so cancels; one effect that
        absorbs a change stands out from the median. Replayed on the stored rankings of
        revisions 8 and 9 (two sets of draws each; Chapter 8,
        ``gaitlib.studies.gap.centred_replay``, 20 % floor throughout): revision 9's second set,
        whose 7 common-mode null draws had set the threshold at −570, gets −32, its middle +
        large injections named right 4 → 22 of 24; the other three sets' thresholds move by at
        most 2; pooled over the four, middle + large 68 → 85 of 96, out-of-library 63 → 64 of
        64, null 16 of 16. The statistic alone gives 86 and 60 (on the common-mode set three
        loading-peak bumps were named ``body_mass`` closing 76–82 % of their gap, the median
        candidate 71–78 %); on that set the share alone changes nothing (no candidate passes
        −570) — chosen on those draws, so revision 10's own fresh draws are its
        test. On them: threshold −35 (18 ranked null draws, none common-mode), independent
        middle + large 23 of 24 (the miss a plate gain ranked first with ``body_mass`` within
        the margin), small 7 of 12, out-of-library 16 of 16 (the floor held two, closing 16 %
        and 19 % of what the median candidate left), null 4 of 4. On a second set of draws
        (``--replicate 1``): threshold −22 (18 ranked null draws, none common-mode), middle +
        large 23 of 24 (the miss a plate gain with ``body_mass`` ranked first), small 5 of 12
        (8 without the floor), out-of-library 16 of 16 (the floor held four, closing 10–17 %;
        12 without it), null 4 of 4 — pooled over both sets, middle + large 46 of 48 (95 %
        interval 86–99 %), out-of-library 32 of 32 (89–100 %).
    revision : bumped when the relative diagnosis decides differently for a reason outside
        these fields. 1: the null calibration; 2: the self-consistent reference fit; 3: the
        HAT tilt located; 4: the baseline from the candidates' fits; 5: the threshold the
        second lowest of 19 null draws (``null_rank``) instead of the lowest of 9; 6: the quiet
        points left out (``quiet_points``); 7: the baseline's fit of the reference from the
        candidates' (``reference_from_candidates``); 8: a fallback for a failed baseline
        continuation (``baseline_fallback``) and the lower of two located pairs
        (``lowest_pair``); 9: a floor on the share of the gap the named effect closes
        (``min_share_closed``); 10: the statistic relative to the median candidate
        (``centred``).
    """

    null_draws: int = 19
    null_rank: int = 2
    reference_rounds: int = 2
    consistency_margin: float = 1e-6
    tilt_channel: bool = True
    baseline_from_candidates: bool = True
    quiet_points: bool = True
    reference_from_candidates: bool = True
    baseline_fallback: bool = True
    lowest_pair: bool = True
    min_share_closed: float = 20.0
    centred: bool = True
    revision: int = 10

    def to_dict(self) -> dict:
        return json.loads(json.dumps(asdict(self)))

    def hash(self) -> str:
        """16 hex digits of the SHA-256 of this method's fields and :data:`METHOD`'s."""
        text = json.dumps({"method": METHOD.to_dict(), "relative": self.to_dict()}, sort_keys=True,
                          separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def draw_statistic(dbic: dict, centred: bool = False) -> float | None:
    """A draw's (or a diagnosis's) statistic from its ranked candidates' ΔBIC (``{effect:
    ΔBIC}``): the lowest; ``centred`` (:attr:`RelativeMethod.centred`), the lowest minus the
    median of all of them (the median of an even count the mean of the middle two). None
    without a ranked candidate."""
    v = [float(x) for x in dbic.values()]
    if not v:
        return None
    return min(v) - float(np.median(v)) if centred else min(v)


def share_beyond_median(pct: float, pcts, centred: bool = True) -> float:
    """The share (%) of the located gap a top effect closes that the floor
    (:attr:`RelativeMethod.min_share_closed`) is held to: its own ``pct`` closed, or with
    ``centred`` the part of the gap the median ranked candidate leaves open (``pcts``: every
    ranked candidate's % closed) that it closes, ``100 (pct − m) / (100 − m)`` for the median
    ``m`` (0 if the median closes everything)."""
    if not centred:
        return float(pct)
    m = float(np.median([float(x) for x in pcts]))
    return 0.0 if m >= 100.0 else 100.0 * (float(pct) - m) / (100.0 - m)


def null_threshold(per_draw: list, rank: int, centred: bool = False) -> float | None:
    """The null calibration's threshold: the ``rank``-th lowest of the draws' statistics
    (:func:`draw_statistic`: each the lowest ΔBIC any candidate reached on that draw, minus
    the draw's median candidate's if ``centred``; ``per_draw``: one ``{effect: ΔBIC}`` per
    draw; draws with no ranked candidate carry no statistic and are left out). With fewer
    ranked draws than ``rank``, the highest of them; None if none was ranked."""
    stats = sorted(draw_statistic(p, centred) for p in per_draw if p)
    return stats[min(rank, len(stats)) - 1] if stats else None


#: The relative method in use.
RELATIVE = RelativeMethod()
