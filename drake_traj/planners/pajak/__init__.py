"""Pająk 2024: the acceleration-level task-space planner (see :mod:`.law` for the method).

Modules: :mod:`.config` (:class:`PajakConfig` and its ``validate``), :mod:`.parameters` (the
paper's task), :mod:`.kernel` (the law and its integrator, compiled), :mod:`.terms` (its
task-space terms: J⁻¹, a and b of eq. 17, the approach damping, σ of eq. 19, compiled),
:mod:`.limits` (its limit keeping: the choice of c and the braking, compiled), :mod:`.law` (the
law for Python callers), :mod:`.integration` (RK4 integration outside Drake) and :mod:`.system`
(the Drake system and ``make``). The robot is reached through
:meth:`~drake_traj.robots.Robot.task_kinematics` only.
"""

from drake_traj.errors import PlanningError
from drake_traj.planners.pajak.config import TASK_JOINTS, PajakConfig
from drake_traj.planners.pajak.integration import integrate
from drake_traj.planners.pajak.kernel import Discrete, Evaluation, Parameter, blended_target, velocity_penalty
from drake_traj.planners.pajak.law import DISCRETE_NAMES, PajakLaw
from drake_traj.planners.pajak.limits import choose_scaling, scaling_interval
from drake_traj.planners.pajak.parameters import PAPER_METHOD, paper_initial_configuration, paper_parameters
from drake_traj.planners.pajak.system import PajakPlanner, make
from drake_traj.planners.pajak.terms import (acceleration_terms, approach_damping, approach_rate, blend_progress,
                                             damping_factor)

__all__ = [
    "DISCRETE_NAMES", "Discrete", "Evaluation", "PAPER_METHOD", "Parameter", "PajakConfig", "PajakLaw",
    "PajakPlanner", "PlanningError", "TASK_JOINTS", "acceleration_terms", "approach_damping", "approach_rate",
    "blend_progress", "blended_target", "choose_scaling", "damping_factor", "integrate", "make", "paper_initial_configuration",
    "paper_parameters", "scaling_interval", "velocity_penalty",
]
