# %% [markdown]
# # Foot–ground contact parameter identification (thesis Ch 4)
#
# The child model's feet touch the ground through three ellipsoids each (toe, ball, heel;
# Sec 4.1.2). Each ellipsoid has 13 parameters — volumetric stiffness $k_v$ and damping
# $a_v$, static and dynamic friction $\mu_s, \mu_d$, radii $a, b, c$, centre
# $r_x, r_y, r_z$ and 3-2-1 Euler angles $\gamma, \beta, \alpha$ (Table 4.5) — 39 for the
# left foot, mirrored to the right. **The chapter asks how to identify them from gait
# data**, and compares three approaches on the same data (both legs, the left leg by the
# Fourier phase shift of Eqs 4.1–4.3):
#
# * **(a) trajectory optimisation** (Sec 4.3.1): the kinematics are fixed to the data;
#   inverse dynamics gives joint torques and pelvis residual loads, the contact model the
#   GRFs, and the 39 parameters minimise the torque and GRF tracking cost of Eq 4.5 within
#   the bounds of Table 4.7 and $0.55 \le \mu_d/\mu_s \le 0.99$ (Eq 4.4). The thesis used
#   MATLAB's GlobalSearch (scatter search + `fmincon`).
# * **(b) optimal control** (Sec 4.3.2): the direct-collocation data-tracking problem of
#   Eqs 4.6–4.11 (states $q, \dot q, \ddot q$, controls jerks and joint torques, implicit
#   dynamics, residual loads bounded by Eq 4.8, weights of Table 4.8) with the 39
#   parameters as static variables.
# * **(c) optimal control with body parameters** (Sec 4.4): (b) plus the 25 segment and
#   joint parameters (Table 4.14 bounds), a non-negative normal force at each ellipsoid and
#   the Imp and Rsd cost terms (Eqs 4.12–4.13).
#
# The thesis found (b) far better than (a) and (c) better than (b) (Sec 4.5: tangential /
# normal GRF RMSEs 36.5 / 234.6 N, 14.1 / 26.4 N and 3.0 / 10.3 N), and used (c)'s values in
# every later chapter. Later chapters here load the parameters stored in
# `data/identified/ch4_child.json`, with their provenance; whether that file is this page's
# (c) is checked in the last section.
#
# **Where we depart from the thesis, and why**
#
# | | thesis | here | why |
# |---|---|---|---|
# | data | Bovi 2011, 20 children, 0.98 s cycle | Schwartz 2008 *Free* class, 0.991 s | Bovi's data are not public |
# | starting parameters | Brown & McPhee's published adult values (friction 0.40 / 0.35 for (a)) | a **neutral start**: the centre of every Table 4.7 box ($k_v$ at its geometric centre, 3.2·10⁶ N/m³), μ_s = 0.40, μ_d = 0.35 | Brown & McPhee's values could not be obtained; (b) also starts from the thesis's identified set and from ours (below) |
# | (a) search | GlobalSearch + `fmincon` | one local solve from the neutral start, then from the best-scoring points of a seeded Latin-hypercube scatter; IPOPT with exact first and second derivatives in scaled variables | same idea, reproducible, exact derivatives |
# | (a) kinematics | measured (pelvis marker) | our reference: data angles (hip = thigh in the laboratory) and a HAT height at which the thesis's identified contact (Table 4.17), at rest, carries the data's vertical GRF | the public data have no pelvis position; this is the one place the thesis's identified geometry enters |
# | (b), (c) bounds | Table 4.7 (the thesis's (c) values lie partly outside it, so (c) must have used unreported wider bounds) | Table 4.7 verbatim for (a), (b) and (c) | the only bounds printed |
# | (b) start | the data (Sec 4.3.2) with Brown & McPhee's parameters | the data with **three contact starts** — the neutral start, the thesis's identified set (Tables 4.17–4.18) and our stored earlier identification (`data/identified/ch4_child.json`) — each reached through a **continuation** on the residual bounds (±1000 → ±100 → ±10 N with an Rsd penalty, then the exact problem); the converged, valid run with the lowest objective is kept | from the neutral start a direct solve stopped at 1000 iterations, infeasible (see below); different starts end in different local optima (measured below) |
# | the swinging foot | nothing keeps it off the ground | its vertical force ≤ 1 % of body weight while the data say it swings (`swing_load_max`, half the validity gate's 2 %) | without it (b) and (c) identify a contact that carries the body in swing (measured below: the thesis's reading side by side) |
# | Jrk denominators of the HAT's horizontal position and tilt (Eq 4.11) | the range of the reference's jerk, which is zero for both (so 1 m/s³, 1 rad/s³) | the data's (the centre of mass's horizontal jerk from the horizontal GRF; the pelvic tilt's) | with 1 the HAT is pinned to a constant speed (Ch 2, "The jerk term's denominators") |
# | iteration limit of (b), (c) | — | 3,000 | the constrained swing takes (c) past 1,000 |
# | (c) start | not stated | **warm start from (b)**'s solution; body parameters from Sec 4.1.1 | as the brief and the thesis's sequence suggest |
# | cycle ends | start and end states bounded by the data | periodic cycle ($x(t_f) = x(0)$, pelvis advanced one stride) | as in the other chapters |
# | implicit dynamics | square of the difference in $[0, 10^{-12}]$ (Eq 4.10) | equality | the same set, better conditioned |
#
# Thesis values appear only in columns and lines labelled with their table; they were
# obtained on different data, with a different start, software and machine.

# %%
import time
from dataclasses import replace

import numpy as np
import pandas as pd
import matplotlib.pyplot as plt
from IPython.display import Markdown, display

from gaitlib import contact, conventions as cv, data, marks, plots
from gaitlib.model import ChildModel
from gaitlib.studies import contact_id as ci, gait

pd.set_option("display.precision", 3)
pd.set_option("display.width", 200)
free = data.load_gait_data("Free")
tracked = gait.tracking_data(free)  # hip = thigh in the laboratory, as tracked
model = ChildModel()
t_chapter = time.perf_counter()

# %% [markdown]
# ## (a) Trajectory optimisation on the data's kinematics (Sec 4.3.1)
#
# 100 samples of the cycle; cost Eq 4.5 with $w_1 = w_2 = 1/4$ (Table 4.8): the mean over
# the cycle of the squared, range-normalised errors of the six hip/knee/ankle net joint
# torques and the four foot forces. The search: a local solve from the neutral start, then
# from the 10 best-scoring of 200 Latin-hypercube trial points (seed 0; score = cost + 1000 ×
# the violation of Eq 4.4). Each local solve is IPOPT with the exact Hessian.

# %%
a = ci.trajectory_optimization()
print({k: a.stats[k] for k in ("status", "n_local", "n_converged", "best_start", "iterations", "wall_s",
                               "objective", "from_cache")})
a.starts

# %% [markdown]
# ## (b) Optimal control (Sec 4.3.2)
#
# The SK data-tracking problem of Eq 4.11 at the thesis's mesh (20 intervals × 5 LGR
# points) with the 39 contact parameters free. The neutral contact is far too soft to carry
# the body at the tracked kinematics (the feet would have to sink more than 6 cm), so the
# start is far from dynamic consistency. During development, solving the exact problem
# directly from the neutral start — states, torques from the data, zero residuals —
# stopped at IPOPT's 1000-iteration limit with the dynamics still violated, and so did a
# direct start from (a)'s parameters. We therefore reach (b) by a continuation: the same
# problem with residual bounds of ±1000, ±100 and ±10 N (±100, ±10, ±1 N·m) and the Rsd
# term added, each stage warm-started from the previous one (whatever its status), then the
# exact (b) problem. Every stage is listed with its status; the result is the solution of
# the exact problem. The first stage is a device to get near dynamic consistency: if it
# stops at its iteration limit, its last iterate (feasible for its loose bounds or not)
# seeds the next stage, and the table says so.

#
# The problem has local optima: from each of three contact starts (see the departures
# table) the continuation ends somewhere else. Each start's run, and which one is kept (the
# converged run that passes the validity gates with the lowest objective):

# %%
b = ci.optimal_control_multistart()
display(b.starts)
print({k: b.stats[k] for k in ("start", "status", "iterations_final", "iterations", "wall_s", "objective",
                               "max_violation", "from_cache")})
b.stages

# %% [markdown]
# ## (c) Optimal control with the mass and joint parameters (Sec 4.4)
#
# Cost Eq 4.13 (Eq 4.11 + Imp + Rsd, $w_5 = w_6 = 1/4$), 39 + 25 parameters, six path
# constraints $F_{n,e} \ge 0$ on the unclamped normal force of each ellipsoid,
# warm-started from (b)'s solution.

# %%
c = ci.optimal_control_body(warm=b)
print({k: c.stats[k] for k in ("status", "iterations", "wall_s", "objective", "max_violation", "from_cache")})
res = {"a": a, "b": b, "c": c}
c.stages

# %% [markdown]
# ### The thesis's reading beside ours
#
# The same (b) and (c) with the problem as printed — the Jrk denominators of the reference
# (1 for the HAT's horizontal position and tilt), nothing keeping the swinging foot off the
# ground, 1,000 iterations, (b) from the neutral start — against the book's reading above.
# The gates say whether a foot carries load while the data say it swings; $k_v$ shows how
# stiff each reading makes the contact. The rest of this page uses the book's reading.

# %%
b_thesis = ci.optimal_control(ci.spec_b(reading="thesis"))
c_thesis = ci.optimal_control_body(ci.spec_c(reading="thesis"), warm=b_thesis)
readings = ci.reading_table({("b", "thesis"): b_thesis, ("b", "book"): b, ("c", "thesis"): c_thesis, ("c", "book"): c})
readings

# %% [markdown]
# ### Solver statistics and compute times
#
# Wall time = symbolic build + IPOPT, summed over the local solves of (a) and the stages of
# (b). The thesis's times are for MATLAB GlobalSearch / GPOPS-II on an Intel i7-6700
# (Secs 4.3.3 and 4.4.2), labelled.

# %%
approach_marks = {ci.APPROACHES[k]: marks.failure_label(r) for k, r in res.items()}  # None: converged


def mark_approaches(df):
    """A table by approach (its first index level) with † and the failure label on the rows of
    an approach whose solve did not converge."""
    return marks.mark_table(df, {k: approach_marks.get(k[0] if isinstance(k, tuple) else k) for k in df.index})


mark_approaches(ci.solver_table(res))

# %% [markdown]
# ## Ground reaction forces, torques and angles (Figs 4.8, 4.9, 4.12, 4.15)
#
# Grey: the data's mean ± 1 SD (*Free*). (a) is evaluated on the data's kinematics, so its
# angles are the tracked reference; (b) and (c) predict them.

# %%
frames = {ci.APPROACHES[k]: r.channels() for k, r in res.items()}
fig = plots.tracking_figure(tracked, frames, channels=("grf_x_r", "grf_y_r", "grf_x_l", "grf_y_l"), ncols=4,
                            title="Figs 4.9 / 4.15: tangential (x) and normal (y) GRFs", marks=approach_marks)
plt.show()
fig = plots.tracking_figure(tracked, frames, channels=[f"tau_{j}" for j in cv.JOINTS], ncols=4,
                            title="Fig 4.8: net joint torques (metatarsal: no data)", marks=approach_marks)
plt.show()
fig = plots.tracking_figure(tracked, {k: v for k, v in frames.items() if not k.startswith("(a)")},
                            channels=list(cv.JOINTS), ncols=4, marks=approach_marks,
                            title="Fig 4.12: joint angles of (b) and (c) (metatarsal: the planned reference)")
plt.show()

# %% [markdown]
# ## RMSEs beside the thesis (Table 4.9)
#
# Over the cycle (a: its 100 uniform samples; b, c: the 100 collocation nodes). Torques
# N·m, GRFs N, residuals R_x, R_y in N and R_z in N·m (RMS). The thesis reports RMSEs of
# (c) only for the GRFs (Sec 4.4.2).

# %%
t49 = ci.rmse_beside_thesis(res)
marks.mark_table(t49, {k: approach_marks.get(str(k).split(" — ")[0]) if str(k).endswith("ours") else None
                       for k in t49.index})

# %% [markdown]
# Which approach fits the GRFs best — the RMSE of each foot force, their mean, and the GRF
# term of Eq 4.5 (mean squared range-normalised error):

# %%
fit = ci.grf_fit(res)
mark_approaches(fit)

# %% [markdown]
# ### Why the GRF fits differ from the thesis's: where the error is
#
# *Total force.* With the pelvis residuals (nearly) zero, the two feet's forces must add up
# to what the motion requires, $m\,\ddot x_{com}$ and $m(\ddot y_{com} + g)$ — inverse
# dynamics of the floating base with no ground load. The part of the data's total GRF that
# an approach's kinematics cannot produce, $E(t)$, is an error no contact parameters can
# remove; the two feet's RMSEs then average at least $\mathrm{RMS}(E)/2$. For (a), whose
# kinematics are the data reference and whose residuals are free, $E$ is what its residuals
# would have to be if its contact reproduced the data's GRFs exactly.

# %%
dc = ci.dynamic_consistency(res)
dc

# %% [markdown]
# *Load sharing.* The vertical error split between the data's swing (data force below
# 20 N) and stance, and the force a foot carries while the data say it is in the air:

# %%
ph = ci.grf_error_by_phase(res)
ph

# %% [markdown]
# ### Do Table 4.7's bounds hold (c) back?
#
# The thesis's own (c) values (Table 4.17) lie outside Table 4.7 in five entries (toe r_x,
# r_y, γ, α; heel r_x), so its Sec 4.4 identification must have used wider bounds, which it
# does not print. (c′) repeats (c) — same problem, also warm-started from (b) — with Table 4.7
# widened just enough to contain the thesis's (c) values. Compare the GRF fits and which
# parameters sit on a bound:

# %%
cw = ci.optimal_control_body(spec=ci.spec_c(contact_bounds="widened"), warm=b)
print({k: cw.stats[k] for k in ("status", "iterations", "wall_s", "objective", "max_violation", "from_cache")})
approach_marks[ci.APPROACHES["c_wide"]] = marks.failure_label(cw)
display(mark_approaches(ci.grf_fit({"b": b, "c": c, "c_wide": cw})))
for r in (c, cw):
    ab = ci.at_bounds(r)
    print(f"{r.label}: at a bound:", ", ".join(f"{p} ({s_})" for p, s_ in zip(ab["parameter"], ab["bound"])) or "none")

# %% [markdown]
# ### What (c)'s GRF error depends on: one change at a time
#
# The thesis's (c) fits the feet's forces to 3.4 / 2.7 N (tangential) and 9.9 / 10.7 N
# (normal, right / left; Sec 4.4.2, a labelled reference); our target is 1.5 times those.
# The same (c), again warm-started from (b), with one change each (`ci.c_ablation`): each
# tracking weight of Eq 4.13 from Table 4.8's ¼ to 1, the Jrk denominators of the HAT as
# printed (1), the swinging foot unbounded as printed, the 40 × 5 mesh, and the left leg
# tracked as the right leg's samples shifted (below); then the GRF weight raised further
# (×16, ×64; `ci.C_GRF_SCAN`) and ×16 and ×32 with the shifted left leg (`ci.C_GRF_LEFT`).
# These rows are ours (ablations); the book's (c) keeps Table 4.8's weights and Eqs 4.1–4.3's
# left leg. Rows that track the shifted
# left leg are scored against it. The last column
# is the floor each run's own kinematics put under its vertical error (the total-force
# mismatch above). A run that did not converge or fails a gate supplies no number to the
# findings below it.

# %% [markdown]
# *The left leg's data.* The public data hold one leg; as in the thesis (Eqs 4.1–4.3), the
# left leg is the right leg's curves half a cycle later, through a least-squares Fourier
# series of order 5. The data's 51 samples carry 25 harmonics; with all of them the left
# leg is the right leg's samples shifted. Five round the vertical force's loading and
# unloading and ring below zero in swing. The two curves, and each approach's left-foot
# RMSE against both (no re-solve):

# %%
left = ci.left_leg_table(res)
mark_approaches(left)

# %%
cabl, cabl_runs = ci.c_ablation(b)
display(marks.mark_table(cabl, {k: marks.failure_label(r) for k, r in cabl_runs.items()}))
display(Markdown("\n".join(f"- {x}" for x in ci.c_ablation_findings(cabl) + ci.left_leg_findings(left, cabl))))

# %% [markdown]
# ### Do the identified feet stand still? (b) and (c) with a friction lower bound
#
# Table 4.7 lets every friction coefficient go down to 0.01, and the thesis's own final set
# (Table 4.18) puts the ball ellipsoid there (μ_s 0.0101, μ_d 0.0100). A foot whose ball
# slides almost without resistance can carry load while it moves. We measure it: the
# *foot slip* is the tangential velocity of the ellipsoid's contact point that the friction
# law reads, averaged over the cycle weighted by the normal force (`gaitlib.studies.gait.
# foot_slip`; the law treats anything slower than v_tr = 0.1 m/s as sticking). Then the
# change (ours, an ablation; the book's (b) and (c) keep Table 4.7): every μ_s and μ_d
# bounded below by 0.2819, the largest coefficient in Table 4.18 (the toe's μ_d), with (b)
# solved by the same multistart and continuation and (c) warm-started from it
# (`ci.friction_identification`). Volumetric contact carries load by sinking into the
# ground, so an identification that may not slide can choose softer ellipsoids that sink
# deeper instead; the *deepest sink* column measures it (the lowest point of any ellipsoid
# below the ground at any node), and a second variant adds the bound that no ellipsoid
# sinks deeper than 18 mm at any node (`GaitSpec.max_sink`, `ci.SINK_LIMIT`; our choice,
# about the deepest the book's (c) sinks). First, no solve: how fast the feet of the
# tracking reference itself slide — the data's joint angles on this model's legs, the HAT as
# the Q term tracks it (upright, at the walking speed, at the height where the contact
# carries the data's load at rest; `gait.reference_slip`). Then what feet that cannot slide
# for free cost the fit:

# %%
ref_slip = {"ours, ch4_child.json — what Chs 5–8 use": gait.reference_slip(replace(ci.spec_c(), contact_params="ch4")),
            "thesis's Tables 4.17–4.18": gait.reference_slip(ci.spec_c())}
display(Markdown("\n".join(f"- {x}" for x in ci.reference_slip_findings(ref_slip))))

# %% [markdown]
# The model's legs are Table 4.1's proportions of a 1.47 m child (thigh 0.245, shank 0.246 of
# the height); the data are the joint angles of 83 children and a dimensionless speed and
# cadence, which the book turns into m/s and s with the model's leg length (v = v*·√(g L),
# Ch 1). If the data's stride is longer than the data's angles carry the model's legs, the
# loaded feet must move forward while the HAT keeps its speed. A scan, no solve: the same
# reference with the thigh and shank × 0.95 … 1.2 (`GaitSpec.leg_scale`; their COM
# distances and inertias follow, masses unchanged; the speed and cycle time follow the longer
# leg), each scale's force-weighted slip, the same anchored, and the *signed* mean slip
# (> 0: the loaded feet move forward — the HAT outruns the legs' sweep; `gait.leg_scale_slip`).
# A probe of the kinematics, not a body we propose: Ch 5 solves its tracking problem once
# with the legs × 1.1 (one change, in its ablation) to see whether the solution's feet
# follow.

# %%
leg_slip = {k: gait.leg_scale_slip(replace(ci.spec_c(), contact_params="ch4") if k.startswith("ours") else ci.spec_c())
            for k in ref_slip}
for k, t in leg_slip.items():
    print(k)
    display(t)
display(Markdown("\n".join(f"- {x}" for x in ci.leg_scale_findings(leg_slip))))

# %% [markdown]
# Is the missing length a 3-D motion the 2-D model lacks? The pelvis turns about the vertical
# in walking (Schwartz 2008's pelvic rotation, kept in `data/context/`, which no solve reads),
# so a 3-D step is longer than the legs' sagittal sweep by what the stance hip moves back
# relative to the pelvis's centre. The same reference (ours, thesis's legs) with each hip
# moving by ±(w/2)·sin θ(t) for hip joint centres w apart — the rotation added, no solve:

# %%
pelvis_tab, pelvis_w0 = gait.pelvic_rotation_slip(replace(ci.spec_c(), contact_params="ch4"))
display(pelvis_tab)
display(Markdown(ci.pelvic_rotation_findings(pelvis_tab, pelvis_w0, data.context_curve("pelvis_rotation", "Free"))))

# %% [markdown]
# Or is it the length the book converts the data's dimensionless speed and cadence with?
# The reference's stride is v*/f*·L; the distance the data's angles carry the loaded feet
# does not depend on L, so the mean slip gives the L at which the two agree, per contact set:

# %%
display(Markdown(ci.stride_sweep_findings({k: gait.stride_sweep(replace(ci.spec_c(), contact_params="ch4")
                                                                if k.startswith("ours") else ci.spec_c())
                                           for k in ref_slip})))

# %% [markdown]
# Does the identification still put the ball at Table 4.7's lowest friction when the
# reference's feet slide less? (b) and (c) identified again on the legs × 1.1, everything
# else as the book's — (b) by the same multistart and continuation, (c) warm-started from
# its (b) (`ci.leg_identification`):

# %%
leg_runs = ci.leg_identification()
leg_tab = ci.friction_table(leg_runs)
display(marks.mark_table(leg_tab, {k: marks.failure_label(r) for k, r in leg_runs.items()}))
display(Markdown("\n".join(f"- {x}" for x in ci.friction_findings(leg_tab))))
print(ci.leg_label("b", gait.LEG_SCALE))
display(leg_runs[ci.leg_label("b", gait.LEG_SCALE)].starts)

# %% [markdown]
# The (c) on the longer legs is stored as `data/identified/ch4_legs.json`
# (`ci.save_identified(..., name="ch4_legs")`); Ch 5 solves its tracking problem on those
# legs with it (its ablation's row "thigh and shank × 1.1 + Ch 4 (c) identified on them"):

# %%
_lc = leg_runs[ci.leg_label("c", gait.LEG_SCALE)]
display(Markdown(ci.identified_note(ci.identified_vs_result(_lc, "ch4_legs"), _lc)))

# %%
fr_runs = ci.friction_identification()
fr = ci.friction_table(fr_runs)
display(marks.mark_table(fr, {k: marks.failure_label(r) for k, r in fr_runs.items()}))
display(Markdown("\n".join(f"- {x}" for x in ci.friction_findings(fr))))

# %% [markdown]
# Each bounded (b) is a multistart like the book's; its starts side by side (the kept one is
# the converged, valid start with the lowest objective), with how fast each start's feet
# slide and how deep they sink:

# %%
for k, r in fr_runs.items():
    if k.startswith(ci.APPROACHES["b"] + ", friction"):
        print(k)
        display(r.starts)
display(Markdown("\n".join(f"- {x}" for x in ci.friction_starts_findings(fr_runs))))

# %% [markdown]
# ## Residual loads on the pelvis (Fig 4.13)
#
# (a) has no control over them (they are whatever the fixed kinematics and the identified
# contact require); (b) and (c) bound them to ±1 N and ±0.1 N·m (Eq 4.8).

# %%
fig, axes = plt.subplots(1, 3, figsize=(12, 3), constrained_layout=True)
for k, r in res.items():
    pct = 100 * r.residuals.index / free.cycle_time
    for ax, col in zip(axes, cv.RESIDUALS):
        ax.plot(pct, r.residuals[col], label=ci.APPROACHES[k])
for ax, col, u in zip(axes, cv.RESIDUALS, ("N", "N", "N·m")):
    ax.set_title(f"{col} ({u})", fontsize=9)
    ax.set_xlabel("% gait cycle")
axes[0].legend(fontsize=7)
marks.mark_all(fig, marks.joint_label(approach_marks))
plt.show()
fig, axes = plt.subplots(1, 3, figsize=(12, 3), constrained_layout=True)
for ax, col, u in zip(axes, cv.RESIDUALS, ("N", "N", "N·m")):
    for k in ("b", "c"):
        r = res[k]
        ax.plot(100 * r.residuals.index / free.cycle_time, r.residuals[col], label=ci.APPROACHES[k])
    ax.set_title(f"{col} ({u}), (b) and (c) only", fontsize=9)
    ax.set_xlabel("% gait cycle")
axes[0].legend(fontsize=7)
marks.mark_all(fig, marks.joint_label({k: v for k, v in approach_marks.items() if not k.startswith("(a)")}))
plt.show()

# %% [markdown]
# ## Identified ellipsoid geometry (Tables 4.10, 4.11, 4.17; Figs 4.10, 4.11, 4.14)
#
# Left foot, in the foot frame (origin on the ground below the ankle in the standing
# posture; lengths mm, angles deg). Each figure draws ours (solid) over the thesis's
# (dashed) for the same approach, on the model's foot skeleton.

# %%
geo = ci.geometry_table(res)
mark_approaches(geo)

# %%
for k, r in res.items():
    fig = plots.foot_contact_geometry(
        {f"ours {ci.APPROACHES[k]}": r.p_contact,
         ci.THESIS_GEOMETRY_SOURCE[k]: ci.thesis_params(k)},
        model=model, title=f"{ci.APPROACHES[k]}: contact geometry, ours vs {ci.THESIS_GEOMETRY_SOURCE[k]}")
    marks.mark_all(fig, approach_marks[ci.APPROACHES[k]])
    plt.show()

# %% [markdown]
# ## Stiffness, damping and friction (Tables 4.12, 4.13, 4.18)

# %%
mark_approaches(ci.contact_table(res))

# %% [markdown]
# Friction ratios μ_d/μ_s (Eq 4.4 bounds them to [0.55, 0.99]) and the parameters that
# ended on a bound of Table 4.7 (or Table 4.14 for (c)'s body parameters):

# %%
display(ci.friction_ratios(res).rename(columns=lambda a: marks.run_label(a, approach_marks.get(a))))
for k, r in res.items():
    ab = ci.at_bounds(r)
    print(f"{ci.APPROACHES[k]}: {len(ab)} of {39 + (25 if k == 'c' else 0)} parameters at a bound:",
          ", ".join(f"{p} ({s})" for p, s in zip(ab["parameter"], ab["bound"])) or "none")

# %% [markdown]
# ## Body and joint parameters of (c) (Tables 4.15, 4.16)
#
# Initial values (Sec 4.1.1, Tables 4.1–4.3 scaled to 41.4 kg and 1.47 m; K and B of
# Table 4.2), ours identified, the Table 4.14 bounds, and the thesis's initial and tuned
# values (as printed; its initial MOIs differ slightly from $SM\,(ROG\,SL)^2$).

# %%
bt = marks.mark_rows(ci.body_table(c), marks.failure_label(c))
bt

# %%
print(f"total mass: initial {model.total_mass():.2f} kg, ours identified {model.total_mass(c.p_body):.2f} kg, "
      f"thesis tuned {model.total_mass(model.p_body_identified()):.2f} kg (subjects' mean 41.4 kg)")

# %% [markdown]
# ### Normal force of each ellipsoid in (c)
#
# The path constraint of Sec 4.4.1 holds on the unclamped force $k_v V (1 + a_v \dot\delta)$;
# the smoothly clamped force is drawn.

# %%
fig, axes = plt.subplots(1, 2, figsize=(11, 3), constrained_layout=True)
for ax, side in zip(axes, cv.SIDES):
    for e in cv.ELLIPSOIDS:
        col = f"fn_{e}_{side}"
        ax.plot(100 * c.ellipsoids.index / free.cycle_time, c.ellipsoids[col], label=e)
    ax.set_title(f"(c): normal force per ellipsoid, {'right' if side == 'r' else 'left'} foot (N)", fontsize=9)
    ax.set_xlabel("% gait cycle")
    ax.legend(fontsize=7)
marks.mark_all(fig, marks.failure_label(c))
plt.show()

# %% [markdown]
# ## The identified parameters later chapters use
#
# `data/identified/ch4_child.json` holds (c)'s 39 contact and 25 body parameters (SI) with
# the spec, gaitlib version, cache fingerprint of the code, IPOPT status and iterations, the
# date and the bounds. It was written by `contact_id.save_identified` from a (c) solution
# of this chapter; later chapters load it with `GaitSpec(contact_params="ch4",
# body_params="ch4")`. The page only reads it, and checks whether it is the (c) solution
# computed above. Re-saving it changes the problem of every later chapter (and every key of
# their stored solutions), so it is re-saved only together with a re-solve of Chs 5–8.

# %%
cmp = ci.identified_vs_result(c)
print({k: v for k, v in cmp["provenance"].items() if k != "spec"})
print(f"stored file vs this page's (c): largest difference {cmp['max_rel_diff_contact']:.1e} (contact) and "
      f"{cmp['max_rel_diff_body']:.1e} (body) of the bound widths")
display(Markdown(ci.identified_note(cmp, c)))

# %% [markdown]
# ## What we found
#
# Computed from the results above (nothing in this paragraph is typed by hand):

# %%
for line in ci.findings(res, cw, fit, dc, ph) + ci.reading_findings(b, readings):
    print("• " + line)
print(f"• This page ran in {time.perf_counter() - t_chapter:.0f} s "
      f"({'from the solution cache' if all(r.stats['from_cache'] for r in res.values()) else 'solving at least one approach'}).")
