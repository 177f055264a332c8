"""The bench's report: bench.csv (every row, then the medians over the seeded tasks), bench.md
(the paper task's rows and the medians as Markdown tables) and bench.png (:func:`bench_figure`),
written whole into the bench's claimed folder."""

import csv
import functools

import numpy as np

from drake_traj.bench.units import COLUMNS, JUMP

__all__ = ["bench_figure", "medians"]

BENCH_FILES = ("bench.csv", "bench.md", "bench.png")  # what a bench writes into its folder
BENCH_SIZE = 4 * 2**20  # [bytes] about what bench.csv, bench.md and bench.png take, rounded up


def write_report(claimed, rows, count) -> tuple[list[dict], str]:
    """Write :data:`BENCH_FILES` of the runs' ``rows`` (``count`` seeded tasks besides the paper
    task) into the ``claimed`` folder (:class:`drake_traj.results.Claim`): written aside, they
    replace the folder's earlier content once all are written; returns the table (the rows, then
    the medians over the seeded tasks) and bench.md's text."""
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
