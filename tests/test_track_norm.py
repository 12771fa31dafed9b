"""The tracking normalisation (GaitSpec.track_norm): the SD denominators by hand on made-up
SDs and ranges, each term's total kept, which channels change on the real data, the key
stability of the new option, and a one-line error for a source without SDs."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from gaitlib import data as data_mod
from gaitlib.model import ChildModel
from gaitlib.problems import gait as gait_ocp


def _made_up(n=11):
    """SDs constant over the cycle (so their RMS is the constant) and round ranges."""
    sd = {}
    ranges = {}
    for i, c in enumerate(gait_ocp.LEG_JOINTS):
        sd[c] = 0.1 * (1 + i % 3)          # hip 0.1, knee 0.2, ankle 0.3 rad
        ranges[c] = 0.5 * (1 + i % 3)      # hip 0.5, knee 1.0, ankle 1.5 rad
    for c in gait_ocp.SD_GROUPS[1]:
        sd[c], ranges[c] = 5.0, 50.0
    for c in gait_ocp.GRF_CHANNELS:
        sd[c], ranges[c] = (10.0, 100.0) if "_x_" in c else (40.0, 400.0)
    frame = pd.DataFrame({c: np.full(n, v) for c, v in sd.items()})
    return SimpleNamespace(sd=frame), sd, ranges


def test_sd_denominators_by_hand():
    gait, sd, ranges = _made_up()
    out = gait_ocp.sd_ranges(gait, ranges)
    # angles: Σ 1/range² = 2 (1/0.25 + 1/1 + 1/2.25) = 2 · 5.4444…; Σ 1/σ² = 2 (100 + 25 + 11.111…)
    k = np.sqrt((100 + 25 + 100 / 9) / (4 + 1 + 1 / 2.25))
    assert out["hip_r"] == pytest.approx(k * 0.1, rel=1e-12)
    assert out["knee_l"] == pytest.approx(k * 0.2, rel=1e-12)
    assert out["ankle_r"] == pytest.approx(k * 0.3, rel=1e-12)
    # torques: every σ/range the same (0.1), so k = 10 and the denominators are the ranges
    for c in gait_ocp.SD_GROUPS[1]:
        assert out[c] == pytest.approx(50.0, rel=1e-12)
    # GRFs: x and y have the same σ/range (0.1): again the ranges
    assert out["grf_x_r"] == pytest.approx(100.0) and out["grf_y_l"] == pytest.approx(400.0)


def test_each_term_costs_a_uniform_error_the_same_and_weights_channels_by_one_over_sd_squared():
    gait = data_mod.load_gait_data("Free")
    ref_range = gait_ocp.reference(gait, ChildModel()).ranges
    out = gait_ocp.sd_ranges(gait, ref_range)
    for group in gait_ocp.SD_GROUPS:
        assert sum(1 / out[c] ** 2 for c in group) == pytest.approx(sum(1 / ref_range[c] ** 2 for c in group), rel=1e-12)
        rms = {c: float(np.sqrt(np.mean(gait.sd[c].to_numpy() ** 2))) for c in group}
        a, b = group[0], group[1]
        assert out[a] / out[b] == pytest.approx(rms[a] / rms[b], rel=1e-12)


def test_reference_changes_only_the_measured_channels():
    gait = data_mod.load_gait_data("Free")
    model = ChildModel()
    a = gait_ocp.reference(gait, model).ranges
    b = gait_ocp.reference(gait, model, track_norm="sd").ranges
    changed = {k for k in a if a[k] != b[k]}
    assert changed == {c for g in gait_ocp.SD_GROUPS for c in g}
    # the HAT, metatarsal and jerk denominators (no SD) are untouched
    for c in ("pelvis_tx", "pelvis_ty", "pelvis_tilt", "mtp_r", "mtp_l", "jerk_knee_r"):
        assert a[c] == b[c]
    with pytest.raises(ValueError, match="track_norm"):
        gait_ocp.reference(gait, model, track_norm="thesis")


def test_track_norm_keeps_keys_and_reaches_the_built_problem():
    spec = gait_ocp.GaitSpec(model="MSK", cost="Eq5.33", n_intervals=2, degree=2)
    assert "track_norm" not in spec.to_dict()
    sd = replace(spec, track_norm="sd")
    assert sd.key() != spec.key() and replace(spec, track_norm=None).key() == spec.key()
    assert replace(spec, track_norm="range").key() != spec.key()  # explicit: another spec, the same problem
    assert gait_ocp.GaitSpec.from_dict(sd.to_dict()) == sd
    with pytest.raises(ValueError, match="track_norm"):
        replace(spec, track_norm="SD")
    built = gait_ocp.build(sd)
    gait = data_mod.load_gait_data("Free")
    expected = gait_ocp.sd_ranges(gait, gait_ocp.reference(gait, ChildModel()).ranges)
    for c, v in expected.items():
        assert built.ref.ranges[c] == pytest.approx(v, rel=1e-12)


def test_a_source_without_sds_gets_a_one_line_error():
    gait, _, ranges = _made_up()
    gait.sd = gait.sd.drop(columns=["knee_l"])
    with pytest.raises(ValueError, match=r"channel 'knee_l'") as e:
        gait_ocp.sd_ranges(gait, ranges)
    assert "\n" not in str(e.value)
