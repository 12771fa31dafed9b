"""benchmarks/gap_pair_test.py's conditional criterion and rule, by hand."""

from __future__ import annotations

import math

import pytest

import gap_pair_test as gpt


def test_conditional_bic_by_hand():
    # n_eff 282, the pair's RSS 600 against the other effect's 650, one parameter:
    # 282 ln(600/650) + ln 282 = -22.572... + 5.642 = -16.93
    assert gpt.conditional(282.0, 600.0, 650.0, 1) == pytest.approx(
        282.0 * math.log(600.0 / 650.0) + math.log(282.0))
    assert abs(gpt.conditional(282.0, 600.0, 650.0, 1) - (-16.930)) < 1e-3
    assert gpt.conditional(100.0, 50.0, 50.0, 2) == pytest.approx(2 * math.log(100.0))  # no gain: the penalty


def test_pair_rule_names_the_top_only_when_its_conditional_passes():
    assert gpt.pair_rule("grf_scale", -12.0, -10.0) == "grf_scale"
    assert gpt.pair_rule("grf_scale", -10.0, -10.0) == "grf_scale"  # at the threshold, as the method's ≤
    assert gpt.pair_rule("grf_scale", -9.9, -10.0) == "unexplained"
    assert gpt.pair_rule("grf_scale", float("nan"), -10.0) == "unexplained"
