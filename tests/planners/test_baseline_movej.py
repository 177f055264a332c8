"""UR-style MoveJ baseline with radius blending (Pająk 2024, experiment 1)."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from drake_traj.robots import ur10e as robot
from drake_traj.bench.task_sets import joint_waypoints, paper_task
from drake_traj.planners.baselines.movej import (
    MovejBlendLaw,
    MovejPlanner,
    trapezoid_profile,
)

V_LIMIT = robot.DEFAULT_JOINT_MOVE_VELOCITY  # 1.05 rad/s
A_LIMIT = robot.DEFAULT_JOINT_MOVE_ACCELERATION  # 1.40 rad/s^2
PAPER_BLEND_RADIUS = 0.05  # [m]
PAPER_BLEND_ACCELERATION = 2.48  # [rad/s^2], Pająk 2024 Table 3 (measured on the robot)


@pytest.fixture(scope="module")
def waypoints():
    return joint_waypoints(*paper_task())


@pytest.fixture(scope="module")
def stop_law(waypoints):
    return MovejBlendLaw(waypoints, V_LIMIT, A_LIMIT, 0.0)


@pytest.fixture(scope="module")
def blend_law(waypoints):
    return MovejBlendLaw(waypoints, V_LIMIT, A_LIMIT, PAPER_BLEND_RADIUS)


def dense(law, num=20001):
    t = np.linspace(0.0, law.duration, num)
    return (t,) + law.sample(t)


def test_paper_waypoints_reach_the_task_poses(waypoints):
    from drake_traj.planners.pajak import paper_initial_configuration, paper_parameters

    assert waypoints.shape == (5, 6)
    np.testing.assert_allclose(waypoints[0], paper_initial_configuration())
    for q, pose in zip(waypoints[1:], paper_parameters().waypoints):
        np.testing.assert_allclose(robot.task_pose(q)[:3], pose[:3], atol=1e-9)
    assert np.all(np.abs(np.diff(waypoints, axis=0)) < np.pi)  # continuous IK branch


def test_trapezoid_profile_ends():
    s, sd, sdd = trapezoid_profile(np.array([-1.0, 0.0, 2.0, 3.0]), 0.5, 2.0, 1.0 / (0.5 * 1.5))
    np.testing.assert_allclose(s, [0.0, 0.0, 1.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(sd, 0.0, atol=1e-15)


def test_without_blending_each_segment_stops_at_its_waypoint(stop_law, waypoints):
    np.testing.assert_array_equal(stop_law.blend_overlaps, 0.0)
    ends = stop_law.segment_starts + stop_law.segment_durations
    np.testing.assert_allclose(stop_law.segment_starts[1:], ends[:-1])
    q, qd, qdd = stop_law.sample(ends)
    np.testing.assert_allclose(q, waypoints[1:], atol=1e-12)
    np.testing.assert_allclose(qd, 0.0, atol=1e-12)
    for k, qd_k in enumerate([stop_law.rates_at(t)[0] for t in ends]):
        np.testing.assert_allclose(qd_k, 0.0, atol=1e-12, err_msg=f"segment {k}")


def test_leading_axis_hits_its_limits_exactly(stop_law):
    for k, d in enumerate(stop_law.displacements):
        lead = int(np.argmax(np.abs(d)))
        start, duration = stop_law.segment_starts[k], stop_law.segment_durations[k]
        t = np.linspace(start, start + duration, 4001)
        _, qd, qdd = stop_law.sample(t)
        assert np.max(np.abs(qdd[:, lead])) == pytest.approx(A_LIMIT, rel=1e-12)
        v_peak = np.max(np.abs(qd[:, lead]))
        if abs(d[lead]) >= V_LIMIT**2 / A_LIMIT:  # trapezoid: cruises at the limit
            assert v_peak == pytest.approx(V_LIMIT, rel=1e-12)
        else:  # triangle: the peak speed stays below
            assert v_peak < V_LIMIT
        # Synchronised: every joint's velocity is the same profile scaled by its displacement.
        np.testing.assert_allclose(qd, np.outer(qd[:, lead] / d[lead], d), atol=1e-12)


def test_limits_hold_without_blends(stop_law):
    _, _, qd, qdd = dense(stop_law)
    assert np.max(np.abs(qd)) <= V_LIMIT * (1 + 1e-12)
    assert np.max(np.abs(qdd)) <= A_LIMIT * (1 + 1e-12)


def test_blends_exceed_the_acceleration_limit(blend_law, stop_law, capsys):
    """The baseline's known flaw: superposed segments exceed 1.40 rad/s^2 in the blends."""
    t, q, qd, qdd = dense(blend_law, 40001)
    intervals = blend_law.blend_intervals()
    assert np.all(intervals[:, 1] > intervals[:, 0])
    in_blend = np.zeros_like(t, dtype=bool)
    for a, b in intervals:
        in_blend |= (t >= a) & (t <= b)
    peak_blend = np.max(np.abs(qdd[in_blend]))
    peak_outside = np.max(np.abs(qdd[~in_blend]))
    with capsys.disabled():
        print(
            f"\nMoveJ paper task: T = {stop_law.duration:.3f} s without blends, {blend_law.duration:.3f} s with "
            f"r = {PAPER_BLEND_RADIUS} m; peak |qdd| in blends {peak_blend:.3f} rad/s^2 (limit {A_LIMIT}, "
            f"paper measured {PAPER_BLEND_ACCELERATION}); outside {peak_outside:.3f}; peak |qd| {np.abs(qd).max():.3f}"
        )
    assert peak_blend > A_LIMIT * 1.1
    assert peak_outside <= A_LIMIT * (1 + 1e-12)
    assert blend_law.duration < stop_law.duration


def test_blend_starts_inside_the_sphere(blend_law):
    """Each overlap lies where the TCP is within r of its waypoint (on both segments)."""
    points = blend_law.tcp_positions()
    for k, (a, b) in enumerate(blend_law.blend_intervals(), start=1):
        for t in np.linspace(a, b, 11):
            q, _, _ = blend_law.sample(t)
            assert np.linalg.norm(robot.flange_pose(q)[:3, 3] - points[k]) <= PAPER_BLEND_RADIUS + 1e-9
    # one of the two sphere crossings bounds each overlap exactly
    for k, (a, b) in enumerate(blend_law.blend_intervals(), start=1):
        d = [np.linalg.norm(robot.flange_pose(blend_law.sample(t)[0])[:3, 3] - points[k]) for t in (a, b)]
        assert max(d) == pytest.approx(PAPER_BLEND_RADIUS, abs=1e-9)


@pytest.mark.parametrize("radius", [0.0, PAPER_BLEND_RADIUS])
def test_position_continuity_and_consistency(radius, waypoints):
    law = MovejBlendLaw(waypoints, V_LIMIT, A_LIMIT, radius)
    t, q, qd, qdd = dense(law, 40001)
    dt = t[1] - t[0]
    # C^1: position steps bounded by the velocity, velocity steps by the acceleration.
    assert np.max(np.abs(np.diff(q, axis=0))) <= np.max(np.abs(qd)) * dt * 1.01
    assert np.max(np.abs(np.diff(qd, axis=0))) <= np.max(np.abs(qdd)) * dt * 1.01
    # qd is the derivative of q (central differences).
    np.testing.assert_allclose((q[2:] - q[:-2]) / (2 * dt), qd[1:-1], atol=1e-3 * V_LIMIT)
    # rates_at (scalar hot path) agrees with sample.
    for i in range(0, len(t), 997):
        qd_i, qdd_i = law.rates_at(float(t[i]))
        np.testing.assert_allclose(qd_i, qd[i], atol=1e-12)
        np.testing.assert_allclose(qdd_i, qdd[i], atol=1e-12)
    # ends at the last waypoint, at rest
    np.testing.assert_allclose(q[-1], waypoints[-1], atol=1e-12)
    np.testing.assert_allclose(qd[-1], 0.0, atol=1e-12)
    np.testing.assert_allclose(law.rates_at(law.duration + 1.0)[0], 0.0)
    np.testing.assert_allclose(law.sample(law.duration + 1.0)[0], waypoints[-1])
    np.testing.assert_allclose(law.sample(-1.0)[0], waypoints[0])


def test_planner_system_integrates_to_the_last_waypoint(blend_law, waypoints):
    planner = MovejPlanner(blend_law)
    np.testing.assert_allclose(planner.task_waypoints(), blend_law.tcp_positions()[1:])
    simulator = Simulator(planner)
    simulator.get_mutable_integrator().set_target_accuracy(1e-9)
    simulator.AdvanceTo(blend_law.duration + 0.05)
    context = simulator.get_context()
    assert planner.finished(context)
    state = planner.reference_state(context)
    np.testing.assert_allclose(state[:6], waypoints[-1], atol=1e-4)
    np.testing.assert_allclose(state[6:], 0.0, atol=1e-6)


def test_duplicate_waypoints_are_dropped(waypoints):
    law = MovejBlendLaw(np.vstack([waypoints[:2], waypoints[1:]]), V_LIMIT, A_LIMIT, 0.0)
    assert len(law.displacements) == len(waypoints) - 1


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(q_waypoints=np.zeros(6)), "q_waypoints"),
        (dict(q_waypoints=np.zeros((1, 6))), "q_waypoints"),
        (dict(q_waypoints=[[0.0] * 6, [np.nan] * 6]), "q_waypoints"),
        (dict(velocity_limit=0.0), "velocity_limit"),
        (dict(velocity_limit=[1.0] * 5), "velocity_limit"),
        (dict(acceleration_limit=-1.0), "acceleration_limit"),
        (dict(acceleration_limit=[1.0, 1.0, 1.0, 1.0, 1.0, np.inf]), "acceleration_limit"),
        (dict(blend_radius=-0.01), "blend_radius"),
        (dict(blend_radius=np.nan), "blend_radius"),
        (dict(blend_radius=1.0), "blend_radius"),  # blend spheres would overlap
    ],
)
def test_validation_names_the_argument(waypoints, kwargs, name):
    arguments = dict(q_waypoints=waypoints, velocity_limit=V_LIMIT, acceleration_limit=A_LIMIT, blend_radius=0.05)
    arguments.update(kwargs)
    with pytest.raises(ValueError, match=name):
        MovejBlendLaw(**arguments)


def test_planner_rejects_other_laws():
    with pytest.raises(TypeError, match="law must be a MovejBlendLaw"):
        MovejPlanner(object())
