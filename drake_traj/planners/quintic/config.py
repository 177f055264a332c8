"""The quintic planner's scenario entry (``planner: !QuinticConfig``) and its checks."""

from dataclasses import dataclass, field

from drake_traj.planners.base import joint_move_limits
from drake_traj.robots import UR10E, Robot

__all__ = ["QuinticConfig"]


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

    def validate(self, robot: Robot = UR10E) -> "QuinticConfig":
        """The config, its own fields checked for ``robot`` as ``make`` checks them first: the
        velocity and acceleration limits (the robot's where empty); ValueError naming the field.
        The goals are checked with the start, by the plan (and against the joint ranges)."""
        joint_move_limits(robot, self.velocity_limit, self.acceleration_limit)
        return self
