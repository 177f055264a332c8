"""The pairs of an arm's links the checks leave out (drake_traj.robots.self_contact): a description
whose shapes overlap in every pose runs, the pairs named; a pair that touches only sometimes is
kept and its refusal says which shapes touch and how often; robot.srdf's pairs; the shipped arms
leave nothing out. The arm of tests/data/descriptions/touching_wrist.urdf has each cause (its
comment gives the numbers the tests compute independently)."""

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from drake_traj import cli, load_scenario
from drake_traj.cell import CellChecker
from drake_traj.cell.clearance import CollisionError
from drake_traj.data import data_directory
from drake_traj.errors import DrakeTrajError
from drake_traj.planners import QuinticConfig, make_planner
from drake_traj.results import SimulationResult
from drake_traj.robots import ROBOT_NAMES, get_robot, self_contact
from drake_traj.robots.chain_arm import ChainArm
from drake_traj.robots.self_contact import ALWAYS, SAMPLES, SEED, SRDF
from drake_traj.scenario import scenario_variants
from drake_traj.station import add_station

DESCRIPTIONS = Path(__file__).resolve().parent / "data" / "descriptions"
URDF, SRDF_FILE = DESCRIPTIONS / "touching_wrist.urdf", DESCRIPTIONS / "touching_wrist.srdf"
ADJACENT = "adjacent through link_3_mount (no collision shapes)"
STRAIGHT = np.zeros(6)  # the counterweight 20 mm into the base; the wrist boxes 30 mm into each other
CLEAR = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])  # the counterweight 0.08 - 0.1 cos(1) = 26 mm above the base


def touching_wrist(**arguments) -> ChainArm:
    return ChainArm.from_model_file(URDF, base_frame="base_link", tool_frame="tool0", acceleration_limits=2.0,
                                    **arguments)


def raw_distances(arm, q) -> dict:
    """{pair of links: least signed distance [m]} within 0 m at ``q`` on a plant of ``arm`` alone
    with Drake's own filters only (none of drake_traj's)."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    instance = arm.add_to_plant(plant)
    plant.Finalize()
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    plant.SetPositions(plant.GetMyMutableContextFromRoot(context), instance, q)
    query = scene_graph.get_query_output_port().Eval(scene_graph.GetMyContextFromRoot(context))
    inspector, found = scene_graph.model_inspector(), {}
    for pair in query.ComputeSignedDistancePairwiseClosestPoints(0.0):
        links = frozenset(plant.GetBodyFromFrameId(inspector.GetFrameId(g)).name() for g in (pair.id_A, pair.id_B))
        found[links] = min(found.get(links, np.inf), pair.distance)
    return found


def test_the_pairs_in_contact_in_every_pose_are_left_out_and_the_arm_starts():
    arm = touching_wrist()
    found = self_contact(arm)
    assert found.rows() == [["link_3", "link_4", ADJACENT], ["link_4", "link_6", ALWAYS]]
    assert found.samples == SAMPLES + 1  # the home and every random draw: the wrist pair never came apart
    checker = CellChecker(arm)
    assert [pair.row() for pair in checker.unchecked_pairs] == found.rows()
    # independently: the wrist centre W (joint_5's origin) is inside link_4's box (centre z = 0.05 m,
    # half sizes 25, 25, 60 mm) and link_6's (centre W, half size 20 mm) in any pose
    plant, context = checker.plant, checker.plant.CreateDefaultContext()
    link = {name: plant.GetBodyByName(name, checker.instance).body_frame() for name in ("link_4", "link_5", "link_6")}
    for q in np.random.default_rng(1).uniform(arm.lower_limits, arm.upper_limits, (20, 6)):
        plant.SetPositions(context, checker.instance, q)
        in_4 = plant.CalcRelativeTransform(context, link["link_4"], link["link_5"]).translation()
        in_6 = plant.CalcRelativeTransform(context, link["link_6"], link["link_5"]).translation()
        assert np.all(np.abs(in_4 - [0, 0, 0.05]) <= [0.025, 0.025, 0.06]) and np.all(np.abs(in_6) <= 0.02)
    # without the filter the start is refused: the wrist boxes 0.11 - 0.08 = 30 mm into each other
    # (sideways 45 mm), link_3's and link_4's 10 mm along joint_4's axis
    raw = raw_distances(arm, CLEAR)
    assert raw[frozenset({"link_4", "link_6"})] == pytest.approx(-0.03, abs=1e-9)
    assert raw[frozenset({"link_3", "link_4"})] == pytest.approx(-0.01, abs=1e-9)
    checker.check_configuration(CLEAR)
    assert not checker.contacts(CLEAR, within=0.02)  # the nearest kept pair: the counterweight 26 mm above the base


def test_the_compiled_model_and_the_station_leave_out_the_same_pairs():
    arm = touching_wrist()
    checker = CellChecker(arm)
    names = {frozenset(checker.owner(g)[0] for g in pair) for pair in
             checker.scene_graph.model_inspector().GetCollisionCandidates()}
    assert frozenset({"link_4", "link_6"}) not in names and frozenset({"link_3", "link_4"}) not in names
    assert frozenset({"base_link", "link_2"}) in names  # the pair that touches only sometimes is checked
    model = checker.compiled_model()  # built from the candidates: it leaves out the same pairs
    bodies = {frozenset(checker.owner(model.geometries[k])[0] for k in pair) for pair in model.pairs}
    assert frozenset({"link_4", "link_6"}) not in bodies and frozenset({"base_link", "link_2"}) in bodies
    assert model.distances(CLEAR[None])[0] == pytest.approx(0.08 - 0.1 * np.cos(1.0), abs=1e-5)
    # the station's plant leaves out the same pairs: the same scene, the same fingerprint
    planner = make_planner(QuinticConfig(goals=[[0.5, 0.9, -0.5, 0.5, 1.0, 0.5]]), arm, CLEAR)
    add_station(DiagramBuilder(), planner, robot=arm)
    assert planner.guard.fingerprint == checker.fingerprint
    assert [pair.row() for pair in planner.guard.unchecked_pairs] == self_contact(arm).rows()


def test_a_pair_touching_only_sometimes_is_kept_and_its_refusal_names_the_shapes_and_the_share():
    arm = touching_wrist()
    with pytest.raises(CollisionError) as refused:
        CellChecker(arm).check_configuration(STRAIGHT)
    error = refused.value
    assert set(error.bodies) == {"base_link", "link_2"} and error.distance == pytest.approx(-0.02, abs=1e-9)
    # the configurations the detection samples (the seed and count are documented), and the
    # counterweight's contact from its height: 0.08 m - 0.1 m cos(joint_2) < 0
    draws = np.random.default_rng(SEED).uniform(arm.lower_limits, arm.upper_limits, (SAMPLES, 6))
    q2 = np.r_[arm.home_configuration[1], draws[:, 1]]
    touching = int(np.sum(0.08 - 0.1 * np.cos(q2) < 0))
    assert 0.5 * len(q2) < touching < len(q2)
    assert ("(base_link and link_2, 20.0 mm deep: base_link's box 1000 x 1000 x 100 mm and link_2's counterweight "
            "sphere of radius 20 mm)") in str(error)
    assert f"are in contact in {touching} of {SAMPLES + 1} poses sampled in the joint ranges, not in all" in str(error)
    assert '<disable_collisions link1="base_link" link2="link_2" reason="User"/>' in str(error)


def test_robot_srdf_pairs_are_left_out_and_the_run_names_them(tmp_path, capsys):
    for name in (URDF.name, SRDF_FILE.name):
        shutil.copy(DESCRIPTIONS / name, tmp_path / name)
    path = tmp_path / "arm.yaml"
    path.write_text("name: touching_wrist_srdf\nrobot: !CustomArm\n  model_file: touching_wrist.urdf\n"
                    "  srdf: touching_wrist.srdf\n  base_frame: base_link\n  tool_frame: tool0\n  name: touching_wrist\n"
                    "  acceleration_limits: [2, 2, 2, 2, 2, 2]\n"
                    "q_initial: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]\n"  # the counterweight in the base: the file's pair
                    "planner: !QuinticConfig\n  goals: [[0.5, 0.5, -0.5, 0.5, 1.0, 0.5]]\n")
    expected = [["base_link", "link_2", SRDF], ["link_4", "link_6", SRDF], ["link_3", "link_4", ADJACENT]]
    assert self_contact(load_scenario(path).base_robot()).rows() == expected  # base_link, link_1: Drake's own
    assert cli.main(["run", str(path), "--out", str(tmp_path / "out")]) == cli.EXIT_OK
    said = [line for line in capsys.readouterr().err.splitlines() if "leave out" in line]
    assert said == ["drake-traj: the checks leave out these pairs of the arm's links (metrics.json: "
                    "unchecked_collision_pairs): base_link and link_2, srdf; link_4 and link_6, srdf; link_3 and link_4, "
                    f"{ADJACENT}"]
    for name in ("metrics.json", "run.json"):
        assert json.loads((tmp_path / "out" / name).read_text())["unchecked_collision_pairs"] == expected
    assert [list(pair) for pair in SimulationResult.load(tmp_path / "out").unchecked_collision_pairs] == expected


@pytest.mark.parametrize("text, words", [
    ('<robot name="r"><disable_collisions link1="link_4" link2="wrist_camera" reason="Never"/></robot>',
     "disables collisions of the link 'wrist_camera', which the arm's model does not have"),
    ('<robot name="r"><disable_collisions link1="link_4" reason="Never"/></robot>', "without link1 and link2"),
    ('<robot name="r"><disable_collisions', "cannot be read as SRDF"),
])
def test_an_srdf_the_model_does_not_fit_is_refused_naming_the_file_and_the_link(tmp_path, text, words):
    srdf = tmp_path / "arm.srdf"
    srdf.write_text(text)
    with pytest.raises(DrakeTrajError) as refused:
        CellChecker(touching_wrist(srdf=srdf))
    assert refused.value.field == ("robot", "srdf") and words in str(refused.value) and str(srdf) in str(refused.value)


def test_robot_srdf_must_be_an_existing_srdf_file(tmp_path):
    yaml = ("name: x\nrobot: !CustomArm\n  model_file: {model}\n  srdf: {srdf}\n  base_frame: base_link\n"
            "  tool_frame: tool0\n  acceleration_limits: [2, 2, 2, 2, 2, 2]\nplanner: !QuinticConfig\n  goals: [[0, 0, 0, 0, 0, 0]]\n")
    (tmp_path / "arm.srdf.xacro").write_text("<robot/>")
    for srdf, words in (("missing.srdf", "is not a file"), ("arm.srdf.xacro", "expand the xacro first")):
        path = tmp_path / "arm.yaml"
        path.write_text(yaml.format(model=URDF, srdf=srdf))
        with pytest.raises(DrakeTrajError) as refused:
            load_scenario(path).base_robot()
        assert refused.value.field[:2] == ("robot", "srdf") and words in str(refused.value)


def test_the_shipped_arms_leave_no_pair_out():
    """The UR e-Series, the papers' robots and every shipped scenario's arm (the example
    description, the PUMA 560 of its DH table) are checked exactly as before."""
    robots = {name: get_robot(name) for name in ROBOT_NAMES}
    for path in sorted(data_directory("diagrams").glob("*.yaml")):
        for variant in scenario_variants(path):
            robot = load_scenario(path, variant).base_robot()
            robots.setdefault(robot.name, robot)
    assert {"example_arm", "puma560", "ur10e", "cartesian"} <= set(robots)
    assert {name: self_contact(robot).rows() for name, robot in robots.items()} == {name: [] for name in robots}


def test_the_finding_is_made_once_per_description():
    arm = touching_wrist()
    first = self_contact(arm)
    assert self_contact(touching_wrist()) is first  # another arm object of the same file
    assert self_contact(arm.with_tcp([0, 0, 0.1], [0, 0, 0])) is first  # a tool changes no link pair
    assert self_contact(touching_wrist(srdf=SRDF_FILE)) is not first
