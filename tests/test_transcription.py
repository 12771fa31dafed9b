"""Gait formulation: builds at low resolution, weights from the thesis tables, references,
and a failed solve is reported as failed."""

from __future__ import annotations

import numpy as np
import pytest

from gaitlib import conventions as cv
from gaitlib import transcription as tr


def test_cost_function_weights_match_thesis_tables():
    # Table 4.8 (Eq 4.11) and Sec 4.4 (w5 = w6 = 1/4)
    assert tr.COST_FUNCTIONS["SK"]["Eq4.11"] == {"Trq": 0.25, "GRF": 0.25, "Q": 0.25, "Jrk": 0.025}
    assert tr.COST_FUNCTIONS["SK"]["Eq4.13"]["Imp"] == 0.25 and tr.COST_FUNCTIONS["SK"]["Eq4.13"]["Rsd"] == 0.25
    # Table 5.3
    assert tr.COST_FUNCTIONS["MSK"]["Eq5.33"]["Act"] == 0.01 and tr.COST_FUNCTIONS["MSK"]["Eq5.33"]["Imp"] == 0.025
    # Table 6.2 MSK rows: SP1 and FP
    assert tr.COST_FUNCTIONS["MSK"]["SP1"] == {"Jrk": 0.025, "Rsd": 0.1, "Imp": 1 / 3, "HAT": 0.5, "Act": 0.01, "GRF": 0.25}
    assert "Trq" not in tr.COST_FUNCTIONS["MSK"]["FP"] and "Ang" not in tr.COST_FUNCTIONS["MSK"]["FP"]


def test_spec_validation_and_key():
    with pytest.raises(ValueError, match="unknown cost"):
        tr.GaitSpec(model="SK", cost="SP9")
    with pytest.raises(ValueError, match="unknown cost term"):
        tr.GaitSpec(weights=(("Jerk", 1.0),))
    a, b = tr.GaitSpec(), tr.GaitSpec(n_intervals=10)
    assert a.key() == tr.GaitSpec().key() and a.key() != b.key()


@pytest.mark.parametrize("model", ["SK", "MSK"])
def test_gait_problem_builds_with_expected_dimensions(model):
    cost = "DT"
    gp = tr.build(tr.GaitSpec(model=model, cost=cost, n_intervals=4, degree=3))
    ph = gp.problem.phases[0]
    assert len(ph.states) == 33
    n_act = 8 if model == "SK" else 2 + 12
    assert len(ph.controls) == 11 + 3 + n_act
    assert {g.name for g in ph.goals} == set(gp.spec.term_weights)
    # the guess covers every state and control
    g = gp.guess.phases["cycle"]
    assert set(g.states) == set(ph.states) and set(g.controls) == set(ph.controls)


def test_reference_hat_height_puts_lowest_ellipsoid_at_2mm():
    gp = tr.build(tr.GaitSpec(n_intervals=4, degree=3))
    ref, model = gp.ref, gp.model
    # the pelvis reference advances at the data's speed
    t = ref.q.index.to_numpy()
    np.testing.assert_allclose(ref.q["pelvis_tx"], ref.gait.speed * t)
    # Fourier derivatives agree with the samples they were fitted to
    v = ref.deriv["knee_r"](t)
    assert np.max(np.abs(v[0] - ref.q["knee_r"])) < np.deg2rad(1.0)
    # lowest ellipsoid point 2 mm below the ground in the reference pose
    from gaitlib import contact
    pc = contact.default_params()
    radii = [pc[13 * k + 4:13 * k + 7] for k in range(3)] * 2
    for n in (0, 12, 30):
        q = ref.q.iloc[n].to_numpy()
        C, Rs = model.ellipsoid_poses(q, pc)
        low = min(C[e, 1] - np.sqrt((Rs[e] @ np.diag(np.square(radii[e])) @ Rs[e].T)[1, 1]) for e in range(6))
        assert low == pytest.approx(-0.002, abs=1e-9)
    # jerk ranges are finite and positive
    assert all(np.isfinite(ref.ranges[f"jerk_{c}"]) and ref.ranges[f"jerk_{c}"] > 0 for c in cv.COORDS)


def test_failed_gait_solve_is_reported_as_failed():
    with pytest.warns(UserWarning, match="FAILED"):
        gs = tr.solve(tr.GaitSpec(n_intervals=3, degree=3, max_iter=2))
    assert not gs.success and gs.stats["status"] == "Maximum_Iterations_Exceeded"
    assert gs.stats["iterations"] == 2
