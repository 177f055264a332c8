"""Boryga's loop as a Drake system: :class:`BorygaLoopPlanner`, a thin
:class:`~drake_traj.planners.base.TimeLawPlanner` around a :class:`~.law.RobotLoopLaw`."""

import numpy as np

from drake_traj.planners.base import TimeLawPlanner
from drake_traj.planners.boryga.figures import loop_path_figure
from drake_traj.planners.boryga.law import joint_speed_cap

__all__ = ["BorygaLoopPlanner"]


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
