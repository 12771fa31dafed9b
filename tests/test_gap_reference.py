"""A change relative to a reference data set (gaitlib.gap.reference): N' = S_R + (N − R),
checked by hand on a synthetic reference fit, and the refusals before any solve."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest

from gaitlib import conventions as cv
from gaitlib.gap import diagnose as D
from gaitlib.gap import io as gio
from gaitlib.gap import locate as L
from gaitlib.gap import reference as R
from gaitlib.gap import validate as V
from gaitlib.problems import gait as gait_ocp


@pytest.fixture(scope="module")
def frame():
    return V.real_frame("Free")


def _ds(tmp_path, df, name):
    p = tmp_path / f"{name}.csv"
    df.to_csv(p, index=False)
    return gio.read_data(p)


@pytest.fixture(scope="module")
def ref(frame, tmp_path_factory):
    return _ds(tmp_path_factory.mktemp("r"), frame, "reference")


def _fake_fit(columns, n=40):
    """A reference 'fit' as a sim_channels frame: smooth periodic curves on τ = k/n, one per
    channel (distinct amplitudes and phases), plus a pelvic tilt and a residual column."""
    tau = np.arange(n) / n
    out = {c: (1.0 + 0.1 * i) * np.sin(2 * np.pi * (tau + 0.07 * i)) for i, c in enumerate(columns)}
    out["pelvis_tilt"] = np.full(n, 0.2)
    out["res_R_x"] = np.zeros(n)
    return pd.DataFrame(out, index=pd.Index(tau, name="tau"))


CHANNELS = list(gait_ocp.LEG_JOINTS) + [f"tau_{j}" for j in gait_ocp.LEG_JOINTS] + list(gait_ocp.GRF_CHANNELS)


def _at(sim, c, t):
    ts = sim.index.to_numpy(float)
    return np.interp(t, np.concatenate([ts - 1, ts, ts + 1]), np.tile(sim[c].to_numpy(), 3))


def test_the_reference_fit_has_no_gap_relative_to_its_own_data(ref):
    """N = R: the located gap of S_R against N' = R + (S_R − R) is zero on every channel the
    fit simulates; the fits' data (N) are untouched."""
    sim = _fake_fit(CHANNELS)
    rel = R.relative_data(ref, ref, sim)
    assert rel.gait is ref.gait and rel.background is not None
    loc = L.locate(sim, rel)
    assert set(loc.channels["name"]) >= {"hip_r", "knee_l", "ankle_r", "grf_y_l"}
    assert np.allclose(loc.points["z"], 0.0, atol=1e-9)
    assert L.locate(sim, ref).rss > 1.0  # without the background: the fake fit's misfit
    assert R.offset_channels(ref.gait, sim) == CHANNELS + ["pelvis_tilt"]
    assert R.offset_channels(ref.gait, sim, tilt=False) == CHANNELS


def test_the_hat_tilt_is_located_only_relative_to_a_reference(ref):
    """Relative, the HAT tilt is a located channel (side "-", the right leg's phases): a fit
    whose HAT tilts by Δ more than the reference's fit, on unchanged data, shows z = Δ/SD*
    there and nowhere else; absolute (no background) it is not located, and without
    ``tilt`` it carries no background."""
    sim = _fake_fit(CHANNELS)
    rel = R.relative_data(ref, ref, sim)
    tilted = sim.copy()
    tilted["pelvis_tilt"] += 0.05
    pts = L.locate(tilted, rel).points
    tilt = pts["channel"] == "angle:pelvis_tilt"
    assert tilt.sum() == L.N_GRID and set(pts.loc[tilt, "side"]) == {"-"}
    assert np.allclose(pts.loc[tilt, "z"], 0.05 / pts.loc[tilt, "sd_eff"], atol=1e-9)
    assert np.allclose(pts.loc[~tilt, "z"], 0.0, atol=1e-9)
    assert "angle:pelvis_tilt" not in set(L.locate(tilted, ref).points["channel"])
    assert "pelvis_tilt" not in R.background(ref, sim, tilt=False).columns


def test_quiet_points_are_left_out_of_a_relative_location(ref):
    """Revision 6: where neither the data nor the reference have variance (both SDs below the
    floor: each foot's GRF in its swing) a fit's change is not located — a swing-foot load
    that appears only in the fit of the data adds nothing; the same load in stance does
    (by hand: z = load / SD*). The points left out are exactly those with SD < floor in
    both; the angle channels keep all 50; absolute, nothing is left out."""
    sim = _fake_fit(CHANNELS, n=L.N_GRID)  # on locate's grid: a change at a grid point stays there
    rel = R.relative_data(ref, ref, sim)
    assert rel.reference_sd is not None and list(rel.reference_sd.columns) == list(rel.background.columns)
    grid = np.arange(L.N_GRID) / L.N_GRID
    loc0 = L.locate(sim, rel)
    pts0 = loc0.points
    kept = pts0.loc[pts0["channel"] == "grf:grf_y_r", "tau"].to_numpy()
    quiet = ~np.isin(np.round(grid, 9), np.round(kept, 9))
    t_data = np.asarray(ref.gait.time, float) / float(ref.gait.cycle_time)
    sd = np.interp(grid, t_data, ref.gait.sd["grf_y_r"].to_numpy())
    assert np.array_equal(quiet, sd < L.SD_FLOOR * np.sqrt(np.mean(sd**2))) and quiet.sum() >= 5  # the swing
    assert (pts0[pts0["kind"] == "angle"].groupby("channel").size() == L.N_GRID).all()
    assert loc0.channels.set_index("channel").loc["grf:grf_y_r", "n"] == L.N_GRID - quiet.sum()
    # a 40 N load added to the fit on the quiet points only: not located
    loaded = sim.copy()
    loaded["grf_y_r"] = sim["grf_y_r"].to_numpy() + 40.0 * quiet
    assert L.locate(loaded, rel).rss == pytest.approx(loc0.rss, abs=1e-9)
    # on stance points it is: z = 40 / SD* there, by hand
    stance = sim.copy()
    k = int(np.flatnonzero(~quiet)[0])
    stance.iloc[k, stance.columns.get_loc("grf_y_r")] += 40.0
    p = L.locate(stance, rel).points
    zk = p.loc[(p["channel"] == "grf:grf_y_r") & np.isclose(p["tau"], grid[k]), ["z", "sd_eff"]].iloc[0]
    assert zk["z"] == pytest.approx(40.0 / zk["sd_eff"], rel=1e-9)
    # the same fit located absolutely sees it
    assert L.locate(loaded, ref).rss > L.locate(sim, ref).rss
    # without the reference's SD (quiet_points off): every point counts
    import dataclasses as dc
    assert L.locate(sim, dc.replace(rel, reference_sd=None)).channels["n"].eq(L.N_GRID).all()


def test_resels_with_points_left_out():
    """Kept points only: a curve whose kept half is a smooth sine keeps that half's
    roughness (the pairs across the gap do not count) and scales with the points kept."""
    tau = np.arange(50) / 50
    z = np.sin(2 * np.pi * tau)
    keep = np.ones(50, bool)
    assert L.resels(z, keep) == pytest.approx(L.resels(z), rel=1e-12)
    noisy = z.copy()
    noisy[25:] = np.where(np.arange(25) % 2 == 0, 5.0, -5.0)  # a rough half, left out
    keep[25:] = False
    r_half = L.resels(noisy, keep)
    # by hand: λ = mean of the 24 kept pairs' squared steps × 25 / Σ(z − z̄)² over the 25 kept points
    zk = z[:25]
    lam = np.mean(np.diff(zk) ** 2) * 25 / np.sum((zk - zk.mean()) ** 2)
    assert r_half == pytest.approx(25 / np.sqrt(4 * np.log(2) / lam), rel=1e-12)
    assert r_half < L.resels(noisy)


def test_background_is_the_fits_residual_by_hand(ref):
    """S_R − R on the data grid: the hip as the thigh in the laboratory (data hip + pelvic
    tilt), the rest as the data."""
    sim = _fake_fit(CHANNELS)
    bg = R.background(ref, sim)
    t = np.asarray(ref.gait.time, float) / float(ref.gait.cycle_time)
    m = ref.gait.mean
    assert np.allclose(bg["hip_r"], _at(sim, "hip_r", t) - (m["hip_r"] + m["pelvis_tilt"]), atol=1e-12)
    assert np.allclose(bg["tau_knee_l"], _at(sim, "tau_knee_l", t) - m["tau_knee_l"], atol=1e-12)
    assert list(bg.index) == list(m.index)


def test_a_marker_offset_shows_alone_and_its_effect_closes_it(tmp_path, frame, ref):
    """A knee offset of +3° on the data's knee (both legs, through the reader): at the
    reference's fit the relative gap is −c/SD* on the knee and zero elsewhere, and the knee
    offset effect at c closes it exactly."""
    sim = _fake_fit(CHANNELS)
    new = _ds(tmp_path, V.inject(frame, "knee_offset", 3.0), "knee")
    rel = R.relative_data(new, ref, sim)
    c = cv.DATA_SIGN["knee"] * math.radians(3.0)
    pts = L.locate(sim, rel).points
    knee = pts["channel"].isin(["angle:knee_r", "angle:knee_l"])
    assert np.allclose(pts.loc[knee, "z"], -c / pts.loc[knee, "sd_eff"], atol=1e-9)
    assert np.allclose(pts.loc[~knee, "z"], 0.0, atol=1e-9)
    assert np.allclose(L.locate(sim, rel, thetas={"knee_offset": {"c": c}}).points["z"], 0.0, atol=1e-9)


def test_subjects_of_a_difference_of_two_means():
    # 1/(1/83 + 1/83) = 41.5 → 42 (round half to even); 1/(1/10 + 1/40) = 8
    assert R.relative_n(83, 83) == 42
    assert R.relative_n(10, 40) == 8
    assert R.relative_n(1, 1) == 1
    with pytest.raises(ValueError, match="subjects"):
        R.relative_n(0, 5)


def test_relative_data_are_labelled_with_both_and_their_subjects(ref):
    rel = R.relative_data(ref, ref, _fake_fit(CHANNELS))
    assert rel.n == R.relative_n(ref.n, ref.n)
    assert ref.label in rel.label and "difference of two group means" in rel.n_source
    assert any(n.startswith("located relative to") for n in rel.notes)


def test_another_speed_class_is_refused_before_any_solve(ref, monkeypatch):
    slow = gio.load_real("Slow")
    with pytest.raises(ValueError, match="cycle time"):
        R.check_same_grid(slow, ref)

    def no_solve(*a, **k):
        raise AssertionError("a solve was started")

    monkeypatch.setattr(D, "baseline_fits", no_solve)
    with pytest.raises(ValueError, match="same speed class"):
        D.diagnose(slow, base=dict(speed_class="Slow", n_intervals=4, degree=2), reference=ref, serial=True)


def test_a_null_draw_is_the_reference_plus_its_sampling_error(ref):
    """Every right-leg channel moves by SD/√n · g (|g| of unit variance: a few SDs/√n at
    most), the left leg is regenerated from the right (the reader's generation), SDs are
    unchanged, a seed gives the same draw and another seed another."""
    from gaitlib import effects as E

    n = 41
    a, b, c = R.null_draw(ref, n, 5), R.null_draw(ref, n, 5), R.null_draw(ref, n, 6)
    assert np.array_equal(a.gait.mean.to_numpy(), b.gait.mean.to_numpy())
    assert not np.allclose(a.gait.mean.to_numpy(), c.gait.mean.to_numpy())
    assert np.array_equal(a.gait.sd[["knee_r", "grf_y_r"]].to_numpy(), ref.gait.sd[["knee_r", "grf_y_r"]].to_numpy())
    assert E.left_generated(ref.gait) and E.left_generated(a.gait)
    for col in ("knee_r", "tau_ankle_r", "grf_y_r", "pelvis_tilt"):
        z = (a.gait.mean[col] - ref.gait.mean[col]) / (ref.gait.sd[col] / np.sqrt(n))
        assert 0.05 < float(np.std(z)) and float(np.max(np.abs(z))) < 5.0, col
    with pytest.raises(ValueError, match="subjects"):
        R.null_draw(ref, 0, 1)
    assert R.null_seed(ref, 0, "h") != R.null_seed(ref, 1, "h") and R.null_seed(ref, 0, "h") == R.null_seed(ref, 0, "h")


def test_the_relative_method_names_itself_and_the_absolute_one():
    from gaitlib.gap import method as M

    assert M.RELATIVE.null_draws >= 1 and M.RELATIVE.revision == 10 and M.RELATIVE.min_share_closed > 0 and M.RELATIVE.baseline_fallback and M.RELATIVE.lowest_pair and M.RELATIVE.tilt_channel and M.RELATIVE.reference_rounds >= 1
    h = M.RELATIVE.hash()
    assert len(h) == 16 and h != M.METHOD.hash()
    assert M.RelativeMethod(null_draws=3).hash() != h and M.RelativeMethod(null_rank=1).hash() != h
    assert M.RelativeMethod(quiet_points=False).hash() != h and M.RELATIVE.quiet_points
    assert M.RelativeMethod(reference_from_candidates=False).hash() != h and M.RELATIVE.reference_from_candidates
    with pytest.raises(dataclasses.FrozenInstanceError):
        M.RELATIVE.null_draws = 1


def test_the_null_threshold_is_the_rank_th_lowest_draw_statistic():
    """Revision 5's rule by hand: each draw's statistic is its lowest ΔBIC over candidates;
    the threshold the r-th lowest statistic; unranked draws carry none; a calibration stored
    before revision 5 keeps its own rule (the lowest)."""
    from gaitlib.gap import diagnose as D
    from gaitlib.gap import method as M

    per = [{"a": -5.0, "b": -82.0}, {}, {"a": 3.0}, {"b": -30.0, "c": -12.0}, {"c": -20.0}]
    # statistics: -82, 3, -30, -20 -> sorted -82, -30, -20, 3
    assert M.null_threshold(per, 1) == -82.0 and M.null_threshold(per, 2) == -30.0
    assert M.null_threshold(per, 9) == 3.0 and M.null_threshold([{}, {}], 2) is None
    assert D.calibration_dBIC({"lowest_dBIC": -82.0}) == -82.0
    assert D.calibration_dBIC({"lowest_dBIC": -82.0, "threshold_dBIC": -30.0}) == -30.0
    assert D.calibration_dBIC(None) is None
    assert M.RELATIVE.null_rank / (M.RELATIVE.null_draws + 1) <= 0.1 + 1e-12


def test_a_calibration_of_another_reference_is_refused(ref, monkeypatch):
    """diagnose(calibration=…) checks the calibration was made for this reference, spec,
    candidates and subjects before using it (after the reference's fits, which are faked)."""
    class FakeSol:
        stats = {"status": "Solve_Succeeded", "objective": 1.0, "iterations": 1}

    monkeypatch.setattr(D, "baseline_fits", lambda spec0, sets, warm, **k: {
        key: {"best": FakeSol(), "warm": FakeSol()} for key in sets})
    monkeypatch.setattr(D, "candidate_fits", lambda spec0, sets, bases, names, **k: {key: {} for key in sets})
    monkeypatch.setattr(D.locate, "locate", lambda *a, **k: type("L", (), {"rss": 1.0})())
    bad = {"relative_method_hash": "x" * 16}
    with pytest.raises(ValueError, match="another relative_method_hash"):
        D.diagnose(ref, reference=ref, calibration=bad, serial=True)


class _Sol:
    def __init__(self, objective, tag, status="Solve_Succeeded"):
        self.stats = {"status": status, "objective": objective, "effects": {}}
        self.tag = tag


def test_the_reference_fit_is_made_self_consistent(ref, monkeypatch):
    """consistent_fits on made-up solves: each model's reference fit is re-solved from its
    data fit and replaced only when lower by more than the margin; the data are then
    continued again and the lower data fit kept; a second round re-solves only the models
    whose data fit moved; a profile candidate is never re-solved."""
    from gaitlib.gap import method as M

    R_ = {"baseline": _Sol(1.0, "R0"), "knee_offset": _Sol(0.9, "Rk"), "hip_offset": _Sol(0.8, "Rh"),
          "ankle_offset": _Sol(0.7, "Ra")}
    N_ = {"baseline": _Sol(2.0, "N0"), "knee_offset": _Sol(1.9, "Nk"), "hip_offset": _Sol(1.8, "Nh"),
          "ankle_offset": _Sol(1.7, "Na")}
    # what a solve returns: (R or N side, model, round) → objective
    table = {("R", "baseline", 1): 0.95, ("N", "baseline", 1): 1.99,   # both lower: moved, then round 2
             ("R", "baseline", 2): 0.95,                                # round 2: the same optimum
             ("R", "knee_offset", 1): 0.85, ("N", "knee_offset", 1): 1.95,  # reference lower, data not
             ("R", "hip_offset", 1): 0.81,                              # higher: kept
             ("R", "ankle_offset", 1): 0.7 * (1 - 1e-8)}                # within the margin: kept
    calls = []

    def fake_solve_many(groups, **kw):
        out = {}
        for g, (spec, jobs) in groups.items():
            side = "R" if g.startswith("consistency-R-") else "N"
            m = g.split("-", 2)[2]
            rnd = 1 + sum(1 for c in calls if c[:2] == (side, m))
            calls.append((side, m, rnd))
            assert [e for e, _ in spec.effects] == ([] if m == "baseline" else [m])
            for key, gait, warm in jobs:
                assert warm is not None
                out[key] = _Sol(table[(side, m, rnd)], f"{side}{m}{rnd}")
        return out

    monkeypatch.setattr(D, "solve_many", fake_solve_many)
    monkeypatch.setattr(D.locate, "locate", lambda *a, **k: None)
    names = ["knee_offset", "hip_offset", "ankle_offset", "co_contraction"]
    fit = lambda n, s: D.Fit(n, s, {}, None, 1, "nlp", "Solve_Succeeded", True)  # noqa: E731
    ref_fits = {n: fit(n, R_[n]) for n in names[:3]}
    fits = {"data": {n: fit(n, N_[n]) for n in names[:3]}}
    spec0 = D.base_spec(dict(n_intervals=4, degree=2))
    out = D.consistent_fits(spec0, ref, R_["baseline"], ref_fits, {"data": ref}, {"data": N_["baseline"]}, fits,
                            names, method=M.RelativeMethod(reference_rounds=2, baseline_from_candidates=False))["data"]
    assert out["ref_fit"].tag == "Rbaseline1" and out["base"].tag == "Nbaseline1"
    assert out["ref_fits"]["knee_offset"].solution.tag == "Rknee_offset1"
    assert out["ref_fits"]["knee_offset"].start == "data"
    assert out["fits"]["knee_offset"].solution is N_["knee_offset"]  # its continuation was not lower
    assert out["ref_fits"]["hip_offset"].solution is R_["hip_offset"]
    assert out["ref_fits"]["ankle_offset"].solution is R_["ankle_offset"]
    assert out["moved"] == {"baseline": {"reference": [1.0, 0.95], "data": [2.0, 1.99]},
                            "knee_offset": {"reference": [0.9, 0.85]}}
    assert sorted(calls) == sorted([("R", "baseline", 1), ("R", "knee_offset", 1), ("R", "hip_offset", 1),
                                    ("R", "ankle_offset", 1), ("N", "baseline", 1), ("N", "knee_offset", 1),
                                    ("R", "baseline", 2)])
    assert ref_fits["knee_offset"].solution is R_["knee_offset"]  # the caller's fits are not changed
    calls.clear()
    off = D.consistent_fits(spec0, ref, R_["baseline"], ref_fits, {"data": ref}, {"data": N_["baseline"]}, fits,
                            names, method=M.RelativeMethod(reference_rounds=0, baseline_from_candidates=False))["data"]
    assert calls == [] and off["ref_fit"] is R_["baseline"] and off["moved"] == {}


def test_the_baseline_is_refitted_from_the_nested_candidates_fits(ref, monkeypatch):
    """baseline_from_candidates: the baseline's data fit re-solved (baseline spec) from each
    nested NLP candidate's converged data fit; the lowest replaces the continuation only if
    lower by more than the margin, and its source is recorded."""
    from gaitlib.gap import method as M

    seen = []

    def fake_solve_many(groups, **kw):
        ((g, (spec, jobs)),) = groups.items()
        assert g == "consistency-N-baseline-from" and spec.effects == ()
        seen.extend(key for key, _, _ in jobs)
        obj = {"data|knee_offset": 1.5, "data|hip_offset": 1.2, "other|knee_offset": 2.0 * (1 - 1e-9)}
        return {key: _Sol(obj[key], key) for key, _, _ in jobs}

    monkeypatch.setattr(D, "solve_many", fake_solve_many)
    monkeypatch.setattr(D.locate, "locate", lambda *a, **k: None)
    fit = lambda n, s: D.Fit(n, s, {}, None, 1, "nlp", "Solve_Succeeded", True)  # noqa: E731
    fits = {"data": {"knee_offset": fit("knee_offset", _Sol(1.4, "k")), "hip_offset": fit("hip_offset", _Sol(1.1, "h")),
                     "ankle_offset": fit("ankle_offset", _Sol(1.0, "a", "Maximum_Iterations_Exceeded"))},
            "other": {"knee_offset": fit("knee_offset", _Sol(1.9, "k2"))}}
    bases = {"data": _Sol(2.0, "N0"), "other": _Sol(2.0, "N1")}
    spec0 = D.base_spec(dict(n_intervals=4, degree=2))
    out = D.consistent_fits(spec0, ref, _Sol(1.0, "R0"), {}, {"data": ref, "other": ref}, bases, fits,
                            ["knee_offset", "hip_offset", "ankle_offset", "co_contraction"],
                            method=M.RelativeMethod(reference_rounds=0))
    assert sorted(seen) == ["data|hip_offset", "data|knee_offset", "other|knee_offset"]  # not the unconverged one
    assert out["data"]["base"].tag == "data|hip_offset"
    assert out["data"]["moved"] == {"baseline": {"data": [2.0, 1.2], "data_from": "hip_offset"}}
    assert out["other"]["base"] is bases["other"] and out["other"]["moved"] == {}  # within the margin


def test_the_baseline_fit_of_the_reference_is_refitted_from_the_candidates_fits(ref, monkeypatch):
    """reference_from_candidates (revision 7): in a relative diagnosis the baseline's fit of
    the reference is re-solved (baseline spec) from each nested NLP candidate's converged fit
    of the reference, the lowest replaces the multistart's only if lower, and that fit — not
    the multistart's — is what the data are continued from and made consistent with."""
    from gaitlib.gap import method as M

    class Stop(Exception):
        pass

    multistart = _Sol(1.0, "R0")
    fit = lambda n, s: D.Fit(n, s, {}, None, 1, "nlp", "Solve_Succeeded", True)  # noqa: E731
    ref_fits = {"knee_offset": fit("knee_offset", _Sol(0.9, "k")), "hip_offset": fit("hip_offset", _Sol(0.8, "h")),
                "ankle_offset": fit("ankle_offset", _Sol(0.7, "a", "Maximum_Iterations_Exceeded"))}
    warm_of_data = []

    def fake_baseline_fits(spec0, datasets, warm, **kw):
        if "data" in datasets:
            warm_of_data.append(warm)
        return {k: {"best": multistart if k == "reference" else _Sol(2.0, "N0")} for k in datasets}

    def fake_solve_many(groups, **kw):
        ((g, (spec, jobs)),) = groups.items()
        assert g == "reference-baseline-from" and spec.effects == ()
        obj = objectives[0]  # not the unconverged ankle fit
        assert sorted(k for k, _, _ in jobs) == sorted(obj)
        return {key: _Sol(obj[key], key) for key, _, _ in jobs}

    def fake_consistent(spec0, ref_, ref_fit, *a, **kw):
        raise Stop(ref_fit)

    monkeypatch.setattr(D, "baseline_fits", fake_baseline_fits)
    monkeypatch.setattr(D, "candidate_fits", lambda spec0, datasets, *a, **kw: {
        k: (ref_fits if k == "reference" else {}) for k in datasets})
    monkeypatch.setattr(D, "solve_many", fake_solve_many)
    monkeypatch.setattr(D, "consistent_fits", fake_consistent)
    monkeypatch.setattr(D.locate, "locate", lambda *a, **k: type("L", (), {"rss": 0.0})())
    names = ["knee_offset", "hip_offset", "ankle_offset"]
    base = dict(n_intervals=4, degree=2)
    lower = {"reference|knee_offset": 0.95, "reference|hip_offset": 0.85}
    higher = {"reference|knee_offset": 1.05, "reference|hip_offset": 1.1}
    objectives = []
    for on, obj, want in ((True, lower, "reference|hip_offset"), (True, higher, "R0"), (False, lower, "R0")):
        objectives[:] = [obj]
        monkeypatch.setattr(D, "RELATIVE", M.RelativeMethod(reference_from_candidates=on))
        warm_of_data.clear()
        with pytest.raises(Stop) as got:
            D.diagnose(ref, reference=ref, effects=names, base=base, serial=True)
        assert got.value.args[0].tag == want
        assert warm_of_data[0].tag == want  # the data continued from it


def test_a_failed_baseline_continuation_falls_back_to_the_candidates_reference_fits(ref, monkeypatch):
    """fallback_baselines (revision 8): the baseline is solved on the data from each nested,
    converged candidate fit of the reference, the lowest converged kept and named; a key none
    of whose starts converges goes to the multistart without the warm start; a key nothing
    reaches is left out."""
    fit = lambda n, s: D.Fit(n, s, {}, None, 1, "nlp", s.stats["status"], True)  # noqa: E731
    ref_fits = {"knee_offset": fit("knee_offset", _Sol(0.9, "k")), "hip_offset": fit("hip_offset", _Sol(0.8, "h")),
                "ankle_offset": fit("ankle_offset", _Sol(0.7, "a", "Maximum_Iterations_Exceeded"))}
    solved, multi = [], []

    def fake_solve_many(groups, **kw):
        ((g, (spec, jobs)),) = groups.items()
        assert g == "baseline-fallback" and spec.effects == ()
        solved.extend((key, start.tag) for key, _, start in jobs)
        obj = {"A|knee_offset": 1.2, "A|hip_offset": 1.1, "B|knee_offset": None, "B|hip_offset": None,
               "C|knee_offset": None, "C|hip_offset": None}
        return {key: _Sol(obj[key], key) if obj[key] is not None else _Sol(9.0, key, "Infeasible_Problem_Detected")
                for key, _, _ in jobs}

    def fake_baseline_fits(spec0, datasets, warm, *, starts, **kw):
        assert warm is None and "warm" not in starts and set(starts) == set(D.BASELINE_STARTS) - {"warm"}
        multi.extend(datasets)
        return {k: (_Sol(1.5, "cold") if k == "B" else None) for k in datasets}

    monkeypatch.setattr(D, "solve_many", fake_solve_many)
    monkeypatch.setattr(D, "baseline_fits", lambda *a, **k: {
        k: (lambda s: (s.stats.update(start="coarse"), s)[1])(v) if v is not None else None
        for k, v in fake_baseline_fits(*a, **k).items()})
    names = ["knee_offset", "hip_offset", "ankle_offset", "body_mass"]
    out = D.fallback_baselines(D.base_spec(dict(n_intervals=4, degree=2)), {"A": ref, "B": ref, "C": ref},
                               {k: ref_fits for k in "ABC"}, names)
    # the unconverged ankle fit is no start; body_mass (not nested here) has no fit to start from
    assert sorted(t for _, t in solved) == sorted(["k", "h"] * 3)
    assert out["A"].tag == "A|hip_offset" and out["A"].stats["start"] == "reference fit of hip_offset"
    assert out["B"].stats["start"] == "multistart coarse" and sorted(multi) == ["B", "C"]
    assert "C" not in out


def test_the_relative_diagnosis_continues_from_the_fallback_baseline(ref, monkeypatch):
    """diagnose: a data baseline whose continuation fails is taken from fallback_baselines
    (baseline_fallback on) and named in the reference's settings; off, the diagnosis stops
    with BaselineFailed, as up to revision 7."""
    from gaitlib.gap import method as M

    class Stop(Exception):
        pass

    def fake_baseline_fits(spec0, datasets, warm, **kw):
        return {k: {"best": _Sol(1.0, "R0") if k == "reference" else None,
                    "warm": _Sol(3.0, "x", "Maximum_Iterations_Exceeded")} for k in datasets}

    def fake_fallback(spec0, datasets, ref_fits, names, **kw):
        assert list(datasets) == ["data"] and ref_fits["data"] is ref_fits_
        s = _Sol(2.0, "F")
        s.stats["start"] = "reference fit of hip_offset"
        return {"data": s}

    def fake_consistent(spec0, ref_, ref_fit, ref_fits, datasets, bases, *a, **kw):
        raise Stop(bases["data"])

    ref_fits_ = {}
    monkeypatch.setattr(D, "baseline_fits", fake_baseline_fits)
    monkeypatch.setattr(D, "candidate_fits", lambda spec0, datasets, *a, **kw: {
        k: (ref_fits_ if k == "reference" else {}) for k in datasets})
    monkeypatch.setattr(D, "fallback_baselines", fake_fallback)
    monkeypatch.setattr(D, "consistent_fits", fake_consistent)
    monkeypatch.setattr(D.locate, "locate", lambda *a, **k: type("L", (), {"rss": 0.0})())
    base = dict(n_intervals=4, degree=2)
    monkeypatch.setattr(D, "RELATIVE", M.RelativeMethod(reference_from_candidates=False))
    with pytest.raises(Stop) as got:
        D.diagnose(ref, reference=ref, effects=["hip_offset"], base=base, serial=True)
    assert got.value.args[0].tag == "F"
    monkeypatch.setattr(D, "RELATIVE", M.RelativeMethod(reference_from_candidates=False, baseline_fallback=False))
    with pytest.raises(D.BaselineFailed):
        D.diagnose(ref, reference=ref, effects=["hip_offset"], base=base, serial=True)


def test_the_lower_of_the_final_and_the_continuation_pair_is_located(ref, monkeypatch):
    """lowest_pair (revision 8): relative_fits locates each candidate's continuation pair
    beside its final one and keeps the lower RSS, with that pair's fits and reference
    parameters; continuation_pairs offers only converged continuations that are not the kept
    fit; lowest_baseline_pair does the same for the baseline."""
    rss = {("Rk", "Nk"): 5.0, ("Rk0", "Nk0"): 2.0, ("Rh", "Nh"): 1.0, ("Rh0", "Nh0"): 3.0,
           ("R0", "N0"): 4.0, ("R00", "N00"): 6.0}
    monkeypatch.setattr(D.gref, "background", lambda ref_, sol, thetas=None, tilt=None: sol.tag)
    monkeypatch.setattr(D.locate, "locate", lambda sol, ds, thetas=None: type(
        "L", (), {"rss": rss[(ds.background, sol.tag)]})())
    monkeypatch.setattr(D.gref, "relative_data", lambda ds, ref_, rf, tilt=None: dataclasses.replace(
        ds, background=rf.tag))

    def fit(n, tag, th, cont=None, status="Solve_Succeeded"):
        s = _Sol(1.0, tag, status)
        s.stats["effects"] = {n: {"c": th}}
        f = D.Fit(n, s, {n: {"c": th}}, None, 1, "nlp", status, True)
        f.continuation = cont
        return f

    def sol(tag, n, th, status="Solve_Succeeded"):
        s = _Sol(1.0, tag, status)
        s.stats["effects"] = {n: {"c": th}}
        return s

    ref_first = {"knee_offset": fit("knee_offset", "Rk0", 0.1), "hip_offset": fit("hip_offset", "Rh0", 0.2),
                 "ankle_offset": fit("ankle_offset", "Ra0", 0.3)}
    kept_hip = sol("Nh", "hip_offset", 0.25)
    data_first = {"knee_offset": fit("knee_offset", "Nk", 0.5, cont=sol("Nk0", "knee_offset", 0.4)),
                  "hip_offset": fit("hip_offset", "Nh", 0.25, cont=sol("Nh0", "hip_offset", 0.3)),
                  "ankle_offset": fit("ankle_offset", "Na", 0.3, cont=sol("Na0", "ankle_offset", 0.3,
                                                                          "Maximum_Iterations_Exceeded"))}
    alt = D.continuation_pairs(ref_first, data_first)
    assert sorted(alt) == ["hip_offset", "knee_offset"]  # the ankle's continuation did not converge
    data_first["knee_offset"].continuation = data_first["knee_offset"].solution
    assert "knee_offset" in D.continuation_pairs(ref_first, data_first)  # the rounds may have moved only R
    data_first["knee_offset"].continuation = alt["knee_offset"][0][2]
    final_ref = {"knee_offset": fit("knee_offset", "Rk", 0.45), "hip_offset": fit("hip_offset", "Rh", 0.2)}
    final = {"knee_offset": fit("knee_offset", "Nk", 0.5), "hip_offset": D.Fit("hip_offset", kept_hip,
                                                                              kept_hip.stats["effects"], None, 1,
                                                                              "nlp", "Solve_Succeeded", True)}
    out = D.relative_fits(final, final_ref, ref, ref, None, alt)
    k, h = out["knee_offset"], out["hip_offset"]
    assert (k.pair, k.start, k.located.rss, k.solution.tag) == ("continuation", "reference", 2.0, "Nk0")
    assert k.reference_thetas == {"knee_offset": {"c": 0.1}} and k.thetas == {"knee_offset": {"c": 0.4}}
    assert (h.pair, h.located.rss, h.solution.tag) == ("final", 1.0, "Nh")
    # the same data fit with the reference's first fit: a pair of its own; the final pair itself is not located again
    rss[("Rk0", "Nk")] = 0.5
    same = {"knee_offset": [("continuation", ref_first["knee_offset"], final["knee_offset"].solution)]}
    k = D.relative_fits(final, final_ref, ref, ref, None, same)["knee_offset"]
    assert (k.pair, k.located.rss, k.reference_thetas) == ("continuation", 0.5, {"knee_offset": {"c": 0.1}})
    own = {"knee_offset": [("continuation", final_ref["knee_offset"], final["knee_offset"].solution)]}
    calls = []
    monkeypatch.setattr(D.locate, "locate", lambda sol, ds, thetas=None: calls.append(sol.tag) or type(
        "L", (), {"rss": rss[(ds.background, sol.tag)]})())
    assert D.relative_fits(final, final_ref, ref, ref, None, own)["knee_offset"].pair == "final"
    assert calls.count("Nk") == 1
    # the baseline: the lower pair, a non-converged data fit skipped
    pairs = [("final", _Sol(1, "R0"), _Sol(1, "N0")), ("continuation", _Sol(1, "R00"), _Sol(1, "N00"))]
    assert D.lowest_baseline_pair(ref, ref, pairs)[0] == "final"
    rss[("R00", "N00")] = 3.0
    assert D.lowest_baseline_pair(ref, ref, pairs)[0] == "continuation"
    pairs[1] = ("continuation", _Sol(1, "R00"), _Sol(1, "N00", "Infeasible_Problem_Detected"))
    assert D.lowest_baseline_pair(ref, ref, pairs)[0] == "final"


def test_the_null_draws_are_located_on_the_lower_pair_as_the_data_are(ref, monkeypatch):
    """null_calibration with lowest_pair: each draw's baseline pair is chosen between its
    final fits and its continuation (the reference's start fit, the draw's first baseline
    fit), the candidates get their continuation pairs, and the choice is recorded; off, the
    final fits are located, as up to revision 7."""
    from gaitlib.gap import method as M

    seen = {}
    monkeypatch.setattr(D.gref, "null_draw", lambda ref_, n, seed: ref_)
    monkeypatch.setattr(D, "baseline_fits", lambda spec0, draws, warm, **kw: {k: _Sol(2.0, f"N0-{k}") for k in draws})
    monkeypatch.setattr(D, "candidate_fits", lambda spec0, ok, bases, names, **kw: {k: {"first": k} for k in ok})
    monkeypatch.setattr(D, "consistent_fits", lambda spec0, ref_, rf, rfs, ok, bases, nf, names, **kw: {
        k: {"ref_fit": _Sol(1.0, "Rfinal"), "ref_fits": {}, "base": _Sol(1.9, "Nfinal"), "fits": {}, "moved": {}}
        for k in ok})

    def fake_lowest(dk, ref_, pairs):
        seen.setdefault("pairs", []).append([(lab, r.tag, n.tag) for lab, r, n in pairs])
        return ("continuation", *pairs[1][1:])

    monkeypatch.setattr(D, "lowest_baseline_pair", fake_lowest)
    monkeypatch.setattr(D, "continuation_pairs", lambda rfs, nf: {"alt": nf["first"]})
    monkeypatch.setattr(D.gref, "relative_data", lambda dk, ref_, rf, tilt=None: rf.tag)

    def fake_relative_fits(fits, ref_fits, rel, ref_, base, alt=None):
        seen.setdefault("located", []).append((rel, base.tag, alt))
        return {}

    monkeypatch.setattr(D, "relative_fits", fake_relative_fits)
    ranking = pd.DataFrame({"effect": ["knee_offset"], "dBIC": [-30.0], "ok": [True], "pair": ["continuation"]})
    monkeypatch.setattr(D, "assemble", lambda *a, **k: type("Dg", (), {"ranking": ranking})())
    kw = dict(objective="fit", root=None, use_cache=False)
    out = D.null_calibration(D.base_spec(dict(n_intervals=4, degree=2)), ref, _Sol(1.0, "Rstart"), {}, ["knee_offset"], 10, {"data": {}},
                             method=M.RelativeMethod(null_draws=2), **kw)
    assert seen["pairs"] == [[("final", "Rfinal", "Nfinal"), ("continuation", "Rstart", f"N0-null{j}")]
                             for j in range(2)]
    assert seen["located"] == [("Rstart", f"N0-null{j}", {"alt": f"null{j}"}) for j in range(2)]
    assert out["baseline_pair"] == {"null0": "continuation", "null1": "continuation"}
    assert [b["pair"] for b in out["best"]] == ["continuation", "continuation"]
    seen.clear()
    out = D.null_calibration(D.base_spec(dict(n_intervals=4, degree=2)), ref, _Sol(1.0, "Rstart"), {}, ["knee_offset"], 10, {"data": {}},
                             method=M.RelativeMethod(null_draws=2, lowest_pair=False), **kw)
    assert "pairs" not in seen and seen["located"] == [("Rfinal", "Nfinal", None)] * 2
    assert out["baseline_pair"] == {}


def test_the_centred_statistic_cancels_a_shift_shared_by_every_candidate():
    """Revision 10's statistic by hand: a draw's lowest ΔBIC minus its median candidate's
    (the mean of the middle two for an even count). A draw where every candidate gained alike
    (the common mode) has a low raw statistic and a small centred one; the centred threshold
    is the rank-th lowest centred statistic."""
    from gaitlib.gap import method as M

    common = {"a": -600.0, "b": -590.0, "c": -585.0, "d": -580.0}  # median -587.5
    one = {"a": -40.0, "b": -2.0, "c": 1.0}  # median -2
    assert M.draw_statistic(common) == -600.0 and M.draw_statistic(common, True) == -12.5
    assert M.draw_statistic(one, True) == -38.0 and M.draw_statistic({}, True) is None
    per = [common, one, {}, {"a": -5.0, "b": 0.0}]  # centred: -12.5, -38, -2.5
    assert M.null_threshold(per, 2) == -40.0 and M.null_threshold(per, 2, centred=True) == -12.5
    assert M.null_threshold(per, 1, centred=True) == -38.0
    assert M.RELATIVE.centred and M.RelativeMethod(centred=False).hash() != M.RELATIVE.hash()


def test_the_share_beyond_the_median_candidate_by_hand():
    """Revision 10's share: the part of the gap the median ranked candidate leaves open that
    the top effect closes, 100 (p − m) / (100 − m); raw without ``centred``; 0 if the median
    closes everything."""
    from gaitlib.gap import method as M

    # common mode: every candidate closes ~75 %, the top 80 %: it closes 5 of the 25 left
    assert abs(M.share_beyond_median(80.0, [80.0, 76.0, 75.0, 74.0, 70.0]) - 100.0 * 5.0 / 25.0) < 1e-12
    assert abs(M.share_beyond_median(40.0, [40.0, 2.0, 1.0]) - 100.0 * 38.0 / 98.0) < 1e-12
    assert M.share_beyond_median(40.0, [40.0, 2.0, 1.0], centred=False) == 40.0
    assert M.share_beyond_median(100.0, [100.0, 100.0, 100.0]) == 0.0
