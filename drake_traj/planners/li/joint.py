"""Joint-space stage of Li et al. 2019 (Li, Zhang, Zhou): re-timing, quintic B-spline, limit check.

Li et al. 2019 plans the tool path in Cartesian space first (:mod:`drake_traj.planners.li.cartesian`),
maps the discrete path points to joint space by inverse kinematics, and then (section 3):

1. re-times the joint samples (section 3.1, eq. 14): each interval gets the time the slowest
   joint needs for its step under the joint velocity and acceleration limits;
2. fits one quintic B-spline per joint through the samples (section 3.2, eq. 15-22), with zero
   velocity and acceleration at both ends.

The functions here are that stage, generic over the robot: inputs are joint samples q (N, n) and
their times, so any inverse kinematics can feed them. Equation numbers are the paper's; the
corrections in docs/papers.md are followed where it differs from the OCR text:

- eq. 22 omits the chain-rule factor of the time normalisation u = (t - t_0) / (t_n - t_0), and its
  end index is the last control point. scipy's ``make_interp_spline(k=5)`` with first and second
  derivative end conditions solves the same system (eq. 18, 22) with the same knots (eq. 17: the
  sample times, multiplicity k + 1 at the ends), in seconds, so no normalisation is needed.
- The paper's steps do not guarantee the joint limits: the fitted spline overshoots between the
  samples near sharp features (arcs, corners), and its acceleration there can exceed the limit
  (docs/papers.md, correction 7). :func:`check_limits` is the post-check, with the exact
  polynomial peaks of every knot interval; the repair that uses it is :mod:`.repair`.

Everything is plain numpy / scipy; tests call the functions directly. Units: rad, s.
"""

from __future__ import annotations

from bisect import bisect_right
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline

from drake_traj.errors import joint_label
from drake_traj.planners.li.cartesian import acc_dec_profile
from drake_traj.planners.laws.polynomials import rate_peaks
from drake_traj.validation import float_array, joint_limit_with_unit, require_finite

__all__ = [
    "JointSplineLaw",
    "LimitReport",
    "check_limits",
    "fit_quintic_spline",
    "joint_interval_times",
    "retime_joint_samples",
]

DEGREE = 5  # quintic B-spline (section 3.2)
# Relative margin of the limit checks: the repair makes every peak <= (1 - margin) * limit, so
# round-off between evaluation routes (B-spline vs piecewise polynomial, ~1e-13 relative) can never
# take a sample over the limit itself.
LIMIT_MARGIN = 1e-9
DEFAULT_SAMPLES_PER_INTERVAL = 16


# --------------------------------------------------------------------------------------------
# Input validation (messages name the argument, the expected form and what was given).
# --------------------------------------------------------------------------------------------


def _samples(times, q) -> tuple[np.ndarray, np.ndarray]:
    """``times`` (N,) strictly increasing and ``q`` (N, n), N >= 2, all finite (copies)."""
    t = float_array(times, "times", "s")
    if t.ndim != 1:
        raise ValueError(f"times must have shape (N,) [s], got shape {t.shape}")
    if t.size < 2:
        raise ValueError(f"times must have at least two samples, got {t.size}")
    require_finite(t, "times", "s")
    steps = np.diff(t)
    if np.any(steps <= 0.0):
        i = int(np.argmax(steps <= 0.0)) + 1
        raise ValueError(
            f"times must be strictly increasing [s]: times[{i}] = {t[i]} <= "
            f"times[{i - 1}] = {t[i - 1]}"
        )
    joints = float_array(q, "q", "rad")
    if joints.ndim != 2 or joints.shape[0] != t.size or joints.shape[1] == 0:
        raise ValueError(
            f"q must have shape (N, n) = ({t.size}, n) with n >= 1 (one row per time) [rad], "
            f"got shape {joints.shape}"
        )
    require_finite(joints, "q", "rad")
    return t, joints


# --------------------------------------------------------------------------------------------
# Section 3.1: time of the discrete points (eq. 14).
# --------------------------------------------------------------------------------------------


def _joint_point_speeds(times: np.ndarray, q: np.ndarray, velocity_limit: np.ndarray) -> np.ndarray:
    """Steps 1-3 of section 3.1 before the look-ahead: |joint speed| at every sample, (N, n).

    - The joint velocities at the samples are the ones the Cartesian plan implies (the paper gets
      them from the inverse kinematics of the tool velocity); here they are estimated from the
      samples at their Cartesian times by second-order finite differences (``np.gradient``), so
      any inverse kinematics will do. Both ends are at rest (the Cartesian plan starts and stops).
    - Step 1: a "break point in joint space" is read as a sample where the joint reverses or stops
      (the sign of its step changes or one of the steps is zero); its speed is set to zero.
    - Step 3: every speed is capped by the joint's omega_m.
    """
    steps = np.diff(q, axis=0)
    speeds = np.minimum(np.abs(np.gradient(q, times, axis=0)), velocity_limit)
    speeds[0] = 0.0
    speeds[-1] = 0.0
    sign = np.sign(steps)
    breaks = (sign[1:] != sign[:-1]) | (sign[1:] == 0.0) | (sign[:-1] == 0.0)
    speeds[1:-1][breaks] = 0.0
    return speeds


def joint_interval_times(times, q, velocity_limit, acceleration_limit) -> np.ndarray:
    """Delta T_ij of eq. 14: the time joint j needs for its step from sample i to sample i + 1.

    Section 3.1 as read here, per joint j:

    - speeds at the samples from :func:`_joint_point_speeds` (Cartesian-implied joint speeds, zero
      at the ends and at joint break points, capped at omega_m);
    - Step 2-3: the samples between zero-speed points form independent parts; in each, all
      samples are break points and their speeds are lowered by the look-ahead of Fig. 2 (eq. 9-10)
      with A = (2/3) alpha_m and segment lengths |q_{i+1,j} - q_ij| (one forward and one backward
      pass, which gives the same speeds as the paper's multi-pass walk);
    - Delta T_ij is the cubic ACC/DEC time of Table 2 (the seven cases of docs/papers.md, V_m = omega_m,
      A = (2/3) alpha_m) from the start to the end speed over that length
      (:func:`drake_traj.planners.li.cartesian.acc_dec_profile`); 0 for a joint that does not move.

    Args:
        times: sample times [s], shape (N,), N >= 2, strictly increasing.
        q: joint samples [rad], shape (N, n).
        velocity_limit: omega_m [rad/s], scalar or (n,), > 0.
        acceleration_limit: alpha_m [rad/s^2], scalar or (n,), > 0.

    Returns:
        Delta T [s], shape (N - 1, n).

    Raises:
        ValueError: bad shapes, non-finite values, non-increasing times or non-positive limits.
    """
    t, joints = _samples(times, q)
    n = joints.shape[1]
    omega = joint_limit_with_unit(velocity_limit, "velocity_limit", "rad/s", n)
    alpha = joint_limit_with_unit(acceleration_limit, "acceleration_limit", "rad/s^2", n)
    lengths = np.abs(np.diff(joints, axis=0))
    speeds = _joint_point_speeds(t, joints, omega)
    reach = 2.0 * (2.0 / 3.0) * alpha * lengths  # 2 A l, A = (2/3) alpha_m (eq. 12)
    for i in range(1, speeds.shape[0]):  # eq. 9, forward
        speeds[i] = np.minimum(speeds[i], np.sqrt(speeds[i - 1] ** 2 + reach[i - 1]))
    for i in range(speeds.shape[0] - 1, 0, -1):  # eq. 10, backward
        speeds[i - 1] = np.minimum(speeds[i - 1], np.sqrt(speeds[i] ** 2 + reach[i - 1]))
    durations = np.zeros_like(lengths)
    for i, j in zip(*np.nonzero(lengths > 0.0)):
        durations[i, j] = acc_dec_profile(
            lengths[i, j], speeds[i, j], speeds[i + 1, j], omega[j], alpha[j]
        ).duration
    return durations


def retime_joint_samples(
    times, q, velocity_limit, acceleration_limit, *, keep_input_times: bool = True
) -> np.ndarray:
    """New knot times for the joint samples (eq. 14): t_i = t_{i-1} + max_j Delta T_ij.

    The paper (eq. 14) sets each interval to the time of its slowest joint,
    max{Delta T_i1, ..., Delta T_ip} (:func:`joint_interval_times`), and drops the Cartesian times.
    That can make an interval shorter than the Cartesian plan's, which runs the tool over its
    Cartesian speed limit (docs/papers.md). With ``keep_input_times`` (default) each interval is
    max(original interval, max_j Delta T_ij): never faster than the Cartesian plan, and never
    faster than any joint allows. With ``keep_input_times=False`` the paper's eq. 14 as printed.

    Args:
        times: the Cartesian-stage times of the samples [s], shape (N,), strictly increasing.
        q: joint samples [rad], shape (N, n).
        velocity_limit: omega_m [rad/s], scalar or (n,), > 0.
        acceleration_limit: alpha_m [rad/s^2], scalar or (n,), > 0.
        keep_input_times: take the maximum with the original intervals (see above).

    Returns:
        New times [s], shape (N,), starting at ``times[0]``.

    Raises:
        ValueError: as :func:`joint_interval_times`; with ``keep_input_times=False``, also when no
            joint moves between two samples (the interval would have zero length).
    """
    t = _samples(times, q)[0]
    durations = np.max(joint_interval_times(t, q, velocity_limit, acceleration_limit), axis=1)
    if keep_input_times:
        durations = np.maximum(durations, np.diff(t))
    elif np.any(durations <= 0.0):
        i = int(np.argmax(durations <= 0.0))
        raise ValueError(
            f"q[{i + 1}] equals q[{i}] in every joint: eq. 14 gives that interval zero time; "
            "drop the repeated sample or use keep_input_times=True"
        )
    return t[0] + np.concatenate([[0.0], np.cumsum(durations)])


# --------------------------------------------------------------------------------------------
# Section 3.2: quintic B-spline fitting (eq. 15-22).
# --------------------------------------------------------------------------------------------


def fit_quintic_spline(times, q) -> BSpline:
    """The quintic B-spline through every sample, at rest (zero qd and qdd) at both ends.

    Eq. 18-19: interpolate (t_i, q_i); eq. 22: first and second derivatives zero at t_0 and t_N
    (the 4 = 2 (k - 1) extra equations); eq. 17: knots at the sample times, multiplicity k + 1 = 6
    at the ends. ``scipy.interpolate.make_interp_spline`` with these end conditions solves the same
    banded system (docs/papers.md), in time units directly (the chain-rule factor of the paper's
    normalisation u in [0, 1] is not needed).

    Args:
        times: knot times [s], shape (N,), N >= 2, strictly increasing.
        q: joint samples [rad], shape (N, n).

    Returns:
        ``scipy.interpolate.BSpline`` of degree 5, vector-valued (n,), on [times[0], times[-1]].

    Raises:
        ValueError: bad shapes, fewer than two samples, non-increasing times, non-finite values.
    """
    t, joints = _samples(times, q)
    zero = np.zeros(joints.shape[1])
    rest = [(1, zero), (2, zero)]
    return make_interp_spline(t, joints, k=DEGREE, bc_type=(rest, rest), axis=0)


class JointSplineLaw:
    """A joint time law q(tau) from a quintic B-spline through re-timed samples.

    The law's clock tau starts at 0 at the first sample. Before 0 it rests at ``q_start``, after
    ``duration`` at ``q_end`` (zero rates outside). :meth:`sample` evaluates the B-spline;
    :meth:`rates_at` evaluates the same spline in piecewise-polynomial form precomputed per knot
    interval (the planner system's hot path, one scalar time per call).

    Attributes:
        spline: the B-spline q(tau) [rad], tau in [0, duration] (``fit_quintic_spline`` of the
            shifted knot times).
        knot_times: the sample times on the law's clock [s], shape (N,), knot_times[0] = 0.
        samples: the joint samples [rad], shape (N, n).
    """

    # a quintic B-spline: q̈ is continuous, no law time where it jumps.
    acceleration_jumps = np.empty(0)

    def __init__(self, times, q):
        t, joints = _samples(times, q)
        knots = t - t[0]
        knots.setflags(write=False)
        joints.setflags(write=False)
        self.knot_times = knots
        self.samples = joints
        self.spline = fit_quintic_spline(knots, joints)
        self._velocity = self.spline.derivative(1)
        self._acceleration = self.spline.derivative(2)
        self._jerk = self.spline.derivative(3)
        # Taylor coefficients of qd and qdd about the midpoint of every knot interval, from the
        # derivative splines that sample() evaluates (so both routes agree to ~1e-15 relative):
        # qd = sum_p vel[p, k] (tau - mid_k)^p (degree 4), qdd = sum_p acc[p, k] (tau - mid_k)^p
        # (degree 3); shapes (5, N - 1, n) and (4, N - 1, n).
        mid = 0.5 * (knots[:-1] + knots[1:])
        factorial = np.array([1.0, 1.0, 2.0, 6.0, 24.0])
        self._mid = mid
        vel = np.stack([self._velocity(mid, nu=d) for d in range(5)])
        acc = np.stack([self._acceleration(mid, nu=d) for d in range(4)])
        self._vel_taylor = vel / factorial[:, None, None]
        self._acc_taylor = acc / factorial[:4, None, None]
        # rates_at: [qd | qdd] = powers(dt) @ coeffs[k], powers = [dt^4, dt^3, dt^2, dt, 1].
        n = joints.shape[1]
        coeffs = np.zeros((knots.size - 1, 5, 2 * n))
        for p in range(5):
            coeffs[:, 4 - p, :n] = self._vel_taylor[p]
        for p in range(4):
            coeffs[:, 4 - p, n:] = self._acc_taylor[p]
        self._rate_coeffs = coeffs
        self._mids = mid.tolist()
        self._breaks = knots[:-1].tolist()
        self._n = n
        self._duration = float(knots[-1])
        self._q_end = joints[-1].copy()

    @property
    def num_joints(self) -> int:
        """Number of joints n."""
        return self._n

    @property
    def q_start(self) -> np.ndarray:
        """Joint positions at tau = 0 [rad], shape (n,)."""
        return self.samples[0].copy()

    @property
    def q_end(self) -> np.ndarray:
        """Joint positions at tau = duration [rad], shape (n,)."""
        return self._q_end.copy()

    @property
    def duration(self) -> float:
        """Length of the motion [s]."""
        return self._duration

    @property
    def polynomial_breaks(self) -> np.ndarray:
        """The knot times [s]: the B-spline is one quintic between them."""
        return self.knot_times

    def interval_polynomials(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """qd and qdd on each knot interval as polynomials in sigma in [-1, 1].

        On interval k, tau = mid_k + sigma * half_k, qd = sum_p vel[p, k] sigma^p and
        qdd = sum_p acc[p, k] sigma^p.

        Returns:
            (mid [s] (N - 1,), half [s] (N - 1,), vel [rad/s] (5, N - 1, n),
            acc [rad/s^2] (4, N - 1, n)).
        """
        half = 0.5 * np.diff(self.knot_times)
        vel = np.stack([self._vel_taylor[p] * half[:, None] ** p for p in range(5)])
        acc = np.stack([self._acc_taylor[p] * half[:, None] ** p for p in range(4)])
        return self._mid.copy(), half, vel, acc

    def sample(self, t):
        """Position, velocity and acceleration at law times ``t`` [s] (vectorised).

        Args:
            t: time(s) on the law's clock [s], scalar or array of any shape, finite; clipped to
                [0, duration] for q (rest at the ends), rates are zero outside.

        Returns:
            (q [rad], qd [rad/s], qdd [rad/s^2]), each of shape t.shape + (n,).
        """
        times = float_array(t, "t", "s")
        require_finite(times, "t", "s")
        clipped = np.clip(times, 0.0, self._duration)
        inside = ((times >= 0.0) & (times <= self._duration))[..., None]
        q = self.spline(clipped)
        qd = np.where(inside, self._velocity(clipped), 0.0)
        qdd = np.where(inside, self._acceleration(clipped), 0.0)
        return q, qd, qdd

    def jerk(self, t):
        """Third derivative [rad/s^3] at law times ``t`` (zero outside [0, duration])."""
        times = float_array(t, "t", "s")
        require_finite(times, "t", "s")
        inside = ((times >= 0.0) & (times <= self._duration))[..., None]
        return np.where(inside, self._jerk(np.clip(times, 0.0, self._duration)), 0.0)

    def rates_at(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """(qd [rad/s], qdd [rad/s^2]) at one law time ``tau`` [s]: the hot path.

        Same values as :meth:`sample` (to ~1e-15 relative): the interval's Taylor polynomials about
        its midpoint, precomputed from the same derivative splines; one bisect and one small
        matrix product (a few microseconds).
        """
        if not 0.0 <= tau <= self._duration:
            return np.zeros(self._n), np.zeros(self._n)
        k = min(bisect_right(self._breaks, tau) - 1, len(self._mids) - 1)
        dt = tau - self._mids[k]
        dt2 = dt * dt
        rates = np.array([dt2 * dt2, dt2 * dt, dt2, dt, 1.0]) @ self._rate_coeffs[k]
        return rates[: self._n], rates[self._n :]


# --------------------------------------------------------------------------------------------
# Post-check of the limits (exact peaks per knot interval, plus dense samples).
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LimitReport:
    """Peak joint velocity and acceleration of a law against the limits.

    Peaks are exact per knot interval (up to round-off): the law is a polynomial there, so the
    candidates are the interval ends, the roots of qdd (velocity extrema) and of the jerk
    (acceleration extrema), found in closed form / by bisection, plus ``samples_per_interval``
    uniform samples per interval.

    Attributes:
        velocity_limit, acceleration_limit: the limits [rad/s], [rad/s^2], shape (n,).
        peak_velocity, peak_acceleration: max |qd|, max |qdd| per joint, shape (n,).
        peak_velocity_time, peak_acceleration_time: law time of each peak [s], shape (n,).
        interval_velocity, interval_acceleration: max |qd|, |qdd| per knot interval and joint,
            shape (N - 1, n).
        margin: relative margin of :attr:`ok`.
    """

    velocity_limit: np.ndarray
    acceleration_limit: np.ndarray
    peak_velocity: np.ndarray
    peak_velocity_time: np.ndarray
    peak_acceleration: np.ndarray
    peak_acceleration_time: np.ndarray
    interval_velocity: np.ndarray = field(repr=False)
    interval_acceleration: np.ndarray = field(repr=False)
    margin: float = LIMIT_MARGIN

    @property
    def velocity_ratio(self) -> np.ndarray:
        """peak |qd| / limit per joint, shape (n,)."""
        return self.peak_velocity / self.velocity_limit

    @property
    def acceleration_ratio(self) -> np.ndarray:
        """peak |qdd| / limit per joint, shape (n,)."""
        return self.peak_acceleration / self.acceleration_limit

    @property
    def worst_ratio(self) -> float:
        """Largest peak / limit over joints, velocity and acceleration."""
        return float(max(np.max(self.velocity_ratio), np.max(self.acceleration_ratio)))

    @property
    def interval_stretch(self) -> np.ndarray:
        """Time stretch each knot interval needs, max over joints of max(v ratio, sqrt(a ratio)).

        Stretching time by s divides qd by s and qdd by s^2 (exact for a uniform stretch), shape
        (N - 1,).
        """
        v = self.interval_velocity / self.velocity_limit
        a = np.sqrt(self.interval_acceleration / self.acceleration_limit)
        return np.max(np.maximum(v, a), axis=1)

    @property
    def ok(self) -> bool:
        """Every peak <= (1 - margin) * limit."""
        return self.worst_ratio <= 1.0 - self.margin

    def describe(self) -> str:
        """One line per joint that breaks a limit (or 'all limits hold')."""
        lines = []
        for j in range(self.peak_velocity.size):
            if self.velocity_ratio[j] > 1.0 - self.margin:
                lines.append(
                    f"{joint_label(j)}: |qd| = {self.peak_velocity[j]:.6g} rad/s at t = "
                    f"{self.peak_velocity_time[j]:.6g} s > limit {self.velocity_limit[j]:.6g} "
                    f"(x{self.velocity_ratio[j]:.4g})"
                )
            if self.acceleration_ratio[j] > 1.0 - self.margin:
                lines.append(
                    f"{joint_label(j)}: |qdd| = {self.peak_acceleration[j]:.6g} rad/s^2 at t = "
                    f"{self.peak_acceleration_time[j]:.6g} s > limit "
                    f"{self.acceleration_limit[j]:.6g} (x{self.acceleration_ratio[j]:.4g})"
                )
        return "; ".join(lines) if lines else "all limits hold"


def check_limits(
    law: JointSplineLaw,
    velocity_limit,
    acceleration_limit,
    samples_per_interval: int = DEFAULT_SAMPLES_PER_INTERVAL,
    *,
    margin: float = LIMIT_MARGIN,
) -> LimitReport:
    """Worst joint velocity and acceleration of ``law`` per joint and where (the post-check).

    On every knot interval the law is a quintic polynomial, so the peaks are taken over the
    interval ends, the real roots of qdd and of the jerk inside the interval, and
    ``samples_per_interval`` uniform samples (so they are the true maxima to round-off, and no
    denser grid can find a larger value).

    Args:
        law: the law to check.
        velocity_limit: [rad/s], scalar or (n,), > 0.
        acceleration_limit: [rad/s^2], scalar or (n,), > 0.
        samples_per_interval: uniform samples per knot interval (ends included), >= 2.
        margin: relative margin of :attr:`LimitReport.ok`, in [0, 1).

    Returns:
        :class:`LimitReport`.
    """
    if not isinstance(law, JointSplineLaw):
        raise ValueError(f"law must be a JointSplineLaw, got {type(law).__name__}")
    n = law.num_joints
    omega = joint_limit_with_unit(velocity_limit, "velocity_limit", "rad/s", n)
    alpha = joint_limit_with_unit(acceleration_limit, "acceleration_limit", "rad/s^2", n)
    if isinstance(samples_per_interval, bool) or int(samples_per_interval) != samples_per_interval:
        raise ValueError(
            f"samples_per_interval must be an integer >= 2, got {samples_per_interval!r}"
        )
    if samples_per_interval < 2:
        raise ValueError(f"samples_per_interval must be >= 2, got {samples_per_interval}")
    margin = float(margin)
    if not 0.0 <= margin < 1.0:
        raise ValueError(f"margin must be in [0, 1), got {margin}")
    mid, half, qd, qdd = law.interval_polynomials()  # in sigma in [-1, 1] per knot interval
    v_peak, v_s, a_peak, a_s = rate_peaks(qd, qdd, int(samples_per_interval))
    mid, half = mid[:, None], half[:, None]
    rows = np.argmax(v_peak, axis=0)
    arows = np.argmax(a_peak, axis=0)
    cols = np.arange(n)
    return LimitReport(
        velocity_limit=omega,
        acceleration_limit=alpha,
        peak_velocity=v_peak[rows, cols],
        peak_velocity_time=(mid + v_s * half)[rows, cols],
        peak_acceleration=a_peak[arows, cols],
        peak_acceleration_time=(mid + a_s * half)[arows, cols],
        interval_velocity=v_peak,
        interval_acceleration=a_peak,
        margin=margin,
    )
