"""UR10e: model file, published limits and analytic kinematics.

Frames follow ``docs/ur10e.md`` and Pająk 2024: the base frame is standard-DH frame 0
(UR's controller "Base" frame), the flange ``tool0`` is DH frame 6. The task-space pose is
p = k(q) = [x, y, z, phi_X, phi_Y, phi_Z]: the TCP's position in metres and Z-Y-X Euler angles in
radians (R = Rz(phi_Z) Ry(phi_Y) Rx(phi_X)), as used by UR's software and by Pająk 2024. The TCP is
the flange unless a ``tool`` X_FT (4x4, the TCP in the flange frame; ``Robot.with_tcp``) is given.

Everything here is plain numpy so tests and planners can call it without building a plant; the
tests check it against Drake's MultibodyPlant.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import ClassVar

import numpy as np

from drake_traj.compiled import compiled
from drake_traj.errors import Cause, DrakeTrajError, SingularConfigurationError, joint_label
from drake_traj.robots.base import FLANGE, Robot, TaskKinematics
from drake_traj.robots.task_space import (is_flange, orientation_error, pose_error, rotation_from_zyx_euler, tcp_rows_into,
                                          wrap_angle, wrapped, zyx_euler_from_rotation)
from drake_traj.validation import invalid, real_array

__all__ = ["UR10E", "UR10e"]

NUM_JOINTS = 6

# Standard DH parameters (docs/ur10e.md; Pająk 2024 Table 1 is the same chain in modified DH).
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
# UR controller defaults for joint moves, used by Pająk 2024 for every joint.
DEFAULT_JOINT_MOVE_VELOCITY = 1.05  # [rad/s] (60 deg/s)
DEFAULT_JOINT_MOVE_ACCELERATION = 1.40  # [rad/s^2] (80 deg/s^2)
# Default PD gains per joint [N m/rad], [N m s/rad]: see README "Controller" for how they were chosen.
DEFAULT_KP = (4000.0, 4000.0, 2000.0, 500.0, 500.0, 300.0)
DEFAULT_KD = (200.0, 200.0, 100.0, 20.0, 20.0, 10.0)
# The start configuration of Pająk 2024's task, q(0) [rad]: the flange at
# p0 = [-0.174, -0.524, 0.273, pi, 0, 3pi/4]; our home configuration.
HOME = (-np.pi / 2, -np.pi / 2, -3 * np.pi / 4, -np.pi / 4, np.pi / 2, np.pi / 4)

LINK_MASSES = np.array([7.369, 13.051, 3.989, 2.1, 1.98, 0.615])  # [kg], links 1..6
BASE_MASS = 4.0  # [kg], approximate; the base is welded to the world.
_D1, _D4, _D5, _D6 = (float(DH_D[k]) for k in (0, 3, 4, 5))
_A2, _A3 = float(DH_A[1]), float(DH_A[2])
FLANGE_FRAME = "tool0"
# The closed form's data, the ``model`` argument of kinematics_into: [UR_CLOSED_FORM, d1, a2, a3, d4, d5, d6]
UR_CLOSED_FORM = 0.0
MODEL = np.array([UR_CLOSED_FORM, _D1, _A2, _A3, _D4, _D5, _D6])
MODEL.flags.writeable = False
BASE_FRAME = "base"


def model_path() -> Path:
    """Absolute path of the UR10e URDF shipped with the package (``models/ur10e.urdf``)."""
    return UR10E.model_path()


def _as_joint_vector(q, name: str = "q") -> np.ndarray:
    q = real_array(q, name, "rad")
    if q.shape != (NUM_JOINTS,):
        raise invalid(name, f"{name} must have shape ({NUM_JOINTS},), got {q.shape}")
    if not np.all(np.isfinite(q)):
        raise invalid(name, f"{name} must be finite, got {q}")
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


def task_pose(q, tool=FLANGE) -> np.ndarray:
    """k(q) of Pająk 2024: [x, y, z, phi_X, phi_Y, phi_Z] of the TCP in the base frame [m, rad];
    ``tool`` (4, 4) is X_FT, the TCP in the flange frame (default: the flange itself)."""
    pose = flange_pose(q)
    if not is_flange(tool):
        pose = pose @ tool
    return np.concatenate([pose[:3, 3], zyx_euler_from_rotation(pose[:3, :3])])


def geometric_jacobian(q) -> np.ndarray:
    """J_g(q) (6x6): [v; omega] of the flange in the base frame, v = d/dt of the flange origin."""
    return _geometric_jacobian(dh_frames(q))


def _geometric_jacobian(frames: np.ndarray) -> np.ndarray:
    axes = frames[:-1, :3, 2]  # z_{j-1}: axis of joint j, (6, 3)
    origins = frames[:-1, :3, 3]
    flange = frames[-1, :3, 3]
    return np.vstack([np.cross(axes, flange - origins).T, axes.T])


def analytic_jacobian(q, *, min_cos_pitch: float = 1e-6, tool=FLANGE) -> np.ndarray:
    """J(q) = diag(I, B^-1(phi)) J_g(q) (Pająk 2024): d k(q)/dt = J(q) qd, of the TCP ``tool``
    (X_FT, default the flange).

    Raises SingularConfigurationError where cos(phi_Y) < ``min_cos_pitch`` (Euler gimbal lock).
    """
    return analytic_jacobian_and_bias(q, np.zeros(NUM_JOINTS), min_cos_pitch=min_cos_pitch, tool=tool)[0]


def analytic_jacobian_and_bias(q, qd, *, min_cos_pitch: float = 1e-6,
                               tool=FLANGE) -> tuple[np.ndarray, np.ndarray]:
    """(J(q), dJ/dt(q, qd) qd) of the analytic Jacobian (Pająk 2024) of the TCP ``tool`` (X_FT,
    default the flange), from :func:`ur10e_kinematics`.

    The bias term is the second derivative of k(q(t)) when qdd = 0.
    Raises SingularConfigurationError where cos(phi_Y) < ``min_cos_pitch`` (Euler gimbal lock).
    """
    q = _as_joint_vector(q)
    qd = _as_joint_vector(qd, "qd")
    pose, jacobian, bias, cos_pitch, _ = ur10e_kinematics(q, qd, tool)
    if cos_pitch < min_cos_pitch:
        raise SingularConfigurationError(
            f"Z-Y-X Euler angles are singular at q={np.round(q, 6).tolist()}: "
            f"phi_Y = {pose[4]:.6f} rad is at +-pi/2 (gimbal lock), B(phi) has no inverse"
        )
    return jacobian, bias


# --------------------------------------------------------------------------------------------
# Closed-form k(q), analytic J(q) and J̇q̇: the hot path of the task-space planners, compiled.
# --------------------------------------------------------------------------------------------


@compiled
def _singularity_factors(model, s3, s5, c2, c23, s234):
    # det J_g = a2 a3 s3 s5 (a2 c2 + a3 c23 + d5 s234): elbow, wrist and shoulder factors.
    a2, a3, d5 = model[2], model[3], model[5]
    shoulder = (a2 * c2 + a3 * c23 + d5 * s234) / (abs(a2) + abs(a3))
    return min(abs(s3), abs(s5), abs(shoulder))


@compiled
def kinematics_into(model, q, qd, tool, pose, jac, bias):
    """k(q) into ``pose`` (6), the analytic J into ``jac`` (6, 6) and J̇q̇ into ``bias`` (6) of the
    TCP; returns (cos φ_Y, singularity measure). Compiled; the kernel of :func:`ur10e_kinematics`.

    ``model`` is the closed form's data [UR_CLOSED_FORM, d1, a2, a3, d4, d5, d6] [m] (:data:`MODEL`
    for the UR10e); ``tool`` (4, 4) is X_FT, the TCP in the flange frame F (``tool0``). The
    standard-DH chain of :func:`dh_frames` written out: joint axes z_j at origins o_j, flange o_6;
    J_g columns z_j x (o_6 - o_j) and z_j; the bias by the velocity/acceleration recursion with
    q̈ = 0; the TCP and the Euler-angle rows by :func:`~drake_traj.robots.task_space.tcp_rows_into`.
    """
    c1, s1 = math.cos(q[0]), math.sin(q[0])
    c2, s2 = math.cos(q[1]), math.sin(q[1])
    c5, s5 = math.cos(q[4]), math.sin(q[4])
    c6, s6 = math.cos(q[5]), math.sin(q[5])
    q23 = q[1] + q[2]
    q234 = q23 + q[3]
    c23, s23 = math.cos(q23), math.sin(q23)
    c234, s234 = math.cos(q234), math.sin(q234)
    # joint axes z_0..z_5 (z_1 = z_2 = z_3) and the link vectors r_j = o_{j+1} - o_j
    axes = np.empty((6, 3))
    links = np.empty((6, 3))
    axes[0, 0], axes[0, 1], axes[0, 2] = 0.0, 0.0, 1.0
    for j in range(1, 4):
        axes[j, 0], axes[j, 1], axes[j, 2] = s1, -c1, 0.0
    x4 = (c1 * c234, s1 * c234, s234)
    axes[4, 0], axes[4, 1], axes[4, 2] = c1 * s234, s1 * s234, -c234
    axes[5, 0], axes[5, 1], axes[5, 2] = c5 * s1 - s5 * x4[0], -c5 * c1 - s5 * x4[1], -s5 * s234
    x5 = (c5 * x4[0] + s5 * s1, c5 * x4[1] - s5 * c1, c5 * s234)
    links[0, 0], links[0, 1], links[0, 2] = 0.0, 0.0, model[1]
    links[1, 0], links[1, 1], links[1, 2] = model[2] * c1 * c2, model[2] * s1 * c2, model[2] * s2
    links[2, 0], links[2, 1], links[2, 2] = model[3] * c1 * c23, model[3] * s1 * c23, model[3] * s23
    links[3, 0], links[3, 1], links[3, 2] = model[4] * s1, -model[4] * c1, 0.0
    for k in range(3):
        links[4, k] = model[5] * axes[4, k]
        links[5, k] = model[6] * axes[5, k]
    # J_v column j = z_j x (o_6 - o_j), accumulating o_6 - o_j from the flange back
    p0 = p1 = p2 = 0.0
    for j in range(5, -1, -1):
        p0 += links[j, 0]
        p1 += links[j, 1]
        p2 += links[j, 2]
        jac[0, j] = axes[j, 1] * p2 - axes[j, 2] * p1
        jac[1, j] = axes[j, 2] * p0 - axes[j, 0] * p2
        jac[2, j] = axes[j, 0] * p1 - axes[j, 1] * p0
    # bias recursion (q̈ = 0): α_{j+1} = α_j + ω_j x z_j q̇_j, ω_{j+1} = ω_j + z_j q̇_j,
    # a_{j+1} = a_j + α_{j+1} x r_j + ω_{j+1} x (ω_{j+1} x r_j)
    w0 = w1 = w2 = 0.0
    al0 = al1 = al2 = 0.0
    l0 = l1 = l2 = 0.0
    for j in range(6):
        z0, z1, z2 = axes[j, 0] * qd[j], axes[j, 1] * qd[j], axes[j, 2] * qd[j]
        al0 += w1 * z2 - w2 * z1
        al1 += w2 * z0 - w0 * z2
        al2 += w0 * z1 - w1 * z0
        w0 += z0
        w1 += z1
        w2 += z2
        r0, r1, r2 = links[j, 0], links[j, 1], links[j, 2]
        u0, u1, u2 = w1 * r2 - w2 * r1, w2 * r0 - w0 * r2, w0 * r1 - w1 * r0
        l0 += al1 * r2 - al2 * r1 + w1 * u2 - w2 * u1
        l1 += al2 * r0 - al0 * r2 + w2 * u0 - w0 * u2
        l2 += al0 * r1 - al1 * r0 + w0 * u1 - w1 * u0
    # the flange's rotation R_F = [x6 y6 z6]: x6 = c6 x5 - s6 z4, y6 = -s6 x5 - c6 z4, z6 = z5
    rotation = np.empty((3, 3))
    for k in range(3):
        rotation[k, 0] = c6 * x5[k] - s6 * axes[4, k]
        rotation[k, 1] = -s6 * x5[k] - c6 * axes[4, k]
        rotation[k, 2] = axes[5, k]
    flange, omega, alpha, acceleration = np.array((p0, p1, p2)), np.array((w0, w1, w2)), np.array((al0, al1, al2)), \
        np.array((l0, l1, l2))
    cy = tcp_rows_into(rotation, axes, flange, omega, alpha, acceleration, tool, pose, jac, bias)
    return cy, _singularity_factors(model, math.sin(q[2]), s5, c2, c23, s234)


@compiled
def _kinematics_many(model, q, qd, tool, pose, jac, bias, cos_pitch, measure):
    for k in range(q.shape[0]):
        cos_pitch[k], measure[k] = kinematics_into(model, q[k], qd[k], tool, pose[k], jac[k], bias[k])


def ur10e_kinematics(q, qd, tool=FLANGE):
    """(k(q), J(q), J̇(q, q̇) q̇, cos φ_Y, singularity measure) of the UR10e's TCP, ``tool``
    (4, 4) X_FT in the flange frame (default: the flange itself).

    The closed form of :func:`kinematics_into` (tests check it against MultibodyPlant and finite
    differences of :func:`task_pose`), vectorised over leading dimensions (q, q̇ of shape (..., 6)).

    Returns:
        pose (..., 6), J (..., 6, 6), bias (..., 6), cos_pitch (...), measure (...), where
        ``measure`` is :func:`singularity_measure`. No exception at gimbal lock: callers check
        ``cos_pitch``. For one state, cos_pitch and measure are floats.
    """
    q = np.asarray(q, dtype=float)
    qd = np.asarray(qd, dtype=float)
    if q.shape == (6,) and qd.shape == (6,):
        pose, jac, bias = np.empty(6), np.empty((6, 6)), np.empty(6)
        cos_pitch, measure = kinematics_into(MODEL, q, qd, tool, pose, jac, bias)
        return pose, jac, bias, cos_pitch, measure
    shape = np.broadcast_shapes(q.shape, qd.shape)
    if shape[-1] != 6:
        raise ValueError(f"q and qd must have shape (..., 6), got {q.shape} and {qd.shape}")
    q = np.ascontiguousarray(np.broadcast_to(q, shape).reshape(-1, 6))
    qd = np.ascontiguousarray(np.broadcast_to(qd, shape).reshape(-1, 6))
    count = q.shape[0]
    pose, jac, bias = np.empty((count, 6)), np.empty((count, 6, 6)), np.empty((count, 6))
    cos_pitch, measure = np.empty(count), np.empty(count)
    _kinematics_many(MODEL, q, qd, tool, pose, jac, bias, cos_pitch, measure)
    lead = shape[:-1]
    return pose.reshape(lead + (6,)), jac.reshape(lead + (6, 6)), bias.reshape(lead + (6,)), \
        cos_pitch.reshape(lead), measure.reshape(lead)


@compiled
def _singularity_measure_many(model, q, out):
    for k in range(q.shape[0]):
        out[k] = _singularity_factors(model, math.sin(q[k, 2]), math.sin(q[k, 4]), math.cos(q[k, 1]),
                                      math.cos(q[k, 1] + q[k, 2]), math.sin(q[k, 1] + q[k, 2] + q[k, 3]))


def singularity_measure(q):
    """min(|sin q3|, |sin q5|, |a2 c2 + a3 c23 + d5 s234| / (|a2| + |a3|)), in [0, 1].

    det J_g = a2 a3 s3 s5 (a2 c2 + a3 c23 + d5 s234) for the UR10e: the three factors are the
    elbow, wrist and shoulder singularities; the measure is zero exactly at a singular J.
    q has shape (..., 6); the result the leading shape (a float for one q).
    """
    q = np.asarray(q, dtype=float)
    rows = np.ascontiguousarray(q.reshape(-1, 6))
    out = np.empty(rows.shape[0])
    _singularity_measure_many(MODEL, rows, out)
    return float(out[0]) if q.ndim == 1 else out.reshape(q.shape[:-1])


def singularity_factors(q) -> dict[str, tuple[float, str]]:
    """The three factors of det J_g at one configuration q [rad] (6,), each in [0, 1] and zero at
    its singularity (:func:`singularity_measure` is the smallest), with what that singularity is:
    ``elbow`` |sin q3|, ``wrist`` |sin q5|, ``shoulder`` |a2 c2 + a3 c23 + d5 s234| / (|a2| + |a3|)."""
    q = np.asarray(q, dtype=float)
    shoulder = (_A2 * np.cos(q[1]) + _A3 * np.cos(q[1] + q[2]) + _D5 * np.sin(q[1] + q[2] + q[3])) / (
        abs(_A2) + abs(_A3))
    return {"elbow": (float(abs(np.sin(q[2]))), "sin q3 near 0, the arm stretched or folded"),
            "wrist": (float(abs(np.sin(q[4]))), "sin q5 near 0, joints 4 and 6 aligned"),
            "shoulder": (float(abs(shoulder)), "the wrist centre near the axis of joint 1")}


# --------------------------------------------------------------------------------------------
# Analytic inverse kinematics of the flange (closed form from the standard-DH chain above).
# --------------------------------------------------------------------------------------------
#
# Derivation (frames of dh_frames; z1 = (s1, -c1, 0), x1 = (c1, s1, 0) is the arm plane direction):
#   * wrist centre o5 = p - d6 z6. Joints 2, 3, 4 rotate about z1, a2/a3 lie in the arm plane and
#     d5 z4 is perpendicular to z1, so o5 . z1 = d4: with (r, psi) the polar coordinates of o5
#     in the base xy-plane, r sin(q1 - psi) = d4 and r cos(q1 - psi) = h = o5 . x1 =
#     a2 c2 + a3 c23 + d5 s234 (the shoulder factor of det J_g), h = +-sqrt(r^2 - d4^2).
#   * z6 = c5 z1 - s5 x4, x6 . z1 = s5 c6, y6 . z1 = -s5 s6: c5 = z6 . z1, |s5| = |(x6, y6) . z1|
#     (sign: wrist branch), q6 = atan2(-y6 . z1 / s5, x6 . z1 / s5).
#   * x4 = (c5 z1 - z6) / s5 = (c1 c234, s1 c234, s234) gives q234.
#   * o4 = o5 - d5 z4: the planar 2R arm u + i v = e^{i q2} (a2 + a3 e^{i q3}) with
#     u = o4 . x1, v = o4_z - d1 (elbow branch: sign of s3); q4 = q234 - q2 - q3.
# Branch signs are therefore (sign h, sign sin q3, sign sin q5): the three factors of
# det J_g = a2 a3 s3 s5 h, constant along any path that avoids the singularities.

# |h| / (|a2| + |a3|), |sin q3| and |sin q5| below this are singular; sin q3 and h come from square
# roots and are resolved only to about sqrt(machine eps) ~ 1.5e-8, so the tolerance sits above that.
IK_SINGULAR_TOLERANCE = 1e-7
IK_BRANCHES = tuple((s, e, w) for s in (1, -1) for e in (1, -1) for w in (1, -1))
IK_PATH_MAX_STEP = 0.5  # [rad], largest joint step between consecutive path samples


def ik_branch(q) -> tuple[int, int, int]:
    """(shoulder, elbow, wrist) branch signs of configuration q, as used by :func:`inverse_kinematics`.

    shoulder = sign(a2 c2 + a3 c23 + d5 s234) (wrist centre on the +x1 / -x1 side of the joint-1
    axis), elbow = sign(sin q3), wrist = sign(sin q5); 0 where the factor is exactly zero.
    """
    q = _as_joint_vector(q)
    h = _A2 * math.cos(q[1]) + _A3 * math.cos(q[1] + q[2]) + _D5 * math.sin(q[1] + q[2] + q[3])
    return tuple(int(np.sign(v)) for v in (h, math.sin(q[2]), math.sin(q[4])))


def _describe_pose(pose: np.ndarray) -> str:
    phi = zyx_euler_from_rotation(pose[:3, :3])
    return (
        f"pose (x, y, z) = ({pose[0, 3]:.6g}, {pose[1, 3]:.6g}, {pose[2, 3]:.6g}) m, "
        f"(phi_X, phi_Y, phi_Z) = ({phi[0]:.6g}, {phi[1]:.6g}, {phi[2]:.6g}) rad"
    )


def _as_flange_pose(pose, name: str = "pose") -> np.ndarray:
    """A 4x4 homogeneous transform, or a task pose [x, y, z, phi_X, phi_Y, phi_Z], as a checked 4x4."""
    pose = np.asarray(pose, dtype=float)
    if pose.shape == (6,):
        if not np.all(np.isfinite(pose)):
            raise invalid(name, f"{name} must be finite, got {pose}")
        out = np.eye(4)
        out[:3, :3] = rotation_from_zyx_euler(pose[3:])
        out[:3, 3] = pose[:3]
        return out
    if pose.shape != (4, 4):
        raise ValueError(
            f"{name} must be a 4x4 transform or a task pose of shape (6,), got shape {pose.shape}"
        )
    if not np.all(np.isfinite(pose)):
        raise invalid(name, f"{name} must be finite, got {pose.tolist()}")
    if not np.allclose(pose[3], [0.0, 0.0, 0.0, 1.0], atol=1e-12, rtol=0.0):
        raise invalid(name, f"{name} must have last row [0, 0, 0, 1], got {pose[3].tolist()}")
    rotation = pose[:3, :3]
    orthogonality = np.max(np.abs(rotation.T @ rotation - np.eye(3)))
    if orthogonality > 1e-6 or np.linalg.det(rotation) <= 0.0:
        raise ValueError(
            f"{name} rotation block is not a proper rotation (|R^T R - I|max = {orthogonality:.3g}, "
            f"det R = {np.linalg.det(rotation):.6g})"
        )
    return pose


def _flange_goal(pose, tool) -> np.ndarray:
    """The flange pose X_BF (4, 4) that puts the TCP ``tool`` (X_FT) at ``pose`` X_BT (a 4x4
    transform or a task pose [x, y, z, phi_X, phi_Y, phi_Z]): X_BF = X_BT X_FT⁻¹."""
    pose = _as_flange_pose(pose)
    if is_flange(tool):
        return pose
    inverse = np.eye(4)
    inverse[:3, :3] = tool[:3, :3].T
    inverse[:3, 3] = -tool[:3, :3].T @ tool[:3, 3]
    return pose @ inverse


def _ik_solve(pose: np.ndarray, tol: float):
    """All branch solutions of the 4x4 flange pose.

    Returns (solutions, failures, flags): solutions maps branch -> q (wrapped); failures maps branch
    -> reason for branches without a real solution; flags = dict(shoulder=bool, wrist=set of shoulder
    signs, elbow=set of branches) marking singular factors. Raises ValueError when the pose is out of
    reach (no branch has a solution and none is wrist-singular).
    """
    rot, p = pose[:3, :3], pose[:3, 3]
    z6 = rot[:, 2]
    o5 = p - _D6 * z6
    r = math.hypot(o5[0], o5[1])
    h_sq = r * r - _D4 * _D4
    reach = abs(_A2) + abs(_A3)
    if h_sq < -(tol * reach) ** 2:
        raise DrakeTrajError(
            f"{_describe_pose(pose)} is out of reach: the wrist centre (flange - d6 z) is "
            f"{r:.6g} m from the joint-1 axis, closer than the shoulder offset d4 = {_D4} m", cause=Cause.UNREACHABLE
        )
    h_abs = math.sqrt(max(h_sq, 0.0))
    shoulder_singular = h_abs < tol * reach
    psi = math.atan2(o5[1], o5[0])
    solutions, failures = {}, {}
    elbow_singular = set()
    wrist_singular = set()
    for shoulder in (1, -1):
        q1 = psi + math.atan2(_D4, shoulder * h_abs)
        c1, s1 = math.cos(q1), math.sin(q1)
        z1 = np.array([s1, -c1, 0.0])
        c5 = float(z6 @ z1)
        s5c6 = float(rot[:, 0] @ z1)  # x6 . z1 = s5 c6
        ms5s6 = float(rot[:, 1] @ z1)  # y6 . z1 = -s5 s6
        s5_abs = math.hypot(s5c6, ms5s6)
        if s5_abs < tol:
            wrist_singular.add(shoulder)
            continue
        for wrist in (1, -1):
            s5 = wrist * s5_abs
            q5 = math.atan2(s5, c5)
            q6 = math.atan2(-ms5s6 / s5, s5c6 / s5)
            x4 = (c5 * z1 - z6) / s5
            q234 = math.atan2(x4[2], c1 * x4[0] + s1 * x4[1])
            c234, s234 = math.cos(q234), math.sin(q234)
            o4 = o5 - _D5 * np.array([c1 * s234, s1 * s234, -c234])
            u = c1 * o4[0] + s1 * o4[1]
            v = o4[2] - _D1
            dist = math.hypot(u, v)
            c3 = (dist * dist - _A2 * _A2 - _A3 * _A3) / (2.0 * _A2 * _A3)
            if abs(c3) > 1.0 + tol:
                for elbow in (1, -1):
                    failures[(shoulder, elbow, wrist)] = (
                        f"the wrist-1 joint would be {dist:.6g} m from the shoulder joint, outside the "
                        f"reach [{abs(abs(_A2) - abs(_A3)):.6g}, {reach:.6g}] m of the upper arm and forearm"
                    )
                continue
            c3 = min(1.0, max(-1.0, c3))
            s3_abs = math.sqrt(1.0 - c3 * c3)
            for elbow in (1, -1):
                if s3_abs < tol:
                    elbow_singular.add((shoulder, elbow, wrist))
                q3 = math.atan2(elbow * s3_abs, c3)
                q2 = math.atan2(v, u) - math.atan2(_A3 * elbow * s3_abs, _A2 + _A3 * c3)
                q4 = q234 - q2 - q3
                q = wrap_angle(np.array([q1, q2, q3, q4, q5, q6]))
                solutions[(shoulder, elbow, wrist)] = q
    flags = dict(shoulder=shoulder_singular, wrist=wrist_singular, elbow=elbow_singular)
    if not solutions and not wrist_singular:
        centre = math.hypot(r, o5[2] - _D1)
        max_centre = math.hypot(reach + _D5, _D4)
        reasons = "; ".join(dict.fromkeys(failures.values()))
        raise DrakeTrajError(
            f"{_describe_pose(pose)} is out of reach: the wrist centre (flange - d6 z) is {centre:.6g} m "
            f"from the shoulder point (0, 0, d1) (the arm reaches at most {max_centre:.6g} m); {reasons}",
            cause=Cause.UNREACHABLE)
    return solutions, failures, flags


def _raise_wrist_singular(pose: np.ndarray) -> None:
    raise SingularConfigurationError(
        f"{_describe_pose(pose)} is at a wrist singularity (sin q5 = 0: flange z axis parallel to "
        f"joint axes 2-4): q4 and q6 are not determined individually, the wrist branch is undefined"
    )


def _unique_rows(solutions, atol: float = 1e-12) -> np.ndarray:
    rows = []
    for q in solutions:
        if not any(np.max(np.abs(wrap_angle(q - other))) <= atol for other in rows):
            rows.append(q)
    return np.array(rows).reshape(-1, NUM_JOINTS)


def inverse_kinematics_all(pose, *, singular_tol: float = IK_SINGULAR_TOLERANCE, tool=FLANGE) -> np.ndarray:
    """All real joint solutions q (k, 6), k <= 8, with flange_pose(q) = pose; each wrapped to (-pi, pi].

    ``pose``: 4x4 transform of ``tool0`` in the base frame, or task pose [x, y, z, phi_X, phi_Y, phi_Z];
    with ``tool`` (X_FT, 4x4), the pose of that TCP (:func:`_flange_goal`; errors describe the
    flange pose it needs).
    Rows are ordered by branch as in ``IK_BRANCHES`` ((shoulder, elbow, wrist) signs, see
    :func:`ik_branch`); branches without a real solution are left out, and solutions that coincide
    (at a shoulder or elbow singularity) are listed once.

    Raises ValueError naming the pose and the reason (distances) when no branch reaches the pose,
    and SingularConfigurationError at a wrist singularity (sin q5 = 0: a continuum of solutions).
    """
    pose = _flange_goal(pose, tool)
    solutions, _, flags = _ik_solve(pose, singular_tol)
    if flags["wrist"]:
        _raise_wrist_singular(pose)
    return _unique_rows([solutions[b] for b in IK_BRANCHES if b in solutions])


def _nearest_equivalent(q: np.ndarray, near: np.ndarray) -> np.ndarray:
    """q shifted joint-wise by multiples of 2 pi towards ``near``, kept inside POSITION_LIMIT."""
    shifted = q + 2 * np.pi * np.round((near - q) / (2 * np.pi))
    outside = np.abs(shifted) > POSITION_LIMIT
    shifted[outside] -= 2 * np.pi * np.sign(shifted[outside])
    return shifted


def inverse_kinematics(
    pose,
    *,
    branch=None,
    near=None,
    singular_tol: float = IK_SINGULAR_TOLERANCE,
    tool=FLANGE,
) -> np.ndarray:
    """One joint solution q (6,) of a flange pose: 4x4 transform or task pose [x, y, z, phi_X, phi_Y, phi_Z];
    with ``tool`` (X_FT, 4x4), of that TCP's pose (:func:`_flange_goal`; errors describe the
    flange pose it needs).

    branch: (shoulder, elbow, wrist) signs, each +1 or -1 (see :func:`ik_branch`); the result is
        wrapped to (-pi, pi] unless ``near`` is also given.
    near: joint vector; the solution (of ``branch`` if given, else of all branches) closest to it in
        joint space, each joint shifted by multiples of 2 pi towards ``near`` (within POSITION_LIMIT),
        so that solving along a continuous path gives a continuous q.
    With neither, the first branch of ``IK_BRANCHES`` that has a solution.

    Raises ValueError naming the pose and the reason (distances) when the pose (or the requested
    branch) is out of reach; SingularConfigurationError at a wrist singularity (sin q5 = 0; for
    ``branch``, of that shoulder branch), and at a shoulder (wrist centre on the cylinder of
    radius d4 about the joint-1 axis) or elbow (sin q3 = 0) singularity when ``branch`` asks for a
    shoulder or elbow sign, which is undefined there.
    """
    pose = _flange_goal(pose, tool)
    if branch is not None:
        branch = tuple(int(b) for b in np.asarray(branch).reshape(-1)) if np.size(branch) == 3 else None
        if branch is None or any(b not in (-1, 1) for b in branch):
            raise ValueError("branch must be three signs (shoulder, elbow, wrist), each +1 or -1")
    if near is not None:
        near = _as_joint_vector(near, "near")
    solutions, failures, flags = _ik_solve(pose, singular_tol)
    if flags["wrist"] and (branch is None or branch[0] in flags["wrist"]):
        _raise_wrist_singular(pose)
    if branch is not None:
        if flags["shoulder"]:
            raise SingularConfigurationError(
                f"{_describe_pose(pose)} is at a shoulder singularity (wrist centre on the cylinder of "
                f"radius d4 = {_D4} m about the joint-1 axis): the shoulder branch is undefined"
            )
        if branch in flags["elbow"]:
            raise SingularConfigurationError(
                f"{_describe_pose(pose)} is at an elbow singularity (sin q3 = 0, arm fully stretched or "
                f"folded): the elbow branch is undefined"
            )
        if branch not in solutions:
            raise DrakeTrajError(
                f"{_describe_pose(pose)} is out of reach of branch (shoulder, elbow, wrist) = {branch}: "
                f"{failures.get(branch, 'no real solution')}", cause=Cause.UNREACHABLE
            )
        candidates = [solutions[branch]]
    else:
        candidates = [solutions[b] for b in IK_BRANCHES if b in solutions]
    if near is None:
        return candidates[0].copy()
    shifted = [_nearest_equivalent(q, near) for q in candidates]
    return min(shifted, key=lambda q: float(np.sum((q - near) ** 2)))


def inverse_kinematics_path(
    poses,
    q_start,
    *,
    max_step: float = IK_PATH_MAX_STEP,
    singular_tol: float = IK_SINGULAR_TOLERANCE,
) -> np.ndarray:
    """Joint path (N, 6) through the flange poses (N, 4, 4) or task poses (N, 6), one branch throughout.

    Sample 0 is the solution nearest ``q_start``, every later sample the solution nearest the previous
    one (2 pi wrapping resolved towards it, see :func:`inverse_kinematics`). Raises ValueError naming
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
            q = inverse_kinematics(pose, near=q_prev, singular_tol=singular_tol)
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
                f"(limit {max_step} rad): the path leaves the branch {ik_branch(q_prev)} "
                f"(now {ik_branch(q)}) or is sampled too coarsely", cause=Cause.INFEASIBLE
            )
        path[i] = q
        q_prev = q
    return path


# --------------------------------------------------------------------------------------------
# The Robot contract.
# --------------------------------------------------------------------------------------------


class UR10e(Robot):
    """The UR10e under the :class:`~drake_traj.robots.base.Robot` contract (the functions of this
    module do the work, with the TCP offset ``tcp_offset`` as their ``tool``). The tool is the
    flange ``tool0`` unless made by :meth:`~drake_traj.robots.base.Robot.with_tcp`."""

    name: ClassVar[str] = "ur10e"
    model_file: ClassVar[str] = "ur10e.urdf"
    joint_names: ClassVar[tuple[str, ...]] = JOINT_NAMES
    joint_types: ClassVar[tuple[str, ...]] = ("revolute",) * NUM_JOINTS
    tool_frame: ClassVar[str] = FLANGE_FRAME
    rated_payload: float = 12.5  # [kg] (UR e-Series data sheet)
    data_source: str = "docs/ur10e.md (Universal Robots' DH and dynamics table, UR10e data sheet)"

    @property
    def lower_limits(self) -> np.ndarray:
        return -POSITION_LIMIT

    @property
    def upper_limits(self) -> np.ndarray:
        return POSITION_LIMIT.copy()

    @property
    def velocity_limits(self) -> np.ndarray:
        return VELOCITY_LIMIT.copy()

    @property
    def effort_limits(self) -> np.ndarray:
        return EFFORT_LIMIT.copy()

    @property
    def joint_move_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """The UR controller's joint-move defaults, 1.05 rad/s and 1.40 rad/s^2 on every joint."""
        return np.full(NUM_JOINTS, DEFAULT_JOINT_MOVE_VELOCITY), np.full(NUM_JOINTS, DEFAULT_JOINT_MOVE_ACCELERATION)

    @property
    def default_gains(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        return DEFAULT_KP, DEFAULT_KD

    @property
    def home_configuration(self) -> np.ndarray:
        """:data:`HOME`, the start of Pająk 2024's task."""
        return np.array(HOME)

    def tcp_pose(self, q) -> np.ndarray:
        """:func:`task_pose` for one q; the closed form of :func:`ur10e_kinematics` for many."""
        q = self.joint_positions(q)
        if q.ndim == 1:
            return task_pose(q, self.tcp_offset)
        return ur10e_kinematics(q, np.zeros_like(q), self.tcp_offset)[0]

    def tool_position(self, q) -> np.ndarray:
        q = self.joint_positions(q)
        return ur10e_kinematics(q, np.zeros_like(q), self.tcp_offset)[0][..., :3]

    def tool_motion(self, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:
        _, jacobian, bias, _, _ = ur10e_kinematics(q, qd, self.tcp_offset)
        return (np.einsum("...ij,...j->...i", jacobian[..., :3, :], qd),
                np.einsum("...ij,...j->...i", jacobian[..., :3, :], qdd) + bias[..., :3])

    def point_ik(self, points, reference) -> np.ndarray:
        """IK of TCP positions at the TCP orientation of ``reference``, on its IK branch, each
        joint within 2 pi of ``reference`` (:func:`inverse_kinematics`)."""
        reference = _as_joint_vector(reference, "reference")
        orientation = task_pose(reference, self.tcp_offset)[3:]
        branch = ik_branch(reference)
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        return np.array([inverse_kinematics(np.concatenate([point, orientation]), branch=branch, near=reference,
                                            tool=self.tcp_offset)
                         for point in points]).reshape(-1, NUM_JOINTS)

    def joint_rates(self, q, v, a) -> tuple[np.ndarray, np.ndarray]:
        """qd = J^-1 [v; 0], qdd = J^-1 ([a; 0] - dJ/dt qd) with the TCP's analytic Jacobian (one q)."""
        jacobian = analytic_jacobian(q, tool=self.tcp_offset)
        qd = np.linalg.solve(jacobian, np.concatenate([v, np.zeros(3)]))
        _, bias = analytic_jacobian_and_bias(q, qd, tool=self.tcp_offset)
        qdd = np.linalg.solve(jacobian, np.concatenate([a, np.zeros(3)]) - bias)
        return qd, qdd

    def task_kinematics(self) -> TaskKinematics:
        """The compiled k(q), analytic Jacobian and J̇q̇ (:func:`kinematics_into` through
        :func:`~drake_traj.robots.compiled_kinematics.task_kinematics_into`, ``model`` =
        :data:`MODEL`), angle wrapping, orientation error, pose errors and closed-form IK, of the
        TCP ``tcp_offset``."""
        flange = _flange_task_kinematics()
        if is_flange(self.tcp_offset):
            return flange
        return flange._replace(inverse_kinematics_all=functools.partial(inverse_kinematics_all, tool=self.tcp_offset),
                               tool=self.tcp_offset)


@functools.cache
def _flange_task_kinematics() -> TaskKinematics:
    from drake_traj.robots.compiled_kinematics import task_kinematics_into  # it imports this module

    return TaskKinematics(task_kinematics_into, wrapped, orientation_error, wrap_angle, pose_error,
                          inverse_kinematics_all, FLANGE, singularity_factors, MODEL)

UR10E = UR10e()
