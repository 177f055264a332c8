"""The synchronised quintic planner system: :class:`QuinticPtpPlanner`, a thin
:class:`~drake_traj.planners.base.TimeLawPlanner` around a :class:`~.law.QuinticLaw`, and
``make``."""

import numpy as np

from drake_traj.errors import DrakeTrajError
from drake_traj.planners.base import TimeLawPlanner, joint_move_limits, planner_robot
from drake_traj.planners.quintic.config import QuinticConfig
from drake_traj.planners.quintic.law import QuinticLaw, plan_synchronized_quintic
from drake_traj.planners.quintic.profile import UNITS
from drake_traj.robots import UR10E, Robot
from drake_traj.validation import instance_of, joint_limit

__all__ = ["QuinticPtpPlanner", "make"]


class QuinticPtpPlanner(TimeLawPlanner):
    """Planner system for a :class:`QuinticLaw`: a :class:`TimeLawPlanner` whose waypoints are
    the flange positions at the joint goals.

    Args:
        plan: the joint-space plan (from :func:`plan_synchronized_quintic`).
        velocity_limit, acceleration_limit: the limits the plan was made for [rad/s, rad/s^2].
        update_period: how often the speed override is read [s].
        robot: the robot (for the tool positions at the goals).
    """

    target_word = "goal"  # the config's goals: a refusal is "on the way to goal k"

    def __init__(self, plan: QuinticLaw, velocity_limit, acceleration_limit, *, update_period: float = 0.001,
                 robot: Robot = UR10E):
        instance_of(plan, QuinticLaw, "plan")
        super().__init__(
            plan,
            joint_limit(velocity_limit, "velocity_limit", plan.num_joints, UNITS),
            joint_limit(acceleration_limit, "acceleration_limit", plan.num_joints, UNITS),
            update_period=update_period,
        )
        self.robot = planner_robot(robot, self.num_joints)

    def task_waypoints(self) -> np.ndarray:
        """Tool positions at the joint goals [m]."""
        return self.robot.tool_position(np.array([segment.q_goal for segment in self.law.segments]))


def make(config: QuinticConfig, robot: Robot, q_initial) -> QuinticPtpPlanner:
    """The planner of ``config`` on ``robot`` from ``q_initial`` (the config checked first:
    :meth:`~.config.QuinticConfig.validate`), the goals checked against the robot's joint ranges."""
    config.validate(robot)
    velocity, acceleration = joint_move_limits(robot, config.velocity_limit, config.acceleration_limit)
    try:
        plan = plan_synchronized_quintic(q_initial, config.goals, velocity, acceleration,
                                         position_lower=robot.lower_limits, position_upper=robot.upper_limits)
    except DrakeTrajError as error:  # a limit not given is the robot's: say so
        name = error.field[0] if error.field else None
        if name in ("velocity_limit", "acceleration_limit") and not len(getattr(config, name)):
            raise error.relocated(error.field, f"{error} (not given: the {robot.name} robot's joint-move limit; give "
                                               f"{name})") from None
        raise
    return QuinticPtpPlanner(plan, velocity, acceleration, robot=robot)
