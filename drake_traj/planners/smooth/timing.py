"""Smooth, jerk-limited, near-time-optimal timing of a joint path (docs/smooth_timing.md).

Given a joint path q(s) and per-joint limits on |q̇|, |q̈| and |q⃛|, :func:`time_path` finds a
path speed profile x(s) = ṡ² by a sequence of linear programs (Palleschi et al. 2019, RA-L,
"Time-optimal path tracking for jerk controlled robots"; the velocity and acceleration constraints
are the TOPP-RA ones of Pham & Pham 2018, linear in x) and returns the motion as quintic Hermite
pieces in time, C2 (q̈ continuous), at rest at both ends, with every limit checked at the exact
peaks of every piece. Joint positions in rad, s the path parameter (joint-space arc length for
a path made from samples), t in s.

Along the path (' = d/ds):

- q̇ = q' ṡ, so |q̇_j| <= v_j is the bound x <= v_j² / q'_j²;
- q̈ = q' x' / 2 + q'' x (linear in x);
- q⃛ = √x (q''' x + 1.5 q'' x' + 0.5 q' x''), linear in x once √x is frozen at the previous
  iterate: the sequential LP (Palleschi et al. 2019's linearisation).

Our discretisation: x and x' at every node, x quadratic in s between nodes (so s̈ = x' / 2 is
continuous). At the ends the motion starts (and stops) with a constant path jerk, s = j t³ / 6,
so x ∝ distance^(4/3): at the node next to an end x' = ±4 x / (3 h) and x'' = 4 x / (9 h²) (h its
distance to the end), q̈ = 0 at the end and the end interval lasts 3 h / √x.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import scipy.sparse
import highspy
from pydrake.trajectories import PiecewisePolynomial, Trajectory

from drake_traj.errors import Cause, DrakeTrajError, joint_label
from drake_traj.planners.base import piecewise_trajectory
from drake_traj.planners.baselines.ruckig import default_jerk_limit
from drake_traj.planners.laws.hermite import HermiteLaw, quintic_hermite_coefficients, sigma_derivatives
from drake_traj.planners.laws.polynomials import rate_peaks
from drake_traj.validation import positive_scalar, positive_vector, real_array, require_finite, whole_number

__all__ = ["InfeasibleTimingError", "SmoothTiming", "check_path", "exact_peaks", "time_path"]

PATH_TOLERANCE = 1e-4
"""The largest joint-space deviation [rad] of the timed motion from the given path."""
LIMIT_MARGIN = 0.99
"""The linear programs aim at this share of each limit; the exact check and the repair do the rest."""
END_JERK_MARGIN = 0.93
"""The share of the jerk limit the programs aim at on the first and last 3 nodes."""
TRUST_REGION = 1.3
"""x may grow by at most this factor from one linear program to the next (where √x is frozen)."""
_REVERSAL_COSINE = -0.5  # consecutive sample steps turning by more than 120°: a reversal


GRID_LEVELS = (20, 50, 100, 250, 1000)
"""The grids solved before the one asked for (those with fewer nodes, and at least a quarter as
many as the path's breaks, which are nodes of every grid): each is started from the last one's solution (nodes evenly spaced in its time, x interpolated) and the shortest motion on
the path is kept, so more ``grid_points`` are not longer. Solved alone from the bang-bang start,
x near the ends grew only by the trust region's factor per program: 1000 nodes ended up to 3 times
longer than 200, and 100 nodes 1.7 % longer than 20 on a short path."""

MAX_GRID_POINTS = 4000
"""Nodes of the timing's linear programs at most (a program of N nodes has 2N variables and about
4nN constraints; 4000 nodes take seconds, a million would not finish)."""


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


def check_path(path, name: str = "path") -> tuple[Trajectory, float]:
    """``path`` as a Drake Trajectory q(s) and its largest deviation from what was given [rad]:
    a Trajectory as it is (0), joint samples (N, n) as the C2 cubic spline through knots picked
    from them (:func:`sample_path`).

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
        _check_corners(path, name)
        fit = 0.0
    else:
        samples = real_array(path, name, "rad")
        if samples.ndim != 2 or samples.shape[0] < 2 or samples.shape[1] < 1:
            raise DrakeTrajError(f"{name} must be joint samples of shape (N, n) with N >= 2, got shape {samples.shape}",
                                 field=(name,))
        require_finite(samples, name, "rad")
        _check_reversals(samples, name)
        path, fit = sample_path(samples, name=name)
    _check_cusps(path, name)
    return path, fit


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


def _check_corners(path: Trajectory, name: str) -> None:
    """A corner error where q' or q'' jumps at a break of ``path`` (relative to their size)."""
    breaks = np.asarray(path.get_segment_times(), dtype=float)[1:-1]
    if not len(breaks):
        return
    delta = 1e-9 * (path.end_time() - path.start_time())
    s_all = np.linspace(path.start_time(), path.end_time(), 50)
    for order, symbol in ((1, "q'"), (2, "q''")):
        scale = max(1.0, max(np.abs(path.EvalDerivative(s, order)).max() for s in s_all))
        for s in breaks:
            left, right = path.EvalDerivative(s - delta, order).ravel(), path.EvalDerivative(s + delta, order).ravel()
            jump = np.abs(right - left).max()
            # what the next derivative moves it by over the 2 delta between the two looks: a dense
            # spline's third derivative is large (knots 0.05 rad apart), and that is no corner
            drift = 2 * delta * max(np.abs(path.EvalDerivative(s - delta, order + 1)).max(),
                                    np.abs(path.EvalDerivative(s + delta, order + 1)).max())
            if jump > 1e-6 * scale + 2 * drift:
                turn = np.dot(path.EvalDerivative(s - delta, 1).ravel(), path.EvalDerivative(s + delta, 1).ravel())
                kind = "turns back" if turn < 0 else "is not C2"
                raise InfeasibleTimingError(
                    f"{name} {kind} at s = {s:.6g}: {symbol} jumps by {jump:.3g} there (a corner), so q̈ would jump "
                    "unless the motion stops there; give a C2 path (e.g. PiecewisePolynomial."
                    "CubicWithContinuousSecondDerivatives) or time the parts on either side separately", field=(name,))


def _check_cusps(path: Trajectory, name: str) -> None:
    s = np.linspace(path.start_time(), path.end_time(), 2001)
    speed = np.linalg.norm(path.MakeDerivative(1).vector_values(s), axis=0)
    typical = np.median(speed)
    if not typical > 0:
        raise InfeasibleTimingError(f"{name} does not move: |q'(s)| is 0 along it", field=(name,))
    if speed.min() < 1e-3 * typical:
        k = int(np.argmin(speed))
        raise InfeasibleTimingError(
            f"{name} has a cusp at s = {s[k]:.6g}: |q'(s)| = {speed[k]:.3g} there, against {typical:.3g} typical "
            "(the path stops and turns, where the timing would need an infinite path acceleration); split the path "
            "there and time each part", field=(name,))


def joint_limits(n: int, velocity_limit, acceleration_limit, jerk_limit):
    """(velocity [rad/s], acceleration [rad/s²], jerk [rad/s³]) per joint of n, checked; a jerk
    limit of None is 10 /s × the acceleration limit."""
    velocity = positive_vector(velocity_limit, "velocity_limit", n)
    acceleration = positive_vector(acceleration_limit, "acceleration_limit", n)
    jerk = default_jerk_limit(acceleration) if jerk_limit is None else positive_vector(jerk_limit, "jerk_limit", n)
    return velocity, acceleration, jerk


def check_least_durations(distance: np.ndarray, limits, max_duration: float, verb: str) -> None:
    """An InfeasibleTimingError naming the joint and the limit where one limit alone makes a
    rest-to-rest move of ``distance`` [rad] per joint last longer than ``max_duration`` [s]: it
    lasts at least d / v, 2 sqrt(d / a) and (32 d / J)^(1/3)."""
    velocity, acceleration, jerk = limits
    bounds = {"velocity_limit": (distance / velocity, velocity, "rad/s"),
              "acceleration_limit": (2 * np.sqrt(distance / acceleration), acceleration, "rad/s²"),
              "jerk_limit": (np.cbrt(32 * distance / jerk), jerk, "rad/s³")}
    for name, (least, limit, unit) in bounds.items():
        if not np.max(least) <= max_duration:
            j = int(np.argmax(least))
            raise InfeasibleTimingError(
                f"the limits are too small for the path: {joint_label(j)} {verb} {distance[j]:.4g} rad with at most "
                f"{limit[j]:.4g} {unit} ({name}): at least {least[j]:.4g} s, longer than max_duration {max_duration:g} s",
                field=("path",))


def _grid(path, velocity, acceleration, points: int) -> np.ndarray:
    """Grid nodes s: ``points`` evenly spaced in the time of an estimate of the bang-bang optimum,
    so the nodes crowd where the path is slow and near the ends, plus the path's breaks (on a path
    through hundreds of dense goals the breaks alone left a hairpin turn two nodes, where the
    program stopped the path: "the path speed falls to 0"). The estimate, on 4001 samples: the
    path speed ṡ² = x at most min_j (v_j² / q'_j², a_j / |q''_j|) (the velocity limits, and the
    accelerations at constant ṡ), reached from rest and brought to rest at the path acceleration
    min_j a_j / |q'_j| (x' = 2 s̈), each a running minimum; t from ds / ṡ with ṡ linear in t
    between samples. Drake's Toppra gave the same T within 0.2 % on seeded tasks at 5 times the
    time, and fails on some paths with tight turns."""
    s = np.linspace(path.start_time(), path.end_time(), 4001)
    d1 = np.abs(path.MakeDerivative(1).vector_values(s))
    d2 = np.abs(path.MakeDerivative(2).vector_values(s))
    with np.errstate(divide="ignore"):
        cap = np.min(np.minimum(velocity[:, None] ** 2 / d1**2, acceleration[:, None] / d2), axis=0)
        path_acceleration = np.min(acceleration[:, None] / d1, axis=0)
    cap[[0, -1]] = 0.0
    ramp = np.concatenate([[0.0], np.cumsum(np.diff(s) * 0.5 * (path_acceleration[1:] + path_acceleration[:-1]))])
    # x(s) <= x(s') + 2 (A(s) - A(s')) for every s' before s, and the same towards the end
    forward = 2 * ramp + np.minimum.accumulate(cap - 2 * ramp)
    backward = 2 * (ramp[-1] - ramp) + np.minimum.accumulate((cap - 2 * (ramp[-1] - ramp))[::-1])[::-1]
    rate = np.sqrt(np.maximum(np.minimum(forward, backward), 0.0))
    times = np.concatenate([[0.0], np.cumsum(2 * np.diff(s) / np.maximum(rate[1:] + rate[:-1], 1e-300))])
    return _with_breaks(path, np.interp(np.linspace(0.0, times[-1], points), times, s))


def _refined(path, coarse: np.ndarray, x: np.ndarray, p: np.ndarray, points: int):
    """(nodes s, x, p) of a finer grid of ``points`` nodes evenly spaced in the time of the coarse
    grid's solution (x, p) at its nodes ``coarse``, plus the path's breaks, with x and p
    interpolated there: the start of the finer grid's programs. On the end intervals x follows
    the end law, x ∝ distance^(4/3)."""
    times = _node_times(coarse, x, p)
    s = _with_breaks(path, np.interp(np.linspace(0.0, times[-1], points), times, coarse))
    x_fine, p_fine = np.interp(s, coarse, x), np.interp(s, coarse, p)
    first, last = s < coarse[1], s > coarse[-2]
    x_fine[first] = x[1] * ((s[first] - coarse[0]) / (coarse[1] - coarse[0])) ** (4 / 3)
    x_fine[last] = x[-2] * ((coarse[-1] - s[last]) / (coarse[-1] - coarse[-2])) ** (4 / 3)
    return s, x_fine, p_fine


def _with_breaks(path, s: np.ndarray) -> np.ndarray:
    """Grid nodes ``s`` in order within the path, with the path's own breaks as nodes (q⃛ may
    jump there) and the nodes too close to one dropped."""
    breaks = np.asarray(path.get_segment_times(), dtype=float)[1:-1]
    s = np.maximum.accumulate(np.clip(s, path.start_time(), path.end_time()))
    s[0], s[-1] = path.start_time(), path.end_time()
    if len(breaks):
        spacing = np.interp(breaks, s[1:], np.diff(s))
        near = (np.abs(s[:, None] - breaks[None, :]) < 0.3 * spacing[None, :]).any(axis=1)
        near[[0, -1]] = False
        s = np.sort(np.concatenate([s[~near], breaks]))
    keep = np.concatenate([[True], np.diff(s) > 1e-9 * (s[-1] - s[0])])
    s = s[keep]
    s[-1] = path.end_time()
    return s


def _path_derivatives(derivatives, s):
    """First, second and third derivatives of q(s) at ``s``, each (N, n), from ``derivatives``:
    the trajectories of those derivatives (``_Program.derivatives``)."""
    return [derivative.vector_values(s).T for derivative in derivatives]


_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(8)


def _node_times(s: np.ndarray, x: np.ndarray, p: np.ndarray) -> np.ndarray:
    """t at the nodes [s]: on the end intervals 3 h / √x (constant path jerk, x ∝ distance^(4/3));
    between interior nodes the integral of ds / √x with x the quadratic of (x, x') at both ends
    (8-point Gauss-Legendre)."""
    h = np.diff(s)
    u = 0.5 * (1 + _GAUSS_NODES)[None, :] * h[:, None]  # (N-1, 8)
    curvature = (p[1:] - p[:-1]) / h
    inside = x[:-1, None] + p[:-1, None] * u + 0.5 * curvature[:, None] * u**2
    dt = 0.5 * h * (_GAUSS_WEIGHTS / np.sqrt(np.maximum(inside, 1e-300))).sum(axis=1)
    dt[0] = 3 * h[0] / np.sqrt(x[1])
    dt[-1] = 3 * h[-1] / np.sqrt(x[-2])
    return np.concatenate([[0.0], np.cumsum(dt)])


class _QuietHighs(highspy.Highs):
    """highspy's HiGHS with its log off from the start: ``Highs.__init__`` registers its callbacks
    (``enableCallbacks``), which writes HiGHS's banner to stdout unless ``output_flag`` is already
    false by then."""

    def enableCallbacks(self):
        self.setOptionValue("output_flag", False)
        super().enableCallbacks()


class _Program:
    """The linear program of one iteration, in z = [x (N), p (N)], x = ṡ² and p = x' = 2 s̈ at the
    nodes, x quadratic in s between interior nodes (so s̈ is continuous): maximise the sum of x
    weighted by the grid spacing subject to the velocity bound, the acceleration at the nodes and
    between them, and the jerk at both ends of every interval with √x frozen at the previous
    iterate (the linearisation of Palleschi et al. 2019)."""

    def __init__(self, path, s, velocity, acceleration, jerk):
        N, n = len(s), path.rows()
        h = np.diff(s)
        self.s, self.num_nodes, self.num_joints = s, N, n
        self.derivatives = [path.MakeDerivative(k) for k in (1, 2, 3)]
        d1, d2, _ = _path_derivatives(self.derivatives, s)
        # q''' on each side of the nodes (it jumps at the breaks of a cubic spline)
        offset = 1e-9 * (s[-1] - s[0])
        after = _path_derivatives(self.derivatives, np.minimum(s + offset, s[-1]))[2]
        before = _path_derivatives(self.derivatives, np.maximum(s - offset, s[0]))[2]
        sp = scipy.sparse
        X = sp.hstack([sp.identity(N), sp.csr_matrix((N, N))], format="csr")
        P = sp.hstack([sp.csr_matrix((N, N)), sp.identity(N)], format="csr")
        inner = slice(1, N - 1)
        # x'' on every interval: (p_{i+1} - p_i) / h inside, 4 x / (9 h²) at the node next to an end
        curvature = sp.diags(1 / h) @ (P[1:] - P[:-1])
        curvature = sp.vstack([X[1] * (4 / (9 * h[0] ** 2)), curvature[1:-1], X[N - 2] * (4 / (9 * h[-1] ** 2))],
                              format="csr")
        # continuity of x (interior intervals) and the end laws p = ±4 x / (3 h)
        continuity = (X[2:N - 1] - X[1:N - 2]) - sp.diags(0.5 * h[1:-1]) @ (P[1:N - 2] + P[2:N - 1])
        self.equality = sp.vstack([continuity, P[1] - X[1] * (4 / (3 * h[0])), P[N - 2] + X[N - 2] * (4 / (3 * h[-1]))],
                                  format="csr")
        mid = 0.5 * (s[1:-2] + s[2:-1])  # interior intervals 1..N-3
        m1, m2 = _path_derivatives(self.derivatives, mid)[:2]
        hm = h[1:-1]
        x_mid = X[1:N - 2] + sp.diags(hm / 8) @ (3 * P[1:N - 2] + P[2:N - 1])
        p_mid = 0.5 * (P[1:N - 2] + P[2:N - 1])

        def per_joint(coefficients, block):
            """The rows diag(coefficients[:, j]) @ block for every joint j, joint after joint."""
            return sp.diags(coefficients.T.ravel()) @ sp.vstack([block] * n, format="csr")

        # per joint: the acceleration at the nodes, then mid-interval
        self.accel = (per_joint(np.concatenate([d2[inner], m2]), sp.vstack([X[inner], x_mid]))
                      + per_joint(0.5 * np.concatenate([d1[inner], m1]), sp.vstack([P[inner], p_mid]))).tocsr()
        self.accel_bound = LIMIT_MARGIN * np.concatenate([np.full(N - 2 + len(mid), acceleration[j]) for j in range(n)])
        # per joint: node i on interval i (its left end), then on interval i - 1 (its right end)
        self.jerk = (per_joint(1.5 * np.concatenate([d2[inner], d2[inner]]), sp.vstack([P[inner], P[inner]]))
                     + per_joint(0.5 * np.concatenate([d1[inner], d1[inner]]), sp.vstack([curvature[1:], curvature[:-1]]))
                     + per_joint(np.concatenate([after[inner], before[inner]]), sp.vstack([X[inner], X[inner]]))).tocsr()
        # the jerk ramps at the ends are where the pieces' jerk exceeds the nodes' most (by up to 8 %
        # on the seeded sweeps, through the frozen √x): aim lower on the first and last 3 nodes
        margin = np.full(N - 2, LIMIT_MARGIN)
        margin[:3] = margin[-3:] = END_JERK_MARGIN
        self.jerk_bound = np.concatenate([np.tile(margin, 2) * jerk[j] for j in range(n)])
        self.jerk_limits = np.repeat(jerk, 2 * (N - 2))
        with np.errstate(divide="ignore"):
            bound = np.min(velocity**2 / np.maximum(d1**2, 1e-300), axis=1)
            mid_bound = np.min(velocity**2 / np.maximum(m1**2, 1e-300), axis=1)
        self.velocity_bound = LIMIT_MARGIN**2 * bound
        self.velocity_bound[[0, -1]] = 0.0
        # x_mid <= the velocity bound, and x_mid >= (x_i + x_{i+1}) / 4, which keeps the quadratic
        # x >= x_i (1 - w)² + x_{i+1} w² > 0 across the interval (w in [0, 1]): a finite time
        self.mid = sp.vstack([x_mid, x_mid - 0.25 * (X[1:N - 2] + X[2:N - 1])], format="csr")
        self.mid_low = np.concatenate([np.full(len(mid), -np.inf), np.zeros(len(mid))])
        self.mid_bound = np.concatenate([LIMIT_MARGIN**2 * mid_bound, np.full(len(mid), np.inf)])
        w = np.zeros(N)
        w[:-1] += 0.5 * h
        w[1:] += 0.5 * h
        self.weights = w
        # every program has the same rows (the first with the jerk rows unbounded) and the jerk
        # programs the same matrix (√x frozen divides the jerk rows' bounds), so HiGHS keeps its
        # factorisation and basis from one jerk program to the next and only the bounds change:
        # its dual simplex then takes tens of iterations, not thousands
        self.matrix = sp.vstack([self.accel, self.mid, self.equality, self.jerk], format="csr")
        self.num_fixed_rows = self.matrix.shape[0] - self.jerk.shape[0]
        zeros = np.zeros(self.equality.shape[0])
        self.row_low = np.concatenate([-self.accel_bound, self.mid_low, zeros, np.full(self.jerk.shape[0], -np.inf)])
        self.row_high = np.concatenate([self.accel_bound, self.mid_bound, zeros, np.full(self.jerk.shape[0], np.inf)])
        self.solver, self.scale, self.jerk_programs, self.status = None, np.ones(2 * N), 0, ""

    def solve(self, previous, growth: float) -> tuple[np.ndarray, np.ndarray]:
        """(x, p) of the LP; without ``previous`` (x, p) the jerk is left out (a bang-bang profile
        with continuous s̈); with it, x grows by at most the factor ``growth`` (the trust region).

        HiGHS now and then stops short of the optimum on a program it has warm-started (status
        "Unknown": numerical trouble, never infeasibility: x = 0 meets every row); the program is
        then solved again from a fresh start, and only a second failure is an error (naming the
        rows in the program and what to change)."""
        N = self.num_nodes
        upper = self.velocity_bound.copy()
        if previous is not None:
            upper = np.minimum(upper, growth * previous[0])
        lower = np.concatenate([np.zeros(N), np.full(N, -np.inf)])
        high = np.concatenate([upper, np.full(N, np.inf)])
        lower[[N, 2 * N - 1]] = high[[N, 2 * N - 1]] = 0.0
        if previous is None:
            self._start(np.ones(2 * N))
        else:
            if not self.jerk_programs:
                # columns scaled to the first program's solution (x spans 1e-6 near the ends to 1
                # mid-path, beyond HiGHS's absolute tolerances)
                self._start(self._scale(*previous), None if self.solver is None else self.solver.getBasis())
            self.jerk_programs += 1
            ends = [1, 2, N - 3, N - 2]  # the nodes next to the ends weigh nothing in the sum but their time,
            lower[ends] = np.minimum(previous[0][ends] / growth, high[ends])  # 3 h / √x, is long: they fall by the trust region's factor at most
            self._set_jerk_rows(previous[0] * growth)
            self._set_time_weights(previous[0])
        z = self._run(lower, high)
        if z is None and previous is not None:  # from a fresh start, scaled to the last iterate
            self._start(self._scale(*previous))
            self.jerk_programs = 1
            self._set_jerk_rows(previous[0] * growth)
            self._set_time_weights(previous[0])
            z = self._run(lower, high)
        if z is None and previous is not None and lower[1] > 0:  # without the floor at the ends
            lower[[1, 2, N - 3, N - 2]] = 0.0
            z = self._run(lower, high)
        if z is None:
            rows = ("velocity_limit and acceleration_limit" if previous is None else
                    "velocity_limit, acceleration_limit and jerk_limit (the jerk linearised at the last iterate)")
            raise InfeasibleTimingError(
                f"the timing's linear program on {N} nodes ({rows}) failed: HiGHS reports {self.status!r} (numerical "
                f"trouble: x = 0 meets every row); give fewer grid_points (e.g. {max(20, N // 2)}), or limits closer "
                "to each other in size across the joints", field=("path",))
        z = z * self.scale
        return np.maximum(z[:N], 0.0), z[N:]

    def _set_time_weights(self, x_previous: np.ndarray) -> None:
        """The objective of a jerk program: the time's decrease to first order at the last iterate,
        Σ h / (2 x^(3/2)) δx (the plain Σ h x let a program stop the path at a node, x = 0, to
        speed up its neighbours: an infinite time)."""
        x = np.maximum(x_previous, 1e-6 * x_previous.max())
        weights = self.weights / x**1.5
        weights = weights / weights[1:-1].max()
        columns = np.arange(self.num_nodes, dtype=np.int32)
        self.solver.changeColsCost(self.num_nodes, columns, -weights * self.scale[:self.num_nodes])

    def _set_jerk_rows(self, x_previous: np.ndarray) -> None:
        """The jerk rows' bounds: the jerk limit over √x frozen at the last iterate."""
        with np.errstate(divide="ignore"):
            bound = self.jerk_bound / np.tile(np.sqrt(np.maximum(x_previous[1:-1], 0.0)), 2 * self.num_joints)
        rows = np.arange(self.num_fixed_rows, self.matrix.shape[0], dtype=np.int32)
        self.solver.changeRowsBounds(len(rows), rows, -bound, bound)

    def jerk_ratio(self, x: np.ndarray, p: np.ndarray) -> float:
        """The largest |q⃛| over its limit at the nodes of the iterate (x, p), with its own √x."""
        rates = np.tile(np.sqrt(np.maximum(x[1:-1], 0.0)), 2 * self.num_joints)
        return float(np.max(np.abs(self.jerk @ np.concatenate([x, p])) * rates / self.jerk_limits))

    def _start(self, scale: np.ndarray, basis=None) -> None:
        """A HiGHS model of the programs with columns scaled by ``scale``, from ``basis`` (None:
        HiGHS's own start)."""
        matrix = self.matrix @ scipy.sparse.diags(scale)
        cost = np.concatenate([-self.weights, np.zeros(self.num_nodes)]) * scale
        lp = highspy.HighsLp()
        lp.num_col_, lp.num_row_ = len(cost), matrix.shape[0]
        lp.col_cost_, lp.col_lower_, lp.col_upper_ = cost, np.zeros(len(cost)), np.zeros(len(cost))
        lp.row_lower_, lp.row_upper_ = self.row_low, self.row_high
        lp.a_matrix_.format_ = highspy.MatrixFormat.kRowwise
        lp.a_matrix_.num_col_, lp.a_matrix_.num_row_ = matrix.shape[1], matrix.shape[0]
        lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = matrix.indptr, matrix.indices, matrix.data
        self.solver = _QuietHighs()
        self.solver.passModel(lp)
        if basis is not None:
            self.solver.setBasis(basis)
        self.scale, self.jerk_programs = scale, 0

    def _run(self, lower: np.ndarray, upper: np.ndarray) -> np.ndarray | None:
        """The solution (scaled columns) of the program with these column bounds, None if HiGHS
        does not find it optimal (``status`` says why)."""
        columns = np.arange(len(lower), dtype=np.int32)
        self.solver.changeColsBounds(len(columns), columns, lower / self.scale, upper / self.scale)
        self.solver.run()
        status = self.solver.getModelStatus()
        if status != highspy.HighsModelStatus.kOptimal:
            self.status = self.solver.modelStatusToString(status)
            return None
        return np.asarray(self.solver.getSolution().col_value)

    def _scale(self, x: np.ndarray, p: np.ndarray) -> np.ndarray:
        """Column scales: x at the given iterate, p at the larger of its value and x / h."""
        h = np.diff(self.s)
        spacing = np.minimum(np.append(h, h[-1]), np.insert(h, 0, h[0]))
        x_scale = np.maximum(x, 1e-9 * x.max())
        return np.concatenate([x_scale, np.maximum(np.abs(p), x_scale / spacing)])


def _midpoints(s: np.ndarray, x: np.ndarray, p: np.ndarray):
    """(s, x, p, time from the interval's start [s]) at the middle (in s) of every interval: x
    quadratic inside, x ∝ distance^(4/3) on the end intervals."""
    h = np.diff(s)
    half = 0.5 * h
    curvature = (p[1:] - p[:-1]) / h
    x_mid = x[:-1] + p[:-1] * half + 0.5 * curvature * half**2
    p_mid = p[:-1] + curvature * half
    u = 0.5 * (1 + _GAUSS_NODES)[None, :] * half[:, None]
    inside = x[:-1, None] + p[:-1, None] * u + 0.5 * curvature[:, None] * u**2
    dt = 0.5 * half * (_GAUSS_WEIGHTS / np.sqrt(np.maximum(inside, 1e-300))).sum(axis=1)
    x_mid[0], x_mid[-1] = x[1] * 2 ** (-4 / 3), x[-2] * 2 ** (-4 / 3)
    p_mid[0], p_mid[-1] = 8 * x_mid[0] / (3 * h[0]), -8 * x_mid[-1] / (3 * h[-1])
    dt[0] = 3 * h[0] * 2 ** (-1 / 3) / np.sqrt(x[1])
    dt[-1] = 3 * h[-1] * (1 - 2 ** (-1 / 3)) / np.sqrt(x[-2])
    return s[:-1] + half, x_mid, p_mid, dt


def _samples(path, program: _Program, x: np.ndarray, p: np.ndarray):
    """(t, [q, q̇, q̈] (K, 3, n), [s, ṡ, s̈] (K, 3)) at the nodes and the middle of every interval
    (the knots of the pieces), at rest at both ends."""
    nodes = _node_times(program.s, x, p)
    s_mid, x_mid, p_mid, dt_mid = _midpoints(program.s, x, p)
    order = np.argsort(np.concatenate([program.s, s_mid]), kind="stable")
    s = np.concatenate([program.s, s_mid])[order]
    x = np.concatenate([x, x_mid])[order]
    p = np.concatenate([p, p_mid])[order]
    t = np.concatenate([nodes, nodes[:-1] + dt_mid])[order]
    d1, d2 = _path_derivatives(program.derivatives[:2], s)
    rate = np.sqrt(np.maximum(x, 0.0))
    q = path.vector_values(s).T
    qd = d1 * rate[:, None]
    qdd = d1 * (0.5 * p)[:, None] + d2 * x[:, None]
    return t, np.stack([q, qd, qdd], axis=1), np.stack([s, rate, 0.5 * p], axis=1)


def exact_peaks(knots, coefficients) -> np.ndarray:
    """max |q̇|, |q̈|, |q⃛| per joint over piecewise quintics (monomial ``coefficients`` (K, 6, n)
    in t - knots[k]), exact to round-off: (3, n)."""
    _, _, (velocity, acceleration, jerk) = sigma_derivatives(knots, np.asarray(coefficients, dtype=float), 3)
    v_peak, _, a_peak, _ = rate_peaks(velocity, acceleration)
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = np.where(jerk[2] != 0, -jerk[1] / (2 * jerk[2]), np.nan)
    vertex = np.where(np.abs(vertex) <= 1, vertex, np.nan)
    candidates = [np.abs(jerk[0] - jerk[1] + jerk[2]), np.abs(jerk[0] + jerk[1] + jerk[2]),
                  np.nan_to_num(np.abs(jerk[0] + jerk[1] * vertex + jerk[2] * vertex**2), nan=0.0)]
    j_peak = np.max(candidates, axis=0)
    return np.stack([v_peak.max(axis=0), a_peak.max(axis=0), j_peak.max(axis=0)])


def _deviation(path, knots, joint_coefficients, path_samples) -> float:
    """Upper bound [rad] of the distance of the pieces from the path: at 4 points inside every
    piece, |q_piece(t) - q(s_piece(t))|, s_piece the quintic Hermite of (s, ṡ, s̈)."""
    s_coefficients = quintic_hermite_coefficients(knots, path_samples[:, :, None], path_samples[:, :, None])
    tau = np.array([0.2, 0.4, 0.6, 0.8])[None, :] * np.diff(knots)[:, None]  # (K, 4)
    powers = tau[:, :, None] ** np.arange(6)  # (K, 4, 6)
    q = np.einsum("kfp,kpn->kfn", powers, joint_coefficients).reshape(-1, joint_coefficients.shape[2])
    s = np.clip(np.einsum("kfp,kp->kf", powers, s_coefficients[:, :, 0]).ravel(), path.start_time(), path.end_time())
    return float(np.abs(q - path.vector_values(s).T).max())


def _iterate(program: _Program, iterations: int, start=None) -> tuple[np.ndarray, np.ndarray, int]:
    """(x, p, the programs with the jerk solved) of the best of the sequential linear programs:
    the first without the jerk (or the given ``start`` (x, p) instead), then up to
    ``iterations`` with it, each linearised at the one before, with √x frozen at the most the
    trust region lets x grow to (so an iterate keeps the jerk at the nodes). An iterate is judged
    by its time stretched until the jerk at the nodes holds with its own √x; where one is longer
    than the best so far, the trust region is halved. They stop once the best shortens by < 0.2 %
    (after 4), or at a degenerate iterate or a failing program after the first (the best so far
    is kept). From a ``start``, an InfeasibleTimingError where no program succeeds."""
    x, p = best = program.solve(None, np.inf) if start is None else start
    best_time, growth, solved = np.inf, TRUST_REGION, 0
    while solved < iterations:
        try:
            x, p = program.solve((x, p), growth)
        except InfeasibleTimingError:
            if not solved:
                raise
            break
        solved += 1
        if not np.all(x[1:-1] > 0):  # a degenerate iterate: keep the best
            break
        estimate = _node_times(program.s, x, p)[-1] * max(1.0, program.jerk_ratio(x, p)) ** (1 / 3)
        if estimate < best_time:
            shorter = 1 - estimate / best_time
            best, best_time = (x, p), estimate
            if solved >= 4 and shorter < 2e-3:
                break
        else:
            growth = 1 + 0.5 * (growth - 1)
    if start is not None and best is start:
        raise InfeasibleTimingError("no program from the coarse grid's solution gave a motion", field=("path",))
    return (*best, solved)


class _Pieces(NamedTuple):
    """The quintic pieces of a solution (x, p), stretched so every limit holds."""

    t: np.ndarray  # knots [s]
    joint_samples: np.ndarray  # (K, q/q̇/q̈, n)
    path_samples: np.ndarray  # (K, s/ṡ/s̈)
    coefficients: np.ndarray  # (K - 1, 6, n)
    ratio: np.ndarray  # exact peaks over the limits (3, n)
    stretch: float
    deviation: float  # [rad] from the path (without the spline's fit)


def _better(coarse: _Pieces, fine: _Pieces, tolerance: float) -> _Pieces:
    """The finer grid's motion where it keeps to the path within ``tolerance`` [rad] and is no
    longer, or where the coarse one strays; else the coarse grid's."""
    if coarse.deviation > tolerance or (fine.deviation <= tolerance and fine.t[-1] <= coarse.t[-1]):
        return fine
    return coarse


def _pieces(path, program: _Program, x: np.ndarray, p: np.ndarray, limits: np.ndarray) -> _Pieces:
    """The motion of the solution (x, p) as quintic Hermite pieces through the nodes and the
    middle of every interval, with the repair (:func:`stretched`)."""
    t, joint_samples, path_samples = _samples(path, program, x, p)
    coefficients = quintic_hermite_coefficients(t, joint_samples, joint_samples)
    t, joint_samples, coefficients, ratio, stretch = stretched(t, joint_samples, coefficients, limits, 1e-6)
    path_samples = path_samples / stretch ** np.arange(3)[None, :]
    return _Pieces(t, joint_samples, path_samples, coefficients, ratio, stretch,
                   _deviation(path, t, coefficients, path_samples))


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


def time_path(path, velocity_limit, acceleration_limit, jerk_limit=None, *, grid_points: int = 200,
              iterations: int = 8, max_duration: float = 600.0) -> SmoothTiming:
    """Time ``path`` from rest to rest under per-joint velocity, acceleration and jerk limits.

    Args:
        path: a Drake Trajectory q(s) (n x 1, C2: q'' may not jump at a break) or joint samples
            (N, n) [rad] in path order (:func:`check_path`).
        velocity_limit, acceleration_limit: per joint [rad/s, rad/s²], > 0 (scalar or (n,)).
        jerk_limit: per joint [rad/s³], > 0; None: 10 /s × the acceleration limit.
        grid_points: nodes of the linear programs evenly in time, besides the path's breaks (more:
            never longer, slower; 100 is within 0.05 % of 4000 on seeded waypoint paths, and 2.3
            times Toppra's CPU against 3.9 at 200, but 200 times dense goals up to 8 % faster).
        iterations: the most linear programs with the jerk on each grid (they stop once T
            shortens by < 0.2 %).
        max_duration: the longest motion accepted [s]: limits so small that the motion would
            last longer are refused.

    Returns:
        :class:`SmoothTiming`: the law, the Drake trajectory and what was checked.

    Raises:
        InfeasibleTimingError: a cusp or a corner (:func:`check_path`), limits too small for the
            path (a motion longer than ``max_duration``), a linear program that fails, or a
            motion that leaves the path by more than :data:`PATH_TOLERANCE`.
        DrakeTrajError: malformed limits (naming the limit and the joint) or path.

    Any abort of Drake's on the way (a ``SystemExit``, which would end the caller's interpreter) is
    turned into an :class:`InfeasibleTimingError` naming the path: the inputs that reach one are
    checked first, this is the net under them.
    """
    try:
        return _time_path(path, velocity_limit, acceleration_limit, jerk_limit, grid_points=grid_points,
                          iterations=iterations, max_duration=max_duration)
    except SystemExit as error:
        raise InfeasibleTimingError(f"the path cannot be timed: Drake refused it ({str(error.code).strip()[:300]})",
                                    field=("path",)) from None


def _time_path(path, velocity_limit, acceleration_limit, jerk_limit=None, *, grid_points: int = 200,
               iterations: int = 8, max_duration: float = 600.0) -> SmoothTiming:
    """The work of :func:`time_path`."""
    grid_points = whole_number(grid_points, "grid_points", minimum=20, maximum=MAX_GRID_POINTS)
    path, fit = check_path(path)
    velocity, acceleration, jerk = joint_limits(path.rows(), velocity_limit, acceleration_limit, jerk_limit)
    max_duration = positive_scalar(max_duration, "max_duration", "s")
    s_all = np.linspace(path.start_time(), path.end_time(), 2001)
    travel = np.trapezoid(np.abs(path.MakeDerivative(1).vector_values(s_all)), s_all, axis=1)  # per joint [rad]
    # A joint's travel D is made of rest-to-rest pieces (it stops where it turns back), and the sums
    # of their least durations are at least those of D (the roots are concave). Checked before any
    # array is made.
    check_least_durations(travel, (velocity, acceleration, jerk), max_duration, "travels")
    limits = np.stack([velocity, acceleration, jerk])
    pieces, solved, previous = None, 0, None
    breaks = len(path.get_segment_times()) - 2  # nodes of every grid: levels they dwarf are skipped
    levels = [points for points in GRID_LEVELS if breaks <= 4 * points and points < grid_points] + [grid_points]
    for points in levels:
        # each grid started from the last one's solution (s, x, p), the first (or one after a grid
        # whose path speed fell to 0: too few nodes at a tight turn) from the bang-bang profile
        if previous is None:
            s, initial = _grid(path, velocity, acceleration, points), None
        else:
            s, *initial = _refined(path, *previous, points)
        program = _Program(path, s, velocity, acceleration, jerk)
        try:
            x, p, more = _iterate(program, iterations, start=initial)
        except InfeasibleTimingError:
            if pieces is None and points == grid_points:
                raise
            continue  # the coarser grids' motion stands
        solved += more
        if not np.all(x[1:-1] > 0):
            previous = None
            if pieces is None and points == levels[-1] and 2 * points <= min(4 * grid_points, MAX_GRID_POINTS):
                levels.append(2 * points)  # no motion yet: twice the nodes in time (a hairpin two nodes wide)
            continue
        previous = (s, x, p)
        finer = _pieces(path, program, x, p, limits)
        pieces = finer if pieces is None else _better(pieces, finer, PATH_TOLERANCE - fit)
    if pieces is None:
        k = int(np.argmin(x[1:-1])) + 1
        raise InfeasibleTimingError(
            f"the limits are too small for the path: the path speed falls to 0 at s = {s[k]:.6g} (velocity_limit, "
            "acceleration_limit or jerk_limit)", field=("path",))
    t, joint_samples, coefficients, ratio, stretch = (pieces.t, pieces.joint_samples, pieces.coefficients,
                                                      pieces.ratio, pieces.stretch)
    if not t[-1] <= max_duration:
        raise InfeasibleTimingError(
            f"the limits are too small for the path: the motion would last {t[-1]:.4g} s > max_duration "
            f"{max_duration:g} s (velocity_limit, acceleration_limit or jerk_limit)", field=("path",))
    if not np.all(ratio <= 1.0):
        k, j = np.unravel_index(np.argmax(ratio), ratio.shape)
        raise InfeasibleTimingError(f"the timed motion exceeds the {('velocity', 'acceleration', 'jerk')[k]} limit of "
                                    f"{joint_label(j)} by a factor {ratio[k, j]:.6g} after the repair", field=("path",))
    deviation = fit + pieces.deviation
    if deviation > PATH_TOLERANCE:
        raise InfeasibleTimingError(
            f"the timed motion leaves the path by {deviation:.3g} rad > {PATH_TOLERANCE:g} rad (grid_points "
            f"{grid_points} too few for this path's curvature: give more)", field=("path",))
    law = HermiteLaw(t, joint_samples, joint_samples)
    return SmoothTiming(law, coefficients, float(t[-1]), path, stretch, ratio, deviation, solved)
