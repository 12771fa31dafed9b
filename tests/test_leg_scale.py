"""The leg-length probe: longer thighs and shanks (``GaitSpec.leg_scale``) — geometry,
inertias, the data's speed and the reference's slip, checked by hand calculations."""

from __future__ import annotations

import math
from types import SimpleNamespace
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from gaitlib import conventions as cv
from gaitlib import data as data_mod
from gaitlib import params
from gaitlib.model import P_BODY_NAMES, ChildModel
from gaitlib.problems import gait as gait_ocp
from gaitlib.studies import card
from gaitlib.studies import contact_id as ci
from gaitlib.studies import fidelity
from gaitlib.studies import gait as gait_study
from gaitlib.studies import msk

BH = cv.BODY_HEIGHT
IDX = {n: i for i, n in enumerate(P_BODY_NAMES)}


def test_leg_scale_lengthens_thigh_and_shank_only_with_their_com_and_inertia():
    s = 1.1
    m0, m1 = ChildModel(), ChildModel(leg_scale=s)
    # Table 4.1: thigh 0.245 BH, shank 0.246 BH; the feet and the HAT unchanged
    assert m1.lengths["thigh"] == pytest.approx(0.245 * BH * s, rel=1e-12)
    assert m1.lengths["shank"] == pytest.approx(0.246 * BH * s, rel=1e-12)
    for k in ("hat", "toe", "forefoot", "hindfoot"):
        assert m1.lengths[k] == m0.lengths[k]
    # the hip stands (thigh + shank) × (s − 1) higher; the standing leg length is cv.leg_length's
    assert m1.standing_leg_length - m0.standing_leg_length == pytest.approx(0.491 * BH * (s - 1), rel=1e-12)
    assert m1.standing_leg_length == pytest.approx(cv.leg_length(BH, s), rel=1e-9)
    p0, p1 = m0.default_p_body(), m1.default_p_body()
    # Table 4.1 thigh: mass 0.100 BM, ROG 0.323 SL, COM 0.433 SL, SL = 0.245 BH × s
    mass = 0.100 * cv.BODY_MASS
    assert p1[IDX["mass_thigh"]] == p0[IDX["mass_thigh"]] == pytest.approx(mass)
    assert p1[IDX["com_thigh"]] == pytest.approx(0.433 * 0.245 * BH * s, rel=1e-12)
    assert p1[IDX["moi_thigh"]] == pytest.approx(mass * (0.323 * 0.245 * BH * s) ** 2, rel=1e-12)
    changed = {P_BODY_NAMES[i] for i in np.flatnonzero(p0 != p1)}
    assert changed == {"com_thigh", "com_shank", "moi_thigh", "moi_shank"}
    # identified sets scale the same way (given for the thesis's legs)
    th = params.body_params("thesis", m1)
    assert th[IDX["com_shank"]] == pytest.approx(0.0916 * s) and th[IDX["moi_shank"]] == pytest.approx(0.0184 * s * s)
    with pytest.raises(ValueError, match="leg_scale"):
        ChildModel(leg_scale=0.1)


def test_the_data_speed_follows_the_longer_leg_and_the_stride_scales_with_it():
    s = 1.1
    g0, g1 = data_mod.load_gait_data("Free"), data_mod.load_gait_data("Free", leg_scale=s)
    L0, L1 = cv.leg_length(BH), cv.leg_length(BH, s)
    # v = v* sqrt(g L), T = 2 / (f* sqrt(g / L)): speed and cycle time × sqrt(L1/L0), stride × L1/L0
    r = math.sqrt(L1 / L0)
    assert g1.speed == pytest.approx(g0.speed * r, rel=1e-12)
    assert g1.cycle_time == pytest.approx(g0.cycle_time * r, rel=1e-12)
    assert g1.speed * g1.cycle_time == pytest.approx(g0.speed * g0.cycle_time * L1 / L0, rel=1e-12)
    # the angles are dimensionless: unchanged
    np.testing.assert_array_equal(g1.mean["knee_r"].to_numpy(), g0.mean["knee_r"].to_numpy())


def test_leg_scale_spec_keeps_old_keys_validates_and_builds_its_model():
    spec = gait_ocp.GaitSpec(model="MSK", cost="Eq5.33", n_intervals=2, degree=2)
    assert "leg_scale" not in spec.to_dict()
    ls = replace(spec, leg_scale=1.1)
    assert ls.key() != spec.key() and gait_ocp.GaitSpec.from_dict(ls.to_dict()) == ls
    assert gait_ocp.spec_model(ls).leg_scale == 1.1 and gait_ocp.spec_model(spec).leg_scale == 1.0
    assert gait_ocp.spec_gait_data(ls)[0].speed > gait_ocp.spec_gait_data(spec)[0].speed
    for bad in (0.5, 1.5, "1.1", True):
        with pytest.raises(ValueError, match="leg_scale"):
            replace(spec, leg_scale=bad)


def test_cot_breakdown_divides_by_the_stride_the_nlp_walks():
    """The COT by term (msk.cot_breakdown) reads Eq 5.57's distance as the NLP does: the spec's
    class data on the spec's legs (speed and cycle time × √(L1/L0), the stride × L1/L0)."""
    spec = gait_ocp.GaitSpec(model="NMSK", cost="DT", speed_class="Fast", track_class="Free")
    ls = replace(spec, leg_scale=1.1, body_params="ch4_legs", contact_params="ch4_legs")
    g0, g1 = data_mod.load_gait_data("Fast"), data_mod.load_gait_data("Fast", leg_scale=1.1)
    assert msk._stride(SimpleNamespace(spec=spec)) == pytest.approx(g0.speed * g0.cycle_time, rel=1e-12)
    assert msk._stride(SimpleNamespace(spec=ls)) == pytest.approx(g1.speed * g1.cycle_time, rel=1e-12)
    L0, L1 = cv.leg_length(BH), cv.leg_length(BH, 1.1)
    assert msk._stride(SimpleNamespace(spec=ls)) / msk._stride(SimpleNamespace(spec=spec)) == pytest.approx(L1 / L0)


def _uniform_walk(spec, n=21):
    """A fake solution of ``spec``: the pelvis moves one stride of the spec's own data per cycle
    at constant speed, pelvis_ty and tilt constant (what hat_reference_of reads)."""
    g = gait_ocp.spec_gait_data(spec)[0]
    tf, S = g.cycle_time, g.speed * g.cycle_time
    t = np.linspace(0.0, tf, n)
    X = pd.DataFrame({"pelvis_tx": S * t / tf, "qd_pelvis_tx": np.full(n, S / tf), "pelvis_ty": np.full(n, 0.7),
                      "qd_pelvis_ty": np.zeros(n), "pelvis_tilt": np.zeros(n), "qd_pelvis_tilt": np.zeros(n)}, index=t)
    return SimpleNamespace(spec=spec, stats={"tf_s": tf}, solution=SimpleNamespace(phase=lambda name: SimpleNamespace(states=X)))


def test_hat_reference_of_a_uniform_walk_is_flat_on_the_books_legs():
    spec = gait_ocp.GaitSpec(model="NMSK", cost="Eq5.55")
    dx = np.asarray(gait_ocp.hat_reference_of(_uniform_walk(spec))[1])
    assert np.abs(dx).max() < 1e-6


def test_hat_reference_of_a_uniform_walk_is_flat_on_longer_legs():
    spec = gait_ocp.GaitSpec(model="NMSK", cost="Eq5.55", leg_scale=1.1, body_params="ch4_legs",
                             contact_params="ch4_legs")
    dx = np.asarray(gait_ocp.hat_reference_of(_uniform_walk(spec))[1])
    assert np.abs(dx).max() < 1e-6


def test_spec_mass_is_the_mass_matrix_translational_entry():
    """spec_mass against the mass matrix's pelvis_tx diagonal (a translation moves every
    segment: Σ m), at a bent pose, for the thesis's body and the longer legs' identified one."""
    q = np.linspace(-0.4, 0.5, len(cv.COORDS))
    i = cv.COORDS.index("pelvis_tx")
    for spec in (gait_ocp.GaitSpec(model="MSK", cost="Eq5.33"),
                 gait_ocp.GaitSpec(model="MSK", cost="Eq5.33", leg_scale=1.1, body_params="ch4_legs")):
        m = gait_ocp.spec_model(spec)
        M = np.asarray(m.mass_matrix(q, params.body_params(spec.body_params, m)))
        assert gait_ocp.spec_mass(spec) == pytest.approx(M[i, i], rel=1e-12)
        assert 25.0 < gait_ocp.spec_mass(spec) < 60.0  # a child of the data's size


def test_leg_scale_slip_at_one_is_the_reference_slip_and_the_hip_rises_with_the_legs():
    spec = gait_ocp.GaitSpec(model="MSK", cost="Eq5.33", contact_params="ch4", body_params="ch4")
    tab = gait_study.leg_scale_slip(spec, scales=(1.0, 1.1))
    r = gait_study.reference_slip(spec)
    assert tab.loc[1.0, "reference slip (m/s)"] == pytest.approx(r["slip"], rel=1e-12)
    assert tab.loc[1.0, "signed mean slip (m/s)"] == pytest.approx(r["mean_slip"], rel=1e-12)
    assert abs(r["mean_slip"]) <= r["slip"]
    # the reference's HAT stands higher by about the legs' extra length (same angles, same feet)
    y = {s: gait_ocp.reference(gait_ocp.spec_gait_data(replace(spec, leg_scale=s))[1], ChildModel(leg_scale=s),
                               gait_ocp.contact_params_of(spec)).q["pelvis_ty"].mean() for s in (1.0, 1.1)}
    extra = 0.1 * 0.491 * BH
    assert y[1.1] - y[1.0] == pytest.approx(extra, rel=0.1)
    assert tab.loc[1.1, "thigh + shank (m)"] == pytest.approx(0.491 * BH * 1.1, rel=1e-12)


def test_leg_scale_findings_interpolate_where_the_signed_slip_changes_sign_by_hand():
    t = pd.DataFrame({"leg scale": [1.0, 1.1, 1.2], "thigh + shank (m)": [0.72, 0.79, 0.87],
                      "reference slip (m/s)": [0.2, 0.1, np.nan], "anchored slip (m/s)": [0.18, 0.05, np.nan],
                      "signed mean slip (m/s)": [0.09, -0.03, np.nan],
                      "note": ["", "", "no reference: row 3: a load of 400.0 N needs more than 0.06 m"]}).set_index("leg scale")
    (s,) = ci.leg_scale_findings({"ours": t})
    # zero crossing: 1.0 + 0.1 × 0.09 / (0.09 + 0.03) = 1.075
    assert "≈ ×1.07" in s or "≈ ×1.08" in s
    assert "lowest in the scan 0.100 m/s at ×1.1" in s and "-50 %" in s
    assert "no reference at ×1.2" in s


def test_leg_row_findings_compare_the_reference_and_the_solution_slip_by_hand():
    cols = {"status": "Solve_Succeeded", "gates": "valid", "deepest sink (mm)": 30.0}
    t = pd.DataFrame([{"run": fidelity.CH5_BASE_ROW, fidelity.SLIP_COLUMN: 0.20, "worst angle RMSE (deg)": 4.5, **cols},
                      {"run": fidelity.LEG_ROW, fidelity.SLIP_COLUMN: 0.18, "worst angle RMSE (deg)": 4.0, **cols},
                      {"run": fidelity.INTEGRAL_DEFECTS, fidelity.SLIP_COLUMN: 0.17, "worst angle RMSE (deg)": 4.6, **cols}]
                     ).set_index("run")
    refs = {fidelity.CH5_BASE_ROW: {"slip": 0.2, "mean_slip": 0.1}, fidelity.LEG_ROW: {"slip": 0.1, "mean_slip": 0.0}}
    (s,) = fidelity.leg_row_findings(t, refs)
    # the reference −50 %, the solution −10 %; the same-NLP spread: slip 0.03 (the move 0.02
    # is within: not what makes it slide), angle 0.1 (the move 0.5 is beyond)
    assert "-50 %" in s and "-10 %" in s and "not what makes the solution slide" in s
    assert "moves it 0.03: within that" in s and "moves it 0.1: beyond that" in s
    t.loc[fidelity.LEG_ROW, fidelity.SLIP_COLUMN] = 0.15  # moves 0.05 > 0.03: 0.05 / 0.1 of the reference's
    (s,) = fidelity.leg_row_findings(t, refs)
    assert "moves 50% as far as its reference's" in s and "beyond that" in s
    t.loc[fidelity.LEG_ROW, "gates"] = "invalid: swing_load"
    assert "not compared" in fidelity.leg_row_findings(t, refs)[0]


def test_leg_floor_findings_name_the_joints_above_the_target_by_hand():
    t = pd.DataFrame({"leg scale": [1.0, fidelity.LEG_SCALE], "hip_r (deg)": [2.5, 2.2], "knee_r (deg)": [2.1, 1.6],
                      "worst (deg)": [2.5, 2.2]}).set_index("leg scale")
    (s,) = fidelity.leg_floor_findings(t, 1.8)
    assert "hip r 2.50 → 2.20, knee r 2.10 → 1.60°" in s
    assert "at the thesis's legs above the 1.8° target: hip r, knee r" in s and "above the 1.8° target: hip r." in s
    assert fidelity.leg_floor_findings(t.drop(index=1.0), 1.8) == []


def test_a_set_identified_on_longer_legs_is_read_for_its_legs_and_rescaled_for_others():
    s = params.load_identified("ch4_legs")
    assert s["leg_scale"] == pytest.approx(1.1) and params.load_identified("ch4_child")["leg_scale"] == 1.0
    m1, m0 = ChildModel(leg_scale=s["leg_scale"]), ChildModel()
    # on the legs it was identified on: as stored; on the thesis's legs: COM / 1.1, MOI / 1.21
    np.testing.assert_array_equal(params.body_params("ch4_legs", m1), s["p_body"])
    p0 = params.body_params("ch4_legs", m0)
    assert p0[IDX["com_thigh"]] == pytest.approx(s["p_body"][IDX["com_thigh"]] / 1.1, rel=1e-12)
    assert p0[IDX["moi_shank"]] == pytest.approx(s["p_body"][IDX["moi_shank"]] / 1.21, rel=1e-12)
    assert p0[IDX["mass_thigh"]] == s["p_body"][IDX["mass_thigh"]]
    np.testing.assert_array_equal(params.contact_params("ch4_legs"), s["p_contact"])
    spec = gait_ocp.GaitSpec(model="MSK", cost="Eq5.33", contact_params="ch4", body_params="ch4")
    assert spec.identified_sets() == ("ch4_child",)  # the keys of the stored "ch4" solutions
    legs = replace(spec, leg_scale=1.1, contact_params="ch4_legs", body_params="ch4_legs")
    assert legs.identified_sets() == ("ch4_legs",)
    with pytest.raises(ValueError, match="ch4_legs"):
        replace(spec, contact_params="ch4_legs")


def test_the_card_sentence_on_longer_legs_concludes_only_when_every_run_stands_and_improves(monkeypatch):
    cols = {"status": "Solve_Succeeded", "gates": "valid"}
    t = pd.DataFrame([{"run": fidelity.CH5_BASE_ROW, fidelity.SLIP_COLUMN: 0.2, "worst angle RMSE (deg)": 4.5, **cols},
                      {"run": fidelity.LEG_SET_ROW, fidelity.SLIP_COLUMN: 0.07, "worst angle RMSE (deg)": 2.0, **cols}]
                     ).set_index("run")
    monkeypatch.setattr(card, "_stored", lambda study: (t, {}))
    (s,) = card.legs_slip_lines()
    assert "MSK 0.200 → 0.070 m/s (worst angle 4.50 → 2.00°)" in s and "stop sliding" in s
    t.loc[fidelity.LEG_SET_ROW, fidelity.SLIP_COLUMN] = 0.15  # still sliding: no conclusion
    (s,) = card.legs_slip_lines()
    assert "stop sliding" not in s and s.endswith(".")


def test_legs_curve_sentences_read_their_tables():
    col = "slip, force-weighted (m/s)"
    cot_u = pd.DataFrame({"mark": ["", "", ""]}, index=["Slow", "Free", "Fast"])
    slip_u = pd.DataFrame({col: [0.5, 0.7, 1.2]}, index=cot_u.index)
    cot_l = pd.DataFrame({"mark": ["", "NOT CONVERGED: x", ""]}, index=cot_u.index)
    slip_l = pd.DataFrame({col: [0.3, 0.6, 0.05]}, index=cot_u.index)
    a, b = fidelity.legs_curve_findings(slip_u, cot_u, slip_l, cot_l)
    assert "2 of 3 runs are converged, valid gaits (Slow, Fast); left out (marked): Free (NOT CONVERGED: x)" in a
    assert "Slow 0.50 → 0.30 m/s, Fast 1.20 → 0.05 m/s" in b and "in 1 of 2" in b
    slip_l[col] = 0.05
    _, b = fidelity.legs_curve_findings(slip_u, cot_u, slip_l, cot_l)
    assert "below v_tr = 0.1 m/s in every one" in b


def test_card_clauses_on_the_stored_legs_curve():
    """The card's clauses on Ch 7's consistent curve on longer legs read the stored study."""
    g = card._legs_curve()
    assert g is not None, "the legs curve is in the store (solutions/)"
    s = card._legs_clause("cot")
    assert f"{len(g['ok'])} of {len(g['cot'])} runs converged and valid" in s
    for c in g["ok"]:
        assert f"{c} {g['cot'].loc[c, 'COT (J/kg/m)']:.2f}" in s
    assert ("not periodic" in s) == (abs(g["drift"]) > fidelity.HAT_DRIFT_TOL)  # the HAT reference's caveat
    for k in g["restarted"]:  # a marked point's restart standing in is named, with its start
        assert k in s and k.endswith("'s solution") and " from " in k
    assert fidelity.minimum_phrase(g["cot"], g["at"]) in s and card.CH7_LEGS_HEADING.split(" (")[0].lower().replace(" ", "-") in s
    assert f"closer in {g['closer']} of {g['n']} cells" in card._legs_clause("cells")
    # the Free run tracks its own data: its cells are not counted
    assert g["n"] == 3 * len([c for c in g["ok"] if c != "Free"])
