"""The timed motion of a joint path (:class:`SmoothTiming`), its exact peaks
(:func:`exact_peaks`), the repair that stretches its time until every limit holds
(:func:`stretched`) and the error of a path that cannot be timed (:class:`InfeasibleTimingError`).
Joint positions in rad, t in s."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from pydrake.trajectories import PiecewisePolynomial, Trajectory

from drake_traj.compiled import compiled
from drake_traj.errors import Cause, DrakeTrajError
from drake_traj.planners.base import piecewise_trajectory
from drake_traj.planners.laws.hermite import HermiteLaw, sigma_derivatives

__all__ = ["InfeasibleTimingError", "SmoothTiming", "exact_peaks", "stretched"]


class InfeasibleTimingError(DrakeTrajError):
    """The path cannot be timed under the given limits (a cusp, a corner, limits too small)."""

    default_cause = Cause.INFEASIBLE


@dataclass(frozen=True)
class SmoothTiming:
    """The timed motion.

    Attributes:
        law: the motion as a time law (:class:`HermiteLaw`, quintic pieces between ``knots``)
            for a :class:`~drake_traj.planners.base.TimeLawPlanner`.
        coefficients: the pieces' monomial coefficients in t - knots[k], (K - 1, 6, n).
        trajectory: the same motion as Drake's PiecewisePolynomial q(t) [rad], t in [0, duration]
            (made on first use).
        duration: T [s].
        path: the geometric path q(s) that was timed (None: the motion itself, s = t).
        stretch: the factor (>= 1) the repair stretched the time by so every limit holds (1: none).
        peaks: max |q̇|, |q̈|, |q⃛| over the limit per joint, exact ((3, n)).
        deviation: the largest joint deviation [rad] from the given path, as checked: the
            spline's from every sample (0 for a Trajectory) plus the pieces' from the spline at 4
            points inside every piece (against q(s(t)), s(t) the same Hermite interpolation of
            the path speed, which bounds the distance to the path at those points).
        iterations: linear programs with the jerk solved, over every grid.
    """

    law: HermiteLaw
    coefficients: np.ndarray
    duration: float
    given_path: Trajectory | None
    stretch: float
    peaks: np.ndarray
    deviation: float
    iterations: int

    @functools.cached_property
    def trajectory(self) -> PiecewisePolynomial:
        return piecewise_trajectory(self.law.knots, self.coefficients)

    @property
    def path(self) -> Trajectory:
        return self.trajectory if self.given_path is None else self.given_path


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
def _rate_peaks(velocity, acceleration):
    """(max |q̇|, max |q̈|) per (interval, joint) over sigma in [-1, 1] [rad/s, rad/s²], from q̇ as quartics
    (``velocity`` (5, K, n)) and q̈ as cubics (``acceleration`` (4, K, n)) in sigma: at the ends
    and where q̈ = 0 (each monotone piece of the cubic between its turning points holds at most
    one root) and where q⃛ = 0 (a quadratic, closed form)."""
    K, n = velocity.shape[1], velocity.shape[2]
    v_peak, a_peak = np.empty((K, n)), np.empty((K, n))
    edges = np.empty(4)
    for k in range(K):
        for j in range(n):
            v, c = velocity[:, k, j], acceleration[:, k, j]
            v_peak[k, j] = max(abs(_polynomial(v, -1.0)), abs(_polynomial(v, 1.0)))
            a_peak[k, j] = max(abs(_polynomial(c, -1.0)), abs(_polynomial(c, 1.0)))
            # q⃛ = 3 c3 s² + 2 c2 s + c1: its roots in (-1, 1), the cubic's turning points
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
            for e in range(1, count):
                a_peak[k, j] = max(a_peak[k, j], abs(_polynomial(c, edges[e])))
            edges[count] = 1.0
            for e in range(count):
                f_lo, f_hi = _polynomial(c, edges[e]), _polynomial(c, edges[e + 1])
                if f_lo * f_hi <= 0.0:
                    root = edges[e] if f_lo == 0.0 else _bracketed_root(c, edges[e], edges[e + 1], f_lo)
                    v_peak[k, j] = max(v_peak[k, j], abs(_polynomial(v, root)))
    return v_peak, a_peak


def exact_peaks(knots, coefficients) -> np.ndarray:
    """max |q̇|, |q̈|, |q⃛| per joint [rad/s, rad/s², rad/s³] over piecewise quintics (monomial
    ``coefficients`` (K, 6, n) in t - knots[k] [s]), exact to round-off: (3, n). Compiled
    (:func:`_rate_peaks`): 0.34 ms on 400 pieces, where the vectorised bisection of
    :mod:`~drake_traj.planners.laws.polynomials` took 3.3 ms for the same peaks."""
    _, _, (velocity, acceleration, jerk) = sigma_derivatives(knots, np.asarray(coefficients, dtype=float), 3)
    v_peak, a_peak = _rate_peaks(np.ascontiguousarray(velocity), np.ascontiguousarray(acceleration))
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = np.where(jerk[2] != 0, -jerk[1] / (2 * jerk[2]), np.nan)
    vertex = np.where(np.abs(vertex) <= 1, vertex, np.nan)
    candidates = [np.abs(jerk[0] - jerk[1] + jerk[2]), np.abs(jerk[0] + jerk[1] + jerk[2]),
                  np.nan_to_num(np.abs(jerk[0] + jerk[1] * vertex + jerk[2] * vertex**2), nan=0.0)]
    j_peak = np.max(candidates, axis=0)
    return np.stack([v_peak.max(axis=0), a_peak.max(axis=0), j_peak.max(axis=0)])


def stretched(knots, states, coefficients, limits: np.ndarray, margin: float):
    """The repair: (knots, states, coefficients, exact peaks over ``limits`` (3, n), stretch) of
    pieces (monomial ``coefficients`` (K - 1, 6, n) in t - knots[k], ``states`` (K, q/q̇/q̈, n) at
    the knots) with time stretched by k >= 1, (1 + ``margin``) × the least that keeps every exact
    peak within its limit (q̇, q̈, q⃛ scale by 1/k, 1/k², 1/k³, a coefficient c_i by 1/k^i)."""
    ratio = exact_peaks(knots, coefficients) / limits
    if not ratio.max() > 1:
        return knots, states, coefficients, ratio, 1.0
    stretch = float(max(ratio.max(axis=1) ** (1.0 / np.arange(1, 4)))) * (1 + margin)
    knots, states = knots * stretch, states / stretch ** np.arange(3)[None, :, None]
    coefficients = coefficients / stretch ** np.arange(6)[None, :, None]
    return knots, states, coefficients, exact_peaks(knots, coefficients) / limits, stretch
