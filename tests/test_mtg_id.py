"""MTG parameter identification (thesis Sec 5.1.1): split identities, constraints at the
optimum, which parameters the data move, the tolerance finding, and the parameter file."""

import json

import casadi as ca
import numpy as np
import pytest

from gaitlib import mtg
from gaitlib.problems import gait as gait_ocp
from gaitlib.studies import mtg_id

COARSE = dict(n_intervals=8, degree=3, body_params="default")  # adult joint dampers: a large push-off deficit


@pytest.fixture(scope="module")
def coarse():
    return mtg_id.identify(mtg_id.IdentSpec(**COARSE))


def _node_margins(res, params):
    """Eqs 5.15–5.17 at the collocation nodes of ``res`` (solved states, demand as the NLP
    interpolates it), for a parameter set."""
    ph = res.solution.phase("cycle")
    tc = ph.controls.index.to_numpy()
    X = ph.states.loc[tc]
    dem = res.demand
    T = dem.index[-1]
    out = {}
    for j in ("hip", "knee", "ankle"):
        tau = np.interp(tc / T, dem.index / T, dem[f"tau_{j}"])
        c = mtg_id._constraints(j, X[f"q_{j}"].to_numpy(), X[f"qd_{j}"].to_numpy(), tau,
                                mtg_id._as_params(params), False)
        out.update({k: np.asarray(v, float) for k, v in c.items()})
    return out


def test_split_identities_eqs_5_18_to_5_20():
    rng = np.random.default_rng(0)
    tau = np.concatenate([rng.normal(0, 30, 500), [0.0, -0.0, 1e-300, -1e-300]])
    for j, pos in (("hip", "hip_flex"), ("knee", "knee_ext"), ("ankle", "ankle_flex")):
        sh = mtg_id.split(j, tau)
        neg = next(g for g in sh if g != pos)
        assert np.array_equal(sh[pos] - sh[neg], tau)  # Eq 5.20, exactly
        assert np.all(sh[pos] * sh[neg] == 0.0)  # no co-contraction
        assert np.all(sh[pos] >= 0) and np.all(sh[neg] >= 0)
        # the positive share belongs to the generator whose model-convention torque is > 0
        assert mtg.TORQUE_SIGN[pos] > 0 and mtg.TORQUE_SIGN[neg] < 0
        # CasADi form (used inside the NLP on the data) is the same function
        x = ca.SX.sym("x")
        f = ca.Function("f", [x], [mtg_id.split(j, x)[pos], mtg_id.split(j, x)[neg]])
        a, b = f(ca.DM(tau[:50]).T)
        assert np.array_equal(np.asarray(a).ravel(), sh[pos][:50])
        assert np.array_equal(np.asarray(b).ravel(), sh[neg][:50])


def test_identified_set_satisfies_constraints_where_gymnast_fails(coarse):
    assert coarse.success, coarse.stats["status"]
    after = _node_margins(coarse, coarse.params)
    before = _node_margins(coarse, None)
    for k, v in after.items():
        assert v.min() >= -1e-6, (k, v.min())  # Eqs 5.15–5.17 at every collocation node
    # the adult Gymnast curves (Eq 5.22) are too weak for the child's push-off
    assert before["ankle_ext.5.15"].min() < -5.0
    # the identification raised the ankle extensor's capacity where it was short
    i = int(np.argmin(before["ankle_ext.5.15"]))
    assert after["ankle_ext.5.15"][i] - before["ankle_ext.5.15"][i] > 5.0
    p = coarse.params["ankle_ext"]
    assert p.s_tau > 1.0 and p.s_V > 1.0


def test_generators_with_slack_constraints_stay_at_the_adult_curves(coarse):
    """KKT: a generator whose constraints are all inactive at Γ_initial has only the
    parameter term, so its optimum is Γ_initial (up to the barrier at tol 1e-10)."""
    before = _node_margins(coarse, None)
    for g in ("hip_ext", "knee_ext"):
        assert min(before[f"{g}.5.15"].min(), before[f"{g}.5.17"].min()) > 1.0  # slack
        p, p0 = coarse.params[g], mtg.DEFAULT_PARAMS
        for k in ("s_tau", "s_A", "s_V"):
            assert abs(getattr(p, k) - getattr(p0, k)) < 1e-3, (g, k, getattr(p, k))


def test_thesis_tolerance_stops_at_a_worse_point(coarse):
    """At IPOPT tol 1e-5 (the thesis's) the barrier still dominates the tiny objective: the
    returned point is feasible but its parameter term of Eq 5.23 is many times the optimum's
    (the tracking term is the same), and generators with slack constraints drift (module
    docstring)."""
    loose = mtg_id.identify(mtg_id.IdentSpec(tol=1e-5, **COARSE))
    assert loose.success
    assert loose.stats["cost_Gamma"] > 5 * coarse.stats["cost_Gamma"]
    assert loose.stats["cost_x"] == pytest.approx(coarse.stats["cost_x"], rel=1e-3)
    assert loose.stats["objective"] > coarse.stats["objective"]
    assert loose.params["hip_ext"].s_tau - 1.0 > 0.05
    m = _node_margins(loose, loose.params)
    assert min(v.min() for v in m.values()) >= -1e-6


def test_parameter_file_round_trip(coarse, tmp_path):
    path = mtg_id.save_params(coarse, tmp_path / "p.json")
    back = gait_ocp.load_mtg_params(path)
    assert back == coarse.params  # JSON floats round-trip exactly
    doc = json.loads(path.read_text())
    assert doc["provenance"]["status"] == coarse.stats["status"]
    assert doc["provenance"]["iterations"] == coarse.stats["iterations"]
    assert doc["provenance"]["spec"]["n_intervals"] == COARSE["n_intervals"]
    q, qd = np.linspace(-0.5, 0.3, 7), np.linspace(-4, 4, 7)
    assert np.array_equal(mtg.joint_torque("ankle", q, qd, 0.3, 0.1, back),
                          mtg.joint_torque("ankle", q, qd, 0.3, 0.1, coarse.params))


def test_parameter_file_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="nothere.json"):
        gait_ocp.load_mtg_params(tmp_path / "nothere.json")
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"params": {"hip_ext": {"s_tau": 1.0}}, "provenance": {}}))
    with pytest.raises(ValueError, match=r"bad\.json.*hip_ext"):
        gait_ocp.load_mtg_params(bad)
    with pytest.raises(ValueError, match="mtg_params"):
        gait_ocp.GaitSpec(model="MSK", cost="Eq5.33", mtg_params="adult")


def test_committed_ch5_file():
    """data/identified/ch5_mtg.json: written by identify() with the book's spec (the body
    parameters the Ch 5 solves use), converged, and what GaitSpec(mtg_params='ch5') loads."""
    import dataclasses

    doc = json.loads(mtg_id.PARAMS_FILE.read_text())
    prov = doc["provenance"]
    assert prov["success"] and prov["status"] == "Solve_Succeeded"
    assert prov["spec"] == json.loads(json.dumps(dataclasses.asdict(mtg_id.chapter_spec())))
    p = gait_ocp.mtg_params_of(gait_ocp.GaitSpec(model="MSK", cost="Eq5.33", mtg_params="ch5"))
    assert set(p) == set(mtg.GENERATORS)
    assert p == gait_ocp.load_mtg_params(mtg_id.PARAMS_FILE)
    assert gait_ocp.mtg_params_of("default") is None
    assert gait_ocp.mtg_params_of("thesis")["ankle_ext"] == mtg.THESIS_PARAMS["ankle_ext"]


def test_gait_spec_mtg_params_reach_the_msk_dynamics():
    """GaitSpec.mtg_params is what the MSK problem's implicit dynamics use: the dynamics
    residual at a node equals τ_inv − MTG torques computed with that set (and differs from
    the adult curves' where they differ)."""
    import casadi as ca

    from gaitlib import conventions as cv
    from gaitlib.ocp import Named

    spec = gait_ocp.GaitSpec(model="MSK", cost="Eq5.33", mtg_params="thesis", n_intervals=4, degree=3)
    gp = gait_ocp.build(spec)
    ph = gp.problem.phases[0]
    g = gp.guess.phases["cycle"]
    i = 40
    x = np.array([np.asarray(g.states[k], float)[i] for k in ph.states])
    u = np.array([np.asarray(g.controls[k], float)[i] for k in ph.controls])
    dyn = next(c for c in ph.path_constraints if c.name == "dynamics")
    r = np.asarray(ca.DM(dyn.fun(Named(ca.DM(x), ph.states), Named(ca.DM(u), ph.controls),
                                 Named(ca.DM.zeros(0, 1), ()), 0.0))).ravel()
    X = dict(zip(ph.states, x))
    U = dict(zip(ph.controls, u))
    q = np.array([X[c] for c in cv.COORDS])
    qd = np.array([X[f"qd_{c}"] for c in cv.COORDS])
    qdd = np.array([X[f"qdd_{c}"] for c in cv.COORDS])
    tau_id = np.asarray(gp.model.function("inverse_dynamics")(q, qd, qdd, gp.p_body, gp.p_contact)[0]).ravel()
    for params, equal in ((mtg.THESIS_PARAMS, True), (None, False)):
        tau_in = []
        for j in cv.JOINTS:
            if j.startswith("mtp"):
                tau_in.append(U[f"tau_{j}"])
            else:
                jn, s = j.rsplit("_", 1)
                tau_in.append(float(mtg.joint_torque(jn, X[j], X[f"qd_{j}"], U[f"a_{jn}_ext_{s}"],
                                                     U[f"a_{jn}_flex_{s}"], params)))
        diff = np.abs(r[3:] - (tau_id - np.array(tau_in))).max()
        assert (diff < 1e-9) == equal, (params is None, diff)
