"""The paper's task for the Pająk 2024 planner (:func:`paper_parameters`: its waypoints, gains and
limits on the UR10e, as a :class:`~.config.PajakConfig`), its start (:func:`paper_initial_configuration`)
and its method as printed (:data:`PAPER_METHOD`)."""

import numpy as np

from drake_traj.planners.pajak.config import PajakConfig
from drake_traj.robots import ur10e  # the paper's arm: its task, start and joint-move limits

__all__ = ["PAPER_METHOD", "paper_initial_configuration", "paper_parameters"]

# The improvement flags of PajakConfig switched off: the paper's method as printed, with the
# corrections of docs/papers.md (used for the Table 2 reproduction and to show what each improvement fixes).
PAPER_METHOD = dict(
    smooth_penalty=False,
    continuous_switching=False,
    bounded_scaling=False,
    damped_inverse=False,
    preserve_damping=False,
    continuous_orientation=False,
)


def paper_initial_configuration() -> np.ndarray:
    """q(0) of the paper's task: [-π/2, -π/2, -3π/4, -π/4, π/2, π/4] [rad] (the UR10e's home)."""
    return np.array(ur10e.HOME)


def paper_parameters(simulation: int = 3, **overrides) -> PajakConfig:
    """The paper's task and parameters for simulation 1 (no limits), 2 (velocity) or 3 (both).

    Waypoints p1, p2, p3, p_f with orientation (π, 0, 3π/4); Λ_P = 20, Λ_V = 9.392, ε = 1 mm,
    ϵ = 5 cm, ϑ = 0.1, limits 1.05 rad/s and 1.40 rad/s². ``overrides`` replace any field.
    """
    if simulation not in (1, 2, 3):
        raise ValueError(f"simulation must be 1, 2 or 3, got {simulation!r}")
    orientation = [np.pi, 0.0, 3 * np.pi / 4]
    positions = [
        [-0.175, -0.525, 0.730],  # p1
        [-0.175, -0.800, 0.730],  # p2
        [0.275, -0.800, 0.730],  # p3
        [0.275, -0.525, 0.730],  # p_f
    ]
    waypoints = np.array([p + orientation for p in positions])
    settings = dict(waypoints=waypoints, limit_velocity=simulation >= 2, limit_acceleration=simulation == 3,
                    velocity_limit=ur10e.DEFAULT_JOINT_MOVE_VELOCITY, acceleration_limit=ur10e.DEFAULT_JOINT_MOVE_ACCELERATION)
    settings.update(overrides)
    return PajakConfig(**settings)
