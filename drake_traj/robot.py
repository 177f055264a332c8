"""UR10e: model file, published limits and analytic kinematics.

Frames follow ``ur10e_facts.md`` and seed 000 (Pająk 2024): the base frame is standard-DH frame 0
(UR's controller "Base" frame), the flange ``tool0`` is DH frame 6. The task-space pose is
p = k(q) = [x, y, z, phi_X, phi_Y, phi_Z]: flange position in metres and Z-Y-X Euler angles in
radians (R = Rz(phi_Z) Ry(phi_Y) Rx(phi_X)), as used by UR's software and by seed 000.

Everything here is plain numpy so tests and planners can call it without building a plant; the
tests check it against Drake's MultibodyPlant.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import numpy as np

NUM_JOINTS = 6

# Standard DH parameters (ur10e_facts.md; seed 000 Table 1 is the same chain in modified DH).
DH_D = np.array([0.1807, 0.0, 0.0, 0.17415, 0.11985, 0.11655])  # [m]
DH_A = np.array([0.0, -0.6127, -0.57155, 0.0, 0.0, 0.0])  # [m]
DH_ALPHA = np.array([np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0])  # [rad]

JOINT_NAMES = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
POSITION_LIMIT = np.full(NUM_JOINTS, 2 * np.pi)  # [rad], symmetric
VELOCITY_LIMIT = np.array([2.094, 2.094, 3.1416, 3.1416, 3.1416, 3.1416])  # [rad/s]
EFFORT_LIMIT = np.array([330.0, 330.0, 150.0, 56.0, 56.0, 56.0])  # [N m]
# UR controller defaults for joint moves, used by seed 000 for every joint.
DEFAULT_JOINT_MOVE_VELOCITY = 1.05  # [rad/s] (60 deg/s)
DEFAULT_JOINT_MOVE_ACCELERATION = 1.40  # [rad/s^2] (80 deg/s^2)

LINK_MASSES = np.array([7.369, 13.051, 3.989, 2.1, 1.98, 0.615])  # [kg], links 1..6
BASE_MASS = 4.0  # [kg], approximate; the base is welded to the world.
FLANGE_FRAME = "tool0"
BASE_FRAME = "base"


def model_path() -> Path:
    """Absolute path of the UR10e URDF shipped with the package (``models/ur10e.urdf``)."""
    path = Path(str(resources.files("drake_traj.models").joinpath("ur10e.urdf")))
    if not path.is_file():
        raise ValueError(f"UR10e model file not found: {path}")
    return path


def _as_joint_vector(q, name: str = "q") -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.shape != (NUM_JOINTS,):
        raise ValueError(f"{name} must have shape ({NUM_JOINTS},), got {q.shape}")
    if not np.all(np.isfinite(q)):
        raise ValueError(f"{name} must be finite, got {q}")
    return q


def dh_frames(q) -> np.ndarray:
    """Poses of DH frames 0..6 in the base frame, shape (7, 4, 4); frame 6 is the flange.

    T_{i-1,i} = Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i) (standard DH).
    """
    q = _as_joint_vector(q)
    frames = np.empty((NUM_JOINTS + 1, 4, 4))
    frames[0] = np.eye(4)
    for i in range(NUM_JOINTS):
        ct, st = np.cos(q[i]), np.sin(q[i])
        ca, sa = np.cos(DH_ALPHA[i]), np.sin(DH_ALPHA[i])
        link = np.array(
            [
                [ct, -st * ca, st * sa, DH_A[i] * ct],
                [st, ct * ca, -ct * sa, DH_A[i] * st],
                [0.0, sa, ca, DH_D[i]],
                [0.0, 0.0, 0.0, 1.0],
            ]
        )
        frames[i + 1] = frames[i] @ link
    return frames


def flange_pose(q) -> np.ndarray:
    """Homogeneous transform of the flange (DH frame 6, ``tool0``) in the base frame, (4, 4)."""
    return dh_frames(q)[-1]
