"""The benchmark on a tiny set: its table is consistent, the same serially and on a Dask cluster,
a failing run is a row, and bad arguments stop it before any run (not a timing test)."""

import contextlib
import csv
import io
import logging
import math
import re
import socket
import warnings

import numpy as np
import pytest

from drake_traj import cli
from drake_traj.bench import engine, optimum, report, task_sets, units
from drake_traj.bench import run as bench_run
from drake_traj.planners import QuinticConfig


def broken_config(poses, joints):
    """An extra planner whose config cannot make a planner (a negative velocity limit)."""
    return QuinticConfig(goals=joints[1:].tolist(), velocity_limit=[-1.0] * 6)


@pytest.fixture(scope="module")
def rows(tmp_path_factory):
    """Serial run (``--workers 1``): the paper task and one random task."""
    out = tmp_path_factory.mktemp("bench")
    table = bench_run.bench(out, count=1, repeats=1, workers=1)
    with open(out / "bench.csv") as handle:
        assert len(list(csv.DictReader(handle))) == len(table)
    assert (out / "bench.md").read_text().startswith("## Paper task")
    assert (out / "bench.png").stat().st_size > 10_000
    return [row for row in table if row["task"] != "median"]


@pytest.fixture(scope="module")
def cluster_rows(tmp_path_factory):
    """The same two tasks on a two-worker Dask LocalCluster (Toppra, the Pająk run it depends on
    and a quick planner, to keep it short), with a planner that cannot be made."""
    out = tmp_path_factory.mktemp("bench_cluster")
    table = bench_run.bench(out, count=1, repeats=1, workers=2, planners=("pajak_blend", "quintic_stop", "toppra"),
                        extra_planners={"broken": broken_config})
    with open(out / "bench.csv") as handle:
        assert [row["failure"] for row in csv.DictReader(handle)] == [row["failure"] for row in table]
    return [row for row in table if row["task"] != "median"]


def same(a, b) -> bool:
    return a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b))


def test_a_cluster_run_equals_the_serial_run_apart_from_timings(rows, cluster_rows):
    ours = [row for row in cluster_rows if row["planner"] != "broken"]
    serial_rows = [row for row in rows if row["planner"] in ("pajak_blend", "quintic_stop", "toppra")]
    assert [(row["task"], row["planner"]) for row in ours] == [(row["task"], row["planner"]) for row in serial_rows]
    for serial, parallel in zip(serial_rows, ours):
        different = [column for column in units.COLUMNS
                     if column not in units.TIMING_COLUMNS and not same(serial[column], parallel[column])]
        assert not different, (serial, parallel)


def test_a_run_that_raises_is_a_failed_row_with_its_reason(cluster_rows):
    broken = [row for row in cluster_rows if row["planner"] == "broken"]
    assert [row["task"] for row in broken] == ["paper", "random_0"]
    for row in broken:
        assert not row["succeeded"] and math.isnan(row["T_s"]), row
        assert row["failure"].startswith("DrakeTrajError: velocity_limit"), row
    assert all(row["failure"] == "" for row in cluster_rows if row["planner"] != "broken")


def test_every_planner_ran_on_every_task(rows):
    assert {(row["task"], row["planner"]) for row in rows} == {
        (task, name) for task in ("paper", "random_0") for name in units.PLANNERS}
    assert all(row["succeeded"] for row in rows)


def test_no_planner_beats_the_time_optimal_bound_on_its_own_path(rows):
    # movej_blend breaks the acceleration limit in its blends, so it may beat the bound; Toppra's
    # grid is discrete: allow 2 % below the bound. NaN: Toppra found no parameterisation.
    assert all(np.isfinite(row["T_over_optimal"]) for row in rows if row["task"] == "paper")
    ratios = [row["T_over_optimal"] for row in rows if row["planner"] != "movej_blend"]
    assert np.nanmin(ratios) >= 0.98


def test_limits_where_promised_and_the_movej_blend_flaw(rows):
    for row in rows:
        if row["planner"] != "movej_blend":  # Toppra's too: its timing stretched where Drake's exceeds them
            assert row["max_qd_over_limit"] <= 1 + 1e-6, row
            assert row["max_qdd_over_limit"] <= 1 + 1e-6, row
    paper_movej = next(row for row in rows if row["task"] == "paper" and row["planner"] == "movej_blend")
    assert paper_movej["max_qdd_over_limit"] > 1.2  # blends superpose accelerations (paper: 2.48 vs 1.40)


def test_continuity_column(rows):
    by_name = {row["planner"]: row for row in rows if row["task"] == "paper"}
    assert by_name["pajak_blend"]["qdd_continuous"] and by_name["ruckig_stop"]["qdd_continuous"]
    assert by_name["smooth_waypoints"]["qdd_continuous"] and by_name["pajak_retimed"]["qdd_continuous"]
    assert by_name["smooth_waypoints"]["T_s"] < by_name["ruckig_stop"]["T_s"]  # 4.10 s against 5.53 s
    assert not by_name["movej_blend"]["qdd_continuous"]  # trapezoids step in acceleration


def test_random_tasks_are_reachable_and_seeded():
    first, again = task_sets.random_tasks(3, seed=7), task_sets.random_tasks(3, seed=7)
    for (q0, poses), (_, poses_again) in zip(first, again):
        np.testing.assert_array_equal(poses, poses_again)
        joints = task_sets.joint_waypoints(q0, poses)
        for q, pose in zip(joints[1:], poses):
            np.testing.assert_allclose(task_sets.robot.task_pose(q)[:3], pose[:3], atol=1e-9)


@pytest.mark.parametrize("arguments, option", [
    (["--count", "-3"], "--count"), (["--repeats", "0"], "--repeats"), (["--seed", "-1"], "--seed"),
    (["--workers", "0"], "--workers"), (["--scheduler", "not-an-address:xyz"], "--scheduler"),
    (["--workers", "2", "--scheduler", "tcp://127.0.0.1:8786"], "--workers"),
])
def test_bad_arguments_stop_before_any_run(tmp_path, capsys, arguments, option):
    out = tmp_path / "out"
    assert cli.main(["bench", "--out", str(out), *arguments]) == 2
    error = capsys.readouterr().err
    assert error.startswith("drake-traj: error: ") and option in error and "Traceback" not in error
    assert len(error.strip().splitlines()) == 1
    assert not out.exists()


def test_an_unreachable_scheduler_is_an_error_naming_the_option(tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    monkeypatch.setattr(engine, "SCHEDULER_TIMEOUT", 1.0)  # 10 s as shipped (tests/test_bounds.py)
    assert cli.main(["bench", "--out", str(out), "--scheduler", "tcp://127.0.0.1:1"]) == 2
    error = capsys.readouterr().err
    assert "--scheduler tcp://127.0.0.1:1: no Dask scheduler answered there" in error
    assert not out.exists()


def test_an_output_that_is_or_lies_below_a_file_is_refused(tmp_path, capsys):
    afile = tmp_path / "bench.csv"
    afile.write_text("keep me")
    for out in (afile, afile / "below"):
        assert cli.main(["bench", "--out", str(out), "--count", "0"]) == 2
        assert f"--out {out}" in capsys.readouterr().err
    assert afile.read_text() == "keep me"


def test_the_plot_has_the_task_count_in_its_title_and_a_legend_on_each_panel(rows, cluster_rows):
    figure = report.bench_figure(rows)
    assert figure.get_suptitle() == f"{len(units.PLANNERS)} planners on 2 UR10e tasks: Pająk 2024's and 1 seeded random ones"
    assert all(ax.get_legend() is not None for ax in figure.axes)
    # a box over fewer runs than tasks (a failed run has no value) says how many
    labels = [label.get_text() for label in report.bench_figure(cluster_rows).axes[0].get_xticklabels()]
    assert labels == ["pajak_blend", "quintic_stop", "toppra", "broken\n(0 of 2)"]


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_progress_without_a_terminal_is_a_line_at_a_time(monkeypatch):
    # a log or CI: no bar redrawn in place; a first line, then the runs done, failed and time left
    monkeypatch.setattr(engine, "LOG_INTERVAL", 0.0)  # a line after every run (8 s apart as shipped)
    stream = io.StringIO()
    progress = engine._Progress(4, stream, "in this process, one after another")
    progress.done({"succeeded": True})
    progress.done({"succeeded": False})
    progress.close()
    first, *lines, last = stream.getvalue().splitlines()
    assert first == "bench: 4 runs in this process, one after another"
    assert re.fullmatch(r"bench: 1/4 runs \(25 %\), 0 failed, 00:00 elapsed, about 00:00 left", lines[0]), lines
    assert re.fullmatch(r"bench: 2/4 runs \(50 %\), 1 failed, 00:00 elapsed, about 00:00 left", lines[1]), lines
    assert re.fullmatch(r"bench: 2/4 runs in 00:00, 1 failed", last)


def test_progress_on_a_terminal_is_a_bar_with_the_time_left():
    stream = Terminal()
    progress = engine._Progress(4, stream, "on a local Dask cluster of 2 processes")
    progress.done({"succeeded": False})
    progress.close()
    text = stream.getvalue()
    assert text.startswith("bench: 4 runs on a local Dask cluster of 2 processes\n")
    assert re.search(r"bench:  25%.*\| 1/4 \[00:00<00:00, .*failed=1\]", text), text  # [elapsed<left]


def test_a_bench_names_what_it_wrote(tmp_path, capsys):
    out = tmp_path / "out"
    bench_run.bench(out, count=0, repeats=1, workers=1, planners=("quintic_stop",), progress=None)
    assert capsys.readouterr().out.splitlines()[-1] == f"wrote {out}: bench.csv, bench.md, bench.png"


def test_the_local_cluster_serves_http_on_a_free_port_without_a_warning():
    # Dask's default HTTP port 8787 taken (another cluster, a notebook): no "Port 8787 is already in use"
    with socket.socket() as taken, warnings.catch_warnings():
        warnings.simplefilter("error")
        with contextlib.suppress(OSError):  # already taken is as good
            taken.bind(("127.0.0.1", 8787))
            taken.listen()
        with engine._engine(2, None) as client:
            assert client.submit(sum, [1, 2]).result() == 3
            assert client.scheduler_info()["services"].get("dashboard") != 8787  # a free port, not Dask's default


def independent_optimal_time(path, velocity: float, acceleration: float, points: int = 3000) -> float:
    """Time-optimal duration along ``path`` (a Drake trajectory q(s)) from rest to rest under
    |q̇_j| <= velocity, |q̈_j| <= acceleration, by the classic numerical integration on x = ṡ²
    (forward at the largest s̈, backward at the smallest, under the maximum-velocity curve found
    by bisection): our own computation, not Drake's Toppra."""
    s = np.linspace(path.start_time(), path.end_time(), points)
    step = s[1] - s[0]
    first = np.array([path.EvalDerivative(x, 1).ravel() for x in s])
    second = np.array([path.EvalDerivative(x, 2).ravel() for x in s])
    moving = np.abs(first) > 1e-12

    def accelerations(x, at=slice(None)):
        """(lowest, highest) s̈ at the grid points ``at`` for ṡ² = x (q̈ = q' s̈ + q'' x)."""
        slope, bias, free = first[at], second[at] * np.asarray(x)[..., None], moving[at]
        with np.errstate(divide="ignore", invalid="ignore"):
            upper = np.where(free, (np.sign(slope) * acceleration - bias) / slope, np.inf)
            lower = np.where(free, (-np.sign(slope) * acceleration - bias) / slope, -np.inf)
        blocked = np.any(~free & (np.abs(bias) > acceleration), axis=-1)
        return np.where(blocked, np.inf, lower.max(axis=-1)), np.where(blocked, -np.inf, upper.min(axis=-1))

    with np.errstate(divide="ignore"):
        ceiling = np.min(np.where(moving, (velocity / np.abs(first)) ** 2, np.inf), axis=1)
    low, high = np.zeros(points), ceiling.copy()
    for _ in range(60):  # the largest x with an admissible s̈ (the feasible x form an interval from 0)
        middle = 0.5 * (low + high)
        lowest, highest = accelerations(middle)
        feasible = lowest <= highest
        low, high = np.where(feasible, middle, low), np.where(feasible, high, middle)
    ceiling = low
    x = np.zeros(points)
    for k in range(points - 1):  # accelerate
        x[k + 1] = min(ceiling[k + 1], x[k] + 2 * step * max(accelerations(x[k], k)[1], 0.0))
    x[-1] = 0.0
    for k in range(points - 1, 0, -1):  # decelerate
        x[k - 1] = min(x[k - 1], x[k] - 2 * step * min(accelerations(x[k], k)[0], 0.0))
    rates = np.sqrt(np.maximum(x, 0.0))
    return float(np.sum(2 * step / (rates[1:] + rates[:-1])))


def test_the_optimal_and_jerk_columns_against_our_own_computation():
    # pajak_blend on the paper task: T_over_optimal is T over the time-optimal T along its own
    # path (Toppra in the bench; here our own integration on ṡ², same spline of the path), and
    # max_jerk the largest rate of change of the reference q̈ (here third differences of q)
    task = task_sets.tasks(count=0, repeats=1)[0]
    output = units.run_planner(task, "pajak_blend", units.CONFIG_BUILDERS["pajak_blend"], keep_path=True)
    row, path = output["row"], output["path"]
    optimal = independent_optimal_time(optimum.geometric_path_from_samples(path), optimum.VELOCITY, optimum.ACCELERATION)
    assert row["T_over_optimal"] == pytest.approx(row["T_s"] / optimal, rel=0.01)
    assert row["optimal_failure"] == ""
    jerk = np.abs(np.diff(path, 3, axis=0)).max() / 1e-3**3
    assert row["max_jerk"] == pytest.approx(jerk, rel=0.01)


def test_a_path_toppra_cannot_parameterise_gives_its_reason_not_a_log_line(capfd):
    # task 69 of the Pająk sweep's 0.7 rad set: Drake's Toppra fails on the 200-knot spline of the
    # law's own path (it logs "Toppra failed to find the maximum path acceleration at knot ..."
    # through spdlog); optimal_duration then tries coarser splines of the same samples
    task = task_sets.pajak_walk_tasks(70, seed=9, step=0.7)[69]
    result = task_sets.pajak.integrate(task_sets.pajak.PajakLaw(task), task_sets.pajak.paper_initial_configuration())
    q, qd = result["q"][: result["finish_index"] + 1], result["qd"][: result["finish_index"] + 1]
    drake_log = logging.getLogger("drake")
    handlers, propagate = list(drake_log.handlers), drake_log.propagate
    with pytest.raises(ValueError) as info:
        optimum.time_optimal_along_path(optimum.geometric_path_from_samples(q, max_knots=200), task.velocity_limit,
                                      task.acceleration_limit)
    assert "Toppra failed to find the maximum path acceleration at knot" in str(info.value)
    printed = capfd.readouterr()
    assert "Toppra failed" not in printed.err + printed.out
    assert drake_log.handlers == handlers and drake_log.propagate == propagate  # the logger as it was
    optimal, reason = optimum.optimal_duration(q, qd, task.velocity_limit, task.acceleration_limit)
    assert reason == "" and 1.0 < result["T"] / optimal < 2.0


def test_every_missing_optimum_has_its_reason(rows):
    for row in rows:
        if row["succeeded"]:
            assert (row["optimal_failure"] == "") == bool(np.isfinite(row["T_over_optimal"])), row


def test_the_optimum_of_a_stop_and_go_path_is_the_sum_of_its_moves():
    # two straight moves with a corner between them, sampled at 1 ms with the stop between two
    # samples (none at rest, as Ruckig's): the optimum stops at the corner,
    # and on a straight line it is bang-bang along the path, known in closed form
    velocity, acceleration = np.array([1.0, 0.5]), np.array([2.0, 1.0])
    legs = [np.array([0.8, 0.3]), np.array([-0.2, 0.6])]

    def straight(leg):  # rest-to-rest time-optimal duration along a straight leg
        length = np.linalg.norm(leg)
        direction = np.abs(leg) / length
        speed, rate = np.min(velocity / direction), np.min(acceleration / direction)
        return 2 * np.sqrt(length / rate) if length < speed**2 / rate else length / speed + speed / rate

    first = round(1.5 * straight(legs[0]), 3) + 5e-4  # the corner 0.5 ms after a sample
    durations = [first, 1.5 * straight(legs[1])]
    t = np.arange(0.0, sum(durations) + 1e-3, 1e-3)
    q, qd = np.zeros((len(t), 2)), np.zeros((len(t), 2))
    for leg, offset, duration, origin in zip(legs, (0.0, first), durations, (np.zeros(2), legs[0])):
        local = np.clip(t - offset, 0.0, duration)
        inside = (t >= offset) & (t <= offset + duration)
        q += np.where(inside[:, None], origin + np.outer(0.5 - 0.5 * np.cos(np.pi * local / duration), leg), 0.0)
        qd += np.where(inside[:, None], np.outer(0.5 * np.pi / duration * np.sin(np.pi * local / duration), leg), 0.0)
    q[t > sum(durations)] = legs[0] + legs[1]
    corner = np.searchsorted(t, first)
    speed = np.linalg.norm(qd, axis=1)[corner - 1 : corner + 1]
    assert np.all((speed > 1e-6) & (speed < optimum.STOP_SPEED))  # no sample at rest at the corner
    optimal, reason = optimum.optimal_duration(q, qd, velocity, acceleration)
    assert reason == ""
    assert optimal == pytest.approx(straight(legs[0]) + straight(legs[1]), rel=2e-3)
