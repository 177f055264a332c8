"""Pająk 2024's planner as a Drake system: the paper's sim 3 in the closed loop, and failures.

The law itself (Table 2, the improvements, the property test) is tested in test_pajak_law.py
with its own fixed-step integrator; here the same law runs under the Simulator in the
PD-controlled diagram, and the two must agree.
"""

import numpy as np
from scipy.spatial import cKDTree
import pytest
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem

from drake_traj.errors import Cause, PlanningError
from drake_traj.robots import ur10e as robot
from drake_traj.scenario import default_plant_config, default_simulator_config, load_scenario, make_planner
from drake_traj.station import build_station, run_station, simulate
from drake_traj.planners import pajak as P
from drake_traj.results import SimulationResult

from conftest import DIAGRAMS

Q0 = P.paper_initial_configuration()
TOL = 1e-9


@pytest.fixture(scope="module")
def sim3(default_run_dir):
    return SimulationResult.load(default_run_dir)


@pytest.fixture(scope="module")
def sim3_law():
    """The same task by the law's own RK4 integrator (independent of Drake's)."""
    return P.integrate(P.PajakLaw(P.paper_parameters(3)), Q0)


def test_default_run_is_pajak_sim3_and_agrees_with_the_law_integrator(sim3, sim3_law):
    assert sim3.name == "pajak_sim3" and sim3.succeeded
    # Measured: 5.332 s both ways (paper 5.32 s; the paper's method gives 5.351 s, see README).
    assert sim3.duration == pytest.approx(sim3_law["T"], abs=0.01)
    assert sim3.duration == pytest.approx(5.32, rel=0.05)  # Table 2


def test_sim3_limits_hold_at_every_logged_sample(sim3):
    assert np.abs(sim3.qdd_ref).max() <= 1.40 + TOL
    assert np.abs(sim3.qd_ref).max() <= 1.05 + TOL
    assert np.abs(sim3.qdd_ref).max() == pytest.approx(1.40, abs=1e-3)  # the limit is used
    assert sim3.scaling[0] == 0.0 and np.all((sim3.scaling >= 0) & (sim3.scaling <= 1))


def test_sim3_reaches_the_goal_through_every_neighbourhood(sim3):
    finish = np.searchsorted(sim3.t, sim3.duration)
    goal = P.paper_parameters(3).waypoints[-1]
    assert np.linalg.norm(robot.task_pose(sim3.q_ref[finish])[:3] - goal[:3]) < 1e-3
    assert np.linalg.norm(sim3.tcp[-1, :3] - goal[:3]) < 1e-3  # measured, after settling
    distances = np.linalg.norm(sim3.tcp_ref[:, None, :3] - sim3.waypoints[None], axis=2)
    assert np.all(distances.min(axis=0) < 0.05)


def test_sim3_closed_loop_tracking_and_torques(sim3):
    metrics = sim3.metrics()
    # Measured: 3.6e-5 rad and 2.8e-5 m; peak torque 0.28 of the effort limit (elbow).
    assert metrics.tracking_error_joint_max_rad < 1e-4
    assert metrics.tracking_error_tcp_max_m < 1e-4
    assert max(metrics.peak_torque_fraction) < 1.0


def test_sim3_acceleration_is_continuous_in_the_diagram():
    # A jump in qdd keeps its size when the log period halves; a continuous qdd halves its
    # largest step-to-step change. (The loggers sample the plant's steps: the plant's step halves too.)
    steps = {}
    for period in (1e-3, 5e-4):
        planner = make_planner(load_scenario(DIAGRAMS / "pajak.yaml", "sim3"))
        plant_config = default_plant_config()
        plant_config.time_step = period
        result = simulate(planner, log_period=period, plant_config=plant_config, settle_time=0.0)
        after_start = result.t > 0.01
        steps[period] = np.abs(np.diff(result.qdd_ref[after_start], axis=0)).max()
    assert steps[5e-4] / steps[1e-3] < 0.65


def test_unreachable_goal_stops_with_the_reason_and_keeps_the_log(tmp_path):
    pose = robot.task_pose(Q0)
    goal = pose.copy()
    shoulder = np.array([0.0, 0.0, robot.DH_D[0]])
    direction = (pose[:3] - shoulder) / np.linalg.norm(pose[:3] - shoulder)
    goal[:3] = shoulder + 1.29 * direction  # inside 1.3 m, but not reachable with this orientation
    config = P.PajakConfig(waypoints=goal[None], limit_velocity=True, limit_acceleration=False, stall_time=1.0)
    with pytest.raises(PlanningError, match="waypoint 0 cannot be reached") as found:  # the preflight, before the motion
        simulate(P.PajakPlanner(config, Q0), max_duration=20.0)
    assert found.value.cause is Cause.UNREACHABLE and found.value.field == ("waypoints", 0)
    result = simulate(P.PajakPlanner(config, Q0), max_duration=20.0, preflight=False)  # the run finds it too
    assert not result.succeeded
    message = result.failure.message
    assert "PlanningError" in message and "no progress" in message and "q = " in message
    assert result.failure.cause == "stall" and result.failure.configuration is not None
    assert len(result.t) > 1000 and np.all(np.isfinite(result.qdd_ref))
    assert np.abs(result.qd_ref).max() <= 1.05 + TOL
    saved = SimulationResult.load(result.save(tmp_path))
    assert saved.failure == result.failure and len(saved.t) == len(result.t)


def test_bad_task_names_the_field():
    with pytest.raises(ValueError, match="vartheta"):
        P.PajakPlanner(P.paper_parameters(3, vartheta=0.7), Q0)
    with pytest.raises(ValueError, match="waypoint 0 cannot be reached.*out of reach"):  # the IK, in the preflight
        P.PajakPlanner(P.PajakConfig(waypoints=[[1.5, 0, 0.2, np.pi, 0, 0]]), Q0).preflight()
    with pytest.raises(ValueError, match="q_initial"):
        P.PajakPlanner(P.paper_parameters(3), Q0[:5])


def test_a_task_done_at_the_start_is_refused_at_its_waypoints(tmp_path):
    """Was "RuntimeError: Segment number 0 out of range [0, 0)" (an empty plan) from the cell check."""
    from drake_traj import cli
    from drake_traj.robots import UR10E

    start = UR10E.tcp_pose(Q0).tolist()
    planner = P.PajakPlanner(P.PajakConfig(waypoints=[start]), Q0)
    with pytest.raises(PlanningError, match=r"^the task has nothing to do: the start pose is already the only "
                                            r"waypoint") as caught:
        planner.plan()
    assert caught.value.field == ("waypoints",) and caught.value.cause is Cause.INVALID
    path = tmp_path / "start.yaml"
    path.write_text(f"name: start\nrobot: ur10e\nplanner: !PajakConfig\n  waypoints:\n    - {start}\n")
    with pytest.raises(PlanningError, match=rf"^{path}, line 5, column 5: planner.waypoints: the task has nothing to do"):
        simulate(load_scenario(path))
    assert cli.main(["run", str(path), "--out", str(tmp_path / "out")]) == 2


class SpeedStep(LeafSystem):
    """1 until ``at`` [s], then ``value``: a speed override stepping down mid-motion."""

    def __init__(self, at: float, value: float):
        super().__init__()
        self.DeclareVectorOutputPort("override", 1, lambda context, out: out.SetAtIndex(
            0, 1.0 if context.get_time() < at else value))


def test_speed_override_slows_the_planner_within_its_limits():
    builder = DiagramBuilder()
    planner = P.PajakPlanner(P.paper_parameters(3), Q0)
    station = builder.AddSystem(build_station(planner))
    step = builder.AddSystem(SpeedStep(2.0, 0.5))
    builder.Connect(step.get_output_port(), station.GetInputPort("speed_override"))
    simulator = Simulator(builder.Build())
    ApplySimulatorConfig(default_simulator_config(), simulator)
    failure = run_station(simulator, station, settle_time=0.5)
    assert failure is None
    result = SimulationResult.from_station(station, station.GetMyContextFromRoot(simulator.get_context()))
    # the override re-times the law's planned path: the same path (the reference within 1e-6 rad of
    # the plan's path), completed later than without the override (5.332 s), at half speed after
    # the step (the scaling is the law's c times the clock's rate: half the plan's at the same point)
    plan = planner.plan()
    grid = np.linspace(0.0, plan.end_time(), 200_001)
    planned = plan.vector_values(grid).T
    nearest = cKDTree(planned).query(result.q_ref)[0]
    assert nearest.max() < 1e-4  # the grid's spacing bounds it (measured 3.9e-6 rad)
    assert result.duration > 5.332 + 0.3 * (5.332 - 2.0)
    assert np.linalg.norm(result.tcp_ref[-1, :3] - P.paper_parameters(3).waypoints[-1, :3]) < 1e-3
    late = result.t > 4.0
    law_time = np.array([cKDTree(planned).query(q)[1] for q in result.q_ref[late][::200]]) * grid[1]
    law_scaling = np.array([planner.law.scaling_at(tau) for tau in law_time])
    np.testing.assert_allclose(result.scaling[late][::200], 0.5 * law_scaling, atol=0.02)
    # the limits and the continuity of q̈ hold through the step
    assert np.abs(np.diff(result.qdd_ref[1:], axis=0)).max() < 0.1
    assert np.abs(result.qdd_ref).max() <= 1.40 + TOL and np.abs(result.qd_ref).max() <= 1.05 + TOL
    assert np.abs(np.diff(result.qdd_ref[result.t > 0.01], axis=0)).max() <= 0.1
