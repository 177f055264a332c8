"""The loop path in time (Boryga, sections 1 and 2.3-2.5, eq. 1-14): the 7th-degree profile
(eq. 1-6), the timing of the five phases (eq. 7-14, :class:`LoopTiming`) and the tool's position,
velocity, acceleration and jerk along the path (:class:`LoopPath`, base frame xyz [m], time [s])."""

from dataclasses import dataclass

import numpy as np

from drake_traj.planners.boryga.geometry import LoopGeometry, loop_geometry
from drake_traj.validation import positive_scalar

__all__ = ["PHASES", "LoopPath", "LoopTiming", "loop_timing", "plan_loop_path", "poly7_profile", "poly7_timing"]

# Phases of the motion, in time order (index into LoopPath.breakpoints).
PHASES = ("BM", "MT1", "arc", "T2M", "ME")


# --------------------------------------------------------------------------------------------
# The 7th-degree acceleration profile (section 1, eq. 1-6).
# --------------------------------------------------------------------------------------------


def _horner(coefficients, t):
    """sum_k coefficients[k] t^k, evaluated in Horner form."""
    result = np.zeros_like(t) + coefficients[-1]
    for c in reversed(coefficients[:-1]):
        result = result * t + c
    return result


def poly7_profile(t, t_f: float, p: float):
    """Displacement, velocity, acceleration and jerk of the 7th-degree profile (eq. 1-3).

    a(t) = -p t^2 (t - t_f/2)^3 (t - t_f)^2 (eq. 1), v = integral of a from 0 (eq. 2),
    s = integral of v from 0 (eq. 3), j = da/dt. On [0, t_f] the motion starts and ends at rest;
    a and j vanish at 0, t_f / 2 and t_f; v peaks at t_f / 2 with p t_f^8 / 6144 and
    s(t_f) = p t_f^9 / 10080 (eq. 6). The polynomials are evaluated as written for any t (no
    clipping): callers pick the half they use.

    Args:
        t: time from the start of the (full) profile [s], scalar or array of any shape.
        t_f: the full profile's duration [s] (2 t^BM on segment BM, eq. 7).
        p: the polynomial coefficient [m/s^9] (eq. 9).

    Returns:
        (s [m], v [m/s], a [m/s^2], j [m/s^3]), each with the shape of ``t``.
    """
    t = np.asarray(t, dtype=float)
    h = 0.5 * t_f
    # eq. 1
    a = -p * t**2 * (t - h) ** 3 * (t - t_f) ** 2
    # d/dt of eq. 1, factored:
    # j = -p t (t - h)^2 (t - t_f) [2 (t - h)(t - t_f) + 3 t (t - t_f) + 2 t (t - h)]
    j = -p * t * (t - h) ** 2 * (t - t_f) * (
        2.0 * (t - h) * (t - t_f) + 3.0 * t * (t - t_f) + 2.0 * t * (t - h)
    )
    # eq. 2 in Horner form (coefficients of t^3 ... t^8).
    c2 = (
        -(t_f**5) / 24.0, t_f**4 / 4.0, -5.0 * t_f**3 / 8.0, 19.0 * t_f**2 / 24.0,
        -t_f / 2.0, 1.0 / 8.0,
    )
    v = -p * t**3 * _horner(c2, t)
    # eq. 3 in Horner form (coefficients of t^4 ... t^9).
    c3 = (
        -(t_f**5) / 96.0, t_f**4 / 20.0, -5.0 * t_f**3 / 48.0, 19.0 * t_f**2 / 168.0,
        -t_f / 16.0, 1.0 / 72.0,
    )
    s = -p * t**4 * _horner(c3, t)
    return s[()], v[()], a[()], j[()]


def poly7_timing(delta_s, v_max) -> tuple[float, float]:
    """Duration t_f and coefficient p of a full 7th-degree profile covering ``delta_s`` (eq. 6).

    Solves p t_f^8 / 6144 = v_max and p t_f^9 / 10080 = delta_s:
    t_f = (10080 / 6144) delta_s / v_max = (105 / 64) delta_s / v_max and p = 10080 delta_s / t_f^9.
    The loop planner uses half profiles: with t_f = 2 t^BM and delta_s = 2 delta_s^BM this gives
    eq. 7 and eq. 9.

    Args:
        delta_s: path length of the full profile [m], > 0.
        v_max: peak speed [m/s], > 0 (reached at t_f / 2, eq. 4-5).

    Returns:
        (t_f [s], p [m/s^9]).
    """
    delta_s = positive_scalar(delta_s, "delta_s", "m")
    v_max = positive_scalar(v_max, "v_max", "m/s")
    t_f = 10080.0 / 6144.0 * delta_s / v_max  # eq. 6, second row divided by the first
    p = 10080.0 * delta_s / t_f**9  # eq. 6, second row
    return t_f, p


# --------------------------------------------------------------------------------------------
# Time law (sections 2.3-2.5, eq. 7-14).
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LoopTiming:
    """Times and polynomial coefficients of the loop path (eq. 7-14).

    Built by :func:`loop_timing`. The motion starts at t = 0 at B.

    Attributes:
        v_max: speed on the loop and peak speed on BM and ME [m/s].
        t_BM: time on BM, (105/64) ds_BM / v_max [s] (eq. 7).
        t_MT1: time on MT1, ds_MT1 / v_max [s] (eq. 8).
        t_BT1: t_BM + t_MT1 [s].
        t_A: time on the arc T1 -> T2, beta R / v_max [s] (eq. 10).
        t_T2M: time on T2M, equal to t_MT1 [s].
        t_ME: time on ME, eq. 7 with ds_ME [s].
        t_T2E: t_T2M + t_ME [s].
        p_BM: coefficient of the start-up profile on BM, 315 ds_BM / (8 t_BM^9) [m/s^9] (eq. 9).
        p_ME: coefficient of the braking profile on ME, eq. 9 with ds_ME, t_ME [m/s^9].
        tau: time shift of the ME profile, t_BT1 + t_A + t_T2M - t_ME [s] (eq. 13): the full
            profile of duration 2 t_ME starts at tau, and its second (braking) half is used.
        t_e: total time t_BT1 + t_A + t_T2E [s] (eq. 14).
    """

    v_max: float
    t_BM: float
    t_MT1: float
    t_BT1: float
    t_A: float
    t_T2M: float
    t_ME: float
    t_T2E: float
    p_BM: float
    p_ME: float
    tau: float
    t_e: float

    @property
    def t_M1(self) -> float:
        """First pass through M [s]."""
        return self.t_BM

    @property
    def t_T1(self) -> float:
        """Arrival at T1 [s]."""
        return self.t_BT1

    @property
    def t_T2(self) -> float:
        """Arrival at T2 [s]."""
        return self.t_BT1 + self.t_A

    @property
    def t_M2(self) -> float:
        """Second pass through M [s]: tau + t_ME (eq. 13)."""
        return self.t_BT1 + self.t_A + self.t_T2M

    @property
    def loop_time(self) -> float:
        """Time between the two passes through M [s]."""
        return self.t_MT1 + self.t_A + self.t_T2M


def loop_timing(geometry: LoopGeometry, v_max) -> LoopTiming:
    """Times and coefficients of the motion along ``geometry`` at loop speed ``v_max``.

    Args:
        geometry: from :func:`loop_geometry`.
        v_max: loop speed and peak speed on the straight segments [m/s], > 0.

    Returns:
        LoopTiming.

    Raises:
        ValueError: ``geometry`` is not a LoopGeometry, or v_max is not a finite number > 0.
    """
    if not isinstance(geometry, LoopGeometry):
        raise ValueError(
            f"geometry must be a LoopGeometry (from loop_geometry), got {type(geometry).__name__}"
        )
    v_max = positive_scalar(v_max, "v_max", "m/s")
    g = geometry
    t_BM = 105.0 / 64.0 * g.ds_BM / v_max  # eq. 7
    t_MT1 = g.ds_MT1 / v_max  # eq. 8
    t_BT1 = t_BM + t_MT1
    p_BM = 315.0 * g.ds_BM / (8.0 * t_BM**9)  # eq. 9
    t_A = g.beta * g.R / v_max  # eq. 10
    t_T2M = t_MT1  # section 2.4 (second): same as MT1
    t_ME = 105.0 / 64.0 * g.ds_ME / v_max  # eq. 7 with ds_ME
    t_T2E = t_T2M + t_ME
    p_ME = 315.0 * g.ds_ME / (8.0 * t_ME**9)  # eq. 9 with ds_ME, t_ME
    tau = t_BT1 + t_A + t_T2M - t_ME  # eq. 13
    t_e = t_BT1 + t_A + t_T2E  # eq. 14
    return LoopTiming(
        v_max=v_max,
        t_BM=t_BM,
        t_MT1=t_MT1,
        t_BT1=t_BT1,
        t_A=t_A,
        t_T2M=t_T2M,
        t_ME=t_ME,
        t_T2E=t_T2E,
        p_BM=p_BM,
        p_ME=p_ME,
        tau=tau,
        t_e=t_e,
    )


# --------------------------------------------------------------------------------------------
# The plan: sampling position, velocity, acceleration and jerk.
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LoopPath:
    """The loop path in time: B at rest at t = 0, E at rest at t = duration.

    Phases (``PHASES``), on [breakpoints[k], breakpoints[k + 1]):
    "BM" start-up half of eq. 1-3 (t_f = 2 t_BM, p = p_BM) along a_hat; "MT1" and "T2M" constant
    v_max along a_hat and -d_hat; "arc" eq. 11-12 at constant v_max; "ME" braking half of eq. 1-3
    (t_f = 2 t_ME, p = p_ME) shifted by tau (eq. 13) along -d_hat. Before t = 0 the plan rests at
    B, after t_e at E.

    Attributes:
        geometry: the path (section 2.2).
        timing: the time law (eq. 7-14).
    """

    geometry: LoopGeometry
    timing: LoopTiming

    def __post_init__(self) -> None:
        if not isinstance(self.geometry, LoopGeometry):
            raise ValueError(f"geometry must be a LoopGeometry, got {type(self.geometry).__name__}")
        if not isinstance(self.timing, LoopTiming):
            raise ValueError(f"timing must be a LoopTiming, got {type(self.timing).__name__}")

    @property
    def duration(self) -> float:
        """t_e [s] (eq. 14)."""
        return self.timing.t_e

    @property
    def path_length(self) -> float:
        """Total path length [m]."""
        return self.geometry.path_length

    @property
    def v_max(self) -> float:
        """Loop speed [m/s]."""
        return self.timing.v_max

    @property
    def breakpoints(self) -> np.ndarray:
        """Start times of the phases BM, MT1, arc, T2M, ME followed by t_e [s], shape (6,).

        These are the times at B, M (first pass), T1, T2, M (second pass) and E.
        """
        tl = self.timing
        return np.array([0.0, tl.t_M1, tl.t_T1, tl.t_T2, tl.t_M2, tl.t_e])

    @property
    def junctions(self) -> dict[str, float]:
        """Times of the characteristic points {"B", "M1", "T1", "T2", "M2", "E"} [s]."""
        return dict(zip(("B", "M1", "T1", "T2", "M2", "E"), self.breakpoints.tolist()))

    @property
    def breakpoint_arc_lengths(self) -> np.ndarray:
        """Distance travelled at each breakpoint [m], shape (6,)."""
        g = self.geometry
        return np.cumsum([0.0, g.ds_BM, g.ds_MT1, g.ds_arc, g.ds_T2M, g.ds_ME])

    def phase_index(self, t, side: str = "right") -> np.ndarray:
        """Index into ``PHASES`` of each time: -1 before B, 5 after E (at rest).

        Args:
            t: time [s], scalar or array of any shape.
            side: "right" (a junction time belongs to the phase that starts there) or "left"
                (to the phase that ends there), to read the one-sided limits at the junctions.
        """
        if side not in ("left", "right"):
            raise ValueError(f"side must be 'left' or 'right', got {side!r}")
        t = np.asarray(t, dtype=float)
        return np.searchsorted(self.breakpoints, t, side=side) - 1

    def _times(self, t) -> np.ndarray:
        try:
            array = np.array(t, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ValueError(
                f"t must be a real number or an array of real numbers [s]: {exc}"
            ) from exc
        if not np.all(np.isfinite(array)):
            raise ValueError("t must be finite [s]")
        return array

    def _on_arc(self, t: np.ndarray):
        """Position [m], velocity [m/s], acceleration [m/s^2] and jerk [m/s^3] on the arc at times
        ``t`` [s] of shape (N,), each (N, 3) in the base frame xyz."""
        g, v = self.geometry, self.timing.v_max
        # beta(t) = beta_b + (v_max / R)(t - t_BT1) (eq. 11), S^A = T Xi^A (eq. 12) and its time
        # derivatives (centripetal acceleration v^2 / R towards O1).
        omega = v / g.R
        angle = g.beta_b + omega * (t - self.timing.t_T1)
        c = np.cos(angle)[:, None]
        s = np.sin(angle)[:, None]
        radial = c * g.xi + s * g.eta  # unit vector from O1 to the tool
        tangent = -s * g.xi + c * g.eta  # unit direction of motion
        return g.O1 + g.R * radial, v * tangent, -(v * omega) * radial, -(v * omega**2) * tangent

    def sample(self, t, side: str = "right"):
        """Position, velocity, acceleration and jerk of the tool at time ``t`` (base frame xyz).

        Acceleration is discontinuous at T1 and T2 (jump v_max^2 / R, centripetal on the arc) and
        jerk at every junction where the polynomial meets a constant-speed part; ``side`` selects
        which one-sided value is returned exactly at a junction time. Position and velocity are
        continuous everywhere.

        Args:
            t: time [s], scalar or array of any shape (finite).
            side: "right" (default) or "left", see :meth:`phase_index`.

        Returns:
            (position [m], velocity [m/s], acceleration [m/s^2], jerk [m/s^3]), each of shape
            t.shape + (3,): (3,) for scalar t, (N, 3) for t of shape (N,).
        """
        t_array = self._times(t)
        shape = t_array.shape
        tt = t_array.reshape(-1)
        phase = self.phase_index(tt, side=side)
        g, tl = self.geometry, self.timing
        v = tl.v_max
        n = tt.size
        pos = np.empty((n, 3))
        vel = np.zeros((n, 3))
        acc = np.zeros((n, 3))
        jerk = np.zeros((n, 3))

        pos[phase < 0] = g.B
        pos[phase >= len(PHASES)] = g.E

        # BM: start-up half of eq. 1-3 with t_f = 2 t_BM, p = p_BM (section 2.3), along a_hat.
        k = phase == 0
        if np.any(k):
            s, sd, sdd, sddd = poly7_profile(tt[k], 2.0 * tl.t_BM, tl.p_BM)
            pos[k] = g.B + s[:, None] * g.a_hat
            vel[k] = sd[:, None] * g.a_hat
            acc[k] = sdd[:, None] * g.a_hat
            jerk[k] = sddd[:, None] * g.a_hat

        # MT1: constant v_max along a_hat (eq. 8).
        k = phase == 1
        if np.any(k):
            pos[k] = g.M + (v * (tt[k] - tl.t_M1))[:, None] * g.a_hat
            vel[k] = v * g.a_hat

        # Arc: eq. 11-12 at constant v_max (:meth:`_on_arc`).
        k = phase == 2
        if np.any(k):
            pos[k], vel[k], acc[k], jerk[k] = self._on_arc(tt[k])

        # T2M: constant v_max along -d_hat (time t_T2M = t_MT1).
        k = phase == 3
        if np.any(k):
            pos[k] = g.T2 - (v * (tt[k] - tl.t_T2))[:, None] * g.d_hat
            vel[k] = -v * g.d_hat

        # ME: braking half of eq. 1-3 with t_f = 2 t_ME, p = p_ME, shifted by tau (eq. 13):
        # local time t' = t - tau in [t_ME, 2 t_ME]. By the profile's symmetry about t_f / 2
        # (a odd, v even), s(t') = ds_ME - s(t_f - t'), so with u = t_f - t' = t_e - t the
        # position is E + s(u) d_hat: the remaining distance to E, which lands on E exactly.
        k = phase == 4
        if np.any(k):
            u = tl.t_e - tt[k]
            s, sd, sdd, sddd = poly7_profile(u, 2.0 * tl.t_ME, tl.p_ME)
            pos[k] = g.E + s[:, None] * g.d_hat
            vel[k] = -sd[:, None] * g.d_hat
            acc[k] = sdd[:, None] * g.d_hat
            jerk[k] = -sddd[:, None] * g.d_hat

        out = tuple(x.reshape(shape + (3,)) for x in (pos, vel, acc, jerk))
        return out

    def arc_length(self, t, side: str = "right") -> np.ndarray:
        """Distance travelled along the path from B at time ``t`` [m] (0 before, L after).

        Args:
            t: time [s], scalar or array of any shape (finite).
            side: "right" or "left" at junction times (the value is continuous either way).

        Returns:
            Array with the shape of ``t`` (a numpy scalar for scalar ``t``).
        """
        t_array = self._times(t)
        tt = t_array.reshape(-1)
        phase = self.phase_index(tt, side=side)
        tl = self.timing
        start = self.breakpoint_arc_lengths
        times = self.breakpoints
        s = np.where(phase < 0, 0.0, self.path_length)
        k = phase == 0
        s[k] = poly7_profile(tt[k], 2.0 * tl.t_BM, tl.p_BM)[0]
        for index in (1, 2, 3):  # constant speed on MT1, the arc and T2M
            k = phase == index
            s[k] = start[index] + tl.v_max * (tt[k] - times[index])
        k = phase == 4
        s[k] = self.path_length - poly7_profile(tl.t_e - tt[k], 2.0 * tl.t_ME, tl.p_ME)[0]
        return s.reshape(t_array.shape)[()]

    def speed(self, t, side: str = "right") -> np.ndarray:
        """Path speed |velocity| at time ``t`` [m/s], with the shape of ``t``."""
        return np.linalg.norm(self.sample(t, side=side)[1], axis=-1)[()]


def plan_loop_path(B, M, E, v_max, delta=None, radius=None) -> LoopPath:
    """Plan the motion B -> M -> loop -> M -> E of Boryga (section 2, eq. 1-14).

    Args:
        B: start point [m], shape (3,).
        M: corner [m], shape (3,), passed twice.
        E: end point [m], shape (3,).
        v_max: loop speed and peak speed on BM and ME [m/s], > 0.
        delta: distance Delta from M to the loop centre [m], > 0 (or give ``radius``).
        radius: loop radius R [m], > 0 (or give ``delta``).

    Returns:
        LoopPath starting at rest at B at t = 0 and ending at rest at E at t = duration.

    Raises:
        ValueError: see :func:`loop_geometry` and :func:`loop_timing`.
    """
    geometry = loop_geometry(B, M, E, delta=delta, radius=radius)
    return LoopPath(geometry, loop_timing(geometry, v_max))
