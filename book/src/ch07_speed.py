# %% [markdown]
# # Chapter 7 — Slow and fast gaits without their data
#
# **What the chapter asks.** Can the MSK and NMSK optimisations predict a child's slow and
# fast walking when the data of those speeds are *not* tracked? The thesis (Ch 7, Sec 7.1)
# solves the data-tracking cost function of Ch 6 (Table 7.1 = the DT weights of Table 6.2;
# Eqs 7.1–7.2) for four speed classes with three changes:
#
# 1. the final time is the class's cycle time (and the pelvis advances one class stride per
#    cycle: speed × cycle time);
# 2. the natural-speed (*Free*) data, **scaled in time only** to that cycle time, are what
#    the Trq/Ang/GRF terms track, what normalises them, and what the initial guess is made
#    of; the HAT term tracks the Ch 5 HAT motion on normalised time;
# 3. the class's own data set only the final time, the stride and the bounds on the joint
#    angles — and are used here only to **score** the prediction (NRMSE = RMSE / data
#    range, thesis Figs 7.1–7.4).
#
# The NMSK solutions give the metabolic cost of transport (COT, Eq 5.57) at each speed: the
# thesis reports a U-shaped curve with its minimum at the natural speed (Fig 7.5).
#
# **Where we depart from the thesis.** Our speed classes are Schwartz et al. 2008's *Very
# Slow, Slow, Fast, Very Fast* (speeds from their dimensionless values and our model's leg
# length), not the thesis's XS/S/M/L at 0.90/1.09/1.29/1.58 m/s: ours span a wider range
# (table below). Thesis values appear only in columns labelled with their table or figure.
# Full model, full mesh (20 × 5 LGR), tolerance 10⁻⁵, one dask sweep of 8 runs.
#
# **The problem's reading** (Ch 2): every run here is solved in the *book's reading* — the
# Jrk term's denominators of the HAT's horizontal position and tilt from the data, and each
# foot's vertical force at most 1 % of body weight while the (time-scaled) data say it
# swings — from the Ch 5 solutions of the same reading. In the *thesis's reading* (the
# problem as printed: Jrk denominators of 1, the swinging foot free) the same 8 runs are
# shown beside them in the next table, each with its validity mark.

# %%
import pandas as pd

from gaitlib import cache, data, marks, plots
from gaitlib.studies import fidelity, gait, predictive as pr
from IPython.display import Markdown, display

pd.set_option("display.precision", 3)
classes = pr.CH7_CLASSES
gaits = {c: data.load_gait_data(c) for c in ("VerySlow", "Slow", "Free", "Fast", "VeryFast")}
pd.DataFrame({c: {"speed (m/s)": g.speed, "cycle time (s)": g.cycle_time, "stride (m)": g.speed * g.cycle_time,
                  "thesis class": pr.THESIS_CLASS[c]} for c, g in gaits.items()}).T

# %%
res = pr.speed_study(("MSK", "NMSK"), classes, progress=False, reading="book")
stats = res.stats()
run_marks = res.marks()
stats[["mark", "status", "converged", "iterations", "solve (s)", "ms/iteration", "objective", "max violation",
       "COT (J/kg/m)"]]

# %%
res_thesis = pr.speed_study(("MSK", "NMSK"), classes, progress=False, reading="thesis")
pr.readings_table({"book's reading": res, "thesis's reading": res_thesis},
                  columns=("mark", "status", "iterations", "COT (J/kg/m)"))

# %% [markdown]
# **Initial guesses.** MSK: the thesis's (Sec 7.1) — the time-scaled *Free* data with the
# Ch 5 HAT and metatarsal motion and MTG activations. NMSK: the *whole* Ch 5 NMSK solution
# scaled in time (a departure, as in Ch 6); from the thesis's partial guess the NMSK runs
# gave these statuses (not used anywhere else on this page):

# %%
res_thesis_guess = pr.speed_study(("NMSK",), classes, progress=False, guess={"NMSK": "thesis"}, reading="book")
tg = res_thesis_guess.stats()[["mark", "status", "iterations", "solve (s)", "objective", "max violation"]]
tg

# %% [markdown]
# **Runs that stopped at the iteration limit.** Each is run again from the same initial
# guess with IPOPT allowed 3000 iterations (Ch 5's limit; the thesis's GPOPS-II ran each to
# convergence, Table 7.2's hours). Where the rerun converged and passes the validity gates
# it **stands in for the 1000-iteration run in every result below** (accuracy, COT,
# findings — Ch 6's rule for its conclusions), named there; the compute-times table keeps
# the study's own runs and statuses. A rerun that did not converge, or is invalid, changes
# nothing: the run stays marked.

# %%
inv = res.rerun_failed(max_iter=3000)
res_used = res.with_reruns(inv)
print("reruns standing in:", ", ".join(res_used.rerun_used) or "none")
res.rerun_table(inv) if inv else "every run converged"

# %% [markdown]
# The same runs once more at the 1000-iteration limit with their collocation defects in
# integral form (`GaitSpec(defects="integral")`: the same NLP — feasible set and optima —
# along another IPOPT path), as in Ch 6. A separate, labelled result: nothing below uses it.

# %%
inv_int = res.rerun_failed(max_iter=1000, defects="integral")
res.rerun_table(inv_int) if inv_int else "every run converged"

# %% [markdown]
# The MSK runs once more from the *whole* Ch 5 MSK solution scaled in time (the NMSK runs'
# start, and the start of Ch 6's MSK runs), at the same 1000-iteration limit, and a run of
# them that stopped at the limit again with 3000 iterations. A separate, labelled result: the
# page's MSK runs keep the thesis's guess (`pr.GUESS_POLICY_CH7`) because from it the one
# run that stops at the limit converges at 3000 iterations — the lines and tables below say
# whether that holds from the whole Ch 5 solution — and nothing below uses these.

# %%
res_msk_ch5 = pr.speed_study(("MSK",), classes, progress=False, guess={"MSK": "ch5"}, reading="book")
print("\n".join(pr.guess_lines({"from the thesis's guess (the page's MSK runs)": res,
                                 "from the whole Ch 5 MSK solution": res_msk_ch5}, "MSK")))
display(res_msk_ch5.stats()[["mark", "status", "iterations", "solve (s)", "objective", "max violation"]])
inv_msk_ch5 = res_msk_ch5.rerun_failed(max_iter=3000)
res_msk_ch5.rerun_table(inv_msk_ch5) if inv_msk_ch5 else "every run converged"

# %% [markdown]
# ## Compute times (thesis Table 7.2)
#
# Ours on this 2-core machine beside the thesis's hours for the class of the same rank
# (labelled; different classes and data).

# %%
times = pr.times_table(res, pr.THESIS_HOURS_TABLE_7_2, lambda s: pr.THESIS_CLASS[s.speed_class])
times["class"] = [s.speed_class for s in res.specs.values()]
times.set_index(["model", "class"])[["mark", "status", "iterations", "build (s)", "solve (s)", "ms/iteration", "thesis (h)", "speed-up"]]

# %% [markdown]
# ## Accuracy against each class's own (untracked) data — thesis Figs 7.1–7.4
#
# A run that did not converge is drawn hatched red with a red † above its bars and named in
# red in the title; the table below gives it a `mark`, and the findings leave it out.

# %%
sc = res_used.scores.copy()
sc["case"] = sc["case"].astype(str)
fig = plots.score_bars(sc, "angle", value="nrmse", cases=classes, title="Joint angles: NRMSE (cf. thesis Fig 7.1)")

# %%
fig = plots.score_bars(sc, "grf", value="nrmse", cases=classes, title="Foot forces: NRMSE (cf. thesis Fig 7.2)")

# %%
fig = plots.score_bars(sc, "torque", value="nrmse", cases=classes, title="Net joint torques: NRMSE (cf. thesis Fig 7.3)")

# %%
fig = plots.score_bars(sc, "excitation", value="nrmse", cases=classes, models=["NMSK"],
                       title="NMSK excitations vs EMG: NRMSE (cf. thesis Fig 7.4)")

# %% [markdown]
# A control: how far is each class's data from the time-scaled *Free* data it was given?
# If the prediction's NRMSE is below this, the optimisation moved towards the untracked
# class; if it is about equal, it mostly reproduced what it tracked. Beside it, each
# prediction's NRMSE against the input it tracked (`gaitlib.studies.predictive.input_pull`):
# a prediction cannot come closer to the class data than the control while it misses its
# own input by more than the class–input distance.

# %%
pull = pr.input_pull(res_used, gaits)
ctrl = pull["control: input vs class"].unstack("kind").groupby(lambda r: r.split(" ", 1)[1]).first().loc[list(classes)]
pull

# %% [markdown]
# **What pins a prediction to its input: an experiment.** The same 8 runs with Table 7.1's
# three data-tracking weights (Trq, Ang, GRF) divided by 10 (`pr.LOOSE_TRACKING`), every
# other term, bound and guess unchanged. If the data terms held the gait to the scaled
# *Free* data, the loosened runs would move towards the class data.

# %%
res_loose = pr.speed_study(("MSK", "NMSK"), classes, progress=False, reading="book", weights=pr.LOOSE_TRACKING)
pull_loose = pr.input_pull(res_loose, gaits)
display(res_loose.stats()[["mark", "status", "iterations", "solve (s)", "COT (J/kg/m)"]])
pd.concat({"Table 7.1's weights": pull[["mark", "vs class data", "vs tracked input"]],
           "tracking weights ÷ 10": pull_loose[["mark", "vs class data", "vs tracked input"]],
           "control": pull[["control: input vs class"]]}, axis=1)

# %%
display(Markdown("\n".join(pr.pin_findings(pull, pull_loose))))

# %% [markdown]
# **Does the start pin them? A second experiment.** Loosened, the predictions did not move
# towards the class data — so is it their start (the Ch 5 solution scaled in time) that
# holds them? The same four NMSK problems (each spec unchanged; iteration limit 3000, the
# chapter's rerun limit) solved from two other starts (`pr.data_start_study`): the
# problem's own data-based guess (thesis Sec 4.3.2) on the scaled *Free* data it tracks — the
# control — and the same guess built on **the class's own data**, which the problem never
# tracks (a start only; the objective decides where a run ends). The objective is the same
# problem's at every start of a class, so the lowest is the better optimum.

# %%
try:
    with cache.only("the runs from the data-based starts are read from the store (pr.data_start_study solves them)"):
        starts = {pr.CH7_OWN_START: res_used,
                  **{st: pr.data_start_study(res_used, st, progress=False) for st in pr.DATA_STARTS}}
except cache.NotCached as e:
    starts = None
    print(f"Not stored yet: {e}")
if starts is not None:
    st_table = pr.start_table(starts, gaits)
    display(st_table)
    display(Markdown("\n\n".join(pr.start_findings(st_table, pr.CH7_OWN_START))))

# %% [markdown]
# ## Cost of transport against speed (thesis Fig 7.5)
#
# The NMSK runs here and, at the natural speed, the like-for-like point: the Ch 6 NMSK DT
# run in the same (book's) reading — the same cost function (Table 6.2's DT = Table 7.1), activation parameters (thesis
# Table 5.10), HAT reference and kind of initial guess as the runs here, on the Free data.
# The Ch 5 NMSK solution (Eq 5.55: another cost function, with its own identified
# activation parameters) is drawn apart, as a labelled reference, not part of the curve.
# The thesis's points are drawn at their own speeds, labelled.

# %%
ch6_dt = pr.cost_function_study(("NMSK",), ("DT",), progress=False, reading="book").solutions.get("NMSK DT")
CH5_ROW = "Free (Ch 5 Eq 5.55)"
cot = pr.cot_table(res_used, {"Free": ch6_dt, CH5_ROW: res.baselines.get("NMSK")})
fig = pr.cot_figure(cot, CH5_ROW)
curves = {"the thesis's problem (Free: Ch 6 DT)": cot}  # every curve of this page, for "What we found"
cot

# %% [markdown]
# ### One consistent problem on valid gaits
#
# In the thesis's reading a swinging foot carries load (the marks of the readings' table
# above say where). Chapter 2 measured why, and that bounding that load gives valid tracking
# solutions. Here the curve is redrawn from **one** problem with only that change (the
# Jrk denominators of the thesis's reading): the NMSK DT runs of this
# chapter at **every** class, *Free* included (the same cost, parameter sets and
# activation parameters at each speed), each foot's vertical force at most 1 % of body
# weight while the (time-scaled) data say it swings, all warm-started from the
# swing-unloaded Ch 5 NMSK solution. If the minimum is not at *Free*, the terms of
# Eq 5.38 say which one moves it: the class where the COT without that term is lowest
# (on these motions, not re-optimised).

# %%
res_u = fidelity.consistent_speed_study(progress=False)
cot_u = pr.cot_table(res_u)
fig = pr.cot_figure(cot_u, label="ours: one problem, swing foot unloaded (converged, valid)")
terms_u = fidelity.cot_terms(cot_u, res_u.solutions)
curves["one consistent problem, swing foot unloaded"] = cot_u
display(cot_u, terms_u)
display(Markdown("\n\n".join(fidelity.cot_curve_findings(cot_u, terms_u))))

# %% [markdown]
# ### The feet skate: the same problem with friction
#
# How fast do the loaded feet of these runs slide? The contact law's friction acts on the
# tangential velocity of each ellipsoid's body point at its penetration centroid
# (`ChildModel.slip`); below the transition velocity v_tr = 0.1 m/s it models sticking.
# `fidelity.foot_slip` averages that speed over the cycle and the six ellipsoids, weighted
# by the normal force. The thesis's Table 4.18 gives the ball ellipsoid μ_s 0.0101 and
# μ_d 0.0100 — Table 4.7's lower bound — so sliding on it costs almost no friction (the
# sentences below give our Ch 4 set's values and the ball's share of the load). The same
# consistent problem is solved again with one change: every ellipsoid's friction
# coefficients at least `fidelity.FRICTION_FLOOR` (the largest coefficient Table 4.18 gives
# any ellipsoid: the toe's μ_d, 0.2819; `GaitSpec(friction_floor=…)`,
# the Ch 5 start solved with the same floor) — **our change**, labelled, everything else as
# above. A run that stops at the 1000-iteration limit counts through its converged, valid
# 3000-iteration rerun from the same start (the chapter's rule), named below; a point still
# marked then, through its best converged, valid restart from the other classes' solutions
# (`fidelity.marked_restarts`, labelled). For scale, the
# data each run tracks (Free scaled in time), placed on the model as its reference, slide
# too (`gait.reference_slip`, no solve): the sentences say which runs slide faster than that.

# %%
slip_u = fidelity.slip_table({s.spec.speed_class: s for s in res_u.solutions.values()})
ref_u = {s.spec.speed_class: gait.reference_slip(s.spec) for s in res_u.solutions.values()}
def stored_consistent(what, restart=False, also=None, **kw):
    """The consistent study with ``kw`` from the store, its reruns shown; with ``restart``, a
    point still marked then stood in for by its best restart from the other classes'
    solutions (and ``also``'s: `fidelity.marked_restarts`; shown). None if not stored."""
    try:
        res0, inv, res = fidelity.stored_consistent_study(what, **kw)
    except cache.NotCached as e:
        print(f"Not stored yet: {e}")
        return None
    if inv:
        print("stopped at the 1000-iteration limit, rerun with 3000 (from the same start):")
        display(res0.rerun_table(inv))
        print("reruns standing in:", ", ".join(res.rerun_used) or "none")
    if not restart:
        return res
    try:
        restarts, used = fidelity.stored_restarts(res, f"the restarts of the marked points ({what})", also=also)
    except cache.NotCached as e:
        print(f"Not stored yet: {e}")
        return res
    if restarts:
        display(fidelity.restart_table(restarts))
        display(Markdown("\n\n".join(fidelity.stand_in_findings(res, used, restarts))))
    return used


res_f = stored_consistent("the runs with the friction floor", restart=True, friction_floor=fidelity.FRICTION_FLOOR)
if res_f is not None:
    cot_f, terms_f, slip_f = fidelity.curve_tables(res_f)
    curves[f"friction ≥ {fidelity.FRICTION_FLOOR:g}"] = cot_f
    fig = pr.cot_figure(cot_f, label=f"ours: one problem, friction ≥ {fidelity.FRICTION_FLOOR:g} (converged, valid"
                        + "".join(f"; {x}" for x in fidelity.stand_in_labels(res_f)) + ")")
    display(marks.mark_table(pd.concat({"as identified": slip_u, f"friction ≥ {fidelity.FRICTION_FLOOR:g}": slip_f},
                                       axis=1),
                             {c: m for c, m in cot_f["mark"].items() if m},
                             column=f"mark (friction ≥ {fidelity.FRICTION_FLOOR:g})"),
            cot_f, terms_f)
    display(Markdown("\n\n".join(fidelity.skating_findings(cot_u, slip_u, cot_f, slip_f, terms_f,
                                                            reruns=tuple(k.split()[-1] for k in res_f.rerun_used),
                                                            reference=ref_u)
                                  + fidelity.cot_curve_findings(cot_f, terms_f, name="The curve with the friction floor"))))
else:
    display(slip_u)

# %% [markdown]
# ### With our Ch 5 activation parameters
#
# The NMSK runs above (and the Ch 6 DT run at *Free*) carry the thesis's Table 5.10 activation
# parameters. Chapter 6 measured what carrying ours instead does (the thesis's procedure on
# our data: Ch 5's identified values, `msk.activation_sets()`); here the same four runs and
# the Ch 6 NMSK DT run with ours (`pr.ch5_activation_speed_study`, `pr.ch5_activation_study`),
# everything else unchanged — **our reading**, labelled. A run that stopped at the
# 1000-iteration limit counts through its converged, valid 3000-iteration rerun.

# %%
try:
    with cache.only("the NMSK runs with Ch 5's activation parameters are read from the store "
                    "(pr.ch5_activation_speed_study() solves them)"):
        res7_c5 = pr.ch5_activation_speed_study(progress=False)
        inv7_c5 = res7_c5.rerun_failed(max_iter=3000)
        dt_c5 = pr.ch5_activation_study(costs=("DT",)).solutions.get("NMSK DT")
except cache.NotCached as e:
    res7_c5 = None
    print(f"Not stored yet: {e}")
if res7_c5 is not None:
    used7_c5 = res7_c5.with_reruns(inv7_c5)
    display(pr.readings_table({"Table 5.10's γ (book)": res, "Ch 5's γ (ours)": res7_c5},
                              columns=("mark", "status", "iterations")).loc[[f"NMSK {c}" for c in classes]])
    if used7_c5.rerun_used:
        print("reruns standing in (our activation parameters):", ", ".join(used7_c5.rerun_used))
        display(res7_c5.rerun_table(inv7_c5))
    cot_c5 = pr.cot_table(used7_c5, {"Free": dt_c5})
    curves["our Ch 5 activation parameters (Free: Ch 6 DT)"] = cot_c5
    fig = pr.cot_figure(cot_c5, label="ours: NMSK DT with our Ch 5 activation parameters (Free = Ch 6 DT)")
    terms_c5 = fidelity.cot_terms(cot_c5, {**used7_c5.solutions, "NMSK DT": dt_c5})
    display(cot_c5, terms_c5)
    display(Markdown("\n\n".join(fidelity.cot_curve_findings(cot_c5, terms_c5,
                                                             name="The curve with our Ch 5 activation parameters")
                                  + pr.torque_gain_lines(res_used, used7_c5)
                                  + ["**Against the class data**, with our Ch 5 activation parameters: "
                                     + x.lstrip("- ") for x in pr.pin_findings(pr.input_pull(used7_c5, gaits))])))

# %% [markdown]
# ### With Bhargava's reading of Eq 5.47's F0
#
# Chapter 5 measured that, of the metabolic model's open readings, the isometric term of the
# concentric shortening heat (Eq 5.47's $F_0$: the thesis's maximum isometric torque, heat even
# from a relaxed generator, against Bhargava's isometric torque at the current activation and
# angle) moves the COT most, and compared both, re-optimised, with children's measured cost.
# Here the consistent problem above is solved again with that one change: every run, and the
# swing-unloaded Ch 5 start, minimises the metabolic rate in Bhargava's reading
# (`fidelity.consistent_speed_study(isometric_torque="bhargava")`) — **our reading**,
# labelled; everything else as above. A run that stops at the 1000-iteration limit counts
# through its converged, valid 3000-iteration rerun from the same start. A point that is still
# marked then is solved again from every valid class's solution, scaled in time to its cycle
# and stride (`fidelity.marked_restarts`, as in the multistart below): the same problem from
# another start; the lowest-objective converged, valid one stands in for it, labelled.

# %%
res_b = stored_consistent("the runs with Bhargava's F0", restart=True, isometric_torque="bhargava")
if res_b is not None:
    cot_b, terms_b, _ = fidelity.curve_tables(res_b)
    curves["Bhargava's F0"] = cot_b
    fig = pr.cot_figure(cot_b, label="ours: one problem, Bhargava's F0 (converged, valid"
                        + "".join(f"; {x}" for x in fidelity.stand_in_labels(res_b)) + ")")
    display(cot_b, terms_b)
    display(Markdown("\n\n".join(fidelity.cot_curve_findings(cot_b, terms_b, name="The curve with Bhargava's F0"))))

# %% [markdown]
# ### Is each point a local optimum? Every run from every other run's solution
#
# The consistent curve's *Free* point sits above its neighbours. "A local optimum" is a
# hypothesis until measured: here each class's problem of the consistent study (its spec
# unchanged, thesis's F0) is solved again from the solution of **every other class's run**,
# every state and control scaled in time to the class's cycle and stride, in two rounds
# (`fidelity.multistart`, `fidelity.CH7_ROUNDS`; one dask sweep each): round 1 starts each
# class from the other four classes' runs of the study (5 × 4 restarts), round 2 from the
# other classes' best valid solutions of round 1 where that is a restart. Within a class the
# objective is the same problem's at every start, so the lowest one among the converged,
# valid starts is the better optimum; the curve of those best starts is then read as above
# (its minimum, and which term moves it). A second round that still finds lower optima says
# the best found is not shown to be the problem's best.

# %%
try:
    with cache.only("the restarts are read from the store (fidelity.multistart solves them)"):
        restarts = fidelity.multistart(res_u, rounds=fidelity.CH7_ROUNDS, progress=False)
except cache.NotCached as e:
    restarts = None
    print(f"Not stored yet: {e}")
if restarts is not None:
    rt, best_u, cot_best, terms_best = fidelity.restart_curve(restarts)
    curves["one consistent problem, best of its starts"] = cot_best
    fig = pr.cot_figure(cot_best, label="ours: one problem, best of its starts per speed (converged, valid)",
                        others={"ours: the same problem from the Ch 5 start (above)": cot_u})
    display(rt, best_u, terms_best)
    display(Markdown("\n\n".join(fidelity.restart_findings(best_u, terms_u, cot_best, terms_best,
                                                             n_runs=len(rt) - len(best_u), table=rt))))

# %% [markdown]
# Where do the restarts that fail stop? For every restart that did not converge: the
# constraint block with the largest violation, how far the cycle's end forward speed is from
# its start (the periodicity of the pelvis's velocity), and the cycle means of the two
# horizontal forces that set it — the feet's fore-aft GRF and the pelvis residual $R_x$
# (bounded ±1 N, Eq 4.8), and their sum over the body's mass beside the mean acceleration
# (Newton's second law for the whole body: a check that no other horizontal force acts) —
# then the ball ellipsoids' share of that GRF and the GRF over its friction limit on the
# ball, $\mu_d$(ball) × the feet's mean normal load (−1: both feet sliding forward on the
# balls whenever loaded) (`fidelity.stop_table`).

# %%
if restarts is not None:
    stops = fidelity.stop_table(restarts)
    display(stops)
    display(Markdown("\n\n".join(fidelity.stop_findings(stops))))

# %% [markdown]
# One change tests that reading: the restarts that stopped as locally infeasible, solved again
# in the problem with the friction floor of the section above (every ellipsoid's friction
# at least the toe's μ_d, so the ball grips), each from that problem's own run of the same
# start class where that run converged to a valid gait (`fidelity.restart_pairs`).

# %%
if restarts is not None and res_f is not None:
    try:
        with cache.only("the infeasible restarts with the friction floor are read from the store "
                        "(fidelity.restart_pairs solves them)"):
            floor_r = fidelity.restart_pairs(res_f, fidelity.infeasible_pairs(stops), progress=False)
    except cache.NotCached as e:
        floor_r = None
        print(f"Not stored yet: {e}")
    if floor_r:
        display(fidelity.restart_table(floor_r))
        display(Markdown("\n\n".join(fidelity.floor_stop_findings(stops, floor_r, fidelity.FRICTION_FLOOR))))

# %% [markdown]
# ### On longer legs with the contact identified on them (a probe)
#
# Chapters 4 and 5 traced the sliding feet to the data's stride being longer than the data's
# angles carry the model's legs: with the thigh and shank × 1.1 and the contact and body
# parameters identified again on them (Ch 4 (c), `data/identified/ch4_legs.json`), the Ch 5
# tracking solutions stand on their feet. The consistent problem above, solved again with
# those two changes at every speed (`fidelity.consistent_speed_study(legs=True)`: the speed
# and cycle time of each class follow the longer leg through the data's dimensionless values;
# the Ch 5 start solved on them too) — a probe, not a body the book adopts. A run that
# stopped at the 1000-iteration limit counts through its converged, valid 3000-iteration
# rerun; a point still marked then, through its best converged, valid restart from the other
# classes' solutions — and from the valid solutions of the same probe with the friction floor
# below, the same class's included (same legs and contact: another problem's optimum as a
# start, the problem solved still this one; `fidelity.marked_restarts(also=…)`, labelled
# "(legs + floor)"). The cells against the class data leave *Free* out (it tracks its own
# data).

# %%
res_l = stored_consistent("the runs on longer legs", restart=True, also=fidelity.legs_partner("legs"),
                          **fidelity.LEGS_PROBES["legs"])
if res_l is not None:
    cot_l, terms_l, slip_l = fidelity.curve_tables(res_l)
    curves[f"legs ×{fidelity.LEG_SCALE:g} + Ch 4 (c) on them"] = cot_l
    fig = pr.cot_figure(cot_l, label=f"ours: one problem, legs ×{fidelity.LEG_SCALE:g} + Ch 4 (c) on them (converged, valid"
                        + "".join(f"; {x}" for x in fidelity.stand_in_labels(res_l)) + ")")
    display(marks.mark_table(pd.concat({"book's legs": slip_u, f"legs ×{fidelity.LEG_SCALE:g} + set": slip_l}, axis=1),
                             {c: m for c, m in cot_l["mark"].items() if m}, column=f"mark (legs ×{fidelity.LEG_SCALE:g})"),
            cot_l, terms_l)
    pull_l = pr.input_pull(res_l, gaits).drop(index="NMSK Free", level="run", errors="ignore")
    display(pull_l)
    display(Markdown("\n\n".join(fidelity.hat_drift_caveat(fidelity.hat_reference_drift(res_l),
                                                           fidelity.hat_reference_drift(res_u))
                                  + fidelity.legs_curve_findings(slip_u, cot_u, slip_l, cot_l) + fidelity.cot_curve_findings(
        cot_l, terms_l, name=f"The curve on legs ×{fidelity.LEG_SCALE:g} with the contact identified on them")
        + [f"**Against the class data**, on legs ×{fidelity.LEG_SCALE:g} with the contact identified on them: "
           + x.lstrip("- ") for x in pr.pin_findings(pull_l)])))

# %% [markdown]
# The same probe with every ellipsoid's friction at least `fidelity.FRICTION_FLOOR` too (the
# change of "The feet skate" above; **our change**, labelled): longer legs, the contact
# identified on them, and no skating ball; marked points restarted as above, from this
# probe's valid solutions and from those of the probe above (labelled "(legs)").

# %%
res_lf = stored_consistent("the runs on longer legs with the friction floor", restart=True,
                           also=fidelity.legs_partner("legs + floor"), **fidelity.LEGS_PROBES["legs + floor"])
if res_lf is not None:
    cot_lf, terms_lf, slip_lf = fidelity.curve_tables(res_lf)
    curves[f"legs ×{fidelity.LEG_SCALE:g} + Ch 4 (c) + friction ≥ {fidelity.FRICTION_FLOOR:g}"] = cot_lf
    fig = pr.cot_figure(cot_lf, label=f"ours: legs ×{fidelity.LEG_SCALE:g} + set + friction ≥ {fidelity.FRICTION_FLOOR:g}"
                        + "".join(f"; {x}" for x in fidelity.stand_in_labels(res_lf)))
    display(marks.mark_table(slip_lf, {c: m for c, m in cot_lf["mark"].items() if m}), cot_lf, terms_lf)
    pull_lf = pr.input_pull(res_lf, gaits).drop(index="NMSK Free", level="run", errors="ignore")
    name_lf = f"legs ×{fidelity.LEG_SCALE:g}, the contact identified on them and friction ≥ {fidelity.FRICTION_FLOOR:g}"
    display(Markdown("\n\n".join(fidelity.hat_drift_caveat(fidelity.hat_reference_drift(res_lf),
                                                           fidelity.hat_reference_drift(res_u))
                                  + fidelity.cot_curve_findings(cot_lf, terms_lf, name=f"The curve on {name_lf}")
                                  + [f"**Against the class data**, on {name_lf}: " + x.lstrip("- ")
                                     for x in pr.pin_findings(pull_lf)])))

# %% [markdown]
# ### Each class's own data tracked (a probe of the input)
#
# Every curve above tracks Free's data scaled in time at each speed (thesis Sec 7.1): the
# same joint angles, torques and forces over each class's cycle time and stride. Is it that
# input that keeps the minimum away from *Free*? The consistent problem is solved again with
# that one change: each class tracks its **own** data (`fidelity.consistent_speed_study(
# own_data=True)`; *Free* included, the same start, cost, weights and parameter sets) — the
# children's gait at each speed as the input instead of one gait stretched in time (our
# probe, not a prediction; how close the runs come to that gait is in the table), with the
# thesis's contact (`fidelity.OWN_DATA_VARIANTS`), beside the same problem on Free's data
# scaled in time (the consistent curve above). A run that stops at the 1000-iteration limit
# counts through its converged, valid 3000-iteration rerun (named). The table sets both
# inputs side by side per class, with each run's worst joint-angle RMSE against the class's
# own data, then the own-data runs' COT by term and how fast their loaded feet slide.
#
# Both probes run at Table 7.1's weights first (how far their runs stay from the children's
# angles is in the table's last columns). The pair is solved again with the three data-tracking weights (Trq, Ang,
# GRF) × 10 (`predictive.TIGHT_TRACKING`, both inputs, everything else unchanged): held that
# much closer to each class's gait, where does the model's cost per metre put its minimum?

# %%
own_tables = {}
for variant in fidelity.OWN_DATA_VARIANTS:
    try:
        base_v, own_v = fidelity.stored_own_data(variant)
    except cache.NotCached as e:
        print(f"Not stored yet: {e}")
        continue
    cot_o, terms_o, slip_o = fidelity.curve_tables(own_v)
    curves[f"each class's own data tracked{variant}"] = cot_o
    if variant:  # the consistent problem with the same change (the "" variant's is the curve above)
        curves[f"Free's data scaled in time{variant}"] = pr.cot_table(base_v)
    fig = pr.cot_figure(cot_o, label=f"ours: each class's own data tracked{variant} (converged, valid)",
                        others={f"ours: Free's data scaled in time{variant}": pr.cot_table(base_v)})
    stand = [f"{k} (own data): its 3000-iteration rerun" for k in own_v.rerun_used]
    stand += [f"{k} (Free scaled in time): its 3000-iteration rerun" for k in base_v.rerun_used]
    stand += [f"{x} (Free scaled in time)" for x in fidelity.stand_in_labels(base_v)]
    print(f"own data{variant} — standing in: " + ("; ".join(stand) or "none"))
    own_t = own_tables[variant] = fidelity.own_data_table(base_v, own_v)
    display(own_t, terms_o, slip_o)
    display(Markdown("\n\n".join(fidelity.own_data_findings(own_t, variant=variant) + fidelity.cot_curve_findings(
        cot_o, terms_o, name=f"The curve tracking each class's own data{variant}"))))
if "" in own_tables:
    display(Markdown("\n\n".join(fidelity.tracking_weight_findings(own_tables))))

# %% [markdown]
# ## The predicted NMSK gaits against each class's data (thesis Figs 7.6–7.9)

# %%
for c in classes:
    s = res_used.solutions.get(f"NMSK {c}")
    if s is None:
        continue
    sims, sim_marks = gait.sims_and_marks({f"NMSK {c}": s})
    fig = plots.tracking_figure(gait.tracking_data(gaits[c]), sims,
                                channels=[f"{j}_r" for j in ("hip", "knee", "ankle")]
                                + [f"tau_{j}_r" for j in ("hip", "knee", "ankle")] + ["grf_x_r", "grf_y_r"],
                                ncols=4, title=f"{c}: prediction vs the class's data (right leg)", marks=sim_marks)

# %% [markdown]
# ## What we found
#
# Computed from the runs above; a run that did not converge, or that fails a physical
# validity gate (`gaitlib.validity`), supplies no number here; a converged, valid
# 3000-iteration rerun stands in for a run that stopped at the limit (named below). The
# table gathers where each COT curve of this page has its minimum (`fidelity.minimum_table`:
# its valid points, and "lowest at …" where the curve still falls into marked speeds).

# %%
print("\n".join(pr.ch7_findings(res_used, classes, ctrl, cot, inv, CH5_ROW)))
minima = fidelity.minimum_table(curves)
display(minima, Markdown("\n\n".join(fidelity.minimum_findings(minima))))
if res7_c5 is not None:
    _k, _n = pr.closer_cells(pr.input_pull(used7_c5, gaits))
    _ok = cot_c5[cot_c5["mark"] == ""]["COT (J/kg/m)"]
    print(f"- With our Ch 5 activation parameters in the NMSK runs (our reading; section above): COT minimum at "
          f"{_ok.idxmin()} ({_ok.min():.2f} J/(kg·m), {len(_ok)} of {len(cot_c5)} points unmarked); closer to the "
          f"class data than the scaled input in {_k} of {_n} cells.")
