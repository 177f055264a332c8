"""The robot contract, and the shared machinery of the papers' point-placing robots.

:class:`Robot` is what the rest of the package knows about a robot: its model file, joints,
limits, default PD gains, tool pose and the kinematic services the planners use (tool motion,
inverse kinematics of tool points, joint rates along a tool motion). The UR10e
(:mod:`drake_traj.robots.ur10e`), Boryga's three robots (:mod:`drake_traj.robots.boryga_robots`)
and the 4-DOF robot of Li et al. 2019 (:mod:`drake_traj.robots.li_4dof`) implement it.

:class:`PointRobot` adds what the papers' robots share (they place a tool point, no orientation):
model file lookup, reach checks with errors naming the point and the reason, and the closed-form
inverse kinematics wrapper. Subclasses (frozen dataclasses) give the dimensions, limits, ``fk``,
``jacobian``, ``bias`` and ``_ik_raw``.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Callable, ClassVar, NamedTuple

import numpy as np
from pydrake.math import RollPitchYaw
from pydrake.multibody.parsing import Parser

from drake_traj.data import data_directory
from drake_traj.errors import Cause, DrakeTrajError
from drake_traj.validation import finite_array, invalid, real_array

__all__ = ["FLANGE", "LIMIT_TOL", "PointRobot", "Robot", "TaskKinematics", "joint_actuators"]

LIMIT_TOL = 1e-12  # slack on joint limits [rad or m]
FLANGE = np.eye(4)  # X_FT of a TCP at the flange: no tool offset
FLANGE.flags.writeable = False


def point_array(position) -> np.ndarray:
    array = np.asarray(position, dtype=float)
    if array.ndim == 0 or array.shape[-1] != 3:
        raise ValueError(f"positions must have shape (..., 3) [m], got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError("positions must be finite")
    return array


def joint_vectors(q, size: int, name: str = "q", *, finite: bool = True) -> np.ndarray:
    """``q`` as a float array of shape (..., size) (with finite entries unless ``finite`` is
    False), or ValueError naming ``name``."""
    array = real_array(q, name, "rad or m")
    if array.ndim == 0 or array.shape[-1] != size:
        raise invalid(name, f"{name} must have shape (..., {size}) [rad or m], got {array.shape}")
    if finite and not np.all(np.isfinite(array)):
        raise invalid(name, f"{name} must be finite")
    return array


def format_point(point) -> str:
    return "[" + ", ".join(f"{v:.6g}" for v in point) + "]"


def stack_columns(columns) -> np.ndarray:
    return np.stack(np.broadcast_arrays(*columns), axis=-1)


class TaskKinematics(NamedTuple):
    """A robot's task-space kinematics for planners that integrate in task space (Pająk 2024):
    6 joints, the TCP pose k(q) = [x, y, z, φ_X, φ_Y, φ_Z] in the base frame [m, rad] with Z-Y-X
    Euler angles. The first three are compiled (:mod:`drake_traj.compiled`) and called from
    compiled kernels; the others are their Python faces.

    Attributes:
        kinematics_into: ``(model, q, q̇, tool, pose, jac, bias) -> (cos φ_Y, singularity
            measure)``: k(q) of the TCP ``tool`` (X_FT, 4x4) of the arm described by ``model``
            into ``pose`` (6,), the analytic Jacobian into ``jac`` (6, 6) and J̇q̇ into ``bias``
            (6,) [m/s², rad/s²]; q [rad], q̇ [rad/s]. The same compiled function for every arm
            (:func:`drake_traj.robots.compiled_kinematics.task_kinematics_into`): the arm is data.
        wrapped: an angle [rad] (float or array) wrapped into (-π, π].
        orientation_error: ``(φ, φ_goal) -> `` the angle of R_goalᵀ R [rad] for Euler angles (3,).
        wrap_angle: :attr:`wrapped` for any array-like.
        pose_error: ``(poses (..., 6), goal (6,)) -> (position error [m], orientation error
            [rad])``, each (...).
        inverse_kinematics_all: ``pose (6,) -> q (k, n)``, every joint solution of a TCP pose
            [rad]; ValueError for a pose out of reach, SingularConfigurationError at a singular one.
        tool: X_FT (4, 4), the TCP in the flange frame (:attr:`Robot.tcp_offset`), the ``tool``
            argument of ``kinematics_into``.
        singularity_factors: ``q (n,) -> {name: (factor, meaning)}``, the factors of det J at q,
            each >= 0 and 0 at its singularity (the singularity measure, in [0, 1], is the smallest),
            with what that singularity is (to name it in a message).
        model: the arm's kinematic data (1-D float array), the ``model`` argument of
            ``kinematics_into``.
    """

    kinematics_into: Callable
    wrapped: Callable
    orientation_error: Callable
    wrap_angle: Callable
    pose_error: Callable
    inverse_kinematics_all: Callable
    tool: np.ndarray
    singularity_factors: Callable
    model: np.ndarray


class Robot:
    """The contract of a robot (subclasses give the class attributes and the kinematics).

    Joint vectors are ordered as ``joint_names``; revolute joints in rad, prismatic in m. Frames:
    the model's ``base_frame`` is welded to the world; the flange is ``tool_frame`` (F), and "the
    tool" of every method below is the TCP (T) at :attr:`tcp_offset` X_FT in it: the flange
    itself unless the robot was made by :meth:`with_tcp`.
    """

    name: ClassVar[str]
    model_file: ClassVar[str]  # file name in the package's models/ folder
    joint_names: ClassVar[tuple[str, ...]]
    joint_types: ClassVar[tuple[str, ...]]  # "revolute" [rad] or "prismatic" [m]
    base_frame: ClassVar[str] = "base"
    tool_frame: ClassVar[str] = "tool0"
    tcp_offset: np.ndarray = FLANGE  # X_FT (4, 4) [m]: the TCP in the flange frame, read-only
    rated_payload: float | None = None  # [kg], the largest payload the maker rates; None: not rated
    data_source: str = ""  # where the robot's numbers come from (a document in docs/, a paper, a file)
    reach: float | None = None  # [m], the radius of the tool's workspace (a maker's rated reach); None: not given

    def with_tcp(self, xyz, rpy) -> "Robot":
        """A robot equal to this one whose tool is the TCP at ``xyz`` [m] with orientation ``rpy``
        [rad] in the flange frame ``tool_frame`` (``tool0``), as a UR controller's ``set_tcp``
        makes it: every pose, motion, inverse kinematics and pose error of the returned robot is
        the TCP's (this one is left unchanged). The offset is from the flange, not from an
        earlier TCP: ``with_tcp`` on a robot made by it replaces its TCP.

        ``rpy`` = (roll, pitch, yaw) are fixed-axis X-Y-Z angles, Drake's ``RollPitchYaw``:
        R_FT = Rz(yaw) Ry(pitch) Rx(roll), the convention of the task poses' Z-Y-X Euler angles.
        UR's ``set_tcp(p[x, y, z, rx, ry, rz])`` takes a rotation vector instead (axis times angle
        [rad], R_FT = exp([r]x)); the two give the same TCP when
        ``RollPitchYaw(RotationMatrix(AngleAxis(|r|, r / |r|)))`` is ``rpy`` (PolyScope shows both).

        Raises:
            DrakeTrajError: ``xyz`` or ``rpy`` not three finite numbers (field ``xyz`` or ``rpy``),
                or a robot without a tool orientation given a non-zero offset.
        """
        xyz = finite_array(xyz, "xyz", "m", shape=(3,))
        rpy = finite_array(rpy, "rpy", "rad", shape=(3,))
        offset = np.eye(4)
        offset[:3, :3] = RollPitchYaw(rpy).ToRotationMatrix().matrix()
        offset[:3, 3] = xyz
        offset.flags.writeable = False
        return self._with_tcp_offset(offset, xyz, rpy)

    def _with_tcp_offset(self, offset: np.ndarray, xyz: np.ndarray, rpy: np.ndarray) -> "Robot":
        """:meth:`with_tcp` once its arguments are checked: a copy with ``tcp_offset`` = ``offset``
        (X_FT, 4x4); ``xyz`` and ``rpy`` for a refusal's message."""
        robot = copy.copy(self)
        robot.tcp_offset = offset
        return robot

    # ---- description ---------------------------------------------------------------------------
    @property
    def num_joints(self) -> int:
        return len(self.joint_names)

    def joint_unit(self, k: int) -> str:
        """"rad" or "m", the position unit of joint ``k``."""
        return "rad" if self.joint_types[k] == "revolute" else "m"

    @property
    def lower_limits(self) -> np.ndarray:  # pragma: no cover - abstract
        """Joint position lower limits, (n,)."""
        raise NotImplementedError

    @property
    def upper_limits(self) -> np.ndarray:  # pragma: no cover - abstract
        """Joint position upper limits, (n,)."""
        raise NotImplementedError

    @property
    def velocity_limits(self) -> np.ndarray:  # pragma: no cover - abstract
        """Rated joint speeds [rad/s or m/s], (n,)."""
        raise NotImplementedError

    @property
    def effort_limits(self) -> np.ndarray:  # pragma: no cover - abstract
        """Joint torque or force limits [N m or N], (n,): the drives saturate there."""
        raise NotImplementedError

    @property
    def joint_move_limits(self) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - abstract
        """(velocity, acceleration) limits a planner keeps when the task gives none, each (n,)."""
        raise NotImplementedError

    @property
    def default_gains(self) -> tuple[tuple[float, ...], tuple[float, ...]]:  # pragma: no cover
        """(kp, kd) of the simulated joint PD controller [N m/rad, N m s/rad or N/m, N s/m]."""
        raise NotImplementedError

    @property
    def home_configuration(self) -> np.ndarray:  # pragma: no cover - abstract
        """A start configuration inside the limits, (n,), used when a scenario gives none."""
        raise NotImplementedError

    # ---- model ---------------------------------------------------------------------------------
    def model_path(self) -> Path:
        """Absolute path of the robot's model file shipped with the package (``models/``)."""
        path = data_directory("models") / self.model_file
        if not path.is_file():
            raise ValueError(f"{self.name} model file not found: {path}")
        return path

    def add_to_plant(self, plant):
        """Parse the model into ``plant`` (not finalized) and weld its base to the world.

        Returns the model instance; each joint has an actuator (:func:`joint_actuators` finds it).
        """
        (instance,) = Parser(plant).AddModels(str(self.model_path()))
        plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(self.base_frame, instance))
        return instance

    # ---- kinematics ----------------------------------------------------------------------------
    def joint_positions(self, q, name: str = "q") -> np.ndarray:
        """``q`` as joint vectors of this robot, a float array of shape (..., n), or ValueError
        naming ``name``: the check of :meth:`tcp_pose`'s and :meth:`tool_position`'s ``q`` (non-finite
        entries pass it: a log with NaN rows gives NaN poses on the UR10e)."""
        return joint_vectors(q, self.num_joints, name, finite=False)

    def tcp_pose(self, q) -> np.ndarray:  # pragma: no cover - abstract
        """[x, y, z, phi_X, phi_Y, phi_Z] of the TCP in the base frame [m, rad], (..., 6) for q of
        shape (..., n); Z-Y-X Euler angles, zeros where the robot only places a point."""
        raise NotImplementedError

    def tool_position(self, q) -> np.ndarray:  # pragma: no cover - abstract
        """The TCP's position in the base frame [m], (..., 3) for q of shape (..., n)."""
        raise NotImplementedError

    def tool_motion(self, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover
        """(velocity [m/s], acceleration [m/s^2]) of the tool point, each (N, 3), for joint
        positions, velocities and accelerations of shape (N, n)."""
        raise NotImplementedError

    def point_ik(self, points, reference) -> np.ndarray:  # pragma: no cover - abstract
        """Joint configurations (N, n) placing the tool point at ``points`` (N, 3) [m].

        A robot whose tool has an orientation keeps that of the configuration ``reference`` and
        its inverse-kinematics branch. Points along a path, in order, give a continuous q where
        the path allows one: each point's solution is the one nearest the point before (the first
        point's, nearest ``reference``), up to a joint's range. Raises ValueError naming the point
        and the reason when a point is out of reach.
        """
        raise NotImplementedError

    def joint_rates(self, q, v, a) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover
        """(qd, qdd) that move the tool point with velocity ``v`` and acceleration ``a`` at q,
        the tool orientation held where the robot has one; arrays broadcast together."""
        raise NotImplementedError

    def task_kinematics(self) -> TaskKinematics:
        """The robot's :class:`TaskKinematics` of its TCP (the Pająk 2024 planner's only way to
        the robot); ValueError naming the robot where it has none (this default)."""
        raise ValueError(f"the {self.name} robot provides no task-space kinematics (6 joints, a tool pose with Z-Y-X "
                         "Euler angles, compiled)")


class PointRobot(Robot):
    """A robot that places a tool point (no orientation); subclasses are frozen dataclasses with
    the dimensions and limits (fields ``lower``, ``upper``, ``velocity_limit``,
    ``effort_limit``). Default PD gains 2000 (N m/rad or N/m) and 100 (N m s/rad or N s/m) on
    every joint: the inverse-dynamics feed-forward does most of the work."""

    lower: tuple[float, ...]
    upper: tuple[float, ...]
    velocity_limit: tuple[float, ...]
    effort_limit: tuple[float, ...]

    # ---- the Robot contract ------------------------------------------------------------------
    @property
    def velocity_limits(self) -> np.ndarray:
        return np.array(self.velocity_limit, dtype=float)

    @property
    def effort_limits(self) -> np.ndarray:
        return np.array(self.effort_limit, dtype=float)

    @property
    def joint_move_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """The rated speeds and no acceleration limit (the papers give none)."""
        return self.velocity_limits, np.full(self.num_joints, np.inf)

    @property
    def default_gains(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        return (2000.0,) * self.num_joints, (100.0,) * self.num_joints

    @property
    def home_configuration(self) -> np.ndarray:
        """Every joint at the middle of its range."""
        return 0.5 * (self.lower_limits + self.upper_limits)

    def tcp_pose(self, q) -> np.ndarray:
        position = self.fk(self.joint_positions(q))
        return np.concatenate([position, np.zeros(position.shape[:-1] + (3,))], axis=-1)

    def tool_position(self, q) -> np.ndarray:
        return self.fk(self.joint_positions(q))

    def tool_motion(self, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:
        jacobian = self.jacobian(q)
        return (np.einsum("...ij,...j->...i", jacobian, qd),
                np.einsum("...ij,...j->...i", jacobian, qdd) + self.bias(q, qd))

    def point_ik(self, points, reference=None) -> np.ndarray:
        """:meth:`ik` (the papers' robots have one solution branch; ``reference`` is unused)."""
        return self.ik(points)

    def _with_tcp_offset(self, offset: np.ndarray, xyz: np.ndarray, rpy: np.ndarray) -> "Robot":
        """This robot for a zero offset; a non-zero one is refused: the robot places a point and
        has no model of the flange's orientation that would carry a tool offset."""
        if np.any(xyz != 0.0) or np.any(rpy != 0.0):
            raise invalid("xyz" if np.any(xyz != 0.0) else "rpy",
                          f"the {self.name} robot places a point and models no flange orientation, so it takes "
                          f"no TCP offset: got xyz = {format_point(xyz)} m, rpy = {format_point(rpy)} rad (give "
                          "zeros, or move the task's points by the tool)")
        return self

    # ---- per-robot kinematics (subclasses) --------------------------------------------------
    def fk(self, q) -> np.ndarray:  # pragma: no cover - abstract
        """Position of ``tool0`` in the base frame [m], shape (..., 3)."""
        raise NotImplementedError

    def jacobian(self, q) -> np.ndarray:  # pragma: no cover - abstract
        """J(q) = d fk / dq, shape (..., 3, n)."""
        raise NotImplementedError

    def bias(self, q, qd) -> np.ndarray:  # pragma: no cover - abstract
        """dJ/dt(q, qd) qd: the tool acceleration when qdd = 0 [m/s^2], shape (..., 3)."""
        raise NotImplementedError

    def singularity_measure(self, q) -> np.ndarray:  # pragma: no cover - abstract
        """In [0, 1]; zero exactly where J(q) is singular."""
        raise NotImplementedError

    def _ik_raw(self, p: np.ndarray):  # pragma: no cover - abstract
        """(q, reasons): IK of (N, 3) points, q of shape (N, n), with NaN rows where the closed form has no solution,
        and a list of (index, reason) for the domain errors found."""
        raise NotImplementedError

    # ---- limits ------------------------------------------------------------------------------
    @property
    def lower_limits(self) -> np.ndarray:
        return np.array(self.lower, dtype=float)

    @property
    def upper_limits(self) -> np.ndarray:
        return np.array(self.upper, dtype=float)

    def within_limits(self, q, tol: float = LIMIT_TOL) -> np.ndarray:
        """Whether each joint vector of ``q`` (..., n) is within the position limits."""
        q = joint_vectors(q, self.num_joints)
        return np.all((q >= self.lower_limits - tol) & (q <= self.upper_limits + tol), axis=-1)

    # ---- inverse kinematics -------------------------------------------------------------------
    def reach_problems(self, positions) -> list[tuple[int, str]]:
        """All out-of-reach points of ``positions`` (..., 3) as (flat index, reason), index order."""
        p = point_array(positions).reshape(-1, 3)
        return self._solve(p)[1]

    def is_reachable(self, positions) -> np.ndarray:
        """Boolean array (...) : True where :meth:`ik` has a solution within the joint limits."""
        p = point_array(positions)
        ok = np.ones(p.shape[:-1], dtype=bool).reshape(-1)
        for index, _ in self._solve(p.reshape(-1, 3))[1]:
            ok[index] = False
        return ok.reshape(p.shape[:-1])

    def reach_check(self, positions, label: str = "point", times=None) -> None:
        """Raise ValueError for the first out-of-reach point of ``positions`` (..., 3).

        The message names the robot, the point's flat index (and time, if ``times`` of the same
        flat length is given), the point, the reason and how many points fail in all.
        """
        p = point_array(positions).reshape(-1, 3)
        problems = self._solve(p)[1]
        if problems:
            raise DrakeTrajError(self._message(p, problems, label, times), cause=Cause.UNREACHABLE)

    def _message(self, p, problems, label, times) -> str:
        index, reason = problems[0]
        at = "" if times is None else f" (t = {float(np.ravel(times)[index]):.6g} s)"
        more = "" if len(problems) == 1 else f"; {len(problems)} of {len(p)} {label}s are out of reach"
        name = label if len(p) == 1 else f"{label} {index}"  # a single point has no index
        return f"{name}{at} at {format_point(p[index])} m is out of reach of the {self.name} robot: {reason}{more}"


    def _solve(self, p: np.ndarray):
        q, problems = self._ik_raw(p)
        bad = {index for index, _ in problems}
        lo, hi = self.lower_limits, self.upper_limits
        for k in range(self.num_joints):
            beyond = (q[:, k] < lo[k] - LIMIT_TOL) | (q[:, k] > hi[k] + LIMIT_TOL)  # NaN: False
            outside = np.flatnonzero(beyond)
            for index in outside:
                index = int(index)
                if index in bad:
                    continue
                bad.add(index)
                unit = self.joint_unit(k)
                problems.append(
                    (index, f"{self.joint_names[k]} = {q[index, k]:.6g} {unit} is beyond its limits "
                            f"[{lo[k]:.6g}, {hi[k]:.6g}] {unit}")
                )
        problems.sort(key=lambda item: item[0])
        return q, problems

    def ik(self, position, label: str = "point", times=None) -> np.ndarray:
        """Closed-form inverse kinematics (the subclass's ``_ik_raw``), checked against the limits.

        Args:
            position: tool positions [m], shape (..., 3).
            label, times: only for the error message (see :meth:`reach_check`).

        Returns:
            Joint vectors, shape (..., n), on the branch documented in the robot's module.

        Raises:
            ValueError: a point out of reach (index and reason in the message).
        """
        p = point_array(position)
        flat = p.reshape(-1, 3)
        q, problems = self._solve(flat)
        if problems:
            raise DrakeTrajError(self._message(flat, problems, label, times), cause=Cause.UNREACHABLE)
        return q.reshape(p.shape[:-1] + (self.num_joints,))


def joint_actuators(plant, instance) -> dict:
    """The actuators of the model instance ``instance`` of ``plant`` (finalized or not) by the
    name of the joint each drives: a model names its actuators as it likes (Drake's SDF parser
    after the joint, a ROS URDF's transmission as its author)."""
    actuators = (plant.get_joint_actuator(index) for index in plant.GetJointActuatorIndices())  # (instance): finalized only
    return {actuator.joint().name(): actuator for actuator in actuators if actuator.model_instance() == instance}
