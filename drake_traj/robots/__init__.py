"""Robots under one contract (:class:`Robot`): the UR e-Series arms (UR3e, UR5e, UR10e, UR16e,
UR20, UR30), the three example robots of Boryga and the 4-DOF robot of Li et al. 2019.
``get_robot(name)`` returns one by its scenario name."""

from drake_traj.errors import did_you_mean
from drake_traj.robots.base import PointRobot, Robot
from drake_traj.robots.boryga_robots import AnthropomorphicArm, CartesianRobot, ScaraArm
from drake_traj.robots.li_4dof import LI_4DOF, Li4Dof
from drake_traj.robots.inertia_estimate import estimated_torque_note
from drake_traj.robots.model_setup import setup_note
from drake_traj.robots.self_contact import (SelfContact, UncheckedPair, exclude_self_contact, self_contact,
                                            srdf_hint, touching_shapes)
from drake_traj.robots.ur10e import UR10E, UR10e
from drake_traj.robots.ur_eseries import UR_ARMS, URArm

__all__ = [
    "ROBOT_NAMES", "AnthropomorphicArm", "CartesianRobot", "LI_4DOF", "Li4Dof", "PointRobot", "Robot", "ScaraArm",
    "UR10E", "UR10e", "UR_ARMS", "URArm", "get_robot", "SelfContact", "UncheckedPair", "exclude_self_contact",
    "self_contact", "srdf_hint", "touching_shapes", "setup_note", "estimated_torque_note",
]

_ROBOTS = {robot.name: robot for robot in (UR10E, *(arm for arm in UR_ARMS if arm is not UR10E), LI_4DOF,
                                           AnthropomorphicArm(), ScaraArm(), CartesianRobot())}
ROBOT_NAMES = tuple(_ROBOTS)


def get_robot(name: str) -> Robot:
    """The robot called ``name`` (one of :data:`ROBOT_NAMES`); a ValueError listing the known
    robots with their reach and rated payload for any other name (and the names closest to it)."""
    try:
        return _ROBOTS[name]
    except (KeyError, TypeError):
        known = "; ".join(f"{robot.name} ({_ratings(robot)})" for robot in _ROBOTS.values())
        hint = did_you_mean(name, _ROBOTS)
        raise ValueError(f"robot must be one of the known robots, got {name!r:.80}; known: {known}"
                         f"{f'; {hint}' if hint else ''}") from None


def _ratings(robot: Robot) -> str:
    reach = "reach not given" if robot.reach is None else f"reach {robot.reach:g} m"
    payload = "no rated payload" if robot.rated_payload is None else f"payload {robot.rated_payload:g} kg"
    return f"{robot.num_joints} joints, {reach}, {payload}"
