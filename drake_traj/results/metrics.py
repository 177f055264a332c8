"""A run's figures of merit: the :class:`Metrics` record (the content of ``metrics.json``) and how
:func:`metrics_of` computes it from a :class:`~drake_traj.results.result.SimulationResult`'s log."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from drake_traj.robots.task_space import pose_error

__all__ = ["Metrics", "json_ready", "metrics_of"]


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
    m/s^2 for prismatic joints); ``*_over_limit`` are ratios to the planner's promised limits (the
    effort limit for torques); ``failure`` is the failure's message and ``failure_cause`` its
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
    max_velocity_over_limit: float
    max_acceleration_over_limit: float
    max_jerk: float
    tracking_error_joint_max_rad: float
    tracking_error_tcp_max_m: float
    final_position_error_m: float
    final_orientation_error_rad: float
    peak_torque_nm: list[float]
    peak_torque_over_limit: list[float]
    time_at_effort_limit_s: list[float]
    simulated_time_s: float
    wall_time_s: float
    real_time_factor: float | None
    planning_time_s: float | None  # [s] the planner's planning before the run (free motion: find + shorten + time + check)
    unchecked_links: list[str]  # links without collision shapes: the self and cell checks were off for them

    def to_dict(self) -> dict:
        """Strict-JSON-ready dict with the field names as keys (None where a value is not finite)."""
        return json_ready(asdict(self))


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
        max_velocity_over_limit=float(np.max(_over_samples(np.max, np.abs(result.qd_ref) / result.velocity_limit))),
        max_acceleration_over_limit=float(np.max(_over_samples(np.max, np.abs(result.qdd_ref) / result.acceleration_limit))),
        max_jerk=float(np.abs(jerk).max()) if len(jerk) else 0.0,
        tracking_error_joint_max_rad=float(np.max(_over_samples(np.max, np.abs(result.q_ref - result.q_meas)))),
        tracking_error_tcp_max_m=float(_over_samples(np.max, tcp_error)),
        final_position_error_m=final_position,
        final_orientation_error_rad=final_orientation,
        peak_torque_nm=peak_torque.tolist(),
        peak_torque_over_limit=(peak_torque / result.effort_limit).tolist(),
        time_at_effort_limit_s=(result.saturated().sum(axis=0) * result.log_period).tolist(),
        simulated_time_s=simulated,
        wall_time_s=result.wall_time,
        real_time_factor=simulated / result.wall_time if result.wall_time > 0 else None,
        planning_time_s=result.planning_time if np.isfinite(result.planning_time) else None,
        unchecked_links=list(result.unchecked_links),
    )
