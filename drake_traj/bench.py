"""``drake-traj bench``: every planner and baseline on the same UR10e waypoint tasks, one table.

Tasks: Pająk 2024's task (q(0), p1..pf) and ``count`` seeded random reachable tasks (three
waypoints, each the flange pose of a random configuration near the previous one). Each task runs,
through the same PD-controlled UR10e, with the UR joint-move limits (1.05 rad/s, 1.40 rad/s^2):

- ``pajak_blend`` / ``pajak_stop``: Pająk 2024's planner, passing or stopping at the waypoints;
- ``movej_blend``: UR-style joint moves with a 0.05 m blend radius;
- ``quintic_stop``: synchronised quintic moves (Benotsmane et al.) through the IK of the waypoints;
- ``ruckig_stop``: Ruckig's jerk-limited moves through the same joint waypoints;
- ``toppra``: Drake's Toppra, time-optimal along the geometric path of ``pajak_blend``.

Columns: T; T over Toppra's time-optimal T on the planner's own path; max |qd| and |qdd| over
the limit; max jerk; whether qdd is continuous (no step between 1 ms samples larger than
``JUMP`` rad/s^2); PD tracking error (joint, TCP); peak torque over the effort limit; planning
compute time (median of ``repeats`` constructions; for the online Pająk planner, the wall time of
its law integrated alone); real-time factor of the closed loop.
"""

import csv
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from drake_traj.diagram import simulate
from drake_traj.planners import (
    MovejConfig,
    PajakConfig,
    QuinticConfig,
    RuckigConfig,
    ToppraConfig,
    make_planner,
)
from drake_traj.planners import pajak
from drake_traj.planners.baselines.toppra import geometric_path_from_samples, time_optimal_along_path
from drake_traj.robots import UR10E
from drake_traj.robots import ur10e as robot

VELOCITY, ACCELERATION = robot.DEFAULT_JOINT_MOVE_VELOCITY, robot.DEFAULT_JOINT_MOVE_ACCELERATION
BLEND_RADIUS = 0.05  # [m], the paper's experiment 1
JUMP = 0.07  # [rad/s^2] between 1 ms samples: a jerk of 70 rad/s^3, above every continuous planner here
TOPPRA_GRID_POINTS = 2000
PLANNERS = ("pajak_blend", "pajak_stop", "movej_blend", "quintic_stop", "ruckig_stop", "toppra")
COLUMNS = (
    "task", "planner", "succeeded", "T_s", "T_over_optimal", "max_qd_over_limit", "max_qdd_over_limit",
    "max_jerk", "qdd_continuous", "tracking_joint_rad", "tracking_tcp_m", "peak_torque_over_limit",
    "planning_s", "real_time_factor",
)


def paper_task():
    """(q0, task poses (4, 6)) of Pająk 2024."""
    return pajak.paper_initial_configuration(), pajak.paper_parameters(3).waypoints


def random_tasks(count: int, seed: int = 0):
    """``count`` reachable tasks: three waypoints, each the flange pose of a configuration at most
    0.6 rad per joint from the previous one, at least 0.15 m apart, away from singularities."""
    rng = np.random.default_rng(seed)
    q0 = pajak.paper_initial_configuration()
    tasks = []
    while len(tasks) < count:
        configurations = [q0]
        for _ in range(3):
            configurations.append(configurations[-1] + rng.uniform(-0.6, 0.6, 6))
        poses = np.array([robot.task_pose(q) for q in configurations])
        far_enough = np.all(np.linalg.norm(np.diff(poses[:, :3], axis=0), axis=1) > 0.15)
        regular = all(robot.singularity_measure(q) > 0.15 and abs(np.cos(p[4])) > 0.3
                      for q, p in zip(configurations, poses))
        if far_enough and regular:
            tasks.append((q0, poses[1:]))
    return tasks


def joint_waypoints(q0, poses) -> np.ndarray:
    """q0 and the IK of each pose, each nearest the previous configuration, shape (m + 1, 6)."""
    return np.vstack([q0, robot.inverse_kinematics_path(poses, q0, max_step=np.inf)])


def _configs(poses, joints) -> dict:
    """Planner configs by name, all with the UR10e's joint-move limits (Toppra needs
    pajak_blend's path, built later)."""
    goals = joints[1:].tolist()
    return {
        "pajak_blend": PajakConfig(waypoints=poses, blend_waypoints=True),
        "pajak_stop": PajakConfig(waypoints=poses, blend_waypoints=False),
        "movej_blend": MovejConfig(goals=goals, blend_radius=BLEND_RADIUS),
        "quintic_stop": QuinticConfig(goals=goals),
        "ruckig_stop": RuckigConfig(goals=goals),
    }


def _planning_time(config, q0, repeats):
    """Median wall time [s] of making the planner and its preflight (for the online Pająk
    planner, the law integrated alone over the whole task)."""
    def once():
        start = time.perf_counter()
        make_planner(config, UR10E, q0).preflight()
        return time.perf_counter() - start
    return statistics.median(once() for _ in range(repeats))


def _optimal_duration(result) -> float:
    """Toppra's time-optimal duration on the result's geometric path (reference up to its end).

    A planner that stops at waypoints leaves a path with corners there, which no timing can pass
    without stopping: the path is split at every stop and the pieces' optimal times are added.
    NaN where Toppra finds no parameterisation (a near-corner left where a planner slowed almost
    to rest without stopping).
    """
    end = np.searchsorted(result.t, result.duration) + 1 if np.isfinite(result.duration) else len(result.t)
    q, qd = result.q_ref[:end], result.qd_ref[:end]
    moving = np.linalg.norm(qd, axis=1) > 1e-6
    moving[0] = moving[-1] = False  # the motion starts and (within the stop threshold) ends at rest
    starts = np.flatnonzero(moving[1:] & ~moving[:-1])  # last rest sample before each move
    stops = np.flatnonzero(~moving[1:] & moving[:-1]) + 1  # first rest sample after each move
    total = 0.0
    for start, stop in zip(starts, stops):
        piece = q[start : stop + 1]
        if np.ptp(piece, axis=0).max() > 1e-6:
            try:
                total += time_optimal_along_path(geometric_path_from_samples(piece), VELOCITY, ACCELERATION)[0]
            except ValueError:
                return float("nan")
    return total


def _row(task, name, result, planning, optimal) -> dict:
    metrics = result.metrics()
    steps = np.abs(np.diff(result.qdd_ref[1:], axis=0))  # after t = 0 (Pająk sims start with a step)
    return {
        "task": task, "planner": name, "succeeded": result.succeeded, "T_s": result.duration,
        "T_over_optimal": result.duration / optimal, "max_qd_over_limit": metrics.max_velocity_over_limit,
        "max_qdd_over_limit": metrics.max_acceleration_over_limit, "max_jerk": metrics.max_jerk,
        "qdd_continuous": bool(steps.max() <= JUMP), "tracking_joint_rad": metrics.tracking_error_joint_max_rad,
        "tracking_tcp_m": metrics.tracking_error_tcp_max_m,
        "peak_torque_over_limit": max(metrics.peak_torque_over_limit), "planning_s": planning,
        "real_time_factor": metrics.real_time_factor,
    }


def run_task(label, q0, poses, repeats=1) -> list[dict]:
    """All planners on one task; returns one row per planner."""
    joints = joint_waypoints(q0, poses)
    rows, results = [], {}
    for name, config in _configs(poses, joints).items():
        planning = _planning_time(config, q0, repeats)
        results[name] = simulate(make_planner(config, UR10E, q0), name=name, settle_time=0.2, max_duration=30.0)
        rows.append((name, results[name], planning))
    reference = results["pajak_blend"]
    end = np.searchsorted(reference.t, reference.duration) + 1
    table = [_row(label, name, result, planning, _optimal_duration(result)) for name, result, planning in rows]
    # A dense grid: Toppra keeps the limits at its grid points only (2.2 % over between them on
    # the paper task's path with the default grid, 0.08 % with 2000 points).
    config = ToppraConfig(path=reference.q_ref[1:end].tolist(), grid_points=TOPPRA_GRID_POINTS)
    try:
        planning = _planning_time(config, reference.q_ref[0], repeats)
    except ValueError:  # no parameterisation of this path: the row says so
        table.append({column: float("nan") for column in COLUMNS} | {"task": label, "planner": "toppra", "succeeded": False})
        return table
    result = simulate(make_planner(config, UR10E, reference.q_ref[0]), name="toppra", settle_time=0.2)
    table.append(_row(label, "toppra", result, planning, _optimal_duration(result)))
    return table


def _markdown(rows) -> str:
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    for row in rows:
        lines.append("| " + " | ".join(_format(row[column]) for column in COLUMNS) + " |")
    return "\n".join(lines) + "\n"


def _format(value) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def medians(rows) -> list[dict]:
    """Per planner, the median of each numeric column over the tasks (share for booleans)."""
    summary = []
    for name in PLANNERS:
        mine = [row for row in rows if row["planner"] == name]
        entry = {"task": "median", "planner": name}
        for column in COLUMNS[2:]:
            values = [float(row[column]) for row in mine]
            finite = [value for value in values if np.isfinite(value)]
            if column == "succeeded":
                entry[column] = float(np.mean(values))
            elif column == "qdd_continuous":  # share of the runs that have a log
                entry[column] = float(np.mean(finite)) if finite else float("nan")
            else:
                entry[column] = float(np.median(finite)) if finite else float("nan")
        summary.append(entry)
    return summary


def bench(out_dir, *, count: int = 20, seed: int = 0, repeats: int = 5, progress=sys.stderr) -> list[dict]:
    """Run the benchmark; writes bench.csv, bench.md and bench.png into ``out_dir``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    tasks = [("paper", *paper_task(), repeats)] + [
        (f"random_{k}", q0, poses, 1) for k, (q0, poses) in enumerate(random_tasks(count, seed))]
    rows = []
    for index, (label, q0, poses, task_repeats) in enumerate(tasks):
        done = int(30 * index / len(tasks))
        print(f"\r[{'#' * done}{'.' * (30 - done)}] {index}/{len(tasks)} {label:10s}", end="", file=progress, flush=True)
        rows.extend(run_task(label, q0, poses, task_repeats))
    print(f"\r[{'#' * 30}] {len(tasks)}/{len(tasks)} done      ", file=progress)
    table = rows + (medians([row for row in rows if row["task"] != "paper"]) if count else [])
    with open(out_dir / "bench.csv", "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(table)
    paper_rows = [row for row in rows if row["task"] == "paper"]
    text = "## Paper task\n\n" + _markdown(paper_rows)
    if count:
        text += f"\n## Medians over {count} seeded tasks\n\n" + _markdown(table[len(rows):])
    (out_dir / "bench.md").write_text(text)
    _plot(rows, out_dir / "bench.png")
    print(text)
    return table


def _plot(rows, path) -> None:
    from matplotlib.figure import Figure

    figure = Figure(figsize=(9, 4), layout="constrained")
    duration_ax, acceleration_ax = figure.subplots(1, 2)
    for ax, column, label in ((duration_ax, "T_over_optimal", "T / time-optimal T on the same path"),
                              (acceleration_ax, "max_qdd_over_limit", "max |qdd| / limit")):
        data = [[row[column] for row in rows if row["planner"] == name] for name in PLANNERS]
        ax.boxplot(data, tick_labels=PLANNERS)
        ax.axhline(1.0, color="grey", linestyle="--")
        ax.set_ylabel(label)
        ax.tick_params(axis="x", rotation=45)
    figure.savefig(path, dpi=110)
