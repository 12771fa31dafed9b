"""Physics tests of the muscle torque generators (gaitlib.mtg) and activation dynamics
(gaitlib.activation): thesis Eqs 5.1–5.9, 5.21, 5.32, 5.34–5.37, 5.54; RBDL Gymnast curves."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from gaitlib import activation as act
from gaitlib import mtg
from gaitlib.conventions import BODY_HEIGHT, BODY_MASS

GENS = mtg.GENERATORS


# ----------------------------------------------------------------------------- curves


@pytest.mark.parametrize("g", GENS)
def test_active_curve_knots(g):
    r = mtg.GYMNAST[g]
    w = r.sigma * math.sqrt(-2.0 * math.log(1e-3))
    c = mtg.curve(g, "active")
    assert c(r.theta_star) == pytest.approx(1.0, abs=1e-12)
    assert c(r.theta_star, 1) == pytest.approx(0.0, abs=1e-9)
    for x in (r.theta_star - r.sigma, r.theta_star + r.sigma):
        assert c(x) == pytest.approx(math.exp(-0.5), abs=1e-12)  # Gaussian at ±σ
    for x in (r.theta_star - w, r.theta_star + w):
        assert c(x) == pytest.approx(0.0, abs=1e-12)
        assert c(x, 1) == pytest.approx(0.0, abs=1e-12)
        assert c(x, 2) == pytest.approx(0.0, abs=1e-12)
    # 0 outside, never negative, maximum 1 at θ*
    xs = np.linspace(r.theta_star - 2 * w, r.theta_star + 2 * w, 4001)
    y = c(xs)
    assert y.min() >= -1e-9 and y.max() <= 1.0 + 1e-9
    assert np.all(y[np.abs(xs - r.theta_star) > w + 1e-9] == pytest.approx(0.0, abs=1e-12))


@pytest.mark.parametrize("g", GENS)
def test_velocity_curve_knots(g):
    r = mtg.GYMNAST[g]
    c = mtg.curve(g, "velocity")
    assert c(0.0) == pytest.approx(1.0, abs=1e-12)
    assert c(1.0) == pytest.approx(0.0, abs=1e-12)
    assert c(-1.0) == pytest.approx(r.E, abs=1e-12)
    assert c(-0.9) == pytest.approx(r.E, abs=1e-12)  # eccentric plateau
    assert c(-3.0) == pytest.approx(r.E, abs=1e-12)  # linear (flat) extension
    assert c(3.0) == pytest.approx(0.0, abs=1e-12)
    # RBDL's concentric Bézier is a best fit to Hill's hyperbola through (0,1), (0.9, H),
    # (1, 0); it does not interpolate ω̂ = 0.5: measured |t^V(0.5) − v½| ≤ 2.5e-3.
    assert c(0.5) == pytest.approx(r.v_half, abs=3e-3)
    alpha = 0.5 * r.v_half / (0.5 - r.v_half)
    hill_slope0 = -alpha * (1 + alpha) / alpha**2  # d/dw α(1−w)/(α+w) at 0
    assert c(0.0, 1) == pytest.approx(hill_slope0, rel=1e-9)
    ws = np.linspace(-1.2, 1.2, 2001)
    assert np.all(np.diff(c(ws)) <= 1e-12)  # monotone non-increasing
    assert c(ws).min() >= -1e-12


@pytest.mark.parametrize("g", GENS)
def test_passive_curve_knots(g):
    r = mtg.GYMNAST[g]
    c = mtg.curve(g, "passive")
    k1 = 4.6 / (r.theta_p1 - r.theta_p0)
    assert c(r.theta_p0) == pytest.approx(0.0, abs=1e-12)
    assert c(r.theta_p0, 1) == pytest.approx(0.0, abs=1e-12)
    assert c(r.theta_p1) == pytest.approx(1.0, abs=1e-12)
    assert c(r.theta_p1, 1) == pytest.approx(k1, rel=1e-9)
    # zero on the slack side, linear with slope k1 beyond θ_P1
    slack = r.theta_p0 - 0.3 * np.sign(k1)
    assert c(slack) == pytest.approx(0.0, abs=1e-12)
    beyond = r.theta_p1 + 0.1 * np.sign(k1)
    assert c(beyond) == pytest.approx(1.0 + k1 * (beyond - r.theta_p1), rel=1e-9)
    xs = np.linspace(min(r.theta_p0, r.theta_p1) - 0.2, max(r.theta_p0, r.theta_p1) + 0.2, 3001)
    assert c(xs).min() >= -1e-9


@pytest.mark.parametrize("g", GENS)
@pytest.mark.parametrize("kind", ["active", "velocity", "passive"])
def test_curves_match_rbdl_bezier_and_are_c2(g, kind):
    c = mtg.curve(g, kind)
    lo, hi = c.domain
    xs = np.linspace(lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo), 3001)
    y_exact, d_exact = c.bezier.value(xs), c.bezier.value(xs, 1)
    slope_scale = max(1.0, np.abs(d_exact).max())
    assert np.abs(c(xs) - y_exact).max() < 1e-5
    assert np.abs(c(xs, 1) - d_exact).max() < 2e-3 * slope_scale
    # continuity of value, slope and curvature across every piece boundary
    for der in (0, 1, 2):
        left, right = c.one_sided_limits(der)
        jump = np.abs(left - right)  # round-off only
        assert np.all(jump <= 1e-9 * (1.0 + np.abs(left).max())), (der, jump.max())
    # the knots exposed for plots are the Bézier segment ends, with exact values/slopes
    k = mtg.curve_knots(g)[kind]
    assert np.allclose(c(k["x"]), k["y"], atol=1e-12)
    assert np.allclose(c(k["x"], 1), k["dydx"], atol=1e-9)


def test_curves_second_derivatives_in_sx():
    x = ca.SX.sym("x")
    for g in GENS:
        for kind in ("active", "velocity", "passive"):
            c = mtg.curve(g, kind)
            y = c(x)
            f = ca.Function("f", [x], [y, ca.jacobian(y, x), ca.hessian(y, x)[0]])
            lo, hi = c.domain
            for xv in np.linspace(lo - 0.05, hi + 0.05, 9):
                v, d, h = (float(z) for z in f(xv))
                assert np.isfinite([v, d, h]).all()
                assert v == pytest.approx(c(xv), abs=1e-10)
                assert d == pytest.approx(c(xv, 1), abs=1e-8 * (1 + abs(c(xv, 1))))
                assert h == pytest.approx(c(xv, 2), abs=1e-6 * (1 + abs(c(xv, 2))))


# ----------------------------------------------------------------------------- torques


def test_tau0_scaling_eq_5_21():
    f = BODY_MASS * BODY_HEIGHT / (69.6 * 1.732)
    for g in GENS:
        assert mtg.tau0(g) == pytest.approx(mtg.GYMNAST[g].tau0 * f, rel=1e-12)
    assert mtg.tau0("knee_ext", body_mass=69.6, body_height=1.732) == pytest.approx(285.619)


def test_default_params_are_eq_5_22():
    p = mtg.DEFAULT_PARAMS
    assert p.to_vector() == pytest.approx([1, 1, 2.22e-16**0.25, 1, 2.22e-16**0.25, 0, 0])
    for name, (lo, hi) in mtg.PARAM_BOUNDS.items():
        assert lo <= getattr(p, name) <= hi or name == "lambda_P"  # λ^P = 0 = its bound
    for g, tp in mtg.THESIS_PARAMS.items():
        for name, (lo, hi) in mtg.PARAM_BOUNDS.items():
            assert lo <= getattr(tp, name) <= hi, (g, name)


@pytest.mark.parametrize("g", GENS)
def test_single_generator_torque_nonnegative(g):
    th = np.linspace(-2.5, 2.5, 101)[:, None, None]
    w = np.linspace(-1.0, 1.0, 21)[None, :, None] * mtg.GYMNAST[g].omega_max
    a = np.linspace(0.0, 1.0, 5)[None, None, :]
    for params in (None, mtg.THESIS_PARAMS):
        tau = mtg.generator_torque(g, th, w, a, params)
        assert tau.min() >= -1e-9  # ≥ 0 up to round-off of the piecewise polynomials
    # at the optimum angle, isometric, a = 1: τ = s^τ τ0 (1 + tiny passive/λ terms)
    r = mtg.GYMNAST[g]
    lam = mtg.DEFAULT_PARAMS.lambda_A
    t = mtg.generator_torque(g, r.theta_star, 0.0, 1.0, None)
    passive = mtg.tau0(g) * mtg.t_passive(g, r.theta_star)
    assert t == pytest.approx(mtg.tau0(g) * (1.0 * ((1 - lam) + lam * r.E)) + passive, rel=1e-8)


def test_joint_sign_mapping():
    # active torque (a = 1) at a mid-range posture, model convention (conventions.py):
    # hip q = 0.3 (flexed), knee q = −0.6 (flexed), ankle q = 0.05
    q = {"hip": 0.3, "knee": -0.6, "ankle": 0.05}
    expected = {  # sign of the model-convention torque
        "hip_ext": -1, "hip_flex": +1,  # hip flexion is CCW positive
        "knee_ext": +1, "knee_flex": -1,  # knee extension is CCW positive
        "ankle_ext": -1, "ankle_flex": +1,  # ankle dorsiflexion is CCW positive
    }
    for g, s in expected.items():
        j = g.split("_")[0]
        assert mtg.TORQUE_SIGN[g] == s
        tau = mtg.generator_joint_torque(g, q[j], 0.0, 1.0)
        assert np.sign(tau) == s and abs(tau) > 5.0, (g, tau)
    # fibre angle positive in hip flexion, knee flexion, ankle dorsiflexion
    assert mtg.fibre_kinematics("knee_ext", -0.6, 0.0)[0] == pytest.approx(0.6)
    assert mtg.fibre_kinematics("hip_flex", 0.3, 0.0)[0] == pytest.approx(0.3)
    assert mtg.fibre_kinematics("ankle_flex", 0.2, 0.0)[0] == pytest.approx(0.2)
    # passive torques resist the end of range: deep knee flexion → knee extensor pushes
    # towards extension (> 0); knee hyperextension → knee flexor pulls back (< 0)
    assert mtg.generator_joint_torque("knee_ext", -2.5, 0.0, 0.0) > 1.0
    assert mtg.generator_joint_torque("knee_flex", 0.2, 0.0, 0.0) < -1.0
    assert mtg.generator_joint_torque("hip_ext", 1.6, 0.0, 0.0) < -1.0
    assert mtg.generator_joint_torque("ankle_ext", 0.6, 0.0, 0.0) < -1.0  # dorsiflexed
    assert mtg.generator_joint_torque("ankle_flex", -0.9, 0.0, 0.0) > 1.0  # plantarflexed


def test_torque_velocity_direction():
    # knee extension (q̇ > 0) shortens the knee extensor: concentric → less torque
    iso = mtg.generator_joint_torque("knee_ext", -0.9, 0.0, 1.0)
    assert mtg.generator_joint_torque("knee_ext", -0.9, 3.0, 1.0) < iso
    assert mtg.generator_joint_torque("knee_ext", -0.9, -3.0, 1.0) > iso
    # hip extension (q̇ < 0) shortens the hip extensor
    iso = -mtg.generator_joint_torque("hip_ext", 0.5, 0.0, 1.0)
    assert -mtg.generator_joint_torque("hip_ext", 0.5, -3.0, 1.0) < iso
    # torque-velocity helper: s^τ τ0 t^V, E times τ0 in fast lengthening, 0 at ω_max
    r = mtg.GYMNAST["ankle_ext"]
    assert mtg.torque_velocity("ankle_ext", 0.0) == pytest.approx(mtg.tau0("ankle_ext"), rel=1e-3)
    tv = mtg.torque_velocity("ankle_ext", -np.array([r.omega_max, -r.omega_max]), params=mtg.MTGParams(lambda_V=0.0))
    # ankle extensor shortens in plantarflexion (q̇ < 0) → ω̂ = +1 at q̇ = −ω_max
    assert tv[0] == pytest.approx(0.0, abs=1e-9)
    assert tv[1] == pytest.approx(r.E * mtg.tau0("ankle_ext"), rel=1e-9)


def test_joint_torque_is_sum_and_affine_in_activation():
    for j in mtg.MTG_JOINTS:
        q, qd = {"hip": 0.2, "knee": -0.4, "ankle": -0.1}[j], 0.7
        t = mtg.joint_torque(j, q, qd, 0.3, 0.6)
        s = mtg.generator_joint_torque(f"{j}_ext", q, qd, 0.3) + mtg.generator_joint_torque(
            f"{j}_flex", q, qd, 0.6
        )
        assert t == pytest.approx(s, rel=1e-12)
        t0, t1, th = (mtg.joint_torque(j, q, qd, a, 0.0) for a in (0.0, 1.0, 0.5))
        assert th == pytest.approx(0.5 * (t0 + t1), rel=1e-12)


def test_pair_activations_no_cocontraction():
    u = np.linspace(-1, 1, 41)
    for j in mtg.MTG_JOINTS:
        a_ext, a_flex = mtg.pair_activations(j, u, eps=1e-3)
        assert np.all(a_ext >= 0) and np.all(a_flex >= 0)
        assert np.max(np.minimum(a_ext, a_flex)) <= 0.5e-3 + 1e-15  # ≤ ε/2 co-contraction
        # u > 0 drives the generator with positive model torque
        pos = a_flex if mtg.TORQUE_SIGN[f"{j}_flex"] > 0 else a_ext
        neg = a_ext if pos is a_flex else a_flex
        assert np.allclose(pos - neg, u, atol=1e-15)
        q = {"hip": 0.2, "knee": -0.4, "ankle": 0.0}[j]
        taus = mtg.pair_torque(j, q, 0.0, u)
        assert np.all(np.diff(taus) > 0)  # monotone in u, positive direction for u > 0
        e0, f0 = mtg.pair_activations(j, 0.7, eps=0.0)
        assert (e0, f0) in ((0.7, 0.0), (0.0, 0.7))


@pytest.mark.parametrize("joint", mtg.MTG_JOINTS)
def test_inverse_activation_reproduces_torque(joint):
    rng = np.random.default_rng(1)
    q0 = {"hip": 0.2, "knee": -0.5, "ankle": 0.05}[joint]
    q = q0 + rng.uniform(-0.3, 0.3, 200)
    qd = rng.uniform(-3.0, 3.0, 200)
    for params in (None, mtg.THESIS_PARAMS):
        lo, hi = mtg.max_joint_torque(joint, q, qd, params)
        frac = rng.uniform(0, 1, 200)
        tau = lo + frac * (hi - lo)  # feasible demands
        r = mtg.activation_for_torque(joint, tau, q, qd, params)
        assert not np.any(r["clipped"])
        assert np.abs(r["residual"]).max() < 1e-9
        assert np.all((r["a_ext"] >= 0) & (r["a_ext"] <= 1) & (r["a_flex"] >= 0) & (r["a_flex"] <= 1))
        assert np.all(np.minimum(r["a_ext"], r["a_flex"]) == 0.0)  # no co-contraction
        tau_chk = mtg.joint_torque(joint, q, qd, r["a_ext"], r["a_flex"], params)
        assert np.allclose(tau_chk, tau, atol=1e-9)
    # infeasible demand: clipped and reported
    r = mtg.activation_for_torque(joint, hi + 50.0, q, qd)
    assert np.all(r["clipped"]) and np.all(r["residual"] > 0)


def test_isometric_envelope_and_split():
    q = np.linspace(-0.5, 0.5, 11)
    env = mtg.isometric_envelope("hip_ext", q)
    assert np.all(env["active"] >= 0) and np.all(env["passive"] >= -1e-12)
    assert np.allclose(env["active"], mtg.tau0("hip_ext") * ((1 - 2.22e-16**0.25) * mtg.t_active("hip_ext", q) + 2.22e-16**0.25))
    s = mtg.split_joint_torque("knee", np.array([-10.0, 5.0]))
    assert np.allclose(s["knee_ext"], [0.0, 5.0]) and np.allclose(s["knee_flex"], [10.0, 0.0])
    s = mtg.split_joint_torque("hip", np.array([-10.0, 5.0]))
    assert np.allclose(s["hip_ext"], [10.0, 0.0]) and np.allclose(s["hip_flex"], [0.0, 5.0])
    dem = mtg.demanded_active_torque("knee_ext", 20.0, -0.4, 0.0)
    assert dem == pytest.approx(20.0 - mtg.generator_joint_torque("knee_ext", -0.4, 0.0, 0.0))


def _central_fd(f, x, h=1e-6):
    g = np.zeros_like(x)
    for i in range(len(x)):
        e = np.zeros_like(x)
        e[i] = h
        g[i] = (f(x + e) - f(x - e)) / (2 * h)
    return g


def test_joint_torque_ad_gradient_matches_fd():
    z = ca.SX.sym("z", 4 + 14)  # q, qd, a_ext, a_flex, Γ_ext (7), Γ_flex (7)
    for joint, q0 in (("hip", 0.3), ("knee", -0.7), ("ankle", 0.1)):
        params = {
            f"{joint}_ext": mtg.MTGParams.from_vector(z[4:11]),
            f"{joint}_flex": mtg.MTGParams.from_vector(z[11:18]),
        }
        tau = mtg.joint_torque(joint, z[0], z[1], z[2], z[3], params)
        F = ca.Function("F", [z], [tau, ca.gradient(tau, z)])
        H = ca.Function("H", [z], [ca.hessian(tau, z)[0]])
        x0 = np.concatenate(
            [[q0, 1.3, 0.4, 0.2], mtg.THESIS_PARAMS[f"{joint}_ext"].to_vector(),
             mtg.THESIS_PARAMS[f"{joint}_flex"].to_vector()]
        )
        x0[9] = x0[16] = 0.05  # non-zero Δ^P
        f_num = lambda x: float(F(x)[0])  # noqa: E731
        g_ad = np.array(F(x0)[1]).ravel()
        g_fd = _central_fd(f_num, x0)
        assert np.allclose(g_ad, g_fd, rtol=1e-5, atol=1e-5 * (1 + abs(f_num(x0))))
        assert np.all(np.isfinite(np.array(H(x0))))
        # numeric path agrees with the symbolic one
        assert f_num(x0) == pytest.approx(
            mtg.joint_torque(
                joint, x0[0], x0[1], x0[2], x0[3],
                {f"{joint}_ext": mtg.MTGParams.from_vector(x0[4:11]),
                 f"{joint}_flex": mtg.MTGParams.from_vector(x0[11:18])},
            ),
            rel=1e-10,
        )


def test_pair_torque_works_in_mx():
    q, qd, u = ca.MX.sym("q"), ca.MX.sym("qd"), ca.MX.sym("u")
    tau = mtg.pair_torque("ankle", q, qd, u)
    F = ca.Function("F", [q, qd, u], [tau])
    assert float(F(0.1, -0.5, -0.3)) == pytest.approx(mtg.pair_torque("ankle", 0.1, -0.5, -0.3), rel=1e-10)
    G = F.expand()  # SX-expandable
    assert float(G(0.1, -0.5, -0.3)) == pytest.approx(float(F(0.1, -0.5, -0.3)), rel=1e-12)


# ----------------------------------------------------------------------------- activation


def test_excitation_table():
    assert len(act.EXCITATIONS) == 16
    assert act.EXCITATIONS[:8] == tuple(m + "_r" for m in act.MUSCLES)
    assert set(act.MUSCLE_GENERATOR.values()) == set(GENS)
    ga = act.generator_activations(dict(zip(act.MUSCLES, np.arange(8) / 10)), 0.25, 0.25)
    assert ga["hip_ext"] == 0.0 and ga["ankle_flex"] == pytest.approx(0.7)
    # Eq 5.54 with s1 = s2 = 0.25: 0.25·SOL + 0.25·PL + 0.5·GAM
    assert ga["ankle_ext"] == pytest.approx(0.25 * 0.4 + 0.25 * 0.5 + 0.5 * 0.6)


@pytest.mark.parametrize("tau_act", [0.006, 0.015, 0.035])
def test_activation_step_response_time_constants(tau_act):
    # Check on the neural activation u (Eq 5.34) and on a with c3 = 0 (a = u): a full
    # excitation step 0 → 1 reaches 1 − e⁻¹ = 63.2 % at t = τ_act; the release 1 → 0
    # decays to e⁻¹ at t = τ_deact = 4 τ_act, i.e. deactivation is 4× slower.
    t = np.linspace(0.0, 10 * tau_act, 2001)
    u, a = act.simulate_activation(t, np.ones_like(t), tau_act, c3=0.0, delay=0.0, u0=0.0)
    assert np.interp(tau_act, t, u) == pytest.approx(1 - math.exp(-1), abs=1e-6)
    assert np.allclose(a, u)
    u, _ = act.simulate_activation(t, np.zeros_like(t), tau_act, c3=0.0, delay=0.0, u0=1.0)
    assert np.interp(4 * tau_act, t, u) == pytest.approx(math.exp(-1), abs=1e-6)
    t63_up = tau_act
    t63_down = np.interp(-math.exp(-1), -u, t)  # time to fall by 63 %
    assert t63_down / t63_up == pytest.approx(4.0, rel=1e-3)


def test_activation_delay_and_bounds():
    tau_act = 0.01
    t = np.linspace(0.0, 0.3, 3001)
    e = (t >= 0.1).astype(float)
    u, _ = act.simulate_activation(t, e, tau_act, c3=0.0, delay=act.DELAY)
    # nothing happens before 0.1 + 50 ms (up to the interpolated edge of one sample)
    assert np.max(u[t < 0.1 + act.DELAY - 1e-4]) < 1e-12
    assert np.interp(0.15 + tau_act, t, u) == pytest.approx(1 - math.exp(-1), abs=5e-3)
    rng = np.random.default_rng(0)
    e = np.repeat(rng.uniform(0, 1, 30), 100)
    t = np.linspace(0, 1.5, e.size)
    for c3 in (0.0, 0.3, 0.75):
        u, a = act.simulate_activation(t, e, 0.006, c3)
        assert u.min() >= 0 and u.max() <= 1 and a.min() >= 0 and a.max() <= 1 + 1e-12
        assert np.all(a >= u - 1e-12)  # the √ nonlinearity raises activation


def test_periodic_activation_is_periodic():
    t = np.linspace(0, 1.0, 200, endpoint=False)
    e = 0.4 * (0.5 + 0.5 * np.sin(2 * np.pi * t)) ** 3
    u, a = act.simulate_activation(t, e, 0.015, 0.3, periodic=True, period=1.0)
    # one more cycle started from the returned state reproduces it
    u2, _ = act.simulate_activation(t, e, 0.015, 0.3, periodic=False, u0=u[0])
    assert np.max(np.abs(u2[100:] - u[100:])) < 1e-6
    # delayed-response: the peak of u lags the peak of e by about delay + τ
    lag = (t[np.argmax(u)] - t[np.argmax(e)]) % 1.0
    assert act.DELAY < lag < act.DELAY + 0.1


def _activation_point_by_point(t, E, tau_act, c3, delay, periodic, period, u0, substeps=10):
    """Eqs 5.34–5.37 stepped as written: the delayed excitation interpolated at each sub-step
    midpoint when it is reached (the reference for the tabulated path in the library)."""
    T = period if period is not None else (t[-1] - t[0]) + np.mean(np.diff(t))
    tt, EE = np.concatenate([t, [t[0] + T]]), np.vstack([E, E[:1]])

    def e_at(s):
        if periodic:
            s = t[0] + np.mod(s - t[0], T)
            return np.array([np.interp(s, tt, EE[:, j]) for j in range(E.shape[1])])
        return np.array([np.interp(s, t, E[:, j]) for j in range(E.shape[1])])

    c1, c2 = 1.0 / tau_act - 1.0 / (act.DEACTIVATION_RATIO * tau_act), 1.0 / (act.DEACTIVATION_RATIO * tau_act)

    def run(u):
        U = np.empty_like(E)
        U[0] = u
        for i in range(len(t) - 1):
            h = (t[i + 1] - t[i]) / substeps
            for k in range(substeps):
                ed = e_at(t[i] + (k + 0.5) * h - delay)
                u = ed + (u - ed) * np.exp(-(c1 * ed + c2) * h)
            U[i + 1] = u
        if periodic:
            h = (t[0] + T - t[-1]) / substeps
            for k in range(substeps):
                ed = e_at(t[-1] + (k + 0.5) * h - delay)
                u = ed + (u - ed) * np.exp(-(c1 * ed + c2) * h)
        return U, u

    U, u_end = run(e_at(t[0] - delay) if u0 is None else np.full(E.shape[1], float(u0)))
    if periodic:
        for _ in range(200):
            if np.max(np.abs(u_end - U[0])) < 1e-12:
                break
            U, u_end = run(u_end)
    return U, act.neural_to_muscle_activation(U, c3, 1e-4)


@pytest.mark.parametrize("periodic", [False, True])
def test_activation_tabulated_is_the_point_by_point_integration_to_the_bit(periodic):
    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(0, 1.1, 60))  # uneven steps
    E = rng.uniform(0, 1, (60, 4))
    u, a = act.simulate_activation(t, E, 0.012, 0.4, periodic=periodic, period=1.2 if periodic else None)
    u_ref, a_ref = _activation_point_by_point(t, E, 0.012, 0.4, act.DELAY, periodic, 1.2 if periodic else None, None)
    np.testing.assert_array_equal(u, u_ref)
    np.testing.assert_array_equal(a, a_ref)
    u1, _ = act.simulate_activation(t, E[:, 1], 0.02, 0.1, periodic=periodic, u0=0.2)
    np.testing.assert_array_equal(u1, _activation_point_by_point(t, E[:, 1:2], 0.02, 0.1, act.DELAY, periodic, None,
                                                                 0.2)[0][:, 0])


def test_neural_to_muscle_activation():
    u = np.linspace(0, 1, 101)
    assert np.allclose(act.neural_to_muscle_activation(u, 0.0), u)
    a = act.neural_to_muscle_activation(u, 0.75)
    assert a[0] == 0.0 and a[-1] == pytest.approx(1.0)
    exact = 0.75 * np.sqrt(u) + 0.25 * u
    assert np.abs(a - exact).max() < 0.01  # smoothed √u (δ = 1e-4) vs Eq 5.37
    assert np.allclose(act.neural_to_muscle_activation(u, 0.75, delta=0.0), exact)


def test_activation_ad_gradients():
    x = ca.SX.sym("x", 4)  # u, e, tau_act, c3
    f = ca.vertcat(act.activation_rate(x[0], x[1], x[2]), act.neural_to_muscle_activation(x[0], x[3]))
    F = ca.Function("F", [x], [f, ca.jacobian(f, x)])
    x0 = np.array([0.3, 0.7, 0.012, 0.4])
    J = np.array(F(x0)[1])
    for k in range(2):
        g_fd = _central_fd(lambda z: float(F(z)[0][k]), x0, h=1e-7)
        assert np.allclose(J[k], g_fd, rtol=1e-5, atol=1e-6)
    # thesis equations: c1 = 1/τa − 1/τd, c2 = 1/τd
    r = act.activation_rate(0.3, 0.7, 0.012)
    assert r == pytest.approx((0.7 / 0.012 + 0.3 / 0.048) * 0.4)


def test_periodic_delay_matrix_and_delay():
    n = 50
    t = np.arange(n) / n
    x = 0.3 + np.sin(2 * np.pi * t) + 0.2 * np.cos(6 * np.pi * t + 0.4)
    d = 0.05

    def exact(s):
        return 0.3 + np.sin(2 * np.pi * (t - s)) + 0.2 * np.cos(6 * np.pi * (t - s) + 0.4)

    assert np.allclose(act.periodic_delay_matrix(n, 0.0), np.eye(n), atol=1e-12)
    assert np.allclose(act.periodic_delay_matrix(n, d) @ x, exact(d), atol=1e-12)
    assert np.allclose(act.delay_periodic(x, d * 0.98, 0.98), exact(d), atol=1e-12)
    assert np.allclose(act.periodic_delay_matrix(n, 3 / n) @ x, np.roll(x, 3), atol=1e-12)
    s = ca.SX.sym("s")
    D = ca.Function("D", [s], [act.periodic_delay_matrix(8, s)])
    assert np.allclose(np.array(D(0.013)), act.periodic_delay_matrix(8, 0.013), atol=1e-12)
