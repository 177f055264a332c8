"""Scenario files: loading, the CLI, the example, and clear errors for bad input."""

import runpy
import sys
from pathlib import Path

import numpy as np
import pytest

from drake_traj import QuinticConfig, cli, get_robot, planners
from drake_traj.scenario import (Scenario, ScenarioError, default_scenario_path, find_scenario, load_scenario,
                                 make_planner, scenario_variants)

from conftest import DIAGRAMS

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
QUINTIC = (DIAGRAMS / "quintic_ptp.yaml").read_text()


def write(tmp_path, text, name="scenario.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_every_shipped_scenario_loads_and_builds_its_planner():
    paths = sorted(DIAGRAMS.glob("*.yaml"))
    assert paths, "no scenarios in diagrams/"
    for path in paths:
        for variant in scenario_variants(path) or [None]:
            scenario = load_scenario(path, variant)
            assert scenario.name == (path.stem if variant is None else f"{path.stem}_{variant}")
            make_planner(scenario)


def test_default_scenario_is_shipped_with_the_package():
    assert default_scenario_path().is_file()


@pytest.mark.parametrize(
    "change, message",
    [
        (("name: quintic_ptp", "name: quintic_ptp\nspeed: 3"), r"line 5, column 1: speed: unknown field"),
        (("  goals:", "  goalz:"), r"goalz"),
        (("q_initial: [-1.5707963267948966, ", "q_initial: ["), r"q_initial must have 6 entries"),
        (("q_initial: [-1.5707963267948966", "q_initial: [.nan"), r"q_initial must be finite"),
        (("q_initial: [-1.5707963267948966", "q_initial: [7.0"), r"q_initial\[0\] = 7.0 rad is outside"),
        (("velocity_limit: [1.05, ", "velocity_limit: [0.0, "), r"velocity_limit\[0\].*> 0"),
        (("acceleration_limit: [1.40, ", "acceleration_limit: [-1.0, "), r"acceleration_limit\[0\].*> 0"),
        (("    - [-0.9, -1.9", "    - [-6.9, -1.9"), r"planner.goals\[0\]\[0\] \(joint 1\) = -6.9 rad"),
        (("    - [-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]", "    - [-0.9, -1.9, -1.9, -0.9, 1.2]"), r"goals"),
        (("    - [-0.9, -1.9", "    - [.inf, -1.9"), r"goals.*finite"),
        (("  kp: [4000, ", "  kp: [-4000, "), r"controller.kp"),
        (("  kd: [200, 200, 100, 20, 20, 10]", "  kd: [200, 200]"), r"controller.kd must have 6"),
        (("time_step: 0.001", "time_step: 0.0"), r"time_step"),
    ],
)
def test_bad_scenarios_name_the_field(tmp_path, change, message):
    old, new = change
    assert old in QUINTIC
    path = write(tmp_path, QUINTIC.replace(old, new, 1))
    with pytest.raises(ValueError, match=message):
        make_planner(load_scenario(path))


def test_missing_scenario_file_is_named(tmp_path):
    with pytest.raises(ValueError, match="scenario file .*nowhere.yaml not found"):
        load_scenario(tmp_path / "nowhere.yaml")


@pytest.mark.parametrize("reference, variant, shipped", [
    ("diagrams/boryga_loop.yaml", "scara", "boryga_loop_scara"), ("diagrams/pajak.yaml", "sim3", "pajak_sim3"),
    ("diagrams/quintic_ptp.yaml", None, "quintic_ptp"), ("../elsewhere/quintic_ptp", None, "quintic_ptp")])
def test_a_path_to_a_shipped_file_not_found_here_suggests_the_shipped_name(reference, variant, shipped, tmp_path,
                                                                           monkeypatch):
    # the README's diagrams/... paths, run outside the checkout
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ScenarioError) as error:
        load_scenario(reference, variant)
    assert str(error.value) == (f"scenario file {reference} not found in {tmp_path}; the shipped scenario of that name "
                                f"runs as `drake-traj run {shipped}` (Python: load_scenario('{shipped}'))")
    assert load_scenario(shipped).name == shipped


def test_a_path_to_a_shipped_file_of_variants_names_them(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["run", "diagrams/pajak.yaml"]) == cli.EXIT_BAD_INPUT
    names = ", ".join(f"pajak_{variant}" for variant in scenario_variants(DIAGRAMS / "pajak.yaml"))
    assert capsys.readouterr().err == (f"drake-traj: error: scenario file diagrams/pajak.yaml not found in {tmp_path}; "
                                       f"the shipped file of that name holds {names}: run one by its name, e.g. "
                                       "`drake-traj run pajak_sim3` (Python: load_scenario('pajak_sim3'))\n")


def test_a_path_of_no_shipped_name_is_only_not_found(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ScenarioError, match=rf"^scenario file diagrams/mine.yaml not found in {tmp_path}$"):
        load_scenario("diagrams/mine.yaml")

def test_a_shipped_name_is_found_beside_a_folder_of_that_name(tmp_path, monkeypatch):
    # an earlier run written with --out quintic_ptp must not hide the shipped scenario
    monkeypatch.chdir(tmp_path)
    (tmp_path / "quintic_ptp").mkdir()
    (tmp_path / "mine").mkdir()
    assert find_scenario("quintic_ptp") == (default_scenario_path().parent / "quintic_ptp.yaml", None)  # the shipped one
    with pytest.raises(ValueError, match="mine is a folder, not a scenario file"):
        find_scenario("mine")


def test_cli_reports_bad_input_without_a_traceback(tmp_path, capsys):
    path = write(tmp_path, QUINTIC.replace("name: quintic_ptp", "name: quintic_ptp\nspeed: 3"))
    assert cli.main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    assert "speed" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_scenario_defaults_are_the_papers_start_and_ur_limits():
    scenario = Scenario(planner=QuinticConfig(goals=[[0.0] * 6]))
    np.testing.assert_allclose(scenario.start_configuration(),
                               [-np.pi / 2, -np.pi / 2, -3 * np.pi / 4, -np.pi / 4, np.pi / 2, np.pi / 4])
    planner = make_planner(scenario)
    np.testing.assert_array_equal(planner.velocity_limit, [1.05] * 6)
    np.testing.assert_array_equal(planner.acceleration_limit, [1.40] * 6)


def test_variants_are_chosen_by_name(tmp_path):
    assert scenario_variants(DIAGRAMS / "pajak.yaml") == ["sim1", "sim2", "sim3", "ur3e", "ur5e", "ur16e", "ur20", "ur30"]
    assert scenario_variants(DIAGRAMS / "quintic_ptp.yaml") == []
    assert load_scenario(DIAGRAMS / "pajak.yaml", "sim2").planner.limit_acceleration is False
    with pytest.raises(ValueError, match=r"no variant was given; its variants are \['sim1', 'sim2', 'sim3', 'ur3e',"):
        load_scenario(DIAGRAMS / "pajak.yaml")
    with pytest.raises(ValueError, match="there is no variant 'sim4'"):
        load_scenario(DIAGRAMS / "pajak.yaml", "sim4")
    with pytest.raises(ValueError, match="holds one scenario, not variants"):
        load_scenario(DIAGRAMS / "quintic_ptp.yaml", "sim3")
    assert cli.main(["run", str(DIAGRAMS / "pajak.yaml"), "--variant", "sim4", "--out", str(tmp_path)]) == 2


def test_example_runs_and_writes_its_outputs(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(sys, "argv", ["quintic_ptp.py", str(tmp_path)])
    runpy.run_path(str(EXAMPLES / "quintic_ptp.py"), run_name="__main__")
    assert "T = " in capsys.readouterr().out
    assert (tmp_path / "result.npz").is_file() and (tmp_path / "joints.png").is_file()


def test_the_config_level_make_planner_says_what_to_pass():
    # drake_traj.planners.make_planner takes a config, a robot and a start; a scenario goes to drake_traj.make_planner
    with pytest.raises(TypeError, match=r"got Scenario: .*; a scenario's planner is drake_traj\.make_planner\(scenario\)"):
        planners.make_planner(load_scenario("quintic_ptp"))
    with pytest.raises(TypeError, match=r"^make_planner\(QuinticConfig\(\.\.\.\), robot, q_initial\) needs robot and "
                                        r"q_initial: .* make_planner\(config, robot, robot.home_configuration\)$"):
        planners.make_planner(QuinticConfig(goals=[[0.0] * 6]))
    robot = get_robot("ur10e")
    with pytest.raises(TypeError, match=r"needs q_initial: "):
        planners.make_planner(QuinticConfig(goals=[[0.0] * 6]), robot)
    assert planners.make_planner(QuinticConfig(goals=[[0.0] * 6]), robot, robot.home_configuration).robot.name == "ur10e"
