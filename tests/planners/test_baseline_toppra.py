"""Time-optimal baseline (Drake's Toppra along a geometric path): drake_traj.planners.baseline_toppra."""

import numpy as np
import pytest

from pydrake.trajectories import PiecewisePolynomial

from drake_traj.planners.baselines import toppra as baseline_toppra
from drake_traj.planners.baselines.toppra import (
    ToppraLaw,
    ToppraPlanner,
    exact_peak_fractions,
    geometric_path_from_samples,
    time_optimal_along_path,
    within_limits,
)
from drake_traj.planners.quintic import plan_synchronized_quintic, quintic_profile

KV, KA = 1.05, 1.40  # Pająk 2024's joint-move limits [rad/s, rad/s^2]
Q0 = np.array([-np.pi / 2, -np.pi / 2, -3 * np.pi / 4, -np.pi / 4, np.pi / 2, np.pi / 4])
Q1 = Q0 + np.array([1.6, -0.7, 0.9, 0.4, -0.2, 0.1])


def trapezoid_minimum_time(displacement, velocity_limit, acceleration_limit) -> float:
    """Analytic rest-to-rest minimum time along the straight line q0 + D u, u in [0, 1].

    Every joint moves in proportion, so u_dot <= min_j K_v/|D_j| and |u_ddot| <= min_j K_a/|D_j|:
    the bang-bang (trapezoid or triangle) profile of the leading joint.
    """
    d = np.abs(displacement)
    moving = d > 0
    v = np.min(velocity_limit / d[moving])
    a = np.min(acceleration_limit / d[moving])
    return 1.0 / v + v / a if v * v / a < 1.0 else 2.0 * np.sqrt(1.0 / a)


def curved_samples(count=2000):
    """A smooth curved joint path (a tilted loop through three joints, others drifting)."""
    u = np.linspace(0.0, 1.0, count)
    q = np.tile(Q0, (count, 1))
    q[:, 0] += 1.2 * np.sin(np.pi * u)
    q[:, 1] += 0.8 * (1.0 - np.cos(1.5 * np.pi * u))
    q[:, 2] += 1.0 * u
    q[:, 3] += 0.3 * np.sin(2 * np.pi * u)
    return q


def sampled_rates(trajectory, duration, count=8001):
    t = np.linspace(0.0, duration, count)
    qd = np.array([trajectory.EvalDerivative(x, 1).ravel() for x in t])
    qdd = np.array([trajectory.EvalDerivative(x, 2).ravel() for x in t])
    return qd, qdd


def test_straight_line_is_the_bang_bang_optimum():
    for q_goal, kv, ka in ((Q1, KV, KA), (Q0 + 0.2, KV, KA), (Q1, np.array([1, 1, 2, 2, 3, 3.0]), 2.0)):
        # Repeats at both ends (a planner standing still) must be dropped.
        samples = np.vstack([np.tile(Q0, (5, 1)), np.linspace(Q0, q_goal, 50), np.tile(q_goal, (5, 1))])
        path = geometric_path_from_samples(samples)
        duration, trajectory = time_optimal_along_path(path, kv, ka)
        expected = trapezoid_minimum_time(q_goal - Q0, kv, ka)
        assert duration == pytest.approx(expected, rel=0.01)
        np.testing.assert_allclose(trajectory.value(trajectory.end_time()).ravel(), q_goal, atol=1e-9)
        np.testing.assert_allclose(trajectory.value(trajectory.start_time()).ravel(), Q0, atol=1e-9)


def test_curved_path_respects_limits_and_beats_other_timings():
    samples = curved_samples()
    path = geometric_path_from_samples(samples)
    # The spline passes through the samples (knots are samples; between, it stays close).
    s = np.linspace(path.start_time(), path.end_time(), 400)
    deviation = max(np.min(np.linalg.norm(samples - path.value(x).ravel(), axis=1)) for x in s)
    assert deviation < 2e-3

    duration, trajectory = time_optimal_along_path(path, KV, KA)
    qd, qdd = sampled_rates(trajectory, duration)
    velocity_ratio = np.abs(qd).max() / KV
    acceleration_ratio = np.abs(qdd).max() / KA
    print(f"curved path: T* = {duration:.4f} s, worst |qd|/Kv = {velocity_ratio:.4f}, "
          f"worst |qdd|/Ka = {acceleration_ratio:.4f}")
    assert velocity_ratio <= 1.01
    assert acceleration_ratio <= 1.05  # Toppra constrains its discrete grid only
    assert max(velocity_ratio, acceleration_ratio) > 0.95  # and it is tight somewhere

    # Another feasible timing of the same path: the quintic law s(t) = L r(t / T) (Benotsmane et al.'s
    # time law), with T the smallest value meeting both limits (qd ~ 1/T, qdd ~ 1/T^2).
    length = path.end_time()
    dq = path.MakeDerivative(1)
    ddq = path.MakeDerivative(2)
    u = np.linspace(0.0, 1.0, 4001)
    r, dr, ddr = quintic_profile(u)
    speed = np.array([dq.value(length * x).ravel() * length * y for x, y in zip(r, dr)])  # * 1/T
    accel = np.array([ddq.value(length * x).ravel() * (length * y) ** 2 + dq.value(length * x).ravel() * length * z
                      for x, y, z in zip(r, dr, ddr)])  # * 1/T^2
    quintic_time = max(np.abs(speed / KV).max(), np.sqrt(np.abs(accel / KA).max()))
    print(f"curved path: quintic timing {quintic_time:.4f} s")
    assert duration < quintic_time


def test_shorter_than_the_synchronized_quintic_on_a_two_point_path():
    plan = plan_synchronized_quintic(Q0, [Q1], KV, KA)
    duration, _ = time_optimal_along_path(geometric_path_from_samples(np.array([Q0, Q1])), KV, KA)
    print(f"two-point path: T* = {duration:.4f} s, quintic {plan.duration:.4f} s")
    assert duration < plan.duration


def test_law_follows_the_trajectory_half_a_period_late_and_rests_outside():
    path = geometric_path_from_samples(curved_samples(300))
    duration, trajectory = time_optimal_along_path(path, KV, KA)
    law = ToppraLaw(trajectory)
    h = law.sample_period
    assert duration + h < law.duration <= duration + 2 * h  # T* rounded up to a node, plus the average
    np.testing.assert_allclose(law.q_start, Q0, atol=1e-9)
    t = np.linspace(0.0, law.duration, 2001)
    q, qd, qdd = law.sample(t)
    for k in range(0, len(t), 50):  # rates_at is the law sample() integrates
        rate, acceleration = law.rates_at(t[k])
        np.testing.assert_allclose(rate, qd[k], atol=1e-12)
        np.testing.assert_allclose(acceleration, qdd[k], atol=1e-12)
    # The trajectory, averaged over the last period: h/2 late, within O(h^2) in position.
    late = np.clip(t - h / 2, 0.0, duration)
    np.testing.assert_allclose(q, [trajectory.value(x).ravel() for x in late], atol=1e-6)
    np.testing.assert_allclose(qd, [trajectory.EvalDerivative(x, 1).ravel() for x in late], atol=2e-3)
    np.testing.assert_allclose(q[-1], law.q_end, atol=1e-6)
    # An average does not overshoot: the law keeps within the trajectory's peaks.
    dense_qd, dense_qdd = sampled_rates(trajectory, duration, count=int(duration / 1e-4) + 1)
    assert np.abs(qd).max() <= np.abs(dense_qd).max() + 1e-9
    assert np.abs(qdd).max() <= np.abs(dense_qdd).max() + 1e-6
    # q, qd, qdd are mutually consistent and qdd is continuous (a step becomes a ramp over h).
    np.testing.assert_allclose(np.gradient(q, t, axis=0)[1:-1], qd[1:-1], atol=2e-3)
    assert np.abs(np.diff(qdd, axis=0)).max() <= 2 * np.abs(dense_qdd).max() * (t[1] - t[0]) / h + 1e-9
    for tau in (-0.1, law.duration + 0.1):
        rate, acceleration = law.rates_at(tau)
        assert not rate.any() and not acceleration.any()
    assert q.shape == (len(t), 6)


def test_errors_are_clear():
    with pytest.raises(ValueError, match="at least 2 distinct"):
        geometric_path_from_samples(np.tile(Q0, (10, 1)))
    with pytest.raises(ValueError, match="shape"):
        geometric_path_from_samples(Q0)
    path = geometric_path_from_samples(np.array([Q0, Q1]))
    with pytest.raises(ValueError, match="velocity_limit"):
        time_optimal_along_path(path, 0.0, KA)
    with pytest.raises(ValueError, match="acceleration_limit"):
        time_optimal_along_path(path, KV, [1.0, 1.0, -1.0, 1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="grid_points"):
        time_optimal_along_path(path, KV, KA, grid_points=[0.0, 0.1])


def test_toppra_failure_is_reported(monkeypatch):
    class NoSolution:
        def __init__(self, *args):
            pass

        AddJointVelocityLimit = AddJointAccelerationLimit = lambda self, *args: None

        def SolvePathParameterization(self):
            return None

    monkeypatch.setattr(baseline_toppra, "Toppra", NoSolution)
    path = geometric_path_from_samples(np.array([Q0, Q1]))
    with pytest.raises(ValueError, match="Toppra found no feasible"):
        time_optimal_along_path(path, KV, KA, grid_points=50)


def test_planner_runs_in_the_closed_loop():
    from drake_traj.station import simulate

    path = geometric_path_from_samples(np.array([Q0, Q0 + np.array([0.6, -0.4, 0.3, 0.2, 0.0, 0.1])]))
    duration, trajectory = time_optimal_along_path(path, KV, KA)
    planner = ToppraPlanner(ToppraLaw(trajectory), KV, KA)
    result = simulate(planner, settle_time=0.1, max_duration=10.0)
    assert result.succeeded, result.failure
    assert result.duration == pytest.approx(duration, abs=0.02)
    metrics = result.metrics()
    assert metrics.peak_velocity_fraction <= 1.01
    assert metrics.peak_acceleration_fraction <= 1.05
    np.testing.assert_allclose(result.q_ref[-1], trajectory.value(trajectory.end_time()).ravel(), atol=1e-5)


def test_faster_than_the_pajak_run_on_its_own_path():
    from drake_traj.station import simulate
    from drake_traj.scenario import load_scenario, make_planner

    result = simulate(make_planner(load_scenario("diagrams/pajak.yaml", "sim3")))
    assert result.succeeded, result.failure
    samples = result.q_ref[result.t <= result.duration]
    duration, trajectory = time_optimal_along_path(geometric_path_from_samples(samples), KV, KA)
    qd, qdd = sampled_rates(trajectory, duration)
    print(f"pajak_sim3 path: T* = {duration:.4f} s vs the planner's {result.duration:.4f} s "
          f"(worst |qd|/Kv = {np.abs(qd).max() / KV:.4f}, |qdd|/Ka = {np.abs(qdd).max() / KA:.4f})")
    assert duration < result.duration
    np.testing.assert_allclose(trajectory.value(trajectory.end_time()).ravel(), samples[-1], atol=1e-6)


def dense_peak_fractions(trajectory, velocity_limit, acceleration_limit, period=1e-5):
    """(peak |qd_j| / limit_j, peak |qdd_j| / limit_j) over samples ``period`` [s] apart."""
    t = np.linspace(trajectory.start_time(), trajectory.end_time(),
                    int(np.ceil((trajectory.end_time() - trajectory.start_time()) / period)) + 1)
    qd = np.abs(trajectory.MakeDerivative(1).vector_values(t)).max(axis=1)
    qdd = np.abs(trajectory.MakeDerivative(2).vector_values(t)).max(axis=1)
    return np.max(qd / velocity_limit), np.max(qdd / acceleration_limit)


# per-joint limits [rad/s, rad/s^2] for the C^1 path below
KV_JOINTS, KA_JOINTS = np.array([1.0, 1.0, 1.2, 1.2, 1.5, 1.5]), np.array([1.4, 1.4, 2.0, 2.0, 3.0, 3.0])


def shape_preserving_path():
    """A C^1 cubic (Fritsch-Carlson) through four joint waypoints, in arc length: q'' jumps at its knots."""
    knots = np.array([Q0, Q0 + [0.6, -0.3, 0.4, 0.2, 0.1, 0.0], Q0 + [0.9, 0.2, 0.7, -0.3, 0.2, 0.4], Q1])
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(knots, axis=0), axis=1))])
    return PiecewisePolynomial.CubicShapePreserving(arc, knots.T, zero_end_point_derivatives=False)


def test_exact_peaks_are_the_sampled_peaks():
    # a C^2 spline (geometric_path_from_samples) and a C^1 one
    kv, ka = KV_JOINTS, KA_JOINTS
    for path in (geometric_path_from_samples(curved_samples(300)), shape_preserving_path()):
        _, trajectory = time_optimal_along_path(path, kv, ka)
        exact = exact_peak_fractions(trajectory, kv, ka)
        sampled = dense_peak_fractions(trajectory, kv, ka)
        print(f"exact peaks {exact}, sampled every 10 us {sampled}")
        # the samples come within what 10 us of motion can change (1.2e-4 at a jump of the C^1
        # path's q''), never above
        np.testing.assert_allclose(exact, sampled, rtol=5e-4)
        assert np.all(np.array(sampled) <= np.array(exact) * (1 + 1e-12))
        assert exact[1] > 1 + 1e-4  # Toppra's timing exceeds the acceleration limit between grid points


def test_within_limits_is_the_least_uniform_stretch():
    _, trajectory = time_optimal_along_path(shape_preserving_path(), KV_JOINTS, KA_JOINTS)
    velocity, acceleration = dense_peak_fractions(trajectory, KV_JOINTS, KA_JOINTS)
    stretch, stretched = within_limits(trajectory, KV_JOINTS, KA_JOINTS)
    assert stretch == pytest.approx(max(velocity, np.sqrt(acceleration)), rel=2e-4)
    assert stretch > 1.01
    assert stretched.end_time() == pytest.approx(stretch * trajectory.end_time(), rel=1e-12)
    np.testing.assert_allclose(stretched.value(stretched.end_time()), trajectory.value(trajectory.end_time()),
                               atol=1e-12)  # the same path
    after = dense_peak_fractions(stretched, KV_JOINTS, KA_JOINTS)
    assert max(after) <= 1 + 1e-6
    assert max(after) >= 1 - 2e-4  # the least stretch: some limit is reached
    # A straight line: Toppra's timing keeps the limits between grid points too, and is kept.
    _, straight = time_optimal_along_path(geometric_path_from_samples(np.array([Q0, Q1])), KV, KA)
    assert within_limits(straight, KV, KA) == (1.0, straight)


def soak_task(seed):
    """(planner config, robot, start [rad], its path, velocity and acceleration limits [rad/s,
    rad/s^2]) of the soak's UR10e Toppra task ``seed``."""
    from drake_traj.bench.soak_tasks import draw_task
    from drake_traj.planners.base import joint_move_limits

    scenario = draw_task("ur10e", "toppra", seed).scenario
    config, robot, q0 = scenario.planner, scenario.robot_with_tool(), scenario.start_configuration()
    path = geometric_path_from_samples(np.vstack([q0, config.path]))
    return config, robot, q0, path, *joint_move_limits(robot, config.velocity_limit, config.acceleration_limit)


@pytest.mark.parametrize("seed", [3, 8, 17, 37])
def test_soak_tasks_plan_within_their_limits(seed):
    """Seeded soak tasks whose plan exceeded its limits (by 1-3.5 % in acceleration) before the
    grid was refined at the path's end and the timing stretched."""
    config, robot, q0, path, _, _ = soak_task(seed)
    planner = baseline_toppra.make(config, robot, q0)
    plan = planner.plan()
    velocity, acceleration = dense_peak_fractions(plan, planner.velocity_limit, planner.acceleration_limit,
                                                  period=1e-4)
    # Toppra's own timing exceeds them; the plan is hardly longer
    optimal, toppra = time_optimal_along_path(path, planner.velocity_limit, planner.acceleration_limit)
    before = dense_peak_fractions(toppra, planner.velocity_limit, planner.acceleration_limit, period=1e-4)
    duration = planner.law.trajectory.end_time()
    print(f"seed {seed}: peaks {before} -> {velocity:.7f}, {acceleration:.7f}; T* {optimal:.4f} s -> "
          f"{duration:.4f} s (stretch {planner.time_stretch:.6f})")
    assert velocity <= 1 + 1e-6 and acceleration <= 1 + 1e-6
    assert before[1] > 1.005
    assert duration == pytest.approx(optimal, rel=2e-3)
    assert max(velocity, acceleration) > 0.99  # still Toppra's (near) time-optimal timing


def test_refined_end_keeps_the_acceleration_limit_there():
    _, _, _, path, kv, ka = soak_task(3)
    optimal, toppra = time_optimal_along_path(path, kv, ka)
    refined_optimal, refined = time_optimal_along_path(path, kv, ka, refine_end=True)
    # three more grid points, all in the last grid interval
    grid, refined_grid = (scaling.vector_values(scaling.get_segment_times()).ravel()
                          for scaling in (toppra.time_scaling(), refined.time_scaling()))
    assert len(refined_grid) == len(grid) + 3
    np.testing.assert_allclose(refined_grid[:len(grid) - 1], grid[:-1], atol=1e-12)
    # the acceleration over the last 50 ms, against the limit: 2 % over before

    def end_fraction(trajectory):
        t = np.linspace(trajectory.end_time() - 0.05, trajectory.end_time(), 5001)
        return np.max(np.abs(trajectory.MakeDerivative(2).vector_values(t)) / ka[:, None])
    print(f"at the end: {end_fraction(toppra):.5f} -> {end_fraction(refined):.5f}; "
          f"T* {optimal:.5f} -> {refined_optimal:.5f} s")
    assert end_fraction(toppra) > 1.02
    assert end_fraction(refined) <= 1 + 1e-4
    assert refined_optimal == pytest.approx(optimal, rel=2e-3)


def test_plain_grid_where_toppra_fails_on_the_refined_one(monkeypatch):
    config, robot, q0, *_ = soak_task(3)
    solve = baseline_toppra.time_optimal_along_path

    def fails_when_refined(*args, refine_end=False, **kwargs):
        if refine_end:
            raise ValueError("Toppra found no feasible time parameterisation of the path")
        return solve(*args, **kwargs)

    monkeypatch.setattr(baseline_toppra, "time_optimal_along_path", fails_when_refined)
    planner = baseline_toppra.make(config, robot, q0)
    plan = planner.plan()
    peaks = dense_peak_fractions(plan, planner.velocity_limit, planner.acceleration_limit, period=1e-4)
    assert max(peaks) <= 1 + 1e-6
    assert planner.time_stretch > 1.01  # the plain grid's 2.3 % over the acceleration limit, stretched away


def test_stretch_errors_are_clear():
    _, trajectory = time_optimal_along_path(geometric_path_from_samples(np.array([Q0, Q1])), KV, KA)
    with pytest.raises(ValueError, match="time_stretch"):
        ToppraPlanner(ToppraLaw(trajectory), KV, KA, time_stretch=0.9)
    # a path of quintic pieces: its q' u + q'' x is no quadratic (the peaks would not be exact)
    samples = curved_samples(6)
    quintic = PiecewisePolynomial.LagrangeInterpolatingPolynomial(np.linspace(0.0, 1.0, 6), samples.T)
    _, trajectory = time_optimal_along_path(quintic, KV, KA, grid_points=50)
    with pytest.raises(ValueError, match="trajectory's path must be a PiecewisePolynomial of degree <= 3"):
        within_limits(trajectory, KV, KA)
