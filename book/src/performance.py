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
import numpy as np
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
fig, axes = plt.subplots(1, 3, figsize=(13, 4))
colors = {"SK": "C0", "MSK": "C1", "NMSK": "C2"}
fin = pd.DataFrame([r for r in scaling["runs"] if r["group"] == "mesh" and r["outcome"] == perf.FINISHED])
for model, g in fin.groupby("model", sort=False):
    g = g.sort_values("nodes")
    f = perf.fit_power_law(g["nodes"], g["ms_per_iteration"])
    conv = g["success"].astype(bool)
    axes[0].loglog(g["nodes"][conv], g["ms_per_iteration"][conv], "o", color=colors[model])
    axes[0].loglog(g["nodes"][~conv], g["ms_per_iteration"][~conv], "x", color=colors[model], ms=9)
    if np.isfinite(f["exponent"]):
        n = np.geomspace(g["nodes"].min(), g["nodes"].max(), 20)
        axes[0].loglog(n, f["prefactor"] * n ** f["exponent"], "-", color=colors[model],
                       label=f"{model}: b = {f['exponent']:.2f}")
    else:
        axes[0].plot([], [], "o", color=colors[model], label=f"{model}: one size")
    axes[1].loglog(g["nodes"], g["solve_s"], "o-", color=colors[model], label=model)
    axes[2].loglog(g["nodes"], g["build_s"], "o-", color=colors[model], label=model)
    if model == "SK":
        axes[0].loglog(g["nodes"], g["function_evals_ms_per_iteration"], "v:", color=colors[model], ms=4,
                       label="SK: function evaluations")
        axes[0].loglog(g["nodes"], g["ipopt_rest_ms_per_iteration"], "s:", color=colors[model], ms=4,
                       label="SK: IPOPT + MUMPS")
if len(fin):
    n = np.geomspace(fin["nodes"].min(), fin["nodes"].max(), 20)
    sk = fin[fin["model"] == "SK"].sort_values("nodes")
    if len(sk):
        ref = sk["ms_per_iteration"].iloc[0] * n / sk["nodes"].iloc[0]
        axes[0].loglog(n, ref, "k--", lw=0.8, label="linear (b = 1)")
axes[0].set(xlabel="collocation nodes N", ylabel="ms per iteration",
            title="Time per iteration (× = did not converge)")
axes[1].set(xlabel="collocation nodes N", ylabel="s", title="Solve time (IPOPT call)")
axes[2].set(xlabel="collocation nodes N", ylabel="s", title="Build time (NLP + exact derivatives)")
from matplotlib.ticker import NullFormatter, ScalarFormatter

for ax in axes:
    if len(fin):
        ax.set_xticks(sorted(fin["nodes"].unique()))
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
    ax.legend(fontsize=7)
    ax.grid(True, which="both", lw=0.3)
fig.tight_layout()
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
    d = pr_runs.iloc[0]
    sz = pr_sizes.set_index("model")
    print(f"• Book options: {d['status']}, {d['iterations']} iterations, {d['solve (s)']:.1f} s "
          f"({d['ms / iteration']:.0f} ms per iteration) — the ≤ 20 s target is "
          f"{'met' if d['solve (s)'] <= 20 and d['status'] == 'Solve_Succeeded' else 'NOT met'}. Of the solve, "
          f"{100 * d['Hessian (s)'] / d['solve (s)']:.0f} % is the Hessian, "
          f"{100 * d['other evaluations (s)'] / d['solve (s)']:.0f} % the other evaluations, "
          f"{100 * d['linear systems, MUMPS (s)'] / d['solve (s)']:.0f} % the linear systems; "
          f"{d['iterations with Hessian perturbation']} of {d['iterations']} iterations needed a Hessian perturbation.")
    print(f"• The MSK constraints are {sz.loc['MSK', 'constraint SX instructions'] / sz.loc['SK', 'constraint SX instructions']:.0f}× "
          f"the SK constraints in SX instructions and the Hessian {sz.loc['MSK', 'Hessian SX instructions'] / sz.loc['SK', 'Hessian SX instructions']:.1f}×: "
          f"the muscle torque generators' piecewise-quintic curves (≈ 60 pieces per generator, each piece "
          f"selected by a chain of if_else nodes at every node) are most of the difference.")
    ok = pr_runs[pr_runs["status"] == "Solve_Succeeded"]
    print(f"• Option variants that converged: {len(ok) - 1}; fastest {ok['solve (s)'].min():.1f} s "
          f"({ok.loc[ok['solve (s)'].idxmin(), 'variant']}); objectives of the converged runs "
          f"{ok['objective'].min():.3f}–{ok['objective'].max():.3f} (different local optima).")

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
# gaitlib's solver does not use this code; it is a measurement of what it could gain. The
# C-to-virtual-machine ratio is a microbenchmark on this shared 2-core machine and varied
# between runs of the script (`benchmarks/README.md` lists them); the floors move with it.

# %%
floor = perf.load_optional("eval_floor")
if floor is not None:
    print(perf.measured_on(floor))
    display(pd.DataFrame([floor["solver_function_ms"]]).rename(index={0: "ms per call (SX virtual machine)"}))
    display(pd.DataFrame({"SX virtual machine (ms)": floor["mapped_vm_ms"],
                          "compiled C (ms)": floor["mapped_compiled_ms"]}).rename_axis(
        f"per-node, mapped over {floor['collocation_nodes']} nodes"))
    if floor.get("floors"):
        ft = perf.eval_floor_table(floor)
        display(ft)
        fl = floor["floors"]
        print(f"• The solver's Hessian has {floor['hessian_nnz']:,} non-zeros, "
              f"{floor['hessian_nnz_outside_node_blocks']} outside the nodes' (x, u) blocks; per node "
              f"{floor['node_hessian_instructions']:,} SX instructions × {floor['collocation_nodes']} nodes = "
              f"{floor['nodes_x_node_hessian_instructions']:,}, against {floor['solver_hessian_instructions']:,} in the "
              f"solver's Hessian: the same work, evaluated per node.")
        print(f"• Compiled with gcc {floor['gcc']} ({floor['compile_s']:.0f} s), the per-node Hessian over all nodes "
              f"takes {floor['mapped_compiled_ms']['hessian']:.1f} ms against the solver's "
              f"{floor['solver_function_ms']['nlp_hess_l']:.1f} ms ({fl['compiled_to_vm_hessian_ratio']:.2f}×). On the "
              f"default path ({fl['iterations']} iterations) the solve would take at best "
              f"{fl['floor_hessian_compiled_s']:.1f} s with the Hessian compiled and "
              f"{fl['floor_all_compiled_s']:.1f} s with every evaluation equally faster; the linear systems and "
              f"IPOPT's own work alone take {fl['floor_evaluations_free_s']:.1f} s. Reaching 20 s on this path would "
              f"need all evaluations together in ≤ {fl['evaluation_budget_ms_per_iteration']:.1f} ms per iteration.")
    cs = floor.get("compiled_solve")
    if cs:
        sv = pd.DataFrame(cs["solves"])
        display(sv)
        bk, cp = sv.iloc[0], sv.iloc[1]
        same = bk["iterations"] == cp["iterations"] and abs(bk["objective"] - cp["objective"]) <= 1e-6 * abs(bk["objective"])
        print(f"• Assembled from the compiled per-node Hessians, IPOPT's exact Hessian equals the solver's to "
              f"{cs['hessian_check_max_rel_diff']:.0e} (relative) and costs {cs['hessian_ms']['assembled_compiled']:.1f} ms "
              f"instead of {cs['hessian_ms']['solver']:.1f} ms. Solved with it: {cp['status']}, {cp['iterations']} "
              f"iterations, {cp['solve_s']:.1f} s ({cp['ms_per_iteration']:.0f} ms per iteration), objective "
              f"{cp['objective']:.4f}; the book's solver in the same run: {bk['status']}, {bk['iterations']} iterations, "
              f"{bk['solve_s']:.1f} s ({bk['ms_per_iteration']:.0f} ms per iteration), objective {bk['objective']:.4f}. "
              + ("Same path, same solution." if same else
                 "Round-off differences alone (the same Hessian summed in another order) send IPOPT down another "
                 "path to another local optimum: a faster Hessian does not give the book's solve faster."))

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
# are the NMSK runs from the thesis's initial guess, which the chapters show beside the runs
# they use.

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
ts = perf.thesis_times_summary(tt)
rows_tt = pd.DataFrame(tt["rows"])
print(f"• {ts['n_rows']} optimisations: {ts['n_converged']} converged, {ts['n_not_converged']} did not, "
      f"{ts['n_missing']} not collected; {ts['n_from_cache']} of the measured ones reloaded from the cache with the "
      f"times of their solve. Our wall times add up to {ts['total_wall_s'] / 3600:.1f} h.")
if ts["n_with_thesis"]:
    conv_tt = rows_tt[rows_tt["speedup"].notna()]
    lo, hi = conv_tt.loc[conv_tt["speedup"].idxmin()], conv_tt.loc[conv_tt["speedup"].idxmax()]
    print(f"• Over the {ts['n_with_thesis']} converged optimisations with a thesis time the speed-up is "
          f"{ts['speedup_min']:.1f}–{ts['speedup_max']:.0f}× (median {ts['speedup_median']:.0f}×). Smallest: "
          f"{lo['chapter']} {lo['run']} — {lo['wall_s'] / 60:.1f} min here vs {lo['thesis_time']}; largest: "
          f"{hi['chapter']} {hi['run']} — {hi['wall_s'] / 60:.1f} min vs {hi['thesis_time']}.")
not_conv = rows_tt[~rows_tt["converged"].astype(bool) & ~rows_tt["status"].isin([perf.NOT_COMPUTED, perf.NO_CACHE])]
if len(not_conv):
    print("• Did not converge (no speed-up given): " + "; ".join(
        f"{r.chapter} {r.run}: {r.status} after {r.iterations} iterations" for r in not_conv.itertuples()) + ".")
missing_tt = rows_tt[rows_tt["status"].isin([perf.NOT_COMPUTED, perf.NO_CACHE])]
if len(missing_tt):
    print("• Not collected: " + "; ".join(f"{r.chapter} {r.run} ({r.status})" for r in missing_tt.itertuples()) + ".")

# %% [markdown]
# ## Side by side with OpenSim Moco
#
# The same 9-degree-of-freedom torque-driven tracking problem (Moco's `example2DWalking`
# tracking half, T9-track) solved by Moco 4.6 and by gaitlib on one machine, in one run;
# `benchmarks/README.md` documents how the two problems were checked to be identical and
# the remaining differences (Moco: finite differences and an L-BFGS Hessian; gaitlib: exact
# derivatives). Speed-up = Moco's median solve time / gaitlib's.

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
    fl_fits = mo_fits[mo_fits["quantity"] == "flops"]
    display(fl_fits.pivot(index="requested_name", columns="model", values="exponent").round(3))
    fallback = mo_rows[mo_rows["requested_name"].str.split().str[0] != mo_rows["ordering_name"]]
    fallback = fallback[fallback["requested"] != 7]
    if len(fallback):
        print("• Not in this MUMPS build (MUMPS used another ordering instead): " + "; ".join(
            f"{name} → {', '.join(f'{u} (KKT of {g2.kkt_n.min():,}–{g2.kkt_n.max():,} rows)' for u, g2 in g.groupby('ordering_name'))}"
            for name, g in fallback.groupby("requested_name", sort=False)) + ". Their fitted exponents mix two "
            "orderings and are left out below.")
    mixed = set(fallback["requested_name"])
    for model, g in fl_fits[~fl_fits["requested_name"].isin(mixed)].groupby("model", sort=False):
        best = g.loc[g["exponent"].idxmin()]
        at = mo_rows[mo_rows["model"] == model]
        at = at[at["nodes"] == at["nodes"].max()].set_index("requested_name")["flops"]
        auto = at["auto (IPOPT default)"]
        used = mo_rows[(mo_rows["model"] == model) & (mo_rows["requested"] == 7)]["ordering_name"].unique()
        is_default = best["used"] in used
        print(f"• {model}: one factorisation's operations grow as nodes^{g['exponent'].min():.2f}–"
              f"{g['exponent'].max():.2f} over the orderings; the slowest growth is {best['requested_name']}'s "
              f"(nodes^{best['exponent']:.2f} ± {best['exponent_se']:.2f})"
              + (f", which is what IPOPT's default (MUMPS's automatic choice) uses. " if is_default else
                 f", but at the largest mesh its count is {at[best['requested_name']] / auto:.2f}× that of IPOPT's "
                 f"default (MUMPS's automatic choice: {', '.join(used)}). ")
              + ("No ordering MUMPS offers grows linearly or slower." if g["exponent"].min() > 1.0 else
                 "At least one ordering grows no faster than linearly."))

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
# ## What we found
#
# Computed from the stored results above (nothing in this paragraph is typed by hand):

# %%
def _fit(model, quantity="time per iteration"):
    r = fits[(fits["model"] == model) & (fits["quantity"] == quantity)]
    return None if r.empty or not np.isfinite(r["exponent"].iloc[0]) else r.iloc[0]


for model in ("SK", "MSK", "NMSK"):
    g = table[table["model"] == model]
    if g.empty:
        continue
    f = _fit(model)
    statuses = ", ".join(f"{int(r.n_intervals)} intervals: {r.status} ({int(r.iterations)} it, "
                         f"{r.ms_per_iteration:.0f} ms/it)" for r in g.itertuples() if isinstance(r.status, str))
    if f is None:
        print(f"• {model}: {statuses}; one mesh size only, no exponent fitted.")
        continue
    verdict = "meets" if f["exponent"] <= 1.0 else "does NOT meet"
    parts = [p for p in (_fit(model, "function evaluations per iteration"), _fit(model, "IPOPT + MUMPS per iteration"))
             if p is not None]
    split = (f" (function evaluations b = {parts[0]['exponent']:.2f}, IPOPT + MUMPS b = {parts[1]['exponent']:.2f})"
             if len(parts) == 2 else "")
    it = _fit(model, "iterations")
    print(f"• {model}: time per iteration grows as N^{f['exponent']:.2f} over N = {f['nodes']} nodes{split}, which "
          f"{verdict} the target of at most linear growth; iterations ∝ N^{it['exponent']:.2f}. Runs: {statuses}.")
sk_runs = table[table["model"] == "SK"].sort_values("nodes")
sk_f, sk_fe = _fit("SK"), _fit("SK", "function evaluations per iteration")
if len(sk_runs) >= 2 and sk_f is not None and sk_fe is not None:
    sk_mu = _fit("SK", "IPOPT + MUMPS per iteration")["exponent"]
    print(f"• How much of that is the machine: the CasADi evaluations do exactly proportional work (the same "
          f"per-node expressions at every node), yet measure b = {sk_fe['exponent']:.2f} for SK; the 1-minute load "
          f"average was {sk_runs['load (1 min) at start'].iloc[0]:.1f} at the smallest SK mesh and "
          f"{sk_runs['load (1 min) at start'].iloc[-1]:.1f} at the largest (2 cores). If contention and cache "
          f"effects inflate every exponent by that {sk_fe['exponent'] - 1:+.2f}, IPOPT + MUMPS per iteration "
          f"(b = {sk_mu:.2f}) still grows "
          f"{'faster than linearly' if sk_mu - (sk_fe['exponent'] - 1) > 1 else 'no faster than linearly'} "
          f"(b ≈ {sk_mu - (sk_fe['exponent'] - 1):.2f}).")
if kkt is not None:
    kf = kkt_fits.set_index(["model", "quantity"])["exponent"]
    for model in dict.fromkeys(kkt_fits["model"]):
        b_it, b_ev, b_fa = kf[(model, "iteration_ms")], kf[(model, "evaluations_ms")], kf[(model, "factor_solve_ms")]
        kr = kkt_rows[kkt_rows["model"] == model].sort_values("nodes")
        jump = (kr["factorisation_ms"] / kr["kkt_dim"]).pct_change().max()
        print(f"• {model} at a fixed point: the NLP evaluations of one iteration grow as N^{b_ev:.2f} "
              f"({'linear' if b_ev <= 1.02 else 'superlinear'}); one MUMPS factorisation + solve through CasADi's "
              f"interface as N^{b_fa:.2f}, with its cost per KKT row rising by up to {100 * jump:.0f} % from one mesh "
              f"to the next — MUMPS's own choices at CasADi's default settings, not IPOPT's (IPOPT's linear-system "
              f"time per iteration is the 'IPOPT + MUMPS' exponent above).")
if fill is not None:
    for model in dict.fromkeys(ff["model"]):
        b_fl, b_np, b_L = b[(model, True, "flops_proxy")], b[(model, False, "flops_proxy")], b[(model, True, "L_nnz")]
        mu = _fit(model, "IPOPT + MUMPS per iteration")
        print(f"• {model}, counted rather than timed: a minimum-degree LDLᵀ of the KKT matrix has a factor growing as "
              f"N^{b_L:.2f} but flops growing as N^{b_fl:.2f} (N^{b_np:.2f} without the periodic constraint)"
              + (f", beside IPOPT + MUMPS's measured N^{mu['exponent']:.2f}" if mu is not None else "")
              + ": the superlinear part of the linear algebra is the fill of the minimum-degree ordering, not "
                "the machine (MUMPS's own counts for every ordering it offers are in the section above).")
by_model = table[table["nodes"] == 100].set_index("model")
if {"SK", "MSK"} <= set(by_model.index):
    msg = (f"• At the thesis mesh (100 nodes) one iteration costs {by_model.loc['SK', 'ms_per_iteration']:.0f} ms (SK), "
           f"{by_model.loc['MSK', 'ms_per_iteration']:.0f} ms (MSK)")
    if "NMSK" in by_model.index:
        msg += f", {by_model.loc['NMSK', 'ms_per_iteration']:.0f} ms (NMSK)"
    print(msg + f"; building the NLP takes {by_model['build_s'].min():.0f}–{by_model['build_s'].max():.0f} s.")
hess_done = hess[hess["outcome"] == perf.FINISHED]
if hess_done["hessian"].nunique() < 2:
    print(f"• Exact Hessian vs L-BFGS: not measured ({', '.join(hess['outcome'].astype(str))}).")
else:
    ex = hess_done[hess_done["hessian"] == "exact"].iloc[0]
    lm = hess_done[hess_done["hessian"] == "limited-memory"].iloc[0]
    print(f"• Exact Hessian vs L-BFGS ({ex['model']}, {int(ex['n_intervals'])} intervals): {ex['status']} in "
          f"{int(ex['iterations'])} iterations / {ex['solve_s']:.0f} s vs {lm['status']} in {int(lm['iterations'])} "
          f"iterations / {lm['solve_s']:.0f} s (objective {ex['objective']:.4g} vs {lm['objective']:.4g}); an L-BFGS "
          f"iteration costs {lm['ms_per_iteration'] / ex['ms_per_iteration']:.2f}× an exact one.")
loads = avail[avail["loads"]]["linear_solver"].tolist() if not avail.empty else []
print(f"• Linear solvers that load in this casadi build: {', '.join(loads)}; "
      f"{len(avail) - len(loads)} others fail to load ({', '.join(avail[~avail['loads']]['linear_solver'])}).")
lin_done = lin[lin["outcome"] == perf.FINISHED] if len(lin) else lin
if len(lin_done) and (lin_done["linear_solver"] == "mumps").any():
    mu = lin_done[lin_done["linear_solver"] == "mumps"].iloc[0]
    for r in lin_done[lin_done["linear_solver"] != "mumps"].itertuples():
        print(f"  {r.linear_solver}: {r.status}, {r.iterations} iterations, {r.ms_per_iteration:.0f} ms/iteration "
              f"({r.ms_per_iteration / mu['ms_per_iteration']:.1f}× MUMPS's {mu['ms_per_iteration']:.0f} ms), "
              f"objective {r.objective:.4g} (MUMPS {mu['objective']:.4g}).")
mt = perf.moco_table(moco)
print("• Against OpenSim Moco (T9-track), median solve times: " + "; ".join(
    f"{r['scheme']}: Moco {r['Moco solve (s)']:.2f} s, gaitlib {r['gaitlib solve (s)']:.2f} s = {r['speed-up']:.1f}× "
    f"(with IPOPT's default options {r['speed-up, gaitlib with IPOPT defaults']:.1f}×; setup + solve "
    f"{r['Moco setup + solve (s)']:.1f} s vs {r['gaitlib setup + solve (s)']:.1f} s)" for _, r in mt.iterrows()) + ".")

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
