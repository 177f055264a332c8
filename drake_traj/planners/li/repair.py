"""Limit repair by a smooth time warp of the joint spline: our addition to Li et al. 2019.

Li et al. 2019's steps (the Cartesian stage, the re-timing of eq. 14 and the quintic B-spline of
eq. 15-22) do not guarantee the joint or the tool limits (docs/papers.md, correction 7): the spline
through the samples overshoots the tool acceleration at the two 90-degree corners and where a line
meets an arc, and eq. 14 lengthens single intervals, which makes the interpolating spline ring.
This module repairs the fitted spline where a limit is broken and leaves the rest of the motion at
the paper's timing (docs/li_efficiency.md has the measurements behind every choice):

- :func:`check_tool_limits`: the tool's speed and acceleration through forward kinematics, peak
  per knot interval: the best of ``samples_per_interval`` samples, refined to the peak of its basin
  by scipy's elementwise bracketing minimiser (the tool motion is not a polynomial in time, so
  these are not closed-form like the joints' peaks of :func:`~.joint.check_limits`);
- :func:`spread_log_stretch`: the smallest log-stretch profile above a requirement whose
  neighbouring values differ by at most given steps, by one forward and one backward pass (the
  look-ahead of eq. 9-10, on log-stretches instead of speeds);
- :func:`warp_log_steps`: those steps from an acceleration budget (how much the warp itself may
  add to any joint's or the tool's acceleration);
- :func:`smooth_time_warp`: stretch the knot intervals by the spread profile, refit the quintic
  B-spline through the same samples (eq. 15-22), check, and repeat until every requirement holds.

The warp changes only the knot times, never the samples: the path is the same, the executed law is
again the paper's quintic B-spline (C^4 in time, so q-ddot is continuous), and its joint peaks are
exact per knot interval.

Plain numpy / scipy; tests call the functions directly. Units: s, rad, m.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy.optimize.elementwise import find_minimum

from drake_traj.planners.li.joint import DEFAULT_SAMPLES_PER_INTERVAL, JointSplineLaw, LimitReport
from drake_traj.validation import finite_array, positive_scalar

__all__ = [
    "TOOL_LIMIT_MARGIN",
    "WARP_BUDGET",
    "ToolLimitReport",
    "WarpReport",
    "check_tool_limits",
    "joint_stretch",
    "spread_log_stretch",
    "tool_speed_and_acceleration",
    "smooth_time_warp",
    "warp_log_steps",
]

# Relative margin of the tool check (in the stretch's scale, see ToolLimitReport.interval_stretch):
# room for the closed loop, which integrates its reference from the law's acceleration.
TOOL_LIMIT_MARGIN = 1e-3
# Share of each acceleration limit the warp itself may use (docs/li_efficiency.md: 0.05 - 0.5
# measured; 0.2 is within 0.6 % of the shortest, 0.25, and leaves more of every limit to the law).
WARP_BUDGET = 0.2
# Each round stretches a broken interval by 1 / WARP_TARGET more than it needs, so that a round
# overshoots a little instead of creeping up on the limit.
WARP_TARGET = 0.99
WARP_MAX_ITERATIONS = 60


# --------------------------------------------------------------------------------------------
# The tool's speed and acceleration through forward kinematics.
# --------------------------------------------------------------------------------------------


def _interval_grid(knots: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Times with ``count`` per knot interval, ends included and shared between neighbours, shape
    ((N - 1)(count - 1) + 1,), and the index of each interval's samples into them, (N - 1, count)."""
    fractions = np.linspace(0.0, 1.0, count)[:-1]
    times = np.append((knots[:-1, None] + np.diff(knots)[:, None] * fractions).ravel(), knots[-1])
    index = (count - 1) * np.arange(knots.size - 1)[:, None] + np.arange(count)
    return times, index


def _tool_norms(law: JointSplineLaw, tool_motion, t) -> tuple[np.ndarray, np.ndarray]:
    """(|v|, |a|) of the tool at law times ``t`` (any shape); ValueError if not finite."""
    flat = np.ravel(t)
    velocity, acceleration = tool_motion(*law.sample(flat))
    speed = np.linalg.norm(np.asarray(velocity, dtype=float).reshape(flat.size, -1), axis=1)
    accel = np.linalg.norm(np.asarray(acceleration, dtype=float).reshape(flat.size, -1), axis=1)
    bad = ~(np.isfinite(speed) & np.isfinite(accel))
    if np.any(bad):
        k = int(np.argmax(bad))
        raise ValueError(f"tool_motion returned a non-finite tool velocity or acceleration at t = {flat[k]:.6g} s")
    return speed.reshape(np.shape(t)), accel.reshape(np.shape(t))


def _interval_peaks(values: np.ndarray, times: np.ndarray, index: np.ndarray,
                    evaluate: Callable) -> tuple[np.ndarray, np.ndarray]:
    """Peak of a smooth function per knot interval, and where.

    ``values`` are its samples at ``times``, ``index`` (N - 1, m) picks each interval's samples.
    Where the best sample of an interval is a local maximum of all the samples (its neighbours,
    across a knot if need be, are not higher), they bracket a maximum, which scipy's elementwise
    bracketing minimiser (Chandrupatla) on -f refines; the larger of the refined and the sampled
    value is kept. A refined peak may lie up to one sample spacing into the next interval (it then
    counts for both: conservative).
    """
    rows = np.arange(index.shape[0])
    best = index[rows, np.argmax(values[index], axis=1)]
    peak = values[best].copy()
    where = times[best].copy()
    inside = (best > 0) & (best < times.size - 1)
    left = np.where(inside, values[np.maximum(best - 1, 0)], np.inf)
    right = np.where(inside, values[np.minimum(best + 1, times.size - 1)], np.inf)
    bracket = (left <= peak) & (right <= peak) & ((left < peak) | (right < peak))  # scipy's condition
    if np.any(bracket):
        r, j = rows[bracket], best[bracket]
        result = find_minimum(lambda x: -evaluate(x), (times[j - 1], times[j], times[j + 1]))
        found = np.asarray(-result.f_x, dtype=float)
        better = np.asarray(result.success) & np.isfinite(found) & (found > peak[r])
        peak[r[better]] = found[better]
        where[r[better]] = np.asarray(result.x, dtype=float)[better]
    return peak, where


@dataclass(frozen=True)
class ToolLimitReport:
    """Peak tool speed and acceleration of a law against the tool limits, per knot interval.

    Attributes:
        speed_limit, acceleration_limit: the tool limits [m/s, m/s^2].
        interval_speed, interval_acceleration: peak |v|, |a| on each knot interval, shape (N - 1,).
        interval_speed_time, interval_acceleration_time: law times of those peaks [s], (N - 1,).
        margin: relative margin of :attr:`ok` and :attr:`interval_stretch`.
    """

    speed_limit: float
    acceleration_limit: float
    interval_speed: np.ndarray = field(repr=False)
    interval_acceleration: np.ndarray = field(repr=False)
    interval_speed_time: np.ndarray = field(repr=False)
    interval_acceleration_time: np.ndarray = field(repr=False)
    margin: float = TOOL_LIMIT_MARGIN

    @property
    def peak_speed(self) -> float:
        """Largest |v| [m/s]."""
        return float(np.max(self.interval_speed))

    @property
    def peak_speed_time(self) -> float:
        """Law time of :attr:`peak_speed` [s]."""
        return float(self.interval_speed_time[np.argmax(self.interval_speed)])

    @property
    def peak_acceleration(self) -> float:
        """Largest |a| [m/s^2]."""
        return float(np.max(self.interval_acceleration))

    @property
    def peak_acceleration_time(self) -> float:
        """Law time of :attr:`peak_acceleration` [s]."""
        return float(self.interval_acceleration_time[np.argmax(self.interval_acceleration)])

    @property
    def interval_stretch(self) -> np.ndarray:
        """Time stretch each knot interval needs to keep both limits with the margin, (N - 1,):
        max(|v| / v_lim, sqrt(|a| / a_lim)) / (1 - margin); a uniform stretch by s divides |v|
        by s and |a| by s^2, so this is exact for a uniform stretch."""
        ratio = np.maximum(self.interval_speed / self.speed_limit,
                           np.sqrt(self.interval_acceleration / self.acceleration_limit))
        return ratio / (1.0 - self.margin)

    @property
    def ok(self) -> bool:
        """Every interval within (1 - margin) of both limits (in the stretch's scale)."""
        return bool(np.all(self.interval_stretch <= 1.0))

    def describe(self) -> str:
        """The peaks against the limits, one line."""
        return (f"tool |v| = {self.peak_speed:.6g} m/s at t = {self.peak_speed_time:.6g} s (limit "
                f"{self.speed_limit:.6g}), |a| = {self.peak_acceleration:.6g} m/s^2 at t = "
                f"{self.peak_acceleration_time:.6g} s (limit {self.acceleration_limit:.6g})")


def check_tool_limits(
    law: JointSplineLaw,
    tool_motion,
    speed_limit: float,
    acceleration_limit: float,
    samples_per_interval: int = DEFAULT_SAMPLES_PER_INTERVAL,
    *,
    margin: float = TOOL_LIMIT_MARGIN,
) -> ToolLimitReport:
    """The tool's peak speed and acceleration through forward kinematics on every knot interval.

    On each interval: ``samples_per_interval`` samples (ends included), and the peak of the best
    sample's basin to the minimiser's tolerance (see :func:`_interval_peaks`). A second local
    maximum narrower than the sample spacing in the same interval could be missed; the spline
    varies on the scale of whole intervals.

    Args:
        law: the joint law.
        tool_motion: ``tool_motion(q, qd, qdd) -> (v (N, 3), a (N, 3))``, the robot's FK rates
            (:meth:`drake_traj.robots.Robot.tool_motion`).
        speed_limit, acceleration_limit: tool limits [m/s, m/s^2], > 0.
        samples_per_interval: integer >= 3.
        margin: in [0, 1).

    Returns:
        :class:`ToolLimitReport`.

    Raises:
        ValueError: bad arguments, or a non-finite tool motion (the time named).
    """
    if not isinstance(law, JointSplineLaw):
        raise ValueError(f"law must be a JointSplineLaw, got {type(law).__name__}")
    if not callable(tool_motion):
        raise ValueError(f"tool_motion must be callable (q, qd, qdd) -> (v, a), got {type(tool_motion).__name__}")
    v_lim = positive_scalar(speed_limit, "speed_limit", "m/s")
    a_lim = positive_scalar(acceleration_limit, "acceleration_limit", "m/s^2")
    if isinstance(samples_per_interval, bool) or int(samples_per_interval) != samples_per_interval \
            or samples_per_interval < 3:
        raise ValueError(f"samples_per_interval must be an integer >= 3, got {samples_per_interval!r}")
    margin = float(margin)
    if not 0.0 <= margin < 1.0:
        raise ValueError(f"margin must be in [0, 1), got {margin}")
    times, index = _interval_grid(law.knot_times, int(samples_per_interval))
    speed, accel = _tool_norms(law, tool_motion, times)
    v_peak, v_time = _interval_peaks(speed, times, index, lambda x: _tool_norms(law, tool_motion, x)[0])
    a_peak, a_time = _interval_peaks(accel, times, index, lambda x: _tool_norms(law, tool_motion, x)[1])
    return ToolLimitReport(v_lim, a_lim, v_peak, a_peak, v_time, a_time, margin)


def tool_speed_and_acceleration(law: JointSplineLaw, tool_motion, samples_per_interval: int = 64):
    """(t, |v|, |a|) of the tool [s, m/s, m/s^2] on ``samples_per_interval`` uniform samples per
    knot interval (the last knot added), for plots and time shares."""
    knots = law.knot_times
    fractions = np.linspace(0.0, 1.0, samples_per_interval, endpoint=False)
    t = np.append((knots[:-1, None] + np.diff(knots)[:, None] * fractions).ravel(), knots[-1])
    speed, accel = _tool_norms(law, tool_motion, t)
    return t, speed, accel


def joint_stretch(report: LimitReport) -> np.ndarray:
    """Time stretch each knot interval needs to keep the joint limits of ``report`` with its
    margin, (N - 1,): :attr:`LimitReport.interval_stretch` / (1 - margin), exact for a uniform
    stretch (the joints' counterpart of :attr:`ToolLimitReport.interval_stretch`)."""
    return report.interval_stretch / (1.0 - report.margin)


# --------------------------------------------------------------------------------------------
# The smooth time warp.
# --------------------------------------------------------------------------------------------


def spread_log_stretch(log_stretch, max_step) -> np.ndarray:
    """The smallest profile g >= ``log_stretch`` with |g[k + 1] - g[k]| <= max_step[k].

    g[k] = max_i (log_stretch[i] - sum of max_step between k and i): one forward pass
    g[k] = max(g[k], g[k - 1] - max_step[k - 1]) and one backward pass, as the look-ahead of
    eq. 9-10 (the same distance transform, here in log-stretch instead of speed).

    Args:
        log_stretch: required log-stretch per knot interval [-], shape (M,), finite.
        max_step: largest change between intervals k and k + 1 [-], shape (M - 1,), >= 0 (inf
            allowed: no coupling).

    Returns:
        g, shape (M,).
    """
    g = finite_array(log_stretch, "log_stretch", "-")
    if g.ndim != 1 or g.size == 0:
        raise ValueError(f"log_stretch must have shape (M,) with M >= 1, got shape {g.shape}")
    step = np.array(max_step, dtype=float)
    if step.shape != (g.size - 1,):
        raise ValueError(f"max_step must have shape ({g.size - 1},) (one per pair of neighbours), got {step.shape}")
    if np.any(np.isnan(step)) or np.any(step < 0.0):
        k = int(np.argmax(np.isnan(step) | (step < 0.0)))
        raise ValueError(f"max_step[{k}] must be >= 0, got {step[k]}")
    for k in range(1, g.size):
        g[k] = max(g[k], g[k - 1] - step[k - 1])
    for k in range(g.size - 2, -1, -1):
        g[k] = max(g[k], g[k + 1] - step[k])
    return g


def warp_log_steps(durations, rate_over_limit, budget: float = WARP_BUDGET) -> np.ndarray:
    """Largest log-stretch change between neighbouring knot intervals for an acceleration budget.

    A warp t(tau) with dt/dtau = exp(G(tau)) of a law whose channel (a joint, or the tool) moves at
    speed v(tau) changes that channel's acceleration by -v G' exp(-2 G) (G' = dG/dtau; the rest is
    the law's own acceleration, divided by exp(2 G)). Keeping this within ``budget`` times the
    channel's acceleration limit a_lim needs |G'| <= budget / max over channels (v / a_lim). Between
    intervals k and k + 1 (mid-points (d_k + d_{k+1}) / 2 apart):

        max_step[k] = budget * (d_k + d_{k+1}) / 2 / max(rho_k, rho_{k+1}),

    with rho = ``rate_over_limit`` (inf where nothing moves).

    Args:
        durations: d_k, the law's knot intervals [s], shape (M,), > 0.
        rate_over_limit: rho_k = max over channels of the peak speed on interval k over that
            channel's acceleration limit [s], shape (M,), >= 0.
        budget: share of the acceleration limits the warp may use, > 0.

    Returns:
        max_step, shape (M - 1,), for :func:`spread_log_stretch`.
    """
    d = finite_array(durations, "durations", "s")
    rho = finite_array(rate_over_limit, "rate_over_limit", "s")
    if d.ndim != 1 or d.size == 0 or np.any(d <= 0.0):
        raise ValueError(f"durations must be a non-empty vector of positive times [s], got {d}")
    if rho.shape != d.shape:
        raise ValueError(f"rate_over_limit must have shape {d.shape} (one per interval), got {rho.shape}")
    if np.any(rho < 0.0):
        k = int(np.argmax(rho < 0.0))
        raise ValueError(f"rate_over_limit[{k}] must be >= 0 [s], got {rho[k]}")
    share = positive_scalar(budget, "budget", "-")
    rate = np.maximum(rho[:-1], rho[1:])
    with np.errstate(divide="ignore"):
        return np.where(rate > 0.0, share * 0.5 * (d[:-1] + d[1:]) / rate, np.inf)


@dataclass(frozen=True)
class WarpReport:
    """What :func:`smooth_time_warp` did.

    Attributes:
        times: the knot times of the returned law [s], from 0, shape (N,).
        log_stretch: G_k, the log of each interval's stretch against the input times, (N - 1,);
            includes ``uniform_stretch``.
        iterations: warp rounds (0: the input already met every requirement).
        uniform_stretch: the factor of a final uniform stretch (1.0 if the rounds converged).
        initial_duration, final_duration: motion length before and after [s].
    """

    times: np.ndarray
    log_stretch: np.ndarray
    iterations: int
    uniform_stretch: float
    initial_duration: float
    final_duration: float

    @property
    def lengthening(self) -> float:
        """final_duration / initial_duration (>= 1)."""
        return self.final_duration / self.initial_duration


def _law(times: np.ndarray, log_stretch: np.ndarray, q: np.ndarray) -> JointSplineLaw:
    durations = np.diff(times) * np.exp(log_stretch)
    return JointSplineLaw(np.concatenate([[0.0], np.cumsum(durations)]), q)


def _needs(needed_stretch, law: JointSplineLaw) -> np.ndarray:
    need = np.asarray(needed_stretch(law), dtype=float)
    expected = (law.knot_times.size - 1,)
    if need.shape != expected:
        raise ValueError(f"needed_stretch must return shape {expected} (one per knot interval), got {need.shape}")
    if not np.all(np.isfinite(need)) or np.any(need < 0.0):
        k = int(np.argmax(~np.isfinite(need) | (need < 0.0)))
        raise ValueError(f"needed_stretch returned {need[k]} for interval {k}: it must be finite and >= 0")
    return need


def _warp_inputs(times, q, needed_stretch, max_step, initial_log_stretch, target, max_iterations):
    """:func:`smooth_time_warp`'s arguments checked (each ValueError names the argument): the knot
    times [s] (N,), the joint samples [rad] (N, n), max_step (N - 2,), the starting log-stretch G
    (N - 1,) and the target, as arrays and a float."""
    t = finite_array(times, "times", "s")
    if t.ndim != 1 or t.size < 2 or np.any(np.diff(t) <= 0.0):
        raise ValueError(f"times must be a strictly increasing vector of at least two knot times [s], got shape "
                         f"{t.shape}" + (f" with times[{int(np.argmax(np.diff(t) <= 0.0)) + 1}] <= the one before"
                                         if t.ndim == 1 and t.size >= 2 else ""))
    joints = finite_array(q, "q", "rad")
    if joints.ndim != 2 or joints.shape[0] != t.size:
        raise ValueError(f"q must have shape ({t.size}, n) (one row per knot time) [rad], got {joints.shape}")
    if not callable(needed_stretch):
        raise ValueError(f"needed_stretch must be callable (law -> stretch per interval), got {type(needed_stretch).__name__}")
    step = np.array(max_step, dtype=float)
    if step.shape != (t.size - 2,):
        raise ValueError(f"max_step must have shape ({t.size - 2},) (one per pair of neighbouring intervals), got {step.shape}")
    if initial_log_stretch is None:
        g = np.zeros(t.size - 1)
    else:
        g = finite_array(initial_log_stretch, "initial_log_stretch", "-", shape=(t.size - 1,))
        if np.any(g < 0.0):
            raise ValueError("initial_log_stretch must be >= 0 (a warp only stretches time)")
    target = float(target)
    if not 0.0 < target <= 1.0:
        raise ValueError(f"target must be in (0, 1], got {target}")
    if isinstance(max_iterations, bool) or int(max_iterations) != max_iterations or max_iterations < 0:
        raise ValueError(f"max_iterations must be an integer >= 0, got {max_iterations!r}")
    return t, joints, step, g, target


def _uniform_fallback(t, g, joints, needed_stretch, iterations: int, uniform: float) -> JointSplineLaw:
    """The law at knot intervals d_k exp(G_k), G already raised by log(``uniform``) after
    ``iterations`` rounds; ValueError if a requirement is still broken (a ``needed_stretch`` that
    does not scale as 1 / c under a uniform stretch by c)."""
    law = _law(t, g, joints)
    need = _needs(needed_stretch, law)
    if np.any(need > 1.0):
        k = int(np.argmax(need))
        raise ValueError(
            f"smooth_time_warp: interval {k} still needs a stretch of {need[k]:.6g} after {iterations} "
            f"rounds and a uniform stretch by {uniform:.6g}; needed_stretch must scale as 1 / c under a "
            "uniform stretch by c"
        )
    return law


def smooth_time_warp(
    times,
    q,
    needed_stretch: Callable[[JointSplineLaw], np.ndarray],
    max_step,
    *,
    initial_log_stretch=None,
    target: float = WARP_TARGET,
    max_iterations: int = WARP_MAX_ITERATIONS,
) -> tuple[JointSplineLaw, WarpReport]:
    """Stretch the knot intervals smoothly until ``needed_stretch`` is <= 1 on every interval.

    The law is the quintic B-spline through ``q`` at knot intervals d_k exp(G_k), d the input's.
    Each round fits it (eq. 15-22), evaluates s_k = needed_stretch(law), and where s_k > 1 raises
    G_k by log(s_k / target); then G is spread (:func:`spread_log_stretch`) so that neighbouring
    intervals differ by at most ``max_step`` (:func:`warp_log_steps`): the motion slows down
    gradually into a slowed-down region and speeds up gradually out of it, within the acceleration
    budget, instead of the per-interval jumps that make the interpolating spline ring. G only
    grows, so the rounds cannot cycle. After ``max_iterations`` rounds any excess left is removed
    by one uniform stretch by max s_k.

    ``needed_stretch`` must scale as 1 / c under a uniform stretch of time by c: peak speed over
    its limit, the square root of peak acceleration over its limit, a minimum duration over the
    duration; then the uniform fallback is exact.

    Args:
        times: knot times [s], shape (N,), strictly increasing.
        q: joint samples [rad], shape (N, n).
        needed_stretch: law -> stretch each knot interval needs, shape (N - 1,), finite, >= 0.
        max_step: shape (N - 2,), >= 0.
        initial_log_stretch: G to start from (e.g. an earlier warp's), shape (N - 1,), >= 0.
        target: each round aims at this fraction of a broken requirement, in (0, 1].
        max_iterations: integer >= 0.

    Returns:
        (law, report): the warped :class:`JointSplineLaw` (clock from 0) and :class:`WarpReport`.

    Raises:
        ValueError: bad arguments (named), or requirements still broken after the uniform
            stretch (a ``needed_stretch`` that does not scale as required).
    """
    t, joints, step, g, target = _warp_inputs(times, q, needed_stretch, max_step, initial_log_stretch, target,
                                              max_iterations)
    law = _law(t, g, joints)
    need = _needs(needed_stretch, law)
    iterations = 0
    while np.any(need > 1.0) and iterations < max_iterations:
        raise_by = np.where(need > 1.0, np.log(need / target), 0.0)
        g = spread_log_stretch(g + raise_by, step)
        iterations += 1
        law = _law(t, g, joints)
        need = _needs(needed_stretch, law)
    uniform = 1.0
    if np.any(need > 1.0):
        uniform = float(np.max(need)) * (1.0 + 1e-12)
        g = g + np.log(uniform)
        law = _uniform_fallback(t, g, joints, needed_stretch, iterations, uniform)
    return law, WarpReport(
        times=law.knot_times,
        log_stretch=g,
        iterations=iterations,
        uniform_stretch=uniform,
        initial_duration=float(t[-1] - t[0]),
        final_duration=law.duration,
    )
