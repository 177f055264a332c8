"""The loop path's joint motion on a robot (:class:`RobotLoopLaw`, a tabulated
:class:`~drake_traj.planners.laws.HermiteLaw`) and the constant clock rate that keeps it within
the joint limits (:func:`joint_speed_cap`)."""

import numpy as np

from drake_traj.errors import Cause, DrakeTrajError, SingularConfigurationError, joint_label
from drake_traj.planners.boryga.path import LoopPath
from drake_traj.planners.laws import HermiteLaw, joint_speed_cap
from drake_traj.robots import Robot
from drake_traj.robots.base import format_point

__all__ = ["FOLLOW_TOLERANCE", "RobotLoopLaw", "joint_speed_cap"]

FOLLOW_TOLERANCE = 1e-4
"""[rad] how far the law's interpolation between two knots may be from the IK of the path point
midway (:class:`RobotLoopLaw`). On smooth stretches it is below 3e-8 rad (91 seeded loops on four
arms, 2 ms knots); where the IK flips branch between two knots it is 1-3 rad."""


class RobotLoopLaw(HermiteLaw):
    """The loop path's joint motion on a robot: the time law a :class:`TimeLawPlanner` follows.

    q(tau) is the robot's inverse kinematics of the path point (:meth:`Robot.point_ik`: the
    closed-form IK of Boryga's robots, eq. 15-32; the UR10e's keeps the flange orientation and IK
    branch of ``reference``; every knot continued from the one before) and the rates come from its
    Jacobian (:meth:`Robot.joint_rates`). That is computed at knots every ``knot_step`` [s] of law
    time and at the path's junctions (both sides: the acceleration jumps by v²/R where the arc
    begins and ends) and interpolated between them (:class:`HermiteLaw`), so the planner's hot
    path costs microseconds, not an IK.

    Args:
        plan: the loop path (:func:`plan_loop_path`), in the robot's base frame.
        robot: the robot.
        reference: a configuration of the robot giving the tool orientation and IK branch.
        knot_step: the largest law-time step between knots [s].

    Raises:
        ValueError: the path leaves the robot's reach (the law time and point named).
        SingularConfigurationError: the path passes at or near a singularity, where the IK jumps
            between two knots (:data:`FOLLOW_TOLERANCE`; the law times and joint named).
        DrakeTrajError: of cause "joint range", where the robot's IK turns a joint back by whole
            turns into its range between two knots.
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
        self._check_follows_the_path()

    def _check_follows_the_path(self) -> None:
        """A refusal where the interpolation between two knots is farther than
        :data:`FOLLOW_TOLERANCE` from the IK of the path point midway: the IK jumps there, and the
        joints would not carry the tool along the path between those knots. A
        SingularConfigurationError where the path passes through a singularity (the IK branch
        flips); a DrakeTrajError of cause "joint range" where a joint jumps by whole turns (the
        robot's IK turned it back inside its range)."""
        middle = (self.knots[:-1] + self.knots[1:]) / 2
        ik = self.robot.point_ik(self.plan.sample(middle)[0].reshape(-1, 3), self.reference)
        error = np.abs(self.sample(middle)[0] - ik)
        beyond = np.flatnonzero(error.max(axis=1) > FOLLOW_TOLERANCE)
        if not beyond.size:
            return
        k = beyond[0]  # the first interval the joints do not follow
        joint = int(np.argmax(error[k]))
        step = self.sample(self.knots[k + 1])[0][joint] - self.sample(self.knots[k])[0][joint]
        where = (f"the loop path between law times {self.knots[k]:.4g} and {self.knots[k + 1]:.4g} s of "
                 f"{self.duration:.4g} s, near {format_point(self.plan.sample(middle[k])[0])} m: {joint_label(joint)} jumps "
                 f"by {step:.3g} rad between knots {(self.knots[k + 1] - self.knots[k]) * 1e3:.3g} ms apart, so no joint "
                 "motion carries the tool along the path there; move B, M or E")
        if abs(step) > np.pi and abs(step - 2 * np.pi * np.round(step / (2 * np.pi))) < 0.1:  # a whole turn
            raise DrakeTrajError(f"{where} (the path needs more than the joint's range: it is turned back by a whole "
                                 "turn)", cause=Cause.JOINT_RANGE)
        raise SingularConfigurationError(f"{where} (the path passes at or near a singularity of the {self.robot.name}, "
                                         "where its inverse kinematics flips branch)")

    def _exact_along(self, taus: np.ndarray, side: str, q=None) -> np.ndarray:
        """(q, q̇, q̈) at the law times ``taus`` [s] in order, (N, 3, n): the tool on the path,
        moving along it (at a junction, the value on ``side``), the path sampled and solved in one
        call each, so the robot's IK follows the path from point to point (:meth:`Robot.point_ik`);
        ``q`` (N, n), where already known, skips the IK."""
        position, velocity, acceleration = self.plan.sample(taus, side=side)[:3]
        if q is None:
            q = self.robot.point_ik(position, self.reference)
        qd, qdd = self.robot.joint_rates(q, velocity, acceleration)
        return np.stack([q, qd, qdd], axis=1)
