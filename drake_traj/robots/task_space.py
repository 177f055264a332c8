"""Task-space poses p = [x, y, z, φ_X, φ_Y, φ_Z] (metres, Z-Y-X Euler angles in radians, R =
Rz(φ_Z) Ry(φ_Y) Rx(φ_X), as UR's software and Pająk 2024 use them): angle wrapping, Euler angles
of a rotation and back, pose errors and the Euler-rate matrix. Plain math for any robot; the
compiled functions are the forms that compiled kernels call.
"""

from __future__ import annotations

import math

import numpy as np

from drake_traj.compiled import compiled

__all__ = ["euler_rate_matrix", "is_flange", "orientation_error", "pose_error", "rotation_from_zyx_euler", "task_pose_error",
           "tcp_rows_into", "velocity_product_terms", "wrap_angle", "wrapped", "zyx_euler_from_rotation"]


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


@compiled
def is_flange(tool) -> bool:
    """Whether the 4x4 ``tool`` offset X_FT is exactly the identity (the TCP is the flange)."""
    for i in range(4):
        for j in range(4):
            if tool[i, j] != (1.0 if i == j else 0.0):
                return False
    return True


@compiled
def velocity_product_terms(axes, links, qd, omega, alpha, acceleration):
    """The flange's angular velocity ω into ``omega`` (3) [rad/s] and its velocity-product
    accelerations (those at q̈ = 0) J̇_ω q̇ into ``alpha`` (3) [rad/s²] and J̇_v q̇ of its origin
    into ``acceleration`` (3) [m/s²], for a chain of six revolute joints with axes z_j (``axes``
    (6, 3), unit, base frame) and link vectors r_j = o_{j+1} - o_j (``links`` (6, 3) [m]; o_6 the
    flange) at joint rates ``qd`` (6) [rad/s]. The recursion: α_{j+1} = α_j + ω_j x z_j q̇_j,
    ω_{j+1} = ω_j + z_j q̇_j, a_{j+1} = a_j + α_{j+1} x r_j + ω_{j+1} x (ω_{j+1} x r_j)."""
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
    omega[0], omega[1], omega[2] = w0, w1, w2
    alpha[0], alpha[1], alpha[2] = al0, al1, al2
    acceleration[0], acceleration[1], acceleration[2] = l0, l1, l2


@compiled
def tcp_rows_into(rotation, axes, flange, omega, alpha, acceleration, tool, pose, jac, bias):
    """The task kinematics of a 6-joint arm's TCP from its flange's: k(q) into ``pose`` (6), the
    analytic J into ``jac`` (6, 6), J̇q̇ into ``bias`` (6); returns cos φ_Y (>= 0).

    Given (base frame, q̈ = 0): ``rotation`` R_F (3, 3) of the flange (overwritten with R_T),
    ``axes`` (6, 3) the joint axes z_j, ``flange`` (3,) the flange origin o_6 [m], ``omega`` (3,)
    ω [rad/s], ``alpha`` (3,) J̇_ω q̇ [rad/s²], ``acceleration`` (3,) J̇_v q̇ of o_6 [m/s²], and
    ``jac``'s rows 0-2 holding the flange's J_v (columns z_j x (o_6 - o_j)). ``tool`` (4, 4) is X_FT
    with translation t [m] and rotation R_t (skipped for the identity, so the flange's numbers are
    the same bit for bit): s = R_F t, p_T = o_6 + s, R_T = R_F R_t; the TCP's velocity v + ω x s,
    so J_v gains the columns z_j x s, and its bias acceleration J̇_ω q̇ x s + ω x (ω x s). Then
    J = diag(I, B⁻¹) J_g and the Euler part of the bias B⁻¹ (α - Ḃ φ̇) (Pająk 2024, with B's
    columns in k(q)'s order), with the TCP's Euler angles (ω and α are the same for every point
    of the last link). At gimbal lock (cos φ_Y = 0) B⁻¹ uses 1e300 for 1/cos φ_Y: callers check
    the returned cos φ_Y.
    """
    p0, p1, p2 = flange[0], flange[1], flange[2]
    w0, w1, w2 = omega[0], omega[1], omega[2]
    al0, al1, al2 = alpha[0], alpha[1], alpha[2]
    l0, l1, l2 = acceleration[0], acceleration[1], acceleration[2]
    if not is_flange(tool):
        s0 = rotation[0, 0] * tool[0, 3] + rotation[0, 1] * tool[1, 3] + rotation[0, 2] * tool[2, 3]  # s = R_F t
        s1 = rotation[1, 0] * tool[0, 3] + rotation[1, 1] * tool[1, 3] + rotation[1, 2] * tool[2, 3]
        s2 = rotation[2, 0] * tool[0, 3] + rotation[2, 1] * tool[1, 3] + rotation[2, 2] * tool[2, 3]
        p0 += s0
        p1 += s1
        p2 += s2
        for j in range(6):  # J_v column j + z_j x s
            jac[0, j] += axes[j, 1] * s2 - axes[j, 2] * s1
            jac[1, j] += axes[j, 2] * s0 - axes[j, 0] * s2
            jac[2, j] += axes[j, 0] * s1 - axes[j, 1] * s0
        u0, u1, u2 = w1 * s2 - w2 * s1, w2 * s0 - w0 * s2, w0 * s1 - w1 * s0  # ω x s
        l0 += al1 * s2 - al2 * s1 + w1 * u2 - w2 * u1  # + J̇_ω q̇ x s + ω x (ω x s)
        l1 += al2 * s0 - al0 * s2 + w2 * u0 - w0 * u2
        l2 += al0 * s1 - al1 * s0 + w0 * u1 - w1 * u0
        flange_rotation = rotation.copy()
        for i in range(3):  # R_T = R_F R_t
            for k in range(3):
                rotation[i, k] = (flange_rotation[i, 0] * tool[0, k] + flange_rotation[i, 1] * tool[1, k]
                                  + flange_rotation[i, 2] * tool[2, k])
    r11, r21, r31, r32, r33 = rotation[0, 0], rotation[1, 0], rotation[2, 0], rotation[2, 1], rotation[2, 2]
    # Z-Y-X Euler angles (k(q) rows 4-6) from R_T's first column, r32 and r33
    cy = math.hypot(r32, r33)  # cos φ_Y >= 0
    pose[0], pose[1], pose[2] = p0, p1, p2 + 0.0
    pose[3], pose[4], pose[5] = math.atan2(r32, r33), math.atan2(-r31, cy), math.atan2(r21, r11)
    sy, cz, sz = -r31, math.cos(pose[5]), math.sin(pose[5])
    icy = 1.0 / cy if cy > 0.0 else 1e300
    # B(φ)⁻¹ v for B of euler_rate_matrix: fx = (cz v0 + sz v1)/cy, fy = -sz v0 + cz v1, fz = v2 + sy fx
    for j in range(6):
        fx = (cz * axes[j, 0] + sz * axes[j, 1]) * icy
        jac[3, j] = fx
        jac[4, j] = -sz * axes[j, 0] + cz * axes[j, 1]
        jac[5, j] = axes[j, 2] + sy * fx
    fx = (cz * w0 + sz * w1) * icy  # Euler rates φ̇
    fy = -sz * w0 + cz * w1
    fz = w2 + sy * fx
    v0 = al0 - (-sy * cz * fx * fy + fz * (-cy * sz * fx - cz * fy))  # α - Ḃ φ̇
    v1 = al1 - (-sy * sz * fx * fy + fz * (cy * cz * fx - sz * fy))
    v2 = al2 + cy * fx * fy
    gx = (cz * v0 + sz * v1) * icy
    bias[0], bias[1], bias[2] = l0, l1, l2
    bias[3], bias[4], bias[5] = gx, -sz * v0 + cz * v1, v2 + sy * gx
    return cy
