"""models/ur10e.urdf: kinematics, inertials, limits, actuators and shapes against docs/ur10e.md.

The model is checked against numbers that do not come from Drake: robot.dh_frames (UR's standard DH
table) for the kinematics, the published mass / CoM / inertia table for the inertials, and gravity
torques summed by hand from masses and lever arms.
"""

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from pydrake.geometry import Capsule, Cylinder, Role
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.multibody.tree import JointActuatorIndex
from pydrake.systems.framework import DiagramBuilder

from drake_traj.robots import base as robot_base
from drake_traj.robots import ur10e as robot

MODEL_FILE = Path(__file__).resolve().parents[2] / "models" / "ur10e.urdf"
LINK_NAMES = (
    "shoulder_link",
    "upper_arm_link",
    "forearm_link",
    "wrist_1_link",
    "wrist_2_link",
    "wrist_3_link",
)
GRAVITY = 9.81  # [m/s^2], Drake's default gravity field is (0, 0, -9.81)

# Pająk 2024's start configuration q(0) and the paper's p0 (printed rounded to [-0.174, -0.524, 0.273]).
Q0 = np.array([-np.pi / 2, -np.pi / 2, -3 * np.pi / 4, -np.pi / 4, np.pi / 2, np.pi / 4])

# Published dynamics (docs/ur10e.md), link i in standard-DH frame i.
COM_IN_DH_FRAME = np.array(
    [
        [0.021, 0.0, 0.027],
        [0.38, 0.0, 0.158],
        [0.24, 0.0, 0.068],
        [0.0, 0.007, 0.018],
        [0.0, 0.007, 0.018],
        [0.0, 0.0, -0.026],
    ]
)
INERTIA_ABOUT_COM = np.array(  # (ixx, ixy, ixz, iyy, iyz, izz) [kg m^2], axes of DH frame i
    [
        [0.03408, 0.00002, -0.00425, 0.03529, 0.00008, 0.02156],
        [0.02814, 0.00005, -0.01561, 0.77068, 0.00002, 0.76943],
        [0.01014, 0.00008, 0.00916, 0.30928, 0.0, 0.30646],
        [0.00296, -0.00001, 0.0, 0.00222, -0.00024, 0.00258],
        [0.00296, -0.00001, 0.0, 0.00222, -0.00024, 0.00258],
        [0.00040, 0.0, 0.0, 0.00041, 0.0, 0.00034],
    ]
)

HOUSING_RGBA = (0.2, 0.4, 0.9, 1.0)  # every joint housing (the browser test looks for these pixels)
TUBE_RGBA = (0.75, 0.78, 0.82, 1.0)  # base, tubes, flange


# --- helpers -------------------------------------------------------------------------------------


def load_ur10e(*, without_packages=False):
    """Plant + SceneGraph with models/ur10e.urdf parsed strictly (warnings are errors), base welded.

    without_packages: empty the parser's PackageMap first (no drake_models, whose files Drake would
    download on first use), so any package:// reference in the model would fail to resolve.
    """
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    parser = Parser(plant)
    parser.SetStrictParsing()
    if without_packages:
        for package in parser.package_map().GetPackageNames():
            parser.package_map().Remove(package)
    (instance,) = parser.AddModels(str(MODEL_FILE))
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(robot.BASE_FRAME, instance))
    plant.Finalize()
    diagram = builder.Build()
    return SimpleNamespace(diagram=diagram, plant=plant, scene_graph=scene_graph, instance=instance)


@pytest.fixture(scope="module")
def ur10e():
    return load_ur10e()


def plant_context(model, q):
    """A fresh root context with the arm at q; returns the plant's sub-context."""
    root = model.diagram.CreateDefaultContext()
    context = model.plant.GetMyContextFromRoot(root)
    model.plant.SetPositions(context, model.instance, np.asarray(q, dtype=float))
    return context


def inertia_matrix(row):
    ixx, ixy, ixz, iyy, iyz, izz = row
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])


def com_positions_in_world(q):
    """(6, 3) world CoMs of links 1..6 from the DH chain and the published table (no Drake)."""
    frames = robot.dh_frames(q)
    return np.array([frames[i + 1][:3, :3] @ COM_IN_DH_FRAME[i] + frames[i + 1][:3, 3] for i in range(6)])


def gravity_torques_by_hand(q):
    """tau_j = u_j . sum_{i >= j} (c_i - p_j) x (m_i g), with joint j's axis u_j through p_j (DH frame j-1).

    This is the generalized force *applied by* gravity, Drake's CalcGravityGeneralizedForces convention.
    """
    frames = robot.dh_frames(q)
    com = com_positions_in_world(q)
    weight = np.array([0.0, 0.0, -GRAVITY])
    tau = np.zeros(6)
    for j in range(6):
        axis, point = frames[j][:3, 2], frames[j][:3, 3]
        moment = sum(np.cross(com[i] - point, robot.LINK_MASSES[i] * weight) for i in range(j, 6))
        tau[j] = axis @ moment
    return tau


# --- 1. kinematics --------------------------------------------------------------------------------


def test_1_tool0_pose_equals_dh_chain_over_random_configurations(ur10e):
    plant = ur10e.plant
    context = plant_context(ur10e, np.zeros(6))
    tool0 = plant.GetFrameByName(robot.FLANGE_FRAME)
    rng = np.random.default_rng(0)
    for q in rng.uniform(-2 * np.pi, 2 * np.pi, (1000, 6)):
        plant.SetPositions(context, q)
        X_WT = plant.CalcRelativeTransform(context, plant.world_frame(), tool0).GetAsMatrix4()
        np.testing.assert_allclose(X_WT, robot.dh_frames(q)[-1], rtol=0, atol=1e-9, err_msg=f"q = {q}")


def test_2_seed_000_start_gives_p0(ur10e):
    plant = ur10e.plant
    context = plant_context(ur10e, Q0)
    X_WT = plant.CalcRelativeTransform(context, plant.world_frame(), plant.GetFrameByName(robot.FLANGE_FRAME))
    # Exact: (-0.17415, -0.5239969, 0.2727031); facts give 5 decimals, the paper 3 ([-0.174, -0.524, 0.273]).
    np.testing.assert_allclose(X_WT.translation(), [-0.17415, -0.52400, 0.27270], rtol=0, atol=5e-6)
    s = np.sqrt(0.5)
    np.testing.assert_allclose(X_WT.rotation().matrix(), [[-s, s, 0], [s, s, 0], [0, 0, -1]], rtol=0, atol=1e-12)


def test_3_home_pose_is_stretched_along_minus_x(ur10e):
    plant = ur10e.plant
    context = plant_context(ur10e, np.zeros(6))
    X_WT = plant.CalcRelativeTransform(context, plant.world_frame(), plant.GetFrameByName(robot.FLANGE_FRAME))
    np.testing.assert_allclose(X_WT.translation(), [-1.18425, -0.2907, 0.06085], rtol=0, atol=1e-12)


# --- 2. inertials ---------------------------------------------------------------------------------


def test_4_masses_match_table(ur10e):
    plant = ur10e.plant
    context = plant_context(ur10e, np.zeros(6))
    masses = [plant.GetBodyByName(name).get_mass(context) for name in LINK_NAMES]
    np.testing.assert_allclose(masses, robot.LINK_MASSES, rtol=0, atol=1e-12)
    # 7.369 + 13.051 + 3.989 + 2.1 + 1.98 + 0.615 = 29.104 kg (the task brief's 28.204 is a slip).
    assert sum(masses) == pytest.approx(29.104, abs=1e-12)
    assert plant.GetBodyByName(robot.BASE_FRAME).get_mass(context) == pytest.approx(robot.BASE_MASS)
    assert plant.CalcTotalMass(context, [ur10e.instance]) == pytest.approx(29.104 + 4.0, abs=1e-12)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_5_com_and_inertia_sit_in_dh_frames(ur10e, seed):
    # Independent of the URDF's inertial origins: CoM_i = X_W,DHi(q) c_i, and the rotational inertia
    # about the CoM, re-expressed in DH frame i, is the tabulated tensor.
    q = np.random.default_rng(100 + seed).uniform(-2 * np.pi, 2 * np.pi, 6)
    plant = ur10e.plant
    context = plant_context(ur10e, q)
    frames = robot.dh_frames(q)
    expected_com = com_positions_in_world(q)
    for i, name in enumerate(LINK_NAMES):
        body = plant.GetBodyByName(name)
        X_WB = body.EvalPoseInWorld(context)
        M_BBo_B = body.CalcSpatialInertiaInBodyFrame(context)
        p_BoBcm_B = M_BBo_B.get_com()
        np.testing.assert_allclose(X_WB.multiply(p_BoBcm_B), expected_com[i], rtol=0, atol=1e-9, err_msg=name)

        I_BBcm_B = M_BBo_B.Shift(p_BoBcm_B).CalcRotationalInertia().CopyToFullMatrix3()
        R_FB = frames[i + 1][:3, :3].T @ X_WB.rotation().matrix()  # F = DH frame i
        I_BBcm_F = R_FB @ I_BBcm_B @ R_FB.T
        np.testing.assert_allclose(I_BBcm_F, inertia_matrix(INERTIA_ABOUT_COM[i]), rtol=0, atol=1e-9, err_msg=name)


def test_6_gravity_torque_at_home_from_lever_arms(ur10e):
    # At q = 0 the arm is stretched along -x; the axes of joints 2 and 3 are horizontal (-y).
    q = np.zeros(6)
    frames = robot.dh_frames(q)
    com = com_positions_in_world(q)
    for j in (1, 2):  # joints 2 and 3
        np.testing.assert_allclose(frames[j][:3, 2], [0, -1, 0], atol=1e-15)
    # About an axis along -y through p, the weight -m g e_z of a point at c has moment
    # u . ((c - p) x (-m g e_z)) = -m g (c_x - p_x): only the horizontal lever arm c_x - p_x counts.
    p2_x, p3_x = frames[1][0, 3], frames[2][0, 3]  # 0 and -0.6127
    tau2 = -GRAVITY * sum(robot.LINK_MASSES[i] * (com[i, 0] - p2_x) for i in range(1, 6))
    tau3 = -GRAVITY * sum(robot.LINK_MASSES[i] * (com[i, 0] - p3_x) for i in range(2, 6))
    # CoM x [m]: link 2 -0.2327, link 3 -0.94425, links 4-6 (4.695 kg) -1.18425; elbow at -0.6127.
    # tau2 = 9.81 (13.051*0.2327 + 3.989*0.94425 + 4.695*1.18425) = 121.287 N m,
    # tau3 = 9.81 (3.989*0.33155 + 4.695*0.57155) = 39.299 N m (positive: gravity pulls the arm down).
    assert tau2 == pytest.approx(121.287256, abs=1e-6)
    assert tau3 == pytest.approx(39.298666, abs=1e-6)

    tau_g = ur10e.plant.CalcGravityGeneralizedForces(plant_context(ur10e, q))  # applied BY gravity
    assert tau_g[1] == pytest.approx(tau2, rel=1e-12)
    assert tau_g[2] == pytest.approx(tau3, rel=1e-12)
    assert tau_g[0] == pytest.approx(0.0, abs=1e-12)  # vertical axis: gravity has no moment about it
    np.testing.assert_allclose(tau_g, gravity_torques_by_hand(q), rtol=0, atol=1e-9)


@pytest.mark.parametrize(
    "q",
    [
        [0, -np.pi / 2, np.pi / 2, 0, 0, 0],  # upper arm straight up, forearm horizontal
        [np.pi / 2, 0, -np.pi / 2, -np.pi / 2, np.pi / 2, 0],
        Q0,
        np.random.default_rng(7).uniform(-2 * np.pi, 2 * np.pi, 6),
    ],
    ids=["upper_arm_up", "elbow_down", "seed000_q0", "random"],
)
def test_7_gravity_torques_equal_moments_of_link_weights(ur10e, q):
    tau_g = ur10e.plant.CalcGravityGeneralizedForces(plant_context(ur10e, q))
    np.testing.assert_allclose(tau_g, gravity_torques_by_hand(q), rtol=0, atol=1e-9)


# --- 3. joints, limits, actuators -----------------------------------------------------------------


def test_8_joints_and_limits_match_robot_constants(ur10e):
    plant = ur10e.plant
    assert plant.num_positions() == plant.num_velocities() == robot.NUM_JOINTS
    for k, name in enumerate(robot.JOINT_NAMES):
        joint = plant.GetJointByName(name, ur10e.instance)
        assert joint.type_name() == "revolute"
        assert joint.position_start() == k
        assert joint.position_lower_limits()[0] == pytest.approx(-robot.POSITION_LIMIT[k], rel=1e-15)
        assert joint.position_upper_limits()[0] == pytest.approx(robot.POSITION_LIMIT[k], rel=1e-15)
        assert joint.velocity_lower_limits()[0] == pytest.approx(-robot.VELOCITY_LIMIT[k], rel=1e-15)
        assert joint.velocity_upper_limits()[0] == pytest.approx(robot.VELOCITY_LIMIT[k], rel=1e-15)
    assert plant.GetJointByName("wrist_3-tool0_fixed_joint").type_name() == "weld"


def test_9_one_actuator_per_joint_with_effort_limit(ur10e):
    plant = ur10e.plant
    assert plant.num_actuators() == robot.NUM_JOINTS
    for k, name in enumerate(robot.JOINT_NAMES):
        actuator = plant.get_joint_actuator(JointActuatorIndex(k))
        assert actuator.name() == f"{name}_actuator"
        assert actuator.joint().name() == name
        assert actuator.input_start() == k
        assert actuator.effort_limit() == pytest.approx(robot.EFFORT_LIMIT[k], rel=1e-15)
        assert actuator.default_gear_ratio() == 1.0
        assert actuator.default_rotor_inertia() == 0.0


# --- 4. shapes -------------------------------------------------------------------------------------


def geometries(ur10e, role):
    """{geometry name: (body name, GeometryId)} of the model's geometries with the given role."""
    inspector = ur10e.scene_graph.model_inspector()
    plant = ur10e.plant
    found = {}
    for body_index in plant.GetBodyIndices(ur10e.instance):
        frame_id = plant.GetBodyFrameIdOrThrow(body_index)
        for geometry_id in inspector.GetGeometries(frame_id, role):
            found[inspector.GetName(geometry_id)] = (plant.get_body(body_index).name(), geometry_id)
    return inspector, found


def test_10_visuals_are_coloured_primitives(ur10e):
    inspector, visuals = geometries(ur10e, Role.kIllustration)
    assert set(body for body, _ in visuals.values()) == {robot.BASE_FRAME, *LINK_NAMES}
    housings = 0
    for name, (body, geometry_id) in visuals.items():
        # Tubes are capsules, housings, base and flange cylinders (tests/robots/test_ur10e_collision.py).
        assert isinstance(inspector.GetShape(geometry_id), Capsule if name.endswith("_tube") else Cylinder), name
        rgba = inspector.GetIllustrationProperties(geometry_id).GetProperty("phong", "diffuse")
        colour = (rgba.r(), rgba.g(), rgba.b(), rgba.a())
        if "housing" in name:
            housings += 1
            assert colour == pytest.approx(HOUSING_RGBA), name
        else:
            assert colour == pytest.approx(TUBE_RGBA), name
    assert housings == 6  # joint 1 housing and the motor housings of joints 2..6


def test_11_collision_shapes_do_not_touch_at_home_and_q0(ur10e):
    _, collisions = geometries(ur10e, Role.kProximity)
    assert set(body for body, _ in collisions.values()) == {robot.BASE_FRAME, *LINK_NAMES}
    for q in (np.zeros(6), Q0):
        root = ur10e.diagram.CreateDefaultContext()
        ur10e.plant.SetPositions(ur10e.plant.GetMyContextFromRoot(root), q)
        query = ur10e.scene_graph.get_query_output_port().Eval(ur10e.scene_graph.GetMyContextFromRoot(root))
        # Bodies joined by a joint are filtered by the plant; every other pair must be apart.
        assert query.ComputePointPairPenetration() == [], f"self-collision at q = {q}"


# --- 5. the file itself -----------------------------------------------------------------------------


def test_12_file_is_self_contained_and_loads_offline():
    text = MODEL_FILE.read_text()
    assert "package://" not in text
    assert "<mesh" not in text and "filename" not in text
    assert '<robot name="ur10e" xmlns:drake="http://drake.mit.edu">' in text  # drake:capsule's namespace
    # Drake reaches the network only to fetch remote packages (drake_models) named by package://
    # URIs; with an empty PackageMap nothing can be fetched. (DRAKE_ALLOW_NETWORK=none cannot be used
    # here: in Drake 1.51 Parser() itself then throws unless drake_models is already in the cache.)
    model = load_ur10e(without_packages=True)
    assert model.plant.GetModelInstanceName(model.instance) == "ur10e"
    assert model.plant.HasFrameNamed(robot.FLANGE_FRAME) and model.plant.HasFrameNamed(robot.BASE_FRAME)


def test_13_model_path_points_at_the_shipped_file():
    # Installed non-editable, the package carries its own copy of models/ur10e.urdf.
    assert robot.model_path().name == MODEL_FILE.name
    assert robot.model_path().read_bytes() == MODEL_FILE.read_bytes()


def test_14_model_path_reports_a_missing_file(monkeypatch, tmp_path):
    monkeypatch.setattr(robot_base, "data_directory", lambda name: tmp_path)
    with pytest.raises(ValueError, match="ur10e.urdf") as info:
        robot.model_path()
    assert str(tmp_path / "ur10e.urdf") in str(info.value)
