"""Robot and cell description files as engineers have them: package:// meshes (a package map and
ROS_PACKAGE_PATH), a base fixed to a world link, mesh collision shapes (convex hulls; STL
converted), xacro, and no arm running with its checks silently off."""

import shutil
import textwrap

import numpy as np
import pytest
from pydrake.geometry import Role

from drake_traj import get_robot, load_scenario, simulate
from drake_traj.cell.clearance import CellChecker, CollisionError
from drake_traj.cell.shapes import shape_radius as _bounding_radius
from drake_traj.data import data_directory
from drake_traj.errors import DrakeTrajError
from drake_traj.robots.chain_arm import ChainArm
from drake_traj.scenario import ScenarioError, make_planner

DESCRIPTION = data_directory("models") / "example_arm_description"
EXAMPLE = data_directory("diagrams") / "example_arm.yaml"
UR5E = get_robot("ur5e")


def example_arm(**arguments) -> ChainArm:
    return ChainArm.from_model_file(DESCRIPTION / "urdf" / "example_arm.urdf", base_frame="base", tool_frame="tool0",
                                    name="example_arm", acceleration_limits=1.4, **arguments)


def copy_description(tmp_path):
    """The example package copied into ``tmp_path`` / pkgs (another place than the shipped one)."""
    folder = tmp_path / "pkgs" / "example_arm_description"
    shutil.copytree(DESCRIPTION, folder)
    return folder


@pytest.mark.parametrize("variant, analytic", [("quintic", ("quintic.yaml", "ptp_ur5e")),
                                               ("pajak", ("pajak.yaml", "ur5e")),
                                               ("smooth", None)])
def test_the_example_description_runs_every_planner_through_the_check(variant, analytic):
    scenario = load_scenario(EXAMPLE, variant)
    result = simulate(scenario)
    assert result.succeeded, result.failure
    metrics = result.metrics()
    assert metrics.unchecked_links == [] and metrics.tracking_error_tcp_max_m < 1e-4
    assert metrics.peak_velocity_fraction <= 1 + 1e-6 and metrics.peak_acceleration_fraction <= 1 + 1e-6
    if analytic is not None:  # the same arm as our UR5e (its kinematics and dynamics): the same motion
        same = simulate(load_scenario(data_directory("diagrams") / analytic[0], analytic[1]))
        assert result.duration == pytest.approx(same.duration, abs=2e-3)
        np.testing.assert_allclose(result.q_ref[-1], same.q_ref[-1], atol=1e-6)


def test_the_example_arm_is_the_ur5e_and_its_collision_shapes_are_the_meshes_hulls():
    arm = example_arm()
    assert arm.base_welded  # its world link's fixed joint, used as it is
    q = np.random.default_rng(3).uniform(-3, 3, (20, 6))
    np.testing.assert_allclose(arm.tcp_pose(q), UR5E.tcp_pose(q), atol=1e-9)
    checker = CellChecker(arm)
    assert checker.unprotected_links == []
    inspector = checker.scene_graph.model_inspector()
    meshes = [g for g in inspector.GetAllGeometryIds(Role.kProximity) if type(inspector.GetShape(g)).__name__ == "Mesh"]
    assert len(meshes) >= 9  # every link's shapes, OBJ and the STL ones converted
    # a 32-sided prism of a cylinder (radius r, length L) has its farthest vertex at sqrt(r² + (L/2)²)
    ours = CellChecker(UR5E)
    ours_inspector = ours.scene_graph.model_inspector()
    radii = sorted(_bounding_radius(inspector.GetShape(g)) for g in meshes)
    expected = sorted(_bounding_radius(ours_inspector.GetShape(g)) for g in ours_inspector.GetAllGeometryIds()
                      if ours.plant.GetBodyFromFrameId(ours_inspector.GetFrameId(g)).model_instance() == ours.instance
                      and ours_inspector.GetProximityProperties(g) is not None)
    np.testing.assert_allclose(radii, expected, atol=1e-6)
    # the joint reach bounds of the dense-sampling guarantee from the hulls: those of the shapes they replace
    np.testing.assert_allclose(checker.reach, ours.reach, atol=1e-6)


def test_a_motion_through_the_table_is_refused_on_the_mesh_hulls():
    scenario = load_scenario(EXAMPLE, "quintic")
    scenario.planner.goals = [[-1.57, 0.6, -0.3, -1.57, 1.57, 0.0]]  # the upper arm down through the table top
    with pytest.raises(CollisionError, match="table"):
        simulate(scenario)


def test_an_unknown_package_is_refused_naming_it_and_how_to_give_it(tmp_path):
    text = (DESCRIPTION / "urdf" / "example_arm.urdf").read_text()
    (tmp_path / "arm.urdf").write_text(text)  # outside its package: package://example_arm_description is unknown
    (tmp_path / "arm.yaml").write_text(textwrap.dedent("""\
        name: elsewhere
        robot: !CustomArm
          model_file: arm.urdf
          name: example_arm
          acceleration_limits: [1.4, 1.4, 1.4, 1.4, 1.4, 1.4]
        planner: !QuinticConfig
          goals: [[-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]]
        """))
    with pytest.raises(ScenarioError, match=r"arm.yaml, line 3.*package 'example_arm_description' "
                                            r"\(package://example_arm_description/meshes/base_foot.obj\), which is on no "
                                            r"package path here: give its folder in packages") as refused:
        load_scenario(tmp_path / "arm.yaml")
    assert refused.value.field[:2] == ("robot", "model_file")
    # given as a package of the scenario, relative to it, it loads
    folder = copy_description(tmp_path)
    text = (tmp_path / "arm.yaml").read_text().replace("  name: example_arm\n", "  name: example_arm\n  packages: "
                                                       f"{{example_arm_description: {folder.relative_to(tmp_path)}}}\n")
    (tmp_path / "arm.yaml").write_text(text)
    assert load_scenario(tmp_path / "arm.yaml").base_robot().packages["example_arm_description"].resolve() == folder


def test_ros_package_path_finds_a_package(tmp_path, monkeypatch):
    folder = copy_description(tmp_path)
    (tmp_path / "arm.urdf").write_text((folder / "urdf" / "example_arm.urdf").read_text())
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(folder.parent))
    arm = ChainArm.from_model_file(tmp_path / "arm.urdf", base_frame="base", tool_frame="tool0", name="mine",
                                   acceleration_limits=1.4)
    assert CellChecker(arm).unprotected_links == []


def test_a_world_joint_with_an_offset_is_refused_naming_the_base_frame(tmp_path):
    text = (DESCRIPTION / "urdf" / "example_arm.urdf").read_text().replace(
        '<origin xyz="0 0 0" rpy="0 0 0" />', '<origin xyz="0.5 0 0" rpy="0 0 0" />', 1)
    folder = copy_description(tmp_path)
    (folder / "urdf" / "moved.urdf").write_text(text)
    with pytest.raises(DrakeTrajError, match=r"welds base_frame 'base' to its world at xyz \[0.5, 0.0, 0.0\]") as refused:
        ChainArm.from_model_file(folder / "urdf" / "moved.urdf", base_frame="base", tool_frame="tool0", name="mine",
                                 acceleration_limits=1.4)
    assert refused.value.field == ("base_frame",)


def without_collisions(text: str) -> str:
    while "<collision" in text:
        start = text.index("<collision")
        text = text[:start] + text[text.index("</collision>", start) + len("</collision>"):]
    return text


def test_an_arm_without_collision_shapes_is_refused_unless_said_so(tmp_path):
    folder = copy_description(tmp_path)
    (folder / "urdf" / "bare.urdf").write_text(without_collisions((folder / "urdf" / "example_arm.urdf").read_text()))
    scenario_text = textwrap.dedent(f"""\
        name: bare
        robot: !CustomArm
          model_file: {folder / 'urdf' / 'bare.urdf'}
          name: bare_arm
          acceleration_limits: [1.4, 1.4, 1.4, 1.4, 1.4, 1.4]
        q_initial: [-1.5707963267948966, -1.5707963267948966, -2.356194490192345, -0.7853981633974483, 1.5707963267948966, 0.7853981633974483]
        planner: !QuinticConfig
          goals: [[-1.57, 0.6, -0.3, -1.57, 1.57, 0.0]]
        """)
    (tmp_path / "bare.yaml").write_text(scenario_text)
    with pytest.raises(DrakeTrajError, match=r"links shoulder_link, upper_arm_link, forearm_link, wrist_1_link, "
                                             r"wrist_2_link, wrist_3_link have no collision shapes") as refused:
        simulate(load_scenario(tmp_path / "bare.yaml"))
    assert refused.value.field == ("robot", "unchecked_links")
    # said explicitly: it runs (this motion goes through the table: nothing sees it) and its metrics say so
    (tmp_path / "bare.yaml").write_text(scenario_text.replace("  name: bare_arm\n", "  name: bare_arm\n"
                                                                                    "  unchecked_links: [all]\n"))
    result = simulate(load_scenario(tmp_path / "bare.yaml"))
    assert result.metrics().unchecked_links == ["shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link",
                                                "wrist_2_link", "wrist_3_link"]


def test_a_xacro_description_is_expanded_with_its_arguments_and_find(tmp_path):
    folder = copy_description(tmp_path)
    text = (folder / "urdf" / "example_arm.urdf").read_text()
    assert text.count('name="example_arm">') == 1  # the robot's tag
    text = text.replace('name="example_arm">', 'name="$(arg name)" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                        '<xacro:arg name="name" default="unnamed"/>')
    text = text.replace("package://example_arm_description/", "file://$(find example_arm_description)/")
    (folder / "urdf" / "example_arm.urdf.xacro").write_text(text)
    arm = ChainArm.from_model_file(folder / "urdf" / "example_arm.urdf.xacro", base_frame="base", tool_frame="tool0",
                                   name="from_xacro", acceleration_limits=1.4, packages={"example_arm_description": folder},
                                   xacro_args={"name": "expanded"})
    q = np.random.default_rng(1).uniform(-3, 3, (10, 6))
    np.testing.assert_allclose(arm.tcp_pose(q), UR5E.tcp_pose(q), atol=1e-9)
    checker = CellChecker(arm)
    assert checker.unprotected_links == []
    assert checker.plant.HasModelInstanceNamed("expanded")  # $(arg name) took effect
    planner = make_planner(load_scenario(EXAMPLE, "quintic"))
    assert planner.robot.name == "example_arm"


def test_a_directives_model_from_a_package(tmp_path):
    package = tmp_path / "fixtures_pkg"
    package.mkdir()
    (package / "package.xml").write_text('<package format="3"><name>fixtures_pkg</name><version>0.0.1</version>'
                                         '<description>x</description><maintainer email="a@b.c">a</maintainer>'
                                         '<license>BSD</license></package>')
    (package / "block.sdf").write_text(
        '<?xml version="1.0"?><sdf version="1.9"><model name="block"><link name="block">'
        '<collision name="c"><geometry><box><size>0.2 0.2 0.2</size></box></geometry></collision>'
        '</link></model></sdf>')
    directives = ("  directives:\n    - add_model: {name: block, file: 'package://fixtures_pkg/block.sdf'}\n"
                  "    - add_weld: {parent: world, child: block::block, X_PC: {translation: [2.0, 0.0, 0.5]}}\n")
    scenario_text = ("name: with_block\nrobot: ur10e\nplanner: !QuinticConfig\n  goals: [[-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]]\n"
                     "cell:\n" + directives)
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "cell.yaml").write_text(scenario_text)
    with pytest.raises(DrakeTrajError, match=r"package 'fixtures_pkg'.*give its folder in packages"):
        simulate(load_scenario(tmp_path / "other" / "cell.yaml"))
    (tmp_path / "other" / "cell.yaml").write_text(scenario_text + "  packages: {fixtures_pkg: ../fixtures_pkg}\n")
    assert simulate(load_scenario(tmp_path / "other" / "cell.yaml")).succeeded


def test_effort_limits_from_limit_tags_where_no_transmission_declares_a_drive(tmp_path):
    """ROS 2 descriptions declare drives with ros2_control, not <transmission>: Drake then makes no
    actuator and keeps no effort limit; the arm takes them from the joints' <limit effort>."""
    folder = copy_description(tmp_path)
    text = (folder / "urdf" / "example_arm.urdf").read_text()
    while "<transmission" in text:
        start = text.index("<transmission")
        text = text[:start] + text[text.index("</transmission>", start) + len("</transmission>"):]
    (folder / "urdf" / "no_drives.urdf").write_text(text)
    arm = ChainArm.from_model_file(folder / "urdf" / "no_drives.urdf", base_frame="base", tool_frame="tool0",
                                   name="no_drives", acceleration_limits=1.4)
    np.testing.assert_array_equal(arm.effort_limits, UR5E.effort_limits)  # 150 150 150 28 28 28 N m
