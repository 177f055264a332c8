"""Boryga's loop as a Drake system: :class:`BorygaLoopPlanner`, a thin
:class:`~drake_traj.planners.base.TimeLawPlanner` around a :class:`~.law.RobotLoopLaw`, and
``make``."""

import numpy as np

from drake_traj.planners.base import TimeLawPlanner
from drake_traj.planners.boryga.config import BorygaConfig
from drake_traj.planners.boryga.figures import loop_path_figure
from drake_traj.planners.boryga.law import RobotLoopLaw, joint_speed_cap
from drake_traj.planners.boryga.path import plan_loop_path
from drake_traj.planners.boryga.placements import PAPER_LOOP, PLACED_ROBOTS, paper_loop_placement
from drake_traj.robots import Robot
from drake_traj.validation import at_field, limit_or_default

__all__ = ["BorygaLoopPlanner", "make"]


class BorygaLoopPlanner(TimeLawPlanner):
    """Boryga's loop motion on a robot under the planner contract: the joint law of
    :class:`RobotLoopLaw`, slowed by a constant clock rate
    (:func:`joint_speed_cap`) where it would break the joint limits.

    Args:
        law: the joint law.
        velocity_limit, acceleration_limit: per-joint limits to keep [rad/s or m/s, rad/s^2 or m/s^2].
    """

    target_word = "point"  # B, M and E are points 0, 1 and 2 (task_waypoints)

    def __init__(self, law, velocity_limit, acceleration_limit, *, update_period: float = 0.001):
        cap, self.peaks = joint_speed_cap(law, velocity_limit, acceleration_limit)
        super().__init__(law, velocity_limit, acceleration_limit, speed_cap=cap, update_period=update_period)
        self.robot = law.robot

    def figures(self) -> dict:
        return {"loop_path": loop_path_figure(self.law.plan, clock_rate=self.speed_cap)}

    def task_waypoints(self) -> np.ndarray:
        """B, M and E [m]."""
        geometry = self.law.plan.geometry
        return np.array([geometry.B, geometry.M, geometry.E])


def make(config: BorygaConfig, robot: Robot, q_initial) -> BorygaLoopPlanner:
    """The loop of ``config`` on ``robot`` (``q_initial`` gives the tool orientation, the IK
    branch and, for the default placement on robots other than Boryga's, the point B); the config
    checked first (:meth:`~.config.BorygaConfig.validate`)."""
    config = config.validate(robot)
    points = [config.B, config.M, config.E]
    if any(point.size for point in points):
        for name, point in zip(("B", "M", "E"), points):  # named before the path between them is solved
            try:
                robot.point_ik(point[None], q_initial)
            except ValueError as error:
                raise at_field(error, name) from error
    elif robot.name in PLACED_ROBOTS:
        placement = paper_loop_placement(robot.name)
        points = [placement.B, placement.M, placement.E]
    else:
        offset = robot.tool_position(np.asarray(q_initial, dtype=float)) - np.asarray(PAPER_LOOP["B"])
        points = [np.asarray(PAPER_LOOP[name]) + offset for name in ("B", "M", "E")]
    law = RobotLoopLaw(plan_loop_path(*points, config.v_max, delta=config.delta), robot, q_initial)
    n = robot.num_joints
    # the UR10e's joint-move limits; on Boryga's robots their rated speeds and no acceleration limit
    default_velocity, default_acceleration = robot.joint_move_limits
    velocity = limit_or_default(config.velocity_limit, default_velocity, "velocity_limit", n)
    if np.size(config.acceleration_limit) or np.all(np.isfinite(default_acceleration)):
        acceleration = limit_or_default(config.acceleration_limit, default_acceleration, "acceleration_limit", n)
    else:
        acceleration = np.full(n, np.inf)
    return BorygaLoopPlanner(law, velocity, acceleration)
