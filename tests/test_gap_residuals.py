"""The HAT residual loads as located channels (gaitlib.gap.locate): OpenSim's guideline
thresholds by hand, the residuals outside the RSS, and the thesis's bounds far below the
guidelines (so residual actuators cannot absorb an effect)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gaitlib import conventions as cv
from gaitlib.gap import io as gio
from gaitlib.gap import locate as L
from gaitlib.problems import gait as gait_ocp


@pytest.fixture(scope="module")
def real():
    return gio.load_real()


def _sim_from_data(gait, residuals=None):
    """A 'solution' that is the data's mean itself on τ (sim_channels format)."""
    view = gait_ocp.tracking_data(gait)
    tau = np.asarray(view.time, float) / float(view.cycle_time)
    cols = [c for c in gait.mean.columns if c in view.mean.columns]
    sim = pd.DataFrame({c: view.mean[c].to_numpy() for c in cols}, index=pd.Index(np.mod(tau, 1.0), name="tau"))
    sim = sim[~sim.index.duplicated(keep="first")].sort_index()
    if residuals is not None:
        for r, v in residuals.items():
            sim[f"res_{r}"] = v(sim.index.to_numpy())
    return sim


def test_residual_thresholds_by_hand(real):
    g = real.gait
    # the Schwartz Free mean: peak total GRF near the vertical peak of one foot plus the other's share
    fx = g.mean["grf_x_r"] + g.mean["grf_x_l"]
    fy = g.mean["grf_y_r"] + g.mean["grf_y_l"]
    f_peak = max(np.sqrt(a * a + b * b) for a, b in zip(fx, fy))
    thr = L.residual_thresholds(g)
    assert thr["R_x"] == pytest.approx(0.05 * f_peak) and thr["R_y"] == pytest.approx(0.05 * f_peak)
    assert thr["R_z"] == pytest.approx(0.01 * 0.55 * 1.47 * f_peak)
    # a 41.4 kg child: peak force above body weight (406 N), so ≈ 20 N and ≈ 3.3 N·m
    assert 20.0 < thr["R_x"] < 30.0 and 3.0 < thr["R_z"] < 5.0
    # the gait problem's residual bounds (thesis Eq 4.8) are below 5 % of the guidelines
    b = dict(zip(cv.RESIDUALS, gait_ocp.GaitSpec().residual_bounds))
    assert all(b[r] / thr[r] < 0.05 for r in cv.RESIDUALS)


def test_residuals_are_located_but_not_in_the_rss(real):
    g = real.gait
    plain = L.locate(_sim_from_data(g), real)
    big = {"R_x": lambda t: 30.0 * np.sin(2 * np.pi * t), "R_y": lambda t: 0.5 + 0 * t, "R_z": lambda t: 0.1 + 0 * t}
    sim = _sim_from_data(g, big)
    withres = L.locate(sim, real)
    assert plain.residuals is None and withres.residuals is not None
    assert withres.rss == pytest.approx(plain.rss, rel=0, abs=1e-12) and withres.n_eff == plain.n_eff
    t = withres.residuals.set_index("channel")
    thr = L.residual_thresholds(g)
    assert t.loc["residual:R_x", "over"] and not t.loc["residual:R_y", "over"]
    # the peak over the solution's own samples (no interpolation)
    assert t.loc["residual:R_x", "peak"] == np.max(np.abs(30.0 * np.sin(2 * np.pi * sim.index.to_numpy())))
    assert t.loc["residual:R_y", "peak_ratio"] == pytest.approx(0.5 / thr["R_y"])
    assert withres.summary()["residuals_over_guideline"] == ["residual:R_x"]
