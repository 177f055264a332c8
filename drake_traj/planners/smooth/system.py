"""The smooth planners as Drake systems: :class:`SmoothPlanner`, a :class:`~drake_traj.planners.timing.SmoothTiming`
run as a time law (speed override, station, preflight and cell checks as for every time law),
and their ``make``: through joint waypoints without stopping (:func:`make_smooth_waypoints`) and
the joint path of Pająk 2024's preflight re-timed (:func:`make_retimed_pajak`)."""

import numpy as np

from drake_traj.planners.base import TimeLawPlanner, start_and_goals
from drake_traj.planners.pajak import PajakPlanner
from drake_traj.planners.smooth.config import RetimedPajakConfig, SmoothWaypointsConfig
from drake_traj.planners.smooth.law import pajak_samples, timed, waypoints_timing
from drake_traj.planners.timing import MAX_GRID_POINTS, SmoothTiming, jerk_limited_limits
from drake_traj.robots import Robot
from drake_traj.validation import instance_of, positive_vector, whole_number

__all__ = ["SmoothPlanner", "make_retimed_pajak", "make_smooth_waypoints"]


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


def make_smooth_waypoints(config: SmoothWaypointsConfig, robot: Robot, q_initial) -> SmoothPlanner:
    """The planner of ``config`` on ``robot`` from ``q_initial`` [rad]: the config checked
    (:meth:`~.config.SmoothWaypointsConfig.validate`), then the faster of stopping at every goal
    and passing them (:func:`~.law.waypoints_timing`)."""
    config.validate(robot)
    q = start_and_goals(q_initial, config.goals, robot.num_joints)
    limits = jerk_limited_limits(robot, config.velocity_limit, config.acceleration_limit, config.jerk_limit)
    return SmoothPlanner(waypoints_timing(q, limits, config.grid_points, robot), *limits,
                         tool_waypoints=robot.tool_position(q[1:]))


def make_retimed_pajak(config: RetimedPajakConfig, robot: Robot, q_initial) -> SmoothPlanner:
    """The planner of ``config`` on ``robot`` from ``q_initial`` [rad]: raises what the Pająk
    preflight raises (an unreachable waypoint, a stall, ...) and what the timing raises."""
    config.validate(robot)
    samples, velocity_limit, acceleration_limit = pajak_samples(PajakPlanner(config.pajak, q_initial, robot=robot))
    limits = jerk_limited_limits(robot, velocity_limit, acceleration_limit,
                                 config.jerk_limit)  # the limits the Pająk planner kept
    timing = timed(samples, "pajak", limits,
                   whole_number(config.grid_points, "grid_points", minimum=20, maximum=MAX_GRID_POINTS))
    return SmoothPlanner(timing, *limits,
                         tool_waypoints=np.asarray(config.pajak.waypoints, dtype=float)[:, :3], target_word="waypoint")
