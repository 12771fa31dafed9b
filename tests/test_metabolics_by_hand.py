"""Independent check of the MTG metabolic model (thesis Sec 5.3.3, Eqs 5.38–5.50) by hand.

One generator, the right ankle extensor (``ankle_ext_r``), driven by its three muscles
soleus, peroneus longus and gastrocnemius medialis (thesis Table 5.5), at five states.
Every expected value below is computed in this file with plain ``math`` from numbers typed
from the thesis (table / equation cited beside each constant); the functions of
:mod:`gaitlib.metabolics` are only called to get the value under test.

Units, term by term
-------------------
=================  ===================================  ====================================
term               thesis (MTG form)                    Bhargava et al. 2004 (muscle form)
=================  ===================================  ====================================
m (5.41)           kg = kg/m³ × m² × m                  same (OpenSim: F0/σ × ρ × l_opt)
φ (5.40)           1 = exp(s × 1 / s)                   same (τ_φ = 45 ms)
e_fast, e_slow     1 (5.43, 5.44)                       same
Ȧ (5.39)           W = 1 × kg × 1 × W/kg × 1            same (133 / 40 W/kg)
Ṁ (5.45)           W = kg × 1 × W/kg × 1                same × L(l̃) (1), dropped in thesis
Ṡ (5.47)           W = (1 × N·m) × rad/s                W = (1 × N) × m/s   (5.46)
Ḃ (5.48)           W = 0.0225 W/kg × kg (muscle mass)   OpenSim probe: 1.2 W/kg × body mass
Ẇ (5.50)           W = N·m × rad/s                      W = N × m/s          (5.49)
Ė (5.38)           W (sum); Ė/BM in W/kg                same
=================  ===================================  ====================================

The shortening and work terms keep their units (and, for one muscle with moment arm r,
τ = r F and ω = v / r give τ ω = F v) so 0.16, 0.18, 0.157 stay dimensionless.

Where the readings differ (pinned in the tests ``test_reading_*``)
------------------------------------------------------------------
- Sign of Eq 5.47: printed as Ṡ = −(0.16 τ0 + 0.18 τ^M) θ̇ for τ^M θ̇ ≥ 0 (concentric).
  With τ^M ≥ 0 and θ̇ > 0 in concentric, that is negative heat while shortening. Bhargava
  (thesis Eq 5.46) has Ṡ = −α v_CE with v_CE < 0 in shortening, i.e. positive heat. The module
  uses Bhargava's sign with ω_f = −v_CE (> 0 shortening).
- Case split of Eq 5.47 at τ^M = 0: printed τ^M θ̇ ≥ 0 puts every relaxed state into the
  concentric case (−0.16 τ0 θ̇, even when lengthening); the module splits on the sign of ω_f.
- F0 in the concentric shortening heat: thesis Eq 5.47 uses the maximum isometric torque
  s^τ τ0^M; Bhargava / OpenSim use F_CE_iso, the isometric force at the current activation
  and length. The module's default is the thesis's.
- Basal rate: thesis Eq 5.48 (and Bhargava) 0.0225 W/kg × each muscle's mass; the OpenSim
  probe's default is a whole-body 1.2 W/kg × body mass. The module uses the thesis's.
- Negative totals: thesis Eq 5.38 is a plain sum (may be < 0); the module clips the non-basal
  part with a smooth max by default (``forbid_negative``), as OpenSim's
  ``forbid_negative_total_power`` does. Both are checked.

Sources: thesis text (Sec 5.3.3, Tables 5.2, 5.5–5.8, Eqs 5.21, 5.38–5.50); Bhargava, Pandy,
Anderson (2004) J Biomech 37:81–88 as restated in thesis Eqs 5.46, 5.49 and in OpenSim's
``Bhargava2004MuscleMetabolicsProbe`` documentation
(https://github.com/opensim-org/opensim-core/blob/master/OpenSim/Simulation/Model/Bhargava2004MuscleMetabolicsProbe.h):
activation 40 / 133 W/kg slow / fast, maintenance 74 / 111 W/kg, α = 0.16 F_iso + 0.18 F
(shortening) or 0.157 F (lengthening), basal_coefficient default 1.2 (W/kg body mass).
Adult Gymnast τ0 of the ankle extensor (127.561 N·m, 69.6 kg, 1.732 m): RBDL
``GymnastWholeBody`` as quoted in the project's model-facts Sec 2 (the thesis's ref [7]).
"""

from __future__ import annotations

import math

import pytest

from gaitlib import metabolics as met
from gaitlib import mtg

REL = 1e-9

# ---- constants typed from the thesis ---------------------------------------------------
RHO = 1060.0  # kg/m³, muscle density (Eq 5.41 text)
A_FAST, A_SLOW = 133.0, 40.0  # W/kg, activation heat constants (Eq 5.39 text)
M_FAST, M_SLOW = 111.0, 74.0  # W/kg, maintenance heat constants (Eq 5.45 text)
TAU_PHI = 0.045  # s, decay time constant (Eq 5.40 text: 45 ms)
B_RATE = 0.0225  # W/kg of muscle, basal rate (Eq 5.48 text)
EPS = 0.1  # W, the module's smooth-max width (module docstring, not the thesis)

# Tables 5.6 (l_opt, cm), 5.7 (PCSA, cm²), 5.8 (f_fast, %): all eight muscles.
TABLE = {
    #       l_opt  PCSA    f_fast
    "GM": (12.39, 9.53, 45),
    "RF": (10.32, 20.68, 65),
    "VM": (8.14, 32.02, 50),
    "BF": (12.66, 8.51, 35),
    "SOL": (4.16, 89.28, 20),
    "PL": (3.92, 24.20, 50),
    "GAM": (5.03, 11.79, 19),
    "TA": (7.99, 8.09, 25),
}
ANKLE_EXT_MUSCLES = ("SOL", "PL", "GAM")  # Table 5.5: ankle extensors

# Maximum isometric torque of the ankle extensor, Eq 5.21 × s^τ (Table 5.2):
# τ0 = (41.4 kg × 1.47 m) / (69.6 kg × 1.732 m) × 127.561 N·m × 0.9999
BM, BH = 41.4, 1.47  # child's mass and height (thesis Sec 4.1: 41.4 kg, 1.47 m)
TAU0_ANKLE_EXT = (41.4 * 1.47) / (69.6 * 1.732) * 127.561 * 0.9999  # N·m (≈ 64.393)


def mass(muscle):
    """Eq 5.41: m = ρ PCSA l_opt (kg), PCSA cm² → m², l_opt cm → m."""
    l_cm, pcsa_cm2, _ = TABLE[muscle]
    return RHO * (pcsa_cm2 * 1e-4) * (l_cm * 1e-2)


def f_fast(muscle):
    return TABLE[muscle][2] / 100.0  # Table 5.8, % → 1; f_slow = 1 − f_fast


def phi(e, t_stim):
    return 0.06 + math.exp(-t_stim * e / TAU_PHI)  # Eq 5.40


def e_fast(e):
    return 1.0 - math.cos(math.pi / 2 * e)  # Eq 5.43


def e_slow(e):
    return math.sin(math.pi / 2 * e)  # Eq 5.44


def A_hand(muscle, e, t_stim):
    m, ff = mass(muscle), f_fast(muscle)
    return phi(e, t_stim) * m * ff * A_FAST * e_fast(e) + phi(e, t_stim) * m * (1 - ff) * A_SLOW * e_slow(e)  # 5.39


def M_hand(muscle, e):
    m, ff = mass(muscle), f_fast(muscle)
    return m * ff * M_FAST * e_fast(e) + m * (1 - ff) * M_SLOW * e_slow(e)  # Eq 5.45


def B_hand(muscle):
    return B_RATE * mass(muscle)  # Eq 5.48


def S_hand(tau_m, omega_f, tau0):
    """Eq 5.47, Bhargava's sign (Eq 5.46 with v_CE = −ω_f): heat > 0 while shortening."""
    if omega_f >= 0:  # concentric (or isometric): v_CE ≤ 0
        return (0.16 * tau0 + 0.18 * tau_m) * omega_f
    return 0.157 * tau_m * omega_f  # eccentric: v_CE > 0


def S_thesis_literal(tau_m, theta_dot, tau0):
    """Eq 5.47 exactly as printed (θ̇ = the generator's velocity, τ^M θ̇ ≥ 0 concentric)."""
    if tau_m * theta_dot >= 0:
        return -(0.16 * tau0 + 0.18 * tau_m) * theta_dot
    return -(0.157 * tau_m) * theta_dot


def smax0(x, eps=EPS):
    return 0.5 * (x + math.sqrt(x * x + eps * eps)) - 0.5 * eps


# ---- the states --------------------------------------------------------------------------
# e: excitations of SOL, PL, GAM; t_stim (s) per muscle; tau_m: ankle-extensor torque in its
# own frame (N·m, ≥ 0); qd: ankle angular velocity (rad/s, model convention, > 0
# dorsiflexion), so the extensor's fibre velocity is ω_f = −q̇ (> 0 shortening, mtg
# TORQUE_SIGN['ankle_ext'] = −1); tau_flex: the antagonist's torque (N·m, ≥ 0), giving
# the net ankle torque τ = −τ_ext + τ_flex of Eq 5.50.
STATES = {
    "rest": {"e": (0.0, 0.0, 0.0), "t_stim": (0.0, 0.0, 0.0), "tau_m": 1.5, "qd": 0.0, "tau_flex": 0.0},
    "isometric": {"e": (0.6, 0.4, 0.5), "t_stim": (0.30, 0.20, 0.25), "tau_m": 40.0, "qd": 0.0, "tau_flex": 1.0},
    "shortening": {"e": (0.8, 0.5, 0.7), "t_stim": (0.25, 0.15, 0.20), "tau_m": 55.0, "qd": -3.0, "tau_flex": 0.5},
    "lengthening": {"e": (0.3, 0.2, 0.25), "t_stim": (0.40, 0.30, 0.35), "tau_m": 45.0, "qd": 1.2, "tau_flex": 0.0},
    "relaxed_shortening": {"e": (0.0, 0.0, 0.0), "t_stim": (0.0, 0.0, 0.0), "tau_m": 2.0, "qd": -2.0, "tau_flex": 0.3},
}


def hand_terms(s):
    """Every term of Eq 5.38 for the ankle extensor and its three muscles, W."""
    A = sum(A_hand(mu, e, ts) for mu, e, ts in zip(ANKLE_EXT_MUSCLES, s["e"], s["t_stim"], strict=True))
    M = sum(M_hand(mu, e) for mu, e in zip(ANKLE_EXT_MUSCLES, s["e"], strict=True))
    B = sum(B_hand(mu) for mu in ANKLE_EXT_MUSCLES)
    omega_f = -s["qd"]
    S = S_hand(s["tau_m"], omega_f, TAU0_ANKLE_EXT)
    W = (-s["tau_m"] + s["tau_flex"]) * s["qd"]  # Eq 5.50: net MTG torque × θ̇
    return {"activation": A, "maintenance": M, "basal": B, "shortening": S, "work": W,
            "plain": A + M + S + B + W, "clipped": B + smax0(A + M + S + W)}


def module_terms(s, **kw):
    ex = {f"{mu}_r": e for mu, e in zip(ANKLE_EXT_MUSCLES, s["e"], strict=True)}
    ts = {f"{mu}_r": t for mu, t in zip(ANKLE_EXT_MUSCLES, s["t_stim"], strict=True)}
    tau_joint = -s["tau_m"] + s["tau_flex"]
    return met.metabolic_rate(
        ex, {"ankle_ext_r": s["tau_m"]}, {"ankle_ext_r": -s["qd"]}, {"ankle_ext_r": TAU0_ANKLE_EXT},
        {"ankle_r": tau_joint}, {"ankle_r": s["qd"]}, t_stim=ts, **kw,
    )


# ---- term by term ------------------------------------------------------------------------


def test_muscle_masses_eq_5_41():
    # SOL: 1060 × 89.28e-4 × 0.0416 = 0.393680... kg (typed product, not the table code)
    assert mass("SOL") == pytest.approx(0.39368, rel=1e-4)
    for mu in TABLE:
        assert met.muscle_mass(mu) == pytest.approx(mass(mu), rel=REL)
        assert met.muscle_mass(mu + "_l") == pytest.approx(mass(mu), rel=REL)


def test_decay_factor_eq_5_40():
    for e, ts in [(0.0, 0.0), (0.6, 0.30), (0.8, 0.25), (0.3, 0.40), (1.0, 0.045)]:
        assert met.decay_factor(e, ts) == pytest.approx(phi(e, ts), rel=REL)
    assert phi(1.0, 0.045) == pytest.approx(0.06 + math.exp(-1.0), rel=1e-15)


@pytest.mark.parametrize("name", STATES)
@pytest.mark.parametrize("mi", range(3))
def test_activation_and_maintenance_heat_eqs_5_39_5_45(name, mi):
    s = STATES[name]
    mu, e, ts = ANKLE_EXT_MUSCLES[mi], s["e"][mi], s["t_stim"][mi]
    assert met.activation_heat_rate(mu + "_r", e, ts) == pytest.approx(A_hand(mu, e, ts), rel=REL, abs=1e-15)
    assert met.maintenance_heat_rate(mu + "_r", e) == pytest.approx(M_hand(mu, e), rel=REL, abs=1e-15)


def test_activation_heat_soleus_number():
    # SOL at e = 0.6, t_stim = 0.3 s, written out:
    # φ = 0.06 + exp(−0.3·0.6/0.045) = 0.06 + e^−4 = 0.0783156...
    # e_fast = 1 − cos(0.3π) = 0.412215..., e_slow = sin(0.3π) = 0.809017...
    # Ȧ = φ m (0.2·133·e_fast + 0.8·40·e_slow) = 0.0783156 × 0.393680 × 36.8536 = 1.13625 W
    assert met.activation_heat_rate("SOL", 0.6, 0.3) == pytest.approx(1.13625, rel=1e-4)
    # Ṁ = m (0.2·111·e_fast + 0.8·74·e_slow) = 0.393680 × 57.0449 = 22.4574 W
    assert met.maintenance_heat_rate("SOL", 0.6) == pytest.approx(22.4574, rel=1e-4)


def test_basal_eq_5_48():
    for mu in TABLE:
        assert met.basal_rate(mu + "_r") == pytest.approx(B_hand(mu), rel=REL)


@pytest.mark.parametrize("name", STATES)
def test_shortening_heat_eq_5_47(name):
    s = STATES[name]
    omega_f = -s["qd"]
    want = S_hand(s["tau_m"], omega_f, TAU0_ANKLE_EXT)
    got = met.shortening_heat_rate(s["tau_m"], omega_f, TAU0_ANKLE_EXT)  # default tanh switch
    exact = met.shortening_heat_rate(s["tau_m"], omega_f, TAU0_ANKLE_EXT, omega_smooth=0)
    assert got == pytest.approx(want, rel=REL, abs=1e-12)
    assert exact == pytest.approx(want, rel=REL, abs=1e-12)


@pytest.mark.parametrize("name", STATES)
def test_work_eq_5_50(name):
    s = STATES[name]
    tau = -s["tau_m"] + s["tau_flex"]
    assert met.work_rate(tau, s["qd"]) == pytest.approx(tau * s["qd"], rel=REL, abs=1e-15)


@pytest.mark.parametrize("name", STATES)
def test_total_eq_5_38(name):
    s = STATES[name]
    h = hand_terms(s)
    plain = module_terms(s, forbid_negative=False)
    clipped = module_terms(s)
    for k in ("activation", "maintenance", "basal", "shortening", "work"):
        assert plain[k] == pytest.approx(h[k], rel=REL, abs=1e-12), k
    assert plain["total"] == pytest.approx(h["plain"], rel=REL, abs=1e-12)
    assert plain["per_kg"] == pytest.approx(h["plain"] / BM, rel=REL, abs=1e-12)
    assert clipped["total"] == pytest.approx(h["clipped"], rel=REL, abs=1e-12)


def test_state_signs():
    """The states cover what they claim: zero activation, isometric, concentric, eccentric."""
    h = {n: hand_terms(s) for n, s in STATES.items()}
    assert h["rest"]["activation"] == h["rest"]["maintenance"] == h["rest"]["shortening"] == 0.0
    assert h["rest"]["plain"] == pytest.approx(h["rest"]["basal"]) == h["rest"]["clipped"]
    assert h["isometric"]["shortening"] == 0.0 and h["isometric"]["work"] == 0.0
    assert h["shortening"]["shortening"] > 0 and h["shortening"]["work"] > 0
    assert h["lengthening"]["shortening"] < 0 and h["lengthening"]["work"] < 0
    assert h["lengthening"]["plain"] < 0  # the thesis's plain sum is negative here ...
    assert h["lengthening"]["clipped"] > h["lengthening"]["basal"] - EPS / 2  # ... clipped is not
    # the smooth max costs −ε/2 = −0.05 W on every clearly positive total (not in the thesis)
    assert h["shortening"]["clipped"] - h["shortening"]["plain"] == pytest.approx(-EPS / 2, abs=1e-4)
    # relaxed shortening: heat from 0.16 τ0 ω alone (the zero-activation ambiguity)
    assert h["relaxed_shortening"]["activation"] == 0.0
    assert h["relaxed_shortening"]["shortening"] == pytest.approx((0.16 * TAU0_ANKLE_EXT + 0.18 * 2.0) * 2.0)


# ---- readings where the thesis and Bhargava / OpenSim differ ------------------------------


def test_reading_sign_of_eq_5_47():
    """Module: Bhargava's sign (heat > 0 shortening, < 0 lengthening), not Eq 5.47 as printed."""
    tau0 = TAU0_ANKLE_EXT
    for tau_m, omega_f in [(55.0, 3.0), (45.0, -1.2)]:
        got = met.shortening_heat_rate(tau_m, omega_f, tau0)
        literal = S_thesis_literal(tau_m, omega_f, tau0)
        assert got == pytest.approx(-literal, rel=REL)
        # Bhargava Eq 5.46 with F ≡ τ^M, F0 ≡ τ0, v_CE ≡ −ω_f
        v_ce = -omega_f
        bhargava = -(0.16 * tau0 + 0.18 * tau_m) * v_ce if v_ce <= 0 else -(0.157 * tau_m) * v_ce
        assert got == pytest.approx(bhargava, rel=REL)
    # concentric numbers: (0.16·64.393 + 0.18·55)·3 = 60.609 W, printed Eq 5.47 gives −60.609 W
    assert met.shortening_heat_rate(55.0, 3.0, tau0) == pytest.approx(60.609, rel=1e-4)


def test_reading_case_split_at_zero_torque():
    """τ^M = 0 while lengthening: printed split (τ^M θ̇ = 0 ≥ 0) gives the concentric case,
    −0.16 τ0 θ̇ > 0 of heat; the module splits on ω_f and gives 0.157 × 0 × ω_f = 0."""
    tau0 = TAU0_ANKLE_EXT
    assert S_thesis_literal(0.0, -1.0, tau0) == pytest.approx(0.16 * tau0)
    assert met.shortening_heat_rate(0.0, -1.0, tau0) == pytest.approx(0.0, abs=1e-12)
    assert met.shortening_heat_rate(0.0, -1.0, tau0, omega_smooth=0) == 0.0


def test_reading_basal_per_muscle_mass():
    """Thesis Eq 5.48: 0.0225 W/kg × muscle mass (16 muscles ≈ 0.06 W); OpenSim's default
    whole-body 1.2 W/kg × 41.4 kg = 49.7 W is not what the module uses."""
    total = sum(met.basal_rate(f"{mu}_{sd}") for mu in TABLE for sd in ("r", "l"))
    hand = 2 * sum(B_RATE * mass(mu) for mu in TABLE)
    assert total == pytest.approx(hand, rel=REL)
    assert 0.03 < total < 0.1
    assert abs(total - 1.2 * BM) > 40.0


def test_reading_isometric_torque_is_max_isometric():
    """Thesis Eq 5.47 uses s^τ τ0 (maximum isometric); the nmsk wrapper's default passes that,
    the 'bhargava' option passes a s^τ τ0 t^A instead. Relaxed, moving ankle: only the
    thesis reading makes heat, (0.16 s^τ τ0 + 0.18 τ^M) ω_f."""
    q = {f"{j}_{sd}": 0.0 for j in ("hip", "knee", "ankle") for sd in ("r", "l")}
    qd = dict.fromkeys(q, 0.0)
    qd["ankle_r"] = -2.0  # plantarflexing: the extensor shortens at 2 rad/s
    ex = {f"{mu}_{sd}": 0.0 for mu in TABLE for sd in ("r", "l")}
    out = met.nmsk_metabolic_rate(q, qd, ex, params=mtg.THESIS_PARAMS, forbid_negative=False)
    tau_ext = out["generator_torques"]["ankle_ext_r"]  # passive MTG torque (input, N·m)
    tau_flex = out["generator_torques"]["ankle_flex_r"]
    # ankle flexor lengthens at 2 rad/s: eccentric 0.157 τ_flex × (−2)
    want_S = (0.16 * TAU0_ANKLE_EXT + 0.18 * tau_ext) * 2.0 + 0.157 * tau_flex * (-2.0)
    assert out["shortening"] == pytest.approx(want_S, rel=REL, abs=1e-12)
    assert out["work"] == pytest.approx((-tau_ext + tau_flex) * (-2.0), rel=REL, abs=1e-12)


# ---- whole model: Eq 5.38 summed over 16 muscles, 12 generators, 6 MTG joints -------------

# Adult τ0 (N·m, RBDL Gymnast, model-facts Sec 2) and s^τ (thesis Table 5.2) per generator;
# σ: model-convention joint torque = σ × generator torque, and ω_f = σ q̇ (model-facts Sec 2:
# extensors σ = −s_θ, flexors +s_θ; s_θ = +1 hip, −1 knee, +1 ankle).
GEN = {
    #               τ0_adult  s^τ     σ
    "hip_ext": (175.746, 0.9995, -1.0),
    "hip_flex": (157.293, 1.0067, 1.0),
    "knee_ext": (285.619, 1.0012, 1.0),
    "knee_flex": (98.7579, 1.0026, -1.0),
    "ankle_ext": (127.561, 0.9999, -1.0),
    "ankle_flex": (44.3106, 1.0015, 1.0),
}


def test_whole_model_sum_eq_5_38():
    """nmsk_metabolic_rate at one gait-like state against the hand sum. The generator torques
    τ^M are the MTG model's (an input to the metabolic model, tested in test_mtg.py); every
    metabolic term, the fibre-velocity signs, τ0 (Eq 5.21 × s^τ) and the sums are by hand."""
    scale = (41.4 * 1.47) / (69.6 * 1.732)  # Eq 5.21
    q = {"hip_r": 0.35, "knee_r": -0.6, "ankle_r": 0.1, "hip_l": -0.15, "knee_l": -0.1, "ankle_l": -0.2}
    qd = {"hip_r": 1.5, "knee_r": 3.0, "ankle_r": -1.0, "hip_l": -0.8, "knee_l": -2.0, "ankle_l": -4.0}
    e = dict(zip(TABLE, (0.30, 0.25, 0.40, 0.35, 0.50, 0.20, 0.45, 0.15), strict=True))
    ex = {f"{mu}_{sd}": e[mu] * (1.0 if sd == "r" else 0.6) for mu in TABLE for sd in ("r", "l")}
    ts = {k: 0.1 + 0.02 * i for i, k in enumerate(ex)}
    out = met.nmsk_metabolic_rate(q, qd, ex, params=mtg.THESIS_PARAMS, t_stim=ts, forbid_negative=False)
    gt = out["generator_torques"]

    A = sum(A_hand(k[:-2], v, ts[k]) for k, v in ex.items())
    M = sum(M_hand(k[:-2], v) for k, v in ex.items())
    B = 2 * sum(B_hand(mu) for mu in TABLE)
    S = W = 0.0
    for sd in ("r", "l"):
        for j in ("hip", "knee", "ankle"):
            tau_joint = 0.0
            for d in ("ext", "flex"):
                tau0_adult, s_tau, sigma = GEN[f"{j}_{d}"]
                tau_m = gt[f"{j}_{d}_{sd}"]
                assert tau_m >= 0
                S += S_hand(tau_m, sigma * qd[f"{j}_{sd}"], s_tau * scale * tau0_adult)
                tau_joint += sigma * tau_m
            W += tau_joint * qd[f"{j}_{sd}"]
    for k, want in (("activation", A), ("maintenance", M), ("basal", B), ("shortening", S), ("work", W)):
        assert out[k] == pytest.approx(want, rel=REL), k
    assert out["total"] == pytest.approx(A + M + S + B + W, rel=REL)
    assert out["per_kg"] == pytest.approx((A + M + S + B + W) / BM, rel=REL)
