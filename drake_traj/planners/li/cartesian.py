"""Velocity look-ahead and cubic ACC/DEC along a Cartesian polyline (Li et al. 2019, Li, Zhang, Zhou).

Li et al. 2019 (Li, Zhang, Zhou: "Trajectory planning of high precision collaborative robots") plans
the tool path in Cartesian space first, then re-times the joints and fits a quintic B-spline. This
module is the Cartesian stage only (section 2):

1. break-point velocity limits (eq. 1-7): how fast the tool may pass each point of the polyline
   given how sharply the direction changes there;
2. the look-ahead (eq. 8-10, Fig. 2): lower the limits until every pair of neighbours can be joined
   with the average ACC/DEC acceleration A over the segment between them;
3. the cubic ACC/DEC profile (eq. 11-13, Tables 1-2): the speed law along one straight segment, one
   of seven cases (:mod:`drake_traj.planners.li.acc_dec`);
4. the whole path: the segment profiles laid end to end, sampled densely in time.

Equation numbers in comments are the paper's. The OCR text has errors; the corrections in docs/papers.md
is followed and wins where they differ:

- eq. 3 and 6 are indexed one off: the direction change at P_i is from P_{i-1}P_i to P_iP_{i+1};
- eq. 4 is v_i = min{v_m, sqrt(a_m dl_i / K_i)} with dl_i = min{l_step, l_i} (sqrt(a_m R) on an
  arc sampled with chords no longer than l_step);
- eq. 8-10 use the average ACC/DEC acceleration A = (2/3) a_m of eq. 12, not a_m: the cubic
  ramp's peak acceleration is 1.5 times its average, so with A = (2/3) a_m the peak is exactly a_m;
- eq. 13 and the seven cases: see :mod:`drake_traj.planners.li.acc_dec`.

Everything here is plain numpy; tests call the functions directly. Units: metres, seconds.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from drake_traj.planners.li.acc_dec import AccDecProfile, acc_dec_profile, acc_dec_state, average_acceleration
from drake_traj.validation import finite_array, invalid, positive_scalar

__all__ = [
    "BreakPointGeometry",
    "CartesianPlan",
    "CartesianSample",
    "break_point_geometry",
    "break_point_limits",
    "forward_backward_pass",
    "look_ahead",
    "plan_cartesian_path",
]


# --------------------------------------------------------------------------------------------
# Input validation helpers (messages always name the argument and the reason).
# --------------------------------------------------------------------------------------------


def _vector(value, name: str, unit: str) -> np.ndarray:
    array = finite_array(value, name, unit)
    if array.ndim != 1:
        raise invalid(name, f"{name} must have shape (n,), got shape {array.shape}")
    return array


def _polyline(points) -> np.ndarray:
    """``points`` as an (N, 3) float array of N >= 2 distinct, non-repeating points."""
    try:
        array = np.array(points, dtype=float)
    except (TypeError, ValueError) as exc:
        raise invalid("points", f"points must be an (N, 3) array of real numbers [m]: {exc}") from exc
    if array.ndim != 2 or array.shape[1] != 3:
        raise invalid("points", f"points must have shape (N, 3) [m], got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        i, j = (int(k) for k in np.argwhere(~np.isfinite(array))[0])
        raise invalid("points", f"points[{i}, {j}] must be finite [m], got {array[i, j]}", i, j)
    if len(np.unique(array, axis=0)) < 2:
        raise ValueError(
            f"points must contain at least two distinct points, got {len(array)} point(s) and "
            f"{len(np.unique(array, axis=0))} distinct"
        )
    repeated = np.all(array[1:] == array[:-1], axis=1)
    if np.any(repeated):
        i = int(np.argmax(repeated)) + 1
        raise ValueError(
            f"points[{i}] repeats points[{i - 1}] = {array[i].tolist()}: consecutive points must "
            "differ (a zero-length segment has no direction)"
        )
    return array


# --------------------------------------------------------------------------------------------
# Break-point velocity limits (eq. 1-7).
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BreakPointGeometry:
    """Geometry of a polyline P_0 ... P_n at its break points.

    Attributes:
        lengths: l_i = |P_i - P_{i-1}| for i = 1..n [m], shape (n,); ``lengths[i - 1]`` is l_i.
        directions: unit vectors of P_{i-1}P_i for i = 1..n [-], shape (n, 3).
        direction_change: K_i = |u_{i+1} - u_i| (eq. 6, indices corrected) [-], shape (n + 1,),
            in [0, 2]; K_0 = K_n = 0 (no incoming or outgoing direction at the ends).
        curvature: K_i / dl_i [1/m], the discrete curvature seen by eq. 4, shape (n + 1,); 1/R at
            the interior points of an arc of radius R sampled with equal chords (dl_i = chord);
            0 at both ends and on straight runs.
        step: dl_i = min{l_step, l_i} [m] (eq. 1), shape (n + 1,); dl_0 = 0.
    """

    lengths: np.ndarray
    directions: np.ndarray
    direction_change: np.ndarray
    curvature: np.ndarray
    step: np.ndarray


def break_point_geometry(points, step_length: float | None = None) -> BreakPointGeometry:
    """Segment lengths, directions and direction changes K_i of a polyline (eq. 1, 3, 6).

    The velocity change at P_i (eq. 2-3) is |v_i| times the change of the direction cosines
    (cos theta_x, cos theta_y, cos theta_z) from P_{i-1}P_i to P_iP_{i+1}; those cosines are the
    components of the unit direction u, so K_i (eq. 6) = |u_{i+1} - u_i| = 2 sin(phi_i / 2) with
    phi_i the turning angle. (The paper indexes eq. 3 and 6 one off; docs/papers.md.)

    Args:
        points: P_0 ... P_n [m], shape (n + 1, 3), n >= 1; consecutive points must differ.
        step_length: l_step [m] of eq. 1, > 0, or None for no step cap (dl_i = l_i).

    Returns:
        :class:`BreakPointGeometry`.

    Raises:
        ValueError: wrong shape, non-finite values, fewer than two distinct points, a repeated
            consecutive point, or a non-positive step length.
    """
    p = _polyline(points)
    l_step = np.inf if step_length is None else positive_scalar(step_length, "step_length", "m")
    chords = np.diff(p, axis=0)
    lengths = np.linalg.norm(chords, axis=1)  # l_i, i = 1..n
    directions = chords / lengths[:, None]  # (cos theta_ix, cos theta_iy, cos theta_iz) (eq. 3)
    n = len(lengths)
    k = np.zeros(n + 1)
    # eq. 6 (indices corrected): K_i from P_{i-1}P_i (directions[i - 1]) to P_iP_{i+1}
    # (directions[i]), i = 1..n-1.
    k[1:n] = np.linalg.norm(directions[1:] - directions[:-1], axis=1)
    step = np.zeros(n + 1)
    step[1:] = np.minimum(l_step, lengths)  # eq. 1: dl_i = min{l_step, l_i}
    curvature = np.zeros(n + 1)
    curvature[1:] = k[1:] / step[1:]
    return BreakPointGeometry(lengths, directions, k, curvature, step)


def break_point_limits(points, v_max: float, a_max: float, step_length: float | None = None):
    """Maximum permissible speed v_i at each point of a polyline (eq. 4-7, corrected).

    Passing P_i at speed v turns the velocity by dv_i = v K_i (eq. 2-3) while covering dl_i, i.e.
    in dt_i = dl_i / v; eq. 1 asks dv_i / dt_i <= a_m, so (eq. 4, docs/papers.md)

        v_i = min{v_m, sqrt(a_m dl_i / K_i)},    dl_i = min{l_step, l_i},

    with v_i = v_m where the path is straight (K_i = 0) and v_0 = v_n = 0 (start and stop at rest).
    On an arc of radius R sampled with equal chords no longer than l_step, v_i = min{v_m,
    sqrt(a_m R)}. The sgn of eq. 4-5 is always +1 here (dl_i > 0); these are speeds. Eq. 7 takes
    the maximum permissible value.

    As in the paper, a sharp corner (even a full reversal, K_i = 2) gets a non-zero speed: the
    turn is modelled as spread over dl_i, not as an instantaneous change of direction.

    Args:
        points: P_0 ... P_n [m], shape (n + 1, 3); consecutive points must differ.
        v_max: v_m, maximum tool speed [m/s], > 0.
        a_max: a_m, maximum tool acceleration [m/s^2], > 0.
        step_length: l_step [m], > 0, or None (dl_i = l_i).

    Returns:
        v_i [m/s], shape (n + 1,).

    Raises:
        ValueError: as :func:`break_point_geometry`, or non-positive / non-finite limits.
    """
    v_m = positive_scalar(v_max, "v_max", "m/s")
    a_m = positive_scalar(a_max, "a_max", "m/s^2")
    geometry = break_point_geometry(points, step_length)
    k = geometry.direction_change
    limits = np.full(k.shape, v_m)
    turning = k > 0.0
    # eq. 4 (corrected): sqrt(a_m dl_i / K_i), capped by v_m; eq. 7 takes this maximum.
    limits[turning] = np.minimum(v_m, np.sqrt(a_m * geometry.step[turning] / k[turning]))
    limits[0] = 0.0  # eq. 1: v_0 = 0
    limits[-1] = 0.0  # and v_n = 0: the tool stops at the end of the path
    return limits


# --------------------------------------------------------------------------------------------
# The look-ahead (eq. 8-10, Fig. 2).
# --------------------------------------------------------------------------------------------


def _look_ahead_inputs(limits, lengths, a_max):
    v = _vector(limits, "limits", "m/s")
    lengths = _vector(lengths, "lengths", "m")
    if v.size < 2:
        raise ValueError(f"limits must have at least two entries (one segment), got {v.size}")
    if lengths.shape != (v.size - 1,):
        raise ValueError(
            f"lengths must have shape ({v.size - 1},) (one per segment between the {v.size} "
            f"limits), got shape {lengths.shape}"
        )
    if np.any(v < 0.0):
        i = int(np.argmax(v < 0.0))
        raise ValueError(f"limits[{i}] must be >= 0 [m/s], got {v[i]}")
    if np.any(lengths <= 0.0):
        i = int(np.argmax(lengths <= 0.0))
        raise ValueError(f"lengths[{i}] must be > 0 [m], got {lengths[i]}")
    return v, lengths, average_acceleration(a_max)


def look_ahead(limits, lengths, a_max: float) -> np.ndarray:
    """The paper's multi-pass velocity look-ahead (Fig. 2, eq. 8-10 with A = (2/3) a_m).

    Walks i = 1..n. If the speeds of P_{i-1} and P_i cannot be joined over l_i, i.e.
    l_imin = |v_i^2 - v_{i-1}^2| / (2A) > l_i (eq. 8), the larger one is lowered: v_i =
    sqrt(2 A l_i + v_{i-1}^2) if v_i > v_{i-1} (eq. 9), then on to i + 1; else v_{i-1} =
    sqrt(2 A l_i + v_i^2) (eq. 10), then back to i - 1, since the lowered v_{i-1} may now be
    out of reach of v_{i-2}. Speeds are only lowered, each to the largest value its neighbour
    allows, so the result is the largest speed vector under ``limits`` that meets eq. 8 everywhere:
    the same as :func:`forward_backward_pass` (tested), but with up to O(n^2) steps.

    A speed is lowered only when the new value is strictly smaller, so round-off in eq. 8 can
    never make the walk cycle.

    Args:
        limits: upper bounds on the speed at P_0 ... P_n [m/s], >= 0, shape (n + 1,) (from
            :func:`break_point_limits`: v_0 = v_n = 0).
        lengths: l_1 ... l_n [m], > 0, shape (n,).
        a_max: a_m [m/s^2], > 0; the look-ahead uses A = (2/3) a_m (eq. 12, docs/papers.md).

    Returns:
        The adjusted speeds [m/s], shape (n + 1,): v_i <= limits_i and
        |v_i^2 - v_{i-1}^2| <= 2 A l_i (to round-off).
    """
    v, lengths, acc = _look_ahead_inputs(limits, lengths, a_max)
    n = lengths.size
    i = 1
    while i <= n:
        reach = 2.0 * acc * lengths[i - 1]
        l_min_times_2a = abs(v[i] ** 2 - v[i - 1] ** 2)  # eq. 8, times 2A
        if l_min_times_2a <= reach:
            i += 1
        elif v[i] > v[i - 1]:
            v[i] = min(v[i], np.sqrt(reach + v[i - 1] ** 2))  # eq. 9
            i += 1
        else:
            lowered = np.sqrt(reach + v[i] ** 2)  # eq. 10
            if lowered < v[i - 1]:
                v[i - 1] = lowered
                i = max(i - 1, 1)  # step back: recheck P_{i-2} -> P_{i-1}
            else:
                i += 1
    return v


def forward_backward_pass(limits, lengths, a_max: float) -> np.ndarray:
    """One forward and one backward pass of eq. 9 and 10 (A = (2/3) a_m).

    Forward: v_i = min(v_i, sqrt(v_{i-1}^2 + 2 A l_i)); backward: v_{i-1} = min(v_{i-1},
    sqrt(v_i^2 + 2 A l_i)). The reference the multi-pass :func:`look_ahead` is tested against,
    and the O(n) way to get the same speeds. Arguments and result as :func:`look_ahead`.
    """
    v, lengths, acc = _look_ahead_inputs(limits, lengths, a_max)
    reach = 2.0 * acc * lengths
    for i in range(1, v.size):  # eq. 9
        v[i] = min(v[i], np.sqrt(v[i - 1] ** 2 + reach[i - 1]))
    for i in range(v.size - 1, 0, -1):  # eq. 10
        v[i - 1] = min(v[i - 1], np.sqrt(v[i] ** 2 + reach[i - 1]))
    return v


# --------------------------------------------------------------------------------------------
# The whole path.
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CartesianSample:
    """Tool state along the path at sample times (all arrays share the first dimension N).

    Attributes:
        t: times [s], shape (N,).
        s: arc length travelled along the polyline [m], shape (N,).
        position: tool position [m], shape (N, 3).
        speed: path speed ds/dt [m/s], shape (N,).
        acceleration: tangential acceleration d^2s/dt^2 [m/s^2], shape (N,).
        segment: index k of the segment P_k P_{k+1} each sample lies on, shape (N,).
    """

    t: np.ndarray
    s: np.ndarray
    position: np.ndarray
    speed: np.ndarray
    acceleration: np.ndarray
    segment: np.ndarray


@dataclass(frozen=True, eq=False)
class CartesianPlan:
    """The Cartesian time law of Li et al. 2019 section 2: a polyline with one ACC/DEC law per segment.

    Built by :func:`plan_cartesian_path`. Segment k runs from P_k to P_{k+1}, from time
    ``t_starts[k]`` for ``profiles[k].duration``, from speed ``velocities[k]`` to
    ``velocities[k + 1]``; speeds and tangential accelerations are continuous at the joints.
    The tool moves straight between points, so at a break point the velocity direction turns
    at once (the paper's model: eq. 1 bounds that turn by a_m over dl_i).

    Attributes:
        points: P_0 ... P_n [m], shape (n + 1, 3).
        limits: break-point limits from eq. 4-7 [m/s], shape (n + 1,).
        velocities: speeds after the look-ahead (Fig. 2) [m/s], shape (n + 1,).
        profiles: one :class:`AccDecProfile` per segment, length n.
        t_starts: start time of each segment [s], shape (n,).
    """

    points: np.ndarray
    limits: np.ndarray
    velocities: np.ndarray
    profiles: tuple[AccDecProfile, ...]
    t_starts: np.ndarray
    _table: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        table = np.array(
            [
                (p.length, p.v_start, p.v_cruise, p.v_end, p.t_acc, p.t_uniform, p.t_dec)
                for p in self.profiles
            ]
        )
        object.__setattr__(self, "_table", table)
        for name in ("points", "limits", "velocities", "t_starts"):
            array = np.array(getattr(self, name), dtype=float)
            array.setflags(write=False)
            object.__setattr__(self, name, array)
        object.__setattr__(self, "profiles", tuple(self.profiles))

    @property
    def lengths(self) -> np.ndarray:
        """l_1 ... l_n [m], shape (n,)."""
        return self._table[:, 0]

    @property
    def cumulative_length(self) -> np.ndarray:
        """Arc length at P_0 ... P_n [m], shape (n + 1,)."""
        return np.concatenate([[0.0], np.cumsum(self.lengths)])

    @property
    def segment_times(self) -> np.ndarray:
        """Time at P_0 ... P_n [s], shape (n + 1,)."""
        return np.append(self.t_starts, self.duration)

    @property
    def duration(self) -> float:
        """Total motion time [s]."""
        return float(self.t_starts[-1] + self.profiles[-1].duration)

    @property
    def cases(self) -> np.ndarray:
        """The :class:`~drake_traj.planners.li.acc_dec.AccDecCase` number of each segment, shape (n,)."""
        return np.array([int(p.case) for p in self.profiles])

    def sample(self, t) -> CartesianSample:
        """Tool position, path speed and tangential acceleration at times ``t``.

        At a segment joint the segment that starts there is used (the values agree: the speed is
        the shared break-point speed and the acceleration is zero). Times are clipped to
        [0, duration]: at rest at P_0 before, at P_n after.

        Args:
            t: times [s], scalar or 1-D array, finite.

        Returns:
            :class:`CartesianSample` with N = t.size.
        """
        times = np.atleast_1d(np.asarray(t, dtype=float))
        if times.ndim != 1:
            raise ValueError(f"t must be a scalar or have shape (N,), got shape {times.shape}")
        if not np.all(np.isfinite(times)):
            raise ValueError("t must be finite [s]")
        times = np.clip(times, 0.0, self.duration)
        k = np.clip(np.searchsorted(self.t_starts, times, side="right") - 1, 0, len(self.profiles) - 1)
        length, v_s, v_c, v_e, t_acc, t_uni, t_dec = self._table[k].T
        local = times - self.t_starts[k]
        # The plan's end time maps to the last profile's own end (no round-off in the subtraction).
        local = np.where(times >= self.duration, t_acc + t_uni + t_dec, local)
        s_local, speed, acceleration = acc_dec_state(
            local, length, v_s, v_c, v_e, t_acc, t_uni, t_dec
        )
        directions = np.diff(self.points, axis=0) / self.lengths[:, None]
        position = self.points[k] + s_local[:, None] * directions[k]
        s = self.cumulative_length[k] + s_local
        return CartesianSample(times, s, position, speed, acceleration, k)

    def sample_uniform(self, period: float) -> CartesianSample:
        """Dense samples every ``period`` seconds from 0, plus the final time [s]."""
        dt = positive_scalar(period, "period", "s")
        times = np.arange(0.0, self.duration, dt)
        return self.sample(np.append(times, self.duration))


def plan_cartesian_path(
    points, v_max: float, a_max: float, step_length: float | None = None
) -> CartesianPlan:
    """Li et al. 2019's Cartesian stage: limits (eq. 4-7), look-ahead (Fig. 2), ACC/DEC (eq. 11-13).

    The tool starts and stops at rest, moves straight from point to point, never exceeds v_max,
    and its tangential acceleration peaks at a_max on every ramp (average A = (2/3) a_max).

    Args:
        points: P_0 ... P_n [m], shape (n + 1, 3), n >= 1; consecutive points must differ.
        v_max: v_m [m/s], > 0.
        a_max: a_m [m/s^2], > 0.
        step_length: l_step of eq. 1 [m], > 0, or None (dl_i = l_i).

    Returns:
        :class:`CartesianPlan`.

    Raises:
        ValueError: fewer than two distinct points, repeated consecutive points, wrong shapes,
            non-finite values or non-positive limits; the message names the argument and reason.
    """
    p = _polyline(points)
    limits = break_point_limits(p, v_max, a_max, step_length)
    lengths = np.linalg.norm(np.diff(p, axis=0), axis=1)
    velocities = look_ahead(limits, lengths, a_max)
    profiles = tuple(
        acc_dec_profile(lengths[k], velocities[k], velocities[k + 1], v_max, a_max)
        for k in range(lengths.size)
    )
    durations = np.array([profile.duration for profile in profiles])
    t_starts = np.concatenate([[0.0], np.cumsum(durations)[:-1]])
    return CartesianPlan(p, limits, velocities, profiles, t_starts)
