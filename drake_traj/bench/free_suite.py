"""``drake-traj bench --suite free``: the free-motion planner on the seeded scenes of
:mod:`drake_traj.bench.free_scenes`, ``count`` queries of every kind, on Dask like the default bench.

One work unit is one query (:func:`run_free_query`): its scene drawn from its seed (scene seeds
``seed``, ``seed + 1``, ... per kind, one query each), the planner made as users make it
(``make_planner(FreeMotionConfig(...), robot, start)``) and planned in the scene's cell as the
preflight does (``CellChecker.check_planner``, which calls ``plan_in``). A row records whether it
was solved (or the refusal's message), the planning time (the planner's ``planning_time_s``, and
the wall and process CPU time round the call), the motion's duration T, T over Drake's Toppra's
time-optimal duration on the same found path (:func:`~drake_traj.bench.optimum.converged_optimum`,
the planner's velocity and acceleration limits, no jerk limit), and the least distance between
any two bodies at every 1 ms sample of the timed motion by a SceneGraph query of this module's own
(:class:`ClearanceProbe`: a cell check of its own, a second plant of the robot and the cell, asked
for signed distances directly: not the planner's checker, its samples or its compiled model). The
query's witness was checked when its scene was made (:mod:`~drake_traj.bench.free_scenes`).

``free.csv`` has every row, ``free.md`` the summary per kind (:func:`summary`), written whole by
the bench's writer (:mod:`drake_traj.results.output`).
"""

import csv
import functools
import sys
import time
from pathlib import Path

import numpy as np

from drake_traj.bench.engine import BenchSetupError, _collect, _default_workers, _engine, _Progress, where
from drake_traj.bench.free_scenes import SCENE_KINDS, generate
from drake_traj.bench.optimum import converged_optimum
from drake_traj.bench.report import _format
from drake_traj.bench.run import _check_where, _claim_output_directory, _whole_number
from drake_traj.bench.units import failure_reason
from drake_traj.cell import CellChecker
from drake_traj.errors import reraise_interrupt
from drake_traj.planners import make_planner

__all__ = ["ClearanceProbe", "FREE_COLUMNS", "FREE_FILES", "free_bench", "run_free_query", "summary"]

FREE_FILES = ("free.csv", "free.md")
FREE_COLUMNS = (
    "kind", "scene_seed", "goal", "solved", "planning_s", "wall_s", "cpu_s", "T_s", "T_toppra_s", "T_over_toppra",
    "min_distance_m", "clearance_m", "keeps_clearance", "generation_s", "failure",
)
PLANNING_TIME = 5.0  # [s] the whole planning budget of a query: FreeMotionConfig's default, as users run it
SAMPLE_PERIOD = 1e-3  # [s] of the timed motion between two samples of the independent check
WITHIN = 0.05  # [m] distances are looked at up to this (a larger one reads as 0.05)
MAX_COUNT = 1000  # queries per kind


class ClearanceProbe:
    """The least signed distance [m] between any two bodies that may collide (the arm's links, its
    tool, the cell's geometry): ``robot`` in ``cell`` in a cell check of its own
    (:class:`~drake_traj.cell.CellChecker`: its plant and SceneGraph, the pairs it checks), asked
    ``ComputeSignedDistancePairwiseClosestPoints`` directly. Joint positions in rad, world = base frame."""

    def __init__(self, robot, cell):
        self.checker = CellChecker(robot, cell)  # its plant and SceneGraph, asked directly

    def distance(self, q, within: float = WITHIN) -> float:
        """The least distance at ``q``; ``within`` [m] where every pair is further apart."""
        pairs = self.checker.pose_query(q).ComputeSignedDistancePairwiseClosestPoints(within)
        return min((pair.distance for pair in pairs), default=within)

    def along(self, configurations, within: float = WITHIN) -> float:
        """The least :meth:`distance` over ``configurations`` (k, n)."""
        return min((self.distance(q, within) for q in configurations), default=within)


def _failed(kind: str, scene_seed: int, reason: str, **known) -> dict:
    return {column: float("nan") for column in FREE_COLUMNS} | {
        "kind": kind, "scene_seed": scene_seed, "goal": "", "solved": False, "keeps_clearance": "",
        "failure": reason} | known


def run_free_query(kind: str, scene_seed: int, planning_time: float = PLANNING_TIME) -> dict:
    """The row of :data:`FREE_COLUMNS` of the query of the ``kind`` scene drawn from
    ``scene_seed``, planned with a budget of ``planning_time`` [s] (module docstring). Whatever
    goes wrong gives a row with its reason in ``failure``."""
    began = time.perf_counter()
    try:
        scene = generate(kind, scene_seed)
    except Exception as error:  # a unit's failure is a row, not a lost run
        reraise_interrupt(error)
        return _failed(kind, scene_seed, failure_reason(error))
    query = scene.queries[0]
    probe = ClearanceProbe(scene.robot, scene.cell)
    known = {"goal": "pose" if query.pose is not None else "joints", "clearance_m": scene.cell.clearance,
             "generation_s": time.perf_counter() - began}
    checker = CellChecker(scene.robot, scene.cell)
    wall, cpu = time.perf_counter(), time.process_time()
    try:
        planner = make_planner(query.config(planning_time=planning_time), scene.robot, query.start)
        checker.check_planner(planner)  # what the preflight's cell check calls: plan_in(checker)
    except Exception as error:  # refused: the planner's message
        reraise_interrupt(error)
        return _failed(kind, scene_seed, failure_reason(error), wall_s=time.perf_counter() - wall,
                       cpu_s=time.process_time() - cpu, **known)
    known |= {"wall_s": time.perf_counter() - wall, "cpu_s": time.process_time() - cpu}
    return _solved_row(kind, scene_seed, planner, probe, known)


def _solved_row(kind, scene_seed, planner, probe, known) -> dict:
    """The row of a planned query: T, T over Toppra's on the found paths, the independent check."""
    duration = planner.planned_duration()
    try:
        optimum = sum(converged_optimum(leg.timing.path, planner.velocity, planner.acceleration)
                      for leg in planner.legs)
    except ValueError:  # Toppra found no parameterisation
        optimum = float("nan")
    plan = planner.plan()
    times = np.append(np.arange(plan.start_time(), plan.end_time(), SAMPLE_PERIOD), plan.end_time())
    nearest = probe.along(plan.vector_values(times).T)
    return {"kind": kind, "scene_seed": scene_seed, "solved": True, "planning_s": planner.planning_time_s,
            "T_s": duration, "T_toppra_s": optimum, "T_over_toppra": duration / optimum, "min_distance_m": nearest,
            "keeps_clearance": bool(nearest >= known["clearance_m"]), "failure": ""} | known


def _percentiles(values) -> str:
    values = np.asarray([v for v in values if np.isfinite(v)], dtype=float)
    if not len(values):
        return "-"
    return f"{np.median(values):.3f} / {np.percentile(values, 90):.3f} / {values.max():.3f}"


REASONS = {"no collision-free path": "no path within the budget", "no smooth motion": "no smooth motion kept the clearance",
           "inverse-kinematics solutions": "no IK solution clear of the cell"}
"""A failure's words -> its short name in the summary (otherwise its error's type)."""


def _reason(failure: str) -> str:
    return next((short for words, short in REASONS.items() if words in failure), failure.split(":")[0])


def summary(rows) -> list[dict]:
    """Per kind (in :data:`SCENE_KINDS`'s order), then over all: queries, solved, planning time
    [s] (the planner's, of the solved queries; CPU and wall round the call, of all) median / p90 /
    worst, T / T_toppra median, the least distance [mm] seen in the solved motions, and the
    failures by their kind (:data:`REASONS`)."""
    table = []
    kinds = [kind for kind in SCENE_KINDS if any(row["kind"] == kind for row in rows)]
    for kind in kinds + ["all"]:
        mine = [row for row in rows if kind in ("all", row["kind"])]
        solved = [row for row in mine if row["solved"]]
        ratios = [row["T_over_toppra"] for row in solved if np.isfinite(row["T_over_toppra"])]
        reasons = {}
        for row in mine:
            if not row["solved"]:
                reasons[_reason(row["failure"])] = reasons.get(_reason(row["failure"]), 0) + 1
        table.append({
            "kind": kind, "queries": len(mine), "solved": f"{len(solved)} / {len(mine)}",
            "solved_percent": 100.0 * len(solved) / len(mine) if mine else float("nan"),
            "planning_s": _percentiles(row["planning_s"] for row in solved),
            "cpu_s": _percentiles(row["cpu_s"] for row in mine), "wall_s": _percentiles(row["wall_s"] for row in mine),
            "T_over_toppra": f"{np.median(ratios):.3f}" if ratios else "-",
            "min_distance_mm": min((1e3 * row["min_distance_m"] for row in solved), default=float("nan")),
            "failures": ", ".join(f"{count} {reason}" for reason, count in reasons.items())})
    return table


SUMMARY_HEADER = ("kind", "queries", "solved", "solved [%]", "planning [s] median / p90 / worst (solved)",
                  "CPU [s] median / p90 / worst", "wall [s] median / p90 / worst", "T / T_toppra median",
                  "least distance [mm]", "failures")


def markdown(rows, count: int, seed: int, planning_time: float) -> str:
    """free.md: the summary per kind, then every query's row."""
    lines = [f"## Free motion: {count} queries per kind, scene seeds {seed}-{seed + count - 1}, planning_time "
             f"{planning_time:g} s\n", "| " + " | ".join(SUMMARY_HEADER) + " |", "|" + "---|" * len(SUMMARY_HEADER)]
    for entry in summary(rows):
        values = list(entry.values())
        lines.append("| " + " | ".join(_format(value) for value in values) + " |")
    lines += ["", "## Every query", "", "| " + " | ".join(FREE_COLUMNS) + " |", "|" + "---|" * len(FREE_COLUMNS)]
    lines += ["| " + " | ".join(_format(row[column]) for column in FREE_COLUMNS) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def _write_csv(rows, path) -> None:
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=FREE_COLUMNS)
        writer.writeheader()
        writer.writerows(rows)


def _check(count, seed, workers, scheduler, kinds, planning_time) -> None:
    """BenchSetupError naming the first argument of :func:`free_bench` that cannot work."""
    _whole_number(count, "count", "--count", 1, MAX_COUNT)
    _whole_number(seed, "seed", "--seed", 0, 2**31 - MAX_COUNT)
    _check_where(workers, scheduler)
    unknown = [kind for kind in kinds if kind not in SCENE_KINDS]
    if unknown or not kinds:
        raise BenchSetupError(f"kinds must be some of {list(SCENE_KINDS)}, got {list(kinds)}")
    if not (isinstance(planning_time, (int, float)) and 0 < planning_time <= 120):
        raise BenchSetupError(f"planning_time must be a number of seconds in (0, 120], got {planning_time!r}")


def free_bench(out_dir, *, count: int = 5, seed: int = 0, workers: int | None = None, scheduler: str | None = None,
               kinds=tuple(SCENE_KINDS), planning_time: float = PLANNING_TIME, progress=sys.stderr,
               overwrite: bool = False, command: str | None = None) -> list[dict]:
    """Run the free-motion suite; writes free.csv and free.md into ``out_dir``.

    Args:
        out_dir: output folder (as :func:`~drake_traj.bench.bench`'s: new or empty, or an earlier
            bench's with ``overwrite``).
        count: queries per scene kind (scene seeds ``seed`` ... ``seed + count - 1``).
        seed: the first scene seed.
        workers, scheduler: where the queries run (:func:`~drake_traj.bench.bench`'s; default a
            local Dask cluster of one process per core, 1: in this process, in order).
        kinds: the scene kinds (:data:`~drake_traj.bench.free_scenes.SCENE_KINDS`).
        planning_time: the planner's whole planning budget of a query [s].
        progress: stream of the progress (None: none); prints free.md and the files written.
        overwrite, command: as :func:`~drake_traj.bench.bench`'s.

    Returns:
        The rows (:data:`FREE_COLUMNS`), kinds in order, scene seeds in order.
    """
    kinds = tuple(kinds)
    _check(count, seed, workers, scheduler, kinds, planning_time)
    if workers is None and scheduler is None:
        workers = _default_workers()
    work = [(kind, seed + k) for kind in kinds for k in range(count)]
    with _claim_output_directory(out_dir, overwrite, command) as claimed:
        with _engine(workers, scheduler) as client:
            bar = _Progress(len(work), progress, where(workers, scheduler), failed=lambda row: not row["solved"])
            try:
                by_query = _run(client, work, planning_time, bar)
            finally:
                bar.close()
        rows = [by_query[unit] for unit in work]
        text = markdown(rows, count, seed, planning_time)
        with claimed.replace() as staging:
            staging.write(FREE_FILES[0], functools.partial(_write_csv, rows))
            staging.write(FREE_FILES[1], lambda path: path.write_text(text))
    print(text)
    print(f"wrote {Path(out_dir)}: {', '.join(FREE_FILES)}")
    return rows


def _run(client, work, planning_time, bar) -> dict:
    """{(kind, scene seed): row} of every unit of ``work``: in this process (``client`` None) or on
    Dask, each counted by the progress ``bar``."""
    if client is None:
        return {unit: bar.done(run_free_query(*unit, planning_time)) for unit in work}
    futures = {client.submit(run_free_query, *unit, planning_time, pure=False): unit for unit in work}
    return _collect(futures, bar, lambda row: row, lambda unit, reason: _failed(*unit, reason))
