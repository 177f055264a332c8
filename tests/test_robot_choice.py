"""A scenario's ``robot:``: a known name, or an arm of one's own (``!CustomArm``, ``!DhArm``), each
malformed one refused at its line naming the field; the tool payload against the robot's rating."""

import textwrap

import numpy as np
import pytest

from pydrake.systems.framework import DiagramBuilder

from drake_traj import QuinticConfig, RuckigConfig, load_scenario
from drake_traj.cell import Cell, CellChecker, Tool
from drake_traj.errors import Cause, DrakeTrajError
from drake_traj.planners import make_planner
from drake_traj.planners.pajak.parameters import paper_parameters
from drake_traj.planners.quintic import QuinticPtpPlanner, plan_synchronized_quintic
from drake_traj.robots import ROBOT_NAMES, UR10e, get_robot
from drake_traj.robots.custom import CustomArm, DhArm, resolve_robot
from drake_traj.scenario import ScenarioError
from drake_traj.station import add_station

GOAL = "[[-1.2, -1.6, -2.0, -0.9, 1.57, 0.8]]"
# a DH table of six rows [d, a, alpha, theta offset] (the UR10e's lengths) and complete joint data
DH_ARM = {"name": "six_axis", "dh": [[0.1807, 0, 1.5708, 0], [0, -0.6127, 0, 0], [0, -0.57155, 0, 0],
                                      [0.17415, 0, 1.5708, 0], [0.11985, 0, -1.5708, 0], [0.11655, 0, 0, 0]],
          "lower": [-6.0] * 6, "upper": [6.0] * 6, "velocity_limits": [2.0] * 6, "acceleration_limits": [3.0] * 6,
          "effort_limits": [300, 300, 150, 50, 50, 50], "masses": [7, 13, 4, 2, 2, 0.6]}


class ThreeKiloArm(UR10e):
    """The UR10e's kinematics rated for 3 kg (a test robot: a second 6-axis arm with its own rating)."""

    def __init__(self):
        super().__init__()
        self.name, self.rated_payload = "three_kilo_arm", 3.0


def scenario(tmp_path, robot_yaml: str, cell_yaml: str = "") -> object:
    path = tmp_path / "arm.yaml"
    path.write_text(f"name: arm\n{robot_yaml}\nplanner: !QuinticConfig\n  goals: {GOAL}\n{cell_yaml}")
    return path


def test_an_unknown_robot_name_lists_the_known_ones_with_reach_and_payload(tmp_path):
    with pytest.raises(ScenarioError, match=r"arm.yaml, line 2, column 8: robot: robot must be one of the known "
                                            r"robots, got 'ur5'; known: ur10e \(6 joints, reach 1.3 m, payload 12.5 kg\)"
                       ) as caught:
        load_scenario(scenario(tmp_path, "robot: ur5"))
    assert caught.value.field == ("robot",)
    for name in ROBOT_NAMES:
        assert f"{name} ({get_robot(name).num_joints} joints" in str(caught.value)


def yaml_of(tag: str, fields: dict) -> str:
    lines = (f"{key}: {value}".replace("'", "") for key, value in fields.items())  # '.nan' -> .nan
    return f"robot: !{tag}\n" + textwrap.indent("\n".join(lines), "  ")


@pytest.mark.parametrize("tag, change, field, words", [
    ("DhArm", {"dh": [[0.1, 0, 0, 0]] * 5}, ("robot", "dh"), r"robot.dh must be 6 rows of 4 numbers .* got shape \(5, 4\)"),
    ("DhArm", {"dh": [[0.1, 0, 0, 0]] * 5 + [[0.1, 0, 0]]}, ("robot", "dh"), r"robot.dh .* rows must have the same length"),
    ("DhArm", {"dh": [[0.1, 0, 0, 0]] * 5 + [[0.1, ".nan", 0, 0]]}, ("robot", "dh", 5, 1), r"robot.dh\[5\]\[1\] must be finite"),
    ("DhArm", {"convention": "craig"}, ("robot", "convention"), r"robot.convention must be one of \('standard', 'modified'\)"),
    ("DhArm", {"effort_limits": []}, ("robot", "effort_limits"), r"robot.effort_limits is missing: a custom arm needs 6"),
    ("DhArm", {"masses": [1, 1, 1, 1, 1]}, ("robot", "masses"), r"robot.masses must have shape \(6,\)"),
    ("DhArm", {"velocity_limits": [2, 2, 2, 0, 2, 2]}, ("robot", "velocity_limits", 3), r"robot.velocity_limits\[3\] must be positive"),
    ("DhArm", {"upper": [6, 6, -7, 6, 6, 6]}, ("robot", "upper", 2), r"robot.upper\[2\] = -7 rad must be above robot.lower\[2\]"),
    ("DhArm", {"inertias": [[1, 1, 1]] * 6}, ("robot", "inertias"), r"robot.inertias must be 6 rows of 6 numbers"),
    ("DhArm", {"name": "ur10e"}, ("robot", "name"), r"robot.name 'ur10e' is a known robot's name"),
    ("DhArm", {"payload": -1}, ("robot", "payload"), r"robot.payload must be positive \[kg\] \(leave it out"),
    ("DhArm", {"payload": 0}, ("robot", "payload"), r"robot.payload must be positive \[kg\]"),
    ("DhArm", {"payload": ".nan"}, ("robot", "payload"), r"robot.payload must be finite"),
    ("DhArm", {"link_radius": ".nan"}, ("robot", "link_radius"), r"robot.link_radius must be finite"),
    ("DhArm", {"masses": "heavy"}, ("robot", "masses"), r"expected a list, found text 'heavy'"),
    ("CustomArm", {"model_file": "arm.urdf"}, ("robot", "acceleration_limits"), r"robot.acceleration_limits is missing"),
    ("CustomArm", {"acceleration_limits": [3] * 6}, ("robot", "model_file"), r"robot.model_file is missing"),
    ("CustomArm", {"model_file": "arm.urdf", "acceleration_limits": [3] * 6, "effort_limits": [1, 1, 1, 1, 1, ".inf"]},
     ("robot", "effort_limits", 5), r"robot.effort_limits\[5\] must be finite \[N m\], got inf"),
    ("CustomArm", {"model_file": "arm.urdf", "acceleration_limits": [3] * 6, "mass": 3}, ("robot", "mass"),
     r"robot.mass: unknown field; CustomArm has"),
])
def test_a_malformed_custom_arm_is_refused_at_its_line_naming_the_field(tmp_path, tag, change, field, words):
    fields = {**(DH_ARM if tag == "DhArm" else {}), **change}
    path = scenario(tmp_path, yaml_of(tag, fields))
    with pytest.raises(ScenarioError, match=words) as caught:
        load_scenario(path)
    assert caught.value.field[:len(field)] == field
    # the field's line; a missing field: the robot field's (line 2)
    line = next((k for k, text in enumerate(path.read_text().splitlines(), 1)
                 if k > 2 and text.strip().startswith(f"{field[1]}:")), 2)
    assert f"arm.yaml, line {line}," in str(caught.value)


def test_a_custom_arms_model_file_is_found_beside_the_scenario(tmp_path):
    path = scenario(tmp_path, yaml_of("CustomArm", {"model_file": "models/my_arm.urdf", "acceleration_limits": [3] * 6}))
    with pytest.raises(ScenarioError, match=rf"robot.model_file {tmp_path / 'models' / 'my_arm.urdf'} is not a file"):
        load_scenario(path)


def test_a_mapping_without_a_tag_asks_for_one(tmp_path):
    with pytest.raises(ScenarioError, match=r"robot: a mapping needs a tag naming its type, one of !CustomArm, !DhArm"):
        load_scenario(scenario(tmp_path, "robot: {model_file: arm.urdf}"))


def test_resolving_a_config_checks_it_in_python_too():
    with pytest.raises(DrakeTrajError, match=r"robot.dh is missing") as caught:
        resolve_robot(DhArm(name="x", dh=[]))
    assert caught.value.field == ("robot", "dh")
    with pytest.raises(DrakeTrajError, match=r"robot.lower must have shape \(6,\)"):
        resolve_robot(CustomArm(model_file="arm.urdf", lower=[0.0] * 7, acceleration_limits=[1.0] * 6))
    assert resolve_robot("ur10e") is get_robot("ur10e")


def test_the_payload_is_checked_against_the_robots_own_rating():
    robot = ThreeKiloArm()
    Cell(tool=Tool(mass=2.9, tcp_xyz=[0, 0, 0.1])).validate(robot)
    Cell(tool=Tool(mass=12.0, tcp_xyz=[0, 0, 0.1])).validate()  # the UR10e's 12.5 kg
    heavy = Cell(tool=Tool(mass=3.5, tcp_xyz=[0, 0, 0.1]))
    for check in (lambda: heavy.validate(robot), lambda: CellChecker(robot, heavy)):
        with pytest.raises(DrakeTrajError, match=r"cell.tool.mass = 3.5 kg is above the three_kilo_arm robot's rated "
                                                 r"payload of 3 kg") as caught:
            check()
        assert caught.value.field == ("cell", "tool", "mass") and caught.value.cause is Cause.INFEASIBLE


def test_an_unrated_arm_takes_no_payload_but_a_point_robot_does():
    unrated = ThreeKiloArm()
    unrated.rated_payload = None
    with pytest.raises(DrakeTrajError, match=r"the three_kilo_arm robot has no rated payload, so it takes no tool mass"):
        Cell(tool=Tool(mass=1.0, tcp_xyz=[0, 0, 0.1])).validate(unrated)
    Cell().validate(unrated)  # no payload: nothing to rate
    Cell(tool=Tool(mass=5.0)).validate(get_robot("scara"))


def test_a_payload_above_the_scenario_robots_rating_is_refused_at_its_line(tmp_path):
    path = scenario(tmp_path, "robot: ur10e", "cell:\n  tool:\n    tcp_xyz: [0, 0, 0.2]\n    mass: 13.0\n")
    with pytest.raises(ScenarioError, match=r"arm.yaml, line 8, column 11: cell.tool.mass = 13 kg is above the ur10e "
                                            r"robot's rated payload of 12.5 kg"):
        load_scenario(path)
    assert np.isclose(get_robot("ur10e").rated_payload, 12.5)


@pytest.mark.parametrize("config", [QuinticConfig(goals=[[-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]]),
                                    RuckigConfig(goals=[[-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]]), paper_parameters(3)])
def test_a_station_runs_a_planner_on_the_robot_it_was_made_for(config):
    arm = ThreeKiloArm()
    planner = make_planner(config, arm, arm.home_configuration)
    assert planner.robot is arm
    assert add_station(DiagramBuilder(), planner).robot is arm  # no robot given: the planner's
    with pytest.raises(DrakeTrajError, match=r"the planner was made for the three_kilo_arm robot, not for robot ur10e") as caught:
        add_station(DiagramBuilder(), make_planner(config, arm, arm.home_configuration), robot=get_robot("ur10e"))
    assert caught.value.field == ("robot",)


def test_a_planner_refuses_a_robot_of_another_joint_count():
    plan = plan_synchronized_quintic(get_robot("ur10e").home_configuration, [[-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]], 1.05, 1.4)
    with pytest.raises(DrakeTrajError, match=r"the planner has 6 joints, robot scara has 3"):
        QuinticPtpPlanner(plan, 1.05, 1.4, robot=get_robot("scara"))
