"""Physics tests of gaitlib.model (11-DOF child model) and gaitlib.jump (Ch 3 jump models)."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from gaitlib import contact
from gaitlib import conventions as cv
from gaitlib.jump import JUMP_SEGMENTS, JumpModel
from gaitlib.model import ELLIPSOID_LABELS, P_BODY_NAMES, ChildModel, solve_spd

N = len(cv.COORDS)


@pytest.fixture(scope="module")
def model():
    return ChildModel()


@pytest.fixture(scope="module")
def standing_height(model):
    """pelvis_ty (all angles 0, at rest) where the contact carries the weight: R_y = 0."""

    def r_y(y):
        q = np.zeros(N)
        q[1] = y
        return model.inverse_dynamics(q, np.zeros(N), np.zeros(N))[1][1]

    L = model.standing_leg_length
    return brentq(r_y, L - 0.005, L + 0.08, xtol=1e-12)


def _contact_state(model, standing_height, rng, scale=0.05):
    """A random state near standing with the feet in contact."""
    q = rng.normal(size=N) * scale
    q[0] = 0.0
    q[1] = standing_height - 0.004
    qd = rng.normal(size=N) * 0.3
    return q, qd


# ----------------------------------------------------------------------------- parameters
def test_parameters_defaults_and_bounds(model):
    p = model.default_p_body()
    assert p.shape == (25,) and len(P_BODY_NAMES) == 25
    d = model.p_body_dict(p)
    # Table 4.15 "initial" column (BM 41.4 kg, BH 1.47 m) for masses and COMs
    np.testing.assert_allclose(
        [d["mass_hat"], d["mass_thigh"], d["mass_forefoot"], d["mass_hindfoot"]],
        [28.1, 4.14, 0.257, 0.257], rtol=3e-3)
    np.testing.assert_allclose(
        [d["com_thigh"], d["com_shank"], d["com_toe"], d["com_forefoot"]],
        [0.1559, 0.1566, 0.0316, 0.0477], rtol=2e-3)
    np.testing.assert_allclose(d["moi_hat"], 1.24, rtol=3e-3)
    lb, ub = model.p_body_bounds()
    np.testing.assert_allclose(lb[:17], 0.5 * p[:17])
    np.testing.assert_allclose(ub[:17], 1.5 * p[:17])
    np.testing.assert_allclose(lb[17:], 0.0)
    np.testing.assert_allclose(ub[17:], 3.0 * p[17:])
    # standing leg length agrees with conventions
    assert model.standing_leg_length == pytest.approx(cv.leg_length(model.body_height))


def test_mass_matrix_spd_and_total_mass(model):
    """M symmetric positive definite; M[0,0] = M[1,1] = total mass = 1.001 BM
    (0.678 + 2 (0.100 + 0.047 + 0.0021 + 0.0062 + 0.0062) = 1.0010 of BM)."""
    p = model.default_p_body()
    total = model.total_mass(p)
    assert total == pytest.approx(1.001 * cv.BODY_MASS, rel=1e-12)
    rng = np.random.default_rng(0)
    for _ in range(5):
        q = rng.normal(size=N)
        M = model.mass_matrix(q, p)
        assert np.abs(M - M.T).max() < 1e-12
        assert np.linalg.eigvalsh(M).min() > 0
        assert M[0, 0] == pytest.approx(total) and M[1, 1] == pytest.approx(total)
        assert M[0, 1] == pytest.approx(0.0, abs=1e-12)


def test_solve_spd_matches_numpy():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(6, 6))
    A = A @ A.T + 6 * np.eye(6)
    b = rng.normal(size=6)
    x = np.asarray(solve_spd(ca.DM(A), ca.DM(b))).ravel()
    np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=1e-12)


def test_mass_matrix_and_bias_consistent_with_inverse_dynamics(model, standing_height):
    """[R; tau] = M qdd + h - Q_passive - Q_contact with M, h, Q_contact from their own
    functions (an independent path: M is the qdd-Jacobian, Q_contact from the contact
    function)."""
    rng = np.random.default_rng(1)
    p, pc = model.default_p_body(), contact.default_params()
    q, qd = _contact_state(model, standing_height, rng)
    qdd = rng.normal(size=N)
    tau, R = model.inverse_dynamics(q, qd, qdd, p, pc)
    Qc = model.contact(q, qd, pc)["Q"]
    K = np.tile(p[17:21], 2)
    B = np.tile(p[21:25], 2)
    Qp = np.concatenate([np.zeros(3), -K * q[3:] - B * qd[3:]])
    rhs = model.mass_matrix(q, p) @ qdd + model.bias(q, qd, p) - Qp - Qc
    np.testing.assert_allclose(np.concatenate([R, tau]), rhs, rtol=1e-10, atol=1e-8)


# ----------------------------------------------------------------------------- dynamics
def test_energy_conserved_in_free_flight():
    """No dampers, no contact (k_v = 0, unsmoothed force clamp): T + V_gravity + V_spring is
    constant along a 1 s flight with random joint motion (DOP853, rtol = atol = 1e-11)."""
    m = ChildModel(smoothing=contact.Smoothing(eps_force=0.0))
    pb = m.default_p_body()
    pb[21:] = 0.0  # B = 0; springs K kept: conservative
    pc = contact.default_params()
    pc[[contact.param_index(e, "k_v") for e in cv.ELLIPSOIDS]] = 0.0
    f = m.function("forward_dynamics")
    E = m.function("energies")
    z8, z3 = np.zeros(8), np.zeros(3)

    def rhs(t, x):
        return np.concatenate([x[N:], np.asarray(f(x[:N], x[N:], z8, z3, pb, pc)).ravel()])

    def energy(x):
        return float(sum(E(x[:N], x[N:], pb)))

    rng = np.random.default_rng(1)
    x0 = np.zeros(2 * N)
    x0[1] = 3.0
    x0[3:N] = rng.normal(size=8) * 0.3
    x0[N:] = rng.normal(size=N)
    x0[N + 1] = 5.0
    sol = solve_ivp(rhs, (0.0, 1.0), x0, method="DOP853", rtol=1e-11, atol=1e-11)
    assert sol.success
    e = np.array([energy(sol.y[:, k]) for k in range(sol.y.shape[1])])
    kinetic0 = float(E(x0[:N], x0[N:], pb)[0])
    assert kinetic0 > 100.0  # a real motion
    assert np.abs(e - e[0]).max() / abs(e[0]) < 1e-8
    # the COM follows the ballistic parabola
    com = m.function("com")
    c0, v0, _ = (np.asarray(v).ravel() for v in com(x0[:N], x0[N:], pb))
    c1 = np.asarray(com(sol.y[:N, -1], sol.y[N:, -1], pb)[0]).ravel()
    t = sol.t[-1]
    np.testing.assert_allclose(c1, c0 + v0 * t - [0.0, 0.5 * cv.G * t**2], atol=1e-8)


def test_inverse_of_forward_dynamics(model, standing_height):
    """ID(q, qd, FD(q, qd, tau, R)) returns tau and R, with contact active."""
    rng = np.random.default_rng(2)
    p, pc = model.default_p_body(), contact.default_params()
    for _ in range(5):
        q, qd = _contact_state(model, standing_height, rng)
        tau = rng.normal(size=8) * 30
        R = rng.normal(size=3) * 20
        qdd = model.forward_dynamics(q, qd, tau, R, p, pc)
        tau2, R2 = model.inverse_dynamics(q, qd, qdd, p, pc)
        np.testing.assert_allclose(tau2, tau, rtol=1e-8, atol=1e-7)
        np.testing.assert_allclose(R2, R, rtol=1e-8, atol=1e-7)
    assert np.abs(model.contact(q, qd, pc)["fn"]).max() > 10.0  # contact was engaged


def test_inverse_dynamics_with_given_grf(model, standing_height):
    """Feeding the contact model's per-foot GRF and CoP to inverse_dynamics_grf gives the
    same residuals and hip/knee/ankle torques (the mtp torque differs: the toe ellipsoid's
    load moves from the toe to the hind-fore-foot)."""
    rng = np.random.default_rng(4)
    q, qd = _contact_state(model, standing_height, rng)
    qdd = rng.normal(size=N)
    c = model.contact(q, qd)
    grf = np.array([c["grf_x"][0], c["grf_y"][0], c["cop_x"][0],
                    c["grf_x"][1], c["grf_y"][1], c["cop_x"][1]])
    assert min(c["grf_y"]) > 1.0
    tau, R = model.inverse_dynamics(q, qd, qdd)
    tau_g, R_g = model.inverse_dynamics_grf(q, qd, qdd, grf)
    np.testing.assert_allclose(R_g, R, rtol=1e-9, atol=1e-8)
    keep = [i for i, j in enumerate(cv.JOINTS) if not j.startswith("mtp")]
    np.testing.assert_allclose(tau_g[keep], tau[keep], rtol=1e-9, atol=1e-8)


def test_contact_generalised_force_is_jacobian_transpose(model, standing_height):
    """Q_contact = sum_e J_c,e^T [fx, fy] + J_theta,e^T mz (Jacobians by AD of the
    ellipsoid centres and the carrying segments' angles)."""
    rng = np.random.default_rng(5)
    pc = contact.default_params()
    q, qd = _contact_state(model, standing_height, rng)
    qs = ca.SX.sym("q", N)
    centres = model.function("ellipsoid_poses")(qs, pc)[0]  # (6, 3)
    angles = model.function("points")(q=qs, p_body=model.default_p_body())["angles"]
    Jc = ca.Function("Jc", [qs], [ca.jacobian(ca.vec(centres[:, :2].T), qs)])(q).full()
    Ja = ca.Function("Ja", [qs], [ca.jacobian(angles, qs)])(q).full()
    c = model.contact(q, qd, pc)
    body = {"toe": "toe", "ball": "foot", "heel": "foot"}
    Q = np.zeros(N)
    for k, lab in enumerate(ELLIPSOID_LABELS):
        e, s = lab.split("_")
        Q += Jc[2 * k:2 * k + 2].T @ [c["fx"][k], c["fy"][k]]
        Q += Ja[model.bodies.index(f"{body[e]}_{s}")] * c["mz"][k]
    np.testing.assert_allclose(c["Q"], Q, rtol=1e-10, atol=1e-9)


# ----------------------------------------------------------------------------- derivatives
def _check_ad_vs_fd(fun: ca.Function, args, wrt, rtol=1e-5, atol=1e-6):
    """AD Jacobian of all outputs w.r.t. input ``wrt`` vs central finite differences."""
    syms = [ca.SX.sym(f"x{i}", *fun.size_in(i)) for i in range(fun.n_in())]
    outs = ca.vertcat(*[ca.vec(o) for o in fun.call(syms)])
    J = ca.Function("J", syms, [ca.jacobian(outs, syms[wrt])])(*args).full()
    f = ca.Function("f", syms, [outs])
    x0 = np.asarray(args[wrt], dtype=float)
    Jfd = np.zeros_like(J)
    for i in range(x0.size):
        h = 1e-6 * max(1.0, abs(x0[i]))
        xp, xm = x0.copy(), x0.copy()
        xp[i] += h
        xm[i] -= h
        ap, am = list(args), list(args)
        ap[wrt], am[wrt] = xp, xm
        Jfd[:, i] = (f(*ap).full().ravel() - f(*am).full().ravel()) / (2 * h)
    scale = np.abs(J).max(axis=0, keepdims=True) + 1.0
    err = np.abs(J - Jfd) / (rtol * scale + atol)
    worst = np.unravel_index(err.argmax(), err.shape)
    assert err.max() < 1.0, f"input {wrt}: worst entry {worst}"


def test_gradients_inverse_dynamics(model, standing_height):
    rng = np.random.default_rng(6)
    q, qd = _contact_state(model, standing_height, rng)
    qdd = rng.normal(size=N)
    args = [q, qd, qdd, model.default_p_body(), contact.default_params()]
    f = model.function("inverse_dynamics")
    for wrt in range(5):
        _check_ad_vs_fd(f, args, wrt)


def test_gradients_com_and_contact(model, standing_height):
    rng = np.random.default_rng(7)
    q, qd = _contact_state(model, standing_height, rng)
    p = model.default_p_body()
    for wrt in range(3):
        _check_ad_vs_fd(model.function("com"), [q, qd, p], wrt)
    fc = model.function("contact")
    xin = fc.sx_in()
    fQ = ca.Function("Qc", xin, [fc.call(xin)[fc.index_out("Q")]])
    for wrt in range(3):
        _check_ad_vs_fd(fQ, [q, qd, contact.default_params()], wrt)


# ----------------------------------------------------------------------------- standing
def test_standing_carries_weight_through_ellipsoids(model, standing_height):
    q = np.zeros(N)
    q[1] = standing_height
    tau, R = model.inverse_dynamics(q, np.zeros(N), np.zeros(N))
    c = model.contact(q, np.zeros(N))
    weight = model.total_mass() * cv.G
    assert abs(R[1]) < 1e-6
    assert c["fn"].sum() == pytest.approx(weight, rel=1e-9)
    assert np.all(c["fn"] >= 0.0) and np.all(c["fn_raw"] >= -1e-9)
    assert c["grf_y"][0] == pytest.approx(0.5 * weight, rel=1e-9)  # both feet equal
    np.testing.assert_allclose(c["fx"], 0.0, atol=1e-9)  # at rest: no friction
    # the hip sits within a few cm of the geometric standing leg length
    assert 0.0 < standing_height - model.standing_leg_length < 0.06


def test_left_right_mirror_symmetry(model, standing_height):
    """Swapping the right and left joint angles (and rates) swaps every per-foot output."""
    rng = np.random.default_rng(8)
    q, qd = _contact_state(model, standing_height, rng, scale=0.1)
    qdd = rng.normal(size=N)
    swap = np.r_[0, 1, 2, 7, 8, 9, 10, 3, 4, 5, 6]
    c, cs = model.contact(q, qd), model.contact(q[swap], qd[swap])
    for k in ("fx", "fy", "fn", "px", "py"):
        np.testing.assert_allclose(cs[k], np.r_[c[k][3:], c[k][:3]], rtol=1e-10, atol=1e-10)
    for k in ("grf_x", "grf_y", "cop_x"):
        np.testing.assert_allclose(cs[k], c[k][::-1], rtol=1e-10, atol=1e-10)
    tau, R = model.inverse_dynamics(q, qd, qdd)
    tau_s, R_s = model.inverse_dynamics(q[swap], qd[swap], qdd[swap])
    np.testing.assert_allclose(tau_s, np.r_[tau[4:], tau[:4]], rtol=1e-10, atol=1e-8)
    np.testing.assert_allclose(R_s, R, rtol=1e-10, atol=1e-8)
    # ellipsoid centres mirror in z
    C, _ = model.ellipsoid_poses(q)
    Cs, _ = model.ellipsoid_poses(q[swap])
    np.testing.assert_allclose(Cs[3:], C[:3] * [1, 1, -1], atol=1e-12)


def test_kinematics_standing_posture(model):
    q = np.zeros(N)
    q[1] = model.standing_leg_length
    P = model.points(q)
    for s in cv.SIDES:
        np.testing.assert_allclose(P[f"heel_{s}"][1], 0.0, atol=1e-12)
        np.testing.assert_allclose(P[f"mtp_{s}"][1], 0.0, atol=1e-12)
        np.testing.assert_allclose(P[f"toe_tip_{s}"][1], 0.0, atol=1e-12)
        np.testing.assert_allclose(P[f"ankle_{s}"][1], cv.ankle_height(), atol=1e-12)
    # angle between AM and AH is beta
    fg = model.foot_geometry
    cosb = np.dot(fg["u_am"], fg["u_ah"])
    assert np.degrees(np.arccos(cosb)) == pytest.approx(106.0)
    seg = model.segments(q)
    assert seg["thigh_r"].shape == (2, 2)


# ----------------------------------------------------------------------------- jump models
@pytest.mark.parametrize("toe", [True, False])
def test_jump_static_grf_equals_weight(toe):
    """Welded-root phase, static posture: ID torques hold it still, the ground reaction is
    the weight, and its moment about the MTP point is the weight's moment."""
    m = JumpModel(toe=toe)
    nj = len(m.joints)
    rng = np.random.default_rng(9)
    qj = rng.normal(size=nj) * 0.3
    r = m.stance_inverse_dynamics(qj, np.zeros(nj), np.zeros(nj))
    W = m.total_mass * cv.G
    assert m.total_mass == pytest.approx(sum(v[0] for k, v in JUMP_SEGMENTS.items()
                                             if toe or k != "toe"))
    np.testing.assert_allclose(r["grf"][:2], [0.0, W], atol=1e-9)
    com, _ = m.com(np.r_[0.0, 0.0, 0.0, qj])
    assert r["grf"][2] == pytest.approx(W * com[0], rel=1e-10)
    assert r["cop_x"] == pytest.approx(com[0], rel=1e-10)
    # forward dynamics with those torques: no acceleration
    s = m.stance_dynamics(qj, np.zeros(nj), r["tau"])
    np.testing.assert_allclose(s["qddj"], 0.0, atol=1e-9)


@pytest.mark.parametrize("toe", [True, False])
def test_jump_stance_grf_is_momentum_rate(toe):
    """Welded phase with arbitrary torques: GRF = m_total (a_com + g) (a_com by central
    differences of the COM velocity along a short integration)."""
    m = JumpModel(toe=toe)
    nj = len(m.joints)
    rng = np.random.default_rng(10)
    qj, qdj, tau = rng.normal(size=nj) * 0.3, rng.normal(size=nj), rng.normal(size=nj) * 50
    f = m.function("stance")

    def rhs(t, x):
        return np.r_[x[nj:], np.asarray(f(x[:nj], x[nj:], tau)[0]).ravel()]

    dt = 1e-4
    fwd = solve_ivp(rhs, (0, dt), np.r_[qj, qdj], rtol=1e-12, atol=1e-12, method="DOP853")
    bwd = solve_ivp(rhs, (0, -dt), np.r_[qj, qdj], rtol=1e-12, atol=1e-12, method="DOP853")
    z = np.zeros(3)
    v = [m.com(np.r_[z, x[:nj]], np.r_[z, x[nj:]])[1] for x in (bwd.y[:, -1], fwd.y[:, -1])]
    a_com = (v[1] - v[0]) / (2 * dt)
    grf = m.stance_dynamics(qj, qdj, tau)["grf"]
    np.testing.assert_allclose(grf[:2], m.total_mass * (a_com + [0.0, cv.G]), rtol=1e-5,
                               atol=1e-3)


@pytest.mark.parametrize("toe", [True, False])
def test_jump_flight_com_parabola_and_energy(toe):
    """Free flight with internal torques: the COM follows a parabola; with no torques and
    no damping, T + V is conserved."""
    m = JumpModel(toe=toe)
    n, nj = m.n, len(m.joints)
    rng = np.random.default_rng(11)
    x0 = np.r_[0.1, 1.0, 0.2, rng.normal(size=nj) * 0.3, 0.5, 3.0, rng.normal(size=n - 2)]
    tau = rng.normal(size=nj) * 20
    f = m.function("flight")

    def rhs(t, x):
        return np.r_[x[n:], np.asarray(f(x[:n], x[n:], tau)).ravel()]

    T = 0.5
    sol = solve_ivp(rhs, (0, T), x0, rtol=1e-11, atol=1e-11, method="DOP853",
                    t_eval=np.linspace(0, T, 11))
    c0, v0 = m.com(x0[:n], x0[n:])
    for t, x in zip(sol.t, sol.y.T):
        c, v = m.com(x[:n], x[n:])
        np.testing.assert_allclose(c, c0 + v0 * t - [0.0, 0.5 * cv.G * t**2], atol=1e-8)
        np.testing.assert_allclose(v, v0 - [0.0, cv.G * t], atol=1e-8)
    # energy with no torque and no damping
    m0 = JumpModel(toe=toe, damping=0.0)
    f0 = m0.function("flight")
    z = np.zeros(nj)
    sol = solve_ivp(lambda t, x: np.r_[x[n:], np.asarray(f0(x[:n], x[n:], z)).ravel()],
                    (0, T), x0, rtol=1e-11, atol=1e-11, method="DOP853")
    e = [sum(m0.energies(x[:n], x[n:]).values()) for x in sol.y.T]
    assert np.ptp(e) / abs(e[0]) < 1e-8


def test_jump_flight_inverse_of_forward():
    m = JumpModel()
    rng = np.random.default_rng(12)
    q, qd, tau = rng.normal(size=7), rng.normal(size=7), rng.normal(size=4) * 30
    qdd = m.flight_dynamics(q, qd, tau)
    r = _call_id(m, q, qd, qdd)
    np.testing.assert_allclose(r["tau"], tau, rtol=1e-9, atol=1e-8)
    np.testing.assert_allclose(r["residual"], 0.0, atol=1e-8)


def _call_id(m, q, qd, qdd):
    out = m.function("flight_id")(q, qd, qdd)
    return {"tau": np.asarray(out[0]).ravel(), "residual": np.asarray(out[1]).ravel()}


def test_jump_ellipsoid_contact_supports_weight():
    """Toe-included model on its three ellipsoids (x2 feet): there is a root height where
    the static contact force equals the weight, with all normal forces >= 0."""
    m = JumpModel(toe=True)
    W = m.total_mass * cv.G
    z7, z4 = np.zeros(7), np.zeros(4)

    def excess(y):
        q = z7.copy()
        q[1] = y
        return m.contact_dynamics(q, z7, z4)["grf_y"] - W

    y = brentq(excess, -0.015, 0.05, xtol=1e-12)
    q = z7.copy()
    q[1] = y
    r = m.contact_dynamics(q, z7, z4)
    assert r["grf_y"] == pytest.approx(W, rel=1e-9)
    assert np.all(r["fn"] >= 0.0)


def test_sign_conventions(model):
    """hip > 0 flexes (knee forward), knee < 0 flexes (ankle behind the knee line), ankle > 0
    dorsiflexes (toes up), mtp > 0 extends the toe (tip up), pelvis_tilt > 0 leans the HAT
    backwards (conventions.py)."""
    q0 = np.zeros(N)
    P0 = model.points(q0)

    def moved(name, val):
        q = q0.copy()
        q[cv.COORDS.index(name)] = val
        return model.points(q)

    assert moved("hip_r", 0.2)["knee_r"][0] > P0["knee_r"][0]
    assert moved("knee_r", -0.2)["ankle_r"][0] < P0["ankle_r"][0]
    assert moved("ankle_l", 0.2)["mtp_l"][1] > P0["mtp_l"][1]
    assert moved("mtp_l", 0.2)["toe_tip_l"][1] > P0["toe_tip_l"][1]
    assert moved("pelvis_tilt", 0.2)["hat_top"][0] < P0["hat_top"][0]
