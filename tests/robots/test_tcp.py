"""Robot.with_tcp: the tool centre point at an offset from the flange.

The UR10e's TCP kinematics (pose, analytic Jacobian, J̇q̇, tool motion, IK, joint rates) are
checked against Drake's MultibodyPlant with a frame welded at the offset on ``tool0``, at random
configurations and random offsets; the identity offset against today's flange numbers, bit for
bit; the point robots' refusal and the input checks by their fields.
"""

import numpy as np
import pytest
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import FixedOffsetFrame, JacobianWrtVariable

from drake_traj.errors import DrakeTrajError
from drake_traj.robots import LI_4DOF, UR10E
from drake_traj.robots import task_space
from drake_traj.robots import ur10e as robot
from drake_traj.robots.boryga_robots import AnthropomorphicArm, ScaraArm

OFFSETS = 6  # random TCP offsets, each checked at CONFIGURATIONS random states
CONFIGURATIONS = 25


def random_offsets(seed=0):
    """(xyz [m], rpy [rad]) pairs: up to 0.3 m from the flange, any orientation."""
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-0.3, 0.3, 3), rng.uniform(-np.pi, np.pi, 3) * np.array([1.0, 0.45, 1.0]))
            for _ in range(OFFSETS)]


@pytest.fixture(scope="module")
def plant_with_tcps():
    """A plant with the UR10e and one frame per random offset welded to ``tool0``."""
    plant = MultibodyPlant(0.0)
    UR10E.add_to_plant(plant)
    tool0 = plant.GetFrameByName(robot.FLANGE_FRAME)
    frames = []
    for k, (xyz, rpy) in enumerate(random_offsets()):
        frames.append(plant.AddFrame(FixedOffsetFrame(f"tcp_{k}", tool0, RigidTransform(RollPitchYaw(rpy), xyz))))
    plant.Finalize()
    return plant, plant.CreateDefaultContext(), frames


def states(seed):
    rng = np.random.default_rng(seed)
    return zip(rng.uniform(-np.pi, np.pi, (CONFIGURATIONS, 6)), rng.uniform(-1.5, 1.5, (CONFIGURATIONS, 6)),
               rng.uniform(-3.0, 3.0, (CONFIGURATIONS, 6)))


def test_tcp_kinematics_match_multibody_plant(plant_with_tcps):
    plant, context, frames = plant_with_tcps
    world = plant.world_frame()
    worst = dict(pose=0.0, jacobian=0.0, bias=0.0, motion=0.0)
    for k, (xyz, rpy) in enumerate(random_offsets()):
        tcp_robot = UR10E.with_tcp(xyz, rpy)
        for q, qd, qdd in states(k):
            plant.SetPositions(context, q)
            plant.SetVelocities(context, qd)
            transform = plant.CalcRelativeTransform(context, world, frames[k])
            pose, jacobian, bias, cos_pitch, _ = robot.ur10e_kinematics(q, qd, tcp_robot.tcp_offset)
            if cos_pitch < 1e-3:
                continue  # gimbal lock of the Euler angles: RollPitchYaw is ill-conditioned there
            np.testing.assert_allclose(pose[:3], transform.translation(), rtol=0, atol=1e-12)
            np.testing.assert_allclose(robot.rotation_from_zyx_euler(pose[3:]), transform.rotation().matrix(),
                                       rtol=0, atol=1e-12)
            np.testing.assert_allclose(tcp_robot.tcp_pose(q), pose, rtol=0, atol=1e-12)  # one q: the numpy path
            spatial = plant.CalcJacobianSpatialVelocity(context, JacobianWrtVariable.kV, frames[k], np.zeros(3),
                                                        world, world)
            translational = plant.CalcJacobianTranslationalVelocity(context, JacobianWrtVariable.kV, frames[k],
                                                                     np.zeros(3), world, world)
            # Euler rows: ω = B(φ_T) φ̇, B of the TCP's angles
            rate_matrix = task_space.euler_rate_matrix(pose[3:])
            drake_bias = plant.CalcBiasTranslationalAcceleration(context, JacobianWrtVariable.kV, frames[k],
                                                                 np.zeros(3), world, world)
            worst["pose"] = max(worst["pose"], np.max(np.abs(pose[:3] - transform.translation())))
            worst["jacobian"] = max(worst["jacobian"], np.max(np.abs(jacobian[:3] - translational)),
                                    np.max(np.abs(rate_matrix @ jacobian[3:] - spatial[:3])))
            worst["bias"] = max(worst["bias"], np.max(np.abs(bias[:3] - drake_bias.ravel())))
            velocity, acceleration = tcp_robot.tool_motion(q[None], qd[None], qdd[None])
            worst["motion"] = max(worst["motion"], np.max(np.abs(velocity[0] - translational @ qd)),
                                  np.max(np.abs(acceleration[0] - translational @ qdd - drake_bias.ravel())))
    print(f"largest differences from MultibodyPlant: {worst}")
    assert max(worst.values()) < 1e-9


def test_euler_bias_of_the_tcp_matches_finite_differences():
    # the Euler rows of J̇q̇: d²φ/dt² along q(t) = q + t q̇ (q̈ = 0), central differences
    h = 1e-4
    for k, (xyz, rpy) in enumerate(random_offsets(seed=3)):
        tcp = UR10E.with_tcp(xyz, rpy).tcp_offset
        for q, qd, _ in states(10 + k):
            pose, jacobian, bias, cos_pitch, _ = robot.ur10e_kinematics(q, qd, tcp)
            if cos_pitch < 0.1:
                continue
            ahead, behind = robot.task_pose(q + h * qd, tcp), robot.task_pose(q - h * qd, tcp)
            second = (task_space.task_pose_error(ahead, pose) + task_space.task_pose_error(behind, pose)) / h**2
            first = task_space.task_pose_error(ahead, behind) / (2 * h)
            np.testing.assert_allclose(jacobian @ qd, first, rtol=0, atol=1e-5)
            np.testing.assert_allclose(bias, second, rtol=0, atol=2e-4)


def test_identity_offset_is_the_flange_bit_for_bit():
    same = UR10E.with_tcp([0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    assert same is not UR10E and UR10E.tcp_offset is robot.FLANGE
    rng = np.random.default_rng(7)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (3, 40, 6))
    for name in ("tcp_pose", "tool_position"):
        assert np.array_equal(getattr(same, name)(q), getattr(UR10E, name)(q))
        assert np.array_equal(getattr(same, name)(q[0]), getattr(UR10E, name)(q[0]))
    for ours, theirs in zip(same.tool_motion(q, qd, qdd), UR10E.tool_motion(q, qd, qdd)):
        assert np.array_equal(ours, theirs)
    assert same.task_kinematics() is UR10E.task_kinematics()
    for ours, theirs in zip(same.joint_rates(q[0], [0.1, -0.2, 0.05], [0.3, 0.0, -0.1]),
                            UR10E.joint_rates(q[0], [0.1, -0.2, 0.05], [0.3, 0.0, -0.1])):
        assert np.array_equal(ours, theirs)


def test_tcp_offset_is_the_flange_pose_times_the_offset():
    xyz, rpy = [0.02, -0.01, 0.15], [0.3, -0.2, 1.1]
    tcp_robot = UR10E.with_tcp(xyz, rpy)
    offset = RigidTransform(RollPitchYaw(rpy), xyz).GetAsMatrix4()
    np.testing.assert_array_equal(tcp_robot.tcp_offset, offset)
    assert not tcp_robot.tcp_offset.flags.writeable and UR10E.tcp_offset is robot.FLANGE  # the original unchanged
    q = np.array([0.3, -1.2, 1.4, -0.9, 1.1, 0.4])
    expected = robot.flange_pose(q) @ offset
    np.testing.assert_allclose(tcp_robot.tool_position(q), expected[:3, 3], rtol=0, atol=1e-14)
    # a straight tool along the flange z axis: the TCP 0.15 m along z6
    straight = UR10E.with_tcp([0.0, 0.0, 0.15], [0.0, 0.0, 0.0])
    np.testing.assert_allclose(straight.tool_position(q) - UR10E.tool_position(q),
                               0.15 * robot.flange_pose(q)[:3, 2], rtol=0, atol=1e-14)
    # with_tcp on a robot with a TCP sets the TCP from the flange again (does not compose)
    np.testing.assert_array_equal(tcp_robot.with_tcp([0.0, 0.0, 0.15], [0.0, 0.0, 0.0]).tcp_offset,
                                  straight.tcp_offset)


def test_inverse_kinematics_of_tcp_poses():
    for k, (xyz, rpy) in enumerate(random_offsets(seed=5)):
        tcp_robot = UR10E.with_tcp(xyz, rpy)
        kinematics = tcp_robot.task_kinematics()
        assert kinematics.kinematics_into is UR10E.task_kinematics().kinematics_into  # the one compiled law
        np.testing.assert_array_equal(kinematics.tool, tcp_robot.tcp_offset)
        rng = np.random.default_rng(20 + k)
        for q in rng.uniform(-np.pi, np.pi, (10, 6)):
            if robot.singularity_measure(q) < 0.1:  # the points around it stay in reach
                continue
            pose = tcp_robot.tcp_pose(q)
            solutions = kinematics.inverse_kinematics_all(pose)
            gap = np.abs(robot.wrap_angle(solutions - q)).max(axis=1)
            assert gap.min() < 1e-7
            for solution in solutions:  # every solution puts the TCP (not the flange) at the pose
                position, orientation = robot.pose_error(tcp_robot.tcp_pose(solution), pose)
                assert position < 1e-9 and orientation < 1e-9
            points = tcp_robot.tool_position(q) + rng.uniform(-0.01, 0.01, (3, 3))
            moved = tcp_robot.point_ik(points, q)
            np.testing.assert_allclose(tcp_robot.tool_position(moved), points, rtol=0, atol=1e-9)
            np.testing.assert_allclose(tcp_robot.tcp_pose(moved)[:, 3:] - pose[3:], 0.0, atol=1e-9)


def test_joint_rates_move_the_tcp():
    tcp_robot = UR10E.with_tcp([0.05, 0.0, 0.2], [0.0, 0.4, 0.0])
    q = np.array([0.3, -1.2, 1.4, -0.9, 1.1, 0.4])
    v, a = np.array([0.1, -0.2, 0.05]), np.array([0.3, 0.0, -0.1])
    qd, qdd = tcp_robot.joint_rates(q, v, a)
    velocity, acceleration = tcp_robot.tool_motion(q[None], qd[None], qdd[None])
    np.testing.assert_allclose(velocity[0], v, rtol=0, atol=1e-12)
    np.testing.assert_allclose(acceleration[0], a, rtol=0, atol=1e-12)
    _, jacobian, bias, _, _ = robot.ur10e_kinematics(q, qd, tcp_robot.tcp_offset)
    np.testing.assert_allclose(jacobian[3:] @ qd, 0.0, atol=1e-12)  # the TCP's orientation held
    np.testing.assert_allclose(jacobian[3:] @ qdd + bias[3:], 0.0, atol=1e-12)


@pytest.mark.parametrize("xyz, rpy, field", [
    ([0.0, 0.0], [0.0, 0.0, 0.0], ("xyz",)),
    ([0.0, np.nan, 0.1], [0.0, 0.0, 0.0], ("xyz",)),
    ([0.0, 0.0, 0.1], [0.0, np.inf, 0.0], ("rpy",)),
    ([0.0, 0.0, 0.1], "up", ("rpy",)),
    ([0.0, 0.0, 0.1], [[0.0, 0.0, 0.0]], ("rpy",)),
])
def test_invalid_offset_names_the_field(xyz, rpy, field):
    with pytest.raises(DrakeTrajError) as error:
        UR10E.with_tcp(xyz, rpy)
    assert error.value.field[:1] == field
    assert field[0] in str(error.value)


@pytest.mark.parametrize("point_robot", [LI_4DOF, AnthropomorphicArm(), ScaraArm()])
def test_point_robots_refuse_a_tool_offset(point_robot):
    assert point_robot.with_tcp([0.0, 0.0, 0.0], [0.0, 0.0, 0.0]) is point_robot
    with pytest.raises(DrakeTrajError, match=f"the {point_robot.name} robot places a point") as error:
        point_robot.with_tcp([0.0, 0.0, 0.15], [0.0, 0.0, 0.0])
    assert error.value.field == ("xyz",)
    with pytest.raises(DrakeTrajError) as error:
        point_robot.with_tcp([0.0, 0.0, 0.0], [0.0, 0.1, 0.0])
    assert error.value.field == ("rpy",)
