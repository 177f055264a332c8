"""Every planner plans the TCP of a robot made by Robot.with_tcp, through the robot contract alone.

A straight tool 0.15 m along the flange z axis: the planned TCP passes through the task's points
(Pająk's waypoints within ϵ and its final accuracy, Li's path points, Boryga's B, M and E) and
the flange, 0.15 m behind it, does not. Positions are checked against an independent computation
(the flange pose from the DH chain times the offset); the simulated result reports the TCP.
"""

import numpy as np
import pytest

from drake_traj.planners import make_planner
from drake_traj.planners.baselines.movej import MovejConfig
from drake_traj.planners.boryga import BorygaConfig
from drake_traj.planners.li import LiConfig
from drake_traj.planners.li.path import li_closed_path
from drake_traj.planners.pajak import parameters as P
from drake_traj.planners.pajak.integration import integrate
from drake_traj.planners.pajak.law import PajakLaw
from drake_traj.planners.quintic import QuinticConfig
from drake_traj.robots import UR10E
from drake_traj.robots import ur10e as robot
from drake_traj.station import simulate

LENGTH = 0.15  # [m], the tool along the flange z axis
TOOL = UR10E.with_tcp([0.0, 0.0, LENGTH], [0.0, 0.0, 0.0])
Q0 = P.paper_initial_configuration()
GOALS = [[-1.2, -1.7, -2.0, -1.0, 1.4, 0.5], [-1.9, -1.4, -2.2, -0.5, 1.7, 1.0]]


def tcp_positions(q) -> np.ndarray:
    """TCP positions of joint rows q (N, 6), independently of the compiled kinematics: the DH
    chain's flange pose times the offset."""
    return np.array([(robot.flange_pose(row) @ TOOL.tcp_offset)[:3, 3] for row in q])


def closest(path, points) -> np.ndarray:
    """For each point (m, 3), its distance to the nearest sample of ``path`` (N, 3) [m]."""
    return np.min(np.linalg.norm(path[:, None, :] - points[None], axis=2), axis=0)


def law_path(planner, step=1e-3) -> np.ndarray:
    """The planner's joint law sampled every ``step`` [s] of law time, (N, n)."""
    taus = np.append(np.arange(0.0, planner.law.duration, step), planner.law.duration)
    return np.array([planner.law.sample(tau)[0] for tau in taus])


@pytest.fixture(scope="module")
def pajak_run():
    return integrate(PajakLaw(P.paper_parameters(3), TOOL), Q0)


def test_pajak_plans_the_tcp_through_its_waypoints(pajak_run):
    config = P.paper_parameters(3)
    waypoints = config.waypoints
    q = pajak_run["q"][: pajak_run["finish_index"] + 1]
    tcp = pajak_run["tcp"][: pajak_run["finish_index"] + 1]
    np.testing.assert_allclose(tcp[:, :3], tcp_positions(q), rtol=0, atol=1e-12)  # the law's k(q) is the TCP's
    np.testing.assert_allclose(tcp, TOOL.tcp_pose(q), rtol=0, atol=1e-12)
    tcp_gap = closest(tcp[:, :3], waypoints[:, :3])
    # where the TCP is nearest each waypoint, the flange is the tool's length from it (the flange
    # itself crosses p1 on the way up from q(0), straight below it: not at the same time)
    nearest = np.argmin(np.linalg.norm(tcp[:, None, :3] - waypoints[None, :, :3], axis=2), axis=0)
    flange_gap = np.linalg.norm(UR10E.tool_position(q[nearest]) - waypoints[:, :3], axis=1)
    print(f"Pająk sim 3 with the tool: T = {pajak_run['T']:.3f} s, final TCP error {pajak_run['error'] * 1e3:.3f} mm, "
          f"{pajak_run['orientation_error']:.2e} rad; TCP to waypoints {np.round(tcp_gap * 1e3, 2)} mm, "
          f"flange {np.round(flange_gap * 1e3, 1)} mm")
    assert np.all(tcp_gap[:-1] < config.neighbourhood)
    assert pajak_run["error"] < config.accuracy and pajak_run["orientation_error"] < config.orientation_accuracy
    assert np.linalg.norm(UR10E.tool_position(q[-1]) - waypoints[-1, :3]) == pytest.approx(LENGTH, abs=2e-3)
    np.testing.assert_allclose(flange_gap, LENGTH, atol=config.neighbourhood)
    assert list(np.unique(pajak_run["waypoint"])) == [0, 1, 2, 3]


def test_pajak_with_a_turned_tool_reaches_the_tcp_pose():
    # an offset off the flange axis, turned: the law's pose (position and Euler angles) is the TCP's
    tool = UR10E.with_tcp([0.0, 0.05, 0.1], [0.2, -0.1, 0.8])
    config = P.paper_parameters(3)
    run = integrate(PajakLaw(config, tool), Q0)
    q = run["q"][: run["finish_index"] + 1]
    independent = np.array([robot.flange_pose(row) @ tool.tcp_offset for row in q])
    np.testing.assert_allclose(run["tcp"][: len(q), :3], independent[:, :3, 3], rtol=0, atol=1e-12)
    turned = np.array([robot.rotation_from_zyx_euler(pose[3:]) for pose in run["tcp"][: len(q)]])
    np.testing.assert_allclose(turned, independent[:, :3, :3], rtol=0, atol=1e-12)
    final = independent[-1]
    goal = robot.rotation_from_zyx_euler(config.waypoints[-1, 3:])
    assert np.linalg.norm(final[:3, 3] - config.waypoints[-1, :3]) < config.accuracy
    assert np.arccos(np.clip((np.trace(goal.T @ final[:3, :3]) - 1) / 2, -1, 1)) < config.orientation_accuracy


def test_li_plans_the_tcp_through_its_points():
    planner = make_planner(LiConfig(), TOOL, Q0)
    points = li_closed_path() - li_closed_path()[0] + TOOL.tool_position(Q0)  # the default: from the TCP at Q0
    knots = np.array([planner.law.sample(tau)[0] for tau in planner.law.knot_times])
    tcp_gap = np.linalg.norm(tcp_positions(knots) - points, axis=1)  # the spline passes its knots at the points
    flange_gap = np.linalg.norm(UR10E.tool_position(knots) - points, axis=1)
    print(f"Li with the tool: {len(points)} points, TCP at most {tcp_gap.max():.2e} m from them, "
          f"flange {flange_gap.min():.4f}-{flange_gap.max():.4f} m")
    assert tcp_gap.max() < 1e-9
    np.testing.assert_allclose(flange_gap, LENGTH, atol=1e-9)  # the path is traced at Q0's orientation


def test_boryga_plans_the_tcp_through_b_m_e():
    planner = make_planner(BorygaConfig(velocity_limit=[1.05] * 6, acceleration_limit=[1.40] * 6), TOOL, Q0)
    points = planner.task_waypoints()
    np.testing.assert_allclose(points[0], TOOL.tool_position(Q0), rtol=0, atol=1e-12)  # B: the TCP at Q0
    q = law_path(planner)
    tcp_gap = closest(tcp_positions(q), points)
    flange_gap = closest(UR10E.tool_position(q), points)
    print(f"Boryga with the tool: TCP to B, M, E {np.round(tcp_gap * 1e3, 4)} mm, flange {np.round(flange_gap, 4)} m")
    assert tcp_gap[0] < 1e-9 and tcp_gap[2] < 1e-9  # B and E are the law's ends
    assert tcp_gap[1] < 0.25 * 1e-3  # M: within one 1 ms sample at v_max = 0.25 m/s
    assert np.all(flange_gap > LENGTH - 1e-3)


@pytest.mark.parametrize("config", [QuinticConfig(goals=GOALS), MovejConfig(goals=GOALS, blend_radius=0.05)])
def test_joint_space_planners_show_tcp_waypoints(config):
    planner = make_planner(config, TOOL, Q0)
    np.testing.assert_allclose(planner.task_waypoints(), tcp_positions(np.array(GOALS)), rtol=0, atol=1e-12)
    offsets = np.linalg.norm(planner.task_waypoints() - UR10E.tool_position(np.array(GOALS)), axis=1)
    np.testing.assert_allclose(offsets, LENGTH, atol=1e-12)


def test_the_result_of_a_tcp_run_reports_the_tcp():
    planner = make_planner(P.paper_parameters(3), TOOL, Q0)
    result = simulate(planner, robot=TOOL, name="pajak_tcp")
    assert result.failure is None, result.failure
    np.testing.assert_allclose(result.tcp[:, :3], tcp_positions(result.q_meas), rtol=0, atol=1e-12)
    np.testing.assert_allclose(result.tcp_ref, TOOL.tcp_pose(result.q_ref), rtol=0, atol=0)
    metrics = result.metrics()
    final = np.linalg.norm(result.tcp[-1, :3] - P.paper_parameters(3).waypoints[-1, :3])
    print(f"simulated Pająk sim 3 with the tool: final TCP position error {metrics.final_position_error_m * 1e3:.3f} mm, "
          f"flange {np.linalg.norm(UR10E.tool_position(result.q_meas[-1]) - result.goal[:3]):.4f} m from the goal")
    assert metrics.final_position_error_m == pytest.approx(final, abs=1e-12)
    assert metrics.final_position_error_m < 2e-3
