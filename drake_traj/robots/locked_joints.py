"""Joints of a description that the arm does not drive, held at a stated position.

A published description often carries more joints than the six between its base and tool frames:
a gripper's fingers (some coupled by URDF ``<mimic>``), a seventh axis elsewhere (a track under
the base). Nothing would drive them, and the station's state is the six joints'. Each such joint
is welded at a position before the plant is finalized: the one the scenario gives
(``robot.locked_joints: {name: position}``), else 0 clipped into the joint's range. A joint
between the base and tool frames may be locked too (the extra axis of a 7-axis arm), and then the
chain steps over it. :func:`joints_to_lock` decides the positions on a model just parsed;
:func:`lock_joints` welds them, in every plant the arm is added to.
"""

from __future__ import annotations

import numpy as np
from pydrake.common.eigen_geometry import AngleAxis
from pydrake.math import RigidTransform
from pydrake.multibody.tree import PrismaticJoint, RevoluteJoint, WeldJoint

from drake_traj.errors import Cause, DrakeTrajError
from drake_traj.robots.chain import kinematic_path, plant_frame

__all__ = ["joints_to_lock", "lock_joints"]

_UNITS = {RevoluteJoint: "rad", PrismaticJoint: "m"}


def _refusal(field: tuple, message: str) -> DrakeTrajError:
    """The refusal at ``field`` (``("locked_joints", name)``): a caller names the field in its terms."""
    return DrakeTrajError(message, field=field, cause=Cause.INVALID)


def joints_to_lock(plant, instance, base_frame: str, tool_frame: str, given: dict[str, float]) -> dict[str, float]:
    """{joint name: position [rad or m]} of every joint of ``instance`` (a model just parsed into
    ``plant``, not finalized) with a degree of freedom off the path from ``base_frame`` to
    ``tool_frame`` (0 clipped into its range), and of the joints ``given`` names, at their given
    positions. DrakeTrajError at ``locked_joints.NAME`` for a name that is no joint of the model, a
    joint without a degree of freedom, a position beyond its range; at ``locked_joints`` for a
    joint to hold that is neither revolute nor prismatic."""
    joints = {plant.get_joint(index).name(): plant.get_joint(index) for index in plant.GetJointIndices(instance)}
    for name in given:
        if name not in joints:
            raise _refusal(("locked_joints", name), f"the model has no joint {name!r}; its joints with a degree of "
                                                    f"freedom: {', '.join(n for n, j in joints.items() if j.num_positions())}")
        if joints[name].num_positions() == 0:
            raise _refusal(("locked_joints", name), f"the joint {name!r} is fixed already")
    base = plant_frame(plant, base_frame, "base_frame").body()
    tool = plant_frame(plant, tool_frame, "tool_frame").body()
    on_path = {joint.index() for side in kinematic_path(plant, base, tool) for joint in side}
    positions = {}
    for name, joint in joints.items():
        if joint.num_positions() == 0 or (name not in given and joint.index() in on_path):
            continue
        kind = next((cls for cls in _UNITS if isinstance(joint, cls)), None)
        if kind is None:
            raise _refusal(("locked_joints",), f"the joint {name!r} ({type(joint).__name__}) is not between "
                                               f"{base_frame} and {tool_frame} and cannot be held: only revolute and "
                                               "prismatic joints are locked")
        lower, upper = float(joint.position_lower_limits()[0]), float(joint.position_upper_limits()[0])
        if name in given:
            value = float(given[name])
            if not lower <= value <= upper:
                raise _refusal(("locked_joints", name), f"{value:g} {_UNITS[kind]} is beyond the joint's range "
                                                        f"[{lower:g}, {upper:g}] {_UNITS[kind]}")
        else:
            value = float(np.clip(0.0, lower, upper))
        positions[name] = value
    return positions


def lock_joints(plant, instance, positions: dict[str, float]) -> None:
    """Weld each joint of ``positions`` ({name: position [rad or m]}) of ``instance`` (not
    finalized) at its position, keeping its name: its actuator removed, the joint replaced by a
    WeldJoint between the same frames at the pose the joint had there. Drake removes a joint only
    from a plant without constraints: the caller removes the model's couplings (URDF ``<mimic>``)
    first (a coupling of held joints holds nothing)."""
    for name, value in positions.items():
        joint = plant.GetJointByName(name, instance)
        for index in plant.GetJointActuatorIndices():  # (by instance, Drake lists none before Finalize)
            if plant.get_joint_actuator(index).joint().index() == joint.index():
                plant.RemoveJointActuator(plant.get_joint_actuator(index))
        if isinstance(joint, RevoluteJoint):
            X_FM = RigidTransform(AngleAxis(value, joint.revolute_axis()), np.zeros(3))
        else:
            X_FM = RigidTransform(value * np.asarray(joint.translation_axis()))
        parent, child = joint.frame_on_parent(), joint.frame_on_child()
        try:
            plant.RemoveJoint(joint)
        except RuntimeError as error:
            raise _refusal(("locked_joints", name), f"Drake cannot remove the joint to hold it: {error}") from None
        plant.AddJoint(WeldJoint(name, parent, child, X_FM))
