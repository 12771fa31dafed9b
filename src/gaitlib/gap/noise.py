"""Smooth random curves: the noise model of twins and of the ranking's resampling.

Group-mean gait curves are smooth, so their sampling error is not white: it is drawn as a
periodic Gaussian process with a squared-exponential correlation of length
:data:`NOISE_LENGTH` (fraction of the cycle) and unit marginal variance, scaled by the
caller (SD/sqrt(n) for a group mean).
"""

from __future__ import annotations

import numpy as np

__all__ = ["NOISE_LENGTH", "smooth_noise"]

#: Correlation length of the twin and resampling noise, fraction of the cycle.
NOISE_LENGTH = 0.05
_N_HARM = 20


def smooth_noise(rng: np.random.Generator, n_curves: int, length: float = NOISE_LENGTH):
    """Random periodic curves with unit marginal variance and squared-exponential
    correlation exp(−Δ²/(2ℓ²)) (Δ: cycle fraction, wrapped), as a callable τ → (n_curves,
    len(τ)). A random Fourier series whose harmonic variances are the kernel's spectrum
    (∝ exp(−(2πkℓ)²/2)), normalised to unit variance."""
    k = np.arange(0, _N_HARM + 1)
    w = np.exp(-0.5 * (2 * np.pi * k * length) ** 2)
    w[0] *= 0.5
    w = w / w.sum()
    a = rng.standard_normal((n_curves, k.size)) * np.sqrt(w)
    b = rng.standard_normal((n_curves, k.size)) * np.sqrt(w)
    b[:, 0] = 0.0  # Var = Σ_k w_k = 1 (w_0 = s(0)/2, w_k = s(k): the one-sided spectrum)

    def f(tau):
        ph = 2 * np.pi * np.outer(k, np.asarray(tau, float))
        return a @ np.cos(ph) + b @ np.sin(ph)

    return f
