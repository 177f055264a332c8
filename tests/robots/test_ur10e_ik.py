"""Analytic inverse kinematics of the UR10e flange (robot.inverse_kinematics*).

Round trips FK(IK(x)) = x over random configurations on all eight branches, nearest-solution
selection, a circular Cartesian path on one branch, reach / singularity / shape errors, and an
independent check against Drake: poses from MultibodyPlant's forward kinematics of models/ur10e.urdf
and Drake's numerical InverseKinematics, so the closed form is not validated only by the module's FK.
"""

import numpy as np
import pytest
from pydrake.math import RigidTransform
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.plant import MultibodyPlant
from pydrake.solvers import Solve

from drake_traj.robots import ur10e as robot
from drake_traj.robots import UR10E

Q0 = np.array([-np.pi / 2, -np.pi / 2, -3 * np.pi / 4, -np.pi / 4, np.pi / 2, np.pi / 4])  # Pająk 2024 q(0)
TOL = 1e-9
MIN_SINGULARITY_MEASURE = 0.05


def random_configurations(count, seed, min_measure=MIN_SINGULARITY_MEASURE):
    """``count`` configurations in (-pi, pi]^6 with singularity_measure >= min_measure (seeded)."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        q = robot.wrap_angle(rng.uniform(-np.pi, np.pi, 6))
        if robot.singularity_measure(q) >= min_measure:
            out.append(q)
    return np.array(out)


def joint_distance(a, b):
    return np.max(np.abs(robot.wrap_angle(np.asarray(a) - np.asarray(b))), axis=-1)


def assert_pose_close(actual, expected, tol=TOL):
    np.testing.assert_allclose(actual[:3, 3], expected[:3, 3], rtol=0, atol=tol)
    np.testing.assert_allclose(actual[:3, :3], expected[:3, :3], rtol=0, atol=tol)


# --- round trips ---------------------------------------------------------------------------------


def test_round_trip_all_branches_1000_configurations():
    branch_seen = set()
    for q in random_configurations(1000, seed=20240601):
        pose = robot.flange_pose(q)
        solutions = robot.inverse_kinematics_all(pose)
        assert solutions.ndim == 2 and solutions.shape[1] == 6 and 1 <= len(solutions) <= 8
        assert np.all(solutions > -np.pi) and np.all(solutions <= np.pi)
        # the original configuration is among the solutions
        assert np.min(joint_distance(solutions, q)) < TOL
        # every solution reproduces the pose, and carries its own branch
        branches = set()
        for solution in solutions:
            assert_pose_close(robot.flange_pose(solution), pose)
            branch = robot.ik_branch(solution)
            branches.add(branch)
            assert np.array_equal(robot.inverse_kinematics(pose, branch=branch), solution)
        assert len(branches) == len(solutions)
        assert robot.ik_branch(q) in branches
        branch_seen |= branches
    assert branch_seen == set(robot.IK_BRANCHES)


def test_seed_000_start_has_eight_solutions_and_task_pose_input():
    pose = robot.flange_pose(Q0)
    np.testing.assert_allclose(pose[:3, 3], [-0.17415, -0.52400, 0.27270], atol=1e-5)
    solutions = robot.inverse_kinematics_all(pose)
    assert solutions.shape == (8, 6)
    assert np.min(joint_distance(solutions, Q0)) < TOL
    assert robot.ik_branch(Q0) == (1, -1, 1)
    q = robot.inverse_kinematics(robot.task_pose(Q0), branch=(1, -1, 1))
    np.testing.assert_allclose(q, Q0, rtol=0, atol=TOL)
    np.testing.assert_allclose(robot.inverse_kinematics_all(robot.task_pose(Q0)), solutions, rtol=0, atol=TOL)


def test_near_selects_the_original_configuration():
    rng = np.random.default_rng(7)
    for q in random_configurations(300, seed=11):
        near = q + rng.normal(scale=0.01, size=6)
        q_near = robot.inverse_kinematics(robot.flange_pose(q), near=near)
        np.testing.assert_allclose(q_near, q, rtol=0, atol=TOL)
        # with branch and near together, near only resolves 2 pi (same answer here)
        q_b = robot.inverse_kinematics(robot.flange_pose(q), branch=robot.ik_branch(q), near=near)
        np.testing.assert_allclose(q_b, q, rtol=0, atol=TOL)


def test_near_resolves_two_pi_towards_near_within_limits():
    pose = robot.flange_pose(Q0)
    shift = np.array([2 * np.pi, 0.0, 2 * np.pi, 0.0, -2 * np.pi, -2 * np.pi])
    q = robot.inverse_kinematics(pose, near=Q0 + shift + 0.01)
    np.testing.assert_allclose(q, Q0 + shift, rtol=0, atol=TOL)
    assert np.all(np.abs(q) <= robot.POSITION_LIMIT)
    # a near beyond the joint limit does not push the answer outside it
    q = robot.inverse_kinematics(pose, near=np.array([0, 0, 0, 0, 0, 2 * np.pi + 3.0]))
    assert np.all(np.abs(q) <= robot.POSITION_LIMIT)
    assert_pose_close(robot.flange_pose(q), pose)


# --- paths ---------------------------------------------------------------------------------------


def circle_poses(count=361, radius=0.1):
    """The flange tracing a horizontal circle of ``radius`` about FK(Q0), orientation fixed, from FK(Q0)."""
    start = robot.flange_pose(Q0)
    centre = start[:3, 3] - np.array([radius, 0.0, 0.0])
    poses = np.repeat(start[None], count, axis=0)
    angle = np.linspace(0.0, 2 * np.pi, count)
    poses[:, 0, 3] = centre[0] + radius * np.cos(angle)
    poses[:, 1, 3] = centre[1] + radius * np.sin(angle)
    return poses


def test_circle_path_stays_on_one_branch():
    poses = circle_poses()
    path = robot.inverse_kinematics_path(poses, Q0)
    assert path.shape == (len(poses), 6)
    np.testing.assert_allclose(path[0], Q0, rtol=0, atol=TOL)
    for q, pose in zip(path, poses):
        assert_pose_close(robot.flange_pose(q), pose)
        assert robot.ik_branch(q) == robot.ik_branch(Q0)
    assert np.max(np.abs(np.diff(path, axis=0))) < 0.05  # continuous
    np.testing.assert_allclose(path[-1], path[0], rtol=0, atol=1e-9)  # closed circle, same q
    # task poses [x, y, z, phi] give the same joint path
    task = np.array([np.concatenate([p[:3, 3], robot.zyx_euler_from_rotation(p[:3, :3])]) for p in poses])
    np.testing.assert_allclose(robot.inverse_kinematics_path(task, Q0), path, rtol=0, atol=TOL)


def test_path_is_continuous_across_pi():
    """Spinning the flange about its z axis past pi: q6 keeps growing instead of wrapping."""
    start = robot.flange_pose(Q0)
    angles = np.linspace(0.0, 3.0, 121)
    poses = np.repeat(start[None], len(angles), axis=0)
    for pose, angle in zip(poses, angles):
        c, s = np.cos(angle), np.sin(angle)
        pose[:3, :3] = start[:3, :3] @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    path = robot.inverse_kinematics_path(poses, Q0)
    np.testing.assert_allclose(path[:, 5], Q0[5] + angles, rtol=0, atol=TOL)
    np.testing.assert_allclose(path[:, :5], np.tile(Q0[:5], (len(angles), 1)), rtol=0, atol=TOL)
    assert path[-1, 5] > np.pi


def test_path_errors_name_the_sample():
    poses = circle_poses(count=50)
    far = poses.copy()
    far[30, 0, 3] += 2.0
    with pytest.raises(ValueError, match=r"sample 30.*reach"):
        robot.inverse_kinematics_path(far, Q0)
    jump = poses.copy()
    jump[20:, :3, 3] += [0.0, 0.0, 0.3]  # a 0.3 m step between samples 19 and 20
    with pytest.raises(ValueError, match=r"sample 20.*joint \d \(\w+\) moves"):
        robot.inverse_kinematics_path(jump, Q0)
    # a q_start far from every solution of the first pose is a jump at sample 0
    with pytest.raises(ValueError, match=r"sample 0.*q_start"):
        robot.inverse_kinematics_path(poses, Q0 + np.array([1.0, 0, 0, 0, 0, 0]))
    wrist = poses.copy()
    wrist[10] = robot.flange_pose([0.3, -1.0, 1.0, -0.5, 0.0, 0.2])
    with pytest.raises(robot.SingularConfigurationError, match=r"sample 10.*wrist singularity"):
        robot.inverse_kinematics_path(wrist, Q0)


# --- reach, singularities, shapes ----------------------------------------------------------------


def test_unreachable_pose_raises_with_distance():
    pose = robot.flange_pose(Q0)
    pose[:3, 3] += [2.0, 0.0, 0.0]  # 2 m away
    reach = r"out of reach: the wrist centre .* is \d\.\d+ m from the shoulder.*reaches at most 1\.3"
    with pytest.raises(ValueError, match=reach):
        robot.inverse_kinematics(pose)
    with pytest.raises(ValueError, match="reach"):
        robot.inverse_kinematics_all(pose)
    with pytest.raises(ValueError, match="reach"):
        robot.inverse_kinematics(pose, near=Q0)
    # wrist centre on the joint-1 axis: inside the d4 cylinder
    inside = np.eye(4)
    inside[:3, 3] = [0.0, 0.0, 0.5 + robot.DH_D[5]]
    with pytest.raises(ValueError, match=r"out of reach.*0 m from the joint-1 axis.*d4"):
        robot.inverse_kinematics(inside)
    assert not issubclass(ValueError, robot.SingularConfigurationError)


def test_branch_out_of_reach_names_branch():
    # a pose near the outer reach: some branches exist, the error for a missing one names it
    for q in random_configurations(200, seed=3):
        pose = robot.flange_pose(q)
        solutions = robot.inverse_kinematics_all(pose)
        if len(solutions) < 8:
            present = {robot.ik_branch(s) for s in solutions}
            missing = next(b for b in robot.IK_BRANCHES if b not in present)
            with pytest.raises(ValueError, match=r"out of reach of branch"):
                robot.inverse_kinematics(pose, branch=missing)
            return
    pytest.fail("no pose with fewer than 8 solutions found")


def test_wrist_singular_pose_raises():
    q = np.array([0.3, -1.0, 1.0, -0.5, 0.0, 0.2])  # sin q5 = 0
    pose = robot.flange_pose(q)
    shoulder = robot.ik_branch(q)[0]
    for call in (
        lambda: robot.inverse_kinematics(pose),
        lambda: robot.inverse_kinematics(pose, near=q),
        lambda: robot.inverse_kinematics(pose, branch=(shoulder, 1, 1)),
        lambda: robot.inverse_kinematics(pose, branch=(shoulder, -1, -1)),
        lambda: robot.inverse_kinematics_all(pose),
    ):
        with pytest.raises(robot.SingularConfigurationError, match="wrist singularity"):
            call()
    # the other shoulder branch is not wrist-singular at this pose and is still solved
    other = robot.inverse_kinematics(pose, branch=(-shoulder, 1, 1))
    assert_pose_close(robot.flange_pose(other), pose)
    assert robot.ik_branch(other) == (-shoulder, 1, 1)
    # just off the singularity the branch is defined again and the round trip holds
    q[4] = 1e-4
    solutions = robot.inverse_kinematics_all(robot.flange_pose(q))
    assert np.min(joint_distance(solutions, q)) < 1e-8


def test_shoulder_singular_pose_raises_for_branch():
    # a2 c2 + a3 c23 = 0 and s234 = 0: the wrist centre lies on the d4 cylinder about joint 1
    q2 = -2.0
    q23 = -np.arccos(-robot.DH_A[1] * np.cos(q2) / robot.DH_A[2])
    q = np.array([0.4, q2, q23 - q2, -q23, 1.0, 0.3])
    assert abs(robot.singularity_measure(q)) < 1e-12
    pose = robot.flange_pose(q)
    with pytest.raises(robot.SingularConfigurationError, match="shoulder singularity"):
        robot.inverse_kinematics(pose, branch=(1, 1, 1))
    # the solution set itself is finite: both shoulder branches coincide and are listed once
    solutions = robot.inverse_kinematics_all(pose)
    assert len(solutions) <= 4
    assert np.min(joint_distance(solutions, q)) < 1e-7
    for solution in solutions:
        assert_pose_close(robot.flange_pose(solution), pose, tol=1e-8)
    np.testing.assert_allclose(robot.inverse_kinematics(pose, near=q + 0.01), q, rtol=0, atol=1e-7)


def test_elbow_singular_pose_raises_for_branch():
    q = np.array([0.4, -0.7, 0.0, -1.0, 1.0, 0.3])  # sin q3 = 0: arm stretched
    pose = robot.flange_pose(q)
    with pytest.raises(robot.SingularConfigurationError, match="elbow singularity"):
        robot.inverse_kinematics(pose, branch=robot.ik_branch(q)[:1] + (1,) + robot.ik_branch(q)[2:])
    assert np.min(joint_distance(robot.inverse_kinematics_all(pose), q)) < 1e-7


@pytest.mark.parametrize(
    "pose",
    [
        np.eye(3),
        np.zeros(5),
        np.zeros((2, 4, 4)),
        np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1.0]]),  # last row
        np.diag([1.0, 1.0, -1.0, 1.0]),  # improper rotation
        np.diag([2.0, 1.0, 1.0, 1.0]),  # not orthonormal
        np.full(6, np.nan),
    ],
)
def test_bad_pose_raises_value_error(pose):
    with pytest.raises(ValueError, match="pose"):
        robot.inverse_kinematics(pose)
    with pytest.raises(ValueError, match="pose"):
        robot.inverse_kinematics_all(pose)


def test_bad_arguments_raise_value_error():
    pose = robot.flange_pose(Q0)
    with pytest.raises(ValueError, match="near"):
        robot.inverse_kinematics(pose, near=np.zeros(5))
    for branch in ((1, 1), (1, 0, 1), (2, 1, 1)):
        with pytest.raises(ValueError, match="branch"):
            robot.inverse_kinematics(pose, branch=branch)
    with pytest.raises(ValueError, match="poses"):
        robot.inverse_kinematics_path(np.zeros((5, 3)), Q0)
    with pytest.raises(ValueError, match="poses"):
        robot.inverse_kinematics_path(pose, Q0)  # a single 4x4 is not a path
    with pytest.raises(ValueError, match="poses"):
        robot.inverse_kinematics_path(np.zeros((0, 6)), Q0)
    with pytest.raises(ValueError, match="q_start"):
        robot.inverse_kinematics_path(pose[None], np.zeros(4))


# --- independent check against Drake -------------------------------------------------------------


@pytest.fixture(scope="module")
def drake_ur10e():
    plant = MultibodyPlant(time_step=0.0)
    UR10E.add_to_plant(plant)
    plant.Finalize()
    return plant


def drake_flange_pose(plant, q):
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, q)
    return plant.CalcRelativeTransform(
        context, plant.GetFrameByName(robot.BASE_FRAME), plant.GetFrameByName(robot.FLANGE_FRAME)
    ).GetAsMatrix4()


def test_drake_forward_kinematics_poses_are_solved(drake_ur10e):
    """Poses from MultibodyPlant (not robot.flange_pose): every branch solution reproduces them."""
    for q in random_configurations(20, seed=99):
        target = drake_flange_pose(drake_ur10e, q)
        solutions = robot.inverse_kinematics_all(target)
        assert np.min(joint_distance(solutions, q)) < TOL
        for solution in solutions:
            assert_pose_close(drake_flange_pose(drake_ur10e, solution), target)


def test_drake_inverse_kinematics_converges_to_one_of_our_solutions(drake_ur10e):
    """Drake's numerical IK (SNOPT, default tolerances ~1e-6) from a perturbed guess lands on one of
    our closed-form solutions, and on no other: the nearest is within 1e-4 rad, the next >= 0.05 rad.
    (The exactness to 1e-9 against Drake's FK is test_drake_forward_kinematics_poses_are_solved.)"""
    plant = drake_ur10e
    world, tool0 = plant.world_frame(), plant.GetFrameByName(robot.FLANGE_FRAME)
    rng = np.random.default_rng(5)
    for q in random_configurations(6, seed=123):
        target = drake_flange_pose(plant, q)
        ik = InverseKinematics(plant)
        # the flange origin and two points 0.1 m along its x and y axes fix the full pose (errors
        # enter linearly; AddOrientationConstraint bounds cos(angle) and leaves ~1e-3 rad)
        for point in (np.zeros(3), [0.1, 0.0, 0.0], [0.0, 0.1, 0.0]):
            p_world = target[:3, :3] @ np.asarray(point) + target[:3, 3]
            ik.AddPositionConstraint(tool0, point, world, p_world, p_world)
        guess = q + rng.uniform(-0.3, 0.3, 6)  # Drake starts off the solution and must find one itself
        result = Solve(ik.prog(), guess)
        assert result.is_success(), result.get_solution_result()
        q_drake = result.GetSolution(ik.q())
        assert_pose_close(drake_flange_pose(plant, q_drake), target, tol=1e-5)
        ours = robot.inverse_kinematics_all(RigidTransform(target).GetAsMatrix4())
        distances = np.sort(joint_distance(ours, q_drake))
        assert distances[0] < 1e-4
        assert len(distances) == 1 or distances[1] > 0.05
        # selecting by near gives that solution, 2 pi resolved towards Drake's answer
        np.testing.assert_allclose(robot.inverse_kinematics(target, near=q_drake), q_drake, rtol=0, atol=1e-4)
