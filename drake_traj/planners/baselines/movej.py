"""UR-style "MoveJ" with radius blending: the baseline of Pająk 2024's experiment 1.

Pająk 2024, experiment 1, ran its task on the real UR10e with the controller's own
"MoveJ" command between the waypoints, with the default joint limits 1.05 rad/s and 1.40 rad/s^2
and "radius blending" of 0.05 m around each waypoint so the robot does not stop there. The paper
reports that the controller respects the acceleration limit between the waypoints but exceeds it
in the blends: up to 2.48 rad/s^2 against 1.40 (its Table 3 and Fig. 19).

UR does not publish its controller, so this module implements an APPROXIMATION of it, built from
UR's own description of MoveJ and of blending:

1. Segments. Joint waypoints q_0..q_m give m segments q_k -> q_{k+1}. Each segment follows a
   synchronised trapezoidal velocity profile q(tau) = q_k + s(tau) D_k, D_k = q_{k+1} - q_k, with
   one normalised profile s: [0, T_k] -> [0, 1] shared by all joints. s is the time-optimal
   trapezoid (triangle if the cruise speed is not reached) under ds/dt <= min_j v_j / |D_kj| and
   |d2s/dt2| <= min_j a_j / |D_kj|. With equal limits on all joints this is exactly "the leading
   axis (the one with the longest minimum time, i.e. the largest |D_kj|) runs at its velocity and
   acceleration limit, the others are scaled to finish together"; with per-joint limits the
   constraining joint reaches its limit and no joint exceeds its own.
2. Blends. With radius r > 0, around every intermediate waypoint q_k (0 < k < m) the next segment
   starts before the current one ends, while the TCP (here: the flange origin, as in Pająk 2024) is
   within r of the waypoint's TCP position p_k. On segment k-1 the TCP enters the sphere at local
   time tau_in (last time with |p(q) - p_k| = r, found by FK sampling and bisection); on segment k
   it leaves the sphere at tau_out (first such time). The overlap lasts
   delta_k = min(T_{k-1} - tau_in, tau_out) (the shorter of the two in-sphere times) and segment k
   starts at t_k = t_{k-1} + T_{k-1} - delta_k.
3. Superposition. Over the whole motion q(t) = q_0 + sum_k s_k(t - t_k) D_k (each s_k held at 0
   before and at 1 after its segment), so in an overlap the joint velocities and accelerations of
   the two segments add. Position stays C^1 and the blended TCP path stays near the waypoint but
   does not pass through it.
4. Limits in the blends (``keep_limits``, default True). In an overlap that lies within segment
   k-1's braking ramp and segment k's starting ramp, q̈ = -A_out,k-1 D_k-1 + A_in,k D_k is constant
   and q̇ is linear between two instants where only one segment moves, so both limits hold there
   if |-A_out,k-1 D_k-1,j + A_in,k D_k,j| <= a_j for every joint j. Where a joint reverses, the two
   ramps at the limit add to up to 2 a_j, so both ramps of blend k are SLOWED by the factor
   lambda_k = min(1, min_j a_j / |-A_k-1 D_k-1,j + A_k D_k,j|) (A: step 1's rates); each segment's
   trapezoid then has a starting and a braking rate of its own (the rest of the segment is as in
   step 1). The overlap is SHRUNK to at most both ramps (delta_k <= min(braking ramp of k-1,
   starting ramp of k)) when the sphere would make it longer. So the velocity and acceleration
   limits hold at every instant; the blend keeps its radius where it fits the ramps and the motion
   takes longer only where a blend reverses a joint. Overlaps of consecutive waypoints still never
   meet (one lies in a segment's starting ramp, the next in its braking ramp).

   ``keep_limits=False`` is the controller Pająk 2024 measured: the ramps at the limits superpose
   as they are, the leaving segment braking at the limit while the next accelerates at it; where a
   joint reverses direction the two add to up to twice the limit. That is the paper's flaw: the
   joint-space blend exceeds the acceleration (and may exceed the velocity) limit; the bench's
   ``movej_blend`` runs this way to reproduce experiment 1.

The TCP does not move along a straight line (this is a joint move), and the real controller's
blend shape, its handling of the speed in the blend and its radius reduction are not modelled.
Blend spheres of consecutive waypoints (including the first and last point) must not overlap:
like UR's controller, which refuses overlapping blends, a radius of half a waypoint distance or
more raises ValueError.

Consecutive identical waypoints are dropped (no zero-length segments).
"""

from bisect import bisect_right
from dataclasses import dataclass, field

import numpy as np

from drake_traj.planners.base import (TimeLawPlanner, joint_goals, joint_move_limits, planner_robot, start_and_goals,
                                     waypoint_rows)
from drake_traj.robots import UR10E, Robot
from drake_traj.validation import flag, instance_of, invalid, positive_vector

__all__ = ["MovejBlendLaw", "MovejConfig", "MovejPlanner", "blend_radius_value", "make", "trapezoid_profile"]

_SAMPLES_PER_SEGMENT = 200  # FK samples for locating the sphere crossings (then bisection)
_BISECTION_STEPS = 60


def trapezoid_profile(tau, ta: float, duration: float, accel: float, decel: float | None = None):
    """Normalised trapezoidal profile s(tau) on [0, duration] and its time derivatives.

    Accelerates at ``accel`` [1/s^2] for ``ta`` seconds, cruises at accel * ta, decelerates at
    ``decel`` (default ``accel``) over the last accel * ta / decel seconds (for a triangle the two
    ramps fill the duration); s(0) = 0, s(duration) = 1. s is held at 0 before and at 1 from
    ``duration`` on, with zero derivatives: the profile is half-open, [0, duration), so at a stop
    between two segments only the next one is active.

    Returns:
        (s, ds/dt, d2s/dt2), arrays of the shape of ``tau``.
    """
    tau = np.asarray(tau, dtype=float)
    decel = accel if decel is None else decel
    u = duration - tau
    speed = accel * ta
    braking_from = duration - speed / decel  # [s] where the braking ramp begins
    accelerating = (tau >= 0.0) & (tau < ta)
    decelerating = (tau >= braking_from) & (u > 0.0) & ~accelerating
    cruising = (tau >= ta) & (tau < braking_from)
    s = np.where(
        tau <= 0.0,
        0.0,
        np.where(
            accelerating,
            0.5 * accel * tau**2,
            np.where(cruising, 0.5 * accel * ta**2 + speed * (tau - ta), np.where(u > 0.0, 1.0 - 0.5 * decel * u**2, 1.0)),
        ),
    )
    sd = np.where(accelerating, accel * tau, np.where(cruising, speed, np.where(decelerating, decel * u, 0.0)))
    sdd = np.where(accelerating, accel, np.where(decelerating, -decel, 0.0))
    return s, sd, sdd


def _trapezoid_timing(speed: float, accel: float, decel: float) -> tuple[float, float, float]:
    """(starting ramp [s], braking ramp [s], duration [s]) of the time-optimal normalised profile
    from s = 0 to 1 at rest under ds/dt <= ``speed`` [1/s], starting rate ``accel`` and braking rate
    ``decel`` [1/s^2]: a trapezoid if the ramps to ``speed`` cover less than s = 1, else a triangle
    whose peak speed w has w^2 (1/accel + 1/decel) / 2 = 1."""
    inverse = 1.0 / accel + 1.0 / decel
    if 0.5 * speed * speed * inverse < 1.0:  # the cruise speed is reached: trapezoid
        return speed / accel, speed / decel, 1.0 / speed + 0.5 * speed * inverse
    peak = np.sqrt(2.0 / inverse)  # triangle
    return float(peak / accel), float(peak / decel), float(peak * inverse)


def blend_radius_value(blend_radius) -> float:
    """``blend_radius`` [m] as a float, finite and >= 0; ValueError naming it otherwise."""
    try:
        radius = float(blend_radius)
    except (TypeError, ValueError) as exc:
        raise invalid("blend_radius", f"blend_radius must be a number of metres: {exc}") from exc
    if not np.isfinite(radius) or radius < 0.0:
        raise invalid("blend_radius", f"blend_radius must be finite and >= 0 [m], got {blend_radius}")
    return radius


class MovejBlendLaw:
    """UR-style MoveJ through joint waypoints with radius blending, as a time law (module doc).

    Args:
        q_waypoints: joint waypoints q_0..q_m [rad], shape (m + 1, n), m >= 1; q_0 is the start.
        velocity_limit: joint speed limit [rad/s], > 0, scalar or shape (n,).
        acceleration_limit: joint acceleration limit [rad/s^2], > 0, scalar or shape (n,).
        blend_radius: r [m] >= 0 around every intermediate waypoint's TCP position; 0 stops at
            every waypoint.
        tcp_position: callable q -> TCP position (3,) [m]; default the UR10e flange origin
            (requires n = 6 when r > 0).
        keep_limits: True (default): the blends keep both limits, slowed or shrunk where they
            would not (module doc, step 4); False: the ramps superpose at the limits as on the
            controller Pająk 2024 measured, exceeding them in the blends.

    Attributes:
        q_start, q_goal (n,), duration [s], q_waypoints (m + 1, n), segment_starts (m,),
        segment_durations (m,), blend_overlaps (m - 1,) [s] (delta_k, 0 without blending),
        segment_accels, segment_decels (m,) [1/s^2] (each segment's starting and braking rate of
        s), segment_ramps, segment_brakes (m,) [s] (their ramps' durations), blend_slowdowns
        (m - 1,) (lambda_k, 1 where a blend needs no slowing or without ``keep_limits``).
    """

    # q̈ jumps where each trapezoid's ramps begin and end: None lets the planner set the reference
    # back on the law at every update (the TimeLaw contract)
    acceleration_jumps = None

    def __init__(self, q_waypoints, velocity_limit, acceleration_limit, blend_radius: float = 0.0, *, tcp_position=None,
                 keep_limits: bool = True):
        waypoints = waypoint_rows(q_waypoints)
        n = waypoints.shape[1]
        self.num_joints = n
        self.velocity_limit = positive_vector(velocity_limit, "velocity_limit", n)
        self.acceleration_limit = positive_vector(acceleration_limit, "acceleration_limit", n)
        self.blend_radius = radius = blend_radius_value(blend_radius)
        self.keep_limits = flag(keep_limits, "keep_limits")
        if tcp_position is None:
            if radius > 0.0 and n != UR10E.num_joints:
                raise ValueError(f"tcp_position is required for blending with n = {n} joints (the default is the UR10e flange)")
            tcp_position = UR10E.tool_position
        self._tcp = tcp_position

        keep = np.concatenate([[True], np.any(np.diff(waypoints, axis=0) != 0.0, axis=1)])
        waypoints = waypoints[keep]
        self.q_waypoints = waypoints
        self.q_start = waypoints[0].copy()
        self.q_goal = waypoints[-1].copy()
        displacements = np.diff(waypoints, axis=0)  # D_k, (m, n)
        m = len(displacements)
        self.displacements = displacements
        speeds, rates = self._segment_rates(displacements)
        slowdowns = self._blend_slowdowns(displacements, rates)
        self.blend_slowdowns = slowdowns
        self.segment_accels = rates * np.append(1.0, slowdowns)[:m]  # lambda of the blend before
        self.segment_decels = rates * np.append(slowdowns, 1.0)[:m]  # lambda of the blend after
        timings = [_trapezoid_timing(*row) for row in zip(speeds, self.segment_accels, self.segment_decels)]
        ramps, brakes, durations = np.array(timings, dtype=float).reshape(m, 3).T.copy()
        self.segment_ramps, self.segment_brakes, self.segment_durations = ramps, brakes, durations
        overlaps = self._blend_overlaps()
        if self.keep_limits:  # within the braking ramp before and the starting ramp after (step 4)
            overlaps = np.minimum(overlaps, np.minimum(brakes[:-1], ramps[1:]))
        self.blend_overlaps = overlaps

        starts = np.zeros(m)
        for k in range(1, m):
            starts[k] = starts[k - 1] + durations[k - 1] - overlaps[k - 1]
        self.segment_starts = starts
        self.duration = float(starts[-1] + durations[-1]) if m else 0.0
        # every joint is one quadratic between the segments' starts, ramp ends and ends [s]
        ramps_at = np.array([np.zeros(m), ramps, durations - brakes, durations])
        self.polynomial_breaks = np.unique(np.append(starts + ramps_at, 0.0))
        # Plain-Python copies for the scalar hot path.
        self._starts = starts.tolist()
        self._segments = list(zip(durations.tolist(), ramps.tolist(), (durations - brakes).tolist(),
                                  self.segment_accels.tolist(), self.segment_decels.tolist(),
                                  [d.copy() for d in displacements]))
        self._zero = np.zeros(n)

    def _segment_rates(self, displacements) -> tuple[np.ndarray, np.ndarray]:
        """Per segment D_k (m, n) [rad], the largest speed [1/s] and rate [1/s^2] of its
        normalised profile s under every joint's limits (module doc, step 1), each (m,)."""
        speeds, rates = [], []
        for d in displacements:
            size = np.abs(d)
            moving = size > 0.0
            speeds.append(np.min(self.velocity_limit[moving] / size[moving]))
            rates.append(np.min(self.acceleration_limit[moving] / size[moving]))
        return np.array(speeds, dtype=float), np.array(rates, dtype=float)

    def _blend_slowdowns(self, displacements, rates) -> np.ndarray:
        """lambda_k (m - 1,) of every intermediate waypoint: the factor on the braking ramp before
        it and the starting ramp after it that keeps their sum within the acceleration limit
        (module doc, step 4); 1 without blending or without ``keep_limits``."""
        slowdowns = np.ones(max(len(rates) - 1, 0))
        if self.keep_limits and self.blend_radius > 0.0:
            for k in range(1, len(rates)):
                superposed = np.abs(rates[k] * displacements[k] - rates[k - 1] * displacements[k - 1])
                slowdowns[k - 1] = min(1.0, float(np.min(self.acceleration_limit / np.maximum(superposed, 1e-300))))
        return slowdowns

    def _blend_overlaps(self) -> np.ndarray:
        """delta_k [s] (m - 1,) of every intermediate waypoint as the blend spheres give it (module
        doc, step 2; 0 without blending); ValueError where the spheres of two waypoints overlap."""
        m = len(self.segment_durations)
        overlaps = np.zeros(max(m - 1, 0))
        radius = self.blend_radius
        if radius > 0.0 and m >= 1:
            points = np.array([self._tcp(q) for q in self.q_waypoints])
            gaps = np.linalg.norm(np.diff(points, axis=0), axis=1)
            if np.any(2.0 * radius >= gaps):
                k = int(np.argmin(gaps))
                raise ValueError(
                    f"blend_radius = {radius} m is too large: the TCP positions of waypoints {k} and {k + 1} are "
                    f"{gaps[k]:.4f} m apart, blend spheres must not overlap (radius < {0.5 * gaps.min():.4f} m)"
                )
            for k in range(1, m):
                tau_in = self._sphere_crossing(k - 1, points[k], last=True)
                tau_out = self._sphere_crossing(k, points[k], last=False)
                overlaps[k - 1] = min(self.segment_durations[k - 1] - tau_in, tau_out)
        return overlaps

    def _sphere_crossing(self, k, centre, *, last):
        """Local time on segment k where |tcp - centre| = r: the last (entering) or first (leaving)."""
        q0, d, r = self.q_waypoints[k], self.q_waypoints[k + 1] - self.q_waypoints[k], self.blend_radius
        durations = self.segment_durations

        def distance(tau):
            s, _, _ = trapezoid_profile(tau, self.segment_ramps[k], durations[k], self.segment_accels[k],
                                        self.segment_decels[k])
            return float(np.linalg.norm(self._tcp(q0 + float(s) * d) - centre))

        taus = np.linspace(0.0, durations[k], _SAMPLES_PER_SEGMENT + 1)
        outside = np.array([distance(t) >= r for t in taus])
        if last:  # the segment ends at the centre (inside); last sample outside, then bisect forwards
            index = np.flatnonzero(outside)
            if not len(index):
                return 0.0
            lo, hi = taus[index[-1]], taus[min(index[-1] + 1, len(taus) - 1)]
            inside_at_hi = True
        else:  # the segment starts at the centre; first sample outside, bisect backwards
            index = np.flatnonzero(outside)
            if not len(index):
                return durations[k]
            lo, hi = taus[max(index[0] - 1, 0)], taus[index[0]]
            inside_at_hi = False
        for _ in range(_BISECTION_STEPS):
            mid = 0.5 * (lo + hi)
            if (distance(mid) < r) == inside_at_hi:
                hi = mid
            else:
                lo = mid
        return 0.5 * (lo + hi)

    # --- evaluation ----------------------------------------------------------------------------
    def rates_at(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """(qd [rad/s], qdd [rad/s^2]) at law time ``tau`` [s]: the planner's hot path.

        At most two segments are active at once (blend spheres do not overlap), so this checks the
        segment that started last before ``tau`` and its predecessor.
        """
        k = bisect_right(self._starts, tau) - 1
        if k < 0:
            return self._zero.copy(), self._zero.copy()
        qd = None
        qdd = None
        for j in (k - 1, k) if k > 0 else (k,):
            local = tau - self._starts[j]
            duration, ta, braking_from, acc, dec, d = self._segments[j]
            if local < 0.0 or local >= duration:  # segments are half-open [t_k, t_k + T_k)
                continue
            if local < ta:
                sd, sdd = acc * local, acc
            elif local < braking_from:
                sd, sdd = acc * ta, 0.0
            else:
                sd, sdd = dec * (duration - local), -dec
            if qd is None:
                qd, qdd = sd * d, sdd * d
            else:
                qd = qd + sd * d
                qdd = qdd + sdd * d
        if qd is None:
            return self._zero.copy(), self._zero.copy()
        return qd, qdd

    def sample(self, t):
        """(q [rad], qd [rad/s], qdd [rad/s^2]) at law times ``t`` [s], each of shape t.shape + (n,).

        q = q_0 + sum_k s_k(t - t_k) D_k (superposed segments); before 0 the law rests at q_0, after
        its duration at the last waypoint.
        """
        t = np.asarray(t, dtype=float)
        flat = t.reshape(-1)
        q = np.tile(self.q_start, (len(flat), 1))
        qd = np.zeros_like(q)
        qdd = np.zeros_like(q)
        for k, d in enumerate(self.displacements):
            s, sd, sdd = trapezoid_profile(flat - self.segment_starts[k], self.segment_ramps[k], self.segment_durations[k],
                                           self.segment_accels[k], self.segment_decels[k])
            q += s[:, None] * d
            qd += sd[:, None] * d
            qdd += sdd[:, None] * d
        if len(self.displacements):
            q[flat >= self.duration] = self.q_goal  # exact end (no rounding of the sum)
        shape = t.shape + (self.num_joints,)
        return q.reshape(shape), qd.reshape(shape), qdd.reshape(shape)

    def blend_intervals(self) -> np.ndarray:
        """(start, end) law times [s] of the overlaps, shape (m - 1, 2); start == end without blending."""
        ends = self.segment_starts[:-1] + self.segment_durations[:-1]
        return np.stack([ends - self.blend_overlaps, ends], axis=1) if len(ends) else np.zeros((0, 2))

    def tcp_positions(self) -> np.ndarray:
        """TCP positions of the waypoints q_0..q_m [m], shape (m + 1, 3)."""
        return np.array([self._tcp(q) for q in self.q_waypoints])


class MovejPlanner(TimeLawPlanner):
    """Planner system for a :class:`MovejBlendLaw` (UR MoveJ baseline, see the module doc).

    The promised limits are the law's: they hold at every instant with the law's ``keep_limits``
    (the default); without it the blends exceed them as on the controller Pająk 2024 measured,
    while without blending the reference respects them either way.

    Args:
        law: the MoveJ time law.
        speed_cap: the largest clock rate c, in (0, 1].
        update_period: how often the speed override is read [s].
        robot: the robot (for the tool positions at the waypoints).
    """

    target_word = "goal"  # the config's goals: a refusal is "on the way to goal k"

    def __init__(self, law: MovejBlendLaw, *, speed_cap: float = 1.0, update_period: float = 0.001,
                 robot: Robot = UR10E):
        instance_of(law, MovejBlendLaw, "law")
        super().__init__(law, law.velocity_limit, law.acceleration_limit, speed_cap=speed_cap, update_period=update_period)
        self.robot = planner_robot(robot, self.num_joints)

    def task_waypoints(self) -> np.ndarray:
        """Tool positions at the goal waypoints q_1..q_m [m], shape (m, 3)."""
        return self.robot.tool_position(self.law.q_waypoints[1:])


@dataclass
class MovejConfig:
    """The UR-style MoveJ baseline through joint goals: the scenario's ``planner: !MovejConfig``.

    Attributes:
        goals: joint waypoints after the start [rad], one row of n per waypoint.
        blend_radius: r [m] around every intermediate waypoint's tool position; 0 stops at each.
        velocity_limit, acceleration_limit: per joint; empty: the robot's joint-move limits.
        keep_limits: True: the blends keep both limits (slowed or shrunk where they would not);
            False: they superpose the ramps at the limits and exceed them, as Pająk 2024 measured
            on the UR controller (the bench's ``movej_blend``).
    """

    goals: list[list[float]] = field(default_factory=list)
    blend_radius: float = 0.0
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)
    keep_limits: bool = True

    def validate(self, robot: Robot = UR10E) -> "MovejConfig":
        """The config, its own fields checked for ``robot`` as :func:`make` checks them first:
        the goals (rows of n joint positions [rad]), the limits (the robot's where empty), the
        blend radius, ``keep_limits``; ValueError naming the field (blend spheres that overlap are
        the law's)."""
        joint_goals(self.goals, robot.num_joints)
        joint_move_limits(robot, self.velocity_limit, self.acceleration_limit)
        blend_radius_value(self.blend_radius)
        flag(self.keep_limits, "keep_limits")
        return self


def make(config: MovejConfig, robot: Robot, q_initial) -> MovejPlanner:
    """The baseline of ``config`` on ``robot`` from ``q_initial`` (the config checked first:
    :meth:`MovejConfig.validate`)."""
    config.validate(robot)
    q = start_and_goals(q_initial, config.goals, robot.num_joints)
    velocity, acceleration = joint_move_limits(robot, config.velocity_limit, config.acceleration_limit)
    law = MovejBlendLaw(q, velocity, acceleration, config.blend_radius, tcp_position=robot.tool_position,
                        keep_limits=config.keep_limits)
    return MovejPlanner(law, robot=robot)
