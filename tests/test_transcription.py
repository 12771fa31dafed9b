"""Gait formulation: builds at low resolution, weights from the thesis tables, references,
and a failed solve is reported as failed."""

from __future__ import annotations

import numpy as np
import pytest

from gaitlib import conventions as cv
from gaitlib.problems import gait as gait_ocp


def test_cost_function_weights_match_thesis_tables():
    # Table 4.8 (Eq 4.11) and Sec 4.4 (w5 = w6 = 1/4)
    assert gait_ocp.COST_FUNCTIONS["SK"]["Eq4.11"] == {"Trq": 0.25, "GRF": 0.25, "Q": 0.25, "Jrk": 0.025}
    assert gait_ocp.COST_FUNCTIONS["SK"]["Eq4.13"]["Imp"] == 0.25 and gait_ocp.COST_FUNCTIONS["SK"]["Eq4.13"]["Rsd"] == 0.25
    # Table 5.3
    assert gait_ocp.COST_FUNCTIONS["MSK"]["Eq5.33"]["Act"] == 0.01 and gait_ocp.COST_FUNCTIONS["MSK"]["Eq5.33"]["Imp"] == 0.025
    # Table 6.2 MSK rows: SP1 and FP
    assert gait_ocp.COST_FUNCTIONS["MSK"]["SP1"] == {"Jrk": 0.025, "Rsd": 0.1, "Imp": 1 / 3, "HAT": 0.5, "Act": 0.01, "GRF": 0.25}
    assert "Trq" not in gait_ocp.COST_FUNCTIONS["MSK"]["FP"] and "Ang" not in gait_ocp.COST_FUNCTIONS["MSK"]["FP"]


def test_spec_validation_and_key():
    with pytest.raises(ValueError, match="unknown cost"):
        gait_ocp.GaitSpec(model="SK", cost="SP9")
    with pytest.raises(ValueError, match="unknown cost term"):
        gait_ocp.GaitSpec(weights=(("Jerk", 1.0),))
    a, b = gait_ocp.GaitSpec(), gait_ocp.GaitSpec(n_intervals=10)
    assert a.key() == gait_ocp.GaitSpec().key() and a.key() != b.key()


@pytest.mark.parametrize("model", ["SK", "MSK"])
def test_gait_problem_builds_with_expected_dimensions(model):
    cost = "DT"
    gp = gait_ocp.build(gait_ocp.GaitSpec(model=model, cost=cost, n_intervals=4, degree=3))
    ph = gp.problem.phases[0]
    assert len(ph.states) == 33
    n_act = 8 if model == "SK" else 2 + 12
    assert len(ph.controls) == 11 + 3 + n_act
    assert {g.name for g in ph.goals} == set(gp.spec.term_weights)
    # the guess covers every state and control
    g = gp.guess.phases["cycle"]
    assert set(g.states) == set(ph.states) and set(g.controls) == set(ph.controls)


def test_reference_hat_height_carries_the_data_vertical_load():
    gp = gait_ocp.build(gait_ocp.GaitSpec(n_intervals=4, degree=3))
    ref, model = gp.ref, gp.model
    # the pelvis reference advances at the data's speed
    t = ref.q.index.to_numpy()
    np.testing.assert_allclose(ref.q["pelvis_tx"], ref.gait.speed * t)
    # Fourier derivatives agree with the samples they were fitted to
    v = ref.deriv["knee_r"](t)
    assert np.max(np.abs(v[0] - ref.q["knee_r"])) < np.deg2rad(1.0)
    # height_for_load: at the returned height the contact (at rest) carries the load exactly
    from gaitlib import contact, kinematics
    pc = contact.default_params()
    Q = ref.q.to_numpy()[[0, 12, 25, 40]]
    load = np.array([300.0, 406.5, 520.0, 150.0])
    ty = kinematics.height_for_load(model, Q, load, pc)
    for q, y, f in zip(Q, ty, load):
        q = q.copy()
        q[1] = y
        fy = model.function("contact")(q=q, qd=np.zeros(11), p_contact=pc)["grf_y"]
        assert float(np.sum(np.asarray(fy))) == pytest.approx(f, abs=1e-4)
    # the smoothed reference height stays within 5 mm of the per-frame estimate
    load = (ref.gait.mean["grf_y_r"] + ref.gait.mean["grf_y_l"]).to_numpy()
    raw = kinematics.height_for_load(model, ref.q.to_numpy(), load, pc)
    assert np.max(np.abs(raw - ref.q["pelvis_ty"].to_numpy())) < 0.005
    # jerk ranges are finite and positive
    assert all(np.isfinite(ref.ranges[f"jerk_{c}"]) and ref.ranges[f"jerk_{c}"] > 0 for c in cv.COORDS)


def test_height_for_load_reports_an_impossible_load():
    gp = gait_ocp.build(gait_ocp.GaitSpec(n_intervals=4, degree=3))
    from gaitlib import kinematics
    with pytest.raises(ValueError, match="row 0"):
        kinematics.height_for_load(gp.model, gp.ref.q.to_numpy()[:1], [1e7], below=0.01)


def test_spec_round_trip():
    s = gait_ocp.GaitSpec(model="MSK", cost="SDT2", weights=(("Jrk", 0.1),), residual_bounds=(2.0, 2.0, 0.2))
    assert gait_ocp.GaitSpec.from_dict(s.to_dict()) == s and gait_ocp.GaitSpec.from_dict(s.to_dict()).key() == s.key()


def test_failed_gait_solve_is_reported_as_failed():
    with pytest.warns(UserWarning, match="FAILED"):
        gs = gait_ocp.solve(gait_ocp.GaitSpec(n_intervals=3, degree=3, max_iter=2))
    assert not gs.success and gs.stats["status"] == "Maximum_Iterations_Exceeded"
    assert gs.stats["iterations"] == 2


def test_every_weighted_cost_term_has_a_goal_factory_for_its_model():
    """Each term a cost function weights (COST_FUNCTIONS) is a named goal factory of
    COST_TERMS that is defined for that model (Act not for SK; Mtb only for NMSK)."""
    from collections import defaultdict

    from gaitlib.problems import gait as gp_mod

    ctx = {m: gp_mod.GoalContext(model=m, ranges=defaultdict(lambda: 1.0), node=None, tf_of=None, stride=1.0) for m in gp_mod.COST_FUNCTIONS}
    for model, costs in gp_mod.COST_FUNCTIONS.items():
        for cost, weights in costs.items():
            for term in weights:
                assert term in gp_mod.COST_TERMS, (model, cost, term)
                assert gp_mod.COST_TERMS[term](ctx[model]) is not None, (model, cost, term)
    assert gp_mod.goal_act(ctx["SK"]) is None and gp_mod.goal_mtb(ctx["MSK"]) is None


def test_q_term_leaves_the_planned_metatarsal_angles_out_only_when_asked():
    """GaitSpec.track_mtp=False drops exactly the two metatarsal angles from Q: an offset of
    0.2 rad at mtp_r (range 0.4 rad) costs (0.2 / 0.4)² = 0.25 when tracked and nothing when
    not; an offset at the knee costs the same either way. The unset option keeps the key."""
    from collections import defaultdict

    from gaitlib import conventions as cv
    from gaitlib.problems import gait as gp_mod

    rg = defaultdict(lambda: 0.4)
    d = {f"ref_{k}": 0.0 for k in cv.COORDS}
    tracked = gp_mod.goal_q(gp_mod.GoalContext(model="SK", ranges=rg, node=None, tf_of=None, stride=1.0))
    untracked = gp_mod.goal_q(gp_mod.GoalContext(model="SK", ranges=rg, node=None, tf_of=None, stride=1.0,
                                                 q_tracked=tuple(k for k in cv.COORDS if not k.startswith("mtp"))))
    x_mtp = {k: (0.2 if k == "mtp_r" else 0.0) for k in cv.COORDS}
    x_knee = {k: (0.2 if k == "knee_r" else 0.0) for k in cv.COORDS}
    assert tracked(x_mtp, None, None, 0.0, d) == pytest.approx(0.25)
    assert untracked(x_mtp, None, None, 0.0, d) == 0.0
    assert untracked(x_knee, None, None, 0.0, d) == tracked(x_knee, None, None, 0.0, d) == pytest.approx(0.25)
    base = gp_mod.GaitSpec(model="MSK")
    from dataclasses import replace

    assert replace(base, track_mtp=None).key() == base.key() != replace(base, track_mtp=False).key()


def test_fourier_order_option_generates_the_left_leg_and_keeps_every_existing_key():
    """GaitSpec.fourier_order: unset keeps the key (the thesis's order 5, Eqs 4.1–4.3); the
    highest order the 51-sample data carry puts the right leg's samples, shifted half a cycle
    (the data's opposite foot contact, 50 %), on the left leg; five harmonics do not: they ring
    below zero in the vertical force's swing, which no contact model produces."""
    from dataclasses import replace

    import numpy as np

    from gaitlib import data as data_mod
    from gaitlib.problems import gait as gp_mod

    base = gp_mod.GaitSpec(model="SK")
    assert "fourier_order" not in base.to_dict()
    exact = replace(base, fourier_order=gp_mod.EXACT_FOURIER_ORDER)
    assert replace(base, fourier_order=None).key() == base.key() != exact.key()
    assert gp_mod.GaitSpec.from_dict(exact.to_dict()) == exact
    for bad in (0, 26, 2.5):
        with pytest.raises(ValueError, match="fourier_order"):
            gp_mod.GaitSpec(model="SK", fourier_order=bad)
    with pytest.raises(ValueError, match="effects"):
        gp_mod.GaitSpec(model="SK", fourier_order=25, effects=(("left_shift", 0.01),))
    g5 = data_mod.load_gait_data("Free", fourier_order=gp_mod.FOURIER_ORDER)
    g25 = data_mod.load_gait_data("Free", fourier_order=gp_mod.EXACT_FOURIER_ORDER)
    assert g5.left_shift == g25.left_shift == 0.5
    r = g25.mean["grf_y_r"].to_numpy()
    shifted = np.roll(r[:-1], -25)  # x(t + 0.5) on the 50 distinct samples of the cycle
    l25, l5 = g25.mean["grf_y_l"].to_numpy()[:-1], g5.mean["grf_y_l"].to_numpy()[:-1]
    assert np.sqrt(np.mean((l25 - shifted) ** 2)) < 0.02 * np.ptp(r)  # ≈ 0.3 N of a ≈ 500 N range
    assert l25.min() > -1.0 and r.min() >= 0.0
    assert l5.min() < -10.0  # the order-5 series rings below zero in swing (N)


def test_build_reads_the_data_with_default_arguments_unless_fourier_order_is_set(monkeypatch):
    """A gap diagnosis on a user's data set substitutes gaitlib.data.load_gait_data for its
    default arguments only (gaitlib.studies.gap.own_data): build() must call it so."""
    from gaitlib import data as data_mod
    from gaitlib.problems import gait as gp_mod

    calls = []

    class Stop(Exception):
        pass

    def spy(*a, **k):
        calls.append(k)
        raise Stop

    monkeypatch.setattr(data_mod, "load_gait_data", spy)
    for order, expected in ((None, {}), (25, {"fourier_order": 25})):
        calls.clear()
        with pytest.raises(Stop):
            gp_mod.build(gp_mod.GaitSpec(model="SK", n_intervals=2, degree=2, fourier_order=order))
        assert calls == [expected]


def test_rebuilt_problems_share_model_functions_and_heights_to_the_bit():
    """A problem rebuilt on the same data (each cached gap solution loaded) reuses the model's
    SX functions and the reference heights — the same numbers as computed afresh."""
    from gaitlib import contact, kinematics
    from gaitlib import model as model_mod
    a, b, heavy = model_mod.ChildModel(), model_mod.ChildModel(), model_mod.ChildModel(body_mass=45.0)
    assert a.function("contact") is b.function("contact")
    assert heavy.function("inverse_dynamics") is not a.function("inverse_dynamics")
    gp = gait_ocp.build(gait_ocp.GaitSpec(n_intervals=4, degree=3))
    pc = contact.default_params()
    Q = gp.ref.q.to_numpy()[[0, 12, 25]]
    load = np.array([300.0, 406.5, 520.0])
    first = kinematics.height_for_load(gp.model, Q, load, pc)
    first[:] = 0.0  # a copy: the caller's changes do not reach the next call
    again = kinematics.height_for_load(gp.model, Q, load, pc)
    kinematics._HEIGHTS.clear()
    fresh = kinematics.height_for_load(gp.model, Q, load, pc)
    np.testing.assert_array_equal(again, fresh)
    # another load (1 N more on one row) is searched again: its row rises, the others stay
    other = kinematics.height_for_load(gp.model, Q, load + np.array([0.0, 1.0, 0.0]), pc)
    assert other[1] < fresh[1] and other[0] == fresh[0] and other[2] == fresh[2]
    # and the rebuilt problem's reference is the first one's, to the bit
    np.testing.assert_array_equal(gait_ocp.build(gait_ocp.GaitSpec(n_intervals=4, degree=3)).ref.q.to_numpy(),
                                  gp.ref.q.to_numpy())
