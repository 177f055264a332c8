"""Rest-to-rest moves timed exactly with Ruckig, as :class:`SmoothTiming`: through waypoints with a
stop at each (Ruckig's time-synchronised moves; one move is the time-optimal rest-to-rest move
under per-joint limits), and along one straight joint segment (Ruckig on the path parameter). The
smooth-waypoints planner takes them where they are faster than the spline's timing
(docs/smooth_timing.md)."""

import numpy as np
from pydrake.trajectories import PiecewisePolynomial

from drake_traj.planners.laws.hermite import HermiteLaw
from drake_traj.planners.timing.limits import check_least_durations, joint_limits
from drake_traj.planners.timing.motion import InfeasibleTimingError, SmoothTiming, stretched
from drake_traj.planners.timing.ruckig_law import RuckigStopLaw
from drake_traj.validation import positive_scalar

__all__ = ["line_timing", "stop_timing"]


def line_timing(q_start, q_goal, velocity_limit, acceleration_limit, jerk_limit=None, *,
                max_duration: float = 600.0) -> SmoothTiming:
    """The time-optimal jerk-limited rest-to-rest motion along the straight joint segment from
    ``q_start`` to ``q_goal`` [rad]: the seven-phase profile of the path parameter s in [0, 1]
    (Ruckig on one degree of freedom) under the tightest of the joints' limits on s
    (v_j / |Δq_j|, a_j / |Δq_j|, J_j / |Δq_j|), which is Ruckig's phase-synchronised motion; no
    linear program, exact on the line (its pieces are cubic in t). T grows with the distance.
    Limits as :func:`time_path`'s; an :class:`InfeasibleTimingError` where the motion would last
    longer than ``max_duration`` [s] or the segment has no length."""
    q, limits = _stop_inputs([q_start, q_goal], velocity_limit, acceleration_limit, jerk_limit, max_duration)
    step = q[1] - q[0]
    moving = step != 0
    line_limits = [[float(np.min(limit[moving] / np.abs(step[moving])))] for limit in limits]
    knots, s, s_jerk = _ruckig_states(RuckigStopLaw([[0.0], [1.0]], *line_limits), max_duration)  # s: (K, s/ṡ/s̈, 1)
    samples = s * step[None, None, :]
    samples[:, 0] += q[0]
    path = PiecewisePolynomial.FirstOrderHold([0.0, 1.0], q.T)
    return _exact_timing(knots, samples, s_jerk * step[None, :], limits, path)


def stop_timing(q_waypoints, velocity_limit, acceleration_limit, jerk_limit=None, *,
                max_duration: float = 600.0) -> SmoothTiming:
    """Time-optimal jerk-limited rest-to-rest moves through joint waypoints (m + 1, n) [rad],
    stopping at each: Ruckig's time-synchronised moves (every joint starts and stops together,
    the limiting joint on its own time-optimal profile, the others on profiles of the same
    duration). One move is the fastest a rest-to-rest move can be under per-joint limits, never
    slower than the straight line (:func:`line_timing`); the joints do not keep to the straight
    segments between the waypoints, so the timing's ``path`` is the motion itself (s = t). Exact
    (cubic pieces in t); T grows with the distance. Limits and errors as :func:`line_timing`'s."""
    q, limits = _stop_inputs(q_waypoints, velocity_limit, acceleration_limit, jerk_limit, max_duration)
    return _exact_timing(*_ruckig_states(RuckigStopLaw(q, *limits), max_duration), limits, None)


def _stop_inputs(q_waypoints, velocity_limit, acceleration_limit, jerk_limit, max_duration):
    """(waypoints (m + 1, n), (velocity, acceleration, jerk)) of rest-to-rest moves, checked: the
    motion moves, and no limit alone makes a move last longer than ``max_duration`` [s] (checked
    before Ruckig sees limits of 1e-300)."""
    q = np.asarray(q_waypoints, dtype=float)
    steps = np.abs(np.diff(q, axis=0))
    velocity, acceleration, jerk = joint_limits(q.shape[1], velocity_limit, acceleration_limit, jerk_limit)
    if not np.any(steps > 0):
        raise InfeasibleTimingError("path does not move: the goal equals the start", field=("path",))
    check_least_durations(steps.max(axis=0), (velocity, acceleration, jerk),
                           positive_scalar(max_duration, "max_duration", "s"), "moves")
    return q, (velocity, acceleration, jerk)


def _ruckig_states(law: RuckigStopLaw, max_duration: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(knots (K,) [s], states (K, position/rate/acceleration, n), jerk (K - 1, n)) of a Ruckig law
    at its knots (every joint is one cubic between them, of that constant jerk), at rest at both
    ends; an :class:`InfeasibleTimingError` naming the limits where it lasts longer than
    ``max_duration``."""
    if not law.duration <= max_duration:
        raise InfeasibleTimingError(f"the limits are too small for the path: the move takes {law.duration:.4g} s, longer "
                                    f"than max_duration {max_duration:g} s (velocity_limit, acceleration_limit or "
                                    "jerk_limit)", field=("path",))
    knots = np.asarray(law.polynomial_breaks, dtype=float)
    knots = knots[np.concatenate([[True], np.diff(knots) > 1e-12])]
    knots[-1] = law.duration
    states = np.stack(law.sample(knots), axis=1)
    states[0, 1:] = states[-1, 1:] = 0.0
    states[-1, 0] = law.q_waypoints[-1]
    return knots, states, law.jerk(0.5 * (knots[:-1] + knots[1:]))


def _exact_timing(knots, states, jerk, limits, path) -> SmoothTiming:
    """The SmoothTiming of the cubic pieces from ``states`` (K, q/q̇/q̈, n) at ``knots`` with
    constant ``jerk`` (K - 1, n) between, along ``path`` (None: the motion itself), stretched in
    time where Ruckig's profile exceeds a limit by its rounding (the jerk by up to 5e-6 of it). The
    law is these pieces (a Hermite quintic through the states would turn their round-off into
    jerk on Ruckig's shortest phases, microseconds long)."""
    coefficients = np.zeros((len(knots) - 1, 6, states.shape[2]))
    coefficients[:, :3] = states[:-1] / np.array([1.0, 1.0, 2.0])[None, :, None]
    coefficients[:, 3] = jerk / 6
    knots, states, coefficients, ratio, stretch = stretched(knots, states, coefficients, np.stack(limits), 1e-9)
    law = HermiteLaw(knots, states, states, pieces=coefficients)
    return SmoothTiming(law, coefficients, float(knots[-1]), path, stretch, ratio, 0.0, 0)
