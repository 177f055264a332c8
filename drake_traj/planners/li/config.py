"""Li et al. 2019's scenario entry (``planner: !LiConfig``) and its checks."""

from dataclasses import dataclass, field, replace

import numpy as np

from drake_traj.robots import UR10E, Robot
from drake_traj.validation import invalid, real_array

__all__ = ["CARTESIAN_ACCELERATION_LIMIT", "CARTESIAN_VELOCITY_LIMIT", "LiConfig"]

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

    def validate(self, robot: Robot = UR10E) -> "LiConfig":
        """The config, its own fields checked as ``make`` checks them first: the points, where
        given, real rows of [x, y, z] [m], at least two; ValueError naming the field. Returns a
        copy with the points as an array (k, 3). ``robot``: the robot it runs on (the points are
        checked in its reach, the limits with the path, by ``make``)."""
        if not np.size(self.points):
            return self
        points = real_array(self.points, "points", "m")
        if points.ndim != 2 or points.shape[1] != 3 or len(points) < 2:
            raise invalid("points", f"points must be a list of at least two [x, y, z] rows [m], got shape {points.shape}")
        return replace(self, points=points)
