"""A run's figures of merit: the :class:`Metrics` record (the content of ``metrics.json``) and how
:func:`metrics_of` computes it from a :class:`~drake_traj.results.result.SimulationResult`'s log."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from drake_traj.robots.task_space import pose_error

__all__ = ["RENAMED_METRICS", "ROUNDING", "Metrics", "json_ready", "metrics_of", "round_angle", "round_fraction", "round_length",
           "round_mass", "round_time", "round_torque"]

# Keys of metrics.json renamed, {old: new}: the old key is written too, with the same value, until the
# next release (docs/results.md, "Renamed metrics").
RENAMED_METRICS = {"max_velocity_over_limit": "peak_velocity_fraction",
                   "max_acceleration_over_limit": "peak_acceleration_fraction",
                   "peak_torque_over_limit": "peak_torque_fraction"}


def _rounded(value, decimals: int):
    """``value`` (a float, or a list or dict of them) rounded to ``decimals`` decimals; None, NaN,
    inf and non-floats as they are."""
    if isinstance(value, list):
        return [_rounded(item, decimals) for item in value]
    if isinstance(value, dict):
        return {key: _rounded(item, decimals) for key, item in value.items()}
    if isinstance(value, float) and np.isfinite(value):
        return round(value, decimals) + 0.0  # + 0.0: no -0.0
    return value


def round_time(seconds):
    """A time [s] to 1e-6 s (1 µs)."""
    return _rounded(seconds, 6)


def round_length(metres):
    """A length [m] to 1e-6 m (1e-3 mm)."""
    return _rounded(metres, 6)


def round_angle(radians):
    """An angle [rad] to 1e-6 rad; also a joint's position and its rates (rad/s, rad/s², rad/s³, or m,
    m/s, m/s², m/s³ for a prismatic joint) to 1e-6 of their unit."""
    return _rounded(radians, 6)


def round_fraction(ratio):
    """A ratio or fraction (of a limit, the real-time factor) to 4 decimals."""
    return _rounded(ratio, 4)


def round_torque(newton_metres):
    """A joint torque [N m] (or force [N] for a prismatic joint) to 1e-4 N m."""
    return _rounded(newton_metres, 4)


def round_mass(kilograms):
    """A mass [kg] or density [kg/m³] to 1e-6 of its unit."""
    return _rounded(kilograms, 6)


def json_ready(value):
    """``value`` with every non-finite float replaced by None (strict JSON has no NaN)."""
    if isinstance(value, float):
        return value if np.isfinite(value) else None
    if isinstance(value, (list, tuple)):
        return [json_ready(item) for item in value]
    if isinstance(value, dict):
        return {key: json_ready(item) for key, item in value.items()}
    return value


def _over_samples(reduce, array: np.ndarray) -> np.ndarray:
    """``reduce`` (np.min, np.max) of ``array`` over its samples (axis 0); NaN where it holds none
    (a station that has not run)."""
    return reduce(array, axis=0) if len(array) else np.full(array.shape[1:], np.nan)


@dataclass(frozen=True)
class Metrics:
    """Figures of merit of a run (:meth:`SimulationResult.metrics`); :meth:`to_dict` is the
    content of ``metrics.json``. Joint quantities are per joint, in rad, rad/s, rad/s^2 (m, m/s,
    m/s^2 for prismatic joints); ``peak_*_fraction`` are the peaks of |q̇|, |q̈| of the reference
    (over all joints) and of |τ| (per joint) as fractions of the planner's promised limits (the
    effort limit for torques; 1: at the limit); ``max_jerk`` is the peak |jerk| of the reference
    [rad/s^3]; ``failure`` is the failure's message and ``failure_cause`` its
    :class:`~drake_traj.errors.Cause` value ("stall", "timeout", ...; both None on success); the final
    errors are those of the measured tool pose at the end of the log against the task's goal (the
    reference's last pose where the task is given in joint space), the orientation error the angle
    of R_goalᵀ R."""

    name: str
    succeeded: bool
    failure: str | None
    failure_cause: str | None
    duration_s: float
    samples: int
    log_period_s: float | None
    qd_min: list[float]
    qd_max: list[float]
    qdd_min: list[float]
    qdd_max: list[float]
    peak_velocity_fraction: float
    peak_acceleration_fraction: float
    max_jerk: float
    tracking_error_joint_max_rad: float
    tracking_error_tcp_max_m: float
    final_position_error_m: float
    final_orientation_error_rad: float
    peak_torque_nm: list[float]
    peak_torque_fraction: list[float]
    time_at_effort_limit_s: list[float]
    simulated_time_s: float
    wall_time_s: float
    real_time_factor: float | None
    planning_time_s: float | None  # [s] the planner's planning before the run (free motion: find + shorten + time + check)
    unchecked_links: list[str]  # links without collision shapes: the self and cell checks were off for them
    unchecked_collision_pairs: list[list[str]]  # [link, link, reason]: pairs of links the checks left out
    estimated_inertia_links: dict[str, float]  # {link: mass [kg]} estimated from its shapes: the torques rest on them
    estimated_inertia_density: float | None  # [kg/m³] of those estimates; None: none estimated
    locked_joints: dict[str, float]  # {joint: position [rad or m]} held where the arm does not drive it

    def __getattr__(self, name: str):
        """An old name of :data:`RENAMED_METRICS` (kept until the next release) reads its new name."""
        if name in RENAMED_METRICS:
            return getattr(self, RENAMED_METRICS[name])
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def to_dict(self) -> dict:
        """Strict-JSON-ready dict with the field names as keys (None where a value is not finite),
        each float rounded to its kind (:data:`ROUNDING`), then the old names of
        :data:`RENAMED_METRICS` with their new names' values."""
        rounded = {key: ROUNDING.get(key, _as_is)(value) for key, value in asdict(self).items()}
        return json_ready(rounded | {old: rounded[new] for old, new in RENAMED_METRICS.items()})


def _as_is(value):
    return value


# How each float field of Metrics is rounded in metrics.json and in printouts.
ROUNDING = {
    "duration_s": round_time, "log_period_s": round_time, "simulated_time_s": round_time, "wall_time_s": round_time,
    "planning_time_s": round_time, "time_at_effort_limit_s": round_time,
    "qd_min": round_angle, "qd_max": round_angle, "qdd_min": round_angle, "qdd_max": round_angle,
    "max_jerk": round_angle, "tracking_error_joint_max_rad": round_angle, "final_orientation_error_rad": round_angle,
    "locked_joints": round_angle,
    "tracking_error_tcp_max_m": round_length, "final_position_error_m": round_length,
    "peak_velocity_fraction": round_fraction, "peak_acceleration_fraction": round_fraction,
    "peak_torque_fraction": round_fraction, "real_time_factor": round_fraction,
    "peak_torque_nm": round_torque,
    "estimated_inertia_links": round_mass, "estimated_inertia_density": round_mass,
}


def metrics_of(result) -> Metrics:
    """Scalar and per-joint figures of merit of ``result`` (a
    :class:`~drake_traj.results.result.SimulationResult`; NaN where the log holds NaN: a NaN is
    never skipped; such a run has not succeeded)."""
    failure = result.failure or result.non_finite_failure()
    tcp_error = result.tcp_position_error()
    simulated = float(result.t[-1]) if len(result.t) else 0.0
    jerk = result.jerk()
    peak_torque = _over_samples(np.max, np.abs(result.tau))
    final_position = final_orientation = float("nan")
    if len(result.t):
        goal = result.goal if np.all(np.isfinite(result.goal)) else result.tcp_ref[-1]
        final_position, final_orientation = pose_error(result.tcp[-1], goal)
    return Metrics(
        name=result.name,
        succeeded=failure is None,
        failure=None if failure is None else failure.message,
        failure_cause=None if failure is None else failure.cause.value,
        duration_s=result.duration,
        samples=int(len(result.t)),
        log_period_s=result.log_period or None,
        qd_min=_over_samples(np.min, result.qd_ref).tolist(),
        qd_max=_over_samples(np.max, result.qd_ref).tolist(),
        qdd_min=_over_samples(np.min, result.qdd_ref).tolist(),
        qdd_max=_over_samples(np.max, result.qdd_ref).tolist(),
        peak_velocity_fraction=float(np.max(_over_samples(np.max, np.abs(result.qd_ref) / result.velocity_limit))),
        peak_acceleration_fraction=float(np.max(_over_samples(np.max, np.abs(result.qdd_ref) / result.acceleration_limit))),
        max_jerk=float(np.abs(jerk).max()) if len(jerk) else 0.0,
        tracking_error_joint_max_rad=float(np.max(_over_samples(np.max, np.abs(result.q_ref - result.q_meas)))),
        tracking_error_tcp_max_m=float(_over_samples(np.max, tcp_error)),
        final_position_error_m=final_position,
        final_orientation_error_rad=final_orientation,
        peak_torque_nm=peak_torque.tolist(),
        peak_torque_fraction=(peak_torque / result.effort_limit).tolist(),
        time_at_effort_limit_s=(result.saturated().sum(axis=0) * result.log_period).tolist(),
        simulated_time_s=simulated,
        wall_time_s=result.wall_time,
        real_time_factor=simulated / result.wall_time if result.wall_time > 0 else None,
        planning_time_s=result.planning_time if np.isfinite(result.planning_time) else None,
        unchecked_links=list(result.unchecked_links),
        unchecked_collision_pairs=[list(pair) for pair in result.unchecked_collision_pairs],
        estimated_inertia_links=dict(result.estimated_inertia),
        estimated_inertia_density=result.inertia_density if np.isfinite(result.inertia_density) else None,
        locked_joints=dict(result.locked_joints),
    )
