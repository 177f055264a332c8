"""Any 6-axis arm of revolute joints as data: :class:`SerialChain`, from a DH table (either
convention) or from a MultibodyPlant. :mod:`drake_traj.robots.chain_kinematics` holds its compiled
task kinematics and numerical inverse kinematics; :mod:`drake_traj.robots.chain_arm` puts it under
the :class:`~drake_traj.robots.base.Robot` contract.

A :class:`SerialChain` holds six revolute joints as fixed transforms between consecutive joint
frames plus unit joint axes: X_{M(i-1) F(i)} for i = 1..6 (M(0) is the base frame B; F(i) the
joint's frame on its parent link, M(i) = F(i) turned by q_i about the axis a_i, the frame on its
child link), then X_{M6 T0} of the flange T0 (the ``tool_frame``). This covers standard DH,
modified (Craig) DH and any URDF/SDF chain read through MultibodyPlant (weld joints folded into
the fixed transforms). :meth:`SerialChain.packed` turns it into the ``model`` array of the one
compiled :func:`~drake_traj.robots.compiled_kinematics.task_kinematics_into`, so the compiled
Pająk 2024 law runs on it unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import Frame, RevoluteJoint, WeldJoint

from drake_traj.errors import joint_label
from drake_traj.robots.chain_kinematics import CHAIN, NUM_JOINTS
from drake_traj.validation import finite_array, invalid, real_array

__all__ = ["SerialChain", "dh_link_frames", "dh_table", "kinematic_path"]

DH_COLUMNS = ("d", "a", "alpha", "theta_offset")
CONVENTIONS = ("standard", "modified")


def _transform(rotation, translation) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = rotation
    out[:3, 3] = translation
    return out


def _rot_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return _transform([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]], np.zeros(3))


def _rot_x(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return _transform([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]], np.zeros(3))


def _shift(x=0.0, z=0.0) -> np.ndarray:
    return _transform(np.eye(3), [x, 0.0, z])


@dataclass(frozen=True)
class SerialChain:
    """Six revolute joints as data (see the module docstring for the frames).

    Attributes:
        fixed: (7, 4, 4) X_{M(i-1) F(i)} for i = 1..6 (M(0) the base frame), then X_{M6 T0} of
            the flange [m].
        axes: (6, 3) unit joint axes a_i, each in its joint frame F(i) (= in M(i)).
    """

    fixed: np.ndarray
    axes: np.ndarray

    def __post_init__(self):
        fixed = finite_array(self.fixed, "fixed", "m", shape=(NUM_JOINTS + 1, 4, 4))
        axes = finite_array(self.axes, "axes", "unit vector", shape=(NUM_JOINTS, 3))
        if not np.any(np.linalg.norm(fixed[:, :3, 3], axis=1) > 0.0):
            raise invalid("fixed", "a chain needs at least one link of non-zero length (every translation is zero)")
        for i, transform in enumerate(fixed):
            rotation = transform[:3, :3]
            if (np.max(np.abs(rotation.T @ rotation - np.eye(3))) > 1e-9 or np.linalg.det(rotation) <= 0.0
                    or np.any(transform[3] != (0.0, 0.0, 0.0, 1.0))):
                raise invalid("fixed", f"fixed[{i}] must be a rigid transform (a proper rotation, last row "
                                       f"[0, 0, 0, 1]), got {transform.tolist()}", i)
        norms = np.linalg.norm(axes, axis=1)
        if np.any(np.abs(norms - 1.0) > 1e-9):
            j = int(np.argmax(np.abs(norms - 1.0)))
            raise invalid("axes", f"axes[{j}] ({joint_label(j)}) must be a unit vector, got {axes[j].tolist()} "
                                  f"(norm {norms[j]:.6g})", j)
        fixed.flags.writeable = False
        axes.flags.writeable = False
        object.__setattr__(self, "fixed", fixed)
        object.__setattr__(self, "axes", axes)

    @classmethod
    def from_dh(cls, table, convention: str = "standard") -> "SerialChain":
        """The chain of a DH table (6, 4), rows [d, a, alpha, theta_offset] (metres, metres,
        radians, radians), one per joint, joint i turning about z of its frame:

        - ``"standard"``: T_i = Rz(q_i + θ_offset_i) Tz(d_i) Tx(a_i) Rx(α_i); the flange is frame 6;
        - ``"modified"`` (Craig): T_i = Rx(α_{i-1}) Tx(a_{i-1}) Rz(q_i + θ_offset_i) Tz(d_i), the
          row of joint i holding a_{i-1} and α_{i-1} as Craig's tables print them; the flange is
          frame 6 (no link beyond joint 6).

        Raises:
            DrakeTrajError: a table not of shape (6, 4) (field ``table``), a non-finite entry
                (its row and column), an unknown ``convention`` (field ``convention``).
        """
        array = dh_table(table, convention)
        fixed = np.empty((NUM_JOINTS + 1, 4, 4))
        links = dh_link_frames(array, convention)  # the part of T_i after q_i's rotation
        for i, (_, a, alpha, _) in enumerate(array):
            before = np.eye(4) if convention == "standard" else _rot_x(alpha) @ _shift(x=a)
            fixed[i] = before if i == 0 else links[i - 1] @ before
        fixed[NUM_JOINTS] = links[NUM_JOINTS - 1]
        return cls(fixed, np.tile([0.0, 0.0, 1.0], (NUM_JOINTS, 1)))

    @classmethod
    def from_plant(cls, plant: MultibodyPlant, base_frame, tool_frame) -> "SerialChain":
        """The chain from ``base_frame`` to ``tool_frame`` (Frames, or frame names) of the
        finalized ``plant``: the joints on the kinematic path from the tool's body up to the
        base's, six RevoluteJoints with any WeldJoints folded into the fixed transforms.

        Raises:
            DrakeTrajError: the plant not finalized, a frame not in it, a tool not below the base,
                not exactly 6 movable joints (naming them), a movable joint that is not revolute.
        """
        return cls(*plant_chain(plant, base_frame, tool_frame)[:2])

    @property
    def characteristic_length(self) -> float:
        """L [m]: the sum of the lengths of the fixed translations (the links), the scale of the
        singularity measure's linear rows."""
        return float(np.sum(np.linalg.norm(self.fixed[:, :3, 3], axis=1)))

    def packed(self) -> np.ndarray:
        """The ``model`` array (float64, read-only) of
        :func:`~drake_traj.robots.compiled_kinematics.task_kinematics_into`: [CHAIN, L, the 7
        fixed transforms (rotation row-major, translation), the 6 axes]."""
        model = np.concatenate([[CHAIN, self.characteristic_length],
                                np.concatenate([self.fixed[:, :3, :3].reshape(-1, 9), self.fixed[:, :3, 3]],
                                               axis=1).ravel(), self.axes.ravel()])
        model.flags.writeable = False
        return model


def dh_table(table, convention: str) -> np.ndarray:
    """``table`` as a finite (6, 4) array of rows [d, a, alpha, theta_offset] (m, m, rad, rad);
    DrakeTrajError naming the field (``table``, its row and column; ``convention``) otherwise."""
    array = real_array(table, "table", "m and rad")
    if array.shape != (NUM_JOINTS, 4):
        raise invalid("table", f"the DH table must have shape (6, 4), rows [{', '.join(DH_COLUMNS)}] (m, m, rad, "
                               f"rad), got shape {array.shape}")
    bad = np.argwhere(~np.isfinite(array))
    if len(bad):
        row, column = (int(v) for v in bad[0])
        raise invalid("table", f"the DH table's row {row} ({joint_label(row)}), column {column} "
                               f"({DH_COLUMNS[column]}) must be finite, got {array[row, column]}", row, column)
    if convention not in CONVENTIONS:
        raise invalid("convention", f"convention must be one of {CONVENTIONS}, got {convention!r}")
    return array


def dh_link_frames(table, convention: str = "standard") -> np.ndarray:
    """(6, 4, 4): DH frame i (the frame a DH table gives link i's centre of mass and inertia in)
    in the frame M(i) of :class:`SerialChain` (link i's joint frame turned by q_i), i = 1..6:
    Rz(θ_offset_i) Tz(d_i) Tx(a_i) Rx(α_i) in the standard convention (frame i on joint i+1's
    axis), Rz(θ_offset_i) Tz(d_i) in the modified one (frame i on joint i's axis). ``table`` as
    :meth:`SerialChain.from_dh`."""
    array = dh_table(table, convention)
    frames = np.empty((NUM_JOINTS, 4, 4))
    for i, (d, a, alpha, offset) in enumerate(array):
        frames[i] = _rot_z(offset) @ _shift(z=d)  # Rz(q + offset) = Rz(q) Rz(offset)
        if convention == "standard":
            frames[i] = frames[i] @ _shift(x=a) @ _rot_x(alpha)
    return frames


def plant_frame(plant, frame, name: str) -> Frame:
    """``frame`` (a Frame, or the name of one) of ``plant``; DrakeTrajError at field ``name``
    for a name the plant has no frame of."""
    if isinstance(frame, Frame):
        return frame
    if not isinstance(frame, str) or not plant.HasFrameNamed(frame):
        raise invalid(name, f"{name} {frame!r} is not a frame of the plant")
    return plant.GetFrameByName(frame)


def _kind(joint) -> str:
    return type(joint).__name__.split("_")[0]


def kinematic_path(plant, base_body, tool_body) -> tuple[list, list]:
    """The joints between two bodies of ``plant`` (finalized or not) through their nearest common
    ancestor A in the kinematic tree: (the joints from ``base_body`` up to A, base first; the joints
    from A down to ``tool_body``, A first). The first list is empty where the base is an ancestor
    of the tool; where it is not (a REP-199 ``base`` frame fixed to ``base_link`` beside the arm's
    first joint) it holds the joints that hang the base from A. Two bodies in separate trees (an
    unfinalized plant's free roots): DrakeTrajError at ``tool_frame``."""
    by_child = {plant.get_joint(index).child_body().index(): plant.get_joint(index)
                for index in plant.GetJointIndices()}

    def up(body) -> list:  # the joints from ``body`` to its tree's root, bottom first
        joints = []
        while body.index() in by_child:
            joints.append(by_child[body.index()])
            body = joints[-1].parent_body()
        return joints

    above_tool, above_base = up(tool_body), up(base_body)
    tool_ancestors = [tool_body.index()] + [joint.parent_body().index() for joint in above_tool]
    base_ancestors = [base_body.index()] + [joint.parent_body().index() for joint in above_base]
    common = next((body for body in base_ancestors if body in tool_ancestors), None)
    if common is None:
        raise invalid("tool_frame", f"the tool frame's body {tool_body.name()!r} and the base frame's body "
                                    f"{base_body.name()!r} are in separate kinematic trees: nothing joins them")
    return above_base[:base_ancestors.index(common)], above_tool[:tool_ancestors.index(common)][::-1]


def plant_chain(plant, base_frame, tool_frame):
    """(fixed (7, 4, 4), axes (6, 3), the six RevoluteJoints) of the kinematic path from
    ``base_frame`` to ``tool_frame`` of the finalized ``plant`` (:meth:`SerialChain.from_plant`),
    through the nearest body above both (:func:`kinematic_path`): the base may hang beside the
    arm's first joint by fixed joints (REP-199's ``base`` below ``base_link``), not by moving ones."""
    if not isinstance(plant, MultibodyPlant) or not plant.is_finalized():
        raise invalid("plant", f"plant must be a finalized MultibodyPlant, got {type(plant).__name__}"
                               + ("" if not isinstance(plant, MultibodyPlant) else " (not finalized)"))
    base, tool = plant_frame(plant, base_frame, "base_frame"), plant_frame(plant, tool_frame, "tool_frame")
    beside, path = kinematic_path(plant, base.body(), tool.body())
    if any(joint.parent_body().index() == plant.world_body().index() for joint in beside):
        raise invalid("tool_frame", f"tool frame {tool.name()!r} is not below the base frame {base.name()!r} in the "
                                    "plant's kinematic tree")
    for joint in beside:
        if not isinstance(joint, WeldJoint):
            raise invalid("base_frame", f"the base frame {base.name()!r} hangs from the {_kind(joint)} joint "
                                        f"{joint.name()!r} beside the arm: a base is fixed to the arm's root")
    movable = [joint for joint in path if not isinstance(joint, WeldJoint)]
    if len(movable) != NUM_JOINTS:
        names = ", ".join(f"{joint.name()!r} ({_kind(joint)})" for joint in movable)
        hint = (": hold the extra ones at a fixed position with locked_joints: {name: position}"
                if len(movable) > NUM_JOINTS else "")
        raise invalid("plant", f"{len(movable)} joints between {base.name()} and {tool.name()}: {names or 'none'}; "
                               f"a 6-axis arm has exactly 6 revolute joints{hint}")
    for joint in movable:
        if not isinstance(joint, RevoluteJoint):
            raise invalid("plant", f"joint {joint.name()!r} is {_kind(joint)}: a 6-axis arm has revolute joints only")
    fixed, axes = [], []
    current = base.GetFixedPoseInBodyFrame().inverse()  # X_{M(i-1) P}: from the last joint frame to a body
    for joint in beside:  # up from the base's body to the common ancestor (fixed joints)
        current = current @ _pose_in_parent(joint).inverse()
    for joint in path:
        current = current @ joint.frame_on_parent().GetFixedPoseInBodyFrame()
        if isinstance(joint, WeldJoint):
            current = current @ joint.X_FM()
        else:
            fixed.append(current.GetAsMatrix4())
            axes.append(np.array(joint.revolute_axis()))
            current = RigidTransform()
        current = current @ joint.frame_on_child().GetFixedPoseInBodyFrame().inverse()
    fixed.append((current @ tool.GetFixedPoseInBodyFrame()).GetAsMatrix4())
    return np.array(fixed), np.array(axes), movable


def _pose_in_parent(weld: WeldJoint) -> RigidTransform:
    """X_PC: the child body's pose in the parent body's frame across the WeldJoint ``weld``."""
    return (weld.frame_on_parent().GetFixedPoseInBodyFrame() @ weld.X_FM()
            @ weld.frame_on_child().GetFixedPoseInBodyFrame().inverse())
