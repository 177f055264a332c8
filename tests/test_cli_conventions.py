"""The command line's conventions: progress on stderr however the output is kept (and --quiet),
a list without Drake, global options before or after the command, "did you mean" for names,
variants, robots and fields, and Ctrl-C clean at any moment, from the command line and from
Python (the run so far kept)."""

import io
import json
import os
import pickle
import re
import signal
import subprocess
import sys
import threading
import time
from dataclasses import fields

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from drake_traj import catalogue, cli
from drake_traj.cli import commands, progress
from drake_traj.errors import Cause, Failure, did_you_mean, interrupt_in, reraise_interrupt
from drake_traj.planners.quintic import QuinticPtpPlanner, plan_synchronized_quintic
from drake_traj.results import SimulationResult
from drake_traj.robots import UR10E, get_robot
from drake_traj.robots.custom import robot_label
from drake_traj.scenario import Scenario, load_scenario, make_planner, shipped_scenarios
from drake_traj.station import build_station, run_station, simulate

from conftest import DIAGRAMS, interrupt_inside_compiled_code

PROGRESS_LINE = re.compile(r"^drake-traj (run|bench): ")


class FakeClock:
    def __init__(self):
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def quintic_ptp_total() -> float:
    """The simulated time a run of quintic_ptp takes [s]: its planned motion and settle time."""
    scenario = load_scenario("quintic_ptp")
    return make_planner(scenario).planned_duration() + scenario.settle_time


# ---- progress -----------------------------------------------------------------------------------

def test_a_progress_line_comes_after_each_interval_of_silence_with_the_time_left():
    clock, stream = FakeClock(), io.StringIO()
    bar = progress.Progress("run", stream=stream, interval=10.0, clock=clock)
    bar.stage("checking the task in the cell")
    clock.now += 9.9
    bar.tick()
    assert stream.getvalue() == ""  # not yet 10 s of silence
    clock.now += 0.1
    bar.tick()
    assert stream.getvalue() == "drake-traj run: checking the task in the cell, 10 s elapsed\n"
    bar.expect(6.0)
    clock.now += 2.0  # 12 s: the simulation starts
    bar.simulated(0.01)
    clock.now += 8.0  # 20 s: 3 s of 6 simulated in 8 s, so 3 s more take 8 s
    bar.simulated(3.0)
    bar.tick()
    assert stream.getvalue().splitlines()[-1] == ("drake-traj run: simulating, 3.00 of 6.00 s simulated (50 %), 20 s "
                                                  "elapsed, about 8 s left")
    bar.tick()  # said just now
    assert len(stream.getvalue().splitlines()) == 2
    clock.now += 200.0
    bar.stage("writing the run's files")
    bar.tick()
    assert stream.getvalue().splitlines()[-1] == "drake-traj run: writing the run's files, 03:40 elapsed"
    bar.close()
    bar.close()  # a second close is no error


def test_quiet_progress_says_nothing():
    clock, stream = FakeClock(), io.StringIO()
    bar = progress.Progress("run", stream=stream, enabled=False, clock=clock)
    bar.stage("planning")
    clock.now += 1000.0
    bar.tick()
    bar.close()
    assert stream.getvalue() == ""


def test_the_background_thread_speaks_while_the_command_is_busy_and_stops_when_closed():
    stream = io.StringIO()
    bar = progress.Progress("run", stream=stream, interval=0.02)
    bar.stage("loading Drake and the planners")
    deadline = time.monotonic() + 30.0
    while stream.getvalue().count("\n") < 2 and time.monotonic() < deadline:  # busy in one long step
        time.sleep(0.01)
    bar.close()
    said = stream.getvalue()
    assert said.count("drake-traj run: loading Drake and the planners, ") >= 2, said
    time.sleep(0.1)
    assert stream.getvalue() == said  # nothing after close
    assert not [thread for thread in threading.enumerate() if thread.name == "drake-traj progress"]


def test_run_says_its_stages_and_simulated_time_in_a_log_and_quiet_silences_it(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(progress, "LOG_INTERVAL", 0.02)
    assert cli.main(["run", "quintic_ptp", "--out", str(tmp_path / "said")]) == cli.EXIT_OK
    lines = [line for line in capsys.readouterr().err.splitlines() if PROGRESS_LINE.match(line)]
    stages = list(dict.fromkeys(line.split(": ")[1].split(",")[0] for line in lines))
    assert stages.index("simulating") < stages.index("writing the run's files"), stages
    total = quintic_ptp_total()
    simulated = [re.search(r"simulating, ([\d.]+) of ([\d.]+) s simulated", line) for line in lines]
    simulated = [(float(match[1]), float(match[2])) for match in simulated if match]
    assert simulated and all(of == pytest.approx(total, abs=0.005) and 0 <= t <= of for t, of in simulated)
    assert [t for t, _ in simulated] == sorted(t for t, _ in simulated)
    assert cli.main(["run", "quintic_ptp", "--out", str(tmp_path / "quiet"), "--quiet"]) == cli.EXIT_OK
    assert not [line for line in capsys.readouterr().err.splitlines() if PROGRESS_LINE.match(line)]


@pytest.mark.parametrize("argv, stream", [(["bench"], "stderr"), (["bench", "--quiet"], None), (["-q", "bench"], None)])
def test_bench_says_its_own_progress_unless_quiet(argv, stream, tmp_path, monkeypatch):
    given = {}
    monkeypatch.setattr(commands, "bench", lambda out, **arguments: given.update(arguments))
    assert cli.main([*argv, "--out", str(tmp_path / "b"), "--count", "0"]) == cli.EXIT_OK
    assert given["progress"] is (sys.stderr if stream else None)


# ---- list without Drake, the catalogue ------------------------------------------------------------

def test_list_imports_neither_drake_nor_numpy():
    code = ("import sys\nfrom drake_traj import cli\ncode = cli.main(['list'])\n"
            "heavy = sorted(m for m in sys.modules if m.split('.')[0] in ('pydrake', 'numpy', 'numba', 'matplotlib'))\n"
            "print('imported:', heavy, 'exit', code)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.stdout.splitlines()[-1] == "imported: [] exit 0", done
    assert "pajak_sim3" in done.stdout


def test_the_catalogue_says_what_loading_each_shipped_scenario_says():
    entries = shipped_scenarios()
    assert len(entries) == len({entry.name for entry in entries}) > 20
    for entry in entries:
        scenario = load_scenario(entry.path, entry.variant)
        assert (entry.name, entry.description, entry.robot) == (scenario.name, scenario.description,
                                                                 robot_label(scenario.robot))
        assert scenario.source.variant == entry.variant
    assert catalogue.SCENARIO_FIELDS == tuple(item.name for item in fields(Scenario))
    assert (catalogue.DEFAULT_NAME, catalogue.DEFAULT_ROBOT) == (Scenario().name, Scenario().robot)


def test_the_catalogue_reads_a_file_of_one_scenario_and_one_of_variants(tmp_path, monkeypatch):
    (tmp_path / "one.yaml").write_text("planner: !QuinticConfig\n  goals: [[0, 0, 0, 0, 0, 0]]\n")
    (tmp_path / "two.yaml").write_text("_arm: &arm {name: mine, dh: []}\n"
                                       "a: {name: first, robot: !DhArm {<<: *arm}, description: the first}\n"
                                       "b: {name: second, robot: ur5e}\n")
    monkeypatch.setattr(catalogue, "shipped_directory", lambda: tmp_path)
    assert [(entry.path.name, entry.variant, entry.name, entry.robot, entry.description)
            for entry in catalogue.shipped_scenarios()] == [
        ("one.yaml", None, "unnamed", "ur10e", ""), ("two.yaml", "a", "first", "mine (DhArm)", "the first"),
        ("two.yaml", "b", "second", "ur5e", "")]


# ---- global options anywhere ----------------------------------------------------------------------

@pytest.mark.parametrize("argv, debug, quiet", [
    (["run", "x.yaml"], False, False),
    (["--debug", "run", "x.yaml"], True, False),
    (["run", "x.yaml", "--debug"], True, False),
    (["--quiet", "run", "x.yaml", "--debug"], True, True),
    (["run", "--quiet", "x.yaml"], False, True),
    (["-q", "bench", "--debug"], True, True),
])
def test_global_options_go_before_or_after_the_command(argv, debug, quiet):
    for parser in (cli.build_parser(), cli.build_parser(commands.OPTIONS)):
        args, _ = parser.parse_known_args(argv)
        assert (args.debug, args.quiet) == (debug, quiet), (argv, parser)


def test_debug_after_the_command_shows_the_traceback(tmp_path, capsys):
    assert cli.main(["run", str(tmp_path / "typo.yaml"), "--debug"]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err and "not found" in err


# ---- did you mean ---------------------------------------------------------------------------------

def test_did_you_mean_names_the_closest_and_nothing_when_none_is_close():
    assert did_you_mean("gaols", ["acceleration_limit", "goals", "velocity_limit"]) == "did you mean 'goals'?"
    assert did_you_mean("QuinticConfg", ["PajakConfig", "QuinticConfig"], tags=True) == "did you mean !QuinticConfig?"
    assert did_you_mean("sim4", ["sim1", "sim2", "ur5e"]) == "did you mean 'sim2' or 'sim1'?"
    assert did_you_mean("nosuch", ["pajak_sim3", "quintic_ptp"]) == ""
    assert did_you_mean(None, ["ur10e"]) == ""


def test_a_misspelt_scenario_name_gets_a_suggestion(capsys):
    assert cli.main(["run", "quintic_pt"]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert err.startswith("drake-traj: error: no scenario file 'quintic_pt' and no shipped scenario of that name; "
                          "shipped: ") and err.endswith(" (drake-traj list); did you mean 'quintic_ptp'?\n"), err


def test_a_misspelt_variant_and_robot_get_a_suggestion():
    with pytest.raises(ValueError, match=r"there is no variant 'ur5'; its variants are \[.*\]; did you mean 'ur5e'"):
        load_scenario("pajak", "ur5")
    with pytest.raises(ValueError, match=r"robot must be one of the known robots, got 'ur5'; known: .*; "
                                         r"did you mean 'ur5e'"):
        get_robot("ur5")


@pytest.mark.parametrize("text, pattern", [
    ("planner: !QuinticConfig\n  gaols: [[0, 0, 0, 0, 0, 0]]\n",
     r"line 2, column 3: planner.gaols: unknown field \(did you mean 'goals'\?\); QuinticConfig has"),
    ("planner: !QuinticConfg\n  goals: [[0, 0, 0, 0, 0, 0]]\n",
     r"planner: unknown type !QuinticConfg; expected one of .* \(did you mean !QuinticConfig\?\)"),
    ("settle_tim: 0.5\nplanner: !QuinticConfig\n  goals: [[0, 0, 0, 0, 0, 0]]\n",
     r"line 1, column 1: settle_tim: unknown field \(did you mean 'settle_time'\?\)"),
    ("robot: ur1oe\nplanner: !QuinticConfig\n  goals: [[0, 0, 0, 0, 0, 0]]\n",
     r"line 1, column 8: robot: robot must be one of the known robots, got 'ur1oe'; .*did you mean .*'ur10e'"),
])
def test_a_misspelt_field_tag_or_robot_in_a_scenario_file_gets_a_suggestion(text, pattern, tmp_path):
    path = tmp_path / "typo.yaml"
    path.write_text(text)
    with pytest.raises(ValueError, match=pattern):
        load_scenario(path)


# ---- Ctrl-C from Python ---------------------------------------------------------------------------

def short_quintic() -> QuinticPtpPlanner:
    """A move of every joint by 0.3 rad from home (about 1 s), a new planner system each call."""
    home = UR10E.home_configuration
    return QuinticPtpPlanner(plan_synchronized_quintic(home, [home + 0.3], 1.05, 1.4), 1.05, 1.4)


def interrupt_at(stop_time: float):
    """A ``progress(t)`` that raises KeyboardInterrupt (as Ctrl-C would) once ``t`` reaches ``stop_time``."""
    def progress_hook(t):
        if t >= stop_time:
            raise KeyboardInterrupt
    return progress_hook


def test_ctrl_c_in_simulate_stops_the_script_with_the_run_so_far(tmp_path):
    with pytest.raises(KeyboardInterrupt) as caught:
        simulate(short_quintic(), progress=interrupt_at(0.3), settle_time=0.1)
    stop = caught.value
    assert type(stop) is KeyboardInterrupt  # as any Ctrl-C: Python's exit on it stays the same
    result = stop.result
    assert result.failure == stop.failure and result.failure.cause is Cause.INTERRUPTED and not result.succeeded
    assert 0.3 <= stop.failure.time < 0.3 + 0.011  # the first 10 ms chunk past 0.3 s
    assert result.t[-1] == pytest.approx(stop.failure.time, abs=2e-3) and result.t[0] == 0.0
    assert stop.__notes__ == [f"interrupted at t = {stop.failure.time:.4f} s: the run so far is this KeyboardInterrupt's "
                              ".result (a failed run; .result.save(folder) keeps it)"]
    result.save(tmp_path / "partial")  # kept as a failed run is
    assert SimulationResult.load(tmp_path / "partial").failure.cause is Cause.INTERRUPTED
    again = pickle.loads(pickle.dumps(stop))  # e.g. from a Dask worker
    assert again.failure == stop.failure and np.array_equal(again.result.t, result.t)


def test_ctrl_c_in_run_station_raises_with_the_failure_and_the_log_in_the_loggers():
    station = build_station(short_quintic())
    simulator = Simulator(station)
    with pytest.raises(KeyboardInterrupt) as caught:
        run_station(simulator, station, settle_time=0.1, progress=interrupt_at(0.2))
    assert not hasattr(caught.value, "result") and caught.value.failure.cause is Cause.INTERRUPTED
    result = SimulationResult.from_station(station, simulator.get_context(), failure=caught.value.failure)
    assert result.t[-1] == pytest.approx(caught.value.failure.time, abs=2e-3)


def test_an_interrupt_that_came_as_compiled_code_returned_is_found_and_raised():
    with pytest.raises(SystemError) as caught:
        interrupt_inside_compiled_code()
    stop = interrupt_in(caught.value)
    assert type(stop) is KeyboardInterrupt and stop is caught.value.__cause__
    with pytest.raises(KeyboardInterrupt):
        reraise_interrupt(caught.value)
    plain = RuntimeError("a planner's own failure")
    assert interrupt_in(plain) is None and reraise_interrupt(plain) is None


def test_an_interrupt_that_came_as_compiled_code_returned_stops_the_run_as_ctrl_c_does():
    def progress_hook(t):
        if t >= 0.2:
            interrupt_inside_compiled_code()
    station = build_station(short_quintic())
    with pytest.raises(KeyboardInterrupt) as caught:  # not a failed run with a SystemError: the stop stops
        run_station(Simulator(station), station, settle_time=0.1, progress=progress_hook)
    assert caught.value.failure.cause is Cause.INTERRUPTED and 0.2 <= caught.value.failure.time < 0.211
    with pytest.raises(KeyboardInterrupt):
        simulate(short_quintic(), progress=progress_hook, settle_time=0.1)


SCRIPT = """
import sys
from drake_traj import load_scenario, simulate

def started(t):
    if t > 0.05 and not getattr(started, "said", False):
        started.said = True
        print("simulating", flush=True)

try:
    simulate(load_scenario(sys.argv[1]), progress=started)
except KeyboardInterrupt as stop:
    stop.result.save(sys.argv[2])
    raise
print("carried on")
"""


def real_time_scenario(folder) -> str:
    """quintic_ptp simulated in real time (6.7 s), time enough to interrupt it while it moves."""
    path = folder / "slow.yaml"
    path.write_text((DIAGRAMS / "quintic_ptp.yaml").read_text() + "simulator:\n  target_realtime_rate: 1.0\n")
    return str(path)


def test_ctrl_c_stops_a_python_script_that_keeps_the_partial_result(tmp_path):
    process = subprocess.Popen([sys.executable, "-c", SCRIPT, real_time_scenario(tmp_path), str(tmp_path / "partial")],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert process.stdout.readline() == "simulating\n"
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=120)
    finally:
        process.kill()
    assert process.returncode == -signal.SIGINT and "carried on" not in out  # Python's exit on Ctrl-C
    assert err.splitlines()[-2] == "KeyboardInterrupt"
    assert re.fullmatch(r"interrupted at t = [\d.]+ s: the run so far is this KeyboardInterrupt's .result \(.*\)",
                        err.splitlines()[-1])
    partial = SimulationResult.load(tmp_path / "partial")
    assert partial.failure.cause is Cause.INTERRUPTED and 0.05 < partial.failure.time < 6.0


# ---- Ctrl-C and SIGTERM on the command line -------------------------------------------------------

def interrupting(signum: int, stop_time: float):
    """Progress.simulated that sends ``signum`` to this process once the simulation reaches ``stop_time``."""
    simulated = progress.Progress.simulated

    def send(self, t):
        simulated(self, t)
        if t >= stop_time:
            os.kill(os.getpid(), signum)
    return send


@pytest.fixture
def python_signal_handlers():
    """Python's own Ctrl-C and SIGTERM handlers, as a console script has them (a test runner's
    worker may ignore Ctrl-C), put back after the test."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler), signal.signal(signal.SIGTERM, signal.SIG_DFL)
    yield
    signal.signal(signal.SIGINT, previous[0])
    signal.signal(signal.SIGTERM, previous[1])


@pytest.mark.parametrize("signum, code, said", [(signal.SIGINT, cli.EXIT_INTERRUPTED, "interrupted"),
                                                (signal.SIGTERM, cli.EXIT_TERMINATED, "terminated (SIGTERM)")])
def test_a_run_stopped_while_it_simulates_writes_what_it_logged(signum, code, said, tmp_path, monkeypatch, capsys,
                                                                python_signal_handlers):
    monkeypatch.setattr(progress.Progress, "simulated", interrupting(signum, 1.0))
    out = tmp_path / "stopped"
    assert cli.main(["run", "quintic_ptp", "--out", str(out), "--quiet"]) == code
    err = capsys.readouterr().err.splitlines()
    failure = json.loads((out / "run.json").read_text())["failure"]
    assert failure["cause"] == "interrupted" and 1.0 <= failure["time"] < 1.02
    assert err == [f"drake-traj: the run stopped at t = {failure['time']:.3f} s; what it logged is in {out}",
                   f"drake-traj: {said}"]
    result = SimulationResult.load(out)
    assert result.failure.cause is Cause.INTERRUPTED and result.t[-1] == pytest.approx(failure["time"], abs=2e-3)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL


def other_lines(err: str) -> list[str]:
    return [line for line in err.splitlines() if not PROGRESS_LINE.match(line)]


@pytest.mark.parametrize("delay", [0.5, 5.0])
def test_ctrl_c_at_any_moment_is_one_line_and_exit_130(delay, tmp_path):
    # 0.5 s: Drake and numba are being imported; 5 s: planning, checking or simulating
    out = tmp_path / "out"
    process = subprocess.Popen([sys.executable, "-m", "drake_traj.cli", "run", real_time_scenario(tmp_path),
                                "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        time.sleep(delay)
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=120)
    finally:
        process.kill()
    assert process.returncode == cli.EXIT_INTERRUPTED, err
    lines = other_lines(err)
    assert lines[-1] == "drake-traj: interrupted" and len(lines) <= 2, err
    if (out / "run.json").exists():  # it was simulating: what it logged is kept
        assert json.loads((out / "run.json").read_text())["failure"]["cause"] == "interrupted"
        assert lines[0].startswith("drake-traj: the run stopped at t = ")
    else:
        assert len(lines) == 1 and not (out / "result.npz").exists()
