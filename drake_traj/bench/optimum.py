"""T_opt, the denominator of the bench's ``T_over_optimal``: Drake's Toppra's time-optimal duration
along a planner's own joint path, split at its stops, its grid refined until it converges. Joint
paths are in rad, limits in rad/s and rad/s^2 (scalar or per joint)."""

import numpy as np

from drake_traj.planners.baselines.toppra import geometric_path_from_samples, time_optimal_along_path
from drake_traj.robots import ur10e as robot

__all__ = ["converged_optimum", "optimal_duration"]

VELOCITY, ACCELERATION = robot.DEFAULT_JOINT_MOVE_VELOCITY, robot.DEFAULT_JOINT_MOVE_ACCELERATION
STOP_SPEED = 1e-3  # [rad/s]: a local minimum of the joint speed below this is a stop (optimal_duration)
OPTIMUM_TOLERANCE = 5e-4  # T_opt's grid is refined until T changes by less than this (0.05 %)
OPTIMUM_GRID_MAX = 32000  # [points] the finest grid tried for T_opt
# knots of the path's spline for Toppra, tried in turn: its reachability analysis fails on some
# splines of a path and not on others (Ruckig's moves on random_4: 200 knots fail on move 3,
# 50 pass; on move 2 the other way round; where both pass, T_opt differs by 0.3 %)
SPLINE_KNOTS = (200, 100, 50)


def optimal_duration(q, qd, velocity_limit=VELOCITY, acceleration_limit=ACCELERATION) -> tuple[float, str]:
    """(T_opt [s], reason): Toppra's time-optimal duration along the joint path q [rad] (N, 6)
    sampled with velocities qd [rad/s] (N, 6), under the joint limits [rad/s, rad/s^2] (scalar
    or per joint); reason is "" or why there is no T_opt (then T_opt is NaN).

    A planner that stops at waypoints leaves a path with corners there, which no timing can pass
    without stopping: the path is split at every stop and the pieces' optimal times are added.
    A stop is a sample at rest (|qd| <= 1e-6 rad/s) or a local minimum of |qd| below
    ``STOP_SPEED``: a stop between two 1 ms samples leaves the nearest one a few 10⁻⁶ rad/s from
    rest (Ruckig's stops: 3e-6 and 7e-6 rad/s on the bench's random_4; unsplit, Toppra found no
    parameterisation of 8 of its 20 paths). Toppra may find no parameterisation (a near-corner
    left where a planner slowed almost to rest without stopping), or fail numerically on one
    spline of the samples and not on a coarser one: each move is tried on splines of
    ``SPLINE_KNOTS`` knots in turn, and where all fail the reason is Toppra's.
    """
    q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
    speed = np.linalg.norm(qd, axis=1)
    moving = speed > 1e-6
    lowest = np.zeros(len(speed), dtype=bool)
    lowest[1:-1] = (speed[1:-1] <= speed[:-2]) & (speed[1:-1] <= speed[2:]) & (speed[1:-1] < STOP_SPEED)
    moving &= ~lowest
    moving[0] = moving[-1] = False  # the motion starts and (within the stop threshold) ends at rest
    starts = np.flatnonzero(moving[1:] & ~moving[:-1])  # last rest sample before each move
    stops = np.flatnonzero(~moving[1:] & moving[:-1]) + 1  # first rest sample after each move
    total = 0.0
    for number, (start, stop) in enumerate(zip(starts, stops)):
        piece = q[start : stop + 1]
        if np.ptp(piece, axis=0).max() <= 1e-6:
            continue
        for knots in SPLINE_KNOTS:
            try:
                total += converged_optimum(geometric_path_from_samples(piece, max_knots=knots), velocity_limit,
                                           acceleration_limit)
                break
            except ValueError as error:
                reason = f"no T_opt: move {number + 1} of {len(starts)}, splines of {SPLINE_KNOTS} knots: {error}"
        else:
            return float("nan"), reason
    return total, ""


def converged_optimum(path, velocity_limit, acceleration_limit) -> float:
    """Drake's Toppra's time-optimal duration [s] of ``path``, its grid refined until T changes by
    less than :data:`OPTIMUM_TOLERANCE`: its default grid first, then 2000, 4000, ... points evenly
    spaced in s (at most :data:`OPTIMUM_GRID_MAX`). Toppra's T depends on its grid: on its default
    grid it was 0.37 % longer than converged on sim 3's path and 1.8 % on quintic_ptp's samples
    joined without their stops (measured), which made every T / T_opt read against it optimistic.
    Raises ValueError where Toppra finds no parameterisation on its default grid."""
    previous = time_optimal_along_path(path, velocity_limit, acceleration_limit)[0]
    points = 2000
    while points <= OPTIMUM_GRID_MAX:
        grid = np.linspace(path.start_time(), path.end_time(), points)
        try:
            current = time_optimal_along_path(path, velocity_limit, acceleration_limit, grid_points=grid)[0]
        except ValueError:  # a finer grid that fails leaves the last one's answer
            return previous
        if abs(current - previous) <= OPTIMUM_TOLERANCE * current:
            return current
        previous, points = current, 2 * points
    return previous
