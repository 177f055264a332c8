"""Arm descriptions as vendors publish them, run as shipped: links without inertia (estimated from
their shapes at a stated density), joints off the base-to-tool chain held, REP-199's ``base``
frame at the world's origin, xacro's ``$(find)`` and typed arguments, STL and COLLADA visual
meshes drawn. The description is our own tiny one with each of those traits
(tests/data/descriptions/bare_arm_description)."""

import json
import math
import shutil
import textwrap
from pathlib import Path

import numpy as np
import pytest
from pydrake.geometry import Role

from drake_traj import cli, load_scenario, simulate
from drake_traj.cell.clearance import CellChecker
from drake_traj.errors import DrakeTrajError
from drake_traj.robots.chain_arm import ChainArm
from drake_traj.robots.custom import CustomArm
from drake_traj.robots.inertia_estimate import DEFAULT_DENSITY
from drake_traj.scenario import ScenarioError

PACKAGE = Path(__file__).parent / "data" / "descriptions" / "bare_arm_description"
URDF = PACKAGE / "urdf" / "bare_arm.urdf"
XACRO = PACKAGE / "urdf" / "bare_arm.urdf.xacro"
LINKS = ("link_1", "link_2", "link_3", "link_4", "link_5", "link_6", "tool0")
# each moving link's collision shape (tool0: its visual sphere) [m]: volume and centre in the link
VOLUMES = dict(link_1=math.pi * 0.06 ** 2 * 0.2, link_2=0.08 * 0.08 * 0.4, link_3=0.06 * 0.06 * 0.3,
               link_4=math.pi * 0.04 ** 2 * 0.1, link_5=4 / 3 * math.pi * 0.04 ** 3, link_6=math.pi * 0.03 ** 2 * 0.02,
               tool0=4 / 3 * math.pi * 0.005 ** 3)
Q = np.random.default_rng(5).uniform(-2.5, 2.5, (8, 6))  # [rad]


def bare_arm(path=URDF, **arguments) -> ChainArm:
    options = dict(base_frame="base_link", tool_frame="tool0", name="bare_arm", acceleration_limits=2.0)
    return ChainArm.from_model_file(path, **(options | arguments))


def plant_of(arm):
    """A CellChecker's plant of ``arm`` (its model added by ``add_to_plant``, as the station's)."""
    checker = CellChecker(arm)
    return checker.plant, checker.scene_graph.model_inspector()


def scenario_file(tmp_path, robot: str, name="bare") -> Path:
    """A quintic-move scenario of the bare arm, its ``robot:`` fields ``robot`` (YAML lines)."""
    path = tmp_path / f"{name}.yaml"
    path.write_text(textwrap.dedent(f"""\
        name: {name}
        robot: !CustomArm
          packages: {{bare_arm_description: {PACKAGE}}}
          tool_frame: tool0
          name: bare_arm
        """) + textwrap.indent(textwrap.dedent(robot), "  ") + textwrap.dedent("""\
        q_initial: [0.0, 0.4, 0.8, 0.0, 0.6, 0.0]
        planner: !QuinticConfig
          goals: [[0.5, 0.3, 0.9, 0.3, 0.5, 0.4]]
        """))
    return path


# ---- inertia ----------------------------------------------------------------------------------

def test_links_without_inertia_weigh_their_shapes_at_the_default_density():
    arm = bare_arm()
    assert list(arm.estimated_inertia) == list(LINKS) and arm.inertia_density == DEFAULT_DENSITY == 1370.0
    for link, volume in VOLUMES.items():
        assert arm.estimated_inertia[link] == pytest.approx(1370.0 * volume, rel=1e-9)
    plant, _ = plant_of(arm)  # the plant of every run has them: link_2 a box 80 x 80 x 400 mm, centred 0.2 m up
    inertia = plant.GetBodyByName("link_2").default_spatial_inertia()
    mass = 1370.0 * 0.08 * 0.08 * 0.4
    np.testing.assert_allclose(inertia.get_com(), [0.0, 0.0, 0.2], atol=1e-12)
    central = inertia.Shift(inertia.get_com()).CalcRotationalInertia().CopyToFullMatrix3()
    np.testing.assert_allclose(np.diag(central), [mass / 12 * (0.08 ** 2 + 0.4 ** 2)] * 2 + [mass / 12 * 2 * 0.08 ** 2])
    assert plant.GetBodyByName("base_link").default_mass() == 0.0  # fixed to the world: nothing to estimate


def test_a_density_scales_the_estimates_and_refuse_names_the_links():
    heavy = bare_arm(inertia_density=2740.0)
    for link in LINKS:
        assert heavy.estimated_inertia[link] == pytest.approx(2 * bare_arm().estimated_inertia[link], rel=1e-12)
    with pytest.raises(DrakeTrajError, match=r"the links link_1, link_2, link_3, link_4, link_5, link_6, tool0 move "
                                             r"and have no inertia") as refused:
        bare_arm(inertia_density=None)
    assert refused.value.field == ("inertia",)


def without(text: str, link: str, tag: str) -> str:
    """``text`` with the ``<tag>`` elements of ``link`` removed."""
    start = text.index(f'<link name="{link}"')
    end = text.index("</link>", start)
    body = text[start:end]
    while f"<{tag}" in body:
        first = body.index(f"<{tag}")
        body = body[:first] + body[body.index(f"</{tag}>", first) + len(f"</{tag}>"):]
    return text[:start] + body + text[end:]


def test_a_link_with_only_a_visual_mesh_weighs_its_hull(tmp_path):
    path = tmp_path / "bare_arm_description" / "urdf" / "visual_wrist.urdf"
    shutil.copytree(PACKAGE, tmp_path / "bare_arm_description")
    path.write_text(without(URDF.read_text(), "link_4", "collision"))
    arm = bare_arm(path)
    # wrist.dae: a 12-sided prism of radius 40 mm (to its corners) and 100 mm long (its OBJ keeps 8 decimals)
    assert arm.estimated_inertia["link_4"] == pytest.approx(1370.0 * 0.5 * 12 * 0.04 ** 2 * math.sin(2 * math.pi / 12)
                                                            * 0.1, rel=1e-6)


def test_a_moving_link_of_no_mass_and_no_shape_is_refused_naming_it(tmp_path):
    shutil.copytree(PACKAGE, tmp_path / "bare_arm_description")
    path = tmp_path / "bare_arm_description" / "urdf" / "hollow.urdf"
    text = without(without(URDF.read_text(), "link_6", "collision"), "link_6", "visual")
    path.write_text(without(text, "tool0", "visual"))
    with pytest.raises(DrakeTrajError, match=r"the model's links link_6, tool0 move behind a joint and weigh nothing: "
                                             r"the description gives no <inertial> and no shapes") as refused:
        bare_arm(path)
    assert refused.value.field == ("model_file",)


def test_scenario_inertia_options_and_their_refusals(tmp_path):
    arm = load_scenario(scenario_file(tmp_path, f"model_file: {URDF}\nbase_frame: base_link\n"
                                                "acceleration_limits: [2, 2, 2, 2, 2, 2]\n"
                                                "inertia: {density: 2740}\n")).base_robot()
    assert arm.inertia_density == 2740.0 and arm.estimated_inertia["link_2"] == pytest.approx(2740.0 * 0.08 * 0.08 * 0.4)
    for option, field, pattern in (("refuse", ("robot", "inertia"), r"robot.inertia: the links link_1, .*tool0 move"),
                                   ("heavy", ("robot", "inertia"), r"robot.inertia must be estimate, refuse or"),
                                   ("{density: 5}", ("robot", "inertia", "density"), r"within 10 and 30000 kg/m\^3")):
        path = scenario_file(tmp_path, f"model_file: {URDF}\nbase_frame: base_link\n"
                                       f"acceleration_limits: [2, 2, 2, 2, 2, 2]\ninertia: {option}\n")
        with pytest.raises(ScenarioError, match=r"bare.yaml, line \d+.*" + pattern) as refused:
            load_scenario(path)
        assert refused.value.field == field


def test_a_torque_refusal_says_the_torques_rest_on_estimated_inertia(tmp_path):
    path = scenario_file(tmp_path, f"model_file: {URDF}\nbase_frame: base_link\nacceleration_limits: [2, 2, 2, 2, 2, 2]\n"
                                   "effort_limits: [0.5, 0.5, 0.5, 0.5, 0.5, 0.5]\n")
    with pytest.raises(DrakeTrajError, match=r"cannot hold the start configuration against gravity.*\(the torques rest "
                                             r"on inertia estimated from the shapes of the links link_1, .*, tool0 at "
                                             r"1370 kg/m\^3"):
        simulate(load_scenario(path))


# ---- the base frame, joints held ----------------------------------------------------------------

@pytest.mark.parametrize("world", [False, True])
def test_rep_199_base_is_put_at_the_worlds_origin(world):
    arm = bare_arm(XACRO, base_frame="base", xacro_args={"world": str(world).lower()})
    by_link = bare_arm()
    turned = by_link.tcp_pose(Q)  # base is base_link turned by pi about z: x, y and the yaw change sign
    np.testing.assert_allclose(arm.tcp_pose(Q)[:, :3], turned[:, :3] * [-1, -1, 1], atol=1e-12)
    assert arm.setup.root_link == "base_link" and arm.setup.replaced_joint == ("world_joint" if world else None)
    plant, _ = plant_of(arm)
    context = plant.CreateDefaultContext()
    np.testing.assert_allclose(plant.GetFrameByName("base").CalcPoseInWorld(context).GetAsMatrix4(), np.eye(4), atol=1e-12)
    np.testing.assert_allclose(plant.GetFrameByName("base_link").CalcPoseInWorld(context).rotation().matrix(),
                               np.diag([-1.0, -1.0, 1.0]), atol=1e-12)


def test_a_model_welded_at_its_base_link_is_used_as_it_is():
    arm = bare_arm(XACRO, xacro_args={"world": "true"})
    assert arm.base_welded and arm.setup.root_link is None


def test_a_track_under_the_base_is_held_and_must_leave_the_base_at_the_origin(tmp_path):
    shutil.copytree(PACKAGE, tmp_path / "bare_arm_description")
    path = tmp_path / "bare_arm_description" / "urdf" / "on_a_track.urdf"
    track = ('<link name="world"/><joint name="track" type="prismatic"><parent link="world"/><child link="base_link"/>'
             '<axis xyz="1 0 0"/><limit lower="-1" upper="2" effort="100" velocity="1"/></joint>')
    path.write_text(URDF.read_text().replace('<robot name="bare_arm">', '<robot name="bare_arm">' + track))
    arm = bare_arm(path)
    assert arm.locked_joints == {"track": 0.0} and arm.base_welded
    with pytest.raises(DrakeTrajError, match=r"welds base_frame 'base_link' to its world at xyz \[0.5, 0.0, 0.0\]") as refused:
        bare_arm(path, locked_joints={"track": 0.5})
    assert refused.value.field == ("base_frame",)


def gripper_arm(**locked) -> ChainArm:
    return bare_arm(XACRO, xacro_args={"gripper": "true"}, locked_joints=locked)


def finger_offset(arm, finger: str) -> float:
    plant, _ = plant_of(arm)
    return float(plant.CalcRelativeTransform(plant.CreateDefaultContext(), plant.GetFrameByName("link_6"),
                                             plant.GetFrameByName(finger)).translation()[0])


def test_the_fingers_are_held_at_their_default_or_given_position():
    arm = gripper_arm()
    assert arm.locked_joints == {"finger_left_joint": 0.005, "finger_right_joint": 0.005}  # 0 clipped into the range
    plant, _ = plant_of(arm)
    assert plant.num_positions() == 6 and plant.num_actuators() == 6 and plant.num_constraints() == 0
    assert finger_offset(arm, "finger_left") == pytest.approx(0.005) and finger_offset(arm, "finger_right") == pytest.approx(-0.005)
    assert finger_offset(gripper_arm(finger_left_joint=0.02), "finger_left") == pytest.approx(0.02)


@pytest.mark.parametrize("locked, field, pattern", [
    ({"nope": 0.0}, ("locked_joints", "nope"), r"the model has no joint 'nope'; its joints with a degree of freedom: "
                                               r"joint_1, .*finger_right_joint"),
    ({"finger_left_joint": 0.5}, ("locked_joints", "finger_left_joint"), r"0.5 m is beyond the joint's range \[0.005, 0.03\] m"),
    ({"link_6-tool0": 0.0}, ("locked_joints", "link_6-tool0"), r"the joint 'link_6-tool0' is fixed already")])
def test_a_bad_lock_is_refused_naming_it(locked, field, pattern):
    with pytest.raises(DrakeTrajError, match=pattern) as refused:
        gripper_arm(**locked)
    assert refused.value.field == field


SEVEN = f"""model_file: {XACRO}
base_frame: base
xacro_args: {{dof: 7, gripper: true, world: false}}
"""


def test_a_seventh_axis_is_refused_first_naming_the_joints_and_locked_joints(tmp_path):
    path = scenario_file(tmp_path, SEVEN + "acceleration_limits: [2, 2, 2, 2, 2, 2, 2]\n")
    with pytest.raises(ScenarioError, match=r"robot.model_file: 7 joints between base and tool0: 'joint_1' \(RevoluteJoint\), "
                                            r"'joint_2' \(RevoluteJoint\), 'joint_2b' \(RevoluteJoint\), .*hold the extra ones at a "
                                            r"fixed position with locked_joints") as refused:
        load_scenario(path)
    assert refused.value.field == ("robot", "model_file")
    held = load_scenario(scenario_file(tmp_path, SEVEN + "acceleration_limits: [2, 2, 2, 2, 2, 2]\n"
                                                         "locked_joints: {joint_2b: 0.0}\n")).base_robot()
    assert held.joint_names == ("joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6")
    np.testing.assert_allclose(held.tcp_pose(Q), bare_arm(base_frame="base").tcp_pose(Q), atol=1e-12)


def test_a_run_says_what_it_assumed_once_and_writes_it(tmp_path, capsys):
    path = scenario_file(tmp_path, f"model_file: {XACRO}\nbase_frame: base\nacceleration_limits: [2, 2, 2, 2, 2, 2]\n"
                                   "xacro_args: {gripper: true, world: true}\nlocked_joints: {finger_left_joint: 0.02}\n")
    assert cli.main(["run", str(path), "--out", str(tmp_path / "run")]) == cli.EXIT_OK
    said = capsys.readouterr().err
    assert said.count("the bare_arm model holds the joints it does not drive at finger_left_joint = 0.02, "
                      "finger_right_joint = 0.005 (locked_joints); it estimates the inertia") == 1
    metrics = json.loads((tmp_path / "run" / "metrics.json").read_text())
    manifest = json.loads((tmp_path / "run" / "run.json").read_text())
    masses = {link: 1370.0 * volume for link, volume in VOLUMES.items()}
    for written in (metrics["estimated_inertia_links"], manifest["estimated_inertia_links"]):
        assert list(written)[:7] == list(LINKS) and written["link_2"] == pytest.approx(masses["link_2"])
        assert written["finger_left"] == pytest.approx(1370.0 * 0.01 * 0.02 * 0.04)
    assert metrics["estimated_inertia_density"] == 1370.0
    assert metrics["locked_joints"] == manifest["locked_joints"] == {"finger_left_joint": 0.02, "finger_right_joint": 0.005}


# ---- xacro, meshes, materials ---------------------------------------------------------------------

def test_xacro_arguments_take_numbers_and_booleans_and_refuse_others(tmp_path):
    arm = load_scenario(scenario_file(tmp_path, f"model_file: {XACRO}\nbase_frame: base_link\n"
                                                "acceleration_limits: [2, 2, 2, 2, 2, 2]\n"
                                                "xacro_args: {dof: 6, gripper: true, world: false}\n")).base_robot()
    assert arm.xacro_args == {"dof": "6", "gripper": "true", "world": "false"} and "finger_left_joint" in arm.locked_joints
    path = scenario_file(tmp_path, f"model_file: {XACRO}\nacceleration_limits: [2, 2, 2, 2, 2, 2]\nxacro_args: {{dof: [6]}}\n")
    with pytest.raises(ScenarioError, match=r"line 8.*expected text, a number or true/false, found a list") as refused:
        load_scenario(path)
    assert refused.value.field == ("robot", "xacro_args", "dof")
    with pytest.raises(DrakeTrajError, match=r"robot.xacro_args.dof must be text, a number or true/false, got None"):
        CustomArm(model_file=str(XACRO), xacro_args={"dof": None}, acceleration_limits=[2.0] * 6).validate()


def test_a_find_of_a_package_not_given_is_one_clear_refusal(tmp_path):
    shutil.copy(XACRO, tmp_path / "bare_arm.urdf.xacro")  # outside its package: $(find bare_arm_description) fails
    with pytest.raises(DrakeTrajError) as refused:
        bare_arm(tmp_path / "bare_arm.urdf.xacro")
    message = str(refused.value)
    assert message == ("model_file: the model refers to the package 'bare_arm_description' ($(find bare_arm_description) in "
                       "bare_arm.urdf.xacro or a file it includes), which is on no package path here: give its folder in "
                       "packages: {bare_arm_description: path/to/bare_arm_description} (relative to the scenario file) or "
                       "put its parent folder on ROS_PACKAGE_PATH; nothing is downloaded")
    assert bare_arm(tmp_path / "bare_arm.urdf.xacro", packages={"bare_arm_description": PACKAGE}).estimated_inertia


def test_stl_and_collada_visual_meshes_are_drawn_as_obj_with_their_colours():
    plant, inspector = plant_of(bare_arm())
    drawn = {}
    for link in ("link_4", "link_6"):
        (geometry,) = plant.GetVisualGeometriesForBody(plant.GetBodyByName(link))
        assert inspector.GetIllustrationProperties(geometry) is not None
        drawn[link] = Path(inspector.GetShape(geometry).source().path())
    assert drawn["link_6"].suffix == drawn["link_4"].suffix == ".obj"
    (diffuse,) = [line.split()[1:] for line in drawn["link_4"].with_suffix(".mtl").read_text().splitlines()
                  if line.startswith("Kd ")]
    np.testing.assert_allclose([float(v) for v in diffuse], [0.8, 0.15, 0.15], atol=1 / 255)  # wrist.dae's red, 8 bits
    # tool0's material is defined after its use: ROS takes it, and so does the text given to Drake
    (tool,) = plant.GetVisualGeometriesForBody(plant.GetBodyByName("tool0"))
    colour = inspector.GetIllustrationProperties(tool).GetProperty("phong", "diffuse")
    assert (colour.r(), colour.g(), colour.b()) == (0.5, 0.5, 0.5)
    arm = bare_arm(XACRO, xacro_args={"tool_material": "none"})  # a material defined nowhere: drawn in Drake's colour
    assert arm.estimated_inertia["tool0"] > 0


def test_a_collada_mesh_in_inches_after_a_blank_line_is_read_in_metres(tmp_path):
    shutil.copytree(PACKAGE, tmp_path / "bare_arm_description")
    wrist = tmp_path / "bare_arm_description" / "meshes" / "wrist.dae"
    text = wrist.read_text()
    assert text.count("<up_axis>") == 1  # trimesh wrote no <unit>: one in inches goes before it
    wrist.write_text("\n" + text.replace("<up_axis>", '<unit name="inch" meter="0.0254"/>\n    <up_axis>'))
    plant, inspector = plant_of(bare_arm(tmp_path / "bare_arm_description" / "urdf" / "bare_arm.urdf"))
    (geometry,) = plant.GetVisualGeometriesForBody(plant.GetBodyByName("link_4"))
    vertices = np.array([[float(v) for v in line.split()[1:4]] for line in
                         Path(inspector.GetShape(geometry).source().path()).read_text().splitlines() if line.startswith("v ")])
    # a 12-sided prism of radius 0.04 and length 0.1 (a corner every 30 degrees from x), in inches
    np.testing.assert_allclose(vertices.max(axis=0), np.array([0.04, 0.04, 0.1]) * 0.0254, rtol=1e-6)
