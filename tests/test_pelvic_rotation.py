"""The pelvic-rotation probe (Ch 4): the data's transverse pelvic rotation (a context curve no
solve reads) moved onto the reference's hips — the curve's round trip, the hips' velocity by
an independent finite difference, and the slip's linearity in the hip width."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from gaitlib import data as data_mod
from gaitlib.studies import contact_id as ci
from gaitlib.studies import gait as gait_study


def test_context_curve_is_the_workbook_row_and_names_what_is_missing():
    c = data_mod.context_curve("pelvis_rotation", "Free")
    assert len(c) == 51 and c["percent_cycle"].iloc[0] == 0 and c["percent_cycle"].iloc[-1] == 100
    # the ipsilateral side is forward at its own foot's contact (0 %) and back half a cycle later
    assert c["mean"].iloc[0] == pytest.approx(c["mean"].max(), abs=0.1)
    assert c["mean"].iloc[25] == pytest.approx(c["mean"].min(), abs=0.5)
    # the committed row of the workbook (Schwartz 2008, Free, 0 %): 4.3966°
    assert c["mean"].iloc[0] == pytest.approx(4.3966, abs=1e-4)
    with pytest.raises(data_mod.DataError, match="pelvis_obliquity.*context quantities.*pelvis_rotation"):
        data_mod.context_curve("pelvis_obliquity", "Free")


def test_hip_velocity_is_the_derivative_of_half_the_width_times_sin_theta():
    gd = data_mod.load_gait_data("Free")
    w = 0.2
    v = gait_study.pelvic_hip_velocity(gd, w)
    np.testing.assert_allclose(v["l"], -v["r"])
    # independent: a centred finite difference of (w/2) sin θ on the data's own 2 % grid
    c = data_mod.context_curve("pelvis_rotation", "Free")
    th = np.radians(c["mean"].to_numpy())
    t = c["percent_cycle"].to_numpy() / 100 * gd.cycle_time
    x = 0.5 * w * np.sin(th)
    fd = (x[2:] - x[:-2]) / (t[2:] - t[:-2])
    fit = np.interp(t[1:-1], np.asarray(gd.time), v["r"])
    # a centred difference on a 2 % grid against the periodic fit's derivative: within 3 mm/s
    # in RMS and 1 cm/s everywhere (largest at the cycle's end, where the data's 100 % is not
    # exactly their 0 % and the fit is periodic) — a wrong factor or sign would be ≥ 3 cm/s off
    assert np.sqrt(np.mean((fit - fd) ** 2)) < 0.003
    assert np.max(np.abs(fit - fd)) < 0.01
    # its scale: the hip moves w·sin(θmax − θmin)… over half a cycle, i.e. peak speeds of ~cm/s
    assert 0.01 < np.max(np.abs(v["r"])) < 0.2


def test_reference_slip_with_zero_width_is_the_two_d_reference_and_linear_in_the_width():
    spec = replace(ci.spec_c(), contact_params="ch4")
    r0 = gait_study.reference_slip(spec)
    assert gait_study.reference_slip(spec, hip_width=0.0) == r0
    tab, w0 = gait_study.pelvic_rotation_slip(spec, widths=(0.0, 0.1, 0.2))
    sm = tab["signed mean slip (m/s)"]
    assert sm[0.0] == pytest.approx(r0["mean_slip"])
    # the load is the 2-D reference's, the slip velocity linear in w: so is the signed mean
    assert sm[0.2] - sm[0.1] == pytest.approx(sm[0.1] - sm[0.0], rel=1e-9)
    assert gait_study.reference_slip(spec, hip_width=w0)["mean_slip"] == pytest.approx(0.0, abs=1e-9)
    # the rotation moves the stance hip back as the body moves on: it lowers a forward slip
    assert r0["mean_slip"] > 0 and sm[0.1] < sm[0.0]
    with pytest.raises(ValueError, match="hip_width"):
        gait_study.reference_slip(spec, hip_width=-0.1)


def test_pelvic_rotation_sentence_reads_its_table():
    tab = pd.DataFrame({"signed mean slip (m/s)": [0.1, 0.08], "reference slip (m/s)": [0.2, 0.19]},
                       index=pd.Index([0.0, 0.2], name="hip centres apart (m)"))
    rot = pd.DataFrame({"mean": [4.0, -4.0]})
    s = ci.pelvic_rotation_findings(tab, 1.0, rot, body_height=1.5)
    assert "+0.100 m/s (no rotation) to 0.20 m: +0.080 (-20 %), force-weighted 0.190" in s
    assert "1.00 m apart (0.67 × the body height)" in s and "is not what makes" in s
    s2 = ci.pelvic_rotation_findings(tab, 0.2, rot, body_height=1.5)
    assert "is not what makes" not in s2 and "0.20 m apart (0.13 × the body height)" in s2


def test_stride_sweep_is_exact_the_data_converted_with_its_length_stop_sliding(monkeypatch):
    """Converting the dimensionless speed and cadence with ``conversion_length`` instead of
    the hip-to-ground length (legs, angles and loads unchanged) gives a reference whose
    signed mean slip is zero — the relation mean slip = (stride − sweep)/T is exact."""
    from gaitlib import conventions as cv
    spec = replace(ci.spec_c(), contact_params="ch4")
    d = gait_study.stride_sweep(spec)
    # stride = v*/f*·L (Schwartz 2008 Free, data/schwartz2008_speed.csv): f* counts steps, two per cycle
    f_cycle = 0.5647953287 / 2
    assert d["stride"] == pytest.approx(0.4293883612 / f_cycle * d["leg_length"], rel=1e-9)
    assert d["sweep"] == pytest.approx(d["stride"] - d["mean_slip"] * d["cycle_time"], rel=1e-12)
    monkeypatch.setattr(cv, "leg_length", lambda body_height=cv.BODY_HEIGHT, leg_scale=1.0: d["conversion_length"])
    monkeypatch.setattr(data_mod, "_LOADED", {})
    r = gait_study.reference_slip(spec)
    assert abs(r["mean_slip"]) < 1e-9
    assert r["speed"] * data_mod.load_gait_data("Free").cycle_time == pytest.approx(d["sweep"], rel=1e-9)


def test_stride_sweep_sentence():
    d = {"stride": 1.2, "sweep": 1.08, "ratio": 0.9, "leg_length": 0.77, "conversion_length": 0.693, "hip_to_ankle": 0.7218}
    s = ci.stride_sweep_findings({"ours": d})
    assert "1.200 m (v*/f*·L with L = 0.770 m" in s and "ours contact set: 1.080 m (90 %)" in s
    assert "0.693 m" in s and "does not explain" in s
    s2 = ci.stride_sweep_findings({"ours": {**d, "conversion_length": 0.75}})
    assert "does not explain" not in s2


def test_card_stride_sentence_reads_the_two_measurements():
    from gaitlib.studies import card
    (s,) = card.stride_lines()
    spec = replace(ci.spec_c(), contact_params="ch4")
    d = gait_study.stride_sweep(spec)
    _, w0 = gait_study.pelvic_rotation_slip(spec, widths=(0.0,))
    assert f"{100 * d['ratio']:.0f} % of the stride" in s and f"{w0:.2f} m apart" in s
    assert f"{d['conversion_length']:.3f} m" in s
    # the verdict only when both are out of reach (half the body height apart; shorter than hip to ankle)
    assert ("neither explains it" in s) == (w0 > 0.5 * 1.47 and d["conversion_length"] < 0.491 * 1.47)
