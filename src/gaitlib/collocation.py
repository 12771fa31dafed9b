"""Direct-collocation schemes and meshes on normalised time τ ∈ [0, 1].

This module knows nothing about optimal control problems: it turns a scheme name and a
mesh into numbers — node positions, differentiation/defect matrices, quadrature weights —
and builds the (linear in the states, linear in the dynamics) defect constraints for
symbolic CasADi matrices. :mod:`gaitlib.ocp` uses it to transcribe a problem.

Symbol legend
-------------
N      number of mesh intervals
d      collocation degree of the LGR scheme (points per interval)
m      state nodes per interval, without the interval's start (LGR: d, trapezoidal: 1,
       Hermite–Simpson: 2); consecutive intervals share their boundary node
n_s    number of state nodes on [0, 1]:  N m + 1
n_c    number of collocation nodes (where controls live and the dynamics, path
       constraints and integrands are evaluated)
n_x    number of states
τ      normalised time; absolute time t = t0 + (tf − t0) τ
h_i    width of interval i in τ (the mesh fractions, summing to 1)

Schemes
-------
``"lgr"`` (Legendre–Gauss–Radau orthogonal collocation, the scheme of GPOPS-II)
    The state is a degree-d polynomial per interval through d + 1 nodes: the d LGR
    points plus the one non-collocated interval end. ``lgr_side="left"`` (default) is
    GPOPS-II's convention: the LGR points include the interval *start* (τ̃ = −1 in
    [−1, 1]) and the end point is not collocated, so controls exist at every state node
    except the very last one. ``lgr_side="right"`` is the flipped set that
    ``casadi.collocation_points(d, "radau")`` returns (Radau IIA: collocated at the
    interval *end*; no control at τ = 0). Both are exact for state polynomials of degree
    ≤ d and integrate polynomials of degree ≤ 2d − 2 exactly; the differentiation
    matrix is the derivative of the Lagrange basis on the d + 1 nodes evaluated at the d
    collocation points (Garg et al. 2010, Patterson & Rao 2014).
``"trapezoidal"``
    Nodes at interval ends; x₁ − x₀ = h/2 (f₀ + f₁); controls at every node.
``"hermite-simpson"`` (*separated* form, as in OpenSim Moco)
    Nodes at interval ends and midpoints, all of them NLP variables (states and
    controls at the midpoint too). Two defects per interval:
    Simpson  x₁ − x₀ − h/6 (f₀ + 4 f_m + f₁) = 0 and
    Hermite  x_m − (x₀ + x₁)/2 − h/8 (f₀ − f₁) = 0.
    ``hs_control_midpoints="interpolate"`` adds u_m = (u₀ + u₁)/2 (Moco's default);
    ``"free"`` leaves the midpoint control free.

All schemes are written in one form. For interval i with state nodes X_i (n_x × (m+1))
and the dynamics F_i evaluated at its collocation nodes (n_x × c),

    defect_i = X_i Aᵀ − h_i (tf − t0) F_i Bᵀ = 0        (n_x × n_def)

with constant A (n_def × (m+1)) and B (n_def × c); ∫ L dt over the interval is
h_i (tf − t0) w · L_i.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import casadi as ca
import numpy as np

SCHEMES = ("lgr", "trapezoidal", "hermite-simpson")
DEFECT_FORMS = ("differential", "integral")

__all__ = [
    "SCHEMES",
    "DEFECT_FORMS",
    "integral_form",
    "Mesh",
    "Scheme",
    "differentiation_matrix",
    "lagrange_basis",
    "lgr_points",
    "lgr_weights",
    "lgr_scheme",
    "make_scheme",
]


# --------------------------------------------------------------------------------------
# Polynomial helpers
# --------------------------------------------------------------------------------------
def lagrange_basis(nodes: np.ndarray) -> list[np.polynomial.Polynomial]:
    """Lagrange basis polynomials ℓ_j(τ) on ``nodes`` (ℓ_j(τ_k) = δ_jk)."""
    nodes = np.asarray(nodes, dtype=float)
    basis = []
    for j, tj in enumerate(nodes):
        p = np.polynomial.Polynomial.fromroots(np.delete(nodes, j))
        basis.append(p / p(tj))
    return basis


def differentiation_matrix(nodes: np.ndarray) -> np.ndarray:
    """``D[k, j] = ℓ_j'(τ_k)`` on ``nodes`` (barycentric formula, Berrut & Trefethen 2004).

    Shape (n, n) for n nodes; exact for polynomials of degree ≤ n − 1.
    """
    t = np.asarray(nodes, dtype=float)
    diff = t[:, None] - t[None, :]
    np.fill_diagonal(diff, 1.0)
    bw = 1.0 / np.prod(diff, axis=1)  # barycentric weights
    D = (bw[None, :] / bw[:, None]) / diff
    np.fill_diagonal(D, 0.0)
    np.fill_diagonal(D, -D.sum(axis=1))
    return D


def lgr_points(d: int, side: str = "left") -> np.ndarray:
    """The d Legendre–Gauss–Radau points mapped to [0, 1].

    ``side="right"`` gives ``casadi.collocation_points(d, "radau")`` (includes τ = 1);
    ``side="left"`` is its mirror image 1 − τ (includes τ = 0, GPOPS-II's convention).
    """
    if d < 1:
        raise ValueError(f"LGR degree must be >= 1, got {d}")
    right = np.array(ca.collocation_points(d, "radau"), dtype=float)
    if side == "right":
        return right
    if side == "left":
        return np.sort(1.0 - right)
    raise ValueError(f"lgr side must be 'left' or 'right', got {side!r}")


def lgr_weights(d: int, side: str = "left") -> np.ndarray:
    """Radau quadrature weights for :func:`lgr_points` on [0, 1] (they sum to 1).

    On [−1, 1] with the fixed point at −1: w₀ = 2/d², w_k = (1 − x_k)/(d P_{d−1}(x_k))²
    (Abramowitz & Stegun 25.4.31); halved for [0, 1], mirrored for ``side="right"``.
    """
    x = 2.0 * lgr_points(d, "left") - 1.0
    P = np.polynomial.legendre.Legendre.basis(d - 1)(x)
    w = (1.0 - x) / (d * P) ** 2
    w[0] = 2.0 / d**2
    w = 0.5 * w
    return w if side == "left" else w[::-1].copy()


# --------------------------------------------------------------------------------------
# Schemes on one interval
# --------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Scheme:
    """One interval of a collocation scheme on τ̂ ∈ [0, 1] (all arrays constant).

    Attributes
    ----------
    name : str
    nodes : ndarray, shape (m + 1,)
        Local state nodes, ``nodes[0] = 0``, ``nodes[-1] = 1``.
    colloc : ndarray of int, shape (c,)
        Which of ``nodes`` are collocation nodes (controls, dynamics, path constraints).
    A : ndarray, shape (n_def, m + 1)
        Defect matrix acting on the interval's states.
    B : ndarray, shape (n_def, c)
        Defect matrix acting on the dynamics at the collocation nodes (times h).
    weights : ndarray, shape (c,)
        Quadrature weights on the collocation nodes for ∫₀¹ · dτ̂.
    """

    name: str
    nodes: np.ndarray
    colloc: np.ndarray
    A: np.ndarray
    B: np.ndarray
    weights: np.ndarray

    @property
    def m(self) -> int:
        return len(self.nodes) - 1

    @property
    def n_defects(self) -> int:
        return self.A.shape[0]


def lgr_scheme(d: int, side: str = "left") -> Scheme:
    """LGR collocation with ``d`` points on one interval (see the module docstring).

    Differentiation matrix ``A = D`` (d × (d+1)): ``D[k, j] = ℓ_j'(τ_k)`` for collocation
    points τ_k and the d + 1 Lagrange nodes; ``B = I``; weights ``w_k = ∫₀¹ ℓ̃_k`` with ℓ̃
    the Lagrange basis on the d collocation points (the Radau quadrature).
    """
    pts = lgr_points(d, side)
    if side == "right":
        nodes = np.concatenate([[0.0], pts])
        colloc = np.arange(1, d + 1)
    else:
        nodes = np.concatenate([pts, [1.0]])
        colloc = np.arange(0, d)
    D = differentiation_matrix(nodes)[colloc, :]
    w = lgr_weights(d, side)
    return Scheme(
        name="lgr", nodes=nodes, colloc=colloc, A=D, B=np.eye(d), weights=w
    )


def trapezoidal_scheme() -> Scheme:
    """Trapezoidal rule: x₁ − x₀ − h/2 (f₀ + f₁) = 0, weights (½, ½)."""
    return Scheme(
        name="trapezoidal",
        nodes=np.array([0.0, 1.0]),
        colloc=np.array([0, 1]),
        A=np.array([[-1.0, 1.0]]),
        B=np.array([[0.5, 0.5]]),
        weights=np.array([0.5, 0.5]),
    )


def hermite_simpson_scheme() -> Scheme:
    """Separated Hermite–Simpson: Simpson and Hermite-interpolation defects, Simpson weights."""
    return Scheme(
        name="hermite-simpson",
        nodes=np.array([0.0, 0.5, 1.0]),
        colloc=np.array([0, 1, 2]),
        A=np.array([[-1.0, 0.0, 1.0], [-0.5, 1.0, -0.5]]),
        B=np.array([[1 / 6, 4 / 6, 1 / 6], [1 / 8, 0.0, -1 / 8]]),
        weights=np.array([1 / 6, 4 / 6, 1 / 6]),
    )


def make_scheme(name: str, degree: int = 5, lgr_side: str = "left") -> Scheme:
    """Scheme by name: ``"lgr"`` (uses ``degree``), ``"trapezoidal"``, ``"hermite-simpson"``."""
    if name == "lgr":
        return lgr_scheme(degree, lgr_side)
    if name == "trapezoidal":
        return trapezoidal_scheme()
    if name == "hermite-simpson":
        return hermite_simpson_scheme()
    raise ValueError(f"unknown scheme {name!r}; choose from {SCHEMES}")


def integral_form(sch: Scheme) -> tuple[np.ndarray, np.ndarray]:
    """The scheme's defects in integral form: (Â⁻¹A, Â⁻¹B) with Â = A[:, 1:].

    Since A·1 = 0 (a constant state has no defect), Â⁻¹A = [−1 | I] exactly; it is returned
    as such, so each row reads x_j − x_0 − h Σ_l (Â⁻¹B)_{jl} f_l with unit coefficients."""
    A, B = np.asarray(sch.A, float), np.asarray(sch.B, float)
    Ahat = A[:, 1:]
    if Ahat.shape[0] != Ahat.shape[1]:
        raise ValueError(f"{sch.name}: the integral form needs as many defects as later nodes")
    if not np.allclose(np.linalg.solve(Ahat, A[:, 0]), -1.0, atol=1e-10):
        raise ValueError(f"{sch.name}: A·1 = 0 expected")
    Ai = np.hstack([-np.ones((Ahat.shape[0], 1)), np.eye(Ahat.shape[0])])
    return Ai, np.linalg.solve(Ahat, B)


# --------------------------------------------------------------------------------------
# Mesh
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Mesh:
    """A fixed mesh on normalised time τ ∈ [0, 1] with one collocation scheme.

    Parameters
    ----------
    n_intervals : int
        N. The thesis (GPOPS-II) used ``Mesh(20, "lgr", 5)``: 100 collocation points.
    scheme : {"lgr", "trapezoidal", "hermite-simpson"}
    degree : int
        LGR points per interval (ignored by the other schemes).
    fractions : tuple of float, optional
        Interval widths (N values, positive, normalised to sum to 1). Uniform if omitted.
    lgr_side : {"left", "right"}
        Which interval end the LGR points include (see the module docstring).
    hs_control_midpoints : {"interpolate", "free"}
        Hermite–Simpson only: constrain midpoint controls to the mean of the ends
        (Moco's default) or leave them free.
    defect_form : {"differential", "integral"}
        How each interval's defects are written. ``"differential"`` (default): X Aᵀ − h F Bᵀ
        with the scheme's A and B. ``"integral"``: the same equations multiplied by Â⁻¹, Â
        being A without its first column (invertible for every scheme here; A·1 = 0), i.e.
        x_j − x_0 − h Σ_l (Â⁻¹B)_{jl} f_l = 0 for each later node j of the interval: the
        same feasible set, another scaling of the rows (GPOPS-II offers both forms).

    Examples
    --------
    >>> mesh = Mesh(20, "lgr", 5)
    >>> mesh.n_state_nodes, mesh.n_colloc_nodes
    (101, 100)
    """

    n_intervals: int
    scheme: str = "lgr"
    degree: int = 5
    fractions: tuple[float, ...] | None = None
    lgr_side: str = "left"
    hs_control_midpoints: str = "interpolate"
    defect_form: str = "differential"

    def __post_init__(self):
        if self.n_intervals < 1:
            raise ValueError("n_intervals must be >= 1")
        if self.scheme not in SCHEMES:
            raise ValueError(f"unknown scheme {self.scheme!r}; choose from {SCHEMES}")
        if self.hs_control_midpoints not in ("interpolate", "free"):
            raise ValueError("hs_control_midpoints must be 'interpolate' or 'free'")
        if self.defect_form not in DEFECT_FORMS:
            raise ValueError(f"defect_form must be one of {DEFECT_FORMS}, got {self.defect_form!r}")
        if self.fractions is not None:
            f = np.asarray(self.fractions, dtype=float)
            if f.shape != (self.n_intervals,) or np.any(f <= 0):
                raise ValueError("fractions must be n_intervals positive numbers")
            object.__setattr__(self, "fractions", tuple(float(v) for v in f / f.sum()))
        make_scheme(self.scheme, self.degree, self.lgr_side)  # validate

    # -- structure ----------------------------------------------------------------
    @cached_property
    def interval(self) -> Scheme:
        """The scheme on one interval."""
        return make_scheme(self.scheme, self.degree, self.lgr_side)

    @cached_property
    def widths(self) -> np.ndarray:
        """h_i, shape (N,), summing to 1."""
        if self.fractions is None:
            return np.full(self.n_intervals, 1.0 / self.n_intervals)
        return np.asarray(self.fractions)

    @cached_property
    def breaks(self) -> np.ndarray:
        """Interval boundaries, shape (N + 1,), from 0 to 1."""
        b = np.concatenate([[0.0], np.cumsum(self.widths)])
        b[-1] = 1.0
        return b

    @property
    def n_state_nodes(self) -> int:
        return self.n_intervals * self.interval.m + 1

    @cached_property
    def state_index(self) -> np.ndarray:
        """Global state-node indices of each interval's nodes, shape (N, m + 1)."""
        m = self.interval.m
        return np.arange(self.n_intervals)[:, None] * m + np.arange(m + 1)[None, :]

    @cached_property
    def tau(self) -> np.ndarray:
        """Normalised times of the state nodes, shape (n_s,)."""
        out = np.empty(self.n_state_nodes)
        for i in range(self.n_intervals):
            out[self.state_index[i]] = self.breaks[i] + self.widths[i] * self.interval.nodes
        out[-1] = 1.0
        return out

    @cached_property
    def colloc_state_nodes(self) -> np.ndarray:
        """State-node index of every collocation node, shape (n_c,), increasing."""
        idx = self.state_index[:, self.interval.colloc]
        return np.unique(idx.ravel())

    @property
    def n_colloc_nodes(self) -> int:
        return len(self.colloc_state_nodes)

    @cached_property
    def tau_colloc(self) -> np.ndarray:
        """Normalised times of the collocation (control) nodes, shape (n_c,)."""
        return self.tau[self.colloc_state_nodes]

    @cached_property
    def colloc_index(self) -> np.ndarray:
        """Collocation-node index of each interval's collocation nodes, shape (N, c)."""
        pos = {s: k for k, s in enumerate(self.colloc_state_nodes)}
        idx = self.state_index[:, self.interval.colloc]
        return np.vectorize(pos.__getitem__)(idx)

    @cached_property
    def quadrature_weights(self) -> np.ndarray:
        """Weights W on the collocation nodes with ∫₀¹ g(τ) dτ ≈ Σ_k W_k g(τ_k), shape (n_c,)."""
        W = np.zeros(self.n_colloc_nodes)
        for i in range(self.n_intervals):
            np.add.at(W, self.colloc_index[i], self.widths[i] * self.interval.weights)
        return W

    @cached_property
    def defect_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """Global (A_g, B_g) with all defects = X A_gᵀ − (tf − t0) F B_gᵀ.

        A_g has shape (N n_def, n_s); B_g has shape (N n_def, n_c) and already contains
        the interval widths h_i. Rows are ordered interval by interval.
        """
        sch = self.interval
        nd = sch.n_defects
        Ai, Bi = sch.A, sch.B
        if self.defect_form == "integral":
            Ai, Bi = integral_form(sch)
        A = np.zeros((self.n_intervals * nd, self.n_state_nodes))
        B = np.zeros((self.n_intervals * nd, self.n_colloc_nodes))
        for i in range(self.n_intervals):
            rows = slice(i * nd, (i + 1) * nd)
            A[rows, self.state_index[i]] += Ai
            B[rows, self.colloc_index[i]] += self.widths[i] * Bi
        return A, B

    @cached_property
    def hs_midpoint_matrix(self) -> np.ndarray | None:
        """C (N × n_c) with U Cᵀ = midpoint control minus the mean of its ends, or None."""
        if self.scheme != "hermite-simpson" or self.hs_control_midpoints == "free":
            return None
        C = np.zeros((self.n_intervals, self.n_colloc_nodes))
        for i in range(self.n_intervals):
            c0, cm, c1 = self.colloc_index[i]
            C[i, [c0, cm, c1]] = [-0.5, 1.0, -0.5]
        return C

    @cached_property
    def interval_of_colloc(self) -> np.ndarray:
        """The first interval each collocation node belongs to, shape (n_c,)."""
        owner = np.full(self.n_colloc_nodes, self.n_intervals)
        for i in range(self.n_intervals):
            owner[self.colloc_index[i]] = np.minimum(owner[self.colloc_index[i]], i)
        return owner

    # -- symbolic builders --------------------------------------------------------
    def defects(self, X, F, duration):
        """Defect constraints for symbolic states and dynamics.

        Parameters
        ----------
        X : casadi.SX or casadi.MX, shape (n_x, n_s)
            States at the state nodes.
        F : casadi.SX or casadi.MX, shape (n_x, n_c)
            ẋ = f(x, u, p, t) at the collocation nodes.
        duration : casadi scalar or float
            tf − t0.

        Returns
        -------
        casadi matrix, shape (n_x, N n_def)
            Column block i holds interval i's defects (zero at a feasible point).
            The constant matrices are sparse (``casadi.sparsify``), so MX graphs keep
            only structural non-zeros; SX drops them anyway.
        """
        A, B = self.defect_matrices
        At = ca.sparsify(ca.DM(A.T))
        Bt = ca.sparsify(ca.DM(B.T))
        return ca.mtimes(X, At) - duration * ca.mtimes(F, Bt)

    def integrate(self, L, duration):
        """∫_{t0}^{tf} L dt ≈ (tf − t0) L W for L of shape (k, n_c); returns shape (k, 1)."""
        return duration * ca.mtimes(L, ca.DM(self.quadrature_weights))

    def describe(self) -> str:
        extra = f", d={self.degree}, {self.lgr_side}" if self.scheme == "lgr" else ""
        if self.defect_form != "differential":
            extra += f", {self.defect_form} defects"
        return (
            f"{self.scheme}{extra}: {self.n_intervals} intervals, "
            f"{self.n_state_nodes} state nodes, {self.n_colloc_nodes} collocation nodes"
        )
