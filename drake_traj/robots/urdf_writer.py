"""URDF text for a 6R arm from its DH table (or any serial chain), link inertias, limits and
primitive shapes.

:func:`chain_urdf` writes any :class:`~drake_traj.robots.chain.SerialChain` (joint origins and
axes from the chain, inertials in the frames given per link); :func:`dh_table_urdf` the arm of a
scenario's ``!DhArm`` (either DH convention, capsules along the links, the pairs that always
overlap filtered).

:func:`dh_arm_urdf` writes a model with the frames of ``models/ur10e.urdf`` (``docs/ur10e.md``,
"The model file"): ``base`` is DH frame 0 (welded to the world by ``Robot.add_to_plant``); link i's
frame is DH frame i-1 turned by q_i about its z axis, so joint i+1 sits in link i at
xyz = (a_i cos θ_i, a_i sin θ_i, d_i), rpy = (α_i, 0, θ_i) and every joint axis is the local z;
``tool0`` is DH frame 6. Each joint J has an effort actuator ``J_actuator`` whose limit is the
joint's torque limit (a transmission, which Drake's parser turns into a ``JointActuator``).
Inertials are given as the DH convention has them (centre of mass and tensor about it in DH frame
i, the frame at link i's distal joint) and moved into link i's frame. Collision shapes are also the
visual shapes, so Meshcat shows what is checked.

:func:`ur_shapes` gives the UR e-Series arms' shapes (the UR10e's of ``docs/ur10e.md`` scaled to
each arm); :func:`chain_capsules` (:func:`dh_capsules`) plain capsules along a chain for an arm
without better data.
``python -m drake_traj.robots.urdf_writer`` regenerates ``models/<arm>.urdf`` for every e-Series arm
but the UR10e (whose hand-written file stays as it is).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from drake_traj.data import data_directory
from drake_traj.robots.chain import NUM_JOINTS, SerialChain, dh_link_frames
from drake_traj.robots.ur_data import DH_ALPHA, JOINT_NAMES, UR10E_DATA, URData
from drake_traj.robots.ur_eseries import UR_ARMS
from drake_traj.validation import invalid

__all__ = ["DH_JOINT_NAMES", "LINK_NAMES", "Shape", "capsule_between", "chain_capsules", "chain_segments", "chain_urdf",
           "dh_arm_urdf", "dh_capsules", "dh_table_urdf", "main", "touching_pairs", "ur_shapes", "ur_urdf"]

# The bodies, base first, as in models/ur10e.urdf (the station and the cell checks name them).
LINK_NAMES = ("base", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link",
              "wrist_3_link")
MARGIN = 0.005  # [m] added to every estimated radius (docs/ur10e.md, "Collision geometry")


@dataclass(frozen=True)
class Shape:
    """A collision (and visual) shape of one body, in that body's frame: a ``cylinder`` or a
    ``capsule`` along its local z, or a ``sphere``; ``xyz`` [m], ``rpy`` [rad] (URDF's fixed-axis
    roll-pitch-yaw), ``radius`` and ``length`` [m] (``length`` unused for a sphere)."""

    name: str
    kind: str
    radius: float
    length: float = 0.0
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    colour: str = "grey"  # "grey" or "blue"


def capsule_between(name: str, start, end, radius: float, colour: str = "grey") -> Shape:
    """A capsule of ``radius`` whose axis runs from ``start`` to ``end`` (points in the body frame [m])."""
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    axis = end - start
    length = float(np.linalg.norm(axis))
    if length == 0.0:
        return Shape(name, "sphere", radius, 0.0, tuple(start), colour=colour)
    pitch = math.atan2(math.hypot(axis[0], axis[1]), axis[2])
    yaw = math.atan2(axis[1], axis[0]) if math.hypot(axis[0], axis[1]) > 0.0 else 0.0
    return Shape(name, "capsule", radius, length, tuple(0.5 * (start + end)), (0.0, pitch, yaw), colour)


def _rpy(rotation) -> tuple[float, float, float]:
    """URDF's fixed-axis roll-pitch-yaw [rad] of a rotation matrix R = Rz(yaw) Ry(pitch) Rx(roll)
    (``+ 0.0`` writes a negative zero as 0.0)."""
    r = np.asarray(rotation, dtype=float)
    return (math.atan2(r[2, 1], r[2, 2]) + 0.0, math.atan2(-r[2, 0], math.hypot(r[0, 0], r[1, 0])) + 0.0,
            math.atan2(r[1, 0], r[0, 0]) + 0.0)


def chain_segments(chain: SerialChain, pedestal: float | None = None) -> list[list[tuple[np.ndarray, np.ndarray]]]:
    """The line segments (start, end) [m] a plain model of ``chain`` puts its links' capsules on,
    each in its body's frame (the base's frame; M(i) for link i): link i runs from joint i (the
    origin of M(i)) along the joint's axis to the foot of the next joint's origin, then across to
    it (where both parts are zero: a point, a ball at the joint). With a ``pedestal`` radius [m],
    the base holds the lower half of link 1's part along joint 1's axis, starting that far above
    joint 1's origin (so that a capsule on it stands on a table flush with the base), and link 1
    the upper half, clear of the table. Base first, then links 1..6."""
    segments: list[list[tuple[np.ndarray, np.ndarray]]] = [[]]
    for i in range(NUM_JOINTS):
        axis, end = chain.axes[i], chain.fixed[i + 1][:3, 3]
        corner = float(axis @ end) * axis
        link = [(np.zeros(3), corner)] if np.linalg.norm(corner) > 1e-12 else []
        if np.linalg.norm(end - corner) > 1e-12 or not link:
            link.append((corner, end))
        segments.append(link)
    column = segments[1][0][1]  # link 1's first segment ends at its corner (or is the point at joint 1)
    height = float(np.linalg.norm(column))
    if pedestal is not None and height > 1e-12 and np.allclose(np.cross(column, chain.axes[0]), 0.0):
        half = 0.5 * column
        segments[1][0] = (half, column)
        origin, rotation = chain.fixed[0][:3, 3], chain.fixed[0][:3, :3]
        segments[0] = [(origin + rotation @ (min(pedestal, 0.5 * height) / height * column), origin + rotation @ half)]
    return segments


def chain_capsules(chain: SerialChain, radii: Sequence[float], *, pedestal: bool = True) -> list[list[Shape]]:
    """Capsules of ``radii[i-1]`` [m] on link i's :func:`chain_segments` of ``chain`` (with a
    pedestal of ``radii[0]`` on the base), the ``shapes`` of :func:`chain_urdf` (base, links 1..6)."""
    return [[capsule_between(f"{LINK_NAMES[body]}_{k}", start, end, float(radii[max(body - 1, 0)]),
                             colour="grey" if body == 0 else "blue") for k, (start, end) in enumerate(segments)]
            for body, segments in enumerate(chain_segments(chain, float(radii[0]) if pedestal else None))]


def _distance_to_segments(point: np.ndarray, segments) -> float:
    """The distance [m] of ``point`` from the nearest of ``segments`` (inf when there are none)."""
    best = np.inf
    for start, end in segments:
        direction = end - start
        length = float(direction @ direction)
        t = 0.0 if length == 0.0 else min(1.0, max(0.0, float((point - start) @ direction) / length))
        best = min(best, float(np.linalg.norm(point - start - t * direction)))
    return best


def touching_pairs(chain: SerialChain, radius: float) -> list[tuple[int, int, str]]:
    """The pairs of non-adjacent bodies (0 = base ... 6) whose :func:`chain_capsules` of
    ``radius`` overlap at every configuration, with the reason, as :func:`chain_urdf`'s
    ``filtered_pairs``: bodies i < j share a point P at every configuration when the axes of
    joints i+1..j all pass through P (turning about them keeps P fixed in both bodies), and
    their capsules overlap whenever dist(P, body i's segments) + dist(P, body j's) <= 2 radius
    (the triangle inequality). A spherical wrist's links 4 and 6 are such a pair."""
    segments = chain_segments(chain, radius)  # as chain_capsules(chain, [radius] * 6)
    pairs = []
    for i in range(NUM_JOINTS - 1):
        frames, frame = [], chain.fixed[i]  # joint frames F(i+1)..F(j) in M(i) at q = 0
        for j in range(i + 1, NUM_JOINTS + 1):
            frames.append(frame)
            if j >= i + 2:
                lines = [(f[:3, 3], f[:3, :3] @ chain.axes[k]) for k, f in enumerate(frames, start=i)]
                projectors = [np.eye(3) - np.outer(u, u) for _, u in lines]
                matrix = sum(projectors)
                if np.linalg.cond(matrix) < 1e9:
                    point = np.linalg.solve(matrix, sum(p @ o for p, (o, _) in zip(projectors, lines)))
                    if max(float(np.linalg.norm(p @ (point - o))) for p, (o, _) in zip(projectors, lines)) < 1e-9:
                        in_j = np.linalg.solve(frame, np.append(point, 1.0))[:3]  # in M(j) = F(j) at q = 0
                        gap = _distance_to_segments(point, segments[i]) + _distance_to_segments(in_j, segments[j])
                        if gap <= 2 * radius:
                            pairs.append((i, j, f"bodies {i} and {j} ({LINK_NAMES[i]}, {LINK_NAMES[j]}) overlap at "
                                                f"every configuration: the axes of joints {i + 1}-{j} meet in one "
                                                f"point, {gap:.4f} m from the two bodies' capsule axes together "
                                                f"(capsules of radius {radius:g} m)"))
            if j < NUM_JOINTS:
                frame = frame @ chain.fixed[j]
    return pairs


def dh_capsules(d, a, radii, *, theta=(0.0,) * 6) -> list[list[Shape]]:
    """Plain shapes along a standard-DH chain (:func:`chain_capsules` without a pedestal): for
    each link i (1..6), a capsule of ``radii[i-1]`` [m] from joint i along its axis by d_i, and one
    from there along x by a_i to joint i+1 (a sphere at the joint where both are zero). Returns
    the shapes of the base (none) and links 1..6, the ``shapes`` of :func:`dh_arm_urdf`."""
    return chain_capsules(SerialChain.from_dh(np.column_stack([d, a, np.zeros(6), theta])), radii, pedestal=False)


def _vector(values, name: str, size: int) -> np.ndarray:
    array = np.asarray(values, dtype=float)
    if array.shape != (size,) or not np.all(np.isfinite(array)):
        raise invalid(name, f"{name} must be {size} finite numbers, got {values!r}")
    return array


def _numbers(values) -> str:
    return " ".join(repr(float(v)) for v in values)


def _compact(value: float) -> str:
    """A number as URDF text, a whole number without its decimals (an axis ``0 0 1``)."""
    return str(int(value)) if float(value).is_integer() else repr(float(value))


def _size(value: float) -> str:
    """A shape's dimension [m], to 1 µm (the shapes are estimates; the kinematics stay exact)."""
    return repr(round(float(value), 6))


def _geometry(shape: Shape) -> str:
    if shape.kind == "cylinder":
        return f'<cylinder radius="{_size(shape.radius)}" length="{_size(shape.length)}"/>'
    if shape.kind == "capsule":
        return f'<drake:capsule radius="{_size(shape.radius)}" length="{_size(shape.length)}"/>'
    if shape.kind == "sphere":
        return f'<sphere radius="{_size(shape.radius)}"/>'
    raise invalid("shapes", f"shape {shape.name!r}: kind must be cylinder, capsule or sphere, got {shape.kind!r}")


def _shape_xml(shape: Shape) -> str:
    if shape.colour not in ("grey", "blue"):
        raise invalid("shapes", f"shape {shape.name!r}: colour must be grey or blue, got {shape.colour!r}")
    origin = f'<origin xyz="{" ".join(_size(v) for v in shape.xyz)}" rpy="{_numbers(shape.rpy)}"/>'
    geometry = _geometry(shape)
    return (f'    <visual name="{shape.name}">\n      {origin}\n      <geometry>{geometry}</geometry>\n'
            f'      <material name="{shape.colour}"/>\n    </visual>\n'
            f'    <collision name="{shape.name}">\n      {origin}\n      <geometry>{geometry}</geometry>\n'
            '    </collision>\n')


def _inertial_xml(mass: float, com, inertia, rpy=(0.0, 0.0, 0.0)) -> str:
    ixx, ixy, ixz, iyy, iyz, izz = (repr(float(v)) for v in inertia)
    return (f'    <inertial>\n      <origin xyz="{_numbers(com)}" rpy="{_numbers(rpy)}"/>\n'
            f'      <mass value="{float(mass)!r}"/>\n'
            f'      <inertia ixx="{ixx}" ixy="{ixy}" ixz="{ixz}" iyy="{iyy}" iyz="{iyz}" izz="{izz}"/>\n'
            '    </inertial>\n')


STANDARD_DH_FRAMES = ("Frames: base = DH frame 0; link i = DH frame i-1 turned by q_i; joint i+1 in link i at\n"
                      "  (a_i cos theta_i, a_i sin theta_i, d_i), rpy (alpha_i, 0, theta_i); tool0 = DH frame 6. Inertials: the\n"
                      "  DH frame i centre of mass and tensor, moved into link i's frame. Visual shapes = collision shapes.")


def dh_arm_urdf(name: str, d: Sequence[float], a: Sequence[float], alpha: Sequence[float], *,
                theta: Sequence[float] = (0.0,) * 6, comment: str = "", **model) -> str:
    """URDF text of a 6R arm from its standard-DH table (:func:`chain_urdf` of
    ``SerialChain.from_dh``, the inertials in DH frame i; frames and names as
    ``models/ur10e.urdf``; see the module docstring).

    Args:
        name: the robot's name.
        d, a, alpha, theta: the standard-DH table, T_{i-1,i} = Rz(q_i + θ_i) Tz(d_i) Tx(a_i) Rx(α_i),
            6 entries each [m, rad]; the joint variable q_i is the DH angle minus θ_i.
        comment: text for the file's header comment.
        model: the other keyword arguments of :func:`chain_urdf` (masses, centers_of_mass,
            inertias (in DH frame i), limits, shapes, base_inertial, filtered_pairs, joint_names).

    Raises DrakeTrajError (a ValueError) naming the argument when a table or list has the wrong
    size or a non-finite entry.
    """
    table = np.column_stack([_vector(v, n, 6) for v, n in ((d, "d"), (a, "a"), (alpha, "alpha"), (theta, "theta"))])
    return chain_urdf(name, SerialChain.from_dh(table), dh_link_frames(table), comment=f"{comment}\n  {STANDARD_DH_FRAMES}",
                      **model)


def chain_urdf(name: str, chain: SerialChain, inertial_frames, *, masses: Sequence[float], centers_of_mass,
               inertias, lower: Sequence[float], upper: Sequence[float], velocity: Sequence[float],
               effort: Sequence[float], shapes: Sequence[Sequence[Shape]],
               base_inertial: tuple[float, Sequence[float], Sequence[float]] = (1.0, (0.0, 0.0, 0.0),
                                                                              (1e-3, 0.0, 0.0, 1e-3, 0.0, 1e-3)),
               filtered_pairs: Sequence[tuple[int, int, str]] = (), joint_names: Sequence[str] = JOINT_NAMES,
               comment: str = "") -> str:
    """URDF text of the 6R arm ``chain``: ``base`` is the chain's base frame (welded to the world
    by ``Robot.add_to_plant``), link i's frame is the chain's M(i) (joint i's frame turned by q_i),
    joint i sits in its parent at ``chain.fixed[i-1]`` and turns about ``chain.axes[i-1]``,
    ``tool0`` is at ``chain.fixed[6]`` in link 6. Each joint J has an effort actuator
    ``J_actuator`` (a transmission).

    Args:
        name: the robot's name.
        chain: the kinematics (:class:`~drake_traj.robots.chain.SerialChain`).
        inertial_frames: (6, 4, 4), the frame link i's centre of mass and inertia are given in,
            in M(i) (a DH table's frame i: :func:`~drake_traj.robots.chain.dh_link_frames`).
        masses: links 1..6 [kg]. centers_of_mass: (6, 3) [m], link i's in its inertial frame.
        inertias: (6, 6) rows (ixx, ixy, ixz, iyy, iyz, izz) [kg m²] about the centre of mass, axes
            of the inertial frame.
        lower, upper: joint position limits [rad]; velocity [rad/s], effort [N m]: rated speeds and
            torque limits (the actuators saturate at ``effort``).
        shapes: 7 lists of :class:`Shape`, for the base and links 1..6, each in its body's frame.
        base_inertial: (mass [kg], centre of mass [m], inertia (6,) [kg m²]) of the base in its frame.
        filtered_pairs: (body index, body index, reason) with 0 = base ... 6 = wrist 3: pairs of
            bodies whose collisions Drake ignores (a ``drake:collision_filter_group`` each), for
            shapes that are in contact, or at a constant distance, at every configuration. Bodies
            joined by a joint are filtered by Drake already.
        joint_names: the six joints' names (the actuators are ``{joint}_actuator``).
        comment: text for the file's header comment.

    Returns the URDF as a string. Raises DrakeTrajError (a ValueError) naming the argument when a
    list has the wrong size or a non-finite entry.
    """
    masses = _vector(masses, "masses", 6)
    coms = [_vector(c, f"centers_of_mass[{i}]", 3) for i, c in enumerate(centers_of_mass)]
    tensors = [_vector(t, f"inertias[{i}]", 6) for i, t in enumerate(inertias)]
    lower, upper, velocity, effort = (_vector(v, n, 6) for v, n in ((lower, "lower"), (upper, "upper"),
                                                                     (velocity, "velocity"), (effort, "effort")))
    frames = np.asarray(inertial_frames, dtype=float)
    if len(coms) != 6 or len(tensors) != 6 or frames.shape != (6, 4, 4):
        raise invalid("centers_of_mass", "centers_of_mass, inertias and inertial_frames must have 6 rows, one per link")
    if len(shapes) != 7:
        raise invalid("shapes", f"shapes must have 7 lists (the base and links 1..6), got {len(shapes)}")
    if len(joint_names) != 6:
        raise invalid("joint_names", f"joint_names must name 6 joints, got {len(joint_names)}")
    base_mass, base_com, base_inertia = base_inertial
    parts = [_header_xml(name, comment),
             _link_xml(LINK_NAMES[0], _inertial_xml(base_mass, base_com, base_inertia), shapes[0])]
    for i in range(6):
        parts.append(_revolute_joint_xml(joint_names[i], i, chain.fixed[i], chain.axes[i],
                                         (lower[i], upper[i], velocity[i], effort[i])))
        position, rotation = frames[i][:3, 3], frames[i][:3, :3]
        parts.append(_link_xml(LINK_NAMES[i + 1], _inertial_xml(masses[i], position + rotation @ coms[i], tensors[i],
                                                                _rpy(rotation)), shapes[i + 1]))
    flange = chain.fixed[6]
    parts.append(f'  <joint name="wrist_3-tool0_fixed_joint" type="fixed">\n    <parent link="{LINK_NAMES[6]}"/>\n'
                 f'    <child link="tool0"/>\n    <origin xyz="{_numbers(flange[:3, 3])}" rpy="{_numbers(_rpy(flange[:3, :3]))}"/>\n'
                 '  </joint>\n  <link name="tool0"/>\n')
    parts += [_transmission_xml(joint) for joint in joint_names]
    parts += [_filter_group_xml(first, second, reason) for first, second, reason in filtered_pairs]
    parts.append("</robot>\n")
    return "".join(parts)


def _header_xml(name: str, comment: str) -> str:
    """The URDF's XML declaration, header comment, ``robot`` element and materials."""
    return (f'<?xml version="1.0"?>\n<!--\n  {name}: written by drake_traj.robots.urdf_writer (do not edit; regenerate).\n'
            f'  {comment}\n-->\n'
            f'<robot name="{name}" xmlns:drake="http://drake.mit.edu">\n'
            '  <material name="blue">\n    <color rgba="0.2 0.4 0.9 1"/>\n  </material>\n'
            '  <material name="grey">\n    <color rgba="0.75 0.78 0.82 1"/>\n  </material>\n')


def _link_xml(name: str, inertial: str, shapes: Sequence[Shape]) -> str:
    """A ``link`` element: its ``inertial`` XML, then each shape's visual and collision."""
    return f'  <link name="{name}">\n' + inertial + "".join(_shape_xml(s) for s in shapes) + '  </link>\n'


def _revolute_joint_xml(name: str, i: int, origin: np.ndarray, axis, limits) -> str:
    """Joint i+1 (0-based ``i``) from link ``LINK_NAMES[i]`` to the next: at ``origin`` (4x4 [m]) in
    its parent, about ``axis`` (in the joint frame), with ``limits`` (lower [rad], upper [rad],
    velocity [rad/s], effort [N m])."""
    lower, upper, velocity, effort = (float(v) for v in limits)
    return (f'  <joint name="{name}" type="revolute">\n'
            f'    <parent link="{LINK_NAMES[i]}"/>\n    <child link="{LINK_NAMES[i + 1]}"/>\n'
            f'    <origin xyz="{_numbers(origin[:3, 3])}" rpy="{_numbers(_rpy(origin[:3, :3]))}"/>\n'
            f'    <axis xyz="{" ".join(_compact(v) for v in axis)}"/>\n'
            f'    <limit lower="{lower!r}" upper="{upper!r}" velocity="{velocity!r}" effort="{effort!r}"/>\n'
            '  </joint>\n')


def _transmission_xml(joint: str) -> str:
    """The transmission of ``joint`` to its effort actuator ``{joint}_actuator``."""
    return (f'  <transmission name="{joint}_transmission">\n'
            '    <type>transmission_interface/SimpleTransmission</type>\n'
            f'    <joint name="{joint}">\n'
            '      <hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface>\n'
            f'    </joint>\n    <actuator name="{joint}_actuator">\n'
            '      <mechanicalReduction>1</mechanicalReduction>\n    </actuator>\n  </transmission>\n')


def _filter_group_xml(first: int, second: int, reason: str) -> str:
    """A ``drake:collision_filter_group`` of bodies ``first`` and ``second`` (0 = base) that ignores
    itself, after a comment with the ``reason``."""
    group = f"{LINK_NAMES[first]}_{LINK_NAMES[second]}"
    return (f'  <!-- {reason} -->\n  <drake:collision_filter_group name="{group}">\n'
            f'    <drake:member link="{LINK_NAMES[first]}"/>\n    <drake:member link="{LINK_NAMES[second]}"/>\n'
            f'    <drake:ignored_collision_filter_group name="{group}"/>\n  </drake:collision_filter_group>\n')


DH_JOINT_NAMES = tuple(f"joint_{i}" for i in range(1, NUM_JOINTS + 1))  # the joints of an arm from a DH table


def dh_table_urdf(name: str, table, convention: str, *, masses, centres_of_mass, inertias, link_radius: float,
                  lower, upper, velocity, effort, source: str = "") -> str:
    """URDF text of the arm of a DH table in either convention (a scenario's ``!DhArm``):
    :func:`chain_urdf` of ``SerialChain.from_dh(table, convention)``, joints ``joint_1`` ..
    ``joint_6``, each link's centre of mass and inertia given in the convention's DH frame i
    (:func:`~drake_traj.robots.chain.dh_link_frames`), capsules of ``link_radius`` [m] along
    the links with a pedestal on the base (:func:`chain_capsules`), and the non-adjacent pairs
    that overlap at every configuration filtered (:func:`touching_pairs`), nothing else.

    Args:
        table: (6, 4) rows [d, a, alpha, theta_offset] [m, m, rad, rad]; convention "standard"
            or "modified".
        masses: (6,) [kg]; centres_of_mass: (6, 3) [m] or None (at the frame's origin);
        inertias: (6, 6) rows [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] [kg m²] about the centre of mass, or
            None (a solid ball of radius ``link_radius``: 2/5 m r² about every axis).
        lower, upper [rad], velocity [rad/s], effort [N m]: (6,) joint limits.
        source: where the numbers come from (the file's header comment).
    """
    chain = SerialChain.from_dh(table, convention)
    masses = _vector(masses, "masses", NUM_JOINTS)
    coms = np.zeros((NUM_JOINTS, 3)) if centres_of_mass is None else np.asarray(centres_of_mass, dtype=float)
    if inertias is None:
        tensors = np.outer(0.4 * masses * link_radius ** 2, [1.0, 0.0, 0.0, 1.0, 0.0, 1.0])
    else:
        ixx, iyy, izz, ixy, ixz, iyz = np.asarray(inertias, dtype=float).T
        tensors = np.column_stack([ixx, ixy, ixz, iyy, iyz, izz])
    return chain_urdf(
        name, chain, dh_link_frames(table, convention), masses=masses, centers_of_mass=coms, inertias=tensors,
        lower=lower, upper=upper, velocity=velocity, effort=effort, shapes=chain_capsules(chain, [link_radius] * 6),
        filtered_pairs=touching_pairs(chain, link_radius), joint_names=DH_JOINT_NAMES,
        comment=f"{source or name}: from its {convention} DH table.\n  Frames: base = the table's base frame; link i "
                f"= joint i's frame turned by q_i; tool0 = DH frame 6.\n  Inertials: given in the {convention} DH "
                f"frames i. Capsules of radius {link_radius:g} m along the links (visual = collision).")


def ur_shapes(data: URData) -> list[list[Shape]]:
    """The shapes of an e-Series arm: those of ``models/ur10e.urdf`` (``docs/ur10e.md``,
    "Collision geometry": the real radii, estimated, plus :data:`MARGIN`) with every UR10e size
    scaled by ``data.size`` (the arm's d5 over the UR10e's) and placed by the arm's own DH lengths
    and tube planes. Base, links 1..6, as :func:`dh_arm_urdf` takes them."""
    s, m = data.size, MARGIN
    d1, d4, d5, d6 = data.d[0], data.d[3], data.d[4], data.d[5]
    a2, a3 = data.a[1], data.a[2]
    upper_plane, forearm_plane = data.tube_offsets
    base_radius, base_height = 0.095 * s, 0.1 * s  # the UR10e's footprint (no margin) and height
    upper_radius, forearm_radius = 0.075 * s + m, 0.058 * s + m  # tube radii at their thick end
    wrist_radius, flange_radius, flange_length = 0.047 * s + m, 0.045 * s + m, 0.05 * s
    turn = math.pi / 2

    def cylinder(name, radius, start, end, *, at=(0.0, 0.0), axis="z", colour="blue"):
        """A cylinder from ``start`` to ``end`` along the body's ``axis`` ("z" or "y") at ``at``
        in the other two coordinates."""
        centre = 0.5 * (start + end)
        xyz = (at[0], at[1], centre) if axis == "z" else (at[0], centre, at[1])
        return Shape(name, "cylinder", radius, abs(end - start), xyz, (0.0, 0.0, 0.0) if axis == "z" else (turn, 0.0, 0.0),
                     colour)

    upper_top = upper_plane + upper_radius
    forearm_bottom = forearm_plane - forearm_radius
    return [
        [cylinder("base_foot", base_radius, 0.0, base_height, colour="grey")],
        [cylinder("joint1_housing", 0.076 * s + m, base_height, d1 + 0.1 * s),
         cylinder("joint2_housing", 0.077 * s + m, -0.03 * s, -upper_top, at=(0.0, d1), axis="y")],
        [capsule_between("upper_arm_tube", (0.0, 0.0, upper_plane), (a2, 0.0, upper_plane), upper_radius),
         cylinder("joint3_housing", 0.077 * s + m, forearm_bottom, upper_top, at=(a2, 0.0))],
        [capsule_between("forearm_tube", (0.0, 0.0, forearm_plane), (a3, 0.0, forearm_plane), forearm_radius),
         cylinder("joint4_housing", wrist_radius, forearm_bottom, d4 - 0.044 * s, at=(a3, 0.0))],
        # about the joint-5 axis (-y here): 0.12 s long, from -0.047 s to 0.073 s along it, + m at each end
        [cylinder("joint5_housing", wrist_radius, 0.047 * s + m, -0.073 * s - m, at=(0.0, d4), axis="y")],
        # about the joint-6 axis (+y here): from behind the joint-5 housing to the flange
        [cylinder("joint6_housing", flange_radius, -wrist_radius, d6 - flange_length, at=(0.0, d5), axis="y")],
        [cylinder("flange", flange_radius, d6 - flange_length, d6, colour="grey")],
    ]


def ur_urdf(data: URData) -> str:
    """The URDF of an e-Series arm from its :class:`URData` (:func:`dh_arm_urdf`, :func:`ur_shapes`)."""
    radius, height = 0.095 * data.size, 0.1 * data.size
    base_inertia = (data.base_mass * (3 * radius ** 2 + height ** 2) / 12, 0.0, 0.0,
                    data.base_mass * (3 * radius ** 2 + height ** 2) / 12, 0.0, data.base_mass * radius ** 2 / 2)
    gap = data.d[5] - 0.05 * data.size - (0.047 * data.size + MARGIN)
    limit = np.array(data.position_limit)
    return dh_arm_urdf(
        data.name, data.d, data.a, DH_ALPHA, masses=data.link_masses, centers_of_mass=data.centers_of_mass,
        inertias=data.inertias, lower=-limit, upper=limit, velocity=data.velocity_limit, effort=data.effort_limit,
        shapes=ur_shapes(data), base_inertial=(data.base_mass, (0.0, 0.0, height / 2), base_inertia),
        filtered_pairs=[(4, 6, f"the joint-5 housing and the flange: {gap * 1000:.2f} mm apart at every configuration "
                               "(the flange turns about the joint-5 axis and its own), as in models/ur10e.urdf")],
        comment=f"{data.title} from docs/ur_family.md (UR's DH table, masses, centres of mass, limits); primitive "
                "shapes: the UR10e's of docs/ur10e.md scaled by d5 / d5(UR10e).")


def main(argv: Sequence[str] | None = None) -> int:
    """Write ``models/<arm>.urdf`` for every e-Series arm but the UR10e into the folder given as
    the one argument (default: the package's ``models``)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    folder = Path(argv[0]) if argv else data_directory("models")
    for data in (arm.data for arm in UR_ARMS if arm.data is not UR10E_DATA):
        path = folder / f"{data.name}.urdf"
        path.write_text(ur_urdf(data))
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
