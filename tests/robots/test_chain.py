"""Any 6-axis arm (drake_traj.robots.chain): the chain from DH tables and from MultibodyPlant
against the UR10e's closed form, an independent chain product and finite differences; the
numerical IK against the closed-form IK; bad input."""

import numpy as np
import pytest
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import FixedOffsetFrame, PrismaticJoint, RevoluteJoint, SpatialInertia

from drake_traj.errors import Cause, DrakeTrajError, SingularConfigurationError
from drake_traj.planners.pajak import PajakLaw
from drake_traj.robots import get_robot, ur10e
from drake_traj.robots.chain import SerialChain
from drake_traj.robots.chain_kinematics import (CHAIN, chain_singularity_factors, inverse_kinematics_all,
                                                inverse_kinematics_near)
from drake_traj.robots.chain_arm import ChainArm
from drake_traj.robots.compiled_kinematics import task_kinematics, task_kinematics_into
from drake_traj.robots.task_space import wrap_angle, zyx_euler_from_rotation
from drake_traj.scenario import load_scenario

from conftest import DIAGRAMS

UR_DH = np.column_stack([ur10e.DH_D, ur10e.DH_A, ur10e.DH_ALPHA, np.zeros(6)])
# Pająk 2024 Table 1: the same arm in modified DH, a and alpha moved down one row
UR_MODIFIED = np.column_stack([ur10e.DH_D, np.r_[0.0, ur10e.DH_A[:-1]], np.r_[0.0, ur10e.DH_ALPHA[:-1]], np.zeros(6)])
# PUMA 560, standard DH (Corke 1996 after Armstrong et al. 1986) [m, rad]
PUMA_DH = np.column_stack([[0.0, 0.0, 0.15005, 0.4318, 0.0, 0.0], [0.0, 0.4318, 0.0203, 0.0, 0.0, 0.0],
                           [np.pi / 2, 0.0, -np.pi / 2, np.pi / 2, -np.pi / 2, 0.0], np.zeros(6)])
TOOL = np.eye(4)
TOOL[:3, :3] = RollPitchYaw(0.3, -0.2, 0.5).ToRotationMatrix().matrix()
TOOL[:3, 3] = [0.02, -0.05, 0.15]


def states(seed, count=40):
    rng = np.random.default_rng(seed)
    return rng.uniform(-2 * np.pi, 2 * np.pi, (count, 6)), rng.uniform(-2.0, 2.0, (count, 6))


def assert_same_kinematics(model, q, qd, tool):
    """pose, J, J̇q̇ of the chain equal the UR10e closed form's (bias relative to its size)."""
    mine = task_kinematics(model, q, qd, tool)
    closed = ur10e.ur10e_kinematics(q, qd, tool)
    np.testing.assert_allclose(mine[0], closed[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(mine[1], closed[1], rtol=0, atol=1e-9)
    np.testing.assert_allclose(mine[2], closed[2], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(mine[3], closed[3], rtol=0, atol=1e-12)


@pytest.mark.parametrize("tool", [np.eye(4), TOOL], ids=["flange", "tool"])
def test_ur10e_dh_chain_is_the_closed_form(tool):
    model = SerialChain.from_dh(UR_DH).packed()
    assert model[0] == CHAIN
    assert_same_kinematics(model, *states(1), tool)
    # the one compiled function dispatches on model[0]
    q, qd = states(2, 1)
    pose, jac, bias = np.empty(6), np.empty((6, 6)), np.empty(6)
    task_kinematics_into(model, q[0], qd[0], tool, pose, jac, bias)
    np.testing.assert_allclose(pose, ur10e.ur10e_kinematics(q[0], qd[0], tool)[0], atol=1e-9, rtol=0)


def test_ur10e_urdf_chain_is_the_closed_form():
    arm = ChainArm.from_model_file(ur10e.model_path(), name="generic_ur10e", base_frame="base", tool_frame="tool0", acceleration_limits=1.4)
    assert arm.joint_names == ur10e.JOINT_NAMES
    np.testing.assert_array_equal(arm.upper_limits, ur10e.POSITION_LIMIT)
    np.testing.assert_array_equal(arm.velocity_limits, ur10e.VELOCITY_LIMIT)
    np.testing.assert_array_equal(arm.effort_limits, ur10e.EFFORT_LIMIT)
    assert arm.default_gains[0][0] == pytest.approx(4000.0) and arm.default_gains[1][0] == pytest.approx(200.0)
    assert_same_kinematics(arm.model, *states(3), np.eye(4))
    tcp = arm.with_tcp([0.02, -0.05, 0.15], [0.3, -0.2, 0.5])
    q, qd = states(4)
    np.testing.assert_allclose(tcp.tcp_pose(q), ur10e.ur10e_kinematics(q, qd, TOOL)[0], atol=1e-9, rtol=0)


def test_modified_dh_is_the_standard_chain():
    q, qd = states(5)
    standard = task_kinematics(SerialChain.from_dh(UR_DH).packed(), q, qd)
    modified = task_kinematics(SerialChain.from_dh(UR_MODIFIED, "modified").packed(), q, qd)
    for mine, theirs in zip(modified[:3], standard[:3]):
        np.testing.assert_allclose(mine, theirs, rtol=1e-12, atol=1e-12)


def test_numeric_ik_finds_every_closed_form_solution():
    model = SerialChain.from_dh(UR_DH).packed()
    rng = np.random.default_rng(6)
    for _ in range(6):
        pose = ur10e.task_pose(rng.uniform(-np.pi, np.pi, 6))
        expected = ur10e.inverse_kinematics_all(pose)
        found = inverse_kinematics_all(model, pose)
        assert len(found) == len(expected)
        for q in expected:
            assert min(np.max(np.abs(wrap_angle(q - other))) for other in found) < 1e-9
    # a wrist singularity (sin q5 = 0) on one shoulder branch: the other branch's regular solutions
    pose = ur10e.task_pose([0.3, -1.0, 1.2, 0.4, 0.0, 0.5])
    regular = []
    for branch in ur10e.IK_BRANCHES:
        try:
            regular.append(ur10e.inverse_kinematics(pose, branch=branch))
        except SingularConfigurationError:
            pass
    found = inverse_kinematics_all(model, pose)
    assert len(regular) == len(found) == 4
    for q in regular:
        assert min(np.max(np.abs(wrap_angle(q - other))) for other in found) < 1e-9
    # shoulder, elbow and wrist singular at once: no regular solution
    with pytest.raises(SingularConfigurationError, match=r"reached only at singular configurations"):
        inverse_kinematics_all(model, ur10e.task_pose([0.3, -np.pi / 2, 0.0, np.pi / 2, 0.0, 0.5]))
    with pytest.raises(DrakeTrajError, match=r"out of reach: the flange would be 3.* m from joint 1's origin, the arm "
                                             r"reaches at most 1.7755 m") as error:
        inverse_kinematics_all(model, [3.0, 0.0, 0.2, np.pi, 0.0, 0.0])
    assert error.value.cause == Cause.UNREACHABLE


def puma_pose(q):
    """The PUMA 560's flange pose [x, y, z, φ_X, φ_Y, φ_Z] by the product of its standard-DH matrices."""
    pose = np.eye(4)
    for (d, a, alpha, _), angle in zip(PUMA_DH, q):
        ct, st, ca, sa = np.cos(angle), np.sin(angle), np.cos(alpha), np.sin(alpha)
        pose = pose @ np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st],
                                [0, sa, ca, d], [0, 0, 0, 1]])
    return np.concatenate([pose[:3, 3], zyx_euler_from_rotation(pose[:3, :3])])


def test_puma_560_against_a_chain_product_and_finite_differences():
    model = SerialChain.from_dh(PUMA_DH).packed()
    rng = np.random.default_rng(7)
    h = 1e-4
    for _ in range(10):
        q, qd = rng.uniform(-np.pi, np.pi, 6), rng.uniform(-1.0, 1.0, 6)
        pose, jac, bias, cos_pitch, measure = task_kinematics(model, q, qd)
        assert cos_pitch > 0.05 and 0.0 < measure <= 1.0
        np.testing.assert_allclose(pose, puma_pose(q), atol=1e-12, rtol=0)

        def difference(a, b):
            delta = a - b
            delta[3:] = wrap_angle(delta[3:])
            return delta

        numeric = np.column_stack([difference(puma_pose(q + 0.1 * h * e), puma_pose(q - 0.1 * h * e)) / (0.2 * h)
                                   for e in np.eye(6)])
        np.testing.assert_allclose(jac, numeric, atol=1e-7, rtol=0)
        second = (difference(puma_pose(q + h * qd), pose) + difference(puma_pose(q - h * qd), pose)) / h ** 2
        np.testing.assert_allclose(bias, second, atol=1e-5, rtol=0)
    # a stretched elbow (joints 2 and 3 aligned: q3 = atan(a3/d4) + pi/2 puts the forearm on a2's line) is singular
    q = np.array([0.3, 0.2, np.pi / 2 + np.arctan2(0.0203, 0.4318), 0.4, 0.5, 0.6])
    factors = chain_singularity_factors(model, q)
    assert factors["jacobian"][0] < 1e-5


def test_law_on_the_dh_chain_matches_the_closed_form():
    """The compiled Pająk law evaluated on the UR10e's DH chain gives the closed form's q̈ where
    neither measure turns on damped least squares (the Pająk task's start)."""
    config = load_scenario(DIAGRAMS / "pajak.yaml", "sim3").planner
    arm = ChainArm.from_dh("ur10e_dh", UR_DH, model_file=ur10e.model_path(), acceleration_limits=1.4,
                           home=ur10e.HOME)
    chain_law, closed_law = PajakLaw(config, arm), PajakLaw(config, ur10e.UR10E)
    discrete = closed_law.initial_discrete()
    q, qd = np.array(ur10e.HOME), np.full(6, 0.1)
    mine, theirs = chain_law.evaluate(0.2, q, qd, discrete), closed_law.evaluate(0.2, q, qd, discrete)
    assert min(mine["measure"], theirs["measure"]) > config.singularity_threshold
    np.testing.assert_allclose(mine["qdd"], theirs["qdd"], atol=1e-9, rtol=0)
    np.testing.assert_allclose(mine["pose"], theirs["pose"], atol=1e-12, rtol=0)
    assert chain_law.reach_failure(q) is None


def plant_with(joints):
    """A finalized plant: a chain of links joined by ``joints`` ("revolute", named j0.., or
    "prismatic", named slider); and the last link's name."""
    plant = MultibodyPlant(0.0)
    parent = plant.world_body()
    inertia = SpatialInertia.SolidSphereWithMass(1.0, 0.05)
    for k, kind in enumerate(joints):
        body = plant.AddRigidBody(f"link{k}", inertia)
        frame = plant.AddFrame(FixedOffsetFrame(f"f{k}", parent.body_frame(), RigidTransform([0.0, 0.0, 0.1])))
        if kind == "revolute":
            plant.AddJoint(RevoluteJoint(f"j{k}", frame, body.body_frame(), [0.0, 1.0, 0.0]))
        else:
            plant.AddJoint(PrismaticJoint("slider", frame, body.body_frame(), [0.0, 0.0, 1.0]))
        parent = body
    plant.Finalize()
    return plant, f"link{len(joints) - 1}"


def test_bad_input():
    with pytest.raises(DrakeTrajError, match=r"must have shape \(6, 4\), rows \[d, a, alpha, theta_offset\].*got shape "
                                             r"\(5, 4\)") as error:
        SerialChain.from_dh(UR_DH[:5])
    assert error.value.field == ("table",)
    bad = UR_DH.copy()
    bad[2, 1] = np.nan
    with pytest.raises(DrakeTrajError, match=r"row 2 \(joint 3\), column 1 \(a\) must be finite") as error:
        SerialChain.from_dh(bad)
    assert error.value.field == ("table", 2, 1)
    with pytest.raises(DrakeTrajError, match=r"convention must be one of \('standard', 'modified'\), got 'craig'"):
        SerialChain.from_dh(UR_DH, "craig")
    plant, tool = plant_with(["revolute"] * 7)
    with pytest.raises(DrakeTrajError, match=r"7 joints between world and link6: 'j0' \(RevoluteJoint\)"):
        SerialChain.from_plant(plant, "world", tool)
    plant, tool = plant_with(["revolute"] * 3 + ["prismatic"] + ["revolute"] * 2)
    with pytest.raises(DrakeTrajError, match=r"joint 'slider' is PrismaticJoint"):
        SerialChain.from_plant(plant, "world", tool)
    with pytest.raises(DrakeTrajError, match=r"acceleration_limits missing for the custom arm 'generic_ur10e'") as error:
        ChainArm.from_model_file(ur10e.model_path(), name="generic_ur10e", base_frame="base", tool_frame="tool0")
    assert error.value.field == ("acceleration_limits",)
    with pytest.raises(TypeError, match=r"unknown arguments \['acceleration_limit'\]"):
        ChainArm.from_model_file(ur10e.model_path(), name="generic_ur10e", base_frame="base", tool_frame="tool0", acceleration_limit=1.4)
    with pytest.raises(DrakeTrajError, match=r"masses missing for the custom arm 'puma': its model is written from the "
                                             r"DH table") as error:
        ChainArm.from_dh("puma", PUMA_DH)  # no model file: one is written from the table and the masses
    assert error.value.field == ("masses",)
    with pytest.raises(DrakeTrajError, match=r"the DH table and the model file disagree"):
        ChainArm.from_dh("puma", PUMA_DH, model_file=ur10e.model_path(), acceleration_limits=1.0)


def test_add_to_plant_gives_every_joint_its_actuator(tmp_path):
    """A model file without transmissions: the effort limits of its <limit> tags, or those given;
    the arm adds {joint}_actuator with its effort limits;
    a plant-built arm plans but has no model to add."""
    text = ur10e.model_path().read_text()
    start, end = text.index("<transmission"), text.rindex("</transmission>") + len("</transmission>")
    bare = tmp_path / "bare.urdf"
    bare.write_text(text[:start] + text[end:])
    # no drive declared: the joints' <limit effort> (ROS 2 descriptions declare drives by ros2_control)
    from_tags = ChainArm.from_model_file(bare, base_frame="base", tool_frame="tool0", acceleration_limits=1.4)
    np.testing.assert_array_equal(from_tags.effort_limits, get_robot("ur10e").effort_limits)
    efforts = np.array([300.0, 300.0, 140.0, 50.0, 50.0, 50.0])
    arm = ChainArm.from_model_file(bare, base_frame="base", tool_frame="tool0", acceleration_limits=1.4,
                                   effort_limits=efforts)
    plant = MultibodyPlant(0.001)
    instance = arm.add_to_plant(plant)
    plant.Finalize()
    for joint, effort in zip(ur10e.JOINT_NAMES, efforts):
        actuator = plant.GetJointActuatorByName(f"{joint}_actuator", instance)
        assert actuator.joint().name() == joint and actuator.effort_limit() == effort
    planned = ChainArm.from_plant(plant, name="generic_ur10e", base_frame="base", tool_frame="tool0",
                                  acceleration_limits=1.4)
    np.testing.assert_array_equal(planned.effort_limits, efforts)
    np.testing.assert_allclose(planned.tcp_pose(ur10e.HOME), ur10e.task_pose(ur10e.HOME), atol=1e-12, rtol=0)
    with pytest.raises(DrakeTrajError, match=r"built from a plant without a model_file"):
        planned.add_to_plant(MultibodyPlant(0.001))


def test_robot_services_match_the_ur10e():
    """tool_motion, joint_rates and point_ik of the UR10e's DH chain as a ChainArm equal the
    UR10e's closed-form services."""
    arm = ChainArm.from_dh("ur10e_dh", UR_DH, model_file=ur10e.model_path(), acceleration_limits=1.4,
                           home=ur10e.HOME)
    q, qd = states(8, 5)
    qdd = np.random.default_rng(9).uniform(-1.0, 1.0, (5, 6))
    for mine, theirs in zip(arm.tool_motion(q, qd, qdd), ur10e.UR10E.tool_motion(q, qd, qdd)):
        np.testing.assert_allclose(mine, theirs, atol=1e-9, rtol=0)
    v, a = np.array([0.1, -0.2, 0.05]), np.array([0.3, 0.1, -0.2])
    for mine, theirs in zip(arm.joint_rates(ur10e.HOME, v, a), ur10e.UR10E.joint_rates(ur10e.HOME, v, a)):
        np.testing.assert_allclose(mine, theirs, atol=1e-9, rtol=0)
    points = ur10e.task_pose(ur10e.HOME)[:3] + np.array([[0.05, 0.0, 0.0], [0.0, -0.1, 0.05]])
    np.testing.assert_allclose(arm.point_ik(points, ur10e.HOME), ur10e.UR10E.point_ik(points, ur10e.HOME),
                               atol=1e-9, rtol=0)


@pytest.mark.parametrize("move", [0.7, 1.0])
def test_point_ik_follows_the_branch_from_a_warm_start_as_the_seeds_would(monkeypatch, move):
    """point_ik along a path: each point from the previous point's solution (Newton), the same
    solutions as the seeded search's nearest to that start (to 1e-9 rad), the UR10e's closed form
    on its branch, and no seeded search while the warm start holds; a far point (another branch
    nearer) falls back to the seeds."""
    arm = ChainArm.from_dh("ur10e_dh", UR_DH, model_file=ur10e.model_path(), acceleration_limits=1.4,
                           home=ur10e.HOME)
    rng = np.random.default_rng(int(10 * move))
    for _ in range(3):
        reference = ur10e.HOME + rng.uniform(-move, move, 6) * np.array([1, 0.3, 0.3, 1, 0.3, 1])
        tcp = arm.tcp_pose(reference)[:3]
        path = tcp + np.linspace(0.0, 1.0, 40)[:, None] * rng.uniform(-0.05, 0.05, 3)  # a 2-9 cm line
        searches = []
        seeded = arm.inverse_kinematics_all
        monkeypatch.setattr(arm, "inverse_kinematics_all", lambda pose: searches.append(pose) or seeded(pose))
        warm = arm.point_ik(path, reference)
        assert searches == []  # every point from the previous one
        monkeypatch.undo()
        start = reference
        for point, q in zip(path, warm):
            expected = arm._nearest_solution(np.concatenate([point, arm.tcp_pose(reference)[3:]]), start)
            np.testing.assert_allclose(q, expected, atol=1e-9, rtol=0)
            start = q
        np.testing.assert_allclose(warm, ur10e.UR10E.point_ik(path, reference), atol=1e-9, rtol=0)
    # Newton from HOME: taken within 0.5 rad and the limits, refused beyond either
    near = ur10e.HOME + np.array([0.1, 0.0, 0.0, 0.0, 0.0, 0.0])
    lower, upper = arm.lower_limits, arm.upper_limits
    np.testing.assert_allclose(inverse_kinematics_near(arm.model, ur10e.task_pose(near), ur10e.HOME, lower=lower,
                                                       upper=upper), near, atol=1e-9, rtol=0)
    assert inverse_kinematics_near(arm.model, ur10e.task_pose(near), ur10e.HOME, lower=lower,
                                   upper=np.r_[ur10e.HOME[0] + 0.05, upper[1:]]) is None
    assert inverse_kinematics_near(arm.model, ur10e.task_pose(ur10e.HOME + np.r_[0.6, np.zeros(5)]), ur10e.HOME,
                                   lower=lower, upper=upper) is None
    path = arm.tcp_pose(ur10e.HOME)[:3] + np.array([[0.0, 0.0, 0.0], [0.3, -0.2, 0.1]])
    monkeypatch.setattr("drake_traj.robots.chain_arm.inverse_kinematics_near", lambda *args: None)
    np.testing.assert_allclose(arm.point_ik(path, ur10e.HOME), ur10e.UR10E.point_ik(path, ur10e.HOME), atol=1e-9, rtol=0)
