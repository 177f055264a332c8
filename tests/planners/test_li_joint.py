"""Tests for the joint stage of Li et al. 2019 (Li, Zhang, Zhou): re-timing (eq. 14), the quintic
B-spline fit (eq. 15-22) and the exact post-check of the joint limits.

The paper claims its joint trajectories satisfy the limits (Fig. 8); docs/papers.md recomputes that
they do not (correction 7). The UR10e test below shows the same on a path of straight lines and
10 mm arcs; tests/planners/test_li_repair.py repairs it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from drake_traj.robots import ur10e as robot
from drake_traj.planners.li.joint import (
    JointSplineLaw,
    check_limits,
    fit_quintic_spline,
    joint_interval_times,
    retime_joint_samples,
)
from drake_traj.planners.li.cartesian import plan_cartesian_path
from drake_traj.planners.li.repair import joint_stretch, smooth_time_warp, warp_log_steps
from drake_traj.planners.quintic import quintic_profile

Q0 = np.array([-np.pi / 2, -np.pi / 2, -3 * np.pi / 4, -np.pi / 4, np.pi / 2, np.pi / 4])
# Joint limits of the UR10e test: half the published velocity limits, 2 rad/s^2 everywhere.
VEL = 0.5 * robot.VELOCITY_LIMIT
ACC = np.full(6, 2.0)
# Tool limits of the Cartesian stage.
V_TOOL, A_TOOL = 0.25, 1.0  # [m/s], [m/s^2]


def rounded_rectangle(width, height, radius, step) -> np.ndarray:
    """Closed XY path centred on the origin: straight sides sampled every ``step``, quarter arcs of
    ``radius``; starts and ends at the middle of the bottom side."""
    w, h, r = width / 2, height / 2, radius

    def line(a, b):
        n = max(int(math.ceil(np.linalg.norm(np.subtract(b, a)) / step)), 1)
        return np.linspace(a, b, n + 1)[:-1]

    def arc(center, start):
        theta = start + np.linspace(0.0, np.pi / 2, int(math.ceil(r * np.pi / 2 / step)) + 1)
        return np.stack([center[0] + r * np.cos(theta), center[1] + r * np.sin(theta)], 1)[:-1]

    pieces = [line((0, -h), (w - r, -h)), arc((w - r, -h + r), -np.pi / 2)]
    pieces += [line((w, -h + r), (w, h - r)), arc((w - r, h - r), 0.0)]
    pieces += [line((w - r, h), (-w + r, h)), arc((-w + r, h - r), np.pi / 2)]
    pieces += [line((-w, h - r), (-w, -h + r)), arc((-w + r, -h + r), np.pi)]
    pieces += [line((-w + r, -h), (0, -h)), np.array([[0.0, -h]])]
    return np.concatenate(pieces)


@pytest.fixture(scope="module")
def ur10e_path():
    """(Cartesian times, joint samples) of a 300 x 200 mm rounded rectangle with 10 mm corner arcs,
    1 cm point spacing, at the flange orientation of Q0, 10 cm beside the flange position of Q0."""
    pose0 = robot.flange_pose(Q0)
    xy = rounded_rectangle(0.3, 0.2, 0.01, 0.01)
    points = pose0[:3, 3] + np.column_stack([xy[:, 0], xy[:, 1] + 0.1, np.zeros(len(xy))])
    plan = plan_cartesian_path(points, V_TOOL, A_TOOL)
    poses = np.repeat(pose0[None], len(points), axis=0)
    poses[:, :3, 3] = points
    q = robot.inverse_kinematics_path(poses, Q0)
    return plan.segment_times, q


@pytest.fixture(scope="module")
def ur10e_retimed(ur10e_path):
    times, q = ur10e_path
    return retime_joint_samples(times, q, VEL, ACC), q


def synthetic_samples(seed=0, num=12, joints=3):
    rng = np.random.default_rng(seed)
    times = np.cumsum(rng.uniform(0.05, 0.4, num)) - 0.3
    q = np.cumsum(rng.normal(scale=0.2, size=(num, joints)), axis=0)
    return times, q


def dense_peaks(law, per_interval=200):
    """max |qd|, |qdd| per joint on ``per_interval`` uniform samples per knot interval."""
    knots = law.knot_times
    s = np.linspace(0.0, 1.0, per_interval)
    t = (knots[:-1, None] + s * np.diff(knots)[:, None]).ravel()
    _, qd, qdd = law.sample(t)
    return np.max(np.abs(qd), axis=0), np.max(np.abs(qdd), axis=0)


# ---------------------------------------------------------------------------------------------
# Quintic B-spline fit (eq. 15-22).
# ---------------------------------------------------------------------------------------------


def test_spline_interpolates_and_rests_at_both_ends():
    times, q = synthetic_samples()
    spline = fit_quintic_spline(times, q)
    assert spline.k == 5
    # eq. 17: knots at the sample times, multiplicity k + 1 = 6 at both ends.
    np.testing.assert_array_equal(spline.t[5:-5], times)
    np.testing.assert_array_equal(spline.t[:6], [times[0]] * 6)
    np.testing.assert_array_equal(spline.t[-6:], [times[-1]] * 6)
    np.testing.assert_allclose(spline(times), q, rtol=0, atol=1e-9)  # eq. 18-19
    for end in (times[0], times[-1]):  # eq. 22: zero velocity and acceleration
        np.testing.assert_allclose(spline(end, nu=1), 0.0, atol=1e-9)
        np.testing.assert_allclose(spline(end, nu=2), 0.0, atol=1e-9)


def test_two_sample_spline_is_the_rest_to_rest_quintic():
    # With two samples the system of eq. 18 + 22 has one solution: 10 s^3 - 15 s^4 + 6 s^5.
    q = np.array([[0.0, 1.0], [2.0, -1.0]])
    spline = fit_quintic_spline([1.0, 3.0], q)
    s = np.linspace(0.0, 1.0, 11)
    r, _, _ = quintic_profile(s)
    np.testing.assert_allclose(spline(1.0 + 2.0 * s), q[0] + r[:, None] * (q[1] - q[0]), atol=1e-12)


def test_law_clock_ends_and_interpolation():
    times, q = synthetic_samples(seed=1)
    law = JointSplineLaw(times, q)
    assert law.duration == pytest.approx(times[-1] - times[0], rel=1e-15)
    np.testing.assert_array_equal(law.q_start, q[0])
    np.testing.assert_array_equal(law.q_end, q[-1])
    pos, qd, qdd = law.sample(times - times[0])
    np.testing.assert_allclose(pos, q, atol=1e-9)
    np.testing.assert_allclose(qd[[0, -1]], 0.0, atol=1e-9)
    np.testing.assert_allclose(qdd[[0, -1]], 0.0, atol=1e-9)
    # Outside [0, duration]: at rest at the end positions.
    pos, qd, qdd = law.sample([-1.0, law.duration + 1.0])
    np.testing.assert_allclose(pos, [q[0], q[-1]], atol=1e-9)
    np.testing.assert_array_equal(qd, 0.0)
    np.testing.assert_array_equal(qdd, 0.0)
    for tau in (-0.5, law.duration + 0.5):
        np.testing.assert_array_equal(law.rates_at(tau), np.zeros((2, 3)))


def test_rates_at_matches_sample(ur10e_retimed):
    law = JointSplineLaw(*ur10e_retimed)
    rng = np.random.default_rng(3)
    taus = np.concatenate([rng.uniform(0.0, law.duration, 500), law.knot_times, [law.duration]])
    _, qd, qdd = law.sample(taus)
    for k, tau in enumerate(taus):
        rate, accel = law.rates_at(float(tau))
        np.testing.assert_allclose(rate, qd[k], rtol=0, atol=1e-12)
        np.testing.assert_allclose(accel, qdd[k], rtol=0, atol=1e-12)


# ---------------------------------------------------------------------------------------------
# Re-timing (section 3.1, eq. 14).
# ---------------------------------------------------------------------------------------------


def rest_to_rest_time(length, omega, alpha):
    """Table 2 time (docs/papers.md) from rest to rest over ``length`` with A = (2/3) alpha: case VII
    L / omega + omega / A when the joint reaches omega (L >= L_e = omega^2 / A), else case VI
    2 sqrt(L / A)."""
    acc = 2.0 / 3.0 * alpha
    if length >= omega**2 / acc:
        return length / omega + omega / acc
    return 2.0 * math.sqrt(length / acc)


def test_interval_time_of_a_single_step_is_table_2_rest_to_rest():
    # Two joints, one step: joint 0 (0.3 rad, slow limits) reaches omega (case VII), joint 1
    # (2 rad, fast limits) does not (case VI); eq. 14 takes the slower.
    q = np.array([[0.0, 0.0], [0.3, -2.0]])
    omega, alpha = np.array([0.2, 3.0]), np.array([0.5, 4.0])
    expected = [rest_to_rest_time(0.3, 0.2, 0.5), rest_to_rest_time(2.0, 3.0, 4.0)]
    assert expected[0] == pytest.approx(0.3 / 0.2 + 0.2 / (2 / 3 * 0.5))
    delta = joint_interval_times([0.0, 0.01], q, omega, alpha)
    np.testing.assert_allclose(delta, [expected], rtol=1e-12)
    new = retime_joint_samples([5.0, 5.01], q, omega, alpha)
    np.testing.assert_allclose(new, [5.0, 5.0 + max(expected)], rtol=1e-12)
    # A Cartesian interval longer than every joint's time is kept.
    np.testing.assert_allclose(retime_joint_samples([0.0, 10.0], q, omega, alpha), [0.0, 10.0])


def test_reversal_is_a_break_point_with_zero_speed():
    # Step 1: the joint reverses at the middle sample, so each step is rest to rest.
    q = np.array([[0.0], [0.4], [0.1]])
    delta = joint_interval_times([0.0, 0.1, 0.2], q, 1.0, 1.0)
    np.testing.assert_allclose(
        delta[:, 0],
        [rest_to_rest_time(0.4, 1.0, 1.0), rest_to_rest_time(0.3, 1.0, 1.0)],
        rtol=1e-12,
    )
    # A joint that does not move needs no time.
    q2 = np.column_stack([q[:, 0], np.zeros(3)])
    np.testing.assert_array_equal(joint_interval_times([0.0, 0.1, 0.2], q2, 1.0, 1.0)[:, 1], 0.0)


def test_retimed_intervals_satisfy_eq_14(ur10e_path, ur10e_retimed):
    times, q = ur10e_path
    new, _ = ur10e_retimed
    delta = joint_interval_times(times, q, VEL, ACC)
    assert delta.shape == (len(times) - 1, 6)
    # eq. 14, with the Cartesian interval kept as a lower bound (module docstring).
    expected = np.maximum(np.diff(times), delta.max(axis=1))
    np.testing.assert_allclose(np.diff(new), expected, rtol=1e-12)
    assert new[0] == times[0]
    # Every joint's time covers its step at no more than its velocity limit.
    assert np.all(delta >= np.abs(np.diff(q, axis=0)) / VEL * (1 - 1e-12))
    # The paper's eq. 14 as printed drops the Cartesian times; some intervals become shorter.
    paper = retime_joint_samples(times, q, VEL, ACC, keep_input_times=False)
    np.testing.assert_allclose(np.diff(paper), delta.max(axis=1), rtol=1e-12)
    assert np.any(np.diff(paper) < np.diff(times))


# ---------------------------------------------------------------------------------------------
# Post-check and repair.
# ---------------------------------------------------------------------------------------------


def test_check_limits_finds_the_true_peaks(ur10e_retimed):
    law = JointSplineLaw(*ur10e_retimed)
    report = check_limits(law, VEL, ACC, samples_per_interval=4)
    dense_v, dense_a = dense_peaks(law, per_interval=400)
    # Exact per-interval extrema: never below a dense grid, and equal to it to grid resolution.
    assert np.all(report.peak_velocity >= dense_v * (1 - 1e-12))
    assert np.all(report.peak_acceleration >= dense_a * (1 - 1e-12))
    np.testing.assert_allclose(report.peak_velocity, dense_v, rtol=1e-4)
    np.testing.assert_allclose(report.peak_acceleration, dense_a, rtol=1e-4)
    # ... and the reported times are where the peaks are.
    _, qd, _ = law.sample(report.peak_velocity_time)
    _, _, qdd = law.sample(report.peak_acceleration_time)
    np.testing.assert_allclose(np.abs(np.diag(qd)), report.peak_velocity, rtol=1e-9)
    np.testing.assert_allclose(np.abs(np.diag(qdd)), report.peak_acceleration, rtol=1e-9)


def test_check_limits_is_exact_on_the_rest_to_rest_quintic():
    # Two samples: q = q0 + D r(t / T); peak |qd| = 15/8 |D| / T at T/2, peak |qdd| =
    # 10 / sqrt(3) |D| / T^2 at T (1/2 -+ sqrt(3)/6). Two grid samples per interval (the ends) only:
    # the peaks come from the polynomial roots.
    d, duration = np.array([0.8, -0.3, 0.0]), 2.0
    law = JointSplineLaw([0.0, duration], np.stack([np.zeros(3), d]))
    report = check_limits(law, 1.0, 1.0, samples_per_interval=2)
    np.testing.assert_allclose(report.peak_velocity, 15 / 8 * np.abs(d) / duration, rtol=1e-12)
    np.testing.assert_allclose(
        report.peak_acceleration, 10 / math.sqrt(3) * np.abs(d) / duration**2, rtol=1e-12
    )
    assert report.peak_velocity_time[0] == pytest.approx(duration / 2, rel=1e-9)
    assert report.peak_acceleration_time[0] == pytest.approx(
        duration * (0.5 - math.sqrt(3) / 6), rel=1e-9
    ) or report.peak_acceleration_time[0] == pytest.approx(duration * (0.5 + math.sqrt(3) / 6))


def joint_warp(times, q, vel, acc, **options):
    """The smooth time warp with the joint limits as its only requirement (budget 0.2 of the
    joint acceleration limits, from the unwarped spline's speeds)."""
    report = check_limits(JointSplineLaw(times, q), vel, acc)
    steps = warp_log_steps(np.diff(times), np.max(report.interval_velocity / acc, axis=1), 0.2)
    return smooth_time_warp(times, q, lambda law: joint_stretch(check_limits(law, vel, acc)), steps, **options)


@pytest.fixture(scope="module")
def ur10e_repaired(ur10e_retimed):
    return joint_warp(*ur10e_retimed, VEL, ACC)


def test_unrepaired_fit_breaks_a_limit_and_the_warp_holds_them(ur10e_retimed, ur10e_repaired):
    times, q = ur10e_retimed
    law, report = ur10e_repaired
    # The paper's steps alone (re-time + fit) overshoot the acceleration limit near the arcs
    # (recomputed: joint 2 at 1.82 times its limit).
    before = check_limits(JointSplineLaw(times, q), VEL, ACC)
    assert not before.ok
    assert np.max(before.acceleration_ratio) > 1.5
    assert "joint 2: |qdd|" in before.describe()
    # After the warp every limit holds on a grid 25x denser than the check's.
    assert check_limits(law, VEL, ACC).ok
    dense_v, dense_a = dense_peaks(law, per_interval=400)
    assert np.all(dense_v <= VEL)
    assert np.all(dense_a <= ACC)
    # The warp only stretches time: same samples, longer intervals, reported.
    np.testing.assert_allclose(law.sample(law.knot_times)[0], q, atol=1e-9)
    assert np.all(np.diff(law.knot_times) >= np.diff(times) * (1 - 1e-12))
    np.testing.assert_allclose(np.diff(law.knot_times), np.diff(times) * np.exp(report.log_stretch), rtol=1e-12)
    # Recomputed: 1.042, against 1.348 for the uniform stretch the worst interval needs.
    assert 1.0 < report.lengthening < 1.06
    assert np.max(before.interval_stretch) > 1.3
    assert report.final_duration == pytest.approx(law.duration)
    assert 1 <= report.iterations <= 10 and report.uniform_stretch == 1.0


def test_uniform_fallback_when_no_warp_rounds(ur10e_retimed, ur10e_repaired):
    times, q = ur10e_retimed
    law, report = joint_warp(times, q, VEL, ACC, max_iterations=0)
    assert report.iterations == 0 and report.uniform_stretch > 1.0
    # Exact for a uniform stretch: qd scales by 1/s and qdd by 1/s^2.
    before = check_limits(JointSplineLaw(times, q), VEL, ACC)
    assert report.uniform_stretch == pytest.approx(np.max(before.interval_stretch), rel=1e-8)  # margin 1e-9
    dense_v, dense_a = dense_peaks(law, per_interval=100)
    assert np.all(dense_v <= VEL) and np.all(dense_a <= ACC)
    assert report.lengthening > ur10e_repaired[1].lengthening + 0.25


def test_warp_leaves_a_feasible_law_alone():
    times, q = synthetic_samples(seed=2)
    law, report = joint_warp(times, q, 100.0, 1000.0)
    assert report.iterations == 0 and report.lengthening == 1.0 and report.uniform_stretch == 1.0
    np.testing.assert_allclose(law.knot_times, times - times[0], rtol=0, atol=1e-14)


def test_warp_on_a_synthetic_sharp_path():
    # Samples on a triangle wave: every reversal is a sharp feature.
    times = np.linspace(0.0, 2.0, 21)
    zigzag = np.where(np.arange(21) % 4 < 2, 0.0, 0.3) + 0.01 * np.arange(21)
    q = np.column_stack([zigzag, np.sin(times)])
    vel, acc = np.array([1.0, 1.0]), np.array([2.0, 2.0])
    new = retime_joint_samples(times, q, vel, acc)
    assert not check_limits(JointSplineLaw(new, q), vel, acc).ok
    law, report = joint_warp(new, q, vel, acc)
    dense_v, dense_a = dense_peaks(law, per_interval=400)
    assert np.all(dense_v <= vel) and np.all(dense_a <= acc)
    assert report.lengthening > 1.0


# ---------------------------------------------------------------------------------------------
# Bad inputs.
# ---------------------------------------------------------------------------------------------

GOOD_T = [0.0, 0.5, 1.0]
GOOD_Q = [[0.0, 0.0], [0.1, 0.2], [0.3, 0.1]]


@pytest.mark.parametrize(
    "times, q, match",
    [
        ([0.0], [[0.0, 0.0]], "times must have at least two samples"),
        ([0.0, 1.0, 1.0], GOOD_Q, r"times must be strictly increasing .*times\[2\]"),
        ([0.0, 2.0, 1.0], GOOD_Q, r"times must be strictly increasing"),
        ([0.0, np.nan, 1.0], GOOD_Q, r"times\[1\] must be finite"),
        ([[0.0, 1.0]], GOOD_Q, r"times must have shape \(N,\)"),
        (GOOD_T, [[0.0, 0.0], [0.1, np.inf], [0.3, 0.1]], r"q\[1, 1\] must be finite"),
        (GOOD_T, [0.0, 0.1, 0.2], r"q must have shape \(N, n\)"),
        (GOOD_T, [[0.0], [0.1]], r"q must have shape \(N, n\)"),
        (GOOD_T, "abc", "q must be an array of real numbers"),
    ],
)
def test_bad_samples(times, q, match):
    with pytest.raises(ValueError, match=match):
        fit_quintic_spline(times, q)
    with pytest.raises(ValueError, match=match):
        JointSplineLaw(times, q)
    with pytest.raises(ValueError, match=match):
        retime_joint_samples(times, q, 1.0, 1.0)


@pytest.mark.parametrize(
    "vel, acc, match",
    [
        (0.0, 1.0, r"velocity_limit\[0\] \(joint 1\) must be > 0"),
        ([1.0, -1.0], 1.0, r"velocity_limit\[1\] \(joint 2\) must be > 0"),
        (1.0, [1.0, 0.0], r"acceleration_limit\[1\] \(joint 2\) must be > 0"),
        (np.nan, 1.0, "velocity_limit must be finite"),
        (1.0, [1.0, np.inf], r"acceleration_limit\[1\] must be finite"),
        ([1.0, 1.0, 1.0], 1.0, r"velocity_limit must be a scalar or have shape \(2,\)"),
    ],
)
def test_bad_limits(vel, acc, match):
    with pytest.raises(ValueError, match=match):
        retime_joint_samples(GOOD_T, GOOD_Q, vel, acc)
    with pytest.raises(ValueError, match=match):
        check_limits(JointSplineLaw(GOOD_T, GOOD_Q), vel, acc)


def test_bad_options():
    law = JointSplineLaw(GOOD_T, GOOD_Q)
    with pytest.raises(ValueError, match="law must be a JointSplineLaw"):
        check_limits("law", 1.0, 1.0)
    with pytest.raises(ValueError, match="samples_per_interval must be >= 2"):
        check_limits(law, 1.0, 1.0, samples_per_interval=1)
    with pytest.raises(ValueError, match="margin must be in"):
        check_limits(law, 1.0, 1.0, margin=1.0)
    with pytest.raises(ValueError, match=r"t\[1\] must be finite"):
        law.sample([0.0, np.nan])
    # eq. 14 as printed cannot time a step in which no joint moves.
    with pytest.raises(ValueError, match=r"q\[2\] equals q\[1\] in every joint"):
        retime_joint_samples(
            GOOD_T, [[0.0, 0.0], [0.1, 0.2], [0.1, 0.2]], 1.0, 1.0, keep_input_times=False
        )
