"""The laboratory effects (joint-angle offsets, force-plate gain and AP bias): the reference
the NLP tracks equals the data as the gap reads them, both by hand; a manipulation of the
tidy CSV (degrees, N/kg, the data's signs) is undone exactly by its effect."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pandas as pd
import pytest

from gaitlib import conventions as cv
from gaitlib import effects as effects_mod
from gaitlib import ocp
from gaitlib import data as data_mod
from gaitlib.problems import gait as gait_ocp
from gaitlib.gap import io as gio

TINY = dict(n_intervals=4, degree=3)


@pytest.fixture(scope="module")
def real():
    return gio.load_real()


def _hand(name, value, mean, col):
    """The data as a laboratory effect reads them, computed here from its definition."""
    x = mean[col].to_numpy(float)
    if name.endswith("_offset"):
        return x - value if col.startswith(name.split("_")[0] + "_") else x
    if name == "grf_scale":
        return x / (1 + value) if col.startswith("grf_") else x
    if name == "grf_ap_bias":
        if not col.startswith("grf_x_"):
            return x
        on = (mean["grf_y_r"].to_numpy(float) > 10.0).astype(float)
        if col.endswith("_l"):  # the generated left leg: the right's indicator, shifted by half a cycle
            on = data_mod.fourier_shift(on, 0.5, 5)
        return x - value * on
    raise KeyError(name)


@pytest.mark.parametrize("name,value", [("hip_offset", 0.05), ("knee_offset", -0.1), ("ankle_offset", 0.03),
                                        ("grf_scale", 0.08), ("grf_ap_bias", -6.0)])
def test_lab_effect_reference_equals_adjusted_data(real, name, value):
    e = effects_mod.EFFECTS[name]
    assert name in effects_mod.LAB_EFFECTS and name not in effects_mod.MODEL_EFFECTS
    assert name not in effects_mod.TWIN_EFFECTS  # data-model effects: no physics twin
    spec = gait_ocp.GaitSpec(**TINY, effects=((name, None),))
    frame = gait_ocp.tracking_frame(spec, gait_ocp.build(spec).ref)
    assert real.gait.left_shift == 0.5 and effects_mod.left_generated(real.gait)
    names = list(frame.columns)
    dsym, th = ca.SX.sym("d", len(names)), ca.SX.sym("th")
    over = e.reference(ocp.Named(dsym, names, "data"), {e.magnitude.name: th}, None, None)
    cols = sorted(over)
    f = ca.Function("f", [dsym, th], [ca.vertcat(*[over[c] for c in cols])])
    got = np.array([np.asarray(f(r.to_numpy(float), value), float).ravel() for _, r in frame.iterrows()])
    adj = effects_mod.adjust_data(real.gait, {name: {e.magnitude.name: value}})
    refs = frame.rename(columns=lambda c: c[len("ref_"):] if c.startswith("ref_") else c)
    for i, c in enumerate(cols):
        col = c[len("ref_"):]
        # the NLP's per-node reference on the data grid and the data as the gap reads them:
        # each the hand value of its own representation (the model's hip reference is the
        # data's hip minus the pelvis tilt; a constant offset commutes with that)
        assert np.allclose(got[:, i], _hand(name, value, refs, col), atol=1e-9), (name, c)
        assert np.allclose(adj.mean[col].to_numpy(float), _hand(name, value, real.gait.mean, col), atol=1e-9)
    # untouched columns stay as they were; the SDs change only under a gain (with the mean)
    for col in real.gait.mean.columns:
        if f"ref_{col}" not in over:
            assert np.array_equal(adj.mean[col].to_numpy(), real.gait.mean[col].to_numpy()), col
    for col in real.gait.sd.columns:
        want = real.gait.sd[col].to_numpy(float)
        if name == "grf_scale" and col.startswith("grf_"):
            want = want / (1 + value)
        assert np.allclose(adj.sd[col].to_numpy(float), want, rtol=1e-12, atol=0), (name, col)
    # the null value is the data as they are
    assert effects_mod.adjust_data(real.gait, {name: {e.magnitude.name: 0.0}}).mean.equals(real.gait.mean)


def test_sign_convention_of_offsets():
    """The offset is in the model's convention: knee flexion in the data is −knee in the
    model (conventions.DATA_SIGN), hip and ankle keep their sign."""
    assert cv.DATA_SIGN["knee"] == -1.0 and cv.DATA_SIGN["hip"] == 1.0 and cv.DATA_SIGN["ankle"] == 1.0
    for j in ("hip", "knee", "ankle"):
        assert f"{cv.DATA_SIGN[j]:+g}" in effects_mod.EFFECTS[f"{j}_offset"].doc


def test_grf_scale_residual_is_on_the_datas_own_scale(real):
    """A gain s multiplies every child's force, so mean and SD: the standardised GRF residual
    of a solution under grf_scale is ((1 + s)·sim − mean)/SD* (SD* with its floor), i.e.
    (1 + s) times the residual against the corrected mean on the uncorrected SD — checked
    by hand on a made-up solution, for the located gap and for the NLP's Fit term."""
    from gaitlib.gap import locate
    from gaitlib.gap import solve as gsolve

    s = 0.12
    g = real.gait
    tau = np.arange(locate.N_GRID) / locate.N_GRID
    t_data = np.asarray(g.time, float) / float(g.cycle_time)
    sim = pd.DataFrame({c: 0.9 * np.interp(tau, t_data, g.mean[c].to_numpy(float)) + 5.0
                        for c in gait_ocp.GRF_CHANNELS}, index=pd.Index(tau, name="tau"))
    loc = locate.locate(sim, real, thetas={"grf_scale": {"s": s}})
    for c in gait_ocp.GRF_CHANNELS:
        m = np.interp(tau, t_data, g.mean[c].to_numpy(float))
        sd = np.interp(tau, t_data, g.sd[c].to_numpy(float))
        sde = np.maximum(sd, locate.SD_FLOOR * np.sqrt(np.mean(sd**2)))
        want = float(np.sum((((1 + s) * sim[c].to_numpy() - m) / sde) ** 2))
        got = float(loc.channels.set_index("name").loc[c, "rss"])
        assert got == pytest.approx(want, rel=1e-9), c
    # the NLP's Fit: the effect rescales the reference and the SD column alike
    e = effects_mod.EFFECTS["grf_scale"]
    names = [f"ref_{c}" for c in gait_ocp.GRF_CHANNELS] + [f"sd_{c}" for c in gait_ocp.GRF_CHANNELS]
    d = ocp.Named(ca.DM(np.arange(1.0, len(names) + 1.0)), names, "data")
    over = e.reference(d, {"s": s}, None, None)
    for c in gait_ocp.GRF_CHANNELS:
        assert float(over[f"ref_{c}"]) == pytest.approx(float(d[f"ref_{c}"]) / (1 + s))
        assert float(over[f"sd_{c}"]) == pytest.approx(float(d[f"sd_{c}"]) / (1 + s))
    assert gsolve.fit_problem  # the Fit term reads both through the effect's data view (gap/solve.py)


def test_an_effect_version_keys_only_its_solves():
    """grf_scale's version enters the cache key of solves with it switched on; a spec without
    a versioned effect keeps the key it had (a one-element formulation tuple = the string)."""
    from gaitlib import cache

    assert effects_mod.EFFECTS["grf_scale"].version
    plain = gait_ocp.GaitSpec(**TINY)
    body = gait_ocp.GaitSpec(**TINY, effects=(("body_mass", None),))
    gain = gait_ocp.GaitSpec(**TINY, effects=(("grf_scale", None),))
    assert plain.effect_versions() == () and body.effect_versions() == ()
    assert gain.effect_versions() == (f"effect:grf_scale-{effects_mod.EFFECTS['grf_scale'].version}",)
    spec = {"kind": "gait", **plain.to_dict()}
    assert plain.key() == cache.key(spec, gait_ocp.FORMULATION, identified=plain.identified_sets())
    g = {"kind": "gait", **gain.to_dict()}
    assert gain.key() != cache.key(g, gait_ocp.FORMULATION, identified=gain.identified_sets())
