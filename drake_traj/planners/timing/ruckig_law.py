"""Ruckig's jerk-limited, time-optimal rest-to-rest joint moves between waypoints, as a time law
(:class:`RuckigStopLaw`): the law of the Ruckig baseline, and of the moves the smooth timing
takes where stopping is faster (:mod:`.moves`).

The stop-at-each-waypoint version of a task, planned with the Ruckig library (community
version, offline use only): for every segment q_k -> q_{k+1} one Ruckig trajectory from rest to
rest (zero velocity and acceleration at both ends) under per-joint velocity, acceleration and
jerk limits, with Ruckig's default ``Synchronization.Time`` (every joint starts and finishes
together, the limiting joint runs its time-optimal profile). The segments are laid end to end
from t = 0. The default jerk limit is :func:`~.limits.default_jerk_limit`.

Evaluation: ``Trajectory.at_time`` itself is cheap (about 0.7 us per call, 2 us with the numpy
conversion, ruckig 0.19.4), but holding ``ruckig.Trajectory`` objects makes nanobind print
"leaked instance" warnings at interpreter exit. So the law copies each joint's seven jerk phases
(start time, position, velocity, acceleration, jerk) out of ``Trajectory.profiles`` into numpy
tables and evaluates the cubic pieces itself: exact (no dense table, no interpolation; tests
check it against ``at_time``), vectorised for :meth:`RuckigStopLaw.sample`. For
:meth:`RuckigStopLaw.rates_at` the phase boundaries of all joints are merged into one knot list
with every joint's (qd, qdd, jerk) at each knot: one bisect plus a few (n,) numpy operations,
about 5 us per call.
"""

from bisect import bisect_right

import numpy as np
import ruckig

from drake_traj.errors import Cause, DrakeTrajError, joint_label, reraise_interrupt
from drake_traj.planners.base import waypoint_rows
from drake_traj.planners.timing.limits import default_jerk_limit
from drake_traj.validation import positive_vector

__all__ = ["RuckigStopLaw"]


class RuckigStopLaw:
    """Jerk-limited rest-to-rest Ruckig moves through joint waypoints, stopping at each.

    A time law for :class:`~drake_traj.planners.base.TimeLawPlanner`.

    Args:
        q_waypoints: joint positions [rad], shape (m + 1, n) with m >= 1: the start q_0 then the
            goals q_1..q_m, visited in order with a stop at each.
        velocity_limit: [rad/s], > 0, scalar or shape (n,).
        acceleration_limit: [rad/s^2], > 0, scalar or shape (n,).
        jerk_limit: [rad/s^3], > 0, scalar or shape (n,); None gives
            :func:`default_jerk_limit` (10/s times the acceleration limit).

    Attributes:
        q_waypoints: (m + 1, n) read-only copy.
        segment_starts, segment_durations: (m,) [s]; segment k runs on
            [segment_starts[k], segment_starts[k] + segment_durations[k]].
        duration: total time [s].

    Raises:
        ValueError: wrong shapes, non-finite waypoints, non-positive limits, or a Ruckig error
            (the message names the segment).
    """

    # jerk-limited, so q̈ is continuous: no law time where it jumps.
    acceleration_jumps = np.empty(0)

    def __init__(self, q_waypoints, velocity_limit, acceleration_limit, jerk_limit=None):
        q = waypoint_rows(q_waypoints)
        n = q.shape[1]
        self.num_joints = n
        self.velocity_limit = positive_vector(velocity_limit, "velocity_limit", n)
        self.acceleration_limit = positive_vector(acceleration_limit, "acceleration_limit", n)
        if jerk_limit is None:
            jerk_limit = default_jerk_limit(self.acceleration_limit)
        self.jerk_limit = positive_vector(jerk_limit, "jerk_limit", n)
        q.setflags(write=False)
        self.q_waypoints = q

        durations, tables = self._plan_segments()
        self.segment_durations = np.array(durations)
        self.segment_starts = np.concatenate([[0.0], np.cumsum(self.segment_durations)[:-1]])
        self.duration = float(self.segment_starts[-1] + self.segment_durations[-1])
        # Piecewise-cubic tables, shape (m, n, 7): phase start time (segment clock), and the
        # position, velocity, acceleration at the phase start and the phase's constant jerk.
        self._phase_starts, self._p, self._v, self._a, self._j = (np.array(table) for table in tables)
        self._joints = np.arange(n)
        self._zeros = np.zeros(n)
        for array in (self.segment_durations, self.segment_starts):
            array.setflags(write=False)
        self._tabulate_knots()

    def _plan_segments(self) -> tuple[list[float], tuple[list, ...]]:
        """(duration [s] of every segment, the tables (phase starts, p, v, a, jerk), each a list
        of one (n, 7) array per segment): one Ruckig trajectory from rest to rest per segment."""
        otg = ruckig.Ruckig(self.num_joints)
        durations, tables = [], ([], [], [], [], [])
        for k in range(len(self.q_waypoints) - 1):
            duration, phases = self._segment(otg, k)
            durations.append(duration)
            for table, phase in zip(tables, phases):
                table.append(phase)
        return durations, tables

    def _segment(self, otg, k: int) -> tuple[float, tuple[np.ndarray, ...]]:
        """(duration [s], (phase starts [s], p, v, a, jerk), each (n, 7)) of Ruckig's move from
        rest at q_waypoints[k] to rest at q_waypoints[k + 1]; ValueError naming the segment."""
        n, q = self.num_joints, self.q_waypoints
        inp = ruckig.InputParameter(n)
        inp.current_position = q[k].tolist()
        inp.current_velocity = [0.0] * n
        inp.current_acceleration = [0.0] * n
        inp.target_position = q[k + 1].tolist()
        inp.target_velocity = [0.0] * n
        inp.target_acceleration = [0.0] * n
        inp.max_velocity = self.velocity_limit.tolist()
        inp.max_acceleration = self.acceleration_limit.tolist()
        inp.max_jerk = self.jerk_limit.tolist()
        trajectory = ruckig.Trajectory(n)
        where = f"segment {k} (q_waypoints[{k}] -> q_waypoints[{k + 1}])"
        try:
            result = otg.calculate(inp, trajectory)
        except Exception as exc:  # ruckig.RuckigError on invalid input
            reraise_interrupt(exc)
            raise ValueError(f"Ruckig failed on {where}: {exc}") from exc
        if result not in (ruckig.Result.Working, ruckig.Result.Finished):
            raise ValueError(f"Ruckig failed on {where}: result {result}")
        duration = float(trajectory.duration)
        profiles = trajectory.profiles
        if len(profiles) != 1:
            raise ValueError(f"Ruckig returned {len(profiles)} sections on {where}, expected 1")
        for j, profile in enumerate(profiles[0]):
            if profile.brake.duration != 0.0 or profile.accel.duration != 0.0:
                raise DrakeTrajError(f"Ruckig returned a brake/accel pre-phase on {where}, {joint_label(j)}", cause=Cause.PLANNING)
        # The seven jerk phases of every joint, padded by Ruckig to the synchronised duration.
        t_phase = np.array([list(profile.t) for profile in profiles[0]])  # (n, 7)
        phase_starts = np.concatenate([np.zeros((n, 1)), np.cumsum(t_phase, axis=1)[:, :-1]], axis=1)
        p0 = np.array([list(profile.p)[:7] for profile in profiles[0]])
        v0 = np.array([list(profile.v)[:7] for profile in profiles[0]])
        a0 = np.array([list(profile.a)[:7] for profile in profiles[0]])
        jerk = np.array([list(profile.j) for profile in profiles[0]])
        # No ruckig object is kept: nanobind warns about instances alive at interpreter exit.
        return duration, (phase_starts, p0, v0, a0, jerk)

    def _tabulate_knots(self) -> None:
        """The hot path of rates_at: one flat list of knots (every phase boundary of every joint
        and segment), with all joints' velocity and acceleration at each knot and their constant
        jerk up to the next knot, so one bisect and a few (n,) operations give (qd, qdd)."""
        knots = np.unique(np.append((self.segment_starts[:, None, None] + self._phase_starts).ravel(), self.duration))
        if len(knots) < 2:  # every waypoint equal: a zero-duration law
            knots = np.array([0.0, 0.0])
        _, v_knot, a_knot = self.sample(knots[:-1])
        self.polynomial_breaks = knots  # law times [s]: every joint is one cubic between them
        self._knots = knots[:-1].tolist()
        self._knot_v = v_knot
        self._knot_a = a_knot
        self._knot_j = self.jerk(0.5 * (knots[:-1] + knots[1:]))  # mid-interval: no boundary ambiguity

    @property
    def q_start(self) -> np.ndarray:
        """Joint positions at t = 0 [rad], shape (n,)."""
        return self.q_waypoints[0].copy()

    @property
    def breakpoints(self) -> np.ndarray:
        """Segment start times followed by the end time [s], shape (m + 1,)."""
        return np.append(self.segment_starts, self.duration)

    def rates_at(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """(qd [rad/s], qdd [rad/s^2]) at law time ``tau`` [s]: zero before 0 and after the end."""
        if not 0.0 <= tau <= self.duration:
            return self._zeros.copy(), self._zeros.copy()
        i = bisect_right(self._knots, tau) - 1
        dt = tau - self._knots[i]
        a = self._knot_a[i]
        j = self._knot_j[i]
        return self._knot_v[i] + dt * (a + (0.5 * dt) * j), a + dt * j

    def _evaluate(self, t):
        """Segment/phase lookup for an array of times: (shape, k, phase, dt, inside)."""
        t_array = np.asarray(t, dtype=float)
        if not np.all(np.isfinite(t_array)):
            raise ValueError("t must be finite")
        flat = t_array.reshape(-1)
        inside = (flat >= 0.0) & (flat <= self.duration)
        k = np.clip(np.searchsorted(self.segment_starts, flat, side="right") - 1, 0, None)
        s = np.clip(flat - self.segment_starts[k], 0.0, self.segment_durations[k])
        starts = self._phase_starts[k]  # (N, n, 7)
        phase = (starts <= s[:, None, None]).sum(axis=2) - 1  # (N, n)
        rows = np.arange(flat.size)[:, None]
        dt = s[:, None] - starts[rows, self._joints, phase]
        return t_array.shape, k[:, None], phase, dt, inside[:, None]

    def sample(self, t):
        """(q [rad], qd [rad/s], qdd [rad/s^2]) at times ``t`` [s], each of shape t.shape + (n,).

        Exact evaluation of Ruckig's piecewise-cubic profiles (matches ``Trajectory.at_time``),
        vectorised. Before 0 the law rests at q_0, after the end at the last waypoint.
        """
        shape, k, phase, dt, inside = self._evaluate(t)
        joints = self._joints
        p = self._p[k, joints, phase]
        v = self._v[k, joints, phase]
        a = self._a[k, joints, phase]
        j = self._j[k, joints, phase]
        q = p + dt * (v + dt * (0.5 * a + dt * j / 6.0))
        qd = np.where(inside, v + dt * (a + 0.5 * dt * j), 0.0)
        qdd = np.where(inside, a + dt * j, 0.0)
        n = self.num_joints
        return q.reshape(shape + (n,)), qd.reshape(shape + (n,)), qdd.reshape(shape + (n,))

    def jerk(self, t):
        """Jerk [rad/s^3] at times ``t``, shape t.shape + (n,): piecewise constant, the value of
        the phase that starts at a boundary, 0 outside [0, duration]."""
        shape, k, phase, _, inside = self._evaluate(t)
        jerk = np.where(inside, self._j[k, self._joints, phase], 0.0)
        return jerk.reshape(shape + (self.num_joints,))
