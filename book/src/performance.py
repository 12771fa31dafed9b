# %% [markdown]
# # Performance
#
# The thesis reports 11 minutes for its SK gait problem (Sec 4.3.3) and about 2 hours for
# the MSK problem (Sec 5.2.2), with GPOPS-II in MATLAB. This page asks how fast gaitlib
# solves the same kind of problem, and how its cost grows:
#
# 1. **with mesh size** — solve time and time per IPOPT iteration from 10 to 80 mesh
#    intervals (× 5 Legendre–Gauss–Radau points), fitted as a power law
#    $t \propto N^b$ in the number of collocation nodes $N$; the target is growth **no worse
#    than linear** in time per iteration ($b \le 1$);
# 2. **with the model** — SK (joint torques), MSK (12 muscle torque generators), NMSK
#    (16 muscles with activation dynamics);
# 3. **with the solver settings** — exact Hessian (CasADi's algorithmic differentiation) vs
#    IPOPT's limited-memory BFGS, MUMPS vs the other linear solvers this IPOPT build can load;
# 4. **against an established tool** — OpenSim Moco on the same torque-driven tracking
#    problem;
# 5. **against the thesis, optimisation by optimisation** — every optimisation the book's
#    chapters run, beside the compute time the thesis prints for it.
#
# Nothing is solved on this page: it reads the results that the benchmark scripts in
# `benchmarks/` wrote (`bench_scaling.py`, `bench_gait.py`, `bench_moco_t9track.py`,
# `bench_thesis_times.py`; one command each, see `benchmarks/README.md`). Each file records when and on which machine it
# was measured — printed below, with a note on whether the 2-core machine was shared with
# other engineers' jobs at the time (then absolute times are inflated by a varying factor;
# the load average at the start of every run is in the tables). Exponents and ratios
# measured within one run are less affected than absolute times.

# %%
import pandas as pd
import matplotlib.pyplot as plt
from IPython.display import display

from gaitlib.studies import performance as perf

pd.set_option("display.precision", 3)
scaling, gait_bench, moco = perf.load("scaling"), perf.load("gait"), perf.load("moco_t9track")
for name, res in (("scaling (bench_scaling.py)", scaling), ("full-mesh gait solves (bench_gait.py)", gait_bench),
                  ("Moco side by side (bench_moco_t9track.py)", moco)):
    print(f"• {name}: {perf.measured_on(res)}")
print(f"• scaling benchmark: {'complete' if scaling['complete'] else 'INCOMPLETE'}, total "
      f"{scaling['meta']['total_wall_s'] / 60:.0f} min, casadi {scaling['meta']['versions']['casadi']}, "
      f"gaitlib commit {scaling['meta']['versions']['gaitlib_commit']}")
sup = scaling["meta"].get("supplement")
if sup:
    print(f"• scaling supplement {sup['started']}: {sup['reason']}; {len(sup['runs'])} runs, load average at start "
          f"{sup['loadavg_start'][0]:.2f} (rows marked 'supplement' below)")

# %% [markdown]
# ## Mesh size and model
#
# The natural-gait data-tracking problem of each model (SK: Eq 4.11; MSK: Eq 5.33; NMSK:
# Eq 5.55; Free speed, the thesis's identified contact parameters fixed, the data-based
# initial guess), exact Hessian, MUMPS, IPOPT tolerance $10^{-5}$. Each run is a fresh
# process, one at a time. *Solve* is the IPOPT call; *build* is constructing the NLP and its
# exact derivative functions (CasADi SX); the time per iteration is split into CasADi
# function/derivative evaluations (IPOPT's `t_wall_nlp_*`) and the rest (IPOPT's own work,
# mostly the MUMPS factorisation).

# %%
table = perf.scaling_table(scaling)
display(table.drop(columns=["max_violation"], errors="ignore"))

# %%
fits = perf.scaling_fits(scaling)
display(fits)

# %%
fig = perf.scaling_figure(scaling)
plt.show()

# %% [markdown]
# ## Full-mesh solves beside the thesis's times
#
# `bench_gait.py` (20 × 5 LGR, the book's mesh). The thesis's times are GPOPS-II's in MATLAB
# on another computer, with the contact parameters identified in the SK run; they are a
# labelled reference, not a like-for-like comparison.

# %%
print(perf.measured_on(gait_bench))
display(perf.gait_table(gait_bench))

# %% [markdown]
# ## Building the NLP: whole-graph vs per-node derivatives
#
# Before the first iteration, IPOPT needs the exact gradient, constraint Jacobian and
# Lagrangian Hessian. Letting CasADi differentiate the NLP's whole SX graph (the default,
# `derivatives="graph"`, which made every stored solution) builds a Hessian of about 12 million
# instructions for the MSK problem, and that symbolic work *is* the build. Every non-linear
# term of the NLP sits in one collocation node's function `node(x, u, p, t, d)`;
# `derivatives="nodes"` (CLI `--derivatives nodes`) differentiates that one small function, evaluates its Jacobian and Hessian at all nodes in
# one mapped call and assembles IPOPT's matrices by the chain rule with the (small, mostly
# linear) rest of the NLP, through constant sparse maps computed once. The functions agree
# with CasADi's own derivatives to round-off and with finite differences
# (`tests/test_node_derivatives.py`, on every stored formulation). IPOPT may still take
# another path from round-off differences, which on these non-convex problems can mean another
# local optimum: both paths' iterations and objectives are shown. `bench_build.py`, both
# paths in one process:

# %%
build = perf.load_optional("build")
if build is not None:
    print(perf.measured_on(build))
    display(perf.build_table(build))
    print("\n".join(perf.build_findings(build)))

# %% [markdown]
# On the whole-graph path a process also keeps the solvers it built: a later problem with
# the same NLP graph and solver options (other data, weights, bounds or starting point — a
# continuation over bounds, a multistart, a twin) reuses the solver instead of
# differentiating the graph again. The same functions, so the same iterates to the last
# bit (`tests/test_build_reuse.py`); the key is the SHA-256 of the NLP's serialised graph,
# and what a process keeps is bounded by `GAITLIB_BUILD_REUSE_MB` (default a quarter of
# the machine's memory, at most 6 GB). `bench_build_reuse.py`, the contact identification
# (b) of Chapter 4 in two fresh processes, without and with reuse:

# %%
for stem in ("build_reuse", "build_reuse_1start", "build_reuse_6x3"):
    reuse = perf.load_optional(stem)
    if reuse is not None:
        print(perf.measured_on(reuse))
        print("\n".join(perf.build_reuse_findings(reuse)))

# %% [markdown]
# ## Where the MSK solve's time goes
#
# The target for the MSK data-tracking solve at the full mesh is ≤ 20 s. `bench_msk_profile.py`
# solves it with IPOPT's own timing statistics, each run in its own process: the book's
# options, and a few IPOPT option variants that might save iterations or factorisations.
# The variants are measurements, not tuning: each may stop in a different local optimum
# (see its objective), so a faster variant is not the same solve. IPOPT's split: the
# Lagrangian Hessian, the other function and derivative evaluations, the linear systems
# (MUMPS factorisations and back-solves) and the rest. An iteration whose KKT matrix needed a
# Hessian perturbation (inertia correction) is factorised at least twice.

# %%
prof = perf.load_optional("msk_profile")
if prof is not None:
    print(perf.measured_on(prof))
    pr_runs, pr_sizes = perf.msk_profile_tables(prof)
    display(pr_runs)
    display(pr_sizes)
    print("\n".join(perf.msk_profile_findings(prof)))

# %% [markdown]
# ## How fast could that solve be on the same path?
#
# The variants above that save iterations stop in other local optima, so the only change
# that keeps the book's solution is a cheaper iteration. `bench_eval_floor.py` asks what the
# function evaluations would cost compiled to C instead of run by CasADi's SX virtual machine.
# Every non-linear term of the Lagrangian belongs to one collocation node (the defects, the
# periodicity and the quadrature of the costs are linear), so the exact Hessian is a sum of
# per-node Hessians; the script checks this on the solver's Hessian pattern, compiles the
# per-node Hessian and Jacobian with gcc, and times them over all nodes beside the solver's
# own functions. With the default run of the profile above (its iterations and its linear
# systems unchanged) that gives lower bounds on the solve time. Finally the compiled
# per-node Hessians are assembled into IPOPT's exact Hessian (checked against the solver's own)
# and the book's problem is solved with it, beside the book's solver, from the same start.
# This benchmark keeps its own older assembly, which goes through a copy of the NLP; gaitlib's
# own compiled path is measured end to end in the next section. The
# C-to-virtual-machine ratio is a microbenchmark on this shared 2-core machine and varied
# between runs of the script (`benchmarks/README.md` lists them); the floors move with it.

# %%
floor = perf.load_optional("eval_floor")
if floor is not None:
    print(perf.measured_on(floor))
    for frame in perf.eval_floor_frames(floor):
        display(frame)
    if floor.get("floors"):
        display(perf.eval_floor_table(floor))
        print("\n".join(perf.eval_floor_findings(floor)))
    if floor.get("compiled_solve"):
        display(pd.DataFrame(floor["compiled_solve"]["solves"]))
        print(perf.compiled_solve_finding(floor))

# %% [markdown]
# ## End to end, as a user runs it
#
# What a user waits for is the command, not the IPOPT call: `bench_e2e.py` runs
# `gaitlib run gait --model MSK --cost DT --speed Free` (20 × 5) and `gaitlib gap` on a new
# CSV (a twin of the Free data with a knee-angle offset) in fresh processes from an empty
# solution cache, timed from the shell: interpreter start, imports, build, solve and outputs.
# Each runs on four paths: the default whole-graph derivatives; per-node derivatives
# (`--derivatives nodes`); and per-node derivatives with the per-node functions compiled to C
# (`--compiled`, `gaitlib.compiled`), first on a machine that has not compiled them yet and
# then with the compiled libraries cached. The compiled functions perform the same floating-
# point operations in the same order as CasADi's virtual machine (compiled without fast-math
# or fused multiply-adds), so they must give the same iterations and the same objective as
# the uncompiled per-node path — the column "same iterates as nodes" checks it. Targets
# (issue 22): ≤ 20 s for the MSK command, ≤ 60 s for the gap.

# %%
e2e = perf.load_optional("e2e")
if e2e is not None:
    print(perf.measured_on(e2e))
    e2e_gait, e2e_gap = perf.e2e_tables(e2e)
    display(e2e_gait)
    if len(e2e_gap):
        display(e2e_gap)
    print("\n".join(perf.e2e_findings(e2e)))

# %% [markdown]
# ### Fewer iterations? IPOPT's own options
#
# On the compiled path the rest is IPOPT's own work per iteration, so the other lever is
# the number of iterations. `bench_ipopt_options.py` solves the same MSK DT Free problem
# (20 × 5, per-node derivatives, compiled, from its data-based guess) once per variant of
# IPOPT's options — the barrier's start (`mu_init`), the NLP scaling, how far the start is
# pushed inside the bounds, the Hessian regularisation's schedule, the curvature test that
# replaces the inertia test, the adaptive barrier — and reads IPOPT's iteration log for the
# iterations that needed an inertia correction. A variant that lands on another local
# optimum is another result, not the same one faster: the last column is the RMS distance of
# its joint angles from the default variant's solution. The variants that looked promising
# on MSK are then tried on the NMSK problem (`--model NMSK`): a lever for the book must hold
# for every model.

# %%
for name in ("ipopt_options", "ipopt_options_nmsk"):  # MSK (all variants), then NMSK (the promising ones)
    ipo = perf.load_optional(name)
    if ipo is not None:
        print(f"{ipo['spec']['model']} DT Free — " + perf.measured_on(ipo))
        display(perf.ipopt_options_table(ipo))
        print("\n".join(perf.ipopt_options_findings(ipo)))

# %% [markdown]
# ### Fewer iterations? A warm-start chain across the speeds
#
# Chapter 7 starts every speed class from its model's Ch 5 solution (the Free data tracked),
# scaled in time to the class's cycle. `bench_warm_chain.py` starts the same specs the other
# way a continuation would: Slow and Fast from the whole Ch 5 solution, VerySlow from the
# Slow run's solution and VeryFast from the Fast run's, each scaled the same way — in the
# book's reading (the swing foot unloaded: the chapter's main runs) and in the thesis's (the
# problem as printed, shown beside them). The book's
# runs are read from the store with the statistics recorded at their solve (before their
# 3000-iteration reruns); the chained runs are solved here. The last column is the RMS
# distance of each chained run's joint angles from the book's run of the same class.

# %%
for name in ("warm_chain", "warm_chain_thesis"):  # the book's reading (Ch 7's main runs), the thesis's
    chain = perf.load_optional(name)
    if chain is not None:
        print(f"{chain['reading']}'s reading — " + perf.measured_on(chain))
        with pd.option_context("display.max_colwidth", 70):
            display(perf.warm_chain_table(chain))
        print("\n".join(perf.warm_chain_findings(chain)))

# %% [markdown]
# ## The whole book from scratch
#
# Issue 22's first target is the whole book from an empty cache in 45 minutes on this 2-core
# machine. `bench_book_budget.py` lists what a from-scratch build would solve: every notebook
# runs from the store only, and the entries it looks up are exactly the optimisations a build
# without the store must solve (an entry read by several pages counts once, for the first
# chapter that reads it). Each stored solution keeps the statistics of its own solve —
# iterations, build and IPOPT time, as recorded when it was solved on this shared machine
# (not re-measured). On those recorded paths the table applies the levers measured above,
# each with the ratio its benchmark measured: per-node builds (the build benchmark's per-node
# build time of the solve's model) with the evaluations compiled (the end-to-end benchmark's
# compiled over uncompiled evaluations); then the evaluations made free altogether (only
# IPOPT's own work left: the floor of any evaluation speed-up); then that split perfectly
# over two workers. The iterations stay as recorded: every measured way to fewer iterations
# (IPOPT's options, the integral defects) ended in other local optima.

# %%
budget = perf.load_optional("book_budget")
if budget is not None:
    print(perf.measured_on(budget))
    with pd.option_context("display.precision", 2):
        display(perf.book_budget_table(budget))
    print("\n".join(perf.book_budget_findings(budget)))

# %% [markdown]
# The perfect split over two workers is an assumption; `bench_workers.py` measures it on a
# cluster of separate processes started as the README shows (`dask scheduler`, `dask worker
# --nworkers N --nthreads 1`), one worker against two, on two of the book's kinds of sweep:
# `gaitlib gap` on a new CSV (Chapter 8's kind of solve, 10 × 3) and four of Chapter 6's MSK
# runs (20 × 5), everything solved (`--no-cache`).

# %%
workers = perf.load_optional("workers")
if workers is not None:
    print(perf.measured_on(workers))
    display(perf.workers_table(workers))
    print("\n".join(perf.workers_findings(workers, budget)))

# %% [markdown]
# ## Every optimisation of the book beside the thesis's times
#
# `bench_thesis_times.py` lists every optimisation the chapters run — by calling the same
# study functions as the notebooks — beside the compute time the thesis prints for it
# (Sec 4.3.3: 6 min and 11 min; Sec 4.4.2: 5 h; Secs 5.2.2 and 5.3.5: 2 h; Tables 6.3 and
# 7.2). The thesis prints no time for the Ch 2 SK tracking with fixed contact parameters, the
# Ch 3 jumps or the Ch 5 MTG identification: their thesis column is empty. Our times are **as
# measured when each solution was solved**: a cached solution keeps the statistics of its
# solve (`from cache`; `solved at` is the file time of the cache entry), on this 2-core
# machine shared with other jobs (the load during each solve is not recorded). *Wall* =
# build (symbolic graph, exact derivatives, IPOPT set-up) + IPOPT, summed over every NLP
# solve of the optimisation (continuation stages, multistart local solves); ms/iteration =
# IPOPT time / iterations. The speed-up (thesis time / our wall) is given **only for runs
# that converged**; a run IPOPT did not finish keeps its status. The thesis's times are
# GPOPS-II in MATLAB (IPOPT, first derivatives) on an i7-6700, on other data: a labelled
# reference, not a like-for-like benchmark. The runs marked *investigation* are the book's
# 3000-iteration reruns of runs that stopped at 1000 iterations; *thesis's partial guess*
# are the runs from the thesis's initial guess, which the chapters show beside the runs they
# use.

# %%
tt = perf.load("thesis_times")
m = tt["meta"]["machine"]
print(f"written {tt['meta']['written']} on {m['cpu']} ({m['cores']} cores, {m['memory_gb']} GB), {m['platform']}; "
      f"casadi {tt['meta']['versions']['casadi']}, gaitlib commit {tt['meta']['versions']['gaitlib_commit']}")
for when, c in tt["meta"]["collections"].items():
    print(f"• collection {when}: mode '{c['mode']}', chapters {', '.join(c['chapters'])}, "
          f"load average at start {c['loadavg_start'][0]:.2f}")
solved = [r["solved_at"] for r in tt["rows"] if r["solved_at"]]
if solved:
    print(f"• the solutions were solved between {min(solved)} and {max(solved)} (UTC)")
display(perf.thesis_times_by_chapter(tt))

# %%
with pd.option_context("display.max_rows", 200, "display.max_colwidth", 60):
    display(perf.thesis_times_table(tt))

# %%
fig = perf.thesis_times_figure(tt)
plt.show()

# %%
print("\n".join(perf.thesis_times_findings(tt)))

# %% [markdown]
# ## Side by side with OpenSim Moco
#
# The same 9-degree-of-freedom torque-driven tracking problem (Moco's `example2DWalking`
# tracking half, T9-track) solved by Moco 4.6 and by gaitlib on one machine, in one run;
# `benchmarks/README.md` documents how the two problems were checked to be identical and
# the remaining differences (Moco: finite differences and an L-BFGS Hessian; gaitlib: exact
# derivatives). Speed-up = Moco's median solve time / gaitlib's. End to end (setup + solve:
# model and problem construction, the NLP with its derivatives, and IPOPT) gaitlib is also
# run with per-node derivatives (the section on building the NLP above), which removes most of
# its setup, and with those per-node functions compiled to C (`--compiled`; compiled once
# before the timed repeats, the same iterates as uncompiled); the "best converged" columns
# divide Moco's time by that of the fastest gaitlib variant that converged in every repeat.

# %%
print(perf.measured_on(moco))
display(perf.moco_table(moco))

# %% [markdown]
# ## One iteration at a fixed point
#
# IPOPT's average time per iteration mixes the cost of an iteration with the number of KKT
# factorisations IPOPT needs in it — one more for every inertia correction, which depends on
# the path the solver takes at each mesh size. `bench_kkt_scaling.py` measures the pieces of
# one iteration at a fixed point instead (the data-based initial guess): one call of each
# NLP function IPOPT evaluates per iteration (Lagrangian Hessian, constraint Jacobian,
# gradient, constraints, objective — the `nlpsol` object's own functions) and one MUMPS
# factorisation and solve of the KKT matrix (through CasADi's MUMPS interface, with its
# default settings, not IPOPT's), medians of 7 repeats, each mesh in its own process. The
# evaluations are exactly the work IPOPT does per iteration; the factorisation is a proxy
# only: with CasADi's default MUMPS settings its cost jumps at a KKT size of ≈ 10,000 rows,
# which IPOPT's MUMPS (its own settings; its automatic ordering here reproduces AMF, see the
# MSK profile) does not show to that extent.

# %%
kkt = perf.load_optional("kkt_scaling")
if kkt is not None:
    print(perf.measured_on(kkt))
    kkt_rows, kkt_fits = perf.kkt_scaling_tables(kkt)
    display(kkt_rows)
    display(kkt_fits.pivot(index="quantity", columns="model", values="exponent").round(3))

# %% [markdown]
# ## Why the linear algebra grows faster than the mesh
#
# The evaluations above grow exactly linearly with the mesh; the factorisation does not.
# `bench_kkt_fill.py` counts, without timing anything, what a sparse LDLᵀ factorisation of
# IPOPT's KKT matrix has to do at each mesh: the KKT pattern is assembled from the solver's
# own Hessian and Jacobian patterns and factorised *symbolically* with an approximate-
# minimum-degree ordering (CasADi's, the family of MUMPS's default orderings — a model of
# MUMPS, not MUMPS), with and without the periodic-gait constraint that links the cycle's
# end to its start. `flops_proxy` is Σ over the factor's columns of (column count)², the
# factorisation's flops up to a constant.

# %%
fill = perf.load_optional("kkt_fill")
if fill is not None:
    print(perf.measured_on(fill))
    fr = pd.DataFrame(fill["rows"])
    display(fr[["model", "periodic", "nodes", "kkt_rows", "kkt_nnz", "L_nnz", "L_max_column", "flops_proxy"]])
    ff = pd.DataFrame(fill["fits"])
    display(ff.pivot_table(index="quantity", columns=["model", "periodic"], values="exponent").round(3))
    b = ff.set_index(["model", "periodic", "quantity"])["exponent"]
    print("; ".join(f"{m}: the KKT's non-zeros grow as nodes^{b[(m, True, 'kkt_nnz')]:.2f}, the factor's as "
                    f"nodes^{b[(m, True, 'L_nnz')]:.2f}, its flops as nodes^{b[(m, True, 'flops_proxy')]:.2f} "
                    f"(nodes^{b[(m, False, 'flops_proxy')]:.2f} without periodicity)"
                    for m in dict.fromkeys(ff["model"])))

# %% [markdown]
# ## MUMPS's own count, ordering by ordering
#
# The symbolic count above models MUMPS with CasADi's minimum-degree ordering.
# `bench_mumps_orderings.py` asks MUMPS itself: IPOPT is started on each mesh once per value
# of `mumps_pivot_order` (AMD, AMF, SCOTCH, PORD, METIS, QAMD and MUMPS's automatic choice,
# IPOPT's default), and MUMPS's analysis report gives the ordering it actually used, the
# estimated entries of the factors and the estimated operations of one factorisation. The
# analysis is made once per solve on a pattern that does not change between iterations, so
# these are the counts of every factorisation in a solve (before delayed pivots). No timing.

# %%
mo = perf.load_optional("mumps_orderings")
if mo is not None:
    print(perf.measured_on(mo))
    mo_rows, mo_fits = pd.DataFrame(mo["rows"]), pd.DataFrame(mo["fits"])
    display(mo_rows.pivot_table(index=["model", "nodes"], columns="requested_name", values="flops").map(
        lambda v: f"{v:.3g}"))
    display(mo_fits[mo_fits["quantity"] == "flops"].pivot(index="requested_name", columns="model",
                                                          values="exponent").round(3))
    print("\n".join(perf.mumps_orderings_findings(mo)))

# %% [markdown]
# ## Exact Hessian vs limited-memory (L-BFGS)
#
# The same problem and mesh, IPOPT's `hessian_approximation` exact (CasADi's second
# derivatives) or `limited-memory`, from the same initial guess. Below the scaling run, the
# MSK row of `bench_gait.py` (full mesh).

# %%
hess = perf.hessian_table(scaling)
display(hess)
lbfgs_gait = [r for r in gait_bench["rows"] if "L-BFGS" in r["run"]]
display(pd.DataFrame(lbfgs_gait)[["run", "status", "iterations", "solve_s", "ms_per_iteration", "objective"]]
        if lbfgs_gait else "no L-BFGS row in gait.json")

# %% [markdown]
# ## Linear solvers
#
# Every `linear_solver` value of IPOPT 3.14 was tried on a two-variable problem in its own
# process; the ones that load then solve the scaling problem. The HSL solvers (MA27–MA97)
# and Pardiso are loaded by IPOPT at run time from libraries this casadi wheel does not
# ship; the message is IPOPT's.

# %%
avail, lin = perf.linear_solver_table(scaling)
display(avail)
display(lin)

# %% [markdown]
# ## A structure-exploiting solver: FATROP
#
# FATROP, which ships in the pinned casadi wheel, solves an optimal control problem by a
# Riccati recursion over its stages with dense stage blocks, instead of MUMPS's sparse
# factorisation of the whole KKT system. It takes only an NLP laid out stage by stage, each
# stage closing its gap explicitly, x_{k+1} = Φ_k(x_k, u_k). `bench_fatrop.py` rewrites the
# book's LGR problems into that layout from the same symbols, data and bounds: a stage is a
# mesh interval; its state is the interval's first state node plus a constant copy of x(0)
# (which carries the periodicity to the last stage); its "controls" are the interval's
# controls and interior state nodes; the defects are multiplied by the inverse of their end
# columns (the *integral form*, an equivalent set of equations) so that the last one is the
# explicit gap. The tests (`tests/test_bench_fatrop.py`) check that the rewrite is the same
# equations at any point and that FATROP accepts its layout. FATROP runs a fixed number of
# iterations here: its time per iteration is the measurement. Beside it, IPOPT on the
# integral form of gaitlib's own NLP (`GaitSpec(defects="integral")`) and on the rewrite.

# %%
fat = perf.load_optional("fatrop")
if fat is not None:
    print(perf.measured_on(fat))
    display(perf.fatrop_table(fat))
    print("\n".join(perf.fatrop_findings(fat)))

# %% [markdown]
# The integral form of the defects, measured on its own: `bench_defect_form.py` solves the
# CLI's MSK DT Free and the book's natural-gait problems in both forms (per-node derivatives,
# compiled, from the same guess). Its rows are denser (each reads all of its interval's
# dynamics), so an iteration costs more; whether it needs fewer iterations is what is measured.

# %%
dform = perf.load_optional("defect_form")
if dform is not None:
    print(perf.measured_on(dform))
    print("\n".join(perf.defect_form_findings(dform)))

# %% [markdown]
# ## What we found
#
# Computed from the stored results above (nothing in this paragraph is typed by hand):

# %%
print("\n".join(perf.findings(scaling, moco, kkt=kkt, fill=fill)))

# %% [markdown]
# Issue 22's time targets beside the measurements above (each row computed from its results
# file; where a target is not met, its section above gives the measured floor of every lever):

# %%
with pd.option_context("display.max_colwidth", 100):
    display(perf.targets_table(e2e, moco, budget, workers).set_index("target"))

# %% [markdown]
# **Where this differs from the thesis, and what the numbers do not separate.** The thesis
# reports only total solve times (GPOPS-II in MATLAB, on its own computer), so it appears
# only as the labelled column of the full-mesh and thesis-times tables, not as a
# like-for-like benchmark; our times in the thesis-times table are those recorded when each
# solution was solved, under whatever load the shared machine had then. The
# time per iteration above is the IPOPT call divided by its iterations: it does not separate
# the number of KKT factorisations per iteration (IPOPT refactorises whenever it corrects the
# inertia of the KKT matrix, more often far from a solution, e.g. in runs that end at the
# iteration limit) from the cost of one factorisation (the MSK profile above counts the
# iterations that needed a perturbation). The exponents describe this machine under the load
# recorded with each run (see the notes printed with each results file), not the algorithm
# alone.
