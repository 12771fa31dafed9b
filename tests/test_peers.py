"""Tests of ``benchmarks/moco/peers.py`` (the T9-track benchmark's peer model): the planar
model read from Moco's 2D_gait.osim, its smooth sphere contact, and the replicas of Moco's
reference-data processing. OpenSim is never imported; the OpenSim comparisons use numbers
that ``benchmarks/moco/moco_side.py`` wrote with opensim 4.6 (``benchmarks/moco/opensim_check/``)."""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from moco.peers import (  # benchmarks/ is on sys.path (tests/conftest.py)
    OSIM_GRAVITY,
    NaturalQuinticSpline,
    opensim_lowpass,
    osim_planar_model,
    read_sto,
    smooth_sphere_halfspace_force,
)

MOCO = Path(__file__).resolve().parents[1] / "benchmarks" / "moco"
OSIM = MOCO / "2D_gait.osim"
CHECK = MOCO / "opensim_check"
LEG = ("femur", "tibia", "talus", "calcn", "toes")


@pytest.fixture(scope="module")
def model():
    return osim_planar_model(OSIM)


@pytest.fixture(scope="module")
def xml_bodies():
    """name -> (mass, com (3,)) straight from the XML."""
    root = ET.parse(OSIM).getroot()
    out = {}
    for b in root.iterfind("Model/BodySet/objects/Body"):
        out[b.get("name")] = (float(b.findtext("mass")),
                              np.array([float(v) for v in b.findtext("mass_center").split()]))
    return out


def _q(model, **values):
    q = np.zeros(model.n)
    for k, v in values.items():
        q[model.coord_index(k)] = v
    return q


# ------------------------------------------------------------------------------- structure
def test_structure(model, xml_bodies):
    assert model.coords == ("pelvis_tx", "pelvis_ty", "pelvis_tilt", "hip_flexion_l",
                            "hip_flexion_r", "knee_angle_l", "knee_angle_r", "ankle_angle_l",
                            "ankle_angle_r")
    assert set(model.welded) == {"lumbar", "subtalar_l", "subtalar_r", "mtp_l", "mtp_r"}
    assert model.parts["pelvis"] == ("pelvis", "torso")
    assert set(model.parts["talus_r"]) == {"talus_r", "calcn_r", "toes_r"}
    assert model.gravity == OSIM_GRAVITY
    assert len(model.contacts) == 4
    assert sum("Muscle" not in n for n in model.ignored) >= 1  # lumbarAct, muscles ignored


def test_total_mass_is_sum_of_osim_bodies(model, xml_bodies):
    total = sum(m for m, _ in xml_bodies.values())
    assert model.total_mass() == pytest.approx(total, rel=1e-14)
    assert total == pytest.approx(62.0, abs=1e-9)


# ----------------------------------------------------------------- statics without contact
def _com_x_by_hand(xml_bodies, side, hip_angle=0.0):
    """World x of each leg body's COM relative to the hip, leg rotated by ``hip_angle`` about
    the hip (knee, ankle 0; pelvis upright): joint offsets typed from the XML."""
    knee = np.array([-0.0045122123214679797, -0.39690724592144699])
    ankle = knee + np.array([0.0, -0.41569482537490499])
    calcn = ankle + np.array([-0.044572091911732101, -0.038339127654237401])
    toes = calcn + np.array([0.16340967877419901, -0.00182784875586352])
    origin = {"femur": np.zeros(2), "tibia": knee, "talus": ankle, "calcn": calcn,
              "toes": toes}
    c, s = math.cos(hip_angle), math.sin(hip_angle)
    out = {}
    for b in LEG:
        m, com = xml_bodies[f"{b}_{side}"]
        p = origin[b] + com[:2]
        out[b] = (m, c * p[0] - s * p[1])
    return out


@pytest.mark.parametrize("hip", [0.0, 0.5])
def test_static_gravity_torques(model, xml_bodies, hip):
    """Pose in the air (no contact), at rest: Q_joint = g Σ_subtree m (x_com − x_joint)."""
    q = _q(model, pelvis_ty=2.0, hip_flexion_r=hip)
    ct = model.contact(q, np.zeros(model.n))
    assert np.all(np.abs(ct["fy"]) == 0.0) and np.all(np.abs(ct["fx"]) == 0.0)
    Q = model.inverse_dynamics(q, np.zeros(model.n), np.zeros(model.n))
    g = OSIM_GRAVITY
    legr = _com_x_by_hand(xml_bodies, "r", hip)
    hip_r = g * sum(m * x for m, x in legr.values())
    assert Q[model.coord_index("hip_flexion_r")] == pytest.approx(hip_r, rel=1e-12)
    # knee of the rotated right leg: bodies below the knee, lever from the knee centre
    knee_x = math.cos(hip) * -0.0045122123214679797 - math.sin(hip) * -0.39690724592144699
    knee_r = g * sum(m * (x - knee_x) for b, (m, x) in legr.items() if b != "femur")
    assert Q[model.coord_index("knee_angle_r")] == pytest.approx(knee_r, rel=1e-12)
    # root: vertical force = weight, no horizontal force
    assert Q[model.coord_index("pelvis_ty")] == pytest.approx(model.total_mass() * g, rel=1e-14)
    assert Q[model.coord_index("pelvis_tx")] == pytest.approx(0.0, abs=1e-9)
    # root moment about the pelvis origin = g Σ m x over all bodies
    legl = _com_x_by_hand(xml_bodies, "l", 0.0)
    mp, cp = xml_bodies["pelvis"]
    mt, ct_ = xml_bodies["torso"]
    torso_x = -0.0972499926058214 + ct_[0]
    hip_x = -0.068277800171117897
    mom = g * (mp * cp[0] + mt * torso_x + sum(m * (x + hip_x) for m, x in legr.values())
               + sum(m * (x + hip_x) for m, x in legl.values()))
    assert Q[model.coord_index("pelvis_tilt")] == pytest.approx(mom, rel=1e-12)


def test_mass_matrix_symmetric_positive_and_forward_inverse_consistent(model):
    rng = np.random.default_rng(3)
    q = _q(model, pelvis_ty=0.93, pelvis_tilt=-0.2, hip_flexion_r=0.4, knee_angle_r=-0.5,
           ankle_angle_l=0.2)
    M = model.mass_matrix(q)
    np.testing.assert_allclose(M, M.T, atol=1e-14)
    assert np.linalg.eigvalsh(M).min() > 0
    assert M[1, 1] == pytest.approx(model.total_mass(), rel=1e-14)
    qd = rng.normal(size=model.n)
    tau = rng.normal(size=model.n) * 20
    qdd = model.forward_dynamics(q, qd, tau)
    np.testing.assert_allclose(model.inverse_dynamics(q, qd, qdd), tau, atol=1e-8)


# ------------------------------------------------------------------------------ contact
def _hand_force(s, d, vx, vy):
    """Simbody's SmoothSphereHalfSpaceForce, written out with numpy."""
    k = 0.5 * s.stiffness ** (2 / 3)
    fh = 4 / 3 * k * math.sqrt(s.radius * k) * (d * d + s.constant_contact_force) ** 0.75
    fh *= 0.5 + 0.5 * math.tanh(s.hertz_smoothing * d)
    vn = -vy
    c = s.dissipation
    fhc = fh * (1 + 1.5 * c * vn) * (0.5 + 0.5 * math.tanh(
        s.hunt_crossley_smoothing * (vn + 2 / (3 * c))))
    vs = math.sqrt(vx * vx + s.constant_contact_force)
    vr = vs / s.transition_velocity
    mu = min(vr, 1.0) * (s.dynamic_friction + 2 * (s.static_friction - s.dynamic_friction)
                         / (1 + vr * vr)) + s.viscous_friction * vs
    return -fhc * mu * vx / vs, fhc


def test_contact_parameters_from_xml(model):
    heel = next(c for c in model.contacts if c.name == "contactHeel_r")
    assert heel.radius == 0.035 and heel.stiffness == 3067776.0 and heel.dissipation == 2.0
    assert (heel.static_friction, heel.dynamic_friction, heel.viscous_friction) == (0.8, 0.8,
                                                                                    0.5)
    assert heel.transition_velocity == 0.2 and heel.constant_contact_force == 1e-5
    assert (heel.hertz_smoothing, heel.hunt_crossley_smoothing) == (300.0, 50.0)
    # heel sphere: calcn location + calcn origin in the talus frame
    np.testing.assert_allclose(
        heel.center, (0.031307527581931796 - 0.044572091911732101,
                      0.010435842527310599 - 0.038339127654237401), rtol=1e-15)


@pytest.mark.parametrize("depth, vx, vy", [(1e-3, 0.0, 0.0), (5e-3, 0.05, -0.1),
                                           (2e-3, 0.6, 0.2), (-5e-3, 0.3, 0.0)])
def test_sphere_force_matches_hand_formula(model, depth, vx, vy):
    """Place the right heel sphere at a given indentation; the model's force equals Simbody's
    formula evaluated by hand (for a translating body, every point moves with qd[:2])."""
    heel = next(c for c in model.contacts if c.name == "contactHeel_r")
    i = [c.name for c in model.contacts].index("contactHeel_r")
    q = _q(model, pelvis_ty=1.0)
    y = float(model.function("points")(q)[list(model.function("points").name_out())
                                            .index("sphere_contactHeel_r")][1])
    q[model.coord_index("pelvis_ty")] += (heel.radius - depth) - y
    qd = _q(model, pelvis_tx=vx, pelvis_ty=vy)
    ct = model.contact(q, qd)
    assert ct["depth"][i] == pytest.approx(depth, abs=1e-12)
    fx, fy = _hand_force(heel, depth, vx, vy)
    assert ct["fy"][i] == pytest.approx(fy, rel=1e-12, abs=1e-300)
    assert ct["fx"][i] == pytest.approx(fx, rel=1e-12, abs=1e-300)
    assert ct["py"][i] == pytest.approx(-0.5 * depth, abs=1e-12)
    f = smooth_sphere_halfspace_force(heel.radius - depth, vx, vy, heel)
    assert float(f["fy"]) == pytest.approx(fy, rel=1e-12, abs=1e-300)


# -------------------------------------------------------------- agreement with OpenSim 4.6
@pytest.mark.skipif(not (CHECK / "moco_dynamics_check.json").exists(),
                    reason="no OpenSim check data")
def test_forward_dynamics_and_contact_match_opensim(model):
    """Accelerations and sphere forces at random states equal OpenSim's (written by
    ``moco_side.py --check-dynamics``): the same model, to rounding."""
    data = json.loads((CHECK / "moco_dynamics_check.json").read_text())
    names = [c.name for c in model.contacts]
    for s in data["samples"]:
        q = np.array([s["q"][c] for c in model.coords])
        qd = np.array([s["qd"][c] for c in model.coords])
        tau = np.array([150.0 * s["u"].get(c, 0.0) for c in model.coords])
        ref = np.array([s["qdd"][c] for c in model.coords])
        qdd = model.forward_dynamics(q, qd, tau)
        np.testing.assert_allclose(qdd, ref, rtol=1e-9, atol=1e-9 * (1 + np.abs(ref).max()))
        ct = model.contact(q, qd)
        for nm, rec in s["sphere_record"].items():
            j = names.index(nm)
            fx, fy = rec[0], rec[1]  # force on the sphere's body, ground frame
            scale = 1.0 + abs(fy)
            assert ct["fx"][j] == pytest.approx(fx, abs=1e-10 * scale)
            assert ct["fy"][j] == pytest.approx(fy, abs=1e-10 * scale)


@pytest.mark.skipif(not (CHECK / "moco_reference.json").exists(),
                    reason="no OpenSim check data")
def test_reference_processing_matches_moco():
    data = json.loads((CHECK / "moco_reference.json").read_text())
    raw = read_sto(MOCO / "referenceCoordinates.sto")
    filt = opensim_lowpass(raw, 6.0)
    assert list(filt.columns) == data["labels"]
    np.testing.assert_allclose(filt.index.to_numpy(), data["time"], atol=1e-15)
    np.testing.assert_allclose(filt.to_numpy(), data["filtered"], atol=1e-12)
    sp = NaturalQuinticSpline(filt.index.to_numpy(), filt.to_numpy())
    np.testing.assert_allclose(sp(np.array(data["spline_time"])), data["spline_values"],
                               atol=1e-12)


def test_natural_quintic_spline():
    x = np.linspace(0.0, 1.0, 12) ** 1.2
    y = np.sin(3 * x)
    s = NaturalQuinticSpline(x, y)
    np.testing.assert_allclose(s(x), y, atol=1e-13)
    for nu in (3, 4):
        assert abs(s(x[0], nu)) < 1e-8 and abs(s(x[-1], nu)) < 1e-8
    # reproduces polynomials of degree <= 2 exactly (natural end conditions hold for them)
    np.testing.assert_allclose(NaturalQuinticSpline(x, 1 + 2 * x - x**2)(0.37),
                               1 + 0.74 - 0.37**2, atol=1e-13)


def test_lowpass_passes_slow_and_removes_fast_signals():
    """OpenSim's 3rd-order Butterworth, forward and backward: constants unchanged, 1 Hz
    kept, 40 Hz removed (6 Hz cut-off, 200 Hz sampling)."""
    import pandas as pd

    t = np.arange(200) * 0.005
    slow, fast = np.sin(2 * np.pi * 1.0 * t), np.sin(2 * np.pi * 40.0 * t)
    frame = pd.DataFrame({"c": np.full(t.size, 2.5), "slow": slow, "fast": fast}, index=t)
    out = opensim_lowpass(frame, 6.0)
    np.testing.assert_allclose(out["c"], 2.5, atol=1e-12)
    mid = slice(50, 150)
    np.testing.assert_allclose(out["slow"].to_numpy()[mid], slow[mid], atol=0.01)
    assert np.abs(out["fast"].to_numpy()[mid]).max() < 0.01
