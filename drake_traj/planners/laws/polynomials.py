"""Exact peaks of piecewise-polynomial joint laws, over knot intervals and joints.

A law that is a polynomial on every knot interval (Li et al. 2019's quintic B-spline, the quintic
Hermite tables of :class:`~drake_traj.planners.laws.hermite.HermiteLaw`, the timed motions of
:func:`~drake_traj.planners.timing.time_path`) reaches its largest |q̇| at an interval end or where
q̈ = 0, and its largest |q̈| at an end or where the jerk is zero. Written in sigma in [-1, 1] on each
interval (tau = mid + sigma half), q̇ is a quartic and q̈ a cubic, so the candidates are
closed-form (the jerk's quadratic) or found to round-off (q̈'s cubic, monotone between its turning
points: Newton's steps kept inside each root's bracket): the peaks are the true maxima to
round-off, which no sampling can promise. Compiled by numba (:func:`~drake_traj.compiled.compiled`):
0.34 ms on 400 pieces of six joints, where a vectorised bisection took 3.3 ms for the same peaks.
"""

import numpy as np

from drake_traj.compiled import compiled

__all__ = ["rate_peaks"]


@compiled
def _polynomial(c, x):
    """sum_p c[p] x^p (Horner)."""
    value = 0.0
    for p in range(len(c) - 1, -1, -1):
        value = value * x + c[p]
    return value


@compiled
def _bracketed_root(c, lo, hi, f_lo):
    """The root in [lo, hi] of the cubic c (coefficients (4,)), monotone there, whose value at lo
    is f_lo and changes sign by hi: Newton's steps kept inside the bracket, which every step
    narrows (a bisection where a step would leave it), to round-off."""
    x = 0.5 * (lo + hi)
    for _ in range(200):
        f = _polynomial(c, x)
        if f == 0.0:
            return x
        if (f < 0.0) == (f_lo < 0.0):
            lo = x
        else:
            hi = x
        step = x - f / ((3.0 * c[3] * x + 2.0 * c[2]) * x + c[1])
        if not lo < step < hi:  # also a NaN or infinite step
            step = 0.5 * (lo + hi)
        if step == x or not lo < step < hi:
            return step
        x = step
    return x


@compiled
def _turning_points(c, edges):
    """The cubic c's turning points in (-1, 1) (the roots of 3 c3 s² + 2 c2 s + c1, closed form)
    into edges[1:], in order, after edges[0] = -1; returns how many edges there are (1 to 3)."""
    a, b, d = 3.0 * c[3], 2.0 * c[2], c[1]
    count = 1
    edges[0] = -1.0
    if a == 0.0:
        if b != 0.0 and -1.0 < -d / b < 1.0:
            edges[1] = -d / b
            count = 2
    elif b * b - 4.0 * a * d >= 0.0:
        q = -0.5 * (b + np.copysign(np.sqrt(b * b - 4.0 * a * d), b))
        for root in (q / a, d / q if q != 0.0 else 2.0):
            if -1.0 < root < 1.0:
                edges[count] = root
                count += 1
        if count == 3 and edges[2] < edges[1]:
            edges[1], edges[2] = edges[2], edges[1]
    return count


@compiled
def _peaks(velocity, acceleration, samples):
    """(max |q̇|, its sigma, max |q̈|, its sigma) per (interval, joint) of :func:`rate_peaks`."""
    intervals, n = velocity.shape[1], velocity.shape[2]
    v_peak, v_at = np.full((intervals, n), -1.0), np.zeros((intervals, n))
    a_peak, a_at = np.full((intervals, n), -1.0), np.zeros((intervals, n))
    edges = np.empty(4)
    for k in range(intervals):
        for j in range(n):
            v, c = velocity[:, k, j], acceleration[:, k, j]
            for m in range(samples):  # the uniform samples, ends included, first
                s = -1.0 + 2.0 * m / (samples - 1)
                if abs(_polynomial(v, s)) > v_peak[k, j]:
                    v_peak[k, j], v_at[k, j] = abs(_polynomial(v, s)), s
                if abs(_polynomial(c, s)) > a_peak[k, j]:
                    a_peak[k, j], a_at[k, j] = abs(_polynomial(c, s)), s
            count = _turning_points(c, edges)
            for e in range(1, count):  # the jerk's zeros: q̈'s extrema
                if abs(_polynomial(c, edges[e])) > a_peak[k, j]:
                    a_peak[k, j], a_at[k, j] = abs(_polynomial(c, edges[e])), edges[e]
            edges[count] = 1.0
            for e in range(count):  # q̈'s zeros, at most one on each monotone piece: q̇'s extrema
                f_lo, f_hi = _polynomial(c, edges[e]), _polynomial(c, edges[e + 1])
                if f_lo * f_hi <= 0.0:
                    root = edges[e] if f_lo == 0.0 else _bracketed_root(c, edges[e], edges[e + 1], f_lo)
                    if abs(_polynomial(v, root)) > v_peak[k, j]:
                        v_peak[k, j], v_at[k, j] = abs(_polynomial(v, root)), root
    return v_peak, v_at, a_peak, a_at


def rate_peaks(qd: np.ndarray, qdd: np.ndarray, samples: int = 2):
    """Largest |q̇| and |q̈| on every interval, and the sigma where each is reached.

    Args:
        qd: q̇ per interval as a quartic in sigma, coefficients (5, K, n).
        qdd: q̈ per interval as a cubic in sigma, coefficients (4, K, n).
        samples: uniform samples of sigma per interval besides the extrema, ends included, >= 2.

    Returns:
        (peak |q̇|, its sigma, peak |q̈|, its sigma), each (K, n); of equal candidates the first
        (the samples in order, then the extrema).
    """
    return _peaks(np.ascontiguousarray(qd, dtype=float), np.ascontiguousarray(qdd, dtype=float), int(samples))
