"""drake_traj.robots.ur10e: k(q), Z-Y-X Euler angles, the analytic Jacobian and dJ/dt qd.

Checked against Drake's MultibodyPlant (geometric Jacobian, bias acceleration, RollPitchYaw)
and against finite differences of k(q).
"""

import numpy as np
import pytest
from pydrake.math import RollPitchYaw
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable

from drake_traj.robots import task_space
from drake_traj.robots import ur10e as robot
from drake_traj.robots import UR10E

Q0 = np.array([-np.pi / 2, -np.pi / 2, -3 * np.pi / 4, -np.pi / 4, np.pi / 2, np.pi / 4])


@pytest.fixture(scope="module")
def plant_and_context():
    plant = MultibodyPlant(0.0)
    UR10E.add_to_plant(plant)
    plant.Finalize()
    return plant, plant.CreateDefaultContext()


def random_configurations(count, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-np.pi, np.pi, (count, 6)), rng.uniform(-1.5, 1.5, (count, 6))


def test_k_of_seed_000_start_is_p0():
    # Pająk 2024 prints p0 = [-0.174, -0.524, 0.273, pi, 0, 3pi/4]; docs/ur10e.md gives the flange
    # at (-0.17415, -0.52400, 0.27270), itself rounded to 5 decimals (exact: y = -0.5239969,
    # z = 0.2727031). phi_X comes out as +-pi (docs/papers.md): compare it wrapped.
    pose = robot.task_pose(Q0)
    np.testing.assert_allclose(pose[:3], [-0.17415, -0.52400, 0.27270], atol=5e-6)
    np.testing.assert_allclose(pose[:3], [-0.174, -0.524, 0.273], atol=5e-4)
    np.testing.assert_allclose(task_space.task_pose_error(pose, [0, 0, 0, np.pi, 0, 3 * np.pi / 4])[3:], 0, atol=1e-12)


def test_euler_angles_match_drake_roll_pitch_yaw():
    rng = np.random.default_rng(1)
    for _ in range(200):
        rotation = robot.flange_pose(rng.uniform(-np.pi, np.pi, 6))[:3, :3]
        # Drake's RollPitchYaw (r, p, y) is R = Rz(y) Ry(p) Rx(r): the same Z-Y-X convention.
        np.testing.assert_allclose(robot.zyx_euler_from_rotation(rotation), RollPitchYaw(rotation).vector(), atol=1e-12)
        np.testing.assert_allclose(
            robot.rotation_from_zyx_euler(robot.zyx_euler_from_rotation(rotation)), rotation, atol=1e-12
        )


@pytest.mark.parametrize(
    "angle, wrapped", [(np.pi, np.pi), (-np.pi, np.pi), (3 * np.pi, np.pi), (0.0, 0.0), (-0.5, -0.5), (2 * np.pi - 0.1, -0.1)]
)
def test_wrap_angle(angle, wrapped):
    assert robot.wrap_angle(angle) == pytest.approx(wrapped, abs=1e-12)


def test_geometric_jacobian_and_bias_match_multibody_plant(plant_and_context):
    plant, context = plant_and_context
    tool0 = plant.GetFrameByName(robot.FLANGE_FRAME)
    world = plant.world_frame()
    for q, qd in zip(*random_configurations(100)):
        plant.SetPositions(context, q)
        plant.SetVelocities(context, qd)
        spatial = plant.CalcJacobianSpatialVelocity(context, JacobianWrtVariable.kV, tool0, np.zeros(3), world, world)
        # Drake orders spatial vectors [omega; v]; ours is [v; omega].
        np.testing.assert_allclose(robot.geometric_jacobian(q), np.vstack([spatial[3:], spatial[:3]]), atol=1e-10)
        bias = plant.CalcBiasSpatialAcceleration(context, JacobianWrtVariable.kV, tool0, np.zeros(3), world, world)
        jacobian, jdot_qd = robot.analytic_jacobian_and_bias(q, qd)
        # Translational part of dJ/dt qd is the bias acceleration of the flange origin itself.
        np.testing.assert_allclose(jdot_qd[:3], bias.translational(), atol=1e-10)


def test_analytic_jacobian_and_bias_match_finite_differences():
    step = 1e-6
    for q, qd in zip(*random_configurations(100, seed=2)):
        jacobian, jdot_qd = robot.analytic_jacobian_and_bias(q, qd)
        numeric = np.column_stack(
            [task_space.task_pose_error(robot.task_pose(q + step * e), robot.task_pose(q - step * e)) / (2 * step) for e in np.eye(6)]
        )
        np.testing.assert_allclose(jacobian, numeric, atol=2e-8)
        # Along q(t) = q + t qd (so qdd = 0), d^2 k/dt^2 = dJ/dt qd.
        h = 1e-4
        centre = robot.task_pose(q)
        second = (task_space.task_pose_error(robot.task_pose(q + h * qd), centre)
                  + task_space.task_pose_error(robot.task_pose(q - h * qd), centre)) / h**2
        np.testing.assert_allclose(jdot_qd, second, atol=2e-5 * max(1.0, np.abs(jdot_qd).max()))


def test_angular_bias_matches_multibody_plant_through_euler_rates(plant_and_context):
    # Independent of our chain recursion: omega = B(phi) phi_dot, so
    # d/dt omega (qdd = 0) = B (dJ/dt qd)[3:] + dB/dt phi_dot, with Drake supplying d/dt omega.
    plant, context = plant_and_context
    tool0 = plant.GetFrameByName(robot.FLANGE_FRAME)
    world = plant.world_frame()
    h = 1e-6
    for q, qd in zip(*random_configurations(50, seed=3)):
        plant.SetPositions(context, q)
        plant.SetVelocities(context, qd)
        alpha = plant.CalcBiasSpatialAcceleration(context, JacobianWrtVariable.kV, tool0, np.zeros(3), world, world).rotational()
        jacobian, jdot_qd = robot.analytic_jacobian_and_bias(q, qd)
        phi = robot.task_pose(q)[3:]
        phi_dot = jacobian[3:] @ qd
        b_dot = (task_space.euler_rate_matrix(phi + h * phi_dot) - task_space.euler_rate_matrix(phi - h * phi_dot)) / (2 * h)
        np.testing.assert_allclose(task_space.euler_rate_matrix(phi) @ jdot_qd[3:] + b_dot @ phi_dot, alpha, atol=1e-7)


def test_gimbal_lock_raises_a_clear_error():
    stretched_up = np.array([0.0, -np.pi / 2, 0.0, 0.0, 0.0, 0.0])  # phi_Y = pi/2 exactly
    with pytest.raises(robot.SingularConfigurationError, match="phi_Y"):
        robot.analytic_jacobian(stretched_up)
    assert issubclass(robot.SingularConfigurationError, ValueError)


@pytest.mark.parametrize("bad", [np.zeros(5), np.zeros((6, 1)), np.array([0, 0, np.nan, 0, 0, 0])])
def test_bad_joint_vectors_are_rejected(bad):
    with pytest.raises(ValueError, match="q must"):
        robot.task_pose(bad)
