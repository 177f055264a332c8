"""Any 6-axis arm: the PUMA 560 from its DH table (diagrams/puma560.yaml) through the
closed loop, its written model against its table in both DH conventions, an arm from a user's
URDF and from a user's plant, and bad input at its line."""

import math

import numpy as np
import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, MultibodyPlant
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from drake_traj import QuinticConfig, cli, load_scenario, simulate
from drake_traj.cell import CellChecker
from drake_traj.errors import DrakeTrajError
from drake_traj.planners import make_planner
from drake_traj.robots.chain import SerialChain
from drake_traj.robots import arm_checks
from drake_traj.robots.chain_arm import ChainArm
from drake_traj.robots.custom import DhArm, resolve_robot
from drake_traj.robots.task_space import orientation_error
from drake_traj.robots.urdf_writer import touching_pairs
from drake_traj.scenario import ScenarioError, make_planner as make_scenario_planner

from conftest import DIAGRAMS

PUMA = DIAGRAMS / "puma560.yaml"
# relative; the logged reference is integrated (RK2 at 1 ms): its q̇ error measured 1.4e-6 rad/s
# on the PUMA's quintic plan (1.3e-6 on the UR10e's, tests/test_simulation.py); the closed-form
# plan itself is checked to 1e-12
LIMIT_TOLERANCE = 3e-6


def puma_arm() -> DhArm:
    return load_scenario(PUMA, "quintic").robot


def rot_x(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def rot_z(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def shift(x=0.0, z=0.0):
    out = np.eye(4)
    out[0, 3], out[2, 3] = x, z
    return out


def dh_frames(table, convention, q):
    """DH frames 1..6 in the base frame, straight from the conventions' products."""
    frames, pose = [], np.eye(4)
    for (d, a, alpha, offset), angle in zip(table, q):
        if convention == "standard":  # Rz(θ) Tz(d) Tx(a) Rx(α)
            pose = pose @ rot_z(angle + offset) @ shift(z=d) @ shift(x=a) @ rot_x(alpha)
        else:  # Craig: Rx(α_{i-1}) Tx(a_{i-1}) Rz(θ) Tz(d)
            pose = pose @ rot_x(alpha) @ shift(x=a) @ rot_z(angle + offset) @ shift(z=d)
        frames.append(pose)
    return frames


def chain_pose(chain, q):
    """The flange pose of a SerialChain: fixed_0 R(a_1, q_1) fixed_1 ... R(a_6, q_6) fixed_6 (Rodrigues)."""
    pose = chain.fixed[0].copy()
    for axis, angle, fixed in zip(chain.axes, q, chain.fixed[1:]):
        skew = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        turn = np.eye(4)
        turn[:3, :3] = np.eye(3) + math.sin(angle) * skew + (1 - math.cos(angle)) * skew @ skew
        pose = pose @ turn @ fixed
    return pose


def modified_from_standard(dh: DhArm) -> dict:
    """The same arm as a modified (Craig) table: row i = [d_i, a_{i-1}, α_{i-1}, θ_i] (exact as the
    PUMA's a_6 = α_6 = 0), its centres of mass and inertias moved from standard frame i to Craig's
    frame i (standard frame i = Craig frame i · Tx(a_i) Rx(α_i))."""
    table = np.array(dh.dh)
    assert table[5, 1] == 0.0 and table[5, 2] == 0.0
    modified = np.column_stack([table[:, 0], np.r_[0.0, table[:5, 1]], np.r_[0.0, table[:5, 2]], table[:, 3]])
    coms, inertias = [], []
    for (_, a, alpha, _), com, (ixx, iyy, izz, ixy, ixz, iyz) in zip(table, dh.centres_of_mass, dh.inertias):
        X = shift(x=a) @ rot_x(alpha)
        coms.append((X @ np.r_[com, 1.0])[:3])
        tensor = X[:3, :3] @ np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]) @ X[:3, :3].T
        inertias.append([tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2]])
    return dict(table=modified, centres_of_mass=np.array(coms), inertias=np.array(inertias))


def arm_from(dh: DhArm, convention: str, table, centres_of_mass, inertias) -> ChainArm:
    return ChainArm.from_dh(dh.name, table, convention, masses=dh.masses, centres_of_mass=centres_of_mass,
                            inertias=inertias, link_radius=dh.link_radius, lower_limits=dh.lower, upper_limits=dh.upper,
                            velocity_limits=dh.velocity_limits, acceleration_limits=dh.acceleration_limits,
                            effort_limits=dh.effort_limits)


def model_flanges(arm: ChainArm, convention: str, table, masses, coms, inertias, configurations) -> list:
    """The flange poses of the arm's written model at ``configurations``, each checked against the
    table: the model's FK (MultibodyPlant) and the SerialChain's equal the DH product to 1e-9, and
    every link's mass, centre of mass and inertia in the world are the table's."""
    plant = MultibodyPlant(0.0)
    arm.add_to_plant(plant)
    plant.Finalize()
    context = plant.CreateDefaultContext()
    bodies = [plant.GetBodyByName(name) for name in ("shoulder_link", "upper_arm_link", "forearm_link",
                                                      "wrist_1_link", "wrist_2_link", "wrist_3_link")]
    flanges = []
    for q in configurations:
        plant.SetPositions(context, q)
        frames = dh_frames(table, convention, q)
        flange = plant.GetFrameByName("tool0").CalcPoseInWorld(context).GetAsMatrix4()
        assert np.max(np.abs(flange - frames[5])) < 1e-9  # the model's FK is the table's
        assert np.max(np.abs(chain_pose(arm.chain, q) - flange)) < 1e-9  # and the SerialChain's
        flanges.append(flange)
        for body, frame, mass, com, (ixx, iyy, izz, ixy, ixz, iyz) in zip(bodies, frames, masses, coms, inertias):
            inertia = body.CalcSpatialInertiaInBodyFrame(context)
            X = body.EvalPoseInWorld(context).GetAsMatrix4()
            assert inertia.get_mass() == pytest.approx(mass, abs=1e-12)
            centre = X[:3, :3] @ inertia.get_com() + X[:3, 3]
            assert np.max(np.abs(centre - (frame @ np.r_[com, 1.0])[:3])) < 1e-9
            about_com = inertia.Shift(inertia.get_com()).CalcRotationalInertia().CopyToFullMatrix3()
            table_tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
            assert np.max(np.abs(X[:3, :3] @ about_com @ X[:3, :3].T - frame[:3, :3] @ table_tensor @ frame[:3, :3].T)) < 1e-9
    return flanges


def test_the_written_model_is_the_table_in_both_conventions():
    dh = puma_arm()
    modified = modified_from_standard(dh)
    configurations = np.random.default_rng(5).uniform(dh.lower, dh.upper, (8, 6))
    flanges = {}
    for convention, table, coms, inertias in (("standard", dh.dh, dh.centres_of_mass, dh.inertias),
                                              ("modified", modified["table"], modified["centres_of_mass"],
                                               modified["inertias"])):
        arm = arm_from(dh, convention, table, coms, inertias)
        flanges[convention] = model_flanges(arm, convention, np.array(table), dh.masses, coms, inertias, configurations)
    np.testing.assert_allclose(flanges["standard"], flanges["modified"], atol=1e-9)  # one arm, two tables


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_random_tables_are_written_exactly(seed, convention):
    """Seeded random tables (lengths to 0.5 m, any angles and offsets), masses, centres of mass and
    rigid-body inertias with products: the written model is the table in either convention."""
    rng = np.random.default_rng(seed)
    table = np.column_stack([rng.uniform(-0.5, 0.5, (6, 2)), rng.uniform(-np.pi, np.pi, (6, 2))])
    masses, coms = rng.uniform(0.5, 10.0, 6), rng.uniform(-0.2, 0.2, (6, 3))
    inertias = []
    for _ in range(6):  # principal moments of a box, turned by a random rotation
        x, y, z = rng.uniform(0.05, 0.5, 3) ** 2
        moments = np.diag([y + z, x + z, x + y]) / 12
        rotation = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        tensor = rotation @ moments @ rotation.T
        inertias.append([tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2]])
    arm = ChainArm.from_dh("random_arm", table, convention, masses=masses, centres_of_mass=coms, inertias=inertias,
                           lower_limits=[-np.pi] * 6, upper_limits=[np.pi] * 6, velocity_limits=1.0,
                           acceleration_limits=1.0, effort_limits=10.0)
    model_flanges(arm, convention, table, masses, coms, inertias, rng.uniform(-np.pi, np.pi, (5, 6)))


def test_only_the_spherical_wrists_always_touching_links_are_filtered():
    arm = load_scenario(PUMA, "quintic").base_robot()
    assert arm.model_text.count("<drake:collision_filter_group") == 1
    assert '<drake:member link="wrist_1_link"/>\n    <drake:member link="wrist_3_link"/>' in arm.model_text
    checker = CellChecker(arm)
    assert checker.contacts(arm.home_configuration, within=0.005) == []
    bodies = {"base", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link", "wrist_3_link"}
    seen, apart = set(), set()
    for q in np.random.default_rng(3).uniform(arm.lower_limits, arm.upper_limits, (60, 6)):
        for contact in checker.contacts(q, within=np.inf):
            if set(contact.bodies) <= bodies:
                seen.add(contact.bodies)
                if contact.distance > 0.0:
                    apart.add(contact.bodies)
    assert len(seen) == 14  # the 15 non-adjacent pairs of the 7 bodies but wrist 1 - wrist 3
    assert apart == seen  # each checked pair is apart somewhere: none is in contact everywhere


def test_the_filtered_pairs_follow_from_the_geometry():
    # the UR10e's table: its short column (d1 = 0.1807 m) puts the pedestal's top (d1 / 2) 0.0903 m
    # below the shoulder, where axes 1 and 2 meet and the upper arm starts; its offset wrist's axes
    # 4 and 5 meet 0.174 m (d4) from the forearm's capsule axis, 5 and 6 0.120 m (d5) from wrist 1's
    ur10e = SerialChain.from_dh([[0.1807, 0, np.pi / 2, 0], [0, -0.6127, 0, 0], [0, -0.57155, 0, 0],
                                 [0.17415, 0, np.pi / 2, 0], [0.11985, 0, -np.pi / 2, 0], [0.11655, 0, 0, 0]])
    assert [pair[:2] for pair in touching_pairs(ur10e, 0.04)] == []  # 0.0903 m > 2 x 0.04 m
    assert [pair[:2] for pair in touching_pairs(ur10e, 0.05)] == [(0, 2)]
    assert [pair[:2] for pair in touching_pairs(ur10e, 0.07)] == [(0, 2), (4, 6)]  # 0.11985 m <= 2 x 0.07 m
    assert [pair[:2] for pair in touching_pairs(ur10e, 0.09)] == [(0, 2), (3, 5), (4, 6)]  # 0.17415 m <= 2 x 0.09 m
    puma = SerialChain.from_dh(puma_arm().dh)
    assert [pair[:2] for pair in touching_pairs(puma, 0.05)] == [(4, 6)]


@pytest.mark.parametrize("variant", ["pajak", "quintic"])
def test_the_puma_runs_each_planner_in_the_closed_loop(variant):
    scenario = load_scenario(PUMA, variant)
    arm = scenario.base_robot()
    result = simulate(scenario)
    assert result.succeeded, result.failure
    assert result.robot == "puma560" and np.array_equal(result.effort_limit, arm.effort_limits)
    q_end = result.q_meas[-1]
    if variant == "pajak":
        goal = np.array(scenario.planner.waypoints[-1])
        assert np.linalg.norm(arm.tcp_pose(q_end)[:3] - goal[:3]) < 1e-3
        assert orientation_error(arm.tcp_pose(q_end)[3:], goal[3:]) < 1e-3
        start = arm.tcp_pose(scenario.start_configuration())[3:]  # orientation held throughout
        assert max(orientation_error(pose[3:], start) for pose in arm.tcp_pose(result.q_ref[::20])) < 0.05
    else:
        assert np.max(np.abs(q_end - scenario.planner.goals[-1])) < 1e-3
        law = make_scenario_planner(scenario).law
        _, qd, qdd = law.sample(np.linspace(0.0, law.duration, 20001))
        assert np.max(np.abs(qd) / arm.velocity_limits) <= 1 + 1e-12
        assert np.max(np.abs(qdd) / arm.joint_move_limits[1]) <= 1 + 1e-12
    velocity, acceleration = arm.joint_move_limits
    assert np.max(np.abs(result.qd_ref) / velocity) <= 1 + LIMIT_TOLERANCE
    assert np.max(np.abs(result.qdd_ref) / acceleration) <= 1 + LIMIT_TOLERANCE
    assert np.all(np.abs(result.tau) <= arm.effort_limits)
    checker = scenario.cell_checker()  # what the run's preflight checked the plan with, on the executed motion
    assert all(checker.contacts(q) == [] for q in result.q_meas[::5])


USER_ARM = """name: user_arm
robot: !CustomArm
  model_file: puma.urdf
  name: my_puma
  acceleration_limits: [2.0, 2.0, 2.0, 2.0, 2.0, 2.0]
  payload: 2.5
q_initial: [0.2, 0.6, -2.5, 0.2, -0.9, 0.1]
planner: !QuinticConfig
  goals:
    - [0.6, 0.4, -2.2, -0.3, -1.1, 0.5]
"""


def test_a_custom_arm_from_a_users_urdf_runs_a_quintic_task(tmp_path):
    (tmp_path / "puma.urdf").write_text(load_scenario(PUMA, "quintic").base_robot().model_text)
    path = tmp_path / "user_arm.yaml"
    path.write_text(USER_ARM)
    scenario = load_scenario(path)
    arm = scenario.base_robot()
    assert arm.name == "my_puma" and arm.model_file == tmp_path / "puma.urdf" and str(path) in arm.data_source
    assert arm.reach == pytest.approx(0.672 + 0.4318 + math.hypot(0.0203, 0.15005) + 0.4318)
    result = simulate(scenario)
    assert result.succeeded and result.robot == "my_puma"
    assert np.max(np.abs(result.q_meas[-1] - scenario.planner.goals[0])) < 1e-3
    assert np.max(np.abs(result.qd_ref)) <= 1.0 * (1 + LIMIT_TOLERANCE)  # the file's velocity limits
    assert np.max(np.abs(result.qdd_ref)) <= 2.0 * (1 + LIMIT_TOLERANCE)


def test_an_arm_from_a_users_own_plant_plans_beside_it():
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    (instance,) = Parser(plant).AddModels(str(DIAGRAMS.parent / "models" / "ur5e.urdf"))  # "the user's file"
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("base", instance))
    plant.Finalize()
    with pytest.raises(ValueError, match=r"^the custom arm's name would be 'ur5e' \(the tool body's model instance\), "
                                         r"a known robot's name .*give the arm a name of its own \(name=\)"):
        ChainArm.from_plant(plant, base_frame="base", tool_frame="tool0", acceleration_limits=[2.0] * 6)
    arm = ChainArm.from_plant(plant, name="my_arm", base_frame="base", tool_frame="tool0", acceleration_limits=[2.0] * 6)
    assert arm.model_file is None and arm.data_source == "a user's plant"
    start, goal = np.array([-1.5, -1.5, -2.0, -0.8, 1.6, 0.8]), np.array([-1.3, -1.7, -1.8, -1.0, 1.4, 1.0])
    planner = builder.AddSystem(make_planner(QuinticConfig(goals=[goal.tolist()]), arm, start))
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(planner.planned_duration() + 0.01)
    q = planner.GetOutputPort("desired_state").Eval(planner.GetMyContextFromRoot(simulator.get_context()))[:6]
    assert np.max(np.abs(q - goal)) < 1e-6
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, q)
    flange = plant.GetFrameByName("tool0").CalcPoseInWorld(context).GetAsMatrix4()
    assert np.max(np.abs(chain_pose(arm.chain, q) - flange)) < 1e-9
    with pytest.raises(ValueError, match=r"was built from a plant without a model_file"):
        simulate(planner)


def puma_yaml(**replace) -> str:
    text = PUMA.read_text()
    for old, new in replace.items():
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    return text


def custom_arm_yaml(model_file: str, extra: str = "") -> str:
    return (f"name: bad_arm\nrobot: !CustomArm\n  model_file: {model_file}\n  acceleration_limits: [2, 2, 2, 2, 2, 2]\n"
            f"{extra}planner: !QuinticConfig\n  goals: [[0.1, 0.1, 0.1, 0.1, 0.1, 0.1]]\n")


def line_of(text: str, start: str) -> int:
    return next(k for k, line in enumerate(text.splitlines(), 1) if line.strip().startswith(start))


def test_bad_custom_arms_are_refused_at_their_line_naming_the_field(tmp_path):
    model = load_scenario(PUMA, "quintic").base_robot().model_text
    cases = [
        ("li.urdf", (DIAGRAMS.parent / "models" / "li_4dof.urdf").read_text(), "",
         r"robot.model_file: 4 joints between base and tool0"),
        ("prismatic.urdf", model.replace('<joint name="joint_3" type="revolute">', '<joint name="joint_3" type="prismatic">'),
         "", r"robot.model_file: joint 'joint_3' is PrismaticJoint: a 6-axis arm has revolute joints only"),
        ("no_speeds.urdf", model.replace(' velocity="1.0"', ""), "",
         r"robot.velocity_limits: (velocity_limits )?missing for the custom arm 'custom_arm'"),
    ]
    for name, urdf, extra, message in cases:
        (tmp_path / name).write_text(urdf)
        path = tmp_path / "bad.yaml"
        path.write_text(custom_arm_yaml(name, extra))
        with pytest.raises(ScenarioError, match=message) as caught:
            load_scenario(path)
        field = caught.value.field
        assert field[0] == "robot" and f"bad.yaml, line {line_of(path.read_text(), field[1] + ':') if field[1] == 'model_file' else 2}," in str(caught.value)


def continuous_joint_2(tmp_path):
    """The PUMA's written model with joint 2 continuous (no position range; speed and torque kept)."""
    model = load_scenario(PUMA, "quintic").base_robot().model_text
    start = model.index('<joint name="joint_2" type="revolute">')
    limit = model.index("<limit ", start)
    end = model.index("/>", limit) + 2
    speed_and_torque = " ".join(part for part in model[limit:end].split() if part.startswith(("velocity=", "effort=")))
    path = tmp_path / "continuous.urdf"
    path.write_text(model[:start] + model[start:limit].replace('type="revolute"', 'type="continuous"')
                    + f"<limit {speed_and_torque.removesuffix('/>')}/>" + model[end:])
    return path


def test_a_missing_limit_names_the_continuous_joints_and_what_to_give_in_each_way_in():
    error = arm_checks.missing_limit("lower_limits", "my_arm", ("joint_2",))
    assert error.field == ("lower_limits",) and error.unbounded_joints == ("joint_2",)
    assert str(error) == ("lower_limits missing for the custom arm 'my_arm': its model gives joint 'joint_2' no finite "
                          "position range (a continuous joint, or limits of ±inf), which a planner needs; give "
                          "lower_limits= and upper_limits= (6 values each [rad])")
    fields = {"lower_limits": "lower", "upper_limits": "upper"}
    scenario = arm_checks.scenario_message(error, lambda key: "robot." + fields.get(key, key))
    assert scenario.startswith("missing for the custom arm 'my_arm': its model gives joint 'joint_2' no finite")
    assert scenario.endswith("give robot.lower and robot.upper (6 values each [rad])")
    assert "lower_limits" not in scenario
    plain = arm_checks.missing_limit("velocity_limits", "my_arm")
    assert arm_checks.scenario_message(plain, lambda key: "robot." + key) == (
        "missing for the custom arm 'my_arm': neither its model nor the scenario gives it (give robot.velocity_limits, "
        "6 values [rad/s])")
    assert arm_checks.scenario_message(DrakeTrajError("other", field=("x",)), str.upper) == "other"
    assert arm_checks.unbounded_joints([-1.0, -np.inf, 0.0, np.nan], ["a", "b", "c", "d"]) == ("b", "d")


def test_a_continuous_joint_runs_once_the_scenario_gives_its_range(tmp_path):
    model = continuous_joint_2(tmp_path)
    path = tmp_path / "ranged.yaml"
    path.write_text(custom_arm_yaml(model.name, "  lower: [-3, -3, -3, -3, -3, -3]\n  upper: [3, 3, 3, 3, 3, 3]\n"))
    arm = load_scenario(path).base_robot()
    assert arm.lower_limits.tolist() == [-3.0] * 6 and arm.upper_limits.tolist() == [3.0] * 6


def test_a_continuous_joint_is_refused_naming_the_scenarios_range_fields(tmp_path):
    model = continuous_joint_2(tmp_path)
    path = tmp_path / "bad.yaml"
    path.write_text(custom_arm_yaml(model.name))
    with pytest.raises(ScenarioError, match=r"bad.yaml, line 2, column \d+: robot.lower: missing for the custom arm "
                                            r"'custom_arm': its model gives joint 'joint_2' no finite position range "
                                            r"\(a continuous joint, or limits of ±inf\), which a planner needs; give "
                                            r"robot.lower and robot.upper \(6 values each \[rad\]\)$") as caught:
        load_scenario(path).base_robot()
    assert caught.value.field == ("robot", "lower") and "lower_limits" not in str(caught.value)
    # from Python, the same error names the keywords
    with pytest.raises(DrakeTrajError, match=r"^lower_limits missing for the custom arm 'arm': its model gives joint "
                                             r"'joint_2' no finite position range .*give lower_limits= and "
                                             r"upper_limits= \(6 values each \[rad\]\)$"):
        ChainArm.from_model_file(model, name="arm", base_frame="base", tool_frame="tool0", acceleration_limits=[2.0] * 6)


def test_a_bad_dh_table_is_refused_by_the_command_line(tmp_path, capsys):
    path = tmp_path / "puma.yaml"
    path.write_text(puma_yaml(**{"    - [0.0, 0.4318, 0.0, 0.0]": "    - [0.0, .nan, 0.0, 0.0]"}))
    assert cli.main(["run", str(path), "--variant", "quintic", "--out", str(tmp_path / "out")]) == 2
    error = capsys.readouterr().err
    assert f"puma.yaml, line {line_of(path.read_text(), '- [0.0, .nan')}" in error and "robot.dh[1][1] must be finite" in error
    path.write_text(puma_yaml(**{"    - [0.0, 0.0, 0.0, 0.0]\n": "    - [0.0, 0.0, 0.0]\n"}))
    with pytest.raises(ScenarioError, match=r"robot.dh .*rows must have the same length"):
        load_scenario(path, "quintic")
    path.write_text(puma_yaml(**{"[0.066, 0.086, 0.020,": "[0.066, 0.086, 0.0125,"}))  # link 3 as published
    with pytest.raises(ScenarioError, match=r"robot.inertias\[2\] is not a rigid body's inertia: its principal moments "
                                            r"0.0125, 0.066, 0.086 kg m\^2 must be >= 0 and each at most the sum") as caught:
        load_scenario(path, "quintic")
    assert caught.value.field == ("robot", "inertias", 2)


def test_a_pajak_waypoint_beyond_the_pumas_reach_names_its_numbers(tmp_path):
    path = tmp_path / "puma.yaml"
    path.write_text(puma_yaml(**{"      - [0.6231217554964667, 0.2536176948257900,": "      - [1.8231217554964667, 0.2536176948257900,"}))
    with pytest.raises(ValueError, match=r"waypoint 2 cannot be reached: .*the arm reaches at most 1\.68702 m") as caught:
        simulate(load_scenario(path, "pajak"))
    assert caught.value.field == ("planner", "waypoints", 2)
    assert f"puma.yaml, line {line_of(path.read_text(), '- [1.8231')}" in str(caught.value)


def test_a_payload_above_the_pumas_rating_is_refused(tmp_path):
    path = tmp_path / "puma.yaml"
    path.write_text(puma_yaml(**{"  max_duration: 30.0\n\nquintic:": "  max_duration: 30.0\n  cell:\n    tool:\n      mass: 3.0\n\nquintic:"}))
    with pytest.raises(ScenarioError, match=r"cell.tool.mass = 3 kg is above the puma560 robot's rated payload of 2.5 kg"):
        load_scenario(path, "pajak")


def test_the_command_line_shows_the_puma_example(capsys):
    assert cli.main(["list"]) == 0
    listing = capsys.readouterr().out
    assert any("puma560_pajak" in line and "puma560 (DhArm)" in line for line in listing.splitlines())
    assert cli.main(["robots"]) == 0
    robots = capsys.readouterr().out
    assert "puma560 (DhArm)" in robots and "puma560.yaml" in robots
    assert not any(line.startswith("puma560 ") for line in robots.splitlines())  # not a registered robot


def test_a_zero_length_dh_table_is_refused_at_dh():
    arm = puma_arm()
    arm.dh = [[0.0, 0.0, row[2], row[3]] for row in arm.dh]
    with pytest.raises(ValueError, match=r"^robot.dh: a chain needs at least one link of non-zero length") as caught:
        resolve_robot(arm)
    assert caught.value.field == ("robot", "dh")


def puma_from_dh(name="my_puma", **change) -> ChainArm:
    """The PUMA 560 through ChainArm.from_dh (the Python path), its data changed by ``change``."""
    dh = puma_arm()
    arguments = dict(masses=dh.masses, centres_of_mass=dh.centres_of_mass, inertias=dh.inertias,
                     link_radius=dh.link_radius, lower_limits=dh.lower, upper_limits=dh.upper,
                     velocity_limits=dh.velocity_limits, acceleration_limits=dh.acceleration_limits,
                     effort_limits=dh.effort_limits, rated_payload=dh.payload)
    return ChainArm.from_dh(name, dh.dh, **{**arguments, **change})


def test_limits_upside_down_are_refused_before_drake_parses_them():
    with pytest.raises(ValueError, match=r"^upper_limits\[0\] = -3 rad must be above lower_limits\[0\] = 3 rad") as caught:
        ChainArm.from_dh("z", puma_arm().dh, lower_limits=[3] * 6, upper_limits=[-3] * 6, velocity_limits=1.,
                         acceleration_limits=2., effort_limits=100., masses=[1] * 6)
    assert caught.value.field == ("upper_limits", 0)


def test_a_users_model_file_with_a_limit_upside_down_is_an_error_naming_the_file(tmp_path, capsys):
    model = load_scenario(PUMA, "quintic").base_robot().model_text
    start = model.index('<limit lower="', model.index('<joint name="joint_2"'))
    end = model.index('velocity=', start)
    (tmp_path / "bad.urdf").write_text(model[:start] + '<limit lower="7.0" upper="6.28" ' + model[end:])
    path = tmp_path / "bad.yaml"
    path.write_text(custom_arm_yaml("bad.urdf"))
    assert cli.main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    error = capsys.readouterr().err
    assert "robot.model_file: the model file" in error and "bad.urdf could not be read" in error
    with pytest.raises(ScenarioError, match=r"robot.model_file: the model file .*bad.urdf could not be read: .*joint") as caught:
        load_scenario(path)
    assert caught.value.field == ("robot", "model_file")


@pytest.mark.parametrize("change, field, pattern", [
    (dict(masses=[1.0, 1.0, 0.0, 1.0, 1.0, 1.0]), ("masses", 2), r"masses\[2\] must be positive \[kg\], got 0"),
    (dict(masses=[1.0, -2.0, 1.0, 1.0, 1.0, 1.0]), ("masses", 1), r"masses\[1\] must be positive \[kg\], got -2"),
    (dict(inertias=[[0.1, 0.0, 0.35, 0, 0, 0]] + [[0.1, 0.1, 0.1, 0, 0, 0]] * 5), ("inertias", 0),
     r"inertias\[0\] is not a rigid body's inertia: its principal moments 0, 0.1, 0.35"),
    (dict(inertias=[[0.1, 0.1, 0.1, 0, 0, 0]] * 3 + [[0.1, 0.1, 0.3, 0, 0, 0]] + [[0.1, 0.1, 0.1, 0, 0, 0]] * 2),
     ("inertias", 3), r"inertias\[3\] is not a rigid body's inertia: .* each at most the sum of the other two"),
    (dict(rated_payload=float("nan")), ("rated_payload",), r"rated_payload must be finite"),
    (dict(rated_payload=-1.0), ("rated_payload",), r"rated_payload must be positive \[kg\]"),
    (dict(link_radius=0.0), ("link_radius",), r"link_radius must be positive \[m\], got 0"),
    (dict(link_radius=float("nan")), ("link_radius",), r"link_radius must be finite"),
    (dict(centres_of_mass=np.zeros((6, 2))), ("centres_of_mass",),
     r"centres_of_mass must be 6 rows of 3 numbers \[m\], got shape \(6, 2\)"),
])
def test_from_dh_refuses_what_the_scenario_refuses_naming_the_argument(change, field, pattern):
    with pytest.raises(ValueError, match=pattern) as caught:
        puma_from_dh(**change)
    assert caught.value.field == field


def test_the_constructor_checks_the_rated_payload(tmp_path):
    (tmp_path / "puma.urdf").write_text(load_scenario(PUMA, "quintic").base_robot().model_text)
    arm = ChainArm.from_model_file(tmp_path / "puma.urdf", base_frame="base", tool_frame="tool0",
                                   acceleration_limits=2.0, rated_payload=2.5)
    assert arm.name == "puma" and arm.rated_payload == 2.5
    for rating in (float("nan"), 0.0, -2.5):
        with pytest.raises(ValueError, match=r"^rated_payload must be") as caught:
            ChainArm.from_model_file(tmp_path / "puma.urdf", base_frame="base", tool_frame="tool0",
                                     acceleration_limits=2.0, rated_payload=rating)
        assert caught.value.field == ("rated_payload",)


def test_a_custom_arm_cannot_take_a_known_robots_name(tmp_path):
    """A PUMA named "ur10e" would be exported as a UR10e's URScript: every constructor refuses a
    known robot's name, given or defaulted from the file's stem."""
    with pytest.raises(ValueError, match=r"^name 'ur10e' is a known robot's name") as caught:
        puma_from_dh(name="ur10e")
    assert caught.value.field == ("name",)
    (tmp_path / "ur5e.urdf").write_text(load_scenario(PUMA, "quintic").base_robot().model_text)
    with pytest.raises(ValueError, match=r"^the custom arm's name would be 'ur5e' \(the model file's name 'ur5e.urdf'\), "
                                         r"a known robot's name .*\(name=\)") as caught:
        ChainArm.from_model_file(tmp_path / "ur5e.urdf", base_frame="base", tool_frame="tool0", acceleration_limits=2.0)
    assert caught.value.field == ("name",)
    arm = ChainArm.from_model_file(tmp_path / "ur5e.urdf", name="my_puma", base_frame="base", tool_frame="tool0",
                                   acceleration_limits=2.0)
    assert arm.name == "my_puma"
    with pytest.raises(ValueError, match=r"^name 'li_4dof' is a known robot's name"):
        ChainArm(arm.chain, name="li_4dof", model_file=arm.model_file, base_frame="base", tool_frame="tool0",
                 joint_names=arm.joint_names, lower_limits=arm.lower_limits, upper_limits=arm.upper_limits,
                 velocity_limits=1.0, acceleration_limits=2.0, effort_limits=100.0)


def six_r_sdf() -> str:
    """A small 6R arm as SDFormat (axes z, y, y, x, y, x; links of 1 kg), the joints with effort
    limits: Drake's SDF parser gives each an actuator named after the joint."""
    origins = [(0, 0, 0.2), (0, 0, 0.1), (0.3, 0, 0), (0.3, 0, 0), (0.1, 0, 0), (0.1, 0, 0)]
    axes = ["0 0 1", "0 1 0", "0 1 0", "1 0 0", "0 1 0", "1 0 0"]
    inertial = ("<inertial><mass>1.0</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz>"
                "<ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>")
    links, joints, pose = ['<link name="base">' + inertial + "</link>"], [], np.zeros(3)
    for i, (origin, axis) in enumerate(zip(origins, axes), 1):
        pose = pose + origin
        links.append(f'<link name="link{i}"><pose>{pose[0]} {pose[1]} {pose[2]} 0 0 0</pose>{inertial}</link>')
        joints.append(f'<joint name="j{i}" type="revolute"><parent>{"base" if i == 1 else f"link{i - 1}"}</parent>'
                      f'<child>link{i}</child><axis><xyz>{axis}</xyz><limit><lower>-3</lower><upper>3</upper>'
                      f'<velocity>2</velocity><effort>60</effort></limit></axis></joint>')
    return ('<?xml version="1.0"?>\n<sdf version="1.9"><model name="six_r">' + "".join(links) + "".join(joints)
            + '<frame name="tool0" attached_to="link6"><pose>0.05 0 0 0 0 0</pose></frame></model></sdf>\n')


@pytest.mark.parametrize("model", ["six_r.sdf", "ros_style.urdf"])
def test_an_sdf_arm_and_an_arm_with_its_own_actuator_names_run_in_the_closed_loop(tmp_path, model):
    """The station finds each joint's actuator by its joint, whatever the model calls it."""
    if model.endswith(".sdf"):
        text, goal = six_r_sdf(), [0.4, -0.3, 0.5, 0.3, -0.4, 0.2]
    else:
        text = load_scenario(PUMA, "quintic").base_robot().model_text
        assert text.count('_actuator">') == 6
        text, goal = text.replace('_actuator">', '_motor">'), [0.6, 0.4, -2.2, -0.3, -1.1, 0.5]
    (tmp_path / model).write_text(text)
    path = tmp_path / "arm.yaml"
    unchecked = "  unchecked_links: [all]\n" if model.endswith(".sdf") else ""  # the SDF arm has no collision shapes
    path.write_text(f"name: own_actuators\nrobot: !CustomArm\n  model_file: {model}\n  name: my_arm\n{unchecked}"
                    "  acceleration_limits: [2, 2, 2, 2, 2, 2]\n"
                    f"q_initial: {[0.2, 0.6, -2.5, 0.2, -0.9, 0.1] if model.endswith('.urdf') else [0.0] * 6}\n"
                    f"planner: !QuinticConfig\n  goals: [{goal}]\n")
    scenario = load_scenario(path)
    plant = MultibodyPlant(0.001)
    instance = scenario.base_robot().add_to_plant(plant)
    plant.Finalize()
    names = [plant.get_joint_actuator(index).name() for index in plant.GetJointActuatorIndices(instance)]
    assert names == ([f"j{i}" for i in range(1, 7)] if model.endswith(".sdf") else [f"joint_{i}_motor" for i in range(1, 7)])
    result = simulate(scenario)
    assert result.succeeded and result.robot == "my_arm"
    assert result.metrics().unchecked_links == ([f"link{i}" for i in range(1, 7)] if model.endswith(".sdf") else [])
    assert np.max(np.abs(result.q_meas[-1] - goal)) < 1e-3
    assert np.max(np.abs(result.qd_ref)) <= (2.0 if model.endswith(".sdf") else 1.0) * (1 + LIMIT_TOLERANCE)


def test_actuators_out_of_the_joints_order_are_refused(tmp_path):
    """The plant's desired-state and actuation ports go by actuator: a model whose transmissions
    come in another order than its joints would drive the wrong joints."""
    text = load_scenario(PUMA, "quintic").base_robot().model_text
    start = text.index('<transmission name="joint_1_transmission">')
    end = text.index("</transmission>", start) + len("</transmission>\n")
    first = text[start:end]
    text = text[:start] + text[end:]
    at = text.index("</robot>")
    (tmp_path / "reordered.urdf").write_text(text[:at] + first + text[at:])
    path = tmp_path / "arm.yaml"
    path.write_text(custom_arm_yaml("reordered.urdf"))
    with pytest.raises(ValueError, match=r"the custom_arm model's actuators drive the joints \['joint_2', 'joint_3', "
                                         r"'joint_4', 'joint_5', 'joint_6', 'joint_1'\] in this order"):
        simulate(load_scenario(path))


def test_boryga_loop_on_the_puma_is_the_seeded_ik_nearest_the_reference():
    """The loop law's knots (warm-started IK, each from the knot before) are the seeded search's
    solutions nearest the reference (the branch of the start, on this loop that never flips), to
    1e-9 rad, and put the TCP on the path between them to 1e-6 m."""
    from drake_traj.planners.boryga import BorygaConfig, make

    arm = load_scenario(PUMA, "quintic").base_robot()
    reference = np.array([0.2, 0.6, -2.5, 0.2, -0.9, 0.1])
    law = make(BorygaConfig(), arm, reference).law
    orientation = arm.tcp_pose(reference)[3:]
    for knot in law.knots[np.linspace(0, len(law.knots) - 2, 15).astype(int)]:
        position = law.plan.sample(knot)[0].reshape(3)
        expected = arm._nearest_solution(np.concatenate([position, orientation]), reference)
        np.testing.assert_allclose(law.sample(knot)[0], expected, atol=1e-9, rtol=0)
    for tau in np.linspace(0.0, law.plan.duration, 15):
        np.testing.assert_allclose(arm.tcp_pose(law.sample(tau)[0])[:3], law.plan.sample(tau)[0].reshape(3), atol=1e-6)
