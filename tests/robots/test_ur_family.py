"""The UR e-Series family (docs/ur_family.md): each arm's URDF through Drake's MultibodyPlant
against its DH chain and its data table, its closed form against the plant, its limits, gains
and errors, and the URDF writer."""

import functools

import numpy as np
import pytest
from pydrake.math import RigidTransform
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.multibody.tree import JacobianWrtVariable, JointActuatorIndex
from pydrake.systems.framework import DiagramBuilder

from drake_traj import load_scenario, simulate
from drake_traj.cell import Cell, CellChecker, Tool
from drake_traj.errors import DrakeTrajError
from drake_traj.robots import ROBOT_NAMES, UR10E, UR_ARMS, get_robot
from drake_traj.robots.task_space import rotation_from_zyx_euler, wrap_angle
from drake_traj.robots.ur_data import UR10E_DATA
from drake_traj.robots.urdf_writer import Shape, dh_arm_urdf, dh_capsules, ur_urdf

ARMS = {arm.name: arm for arm in UR_ARMS}
LINKS = ("shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link", "wrist_3_link")
BODIES = {"base", *LINKS}
TOL = 1e-9


@functools.cache
def plant_of(name):
    """The arm's model file in a continuous MultibodyPlant with SceneGraph, and a context."""
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    instance = ARMS[name].add_to_plant(plant)
    plant.Finalize()
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    return plant, instance, plant.GetMyMutableContextFromRoot(context), diagram


def random_configurations(arm, count, seed):
    return np.random.default_rng(seed).uniform(arm.lower_limits, arm.upper_limits, (count, 6))


def test_the_family_is_registered_and_an_unknown_name_lists_the_known_ones():
    assert [arm.name for arm in UR_ARMS] == ["ur3e", "ur5e", "ur10e", "ur16e", "ur20", "ur30"]
    for arm in UR_ARMS:
        assert get_robot(arm.name) is arm and arm.name in ROBOT_NAMES
    assert get_robot("ur10e") is UR10E
    with pytest.raises(ValueError, match=r"robot must be one of the known robots, got 'ur7e'; known: .*ur3e .*ur5e .*ur16e .*ur20 .*ur30 "):
        get_robot("ur7e")


@pytest.mark.parametrize("name", ARMS)
def test_urdf_forward_kinematics_equals_the_dh_chain(name):
    arm = ARMS[name]
    plant, instance, context, _ = plant_of(name)
    base = plant.GetFrameByName("base", instance)
    frames = [plant.GetFrameByName(link, instance) for link in LINKS] + [plant.GetFrameByName("tool0", instance)]
    worst = 0.0
    for q in random_configurations(arm, 100, seed=len(name)):
        plant.SetPositions(context, instance, q)
        dh = arm.dh_frames(q)
        # tool0 is DH frame 6; link i's frame is DH frame i-1 turned by q_i, so its origin is DH frame i-1's
        worst = max(worst, np.max(np.abs(plant.CalcRelativeTransform(context, base, frames[-1]).GetAsMatrix4() - dh[6])))
        for i, frame in enumerate(frames[:-1]):
            origin = plant.CalcRelativeTransform(context, base, frame).translation()
            worst = max(worst, np.max(np.abs(origin - dh[i][:3, 3])))
    assert worst < TOL


@pytest.mark.parametrize("name", ARMS)
def test_closed_form_pose_jacobian_and_bias_equal_the_plant(name):
    arm = ARMS[name]
    plant, instance, context, _ = plant_of(name)
    world, tool0 = plant.world_frame(), plant.GetFrameByName("tool0", instance)
    rng = np.random.default_rng(7)
    for q in random_configurations(arm, 20, seed=3):
        qd = rng.uniform(-2.0, 2.0, 6)
        plant.SetPositions(context, instance, q)
        plant.SetVelocities(context, instance, qd)
        pose, jacobian, bias, cos_pitch, _ = arm.kinematics(q, qd)
        X = plant.CalcRelativeTransform(context, world, tool0)
        assert np.allclose(pose[:3], X.translation(), atol=TOL, rtol=0)
        assert np.allclose(rotation_from_zyx_euler(pose[3:]), X.rotation().matrix(), atol=TOL, rtol=0)
        spatial = plant.CalcJacobianSpatialVelocity(context, JacobianWrtVariable.kV, tool0, np.zeros(3), world, world)
        assert np.allclose(arm.geometric_jacobian(q), np.vstack([spatial[3:], spatial[:3]]), atol=TOL, rtol=0)
        assert np.allclose(jacobian[:3], spatial[3:], atol=TOL, rtol=0)
        acceleration = plant.CalcBiasTranslationalAcceleration(context, JacobianWrtVariable.kV, tool0, np.zeros(3),
                                                               world, world)
        assert np.allclose(bias[:3], acceleration.ravel(), atol=TOL, rtol=0)
        # the Euler rows: B(phi) J_phi = J_omega (Z-Y-X angles: omega = B(phi) phi_dot)
        phi_x, phi_y, phi_z = pose[3:]
        euler_rates = np.array([[np.cos(phi_y) * np.cos(phi_z), -np.sin(phi_z), 0.0],
                                [np.cos(phi_y) * np.sin(phi_z), np.cos(phi_z), 0.0],
                                [-np.sin(phi_y), 0.0, 1.0]])
        if cos_pitch > 1e-3:
            assert np.allclose(euler_rates @ jacobian[3:], spatial[:3], atol=TOL / cos_pitch, rtol=0)


@pytest.mark.parametrize("name", ARMS)
def test_inverse_kinematics_round_trips(name):
    arm = ARMS[name]
    for q in random_configurations(arm, 30, seed=11):
        solutions = arm.inverse_kinematics_all(arm.task_pose(q))
        for solution in solutions:
            assert np.max(np.abs(arm.flange_pose(solution) - arm.flange_pose(q))) < TOL
        assert min(np.max(np.abs(wrap_angle(solution - q))) for solution in solutions) < TOL
        assert np.max(np.abs(arm.inverse_kinematics(arm.task_pose(q), branch=arm.ik_branch(q), near=q) - q)) < TOL


@pytest.mark.parametrize("name", ARMS)
def test_point_ik_equals_inverse_kinematics_point_by_point(name):
    """point_ik (the branch's closed form compiled over the points) gives what
    inverse_kinematics gives for each point on the reference's branch and near it, with and
    without a TCP: the solutions to 1e-12 rad, and a path it cannot solve refused with the same
    error as the first point inverse_kinematics refuses (out of reach and singular points)."""
    rng = np.random.default_rng(sum(map(ord, name)))
    solved = refused = 0
    for trial in range(24):
        arm = ARMS[name].with_tcp(rng.uniform(-0.1, 0.2, 3), rng.uniform(-1, 1, 3)) if trial % 2 else ARMS[name]
        reference = rng.uniform(-3, 3, 6)
        orientation = arm.task_pose(reference, arm.tcp_offset)[3:]
        reach = np.abs(arm.data.a).sum()
        points = arm.tool_position(reference) + rng.normal(scale=0.01 if trial % 3 else 0.5 * reach, size=(100, 3))
        expected, reason = [], None
        for point in points:
            try:
                expected.append(arm.inverse_kinematics(np.concatenate([point, orientation]),
                                                       branch=arm.ik_branch(reference), near=reference,
                                                       tool=arm.tcp_offset))
            except ValueError as error:
                reason = str(error)
                break
        if reason is None:
            np.testing.assert_allclose(arm.point_ik(points, reference), expected, atol=1e-12, rtol=0)
            solved += 1
        else:
            with pytest.raises(ValueError) as raised:
                arm.point_ik(points, reference)
            assert str(raised.value) == reason
            refused += 1
    assert solved >= 5 and refused >= 4, (solved, refused)


def test_point_ik_along_a_path_continues_each_joint_past_half_a_turn_from_the_reference():
    """Points on an arc of 1.6 pi about the base axis, at the TCP orientation of the reference:
    joint 1 turns 1.6 pi with them. point_ik continues every joint from the point before (whole
    turns), so q is continuous (each step < 0.05 rad), every point is reached to 1e-9 m, and joint
    1 ends about 1.6 pi from where it began (the nearest-to-the-reference rule jumped by 2 pi)."""
    reference = np.array([0.3, -1.2, 1.4, -1.8, -1.5, 0.4])
    start = UR10E.tool_position(reference)
    radius, angle0 = np.hypot(*start[:2]), np.arctan2(start[1], start[0])
    angles = angle0 + np.linspace(0.0, 1.6 * np.pi, 801)
    points = np.column_stack([radius * np.cos(angles), radius * np.sin(angles), np.full_like(angles, start[2])])
    q = UR10E.point_ik(points, reference)
    assert np.max(np.abs(np.diff(q, axis=0))) < 0.05
    np.testing.assert_allclose(UR10E.tool_position(q), points, atol=1e-9, rtol=0)
    assert abs(q[-1, 0] - q[0, 0] - 1.6 * np.pi) < 0.01  # the wrist centre's arc is off the base axis by d6
    # from joint 1 at 5 rad, 3.2 pi on: past its limit (2 pi), it is turned back inside by whole turns
    reference[0] = 5.0
    start = UR10E.tool_position(reference)
    angles = np.arctan2(start[1], start[0]) + np.linspace(0.0, 3.2 * np.pi, 1601)
    points = np.column_stack([radius * np.cos(angles), radius * np.sin(angles), np.full_like(angles, start[2])])
    q = UR10E.point_ik(points, reference)
    np.testing.assert_allclose(UR10E.tool_position(q), points, atol=1e-9, rtol=0)
    assert np.all(np.abs(q) <= UR10E.upper_limits) and abs(q[0, 0] - 5.0) < 0.05
    assert sorted(np.round(np.diff(q[:, 0])[np.abs(np.diff(q[:, 0])) > 1] / (2 * np.pi))) == [-1.0, -1.0]


def test_joint_rates_are_batched_over_states():
    """joint_rates of (N, 6) states with one tool velocity (3,) and N accelerations: each row what
    one state gives, and the TCP moves with v and a (tool_motion); a wrong shape, or a state at
    the Euler angles' gimbal lock anywhere in the batch, is refused naming it."""
    rng = np.random.default_rng(5)
    q = rng.uniform(-2.5, 2.5, (20, 6))
    q = q[np.abs(np.sin(q[:, 2])) > 0.2][:10]
    v, a = rng.normal(size=3) * 0.2, rng.normal(size=(len(q), 3))
    qd, qdd = UR10E.joint_rates(q, v, a)
    for k in range(len(q)):
        one = UR10E.joint_rates(q[k], v, a[k])
        np.testing.assert_allclose(qd[k], one[0], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(qdd[k], one[1], rtol=1e-12, atol=1e-12)
    velocity, acceleration = UR10E.tool_motion(q, qd, qdd)
    np.testing.assert_allclose(velocity, np.broadcast_to(v, velocity.shape), atol=1e-9)
    np.testing.assert_allclose(acceleration, a, atol=1e-8)
    with pytest.raises(ValueError, match=r"v must have shape \(\.\.\., 3\)"):
        UR10E.joint_rates(q, np.zeros(2), a)
    locked = UR10E.inverse_kinematics_all([0.6, 0.2, 0.5, 0.0, np.pi / 2, 0.0])[0]
    with pytest.raises(DrakeTrajError, match="gimbal lock") as refused:
        UR10E.joint_rates(np.vstack([q[:2], locked]), v, a[:3])
    assert refused.value.cause == "singular"


@pytest.mark.parametrize("name", ARMS)
def test_urdf_masses_centres_of_mass_and_inertias_equal_the_table(name):
    arm = ARMS[name]
    plant, instance, context, _ = plant_of(name)
    q = random_configurations(arm, 1, seed=5)[0]
    plant.SetPositions(context, instance, q)
    dh = arm.dh_frames(q)
    for i, link in enumerate(LINKS):
        body = plant.GetBodyByName(link, instance)
        inertia = body.CalcSpatialInertiaInBodyFrame(context)
        X_WB = plant.EvalBodyPoseInWorld(context, body)
        assert inertia.get_mass() == arm.data.link_masses[i]
        com_world = X_WB @ inertia.get_com()
        assert np.allclose(com_world, dh[i + 1][:3, :3] @ arm.data.centers_of_mass[i] + dh[i + 1][:3, 3], atol=TOL)
        about_com = inertia.Shift(inertia.get_com()).CalcRotationalInertia().ReExpress(X_WB.rotation())
        ixx, ixy, ixz, iyy, iyz, izz = arm.data.inertias[i]
        table = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        R = dh[i + 1][:3, :3]
        assert np.allclose(about_com.CopyToFullMatrix3(), R @ table @ R.T, atol=1e-12, rtol=0)


@pytest.mark.parametrize("name", ARMS)
def test_limits_and_effort_limits_read_back_from_the_plant(name):
    arm = ARMS[name]
    plant, instance, _, _ = plant_of(name)
    assert np.array_equal(plant.GetPositionLowerLimits(), arm.lower_limits)
    assert np.array_equal(plant.GetPositionUpperLimits(), arm.upper_limits)
    assert np.array_equal(plant.GetVelocityUpperLimits(), arm.velocity_limits)
    efforts = [plant.get_joint_actuator(JointActuatorIndex(k)) for k in range(plant.num_actuators())]
    assert [actuator.name() for actuator in efforts] == [f"{joint}_actuator" for joint in arm.joint_names]
    assert np.array_equal([actuator.effort_limit() for actuator in efforts], arm.effort_limits)


def test_each_arm_has_its_own_published_numbers():
    # rated payloads [kg] and published reaches [m] (data sheets, docs/ur_family.md)
    assert {a.name: (a.rated_payload, a.data.reach) for a in UR_ARMS} == {
        "ur3e": (3.0, 0.5), "ur5e": (5.0, 0.85), "ur10e": (12.5, 1.3), "ur16e": (16.0, 0.9), "ur20": (20.0, 1.75),
        "ur30": (30.0, 1.3)}
    assert ARMS["ur5e"].effort_limits.tolist() == [150, 150, 150, 28, 28, 28]
    assert ARMS["ur3e"].velocity_limits[3:].tolist() == [2 * np.pi] * 3  # 360 deg/s wrists
    for arm in UR_ARMS:
        assert arm.data_source.startswith("Universal Robots'") and "the manual's UR" in arm.data_source
        speed, acceleration = arm.joint_move_limits
        assert np.array_equal(speed, np.minimum(1.05, arm.velocity_limits)) and np.all(acceleration == 1.40)
        assert np.array_equal(arm.task_kinematics().model, [0.0, arm.data.d[0], arm.data.a[1], arm.data.a[2],
                                                            *arm.data.d[3:]])


def test_the_ur30_is_ur_s_table_on_the_ur20_s_platform_and_its_tensors_are_marked_estimates():
    ur30, ur20 = ARMS["ur30"].data, ARMS["ur20"].data
    # UR's DH table (ROS 2 description, default_kinematics.yaml): the UR20's d, shorter a2 and a3
    assert (ur30.d, ur30.a) == ((0.2363, 0.0, 0.0, 0.201, 0.1593, 0.1543), (0.0, -0.637, -0.5037, 0.0, 0.0, 0.0))
    assert ur30.d == ur20.d and ur30.size == ur20.size and ur30.tube_offsets == ur20.tube_offsets
    assert ur30.link_masses == (16.343, 28.542, 7.156, 3.054, 3.126, 0.926)
    assert ARMS["ur30"].effort_limits.tolist() == [738, 738, 433, 107, 107, 107]
    assert np.allclose(np.degrees(ARMS["ur30"].velocity_limits), [120, 120, 150, 210, 210, 210], rtol=1e-12, atol=0)
    # links 1, 4, 5, 6: the UR20's tensors; links 2, 3: the UR20's scaled to the shorter tubes,
    # each a rigid body's (principal moments >= 0, each at most the sum of the other two)
    assert ur30.inertias[0] == ur20.inertias[0] and ur30.inertias[3:] == ur20.inertias[3:]
    assert ur30.inertias[1] == (0.1413, 0.00013524, -0.03675, 2.4543, 3.8529e-05, 2.4379)
    assert ur30.inertias[2] == (0.023723, -3.139e-05, -0.018194, 0.32878, -9.0824e-06, 0.32689)
    for ixx, ixy, ixz, iyy, iyz, izz in ur30.inertias:
        moments = np.linalg.eigvalsh([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        assert moments[0] > 0 and moments[2] <= moments[0] + moments[1]
    # not the ROS 2 description's placeholder (the UR16e's tensors)
    assert not set(ur30.inertias) & set(ARMS["ur16e"].data.inertias)
    # the reach figure an unreachable pose names: the wrist centre's farthest from the shoulder
    with pytest.raises(DrakeTrajError, match=rf"the UR30 reaches at most {np.hypot(0.637 + 0.5037 + 0.1593, 0.201):.6g} m"):
        ARMS["ur30"].inverse_kinematics([2.0, 0.0, 0.3, np.pi, 0.0, 0.0])


def test_the_ur20s_wrist_3_is_urs_2025_table():
    # UR's DH article, updated 2025: link 6 0.846 kg at [0, -0.0003, -0.0318] (was 0.926 kg, [0, 0, -0.0293])
    data = ARMS["ur20"].data
    assert data.link_masses[5] == 0.846 and data.centers_of_mass[5] == (0.0, -0.0003, -0.0318)


def test_the_payload_is_checked_against_each_arms_rating():
    tool = Cell(tool=Tool(mass=4.0, tcp_xyz=[0.0, 0.0, 0.1]))
    tool.validate(ARMS["ur5e"])
    assert CellChecker(ARMS["ur5e"], tool).plant.GetBodyByName("tool").default_mass() == 4.0
    with pytest.raises(DrakeTrajError, match=r"cell.tool.mass = 4 kg is above the ur3e robot's rated payload of 3 kg") as info:
        tool.validate(ARMS["ur3e"])
    assert info.value.field == ("cell", "tool", "mass")
    with pytest.raises(DrakeTrajError, match=r"above the ur3e robot's rated payload"):
        CellChecker(ARMS["ur3e"], tool)
    heavy = Cell(tool=Tool(mass=15.0, tcp_xyz=[0.0, 0.0, 0.1]))
    heavy.validate(ARMS["ur16e"])
    with pytest.raises(DrakeTrajError, match=r"above the ur10e robot's rated payload of 12.5 kg"):
        heavy.validate(UR10E)


def test_default_gains_scale_the_ur10es_by_the_torque_limits():
    assert UR10E.default_gains == ((4000.0, 4000.0, 2000.0, 500.0, 500.0, 300.0), (200.0, 200.0, 100.0, 20.0, 20.0, 10.0))
    assert all(isinstance(gain, float) for gains in UR10E.default_gains for gain in gains)
    kp, kd = ARMS["ur5e"].default_gains
    assert kp == (round(4000 * 150 / 330), round(4000 * 150 / 330), 2000, 250, 250, 150)
    assert kd == (90.9, 90.9, 100.0, 10.0, 10.0, 5.0)
    assert ARMS["ur16e"].default_gains[0][3:] == (round(500 * 54 / 56), round(500 * 54 / 56), round(300 * 54 / 56))


def test_an_unreachable_pose_is_named_with_that_arms_numbers():
    ur5e = ARMS["ur5e"]
    reach = np.hypot(0.425 + 0.3922 + 0.0997, 0.1333)  # the wrist centre's reach from the shoulder [m]
    with pytest.raises(DrakeTrajError, match=rf"out of reach: .*the UR5e reaches at most {reach:.6g} m"):
        ur5e.inverse_kinematics([1.0, 0.0, 0.3, np.pi, 0.0, 0.0])
    ur10e_q = UR10E.inverse_kinematics([1.0, 0.0, 0.3, np.pi, 0.0, 0.0])  # inside the UR10e's reach
    assert np.max(np.abs(UR10E.task_pose(ur10e_q)[:3] - [1.0, 0.0, 0.3])) < TOL


@pytest.mark.parametrize("name", ARMS)
def test_home_is_free_of_self_contact_and_no_checked_pair_touches_at_every_configuration(name):
    arm = ARMS[name]
    checker = CellChecker(arm)
    home = checker.contacts(arm.home_configuration, within=0.005)
    assert home == [], home
    apart, seen = set(), set()
    for q in random_configurations(arm, 120, seed=2):
        for contact in checker.contacts(q, within=np.inf):
            if not set(contact.bodies) <= BODIES:  # the cell's table
                continue
            seen.add(contact.bodies)
            if contact.distance > 0.0:
                apart.add(contact.bodies)
    assert len(seen) == 14  # the non-adjacent pairs of the 7 bodies but wrist 1 - wrist 3 (filtered)
    assert apart == seen


@pytest.mark.parametrize("name", [arm.name for arm in UR_ARMS if arm is not UR10E])
def test_shipped_urdf_is_the_writers_output(name):
    # models/<arm>.urdf is regenerated by `python -m drake_traj.robots.urdf_writer`
    assert ARMS[name].model_path().read_text() == ur_urdf(ARMS[name].data)


def test_the_writer_takes_any_dh_arm_and_refuses_malformed_tables():
    data = UR10E_DATA
    arguments = dict(masses=data.link_masses, centers_of_mass=data.centers_of_mass, inertias=data.inertias,
                     lower=[-3.0] * 6, upper=[3.0] * 6, velocity=[1.0] * 6, effort=[10.0] * 6,
                     shapes=dh_capsules(data.d, data.a, [0.05] * 6, theta=[0.0, 0.3, 0, 0, 0, 0.1]),
                     theta=[0.0, 0.3, 0, 0, 0, 0.1])
    text = dh_arm_urdf("offset_arm", data.d, data.a, [np.pi / 2, 0, 0, np.pi / 2, -np.pi / 2, 0], **arguments)
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    (instance,) = Parser(plant).AddModelsFromString(text, "urdf")
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("base", instance), RigidTransform())
    plant.Finalize()
    context = plant.CreateDefaultContext()
    q = np.array([0.3, -1.0, 0.7, 0.2, -0.4, 1.1])
    plant.SetPositions(context, q)
    # the DH chain with theta offsets: T = prod Rz(q_i + theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)
    expected = UR10E.flange_pose(q + np.array([0.0, 0.3, 0, 0, 0, 0.1]))
    X = plant.CalcRelativeTransform(context, plant.world_frame(), plant.GetFrameByName("tool0")).GetAsMatrix4()
    assert np.max(np.abs(X - expected)) < TOL
    with pytest.raises(ValueError, match=r"d must be 6 finite numbers"):
        dh_arm_urdf("bad", data.d[:5], data.a, [0.0] * 6, **arguments)
    with pytest.raises(ValueError, match=r"effort must be 6 finite numbers"):
        dh_arm_urdf("bad", data.d, data.a, [0.0] * 6, **{**arguments, "effort": [np.nan] * 6})
    with pytest.raises(ValueError, match=r"shapes must have 7 lists"):
        dh_arm_urdf("bad", data.d, data.a, [0.0] * 6, **{**arguments, "shapes": [[Shape("s", "sphere", 0.1)]]})


UR5E_PAJAK = """name: ur5e_pajak
robot: ur5e
planner: !PajakConfig
  waypoints:
    - [-0.134, -0.45, 0.45, 3.141592653589793, 0.0, 2.356194490192345]
    - [{x}, -0.55, 0.45, 3.141592653589793, 0.0, 2.356194490192345]
  velocity_limit: 1.05
  acceleration_limit: 1.40
plant:
  time_step: 0.001
settle_time: 0.3
"""


def test_the_pajak_law_runs_the_ur5e_with_its_own_kinematics_and_limits(tmp_path):
    ur5e = ARMS["ur5e"]
    path = tmp_path / "ur5e_pajak.yaml"
    path.write_text(UR5E_PAJAK.format(x=0.1))
    result = simulate(load_scenario(path))
    assert result.succeeded and result.robot == "ur5e"
    assert np.array_equal(result.effort_limit, ur5e.effort_limits)
    assert np.linalg.norm(ur5e.tcp_pose(result.q_meas[-1])[:3] - [0.1, -0.55, 0.45]) < 1e-3  # accuracy 1 mm
    assert np.max(np.abs(result.qd_ref)) <= 1.05 + 1e-9 and np.max(np.abs(result.qdd_ref)) <= 1.40 + 1e-9
    assert np.all(np.abs(result.tau) <= ur5e.effort_limits + 1e-9)
    path.write_text(UR5E_PAJAK.format(x=0.9))  # inside the UR10e's reach, beyond the UR5e's
    with pytest.raises(ValueError, match=r"waypoint 1 cannot be reached: .*the UR5e reaches at most 0.926539 m"):
        simulate(load_scenario(path))
