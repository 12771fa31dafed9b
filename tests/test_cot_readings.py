"""The readings of the metabolic model behind :func:`gaitlib.studies.msk.cot_readings`: each
alternative changes exactly the term it names (hand-checked), and the table integrates and
divides as Eq 5.57 says. No solve: a hand-built state set and a stand-in solution."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import casadi as ca
import numpy as np
import pandas as pd
import pytest

from gaitlib import metabolics as met
from gaitlib import mtg
from gaitlib.studies import fidelity, msk

BM = 41.4  # kg, the child (thesis Sec 4.1)
EPS = 0.1  # W, the smooth max's width (metabolics module docstring)
TERMS = ("activation", "maintenance", "shortening", "basal", "work")

# five gait-like states of the six MTG joints (rad, rad/s; model convention)
Q = {"hip_r": [0.35, 0.1, -0.2, 0.0, 0.3], "knee_r": [-0.6, -0.1, -1.0, -0.3, -0.05],
     "ankle_r": [0.1, -0.2, 0.05, 0.2, -0.3], "hip_l": [-0.15, 0.2, 0.4, -0.3, 0.0],
     "knee_l": [-0.1, -0.9, -0.4, 0.0, -1.1], "ankle_l": [-0.2, 0.1, 0.0, -0.35, 0.15]}
QD = {"hip_r": [1.5, -0.5, 0.2, -2.0, 0.7], "knee_r": [3.0, -4.0, 1.0, 0.5, -1.5],
      "ankle_r": [-1.0, 2.0, -3.5, 0.3, 1.2], "hip_l": [-0.8, 1.1, -0.3, 2.2, -1.7],
      "knee_l": [-2.0, 3.5, 0.1, -1.0, 2.5], "ankle_l": [-4.0, 0.5, 1.5, -2.5, 0.0]}
E = [0.30, 0.05, 0.40, 0.35, 0.02, 0.20, 0.45, 0.15, 0.25, 0.6, 0.1, 0.3, 0.5, 0.05, 0.2, 0.4]


def _rate(**kw):
    q = {k: np.array(v) for k, v in Q.items()}
    qd = {k: np.array(v) for k, v in QD.items()}
    ex = [np.full(5, e) for e in E]
    return met.nmsk_metabolic_rate(q, qd, ex, params=mtg.THESIS_PARAMS, t_stim=0.3, **kw)


def _changed(a, b):
    return [k for k in ("total",) + TERMS if not np.allclose(a[k], b[k], rtol=1e-12, atol=1e-12)]


def test_sign_as_printed_flips_only_the_shortening_heat():
    d, p = _rate(), _rate(shortening_sign="printed")
    assert set(_changed(d, p)) <= {"shortening", "total"}
    np.testing.assert_allclose(p["shortening"], -d["shortening"], rtol=1e-12)
    # one generator by hand: concentric (ω_f = 2 rad/s, τ^M = 30, τ_max = 50):
    # printed −(0.16·50 + 0.18·30)·2 = −26.8 W; eccentric (ω_f = −2): −0.157·30·(−2) = +9.42 W
    assert met.shortening_heat_rate(30.0, 2.0, 50.0, 0.0, sign="printed") == pytest.approx(-26.8)
    assert met.shortening_heat_rate(30.0, -2.0, 50.0, 0.0, sign="printed") == pytest.approx(9.42)


def test_case_split_as_printed_differs_only_at_zero_torque():
    # τ^M = 0 lengthening: printed split → concentric 0.16·50·(−1.5) = −12 W; default 0.157·0 = 0
    assert met.shortening_heat_rate(0.0, -1.5, 50.0, split="printed") == pytest.approx(-12.0, rel=1e-12)
    assert met.shortening_heat_rate(0.0, -1.5, 50.0) == pytest.approx(0.0, abs=1e-15)
    # τ^M > 0: identical (numeric and CasADi)
    tau = np.array([0.5, 10.0, 30.0, 60.0])
    om = np.array([-2.0, -0.003, 0.004, 1.5])
    np.testing.assert_array_equal(met.shortening_heat_rate(tau, om, 50.0, split="printed"),
                                  met.shortening_heat_rate(tau, om, 50.0))
    t, w = ca.SX.sym("t"), ca.SX.sym("w")
    f = ca.Function("f", [t, w], [met.shortening_heat_rate(t, w, 50.0, split="printed")])
    assert float(f(0.0, -1.5)) == pytest.approx(-12.0, rel=1e-12)
    assert float(f(30.0, -2.0)) == pytest.approx(-0.157 * 30 * 2.0, rel=1e-9)
    # on the gait states every τ^M > 0, so nothing changes
    assert _changed(_rate(), _rate(shortening_split="printed")) == []


def test_bhargava_isometric_torque_changes_only_the_shortening_heat():
    d, b = _rate(), _rate(isometric_torque="bhargava")
    assert set(_changed(d, b)) == {"shortening", "total"}


def test_whole_body_basal_changes_only_the_basal_rate():
    d, w = _rate(), _rate(basal_whole_body=1.2)
    assert set(_changed(d, w)) == {"basal", "total"}
    assert w["basal"] == pytest.approx(1.2 * BM)  # 49.68 W
    np.testing.assert_allclose(w["total"] - d["total"], 1.2 * BM - d["basal"], rtol=1e-12)
    # Eq 5.48 for comparison: 0.0225 W/kg × 16 muscles' mass ≈ 0.06 W
    assert 0.03 < d["basal"] < 0.1


def test_plain_sum_against_the_smooth_clip():
    d, p = _rate(), _rate(forbid_negative=False)
    assert set(_changed(d, p)) <= {"total"}
    rest = p["total"] - p["basal"]
    np.testing.assert_allclose(p["total"], sum(p[k] for k in TERMS), rtol=1e-12)
    smax = 0.5 * (rest + np.sqrt(rest**2 + EPS**2)) - 0.5 * EPS
    np.testing.assert_allclose(d["total"], d["basal"] + smax, rtol=1e-12)
    # smax(x) ≥ x − ε/2 and smax(x) ≥ −ε/2: plain ≤ clipped + ε/2; strictly below when rest < 0
    assert np.all(p["total"] <= d["total"] + EPS / 2 + 1e-12)
    x = np.array([-30.0, -1.0, 0.0, 2.0, 300.0])
    r = met.metabolic_rate({}, {}, {}, {}, {"j": x}, {"j": np.ones(5)})
    r0 = met.metabolic_rate({}, {}, {}, {}, {"j": x}, {"j": np.ones(5)}, forbid_negative=False)
    np.testing.assert_array_equal(r0["total"], x)
    assert np.all(r["total"][:2] > x[:2]) and r["total"][2] == 0.0
    assert np.all(x[3:] - r["total"][3:] <= EPS / 2)


def test_readings_keyword_errors():
    with pytest.raises(ValueError):
        met.shortening_heat_rate(1.0, 1.0, 1.0, sign="literal")
    with pytest.raises(ValueError):
        met.shortening_heat_rate(1.0, 1.0, 1.0, split="tau")


# ---- the table: a stand-in solution (uniform grid, constant rates) -----------------------

T_F, STRIDE, TRAVEL = 1.0, 1.2, 1.25  # s, m, m


def _fake_sol():
    t = np.linspace(0.0, T_F, 11)[:-1]  # control nodes, t_f excluded
    states = pd.DataFrame({"pelvis_tx": [0.0, TRAVEL]}, index=[0.0, T_F])
    ph = SimpleNamespace(states=states)
    return SimpleNamespace(q=pd.DataFrame(index=pd.Index(t, name="time")), stats={"tf_s": T_F},
                           solution=SimpleNamespace(phase=lambda name: ph))


# constant rates, W, per reading (what the fake metabolic model returns)
BASE = {"activation": 5.0, "maintenance": 40.0, "shortening": 100.0, "basal": 0.06, "work": 60.0}


def _fake_edot(calls):
    def f(sol, **kw):
        calls.append(kw)
        r = dict(BASE)
        if kw.get("shortening_sign") == "printed":
            r["shortening"] = -r["shortening"]
        if kw.get("isometric_torque") == "bhargava":
            r["shortening"] = 35.0
        if kw.get("basal_whole_body"):
            r["basal"] = kw["basal_whole_body"] * BM
        r["total"] = sum(r.values())
        n = len(sol.q)
        return {k: np.full(n, v) for k, v in r.items()}

    return f


def test_cot_readings_table(monkeypatch):
    calls = []
    monkeypatch.setattr(msk, "_recompute_edot", _fake_edot(calls))
    monkeypatch.setattr(msk, "_stride", lambda sol: STRIDE)
    df = msk.cot_readings(_fake_sol())
    first = df.iloc[0]
    # Eq 5.57 by hand: constant Ė over t_f: COT = Ė t_f / (BM D)
    tot = sum(BASE.values())
    assert first["COT"] == pytest.approx(tot * T_F / (BM * STRIDE), rel=1e-12)
    for k in TERMS:
        assert first[k] == pytest.approx(BASE[k] * T_F / (BM * STRIDE), rel=1e-12)
    assert first["change vs NLP reading (%)"] == 0.0
    # each alternative: the options it passes, one at a time
    assert {tuple(sorted(c.items())) for c in calls} == {
        (), (("shortening_sign", "printed"),), (("shortening_split", "printed"),),
        (("isometric_torque", "bhargava"),), (("forbid_negative", False),), (("basal_whole_body", 1.2),)}
    sp = df.loc["Eq 5.47 sign as printed"]
    assert sp["shortening"] == pytest.approx(-first["shortening"])
    assert sp["COT"] == pytest.approx((tot - 200.0) * T_F / (BM * STRIDE))
    bb = df.loc["basal whole-body (OpenSim)"]
    assert bb["basal"] == pytest.approx(1.2 * T_F / STRIDE)  # 1.2 W/kg × BM × t_f / (BM D)
    # distance readings scale the whole row by D_stride / D_alt
    for lab, d in (("D = pelvis travel", TRAVEL), ("D = thesis 1.24 m", msk.THESIS_DISTANCE_M)):
        row = df.loc[lab]
        for k in ("COT",) + TERMS:
            assert row[k] == pytest.approx(first[k] * STRIDE / d, rel=1e-12)
        assert row["change vs NLP reading (%)"] == pytest.approx(100 * (STRIDE / d - 1), rel=1e-12)
    th = df.iloc[-1]
    assert "thesis" in df.index[-1] and th["COT"] == msk.THESIS_COT
    assert th[list(TERMS)].isna().all() and math.isnan(th["change vs NLP reading (%)"])


def test_cot_ranges_by_hand(monkeypatch):
    """msk.cot_ranges: the model's COT, the gross one (OpenSim's whole-body basal), per stride,
    against Waters et al.'s gross mean and Weyand et al.'s per-stride mean ± SD, by hand."""
    calls = []
    monkeypatch.setattr(msk, "_recompute_edot", _fake_edot(calls))
    monkeypatch.setattr(msk, "_stride", lambda sol: STRIDE)
    sol = _fake_sol()
    df = msk.cot_ranges({"nlp": sol, "bh": sol}, {"bh": {"isometric_torque": "bhargava"}})
    tot = sum(BASE.values())
    net = tot * T_F / (BM * STRIDE)
    gross = (tot - BASE["basal"] + 1.2 * BM) * T_F / (BM * STRIDE)
    r = df.loc["nlp"]
    assert r["D (m)"] == STRIDE
    assert r["COT"] == pytest.approx(net, rel=1e-12)
    assert r["COT gross"] == pytest.approx(gross, rel=1e-12)
    assert r["per stride"] == pytest.approx(tot * T_F / BM, rel=1e-12)  # J/kg per stride: Ė t_f / BM
    assert r["gross ÷ Waters"] == pytest.approx(gross / (0.22 * 20.1), rel=1e-12)
    assert r["z (net)"] == pytest.approx((tot * T_F / BM - 2.74) / 0.12, rel=1e-12)
    assert r["z (gross)"] == pytest.approx((gross * STRIDE - 2.74) / 0.12, rel=1e-12)
    b = df.loc["bh"]
    assert b["COT"] == pytest.approx((tot - 100.0 + 35.0) * T_F / (BM * STRIDE), rel=1e-12)
    assert {tuple(sorted(c.items())) for c in calls} == {
        (), (("basal_whole_body", 1.2),), (("isometric_torque", "bhargava"),),
        (("basal_whole_body", 1.2), ("isometric_torque", "bhargava"))}
    # the sentences: a marked run is never counted in range
    text = fidelity.cot_range_findings(df.assign(**{"z (net)": [0.5, 1.0]}), {"nlp": "", "bh": "INVALID: x"})
    assert text[-1] == "**In the measured range:** nlp."
    assert "INVALID: x" in text[2] and "no conclusion" in text[2]


def test_best_starts_and_restart_findings_by_hand():
    """fidelity.best_starts: within a class the lowest objective among converged, valid starts
    decides (a marked start's lower objective never counts); restart_findings names the local
    optima and reads the curve of the best starts."""
    own = fidelity.OWN_START
    rows = {("Slow", own): ["", 0.20, 4.0], ("Slow", "Free"): ["", 0.18, 3.0], ("Slow", "Fast"): ["INVALID: x", 0.10, 1.0],
            ("Free", own): ["", 0.30, 5.0], ("Free", "Slow"): ["", 0.33, 2.0]}
    t = pd.DataFrame.from_dict(rows, orient="index", columns=["mark", "objective", "COT (J/kg/m)"])
    t.index = pd.MultiIndex.from_tuples(t.index, names=["class", "start"])
    best = fidelity.best_starts(t)
    assert list(best.index) == ["Slow", "Free"]  # speed order
    assert best.loc["Slow", "best start"] == "Free" and best.loc["Slow", "valid starts"] == "2 of 3"
    assert best.loc["Slow", "objective change (%)"] == pytest.approx(-10.0)  # 0.18 / 0.20 − 1
    assert best.loc["Free", "best start"] == own and best.loc["Free", "objective change (%)"] == pytest.approx(0.0)
    assert best.loc["Slow", "COT over valid starts (J/kg/m)"] == "3.00–4.00"
    idx = ["Slow", "Free", "Fast"]
    terms = pd.DataFrame({"speed (m/s)": [0.8, 1.2, 1.5], "total": [4.0, 5.0, 4.5]}, index=idx)
    terms_b = pd.DataFrame({"speed (m/s)": [0.8, 1.2, 1.5], "total": [3.0, 5.0, 4.5], "work": [1.0, 2.5, 2.0]},
                           index=idx)
    cot_b = pd.DataFrame({"mark": ["", "", ""]}, index=idx)
    out = fidelity.restart_findings(best, terms, cot_b, terms_b, n_runs=3)
    assert out[0].startswith("**1 of 2 of the study's valid points are local optima**")
    assert "Slow from Free -10.0 %, COT 4.00 → 3.00" in out[0]
    # Free's valid starts: 5.0 (own) and 2.0; the best curve 3.0 … 5.0
    assert out[1] == ("Across a class's valid starts the COT spans up to 3.00 J kg⁻¹ m⁻¹ (Free: 2.00–5.00), against "
                      "2.00 between the highest and the lowest point of the best starts' curve: which optimum a run "
                      "ends in moves a point as much as the speed does.")
    out = out[:1] + out[2:]
    assert "minimum at **Slow**" in out[1] and "work +1.50" in out[2] and out[-1] == "(The study's own curve has its minimum at Slow.)"
    # the study's own run best everywhere → no local optimum named
    best2 = fidelity.best_starts(t.drop(index=("Slow", "Free")))
    assert fidelity.restart_findings(best2, terms, cot_b, terms_b, n_runs=2)[0].startswith("No restart (2 solved)")


def test_multistart_second_round_starts_from_the_first_rounds_best(monkeypatch):
    """fidelity.multistart: round 2 starts every class from the other classes' best valid
    solutions of round 1, skipping a class whose best is the study's own run (round 1's start)."""
    own = fidelity.OWN_START
    calls = []

    def fake_restarts(res, classes=None, *, starts=None, label="", **kw):
        calls.append((starts, label))
        srcs = ("Slow", "Free") if starts is None else tuple(starts)
        return {c: {own: f"{c}-own", **{s + label: f"{c}<-{s}{label}" for s in srcs if s != c}}
                for c in ("Slow", "Free")}

    best = pd.DataFrame({"best start": ["Free", own]}, index=pd.Index(["Slow", "Free"], name="class"))
    monkeypatch.setattr(fidelity, "curve_restarts", fake_restarts)
    monkeypatch.setattr(fidelity, "restart_table", lambda r: r)
    monkeypatch.setattr(fidelity, "best_starts", lambda t: best)
    out = fidelity.multistart(object())
    assert calls[0] == (None, "") and calls[1] == ({"Slow": "Slow<-Free"}, fidelity.ROUND_2)
    assert out["Free"] == {own: "Free-own", "Slow": "Free<-Slow", "Slow (round 2)": "Free<-Slow (round 2)"}
    assert out["Slow"] == {own: "Slow-own", "Free": "Slow<-Free"}  # no round-2 start but its own best
    with pytest.raises(ValueError, match="rounds"):
        fidelity.multistart(object(), rounds=3)


def test_round_findings_by_hand():
    """fidelity.round_findings: a round-2 start counts only where it lowers round 1's best valid
    objective of its class; none → the first round's best stand."""
    own, r2 = fidelity.OWN_START, fidelity.ROUND_2
    rows = {("Slow", own): ["", 0.20, 4.0], ("Slow", "Free"): ["", 0.18, 3.0], ("Slow", "Free" + r2): ["", 0.09, 2.5],
            ("Free", own): ["", 0.30, 5.0], ("Free", "Slow"): ["", 0.33, 2.0],
            ("Free", "Slow" + r2): ["INVALID: x", 0.01, 1.0]}
    t = pd.DataFrame.from_dict(rows, orient="index", columns=["mark", "objective", "COT (J/kg/m)"])
    t.index = pd.MultiIndex.from_tuples(t.index, names=["class", "start"])
    out = fidelity.round_findings(t)
    assert out[0].startswith("**Round 2 lowers the best objective again in 1 of 2 classes** (2 restarts, 1 converged")
    assert "Slow -50.0 % (COT 3.00 → 2.50)" in out[0]  # 0.09 / 0.18 − 1
    t2 = t.drop(index=("Slow", "Free" + r2))
    assert fidelity.round_findings(t2)[0].startswith("Round 2 (1 restarts, 0 converged and valid) lowers no class's")
    assert fidelity.round_findings(t2[~t2.index.get_level_values("start").str.endswith(r2)]) == []


def test_marked_restarts_stand_in_only_for_marked_points(monkeypatch):
    """fidelity.marked_restarts starts only the marked classes, and only from valid classes'
    solutions; with_restarts hands the lowest-objective converged, valid restart to
    with_reruns (a marked restart's lower objective never counts); stand_in_findings names it."""
    own = fidelity.OWN_START

    class Sol:
        def __init__(self, name, mark="", cot=4.0):
            self.name, self.mark, self.stats = name, mark, {"COT": cot}

    @dataclasses.dataclass
    class Study:
        solutions: dict
        rerun_used: tuple = ()
        restart_used: tuple = ()
        restart_from: dict = dataclasses.field(default_factory=dict)

        @property
        def records(self):
            return {k: None for k in self.solutions}

        def with_reruns(self, reruns):
            got.append(reruns)
            return Study({**self.solutions, **reruns}, self.rerun_used + tuple(reruns), self.restart_used)

    got, calls = [], []
    slow = Sol("slow", "NOT CONVERGED: Maximum_Iterations_Exceeded")
    res = Study({"NMSK Slow": slow, "NMSK Free": Sol("free"), "NMSK Fast": Sol("fast", "INVALID: x")})
    r_free, r_fast = Sol("slow<-free", cot=3.5), Sol("slow<-fast", "INVALID: y")
    fast = res.solutions["NMSK Fast"]
    restarts = {"Slow": {own: slow, "Free": r_free, "Fast": r_fast}, "Fast": {own: fast, "Free": Sol("fast<-free", "x")}}

    def fake_curve_restarts(r, classes=None, *, starts=None, **kw):
        calls.append((classes, starts))
        return restarts

    monkeypatch.setattr(fidelity.marks, "failure_label", lambda s: s.mark or None)
    monkeypatch.setattr(fidelity, "curve_restarts", fake_curve_restarts)
    monkeypatch.setattr(fidelity, "restart_table", lambda rs: pd.DataFrame(
        [["NOT CONVERGED: …", 0.5], ["", 0.3], ["INVALID: y", 0.1], ["INVALID: x", 0.2], ["x", 0.1]],
        columns=["mark", "objective"], index=pd.MultiIndex.from_tuples(
            [("Slow", own), ("Slow", "Free"), ("Slow", "Fast"), ("Fast", own), ("Fast", "Free")], names=["class", "start"])
    ).assign(**{"COT (J/kg/m)": [5.0, 3.5, 1.0, 2.0, 2.0]}))
    assert fidelity.marked_restarts(res) is restarts
    assert calls == [(["Slow", "Fast"], {"Free": res.solutions["NMSK Free"]})]  # marked classes; valid starts only
    assert fidelity.best_starts(fidelity.restart_table(restarts)).loc["Fast", "best start"] is None  # not NaN
    used = fidelity.with_restarts(res, restarts)
    assert got == [{"NMSK Slow": r_free}] and used.solutions["NMSK Slow"] is r_free
    assert used.restart_used == ("NMSK Slow",) and used.rerun_used == ()  # not a 3000-iteration rerun
    assert used.restart_from == {"NMSK Slow": "Free"} and fidelity.stand_in_labels(used) == ["Slow from Free's solution"]
    out = fidelity.stand_in_findings(res, used, restarts)
    assert out[0] == ("**Slow** (its own run NOT CONVERGED: Maximum_Iterations_Exceeded): 1 of 2 starts from the other "
                      "classes' solutions converge to a valid gait; the lowest objective, from Free's solution (COT "
                      "3.50 J kg⁻¹ m⁻¹), stands in for it — the same problem, another start (labelled).")
    assert out[1].startswith("**Fast** (its own run INVALID: x): none of its 1 starts")
    assert fidelity.with_restarts(res, {}) is res and fidelity.stand_in_findings(res, res, {}) == []
    assert fidelity.marked_restarts(Study({"NMSK Free": Sol("free")})) == {}


def test_restart_runs_never_start_a_run_from_itself_but_from_another_problems_same_class(monkeypatch):
    """fidelity.restart_runs: a class's run is never started from its own solution, but is from
    the same class's solution of another problem; marked_restarts(also=…) adds the other
    study's valid solutions as starts, named with its label, the problem solved still ``res``'s."""
    spec = SimpleNamespace(leg_scale=None, source="x")
    gd = SimpleNamespace(cycle_time=1.0, speed=1.2)
    monkeypatch.setattr(fidelity.data_mod, "load_gait_data", lambda c, src, **kw: gd)
    monkeypatch.setattr(fidelity.pr, "run_guess", lambda s, kind, **kw: ("guess", s, kw["stride"]))
    mine = {"NMSK Slow": "slow", "NMSK Free": "free"}
    res = SimpleNamespace(specs={k: spec for k in mine}, solutions=mine)
    specs, guesses = fidelity.restart_runs(res)
    assert sorted(specs) == ["NMSK Free from Slow", "NMSK Slow from Free"]
    assert guesses["NMSK Slow from Free"] == ("guess", "free", 1.2)
    other = {"Slow": "slow'", "Free": "free'"}
    assert list(fidelity.restart_runs(res, ["Slow"], starts=other)[0]) == ["NMSK Slow from Free"]  # other classes only
    specs, guesses = fidelity.restart_runs(res, ["Slow"], starts=other, same_class=True)
    assert sorted(specs) == ["NMSK Slow from Free", "NMSK Slow from Slow"] and specs["NMSK Slow from Slow"] is spec
    assert guesses["NMSK Slow from Slow"][1] == "slow'"
    assert list(fidelity.restart_runs(res, ["Slow"], starts={"Slow": "slow"}, same_class=True)[0]) == []  # its own

    calls = []

    def fake(r, classes=None, *, starts=None, label="", same_class=False, **kw):
        calls.append((r, classes, starts, label, same_class))
        return {c: {fidelity.OWN_START: "own", **{k + label: f"{c}<-{k}{label}" for k in starts}} for c in classes}

    monkeypatch.setattr(fidelity, "curve_restarts", fake)
    monkeypatch.setattr(fidelity, "_marked_classes", lambda r: ["Slow"] if r is res else [])
    other = SimpleNamespace(solutions={"NMSK Slow": "o-slow", "NMSK Fast": "o-fast"})
    out = fidelity.marked_restarts(res, also={"floor": other})
    assert [c[1:] for c in calls] == [(["Slow"], {"Free": "free"}, "", False),
                                      (["Slow"], {"Slow": "o-slow", "Fast": "o-fast"}, " (floor)", True)]
    assert all(c[0] is res for c in calls)  # the problem solved is res's
    assert out == {"Slow": {fidelity.OWN_START: "own", "Free": "Slow<-Free", "Slow (floor)": "Slow<-Slow (floor)",
                            "Fast (floor)": "Slow<-Fast (floor)"}}


def test_stop_table_and_findings_by_hand(monkeypatch):
    """fidelity.stop_table: the forward-speed change over the cycle and the cycle means of the
    fore-aft GRF and R_x (each node's share of the cycle, by hand) of the runs that did not
    converge only, and their sum over the body's mass; stop_findings reads the infeasible ones."""
    NS = SimpleNamespace
    monkeypatch.setattr(fidelity.gait_ocp, "spec_mass", lambda spec: 30.0)  # (−4 + 1) N / 30 kg = −0.1 m s⁻²
    t = pd.Index([0.0, 0.5, 1.0])

    def run(success, status, dv=-0.1, grf_l=(-1.0, -3.0, -1.0)):
        states = pd.DataFrame({"qd_pelvis_tx": [1.0, 1.0 + dv / 2, 1.0 + dv]}, index=t)
        grf = pd.DataFrame({"grf_x_r": [-2.0] * 3, "grf_x_l": list(grf_l), "grf_y_r": [200.0] * 3,
                            "grf_y_l": [200.0] * 3}, index=t)
        ell = pd.DataFrame({"fx_ball_r": grf["grf_x_r"], "fx_ball_l": grf["grf_x_l"]}, index=t)
        return NS(stats={"success": success, "status": status},
                  solution=NS(states=states, worst_constraint="cycle/periodic", max_violation=abs(dv)),
                  spec=NS(contact_params="default", friction_floor=None), grf=grf, ellipsoids=ell,
                  residuals=pd.DataFrame({"R_x": [1.0] * 3}, index=t))

    inf = "Infeasible_Problem_Detected"
    restarts = {"Free": {fidelity.OWN_START: run(True, "Solve_Succeeded"), "Slow": run(False, inf), "Fast": None},
                "Fast": {"Free": run(False, inf, dv=-0.1002), "Slow": run(False, "Maximum_Iterations_Exceeded")}}
    st = fidelity.stop_table(restarts)
    assert list(st.index) == [("Free", "Slow"), ("Fast", "Free"), ("Fast", "Slow")]  # converged and raised left out
    r = st.loc[("Free", "Slow")]
    assert r["forward speed change (m/s)"] == pytest.approx(-0.1)
    assert r["mean fore-aft acceleration (m/s²)"] == pytest.approx(-0.1)  # over a 1 s cycle
    # node shares of the cycle 0.5, 0.5, 0 (the last node at t_f): right −2; left −1·0.5 − 3·0.5 = −2 → −4 N; R_x 1 N
    assert r["mean fore-aft GRF (N)"] == pytest.approx(-4.0) and r["mean R_x (N)"] == pytest.approx(1.0)
    # all of it on the balls; Table 4.18's ball μ_d 0.01 × 400 N normal load = 4 N → −1
    assert r["ball's share of it"] == pytest.approx(1.0) and r["μ_d(ball)"] == pytest.approx(0.01)
    assert r["GRF / (μ_d(ball) × normal load)"] == pytest.approx(-1.0)
    assert r["(GRF + R_x) / mass (m/s²)"] == pytest.approx(-0.1)
    out = fidelity.stop_findings(st)
    assert out[0].startswith("**2 of the 3 restarts that did not converge stop as locally infeasible** (IPOPT's "
                             "restoration phase fails; 2 classes: Free, Fast), the largest violation at cycle/periodic in 2")
    assert "ends -0.100 m/s off" in out[0] and "-0.1002 … -0.1000 m s⁻²" in out[0]
    assert "the feet brake on average and the residual pushes forward at its bound" in out[0]
    assert "within 0.2 % of its mean" in out[0]
    # Newton: −0.1 m s⁻² from the forces against −0.1002 and −0.1 from the velocity change → 0.2 % at most
    assert "their sum over the body's mass, -0.1000 m s⁻², is that acceleration within 0.2 %" in out[0]
    assert "from the ball ellipsoids alone (share 1.0000) at -1.000 × μ_d(ball) = 0.0100 times" in out[0]
    assert fidelity.stop_findings(st.drop(index=[("Free", "Slow"), ("Fast", "Free")])) == []


def test_restart_pairs_and_floor_stop_findings(monkeypatch):
    """fidelity.infeasible_pairs keeps the first round's infeasible restarts; restart_pairs
    starts each class only from a valid, solved (not stood-in) run of its start class, one
    sweep per start, the study's own runs left out; floor_stop_findings counts the valid ones."""
    own, inf = fidelity.OWN_START, "Infeasible_Problem_Detected"
    stops = pd.DataFrame({"status": [inf, inf, "Maximum_Iterations_Exceeded", inf]}, index=pd.MultiIndex.from_tuples(
        [("Free", "VerySlow"), ("VeryFast", "Fast"), ("Fast", "Slow"), ("Fast", "Slow" + fidelity.ROUND_2)],
        names=["class", "start"]))
    assert fidelity.infeasible_pairs(stops) == [("Free", "VerySlow"), ("VeryFast", "Fast")]

    class Sol:
        def __init__(self, mark="", cot=3.0):
            self.mark, self.stats = mark, {"COT": cot}

    calls = []

    def fake(res, classes=None, *, starts=None, **kw):
        calls.append((classes, sorted(starts)))
        return {c: {own: "own", **{k: Sol(cot=2.5) for k in starts}} for c in classes}

    monkeypatch.setattr(fidelity.marks, "failure_label", lambda s: s.mark or None)
    monkeypatch.setattr(fidelity, "curve_restarts", fake)
    res = SimpleNamespace(solutions={"NMSK VerySlow": Sol(), "NMSK Fast": Sol()}, restart_used=("NMSK Fast",))
    out = fidelity.restart_pairs(res, fidelity.infeasible_pairs(stops) + [("Fast", "VerySlow")])
    assert calls == [(["Free", "Fast"], ["VerySlow"])]  # Fast's run is a stand-in: no start
    assert set(out) == {"Free", "Fast"} and set(out["Free"]) == {"VerySlow"}
    text = fidelity.floor_stop_findings(stops, out, 0.2819)[0]
    assert text.startswith("**With every ellipsoid's friction at least 0.2819** (the problem of the friction-floor "
                           "section above; its own runs as starts), the same 1 restarts: 1 of 1 converge")
    assert "Free from VerySlow: converged, valid (COT 2.50)" in text and "it is the ball's μ_d" in text
    out["Free"]["VerySlow"] = Sol("NOT CONVERGED: Maximum_Iterations_Exceeded")
    out["Free"]["VerySlow"].stats["status"] = "Maximum_Iterations_Exceeded"
    text = fidelity.floor_stop_findings(stops, out, 0.2819)[0]
    assert "0 of 1 converge" in text and "Free from VerySlow: NOT CONVERGED: Maximum_Iterations_Exceeded" in text
    assert "ball's μ_d" not in text and "None stops as locally infeasible any more" in text
    out["Free"]["VerySlow"].stats["status"] = "Infeasible_Problem_Detected"
    assert fidelity.floor_stop_findings(stops, out, 0.2819)[0].endswith("1 of 1 stop as locally infeasible again.")
    assert fidelity.floor_stop_findings(stops, {}, 0.2819) == []


def test_minimum_table_and_findings_by_hand():
    """fidelity.minimum_table: per curve its valid points, where it is lowest (a reference row
    is no point of the curve), and whether that is a located minimum at Free; too few points
    and an unstored curve are said so / left out; minimum_findings counts them."""
    classes = ["VerySlow", "Slow", "Free", "Fast", "VeryFast"]

    def cot(values, marks=("",) * 5, extra=None):
        t = pd.DataFrame({"mark": list(marks), "COT (J/kg/m)": values, "speed (m/s)": [0.5, 0.8, 1.2, 1.6, 2.0]},
                         index=classes)
        ref = pd.DataFrame({"mark": [""], "COT (J/kg/m)": [extra], "speed (m/s)": [1.1]}, index=["Free (ref)"])
        return pd.concat([t, ref]) if extra else t

    t = fidelity.minimum_table({
        "U": cot([6.8, 6.7, 5.6, 5.9, 6.2], extra=1.0),  # the reference's 1.0 is not a point
        "falls": cot([6.6, 6.7, 5.6, 0.1, 0.1], ("", "", "", "x", "x")),
        "fast": cot([3.3, 5.6, 4.9, 2.5, 2.2]),
        "few": cot([1.0, 2.0, 3.0, 4.0, 5.0], ("x", "x", "x", "", "")),
        "not stored": None})
    assert list(t.index) == ["U", "falls", "fast", "few"]
    assert t.loc["U"].tolist() == ["5 of 5", "minimum at Free", 5.6, True, ""]
    assert t.loc["falls", "where lowest"].startswith("lowest at Free, its fastest valid speed (Fast, VeryFast marked")
    assert not t.loc["falls", "minimum at Free"] and t.loc["falls", "valid points"] == "3 of 5"
    assert t.loc["fast", "where lowest"] == "minimum at VeryFast" and t.loc["fast", "COT there (J/kg/m)"] == 2.2
    assert t.loc["few", "where lowest"] == "too few valid points" and math.isnan(t.loc["few", "COT there (J/kg/m)"])
    assert fidelity.minimum_findings(t) == [
        "**Of the 3 COT curves above with at least three valid points, 1 has a located minimum at Free** (U, a U); "
        "elsewhere: fast (VeryFast); not located (lowest at the end of the valid speeds): falls."]
    assert fidelity.minimum_findings(t.loc[["few"]]) == []
    gap = fidelity.minimum_table({"gap": cot([6.8, 6.7, 5.6, 5.9, 6.2], ("x", "", "", "", ""))})
    assert "(gap, U not tested: marked speeds left out)" in fidelity.minimum_findings(gap)[0]
    bump = fidelity.minimum_table({"bump": cot([6.5, 6.7, 5.6, 5.9, 6.2])})
    assert bump.loc["bump", "steps the wrong way (not a U)"] == "VerySlow 6.50 → Slow 6.70"
    assert "(bump, not a U: VerySlow 6.50 → Slow 6.70)" in fidelity.minimum_findings(bump)[0]


def test_tracking_weight_findings_by_hand():
    """fidelity.tracking_weight_findings: per class valid at both weights, the own-data runs'
    worst angle base → heavier data terms; still far → the weights are not the cause, with the
    share they take off (1 − after/before, by hand); within 5° → the runs walk as the children."""
    col, mark = "worst angle RMSE vs class data, deg (own data)", "mark (own data)"
    base = pd.DataFrame({mark: ["", "", "x"], col: [12.0, 16.0, 15.0]}, index=["Free", "Fast", "VeryFast"])
    tight = pd.DataFrame({mark: ["", "", ""], col: [10.8, 12.0, 3.0]}, index=base.index)
    out = fidelity.tracking_weight_findings({"": base, " ×10": tight})
    assert out == ["**Tracking each class's own data ×10** against the same at Table 7.1's weights, the worst joint "
                   "angle's RMSE against the class's data (deg, classes valid in both): Free 12.0 → 10.8, Fast 16.0 → "
                   "12.0 — still 10.8–12.0°: the data terms' weights are not what holds the runs from the children's "
                   "angles (measured: the change takes off 10–25 %)."]
    tight[col] = [4.0, 4.5, 3.0]
    assert "within 5° everywhere" in fidelity.tracking_weight_findings({"": base, " ×10": tight})[0]
    assert fidelity.tracking_weight_findings({"": base}) == []


def test_own_data_findings_by_hand():
    """fidelity.own_data_findings: each input's minimum over its valid points, and the verdict on
    the one change (the tracked data) — moved to Free, not moved, moved elsewhere, too few."""
    classes = ["VerySlow", "Slow", "Free", "Fast", "VeryFast"]
    col = "worst angle RMSE vs class data, deg ({})"

    def table(cot_in, cot_own, marks_own=("",) * 5):
        t = pd.DataFrame({"mark (Free scaled in time)": [""] * 5, "COT (Free scaled in time)": cot_in,
                          col.format("Free scaled in time"): [6.0, 5.0, 1.0, 7.0, 9.0],
                          "mark (own data)": list(marks_own), "COT (own data)": cot_own,
                          col.format("own data"): [1.5, 1.2, 1.0, 1.4, 2.0]}, index=classes)
        return t.rename_axis("class")

    up = fidelity.own_data_findings(table([3.3, 5.6, 4.9, 2.5, 2.2], [5.0, 4.0, 3.0, 3.5, 4.2]))[0]
    assert "(5 of 5 speeds valid; COT in J kg⁻¹ m⁻¹: VerySlow 5.00, Slow 4.00, Free 3.00, Fast 3.50, VeryFast 4.20)" in up
    assert ("the curve: **minimum at Free**; on Free's data scaled in time: minimum at VeryFast. The input moves the "
            "minimum") in up
    assert "off by 1.0–2.0° in the own-data runs and 1.0–9.0° in the Free-input runs (5 classes where both are valid)." in up
    same = fidelity.own_data_findings(table([3.3, 5.6, 4.9, 2.5, 2.2], [5.0, 4.0, 3.0, 3.5, 2.9]))[0]
    assert "The input is not what moves the minimum" in same and "still lowest at VeryFast" in same
    t = table([3.3, 5.6, 4.9, 2.5, 2.2], [5.0, 4.0, 3.0, 3.5, 2.9])
    t[col.format("own data")] += 10.0  # 11–12° off the class data: the runs do not walk as the children
    assert "11.0–12.0° in the own-data runs" in fidelity.own_data_findings(t)[0]
    assert "the runs do not walk as the children walk" in fidelity.own_data_findings(t)[0]
    other = fidelity.own_data_findings(table([3.3, 5.6, 4.9, 2.5, 2.2], [5.0, 4.0, 3.0, 2.0, 2.9]))[0]
    assert "The input moves the minimum (VeryFast → Fast) but not to the natural speed" in other
    # a marked point is left out: VeryFast's 1.0 does not count
    marked = fidelity.own_data_findings(table([3.3, 5.6, 4.9, 2.5, 2.2], [5.0, 4.0, 3.0, 3.5, 1.0],
                                              ("", "", "", "", "NOT CONVERGED: x")))[0]
    assert "(4 of 5 speeds valid" in marked and "**minimum at Free**" in marked and "(4 classes" in marked
    # lowest at the end of the valid speeds with marked classes beyond: not a located minimum, no verdict
    end = fidelity.own_data_findings(table([3.3, 5.6, 4.9, 2.5, 2.2], [5.0, 4.0, 3.0, 3.5, 1.0],
                                           ("", "", "", "x", "x")))[0]
    assert ("**lowest at Free, its fastest valid speed (Fast, VeryFast marked: the minimum not located)**" in end
            and "Whether the input moves the minimum is not measured" in end and "The input" not in end)
    few = fidelity.own_data_findings(table([3.3, 5.6, 4.9, 2.5, 2.2], [5.0, 4.0, 3.0, 3.5, 1.0],
                                           ("x", "x", "x", "", "")))[0]
    assert few.startswith("**Tracking each class's own data** only 2 of 5 speeds converge")


def test_hat_reference_drift_and_its_caveat():
    """fidelity.hat_reference_drift: the largest rise of dx = pelvis_tx − stride·τ over a
    study's HAT references (by hand); the caveat only beyond HAT_DRIFT_TOL."""
    tau = tuple(k / 4 for k in range(4))
    ok = SimpleNamespace(hat_reference=(tau, (0.0, 0.01, -0.01, 0.00005), (0.7,) * 4, (0.0,) * 4))
    bad = SimpleNamespace(hat_reference=(tau, (0.0, 0.03, 0.06, 0.09), (0.7,) * 4, (0.0,) * 4))
    none = SimpleNamespace(hat_reference=())
    assert fidelity.hat_reference_drift(SimpleNamespace(specs={"a": ok, "b": none})) == pytest.approx(0.00005)
    assert fidelity.hat_reference_drift(SimpleNamespace(specs={"a": ok, "b": bad})) == pytest.approx(0.09)
    assert fidelity.hat_reference_drift(SimpleNamespace(specs={"b": none})) == 0.0
    assert fidelity.hat_drift_caveat(0.00005, 0.00005) == []
    text = fidelity.hat_drift_caveat(0.09, 0.00005)[0]
    assert "rises 0.090 m over the cycle (the book's-legs runs: 0.00005 m)" in text
