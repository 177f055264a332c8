"""UR-style MoveJ baseline with radius blending (Pająk 2024, experiment 1)."""

from dataclasses import replace

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from drake_traj.robots import UR10E
from drake_traj.robots import ur10e as robot
from drake_traj.bench.soak_tasks import draw_task
from drake_traj.bench.task_sets import joint_waypoints, paper_task
from drake_traj.planners.baselines.movej import (
    MovejBlendLaw,
    MovejConfig,
    MovejPlanner,
    make,
    trapezoid_profile,
)
from drake_traj.scenario.scenario import make_planner

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


@pytest.fixture(scope="module")
def paper_law(waypoints):
    """The blends as Pająk 2024 measured them on the controller: superposed at the limits."""
    return MovejBlendLaw(waypoints, V_LIMIT, A_LIMIT, PAPER_BLEND_RADIUS, keep_limits=False)


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


def test_paper_blends_exceed_the_acceleration_limit(paper_law, blend_law, stop_law, capsys):
    """The controller's flaw (keep_limits=False): superposed segments exceed 1.40 rad/s^2 in the blends."""
    t, q, qd, qdd = dense(paper_law, 40001)
    intervals = paper_law.blend_intervals()
    assert np.all(intervals[:, 1] > intervals[:, 0])
    in_blend = np.zeros_like(t, dtype=bool)
    for a, b in intervals:
        in_blend |= (t >= a) & (t <= b)
    peak_blend = np.max(np.abs(qdd[in_blend]))
    peak_outside = np.max(np.abs(qdd[~in_blend]))
    with capsys.disabled():
        print(
            f"\nMoveJ paper task: T = {stop_law.duration:.3f} s without blends, {paper_law.duration:.3f} s with "
            f"r = {PAPER_BLEND_RADIUS} m; peak |qdd| in blends {peak_blend:.3f} rad/s^2 (limit {A_LIMIT}, "
            f"paper measured {PAPER_BLEND_ACCELERATION}); outside {peak_outside:.3f}; peak |qd| {np.abs(qd).max():.3f}; "
            f"keeping the limits T = {blend_law.duration:.3f} s"
        )
    assert peak_blend > A_LIMIT * 1.1
    assert peak_outside <= A_LIMIT * (1 + 1e-12)
    assert paper_law.duration < blend_law.duration < stop_law.duration
    np.testing.assert_array_equal(paper_law.blend_slowdowns, 1.0)


def test_kept_limits_on_the_paper_task(blend_law):
    """keep_limits (the default): the same blends within both limits, slowed where a joint reverses."""
    _, _, qd, qdd = dense(blend_law, 40001)
    assert np.max(np.abs(qd)) <= V_LIMIT * (1 + 1e-12)
    assert np.max(np.abs(qdd)) <= A_LIMIT * (1 + 1e-12)
    assert np.all(blend_law.blend_overlaps > 0.0)  # still blends
    assert np.min(blend_law.blend_slowdowns) < 1.0


@pytest.mark.parametrize("law_name", ["blend_law", "paper_law"])
def test_blend_starts_inside_the_sphere(law_name, request):
    """Each overlap lies where the TCP is within r of its waypoint (on both segments)."""
    law = request.getfixturevalue(law_name)
    points = law.tcp_positions()
    for k, (a, b) in enumerate(law.blend_intervals(), start=1):
        for t in np.linspace(a, b, 11):
            q, _, _ = law.sample(t)
            assert np.linalg.norm(robot.flange_pose(q)[:3, 3] - points[k]) <= PAPER_BLEND_RADIUS + 1e-9
    # one of the two sphere crossings bounds each overlap exactly (unless the ramps shrank it)
    ramps = np.minimum(law.segment_brakes[:-1], law.segment_ramps[1:])
    for k, (a, b) in enumerate(law.blend_intervals(), start=1):
        d = [np.linalg.norm(robot.flange_pose(law.sample(t)[0])[:3, 3] - points[k]) for t in (a, b)]
        if b - a < ramps[k - 1]:
            assert max(d) == pytest.approx(PAPER_BLEND_RADIUS, abs=1e-9)


@pytest.mark.parametrize("radius, keep_limits", [(0.0, True), (PAPER_BLEND_RADIUS, True), (PAPER_BLEND_RADIUS, False)])
def test_position_continuity_and_consistency(radius, keep_limits, waypoints):
    law = MovejBlendLaw(waypoints, V_LIMIT, A_LIMIT, radius, keep_limits=keep_limits)
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
        (dict(keep_limits="no"), "keep_limits"),
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


# --- the limits in the blends (keep_limits) ------------------------------------------------------

def plan_peaks(plan, velocity_limit, acceleration_limit, step=1e-4):
    """(peak |q̇| / limit, peak |q̈| / limit) of Drake's ``plan`` at ``step`` [s] samples."""
    t = np.append(np.arange(plan.start_time(), plan.end_time(), step), plan.end_time())
    qd = plan.MakeDerivative(1).vector_values(t)
    qdd = plan.MakeDerivative(2).vector_values(t)
    return (float(np.max(np.abs(qd) / np.reshape(velocity_limit, (-1, 1)))),
            float(np.max(np.abs(qdd) / np.reshape(acceleration_limit, (-1, 1)))))


# Soak tasks with blends (drake_traj.bench.soak_tasks.draw_task("ur10e", "movej", seed)): with the
# controller's superposed blends (keep_limits=False) every one of them breaks the acceleration limit,
# by 1.07-2.0 times, when drawn as the soak draws them now
SOAK_SEEDS = (1, 2, 5, 7, 8, 20, 23, 26, 28)


@pytest.mark.parametrize("seed", SOAK_SEEDS)
def test_soak_tasks_keep_both_limits(seed):
    task = draw_task("ur10e", "movej", seed)
    assert task.scenario.planner.blend_radius > 0.0
    planner = make_planner(task.scenario)
    velocity, acceleration = plan_peaks(planner.plan(), planner.velocity_limit, planner.acceleration_limit)
    assert velocity <= 1 + 1e-6
    assert acceleration <= 1 + 1e-6
    # the same task with the controller's superposed blends: the violation the soak found, in less time
    paper = make_planner(replace(task.scenario, planner=replace(task.scenario.planner, keep_limits=False)))
    paper_velocity, paper_acceleration = plan_peaks(paper.plan(), paper.velocity_limit, paper.acceleration_limit)
    assert paper_acceleration > 1.05
    assert paper.law.duration < planner.law.duration


def unit_tcp(q):
    """The first three joint positions as a position [m]: a hand-made TCP for a 3-joint law."""
    return np.asarray(q, dtype=float)[:3]


def test_reversing_joint_blend_is_slowed_to_its_limit():
    """Joint 0 reverses at the waypoint: paper ramps add to 2 a; keep_limits halves both (lambda = 1/2)."""
    waypoints = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    v, a, r = 0.5, 1.0, 0.2
    paper = MovejBlendLaw(waypoints, v, a, r, tcp_position=unit_tcp, keep_limits=False)
    kept = MovejBlendLaw(waypoints, v, a, r, tcp_position=unit_tcp)
    np.testing.assert_allclose(kept.blend_slowdowns, [0.5])
    for law, peak in ((paper, 2.0 * a), (kept, a)):
        t = np.linspace(0.0, law.duration, 200001)
        _, qd, qdd = law.sample(t)
        assert np.max(np.abs(qdd)) == pytest.approx(peak, rel=1e-12)
        assert np.max(np.abs(qd)) <= v * (1 + 1e-12)
    # by hand: each segment 1 rad (leading joint) at 0.5 rad/s, its ramp next to the waypoint at
    # 0.5 rad/s^2: T = 1/0.5 + 0.5 * 0.5 * (1/1 + 1/0.5) = 2.75 s; the TCP is r from the waypoint
    # where 1 - s = r on the braking ramp, 0.25 u^2 = r, and where sqrt(2) s = r on the next one
    overlap = min(np.sqrt(4.0 * r), np.sqrt(4.0 * r / np.sqrt(2.0)))
    assert overlap < 1.0  # within both ramps (0.5 / 0.5 = 1 s long)
    assert kept.duration == pytest.approx(2 * 2.75 - overlap, rel=1e-9)


def test_blend_longer_than_the_ramps_is_shrunk():
    """Straight on through the waypoint: the sphere's overlap (cruise plus start) would move at twice
    the speed; keep_limits shrinks it to the ramps, which then hand over at the cruise speed."""
    waypoints = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]
    v, a, r = 0.5, 1.0, 0.4
    paper = MovejBlendLaw(waypoints, v, a, r, tcp_position=unit_tcp, keep_limits=False)
    kept = MovejBlendLaw(waypoints, v, a, r, tcp_position=unit_tcp)
    np.testing.assert_allclose(kept.blend_slowdowns, [1.0])  # the ramps cancel: no slowing
    np.testing.assert_allclose(kept.blend_overlaps, [v / a], rtol=1e-12)  # 0.5 s, both ramps
    assert paper.blend_overlaps[0] > v / a
    t = np.linspace(0.0, kept.duration, 100001)
    _, qd, qdd = kept.sample(t)
    assert np.max(np.abs(qd)) == pytest.approx(v, rel=1e-12)
    assert np.max(np.abs(qdd)) == pytest.approx(a, rel=1e-12)
    assert kept.duration == pytest.approx(2.0 / v + v / a, rel=1e-12)  # 2 rad at 0.5 rad/s, one start, one stop
    _, paper_qd, _ = paper.sample(np.linspace(0.0, paper.duration, 100001))
    assert np.max(np.abs(paper_qd)) > 1.5 * v


def test_config_passes_keep_limits_and_checks_it(waypoints):
    for keep in (True, False):
        config = MovejConfig(goals=waypoints[1:].tolist(), blend_radius=PAPER_BLEND_RADIUS, keep_limits=keep)
        assert make(config, UR10E, waypoints[0]).law.keep_limits is keep
    with pytest.raises(ValueError, match="keep_limits"):
        MovejConfig(goals=waypoints[1:].tolist(), keep_limits="yes").validate()
