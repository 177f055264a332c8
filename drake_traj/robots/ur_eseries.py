"""The UR e-Series family: each arm's published data and the one closed form that serves them all.

Every e-Series arm (UR3e, UR5e, UR10e, UR16e) and its successors (UR20, UR30) have the same
kinematic structure: the standard-DH chain T_{i-1,i} = Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i) with alpha = (pi/2, 0, 0, pi/2,
-pi/2, 0) and only d1, a2, a3, d4, d5, d6 differing. The closed-form k(q), analytic Jacobian, J̇q̇
(:func:`~drake_traj.robots.ur_closed_form.kinematics_into`, compiled) and inverse kinematics below take those lengths as data
(:class:`URData`); :class:`URArm` is one arm under the :class:`~drake_traj.robots.base.Robot`
contract. The data and their sources: ``docs/ur_family.md`` (``docs/ur10e.md`` for the UR10e).

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
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from drake_traj.errors import Cause, DrakeTrajError, SingularConfigurationError, joint_label
from drake_traj.robots.base import FLANGE, Robot, TaskKinematics
from drake_traj.robots.compiled_kinematics import task_kinematics, task_kinematics_into
from drake_traj.robots.task_space import (is_flange, orientation_error, pose_error, rotation_from_zyx_euler,
                                          wrap_angle, wrapped, zyx_euler_from_rotation)
from drake_traj.robots.ur_closed_form import UR_CLOSED_FORM, singularity_measure_many
from drake_traj.validation import invalid, real_array

__all__ = ["UR3E", "UR5E", "UR10E", "UR16E", "UR20", "UR30", "UR_ARMS", "URArm", "URData"]

NUM_JOINTS = 6
DH_ALPHA = np.array([np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0])  # [rad], every e-Series arm
JOINT_NAMES = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
# UR controller defaults for joint moves, used by Pająk 2024 for every joint.
DEFAULT_JOINT_MOVE_VELOCITY = 1.05  # [rad/s] (60 deg/s)
DEFAULT_JOINT_MOVE_ACCELERATION = 1.40  # [rad/s^2] (80 deg/s^2)
# The UR10e's PD gains [N m/rad], [N m s/rad] (docs/drake-api.md, "The controller"); every other arm's are these
# scaled joint by joint by its torque limit over the UR10e's (:attr:`URArm.default_gains`).
UR10E_KP = (4000.0, 4000.0, 2000.0, 500.0, 500.0, 300.0)
UR10E_KD = (200.0, 200.0, 100.0, 20.0, 20.0, 10.0)
UR10E_EFFORT_LIMIT = (330.0, 330.0, 150.0, 56.0, 56.0, 56.0)  # [N m]
# The start configuration of Pająk 2024's task, q(0) [rad] (on the UR10e the flange at
# p0 = [-0.174, -0.524, 0.273, pi, 0, 3pi/4]): every arm's home configuration.
HOME = (-np.pi / 2, -np.pi / 2, -3 * np.pi / 4, -np.pi / 4, np.pi / 2, np.pi / 4)
FLANGE_FRAME = "tool0"
BASE_FRAME = "base"
_FULL_TURN = 2 * np.pi


@dataclass(frozen=True)
class URData:
    """One e-Series arm's published data (``docs/ur_family.md`` gives every number's source).

    Lengths in m, masses in kg, angles in rad, speeds in rad/s, torques in N m. Link i (1..6) is
    the body turned by joint i; its centre of mass and inertia tensor (about the centre of mass)
    are in standard-DH frame i, the frame at the link's distal joint (UR's convention).
    ``tube_offsets`` are the planes of the upper-arm and forearm tubes along the joint-2/3 axes
    (UR's ROS 2 description), used only for collision shapes; ``size`` scales the UR10e's
    housing and tube radii to this arm's (:mod:`drake_traj.robots.urdf_writer`).
    """

    name: str  # scenario name, e.g. "ur5e"
    title: str  # "UR5e"
    d: tuple[float, ...]  # DH d_1..d_6
    a: tuple[float, ...]  # DH a_1..a_6
    link_masses: tuple[float, ...]
    centers_of_mass: tuple[tuple[float, float, float], ...]
    inertias: tuple[tuple[float, ...], ...]  # (ixx, ixy, ixz, iyy, iyz, izz) per link
    velocity_limit: tuple[float, ...]
    effort_limit: tuple[float, ...]
    rated_payload: float
    reach: float  # published reach [m]
    tube_offsets: tuple[float, float]
    size: float
    base_mass: float = 4.0  # approximate (the ROS description flags it); the base is welded
    position_limit: tuple[float, ...] = (_FULL_TURN,) * NUM_JOINTS  # symmetric
    data_source: str = "docs/ur_family.md (Universal Robots' DH table and data sheets, UR's ROS 2 description)"

    @property
    def model(self) -> np.ndarray:
        """The closed form's data [UR_CLOSED_FORM, d1, a2, a3, d4, d5, d6] (read-only)."""
        d, a = self.d, self.a
        model = np.array([UR_CLOSED_FORM, d[0], a[1], a[2], d[3], d[4], d[5]])
        model.flags.writeable = False
        return model


def _degrees(*values: float) -> tuple[float, ...]:
    return tuple(math.radians(v) for v in values)


def _cylinder_tensors(principal):
    """(ixx, ixy, ixz, iyy, iyz, izz) of diagonal tensors given by their principal moments."""
    return tuple((ixx, 0.0, 0.0, iyy, 0.0, izz) for ixx, iyy, izz in principal)


UR3E_DATA = URData(
    name="ur3e", title="UR3e",
    d=(0.15185, 0.0, 0.0, 0.13105, 0.08535, 0.0921), a=(0.0, -0.24355, -0.2132, 0.0, 0.0, 0.0),
    link_masses=(1.98, 3.4445, 1.437, 0.871, 0.805, 0.261),
    centers_of_mass=((0.0, -0.02, 0.0), (0.13, 0.0, 0.1157), (0.05, 0.0, 0.0238), (0.0, 0.0, 0.01), (0.0, 0.0, 0.01),
                     (0.0, 0.0, -0.02)),
    # the ROS 2 description's cylinder approximation, turned into the DH frames (UR publishes none)
    inertias=_cylinder_tensors(((0.008093166666666665, 0.005625, 0.008093166666666665),
                                (0.00961875, 0.021728491912499998, 0.021728491912499998),
                                (0.00354375, 0.006544570199999999, 0.006544570199999999),
                                (0.0020849999999999996, 0.00225, 0.0020849999999999996),
                                (0.0020849999999999996, 0.00225, 0.0020849999999999996),
                                (0.00013626666666666665, 0.00013626666666666665, 0.0001792))),
    velocity_limit=_degrees(180, 180, 180, 360, 360, 360), effort_limit=(54.0, 54.0, 28.0, 9.0, 9.0, 9.0),
    rated_payload=3.0, reach=0.5, tube_offsets=(0.120, 0.027), size=0.08535 / 0.11985, base_mass=2.0)

UR5E_DATA = URData(
    name="ur5e", title="UR5e",
    d=(0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996), a=(0.0, -0.425, -0.3922, 0.0, 0.0, 0.0),
    link_masses=(3.761, 8.058, 2.846, 1.37, 1.3, 0.365),
    centers_of_mass=((0.0, -0.02561, 0.00193), (0.2125, 0.0, 0.11336), (0.15, 0.0, 0.0265), (0.0, -0.0018, 0.01634),
                     (0.0, 0.0018, 0.01634), (0.0, 0.0, -0.001159)),
    # the ROS 2 description's cylinder approximation, turned into the DH frames (UR publishes none)
    inertias=_cylinder_tensors(((0.010267499999999999, 0.00666, 0.010267499999999999),
                                (0.0151074, 0.13388583541666665, 0.13388583541666665),
                                (0.004095, 0.03120936758333333, 0.03120936758333333),
                                (0.0025599, 0.0021942, 0.0025599), (0.0025599, 0.0021942, 0.0025599),
                                (9.890414008333333e-05, 9.890414008333333e-05, 0.0001321171875))),
    velocity_limit=_degrees(180, 180, 180, 180, 180, 180), effort_limit=(150.0, 150.0, 150.0, 28.0, 28.0, 28.0),
    rated_payload=5.0, reach=0.85, tube_offsets=(0.138, 0.007), size=0.0997 / 0.11985)

UR10E_DATA = URData(
    name="ur10e", title="UR10e",
    d=(0.1807, 0.0, 0.0, 0.17415, 0.11985, 0.11655), a=(0.0, -0.6127, -0.57155, 0.0, 0.0, 0.0),
    link_masses=(7.369, 13.051, 3.989, 2.1, 1.98, 0.615),
    centers_of_mass=((0.021, 0.0, 0.027), (0.38, 0.0, 0.158), (0.24, 0.0, 0.068), (0.0, 0.007, 0.018),
                     (0.0, 0.007, 0.018), (0.0, 0.0, -0.026)),
    inertias=((0.03408, 0.00002, -0.00425, 0.03529, 0.00008, 0.02156),
              (0.02814, 0.00005, -0.01561, 0.77068, 0.00002, 0.76943),
              (0.01014, 0.00008, 0.00916, 0.30928, 0.0, 0.30646),
              (0.00296, -0.00001, 0.0, 0.00222, -0.00024, 0.00258),
              (0.00296, -0.00001, 0.0, 0.00222, -0.00024, 0.00258),
              (0.0004, 0.0, 0.0, 0.00041, 0.0, 0.00034)),
    # docs/ur10e.md's rounded speeds and its 56 N m wrists (the ROS description: 54), kept as shipped
    velocity_limit=(2.094, 2.094, 3.1416, 3.1416, 3.1416, 3.1416), effort_limit=UR10E_EFFORT_LIMIT,
    rated_payload=12.5, reach=1.3, tube_offsets=(0.176, 0.039), size=1.0,
    data_source="docs/ur10e.md (Universal Robots' DH and dynamics table, UR10e data sheet)")

UR16E_DATA = URData(
    name="ur16e", title="UR16e",
    d=(0.1807, 0.0, 0.0, 0.17415, 0.11985, 0.11655), a=(0.0, -0.4784, -0.36, 0.0, 0.0, 0.0),
    link_masses=(7.369, 10.45, 4.321, 2.18, 2.033, 0.907),
    centers_of_mass=((0.0, -0.016, 0.03), (0.302, 0.0, 0.16), (0.194, 0.0, 0.065), (0.0, -0.009, 0.011),
                     (0.0, 0.018, 0.012), (0.0, 0.0, -0.044)),
    inertias=((0.03351, 0.00002, -0.00001, 0.03374, 0.00374, 0.021),
              (0.02796, -0.0001, -0.0072, 0.47558, 0.00003, 0.47635),
              (0.01091, 0.00006, 0.01012, 0.1206, 0.00001, 0.11714),
              (0.00609, -0.00001, 0.0, 0.00245, 0.00083, 0.00579),
              (0.00389, -0.00001, 0.0, 0.00219, -0.00045, 0.00363),
              (0.00117, 0.0, 0.0, 0.00118, 0.0, 0.00084)),
    velocity_limit=_degrees(120, 120, 180, 180, 180, 180), effort_limit=(330.0, 330.0, 150.0, 54.0, 54.0, 54.0),
    rated_payload=16.0, reach=0.9, tube_offsets=(0.176, 0.040), size=1.0)

UR20_DATA = URData(
    name="ur20", title="UR20",
    d=(0.2363, 0.0, 0.0, 0.201, 0.1593, 0.1543), a=(0.0, -0.862, -0.7287, 0.0, 0.0, 0.0),
    # link 6: UR's DH article as updated in 2025 (0.846 kg, [0, -0.0003, -0.0318]; the ROS 2 description 2.4.5
    # still has 0.926 kg, [0, 0, -0.0293])
    link_masses=(16.343, 29.632, 7.879, 3.054, 3.126, 0.846),
    centers_of_mass=((0.0, -0.061, 0.0062), (0.5226, 0.0, 0.2098), (0.3234, 0.0, 0.0604), (0.0, -0.0026, 0.0393),
                     (0.0, 0.0024, 0.0379), (0.0, -0.0003, -0.0318)),
    inertias=((0.08866, -0.00011, -0.00011, 0.07632, 0.0072, 0.08418),
              (0.1467, 0.00019, -0.05163, 4.6659, 0.00004, 4.6348),
              (0.02612, -0.00005, -0.02898, 0.75763, -0.00001, 0.75327),
              (0.00555, -0.00001, -0.00002, 0.00537, 0.00036, 0.00402),
              (0.00586, -0.00001, -0.00002, 0.00578, -0.00037, 0.00427),
              (0.00092, 0.0, 0.0, 0.00091, 0.0, 0.00117)),
    velocity_limit=_degrees(120, 120, 150, 210, 210, 210), effort_limit=(738.0, 738.0, 433.0, 107.0, 107.0, 107.0),
    rated_payload=20.0, reach=1.75, tube_offsets=(0.260, 0.043), size=0.1593 / 0.11985)


def _shortened_tube(tensor, mass_ratio: float, length_ratio: float) -> tuple[float, ...]:
    """A tube link's tensor (ixx, ixy, ixz, iyy, iyz, izz) in its DH frame (x along the tube, z
    the joint axis) carried over to a link of the same cross-section, ``mass_ratio`` times the
    mass and ``length_ratio`` times the length: the moment about the tube (ixx) and iyz scale with
    the mass, ixy and ixz with mass x length, the two moments across it (iyy, izz) with mass x
    length²; rounded to 5 significant digits like UR's tables."""
    ixx, ixy, ixz, iyy, iyz, izz = tensor
    m, l = mass_ratio, length_ratio
    return tuple(float(f"{v:.5g}") for v in (ixx * m, ixy * m * l, ixz * m * l, iyy * m * l * l, iyz * m, izz * m * l * l))


# The UR30 is the UR20's base, shoulder and wrist (d1, d4, d5, d6, and the masses of links 1, 4, 5
# and 6 are the UR20's) with a shorter upper arm and forearm. UR publishes no UR30 tensors we could
# read (the ROS 2 description's are the UR16e's digit for digit, a placeholder): links 1, 4, 5, 6
# take the UR20's measured tensors, links 2 and 3 the UR20's scaled to the UR30's mass and length
# (:func:`_shortened_tube`). Estimates, not UR's: docs/ur_family.md.
UR30_DATA = URData(
    name="ur30", title="UR30",
    d=(0.2363, 0.0, 0.0, 0.201, 0.1593, 0.1543), a=(0.0, -0.637, -0.5037, 0.0, 0.0, 0.0),
    link_masses=(16.343, 28.542, 7.156, 3.054, 3.126, 0.926),
    centers_of_mass=((-0.0001, -0.06, 0.0069), (0.3894, 0.0, 0.2103), (0.2257, 0.0, 0.0629), (0.0, -0.0048, 0.0353),
                     (0.0, 0.0046, 0.0341), (0.0, 0.0, -0.0293)),
    inertias=(UR20_DATA.inertias[0],
              _shortened_tube(UR20_DATA.inertias[1], 28.542 / 29.632, 0.637 / 0.862),
              _shortened_tube(UR20_DATA.inertias[2], 7.156 / 7.879, 0.5037 / 0.7287),
              *UR20_DATA.inertias[3:]),
    velocity_limit=_degrees(120, 120, 150, 210, 210, 210), effort_limit=(738.0, 738.0, 433.0, 107.0, 107.0, 107.0),
    rated_payload=30.0, reach=1.3, tube_offsets=(0.260, 0.043), size=0.1593 / 0.11985)




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


# --------------------------------------------------------------------------------------------
# One e-Series arm under the Robot contract.
# --------------------------------------------------------------------------------------------


class URArm(Robot):
    """An e-Series arm (:class:`URData`) under the :class:`~drake_traj.robots.base.Robot`
    contract, with its closed-form kinematics as methods. The tool is the flange ``tool0`` unless
    made by :meth:`~drake_traj.robots.base.Robot.with_tcp` (then ``tcp_offset`` is the ``tool``
    of the Robot methods; the kinematics methods take ``tool`` explicitly)."""

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
        """The UR10e's gains (:data:`UR10E_KP`, :data:`UR10E_KD`) scaled joint by joint by this
        arm's torque limit over the UR10e's (kp to 1 N m/rad, kd to 0.1 N m s/rad): a joint then
        saturates at the same position error as the UR10e's."""
        ratio = [limit / reference for limit, reference in zip(self.data.effort_limit, UR10E_EFFORT_LIMIT)]
        return (tuple(float(round(kp * r)) for kp, r in zip(UR10E_KP, ratio)),
                tuple(round(kd * r, 1) for kd, r in zip(UR10E_KD, ratio)))

    @property
    def home_configuration(self) -> np.ndarray:
        """:data:`HOME`, the start of Pająk 2024's task."""
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

    def _ik_solve(self, pose: np.ndarray, tol: float):
        """All branch solutions of the 4x4 flange pose.

        Returns (solutions, failures, flags): solutions maps branch -> q (wrapped); failures maps branch
        -> reason for branches without a real solution; flags = dict(shoulder=bool, wrist=set of shoulder
        signs, elbow=set of branches) marking singular factors. Raises ValueError when the pose is out of
        reach (no branch has a solution and none is wrist-singular).
        """
        rot, p = pose[:3, :3], pose[:3, 3]
        d1, a2, a3, d4, d5, d6 = (float(v) for v in self.model[1:])
        title = self.data.title
        z6 = rot[:, 2]
        o5 = p - d6 * z6
        r = math.hypot(o5[0], o5[1])
        h_sq = r * r - d4 * d4
        reach = abs(a2) + abs(a3)
        if h_sq < -(tol * reach) ** 2:
            raise DrakeTrajError(
                f"{_describe_pose(pose)} is out of reach: the wrist centre (flange - d6 z) is "
                f"{r:.6g} m from the joint-1 axis, closer than the {title}'s shoulder offset d4 = {d4} m", cause=Cause.UNREACHABLE
            )
        h_abs = math.sqrt(max(h_sq, 0.0))
        shoulder_singular = h_abs < tol * reach
        psi = math.atan2(o5[1], o5[0])
        solutions, failures = {}, {}
        elbow_singular = set()
        wrist_singular = set()
        for shoulder in (1, -1):
            q1 = psi + math.atan2(d4, shoulder * h_abs)
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
                o4 = o5 - d5 * np.array([c1 * s234, s1 * s234, -c234])
                u = c1 * o4[0] + s1 * o4[1]
                v = o4[2] - d1
                dist = math.hypot(u, v)
                c3 = (dist * dist - a2 * a2 - a3 * a3) / (2.0 * a2 * a3)
                if abs(c3) > 1.0 + tol:
                    for elbow in (1, -1):
                        failures[(shoulder, elbow, wrist)] = (
                            f"the wrist-1 joint would be {dist:.6g} m from the shoulder joint, outside the "
                            f"reach [{abs(abs(a2) - abs(a3)):.6g}, {reach:.6g}] m of the {title}'s upper arm and forearm"
                        )
                    continue
                c3 = min(1.0, max(-1.0, c3))
                s3_abs = math.sqrt(1.0 - c3 * c3)
                for elbow in (1, -1):
                    if s3_abs < tol:
                        elbow_singular.add((shoulder, elbow, wrist))
                    q3 = math.atan2(elbow * s3_abs, c3)
                    q2 = math.atan2(v, u) - math.atan2(a3 * elbow * s3_abs, a2 + a3 * c3)
                    q4 = q234 - q2 - q3
                    q = wrap_angle(np.array([q1, q2, q3, q4, q5, q6]))
                    solutions[(shoulder, elbow, wrist)] = q
        flags = dict(shoulder=shoulder_singular, wrist=wrist_singular, elbow=elbow_singular)
        if not solutions and not wrist_singular:
            centre = math.hypot(r, o5[2] - d1)
            max_centre = math.hypot(reach + d5, d4)
            reasons = "; ".join(dict.fromkeys(failures.values()))
            raise DrakeTrajError(
                f"{_describe_pose(pose)} is out of reach: the wrist centre (flange - d6 z) is {centre:.6g} m "
                f"from the shoulder point (0, 0, d1) (the {title} reaches at most {max_centre:.6g} m); {reasons}",
                cause=Cause.UNREACHABLE)
        return solutions, failures, flags

    def inverse_kinematics_all(self, pose, *, singular_tol: float = IK_SINGULAR_TOLERANCE, tool=FLANGE) -> np.ndarray:
        """All real joint solutions q (k, 6), k <= 8, with flange_pose(q) = pose; each wrapped to (-pi, pi].

        ``pose``: 4x4 transform of ``tool0`` in the base frame, or task pose [x, y, z, phi_X, phi_Y, phi_Z];
        with ``tool`` (X_FT, 4x4), the pose of that TCP (:func:`_flange_goal`; errors describe the
        flange pose it needs).
        Rows are ordered by branch as in ``IK_BRANCHES`` ((shoulder, elbow, wrist) signs, see
        :meth:`ik_branch`); branches without a real solution are left out, and solutions that coincide
        (at a shoulder or elbow singularity) are listed once.

        Raises ValueError naming the pose and the reason (distances) when no branch reaches the pose,
        and SingularConfigurationError at a wrist singularity (sin q5 = 0: a continuum of solutions).
        """
        pose = _flange_goal(pose, tool)
        solutions, _, flags = self._ik_solve(pose, singular_tol)
        if flags["wrist"]:
            _raise_wrist_singular(pose)
        return _unique_rows([solutions[b] for b in IK_BRANCHES if b in solutions])

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
        with ``tool`` (X_FT, 4x4), of that TCP's pose (:func:`_flange_goal`; errors describe the
        flange pose it needs).

        branch: (shoulder, elbow, wrist) signs, each +1 or -1 (see :meth:`ik_branch`); the result is
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
        solutions, failures, flags = self._ik_solve(pose, singular_tol)
        if flags["wrist"] and (branch is None or branch[0] in flags["wrist"]):
            _raise_wrist_singular(pose)
        if branch is not None:
            if flags["shoulder"]:
                raise SingularConfigurationError(
                    f"{_describe_pose(pose)} is at a shoulder singularity (wrist centre on the cylinder of "
                    f"radius d4 = {self.data.d[3]} m about the joint-1 axis): the shoulder branch is undefined"
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
        """IK of TCP positions at the TCP orientation of ``reference``, on its IK branch, each
        joint within 2 pi of ``reference`` (:meth:`inverse_kinematics`)."""
        reference = _as_joint_vector(reference, "reference")
        orientation = self.task_pose(reference, self.tcp_offset)[3:]
        branch = self.ik_branch(reference)
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        return np.array([self.inverse_kinematics(np.concatenate([point, orientation]), branch=branch, near=reference,
                                                 tool=self.tcp_offset)
                         for point in points]).reshape(-1, NUM_JOINTS)

    def joint_rates(self, q, v, a) -> tuple[np.ndarray, np.ndarray]:
        """qd = J^-1 [v; 0], qdd = J^-1 ([a; 0] - dJ/dt qd) with the TCP's analytic Jacobian (one q)."""
        jacobian = self.analytic_jacobian(q, tool=self.tcp_offset)
        qd = np.linalg.solve(jacobian, np.concatenate([v, np.zeros(3)]))
        _, bias = self.analytic_jacobian_and_bias(q, qd, tool=self.tcp_offset)
        qdd = np.linalg.solve(jacobian, np.concatenate([a, np.zeros(3)]) - bias)
        return qd, qdd

    def task_kinematics(self) -> TaskKinematics:
        """The compiled k(q), analytic Jacobian and J̇q̇ (:func:`kinematics_into` through
        :func:`~drake_traj.robots.compiled_kinematics.task_kinematics_into`, ``model`` = this
        arm's :attr:`URData.model`), angle wrapping, orientation error, pose errors and
        closed-form IK, of the TCP ``tcp_offset``."""
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
