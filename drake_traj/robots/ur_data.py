"""The UR e-Series family's published data: one :class:`URData` per arm (UR3e, UR5e, UR10e, UR16e,
UR20, UR30) and what every arm shares (the DH twists, the joint names, the home configuration, the
controller's joint-move defaults, the UR10e's gains).

Every e-Series arm and its successors have the same kinematic structure: the standard-DH chain
T_{i-1,i} = Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i) with alpha = (pi/2, 0, 0, pi/2, -pi/2, 0) and only
d1, a2, a3, d4, d5, d6 differing (:attr:`URData.model`, the data of the closed form
:mod:`drake_traj.robots.ur_closed_form`). :class:`~drake_traj.robots.ur_eseries.URArm` puts one
arm under the :class:`~drake_traj.robots.base.Robot` contract. The numbers and their sources:
``docs/ur_family.md`` (``docs/ur10e.md`` for the UR10e). Units: lengths in m, masses in kg,
angles in rad, speeds in rad/s, torques in N m; frames: standard-DH frame 0 is the base frame
(UR's controller "Base" frame), DH frame 6 the flange ``tool0``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from drake_traj.robots.ur_closed_form import UR_CLOSED_FORM

__all__ = ["BASE_FRAME", "DEFAULT_JOINT_MOVE_ACCELERATION", "DEFAULT_JOINT_MOVE_VELOCITY", "DH_ALPHA", "FLANGE_FRAME",
           "HOME", "JOINT_NAMES", "NUM_JOINTS", "UR10E_DATA", "UR10E_EFFORT_LIMIT", "UR10E_KD", "UR10E_KP",
           "UR16E_DATA", "UR20_DATA", "UR30_DATA", "UR3E_DATA", "UR5E_DATA", "URData"]

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
# scaled joint by joint by its torque limit over the UR10e's
# (:attr:`drake_traj.robots.ur_eseries.URArm.default_gains`).
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
    data_source: str = "Universal Robots' DH table, data sheets and ROS 2 description (the manual's UR e-Series page)"

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
    data_source="Universal Robots' DH and dynamics table and UR10e data sheet (the manual's UR10e page)")

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
