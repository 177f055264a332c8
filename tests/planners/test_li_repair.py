"""Tests for our limit repair of Li et al. 2019 (drake_traj.planners.li.repair): the tool check
through forward kinematics, the spread of the log-stretch, its slope from an acceleration budget,
and the smooth time warp. The whole pipeline on both robots: test_li_plan.py."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drake_traj.planners.li.joint import JointSplineLaw
from drake_traj.planners.li.repair import (
    ToolLimitReport,
    check_tool_limits,
    smooth_time_warp,
    spread_log_stretch,
    tool_speed_and_acceleration,
    warp_log_steps,
)
from drake_traj.robots import LI_4DOF


def identity_tool(q, qd, qdd):
    """A 'robot' whose tool point is its joint vector (3 prismatic joints)."""
    return qd, qdd


# ---------------------------------------------------------------------------------------------
# spread_log_stretch
# ---------------------------------------------------------------------------------------------


def test_spread_by_hand():
    g = spread_log_stretch([0.0, 0.0, 1.0, 0.0, 0.0], [0.3, 0.3, 0.3, 0.5])
    np.testing.assert_allclose(g, [0.4, 0.7, 1.0, 0.7, 0.2], atol=1e-15)
    # An infinite step decouples neighbours; a zero step makes them equal.
    np.testing.assert_allclose(spread_log_stretch([0.0, 1.0, 0.0], [np.inf, 0.0]), [0.0, 1.0, 1.0])


def test_spread_is_the_smallest_envelope_with_bounded_steps():
    rng = np.random.default_rng(4)
    for _ in range(20):
        m = int(rng.integers(2, 40))
        required = np.where(rng.random(m) < 0.3, rng.uniform(0.0, 1.0, m), 0.0)
        steps = rng.uniform(0.0, 0.2, m - 1)
        g = spread_log_stretch(required, steps)
        # Brute force: g_k = max_i (required_i - steps summed between k and i).
        distance = np.abs(np.concatenate([[0.0], np.cumsum(steps)])[:, None]
                          - np.concatenate([[0.0], np.cumsum(steps)])[None, :])
        np.testing.assert_allclose(g, np.max(required[None, :] - distance, axis=1), atol=1e-12)
        assert np.all(g >= required)
        assert np.all(np.abs(np.diff(g)) <= steps + 1e-12)


def test_spread_rejects_bad_input():
    with pytest.raises(ValueError, match=r"max_step must have shape \(2,\)"):
        spread_log_stretch([0.0, 1.0, 0.0], [0.1])
    with pytest.raises(ValueError, match=r"max_step\[1\] must be >= 0"):
        spread_log_stretch([0.0, 1.0, 0.0], [0.1, -0.1])
    with pytest.raises(ValueError, match=r"log_stretch\[1\] must be finite"):
        spread_log_stretch([0.0, np.nan, 0.0], [0.1, 0.1])
    with pytest.raises(ValueError, match="log_stretch must have shape"):
        spread_log_stretch([], [])


# ---------------------------------------------------------------------------------------------
# warp_log_steps
# ---------------------------------------------------------------------------------------------


def test_warp_log_steps_by_hand():
    steps = warp_log_steps([0.1, 0.2, 0.3, 0.4], [0.5, 0.0, 0.25, 0.0], 0.2)
    # budget * mean duration / larger rate of the two neighbours
    np.testing.assert_allclose(steps[:2], [0.2 * 0.15 / 0.5, 0.2 * 0.25 / 0.25], rtol=1e-15)
    assert steps[2] == pytest.approx(0.2 * 0.35 / 0.25)
    assert np.isinf(warp_log_steps([0.1, 0.1], [0.0, 0.0], 0.2)).all()  # nothing moves: no coupling
    with pytest.raises(ValueError, match="budget must be > 0"):
        warp_log_steps([0.1, 0.1], [1.0, 1.0], 0.0)
    with pytest.raises(ValueError, match=r"rate_over_limit must have shape \(2,\)"):
        warp_log_steps([0.1, 0.1], [1.0], 0.2)
    with pytest.raises(ValueError, match=r"rate_over_limit\[0\] must be >= 0"):
        warp_log_steps([0.1, 0.1], [-1.0, 1.0], 0.2)
    with pytest.raises(ValueError, match="durations must be a non-empty vector of positive times"):
        warp_log_steps([0.1, 0.0], [1.0, 1.0], 0.2)


def test_the_warp_adds_at_most_its_budget_of_acceleration():
    # One joint at constant speed v (rest only at the far ends); the middle interval must take
    # twice as long. The warp slows down into it and speeds up out of it; the acceleration this
    # costs in the middle of the motion is budget * alpha (the warp's own term v G' exp(-2G), at
    # the steepest allowed slope), measured on the refitted spline.
    v, alpha, budget, dt = 0.5, 2.0, 0.2, 0.01
    times = np.arange(0.0, 4.0 + dt / 2, dt)
    q = (v * times)[:, None]
    durations = np.diff(times)
    steps = warp_log_steps(durations, np.full(durations.size, v / alpha), budget)
    middle = durations.size // 2
    minimum = durations * (1.0 - 1e-9)  # below the input: the cumulative sum of the knot times rounds
    minimum[middle] *= 2.0
    law, report = smooth_time_warp(times, q, lambda law: minimum / np.diff(law.knot_times), steps, target=0.999)
    assert report.iterations == 1 and report.uniform_stretch == 1.0
    expected = spread_log_stretch(np.where(np.arange(durations.size) == middle, np.log(2.0 * (1.0 - 1e-9) / 0.999), 0.0), steps)
    np.testing.assert_allclose(report.log_stretch, expected, atol=1e-12)
    # The ramp in G reaches 0 at 2 * log 2 * v / (budget * alpha) = 1.73 s of law time each side.
    inner = (law.knot_times > 0.5) & (law.knot_times < law.duration - 0.5)
    t = np.linspace(law.knot_times[inner][0], law.knot_times[inner][-1], 4001)
    qdd = np.abs(law.sample(t)[2][:, 0])
    assert budget * alpha * 0.8 < qdd.max() < budget * alpha * 1.05


# ---------------------------------------------------------------------------------------------
# check_tool_limits
# ---------------------------------------------------------------------------------------------


def test_tool_peaks_are_exact_on_the_rest_to_rest_quintic():
    # Two samples: p = D r(t / T), r = 10 s^3 - 15 s^4 + 6 s^5: |v| peaks at 15/8 |D| / T at T/2,
    # |a| at 10 / sqrt(3) |D| / T^2 at T (1/2 -+ sqrt(3)/6). Four samples per interval only:
    # the peaks come from the refinement.
    d, duration = np.array([0.3, -0.4, 0.0]), 2.0
    norm = float(np.linalg.norm(d))
    law = JointSplineLaw([0.0, duration], np.stack([np.zeros(3), d]))
    report = check_tool_limits(law, identity_tool, 1.0, 1.0, samples_per_interval=4)
    assert report.peak_speed == pytest.approx(15 / 8 * norm / duration, rel=1e-9)
    assert report.peak_speed_time == pytest.approx(duration / 2, rel=1e-5)
    assert report.peak_acceleration == pytest.approx(10 / math.sqrt(3) * norm / duration**2, rel=1e-9)
    assert min(abs(report.peak_acceleration_time - duration * (0.5 + sign * math.sqrt(3) / 6))
               for sign in (-1, 1)) < 1e-5
    # The samples alone (s = 1/3: r'' = 40/9) fall 23 % short of the acceleration peak.
    assert 40 / 9 * norm / duration**2 < 0.8 * report.peak_acceleration


def test_tool_peaks_match_a_dense_grid_on_the_4dof_robot():
    # 40 points of a 20 mm arc in the plane Z = 0 at 1 mm spacing, 30 ms apart.
    angle = np.linspace(0.0, 2.0, 40)
    points = np.column_stack([0.3 + 0.02 * np.cos(angle), 0.02 * np.sin(angle), np.zeros(40)])
    times = 0.03 * np.arange(40) + 0.02 * np.sin(np.arange(40))  # uneven intervals
    law = JointSplineLaw(times, LI_4DOF.ik(points))
    report = check_tool_limits(law, LI_4DOF.tool_motion, 0.2, 0.1)
    t, speed, accel = tool_speed_and_acceleration(law, LI_4DOF.tool_motion, samples_per_interval=2000)
    k = np.minimum(np.searchsorted(law.knot_times, t, side="right") - 1, times.size - 2)
    dense_v = np.zeros(times.size - 1)
    dense_a = np.zeros(times.size - 1)
    np.maximum.at(dense_v, k, speed)
    np.maximum.at(dense_a, k, accel)
    for reported, dense in ((report.interval_speed, dense_v), (report.interval_acceleration, dense_a)):
        # Never below the dense grid; above it only by a peak a sample spacing into a neighbour.
        assert np.all(reported >= dense * (1 - 1e-9))
        neighbours = np.maximum(dense, np.maximum(np.append(dense[1:], 0.0), np.insert(dense[:-1], 0, 0.0)))
        assert np.all(reported <= neighbours * (1 + 1e-6))
        assert reported.max() == pytest.approx(dense.max(), rel=1e-6)
    # The times are where the peaks are.
    velocity, _ = LI_4DOF.tool_motion(*law.sample(report.interval_speed_time))
    _, acceleration = LI_4DOF.tool_motion(*law.sample(report.interval_acceleration_time))
    np.testing.assert_allclose(np.linalg.norm(velocity, axis=1), report.interval_speed, rtol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(acceleration, axis=1), report.interval_acceleration, rtol=1e-12)


def test_tool_report_stretch_and_ok():
    report = ToolLimitReport(0.2, 0.1, np.array([0.1, 0.25]), np.array([0.16, 0.05]),
                             np.zeros(2), np.zeros(2), margin=0.0)
    np.testing.assert_allclose(report.interval_stretch, [math.sqrt(1.6), 1.25])
    assert not report.ok
    assert report.peak_speed == 0.25 and report.peak_acceleration == 0.16
    fine = ToolLimitReport(0.2, 0.1, np.array([0.1]), np.array([0.1]), np.zeros(1), np.zeros(1), margin=0.0)
    assert fine.ok
    assert not ToolLimitReport(0.2, 0.1, np.array([0.1]), np.array([0.1]), np.zeros(1), np.zeros(1)).ok  # margin
    assert "limit 0.1" in fine.describe()


def test_check_tool_limits_rejects_bad_input():
    law = JointSplineLaw([0.0, 1.0], [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])
    with pytest.raises(ValueError, match="law must be a JointSplineLaw"):
        check_tool_limits("law", identity_tool, 0.2, 0.1)
    with pytest.raises(ValueError, match="tool_motion must be callable"):
        check_tool_limits(law, None, 0.2, 0.1)
    with pytest.raises(ValueError, match="speed_limit must be > 0"):
        check_tool_limits(law, identity_tool, 0.0, 0.1)
    with pytest.raises(ValueError, match="acceleration_limit must be finite"):
        check_tool_limits(law, identity_tool, 0.2, np.inf)
    with pytest.raises(ValueError, match="samples_per_interval must be an integer >= 3"):
        check_tool_limits(law, identity_tool, 0.2, 0.1, samples_per_interval=2)
    with pytest.raises(ValueError, match="margin must be in"):
        check_tool_limits(law, identity_tool, 0.2, 0.1, margin=1.0)
    with pytest.raises(ValueError, match="non-finite tool velocity or acceleration at t = "):
        check_tool_limits(law, lambda q, qd, qdd: (np.full_like(qd, np.nan), qdd), 0.2, 0.1)


# ---------------------------------------------------------------------------------------------
# smooth_time_warp
# ---------------------------------------------------------------------------------------------

TIMES = np.linspace(0.0, 1.0, 11)
Q = np.linspace(0.0, 0.5, 11)[:, None]
STEPS = np.full(9, 0.1)


def test_warp_falls_back_to_a_uniform_stretch():
    minimum = np.full(10, 0.1)
    minimum[3] = 0.25
    law, report = smooth_time_warp(TIMES, Q, lambda law: minimum / np.diff(law.knot_times), STEPS, max_iterations=0)
    assert report.iterations == 0
    assert report.uniform_stretch == pytest.approx(2.5, rel=1e-11)
    np.testing.assert_allclose(np.diff(law.knot_times), 0.25, rtol=1e-11)
    # A requirement that does not scale with time cannot be met: a clear error, not a silent law.
    with pytest.raises(ValueError, match="must scale as 1 / c"):
        smooth_time_warp(TIMES, Q, lambda law: np.full(10, 2.0), STEPS, max_iterations=2)


def test_warp_starts_from_an_earlier_warp():
    earlier = np.full(10, 0.5)
    law, report = smooth_time_warp(TIMES, Q, lambda law: np.zeros(10), STEPS, initial_log_stretch=earlier)
    assert report.iterations == 0
    np.testing.assert_allclose(law.duration, math.exp(0.5), rtol=1e-12)
    assert report.initial_duration == 1.0 and report.lengthening == pytest.approx(math.exp(0.5))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(needed_stretch=lambda law: np.zeros(9)), r"needed_stretch must return shape \(10,\)"),
        (dict(needed_stretch=lambda law: np.full(10, np.nan)), "needed_stretch returned nan for interval 0"),
        (dict(needed_stretch=lambda law: -np.ones(10)), "must be finite and >= 0"),
        (dict(needed_stretch="not callable"), "needed_stretch must be callable"),
        (dict(max_step=np.ones(10)), r"max_step must have shape \(9,\)"),
        (dict(target=0.0), r"target must be in \(0, 1\]"),
        (dict(target=1.5), r"target must be in \(0, 1\]"),
        (dict(max_iterations=-1), "max_iterations must be an integer >= 0"),
        (dict(max_iterations=True), "max_iterations must be an integer >= 0"),
        (dict(initial_log_stretch=-np.ones(10)), "initial_log_stretch must be >= 0"),
        (dict(initial_log_stretch=np.ones(3)), r"initial_log_stretch must have shape \(10,\)"),
        (dict(times=TIMES[::-1]), "times must be a strictly increasing vector"),
        (dict(q=Q[:5]), r"q must have shape \(11, n\)"),
    ],
)
def test_warp_rejects_bad_input(kwargs, match):
    args = dict(times=TIMES, q=Q, needed_stretch=lambda law: np.zeros(10), max_step=STEPS)
    args.update(kwargs)
    times, q, needed, steps = (args.pop(k) for k in ("times", "q", "needed_stretch", "max_step"))
    with pytest.raises(ValueError, match=match):
        smooth_time_warp(times, q, needed, steps, **args)
