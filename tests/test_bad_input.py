"""Bad input, as a new user would give it: one clean message naming the input, never a traceback,
nothing of an earlier run touched. Table-driven over scenario YAML, the CLI, the Python API and
saved results; a property test mutates the shipped scenarios at random."""

import contextlib
import functools
import io
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import drake_traj
from drake_traj import (
    ControllerGains,
    LiConfig,
    PajakConfig,
    QuinticConfig,
    Scenario,
    SimulationResult,
    ToppraConfig,
    cli,
    get_robot,
    load_scenario,
    make_station,
    simulate,
)
from drake_traj.cli import commands
from drake_traj.planners import make_planner
from drake_traj.planners.pajak import PajakPlanner, paper_parameters
from drake_traj.planners.quintic import QuinticPtpPlanner, plan_synchronized_quintic
from drake_traj.results import OutputError, ResultFileError
from drake_traj.scenario import SpeedOverride
from drake_traj.station import build_station

DIAGRAMS = Path(__file__).resolve().parents[1] / "diagrams"
QUINTIC = (DIAGRAMS / "quintic_ptp.yaml").read_text()
HOME = "[-1.5707963267948966, -1.5707963267948966, -2.356194490192345, -0.7853981633974483, 1.5707963267948966, 0.7853981633974483]"


def quintic(old: str, new: str) -> str:
    """The shipped quintic scenario with one text replaced (which must be there)."""
    assert old in QUINTIC, old
    return QUINTIC.replace(old, new, 1)


def pajak(planner_lines: str) -> str:
    """A one-scenario Pająk file with the given planner fields."""
    return f"name: pajak_case\nrobot: ur10e\nplanner: !PajakConfig\n{planner_lines}"


PAJAK_WAYPOINTS = "  waypoints:\n    - [-0.175, -0.525, 0.730, 3.141592653589793, 0.0, 2.356194490192345]\n"

# (case id, scenario text (str) or bytes, regex the message must contain)
YAML_CASES = [
    ("empty file", "", r"empty"),
    ("only comments", "# nothing here\n", r"empty"),
    ("unclosed bracket", quintic("  goals:", "  goals: [1, 2"), r"YAML syntax error at line \d+, column \d+"),
    ("bad indentation", quintic("name: quintic_ptp", "name: quintic_ptp\n  robot: ur10e"), r"YAML syntax error at line 5, column 8"),
    ("top-level list", "- 1\n- 2\n", r"must be a mapping"),
    ("top-level scalar", "hello\n", r"must be a mapping"),
    ("unknown top-level key", quintic("name: quintic_ptp", "name: quintic_ptp\nspeed: 3"), r"line 5, column 1: speed: unknown field"),
    ("unknown planner key", quintic("  goals:", "  goalz:"), r"planner.goalz: unknown field"),
    ("duplicate top-level key", quintic("name: quintic_ptp", "name: quintic_ptp\nname: again"), r"name: duplicate key \(first at line 4\)"),
    ("duplicate planner key", quintic("  velocity_limit:", "  acceleration_limit: [1, 1, 1, 1, 1, 1]\n  velocity_limit:"),
     r"planner.acceleration_limit: duplicate key"),
    ("python object tag", quintic("name: quintic_ptp", "name: !!python/object:os.system quintic_ptp"),
     r"name: the tag 'python/object:os.system' is not allowed"),
    ("python name tag", quintic("settle_time: 0.5", "settle_time: !!python/name:os.system ''"), r"settle_time: the tag"),
    ("time step as text", quintic("  time_step: 0.001", '  time_step: "fast"'), r"plant.time_step: expected a number, found text 'fast'"),
    ("q_initial as text", quintic(f"q_initial: {HOME}", 'q_initial: "home"'), r"q_initial: expected a list, found text 'home'"),
    ("q_initial too short", quintic(f"q_initial: {HOME}", "q_initial: [0, 0, 0]"), r"q_initial must have 6 entries"),
    ("q_initial NaN", quintic(f"q_initial: {HOME}", "q_initial: [.nan, 0, 0, 0, 0, 0]"), r"q_initial must be finite"),
    ("q_initial out of range", quintic(f"q_initial: {HOME}", "q_initial: [7, 0, 0, 0, 0, 0]"), r"q_initial\[0\] = 7.0 rad is outside"),
    ("limit scalar for a list", quintic("  velocity_limit: [1.05, 1.05, 1.05, 1.05, 1.05, 1.05]", "  velocity_limit: 1.05"),
     r"planner.velocity_limit: expected a list, found a number"),
    ("limit entry text", quintic("  velocity_limit: [1.05, ", "  velocity_limit: [fast, "), r"planner.velocity_limit\[0\]: expected a number"),
    ("limit negative", quintic("  velocity_limit: [1.05, ", "  velocity_limit: [-1.05, "), r"planner.velocity_limit\[0\].*> 0"),
    ("limit zero", quintic("  acceleration_limit: [1.40, ", "  acceleration_limit: [0, "), r"planner.acceleration_limit\[0\].*> 0"),
    ("limit above rated", quintic("  velocity_limit: [1.05, 1.05, 1.05, 1.05, 1.05, 1.05]", "  velocity_limit: [10, 10, 10, 10, 10, 10]"),
     r"planner.velocity_limit\[0\] = 10 rad/s is above the rated speed of the ur10e's joint 1 \(shoulder_pan_joint\), 2.094"),
    ("limit wrong length", quintic("  velocity_limit: [1.05, 1.05, 1.05, 1.05, 1.05, 1.05]", "  velocity_limit: [1, 1, 1, 1, 1]"),
     r"planner.velocity_limit must be a scalar or have shape \(6,\)"),
    ("limit infinite", quintic("  acceleration_limit: [1.40, ", "  acceleration_limit: [.inf, "), r"planner.acceleration_limit\[0\].*finite"),
    ("goal row too short", quintic("    - [-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]", "    - [-0.9, -1.9, -1.9, -0.9, 1.2]"), r"planner.goals"),
    ("goal out of range", quintic("    - [-0.9, -1.9", "    - [-6.9, -1.9"), r"goals\[0\]\[0\] \(joint 1\) = -6.9 rad"),
    ("goals empty", quintic("  goals:\n", "  goals: []\n  goals_removed:\n"), r"planner.goals_removed: unknown field"),
    ("goals scalar", quintic("  goals:\n    - [-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]\n", "  goals: 3\n  unused:\n    - [-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]\n"),
     r"planner.goals: expected a list, found an integer"),
    ("unknown planner tag", quintic("planner: !QuinticConfig", "planner: !FastestConfig"), r"planner: unknown type !FastestConfig; expected one of"),
    ("untagged pajak planner", pajak(PAJAK_WAYPOINTS).replace(" !PajakConfig", ""), r"planner: needs a tag naming its type"),
    ("unknown robot", quintic("name: quintic_ptp", "name: quintic_ptp\nrobot: puma"), r"robot: robot must be one of"),
    ("robot as number", quintic("name: quintic_ptp", "name: quintic_ptp\nrobot: 5"), r"robot: expected text, found an integer"),
    ("name with ..", quintic("name: quintic_ptp", "name: ../../x"), r"name must be a plain name"),
    ("name absolute", quintic("name: quintic_ptp", "name: /some/abs/path"), r"name must be a plain name"),
    ("name with space", quintic("name: quintic_ptp", "name: my run"), r"name must be a plain name"),
    ("log period tiny", quintic("settle_time: 0.5", "log_period: 1.0e-7\nsettle_time: 0.5"), r"log_period must be a whole multiple of plant.time_step"),
    ("number quoted", quintic("settle_time: 0.5", 'log_period: "1e-3"\nsettle_time: 0.5'), r"log_period: expected a number, found text '1e-3'"),
    ("log period huge", quintic("settle_time: 0.5", "log_period: 200.0\nsettle_time: 0.5"), r"log_period must be at most 0.01 s"),
    ("time step coarse", quintic("  time_step: 0.001", "  time_step: 10"), r"plant.time_step must be at most 0.01 s.*got 10 s"),
    ("max duration below log period", quintic("settle_time: 0.5", "settle_time: 0.5\nmax_duration: 0.0005"),
     r"max_duration \(0.0005 s\) must be longer than log_period \(0.001 s\)"),
    ("motion longer than max duration", quintic("settle_time: 0.5", "settle_time: 0.5\nmax_duration: 2.0"),
     r"max_duration \(2 s\) is shorter than the planned motion \(6.177 s"),
    ("contact approximation unknown", quintic("  time_step: 0.001", "  time_step: 0.001\n  discrete_contact_approximation: foo"),
     r"plant: Unknown discrete_contact_approximation: 'foo'"),
    ("name too long", quintic("name: quintic_ptp", "name: " + "a" * 150), r"at most 100 characters"),
    ("NUL byte", quintic("name: quintic_ptp", "name: quintic_ptp\x00"), r"the character '\\x00' at offset \d+ is not allowed"),
    ("nested too deeply", "a: " + "[" * 3000 + "]" * 3000 + "\n", r"nested too deeply"),
    ("merge of a list", "name: q\nq_initial: &l [1, 2]\nplanner: !QuinticConfig\n  <<: *l\n", r"expected a mapping for merging"),
    ("planner tag on the controller", quintic("controller:", "controller: !QuinticConfig"),
     r"controller: the tag !QuinticConfig does not belong here: this field is a ControllerGains"),
    ("key that is a list", "? [a, b]\n: 1\n", r"a key must be a plain name, found a list of 2 entries"),
    ("goal of five numbers", quintic("    - [-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]", "    - [-0.9, -1.9, -1.9, -0.9, 1.2]"),
     r"planner.goals must be .*: its rows must have the same length, got lengths \[5, 6, 6\]"),
    ("pajak waypoint on the base axis", pajak("  waypoints:\n    - [0.0, 0.0, 0.1, 3.141592653589793, 0.0, 2.356194490192345]\n"),
     r"line 5, column 7: planner.waypoints\[0\]: waypoint 0 cannot be reached"),
    ("log period off grid", quintic("settle_time: 0.5", "log_period: 0.0015\nsettle_time: 0.5"), r"log_period must be a whole multiple"),
    ("time step zero", quintic("  time_step: 0.001", "  time_step: 0.0"), r"plant.time_step must be a finite, positive"),
    ("time step negative", quintic("  time_step: 0.001", "  time_step: -0.001"), r"plant.time_step must be a finite, positive"),
    ("plant unknown key", quintic("  time_step: 0.001", "  time_step: 0.001\n  gravity: 9.81"), r"plant.gravity: unknown field"),
    ("integration scheme", quintic("settle_time: 0.5", "settle_time: 0.5\nsimulator:\n  integration_scheme: warp"),
     r"simulator.integration_scheme must be one of"),
    ("max step negative", quintic("settle_time: 0.5", "settle_time: 0.5\nsimulator:\n  max_step_size: -1.0"), r"simulator.max_step_size must be"),
    ("kp wrong length", quintic("  kp: [4000, 4000, 2000, 500, 500, 300]", "  kp: [4000, 4000]"), r"controller.kp must have 6 entries"),
    ("kp negative", quintic("  kp: [4000, ", "  kp: [-4000, "), r"controller.kp"),
    ("feedforward as text", quintic("  feedforward_acceleration: true", '  feedforward_acceleration: "yes"'),
     r"controller.feedforward_acceleration: expected true or false"),
    ("settle time negative", quintic("settle_time: 0.5", "settle_time: -1"), r"settle_time must be a finite"),
    ("max duration zero", quintic("settle_time: 0.5", "settle_time: 0.5\nmax_duration: 0"), r"max_duration must be a finite, positive"),
    ("tracking tolerance negative", quintic("settle_time: 0.5", "settle_time: 0.5\ntracking_tolerance: -1"), r"tracking_tolerance must be"),
    ("override above one", quintic("settle_time: 0.5", "settle_time: 0.5\nspeed_override: {times: [1.0], values: [2.0]}"),
     r"speed_override.values must be in \[0, 1\]"),
    ("override times backwards", quintic("settle_time: 0.5", "settle_time: 0.5\nspeed_override: {times: [2.0, 1.0], values: [0.5, 1.0]}"),
     r"speed_override.times must be finite, >= 0 and increasing"),
    ("override unequal lengths", quintic("settle_time: 0.5", "settle_time: 0.5\nspeed_override: {times: [2.0], values: [0.5, 1.0]}"),
     r"speed_override.times and speed_override.values must be two lists of equal length"),
    ("binary file", b"\x89PNG\r\n\x1a\n\x00\x00\xff\xfe", r"is not a text \(UTF-8\) file"),
    ("pajak waypoint out of reach", pajak("  waypoints:\n    - [1.5, 0, 0.2, 3.14, 0, 0]\n"), r"planner.waypoints\[0\]: waypoint 0 cannot be reached: .* out of reach"),
    ("pajak waypoints too close", pajak(PAJAK_WAYPOINTS + "    - [-0.175, -0.535, 0.730, 3.141592653589793, 0.0, 2.356194490192345]\n"),
     r"waypoints\[0\] and waypoints\[1\] are 0.0100 m apart"),
    ("pajak vartheta out of range", pajak(PAJAK_WAYPOINTS + "  vartheta: 0.7\n"), r"vartheta must be a number in \(0, 0.5\)"),
    ("pajak waypoint short row", pajak("  waypoints:\n    - [-0.175, -0.525, 0.730]\n"), r"waypoints must have shape \(w, 6\)"),
    ("boryga only B", "name: b\nrobot: scara\nplanner: !BorygaConfig\n  B: [0.5, 0.5, 0.265]\n", r"B, M and E must all be 3-vectors"),
    ("boryga M out of reach", "name: b\nrobot: ur10e\nplanner: !BorygaConfig\n  B: [0.5, 0.3, 0.5]\n  M: [3.0, 0.3, 0.5]\n"
     "  E: [0.5, 0.5, 0.5]\n", r"line 5, column 6: planner.M: pose \(x, y, z\) = \(3, 0.3, 0.5\) m, .* is out of reach"),
    ("boryga loop beyond reach", "name: b\nrobot: ur10e\nplanner: !BorygaConfig\n  B: [0.5, 0.3, 0.5]\n  M: [1.18, 0.3, 0.5]\n"
     "  E: [0.5, 0.5, 0.5]\n", r"planner: the loop path leaves the ur10e's reach at law time 4.542 s of 9.311 s, at \[1.1998, 0.3, 0.5\] m"),
    ("li point out of reach", "name: l\nrobot: ur10e\nplanner: !LiConfig\n  points: [[0.5, 0.2, 0.5], [0.7, 0.2, 0.5], [3.0, 0.2, 0.5]]\n",
     r"line 4, column 46: planner.points\[2\]: pose \(x, y, z\) = \(3, 0.2, 0.5\) m, .* is out of reach"),
    ("li point out of reach of the 4-dof robot", "name: l\nrobot: li_4dof\nplanner: !LiConfig\n  points: [[0.3, 0, 0], [0.5, 0.2, 0]]\n",
     r"planner.points\[1\]: point at \[0.5, 0.2, 0\] m is out of reach of the li_4dof robot: the wrist"),
    ("li tool acceleration zero", "name: l\nrobot: li_4dof\nplanner: !LiConfig\n  tool_acceleration_limit: 0.0\n", r"a_max"),
    ("li on a robot without acceleration limits", "name: l\nrobot: scara\nplanner: !LiConfig {}\n",
     r"acceleration_limit must be given: the robot has no default"),
]


@pytest.fixture
def earlier_run(tmp_path):
    """An output folder holding a sentinel: an earlier run's file that must not change."""
    folder = tmp_path / "earlier"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine")
    return folder


def folder_state(folder: Path) -> dict:
    return {path.name: path.read_bytes() for path in sorted(folder.iterdir())} if folder.exists() else {}


def assert_clean_exit(code, capsys, pattern, expected_code=cli.EXIT_BAD_INPUT, name=None):
    captured = capsys.readouterr()
    if name is not None:
        assert name in captured.err, captured.err  # the message names the file
    assert code == expected_code, captured.err
    assert "Traceback" not in captured.err + captured.out
    assert captured.err.startswith("drake-traj: ") or captured.err.startswith("usage:"), captured.err
    if captured.err.startswith("usage:"):  # argparse: its usage, then one line of error
        assert "error:" in captured.err.strip().splitlines()[-1], captured.err
    else:
        assert len(captured.err.strip().splitlines()) == 1, captured.err  # one paragraph
    assert re.search(pattern, captured.err), captured.err


@pytest.mark.parametrize("case, text, pattern", YAML_CASES, ids=[case[0] for case in YAML_CASES])
def test_bad_scenario_files(case, text, pattern, tmp_path, earlier_run, capsys):
    path = tmp_path / "scenario.yaml"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    before = folder_state(earlier_run)
    code = cli.main(["run", str(path), "--out", str(earlier_run)])
    assert_clean_exit(code, capsys, pattern, name=str(path))
    assert folder_state(earlier_run) == before


def test_scenario_messages_name_the_file_and_line(tmp_path):
    path = tmp_path / "scenario.yaml"
    path.write_text(quintic("  velocity_limit: [1.05, ", "  velocity_limit: [fast, "))
    with pytest.raises(ValueError, match=rf"{path}, line 12, column 20: planner.velocity_limit\[0\]"):
        load_scenario(path)


CLI_CASES = [
    ("out is a file", ["run", "quintic_ptp", "--out", "{file}"], r"output folder .* is a file"),
    ("out below a file", ["run", "quintic_ptp", "--out", "{file}/x"], r"cannot be created: .* is a file"),
    ("out holds a run", ["run", "quintic_ptp", "--out", "{run}"], r"holds an earlier run .* --overwrite"),
    ("out not writable", ["run", "quintic_ptp", "--out", "/proc/drake_traj_x"], r"output folder /proc/drake_traj_x"),
    ("port zero", ["run", "quintic_ptp", "--meshcat", "--port", "0"], r"--port must be a port number"),
    ("rate negative", ["run", "quintic_ptp", "--meshcat", "--rate", "-1"], r"--rate must be a positive"),
    ("wait timeout nan", ["run", "quintic_ptp", "--meshcat", "--wait-timeout", "nan"], r"--wait-timeout must be"),
    ("serve after negative", ["run", "quintic_ptp", "--meshcat", "--serve-after", "-1"],
     r"--serve-after must be a number of seconds >= 0, got -1"),
    ("serve after nan", ["run", "quintic_ptp", "--meshcat", "--serve-after", "nan"], r"--serve-after must be .*, got nan"),
    ("serve after without meshcat", ["run", "quintic_ptp", "--serve-after", "5"],
     r"--serve-after sets up the live view; add --meshcat"),
    ("show an unknown name", ["show", "nosuch"], r"no shipped scenario of that name; shipped: .*pajak_sim3.*quintic_ptp"),
    ("unknown option", ["run", "quintic_ptp", "--fast"], r"unrecognized arguments: --fast"),
    ("unknown command", ["fly"], r"invalid choice: 'fly'"),
    ("port not a number", ["run", "quintic_ptp", "--port", "seven"], r"--port: invalid int value: 'seven'"),
    ("unknown scenario name", ["run", "nosuch"], r"no scenario file 'nosuch' and no shipped scenario"),
    ("missing scenario file", ["run", "nowhere/x.yaml"], r"scenario file nowhere/x.yaml not found"),
    ("scenario is a folder", ["run", "{dir}.yaml"], r"is a folder, not a scenario file"),
    ("no variant", ["run", str(DIAGRAMS / "pajak.yaml")], r"no variant was given; its variants are \['sim1', 'sim2', 'sim3', 'ur3e',"),
    ("unknown variant", ["run", str(DIAGRAMS / "pajak.yaml"), "--variant", "sim4"], r"there is no variant 'sim4'"),
    ("variant of a single file", ["run", "quintic_ptp", "--variant", "sim3"], r"holds one scenario, not variants"),
    ("rate without meshcat", ["run", "quintic_ptp", "--rate", "2"], r"--rate sets up the live view; add --meshcat"),
    ("out empty", ["run", "quintic_ptp", "--out", ""], r"--out must name a folder"),
    ("out holds other files", ["run", "quintic_ptp", "--out", "{foreign}"], r"holds files that are not a drake-traj run \(notes.txt\)"),
    ("scenario is a device", ["run", "/dev/null"], r"scenario file /dev/null is not a regular file"),
    ("scenario is a loop of links", ["run", "{loop}.yaml"], r"is a broken link or a loop of links"),
    ("out is a loop of links", ["run", "quintic_ptp", "--out", "{loop}"], r"output folder .* is a broken link or a loop of links"),
    ("scenario path too long", ["run", "a" * 6000 + ".yaml"], r"scenario file a{80}\.\.\. cannot be used: File name too long"),
    ("bench count huge", ["bench", "--count", "99999999999", "--workers", "1"], r"count \(--count\) must be a whole number from 0 to 10000"),
]


@pytest.mark.parametrize("case, argv, pattern", CLI_CASES, ids=[case[0] for case in CLI_CASES])
def test_bad_command_lines(case, argv, pattern, tmp_path, earlier_run, capsys):
    file = tmp_path / "a_file"
    file.write_text("x")
    (earlier_run / "result.npz").write_bytes(b"an earlier run")
    (tmp_path / "folder.yaml").mkdir()
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    for name in ("loop", "loop.yaml"):
        (tmp_path / name).symlink_to(tmp_path / name)
    argv = [arg.format(file=file, run=earlier_run, dir=tmp_path / "folder", foreign=foreign, loop=tmp_path / "loop")
            for arg in argv]
    before = folder_state(earlier_run)
    assert_clean_exit(cli.main(argv), capsys, pattern)
    assert folder_state(earlier_run) == before


def quintic_plan():
    ur10e = get_robot("ur10e")
    return plan_synchronized_quintic(ur10e.home_configuration, [[-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]], 1.05, 1.40)


def quintic_planner():
    """A fresh planner system of :func:`quintic_plan` (a planner is used in one diagram only)."""
    return QuinticPtpPlanner(quintic_plan(), 1.05, 1.4)


@functools.cache
def short_result() -> SimulationResult:
    """The result of a 10 mrad move (a fraction of a second of simulation), made once."""
    ur10e = get_robot("ur10e")
    planner = QuinticPtpPlanner(plan_synchronized_quintic(ur10e.home_configuration, [ur10e.home_configuration + 0.01],
                                                          1.05, 1.40), 1.05, 1.4)
    return simulate(planner, settle_time=0.01)


def used_twice():
    planner = quintic_planner()
    build_station(planner)
    simulate(planner)


UR10E_HOME = get_robot("ur10e").home_configuration
GOAL = [[-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]]

API_CASES = [
    ("quintic plan list", lambda: QuinticPtpPlanner(plan=[1, 2], velocity_limit=1, acceleration_limit=1), TypeError, r"plan must be a QuinticLaw"),
    ("pajak q_initial text", lambda: PajakPlanner(paper_parameters(3), ["a"] * 6), ValueError, r"q_initial"),
    ("pajak q_initial short", lambda: PajakPlanner(paper_parameters(3), [0.0] * 5), ValueError, r"q_initial must have shape \(6,\)"),
    ("simulate not a planner", lambda: simulate("planner"), TypeError, r"planner must be a PlannerSystem"),
    ("robot as text", lambda: make_planner(QuinticConfig(goals=[[0.0] * 6]), "ur10e", [0.0] * 6), TypeError, r"robot must be a Robot"),
    ("q_initial wrong shape", lambda: make_planner(QuinticConfig(goals=[[0.0] * 6]), get_robot("ur10e"), [0.0] * 4), ValueError,
     r"q_initial must have shape \(6,\)"),
    ("config not a config", lambda: make_planner({"goals": []}, get_robot("ur10e"), [0.0] * 6), TypeError, r"config must be one of"),
    ("unknown robot", lambda: get_robot("puma"), ValueError, r"robot must be one of"),
    ("override out of range", lambda: SpeedOverride([0.0], [1.5]).validate(), ValueError, r"speed_override.values must be in \[0, 1\]"),
    ("override constant out of range", lambda: simulate(QuinticPtpPlanner(quintic_plan(), 1.05, 1.4), speed_override=2.0), ValueError,
     r"speed_override must be in \[0, 1\]"),
    ("load_scenario a number", lambda: load_scenario(123), TypeError, r"path must be a file path"),
    ("pajak waypoints five values", lambda: PajakConfig(waypoints=[[0.1, 0.2, 0.3, 0.0, 0.0]]).validate(), ValueError,
     r"waypoints must have shape \(w, 6\)"),
    ("quintic limits negative", lambda: plan_synchronized_quintic([0.0] * 6, [[0.1] * 6], -1.0, 1.4), ValueError, r"velocity_limit"),
    ("gains too short", lambda: ControllerGains(kp=[1.0, 2.0]).for_robot(get_robot("ur10e")), ValueError, r"controller.kp must have 6"),
    ("plant config text", lambda: build_station(QuinticPtpPlanner(quintic_plan(), 1.05, 1.4), plant_config="fast"), TypeError,
     r"plant_config must be a MultibodyPlantConfig"),
    ("station robot mismatch", lambda: build_station(QuinticPtpPlanner(quintic_plan(), 1.05, 1.4), robot=get_robot("scara")), ValueError,
     r"the planner has 6 joints, robot scara has 3"),
    ("scenario duration as text", lambda: Scenario(max_duration="10").validate(), ValueError,
     r"max_duration must be a number, got str '10'"),
    ("li points of two numbers", lambda: make_planner(LiConfig(points=[[0.1, 0.2], [0.3, 0.4]]), get_robot("ur10e"),
                                                      get_robot("ur10e").home_configuration), ValueError,
     r"points must be a list of at least two \[x, y, z\] rows \[m\], got shape \(2, 2\)"),
    ("pajak on another robot", lambda: make_planner(paper_parameters(3), get_robot("li_4dof"), [0.0] * 4), ValueError,
     r"the Pająk planner runs on a 6-axis arm with task-space kinematics, not on 'li_4dof'"),
    # numbers given as text or booleans are refused, not converted
    ("quintic goals as text", lambda: make_planner(QuinticConfig(goals=[[str(v) for v in GOAL[0]]]), get_robot("ur10e"), UR10E_HOME),
     ValueError, r"goals must be a real number or an array of real numbers .*found str '-0.9'"),
    ("pajak waypoints as text", lambda: PajakConfig(waypoints=[["-0.175", "-0.525", "0.730", "3.14", "0.0", "2.35"]]).validate(),
     ValueError, r"waypoints must be .*found str '-0.175'"),
    ("limits as booleans", lambda: make_planner(QuinticConfig(goals=GOAL, velocity_limit=[True] * 6), get_robot("ur10e"), UR10E_HOME),
     ValueError, r"velocity_limit must be .*found bool True"),
    ("feedforward as text", lambda: ControllerGains(feedforward_acceleration="no").for_robot(get_robot("ur10e")), ValueError,
     r"controller.feedforward_acceleration must be True or False, got str 'no'"),
    ("gains as text", lambda: ControllerGains(kp="abc").for_robot(get_robot("ur10e")), ValueError,
     r"controller.kp must be .*found str 'abc'"),
    # simulate: every argument checked before the run
    ("tracking tolerance NaN", lambda: simulate(quintic_planner(), tracking_tolerance=math.nan), ValueError,
     r"tracking_tolerance must be finite \[m\], got nan"),
    ("tracking tolerance negative", lambda: simulate(quintic_planner(), tracking_tolerance=-1), ValueError,
     r"tracking_tolerance must be > 0 \[m\], got -1.0"),
    ("tracking tolerance text", lambda: simulate(quintic_planner(), tracking_tolerance="5 mm"), ValueError,
     r"tracking_tolerance must be a real number \[m\], found str '5 mm'"),
    ("log period off the plant's steps", lambda: simulate(quintic_planner(), log_period=0.0015), ValueError,
     r"log_period must be a whole multiple of plant.time_step = 0.001 s .*got 0.0015 s"),
    ("log period text", lambda: simulate(quintic_planner(), log_period="0.001"), ValueError,
     r"log_period must be a real number \[s\], found str '0.001'"),
    ("speed override text", lambda: simulate(quintic_planner(), speed_override="half"), ValueError,
     r"speed_override must be a real number .*found str 'half'"),
    ("progress not a function", lambda: simulate(quintic_planner(), progress=5), TypeError,
     r"progress must be a function progress\(t\) or None, got int: 5"),
    ("add_systems not a function", lambda: simulate(quintic_planner(), add_systems=5), TypeError,
     r"add_systems must be a function add_systems\(builder, station\) or None, got int"),
    ("planner used twice", used_twice, ValueError,
     r"planner is already part of a diagram .*: a planner system can be used in one diagram .*make a new one"),
    # the scenario API
    ("top-level make_planner given a config", lambda: drake_traj.make_planner(QuinticConfig(goals=GOAL), get_robot("ur10e"), UR10E_HOME),
     TypeError, r"scenario must be a Scenario, got QuinticConfig and 2 more arguments: .*"
                r"drake_traj.planners.make_planner\(config, robot, q_initial\)"),
    ("make_planner None", lambda: drake_traj.make_planner(None), TypeError, r"scenario must be a Scenario, got NoneType"),
    ("make_planner a name", lambda: drake_traj.make_planner("quintic_ptp"), TypeError,
     r"scenario must be a Scenario, got str: 'quintic_ptp' \(load one with drake_traj.load_scenario"),
    ("make_station None", lambda: make_station(None), TypeError, r"scenario must be a Scenario, got NoneType"),
    ("make_station a file name", lambda: make_station("x.yaml"), TypeError,
     r"scenario must be a Scenario, got str: 'x.yaml' \(load one with drake_traj.load_scenario"),
    ("variant a list", lambda: load_scenario(DIAGRAMS / "pajak.yaml", ["sim1"]), TypeError, r"variant must be a str, got list"),
    ("scenario log period text", lambda: make_station(Scenario(planner=QuinticConfig(goals=GOAL), log_period="0.001")), ValueError,
     r"log_period must be a real number \[s\], found str '0.001'"),
    ("scenario q_initial text", lambda: drake_traj.make_planner(Scenario(q_initial=["a"] * 6)), ValueError,
     r"^q_initial must be .*found str 'a'"),
    ("toppra grid points fraction", lambda: make_planner(ToppraConfig(path=[UR10E_HOME + 0.1], grid_points=2.5), get_robot("ur10e"),
                                                         UR10E_HOME), ValueError, r"grid_points must be a whole number >= 3, got 2.5"),
    ("toppra grid points two", lambda: make_planner(ToppraConfig(path=[UR10E_HOME + 0.1], grid_points=2), get_robot("ur10e"),
                                                    UR10E_HOME), ValueError, r"grid_points must be a whole number >= 3, got 2"),
    ("tcp_pose of None", lambda: get_robot("ur10e").tcp_pose(None), ValueError, r"q must be .*found NoneType None"),
    ("tcp_pose short q", lambda: get_robot("scara").tcp_pose([0.0, 0.0]), ValueError, r"q must have shape \(\.\.\., 3\)"),
    # results
    ("result array None", lambda: SimulationResult(**{**vars(short_result()), "q_meas": None}), ValueError,
     r"q_meas must be .*found NoneType None"),
    ("result array short rows", lambda: SimulationResult(**{**vars(short_result()), "tau": short_result().tau[:, :3]}), ValueError,
     r"tau has 3 joints, t and q_ref 6"),
    ("load None", lambda: SimulationResult.load(None), TypeError, r"directory must be a folder path \(str or Path\), got NoneType"),
    ("export to None", lambda: short_result().export(None, "csv"), TypeError, r"path must be a file path \(str or Path\), got NoneType"),
    ("figures to None", lambda: short_result().save_figures(None), TypeError, r"directory must be a folder path"),
    ("figures into a file", lambda: short_result().save_figures(__file__), ValueError,
     r"directory: output folder .*test_bad_input.py is a file, not a folder"),
]


@pytest.mark.parametrize("case, call, error, pattern", API_CASES, ids=[case[0] for case in API_CASES])
def test_bad_python_arguments(case, call, error, pattern):
    with pytest.raises(error, match=pattern):
        call()


@pytest.fixture(scope="module")
def saved_run(tmp_path_factory):
    """A real result folder (a short quintic move that times out: failure and NaN duration)."""
    result = simulate(QuinticPtpPlanner(quintic_plan(), 1.05, 1.4), max_duration=0.2)
    return result.save(tmp_path_factory.mktemp("saved"))


def damaged(folder: Path, tmp_path: Path, how: str) -> Path:
    target = tmp_path / how
    target.mkdir()
    data = (folder / "result.npz").read_bytes()
    if how == "truncated":
        (target / "result.npz").write_bytes(data[: len(data) // 2])
    elif how == "random bytes":
        (target / "result.npz").write_bytes(np.random.default_rng(0).bytes(2000))
    elif how == "empty":
        (target / "result.npz").write_bytes(b"")
    else:
        with np.load(folder / "result.npz") as archive:
            arrays = {name: archive[name] for name in archive.files}
        if how == "missing array":
            del arrays["q_ref"]
        elif how == "unequal lengths":
            arrays["q_meas"] = arrays["q_meas"][:-3]
        elif how == "bad metadata":
            arrays["meta"] = np.array("{not json")
        elif how == "text array":
            arrays["tau"] = np.array(["x"] * len(arrays["t"]))
        elif how == "foreign metadata":
            arrays["meta"] = np.array(json.dumps({"name": "x", "color": "red"}))
        np.savez(target / "result.npz", **arrays)
    return target


@pytest.mark.parametrize("how, pattern", [
    ("truncated", r"cannot be read"), ("random bytes", r"cannot be read"), ("empty", r"cannot be read"),
    ("missing array", r"is not a complete result: it has no 'q_ref'"),
    ("unequal lengths", r"the array 'q_meas' has \d+ rows"), ("bad metadata", r"cannot be read|metadata"),
    ("text array", r"the array 'tau'"), ("foreign metadata", r"its metadata is not a result's"),
])
def test_damaged_result_files_name_the_file(saved_run, tmp_path, how, pattern):
    folder = damaged(saved_run, tmp_path, how)
    with pytest.raises(ResultFileError, match=pattern) as info:
        SimulationResult.load(folder)
    assert str(folder / "result.npz") in str(info.value)


def test_a_log_with_nan_has_not_succeeded():
    # NaN in a logged array is a failure, and the metrics carry it instead of skipping it
    arrays = vars(short_result())
    result = SimulationResult(**{**arrays, "q_meas": arrays["q_meas"].copy()})
    assert result.succeeded
    result.q_meas[5, 2] = math.nan
    metrics = result.metrics()
    assert not result.succeeded and not metrics.succeeded
    assert metrics.failure.startswith("the log is not finite: q_meas[5]")
    assert math.isnan(metrics.tracking_error_joint_max_rad)
    assert result.execution_failure(0.005).cause == "non-finite"


def test_missing_result_file_is_named(tmp_path):
    with pytest.raises(ResultFileError, match=f"no result file at {tmp_path / 'result.npz'}"):
        SimulationResult.load(tmp_path)


def test_a_failed_runs_metrics_are_strict_json(saved_run):
    def refuse(constant):
        raise AssertionError(f"non-standard JSON constant {constant}")

    metrics = json.loads((saved_run / "metrics.json").read_text(), parse_constant=refuse)
    assert metrics["succeeded"] is False and metrics["duration_s"] is None
    assert SimulationResult.load(saved_run).failure.cause == "timeout"


def test_an_impossible_run_is_refused_before_it_starts(tmp_path, capsys):
    # The reproduction: 10 rad/s and 200 rad/s^2 on the quintic scenario.
    path = tmp_path / "fast.yaml"
    path.write_text(quintic("  velocity_limit: [1.05, 1.05, 1.05, 1.05, 1.05, 1.05]", "  velocity_limit: [10, 10, 10, 10, 10, 10]"))
    assert cli.main(["run", str(path), "--out", str(tmp_path / "out")]) == cli.EXIT_BAD_INPUT
    assert "rated speed" in capsys.readouterr().err
    assert not (tmp_path / "out" / "result.npz").exists()


def test_a_run_the_arm_cannot_follow_is_a_failure():
    # Within the rated speeds, but an acceleration no drive can deliver (0.05 rad in 38 ms at
    # 200 rad/s²): the drives saturate.
    ur10e = get_robot("ur10e")
    planner = make_planner(QuinticConfig(goals=[ur10e.home_configuration + 0.05], velocity_limit=[2.0, 2.0, 3.0, 3.0, 3.0, 3.0],
                                         acceleration_limit=[200.0] * 6), ur10e, ur10e.home_configuration)
    result = simulate(planner, settle_time=0.1)
    assert not result.succeeded and result.failure.cause in ("saturation", "tracking")
    assert "joint" in result.failure.message or "TCP" in result.failure.message
    assert max(result.metrics().time_at_effort_limit_s) > 0.0


# ---- property test: the shipped scenarios mutated at random ------------------------------------

def _scalar(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return ".nan" if math.isnan(value) else (".inf" if value == math.inf else "-.inf" if value == -math.inf else repr(value))
    if isinstance(value, str):
        return json.dumps(value)
    return repr(value)


def emit(value, indent: int = 0) -> str:
    """YAML of nested dicts (a ``_tag`` key becomes the mapping's tag), lists and scalars."""
    pad = " " * indent
    if isinstance(value, dict):
        lines = []
        for key, item in value.items():
            if key == "_tag":
                continue
            if isinstance(item, dict):
                lines.append(f"{pad}{key}: {item.get('_tag', '')}{' {}' if len(item) <= ('_tag' in item) else ''}")
                if len(item) > ("_tag" in item):
                    lines.append(emit(item, indent + 2))
            else:
                lines.append(f"{pad}{key}: {emit(item)}")
        return "\n".join(lines)
    if isinstance(value, list):
        return "[" + ", ".join(emit(item) for item in value) + "]"
    return _scalar(value)


class _TagKeeper(yaml.SafeLoader):
    pass


_TagKeeper.add_multi_constructor("!", lambda loader, suffix, node: {"_tag": "!" + suffix, **loader.construct_mapping(node, deep=True)})

SHIPPED = {
    "quintic_ptp": yaml.load(QUINTIC, Loader=_TagKeeper),
    "boryga_loop_scara": yaml.load((DIAGRAMS / "boryga_loop.yaml").read_text(), Loader=_TagKeeper)["scara"],
    "pajak_sim3": yaml.load((DIAGRAMS / "pajak.yaml").read_text(), Loader=_TagKeeper)["sim3"],
}
WEIRD = st.sampled_from([math.nan, math.inf, -math.inf, -1.0, 0.0, 1e9, -1e9, "text", True, [], [1.0], None])


def paths_of(value, prefix=()):
    """Every (path, leaf or list) in a nested dict/list."""
    if isinstance(value, dict):
        for key, item in value.items():
            if key != "_tag":
                yield from paths_of(item, prefix + (key,))
    elif isinstance(value, list):
        yield prefix, value
        for index, item in enumerate(value):
            yield from paths_of(item, prefix + (index,))
    else:
        yield prefix, value


@st.composite
def mutated_scenario(draw):
    name = draw(st.sampled_from(sorted(SHIPPED)))
    document = json.loads(json.dumps(SHIPPED[name]))
    paths = [path for path, _ in paths_of(document) if path]
    path = draw(st.sampled_from(paths))
    parent = document
    for key in path[:-1]:
        parent = parent[key]
    action = draw(st.sampled_from(["delete", "weird", "shorten", "lengthen"]))
    leaf = path[-1]
    if action == "delete" and isinstance(parent, dict):
        del parent[leaf]
    elif action in ("shorten", "lengthen") and isinstance(parent[leaf], list) and parent[leaf]:
        parent[leaf] = parent[leaf][:-1] if action == "shorten" else parent[leaf] + [parent[leaf][-1]]
    else:
        parent[leaf] = draw(WEIRD)
    document["settle_time"] = 0.05
    return document


@settings(max_examples=60, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(mutated_scenario())
def test_mutated_scenarios_fail_cleanly_or_run_within_their_limits(tmp_path_factory, document):
    folder = tmp_path_factory.mktemp("mutated")
    path = folder / "scenario.yaml"
    path.write_text(emit({key: value for key, value in document.items() if value is not None}) + "\n")
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
        code = cli.main(["run", str(path), "--out", str(folder / "out")])
    err = stderr.getvalue()
    assert "Traceback" not in err and "internal error" not in err, err
    if code == cli.EXIT_BAD_INPUT:
        assert err.startswith("drake-traj: ") and str(path) in err or "scenario" in err, err
        return
    result = SimulationResult.load(folder / "out")
    for name in ("q_ref", "qd_ref", "qdd_ref", "q_meas", "tau"):
        assert np.all(np.isfinite(getattr(result, name))), name
    if code == cli.EXIT_OK:
        metrics = result.metrics()
        assert result.succeeded
        assert metrics.max_velocity_over_limit <= 1 + 1e-6 and metrics.max_acceleration_over_limit <= 1 + 1e-6
    else:
        assert code == cli.EXIT_RUN_FAILED and result.failure is not None


# ---- nothing lost: run folders, saving, signals -------------------------------------------------

def fake_run(folder: Path) -> dict:
    """A folder holding a run (manifest and result); returns its state."""
    folder.mkdir()
    (folder / "result.npz").write_bytes(b"the earlier run")
    (folder / "run.json").write_text(json.dumps({"files": ["result.npz"]}))
    return folder_state(folder)


def test_overwrite_keeps_the_earlier_run_when_the_new_input_is_bad(tmp_path, capsys):
    earlier = fake_run(tmp_path / "run")
    path = tmp_path / "bad.yaml"
    path.write_text(quintic("  velocity_limit: [1.05, ", "  velocity_limit: [.nan, "))
    assert cli.main(["run", str(path), "--out", str(tmp_path / "run"), "--overwrite"]) == cli.EXIT_BAD_INPUT
    assert folder_state(tmp_path / "run") == earlier
    assert "velocity_limit" in capsys.readouterr().err


def test_save_refuses_another_runs_folder(saved_run, tmp_path):
    result = SimulationResult.load(saved_run)
    earlier = fake_run(tmp_path / "other")
    with pytest.raises(OutputError, match=r"holds an earlier run .*; choose another directory, or pass overwrite=True"):
        result.save(tmp_path / "other")
    assert folder_state(tmp_path / "other") == earlier
    result.save(tmp_path / "other", overwrite=True)
    assert SimulationResult.load(tmp_path / "other").name == result.name


def test_a_log_whose_time_runs_backwards_is_refused(saved_run, tmp_path):
    with np.load(saved_run / "result.npz") as archive:
        arrays = {name: archive[name] for name in archive.files}
    arrays["t"] = arrays["t"][::-1].copy()
    (tmp_path / "t_reversed").mkdir()
    np.savez(tmp_path / "t_reversed" / "result.npz", **arrays)
    with pytest.raises(ResultFileError, match=r"result.npz: the log's times 't' do not increase"):
        SimulationResult.load(tmp_path / "t_reversed")


def test_signals_while_writing_wait_until_the_files_are_written():
    with commands.signals_held() as received:
        os.kill(os.getpid(), signal.SIGINT)
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(0.05)  # the handlers run here, and record instead of raising
    assert received == [signal.SIGINT, signal.SIGTERM]


def test_sigterm_stops_a_run_like_ctrl_c_with_its_own_exit_code(tmp_path, monkeypatch, capsys):
    def terminated(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(1.0)  # the SIGTERM handler raises KeyboardInterrupt here
        raise AssertionError("SIGTERM did not stop the run")

    monkeypatch.setattr(commands, "simulate", terminated)
    assert cli.main(["run", "quintic_ptp", "--out", str(tmp_path / "x")]) == cli.EXIT_TERMINATED == 143
    assert "terminated (SIGTERM)" in capsys.readouterr().err
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # restored


def test_a_terminal_that_cannot_show_a_character_gets_an_escape_not_an_error(tmp_path):
    # PYTHONIOENCODING=ascii (an old terminal, a pipe into a legacy tool): "Pająk" has an "ą"
    listed = subprocess.run([sys.executable, "-m", "drake_traj.cli", "list"], capture_output=True, cwd=tmp_path,
                            env=dict(os.environ, PYTHONIOENCODING="ascii"), timeout=120)
    assert listed.returncode == cli.EXIT_OK, listed.stderr
    assert b"Paj\\u0105k 2024 simulation 3" in listed.stdout and not listed.stderr


def test_debug_shows_the_traceback(tmp_path, capsys):
    assert cli.main(["--debug", "run", str(tmp_path / "nowhere.yaml")]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err and "not found" in err


# ---- the new surfaces: the cell's TCP, refusals beside a run, located errors ------------------

def test_a_cells_tcp_other_than_the_planners_robot_is_refused_before_the_run():
    from drake_traj.cell import Cell, Tool

    bare = make_planner(QuinticConfig(goals=GOAL), get_robot("ur10e"), UR10E_HOME)
    with pytest.raises(ValueError, match=r"^cell.tool.tcp_xyz: the cell's tool has its TCP at tcp_xyz \[0, 0, 0.3\] m, "
                                         r"tcp_rpy \[0, 0, 0\] rad, but the planner's robot ur10e has its TCP at xyz "
                                         r"\[0, 0, 0\] m, rpy \[0, 0, 0\] rad .*robot.with_tcp") as caught:
        simulate(bare, cell=Cell(tool=Tool(tcp_xyz=[0, 0, 0.3])))
    assert caught.value.field == ("cell", "tool", "tcp_xyz")
    scenario = load_scenario("quintic_ptp")  # its robot's TCP is its own cell's (the flange)
    with pytest.raises(ValueError, match=r"^cell.tool.tcp_rpy: .*tcp_rpy \[0, 0, 0.5\] rad"):
        simulate(scenario, cell=Cell(tool=Tool(tcp_rpy=[0, 0, 0.5])))
    # the same TCP in both runs
    tool = Tool(tcp_xyz=[0, 0, 0.15])
    planner = make_planner(QuinticConfig(goals=[UR10E_HOME + 0.01]), get_robot("ur10e").with_tcp([0, 0, 0.15], [0, 0, 0]),
                           UR10E_HOME)
    assert simulate(planner, cell=Cell(tool=tool), settle_time=0.01).succeeded


def test_a_robots_own_error_is_named_at_its_field_not_the_tools():
    from drake_traj.robots.custom import DhArm

    for call in (lambda scenario: scenario.validate(), simulate):
        with pytest.raises(ValueError, match=r"^robot.dh is missing") as caught:
            call(Scenario(robot=DhArm(name="bare")))
        assert caught.value.field == ("robot", "dh")


def test_a_cell_that_is_not_a_cell_is_named():
    for call in (lambda scenario: scenario.validate(), simulate, make_station):
        scenario = Scenario(name="s")
        scenario.cell = "table"
        with pytest.raises(TypeError, match=r"scenario 's': cell must be a drake_traj.cell.Cell .*got str: 'table'"):
            call(scenario)


def test_exporting_into_the_runs_folder_itself_asks_for_a_file_name(saved_run, capsys):
    before = folder_state(saved_run)
    code = cli.main(["export", str(saved_run), "--format", "csv", "--out", str(saved_run)])
    err = capsys.readouterr().err
    assert code == cli.EXIT_BAD_INPUT and f"--out {saved_run} is a folder; give a file name" in err, err
    assert "--overwrite" not in err and folder_state(saved_run) == before


def test_drives_that_cannot_hold_the_start_are_named_before_the_run(tmp_path, capsys):
    # torque limits of 1e-3 N m: the shoulder cannot hold the arm (before: "collision ... and table")
    scenario = load_scenario(DIAGRAMS / "example_arm.yaml", "quintic")
    scenario.robot.effort_limits = [1e-3] * 6
    with pytest.raises(ValueError, match=r"robot.effort_limits\[1\]: joint 2 \(shoulder_lift_joint\) of the example_arm "
                                         r"cannot hold the start configuration against gravity: it needs .* N m there, "
                                         r"beyond its effort limit of ±0.001 N m") as caught:
        simulate(scenario)
    assert caught.value.cause == "saturation" and caught.value.field == ("robot", "effort_limits", 1)
    # 12.5 kg at the end of a 10 m TCP, from the command line: at the payload's line, nothing run
    path = tmp_path / "heavy.yaml"
    path.write_text(QUINTIC + "cell:\n  tool:\n    tcp_xyz: [10, 0, 0]\n    mass: 12.5\n    center_of_mass: [10, 0, 0]\n")
    line = path.read_text().splitlines().index("    mass: 12.5") + 1
    assert_clean_exit(cli.main(["run", str(path), "--out", str(tmp_path / "out")]), capsys,
                      rf"line {line}, column \d+: cell.tool.mass: joint 2 \(shoulder_lift_joint\) of the ur10e cannot hold "
                      r"the start configuration against gravity with the tool's 12.5 kg payload: it needs -771.8 N m there, "
                      r"beyond its effort limit of ±330 N m")
    assert not (tmp_path / "out").exists()


def test_a_refusal_never_removes_an_earlier_run(tmp_path, capsys):
    # C19: the start configuration inside a box; --overwrite on a good run's folder
    folder = tmp_path / "run"
    folder.mkdir()
    for name, content in (("result.npz", b"the earlier run"), ("metrics.json", b"{}"), ("joints.png", b"png")):
        (folder / name).write_bytes(content)
    (folder / "run.json").write_text(json.dumps({"files": ["joints.png", "metrics.json", "result.npz"],
                                                 "scenario": "earlier", "failure": None}))
    earlier = folder_state(folder)
    centre = get_robot("ur10e").tool_position(UR10E_HOME)
    path = tmp_path / "c19.yaml"
    path.write_text(QUINTIC + "cell:\n  obstacles:\n  - !Box {name: crate, size: [0.2, 0.2, 0.2], "
                              f"xyz: [{centre[0]:.4f}, {centre[1]:.4f}, {centre[2]:.4f}]}}\n")
    code = cli.main(["run", str(path), "--out", str(folder), "--overwrite"])
    err = capsys.readouterr().err
    assert code == cli.EXIT_BAD_INPUT and "crate" in err, err
    assert f"the earlier run in {folder} is kept" in err, err
    after = folder_state(folder)
    assert {name: after[name] for name in earlier if name != "run.json"} == {
        name: content for name, content in earlier.items() if name != "run.json"}  # the earlier run intact
    assert set(after) == set(earlier) | {"refusal.png"}
    manifest = json.loads(after["run.json"])
    assert manifest["files"] == ["joints.png", "metrics.json", "refusal.png", "result.npz"]  # a new run replaces all
    assert manifest["scenario"] == "earlier" and manifest["failure"] is None
    assert manifest["refusal"]["failure"]["cause"] == "collision" and "crate" in manifest["refusal"]["failure"]["message"]
    # a refusal where there was only a refusal replaces it
    code = cli.main(["run", str(path), "--out", str(tmp_path / "refused")])
    code = cli.main(["run", str(path), "--out", str(tmp_path / "refused"), "--overwrite"])
    capsys.readouterr()
    assert code == cli.EXIT_BAD_INPUT and sorted(folder_state(tmp_path / "refused")) == ["refusal.png", "run.json"]
