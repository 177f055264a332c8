"""Li et al. 2019 under the planner contract: :class:`LiPathPlanner` (the joint spline of
:func:`~.plan.plan_li_path` on the scaled clock) and ``make``."""

import numpy as np

from drake_traj.planners.base import TimeLawPlanner, joint_move_limits
from drake_traj.planners.li.config import LiConfig
from drake_traj.planners.li.figures import tool_speed_figure
from drake_traj.planners.li.path import li_closed_path
from drake_traj.planners.li.plan import LiPlan, plan_li_path
from drake_traj.planners.li.repair import tool_speed_and_acceleration
from drake_traj.robots import LI_4DOF, Robot
from drake_traj.validation import at_field, instance_of

__all__ = ["LiPathPlanner", "make"]


class LiPathPlanner(TimeLawPlanner):
    """Li et al. 2019's planner under the contract: follows :attr:`LiPlan.law` on the scaled clock.

    Args:
        plan: from :func:`plan_li_path`.
        velocity_limit, acceleration_limit: the joint limits the plan keeps.
        tool_motion: the robot's FK rates, for the tool speed figure.
        tool_limits: (speed [m/s], acceleration [m/s^2]) of the tool.
    """

    target_word = "point"  # the config's points

    def __init__(self, plan: LiPlan, velocity_limit, acceleration_limit, tool_motion, tool_limits):
        instance_of(plan, LiPlan, "plan")
        super().__init__(plan.law, velocity_limit, acceleration_limit)
        self.li_plan = plan
        self._tool_motion = tool_motion
        self.tool_limits = tool_limits

    def tool_statistics(self) -> dict:
        """Tool speed and acceleration peaks and the share of time above 0.5 and 0.8 a_max
        (the paper's efficiency figure), on dense samples."""
        t, speed, acceleration = tool_speed_and_acceleration(self.law, self._tool_motion)
        v_max, a_max = self.tool_limits
        weights = np.gradient(t)
        return {
            "peak_speed": float(speed.max()),
            "peak_acceleration": float(acceleration.max()),
            "share_above_half_a_max": float(weights[acceleration > 0.5 * a_max].sum() / t[-1]),
            "share_above_0.8_a_max": float(weights[acceleration > 0.8 * a_max].sum() / t[-1]),
        }

    def figures(self) -> dict:
        return {"tool_speed": tool_speed_figure(self)}


def make(config: LiConfig, robot: Robot, q_initial) -> LiPathPlanner:
    """The planner of ``config`` on ``robot`` (``q_initial``: see :class:`LiConfig`); the config
    checked first (:meth:`~.config.LiConfig.validate`)."""
    q_initial = np.asarray(q_initial, dtype=float)
    config = config.validate(robot)
    if np.size(config.points):
        points = config.points
        for index, point in enumerate(points):  # named by its index before the path between them is solved
            try:
                robot.point_ik(point[None], q_initial)
            except ValueError as error:
                raise at_field(error, "points", index) from error
    else:
        points = li_closed_path()
        if robot.name != LI_4DOF.name:
            points = points - points[0] + robot.tool_position(q_initial)
    velocity, acceleration = joint_move_limits(robot, config.velocity_limit, config.acceleration_limit)
    tool_limits = (config.tool_velocity_limit, config.tool_acceleration_limit)
    plan = plan_li_path(points, lambda path: robot.point_ik(path, q_initial), robot.tool_motion, velocity,
                        acceleration, *tool_limits)
    return LiPathPlanner(plan, velocity, acceleration, robot.tool_motion, tool_limits)
