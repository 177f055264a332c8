"""Li et al. 2019's scenario entry (``planner: !LiConfig``) and its ``make``."""

from dataclasses import dataclass, field

import numpy as np

from drake_traj.planners.li.path import li_closed_path
from drake_traj.planners.li.plan import plan_li_path
from drake_traj.planners.li.system import LiPathPlanner
from drake_traj.robots import LI_4DOF, Robot
from drake_traj.validation import at_field, invalid, limit_or_default, real_array

__all__ = ["CARTESIAN_ACCELERATION_LIMIT", "CARTESIAN_VELOCITY_LIMIT", "LiConfig", "make"]

# Table 4: Sup |V_m| = 200 mm/s, Sup |a_m| = 100 mm/s^2 (the tool limits of the paper's experiment).
CARTESIAN_VELOCITY_LIMIT = 0.2  # [m/s]
CARTESIAN_ACCELERATION_LIMIT = 0.1  # [m/s^2]


@dataclass
class LiConfig:
    """Li et al. 2019: look-ahead and cubic ACC/DEC on a tool path, IK, joint re-timing, quintic
    B-spline, and our repairs so every limit holds: the scenario's ``planner: !LiConfig`` entry.

    Attributes:
        points: the tool path [m] in the robot's base frame, one row of 3 per point; empty: the
            closed path like Fig. 6 (:func:`li_closed_path`), for robots other than the paper's
            4-DOF robot translated so that it starts at the tool at ``q_initial`` (the tool keeps
            that orientation where it has one).
        tool_velocity_limit, tool_acceleration_limit: Table 4's tool limits [m/s, m/s^2].
        velocity_limit, acceleration_limit: per joint; empty: the robot's joint-move limits
            (Table 5 for the 4-DOF robot; 1.05 rad/s, 1.40 rad/s^2 for the UR10e).
    """

    points: list[list[float]] = field(default_factory=list)
    tool_velocity_limit: float = CARTESIAN_VELOCITY_LIMIT
    tool_acceleration_limit: float = CARTESIAN_ACCELERATION_LIMIT
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)


def make(config: LiConfig, robot: Robot, q_initial) -> LiPathPlanner:
    """The planner of ``config`` on ``robot`` (``q_initial``: see :class:`LiConfig`)."""
    q_initial = np.asarray(q_initial, dtype=float)
    if np.size(config.points):
        points = real_array(config.points, "points", "m")
        if points.ndim != 2 or points.shape[1] != 3 or len(points) < 2:
            raise invalid("points", f"points must be a list of at least two [x, y, z] rows [m], got shape {points.shape}")
        for index, point in enumerate(points):  # named by its index before the path between them is solved
            try:
                robot.point_ik(point[None], q_initial)
            except ValueError as error:
                raise at_field(error, "points", index) from error
    else:
        points = li_closed_path()
        if robot.name != LI_4DOF.name:
            points = points - points[0] + robot.tool_position(q_initial)
    default_velocity, default_acceleration = robot.joint_move_limits
    n = robot.num_joints
    velocity = limit_or_default(config.velocity_limit, default_velocity, "velocity_limit", n)
    acceleration = limit_or_default(config.acceleration_limit, default_acceleration, "acceleration_limit", n)
    tool_limits = (config.tool_velocity_limit, config.tool_acceleration_limit)
    plan = plan_li_path(points, lambda path: robot.point_ik(path, q_initial), robot.tool_motion, velocity,
                        acceleration, *tool_limits)
    return LiPathPlanner(plan, velocity, acceleration, robot.tool_motion, tool_limits)
