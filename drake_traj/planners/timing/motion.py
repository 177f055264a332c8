"""The timed motion of a joint path (:class:`SmoothTiming`), its exact peaks
(:func:`exact_peaks`), the repair that stretches its time until every limit holds
(:func:`stretched`) and the error of a path that cannot be timed (:class:`InfeasibleTimingError`).
Joint positions in rad, t in s."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from pydrake.trajectories import PiecewisePolynomial, Trajectory

from drake_traj.errors import Cause, DrakeTrajError
from drake_traj.planners.base import piecewise_trajectory
from drake_traj.planners.laws.hermite import HermiteLaw, sigma_derivatives
from drake_traj.planners.laws.polynomials import rate_peaks

__all__ = ["InfeasibleTimingError", "SmoothTiming", "exact_peaks", "stretched"]


class InfeasibleTimingError(DrakeTrajError):
    """The path cannot be timed under the given limits (a cusp, a corner, limits too small)."""

    default_cause = Cause.INFEASIBLE


@dataclass(frozen=True)
class SmoothTiming:
    """The timed motion.

    Attributes:
        law: the motion as a time law (:class:`HermiteLaw` whose pieces are ``coefficients``,
            those checked, between its ``knots``) for a
            :class:`~drake_traj.planners.base.TimeLawPlanner`.
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


def exact_peaks(knots, coefficients) -> np.ndarray:
    """max |q̇|, |q̈|, |q⃛| per joint [rad/s, rad/s², rad/s³] over piecewise quintics (monomial
    ``coefficients`` (K, 6, n) in t - knots[k] [s]), exact to round-off: (3, n); |q̇| and |q̈| by
    :func:`~drake_traj.planners.laws.polynomials.rate_peaks`, |q⃛| (a quadratic) in closed form."""
    _, _, (velocity, acceleration, jerk) = sigma_derivatives(knots, np.asarray(coefficients, dtype=float), 3)
    v_peak, _, a_peak, _ = rate_peaks(velocity, acceleration)
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
