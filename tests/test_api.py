"""The Python API agrees with the CLI, and errors carry their location and cause as data."""

import ast
import json
import pickle
from pathlib import Path

import numpy as np
import pytest
from pydrake.common.yaml import yaml_dump_typed

import drake_traj
from drake_traj import Cause, DrakeTrajError, Failure, PlanningError, cli
from drake_traj.errors import field_text, joint_label
from drake_traj.scenario import ScenarioError, load_scenario, make_planner
from drake_traj.station import make_station, simulate
from drake_traj.validation import finite_array, positive_vector, real_scalar, require_positive

from conftest import DIAGRAMS

PACKAGE = Path(drake_traj.__file__).resolve().parent


# --- errors as data ----------------------------------------------------------------------------
def test_field_paths_are_written_as_in_a_scenario_file():
    assert field_text(("planner", "waypoints", 3)) == "planner.waypoints[3]"
    assert field_text(("controller", "kp")) == "controller.kp"
    assert field_text(("goals", 0, 5)) == "goals[0][5]"
    assert field_text(()) == ""


def test_joints_are_named_by_their_one_based_number_and_name():
    assert joint_label(1, drake_traj.get_robot("ur10e").joint_names) == "joint 2 (shoulder_lift_joint)"
    assert joint_label(0) == "joint 1"


@pytest.mark.parametrize("check, field", [
    (lambda: positive_vector([1.0, -1.0, 1.0], "velocity_limit", 3), ("velocity_limit", 1)),
    (lambda: finite_array([[0.0, 1.0], [np.nan, 2.0]], "goals", "rad"), ("goals", 1, 0)),
    (lambda: require_positive(np.array([[1.0, 0.0]]), "velocity_limit"), ("velocity_limit", 0, 1)),  # broadcastable
    (lambda: real_scalar("fast", "speed_override.values", "-"), ("speed_override", "values")),
    (lambda: real_scalar(-1.0, "path parameter s", "-", minimum=0.0), ()),  # a phrase, not a field
])
def test_shared_checks_give_the_field_and_the_cause(check, field):
    with pytest.raises(DrakeTrajError) as info:
        check()
    assert info.value.field == field and info.value.cause is Cause.INVALID


def test_a_negative_limit_names_its_joint_from_one():
    with pytest.raises(DrakeTrajError, match=r"velocity_limit\[1\] \(joint 2\) must be finite and > 0"):
        positive_vector([1.0, -1.0, 1.0], "velocity_limit", 3)


def test_errors_keep_their_data_through_pickling():  # as they come back from a Dask worker
    error = PlanningError("stalled", time=1.5, configuration=np.zeros(6), cause=Cause.STALL, field=("waypoints", 2))
    back = pickle.loads(pickle.dumps(error))
    assert type(back) is PlanningError and str(back) == str(error)
    assert back.cause is Cause.STALL and back.field == ("waypoints", 2) and back.time == 1.5
    np.testing.assert_array_equal(back.configuration, np.zeros(6))


def test_relocated_keeps_type_cause_and_attributes():
    error = PlanningError("waypoint 1 cannot be reached", time=0.0, cause=Cause.UNREACHABLE, field=("waypoints", 1))
    moved = error.relocated(("planner", "waypoints", 1), "file.yaml, line 3: planner.waypoints[1]: ...")
    assert type(moved) is PlanningError and moved.cause is Cause.UNREACHABLE and moved.time == 0.0
    assert moved.field == ("planner", "waypoints", 1) and str(moved).startswith("file.yaml, line 3")
    assert error.field == ("waypoints", 1)  # the original is unchanged


def test_a_failure_cause_is_the_enum_and_files_hold_its_value():
    failure = Failure("stall", "no progress", 2.0, (0.0,) * 6)
    assert failure.cause is Cause.STALL and failure.cause == "stall"
    data = json.loads(json.dumps(failure.to_dict()))
    assert data["cause"] == "stall" and Failure.from_dict(data) == failure
    with pytest.raises(ValueError):
        Failure("no such cause", "?")


def test_scenario_file_errors_carry_the_field(tmp_path):
    text = (DIAGRAMS / "quintic_ptp.yaml").read_text()
    path = tmp_path / "scenario.yaml"
    path.write_text(text.replace("  kd: [200, 200, 100, 20, 20, 10]", "  kd: [200, 200]"))
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert info.value.field == ("controller", "kd") and info.value.cause is Cause.INVALID
    path.write_text(text.replace("  goals:", "  goalz:"))
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert info.value.field == ("planner", "goalz")


def test_a_planner_field_error_is_located_at_its_line(tmp_path):
    text = (DIAGRAMS / "quintic_ptp.yaml").read_text()
    assert "velocity_limit: [1.05, " in text
    path = tmp_path / "scenario.yaml"
    path.write_text(text.replace("velocity_limit: [1.05, ", "velocity_limit: [0.0, "))
    line = 1 + text.splitlines().index(next(row for row in text.splitlines() if "velocity_limit" in row))
    with pytest.raises(DrakeTrajError) as info:
        make_planner(load_scenario(path))
    assert info.value.field == ("planner", "velocity_limit", 0)
    assert f"line {line}," in str(info.value) and "planner.velocity_limit[0]" in str(info.value)


def test_no_message_of_the_package_is_read_back_with_a_regular_expression():
    # the two regular expressions left read YAML text and check a scenario name, not messages
    users = {path.relative_to(PACKAGE).as_posix() for path in PACKAGE.rglob("*.py")
             if any(isinstance(node, ast.Import) and any(alias.name == "re" for alias in node.names)
                    for node in ast.walk(ast.parse(path.read_text())))}
    assert users == {"scenario/scenario.py", "scenario/yaml_schema.py"}


# --- Python as the CLI -------------------------------------------------------------------------
def test_load_scenario_takes_a_shipped_name_as_the_cli_does():
    by_name = load_scenario("quintic_ptp")
    by_path = load_scenario(DIAGRAMS / "quintic_ptp.yaml")
    assert yaml_dump_typed(by_name) == yaml_dump_typed(by_path) and by_name.source.path.name == "quintic_ptp.yaml"
    assert load_scenario("pajak", "sim3").name == load_scenario("pajak_sim3").name == "pajak_sim3"
    with pytest.raises(ScenarioError, match=r"no shipped scenario of that name; shipped: .*quintic_ptp"):
        load_scenario("quintic_ptq")


def test_simulate_runs_a_scenario_as_its_parts_do():
    scenario = load_scenario("quintic_ptp")
    whole = simulate(scenario, settle_time=0.05)
    arguments = scenario.station_arguments()
    parts = simulate(arguments.pop("planner"), name=scenario.name, simulator_config=scenario.simulator,
                     settle_time=0.05, max_duration=scenario.max_duration,
                     tracking_tolerance=scenario.tracking_tolerance, **arguments)
    assert whole.succeeded and whole.name == "quintic_ptp"
    np.testing.assert_array_equal(whole.q_ref, parts.q_ref)
    np.testing.assert_array_equal(whole.q_meas, parts.q_meas)


def test_simulate_refuses_a_max_duration_shorter_than_the_plan_as_the_cli_does(tmp_path, capsys):
    path = tmp_path / "short.yaml"
    path.write_text((DIAGRAMS / "quintic_ptp.yaml").read_text() + "max_duration: 1.0\n")
    with pytest.raises(ScenarioError) as info:
        simulate(load_scenario(path))
    assert info.value.field == ("max_duration",) and info.value.cause is Cause.INFEASIBLE
    assert "shorter than the planned motion (6.177 s" in str(info.value)
    assert cli.main(["run", str(path), "--out", str(tmp_path / "out")]) == cli.EXIT_BAD_INPUT
    assert str(info.value) in capsys.readouterr().err


def test_a_result_of_ones_own_robot_names_joints_by_number():
    result = simulate(drake_traj.planners.make_planner(
        drake_traj.QuinticConfig(goals=[[-1.5, -1.6, -2.3, -0.8, 1.6, 0.8]]), drake_traj.get_robot("ur10e"),
        drake_traj.get_robot("ur10e").home_configuration), settle_time=0.0)
    assert result.joint_names[1] == "shoulder_lift_joint"
    result.robot = "my_arm"  # a Robot of one's own: not in the registry
    assert result.joint_names is None and result.execution_failure(0.005) is None


def test_simulate_refuses_a_robot_beside_a_scenario():
    with pytest.raises(TypeError, match="names its robot"):
        simulate(load_scenario("quintic_ptp"), robot=drake_traj.get_robot("ur10e"))


def test_make_station_takes_a_scenario_not_a_name():
    with pytest.raises(TypeError, match=r"scenario must be a Scenario, got str.*load_scenario"):
        make_station("quintic_ptp")


UNREACHABLE_WAYPOINT = """\
name: far
robot: ur10e
planner: !PajakConfig
  waypoints:
    - [-0.175, -0.525, 0.730, 3.141592653589793, 0.0, 2.356194490192345]
    - [-0.175, -0.525, 0.100, 3.141592653589793, 0.0, 2.356194490192345]
    - [0.0, 0.0, 0.1, 3.141592653589793, 0.0, 2.356194490192345]
"""


def test_python_runs_the_preflight_by_default_as_the_cli_does(tmp_path, capsys):
    path = tmp_path / "far.yaml"
    path.write_text(UNREACHABLE_WAYPOINT)
    with pytest.raises(PlanningError) as info:
        simulate(load_scenario(path))
    error = info.value
    assert error.cause is Cause.UNREACHABLE and error.field == ("planner", "waypoints", 2)
    assert str(error).startswith(f"{path}, line 7, column 7: planner.waypoints[2]: ")
    assert cli.main(["run", str(path), "--out", str(tmp_path / "out")]) == cli.EXIT_BAD_INPUT
    assert str(error) in capsys.readouterr().err  # the same message, located the same way
