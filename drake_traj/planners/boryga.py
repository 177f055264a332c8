"""Rectilinear path with a loop through the corner: geometry and time law (Boryga, Boryga).

Boryga (M. Boryga, "Trajectory Planning of an End-Effector for Path with Loop") moves the tool
from B to E through a sharp corner M without stopping there. The path is two straight segments,
B -> M and M -> E, joined by a loop through the corner:

    B --(7th-degree start-up)--> M --(v_max)--> T1 --(arc about O1, v_max)--> T2 --(v_max)--> M
      --(7th-degree braking)--> E

The tool passes M twice; the time between the two passes is the loop time. On B -> M the
acceleration is the first (start-up) half of the 7th-degree profile of eq. 1, so the tool leaves B
at rest and reaches M at v_max with zero acceleration (and zero jerk). M -> T1, the arc T1 -> T2 and
T2 -> M run at the constant speed v_max. On M -> E the acceleration is the second (braking) half of
the profile, so the tool stops at E with zero acceleration. The loop circle of radius R is centred
at O1 on the bisector of the angle BME, at distance Delta from M, and is tangent to the extensions
of BM and EM beyond M at T1 and T2 (section 2.2).

Equation numbers below are the paper's. The corrections in docs/papers.md are trusted over the OCR'd
text: the paper's p_BM of 4.46156e4 m/s^9 transposes digits (4.46516e4), its t_e = 0.815 s is a sum
of rounded parts (0.81368 s), its total path 0.152 m is 0.15217 m (the 0.036 m it gives "on the
loop" is the arc alone), its frame "zeta-eta-zeta" is xi-eta-zeta, and the start angle is beta_b in
eq. 11 and beta_p in section 3 (both pi - beta/2). The transformation T of eq. 12 is not given in
the paper; the construction of docs/papers.md is used: xi = (M - O1) / Delta, zeta = unit(a_hat x d_hat),
eta = zeta x xi, origin O1. With it the arc starts at T1 tangent to BM and ends at T2 heading
towards M along EM.

Geometric note (why no "loop crosses a segment" check exists): the loop circle is tangent to the
line BM at T1 and to the line EM at T2, so it lies on one side of each line and meets each line
only at its tangent point; T1 and T2 lie beyond M (M + l a_hat and M + l d_hat with l > 0), not on
the segments BM and ME. The path therefore touches itself only at M, for any B, M, E with a real
corner and any Delta > 0. What can fail is the input: coincident or collinear points (no corner, no
loop), non-positive or non-finite sizes and speeds, or a radius R and a distance Delta given
together that do not fit the corner (R must equal Delta sin(angle BME / 2)).

Everything here is plain numpy: tests call it directly and the planner system (later) is a thin
shell around it. Positions are in the base frame xyz [m]; times in seconds.
"""

from dataclasses import dataclass, field

import numpy as np

from drake_traj.planners.base import HermiteLaw, TimeLawPlanner
from drake_traj.robots import Robot
from drake_traj.robots.base import format_point
from drake_traj.validation import finite_array, limit_or_default, positive_scalar, real_array

__all__ = [
    "PHASES",
    "LoopGeometry",
    "LoopPathPlan",
    "LoopTimeLaw",
    "loop_geometry",
    "loop_time_law",
    "plan_loop_path",
    "poly7_profile",
    "poly7_timing",
]

# sin(angle BME) below this counts as collinear: no corner (angle 0 or pi to within ~1e-7 rad).
# Near those angles the bisector b = a_hat + d_hat (angle pi) or the radius (angle 0) vanish and
# the construction loses all accuracy.
_COLLINEAR_SIN_TOL = 1e-7
# Relative tolerance for a radius and a Delta given together to count as the same loop.
_FIT_RTOL = 1e-9

# Phases of the motion, in time order (index into LoopPathPlan.breakpoints).
PHASES = ("BM", "MT1", "arc", "T2M", "ME")


# --------------------------------------------------------------------------------------------
# Input validation helpers (messages always name the argument and the reason).
# --------------------------------------------------------------------------------------------


def _readonly(array: np.ndarray) -> np.ndarray:
    array = np.array(array, dtype=float)
    array.setflags(write=False)
    return array


def _unit(vector: np.ndarray) -> np.ndarray:
    return vector / np.linalg.norm(vector)


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
# Path geometry (section 2.2).
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class LoopGeometry:
    """Geometry of the path B -> M -> T1 -> (arc) -> T2 -> M -> E (section 2.2, Table 1).

    Built by :func:`loop_geometry`. All points and vectors are in the base frame xyz; arrays are
    read-only copies.

    Attributes:
        B, M, E: start point, corner and end point [m], shape (3,).
        delta: Delta, distance from M to the loop centre O1 [m].
        R: loop radius [m], the distance from O1 to the line BM (and to the line EM).
        corner_angle: the angle BME [rad], in (0, pi).
        a_hat: unit vector of a = M - B (direction of motion on BM and MT1).
        d_hat: unit vector of d = M - E (the motion on T2M and ME is along -d_hat).
        b_hat: unit vector of b = a_hat + d_hat, the bisector of the angle BME, pointing away
            from the corner's inside (towards O1).
        O1: loop centre, M + Delta b_hat [m].
        T1: tangent point on the extension of BM beyond M, M + ds_MT1 a_hat [m].
        T2: tangent point on the extension of EM beyond M, M + ds_T2M d_hat [m].
        beta: arc angle T1 -> T2 about O1 [rad]: pi + the angle between a_hat and d_hat.
        beta_b: start angle of the arc in the xi-eta plane, pi - beta / 2 [rad] (eq. 11; called
            beta_p in the paper's section 3).
        xi, eta, zeta: axes of the local frame of eq. 12 (docs/papers.md): xi = (M - O1) / Delta,
            zeta = unit(a_hat x d_hat), eta = zeta x xi. Right-handed, orthonormal.
        ds_BM, ds_MT1, ds_arc, ds_T2M, ds_ME: path increments of the five parts [m]
            (ds_arc = beta R is the paper's Delta s^A).
    """

    B: np.ndarray
    M: np.ndarray
    E: np.ndarray
    delta: float
    R: float
    corner_angle: float
    a_hat: np.ndarray
    d_hat: np.ndarray
    b_hat: np.ndarray
    O1: np.ndarray
    T1: np.ndarray
    T2: np.ndarray
    beta: float
    beta_b: float
    xi: np.ndarray
    eta: np.ndarray
    zeta: np.ndarray
    ds_BM: float
    ds_MT1: float
    ds_arc: float
    ds_T2M: float
    ds_ME: float

    @property
    def ds_loop(self) -> float:
        """Path length of the whole loop M -> T1 -> T2 -> M [m]."""
        return self.ds_MT1 + self.ds_arc + self.ds_T2M

    @property
    def path_length(self) -> float:
        """Total path length B -> M -> T1 -> T2 -> M -> E [m] (section 2.5)."""
        return self.ds_BM + self.ds_loop + self.ds_ME

    @property
    def transform(self) -> np.ndarray:
        """T of eq. 12: the 4x4 homogeneous transform from xi-eta-zeta (origin O1) to xyz.

        Columns xi, eta, zeta, O1 over the row [0, 0, 0, 1], so S^A = T Xi^A with
        Xi^A = [R cos beta(t), R sin beta(t), 0, 1].
        """
        T = np.eye(4)
        T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = self.xi, self.eta, self.zeta, self.O1
        return T

    def arc_point(self, angle) -> np.ndarray:
        """Point of the loop circle at angle ``angle`` [rad] in the xi-eta plane (eq. 12) [m].

        Args:
            angle: scalar or array of any shape.

        Returns:
            Array of shape angle.shape + (3,).
        """
        angle = np.asarray(angle, dtype=float)[..., None]
        return self.O1 + self.R * (np.cos(angle) * self.xi + np.sin(angle) * self.eta)


def loop_geometry(B, M, E, delta=None, radius=None) -> LoopGeometry:
    """Loop path geometry from B, M, E and Delta or R (section 2.2, flowchart of Fig. 3).

    a = M - B and d = M - E; b = a_hat + d_hat is along the bisector of the angle BME and
    O1 = M + Delta b_hat. R is the distance from O1 to the line BM, which is Delta sin(angle/2); the
    tangent points are T1 = M + l a_hat and T2 = M + l d_hat with l = sqrt(Delta^2 - R^2)
    (Pythagoras) = Delta cos(angle/2). The arc angle is beta = pi + angle(a_hat, d_hat) and the
    arc starts at beta_b = pi - beta / 2 (eq. 11). Both R and l are evaluated in the half-angle form
    (same values, no cancellation when the corner is nearly straight).

    Give ``delta`` or ``radius`` (the paper's alternative: Delta = R / sin(angle BME / 2)). Both may
    be given only if they describe the same loop.

    Args:
        B: start point [m], shape (3,).
        M: corner point, passed twice [m], shape (3,).
        E: end point [m], shape (3,).
        delta: Delta, distance from M to the loop centre [m], > 0.
        radius: R, loop radius [m], > 0.

    Returns:
        LoopGeometry.

    Raises:
        ValueError: a point that is not a finite 3-vector; B or E coinciding with M; B, M, E
            collinear (no corner to loop through); neither or a non-positive/non-finite delta or
            radius; delta and radius given together that do not fit the corner.
    """
    B = finite_array(B, "B", "m", shape=(3,))
    M = finite_array(M, "M", "m", shape=(3,))
    E = finite_array(E, "E", "m", shape=(3,))
    a = M - B
    d = M - E
    norm_a = float(np.linalg.norm(a))
    norm_d = float(np.linalg.norm(d))
    if norm_a == 0.0:
        raise ValueError(f"B and M coincide (both {M}): segment BM has no length, no corner")
    if norm_d == 0.0:
        raise ValueError(f"E and M coincide (both {M}): segment ME has no length, no corner")
    a_hat = a / norm_a
    d_hat = d / norm_d
    cross = np.cross(a_hat, d_hat)
    sin_angle = float(np.linalg.norm(cross))
    cos_angle = float(a_hat @ d_hat)
    if sin_angle < _COLLINEAR_SIN_TOL:
        if cos_angle > 0.0:
            raise ValueError(
                "B, M and E are collinear with B and E on the same side of M (angle BME = 0): "
                "the path reverses at M, there is no corner to loop through"
            )
        raise ValueError(
            "B, M and E are collinear with M between B and E (angle BME = pi): "
            "the path is straight, there is no corner to loop through"
        )
    corner_angle = float(np.arctan2(sin_angle, cos_angle))  # angle BME = angle(a_hat, d_hat)
    half_sin = np.sin(0.5 * corner_angle)
    half_cos = np.cos(0.5 * corner_angle)

    if delta is None and radius is None:
        raise ValueError(
            "delta or radius must be given (Delta [m] or R [m] of the loop), got neither"
        )
    if delta is not None:
        delta = positive_scalar(delta, "delta", "m")
    if radius is not None:
        radius = positive_scalar(radius, "radius", "m")
        delta_from_radius = radius / half_sin  # section 2.2: Delta from R and the half angle BME
        if delta is None:
            delta = delta_from_radius
        elif abs(delta - delta_from_radius) > _FIT_RTOL * delta:
            raise ValueError(
                f"radius = {radius} m does not fit delta = {delta} m for the angle BME = "
                f"{corner_angle} rad: the loop tangent to BM and EM with centre at distance delta "
                f"from M has R = delta sin(angle / 2) = {delta * half_sin} m"
            )

    b = a_hat + d_hat  # bisector direction of the angle BME, away from B and E
    b_hat = _unit(b)
    O1 = M + delta * b_hat
    R = float(delta * half_sin)  # distance from O1 to the line BM (or EM)
    l_tangent = float(delta * half_cos)  # |M T1| = |M T2| = sqrt(Delta^2 - R^2)
    T1 = M + l_tangent * a_hat
    T2 = M + l_tangent * d_hat
    beta = float(np.pi + corner_angle)  # pi + angle between a_hat and d_hat
    beta_b = float(np.pi - 0.5 * beta)  # eq. 11

    # Local frame of eq. 12 (docs/papers.md): xi towards M, zeta normal to the path's plane.
    xi = (M - O1) / delta
    zeta = cross / sin_angle
    eta = np.cross(zeta, xi)

    return LoopGeometry(
        B=_readonly(B),
        M=_readonly(M),
        E=_readonly(E),
        delta=float(delta),
        R=R,
        corner_angle=corner_angle,
        a_hat=_readonly(a_hat),
        d_hat=_readonly(d_hat),
        b_hat=_readonly(b_hat),
        O1=_readonly(O1),
        T1=_readonly(T1),
        T2=_readonly(T2),
        beta=beta,
        beta_b=beta_b,
        xi=_readonly(xi),
        eta=_readonly(eta),
        zeta=_readonly(zeta),
        ds_BM=norm_a,
        ds_MT1=l_tangent,
        ds_arc=float(beta * R),
        ds_T2M=l_tangent,
        ds_ME=norm_d,
    )


# --------------------------------------------------------------------------------------------
# Time law (sections 2.3-2.5, eq. 7-14).
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LoopTimeLaw:
    """Times and polynomial coefficients of the loop path (eq. 7-14).

    Built by :func:`loop_time_law`. The motion starts at t = 0 at B.

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


def loop_time_law(geometry: LoopGeometry, v_max) -> LoopTimeLaw:
    """Times and coefficients of the motion along ``geometry`` at loop speed ``v_max``.

    Args:
        geometry: from :func:`loop_geometry`.
        v_max: loop speed and peak speed on the straight segments [m/s], > 0.

    Returns:
        LoopTimeLaw.

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
    return LoopTimeLaw(
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
class LoopPathPlan:
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
    timing: LoopTimeLaw

    def __post_init__(self) -> None:
        if not isinstance(self.geometry, LoopGeometry):
            raise ValueError(f"geometry must be a LoopGeometry, got {type(self.geometry).__name__}")
        if not isinstance(self.timing, LoopTimeLaw):
            raise ValueError(f"timing must be a LoopTimeLaw, got {type(self.timing).__name__}")

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

        # Arc: beta(t) = beta_b + (v_max / R)(t - t_BT1) (eq. 11), S^A = T Xi^A (eq. 12) and
        # its time derivatives (centripetal acceleration v^2 / R towards O1).
        k = phase == 2
        if np.any(k):
            omega = v / g.R
            angle = g.beta_b + omega * (tt[k] - tl.t_T1)
            c = np.cos(angle)[:, None]
            s = np.sin(angle)[:, None]
            radial = c * g.xi + s * g.eta  # unit vector from O1 to the tool
            tangent = -s * g.xi + c * g.eta  # unit direction of motion
            pos[k] = g.O1 + g.R * radial
            vel[k] = v * tangent
            acc[k] = -(v * omega) * radial
            jerk[k] = -(v * omega**2) * tangent

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


def plan_loop_path(B, M, E, v_max, delta=None, radius=None) -> LoopPathPlan:
    """Plan the motion B -> M -> loop -> M -> E of Boryga (section 2, eq. 1-14).

    Args:
        B: start point [m], shape (3,).
        M: corner [m], shape (3,), passed twice.
        E: end point [m], shape (3,).
        v_max: loop speed and peak speed on BM and ME [m/s], > 0.
        delta: distance Delta from M to the loop centre [m], > 0 (or give ``radius``).
        radius: loop radius R [m], > 0 (or give ``delta``).

    Returns:
        LoopPathPlan starting at rest at B at t = 0 and ending at rest at E at t = duration.

    Raises:
        ValueError: see :func:`loop_geometry` and :func:`loop_time_law`.
    """
    geometry = loop_geometry(B, M, E, delta=delta, radius=radius)
    return LoopPathPlan(geometry, loop_time_law(geometry, v_max))


# --------------------------------------------------------------------------------------------
# Joint motion on a robot and the planner system (docs/design.md contract).
# --------------------------------------------------------------------------------------------


class RobotLoopLaw(HermiteLaw):
    """The loop path's joint motion on a robot: the time law a :class:`TimeLawPlanner` follows.

    q(tau) is the robot's inverse kinematics of the path point (:meth:`Robot.point_ik`: the
    closed-form IK of Boryga's robots, eq. 15-32; the UR10e's keeps the flange orientation and IK
    branch of ``reference``) and the rates come from its Jacobian (:meth:`Robot.joint_rates`):
    :meth:`exact`. That is computed at knots every ``knot_step`` [s] of law time and at the path's
    junctions (both sides: the acceleration jumps by v²/R where the arc begins and ends) and
    interpolated between them (:class:`HermiteLaw`), so the planner's hot path costs microseconds,
    not an IK.

    Args:
        plan: the loop path (:func:`plan_loop_path`), in the robot's base frame.
        robot: the robot.
        reference: a configuration of the robot giving the tool orientation and IK branch.
        knot_step: the largest law-time step between knots [s].
    """

    def __init__(self, plan: LoopPathPlan, robot: Robot, reference, *, knot_step: float = 2e-3):
        self.plan = plan
        self.robot = robot
        self.reference = np.asarray(reference, dtype=float)
        coarse = np.union1d(np.linspace(0.0, plan.duration, 201), plan.breakpoints)
        positions = plan.sample(coarse)[0].reshape(-1, 3)
        try:
            robot.point_ik(positions, self.reference)  # out of reach: a ValueError now
        except ValueError:
            for tau, position in zip(coarse, positions):  # the first sample out of reach, named
                try:
                    robot.point_ik(position[None], self.reference)
                except ValueError as error:
                    raise ValueError(f"the loop path leaves the {robot.name}'s reach at law time {tau:.4g} s of "
                                     f"{plan.duration:.4g} s, at {format_point(position)} m: {error}") from error
            raise
        knots = np.union1d(np.linspace(0.0, plan.duration, int(np.ceil(plan.duration / knot_step)) + 1),
                           plan.breakpoints)
        right = np.array([self.exact(tau, "right") for tau in knots])
        left = np.array([self.exact(tau, "left") if np.isin(tau, plan.breakpoints) else row
                         for tau, row in zip(knots, right)])
        super().__init__(knots, right, left, acceleration_jumps=plan.breakpoints)

    def exact(self, tau: float, side: str = "right") -> np.ndarray:
        """(q, q̇, q̈) at law time tau [s], (3, n): the tool on the path, moving along it (at a
        junction, the value on ``side``)."""
        position, velocity, acceleration = (value.reshape(3) for value in self.plan.sample(tau, side=side)[:3])
        q = self.robot.point_ik(position[None], self.reference)[0]
        qd, qdd = self.robot.joint_rates(q, velocity, acceleration)
        return np.array([q, np.reshape(qd, -1), np.reshape(qdd, -1)])


def joint_speed_cap(law: HermiteLaw, velocity_limit, acceleration_limit) -> tuple[float, dict]:
    """The largest constant clock rate c <= 1 that keeps ``law`` within the joint limits.

    With a constant c, joint velocity scales by c and acceleration by c^2, so
    c = min(1, min_j v_lim_j / peak|qd_j|, sqrt(min_j a_lim_j / peak|qdd_j|)), with the law's
    exact peaks (:meth:`HermiteLaw.peak_rates`: on each knot interval the law is a polynomial;
    a sampled peak missed up to 0.07 % of the limit on seeded random loops).

    Returns:
        (c, peaks) with peaks = {"qd": per-joint peak |qd|, "qdd": per-joint peak |qdd|} at c = 1.
    """
    peak_qd, peak_qdd = law.peak_rates()
    with np.errstate(divide="ignore"):
        cap = min(
            1.0,
            float(np.min(np.asarray(velocity_limit) / peak_qd)),
            float(np.sqrt(np.min(np.asarray(acceleration_limit) / peak_qdd))),
        )
    return cap, {"qd": peak_qd, "qdd": peak_qdd}


class BorygaLoopPlanner(TimeLawPlanner):
    """Boryga's loop motion on a robot under the planner contract: the joint law of
    :class:`RobotLoopLaw`, slowed by a constant clock rate
    (:func:`joint_speed_cap`) where it would break the joint limits.

    Args:
        law: the joint law.
        velocity_limit, acceleration_limit: per-joint limits to keep [rad/s or m/s, rad/s^2 or m/s^2].
    """

    def __init__(self, law, velocity_limit, acceleration_limit, *, update_period: float = 0.001):
        cap, self.peaks = joint_speed_cap(law, velocity_limit, acceleration_limit)
        super().__init__(law, velocity_limit, acceleration_limit, speed_cap=cap, update_period=update_period)

    def figures(self) -> dict:
        return {"loop_path": loop_path_figure(self.law.plan, clock_rate=self.speed_cap)}

    def task_waypoints(self) -> np.ndarray:
        """B, M and E [m]."""
        geometry = self.law.plan.geometry
        return np.array([geometry.B, geometry.M, geometry.E])


def loop_path_figure(plan: LoopPathPlan, *, clock_rate: float = 1.0, samples: int = 4001):
    """The paper's figs. 5-7 for ``plan`` as run at the constant clock rate ``clock_rate`` (the
    planner's speed cap; 1: the path's own profile at v_max): position, velocity and acceleration
    per axis and their norms (speed along the path, acceleration magnitude) against time, junctions
    marked. At rate c the tool is at the path's point tau at t = tau / c, with velocity × c and
    acceleration × c²."""
    from matplotlib.figure import Figure

    c = positive_scalar(clock_rate, "clock_rate", "")
    tau = np.linspace(0.0, plan.duration, samples)
    position, velocity, acceleration = plan.sample(tau)[:3]
    t, velocity, acceleration = tau / c, velocity * c, acceleration * c * c
    figure = Figure(figsize=(9, 8), layout="constrained")
    axes = figure.subplots(3, 1, sharex=True)
    for ax, data, label, norm_label in (
        (axes[0], position, "position [m]", None),
        (axes[1], velocity, "velocity [m/s]", "speed"),
        (axes[2], acceleration, "acceleration [m/s$^2$]", "|a|"),
    ):
        for k, axis in enumerate("xyz"):
            ax.plot(t, data[:, k], label=axis)
        if norm_label:
            ax.plot(t, np.linalg.norm(data, axis=1), "k--", label=norm_label)
        for index, (time, name) in enumerate(zip(plan.breakpoints / c, ("B", "M", "T1", "T2", "M", "E"))):
            ax.axvline(time, color="grey", linewidth=0.6)
            if ax is axes[0]:  # alternate heights: M and T1 (T2 and M) are close on a small loop
                ax.annotate(name, (time, 1.0 + 0.07 * (index % 2)), xycoords=("data", "axes fraction"), ha="center",
                            va="bottom")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        ax.legend(ncol=4, fontsize="small")
    axes[-1].set_xlabel("t [s]")
    if c < 1.0:
        figure.suptitle(f"as run: the path's profile at v_max slowed to c = {c:.4g} by the joint limits "
                        "(t = τ / c, velocity × c, acceleration × c²)", fontsize="medium")
    return figure


# ------------------------------------------------------------------------------------------------
# The paper's example loop and its placement in each workspace.
# ------------------------------------------------------------------------------------------------

# Boryga, section 3 / Table 1: B, M, E [m], Delta [m], v_max [m/s]. Horizontal plane z = 1 m.
PAPER_LOOP = {
    "B": (0.5, 0.5, 1.0),
    "M": (0.54, 0.53, 1.0),
    "E": (0.54, 0.5, 1.0),
    "delta": 0.02,
    "v_max": 0.25,
}


@dataclass(frozen=True, eq=False)
class LoopPlacement:
    """The paper's loop (same shape, Delta and v_max) moved into one robot's workspace.

    Attributes:
        robot: robot name.
        B, M, E: placed points [m], read-only arrays (3,).
        delta: Delta [m]; v_max: loop speed [m/s] (the paper's).
        offset: translation applied to the paper's Table 1 points [m] (no rotation is needed).
        reason: where the loop was put and why.
    """

    robot: str
    B: np.ndarray
    M: np.ndarray
    E: np.ndarray
    delta: float
    v_max: float
    offset: np.ndarray
    reason: str = field(default="")

    def plan(self):
        """The placed loop as a time law, :func:`plan_loop_path`."""
        return plan_loop_path(self.B, self.M, self.E, self.v_max, delta=self.delta)


_PLACEMENT = {
    # Pure translation, so the loop keeps its shape, plane (horizontal), Delta and v_max.
    "anthropomorphic": (
        (-0.2, -0.2, -0.5),
        "translated by (-0.2, -0.2, -0.5) m: B = (0.3, 0.3, 0.5), M = (0.34, 0.33, 0.5), "
        "E = (0.34, 0.3, 0.5). The paper's path is 0.97-1.03 m from the shoulder against a 0.78 m "
        "reach (docs/papers.md); here the whole loop is 0.46-0.53 m from the shoulder (59-68 % of the "
        "reach), 0.17 m above it, in front of the arm near the diagonal x = y as in the paper: the "
        "elbow stays bent at 95-109 deg, far from the stretched/folded singularities, the joint-1 "
        "axis and every joint limit.",
    ),
    "scara": (
        (0.0, 0.0, -0.735),
        "translated down by 0.735 m to z = 0.265 m (mid-stroke lambda3 = 0.1 m); x and y are the "
        "paper's, so theta1 and theta2 follow the paper's plan. At the paper's z = 1 m the stroke "
        "would be -0.635 m (docs/papers.md); the horizontal distances 0.71-0.78 m are inside the annulus "
        "0.12-0.96 m, with theta2 between about -86 and -71 deg (arm well bent, far from its limits).",
    ),
    "cartesian": (
        (0.0, 0.0, 0.0),
        "not moved: the paper's points are inside the chosen joint ranges (lambda1 = 0.76 m, "
        "lambda2 = 0.5-0.55 m, lambda3 = -s_x = -0.5 to -0.56 m).",
    ),
}


def paper_loop_placement(robot_name: str) -> LoopPlacement:
    """The paper's example loop (Table 1, Delta = 0.02 m, v_max = 0.25 m/s) placed for a robot.

    Returns:
        LoopPlacement with B, M, E, delta, v_max, the offset from Table 1 and the reason.
    """
    if robot_name not in _PLACEMENT:
        raise ValueError(f"robot must be one of Boryga's {tuple(_PLACEMENT)}, got {robot_name!r}")
    offset, reason = _PLACEMENT[robot_name]
    offset = np.array(offset, dtype=float)
    points = []
    for key in ("B", "M", "E"):
        point = np.array(PAPER_LOOP[key], dtype=float) + offset
        point.setflags(write=False)
        points.append(point)
    offset.setflags(write=False)
    return LoopPlacement(
        robot=robot_name,
        B=points[0],
        M=points[1],
        E=points[2],
        delta=PAPER_LOOP["delta"],
        v_max=PAPER_LOOP["v_max"],
        offset=offset,
        reason=reason,
    )


@dataclass
class BorygaConfig:
    """Boryga's loop path B -> M -> loop through the corner -> M -> E, traced by the scenario's
    robot (inverse kinematics): the scenario's ``planner: !BorygaConfig`` entry.

    Attributes:
        B, M, E: the path's points [m] in the robot's base frame; all empty: the paper's example
            (Table 1) placed in the robot's workspace (:func:`paper_loop_placement` for Boryga's
            robots; for another robot translated so that B is the tool at ``q_initial``, the loop
            in the horizontal plane through it, traced at the tool orientation of ``q_initial``).
        delta: Δ [m] of the loop (section 2.2).
        v_max: the speed along the path [m/s].
        velocity_limit, acceleration_limit: per joint; empty: the robot's joint-move limits
            (:attr:`Robot.joint_move_limits`: 1.05 rad/s and 1.40 rad/s² on the UR10e; the rated
            speeds and no acceleration limit on Boryga's robots, as in the paper).
    """

    B: list[float] = field(default_factory=list)
    M: list[float] = field(default_factory=list)
    E: list[float] = field(default_factory=list)
    delta: float = 0.02
    v_max: float = 0.25
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)


def make(config: BorygaConfig, robot: Robot, q_initial) -> BorygaLoopPlanner:
    """The loop of ``config`` on ``robot`` (``q_initial`` gives the tool orientation, the IK
    branch and, for the default placement on robots other than Boryga's, the point B)."""
    points = [real_array(getattr(config, name), name, "m") for name in ("B", "M", "E")]
    if any(point.size for point in points):
        if not all(point.shape == (3,) for point in points):
            raise ValueError(f"B, M and E must all be 3-vectors [m] or all empty, got {[p.tolist() for p in points]}")
        for name, point in zip(("B", "M", "E"), points):  # named before the path between them is solved
            try:
                robot.point_ik(point[None], q_initial)
            except ValueError as error:
                raise ValueError(f"{name}: {error}") from error
    elif robot.name in _PLACEMENT:
        placement = paper_loop_placement(robot.name)
        points = [placement.B, placement.M, placement.E]
    else:
        offset = robot.tool_position(np.asarray(q_initial, dtype=float)) - np.asarray(PAPER_LOOP["B"])
        points = [np.asarray(PAPER_LOOP[name]) + offset for name in ("B", "M", "E")]
    law = RobotLoopLaw(plan_loop_path(*points, config.v_max, delta=config.delta), robot, q_initial)
    n = robot.num_joints
    # the UR10e's joint-move limits; on Boryga's robots their rated speeds and no acceleration limit
    default_velocity, default_acceleration = robot.joint_move_limits
    velocity = limit_or_default(config.velocity_limit, default_velocity, "velocity_limit", n)
    if np.size(config.acceleration_limit) or np.all(np.isfinite(default_acceleration)):
        acceleration = limit_or_default(config.acceleration_limit, default_acceleration, "acceleration_limit", n)
    else:
        acceleration = np.full(n, np.inf)
    return BorygaLoopPlanner(law, velocity, acceleration)
