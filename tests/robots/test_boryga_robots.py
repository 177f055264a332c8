"""drake_traj.robots.boryga_robots: the three manipulators of Boryga (section 4).

FK against Drake's MultibodyPlant (URDF ``tool0``), closed-form IK (eq. 18-20, 24-26 with the
docs/papers.md sign fix, 30-32) against FK, joint rates against finite differences of IK along the placed
loop path, and rejection of out-of-reach points (Corrected (docs/papers.md): the paper's own example path is out of
reach of the anthropomorphic arm and needs a negative SCARA stroke).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable

from drake_traj.planners.boryga import PAPER_LOOP, paper_loop_placement, plan_loop_path
from drake_traj.robots import boryga_robots as pr
from drake_traj.robots import get_robot

NAMES = pr.ROBOT_NAMES


@pytest.fixture(scope="module", params=NAMES)
def plant_setup(request):
    name = request.param
    plant = MultibodyPlant(0.0)
    instance = get_robot(name).add_to_plant(plant)
    plant.Finalize()
    return name, plant, instance, plant.CreateDefaultContext()


def _set_q(plant, context, robot, q):
    x = np.zeros(plant.num_positions())
    for k, joint_name in enumerate(robot.joint_names):
        x[plant.GetJointByName(joint_name).position_start()] = q[k]
    plant.SetPositions(context, x)


def _random_q(robot, count, seed):
    rng = np.random.default_rng(seed)
    return rng.uniform(robot.lower_limits, robot.upper_limits, (count, 3))


@pytest.fixture(scope="module")
def placed():
    """Per robot: (robot, plan, dense times, q, qd, qdd) along the placed loop."""
    out = {}
    for name in NAMES:
        robot = get_robot(name)
        plan = paper_loop_placement(name).plan()
        times = np.linspace(0.0, plan.duration, 8001)
        out[name] = (robot, plan, times) + robot.joint_trajectory(plan, times)
    return out


# ---------------------------------------------------------------------------------------------
# Model files
# ---------------------------------------------------------------------------------------------


def test_urdf_joints_limits_and_actuators_match_module(plant_setup):
    name, plant, instance, _ = plant_setup
    robot = get_robot(name)
    assert robot.model_path().name == f"boryga_{name}.urdf"
    assert plant.num_positions() == 3 and plant.num_actuators() == 3
    plant.GetFrameByName("tool0", instance)
    for k, joint_name in enumerate(robot.joint_names):
        joint = plant.GetJointByName(joint_name, instance)
        assert joint.type_name() == robot.joint_types[k]
        assert joint.position_lower_limits()[0] == robot.lower[k]
        assert joint.position_upper_limits()[0] == robot.upper[k]
        assert joint.velocity_upper_limits()[0] == robot.velocity_limit[k]
        actuator = plant.GetJointActuatorByName(f"{joint_name}_actuator", instance)
        assert actuator.effort_limit() == robot.effort_limit[k]
    # Every non-world body has a positive mass (the paper gives none: chosen values).
    for index in plant.GetBodyIndices(instance):
        body = plant.get_body(index)
        if body.name() != "tool0":
            assert body.default_mass() > 0.0, body.name()


def test_paper_dimensions():
    a, s, c = (get_robot(n) for n in NAMES)
    assert (a.lambda1, a.l2, a.l3) == (0.33, 0.42, 0.36)
    assert (s.lambda1, s.lambda2, s.l1, s.l2) == (0.3, 0.065, 0.54, 0.42)
    assert c.l2 == 0.24
    with pytest.raises(ValueError, match="robot must be one of"):
        get_robot("delta")


# ---------------------------------------------------------------------------------------------
# Forward kinematics and Jacobian against MultibodyPlant
# ---------------------------------------------------------------------------------------------


def test_fk_jacobian_and_bias_match_multibody_plant(plant_setup):
    name, plant, instance, context = plant_setup
    robot = get_robot(name)
    tool = plant.GetFrameByName("tool0", instance)
    world = plant.world_frame()
    rng = np.random.default_rng(7)
    qs = _random_q(robot, 150, seed=1)
    fk = robot.fk(qs)  # vectorised
    for q, p in zip(qs, fk):
        _set_q(plant, context, robot, q)
        drake_p = plant.CalcPointsPositions(context, tool, np.zeros(3), world)[:, 0]
        np.testing.assert_allclose(drake_p, p, atol=1e-9)
        np.testing.assert_allclose(robot.fk(q), p, atol=1e-15)
        jac = plant.CalcJacobianTranslationalVelocity(
            context, JacobianWrtVariable.kV, tool, np.zeros(3), world, world
        )
        order = [plant.GetJointByName(j).velocity_start() for j in robot.joint_names]
        np.testing.assert_allclose(robot.jacobian(q), jac[:, order], atol=1e-9)
        qd = rng.uniform(-2.0, 2.0, 3)
        v = np.zeros(plant.num_velocities())
        v[order] = qd
        plant.SetVelocities(context, v)
        bias = plant.CalcBiasTranslationalAcceleration(
            context, JacobianWrtVariable.kV, tool, np.zeros(3), world, world
        )[:, 0]
        np.testing.assert_allclose(robot.bias(q, qd), bias, atol=1e-9)
        plant.SetVelocities(context, np.zeros(plant.num_velocities()))


# ---------------------------------------------------------------------------------------------
# Inverse kinematics
# ---------------------------------------------------------------------------------------------


def _branch_q(robot, count, seed):
    """Random q within the limits and on the IK branch (away from singularities)."""
    q = _random_q(robot, count, seed)
    if robot.name == "anthropomorphic":
        q[:, 2] = np.random.default_rng(seed + 1).uniform(0.05, robot.upper[2], count)  # theta3 >= 0
        keep = robot.singularity_measure(q) > 0.05  # tool in front of the joint-1 axis, r > 0
        return q[keep & (robot._terms(q)[6] > 0.0)]
    if robot.name == "scara":
        q[:, 1] = np.random.default_rng(seed + 1).uniform(robot.lower[1], -0.05, count)  # theta2 <= 0
    return q


@pytest.mark.parametrize("name", NAMES)
def test_ik_recovers_branch_configurations(name):
    robot = get_robot(name)
    q = _branch_q(robot, 2000, seed=3)
    assert len(q) > 500
    x = robot.fk(q)
    q_ik = robot.ik(x)
    np.testing.assert_allclose(robot.fk(q_ik), x, atol=1e-9)
    np.testing.assert_allclose(q_ik, q, atol=1e-7)  # same branch (FK of it is checked to 1e-9)
    for single_q, single_x in zip(q[:20], x[:20]):  # unbatched calls
        np.testing.assert_allclose(robot.fk(robot.ik(single_x)), single_x, atol=1e-9)


@pytest.mark.parametrize("name", NAMES)
def test_fk_of_ik_over_random_reachable_points(name):
    robot = get_robot(name)
    rng = np.random.default_rng(11)
    box = {  # (xy low, xy high, z low, z high) [m], larger than each workspace
        "anthropomorphic": (-0.8, 0.8, -0.5, 1.2),
        "scara": (-1.0, 1.0, 0.1, 0.4),
        "cartesian": (-0.9, 0.9, 0.1, 1.4),
    }[name]
    lo, hi, z_lo, z_hi = box
    points = np.column_stack([rng.uniform(lo, hi, (5000, 2)), rng.uniform(z_lo, z_hi, 5000)])
    ok = robot.is_reachable(points)
    assert 500 < ok.sum() < len(points)  # both kinds present
    q = robot.ik(points[ok])
    assert np.all(robot.within_limits(q))
    np.testing.assert_allclose(robot.fk(q), points[ok], atol=1e-9)
    # every rejected point has a reason, and ik refuses it
    problems = robot.reach_problems(points)
    assert [i for i, _ in problems] == list(np.flatnonzero(~ok))
    with pytest.raises(ValueError, match=f"point {problems[0][0]} "):
        robot.ik(points)


def test_scara_eq_24_printed_sign_is_wrong_and_fix_is_consistent():
    # Correction (docs/papers.md): with theta2 = -arccos (eq. 25), eq. 24's "- arcsin" does not reproduce the
    # point; "+ arcsin" does, and so does the other consistent pair (theta2 = +arccos, - arcsin).
    robot = get_robot("scara")
    x = np.array([0.52, 0.51, 0.265])
    B = x[0] ** 2 + x[1] ** 2
    C, D, E = 2 * robot.l1 * robot.l2, robot.l1**2 + robot.l2**2, 2 * robot.l1
    acos = math.acos((B - D) / C)
    asin = math.asin(math.sqrt((C**2 - (B - D) ** 2) / (E**2 * B)))
    base = math.atan2(x[1], x[0])
    stroke = robot.top - x[2]
    printed = robot.fk([base - asin, -acos, stroke])
    assert np.linalg.norm(printed - x) > 0.1
    np.testing.assert_allclose(robot.fk([base + asin, -acos, stroke]), x, atol=1e-12)
    np.testing.assert_allclose(robot.fk([base - asin, +acos, stroke]), x, atol=1e-12)
    np.testing.assert_allclose(robot.ik(x), [base + asin, -acos, stroke], atol=1e-12)


# ---------------------------------------------------------------------------------------------
# Out-of-reach points
# ---------------------------------------------------------------------------------------------

UNREACHABLE = {
    "anthropomorphic": [
        ((0.6, 0.5, 0.5), "exceeds the reach"),
        ((0.02, 0.01, 0.35), r"below \|l2 - l3\|"),
        ((0.0, 0.0, 0.6), "joint-1 axis"),
        ((-0.5, 0.0, 0.3), "waist_joint = 3.14159 rad is beyond its limits"),
        ((0.05, 0.0, 0.0), "shoulder_joint = .* is beyond its limits"),
    ],
    "scara": [
        ((0.9, 0.5, 0.25), "exceeds l1 \\+ l2 = 0.96"),
        ((0.05, 0.05, 0.25), r"below \|l1 - l2\| = 0.12"),
        ((0.5, 0.5, 0.4), "negative stroke lambda3 = -0.035"),
        ((0.5, 0.5, 0.1), "quill_joint = 0.265 m is beyond its limits"),
        ((-0.559, 0.421, 0.25), "shoulder_joint = 3.13894 rad is beyond its limits"),  # atan2 + arcsin
    ],
    "cartesian": [
        ((0.5, 0.5, 0.1), "z_joint = -0.14 m is beyond its limits"),
        ((0.5, 0.9, 0.5), "y_joint = 0.9 m is beyond its limits"),
        ((-0.85, 0.5, 0.5), "x_joint = 0.85 m is beyond its limits"),
    ],
}


@pytest.mark.parametrize("name", NAMES)
def test_unreachable_points_raise_naming_index_and_reason(name):
    robot = get_robot(name)
    good = paper_loop_placement(name).M
    for bad, reason in UNREACHABLE[name]:
        points = np.array([good] * 6)
        points[3] = bad
        assert list(robot.is_reachable(points)) == [True, True, True, False, True, True]
        with pytest.raises(ValueError, match=f"point 3 at .* out of reach of the {name} robot: .*{reason}"):
            robot.ik(points)
        with pytest.raises(ValueError, match=f"^point at .*{reason}"):  # one point: no index
            robot.ik(bad)
        with pytest.raises(ValueError, match="point 3"):
            robot.reach_check(points)
    robot.reach_check(good)  # no exception


@pytest.mark.parametrize("name", ["anthropomorphic", "scara"])
def test_paper_example_path_is_rejected(name):
    # Correction (docs/papers.md): Table 1's path (z = 1 m) is 0.97-1.03 m from the anthropomorphic shoulder
    # (reach 0.78 m) and needs a SCARA stroke of -0.635 m.
    p = PAPER_LOOP
    plan = plan_loop_path(p["B"], p["M"], p["E"], p["v_max"], delta=p["delta"])
    times = np.linspace(0.0, plan.duration, 501)
    reason = {"anthropomorphic": "distance 0.974115 m from the shoulder .* exceeds the reach l2 \\+ l3 = 0.78 m",
              "scara": "negative stroke lambda3 = -0.635 m"}[name]
    with pytest.raises(ValueError, match=rf"sample 0 \(t = 0 s\) at \[0.5, 0.5, 1\] m .*{reason}.*501 of 501 samples"):
        get_robot(name).joint_trajectory(plan, times)
    positions = plan.sample(times)[0]
    distance = np.linalg.norm(positions - [0.0, 0.0, 0.33], axis=1)
    assert 0.974 < distance.min() and distance.max() < 1.032  # docs/papers.md rounds to 0.97-1.03 m


def test_cartesian_runs_the_paper_example_path_unmoved():
    p = PAPER_LOOP
    placement = paper_loop_placement("cartesian")
    np.testing.assert_array_equal(placement.offset, 0.0)
    plan = plan_loop_path(p["B"], p["M"], p["E"], p["v_max"], delta=p["delta"])
    times = np.linspace(0.0, plan.duration, 501)
    q, qd, qdd = get_robot("cartesian").joint_trajectory(plan, times)
    np.testing.assert_allclose(q[:, 0], 0.76, atol=1e-15)  # lambda1 = s_z - l2 (eq. 30), constant
    _, v, a = plan.sample(times)[:3]
    np.testing.assert_allclose(qd, np.column_stack([v[:, 2], v[:, 1], -v[:, 0]]), atol=1e-15)
    np.testing.assert_allclose(qdd, np.column_stack([a[:, 2], a[:, 1], -a[:, 0]]), atol=1e-12)


def test_joint_rates_refuse_singular_configurations():
    with pytest.raises(ValueError, match="point 1 .* Jacobian is singular"):
        get_robot("scara").joint_rates([[0.3, -1.0, 0.1], [0.3, 0.0, 0.1]], np.ones(3), np.zeros(3))
    with pytest.raises(ValueError, match="point 0 .* Jacobian is singular"):
        get_robot("anthropomorphic").joint_rates([0.3, 0.2, 0.0], np.ones(3), np.zeros(3))


# ---------------------------------------------------------------------------------------------
# The placed loop
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", NAMES)
def test_placement_keeps_the_paper_shape(name):
    placement = paper_loop_placement(name)
    for key in ("B", "M", "E"):
        np.testing.assert_allclose(getattr(placement, key), np.array(PAPER_LOOP[key]) + placement.offset, atol=0)
    assert (placement.delta, placement.v_max) == (0.02, 0.25)
    assert placement.reason
    plan = placement.plan()
    assert plan.duration == pytest.approx(0.81368, abs=1e-5)  # docs/papers.md t_e, shape unchanged


@pytest.mark.parametrize("name", NAMES)
def test_fk_of_ik_along_the_placed_loop(placed, name):
    robot, plan, times, q, qd, qdd = placed[name]
    positions = plan.sample(times)[0]
    np.testing.assert_allclose(robot.fk(q), positions, atol=1e-9)
    assert np.all(robot.within_limits(q))
    assert np.all(robot.singularity_measure(q) > 0.2)
    # joint positions are continuous (no branch switch or wrap along the path)
    assert np.abs(np.diff(q, axis=0)).max() < 1e-3


@pytest.mark.parametrize("name", NAMES)
def test_joint_rates_match_finite_differences_of_ik(placed, name):
    robot, plan, times, q, qd, qdd = placed[name]
    h_v, h_a = 1e-6, 1e-4
    # keep away from the breakpoints (acceleration jumps at T1 and T2, jerk elsewhere)
    keep = np.min(np.abs(times[:, None] - plan.breakpoints[None, :]), axis=1) > 3 * h_a
    keep &= (times > 3 * h_a) & (times < plan.duration - 3 * h_a)
    t = times[keep][::4]
    q_t = robot.ik(plan.sample(t)[0])
    qd_fd = (robot.ik(plan.sample(t + h_v)[0]) - robot.ik(plan.sample(t - h_v)[0])) / (2 * h_v)
    qdd_fd = (robot.ik(plan.sample(t + h_a)[0]) - 2 * q_t + robot.ik(plan.sample(t - h_a)[0])) / h_a**2
    qd_t, qdd_t = robot.joint_rates(q_t, *plan.sample(t)[1:3])
    np.testing.assert_allclose(qd_t, qd[keep][::4], atol=1e-12)
    np.testing.assert_allclose(qd_t, qd_fd, atol=1e-7)
    np.testing.assert_allclose(qdd_t, qdd_fd, atol=1e-4 * max(1.0, np.abs(qdd_t).max()))
    # and the joint velocity integrates back to the joint path (trapezoid over the dense samples)
    dt = np.diff(times)
    np.testing.assert_allclose(q[0] + np.sum(0.5 * (qd[1:] + qd[:-1]) * dt[:, None], axis=0), q[-1], atol=1e-6)


def test_peak_joint_rates_on_the_placed_loops(placed, capsys):
    lines = []
    for name in NAMES:
        robot, plan, times, q, qd, qdd = placed[name]
        peak_v, peak_a = np.abs(qd).max(axis=0), np.abs(qdd).max(axis=0)
        assert np.all(peak_v < np.array(robot.velocity_limit))
        units = ["rad" if t == "revolute" else "m" for t in robot.joint_types]
        lines.append(
            f"{name:16s} peak |qd| = "
            + ", ".join(f"{v:.4f} {u}/s" for v, u in zip(peak_v, units))
            + "; peak |qdd| = "
            + ", ".join(f"{a:.3f} {u}/s^2" for a, u in zip(peak_a, units))
        )
    # Cartesian: joints follow the tool, peak speed v_max and the centripetal jump v_max^2 / R.
    _, _, _, _, qd_c, qdd_c = placed["cartesian"]
    assert np.abs(qd_c).max() == pytest.approx(0.25, abs=1e-9)
    assert np.abs(qdd_c).max() == pytest.approx(6.99, abs=5e-3)
    with capsys.disabled():
        print("\n" + "\n".join(lines))
