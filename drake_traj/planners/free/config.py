"""The free-motion planner's scenario entry (``planner: !FreeMotionConfig``) and its checks."""

from dataclasses import dataclass, field

import numpy as np

from drake_traj.planners.free.search import COLLISION_CHECKS, DEFAULT_MAX_STEP, PLANNERS
from drake_traj.robots import UR10E, Robot
from drake_traj.validation import finite_array, invalid, positive_scalar, whole_number

__all__ = ["FreeMotionConfig", "MAX_GOALS", "MAX_PLANNING_TIME"]

MAX_GOALS = 100  # goals (or poses) of one task at most
MAX_PLANNING_TIME = 120.0  # [s] the largest planning budget of a task


@dataclass
class FreeMotionConfig:
    """Goals reached through the cell on a path found for them: the scenario's
    ``planner: !FreeMotionConfig`` entry.

    Attributes:
        goals: joint configurations [rad] reached in order, one row of n each; the arm stops at each.
        poses: TCP poses [x, y, z, φ_X, φ_Y, φ_Z] [m, rad] instead of goals (Z-Y-X Euler angles as
            Pająk's waypoints): each reached by the inverse-kinematics solution nearest the
            previous configuration that is inside the joint ranges, clear of the cell and reached
            by a path.
        velocity_limit, acceleration_limit, jerk_limit: per joint (or one value); empty: the
            robot's joint-move limits, and 10 /s × the acceleration limit.
        planning_time: the whole planning budget of the task [s]: the search, shortening,
            smoothing, timing and check of every goal's leg (each leg a share of what is left; the
            search of a leg stops where the rest of it would not fit).
        seed: the random numbers' seed: the same seed finds the same path.
        planner: the OMPL planner, one of :data:`~drake_traj.planners.free.search.PLANNERS` (``rrt_connect``: the first
            path found, then shortened).
        shortcut_rounds: random shortcuts tried on each found path.
        grid_points: nodes of the timing's linear programs.
        max_step: the longest edge the search adds [rad] (OMPL's range: :data:`~drake_traj.planners.free.search.DEFAULT_MAX_STEP`).
        collision_check: ``compiled`` (the compiled collision model) or ``scenegraph`` (SceneGraph
            from Python: the slower reference) for the search's configurations and segments; the
            timed motion is checked by the cell check either way.
    """

    goals: list[list[float]] = field(default_factory=list)
    poses: list[list[float]] = field(default_factory=list)
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)
    jerk_limit: list[float] = field(default_factory=list)
    planning_time: float = 5.0
    seed: int = 0
    planner: str = "rrt_connect"
    shortcut_rounds: int = 60
    grid_points: int = 200
    max_step: float = DEFAULT_MAX_STEP
    collision_check: str = "compiled"

    def validate(self, robot: Robot = UR10E) -> "FreeMotionConfig":
        """The config, its own fields checked for ``robot`` (its number of joints n): ValueError
        naming the field for a malformed config (the geometry is the planner's)."""
        num_joints = robot.num_joints
        if bool(len(self.goals)) == bool(len(self.poses)):
            raise invalid("goals", "give either goals (joint configurations) or poses (TCP poses), one of the two")
        name, width = ("goals", num_joints) if len(self.goals) else ("poses", 6)
        rows = finite_array(getattr(self, name), name, "rad" if name == "goals" else "m and rad")
        if rows.ndim != 2 or rows.shape[1] != width:
            raise invalid(name, f"{name} must be rows of {width} values, got shape {rows.shape}")
        if len(rows) > MAX_GOALS:
            raise invalid(name, f"{name} has {len(rows)} rows, at most {MAX_GOALS}")
        budget = positive_scalar(self.planning_time, "planning_time", "s")
        if budget > MAX_PLANNING_TIME:
            raise invalid("planning_time", f"planning_time = {budget:g} s is above {MAX_PLANNING_TIME:g} s")
        if self.planner not in PLANNERS:
            raise invalid("planner", f"planner must be one of {sorted(PLANNERS)}, got {self.planner!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or not 0 <= self.seed < 2**31:
            raise invalid("seed", f"seed must be a whole number in [0, 2^31), got {self.seed!r}")
        whole_number(self.shortcut_rounds, "shortcut_rounds", minimum=0)
        whole_number(self.grid_points, "grid_points", minimum=20)
        positive_scalar(self.max_step, "max_step", "rad")
        if self.collision_check not in COLLISION_CHECKS:
            raise invalid("collision_check", f"collision_check must be one of {list(COLLISION_CHECKS)}, got "
                                             f"{self.collision_check!r}")
        return self
