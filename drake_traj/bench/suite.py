"""``drake-traj bench``: every planner and baseline on the same UR10e waypoint tasks, one table.

Tasks: Pająk 2024's task (q(0), p1..pf) and ``count`` seeded random reachable tasks (three
waypoints, each the flange pose of a random configuration near the previous one). Each task runs,
through the same PD-controlled UR10e, with the UR joint-move limits (1.05 rad/s, 1.40 rad/s^2):

- ``pajak_blend`` / ``pajak_stop``: Pająk 2024's planner, passing or stopping at the waypoints;
- ``movej_blend``: UR-style joint moves with a 0.05 m blend radius;
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

Work units and the engine. One unit is one (planner, task) run: :func:`run_planner` for the
planners a config describes, :func:`run_toppra` for Toppra. Both are top-level functions of
picklable arguments (a :class:`Task`, a planner name, a config builder) returning a plain dict
(the row and, for ``pajak_blend``, its planned joint path as an array), so Dask can ship them to
any worker. Toppra's row parameterises ``pajak_blend``'s path, so its unit takes that run's
output as an argument: on Dask, the ``pajak_blend`` future itself, which makes the dependency
explicit to the scheduler (Toppra starts as soon as that one run ends, on whichever worker is
free, while the task's other runs go on elsewhere). We chose runs over whole tasks as the unit
because the runs of a task differ in cost by 10-50x (Pająk's law against a quintic), so
small units keep every worker busy to the end of a sweep, and a failure stays the failure of
one run. ``workers=1`` calls the same functions in this process, in order; otherwise the
runs go to a Dask ``LocalCluster`` of ``workers`` processes, or to the existing cluster whose
scheduler is at ``scheduler`` (its workers need the same drake_traj installed). A run that
raises, or whose worker dies, is a row with ``succeeded`` false, NaN metrics and the reason in
``failure``, never a lost task.
"""

import asyncio
import concurrent.futures
import contextlib
import csv
import functools
import importlib.metadata
import logging
import numbers
import os
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from distributed import Client, LocalCluster, as_completed
from distributed.comm import connect as dask_connect
from tqdm import tqdm

from drake_traj.cell import CellChecker
from drake_traj.errors import DrakeTrajError
from drake_traj.results import OutputError, claim
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
from drake_traj.planners import pajak
from drake_traj.planners.baselines.toppra import geometric_path_from_samples, time_optimal_along_path
from drake_traj.robots import UR10E, ur10e as robot

__all__ = [
    "COLUMNS", "CONFIG_BUILDERS", "PLANNERS", "BenchSetupError", "Task", "bench", "bench_figure", "medians", "optimal_duration",
    "pajak_walk_tasks", "paper_task", "random_tasks", "run_planner", "run_toppra", "tasks",
]

VELOCITY, ACCELERATION = robot.DEFAULT_JOINT_MOVE_VELOCITY, robot.DEFAULT_JOINT_MOVE_ACCELERATION
BLEND_RADIUS = 0.05  # [m], the paper's experiment 1
JUMP = 0.07  # [rad/s^2] between 1 ms samples: a jerk of 70 rad/s^3, above every continuous planner here
TOPPRA_GRID_POINTS = 2000
STOP_SPEED = 1e-3  # [rad/s]: a local minimum of the joint speed below this is a stop (optimal_duration)
# knots of the path's spline for Toppra, tried in turn: its reachability analysis fails on some
# splines of a path and not on others (Ruckig's moves on random_4: 200 knots fail on move 3,
# 50 pass; on move 2 the other way round; where both pass, T_opt differs by 0.3 %)
OPTIMUM_TOLERANCE = 5e-4  # T_opt's grid is refined until T changes by less than this (0.05 %)
OPTIMUM_GRID_MAX = 32000  # [points] the finest grid tried for T_opt
SPLINE_KNOTS = (200, 100, 50)
SETTLE_TIME, MAX_DURATION = 0.2, 30.0  # [s] of every run
REFERENCE = "pajak_blend"  # the planner whose path Toppra parameterises
COLUMNS = (
    "task", "planner", "succeeded", "T_s", "T_over_optimal", "max_qd_over_limit", "max_qdd_over_limit",
    "max_jerk", "qdd_continuous", "tracking_joint_rad", "tracking_tcp_m", "peak_torque_over_limit",
    "planning_s", "real_time_factor", "failure", "optimal_failure",
)
TIMING_COLUMNS = ("planning_s", "real_time_factor")


class BenchSetupError(DrakeTrajError):
    """A bench argument, output directory or scheduler that cannot work, found before any run."""


# --------------------------------------------------------------------------------------------
# Tasks and planner configs.
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Task:
    """A bench task: start configuration q0 [rad] (6,), task poses (m, 6) [m, rad], and how many
    times to repeat the planning-time measurement."""

    label: str
    q0: np.ndarray
    poses: np.ndarray
    repeats: int = 1


def paper_task():
    """(q0, task poses (4, 6)) of Pająk 2024."""
    return pajak.paper_initial_configuration(), pajak.paper_parameters(3).waypoints


def random_tasks(count: int, seed: int = 0):
    """``count`` reachable tasks: three waypoints, each the flange pose of a configuration at most
    0.6 rad per joint from the previous one, at least 0.15 m apart, away from singularities, and
    each configuration inside the default cell (a table flush with the base) with its clearance
    and free of self-collision. The motions between them are checked by each run."""
    rng = np.random.default_rng(seed)
    q0 = pajak.paper_initial_configuration()
    cell = _cell_checker()
    tasks = []
    while len(tasks) < count:
        configurations = [q0]
        for _ in range(3):
            configurations.append(configurations[-1] + rng.uniform(-0.6, 0.6, 6))
        poses = np.array([robot.task_pose(q) for q in configurations])
        far_enough = np.all(np.linalg.norm(np.diff(poses[:, :3], axis=0), axis=1) > 0.15)
        regular = all(robot.singularity_measure(q) > 0.15 and abs(np.cos(p[4])) > 0.3
                      for q, p in zip(configurations, poses))
        if far_enough and regular and not any(cell.contacts(q) for q in configurations[1:]):
            tasks.append((q0, poses[1:]))
    return tasks


def pajak_walk_tasks(count: int, seed: int = 9, step: float = 0.7) -> list[PajakConfig]:
    """``count`` seeded Pająk tasks of the law's random sweep (issue 22, tests/planners/test_pajak_random.py):
    walks in joint space from the paper's q(0), each of 1-4 waypoints the flange pose of a
    configuration up to ``step`` [rad] per joint from the previous one, limits drawn from
    0.5-2 rad/s and 0.7-3 rad/s² (one value for every joint or one per joint, by a fair coin).
    Tasks that ``validate()`` refuses (two waypoints closer than the neighbourhood) are drawn
    again. Not filtered for collisions or singularities: the law alone is what they measure."""
    rng = np.random.default_rng(seed)
    q0 = pajak.paper_initial_configuration()
    drawn = []
    while len(drawn) < count:
        configurations = [q0]
        for _ in range(int(rng.integers(1, 5))):
            configurations.append(configurations[-1] + rng.uniform(-step, step, 6))
        if rng.integers(0, 2):
            velocity, acceleration = rng.uniform(0.5, 2.0, 6), rng.uniform(0.7, 3.0, 6)
        else:
            velocity, acceleration = np.full(6, rng.uniform(0.5, 2.0)), np.full(6, rng.uniform(0.7, 3.0))
        task = PajakConfig(waypoints=np.array([robot.task_pose(q) for q in configurations[1:]]),
                           velocity_limit=velocity, acceleration_limit=acceleration)
        try:
            task.validate()
        except ValueError:  # e.g. two waypoints closer than the neighbourhood
            continue
        drawn.append(task)
    return drawn


def tasks(count: int, seed: int = 0, repeats: int = 5) -> list[Task]:
    """The paper task (planning timed ``repeats`` times) and ``count`` seeded random tasks (once)."""
    return [Task("paper", *paper_task(), repeats)] + [
        Task(f"random_{k}", q0, poses) for k, (q0, poses) in enumerate(random_tasks(count, seed))]


def joint_waypoints(q0, poses) -> np.ndarray:
    """q0 and the IK of each pose, each nearest the previous configuration, shape (m + 1, 6)."""
    return np.vstack([q0, robot.inverse_kinematics_path(poses, q0, max_step=np.inf)])


# Config builders: (task poses, joint waypoints) -> planner config, all with the UR10e's joint-move
# limits. Top-level functions, so that Dask can send them to its workers.
def pajak_blend_config(poses, joints):
    return PajakConfig(waypoints=poses, blend_waypoints=True)


def pajak_stop_config(poses, joints):
    return PajakConfig(waypoints=poses, blend_waypoints=False)


def movej_blend_config(poses, joints):
    return MovejConfig(goals=joints[1:].tolist(), blend_radius=BLEND_RADIUS)


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


# --------------------------------------------------------------------------------------------
# One run: the work unit.
# --------------------------------------------------------------------------------------------


def run_planner(task: Task, name: str, build, keep_path: bool = False) -> dict:
    """The run of planner ``name`` (config from ``build(poses, joints)``) on ``task``.

    Returns ``{"row": row, "path": path}``: the row of :data:`COLUMNS`, and with ``keep_path``
    the planned joint path [rad] (the reference from t = 0 to the planner's finish, (N, 6)) when
    the run succeeded, else None. Whatever goes wrong gives a failed row with its reason.
    """
    try:
        config = build(task.poses, joint_waypoints(task.q0, task.poses))
    except Exception as error:  # a run's failure is a row, not a lost task
        return {"row": failed_row(task.label, name, _reason(error)), "path": None}
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
        _cell_checker().check_planner(planner)
        result = simulate(planner, name=name, settle_time=SETTLE_TIME, max_duration=MAX_DURATION, preflight=False)
        row = _row(label, name, result, planning, _optimal_duration(result))
    except Exception as error:  # a run's failure is a row, not a lost task
        return {"row": failed_row(label, name, _reason(error)), "path": None}
    path = result.q_ref[: np.searchsorted(result.t, result.duration) + 1] if keep_path and result.succeeded else None
    return {"row": row, "path": path}


@functools.cache
def _cell_checker() -> CellChecker:
    """The default cell's checker, one per process (a Dask worker builds its own)."""
    return CellChecker(UR10E)


def _planning_time(config, q0, repeats):
    """Median wall time [s] of making the planner and its preflight (for the online Pająk
    planner, the law integrated alone over the whole task)."""
    def once():
        start = time.perf_counter()
        make_planner(config, UR10E, q0).preflight()
        return time.perf_counter() - start
    return statistics.median(once() for _ in range(repeats))


def optimal_duration(q, qd, velocity_limit=VELOCITY, acceleration_limit=ACCELERATION) -> tuple[float, str]:
    """(T_opt [s], reason): Toppra's time-optimal duration along the joint path q [rad] (N, 6)
    sampled with velocities qd [rad/s] (N, 6), under the joint limits [rad/s, rad/s^2] (scalar
    or per joint); reason is "" or why there is no T_opt (then T_opt is NaN).

    A planner that stops at waypoints leaves a path with corners there, which no timing can pass
    without stopping: the path is split at every stop and the pieces' optimal times are added.
    A stop is a sample at rest (|qd| <= 1e-6 rad/s) or a local minimum of |qd| below
    ``STOP_SPEED``: a stop between two 1 ms samples leaves the nearest one a few 10⁻⁶ rad/s from
    rest (Ruckig's stops: 3e-6 and 7e-6 rad/s on the bench's random_4; unsplit, Toppra found no
    parameterisation of 8 of its 20 paths). Toppra may find no parameterisation (a near-corner
    left where a planner slowed almost to rest without stopping), or fail numerically on one
    spline of the samples and not on a coarser one: each move is tried on splines of
    ``SPLINE_KNOTS`` knots in turn, and where all fail the reason is Toppra's.
    """
    q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
    speed = np.linalg.norm(qd, axis=1)
    moving = speed > 1e-6
    lowest = np.zeros(len(speed), dtype=bool)
    lowest[1:-1] = (speed[1:-1] <= speed[:-2]) & (speed[1:-1] <= speed[2:]) & (speed[1:-1] < STOP_SPEED)
    moving &= ~lowest
    moving[0] = moving[-1] = False  # the motion starts and (within the stop threshold) ends at rest
    starts = np.flatnonzero(moving[1:] & ~moving[:-1])  # last rest sample before each move
    stops = np.flatnonzero(~moving[1:] & moving[:-1]) + 1  # first rest sample after each move
    total = 0.0
    for number, (start, stop) in enumerate(zip(starts, stops)):
        piece = q[start : stop + 1]
        if np.ptp(piece, axis=0).max() <= 1e-6:
            continue
        for knots in SPLINE_KNOTS:
            try:
                total += converged_optimum(geometric_path_from_samples(piece, max_knots=knots), velocity_limit,
                                           acceleration_limit)
                break
            except ValueError as error:
                reason = f"no T_opt: move {number + 1} of {len(starts)}, splines of {SPLINE_KNOTS} knots: {error}"
        else:
            return float("nan"), reason
    return total, ""


def converged_optimum(path, velocity_limit, acceleration_limit) -> float:
    """Drake's Toppra's time-optimal duration [s] of ``path``, its grid refined until T changes by
    less than :data:`OPTIMUM_TOLERANCE`: its default grid first, then 2000, 4000, ... points evenly
    spaced in s (at most :data:`OPTIMUM_GRID_MAX`). Toppra's T depends on its grid: on its default
    grid it was 0.37 % longer than converged on sim 3's path and 1.8 % on quintic_ptp's samples
    joined without their stops (measured), which made every T / T_opt read against it optimistic.
    Raises ValueError where Toppra finds no parameterisation on its default grid."""
    previous = time_optimal_along_path(path, velocity_limit, acceleration_limit)[0]
    points = 2000
    while points <= OPTIMUM_GRID_MAX:
        grid = np.linspace(path.start_time(), path.end_time(), points)
        try:
            current = time_optimal_along_path(path, velocity_limit, acceleration_limit, grid_points=grid)[0]
        except ValueError:  # a finer grid that fails leaves the last one's answer
            return previous
        if abs(current - previous) <= OPTIMUM_TOLERANCE * current:
            return current
        previous, points = current, 2 * points
    return previous


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
        "max_qd_over_limit": metrics.max_velocity_over_limit,
        "max_qdd_over_limit": metrics.max_acceleration_over_limit, "max_jerk": metrics.max_jerk,
        "qdd_continuous": bool(steps.max() <= JUMP) if steps.size else float("nan"),
        "tracking_joint_rad": metrics.tracking_error_joint_max_rad,
        "tracking_tcp_m": metrics.tracking_error_tcp_max_m,
        "peak_torque_over_limit": max(metrics.peak_torque_over_limit), "planning_s": planning,
        "real_time_factor": metrics.real_time_factor, "failure": metrics.failure or "", "optimal_failure": no_optimum,
    }


def failed_row(task: str, planner: str, reason: str) -> dict:
    """The row of a run that produced no log: NaN metrics and the reason."""
    return {column: float("nan") for column in COLUMNS} | {
        "task": task, "planner": planner, "succeeded": False, "failure": reason, "optimal_failure": ""}


def _reason(error: BaseException) -> str:
    return " ".join(f"{type(error).__name__}: {error}".split())


# --------------------------------------------------------------------------------------------
# Running the units: in this process, or on Dask.
# --------------------------------------------------------------------------------------------


def _run_serial(work, builders, toppra, bar) -> dict:
    rows = {}
    for task in work:
        for name, build in builders.items():
            output = run_planner(task, name, build, keep_path=toppra and name == REFERENCE)
            rows[task.label, name] = bar.done(output["row"])
            if name == REFERENCE:
                reference = output
        if toppra:
            rows[task.label, "toppra"] = bar.done(run_toppra(task, reference)["row"])
    return rows


def _run_on(client, work, builders, toppra, bar) -> dict:
    runs = {}  # future -> (task, planner name)
    for task in work:
        for name, build in builders.items():
            future = client.submit(run_planner, task, name, build, toppra and name == REFERENCE, pure=False)
            runs[future] = (task, name)
            if name == REFERENCE:
                reference = future
        if toppra:
            runs[client.submit(run_toppra, task, reference, pure=False)] = (task, "toppra")
    rows = {}
    for future in as_completed(runs):
        task, name = runs.pop(future)
        try:
            row = future.result()["row"]
        except Exception as error:  # the worker died, or could not load the unit
            row = failed_row(task.label, name, _reason(error))
        rows[task.label, name] = bar.done(row)
        future.release()
    return rows


class _Progress:
    """Runs done, failed and the time left: a tqdm bar on a terminal; on another stream (a log
    file, CI) a line at most every :data:`LOG_INTERVAL`; nothing when the stream is None. A first
    line says how many runs there are and where they run."""

    def __init__(self, total: int, stream, where: str):
        self._stream = stream
        terminal = stream is not None and getattr(stream, "isatty", lambda: False)()
        self._lines = stream is not None and not terminal
        if stream is not None:
            print(f"bench: {total} runs {where}", file=stream, flush=True)
        self._bar = tqdm(total=total, unit="run", desc="bench", file=stream or sys.stderr, disable=not terminal,
                         dynamic_ncols=True)
        self.total, self.count, self.failed = total, 0, 0
        self._start = self._said = time.monotonic()

    def done(self, row) -> dict:
        """Count ``row``'s run; returns the row."""
        self.count += 1
        self.failed += not row["succeeded"]
        self._bar.set_postfix(failed=self.failed, refresh=False)
        self._bar.update()
        if self._lines and time.monotonic() - self._said >= LOG_INTERVAL and self.count < self.total:
            self._say(self.line())
        return row

    def line(self) -> str:
        """The progress after a run as one line: runs done of all, failed, elapsed and the time
        left estimated as the mean time per run so far times the runs left."""
        elapsed = time.monotonic() - self._start
        left = elapsed / self.count * (self.total - self.count)
        return (f"bench: {self.count}/{self.total} runs ({100 * self.count / self.total:.0f} %), {self.failed} failed, "
                f"{tqdm.format_interval(elapsed)} elapsed, about {tqdm.format_interval(left)} left")

    def _say(self, text: str) -> None:
        print(text, file=self._stream, flush=True)
        self._said = time.monotonic()

    def close(self):
        self._bar.close()
        if self._lines:
            self._say(f"bench: {self.count}/{self.total} runs in {tqdm.format_interval(time.monotonic() - self._start)}, "
                      f"{self.failed} failed")


def _where(workers: int | None, scheduler: str | None) -> str:
    """Where the runs go, for the progress's first line."""
    if scheduler is not None:
        return f"on the Dask cluster at {scheduler}"
    if workers == 1:
        return "in this process, one after another"
    return f"on a local Dask cluster of {workers} processes"


def _default_workers() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


async def _dask_handshake(address: str, timeout: float) -> None:
    """Open a Dask connection to ``address`` and close it; raises unless a Dask peer answers
    Dask's handshake within ``timeout`` [s] (Dask's own connect waits for the handshake without
    a time limit: a listener that is not Dask would hold it forever)."""
    # Dask retries a refused connection for 0.8 of the time, so that a refusal is told from silence
    comm = await asyncio.wait_for(dask_connect(address, timeout=0.8 * timeout), timeout)
    await comm.close()


def _connect(scheduler: str) -> Client:
    """A client of the Dask scheduler at ``scheduler`` whose workers have our drake_traj; a
    BenchSetupError naming the address within :data:`SCHEDULER_TIMEOUT` otherwise."""
    advice = ("Give the address a running scheduler prints (e.g. tcp://host:8786), or leave --scheduler out to run "
              "on this machine.")
    try:  # in a thread of its own: bench may be called where an event loop runs (a notebook)
        with concurrent.futures.ThreadPoolExecutor(1) as pool:
            pool.submit(asyncio.run, _dask_handshake(scheduler, SCHEDULER_TIMEOUT)).result()
    except TimeoutError:  # asyncio's since Python 3.11
        raise BenchSetupError(f"--scheduler {scheduler}: something accepts connections there but did not answer as a "
                              f"Dask scheduler within {SCHEDULER_TIMEOUT:g} s. {advice}") from None
    except OSError as error:  # refused (Dask retries until the timeout), unreachable, closed at once
        raise BenchSetupError(f"--scheduler {scheduler}: no Dask scheduler answered there ({_reason(error)}; "
                              f"waited at most {SCHEDULER_TIMEOUT:g} s). {advice}") from None
    except ValueError as error:  # a malformed address
        raise BenchSetupError(f"--scheduler {scheduler}: not an address Dask can connect to ({_reason(error)}). "
                              f"{advice}") from None
    except Exception as error:  # e.g. MemoryError: a peer's bytes read as a Dask message length
        raise BenchSetupError(f"--scheduler {scheduler}: what answers there does not speak Dask's protocol (reading "
                              f"its reply as Dask's gave {type(error).__name__}). {advice}") from None
    try:
        client = Client(scheduler, timeout=SCHEDULER_TIMEOUT)
    except Exception as error:  # a Dask peer that is not a scheduler (a worker), ...
        raise BenchSetupError(f"--scheduler {scheduler}: cannot connect to a Dask scheduler there ({_reason(error)}). "
                              f"{advice}") from None
    ours = importlib.metadata.version("drake_traj")
    try:
        theirs = set(client.run(importlib.metadata.version, "drake_traj").values())
    except Exception as error:
        client.close()
        raise BenchSetupError(
            f"--scheduler {scheduler}: a worker of that cluster cannot load drake_traj ({_reason(error)}); "
            f"install drake_traj {ours} on every worker."
        ) from None
    if theirs - {ours}:
        client.close()
        raise BenchSetupError(
            f"--scheduler {scheduler}: that cluster's workers have drake_traj {sorted(theirs)}, this is {ours}; "
            "install the same version on every worker."
        )
    if not theirs:
        print(f"--scheduler {scheduler}: the cluster has no workers yet; the runs wait for them", file=sys.stderr)
    return client


@contextlib.contextmanager
def _engine(workers, scheduler):
    """A Dask client of the cluster at ``scheduler`` or of a new local cluster of ``workers``
    processes; None (run in this process) for one local worker."""
    if scheduler is None and workers == 1:
        yield None
        return
    if scheduler is not None:
        with _connect(scheduler) as client:
            yield client
        return
    # no dashboard; the scheduler's HTTP server (health, metrics) on a free local port: on Dask's
    # default 8787 a second cluster (another bench, a notebook) warned "Port 8787 is already in use"
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                      scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}, silence_logs=logging.ERROR) as cluster, \
            Client(cluster) as client:
        yield client


# --------------------------------------------------------------------------------------------
# Arguments, tables and the plot.
# --------------------------------------------------------------------------------------------


MAX_COUNT = 10_000  # seeded tasks per bench: each costs about 10 s of one core here (all planners)
LOG_INTERVAL = 30.0  # [s] at most between progress lines where the progress is not a terminal
SCHEDULER_TIMEOUT = 10.0  # [s] a --scheduler address answers as a Dask scheduler within this, or is refused


def _check_arguments(count, seed, repeats, workers, scheduler, planners, extra_planners) -> None:
    def whole(value, name, option, least, most=2**32 - 1, why=""):
        if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not least <= value <= most:
            raise BenchSetupError(f"{name} ({option}) must be a whole number from {least} to {most}{why}, got {value!r}")

    whole(count, "count", "--count", 0, MAX_COUNT)
    whole(seed, "seed", "--seed", 0)
    whole(repeats, "repeats", "--repeats", 1, 1000)
    if workers is not None:
        whole(workers, "workers", "--workers", 1, _default_workers(),
              " (this machine's cores, a process each; for more, a Dask cluster: --scheduler)")
        if scheduler is not None:
            raise BenchSetupError(
                f"workers (--workers {workers}) sizes the local cluster; with --scheduler {scheduler} the runs go "
                "to that cluster's workers: give one of the two")
    if scheduler is not None and (not isinstance(scheduler, str) or not scheduler.strip()):
        raise BenchSetupError(f"scheduler (--scheduler) must be an address such as tcp://host:8786, got {scheduler!r}")
    unknown = [name for name in planners if name not in PLANNERS]
    if unknown or not planners:
        raise BenchSetupError(f"planners must be some of {list(PLANNERS)}, got {list(planners)}")
    if "toppra" in planners and REFERENCE not in planners:
        raise BenchSetupError(f"planners: toppra parameterises the path of {REFERENCE}; select both")
    for name, build in extra_planners.items():
        if name in PLANNERS or not callable(build):
            raise BenchSetupError(
                f"extra_planners[{name!r}] must be a new planner name with a config builder, got {build!r}")


BENCH_FILES = ("bench.csv", "bench.md", "bench.png")  # what a bench writes into its folder
BENCH_SIZE = 4 * 2**20  # [bytes] about what bench.csv, bench.md and bench.png take, rounded up


def _claim_output_directory(out_dir, overwrite: bool, command: str | None):
    """``out_dir`` claimed for this bench (:func:`drake_traj.output.claim`): created, writable,
    not a run's folder, not an earlier bench's unless ``overwrite``, locked; BenchSetupError if
    not (if it is or lies below a file, say)."""
    out_dir = Path(out_dir)
    try:
        return claim(out_dir, "bench", overwrite=overwrite, estimate=BENCH_SIZE, command=command)
    except OutputError as error:
        raise BenchSetupError(f"--out {out_dir}: {error}") from None


def bench(out_dir, *, count: int = 20, seed: int = 0, repeats: int = 5, workers: int | None = None,
          scheduler: str | None = None, planners=PLANNERS, extra_planners: dict | None = None,
          progress=sys.stderr, overwrite: bool = False, command: str | None = None) -> list[dict]:
    """Run the benchmark; writes bench.csv, bench.md and bench.png into ``out_dir``.

    Args:
        out_dir: output directory (created; must not be or lie below a file, nor hold a run, an
            earlier bench or other files). The files are written whole beside the earlier ones
            and replace them only once complete on disk (:mod:`drake_traj.output`).
        count: seeded random tasks besides the paper task (>= 0).
        seed: seed of the random tasks (>= 0).
        repeats: planning-time repeats on the paper task (>= 1).
        workers: processes of the local Dask cluster (1 to the machine's cores; default one per
            core); 1 runs every unit in this process, in order, without Dask. The cluster's
            processes are spawned and import the main module: from a script, call ``bench`` under
            ``if __name__ == "__main__":``.
        scheduler: address of an existing Dask scheduler (e.g. ``tcp://host:8786``) to run the
            units on instead of a local cluster; its workers need the same drake_traj. An address
            that does not answer as a Dask scheduler within :data:`SCHEDULER_TIMEOUT` (10 s) is
            refused.
        planners: the names of :data:`PLANNERS` to run (toppra needs pajak_blend).
        extra_planners: more planners to run on every task: name -> ``build(poses, joints)``
            returning a planner config (poses (m, 6) [m, rad], joint waypoints (m + 1, 6)
            [rad]). On Dask, ``build`` must be a top-level function of a module the workers
            can import. A build or planner that raises gives failed rows.
        progress: stream of the progress (stderr by default; None: none): a first line with the
            number of runs and where they run, then on a terminal a bar with the runs done, failed
            and the time left, elsewhere (a log, CI) a line of the same at most every
            :data:`LOG_INTERVAL` (30 s) and at the end. ``print``s bench.md's tables and a last
            line naming the files written.
        overwrite: replace an earlier bench in ``out_dir``.
        command: names this process to another writer of ``out_dir`` (default its command line).

    Returns:
        The rows (one per run, tasks in order, planners in the order of ``planners``, then the
        extra ones) followed by the medians over the random tasks.

    Raises:
        BenchSetupError: a bad argument, output directory or scheduler, before any run.
        drake_traj.output.WriteError: the files could not be written (disk full, ...); the
            earlier content of ``out_dir`` is intact.
    """
    planners, extra_planners = tuple(planners), dict(extra_planners or {})
    _check_arguments(count, seed, repeats, workers, scheduler, planners, extra_planners)
    if workers is None and scheduler is None:
        workers = _default_workers()
    builders = {name: CONFIG_BUILDERS[name] for name in planners if name != "toppra"} | extra_planners
    toppra = "toppra" in planners
    with _claim_output_directory(out_dir, overwrite, command) as claimed:
        table, text = _bench(claimed, count, seed, repeats, workers, scheduler, (*planners, *extra_planners), builders,
                             toppra, progress)
    print(text)
    print(f"wrote {out_dir}: {', '.join(BENCH_FILES)}")
    return table


def _bench(claimed, count, seed, repeats, workers, scheduler, names, builders, toppra, progress):
    """The bench of :func:`bench` into its ``claimed`` folder (rows of the planners ``names`` in
    order); returns the table and bench.md's text."""
    with _engine(workers, scheduler) as client:
        bar = _Progress((count + 1) * (len(builders) + toppra), progress, _where(workers, scheduler))
        try:
            work = tasks(count, seed, repeats)
            if client is None:
                by_run = _run_serial(work, builders, toppra, bar)
            else:
                by_run = _run_on(client, work, builders, toppra, bar)
        finally:
            bar.close()
    rows = [by_run[task.label, name] for task in work for name in names]
    failed = sum(not row["succeeded"] for row in rows)
    if failed:
        print(f"{failed} of {len(rows)} runs failed (see the failure column)", file=sys.stderr)
    table = rows + (medians([row for row in rows if row["task"] != "paper"]) if count else [])
    paper_rows = [row for row in rows if row["task"] == "paper"]
    text = "## Paper task\n\n" + _markdown(paper_rows)
    if count:
        text += f"\n## Medians over {count} seeded tasks\n\n" + _markdown(table[len(rows):])
    with claimed.replace() as staging:
        csv_file, markdown, figure = BENCH_FILES
        staging.write(csv_file, functools.partial(_write_csv, table))
        staging.write(markdown, lambda path: path.write_text(text))
        staging.write(figure, lambda path: bench_figure(rows).savefig(path, dpi=110))
    return table, text


def _write_csv(table, path) -> None:
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(table)


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
    return str(value).replace("|", "/")


def _planner_names(rows) -> list[str]:
    return list(dict.fromkeys(row["planner"] for row in rows))


def medians(rows) -> list[dict]:
    """Per planner, the median of each numeric column over the tasks (share for booleans; for
    ``failure``, how many runs failed)."""
    summary = []
    for name in _planner_names(rows):
        mine = [row for row in rows if row["planner"] == name]
        failed = sum(bool(row["failure"]) for row in mine)
        unbounded = sum(bool(row["optimal_failure"]) for row in mine)
        entry = {"task": "median", "planner": name, "failure": f"{failed} of {len(mine)} failed" if failed else "",
                 "optimal_failure": f"{unbounded} of {len(mine)} without T_opt" if unbounded else ""}
        for column in COLUMNS[2:-2]:
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


def bench_figure(rows):
    """The plot of ``bench.png``: per planner, boxes of T over the time-optimal T, of the peak q̈
    over the limit and of the largest jerk across the tasks of ``rows``, the task count in the
    title."""
    from matplotlib.figure import Figure

    names = _planner_names(rows)
    tasks = list(dict.fromkeys(row["task"] for row in rows))
    seeded = sum(task != "paper" for task in tasks)
    figure = Figure(figsize=(13, 4.6), layout="constrained")
    duration_ax, acceleration_ax, jerk_ax = figure.subplots(1, 3)
    jerk_ax.set_yscale("log")  # 10-30 rad/s^3 for the smooth planners, thousands for the bang-bang ones
    for ax, column, label, bound, level in (
            (duration_ax, "T_over_optimal", "T / time-optimal T on the same path", "1: time-optimal", 1.0),
            (acceleration_ax, "max_qdd_over_limit", "max |qdd| / limit", "1: the limit", 1.0),
            (jerk_ax, "max_jerk", "max |jerk| of the reference [rad/s^3]", "JUMP per 1 ms: continuous qdd",
             JUMP / 1e-3)):
        data = [[row[column] for row in rows if row["planner"] == name and np.isfinite(row[column])]
                for name in names]
        # a planner whose runs did not all give a value (failed runs) says over how many the box is
        ticks = [name if len(values) == len(tasks) else f"{name}\n({len(values)} of {len(tasks)})"
                 for name, values in zip(names, data)]
        boxes = ax.boxplot(data, tick_labels=ticks)
        line = ax.axhline(level, color="grey", linestyle="--")
        ax.legend([boxes["medians"][0], line], ["median over the tasks (box: quartiles)", bound], fontsize="small")
        ax.set_ylabel(label)
        ax.tick_params(axis="x", rotation=45)
    figure.suptitle(f"{len(names)} planners on {len(tasks)} UR10e tasks: Pająk 2024's"
                    + (f" and {seeded} seeded random ones" if seeded else ""))
    return figure
