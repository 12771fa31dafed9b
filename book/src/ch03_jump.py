# %% [markdown]
# # The vertical jump: toes and foot–ground contact (thesis Ch 3)
#
# Before building a gait model, the thesis studies a simpler task, the highest possible
# vertical jump, to answer two questions (Ch 3 introduction):
#
# 1. **Which foot–ground contact model gives realistic ground reaction forces (GRFs)?** —
#    a *kinematically constrained* contact (the foot, or the toe, welded to the ground
#    until take-off) or a *3D ellipsoidal volumetric* contact (three compliant ellipsoids
#    per foot, the foot free to move throughout);
# 2. **Do the toes (metatarsal joints) matter?** — a toeless model against a toe-included
#    one.
#
# It predicts three jumps by direct-collocation optimal control, with no experimental data
# to track: **(i)** toeless and **(ii)** toe-included, both with kinematically constrained
# contact (preflight + flight phases), and **(iii)** toe-included with ellipsoid contact
# (crouch + thrust + flight). Its answers: the toe-included model with ellipsoid contact
# jumps highest (thesis Sec 3.4.4: 14, 66 and 89 cm), needs the least static friction
# (Sec 3.4.3: μ_s ≥ 1.4, 1 and 0.12) and shows no torque spike at take-off. This page
# solves the same three problems with `gaitlib.studies.jump` and puts our numbers beside
# the thesis's.
#
# **Units.** SI inside the library; degrees and centimetres only in tables and figure
# axes. Angles are counter-clockwise positive and zero when standing upright: hip > 0
# flexion, knee < 0 flexion, ankle > 0 dorsiflexion, metatarsal (mtp) > 0 toe extension
# (heel up while the toe is on the ground). Torques are positive in the angle's sense.

# %%
import numpy as np
import pandas as pd
import matplotlib.pyplot as plt
from IPython.display import HTML, Markdown, display

from gaitlib import contact, conventions as cv, marks, plots, validity
from gaitlib.jump import JUMP_SEGMENTS, JumpModel
from gaitlib.studies import jump

pd.set_option("display.precision", 3)
pd.set_option("display.max_colwidth", 80)
NAMES = ("toeless", "toe", "ellipsoid")
contact_params = contact.default_params()

# %% [markdown]
# ## The models (thesis Secs 3.1–3.2)
#
# Four (toeless: foot, shank, thigh, head–trunk HT) or five (plus the toe) rigid bodies,
# with the thesis's segment properties, legs already doubled (thesis **Table 3.1, used as
# the model's input**). With the foot (toeless) or the toe (toe-included) welded to the
# ground the model has 3 or 4 degrees of freedom — the joint angles (Tables 3.2–3.3); in
# flight, and throughout with ellipsoid contact, the root segment's position and angle
# (x, y, θ_z of the metatarsal point and the root segment) add three. Each joint has a
# small viscous damper (Sec 3.1.2; 0.1 N·m·s/rad, value not printed in the thesis). The
# ellipsoid model carries a toe ellipsoid on the toe and ball and heel ellipsoids on the
# foot, on both (doubled) feet — with the thesis's identified *child* foot parameters
# (Tables 4.17–4.18), because the adult values Ch 3 used (Brown & McPhee, with a manually
# adjusted damping a_v and friction μ) are not printed. The geometry conventions are in
# `gaitlib.jump`.

# %%
seg = pd.DataFrame(JUMP_SEGMENTS, index=["mass (kg)", "length (m)", "COM from lower joint (m)",
                                         "MOI about COM (kg m²)"]).T
seg.index.name = "body (thesis Table 3.1)"
models = {"toeless": JumpModel(toe=False), "toe": JumpModel(toe=True)}
print(f"total mass: toeless {models['toeless'].total_mass:.2f} kg, toe-included "
      f"{models['toe'].total_mass:.2f} kg; weight {models['toe'].total_mass * cv.G:.0f} N")
seg

# %%
fig, axes = plt.subplots(1, 3, figsize=(8.5, 4.0), constrained_layout=True)
plots.draw_jump(axes[0], models["toeless"], np.zeros(6), ellipsoids=False)
axes[0].set_title("toeless, foot welded", fontsize=9)
plots.draw_jump(axes[1], models["toe"], np.zeros(7), ellipsoids=False)
axes[1].set_title("toe-included, toe welded", fontsize=9)
plots.draw_jump(axes[2], models["toe"], np.zeros(7), ellipsoids=True)
axes[2].set_title("toe-included, 3 ellipsoids", fontsize=9)
for ax in axes:
    ax.set_xlim(-0.45, 0.35)
    ax.set_xlabel("x (m)")
axes[0].set_ylabel("y (m)")
plt.show()

# %% [markdown]
# ## The optimal control problem (thesis Sec 3.3)
#
# **States and controls** (Eqs 3.4–3.5): $x = [q, \dot q, \tau]$, $u = \dot\tau$ — the
# joint torques are states so that their initial and final values can be constrained, and
# their rates are the controls. **Dynamics** (Eqs 3.1–3.2) $M(q)\ddot q + F(q,\dot q) =
# \tau$ with exact derivatives (CasADi); we impose it in implicit form ($\ddot q$ extra
# controls, inverse dynamics $-\ \tau = 0$ a path constraint), the same continuous problem
# as the thesis's $\ddot q = M^{-1}F$ and much better conditioned with the light toe as the
# root segment. **Events** (Table 3.7): COM acceleration zero at the start (static
# equilibrium); vertical GRF zero at take-off (end of the preflight / thrust); COM vertical
# velocity zero at the end of the flight (apex); time and shared states continuous between
# phases. **Path** (Table 3.8): the COM stays within ±Δx of its initial horizontal position.
# **Cost** (Tables 3.9–3.10), with $v_{des}$ = 10 m/s, $y_{des}$ = 1 m, θ_des = −110°:
#
# * kinematic contact: $w_1 (v_{des}/v_{y,COM}(t_{TO}))^2 + w_2 (y_{des}/y_{COM}(t_{apex}))^2$;
# * ellipsoid contact: $w_1 (\theta_{knee} - \theta_{des})^2 + w_2 \dot\theta_{knee}^2$ at
#   the end of the crouch $+\ w_3 (v_{des}/v_{y,COM}(t_{TO}))^2 + w_4 (y_{des}/y_{COM}(t_{apex}))^2$.
#
# **Bounds** (Table 3.5) as printed, except the ankle: we read the thesis's 50–110° as the
# shank–foot angle, 90° standing and decreasing with dorsiflexion, i.e. −20° to +40° in
# our convention (the other reading, −40° to +20°, would allow only 20° of dorsiflexion,
# little for the deep crouches with the heels down of Sec 3.4.1: knee −94° to −150°).
#
# **Where the thesis is silent, our choices** (all fields of `jump.JumpSpec`, listed
# below): the jump starts from standing at rest; the welded ground only pushes
# ($F_y \ge 0$), the heel does not go through it (mtp ≥ 0 while the toe is welded), and in
# flight the ankle and toe tip stay above it; with ellipsoid contact the feet stay on the
# ground during the crouch ($F_y \ge$ 2 % of the weight — without it the optimum hops
# during the "crouch"), take-off is $0 \le F_y \le 1$ N (the smoothed contact law never
# reaches exactly 0) and $F_y \le 7$ N (1 % of the weight) throughout the flight (no
# touch-down); phase-duration ranges; a small torque-rate regularisation $w_{reg}\int\sum_j(\dot\tau_j/\dot\tau_{max})^2dt$
# (goal `reg_taud`, its share of the objective is in the goals table below: nothing in the
# thesis's cost acts on the flight's torques, and without it the torques ring from node to
# node); the apex node's COM is tied to the take-off
# COM by the exact ballistic parabola (without it IPOPT gains metres of "height" in flight
# from the collocation error of the light, fast-spinning toe); and the kinematic models'
# preflight is split into crouch + thrust at a free instant, with no constraint at the
# split, so that the thrust gets its own mesh intervals — GPOPS-II's hp-adaptive mesh
# (Table 3.11: 30 meshes, 4–20 collocation points per interval) refined where needed; we
# use fixed LGR meshes of 10 intervals × 4 points per phase (4: the thesis's minimum),
# with the thrust's intervals shrinking towards take-off, reached by continuation from a
# 5-interval solve. IPOPT tolerance 10⁻⁶ and at most 5000 iterations (Table 3.11).

# %%
b = []
for j, ((a0, a1), (v0, v1), (t0, t1)) in jump.TABLE_3_5.items():
    ours = jump.joint_bounds(j)
    b.append({"joint": j, "angle, thesis (deg)": f"{a0:g} … {a1:g}",
              "angle, ours (deg)": "{:.0f} … {:.0f}".format(*np.degrees(ours["q"])),
              "ang. velocity, ours (deg/s)": "{:.0f} … {:.0f}".format(*np.degrees(ours["qd"])),
              "torque, ours (N·m)": "{:.0f} … {:.0f}".format(*ours["tau"])})
pd.DataFrame(b).set_index("joint").rename_axis("Table 3.5")

# %%
spec_rows = {}
for n in NAMES:
    sp = jump.SPECS[n]
    spec_rows[sp.label] = {
        "weights (Table 3.10)": ", ".join(f"{w:g}" for w in sp.weights),
        "Δx_COM (Table 3.8, cm)": 100 * sp.dx_com,
        "phases": " + ".join(sp.phases),
        "durations (s)": ", ".join(f"{a:g}–{b:g}" for a, b in sp.durations),
        "mesh per phase": f"{sp.n_intervals} × {sp.degree} LGR (thrust refined {sp.thrust_refine:g}:1)",
        "continuation": " → ".join(str(k) for k in sp.continuation + (sp.n_intervals,)),
        "|τ̇| ≤ (N·m/s)": f"{sp.taud_max:g}", "w_reg": f"{sp.w_reg:g}", "IPOPT tol": f"{sp.tol:g}",
        "max iterations": sp.max_iter,
    }
pd.DataFrame(spec_rows).T

# %% [markdown]
# ## Solving the three jumps
#
# Each solve is reloaded from the solution cache only if it was computed from this exact
# specification with this exact code (the key hashes both); otherwise it is solved now.
# A solve that IPOPT does not report as converged is shown as such everywhere below.

# %%
sols = {n: jump.solve(n, use_cache=True) for n in NAMES}
for n, s in sols.items():
    print(f"{s.spec.label:34s} {s.solution.summary().splitlines()[0]}")
jump_marks = {s.spec.label: marks.failure_label(s) for s in sols.values()}  # None: converged


def mark_jump_columns(fig):
    """A failed solve's column of a jump figure gets the red watermark (one column per model)."""
    labs = list(jump_marks.values())
    for k, ax in enumerate(fig.axes):
        marks.mark_axes(ax, labs[k % len(labs)])
    marks.mark_figure(fig, marks.joint_label(jump_marks))
    return fig

# %% [markdown]
# ### Solver statistics
#
# Wall-clock times on this 2-core machine, shared with other work while the book builds
# (one core per solve, `OPENBLAS_NUM_THREADS=1`); `continuation` lists the 5-interval
# solve that gave each final solve its initial guess. The thesis does not report its
# Ch 3 solve times.

# %%
with pd.option_context("display.float_format", "{:.4g}".format):
    display(jump.stats_table(sols))

# %% [markdown]
# The objective term by term (weighted values; `reg_taud` is our regularisation):

# %%
pd.concat({s.spec.label: s.solution.goals.set_index(["phase", "goal"])["weighted"]
           for s in sols.values()}, axis=1)

# %% [markdown]
# ## Joint angles (thesis Fig 3.3)
#
# Columns: the three models, as in the thesis's figures; colours: crouch, thrust (for the
# kinematic models together the thesis's preflight phase) and flight.

# %%
fig = mark_jump_columns(jump.plot_channels(sols, "angles"))
plt.show()

# %% [markdown]
# ## Joint torques (thesis Fig 3.4)

# %%
fig = mark_jump_columns(jump.plot_channels(sols, "torques"))
plt.show()

# %% [markdown]
# How close the torques come to the bounds of Table 3.5 (peak |τ| as a share of the bound
# on that side), and the largest torque change in the last 50 ms before take-off — the
# "sharp fluctuation" the thesis sees in the toe-included kinematic model (Sec 3.4.2):

# %%
rows = {}
for n, s in sols.items():
    tr = s.trajectory
    pre = tr[tr.phase != "flight"]
    t_to = s.jump_height["takeoff_time"]
    last = pre[pre.index >= t_to - 0.05]
    r = {}
    for j in s.model.joints:
        lo, hi = jump.joint_bounds(j)["tau"]
        c = tr[f"tau_{j}"]
        r[f"{j}: peak τ (N·m)"] = c.abs().max()
        r[f"{j}: peak / bound (%)"] = 100 * max(c.max() / hi, c.min() / lo)
        r[f"{j}: Δτ last 50 ms (N·m)"] = np.ptp(last[f"tau_{j}"])
    rows[s.spec.label] = r
pd.DataFrame(rows)

# %% [markdown]
# ## Ground reaction forces and friction (thesis Figs 3.5–3.7, Eq 3.6)
#
# The force of both feet together. For the welded models it is the root reaction; for the
# ellipsoid model the sum of the six ellipsoid forces. The dashed line is the body weight
# (thesis Fig 3.6). Eq 3.6: the static friction coefficient must satisfy
# μ_s ≥ |F_x / F_y|; the ratio is undefined at take-off, where F_y → 0, so we evaluate it
# while F_y ≥ 5 % of the weight (`fy_min_fraction`).

# %%
fig = mark_jump_columns(jump.plot_channels(sols, "grf"))
plt.show()

# %%
fig = mark_jump_columns(jump.plot_channels(sols, "friction"))
plt.show()

# %%
W = models["toe"].total_mass * cv.G
grf_rows = {}
for n, s in sols.items():
    tr = s.trajectory
    c = tr[tr.phase != "flight"]
    grf_rows[s.spec.label] = {"F_x range (N)": np.ptp(c["grf_x"]), "peak F_y (N)": c["grf_y"].max(),
                              "peak F_y / weight": c["grf_y"].max() / (s.model.total_mass * cv.G),
                              "required μ_s = max|F_x/F_y|": s.required_friction,
                              "μ_s, thesis, Sec 3.4.3": jump.THESIS[n]["mu_s"]}
marks.mark_table(pd.DataFrame(grf_rows).T, jump_marks)

# %% [markdown]
# ## Foot position and orientation (thesis Fig 3.8)
#
# The metatarsal (MTP) point — the origin of the root segment — and the angles of the root
# segment (the toe; the foot for the toeless model) and of the foot, relative to standing.

# %%
fig = mark_jump_columns(jump.plot_channels(sols, "foot"))
plt.show()

# %% [markdown]
# ## Jump heights beside the thesis
#
# The thesis does not define its jump height; Sec 3.4.4 reports it with the foot's position
# (Fig 3.8). We give the COM rise during flight (the usual biomechanical jump height,
# $v_{y,TO}^2/2g$), the COM rise from standing, and the lift of the MTP point at the apex.
# The thesis's values are in the columns labelled "thesis".

# %%
results = jump.results_table(sols)
marks.mark_table(results, jump_marks)

# %% [markdown]
# ### How much do these numbers depend on the mesh?
#
# Each final solve started from a 5-interval solve of the same problem (the
# continuation). The coarse and final results side by side:

# %%
mesh_rows = []
for n, s in sols.items():
    for c in s.solution.info.get("continuation", []):
        mesh_rows.append({"jump": s.spec.label, "intervals per phase": c["n_intervals"],
                          "IPOPT status": c["status"], "iterations": c["iterations"],
                          "COM rise in flight (cm)": 100 * c["com_rise_flight"],
                          "take-off v_y (m/s)": c["takeoff_vy"],
                          "required μ_s": c["required_friction"]})
    mesh_rows.append({"jump": s.spec.label, "intervals per phase": s.spec.n_intervals,
                      "IPOPT status": s.status, "iterations": s.solution.iterations,
                      "COM rise in flight (cm)": 100 * s.jump_height["com_rise_flight"],
                      "take-off v_y (m/s)": s.jump_height["takeoff_vy"],
                      "required μ_s": s.required_friction})
pd.DataFrame(mesh_rows).set_index(["jump", "intervals per phase"])

# %% [markdown]
# ## The three jumps
#
# Stick figures drawn by `gaitlib.plots.animate_jump` (the toe-included model with its
# three contact ellipsoids where it has them), with the GRF of both feet as a green arrow
# (one body weight ↦ 0.5 m) from the centre of pressure (welded models) or from the
# normal-force-weighted mean of the ellipsoid centres.

# %%
HTML(plots.animation_html(jump.animate(sols["toeless"], max_frames=30, dpi=60, mark=marks.failure_label(sols["toeless"]))))

# %%
HTML(plots.animation_html(jump.animate(sols["toe"], max_frames=30, dpi=60, mark=marks.failure_label(sols["toe"]))))

# %%
HTML(plots.animation_html(jump.animate(sols["ellipsoid"], max_frames=30, dpi=60, mark=marks.failure_label(sols["ellipsoid"]))))

# %% [markdown]
# ## The physiological jump: joint torques limited by strength
#
# The thesis's Table 3.5 lets every joint produce 1500–4000 N·m. The same three problems
# again, with one change (`JumpSpec(torque_limits="strength")`): at hip, knee and ankle the
# torque must stay, at every node of every phase, within what the muscles can produce at
# that joint angle and angular velocity — the envelope of Ch 5's muscle torque generators
# with the agonist fully active (torque–angle × torque–velocity + passive, thesis Eq 5.8),
# scaled by Eq 5.21 to this model's mass and standing height and doubled for the two legs;
# at the metatarsal joint (no generator) a box of ± the ankle plantarflexors' peak. Phases,
# cost, contact and mesh are the thesis-bounds jumps'. Each solve starts from the same
# problem with box limits only (each joint's peak strength), itself solved through the mesh
# continuation: part of the specification, so the result is reproducible. The human range
# beside the COM rise is a labelled reference (standing vertical jumps, Linthorne 2001). It is
# adults' on purpose: Ch 3's model is Table 3.1's adult (its segments weigh 74 kg), not the
# child of Chs 4–7, so a children's range of jump heights would not be its reference.

# %%
strong = jump.solve_strength(NAMES)
strong_gates = {n: validity.label(s, name=n) for n, s in strong.items()}
marks.mark_table(jump.strength_table(strong, strong_gates),
                 {s.spec.label: marks.failure_label(s) for s in strong.values()})

# %% [markdown]
# **A strength-limited jump that did not converge: the procedure or the problem?** Each
# such jump is solved again by other procedures (`jump.STRENGTH_RETRIES`): no mesh
# continuation (the full mesh straight from the box-limited start), a 7-interval stage
# instead of the 5-interval one, and that with 15,000 iterations instead of Table 3.11's
# 5,000; the spec's own procedure with one change to the problem, **ours**: the welded
# foot's friction capped, |F_x| ≤ μ F_y (μ the static friction Sec 3.4.3 calls satisfactory
# for that welded model: 1 with toes, 1.4 without), alone and with 15,000 iterations — the
# thesis bounds nothing there and reports the friction a jump requires instead. Then the
# linear algebra and the start, one change at a time: the spec's own procedure with MUMPS's
# pivot tolerance raised from IPOPT's default 10⁻⁶ to 10⁻² (more stable pivoting, so IPOPT
# reads the inertia of its KKT matrix more reliably); the full mesh started from the toeless
# jump's strength-limited solution (its metatarsal joint at 0: the foot flat on its toe);
# that start with the raised pivot tolerance; and that with the friction cap. A procedure
# that stops at a feasible point without converging shows that the problem has jumps; one
# that reports infeasibility from every start would point at the problem itself. A retry
# that has not converged supplies no result.

# %%
strong_retries = jump.strength_retries(strong)
if strong_retries:
    display(jump.strength_retry_table(strong, strong_retries))
    display(Markdown("\n\n".join(jump.strength_retry_findings(strong, strong_retries))))

# %% [markdown]
# **What the strength-limited jumps say.** A jump whose own procedure did not converge is
# read through its *stand-in* (`jump.strength_stand_ins`): of its retries that solve the same
# problem (the friction-capped ones change it) and converged and pass the validity gates,
# the one with the lowest objective; the sentence names its procedure.

# %%
strong_stand_ins = jump.strength_stand_ins(strong, strong_retries, lambda s: validity.check(s).passed)
display(Markdown("\n\n".join(jump.strength_findings(strong, {n: validity.check(s).passed for n, s in strong.items()},
                                                      strong_stand_ins))))

# %% [markdown]
# The strength-limited jumps' torques; a jump whose own procedure did not converge is shown
# through its stand-in, named in its column's title.

# %%
shown = {**strong, **strong_stand_ins}
fig = jump.plot_channels(shown, "torques", titles={n: f"{strong[n].spec.label}\n(its stand-in, above)"
                                                   for n in strong_stand_ins})
for k, ax in enumerate(fig.axes):
    marks.mark_axes(ax, marks.failure_label(list(shown.values())[k % len(shown)]))
plt.show()

# %% [markdown]
# ### Why the strength-limited jumps leave the ground crouched: the cost
#
# A human vertical jump leaves the ground with hips and knees nearly straight. The jumps
# above do not: at take-off (the last node before the flight) they are still crouched. Table
# 3.9's cost is two terms, (v_des / v_y,COM(t_TO))² and (y_des / y_COM(t_apex))², with
# v_des = 10 m/s and y_des = 1 m; the thesis reads both as serving the apex height (Sec 3.3).
# The first rewards the vertical speed at take-off whatever the posture. The table shows the
# take-off of each jump under the thesis's cost beside the same problem with that term's
# weight × 0.01 (ours, `jump.apex_cost_spec`: everything else unchanged, solved from the
# thesis-cost optimum, so the one change is the cost; a jump read through its stand-in is
# changed on its stand-in's procedure). "Apex − standing COM" is the COM's highest point above
# where it stood; "COM rise in flight", our reading of the thesis's jump height (Sec 3.4.4
# does not define it), counts from take-off.

# %%
apex = jump.solve_apex_cost(shown)
apex_gates = {**{n: validity.label(s, name=n) for n, s in shown.items()},
              **{f"{n}, apex": validity.label(s, name=f"{n}, apex") for n, s in apex.items()}}
display(marks.mark_table(jump.takeoff_table(shown, apex, apex_gates).round(1),
                         {(s.spec.label, cost): marks.failure_label(s) for n in shown
                          for cost, s in zip(jump.TAKEOFF_COSTS, (shown[n], apex[n]))}))
display(Markdown("\n\n".join(jump.takeoff_findings(
    shown, apex, {f"{n}, apex": validity.check(s).passed for n, s in apex.items()}))))

# %% [markdown]
# ## What we found
#
# Computed from the solutions above (nothing in this list is typed by hand):

# %%
for line in jump.findings(sols, contact_params):
    print("• " + line)

# %% [markdown]
# **Why our heights differ from the thesis's.** Nothing in the thesis's formulation limits
# the jump to a human one: Table 3.5 allows joint torques of 1500–4000 N·m — several times
# what the leg muscles of a 74 kg adult produce — with no torque–velocity or power limit
# (the list above says which torques reach their bounds, and by how many body weights the
# ground pushes). The section on the physiological jump measures what the body's strength
# changes, with everything else held. The problem also has local optima: the continuation
# table shows the coarse optima the final solves started from. That the thesis's GPOPS-II
# solves stayed near a human jump because they started from an experimental jump's postures
# (Table 3.6) within per-phase state ranges it did not print ("defined based on … the
# posture of the human at each phase", Sec 3.3) is a hypothesis we cannot test without
# those ranges. The thesis-bounds numbers are the printed formulation's, not a prediction of
# a human jump. What carries over is the contact comparison: a
# welded foot transmits any tangential force, so |F_x/F_y| is limited by nothing, while
# the velocity-based friction law of the ellipsoids caps it near their friction
# coefficients — the thesis's own explanation of its 0.12 (Sec 3.4.3). Our cap is the
# child foot's toe-ellipsoid μ_s from Ch 4, because the adjusted μ of Ch 3 is not printed.
