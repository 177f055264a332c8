"""Headless closed-loop simulations: the quintic diagram end to end, logging, failure handling."""

import json

import numpy as np
import pytest
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from drake_traj.robots import ur10e as robot
from drake_traj.station import simulate
from drake_traj.planners.quintic import QuinticLaw, QuinticPtpPlanner, plan_synchronized_quintic
from drake_traj.results import ARRAY_NAMES, SimulationResult, joint_style
from drake_traj.scenario import ControllerGains, load_scenario, make_planner

from conftest import DIAGRAMS

LIMIT_TOLERANCE = 1e-6  # relative; the planner evaluates its limited law at every integrator stage


@pytest.fixture(scope="module")
def quintic_result(quintic_run_dir):
    return SimulationResult.load(quintic_run_dir)


@pytest.fixture(scope="module")
def quintic_planner():
    return make_planner(load_scenario(DIAGRAMS / "quintic_ptp.yaml"))


def short_move(**kwargs):
    """A single 1-goal quintic move from Pająk 2024's start (about 1.7 s)."""
    q0 = np.array([-np.pi / 2, -np.pi / 2, -3 * np.pi / 4, -np.pi / 4, np.pi / 2, np.pi / 4])
    plan = plan_synchronized_quintic(q0, q0 + [0.6, -0.3, 0.4, -0.5, 0.3, 0.8], 1.05, 1.40)
    return QuinticPtpPlanner(plan, 1.05, 1.40, **kwargs)


def test_result_files_are_time_major_with_the_contract_names(quintic_run_dir, quintic_result):
    with np.load(quintic_run_dir / "result.npz") as data:
        assert set(ARRAY_NAMES) <= set(data.files)
        rows = len(data["t"])
        for name, width in (("q_ref", 6), ("qd_ref", 6), ("qdd_ref", 6), ("q_meas", 6), ("qd_meas", 6),
                            ("tau", 6), ("tcp", 6)):
            assert data[name].shape == (rows, width), name
        assert data["scaling"].shape == (rows,)
    metrics = json.loads((quintic_run_dir / "metrics.json").read_text())
    assert metrics["succeeded"] and metrics["samples"] == rows
    for stem in ("joints", "tracking", "scaling", "tcp_path"):
        assert (quintic_run_dir / f"{stem}.png").stat().st_size > 10_000


def test_log_grid_is_uniform_at_one_millisecond(quintic_result):
    np.testing.assert_allclose(np.diff(quintic_result.t), 1e-3, atol=1e-12)
    assert quintic_result.t[0] == 0.0


def test_reference_follows_the_closed_form_plan(quintic_result, quintic_planner):
    # Independent of the Simulator: the plan's closed-form q(t), qd(t), qdd(t) on the log grid.
    # The Simulator integrates the reference with fixed-step RK2 at 1 ms (the default): its global
    # error over the 6.2 s motion measured 5.1e-6 rad (q) and 1.3e-6 rad/s (q̇).
    q, qd, qdd = quintic_planner.law.sample(quintic_result.t)
    np.testing.assert_allclose(quintic_result.q_ref, q, atol=1e-5)
    np.testing.assert_allclose(quintic_result.qd_ref, qd, atol=3e-6)
    np.testing.assert_allclose(quintic_result.qdd_ref, qdd, atol=1e-9)
    assert quintic_result.duration == pytest.approx(quintic_planner.law.duration, abs=1e-3)


def test_limits_hold_at_every_logged_sample(quintic_result):
    velocity_ratio = np.abs(quintic_result.qd_ref) / quintic_result.velocity_limit
    acceleration_ratio = np.abs(quintic_result.qdd_ref) / quintic_result.acceleration_limit
    assert velocity_ratio.max() <= 1 + LIMIT_TOLERANCE
    assert acceleration_ratio.max() <= 1 + LIMIT_TOLERANCE
    # The synchronised plan is time-optimal for its limiting joint: the limit is reached.
    assert acceleration_ratio.max() == pytest.approx(1.0, abs=1e-4)
    assert np.all(np.abs(quintic_result.tau) < quintic_result.effort_limit)


def test_pd_loop_tracks_the_reference(quintic_result, quintic_planner):
    metrics = quintic_result.metrics()
    # Measured on this scenario: 3.5e-5 rad and 3.2e-5 m with inverse-dynamics feed-forward.
    assert metrics.tracking_error_joint_max_rad < 5e-5
    assert metrics.tracking_error_tcp_max_m < 5e-5
    np.testing.assert_allclose(quintic_result.q_meas[-1], quintic_planner.law.q_goal, atol=1e-5)
    np.testing.assert_allclose(quintic_result.qd_meas[-1], 0.0, atol=1e-5)


def test_logged_tcp_is_k_of_the_measured_configuration(quintic_result):
    for row in range(0, len(quintic_result.t), 997):
        np.testing.assert_allclose(quintic_result.tcp[row], robot.task_pose(quintic_result.q_meas[row]), atol=1e-12)


def test_gravity_compensation_alone_tracks_worse_than_inverse_dynamics_feedforward():
    with_feedforward = simulate(short_move(), settle_time=0.1).metrics()
    gravity_only = simulate(short_move(), gains=ControllerGains(feedforward_acceleration=False), settle_time=0.1).metrics()
    assert gravity_only.tracking_error_joint_max_rad > 10 * with_feedforward.tracking_error_joint_max_rad
    assert gravity_only.tracking_error_joint_max_rad < 5e-3  # measured 1.05e-3: still a usable PD loop


class PlanFailingAt(QuinticLaw):
    """A quintic plan whose rates raise after law time ``fail_time`` [s] (a stand-in for any
    fault in a planner's law)."""

    def __init__(self, fail_time, plan):
        super().__init__(plan.segments)
        object.__setattr__(self, "fail_time", fail_time)

    def rates_at(self, t):
        if t > self.fail_time:
            raise ValueError("singular configuration (test fault)")
        return super().rates_at(t)


def test_a_run_that_fails_part_way_keeps_its_log_and_the_reason(tmp_path):
    plan = short_move().law
    # no preflight: its plan would meet the fault before the run (a PlanningError, nothing run)
    result = simulate(QuinticPtpPlanner(PlanFailingAt(0.4, plan), 1.05, 1.40), preflight=False)
    assert not result.succeeded
    assert "singular configuration (test fault)" in result.failure.message and "t = 0.4" in result.failure.message
    assert result.failure.cause == "error" and 0.4 <= result.failure.time <= 0.402
    assert 395 <= len(result.t) <= 402 and np.all(np.isfinite(result.q_ref))
    loaded = SimulationResult.load(result.save(tmp_path))
    assert loaded.failure == result.failure
    np.testing.assert_array_equal(loaded.q_ref, result.q_ref)


def test_a_planner_that_never_finishes_is_reported():
    result = simulate(short_move(), max_duration=0.5)
    assert not result.succeeded and "did not finish" in result.failure.message
    assert result.failure.cause == "timeout"
    assert np.isnan(result.duration)


def test_speed_override_slows_the_clock_and_keeps_velocity_continuous():
    builder = DiagramBuilder()
    planner = builder.AddSystem(short_move())
    override = builder.AddSystem(ConstantVectorSource([0.5]))
    builder.Connect(override.get_output_port(), planner.GetInputPort("speed_override"))
    simulator = Simulator(builder.Build())
    context = planner.GetMyContextFromRoot(simulator.get_context())
    times, scalings, accelerations = np.arange(0.0, 1.0001, 1e-3), [], []
    for t in times:
        simulator.AdvanceTo(t)
        scalings.append(planner.GetOutputPort("scaling").Eval(context)[0])
        accelerations.append(planner.GetOutputPort("desired_acceleration").Eval(context).copy())
    c = np.array(scalings)
    # c relaxes from 1 to 0.5 in the form of eq. 18 at 4 /s, c(t) = 0.5 exp(-4 t) + 0.5, behind it
    # by at most the area of the ramp of ċ (20 /s², 100 ms to reach the initial rate of -2 /s),
    # and never faster than the acceleration limits allow.
    assert np.all(np.diff(c) <= 1e-12) and c[0] == 1.0
    np.testing.assert_allclose(c, 0.5 * np.exp(-4.0 * times) + 0.5, atol=0.1)
    assert c[-1] == pytest.approx(0.5 * np.exp(-4.0) + 0.5, abs=0.02)
    # The reference is the law at the clock tau = integral of c (trapezoids on the 1 ms samples).
    tau = np.sum(0.5 * (c[1:] + c[:-1])) * 1e-3
    q, qd, _ = planner.law.sample(tau)
    state = planner.GetOutputPort("desired_state").Eval(context)
    np.testing.assert_allclose(state[:6], q, atol=1e-6)
    np.testing.assert_allclose(state[6:], qd * c[-1], atol=1e-6)
    assert np.abs(np.diff(accelerations, axis=0)).max() < 0.05  # q̈ continuous through the change


def test_speed_override_outside_zero_one_is_rejected():
    builder = DiagramBuilder()
    planner = builder.AddSystem(short_move())
    override = builder.AddSystem(ConstantVectorSource([1.5]))
    builder.Connect(override.get_output_port(), planner.GetInputPort("speed_override"))
    simulator = Simulator(builder.Build())
    with pytest.raises(ValueError, match="speed_override"):
        simulator.AdvanceTo(0.1)


@pytest.mark.parametrize("name", ["quintic_ptp", "boryga_loop_ur10e", "boryga_loop_scara"])
def test_the_ur_controllers_500_hz_works_in_a_scenario(name, tmp_path):
    # plant: {time_step: 0.002} in a scenario file; log_period follows the plant's step.
    from drake_traj.scenario import find_scenario

    path, variant = find_scenario(name)
    scenario = load_scenario(path, variant)
    scenario.plant.time_step = 0.002
    scenario.validate()
    assert scenario.logging_period() == 0.002
    arguments = scenario.station_arguments()
    result = simulate(arguments.pop("planner"), simulator_config=scenario.simulator, settle_time=0.1,
                      max_duration=scenario.max_duration, tracking_tolerance=scenario.tracking_tolerance, **arguments)
    assert result.succeeded, result.failure
    np.testing.assert_allclose(np.diff(result.t), 0.002, atol=1e-12)
    metrics = result.metrics()
    assert metrics.peak_velocity_fraction <= 1 + LIMIT_TOLERANCE and metrics.peak_acceleration_fraction <= 1 + LIMIT_TOLERANCE
    assert metrics.tracking_error_tcp_max_m < 5e-4  # the PD loop at 500 Hz (measured below 0.2 mm)


@pytest.fixture(scope="module")
def sim3_result(default_run_dir):
    return SimulationResult.load(default_run_dir)


def test_every_panel_has_a_legend_and_joints_differ_in_more_than_colour(quintic_result):
    styles = {(joint_style(j)["linestyle"], joint_style(j)["marker"]) for j in range(6)}
    assert len(styles) == 6  # overlapping lines of two joints stay apart without their colours
    for figure in (quintic_result.joint_figure(), quintic_result.tracking_figure(), quintic_result.scaling_figure()):
        for ax in figure.axes:
            assert ax.get_legend() is not None, figure.get_suptitle()
            joints = [line for line in ax.get_lines() if line.get_label().startswith("joint")]
            assert len({(line.get_linestyle(), line.get_marker()) for line in joints}) == len(joints)
    assert quintic_result.tcp_path_figure().legends  # its one panel's legend, beside the 3-D box


def spheres(figure) -> list:
    return [item for item in figure.axes[0].collections if isinstance(item, Poly3DCollection)]


def test_the_tcp_path_shows_the_neighbourhoods_where_the_planner_turns(sim3_result, quintic_result, tmp_path):
    # the Pająk planner turns to the next waypoint inside ϵ = 5 cm of each (eq. 19); not at the
    # last one, where the task ends; the quintic planner passes through its goals: none drawn
    assert sim3_result.waypoint_neighbourhood == 0.05 and len(sim3_result.waypoints) == 4
    figure = sim3_result.tcp_path_figure()
    assert len(spheres(figure)) == 3
    assert "neighbourhood, ϵ = 50 mm" in [text.get_text() for text in figure.legends[0].get_texts()]
    assert np.isnan(quintic_result.waypoint_neighbourhood)
    assert not spheres(quintic_result.tcp_path_figure())
    assert SimulationResult.load(sim3_result.save(tmp_path / "again")).waypoint_neighbourhood == 0.05
