"""Ruckig baseline: jerk-limited, time-optimal rest-to-rest joint moves between waypoints.

The stop-at-each-waypoint version of a task, planned with the Ruckig library: for every segment
q_k -> q_{k+1} one Ruckig trajectory from rest to rest under per-joint velocity, acceleration and
jerk limits, every joint starting and finishing together. The law,
:class:`~drake_traj.planners.timing.RuckigStopLaw`, is the shared timing's (the smooth planners
take its moves where stopping is faster); here are the planner system, the config and ``make``.
The default jerk limit is :func:`~drake_traj.planners.timing.default_jerk_limit` (10 /s times the
acceleration limit: the UR10e publishes none).
"""

from dataclasses import dataclass, field

import numpy as np

from drake_traj.planners.base import TimeLawPlanner, joint_goals, planner_robot, start_and_goals
from drake_traj.planners.timing import RuckigStopLaw, jerk_limited_limits
from drake_traj.robots import UR10E, Robot
from drake_traj.validation import instance_of

__all__ = ["RuckigConfig", "RuckigPlanner", "make"]


class RuckigPlanner(TimeLawPlanner):
    """Planner system for a :class:`RuckigStopLaw`; its waypoints are the flange positions at
    the joint waypoints.

    Args:
        law: the Ruckig time law.
        speed_cap, update_period: as in :class:`TimeLawPlanner`.
        robot: the robot (for the tool positions at the waypoints).
    """

    target_word = "goal"  # the config's goals: a refusal is "on the way to goal k"

    def __init__(self, law: RuckigStopLaw, *, speed_cap: float = 1.0, update_period: float = 0.001,
                 robot: Robot = UR10E):
        instance_of(law, RuckigStopLaw, "law")
        super().__init__(
            law,
            law.velocity_limit,
            law.acceleration_limit,
            speed_cap=speed_cap,
            update_period=update_period,
        )
        self.robot = planner_robot(robot, self.num_joints)

    def task_waypoints(self) -> np.ndarray:
        """Tool positions [m] at the waypoints q_1..q_m (the goals), shape (m, 3)."""
        return self.robot.tool_position(self.law.q_waypoints[1:])


@dataclass
class RuckigConfig:
    """The Ruckig baseline, jerk-limited moves through joint goals with a stop at each: the
    scenario's ``planner: !RuckigConfig`` entry.

    Attributes:
        goals: joint waypoints after the start [rad], one row of n per waypoint.
        velocity_limit, acceleration_limit: per joint; empty: the robot's joint-move limits.
        jerk_limit: per joint [rad/s^3]; empty: :func:`~drake_traj.planners.timing.default_jerk_limit`
            of the acceleration limit.
    """

    goals: list[list[float]] = field(default_factory=list)
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)
    jerk_limit: list[float] = field(default_factory=list)

    def validate(self, robot: Robot = UR10E) -> "RuckigConfig":
        """The config, its own fields checked for ``robot`` as :func:`make` checks them first: the
        velocity, acceleration and jerk limits (the robot's and the default where empty), then the
        goals (rows of n joint positions [rad]); ValueError naming the field."""
        jerk_limited_limits(robot, self.velocity_limit, self.acceleration_limit, self.jerk_limit)
        joint_goals(self.goals, robot.num_joints)
        return self


def make(config: RuckigConfig, robot: Robot, q_initial) -> RuckigPlanner:
    """The baseline of ``config`` on ``robot`` from ``q_initial`` (the config checked first:
    :meth:`RuckigConfig.validate`)."""
    config.validate(robot)
    limits = jerk_limited_limits(robot, config.velocity_limit, config.acceleration_limit, config.jerk_limit)
    return RuckigPlanner(RuckigStopLaw(start_and_goals(q_initial, config.goals, robot.num_joints), *limits), robot=robot)
