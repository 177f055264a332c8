"""Task-space poses p = [x, y, z, φ_X, φ_Y, φ_Z] (metres, Z-Y-X Euler angles in radians, R =
Rz(φ_Z) Ry(φ_Y) Rx(φ_X), as UR's software and Pająk 2024 use them): angle wrapping, Euler angles
of a rotation and back, pose errors and the Euler-rate matrix. Plain math for any robot; the
compiled functions are the forms that compiled kernels call.
"""

from __future__ import annotations

import math

import numpy as np

from drake_traj.compiled import compiled

__all__ = ["euler_rate_matrix", "orientation_error", "pose_error", "rotation_from_zyx_euler", "task_pose_error",
           "wrap_angle", "wrapped", "zyx_euler_from_rotation"]


@compiled
def wrapped(angle):
    """:func:`wrap_angle` compiled, for a float or an array (the form compiled kernels call)."""
    return np.pi - np.mod(np.pi - angle, 2.0 * np.pi)


def wrap_angle(angle):
    """Wrap angles [rad] to (-pi, pi] (Corrected (docs/papers.md): the orientation error of Pająk 2024 must be wrapped)."""
    return wrapped(np.asarray(angle, dtype=float))


def zyx_euler_from_rotation(rotation: np.ndarray) -> np.ndarray:
    """Z-Y-X Euler angles (phi_X, phi_Y, phi_Z) [rad] of R = Rz(phi_Z) Ry(phi_Y) Rx(phi_X).

    Pająk 2024, k(q) rows 4-6: phi_X = atan2(r32, r33), phi_Y = atan2(-r31, sqrt(r32^2 + r33^2)),
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


def task_pose_error(pose, goal) -> np.ndarray:
    """e = pose - goal (eq. 6) with the orientation part wrapped to (-pi, pi] (docs/papers.md)."""
    error = np.asarray(pose, dtype=float) - np.asarray(goal, dtype=float)
    error[3:] = wrap_angle(error[3:])
    return error


@compiled
def orientation_error(phi, goal) -> float:
    """Angle [rad] of R_goalᵀ R between the Z-Y-X Euler orientations ``phi`` and ``goal`` (3 each):
    the rotation that is left, not a difference of Euler angles. Compiled, for kernels."""
    r = np.empty((2, 3, 3))
    for k, angles in enumerate((phi, goal)):
        cx, sx = math.cos(angles[0]), math.sin(angles[0])
        cy, sy = math.cos(angles[1]), math.sin(angles[1])
        cz, sz = math.cos(angles[2]), math.sin(angles[2])
        r[k, 0, 0], r[k, 0, 1], r[k, 0, 2] = cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx
        r[k, 1, 0], r[k, 1, 1], r[k, 1, 2] = sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx
        r[k, 2, 0], r[k, 2, 1], r[k, 2, 2] = -sy, cy * sx, cy * cx
    m = np.empty((3, 3))  # R_goalᵀ R
    for i in range(3):
        for j in range(3):
            m[i, j] = r[1, 0, i] * r[0, 0, j] + r[1, 1, i] * r[0, 1, j] + r[1, 2, i] * r[0, 2, j]
    # sin and cos of the angle from the skew part and the trace: accurate at any angle
    sine = 0.5 * math.sqrt((m[2, 1] - m[1, 2]) ** 2 + (m[0, 2] - m[2, 0]) ** 2 + (m[1, 0] - m[0, 1]) ** 2)
    return math.atan2(sine, 0.5 * (m[0, 0] + m[1, 1] + m[2, 2] - 1.0))


@compiled
def _pose_errors(pose, goal, position, orientation):
    for k in range(pose.shape[0]):
        g = goal[k % goal.shape[0]]
        position[k] = math.sqrt((pose[k, 0] - g[0]) ** 2 + (pose[k, 1] - g[1]) ** 2 + (pose[k, 2] - g[2]) ** 2)
        orientation[k] = orientation_error(pose[k, 3:], g[3:])


def pose_error(pose, goal):
    """(position error [m], orientation error [rad]) of task poses [x, y, z, φ_X, φ_Y, φ_Z] against
    ``goal``: the distance of the positions and the angle of R_goalᵀ R (:func:`orientation_error`).

    ``pose`` has shape (..., 6) and ``goal`` (6,) or the same shape; the errors have the leading
    shape (floats for one pose).
    """
    pose = np.asarray(pose, dtype=float)
    goal = np.asarray(goal, dtype=float)
    if pose.shape[-1:] != (6,) or goal.shape not in ((6,), pose.shape):
        raise ValueError(f"pose must have shape (..., 6) and goal (6,) or the same shape, got {pose.shape} "
                         f"and {goal.shape}")
    rows = np.ascontiguousarray(pose.reshape(-1, 6))
    position, orientation = np.empty(rows.shape[0]), np.empty(rows.shape[0])
    _pose_errors(rows, np.ascontiguousarray(goal.reshape(-1, 6)), position, orientation)
    if pose.ndim == 1:
        return float(position[0]), float(orientation[0])
    return position.reshape(pose.shape[:-1]), orientation.reshape(pose.shape[:-1])


def euler_rate_matrix(phi) -> np.ndarray:
    """B(phi) with omega = B(phi) d(phi)/dt, columns ordered (phi_X, phi_Y, phi_Z) like k(q).

    Pająk 2024 prints B with its columns in Z, Y, X order; Corrected (docs/papers.md): they must follow k(q)'s order.
    """
    _, phi_y, phi_z = phi
    cy, sy, cz, sz = np.cos(phi_y), np.sin(phi_y), np.cos(phi_z), np.sin(phi_z)
    return np.array([[cy * cz, -sz, 0.0], [cy * sz, cz, 0.0], [-sy, 0.0, 1.0]])
