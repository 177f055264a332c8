"""Smooth, jerk-limited, near-time-optimal timing of a joint path (docs/smooth_timing.md):
:func:`time_path`, the linear programs (:mod:`.program`) solved on grids of more and more nodes
(:mod:`.grid`), the best motion kept.

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

from typing import NamedTuple

import numpy as np

from drake_traj.errors import joint_label
from drake_traj.planners.laws.hermite import HermiteLaw, quintic_hermite_coefficients
from drake_traj.planners.timing.grid import initial_grid, node_samples, node_times, refined_grid
from drake_traj.planners.timing.limits import check_least_durations, joint_limits
from drake_traj.planners.timing.motion import InfeasibleTimingError, SmoothTiming, stretched
from drake_traj.planners.timing.paths import PATH_TOLERANCE, checked_path
from drake_traj.planners.timing.program import solve_on_grid
from drake_traj.validation import positive_scalar, whole_number

__all__ = ["GRID_LEVELS", "MAX_GRID_POINTS", "time_path"]

GRID_LEVELS = (20, 50, 100, 250, 1000)
"""The grids solved before the one asked for (those with fewer nodes, and at least a quarter as
many as the path's breaks, which are nodes of every grid): each is started from the last one's solution (nodes evenly spaced in its time, x interpolated) and the shortest motion on
the path is kept, so more ``grid_points`` are not longer. Solved alone from the bang-bang start,
x near the ends grew only by the trust region's factor per program: 1000 nodes ended up to 3 times
longer than 200, and 100 nodes 1.7 % longer than 20 on a short path."""

MAX_GRID_POINTS = 4000
"""Nodes of the timing's linear programs at most (a program of N nodes has 2N variables and about
4nN constraints; 4000 nodes take seconds, a million would not finish)."""


def _deviation(values, knots, joint_coefficients, path_samples) -> float:
    """Upper bound [rad] of the distance of the pieces from the path: at 4 points inside every
    piece, |q_piece(t) - q(s_piece(t))|, s_piece the quintic Hermite of (s, ṡ, s̈)."""
    s_coefficients = quintic_hermite_coefficients(knots, path_samples[:, :, None], path_samples[:, :, None])
    tau = np.array([0.2, 0.4, 0.6, 0.8])[None, :] * np.diff(knots)[:, None]  # (K, 4)
    powers = tau[:, :, None] ** np.arange(6)  # (K, 4, 6)
    q = np.einsum("kfp,kpn->kfn", powers, joint_coefficients).reshape(-1, joint_coefficients.shape[2])
    path = values.path
    s = np.clip(np.einsum("kfp,kp->kf", powers, s_coefficients[:, :, 0]).ravel(), path.start_time(), path.end_time())
    return float(np.abs(q - values(s, 0)[0]).max())


class _Pieces(NamedTuple):
    """The quintic pieces of a solution (x, p), stretched so every limit holds."""

    t: np.ndarray  # knots [s]
    joint_samples: np.ndarray  # (K, q/q̇/q̈, n)
    path_samples: np.ndarray  # (K, s/ṡ/s̈)
    coefficients: np.ndarray  # (K - 1, 6, n)
    ratio: np.ndarray  # exact peaks over the limits (3, n)
    stretch: float
    deviation: float  # [rad] from the path (without the spline's fit)


def _shortest(solutions, limits: np.ndarray, tolerance: float) -> _Pieces:
    """The shortest motion of the grids' ``solutions`` (program, x, p), coarse to fine, that keeps to
    the path within ``tolerance`` [rad] (of equal ones the finer grid's), or where none does the
    finest grid's. The pieces (their exact check, repair and deviation: the cost) are made in the
    order of the solutions' times at the nodes, which the repair only stretches, until that time
    exceeds the shortest motion found: most often once or twice, not once per grid."""
    bounds = [node_times(program.s, x, p)[-1] for program, x, p in solutions]
    made, best = {}, None  # best: (T, -k) of the shortest motion that keeps to the path so far
    for k in sorted(range(len(solutions)), key=lambda k: (bounds[k], -k)):
        if best is not None and bounds[k] > best[0]:
            break
        made[k] = _pieces(*solutions[k], limits)
        if made[k].deviation <= tolerance and (best is None or (made[k].t[-1], -k) < best):
            best = (made[k].t[-1], -k)
    return made[len(solutions) - 1 if best is None else -best[1]]


def _pieces(program, x: np.ndarray, p: np.ndarray, limits: np.ndarray) -> _Pieces:
    """The motion of the solution (x, p) of ``program`` (its grid and the path's values) as
    quintic Hermite pieces through the nodes and the middle of every interval, with the repair
    (:func:`stretched`)."""
    t, joint_samples, path_samples = node_samples(program, x, p)
    coefficients = quintic_hermite_coefficients(t, joint_samples, joint_samples)
    t, joint_samples, coefficients, ratio, stretch = stretched(t, joint_samples, coefficients, limits, 1e-6)
    path_samples = path_samples / stretch ** np.arange(3)[None, :]
    return _Pieces(t, joint_samples, path_samples, coefficients, ratio, stretch,
                   _deviation(program.values, t, coefficients, path_samples))


def time_path(path, velocity_limit, acceleration_limit, jerk_limit=None, *, grid_points: int = 200,
              iterations: int = 8, max_duration: float = 600.0) -> SmoothTiming:
    """Time ``path`` from rest to rest under per-joint velocity, acceleration and jerk limits.

    Args:
        path: a Drake Trajectory q(s) (n x 1, C2: q'' may not jump at a break) or joint samples
            (N, n) [rad] in path order (:func:`check_path`).
        velocity_limit, acceleration_limit: per joint [rad/s, rad/s²], > 0 (scalar or (n,)).
        jerk_limit: per joint [rad/s³], > 0; None: 10 /s × the acceleration limit.
        grid_points: nodes of the linear programs evenly in time, besides the path's breaks (more:
            never longer, slower; 100 is within 0.05 % of 4000 on seeded waypoint paths and takes
            0.54 times Drake's Toppra's CPU in the median against 0.9 at 200 (docs/smooth_timing.md,
            "Planning time"), but 200 times dense goals up to 8 % faster).
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
    path, fit, values = checked_path(path)
    velocity, acceleration, jerk = joint_limits(path.rows(), velocity_limit, acceleration_limit, jerk_limit)
    max_duration = positive_scalar(max_duration, "max_duration", "s")
    s_all = np.linspace(path.start_time(), path.end_time(), 2001)
    travel = np.trapezoid(np.abs(values(s_all, 1)[0]), s_all, axis=0)  # per joint [rad]
    # A joint's travel D is made of rest-to-rest pieces (it stops where it turns back), and the sums
    # of their least durations are at least those of D (the roots are concave). Checked before any
    # array is made.
    check_least_durations(travel, (velocity, acceleration, jerk), max_duration, "travels")
    limits = np.stack([velocity, acceleration, jerk])
    solutions, solved, previous = [], 0, None
    breaks = len(path.get_segment_times()) - 2  # nodes of every grid: levels they dwarf are skipped
    levels = [points for points in GRID_LEVELS if breaks <= 4 * points and points < grid_points] + [grid_points]
    for points in levels:
        # each grid started from the last one's solution (s, x, p), the first (or one after a grid
        # whose path speed fell to 0: too few nodes at a tight turn) from the bang-bang profile
        if previous is None:
            (s, *guess), initial = initial_grid(values, velocity, acceleration, points), None
        else:
            (s, *initial), guess = refined_grid(path, *previous, points), None
        try:
            program, x, p, more = solve_on_grid(values, s, (velocity, acceleration, jerk), iterations, start=initial,
                                                guess=guess)
        except InfeasibleTimingError:
            if not solutions and points == grid_points:
                raise
            continue  # the coarser grids' motion stands
        solved += more
        if not np.all(x[1:-1] > 0):
            previous = None
            if not solutions and points == levels[-1] and 2 * points <= min(4 * grid_points, MAX_GRID_POINTS):
                levels.append(2 * points)  # no motion yet: twice the nodes in time (a hairpin two nodes wide)
            continue
        previous = (s, x, p)
        solutions.append((program, x, p))
    if not solutions:
        k = int(np.argmin(x[1:-1])) + 1
        raise InfeasibleTimingError(
            f"the limits are too small for the path: the path speed falls to 0 at s = {s[k]:.6g} (velocity_limit, "
            "acceleration_limit or jerk_limit)", field=("path",))
    pieces = _shortest(solutions, limits, PATH_TOLERANCE - fit)
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
    law = HermiteLaw(t, joint_samples, joint_samples, pieces=coefficients)  # the checked pieces themselves
    return SmoothTiming(law, coefficients, float(t[-1]), path, stretch, ratio, deviation, solved)
