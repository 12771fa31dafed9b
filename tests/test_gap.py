"""Tests of the sim-to-real gap diagnosis (gaitlib.gap, issue 7)."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pandas as pd
import pytest

from gaitlib import data as data_mod
from gaitlib import ocp
from gaitlib.problems import gait as gait_ocp
from gaitlib import effects as effects_mod
from gaitlib.gap import io as gio
from gaitlib.gap import locate as L

TINY = dict(n_intervals=3, degree=2)


@pytest.fixture(scope="module")
def real():
    return gio.load_real()


# -------------------------------------------------------------------------- locate

def _data_as_sim(ds) -> pd.DataFrame:
    """The data (as tracked) on the locate grid: a 'solution' with zero residual."""
    view = gait_ocp.tracking_data(ds.gait)
    tau = view.time / view.cycle_time
    df = view.mean.copy()
    df.index = pd.Index(tau, name="tau")
    return df[df.index < 1.0]


def test_locate_finds_a_known_phase_offset(real):
    """A +2 SD offset on the right knee in mid swing only: exactly that cell is off (RMS z =
    2, significant); every other cell is zero and not significant."""
    sim = _data_as_sim(real)
    e = L.phase_edges(real.gait.events)
    tau = sim.index.to_numpy()
    msw = (tau >= e[4]) & (tau < e[5])
    sd = np.interp(tau, real.gait.time / real.gait.cycle_time, real.gait.sd["knee_r"].to_numpy())
    floor = L.SD_FLOOR * np.sqrt(np.mean(real.gait.sd["knee_r"].to_numpy()[:-1] ** 2))
    sim.loc[msw, "knee_r"] += 2.0 * np.maximum(sd[msw], floor)
    loc = L.locate(sim, real)
    t = loc.table.set_index(["channel", "phase"])
    assert t.loc[("angle:knee_r", "MSw"), "rms_z"] == pytest.approx(2.0, rel=1e-9)
    assert bool(t.loc[("angle:knee_r", "MSw"), "significant"])
    others = t.drop(index=("angle:knee_r", "MSw"))
    assert others["rms_z"].max() < 1e-9
    assert not others["significant"].any()
    # phases from the events: right leg MSw is the middle third of swing
    assert e[3] == pytest.approx(real.gait.events["foot_off"])
    # pointwise test: 2 SD out with n = 82 subjects is far beyond the band (z = (2−1)·√82)
    assert loc.points.query("channel == 'angle:knee_r'")["p_bonf"].min() < 1e-10


def test_locate_band_edge_is_not_significant(real):
    """Exactly on the band edge (|z| = 1) the one-sided test gives p = 1/2 per point."""
    sim = _data_as_sim(real)
    sd = np.maximum(real.gait.sd["hip_r"].to_numpy()[:-1],
                    L.SD_FLOOR * np.sqrt(np.mean(real.gait.sd["hip_r"].to_numpy()[:-1] ** 2)))
    sim["hip_r"] = sim["hip_r"] + sd
    loc = L.locate(sim, real)
    p = loc.points.query("channel == 'angle:hip_r'")
    assert np.allclose(p["z"], 1.0)
    assert np.allclose(p["p_bonf"], 1.0)  # min(1, 0.5 × 50)


def test_resels_of_smooth_and_rough_curves():
    tau = np.arange(50) / 50
    assert L.resels(np.sin(2 * np.pi * tau)) == pytest.approx(3.77 * 1, rel=0.02)  # 3.77 k for harmonic k
    assert L.resels(np.sin(2 * np.pi * 3 * tau)) == pytest.approx(3.77 * 3, rel=0.05)
    assert L.resels(np.ones(50)) == 1.0


# -------------------------------------------------------------------------- effects

def _nlp_at_guess(spec):
    gp = gait_ocp.build(spec)
    # an unexpanded MX graph: the NLP's functions without the (slow) expanded solver build
    T = ocp.transcribe(gp.problem, gp.mesh, ocp.SolverOptions(graph="mx", expand=False))
    w0 = T.initial_point(gp.guess)
    p = np.concatenate([T.data_vector(), T.goal_weights()])
    f = ca.Function("fg", [T.nlp["x"], T.nlp["p"]], [T.nlp["f"], T.nlp["g"]])
    fv, gv = f(w0, p)
    return gp, T, float(fv), np.asarray(gv).ravel()


def test_effects_at_null_leave_the_problem_unchanged():
    """Every effect, with its parameters free but at their null values, gives the baseline
    NLP's objective and constraints at the same point (the baseline's optimum stays an
    optimum); a magnitude fixed at 0 drops the effect. SK for the effects that apply to it,
    MSK for the muscle-level ones."""
    ref = {}
    for name, e in effects_mod.EFFECTS.items():
        if not e.resolve:
            continue
        model = "SK" if "SK" in e.models else "MSK"
        base = dict(model=model, cost="DT", **TINY)
        if model not in ref:
            ref[model] = _nlp_at_guess(gait_ocp.GaitSpec(**base))
        _, T0, f0, g0 = ref[model]
        gp, T, f1, g1 = _nlp_at_guess(gait_ocp.GaitSpec(**base, effects=((name, None),)))
        assert [p.name for p in gp.problem.parameters] == [f"fx.{name}.{q.name}" for q in e.params]
        assert f1 == pytest.approx(f0, rel=1e-12, abs=1e-12), name
        if e.path is None:
            assert np.allclose(g1, g0, atol=1e-9), name
        else:  # co-contraction at c = 0: a_flex ≥ 0 and a_ext ≥ 0 — inactive for the guess
            assert len(g1) > len(g0) and T.n_constraints > T0.n_constraints
        fixed0 = effects_mod.bind(gait_ocp.GaitSpec(**base, effects=((name, 0.0),)), None)
        assert fixed0.items == [] and fixed0.parameters == []


def test_effects_registry_documented():
    assert len(effects_mod.EFFECTS) >= 6
    for name, e in effects_mod.EFFECTS.items():
        assert e.name == name and e.n_params >= 1 and len(e.doc) > 200
        assert "Parameters" in e.doc and all(p.unit for p in e.params)
        for p in e.params:
            assert p.lower <= p.null <= p.upper
        for m in e.twin_magnitudes:
            assert e.magnitude.lower <= m <= e.magnitude.upper
    with pytest.raises(ValueError, match="unknown effect"):
        gait_ocp.GaitSpec(effects=(("gravity_off", 1.0),))
    with pytest.raises(ValueError, match="applies to models"):
        gait_ocp.GaitSpec(model="SK", effects=(("co_contraction", 0.2),))
    with pytest.raises(ValueError, match="outside"):
        gait_ocp.GaitSpec(effects=(("hat_com", 5.0),))
    s = gait_ocp.GaitSpec(effects=[("hat_com", 0.02), ["friction", None]])
    assert gait_ocp.GaitSpec.from_dict(s.to_dict()) == s


def _named_x(values: dict):
    names = gait_ocp._states(gait_ocp.GaitSpec())
    v = np.zeros(len(names))
    for k, val in values.items():
        v[names.index(k)] = val
    return ocp.Named(ca.DM(v), names, "state")


def test_hat_com_offset_static_moment():
    """Upright HAT at rest: the offset's extra moment about the hip is m_HAT g d, no force."""
    spec = gait_ocp.GaitSpec(**TINY, effects=(("hat_com", 0.03),))
    gp = gait_ocp.build(spec)
    ctx = effects_mod.Context(spec, gp.model, gp.ref, gp.ref.gait.cycle_time, gp.p_body, gp.p_contact)
    w = np.asarray(effects_mod.EFFECTS["hat_com"].root_load(_named_x({}), {"d": 0.03}, ctx), float).ravel()
    m = gp.p_body[gp.model.p_body_names.index("mass_hat")]
    assert w == pytest.approx([0.0, 0.0, m * 9.81 * 0.03], abs=1e-12)


def test_arm_swing_antiphase_cancels_horizontal_force_and_moment():
    """Antiphase arms (contralateral hips moving symmetrically about their means): the two
    arms' horizontal forces and pitch moments cancel exactly, their vertical forces add."""
    spec = gait_ocp.GaitSpec(**TINY, effects=(("arm_swing", 1.0),))
    gp = gait_ocp.build(spec)
    ctx = effects_mod.Context(spec, gp.model, gp.ref, gp.ref.gait.cycle_time, gp.p_body, gp.p_contact)
    cr, cl = float(np.mean(gp.ref.q["hip_r"])), float(np.mean(gp.ref.q["hip_l"]))
    a, ad, add = 0.3, 1.1, -4.0
    x = _named_x({"hip_r": cr + a, "qd_hip_r": ad, "qdd_hip_r": add,
                  "hip_l": cl - a, "qd_hip_l": -ad, "qdd_hip_l": -add})
    w = np.asarray(effects_mod.EFFECTS["arm_swing"].root_load(x, {"G": 1.0}, ctx), float).ravel()
    assert abs(w[0]) < 1e-12 and abs(w[2]) < 1e-12
    m, lc = effects_mod.ARM["mass"], effects_mod.ARM["com"]
    # each arm's COM rises by lc (1 − cos φ); vertical force = 2 m d²/dt² of it, here with φ = a
    phi, phid, phidd = a, ad, add
    ydd = lc * (phidd * np.sin(phi) + phid**2 * np.cos(phi))
    assert w[1] == pytest.approx(2 * m * ydd, rel=1e-12)


def test_left_shift_reference_is_the_fourier_shift(real):
    """The symbolic left-leg reference at δ equals data.fourier_shift of the right leg at
    shift + δ (order 5) on the data grid; δ = 0 gives the data's own left leg."""
    spec = gait_ocp.GaitSpec(**TINY, effects=(("left_shift", None),))
    gp = gait_ocp.build(spec)
    frame = gait_ocp.tracking_frame(spec, gp.ref)
    delta = ca.SX.sym("delta")
    names = list(frame.columns)
    dsym = ca.SX.sym("d", len(names))
    over = effects_mod.EFFECTS["left_shift"].reference(ocp.Named(dsym, names, "data"), {"delta": delta}, None, None)
    f = ca.Function("f", [dsym, delta], [over["ref_knee_l"], over["ref_grf_y_l"]])
    g = real.gait
    for dv in (0.0, 0.02, -0.035):
        kn, gy = [], []
        for _, row in frame.iterrows():
            a, b = f(row.to_numpy(float), dv)
            kn.append(float(a)), gy.append(float(b))
        ref_kn = data_mod.fourier_shift(g.mean["knee_r"].to_numpy(), g.left_shift + dv, 5)
        ref_gy = data_mod.fourier_shift(g.mean["grf_y_r"].to_numpy(), g.left_shift + dv, 5)
        assert np.allclose(kn, ref_kn, atol=1e-9) and np.allclose(gy, ref_gy, atol=1e-7)
    assert effects_mod.left_generated(g)


# -------------------------------------------------------------------------- IO and twins

def test_tidy_reader_errors_name_the_quantity(tmp_path, real):
    df = data_mod.load_tidy(data_mod.DATA_DIR / "schwartz2008_curves.csv")
    df = df[(df.speed_class == "Free") & (df.quantity != "grf_vertical")]
    p = tmp_path / "hand.csv"
    df.to_csv(p, index=False)
    with pytest.raises(data_mod.DataError, match="grf_vertical"):
        gio.read_data(p)
    ds = gio.read_data(p, fill_from="schwartz2008")
    assert ds.filled == ("grf_vertical",)
    assert np.allclose(ds.gait.mean["grf_y_r"], real.gait.mean["grf_y_r"])
    df2 = df.assign(source="mylab")
    df2.to_csv(p, index=False)
    with pytest.raises(data_mod.DataError, match="like"):
        gio.read_data(p, fill_from="schwartz2008")


def test_hand_written_csv_reads_like_the_real_data(tmp_path, real):
    """A CSV with only the needed quantities, every 10 % of the cycle, written by hand,
    reads as the same data set interpolated (the real reader does the work)."""
    df = data_mod.load_tidy(data_mod.DATA_DIR / "schwartz2008_curves.csv")
    df = df[(df.speed_class == "Free") & df.quantity.isin(gio.REQUIRED_QUANTITIES) & (df.percent_cycle % 10 == 0)]
    p = tmp_path / "hand.csv"
    with open(p, "w") as f:
        f.write(",".join(data_mod.TIDY_COLUMNS) + "\n")
        for r in df.itertuples(index=False):
            f.write(f"{r.source},{r.speed_class},{r.quantity},{r.side},{r.percent_cycle:g},{r.mean},{r.sd},{r.unit}\n")
    ds = gio.read_data(p)
    assert ds.n == 82 and ds.base == "schwartz2008"
    assert ds.gait.cycle_time == pytest.approx(real.gait.cycle_time)
    k = np.arange(0, 51, 5)  # the written points
    assert np.allclose(ds.gait.mean["knee_r"].to_numpy()[k], real.gait.mean["knee_r"].to_numpy()[k])


def test_twin_round_trip_through_the_tidy_reader(tmp_path, real):
    """A noise-free twin written in the tidy format and read back equals the solution it was
    made of (both legs; RSS ≈ 0); with noise, RSS ≈ N_points / n (SD/√n noise)."""
    from gaitlib.gap import twin

    spec = gait_ocp.GaitSpec(model="SK", cost="DT", n_intervals=4, degree=2, max_iter=40)
    gp = gait_ocp.build(spec)
    # any state/control trajectory will do for the round trip: the data-based guess
    sol = gait_ocp.postprocess(gp, ocp.transcribe(gp.problem, gp.mesh, ocp.SolverOptions(max_iter=0)).solve(gp.guess))
    clean = twin.twin_frame(sol, real, seed=None, noise=False)
    assert set(clean["side"]) == {"R", "L", "ipsilateral"} and set(clean["source"]) == {"twin(schwartz2008)"}
    p = tmp_path / "twin.csv"
    clean.to_csv(p, index=False, float_format="%.12g")
    ds = gio.read_data(p)
    assert not effects_mod.left_generated(ds.gait)
    loc = L.locate(sol, ds)
    assert loc.rss < 1e-12
    rss = []
    for seed in range(4):
        twin.twin_frame(sol, real, seed=seed).to_csv(p, index=False, float_format="%.12g")
        rss.append(L.locate(sol, gio.read_data(p)).rss)
    expected = loc.n_points / real.n
    assert 0.4 * expected < np.mean(rss) < 1.8 * expected
    a = twin.twin_frame(sol, real, seed=3)
    b = twin.twin_frame(sol, real, seed=3)
    assert a.equals(b)


def test_smooth_noise_unit_variance_and_correlation():
    from gaitlib.gap.twin import NOISE_LENGTH, smooth_noise

    g = smooth_noise(np.random.default_rng(0), 20000)(np.array([0.0, 0.02, 0.5, 1.0]))
    assert g.var(axis=0) == pytest.approx([1, 1, 1, 1], rel=0.05)
    assert np.corrcoef(g[:, 0], g[:, 1])[0, 1] == pytest.approx(np.exp(-0.5 * (0.02 / NOISE_LENGTH) ** 2), abs=0.02)
    assert np.allclose(g[:, 0], g[:, 3])  # periodic


# -------------------------------------------------------------------------- diagnosis

def test_criteria_pay_for_parameters():
    from gaitlib.gap.diagnose import _criteria

    daic, dbic = _criteria(100.0, 100.0, 1, 200.0)
    assert daic == pytest.approx(2.0) and dbic == pytest.approx(np.log(200.0))
    daic, dbic = _criteria(100.0, 90.0, 2, 200.0)
    assert dbic == pytest.approx(200 * np.log(0.9) + 2 * np.log(200))


def test_baseline_fit_keeps_the_best_converged_start(tmp_path, real, monkeypatch):
    """The multistart baseline fit solves from every start (cold, warm, the spec's own cost
    then the fit, a coarser mesh then the fit, the GRF-weighted fit then the fit) and keeps the converged fit with the lowest
    objective, naming its start; a mesh no finer than the coarse one has no coarse start."""
    from gaitlib.gap import diagnose as D

    spec = gait_ocp.GaitSpec(model="SK", cost="DT", n_intervals=4, degree=2)
    monkeypatch.setattr(D, "COARSE_MESH", (2, 2))
    root = tmp_path / "sol"
    warm = D.solve_many({"w": (spec, [("w", real.gait, None)])}, root=root, serial=True, progress=False)["w"]
    out = D.baseline_fits(spec, {"d": real}, warm, root=root, detail=True, serial=True, progress=False)["d"]
    assert set(out) == {"cold", "warm", "dt", "coarse", "grf", "best"}
    conv = {k: s for k, s in out.items() if k != "best" and D._status(s)[1]}
    assert conv, {k: s.stats["status"] for k, s in out.items()}
    best = min(conv.values(), key=lambda s: s.stats["objective"])
    assert out["best"] is best and out["best"].stats["start"] in conv
    assert conv[out["best"].stats["start"]] is best
    # every start is a fit of the same problem: same objective kind, comparable objectives
    assert all(s.stats["objective_kind"] == "fit" for k, s in out.items())
    monkeypatch.setattr(D, "COARSE_MESH", (4, 2))
    assert D._coarse_spec(spec) is None
    with pytest.raises(ValueError, match="unknown baseline start"):
        D.baseline_fits(spec, {"d": real}, starts=("cold", "hot"))


def test_grf_weighted_scales_only_the_grf_sds(real):
    """The first stage of the ``grf`` start: GRF SDs × factor, everything else identical,
    and a different data signature (its own cache key)."""
    from gaitlib.gap import diagnose as D

    g = real.gait
    w = D.grf_weighted(g, 0.1)
    grf = list(gait_ocp.GRF_CHANNELS)
    other = [c for c in g.sd.columns if c not in grf]
    np.testing.assert_array_equal(w.sd[grf].to_numpy(), 0.1 * g.sd[grf].to_numpy())
    np.testing.assert_array_equal(w.sd[other].to_numpy(), g.sd[other].to_numpy())
    np.testing.assert_array_equal(w.mean.to_numpy(), g.mean.to_numpy())
    assert gio.signature(w) != gio.signature(g)
    # the Fit objective's SD columns follow: the GRF weight grows by 1/factor²
    from gaitlib.gap.solve import sd_columns

    tau = np.linspace(0, 0.98, 7)
    a, b = sd_columns(g, tau), sd_columns(w, tau)
    np.testing.assert_allclose(b["sd_grf_y_r"], 0.1 * a["sd_grf_y_r"])
    np.testing.assert_allclose(b["sd_knee_r"], a["sd_knee_r"])


class _S:
    def __init__(self, status, objective):
        self.stats = {"status": status, "objective": objective}


def test_needs_retry_on_failure_or_a_nested_fit_worse_than_the_baseline():
    from gaitlib.gap import diagnose as D

    base = _S("Solve_Succeeded", 10.0)
    nested = next(n for n, e in effects_mod.EFFECTS.items() if D._nested(e))
    assert D.needs_retry(nested, None, base)
    assert D.needs_retry(nested, _S("Maximum_Iterations_Exceeded", 1.0), base)
    assert D.needs_retry(nested, _S("Solve_Succeeded", 10.5), base)
    assert not D.needs_retry(nested, _S("Solve_Succeeded", 10.0 * (1 + 0.5 * D.RETRY_MARGIN)), base)
    assert not D.needs_retry(nested, _S("Solve_Succeeded", 9.0), base)


def test_candidate_retry_keeps_the_best_start(tmp_path, real):
    """A candidate fit that ends above the baseline's objective is re-solved from the
    baseline's other starts; the converged fit with the lowest objective is kept and its
    start named."""
    from gaitlib.gap import diagnose as D

    # 4 x 3: at 3 x 2 whether a baseline start converges depends on the CPU's last bits (both
    # stopped at the iteration limit on an AVX2-only EPYC)
    spec = gait_ocp.GaitSpec(model="SK", cost="DT", n_intervals=4, degree=3)
    root = tmp_path / "sol"
    det = D.baseline_fits(spec, {"d": real}, None, root=root, detail=True, starts=("cold", "dt"), serial=True,
                          progress=False)
    base = det["d"]["best"]
    assert base is not None and D._status(base)[1]
    alts = D.alternates_of(det)
    assert set(alts["d"]) == {"cold", "dt"} - {base.stats["start"]}
    # an impossible baseline objective forces the retry of every nested candidate
    import copy

    low = copy.copy(base)
    low.stats = dict(base.stats, objective=-1.0)
    name = "friction"
    assert D._nested(effects_mod.EFFECTS[name])
    fits = D.candidate_fits(spec, {"d": real}, {"d": low}, [name], root=root, alternates=alts, serial=True,
                            progress=False)["d"]
    f = fits[name]
    assert f.solution is not None and "retry_start" in f.solution.stats
    assert f.solution.stats["retry_start"] in {"best", "null"} | set(alts["d"])  # null: the null start
    # without alternates: no retry from other starts; only the null start (from the baseline
    # itself) may follow the first solve
    f1 = D.candidate_fits(spec, {"d": real}, {"d": low}, [name], root=root, serial=True, progress=False)["d"][name]
    assert f1.solution.stats.get("retry_start", "best") in {"best", "null"}
    if f.ok and f1.ok:
        assert f.solution.stats["objective"] <= f1.solution.stats["objective"] + 1e-12


def test_diagnose_names_the_injected_effect_on_a_twin(tmp_path):
    """A coarse SK twin with lower friction (k = −0.3): the diagnosis, given the baseline
    model and three candidates, names friction and recovers its magnitude."""
    from gaitlib.gap import diagnose as D
    from gaitlib.gap import twin

    base = dict(model="SK", cost="DT", n_intervals=10, degree=3)
    p = twin.write_twin(tmp_path / "twin.csv", (("friction", -0.3),), seed=1, base=base, root=tmp_path / "sol")
    d = D.diagnose(p, base=base, effects=("friction", "segment_inertia", "hat_com"), root=tmp_path / "sol",
                   resamples=50, serial=True, progress=False)
    assert d.top_effect == "friction", d.ranking
    r = d.ranking.set_index("effect")
    assert r.loc["friction", "parameters"]["k"] == pytest.approx(-0.3, abs=0.06)
    assert r.loc["friction", "dBIC"] <= D.BIC_THRESHOLD
    lo, hi = d.intervals["friction"]
    assert lo <= r.loc["friction", "pct_closed"] <= hi
    out = d.save(tmp_path / "out", figures=False)
    import json

    j = json.loads((out / "diagnosis.json").read_text())
    assert j["top_effect"] == "friction" and j["ranking"][0]["effect"] == "friction"


# -------------------------------------------------------------------------- the shell interface

def test_cli_gap_on_a_hand_written_csv(tmp_path):
    """``gaitlib gap --data CSV --out DIR`` from a fresh process on a tidy CSV written line by
    line (another lab's name, only the quantities the problem needs, every 10 % of the
    cycle; ``--like schwartz2008`` for speed, cycle time and events, ``--n-subjects`` for its
    own n): diagnosis.json has the data's n and its source, the located gap, the ranking
    (effect, parameters added, identified values, start of the kept fit, whether it nests the
    baseline, RSS before/after, % closed — never negative for a ranked nested candidate —,
    ΔAIC/ΔBIC), the summary's counts, the shrink with its interval, and a top effect that is
    either the best eligible candidate or "unexplained"."""
    import json
    import os
    import shutil
    import subprocess
    import sys

    from gaitlib.gap import diagnose as D

    df = data_mod.load_tidy(data_mod.DATA_DIR / "schwartz2008_curves.csv")
    df = df[(df.speed_class == "Free") & df.quantity.isin(gio.REQUIRED_QUANTITIES) & (df.percent_cycle % 10 == 0)]
    csv = tmp_path / "mylab.csv"
    with open(csv, "w") as f:
        f.write("source,speed_class,quantity,side,percent_cycle,mean,sd,unit\n")
        for r in df.itertuples(index=False):
            f.write(f"mylab,Free,{r.quantity},{r.side},{r.percent_cycle:g},{r.mean:.6g},{r.sd:.6g},{r.unit}\n")
    exe = shutil.which("gaitlib", path=os.path.dirname(sys.executable)) or shutil.which("gaitlib")
    assert exe, "the gaitlib console script is not installed"
    out = tmp_path / "out"
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    cmd = [exe, "gap", "--data", str(csv), "--out", str(out), "--like", "schwartz2008", "--n-subjects", "24",
           "--effects", "friction,hat_com,segment_inertia", "--intervals", "6", "--degree", "3",
           "--resamples", "40", "--serial", "--cache", str(tmp_path / "cache")]
    # a guard against a hang, not a speed claim: ≈ 50 s here alone, > 240 s on 2 busy cores
    p = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-3000:]
    j = json.loads((out / "diagnosis.json").read_text())
    for f in ("gap_heatmap.png", "ranking.png", "located.csv", "ranking.csv"):
        assert (out / f).is_file(), f
    assert j["data"]["base_source"] == "schwartz2008"
    assert j["data"]["n_subjects"] == 24 and j["data"]["n_subjects_source"] == "option"
    # located: 16 channels (angles, torques, GRFs; both legs) × 6 phases
    loc = j["located"]
    assert loc["summary"]["cells"] == 16 * 6 and len(loc["channels"]) == 16
    assert loc["summary"]["rss"] == pytest.approx(sum(c["rss"] for c in loc["channels"]))
    assert {"channel", "phase", "rms_z", "mean_z", "frac_out", "p_min", "significant"} <= set(loc["table"][0])
    # ranking: every candidate, with its added parameters and identified values
    rk = {r["effect"]: r for r in j["ranking"]}
    assert set(rk) == {"friction", "hat_com", "segment_inertia"}
    for name, r in rk.items():
        e = effects_mod.EFFECTS[name]
        assert r["n_params"] == e.n_params and set(r["parameters"]) == {q.name for q in e.params}
        assert r["rss_before"] == pytest.approx(loc["summary"]["rss"])
        assert r["start"] in ("baseline", "null") + D.BASELINE_STARTS and r["nests_baseline"]
        if r["rank"] is None:  # a failed search or a located gap above the baseline's: no % closed
            assert r["search"] != "ok" and r["pct_closed"] is None and r["dBIC"] is None
            continue
        assert r["pct_closed"] == pytest.approx(100 * (1 - r["rss_after"] / r["rss_before"]))
        assert r["pct_closed"] >= -100 * j["summary"]["retry_margin"]  # every candidate here nests the baseline
        n_eff = j["criterion"]["n_eff"]
        assert r["dBIC"] == pytest.approx(n_eff * np.log(r["rss_after"] / r["rss_before"]) + e.n_params * np.log(n_eff))
    s = j["summary"]
    assert s["candidates"] == 3 and s["ranked"] + s["failed_search"] + s["located_above_baseline"] == 3
    # shrink of the top effects: before/after per channel and phase, % closed and its interval
    assert j["shrink"]
    for name, s in j["shrink"].items():
        lo, hi = s["interval_95"]
        assert lo <= s["pct_closed"] <= hi
        assert {"rms_before", "rms_after", "pct_closed"} <= set(s["table"][0])
    # top effect: the best converged candidate within the threshold, else "unexplained"
    elig = [r for r in j["ranking"] if r["ok"] and r["dBIC"] is not None and r["dBIC"] <= j["criterion"]["threshold_dBIC"]]
    assert j["top_effect"] == (elig[0]["effect"] if elig else "unexplained")
    assert j["verdict"] in ("explained", "partial", "unexplained")


def test_exact_left_leg_is_the_right_leg_rolled_by_half_a_cycle():
    """With the left-leg shift at exactly half the 50-interval data cycle, the exact left leg
    is the right leg's samples rolled by 25; the Fourier-generated left leg is not (it rings
    where the GRF is zero), and a left channel that is the source's own is kept."""
    from gaitlib.studies.gap import exact_left_leg

    g = data_mod.load_gait_data("Free", "schwartz2008", left_shift=0.5)
    gx, replaced = exact_left_leg(g)
    assert {"hip_l", "tau_ankle_l", "grf_x_l", "grf_y_l", "emg_TA_l"} <= set(replaced)
    for c in ("hip_l", "tau_ankle_l", "grf_y_l"):
        r = g.mean[c[:-2] + "_r"].to_numpy()[:-1]  # 50 distinct samples of the cycle
        np.testing.assert_allclose(gx.mean[c].to_numpy()[:-1], np.roll(r, -25), atol=1e-12)
        np.testing.assert_allclose(gx.sd[c].to_numpy()[:-1], np.roll(g.sd[c[:-2] + "_r"].to_numpy()[:-1], -25),
                                   atol=1e-12)
    # the Fourier series of a GRF that is zero in swing is not zero there: its ringing, in N
    # (here it even pulls the foot down: a negative vertical GRF of more than 5 N)
    swing_r = np.abs(g.mean["grf_y_r"].to_numpy()[:-1]) < 1.0
    swing_l = np.roll(swing_r, -25)
    assert swing_l.sum() >= 15
    yl_exact, yl_fourier = gx.mean["grf_y_l"].to_numpy()[:-1], g.mean["grf_y_l"].to_numpy()[:-1]
    assert np.all(np.abs(yl_exact[swing_l]) < 1.0)
    assert np.min(yl_fourier[swing_l]) < -5.0
    # a left leg that is not the Fourier series of the right one is left alone
    g2 = g.__class__(**{**g.__dict__, "mean": g.mean.assign(knee_l=g.mean["knee_l"] + 0.01)})
    _, rep2 = exact_left_leg(g2)
    assert "knee_l" not in rep2 and "hip_l" in rep2


def test_stored_gap_solutions_are_reachable(real):
    """The gap solutions' keys hash the data's numbers (:func:`gaitlib.gap.io.signature`),
    which depend in the last bits on OpenBLAS's kernel (the Fourier left leg): under the
    Makefile's ``OPENBLAS_CORETYPE`` the real data's signature is the one the committed
    store was written with, so the book's gap chapter reloads instead of re-solving (hours)."""
    import os

    from gaitlib import cache
    from gaitlib.gap import twin
    from gaitlib.gap.solve import _where

    store = cache.store_dir()
    if store is None or "ch08_gap.ipynb:" not in ((store / "README.md").read_text()
                                                  if (store / "README.md").is_file() else ""):
        pytest.skip("the store does not hold the gap chapter's solutions (solutions/README.md)")
    spec = twin.twin_spec(())  # the effect-free twin's generating solve (Ch 8), on the real data
    where = _where(spec, real.gait, None, None, objective="cost")
    assert (store / "gap" / where.name).is_dir(), (
        f"the effect-free twin generator {where.name} is not in {store / 'gap'} (data signature "
        f"{gio.signature(real.gait)}, OPENBLAS_CORETYPE={os.environ.get('OPENBLAS_CORETYPE')!r}): run under "
        "the Makefile's settings, or refresh the store (tools/store_solutions.py)")


def test_ranking_bars_draws_an_interval_that_excludes_the_point():
    """The resampled interval of % closed need not contain the point estimate (the redrawn
    noise raises every RSS): the figure draws it as the segment [lo, hi] it is."""
    import matplotlib

    matplotlib.use("Agg")
    from gaitlib.gap import figures as F

    r = pd.DataFrame({"effect": ["a", "b"], "n_params": [1, 1], "ok": [True, True], "pct_closed": [2.2, 10.0],
                      "pct_closed_lo": [0.9, 8.0], "pct_closed_hi": [2.19, 12.0], "dBIC": [0.2, -20.0]})
    fig = F.ranking_bars(r, top="b")
    segs = [c for c in fig.axes[0].collections if hasattr(c, "get_segments")]
    ends = sorted(tuple(np.round(s[:, 0], 2)) for c in segs for s in c.get_segments())
    assert ends == [(0.9, 2.19), (8.0, 12.0)]


def test_data_signature_ignores_the_last_bits(real):
    """Another CPU's BLAS kernel changes derived curves in the last bits: same signature;
    a real change of the data (1e-6 of a curve's scale) changes it."""
    import dataclasses

    g = real.gait
    base = gio.signature(g)
    m = g.mean.to_numpy(float)
    ulp = dataclasses.replace(g, mean=g.mean.copy(deep=True))
    ulp.mean.iloc[:, :] = np.nextafter(m, np.inf)
    assert gio.signature(ulp) == base
    moved = dataclasses.replace(g, mean=g.mean.copy(deep=True))
    col = moved.mean.columns[0]
    moved.mean[col] = moved.mean[col] + 1e-6 * np.abs(moved.mean[col]).max()
    assert gio.signature(moved) != base


def test_data_signature_sees_a_column_scaled_by_a_power_of_ten(real):
    import dataclasses

    g = real.gait
    scaled = dataclasses.replace(g, sd=g.sd * 10.0)
    assert gio.signature(scaled) != gio.signature(g)


def test_activation_timing_twin_carries_the_delay_in_its_emg(real):
    """Activation timing is comparison-only (no re-solve): its twin must carry it in the
    data — the twin's EMG at t is the model's activation at t + Δd — and the effect's own
    data adjustment (the data's EMG at t − Δd) undoes it; angles, torques and GRFs equal the
    effect-free twin's."""
    import dataclasses

    from gaitlib.gap import twin

    spec = gait_ocp.GaitSpec(model="MSK", cost="DT", n_intervals=4, degree=2, max_iter=40, derivatives="nodes")
    gp = gait_ocp.build(spec)
    sol = gait_ocp.postprocess(gp, ocp.transcribe(gp.problem, gp.mesh, ocp.SolverOptions(max_iter=0)).solve(gp.guess))
    dd = 0.04
    sol_d = dataclasses.replace(sol, spec=dataclasses.replace(spec, effects=(("activation_timing", dd),)))
    a = twin.twin_frame(sol, real, seed=None, noise=False)
    b = twin.twin_frame(sol_d, real, seed=None, noise=False)
    emg = a["quantity"].str.startswith("emg_")
    assert emg.any()
    assert np.array_equal(a.loc[~emg, "mean"].to_numpy(), b.loc[~emg, "mean"].to_numpy())
    assert not np.allclose(a.loc[emg, "mean"].to_numpy(), b.loc[emg, "mean"].to_numpy())
    # hand check on one channel: b(τ) = a(τ + Δd/T), a periodic curve sampled every 2 %
    T = real.gait.cycle_time
    q = a["quantity"].iloc[int(np.flatnonzero(emg.to_numpy())[0])]
    pick = lambda f: f[(f["quantity"] == q) & (f["side"] == "R")].sort_values("percent_cycle")  # noqa: E731
    pa, pb = pick(a), pick(b)
    tau = pa["percent_cycle"].to_numpy() / 100
    ya = pa["mean"].to_numpy()
    shifted = np.interp(np.mod(tau + dd / T, 1.0), np.concatenate([tau[:-1] - 1, tau[:-1], tau[:-1] + 1]),
                        np.tile(ya[:-1], 3))
    assert np.max(np.abs(shifted - pb["mean"].to_numpy())) < 0.05 * np.ptp(ya)
    # the effect's data adjustment brings the twin's EMG back onto the activations
    p = effects_mod.EFFECTS["activation_timing"]
    ds_b = gio.read_data(_write(b, real))
    back = p.data_adjust(ds_b.gait, {"dd": dd})
    ds_a = gio.read_data(_write(a, real))
    col = next(c for c in ds_a.gait.mean.columns if c.startswith("emg_") and c.endswith("_r"))
    err = back.mean[col].to_numpy() - ds_a.gait.mean[col].to_numpy()
    assert np.max(np.abs(err[5:-5])) < 0.05 * np.ptp(ds_a.gait.mean[col].to_numpy())


def _write(frame, real):
    import tempfile
    from pathlib import Path

    p = Path(tempfile.mkdtemp()) / "twin.csv"
    frame.to_csv(p, index=False, float_format="%.12g")
    return p
