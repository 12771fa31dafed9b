"""Physics and number tests of the Ch 3 vertical-jump study (gaitlib.studies.jump).

Coarse meshes (4 LGR intervals x 4 points per phase) keep each solve to a few seconds; the
assertions are about the physics of the solution, which does not depend on the mesh:
take-off and apex events, the static start, zero flight GRF, the ballistic flight, the COM
band, the friction ratio of Eq 3.6 and the bookkeeping of failed solves.
"""

from __future__ import annotations

import math
import warnings
from types import SimpleNamespace
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from gaitlib import ocp
from gaitlib import cache
from gaitlib.studies import jump as J

COARSE = dict(n_intervals=4)


@pytest.fixture(scope="module")
def toe():
    return J.solve(J.spec("toe", **COARSE))


@pytest.fixture(scope="module")
def ellipsoid():
    return J.solve(J.spec("ellipsoid", **COARSE))


# ------------------------------------------------------------------------------ spec
def test_thesis_tables():
    """Weights (Table 3.10), COM bands (Table 3.8) and the ankle mapping of Table 3.5."""
    assert J.SPECS["toeless"].weights == (1.0, 12.0)
    assert J.SPECS["toe"].weights == (1.0, 1.0)
    assert J.SPECS["ellipsoid"].weights == (2.0, 1.0, 1.0, 5.0)
    assert [J.SPECS[k].dx_com for k in ("toeless", "toe", "ellipsoid")] == [0.01, 0.06, 0.002]
    b = J.joint_bounds("ankle")  # thesis 50..110 deg, 90 = standing, dorsiflexion decreases it
    np.testing.assert_allclose(np.degrees(b["q"]), [-20.0, 40.0])
    np.testing.assert_allclose(np.degrees(b["qd"]), [-1500.0, 1200.0])
    assert b["tau"] == (-2000.0, 4000.0)
    k = J.joint_bounds("knee")
    np.testing.assert_allclose(np.degrees(k["q"]), [-150.0, 0.0])
    assert k["tau"] == (-2000.0, 1500.0)
    with pytest.raises(ValueError):
        J.JumpSpec("toe", weights=(1.0, 1.0, 1.0, 1.0))


def test_implicit_and_explicit_dynamics_agree():
    """The implicit form's inverse-dynamics constraint is the explicit model inverted: the
    two phase models give the same residual-free q̈ for the same state and torques."""
    jp = J.build(J.spec("toe", n_intervals=2))
    m = jp.model
    rng = np.random.default_rng(3)
    qj, qdj, tau = rng.normal(size=4) * 0.3, rng.normal(size=4), rng.normal(size=4) * 80
    qdd = m.stance_dynamics(qj, qdj, tau)["qddj"]
    back = m.stance_inverse_dynamics(qj, qdj, qdd)["tau"]
    np.testing.assert_allclose(back, tau, rtol=1e-9, atol=1e-8)


# ------------------------------------------------------------------------------ kinematic
def test_kinematic_jump_events_and_physics(toe):
    s = toe
    assert s.success, s.status
    tr, m = s.trajectory, s.model
    W = m.total_mass * m.g
    crouch, thrust, flight = (tr[tr.phase == p] for p in ("crouch", "thrust", "flight"))
    # Table 3.7: a_COM = 0 at the start (GRF = weight, no horizontal force), at rest
    np.testing.assert_allclose(crouch[["grf_x", "grf_y"]].iloc[0], [0.0, W], atol=1e-5 * W)
    np.testing.assert_allclose(crouch[[f"qd_{j}" for j in m.joints]].iloc[0], 0.0, atol=1e-8)
    # take-off: vertical GRF zero at the end of the thrust, COM moving up
    assert abs(thrust["grf_y"].iloc[-1]) < 1e-4 * W
    assert thrust["com_vy"].iloc[-1] > 0.5
    # the welded ground only pushes
    assert (pd.concat([crouch, thrust])["grf_y"] > -1e-3 * W).all()
    # flight: no ground force, apex at the end (v_y,COM = 0)
    assert (flight[["grf_x", "grf_y"]] == 0.0).all().all()
    assert abs(flight["com_vy"].iloc[-1]) < 1e-6
    # continuity at take-off: joint angles, velocities, torques and the root at rest
    a, b = thrust.iloc[-1], flight.iloc[0]
    cols = list(m.joints) + [f"qd_{j}" for j in m.joints] + [f"tau_{j}" for j in m.joints]
    np.testing.assert_allclose(a[cols].astype(float), b[cols].astype(float), atol=1e-7)
    np.testing.assert_allclose(b[["x", "y", "theta_z", "qd_x", "qd_y", "qd_theta_z"]].astype(float),
                               0.0, atol=1e-9)


def test_jump_height_is_ballistic(toe):
    """COM rise in flight = v_TO² / 2g, flight time = v_TO / g, and the COM follows the
    parabola y_TO + v_TO s − g s²/2 at every interior flight node (only its end is
    constrained), within 1 cm on this coarse mesh."""
    s = toe
    h, g = s.jump_height, s.model.g
    v = h["takeoff_vy"]
    assert h["com_rise_flight"] == pytest.approx(v**2 / (2 * g), rel=1e-6)
    assert h["ballistic"] == pytest.approx(v**2 / (2 * g), rel=1e-12)
    assert h["apex_time"] - h["takeoff_time"] == pytest.approx(v / g, rel=1e-6)
    fl = s.trajectory[s.trajectory.phase == "flight"]
    t = fl.index.to_numpy() - h["takeoff_time"]
    parabola = fl["com_y"].iloc[0] + v * t - 0.5 * g * t**2
    assert np.max(np.abs(fl["com_y"].to_numpy() - parabola)) < 0.01
    # the COM velocity of the collocated states errs most just after take-off, where the
    # light toe is released (the collocation error the ballistic apex constraint guards
    # the cost against): within 15 % of v_TO on this 4-interval mesh
    assert np.max(np.abs(fl["com_vy"].to_numpy() - (v - g * t))) < 0.15 * v
    # COM rise from standing and foot lift are consistent with the COM rise in flight
    assert h["com_rise_standing"] == pytest.approx(
        fl["com_y"].iloc[-1] - s.trajectory["com_y"].iloc[0])
    assert h["foot_lift"] == pytest.approx(fl["y"].iloc[-1])


def test_com_band_and_bounds(toe):
    """Table 3.8 band |x_COM − x_COM(0)| ≤ 6 cm in every phase; Table 3.5 bounds hold."""
    s = toe
    tr = s.trajectory
    dx = tr["com_x"] - tr["com_x"].iloc[0]
    assert dx.abs().max() <= s.spec.dx_com + 1e-6
    for j in s.model.joints:
        b = J.joint_bounds(j)
        assert tr[j].min() >= b["q"][0] - 1e-6 and tr[j].max() <= b["q"][1] + 1e-6
        assert tr[f"tau_{j}"].min() >= b["tau"][0] - 1e-4
        assert tr[f"tau_{j}"].max() <= b["tau"][1] + 1e-4
    assert tr.loc[tr.phase != "flight", "mtp"].min() >= -1e-8  # heel above the ground


def test_friction_ratio_eq_3_6(toe):
    s = toe
    tr = s.trajectory
    W = s.model.total_mass * s.model.g
    loaded = tr["grf_y"] >= s.spec.fy_min_fraction * W
    np.testing.assert_allclose(tr.loc[loaded, "friction_ratio"],
                               (tr.loc[loaded, "grf_x"] / tr.loc[loaded, "grf_y"]).abs())
    assert tr.loc[~loaded, "friction_ratio"].isna().all()
    contact = tr[tr.phase != "flight"]
    assert s.required_friction == pytest.approx(contact["friction_ratio"].max())


def test_results_and_stats_tables(toe):
    res = J.results_table({"toe": toe})
    row = res.iloc[0]
    assert row["IPOPT status"] == "Solve_Succeeded"
    assert row["jump height (cm), thesis, Sec 3.4.4"] == 66.0
    assert row["μ_s, thesis, Sec 3.4.3"] == 1.0
    assert row["COM rise in flight (cm)"] == pytest.approx(100 * toe.jump_height["com_rise_flight"])
    st = J.stats_table({"toe": toe}).iloc[0]
    assert st["iterations"] > 0 and st["solve_time_s"] > 0
    assert st["time_per_iteration_ms"] == pytest.approx(1e3 * st["solve_time_s"] / st["iterations"])


# ------------------------------------------------------------------------------ ellipsoid
def test_ellipsoid_jump(ellipsoid):
    s = ellipsoid
    assert s.success, s.status
    tr, m = s.trajectory, s.model
    W = m.total_mass * m.g
    crouch, thrust, flight = (tr[tr.phase == p] for p in ("crouch", "thrust", "flight"))
    # static start carried by the ellipsoids: GRF = (0, W), at rest
    np.testing.assert_allclose(crouch[["grf_x", "grf_y"]].iloc[0], [0.0, W], atol=1e-4 * W)
    np.testing.assert_allclose(crouch.filter(like="qd_").iloc[0], 0.0, atol=1e-8)
    # take-off: 0 ≤ F_y ≤ 1 N; in flight the feet are off the ground (GRF < 1 N)
    assert 0.0 <= thrust["grf_y"].iloc[-1] <= s.spec.fy_takeoff + 1e-6
    assert flight["grf_y"].max() <= s.spec.flight_fy_max + 1e-6
    # ballistic apex and the 2 mm COM band
    v, g = s.jump_height["takeoff_vy"], m.g
    assert s.jump_height["com_rise_flight"] == pytest.approx(v**2 / (2 * g), rel=1e-6)
    assert (tr["com_x"] - tr["com_x"].iloc[0]).abs().max() <= 0.002 + 1e-6
    # velocity-based friction: |Fx/Fy| cannot exceed the largest μ of the ellipsoids much
    assert s.required_friction < 0.5


# ------------------------------------------------------------------------------ failures
def test_failed_solve_is_reported():
    """An unconverged solve keeps IPOPT's status; tables and figures say FAILED."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ocp.SolveFailedWarning)
        s = J.solve(J.spec("toeless", n_intervals=3, max_iter=3))
    assert not s.success
    assert s.status == "Maximum_Iterations_Exceeded"
    assert J.results_table({"toeless": s}).iloc[0]["IPOPT status"] == s.status
    import matplotlib

    matplotlib.use("Agg")
    fig = J.plot_channels({"toeless": s}, "angles")
    assert "FAILED" in fig.axes[0].get_title()


def test_cache_roundtrip(toe, tmp_path):
    """A cached solution reloads with the same numbers and says so."""
    sp = toe.spec
    where = J.cache_location(sp, tmp_path)
    cache.save(where, toe.solution.save)  # entries are written with their checksums
    s2 = J.solve(sp, use_cache=True, root=tmp_path)
    assert s2.from_cache and s2.stats["from_cache"]
    assert s2.jump_height == pytest.approx(toe.jump_height)
    pd.testing.assert_frame_equal(s2.trajectory, toe.trajectory)


def test_animation(toe):
    import matplotlib

    matplotlib.use("Agg")
    anim = J.animate(toe, max_frames=6)
    assert len(anim.frame_indices) == 6
    html = __import__("gaitlib.plots", fromlist=["animation_html"]).animation_html(anim)
    assert "<img" in html or "data:image" in html
    t, Q = toe.poses()
    assert Q.shape == (len(t), toe.model.n) and np.all(np.diff(t) > 0)


def test_standing_top_is_table_3_1_by_hand():
    from gaitlib.jump import JumpModel
    h = 0.116 * math.sin(math.radians(28.8)) + 0.503 + 0.440 + 0.660  # foot·sin(incline) + shank + thigh + HT
    assert JumpModel(toe=True).standing_top == pytest.approx(h, abs=5e-4)


def test_strength_limits_keep_the_thesis_keys_and_bound_every_phase():
    from gaitlib import mtg
    from gaitlib.problems import jump as J

    base = J.SPECS["toe"]
    assert "torque_limits" not in base.to_dict()  # the stored jumps keep their keys
    st = J.spec("toe", torque_limits="strength")
    assert st.to_dict()["torque_limits"] == "strength" and J.cache_location(st) != J.cache_location(base)
    with pytest.raises(ValueError, match="torque_limits"):
        J.spec("toe", torque_limits="human")
    jp = J.build(replace(st, n_intervals=3, continuation=()))
    model = jp.model
    env = J.strength_envelope(model)
    kw = dict(body_mass=model.total_mass, body_height=model.standing_top)
    for ph in jp.problem.phases:
        assert "strength" in [c.name for c in ph.path_constraints]
        # box: the metatarsal joint within ± the two-leg ankle plantarflexor peak (Eq 5.21 scaling)
        pf = 2 * mtg.strength_limits(None, **kw)["ankle"][0]
        lo, hi = ph.bounds["tau_mtp"]
        assert lo * st.tau_scale == pytest.approx(pf) and hi * st.tau_scale == pytest.approx(-pf)
    # the envelope is two legs × the MTG pair's extreme net torque at the state
    for j, q, qd in (("knee", -1.0, 5.0), ("hip", 0.8, -3.0), ("ankle", 0.1, 2.0)):
        lo, hi = mtg.max_joint_torque(j, q, qd, None, **kw)
        assert env["envelope"][j](q, qd) == pytest.approx((2 * lo, 2 * hi))
        assert 2 * lo >= env["peak"][j][0] - 1e-9 and 2 * hi <= env["peak"][j][1] + 1e-9


def test_strength_findings_read_claims_on_converged_valid_jumps_only():
    from types import SimpleNamespace

    def fake(name, rise, ok=True, mu=0.5):
        return SimpleNamespace(jump_height={"com_rise_flight": rise, "takeoff_vy": (2 * 9.81 * rise) ** 0.5},
                               success=ok, status="Solve_Succeeded" if ok else "Infeasible_Problem_Detected",
                               required_friction=mu, spec=SimpleNamespace(label=J.LABELS[name]))

    sols = {"toeless": fake("toeless", 0.12, mu=2.1), "toe": fake("toe", 0.5, ok=False), "ellipsoid": fake("ellipsoid", 0.18, mu=0.34)}
    text = " ".join(J.strength_findings(sols, {"toeless": True, "toe": False, "ellipsoid": True}))
    assert "did NOT converge (Infeasible_Problem_Detected)" in text
    assert "the toes raise the jump — not read" in text
    assert "toes and compliant contact together raise it — with strength limits" in text and "12 cm" in text
    assert "18 cm: holds" in text
    assert "outside the 20–70 cm" in text  # 12 cm, below the human range
    assert "ellipsoid contact 0.34 vs welded toeless, kinematic contact 2.10 — less, as in the thesis" in text


def test_strength_retry_findings_tell_procedure_from_problem():
    """A jump that stops at a feasible point without converging under another continuation
    has jumps (the procedure failed); infeasible from every continuation: said so."""
    from types import SimpleNamespace

    def fake(cont, status, it, viol, rise=0.2, obj=1.0, mu=2.0, limit=5000, cap=None):
        return SimpleNamespace(success=status == "Solve_Succeeded", status=status, stats={"iterations": it},
                               solution=SimpleNamespace(max_violation=viol, objective=obj, worst_constraint="x"),
                               jump_height={"com_rise_flight": rise, "takeoff_vy": 2.1}, required_friction=mu,
                               spec=SimpleNamespace(label="toe-included, kinematic contact", continuation=cont,
                                                    max_iter=limit, friction_max=cap, start_from=None, ipopt=()))

    sols = {"toe": fake((5,), "Infeasible_Problem_Detected", 2114, 1e-2, rise=0.01)}
    retries = {"toe": {((), None): fake((), "Infeasible_Problem_Detected", 2068, 1e-6, obj=3.0),
                       ((7,), None): fake((7,), "Maximum_Iterations_Exceeded", 5000, 7e-8, rise=0.22, mu=6.16,
                                          obj=2.0),
                       ((7,), 15000): fake((7,), "Maximum_Iterations_Exceeded", 15000, 2e-11, rise=0.30, mu=7.4,
                                           obj=1.0, limit=15000)}}
    (line,) = J.strength_retry_findings(sols, retries)
    assert line.startswith("**toe-included, kinematic contact** — a 5-interval continuation stage (the spec's own): "
                           "Infeasible_Problem_Detected after 2114 iterations; no continuation, limit 5000 iterations: "
                           "Infeasible_Problem_Detected after 2068 iterations; a 7-interval continuation stage, limit "
                           "5000 iterations: Maximum_Iterations_Exceeded after 5000 iterations; a 7-interval "
                           "continuation stage, limit 15000 iterations: Maximum_Iterations_Exceeded after 15000 "
                           "iterations.")
    # the feasible point with the lowest objective is reported
    assert ("With a 7-interval continuation stage, limit 15000 iterations it stopped at a feasible point (largest "
            "violation 2.0e-11; COM rise 30 cm, required μ_s 7.4)") in line
    retries["toe"][((7,), 15000)] = fake((7,), "Solve_Succeeded", 9000, 1e-9, rise=0.31, mu=7.0, limit=15000)
    (line,) = J.strength_retry_findings(sols, retries)
    assert line.endswith("Converged: with a 7-interval continuation stage, limit 15000 iterations, COM rise 31 cm, "
                         "take-off v_y 2.10 m/s, required μ_s 7.0 (objective 1.00).")
    retries["toe"][((5,), None, True)] = fake((5,), "Maximum_Iterations_Exceeded", 5000, 1e-8, rise=0.21, mu=1.0,
                                               cap=1.0)
    (line,) = J.strength_retry_findings(sols, retries)
    assert "a 5-interval continuation stage, |F_x| ≤ 1 F_y, limit 5000 iterations: Maximum_Iterations_Exceeded" in line
    for k in retries["toe"]:
        retries["toe"][k] = fake((), "Infeasible_Problem_Detected", 900, 0.3)
    (line,) = J.strength_retry_findings(sols, retries)
    assert line.endswith("No procedure found a feasible point.")


def test_friction_cap_keeps_the_keys_and_adds_two_rows_per_preflight_node():
    """``friction_max`` (ours): absent from every existing key while unset; only for welded
    contact; the preflight phases get the cone μF_y ∓ F_x ≥ 0 (two rows), the flight none."""
    from gaitlib.problems import jump as J

    for n in J.SPECS:
        assert "friction_max" not in J.SPECS[n].to_dict()
    st = J.spec("toe", torque_limits="strength")
    capped = replace(st, friction_max=1.0)
    assert J.cache_location(capped) != J.cache_location(st)
    with pytest.raises(ValueError, match="friction_max"):
        J.spec("ellipsoid", friction_max=1.0)
    with pytest.raises(ValueError, match="friction_max"):
        J.spec("toe", friction_max=0.0)
    jp = J.build(replace(capped, n_intervals=3, continuation=()))
    rows = {ph.name: [c for c in ph.path_constraints if c.name == "friction_cone"] for ph in jp.problem.phases}
    assert len(rows["crouch"]) == len(rows["thrust"]) == 1 and not rows["flight"]
    c = rows["crouch"][0]
    assert c.lower == 0.0 and c.upper == np.inf


def test_retry_specs_keep_the_stored_procedures_and_cap_friction_at_the_thesis_mu():
    from gaitlib.problems import jump as P
    st = P.spec("toe", torque_limits="strength")
    got = [J.retry_spec(st, r) for r in J.STRENGTH_RETRIES]
    assert got[:3] == [replace(st, continuation=()), replace(st, continuation=(7,)),
                       replace(st, continuation=(7,), max_iter=15000)]
    assert [g.friction_max for g in got] == [None, None, None, 1.0, 1.0, None, None, None, 1.0]  # Sec 3.4.3: "1 …"
    assert got[5] == replace(st, ipopt=J.PIVTOL)  # the spec's own procedure, MUMPS's pivot tolerance raised
    assert got[6] == replace(st, continuation=(), start_from="toeless")
    assert got[7] == replace(st, continuation=(), start_from="toeless", ipopt=J.PIVTOL)
    assert J.retry_spec(P.spec("toeless", torque_limits="strength"), J.STRENGTH_RETRIES[6]) is None  # not from itself
    assert J.retry_spec(P.spec("toeless", torque_limits="strength"), J.STRENGTH_RETRIES[3]).friction_max == 1.4
    assert J.retry_spec(P.spec("ellipsoid", torque_limits="strength"), J.STRENGTH_RETRIES[3]).friction_max is None


def test_start_from_keeps_the_keys_and_puts_the_missing_toe_flat():
    """``start_from`` (ours): absent from every existing key while unset, another jump only;
    the toeless solution's states and controls carry over by name, the metatarsal ones at 0."""
    from gaitlib.problems import jump as P

    for n in P.SPECS:
        assert "start_from" not in P.SPECS[n].to_dict()
    st = P.spec("toe", torque_limits="strength")
    assert P.cache_location(replace(st, start_from="toeless")) != P.cache_location(st)
    with pytest.raises(ValueError, match="start_from"):
        P.spec("toe", start_from="toe")
    with pytest.raises(ValueError, match="start_from"):
        P.spec("toe", start_from="heel")
    toe = P.build(replace(st, n_intervals=3, continuation=())).problem
    t = np.linspace(0.0, 1.0, 4)
    phases = {ph.name: SimpleNamespace(
        states=pd.DataFrame({c: 0.1 * (k + 1) + t for k, c in enumerate(ph.states)}, index=t),
        controls=pd.DataFrame({c: -t for c in ph.controls}, index=t), t0=0.0, tf=1.0)
        for ph in P.build(replace(P.spec("toeless"), n_intervals=3, continuation=())).problem.phases}
    g = P.guess_across(SimpleNamespace(phases=phases), toe)
    for ph in toe.phases:
        pg = g.phases[ph.name]
        assert list(pg.states.columns) == list(ph.states) and list(pg.controls.columns) == list(ph.controls)
        for c in ph.states:
            src = phases[ph.name].states
            expect = src[c].to_numpy() if c in src else np.zeros(4)
            assert np.array_equal(pg.states[c].to_numpy(), expect), c
        assert (pg.states[[c for c in ph.states if c.endswith("mtp")]] == 0).all().all()
    assert not g.parameters


def test_stand_in_is_a_converged_valid_retry_of_the_same_problem():
    """Of a failed jump's retries: only converged, valid ones without a friction cap the spec
    lacks stand in; the lowest objective wins; none → no stand-in."""
    def fake(obj, ok=True, cap=None):
        return SimpleNamespace(success=ok, solution=SimpleNamespace(objective=obj),
                               spec=SimpleNamespace(friction_max=cap))

    own = {"toe": fake(0.0, ok=False)}
    a, b, capped, failed = fake(20.0), fake(25.0), fake(5.0, cap=1.0), fake(1.0, ok=False)
    retries = {"toe": {1: a, 2: b, 3: capped, 4: failed}}
    assert J.strength_stand_ins(own, retries, lambda s: True) == {"toe": a}
    assert J.strength_stand_ins(own, retries, lambda s: s is b) == {"toe": b}
    assert J.strength_stand_ins(own, retries, lambda s: False) == {}


# ------------------------------------------------------------------ take-off and the cost
def test_apex_cost_spec_keeps_the_keys_and_drops_only_the_takeoff_term():
    """``start_weights`` (ours) is absent from every existing key while unset; the apex-height
    variant scales Table 3.9's take-off velocity weight only (w1 welded, w3 ellipsoid) and
    starts from the thesis's cost."""
    from gaitlib.problems import jump as P

    for n in P.SPECS:
        assert "start_weights" not in P.SPECS[n].to_dict()
    assert J.apex_cost_spec(J.SPECS["toeless"], 0.0).weights == (0.0, 12.0)
    assert J.apex_cost_spec(J.SPECS["toe"]).weights == (J.TAKEOFF_FACTOR, 1.0)
    e = J.apex_cost_spec(J.SPECS["ellipsoid"])
    assert e.weights == (2.0, 1.0, J.TAKEOFF_FACTOR, 5.0) and e.start_weights == (2.0, 1.0, 1.0, 5.0)
    assert replace(e, weights=J.SPECS["ellipsoid"].weights, start_weights=None) == J.SPECS["ellipsoid"]
    assert P.cache_location(e) != P.cache_location(replace(e, start_weights=None))
    with pytest.raises(ValueError, match="start_weights"):
        P.spec("toe", start_weights=(1.0, 1.0))  # its own weights: no other start
    with pytest.raises(ValueError, match="start_weights"):
        P.spec("toe", start_weights=(1.0, 1.0, 1.0))


def test_start_weights_starts_from_the_same_jump_with_the_other_cost(toe, monkeypatch):
    """The full mesh starts from the solution of the same spec with ``start_weights`` (no mesh
    continuation), recorded; the goal of the dropped term carries weight 0."""
    from gaitlib.problems import jump as P

    calls = []

    def fake_solve(sp, guess=None, **kw):
        calls.append(sp)
        return toe

    sp = replace(J.apex_cost_spec(toe.spec), max_iter=20)  # the wiring, not the optimum
    monkeypatch.setattr(P, "solve", fake_solve)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ocp.SolveFailedWarning)
        sol = P._solve_continued(sp, None)
    assert calls == [replace(sp, weights=toe.spec.weights, start_weights=None)]
    rec = sol.info["continuation"]
    assert len(rec) == 1 and rec[0]["start_weights"] == list(toe.spec.weights)
    goals = pd.DataFrame(sol.goals)
    assert (goals.loc[goals["goal"] == J.TAKEOFF_GOAL, "weight"] == J.TAKEOFF_FACTOR).all()
    assert (goals.loc[goals["goal"] == "apex_height", "weight"] == 1.0).all()


def _fake_jump(label, com_y, hip, knee, vy, rise, apex, goals, ok=True):
    """A stand-in for a JumpSolution: standing at com_y[0], take-off at the last node before flight."""
    tr = pd.DataFrame({"phase": ["crouch", "thrust", "thrust", "flight"], "com_y": com_y,
                       "hip": np.radians(hip), "knee": np.radians(knee), "ankle": np.zeros(4)})
    g = pd.DataFrame(goals, columns=["phase", "goal", "weight", "value", "weighted"])
    return SimpleNamespace(trajectory=tr, jump_height={"takeoff_vy": vy, "com_rise_flight": rise, "com_rise_standing": apex},
                           solution=SimpleNamespace(goals=g, objective=float(g["weighted"].sum())), success=ok,
                           status="Solve_Succeeded" if ok else "Maximum_Iterations_Exceeded",
                           spec=SimpleNamespace(label=label), stats={"iterations": 10})


def test_takeoff_state_by_hand():
    s = _fake_jump("toe", [1.10, 1.00, 1.02, 1.20], [0, 40, 70, 10], [0, -60, -45, 0], 2.0, 0.20, 0.10,
                   [("thrust", "v_takeoff", 1.0, 25.0, 25.0), ("flight", "apex_height", 1.0, 0.8, 0.8),
                    ("thrust", "reg_taud", 0.1, 0.2, 0.02)])
    t = J.takeoff_state(s)
    assert t["com_takeoff"] == pytest.approx(1.02 - 1.10)
    assert t["hip"] == pytest.approx(70.0) and t["knee"] == pytest.approx(-45.0)
    assert t["takeoff_share"] == pytest.approx(100 * 25.0 / 25.82)
    assert (t["takeoff_vy"], t["rise_flight"], t["apex"]) == (2.0, 0.20, 0.10)


def test_takeoff_findings_read_apex_runs_that_converged_and_pass_only():
    th = [("thrust", "v_takeoff", 1.0, 40.0, 40.0), ("flight", "apex_height", 12.0, 0.8, 9.6)]
    ap = [("thrust", "v_takeoff", 0.0, 50.0, 0.0), ("flight", "apex_height", 12.0, 0.7, 8.4)]
    read = {"toeless": _fake_jump("toeless", [1.1, 1.0, 0.99, 1.1], [0, 60, 70, 0], [0, -80, -46, 0], 1.5, 0.12, 0.01, th),
            "toe": _fake_jump("toe", [1.1, 1.0, 1.03, 1.3], [0, 60, 60, 0], [0, -80, -50, 0], 2.2, 0.26, 0.19, th)}
    apex = {"toeless": _fake_jump("toeless", [1.1, 1.0, 1.06, 1.1], [0, 30, 20, 0], [0, -60, -10, 0], 1.3, 0.09, 0.05, ap),
            "toe": _fake_jump("toe", [1.1, 1.0, 1.1, 1.3], [0, 30, 5, 0], [0, -60, -5, 0], 2.0, 0.2, 0.2, ap, ok=False)}
    text = " ".join(J.takeoff_findings(read, apex, {"toeless, apex": True, "toe, apex": True}))
    assert "the COM 7 to 11 cm below its standing height" in text
    assert "hips flexed 60 to 70°" in text and "the knees at -50 to -46°" in text
    assert "term is 81 % of the objective" in text  # 40 / 49.6, both jumps
    assert f"toe, take-off term × {J.TAKEOFF_FACTOR:g}: did NOT converge (Maximum_Iterations_Exceeded) — not read" in text
    assert "COM at take-off -11 → -4 cm from standing, hip 70 → 20°, knee -46 → -10°" in text
    assert "apex +1 → +5 cm" in text and "COM rise in flight 12 → 9 cm" in text
    assert f"term × {J.TAKEOFF_FACTOR:g} the apex is higher in 1 of 1 jumps and the take-off less crouched in 1 of 1" in text
    assert "is higher with it scaled down in 0 of 1 (toeless 12 → 9 cm)." in text
    assert f"Thesis: the toes raise the jump — not read: {J.LABELS['toe']} not converged or not valid." in text
    assert "not the strength envelope" in text


def test_takeoff_clause_for_the_card():
    th = [("thrust", "v_takeoff", 1.0, 40.0, 40.0), ("flight", "apex_height", 12.0, 0.8, 10.0)]
    ap = [("thrust", "v_takeoff", 0.01, 50.0, 0.5), ("flight", "apex_height", 12.0, 0.7, 8.4)]
    read = _fake_jump("toeless", [1.1, 1.0, 0.99, 1.1], [0, 60, 70, 0], [0, -80, -46, 0], 1.5, 0.12, 0.01, th)
    good = _fake_jump("toeless", [1.1, 1.0, 1.06, 1.1], [0, 30, 20, 0], [0, -60, -10, 0], 1.3, 0.09, 0.05, ap)
    c = J.takeoff_clause(read, None, False)
    assert c == "leaves the ground crouched (COM -11 cm from standing, hip 70°, knee -46°), Table 3.9's take-off velocity term 80 % of the objective"
    assert J.takeoff_clause(read, good, False).endswith(f"with it × {J.TAKEOFF_FACTOR:g}: fails a validity gate")
    assert J.takeoff_clause(read, good, True).endswith("apex +1 → +5 cm from the standing COM; COM rise in flight 12 → 9 cm")
