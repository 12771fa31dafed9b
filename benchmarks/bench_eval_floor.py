"""How fast could the MSK solve be on its own iteration path? (the ≤ 20 s target of the MSK solve)

    .venv/bin/python benchmarks/bench_eval_floor.py           # MSK 20 × 5, ≈ 3 min (gcc -O2 of one node)
    .venv/bin/python benchmarks/bench_eval_floor.py --quick   # MSK 4 × 3, -O1 (checks the script)

``bench_msk_profile.py`` splits the book's MSK natural-gait solve (Eq 5.33, 20 × 5) into the
Lagrangian Hessian, the other evaluations, IPOPT's linear systems (MUMPS) and the rest. This
script asks what the function evaluations would cost if they were compiled C instead of
CasADi's SX virtual machine, and therefore what the solve time would be at best on the
*same* iteration path (same iterations, same factorisations — only evaluations faster):

1. At the data-based initial point (Lagrange multipliers drawn at random, fixed seed), the
   solver's own functions are timed, each the median of 15 calls: ``nlp_hess_l``,
   ``nlp_jac_g``, ``nlp_g``, ``nlp_f``, ``nlp_grad_f`` (one SX graph each, as the book runs them).
2. The per-node function ``node(x, u, p, t, d) → (ẋ, path, integrand)`` the transcription
   maps over the collocation nodes is differentiated per node: the Hessian of
   μᵀẋ + νᵀpath + aᵀintegrand with respect to (x, u) and the Jacobian of its outputs. Every
   non-linear term of the NLP's Lagrangian is one of these per-node terms (the collocation
   defects, the periodicity and the quadrature of the cost are linear in the node values),
   so the global Hessian is their sum over the nodes, placed into (x_k, u_k) blocks (checked
   here on the solver's Hessian pattern: no non-zero outside those blocks). The
   two per-node functions are generated as C, compiled with gcc (timed) and evaluated at
   every collocation node in one mapped call (median of 15); the SX virtual machine on the
   same mapped call is timed beside it. The C code gives the same numbers as the SX
   virtual machine to round-off (checked here, relative 1e-12).
3. With the default run of ``results/msk_profile.json`` (iterations, Hessian, other
   evaluations, linear systems, rest), three floors of the solve time on that path:
   *evaluations free* (linear systems + rest), *Hessian compiled* (the others as measured),
   *all evaluations compiled* (every evaluation scaled by the measured C/VM ratio of the
   Hessian). The cost of assembling per-node blocks into IPOPT's sparse Hessian is left
   out (not implemented), so these are lower bounds.

4. The compiled per-node Hessian is then assembled into the exact Hessian of the Lagrangian
   and given to IPOPT (``nlpsol`` option ``hess_lag``); the book's problem is solved from
   the same start with the book's solver and with this one, one after the other. The
   per-node multipliers (μ, ν, a) are the gradient of the Lagrangian with respect to the
   node values, taken on a copy of the NLP whose node function returns extra NLP
   parameters instead of computing ẋ, path and integrand (:class:`Passthrough`); the
   script checks that they depend on neither the variables nor the data, that this copy's
   Lagrangian has no Hessian of its own (every non-linear term is a node's), and that the
   assembled Hessian equals the solver's own at a random point (relative 1e-12).

Steps 1–3 measure costs; step 4 is a real solve with a compiled exact Hessian, kept in this
benchmark (gaitlib's solver does not use it). Writes ``benchmarks/results/eval_floor.json``
and ``eval_floor.md``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

from gaitlib import blas

blas.pin()  # the Makefile's BLAS settings (unless set), before numpy is imported

import numpy as np  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
REPEATS = 15
TARGET_S = 20.0


def _median_ms(fun, args, repeats=REPEATS) -> float:
    fun(*args)
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fun(*args)
        ts.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(ts))


def per_node_functions(node):
    """Per-node Hessian of the node Lagrangian (upper triangle) and Jacobian of the outputs."""
    import casadi as ca

    x, u, p, t, d = (ca.SX.sym(n, node.size1_in(i)) for i, n in enumerate(("x", "u", "p", "t", "d")))
    F, G, L = node(x, u, p, t, d)
    mu, nu, a = ca.SX.sym("mu", F.numel()), ca.SX.sym("nu", G.numel()), ca.SX.sym("a", L.numel())
    z = ca.vertcat(x, u)
    lag = ca.dot(mu, F) + ca.dot(nu, G) + ca.dot(a, L)
    hess = ca.Function("gl_node_hess", [x, u, p, t, d, mu, nu, a], [ca.triu(ca.hessian(lag, z)[0])])
    Y = ca.vertcat(F, G, L)
    jac = ca.Function("gl_node_jac", [x, u, p, t, d], [Y, ca.jacobian(Y, z)])
    return hess, jac


def node_variables(lay, mesh) -> list[np.ndarray]:
    """NLP indices of each collocation node's (x_k, u_k), in the per-node functions' order."""
    return [np.concatenate([lay.ix[:, k], lay.iu[:, c]]) for c, k in enumerate(mesh.colloc_state_nodes)]


def hessian_blocks(H, lay, mesh) -> dict:
    """Check that the NLP Hessian's pattern ``H`` is block-diagonal in the collocation nodes'
    (x_k, u_k) blocks — what makes it the sum of the per-node Hessians."""
    block = np.full(H.size1(), -1)
    for c, z in enumerate(node_variables(lay, mesh)):
        block[z] = c
    rows, cols = np.asarray(H.get_triplet()[0]), np.asarray(H.get_triplet()[1])
    same = (block[rows] == block[cols]) & (block[rows] >= 0)
    per_block = np.bincount(block[rows][same], minlength=len(mesh.colloc_state_nodes))
    return {"hessian_nnz": int(H.nnz()), "hessian_nnz_outside_node_blocks": int((~same).sum()),
            "hessian_nnz_per_node_block_max": int(per_block.max())}


def node_inputs(nlp, ph, w, p):
    """The per-node function's inputs (x, u, p, t, d) at every collocation node, one column per
    node, taken from the NLP variables ``w`` and parameters ``p`` (DM or MX). Fixed phase
    times only (the natural-gait problems)."""
    import casadi as ca

    from gaitlib import ocp

    lay, mesh = nlp.layouts[ph.name], nlp.meshes[ph.name]
    if not (lay.t0_fixed and lay.tf_fixed):
        raise ValueError(f"phase {ph.name!r}: free start or end time; this benchmark needs fixed times")
    nc, cols = lay.nc, list(mesh.colloc_state_nodes)
    Xc = ca.reshape(w[[int(i) for i in lay.ix[:, cols].ravel(order="F")]], lay.ix.shape[0], nc)
    U = ca.reshape(w[[int(i) for i in lay.iu.ravel(order="F")]], lay.iu.shape[0], nc)
    s0, nd, _ = nlp._data_slices[ph.name]
    D = ca.reshape(p[s0:s0 + nd * nc], nd, nc)
    t0, tf = float(ocp._lohi(ph.t0)[0]), float(ocp._lohi(ph.tf)[0])
    Tc = ca.DM((t0 + (tf - t0) * np.asarray(mesh.tau_colloc)).reshape(1, -1))
    P = ca.DM.zeros(nlp._node_functions[ph.name].size1_in(2), nc)
    return Xc, U, P, Tc, D


def _passthrough_class(node_sizes, path_sizes):
    """A :class:`gaitlib.ocp.Transcription` whose node function returns its last data
    channels (``n_F + n_G + n_L`` of them) as (ẋ, path, integrand)."""
    import casadi as ca

    from gaitlib import ocp

    nF, nG, nL = node_sizes
    nY = nF + nG + nL

    class Passthrough(ocp.Transcription):
        def _node_function(self, ph, n_p):
            nd = len(ph.data_names)
            x, u, p, t, d = (ca.SX.sym("x", len(ph.states)), ca.SX.sym("u", len(ph.controls)),
                             ca.SX.sym("p", n_p), ca.SX.sym("t"), ca.SX.sym("d", nd))
            y = d[nd - nY:]
            self._path_sizes[ph.name] = path_sizes
            return ca.Function(f"{ph.name}_passthrough", [x, u, p, t, d], [y[:nF], y[nF:nF + nG], y[nF + nG:]])

    return Passthrough


def compiled_hessian(nlp, gp, hess, hess_c):
    """The exact Hessian of ``nlp``'s Lagrangian assembled from the compiled per-node Hessian
    ``hess_c`` (an MX Function with the signature of IPOPT's ``nlp_hess_l``)."""
    import casadi as ca
    import pandas as pd

    (ph,) = gp.problem.phases
    node = nlp._node_functions[ph.name]
    nF, nG, nL = (node.size1_out(i) for i in range(3))
    nY = nF + nG + nL
    extra = pd.DataFrame(0.0, index=ph.data.index, columns=[f"__node_output_{i}" for i in range(nY)])
    ph2 = dataclasses.replace(ph, data=pd.concat([ph.data, extra], axis=1))
    pt = _passthrough_class((nF, nG, nL), nlp._path_sizes[ph.name])(
        dataclasses.replace(gp.problem, phases=(ph2,)), gp.mesh, gp.options)
    if (pt.n_variables, pt.n_constraints) != (nlp.n_variables, nlp.n_constraints):
        raise AssertionError("the passthrough NLP has another layout")
    w2, p2, f2, g2 = pt.nlp["x"], pt.nlp["p"], pt.nlp["f"], pt.nlp["g"]
    lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", g2.shape[0])
    lag2 = lam_f * f2 + ca.dot(lam_g, g2)
    start, nd_ext, nc = pt._data_slices[ph.name]
    ypos = [start + c * nd_ext + nd_ext - nY + j for c in range(nc) for j in range(nY)]
    ybar = ca.gradient(lag2, p2)[ypos]
    if ca.depends_on(ybar, w2) or ca.depends_on(ybar, p2[:pt._n_pdata]):
        raise AssertionError("node multipliers depend on the variables or the data (free time?)")
    if ca.hessian(lag2, w2)[0].nnz():
        raise AssertionError("the Lagrangian has non-linear terms outside the nodes")
    ybar_fun = ca.Function("node_multipliers", [p2[pt._n_pdata:], lam_f, lam_g], [ca.reshape(ybar, nY, nc)])

    X, P = ca.MX.sym("x", nlp.n_variables), ca.MX.sym("p", nlp.nlp["p"].shape[0])
    LF, LG = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", nlp.n_constraints)
    YB = ybar_fun(P[nlp._n_pdata:], LF, LG)
    Hb = hess_c.map(nc)(*node_inputs(nlp, ph, X, P), YB[:nF, :], YB[nF:nF + nG, :], YB[nF + nG:, :])
    br, bc = (np.asarray(v) for v in hess.sparsity_out(0).get_triplet())
    zs = node_variables(nlp.layouts[ph.name], nlp.meshes[ph.name])
    rows, colg = np.concatenate([z[br] for z in zs]), np.concatenate([z[bc] for z in zs])
    if np.any(rows > colg):
        raise AssertionError("node blocks are not upper-triangular in the NLP's variable order")
    sp = ca.Sparsity.triplet(nlp.n_variables, nlp.n_variables, rows.tolist(), colg.tolist())
    order = np.lexsort((rows, colg))  # compressed-column order of the assembled pattern
    H = ca.sparsity_cast(Hb.nz[:][order.tolist()], sp)
    return ca.Function("nlp_hess_l", [X, P, LF, LG], [H], ["x", "p", "lam_f", "lam_g"], ["triu_hess_gamma_x_x"])


def solve_both(nlp, w0, pv, hess_lag, options) -> dict:
    """Check ``hess_lag`` against the solver's Hessian at ``w0`` (parameters ``pv``), then
    solve from ``w0`` with the book's solver and with one using ``hess_lag``."""
    import casadi as ca

    lg = np.random.default_rng(1).normal(size=nlp.n_constraints)
    h_ref = nlp.solver.get_function("nlp_hess_l")
    a, b = ca.DM(h_ref(w0, pv, 0.7, lg)), ca.DM(hess_lag(w0, pv, 0.7, lg))
    if a.sparsity() != b.sparsity():
        raise AssertionError("assembled Hessian has another pattern than the solver's")
    an, bn = np.asarray(a.nonzeros()), np.asarray(b.nonzeros())
    rel = float(np.max(np.abs(an - bn)) / np.max(np.abs(an)))
    if rel > 1e-12:
        raise AssertionError(f"assembled Hessian differs from the solver's: {rel:.2e}")
    out = {"hessian_check_max_rel_diff": rel,
           "hessian_ms": {"solver": _median_ms(h_ref, [w0, pv, 0.7, lg]),
                          "assembled_compiled": _median_ms(hess_lag, [w0, pv, 0.7, lg])}, "solves": []}
    compiled = ca.nlpsol("compiled_hessian", "ipopt", nlp.nlp, {**options.nlpsol_options(), "hess_lag": hess_lag})
    for name, solver in (("book (SX Hessian)", nlp.solver), ("compiled per-node Hessian", compiled)):
        t0 = time.perf_counter()
        r = solver(x0=w0, lbx=nlp.lbw, ubx=nlp.ubw, lbg=nlp.lbg, ubg=nlp.ubg, p=pv)
        dt = time.perf_counter() - t0
        st = solver.stats()
        out["solves"].append({"solver": name, "status": st["return_status"], "iterations": int(st["iter_count"]),
                              "solve_s": dt, "ms_per_iteration": 1e3 * dt / max(int(st["iter_count"]), 1),
                              "objective": float(r["f"])})
        print(f"{name}: {st['return_status']}, {st['iter_count']} it, {dt:.1f} s, objective {float(r['f']):.4f}",
              flush=True)
    return out


def compile_c(funs, opt: str, workdir: Path) -> tuple[list, float]:
    """Generate C for ``funs``, compile with gcc ``opt``; the loaded externals and compile seconds."""
    import casadi as ca

    cg = ca.CodeGenerator("gl_nodes.c", {"with_header": False})
    for f in funs:
        cg.add(f)
    cg.generate(str(workdir) + os.sep)
    so = workdir / "gl_nodes.so"
    t0 = time.perf_counter()
    subprocess.run(["gcc", "-fPIC", "-shared", opt, str(workdir / "gl_nodes.c"), "-o", str(so)], check=True)
    dt = time.perf_counter() - t0
    return [ca.external(f.name(), str(so)) for f in funs], dt


def measure(quick: bool) -> dict:
    import casadi as ca

    from gaitlib import ocp
    from gaitlib.problems import gait as gait_ocp
    from gaitlib.studies import gait

    spec = gait.natural_gait_spec("MSK")
    if quick:
        spec = dataclasses.replace(spec, n_intervals=4, degree=3)
    gp = gait_ocp.build(spec)
    t0 = time.perf_counter()
    nlp = ocp.transcribe(gp.problem, gp.mesh, gp.options)
    build_s = time.perf_counter() - t0
    (ph,) = gp.problem.phases
    lay, mesh = nlp.layouts[ph.name], nlp.meshes[ph.name]
    node = nlp._node_functions[ph.name]
    rng = np.random.default_rng(0)

    # 1. the solver's own functions at the initial point
    w0 = np.clip(nlp.initial_point(gp.guess), nlp.lbw, nlp.ubw)
    pv = np.concatenate([nlp.data_vector(), nlp.goal_weights()])
    lam_g = rng.normal(size=nlp.n_constraints)
    s = nlp.solver
    solver_ms = {
        "nlp_hess_l": _median_ms(s.get_function("nlp_hess_l"), [w0, pv, 1.0, lam_g]),
        "nlp_jac_g": _median_ms(s.get_function("nlp_jac_g"), [w0, pv]),
        "nlp_g": _median_ms(s.get_function("nlp_g"), [w0, pv]),
        "nlp_f": _median_ms(s.get_function("nlp_f"), [w0, pv]),
        "nlp_grad_f": _median_ms(s.get_function("nlp_grad_f"), [w0, pv]),
    }
    hess_instr = int(s.get_function("nlp_hess_l").n_instructions())
    blocks = hessian_blocks(s.get_function("nlp_hess_l").sparsity_out(0), lay, mesh)

    # 2. per-node derivatives: SX virtual machine vs compiled C, one mapped call over the nodes
    nc = lay.nc
    inputs = list(node_inputs(nlp, ph, ca.DM(w0), ca.DM(pv)))
    hess, jac = per_node_functions(node)
    mult = [rng.normal(size=(hess.size1_in(k), nc)) for k in (5, 6, 7)]
    h_args, j_args = inputs + mult, inputs
    opt = "-O1" if quick else "-O2"
    with tempfile.TemporaryDirectory() as tmp:
        (hess_c, jac_c), compile_s = compile_c([hess, jac], opt, Path(tmp))
        vm = {"hessian": _median_ms(hess.map(nc), h_args), "jacobian": _median_ms(jac.map(nc), j_args)}
        cc = {"hessian": _median_ms(hess_c.map(nc), h_args), "jacobian": _median_ms(jac_c.map(nc), j_args)}
        hv, hc = np.asarray(hess.map(nc)(*h_args)), np.asarray(hess_c.map(nc)(*h_args))
        rel = float(np.max(np.abs(hv - hc)) / max(np.max(np.abs(hv)), 1e-300))
        solve = solve_both(nlp, w0, pv, compiled_hessian(nlp, gp, hess, hess_c), gp.options)
    if m_blocks := blocks["hessian_nnz_outside_node_blocks"]:
        raise AssertionError(f"{m_blocks} Hessian non-zeros couple different nodes: not a sum of per-node Hessians")
    if rel > 1e-12:
        raise AssertionError(f"compiled per-node Hessian differs from the SX virtual machine: {rel:.2e}")
    return {
        "n_intervals": spec.n_intervals, "degree": spec.degree, "collocation_nodes": nc,
        "n_variables": int(nlp.n_variables), "build_s": build_s,
        "solver_function_ms": solver_ms, "solver_hessian_instructions": hess_instr,
        **blocks, "node_hessian_nnz": int(hess.sparsity_out(0).nnz()),
        "node_hessian_instructions": int(hess.n_instructions()),
        "node_jacobian_instructions": int(jac.n_instructions()),
        "nodes_x_node_hessian_instructions": int(hess.n_instructions()) * nc,
        "mapped_vm_ms": vm, "mapped_compiled_ms": cc, "gcc": opt, "compile_s": compile_s,
        "compiled_vs_vm_max_rel_diff": rel, "compiled_solve": solve,
    }


def floors(m: dict, profile: dict) -> dict:
    """Lower bounds of the solve time on the default run's path (seconds)."""
    d = next(r for r in profile["runs"] if r["variant"] == "default")
    its = d["iterations"]
    base = d["linear_systems_s"] + d["rest_s"]
    ratio = m["mapped_compiled_ms"]["hessian"] / m["solver_function_ms"]["nlp_hess_l"]
    return {
        "profile_measured": profile["measured"], "iterations": its, "solve_s": d["solve_s"],
        "evaluations_s": d["hessian_s"] + d["other_evals_s"], "linear_systems_s": d["linear_systems_s"],
        "rest_s": d["rest_s"], "compiled_to_vm_hessian_ratio": ratio,
        "floor_evaluations_free_s": base,
        "floor_hessian_compiled_s": base + d["other_evals_s"] + its * m["mapped_compiled_ms"]["hessian"] / 1e3,
        "floor_all_compiled_s": base + (d["hessian_s"] + d["other_evals_s"]) * ratio,
        "evaluation_budget_ms_per_iteration": 1e3 * (TARGET_S - base) / its,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    load = os.getloadavg()[0]
    m = measure(args.quick)
    prof_path = OUT / "msk_profile.json"
    profile = json.loads(prof_path.read_text())
    fl = floors(m, profile) if not args.quick else None
    doc = {"measured": datetime.now(timezone.utc).isoformat(timespec="seconds"),
           "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
           "load_at_start": load, "code": __import__("gaitlib.cache").cache.fingerprint(),
           "quick": args.quick, **m, "floors": fl}
    from report import md_table, write_report

    sm, vm, cc = m["solver_function_ms"], m["mapped_vm_ms"], m["mapped_compiled_ms"]
    md = [f"# MSK {m['n_intervals']} × {m['degree']}: evaluation cost, SX virtual machine vs compiled C "
          f"({doc['measured']}, {doc['machine']}, load {load:.2f})", "",
          "The solver's own functions at the data-based initial point (ms per call, median of "
          f"{REPEATS}):", "", "| " + " | ".join(sm) + " |", "|" + "---|" * len(sm),
          "| " + " | ".join(f"{v:.2f}" for v in sm.values()) + " |", "",
          f"Per-node derivatives mapped over the {m['collocation_nodes']} collocation nodes (ms per mapped call; "
          f"C compiled with gcc {m['gcc']} in {m['compile_s']:.0f} s; largest relative difference C vs VM "
          f"{m['compiled_vs_vm_max_rel_diff']:.1e}):", "",
          "| | SX instructions per node | × nodes | SX virtual machine | compiled C |", "|---|---|---|---|---|",
          f"| Hessian of the node Lagrangian ({m['node_hessian_nnz']} non-zeros; solver's Hessian "
          f"{m['hessian_nnz']:,}, none outside the node blocks, at most {m['hessian_nnz_per_node_block_max']} per block) | "
          f"{m['node_hessian_instructions']:,} | "
          f"{m['nodes_x_node_hessian_instructions']:,} (solver's nlp_hess_l: {m['solver_hessian_instructions']:,}) | "
          f"{vm['hessian']:.2f} | {cc['hessian']:.2f} |",
          f"| Jacobian of the node outputs | {m['node_jacobian_instructions']:,} | — | {vm['jacobian']:.2f} | "
          f"{cc['jacobian']:.2f} |"]
    cs = m["compiled_solve"]
    md += ["", f"The compiled per-node Hessian assembled into IPOPT's exact Hessian (`hess_lag`): equal to the "
           f"solver's to {cs['hessian_check_max_rel_diff']:.1e} (relative), {cs['hessian_ms']['assembled_compiled']:.2f} "
           f"ms per call against {cs['hessian_ms']['solver']:.2f} ms. Solved from the same start, one after the other:", ""]
    md += md_table(["solver", "status", "iterations", "solve_s", "ms_per_iteration", "objective"], cs["solves"])
    if fl:
        md += ["", f"Floors of the solve time on the default run's path ({fl['iterations']} iterations; "
               f"`msk_profile.json` of {fl['profile_measured']}: solve {fl['solve_s']:.1f} s = evaluations "
               f"{fl['evaluations_s']:.1f} + linear systems {fl['linear_systems_s']:.1f} + rest {fl['rest_s']:.1f}):", "",
               "| assumption | solve time at best (s) | target |", "|---|---|---|",
               f"| evaluations free | {fl['floor_evaluations_free_s']:.1f} | {TARGET_S:.0f} |",
               f"| Hessian compiled (C/VM {fl['compiled_to_vm_hessian_ratio']:.2f}), other evaluations as measured | "
               f"{fl['floor_hessian_compiled_s']:.1f} | {TARGET_S:.0f} |",
               f"| every evaluation at the Hessian's C/VM ratio | {fl['floor_all_compiled_s']:.1f} | {TARGET_S:.0f} |",
               "", f"To reach {TARGET_S:.0f} s on this path, all evaluations together would have to cost "
               f"≤ {fl['evaluation_budget_ms_per_iteration']:.1f} ms per iteration (assembly excluded)."]
    write_report(OUT, "eval_floor_quick" if args.quick else "eval_floor", doc, md)
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
