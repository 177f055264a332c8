"""Acceleration-level planning law of Pająk 2024, as plain numpy.

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

Corrections and readings (``docs/papers.md``, Pająk 2024):

- the orientation error is wrapped to (-π, π];
- cases (2) and (4) of the scaling choice use q̈_min (the paper prints q̈_max), and ĉ is chosen
  from the bounds of all joints (the "one ĉ suitable for all accelerations"), so fixing one joint
  never pushes another out of its box;
- ρ is not given in the paper; ``rho = 0.03`` with d normalised by the range q̇_max - q̇_min
  (2.1 rad/s) reproduces sim 2's minimum joint velocity (-0.98 vs -0.97 rad/s);
- σ of eq. 19 is only described in words (0 when the TCP enters the ball, 1 when it leaves).
  Here σ = (TCP path length since entering the ball) / (1.25 ϵ): monotone, continuous, 0 on
  entry, and it reaches 1 about when the TCP leaves (the path through the balls of the paper's
  task is 1.2-1.35 ϵ). It grows whenever the TCP moves, so the target always leads; the literal
  1 - δ/ϵ is not monotone and a projection on p_i -> p_{i+1} does not grow while the TCP still
  heads for p_i: both stall inside the first ball.
- the kinematics (k(q), the analytic J and J̇q̇) are the same as ``drake_traj.robots.ur10e`` (checked
  by the tests to 1e-9) written in closed form, ~20x faster (acceleration() is called 3-4
  times per simulated millisecond).

Improvements over the literal method (each a flag of :class:`PajakConfig`, default on; all
off gives the paper's method as printed, with the corrections of docs/papers.md):

1. ``smooth_penalty`` / ``continuous_switching``: q̈ continuous after t = 0. The penalty minus
   its tangent at the threshold has zero slope there (the literal q̈ jumps by ρ/(R ϑ²) = 1.43
   rad/s² when it switches on); the waypoint switches exactly when σ reaches 1, where the
   blended target already is p_{i+1} (literal: when the TCP leaves the ball, whatever σ is).
2. ``bounded_scaling``: c stays in [0, 1] and the limits hold on every evaluation. The box
   used for c also keeps q̇ viable (q̈_i <= K (q̇_max - q̇_i), active only within ϑ/4 of the
   limit), and when no c in [0, 1] keeps the limits (a = -J⁻¹J̇q̇ alone breaks them) q̈ blends
   continuously from the clipped law to proportional braking; the event is counted
   (``SATURATED``). The literal c leaves [0, 1] there, which switches the penalty off or
   reverses the feedback, and the motion diverges.
3. ``damped_inverse``: damped least squares (JᵀJ + λ²I)⁻¹Jᵀ, λ² growing as the UR10e's
   singularity measure (factors of det J) falls below 0.1, so the motion stays bounded near
   singular configurations. No progress for ``stall_time`` seconds, a gimbal-locked Euler pose
   or a non-finite value raise :class:`PlanningError` naming time, configuration and cause.
4. ``preserve_damping``: with c < 1 the literal law has damping c Λ_V against stiffness c Λ_P,
   which breaks condition (11) below c* = 4 Λ_P / Λ_V² = 0.907, and the TCP overshoots the
   final goal (0.76 mm in sim 3, 2.1 cm on a direct move with the paper's limits). Damping is
   added only where a component e_j of the error is heading into a sign change, and only as
   much as it takes (:func:`approach_damping`): with K = c_r Λ_P (c_r: the eq. 18 value, = c
   up to one update period while the limits are active) and the approach rate
   r_j = -ė_j/e_j, the damping D_j = r_j + K/r_j makes ė_j = -r_j e_j an invariant line of
   ë = -D ė - K e (dr/dt = r² - D r + K = 0), so e_j decays as exp(-r_j t) and never changes
   sign. It holds r_j from 2 sqrt(K) (the critical damping coefficient) up, is ramped in
   smoothly from c_r Λ_V at r_j = sqrt(K) (the critically damped rate), and is c_r Λ_V below
   that, i.e. the literal law while the TCP is far from the goal relative to its speed. The
   added term is c J⁻¹ (D - c_r Λ_V) ė / c_r: q̈ stays linear in c (cases 1-4 exact) and
   continuous. Applied while converging to a fixed target (p_w; each waypoint in stop mode),
   ramped in with σ during the last blend. Sim 3 takes 5.28 s (literal 5.35 s with the
   overshoot, paper 5.32 s); critical damping on the whole final approach (c Λ_V
   sqrt(c*/c_r), the first version of this fix) also stops the overshoot but takes 5.86 s,
   because it slows the TCP long before any overshoot is possible. Caveat: when the limits
   bind while braking (c < c_r, or the improvement-2 fallback with c near 0, where the TCP
   coasts) no damping can act, and random tasks with hard limits can still overshoot.

Equation numbers in comments are the paper's.
"""


from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from drake_traj.errors import PlanningError
from drake_traj.planners.pajak.parameters import PajakConfig
from drake_traj.planners.scaling import relaxed_scaling
from drake_traj.robots import ur10e as robot

__all__ = [
    "DISCRETE_NAMES",
    "DISCRETE_SIZE",
    "PajakLaw",
    "acceleration_terms",
    "approach_damping",
    "blend_progress",
    "blended_target",
    "choose_scaling",
    "damping_factor",
    "scaling_interval",
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
TRAVEL = 6  # TCP path length since it entered the ball, up to the last update [m]
X_REF = slice(7, 10)  # TCP position at the last update [m]
BEST = 10  # smallest "remaining path" measure so far (progress monitor) [m]
T_BEST = 11  # time at which BEST was last improved [s]
SATURATED = 12  # number of updates at which no c in [0, 1] satisfied the limits (improvement 2)
DISCRETE_SIZE = 13
DISCRETE_NAMES = (
    "c", "t0", "c0", "waypoint", "blending", "sigma", "travel", "x_ref_x", "x_ref_y", "x_ref_z", "best",
    "t_best", "saturated",
)

_ORIENTATION_LENGTH = 0.1  # [m/rad], weight of orientation in the progress measure
_MIN_COS_PITCH = 1e-6  # Euler gimbal lock (as robot.analytic_jacobian_and_bias)
_BRAKE_TIME = 0.05  # [s], time constant of the fallback braking at low speed (improvement 2)
_BRAKE_GAP = 0.1  # emptiness of the c interval at which the fallback is pure braking



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


def approach_damping(error, error_rate, stiffness, damping, delta):
    """Damping [1/s] per error component that keeps it from changing sign (improvement 4).

    For ë = -D ė - K e per component, the approach rate r = -ė/e obeys dr/dt = r² - D r + K.
    With D = r + K/r it is constant: ė = -r e is invariant and e decays as exp(-r t) without
    crossing 0. Returned: D = the given ``damping`` for r <= sqrt(K) (the literal law), ramped
    (smoothstep in r) up to λ + K/λ at r = λ = 2 sqrt(K), and r + K/r above λ; never below
    ``damping``. Continuous in the state. r = -ė e / (e² + δ²): δ only keeps r finite at e = 0;
    a component heading for 0 is held before it gets there (also a lateral one).

    Args (broadcast together, e.g. (N, 6)): error e, error_rate ė = J q̇, stiffness K > 0,
    damping (the unmodified one, c_r Λ_V), delta δ > 0.
    """
    rate = -(error * error_rate) / (error * error + delta * delta)
    root = np.sqrt(stiffness)
    held = np.maximum(rate, 2.0 * root)
    hold = held + stiffness / held
    x = np.clip(rate / root - 1.0, 0.0, 1.0)
    return np.maximum(damping, damping + (hold - damping) * (x * x * (3.0 - 2.0 * x)))


def damping_factor(measure, threshold, max_damping):
    """λ² of the damped least-squares inverse (improvement 3): 0 for measure >= threshold,
    rising to max_damping² at a singular J: λ² = λ_max² (1 - (measure/threshold)²)."""
    ratio = np.minimum(np.asarray(measure, dtype=float) / threshold, 1.0)
    return (max_damping * max_damping) * (1.0 - ratio * ratio)


def _solve(jac, rhs, lam2=None):
    """J⁻¹ rhs (eq. 13), or (JᵀJ + λ²I)⁻¹ Jᵀ rhs (damped least squares) when lam2 is given."""
    if lam2 is None:
        return np.linalg.solve(jac, rhs)
    jt = np.swapaxes(jac, -1, -2)
    normal = jt @ jac + np.asarray(lam2)[..., None, None] * _EYE6
    return np.linalg.solve(normal, jt @ rhs)


_EYE6 = np.eye(6)


def acceleration_terms(jac, bias, error, qd, position_gain, velocity_gain, penalty=0.0, lam2=None):
    """(a, b_V, b_P) of eq. 17 with b = b_V + b_P:

    a = -J⁻¹ J̇q̇, b_V = -J⁻¹ Λ_V J q̇ + Δq̈, b_P = -J⁻¹ Λ_P e (e of eq. 6 or eq. 19).
    q̈ = a + c (b_V + b_P) is eq. 17; with c = 1 it is eq. 16 (eq. 13 without Δq̈).
    With ``lam2`` (λ², see :func:`damping_factor`) J⁻¹ is the damped least-squares inverse.
    Shapes: jac (..., 6, 6), the vectors (..., 6); gains broadcast against (..., 6).
    """
    jac = np.asarray(jac, dtype=float)
    shape = jac.shape[:-1] + (3,)
    rhs = np.empty(shape)
    rhs[..., 0] = bias
    rhs[..., 1] = velocity_gain * (jac @ np.asarray(qd, dtype=float)[..., None])[..., 0]
    rhs[..., 2] = position_gain * error
    sol = _solve(jac, rhs, lam2)
    return -sol[..., 0], penalty - sol[..., 1], -sol[..., 2]


def scaling_interval(a, b, qdd_min, qdd_max):
    """Interval [c_lo, c_hi] of c with q̈_min <= a + c b <= q̈_max on every joint (last axis).

    Each joint gives the bound of cases (1)-(4) (Corrected (docs/papers.md): (2) and (4) use q̈_min):
    b_i > 0: (q̈_min - a_i)/b_i <= c <= (q̈_max - a_i)/b_i; b_i < 0: the same with the roles
    of q̈_min and q̈_max swapped; b_i = 0: no bound if a_i is inside the box, else empty.
    Upper bounds (cases 1, 2) combine by min (case a), lower bounds (3, 4) by max (case b).
    The interval is empty where c_lo > c_hi.
    """
    b = np.asarray(b, dtype=float)
    if b.all():
        inv = 1.0 / b
        to_max = (qdd_max - a) * inv
        to_min = (qdd_min - a) * inv
    else:  # b_i = 0: ±inf bounds (a_i inside) or an empty interval (a_i outside)
        with np.errstate(divide="ignore", invalid="ignore"):
            to_max = (qdd_max - a) / b
            to_min = (qdd_min - a) / b
    # fmin/fmax ignore the NaN of 0/0 (a_i exactly on a bound with b_i = 0: no bound)
    return np.fmin(to_max, to_min).max(axis=-1), np.fmax(to_max, to_min).min(axis=-1)


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
        c = np.minimum(np.maximum(c, 0.0), 1.0)
    return c, feasible


def blend_progress(position, reference, travel, length):
    """σ of eq. 19 before the monotone max: the TCP path length through the ball / ``length``.

    σ = (ℓ + |x - x_ref|) / length, clipped to [0, 1], where ℓ is the path length accumulated
    at the updates since the TCP entered the ball and x_ref the TCP position at the last update.
    It is 0 on entry, continuous in x and grows whenever the TCP moves, so the target always
    leads (a projection on p_i -> p_{i+1} does not grow while the TCP is still heading for p_i,
    and 1 - δ/ϵ is not monotone: both stall, docs/papers.md). ``length`` = ``blend_length`` · ϵ.
    """
    step = np.sqrt(np.sum((position - reference) ** 2, axis=-1))
    return np.clip((travel + step) / length, 0.0, 1.0), step


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
    """The planning law of Pająk 2024 for one task, or for several tasks at once.

    State: continuous (q, q̇) and the discrete vector of :data:`DISCRETE_NAMES` (size
    :data:`DISCRETE_SIZE`; the first three entries are [c, t0, c0] of the scaling contract).

    Args:
        parameters: one :class:`PajakConfig` (then q, q̇ have shape (6,) and the discrete
            state (DISCRETE_SIZE,)), or a sequence of them for a batch of tasks (shapes (N, 6)
            and (N, DISCRETE_SIZE)); all must share the boolean flags.
    """

    def __init__(self, parameters):
        single = isinstance(parameters, PajakConfig)
        plist = [parameters] if single else list(parameters)
        if not plist:
            raise ValueError("parameters must be a PajakConfig or a non-empty sequence of them")
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
            "max_damping", "stop_speed", "stall_time", "blend_length",
        ):
            values = stack(name)
            setattr(self, name, values)
        # velocity-viability bound of the acceleration box (improvement 2): it falls from q̈_max
        # at d = ϑ/4 to 0 at the velocity limit
        self.viability_gain = self.qdd_max / (0.25 * self.vartheta[:, None] * 2.0 * self.qd_max)
        self.viability_onset = self.qd_max * (1.0 - 0.5 * self.vartheta[:, None])
        self.blend_distance = self.blend_length * self.neighbourhood
        # c below which condition (11) fails for the scaled gains c Λ_V, c Λ_P: 4 Λ_P / Λ_V² = 0.907
        self.critical_scaling = np.max(4.0 * self.kp / self.kv**2, axis=1)
        # improvement 4: regularisation δ of the approach rate at e_j = 0, 1e-4 ε (orientation
        # through _ORIENTATION_LENGTH); a relative δ (a fraction of |e|) lets small lateral
        # components cross 0 and overshot more random tasks
        delta = 1e-4 * self.accuracy[:, None]
        self.approach_delta = np.concatenate(
            [np.repeat(delta, 3, axis=1), np.repeat(delta / _ORIENTATION_LENGTH, 3, axis=1)], axis=1
        )
        self._rows = np.arange(count)
        self._zeros = np.zeros(count)
        self._ones = np.ones(count)
        self._false = np.zeros(count, dtype=bool)
        # |q̇| above which the penalty of eq. 14 is active: d < ϑ  <=>  |q̇| > q̇_max (1 - 2ϑ)
        self.penalty_onset = self.qd_max * (1.0 - 2.0 * self.vartheta[:, None])

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
    def _kinematics(self, q, qd):
        if self.count == 1:
            pose, jac, bias, cy, measure = robot.ur10e_kinematics(q[0], qd[0])
            return pose[None], jac[None], bias[None], np.array([cy]), np.array([measure])
        return robot.ur10e_kinematics(q, qd)

    def _evaluate(self, t, q, qd, d) -> _Evaluation:
        pose, jac, bias, cy, measure = self._kinematics(q, qd)
        rows = self._rows
        i = d[:, WAYPOINT].astype(np.intp)
        p_i = self.waypoints[rows, i]
        blending = d[:, BLENDING] > 0.5
        if self.blend_waypoints and blending.any():
            p_next = self.waypoints[rows, np.minimum(i + 1, self.num_waypoints - 1)]
            raw, _ = blend_progress(pose[:, :3], d[:, X_REF], d[:, TRAVEL], self.blend_distance)
            sigma = np.where(blending, np.maximum(raw, d[:, SIGMA]), 0.0)  # monotone σ
            target = np.where(blending[:, None], blended_target(p_i, p_next, sigma), p_i)  # eq. 19
        else:
            sigma = self._zeros
            target = p_i  # eq. 6
        error = pose - target
        error[:, 3:] = robot.wrap_angle(error[:, 3:])  # orientation wrapped (docs/papers.md)
        if self.limit_velocity and (np.abs(qd) > self.penalty_onset).any():
            penalty = velocity_penalty(
                qd, -self.qd_max, self.qd_max, self.rho[:, None], self.vartheta[:, None],
                smooth=self.smooth_penalty,
            )  # eq. 14-15
        else:
            penalty = 0.0
        lam2 = None
        if self.damped_inverse and (measure < self.singularity_threshold).any():
            lam2 = damping_factor(measure, self.singularity_threshold, self.max_damping)
        a, b_v, b_p = acceleration_terms(jac, bias, error, qd, self.kp, self.kv, penalty, lam2)  # eq. 17
        saturated = self._false
        if not self.limit_acceleration:
            c_r = c = self._ones
            qdd = a + b_v + b_p  # eq. 16 (eq. 13 without the penalty)
            return _Evaluation(qdd, c, c_r, saturated, pose, target, sigma, measure, cy)
        c_r = relaxed_scaling(t, d[:, T0], d[:, C0], 1.0, self.scaling_rate)[0]  # eq. 18
        b = b_v + b_p
        if self.preserve_damping:
            # improvement 4: per error component, the damping that keeps it from changing sign
            # (approach_damping), with the gains scaled by c_r so that q̈ stays linear in c.
            # Applied while converging to a fixed target (p_w; every waypoint in stop mode),
            # ramped in with σ during the last blend so that q̈ stays continuous.
            if not self.blend_waypoints:
                weight = self._ones
            elif (i >= self.num_waypoints - 2).any():
                weight = np.where(i >= self.num_waypoints - 1, 1.0, np.where(i == self.num_waypoints - 2, sigma, 0.0))
            else:
                weight = None
            if weight is not None:
                scale = np.minimum(np.maximum(c_r, 1e-3), 1.0)[:, None]
                error_rate = (jac @ qd[:, :, None])[:, :, 0]  # ė = J q̇
                damping = approach_damping(error, error_rate, scale * self.kp, scale * self.kv, self.approach_delta)
                added = weight[:, None] * (damping / scale - self.kv)  # per unit of c
                if (added > 0.0).any():
                    b = b - _solve(jac, (added * error_rate)[:, :, None], lam2)[:, :, 0]
        lower, upper = -self.qdd_max, self.qdd_max
        if self.bounded_scaling and self.limit_velocity and (np.abs(qd) > self.viability_onset).any():
            # improvement 2: the box also keeps q̇ viable: q̈_i <= K (q̇_max - q̇_i) (and the
            # mirror bound), so q̇ can only approach its limit exponentially even when c is held
            # small by another joint and the penalty (scaled by c) cannot act. K puts the bound's
            # onset at d = ϑ/4, inside the penalty zone.
            upper = np.minimum(np.maximum(self.viability_gain * (self.qd_max - qd), lower), upper)
            lower = np.minimum(np.maximum(self.viability_gain * (-self.qd_max - qd), lower), -lower)
        c_lo, c_hi = scaling_interval(a, b, lower, upper)  # cases 1-4
        c, feasible = choose_scaling(c_r, c_lo, c_hi, bounded=self.bounded_scaling)  # cases a-c
        qdd = a + c[:, None] * b  # eq. 17
        if self.bounded_scaling and not feasible.all():
            # improvement 2: no c in [0, 1] keeps the limits (then a = -J⁻¹J̇q̇ alone breaks
            # them: the joints move too fast for the curvature of the path). Blend, by how
            # empty the interval is, from q̈ clipped to the box to braking all joints
            # proportionally at the largest admissible rate; both stay in the box (braking only
            # lowers |q̇|), and the blend is continuous.
            saturated = ~feasible
            clipped = np.minimum(np.maximum(qdd, lower), upper)
            with np.errstate(divide="ignore"):
                rate = np.min(self.qdd_max / np.abs(qd), axis=1)
            brake = -qd * np.minimum(rate, 1.0 / _BRAKE_TIME)[:, None]
            gap = np.maximum(c_lo, 0.0) - np.minimum(c_hi, 1.0)
            weight = np.minimum(np.maximum(gap / _BRAKE_GAP, 0.0), 1.0)[:, None]
            qdd = np.where(saturated[:, None], clipped + weight * (brake - clipped), qdd)
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
            _, step = blend_progress(position, d[:, X_REF], d[:, TRAVEL], self.blend_distance)
            d[:, TRAVEL] = np.where(blending, d[:, TRAVEL] + step, 0.0)
            d[:, X_REF] = position
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
            d[:, BLENDING] = np.where(enter, 1.0, d[:, BLENDING])
            d[:, TRAVEL] = np.where(enter, 0.0, d[:, TRAVEL])
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
        d[:, BEST] = np.where(improved, remaining, d[:, BEST])
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
            _, jac, _, _, _ = robot.ur10e_kinematics(q[0], qd[0])
            return np.array([np.linalg.norm(jac[:3] @ qd[0])])
        _, jac, _, _, _ = robot.ur10e_kinematics(q, qd)
        return np.linalg.norm(np.einsum("nij,nj->ni", jac[:, :3], qd), axis=1)

    def finished(self, q, qd, discrete):
        """True once the TCP is within ε of the final waypoint p_w and p_w is the active target."""
        q2, d2 = self._batch(q, 6), self._batch(discrete, DISCRETE_SIZE)
        pose, *_ = self._kinematics(q2, np.zeros_like(q2))  # the fast scalar path for one task
        i = d2[:, WAYPOINT].astype(int)
        last = i >= self.num_waypoints - 1
        distance = np.linalg.norm(pose[:, :3] - self.waypoints[self._rows, i, :3], axis=1)
        done = last & (distance < self.accuracy)
        return bool(done[0]) if self.single else done

    def tcp_positions(self) -> np.ndarray:
        """Waypoint positions [m], (w, 3) (single task) for plots."""
        return self.waypoints[0, : self.num_waypoints[0], :3].copy()


_CAUSES = {-1: "stall", -2: "singular", -3: "non-finite", -4: "timeout"}
