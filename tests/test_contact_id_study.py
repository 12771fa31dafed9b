"""Ch 4 contact identification study (gaitlib.studies.contact_id): approach (a)'s problem
and multistart, the (b)/(c) specs, and the identified-parameter file round trip."""

import dataclasses
import json
from types import SimpleNamespace

import numpy as np
import pytest

from gaitlib import cache, contact, params
from gaitlib import conventions as cv
from gaitlib.problems import gait as gait_ocp
from gaitlib.model import P_BODY_NAMES, ChildModel
from gaitlib.studies import contact_id as ci


@pytest.fixture(scope="module")
def small():
    """Approach (a)'s problem on a coarse time grid (20 samples), a small search."""
    return ci.InverseDynamicsID(ci.TrajOptSpec(n_time=20, n_trial=24, n_local=2, seed=3))


def test_scaling_round_trip_and_log_kv(small):
    lo, hi = contact.bounds()
    p = ci.neutral_start()
    z = small.z_of_p(p)
    assert np.all((z >= 0) & (z <= 1))
    np.testing.assert_allclose(small.p_of_z(z), p, rtol=1e-12)
    np.testing.assert_allclose(small.p_of_z(np.zeros(39)), lo)
    np.testing.assert_allclose(small.p_of_z(np.ones(39)), hi)
    i = contact.param_index("ball", "k_v")
    # geometric centre of the k_v box at z = 1/2 (log scaling)
    assert small.p_of_z(np.full(39, 0.5))[i] == pytest.approx(np.sqrt(lo[i] * hi[i]))


def test_neutral_start_inside_table_4_7_and_eq_4_4():
    lo, hi = contact.bounds()
    p = ci.neutral_start()
    assert np.all(p >= lo) and np.all(p <= hi)
    for e in cv.ELLIPSOIDS:
        r = p[contact.param_index(e, "mu_d")] / p[contact.param_index(e, "mu_s")]
        assert ci.MU_RATIO[0] <= r <= ci.MU_RATIO[1]


def test_eq_4_5_gradient_matches_finite_differences(small):
    """Exact gradient (AD) of the Eq 4.5 cost vs central differences at the neutral start."""
    p = ci.neutral_start()
    g = np.asarray(small.gradient_function(p)).ravel()
    lo, hi = contact.bounds()
    fd = np.zeros(39)
    for i in range(39):
        h = 1e-6 * (hi[i] - lo[i])
        e = np.zeros(39)
        e[i] = h
        fd[i] = (small.cost(p + e) - small.cost(p - e)) / (2 * h)
    scale = np.abs(g) * (hi - lo)  # sensitivity over the box, comparable across units
    big = scale > 1e-6 * scale.max()
    np.testing.assert_allclose(g[big] * (hi - lo)[big], fd[big] * (hi - lo)[big], rtol=1e-4,
                               atol=1e-7 * scale.max())


def test_eq_4_5_is_zero_for_data_and_positive_otherwise(small):
    """The cost is the mean of squared range-normalised errors: J = ¼ Trq + ¼ GRF, J ≥ 0."""
    J, trq, grf = (float(v) for v in small.cost_function(ci.neutral_start()))
    assert J == pytest.approx(0.25 * trq + 0.25 * grf)
    assert trq > 0 and grf > 0


def test_scatter_is_seeded_and_respects_eq_4_4_where_possible(small):
    A, B = small.scatter(), small.scatter()
    np.testing.assert_array_equal(A, B)
    assert A.shape == (24, 39)
    lo, hi = contact.bounds()
    assert np.all(A >= lo - 1e-12) and np.all(A <= hi + 1e-12)
    other = ci.InverseDynamicsID(ci.TrajOptSpec(n_time=20, n_trial=24, seed=4)).scatter()
    assert not np.allclose(A, other)


def test_multistart_optimum_below_every_start_and_feasible(small, tmp_path):
    res = ci.trajectory_optimization(small.spec, use_cache=False, root=tmp_path, problem=small)
    assert res.success and res.stats["status"] == "Solve_Succeeded"
    st = res.starts
    assert len(st) == 1 + small.spec.n_local
    best = res.stats["objective"]
    # the best local optimum is at most the cost of every start point (and every local result)
    for start in [ci.neutral_start()] + [small.scatter()[int(s.split("#")[1])] for s in st["start"][1:]]:
        assert best <= small.cost(np.clip(start, small.lo, small.hi)) + 1e-12
    assert best <= st["cost"].min() + 1e-12
    lo, hi = contact.bounds()
    assert np.all(res.p_contact >= lo - 1e-9) and np.all(res.p_contact <= hi + 1e-9)
    ratios = ci.friction_ratios({"a": res})[ci.APPROACHES["a"]]
    assert np.all(ratios >= ci.MU_RATIO[0] - 1e-6) and np.all(ratios <= ci.MU_RATIO[1] + 1e-6)
    # frames are the problem's: inverse dynamics torques and contact forces at the optimum
    out = small.frames_function(res.p_contact)
    np.testing.assert_allclose(res.grf.to_numpy().T, np.asarray(out[2]))
    # the RMSE table is consistent with the frames (right vertical GRF)
    g = small.grf_data[1]
    rm = res.rmse.set_index("channel").loc["grf_y_r", "rmse"]
    assert rm == pytest.approx(np.sqrt(np.mean((res.grf["grf_y_r"].to_numpy() - g) ** 2)), rel=1e-9)
    # cached: the same result comes back
    res2 = ci.trajectory_optimization(small.spec, root=tmp_path, problem=small)
    res3 = ci.trajectory_optimization(small.spec, root=tmp_path, problem=small)
    assert not res2.stats["from_cache"] and res3.stats["from_cache"]
    np.testing.assert_allclose(res3.p_contact, res2.p_contact)


def test_specs_b_and_c_follow_the_thesis():
    b, c = ci.spec_b(4, 3), ci.spec_c(4, 3)
    assert b.term_weights == {"Trq": 0.25, "GRF": 0.25, "Q": 0.25, "Jrk": 1 / 40}  # Table 4.8
    assert c.term_weights == {**b.term_weights, "Imp": 0.25, "Rsd": 0.25}  # Sec 4.4.2: w5 = w6 = 1/4
    assert b.free_contact and not b.free_body and not b.normal_force_constraint
    assert c.free_contact and c.free_body and c.normal_force_constraint
    gp = gait_ocp.build(c)
    lo, hi = contact.bounds()
    P = {p.name: p for p in gp.problem.parameters}
    for i, n in enumerate(contact.param_names()):  # Table 4.7 verbatim
        assert (P[f"c.{n}"].lower, P[f"c.{n}"].upper) == (lo[i], hi[i])
    blo, bhi = ChildModel().p_body_bounds()  # Table 4.14
    for i, n in enumerate(P_BODY_NAMES):
        assert (P[f"b.{n}"].lower, P[f"b.{n}"].upper) == (blo[i], bhi[i])
    names = [pc.name for pc in gp.problem.phases[0].path_constraints]
    assert "normal_force" in names
    assert "friction_ratio" in [e.name for e in gp.problem.phases[0].endpoint_constraints]


def _fake_c_result(p_contact, p_body):
    """A (c) result carrying real parameter vectors and a solution stub (spec, stats): enough
    for the file round trip, which does not depend on how the numbers were obtained."""
    spec = ci.spec_c(4, 3)
    sol = SimpleNamespace(spec=spec, stats={"spec_key": "test"})
    stats = {"status": "Solve_Succeeded", "success": True, "iterations": 7, "objective": 0.1, "solve_s": 1.0}
    return ci.ApproachResult("c", np.asarray(p_contact, float), np.asarray(p_body, float), None, None, None, None,
                             None, None, stats, solution=sol)


def test_identified_file_round_trip_with_provenance(tmp_path, monkeypatch):
    m = ChildModel()
    pc = contact.default_params()  # a contact that carries the body (the gait reference needs it)
    pc[contact.param_index("ball", "mu_s")] = 0.5
    pb = 1.1 * m.default_p_body()
    monkeypatch.setattr(params, "IDENTIFIED_DIR", tmp_path)
    path = ci.save_identified(_fake_c_result(pc, pb), path=params.identified_path("ch4_child"))
    assert path == tmp_path / "ch4_child.json"
    raw = json.loads(path.read_text())
    prov = raw["provenance"]
    for k in ("spec", "gaitlib_version", "cache_fingerprint", "ipopt_status", "iterations", "date"):
        assert k in prov
    assert prov["cache_fingerprint"] == cache.fingerprint((gait_ocp.FORMULATION, ci.FORMULATION),
                                                          identified=ci.spec_c(4, 3).identified_sets())
    assert prov["spec"]["cost"] == "Eq4.13"
    assert raw["units"]["p_contact"]["toe.k_v"] == "N/m^3" and raw["units"]["p_body"]["mass_hat"] == "kg"
    lo, hi = contact.bounds()
    assert raw["bounds"]["p_contact"]["heel.a"] == [lo[contact.param_index("heel", "a")],
                                                    hi[contact.param_index("heel", "a")]]
    got = params.load_identified("ch4_child")
    np.testing.assert_array_equal(got["p_contact"], pc)
    np.testing.assert_array_equal(got["p_body"], pb)
    np.testing.assert_array_equal(params.contact_params("ch4"), pc)
    np.testing.assert_array_equal(params.body_params("ch4"), pb)
    # a gait spec loads them as its fixed parameters
    gp = gait_ocp.build(gait_ocp.GaitSpec(model="SK", cost="Eq4.11", n_intervals=3, degree=2, contact_params="ch4",
                              body_params="ch4"))
    np.testing.assert_array_equal(gp.p_contact, pc)
    np.testing.assert_array_equal(gp.p_body, pb)
    cmp = ci.identified_vs_result(_fake_c_result(pc, pb))
    assert cmp["max_rel_diff_contact"] == 0 and cmp["max_rel_diff_body"] == 0


def test_identified_file_missing_or_bad_is_a_clear_error(tmp_path, monkeypatch):
    monkeypatch.setattr(params, "IDENTIFIED_DIR", tmp_path)
    with pytest.raises(FileNotFoundError, match="ch4_child.json"):
        params.load_identified("ch4_child")
    with pytest.raises(FileNotFoundError, match="ch4_child.json"):
        gait_ocp.build(gait_ocp.GaitSpec(model="SK", n_intervals=3, degree=2, contact_params="ch4"))
    (tmp_path / "ch4_child.json").write_text(json.dumps({"p_contact": {}, "p_body": {}, "provenance": {}}))
    with pytest.raises(ValueError, match="p_contact has missing"):
        params.load_identified("ch4_child")
    with pytest.raises(ValueError, match="contact_params"):
        gait_ocp.GaitSpec(contact_params="thesis")


def test_save_refuses_unconverged(tmp_path):
    r = _fake_c_result(ci.neutral_start(), ChildModel().default_p_body())
    r.stats.update(status="Maximum_Iterations_Exceeded", success=False)
    with pytest.raises(ValueError, match="did not converge"):
        ci.save_identified(r, path=tmp_path / "x.json")


def test_thesis_reference_tables_are_consistent():
    """Table 4.17/4.18 (approach (c)) are the library's default contact parameters; every
    thesis set respects Eq 4.4 (to the printed digits); Table 4.11's (b) lies inside Table 4.7,
    Table 4.10's (a) except heel r_y (−3.7 mm < −3.0 mm), Table 4.17's (c) except the five
    entries the contact module lists (Sec 4.4 used wider, unreported bounds)."""
    np.testing.assert_allclose(ci.thesis_params("c"), contact.default_params(), rtol=0, atol=1e-15)
    lo, hi = contact.bounds()
    outside = {}
    for k in ("a", "b", "c"):
        p = ci.thesis_params(k)
        for e in cv.ELLIPSOIDS:
            r = p[contact.param_index(e, "mu_d")] / p[contact.param_index(e, "mu_s")]
            assert ci.MU_RATIO[0] <= r <= ci.MU_RATIO[1] + 1e-3, (k, e, r)
        outside[k] = {n for n, v, l, h in zip(contact.param_names(), p, lo, hi) if not l - 1e-9 <= v <= h + 1e-9}
    assert outside == {"a": {"heel.r_y"}, "b": set(), "c": set(contact.TABLE_4_17_OUTSIDE_TABLE_4_7)}


def test_committed_ch4_parameters_are_a_converged_feasible_identification():
    """data/identified/ch4_child.json (approach (c) on the Free data): converged, within the
    Table 4.7 / Table 4.14 bounds it records (which are the library's), Eq 4.4 holds, the
    total mass stays within ±20 % of the subjects' 41.4 kg."""
    got = params.load_identified("ch4_child")
    prov = got["provenance"]
    assert prov["ipopt_status"] == "Solve_Succeeded"
    assert prov["spec"]["cost"] == "Eq4.13" and prov["spec"]["free_body"] and prov["spec"]["normal_force_constraint"]
    assert prov["spec"]["n_intervals"] == 20 and prov["spec"]["degree"] == 5
    lo, hi = contact.bounds()
    pc, pb = got["p_contact"], got["p_body"]
    tol = 1e-7 * (hi - lo)
    assert np.all(pc >= lo - tol) and np.all(pc <= hi + tol)
    np.testing.assert_allclose([got["bounds"]["p_contact"][n] for n in contact.param_names()],
                               np.column_stack([lo, hi]))
    blo, bhi = ChildModel().p_body_bounds()
    assert np.all(pb >= blo - 1e-7 * (bhi - blo)) and np.all(pb <= bhi + 1e-7 * (bhi - blo))
    for e in cv.ELLIPSOIDS:
        r = pc[contact.param_index(e, "mu_d")] / pc[contact.param_index(e, "mu_s")]
        assert ci.MU_RATIO[0] - 1e-6 <= r <= ci.MU_RATIO[1] + 1e-6
    assert 0.8 * 41.4 <= ChildModel().total_mass(pb) <= 1.2 * 41.4


def test_identified_note_names_the_spec_fields_that_differ():
    spec = gait_ocp.GaitSpec(model="SK", cost="Eq4.13", jerk_ranges="data")
    res = SimpleNamespace(solution=SimpleNamespace(spec=spec))
    same = {"max_rel_diff_contact": 0.0, "max_rel_diff_body": 1e-9, "provenance": {"spec": spec.to_dict()}}
    assert ci.identified_note(same, res).startswith("The stored file is this page's (c)")
    old = {k: v for k, v in spec.to_dict().items() if k != "jerk_ranges"}
    other = {"max_rel_diff_contact": 0.5, "max_rel_diff_body": 0.2, "provenance": {"spec": old, "date": "2026-11-22"}}
    text = ci.identified_note(other, res)
    assert "not this page's (c)" in text and "0.50" in text and "jerk_ranges: 'unset' there, 'data' here" in text


def test_readings_thesis_is_the_printed_problem_book_adds_three_fields():
    from gaitlib.problems import contact_id as cid_ocp
    from gaitlib import validity
    assert ci.spec_b(4, 3, reading="thesis") == cid_ocp.spec_b(4, 3)
    assert ci.spec_c(4, 3, reading="thesis") == cid_ocp.spec_c(4, 3)
    b = ci.spec_b(4, 3)
    assert (b.jerk_ranges, b.max_iter) == ("data", 3000)
    # 1 % of body weight, half the gate's 2 %: 0.01 × 41.4 kg × g
    assert b.swing_load_max == pytest.approx(0.01 * 41.4 * 9.81, abs=1e-3)
    assert b.swing_load_max < validity.SWING_LOAD_BW * 41.4 * 9.81
    gp = gait_ocp.build(ci.spec_c(4, 3))
    assert "swing_load" in [pc.name for pc in gp.problem.phases[0].path_constraints]
    with pytest.raises(ValueError, match="reading"):
        ci.reading_options("printed")


def test_start_params_and_the_multistart_keeps_the_lowest_valid(monkeypatch):
    np.testing.assert_array_equal(ci.start_params("neutral"), ci.neutral_start())
    th = ci.start_params("thesis (c)")
    assert th[contact.param_index("toe", "k_v")] == ci.THESIS_CONTACT["c"]["toe"][0]
    # the pick: lowest objective among converged and valid, else lowest of all
    objective = {"neutral": 0.02, "thesis (c)": 0.01, "ch4_child": 0.03}
    valid = {"neutral": True, "thesis (c)": False, "ch4_child": True}
    made = {}

    def fake_run(spec, start=None, **kw):
        name = next(n for n in ci.B_STARTS if np.array_equal(ci.start_params(n), start))
        made[name] = r = ci.ApproachResult("b", np.asarray(start), None, None, None, None, None, None, None,
                                           {"status": "Solve_Succeeded", "success": True, "iterations": 10,
                                            "objective": objective[name], "eq4_5": 0.0}, solution=name)
        return r

    monkeypatch.setattr(ci, "optimal_control", fake_run)
    monkeypatch.setattr(ci.validity, "check", lambda sol: SimpleNamespace(passed=valid[sol], label=lambda: "x"))
    monkeypatch.setattr(ci.params_mod, "contact_params", lambda which: 2 * ci.neutral_start())
    # the starts table's slip and sink columns read the solutions; stubbed with known values
    monkeypatch.setattr(ci.gait_study, "foot_slip", lambda sol: {"slip": {"neutral": 0.1}.get(sol, 0.2)})
    monkeypatch.setattr(ci.gait_study, "foot_sink", lambda q, p, model=None: 0.015)
    best = ci.optimal_control_multistart()
    assert best.starts.loc["neutral", "foot slip (m/s)"] == 0.1 and best.starts.loc["ch4_child", "foot slip (m/s)"] == 0.2
    assert (best.starts["deepest sink (mm)"] == 15.0).all()
    assert best is made["neutral"] and best.stats["start"] == "neutral"
    assert best.starts.loc["neutral", "kept"] and not best.starts.loc["thesis (c)", "kept"]
    valid.update({"neutral": False, "ch4_child": False})
    assert ci.optimal_control_multistart().stats["start"] == "thesis (c)"


def test_each_c_ablation_change_is_one_change_on_the_book_reading_spec():
    base = ci.spec_c()
    assert base.jerk_ranges == "data" and base.swing_load_max == pytest.approx(0.01 * 41.4 * 9.81, abs=1e-3)
    specs = ci.c_ablation_specs()
    assert set(specs) == set(ci.c_changes())
    for name, change in ci.c_changes().items():
        spec = specs[name]
        differs = {f.name for f in dataclasses.fields(base) if getattr(spec, f.name) != getattr(base, f.name)}
        assert differs == set(change), name
    # Eq 4.13's tracking weights are 1/4 (Table 4.8): "×4" sets 1
    w = dict(gait_ocp.COST_FUNCTIONS["SK"][base.cost])
    assert w["GRF"] == w["Q"] == w["Trq"] == 0.25
    assert dict(specs["GRF weight ×4"].weights) == {"GRF": 1.0}


def test_c_ablation_targets_are_one_and_a_half_times_sec_4_4_2():
    # Sec 4.4.2: "3.37 N and 2.71 N" tangential, "9.94 N and 10.72 N" normal (right, left)
    assert ci.C_TARGET_FACTOR * ci.THESIS_RMSE["c"][("grf_y", "l")] == pytest.approx(16.08)
    assert ci.C_TARGET_FACTOR * ci.THESIS_RMSE["c"][("grf_x", "r")] == pytest.approx(5.055)
