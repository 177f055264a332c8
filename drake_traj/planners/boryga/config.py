"""Boryga's loop planner's scenario entry (``planner: !BorygaConfig``) and its ``make``."""

from dataclasses import dataclass, field

import numpy as np

from drake_traj.planners.boryga.law import RobotLoopLaw
from drake_traj.planners.boryga.path import plan_loop_path
from drake_traj.planners.boryga.placements import PAPER_LOOP, PLACED_ROBOTS, paper_loop_placement
from drake_traj.planners.boryga.system import BorygaLoopPlanner
from drake_traj.robots import Robot
from drake_traj.validation import at_field, invalid, limit_or_default, real_array

__all__ = ["BorygaConfig", "make"]


@dataclass
class BorygaConfig:
    """Boryga's loop path B -> M -> loop through the corner -> M -> E, traced by the scenario's
    robot (inverse kinematics): the scenario's ``planner: !BorygaConfig`` entry.

    Attributes:
        B, M, E: the path's points [m] in the robot's base frame; all empty: the paper's example
            (Table 1) placed in the robot's workspace (:func:`paper_loop_placement` for Boryga's
            robots; for another robot translated so that B is the tool at ``q_initial``, the loop
            in the horizontal plane through it, traced at the tool orientation of ``q_initial``).
        delta: Δ [m] of the loop (section 2.2).
        v_max: the speed along the path [m/s].
        velocity_limit, acceleration_limit: per joint; empty: the robot's joint-move limits
            (:attr:`Robot.joint_move_limits`: 1.05 rad/s and 1.40 rad/s² on the UR10e; the rated
            speeds and no acceleration limit on Boryga's robots, as in the paper).
    """

    B: list[float] = field(default_factory=list)
    M: list[float] = field(default_factory=list)
    E: list[float] = field(default_factory=list)
    delta: float = 0.02
    v_max: float = 0.25
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)


def make(config: BorygaConfig, robot: Robot, q_initial) -> BorygaLoopPlanner:
    """The loop of ``config`` on ``robot`` (``q_initial`` gives the tool orientation, the IK
    branch and, for the default placement on robots other than Boryga's, the point B)."""
    points = [real_array(getattr(config, name), name, "m") for name in ("B", "M", "E")]
    if any(point.size for point in points):
        if not all(point.shape == (3,) for point in points):
            raise invalid("B", f"B, M and E must all be 3-vectors [m] or all empty, got {[p.tolist() for p in points]}")
        for name, point in zip(("B", "M", "E"), points):  # named before the path between them is solved
            try:
                robot.point_ik(point[None], q_initial)
            except ValueError as error:
                raise at_field(error, name) from error
    elif robot.name in PLACED_ROBOTS:
        placement = paper_loop_placement(robot.name)
        points = [placement.B, placement.M, placement.E]
    else:
        offset = robot.tool_position(np.asarray(q_initial, dtype=float)) - np.asarray(PAPER_LOOP["B"])
        points = [np.asarray(PAPER_LOOP[name]) + offset for name in ("B", "M", "E")]
    law = RobotLoopLaw(plan_loop_path(*points, config.v_max, delta=config.delta), robot, q_initial)
    n = robot.num_joints
    # the UR10e's joint-move limits; on Boryga's robots their rated speeds and no acceleration limit
    default_velocity, default_acceleration = robot.joint_move_limits
    velocity = limit_or_default(config.velocity_limit, default_velocity, "velocity_limit", n)
    if np.size(config.acceleration_limit) or np.all(np.isfinite(default_acceleration)):
        acceleration = limit_or_default(config.acceleration_limit, default_acceleration, "acceleration_limit", n)
    else:
        acceleration = np.full(n, np.inf)
    return BorygaLoopPlanner(law, velocity, acceleration)
