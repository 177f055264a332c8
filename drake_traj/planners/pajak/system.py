"""The Pająk 2024 planner as a Drake system: a thin shell around :class:`PajakLaw`."""

from __future__ import annotations

import numpy as np

from drake_traj.errors import Cause, PlanningError
from drake_traj.planners.base import DEFAULT_PREFLIGHT_HORIZON, PlannerSystem
from drake_traj.planners.laws.hermite import quintic_hermite_coefficients
from drake_traj.planners.pajak.integration import integrate
from drake_traj.planners.pajak.kernel import Discrete
from drake_traj.planners.pajak.law import PajakLaw
from drake_traj.planners.pajak.parameters import PajakConfig
from drake_traj.robots import UR10E, Robot
from drake_traj.validation import finite_array, invalid, run_duration

__all__ = ["MAX_PREFLIGHT_STEPS", "PajakPlanner", "make"]

# The preflight's integration steps at most: its log holds Log.SIZE values a step (54: 432 MB at
# this bound; 600 s, the longest run, at the default 1 ms update period is 6e5 steps)
MAX_PREFLIGHT_STEPS = 1_000_000


class PajakPlanner(PlannerSystem):
    """Pająk 2024's planner as a LeafSystem: continuous [q; q̇], discrete ``scaling`` [c, t0, c0]
    and ``task`` (the rest of :class:`~.kernel.Discrete`), updated every ``update_period``.

    The acceleration (and c) are evaluated by :meth:`PajakLaw.acceleration` at every derivative
    call, so the acceleration limit holds at every integrator stage, not only at updates. A
    :class:`PlanningError` from the law ends the simulation; ``simulate`` keeps the log. The
    ``speed_override`` input, sampled at the updates, is the value c relaxes to instead of 1
    (eq. 18): c stays continuous and within the limits, and the task is still completed (at
    0 the feedback fades out and the arm coasts: an override for slowing, not for stopping).

    Args:
        parameters: the task and the law's settings.
        q_initial: joint positions at t = 0 [rad].
        robot: the robot, a 6-axis arm with task-space kinematics (:class:`PajakLaw`; default the
            UR10e); the planner's :attr:`robot`.
    """

    plans_online = True

    def __init__(self, parameters: PajakConfig, q_initial, *, robot: Robot = UR10E):
        self.law = PajakLaw(parameters, robot)
        self.robot = self.law.robot
        update_period = self.law.parameters.update_period
        initial = self.law.initial_discrete()
        super().__init__(finite_array(q_initial, "q_initial", "rad", shape=(robot.num_joints,)),
                         initial_scaling=float(initial[Discrete.C]))
        self.task_state_index = self.DeclareDiscreteState(initial[Discrete.C0 + 1:])
        self.velocity_limit = self.law.qd_max
        self.acceleration_limit = self.law.qdd_max
        self.DeclarePeriodicDiscreteUpdateEvent(update_period, 0.0, self._update)
        self._run = None  # the preflight's integration (:func:`integrate`), kept once it finished

    def _law_arguments(self, context):
        state = self.reference_state(context)
        discrete = np.concatenate([
            context.get_discrete_state(self.scaling_state_index).get_value(),
            context.get_discrete_state(self.task_state_index).get_value(),
        ])
        return context.get_time(), state[: self.num_joints], state[self.num_joints:], discrete

    def evaluate(self, context) -> tuple[np.ndarray, float]:
        return self.law.acceleration(*self._law_arguments(context))

    def finished(self, context) -> bool:
        _, q, qd, discrete = self._law_arguments(context)
        return self.law.finished(q, qd, discrete)

    def limit_conflicts(self, context) -> int:
        """Updates so far at which the limits overruled the law (q̈ clipped to the box, or the
        fallback braking; improvement 2)."""
        return int(context.get_discrete_state(self.task_state_index).get_value()[Discrete.SATURATED - Discrete.C0 - 1])

    def preflight(self, horizon: float = DEFAULT_PREFLIGHT_HORIZON) -> np.ndarray:
        """Run the whole task ahead of time (:func:`integrate`, the law alone) before t = 0, up
        to ``horizon`` [s] (a run's ``max_duration``; at most :data:`MAX_PREFLIGHT_STEPS` update
        periods).

        Raises the :class:`PlanningError` that the motion would end with: a waypoint out of
        reach (before integrating), a stall, gimbal lock, non-finite values or no finish within
        ``horizon`` (cause TIMEOUT), naming the time, the configuration and the cause (the stall
        message names the waypoint). A run that finishes has reached the whole pose (position
        within ε, orientation within ``orientation_accuracy``).

        The integration is kept once it finished (the law does not change): a second preflight
        and :meth:`plan` reuse it; one that failed is run again and raises again.

        Returns:
            The planned TCP path [m], (N, 3).
        """
        horizon = run_duration(horizon, "horizon")
        update_period = self.law.parameters.update_period
        if horizon / update_period > MAX_PREFLIGHT_STEPS:
            raise invalid("update_period", f"update_period = {update_period:g} s would take {horizon / update_period:.3g} "
                                           f"steps to look {horizon:g} s ahead (max_duration); at most "
                                           f"{MAX_PREFLIGHT_STEPS:.0e}: raise update_period or lower max_duration")
        if self._run is None:
            try:
                self._run = integrate(self.law, self.initial_positions(), dt=update_period, t_max=horizon)
            except PlanningError as error:
                if error.cause is not Cause.TIMEOUT:
                    raise
                raise PlanningError(f"the task did not finish within {horizon:g} s, the preflight's horizon (the run's "
                                    "max_duration)", time=error.time, configuration=error.configuration,
                                    cause=Cause.TIMEOUT, partial=error.partial) from None
        elif self._run["T"] > horizon:
            raise PlanningError(f"the task takes {self._run['T']:.3f} s, longer than {horizon:g} s, the preflight's "
                                "horizon (the run's max_duration)", cause=Cause.TIMEOUT)
        return self._run["tcp"][:, :3]

    def _plan_pieces(self) -> tuple[np.ndarray, np.ndarray]:
        """The preflight's samples (t, q, q̇, q̈) up to the finish, one every update period,
        joined by quintic Hermite pieces (:func:`quintic_hermite_coefficients`; q̈ the law's
        after each step's update on both sides of its sample). The preflight's own integration
        when one was run (with the run's horizon), else one with the default horizon."""
        if self._run is None:
            self.preflight()
        end = self._run["finish_index"] + 1
        times = self._run["t"][:end]
        samples = np.stack([self._run[name][:end] for name in ("q", "qd", "qdd")], axis=1)
        return times, quintic_hermite_coefficients(times, samples, samples)

    def goal_pose(self) -> np.ndarray:
        """p_f, the last waypoint [m, rad]."""
        return self.law.waypoints[-1].copy()

    def task_waypoints(self) -> np.ndarray:
        return self.law.tcp_positions()

    def waypoint_neighbourhood(self) -> float:
        """ϵ [m] when the planner blends its waypoints (eq. 19), else NaN (it stops at each)."""
        parameters = self.law.parameters
        return float(parameters.neighbourhood) if parameters.blend_waypoints else float("nan")

    def _update(self, context, discrete_state):
        t, q, qd, discrete = self._law_arguments(context)
        updated = self.law.update(t, q, qd, discrete, self.speed_override(context))
        discrete_state.get_mutable_vector(self.scaling_state_index).SetFromVector(updated[: Discrete.C0 + 1])
        discrete_state.get_mutable_vector(self.task_state_index).SetFromVector(updated[Discrete.C0 + 1:])
        if self.law.finished(q, qd, updated):
            self._record_finish(discrete_state.get_mutable_vector(self.finish_state_index), t)


def make(config: PajakConfig, robot: Robot, q_initial) -> PajakPlanner:
    """The planner of ``config`` on ``robot`` (a 6-axis arm with the task kinematics the compiled
    law is bound to, :class:`PajakLaw`), starting at rest at ``q_initial`` [rad]."""
    return PajakPlanner(config, q_initial, robot=robot)
