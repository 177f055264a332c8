"""Every planner of a UR10e scenario runs on other arms too: the joint-space planners (MoveJ,
Ruckig, Toppra, smooth waypoints) on the joint goals of the shipped UR3e and PUMA 560 quintic
tasks, and the Pająk planner (its limits left out) and the re-timed Pająk path on their Pająk tasks. Each is made for that arm (its limits,
its kinematics), passes the preflight (the whole task before t = 0, then the planned motion in the
cell: joint ranges, self-collision, the table) and its plan keeps the arm's limits at dense
samples; empty limits take the arm's joint-move limits."""

import dataclasses

import numpy as np
import pytest

import drake_traj
from drake_traj import MovejConfig, RetimedPajakConfig, RuckigConfig, SmoothWaypointsConfig, ToppraConfig
from drake_traj.scenario import preflight

JOINT_SPACE = {
    "movej": lambda goals: MovejConfig(goals=goals),  # (no blends: blend_radius 0)
    "ruckig": lambda goals: RuckigConfig(goals=goals),
    "toppra": lambda goals: ToppraConfig(path=goals, grid_points=1000),
    "smooth_waypoints": lambda goals: SmoothWaypointsConfig(goals=goals),
}
ARMS = {"ur3e": ("quintic_ptp_ur3e", "pajak_ur3e"), "puma560": ("puma560_quintic", "puma560_pajak")}
# every planner here keeps its limits at every instant (Toppra's baseline too: its timing is
# stretched where Drake's exceeds them between grid points), within round-off
SLACK = 1.0 + 1e-9


def planned_peaks(planner, robot):
    """(peak |q̇| / limit, peak |q̈| / limit) of ``planner.plan()`` at 1 ms samples, and the
    limits it promises [rad/s, rad/s²]."""
    plan = planner.plan()
    times = np.arange(plan.start_time(), plan.end_time(), 1e-3)
    rate, acceleration_of = plan.derivative(1), plan.derivative(2)
    qd = np.array([rate.value(t).ravel() for t in times])
    qdd = np.array([acceleration_of.value(t).ravel() for t in times])
    velocity = np.broadcast_to(planner.velocity_limit, (robot.num_joints,))
    acceleration = np.broadcast_to(planner.acceleration_limit, (robot.num_joints,))
    return np.max(np.abs(qd) / velocity), np.max(np.abs(qdd) / acceleration), velocity, acceleration


@pytest.mark.parametrize("arm", sorted(ARMS))
@pytest.mark.parametrize("kind", sorted(JOINT_SPACE) + ["pajak", "pajak_retimed"])
def test_a_planner_made_for_another_arm_passes_the_preflight_within_its_limits(arm, kind):
    quintic_name, pajak_name = ARMS[arm]
    if kind == "pajak":  # its limits left out: the arm's joint-move limits
        base = drake_traj.load_scenario(pajak_name)
        scenario = dataclasses.replace(base, planner=dataclasses.replace(base.planner, velocity_limit=None,
                                                                         acceleration_limit=None))
    elif kind == "pajak_retimed":
        base = drake_traj.load_scenario(pajak_name)
        scenario = dataclasses.replace(base, planner=RetimedPajakConfig(pajak=base.planner))
    else:
        base = drake_traj.load_scenario(quintic_name)
        scenario = dataclasses.replace(base, planner=JOINT_SPACE[kind](base.planner.goals))
    robot = scenario.robot_with_tool()
    assert robot.name == arm
    planner = drake_traj.make_planner(scenario)
    assert planner.robot.name == arm and type(planner.robot) is type(robot)  # made for that arm
    preflight(scenario, planner)  # raises on a refusal (range, contact, unfinished task)
    velocity_ratio, acceleration_ratio, velocity, acceleration = planned_peaks(planner, robot)
    assert np.all(velocity <= robot.velocity_limits + 1e-12)  # never above the arm's rated speeds
    if kind != "pajak_retimed":  # empty limits: the arm's joint-move limits
        assert np.allclose(velocity, robot.joint_move_limits[0])
        assert np.allclose(acceleration, robot.joint_move_limits[1])
    assert velocity_ratio <= SLACK and acceleration_ratio <= SLACK
    assert velocity_ratio > 0.5 and acceleration_ratio > 0.5  # the limits are used, not ignored
