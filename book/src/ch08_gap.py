# %% [markdown]
# # Where the model misses reality
#
# Every chapter so far fits a model to child gait data and reports how well it fits. This
# chapter asks the next question: **where** does the simulation leave the data, **which**
# unmodelled effect would explain it, and **how much** of the misfit does that effect
# remove? The thesis answers it by hand, one guess at a time: no co-contraction for the
# tibialis anterior (TA) / gastrocnemius (GAM) mismatch (Sec 5.3.5), no arms (Sec 8.2), a
# left leg generated from the right one with an assumed time shift (Sec 6.2.3), adult joint
# properties for a child (Sec 4.4). Here the diagnosis is a tool, `gaitlib.gap`:
#
# 1. **Locate** — the residual of every channel, standardised by the data's SD, by gait
#    phase, with a test of where it leaves the data's ±1 SD band.
# 2. **Attribute** — re-solve with each candidate effect of a library (small model
#    extensions and laboratory effects with one parameter each), rank them by a criterion
#    that pays for parameters, and say "unexplained" when none is good enough or none
#    stands out from the others.
# 3. **Shrink** — for the top effects, the gap before and after, % closed, with an interval
#    from resampling the data within its SD.
# 4. **Validate on twins** — synthetic data sets made by the model with one effect switched
#    on; the diagnosis, given only the baseline model, must name it.
# 5. **Validate without circularity** — the real data manipulated by editing the file only,
#    by effects inside and outside the library, and twins from another variant of the
#    model; the right answers stated in advance.
#
# The same is available from the shell: `gaitlib gap --data CSV --out DIR` on any tidy CSV
# (the data chapter's format) writes `diagnosis.json` and the figures below;
# `gaitlib gap-twin --effect NAME --magnitude X --seed N --out CSV` writes a twin;
# `gaitlib gap-validate --out DIR` runs the validation of step 5.

# %%
import time

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from gaitlib import cache, gap, marks, validity
from gaitlib.gap import diagnose, locate, twin
from gaitlib.gap import figures as gap_figures
from gaitlib.studies import gap as gap_study
from IPython.display import Markdown, display

pd.set_option("display.precision", 3)
pd.set_option("display.max_colwidth", 70)
pd.set_option("display.width", 200)
T0 = time.perf_counter()

# %% [markdown]
# ## 1. Locate: SD-standardised residuals by channel and phase
#
# For a solution and a data set, every channel — hip, knee and ankle angle (the hip as the
# thigh's angle in the laboratory, as the gait problem tracks it), net joint torques,
# anterior and vertical GRF, both legs, and for muscle models the excitations against the
# EMG — is read on the data's 50-point grid and standardised,
# $z_j = (\mathrm{sim}_j - \mathrm{mean}_j) / \mathrm{SD}^*_j$, with $\mathrm{SD}^*$ the
# data's SD floored at 10 % of its cycle RMS (GRF SDs vanish in swing). The residuals are
# aggregated over the six phases of the data's own cycle events (loading response,
# mid/terminal stance, pre-swing, initial/mid/terminal swing; the left leg's shifted by the
# data's left-leg shift).
#
# **The band test and its assumptions.** Statistical parametric mapping (spm1d) needs each
# subject's curve; the public data give only the group mean and SD, so an equivalent
# pointwise test is used: the data mean is normal with standard error $\mathrm{SD}^*/\sqrt n$
# ($n$ subjects; 82 for Schwartz 2008 *Free*, unknown → 1 for gaitutils), the simulation is
# a fixed curve, and H0 is "the simulation lies inside the population band",
# $|\mathrm{sim}-\mu| \le \mathrm{SD}^*$. At the band edge
# $Z = (|\mathrm{sim}-\mathrm{mean}| - \mathrm{SD}^*)\sqrt n/\mathrm{SD}^*$ is standard normal;
# $p = 1-\Phi(Z)$, Bonferroni over the channel's 50 points (no smoothness assumption,
# conservative). A cell is significant (\*) if any of its points is at α = 0.05.
#
# The baseline here is the SK model (data tracking, Eq 4.11) **fitted** to Schwartz 2008
# *Free* by the diagnosis's objective: the SD-standardised tracking error of these channels
# plus a tenth of the thesis's regularisation (`gaitlib.gap.solve`), on the thesis's full
# 20 × 5 LGR mesh. (The twin validation of Sec. 3, ≈ 560 solves, runs on a coarse mesh and is
# repeated on 20 × 5 at the middle magnitude.)

# %%
dS = gap_study.sk_diagnosis("schwartz2008")
sS = gap_study.summary(dS)
print(f"baseline fit: {dS.baseline.stats['status']}, {dS.baseline.stats['iterations']} iterations; "
      f"RSS = {sS['rss']:.1f} over {dS.located.n_points} points (n_eff = {sS['n_eff']:.0f} resels), "
      f"RMS z = {sS['rms_z']:.2f}; {sS['significant_cells']} of {sS['cells']} cells leave the band significantly")
gap_figures.gap_heatmap(dS.located, title="SK baseline fit vs Schwartz 2008 Free: RMS z by channel and phase (* significant)",
              mark=marks.failure_label(dS.baseline));
plt.show()
gap_study.top_cells(dS.located)

# %% [markdown]
# ## 2. Attribute: the effect library and the criterion
#
# Each candidate is a documented model extension the transcription switches on
# (`GaitSpec.effects`), with one parameter whose null value is the baseline model exactly
# (tested). `k` is the number of parameters it adds. Effects that change only *how* a net
# joint torque is produced (joint stiffness and damping, co-contraction, activation timing)
# cannot show in angles, torques or GRFs — the net torque is fixed by the motion's inverse
# dynamics — so they are candidates only for muscle models, against the EMG (Sec. 5).
#
# Beside these *model* effects the library holds *laboratory* effects: how the data were
# measured and processed, not what the body does — a constant offset of the hip, knee or
# ankle angle (marker placement), a force-plate gain and a force-plate anterior–posterior
# bias in stance. Like the left leg's time shift, they change how the data are read (the
# tracked references inside the NLP, and the data the gap of their solution is computed
# against), not the physics; their null value is the data as published (tested). A
# laboratory's left/right step-time asymmetry is the left leg's time shift.

# %%
gap_study.effect_table()

# %% [markdown]
# **Re-solving.** For a data set the baseline is fitted from five starts
# (`gaitlib.gap.diagnose.BASELINE_STARTS`): the data's own data-based guess; a given
# solution (here the fit of the real data); the spec's own cost function (Eq 4.11) solved
# first, then the fit from it; on a mesh finer than 10 × 3, the fit on 10 × 3 first, then
# the fit from it; and the fit with the GRF channels weighted 100× (their SDs × 0.1) first,
# then the fit of the data as they are from it — a continuation that finds the contact
# pattern before the kinematics. The converged fit with the lowest objective is kept, and
# the table columns `base_start` say which start won. Each candidate is then re-solved with
# its parameter free in the NLP, warm-started from the baseline fit, through the sweep
# (`gaitlib.sweep`: one NLP per effect, re-solved on every data set by swapping its data).
# A candidate contains the baseline model (its parameter's null value), so its fit can
# never be worse than the baseline's; where it did not converge or ends above the
# baseline's objective, it has stopped in a worse local optimum and is re-solved from each
# of the baseline's other starts, the best converged fit kept (`retried` counts these in
# the twin tables, `true_start` says where the injected effect's fit came from). The
# continuation starts and the retry were added, in that order, after the 20 × 5 twin check
# below found single-start fits stalling in local optima. Effects the NLP cannot see (their
# signature is EMG-only) are *profiled*: re-solved at a grid of fixed magnitudes, the one
# with the smallest gap kept.
#
# **Ranking by a penalised criterion.** With RSS the sum of $z^2$ over the located channels
# and points, each model is a Gaussian likelihood with unknown variance on $n_{eff}$
# effectively independent samples — the resel count of the baseline's residual (spm1d's
# smoothness estimate, summed over channels). Then
# $\Delta\mathrm{AIC} = n_{eff}\ln(\mathrm{RSS}_k/\mathrm{RSS}_0) + 2k$ and
# $\Delta\mathrm{BIC} = n_{eff}\ln(\mathrm{RSS}_k/\mathrm{RSS}_0) + k\ln n_{eff}$. Effects are
# ranked by ΔBIC; the top one is named only if it converged and reaches ΔBIC at or below a
# threshold (printed below; "very strong" evidence on Kass & Raftery's scale), else the diagnosis says
# **unexplained**. Verdict "explained" if the named effect also closes ≥ 50 % of the RSS,
# "partial" otherwise. The raw figure (% closed) is shown beside the penalised one.
#
# **Shrink and its interval.** % closed per channel and phase, and overall with a 95 %
# interval from redrawing the data means B = 200 times within SD*/√n (smooth noise, the
# solutions held fixed — the interval covers the data's uncertainty, not the
# re-identification's).

#
# **Out-of-library test.** When the data hold a gap that no library effect represents,
# several effects can each absorb a part of it, and each may pass the threshold against the
# baseline. The top effect is therefore also required to beat every other ranked candidate
# by a margin of ΔBIC (a Bayes factor of the named effect over the runner-up); otherwise the
# diagnosis says **unexplained** and lists the contenders. The margin is a field of the
# method (printed below; 0 means no such test).
#
# **Residual loads.** The HAT's residual forces and moment are located too, against OpenSim's
# residual guidelines (Hicks et al. 2015: peak residual force ≤ 5 % of the peak external
# force, peak moment ≤ 1 % of COM height × that force) rather than a data SD, and are not
# part of the RSS. The gait problem bounds them (thesis Eq 4.8), far below those guidelines
# (table below): residual actuators cannot absorb an effect of this library, whose loads
# therefore show in the tracked channels.
#
# **One frozen method.** The thresholds, grids, the default baseline and the margin live in
# one frozen object (`gaitlib.gap.method.METHOD`); its hash names the method and seeds the
# draws of the validation on manipulated data (Section 3b), so a change of method redraws
# that validation.

# %%
from gaitlib.gap import method as gap_method
print(f"method {gap_method.METHOD.hash()}: threshold ΔBIC ≤ {diagnose.BIC_THRESHOLD:g}; 'explained' from "
      f"{diagnose.EXPLAINED_PCT:g} % closed; runner-up margin {gap_method.RUNNER_UP_MARGIN:g}; "
      f"profile grids {diagnose.PROFILE_GRID}")

# %% [markdown]
# ## 3. Validation on twins whose effect is withheld
#
# A twin of Schwartz 2008 *Free* is the SK model with one effect switched on at a chosen
# magnitude, solved tracking the real data with its own cost function (Eq 4.11); its
# channels become the synthetic mean, the real SD its SD, and smooth noise of SD/√n
# (n = 82, correlation length 5 % of the cycle) is added. It is written in the tidy format
# (both legs) and read back through the same reader as the real data. The diagnosis is then
# run on it with the **baseline model only** and must name the effect. Every SK effect ×
# three magnitudes (small, middle, large) × two noise seeds, plus an effect-free twin per
# seed (correct answer: "unexplained").
#
# **Mesh.** The twin study runs on the coarse 10 × 3 LGR mesh (the default baseline of
# `gaitlib gap`): it takes ≈ 13 solves per twin (six for the baseline's four starts — the
# coarse-mesh start does not apply —, six candidates, the true model, plus the retries) for
# 38 twins, ≈ 2–4 s each here, against ≈ 10× that per solve on the
# thesis's 20 × 5 mesh. The coarse mesh has a cost we measured and report: its 30 nodes
# are sparser than the data's 50 points, so even the true model fitted to its own twin
# leaves a residual above the noise (the heel-strike GRF between nodes); this is why the
# shrink is measured against the true model fitted the same way (below) and also,
# more strictly, against the noise floor.
#
# **Shrink of the injected gap.** For each twin,
# $(\mathrm{RSS}_{base} - \mathrm{RSS}_{top}) / (\mathrm{RSS}_{base} - \mathrm{RSS}_{true})$ with
# $\mathrm{RSS}_{true}$ the true model (the injected effect fixed at its injected magnitude)
# fitted by the same method — the part of the closable gap that the named effect closes;
# undefined when the true model does not improve on the baseline fit (no gap the method
# can see). The stricter figure replaces $\mathrm{RSS}_{true}$ by the generating solution's
# own RSS on its twin (noise only).
#
# The true model is fitted from the same warm start with its magnitude fixed; where that
# fit stops in a worse local optimum than the named effect's free fit, the ratio exceeds
# 100 % (up to ≈ 10× below). The headline figure therefore caps each twin at 100 % — an
# effect cannot close more than the whole injected gap — and the uncapped mean and the
# median are shown beside it.

# %%
tv = gap_study.twin_validation()
acc = tv.accuracy()
acc

# %%
gap_figures.confusion_plot(tv.confusion, title="twins: injected effect (rows) vs effect named by the diagnosis");
plt.show()
rows = tv.rows.copy()
rows[["twin", "injected", "magnitude", "top", "verdict", "correct", "identified_magnitude", "rss_base", "base_start", "rss_top",
      "rss_true_fixed", "rss_gen", "shrink_injected_top", "shrink_vs_noise_top", "dBIC_top", "dBIC_true", "retried",
      "true_start"]]

# %%
st = tv.summary()
wrong = tv.misses()
met = {True: "met", False: "NOT met"}
print(f"twin generation: {st['gen_converged']} of {st['gen_total']} solves converged; diagnosis runs: {st['twins']}")
print(f"top-1 accuracy at the middle magnitude: {st['top1_pct']:.0f} % "
      f"(target ≥ {twin.TARGET_TOP1_PCT:.0f} %: {met[st['top1_met']]})")
print(f"mean shrink of the injected gap over all magnitudes, each twin capped at 100 %: {st['shrink_pct']:.0f} % "
      f"({st['shrink_defined']} twins where defined; target ≥ {twin.TARGET_SHRINK_PCT:.0f} %: {met[st['shrink_met']]}); "
      f"uncapped mean {st['shrink_uncapped_pct']:.0f} %, median {st['shrink_median_pct']:.0f} %; "
      f"against the noise floor: {st['shrink_vs_noise_pct']:.0f} %")
print(f"effect-free twins named 'unexplained': {st['free_unexplained']} of {st['free_twins']}")
print("misnamed twins:")
wrong[["twin", "injected", "magnitude", "top", "dBIC_top", "dBIC_true", "identified_magnitude"]]

# %% [markdown]
# **Where the diagnosis errs.** For each misnamed twin, the criterion of the true model
# fitted the same way (`dBIC_true`, magnitude fixed at the injected value) beside that of
# what was named (`dBIC_top`; empty when nothing was named — no candidate passed the
# threshold, or none beat the others by the runner-up margin):

# %%
thr = diagnose.BIC_THRESHOLD
true_not_better = wrong[wrong["true_not_named"]]
print(f"misnamed twins where even the true model, fitted the same way, would not have been named: "
      f"{len(true_not_better)} of {len(wrong)}")
for r in true_not_better.itertuples():
    print(f"  {r.twin}: ΔBIC true = {r.dBIC_true:.1f}, named = {r.dBIC_top:.1f}" if np.isfinite(r.dBIC_top) else
          f"  {r.twin}: ΔBIC true = {r.dBIC_true:.1f} (threshold {thr:g}; best other candidate "
          f"{r.dBIC_best_other:.1f}, runner-up margin {gap_method.RUNNER_UP_MARGIN:g}), nothing named")

# %% [markdown]
# Where that count equals the number of misnamed twins, the ranking is not what fails:
# either the injected effect is too small to beat the noise and the coarse-mesh residual
# by the criterion even when its magnitude is known (a small body-mass error: the criterion
# refuses to name anything, as it should), or the true model's own fit stops in a worse
# local optimum than a neighbouring effect's (arm swing and foot-contact geometry both
# reshape the stance-phase GRFs). The identified magnitudes in the table above show how
# well each effect is identifiable from angles, torques and GRFs.

# %% [markdown]
# **The same check on the thesis's mesh.** The real-data diagnoses below run on the 20 × 5
# mesh, the twin study above on 10 × 3. The check is repeated on 20 × 5 at the middle
# magnitude of every effect and the effect-free twin, with both noise seeds (≈ 250 full-mesh
# solves, `gaitlib.studies.gap.twin_validation_full_mesh`):

# %%
tvf = gap_study.twin_validation_full_mesh()
rf = tvf.rows
display(rf[["twin", "injected", "magnitude", "top", "verdict", "correct", "identified_magnitude", "rss_base",
            "base_start", "rss_top", "rss_true_fixed", "rss_gen", "shrink_injected_top", "shrink_vs_noise_top", "dBIC_top",
            "dBIC_true", "retried", "true_start"]])
head, *misses = gap_study.twin_full_mesh_lines(tvf)
print(head)
for line in misses:
    print("  " + line)

# %% [markdown]
# **How the method got here.** The earlier versions of this chapter ran the same check
# (measured then, on the same twins): with a single start (data-based guess and the warm
# start from the real-data fit) it named 4 of 6 twins at seed 1 and misnamed the effect-free
# twin, whose baseline fit had stalled at 3× the noise; with the four starts without the GRF
# continuation and without the retry, 9 of 12 over both seeds. The misses were fits, not the
# criterion: a **segment-inertia** twin whose generating gait has a second, brief right-foot
# contact just after toe-off (the GRF drops to near zero and returns within 3 % of the
# cycle), which no start found until the GRF-weighted continuation; and candidates that,
# warm-started only from the kept baseline fit, stopped above the baseline's own objective —
# which the retry now catches. What the current method gives:

# %%
display(Markdown("\n\n".join(gap_study.twin_full_mesh_verdict(tvf))))

# %%
display(Markdown(gap_study.circularity(tvf, dS)))

# %% [markdown]
# ## 3b. Validation that is not circular: the real data manipulated
#
# Twins are made by the model the diagnosis searches. Here the **real** Schwartz 2008 *Free*
# data are manipulated by editing the data file only — no gaitlib model or effect code
# (`gaitlib.gap.validate.INJECTIONS`) — and each manipulated file is diagnosed as a user's
# CSV would be. The right answer of every manipulation is stated in the code, in advance:
#
# - *independent* set (a library effect represents it): all loads × (1 + m) (moments, powers,
#   GRFs: what a body-mass error does; expected `body_mass`), a hip, knee or ankle angle
#   offset (expected that joint's offset), a force-plate gain and an anterior–posterior
#   plate bias in stance (expected `grf_scale`, `grf_ap_bias`); a gain (the load scale, the
#   plate gain) multiplies the SD with the mean, as it multiplies every child's curve;
# - *out-of-library* set (no library effect represents it; expected **unexplained**): a knee
#   range of motion scaled about its mean (knee-axis cross-talk), a swing-phase hip bump, the
#   ankle moment and power scaled alone (an inverse-dynamics error), a larger loading peak of
#   the vertical GRF.
#
# Each manipulation has magnitude bands (small, middle, large; the out-of-library set middle
# and large); one magnitude per band is drawn from a generator seeded by the method's hash.
# The data already carry their own gap, so every injection sits on top of it, as it would in
# a laboratory. The baseline is `gaitlib gap`'s default 10 × 3 mesh with the per-node
# derivative path. The validation is 27 diagnoses (≈ 500 solves); it is run by the command
# printed below, whose output (`benchmarks/results/gap_validation/`) this page reads —
# refusing it if it was made by another method than the current one (its hash).

# %%
val = gap_study.stored_validation("real")
print(f"method {val.settings['method_hash']}; baseline {val.settings['base']}")
print("written by:", gap_study.VALIDATION_RUNS["real"])
display(val.scores())
display(val.confusion())
gap_study.validation_cases(val)

# %%
display(Markdown("\n\n".join(gap_study.validation_lines(val))))

# %% [markdown]
# **A change of method found on this validation (revision 2).** In the first frozen method the
# force-plate gain effect (`grf_scale`) divided the data's GRF means by (1 + s) but left their
# SDs as published. A gain multiplies every child's force, so the SD as well; dividing the
# mean only shrinks every GRF residual by 1/(1 + s) whatever causes it, so a positive gain
# "closed" part of any gap in which the model's forces fall short of the data's.
# The standardised residual under a gain is now ((1 + s)·sim − mean)/SD, on the data's own
# scale like the baseline's (`gaitlib.effects.GRF_SCALE`, version 2, tested by hand), and the
# validation's gain manipulations scale the SD with the mean. Both changed how the diagnosis
# decides, so the method's revision was bumped and every draw redrawn (the hash seeds
# them). The validation as the first method ran it (other draws, so rates rather than pairs)
# beside this one:

# %%
val_rev1 = gap_study.superseded_validation("real_rev1")
display(Markdown("\n\n".join(gap_study.revision_lines(val_rev1, val))))

# %% [markdown]
# **How visible an injection is.** Against the real data's own gap, an injection is seen only
# as far as it makes the baseline fit worse: `added_pct` is the RSS of the baseline's fit of
# the manipulated data minus that of its fit of the unedited data (% of the latter) — at
# most what the right effect can close. Where the baseline model can follow a manipulation
# (a crouched knee, a tilted thigh) at little cost elsewhere, the manipulation adds little
# gap, and the effect that explains the most of the data's *own* gap keeps the first rank:

# %%
gap_figures.validation_plot(val.rows);
plt.show()
display(Markdown(gap_study.visibility_text(val)))

# %% [markdown]
# **How much moves when nothing is injected.** An injection can be named only if it moves
# the diagnosis's numbers further than the data's own uncertainty does. The *null* set
# measures that: the unedited data with only the sampling error of their means redrawn
# (SD/√n times a smooth unit curve, the twins' noise model; the draws' seeds from the
# method's hash), diagnosed the same way. The first table is every candidate's ΔBIC on the
# unedited data and over the draws. The second puts each independent injection against
# that spread: the expected effect's ΔBIC, its null mean and SD (z = how many null SDs the
# injection moved it), and `needed`: the ΔBIC it must reach to be named while every other
# candidate keeps its null mean (the threshold, or the best other candidate's null mean
# minus the runner-up margin, whichever is lower).

# %%
valn = gap_study.stored_validation("null")
print("written by:", gap_study.VALIDATION_RUNS["null"])
null_cands, null_vis = gap_study.null_tables(valn, val)
display(null_cands.round(1))
display(null_vis.round(2))
display(Markdown("\n\n".join(gap_study.null_lines(valn, val))))
refit = gap_study.stored_null_refit()
if refit is not None:
    display(Markdown("\n\n".join(gap_study.null_refit_lines(refit))))

# %% [markdown]
# Two more experiments outside the method ask whether the injections are lost in the
# baseline's local optimum or in the runner-up test. The first gives every independent
# injection's baseline the unedited data's fit as one more start. The second takes every
# case whose top effect passed the threshold but not the runner-up margin, fits the two
# effects together, and asks whether the top effect still passes given the runner-up (it
# then explains a part of the gap the runner-up does not):

# %%
for _rel, _script, _lines in (("gap_normative_start.json", "gap_normative_start.py", gap_study.normative_start_lines),
                              ("gap_pair_test.json", "gap_pair_test.py", gap_study.pair_test_lines)):
    _r = gap_study.stored_experiment(_rel, _script)
    display(Markdown("\n\n".join(_lines(_r)) if _r is not None else f"(`benchmarks/{_script}`: not run)"))

# %% [markdown]
# **Model-variant twins.** Twins generated by *another variant* of the model than the one
# diagnosed — the thesis's identified body parameters (Tables 4.15–4.16) instead of the
# scaled defaults, or our Ch 4 contact parameters instead of the thesis's — solved with the
# spec's cost function against the real data and noised as the twins of Section 3; the
# right answer is the family of library effects that represents the variant, stated in
# advance (`gaitlib.gap.validate.VARIANTS`: body → segment inertia, body mass, HAT COM;
# contact → foot contact geometry, friction). Two noise seeds each, drawn from the method's
# hash:

# %%
valv = gap_study.stored_validation("variants")
print("written by:", gap_study.VALIDATION_RUNS["variants"])
display(gap_study.validation_cases(valv))
display(Markdown("\n\n".join(gap_study.validation_lines(valv)[:-1])))

# %% [markdown]
# **A change relative to a reference.** The injections above are lost in the real data's own
# gap: the baseline's RSS on the unedited data is far larger than what a middle-sized
# laboratory effect adds. A laboratory often asks a question that does not carry that gap:
# *what changed between two data sets* — its own children against a normative set, one
# marker protocol against another, before and after a plate recalibration. `gaitlib gap
# --data CSV --reference REF` answers it (`gaitlib.gap.reference`): the baseline and every
# candidate are fitted to the reference as in the absolute diagnosis (every start), the data
# are fitted as the continuation of those fits (the baseline from the reference's fit, each
# candidate from its own fit of the reference), and each model's located gap has its own
# residual on the reference subtracted, [F_k(N) − N] − [F_k(R) − R]. When nothing changed the
# gap is the sampling error; an effect whose parameter change is the whole change closes it.
# Stated assumptions: the model's own misfit does not change with the effect (first order),
# and both data sets share speed class and time grid. Here the reference is the unedited
# data resampled within SD/√n, every manipulated set is resampled too (two independent
# groups), and four *null* draws — the unedited data resampled, nothing changed — must read
# "unexplained". The second table gives, for every independent injection, the change the
# expected effect's fit identified between the reference and the data (`parameter_change` of
# the ranking) against the change that undoes the manipulation
# (`gaitlib.gap.validate.effect_magnitude`: rad, model signs; gains; N).
#
# *The first reading* (no calibration; the same draws as the absolute validation above, so
# each case is paired with its absolute diagnosis) showed what a clean background does to the
# criterion — read the last paragraph:

# %%
valr0 = gap_study.superseded_validation("relative_rev0")
display(valr0.scores())
display(gap_study.relative_cases(valr0, val))
display(gap_study.relative_magnitudes(valr0).round(4))
display(Markdown("\n\n".join(gap_study.relative_lines(valr0, val))))

# %% [markdown]
# So the relative diagnosis calibrates its threshold on the reference itself
# (`gaitlib.gap.method.RELATIVE`, revision 1): the reference is redrawn K times within the
# sampling error of a difference, each draw is diagnosed relative to the reference exactly as
# the data are, and the top effect must also beat the lowest ΔBIC any candidate reached on
# any draw — a max-statistic test over the candidates at level 1/(K + 1). A change of method
# redraws the validation (its magnitudes follow the relative method's hash), so the result
# below is on draws the calibration was not designed on (revision 1, superseded below):

# %%
valr1 = gap_study.superseded_validation("relative_rev1")
print(f"relative method {valr1.settings['relative_method_hash']}: {valr1.settings['relative_method']}")
display(Markdown("\n\n".join(gap_study.calibration_lines(valr1))))
display(valr1.scores())
display(gap_study.relative_cases(valr1, val))
display(gap_study.relative_magnitudes(valr1).round(4))
display(Markdown("\n\n".join(gap_study.relative_lines(valr1, val))))
_rb = gap_study.stored_reference_basin()
display(Markdown("\n\n".join(gap_study.reference_basin_lines(_rb)) if _rb is not None
                 else "(`benchmarks/gap_reference_basin.py`: not run)"))

# %% [markdown]
# So revision 2 makes the reference fit *self-consistent* (`RELATIVE.reference_rounds`,
# `gaitlib.gap.diagnose.consistent_fits`): after the data's continuation, each model's fit of
# the reference (the baseline's and every NLP-identified candidate's) is re-solved from its
# fit of the data; where that reaches a lower objective on the reference, it replaces the
# model's reference fit for this data set and the data are continued again from it (the lower
# data fit kept; a second round for the models whose data fit moved). The null draws of the
# calibration are fitted the same way, so the threshold is this procedure's own. Again on
# fresh draws (the relative method's hash changed; revision 2, superseded below):

# %%
valr2 = gap_study.superseded_validation("relative_rev2")
print(f"relative method {valr2.settings['relative_method_hash']}: {valr2.settings['relative_method']}")
display(Markdown("\n\n".join(gap_study.calibration_lines(valr2) + gap_study.consistency_lines(valr2))))
display(valr2.scores())
display(gap_study.relative_cases(valr2, val))
display(Markdown("\n\n".join(gap_study.relative_lines(valr2, val) + gap_study.tie_lines(valr2))))

# %% [markdown]
# Where the hip-offset injections end in a tie with `hat_com` (last paragraph), the two are
# the same change on the located channels. The model's HAT can tilt by the offset with
# its centre of mass kept over the hips (a HAT COM offset), which moves the hip angle it
# tracks — the thigh in the laboratory less the HAT's tilt — as a marker offset of the hip
# does, with the same loads to first order; only the HAT's tilt differs, and it was not located
# (absolute, the model's upright HAT against the data's forward-tilted pelvis is a constant
# misfit of the model). Relative to a reference that constant cancels, so revision 3
# (`RELATIVE.tilt_channel`, `gaitlib.gap.locate.RELATIVE_ONLY`) locates the HAT's tilt
# against the data's pelvic tilt as one more channel. Fresh draws again (revision 3,
# superseded below):

# %%
valr3 = gap_study.superseded_validation("relative_rev3")
print(f"relative method {valr3.settings['relative_method_hash']}: {valr3.settings['relative_method']}")
display(Markdown("\n\n".join(gap_study.calibration_lines(valr3) + gap_study.consistency_lines(valr3))))
display(valr3.scores())
display(gap_study.relative_cases(valr3, val))
display(Markdown("\n\n".join(gap_study.relative_lines(valr3, val) + gap_study.tie_lines(valr3))))
_bb = gap_study.stored_baseline_basin()
display(Markdown("\n\n".join(gap_study.baseline_basin_lines(_bb)) if _bb is not None
                 else "(`benchmarks/gap_baseline_basin.py`: not run)"))

# %% [markdown]
# So revision 4 (`RELATIVE.baseline_from_candidates`) re-solves the baseline's fit of the
# data from every nested candidate's fit of it before the reference's self-consistency
# rounds, and keeps the lowest: each of those candidates contains the baseline, and a
# baseline re-solved from one of their trajectories that ends lower than the continuation
# shows the continuation had stopped short. The null draws
# of the calibration are fitted the same way. Fresh draws again (revision 4, superseded below):

# %%
def show_relative(v):
    """A relative validation as this section shows it: its method, calibration, scores, cases,
    identified magnitudes and the sentences computed from them."""
    print(f"relative method {v.settings['relative_method_hash']}: {v.settings['relative_method']}")
    display(Markdown("\n\n".join(gap_study.calibration_lines(v) + gap_study.consistency_lines(v))))
    display(v.scores())
    display(gap_study.relative_cases(v, val))
    display(gap_study.relative_magnitudes(v).round(4))
    display(Markdown("\n\n".join(gap_study.relative_lines(v, val))))


def show_fresh(v, label):
    """A revision's validation on its own fresh draws: :func:`show_relative`, then what set
    its threshold, the threshold rules, the common-mode draws, fixed thresholds, the misses
    and the null's tail."""
    show_relative(v)
    display(Markdown("\n\n".join(gap_study.threshold_draw_lines(v, label))))
    display(gap_study.rule_table(v))
    display(gap_study.common_mode_table({label: v}).round(1))
    display(gap_study.threshold_sweep({label: v}))
    display(gap_study.ranking_misses({label: v}))
    display(Markdown("\n\n".join(gap_study.threshold_lines({label: v}) + gap_study.null_tail_lines({label: v}))))


def show_second_set(v0, v1, label):
    """A revision's second set of draws (``v1``) beside its first (``v0``): :func:`show_fresh`,
    its pairs and what the share floor held, then both pooled with their intervals, the
    fixed thresholds and the misses on the pooled cases. Returns the two as replicates."""
    show_fresh(v1, f"{label}, replicate 1")
    display(gap_study.pair_counts(v1))
    display(Markdown("\n\n".join(gap_study.floor_held_lines(v1, f"{label}, replicate 1"))))
    reps = {"replicate 0": v0, "replicate 1": v1}
    display(gap_study.replicate_table(reps))
    display(Markdown("\n\n".join(gap_study.replicate_lines(reps))))
    return reps


valr4 = gap_study.superseded_validation("relative_rev4")
show_relative(valr4)

# %% [markdown]
# **The same method on other draws.** Every number above comes from one reference draw and
# one draw of magnitudes and resampling seeds, and the threshold moved between revisions
# whose draws all differed (first line below) — the method's change and the draws' cannot be
# told apart that way. A second replicate (`gaitlib gap-validate --replicate 1`) keeps the
# method (revision 4, the same hash) and draws everything afresh: the reference, its null
# draws (so the threshold), the magnitudes, signs and resampling seeds. The two together
# give each target group twice the cases, with a 95 % interval (Wilson's) on the pooled rate:

# %%
print("thresholds (ΔBIC ≤) by revision, each on its own draws: " + ", ".join(
    f"revision {k} {gap_study.calibration_threshold(v):.0f}" for k, v in ((1, valr1), (2, valr2), (3, valr3), (4, valr4))))
valr4_1 = gap_study.superseded_validation("relative_rev4_r1")
display(Markdown("\n\n".join(gap_study.calibration_lines(valr4_1))))
display(valr4_1.scores())
reps4 = {"replicate 0": valr4, "replicate 1": valr4_1}
display(gap_study.replicate_table(reps4))
display(Markdown("\n\n".join(gap_study.replicate_lines(reps4) + [
    x for lab, v in reps4.items() for x in gap_study.threshold_draw_lines(v, lab)])))

# %% [markdown]
# **What a threshold can do, and what it cannot.** A case's verdict depends on the threshold
# only through "the first-ranked effect's ΔBIC at or below it" (the runner-up margin does
# not depend on it), so every case of both replicates can be decided again at any fixed
# threshold from its stored ranking (`gap_study.named_at`; replayed at each replicate's own
# threshold it gives back every stored verdict — `tests/test_gap_validate.py`). Pooled over
# the two replicates:

# %%
display(gap_study.threshold_sweep(reps4))
display(gap_study.ranking_misses(reps4))
display(Markdown("\n\n".join(gap_study.threshold_lines(reps4))))

# %% [markdown]
# The load family's misses, looked at channel by channel (`benchmarks/gap_load_confusion.py`,
# an experiment outside the frozen method: every middle and large `load_scale` and
# `plate_gain` case of both replicates diagnosed again, ranking only, and the located
# relative RSS of the baseline, `body_mass` and `grf_scale` split by channel kind — the net
# joint torques being the only channels in which a normalising-mass error and a plate gain
# differ):

# %%
_lc = gap_study.stored_load_confusion()
display(Markdown("\n\n".join(gap_study.load_confusion_lines(_lc)) if _lc is not None
                 else "(`benchmarks/gap_load_confusion.py`: not run)"))

# %% [markdown]
# **Revision 5: a threshold that one draw does not set.** Revisions 1–4 named an effect only
# beyond the lowest statistic of 9 null draws (each draw's lowest ΔBIC over the candidates):
# a test at level 1/10 whose threshold is one extreme of 9 values, and it moved with the
# draws alone between revision 4's replicates (above; the draw that set each is described
# under the replicates' table). Revision 5 keeps the level and takes the second lowest of 19 draws' statistics
# (`RELATIVE.null_rank`, `gaitlib.gap.method.null_threshold`): one such draw no longer sets
# the threshold. The change was made after seeing revision 4's replicates, so its
# validation is on fresh draws (the relative method's hash changed; revision 5, superseded
# below):

# %%
valr5 = gap_study.superseded_validation("relative_rev5")
show_relative(valr5)

# %% [markdown]
# The same cases decided by both rules (paired: the same rankings, only the threshold
# differs — revisions 1–4's rule applied to the first 9 of these 19 null draws, which are
# the draws a 9-draw calibration of this method would have made), and what any fixed
# threshold gives on them:

# %%
display(gap_study.rule_table(valr5))
display(gap_study.threshold_sweep({"revision 5": valr5}))
display(gap_study.ranking_misses({"revision 5": valr5}))
display(Markdown("\n\n".join(gap_study.threshold_lines({"revision 5": valr5}))))

# %% [markdown]
# **Revision 6: the quiet points.** The load family's misses trace largely to the GRFs in
# swing (the experiment above): there every child's force is zero — no variance in the data
# or the reference — yet the model's feet carry load, and a candidate that makes the model heavier changes that
# load. Nothing in the data can change at such a point, so a located change there is the
# model's own misfit changing, which the relative method assumes away. Revision 6
# (`RELATIVE.quiet_points`, `gaitlib.gap.reference`, "Quiet points") leaves out the points
# where both SDs are below the locate floor. First, paired: revision 5's own draws — the
# same reference, null draws, manipulations and seeds, so the same fits — located with the
# quiet points left out, the rest of revision 5 unchanged, its null threshold recomputed on
# its null draws so located (`benchmarks/gap_paired.py quiet_points_rev5`):

# %%
valq = gap_study.stored_paired("quiet_points_rev5")
if valq is not None:
    pair = {"revision 5": valr5, "revision 5's draws, quiet points left out": valq}
    display(gap_study.replicate_table(pair).drop(columns=["pooled", "pooled %", "95 % interval"]))
    display(gap_study.threshold_sweep({"quiet points left out": valq}))
    display(gap_study.ranking_misses({"quiet points left out": valq}))
    display(Markdown("\n\n".join(gap_study.paired_lines(valr5, valq, gap_study.PAIRED["quiet_points_rev5"])
                                   + gap_study.threshold_lines({"quiet points left out": valq}))))
else:
    print("(benchmarks/gap_paired.py quiet_points_rev5: not run)")

# %% [markdown]
# Then revision 6 on fresh draws (its hash changed):

# %%
valr6 = gap_study.superseded_validation("relative_rev6")
show_relative(valr6)
display(Markdown("\n\n".join(gap_study.threshold_draw_lines(valr6, "revision 6"))))
display(gap_study.rule_table(valr6))
display(gap_study.threshold_sweep({"revision 6": valr6}))
display(gap_study.ranking_misses({"revision 6": valr6}))
display(Markdown("\n\n".join(gap_study.threshold_lines({"revision 6": valr6}))))

# %% [markdown]
# **Revision 6 on a second set of draws** (`--replicate 1`: the reference, its 19 null draws,
# the magnitudes, signs and resampling seeds drawn afresh, the method unchanged), and both
# replicates pooled, with a 95 % interval on each pooled rate:

# %%
valr6_1 = gap_study.superseded_validation("relative_rev6_r1")
display(Markdown("\n\n".join(gap_study.calibration_lines(valr6_1))))
display(valr6_1.scores())
display(gap_study.rule_table(valr6_1))
reps6 = {"replicate 0": valr6, "replicate 1": valr6_1}
display(gap_study.replicate_table(reps6))
display(Markdown("\n\n".join(gap_study.replicate_lines(reps6) + [
    x for lab, v in reps6.items() for x in gap_study.threshold_draw_lines(v, f"revision 6, {lab}")])))
display(gap_study.threshold_sweep(reps6))
display(gap_study.ranking_misses(reps6))
display(Markdown("\n\n".join(gap_study.threshold_lines(reps6))))

# %% [markdown]
# **The null's tail.** Revision 5's null cases named an effect beyond its threshold, and
# revision 6's calibrations set thresholds that held back injections its ranking had right
# (its rule tables above; the draw behind each lowest statistic is described there too).
# Every relative validation has two kinds of draw of the same null — its calibration's
# draws and its `null` cases (the unedited data resampled, nothing changed) — side by side
# (revisions 1–3 fitted and ranked differently; the first pooled sentence counts revision
# 4's replicates and revision 5, whose fits and rankings are made the same way, the second
# revision 6's two replicates, which leave the quiet points out of the location):

# %%
null_all = {"revision 1": valr1, "revision 2": valr2, "revision 3": valr3, "revision 4": valr4,
            "revision 4, replicate 1": valr4_1, "revision 5": valr5, "revision 6": valr6,
            "revision 6, replicate 1": valr6_1}
display(gap_study.null_tail_table(null_all).round(1))
null_same = {k: null_all[k] for k in ("revision 4", "revision 4, replicate 1", "revision 5")}
display(Markdown("\n\n".join(gap_study.null_tail_lines(null_same)
                               + gap_study.null_tail_lines({k: null_all[k] for k in
                                                            ("revision 6", "revision 6, replicate 1")}))))

# %% [markdown]
# **Where the tail comes from: draws in which every candidate gains alike.** A draw's
# statistic is its best candidate's ΔBIC; in most draws one candidate absorbs some noise and
# the others gain little or lose, but in some *every* candidate gains — a knee offset, a
# friction coefficient and a left-right shift alike — which no one effect can do: the
# baseline's own relative fit carries a difference every candidate is credited with
# closing. The baseline's relative gap is [F(N) − N] − [F(R) − R]: its fit of the draw and
# its fit of the reference must sit in the same optimum for the model's own misfit to
# cancel, and the self-consistency rounds only re-solve the reference from the draw's fit.
# Per validation, the draws whose median candidate reached ΔBIC ≤ −20, and whether the
# baseline's fit of the reference kept its start (the reference's multistart) through the
# rounds:

# %%
cm_vals = {"revision 4": valr4, "revision 4, replicate 1": valr4_1, "revision 5": valr5,
           "revision 6": valr6, "revision 6, replicate 1": valr6_1}
display(gap_study.common_mode_table(cm_vals).round(1))
display(Markdown("\n\n".join(gap_study.common_mode_lines(cm_vals))))

# %% [markdown]
# **Revision 7: the baseline's fit of the reference from the candidates'.** The reference's
# multistart is not the best optimum the baseline reaches on the reference: re-solved from a
# null draw's fit it went lower in most draws, by different amounts. Revision 7
# (`RELATIVE.reference_from_candidates`, `gaitlib.gap.reference`) re-solves the baseline's
# fit of the reference from every nested candidate's fit of it and keeps the lowest, before
# the data are continued from it — the reference-side twin of revision 4's baseline from the
# candidates' fits of the data. Paired first: revision 6's own draws with only that changed
# (`benchmarks/gap_paired.py reference_fit_rev6`):

# %%
valp7 = gap_study.stored_paired("reference_fit_rev6")
if valp7 is not None:
    pair = {"revision 6": valr6, "revision 6's draws, reference fit from the candidates'": valp7}
    display(gap_study.replicate_table(pair).drop(columns=["pooled", "pooled %", "95 % interval"]))
    display(gap_study.common_mode_table(pair).round(1))
    display(gap_study.ranking_misses({"reference fit from the candidates'": valp7}))
    display(Markdown("\n\n".join(gap_study.paired_lines(valr6, valp7, gap_study.PAIRED["reference_fit_rev6"])
                                   + gap_study.threshold_draw_lines(valp7, "the paired run"))))
else:
    print("(benchmarks/gap_paired.py reference_fit_rev6: not run)")

# %% [markdown]
# Common-mode draws remain. Is the rest the same mismatch — the baseline's lowest optimum
# on the draw not the one it takes on the reference? Its four common-mode draws and four
# others, diagnosed again with the baseline's two fits chosen as a *pair* (of the draw's
# fit with the reference re-solved from it, and the reference's fit with the draw re-solved
# from it, the lower sum of objectives):

# %%
bpair = gap_study.stored_baseline_pair()
if bpair is not None:
    display(gap_study.experiment_draws_table(bpair, ("as_run", "pair")).round(4))
    display(Markdown("\n\n".join(gap_study.baseline_pair_lines(bpair))))
else:
    print("(benchmarks/gap_baseline_pair.py: not run)")

# %% [markdown]
# And each candidate against a baseline of its own — the baseline re-solved from that
# candidate's fits of the draw and of the reference — instead of the one baseline; the same
# draws and two more (one where no candidate was ranked: every candidate's relative gap above
# the baseline's, the opposite shift):

# %%
cbase = gap_study.stored_candidate_baseline()
if cbase is not None:
    display(gap_study.experiment_draws_table(cbase, ("as_run", "one_baseline", "own_baseline")).round(1))
    display(Markdown("\n\n".join(gap_study.candidate_baseline_lines(cbase))))
else:
    print("(benchmarks/gap_candidate_baseline.py: not run)")

# %% [markdown]
# Then revision 7 on fresh draws (its hash changed):

# %%
valr7 = gap_study.superseded_validation("relative_rev7")
show_fresh(valr7, "revision 7")

# %% [markdown]
# **Revision 8: a fallback for a failed continuation, and the lower of two located pairs.**
# Two of revision 7's four misses among the middle and large injections had a cause in the
# fits, not in the criterion. In `knee_offset_large_1` the baseline's continuation from the
# reference's fit did not converge and nothing was ranked; revision 8 then solves the
# baseline from each nested candidate's fit of the reference, and failing those from the
# absolute multistart's starts (`RELATIVE.baseline_fallback`). In `ankle_offset_middle_1`
# the ankle-offset candidate identified about the injected change yet closed little of the
# gap (sentences below): its continuation from its own fit of the reference had ended above
# the baseline's fit of the data, so the null start (from the baseline's fit) was kept — a
# fit of the data in another optimum than its fit of the reference. A relative gap compares
# two fits; when they sit in different optima, the difference of the optima is read as a
# change of the data. Revision 8 locates
# each model's gap for two pairs of its fits — the final pair (after the other starts and
# the self-consistency rounds) and the continuation pair (its first fit of the reference and
# the data's fit continued from it) — and keeps the lower RSS, for the baseline and every
# candidate alike, and on the null draws the same way (`RELATIVE.lowest_pair`); no new solve.
# Paired first, on revision 7's own draws (`benchmarks/gap_paired.py lowest_pair_rev7`):

# %%
valp8 = gap_study.stored_paired("lowest_pair_rev7")
if valp8 is not None:
    pair = {"revision 7": valr7, "revision 7's draws, fallback and lower pair": valp8}
    display(gap_study.replicate_table(pair).drop(columns=["pooled", "pooled %", "95 % interval"]))
    display(gap_study.common_mode_table(pair).round(1))
    display(gap_study.ranking_misses({"fallback and lower pair": valp8}))
    display(gap_study.pair_counts(valp8))
    display(Markdown("\n\n".join(gap_study.case_change_lines(valr7, valp8, ["knee_offset_large_1",
                                                                             "ankle_offset_middle_1"])
                                   + gap_study.paired_lines(valr7, valp8, gap_study.PAIRED["lowest_pair_rev7"])
                                   + gap_study.threshold_draw_lines(valp8, "the paired run"))))
else:
    print("(benchmarks/gap_paired.py lowest_pair_rev7: not run)")

# %% [markdown]
# Then revision 8 on fresh draws (its hash changed; superseded below):

# %%
valr8 = gap_study.superseded_validation("relative_rev8")
show_fresh(valr8, "revision 8")
display(gap_study.pair_counts(valr8))

# %% [markdown]
# **Revision 8 on a second set of draws** (`--replicate 1`: the reference, its 19 null draws,
# the magnitudes, signs and resampling seeds drawn afresh, the method unchanged), and both
# replicates pooled, with a 95 % interval on each pooled rate:

# %%
valr8_1 = gap_study.superseded_validation("relative_rev8_r1")
show_fresh(valr8_1, "revision 8, replicate 1")
display(gap_study.pair_counts(valr8_1))
reps8 = {"replicate 0": valr8, "replicate 1": valr8_1}
display(gap_study.replicate_table(reps8))
display(Markdown("\n\n".join(gap_study.replicate_lines(reps8))))
display(gap_study.threshold_sweep(reps8))
display(gap_study.ranking_misses(reps8))
display(Markdown("\n\n".join(gap_study.threshold_lines(reps8))))

# %% [markdown]
# **Revision 9: the share of the gap a named effect closes.** Revision 8's wrong names among
# the out-of-library cases came with little of the relative gap closed. Revision 9 names the
# first-ranked effect only if it also closes at least `RELATIVE.min_share_closed` % of the
# relative gap (`gaitlib.gap.diagnose.assemble(min_share=)`); nothing else changes — no fit,
# no null draw — so revision 8's two sets of draws decided again with that test
# (`gap_study.with_share_floor`, each floor of the table; 0: revision 8 as it is) are exactly
# its paired run. The floor was chosen on these draws, so they cannot be its test: its own
# fresh draws follow.

# %%
display(gap_study.share_floor_sweep(reps8))
display(Markdown("\n\n".join(gap_study.share_floor_lines(reps8, floor=gap_method.RELATIVE.min_share_closed))))

# %% [markdown]
# Then revision 9 on fresh draws (its hash changed):

# %%
valr9 = gap_study.superseded_validation("relative_rev9")
show_fresh(valr9, "revision 9")
display(gap_study.pair_counts(valr9))

# %% [markdown]
# What the share floor did on these draws — the same rankings decided without it (0) and
# with it (the cases it held are read back from the stored ranking):

# %%
display(gap_study.share_floor_sweep({"revision 9": valr9}, (0.0, gap_method.RELATIVE.min_share_closed)))
display(Markdown("\n\n".join(gap_study.floor_held_lines(valr9, "revision 9"))))

# %% [markdown]
# **Revision 9 on a second set of draws** (`--replicate 1`: the reference, its 19 null
# draws, the magnitudes, signs and resampling seeds drawn afresh, the method unchanged), and
# both replicates pooled, with a 95 % interval on each pooled rate:

# %%
valr9_1 = gap_study.superseded_validation("relative_rev9_r1")
reps9 = show_second_set(valr9, valr9_1, "revision 9")
display(gap_study.share_floor_sweep(reps9, (0.0, gap_method.RELATIVE.min_share_closed)))
display(gap_study.threshold_sweep(reps9))
display(gap_study.ranking_misses(reps9))
display(Markdown("\n\n".join(gap_study.threshold_lines(reps9))))

# %% [markdown]
# **Revision 10: the statistic relative to the median candidate.** On revision 9's second
# set the rankings were right — the injected effect first in 22 of 24 middle and large
# cases — but 7 of its 19 null draws were common-mode: every candidate gained alike, by
# hundreds, because the baseline's fit of the reference sat in a worse optimum than the
# candidates' fits of it. A shift every candidate is credited with moves the median
# candidate's ΔBIC with the lowest; one effect that absorbs a change stands out from it.
# Revision 10 (`RELATIVE.centred`) decides relative to the median ranked candidate: each
# first-ranked effect's ΔBIC minus the median candidate's is held to the threshold the null
# draws set on the same statistic (their lowest minus their median), besides the fixed
# ΔBIC ≤ −10 on the raw value; and the 20 % share floor applies to the part of the gap the
# median candidate leaves open (on a common-mode draw every candidate "closes" 70–80 % of
# the gap, so a share of the whole gap says nothing there). Nothing is refitted, so
# revisions 8 and 9's four sets of draws decided that way (`gap_study.centred_replay`, the
# 20 % floor throughout) are its paired run — and the rule was chosen on them, so its own
# fresh draws follow.

# %%
reps89 = {"revision 8": valr8, "revision 8, replicate 1": valr8_1, "revision 9": valr9,
          "revision 9, replicate 1": valr9_1}
display(gap_study.centred_replay(reps89, floor=gap_method.RELATIVE.min_share_closed))
display(Markdown("\n\n".join(gap_study.centred_lines(reps89, floor=gap_method.RELATIVE.min_share_closed))))

# %% [markdown]
# Then revision 10 on fresh draws (its hash changed) — the relative method in use:

# %%
valr = gap_study.stored_validation("relative")
print("written by:", gap_study.VALIDATION_RUNS["relative"])
show_fresh(valr, "revision 10")
display(gap_study.pair_counts(valr))
display(Markdown("\n\n".join(gap_study.floor_held_lines(valr, "revision 10"))))
display(gap_study.centred_replay({"revision 10": valr}))

# %% [markdown]
# **Revision 10 on a second set of draws** (`--replicate 1`: the reference, its 19 null
# draws, the magnitudes, signs and resampling seeds drawn afresh, the method unchanged), and
# both sets pooled, with a 95 % interval on each pooled rate — revision 9's second set is the
# reason to look: one set of draws hid its common mode.

# %%
valr_1 = gap_study.stored_validation("relative_r1")
print("written by:", gap_study.VALIDATION_RUNS["relative_r1"])
reps10 = show_second_set(valr, valr_1, "revision 10")
display(gap_study.centred_replay(reps10))
display(gap_study.threshold_sweep(reps10))
display(gap_study.ranking_misses(reps10))
display(Markdown("\n\n".join(gap_study.threshold_lines(reps10))))

# %% [markdown]
# **Every revision at a glance**: each stored relative validation as it decided, with the
# threshold its null draws set and how many of those draws were common-mode (every candidate
# gaining alike, the median candidate's ΔBIC ≤ −20). Each row is its own draws; the changes'
# paired runs are in the sections above.

# %%
rev_vals = {name: (rev, gap_study.superseded_validation(name)) for name, rev in gap_study.SUPERSEDED_VALIDATIONS.items()
            if name.startswith("relative")}
rev_vals.update({name: (gap_method.RELATIVE.revision, gap_study.stored_validation(name))
                 for name in gap_study.VALIDATION_RUNS if name.startswith("relative")})
display(gap_study.revision_table(rev_vals))

# %% [markdown]
# ## 3c. Muscle-level twins: co-contraction, joint stiffness and activation timing against EMG
#
# The effects of Section 5 show only in the muscles: co-contraction and joint stiffness
# change the generators' activations, not the net joint moments; activation timing changes
# only how the activations line up with the EMG. Their twins are made by the **MSK** model
# (10 × 3 LGR, per-node derivatives) with one such effect switched on, at a magnitude
# between the points of the profile grids (so that no grid point hits it exactly); the twin's
# EMG channels are the generating solution's generator activations (for activation timing,
# shifted by the delay), noised as in Section 3. Each is diagnosed with the MSK baseline and
# the three muscle-level effects as candidates; the effect-free twin's right answer is
# "unexplained". Two noise seeds.

# %%
tvm = gap_study.muscle_twin_validation()
display(tvm.rows[["twin", "injected", "magnitude", "top", "verdict", "correct", "identified_magnitude", "rss_base",
                  "rss_top", "rss_gen", "dBIC_top", "dBIC_true", "dBIC_best_other"]])
display(Markdown("\n\n".join(gap_study.muscle_twin_lines(tvm))))

# %% [markdown]
# ## 4. Findings on the real data
#
# ### Schwartz 2008, *Free* speed (82 children)
#
# The ranking of the SK candidates on the real data — raw (% of the RSS closed, with the
# resampling interval for the top three) and penalised (ΔBIC; dashed line the threshold):

# %%
gap_figures.ranking_bars(dS.ranking, top=dS.top_effect, mark=marks.failure_label(dS.baseline));
plt.show()
gap_study.ranking_table(dS)

# %% [markdown]
# The HAT residual loads of this baseline fit against OpenSim's guidelines (located, not part
# of the RSS; `peak_ratio` = peak / guideline), and the largest ratio over all candidates' fits:

# %%
display(dS.located.residuals)
print(f"largest peak/guideline ratio over the candidates' fits: {dS.ranking['residual_ratio'].max():.3f}")

# %%
best = sS["best"]
if best is not None:
    gap_figures.shrink_heatmaps(dS.located, dS.fits[best].located, best,
                      marks=(marks.failure_label(dS.baseline), marks.failure_label(dS.fits[best].status)),
                      title=f"Schwartz 2008 Free: gap of the SK baseline fit and with {best}");
    plt.show()
    sh = dS.shrink[best]
    display(sh.sort_values("rms_before", ascending=False).head(8)[
        ["channel", "phase", "rms_before", "rms_after", "pct_closed", "significant_before", "significant_after"]])

# %% [markdown]
# #### The same data on the coarse mesh
#
# `gaitlib gap` diagnoses a new data set on a 10 × 3 mesh by default (its baseline
# `DEFAULT_BASE`, for speed); this chapter's real-data diagnoses run on the thesis's 20 × 5.
# The Schwartz *Free* data diagnosed both ways, everything else equal:

# %%
dS_coarse = gap_study.sk_diagnosis(mesh=(10, 3))
mesh_tab = gap_study.mesh_table({"10 × 3 (gaitlib gap's default)": dS_coarse, "20 × 5 (the thesis's, this chapter)": dS})
display(mesh_tab)
display(Markdown(gap_study.mesh_verdict(mesh_tab, diagnose.BIC_THRESHOLD, valn)))

# %% [markdown]
# #### The same data and the same problem on the other derivative path
#
# Every solve above builds the NLP's exact derivatives by letting CasADi differentiate the
# whole NLP graph. gaitlib can also assemble them from per-node derivative functions
# (`GaitSpec(derivatives="nodes")`, `gaitlib gap --derivatives nodes`): the same functions to
# round-off (`tests/test_node_derivatives.py`) and the same problem, so nothing about the
# model or the data changes — only the round-off along IPOPT's path. The Schwartz *Free* data
# diagnosed on both paths at both meshes, and the *Slow* data (which this chapter does not
# diagnose otherwise) at `gaitlib gap`'s default 10 × 3:

# %%
dS_nodes = gap_study.sk_diagnosis(derivatives="nodes")
dS_coarse_nodes = gap_study.sk_diagnosis(mesh=(10, 3), derivatives="nodes")
dSlow = gap_study.sk_diagnosis(speed_class="Slow", mesh=(10, 3))
dSlow_nodes = gap_study.sk_diagnosis(speed_class="Slow", mesh=(10, 3), derivatives="nodes")
path_runs = {"Free, 20 × 5, whole-graph derivatives (this chapter)": dS, "Free, 20 × 5, per-node derivatives": dS_nodes,
             "Free, 10 × 3, whole-graph derivatives": dS_coarse, "Free, 10 × 3, per-node derivatives": dS_coarse_nodes,
             "Slow, 10 × 3, whole-graph derivatives": dSlow, "Slow, 10 × 3, per-node derivatives": dSlow_nodes}
path_tab = gap_study.mesh_table(path_runs, index="run")
display(path_tab)
labels = list(path_runs)
display(Markdown(gap_study.path_verdict(path_tab, list(zip(labels[::2], labels[1::2])), diagnose.BIC_THRESHOLD)))

# %% [markdown]
# ### The second lab: gaitutils normative data
#
# The gaitutils normal data (an independent lab; speed 1.28 m/s, stride 0.99 s) have
# angles and moments but no GRFs, and EMG envelopes without SD. The GRFs the gait problem
# needs are taken from Schwartz 2008 *Free* and **excluded** from the gap; EMG without SD
# cannot be standardised and is excluded too (listed below). The left leg is generated from
# the right one (as for Schwartz), so the left-leg time shift is a candidate for both.

# %%
dU = gap_study.sk_diagnosis("gaitutils")
sU = gap_study.summary(dU)
print("excluded channels:", [(d["id"], d["reason"]) for d in dU.located.excluded])
print(f"baseline fit: {dU.baseline.stats['status']}; RSS = {sU['rss']:.1f}, RMS z = {sU['rms_z']:.2f}; "
      f"{sU['significant_cells']} of {sU['cells']} cells significant (n = 1: the band test is conservative)")
gap_figures.gap_heatmap(dU.located, title="SK baseline fit vs gaitutils normal data", mark=marks.failure_label(dU.baseline));
plt.show()
gap_figures.ranking_bars(dU.ranking, top=dU.top_effect, mark=marks.failure_label(dU.baseline));
plt.show()
gap_study.ranking_table(dU)

# %% [markdown]
# ### How much of the gap is the data's own left leg?
#
# Both data sets give one leg; the left leg is generated from it as the thesis does
# (Eqs 4.1–4.3: a 5th-order Fourier series of the right leg, phase-shifted by the
# opposite-foot-contact event) and tracked as if it were data. A 5th-order series cannot
# follow a GRF that is zero for 40 % of the cycle: it rings by a few newtons while the foot
# is in the air, where the band (SD floored at 10 % of the cycle RMS) is only a few newtons
# wide. The largest cells of the Schwartz map above — left GRFs and ankle torque in swing —
# are of this kind: the simulated foot is off the ground and its GRF is zero.
#
# Nothing is re-solved here. The same solutions (baseline and every candidate, fitted to the
# data as tracked) are located against the data with the left leg shifted **exactly** —
# the right leg's own samples at τ + shift, periodic linear interpolation
# (`gaitlib.studies.gap.left_leg_check`). The right leg's mean does not end exactly where it
# starts (e.g. the hip moment), so the exact shift carries a small jump at the seam; the
# Fourier series trades that jump for its ringing. First, the generated left leg itself
# against the exact shift — the data pipeline's own gap, in the same SD units:

# %%
chkS = gap_study.left_leg_check(dS)
chkU = gap_study.left_leg_check(dU)
gen = pd.concat({"Schwartz 2008 Free": chkS["generation"].set_index("channel"),
                 "gaitutils": chkU["generation"].set_index("channel")}, axis=1)
display(gen)
print(f"vertical GRF of the generated left leg: minimum {dS.data.gait.mean['grf_y_l'].min():.1f} N "
      f"(the right leg's: {dS.data.gait.mean['grf_y_r'].min():.1f} N) — a ground that pulls the swinging foot down")
llc = pd.DataFrame({lab: {"baseline RSS, data as tracked": c["rss"]["data as tracked"],
                          "baseline RSS, left leg shifted exactly": c["rss"]["left leg shifted exactly"],
                          "RSS of the generated left leg vs the exact shift": float(c["generation"]["rss"].sum())}
                    for lab, c in (("Schwartz 2008 Free", chkS), ("gaitutils", chkU))}).T
llc

# %%
gap_figures.data_views(dS.located, chkS["located_exact"], ["grf:grf_x_l", "grf:grf_y_l", "torque:ankle_l", "torque:hip_l"],
             sim_label="SK baseline fit", mark=marks.failure_label(dS.baseline));
plt.show()
gap_figures.gap_heatmap(chkS["located_exact"], title="SK baseline fit vs Schwartz 2008 Free, left leg shifted exactly",
              mark=marks.failure_label(dS.baseline));
plt.show()

# %% [markdown]
# The candidates' fits, re-located (not re-fitted) against the exactly shifted data, beside
# their figures against the data as tracked — does the ranking survive the change of data
# view?

# %%
for lab, c in (("Schwartz 2008 Free", chkS), ("gaitutils", chkU)):
    print(lab)
    display(c["ranking"])

# %% [markdown]
# ## 5. Does co-contraction close the TA/GAM gap? (thesis Sec 5.3.5)
#
# The thesis's NMSK solution predicts a TA excitation below its EMG and a GAM excitation
# above it, and blames the MTGs' lack of co-contraction. Co-contraction, joint stiffness and
# activation timing are muscle-level effects: they leave angles, torques and GRFs
# unchanged and show only in the excitations, so the test needs the NMSK model. The
# baseline is the **Ch 5 NMSK solution** itself in the book's reading (Eq 5.55, the
# thesis's 20 × 5 mesh, `gaitlib.studies.msk.solve("NMSK", reading="book")`: the data's Jrk
# denominators, the swinging foot unloaded — a valid gait; in the thesis's reading the
# baseline fails the swing gate, so it carries no conclusion here: its ranking is shown
# apart below), whose gap is located with the EMG channels; each
# candidate is re-solved on the same mesh with the thesis's own cost function plus the
# effect, warm-started from it — co-contraction and joint stiffness at the magnitudes of
# their profile grid, activation timing (a comparison-only effect: the excitation compared
# with the EMG at a shifted time) by a bounded search on the baseline's excitations.
# The co-contraction constraint is $a_{flex} \ge c\,a_{ext}$ and $a_{ext} \ge c\,a_{flex}$
# for every generator pair (hip, knee, ankle; both legs).

# %%
dN = gap_study.nmsk_attribution(reading="book")
sN = gap_study.summary(dN)
print(f"Ch 5 NMSK solution: {dN.baseline.stats['status']}, {dN.baseline.stats['iterations']} iterations; "
      f"RSS = {sN['rss']:.1f} (RMS z = {sN['rms_z']:.2f}) over {dN.located.n_points} points incl. EMG")
gap_figures.gap_heatmap(dN.located, title="Ch 5 NMSK solution vs Schwartz 2008 Free (with EMG)",
              mark=marks.failure_label(dN.baseline));
plt.show()
for n, f in dN.fits.items():
    if f.profile:
        print(n, "profile (magnitude, RSS, status):", [(m, round(r, 1), s) for m, r, s in f.profile])
gap_study.ranking_table(dN)

# %% [markdown]
# The same attribution on the thesis's reading of Ch 5 (the swinging foot free; its baseline
# fails the validity gates — marked — and is not used for any conclusion):

# %%
dN_thesis = gap_study.nmsk_attribution(reading="thesis")
display(Markdown(f"Baseline: {marks.failure_label(dN_thesis.baseline) or 'valid'}; top effect "
                 f"{dN_thesis.top_effect}, verdict {dN_thesis.verdict}."))
gap_study.ranking_table(dN_thesis)

# %% [markdown]
# The EMG part of the gap, channel by channel, for the baseline and each candidate's best
# fit (RSS summed over both legs; mean z < 0: the excitation is below the EMG), and every
# profile point of co-contraction and joint stiffness — the whole gap and the EMG alone:

# %%
emg = gap_study.emg_gap_table(dN)
display(emg)
prof = {n: gap_study.profile_table(dN, n) for n, f in dN.fits.items() if f.profile}
for n, t in prof.items():
    print(n)
    display(t)

# %%
cc = dN.fits.get("co_contraction")
if cc is not None and cc.located is not None:
    gap_figures.channel_curves(dN.located, cc.located, ["emg:TA_r", "emg:MG_r", "emg:TA_l", "emg:MG_l"],
                     labels=("Ch 5 NMSK", f"co-contraction c = {cc.thetas['co_contraction']['c']:.2f}"),
                     marks=(marks.failure_label(dN.baseline), marks.failure_label(cc.status)));
    plt.show()

# %% [markdown]
# ## 6. The gap of the book's Ch 5–7 solutions
#
# The same locating step applied to the solutions the chapters report, reloaded (nothing is
# re-solved): the Ch 5 MSK and NMSK solutions (in the book's reading and in the thesis's),
# the 16 cost-function runs of Ch 6 and the 8 speed runs of Ch 7 (both in the book's
# reading). A Ch 7 run is located against **its own speed class's data** — the
# data it never tracked (it tracks the Free data scaled in time): that gap is the
# prediction error. RMS z over the angles, torques and GRFs of both legs (against the data
# as tracked, and with the left leg shifted exactly), and over the EMG channels for the
# excitations (NMSK) or generator activations (MSK) — the latter are not tracked by every
# cost function; a run IPOPT did not finish keeps its status.

# %%
bg = gap_study.book_gaps()
with pd.option_context("display.max_rows", 40):
    display(bg)

# %%
conv = bg[bg["mark"] == ""]  # converged and valid: only these carry a sentence
left_top = conv["largest cell"].str.contains("_l ").mean() * 100
best6 = conv[conv["chapter"] == "Ch 6"].sort_values("RMS z, angles/torques/GRFs").head(1)
ch7 = conv[conv["chapter"] == "Ch 7"]
print(f"{len(conv)} of {len(bg)} solutions converged and pass the validity gates; among them the largest cell is a left-leg channel in "
      f"{left_top:.0f} %; shifting the left leg exactly changes the RMS z by "
      f"{(conv['RMS z, same, left leg shifted exactly'] - conv['RMS z, angles/torques/GRFs']).median():+.2f} (median).")
if len(best6):
    b = best6.iloc[0]
    print(f"Ch 6: the smallest gap in angles, torques and GRFs is {b['model']} {b['case']} (RMS z "
          f"{b['RMS z, angles/torques/GRFs']:.2f}).")
if len(ch7):
    print("Ch 7, against each class's own data: " + "; ".join(
        f"{r['model']} {r['case']}: RMS z {r['RMS z, angles/torques/GRFs']:.2f}" for _, r in ch7.iterrows()))

# %% [markdown]
# ## 6b. The library's candidates on the Ch 5 MSK solution
#
# The attribution of section 5, on the Ch 5 **MSK** solution in the book's reading, with every
# effect of the library that applies to the MSK model (model effects and laboratory effects;
# `gaitlib.studies.gap.ch5_attribution("MSK", reading="book")`): each candidate re-solved
# with Eq 5.33 plus the effect, warm-started from the Ch 5 solution, on its 20 × 5 mesh.
# The report card's MSK tracking rows carry this verdict.

# %%
try:
    with cache.only("the MSK diagnosis is read from the store (gap_study.ch5_attribution('MSK') solves it)"):
        dM = gap_study.ch5_attribution("MSK", reading="book")
except cache.NotCached as e:
    dM = None
    print(f"Not stored yet: {e}")
if dM is not None:
    sM = gap_study.summary(dM)
    print(f"Ch 5 MSK solution: {dM.baseline.stats['status']}, {dM.baseline.stats['iterations']} iterations; "
          f"RSS = {sM['rss']:.1f} (RMS z = {sM['rms_z']:.2f}) over {dM.located.n_points} points; "
          f"verdict {dM.verdict}, top effect {dM.top_effect}")
    display(gap_study.ranking_table(dM))

# %% [markdown]
# Joint stiffness (the hip, knee and ankle stiffness and damping multiplied by 1 + k) below
# the method's grid, whose lowest point is k = −0.5: the same re-solve at k = −0.7 and −0.9,
# the effect's bound (`gap_study.ch5_profile`). This is outside the frozen method, so no
# verdict above changes; the findings below say whether the grid's best point was its edge.

# %%
try:
    with cache.only("the profile is read from the store (gap_study.ch5_profile solves it)"):
        prof_js = gap_study.ch5_profile("MSK", "joint_stiffness", (-0.5, -0.7, -0.9))
except cache.NotCached as e:
    prof_js = None
    print(f"Not stored yet: {e}")
if prof_js is not None:
    display(prof_js)
    ok_js = prof_js[prof_js["status"].isin(list(validity.CONVERGED_STATUSES))]
    best_js = ok_js.loc[ok_js["RSS"].idxmin()]
    print(f"Lowest located gap among the converged points: k = {best_js['magnitude']:g}, RSS {best_js['RSS']:.0f} "
          f"({best_js['% closed']:.1f} % of the baseline's {prof_js['RSS'].iloc[0]:.0f} closed), "
          f"{best_js['EMG share of the closed gap (%)']:.1f} % of that in the EMG channels (the generators' "
          f"activations against the EMG).")

# %% [markdown]
# ## The diagnosis's targets at a glance
#
# What this chapter set out to show about the diagnosis itself, each target beside the number
# measured above: the in-model twins on both meshes (Sections 2–3), the relative method in use
# on its independent and out-of-library manipulations (Section 3b; both sets of draws
# pooled), and the real data's verdict on both meshes (Section 4).

# %%
display(gap_study.target_table(tv, tvf, reps10, mesh_tab))

# %% [markdown]
# ## Findings

# %%
display(Markdown("\n\n".join(gap_study.findings(tv, tvf, dS, dU, dN, chkS, chkU, bg, emg, val=val, valv=valv,
                                                    diag_m=dM, profile_m=prof_js, valn=valn, tv_muscle=tvm,
                                                    valr=valr, valr_reps=reps4, load_confusion=_lc,
                                                    quiet_pair=(valr5, valq), null_tail=null_same,
                                                    valr_now_reps=reps6, common_mode=cm_vals,
                                                    ref_pair=(valr6, valp7), baseline_pair=bpair,
                                                    candidate_baseline=cbase, pair_rev8=(valr7, valp8),
                                                    current_reps=[reps9, reps10], floor_reps=reps8, centred_reps=reps89))))
print(f"notebook time: {time.perf_counter() - T0:.0f} s")
