"""Synchronised quintic moves as a time law: :class:`QuinticSegment` (one move, eq. 1-6) and
:class:`QuinticLaw` (a chain of moves with a stop at each goal), planned by
:func:`plan_synchronized_quintic` (eq. 4, 8, 9). Joint positions in rad, times in s."""

from bisect import bisect_right
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from drake_traj.errors import Cause, DrakeTrajError, field_text, joint_label
from drake_traj.planners.quintic.profile import (UNITS, joint_minimum_times, quintic_profile, quintic_third_derivative,
                                                 synchronized_duration)
from drake_traj.validation import MAX_RUN_DURATION, invalid, joint_bound, joint_limit, real_array, require_finite

__all__ = ["QuinticLaw", "QuinticSegment", "plan_synchronized_quintic"]


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
        q_start = real_array(self.q_start, "q_start", UNITS)
        q_goal = real_array(self.q_goal, "q_goal", UNITS)
        if q_start.ndim != 1 or q_start.size == 0:
            raise ValueError(f"q_start must have shape (n,) with n >= 1, got shape {q_start.shape}")
        if q_goal.shape != q_start.shape:
            raise ValueError(
                f"q_goal must have the shape of q_start {q_start.shape}, got shape {q_goal.shape}"
            )
        require_finite(q_start, "q_start")
        require_finite(q_goal, "q_goal")
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
class QuinticLaw:
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

    @property
    def polynomial_breaks(self) -> np.ndarray:
        """0, every segment's start and end [s]: the law is one quintic (or at rest) between them."""
        return np.unique(np.concatenate([[0.0], self._t_starts, self._t_starts + self._durations]))

    def _locate(self, t):
        """Segment index and clipped normalised time s for every sample of ``t``."""
        t_array = real_array(t, "t", UNITS)
        require_finite(t_array, "t")
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
        dddr = np.where(moving, quintic_third_derivative(s), 0.0)
        rate = d / tf[:, None]
        jerk = dddr[:, None] * rate / tf[:, None] / tf[:, None]
        return jerk.reshape(shape + (self.num_joints,))


def _too_long(k: int, d: np.ndarray, kv: np.ndarray, ka: np.ndarray, t: float, t_f: float) -> DrakeTrajError:
    """The refusal of a plan whose move to goal ``k`` (displacement ``d``, ``t_f`` [s], from
    ``t`` [s]) ends after :data:`MAX_RUN_DURATION`, at the limit of the joint that makes it so
    long (cause INFEASIBLE)."""
    times = np.asarray(joint_minimum_times(d, kv, ka))
    j = int(np.argmax(times))
    by_velocity = 15.0 / 8.0 * abs(d[j]) / kv[j] >= times[j]
    name, value, unit = ("velocity_limit", kv[j], "rad/s") if by_velocity else ("acceleration_limit", ka[j], "rad/s^2")
    return DrakeTrajError(
        f"{name}[{j}] = {value:g} {unit} ({joint_label(j)}) makes the move to goal {k} ({abs(d[j]):.4g} rad on that "
        f"joint) last {t_f:.4g} s, ending at t = {t + t_f:.4g} s, after the {MAX_RUN_DURATION:g} s a run may last: "
        "raise it", field=(name, j), cause=Cause.INFEASIBLE)


def _goal_rows(goals, n: int) -> np.ndarray:
    """``goals`` [rad] as an (m, n) array of finite values, m >= 1 (a single goal of shape (n,) as
    one row); ValueError naming ``goals``."""
    goal_array = real_array(goals, "goals", UNITS)
    if goal_array.ndim == 1 and goal_array.shape == (n,):
        goal_array = goal_array[None, :]
    if goal_array.ndim != 2 or goal_array.shape[1] != n:
        raise invalid("goals", f"goals must have shape (m, {n}) or ({n},) to match q_start, "
                               f"got shape {goal_array.shape}")
    if goal_array.shape[0] == 0:
        raise invalid("goals", f"goals must contain at least one goal, got shape {goal_array.shape}")
    require_finite(goal_array, "goals")
    return goal_array


def _check_position_bounds(q0: np.ndarray, goal_array: np.ndarray, position_lower, position_upper) -> None:
    """Refuse ``position_lower`` above ``position_upper`` [rad] (scalars or shape (n,), None for
    no bound), and ``q0`` (n,) or a row of ``goal_array`` (m, n) [rad] outside them: ValueError
    naming the argument, the goal index and the joint."""
    n = q0.size
    lower = None if position_lower is None else joint_bound(position_lower, "position_lower", n, UNITS)
    upper = None if position_upper is None else joint_bound(position_upper, "position_upper", n, UNITS)
    if lower is not None and upper is not None and np.any(lower > upper):
        j = int(np.argmax(lower > upper))
        raise invalid("position_lower", f"position_lower[{j}] = {lower[j]} is above position_upper[{j}] = "
                                        f"{upper[j]} ({joint_label(j)})", j)
    bounds = [(bound, beyond, side) for bound, beyond, side in ((lower, np.less, "below position_lower"),
                                                                (upper, np.greater, "above position_upper"))
              if bound is not None]
    rows = [("q_start", (), q0)] + [("goals", (k,), goal) for k, goal in enumerate(goal_array)]
    for name, index, row in rows:
        for bound, beyond, side in bounds:
            outside = np.flatnonzero(beyond(row, bound))
            if len(outside):
                j = int(outside[0])
                raise invalid(name, f"{field_text((name, *index, j))} ({joint_label(j)}) = {row[j]} rad is "
                                    f"{side}[{j}] = {bound[j]} rad", *index, j)


def plan_synchronized_quintic(
    q_start,
    goals,
    velocity_limit,
    acceleration_limit,
    position_lower=None,
    position_upper=None,
) -> QuinticLaw:
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
        QuinticLaw starting at t = 0 from ``q_start``.

    Raises:
        ValueError: wrong shapes, non-finite values, non-positive limits, position_lower above
            position_upper, or q_start / a goal outside the position bounds. The message names the
            argument (and the goal index and joint where relevant). A plan longer than
            :data:`~drake_traj.validation.MAX_RUN_DURATION` (600 s) is refused at the
            ``velocity_limit`` or ``acceleration_limit`` of the joint that makes it so long
            (DrakeTrajError, cause INFEASIBLE).
    """
    q0 = real_array(q_start, "q_start", UNITS)
    if q0.ndim != 1 or q0.size == 0:
        raise ValueError(f"q_start must have shape (n,) with n >= 1, got shape {q0.shape}")
    n = q0.size
    require_finite(q0, "q_start")

    goal_array = _goal_rows(goals, n)
    kv = joint_limit(velocity_limit, "velocity_limit", n, UNITS)
    ka = joint_limit(acceleration_limit, "acceleration_limit", n, UNITS)
    _check_position_bounds(q0, goal_array, position_lower, position_upper)

    segments: list[QuinticSegment] = []
    t = 0.0
    current = q0
    for goal in goal_array:
        d = goal - current  # eq. 4
        if not np.any(d != 0.0):
            continue  # already there: no segment, no division by a zero duration
        t_f = synchronized_duration(d, kv, ka)  # eq. 9 per joint, second eq. 8 over joints
        if t + t_f > MAX_RUN_DURATION:  # before anything sized by the duration is allocated
            raise _too_long(len(segments), d, kv, ka, t, t_f)
        segments.append(QuinticSegment(current, goal, t, t_f))
        t = segments[-1].t_end
        current = goal
    if not segments:
        segments.append(QuinticSegment(q0, q0, 0.0, 0.0))
    return QuinticLaw(tuple(segments))
