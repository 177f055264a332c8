"""Exact peaks of piecewise-polynomial joint laws, vectorised over knot intervals and joints.

A law that is a polynomial on every knot interval (Li et al. 2019's quintic B-spline, the quintic
Hermite tables of :class:`~drake_traj.planners.base.HermiteLaw`) reaches its largest |q̇| at an
interval end or where q̈ = 0, and its largest |q̈| at an end or where the jerk is zero. Written in
sigma in [-1, 1] on each interval (tau = mid + sigma half), q̇ is a quartic and q̈ a cubic, so the
candidates are closed-form (the jerk's quadratic) or bisected to full precision (q̈'s cubic): the
peaks are the true maxima to round-off, which no sampling can promise.
"""

import numpy as np

__all__ = ["cubic_roots", "interval_peaks", "polynomial_values", "quadratic_roots", "rate_peaks"]

_BISECTION_STEPS = 60


def quadratic_roots(a, b, c):
    """Real roots in [-1, 1] of a x^2 + b x + c (arrays), shape (..., 2); NaN where none."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        disc = b * b - 4.0 * a * c
        sq = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
        qq = -0.5 * (b + np.where(b >= 0.0, 1.0, -1.0) * sq)  # the stable form
        roots = np.stack([qq / a, c / qq], axis=-1)
    return np.where(np.abs(roots) <= 1.0, roots, np.nan)


def polynomial_values(coeffs, x):
    """sum_p coeffs[p] x^p by Horner; coeffs (P, ...), x broadcastable to coeffs[0]."""
    value = np.zeros(np.broadcast(coeffs[0], x).shape)
    for c in coeffs[::-1]:
        value = value * x + c
    return value


def cubic_roots(coeffs):
    """Real roots in [-1, 1] of sum_p coeffs[p] x^p (coeffs (4, ...)), shape (..., 3); NaN if none.

    The cubic is monotone between the roots of its derivative (closed form), so each of the three
    pieces holds at most one root; a sign change is bisected to full precision.
    """
    c0, c1, c2, c3 = coeffs
    turning = quadratic_roots(3.0 * c3, 2.0 * c2, c1)
    turning = np.sort(np.where(np.isnan(turning), 1.0, turning), axis=-1)  # NaN -> empty piece
    lo = np.concatenate([np.full(turning.shape[:-1] + (1,), -1.0), turning], axis=-1)
    hi = np.concatenate([turning, np.ones(turning.shape[:-1] + (1,))], axis=-1)
    expanded = coeffs[..., None]
    f_lo = polynomial_values(expanded, lo)
    f_hi = polynomial_values(expanded, hi)
    bracket = f_lo * f_hi <= 0.0
    rising = f_hi >= f_lo
    for _ in range(_BISECTION_STEPS):
        mid = 0.5 * (lo + hi)
        left = (polynomial_values(expanded, mid) >= 0.0) == rising  # the root is at or left of mid
        hi = np.where(left, mid, hi)
        lo = np.where(left, lo, mid)
    return np.where(bracket, 0.5 * (lo + hi), np.nan)


def interval_peaks(coeffs: np.ndarray, s_candidates: np.ndarray):
    """max |poly| over the candidate sigma per (interval, joint) (NaN = no candidate), and where."""
    values = np.abs(polynomial_values(coeffs[..., None], s_candidates))
    values = np.where(np.isnan(values), -1.0, values)
    index = np.argmax(values, axis=-1)
    peak = np.take_along_axis(values, index[..., None], axis=-1)[..., 0]
    candidates = np.nan_to_num(s_candidates, nan=0.0)
    where = np.take_along_axis(candidates, index[..., None], axis=-1)[..., 0]
    return peak, where


def rate_peaks(qd: np.ndarray, qdd: np.ndarray, samples: int = 2):
    """Largest |q̇| and |q̈| on every interval, and the sigma where each is reached.

    Args:
        qd: q̇ per interval as a quartic in sigma, coefficients (5, K, n).
        qdd: q̈ per interval as a cubic in sigma, coefficients (4, K, n).
        samples: uniform samples of sigma per interval besides the extrema, ends included, >= 2.

    Returns:
        (peak |q̇|, its sigma, peak |q̈|, its sigma), each (K, n).
    """
    grid = np.broadcast_to(np.linspace(-1.0, 1.0, samples), qd.shape[1:] + (samples,))
    v_candidates = np.concatenate([grid, cubic_roots(qdd)], axis=-1)  # q̈ = 0
    a_candidates = np.concatenate([grid, quadratic_roots(3.0 * qdd[3], 2.0 * qdd[2], qdd[1])], axis=-1)  # jerk = 0
    v_peak, v_sigma = interval_peaks(qd, v_candidates)
    a_peak, a_sigma = interval_peaks(qdd, a_candidates)
    return v_peak, v_sigma, a_peak, a_sigma
