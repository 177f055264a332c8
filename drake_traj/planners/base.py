"""The planner contract (DESIGN.md) as a LeafSystem base class.

Every planner is a LeafSystem with

- continuous state x = [q; qd] (6 + 6): the joint reference being generated, integrated by the
  Simulator from the planner's acceleration;
- a discrete state group ``scaling`` = [c, t0, c0]: the scaling coefficient and the anchor of its
  relaxation (eq. 18 of seed 000), plus planner-specific discrete groups declared by subclasses;
- output ports ``desired_state`` [q; qd], ``desired_acceleration`` qdd and ``scaling`` c;
- an optional input port ``speed_override`` (a value in [0, 1]; unconnected means 1).

Subclasses implement :meth:`PlannerSystem.evaluate` (qdd and c from the context) and
:meth:`PlannerSystem.finished`, and declare their own update events. The evaluation is cached
per context, so the derivatives and the output ports at one context share a single call.
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import BasicVector, LeafSystem, ValueProducer

from drake_traj import robot


class PlannerSystem(LeafSystem):
    """Base of all planners: state layout, ports and the speed-override input.

    Args:
        q_initial: joint positions at t = 0 [rad], shape (6,); the reference starts at rest.
        initial_scaling: c at t = 0 (eq. 18 anchor c0 with t0 = 0).
    """

    def __init__(self, q_initial, *, initial_scaling: float = 1.0):
        super().__init__()
        n = robot.NUM_JOINTS
        q_initial = robot._as_joint_vector(q_initial, "q_initial")
        self.num_joints = n
        self._q_initial = q_initial
        self.DeclareContinuousState(BasicVector(np.concatenate([q_initial, np.zeros(n)])), n, n, 0)
        self.scaling_state_index = self.DeclareDiscreteState(
            np.array([initial_scaling, 0.0, initial_scaling])
        )
        self.speed_override_port = self.DeclareVectorInputPort("speed_override", 1)
        self.DeclareVectorOutputPort("desired_state", 2 * n, self._calc_desired_state)
        self.DeclareVectorOutputPort("desired_acceleration", n, self._calc_desired_acceleration)
        self.DeclareVectorOutputPort("scaling", 1, self._calc_scaling_output)
        self._evaluation = self.DeclareCacheEntry(
            "reference acceleration and scaling [qdd; c]",
            ValueProducer(allocate=AbstractValue.Make(BasicVector(n + 1)).Clone, calc=self._calc_evaluation),
            {self.all_sources_ticket()},
        )

    # --- to implement -------------------------------------------------------------------------
    def evaluate(self, context) -> tuple[np.ndarray, float]:
        """(qdd [rad/s^2], c) of the reference at the context's time and state."""
        raise NotImplementedError

    def finished(self, context) -> bool:
        """True once the planner's task is complete (used to stop the simulation)."""
        raise NotImplementedError

    def task_waypoints(self) -> np.ndarray:
        """TCP positions [m] the task passes through (base frame), shape (m, 3), for plots."""
        return np.zeros((0, 3))

    def initial_positions(self) -> np.ndarray:
        """q at t = 0 [rad]: where the robot starts."""
        return self._q_initial.copy()

    # --- shared ------------------------------------------------------------------------------
    def speed_override(self, context) -> float:
        """The speed override in [0, 1]; 1 when the input is not connected."""
        if not self.speed_override_port.HasValue(context):
            return 1.0
        value = float(self.speed_override_port.Eval(context)[0])
        if not np.isfinite(value) or not 0.0 <= value <= 1.0:
            raise ValueError(f"speed_override must be a finite value in [0, 1], got {value}")
        return value

    def reference_state(self, context) -> np.ndarray:
        """[q; qd] of the reference, shape (12,)."""
        return context.get_continuous_state_vector().CopyToVector()

    def acceleration(self, context) -> np.ndarray:
        """Reference joint acceleration qdd [rad/s^2] (cached :meth:`evaluate`)."""
        return self._evaluation.Eval(context).get_value()[: self.num_joints]

    def scaling(self, context) -> float:
        """The scaling coefficient c at the context's time (cached :meth:`evaluate`)."""
        return float(self._evaluation.Eval(context).get_value()[self.num_joints])

    def _calc_evaluation(self, context, value):
        acceleration, scaling = self.evaluate(context)
        value.get_mutable_value().SetFromVector(np.append(acceleration, scaling))

    def DoCalcTimeDerivatives(self, context, derivatives):
        qd = self.reference_state(context)[self.num_joints :]
        derivatives.get_mutable_vector().SetFromVector(np.concatenate([qd, self.acceleration(context)]))

    def _calc_desired_state(self, context, output):
        output.SetFromVector(self.reference_state(context))

    def _calc_desired_acceleration(self, context, output):
        output.SetFromVector(self.acceleration(context))

    def _calc_scaling_output(self, context, output):
        output.SetAtIndex(0, self.scaling(context))
