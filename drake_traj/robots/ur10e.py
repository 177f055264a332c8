"""UR10e: the e-Series arm of Pająk 2024 and of the shipped scenarios, its data and its closed
form as module-level names (the family's implementation is :mod:`drake_traj.robots.ur_eseries`,
its data :mod:`drake_traj.robots.ur_data`; data and checks: ``docs/ur10e.md``).

The functions here are :data:`UR10E`'s methods (:class:`~drake_traj.robots.ur_eseries.URArm`):
``dh_frames(q)``, ``task_pose(q, tool)``, ``inverse_kinematics(pose, ...)`` and so on.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from drake_traj.errors import SingularConfigurationError  # noqa: F401  (callers use robot.SingularConfigurationError)
from drake_traj.robots.base import FLANGE  # noqa: F401
from drake_traj.robots.task_space import (pose_error, rotation_from_zyx_euler, wrap_angle,  # noqa: F401
                                          zyx_euler_from_rotation)
from drake_traj.robots.ur_data import (BASE_FRAME, DEFAULT_JOINT_MOVE_ACCELERATION,  # noqa: F401
                                      DEFAULT_JOINT_MOVE_VELOCITY, DH_ALPHA, FLANGE_FRAME, HOME, JOINT_NAMES,
                                      NUM_JOINTS, UR10E_DATA)
from drake_traj.robots.ur_eseries import UR10E, UR10e
from drake_traj.robots.ur_ik import IK_BRANCHES  # noqa: F401

__all__ = ["UR10E", "UR10e"]

DH_D = np.array(UR10E_DATA.d)  # [m]
DH_A = np.array(UR10E_DATA.a)  # [m]
POSITION_LIMIT = np.array(UR10E_DATA.position_limit)  # [rad], symmetric
VELOCITY_LIMIT = np.array(UR10E_DATA.velocity_limit)  # [rad/s]
EFFORT_LIMIT = np.array(UR10E_DATA.effort_limit)  # [N m]
LINK_MASSES = np.array(UR10E_DATA.link_masses)  # [kg], links 1..6
BASE_MASS = UR10E_DATA.base_mass  # [kg], approximate; the base is welded to the world.
MODEL = UR10E.model  # [UR_CLOSED_FORM, d1, a2, a3, d4, d5, d6]

dh_frames = UR10E.dh_frames
flange_pose = UR10E.flange_pose
task_pose = UR10E.task_pose
geometric_jacobian = UR10E.geometric_jacobian
analytic_jacobian = UR10E.analytic_jacobian
analytic_jacobian_and_bias = UR10E.analytic_jacobian_and_bias
ur10e_kinematics = UR10E.kinematics
singularity_measure = UR10E.singularity_measure
singularity_factors = UR10E.singularity_factors
ik_branch = UR10E.ik_branch
inverse_kinematics_all = UR10E.inverse_kinematics_all
inverse_kinematics = UR10E.inverse_kinematics
inverse_kinematics_path = UR10E.inverse_kinematics_path


def model_path() -> Path:
    """Absolute path of the UR10e URDF shipped with the package (``models/ur10e.urdf``)."""
    return UR10E.model_path()
