"""The bench's planners and its work unit: one (planner, task) run through the same PD-controlled
UR10e, with the UR joint-move limits (1.05 rad/s, 1.40 rad/s^2), gives one row of the table.

- ``pajak_blend`` / ``pajak_stop``: Pająk 2024's planner, passing or stopping at the waypoints;
- ``movej_blend``: UR-style joint moves with a 0.05 m blend radius, blends superposed at the limits
  as Pająk 2024 measured on the controller (``keep_limits=False``: they exceed the acceleration limit);
- ``quintic_stop``: synchronised quintic moves (Benotsmane et al.) through the IK of the waypoints;
- ``ruckig_stop``: Ruckig's jerk-limited moves through the same joint waypoints;
- ``smooth_waypoints``: the smooth path through the same joint waypoints, timed jerk-limited and
  near time-optimal without stopping (docs/smooth_timing.md);
- ``pajak_retimed``: the joint path of ``pajak_blend``'s preflight, timed the same way;
- ``toppra``: Drake's Toppra, time-optimal along the geometric path of ``pajak_blend``.

Columns: T; T over Toppra's time-optimal T on the planner's own path; max |qd| and |qdd| over
the limit; max jerk; whether qdd is continuous (no step between 1 ms samples larger than
``JUMP`` rad/s^2); PD tracking error (joint, TCP); peak torque over the effort limit; planning
compute time (median of ``repeats`` constructions; for the online Pająk planner, the wall time of
its law integrated alone); real-time factor of the closed loop; ``failure``, empty or why the run
failed; ``optimal_failure``, empty or why Toppra found no T_opt on the planner's path (Drake's own
log line is the reason; it is not printed). Only ``planning_s`` and ``real_time_factor`` are timings: every other column is the same
however the runs are spread over processes and machines.

The units, :func:`run_planner` for the planners a config describes and :func:`run_toppra` for
Toppra, are top-level functions of picklable arguments (a :class:`Task`, a planner name, a config
builder) returning a plain dict (the row and, for ``pajak_blend``, its planned joint path as an
array), so that Dask can ship them to any worker (:mod:`drake_traj.bench.engine`).
"""

import statistics
import time

import numpy as np

from drake_traj.bench.optimum import optimal_duration
from drake_traj.bench.task_sets import Task, default_cell_checker, joint_waypoints
from drake_traj.errors import reraise_interrupt
from drake_traj.station import simulate
from drake_traj.planners import (
    MovejConfig,
    PajakConfig,
    QuinticConfig,
    RetimedPajakConfig,
    RuckigConfig,
    SmoothWaypointsConfig,
    ToppraConfig,
    make_planner,
)
from drake_traj.robots import UR10E

__all__ = ["COLUMNS", "CONFIG_BUILDERS", "PLANNERS", "run_planner", "run_toppra"]

BLEND_RADIUS = 0.05  # [m], the paper's experiment 1
JUMP = 0.07  # [rad/s^2] between 1 ms samples: a jerk of 70 rad/s^3, above every continuous planner here
TOPPRA_GRID_POINTS = 2000
SETTLE_TIME, MAX_DURATION = 0.2, 30.0  # [s] of every run
REFERENCE = "pajak_blend"  # the planner whose path Toppra parameterises
COLUMNS = (
    "task", "planner", "succeeded", "T_s", "T_over_optimal", "max_qd_over_limit", "max_qdd_over_limit",
    "max_jerk", "qdd_continuous", "tracking_joint_rad", "tracking_tcp_m", "peak_torque_over_limit",
    "planning_s", "real_time_factor", "failure", "optimal_failure",
)
TIMING_COLUMNS = ("planning_s", "real_time_factor")


# Config builders: (task poses, joint waypoints) -> planner config, all with the UR10e's joint-move
# limits. Top-level functions, so that Dask can send them to its workers.
def pajak_blend_config(poses, joints):
    return PajakConfig(waypoints=poses, blend_waypoints=True)


def pajak_stop_config(poses, joints):
    return PajakConfig(waypoints=poses, blend_waypoints=False)


def movej_blend_config(poses, joints):
    return MovejConfig(goals=joints[1:].tolist(), blend_radius=BLEND_RADIUS, keep_limits=False)  # the paper's flaw


def quintic_stop_config(poses, joints):
    return QuinticConfig(goals=joints[1:].tolist())


def ruckig_stop_config(poses, joints):
    return RuckigConfig(goals=joints[1:].tolist())


def smooth_waypoints_config(poses, joints):
    return SmoothWaypointsConfig(goals=joints[1:].tolist())


def pajak_retimed_config(poses, joints):
    return RetimedPajakConfig(pajak=PajakConfig(waypoints=poses, blend_waypoints=True))


CONFIG_BUILDERS = {
    "pajak_blend": pajak_blend_config,
    "pajak_stop": pajak_stop_config,
    "movej_blend": movej_blend_config,
    "quintic_stop": quintic_stop_config,
    "ruckig_stop": ruckig_stop_config,
    "smooth_waypoints": smooth_waypoints_config,
    "pajak_retimed": pajak_retimed_config,
}
PLANNERS = (*CONFIG_BUILDERS, "toppra")


def run_planner(task: Task, name: str, build, keep_path: bool = False) -> dict:
    """The run of planner ``name`` (config from ``build(poses, joints)``) on ``task``.

    Returns ``{"row": row, "path": path}``: the row of :data:`COLUMNS`, and with ``keep_path``
    the planned joint path [rad] (the reference from t = 0 to the planner's finish, (N, 6)) when
    the run succeeded, else None. Whatever goes wrong gives a failed row with its reason.
    """
    try:
        config = build(task.poses, joint_waypoints(task.q0, task.poses))
    except Exception as error:  # a run's failure is a row, not a lost task
        reraise_interrupt(error)
        return {"row": failed_row(task.label, name, failure_reason(error)), "path": None}
    return _run(task.label, name, config, task.q0, task.repeats, keep_path)


def run_toppra(task: Task, reference: dict) -> dict:
    """Toppra's run on ``task``: time-optimal along the path of the reference run's output
    ``reference`` (:func:`run_planner` of ``pajak_blend`` with ``keep_path``)."""
    path = reference["path"]
    if path is None:
        reason = reference["row"]["failure"] or "no path"
        return {"row": failed_row(task.label, "toppra", f"no {REFERENCE} path to parameterise ({reason})"),
                "path": None}
    # A dense grid: Toppra keeps the limits at its grid points only (2.2 % over between them on
    # the paper task's path with the default grid, 0.08 % with 2000 points).
    config = ToppraConfig(path=path[1:].tolist(), grid_points=TOPPRA_GRID_POINTS)
    return _run(task.label, "toppra", config, path[0], task.repeats, keep_path=False)


def _run(label, name, config, q0, repeats, keep_path) -> dict:
    try:
        planning = _planning_time(config, q0, repeats)
        # _planning_time has run the preflight already (a task it refuses is this row's failure);
        # a plan that leaves the cell (the default table) or hits the arm itself is refused too
        planner = make_planner(config, UR10E, q0)
        default_cell_checker().check_planner(planner)
        result = simulate(planner, name=name, settle_time=SETTLE_TIME, max_duration=MAX_DURATION, preflight=False)
        row = _row(label, name, result, planning, _optimal_duration(result))
    except Exception as error:  # a run's failure is a row, not a lost task
        reraise_interrupt(error)
        return {"row": failed_row(label, name, failure_reason(error)), "path": None}
    path = result.q_ref[: np.searchsorted(result.t, result.duration) + 1] if keep_path and result.succeeded else None
    return {"row": row, "path": path}


def _planning_time(config, q0, repeats):
    """Median wall time [s] of making the planner and its preflight (for the online Pająk
    planner, the law integrated alone over the whole task)."""
    def once():
        start = time.perf_counter()
        make_planner(config, UR10E, q0).preflight()
        return time.perf_counter() - start
    return statistics.median(once() for _ in range(repeats))


def _optimal_duration(result) -> tuple[float, str]:
    """:func:`optimal_duration` on the result's reference up to its end, with the bench's limits."""
    end = np.searchsorted(result.t, result.duration) + 1 if np.isfinite(result.duration) else len(result.t)
    return optimal_duration(result.q_ref[:end], result.qd_ref[:end])


def _row(task, name, result, planning, optimal) -> dict:
    optimal, no_optimum = optimal
    metrics = result.metrics()
    steps = np.abs(np.diff(result.qdd_ref[1:], axis=0))  # after t = 0 (Pająk sims start with a step)
    return {
        "task": task, "planner": name, "succeeded": result.succeeded, "T_s": result.duration,
        "T_over_optimal": result.duration / optimal if optimal > 0 else float("nan"),
        "max_qd_over_limit": metrics.peak_velocity_fraction,
        "max_qdd_over_limit": metrics.peak_acceleration_fraction, "max_jerk": metrics.max_jerk,
        "qdd_continuous": bool(steps.max() <= JUMP) if steps.size else float("nan"),
        "tracking_joint_rad": metrics.tracking_error_joint_max_rad,
        "tracking_tcp_m": metrics.tracking_error_tcp_max_m,
        "peak_torque_over_limit": max(metrics.peak_torque_fraction), "planning_s": planning,
        "real_time_factor": metrics.real_time_factor, "failure": metrics.failure or "", "optimal_failure": no_optimum,
    }


def failed_row(task: str, planner: str, reason: str) -> dict:
    """The row of a run that produced no log: NaN metrics and the reason."""
    return {column: float("nan") for column in COLUMNS} | {
        "task": task, "planner": planner, "succeeded": False, "failure": reason, "optimal_failure": ""}


def failure_reason(error: BaseException) -> str:
    """``error`` as one line, its type first: the ``failure`` of a run that raised it."""
    return " ".join(f"{type(error).__name__}: {error}".split())
