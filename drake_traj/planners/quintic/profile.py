"""The quintic time law of Benotsmane et al. and its closed-form timing (eq. 6-9): the
normalised profile r(s), each joint's minimum time (eq. 9, corrected in docs/papers.md), the
synchronised duration (second eq. 8) and the peaks (eq. 7, first eq. 8). Plain numpy functions of
displacements [rad], limits [rad/s, rad/s^2] and durations [s]."""

import numpy as np

from drake_traj.validation import real_array, require_finite, require_positive

__all__ = [
    "UNITS", "joint_minimum_times", "peak_acceleration", "peak_velocity", "quintic_profile", "quintic_third_derivative",
    "synchronized_duration",
]

UNITS = "rad, rad/s, rad/s^2 or s"  # the units the inputs' messages name

# Peak values of the normalised profile r(s) on s in [0, 1] (eq. 7 and the first eq. 8).
_PEAK_DR = 15.0 / 8.0  # max r'(s), at s = 1/2
_PEAK_DDR = 10.0 / np.sqrt(3.0)  # max |r''(s)|, at s = 1/2 -+ sqrt(3)/6


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


def quintic_third_derivative(s: np.ndarray) -> np.ndarray:
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
    d = real_array(displacement, "displacement", UNITS)
    kv = real_array(velocity_limit, "velocity_limit", UNITS)
    ka = real_array(acceleration_limit, "acceleration_limit", UNITS)
    for array, name in ((d, "displacement"), (kv, "velocity_limit"), (ka, "acceleration_limit")):
        require_finite(array, name)
    require_positive(kv, "velocity_limit")
    require_positive(ka, "acceleration_limit")
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
    d = real_array(displacement, "displacement", UNITS)
    t_f = real_array(duration, "duration", UNITS)
    require_finite(d, "displacement")
    require_finite(t_f, "duration")
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
