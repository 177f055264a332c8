"""The smooth planners' scenario entries, each with its own checks (``validate``): through joint
waypoints without stopping (``planner: !SmoothWaypointsConfig``) and the joint path of Pająk
2024's preflight re-timed (``planner: !RetimedPajakConfig``)."""

from dataclasses import dataclass, field

from drake_traj.errors import DrakeTrajError
from drake_traj.planners.base import joint_goals
from drake_traj.planners.pajak import PajakConfig
from drake_traj.planners.timing import jerk_limited_limits
from drake_traj.robots import UR10E, Robot
from drake_traj.validation import instance_of

__all__ = ["MAX_GOALS", "RetimedPajakConfig", "SmoothWaypointsConfig"]

MAX_GOALS = 2000  # goals of one smooth-waypoints task at most (0.05 rad apart: 100 rad of motion)


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

    def validate(self, robot: Robot = UR10E) -> "SmoothWaypointsConfig":
        """The config, its own fields checked for ``robot`` as the planner's ``make`` checks them
        first: the goals (rows of n joint positions [rad], at most :data:`MAX_GOALS`), then the
        velocity, acceleration and jerk limits (:func:`~drake_traj.planners.timing.jerk_limited_limits`).
        Raises a ValueError naming the field (``grid_points`` is checked with the path)."""
        goals = joint_goals(self.goals, robot.num_joints)
        if len(goals) > MAX_GOALS:
            raise DrakeTrajError(f"goals: {len(goals)} goals, at most {MAX_GOALS} (each is a knot of the path and a node "
                                 "of the timing's programs): thin them out", field=("goals",))
        jerk_limited_limits(robot, self.velocity_limit, self.acceleration_limit, self.jerk_limit)
        return self


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

    def validate(self, robot: Robot = UR10E) -> "RetimedPajakConfig":
        """The config, its own field checked as the planner's ``make`` checks it first: ``pajak``
        is a :class:`PajakConfig` (the Pająk law checks it with the robot, the jerk limit and
        ``grid_points`` are checked after its preflight). ``robot``: the robot it runs on."""
        instance_of(self.pajak, PajakConfig, "pajak")
        return self
