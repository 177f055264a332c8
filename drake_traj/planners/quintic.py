"""Synchronised quintic point-to-point planner (Benotsmane et al., Benotsmane).

Benotsmane et al. (Benotsmane, Kacemi, Benachenhou: "Calculation methodology for trajectory planning of a
6 axis manipulator arm") moves all joints from q^i to q^f along the same fifth-degree time law
r(t) (eq. 6), so every joint leaves and arrives at the same time. The duration t_f is the minimum
time of the constraining joint (eq. 8, 9): the slowest joint touches its velocity limit K_v or its
acceleration limit K_a, every other joint stays below its own. A sequence of goals is a chain of
such moves with a stop (zero velocity and acceleration) at every goal.

Equation numbers below are the paper's. Its numbering is repeated: "(8)" is both the peak
acceleration and t_f = max_j t_fj; comments say which one is meant. Eq. 9 as printed (K_a^2 under
the root) is wrong; docs/papers.md gives the corrected form used here,
t_fj = max(15|D_j| / (8 K_vj), sqrt(10 |D_j| / (sqrt(3) K_aj))), and D_j is the displacement
q^f_j - q^i_j [rad], not a duration.

The functions and the two dataclasses here are plain numpy: tests call them directly and the
planner system is a thin shell around them.
"""

from bisect import bisect_right
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from drake_traj.planners.base import TimeLawPlanner
from drake_traj.robots import UR10E, Robot
from drake_traj.validation import instance_of, limit_or_default, real_array

__all__ = [
    "QuinticPlan",
    "QuinticPtpPlanner",
    "QuinticSegment",
    "joint_minimum_times",
    "peak_acceleration",
    "peak_velocity",
    "plan_synchronized_quintic",
    "quintic_profile",
    "synchronized_duration",
]

# Peak values of the normalised profile r(s) on s in [0, 1] (eq. 7 and the first eq. 8).
_PEAK_DR = 15.0 / 8.0  # max r'(s), at s = 1/2
_PEAK_DDR = 10.0 / np.sqrt(3.0)  # max |r''(s)|, at s = 1/2 -+ sqrt(3)/6


# --------------------------------------------------------------------------------------------
# Input validation helpers (messages always name the argument and the reason).
# --------------------------------------------------------------------------------------------


def _as_float_array(value, name: str) -> np.ndarray:
    """``value`` as a float ndarray (copy), or ValueError naming ``name`` (text and booleans are
    not numbers: :func:`~drake_traj.validation.real_array`)."""
    return real_array(value, name, "rad, rad/s, rad/s^2 or s")


def _require_finite(array: np.ndarray, name: str) -> None:
    if not np.all(np.isfinite(array)):
        bad = np.argwhere(~np.isfinite(np.atleast_1d(array)))[0]
        where = "" if array.ndim == 0 else "[" + ", ".join(str(int(i)) for i in bad) + "]"
        value = np.atleast_1d(array)[tuple(bad)]
        raise ValueError(f"{name}{where} must be finite, got {value}")


def _require_positive(array: np.ndarray, name: str) -> None:
    if np.any(array <= 0.0):
        if array.ndim == 0:
            raise ValueError(f"{name} must be > 0, got {float(array)}")
        bad = np.argwhere(array <= 0.0)[0]
        where = ", ".join(str(int(i)) for i in bad)
        raise ValueError(
            f"{name}[{where}] (joint {where}) must be > 0, got {float(array[tuple(bad)])}"
        )


def _bound_vector(value, name: str, num_joints: int) -> np.ndarray:
    """A per-joint value: scalar (same for every joint) or shape (num_joints,); finite."""
    array = _as_float_array(value, name)
    if array.ndim == 0:
        array = np.full(num_joints, float(array))
    elif array.shape != (num_joints,):
        raise ValueError(
            f"{name} must be a scalar or have shape ({num_joints},), got shape {array.shape}"
        )
    _require_finite(array, name)
    return array


def _limit_vector(value, name: str, num_joints: int) -> np.ndarray:
    """A per-joint limit: as :func:`_bound_vector`, and > 0."""
    array = _bound_vector(value, name, num_joints)
    _require_positive(array, name)
    return array


def _scalar_or_array(result: np.ndarray):
    """0-d arrays become Python floats; everything else is returned as is."""
    return float(result) if np.ndim(result) == 0 else result


# --------------------------------------------------------------------------------------------
# The time law and the closed-form timing (eq. 6-9).
# --------------------------------------------------------------------------------------------


def quintic_profile(s):
    """Normalised quintic time law r(s) = 10 s^3 - 15 s^4 + 6 s^5 and its s-derivatives.

    Eq. 6 with s = t / t_f. r(0) = 0, r(1) = 1, and r', r'' vanish at both ends (eq. 5), so the
    joint starts and stops at rest with zero acceleration. Outside [0, 1], s is clipped: r = 0
    before, r = 1 after, with zero derivatives. NaN propagates.

    Args:
        s: normalised time [-] (scalar or array of any shape).

    Returns:
        (r, dr, ddr): r(s) [-], dr/ds [-] and d^2r/ds^2 [-], each with the shape of ``s``
        (numpy scalars for scalar ``s``). Time derivatives follow from dr/dt = r'(s) / t_f and
        d^2r/dt^2 = r''(s) / t_f^2.
    """
    s_raw = np.asarray(s, dtype=float)
    inside = (s_raw >= 0.0) & (s_raw <= 1.0)
    sc = np.clip(s_raw, 0.0, 1.0)
    # eq. 6, in Horner form: r = s^3 (10 - 15 s + 6 s^2).
    r = sc**3 * (10.0 + sc * (-15.0 + 6.0 * sc))
    # d/ds of eq. 6: r' = 30 s^2 (1 - s)^2 (the shape of eq. 2's velocity);
    # max 15/8 at s = 1/2 (eq. 7).
    dr = 30.0 * sc**2 * (1.0 - sc) ** 2
    # d^2/ds^2 of eq. 6: r'' = 60 s (1 - s) (1 - 2 s); zero at both ends (eq. 5);
    # max |r''| = 10/sqrt(3) at s = 1/2 -+ sqrt(3)/6 (first eq. 8).
    ddr = 60.0 * sc * (1.0 - sc) * (1.0 - 2.0 * sc)
    dr = np.where(inside, dr, 0.0)
    ddr = np.where(inside, ddr, 0.0) + 0.0  # "+ 0.0" turns the -0.0 at s = 1 into 0.0
    # Keep NaN visible rather than silently mapping it to rest.
    nan = np.isnan(s_raw)
    if np.any(nan):
        dr = np.where(nan, np.nan, dr)
        ddr = np.where(nan, np.nan, ddr)
    return r[()], dr[()], ddr[()]


def _quintic_third_derivative(s: np.ndarray) -> np.ndarray:
    """d^3r/ds^3 = 60 (1 - 6 s + 6 s^2) for s in [0, 1], else 0 [-].

    Not in the paper; it is 60 at both ends, so the end jerk is 60 D / t_f^3 (docs/papers.md).
    """
    s = np.asarray(s, dtype=float)
    inside = (s >= 0.0) & (s <= 1.0)
    return np.where(inside, 60.0 * (1.0 + s * (-6.0 + 6.0 * s)), 0.0)


def joint_minimum_times(displacement, velocity_limit, acceleration_limit):
    """Minimum quintic move time of each joint on its own (eq. 9, corrected as corrected in docs/papers.md).

    t_fj = max(15 |D_j| / (8 K_vj), sqrt(10 |D_j| / (sqrt(3) K_aj))). The first term makes the
    peak velocity (eq. 7) equal K_vj, the second makes the peak acceleration (first eq. 8) equal
    K_aj. The paper prints K_aj^2 under the root, which would let the acceleration reach ten times
    the limit for K_a = 10. A zero displacement gives 0; a negative one uses |D_j|.

    Args:
        displacement: D_j = q^f_j - q^i_j [rad] (eq. 4), scalar or shape (n,).
        velocity_limit: K_vj [rad/s], > 0, scalar or broadcastable to ``displacement``.
        acceleration_limit: K_aj [rad/s^2], > 0, scalar or broadcastable to ``displacement``.

    Returns:
        t_fj [s]: float for all-scalar inputs, else an array of the broadcast shape.

    Raises:
        ValueError: non-finite values, non-positive limits (naming the joint), or shapes that do
            not broadcast.
    """
    d = _as_float_array(displacement, "displacement")
    kv = _as_float_array(velocity_limit, "velocity_limit")
    ka = _as_float_array(acceleration_limit, "acceleration_limit")
    for array, name in ((d, "displacement"), (kv, "velocity_limit"), (ka, "acceleration_limit")):
        _require_finite(array, name)
    _require_positive(kv, "velocity_limit")
    _require_positive(ka, "acceleration_limit")
    try:
        d, kv, ka = np.broadcast_arrays(d, kv, ka)
    except ValueError as exc:
        raise ValueError(
            f"displacement {d.shape}, velocity_limit {kv.shape} and acceleration_limit {ka.shape} "
            "must have broadcastable shapes"
        ) from exc
    abs_d = np.abs(d)
    t_velocity = _PEAK_DR * abs_d / kv  # eq. 9, first term: 15 |D| / (8 K_v)
    # eq. 9, second term (corrected as corrected in docs/papers.md): sqrt(10 |D| / (sqrt(3) K_a))
    t_acceleration = np.sqrt(_PEAK_DDR * abs_d / ka)
    return _scalar_or_array(np.maximum(t_velocity, t_acceleration))


def synchronized_duration(displacement, velocity_limit, acceleration_limit) -> float:
    """Duration of the synchronised move: the constraining joint's minimum time (second eq. 8).

    t_f = max(t_f1, ..., t_fn), with t_fj from :func:`joint_minimum_times`. All joints then run on
    the same r(t / t_f), so they leave and arrive together and none exceeds its limits.

    Args:
        displacement: D_j [rad], scalar or shape (n,).
        velocity_limit: K_vj [rad/s], > 0, scalar or per joint.
        acceleration_limit: K_aj [rad/s^2], > 0, scalar or per joint.

    Returns:
        t_f [s] (0.0 when every displacement is zero).
    """
    times = np.asarray(joint_minimum_times(displacement, velocity_limit, acceleration_limit))
    if times.size == 0:
        raise ValueError("displacement must contain at least one joint, got an empty array")
    return float(np.max(times))  # second eq. 8


def _peak_inputs(displacement, duration):
    d = _as_float_array(displacement, "displacement")
    t_f = _as_float_array(duration, "duration")
    _require_finite(d, "displacement")
    _require_finite(t_f, "duration")
    if np.any(t_f < 0.0):
        raise ValueError(f"duration must be >= 0 [s], got {t_f.min()}")
    try:
        d, t_f = np.broadcast_arrays(d, t_f)
    except ValueError as exc:
        raise ValueError(
            f"displacement {d.shape} and duration {t_f.shape} must have broadcastable shapes"
        ) from exc
    if np.any((t_f == 0.0) & (d != 0.0)):
        raise ValueError("duration must be > 0 [s] for a non-zero displacement, got 0.0")
    # Zero displacement in zero time is no motion: use t_f = 1 so the peak comes out 0, not NaN.
    return np.abs(d), np.where(t_f > 0.0, t_f, 1.0)


def peak_velocity(displacement, duration):
    """Peak joint speed of a quintic move, |qd_j|max = 15 |D_j| / (8 t_f) (eq. 7), at t = t_f / 2.

    Args:
        displacement: D_j [rad], scalar or array.
        duration: t_f [s], >= 0 (0 only together with D_j = 0), broadcastable to ``displacement``.

    Returns:
        [rad/s], float for scalar inputs, else an array.
    """
    abs_d, t_f = _peak_inputs(displacement, duration)
    return _scalar_or_array(_PEAK_DR * abs_d / t_f)  # eq. 7


def peak_acceleration(displacement, duration):
    """Peak |joint acceleration| of a quintic move, 10 |D_j| / (sqrt(3) t_f^2) (first eq. 8).

    Reached at t / t_f = 1/2 -+ sqrt(3)/6 (accelerating, then decelerating).

    Args:
        displacement: D_j [rad], scalar or array.
        duration: t_f [s], >= 0 (0 only together with D_j = 0), broadcastable to ``displacement``.

    Returns:
        [rad/s^2], float for scalar inputs, else an array.
    """
    abs_d, t_f = _peak_inputs(displacement, duration)
    return _scalar_or_array(_PEAK_DDR * abs_d / t_f**2)  # first eq. 8


# --------------------------------------------------------------------------------------------
# Segments and plans.
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class QuinticSegment:
    """One synchronised quintic move from ``q_start`` to ``q_goal``, starting and ending at rest.

    q(t) = q_start + r((t - t_start) / duration) (q_goal - q_start) for t in
    [t_start, t_start + duration] (eq. 1, 4, 6). Frozen (a plan is immutable); the arrays are stored
    as read-only float copies.

    Attributes:
        q_start: joint positions q^i at the segment start [rad], shape (n,).
        q_goal: joint positions q^f at the segment end [rad], shape (n,).
        t_start: start time of the segment on the plan's clock [s].
        duration: t_f of the segment [s], >= 0 (0 only when q_goal == q_start).
    """

    q_start: np.ndarray
    q_goal: np.ndarray
    t_start: float
    duration: float

    def __post_init__(self) -> None:
        q_start = _as_float_array(self.q_start, "q_start")
        q_goal = _as_float_array(self.q_goal, "q_goal")
        if q_start.ndim != 1 or q_start.size == 0:
            raise ValueError(f"q_start must have shape (n,) with n >= 1, got shape {q_start.shape}")
        if q_goal.shape != q_start.shape:
            raise ValueError(
                f"q_goal must have the shape of q_start {q_start.shape}, got shape {q_goal.shape}"
            )
        _require_finite(q_start, "q_start")
        _require_finite(q_goal, "q_goal")
        t_start = float(self.t_start)
        duration = float(self.duration)
        if not np.isfinite(t_start):
            raise ValueError(f"t_start must be finite [s], got {t_start}")
        if not np.isfinite(duration) or duration < 0.0:
            raise ValueError(f"duration must be finite and >= 0 [s], got {duration}")
        if duration == 0.0 and np.any(q_goal != q_start):
            raise ValueError("duration must be > 0 [s] when q_goal differs from q_start, got 0.0")
        q_start.setflags(write=False)
        q_goal.setflags(write=False)
        object.__setattr__(self, "q_start", q_start)
        object.__setattr__(self, "q_goal", q_goal)
        object.__setattr__(self, "t_start", t_start)
        object.__setattr__(self, "duration", duration)

    @property
    def displacement(self) -> np.ndarray:
        """D = q_goal - q_start [rad] (eq. 4), shape (n,)."""
        return self.q_goal - self.q_start

    @property
    def t_end(self) -> float:
        """t_start + duration [s]."""
        return self.t_start + self.duration


@dataclass(frozen=True)
class QuinticPlan:
    """A chain of quintic segments: a sequence of joint goals with a stop at each.

    Segments are ordered in time and do not overlap; the planner lays them end to end from t = 0,
    each starting where the previous one ended. Before the first segment the plan rests at the
    first ``q_start``; between segments (if built with gaps) and after the last one it rests at the
    latest goal.

    Attributes:
        segments: the segments, in time order (at least one).
    """

    segments: tuple[QuinticSegment, ...]
    # q̈ is continuous (zero at both ends of each segment): no law time where it jumps.
    acceleration_jumps: ClassVar[np.ndarray] = np.empty(0)
    _t_starts: np.ndarray = field(init=False, repr=False, compare=False)
    _durations: np.ndarray = field(init=False, repr=False, compare=False)
    _q_starts: np.ndarray = field(init=False, repr=False, compare=False)
    _q_goals: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        segments = tuple(self.segments)
        if not segments:
            raise ValueError("segments must contain at least one QuinticSegment, got none")
        for k, segment in enumerate(segments):
            if not isinstance(segment, QuinticSegment):
                raise ValueError(
                    f"segments[{k}] must be a QuinticSegment, got {type(segment).__name__}"
                )
        shape = segments[0].q_start.shape
        for k, segment in enumerate(segments[1:], start=1):
            if segment.q_start.shape != shape:
                raise ValueError(
                    f"segments[{k}] has {segment.q_start.shape[0]} joints, "
                    f"segments[0] has {shape[0]}"
                )
            previous = segments[k - 1]
            if segment.t_start < previous.t_end:
                raise ValueError(
                    f"segments[{k}] starts at t = {segment.t_start} s, before segments[{k - 1}] "
                    f"ends at t = {previous.t_end} s"
                )
        object.__setattr__(self, "segments", segments)
        object.__setattr__(self, "_t_starts", np.array([seg.t_start for seg in segments]))
        object.__setattr__(self, "_durations", np.array([seg.duration for seg in segments]))
        object.__setattr__(self, "_q_starts", np.stack([seg.q_start for seg in segments]))
        object.__setattr__(self, "_q_goals", np.stack([seg.q_goal for seg in segments]))
        for array in (self._t_starts, self._durations, self._q_starts, self._q_goals):
            array.setflags(write=False)

    @property
    def num_joints(self) -> int:
        """Number of joints n."""
        return int(self._q_starts.shape[1])

    @property
    def q_start(self) -> np.ndarray:
        """Joint positions at the start of the plan [rad], shape (n,)."""
        return self.segments[0].q_start.copy()

    @property
    def q_goal(self) -> np.ndarray:
        """Joint positions at the end of the plan (the last goal) [rad], shape (n,)."""
        return self.segments[-1].q_goal.copy()

    @property
    def duration(self) -> float:
        """Total duration [s]: the end time of the last segment (the plan starts at t = 0)."""
        return self.segments[-1].t_end

    @property
    def breakpoints(self) -> np.ndarray:
        """Segment start times followed by the plan's end time [s], shape (K + 1,)."""
        return np.append(self._t_starts, self.duration)

    def _locate(self, t):
        """Segment index and clipped normalised time s for every sample of ``t``."""
        t_array = _as_float_array(t, "t")
        _require_finite(t_array, "t")
        flat = t_array.reshape(-1)
        index = np.searchsorted(self._t_starts, flat, side="right") - 1
        before = index < 0
        index = np.maximum(index, 0)
        t0 = self._t_starts[index]
        tf = self._durations[index]
        t_end = t0 + tf  # same expression as QuinticSegment.t_end, so t == duration hits s = 1
        moving = (~before) & (tf > 0.0) & (flat <= t_end)
        safe_tf = np.where(tf > 0.0, tf, 1.0)  # never divide by a zero duration
        s = np.where(moving, np.clip((flat - t0) / safe_tf, 0.0, 1.0), np.where(before, 0.0, 1.0))
        return t_array.shape, index, s, safe_tf, moving

    def sample(self, t):
        """Reference position, velocity and acceleration at plan time ``t``.

        q = q^i + r D for s <= 1/2 (eq. 1) and q = q^f - (1 - r) D for s > 1/2 (eq. 3, with
        1 - r(s) = r(1 - s)), so the goal is reproduced exactly at the end of every segment;
        qd = r'(s) D / t_f (eq. 2), qdd = r''(s) D / t_f^2.

        Args:
            t: time [s], scalar or array of any shape (finite).

        Returns:
            (q [rad], qd [rad/s], qdd [rad/s^2]), each of shape t.shape + (n,): (n,) for scalar t,
            (N, n) for t of shape (N,).
        """
        shape, index, s, tf, _ = self._locate(t)
        q0 = self._q_starts[index]
        q1 = self._q_goals[index]
        d = q1 - q0  # eq. 4
        r, dr, ddr = quintic_profile(s)
        r_mirror, _, _ = quintic_profile(1.0 - s)  # 1 - r(s), without cancellation near s = 1
        first_half = (s <= 0.5)[:, None]
        q = np.where(first_half, q0 + r[:, None] * d, q1 - r_mirror[:, None] * d)  # eq. 1 / eq. 3
        # D / t_f [rad/s]; divided step by step so tiny moves cannot overflow.
        rate = d / tf[:, None]
        qd = dr[:, None] * rate  # eq. 2
        qdd = ddr[:, None] * rate / tf[:, None]  # d/dt of eq. 2; zero at both ends (eq. 5)
        n = self.num_joints
        return q.reshape(shape + (n,)), qd.reshape(shape + (n,)), qdd.reshape(shape + (n,))

    def rates_at(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(qd [rad/s], qdd [rad/s^2]) at one plan time ``t`` [s]: the planner system's hot path.

        Same values as :meth:`sample` (r' = 30 s^2 (1 - s)^2, r'' = 60 s (1 - s)(1 - 2 s), the
        derivatives of eq. 6), without the array bookkeeping.
        """
        k = bisect_right(self._t_starts, t) - 1
        duration = self._durations[k] if k >= 0 else 0.0
        s = (t - self._t_starts[k]) / duration if duration > 0.0 else -1.0
        if not 0.0 <= s <= 1.0:  # before the plan, at rest between segments, or after the end
            return np.zeros(self.num_joints), np.zeros(self.num_joints)
        rate = (self._q_goals[k] - self._q_starts[k]) / duration
        return 30.0 * (s * (1.0 - s)) ** 2 * rate, 60.0 * s * (1.0 - s) * (1.0 - 2.0 * s) * rate / duration

    def jerk(self, t):
        """Reference jerk d^3q/dt^3 = r'''(s) D / t_f^3 [rad/s^3] at plan time ``t``.

        Non-zero at the ends of each moving segment: 60 D / t_f^3 (docs/papers.md). At a boundary
        between two segments the value of the segment that starts there is returned; at the plan's
        end, the last segment's end value; outside every segment, 0.

        Args:
            t: time [s], scalar or array of any shape (finite).

        Returns:
            Array of shape t.shape + (n,).
        """
        shape, index, s, tf, moving = self._locate(t)
        d = self._q_goals[index] - self._q_starts[index]
        dddr = np.where(moving, _quintic_third_derivative(s), 0.0)
        rate = d / tf[:, None]
        jerk = dddr[:, None] * rate / tf[:, None] / tf[:, None]
        return jerk.reshape(shape + (self.num_joints,))


def plan_synchronized_quintic(
    q_start,
    goals,
    velocity_limit,
    acceleration_limit,
    position_lower=None,
    position_upper=None,
) -> QuinticPlan:
    """Plan synchronised quintic moves through a sequence of joint goals, stopping at each.

    For every goal the displacement D = q^f - q^i (eq. 4) gives each joint's minimum time (eq. 9,
    corrected) and the segment lasts t_f = max_j t_fj (second eq. 8); all joints follow the same
    r(t / t_f) (eq. 6), so they start and stop together, the constraining joint reaches its velocity
    or acceleration limit and no joint exceeds either. A goal equal to the current position
    (D = 0 on every joint) is skipped; if every goal is skipped the plan is a single zero-duration
    segment that rests at ``q_start``.

    Because r is monotone on [0, 1], every joint stays between its start and goal, so checking the
    endpoints against the position bounds checks the whole motion.

    Args:
        q_start: initial joint positions q^i [rad], shape (n,).
        goals: joint goals [rad], shape (m, n), or (n,) for a single goal; visited in order.
        velocity_limit: K_v [rad/s], > 0, scalar or shape (n,).
        acceleration_limit: K_a [rad/s^2], > 0, scalar or shape (n,).
        position_lower: optional lower joint bounds [rad], scalar or shape (n,).
        position_upper: optional upper joint bounds [rad], scalar or shape (n,).

    Returns:
        QuinticPlan starting at t = 0 from ``q_start``.

    Raises:
        ValueError: wrong shapes, non-finite values, non-positive limits, position_lower above
            position_upper, or q_start / a goal outside the position bounds. The message names the
            argument (and the goal index and joint where relevant).
    """
    q0 = _as_float_array(q_start, "q_start")
    if q0.ndim != 1 or q0.size == 0:
        raise ValueError(f"q_start must have shape (n,) with n >= 1, got shape {q0.shape}")
    n = q0.size
    _require_finite(q0, "q_start")

    goal_array = _as_float_array(goals, "goals")
    if goal_array.ndim == 1 and goal_array.shape == (n,):
        goal_array = goal_array[None, :]
    if goal_array.ndim != 2 or goal_array.shape[1] != n:
        raise ValueError(
            f"goals must have shape (m, {n}) or ({n},) to match q_start, "
            f"got shape {goal_array.shape}"
        )
    if goal_array.shape[0] == 0:
        raise ValueError(f"goals must contain at least one goal, got shape {goal_array.shape}")
    _require_finite(goal_array, "goals")

    kv = _limit_vector(velocity_limit, "velocity_limit", n)
    ka = _limit_vector(acceleration_limit, "acceleration_limit", n)

    lower = None if position_lower is None else _bound_vector(position_lower, "position_lower", n)
    upper = None if position_upper is None else _bound_vector(position_upper, "position_upper", n)
    if lower is not None and upper is not None and np.any(lower > upper):
        j = int(np.argmax(lower > upper))
        raise ValueError(
            f"position_lower[{j}] = {lower[j]} is above position_upper[{j}] = {upper[j]} "
            f"(joint {j})"
        )
    points = (("q_start", q0[None, :]), ("goals", goal_array))
    for name, array in points:
        for k, row in enumerate(array):
            label = name if name == "q_start" else f"goals[{k}]"
            if lower is not None and np.any(row < lower):
                j = int(np.argmax(row < lower))
                raise ValueError(
                    f"{label} joint {j} = {row[j]} rad is below "
                    f"position_lower[{j}] = {lower[j]} rad"
                )
            if upper is not None and np.any(row > upper):
                j = int(np.argmax(row > upper))
                raise ValueError(
                    f"{label} joint {j} = {row[j]} rad is above "
                    f"position_upper[{j}] = {upper[j]} rad"
                )

    segments: list[QuinticSegment] = []
    t = 0.0
    current = q0
    for goal in goal_array:
        d = goal - current  # eq. 4
        if not np.any(d != 0.0):
            continue  # already there: no segment, no division by a zero duration
        t_f = synchronized_duration(d, kv, ka)  # eq. 9 per joint, second eq. 8 over joints
        segments.append(QuinticSegment(current, goal, t, t_f))
        t = segments[-1].t_end
        current = goal
    if not segments:
        segments.append(QuinticSegment(q0, q0, 0.0, 0.0))
    return QuinticPlan(tuple(segments))


class QuinticPtpPlanner(TimeLawPlanner):
    """Planner system for a :class:`QuinticPlan`: a :class:`TimeLawPlanner` whose waypoints are
    the flange positions at the joint goals.

    Args:
        plan: the joint-space plan (from :func:`plan_synchronized_quintic`).
        velocity_limit, acceleration_limit: the limits the plan was made for [rad/s, rad/s^2].
        update_period: how often the speed override is read [s].
        robot: the robot (for the tool positions at the goals).
    """

    def __init__(self, plan: QuinticPlan, velocity_limit, acceleration_limit, *, update_period: float = 0.001,
                 robot: Robot = UR10E):
        instance_of(plan, QuinticPlan, "plan")
        super().__init__(
            plan,
            _limit_vector(velocity_limit, "velocity_limit", plan.num_joints),
            _limit_vector(acceleration_limit, "acceleration_limit", plan.num_joints),
            update_period=update_period,
        )
        self.robot = robot

    def task_waypoints(self) -> np.ndarray:
        """Tool positions at the joint goals [m]."""
        return self.robot.tool_position(np.array([segment.q_goal for segment in self.law.segments]))


@dataclass
class QuinticConfig:
    """Synchronised quintic point-to-point moves through joint goals (Benotsmane et al.), a stop
    at each: the scenario's ``planner: !QuinticConfig`` entry.

    Attributes:
        goals: joint goals [rad or m], one row of n per goal, visited in order from the start.
        velocity_limit, acceleration_limit: per joint [rad/s, rad/s^2]; empty: the robot's
            joint-move limits (UR10e: 1.05 rad/s, 1.40 rad/s^2).
    """

    goals: list[list[float]] = field(default_factory=list)
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)


def make(config: QuinticConfig, robot: Robot, q_initial) -> QuinticPtpPlanner:
    """The planner of ``config`` on ``robot`` from ``q_initial``, the goals checked against the
    robot's joint ranges."""
    default_velocity, default_acceleration = robot.joint_move_limits
    velocity = limit_or_default(config.velocity_limit, default_velocity, "velocity_limit", robot.num_joints)
    acceleration = limit_or_default(config.acceleration_limit, default_acceleration, "acceleration_limit",
                                    robot.num_joints)
    plan = plan_synchronized_quintic(q_initial, config.goals, velocity, acceleration,
                                     position_lower=robot.lower_limits, position_upper=robot.upper_limits)
    return QuinticPtpPlanner(plan, velocity, acceleration, robot=robot)
