"""The trajectory-scaling coefficient c(t) shared by the planners.

Pająk 2024, eq. 18: after the last change at t0, where c had the value c0, the coefficient relaxes
exponentially back to 1:  c(t) = (c0 - 1) exp(-(t - t0)) + 1. :func:`relaxed_scaling` generalises
the target 1 to a ``goal`` (the speed override, in [0, 1]) and keeps a rate [1/s] (1 in the
paper); the Pająk planner uses it.

The time-law planners run their law on a clock tau with d tau/dt = c. Their q̈ is
c² q_law''(tau) + ċ q_law'(tau), so a step in ċ (eq. 18's relaxation when the override changes)
is a step in q̈. Their clock is therefore piecewise quadratic: ċ is held over each update period
and changes between periods by at most ``jerk`` × period (:func:`next_clock_rate`), towards eq.
18's rate (goal - c) × rate, and never beyond what the joint acceleration limits allow at that
point of the law (:func:`admissible_clock_rate`).
"""

from __future__ import annotations

import math

import numpy as np

from drake_traj.compiled import compiled


@compiled
def relaxed_scaling(t: float, t0: float, c0: float, goal: float = 1.0, rate: float = 1.0):
    """(c, dc/dt) at time t [s] of eq. 18 generalised: c = (c0 - goal) exp(-rate (t - t0)) + goal.

    Compiled (:mod:`drake_traj.compiled`): the Pająk 2024 law calls it on every evaluation."""
    decay = math.exp(-rate * (t - t0))
    return (c0 - goal) * decay + goal, -rate * (c0 - goal) * decay


def clock_at(elapsed, tau: float, c: float, c_rate: float):
    """(tau, c) after ``elapsed`` [s] with ċ = ``c_rate`` held: the piecewise-quadratic clock."""
    return tau + c * elapsed + 0.5 * c_rate * elapsed * elapsed, c + c_rate * elapsed


def admissible_clock_rate(c: float, qd_law, qdd_law, acceleration_limit, margin: float = 1e-3) -> tuple[float, float]:
    """Interval [lo, hi] of ċ [1/s] with |c² q_law'' + ċ q_law'| <= max((1 - margin) q̈_max,
    c² |q_law''|) on every joint: within the limit, or no worse than the law itself where the law
    is at the limit or beyond it (a baseline's blends). It always contains 0. The margin covers
    what the combination can do between the two instants a period is checked at (measured: up to
    6e-5 of the limit over 1 ms).

    Per joint with q_law' != 0: ċ between (±bound - c² q_law'') / q_law'; joints at rest in the
    law bound nothing.
    """
    qd_law = np.asarray(qd_law, dtype=float)
    base = c * c * np.asarray(qdd_law, dtype=float)
    moving = qd_law != 0.0
    if not moving.any():
        return -np.inf, np.inf
    bound = np.maximum((1.0 - margin) * np.asarray(acceleration_limit, dtype=float)[moving], np.abs(base[moving]))
    upper = (bound - base[moving]) / qd_law[moving]
    lower = (-bound - base[moving]) / qd_law[moving]
    return float(np.max(np.minimum(upper, lower))), float(np.min(np.maximum(upper, lower)))


def next_clock_rate(c: float, c_rate: float, goal: float, *, rate: float, jerk: float, period: float,
                    cap: float = 1.0) -> float:
    """ċ for the next update period: towards eq. 18's rate × (goal - c), changed by at most
    ``jerk`` × ``period`` [1/s²] (so q̈ changes continuously), and keeping c in [0, cap] at the
    period's end."""
    step = jerk * period
    candidate = c_rate + min(max(rate * (goal - c) - c_rate, -step), step)
    return min(max(candidate, -c / period), (cap - c) / period)
