"""``drake-traj bench --suite soak``: seeded random tasks (:mod:`.soak_tasks`) for every planner and
baseline on every shipped arm, each planned as ``drake-traj run`` plans it (the scenario's
preflight: the planner's own check, then the cell check) and the plan checked by the soak's own
checks (:mod:`.soak_checks`); on Dask like the bench.

One unit is one task (:func:`run_soak_task`). A plan the preflight accepts is **silent wrong**
when one of these fails (each row says which):

- a velocity, acceleration or (where the planner promises one) jerk peak above its limit by more
  than :data:`~drake_traj.bench.soak_checks.LIMIT_TOLERANCE` (relative), at any 0.1 ms sample or
  at any piece's exact peak; a NaN anywhere in the plan;
- Li et al. 2019's tool speed or acceleration above its limit (same tolerance) at any 1 ms sample;
- a joint past its range at any 0.1 ms sample;
- the goal missed: the last joint goal by more than :data:`JOINT_GOAL_TOLERANCE` or not at rest
  there; the last pose (Drake's forward kinematics) by more than the planner's accuracy (Pająk's
  ``accuracy`` and ``orientation_accuracy``) or :data:`POSE_GOAL_TOLERANCE` (the IK-traced plans);
- two bodies closer than the cell check promises between its samples (the clearance less its
  spacing, half the clearance) by SceneGraph, anywhere along the motion;
- in one task in :data:`CLOSED_LOOP_EVERY` (seeds divisible by it), the closed loop's run failing.

A refusal is a DrakeTrajError (any ValueError passes as a refusal); its cause, field and the
independent diagnosis are in the row. A refusal the diagnosis contradicts, and any other exception,
count as **wrong** too. Rows carry the seed and the drawn parameters, and the command that reruns
the task alone.
"""

import json
import time
import traceback

import numpy as np

from drake_traj.bench.soak_checks import (DENSE_PERIOD, LIMIT_TOLERANCE, ClearanceCheck, dense_rates, diagnose,
                                          piece_coefficients, pose_error, rate_peaks, tool_rates)
from drake_traj.bench.soak_tasks import draw_task
from drake_traj.bench.units import failure_reason
from drake_traj.errors import DrakeTrajError, field_text, reraise_interrupt
from drake_traj.planners import release_system
from drake_traj.scenario import check_planned_duration, make_planner, preflight
from drake_traj.station import simulate

__all__ = ["SOAK_COLUMNS", "rerun_command", "run_soak_task", "soak_row"]

JOINT_GOAL_TOLERANCE = 1e-6  # [rad] the last joint goal, and [rad/s] at rest there
POSE_GOAL_TOLERANCE = 1e-6  # [m, rad] the last pose of a plan traced by inverse kinematics (Boryga, Li, free motion)
CLOSED_LOOP_EVERY = 50
SOAK_COLUMNS = (
    "arm", "planner", "seed", "outcome", "silent_wrong", "wrong", "cause", "field", "diagnosis", "T_s",
    "velocity_fraction", "acceleration_fraction", "jerk_fraction", "tool_speed_fraction", "tool_acceleration_fraction",
    "range_excess_rad", "goal_error", "goal_tolerance", "least_distance_m", "clearance_m", "uncertified_intervals",
    "closed_loop", "planning_s", "check_s", "message", "params", "rerun",
)


def rerun_command(arm: str, planner: str, seed: int) -> str:
    """The command that runs task ``seed`` of ``planner`` on ``arm`` alone."""
    return (f"drake-traj bench --suite soak --arms {arm} --planners {planner} --seed {seed} --count 1 --workers 1 "
            f"--out out/soak_{arm}_{planner}_{seed} --overwrite")


def soak_row(key, **values) -> dict:
    """A row of :data:`SOAK_COLUMNS` of the task ``key`` (arm, planner, seed): ``values``, the rest empty."""
    arm, planner, seed = key
    row = {column: "" for column in SOAK_COLUMNS} | {"arm": arm, "planner": planner, "seed": seed,
                                                     "silent_wrong": False, "wrong": False}
    return row | values | {"rerun": rerun_command(arm, planner, seed)}


def run_soak_task(arm: str, planner: str, seed: int) -> dict:
    """The row of :data:`SOAK_COLUMNS` of one task (module docstring); never raises."""
    key = (arm, planner, seed)
    try:
        task = draw_task(arm, planner, seed)
    except Exception as error:  # the draw itself failed: a bug of the soak, a wrong row
        reraise_interrupt(error)
        return soak_row(key, outcome="error", wrong=True, message=f"drawing the task: {failure_reason(error)}")
    began = time.perf_counter()
    try:
        return _planned(task, began)
    except Exception as error:  # anything the checks did not expect
        reraise_interrupt(error)
        return soak_row(key, outcome="error", wrong=True, params=json.dumps(task.params),
                    message=f"{failure_reason(error)} | {traceback.format_exc(limit=-3)!r:.400}")


def _planned(task, began) -> dict:
    """Plan ``task`` as ``drake-traj run`` does (the scenario checked, its planner made, the
    preflight, the planned duration against ``max_duration``), then check the plan or the refusal.
    The planner is emptied afterwards (:func:`~drake_traj.planners.release_system`)."""
    key = (task.arm, task.planner, task.seed)
    scenario = task.scenario
    planner = None
    try:
        scenario.validate()
        planner = make_planner(scenario)
        preflight(scenario, planner)
        check_planned_duration(scenario, planner)
    except ValueError as error:
        release_system(planner)
        return _refused(task, key, error, began)
    planning = time.perf_counter() - began
    checked = time.perf_counter()
    values, wrongs = _check_plan(task, planner)
    release_system(planner)
    if task.seed % CLOSED_LOOP_EVERY == 0:
        values["closed_loop"] = _closed_loop(scenario)
        if values["closed_loop"] != "succeeded":
            wrongs.append(f"closed loop: {values['closed_loop']}")
    return soak_row(key, outcome="planned", silent_wrong=bool(wrongs), wrong=bool(wrongs), message="; ".join(wrongs),
                    planning_s=planning, check_s=time.perf_counter() - checked, params=json.dumps(task.params),
                    **values)


def _refused(task, key, error, began) -> dict:
    """The row of a refused task: its cause, field and the independent diagnosis."""
    cause = str(getattr(error, "cause", "")) if isinstance(error, DrakeTrajError) else "value error"
    field = field_text(error.field) if isinstance(error, DrakeTrajError) and error.field else ""
    robot = task.scenario.robot_with_tool()
    diagnosis = "not diagnosed"
    if cause in ("collision", "joint range", "unreachable"):
        diagnosis = diagnose(error, robot, ClearanceCheck(robot, task.scenario.cell), task.scenario.cell.clearance)
    return soak_row(key, outcome="refused", cause=cause, field=field, diagnosis=diagnosis,
                    wrong=diagnosis.startswith("contradicted"), planning_s=time.perf_counter() - began,
                    message=" ".join(str(error).split())[:400], params=json.dumps(task.params),
                    clearance_m=task.scenario.cell.clearance)


JERK_LIMITED = ("smooth_waypoints", "pajak_retimed", "free_motion", "ruckig")  # the planners that take a jerk limit


def promised_limits(name: str, planner) -> dict:
    """{order: limit (n,)} soak planner ``name``'s ``planner`` promises: velocity (1) and
    acceleration (2) always, jerk (3) for :data:`JERK_LIMITED` (the smooth and free-motion
    planners' ``jerk_limit`` or ``jerk``, Ruckig's law's ``jerk_limit``)."""
    limits = {1: np.asarray(planner.velocity_limit, dtype=float), 2: np.asarray(planner.acceleration_limit, dtype=float)}
    if name in JERK_LIMITED:
        holder = planner.law if name == "ruckig" else planner
        limits[3] = np.asarray(getattr(holder, "jerk_limit", None) if hasattr(holder, "jerk_limit") else holder.jerk,
                               dtype=float)
    return limits


def _check_plan(task, planner) -> tuple[dict, list[str]]:
    """The values of a plan's checks and what it got wrong."""
    scenario, robot = task.scenario, task.scenario.robot_with_tool()
    plan = planner.plan()
    breaks, coefficients = piece_coefficients(plan)
    times, rates = dense_rates(plan, pieces=(breaks, coefficients))
    wrongs = []
    if not all(np.all(np.isfinite(values)) for values in rates) or not np.all(np.isfinite(coefficients)):
        return {"T_s": plan.end_time()}, ["the plan has NaN or infinite values"]
    values = {"T_s": plan.end_time()}
    for order, limit in promised_limits(task.planner, planner).items():
        name = ("velocity", "acceleration", "jerk")[order - 1]
        sampled = np.max(np.abs(rates[order]) / limit)
        exact = np.max(rate_peaks(breaks, coefficients, order) / limit)
        values[f"{name}_fraction"] = float(max(sampled, exact))
        if values[f"{name}_fraction"] > 1 + LIMIT_TOLERANCE:
            wrongs.append(f"{name} {values[f'{name}_fraction']:.9f} of its limit")
    clearance = ClearanceCheck(robot, scenario.cell)
    if task.planner == "li":
        wrongs += _tool_limits(scenario, robot, clearance, rates, values)
    q = rates[0]
    excess = max(float(np.max(robot.lower_limits - q)), float(np.max(q - robot.upper_limits)), 0.0)
    values["range_excess_rad"] = excess
    if excess > 0:
        wrongs.append(f"a joint {excess:.3g} rad past its range")
    wrongs += _goal(task, q[-1], rates[1][-1], clearance, values)
    bound = scenario.cell.clearance / 2
    along = clearance.along(times, q, bound)
    values |= {"least_distance_m": along["least"], "clearance_m": scenario.cell.clearance,
               "uncertified_intervals": along["uncertified"]}
    if along["below"]:
        wrongs.append(f"{along['least'] * 1e3:.3f} mm between two bodies at t = {along['least_time']:.4f} s, under half "
                      f"the clearance ({bound * 1e3:.3f} mm)")
    return values, wrongs


def _tool_limits(scenario, robot, clearance, rates, values) -> list[str]:
    """Li et al. 2019's tool limits at every millisecond of the plan (:func:`tool_rates`): the peak
    fractions in ``values``; what is wrong."""
    stride = int(round(1e-3 / DENSE_PERIOD))
    speed, acceleration = tool_rates(clearance.probe.checker, robot, *(rate[::stride] for rate in rates[:3]))
    config, wrongs = scenario.planner, []
    for name, peak, limit in (("tool_speed", speed.max(), config.tool_velocity_limit),
                              ("tool_acceleration", acceleration.max(), config.tool_acceleration_limit)):
        values[f"{name}_fraction"] = float(peak / limit)
        if peak > limit * (1 + LIMIT_TOLERANCE):
            wrongs.append(f"{name.replace('_', ' ')} {peak / limit:.9f} of its limit")
    return wrongs


def _goal(task, q_end, qd_end, clearance, values) -> list[str]:
    """The goal's check: the error and its tolerance in ``values``; what is wrong."""
    config = task.scenario.planner
    if task.planner in ("pajak", "pajak_retimed"):
        pajak = config.pajak if task.planner == "pajak_retimed" else config
        goal, tolerance = pajak.waypoints[-1], (pajak.accuracy, pajak.orientation_accuracy)
    elif task.planner == "boryga":
        goal, tolerance = list(config.E) + [np.nan] * 3, (POSE_GOAL_TOLERANCE, np.inf)
    elif task.planner == "li":
        goal, tolerance = list(config.points[-1]) + [np.nan] * 3, (POSE_GOAL_TOLERANCE, np.inf)
    elif task.planner == "free_motion" and config.poses:
        goal, tolerance = config.poses[-1], (POSE_GOAL_TOLERANCE, POSE_GOAL_TOLERANCE)
    else:
        goals = config.path if task.planner == "toppra" else config.goals
        error = float(np.max(np.abs(q_end - np.asarray(goals[-1]))))
        speed = float(np.max(np.abs(qd_end)))
        values |= {"goal_error": max(error, speed), "goal_tolerance": JOINT_GOAL_TOLERANCE}
        return [f"ends {error:.3g} rad from its last goal at {speed:.3g} rad/s"] if max(error, speed) > JOINT_GOAL_TOLERANCE else []
    position, orientation = pose_error(clearance.probe.checker, task.scenario.robot_with_tool(), q_end,
                                       np.nan_to_num(np.asarray(goal, dtype=float)))
    if not np.isfinite(tolerance[1]):
        orientation = 0.0
    values |= {"goal_error": max(position / tolerance[0], orientation / tolerance[1]), "goal_tolerance": 1.0}
    if position > tolerance[0] or orientation > tolerance[1]:
        return [f"ends {position * 1e3:.4f} mm and {orientation:.3g} rad from its last pose"]
    return []


def _closed_loop(scenario) -> str:
    """"succeeded", or why the closed loop's run failed or broke a promised limit at a logged
    sample of its reference (peak |q̇| or |q̈| over the planner's limit by more than
    :data:`~drake_traj.bench.soak_checks.LIMIT_TOLERANCE`)."""
    result = simulate(scenario)
    if not result.succeeded:
        return f"{result.failure.cause}: {result.failure.message}"[:300]
    metrics = result.metrics()
    for name, fraction in (("velocity", metrics.peak_velocity_fraction),
                           ("acceleration", metrics.peak_acceleration_fraction)):
        if fraction > 1 + LIMIT_TOLERANCE:
            return f"the logged reference's peak {name} is {fraction:.9f} of its limit"
    return "succeeded"
