"""The station as a Drake user composes it: public API only, one's own builder and Simulator."""

import inspect
import runpy
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import yaml
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

import drake_traj
from drake_traj import SimulationResult, load_scenario, make_planner, make_station, run_station, simulate
from drake_traj.results import ARRAY_NAMES, LOGGERS
from drake_traj.scenario import find_scenario
from drake_traj.station import build_station
from drake_traj.robots.ur10e import flange_pose

DIAGRAMS = Path(__file__).resolve().parents[1] / "diagrams"
PORTS_IN = {"speed_override": 1, "applied_generalized_force": 6}
PORTS_OUT = {"desired_state": 12, "desired_acceleration": 6, "scaling": 1, "measured_state": 12, "torque": 6,
             "tcp_pose": 6}


@pytest.fixture(scope="module")
def scenario():
    return load_scenario(*find_scenario("quintic_ptp"))


def test_station_is_named_with_named_parts_and_ports(scenario):
    station = make_station(scenario)
    assert station.get_name() == "station"
    for name in ("planner", "plant", "scene_graph", "lookahead", "feedforward", "tcp_pose", *LOGGERS):
        assert station.HasSubsystemNamed(name), name
    for name, size in PORTS_IN.items():
        assert station.GetInputPort(name).size() == size
    for name, size in PORTS_OUT.items():
        assert station.GetOutputPort(name).size() == size
    assert station.num_input_ports() == len(PORTS_IN) and station.num_output_ports() == len(PORTS_OUT)


def declared_ports(docstring: str) -> dict:
    """The ``.. pydrake_system::`` block of a docstring (Drake's way to document a system's ports)
    as {"name": ..., "input_ports": [...], "output_ports": [...]}, without "(optional)" marks."""
    lines = inspect.cleandoc(docstring).splitlines()
    start = lines.index(".. pydrake_system::") + 1
    end = next(k for k in range(start + 1, len(lines)) if lines[k] and not lines[k].startswith(" "))
    block = yaml.safe_load(textwrap.dedent("\n".join(lines[start:end])))
    for key in ("input_ports", "output_ports"):
        block[key] = [port.removesuffix(" (optional)") for port in block[key]]
    return block


def test_the_docstring_declares_the_built_stations_ports(scenario):
    # the ports are documented once, in build_station's docstring: it cannot drift from the diagram
    declared = declared_ports(build_station.__doc__)
    station = make_station(scenario)
    assert declared["name"] == station.get_name()
    assert declared["input_ports"] == [station.get_input_port(k).get_name() for k in range(station.num_input_ports())]
    assert declared["output_ports"] == [station.get_output_port(k).get_name()
                                        for k in range(station.num_output_ports())]
    described = build_station.__doc__.split(".. pydrake_system::")[1]
    for port in declared["input_ports"] + declared["output_ports"]:
        assert f"- ``{port}`` (" in described, f"{port} is declared but not described"


@pytest.mark.parametrize("name, variant", [("quintic_ptp", None), ("pajak", "sim3")])
def test_the_stations_acceleration_and_scaling_are_the_planners_own_ports(name, variant):
    # the station splits the planner's one-call [q̈; c] port in C++ for the plant and the loggers:
    # mid-motion (c below 1 on the Pająk task) its ports equal the planner's separate ports
    station = make_station(load_scenario(*find_scenario(name, variant)))
    simulator = Simulator(station)
    simulator.AdvanceTo(1.5)
    context = simulator.get_context()
    planner = station.GetSubsystemByName("planner")
    planner_context = planner.GetMyContextFromRoot(context)
    acceleration = station.GetOutputPort("desired_acceleration").Eval(context)
    assert np.max(np.abs(acceleration)) > 0.01  # moving
    np.testing.assert_array_equal(acceleration, planner.GetOutputPort("desired_acceleration").Eval(planner_context))
    np.testing.assert_array_equal(station.GetOutputPort("scaling").Eval(context),
                                  planner.GetOutputPort("scaling").Eval(planner_context))
    np.testing.assert_array_equal(planner.GetOutputPort("acceleration_and_scaling").Eval(planner_context),
                                  np.r_[acceleration, station.GetOutputPort("scaling").Eval(context)])


def test_a_fresh_context_starts_at_the_planners_start(scenario):
    station = make_station(scenario)
    context = station.CreateDefaultContext()
    q0 = scenario.start_configuration()
    np.testing.assert_array_equal(station.GetOutputPort("measured_state").Eval(context), np.r_[q0, np.zeros(6)])
    np.testing.assert_array_equal(station.GetOutputPort("desired_state").Eval(context), np.r_[q0, np.zeros(6)])
    np.testing.assert_allclose(station.GetOutputPort("tcp_pose").Eval(context)[:3],
                               drake_traj.get_robot("ur10e").tool_position(q0), atol=1e-12)


def test_ones_own_diagram_with_an_override_equals_simulate(scenario):
    builder = DiagramBuilder()
    station = builder.AddSystem(make_station(scenario))
    override = builder.AddSystem(ConstantVectorSource([0.5]))
    builder.Connect(override.get_output_port(), station.GetInputPort("speed_override"))
    simulator = Simulator(builder.Build())
    ApplySimulatorConfig(scenario.simulator, simulator)
    failure = run_station(simulator, station, settle_time=scenario.settle_time, max_duration=scenario.max_duration)
    mine = SimulationResult.from_station(station, station.GetMyContextFromRoot(simulator.get_context()),
                                         name=scenario.name, failure=failure)

    arguments = scenario.station_arguments()
    theirs = simulate(arguments.pop("planner"), name=scenario.name, simulator_config=scenario.simulator,
                      settle_time=scenario.settle_time, max_duration=scenario.max_duration, speed_override=0.5,
                      **arguments)
    assert mine.succeeded and theirs.succeeded
    for name in ARRAY_NAMES:
        np.testing.assert_allclose(getattr(mine, name), getattr(theirs, name), rtol=0, atol=1e-12, err_msg=name)
    assert mine.duration == theirs.duration
    # the override slowed the 6.18 s motion down (c relaxes to 0.5 within about 1 s)
    assert mine.duration > 1.8 * make_planner(scenario).law.duration


def test_a_planning_failure_in_ones_own_run_is_a_record_with_the_log(scenario):
    builder = DiagramBuilder()
    station = builder.AddSystem(make_station(scenario))
    simulator = Simulator(builder.Build())
    failure = run_station(simulator, station, settle_time=0.0, max_duration=0.5)
    assert failure.cause == "timeout" and failure.time == pytest.approx(0.5)
    result = SimulationResult.from_station(station, station.GetMyContextFromRoot(simulator.get_context()),
                                           failure=failure)
    assert not result.succeeded and len(result.t) == 501


def test_public_modules_declare_their_api():
    for module in ("drake_traj.station", "drake_traj.results", "drake_traj.scenario", "drake_traj.cell",
                   "drake_traj.bench", "drake_traj.cli", "drake_traj.errors", "drake_traj.robots", "drake_traj.planners"):
        imported = __import__(module, fromlist=["__all__"])
        assert imported.__all__ and all(hasattr(imported, name) for name in imported.__all__), module


@pytest.mark.parametrize("script", ["light_curtain.py", "disturbance.py"])
def test_diagram_scripts_run(script, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(sys, "argv", [script, str(tmp_path)])
    namespace = runpy.run_path(str(DIAGRAMS / script), run_name="drake_traj_test")
    result = namespace["main"]([str(tmp_path)])
    assert (tmp_path / script.replace(".py", ".png")).stat().st_size > 10_000
    steps = np.abs(np.diff(result.qdd_ref[1:], axis=0)).max()
    assert steps < 0.1 and result.metrics().peak_acceleration_fraction <= 1 + 1e-9
    if script == "light_curtain.py":
        assert result.succeeded
        # slowed to 25 % while the person is inside (1.5-3.5 s), back to full speed after
        assert result.scaling[np.searchsorted(result.t, 3.4)] == pytest.approx(0.25, abs=0.01)
        assert result.scaling[-1] == pytest.approx(1.0, abs=1e-3)
    else:
        error = np.linalg.norm(result.tcp_ref[:, :3] - result.tcp[:, :3], axis=1)
        assert error.max() > 5e-3  # the 60 N m pulse pushes the TCP off by millimetres (measured 10.4 mm)
        assert error[result.t > 2.0].max() < 1e-4  # and the PD loop brings it back


def test_the_fixture_cell_script_runs_with_its_tool_and_refuses_a_taller_fixture(tmp_path, capsys):
    namespace = runpy.run_path(str(DIAGRAMS / "fixture_cell.py"), run_name="drake_traj_test")
    result = namespace["main"]([str(tmp_path)])
    printed = capsys.readouterr().out
    assert result.succeeded and result.robot == "ur10e"
    # the result's TCP is the gripper's tip, 0.15 m below the flange (the tool points down)
    flange = np.array([flange_pose(q)[:3, 3] for q in result.q_meas[::500]])
    assert np.allclose(np.linalg.norm(result.tcp[::500, :3] - flange, axis=1), 0.15, atol=1e-9)
    assert "nearest to the fixture" in printed and "with a 0.5 m fixture: refused" in printed
    assert "fixture" in printed.split("refused:")[1]
    for name in ("meshcat.html", "refusal.png", "tcp_path.png"):
        assert (tmp_path / name).stat().st_size > 10_000
