"""The shipped e-Series variants (diagrams/pajak.yaml ur3e..ur20, diagrams/quintic.yaml
ptp_ur3e..ptp_ur20): each on its own arm with that arm's limits and default gains, its task
accepted by the preflight (the Pająk law integrated, the cell check), and one closed-loop run per
arm with the limits held at every logged sample and the goal reached."""

import numpy as np
import pytest

from drake_traj.robots import get_robot
from drake_traj.robots.task_space import wrap_angle
from drake_traj.scenario import load_scenario, make_planner, preflight, shipped_scenarios
from drake_traj.station import simulate

ARMS = ("ur3e", "ur5e", "ur16e", "ur20")
VARIANTS = [f"pajak_{arm}" for arm in ARMS] + [f"quintic_ptp_{arm}" for arm in ARMS]


def test_every_arm_has_both_variants_shipped():
    shipped = {entry.name: entry.robot for entry in shipped_scenarios()}
    assert {name: shipped.get(name) for name in VARIANTS} == {name: name.rsplit("_", 1)[1] for name in VARIANTS}


@pytest.mark.parametrize("name", VARIANTS)
def test_variant_runs_its_own_arm_and_passes_the_preflight(name):
    scenario = load_scenario(name)
    arm = get_robot(scenario.robot)
    assert scenario.controller.for_robot(arm).kp == list(arm.default_gains[0])
    planner = make_planner(scenario)
    velocity, acceleration = arm.joint_move_limits
    np.testing.assert_array_equal(planner.velocity_limit, velocity)
    np.testing.assert_array_equal(planner.acceleration_limit, acceleration)
    np.testing.assert_array_equal(velocity, np.minimum(1.05, arm.velocity_limits))
    path = preflight(scenario, planner)
    if name.startswith("pajak"):  # the law's motion ends within 1 mm of the last waypoint, inside the arm's reach
        waypoints = np.array(scenario.planner.waypoints)[:, :3]
        assert np.linalg.norm(path[-1] - waypoints[-1]) < 1e-3
        assert np.all(np.linalg.norm(waypoints - arm.tcp_pose(arm.home_configuration)[:3], axis=1) < arm.reach)


@pytest.mark.parametrize("name", ["pajak_ur3e", "quintic_ptp_ur5e", "pajak_ur16e", "quintic_ptp_ur20"])
def test_closed_loop_holds_the_arms_limits_and_reaches_the_goal(name):
    scenario = load_scenario(name)
    arm = get_robot(scenario.robot)
    result = simulate(scenario)
    assert result.succeeded, result.failure
    assert result.robot == arm.name
    velocity, acceleration = arm.joint_move_limits
    np.testing.assert_array_equal(result.effort_limit, arm.effort_limits)
    # every logged 1 ms sample of the reference within the planner's limits; torques within the arm's
    assert np.all(np.abs(result.qd_ref) <= velocity + 1e-9) and np.all(np.abs(result.qdd_ref) <= acceleration + 1e-9)
    assert np.all(np.abs(result.tau) <= arm.effort_limits + 1e-9)
    if name.startswith("pajak"):
        goal = np.array(scenario.planner.waypoints[-1])
        final = arm.tcp_pose(result.q_meas[-1])
        assert np.linalg.norm(final[:3] - goal[:3]) < scenario.planner.accuracy  # 1 mm
        assert np.max(np.abs(wrap_angle(final[3:] - goal[3:]))) < scenario.planner.orientation_accuracy
    else:
        assert np.max(np.abs(result.q_meas[-1] - scenario.planner.goals[-1])) < 1e-3
