# %% [markdown]
# # Appendix: the physics of gaitlib
#
# This appendix shows, with numbers, what the model of the book *is*: the 11-DOF child
# gait model (thesis Ch 4.1), its six contact ellipsoids (thesis Sec 4.1.2), and the
# muscle torque generators (MTGs, thesis Ch 5). Everything is computed by the library, so
# the figures are the model the optimisations use.
#
# **Units and conventions** (defined once, in `gaitlib.conventions`): SI inside the
# library — m, kg, s, rad, N, N·m; degrees and millimetres only in tables and figure axes.
# Ground frame: **X forward**, **Y up**, Z lateral (to the walker's right); the model moves
# in the X–Y plane and every figure is seen from the walker's right side. Angles and
# torques are counter-clockwise (CCW) positive: hip > 0 flexion, knee < 0 flexion, ankle > 0
# dorsiflexion, metatarsal (mtp) > 0 toe extension; all joint angles are 0 when standing
# upright with the foot flat. `pelvis_tx, pelvis_ty` are the position of the hip joint
# centre, `pelvis_tilt` the HAT's (head–arms–trunk) absolute angle.
#
# In every stick figure the **right leg is red**, the **left leg blue**, the HAT dark grey;
# the contact ellipsoids are drawn as the exact outline of their projection on the
# sagittal plane, and the ground reaction force (GRF) of each foot as a green arrow from
# its centre of pressure (1 body weight ↦ 0.5 m). The drawing functions are
# `gaitlib.plots.draw_model`, `animate_gait` and `draw_jump`, shared by all chapters.

# %%
import numpy as np
import pandas as pd
import matplotlib.pyplot as plt
from IPython.display import HTML
from scipy.optimize import brentq

from gaitlib import contact, conventions as cv, data, kinematics, mtg, plots
from gaitlib.jump import JumpModel
from gaitlib.model import ChildModel, ELLIPSOID_LABELS

pd.set_option("display.precision", 4)
model = ChildModel()
p_body = model.default_p_body()
p_contact = contact.default_params()
BW = model.total_mass() * model.g
print(f"body mass {model.body_mass} kg, body height {model.body_height} m; "
      f"sum of segment masses {model.total_mass():.2f} kg, body weight {BW:.1f} N")

# %% [markdown]
# ## Segments
#
# Nine rigid bodies: HAT, and per leg thigh, shank, hind-fore-foot (one rigid body made
# of the fore-foot piece ankle→metatarsal point, AM, and the hind-foot piece heel→ankle,
# HA, at the fixed angle β = 106°) and toe. Lengths are fractions of body height, masses
# fractions of body mass, moments of inertia `SM (ROG·SL)²` about the segment's centre of
# mass (thesis Tables 4.1 and 4.3, scaled to 41.4 kg / 1.47 m); the centre of mass is
# measured from the segment's proximal joint (the HAT's from the hip, upwards). These are
# the defaults `ChildModel.default_p_body()`; the identified values of thesis Tables
# 4.15–4.16 are available as `ChildModel.p_body_identified()`.

# %%
pb = model.p_body_dict(p_body)
rows = {}
for seg in ("hat", "thigh", "shank", "forefoot", "hindfoot", "toe"):
    rows[seg] = {
        "length (m)": model.lengths[seg],
        "mass (kg)": pb[f"mass_{seg}"],
        "COM from proximal joint (m)": model.hat_com_height if seg == "hat" else pb[f"com_{seg}"],
        "MOI about COM (kg m²)": pb[f"moi_{seg}"],
        "count": 1 if seg == "hat" else 2,
    }
seg_table = pd.DataFrame(rows).T
seg_table.index.name = "segment (thesis Tables 4.1, 4.3)"
seg_table

# %% [markdown]
# Passive joint springs and dampers (thesis Table 4.2; the metatarsal joint uses the
# ankle's values), torque `−K q − B q̇` on the distal segment:

# %%
pd.DataFrame({"K (N·m/rad)": [pb[f"K_{j}"] for j in ("hip", "knee", "ankle", "mtp")],
              "B (N·m·s/rad)": [pb[f"B_{j}"] for j in ("hip", "knee", "ankle", "mtp")]},
             index=pd.Index(["hip", "knee", "ankle", "mtp"], name="joint (thesis Table 4.2)"))

# %% [markdown]
# ## Contact ellipsoids
#
# Each foot carries three ellipsoids — *toe* (on the toe segment), *ball* and *heel* (on
# the hind-fore-foot) — with 13 parameters each: volumetric stiffness k_v (N/m³), damping
# a_v (s/m), static and dynamic friction μ_s, μ_d, radii a, b, c along the ellipsoid's own
# axes, centre r = (r_x, r_y, r_z) and three Euler angles γ, β, α (thesis Table 4.5). The
# centre is given in a foot frame whose origin is the ground point below the ankle in the
# standing posture, axes parallel to the ground frame. The values are the thesis's
# identified **left-foot** parameters, **thesis Tables 4.17–4.18 (identified values, used
# as our defaults)**; the right foot is their mirror image in the sagittal plane.
#
# **Orientation — our interpretation.** The thesis does not say how its Euler angles are
# to be read. We read them as a *direction-cosine matrix*: `Rz(γ) Ry(β) Rx(α)` maps segment
# coordinates to ellipsoid coordinates, so the ellipsoid → segment rotation is its
# transpose (`contact.ellipsoid_to_segment`, whose docstring gives the reasons: with this
# reading the ball ellipsoid's long 80 mm axis lies almost horizontally across the
# metatarsal heads and the lowest points of the three ellipsoids are within 8 mm of each
# other, so a standing foot loads all three; read as an active rotation the ball's long
# axis would point 58° downwards and the ball would carry the body alone).

# %%
contact.params_table(p_contact)

# %% [markdown]
# Five of these identified values lie outside the Table 4.7 bounds the thesis states
# (`contact.TABLE_4_17_OUTSIDE_TABLE_4_7`): the thesis's Sec 4.4 identification must have
# used wider bounds it did not print. One consequence is visible in the figures below:
# the toe ellipsoid's centre (r_x = 163 mm) lies *beyond* the tip of the toe segment
# (0.043 BH = 63 mm in front of the metatarsal point, which is 84 mm in front of the ankle).

# %%
print(contact.TABLE_4_17_OUTSIDE_TABLE_4_7)
fg = model.foot_geometry
print(f"ankle height {fg['ankle_height'] * 1e3:.1f} mm; metatarsal point {fg['mtp'][0] * 1e3:.1f} mm "
      f"in front of and heel {-fg['heel'][0] * 1e3:.1f} mm behind the ankle; toe tip "
      f"{(fg['mtp'][0] + model.lengths['toe']) * 1e3:.1f} mm")

# %% [markdown]
# ## Standing
#
# The standing posture has every angle zero; the hip height `pelvis_ty` is found where the
# body is carried by the contact alone — the vertical residual load `R_y` of
# `model.inverse_dynamics` at rest is zero (`scipy.optimize.brentq`, bracketed between
# the geometric leg length `standing_leg_length` — thigh + shank + ankle height, at which
# the heel and metatarsal points touch the ground — and 4 cm above it).

# %%
def R_y(ty, q=None):
    q = np.zeros(11) if q is None else q.copy()
    q[1] = ty
    return model.inverse_dynamics(q, np.zeros(11), np.zeros(11))[1][1]


L = model.standing_leg_length
ty_stand = brentq(R_y, L, L + 0.04, xtol=1e-12)
q_stand = np.zeros(11)
q_stand[1] = ty_stand
tau_s, R_s = model.inverse_dynamics(q_stand, np.zeros(11), np.zeros(11))
c_stand = model.contact(q_stand, np.zeros(11))
bottoms = kinematics.ellipsoid_bottoms(model, q_stand)
print(f"geometric leg length {L:.4f} m; hip height at equilibrium {ty_stand:.4f} m "
      f"(+{(ty_stand - L) * 1e3:.1f} mm)")
pd.DataFrame({"normal force (N)": c_stand["fn"], "share of BW (%)": 100 * c_stand["fn"] / BW,
              "penetration (mm)": -1e3 * bottoms, "force point x (mm)": 1e3 * c_stand["px"]},
             index=pd.Index(ELLIPSOID_LABELS, name="ellipsoid"))

# %%
com_stand = model.com(q_stand)[0]
for i, s in enumerate(cv.SIDES):
    print(f"foot {s}: GRF = ({c_stand['grf_x'][i]:.2f}, {c_stand['grf_y'][i]:.2f}) N, "
          f"centre of pressure x = {1e3 * c_stand['cop_x'][i]:.1f} mm (ankle and hip at x = 0)")
print(f"sum of vertical GRF {c_stand['grf_y'].sum():.2f} N, body weight {BW:.2f} N")
print(f"whole-body COM x = {1e3 * com_stand[0]:.1f} mm; residual loads R = "
      f"({R_s[0]:.3f} N, {R_s[1]:.3f} N, {R_s[2]:.3f} N·m)")
print("joint torques holding the pose (N·m):", {j: round(float(v), 3) for j, v in zip(cv.JOINTS, tau_s)})

# %% [markdown]
# Per foot the heel carries about half of the load, the ball 30 % and the toe 20 %; the
# centre of pressure lies 24 mm in front of the ankle. The whole-body centre of mass is
# almost exactly above the ankle (the feet are the only parts off the vertical line), so
# the perfectly upright pose is in vertical but not in moment equilibrium: the ground
# pushes 23 mm in front of the COM, and the pose needs a clockwise residual moment
# R_z ≈ −406.5 N × 0.023 m ≈ −9.4 N·m on the HAT (and matching joint torques) to be held
# still. A real child stands leaning forward by about 1.7° (23 mm over 0.85 m of COM
# height) — this is a property of the identified ellipsoid positions, not of a bug.

# %%
fig, axes = plt.subplots(1, 2, figsize=(10, 5.5), gridspec_kw={"width_ratios": [1, 2.2]},
                         constrained_layout=True)
plots.draw_model(axes[0], model, q_stand)
axes[0].set_title("standing, all angles 0", fontsize=10)
plots.draw_model(axes[1], model, q_stand, grf_scale=0.1 / BW * 2)
axes[1].set_xlim(-0.09, 0.21)
axes[1].set_ylim(-0.03, 0.1)
for lab, x, b in zip(ELLIPSOID_LABELS[:3], c_stand["px"][:3], bottoms[:3]):
    axes[1].annotate(lab.split("_")[0], (x, b), (x, -0.025), ha="center", fontsize=9,
                     arrowprops={"arrowstyle": "-", "color": "0.5"})
axes[1].set_title("foot (both feet coincide); GRF arrow 0.1 m per half body weight", fontsize=10)
for ax in axes:
    ax.set_xlabel("x (m)")
axes[0].set_ylabel("y (m)")
plt.show()

# %% [markdown]
# ## A mid-stance pose from data
#
# `kinematics.pose_from_data` turns a data set's mean joint angles into model
# coordinates: `pelvis_tx` = speed × t, the HAT upright (`pelvis_tilt` = 0), hip, knee,
# ankle and metatarsal angles of both legs from the data (the metatarsal angles are the
# thesis's planned trajectory, Table 4.6), and `pelvis_ty` such that the lowest of the six
# ellipsoids is exactly 2 mm below the ground (computed from the ellipsoid geometry:
# lowest point `y_c − sqrt(e_yᵀ R D² Rᵀ e_y)`). Because the data's pelvic tilt (≈ 11°
# anterior) contains an anatomical offset and is not the model's HAT angle, the default
# keeps the thighs' orientation in the laboratory: model hip angle = data hip angle +
# data pelvic tilt (model signs). Below, the Schwartz 2008 *Free* class at 25 % of the
# cycle (right heel strike at 0 %), once as produced, and once lowered until the contact
# carries the body weight (`kinematics.settle_height`: R_y = 0, as for standing).

# %%
free = data.load_gait_data("Free")
t_mid = 0.25 * free.cycle_time
q_mid = kinematics.pose_from_data(model, free, [t_mid])[0]
print("q at 25 % (m, rad):", {k: round(float(v), 4) for k, v in zip(cv.COORDS, q_mid)})
print("lowest points of the six ellipsoids (mm):",
      {k: round(float(v), 2) for k, v in zip(ELLIPSOID_LABELS, 1e3 * kinematics.ellipsoid_bottoms(model, q_mid))})
q_mid_settled = q_mid.copy()
q_mid_settled[1] = kinematics.settle_height(model, q_mid)
c_mid = model.contact(q_mid_settled, np.zeros(11))
tau_m, R_m = model.inverse_dynamics(q_mid_settled, np.zeros(11), np.zeros(11))
print(f"settled: hip {1e3 * (q_mid[1] - q_mid_settled[1]):.1f} mm lower; normal forces (N):",
      {k: round(float(v), 1) for k, v in zip(ELLIPSOID_LABELS, c_mid["fn"])})
print(f"right foot GRF ({c_mid['grf_x'][0]:.1f}, {c_mid['grf_y'][0]:.1f}) N at x = {c_mid['cop_x'][0]:.3f} m "
      f"(right ankle at x = {model.points(q_mid_settled)['ankle_r'][0]:.3f} m); "
      f"static residuals R_x = {R_m[0]:.2f} N, R_z = {R_m[2]:.2f} N·m")

# %%
fig, axes = plt.subplots(1, 2, figsize=(9, 5.5), constrained_layout=True, sharey=True)
plots.draw_model(axes[0], model, q_mid)
axes[0].set_title("Free, 25 % of the cycle: lowest ellipsoid 2 mm deep", fontsize=10)
plots.draw_model(axes[1], model, q_mid_settled)
axes[1].set_title("lowered until the contact carries the body weight", fontsize=10)
for ax in axes:
    ax.set_xlabel("x (m)")
axes[0].set_ylabel("y (m)")
plt.show()

# %% [markdown]
# At 2 mm depth only the right toe ellipsoid touches and its force (a few newtons) is too
# small for an arrow. Lowered to static equilibrium the right foot is flat on the ground
# and carries most of the weight, its centre of pressure a few centimetres in front of the
# ankle; the swinging left foot's toe ellipsoid — which extends beyond the toe tip —
# grazes the ground (the data's toe clearance is smaller than the model's toe ellipsoid).
#
# The same construction over a whole cycle gives a kinematic animation of the data
# (`plots.animate_gait`, 40 frames; the camera shows the whole stride with fixed axes).
# Each frame is lowered to static equilibrium, so the green arrows show how a *static*
# body weight would be shared between the feet in that posture — not the measured GRF.

# %%
t_cycle = np.linspace(0.0, free.cycle_time, 40, endpoint=False)
Q_cycle = kinematics.pose_from_data(model, free, t_cycle)
for q in Q_cycle:
    q[1] = kinematics.settle_height(model, q)
anim = plots.animate_gait(model, t_cycle, Q_cycle, Qd=np.zeros_like(Q_cycle),
                          title="Schwartz 2008 Free: data kinematics, statically settled")
HTML(plots.animation_html(anim))

# %% [markdown]
# ## Contact law: normal force, damping, friction
#
# Normal force of one ellipsoid, `F_n = k_v V (1 + a_v δ̇)` (thesis Table 4.4 No. 5):
# `V` is the volume of the ellipsoid below the ground, `δ̇` the penetration rate. Below,
# each of the three ellipsoids in its standing orientation (foot flat) is lowered step by
# step into the ground, at rest (solid) and while pressing in at δ̇ = 0.3 m/s (dashed; for
# the toe and heel a_v ≈ 1.1 and 2.4 s/m raise the force by 34 % and 73 %, the ball's a_v
# is ≈ 0). The depth axis is the penetration of the lowest point. The dotted lines mark
# each ellipsoid's load in the standing equilibrium above.

# %%
depth = np.linspace(0.0, 0.012, 61)
colors = {"toe": "tab:orange", "ball": "tab:green", "heel": "tab:purple"}
fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True)
for k, e in enumerate(cv.ELLIPSOIDS):
    pe = p_contact[contact.ellipsoid_slice(e)]
    k_v, a_v, mu_s, mu_d, a, b, c = pe[:7]
    R = contact.ellipsoid_to_segment(*pe[10:13])  # standing: segment frame = ground frame
    h = np.sqrt(kinematics.shape_matrix(R, (a, b, c))[1, 1])  # centre height at first touch
    for rate, ls in ((0.0, "-"), (0.3, "--")):
        F = [contact.ellipsoid_plane(R, [0.0, h - d, 0.0], [0.0, -rate, 0.0], 0.0,
                                     k_v, a_v, mu_s, mu_d, a, b, c)["fn"] for d in depth]
        axes[0].plot(1e3 * depth, F, ls, color=colors[e],
                     label=f"{e} (k_v {k_v:.3g} N/m³, a_v {a_v:.3g} s/m)" if rate == 0 else None)
    axes[0].axhline(c_stand["fn"][k], color=colors[e], ls=":", lw=0.8)
    v = np.linspace(-0.5, 0.5, 401)
    axes[1].plot(v, contact.friction_coefficient(v, mu_s, mu_d), color=colors[e],
                 label=f"{e} (μ_s {mu_s:.3g}, μ_d {mu_d:.3g})")
axes[0].set(xlabel="penetration depth of the lowest point (mm)", ylabel="normal force (N)",
            title="F_n: at rest (solid), pressing in at 0.3 m/s (dashed)", ylim=(0, 700))
axes[0].legend(fontsize=8)
axes[1].set(xlabel="slip velocity (m/s)", ylabel="μ(v)",
            title=f"Brown–McPhee friction, v_tr = {contact.Smoothing().v_transition} m/s")
axes[1].legend(fontsize=8)
axes[1].axhline(0, color="0.7", lw=0.6)
plt.show()

# %% [markdown]
# The force grows faster than linearly with depth (the cap volume grows like δ² for
# small δ, times the ellipsoid's horizontal cross-section). The friction coefficient is a
# smooth odd function of the slip velocity: it peaks at ≈ μ_s at the transition velocity
# v_tr and tends to μ_d for fast slip (the friction force is `−μ(v) F_n`). The ball's
# identified friction (μ ≈ 0.01) is essentially zero, so in the model the forefoot's grip
# comes from the toe (μ_s 0.34) and heel (0.17) ellipsoids.

# %% [markdown]
# ## Muscle torque generators
#
# Each hip, knee and ankle joint is driven by an extensor and a flexor MTG (thesis Ch 5;
# Millard et al. 2017, RBDL "Gymnast" data). One generator's torque, in its own fibre
# frame where it is never negative, is (thesis Eq 5.8)
#
# τ^M = s^τ τ0 [ a t^A(θ_A) t^V(ω̂) + t^P(θ_f − Δ^P)(1 − β^P ω̂) ],
#
# with the active-torque–angle curve t^A, the torque–velocity curve t^V of the normalised
# velocity ω̂ = ω_f / (s^V ω_max) (ω̂ > 0 shortening) and the passive curve t^P. The fibre
# angle is θ_f = s_θ q with s_θ = +1 (hip), −1 (knee), +1 (ankle), so θ_f > 0 is hip and
# knee flexion and ankle dorsiflexion. The curves are RBDL's quintic Bézier curves, rebuilt
# in `gaitlib.mtg`; below, the six generator types against their knots (the ends of the
# Bézier segments, dots) and named landmarks (crosses: θ*, θ* ± σ, ω̂ = −1, 0, ½, 1 with
# values E, 1, v½, 0, and the passive curve's θ_P0 and θ_P1). Angles in degrees.

# %%
gym = pd.DataFrame({g: {"τ0 adult (N·m)": r.tau0, "τ0 child (N·m)": mtg.tau0(g),
                        "ω_max (rad/s)": r.omega_max, "θ* (deg)": np.degrees(r.theta_star),
                        "σ (deg)": np.degrees(r.sigma), "E": r.E, "v½": r.v_half,
                        "θ_P0 (deg)": np.degrees(r.theta_p0), "θ_P1 (deg)": np.degrees(r.theta_p1)}
                    for g, r in mtg.GYMNAST.items()}).T
gym.index.name = "generator (RBDL Gymnast)"
gym

# %%
kinds = {"active": ("t^A(θ_f)", "fibre angle θ_f (deg)", True),
         "velocity": ("t^V(ω̂)", "normalised velocity ω̂ (> 0 shortening)", False),
         "passive": ("t^P(θ_f)", "fibre angle θ_f (deg)", True)}
fig, axes = plt.subplots(len(mtg.GENERATORS), 3, figsize=(11, 14), constrained_layout=True)
for row, g in zip(axes, mtg.GENERATORS):
    kn = mtg.curve_knots(g)
    for ax, (kind, (name, xlabel, deg)) in zip(row, kinds.items()):
        lo, hi = kn[kind]["domain"]
        pad = 0.15 * (hi - lo)
        x = np.linspace(lo - pad, hi + pad, 400)
        sx = np.degrees if deg else (lambda v: v)
        ax.plot(sx(x), mtg.curve(g, kind)(x), color="k", lw=1.2)
        ax.plot(sx(kn[kind]["x"]), kn[kind]["y"], "o", color="tab:blue", ms=4, label="knots")
        for nm, val in kn["named"][kind].items():
            ax.plot(sx(val[0]), val[1], "x", color="tab:red", ms=6)
        ax.axvspan(sx(lo), sx(hi), color="0.93", zorder=0)
        ax.set_title(f"{g}: {name}", fontsize=9)
        ax.tick_params(labelsize=7)
        if g == mtg.GENERATORS[-1]:
            ax.set_xlabel(xlabel, fontsize=8)
fig.suptitle("MTG curves (grey: curve domain; outside it RBDL extends linearly)", fontsize=10)
plt.show()

# %% [markdown]
# ## The jump models
#
# The vertical-jump models of thesis Ch 3 reuse the same planar-tree code and drawing
# helpers (`plots.draw_jump`): the toeless (4 bodies) and toe-included (5 bodies, with
# the three contact ellipsoids of one foot) models of thesis Table 3.1, in the standing
# posture and in a crouch.

# %%
fig, axes = plt.subplots(1, 3, figsize=(9, 4.5), constrained_layout=True, sharey=True)
toe_model, toeless = JumpModel(toe=True), JumpModel(toe=False)
plots.draw_jump(axes[0], toeless, np.zeros(toeless.n))
axes[0].set_title("toeless, standing", fontsize=10)
plots.draw_jump(axes[1], toe_model, np.zeros(toe_model.n))
axes[1].set_title("toe-included, standing", fontsize=10)
plots.draw_jump(axes[2], toe_model, [0.0, 0.5, -1.1, 0.9])  # welded: mtp, ankle, knee, hip
axes[2].set_title("toe-included, crouch", fontsize=10)
for ax in axes:
    ax.set_xlabel("x (m)")
    ax.set_xlim(-0.45, 0.45)
axes[0].set_ylabel("y (m)")
plt.show()
