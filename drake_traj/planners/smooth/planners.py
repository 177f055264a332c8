"""The smooth timing (:func:`~drake_traj.planners.smooth.timing.time_path`) as planners: through
joint waypoints without stopping (:class:`SmoothWaypointsConfig`), and the joint path of Pająk
2024's preflight re-timed (:class:`RetimedPajakConfig`). Both are time-law planners (speed
override, station, preflight and cell checks as for every time law)."""


from dataclasses import dataclass, field

import numpy as np
from pydrake.trajectories import PiecewisePolynomial

from drake_traj.errors import Cause, DrakeTrajError, joint_label
from drake_traj.planners.base import TimeLawPlanner, start_and_goals
from drake_traj.planners.baselines.ruckig import jerk_limited_limits
from drake_traj.planners.pajak import PajakConfig, PajakPlanner
from drake_traj.planners.smooth.moves import line_timing, stop_timing
from drake_traj.planners.smooth.timing import MAX_GRID_POINTS, SmoothTiming, time_path
from drake_traj.robots import Robot
from drake_traj.validation import instance_of, positive_vector, whole_number

MAX_GOALS = 2000  # goals of one smooth-waypoints task at most (0.05 rad apart: 100 rad of motion)

__all__ = ["RetimedPajakConfig", "SmoothPlanner", "SmoothWaypointsConfig", "make_retimed_pajak",
           "make_smooth_waypoints", "waypoint_path"]


class SmoothPlanner(TimeLawPlanner):
    """A :class:`SmoothTiming` run as a time law.

    Args:
        timing: the timed motion.
        velocity_limit, acceleration_limit, jerk_limit: the limits it was timed under, per joint.
        tool_waypoints: tool positions [m] the task passes through (base frame), (m, 3), for plots.
        target_word: the task's word for them ("goal": the config's goals; "waypoint": a re-timed
            Pająk task's), as a refusal names them ("on the way to goal k").
        speed_cap, update_period: as :class:`TimeLawPlanner`.
    """

    target_word = "goal"

    def __init__(self, timing: SmoothTiming, velocity_limit, acceleration_limit, jerk_limit, *,
                 tool_waypoints=None, target_word: str = "goal", speed_cap: float = 1.0, update_period: float = 0.001):
        instance_of(timing, SmoothTiming, "timing")
        n = len(timing.law.q_start)
        super().__init__(timing.law, positive_vector(velocity_limit, "velocity_limit", n),
                         positive_vector(acceleration_limit, "acceleration_limit", n), speed_cap=speed_cap,
                         update_period=update_period)
        self.timing = timing
        self.jerk_limit = positive_vector(jerk_limit, "jerk_limit", n)
        self._tool_waypoints = np.zeros((0, 3)) if tool_waypoints is None else np.asarray(tool_waypoints, float)
        self.target_word = instance_of(target_word, str, "target_word")

    def task_waypoints(self) -> np.ndarray:
        return self._tool_waypoints.copy()


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


def _timed(path, name: str, velocity, acceleration, jerk, grid_points: int) -> SmoothTiming:
    try:
        return time_path(path, velocity, acceleration, jerk, grid_points=grid_points)
    except DrakeTrajError as error:
        if error.field[:1] == ("path",):
            raise error.relocated((name, *error.field[1:]), f"{name}: {error}") from None
        raise


@dataclass
class SmoothWaypointsConfig:
    """Through joint waypoints without stopping, jerk-limited and near time-optimal: the
    scenario's ``planner: !SmoothWaypointsConfig`` entry.

    Attributes:
        goals: joint waypoints after the start [rad], one row of n per waypoint.
        velocity_limit, acceleration_limit: per joint; empty: the robot's joint-move limits.
        jerk_limit: per joint [rad/s³]; empty: 10 /s × the acceleration limit.
        grid_points: nodes of the timing's linear programs evenly in time, besides the path's
            breaks (more: never longer, slower).
    """

    goals: list[list[float]] = field(default_factory=list)
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)
    jerk_limit: list[float] = field(default_factory=list)
    grid_points: int = 200


def make_smooth_waypoints(config: SmoothWaypointsConfig, robot: Robot, q_initial) -> SmoothPlanner:
    """The planner of ``config`` on ``robot`` from ``q_initial`` [rad]: the faster of stopping at
    every goal (:func:`stop_timing`, Ruckig's time-synchronised moves: the optimum of one move)
    and passing them without stopping, along their line where they lie on one in order
    (:func:`line_timing`), else the smooth timing of the spline through them (:func:`time_path`).
    Stopping wins on some moves of a millimetre-radian or less (2 of 16 seeded tasks there); the
    spline's errors (a cusp, a joint range left) are raised."""
    q = start_and_goals(q_initial, config.goals, robot.num_joints)
    if len(q) - 1 > MAX_GOALS:
        raise DrakeTrajError(f"goals: {len(q) - 1} goals, at most {MAX_GOALS} (each is a knot of the path and a node of "
                             "the timing's programs): thin them out", field=("goals",))
    velocity, acceleration, jerk = jerk_limited_limits(robot, config.velocity_limit, config.acceleration_limit,
                                                       config.jerk_limit)
    path = waypoint_path(q)
    _check_joint_range(path, robot, "goals")
    grid_points = whole_number(config.grid_points, "grid_points", minimum=20, maximum=MAX_GRID_POINTS)
    try:
        # stopping at every goal: Ruckig's time-synchronised moves, the optimum of one move
        timing = stop_timing(q, velocity, acceleration, jerk)
    except DrakeTrajError as error:
        raise error.relocated(("goals",), f"goals: {error}") from None
    if len(path.get_segment_times()) > 2:  # without stopping: along one line, or the spline's timing
        if _on_one_line(q):
            through = line_timing(q[0], q[-1], velocity, acceleration, jerk)
        else:
            through = _timed(path, "goals", velocity, acceleration, jerk, grid_points)
        if through.duration <= timing.duration:
            timing = through
    return SmoothPlanner(timing, velocity, acceleration, jerk, tool_waypoints=robot.tool_position(q[1:]))


@dataclass
class RetimedPajakConfig:
    """Pająk 2024's task-space path, re-timed: the joint path of the Pająk planner's preflight (its
    ``plan()``), timed jerk-limited and near time-optimal under its own velocity and acceleration
    limits: the scenario's ``planner: !RetimedPajakConfig`` entry.

    Attributes:
        pajak: the Pająk task and settings that make the path (its limits are the timing's).
        jerk_limit: per joint [rad/s³]; empty: 10 /s × the acceleration limit.
        grid_points: nodes of the timing's linear programs.
    """

    pajak: PajakConfig = field(default_factory=PajakConfig)
    jerk_limit: list[float] = field(default_factory=list)
    grid_points: int = 250


def pajak_joint_path(config: PajakConfig, robot: Robot, q_initial) -> np.ndarray:
    """The joint samples [rad] (N, n) of the Pająk planner's planned motion (its preflight, one
    sample per update period up to the finish), the path the re-timed planner times."""
    return _pajak_samples(PajakPlanner(config, q_initial, robot=robot))


def _pajak_samples(planner: PajakPlanner) -> np.ndarray:
    """The planned motion's samples up to the task's finish (not the law's settling after it)."""
    plan = planner.plan()
    times = np.asarray(plan.get_segment_times())
    return plan.vector_values(times[times <= planner.planned_duration() + 1e-12]).T


def make_retimed_pajak(config: RetimedPajakConfig, robot: Robot, q_initial) -> SmoothPlanner:
    """The planner of ``config`` on ``robot`` from ``q_initial`` [rad]: raises what the Pająk
    preflight raises (an unreachable waypoint, a stall, ...) and what the timing raises."""
    instance_of(config.pajak, PajakConfig, "pajak")
    pajak = PajakPlanner(config.pajak, q_initial, robot=robot)
    samples = _pajak_samples(pajak)
    velocity, acceleration, jerk = jerk_limited_limits(robot, pajak.velocity_limit, pajak.acceleration_limit,
                                                       config.jerk_limit)  # the limits the Pająk planner kept
    timing = _timed(samples, "pajak", velocity, acceleration, jerk,
                    whole_number(config.grid_points, "grid_points", minimum=20, maximum=MAX_GRID_POINTS))
    return SmoothPlanner(timing, velocity, acceleration, jerk,
                         tool_waypoints=np.asarray(config.pajak.waypoints, dtype=float)[:, :3], target_word="waypoint")
