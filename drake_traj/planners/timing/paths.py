"""The joint path a timing times: a Drake Trajectory q(s) or joint samples, checked
(:func:`check_path`: no cusp, no corner, no reversal), the C2 spline through samples
(:func:`sample_path`), the centripetal C2 spline through joint waypoints
(:func:`waypoint_path`) and q(s) with its derivatives at many s (:class:`PathValues`). Joint
positions in rad, s the path parameter (joint-space arc length for a path made from samples)."""

from __future__ import annotations

import math

import numpy as np
from pydrake.trajectories import PiecewisePolynomial, Trajectory

from drake_traj.errors import DrakeTrajError
from drake_traj.planners.timing.motion import InfeasibleTimingError
from drake_traj.validation import real_array, require_finite

__all__ = ["PATH_TOLERANCE", "PathValues", "check_path", "checked_path", "sample_path", "waypoint_path"]

PATH_TOLERANCE = 1e-4
"""The largest joint-space deviation [rad] of the timed motion from the given path."""
_REVERSAL_COSINE = -0.5  # consecutive sample steps turning by more than 120°: a reversal
_TAYLOR_DEGREE = 5  # pieces of at most this degree are evaluated by Horner


class PathValues:
    """q(s) and its first three derivatives at many s, each (len(s), n) [rad, rad/rad^k], of a
    path (a Drake Trajectory q(s), ``path``). On a PiecewisePolynomial of pieces of degree <= 5
    (the splines here are cubic), Horner on each piece's Taylor coefficients at its start, taken
    once from Drake: a sixth of ``vector_values``' time on 4001 points, equal to round-off; on any
    other trajectory, Drake's own evaluation."""

    def __init__(self, path):
        self.path = path
        self._derivatives = [path] + [path.MakeDerivative(k) for k in (1, 2, 3)]
        self._coefficients = None
        if not isinstance(path, PiecewisePolynomial):
            return
        segments = path.get_number_of_segments()
        degree = max(path.getSegmentPolynomialDegree(k, j) for k in range(segments) for j in range(path.rows()))
        if degree > _TAYLOR_DEGREE:
            return
        self._breaks = np.asarray(path.get_segment_times(), dtype=float)
        starts = self._breaks[:-1]
        derivatives = self._derivatives + [path.MakeDerivative(k) for k in range(4, degree + 1)]
        taylor = [derivatives[k].vector_values(starts).T / math.factorial(k) for k in range(degree + 1)]  # (K, n)
        self._coefficients = []
        for r in range(4):  # the r-th derivative: c_(k + r) (k + r)! / k! for (s - start)^k, highest k first
            terms = [taylor[k + r] * (math.factorial(k + r) / math.factorial(k)) for k in range(degree - r, -1, -1)]
            self._coefficients.append(terms or [np.zeros_like(taylor[0])])

    def __call__(self, s, *orders) -> list[np.ndarray]:
        """[the ``order``-th derivative of q at ``s`` [rad] for each of ``orders`` (0: q)], each
        (len(s), n) [rad/rad^order]."""
        s = np.asarray(s, dtype=float)
        if self._coefficients is None:
            return [self._derivatives[order].vector_values(s).T for order in orders]
        segment = np.clip(np.searchsorted(self._breaks, s, side="right") - 1, 0, len(self._breaks) - 2)
        offset = (s - self._breaks[segment])[:, None]
        values = []
        for order in orders:
            coefficients = self._coefficients[order]
            value = coefficients[0][segment]
            for coefficient in coefficients[1:]:
                value = value * offset + coefficient[segment]
            values.append(value)
        return values


def check_path(path, name: str = "path") -> tuple[Trajectory, float]:
    """``path`` as a Drake Trajectory q(s) and its largest deviation from what was given [rad]
    (:func:`checked_path`)."""
    return checked_path(path, name)[:2]


def checked_path(path, name: str = "path") -> tuple[Trajectory, float, PathValues]:
    """``path`` as a Drake Trajectory q(s), its largest deviation from what was given [rad] and its
    :class:`PathValues`: a Trajectory as it is (0), joint samples (N, n) as the C2 cubic spline
    through knots picked from them (:func:`sample_path`).

    Raises:
        InfeasibleTimingError: samples that turn back (two consecutive steps more than 120°
            apart: a cusp or a joint reversal at a corner), a Trajectory whose q'' jumps at a
            break (a corner: q̈ would jump there) or whose q' vanishes (a cusp).
        DrakeTrajError: wrong shapes or non-finite samples.
    """
    if isinstance(path, Trajectory):
        if path.cols() != 1 or path.rows() < 1:
            raise DrakeTrajError(f"{name} must be a trajectory of one column (n x 1), got {path.rows()} x {path.cols()}",
                                 field=(name,))
        if not path.end_time() > path.start_time():
            raise DrakeTrajError(f"{name} must have a positive length in s, got [{path.start_time()}, {path.end_time()}]",
                                 field=(name,))
        values = PathValues(path)
        _check_corners(path, values, name)
        fit = 0.0
    else:
        samples = real_array(path, name, "rad")
        if samples.ndim != 2 or samples.shape[0] < 2 or samples.shape[1] < 1:
            raise DrakeTrajError(f"{name} must be joint samples of shape (N, n) with N >= 2, got shape {samples.shape}",
                                 field=(name,))
        require_finite(samples, name, "rad")
        _check_reversals(samples, name)
        path, fit = sample_path(samples, name=name)
        values = PathValues(path)
    _check_cusps(path, values, name)
    return path, fit, values


def sample_path(samples, max_knots: int = 200, *, name: str = "path") -> tuple[PiecewisePolynomial, float]:
    """The C2 cubic spline q(s) through knots picked from joint samples (N, n) [rad], s the
    arc length through the knots [rad], and its largest deviation from the samples [rad].

    Knots are spaced evenly in arc length plus turning angle (each half of the total), so a
    tight turn gets as many knots as a long straight stretch (a path from Pająk's law turns
    through tens of degrees within 0.1 mrad where it slows down). Repeated samples (closer than
    1e-9 rad) are dropped. Where the spline strays from a sample by more than half of
    :data:`PATH_TOLERANCE`, the knot interval holding that sample is split at its middle (in the
    same measure), round after round, up to 4 × ``max_knots`` knots: knots are added only where
    the path needs them.

    Raises:
        InfeasibleTimingError: fewer than two distinct samples, or a spline that still strays.
    """
    q = np.asarray(samples, dtype=float)
    step = np.linalg.norm(np.diff(q, axis=0), axis=1)
    q = q[np.concatenate([[True], step > 1e-9])]
    if len(q) < 2:
        raise InfeasibleTimingError(f"{name} must hold at least 2 distinct configurations", field=(name,))
    steps = np.diff(q, axis=0)
    length = np.linalg.norm(steps, axis=1)
    arc = np.concatenate([[0.0], np.cumsum(length)])
    if len(q) == 2:
        return PiecewisePolynomial.FirstOrderHold(arc, q.T), 0.0
    unit = steps / length[:, None]
    turn = np.arccos(np.clip(np.sum(unit[1:] * unit[:-1], axis=1), -1.0, 1.0))
    measure = arc + np.concatenate([[0.0], np.cumsum(turn), [turn.sum()]]) * (arc[-1] / max(turn.sum(), 1e-12))
    index = np.unique(np.concatenate([[0, len(q) - 1],
                                      np.searchsorted(measure, np.linspace(0, measure[-1], max_knots)).clip(0, len(q) - 1)]))
    while True:
        chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(q[index], axis=0), axis=1))])
        path = (PiecewisePolynomial.FirstOrderHold(chord, q[index].T) if len(index) == 2 else
                PiecewisePolynomial.CubicWithContinuousSecondDerivatives(chord, q[index].T, periodic_end_condition=False))
        at = np.interp(arc, arc[index], chord)  # each sample's parameter, by arc length between knots
        error = np.abs(path.vector_values(at).T - q).max(axis=1)
        deviation = float(error.max())
        if deviation <= 0.5 * PATH_TOLERANCE or len(index) >= 4 * max_knots:
            break
        # a knot at the middle (in the measure) of every knot interval holding a sample that strays
        stray = np.searchsorted(index, np.flatnonzero(error > 0.5 * PATH_TOLERANCE), side="right") - 1
        stray = np.unique(stray.clip(0, len(index) - 2))
        stray = stray[index[stray + 1] - index[stray] > 1]
        if not len(stray):
            break
        middle = np.searchsorted(measure, 0.5 * (measure[index[stray]] + measure[index[stray + 1]]))
        index = np.unique(np.concatenate([index, np.clip(middle, index[stray] + 1, index[stray + 1] - 1)]))
    if deviation > 0.5 * PATH_TOLERANCE:
        raise InfeasibleTimingError(f"{name}: no spline through {len(index)} of its samples stays within "
                                    f"{0.5 * PATH_TOLERANCE:g} rad of them ({deviation:.3g} rad): the samples are "
                                    "too sparse or too noisy for a C2 path", field=(name,))
    return path, deviation


def _check_reversals(samples: np.ndarray, name: str) -> None:
    steps = np.diff(samples, axis=0)
    steps = steps[np.linalg.norm(steps, axis=1) > 1e-9]
    if len(steps) < 2:
        return
    unit = steps / np.linalg.norm(steps, axis=1)[:, None]
    cosine = np.sum(unit[1:] * unit[:-1], axis=1)
    if np.any(cosine < _REVERSAL_COSINE):
        k = int(np.argmax(cosine < _REVERSAL_COSINE)) + 1
        angle = np.degrees(np.arccos(np.clip(cosine[k - 1], -1, 1)))
        raise InfeasibleTimingError(
            f"{name} turns back by {angle:.0f}° at its distinct sample {k}: a cusp or a joint reversal at a corner, "
            "which no motion with continuous q̈ passes without stopping; split the path there and time each part",
            field=(name, k))


def _check_corners(path: Trajectory, values: PathValues, name: str) -> None:
    """A corner error where q' or q'' jumps at a break of ``path`` (relative to their size),
    ``values`` its :class:`PathValues`."""
    breaks = np.asarray(path.get_segment_times(), dtype=float)[1:-1]
    if not len(breaks):
        return
    delta = 1e-9 * (path.end_time() - path.start_time())
    s_all = np.linspace(path.start_time(), path.end_time(), 50)
    for order, symbol in ((1, "q'"), (2, "q''")):
        scale = max(1.0, np.abs(values(s_all, order)[0]).max())
        left, left_next = values(breaks - delta, order, order + 1)
        right, right_next = values(breaks + delta, order, order + 1)
        jump = np.abs(right - left).max(axis=1)
        # what the next derivative moves it by over the 2 delta between the two looks: a dense
        # spline's third derivative is large (knots 0.05 rad apart), and that is no corner
        drift = 2 * delta * np.maximum(np.abs(left_next).max(axis=1), np.abs(right_next).max(axis=1))
        corners = np.flatnonzero(jump > 1e-6 * scale + 2 * drift)
        if len(corners):
            k = corners[0]
            turn = np.dot(*(values([breaks[k] + side], 1)[0][0] for side in (-delta, delta)))
            kind = "turns back" if turn < 0 else "is not C2"
            raise InfeasibleTimingError(
                f"{name} {kind} at s = {breaks[k]:.6g}: {symbol} jumps by {jump[k]:.3g} there (a corner), so q̈ would "
                "jump unless the motion stops there; give a C2 path (e.g. PiecewisePolynomial."
                "CubicWithContinuousSecondDerivatives) or time the parts on either side separately", field=(name,))


def _check_cusps(path: Trajectory, values: PathValues, name: str) -> None:
    s = np.linspace(path.start_time(), path.end_time(), 2001)
    speed = np.linalg.norm(values(s, 1)[0], axis=1)
    typical = np.median(speed)
    if not typical > 0:
        raise InfeasibleTimingError(f"{name} does not move: |q'(s)| is 0 along it", field=(name,))
    if speed.min() < 1e-3 * typical:
        k = int(np.argmin(speed))
        raise InfeasibleTimingError(
            f"{name} has a cusp at s = {s[k]:.6g}: |q'(s)| = {speed[k]:.3g} there, against {typical:.3g} typical "
            "(the path stops and turns, where the timing would need an infinite path acceleration); split the path "
            "there and time each part", field=(name,))


def waypoint_path(q_waypoints) -> PiecewisePolynomial:
    """The C2 path through joint waypoints (m + 1, n) [rad]: the not-a-knot cubic spline with the
    centripetal parameter (s grows by the square root of each chord's length [rad], which bulges
    less past a waypoint where joints reverse than the chord length: 2 % shorter motions on
    seeded tasks); the straight segment for one move. Repeated waypoints (closer than 1e-5 of the
    longest chord) are dropped."""
    q = np.asarray(q_waypoints, dtype=float)
    step = np.linalg.norm(np.diff(q, axis=0), axis=1)
    # goals closer than 1e-5 of the longest chord are one (closer than about 1e-6 of it, the spline
    # stops and turns there: a cusp); no drive resolves them apart
    keep = np.concatenate([[True], step > 1e-5 * max(1.0, float(step.max(initial=0.0)))])
    q = q[keep]
    if len(q) < 2:
        raise DrakeTrajError("goals: every goal equals the start: there is no path to time", field=("goals",))
    chord = np.concatenate([[0.0], np.cumsum(np.sqrt(np.linalg.norm(np.diff(q, axis=0), axis=1)))])
    if len(q) == 2:
        return PiecewisePolynomial.FirstOrderHold(chord, q.T)
    return PiecewisePolynomial.CubicWithContinuousSecondDerivatives(chord, q.T, periodic_end_condition=False)
