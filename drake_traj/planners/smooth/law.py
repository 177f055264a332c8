"""The timed motions of the smooth planners, from the shared timing
(:mod:`drake_traj.planners.timing`): through joint waypoints, the faster of stopping at each and
passing them (:func:`waypoints_timing`), and the joint path of Pająk 2024's preflight
(:func:`pajak_joint_path`) timed as any path (:func:`timed`). Joint positions in rad."""

import numpy as np

from drake_traj.errors import Cause, DrakeTrajError, joint_label
from drake_traj.planners.base import release_system
from drake_traj.planners.pajak import PajakConfig, PajakPlanner
from drake_traj.planners.timing import (MAX_GRID_POINTS, SmoothTiming, line_timing, stop_timing, time_path,
                                        waypoint_path)
from drake_traj.robots import Robot
from drake_traj.validation import whole_number

__all__ = ["pajak_joint_path", "pajak_samples", "timed", "waypoints_timing"]


def _on_one_line(q: np.ndarray) -> bool:
    """True where the waypoints (m + 1, n) [rad] lie on the segment from the first to the last, in
    order along it (within 1e-9 of its length or 1e-7 rad, rounding): the path through them is that segment, and a
    C2 spline through evenly spaced collinear goals is slow to time."""
    step = q[-1] - q[0]
    length = float(np.linalg.norm(step))
    if length == 0.0:
        return False
    along = (q - q[0]) @ step / length**2  # (m + 1,) the position along the segment, 0 to 1
    off = np.linalg.norm(q - q[0] - np.outer(along, step), axis=1).max()
    return bool(off <= max(1e-9 * length, 1e-7) and np.all(np.diff(along) >= -1e-12))


def _check_joint_range(path, robot: Robot, name: str) -> None:
    """A JOINT_RANGE error naming the joint where the path leaves the robot's position range."""
    s = np.linspace(path.start_time(), path.end_time(), 1001)
    q = path.vector_values(s).T
    low, high = robot.lower_limits, robot.upper_limits
    outside = (q < low) | (q > high)
    if np.any(outside):
        k, j = np.argwhere(outside)[0]
        raise DrakeTrajError(
            f"{name}: the smooth path through them leaves the range of {joint_label(j)} ([{low[j]:.4g}, {high[j]:.4g}] "
            f"rad) with q = {q[k, j]:.4g} rad at s = {s[k]:.4g} rad of {s[-1]:.4g}: move the waypoints inwards",
            field=(name,), cause=Cause.JOINT_RANGE)


def timed(path, name: str, limits, grid_points: int) -> SmoothTiming:
    """:func:`time_path` of ``path`` under ``limits`` (velocity, acceleration, jerk per joint), its
    errors about the path located at the config's field ``name``."""
    velocity, acceleration, jerk = limits
    try:
        return time_path(path, velocity, acceleration, jerk, grid_points=grid_points)
    except DrakeTrajError as error:
        if error.field[:1] == ("path",):
            raise error.relocated((name, *error.field[1:]), f"{name}: {error}") from None
        raise


def waypoints_timing(q, limits, grid_points, robot: Robot) -> SmoothTiming:
    """The motion through the start and goals ``q`` (m + 1, n) [rad] under ``limits`` (velocity,
    acceleration, jerk per joint): the faster of stopping at every goal (:func:`stop_timing`,
    Ruckig's time-synchronised moves: the optimum of one move) and passing them without stopping,
    along their line where they lie on one in order (:func:`line_timing`), else the smooth timing
    of the spline through them (:func:`time_path` on ``grid_points`` nodes). Stopping wins on some
    moves of a millimetre-radian or less (2 of 16 seeded tasks there); the spline's errors (a
    cusp, a joint range of ``robot`` left) are raised."""
    velocity, acceleration, jerk = limits
    path = waypoint_path(q)
    _check_joint_range(path, robot, "goals")
    grid_points = whole_number(grid_points, "grid_points", minimum=20, maximum=MAX_GRID_POINTS)
    try:
        # stopping at every goal: Ruckig's time-synchronised moves, the optimum of one move
        timing = stop_timing(q, velocity, acceleration, jerk)
    except DrakeTrajError as error:
        raise error.relocated(("goals",), f"goals: {error}") from None
    if len(path.get_segment_times()) > 2:  # without stopping: along one line, or the spline's timing
        if _on_one_line(q):
            through = line_timing(q[0], q[-1], velocity, acceleration, jerk)
        else:
            through = timed(path, "goals", limits, grid_points)
        if through.duration <= timing.duration:
            timing = through
    return timing


def pajak_joint_path(config: PajakConfig, robot: Robot, q_initial) -> np.ndarray:
    """The joint samples [rad] (N, n) of the Pająk planner's planned motion (its preflight, one
    sample per update period up to the finish), the path the re-timed planner times."""
    return pajak_samples(PajakPlanner(config, q_initial, robot=robot))[0]


def pajak_samples(planner: PajakPlanner) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(samples [rad] (N, n), velocity limit [rad/s] (n,), acceleration limit [rad/s²] (n,)): the
    Pająk ``planner``'s planned motion up to the task's finish (not the law's settling after it),
    and the limits it kept. The planner is released afterwards (:func:`release_system`), whether
    it planned or raised: it must not be used again."""
    try:
        plan = planner.plan()
        times = np.asarray(plan.get_segment_times())
        samples = plan.vector_values(times[times <= planner.planned_duration() + 1e-12]).T
        return samples, np.asarray(planner.velocity_limit), np.asarray(planner.acceleration_limit)
    finally:
        release_system(planner)
