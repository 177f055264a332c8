"""The UR e-Series family under the :class:`~drake_traj.robots.base.Robot` contract: :class:`URArm`,
one arm of the one closed form that serves them all, and its instances :data:`UR3E`, :data:`UR5E`,
:data:`UR10E`, :data:`UR16E`, :data:`UR20`, :data:`UR30` (:data:`UR_ARMS`).

Every e-Series arm (UR3e, UR5e, UR10e, UR16e) and its successors (UR20, UR30) have the same
kinematic structure: the standard-DH chain T_{i-1,i} = Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i) with
alpha = (pi/2, 0, 0, pi/2, -pi/2, 0) and only d1, a2, a3, d4, d5, d6 differing. The closed-form
k(q), analytic Jacobian, J̇q̇ (:func:`~drake_traj.robots.ur_closed_form.kinematics_into`, compiled)
and inverse kinematics (:mod:`drake_traj.robots.ur_ik`) take those lengths as data
(:class:`~drake_traj.robots.ur_data.URData`). The data and their sources:
:mod:`drake_traj.robots.ur_data`, ``docs/ur_family.md`` (``docs/ur10e.md`` for the UR10e).

Frames follow ``docs/ur10e.md`` and Pająk 2024: the base frame is standard-DH frame 0
(UR's controller "Base" frame), the flange ``tool0`` is DH frame 6. The task-space pose is
p = k(q) = [x, y, z, phi_X, phi_Y, phi_Z]: the TCP's position in metres and Z-Y-X Euler angles in
radians (R = Rz(phi_Z) Ry(phi_Y) Rx(phi_X)), as used by UR's software and by Pająk 2024. The TCP is
the flange unless a ``tool`` X_FT (4x4, the TCP in the flange frame; ``Robot.with_tcp``) is given.

Nothing here needs a plant (the kinematics are numpy and the compiled closed form); the tests
check it against Drake's MultibodyPlant.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np

from drake_traj.errors import Cause, DrakeTrajError, SingularConfigurationError, joint_label
from drake_traj.robots.base import FLANGE, Robot, TaskKinematics
from drake_traj.robots.compiled_kinematics import point_motion_rates, task_kinematics, task_kinematics_into
from drake_traj.robots.task_space import (is_flange, orientation_error, pose_error, rotation_from_zyx_euler, wrap_angle, wrapped,
                                          zyx_euler_from_rotation)
from drake_traj.robots.ur_closed_form import singularity_measure_many
from drake_traj.robots.ur_data import (BASE_FRAME, DEFAULT_JOINT_MOVE_ACCELERATION, DEFAULT_JOINT_MOVE_VELOCITY,
                                       DH_ALPHA, FLANGE_FRAME, HOME, JOINT_NAMES, NUM_JOINTS, UR3E_DATA, UR5E_DATA,
                                       UR10E_DATA, UR10E_EFFORT_LIMIT, UR10E_KD, UR10E_KP, UR16E_DATA, UR20_DATA,
                                       UR30_DATA, URData)
from drake_traj.robots.ur_ik import (IK_BRANCHES, IK_PATH_MAX_STEP, IK_SINGULAR_TOLERANCE, branch_ik_many, branch_solutions,
                                     describe_pose, flange_goal, raise_wrist_singular, unique_rows)
from drake_traj.validation import finite_array, invalid, real_array

__all__ = ["UR3E", "UR5E", "UR10E", "UR16E", "UR20", "UR30", "UR_ARMS", "URArm"]


def _as_joint_vector(q, name: str = "q") -> np.ndarray:
    q = real_array(q, name, "rad")
    if q.shape != (NUM_JOINTS,):
        raise invalid(name, f"{name} must have shape ({NUM_JOINTS},), got {q.shape}")
    if not np.all(np.isfinite(q)):
        raise invalid(name, f"{name} must be finite, got {q}")
    return q


def _geometric_jacobian(frames: np.ndarray) -> np.ndarray:
    axes = frames[:-1, :3, 2]  # z_{j-1}: axis of joint j, (6, 3)
    origins = frames[:-1, :3, 3]
    flange = frames[-1, :3, 3]
    return np.vstack([np.cross(axes, flange - origins).T, axes.T])


# --------------------------------------------------------------------------------------------
# One e-Series arm under the Robot contract.
# --------------------------------------------------------------------------------------------


class URArm(Robot):
    """An e-Series arm (:class:`~drake_traj.robots.ur_data.URData`) under the
    :class:`~drake_traj.robots.base.Robot` contract, with its closed-form kinematics as methods.
    The tool is the flange ``tool0`` unless made by :meth:`~drake_traj.robots.base.Robot.with_tcp`
    (then ``tcp_offset`` is the ``tool`` of the Robot methods; the kinematics methods take
    ``tool`` explicitly)."""

    joint_names: ClassVar[tuple[str, ...]] = JOINT_NAMES
    joint_types: ClassVar[tuple[str, ...]] = ("revolute",) * NUM_JOINTS
    tool_frame: ClassVar[str] = FLANGE_FRAME
    base_frame: ClassVar[str] = BASE_FRAME

    def __init__(self, data: URData):
        self.data = data
        self.name = data.name
        self.model_file = f"{data.name}.urdf"
        self.rated_payload = data.rated_payload
        self.data_source = data.data_source
        self.reach = data.reach
        self.model = data.model  # the closed form's data, TaskKinematics.model
        self._d = np.array(data.d)
        self._a = np.array(data.a)
        self._position_limit = np.array(data.position_limit)
        self._task_kinematics = None

    def __repr__(self) -> str:
        return f"URArm({self.data.title})"

    # ---- limits and defaults -------------------------------------------------------------------
    @property
    def lower_limits(self) -> np.ndarray:
        return -self._position_limit

    @property
    def upper_limits(self) -> np.ndarray:
        return self._position_limit.copy()

    @property
    def velocity_limits(self) -> np.ndarray:
        return np.array(self.data.velocity_limit)

    @property
    def effort_limits(self) -> np.ndarray:
        return np.array(self.data.effort_limit)

    @property
    def joint_move_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """The UR controller's joint-move defaults, 1.05 rad/s (capped by the rated speed) and
        1.40 rad/s^2 on every joint."""
        return (np.minimum(DEFAULT_JOINT_MOVE_VELOCITY, self.velocity_limits),
                np.full(NUM_JOINTS, DEFAULT_JOINT_MOVE_ACCELERATION))

    @property
    def default_gains(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """The UR10e's gains (:data:`~drake_traj.robots.ur_data.UR10E_KP`,
        :data:`~drake_traj.robots.ur_data.UR10E_KD`) scaled joint by joint by this
        arm's torque limit over the UR10e's (kp to 1 N m/rad, kd to 0.1 N m s/rad): a joint then
        saturates at the same position error as the UR10e's."""
        ratio = [limit / reference for limit, reference in zip(self.data.effort_limit, UR10E_EFFORT_LIMIT)]
        return (tuple(float(round(kp * r)) for kp, r in zip(UR10E_KP, ratio)),
                tuple(round(kd * r, 1) for kd, r in zip(UR10E_KD, ratio)))

    @property
    def home_configuration(self) -> np.ndarray:
        """:data:`~drake_traj.robots.ur_data.HOME`, the start of Pająk 2024's task."""
        return np.array(HOME)

    # ---- forward kinematics ------------------------------------------------------------------
    def dh_frames(self, q) -> np.ndarray:
        """Poses of DH frames 0..6 in the base frame, shape (7, 4, 4); frame 6 is the flange.

        T_{i-1,i} = Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i) (standard DH).
        """
        q = _as_joint_vector(q)
        dh_d, dh_a = self._d, self._a
        frames = np.empty((NUM_JOINTS + 1, 4, 4))
        frames[0] = np.eye(4)
        for i in range(NUM_JOINTS):
            ct, st = np.cos(q[i]), np.sin(q[i])
            ca, sa = np.cos(DH_ALPHA[i]), np.sin(DH_ALPHA[i])
            link = np.array(
                [
                    [ct, -st * ca, st * sa, dh_a[i] * ct],
                    [st, ct * ca, -ct * sa, dh_a[i] * st],
                    [0.0, sa, ca, dh_d[i]],
                    [0.0, 0.0, 0.0, 1.0],
                ]
            )
            frames[i + 1] = frames[i] @ link
        return frames

    def flange_pose(self, q) -> np.ndarray:
        """Homogeneous transform of the flange (DH frame 6, ``tool0``) in the base frame, (4, 4)."""
        return self.dh_frames(q)[-1]

    def task_pose(self, q, tool=FLANGE) -> np.ndarray:
        """k(q) of Pająk 2024: [x, y, z, phi_X, phi_Y, phi_Z] of the TCP in the base frame [m, rad];
        ``tool`` (4, 4) is X_FT, the TCP in the flange frame (default: the flange itself)."""
        pose = self.flange_pose(q)
        if not is_flange(tool):
            pose = pose @ tool
        return np.concatenate([pose[:3, 3], zyx_euler_from_rotation(pose[:3, :3])])

    def geometric_jacobian(self, q) -> np.ndarray:
        """J_g(q) (6x6): [v; omega] of the flange in the base frame, v = d/dt of the flange origin."""
        return _geometric_jacobian(self.dh_frames(q))

    def analytic_jacobian(self, q, *, min_cos_pitch: float = 1e-6, tool=FLANGE) -> np.ndarray:
        """J(q) = diag(I, B^-1(phi)) J_g(q) (Pająk 2024): d k(q)/dt = J(q) qd, of the TCP ``tool``
        (X_FT, default the flange).

        Raises SingularConfigurationError where cos(phi_Y) < ``min_cos_pitch`` (Euler gimbal lock).
        """
        return self.analytic_jacobian_and_bias(q, np.zeros(NUM_JOINTS), min_cos_pitch=min_cos_pitch, tool=tool)[0]

    def analytic_jacobian_and_bias(self, q, qd, *, min_cos_pitch: float = 1e-6,
                                   tool=FLANGE) -> tuple[np.ndarray, np.ndarray]:
        """(J(q), dJ/dt(q, qd) qd) of the analytic Jacobian (Pająk 2024) of the TCP ``tool`` (X_FT,
        default the flange), from :meth:`kinematics`.

        The bias term is the second derivative of k(q(t)) when qdd = 0.
        Raises SingularConfigurationError where cos(phi_Y) < ``min_cos_pitch`` (Euler gimbal lock).
        """
        q = _as_joint_vector(q)
        qd = _as_joint_vector(qd, "qd")
        pose, jacobian, bias, cos_pitch, _ = self.kinematics(q, qd, tool)
        if cos_pitch < min_cos_pitch:
            raise SingularConfigurationError(
                f"Z-Y-X Euler angles are singular at q={np.round(q, 6).tolist()}: "
                f"phi_Y = {pose[4]:.6f} rad is at +-pi/2 (gimbal lock), B(phi) has no inverse"
            )
        return jacobian, bias

    def kinematics(self, q, qd, tool=FLANGE):
        """(k(q), J(q), J̇(q, q̇) q̇, cos φ_Y, singularity measure) of the TCP, ``tool`` (4, 4)
        X_FT in the flange frame (default: the flange itself).

        The closed form (:func:`~drake_traj.robots.ur_closed_form.kinematics_into`; tests check it
        against MultibodyPlant and finite differences of :meth:`task_pose`) through
        :func:`~drake_traj.robots.compiled_kinematics.task_kinematics`, vectorised over leading
        dimensions (q, q̇ of shape (..., 6)).

        Returns:
            pose (..., 6), J (..., 6, 6), bias (..., 6), cos_pitch (...), measure (...), where
            ``measure`` is :meth:`singularity_measure`. No exception at gimbal lock: callers check
            ``cos_pitch``. For one state, cos_pitch and measure are floats.
        """
        return task_kinematics(self.model, q, qd, tool)

    # ---- singularities -------------------------------------------------------------------------
    def singularity_measure(self, q):
        """min(|sin q3|, |sin q5|, |a2 c2 + a3 c23 + d5 s234| / (|a2| + |a3|)), in [0, 1].

        det J_g = a2 a3 s3 s5 (a2 c2 + a3 c23 + d5 s234): the three factors are the elbow, wrist
        and shoulder singularities; the measure is zero exactly at a singular J.
        q has shape (..., 6); the result the leading shape (a float for one q).
        """
        q = np.asarray(q, dtype=float)
        rows = np.ascontiguousarray(q.reshape(-1, 6))
        out = np.empty(rows.shape[0])
        singularity_measure_many(self.model, rows, out)
        return float(out[0]) if q.ndim == 1 else out.reshape(q.shape[:-1])

    def _shoulder_factor(self, q) -> float:
        """a2 c2 + a3 c23 + d5 s234 [m]: the wrist centre's distance along x1 (signed)."""
        a2, a3, d5 = self._a[1], self._a[2], self._d[4]
        return a2 * math.cos(q[1]) + a3 * math.cos(q[1] + q[2]) + d5 * math.sin(q[1] + q[2] + q[3])

    def singularity_factors(self, q) -> dict[str, tuple[float, str]]:
        """The three factors of det J_g at one configuration q [rad] (6,), each >= 0 and zero at its
        singularity (the shoulder's may exceed 1 by d5's share) (:meth:`singularity_measure` is the smallest), with what that singularity is:
        ``elbow`` |sin q3|, ``wrist`` |sin q5|, ``shoulder`` |a2 c2 + a3 c23 + d5 s234| / (|a2| + |a3|)."""
        q = np.asarray(q, dtype=float)
        shoulder = self._shoulder_factor(q) / (abs(self._a[1]) + abs(self._a[2]))
        return {"elbow": (float(abs(np.sin(q[2]))), "sin q3 near 0, the arm stretched or folded"),
                "wrist": (float(abs(np.sin(q[4]))), "sin q5 near 0, joints 4 and 6 aligned"),
                "shoulder": (float(abs(shoulder)), "the wrist centre near the axis of joint 1")}

    def ik_branch(self, q) -> tuple[int, int, int]:
        """(shoulder, elbow, wrist) branch signs of configuration q, as used by :meth:`inverse_kinematics`.

        shoulder = sign(a2 c2 + a3 c23 + d5 s234) (wrist centre on the +x1 / -x1 side of the joint-1
        axis), elbow = sign(sin q3), wrist = sign(sin q5); 0 where the factor is exactly zero.
        """
        q = _as_joint_vector(q)
        return tuple(int(np.sign(v)) for v in (self._shoulder_factor(q), math.sin(q[2]), math.sin(q[4])))


    def inverse_kinematics_all(self, pose, *, singular_tol: float = IK_SINGULAR_TOLERANCE, tool=FLANGE) -> np.ndarray:
        """All real joint solutions q (k, 6), k <= 8, with flange_pose(q) = pose; each wrapped to (-pi, pi].

        ``pose``: 4x4 transform of ``tool0`` in the base frame, or task pose [x, y, z, phi_X, phi_Y, phi_Z];
        with ``tool`` (X_FT, 4x4), the pose of that TCP (:func:`~drake_traj.robots.ur_ik.flange_goal`;
        errors describe the flange pose it needs).
        Rows are ordered by branch as in ``IK_BRANCHES`` (:mod:`~drake_traj.robots.ur_ik`; (shoulder, elbow,
        wrist) signs, see :meth:`ik_branch`); branches without a real solution are left out, and solutions that coincide
        (at a shoulder or elbow singularity) are listed once.

        Raises UnreachablePoseError (a ValueError; its ``pose`` the flange pose) naming the pose and
        the reason (distances) when no branch reaches the pose, and SingularConfigurationError at a wrist singularity (sin q5 = 0: a continuum of solutions).
        """
        pose = flange_goal(pose, tool)
        solutions, _, flags = branch_solutions(self.model, self.data.title, pose, singular_tol)
        if flags["wrist"]:
            raise_wrist_singular(pose)
        return unique_rows([solutions[b] for b in IK_BRANCHES if b in solutions])

    def _nearest_equivalent(self, q: np.ndarray, near: np.ndarray) -> np.ndarray:
        """q shifted joint-wise by multiples of 2 pi towards ``near``, kept inside POSITION_LIMIT."""
        shifted = q + 2 * np.pi * np.round((near - q) / (2 * np.pi))
        outside = np.abs(shifted) > self._position_limit
        shifted[outside] -= 2 * np.pi * np.sign(shifted[outside])
        return shifted

    def inverse_kinematics(
        self,
        pose,
        *,
        branch=None,
        near=None,
        singular_tol: float = IK_SINGULAR_TOLERANCE,
        tool=FLANGE,
    ) -> np.ndarray:
        """One joint solution q (6,) of a flange pose: 4x4 transform or task pose [x, y, z, phi_X, phi_Y, phi_Z];
        with ``tool`` (X_FT, 4x4), of that TCP's pose (:func:`~drake_traj.robots.ur_ik.flange_goal`;
        errors describe the flange pose it needs).

        branch: (shoulder, elbow, wrist) signs, each +1 or -1 (see :meth:`ik_branch`); the result is
            wrapped to (-pi, pi] unless ``near`` is also given.
        near: joint vector; the solution (of ``branch`` if given, else of all branches) closest to it in
            joint space, each joint shifted by multiples of 2 pi towards ``near`` (within POSITION_LIMIT),
            so that solving along a continuous path gives a continuous q.
        With neither, the first branch of ``IK_BRANCHES`` (:mod:`~drake_traj.robots.ur_ik`) that has a
        solution.

        Raises UnreachablePoseError (a ValueError; its ``pose`` the flange pose) naming the pose and the
        reason (distances) when the pose is out of reach, a DrakeTrajError (cause UNREACHABLE) when
        the requested branch is; SingularConfigurationError at a wrist singularity (sin q5 = 0; for
        ``branch``, of that shoulder branch), and at a shoulder (wrist centre on the cylinder of
        radius d4 about the joint-1 axis) or elbow (sin q3 = 0) singularity when ``branch`` asks for a
        shoulder or elbow sign, which is undefined there.
        """
        pose = flange_goal(pose, tool)
        if branch is not None:
            branch = tuple(int(b) for b in np.asarray(branch).reshape(-1)) if np.size(branch) == 3 else None
            if branch is None or any(b not in (-1, 1) for b in branch):
                raise ValueError("branch must be three signs (shoulder, elbow, wrist), each +1 or -1")
        if near is not None:
            near = _as_joint_vector(near, "near")
        solutions, failures, flags = branch_solutions(self.model, self.data.title, pose, singular_tol)
        if flags["wrist"] and (branch is None or branch[0] in flags["wrist"]):
            raise_wrist_singular(pose)
        if branch is not None:
            if flags["shoulder"]:
                raise SingularConfigurationError(
                    f"{describe_pose(pose)} is at a shoulder singularity (wrist centre on the cylinder of "
                    f"radius d4 = {self.data.d[3]} m about the joint-1 axis): the shoulder branch is undefined"
                )
            if branch in flags["elbow"]:
                raise SingularConfigurationError(
                    f"{describe_pose(pose)} is at an elbow singularity (sin q3 = 0, arm fully stretched or "
                    f"folded): the elbow branch is undefined"
                )
            if branch not in solutions:
                raise DrakeTrajError(
                    f"{describe_pose(pose)} is out of reach of branch (shoulder, elbow, wrist) = {branch}: "
                    f"{failures.get(branch, 'no real solution')}", cause=Cause.UNREACHABLE
                )
            candidates = [solutions[branch]]
        else:
            candidates = [solutions[b] for b in IK_BRANCHES if b in solutions]
        if near is None:
            return candidates[0].copy()
        shifted = [self._nearest_equivalent(q, near) for q in candidates]
        return min(shifted, key=lambda q: float(np.sum((q - near) ** 2)))

    def inverse_kinematics_path(
        self,
        poses,
        q_start,
        *,
        max_step: float = IK_PATH_MAX_STEP,
        singular_tol: float = IK_SINGULAR_TOLERANCE,
    ) -> np.ndarray:
        """Joint path (N, 6) through the flange poses (N, 4, 4) or task poses (N, 6), one branch throughout.

        Sample 0 is the solution nearest ``q_start``, every later sample the solution nearest the previous
        one (2 pi wrapping resolved towards it, see :meth:`inverse_kinematics`). Raises ValueError naming
        the sample index when a sample is out of reach or singular (SingularConfigurationError), or when
        a joint moves more than ``max_step`` [rad] between consecutive samples (or from ``q_start`` to
        sample 0): the path jumps branches or needs finer sampling.
        """
        poses = np.asarray(poses, dtype=float)
        if poses.ndim not in (2, 3) or poses.shape[1:] not in ((4, 4), (6,)) or poses.shape[0] == 0:
            raise ValueError(f"poses must have shape (N, 4, 4) or (N, 6) with N >= 1, got {poses.shape}")
        q_prev = _as_joint_vector(q_start, "q_start")
        if not max_step > 0.0:
            raise ValueError(f"max_step must be positive, got {max_step}")
        path = np.empty((poses.shape[0], NUM_JOINTS))
        for i, pose in enumerate(poses):
            try:
                q = self.inverse_kinematics(pose, near=q_prev, singular_tol=singular_tol)
            except SingularConfigurationError as err:
                raise SingularConfigurationError(f"path sample {i}: {err}") from err
            except ValueError as err:
                message = f"path sample {i}: {err}"
                raise (err.relocated(err.field, message) if isinstance(err, DrakeTrajError)
                       else DrakeTrajError(message)) from err
            step = np.abs(q - q_prev)
            if np.max(step) > max_step:
                joint = int(np.argmax(step))
                where = "q_start" if i == 0 else f"sample {i - 1}"
                raise DrakeTrajError(
                    f"path sample {i}: {joint_label(joint, JOINT_NAMES)} moves {step[joint]:.4g} rad from {where} "
                    f"(limit {max_step} rad): the path leaves the branch {self.ik_branch(q_prev)} "
                    f"(now {self.ik_branch(q)}) or is sampled too coarsely", cause=Cause.INFEASIBLE
                )
            path[i] = q
            q_prev = q
        return path

    # --------------------------------------------------------------------------------------------
    # The Robot contract.
    # --------------------------------------------------------------------------------------------

    # ---- the Robot contract ------------------------------------------------------------------
    def tcp_pose(self, q) -> np.ndarray:
        """:meth:`task_pose` for one q; the closed form of :meth:`kinematics` for many."""
        q = self.joint_positions(q)
        if q.ndim == 1:
            return self.task_pose(q, self.tcp_offset)
        return self.kinematics(q, np.zeros_like(q), self.tcp_offset)[0]

    def tool_position(self, q) -> np.ndarray:
        q = self.joint_positions(q)
        return self.kinematics(q, np.zeros_like(q), self.tcp_offset)[0][..., :3]

    def tool_motion(self, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:
        _, jacobian, bias, _, _ = self.kinematics(q, qd, self.tcp_offset)
        return (np.einsum("...ij,...j->...i", jacobian[..., :3, :], qd),
                np.einsum("...ij,...j->...i", jacobian[..., :3, :], qdd) + bias[..., :3])

    def point_ik(self, points, reference) -> np.ndarray:
        """IK of TCP positions (N, 3) [m] at the TCP orientation of ``reference``, on its IK
        branch (:meth:`inverse_kinematics` of each point: the branch's closed form compiled over
        the points, :func:`~drake_traj.robots.ur_ik.branch_ik_many`; a point it does not solve goes
        through :meth:`inverse_kinematics`, which names why). Each joint is continued from the
        point before by whole turns (the first point's from ``reference``), so points along a path
        in order give a continuous q; a joint past its position limit is turned back inside it."""
        reference = _as_joint_vector(reference, "reference")
        orientation = self.task_pose(reference, self.tcp_offset)[3:]
        branch = self.ik_branch(reference)
        points = finite_array(points, "points", "m").reshape(-1, 3)
        tcp = np.eye(4)
        tcp[:3, :3] = rotation_from_zyx_euler(orientation)
        flange = flange_goal(tcp, self.tcp_offset)  # X_BF = X_BT X_FT⁻¹ of a TCP at the origin
        positions = np.ascontiguousarray(points + flange[:3, 3])  # the flange positions [m]
        solutions = np.empty((len(points), NUM_JOINTS))
        status = branch_ik_many(self.model, np.ascontiguousarray(flange[:3, :3]), positions, *map(float, branch),
                                IK_SINGULAR_TOLERANCE, solutions) if 0 not in branch else np.ones(len(points))
        for k in np.flatnonzero(status):
            solutions[k] = self.inverse_kinematics(np.concatenate([points[k], orientation]), branch=branch,
                                                   tool=self.tcp_offset)
        continued = np.unwrap(np.vstack([reference, solutions]), axis=0)[1:]  # each from the one before
        turns = np.ceil(np.maximum(np.abs(continued) - self._position_limit, 0.0) / (2 * np.pi))
        return continued - 2 * np.pi * np.sign(continued) * turns  # back inside the range by whole turns

    def joint_rates(self, q, v, a) -> tuple[np.ndarray, np.ndarray]:
        """qd = J⁻¹ [v; 0], qdd = J⁻¹ ([a; 0] - J̇q̇) with the TCP's analytic Jacobian: q (..., 6),
        v and a (..., 3) broadcast (:func:`~drake_traj.robots.compiled_kinematics.point_motion_rates`)."""
        return point_motion_rates(self.model, self.tcp_offset, q, v, a)

    def task_kinematics(self) -> TaskKinematics:
        """The compiled k(q), analytic Jacobian and J̇q̇ (:func:`kinematics_into` through
        :func:`~drake_traj.robots.compiled_kinematics.task_kinematics_into`, ``model`` = this
        arm's :attr:`~drake_traj.robots.ur_data.URData.model`), angle wrapping, orientation error,
        pose errors and closed-form IK, of the TCP ``tcp_offset``."""
        if self._task_kinematics is None:  # shared by the copies with_tcp makes
            self._task_kinematics = TaskKinematics(task_kinematics_into, wrapped, orientation_error, wrap_angle,
                                                   pose_error, self.inverse_kinematics_all, FLANGE,
                                                   self.singularity_factors, self.model)
        flange = self._task_kinematics
        if is_flange(self.tcp_offset):
            return flange
        return flange._replace(inverse_kinematics_all=lambda pose: self.inverse_kinematics_all(pose, tool=self.tcp_offset),
                               tool=self.tcp_offset)


UR3E, UR5E, UR16E, UR20, UR30 = (URArm(data) for data in (UR3E_DATA, UR5E_DATA, UR16E_DATA, UR20_DATA, UR30_DATA))


class UR10e(URArm):
    """The UR10e, the arm of Pająk 2024 and of the shipped scenarios (``docs/ur10e.md``)."""

    def __init__(self):
        super().__init__(UR10E_DATA)


UR10E = UR10e()
UR_ARMS = (UR3E, UR5E, UR10E, UR16E, UR20, UR30)  # in the order of their payload
