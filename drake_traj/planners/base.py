"""The planner contract (docs/design.md) as a LeafSystem base class.

Every planner is a LeafSystem with

- continuous state x = [q; qd] (6 + 6): the joint reference being generated, integrated by the
  Simulator from the planner's acceleration;
- a discrete state group ``scaling`` = [c, t0, c0]: the scaling coefficient and the anchor of its
  relaxation (eq. 18 of Pająk 2024), a group ``finish`` = [the time the task finished, NaN
  before] that subclasses record from their own update events, plus planner-specific discrete
  groups declared by subclasses;
- output ports ``desired_state`` [q; qd] (the continuous state; a :class:`TimeLawPlanner`'s qd
  is its law's), ``desired_acceleration`` qdd, ``scaling`` c,
  ``acceleration_and_scaling`` [qdd; c] and ``reference_and_scaling`` [q; qd; qdd; c] (all from
  one Python call per evaluation: the station splits the last with a C++ ``Demultiplexer`` for
  the plant and the loggers);
- an optional input port ``speed_override`` (a value in [0, 1]; unconnected means 1).

At the simulator's initialization a planner in a station checks that its plan was accepted by
the cell check in that station's scene (``guard``, :mod:`drake_traj.cell.guard`): an unchecked plan is
checked there, and refused before the motion where it would collide.

Subclasses implement :meth:`PlannerSystem.evaluate` (qdd and c from the context) and
:meth:`PlannerSystem.finished`, and declare their own update events. The evaluation is cached
per context, so the derivatives and the output ports at one context share a single call.
:class:`TimeLawPlanner` (a law on a scaled clock) keeps its own, cheaper evaluation: its
subclasses provide the law, not ``evaluate``.
"""

from __future__ import annotations

from bisect import bisect_right
from typing import NamedTuple

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.polynomial import Polynomial
from pydrake.systems.framework import BasicVector, ContinuousStateIndex, EventStatus, LeafSystem, ValueProducer
from pydrake.trajectories import PiecewisePolynomial

from drake_traj.errors import Cause, PlanningError
from drake_traj.planners.laws.contract import MEMBERS, missing_members
from drake_traj.planners.laws.pieces import law_pieces
from drake_traj.planners.laws.scaling import admissible_clock_rate, clock_at, next_clock_rate
from drake_traj.robots import Robot
from drake_traj.validation import finite_array, instance_of, invalid, limit_or_default, run_duration

_DID_NOTHING = EventStatus.DidNothing()  # returned by the time-law update in the common case
# [s] how far ahead :meth:`PlannerSystem.preflight` looks when not told: a run's default max_duration
DEFAULT_PREFLIGHT_HORIZON = 120.0


def piecewise_trajectory(breaks, coefficients) -> PiecewisePolynomial:
    """Drake's PiecewisePolynomial of polynomial pieces: q(t) = sum_j coefficients[k, j]
    (t - breaks[k])^j on [breaks[k], breaks[k + 1]] (breaks [s] (K + 1,), coefficients (K, P, n)),
    an n x 1 column per time."""
    coefficients = np.asarray(coefficients, dtype=float)
    count, size, rows = coefficients.shape
    polynomials = np.empty(count * rows, dtype=object)  # each piece's column, one object array for all
    polynomials[:] = [Polynomial(c) for c in coefficients.transpose(0, 2, 1).reshape(-1, size)]
    return PiecewisePolynomial(list(polynomials.reshape(count, rows, 1)), np.asarray(breaks, dtype=float).tolist())


class PlannerSystem(LeafSystem):
    """Base of all planners: state layout, ports and the speed-override input.

    ``plans_online`` is True for planners that compute the motion as it runs (their
    :meth:`preflight` integrates it ahead of time), False for those that plan it when made.

    Args:
        q_initial: joint positions at t = 0 [rad or m], shape (n,); the reference starts at rest.
        initial_scaling: c at t = 0 (eq. 18 anchor c0 with t0 = 0).
    """

    plans_online = False
    planning_time_s = float("nan")  # [s] a planner's own planning before the run, where it measures one
    robot: Robot | None = None  # the robot the planner was made for, where it knows one (a station runs it there)

    def __init__(self, q_initial, *, initial_scaling: float = 1.0):
        super().__init__()
        q_initial = finite_array(q_initial, "q_initial", "rad or m")
        if q_initial.ndim != 1 or not len(q_initial):
            raise ValueError(f"q_initial must be a non-empty vector of joint positions, got shape {q_initial.shape}")
        n = len(q_initial)
        self.num_joints = n
        self._q_initial = q_initial
        self._plan = None  # the PiecewisePolynomial of plan(), made at the first call
        # fingerprints of the collision scenes in which the cell check accepted plan()
        # (CellChecker.check_planner), and the station's guard (drake_traj.cell.guard.MotionGuard, set
        # by add_station): the motion starts only where the guard finds its scene checked
        self.checked_scenes: set[str] = set()
        self.guard = None
        self.DeclareInitializationPublishEvent(self._before_motion)
        self.DeclareContinuousState(BasicVector(np.concatenate([q_initial, np.zeros(n)])), n, n, 0)
        self.scaling_state_index = self.DeclareDiscreteState(
            np.array([initial_scaling, 0.0, initial_scaling])
        )
        self.finish_state_index = self.DeclareDiscreteState(np.array([np.nan]))
        self.speed_override_port = self.DeclareVectorInputPort("speed_override", 1)
        self._declare_desired_state()
        self.DeclareVectorOutputPort("desired_acceleration", n, self._calc_desired_acceleration)
        self.DeclareVectorOutputPort("scaling", 1, self._calc_scaling_output)
        self.DeclareVectorOutputPort("acceleration_and_scaling", n + 1, self._calc_acceleration_and_scaling)
        self.DeclareVectorOutputPort("reference_and_scaling", 3 * n + 1, self._calc_reference_and_scaling)
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

    def figures(self) -> dict:
        """Planner-specific figures {file stem: matplotlib Figure} (e.g. the paper's path plots)."""
        return {}

    def initial_positions(self) -> np.ndarray:
        """q at t = 0 [rad]: where the robot starts."""
        return self._q_initial.copy()

    def preflight(self, horizon: float = DEFAULT_PREFLIGHT_HORIZON) -> np.ndarray | None:
        """Check the whole task before t = 0; raise :class:`~drake_traj.errors.PlanningError` if
        it cannot be completed within ``horizon`` [s] (a run's ``max_duration``, at most
        :data:`~drake_traj.validation.MAX_RUN_DURATION`; a task that takes longer fails with
        cause TIMEOUT). Planners that plan the whole motion when they are made have nothing left
        to check (this default); online planners run their law ahead of time, up to ``horizon``.

        Returns:
            The planned tool path [m], shape (N, 3) in the base frame, where the check computes
            it (for drawing before the motion), else None.
        """
        run_duration(horizon, "horizon")
        return None

    def planned_duration(self) -> float:
        """How long the motion is planned to take [s] (NaN where it is not known before the run)."""
        return float("nan")

    def plan(self) -> PiecewisePolynomial:
        """The planned reference before the run: q(t) [rad, m for prismatic joints], n x 1, for t
        in [0, T] [s] of simulation time from the start of the run, T the planned finish, at speed
        override 1 (the ``speed_override`` input not connected). Its derivatives are q̇ [rad/s] and
        q̈ [rad/s²], with q̈'s jumps where the law's are.

        Time-law planners: the law's own polynomials on its scaled clock (exact to round-off;
        measured against the law's ``sample`` at 2 000 random times: below 1e-14 rad, 1e-14 rad/s,
        1e-13 rad/s² on the shipped time-law scenarios). Pająk: the preflight's RK4 samples every step
        (``update_period``) joined by quintic Hermite pieces through (q, q̇, q̈), q̈ the law's
        after each step's update (between samples its q̈ is within 7.2e-7 rad/s² of the law's
        evaluated on the plan, pajak_sim3 mid-step), slowed by a constant clock rate where the
        pieces would pass the joint limits between the samples. Against the simulated reference (fixed-step RK2, 1 ms) see
        ``tests/test_plan.py``: the difference there is the simulator's integration error.

        Made at the first call and kept (the law does not change); each call returns a copy. Use
        it in a diagram of your own as ``TrajectorySource(planner.plan())`` (docs/drake-api.md).

        Raises:
            PlanningError: the task cannot be planned ahead: what :meth:`preflight` raises (Pająk:
                an unreachable waypoint, a stall, ...), or a motion of 0 s.
        """
        if self._plan is None:
            self._plan = piecewise_trajectory(*self._plan_pieces())
        return self._plan.Clone()

    def _plan_pieces(self) -> tuple[np.ndarray, np.ndarray]:
        """(breaks [s] (K + 1,) from 0 to the planned finish, coefficients (K, P, n)) of
        :meth:`plan` (:func:`piecewise_trajectory`)."""
        raise NotImplementedError

    def goal_pose(self) -> np.ndarray | None:
        """The tool pose the task ends at, [x, y, z, phi_X, phi_Y, phi_Z] [m, rad], where the task
        is given in task space; None where it is given in joint space."""
        return None

    def waypoint_neighbourhood(self) -> float:
        """The radius [m] of the ball around each waypoint but the last inside which the planner
        turns to the next one (Pająk 2024's ϵ, eq. 19); NaN for planners that pass through their
        waypoints or stop at them (this default)."""
        return float("nan")

    # --- shared ------------------------------------------------------------------------------
    def _before_motion(self, context) -> EventStatus:
        """At the simulator's initialization: the station's guard refuses a plan that was not
        checked in the station's scene (checking it there first; drake_traj.cell.guard), whatever
        started the simulation (run_station or one's own Simulator)."""
        if self.guard is not None:
            self.guard.ensure_checked(self, DEFAULT_PREFLIGHT_HORIZON)
        return EventStatus.Succeeded()

    def finish_time(self, context) -> float:
        """When the task finished [s], as recorded by the planner's update events; NaN before."""
        return float(context.get_discrete_state(self.finish_state_index).get_value()[0])

    def _record_finish(self, finish_state, time: float) -> None:
        """Set the ``finish`` group (a mutable BasicVector of the updated state) to ``time`` [s]
        unless a finish is already recorded there."""
        if np.isnan(finish_state.GetAtIndex(0)):
            finish_state.SetAtIndex(0, time)

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

    def _declare_desired_state(self) -> None:
        """The ``desired_state`` output port: the continuous state [q; q̇] (a state output port, no
        Python call)."""
        self.DeclareStateOutputPort("desired_state", ContinuousStateIndex(0))

    def _calc_evaluation(self, context, value):
        acceleration, scaling = self.evaluate(context)
        vector = value.get_mutable_value()
        vector.SetFromVector(np.concatenate((acceleration, (scaling,))))

    def DoCalcTimeDerivatives(self, context, derivatives):
        qd = self.reference_state(context)[self.num_joints :]
        derivatives.get_mutable_vector().SetFromVector(np.concatenate([qd, self.acceleration(context)]))

    def _calc_desired_acceleration(self, context, output):
        output.SetFromVector(self.acceleration(context))

    def _calc_scaling_output(self, context, output):
        output.SetAtIndex(0, self.scaling(context))

    def _calc_acceleration_and_scaling(self, context, output):
        output.SetFromVector(self._evaluation.Eval(context).get_value())

    def _calc_reference_and_scaling(self, context, output):
        output.SetFromVector(np.concatenate((self.reference_state(context), self._evaluation.Eval(context).get_value())))


class _Rates(NamedTuple):
    """A time-law planner's rates at one instant (views of one read-only array)."""

    derivatives: np.ndarray  # d/dt [q; q̇] = [q_law'(tau) c; q̈], (2n,)
    velocity: np.ndarray  # q̇ = q_law'(tau) c [rad/s], (n,): the reference's (``desired_state``)
    velocity_acceleration_and_scaling: np.ndarray  # [q̇; q̈; c], (2n + 1,): all of the values
    acceleration: np.ndarray  # q̈ = q_law'' c² + q_law' ċ [rad/s²], (n,)
    acceleration_and_scaling: np.ndarray  # [q̈; c], (n + 1,)
    scaling: float  # c


class TimeLawPlanner(PlannerSystem):
    """A planner that follows a closed-form joint time law on a scaled planner clock.

    ``law`` is a :class:`~drake_traj.planners.laws.TimeLaw` (checked when the planner is made: a
    TypeError names what is missing): ``q_start``, ``duration``, ``acceleration_jumps``,
    ``rates_at(tau)`` (the hot path) and ``sample(tau)``. The clock tau advances at the rate c:
    with c = 1 the reference is the law itself, qd = q_law'(tau) c and
    qdd = q_law''(tau) c² + q_law'(tau) ċ. c starts at ``speed_cap`` (a law that breaks the limits
    by a factor is slowed into them with ``speed_cap`` < 1: velocity scales by c, acceleration by
    c²) and relaxes towards ``speed_cap`` times the
    ``speed_override`` input in the form of eq. 18 of Pająk 2024 (at ``scaling_rate``; a speed
    slider's response, faster than the paper's 1/s), with ċ held over each ``update_period`` and
    changed by at most ``clock_jerk`` × period, so q̈ stays continuous (see
    :mod:`drake_traj.planners.laws.scaling`), and never faster than the joint acceleration limits
    allow at that point of the law (checked at both ends of the period).

    The Simulator integrates the state [q; qd] from the law's rates, q' = q_law'(tau) c and
    qd' = qdd (so q follows the law's own velocity, not the integrated one). Where the law's
    acceleration jumps (its ``acceleration_jumps``, law times; None: anywhere), a fixed step
    integrates the jump with an error that would stay: the update after it sets the reference
    back on the law, (q_law(tau), q_law'(tau) c), as does every update that changes the clock,
    and the one that records the exact finish time (so the motion ends exactly at the law's end). While c is at its goal and nothing jumps, the update changes
    nothing. The rates depend on the time and the clock only, and the last ones are kept by that
    key (:meth:`_rates`): the derivatives, the outputs and the update of one step share one law
    evaluation.

    The ``desired_state`` output (and :meth:`reference_state`) is [q; q_law'(tau) c]: q the
    integrated state, q̇ the law's own velocity on the clock (the one q integrates), not the
    integrated q̇. A logger samples the output at the end of an integrator step, before the
    update at that time (Drake publishes before it updates), so an integrated q̇ would carry the
    step's error into the log and the plant: up to h |Δq̈| / 2 after a jump of q̈ (MoveJ's ramps),
    h²/8 per jump of the jerk (Ruckig's phases), past the velocity limit where the law runs at
    it. The law's q̇ keeps the limits the planner promises at every sample, as q̈ (the law's) does.

    The ``scaling`` output is c, or c_law(tau) × c for a law with a scaling of its own
    (``law.scaling_at(tau)``, the Pająk plan's coefficient of eq. 17-18).

    Discrete state: ``clock`` = [tau, ċ, c, t0]: the law time, the clock's rate and c at the last
    update t0 (the clock's truth); ``scaling`` = [c, t0, c] (the contract's view of the same
    clock) and ``finish``.

    Args:
        law: the time law (see above).
        velocity_limit, acceleration_limit: the limits the reference promises, per joint.
        speed_cap: the largest clock rate c, in (0, 1].
        update_period: the period of the update (speed override, clock, reference on the law,
            finish) [s].
        scaling_rate: the rate of the eq. 18 relaxation towards the override [1/s]: 4 /s follows a
            step of the override with a time constant of 0.25 s.
        clock_jerk: the largest change of ċ per second [1/s²]: a step of the override changes q̈
            by at most clock_jerk × update_period × |q_law'| per period (0.02 rad/s² per 1 ms at
            1 rad/s with the default 20 /s²).
    """

    def __init__(self, law, velocity_limit, acceleration_limit, *, speed_cap: float = 1.0, update_period: float = 0.001,
                 scaling_rate: float = 4.0, clock_jerk: float = 20.0):
        if type(self).evaluate is not TimeLawPlanner.evaluate:  # the hot path never calls it
            raise TypeError(f"{type(self).__name__} overrides evaluate, which a TimeLawPlanner does not use (its "
                            "rates come from the law): change the law, or derive from PlannerSystem")
        missing = missing_members(law)
        if missing:
            raise TypeError(f"law must be a TimeLaw (drake_traj.planners.laws.TimeLaw: {', '.join(MEMBERS)}); "
                            f"a {type(law).__name__} has no {', '.join(missing)}")
        if not np.isfinite(speed_cap) or not 0.0 < speed_cap <= 1.0:
            raise ValueError(f"speed_cap must be in (0, 1], got {speed_cap}")
        for name, value in (("update_period", update_period), ("scaling_rate", scaling_rate), ("clock_jerk", clock_jerk)):
            if not np.isfinite(value) or value <= 0:
                raise invalid(name, f"{name} must be a positive number, got {value}")
        super().__init__(law.q_start, initial_scaling=speed_cap)
        self.law = law
        self.speed_cap = float(speed_cap)
        self.update_period = float(update_period)
        self.scaling_rate = float(scaling_rate)
        self.clock_jerk = float(clock_jerk)
        self.velocity_limit = np.asarray(velocity_limit, dtype=float)
        self.acceleration_limit = np.asarray(acceleration_limit, dtype=float)
        self.clock_state_index = self.DeclareDiscreteState(np.array([0.0, 0.0, self.speed_cap, 0.0]))
        self.DeclarePeriodicUnrestrictedUpdateEvent(update_period, 0.0, self._update)
        self._kept = (None, None)  # (key, _Rates) of _rates: see there why not a cache entry
        # a law with a scaling of its own (the Pająk plan's c, eq. 17-18) reports c_law(tau) × c
        self._law_scaling = getattr(law, "scaling_at", None)
        self._law_finish = getattr(law, "finish_time", None)  # the task's end, before the law's (its settling)
        jumps = law.acceleration_jumps  # law times where q_law'' jumps (None: anywhere)
        self._acceleration_jumps = None if jumps is None else sorted(np.asarray(jumps, dtype=float).tolist())

    def _clock_state(self, context) -> list[float]:
        """[tau0 [s], ċ [1/s], c0, t0 [s]]: the clock at the last update (one read of the state)."""
        return context.get_discrete_state(self.clock_state_index).get_value().tolist()

    def _clock(self, context):
        """(tau [s], c, ċ [1/s]) at the context's time."""
        tau0, c_rate, c0, t0 = self._clock_state(context)
        tau, c = clock_at(context.get_time() - t0, tau0, c0, c_rate)
        return tau, c, c_rate

    def _rates(self, context) -> _Rates:
        """The law's rates at the context's time (:class:`_Rates`).

        They depend on the time and the clock state only, so the last ones are kept by that key.
        Per step Drake asks at t (first RK2 stage), at t + h (second stage) and for the output at
        t + h at the step's end: 1.1 law evaluations per step on average (counted on Li 4-DOF).
        The arrays are read-only views of one (shared by every caller with that key).

        Kept on the instance, not in a Drake cache entry: the value is a function of the key alone
        (the law does not change), so contexts with the same key may share it. Two cache-entry
        versions were tried (2026-11-25, not kept in the repository) and both cost more, planner
        alone under RK2 at 1 ms, µs per step, quintic_ptp / Li 4-DOF: this memo 64 / 68; a cache
        entry on time and the clock state 111 / 99 (Drake invalidates it at every SetTime: 3.2 law
        evaluations per step instead of 1.1); a per-context entry holding this memo 88 / 93 (its
        Eval from Python). Station / floor with examples/bench_planner_cost.py: this memo 0.45 /
        0.44, the cache entry on time and clock 0.33 / 0.26."""
        key = (context.get_time(), *self._clock_state(context))
        if key != self._kept[0]:
            t, tau0, c_rate, c0, t0 = key
            tau, c = clock_at(t - t0, tau0, c0, c_rate)
            qd_law, qdd_law = self.law.rates_at(tau)
            scaling = c if self._law_scaling is None else c * self._law_scaling(tau)
            values = np.concatenate((qd_law * c, qdd_law * c**2 + qd_law * c_rate, (scaling,)))
            values.flags.writeable = False
            n = self.num_joints
            self._kept = (key, _Rates(values[: 2 * n], values[:n], values, values[n : 2 * n], values[n:], scaling))
        return self._kept[1]

    def _declare_desired_state(self) -> None:
        """``desired_state`` [q; q_law'(tau) c]: q the integrated state, q̇ the law's (class docstring)."""
        self.DeclareVectorOutputPort("desired_state", 2 * self.num_joints, self._calc_desired_state)

    def _integrated_positions(self, context) -> np.ndarray:
        """q [rad] of the continuous state, (n,)."""
        return context.get_continuous_state_vector().CopyToVector()[: self.num_joints]

    def reference_state(self, context) -> np.ndarray:
        """[q [rad]; q̇ [rad/s]] of the reference, shape (2n,): the integrated q and the law's
        q̇ = q_law'(tau) c (the ``desired_state`` output)."""
        return np.concatenate((self._integrated_positions(context), self._rates(context).velocity))

    def _calc_desired_state(self, context, output):
        output.SetFromVector(self.reference_state(context))

    def evaluate(self, context) -> tuple[np.ndarray, float]:
        rates = self._rates(context)
        return rates.acceleration, rates.scaling

    def acceleration(self, context) -> np.ndarray:
        return self._rates(context).acceleration

    def scaling(self, context) -> float:
        return self._rates(context).scaling

    def DoCalcTimeDerivatives(self, context, derivatives):
        derivatives.SetFromVector(self._rates(context).derivatives)

    def _calc_desired_acceleration(self, context, output):
        output.SetFromVector(self._rates(context).acceleration)

    def _calc_scaling_output(self, context, output):
        output.SetAtIndex(0, self._rates(context).scaling)

    def _calc_acceleration_and_scaling(self, context, output):
        output.SetFromVector(self._rates(context).acceleration_and_scaling)

    def _calc_reference_and_scaling(self, context, output):
        rates = self._rates(context).velocity_acceleration_and_scaling
        output.SetFromVector(np.concatenate((self._integrated_positions(context), rates)))

    def finished(self, context) -> bool:
        return self._clock(context)[0] >= self._finish_tau()

    def planned_duration(self) -> float:
        """The motion's duration at the speed cap, without override [s]."""
        return self._finish_tau() / self.speed_cap

    def _finish_tau(self) -> float:
        """The law time [s] at which the task is complete: the law's ``duration``, or its
        ``finish`` where it has one (a law that settles after its task is done, Pająk's)."""
        return self.law.duration if self._law_finish is None else self._law_finish()

    def _plan_pieces(self) -> tuple[np.ndarray, np.ndarray]:
        """The law's pieces on the clock at the speed cap (c starts there and stays without an
        override): :func:`~drake_traj.planners.laws.pieces.law_pieces`."""
        if not self.law.duration > 0.0:
            raise PlanningError(f"the motion lasts {self.law.duration} s (every goal equals the start): there is no "
                                "trajectory to plan", cause=Cause.PLANNING)
        return law_pieces(self.law, self.speed_cap)

    def _next_clock_rate(self, tau: float, c: float, c_rate: float, goal: float) -> float:
        """ċ for the next period (:func:`next_clock_rate`), within the acceleration limits at
        both ends of the period where they allow it."""
        h = self.update_period
        candidate = next_clock_rate(c, c_rate, goal, rate=self.scaling_rate, jerk=self.clock_jerk, period=h,
                                    cap=self.speed_cap)
        low, high = admissible_clock_rate(c, *self.law.rates_at(tau), self.acceleration_limit)
        tau_end, c_end = clock_at(h, tau, c, candidate)
        low_end, high_end = admissible_clock_rate(c_end, *self.law.rates_at(tau_end), self.acceleration_limit)
        return min(max(candidate, max(low, low_end)), min(high, high_end))  # both intervals contain 0

    def _jumped(self, tau: float, tau_before: float) -> bool:
        """True where the law's acceleration jumps in (tau_before, tau] (anywhere for a law that
        does not say)."""
        jumps = self._acceleration_jumps
        return jumps is None or bisect_right(jumps, tau) > bisect_right(jumps, tau_before)

    def _update(self, context, state):
        t, h = context.get_time(), self.update_period
        tau0, c_rate, c0, t0 = self._clock_state(context)
        tau, c = clock_at(t - t0, tau0, c0, c_rate)
        goal = self.speed_cap * self.speed_override(context)
        steady = c_rate == 0.0 and c == goal
        jumped = self._jumped(tau, clock_at(max(t - h, t0) - t0, tau0, c0, c_rate)[0])
        finish = self._finish_tau()
        if steady and not jumped and tau < finish:
            return _DID_NOTHING  # the clock runs on as it is: nothing to write (the common case)
        finishing = tau >= finish and np.isnan(self.finish_time(context))
        if steady and not (jumped or finishing):
            return _DID_NOTHING
        discrete = state.get_mutable_discrete_state()
        if finishing:  # finished in (t0, t]: tau0 + c0 s + ċ s² / 2 = finish
            roots = np.roots([0.5 * c_rate, c0, tau0 - finish]) if c_rate else [(finish - tau0) / c0]
            s = min(float(np.real(r)) for r in np.atleast_1d(roots) if abs(np.imag(r)) < 1e-12 and np.real(r) >= -1e-12)
            self._record_finish(discrete.get_mutable_vector(self.finish_state_index), t0 + max(s, 0.0))
        if abs(goal - c) <= 1e-9 and abs(c_rate) <= self.clock_jerk * h:
            c, c_rate = goal, 0.0  # arrived: hold c exactly (a step of q̈ below one period's change)
        else:
            c_rate = self._next_clock_rate(tau, c, c_rate, goal)
        discrete.get_mutable_vector(self.scaling_state_index).SetFromVector([c, t, c])
        discrete.get_mutable_vector(self.clock_state_index).SetFromVector([tau, c_rate, c, t])
        q_law, qd_law, _ = self.law.sample(tau)
        state.get_mutable_continuous_state().get_mutable_vector().SetFromVector(np.concatenate([q_law, qd_law * c]))
        return EventStatus.Succeeded()


def release_system(system: LeafSystem | None) -> None:
    """Drop what the Python LeafSystem ``system`` holds (its planner's law, plan, preflight log):
    pydrake 1.51 never frees a LeafSystem written in Python (its ports and callbacks hold it
    through references Python's collector cannot follow), so one that is done with would stay in
    memory whole (a Pająk planner behind a re-timed path: about 50 MB); emptied, it leaves its
    C++ shell. The system must not be used afterwards. None: nothing to do."""
    if system is not None:
        vars(system).clear()


def planner_robot(robot: Robot, num_joints: int) -> Robot:
    """``robot``, the robot a planner of ``num_joints`` joints runs on; TypeError or ValueError
    naming ``robot`` when it is not a Robot or has another number of joints."""
    instance_of(robot, Robot, "robot")
    if robot.num_joints != num_joints:
        raise invalid("robot", f"the planner has {num_joints} joints, robot {robot.name} has {robot.num_joints}")
    return robot


def joint_goals(goals, num_joints: int) -> np.ndarray:
    """A config's joint ``goals`` [rad] as an array (m, n), checked: finite, at least one row of
    ``num_joints``; ValueError naming ``goals`` otherwise."""
    rows = finite_array(goals, "goals", "rad")
    if rows.size == 0:
        raise invalid("goals", "goals must have at least one row of joint positions, got none")
    if rows.ndim != 2 or rows.shape[1] != num_joints:
        raise invalid("goals", f"goals must have shape (m, {num_joints}), got shape {rows.shape}")
    return rows


def waypoint_rows(q_waypoints) -> np.ndarray:
    """A law's ``q_waypoints`` [rad or m], the start then each goal, as a float array (m + 1, n), a
    copy, with m >= 1, n >= 1 and every value finite; ValueError naming the first bad entry."""
    try:
        rows = np.array(q_waypoints, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"q_waypoints must be an (m + 1, n) array of joint positions: {exc}") from exc
    if rows.ndim != 2 or rows.shape[0] < 2 or rows.shape[1] < 1:
        raise ValueError(f"q_waypoints must have shape (m + 1, n) with m >= 1, n >= 1, got shape {rows.shape}")
    if not np.all(np.isfinite(rows)):
        k, j = np.argwhere(~np.isfinite(rows))[0]
        raise ValueError(f"q_waypoints[{k}, {j}] must be finite, got {rows[k, j]}")
    return rows


def start_and_goals(q_initial, goals, num_joints: int) -> np.ndarray:
    """The start ``q_initial`` (n,) followed by the rows of ``goals`` (m, n): shape (m + 1, n)."""
    start = finite_array(q_initial, "q_initial", "rad", shape=(num_joints,))
    return np.vstack([start, joint_goals(goals, num_joints)])


def joint_move_limits(robot: Robot, velocity_limit, acceleration_limit) -> tuple[np.ndarray, np.ndarray]:
    """(velocity [rad/s], acceleration [rad/s²]) per joint of ``robot`` from a config's entries,
    each empty for the robot's joint-move limit (:attr:`~drake_traj.robots.Robot.joint_move_limits`);
    ValueError naming the entry where it is malformed, or empty where the robot has no default."""
    default_velocity, default_acceleration = robot.joint_move_limits
    n = robot.num_joints
    return (limit_or_default(velocity_limit, default_velocity, "velocity_limit", n),
            limit_or_default(acceleration_limit, default_acceleration, "acceleration_limit", n))
