"""Li et al. 2019's planner end to end: the closed path on the 4-DOF robot and on the UR10e."""

import numpy as np
import pytest

from drake_traj.station import simulate
from drake_traj.robots import get_robot
from drake_traj.scenario import load_scenario, make_planner

from conftest import DIAGRAMS

TOOL_SPEED, TOOL_ACCELERATION = 0.2, 0.1  # Table 4 [m/s, m/s^2]


def distance_to_polyline(points, polyline):
    """For each point, the distance to the nearest segment of ``polyline`` [m]."""
    start, end = polyline[:-1], polyline[1:]
    direction = end - start
    fraction = np.clip(np.einsum("psk,sk->ps", points[:, None] - start[None], direction) / (direction**2).sum(1), 0, 1)
    nearest = start[None] + fraction[..., None] * direction[None]
    return np.linalg.norm(points[:, None] - nearest, axis=2).min(axis=1)


@pytest.fixture(scope="module", params=["4dof", "ur10e"])
def li_run(request):
    scenario = load_scenario(DIAGRAMS / "li_closed_path.yaml", request.param)
    planner = make_planner(scenario)
    result = simulate(planner, name=scenario.name, robot=get_robot(scenario.robot), settle_time=0.1,
                      max_duration=scenario.max_duration, cell=scenario.cell)
    return planner, result


def test_joint_limits_hold_at_every_logged_sample(li_run):
    planner, result = li_run
    assert result.succeeded
    assert np.all(np.abs(result.qd_ref) <= planner.velocity_limit)
    assert np.all(np.abs(result.qdd_ref) <= planner.acceleration_limit)
    assert np.abs(np.diff(result.qdd_ref, axis=0)).max() <= 0.1  # q-ddot continuous [rad/s^2 per 1 ms]


def test_tool_limits_hold_through_forward_kinematics(li_run):
    planner, result = li_run
    velocity, acceleration = planner._tool_motion(result.q_ref, result.qd_ref, result.qdd_ref)
    assert np.linalg.norm(velocity, axis=1).max() <= TOOL_SPEED
    assert np.linalg.norm(acceleration, axis=1).max() <= TOOL_ACCELERATION * (1 + 1e-6)


def test_tool_stays_on_the_path_and_closes_it(li_run):
    planner, result = li_run
    path = planner.li_plan.cartesian.points
    deviation = distance_to_polyline(result.tcp_ref[:, :3], path)
    # Measured: 0.08 mm (4-DOF) and 0.07 mm (UR10e) between the 1 mm spaced path points.
    assert deviation.max() < 2e-4
    np.testing.assert_allclose(result.tcp[-1, :3], path[-1], atol=1e-5)  # back at the start, at rest
    assert result.metrics().tracking_error_tcp_max_m < 1e-4


def test_the_repairs_only_lengthen_the_motion_and_by_little(li_run):
    planner, result = li_run
    plan = planner.li_plan
    assert plan.joint_repair.initial_duration == plan.tool_repair.initial_duration == plan.cartesian.duration
    assert plan.cartesian.duration <= plan.joint_repair.final_duration <= plan.tool_repair.final_duration
    assert planner.law.duration == plan.tool_repair.final_duration
    assert plan.joint_repair.uniform_stretch == plan.tool_repair.uniform_stretch == 1.0  # the warps converged
    # The closed loop ends with the law, at most 1.25 times the Cartesian stage.
    assert result.duration == pytest.approx(planner.law.duration, abs=2e-3)
    assert result.duration <= 1.25 * plan.cartesian.duration


def test_li_planner_rejects_bad_input(tmp_path):
    text = (DIAGRAMS / "li_closed_path.yaml").read_text()
    text = "4dof:" + text.split("\n4dof:")[1].split("\nur10e:")[0]  # the 4-DOF variant alone
    path = tmp_path / "bad.yaml"
    path.write_text(text.replace("    tool_velocity_limit: 0.2", "    tool_velocity_limit: 0.2\n    points: [[0.3, 0, 0], [0.9, 0, 0]]"))
    with pytest.raises(ValueError, match="out of reach|too far"):
        make_planner(load_scenario(path))
    path.write_text(text.replace("    tool_velocity_limit: 0.2", "    tool_velocity_limit: 0.2\n    points: [[0.3, 0, 0], [0.3, 0, 0], [0.35, 0, 0]]"))
    with pytest.raises(ValueError, match="repeats"):
        make_planner(load_scenario(path))
    path.write_text(text.replace("    tool_acceleration_limit: 0.1", "    tool_acceleration_limit: 0.0"))
    with pytest.raises(ValueError, match="a_max"):
        make_planner(load_scenario(path))
    text = text.replace("robot: li_4dof", "robot: scara")
    path.write_text(text)
    with pytest.raises(ValueError, match="acceleration_limit must be given: the robot has no default"):
        make_planner(load_scenario(path))
    # the path placed at the tool of the SCARA's home configuration, where its arm is stretched
    path.write_text(text.replace("    tool_velocity_limit: 0.2", "    tool_velocity_limit: 0.2\n    acceleration_limit: [1, 1, 1]"))
    with pytest.raises(ValueError, match="out of reach of the scara"):
        make_planner(load_scenario(path))
