"""Ruckig baseline (drake_traj.planners.baseline_ruckig) on the stop-at-each-waypoint version of
Pająk 2024's task."""

from __future__ import annotations

import numpy as np
import pytest
import ruckig

from drake_traj.robots import ur10e as robot
from drake_traj.planners.baselines.ruckig import RuckigPlanner
from drake_traj.planners.timing import RuckigStopLaw, default_jerk_limit, ruckig_law
from drake_traj.planners.quintic import plan_synchronized_quintic

VELOCITY_LIMIT = 1.05  # rad/s (Pająk 2024)
ACCELERATION_LIMIT = 1.40  # rad/s^2 (Pająk 2024)
JERK_LIMIT = 14.0  # rad/s^3: the default, 10/s times the acceleration limit

# Pająk 2024 (docs/papers.md): q(0) and p1, p2, p3, pf; orientation
# (pi, 0, 3 pi/4) on every pose.
Q_INITIAL = np.array([-np.pi / 2, -np.pi / 2, -3 * np.pi / 4, -np.pi / 4, np.pi / 2, np.pi / 4])
ORIENTATION = [np.pi, 0.0, 3 * np.pi / 4]
POSITIONS = np.array(
    [
        [-0.175, -0.525, 0.730],  # p1
        [-0.175, -0.800, 0.730],  # p2
        [0.275, -0.800, 0.730],  # p3
        [0.275, -0.525, 0.730],  # pf
    ]
)


@pytest.fixture(scope="module")
def waypoints() -> np.ndarray:
    q = [Q_INITIAL]
    for position in POSITIONS:
        q.append(robot.inverse_kinematics(np.concatenate([position, ORIENTATION]), near=q[-1]))
    return np.array(q)


@pytest.fixture(scope="module")
def law(waypoints) -> RuckigStopLaw:
    return RuckigStopLaw(waypoints, VELOCITY_LIMIT, ACCELERATION_LIMIT, JERK_LIMIT)


def _reference_trajectory(q_from, q_to, jerk=JERK_LIMIT):
    """The same segment computed directly with Ruckig (for comparison with at_time)."""
    n = len(q_from)
    otg, inp, trajectory = ruckig.Ruckig(n), ruckig.InputParameter(n), ruckig.Trajectory(n)
    inp.current_position, inp.target_position = list(q_from), list(q_to)
    inp.max_velocity = [VELOCITY_LIMIT] * n
    inp.max_acceleration = [ACCELERATION_LIMIT] * n
    inp.max_jerk = [jerk] * n
    assert otg.calculate(inp, trajectory) == ruckig.Result.Working
    return trajectory


def test_default_jerk_is_ten_per_second_times_acceleration(waypoints):
    assert default_jerk_limit(ACCELERATION_LIMIT) == pytest.approx(JERK_LIMIT)
    default = RuckigStopLaw(waypoints, VELOCITY_LIMIT, ACCELERATION_LIMIT)
    np.testing.assert_array_equal(default.jerk_limit, np.full(6, JERK_LIMIT))
    assert default.duration == pytest.approx(RuckigStopLaw(waypoints, VELOCITY_LIMIT, ACCELERATION_LIMIT, JERK_LIMIT).duration)


def test_segments_end_at_rest_on_their_waypoints(law, waypoints):
    assert law.segment_durations.shape == (4,)
    np.testing.assert_array_equal(law.q_start, waypoints[0])
    ends = law.breakpoints
    q, qd, qdd = law.sample(ends)
    np.testing.assert_allclose(q, waypoints, rtol=0, atol=1e-9)
    np.testing.assert_allclose(qd, 0.0, rtol=0, atol=1e-9)
    np.testing.assert_allclose(qdd, 0.0, rtol=0, atol=1e-9)
    for t in ends:
        qd, qdd = law.rates_at(float(t))
        np.testing.assert_allclose(qd, 0.0, rtol=0, atol=1e-9)
        np.testing.assert_allclose(qdd, 0.0, rtol=0, atol=1e-9)
    # Outside the law: at rest on the first / last waypoint.
    q, qd, _ = law.sample(np.array([-1.0, law.duration + 1.0]))
    np.testing.assert_allclose(q, waypoints[[0, -1]], rtol=0, atol=1e-9)
    assert not np.any(qd)


def test_matches_ruckig_at_time_and_rates_at_matches_sample(law, waypoints):
    t = np.linspace(0.0, law.duration, 2001)
    q, qd, qdd = law.sample(t)
    for k in range(4):
        trajectory = _reference_trajectory(waypoints[k], waypoints[k + 1])
        assert trajectory.duration == pytest.approx(law.segment_durations[k], abs=1e-12)
        start = law.segment_starts[k]
        mask = (t >= start) & (t < start + law.segment_durations[k])
        for i in np.flatnonzero(mask)[::7]:
            expected = np.array(trajectory.at_time(t[i] - start))
            np.testing.assert_allclose(np.stack([q[i], qd[i], qdd[i]]), expected, rtol=0, atol=1e-9)
    for i in range(0, len(t), 13):
        rates = law.rates_at(float(t[i]))
        np.testing.assert_allclose(rates[0], qd[i], rtol=0, atol=1e-9)
        np.testing.assert_allclose(rates[1], qdd[i], rtol=0, atol=1e-9)


def test_limits_hold_on_dense_samples(law):
    dt = 1e-4
    t = np.arange(0.0, law.duration + dt, dt)
    q, qd, qdd = law.sample(t)
    velocity_ratio = np.max(np.abs(qd)) / VELOCITY_LIMIT
    acceleration_ratio = np.max(np.abs(qdd)) / ACCELERATION_LIMIT
    # qdd is continuous and piecewise linear, so |qdd(t + dt) - qdd(t)| <= j_max dt bounds the jerk.
    jerk_ratio_fd = np.max(np.abs(np.diff(qdd, axis=0))) / dt / JERK_LIMIT
    jerk_ratio = np.max(np.abs(law.jerk(t))) / JERK_LIMIT
    print(f"worst ratios: velocity {velocity_ratio:.12f}, acceleration {acceleration_ratio:.12f}, "
          f"jerk {jerk_ratio:.12f} (finite difference {jerk_ratio_fd:.12f})")
    tol = 1 + 1e-9
    assert velocity_ratio <= tol
    assert acceleration_ratio <= tol
    assert jerk_ratio <= tol
    assert jerk_ratio_fd <= tol
    # q is the integral of qd: the pieces are consistent.
    np.testing.assert_allclose(np.diff(q, axis=0), 0.5 * dt * (qd[1:] + qd[:-1]), rtol=0, atol=1e-9)
    # Time-optimal: on every segment some joint reaches the velocity or acceleration limit.
    for k in range(4):
        inside = (t >= law.segment_starts[k]) & (t <= law.segment_starts[k] + law.segment_durations[k])
        reached = max(np.max(np.abs(qd[inside])) / VELOCITY_LIMIT, np.max(np.abs(qdd[inside])) / ACCELERATION_LIMIT)
        assert reached > 0.999


def test_joints_are_synchronised(law, waypoints):
    """Every moving joint leaves its start and reaches its goal together with the others."""
    dt = 1e-4
    for k in range(4):
        start, duration = law.segment_starts[k], law.segment_durations[k]
        t = start + np.arange(0.0, duration + dt / 2, dt)
        q, qd, _ = law.sample(t)
        moving = np.abs(waypoints[k + 1] - waypoints[k]) > 1e-6
        assert moving.sum() >= 3
        for j in np.flatnonzero(moving):
            in_motion = np.flatnonzero(np.abs(qd[:, j]) > 1e-9)
            assert t[in_motion[0]] - start <= 2 * dt, (k, j)
            assert start + duration - t[in_motion[-1]] <= 2 * dt, (k, j)
        for j in np.flatnonzero(~moving):
            np.testing.assert_allclose(q[:, j], waypoints[k, j], rtol=0, atol=1e-9)


def test_not_slower_than_synchronised_quintic(law, waypoints):
    plan = plan_synchronized_quintic(waypoints[0], waypoints[1:], VELOCITY_LIMIT, ACCELERATION_LIMIT)
    quintic = np.array([segment.duration for segment in plan.segments])
    print(f"segment durations: ruckig {np.round(law.segment_durations, 4)}, quintic {np.round(quintic, 4)}; "
          f"totals: ruckig {law.duration:.4f} s, quintic {plan.duration:.4f} s")
    assert len(quintic) == 4
    assert np.all(law.segment_durations <= quintic + 1e-12)
    assert law.duration <= plan.duration


def test_planner_system(law, waypoints):
    planner = RuckigPlanner(law)
    np.testing.assert_array_equal(planner.initial_positions(), waypoints[0])
    np.testing.assert_allclose(planner.task_waypoints(), POSITIONS, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(planner.velocity_limit, np.full(6, VELOCITY_LIMIT))
    context = planner.CreateDefaultContext()
    context.SetTime(0.3)
    qdd, c = planner.evaluate(context)
    assert c == 1.0
    np.testing.assert_allclose(qdd, law.rates_at(0.3)[1], rtol=0, atol=1e-12)
    assert not planner.finished(context)
    context.SetTime(law.duration + 0.01)
    assert planner.finished(context)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((np.zeros(6), 1.0, 1.0, 1.0), "q_waypoints must have shape"),
        ((np.zeros((1, 6)), 1.0, 1.0, 1.0), "q_waypoints must have shape"),
        ((np.zeros((2, 6, 1)), 1.0, 1.0, 1.0), "q_waypoints must have shape"),
        ((np.array([[0.0] * 6, [np.nan] + [0.0] * 5]), 1.0, 1.0, 1.0), r"q_waypoints\[1, 0\] must be finite"),
        ((np.zeros((2, 6)), 0.0, 1.0, 1.0), r"velocity_limit\[0\]"),
        ((np.zeros((2, 6)), 1.0, [1.0] * 5 + [-1.0], 1.0), r"acceleration_limit\[5\]"),
        ((np.zeros((2, 6)), 1.0, 1.0, -2.0), r"jerk_limit\[0\]"),
        ((np.zeros((2, 6)), [1.0] * 5, 1.0, 1.0), "velocity_limit must be a scalar or have shape"),
        ((np.zeros((2, 6)), 1.0, 1.0, np.inf), r"jerk_limit\[0\]"),
    ],
)
def test_invalid_input_raises(args, match):
    with pytest.raises(ValueError, match=match):
        RuckigStopLaw(*args)


_REAL_RUCKIG = ruckig.Ruckig


class _FailingRuckig:
    """Stands in for ruckig.Ruckig: fails on the third call (segment 2)."""

    calls = 0

    def __init__(self, dofs):
        self._real = _REAL_RUCKIG(dofs)

    def calculate(self, inp, trajectory):
        type(self).calls += 1
        if type(self).calls == 3:
            return ruckig.Result.ErrorExecutionTimeCalculation
        return self._real.calculate(inp, trajectory)


def test_ruckig_error_names_the_segment(monkeypatch, waypoints):
    _FailingRuckig.calls = 0
    monkeypatch.setattr(ruckig_law.ruckig, "Ruckig", _FailingRuckig)
    with pytest.raises(ValueError, match=r"segment 2 .*ErrorExecutionTimeCalculation"):
        RuckigStopLaw(waypoints, VELOCITY_LIMIT, ACCELERATION_LIMIT)


def test_ruckig_exception_becomes_value_error(monkeypatch, waypoints):
    class Raising:
        def __init__(self, dofs):
            pass

        def calculate(self, inp, trajectory):
            raise ruckig.RuckigError("boom")

    monkeypatch.setattr(ruckig_law.ruckig, "Ruckig", Raising)
    with pytest.raises(ValueError, match="segment 0 .*boom"):
        RuckigStopLaw(waypoints, VELOCITY_LIMIT, ACCELERATION_LIMIT)


def test_repeated_waypoint_is_a_zero_duration_segment(waypoints):
    q = np.vstack([waypoints[:2], waypoints[1:3]])  # q1 twice
    law = RuckigStopLaw(q, VELOCITY_LIMIT, ACCELERATION_LIMIT)
    assert law.segment_durations[1] == 0.0
    t = np.linspace(0.0, law.duration, 501)
    q_s, qd_s, _ = law.sample(t)
    assert np.all(np.isfinite(q_s))
    np.testing.assert_allclose(law.sample(law.duration)[0], waypoints[2], rtol=0, atol=1e-9)
    for i in range(0, 501, 25):
        np.testing.assert_allclose(law.rates_at(float(t[i]))[0], qd_s[i], rtol=0, atol=1e-9)
