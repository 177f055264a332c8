"""Tests for the 4-DOF collaborative robot of Li et al. 2019 (Li, Zhang, Zhou): DH kinematics
against Drake's MultibodyPlant (models/li_4dof.urdf), inverse kinematics, joint rates, reach
checks, limits and the closed test path.

OCR corrections (docs/papers.md): Table 3 printed "057" for 0.5 pi; Table 5 printed "0.757" for
0.75 pi, "0.257" / "1.257" for 0.25 pi / 1.25 pi, "25" for 2.5 rad/s and "15" for 1.5 rad/s^2.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from drake_traj.planners.li import config as li_config
from drake_traj.planners.li.path import li_closed_path
from drake_traj.robots import LI_4DOF

PI = math.pi


@pytest.fixture(scope="module")
def plant():
    plant = MultibodyPlant(0.0)
    (instance,) = Parser(plant).AddModels(str(LI_4DOF.model_path()))
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("base", instance))
    plant.Finalize()
    return plant


def random_q(rng, n):
    lo, hi = LI_4DOF.lower_limits, LI_4DOF.upper_limits
    return rng.uniform(lo, hi, size=(n, 4))


def random_task_q(rng, n, pitch=0.0):
    """Joint vectors on the IK's branch: q2 + q3 + q4 = pitch, elbow up, forward, in limits."""
    q = np.empty((0, 4))
    while len(q) < n:
        cand = random_q(rng, 4 * n)
        cand[:, 2] = rng.uniform(-PI / 4, PI / 2, size=len(cand))  # elbow up: q3 in [-pi/2, pi/2]
        cand[:, 3] = pitch - cand[:, 1] - cand[:, 2]
        _, _, u, _ = LI_4DOF._planar(cand)
        keep = LI_4DOF.within_limits(cand) & (u > 1e-3)  # the IK's branch reaches forward (u > 0)
        q = np.vstack([q, cand[keep]])
    return q[:n]


# ---- tables ---------------------------------------------------------------------------------------


def test_dh_table_and_limits_are_the_papers():
    # Table 3 (mm in the paper); "057" printed for 0.5 pi.
    assert LI_4DOF.d == (0.255, 0.0, 0.0, 0.0)
    assert LI_4DOF.a == (0.0, 0.257, 0.250, 0.140)
    assert LI_4DOF.alpha == (PI / 2, 0.0, 0.0, 0.0)
    assert LI_4DOF.theta_offset == (0.0, PI / 2, -PI / 2, -PI / 2)
    # Table 5 (printed "0.757", "0.257", "1.257", "25", "15").
    np.testing.assert_allclose(LI_4DOF.lower_limits, [-0.75 * PI, -0.75 * PI, -0.25 * PI, -0.25 * PI])
    np.testing.assert_allclose(LI_4DOF.upper_limits, [0.75 * PI, 0.75 * PI, 1.25 * PI, 1.25 * PI])
    np.testing.assert_array_equal(LI_4DOF.velocity_limits, [2.0, 2.5, 3.0, 3.0])
    np.testing.assert_array_equal(LI_4DOF.acceleration_limits, [1.0, 1.2, 1.5, 1.8])
    # Table 4.
    assert li_config.CARTESIAN_VELOCITY_LIMIT == 0.2
    assert li_config.CARTESIAN_ACCELERATION_LIMIT == 0.1


def test_initial_pose():
    # q = 0: upper arm vertical, forearm horizontal, last link pointing down.
    np.testing.assert_allclose(LI_4DOF.fk(np.zeros(4)), [0.25, 0.0, 0.372], atol=1e-15)


# ---- URDF / plant ---------------------------------------------------------------------------------


def test_urdf_has_no_package_uri():
    text = LI_4DOF.model_path().read_text()
    assert "package://" not in text
    assert not re.search(r"<mesh", text)


def test_plant_tool0_equals_dh_fk(plant):
    rng = np.random.default_rng(2)
    context = plant.CreateDefaultContext()
    tool = plant.GetFrameByName("tool0")
    qs = random_q(rng, 200)
    poses = LI_4DOF.fk_pose(qs)
    positions = LI_4DOF.fk(qs)
    for q, pose, position in zip(qs, poses, positions):
        plant.SetPositions(context, q)
        X = plant.CalcRelativeTransform(context, plant.world_frame(), tool)
        np.testing.assert_allclose(X.GetAsMatrix4(), pose, atol=1e-9)
        np.testing.assert_allclose(X.translation(), position, atol=1e-9)


def test_plant_limits_equal_module(plant):
    assert plant.num_positions() == 4
    for k, name in enumerate(LI_4DOF.joint_names):
        joint = plant.GetJointByName(name)
        assert joint.position_start() == k
        assert plant.GetJointActuatorByName(f"{name}_actuator").effort_limit() == LI_4DOF.effort_limit[k]
    np.testing.assert_array_equal(plant.GetPositionLowerLimits(), LI_4DOF.lower_limits)
    np.testing.assert_array_equal(plant.GetPositionUpperLimits(), LI_4DOF.upper_limits)
    np.testing.assert_array_equal(plant.GetVelocityUpperLimits(), LI_4DOF.velocity_limits)
    np.testing.assert_array_equal(plant.GetVelocityLowerLimits(), -LI_4DOF.velocity_limits)
    np.testing.assert_array_equal(plant.GetAccelerationUpperLimits(), LI_4DOF.acceleration_limits)
    np.testing.assert_array_equal(plant.GetAccelerationLowerLimits(), -LI_4DOF.acceleration_limits)


def test_robot_contract(plant):
    model = LI_4DOF
    assert model.name == "li_4dof"
    assert model.num_joints == 4
    np.testing.assert_array_equal(model.effort_limits, [40.0, 60.0, 30.0, 10.0])
    q = np.array([0.1, -0.9, 0.3, 0.6])
    np.testing.assert_allclose(model.tcp_pose(q), np.r_[LI_4DOF.fk(q), 0.0, 0.0, 0.0])
    other = MultibodyPlant(1e-3)
    model.add_to_plant(other)
    other.Finalize()
    assert other.num_actuators() == 4
    assert other.num_positions() == 4


# ---- kinematics -----------------------------------------------------------------------------------


def test_jacobian_and_bias_match_finite_differences():
    rng = np.random.default_rng(3)
    h = 1e-6
    for q in random_q(rng, 20):
        jac = LI_4DOF.jacobian(q)
        fd = np.stack([(LI_4DOF.fk(q + h * e) - LI_4DOF.fk(q - h * e)) / (2 * h) for e in np.eye(4)], -1)
        np.testing.assert_allclose(jac, fd, atol=1e-8)
        qd = rng.normal(size=4)
        jdot = (LI_4DOF.jacobian(q + h * qd) - LI_4DOF.jacobian(q - h * qd)) / (2 * h)
        np.testing.assert_allclose(LI_4DOF.bias(q, qd), jdot @ qd, atol=1e-7)


def test_singularity_measure_vanishes_with_the_task_jacobian():
    rng = np.random.default_rng(4)
    qs = random_q(rng, 50)
    _, _, u, _ = LI_4DOF._planar(qs)
    l2, l3, _ = LI_4DOF.lengths
    det = np.linalg.det(LI_4DOF.task_jacobian(qs))
    np.testing.assert_allclose(np.abs(det), np.abs(u * l2 * l3 * np.cos(qs[:, 2])), atol=1e-12)


def test_ik_round_trip_random_points():
    rng = np.random.default_rng(5)
    q_true = random_task_q(rng, 500)
    points = LI_4DOF.fk(q_true)
    assert LI_4DOF.is_reachable(points).all()
    q = LI_4DOF.ik(points)
    np.testing.assert_allclose(LI_4DOF.fk(q), points, atol=1e-9)
    np.testing.assert_allclose(q, q_true, atol=1e-7)  # the same (elbow-up, pitch 0) branch
    np.testing.assert_allclose(LI_4DOF.pitch(q), 0.0, atol=1e-12)
    assert LI_4DOF.within_limits(q).all()


def test_ik_round_trip_random_points_in_the_plane_z0():
    rng = np.random.default_rng(6)
    r = rng.uniform(0.16, 0.49, 400)
    angle = rng.uniform(-0.7 * PI, 0.7 * PI, 400)
    points = np.stack([r * np.cos(angle), r * np.sin(angle), np.zeros(400)], -1)
    q = LI_4DOF.ik(points)
    np.testing.assert_allclose(LI_4DOF.fk(q), points, atol=1e-9)


def test_ik_with_another_pitch():
    from dataclasses import replace

    arm = replace(LI_4DOF, tool_pitch=0.3)
    rng = np.random.default_rng(7)
    points = LI_4DOF.fk(random_task_q(rng, 200, pitch=0.3))
    q = arm.ik(points)
    np.testing.assert_allclose(arm.fk(q), points, atol=1e-9)
    np.testing.assert_allclose(arm.pitch(q), 0.3, atol=1e-12)


def test_ik_round_trip_closed_path():
    path = li_closed_path()
    q = LI_4DOF.ik(path)
    np.testing.assert_allclose(LI_4DOF.fk(q), path, atol=1e-9)
    # Margins claimed in li_closed_path's docstring.
    assert q[:, 2].min() - LI_4DOF.lower[2] >= 0.15
    assert np.abs(q[:, 0]).max() <= 0.36
    assert LI_4DOF.singularity_measure(q).min() > 0.3


def test_joint_rates_match_finite_differences():
    # A smooth tool motion in the plane Z = 0 (circle of radius 0.05 m around (0.3, 0, 0)).
    def p(t):
        return np.stack([0.3 + 0.05 * np.cos(t), 0.05 * np.sin(2 * t), np.zeros_like(t)], -1)

    def v(t):
        return np.stack([-0.05 * np.sin(t), 0.1 * np.cos(2 * t), np.zeros_like(t)], -1)

    def a(t):
        return np.stack([-0.05 * np.cos(t), -0.2 * np.sin(2 * t), np.zeros_like(t)], -1)

    t = np.linspace(0.0, 6.0, 40)
    h = 1e-4
    q = LI_4DOF.ik(p(t))
    qd, qdd = LI_4DOF.joint_rates(q, v(t), a(t))
    q_plus, q_minus = LI_4DOF.ik(p(t + h)), LI_4DOF.ik(p(t - h))
    np.testing.assert_allclose(qd, (q_plus - q_minus) / (2 * h), atol=1e-7)
    np.testing.assert_allclose(qdd, (q_plus - 2 * q + q_minus) / h**2, atol=2e-5)
    np.testing.assert_allclose(qd[:, 1] + qd[:, 2] + qd[:, 3], 0.0, atol=1e-12)
    # Joint rates map back to the tool velocity and acceleration.
    np.testing.assert_allclose(np.einsum("nij,nj->ni", LI_4DOF.jacobian(q), qd), v(t), atol=1e-12)


def test_joint_rates_reject_singular_points():
    q = np.array([[0.1, -0.5, 0.2, 0.3], [0.0, -0.3, PI / 2, 0.0]])  # second: arm stretched
    with pytest.raises(ValueError, match=r"point 1 .*singular"):
        LI_4DOF.joint_rates(q, np.zeros(3), np.zeros(3))


# ---- reach checks ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "bad, reason",
    [
        ((0.6, 0.0, 0.0), r"beyond L2 \+ L3"),
        ((0.003, 0.0, 0.115), r"below \|L2 - L3\|"),  # wrist 3 mm from the shoulder
        ((0.0, 0.0, 0.2), r"joint-1 axis"),
        ((-0.3, -0.05, 0.0), r"joint1 = .* beyond its limits"),  # behind the robot
        ((0.15, 0.0, 0.0), r"joint3 = .* beyond its limits"),  # elbow folded too far
    ],
)
def test_unreachable_points_raise_with_index(bad, reason):
    points = np.array([[0.3, 0.0, 0.0], [0.25, 0.1, 0.0], bad, [0.3, 0.05, 0.0]])
    with pytest.raises(ValueError, match=r"point 2 at .*out of reach of the li_4dof robot: .*" + reason):
        LI_4DOF.ik(points)
    with pytest.raises(ValueError, match=r"sample 2 \(t = 0\.2 s\)"):
        LI_4DOF.reach_check(points, label="sample", times=[0.0, 0.1, 0.2, 0.3])
    assert LI_4DOF.is_reachable(points).tolist() == [True, True, False, True]
    assert [index for index, _ in LI_4DOF.reach_problems(points)] == [2]


def test_reach_check_counts_all_failures():
    points = np.array([[0.3, 0.0, 0.0], [0.7, 0.0, 0.0], [0.8, 0.0, 0.0]])
    with pytest.raises(ValueError, match=r"point 1 .*; 2 of 3 points are out of reach"):
        LI_4DOF.reach_check(points)


# ---- the closed path ------------------------------------------------------------------------------


def test_closed_path_shape():
    path = li_closed_path()
    assert path.shape == (687, 3)  # 686 distinct points (the paper's count) + S again
    np.testing.assert_array_equal(path[0], path[-1])
    np.testing.assert_allclose(path[0], [0.2, -0.074, 0.0])
    assert len(np.unique(path[:-1].round(12), axis=0)) == 686
    np.testing.assert_array_equal(path[:, 2], 0.0)
    steps = np.linalg.norm(np.diff(path, axis=0), axis=1)
    assert 0.0009 < steps.min() and steps.max() < 0.0011
    assert steps.sum() == pytest.approx(0.6865, abs=1e-3)
    x, y = path[:, 0], path[:, 1]
    area = 0.5 * np.sum(x[:-1] * y[1:] - x[1:] * y[:-1])
    assert area > 0  # anticlockwise
    assert x.min() == pytest.approx(0.2) and x.max() == pytest.approx(0.4)
    assert y.min() == pytest.approx(-0.074) and y.max() == pytest.approx(0.05)
    # Break points are sampled exactly.
    for corner in ([0.3, 0.05], [0.3, 0.02], [0.27, 0.05], [0.2, 0.02], [0.4, -0.034]):
        assert np.min(np.linalg.norm(path[:, :2] - corner, axis=1)) < 1e-12


def test_closed_path_density():
    assert li_closed_path(2.0).shape == (1374, 3)
    with pytest.raises(ValueError, match="points_per_mm"):
        li_closed_path(0.0)
