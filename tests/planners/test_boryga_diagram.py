"""Boryga's loop on the UR10e and on the paper's three robots, in the closed loop."""

import numpy as np
import pytest

from drake_traj.bench.soak_tasks import draw_task
from drake_traj.errors import DrakeTrajError, SingularConfigurationError
from drake_traj.robots import UR10E, boryga_robots
from drake_traj.robots import ur10e as robot
from drake_traj.station import simulate
from drake_traj.robots import get_robot
from drake_traj.planners import make_planner as make_planner_from_config
from drake_traj.planners.boryga import BorygaConfig, RobotLoopLaw, joint_speed_cap, paper_loop_placement, plan_loop_path
from drake_traj.scenario import load_scenario, make_planner

from conftest import DIAGRAMS

NOMINAL_DURATION = 0.81368  # t_e of the paper's example (docs/papers.md)


def run(name):
    scenario = load_scenario(DIAGRAMS / "boryga_loop.yaml", name)
    planner = make_planner(scenario)
    result = simulate(planner, name=scenario.name, robot=get_robot(scenario.robot), settle_time=0.1)
    return planner, result


@pytest.fixture(scope="module")
def ur10e_run():
    return run("ur10e")


def test_ur10e_traces_the_loop_in_a_plane_at_fixed_orientation(ur10e_run):
    planner, result = ur10e_run
    assert result.succeeded
    plan = planner.law.plan
    # The clock runs at the constant rate c: the TCP is at the plan's point for tau = c t.
    c = planner.speed_cap
    np.testing.assert_allclose(result.scaling, c, rtol=1e-12)
    position = plan.sample(np.minimum(c * result.t, plan.duration))[0]
    # The logged reference is the law integrated over one 1 ms RK2 step from the law's state:
    # 2e-6 m off it where the acceleration jumps by v²/R = 7 m/s² (the arc's ends), 1e-9 elsewhere.
    np.testing.assert_allclose(result.tcp_ref[:, :3], position, atol=5e-6)
    np.testing.assert_allclose(robot.wrap_angle(result.tcp_ref[:, 3:] - result.tcp_ref[0, 3:]), 0, atol=1e-9)  # fixed
    np.testing.assert_allclose(result.tcp_ref[:, 2], result.tcp_ref[0, 2], atol=1e-9)  # a horizontal plane
    np.testing.assert_allclose(result.q_ref[0], robot.HOME, atol=1e-9)  # B is the flange at q_initial


def test_ur10e_loop_is_slowed_into_its_joint_limits(ur10e_run):
    planner, result = ur10e_run
    # Unscaled, the loop's v_max^2/R = 6.99 m/s^2 needs far more than 1.40 rad/s^2 at the joints.
    assert planner.peaks["qdd"].max() > 1.40
    c = planner.speed_cap
    assert c == pytest.approx(np.sqrt(1.40 / planner.peaks["qdd"].max()), rel=1e-12)
    assert result.duration == pytest.approx(NOMINAL_DURATION / c, abs=2e-3)
    assert np.abs(result.qdd_ref).max() <= 1.40 * (1 + 1e-6)
    assert np.abs(result.qd_ref).max() <= 1.05
    assert np.abs(result.qdd_ref).max() == pytest.approx(1.40, rel=1e-3)  # the cap is tight
    assert result.metrics().tracking_error_tcp_max_m < 1e-4


@pytest.mark.parametrize("name", boryga_robots.ROBOT_NAMES)
def test_paper_robots_trace_the_placed_loop(name):
    planner, result = run(name)
    assert result.succeeded
    assert planner.speed_cap == 1.0  # within the robots' velocity limits, no acceleration limit set
    assert result.duration == pytest.approx(NOMINAL_DURATION, abs=2e-3)
    placement = paper_loop_placement(name)
    position = placement.plan().sample(np.minimum(result.t, NOMINAL_DURATION))[0]
    # The logged reference is the law integrated over one 1 ms RK2 step from the law's state:
    # 2e-6 m off it where the acceleration jumps by v²/R = 7 m/s² (the arc's ends), 1e-9 elsewhere.
    np.testing.assert_allclose(result.tcp_ref[:, :3], position, atol=5e-6)
    np.testing.assert_allclose(result.tcp[-1, :3], placement.E, atol=1e-4)  # measured, at rest at E
    assert np.all(np.abs(result.qd_ref) <= np.asarray(get_robot(name).velocity_limit))


def test_speed_cap_is_one_when_the_law_is_within_limits():
    q0 = np.asarray(robot.HOME)
    start = robot.task_pose(q0)
    plan = plan_loop_path(start[:3], start[:3] + [0.04, 0.03, 0], start[:3] + [0.04, 0, 0], 0.01, delta=0.02)
    law = RobotLoopLaw(plan, UR10E, q0)
    cap, peaks = joint_speed_cap(law, [3.0] * 6, [50.0] * 6)
    assert cap == 1.0 and peaks["qd"].max() < 3.0


def test_a_loop_through_a_singularity_is_refused_where_the_ik_jumps():
    """Soak task puma560 / boryga / 3: the loop passes the PUMA's elbow singularity, where its IK
    flips branch (joint 3 jumps 2.94 rad between two knots 2 ms apart). It was planned at
    1.39e4 s (the interpolation across the jump slowed to the limits) and refused as too long;
    now refused as singular, naming the law times and the joint."""
    scenario = draw_task("puma560", "boryga", 3).scenario
    with pytest.raises(SingularConfigurationError, match=r"between law times 1.376 and 1.378 s .* joint 3 jumps by "
                                                        r"-2.94 rad .* singularity of the puma560"):
        make_planner(scenario)


def test_a_loop_whose_joint_passes_half_a_turn_from_the_start_follows_it():
    """Soak task ur3e / boryga / 39: joint 4 passes half a turn from its start. The UR's IK of each
    knot was the solution nearest the start, so joint 4 jumped a whole turn (planned at 2.6e4 s,
    refused as too long); each knot now continues from the one before: every step between knots
    < 0.05 rad, the plan 21.3 s long."""
    planner = make_planner(draw_task("ur3e", "boryga", 39).scenario)
    q = planner.law.sample(planner.law.knots)[0]
    assert np.max(np.abs(np.diff(q, axis=0))) < 0.05
    assert np.max(np.abs(q[:, 3] - q[0, 3])) > np.pi and 21.0 < planner.planned_duration() < 21.5


class _TurnedBack(type(UR10E)):
    """The UR10e with its wrist 3 turned back by a whole turn where the tool is past x = ``beyond``
    [m] (as an IK keeping a joint in its range would): the law sees a joint jump of 2 pi."""

    beyond = 0.0

    def point_ik(self, points, reference):
        q = super().point_ik(points, reference)
        q[np.asarray(points).reshape(-1, 3)[:, 0] > self.beyond, 5] -= 2 * np.pi
        return q


def test_a_loop_whose_joint_is_turned_back_a_whole_turn_is_refused_for_its_range():
    q0 = np.asarray(robot.HOME)
    start = UR10E.tool_position(q0)
    plan = plan_loop_path(start, start + [0.08, 0.03, 0], start + [0.08, 0, 0], 0.05, delta=0.02)
    turned = _TurnedBack()
    turned.beyond = start[0] + 0.04
    with pytest.raises(DrakeTrajError, match="joint 6 jumps by -6.28 rad .* more than the joint's range") as refused:
        RobotLoopLaw(plan, turned, q0)
    assert refused.value.cause == "joint range"


def test_bad_loop_scenarios_name_the_reason(tmp_path):
    text = (DIAGRAMS / "boryga_loop.yaml").read_text()
    text = "scara:" + text.split("\nscara:")[1].split("\ncartesian:")[0]  # the scara variant alone
    path = tmp_path / "bad.yaml"
    path.write_text(text.replace("    delta: 0.02", "    delta: 0.02\n    B: [0.5, 0.5, 1.0]\n    M: [0.54, 0.53, 1.0]\n    E: [0.54, 0.5, 1.0]"))
    with pytest.raises(ValueError, match="out of reach of the scara"):  # the paper's own placement (docs/papers.md)
        make_planner(load_scenario(path))
    path.write_text(text.replace("    v_max: 0.25", "    v_max: -0.25"))
    with pytest.raises(ValueError, match="v_max"):
        make_planner(load_scenario(path))
    path.write_text(text.replace("robot: scara", "robot: puma"))
    with pytest.raises(ValueError, match="robot must be one of"):
        load_scenario(path)


def test_cli_writes_the_loop_path_figure(tmp_path):
    from drake_traj import cli

    assert cli.main(["run", str(DIAGRAMS / "boryga_loop.yaml"), "--variant", "cartesian", "--out", str(tmp_path)]) == 0
    for stem in ("loop_path", "joints", "tcp_path"):
        assert (tmp_path / f"{stem}.png").stat().st_size > 10_000


def random_loops(count: int, seed: int = 11) -> list[BorygaConfig]:
    """Seeded loops of a user's own on the UR10e: B at the tool at home, M and E random steps of up
    to 0.3 m (0.09 m in z), random Δ (5-50 mm) and path speed (0.05-0.5 m/s)."""
    rng = np.random.default_rng(seed)
    tool = UR10E.tool_position(UR10E.home_configuration)
    loops = []
    for _ in range(count):
        corner = tool + rng.uniform(-0.3, 0.3, 3) * [1, 1, 0.3]
        end = corner + rng.uniform(-0.3, 0.3, 3) * [1, 1, 0.3]
        loops.append(BorygaConfig(B=tool.tolist(), M=corner.tolist(), E=end.tolist(),
                                  delta=float(rng.uniform(0.005, 0.05)), v_max=float(rng.uniform(0.05, 0.5))))
    return loops


def test_a_users_loop_keeps_the_ur10es_joint_move_limits_at_every_instant():
    # no limits given: the UR10e's joint-move limits (1.05 rad/s, 1.40 rad/s²; with none, 3 of 12
    # such loops drove a joint into its torque limit). The cap uses the law's exact peaks: a
    # sampled peak let loops 6 and 13 of these exceed 1.40 rad/s² by up to 0.07 %.
    loops = random_loops(14)
    for index in (0, 3, 6, 13):
        config = loops[index]
        planner = make_planner_from_config(config, UR10E, UR10E.home_configuration)
        np.testing.assert_array_equal(planner.acceleration_limit, 1.40)
        np.testing.assert_array_equal(planner.velocity_limit, 1.05)
        c = planner.speed_cap
        tau = np.arange(0.0, planner.law.duration, 1e-3 * c)  # the reference's 1 ms samples
        rates = np.array([np.concatenate(planner.law.rates_at(t)) for t in tau])
        assert np.abs(rates[:, :6]).max() * c <= 1.05 * (1 + 1e-9), index
        assert np.abs(rates[:, 6:]).max() * c**2 <= 1.40 * (1 + 1e-9), index
        assert c == 1.0 or max(np.abs(rates[:, :6]).max() * c / 1.05, np.abs(rates[:, 6:]).max() * c**2 / 1.40) > 0.999


def test_a_users_loop_runs_within_the_limits_and_ends_at_e():
    config = random_loops(14)[13]
    result = simulate(make_planner_from_config(config, UR10E, UR10E.home_configuration), settle_time=0.1)
    assert result.succeeded, result.failure
    metrics = result.metrics()
    assert metrics.peak_acceleration_fraction <= 1 + 1e-9 and metrics.peak_velocity_fraction <= 1 + 1e-9
    np.testing.assert_allclose(result.tcp[-1, :3], config.E, atol=1e-6)


def test_the_hermite_laws_interval_polynomials_and_exact_peaks():
    law = make_planner_from_config(random_loops(14)[13], UR10E, UR10E.home_configuration).law
    mid, half, velocity, acceleration = law.interval_polynomials()
    rng = np.random.default_rng(5)
    for k in rng.integers(0, len(mid), 20):
        for sigma in (-1.0, rng.uniform(-1, 1), 1.0 - 1e-9):
            qd, qdd = law.rates_at(mid[k] + sigma * half[k])
            np.testing.assert_allclose(np.polynomial.polynomial.polyval(sigma, velocity[:, k]), qd, rtol=1e-9, atol=1e-9)
            np.testing.assert_allclose(np.polynomial.polynomial.polyval(sigma, acceleration[:, k]), qdd, rtol=1e-7, atol=1e-7)
    peak_qd, peak_qdd = law.peak_rates()
    dense = np.array([np.concatenate(law.rates_at(t)) for t in np.linspace(0.0, law.duration, 100001)])
    assert np.all(peak_qd >= np.abs(dense[:, :6]).max(axis=0)) and np.all(peak_qdd >= np.abs(dense[:, 6:]).max(axis=0))
    np.testing.assert_allclose(peak_qdd, np.abs(dense[:, 6:]).max(axis=0), rtol=1e-5, atol=1e-9)  # and no larger than the law's


def test_the_loop_figure_shows_the_motion_as_run(ur10e_run):
    # the UR10e runs the loop at the speed cap c: the figure's time axis ends at the run's finish
    # (t = τ / c) and its speed peaks at v_max c, not at the path's own v_max
    planner, result = ur10e_run
    c = planner.speed_cap
    assert c < 0.31
    figure = planner.figures()["loop_path"]
    speed = next(line for line in figure.axes[1].lines if line.get_label() == "speed")
    assert speed.get_xdata()[-1] == pytest.approx(planner.law.duration / c, rel=1e-12)
    assert speed.get_xdata()[-1] == pytest.approx(result.duration, abs=2e-3)
    assert max(speed.get_ydata()) == pytest.approx(0.25 * c, rel=1e-3)
    assert "slowed to c = 0.3023" in figure.get_suptitle()
