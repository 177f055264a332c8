"""The loop path's joint motion on a robot (:class:`RobotLoopLaw`, a tabulated
:class:`~drake_traj.planners.laws.HermiteLaw`) and the constant clock rate that keeps it within
the joint limits (:func:`joint_speed_cap`)."""

import numpy as np

from drake_traj.planners.boryga.path import LoopPath
from drake_traj.planners.laws import HermiteLaw, joint_speed_cap
from drake_traj.robots import Robot
from drake_traj.robots.base import format_point

__all__ = ["RobotLoopLaw", "joint_speed_cap"]


class RobotLoopLaw(HermiteLaw):
    """The loop path's joint motion on a robot: the time law a :class:`TimeLawPlanner` follows.

    q(tau) is the robot's inverse kinematics of the path point (:meth:`Robot.point_ik`: the
    closed-form IK of Boryga's robots, eq. 15-32; the UR10e's keeps the flange orientation and IK
    branch of ``reference``) and the rates come from its Jacobian (:meth:`Robot.joint_rates`):
    :meth:`exact`. That is computed at knots every ``knot_step`` [s] of law time and at the path's
    junctions (both sides: the acceleration jumps by v²/R where the arc begins and ends) and
    interpolated between them (:class:`HermiteLaw`), so the planner's hot path costs microseconds,
    not an IK.

    Args:
        plan: the loop path (:func:`plan_loop_path`), in the robot's base frame.
        robot: the robot.
        reference: a configuration of the robot giving the tool orientation and IK branch.
        knot_step: the largest law-time step between knots [s].
    """

    def __init__(self, plan: LoopPath, robot: Robot, reference, *, knot_step: float = 2e-3):
        self.plan = plan
        self.robot = robot
        self.reference = np.asarray(reference, dtype=float)
        coarse = np.union1d(np.linspace(0.0, plan.duration, 201), plan.breakpoints)
        positions = plan.sample(coarse)[0].reshape(-1, 3)
        try:
            robot.point_ik(positions, self.reference)  # out of reach: a ValueError now
        except ValueError:
            for tau, position in zip(coarse, positions):  # the first sample out of reach, named
                try:
                    robot.point_ik(position[None], self.reference)
                except ValueError as error:
                    raise ValueError(f"the loop path leaves the {robot.name}'s reach at law time {tau:.4g} s of "
                                     f"{plan.duration:.4g} s, at {format_point(position)} m: {error}") from error
            raise
        knots = np.union1d(np.linspace(0.0, plan.duration, int(np.ceil(plan.duration / knot_step)) + 1),
                           plan.breakpoints)
        junctions = np.flatnonzero(np.isin(knots, plan.breakpoints))
        right = self._exact_along(knots, "right")
        left = right.copy()
        left[junctions] = self._exact_along(knots[junctions], "left", right[junctions, 0])
        super().__init__(knots, right, left, acceleration_jumps=plan.breakpoints)

    def _exact_along(self, taus: np.ndarray, side: str, q=None) -> np.ndarray:
        """(q, q̇, q̈) at the law times ``taus`` [s] in order, (N, 3, n) (:meth:`exact` at each):
        the path sampled and solved in one call each, so the robot's IK follows the path from
        point to point (:meth:`Robot.point_ik`); ``q`` (N, n), where already known, skips the IK."""
        position, velocity, acceleration = self.plan.sample(taus, side=side)[:3]
        if q is None:
            q = self.robot.point_ik(position, self.reference)
        qd, qdd = self.robot.joint_rates(q, velocity, acceleration)
        return np.stack([q, qd, qdd], axis=1)

    def exact(self, tau: float, side: str = "right") -> np.ndarray:
        """(q, q̇, q̈) at law time tau [s], (3, n): the tool on the path, moving along it (at a
        junction, the value on ``side``)."""
        position, velocity, acceleration = (value.reshape(3) for value in self.plan.sample(tau, side=side)[:3])
        q = self.robot.point_ik(position[None], self.reference)[0]
        qd, qdd = self.robot.joint_rates(q, velocity, acceleration)
        return np.array([q, np.reshape(qd, -1), np.reshape(qdd, -1)])

