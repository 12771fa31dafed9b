"""Nested candidates never ranked worse than their baseline; the data's own subject count."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from gaitlib import data as data_mod
from gaitlib.problems import gait as gait_ocp
from gaitlib.gap import diagnose as D
from gaitlib import effects as effects_mod
from gaitlib.gap import io as gio
from gaitlib.gap import locate as L


@pytest.fixture(scope="module")
def real():
    return gio.load_real()


# -------------------------------------------------------------------------- nesting

def test_every_nlp_candidate_nests_the_baseline():
    """Every NLP-identified effect has its null value inside its bounds (the baseline model is
    a member); profiled effects are fitted on grids without the null value and are stated
    as not nesting."""
    for n, e in effects_mod.EFFECTS.items():
        nests, why = D.nesting(n)
        assert why
        if e.identify == "nlp":
            assert nests and D._nested(e), n
        if e.identify == "profile" and e.resolve:
            assert not nests and all(m != e.magnitude.null for m in D.PROFILE_GRID[n]), n


def test_null_start_reproduces_the_baseline_point(real):
    """The null start's NLP point is the baseline solution itself on its own mesh with the
    effect's parameters at their null values: the candidate's objective there equals the
    baseline's (no solve: evaluated at the start)."""
    from gaitlib import ocp
    from gaitlib.gap import nullstart as N
    from gaitlib.gap.solve import Runner

    spec = gait_ocp.GaitSpec(model="SK", cost="DT", n_intervals=4, degree=3)
    r0 = Runner(spec)
    # any point will do: the data-based guess after 0 iterations, as a "solution"
    T0 = ocp.transcribe(r0.problem, r0.gp.mesh, ocp.SolverOptions(max_iter=0))
    base = gait_ocp.postprocess(r0.gp, T0.solve(r0.data_guess(real.gait), data={"cycle": r0.frame(real.gait)}))
    for name in ("friction", "arm_swing", "hat_com"):
        r1 = N._NullRunner(D.with_effects(spec, ((name, None),)))
        T1 = ocp.transcribe(r1.problem, r1.gp.mesh, ocp.SolverOptions(max_iter=0))
        w1 = T1.initial_point(N.null_guess(base))
        p = [f"fx.{name}.{q.name}" for q in effects_mod.EFFECTS[name].params]
        ip = [T1.ip[T1.problem.parameter_names.index(k)] for k in p]
        assert np.all(w1[ip] == [q.null for q in effects_mod.EFFECTS[name].params])
        s1 = T1.solve(N.null_guess(base), data={"cycle": r1.frame(real.gait)})
        assert s1.objective == pytest.approx(base.solution.objective, rel=1e-12, abs=1e-14), name


def _bad_first_solves(monkeypatch, max_iter=8):
    """Make every candidate's first solve a bad local search: from the data-based guess
    (not the baseline fit) and stopped after ``max_iter`` iterations."""
    orig = D.solve_many

    def bad(groups, **kw):
        g2 = {g: (dataclasses.replace(spec, max_iter=max_iter), [(k, gait, None) for k, gait, _ in jobs])
              for g, (spec, jobs) in groups.items()}
        return orig(g2, **kw)

    monkeypatch.setattr(D, "solve_many", bad)


def test_nested_candidate_above_the_baseline_is_resolved_or_reported(tmp_path, real, monkeypatch):
    """A nested candidate whose (forced) first fit ends far above the baseline's objective is
    re-solved from the null start and ends at or below the baseline's objective; it is
    ranked with a % closed ≥ −100 RETRY_MARGIN. If the null start fails too (forced), the
    candidate is a failed search: not ranked, no % closed, counted in diagnosis.json."""
    spec = gait_ocp.GaitSpec(model="SK", cost="DT", n_intervals=4, degree=3)
    root = tmp_path / "sol"
    base = D.solve_many({"b": (spec, [("b", real.gait, None)])}, root=root, serial=True, progress=False)["b"]
    assert D._status(base)[1]
    f0 = base.stats["objective"]
    _bad_first_solves(monkeypatch)
    name = "friction"
    fits = D.candidate_fits(spec, {"d": real}, {"d": base}, [name], root=root, serial=True, progress=False)["d"]
    f = fits[name]
    first = f.solution.stats  # the kept fit; the bad first one is under "best"
    assert f.start == "null" and first["retry_start"] == "null"
    assert f.ok and f.search == "ok"
    assert first["objective"] <= f0 * (1 + D.RETRY_MARGIN)
    d = D.assemble(real, spec, base, fits, resamples=0)
    r = d.ranking.set_index("effect").loc[name]
    assert r["rank"] == 1 and r["start"] == "null" and bool(r["nests_baseline"])
    assert r["pct_closed"] >= -100 * D.RETRY_MARGIN
    # the null start forced to fail as well: a failed search
    bad_sol = D.solve_many({"x": (D.with_effects(spec, ((name, None),)), [("x", real.gait, base)])},
                           root=root, serial=True, progress=False)["x"]
    assert D.needs_retry(name, bad_sol, base)
    monkeypatch.setattr(D, "null_start_many",
                        lambda groups, **kw: {k: bad_sol for _, (_, jobs) in groups.items() for k, _, _ in jobs})
    fits = D.candidate_fits(spec, {"d": real}, {"d": base}, [name, "hat_com"], root=root, serial=True,
                            progress=False)["d"]
    assert fits[name].search == "failed search"
    d = D.assemble(real, spec, base, fits, resamples=0)
    r = d.ranking.set_index("effect").loc[name]
    assert r["rank"] is pd_na() and np.isnan(r["pct_closed"]) and np.isnan(r["dBIC"]) and not r["ok"]
    assert r["status"].startswith("failed search")
    assert d.top_effect != name
    j = json.loads((d.save(tmp_path / "out", figures=False) / "diagnosis.json").read_text())
    assert j["summary"]["failed_search"] == 2 and set(j["summary"]["failed_search_effects"]) == {name, "hat_com"}
    assert j["summary"]["ranked"] == 0
    assert all(row["rank"] is None and row["pct_closed"] is None for row in j["ranking"])


def pd_na():
    import pandas as pd

    return pd.NA


def test_nested_fit_with_a_located_gap_above_the_baseline_is_not_ranked(tmp_path, real):
    """A nested candidate whose fit is no failed search by the objective but whose located
    RSS is above the baseline's is not ranked (its % closed would be negative although its
    model contains the baseline); a non-nesting candidate keeps its negative % closed."""
    spec = gait_ocp.GaitSpec(model="SK", cost="DT", n_intervals=4, degree=3, max_iter=5)
    root = tmp_path / "sol"
    rough = D.solve_many({"b": (spec, [("b", real.gait, None)])}, root=root, serial=True, progress=False)["b"]
    good = D.solve_many({"b": (dataclasses.replace(spec, max_iter=1000), [("b", real.gait, None)])}, root=root,
                        serial=True, progress=False)["b"]
    loc_rough = L.locate(rough, real)
    assert loc_rough.rss > L.locate(good, real).rss
    fits = {"hat_com": D.Fit("hat_com", rough, {"hat_com": {"d": 0.0}}, loc_rough, 1, "nlp", "Solve_Succeeded", True),
            "co_contraction": D.Fit("co_contraction", rough, {}, loc_rough, 1, "profile", "Solve_Succeeded", True)}
    d = D.assemble(real, spec, good, fits, resamples=0)
    r = d.ranking.set_index("effect")
    assert r.loc["hat_com", "search"] == D.ABOVE_LOCATED and np.isnan(r.loc["hat_com", "pct_closed"])
    assert r.loc["co_contraction", "rank"] == 1 and r.loc["co_contraction", "pct_closed"] < 0
    assert not bool(r.loc["co_contraction", "nests_baseline"])
    s = d.summary()
    assert s["located_above_baseline_effects"] == ["hat_com"] and "co_contraction" in s["not_nesting"]
    # the ranking figure shows only ranked effects and marks the non-nesting one
    import matplotlib

    matplotlib.use("Agg")
    from gaitlib.gap import figures as F

    labels = [t.get_text() for t in F.ranking_bars(d.ranking).axes[0].get_yticklabels()]
    assert labels == ["co_contraction (k=1, not nesting)"]


# -------------------------------------------------------------------------- subjects

def _foreign_csv(tmp_path, n_col=None, source="mylab"):
    df = data_mod.load_tidy(data_mod.DATA_DIR / "schwartz2008_curves.csv")
    df = df[(df.speed_class == "Free") & df.quantity.isin(gio.REQUIRED_QUANTITIES)].assign(source=source)
    if n_col is not None:
        df = df.assign(n_subjects=n_col)
    p = tmp_path / f"{source}.csv"
    df.to_csv(p, index=False)
    return p


def test_n_subjects_is_the_datas_own(tmp_path, real):
    """n comes from the option, the CSV's column or the known source the CSV names — never
    from ``like``; a foreign CSV without it is a one-line error naming the option."""
    p = _foreign_csv(tmp_path)
    with pytest.raises(data_mod.DataError, match="--n-subjects") as e:
        gio.read_data(p, like="schwartz2008")
    assert "\n" not in str(e.value)
    ds = gio.read_data(p, like="schwartz2008", n_subjects=24)
    assert (ds.n, ds.n_source, ds.base) == (24, "option", "schwartz2008")
    # the band test uses it: SE = SD*/√24
    sim = gait_ocp.tracking_data(ds.gait).mean.copy()
    sim.index = ds.gait.time / ds.gait.cycle_time
    sim = sim[sim.index < 1]
    sim["knee_r"] += 1.5 * np.maximum(ds.gait.sd["knee_r"].to_numpy()[:-1], 1e-9)
    pts = L.locate(sim, ds).points.query("channel == 'angle:knee_r'")
    from scipy.stats import norm

    i = int(np.argmax(pts["sd"].to_numpy()))  # a point above the SD floor: z = 1.5
    assert pts["p_bonf"].iloc[i] == pytest.approx(min(1.0, 50 * norm.sf(0.5 * np.sqrt(24))), rel=1e-6)
    # the column
    p = _foreign_csv(tmp_path, n_col=31)
    ds = gio.read_data(p, like="schwartz2008")
    assert (ds.n, ds.n_source) == (31, "column")
    assert gio.read_data(p, like="schwartz2008", n_subjects=31).n_source == "option"
    with pytest.raises(data_mod.DataError, match="disagree"):
        gio.read_data(p, like="schwartz2008", n_subjects=30)
    p = _foreign_csv(tmp_path, n_col=0)
    with pytest.raises(data_mod.DataError, match="column 'n_subjects' row 2"):
        gio.read_data(p, like="schwartz2008")
    # a known source: its own n (Schwartz 2008, Free: 82 subjects in the speed table)
    p = _foreign_csv(tmp_path, source="schwartz2008")
    ds = gio.read_data(p, like="gaitutils")
    assert (ds.n, ds.n_source) == (82, "known source schwartz2008")
    assert (real.n, real.n_source) == (82, "known source schwartz2008")
    g = gio.load_real("Free", "gaitutils", fill_from="schwartz2008")
    assert (g.n, g.n_source) == (1, "known source gaitutils")


def test_cli_needs_n_subjects_for_a_foreign_csv(tmp_path):
    import os
    import shutil
    import subprocess
    import sys

    p = _foreign_csv(tmp_path)
    exe = shutil.which("gaitlib", path=os.path.dirname(sys.executable)) or shutil.which("gaitlib")
    assert exe
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    r = subprocess.run([exe, "gap", "--data", str(p), "--out", str(tmp_path / "o"), "--like", "schwartz2008"],
                       env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode != 0
    err = r.stderr.strip()
    assert len(err.splitlines()) == 1 and "--n-subjects" in err and "mylab" in err
    assert not (tmp_path / "o").exists()


def _rough_and_hat_com(tmp_path, real):
    """A 5-iteration SK DT baseline on the 4 × 3 mesh and a ``hat_com`` fit that is the
    converged solve of the same problem (the null value: a candidate that closes part of the
    rough baseline's gap): (spec, baseline, {"hat_com": Fit})."""
    spec = gait_ocp.GaitSpec(model="SK", cost="DT", n_intervals=4, degree=3, max_iter=5)
    root = tmp_path / "sol"
    rough = D.solve_many({"b": (spec, [("b", real.gait, None)])}, root=root, serial=True, progress=False)["b"]
    good = D.solve_many({"b": (dataclasses.replace(spec, max_iter=1000), [("b", real.gait, None)])}, root=root,
                        serial=True, progress=False)["b"]
    return spec, rough, {"hat_com": D.Fit("hat_com", good, {"hat_com": {"d": 0.0}}, L.locate(good, real), 1, "nlp",
                                          "Solve_Succeeded", True)}


def test_min_share_holds_a_top_effect_that_closes_too_little(tmp_path, real):
    """``assemble(min_share=)`` (the relative method's ``min_share_closed``): the top effect,
    past the threshold and alone, is named only if it closes at least that % of the located
    RSS; just below its own % closed it is named, just above it the diagnosis is
    "unexplained"."""
    spec, rough, fits = _rough_and_hat_com(tmp_path, real)
    d0 = D.assemble(real, spec, rough, fits, resamples=0, threshold=1e9)
    pct = float(d0.ranking.set_index("effect").loc["hat_com", "pct_closed"])
    assert d0.top_effect == "hat_com" and 0 < pct < 100
    d1 = D.assemble(real, spec, rough, fits, resamples=0, threshold=1e9, min_share=pct - 1)
    assert d1.top_effect == "hat_com" and d1.settings["held_by_share_floor"] is None
    d2 = D.assemble(real, spec, rough, fits, resamples=0, threshold=1e9, min_share=pct + 1)
    assert d2.top_effect == "unexplained" and d2.verdict == "unexplained"
    assert d2.settings["held_by_share_floor"] == "hat_com" and d2.settings["min_share_closed"] == pct + 1
    assert json.loads(json.dumps(d2.to_dict(), default=str))["settings"]["held_by_share_floor"] == "hat_com"


def test_centred_decides_on_the_top_effect_minus_the_median_candidate(tmp_path, real):
    """``assemble(centred=True)`` (the relative method's ``centred``, revision 10): the top
    effect must reach :data:`BIC_THRESHOLD` raw and ``threshold`` after the median ranked
    candidate's ΔBIC is subtracted. Two candidates: the fitted one and one that changes
    nothing (the baseline itself, ΔBIC = ln n_eff); the median is their mean, so the centred
    statistic is half their difference, computed here from the ranking."""
    spec, rough, fits = _rough_and_hat_com(tmp_path, real)
    fits["hip_offset"] = D.Fit("hip_offset", rough, {"hip_offset": {"d": 0.0}}, L.locate(rough, real), 1, "nlp",
                               "Solve_Succeeded", True)
    d0 = D.assemble(real, spec, rough, fits, resamples=0, threshold=-10.0)
    b = d0.ranking.set_index("effect")["dBIC"].astype(float)
    assert b["hat_com"] <= D.BIC_THRESHOLD and abs(b["hip_offset"] - np.log(d0.located.n_eff)) < 1e-9
    half = (b["hat_com"] - b["hip_offset"]) / 2.0
    assert d0.top_effect == "hat_com" and not d0.settings["centred"] and d0.settings["median_dBIC"] is None
    d1 = D.assemble(real, spec, rough, fits, resamples=0, threshold=half + 1.0, centred=True)
    assert d1.top_effect == "hat_com" and abs(d1.settings["median_dBIC"] - (b["hat_com"] + b["hip_offset"]) / 2) < 1e-9
    d2 = D.assemble(real, spec, rough, fits, resamples=0, threshold=half - 1.0, centred=True)
    assert d2.top_effect == "unexplained" and d2.settings["centred"]
    # the share floor on what the median candidate leaves: (p - m) / (100 - m), m the mean of the two
    p = d0.ranking.set_index("effect")["pct_closed"].astype(float)
    m = (p["hat_com"] + p["hip_offset"]) / 2.0
    share = 100.0 * (p["hat_com"] - m) / (100.0 - m)
    assert abs(d1.settings["share_closed"] - share) < 1e-9 and share < p["hat_com"]
    d3 = D.assemble(real, spec, rough, fits, resamples=0, threshold=half + 1.0, centred=True, min_share=share + 0.5)
    assert d3.top_effect == "unexplained" and d3.settings["held_by_share_floor"] == "hat_com"
    d4 = D.assemble(real, spec, rough, fits, resamples=0, threshold=half + 1.0, min_share=share + 0.5)
    assert d4.top_effect == "hat_com"  # raw: its own % closed is above the floor
