"""The Pająk 2024 law, compiled: every equation of the planner (its discrete update and fixed-step
integrator are in :mod:`.stepping`).

This module is the one implementation of the law, with its task-space terms (:mod:`.terms`: J⁻¹,
a and b of eq. 17, the approach damping, σ of eq. 19), its limit keeping (:mod:`.limits`: the
choice of c, the braking) and its update and integrator (:mod:`.stepping`). :mod:`.law` wraps it
for Python callers (the Drake system, tests) and :mod:`.integration` for whole runs; the functions
here and in :mod:`.stepping` take flat float vectors whose layouts are the enums below, so that a
call from Python costs no conversion:

- :class:`Parameter`: the task's settings (from :class:`~.config.PajakConfig`), with the
  waypoints (w, 6) and the remaining path after each waypoint (w,) as separate arrays;
- :class:`Discrete`: the discrete state of the law (the Drake system's ``scaling`` group is its
  first three entries, c, t0 and c0);
- :class:`Evaluation`: what one evaluation computes (q̈, c, the pose, the target, ...);
- :class:`Log`: one sample of :func:`~.stepping.integrate_kernel`'s log;

and the arm, ``model`` (its kinematic data, :attr:`~drake_traj.robots.base.TaskKinematics.model`),
and its TCP, ``tool`` (4, 4): X_FT, the TCP in the flange frame
(:attr:`~drake_traj.robots.Robot.tcp_offset`), arguments of every kernel that evaluates k(q).

Equation numbers in comments are Pająk 2024's; docs/papers.md explains the corrections and our
improvements (each a flag of the parameters).
"""

import inspect
import math
from enum import IntEnum

import numpy as np

from drake_traj import compiled as compiled_module
from drake_traj.compiled import compiled, sources_digest
from drake_traj.planners.laws import scaling
from drake_traj.planners.laws.scaling import relaxed_scaling
from drake_traj.planners.pajak import limits, terms
from drake_traj.planners.pajak.limits import (brake, brake_weight, choose_scaling, holding_joint, keep_limits,
                                              limit_jerk, scaling_interval, scaling_slew)
from drake_traj.planners.pajak.terms import (acceleration_terms, approach_damping, approach_rate, blend_progress,
                                             budgeted_rate, damping_factor)
from drake_traj.robots import UR10E, compiled_kinematics

__all__ = [
    "Discrete", "Evaluation", "Log", "Parameter", "Status", "acceleration_box", "blended_target", "KINEMATICS",
    "evaluate_kernel", "velocity_penalty", "viability_bound",
]


def _layout(name: str, fields) -> type[IntEnum]:
    """An IntEnum of the start index of each (field, size) in a flat vector, and SIZE."""
    offsets, start = {}, 0
    for field, size in fields:
        offsets[field] = start
        start += size
    offsets["SIZE"] = start
    return IntEnum(name, offsets)


Parameter = _layout("Parameter", [
    ("KP", 6), ("KV", 6),  # Λ_P [1/s²], Λ_V [1/s] per task component (eq. 9)
    ("QD_MAX", 6), ("QDD_MAX", 6),  # joint limits [rad/s], [rad/s²] (eq. 4-5)
    ("VIABILITY_GAIN", 6),  # K, the slope of the velocity-viability bound at the limit (viability_bound) [1/s]
    ("VIABILITY_ONSET", 6),  # |q̇_i| above which that bound can bind [rad/s]
    ("PENALTY_ONSET", 6),  # |q̇_i| above which the penalty of eq. 14 is active [rad/s]
    ("VARTHETA", 1), ("RHO", 1),  # ϑ, ρ of eq. 14
    ("ACCURACY", 1),  # ε [m]
    ("ORIENTATION_ACCURACY", 1),  # the finish's orientation bound [rad]
    ("NEIGHBOURHOOD", 1),  # ϵ [m] (eq. 19)
    ("BLEND_DISTANCE", 1),  # path length through the ball at which σ = 1 [m]
    ("SCALING_RATE", 1),  # rate of eq. 18 [1/s]
    ("SCALING_SLEW", 1),  # largest |dc/dt| [1/s] (improvement 1)
    ("JERK_BUDGET", 1),  # largest |dq̈_i/dt| that c, σ and the approach rate may cause [rad/s³] (improvement 1)
    ("JERK_LIMIT", 1),  # largest |dq̈_i/dt| within the joint limits [rad/s³] (improvement 1)
    ("SINGULARITY_THRESHOLD", 1), ("MAX_DAMPING", 1),  # damped least squares (improvement 3)
    ("APPROACH_DELTA", 1),  # δ of the approach rate [m] (improvement 4)
    ("STOP_SPEED", 1),  # stop mode: TCP speed below which a waypoint is reached [m/s]
    ("STALL_TIME", 1),  # no progress for this long is a stall [s]
    ("NUM_WAYPOINTS", 1),
    # switches (1.0 on, 0.0 off): PajakConfig's flags
    ("LIMIT_VELOCITY", 1), ("LIMIT_ACCELERATION", 1), ("BLEND_WAYPOINTS", 1), ("SMOOTH_PENALTY", 1),
    ("CONTINUOUS_SWITCHING", 1), ("BOUNDED_SCALING", 1), ("DAMPED_INVERSE", 1), ("PRESERVE_DAMPING", 1),
    ("CONTINUOUS_ORIENTATION", 1),
    ("MIN_COS_PITCH", 1),  # |cos φ_Y| below which the law stops at the Euler angles' gimbal lock (SINGULAR)
])

Discrete = _layout("Discrete", [
    ("C", 1),  # c at the last update
    ("T0", 1), ("C0", 1),  # eq. 18 anchor: c was C0 at time T0 [s]
    ("GOAL", 1),  # the value c relaxes to (eq. 18: 1; the speed override)
    ("T_UPDATE", 1),  # time of the last update [s]
    ("WAYPOINT", 1),  # index i of the active waypoint p_i (an integer)
    ("BLENDING", 1),  # 1 while the TCP passes the neighbourhood of p_i (eq. 19, second case)
    ("SIGMA", 1),  # σ of eq. 19 at the last update (σ never decreases)
    ("TRAVEL", 1),  # TCP path length since it entered the ball, up to the last update [m]
    ("X_REF", 3),  # TCP position at the last update [m]
    ("BEST", 1),  # smallest remaining path so far (progress monitor) [m]
    ("T_BEST", 1),  # when BEST last improved [s]
    ("BRAKE", 1), ("BRAKE_SLOPE", 1),  # fallback braking weight at the last update and its slope [1/s]
    ("SATURATED", 1),  # updates at which the limits overruled the law (improvement 2)
    ("APPROACH", 1),  # approach rate of improvement 4 at the last update (0 where unused) [1/s]
    ("BRANCH", 1),  # 1 once ERROR and FINAL_ERROR hold the last update's orientation errors (improvement 6)
    ("ERROR", 3), ("FINAL_ERROR", 3),  # orientation part of e (eq. 6/19) and of the error to p_w there [rad]
    ("HELD_BY", 1), ("HELD_BY_VELOCITY", 1),  # Evaluation.HOLDING(_VELOCITY) when the limits last set c (the anchor)
    ("QDD", 6), ("QDD_TIME", 1),  # q̈ after the last update and its time, the jerk limit's reference [rad/s², s]
])

Evaluation = _layout("Evaluation", [
    ("QDD", 6),  # q̈ [rad/s²]
    ("C", 1), ("C_RELAXED", 1),  # c and the eq. 18 value c_r
    ("SATURATED", 1),  # 1 where the limits overrule the law (q̈ clipped to the box, braking, the jerk limit)
    ("VIOLATION", 1),  # how far a = -J⁻¹J̇q̇ alone is outside the box, relative to q̈_max
    ("BRAKE", 1),  # weight of the fallback braking in q̈
    ("SIGMA", 1), ("MEASURE", 1), ("COS_PITCH", 1),  # σ, singularity measure, cos φ_Y
    ("POSE", 6), ("TARGET", 6),  # k(q) and the target of eq. 6 / eq. 19 [m, rad]
    ("POSITION_ERROR", 1), ("ORIENTATION_ERROR", 1),  # to the active waypoint (update_kernel) [m, rad]
    ("REMAINING", 1),  # remaining path to p_w (update_kernel) [m]
    ("APPROACH", 1),  # approach rate the damping of improvement 4 is sized for (0 where unused) [1/s]
    ("ERROR", 3), ("FINAL_ERROR", 3),  # orientation part of e and of the error to p_w (improvement 6) [rad]
    ("HOLDING", 1),  # the joint whose limit bounds c lowest (limits.holding_joint; -1: none below 1)
    ("HOLDING_VELOCITY", 1),  # 1 where that bound is its velocity limit's viability bound, 0 its acceleration limit
])

Log = _layout("Log", [
    ("T", 1), ("Q", 6), ("QD", 6), ("QDD", 6), ("C", 1), ("TCP", 6), ("SATURATED", 1),
    ("DISCRETE", int(Discrete.SIZE)),
])


class Status(IntEnum):
    """What :func:`~.stepping.update_kernel` and :func:`~.stepping.integrate_kernel` report."""

    RUNNING = 0
    FINISHED = 1
    STALL = -1
    SINGULAR = -2  # Euler gimbal lock
    NON_FINITE = -3
    TIMEOUT = -4


MIN_COS_PITCH = 1e-6  # Euler gimbal lock (as the UR10e's analytic_jacobian_and_bias): the paper's method
# "ours" (improvement 6 on): stop at the Euler angles' gimbal lock once φ_Y is within 1e-3 rad
# (0.057°) of ±90° (the margin PajakConfig.validate keeps waypoints from it). Closer, B(φ)⁻¹ and
# with it a = -J⁻¹J̇q̇ grow as 1/cos φ_Y: on moves of 1 rad per joint (examples/pajak_sweep.py,
# seed 9) task 42 passed |cos φ_Y| = 1.6e-4, a left the acceleration box for a sample and q̈ jumped
# by 1.93 rad/s² in 1 ms (1.28 at 0.5 ms); the finished tasks that pass nearest without a jump reach
# 0.010 (at 1.0 rad per joint) and 0.028 (0.7 rad), with at most 0.27 rad/s² per ms (measured)
GIMBAL_MARGIN = 1e-3
SCALE_FLOOR = 0.1  # smallest c_r the approach damping is sized for (improvement 4)
# largest |∂Δq̈_i/∂q̇_i| of the smooth penalty [1/s] (improvement 1): above the paper task's 59 1/s
# (sim 3 keeps its numbers), far below the 1 ms step's stability bound of 2.8/1 ms (RK4). Riding
# it, the penalty changes q̈_i at c · stiffness · q̈_i: at 300 1/s that was 0.10-0.17 rad/s² per ms
# on moves of 1 rad per joint (c of 0.15-0.5, q̈_i near its limit); at 150 half that
PENALTY_STIFFNESS = 150.0
# the velocity-viability bound aims this fraction of q̇_max below the limit: riding it for seconds
# (q̇ within 1e-15 of the limit), an RK4 stage, whose q̇ uses another stage's q̈, passed the limit
# by 1e-10 rad/s (measured)
VIABILITY_MARGIN = 1e-6
# q̇_max - q̇_min [rad/s] below which the cap grows as (PENALTY_SPAN/span)², so the knee stays at
# one d, (2ρ/(cap PENALTY_SPAN²))^(1/3) (0.074 with the defaults): the stiffness at a given d grows
# as 1/span², and an absolute cap made the penalty too weak to keep q̇ off low limits (c then held
# near 0 by the velocity limit's viability bound: a stall)
PENALTY_SPAN = 1.0

# The compiled task kinematics (Robot.task_kinematics), bound once as module globals: numba
# compiles the calls to them into the law and caches the law on disk. Passed in (a closure over
# compiled functions, or an argument), they would miss numba's cache in every process (measured:
# a closure over a compiled function recompiled in each new process), and the law takes 12-40 s
# to compile. The law is therefore bound to one kinematics function for every arm
# (compiled_kinematics.task_kinematics_into), and the arm is data: the ``model`` array argument
# (the UR e-Series closed form's lengths, or a generic chain), as the TCP offset is (``tool``);
# numba's cache keys arrays by their type only, so one compiled law serves every arm and tool.
# :mod:`.stepping` (the update, the finish test) binds these same globals.
KINEMATICS = UR10E.task_kinematics()
kinematics_into, orientation_error, wrapped = KINEMATICS.kinematics_into, KINEMATICS.orientation_error, KINEMATICS.wrapped


# --------------------------------------------------------------------------------------------
# The law's joint-space pieces (compiled functions of floats and small arrays, tested one by one;
# its task-space terms are in :mod:`.terms`)
# --------------------------------------------------------------------------------------------


@compiled
def velocity_penalty(qd: float, qd_max: float, rho: float, vartheta: float, smooth: bool) -> float:
    """Δq̈_i = -∂κ(q̇_i)/∂q̇_i (eq. 15) for the interior penalty κ of eq. 14 [rad/s²], limits ±q̇_max.

    d(q̇_i) = min(q̇_i - q̇_min, q̇_max - q̇_i) / (q̇_max - q̇_min) (eq. 14). Literal (``smooth``
    False): κ = ρ (1/d - 1/ϑ) for d < ϑ, whose slope -ρ/ϑ² at d = ϑ makes q̈ jump by
    ρ/((q̇_max - q̇_min) ϑ²) when the penalty switches on. Smooth (improvement 1): κ minus its
    tangent at ϑ, κ = ρ (1/d - 1/ϑ + (d - ϑ)/ϑ²), zero value and slope at the threshold; and
    its stiffness |∂Δq̈_i/∂q̇_i| = 2ρ/(d³ span²) capped at PENALTY_STIFFNESS, scaled by
    (PENALTY_SPAN/span)² for a span = q̇_max - q̇_min below PENALTY_SPAN [rad/s]: below the d where
    it reaches the cap (the knee, at most ϑ), Δq̈_i goes on linearly with that slope (an affine κ'
    in q̇), so the penalty never makes the law stiff (with d of 0.02 the uncapped stiffness was
    4000 1/s and q̈ chattered by 1 rad/s² at a 1 ms step; the velocity limit itself is held by the
    acceleration box's viability bound, improvement 2). The scaling keeps the knee at one d for
    low limits: the stiffness at a given d grows as 1/span², and an absolute cap moved the knee
    above ϑ at 0.06 rad/s, where the penalty jumped at ϑ and pushed towards the limit (the law
    stalled). d is floored at 1e-3 beyond the limits.
    """
    span = 2.0 * qd_max
    to_min = qd + qd_max
    to_max = qd_max - qd
    d = max(min(to_min, to_max) / span, 1e-3)  # eq. 14
    if d >= vartheta:
        return 0.0
    if smooth:
        cap = PENALTY_STIFFNESS * max(1.0, (PENALTY_SPAN / span) ** 2)
        # stiffness = the cap at d = knee; a knee at or above ϑ (a large ρ) makes the penalty linear from ϑ
        knee = min((2.0 * rho / (cap * span * span)) ** (1.0 / 3.0), vartheta)
        magnitude = rho / (max(d, knee) ** 2 * span) - rho / (vartheta * vartheta * span)
        if d < knee:
            magnitude += cap * span * (knee - d)
    else:
        magnitude = rho / (d * d * span)
    # ∂κ/∂q̇_i = κ'(d) ∂d/∂q̇_i, ∂d/∂q̇_i = -1/span near q̇_max: eq. 15 pushes from the nearer limit
    return -magnitude if to_max < to_min else magnitude


@compiled
def acceleration_box(qd, p, lower, upper):
    """The box [lower, upper] (6 each) that q̈ must stay in: ±q̈_max (eq. 5), narrowed near the
    velocity limits (improvement 2) so that q̇ stays viable: q̈_i <= viability_bound(q̇_max - q̇_i)
    and the mirror bound, so q̇ can only approach its limit exponentially even when c is held
    small by another joint and the penalty (scaled by c) cannot act."""
    viable = p[Parameter.BOUNDED_SCALING] > 0.0 and p[Parameter.LIMIT_VELOCITY] > 0.0
    jerk = p[Parameter.JERK_BUDGET]
    for k in range(6):
        limit = p[Parameter.QDD_MAX + k]
        lower[k], upper[k] = -limit, limit
        if viable and abs(qd[k]) > p[Parameter.VIABILITY_ONSET + k]:
            gain = p[Parameter.VIABILITY_GAIN + k]
            speed = p[Parameter.QD_MAX + k] * (1.0 - VIABILITY_MARGIN)
            upper[k] = min(max(viability_bound(speed - qd[k], gain, jerk), -limit), limit)
            lower[k] = min(max(-viability_bound(speed + qd[k], gain, jerk), -limit), limit)


@compiled
def viability_bound(gap: float, gain: float, jerk: float) -> float:
    """The largest q̈_i [rad/s²] towards a velocity limit ``gap`` = q̇_max - |q̇_i| away [rad/s]
    (improvement 2, with improvement 1's jerk budget): f(x) = sqrt(2 J x + (J/K)²) - J/K for
    x >= 0, K x beyond the limit (x < 0). q̈ riding the bound changes at f'(x) f(x) =
    J (1 - (J/K) / sqrt(2 J x + (J/K)²)) < ``jerk`` J [rad/s³], where the linear bound K x
    changed it at K f, up to K q̈_max (0.1-0.3 rad/s² per ms at moves of 1 rad); its slope at the limit is ``gain`` K
    [1/s], so q̇ still approaches the limit exponentially, at rate K."""
    if gap <= 0.0:
        return gain * gap
    offset = jerk / gain
    return math.sqrt(2.0 * jerk * gap + offset * offset) - offset


# --------------------------------------------------------------------------------------------
# The law
# --------------------------------------------------------------------------------------------
#
# numba caches a compiled function under its own source file only (numba issue #1833): after an
# edit of the robot's kinematics, of eq. 18, of the limit keeping (limits.py) or of the task-space
# terms (terms.py) in their modules, the cached law would go on using the old code. Numba does hash
# a function's closure into its cache key, so each function below that reaches compiled code of
# another module is made in a closure over the digest of those modules' sources
# (``dependencies``, unused otherwise); they call each other through the module's globals.


DEPENDENCY_SOURCES = (
    *(inspect.getsourcefile(function.py_func) for function in (kinematics_into, orientation_error, wrapped)),
    *compiled_kinematics.SOURCES, scaling.__file__, limits.__file__, terms.__file__, compiled_module.__file__)
_DEPENDENCIES = sources_digest(*DEPENDENCY_SOURCES)


def _blended_target(dependencies):
    @compiled
    def blended_target(p_i, p_next, sigma):
        """σ p_{i+1} + (1 - σ) p_i of eq. 19, the orientation part along the wrapped difference."""
        dependencies  # noqa: B018 (numba's cache key, see above)
        target = np.empty(6)
        for k in range(6):
            step = p_next[k] - p_i[k]
            if k >= 3:
                step = wrapped(step)
            target[k] = p_i[k] + sigma * step
        return target

    return blended_target


blended_target = _blended_target(_DEPENDENCIES)


def _evaluate_kernel(dependencies):
    @compiled
    def evaluate_kernel(t, q, qd, d, p, model, tool, waypoints, out):
        """One evaluation of the law at time t for (q, q̇) and the discrete state ``d`` into
        ``out`` (layout :class:`Evaluation`): q̈ of eq. 17 with c from eq. 18 and the limits,
        for the TCP ``tool`` (X_FT): the pose k(q) of eq. 6, J and J̇q̇ of eq. 13 are the TCP's.

        No exception: gimbal lock shows in out[COS_PITCH], a failure as non-finite out[QDD].
        """
        dependencies  # noqa: B018 (numba's cache key, see above)
        pose = out[Evaluation.POSE:Evaluation.POSE + 6]
        qdd = out[Evaluation.QDD:Evaluation.QDD + 6]
        target = out[Evaluation.TARGET:Evaluation.TARGET + 6]
        jac = np.empty((6, 6))
        bias = np.empty(6)
        cos_pitch, measure = kinematics_into(model, q, qd, tool, pose, jac, bias)  # k(q), J, J̇q̇ (eq. 6, 13)
        out[Evaluation.COS_PITCH] = cos_pitch
        out[Evaluation.MEASURE] = measure
        out[Evaluation.SATURATED] = 0.0
        out[Evaluation.VIOLATION] = 0.0
        out[Evaluation.BRAKE] = 0.0
        i = int(d[Discrete.WAYPOINT])
        last = int(p[Parameter.NUM_WAYPOINTS]) - 1
        use_damped = p[Parameter.DAMPED_INVERSE] > 0.0 and measure < p[Parameter.SINGULARITY_THRESHOLD]
        lam2 = 0.0
        if use_damped:
            lam2 = damping_factor(measure, p[Parameter.SINGULARITY_THRESHOLD], p[Parameter.MAX_DAMPING])
        kp = p[Parameter.KP:Parameter.KP + 6]
        limited = p[Parameter.LIMIT_ACCELERATION] > 0.0
        bounded = limited and p[Parameter.BOUNDED_SCALING] > 0.0
        elapsed = max(t - d[Discrete.T_UPDATE], 0.0)
        # c is at most this until the next update (improvement 1's rate limit of c)
        scale_bound = min(d[Discrete.C] + p[Parameter.SCALING_SLEW] * elapsed, 1.0)
        out[Evaluation.APPROACH] = 0.0
        out[Evaluation.HOLDING] = -1.0
        out[Evaluation.HOLDING_VELOCITY] = 0.0
        sigma = 0.0
        if p[Parameter.BLEND_WAYPOINTS] > 0.0 and d[Discrete.BLENDING] > 0.5:
            raw, _ = blend_progress(pose, d[Discrete.X_REF:Discrete.X_REF + 3], d[Discrete.TRAVEL],
                                    p[Parameter.BLEND_DISTANCE])
            following = min(i + 1, last)
            if bounded:
                # improvement 1: σ follows the TCP's path, but no faster than the jerk budget
                # allows. The target moves by p_{i+1} - p_i per unit of σ, so q̈ by
                # c J⁻¹ (Λ_P ∘ (p_{i+1} - p_i)) (eq. 17). Driven by the path alone σ moves the
                # target at (path speed) |p_{i+1} - p_i| / (1.25 ϵ): on a long leg entered at
                # speed, q̈ changed by up to 0.17 rad/s² per ms for tens of ms.
                step = np.empty(6)
                for k in range(6):
                    step[k] = waypoints[following, k] - waypoints[i, k]
                    if k >= 3:
                        step[k] = wrapped(step[k])
                    step[k] *= kp[k]
                rate = budgeted_rate(jac, lam2, use_damped, step, scale_bound, p[Parameter.JERK_BUDGET])
                raw = min(raw, d[Discrete.SIGMA] + rate * elapsed)
            sigma = max(raw, d[Discrete.SIGMA])  # σ never decreases
            target[:] = blended_target(waypoints[i], waypoints[following], sigma)  # eq. 19
        else:
            target[:] = waypoints[i]  # eq. 6
        out[Evaluation.SIGMA] = sigma
        error = np.empty(6)
        error_rate = np.empty(6)
        final = np.empty(6)  # the error to p_w (improvement 4's approach rate)
        goal = i if p[Parameter.BLEND_WAYPOINTS] == 0.0 else last
        # improvement 6: each orientation component on the branch (a multiple of 2π) nearest to its
        # value at the last update, so that it is continuous where it passes ±π (wrapped to the
        # shortest branch it jumps by 2π there, and q̈ with it: by up to 3.8 rad/s² in 1 ms on
        # moves of 1 rad per joint, where φ_X and φ_Z turn fast near the Euler angles' gimbal lock)
        continued = p[Parameter.CONTINUOUS_ORIENTATION] > 0.0 and d[Discrete.BRANCH] > 0.5
        for k in range(6):
            error[k] = pose[k] - target[k]  # eq. 6
            final[k] = pose[k] - waypoints[goal, k]
            if k >= 3:
                if continued:
                    last_error = d[Discrete.ERROR + k - 3]
                    last_final = d[Discrete.FINAL_ERROR + k - 3]
                    error[k] = last_error + wrapped(error[k] - last_error)
                    final[k] = last_final + wrapped(final[k] - last_final)
                else:
                    error[k] = wrapped(error[k])  # orientation wrapped (docs/papers.md)
                    final[k] = wrapped(final[k])
                out[Evaluation.ERROR + k - 3] = error[k]
                out[Evaluation.FINAL_ERROR + k - 3] = final[k]
            rate = 0.0
            for j in range(6):
                rate += jac[k, j] * qd[j]
            error_rate[k] = rate  # ė = J q̇
        penalty = np.zeros(6)
        if p[Parameter.LIMIT_VELOCITY] > 0.0:
            smooth = p[Parameter.SMOOTH_PENALTY] > 0.0
            for k in range(6):
                if abs(qd[k]) > p[Parameter.PENALTY_ONSET + k]:
                    penalty[k] = velocity_penalty(qd[k], p[Parameter.QD_MAX + k], p[Parameter.RHO],
                                                  p[Parameter.VARTHETA], smooth)  # eq. 14-15
        damping = p[Parameter.KV:Parameter.KV + 6].copy()
        c_r = 1.0
        if limited:
            c_r = relaxed_scaling(t, d[Discrete.T0], d[Discrete.C0], d[Discrete.GOAL],
                                  p[Parameter.SCALING_RATE])[0]  # eq. 18
        if limited and p[Parameter.PRESERVE_DAMPING] > 0.0:
            # improvement 4: with the gains scaled by c the damping breaks condition (11) below
            # c = 4 Λ_P / Λ_V² and the TCP overshoots p_w. The damping that holds the approach
            # rate (approach_damping), sized for c = c_r (at least SCALE_FLOOR) and scaled by c
            # like the rest of b, so q̈ stays linear in c. Applied while converging to a fixed
            # target (p_w; every waypoint in stop mode), ramped in with σ during the last blend.
            weight = 0.0
            if p[Parameter.BLEND_WAYPOINTS] == 0.0 or i >= last:
                weight = 1.0
            elif i == last - 1:
                weight = sigma
            if weight > 0.0:
                closing = approach_rate(final, error_rate, p[Parameter.APPROACH_DELTA])
                scale = min(max(c_r, SCALE_FLOOR), 1.0)
                previous = d[Discrete.APPROACH]
                if bounded and closing < previous:
                    # improvement 1: the damping eases off no faster than the jerk budget allows.
                    # When the TCP sweeps past p_w within millimetres, r falls from several per
                    # second to 0 within a few ms, and with it the damping (per unit of c, several
                    # times Λ_V with c_r at SCALE_FLOOR): q̈ changed by up to 0.15 rad/s² per ms.
                    # Held higher, r only adds damping (no overshoot); it may rise at once.
                    # ∂q̈/∂r = -c J⁻¹ (weight ∂D/∂r ∘ ė) (eq. 17), with the largest slope of
                    # approach_damping (per unit of c): 1 - K/r² < 1 above r = 2 √K, at most
                    # 1.5 (2.5 - D_0/√K) on its smoothstep (D_0 the damping it starts from).
                    direction = np.empty(6)
                    for k in range(6):
                        slope = max(1.0, 1.5 * (2.5 - damping[k] * math.sqrt(scale / kp[k])))
                        direction[k] = weight * slope / scale * error_rate[k]
                    fall = budgeted_rate(jac, lam2, use_damped, direction, scale_bound, p[Parameter.JERK_BUDGET])
                    closing = max(closing, previous - fall * elapsed)
                out[Evaluation.APPROACH] = closing
                for k in range(6):
                    held = approach_damping(closing, scale * kp[k], scale * damping[k])
                    damping[k] += weight * (held / scale - damping[k])  # per unit of c
        a = np.empty(6)
        b = np.empty(6)
        acceleration_terms(jac, bias, error, error_rate, kp, damping, penalty, lam2, use_damped, a, b)  # eq. 17
        if not limited:
            out[Evaluation.C] = 1.0
            out[Evaluation.C_RELAXED] = 1.0
            for k in range(6):
                qdd[k] = a[k] + b[k]  # eq. 16 (eq. 13 without the penalty)
            return
        out[Evaluation.C_RELAXED] = c_r
        lower = np.empty(6)
        upper = np.empty(6)
        acceleration_box(qd, p, lower, upper)
        holding, by_velocity = holding_joint(a, b, lower, upper, p[Parameter.QDD_MAX:Parameter.QDD_MAX + 6])
        out[Evaluation.HOLDING] = holding
        out[Evaluation.HOLDING_VELOCITY] = 1.0 if by_velocity else 0.0
        if p[Parameter.BOUNDED_SCALING] == 0.0:  # the paper's choice of c (may leave [0, 1])
            c_lo, c_hi = scaling_interval(a, b, lower, upper)  # cases 1-4
            c, _ = choose_scaling(c_r, c_lo, c_hi, False)  # cases a-c
            out[Evaluation.C] = c
            for k in range(6):
                qdd[k] = a[k] + c * b[k]  # eq. 17
            return
        qdd_max = p[Parameter.QDD_MAX:Parameter.QDD_MAX + 6]
        slew = scaling_slew(b, p[Parameter.SCALING_SLEW], p[Parameter.JERK_BUDGET]) * elapsed
        c, violation = keep_limits(a, b, c_r, lower, upper, qdd_max, d[Discrete.C] - slew, d[Discrete.C] + slew,
                                   qdd)
        out[Evaluation.C] = c
        out[Evaluation.VIOLATION] = violation
        weight, _ = brake_weight(violation, d[Discrete.BRAKE], d[Discrete.BRAKE_SLOPE], elapsed)
        out[Evaluation.BRAKE] = weight
        if weight > 0.0:
            brake(qd, lower, upper, qdd_max, weight, qdd)
        # improvement 1: q̈ follows the law no faster than the jerk limit, within the box. Near a
        # singular J, a = -J⁻¹J̇q̇ of eq. 17 grows faster than the scaling can follow (c scales b
        # only, and its own rate is limited) and leaves the box: on moves of 1 rad per joint q̈
        # changed by more than 0.1 rad/s² within 1 ms on 13 of 250 finished tasks, by up to 0.51
        # (examples/pajak_continuity.py, seeds 1-5)
        reach = p[Parameter.JERK_LIMIT] * max(t - d[Discrete.QDD_TIME], 0.0)
        limit_jerk(d[Discrete.QDD:Discrete.QDD + 6], reach, lower, upper, qdd)
        for k in range(6):
            if abs(qdd[k] - (a[k] + c * b[k])) > 1e-9 * qdd_max[k]:
                out[Evaluation.SATURATED] = 1.0  # the limits overrule the law

    return evaluate_kernel


evaluate_kernel = _evaluate_kernel(_DEPENDENCIES)
