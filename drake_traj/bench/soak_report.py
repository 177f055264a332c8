"""``drake-traj bench --suite soak``'s entry point and report: :func:`soak_bench` checks its
arguments and claims its folder before any task, runs every (arm, planner, seed) task
(:func:`~drake_traj.bench.soak_suite.run_soak_task`) in this process or on Dask, and writes
``soak.csv`` (every row), ``soak.md`` (the figures per arm and planner, then every wrong row with
the command that reruns it) and ``soak.png`` (:func:`soak_figure`)."""

import csv
import functools
import sys
import time
from pathlib import Path

import numpy as np

from drake_traj.bench.engine import BenchSetupError, _collect, _default_workers, _engine, _Progress, where
from drake_traj.bench.report import _format
from drake_traj.bench.run import _check_where, _claim_output_directory, _whole_number
from drake_traj.bench.soak_suite import SOAK_COLUMNS, run_soak_task, soak_row
from drake_traj.bench.soak_tasks import ARMS, DRAWS

__all__ = ["SOAK_ARMS", "SOAK_FILES", "SOAK_PLANNERS", "merge_soaks", "read_soak_csv", "soak_bench", "soak_figure",
           "soak_summary"]

SOAK_FILES = ("soak.csv", "soak.md", "soak.png")
SOAK_ARMS, SOAK_PLANNERS = tuple(ARMS), tuple(DRAWS)  # what --arms and --planners take, all by default
MAX_COUNT = 100_000  # tasks per arm and planner
SHOWN_WRONG = 50  # wrong rows listed in soak.md (all are in soak.csv)
# tasks per local Dask cluster: pydrake 1.51 never frees what a task's Drake systems hold (about
# 1.7 MB a task, measured, once each planner is emptied), so a local soak makes its cluster afresh
# every LOCAL_CHUNK tasks (1-2 GB a worker at most; about 8 s to start one); workers of a cluster
# of one's own (--scheduler) are best started with `dask worker --lifetime 10m --lifetime-restart`
LOCAL_CHUNK = 2000


def _worst(rows, column, pick=max) -> float:
    values = [float(row[column]) for row in rows if row[column] != "" and np.isfinite(float(row[column]))]
    return pick(values) if values else float("nan")


def _counts(values) -> str:
    counts = {}
    for value in values:
        counts[value] = counts.get(value, 0) + 1
    return ", ".join(f"{count} {value}" for value, count in sorted(counts.items(), key=lambda item: -item[1]))


def soak_summary(rows) -> list[dict]:
    """Per (arm, planner), in the rows' order: tasks, planned, refused by cause, errors, silent
    wrong, wrong refusals, the diagnoses, the worst of each check (peak fractions of the limits,
    joint-range excess, goal error over its tolerance, least distance over the clearance, 1 ms
    intervals not certified), the closed loop's runs and the time per task [s]."""
    table = []
    for arm, planner in dict.fromkeys((row["arm"], row["planner"]) for row in rows):
        mine = [row for row in rows if row["arm"] == arm and row["planner"] == planner]
        planned = [row for row in mine if row["outcome"] == "planned"]
        refused = [row for row in mine if row["outcome"] == "refused"]
        loops = [row for row in planned if row["closed_loop"]]
        distances = [float(row["least_distance_m"]) / float(row["clearance_m"]) for row in planned
                     if row["least_distance_m"] != ""]
        seconds = [float(row["planning_s"] or 0) + float(row["check_s"] or 0) for row in mine]
        table.append({
            "arm": arm, "planner": planner, "tasks": len(mine), "planned": len(planned),
            "refused": f"{len(refused)}" + (f" ({_counts(row['cause'] for row in refused)})" if refused else ""),
            "errors": sum(row["outcome"] == "error" for row in mine),
            "silent_wrong": sum(bool(row["silent_wrong"]) for row in mine),
            "wrong_refusals": sum(row["outcome"] == "refused" and bool(row["wrong"]) for row in mine),
            "diagnoses": _counts(row["diagnosis"].split(":")[0] for row in refused),
            "velocity": _worst(planned, "velocity_fraction"), "acceleration": _worst(planned, "acceleration_fraction"),
            "jerk": _worst(planned, "jerk_fraction"),
            "tool": max(_worst(planned, "tool_speed_fraction"), _worst(planned, "tool_acceleration_fraction")),
            "range_excess_rad": _worst(planned, "range_excess_rad"),
            "goal": _worst([row for row in planned if row["goal_tolerance"] != ""], "goal_error"),
            "least_over_clearance": min(distances, default=float("nan")),
            "uncertified": int(sum(int(row["uncertified_intervals"] or 0) for row in planned)),
            "closed_loop": f"{sum(row['closed_loop'] == 'succeeded' for row in loops)} / {len(loops)}",
            "seconds_per_task": float(np.mean(seconds)) if seconds else float("nan"),
        })
    return table


SUMMARY_HEADER = ("arm", "planner", "tasks", "planned", "refused (by cause)", "errors", "silent wrong",
                  "wrong refusals", "refusals: independent diagnosis", "worst peak q̇ / limit", "worst peak q̈ / limit",
                  "worst peak q⃛ / limit", "worst tool speed or acceleration / limit (Li)", "worst range excess [rad]", "worst goal error / tolerance",
                  "least distance / clearance", "1 ms intervals not certified", "closed loop passed / run",
                  "time per task [s]")


def _cell(value) -> str:
    """A summary value as soak.md shows it: "-" where there is none (no plan, no limit)."""
    return "-" if isinstance(value, float) and not np.isfinite(value) else _format(value)


def _seeds(rows) -> str:
    """The seeds of ``rows`` as ranges: "0-999" or "0-499, 1000-1499"."""
    seeds = sorted({row["seed"] for row in rows})
    ranges, first = [], seeds[0]
    for before, after in zip(seeds, seeds[1:] + [None]):
        if after != before + 1:
            ranges.append(f"{first}-{before}" if before != first else f"{first}")
            first = after
    return ", ".join(ranges)


def markdown(rows, table, wall: float | None, stopped: str | None = None) -> str:
    """soak.md: the summary per arm and planner, then the wrong rows with their rerun commands;
    ``stopped`` (an interrupted soak's "stopped after N of M tasks") in the title."""
    wrong = [row for row in rows if row["wrong"]]
    took = (f"{wall:.0f} s wall" if wall is not None else "merged from parts") + (f", {stopped}" if stopped else "")
    lines = [f"## Soak: {len(rows)} tasks, seeds {_seeds(rows)}, {took}\n",
             "| " + " | ".join(SUMMARY_HEADER) + " |", "|" + "---|" * len(SUMMARY_HEADER)]
    lines += ["| " + " | ".join(_cell(value) for value in entry.values()) + " |" for entry in table]
    lines += ["", f"## Wrong: {len(wrong)}", ""]
    for row in wrong[:SHOWN_WRONG]:
        lines.append(f"- {row['arm']} {row['planner']} seed {row['seed']} ({row['outcome']}): {row['message'][:300]}  \n"
                     f"  `{row['rerun']}`")
    if len(wrong) > SHOWN_WRONG:
        lines.append(f"- ... and {len(wrong) - SHOWN_WRONG} more in soak.csv")
    return "\n".join(lines) + "\n"


def soak_figure(rows):
    """soak.png: per planner (all arms), the share of tasks planned, refused and wrong, and the
    worst peak of |q̈| over its limit and the least distance over the clearance of each plan."""
    from matplotlib.figure import Figure

    planners = list(dict.fromkeys(row["planner"] for row in rows))
    figure = Figure(figsize=(14, 4.6), layout="constrained")
    outcome_ax, acceleration_ax, distance_ax = figure.subplots(1, 3)
    bottom = np.zeros(len(planners))
    for label, test, colour in (("planned", lambda r: r["outcome"] == "planned" and not r["wrong"], "tab:green"),
                                ("refused", lambda r: r["outcome"] == "refused" and not r["wrong"], "tab:blue"),
                                ("wrong", lambda r: r["wrong"], "tab:red")):
        shares = np.array([np.mean([test(r) for r in rows if r["planner"] == name]) for name in planners])
        outcome_ax.bar(planners, shares, bottom=bottom, label=label, color=colour)
        bottom += shares
    outcome_ax.set_ylabel("share of tasks")
    outcome_ax.legend(fontsize="small")
    for ax, column, label, level in ((acceleration_ax, "acceleration_fraction", "peak |q̈| / limit", 1.0),
                                     (distance_ax, None, "least distance / clearance", 0.5)):
        data = []
        for name in planners:
            planned = [r for r in rows if r["planner"] == name and r["outcome"] == "planned" and r["least_distance_m"] != ""]
            data.append([float(r[column]) if column else float(r["least_distance_m"]) / float(r["clearance_m"])
                         for r in planned] or [np.nan])
        ax.boxplot(data, tick_labels=planners, whis=(0, 100))
        ax.axhline(level, color="grey", linestyle="--", label=f"{level:g}: the promise")
        ax.set_ylabel(label)
        ax.legend(fontsize="small")
    distance_ax.set_yscale("log")
    for ax in (outcome_ax, acceleration_ax, distance_ax):
        ax.tick_params(axis="x", rotation=45)
    arms = len({row["arm"] for row in rows})
    figure.suptitle(f"Soak: {len(rows)} seeded tasks on {arms} arm{'s' if arms > 1 else ''} (whiskers: best and worst)")
    return figure


def _write_csv(rows, path) -> None:
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=SOAK_COLUMNS)
        writer.writeheader()
        writer.writerows(rows)


TEXT_COLUMNS = ("arm", "planner", "outcome", "cause", "field", "diagnosis", "closed_loop", "message", "params", "rerun")


def read_soak_csv(path) -> list[dict]:
    """The rows of a soak.csv as :func:`soak_bench` returns them (numbers and booleans parsed;
    empty cells stay ""); BenchSetupError naming the file if it is not a soak's."""
    try:
        with open(path, newline="") as handle:
            rows = list(csv.DictReader(handle))
    except OSError as error:
        raise BenchSetupError(f"--merge: cannot read {path} ({error.strerror})") from None
    if not rows or tuple(rows[0]) != SOAK_COLUMNS:
        raise BenchSetupError(f"--merge: {path} is not a soak.csv of this version (its columns differ or it is empty)")
    for row in rows:
        for column, value in row.items():
            if column == "seed":
                row[column] = int(value)
            elif column in ("silent_wrong", "wrong"):
                row[column] = value == "True"
            elif column not in TEXT_COLUMNS and value != "":
                row[column] = float(value)
    return rows


def merge_soaks(out_dir, parts, *, progress=sys.stderr, overwrite: bool = False, command: str | None = None) -> list[dict]:
    """One report of soaks run in parts: the rows of every ``parts`` folder's soak.csv (each task
    once: a task in two parts is refused), written as :func:`soak_bench` writes one soak."""
    rows, seen = [], set()
    for part in parts:
        for row in read_soak_csv(Path(part) / SOAK_FILES[0]):
            key = (row["arm"], row["planner"], row["seed"])
            if key in seen:
                raise BenchSetupError(f"--merge: {part} has task {key} that an earlier part has too")
            seen.add(key)
            rows.append(row)
    with _claim_output_directory(out_dir, overwrite, command) as claimed:
        _write(claimed, out_dir, rows, None, progress)
    return rows


def _check(count, seed, arms, planners, workers, scheduler) -> None:
    """BenchSetupError naming the first argument of :func:`soak_bench` that cannot work."""
    _whole_number(count, "count", "--count", 1, MAX_COUNT)
    _whole_number(seed, "seed", "--seed", 0, 2**31 - MAX_COUNT)
    _check_where(workers, scheduler)
    for name, given, known in (("arms", arms, ARMS), ("planners", planners, DRAWS)):
        unknown = [value for value in given if value not in known]
        if unknown or not given:
            raise BenchSetupError(f"{name} (--{name}) must be some of {list(known)}, got {list(given)}")


def soak_bench(out_dir, *, count: int = 10, seed: int = 0, arms=SOAK_ARMS, planners=SOAK_PLANNERS,
               workers: int | None = None, scheduler: str | None = None, progress=sys.stderr, overwrite: bool = False,
               command: str | None = None) -> list[dict]:
    """Run the soak; writes soak.csv, soak.md and soak.png into ``out_dir``.

    Args:
        out_dir: output folder (as :func:`~drake_traj.bench.bench`'s).
        count: tasks per arm and planner (seeds ``seed`` ... ``seed + count - 1``).
        seed: the first task seed.
        arms, planners: the arms (:data:`~drake_traj.bench.soak_tasks.ARMS`) and planners
            (:data:`~drake_traj.bench.soak_tasks.DRAWS`) to soak.
        workers, scheduler: where the tasks run (:func:`~drake_traj.bench.bench`'s).
        progress: stream of the progress (None: none); prints the summary, the wrong rows' rerun
            commands and the files written.
        overwrite, command: as :func:`~drake_traj.bench.bench`'s.

    Returns:
        The rows (:data:`~drake_traj.bench.soak_suite.SOAK_COLUMNS`): arms, planners, seeds in order.
    """
    arms, planners = tuple(arms), tuple(planners)
    _check(count, seed, arms, planners, workers, scheduler)
    if workers is None and scheduler is None:
        workers = _default_workers()
    work = [(arm, planner, seed + k) for arm in arms for planner in planners for k in range(count)]
    with _claim_output_directory(out_dir, overwrite, command) as claimed:
        began = time.monotonic()
        bar = _Progress(len(work), progress, where(workers, scheduler), unit="task", bad="wrong",
                        failed=lambda row: row["wrong"])
        by_task = {}
        try:
            # a local cluster is made afresh for every LOCAL_CHUNK tasks (what pydrake leaks: release_system)
            size = len(work) if scheduler is not None else LOCAL_CHUNK
            for first in range(0, len(work), size):
                with _engine(workers, scheduler) as client:
                    _run(client, work[first:first + size], bar, by_task)
        except KeyboardInterrupt as stop:  # Ctrl-C or SIGTERM: the tasks done are written, then it goes on
            bar.close()
            rows = [by_task[unit] for unit in work if unit in by_task]
            stopped = f"stopped after {len(rows)} of {len(work)} tasks"
            if rows:
                _write(claimed, out_dir, rows, time.monotonic() - began, progress, stopped=stopped)
            stop.add_note(f"the soak {stopped}" + (f": their rows are in {Path(out_dir)} (a part for --merge)"
                                                   if rows else ", nothing written"))
            raise
        finally:
            bar.close()
        rows = [by_task[unit] for unit in work]
        _write(claimed, out_dir, rows, time.monotonic() - began, progress)
    return rows


def _write(claimed, out_dir, rows, wall: float | None, progress, stopped: str | None = None) -> None:
    """soak.csv, soak.md and soak.png of ``rows`` into the ``claimed`` folder; the summary and the
    files written on ``progress``. ``wall`` [s]: how long the tasks took (None: merged parts);
    ``stopped``: how far an interrupted soak got, said in soak.md's title."""
    text = markdown(rows, soak_summary(rows), wall, stopped)
    with claimed.replace() as staging:
        staging.write(SOAK_FILES[0], functools.partial(_write_csv, rows))
        staging.write(SOAK_FILES[1], lambda path: path.write_text(text))
        staging.write(SOAK_FILES[2], lambda path: soak_figure(rows).savefig(path, dpi=110))
    if progress is not None:
        print(text, file=progress)
        print(f"wrote {Path(out_dir)}: {', '.join(SOAK_FILES)}", file=progress)


def _failed(unit, reason: str) -> dict:
    """The row of a task whose worker died or could not load it."""
    return soak_row(unit, outcome="error", wrong=True, message=reason)


def _run(client, work, bar, rows: dict) -> None:
    """Each task of ``work`` run, in this process (``client`` None) or on Dask, its row put in
    ``rows`` {(arm, planner, seed): row} as it ends (an interrupt keeps those) and counted by the
    progress ``bar``."""
    if client is None:
        for unit in work:
            rows[unit] = bar.done(run_soak_task(*unit))
        return
    futures = {client.submit(run_soak_task, *unit, pure=False): unit for unit in work}
    _collect(futures, bar, lambda row: row, _failed, rows)
