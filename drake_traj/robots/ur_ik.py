"""The closed-form inverse kinematics of any UR e-Series arm: the joint solution of a flange pose on
each (shoulder, elbow, wrist) branch, from the arm's DH lengths (the closed form's data
:attr:`~drake_traj.robots.ur_data.URData.model`), with the pose checks and the messages of
:class:`~drake_traj.robots.ur_eseries.URArm`'s IK methods.

Frames follow ``docs/ur10e.md``: the base frame is standard-DH frame 0, the flange ``tool0`` DH
frame 6. A pose is a 4x4 transform X_BF (translation in m) or a task pose
[x, y, z, phi_X, phi_Y, phi_Z] (m, then Z-Y-X Euler angles in rad); joint angles are in rad.
"""

from __future__ import annotations

import math

import numpy as np

from drake_traj.compiled import compiled, sources_digest
from drake_traj.errors import SingularConfigurationError, UnreachablePoseError
from drake_traj.robots import task_space
from drake_traj.robots.task_space import is_flange, rotation_from_zyx_euler, wrap_angle, wrapped, zyx_euler_from_rotation
from drake_traj.robots.ur_data import NUM_JOINTS
from drake_traj.validation import invalid

__all__ = ["BEYOND_THE_ELBOW", "ELBOW_SINGULAR", "IK_BRANCHES", "IK_PATH_MAX_STEP", "IK_SINGULAR_TOLERANCE",
           "OFF_THE_SHOULDER", "SHOULDER_SINGULAR", "WRIST_SINGULAR", "branch_ik_into", "branch_ik_many",
           "branch_solutions", "describe_pose",
           "flange_goal", "raise_wrist_singular", "unique_rows"]


def describe_pose(pose: np.ndarray) -> str:
    """The 4x4 flange ``pose`` X_BF as the IK errors name it: position [m], Z-Y-X Euler angles [rad]."""
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


def flange_goal(pose, tool) -> np.ndarray:
    """The flange pose X_BF (4, 4) that puts the TCP ``tool`` (X_FT) at ``pose`` X_BT (a 4x4
    transform or a task pose [x, y, z, phi_X, phi_Y, phi_Z]): X_BF = X_BT X_FT⁻¹."""
    pose = _as_flange_pose(pose)
    if is_flange(tool):
        return pose
    inverse = np.eye(4)
    inverse[:3, :3] = tool[:3, :3].T
    inverse[:3, 3] = -tool[:3, :3].T @ tool[:3, 3]
    return pose @ inverse


# --------------------------------------------------------------------------------------------
# Analytic inverse kinematics of the flange (closed form from the standard-DH chain of
# drake_traj.robots.ur_eseries.URArm.dh_frames).
# --------------------------------------------------------------------------------------------
#
# Derivation (frames of URArm.dh_frames; z1 = (s1, -c1, 0), x1 = (c1, s1, 0) is the arm plane direction):
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


def raise_wrist_singular(pose: np.ndarray) -> None:
    """SingularConfigurationError: the flange ``pose`` (4x4 X_BF) is at a wrist singularity."""
    raise SingularConfigurationError(
        f"{describe_pose(pose)} is at a wrist singularity (sin q5 = 0: flange z axis parallel to "
        f"joint axes 2-4): q4 and q6 are not determined individually, the wrist branch is undefined"
    )


def unique_rows(solutions, atol: float = 1e-12) -> np.ndarray:
    """The joint ``solutions`` [rad] as rows (k, 6), each solution that coincides with an earlier
    one (every joint within ``atol`` modulo 2 pi) left out."""
    rows = []
    for q in solutions:
        if not any(np.max(np.abs(wrap_angle(q - other))) <= atol for other in rows):
            rows.append(q)
    return np.array(rows).reshape(-1, NUM_JOINTS)


def branch_solutions(model, title: str, pose: np.ndarray, tol: float):
    """All branch solutions of the 4x4 flange pose X_BF (base frame, m) of the e-Series arm
    ``title`` whose closed-form data is ``model`` = [UR_CLOSED_FORM, d1, a2, a3, d4, d5, d6] [m];
    ``tol`` is the singularity tolerance (:data:`IK_SINGULAR_TOLERANCE`). Each branch is
    :func:`branch_ik_into`'s.

    Returns (solutions, failures, flags): solutions maps branch -> q (wrapped) [rad]; failures maps branch
    -> reason for branches without a real solution; flags = dict(shoulder=bool, wrist=set of shoulder
    signs, elbow=set of branches) marking singular factors. Raises UnreachablePoseError (its ``pose`` the flange pose) when the
    pose is out of reach (no branch has a solution and none is wrist-singular).
    """
    model = np.ascontiguousarray(model, dtype=float)
    rotation, position = np.ascontiguousarray(pose[:3, :3]), np.ascontiguousarray(pose[:3, 3])
    d1, a2, a3, d4, d5, d6 = (float(v) for v in model[1:])
    o5 = position - d6 * rotation[:, 2]
    r = math.hypot(o5[0], o5[1])
    solutions, failures = {}, {}
    unreached = []  # [m] the wrist-1 joint's distances from the shoulder joint that no elbow reaches
    flags = dict(shoulder=False, wrist=set(), elbow=set())
    q = np.empty(NUM_JOINTS)
    for branch in IK_BRANCHES:
        status, distance = branch_ik_into(model, rotation, position, *map(float, branch), tol, q)
        if status & OFF_THE_SHOULDER:
            raise UnreachablePoseError(
                f"{describe_pose(pose)} is out of reach: the wrist centre (flange - d6 z) is "
                f"{r:.6g} m from the joint-1 axis, closer than the {title}'s shoulder offset d4 = {d4} m", pose=pose)
        flags["shoulder"] = bool(status & SHOULDER_SINGULAR)
        if status & WRIST_SINGULAR:
            flags["wrist"].add(branch[0])
        elif status & BEYOND_THE_ELBOW:
            unreached.append(distance)
            failures[branch] = _beyond_the_elbow(f"{distance:.6g} m", a2, a3, title)
        else:
            if status & ELBOW_SINGULAR:
                flags["elbow"].add(branch)
            solutions[branch] = q.copy()
    if not solutions and not flags["wrist"]:
        centre = math.hypot(r, o5[2] - d1)
        max_centre = math.hypot(abs(a2) + abs(a3) + d5, d4)
        near, far = min(unreached), max(unreached)  # one per shoulder and wrist branch
        distance = f"{near:.6g} m" if f"{near:.6g}" == f"{far:.6g}" else f"{near:.6g} to {far:.6g} m (by IK branch)"
        raise UnreachablePoseError(
            f"{describe_pose(pose)} is out of reach: the wrist centre (flange - d6 z) is {centre:.6g} m "
            f"from the shoulder point (0, 0, d1) (the {title} reaches at most {max_centre:.6g} m); "
            f"{_beyond_the_elbow(distance, a2, a3, title)}", pose=pose)
    return solutions, failures, flags


def _beyond_the_elbow(distance: str, a2: float, a3: float, title: str) -> str:
    """Why no elbow angle exists: the wrist-1 joint ``distance`` (text with its unit) from the
    shoulder joint, outside what the upper arm ``a2`` and forearm ``a3`` [m] span."""
    return (f"the wrist-1 joint would be {distance} from the shoulder joint, outside the reach "
            f"[{abs(abs(a2) - abs(a3)):.6g}, {abs(a2) + abs(a3):.6g}] m of the {title}'s upper arm and forearm")


# branch_ik_into's status bits: no solution (off the shoulder, wrist singular, beyond the elbow), or a
# solution at a singular factor (shoulder, elbow)
OFF_THE_SHOULDER, SHOULDER_SINGULAR, WRIST_SINGULAR, BEYOND_THE_ELBOW, ELBOW_SINGULAR = 1, 2, 4, 8, 16


def _branch_ik_with(dependencies):
    @compiled
    def branch_ik_into(model, rotation, position, shoulder, elbow, wrist, tol, out):
        """The closed form (the derivation above) on one branch: the solution of the flange pose
        of rotation ``rotation`` (3, 3) at ``position`` (3,) [m] on branch (``shoulder``,
        ``elbow``, ``wrist``) (each +1.0 or -1.0) into ``out`` (6,) [rad, wrapped]. Returns
        (status, distance): status the bits :data:`OFF_THE_SHOULDER`, :data:`WRIST_SINGULAR`,
        :data:`BEYOND_THE_ELBOW` (``out`` not written; ``distance`` [m] the wrist-1 joint's from
        the shoulder joint, beyond the elbow's reach) and :data:`SHOULDER_SINGULAR`,
        :data:`ELBOW_SINGULAR` (a solution, at that singular factor)."""
        dependencies  # noqa: B018 (numba's cache key: drake_traj.compiled.sources_digest)
        d1, a2, a3, d4, d5, d6 = model[1], model[2], model[3], model[4], model[5], model[6]
        z6 = rotation[:, 2]
        o5 = position - d6 * z6
        r = math.hypot(o5[0], o5[1])
        h_sq = r * r - d4 * d4
        reach = abs(a2) + abs(a3)
        if h_sq < -(tol * reach) ** 2:
            return OFF_THE_SHOULDER, 0.0
        h_abs = math.sqrt(max(h_sq, 0.0))
        status = SHOULDER_SINGULAR if h_abs < tol * reach else 0
        q1 = math.atan2(o5[1], o5[0]) + math.atan2(d4, shoulder * h_abs)
        c1, s1 = math.cos(q1), math.sin(q1)
        z1 = np.array([s1, -c1, 0.0])
        c5 = z6[0] * z1[0] + z6[1] * z1[1]  # z6 . z1
        s5c6 = rotation[0, 0] * z1[0] + rotation[1, 0] * z1[1]  # x6 . z1 = s5 c6
        ms5s6 = rotation[0, 1] * z1[0] + rotation[1, 1] * z1[1]  # y6 . z1 = -s5 s6
        s5_abs = math.hypot(s5c6, ms5s6)
        if s5_abs < tol:
            return status | WRIST_SINGULAR, 0.0
        s5 = wrist * s5_abs
        x4 = (c5 * z1 - z6) / s5
        q234 = math.atan2(x4[2], c1 * x4[0] + s1 * x4[1])
        c234, s234 = math.cos(q234), math.sin(q234)
        o4 = o5 - d5 * np.array([c1 * s234, s1 * s234, -c234])
        u = c1 * o4[0] + s1 * o4[1]
        v = o4[2] - d1
        distance = math.hypot(u, v)
        c3 = (distance * distance - a2 * a2 - a3 * a3) / (2.0 * a2 * a3)
        if abs(c3) > 1.0 + tol:
            return status | BEYOND_THE_ELBOW, distance
        c3 = min(1.0, max(-1.0, c3))
        s3_abs = math.sqrt(1.0 - c3 * c3)
        if s3_abs < tol:
            status |= ELBOW_SINGULAR
        q3 = math.atan2(elbow * s3_abs, c3)
        q2 = math.atan2(v, u) - math.atan2(a3 * elbow * s3_abs, a2 + a3 * c3)
        out[:] = wrapped(np.array([q1, q2, q3, q234 - q2 - q3, math.atan2(s5, c5), math.atan2(-ms5s6 / s5, s5c6 / s5)]))
        return status, distance

    @compiled
    def branch_ik_many(model, rotation, positions, shoulder, elbow, wrist, tol, out):
        """:func:`branch_ik_into` at each row of ``positions`` (N, 3) [m] into the rows of
        ``out`` (N, 6), for a path of poses of one rotation; returns the statuses (N,)."""
        status = np.zeros(positions.shape[0], dtype=np.int64)
        for k in range(positions.shape[0]):
            status[k] = branch_ik_into(model, rotation, positions[k], shoulder, elbow, wrist, tol, out[k])[0]
        return status

    return branch_ik_into, branch_ik_many


branch_ik_into, branch_ik_many = _branch_ik_with(sources_digest(task_space.__file__))
