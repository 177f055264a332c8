"""Boryga's loop planner's scenario entry (``planner: !BorygaConfig``) and its checks."""

from dataclasses import dataclass, field, replace

from drake_traj.robots import UR10E, Robot
from drake_traj.validation import invalid, real_array

__all__ = ["BorygaConfig"]


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

    def validate(self, robot: Robot = UR10E) -> "BorygaConfig":
        """The config, its own fields checked as ``make`` checks them first: B, M and E real and
        all 3-vectors [m] or all empty; ValueError naming the field. Returns a copy with B, M and
        E as arrays. ``robot``: the robot it runs on (the points are checked in its reach, and Δ
        and v_max with the path, by ``make``)."""
        points = [real_array(getattr(self, name), name, "m") for name in ("B", "M", "E")]
        if any(point.size for point in points) and not all(point.shape == (3,) for point in points):
            raise invalid("B", f"B, M and E must all be 3-vectors [m] or all empty, got {[p.tolist() for p in points]}")
        return replace(self, B=points[0], M=points[1], E=points[2])
