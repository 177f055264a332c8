"""UR10e: model file, published limits and analytic kinematics.

Frames follow ``ur10e_facts.md`` and seed 000 (Pająk 2024): the base frame is standard-DH frame 0
(UR's controller "Base" frame), the flange ``tool0`` is DH frame 6. The task-space pose is
p = k(q) = [x, y, z, phi_X, phi_Y, phi_Z]: flange position in metres and Z-Y-X Euler angles in
radians (R = Rz(phi_Z) Ry(phi_Y) Rx(phi_X)), as used by UR's software and by seed 000.

Everything here is plain numpy so tests and planners can call it without building a plant; the
tests check it against Drake's MultibodyPlant.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import numpy as np

NUM_JOINTS = 6

# Standard DH parameters (ur10e_facts.md; seed 000 Table 1 is the same chain in modified DH).
DH_D = np.array([0.1807, 0.0, 0.0, 0.17415, 0.11985, 0.11655])  # [m]
DH_A = np.array([0.0, -0.6127, -0.57155, 0.0, 0.0, 0.0])  # [m]
DH_ALPHA = np.array([np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0])  # [rad]

JOINT_NAMES = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
POSITION_LIMIT = np.full(NUM_JOINTS, 2 * np.pi)  # [rad], symmetric
VELOCITY_LIMIT = np.array([2.094, 2.094, 3.1416, 3.1416, 3.1416, 3.1416])  # [rad/s]
EFFORT_LIMIT = np.array([330.0, 330.0, 150.0, 56.0, 56.0, 56.0])  # [N m]
# UR controller defaults for joint moves, used by seed 000 for every joint.
DEFAULT_JOINT_MOVE_VELOCITY = 1.05  # [rad/s] (60 deg/s)
DEFAULT_JOINT_MOVE_ACCELERATION = 1.40  # [rad/s^2] (80 deg/s^2)

LINK_MASSES = np.array([7.369, 13.051, 3.989, 2.1, 1.98, 0.615])  # [kg], links 1..6
BASE_MASS = 4.0  # [kg], approximate; the base is welded to the world.
FLANGE_FRAME = "tool0"
BASE_FRAME = "base"


def model_path() -> Path:
    """Absolute path of the UR10e URDF shipped with the package (``models/ur10e.urdf``)."""
    path = Path(str(resources.files("drake_traj.models").joinpath("ur10e.urdf")))
    if not path.is_file():
        raise ValueError(f"UR10e model file not found: {path}")
    return path


def _as_joint_vector(q, name: str = "q") -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.shape != (NUM_JOINTS,):
        raise ValueError(f"{name} must have shape ({NUM_JOINTS},), got {q.shape}")
    if not np.all(np.isfinite(q)):
        raise ValueError(f"{name} must be finite, got {q}")
    return q


def dh_frames(q) -> np.ndarray:
    """Poses of DH frames 0..6 in the base frame, shape (7, 4, 4); frame 6 is the flange.

    T_{i-1,i} = Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i) (standard DH).
    """
    q = _as_joint_vector(q)
    frames = np.empty((NUM_JOINTS + 1, 4, 4))
    frames[0] = np.eye(4)
    for i in range(NUM_JOINTS):
        ct, st = np.cos(q[i]), np.sin(q[i])
        ca, sa = np.cos(DH_ALPHA[i]), np.sin(DH_ALPHA[i])
        link = np.array(
            [
                [ct, -st * ca, st * sa, DH_A[i] * ct],
                [st, ct * ca, -ct * sa, DH_A[i] * st],
                [0.0, sa, ca, DH_D[i]],
                [0.0, 0.0, 0.0, 1.0],
            ]
        )
        frames[i + 1] = frames[i] @ link
    return frames


def flange_pose(q) -> np.ndarray:
    """Homogeneous transform of the flange (DH frame 6, ``tool0``) in the base frame, (4, 4)."""
    return dh_frames(q)[-1]


class SingularConfigurationError(ValueError):
    """Raised where the analytic Jacobian cannot be formed (Euler-angle gimbal lock)."""


def wrap_angle(angle):
    """Wrap angles [rad] to (-pi, pi] (ERRATA: the orientation error of seed 000 must be wrapped)."""
    return np.pi - np.mod(np.pi - np.asarray(angle, dtype=float), 2 * np.pi)


def zyx_euler_from_rotation(rotation: np.ndarray) -> np.ndarray:
    """Z-Y-X Euler angles (phi_X, phi_Y, phi_Z) [rad] of R = Rz(phi_Z) Ry(phi_Y) Rx(phi_X).

    Seed 000, k(q) rows 4-6: phi_X = atan2(r32, r33), phi_Y = atan2(-r31, sqrt(r32^2 + r33^2)),
    phi_Z = atan2(r21, r11).
    """
    r = rotation
    return np.array(
        [
            np.arctan2(r[2, 1], r[2, 2]),
            np.arctan2(-r[2, 0], np.hypot(r[2, 1], r[2, 2])),
            np.arctan2(r[1, 0], r[0, 0]),
        ]
    )


def rotation_from_zyx_euler(phi) -> np.ndarray:
    """Rotation matrix Rz(phi_Z) Ry(phi_Y) Rx(phi_X) for phi = (phi_X, phi_Y, phi_Z) [rad]."""
    (cx, cy, cz), (sx, sy, sz) = np.cos(phi), np.sin(phi)
    return np.array(
        [
            [cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx],
            [sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx],
            [-sy, cy * sx, cy * cx],
        ]
    )


def task_pose(q) -> np.ndarray:
    """k(q) of seed 000: [x, y, z, phi_X, phi_Y, phi_Z] of the flange in the base frame [m, rad]."""
    pose = flange_pose(q)
    return np.concatenate([pose[:3, 3], zyx_euler_from_rotation(pose[:3, :3])])


def task_pose_error(pose, goal) -> np.ndarray:
    """e = pose - goal (eq. 6) with the orientation part wrapped to (-pi, pi] (ERRATA)."""
    error = np.asarray(pose, dtype=float) - np.asarray(goal, dtype=float)
    error[3:] = wrap_angle(error[3:])
    return error


def euler_rate_matrix(phi) -> np.ndarray:
    """B(phi) with omega = B(phi) d(phi)/dt, columns ordered (phi_X, phi_Y, phi_Z) like k(q).

    Seed 000 prints B with its columns in Z, Y, X order; ERRATA: they must follow k(q)'s order.
    """
    _, phi_y, phi_z = phi
    cy, sy, cz, sz = np.cos(phi_y), np.sin(phi_y), np.cos(phi_z), np.sin(phi_z)
    return np.array([[cy * cz, -sz, 0.0], [cy * sz, cz, 0.0], [-sy, 0.0, 1.0]])


def _euler_rate_matrix_derivative(phi, phi_dot) -> np.ndarray:
    """dB/dt for B of :func:`euler_rate_matrix`, given Euler rates phi_dot [rad/s]."""
    _, phi_y, phi_z = phi
    cy, sy, cz, sz = np.cos(phi_y), np.sin(phi_y), np.cos(phi_z), np.sin(phi_z)
    d_dy = np.array([[-sy * cz, 0.0, 0.0], [-sy * sz, 0.0, 0.0], [-cy, 0.0, 0.0]])
    d_dz = np.array([[-cy * sz, -cz, 0.0], [cy * cz, -sz, 0.0], [0.0, 0.0, 0.0]])
    return d_dy * phi_dot[1] + d_dz * phi_dot[2]


def geometric_jacobian(q) -> np.ndarray:
    """J_g(q) (6x6): [v; omega] of the flange in the base frame, v = d/dt of the flange origin."""
    return _geometric_jacobian(dh_frames(q))


def _geometric_jacobian(frames: np.ndarray) -> np.ndarray:
    axes = frames[:-1, :3, 2]  # z_{j-1}: axis of joint j, (6, 3)
    origins = frames[:-1, :3, 3]
    flange = frames[-1, :3, 3]
    return np.vstack([np.cross(axes, flange - origins).T, axes.T])


def _geometric_jacobian_bias(frames: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """dJ_g/dt qd: the flange's [linear; angular] acceleration when qdd = 0 (base frame)."""
    axes = frames[:-1, :3, 2]
    origins = frames[:, :3, 3]
    # omega_j: angular velocity of the frame carrying axis j, v_j: velocity of that frame's origin.
    omegas = np.vstack([np.zeros(3), np.cumsum(axes * qd[:, None], axis=0)])
    velocities = np.array(
        [np.sum(np.cross(axes[:j], origins[j] - origins[:j]) * qd[:j, None], axis=0) for j in range(7)]
    )
    axis_rates = np.cross(omegas[:-1], axes)  # dz_j/dt = omega_j x z_j
    linear = np.cross(axis_rates, origins[-1] - origins[:-1]) + np.cross(axes, velocities[-1] - velocities[:-1])
    return np.concatenate([linear.T @ qd, axis_rates.T @ qd])


def analytic_jacobian(q, *, min_cos_pitch: float = 1e-6) -> np.ndarray:
    """J(q) = diag(I, B^-1(phi)) J_g(q) (seed 000): d k(q)/dt = J(q) qd.

    Raises SingularConfigurationError where cos(phi_Y) < ``min_cos_pitch`` (Euler gimbal lock).
    """
    return analytic_jacobian_and_bias(q, np.zeros(NUM_JOINTS), min_cos_pitch=min_cos_pitch)[0]


def analytic_jacobian_and_bias(q, qd, *, min_cos_pitch: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """(J(q), dJ/dt(q, qd) qd) of the analytic Jacobian, in one pass over the chain.

    The bias term is the second derivative of k(q(t)) when qdd = 0:
    [a_bias; B^-1 (alpha_bias - dB/dt phi_dot)] with phi_dot = B^-1 omega.
    """
    qd = _as_joint_vector(qd, "qd")
    frames = dh_frames(q)
    phi = zyx_euler_from_rotation(frames[-1, :3, :3])
    if abs(np.cos(phi[1])) < min_cos_pitch:
        raise SingularConfigurationError(
            f"Z-Y-X Euler angles are singular at q={np.round(q, 6).tolist()}: "
            f"phi_Y = {phi[1]:.6f} rad is at +-pi/2 (gimbal lock), B(phi) has no inverse"
        )
    jacobian_g = _geometric_jacobian(frames)
    b = euler_rate_matrix(phi)
    jacobian = np.vstack([jacobian_g[:3], np.linalg.solve(b, jacobian_g[3:])])
    bias_g = _geometric_jacobian_bias(frames, qd)
    phi_dot = jacobian[3:] @ qd
    angular_bias = np.linalg.solve(b, bias_g[3:] - _euler_rate_matrix_derivative(phi, phi_dot) @ phi_dot)
    return jacobian, np.concatenate([bias_g[:3], angular_bias])
