"""The quintic planner's scenario entry (``planner: !QuinticConfig``) and its ``make``."""

from dataclasses import dataclass, field

from drake_traj.errors import DrakeTrajError
from drake_traj.planners.quintic.law import plan_synchronized_quintic
from drake_traj.planners.quintic.system import QuinticPtpPlanner
from drake_traj.robots import Robot
from drake_traj.validation import limit_or_default

__all__ = ["QuinticConfig", "make"]


@dataclass
class QuinticConfig:
    """Synchronised quintic point-to-point moves through joint goals (Benotsmane et al.), a stop
    at each: the scenario's ``planner: !QuinticConfig`` entry.

    Attributes:
        goals: joint goals [rad or m], one row of n per goal, visited in order from the start.
        velocity_limit, acceleration_limit: per joint [rad/s, rad/s^2]; empty: the robot's
            joint-move limits (UR10e: 1.05 rad/s, 1.40 rad/s^2).
    """

    goals: list[list[float]] = field(default_factory=list)
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)


def make(config: QuinticConfig, robot: Robot, q_initial) -> QuinticPtpPlanner:
    """The planner of ``config`` on ``robot`` from ``q_initial``, the goals checked against the
    robot's joint ranges."""
    default_velocity, default_acceleration = robot.joint_move_limits
    velocity = limit_or_default(config.velocity_limit, default_velocity, "velocity_limit", robot.num_joints)
    acceleration = limit_or_default(config.acceleration_limit, default_acceleration, "acceleration_limit",
                                    robot.num_joints)
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
