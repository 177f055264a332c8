"""The task-space terms of the Pająk 2024 law, compiled: J⁻¹ (damped near a singular J) and
a, b of eq. 17, the rates of improvement 1's jerk budget, the approach damping of improvement 4
and the progress σ of eq. 19. Plain functions of floats and small arrays, called by
:mod:`.kernel`'s law and tested one by one; equation numbers are Pająk 2024's."""

import math

import numpy as np

from drake_traj.compiled import compiled

__all__ = ["ORIENTATION_LENGTH", "acceleration_terms", "approach_damping", "approach_rate", "blend_progress",
           "budgeted_rate", "damping_factor"]

ORIENTATION_LENGTH = 0.1  # [m/rad], weight of orientation in the progress measure and the approach rate


@compiled
def approach_rate(error, error_rate, delta: float) -> float:
    """r = -ė·e / (|e|² + δ²) [1/s]: the rate at which the TCP closes on p_w, from the error e to
    it and ė = J q̇ (6 each), orientation rows weighted by 0.1 m/rad (improvement 4). The distance
    decays as exp(-r t) while r holds; δ only keeps r finite at e = 0. One rate for the whole pose,
    not one per component: a component that passes 0 while the TCP sweeps by the goal would give
    a rate that spikes to ±∞ and back within milliseconds."""
    closing = 0.0
    size = delta * delta
    for k in range(6):
        weight = 1.0 if k < 3 else ORIENTATION_LENGTH * ORIENTATION_LENGTH
        closing += weight * error[k] * error_rate[k]
        size += weight * error[k] * error[k]
    return -closing / size


@compiled
def approach_damping(rate: float, stiffness: float, damping: float) -> float:
    """Damping D [1/s] that keeps the TCP from overshooting p_w when it closes at ``rate`` r
    against ``stiffness`` K, given the law's ``damping`` (improvement 4).

    For ë = -D ė - K e, r = -ė/e obeys dr/dt = r² - D r + K. With D = r + K/r it is constant:
    ė = -r e is invariant and e decays as exp(-r t) without crossing 0. Returned: the given
    ``damping`` for r <= sqrt(K) (the literal law), ramped (smoothstep in r) up to λ + K/λ at
    r = λ = 2 sqrt(K), and r + K/r above λ; never below ``damping``. Continuous in r.
    """
    root = math.sqrt(stiffness)
    held = max(rate, 2.0 * root)
    hold = held + stiffness / held
    x = min(max(rate / root - 1.0, 0.0), 1.0)
    return max(damping, damping + (hold - damping) * (x * x * (3.0 - 2.0 * x)))


@compiled
def damping_factor(measure: float, threshold: float, max_damping: float) -> float:
    """λ² of the damped least-squares inverse (improvement 3): 0 for measure >= threshold,
    rising to max_damping² at a singular J: λ² = λ_max² (1 - measure/threshold)², which starts
    with zero slope, so q̈ does not bend sharply where the damping sets in."""
    gap = max(1.0 - measure / threshold, 0.0)
    return max_damping * max_damping * gap * gap


@compiled
def _factor(jac, lam2, use_damped, matrix, pivots):
    """LU factors (partial pivoting) of J, or of JᵀJ + λ²I for the damped inverse, into
    ``matrix`` (6, 6) and ``pivots`` (6,)."""
    for i in range(6):
        for j in range(6):
            if use_damped:
                total = 0.0
                for k in range(6):
                    total += jac[k, i] * jac[k, j]
                matrix[i, j] = total + (lam2 if i == j else 0.0)
            else:
                matrix[i, j] = jac[i, j]
    for k in range(6):
        pivot = k
        for i in range(k + 1, 6):
            if abs(matrix[i, k]) > abs(matrix[pivot, k]):
                pivot = i
        pivots[k] = pivot
        if pivot != k:
            for j in range(6):
                matrix[k, j], matrix[pivot, j] = matrix[pivot, j], matrix[k, j]
        for i in range(k + 1, 6):
            factor = matrix[i, k] / matrix[k, k]
            matrix[i, k] = factor
            for j in range(k + 1, 6):
                matrix[i, j] -= factor * matrix[k, j]


@compiled
def _solve(jac, use_damped, matrix, pivots, rhs, out):
    """J⁻¹ rhs (eq. 13), or (JᵀJ + λ²I)⁻¹ Jᵀ rhs (damped least squares), into ``out`` (6,),
    from the factors of :func:`_factor`."""
    for i in range(6):
        if use_damped:
            total = 0.0
            for k in range(6):
                total += jac[k, i] * rhs[k]
            out[i] = total
        else:
            out[i] = rhs[i]
    for k in range(6):
        pivot = pivots[k]
        if pivot != k:
            out[k], out[pivot] = out[pivot], out[k]
    for i in range(6):
        for k in range(i):
            out[i] -= matrix[i, k] * out[k]
    for i in range(5, -1, -1):
        for k in range(i + 1, 6):
            out[i] -= matrix[i, k] * out[k]
        out[i] /= matrix[i, i]


@compiled
def acceleration_terms(jac, bias, error, error_rate, kp, damping, penalty, lam2, use_damped, a, b):
    """a and b of eq. 17 into ``a``, ``b`` (6,):

    a = -J⁻¹ J̇q̇, b = -J⁻¹ (D ė + Λ_P e) + Δq̈, with ė = J q̇ (``error_rate``), e of eq. 6 or
    eq. 19 and the damping D = Λ_V (eq. 13) or more (improvement 4). q̈ = a + c b is eq. 17;
    with c = 1 it is eq. 16 (eq. 13 without Δq̈). With ``use_damped`` J⁻¹ is the damped
    least-squares inverse with λ² = ``lam2`` (:func:`damping_factor`).
    """
    matrix = np.empty((6, 6))
    pivots = np.empty(6, dtype=np.int64)
    _factor(jac, lam2, use_damped, matrix, pivots)
    rhs = np.empty(6)
    _solve(jac, use_damped, matrix, pivots, bias, a)
    for i in range(6):
        a[i] = -a[i]
        rhs[i] = damping[i] * error_rate[i] + kp[i] * error[i]
    _solve(jac, use_damped, matrix, pivots, rhs, b)
    for i in range(6):
        b[i] = penalty[i] - b[i]


@compiled
def budgeted_rate(jac, lam2, use_damped, direction, scale: float, budget: float) -> float:
    """Largest rate [1/s] at which a quantity that moves q̈ = a + c b (eq. 17) by
    ∂q̈/∂x = -c J⁻¹ ``direction`` (``direction`` (6,) in task space, J⁻¹ damped as in
    :func:`acceleration_terms`) may change without changing any q̈_i faster than ``budget``
    [rad/s³] (improvement 1): budget / (c max |J⁻¹ direction|), with c = ``scale``, the largest
    c until the next update. Very large (not infinite) where x does not move q̈, so that the
    rate times 0 s is 0."""
    matrix = np.empty((6, 6))
    pivots = np.empty(6, dtype=np.int64)
    _factor(jac, lam2, use_damped, matrix, pivots)
    sensitivity = np.empty(6)
    _solve(jac, use_damped, matrix, pivots, direction, sensitivity)
    largest = 1e-300
    for k in range(6):
        largest = max(largest, scale * abs(sensitivity[k]))
    return budget / largest


@compiled
def blend_progress(position, reference, travel: float, length: float):
    """(σ of eq. 19 before the monotone max, step): σ = the TCP path length through the ball /
    ``length``, clipped to [0, 1].

    σ = (ℓ + |x - x_ref|) / length, where ℓ is the path length accumulated at the updates since
    the TCP entered the ball and x_ref the TCP position at the last update (step = |x - x_ref|).
    It is 0 on entry, continuous in x and grows whenever the TCP moves, so the target always
    leads (a projection on p_i -> p_{i+1} does not grow while the TCP is still heading for p_i,
    and 1 - δ/ϵ is not monotone: both stall, docs/papers.md). ``length`` = ``blend_length`` · ϵ.
    """
    step = math.sqrt((position[0] - reference[0]) ** 2 + (position[1] - reference[1]) ** 2
                     + (position[2] - reference[2]) ** 2)
    return min(max((travel + step) / length, 0.0), 1.0), step
