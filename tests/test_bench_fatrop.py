"""benchmarks/bench_fatrop.py rewrites gaitlib's LGR transcription stage by stage for FATROP:
the same equations under a non-singular linear map, the same objective, a layout FATROP accepts."""

from __future__ import annotations

from dataclasses import replace

import casadi as ca
import numpy as np
import pytest

import bench_fatrop as bf
from gaitlib import ocp
from gaitlib.problems import gait as gait_ocp


@pytest.fixture(scope="module")
def small():
    gp = gait_ocp.build(gait_ocp.GaitSpec(model="SK", cost="Eq4.11", n_intervals=4, degree=2))
    tr = ocp.transcribe(gp.problem, gp.mesh, replace(gp.options, derivatives="graph", compiled=False))
    return gp, tr, bf.stagewise(tr)


def _rows(tr, sw):
    """Stage-wise rows as numbers at a point of gaitlib's variables: (gap rows, interior rows) per
    interval, by the layout the rewrite declares."""
    nlp, _, _, _, _, _, dims, x_of_w = sw
    gfun = ca.Function("g", [nlp["x"], nlp["p"]], [nlp["g"], nlp["f"]])
    nx = dims["nx"][0] // 2
    m = tr.meshes["cycle"].interval.A.shape[1] - 1

    def at(w, p):
        g, f = gfun(x_of_w(w), p)
        g = np.asarray(g).ravel()
        out, r = [], 0
        for k in range(dims["N"]):
            gap = g[r:r + nx]
            r += 2 * nx
            s = r + (nx if k == 0 else 0)
            interior = g[s:s + (m - 1) * nx].reshape(m - 1, nx)
            out.append(np.vstack([interior, gap]))
            r += dims["ng"][k]
        return out, float(f)
    return at


def test_the_rewrite_is_the_defects_under_the_inverse_of_their_end_columns(small):
    """At any point (random here), each interval's rewritten rows equal Â⁻¹ times gaitlib's
    defect rows (Â: the differentiation matrix without its first column), the objective is the
    same, and the copy of x(0) the rewrite adds is constant."""
    gp, tr, sw = small
    A = np.asarray(tr.meshes["cycle"].interval.A, float)
    rng = np.random.default_rng(3)
    lo, hi = np.maximum(tr.lbw, -1.0), np.minimum(tr.ubw, 1.0)
    w = lo + (hi - lo) * rng.random(tr.n_variables)
    p = np.concatenate([tr.data_vector(), tr.goal_weights()])
    g = np.asarray(ca.Function("g", [tr.w, tr.nlp["p"]], [tr.g])(w, p)).ravel()
    f = float(ca.Function("f", [tr.w, tr.nlp["p"]], [tr.nlp["f"]])(w, p))
    rows, f_sw = _rows(tr, sw)(w, p)
    nx = len(gp.problem.phases[0].states)
    defect_blocks = [b for b in tr.blocks if "/defects[" in b.name]
    assert len(defect_blocks) == len(rows) == 4
    for blk, got in zip(defect_blocks, rows):
        d = g[blk.start:blk.start + blk.size].reshape(-1, nx)  # one row per defect, states along
        want = np.linalg.solve(A[:, 1:], d)
        assert np.allclose(got, want, rtol=1e-9, atol=1e-9 * max(1.0, np.abs(want).max()))
    assert f_sw == pytest.approx(f, rel=1e-12)


def test_every_other_row_and_bound_is_gaitlibs(small):
    """At any point, the rewrite's remaining rows are gaitlib's path and endpoint rows in
    gaitlib's order, with the same bounds; the rows of the added copy of x(0) vanish; the
    variable bounds are gaitlib's, permuted (the copy free)."""
    gp, tr, sw = small
    nlp, perm_w, lbx, ubx, lbg, ubg, dims, x_of_w = sw
    rng = np.random.default_rng(5)
    lo, hi = np.maximum(tr.lbw, -1.0), np.minimum(tr.ubw, 1.0)
    w = lo + (hi - lo) * rng.random(tr.n_variables)
    p = np.concatenate([tr.data_vector(), tr.goal_weights()])
    g = np.asarray(ca.Function("g", [tr.w, tr.nlp["p"]], [tr.g])(w, p)).ravel()
    gs = np.asarray(ca.Function("g", [nlp["x"], nlp["p"]], [nlp["g"]])(x_of_w(w), p)).ravel()
    nx = dims["nx"][0] // 2
    m = tr.meshes["cycle"].interval.A.shape[1] - 1
    other, zero, r = [], [], 0
    for k in range(dims["N"]):
        zero.append(np.arange(r + nx, r + 2 * nx))  # z_{k+1} − z_k
        r += 2 * nx
        if k == 0:
            zero.append(np.arange(r, r + nx))  # z_0 − x(0)
        s = r + (nx if k == 0 else 0) + (m - 1) * nx
        other.append(np.arange(s, r + dims["ng"][k]))
        r += dims["ng"][k]
    other.append(np.arange(r, r + dims["ng"][-1]))
    other, zero = np.concatenate(other), np.concatenate(zero)
    keep = np.concatenate([np.arange(b.start, b.start + b.size) for b in tr.blocks if "/defects[" not in b.name])
    assert other.size == keep.size and other.size + zero.size + sum(
        b.size for b in tr.blocks if "/defects[" in b.name) == gs.size
    assert np.allclose(gs[other], g[keep], rtol=1e-12, atol=1e-12)
    assert np.array_equal(lbg[other], tr.lbg[keep]) and np.array_equal(ubg[other], tr.ubg[keep])
    assert np.all(gs[zero] == 0.0)
    mine = perm_w >= 0
    assert np.array_equal(lbx[mine], tr.lbw[perm_w[mine]]) and np.array_equal(ubx[mine], tr.ubw[perm_w[mine]])
    assert np.all(np.isinf(lbx[~mine])) and np.all(np.isinf(ubx[~mine]))
    assert np.array_equal(np.sort(perm_w[mine]), np.arange(tr.n_variables))
    assert sum(dims["nx"]) + sum(dims["nu"]) == nlp["x"].numel()
    assert sum(dims["nx"][1:]) + sum(dims["ng"]) == nlp["g"].numel()


def test_fatrop_accepts_the_layout(small):
    """FATROP checks the declared stage structure against the Jacobian's pattern (and that
    the next state enters each gap row with coefficient +1) when it is built."""
    _, _, (nlp, *_, dims, _x) = small
    ca.nlpsol("s", "fatrop", nlp, {"structure_detection": "manual", **dims,
                                   "fatrop": {"max_iter": 1, "print_level": 0}})
