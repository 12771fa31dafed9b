"""The laboratory effects (joint-angle offsets, force-plate gain and AP bias): the reference
the NLP tracks equals the data as the gap reads them, both by hand; a manipulation of the
tidy CSV (degrees, N/kg, the data's signs) is undone exactly by its effect."""

from __future__ import annotations

import casadi as ca
import numpy as np
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
    # untouched columns stay as they were; the SDs are never changed
    for col in real.gait.mean.columns:
        if f"ref_{col}" not in over:
            assert np.array_equal(adj.mean[col].to_numpy(), real.gait.mean[col].to_numpy()), col
    assert adj.sd.equals(real.gait.sd)
    # the null value is the data as they are
    assert effects_mod.adjust_data(real.gait, {name: {e.magnitude.name: 0.0}}).mean.equals(real.gait.mean)


def test_sign_convention_of_offsets():
    """The offset is in the model's convention: knee flexion in the data is −knee in the
    model (conventions.DATA_SIGN), hip and ankle keep their sign."""
    assert cv.DATA_SIGN["knee"] == -1.0 and cv.DATA_SIGN["hip"] == 1.0 and cv.DATA_SIGN["ankle"] == 1.0
    for j in ("hip", "knee", "ankle"):
        assert f"{cv.DATA_SIGN[j]:+g}" in effects_mod.EFFECTS[f"{j}_offset"].doc
