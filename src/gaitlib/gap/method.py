"""The gap diagnosis's settings: the thresholds and grids :mod:`gaitlib.gap.diagnose` decides
with and its figures draw."""

from __future__ import annotations

__all__ = ["BIC_THRESHOLD", "PROFILE_GRID", "DEFAULT_BASE", "EXPLAINED_PCT"]

#: ΔBIC a top effect must reach (≤) to be named.
BIC_THRESHOLD = -10.0
#: Fixed magnitudes tried for ``identify="profile"`` effects that need a re-solve.
PROFILE_GRID = {"co_contraction": (0.1, 0.2, 0.35, 0.5), "joint_stiffness": (-0.5, 1.0, 2.0, 3.0)}
#: Default baseline: SK, data-tracking cost (Eq 4.11), 10 × 3 LGR.
DEFAULT_BASE = dict(model="SK", cost="DT", n_intervals=10, degree=3)
#: % of the RSS a named effect must close for the verdict "explained" (else "partial").
EXPLAINED_PCT = 50.0
