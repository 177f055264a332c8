"""Pająk 2024: the acceleration-level task-space planner (see :mod:`.law` for the method).

Modules: :mod:`.parameters` (the config and the paper's task), :mod:`.law` (the planning law as
plain numpy), :mod:`.integration` (RK4 integration outside Drake) and :mod:`.system` (the Drake
system and ``make``).
"""

from drake_traj.errors import PlanningError
from drake_traj.planners.pajak.integration import integrate, integrate_many
from drake_traj.planners.pajak.law import (
    DISCRETE_NAMES,
    DISCRETE_SIZE,
    PajakLaw,
    acceleration_terms,
    approach_damping,
    blend_progress,
    blended_target,
    choose_scaling,
    damping_factor,
    scaling_interval,
    velocity_penalty,
)
from drake_traj.planners.pajak.parameters import PAPER_METHOD, PajakConfig, paper_initial_configuration, paper_parameters
from drake_traj.planners.pajak.system import PajakPlanner, make

__all__ = [
    "DISCRETE_NAMES", "DISCRETE_SIZE", "PAPER_METHOD", "PajakConfig", "PajakLaw", "PajakPlanner", "PlanningError",
    "acceleration_terms", "approach_damping", "blend_progress", "blended_target", "choose_scaling", "damping_factor",
    "integrate", "integrate_many", "make", "paper_initial_configuration", "paper_parameters", "scaling_interval",
    "velocity_penalty",
]
