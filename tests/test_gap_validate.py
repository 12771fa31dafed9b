"""The non-circular validation's manipulations (gaitlib.gap.validate): data round trips
through the tidy reader against the laboratory effects that should undo them, and draws
that follow the method's hash."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from gaitlib import conventions as cv
from gaitlib import effects as effects_mod
from gaitlib.gap import io as gio
from gaitlib.gap import method as M
from gaitlib.gap import validate as V


@pytest.fixture(scope="module")
def frame():
    return V.real_frame("Free")


def _read(tmp_path, df, name):
    p = tmp_path / f"{name}.csv"
    df.to_csv(p, index=False)
    return gio.read_data(p).gait


@pytest.fixture(scope="module")
def base_gait(frame, tmp_path_factory):
    return _read(tmp_path_factory.mktemp("v"), frame, "unedited")


@pytest.mark.parametrize("joint,quantity", [("hip", "hip_flexion"), ("knee", "knee_flexion"),
                                            ("ankle", "ankle_dorsiflexion")])
def test_offset_injection_is_undone_by_its_effect(tmp_path, frame, base_gait, joint, quantity):
    """+c degrees on the data's joint angle is c·π/180 times DATA_SIGN in the model's
    coordinate; the effect at that value gives back the unedited data (both legs)."""
    c = 3.7
    g = _read(tmp_path, V.inject(frame, f"{joint}_offset", c), "x")
    cm = cv.DATA_SIGN[joint] * math.radians(c)
    for s in cv.SIDES:
        assert np.allclose(g.mean[f"{joint}_{s}"] - base_gait.mean[f"{joint}_{s}"], cm, atol=1e-9)
    back = effects_mod.adjust_data(g, {f"{joint}_offset": {"c": cm}})
    assert np.allclose(back.mean.to_numpy(float), base_gait.mean.to_numpy(float), atol=1e-9)
    assert V.INJECTIONS[f"{joint}_offset"].expected == f"{joint}_offset"


def test_plate_injections_are_undone_by_their_effects(tmp_path, frame, base_gait):
    s = -0.06
    g = _read(tmp_path, V.inject(frame, "plate_gain", s), "gain")
    back = effects_mod.adjust_data(g, {"grf_scale": {"s": s}})
    assert np.allclose(back.mean.to_numpy(float), base_gait.mean.to_numpy(float), atol=1e-9)
    assert np.allclose(back.sd.to_numpy(float), base_gait.sd.to_numpy(float), atol=1e-9)  # a gain scales the SD
    b_bw = 0.015
    g = _read(tmp_path, V.inject(frame, "plate_ap_bias", b_bw), "bias")
    b_n = b_bw * base_gait.body_mass * cv.G * cv.DATA_SIGN.get("grf_x", 1.0)
    back = effects_mod.adjust_data(g, {"grf_ap_bias": {"b": b_n}})
    assert np.allclose(back.mean.to_numpy(float), base_gait.mean.to_numpy(float), atol=1e-9)
    on = base_gait.mean["grf_y_r"] > effects_mod.PLATE_THRESHOLD_N
    assert 0.4 < on.mean() < 0.8  # the bias acts in stance only


def test_load_scale_scales_every_load_and_nothing_else(tmp_path, frame, base_gait):
    m = 0.1
    g = _read(tmp_path, V.inject(frame, "load_scale", m), "load")
    for c in g.mean.columns:
        ratio_ok = np.allclose(g.mean[c], (1 + m) * base_gait.mean[c], atol=1e-9) \
            and np.allclose(g.sd[c], (1 + m) * base_gait.sd[c], atol=1e-9)
        same = np.allclose(g.mean[c], base_gait.mean[c], atol=1e-12) and np.allclose(g.sd[c], base_gait.sd[c], atol=1e-12)
        if c.startswith(("tau_", "pow_", "grf_")):
            assert ratio_ok, c
        else:
            assert same, c


def test_out_of_library_manipulations_change_only_their_channel(tmp_path, frame, base_gait):
    for name, stems in (("knee_rom", ("knee",)), ("hip_swing_bump", ("hip",)),
                        ("ankle_moment_gain", ("tau_ankle", "pow_ankle")), ("impact_peak", ("grf_y",))):
        g = _read(tmp_path, V.inject(frame, name, 0.2 if name != "hip_swing_bump" else 5.0), name)
        changed = {c for c in g.mean.columns if not np.allclose(g.mean[c], base_gait.mean[c], atol=1e-12)}
        assert changed and all(c.rsplit("_", 1)[0] in stems for c in changed), (name, changed)
        assert V.INJECTIONS[name].expected == "unexplained"
    # the knee's excursion scales about its mean: the mean stays, the range grows by 1.2
    g = _read(tmp_path, V.inject(frame, "knee_rom", 0.2), "rom")
    k0, k1 = base_gait.mean["knee_r"].to_numpy(), g.mean["knee_r"].to_numpy()
    assert np.ptp(k1) == pytest.approx(1.2 * np.ptp(k0), rel=1e-9)


def test_draws_follow_the_method_hash():
    d1, d2 = V.draws(), V.draws()
    assert d1.equals(d2)
    other = dataclasses.replace(M.METHOD, bic_threshold=-9.0)
    assert other.hash() != M.METHOD.hash()
    d3 = V.draws(method=other)
    assert (d3["magnitude"] != d1["magnitude"]).all()
    for _, r in d1.iterrows():
        lo, hi = V.INJECTIONS[r["injection"]].bands[V.BANDS.index(r["band"])]
        assert lo <= abs(r["magnitude"]) <= hi
    assert set(d1["set"]) == {"independent", "out-of-library"}
    assert (d1[d1["set"] == "out-of-library"]["band"] != "small").all()
    for n, inj in V.INJECTIONS.items():
        assert inj.expected == "unexplained" or inj.expected in effects_mod.EFFECTS, n


def test_method_is_frozen_and_names_itself():
    m = M.METHOD
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.bic_threshold = -5.0
    assert M.BIC_THRESHOLD == m.bic_threshold and M.EXPLAINED_PCT == m.explained_pct
    assert M.RUNNER_UP_MARGIN == m.runner_up_margin and M.DEFAULT_BASE == dict(m.base)
    assert M.PROFILE_GRID == {k: tuple(v) for k, v in m.profile_grid}
    assert m.hash() == M.Method().hash() and len(m.hash()) == 16
    assert dataclasses.replace(m, runner_up_margin=m.runner_up_margin + 1).hash() != m.hash()


def test_runner_up_margin_names_only_a_clear_winner():
    """contenders_of: the ranked, converged candidates within the margin of the best ΔBIC;
    the diagnosis names an effect only when it is alone there."""
    import pandas as pd
    from gaitlib.gap import diagnose as D

    r = pd.DataFrame({"effect": ["a", "b", "c", "d"], "ok": [True, True, True, False],
                      "dBIC": [-40.0, -31.0, -12.0, -80.0]})
    assert D.contenders_of(r, 10.0) == ["a", "b"]  # b within 10 of a; d did not converge
    assert D.contenders_of(r, 5.0) == ["a"]
    assert D.contenders_of(r, 0.0) == ["a"]
    assert D.contenders_of(r.iloc[:0], 10.0) == []


def test_model_variants_are_other_models_with_a_stated_family():
    from gaitlib.problems import gait as gait_ocp

    d = V.draws(("model-variant",))
    assert len(d) == len(V.VARIANTS) * V.VARIANT_SEEDS and (d["unit"] == "seed").all()
    for name, (fields, family) in V.VARIANTS.items():
        spec = gait_ocp.GaitSpec(**fields)
        assert spec != gait_ocp.GaitSpec()  # another model than the baseline's
        assert all(e in effects_mod.MODEL_EFFECTS for e in family.split("|")), name


def test_stored_validation_is_refused_for_another_method(tmp_path, monkeypatch):
    import pandas as pd
    from gaitlib.studies import gap as G
    from gaitlib.studies import performance as perf

    rows = pd.DataFrame([{"set": "independent", "band": "middle", "correct": True, "named": "grf_scale",
                          "expected": "grf_scale"}])
    folder = tmp_path / "gap_validation" / "real"
    V.Validation(rows, {"named": "unexplained"}, {"method_hash": M.METHOD.hash()}).save(folder)
    monkeypatch.setattr(perf, "results_dir", lambda: tmp_path)
    v = G.stored_validation("real")
    assert v.rows.equals(rows) and v.scores()["top1_pct"].tolist() == [100.0]
    V.Validation(rows, {}, {"method_hash": "0" * 16}).save(folder)
    with pytest.raises(RuntimeError, match="rerun `gaitlib gap-validate"):
        G.stored_validation("real")
    # the stored results in the repository are the current method's
    monkeypatch.undo()
    for name in G.VALIDATION_RUNS:
        assert G.stored_validation(name).settings["method_hash"] == M.METHOD.hash()


def test_resample_adds_only_the_sampling_error_of_the_means(tmp_path, frame):
    """The null set's data: each curve's mean moves by SD/√n times a smooth unit-variance
    curve; nothing else changes; the same seed gives the same data; a user's reader
    accepts it."""
    n = 82
    a, b, c = V.resample(frame, 7, n), V.resample(frame, 7, n), V.resample(frame, 8, n)
    assert a.equals(b) and not a["mean"].equals(c["mean"])
    assert a.drop(columns="mean").equals(frame.drop(columns="mean"))
    sd = frame["sd"].to_numpy(float)
    z = (a["mean"].to_numpy(float) - frame["mean"].to_numpy(float))[sd > 0] / (sd[sd > 0] / math.sqrt(n))
    assert 0.6 < z.std() < 1.4 and abs(z.mean()) < 0.5  # unit variance, centred (18 smooth curves)
    assert np.all(a.loc[sd == 0, "mean"].to_numpy() == frame.loc[sd == 0, "mean"].to_numpy())
    # smooth: successive points (2 % of the cycle apart, correlation length 5 %) move together
    q = a["quantity"] == "knee_flexion"
    dz = np.diff((a.loc[q, "mean"] - frame.loc[q, "mean"]).to_numpy() / (frame.loc[q, "sd"].to_numpy() / math.sqrt(n)))
    assert np.std(dz) < 0.8
    _read(tmp_path, a, "null")
    with pytest.raises(ValueError, match="n \\(subjects\\)"):
        V.resample(frame, 7, 0)


def test_a_replicate_draws_afresh_with_the_method_unchanged():
    h = M.RELATIVE.hash()
    assert V.replicate_hash(h, 0) == h  # replicate 0: the stored validation's own draws
    sets = ("independent", "out-of-library", "null")
    d0 = V.draws(sets, 2, seed_hash=V.replicate_hash(h, 0))
    d1 = V.draws(sets, 2, seed_hash=V.replicate_hash(h, 1))
    assert d0.equals(V.draws(sets, 2, seed_hash=h))
    assert list(d1["case"]) == list(d0["case"])  # the same cases, other draws
    assert (d1["magnitude"] != d0["magnitude"]).all()
    assert d1.equals(V.draws(sets, 2, seed_hash=V.replicate_hash(h, 1)))  # reproducible
    for _, r in d1[d1["set"] != "null"].iterrows():
        lo, hi = V.INJECTIONS[r["injection"]].bands[V.BANDS.index(r["band"])]
        assert lo <= abs(r["magnitude"]) <= hi
    with pytest.raises(ValueError, match="replicate"):
        V.replicate_hash(h, -1)


def test_null_draws_follow_the_method_hash():
    d = V.draws(("null",))
    assert len(d) == V.NULL_DRAWS and (d["unit"] == "seed").all() and d["magnitude"].nunique() == V.NULL_DRAWS
    other = dataclasses.replace(M.METHOD, bic_threshold=-9.0)
    assert (V.draws(("null",), method=other)["magnitude"] != d["magnitude"]).all()


def test_null_spread_and_visibility_by_hand():
    """Hand-made null draws: the spread of each candidate's ΔBIC and of the baseline's RSS;
    an injection reaches naming when its ΔBIC is below min(threshold, best other null mean
    − margin)."""
    import pandas as pd

    null_rows = pd.DataFrame([
        {"set": "null", "named": "unexplained", "rss_baseline": 110.0, "dBIC": {"a": -20.0, "b": -2.0}},
        {"set": "null", "named": "a", "rss_baseline": 95.0, "dBIC": {"a": -30.0, "b": 0.0}},
        {"set": "null", "named": "unexplained", "rss_baseline": 100.0, "dBIC": {"a": -25.0, "b": 2.0}},
    ])
    null = V.Validation(null_rows, {"named": "unexplained", "rss_baseline": 100.0, "dBIC": {"a": -24.0, "b": 1.0}}, {})
    s = V.null_spread(null)
    assert s["draws"] == 3 and s["same_verdict"] == 2 and s["rss_pct"] == [10.0, -5.0, 0.0]
    c = s["candidates"]
    assert c.loc["a", "mean"] == -25.0 and c.loc["a", "sd"] == pytest.approx(5.0)
    assert c.loc["b", "mean"] == 0.0 and c.loc["b", "sd"] == pytest.approx(2.0)
    assert c.loc["a", "unedited"] == -24.0 and list(c.index) == ["a", "b"]
    real = V.Validation(pd.DataFrame([
        {"injection": "x", "band": "middle", "magnitude": 1.0, "unit": "1", "expected": "b", "named": "a",
         "correct": False, "added_pct": 3.0, "expected_dBIC": -30.0},
        {"injection": "y", "band": "large", "magnitude": 2.0, "unit": "1", "expected": "b", "named": "b",
         "correct": True, "added_pct": 9.0, "expected_dBIC": -40.0},
        {"injection": "z", "band": "large", "magnitude": 2.0, "unit": "1", "expected": "unexplained",
         "named": "a", "correct": False, "added_pct": 1.0, "expected_dBIC": np.nan},
    ]), {}, {})
    v = V.visibility(real, s, margin=10.0)
    assert list(v["injection"]) == ["x", "y"]  # z expects no library effect
    assert v["needed"].tolist() == [-35.0, -35.0]  # a's null mean −25 minus the margin, below −10
    assert v["reaches"].tolist() == [False, True]
    assert v["z"].tolist() == pytest.approx([-15.0, -20.0]) and v["null_rss_pct_max"].tolist() == [10.0, 10.0]
    with pytest.raises(ValueError, match="no 'null' rows"):
        V.null_spread(real)


def test_null_lines_count_from_the_runs():
    import pandas as pd
    from gaitlib.studies import gap as G

    null = V.Validation(pd.DataFrame([
        {"set": "null", "named": "unexplained", "rss_baseline": 104.0, "dBIC": {"a": -20.0, "b": -1.0}},
        {"set": "null", "named": "a", "rss_baseline": 98.0, "dBIC": {"a": -30.0, "b": 1.0}},
    ]), {"named": "unexplained", "rss_baseline": 100.0, "dBIC": {"a": -24.0, "b": 0.0}}, {})
    real = V.Validation(pd.DataFrame([
        {"injection": "x", "band": "middle", "magnitude": 1.0, "unit": "1", "expected": "b", "named": "b",
         "correct": True, "added_pct": 5.0, "expected_dBIC": -40.0},
        {"injection": "x", "band": "small", "magnitude": 0.5, "unit": "1", "expected": "b", "named": "a",
         "correct": False, "added_pct": 1.0, "expected_dBIC": -2.0},
    ]), {}, {})
    first, second = G.null_lines(null, real)
    assert "RSS moved by -2.0 to +4.0 %" in first and "in 1 of 2 draws (otherwise: a 1×)" in first
    assert "a -24.0, -25.0 ± 7.1 (-30.0 to -20.0)" in first
    assert ("of the 1 independent injections at middle and large magnitudes the injected effect's ΔBIC moved beyond "
            "twice its null SD in 1 of 1") in second
    assert "reached what naming needs against the other candidates' null ΔBIC in 1" in second
    assert "largest change (4.0 %) in 1; named right: 1" in second
    assert "At small magnitudes: the injected effect's ΔBIC moved beyond twice its null SD in 0 of 1" in second


def test_null_refit_lines_count_from_the_experiment():
    from gaitlib.studies import gap as G

    refit = {"top": 3, "cases": {
        "unedited": {"source": "kept", "rss0": 100.0, "rss1": 100.0, "named0": "unexplained", "named1": "unexplained",
                     "dBIC0": {"a": -5.0, "b": 0.0}, "dBIC1": {"a": -5.0, "b": 0.0}},
        "null_0": {"source": "a", "rss0": 110.0, "rss1": 99.0, "named0": "a", "named1": "unexplained",
                   "dBIC0": {"a": -30.0, "b": 0.0}, "dBIC1": {"a": -2.0, "b": -10.0}},
        "null_1": {"source": "kept", "rss0": 100.0, "rss1": 100.0, "named0": "unexplained", "named1": "unexplained",
                   "dBIC0": {"a": -10.0, "b": 2.0}, "dBIC1": {"a": -4.0, "b": 10.0}},
    }}
    (line,) = G.null_refit_lines(refit, top=2)
    assert "A better baseline was found in 1 of 3 cases (RSS lower by 10.0–10.0 %)" in line
    assert "verdicts changed in 1 (null_0: a → unexplained)" in line
    assert "an effect was named in 0 of 2 draws after against 1 before" in line
    assert "a 14.1 → 1.4; b 1.4 → 14.1" in line and "largest SD after it: b, 14.1" in line


def test_muscle_twin_lines_from_the_rows():
    import pandas as pd
    from types import SimpleNamespace
    from gaitlib.studies import gap as G

    rows = pd.DataFrame([
        {"twin": "none#1", "injected": "none", "magnitude": 0.0, "top": "joint_stiffness", "verdict": "partial",
         "correct": False, "identified_magnitude": np.nan, "dBIC_top": -277.7, "dBIC_true": np.nan},
        {"twin": "none#2", "injected": "none", "magnitude": 0.0, "top": "unexplained", "verdict": "unexplained",
         "correct": True, "identified_magnitude": np.nan, "dBIC_top": np.nan, "dBIC_true": np.nan},
        {"twin": "co@0#1", "injected": "co_contraction", "magnitude": 0.27, "top": "activation_timing",
         "verdict": "partial", "correct": False, "identified_magnitude": 0.2, "dBIC_top": -52.2, "dBIC_true": -15.2},
        {"twin": "co@0#2", "injected": "co_contraction", "magnitude": 0.27, "top": "co_contraction",
         "verdict": "partial", "correct": True, "identified_magnitude": 0.2, "dBIC_top": -188.3, "dBIC_true": -188.3},
    ])
    rows["rss_base"] = [1200.0, 500.0, 1600.0, 1200.0]
    rows["rss_top"] = [600.0, 500.0, 1500.0, 800.0]
    rows["rss_gen"] = [12.0, 10.0, 12.0, 10.0]
    first, second, third = G.muscle_twin_lines(SimpleNamespace(rows=rows))
    assert "has an RSS of 1200, 500 against the generating solution's 12, 10 (50–100×)" in third
    assert "on none#1, joint_stiffness closed 50 % with no effect injected." in third
    assert first.startswith("**Muscle-level twins: 1 of 2 named right (50 %)** — co_contraction (0.27): 1 of 2, "
                            "identified 0.2, 0.2. Effect-free twins read \"unexplained\": 1 of 2.")
    assert second == ("Misnamed: none#1 (no effect) → joint_stiffness (partial; ΔBIC -277.7); co@0#1 → "
                      "activation_timing (partial; ΔBIC named -52.2, injected -15.2).")


def test_revision_lines_count_an_effect_in_both_revisions(tmp_path, monkeypatch):
    """The before/after of a method change counts, per revision, the cases that named the
    effect, named it rightly (also within a "|" family), ranked it first and expected it —
    by hand on two made-up validations; a superseded result loads without the hash check."""
    import pandas as pd
    from gaitlib.studies import gap as G
    from gaitlib.studies import performance as perf

    def rows(named, rank1, expected):
        return pd.DataFrame({"set": "independent", "band": "middle", "named": named, "rank1": rank1, "expected": expected,
                             "correct": [n in e.split("|") for n, e in zip(named, expected)]})

    old = V.Validation(rows(["grf_scale", "grf_scale", "unexplained"], ["grf_scale", "grf_scale", "grf_scale"],
                            ["body_mass", "grf_scale|body_mass", "grf_scale"]),
                       {"named": "unexplained", "rank1": "grf_scale"}, {"method_hash": "a" * 16, "method": {}})
    new = V.Validation(rows(["body_mass", "unexplained", "grf_scale"], ["body_mass", "left_shift", "grf_scale"],
                            ["body_mass", "grf_scale|body_mass", "grf_scale"]),
                       {"named": "unexplained", "rank1": "left_shift"},
                       {"method_hash": "b" * 16, "method": {"revision": 2}})
    assert G.effect_naming(old, "grf_scale") == {"cases": 3, "named": 2, "named_right": 1, "ranked_first": 3,
                                                 "expected": 2, "unedited_named": "unexplained",
                                                 "unedited_rank1": "grf_scale"}
    assert G.effect_naming(new, "grf_scale")["named"] == 1 and G.effect_naming(new, "grf_scale")["named_right"] == 1
    before, after = G.revision_lines(old, new)
    assert "revision 1" in before and "named in 2 of 3 cases (1 of them right" in before
    assert "revision 2" in after and "ranked first in 1;" in after and "ranked first left_shift" in after
    old.save(tmp_path / "gap_validation" / "real_rev1")
    monkeypatch.setattr(perf, "results_dir", lambda: tmp_path)
    assert G.superseded_validation("real_rev1").settings["method_hash"] == "a" * 16
    with pytest.raises(ValueError, match="unknown superseded"):
        G.superseded_validation("real")


def test_experiment_lines_are_computed_from_their_results(tmp_path, monkeypatch):
    """The normative-start and pair-test sentences count what their results hold (made-up
    results, counted by hand); a result of another method is refused."""
    import json
    from gaitlib.studies import gap as G
    from gaitlib.studies import performance as perf

    def r(named, start, obj, rss):
        return {"named": named, "start": start, "objective": obj, "rss_baseline": rss}

    norm = {"method_hash": M.METHOD.hash(), "cases": [
        {"injection": "load_scale", "band": "middle", "expected": "body_mass",
         "without": r("unexplained", "grf", 0.8, 713.0), "with": r("body_mass", "warm", 0.7, 692.0)},
        {"injection": "hip_offset", "band": "large", "expected": "hip_offset",
         "without": r("hip_offset", "grf", 0.8, 650.0), "with": r("hip_offset", "grf", 0.8, 650.0)}]}
    (line,) = G.normative_start_lines(norm)
    assert "named right in 2 (without it: 1)" in line and "in 1 (load_scale middle: RSS 713 → 692)" in line
    assert "changed in 1 (load_scale middle: unexplained → body_mass)" in line
    pair = {"method_hash": M.METHOD.hash(), "threshold": -10.0, "margin": 10.0, "cases": [
        {"case": "a", "top": "x", "second": "y", "expected": "x", "cond_top": -12.0, "cond_second": -11.0,
         "rule_names": "x", "rule_right": True, "method_right": False},
        {"case": "b", "top": "y", "second": "z", "expected": "unexplained", "cond_top": -3.0, "cond_second": -1.0,
         "rule_names": "unexplained", "rule_right": True, "method_right": True},
        {"case": "c", "top": "y", "second": "z", "expected": "z", "skipped": "no converged pair fit"}]}
    first, second = G.pair_test_lines(pair)
    assert "In 3 cases" in first and "converged in 2" in first and "passed the threshold in 1 of them (both" \
        " effects given the other in 1" in first
    assert "right in 2 of these 2 cases, the method in 1" in second
    (tmp_path / "x.json").write_text(json.dumps(dict(pair, method_hash="0" * 16)))
    monkeypatch.setattr(perf, "results_dir", lambda: tmp_path)
    assert G.stored_experiment("absent.json", "s.py") is None
    with pytest.raises(RuntimeError, match="rerun benchmarks/s.py"):
        G.stored_experiment("x.json", "s.py")


def test_relative_lines_count_both_runs_on_the_same_cases():
    """The relative validation's sentences and side-by-side table count the two made-up runs
    by hand: the same case names pair the absolute and relative diagnoses."""
    import pandas as pd
    from gaitlib.studies import gap as G

    def rows(named):
        cases = ["knee_offset_middle_0", "plate_gain_large_0", "hip_offset_small_0", "knee_rom_large_0", "null_0",
                 "null_1"]
        sets = ["independent", "independent", "independent", "out-of-library", "null", "null"]
        bands = ["middle", "large", "small", "large", "—", "—"]
        exp = ["knee_offset", "grf_scale", "hip_offset", "unexplained", "unexplained", "unexplained"]
        return pd.DataFrame({"set": sets, "injection": [c.rsplit("_", 2)[0] for c in cases], "band": bands,
                             "magnitude": [-2.5, 0.12, 1.0, 0.2, 7.0, 8.0], "unit": ["deg", "1", "deg", "1", "seed", "seed"],
                             "case": cases, "expected": exp, "named": named, "verdict": "partial",
                             "correct": [n == e for n, e in zip(named, exp)], "rank1": named, "rank1_dBIC": -20.0,
                             "rank1_pct": 30.0, "rank2": None, "rank2_dBIC": float("nan"), "rank2_pct": float("nan"),
                             "added_pct": [3.0, 5.0, 1.0, 2.0, 0.5, 0.4], "n_eff": [250.0, 260, 255, 240, 230, 270]})

    absolute = V.Validation(rows(["unexplained", "grf_scale", "unexplained", "left_shift", "x", "y"]), {}, {})
    rel = V.Validation(rows(["knee_offset", "body_mass", "hip_offset", "unexplained", "unexplained", "friction"]),
                       {"named": "unexplained"}, {"relative": True})
    ind, small, ool, nul = G.relative_lines(rel, absolute)  # no expected_change: no magnitude sentence
    c_knee = V.effect_magnitude("knee_offset", -2.5, gio.load_real().gait)[1]
    rel.rows["expected_change"] = [{"c": 1.1 * c_knee}, {"s": 0.9 * 0.12}, {"c": 0.0}, None, None, None]
    mag = G.relative_lines(rel, absolute)[2]
    assert mag.endswith("identified / injected 0.90 to 1.10 (median 1.00) over the 2 middle and large injections.")
    m = G.relative_magnitudes(rel)
    assert list(m["parameter"]) == ["c", "s", "c"] and m["ratio"].round(6).tolist() == [1.1, 0.9, 0.0]
    assert "middle and large magnitudes 1 of 2 named right (50 %" in ind and "same manipulations: 1 of 2." in ind
    assert "plate_gain large (+0.12 1) named body_mass" in ind
    assert small.startswith("Small magnitudes: 1 of 1 named right (0 unexplained)")
    assert "1 of 1 read \"unexplained\" (100 %" in ool
    assert "1 of 2 read \"unexplained\" — named: friction (partial)." in nul
    assert "reached ΔBIC -20 to -20 (unexplained, closing 30 %" in nul and "residual, 230–270)" in nul
    t = G.relative_cases(rel, absolute)
    assert list(t["named (absolute)"][:2]) == ["unexplained", "grf_scale"]
    assert list(t["named (relative)"][:2]) == ["knee_offset", "body_mass"]
    with pytest.raises(ValueError, match="not a relative one"):
        G.relative_lines(absolute, rel)
    rel.rows["magnitude"] = rel.rows["magnitude"] * 1.5  # other draws: nothing is paired
    assert "(other draws than the absolute validation's" in G.relative_lines(rel, absolute)[0]
    assert "absolute diagnosis named 1 of 2 of its own" in G.relative_lines(rel, absolute)[0]
    assert set(G.relative_cases(rel, absolute)["named (absolute)"]) == {"—"}
    rel.rows["rank1_dBIC"] = -4.0  # null draws within the threshold: not "beyond" it
    nul = G.relative_lines(rel, absolute)[-1]
    assert "reached ΔBIC -4 to -4 (unexplained, closing 30 %): within the threshold (-10) even without" in nul
    assert "beyond" not in nul


@pytest.mark.parametrize("name,m", [("hip_offset", 2.5), ("knee_offset", -3.0), ("ankle_offset", 4.0),
                                    ("plate_gain", -0.05), ("plate_ap_bias", 0.02)])
def test_effect_magnitude_undoes_its_manipulation(tmp_path, frame, base_gait, name, m):
    """The change a relative diagnosis should identify: the effect at effect_magnitude(...)
    gives the unedited data back (both legs, through the reader)."""
    g = _read(tmp_path, V.inject(frame, name, m), "x")
    p, v = V.effect_magnitude(name, m, base_gait)
    back = effects_mod.adjust_data(g, {V.INJECTIONS[name].expected: {p: v}})
    assert np.allclose(back.mean.to_numpy(float), base_gait.mean.to_numpy(float), atol=1e-9)


def test_effect_magnitude_of_a_load_scale_is_the_mass_change():
    assert V.effect_magnitude("load_scale", 0.11, None) == ("k", 0.11)
    with pytest.raises(ValueError, match="not an independent manipulation"):
        V.effect_magnitude("knee_rom", 0.1, None)


def test_calibration_lines_count_the_stored_null_draws():
    from gaitlib.studies import gap as G

    calib = {"draws": 3, "n_subjects": 41, "lowest_dBIC": -150.0, "baseline_failed": ["null2"],
             "best": [{"draw": "null0", "effect": "ankle_offset", "dBIC": -150.0},
                      {"draw": "null1", "effect": "ankle_offset", "dBIC": -40.0},
                      {"draw": "null2", "effect": "baseline failed", "dBIC": None}]}
    v = V.Validation(V.pd.DataFrame(), {"null_calibration": calib}, {"relative": True})
    (line,) = G.calibration_lines(v)
    assert "redrawn 3 times" in line and "(n = 41)" in line and "from -40 to -150 (ankle_offset ×2)" in line
    assert "named only at ΔBIC ≤ -150 (the lowest of the draws, level 1/4; the threshold alone: -10)" in line
    assert "baseline: null2." in line
    calib.update(rank=2, threshold_dBIC=-40.0)  # revision 5's rule: the second lowest
    (line,) = G.calibration_lines(v)
    assert "named only at ΔBIC ≤ -40 (the second lowest of the draws, level 2/4;" in line
    assert G.calibration_lines(V.Validation(V.pd.DataFrame(), {}, {}))[0].startswith("(no null calibration")


def test_a_null_draw_named_says_how_small_its_change_was():
    from gaitlib.studies import gap as G

    named = V.pd.DataFrame({"named": ["ankle_offset"], "rank1": ["ankle_offset"],
                            "rank1_change": [{"c": 0.0069}]})
    t = G._change_clause(named)
    assert "ankle_offset c +0.0069 rad (+0.40°)" in t and "not a change" in t
    assert G._change_clause(named.drop(columns="rank1_change")) == ""
    wrong = V.pd.DataFrame({"injection": ["hip_offset"], "band": ["large"], "rank1": ["hat_com"], "rank1_dBIC": [-324.2],
                            "rank1_pct": [71.6], "expected": ["hip_offset"], "expected_dBIC": [-324.7],
                            "expected_pct": [71.64]})
    assert G._against_expected(wrong) == (" First-ranked against the expected effect (ΔBIC, % closed): hip_offset "
                                          "large: hat_com -324 (72 %) vs hip_offset -325 (72 %).")
    tie = wrong.assign(rank1="hip_offset", rank2="hat_com", rank2_dBIC=-324.2, rank2_pct=71.6)
    assert "hip_offset large: hip_offset first at -325 (72 %), hat_com at -324 (72 %)" in G._against_expected(tie)


def test_consistency_lines_count_the_moved_reference_fits_by_hand():
    """The self-consistent reference fit's sentence, from a made-up calibration and cases:
    2 of 3 draws moved (one the baseline's), 3 model fits lowered by 1–10 %, 1 of 2 cases."""
    from gaitlib.studies import gap as G

    calib = {"moved": {"null0": {"baseline": {"reference": [1.0, 0.99], "data": [2.0, 1.9]},
                                 "knee_offset": {"reference": [1.0, 0.9]}},
                       "null1": {}, "null2": {"knee_offset": {"reference": [0.5, 0.475]}}}}
    rows = V.pd.DataFrame([{"set": "null", "reference_moved": ["baseline"]}, {"set": "null", "reference_moved": []}])
    (line,) = G.consistency_lines(V.Validation(rows, {"null_calibration": calib}, {"relative": True}))
    assert "lower objective in 2 of 3 null draws (1 of them the baseline's; 3 model fits in all: knee_offset ×2, " \
           "baseline ×1), lower by 1–10 %; in 1 of 2 validation cases (1 of them the baseline's)." in line
    (old,) = G.consistency_lines(V.Validation(rows, {"null_calibration": {"draws": 9}}, {"relative": True}))
    assert old.startswith("(no self-consistent reference fit")


def test_tie_lines_read_both_candidates_dbic_from_the_cases():
    from gaitlib.studies import gap as G

    rows = V.pd.DataFrame([
        {"case": "h_m", "expected": "hip_offset", "band": "middle", "dBIC": {"hip_offset": -135.15, "hat_com": -135.05}},
        {"case": "h_l", "expected": "hip_offset", "band": "large", "dBIC": {"hip_offset": -312.66, "hat_com": -312.62}},
        {"case": "h_s", "expected": "hip_offset", "band": "small", "dBIC": {"hip_offset": 2.0, "hat_com": 40.0}},
        {"case": "k_m", "expected": "knee_offset", "band": "middle", "dBIC": {"hip_offset": 0.0, "hat_com": 9.0}}])
    (line,) = G.tie_lines(V.Validation(rows, {}, {"relative": True}))
    assert line.startswith("In the 2 hip_offset injections at middle and large magnitudes, hat_com's ΔBIC differs "
                           "from hip_offset's by at most 0.1 (h_m: -135.2 vs -135.1; h_l: -312.7 vs -312.6)")


def test_relative_null_sets_regenerate_the_stored_draws(tmp_path, frame):
    """The reference and null draws of a stored relative validation, regenerated from its
    seeds: the same means as resample(frame, seed) read back; an absolute one is refused."""
    rows = V.pd.DataFrame([{"set": "null", "case": "null_0", "magnitude": 11.0},
                           {"set": "independent", "case": "knee_offset_middle_0", "magnitude": 2.0}])
    v = V.Validation(rows, {"reference_seed": 5}, {"relative": True, "speed_class": "Free"})
    ref, nulls = V.relative_null_sets(v, tmp_path)
    n = gio.read_data(tmp_path / "unedited.csv").n
    V.resample(frame, 5, n).to_csv(tmp_path / "r.csv", index=False)
    V.resample(frame, 11, n).to_csv(tmp_path / "n.csv", index=False)
    assert ref.gait.mean.equals(gio.read_data(tmp_path / "r.csv").gait.mean)
    assert [c["case"] for c, _ in nulls] == ["null_0"]
    assert nulls[0][1].gait.mean.equals(gio.read_data(tmp_path / "n.csv").gait.mean)
    with pytest.raises(ValueError, match="not a relative validation"):
        V.relative_null_sets(V.Validation(rows, {}, {}), tmp_path)
    # a manipulated case: injected, then resampled with the seed of the validation's own draws
    rows["injection"] = [None, "knee_offset"]
    v = V.Validation(rows, {"reference_seed": 5}, {"relative": True, "speed_class": "Free",
                                                     "relative_method_hash": "h" * 16, "replicate": 1})
    _, ((c, ds),) = V.relative_case_sets(v, tmp_path, ["knee_offset_middle_0"])
    seed = V._seed(V.replicate_hash("h" * 16, 1), "knee_offset_middle_0", 1) % 2**31
    V.resample(V.inject(frame, "knee_offset", 2.0), seed, n).to_csv(tmp_path / "k.csv", index=False)
    assert c["case"] == "knee_offset_middle_0" and ds.gait.mean.equals(gio.read_data(tmp_path / "k.csv").gait.mean)
    with pytest.raises(ValueError, match="no case nope"):
        V.relative_case_sets(v, tmp_path, ["nope"])


def test_wilson_interval_by_hand():
    from gaitlib.studies import gap as G

    # 22 of 24: p = 0.9167, z² = 3.8415; centre 0.8592, half-width 0.1177 (by hand)
    lo, hi = G.wilson(22, 24)
    assert lo == pytest.approx(74.15, abs=0.05) and hi == pytest.approx(97.68, abs=0.05)
    lo, hi = G.wilson(0, 4)  # none of 4: from 0 to 4/(4 + z²) = 49.0 %
    assert lo == 0.0 and hi == pytest.approx(100 * 3.8415 / (4 + 3.8415), abs=0.05)


def test_replicate_table_pools_the_groups_by_hand():
    import pandas as pd
    from gaitlib.studies import gap as G

    def val(rows, lowest):
        cols = ("set", "band", "case", "magnitude", "unit", "named", "correct")
        return V.Validation(pd.DataFrame([dict(zip(cols, r)) for r in rows]),
                            {"named": "unexplained", "null_calibration": {"lowest_dBIC": lowest}},
                            {"relative": True})

    r0 = val([("independent", "middle", "a_middle_0", 0.1, "1", "body_mass", True),
              ("independent", "large", "a_large_0", 0.2, "1", "grf_scale", False),
              ("independent", "small", "a_small_0", 0.05, "1", "unexplained", False),
              ("out-of-library", "large", "o_large_0", 0.2, "1", "unexplained", True),
              ("null", "—", "null_0", 7.0, "seed", "unexplained", True)], -30.0)
    r1 = val([("independent", "middle", "a_middle_0", 0.11, "1", "body_mass", True),
              ("independent", "large", "a_large_0", 0.21, "1", "body_mass", True),
              ("independent", "small", "a_small_0", 0.06, "1", "body_mass", True),
              ("out-of-library", "large", "o_large_0", 0.25, "1", "foot_contact", False),
              ("null", "—", "null_0", 8.0, "seed", "unexplained", True)], -80.0)
    t = G.replicate_table({"replicate 0": r0, "replicate 1": r1})
    assert t.loc["independent, middle + large", "replicate 0"] == "1/2"
    assert t.loc["independent, middle + large", "pooled"] == "3/4"
    assert t.loc["independent, middle + large", "pooled %"] == 75.0
    assert t.loc["out-of-library", "pooled"] == "1/2" and t.loc["independent, small", "pooled"] == "1/2"
    assert t.loc["null (nothing changed)", "pooled"] == "2/2"
    assert t.loc["threshold (ΔBIC ≤)", "replicate 0"] == "-30" and t.loc["threshold (ΔBIC ≤)", "replicate 1"] == "-80"
    lines = G.replicate_lines({"replicate 0": r0, "replicate 1": r1})
    assert "moves by 50" in lines[0]
    assert any(x.startswith("independent, middle + large: replicate 0 1/2, replicate 1 2/2; pooled 3/4 = 75 %")
               and "target not met" in x for x in lines)
    assert any("o_large_0 (+0.25 1) named foot_contact" in x for x in lines)
    assert not any("a_small_0" in x for x in lines)  # small injections are not a target
    # ranked first, named or not: needs the rank1/expected columns
    for v in (r0, r1):
        v.rows["rank1"] = ["body_mass", "body_mass", "x", "y", "z"]
        v.rows["expected"] = ["body_mass", "body_mass", "body_mass", "unexplained", "unexplained"]
    r0.rows.loc[1, "named"] = "unexplained"  # replicate 0's large miss: right effect first, within the threshold
    r0.rows["rank1_dBIC"] = r1.rows["rank1_dBIC"] = [-50.0, -25.0, -5.0, -5.0, -5.0]
    line = [x for x in G.replicate_lines({"replicate 0": r0, "replicate 1": r1}) if "ranked first" in x][0]
    assert "replicate 0 2/2; of its 1 misses 1 had it ranked first and were read \"unexplained\" — 1 with the " \
           "first-ranked ΔBIC within that replicate's threshold;" in line  # -25 > -30
    assert "replicate 1 2/2; of its 0 misses 0 had" in line
    r0.rows.loc[1, "rank1_dBIC"] = -40.0  # beyond -30: held by another test
    line = [x for x in G.replicate_lines({"replicate 0": r0, "replicate 1": r1}) if "ranked first" in x][0]
    assert "— 0 with the first-ranked ΔBIC within that replicate's threshold, 1 beyond it" in line


def test_target_table_reads_each_target_off_its_results():
    import pandas as pd
    from gaitlib.studies import gap as G

    class Twins:  # a twin check's summary, as TwinValidation.summary() gives it
        def __init__(self, top1, shrink, free):
            self.s = {"top1_pct": top1, "shrink_pct": shrink, "top1_met": top1 >= 90, "shrink_met": shrink >= 60,
                      "free_unexplained": free, "free_twins": 2}

        def summary(self):
            return self.s

    def val(named_right):  # 10 middle/large injections, k named right; 10 out-of-library, all "unexplained"
        rows = [("independent", "middle", f"a_{i}", i < named_right) for i in range(10)]
        rows += [("out-of-library", "large", f"o_{i}", True) for i in range(10)]
        return V.Validation(pd.DataFrame([dict(zip(("set", "band", "case", "correct"), r)) for r in rows]),
                            {"named": "unexplained"}, {"relative": True})

    mesh = pd.DataFrame({"verdict": ["unexplained", "unexplained"], "top effect": ["unexplained", "unexplained"]},
                        index=["10 × 3", "20 × 5"])
    t = G.target_table(Twins(100.0, 85.9, 2), Twins(91.7, 99.9, 0), {"r0": val(10), "r1": val(8)}, mesh)
    assert t.loc["in-model twins (10 × 3): top-1 at the middle magnitude", "measured"] == "100 %"
    assert t.loc["in-model twins (20 × 5): top-1 at the middle magnitude", "met"] == "yes"
    assert t.loc["in-model twins (20 × 5): effect-free twins \"unexplained\"", "measured"] == "0 of 2"
    assert t.loc["in-model twins (20 × 5): effect-free twins \"unexplained\"", "met"] == "no"
    row = [i for i in t.index if i.startswith("independent injections")][0]
    assert "pooled over 2 sets of draws" in row
    assert t.loc[row, "measured"].startswith("18/20 = 90 %") and t.loc[row, "met"] == "yes"  # 90 % is ≥ 90 %
    t = G.target_table(Twins(100.0, 85.9, 2), Twins(91.7, 99.9, 0), {"r0": val(10), "r1": val(7)}, mesh)
    assert t.loc[row, "measured"].startswith("17/20 = 85 %") and t.loc[row, "met"] == "no"
    ool = [i for i in t.index if i.startswith("out-of-library")][0]
    assert t.loc[ool, "measured"].startswith("20/20 = 100 %") and t.loc[ool, "met"] == "yes"
    real = [i for i in t.index if i.startswith("real data")][0]
    assert t.loc[real, "met"] == "yes" and t.loc[real, "measured"] == "unexplained at both"
    mesh.loc["20 × 5"] = ["named", "arm_swing"]
    t = G.target_table(Twins(100.0, 85.9, 2), Twins(91.7, 99.9, 0), {"r0": val(10)}, mesh)
    assert t.loc[real, "met"] == "no" and t.loc[real, "measured"] == "unexplained; named (arm_swing)"
    assert "(relative method, one set of draws)" in [i for i in t.index if i.startswith("independent")][0]


def test_replaying_a_stored_relative_validation_at_its_threshold_gives_back_every_verdict():
    """gap_study.named_at replays assemble's rule (first-ranked ΔBIC at or below the
    threshold, no runner-up within the margin) on the stored rankings: at each stored
    validation's own threshold it must give back every stored verdict; a looser threshold
    can only name more, a stricter one only fewer."""
    from gaitlib.studies import gap as G

    for name in ("relative_rev4", "relative_rev4_r1", "relative_rev3"):
        v = G.superseded_validation(name)
        t = G.calibration_threshold(v)
        r = G.named_at(v, t)
        assert (r["named"] == v.rows["named"]).all() and (r["correct"] == v.rows["correct"].astype(bool)).all()
        loose, strict = G.named_at(v, t + 20), G.named_at(v, t - 20)
        named = lambda x: (x["named"] != "unexplained").sum()  # noqa: E731
        assert named(strict) <= named(r) <= named(loose)


def test_threshold_sweep_and_the_ranking_ceiling_by_hand():
    """Two independent cases, one out-of-library: a case ranked right with ΔBIC −40 is named
    right at −30 but not at −50; one ranked wrong is never right (the ceiling); the
    out-of-library case (ΔBIC −35 first) is right only where its ΔBIC misses the threshold."""
    from gaitlib.studies import gap as G

    rows = V.pd.DataFrame({
        "case": ["a_middle_0", "b_large_0", "c_middle_0"], "set": ["independent", "independent", "out-of-library"],
        "band": ["middle", "large", "middle"], "expected": ["knee_offset", "body_mass", "unexplained"],
        "rank1": ["knee_offset", "grf_scale", "foot_contact"], "rank1_dBIC": [-40.0, -200.0, -35.0],
        "rank2": ["hip_offset", "body_mass", "friction"], "rank2_dBIC": [-5.0, -150.0, -1.0],
        "contenders": [["knee_offset"], ["grf_scale"], ["foot_contact"]], "expected_rank": [1, 2, None],
        "magnitude": [3.0, 0.2, 0.1], "verdict": ["partial"] * 3, "named": ["knee_offset", "grf_scale", "foot_contact"],
        "correct": [True, False, False]})
    v = V.Validation(rows, {}, {"relative": True})
    sw = G.threshold_sweep({"r0": v}, thresholds=(-30, -50))
    assert sw.loc[-30, "independent, middle + large"] == "1/2 (50 %)" and sw.loc[-30, "out-of-library"] == "0/1 (0 %)"
    assert sw.loc[-50, "independent, middle + large"] == "0/2 (0 %)" and sw.loc[-50, "out-of-library"] == "1/1 (100 %)"
    miss = G.ranking_misses({"r0": v})
    assert miss["case"].tolist() == ["b_large_0"] and miss["why"].iloc[0] == "another effect ranked first"
    (line,) = G.threshold_lines({"r0": v})
    assert "1 cases no threshold names right — 1 of the body_mass injections" in line
    assert "b_large_0 (r0): grf_scale -200, body_mass -150" in line


def test_load_confusion_lines_by_hand():
    """The experiment's sentence from a made-up result: the torque share of the baseline's
    change, the medians left by each effect, the ranked-first counts, the swing cells."""
    from gaitlib.studies import gap as G

    def case(rank1, bm_grf, gs_grf, cell):
        return {"injection": "load_scale", "expected": "body_mass", "magnitude": 0.1, "rank1": rank1,
                "baseline": {"angle": 10.0, "grf": 60.0, "torque": 30.0},
                "body_mass": {"angle": 9.0, "grf": bm_grf, "torque": 5.0, "worst_grf_cell": cell, "change": 0.09},
                "grf_scale": {"angle": 9.0, "grf": gs_grf, "torque": 29.0, "worst_grf_cell": "grf:grf_y_r LR",
                              "change": 0.12}}

    res = {"cases": [case("grf_scale", 8.0, 2.0, "grf:grf_y_l TSw"), case("body_mass", 4.0, 3.0, "grf:grf_x_r LR")]}
    a, b = G.load_confusion_lines(res)
    assert "torque channels carry 30–30 %" in a and "GRF channels: body_mass 6.0, grf_scale 2.5" in a
    assert "Ranked first: grf_scale 1×, body_mass 1×" in a and "+0.090 for +0.100" in a
    assert "identifies the injected magnitude (within 10 %)" in b
    assert "leaves 3.5 more GRF RSS than `grf_scale` (median; more in 2 of 2 cases)." in b
    assert "body_mass leaves 24.0 less (median), more than its GRF excess in 2 of 2 cases" in b
    for x in res["cases"]:  # the swing measurements of the experiment's second version
        x["body_mass"].update(grf_swing=4.0, swing_load_N={"r": 70.0, "l": 120.0})
        x["grf_scale"].update(grf_swing=1.0, swing_load_N={"r": 70.0, "l": 100.0})
        x["baseline"]["swing_load_N"] = {"r": 70.0, "l": 105.0}
    b = G.load_confusion_lines(res)[1]
    # excess GRF 8 − 2 = 6 and 4 − 3 = 1; in swing 4 − 1 = 3 of each: 50 % and 300 %, median 175 %
    assert "175 % of that excess (median) lies in the swing phases, where body_mass leaves 4.0 and grf_scale 1.0" in b
    assert "peak vertical GRF 105 N in the baseline's fit, 120 N in body_mass's, 100 N in grf_scale's" in b


def test_threshold_draw_lines_name_the_draw_that_sets_the_lowest_statistic():
    from gaitlib.studies import gap as G

    calib = {"dBIC": [{"a": -10.0, "b": 2.0}, {"a": -80.0, "b": -50.0, "c": -30.0}, {}],
             "moved": {"null0": {"baseline": {"reference": [0.78, 0.75]}},
                       "null1": {"baseline": {"reference": [0.73, 0.70]}}}}
    (line,) = G.threshold_draw_lines(V.Validation(V.pd.DataFrame(), {"null_calibration": calib}, {}), "rep")
    assert line.startswith("The draw that sets rep's lowest statistic (null1): a at ΔBIC -80; 2 of its 3 ranked")
    assert "from -50 to -80" in line and "objective 0.700, against a median of 0.750 in the other 1 draws" in line


def test_paired_lines_by_hand():
    """Two validations of the same draws: counts per group before → after, thresholds, the
    ranked-right ceiling and the verdicts that changed, all from the rows."""
    from gaitlib.studies import gap as G

    def rows(named, rank1, contenders):
        return V.pd.DataFrame({
            "case": ["load_scale_middle_0", "knee_offset_large_0", "knee_rom_middle_0"],
            "set": ["independent", "independent", "out-of-library"], "band": ["middle", "large", "middle"],
            "expected": ["body_mass", "knee_offset", "unexplained"], "named": named, "rank1": rank1,
            "rank1_dBIC": [-200.0, -300.0, -20.0], "rank2": ["body_mass", "hip_offset", "friction"],
            "rank2_dBIC": [-150.0, -10.0, -5.0], "contenders": contenders, "expected_rank": [2, 1, None],
            "magnitude": [0.1, 5.0, 0.1], "verdict": ["explained"] * 3,
            "correct": [n == e for n, e in zip(named, ["body_mass", "knee_offset", "unexplained"])]})

    cal = lambda t: {"null_calibration": {"lowest_dBIC": t}}  # noqa: E731
    before = V.Validation(rows(["grf_scale", "knee_offset", "unexplained"], ["grf_scale", "knee_offset", "foot_contact"],
                               [["grf_scale"], ["knee_offset"], ["foot_contact"]]), cal(-30.0), {"relative": True})
    after = V.Validation(rows(["body_mass", "knee_offset", "unexplained"], ["body_mass", "knee_offset", "foot_contact"],
                              [["body_mass"], ["knee_offset"], ["foot_contact"]]), cal(-25.0), {"relative": True})
    (line,) = G.paired_lines(before, after, G.PAIRED["quiet_points_rev5"])
    assert "The same draws, located with the quiet points left out: " in line
    assert "independent, middle + large: 1/2 → 2/2; out-of-library: 1/1 → 1/1" in line
    assert "(thresholds ΔBIC ≤ -30 → -25)" in line and ": 1 → 2 of 2." in line
    assert "Verdicts changed: load_scale_middle_0 grf_scale → body_mass (expected body_mass)." in line


def test_null_tail_by_hand():
    """Calibration draws and null cases of two made-up validations: counts at or below the
    cut, the pooled sentence with both rates and the lowest values."""
    from gaitlib.studies import gap as G

    def val(per, null_dbic, named):
        rows = V.pd.DataFrame({"set": ["null"] * len(null_dbic), "rank1_dBIC": null_dbic, "named": named})
        return V.Validation(rows, {"null_calibration": {"dBIC": per, "lowest_dBIC": min(min(p.values()) for p in per if p)}},
                            {"relative": True})

    a = val([{"x": -60.0, "y": -5.0}, {"x": -10.0}, {}], [-70.0, -3.0], ["hip_offset", "unexplained"])
    b = val([{"x": -2.0}], [float("nan"), -55.0], ["unexplained", "unexplained"])
    t = G.null_tail_table({"a": a, "b": b})
    assert t.loc["a", "calibration draws"] == 2 and t.loc["a", "draws ≤ -50"] == 1 and t.loc["a", "their lowest"] == -60
    assert t.loc["b", "null cases' first-ranked ΔBIC"] == "—, -55" and t.loc["b", "null cases ≤ -50"] == 1
    (line,) = G.null_tail_lines({"a": a, "b": b})
    assert line.startswith("Over a, b the null reached ΔBIC ≤ -50 in 1 of 3 calibration draws")
    assert "and in 2 of 4 null cases" in line and "calibration draws -60, null cases -70" in line
    assert "(1 of 4 null cases named an effect)" in line


def test_common_mode_draws_by_hand():
    """Calibration draws of a made-up validation: a draw is common-mode when its median
    candidate's ΔBIC is at or below the cut; 'kept' when its baseline's fit of the reference
    was not re-solved lower (no ``reference`` under the baseline in ``moved``)."""
    from gaitlib.studies import gap as G

    per = [{"x": -100.0, "y": -90.0, "z": -30.0},   # median -90: common mode, reference kept
           {"x": -60.0, "y": -25.0, "z": -21.0},    # median -25: common mode, reference re-solved
           {"x": -40.0, "y": 5.0, "z": 0.0},        # median 0: one effect, reference kept
           {}]                                       # no ranked candidate: not a draw
    moved = {"null0": {"baseline": {"data": [2.0, 1.9]}}, "null1": {"baseline": {"reference": [1.0, 0.9]}},
             "null2": {}}
    v = V.Validation(V.pd.DataFrame({"set": []}), {"null_calibration": {"dBIC": per, "moved": moved,
                                                                        "threshold_dBIC": -60.0}}, {"relative": True})
    r = G.common_mode_table({"v": v}).loc["v"]
    assert r["draws"] == 3 and r["common-mode (median ≤ -20)"] == 2
    assert r["of which the reference's baseline fit kept"] == 1 and r["other draws"] == 1 and r["of which kept"] == 1
    assert r["common-mode lowest"] == -100.0 and r["other draws' lowest"] == -40.0 and r["threshold"] == -60.0
    (line,) = G.common_mode_lines({"v": v})
    assert line.startswith("Over v: 2 of 3 calibration draws were common-mode")
    assert "their statistics from -60 to -100; in 1 of the 2 the baseline's fit of the reference kept its start" in line
    assert "against 1 of the 1 other draws. The other draws' statistics reached at most -40." in line


def test_baseline_pair_lines_by_hand():
    """A made-up gap_baseline_pair result: one common-mode draw the pair fixes, one it does
    not (objectives moved by 0.002), one other draw whose first-ranked ΔBIC moved by 1.5."""
    from gaitlib.studies import gap as G

    def run(rank1, med, n, r):
        return {"rank1": "x", "rank1_dBIC": rank1, "median_dBIC": med, "objective_N": n, "objective_R": r}

    r = {"draws": [{"draw": "a", "as_run": run(-100.0, -80.0, 0.80, 0.77), "pair": run(-8.0, 1.0, 0.81, 0.77)},
                   {"draw": "b", "as_run": run(-60.0, -40.0, 0.79, 0.76), "pair": run(-60.0, -40.0, 0.792, 0.76)},
                   {"draw": "c", "as_run": run(-12.0, -1.0, 0.78, 0.76), "pair": run(-13.5, -1.0, 0.78, 0.76)}]}
    (line,) = G.baseline_pair_lines(r)
    assert "of 2 common-mode draws, 1 lost the common mode — a -100 (median -80) → -8 (median 1); b -60" in line
    assert "the first-ranked ΔBIC of the 1 other draws moved by at most 1.5" in line
    assert "In b the pair moved the baseline's objectives by at most 0.0020" in line


def test_candidate_baseline_lines_by_hand():
    """A made-up gap_candidate_baseline result: medians and first-ranked ΔBIC, both ways."""
    from gaitlib.studies import gap as G

    def x(first, med, n=3):
        return {"rank1": "k", "rank1_dBIC": first, "median_dBIC": med, "ranked": n}

    r = {"draws": [{"one_baseline": x(-100.0, -80.0), "own_baseline": x(-150.0, -2.0)},
                   {"one_baseline": x(-10.0, 3.0), "own_baseline": x(-30.0, -25.0)},
                   {"one_baseline": x(None, None, 0), "own_baseline": x(None, None, 0)}]}
    (line,) = G.candidate_baseline_lines(r)
    assert "(`benchmarks/gap_candidate_baseline.py`, 3 draws, ranking only)" in line
    assert "fell within -25 to -2 (against the one baseline: -80 to 3; ≤ -20 in 1 draws against 1)" in line
    assert "the first-ranked ΔBIC spread to -150 to -30 (against -100 to -10)" in line


def test_a_failed_baseline_is_named_so_among_the_ranking_misses():
    """An independent middle injection whose baseline fit failed (nothing ranked) is listed as
    that, in the table and in the sentence — not as 'another effect ranked first'."""
    from gaitlib.studies import gap as G

    nan = float("nan")
    rows = V.pd.DataFrame({"set": ["independent"] * 2, "band": ["middle", "large"], "case": ["k_m", "k_l"],
                           "expected": ["knee_offset"] * 2, "magnitude": [3.0, 7.0],
                           "named": ["knee_offset", "baseline failed"], "rank1": ["knee_offset", nan],
                           "rank1_dBIC": [-80.0, nan], "rank2": ["hip_offset", nan], "rank2_dBIC": [-5.0, nan],
                           "expected_rank": [1, nan], "contenders": [["knee_offset"], []],
                           "correct": [True, False], "verdict": ["explained", "baseline failed"]})
    v = V.Validation(rows, {"null_calibration": {"lowest_dBIC": -30.0}}, {"relative": True})
    m = G.ranking_misses({"r": v})
    assert list(m["case"]) == ["k_l"] and m.iloc[0]["why"] == "baseline fit failed: nothing ranked"
    (line,) = G.threshold_lines({"r": v})
    assert "k_l (r): the baseline fit failed, nothing ranked" in line


def test_pair_counts_reads_the_located_pairs_of_cases_and_null_draws():
    """studies.gap.pair_counts: per set, the cases whose baseline / first-ranked candidate
    were located on the continuation pair; the calibration's draws alike; NaN where a
    validation did not record them."""
    from gaitlib.gap.validate import Validation
    from gaitlib.studies import gap as gs

    rows = pd.DataFrame({"set": ["independent", "independent", "independent", "null"],
                         "baseline_pair": ["final", "continuation", "continuation", "final"],
                         "rank1_pair": ["continuation", "final", None, "continuation"]})
    calib = {"best": [{"draw": "null0", "pair": "continuation"}, {"draw": "null1", "pair": "final"},
                      {"draw": "null2", "effect": "baseline failed"}],
             "baseline_pair": {"null0": "final", "null1": "continuation"}}
    t = gs.pair_counts(Validation(rows, {"null_calibration": calib}, {}))
    assert t.loc["independent"].tolist() == [3, 2, 1]
    assert t.loc["null"].tolist() == [1, 0, 1]
    assert t.loc["null calibration draws"].tolist() == [3, 1, 1]
    old = gs.pair_counts(Validation(rows[["set"]], {}, {}))
    assert old["baseline on the continuation pair"].isna().all() and "null calibration draws" not in old.index


def test_case_change_lines_read_both_sides_of_a_paired_case():
    """studies.gap.case_change_lines: a failed baseline before, the named effect, its change
    (rad also in °), % closed, ΔBIC, fallback start and located pair after — every number
    from the two rows."""
    from gaitlib.gap.validate import Validation
    from gaitlib.studies import gap as gs

    common = {"case": "ankle_offset_middle_1", "injection": "ankle_offset", "magnitude": -2.73, "unit": "deg"}
    before = pd.DataFrame([{**common, "named": "baseline failed", "error": "baseline failed: warm X"}])
    after = pd.DataFrame([{**common, "named": "ankle_offset", "expected_effect": "ankle_offset",
                           "expected_change": "{'c': -0.05}", "expected_pct": 56.04, "expected_dBIC": -166.2,
                           "baseline_fallback": "reference fit of grf_scale", "rank1": "ankle_offset",
                           "rank1_pair": "continuation"}])
    (line,) = gs.case_change_lines(Validation(before, {}, {}), Validation(after, {}, {}), ["ankle_offset_middle_1"])
    assert "before, baseline failed (baseline failed: warm X)" in line
    assert f"c -0.05 rad ({math.degrees(-0.05):+.2f}°), 56 % closed, ΔBIC -166" in line
    assert "baseline from the reference fit of grf_scale; located on its continuation pair" in line


def test_share_floor_replay_by_hand():
    """A named effect below the floor on the share it closed is read "unexplained": the
    out-of-library case named with 15 % turns right at a 20 % floor, the injection named
    right with 40 % stays, the one named right with 12 % turns wrong; 0 is the method as is."""
    from gaitlib.studies import gap as G

    rows = V.pd.DataFrame({
        "case": ["a_middle_0", "b_large_0", "c_middle_0"], "set": ["independent", "independent", "out-of-library"],
        "band": ["middle", "large", "middle"], "expected": ["knee_offset", "ankle_offset", "unexplained"],
        "rank1": ["knee_offset", "ankle_offset", "hip_offset"], "rank1_pct": [40.0, 12.0, 15.0],
        "named": ["knee_offset", "ankle_offset", "hip_offset"], "correct": [True, True, False]})
    v = V.Validation(rows, {}, {"relative": True})
    assert G.with_share_floor(v, 0.0)["correct"].tolist() == [True, True, False]
    r = G.with_share_floor(v, 20.0)
    assert r["named"].tolist() == ["knee_offset", "unexplained", "unexplained"]
    assert r["correct"].tolist() == [True, False, True]
    sw = G.share_floor_sweep({"r0": v}, floors=(0.0, 13.0, 20.0))
    assert sw.loc[0.0, "independent, middle + large"] == "2/2 (100 %)" and sw.loc[0.0, "out-of-library"] == "0/1 (0 %)"
    assert sw.loc[13.0, "independent, middle + large"] == "1/2 (50 %)" and sw.loc[20.0, "out-of-library"] == "1/1 (100 %)"
    (line,) = G.share_floor_lines({"r0": v})
    assert "closed 15–15 % of their relative gap (c_middle_0 (r0): hip_offset 15 %)" in line
    assert "named right closed 12 % or more (the least: b_large_0, r0)" in line
    assert "a lead for the next revision" in line
    (line,) = G.share_floor_lines({"r0": v}, floor=20.0)
    assert "With a 20 % floor the same rankings give independent, middle + large 1/2 (50 %)" in line
    assert "out-of-library 1/1 (100 %)" in line and "lead" not in line


def test_named_at_replays_the_share_floor_of_the_validations_method():
    """From revision 9 a stored validation's own ``min_share_closed`` is part of the replayed
    rule: a first-ranked effect below it is "unexplained" at any threshold."""
    from gaitlib.studies import gap as G

    rows = V.pd.DataFrame({
        "case": ["a_middle_0", "c_middle_0"], "set": ["independent", "out-of-library"], "band": ["middle", "middle"],
        "expected": ["knee_offset", "unexplained"], "rank1": ["knee_offset", "hip_offset"],
        "rank1_dBIC": [-40.0, -35.0], "rank1_pct": [40.0, 15.0], "contenders": [["knee_offset"], ["hip_offset"]],
        "verdict": ["partial", "unexplained"], "named": ["knee_offset", "unexplained"], "correct": [True, True]})
    v9 = V.Validation(rows, {}, {"relative": True, "relative_method": {"min_share_closed": 20.0}})
    v8 = V.Validation(rows, {}, {"relative": True, "relative_method": {}})
    assert G.named_at(v9, -30)["named"].tolist() == ["knee_offset", "unexplained"]
    assert G.named_at(v8, -30)["named"].tolist() == ["knee_offset", "hip_offset"]


def test_share_floor_replay_reads_back_what_the_validations_own_floor_held():
    """A validation made with a floor (revision 9) stores the held case as "unexplained"; the
    replay reads it back from the ranking: named again without the floor (0), held again at
    the floor; a case outside the threshold or with a runner-up in the margin stays
    "unexplained" at any floor; :func:`floor_held_lines` names the held case and the counts."""
    from gaitlib.studies import gap as G

    rows = V.pd.DataFrame({
        "case": ["a_middle_0", "c_middle_0", "d_large_0", "e_large_0"],
        "set": ["independent", "out-of-library", "out-of-library", "out-of-library"],
        "band": ["middle", "middle", "large", "large"],
        "expected": ["knee_offset", "unexplained", "unexplained", "unexplained"],
        "rank1": ["knee_offset", "hip_offset", "hip_offset", "grf_scale"],
        "rank1_dBIC": [-60.0, -45.0, -30.0, -80.0], "rank1_pct": [40.0, 15.0, 12.0, 10.0],
        "threshold_used": [-38.0] * 4,
        "contenders": [["knee_offset"], ["hip_offset"], ["hip_offset"], ["grf_scale", "body_mass"]],
        "verdict": ["partial", "unexplained", "unexplained", "unexplained"],
        "named": ["knee_offset", "unexplained", "unexplained", "unexplained"], "correct": [True, True, True, True]})
    v9 = V.Validation(rows, {}, {"relative": True, "relative_method": {"min_share_closed": 20.0}})
    assert G._floor_held(v9).tolist() == [False, True, False, False]
    assert G.with_share_floor(v9, 0.0)["named"].tolist() == ["knee_offset", "hip_offset", "unexplained", "unexplained"]
    assert G.with_share_floor(v9, 14.0)["named"].tolist()[1] == "hip_offset"
    assert G.with_share_floor(v9, 20.0)["named"].tolist() == rows["named"].tolist()
    sw = G.share_floor_sweep({"r9": v9}, (0.0, 20.0))
    assert sw.loc[0.0, "out-of-library"] == "2/3 (67 %)" and sw.loc[20.0, "out-of-library"] == "3/3 (100 %)"
    (line,) = G.floor_held_lines(v9, "revision 9")
    assert "floor held 1 case" in line and "c_middle_0 (hip_offset, ΔBIC -45, 15 % closed; right answer unexplained)" in line
    assert "out-of-library 2/3 (67 %) → 3/3 (100 %)" in line
    assert G.floor_held_lines(V.Validation(rows, {}, {"relative": True, "relative_method": {}}), "r8") == []


def test_the_centred_replay_decides_on_the_top_effect_minus_the_median_candidate():
    """Revision 10's statistic replayed on stored rankings, by hand: a case whose candidates
    all gained alike (the common mode) passes a raw threshold but not the centred one; a case
    where one effect stands out passes both; the runner-up margin is recomputed from the
    ranking (the stored contenders are empty where nothing passed the case's threshold), and
    the calibration's thresholds come from its null draws on each statistic."""
    from gaitlib.studies import gap as G

    common = {"grf_scale": -300.0, "body_mass": -280.0, "hip_offset": -270.0}  # median -280: centred -20
    alone = {"knee_offset": -60.0, "hip_offset": -5.0, "grf_scale": 0.0}  # median -5: centred -55
    tied = {"grf_scale": -100.0, "body_mass": -95.0, "hip_offset": 0.0}  # runner-up within 10
    rows = V.pd.DataFrame({
        "case": ["a_middle_0", "b_middle_0", "c_large_0"], "set": ["independent", "out-of-library", "independent"],
        "band": ["middle", "middle", "large"], "expected": ["knee_offset", "unexplained", "body_mass"],
        "rank1": ["knee_offset", "grf_scale", "grf_scale"], "rank1_dBIC": [-60.0, -300.0, -100.0],
        "rank1_pct": [40.0, 70.0, 50.0], "dBIC": [alone, common, tied], "contenders": [[], [], []],
        "pct_closed": [{"knee_offset": 40.0, "hip_offset": 2.0, "grf_scale": 0.0},
                       {"grf_scale": 70.0, "body_mass": 60.0, "hip_offset": 55.0},
                       {"grf_scale": 50.0, "body_mass": 45.0, "hip_offset": 1.0}],
        "verdict": ["unexplained"] * 3, "named": ["unexplained"] * 3, "correct": [False, True, False]})
    null = [{"a": -50.0, "b": -20.0, "c": -25.0}, {"a": -8.0, "b": 0.0, "c": 1.0}, {"a": -30.0, "b": 2.0, "c": 0.0}]
    # raw statistics -50, -8, -30 (second lowest -30); centred -25, -8, -30 (second lowest -25)
    v = V.Validation(rows, {"null_calibration": {"dBIC": null, "rank": 2, "threshold_dBIC": -30.0}},
                     {"relative": True, "relative_method": {"min_share_closed": 20.0}})
    assert G.case_statistic(v).tolist() == [-60.0, -300.0, -100.0]
    assert G.case_statistic(v, centred=True).tolist() == [-55.0, -20.0, -5.0]
    assert G._lone(v).tolist() == [True, True, False]
    assert G.replayed_threshold(v) == -25.0 and G.calibration_threshold(v) == -30.0
    assert G.replayed_threshold(v, centred=False) == -30.0
    assert G.named_at(v, -30.0)["named"].tolist() == ["knee_offset", "grf_scale", "unexplained"]
    assert G.named_at(v, -30.0, centred=True)["named"].tolist() == ["knee_offset", "unexplained", "unexplained"]
    # shares of what the median candidate leaves: a (40 - 5 ... ) by hand from pct_closed
    assert G.case_share(v).tolist() == [40.0, 70.0, 50.0]
    assert np.allclose(G.case_share(v, centred=True), [100 * (40 - 2) / 98, 100 * (70 - 60) / 40, 100 * (50 - 45) / 55])
    assert G.named_at(v, -30.0, centred=True, floor=30.0)["named"].tolist() == ["knee_offset", "unexplained",
                                                                                "unexplained"]
    assert G.named_at(v, -30.0, centred=True, floor=39.0)["named"].tolist() == ["unexplained"] * 3
    t = G.centred_replay({"r": v})
    assert t.loc[("r", "raw ΔBIC"), "out-of-library"] == "0/1" and t.loc[("r", "centred"), "out-of-library"] == "1/1"
    assert t.loc[("r", "centred"), "threshold"] == -25.0 and t.loc[("r", "raw ΔBIC"), "threshold"] == -30.0
    assert t.loc[("r", "centred"), "independent, middle + large"] == "1/2"  # c: runner-up within the margin
    (line,) = G.centred_lines({"r": v})
    assert "out-of-library 0/1 (0 %) → 1/1 (100 %)" in line and "b_middle_0" not in line.split("to a wrong one")[-1]


def test_the_revision_table_reads_each_validation_as_it_decided():
    """One row per stored relative validation: its revision and change, its set of draws, its
    calibration's threshold (the fixed one without a calibration), its common-mode null
    draws counted by hand, and named right per target group from its stored verdicts."""
    from gaitlib.studies import gap as G

    rows = V.pd.DataFrame({"set": ["independent", "out-of-library", "null"], "band": ["large", "middle", "none"],
                           "expected": ["knee_offset", "unexplained", "unexplained"],
                           "named": ["knee_offset", "hip_offset", "unexplained"], "correct": [True, False, True]})
    calib = {"dBIC": [{"a": -40.0, "b": -30.0, "c": -25.0}, {"a": -12.0, "b": 0.0, "c": 3.0}], "rank": 2,
             "threshold_dBIC": -12.0}  # medians -30 (common-mode) and 0
    v = V.Validation(rows, {"null_calibration": calib}, {"relative": True, "replicate": 1})
    t = G.revision_table({"r": (10, v), "r0": (0, V.Validation(rows, {}, {"relative": True}))})
    assert t.loc["r", "threshold (ΔBIC ≤)"] == "-12" and t.loc["r", "common-mode null draws"] == "1/2"
    assert t.loc["r", "draws"] == 1 and t.loc["r", "change"] == G.REVISION_CHANGES[10]
    assert t.loc["r", "independent, middle + large"] == "1/1" and t.loc["r", "out-of-library"] == "0/1"
    assert t.loc["r0", "threshold (ΔBIC ≤)"] == "-10 (fixed)" and t.loc["r0", "common-mode null draws"] == "—"


def test_a_validation_cut_short_resumes_from_its_checkpoint_to_the_same_result(tmp_path, monkeypatch):
    """validate.run(checkpoint=...) rewrites the finished cases after each; a rerun takes them
    (and the relative run's null calibration) from it and diagnoses only the rest — the
    result equals an uninterrupted run's. The diagnosis is replaced by a stand-in whose answer
    is a function of the case's data alone (the real one is exercised by the stored runs)."""
    from types import SimpleNamespace

    calls, ever, given = [], [0], []

    def diag(ds, base=None, resamples=0, reference=None, calibration=None, **kw):
        calls.append(Path(ds.path).stem)
        given.append(calibration is not None)
        ever[0] += 1  # a calibration computed afresh by the resumed run would differ
        if len(calls) > limit[0]:
            raise KeyboardInterrupt  # the session ends
        return SimpleNamespace(settings={"threshold_used": -30.0, "reference": {
            "null_calibration": calibration or {"dBIC": [{"a": -5.0 - ever[0], "b": -1.0}], "rank": 1},
            "moved": {}, "rss_reference": 100.0}}, reference_fit=None, data=ds)

    def summary(d, expected=None):  # depends on the case's data only
        m = d.data.gait.mean
        return {"named": "unexplained", "verdict": "unexplained",
                "rss_baseline": float(np.round(np.nansum(np.abs(m.to_numpy(dtype=float))), 6))}

    monkeypatch.setattr(V.diagnose, "diagnose", diag)
    monkeypatch.setattr(V, "_summary", summary)
    monkeypatch.setattr(V.locate, "locate", lambda fit, data: SimpleNamespace(rss=1.0))
    kw = dict(sets=("independent", "null"), relative=True, work_dir=tmp_path / "w")
    limit = [10**6]
    whole = V.run(**kw)
    n = len(whole.rows)
    assert len(calls) == n
    calls.clear()
    ck = tmp_path / "ck" / "partial.json"
    limit, ever[0] = [5], 0  # the same first calibration as the whole run's; not reset for the resumed run
    with pytest.raises(KeyboardInterrupt):
        V.run(checkpoint=ck, **kw)
    j = json.loads(ck.read_text())
    assert j["settings"]["partial"] is True and len(j["rows"]) == 5
    first = list(calls[:5])
    calls.clear()
    given.clear()
    limit = [10**6]
    resumed = V.run(checkpoint=ck, **kw)
    assert len(calls) == n - 5 and not set(calls) & set(first)  # only the rest diagnosed
    assert all(given)  # each with the checkpoint's null calibration
    a, b = whole.to_dict(), resumed.to_dict()
    assert a == b  # every row, the unedited record (calibration included) and the settings
    with pytest.raises(ValueError, match="checkpoint of other settings .*per_band"):
        V.run(checkpoint=ck, per_band=2, **kw)
