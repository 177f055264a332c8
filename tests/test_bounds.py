"""Bounded, honest and clear (beside tests/test_bad_input.py): every run, preflight, bench
and live view ends within stated limits or is refused naming the input; a result of a station
that has not finished is not a success; the live view keeps the scenario's speed profile; the
public station functions, a busy port, shipped names with --variant and a variant's shallow
YAML merge get clear messages."""

import json
import re
import socket
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.systems.analysis import Simulator, SimulatorConfig
from pydrake.systems.framework import Diagram, DiagramBuilder

from drake_traj import Cause, DrakeTrajError, PlanningError, SimulationResult, cli, load_scenario, make_planner, simulate
from drake_traj.bench import engine as bench_module
from drake_traj.data import data_directory
from drake_traj.station import SPEED_SLIDER, SpeedSlider, add_station, build_station, make_station, run_station, start_meshcat
from drake_traj.planners.pajak.system import MAX_PREFLIGHT_STEPS, PajakPlanner
from drake_traj.planners.quintic import QuinticPtpPlanner, plan_synchronized_quintic
from drake_traj.robots import UR10E
from drake_traj.scenario import ScenarioError, SpeedOverride, find_scenario, preflight
from drake_traj.validation import MAX_RUN_DURATION, MAX_SETTLE_TIME, REALTIME_RATES

DIAGRAMS = Path(__file__).resolve().parents[1] / "diagrams"
QUINTIC = (DIAGRAMS / "quintic_ptp.yaml").read_text()
PAJAK = (DIAGRAMS / "pajak.yaml").read_text()


def quintic(old: str, new: str) -> str:
    """The shipped quintic scenario with one text replaced (which must be there)."""
    assert old in QUINTIC, old
    return QUINTIC.replace(old, new, 1)


def short_planner() -> QuinticPtpPlanner:
    """A 10 mrad move of every joint from home (0.1 s of motion), a new planner system each call."""
    home = UR10E.home_configuration
    return QuinticPtpPlanner(plan_synchronized_quintic(home, [home + 0.01], 1.05, 1.4), 1.05, 1.4)


def clean_refusal(code: int, capsys, pattern: str) -> str:
    """Exit 2 with one paragraph starting ``drake-traj:`` matching ``pattern``, no traceback."""
    err = capsys.readouterr().err
    assert code == cli.EXIT_BAD_INPUT, err
    assert err.startswith("drake-traj: ") and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert re.search(pattern, err), err
    return err


# --- bounds: bench ------------------------------------------------------------------------------


def test_bench_workers_are_at_most_the_cores(tmp_path, capsys):
    cores = bench_module._default_workers()
    for workers in (100000, cores + 1):
        code = cli.main(["bench", "--workers", str(workers), "--count", "0", "--out", str(tmp_path / "b")])
        clean_refusal(code, capsys, rf"--workers\) must be a whole number from 1 to {cores} \(this machine's cores.*"
                                    rf"got {workers}")
    assert not (tmp_path / "b").exists()


@pytest.fixture
def listener():
    """A plain TCP socket on a loopback port, not Dask: ``silent`` accepts and never answers,
    ``chatty`` answers like a web server; yields ``start(kind) -> address``."""
    servers, connections = [], []

    def start(kind: str) -> str:
        server = socket.socket()
        server.bind(("127.0.0.1", 0))
        server.listen()
        servers.append(server)

        def serve():
            while True:
                try:
                    connection, _ = server.accept()
                except OSError:
                    return
                connections.append(connection)
                if kind == "chatty":
                    connection.sendall(b"HTTP/1.1 200 OK\r\nContent-Length: 5\r\n\r\nhello")

        threading.Thread(target=serve, daemon=True).start()
        return f"tcp://127.0.0.1:{server.getsockname()[1]}"

    yield start
    for item in servers + connections:
        item.close()


def free_loopback_address() -> str:
    """The address of a loopback port where nothing listens."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return f"tcp://127.0.0.1:{probe.getsockname()[1]}"


@pytest.mark.parametrize("kind, pattern", [
    ("silent", r"did not answer as a Dask scheduler within 1 s"),
    ("chatty", r"does not speak Dask's protocol"),
    ("nothing", r"no Dask scheduler answered there .*waited at most 1 s"),
])
def test_a_scheduler_that_is_not_dask_is_refused_in_time(kind, pattern, listener, monkeypatch, tmp_path, capsys):
    # the stated timeout is 10 s (README); 1 s here keeps the test short, the same code path
    assert bench_module.SCHEDULER_TIMEOUT == 10.0
    monkeypatch.setattr(bench_module, "SCHEDULER_TIMEOUT", 1.0)
    address = free_loopback_address() if kind == "nothing" else listener(kind)
    start = time.monotonic()
    code = cli.main(["bench", "--scheduler", address, "--count", "0", "--out", str(tmp_path / "b")])
    elapsed = time.monotonic() - start
    err = clean_refusal(code, capsys, pattern)
    assert f"--scheduler {address}:" in err
    assert elapsed < 5.0, elapsed  # Dask alone waits for a silent peer's handshake forever
    assert not (tmp_path / "b").exists()


# --- bounds: times and pace ---------------------------------------------------------------------


@pytest.mark.parametrize("old, new, pattern", [
    ("settle_time: 0.5", "settle_time: 0.5\nmax_duration: 1.0e9", r"line 21, column 15: max_duration must be at most 600 s"),
    ("  time_step: 0.001", "  time_step: 1.0e-9", r"line 19, column 14: plant.time_step must be at least 1e-05 s"),
    ("settle_time: 0.5", "settle_time: 0.5\nsimulator:\n  max_step_size: 1.0e-9",
     r"line 22, column 18: simulator.max_step_size must be at least 1e-05 s"),
    ("settle_time: 0.5", "settle_time: 1.0e5", r"line 20, column 14: settle_time must be at most 60 s after the planner finishes"),
    ("settle_time: 0.5", "settle_time: 0.5\nsimulator:\n  target_realtime_rate: 1.0e-9",
     r"line 22, column 25: simulator.target_realtime_rate must be 0 \(as fast as it goes\) or from 0.1 to 1000 times"),
])
def test_run_times_and_pace_out_of_range_are_located(old, new, pattern, tmp_path):
    path = tmp_path / "scenario.yaml"
    path.write_text(quintic(old, new))
    with pytest.raises(ScenarioError, match=re.escape(str(path)) + ", " + pattern) as info:
        load_scenario(path)
    assert info.value.field[0] in ("max_duration", "settle_time", "simulator", "plant")


def test_the_stated_ranges_are_accepted_at_their_ends(tmp_path):
    path = tmp_path / "scenario.yaml"
    path.write_text(quintic("settle_time: 0.5", f"settle_time: {MAX_SETTLE_TIME}\nmax_duration: {MAX_RUN_DURATION}\n"
                                                f"simulator:\n  target_realtime_rate: {REALTIME_RATES[0]}"))
    scenario = load_scenario(path)
    assert (scenario.settle_time, scenario.max_duration) == (MAX_SETTLE_TIME, MAX_RUN_DURATION)
    assert scenario.simulator.target_realtime_rate == REALTIME_RATES[0]


@pytest.mark.parametrize("rate, shown", [("1e-9", "1e-09"), ("0.05", "0.05"), ("1e4", "10000.0"), ("nan", "nan")])
def test_live_rate_out_of_range_is_refused_before_anything(rate, shown, tmp_path, capsys):
    code = cli.main(["run", "quintic_ptp", "--meshcat", "--rate", rate, "--out", str(tmp_path / "run")])
    clean_refusal(code, capsys, rf"--rate must be a positive real-time rate from 0.1 to 1000, got {shown}$")
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("arguments, pattern", [
    (dict(settle_time=1e5, max_duration=1e9), r"max_duration must be at most 600 s"),
    (dict(settle_time=1e5), r"settle_time must be at most 60 s"),
    (dict(simulator_config=SimulatorConfig(target_realtime_rate=1e-9)),
     r"simulator_config.target_realtime_rate must be 0 \(as fast as it goes\) or from 0.1"),
    (dict(simulator_config=SimulatorConfig(max_step_size=1e-9)), r"simulator_config.max_step_size must be at least 1e-05 s"),
    (dict(plant_config=MultibodyPlantConfig(time_step=1e-9)), r"plant.time_step must be at least 1e-05 s"),
])
def test_simulate_refuses_times_out_of_range(arguments, pattern):
    with pytest.raises(DrakeTrajError, match=pattern):
        simulate(short_planner(), **arguments)


def test_run_station_refuses_times_out_of_range():
    builder = DiagramBuilder()
    station = builder.AddSystem(build_station(short_planner()))
    simulator = Simulator(builder.Build())
    with pytest.raises(DrakeTrajError, match=r"max_duration must be at most 600 s .*got 1e\+09 s"):
        run_station(simulator, station, max_duration=1e9)
    with pytest.raises(DrakeTrajError, match=r"settle_time must be at most 60 s"):
        run_station(simulator, station, settle_time=1e5)
    assert simulator.get_context().get_time() == 0.0  # refused before any step


# --- the preflight looks as far ahead as the run goes -----------------------------------------


def slow_pajak(tmp_path: Path, max_duration: float, update_period: float | None = None) -> Path:
    """Pająk 2024's task (sim 3) at a 0.06 rad/s velocity limit: about 40 s of motion, found by the
    law alone in well under a second."""
    text = PAJAK.replace("velocity_limit: 1.05", "velocity_limit: 0.06").replace("acceleration_limit: 1.40",
                                                                                 "acceleration_limit: 0.2")
    text = text.replace("max_duration: 30.0", f"max_duration: {max_duration}")
    if update_period is not None:
        text = text.replace("  preserve_damping: true", f"  preserve_damping: true\n  update_period: {update_period}")
    path = tmp_path / "slow.yaml"
    path.write_text(text)
    return path


def update_period_line(path: Path) -> int:
    """The 1-based line of ``update_period:`` in the scenario file ``path``."""
    return next(number for number, line in enumerate(path.read_text().splitlines(), 1) if "update_period:" in line)


def test_the_preflight_integrates_up_to_max_duration(tmp_path):
    scenario = load_scenario(slow_pajak(tmp_path, 60.0), "sim3")
    planner = make_planner(scenario)
    preflight(scenario, planner)  # refused by a fixed 30 s horizon before
    duration = planner.plan().end_time()
    assert 30.0 < duration < 60.0, duration
    # a horizon shorter than the task, on the kept integration too: refused at max_duration
    with pytest.raises(PlanningError, match=r"takes \d+\.\d+ s, longer than 35 s, the preflight's horizon") as kept:
        planner.preflight(35.0)
    assert kept.value.cause is Cause.TIMEOUT


def test_the_plan_keeps_the_preflight_of_the_runs_horizon(tmp_path, monkeypatch):
    # plan() (the cell check's input) reuses the integration of the preflight with max_duration;
    # it used to integrate again with the default horizon, refusing a task longer than that
    monkeypatch.setattr(PajakPlanner.preflight, "__defaults__", (30.0,))  # a default below the task's 40 s
    scenario = load_scenario(slow_pajak(tmp_path, 60.0), "sim3")
    planner = make_planner(scenario)
    preflight(scenario, planner)
    assert 30.0 < planner.plan().end_time() < 60.0


def test_a_task_longer_than_max_duration_is_refused_at_max_duration(tmp_path):
    path = slow_pajak(tmp_path, 35.0)
    scenario = load_scenario(path, "sim3")
    with pytest.raises(PlanningError, match=re.escape(str(path)) + r", line \d+, column 17: max_duration: the task did "
                                            r"not finish within 35 s, the preflight's horizon .*raise max_duration") as info:
        preflight(scenario, make_planner(scenario))
    assert info.value.field == ("max_duration",) and info.value.cause is Cause.TIMEOUT
    # from Python, simulate looks as far ahead as the max_duration given
    with pytest.raises(PlanningError, match=r"did not finish within 20 s, the preflight's horizon"):
        simulate(scenario, max_duration=20.0)


def test_an_update_period_finer_than_the_stated_step_is_refused(tmp_path, capsys):
    path = slow_pajak(tmp_path, 30.0, update_period=1.0e-9)
    code = cli.main(["run", str(path), "--variant", "sim3", "--no-preflight", "--out", str(tmp_path / "run")])
    clean_refusal(code, capsys, rf"line {update_period_line(path)}, column 18: planner.update_period must be at least 1e-05 s")


def test_a_preflight_of_too_many_steps_names_the_update_period(tmp_path, capsys):
    path = slow_pajak(tmp_path, 600.0, update_period=1.0e-5)
    code = cli.main(["run", str(path), "--variant", "sim3", "--out", str(tmp_path / "run")])
    clean_refusal(code, capsys, rf"line {update_period_line(path)}, column 18: planner.update_period: update_period = 1e-05 s would take 6e\+07 "
                                r"steps to look 600 s ahead \(max_duration\); at most " + re.escape(f"{MAX_PREFLIGHT_STEPS:.0e}"))


# --- honest results from Python -----------------------------------------------------------------


def test_a_station_that_has_not_finished_is_not_a_success(tmp_path):
    builder = DiagramBuilder()
    station = builder.AddSystem(build_station(short_planner()))
    simulator = Simulator(builder.Build())

    def result():
        return SimulationResult.from_station(station, station.GetMyContextFromRoot(simulator.get_context()))

    never_run = result()
    assert not never_run.succeeded and never_run.failure.cause is Cause.NOT_RUN
    assert "the station has not run: 0 sample(s)" in never_run.failure.message
    saved = json.loads((never_run.save(tmp_path / "never") / "metrics.json").read_text())
    assert saved["succeeded"] is False and saved["failure_cause"] == "not run"
    simulator.AdvanceTo(0.0005)  # less than one log period
    assert result().failure.cause is Cause.NOT_RUN
    simulator.AdvanceTo(0.05)  # half the motion
    halfway = result()
    assert not halfway.succeeded and halfway.failure.cause is Cause.TIMEOUT
    assert "the planner had not finished when the log ends at t = 0.0500 s" in halfway.failure.message
    assert run_station(simulator, station, settle_time=0.01) is None
    assert result().succeeded  # the same station, run to its end


def test_the_live_slider_scales_the_scenarios_speed_profile():
    meshcat = start_meshcat(announce=False)
    builder = DiagramBuilder()
    slider = builder.AddSystem(SpeedSlider(meshcat, profile=SpeedOverride(times=[0.0, 1.0], values=[0.5, 0.2])))
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    output = slider.get_output_port()
    seen = []
    for value, t in ((1.0, 0.5), (0.5, 0.5), (0.5, 1.5)):
        meshcat.SetSliderValue(SPEED_SLIDER, value)
        context.SetTime(t)
        seen.append(output.Eval(slider.GetMyContextFromRoot(context))[0])
    np.testing.assert_allclose(seen, [0.5, 0.25, 0.1], rtol=0, atol=1e-12)


def test_a_live_run_keeps_the_speed_profile(tmp_path, capsys):
    """One short move (0.1 rad per joint) at half speed from t = 0: live as without the live view."""
    goal = "[-1.47, -1.47, -2.26, -0.69, 1.67, 0.89]"
    path = tmp_path / "slowed.yaml"
    path.write_text(re.sub(r"  goals:\n(    - .*\n)+", f"  goals:\n    - {goal}\n", QUINTIC)
                    .replace("settle_time: 0.5", "settle_time: 0.05\nspeed_override: {times: [0.0], values: [0.5]}"))
    scenario = load_scenario(path)
    headless = simulate(scenario)
    code = cli.main(["run", str(path), "--meshcat", "--no-wait", "--serve-after", "0", "--rate", "10",
                     "--out", str(tmp_path / "live")])
    assert code == cli.EXIT_OK, capsys.readouterr().err
    live = json.loads((tmp_path / "live" / "metrics.json").read_text())
    unslowed = make_planner(scenario).planned_duration()
    assert headless.duration > 1.5 * unslowed  # the profile halves the speed
    assert live["duration_s"] == pytest.approx(headless.duration, abs=2e-3)  # dropped before: the unslowed time


# --- clear messages -----------------------------------------------------------------------------


VARIANTS = """\
_base: &base
  robot: ur10e
  planner: !QuinticConfig
    goals:
      - [-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]
    velocity_limit: [1.05, 1.05, 1.05, 1.05, 1.05, 1.05]
  settle_time: 0.5

slow:
  <<: *base
  name: slow
  planner:
{planner}"""


@pytest.mark.parametrize("planner, pattern", [
    ("    velocity_limit: [0.5, 0.5, 0.5, 0.5, 0.5, 0.5]\n", r"line 13, column 5: planner.goals must have shape"),
    ("    vartheta: 0.2\n", r"line 13, column 5: planner: needs a tag naming its type"),
])
def test_a_variants_planner_that_replaces_the_anchors_is_named_at_its_own_line(planner, pattern, tmp_path):
    path = tmp_path / "variants.yaml"
    path.write_text(VARIANTS.format(planner=planner))
    with pytest.raises(DrakeTrajError, match=pattern + r".*\(note: planner at line 12 replaces the whole planner "
                                             r"!QuinticConfig merged from line 3: a YAML merge \(<<\) is shallow"):
        make_planner(load_scenario(path, "slow"))  # the missing goals are found when the planner is made


def test_variant_with_a_shipped_scenario_name(capsys):
    # the shipped file, where the installed package keeps it (site-packages in CI, diagrams/ here)
    assert find_scenario("pajak_sim3", "sim1") == (data_directory("diagrams") / "pajak.yaml", "sim1")
    assert load_scenario("pajak_sim3", "sim1").name == "pajak_sim1"
    assert cli.main(["show", "pajak_sim3", "--variant", "sim1"]) == cli.EXIT_OK
    capsys.readouterr()
    clean_refusal(cli.main(["show", "pajak_sim3", "--variant", "sim4"]), capsys,
                  r"there is no variant 'sim4'; its variants are \['sim1', 'sim2', 'sim3', 'ur3e', 'ur5e', 'ur16e', 'ur20', 'ur30'\]")


def other_simulator():
    return Simulator(build_station(short_planner()))


@pytest.mark.parametrize("call, error, pattern", [
    (lambda: add_station(None, short_planner()), TypeError, r"builder must be a DiagramBuilder, got NoneType"),
    (lambda: add_station("builder", short_planner()), TypeError, r"builder must be a DiagramBuilder, got str"),
    (lambda: run_station(None, build_station(short_planner())), TypeError, r"simulator must be a Simulator, got NoneType"),
    (lambda: run_station(other_simulator(), None), TypeError, r"station must be a Diagram, got NoneType"),
    (lambda: run_station(other_simulator(), Diagram()), ValueError,
     r"station must be a station .*has no subsystem named 'planner'"),
    (lambda: run_station(other_simulator(), build_station(short_planner())), ValueError,
     r"station 'station' is not part of the simulator's diagram"),
    (lambda: make_station(load_scenario("quintic_ptp"), meshcat="http://localhost:7000"), TypeError,
     r"meshcat must be a Meshcat, got str"),
    (lambda: simulate(short_planner(), meshcat=7000), TypeError, r"meshcat must be a Meshcat, got int"),
])
def test_public_station_functions_check_their_arguments(call, error, pattern):
    with pytest.raises(error, match=pattern):
        call()


@pytest.fixture
def busy_port():
    """A port another program listens on (every interface, as Meshcat would)."""
    with socket.socket() as server:
        server.bind(("", 0))
        server.listen()
        yield server.getsockname()[1]


def test_a_busy_meshcat_port_is_named(busy_port, tmp_path, capsys):
    with pytest.raises(DrakeTrajError, match=rf"port {busy_port} \(--port\) cannot be opened for Meshcat: another "
                                             "program is listening there"):
        start_meshcat(busy_port)
    code = cli.main(["run", "quintic_ptp", "--meshcat", "--no-wait", "--port", str(busy_port), "--out", str(tmp_path / "r")])
    clean_refusal(code, capsys, rf"port {busy_port} \(--port\) cannot be opened for Meshcat")
    assert not (tmp_path / "r").exists()
