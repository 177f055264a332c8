"""Acceleration-level planning law of seed 000 (Pająk 2024), as plain numpy.

The paper plans the joint trajectory of a 6-DOF arm by integrating a joint acceleration law:
the task-space error e = k(q) - p (eq. 6) is driven by e'' + Λ_V e' + Λ_P e = 0 (eq. 9), which
gives q̈ = -J⁻¹ (J̇q̇ + Λ_V J q̇ + Λ_P e) (eq. 13). Joint velocity limits are kept by an interior
penalty near the limits (eq. 14-16) and joint acceleration limits by a trajectory-scaling
coefficient c: q̈ = a + c b (eq. 17), c chosen from the violated limits (cases 1-4, a-c) and
relaxed back to 1 by eq. 18. Waypoints are passed without stopping by blending the target in a
ball around each waypoint (eq. 19), or the arm stops at each.

This module is the law only: a LeafSystem (continuous state [q; q̇], discrete state below) calls
:meth:`PajakLaw.acceleration` from its derivatives and :meth:`PajakLaw.update` from a periodic
update. :func:`integrate` is a small fixed-step RK4 loop for tests and benchmarks, and
:func:`integrate_many` runs many tasks at once (vectorised over tasks).

Corrections and readings (``/work/shared/ERRATA.md``, seed 000):

- the orientation error is wrapped to (-π, π] (``robot.task_pose_error``);
- cases (2) and (4) of the scaling choice use q̈_min (the paper prints q̈_max);
- ρ is not given in the paper; ``rho = 0.03`` with d normalised by the range q̇_max - q̇_min
  (2.1 rad/s) reproduces sim 2's minimum joint velocity;
- σ of eq. 19 is a monotone continuous progress variable: the projection of the TCP on the
  segment p_i -> p_{i+1}, measured from where the TCP entered the ball and reaching 1 one
  neighbourhood radius ϵ further on (the literal 1 - δ/ϵ is not monotone and stalls).

Improvements over the literal method (each a flag of :class:`PajakParameters`, default on; all
off gives the paper's method as printed, with the ERRATA corrections):

1. ``smooth_penalty`` / ``continuous_switching``: q̈ continuous after t = 0. The penalty minus
   its tangent at the threshold has zero slope there (q̈ no longer jumps by ρ/(R ϑ²) when it
   switches on); the blended target starts at p_i exactly when the TCP enters the ball (σ = 0)
   and the waypoint switches exactly when σ reaches 1, so the target never jumps.
2. ``bounded_scaling``: c stays in [0, 1]. When no c in [0, 1] keeps every limit, q̈ is clipped
   to the acceleration box (narrowed near the velocity limits so the joints brake) and the
   event is counted (discrete state ``SATURATED``) instead of letting c leave [0, 1], where it
   would switch the velocity penalty off or reverse the feedback and diverge.
3. ``damped_inverse``: damped least squares near a singular J (the damping grows as the UR's
   singularity measure falls below a threshold), so q̈ stays bounded; no progress for
   ``stall_time`` seconds, a gimbal-locked Euler pose or a non-finite value raise
   :class:`PlanningError` naming time, configuration and cause.
4. ``preserve_damping``: with c < 1 the literal law has damping c Λ_V against stiffness c Λ_P,
   which breaks condition (11) below c = 4 Λ_P / Λ_V² ≈ 0.907 and the TCP overshoots the goal.
   Time-scaling semantics fix it: damping c Λ_V and stiffness c² Λ_P keep the damping ratio of
   the unscaled law. To keep q̈ linear in c (so cases 1-4 stay an exact interval computation) the
   stiffness is written c · c_r Λ_P with c_r the eq. 18 value from the anchor: c = c_r whenever
   the limits are inactive, and while they are active the anchor is re-recorded every update,
   so c_r - c = O(update period).

Equation numbers in comments are the paper's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace

import numpy as np

from drake_traj import robot
from drake_traj.planners.scaling import relaxed_scaling

__all__ = [
    "DISCRETE_SIZE",
    "PajakLaw",
    "PajakParameters",
    "PlanningError",
    "acceleration_terms",
    "blend_progress",
    "blended_target",
    "choose_scaling",
    "integrate",
    "integrate_many",
    "paper_parameters",
    "paper_initial_configuration",
    "scaling_interval",
    "singularity_measure",
    "ur10e_kinematics",
    "velocity_penalty",
]

# --------------------------------------------------------------------------------------------
# Discrete state: a flat float vector (index constants below).
# --------------------------------------------------------------------------------------------
C = 0  # c at the last update (output / plotting)
T0 = 1  # eq. 18 anchor: time [s] at which c was last set by the limits
C0 = 2  # eq. 18 anchor: c at T0
WAYPOINT = 3  # index i of the active waypoint p_i (float holding an integer)
BLENDING = 4  # 1 while the TCP passes the neighbourhood of p_i (eq. 19, second case)
SIGMA = 5  # σ of eq. 19 stored at the last update (σ is monotone: max with the current value)
S_ENTRY = 6  # projection of the TCP on p_i -> p_{i+1} where it entered the ball [m]
BEST = 7  # smallest "remaining path" measure so far (progress monitor) [m]
T_BEST = 8  # time at which BEST was last improved [s]
SATURATED = 9  # number of updates at which no c in [0, 1] satisfied the limits (improvement 2)
DISCRETE_SIZE = 10
DISCRETE_NAMES = ("c", "t0", "c0", "waypoint", "blending", "sigma", "s_entry", "best", "t_best", "saturated")

# UR10e geometry (standard DH, robot.py).
_D1, _D4, _D5, _D6 = (float(robot.DH_D[k]) for k in (0, 3, 4, 5))
_A2, _A3 = float(robot.DH_A[1]), float(robot.DH_A[2])
SHOULDER = np.array([0.0, 0.0, _D1])  # shoulder point (joint-2 axis on the base axis) [m]
REACH = 1.3  # [m], UR10e reach from the shoulder (ur10e_facts.md)
_ORIENTATION_LENGTH = 0.1  # [m/rad], weight of orientation in the progress measure
_MIN_COS_PITCH = 1e-6  # Euler gimbal lock (as robot.analytic_jacobian_and_bias)


class PlanningError(ValueError):
    """The planner cannot complete the task: names the time, configuration and cause.

    Attributes:
        time: simulation time [s] (None if not known).
        configuration: q [rad] at that time (None if not known).
        cause: short machine-readable cause ("stall", "singular", "non-finite", "timeout", ...).
        partial: what was computed before the failure (dict of arrays, set by :func:`integrate`).
    """

    def __init__(self, message: str, *, time=None, configuration=None, cause: str = "", partial=None):
        where = ""
        if time is not None:
            where = f"at t = {float(time):.4f} s"
        if configuration is not None:
            where += f"{', ' if where else 'at '}q = {np.round(np.asarray(configuration, float), 4).tolist()}"
        super().__init__(f"{message} ({where})" if where else message)
        self.time = time
        self.configuration = None if configuration is None else np.array(configuration, dtype=float)
        self.cause = cause
        self.partial = partial


# --------------------------------------------------------------------------------------------
# Parameters
# --------------------------------------------------------------------------------------------


@dataclass
class PajakParameters:
    """Parameters of the planning law (seed 000, section "Model and task of the manipulator").

    Attributes:
        waypoints: (w, 6) task poses p_1..p_w [x, y, z, φ_X, φ_Y, φ_Z] [m, rad]; p_w is p_f.
        position_gain: Λ_P (scalar or 6 values) [1/s²], eq. 9.
        velocity_gain: Λ_V (scalar or 6 values) [1/s], eq. 9.
        velocity_limit: q̇_max = -q̇_min (scalar or 6) [rad/s], eq. 4.
        acceleration_limit: q̈_max = -q̈_min (scalar or 6) [rad/s²], eq. 5.
        vartheta: ϑ, penalty threshold on the normalised distance d (eq. 14), in (0, 0.5).
        rho: ρ, penalty strength (eq. 14) [rad/s], not given in the paper (ERRATA: 0.03).
        accuracy: ε, the task is finished when the TCP is this close to p_w [m].
        neighbourhood: ϵ, radius of the blending ball around each waypoint [m] (eq. 19).
        limit_velocity: add the penalty perturbation Δq̈ (eq. 15-16); sims 2 and 3.
        limit_acceleration: scale the trajectory (eq. 17-18), c(0) = 0; sim 3.
        blend_waypoints: pass waypoints without stopping (eq. 19); False stops at each.
        smooth_penalty: improvement 1, penalty with zero slope at the threshold.
        continuous_switching: improvement 1, σ = 0 on entry and the switch exactly at σ = 1.
        bounded_scaling: improvement 2, c in [0, 1]; otherwise clip q̈ and count it.
        damped_inverse: improvement 3, damped least squares near singular J.
        preserve_damping: improvement 4, stiffness scaled by c·c_r (≈ c²): condition (11) for any c.
        scaling_rate: rate of eq. 18 [1/s] (1 in the paper).
        singularity_threshold: DLS starts below this value of :func:`singularity_measure`.
        max_damping: DLS damping λ at the singularity.
        stop_speed: in stop mode, TCP speed [m/s] below which a waypoint counts as reached.
        stall_time: no progress for this long [s] raises PlanningError.
    """

    waypoints: np.ndarray
    position_gain: float | np.ndarray = 20.0
    velocity_gain: float | np.ndarray = 9.392
    velocity_limit: float | np.ndarray = robot.DEFAULT_JOINT_MOVE_VELOCITY
    acceleration_limit: float | np.ndarray = robot.DEFAULT_JOINT_MOVE_ACCELERATION
    vartheta: float = 0.1
    rho: float = 0.03
    accuracy: float = 0.001
    neighbourhood: float = 0.05
    limit_velocity: bool = False
    limit_acceleration: bool = False
    blend_waypoints: bool = True
    smooth_penalty: bool = True
    continuous_switching: bool = True
    bounded_scaling: bool = True
    damped_inverse: bool = True
    preserve_damping: bool = True
    scaling_rate: float = 1.0
    singularity_threshold: float = 0.02
    max_damping: float = 0.05
    stop_speed: float = 0.01
    stall_time: float = 2.0

    def validate(self) -> "PajakParameters":
        """Check every field; return a copy with arrays normalised ((w, 6) waypoints, (6,) gains
        and limits). Raises ValueError naming the field."""
        n = robot.NUM_JOINTS
        try:
            waypoints = np.array(self.waypoints, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"waypoints must be an array of numbers of shape (w, 6): {exc}") from exc
        if waypoints.ndim == 1 and waypoints.shape == (6,):
            waypoints = waypoints[None, :]
        if waypoints.ndim != 2 or waypoints.shape[1] != 6 or waypoints.shape[0] == 0:
            raise ValueError(f"waypoints must have shape (w, 6) with w >= 1, got shape {waypoints.shape}")
        if not np.all(np.isfinite(waypoints)):
            k = int(np.argwhere(~np.isfinite(waypoints))[0, 0])
            raise ValueError(f"waypoints[{k}] must be finite, got {waypoints[k].tolist()}")
        reach = np.linalg.norm(waypoints[:, :3] - SHOULDER, axis=1)
        if np.any(reach > REACH):
            k = int(np.argmax(reach > REACH))
            raise ValueError(
                f"waypoints[{k}] position {waypoints[k, :3].tolist()} is {reach[k]:.3f} m from the "
                f"shoulder (0, 0, {_D1}), beyond the UR10e reach of {REACH} m"
            )
        if np.any(np.abs(np.cos(waypoints[:, 4])) < 1e-3):
            k = int(np.argmax(np.abs(np.cos(waypoints[:, 4])) < 1e-3))
            raise ValueError(
                f"waypoints[{k}] phi_Y = {waypoints[k, 4]:.4f} rad is at +-pi/2: Z-Y-X Euler angles are "
                "singular (gimbal lock) there"
            )
        values = {}
        for name in ("position_gain", "velocity_gain", "velocity_limit", "acceleration_limit"):
            values[name] = _positive_vector(getattr(self, name), name, n)
        for name in (
            "rho", "accuracy", "neighbourhood", "scaling_rate", "singularity_threshold", "max_damping",
            "stop_speed", "stall_time",
        ):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
                raise ValueError(f"{name} must be a real number, got {value!r}")
            if not np.isfinite(value) or value <= 0:
                raise ValueError(f"{name} must be finite and > 0, got {value}")
            values[name] = float(value)
        vartheta = self.vartheta
        if isinstance(vartheta, bool) or not isinstance(vartheta, (int, float, np.floating)) or not (
            0.0 < vartheta < 0.5
        ):
            raise ValueError(f"vartheta must be a number in (0, 0.5), got {vartheta!r}")
        if values["accuracy"] > values["neighbourhood"]:
            raise ValueError(
                f"accuracy ({values['accuracy']} m) must not be larger than neighbourhood "
                f"({values['neighbourhood']} m)"
            )
        steps = np.linalg.norm(np.diff(waypoints[:, :3], axis=0), axis=1)
        if np.any(steps < values["neighbourhood"]):
            k = int(np.argmax(steps < values["neighbourhood"]))
            raise ValueError(
                f"waypoints[{k}] and waypoints[{k + 1}] are {steps[k]:.4f} m apart, closer than the "
                f"neighbourhood {values['neighbourhood']} m"
            )
        for flag in (
            "limit_velocity", "limit_acceleration", "blend_waypoints", "smooth_penalty",
            "continuous_switching", "bounded_scaling", "damped_inverse", "preserve_damping",
        ):
            if not isinstance(getattr(self, flag), (bool, np.bool_)):
                raise ValueError(f"{flag} must be True or False, got {getattr(self, flag)!r}")
        return replace(self, waypoints=waypoints, vartheta=float(vartheta), **values)


def _positive_vector(value, name: str, n: int) -> np.ndarray:
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a number or {n} numbers: {exc}") from exc
    if array.ndim == 0:
        array = np.full(n, float(array))
    if array.shape != (n,):
        raise ValueError(f"{name} must be a scalar or have shape ({n},), got shape {array.shape}")
    if not np.all(np.isfinite(array)) or np.any(array <= 0):
        raise ValueError(f"{name} must be finite and > 0, got {array.tolist()}")
    return array


def paper_initial_configuration() -> np.ndarray:
    """q(0) of the paper's task: [-π/2, -π/2, -3π/4, -π/4, π/2, π/4] [rad]."""
    return np.array([-np.pi / 2, -np.pi / 2, -3 * np.pi / 4, -np.pi / 4, np.pi / 2, np.pi / 4])


def paper_parameters(simulation: int = 3, **overrides) -> PajakParameters:
    """The paper's task and parameters for simulation 1 (no limits), 2 (velocity) or 3 (both).

    Waypoints p1, p2, p3, p_f with orientation (π, 0, 3π/4); Λ_P = 20, Λ_V = 9.392, ε = 1 mm,
    ϵ = 5 cm, ϑ = 0.1, limits 1.05 rad/s and 1.40 rad/s². ``overrides`` replace any field.
    """
    if simulation not in (1, 2, 3):
        raise ValueError(f"simulation must be 1, 2 or 3, got {simulation!r}")
    orientation = [np.pi, 0.0, 3 * np.pi / 4]
    positions = [
        [-0.175, -0.525, 0.730],  # p1
        [-0.175, -0.800, 0.730],  # p2
        [0.275, -0.800, 0.730],  # p3
        [0.275, -0.525, 0.730],  # p_f
    ]
    waypoints = np.array([p + orientation for p in positions])
    settings = dict(limit_velocity=simulation >= 2, limit_acceleration=simulation == 3)
    settings.update(overrides)
    return PajakParameters(waypoints=waypoints, **settings)


# --------------------------------------------------------------------------------------------
# Kinematics: closed-form UR10e k(q), analytic J(q) and J̇q̇ (same as robot.py, ~20x faster).
# --------------------------------------------------------------------------------------------


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _chain(q, qd, m):
    """k(q), analytic J and J̇q̇ as nested tuples of components (floats, or arrays of tasks).

    ``m`` is ``math`` for floats or ``numpy`` for arrays. Standard DH frames of robot.py written
    out: joint axes z_j at origins o_j, flange o_6; J_g columns z_j x (o_6 - o_j) and z_j; the
    bias by the usual velocity/acceleration recursion with q̈ = 0; then J = diag(I, B⁻¹) J_g and
    the Euler part of the bias B⁻¹ (α - Ḃ φ̇) (seed 000, with B's columns in k(q)'s order).
    """
    q1, q2, q3, q4, q5, q6 = q
    c1, s1 = m.cos(q1), m.sin(q1)
    c2, s2 = m.cos(q2), m.sin(q2)
    c5, s5 = m.cos(q5), m.sin(q5)
    c6, s6 = m.cos(q6), m.sin(q6)
    q23 = q2 + q3
    q234 = q23 + q4
    c23, s23 = m.cos(q23), m.sin(q23)
    c234, s234 = m.cos(q234), m.sin(q234)
    z0 = (0.0, 0.0, 1.0)
    z1 = (s1, -c1, 0.0)
    x4 = (c1 * c234, s1 * c234, s234)
    z4 = (c1 * s234, s1 * s234, -c234)
    z5 = (c5 * s1 - s5 * x4[0], -c5 * c1 - s5 * x4[1], -s5 * s234)
    x5 = (c5 * x4[0] + s5 * s1, c5 * x4[1] - s5 * c1, c5 * s234)
    x6 = tuple(c6 * x5[k] - s6 * z4[k] for k in range(3))
    y6 = tuple(-s6 * x5[k] - c6 * z4[k] for k in range(3))
    # r_j = o_{j+1} - o_j
    rs = (
        (0.0, 0.0, _D1),
        (_A2 * c1 * c2, _A2 * s1 * c2, _A2 * s2),
        (_A3 * c1 * c23, _A3 * s1 * c23, _A3 * s23),
        (_D4 * z1[0], _D4 * z1[1], 0.0),
        (_D5 * z4[0], _D5 * z4[1], _D5 * z4[2]),
        (_D6 * z5[0], _D6 * z5[1], _D6 * z5[2]),
    )
    axes = (z0, z1, z1, z1, z4, z5)
    # p_j = o_6 - o_j
    ps = [None] * 6
    acc = (0.0, 0.0, 0.0)
    for j in range(5, -1, -1):
        r = rs[j]
        acc = (acc[0] + r[0], acc[1] + r[1], acc[2] + r[2])
        ps[j] = acc
    jv = [_cross(axes[j], ps[j]) for j in range(6)]
    # bias recursion (q̈ = 0): α_{j+1} = α_j + ω_j x z_j q̇_j, ω_{j+1} = ω_j + z_j q̇_j,
    # a_{j+1} = a_j + α_{j+1} x r_j + ω_{j+1} x (ω_{j+1} x r_j)
    w = (0.0, 0.0, 0.0)
    al = (0.0, 0.0, 0.0)
    lin = (0.0, 0.0, 0.0)
    for j in range(6):
        z, r, v = axes[j], rs[j], qd[j]
        zq = (z[0] * v, z[1] * v, z[2] * v)
        if j:
            wz = _cross(w, zq)
            al = (al[0] + wz[0], al[1] + wz[1], al[2] + wz[2])
        w = (w[0] + zq[0], w[1] + zq[1], w[2] + zq[2])
        t1 = _cross(al, r)
        t2 = _cross(w, _cross(w, r))
        lin = (lin[0] + t1[0] + t2[0], lin[1] + t1[1] + t2[1], lin[2] + t1[2] + t2[2])
    # Z-Y-X Euler angles (k(q) rows 4-6)
    r11, r21, r31, r32, r33 = x6[0], x6[1], x6[2], y6[2], z5[2]
    phx = m.atan2(r32, r33)
    cy = m.hypot(r32, r33)  # = cos φ_Y >= 0
    phy = m.atan2(-r31, cy)
    phz = m.atan2(r21, r11)
    sy, cz, sz = -r31, m.cos(phz), m.sin(phz)
    if m is math:
        icy = 1.0 / cy if cy > 0.0 else 1e300
    else:
        icy = 1.0 / np.maximum(cy, 1e-300)

    def binv(v):  # B(φ)⁻¹ v, B of robot.euler_rate_matrix
        fx = (cz * v[0] + sz * v[1]) * icy
        return (fx, -sz * v[0] + cz * v[1], v[2] + sy * fx)

    jw = [binv(axes[j]) for j in range(6)]
    fx, fy, fz = binv(w)  # Euler rates φ̇
    bdot = (
        -sy * cz * fx * fy + fz * (-cy * sz * fx - cz * fy),
        -sy * sz * fx * fy + fz * (cy * cz * fx - sz * fy),
        -cy * fx * fy,
    )
    ang = binv((al[0] - bdot[0], al[1] - bdot[1], al[2] - bdot[2]))
    pose = (ps[0][0], ps[0][1], ps[0][2] + 0.0, phx, phy, phz)
    jac = tuple(tuple(jv[j][k] for j in range(6)) for k in range(3)) + tuple(
        tuple(jw[j][k] for j in range(6)) for k in range(3)
    )
    bias = lin + ang
    measure = _singularity_factors(s5, m.sin(q3), c2, c23, s234, m)
    return pose, jac, bias, cy, measure


def _singularity_factors(s5, s3, c2, c23, s234, m):
    # det J_g = a2 a3 s3 s5 (a2 c2 + a3 c23 + d5 s234): elbow, wrist and shoulder factors.
    shoulder = (_A2 * c2 + _A3 * c23 + _D5 * s234) / (abs(_A2) + abs(_A3))
    if m is math:
        return min(abs(s3), abs(s5), abs(shoulder))
    return np.minimum(np.minimum(np.abs(s3), np.abs(s5)), np.abs(shoulder))


def ur10e_kinematics(q, qd):
    """(k(q), J(q), J̇(q, q̇) q̇, cos φ_Y, singularity measure) of the UR10e flange.

    Same quantities as ``robot.task_pose`` and ``robot.analytic_jacobian_and_bias`` (the tests
    check agreement to 1e-9), in closed form: about 30 µs for one state instead of ~600 µs, and
    vectorised over leading dimensions (q, q̇ of shape (..., 6)).

    Returns:
        pose (..., 6), J (..., 6, 6), bias (..., 6), cos_pitch (...), measure (...), where
        ``measure`` is :func:`singularity_measure`. No exception at gimbal lock: callers check
        ``cos_pitch``.
    """
    q = np.asarray(q, dtype=float)
    qd = np.asarray(qd, dtype=float)
    if q.shape == (6,) and qd.shape == (6,):
        pose, jac, bias, cy, measure = _chain(q.tolist(), qd.tolist(), math)
        return np.array(pose), np.array(jac), np.array(bias), cy, measure
    shape = np.broadcast_shapes(q.shape, qd.shape)
    if shape[-1] != 6:
        raise ValueError(f"q and qd must have shape (..., 6), got {q.shape} and {qd.shape}")
    q = np.broadcast_to(q, shape).reshape(-1, 6)
    qd = np.broadcast_to(qd, shape).reshape(-1, 6)
    pose, jac, bias, cy, measure = _chain(tuple(q.T), tuple(qd.T), np)
    count = q.shape[0]
    pose_a = np.empty((count, 6))
    bias_a = np.empty((count, 6))
    jac_a = np.empty((count, 6, 6))
    for k in range(6):
        pose_a[:, k] = pose[k]
        bias_a[:, k] = bias[k]
        for j in range(6):
            jac_a[:, k, j] = jac[k][j]
    lead = shape[:-1]
    return (
        pose_a.reshape(lead + (6,)),
        jac_a.reshape(lead + (6, 6)),
        bias_a.reshape(lead + (6,)),
        np.reshape(cy, lead),
        np.reshape(measure, lead),
    )


def singularity_measure(q):
    """min(|sin q3|, |sin q5|, |a2 c2 + a3 c23 + d5 s234| / (|a2| + |a3|)), in [0, 1].

    det J_g = a2 a3 s3 s5 (a2 c2 + a3 c23 + d5 s234) for the UR10e: the three factors are the
    elbow, wrist and shoulder singularities; the measure is zero exactly at a singular J.
    """
    q = np.asarray(q, dtype=float)
    c2, c23, s234 = np.cos(q[..., 1]), np.cos(q[..., 1] + q[..., 2]), np.sin(q[..., 1:4].sum(-1))
    return _singularity_factors(np.sin(q[..., 4]), np.sin(q[..., 2]), c2, c23, s234, np)


# --------------------------------------------------------------------------------------------
# The law's pieces (pure functions, vectorised over leading dimensions)
# --------------------------------------------------------------------------------------------


def velocity_penalty(qd, qd_min, qd_max, rho: float, vartheta: float, *, smooth: bool = True):
    """Δq̈ = -Σ ∂κ(q̇_i)/∂q̇ (eq. 15) for the interior penalty κ of eq. 14 [rad/s²].

    d(q̇_i) = min(q̇_i - q̇_min, q̇_max - q̇_i) / (q̇_max - q̇_min) (eq. 14). Literal (``smooth``
    False): κ = ρ (1/d - 1/ϑ) for d < ϑ, whose slope -ρ/ϑ² at d = ϑ makes q̈ jump by
    ρ/((q̇_max - q̇_min) ϑ²) when the penalty switches on. Smooth (improvement 1): κ minus its
    tangent at ϑ, κ = ρ (1/d - 1/ϑ + (d - ϑ)/ϑ²), zero value and slope at the threshold, the
    same 1/d growth at the limit. d is floored at 1e-3 beyond the limits.
    """
    span = qd_max - qd_min
    to_min = qd - qd_min
    to_max = qd_max - qd
    upper = to_max < to_min
    d = np.maximum(np.minimum(to_min, to_max) / span, 1e-3)  # eq. 14
    inv_d2 = 1.0 / (d * d)
    if smooth:
        magnitude = rho * (inv_d2 - 1.0 / (vartheta * vartheta)) / span
    else:
        magnitude = rho * inv_d2 / span
    magnitude = np.where(d < vartheta, magnitude, 0.0)
    # ∂κ/∂q̇_i = κ'(d) ∂d/∂q̇_i, with ∂d/∂q̇_i = -1/span near q̇_max and +1/span near q̇_min;
    # eq. 15 pushes away from the nearer limit.
    return np.where(upper, -magnitude, magnitude)


def _solve(jac, rhs, measure, params_threshold, max_damping, damped: bool):
    """J⁻¹ rhs (eq. 13), or the damped least-squares (JᵀJ + λ²I)⁻¹ Jᵀ rhs (improvement 3)."""
    if not damped:
        return np.linalg.solve(jac, rhs)
    ratio = np.minimum(np.asarray(measure, dtype=float) / params_threshold, 1.0)
    lam2 = (max_damping * max_damping) * (1.0 - ratio * ratio)
    jt = np.swapaxes(jac, -1, -2)
    normal = jt @ jac
    normal = normal + lam2[..., None, None] * np.eye(6) if np.ndim(lam2) else normal + lam2 * np.eye(6)
    return np.linalg.solve(normal, jt @ rhs)


def acceleration_terms(jac, bias, error, qd, position_gain, velocity_gain, penalty=0.0, *,
                       measure=1.0, singularity_threshold=0.02, max_damping=0.05, damped=True):
    """(a, b_V, b_P) of eq. 17 with b = b_V + b_P:

    a = -J⁻¹ J̇q̇, b_V = -J⁻¹ Λ_V J q̇ + Δq̈, b_P = -J⁻¹ Λ_P e (e of eq. 6 or eq. 19).
    q̈ = a + c (b_V + b_P) is eq. 17; with c = 1 it is eq. 16 (eq. 13 without Δq̈).
    Shapes: jac (..., 6, 6), the vectors (..., 6); gains broadcast against (..., 6).
    """
    rhs = np.stack(
        [bias, velocity_gain * np.einsum("...ij,...j->...i", jac, qd), position_gain * error], axis=-1
    )
    sol = _solve(jac, rhs, measure, singularity_threshold, max_damping, damped)
    return -sol[..., 0], -sol[..., 1] + penalty, -sol[..., 2]


def scaling_interval(a, b, qdd_min, qdd_max):
    """Interval [c_lo, c_hi] of c with q̈_min <= a + c b <= q̈_max on every joint (last axis).

    Each joint gives the bound of cases (1)-(4) (ERRATA: (2) and (4) use q̈_min):
    b_i > 0: (q̈_min - a_i)/b_i <= c <= (q̈_max - a_i)/b_i; b_i < 0: the same with the roles
    of q̈_min and q̈_max swapped; b_i = 0: no bound if a_i is inside the box, else empty.
    Upper bounds (cases 1, 2) combine by min (case a), lower bounds (3, 4) by max (case b).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        to_max = (qdd_max - a) / b
        to_min = (qdd_min - a) / b
    positive = b > 0
    zero = b == 0
    inside = (a >= qdd_min) & (a <= qdd_max)
    low = np.where(positive, to_min, to_max)
    high = np.where(positive, to_max, to_min)
    low = np.where(zero, np.where(inside, -np.inf, np.inf), low)
    high = np.where(zero, np.where(inside, np.inf, -np.inf), high)
    return low.max(axis=-1), high.min(axis=-1)


def choose_scaling(c_relaxed, c_lo, c_hi, *, bounded: bool = True):
    """c from the relaxed value c_r (eq. 18) and the admissible interval (case a-c).

    c = c_r when it is admissible; otherwise the admissible value closest to c_r (case a: the
    smallest upper bound, case b: the largest lower bound, case c: the point of
    [ĉ_min, ĉ_max] closest to c_r, which is the previous c when the anchor was just recorded).
    ``bounded`` (improvement 2) restricts the interval to [0, 1].

    Returns:
        (c, feasible): feasible is False where the interval is empty (then c is the clip of c_r
        to it, and the caller must keep the limits some other way).
    """
    if bounded:
        c_lo = np.maximum(c_lo, 0.0)
        c_hi = np.minimum(c_hi, 1.0)
    feasible = c_lo <= c_hi
    c = np.minimum(np.maximum(c_relaxed, c_lo), c_hi)
    if bounded:
        c = np.clip(c, 0.0, 1.0)
    return c, feasible


def blend_progress(position, p_i, p_next, s_entry, neighbourhood, *, continuous: bool = True):
    """σ of eq. 19 (before the monotone max), from the TCP projection on p_i -> p_{i+1}.

    s = (x - p_i)·u, u the unit direction of the segment. Continuous (default): σ = (s - s_entry)
    / (ϵ - s_entry), 0 where the TCP entered the ball, 1 one radius past p_i along the segment
    (the denominator is kept >= ϵ/2). Literal reading: σ = s/ϵ. Clipped to [0, 1].
    """
    segment = p_next - p_i
    length = np.linalg.norm(segment, axis=-1)
    s = np.einsum("...i,...i->...", position - p_i, segment) / np.maximum(length, 1e-12)
    if continuous:
        sigma = (s - s_entry) / np.maximum(neighbourhood - s_entry, 0.5 * neighbourhood)
    else:
        sigma = s / neighbourhood
    return np.clip(sigma, 0.0, 1.0), s


def blended_target(p_i, p_next, sigma):
    """σ p_{i+1} + (1 - σ) p_i of eq. 19, the orientation part along the wrapped difference."""
    step = p_next - p_i
    step = np.concatenate([step[..., :3], robot.wrap_angle(step[..., 3:])], axis=-1)
    return p_i + np.asarray(sigma)[..., None] * step


# --------------------------------------------------------------------------------------------
# The law
# --------------------------------------------------------------------------------------------


@dataclass
class _Evaluation:
    qdd: np.ndarray
    c: np.ndarray
    c_relaxed: np.ndarray
    saturated: np.ndarray
    pose: np.ndarray
    target: np.ndarray
    sigma: np.ndarray
    measure: np.ndarray
    cos_pitch: np.ndarray


class PajakLaw:
    """The planning law of seed 000 for one task, or for several tasks at once.

    State: continuous (q, q̇) and the discrete vector of :data:`DISCRETE_NAMES` (size
    :data:`DISCRETE_SIZE`; the first three entries are [c, t0, c0] of the scaling contract).

    Args:
        parameters: one :class:`PajakParameters` (then q, q̇ have shape (6,) and the discrete
            state (DISCRETE_SIZE,)), or a sequence of them for a batch of tasks (shapes (N, 6)
            and (N, DISCRETE_SIZE)); all must share the boolean flags.
    """

    def __init__(self, parameters):
        single = isinstance(parameters, PajakParameters)
        plist = [parameters] if single else list(parameters)
        if not plist:
            raise ValueError("parameters must be a PajakParameters or a non-empty sequence of them")
        plist = [p.validate() for p in plist]
        flags = (
            "limit_velocity", "limit_acceleration", "blend_waypoints", "smooth_penalty",
            "continuous_switching", "bounded_scaling", "damped_inverse", "preserve_damping",
        )
        for name in flags:
            if len({bool(getattr(p, name)) for p in plist}) != 1:
                raise ValueError(f"parameters: every task of a batch must have the same {name}")
        self.single = single
        self.parameters = plist[0] if single else plist
        first = plist[0]
        for name in flags:
            setattr(self, name, bool(getattr(first, name)))
        count = len(plist)
        self.count = count
        most = max(p.waypoints.shape[0] for p in plist)
        wp = np.empty((count, most, 6))
        for k, p in enumerate(plist):
            w = p.waypoints.shape[0]
            wp[k, :w] = p.waypoints
            wp[k, w:] = p.waypoints[-1]
        self.waypoints = wp
        self.num_waypoints = np.array([p.waypoints.shape[0] for p in plist])
        # remaining path after p_i (position + weighted orientation), for the progress monitor
        steps = np.linalg.norm(np.diff(wp[:, :, :3], axis=1), axis=2) + _ORIENTATION_LENGTH * np.linalg.norm(
            robot.wrap_angle(np.diff(wp[:, :, 3:], axis=1)), axis=2
        )
        self.remaining = np.concatenate([np.cumsum(steps[:, ::-1], axis=1)[:, ::-1], np.zeros((count, 1))], axis=1)

        def stack(name):
            return np.array([np.asarray(getattr(p, name), dtype=float) for p in plist])

        self.kp = stack("position_gain")
        self.kv = stack("velocity_gain")
        self.qd_max = stack("velocity_limit")
        self.qdd_max = stack("acceleration_limit")
        for name in (
            "vartheta", "rho", "accuracy", "neighbourhood", "scaling_rate", "singularity_threshold",
            "max_damping", "stop_speed", "stall_time",
        ):
            values = stack(name)
            setattr(self, name, values)
        # velocity-aware acceleration box of the fallback: its bound falls from q̈_max at the
        # penalty threshold to 0 at the velocity limit (improvement 2)
        self.brake_gain = self.qdd_max / (self.vartheta[:, None] * 2.0 * self.qd_max)
        self._rows = np.arange(count)

    # --- shapes --------------------------------------------------------------------------------
    def _batch(self, value, width):
        value = np.asarray(value, dtype=float)
        if self.single:
            if value.shape != (width,):
                raise ValueError(f"expected shape ({width},), got {value.shape}")
            return value[None, :]
        if value.shape != (self.count, width):
            raise ValueError(f"expected shape ({self.count}, {width}), got {value.shape}")
        return value

    def _out(self, value):
        return value[0] if self.single else value

    # --- discrete state ------------------------------------------------------------------------
    def initial_discrete(self, q0=None) -> np.ndarray:
        """Discrete state at t = 0: c(0) = 0 with the anchor (t0, c0) = (0, 0) when the
        acceleration is limited (eq. 18, smooth start), c = 1 otherwise; waypoint 0; the TCP
        may already be inside the first ball (checked at the first update)."""
        d = np.zeros((self.count, DISCRETE_SIZE))
        c = 0.0 if self.limit_acceleration else 1.0
        d[:, C] = c
        d[:, C0] = c
        d[:, BEST] = np.inf
        return self._out(d)

    # --- evaluation ----------------------------------------------------------------------------
    def _evaluate(self, t, q, qd, d) -> _Evaluation:
        if self.count == 1:
            pose, jac, bias, cy, measure = ur10e_kinematics(q[0], qd[0])
            pose, jac, bias = pose[None], jac[None], bias[None]
            cy, measure = np.array([cy]), np.array([measure])
        else:
            pose, jac, bias, cy, measure = ur10e_kinematics(q, qd)
        rows = self._rows
        i = d[:, WAYPOINT].astype(int)
        p_i = self.waypoints[rows, i]
        sigma = np.zeros(self.count)
        target = p_i
        blending = d[:, BLENDING] > 0.5
        if self.blend_waypoints and blending.any():
            p_next = self.waypoints[rows, np.minimum(i + 1, self.num_waypoints - 1)]
            raw, _ = blend_progress(
                pose[:, :3], p_i[:, :3], p_next[:, :3], d[:, S_ENTRY], self.neighbourhood,
                continuous=self.continuous_switching,
            )
            sigma = np.where(blending, np.maximum(raw, d[:, SIGMA]), 0.0)  # monotone σ
            target = np.where(blending[:, None], blended_target(p_i, p_next, sigma), p_i)  # eq. 19
        error = robot.task_pose_error(pose, target)  # eq. 6 / eq. 19, orientation wrapped
        if self.limit_velocity:
            penalty = velocity_penalty(
                qd, -self.qd_max, self.qd_max, self.rho[:, None], self.vartheta[:, None],
                smooth=self.smooth_penalty,
            )  # eq. 14-15
        else:
            penalty = 0.0
        a, b_v, b_p = acceleration_terms(
            jac, bias, error, qd, self.kp, self.kv, penalty, measure=measure,
            singularity_threshold=self.singularity_threshold, max_damping=self.max_damping,
            damped=self.damped_inverse,
        )  # eq. 17 (eq. 16 when c = 1)
        saturated = np.zeros(self.count, dtype=bool)
        if self.limit_acceleration:
            c_r, _ = relaxed_scaling(t, d[:, T0], d[:, C0], 1.0, self.scaling_rate)  # eq. 18
            # improvement 4: stiffness c·c_r Λ_P (≈ c²), damping c Λ_V; literal: c Λ_P
            b = b_v + (np.clip(c_r, 0.0, 1.0)[:, None] if self.preserve_damping else 1.0) * b_p
            c_lo, c_hi = scaling_interval(a, b, -self.qdd_max, self.qdd_max)  # cases 1-4
            c, feasible = choose_scaling(c_r, c_lo, c_hi, bounded=self.bounded_scaling)  # cases a-c
            qdd = a + c[:, None] * b  # eq. 17
            if self.bounded_scaling:
                saturated = ~feasible
                if saturated.any():
                    upper = self.qdd_max
                    lower = -self.qdd_max
                    if self.limit_velocity:
                        upper = np.minimum(upper, self.brake_gain * (self.qd_max - qd))
                        lower = np.maximum(lower, self.brake_gain * (-self.qd_max - qd))
                    qdd = np.where(saturated[:, None], np.clip(qdd, lower, upper), qdd)
        else:
            c_r = np.ones(self.count)
            c = c_r
            qdd = a + b_v + b_p  # eq. 16 (eq. 13 without the penalty)
        return _Evaluation(qdd, c, c_r, saturated, pose, target, sigma, measure, cy)

    def acceleration(self, t: float, q, qd, discrete):
        """(q̈ [rad/s²], c) at time t for the state (q, q̇) and the discrete state.

        q̈ is eq. 17 with c = min(eq. 18 relaxation from the anchor, the admissible ĉ for this
        state), evaluated here on every call, so the acceleration limits hold at every
        evaluation (not only at updates) and q̈ is continuous in t between updates.

        Raises:
            PlanningError: at an Euler gimbal lock (cos φ_Y below 1e-6) or a non-finite q̈.
        """
        q2, qd2, d2 = self._batch(q, 6), self._batch(qd, 6), self._batch(discrete, DISCRETE_SIZE)
        ev = self._evaluate(t, q2, qd2, d2)
        if self.single:
            self._check(t, q2[0], ev, 0)
        return self._out(ev.qdd), (float(ev.c[0]) if self.single else ev.c)

    def evaluate(self, t: float, q, qd, discrete) -> dict:
        """Everything the law computes at (t, q, q̇, discrete), as a dict of arrays: qdd, c,
        c_relaxed, saturated, pose, target, sigma, measure (singularity), cos_pitch."""
        q2, qd2, d2 = self._batch(q, 6), self._batch(qd, 6), self._batch(discrete, DISCRETE_SIZE)
        ev = self._evaluate(t, q2, qd2, d2)
        return {f.name: self._out(getattr(ev, f.name)) for f in fields(ev)}

    def _check(self, t, q, ev: _Evaluation, k: int):
        if ev.cos_pitch[k] < _MIN_COS_PITCH:
            raise PlanningError(
                f"Z-Y-X Euler angles are singular: phi_Y = {ev.pose[k, 4]:.6f} rad is at +-pi/2 "
                "(gimbal lock), the analytic Jacobian has no inverse",
                time=t, configuration=q, cause="singular",
            )
        if not np.all(np.isfinite(ev.qdd[k])):
            raise PlanningError(
                f"non-finite acceleration {ev.qdd[k].tolist()} (singularity measure "
                f"{float(ev.measure[k]):.2e})",
                time=t, configuration=q, cause="non-finite",
            )

    # --- discrete update -----------------------------------------------------------------------
    def update(self, t: float, q, qd, discrete):
        """New discrete state at time t (call periodically, e.g. every integration step).

        Records the eq. 18 anchor (t0, c0) = (t, c) when the limits set c; switches waypoints
        (eq. 19 blending, or stop-and-go with c restarting from 0 when the acceleration is
        limited); tracks progress.

        Raises:
            PlanningError: no progress for ``stall_time`` s, gimbal lock, or non-finite values.
        """
        q2, qd2, d2 = self._batch(q, 6), self._batch(qd, 6), self._batch(discrete, DISCRETE_SIZE)
        new, status, message = self._update(t, q2, qd2, d2)
        if self.single and status[0] < 0:
            raise PlanningError(message[0], time=t, configuration=q2[0], cause=_CAUSES[int(status[0])])
        return self._out(new)

    def _update(self, t, q, qd, d):
        """(new discrete, status per task, message per task); status 0 running, 1 finished,
        negative: failure (see _CAUSES)."""
        d = d.copy()
        rows = self._rows
        ev = self._evaluate(t, q, qd, d)
        status = np.zeros(self.count, dtype=int)
        messages = [""] * self.count
        bad = ~np.all(np.isfinite(ev.qdd), axis=1) | ~np.all(np.isfinite(q), axis=1) | ~np.all(
            np.isfinite(qd), axis=1
        )
        gimbal = ev.cos_pitch < _MIN_COS_PITCH
        # eq. 18 anchor: record (t, c) whenever the limits moved c off the relaxation curve
        if self.limit_acceleration:
            active = np.abs(ev.c - ev.c_relaxed) > 1e-12
            d[:, T0] = np.where(active, t, d[:, T0])
            d[:, C0] = np.where(active, ev.c, d[:, C0])
            d[:, SATURATED] += ev.saturated
        d[:, C] = ev.c
        position = ev.pose[:, :3]
        i = d[:, WAYPOINT].astype(int)
        last = i >= self.num_waypoints - 1
        p_i = self.waypoints[rows, i]
        distance = np.linalg.norm(position - p_i[:, :3], axis=1)
        if self.blend_waypoints:
            blending = d[:, BLENDING] > 0.5
            d[:, SIGMA] = np.where(blending, ev.sigma, 0.0)
            if self.continuous_switching:
                switch = blending & (ev.sigma >= 1.0)  # σ reached 1: the target is p_{i+1} already
            else:
                switch = blending & (distance >= self.neighbourhood)  # left the ball (literal)
            i = np.where(switch, i + 1, i)
            d[:, WAYPOINT] = i
            d[:, BLENDING] = np.where(switch, 0.0, d[:, BLENDING])
            d[:, SIGMA] = np.where(switch, 0.0, d[:, SIGMA])
            # entering the ball of p_i (i < w): start blending towards p_{i+1} with σ = 0
            last = i >= self.num_waypoints - 1
            p_i = self.waypoints[rows, i]
            distance = np.linalg.norm(position - p_i[:, :3], axis=1)
            enter = (d[:, BLENDING] < 0.5) & ~last & (distance < self.neighbourhood)
            if enter.any():
                p_next = self.waypoints[rows, np.minimum(i + 1, self.num_waypoints - 1)]
                _, s = blend_progress(position, p_i[:, :3], p_next[:, :3], 0.0, self.neighbourhood)
                d[:, BLENDING] = np.where(enter, 1.0, d[:, BLENDING])
                d[:, S_ENTRY] = np.where(enter, s, d[:, S_ENTRY])
                d[:, SIGMA] = np.where(enter, 0.0, d[:, SIGMA])
        else:
            # stop at each waypoint: reached within ε at low TCP speed, then the next task
            # starts from rest (with c from 0 again when the acceleration is limited)
            speed = self._tcp_speed(q, qd)
            switch = ~last & (distance < self.accuracy) & (speed < self.stop_speed)
            i = np.where(switch, i + 1, i)
            d[:, WAYPOINT] = i
            if self.limit_acceleration:
                d[:, T0] = np.where(switch, t, d[:, T0])
                d[:, C0] = np.where(switch, 0.0, d[:, C0])
                d[:, C] = np.where(switch, 0.0, d[:, C])
            last = i >= self.num_waypoints - 1
            p_i = self.waypoints[rows, i]
            distance = np.linalg.norm(position - p_i[:, :3], axis=1)
        # finished: TCP within ε of p_w
        finished = last & (distance < self.accuracy)
        # progress monitor: remaining path = distance to p_i (+ weighted orientation) + rest
        orientation = np.linalg.norm(robot.wrap_angle(ev.pose[:, 3:] - p_i[:, 3:]), axis=1)
        remaining = distance + _ORIENTATION_LENGTH * orientation + self.remaining[rows, i]
        improved = remaining < d[:, BEST] - 1e-4
        d[:, BEST] = np.where(improved, remaining, np.minimum(d[:, BEST], remaining))
        d[:, T_BEST] = np.where(improved, t, d[:, T_BEST])
        stalled = ~finished & (t - d[:, T_BEST] > self.stall_time)
        status = np.where(finished, 1, status)
        for k in np.flatnonzero(stalled | gimbal | bad):
            if bad[k]:
                status[k] = -3
                messages[k] = f"non-finite state or acceleration (singularity measure {ev.measure[k]:.2e})"
            elif gimbal[k]:
                status[k] = -2
                messages[k] = (
                    f"Z-Y-X Euler angles are singular: phi_Y = {ev.pose[k, 4]:.6f} rad is at +-pi/2 "
                    "(gimbal lock)"
                )
            else:
                status[k] = -1
                near = " near a singular configuration" if ev.measure[k] < self.singularity_threshold[k] else ""
                messages[k] = (
                    f"no progress towards waypoint {int(d[k, WAYPOINT])} for {self.stall_time[k]:.1f} s"
                    f"{near}: remaining path {remaining[k]:.4f} m, TCP {np.round(position[k], 4).tolist()}, "
                    f"c = {float(ev.c[k]):.3g}, singularity measure {float(ev.measure[k]):.3g}"
                )
        return d, status, messages

    def _tcp_speed(self, q, qd):
        if self.count == 1:
            _, jac, _, _, _ = ur10e_kinematics(q[0], qd[0])
            return np.array([np.linalg.norm(jac[:3] @ qd[0])])
        _, jac, _, _, _ = ur10e_kinematics(q, qd)
        return np.linalg.norm(np.einsum("nij,nj->ni", jac[:, :3], qd), axis=1)

    def finished(self, q, qd, discrete):
        """True once the TCP is within ε of the final waypoint p_w and p_w is the active target."""
        q2, d2 = self._batch(q, 6), self._batch(discrete, DISCRETE_SIZE)
        pose, *_ = ur10e_kinematics(q2, np.zeros_like(q2))
        i = d2[:, WAYPOINT].astype(int)
        last = i >= self.num_waypoints - 1
        distance = np.linalg.norm(pose[:, :3] - self.waypoints[self._rows, i, :3], axis=1)
        done = last & (distance < self.accuracy)
        return bool(done[0]) if self.single else done

    def tcp_positions(self) -> np.ndarray:
        """Waypoint positions [m], (w, 3) (single task) for plots."""
        return self.waypoints[0, : self.num_waypoints[0], :3].copy()


_CAUSES = {-1: "stall", -2: "singular", -3: "non-finite", -4: "timeout"}


# --------------------------------------------------------------------------------------------
# Fixed-step integration for tests and benchmarks
# --------------------------------------------------------------------------------------------


def _rk4_step(law, t, q, qd, d, dt):
    k1v, k1a = qd, law._evaluate(t, q, qd, d).qdd
    h = 0.5 * dt
    k2v = qd + h * k1a
    k2a = law._evaluate(t + h, q + h * k1v, k2v, d).qdd
    k3v = qd + h * k2a
    k3a = law._evaluate(t + h, q + h * k2v, k3v, d).qdd
    k4v = qd + dt * k3a
    k4a = law._evaluate(t + dt, q + dt * k3v, k4v, d).qdd
    q_new = q + dt / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
    qd_new = qd + dt / 6.0 * (k1a + 2 * k2a + 2 * k3a + k4a)
    return q_new, qd_new


def integrate(law: PajakLaw, q0, *, dt: float = 1e-3, t_max: float = 30.0) -> dict:
    """Integrate one task with RK4 at a fixed step, updating the discrete state every step.

    At every step k: discrete update at t_k, then the sample (t_k, q_k, q̇_k, q̈_k, c_k, TCP,
    waypoint), then an RK4 step with the discrete state held. Stops at the first sample where the
    task is finished.

    Returns:
        dict of arrays: t (K,), q, qd, qdd (K, 6), c (K,), tcp (K, 6) pose, waypoint (K,),
        saturated (K,) bool, discrete (K, DISCRETE_SIZE), and "T" (final time) and "error"
        (final TCP position error [m]).

    Raises:
        PlanningError: singularity, no progress, non-finite values or not finished by t_max;
            ``.partial`` holds the arrays computed so far.
    """
    if not law.single:
        raise ValueError("law must be a single-task PajakLaw (use integrate_many for batches)")
    if not np.isfinite(dt) or dt <= 0:
        raise ValueError(f"dt must be a positive number of seconds, got {dt}")
    if not np.isfinite(t_max) or t_max <= 0:
        raise ValueError(f"t_max must be a positive number of seconds, got {t_max}")
    q = law._batch(robot._as_joint_vector(q0, "q0"), 6).copy()
    qd = np.zeros_like(q)
    d = law._batch(law.initial_discrete(), DISCRETE_SIZE)
    steps = int(math.ceil(t_max / dt))
    log = {name: [] for name in ("t", "q", "qd", "qdd", "c", "tcp", "waypoint", "saturated", "discrete")}

    def partial():
        out = {k: np.array(v) for k, v in log.items()}
        return out

    t = 0.0
    for k in range(steps + 1):
        t = k * dt
        try:
            d, status, message = law._update(t, q, qd, d)
            if status[0] < 0:
                raise PlanningError(message[0], time=t, configuration=q[0], cause=_CAUSES[int(status[0])])
            ev = law._evaluate(t, q, qd, d)
            law._check(t, q[0], ev, 0)
        except PlanningError as exc:
            exc.partial = partial()
            raise
        except (np.linalg.LinAlgError, FloatingPointError) as exc:
            raise PlanningError(
                f"numerical failure: {exc}", time=t, configuration=q[0], cause="non-finite", partial=partial()
            ) from exc
        log["t"].append(t)
        log["q"].append(q[0].copy())
        log["qd"].append(qd[0].copy())
        log["qdd"].append(ev.qdd[0].copy())
        log["c"].append(float(ev.c[0]))
        log["tcp"].append(ev.pose[0].copy())
        log["waypoint"].append(int(d[0, WAYPOINT]))
        log["saturated"].append(bool(ev.saturated[0]))
        log["discrete"].append(d[0].copy())
        if status[0] == 1:
            out = partial()
            out["T"] = t
            out["error"] = float(np.linalg.norm(ev.pose[0, :3] - law.waypoints[0, law.num_waypoints[0] - 1, :3]))
            return out
        try:
            q, qd = _rk4_step(law, t, q, qd, d, dt)
        except (np.linalg.LinAlgError, FloatingPointError) as exc:
            raise PlanningError(
                f"numerical failure: {exc}", time=t, configuration=q[0], cause="non-finite", partial=partial()
            ) from exc
    raise PlanningError(
        f"the task did not finish within t_max = {t_max} s", time=t, configuration=q[0], cause="timeout",
        partial=partial(),
    )


def integrate_many(law: PajakLaw, q0, *, dt: float = 2e-3, t_max: float = 30.0) -> list[dict]:
    """Integrate a batch of tasks at once (RK4, vectorised over tasks), without raising.

    Each task stops (its state frozen) when it finishes or fails. Nothing is stored per sample;
    the summary per task has: status ("finished" or a failure cause), message, T, error (final
    TCP distance to p_w [m]), max_velocity_ratio = max |q̇|/q̇_max and max_acceleration_ratio =
    max |q̈|/q̈_max over every evaluated sample (RK4 stages included), saturated (updates with
    the fallback), nan (any non-finite value seen).
    """
    if law.single:
        raise ValueError("law must be a batch PajakLaw (built from a sequence of parameters)")
    q = np.array(q0, dtype=float)
    if q.shape != (law.count, 6):
        raise ValueError(f"q0 must have shape ({law.count}, 6), got {q.shape}")
    qd = np.zeros_like(q)
    d = law.initial_discrete()
    running = np.ones(law.count, dtype=bool)
    result = [dict(status="timeout", message="", T=np.nan, error=np.nan, max_velocity_ratio=0.0,
                   max_acceleration_ratio=0.0, saturated=0, nan=False) for _ in range(law.count)]
    vel_ratio = np.zeros(law.count)
    acc_ratio = np.zeros(law.count)
    nan = np.zeros(law.count, dtype=bool)
    steps = int(math.ceil(t_max / dt))
    t = 0.0

    def stage(t_s, q_s, qd_s):
        qdd = law._evaluate(t_s, q_s, qd_s, d).qdd
        ok = np.all(np.isfinite(qdd), axis=1)
        nan[running & ~ok] = True
        ratio = np.max(np.abs(qdd) / law.qdd_max, axis=1)
        acc_ratio[running] = np.maximum(acc_ratio[running], np.where(ok, ratio, np.inf)[running])
        return np.where(ok[:, None], qdd, 0.0)

    with np.errstate(all="ignore"):
        for k in range(steps + 1):
            t = k * dt
            d_new, status, message = law._update(t, q, qd, d)
            d = np.where(running[:, None], d_new, d)
            vel_ratio[running] = np.maximum(vel_ratio[running], np.max(np.abs(qd) / law.qd_max, axis=1)[running])
            for j in np.flatnonzero(running & (status != 0)):
                pose, *_ = ur10e_kinematics(q[j], qd[j])
                r = result[j]
                r["status"] = "finished" if status[j] == 1 else _CAUSES[int(status[j])]
                r["message"] = message[j]
                r["T"] = t
                r["error"] = float(np.linalg.norm(pose[:3] - law.waypoints[j, law.num_waypoints[j] - 1, :3]))
                r["q"] = q[j].copy()
                running[j] = False
            if not running.any():
                break
            h = 0.5 * dt
            k1a = stage(t, q, qd)
            k2v = qd + h * k1a
            k2a = stage(t + h, q + h * qd, k2v)
            k3v = qd + h * k2a
            k3a = stage(t + h, q + h * k2v, k3v)
            k4v = qd + dt * k3a
            k4a = stage(t + dt, q + dt * k3v, k4v)
            q_new = q + dt / 6.0 * (qd + 2 * k2v + 2 * k3v + k4v)
            qd_new = qd + dt / 6.0 * (k1a + 2 * k2a + 2 * k3a + k4a)
            q = np.where(running[:, None], q_new, q)
            qd = np.where(running[:, None], qd_new, qd)
    for j in range(law.count):
        r = result[j]
        if running[j]:
            r["message"] = f"the task did not finish within t_max = {t_max} s"
            r["T"] = t
        r["max_velocity_ratio"] = float(vel_ratio[j])
        r["max_acceleration_ratio"] = float(acc_ratio[j])
        r["saturated"] = int(d[j, SATURATED])
        r["nan"] = bool(nan[j])
    return result
