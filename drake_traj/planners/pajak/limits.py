"""The Pająk 2024 law's limit keeping, compiled: the choice of the scaling coefficient c
(cases 1-4 and a-c of eq. 17, corrected in docs/papers.md), its rate limit, and the fallback
braking where no c keeps q̈ in its box (improvements 1 and 2). Plain functions of floats and
(6,) arrays [rad/s, rad/s²], called by :mod:`.kernel`'s law and tested one by one."""

import numpy as np

from drake_traj.compiled import compiled

__all__ = ["BRAKE_LAG", "BRAKE_ONSET", "BRAKE_SLEW", "BRAKE_TIME", "brake", "brake_weight", "choose_scaling",
           "holding_joint", "keep_limits", "limit_jerk", "scaling_interval", "scaling_slew"]

BRAKE_TIME = 0.05  # [s], time constant of the fallback braking at low speed (improvement 2)
BRAKE_ONSET = 0.5  # violation (relative to q̈_max) at which the fallback is pure braking
BRAKE_LAG = 0.02  # [s], time constant with which the braking weight follows its target
BRAKE_SLEW = 10.0  # [1/s], largest rate of change of the braking weight


@compiled
def scaling_slew(b, slew: float, budget: float) -> float:
    """Largest |dc/dt| [1/s] (improvement 1): ``slew``, lowered where a change of c at that rate
    would change some q̈_i = a_i + c b_i faster than ``budget`` [rad/s³]: at most
    budget / max |b_i|. Where c is small the law's b is large (b_i of 100-400 rad/s² with the
    penalty of eq. 15 active and c of a few 10⁻³), and eq. 18's relaxation at (1 - c) per second
    alone changed q̈ by 0.1-0.2 rad/s² per ms."""
    largest = 0.0
    for k in range(b.shape[0]):
        largest = max(largest, abs(b[k]))
    if largest * slew <= budget:
        return slew
    return budget / largest


@compiled
def scaling_interval(a, b, lower, upper):
    """(c_lo, c_hi): the interval of c with lower <= a + c b <= upper on every joint.

    Each joint gives the bound of cases (1)-(4) (Corrected (docs/papers.md): (2) and (4) use q̈_min):
    b_i > 0: (q̈_min - a_i)/b_i <= c <= (q̈_max - a_i)/b_i; b_i < 0: the same with the roles
    of q̈_min and q̈_max swapped; b_i = 0: no bound if a_i is inside the box, else empty.
    Upper bounds (cases 1, 2) combine by min (case a), lower bounds (3, 4) by max (case b).
    The interval is empty where c_lo > c_hi.
    """
    c_lo = -np.inf
    c_hi = np.inf
    for i in range(a.shape[0]):
        to_max = (upper[i] - a[i]) / b[i]
        to_min = (lower[i] - a[i]) / b[i]
        c_lo = max(c_lo, np.fmin(to_max, to_min))  # fmin, fmax: a NaN (0 / 0) bounds nothing
        c_hi = min(c_hi, np.fmax(to_max, to_min))
    return c_lo, c_hi


@compiled
def holding_joint(a, b, lower, upper, qdd_max):
    """(j, by_velocity): the joint whose bound of cases 1-4 (:func:`scaling_interval`) is the
    smallest upper bound of c, where it is below 1 (j = -1 where no joint bounds c below 1), and
    whether its box edge there is narrower than ±q̈_max, i.e. the viability bound of its
    velocity limit (:func:`~.kernel.acceleration_box`) rather than its acceleration limit. What
    holds c near 0 when the law stalls; diagnosis only, c is chosen elsewhere."""
    smallest = 1.0
    j = -1
    by_velocity = False
    for i in range(a.shape[0]):
        to_max = (upper[i] - a[i]) / b[i]
        to_min = (lower[i] - a[i]) / b[i]
        bound = np.fmax(to_max, to_min)  # a NaN (0 / 0) bounds nothing
        if bound < smallest:
            smallest = bound
            j = i
            edge = upper[i] if to_max >= to_min else lower[i]
            by_velocity = abs(edge) < qdd_max[i] * (1.0 - 1e-9)
    return j, by_velocity


@compiled
def choose_scaling(c_relaxed: float, c_lo: float, c_hi: float, bounded: bool = True):
    """(c, feasible) from the relaxed value c_r (eq. 18) and the admissible interval (case a-c).

    c = c_r when it is admissible; otherwise the admissible value closest to c_r (case a: the
    smallest upper bound, case b: the largest lower bound, case c: the point of
    [ĉ_min, ĉ_max] closest to c_r, which is the previous c when the anchor was just recorded).
    ``bounded`` (improvement 2) restricts the interval to [0, 1]. feasible is False where the
    interval is empty (then c is the clip of c_r to it, and the caller must keep the limits
    some other way).
    """
    if bounded:
        c_lo = max(c_lo, 0.0)
        c_hi = min(c_hi, 1.0)
    c = min(max(c_relaxed, c_lo), c_hi)
    if bounded:
        c = min(max(c, 0.0), 1.0)
    return c, c_lo <= c_hi


@compiled
def keep_limits(a, b, c_relaxed: float, lower, upper, qdd_max, c_low: float, c_high: float, qdd):
    """Improvement 2: q̈ = a + c b (eq. 17) inside the box [lower, upper] at every evaluation,
    with c continuous in the state; returns (c, violation), q̈ into ``qdd``.

    - c is chosen by cases 1-4 and a-c (:func:`scaling_interval`, :func:`choose_scaling`) in
      [0, 1], then kept in [c_low, c_high] (the rate limit of c, improvement 1).
    - When a = -J⁻¹J̇q̇ alone is outside the box (``violation`` = the largest excess relative to
      q̈_max > 0: the joints move too fast for the curvature of the path), no c in [0, 1] keeps
      the limits. c is then chosen in the box widened by twice the violation, which a is
      strictly inside, so c stays continuous as some b_i changes sign (in the box itself the
      interval's bounds would jump between ±∞).
    - q̈ is clipped to the box: the limits win where the law (or the rate-limited c) would
      break them; the caller counts those evaluations.
    """
    violation = 0.0
    for k in range(6):
        violation = max(violation, (a[k] - upper[k]) / qdd_max[k], (lower[k] - a[k]) / qdd_max[k])
    low = np.empty(6)
    high = np.empty(6)
    for k in range(6):
        widen = 2.0 * violation * qdd_max[k]
        low[k] = lower[k] - widen
        high[k] = upper[k] + widen
    c_lo, c_hi = scaling_interval(a, b, low, high)  # cases 1-4
    c, _ = choose_scaling(c_relaxed, c_lo, c_hi, True)  # cases a-c
    c = min(max(c, c_low), c_high)
    for k in range(6):
        qdd[k] = min(max(a[k] + c * b[k], lower[k]), upper[k])  # eq. 17, clipped to the box
    return c, violation


@compiled
def limit_jerk(last, reach: float, lower, upper, qdd):
    """Improvement 1's jerk limit: q̈ (in ``qdd``) at most ``reach`` [rad/s²] from ``last``, its
    value after the last update (``reach``: the jerk limit times the time since), then clipped to the box
    [lower, upper]: the joint limits win where the box moved further (its edges move at no more
    than the jerk budget where q̈ rides them, :func:`~.kernel.viability_bound`)."""
    for k in range(qdd.shape[0]):
        qdd[k] = min(max(min(max(qdd[k], last[k] - reach), last[k] + reach), lower[k]), upper[k])


@compiled
def brake_weight(violation: float, weight: float, slope: float, elapsed: float):
    """(weight now, its target): the share of braking in q̈ (improvement 2). The target is
    smoothstep(violation / BRAKE_ONSET); the weight follows it from its value ``weight`` at the
    last update with that update's ``slope`` [1/s] for ``elapsed`` seconds (so q̈ changes at a
    bounded rate while the braking sets in or ends)."""
    x = min(violation / BRAKE_ONSET, 1.0)
    return min(max(weight + slope * elapsed, 0.0), 1.0), x * x * (3.0 - 2.0 * x)


@compiled
def brake(qd, lower, upper, qdd_max, weight: float, qdd):
    """q̈ blended by ``weight`` from its value in ``qdd`` (in the box) into braking every joint in
    proportion to its speed at the largest rate the box allows (at most 1/BRAKE_TIME); both ends
    are in the box, so the blend is (improvement 2)."""
    rate = 1.0 / BRAKE_TIME
    for k in range(6):
        rate = min(rate, qdd_max[k] / abs(qd[k]))
    for k in range(6):
        braking = min(max(-qd[k] * rate, lower[k]), upper[k])
        qdd[k] += weight * (braking - qdd[k])
