"""The swing-load ablation (gaitlib.studies.fidelity): the data's swing windows by hand, the
key stability of the new spec option, the constraint's rows against the node's own forces,
and the clearance probe's invariants."""

from __future__ import annotations

from dataclasses import replace

import casadi as ca
import numpy as np
import pandas as pd
import pytest

from gaitlib import data as data_mod
from gaitlib.ocp import Named
from gaitlib.problems import gait as gait_ocp
from gaitlib.studies import fidelity


def test_swing_windows_by_hand():
    # Schwartz 2008 Free: foot off 59 %, left leg shifted by half a cycle, 2 % margin
    w = data_mod.swing_windows({"foot_off": 0.59, "opposite_foot_contact": 0.5}, 0.5, 0.02)
    assert w["r"] == pytest.approx((0.61, 0.98))
    assert w["l"] == pytest.approx((0.11, 0.48))
    tau = np.array([0.05, 0.2, 0.6, 0.7, 0.97, 0.99])
    assert data_mod.in_window(tau, w["r"]).tolist() == [False, False, False, True, True, False]
    assert data_mod.in_window(tau, w["l"]).tolist() == [False, True, False, False, False, False]
    # a window that wraps past the cycle's end (left shift 0.6: 1.21 … 1.58 → 0.21 … 0.58)
    w = data_mod.swing_windows({"foot_off": 0.59}, 0.6, 0.02)
    assert w["l"] == pytest.approx((0.21, 0.58))
    w = data_mod.swing_windows({"foot_off": 0.70}, 0.5, 0.02)  # right: 0.72 … 0.98; left 0.22 … 0.48
    assert data_mod.in_window([0.1, 0.3], w["l"]).tolist() == [False, True]


def test_the_new_option_keeps_every_existing_key():
    spec = gait_ocp.GaitSpec(model="MSK", cost="Eq5.33")
    assert "swing_load_max" not in spec.to_dict()
    bounded = replace(spec, swing_load_max=4.06)
    assert bounded.to_dict()["swing_load_max"] == 4.06
    assert bounded.key() != spec.key()
    assert gait_ocp.GaitSpec.from_dict(bounded.to_dict()) == bounded
    assert gait_ocp.GaitSpec.from_dict(spec.to_dict()) == spec
    with pytest.raises(ValueError, match="swing_load_max"):
        gait_ocp.GaitSpec(model="MSK", cost="Eq5.33", swing_load_max=-1.0)
    with pytest.raises(ValueError, match="fixed final time"):
        gait_ocp.GaitSpec(model="MSK", cost="Eq5.33", swing_load_max=4.0, tf_bounds=(0.8, 1.2))


def test_the_constraint_is_each_swinging_foots_vertical_force_and_nothing_else():
    """The 'swing_load' path constraint equals the node's right (left) vertical GRF where
    the data say the right (left) foot swings, and 0 elsewhere."""
    spec = gait_ocp.GaitSpec(model="MSK", cost="Eq5.33", n_intervals=3, degree=2, swing_load_max=4.0)
    gp = gait_ocp.build(spec)
    ph = gp.problem.phases[0]
    pc = {c.name: c for c in ph.path_constraints}["swing_load"]
    assert pc.upper == 4.0 and pc.lower == -np.inf
    x = ca.SX.sym("x", len(ph.states))
    u = ca.SX.sym("u", len(ph.controls))
    p = ca.SX.sym("p", len(gp.problem.parameter_names))
    t = ca.SX.sym("t")
    xn, un, pn = Named(x, ph.states), Named(u, ph.controls), Named(p, gp.problem.parameter_names)
    f = ca.Function("f", [x, u, p, t], [pc.fun(xn, un, pn, t), gp.node(xn, un, pn)["grf"]])
    gd = data_mod.load_gait_data("Free")
    T = gd.cycle_time
    pose = gp.ref.q  # the reference pose: both feet near the ground at times
    for tau, right, left in ((0.05, False, False), (0.3, False, True), (0.55, False, False), (0.8, True, False)):
        q = pose.iloc[int(np.argmin(np.abs(pose.index.to_numpy() / T - tau)))]
        xv = np.zeros(len(ph.states))
        for i, name in enumerate(ph.states):
            if name in q.index:
                xv[i] = q[name]
        xv[ph.states.index("pelvis_ty")] -= 0.01  # press both feet a little into the ground
        c, grf = (np.asarray(v).ravel() for v in f(xv, np.zeros(len(ph.controls)), np.zeros(p.numel()), tau * T))
        assert grf[1] > 1.0 or grf[3] > 1.0
        assert c[0] == pytest.approx(grf[1] if right else 0.0)
        assert c[1] == pytest.approx(grf[3] if left else 0.0)


def test_clearance_is_relative_to_the_lower_foot():
    c = fidelity.data_clearance(n=40)
    assert np.allclose(np.minimum(c["clear_r"], c["clear_l"]), 0.0)
    assert (c[["clear_r", "clear_l"]] >= 0).all().all()
    # the data's windows: right swings 61–98 %, left 11–48 % (Free)
    assert c["swing_r"].mean() == pytest.approx(0.375, abs=0.03)
    s = fidelity.clearance_summary(c)
    assert set(s.index) == {"r", "l"}


def test_each_ablation_change_is_one_change_on_the_swing_unloaded_spec():
    base, bounded = fidelity.ablation_specs("MSK").values()
    assert base.swing_load_max is None
    # half the gate's limit: 1 % of 41.4 kg × 9.81 m/s²
    assert bounded.swing_load_max == pytest.approx(0.01 * 41.4 * 9.81, abs=1e-3)
    assert replace(bounded, swing_load_max=None) == base
    for name, change in fidelity.tracking_changes("MSK").items():
        spec = replace(bounded, **change)  # a valid spec (GaitSpec checks its fields)
        differs = {k for k, v in spec.to_dict().items() if bounded.to_dict().get(k) != v}
        assert differs == set(change), name
    # Table 5.3's tracking weights are 1/4: "×4" restores 1
    assert "GRF weight ×4" in fidelity.tracking_changes("MSK")


def test_each_ch5_ablation_change_is_one_change_on_the_book_reading_spec():
    from gaitlib.studies import msk
    base = msk.ch5_spec("MSK", reading="book")
    assert base.jerk_ranges == "data" and base.swing_load_max == pytest.approx(0.01 * 41.4 * 9.81, abs=1e-3)
    for name, change in fidelity.ch5_changes("MSK").items():
        spec = replace(base, **change)
        differs = {k for k, v in spec.to_dict().items() if base.to_dict().get(k) != v}
        assert differs <= set(change) and differs, name
    assert {"coordinate weight ×4", "torque weight ×4", "GRF weight ×4"} <= set(fidelity.ch5_changes("MSK"))
    for model in ("MSK", "NMSK"):  # the same NLP, its defects in integral form: the one field
        assert fidelity.ch5_changes(model)[fidelity.INTEGRAL_DEFECTS] == {"defects": "integral"}


def test_nmsk_ch5_ablation_starts_each_change_from_the_msk_run_of_that_change(monkeypatch):
    """As the book's NMSK solve starts from the book's MSK solution, each NMSK change starts
    from the MSK ablation's solution with the same change."""
    from gaitlib.problems import gait as gait_ocp
    from gaitlib.studies import msk

    seen = {}

    def fake_solve_specs(specs, guesses=None, **kw):
        model = next(iter(specs.values())).model
        seen.setdefault(model, []).append((dict(specs), guesses))
        return {k: type("R", (), {"value": f"{model}:{k}"})() for k in specs}

    monkeypatch.setattr(gait_ocp, "solve_specs", fake_solve_specs)
    monkeypatch.setattr(msk, "solve", lambda model, **kw: f"{model}:base")
    monkeypatch.setattr(fidelity, "ablation_row", lambda k, v: {"run": k, "solution": v})
    table, sols = fidelity.ch5_ablation("NMSK")
    assert seen["MSK"][0][1] is None  # MSK from the data
    (specs, guesses), (specs2, guesses2), *trade = seen["NMSK"]
    # the second start: the ×32 problem again, from the NMSK ×16 run
    two = fidelity.second_start("metatarsal untracked + coordinate weight ×32")
    assert two == "metatarsal untracked + coordinate weight ×32, from the NMSK ×16 run"
    assert specs2 == {two: specs["metatarsal untracked + coordinate weight ×32"]}
    assert guesses2 == {two: "NMSK:metatarsal untracked + coordinate weight ×16"} and sols[two] == f"NMSK:{two}"
    assert set(guesses) == set(specs) == set(fidelity.ch5_changes("NMSK"))
    assert all(g == f"MSK:{k}" for k, g in guesses.items() if not k.endswith(", no Mtb term"))
    nomtb = [k for k in specs if k.endswith(", no Mtb term")]
    assert nomtb == ["metatarsal untracked + coordinate weight ×32, no Mtb term"]
    assert guesses[nomtb[0]] == "MSK:metatarsal untracked + coordinate weight ×32"
    assert dict(specs[nomtb[0]].weights) == {"Q": 8.0, "Mtb": 0.0} and "Mtb" not in dict(fidelity.ch5_changes("MSK")
                                                                                         ).get(nomtb[0], {})
    assert sols[fidelity.CH5_BASE_ROW] == "NMSK:base"
    # the trade-off rows, one solve each, in order, each from the NMSK row it names
    assert [next(iter(sp)) for sp, _ in trade] == list(fidelity.TRADE_OFF)
    first = "metatarsal untracked + coordinate weight ×32 + GRF weight ×2"
    assert fidelity.TRADE_OFF[first][1] == two
    for (sp, g), (k, (weights, src)) in zip(trade, fidelity.TRADE_OFF.items()):
        assert g == {k: f"NMSK:{src}"} and dict(sp[k].weights) == dict(weights) and sp[k].track_mtp is False
    # Table 5.9's weights are 1/4: ×32 on Q is 8, ×2 on GRF is 1/2
    assert dict(fidelity.TRADE_OFF[first][0]) == {"Q": 8.0, "GRF": 0.5}


def _row(status="Solve_Succeeded", obj=0.3, gates="valid", angle=10.0, torque=12.0, grf=60.0, swing=4.0, ds=27.0):
    return {"status": status, "iterations": 300, "objective": obj, "swing load (N)": swing,
            "double support (%)": ds, "worst angle RMSE (deg)": angle, "worst torque RMSE (N·m)": torque,
            "worst GRF RMSE (N)": grf, "gates": gates}


def _summary(clear_mm=0.0):
    import pandas as pd
    return pd.DataFrame({"min mid-swing clearance (mm)": [clear_mm, clear_mm], "at (% cycle)": [78.0, 28.0],
                         "mean clearance in swing (mm)": [9.0, 9.0],
                         "swing within 2 mm of the ground (%)": [35.0, 29.0]}, index=pd.Index(["r", "l"], name="foot"))


def test_swing_findings_read_the_better_converged_start_and_the_spread():
    import pandas as pd
    tab = pd.DataFrame({"MSK Eq5.33": _row(obj=0.227, gates="invalid: swing load 180 N", swing=180.0, ds=52.9),
                        "MSK Eq5.33, swing load ≤ 4.06 N": _row(obj=0.332, angle=11.1),
                        "MSK Eq5.33, swing load ≤ 4.06 N, from the baseline": _row(obj=0.270, angle=10.3)}).T
    text = " ".join(fidelity.swing_findings(_summary(), tab))
    assert "no clearance" in text
    assert "objective 0.227 → 0.270" in text  # the better (lower-objective) start is the one read
    assert "23 % apart" in text  # (0.332 − 0.270) / 0.270
    assert "2 of 2 starts" in text
    # a start that did not converge is never read
    tab.iloc[2, tab.columns.get_loc("status")] = "Maximum_Iterations_Exceeded"
    text = " ".join(fidelity.swing_findings(_summary(5.0), tab))
    assert "objective 0.227 → 0.332" in text and "did not converge" in text
    assert "no clearance" not in text  # 5 mm > the 2 mm touch threshold


def test_tracking_findings_count_channels_against_the_target():
    import pandas as pd
    tab = pd.DataFrame({"swing unloaded only": dict(_row(), **{"starts converged": "2/2"}),
                        "coordinate weight ×4": dict(_row(angle=11.9), **{"starts converged": "2/2"}),
                        "mesh 40 × 5": dict(_row(status="Maximum_Iterations_Exceeded"), **{"starts converged": "0/2"}),
                        "Jrk ranges from the data": dict(_row(angle=6.0), **{"starts converged": "2/2"})}).T
    idx = pd.MultiIndex.from_tuples([("angle", "hip", "r", "deg"), ("grf", "y", "l", "N")],
                                    names=["kind", "channel", "side", "unit"])
    pc = pd.DataFrame({"swing unloaded only": [5.9, 47.0], "coordinate weight ×4": [4.5, 30.0],
                       "target": [1.8, 36.3]}, index=idx)
    text = " ".join(fidelity.tracking_findings(tab, pc))
    assert "1 of 2 channels" in text and "grf y l" in text
    assert "mesh 40 × 5:** neither start converged" in text
    assert "does not lower the angle error" in text and "hypothesis" not in text
    assert "One such thing, measured: the Jrk term's denominators of the HAT (Jrk ranges from the data: worst 6.0°" in text


def test_cot_curve_findings_locate_the_minimum_and_the_term_that_moves_it():
    import pandas as pd
    cot = pd.DataFrame({"mark": ["", "", "", "NOT CONVERGED: Maximum_Iterations_Exceeded"],
                        "speed (m/s)": [0.9, 1.2, 1.5, 1.7]}, index=["Slow", "Free", "Fast", "VeryFast"])
    # total = the sum; without 'work' the lowest would be Free (3.0 - 0.5), with it Slow
    terms = pd.DataFrame({"speed (m/s)": [0.9, 1.2, 1.5], "activation": [0.1, 0.1, 0.1],
                          "maintenance": [0.5, 0.5, 0.5], "shortening": [2.0, 1.4, 1.6], "basal": [0.0, 0.0, 0.0],
                          "work": [0.3, 1.0, 1.2]}, index=["Slow", "Free", "Fast"])
    terms["total"] = terms[["activation", "maintenance", "shortening", "basal", "work"]].sum(axis=1)
    text = " ".join(fidelity.cot_curve_findings(cot, terms))
    assert "minimum at **Slow**" in text and "not at the natural speed" in text
    assert "Without the work term the minimum would be at Free" in text
    assert "VeryFast: NOT CONVERGED" in text
    assert "too few" in " ".join(fidelity.cot_curve_findings(cot, terms.iloc[:2]))
    terms.loc["Free", "shortening"] = 0.5  # now Free is lowest
    terms["total"] = terms[["activation", "maintenance", "shortening", "basal", "work"]].sum(axis=1)
    text = " ".join(fidelity.cot_curve_findings(cot, terms))  # Slow 2.9, Free 2.1, Fast 3.4; VeryFast marked
    assert "as the thesis and walking physiology say; whether it is a U is not tested (marked speeds left out)." in text
    text = " ".join(fidelity.cot_curve_findings(cot.iloc[:3], terms))  # the three speeds measured, all valid
    assert "the natural speed, as the thesis and walking physiology say, a U-curve as the thesis reports." in text
    assert fidelity.minimum_phrase(cot, "Free") == "minimum at Free"
    # a fourth valid point below its slower neighbour: the minimum at Free, but not a U
    cot4 = cot.assign(mark="")
    terms4 = pd.concat([terms, pd.DataFrame({"speed (m/s)": [1.7], "total": [3.0]}, index=["VeryFast"])])
    text = " ".join(fidelity.cot_curve_findings(cot4, terms4))
    assert "minimum at **Free**" in text and "not a U, though: the COT moves the wrong way between Fast 3.40 → VeryFast 3.00." in text


def test_a_lowest_point_at_the_end_of_the_valid_speeds_is_not_a_located_minimum():
    """Valid VerySlow, Slow, Free falling to Free, Fast and VeryFast marked: Free is only the
    lowest valid point — the curve is still falling where it stops, so no minimum is claimed
    (nor "the natural speed"); a lowest VeryFast ends the classes measured: a minimum there."""
    import pandas as pd
    bad = "NOT CONVERGED: Maximum_Iterations_Exceeded"
    cot = pd.DataFrame({"mark": ["", "", "", bad, bad], "speed (m/s)": [0.5, 0.9, 1.2, 1.5, 1.8]},
                       index=["VerySlow", "Slow", "Free", "Fast", "VeryFast"])
    terms = pd.DataFrame({"speed (m/s)": [0.5, 0.9, 1.2], "total": [6.6, 6.7, 5.6]}, index=["VerySlow", "Slow", "Free"])
    assert fidelity.unlocated_beyond(cot, "Free") == ["Fast", "VeryFast"]
    text = " ".join(fidelity.cot_curve_findings(cot, terms))
    assert "is lowest at **Free**, its fastest valid speed: Fast, VeryFast are left out" in text
    assert "minimum at" not in text and "as the thesis" not in text
    assert fidelity.minimum_phrase(cot, "Free") == ("lowest at Free, its fastest valid speed (Fast, VeryFast marked: "
                                                    "the minimum not located)")
    rev = cot.assign(mark=["", bad, "", "", ""])  # Slow marked: VerySlow and Free bracket it, nothing beyond
    assert fidelity.unlocated_beyond(rev, "VeryFast") == [] and fidelity.unlocated_beyond(rev, "Free") == []
    low = cot.assign(mark=[bad, "", "", "", ""])  # the slowest valid point lowest, VerySlow marked
    assert fidelity.minimum_phrase(low, "Slow").startswith("lowest at Slow, its slowest valid speed (VerySlow marked")


def test_metatarsal_findings_read_the_knees_from_the_ablation_and_the_floor():
    """Hand-made channel table and floor: knees 4.0/4.4° in Ch 5, 2.6/2.4° with the coordinate
    weight, 2.3/2.5° with both changes, target 1.8°; free-metatarsal floor 0.9/1.0°. The
    largest drop from freeing the metatarsal is 2.6 − 2.3 = 0.3°, no knee meets the target,
    and both combined runs are 2.3 − 0.9 = 1.4° and 2.5 − 1.0 = 1.5° above the floor."""
    q = "coordinate weight ×4"
    combo = f"{fidelity.METATARSAL_FREE} + {q}"
    idx = pd.MultiIndex.from_tuples([("angle", "knee", "r", "deg"), ("angle", "knee", "l", "deg"),
                                     ("angle", "hip", "r", "deg")], names=["kind", "channel", "side", "unit"])
    ch = pd.DataFrame({fidelity.CH5_BASE_ROW: [4.0, 4.4, 1.0], q: [2.6, 2.4, 0.9], fidelity.METATARSAL_FREE: [3.9, 4.5, 1.0],
                       combo: [2.3, 2.5, 0.8], "thesis (Table 5.4)": [1.1, 1.2, 0.6], "target": [1.8, 1.8, 1.8],
                       "best change": [combo, q, combo], "met by": ["none", "none", "all"]}, index=idx)
    floor = pd.DataFrame({"swing clearance (mm)": [1e3 * fidelity.TOUCH] * 2, "metatarsal": ["tracked (planned)", "free"],
                          "knee_r (deg)": [2.2, 0.9], "knee_l (deg)": [2.0, 1.0]})
    (line,) = fidelity.metatarsal_findings(ch, floor)
    assert "R 4.0° → 3.9° untracked; 2.6° with the coordinate weight ×4 → 2.3° with both" in line
    assert "lowers the knees by at most 0.3°" in line and "met by neither knee" in line
    assert "stay 1.4–1.5° above the free-metatarsal geometric floor" in line
    assert fidelity.metatarsal_findings(ch.drop(columns=[combo]), floor) == []


def test_q_scan_findings_read_the_worst_channel_of_each_kind_and_every_target_at_once():
    """A hand-made channel table: the untracked-metatarsal run and the scan at ×4 and ×16
    (Table 5.3's Q weight ¼ → 1 and 4). Worst angle/torque/GRF by hand: ×1 4.5/3.0/20,
    ×4 2.0/3.5/25, ×16 1.6/4.0/34; targets 1.8, 5.85, 36 → only ×16 meets all three."""
    idx = pd.MultiIndex.from_tuples([("angle", "knee", "r", "deg"), ("angle", "hip", "r", "deg"),
                                     ("torque", "knee", "r", "N*m"), ("grf", "y", "r", "N")],
                                    names=["kind", "channel", "side", "unit"])
    m = fidelity.METATARSAL_FREE
    pc = pd.DataFrame({"Ch 5, book's reading": [4.4, 1.7, 1.6, 23.0], m: [4.5, 1.4, 3.0, 20.0],
                       f"{m} + coordinate weight ×4": [2.0, 1.0, 3.5, 25.0],
                       f"{m} + coordinate weight ×16": [1.6, 0.8, 4.0, 34.0],
                       "thesis, Table 5.4": [1.1, 0.6, 1.8, 24.0], "target": [1.8, 1.8, 5.85, 36.0]}, index=idx)
    assert fidelity.all_targets(pc) == [f"{m} + coordinate weight ×16"]
    text = " ".join(fidelity.q_scan_findings(pc, "MSK"))
    assert "×1: 4.50°, 3.0 N·m, 20.0 N; ×4: 2.00°, 3.5 N·m, 25.0 N; ×16: 1.60°, 4.0 N·m, 34.0 N." in text
    assert "targets 1.8°, 5.85 N·m, 36 N" in text
    assert f"met by: {m} + coordinate weight ×16 —" in text
    assert fidelity.q_scan_findings(pc.drop(columns=[f"{m} + coordinate weight ×4", f"{m} + coordinate weight ×16"])) == []
    # NMSK: without the ×16 run and with ×4's GRF at 40 N no run meets every target; the run
    # with the lowest worst angle (×4, 2.0°) names the kinds over target (angle, GRF), and the
    # MSK table's runs that meet every target are named
    nm = pc.drop(columns=[f"{m} + coordinate weight ×16"]).assign(**{f"{m} + coordinate weight ×4": [2.0, 1.0, 3.5, 40.0]})
    text = " ".join(fidelity.q_scan_findings(nm, "NMSK", msk_channels=pc))
    assert "from Table 5.9's 0.25" in text
    assert "No run meets every target at once; the lowest worst angle, at ×4, comes with angle 2.0°, GRF 40.0 N over target." in text
    assert text.endswith(f"meets every target at once in: {m} + coordinate weight ×16.")
    nm2 = nm.assign(**{f"{m} + coordinate weight ×4, no Mtb term": [2.2, 1.0, 3.0, 41.0]})
    text = " ".join(fidelity.q_scan_findings(nm2, "NMSK"))
    assert (f"Without the Mtb term ({m} + coordinate weight ×4, no Mtb term): 2.20°, 3.0 N·m, 41.0 N (with it: "
            "2.00°, 3.5 N·m, 40.0 N) — from the same start, the Mtb term is not what keeps") in text
    # the second start: the ×4 row again from another run; its objective beside the first start's
    two = fidelity.second_start("metatarsal untracked + coordinate weight ×32")
    nm3 = nm.rename(columns={f"{m} + coordinate weight ×4": f"{m} + coordinate weight ×32"}).assign(
        **{two: [1.7, 0.9, 3.9, 37.0]})
    text = " ".join(fidelity.q_scan_findings(nm3, "NMSK", objectives={two: 0.08, f"{m} + coordinate weight ×32": 0.11}))
    assert (f"The start matters: {two} (objective 0.0800 vs 0.1100 from the MSK run): 1.70°, 3.9 N·m, 37.0 N (from "
            "the MSK run of the same change: 2.00°, 3.5 N·m, 40.0 N); still over target: GRF 37.0 N.") in text
    text = " ".join(fidelity.q_scan_findings(nm2, "NMSK", objectives={f"{m} + coordinate weight ×4": 0.10,
                                                                      f"{m} + coordinate weight ×4, no Mtb term": 0.12}))
    assert "— its objective (0.1200) exceeds that of the run with the term (0.1000)" in text
    assert "not what keeps" not in text
    # objectives within 1 %: no claim that the start matters
    text = " ".join(fidelity.q_scan_findings(nm3, "NMSK", objectives={two: 0.1100, f"{m} + coordinate weight ×32": 0.1101}))
    assert f"From a second start: {two} (objective" in text and "The start matters" not in text


def test_path_findings_compare_the_integral_row_with_the_book_run():
    cols = ["status", "iterations", "objective", "worst angle RMSE (deg)", "worst torque RMSE (N·m)",
            "worst GRF RMSE (N)", "gates"]
    t = pd.DataFrame([["Solve_Succeeded", 435, 0.0446, 5.8, 2.93, 25.6, "valid"],
                      ["Solve_Succeeded", 574, 0.0391, 5.08, 3.24, 26.2, "valid"]], columns=cols,
                     index=[fidelity.CH5_BASE_ROW, fidelity.INTEGRAL_DEFECTS])
    (line,) = fidelity.path_findings(t)
    # 0.0391 / 0.0446 - 1 = -12.33 %
    assert "objective 0.0391 in 574 iterations vs the book's 0.0446 in 435 (-12.3 %)" in line
    assert "worst angle RMSE 5.08° vs 5.80°" in line and "worst GRF RMSE 26.20 N vs 25.60 N" in line
    t.loc[fidelity.INTEGRAL_DEFECTS, "status"] = "Maximum_Iterations_Exceeded"
    (line,) = fidelity.path_findings(t)
    assert line.startswith("- The same NLP with its defects in integral form: not compared") and "(-" not in line
    assert fidelity.path_findings(t.drop(index=fidelity.INTEGRAL_DEFECTS)) == []


def test_single_change_findings_by_hand():
    cols = ["status", "iterations", "objective", "worst angle RMSE (deg)", "worst torque RMSE (N·m)",
            "worst GRF RMSE (N)", "gates"]
    t = pd.DataFrame([["Solve_Succeeded", 1063, 0.0326, 4.5, 3.3, 23.9, "valid"],
                      ["Solve_Succeeded", 306, 0.0331, 3.6, 3.4, 24.1, "valid"]], columns=cols,
                     index=[fidelity.CH5_BASE_ROW, fidelity.SD_NORM])
    idx = pd.MultiIndex.from_tuples([("angle", "knee", "r", "deg"), ("angle", "ankle", "l", "deg"),
                                     ("grf", "y", "r", "N")], names=["kind", "channel", "side", "unit"])
    ch = pd.DataFrame({fidelity.CH5_BASE_ROW: [4.5, 1.7, 23.9], fidelity.SD_NORM: [3.6, 3.4, 24.1],
                       "target": [1.8, 1.8, 36.3]}, index=idx)
    (line,) = fidelity.single_change_findings(t, ch, rows=(fidelity.SD_NORM,), n_moves=2)
    # moves / target: knee 0.9/1.8 = 0.5, ankle 1.7/1.8 = 0.94, GRF 0.2/36.3: ankle first, then knee
    assert "the largest moves relative to their targets: angle ankle L 1.70 → 3.40°, angle knee R 4.50 → 3.60°;" in line
    assert "worst RMSE angle 4.50 → 3.60°; torque 3.30 → 3.40 N·m; GRF 23.90 → 24.10 N" in line
    # within target: the book's ankle (1.7 ≤ 1.8) and GRF; the change's GRF only
    assert "channels within target: 1 of 3 (the book's run: 2)" in line
    t.loc[fidelity.SD_NORM, "gates"] = "invalid: swing load"
    (line,) = fidelity.single_change_findings(t, ch, rows=(fidelity.SD_NORM,))
    assert line.startswith(f"- {fidelity.SD_NORM}: not compared") and "→" not in line


def test_skating_findings_by_hand():
    cls = ["Slow", "Free", "Fast"]
    cot = pd.DataFrame({"mark": ["", "", ""], "COT (J/kg/m)": [4.0, 5.0, 3.0]}, index=cls)
    slip = pd.DataFrame({"slip, force-weighted (m/s)": [0.5, 0.8, 1.2],
                         "load carried sliding > 0.1 m/s (%)": [70.0, 90.0, 95.0]}, index=cls)
    cot_f = pd.DataFrame({"mark": ["", "", "NOT CONVERGED: Maximum_Iterations_Exceeded"],
                          "COT (J/kg/m)": [6.0, 5.5, 5.0]}, index=cls)
    slip_f = pd.DataFrame({"slip, force-weighted (m/s)": [0.02, 0.15, 0.3],
                           "load carried sliding > 0.1 m/s (%)": [1.0, 20.0, 30.0]}, index=cls)
    a, b = fidelity.skating_findings(cot, slip, cot_f, slip_f, pd.DataFrame(), floor=0.3, reruns=("Slow",))
    assert "Slow 0.50 m/s (70 % of the load), Free 0.80 m/s (90 % of the load), Fast 1.20 m/s" in a
    assert "2 of 3 runs converge to valid gaits (Slow through its 3000-iteration rerun)" in b
    # the marked Fast run is left out of the minimum: Free 5.5 < Slow 6.0
    assert "minimum at **Free**, the natural speed." in b and "Left out (marked): Fast (NOT CONVERGED" in b
    assert "Still sliding faster than 0.1 m/s: Free — the minimum's own run" in b
    # with each run's reference slip: runs faster than their reference are named
    ref = {"Slow": {"slip": 0.3}, "Free": {"slip": 0.9}, "Fast": {"slip": 0.4}}
    a, r, b = fidelity.skating_findings(cot, slip, cot_f, slip_f, pd.DataFrame(), floor=0.3, reference=ref)
    assert "already slide: Slow 0.30 m/s, Free 0.90 m/s, Fast 0.40 m/s" in r
    assert "faster than their own reference at Slow, Fast." in r and "every speed" not in r
    _, r, _ = fidelity.skating_findings(cot, slip, cot_f, slip_f, pd.DataFrame(), floor=0.3,
                                        reference={k: {"slip": 0.1} for k in ref})
    assert "at Slow, Free, Fast — every speed: the extra slide is the prediction's, not the data's." in r
