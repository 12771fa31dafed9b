"""FATROP against IPOPT + MUMPS on the book's natural-gait problems (issue: Performance II).

    .venv/bin/python benchmarks/bench_fatrop.py                      # SK and MSK, 20 × 5 (the book's mesh)
    .venv/bin/python benchmarks/bench_fatrop.py --quick              # SK, 4 × 5 (checks the script)
    .venv/bin/python benchmarks/bench_fatrop.py --models MSK --intervals 20

FATROP (in the pinned casadi wheel, ``nlpsol("fatrop")``) solves an optimal control problem
by a Riccati recursion over its stages, with dense stage blocks, instead of a sparse LDLᵀ of
the whole KKT system. It takes only NLPs laid out stage by stage:

    variables  x₀ u₀ x₁ u₁ … x_N          (x_k: the stage's state, u_k: its "controls")
    rows       for k < N: x_{k+1} − Φ_k(x_k, u_k) = 0 (coefficient exactly +1 on x_{k+1}),
               then the stage's own constraints g_k(x_k, u_k); then g_N(x_N)

and a Lagrangian Hessian block-diagonal in (x_k, u_k). gaitlib's LGR transcription is
rewritten into that form here, from the same symbols, data and bounds
(``gaitlib.ocp.Transcription``), so the two solvers meet the same optimal control problem:

- stage k = mesh interval k; its state is the interval's first state node X_{k,0} plus a
  constant copy z of the cycle's first state (z_{k+1} = z_k, z₀ = X_{0,0}), which carries the
  periodicity and endpoint constraints to the last stage (they couple x(0) and x(T));
- its "controls" are the controls at the interval's collocation nodes and its interior
  state nodes X_{k,1..d−1};
- the defects X_k Aᵀ − h F Bᵀ = 0 (LGR, left: collocated at X_{k,0..d−1}, not at the end
  node) are multiplied by Â⁻¹ (Â = A without its first column; A·1 = 0): the integral form
  X_{k,j} = X_{k,0} + h Σ_l (Â⁻¹B)_{jl} F_l. Its last row is the stage's explicit
  dynamics X_{k+1,0} = Φ_k; the others are equality constraints of the stage. An
  equivalent set of equations (a non-singular linear map of each interval's defects): the
  same feasible set and optimum, another scaling of the rows.

Four solves per problem, the same initial point and data, IPOPT with gaitlib's options:
``ipopt``: gaitlib's own NLP (what the book solves); ``ipopt (integral form)``: gaitlib's
NLP with ``Mesh(defect_form="integral")`` (the rewrite's rows, without the copy of x(0));
``ipopt (stage-wise)``: the rewritten NLP; ``fatrop``: the rewritten NLP, FATROP with the same tolerance and iteration limit. Each
reports status, iterations, solve wall time, time per iteration, objective (of the one
objective expression, so comparable) and the largest constraint violation of gaitlib's own
constraints at the returned point. Writes ``benchmarks/results/fatrop.json`` and ``.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from dataclasses import replace
from datetime import datetime, timezone
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import casadi as ca  # noqa: E402
import numpy as np  # noqa: E402

from gaitlib import ocp  # noqa: E402
from gaitlib.collocation import integral_form  # noqa: E402
from gaitlib.problems import gait as gait_ocp  # noqa: E402
from report import machine_info, write_report  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
PRINT_LEVEL = 0
SPECS = {"SK": "Eq4.11", "MSK": "DT"}


def stagewise(tr: ocp.Transcription):
    """The transcription's NLP rewritten stage by stage for FATROP.

    Returns ``(nlp, perm, lbx, ubx, lbg, ubg, dims, x_of_w)``: ``nlp`` with the same objective
    expression; ``x_of_w(w)`` maps gaitlib's variable vector to the stage-wise one."""
    (ph,) = tr.problem.phases
    if tr.problem.parameters or tr.problem.linkages:
        raise NotImplementedError("stage-wise rewrite: problems with parameters or linkages")
    if any(gl.integrand is None for gl in ph.goals):
        raise NotImplementedError("stage-wise rewrite: endpoint goals (the objective must be stage-separable)")
    lay, mesh = tr.layouts[ph.name], tr.meshes[ph.name]
    if lay.it0 is not None or lay.itf is not None:
        raise NotImplementedError("stage-wise rewrite: free initial or final time")
    if mesh.scheme != "lgr" or mesh.lgr_side != "left":
        raise NotImplementedError("stage-wise rewrite: LGR collocation with the left convention only")
    sch = mesh.interval
    nx, nu, N = lay.nx, lay.nu, mesh.n_intervals
    _, M = integral_form(sch)  # X_{k,1..m} = X_{k,0} + h·dur·F Mᵀ
    m = M.shape[0]  # state nodes per interval minus one
    for i in range(N):  # each interval: state nodes i*m .. i*m+m, collocation nodes i*m .. i*m+m-1
        assert list(mesh.state_index[i]) == list(range(i * m, i * m + m + 1))
        assert list(mesh.colloc_index[i]) == list(range(i * m, i * m + m))

    w = ca.vertsplit(tr.w)
    p = tr.nlp["p"]
    t0, tf = float(ocp._lohi(ph.t0)[0]), float(ocp._lohi(ph.tf)[0])
    dur = tf - t0
    start, nd, nc = tr._data_slices[ph.name]
    D = ca.reshape(p[start:start + nd * nc], nd, nc)
    X = ca.horzcat(*[ca.vertcat(*[w[j] for j in lay.ix[:, k]]) for k in range(lay.ns)])
    U = ca.horzcat(*[ca.vertcat(*[w[j] for j in lay.iu[:, c]]) for c in range(lay.nc)])
    Xc = X[:, list(mesh.colloc_state_nodes)]
    Tc = t0 + dur * ca.DM(mesh.tau_colloc).T
    F, G, _ = tr._node_functions[ph.name].map(lay.nc)(Xc, U, ca.SX(0, 1), Tc, D)
    pc_lo, pc_hi = tr._path_bounds(ph)
    z = [ca.SX.sym(f"z{k}", nx) for k in range(N + 1)]

    # the endpoint rows of gaitlib's NLP, with x(0) read from the constant copy at the last stage
    end_rows, end_lo, end_hi = [], [], []
    for blk in tr.blocks:
        kind = blk.name.split("/", 1)[-1]
        if kind.startswith(("defects[", "path[")):
            continue
        end_rows.append(tr.g[blk.start:blk.start + blk.size])
        end_lo.append(tr.lbg[blk.start:blk.start + blk.size])
        end_hi.append(tr.ubg[blk.start:blk.start + blk.size])
    g_end = ca.substitute(ca.vertcat(*end_rows), X[:, 0], z[N])
    if ca.depends_on(g_end, ca.vertcat(*[X[:, k] for k in range(lay.ns - 1)])):
        raise NotImplementedError("stage-wise rewrite: an endpoint row reads an interior state node")

    xs, g, lbg, ubg, perm_w = [], [], [], [], []
    nxs, nus, ngs = [], [], []
    for k in range(N + 1):
        node0 = k * m
        xs += [X[:, node0], z[k]]
        perm_w += list(lay.ix[:, node0]) + [-1] * nx
        nxs.append(2 * nx)
        if k == N:
            nus.append(0)
            ngs.append(g_end.numel())
            g.append(g_end)
            lbg.append(np.concatenate(end_lo))
            ubg.append(np.concatenate(end_hi))
            break
        cols = list(range(k * m, k * m + m))
        for c in cols:
            xs.append(U[:, c])
            perm_w += list(lay.iu[:, c])
        for j in range(1, m):
            xs.append(X[:, node0 + j])
            perm_w += list(lay.ix[:, node0 + j])
        nus.append(m * nu + (m - 1) * nx)
        h = float(mesh.widths[k]) * dur
        Fk = F[:, cols]
        integ = [X[:, node0] + h * ca.mtimes(Fk, ca.DM(M[j - 1])) for j in range(1, m + 1)]
        # gap rows: x_{k+1} − Φ_k
        g.append(ca.vertcat(X[:, node0 + m] - integ[m - 1], z[k + 1] - z[k]))
        lbg.append(np.zeros(2 * nx))
        ubg.append(np.zeros(2 * nx))
        rows, lo, hi = [], [], []
        if k == 0:
            rows.append(z[0] - X[:, 0])
            lo.append(np.zeros(nx))
            hi.append(np.zeros(nx))
        for j in range(1, m):
            rows.append(X[:, node0 + j] - integ[j - 1])
            lo.append(np.zeros(nx))
            hi.append(np.zeros(nx))
        for c in cols:
            if G.size1():
                rows.append(G[:, c])
                lo.append(np.broadcast_to(pc_lo, (G.size1(),)))
                hi.append(np.broadcast_to(pc_hi, (G.size1(),)))
        gk = ca.vertcat(*rows)
        ngs.append(gk.numel())
        g.append(gk)
        lbg.append(np.concatenate(lo))
        ubg.append(np.concatenate(hi))

    x = ca.vertcat(*xs)
    perm_w = np.asarray(perm_w)
    n = x.numel()
    assert n == tr.n_variables + (N + 1) * nx, (n, tr.n_variables)
    z_pos = np.flatnonzero(perm_w < 0)
    first = np.asarray(lay.ix[:, 0])
    lbx = np.where(perm_w >= 0, tr.lbw[np.maximum(perm_w, 0)], -np.inf)
    ubx = np.where(perm_w >= 0, tr.ubw[np.maximum(perm_w, 0)], np.inf)

    def x_of_w(wv):
        wv = np.asarray(wv, float).ravel()
        out = np.where(perm_w >= 0, wv[np.maximum(perm_w, 0)], 0.0)
        out[z_pos] = np.tile(wv[first], N + 1)
        return out

    nlp = {"x": x, "f": tr.nlp["f"], "g": ca.vertcat(*g), "p": p}
    dims = {"N": N, "nx": nxs, "nu": nus, "ng": ngs}
    return nlp, perm_w, lbx, ubx, np.concatenate(lbg), np.concatenate(ubg), dims, x_of_w


def _violation(tr, wv, pvec):
    gv = np.asarray(ca.Function("g", [tr.w, tr.nlp["p"]], [tr.g])(wv, pvec)).ravel()
    return float(max(np.max(np.maximum(tr.lbg - gv, gv - tr.ubg), initial=0.0),
                     np.max(np.maximum(tr.lbw - wv, wv - tr.ubw), initial=0.0)))


def run_one(model: str, n_intervals: int, max_iter: int, fatrop_max_iter: int | None = None) -> list[dict]:
    spec = gait_ocp.GaitSpec(model=model, cost=SPECS[model], n_intervals=n_intervals)
    gp = gait_ocp.build(spec)
    opts = replace(gp.options, derivatives="graph", compiled=False, max_iter=max_iter)
    t = time.perf_counter()
    tr = ocp.transcribe(gp.problem, gp.mesh, opts)
    build_ipopt = time.perf_counter() - t
    w0 = np.clip(tr.initial_point(gp.guess), tr.lbw, tr.ubw)
    pvec = np.concatenate([tr.data_vector(), tr.goal_weights()])
    rows = []

    def record(name, status, it, solve_s, build_s, wsol, obj, extra=None):
        rows.append({"model": model, "cost": SPECS[model], "mesh": f"{n_intervals} x {gp.mesh.degree}",
                     "solver": name, "status": status, "iterations": int(it),
                     "build_s": round(build_s, 2), "solve_s": round(solve_s, 3),
                     "ms_per_iteration": round(1e3 * solve_s / max(int(it), 1), 2),
                     "objective": float(obj), "max_violation": _violation(tr, wsol, pvec), **(extra or {})})
        print(json.dumps(rows[-1]), flush=True)

    def solve_transcription(name, trx, build_s):
        t = time.perf_counter()
        r = trx.solver(x0=w0, lbx=trx.lbw, ubx=trx.ubw, lbg=trx.lbg, ubg=trx.ubg, p=pvec)
        st = trx.solver.stats()
        record(name, st["return_status"], st["iter_count"], time.perf_counter() - t, build_s,
               np.asarray(r["x"]).ravel(), r["f"], {"n_variables": trx.n_variables, "n_constraints": trx.n_constraints})

    solve_transcription("ipopt", tr, build_ipopt)
    # gaitlib's own NLP with the defects in integral form (the rewrite's rows, without its copy of x(0))
    t = time.perf_counter()
    tri = ocp.transcribe(gp.problem, replace(gp.mesh, defect_form="integral"), opts)
    solve_transcription("ipopt (integral form)", tri, time.perf_counter() - t)

    t = time.perf_counter()
    nlp, perm_w, lbx, ubx, lbg, ubg, dims, x_of_w = stagewise(tr)
    rewrite_s = time.perf_counter() - t
    x0 = x_of_w(w0)
    keep = perm_w >= 0

    def back(xv):
        wv = np.zeros(tr.n_variables)
        wv[perm_w[keep]] = np.asarray(xv, float).ravel()[keep]
        return wv

    extra_dims = {"N": dims["N"], "stage_nx": dims["nx"][0], "stage_nu": dims["nu"][0], "stage_ng": dims["ng"][1],
                  "n_variables": int(nlp["x"].numel()), "n_constraints": int(nlp["g"].numel())}
    t = time.perf_counter()
    ip = ca.nlpsol("stagewise_ipopt", "ipopt", nlp, opts.nlpsol_options())
    b = time.perf_counter() - t + rewrite_s
    t = time.perf_counter()
    r = ip(x0=x0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg, p=pvec)
    st = ip.stats()
    record("ipopt (stage-wise)", st["return_status"], st["iter_count"], time.perf_counter() - t, b,
           back(r["x"]), r["f"], extra_dims)

    fopts = {"structure_detection": "manual", **dims, "print_time": False,
             "fatrop": {"tol": opts.tol, "constr_viol_tol": opts.constr_viol_tol, "max_iter": fatrop_max_iter or max_iter,
                        "print_level": PRINT_LEVEL}}
    t = time.perf_counter()
    try:
        fs = ca.nlpsol("stagewise_fatrop", "fatrop", nlp, fopts)
    except RuntimeError as e:  # the structure it expects, said in its own words
        record("fatrop", f"not built: {str(e).splitlines()[-1][:200]}", 0, 0.0, time.perf_counter() - t + rewrite_s,
               w0, np.nan, extra_dims)
        return rows
    b = time.perf_counter() - t + rewrite_s
    t = time.perf_counter()
    r = fs(x0=x0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg, p=pvec)
    solve_s = time.perf_counter() - t
    st = fs.stats()
    it = int(st.get("iter_count", 0))
    limit = fopts["fatrop"]["max_iter"]
    status = ("Solve_Succeeded" if st.get("success") else
              "Maximum_Iterations_Exceeded" if it >= limit else f"failed (FATROP return flag {st.get('return_status')})")
    record("fatrop", status, it, solve_s, b, back(r["x"]), r["f"],
           {**extra_dims, "max_iter": limit, "fatrop_time_total": st.get("fatrop", {}).get("time_total"),
            "fatrop_compute_sd_time": st.get("fatrop", {}).get("compute_sd_time")})
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--models", nargs="+", default=["SK", "MSK"], choices=list(SPECS))
    ap.add_argument("--intervals", type=int, default=20)
    ap.add_argument("--max-iter", type=int, default=1000)
    ap.add_argument("--fatrop-max-iter", type=int, default=None,
                    help="FATROP's iteration limit (default --max-iter): its time per iteration is the floor")
    ap.add_argument("--fatrop-log", action="store_true", help="print FATROP's iteration log (stdout)")
    ap.add_argument("--quick", action="store_true", help="SK on 4 intervals (checks the script)")
    args = ap.parse_args(argv)
    global PRINT_LEVEL
    PRINT_LEVEL = 5 if args.fatrop_log else 0
    if args.quick:
        args.models, args.intervals, args.fatrop_max_iter = ["SK"], 4, 5
    started = datetime.now(timezone.utc).isoformat(timespec="seconds")
    load_start = list(os.getloadavg())
    rows = []
    for mdl in args.models:
        rows += run_one(mdl, args.intervals, args.max_iter, args.fatrop_max_iter)
    if args.quick:
        return rows
    machine = machine_info()
    meta = {"measured": started, "machine": machine, "load_average_start": load_start, "casadi": ca.__version__,
            "python": sys.version.split()[0],
            "command": "python benchmarks/bench_fatrop.py " + " ".join(argv if argv is not None else sys.argv[1:])}
    cols = ["model", "cost", "mesh", "solver", "status", "iterations", "build_s", "solve_s", "ms_per_iteration",
            "objective", "max_violation", "n_variables", "n_constraints"]
    lines = [f"# FATROP vs IPOPT + MUMPS on the natural-gait problems ({started}, {machine['cpu']}; load average "
             f"at start {load_start[0]:.2f})", "",
             f"`{meta['command']}`; casadi {meta['casadi']}, one BLAS thread. Method: the module docstring of "
             "`benchmarks/bench_fatrop.py`.", "",
             "| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        lines.append("| " + " | ".join(_fmt(r.get(c, "")) for c in cols) + " |")
    lines += ["", "Stage dimensions (FATROP's dense blocks): "
              + "; ".join(f"{r['model']}: N = {r['N']}, nx = {r['stage_nx']}, nu = {r['stage_nu']}, "
                          f"ng = {r['stage_ng']}" for r in rows if r["solver"] == "fatrop")]
    write_report(OUT, "fatrop", {"meta": meta, "rows": rows}, lines)
    return rows


def _fmt(v):
    if isinstance(v, float):
        return f"{v:.4g}" if abs(v) < 1e4 else f"{v:.3e}"
    return str(v)


if __name__ == "__main__":
    main()
