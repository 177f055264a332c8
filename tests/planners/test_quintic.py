"""Tests for the synchronised quintic point-to-point planner (Benotsmane et al., Benotsmane).

Numbers from the paper are checked against the corrected values of ``docs/papers.md``;
where the paper printed something else, the comment says what it printed.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from drake_traj.planners.quintic import (
    QuinticLaw,
    QuinticSegment,
    joint_minimum_times,
    peak_acceleration,
    peak_velocity,
    plan_synchronized_quintic,
    quintic_profile,
    synchronized_duration,
)

from conftest import DIAGRAMS

SQRT3 = math.sqrt(3.0)
# Normalised times of the acceleration peaks: s = 1/2 -+ sqrt(3)/6.
S_ACC_PEAKS = (0.5 - SQRT3 / 6.0, 0.5 + SQRT3 / 6.0)

# Table 2: maximum motor velocity omega [rad/s] and transmission ratio n per joint.
TABLE2_OMEGA = np.array([460.83, 460.83, 460.83, 460.83, 370.37, 370.37])
TABLE2_RATIO = np.array([0.31, 0.19, 0.25, 0.20, 0.40, 0.26])
# Table 1: initial and final joint positions [rad].
TABLE1_Q_INITIAL = np.array([0.0, np.pi, np.pi / 6, 0.0, np.pi, 0.0])
TABLE1_Q_FINAL = np.array([np.pi / 2, 0.0, np.pi, np.pi / 2, 2 * np.pi, 2 * np.pi])


def dense_times(t_f: float, num: int = 20001) -> np.ndarray:
    """``num`` uniform samples on [0, t_f] plus the analytic peak instants, sorted."""
    extra = [0.5 * t_f, S_ACC_PEAKS[0] * t_f, S_ACC_PEAKS[1] * t_f]
    return np.unique(np.concatenate([np.linspace(0.0, t_f, num), extra]))


# ---------------------------------------------------------------------------------------------
# The time law (eq. 6) and its peaks (eq. 7, first eq. 8).
# ---------------------------------------------------------------------------------------------


def test_profile_boundary_values_and_peaks():
    r, dr, ddr = quintic_profile(np.array([0.0, 0.5, 1.0]))
    np.testing.assert_array_equal(r, [0.0, 0.5, 1.0])
    np.testing.assert_array_equal(dr, [0.0, 15.0 / 8.0, 0.0])
    np.testing.assert_array_equal(ddr, [0.0, 0.0, 0.0])  # eq. 5: zero acceleration at both ends
    _, _, ddr_peaks = quintic_profile(np.array(S_ACC_PEAKS))
    np.testing.assert_allclose(ddr_peaks, [10.0 / SQRT3, -10.0 / SQRT3], rtol=1e-14)


def test_profile_clips_outside_unit_interval_and_keeps_shape():
    s = np.array([[-2.0, -1e-9], [1.0 + 1e-9, 3.0]])
    r, dr, ddr = quintic_profile(s)
    assert r.shape == dr.shape == ddr.shape == (2, 2)
    np.testing.assert_array_equal(r, [[0.0, 0.0], [1.0, 1.0]])
    np.testing.assert_array_equal(dr, np.zeros((2, 2)))
    np.testing.assert_array_equal(ddr, np.zeros((2, 2)))
    r0, dr0, ddr0 = quintic_profile(0.25)
    assert np.ndim(r0) == np.ndim(dr0) == np.ndim(ddr0) == 0


def test_profile_derivatives_match_finite_differences_and_symmetry():
    s = np.linspace(0.0, 1.0, 100001)
    h = s[1] - s[0]
    r, dr, ddr = quintic_profile(s)
    np.testing.assert_allclose(np.gradient(r, h, edge_order=2), dr, atol=1e-8)
    np.testing.assert_allclose(np.gradient(dr, h, edge_order=2), ddr, atol=1e-7)
    r_mirror, _, _ = quintic_profile(1.0 - s)
    np.testing.assert_allclose(r + r_mirror, 1.0, atol=1e-15)
    assert np.all(np.diff(r) >= 0.0)  # monotone: joints stay between start and goal


# ---------------------------------------------------------------------------------------------
# The paper's tables.
# ---------------------------------------------------------------------------------------------


def test_table6_theoretical_peaks():
    d, t_f = np.pi / 2, 230.0  # Table 5: joint 1, q^i = 0, q^f = pi/2, T = 230 s
    # Paper printed 0,012 rad/s (truncated) and 1,7e-4 rad/s^2; the experiment gave
    # BCV = 0.0129 rad/s and BCA = 1.8e-4 rad/s^2. Recomputed (docs/papers.md): 0.012805 rad/s and
    # 1.7144e-4 rad/s^2.
    assert peak_velocity(d, t_f) == pytest.approx(0.012805, rel=1e-4)
    assert peak_acceleration(d, t_f) == pytest.approx(1.7144e-4, rel=1e-4)
    assert math.floor(peak_velocity(d, t_f) * 1e3) / 1e3 == pytest.approx(0.012)  # as printed
    assert math.floor(peak_acceleration(d, t_f) * 1e5) / 1e5 == pytest.approx(1.7e-4)  # as printed
    assert peak_velocity(-d, t_f) == peak_velocity(d, t_f)
    np.testing.assert_allclose(
        peak_velocity(np.array([d, -2 * d]), t_f), [0.012805404838, 0.025610809676], rtol=1e-10
    )


def test_table6_peaks_reproduced_by_dense_sampling():
    d, t_f = np.pi / 2, 230.0
    plan = QuinticLaw((QuinticSegment(np.array([0.0]), np.array([d]), 0.0, t_f),))
    t = np.linspace(0.0, t_f, 20001)
    h = t[1] - t[0]
    q = plan.sample(t)[0][:, 0]
    # Boundary conditions of position: q^i = 0 and q^f = pi/2 (paper's experiment: BCP = 1,58 rad).
    assert q[0] == 0.0
    assert q[-1] == d
    # Independent of the closed-form derivatives: finite differences of sampled positions only.
    v_fd = np.diff(q) / h
    a_fd = np.diff(q, 2) / h**2
    assert np.max(np.abs(v_fd)) == pytest.approx(0.012805, rel=1e-4)
    assert np.max(np.abs(a_fd)) == pytest.approx(1.7144e-4, rel=1e-4)
    assert np.max(np.abs(v_fd)) == pytest.approx(peak_velocity(d, t_f), rel=1e-6)
    assert np.max(np.abs(a_fd)) == pytest.approx(peak_acceleration(d, t_f), rel=1e-6)
    # The peaks are where the closed form says: velocity at T/2,
    # acceleration at s = 1/2 -+ sqrt(3)/6.
    assert t[np.argmax(np.abs(v_fd))] + h / 2 == pytest.approx(t_f / 2, abs=h)
    assert t[np.argmax(a_fd) + 1] == pytest.approx(S_ACC_PEAKS[0] * t_f, abs=h)
    assert t[np.argmin(a_fd) + 1] == pytest.approx(S_ACC_PEAKS[1] * t_f, abs=h)


def test_table3_velocity_gains_from_table2():
    k_v = TABLE2_OMEGA * TABLE2_RATIO  # eq. 10: K_vj = omega_motor * n
    # Corrected Table 3 (docs/papers.md).
    np.testing.assert_allclose(
        k_v, [142.857, 87.558, 115.208, 92.166, 148.148, 96.296], rtol=1e-5
    )
    # The paper printed 142.85, 87.55, 115.2, 115.2, 148.14, 85.18 rad/s. Joints 1, 2, 3 and 5 are
    # our values truncated to the printed digits; joint 4 (115.2, a copy of joint 3) and joint 6
    # (85.18) are wrong: omega * n gives 92.166 and 96.296.
    printed = {0: (142.85, 2), 1: (87.55, 2), 2: (115.2, 1), 4: (148.14, 2)}
    for j, (value, digits) in printed.items():
        scale = 10.0**digits
        assert math.floor(k_v[j] * scale) / scale == pytest.approx(value, abs=1e-9), j
    assert k_v[3] != pytest.approx(115.2, abs=1.0)
    assert k_v[5] != pytest.approx(85.18, abs=1.0)


def test_table1_move_with_table3_gains_is_set_by_joint_6():
    k_v = TABLE2_OMEGA * TABLE2_RATIO
    # Table 4's K_a needs the inertia matrix, which the paper does not give; a large K_a leaves the
    # velocity term of eq. 9 in charge.
    k_a = 1e6
    plan = plan_synchronized_quintic(TABLE1_Q_INITIAL, TABLE1_Q_FINAL, k_v, k_a)
    d = TABLE1_Q_FINAL - TABLE1_Q_INITIAL
    times = joint_minimum_times(d, k_v, k_a)
    assert int(np.argmax(times)) == 5  # joint 6: 2 pi at 96.296 rad/s
    assert plan.duration == pytest.approx(15 * 2 * np.pi / (8 * 96.2962), rel=1e-6)
    assert plan.duration == pytest.approx(0.122341, rel=1e-5)
    q, qd, _ = plan.sample(plan.duration / 2)
    assert qd[5] == pytest.approx(k_v[5], rel=1e-12)
    assert qd[1] < 0.0  # joint 2 goes from pi down to 0
    np.testing.assert_array_equal(plan.sample(plan.duration)[0], TABLE1_Q_FINAL)


def test_eq9_corrected_acceleration_term():
    d, k_a = 2.0, 10.0
    t_corrected = joint_minimum_times(d, 1e9, k_a)
    assert t_corrected == pytest.approx(math.sqrt(10 * d / (SQRT3 * k_a)), rel=1e-15)
    assert peak_acceleration(d, t_corrected) == pytest.approx(k_a, rel=1e-14)
    # The paper printed sqrt(10 |D| / (sqrt(3) K_a^2)): the peak would be K_a^2, 10x the limit here.
    t_printed = math.sqrt(10 * d / (SQRT3 * k_a**2))
    assert peak_acceleration(d, t_printed) == pytest.approx(10 * k_a, rel=1e-14)


# ---------------------------------------------------------------------------------------------
# Seeded random multi-joint moves.
# ---------------------------------------------------------------------------------------------


def _random_move(rng: np.random.Generator):
    n = 6
    q0 = rng.uniform(-np.pi, np.pi, n)
    d = rng.uniform(-3.0, 3.0, n) * rng.choice([0.01, 0.3, 1.0], n)
    k_v = rng.uniform(0.3, 3.2, n)
    k_a = rng.uniform(0.5, 8.0, n)
    return q0, q0 + d, k_v, k_a


@pytest.mark.parametrize("seed", range(40))
def test_random_moves_limits_synchronisation_and_ends(seed):
    rng = np.random.default_rng(4000 + seed)
    q0, qf, k_v, k_a = _random_move(rng)
    plan = plan_synchronized_quintic(q0, qf, k_v, k_a)
    d = qf - q0
    t_f = synchronized_duration(d, k_v, k_a)
    assert plan.duration == t_f
    assert len(plan.segments) == 1

    t = dense_times(t_f)
    q, qd, qdd = plan.sample(t)
    assert q.shape == qd.shape == qdd.shape == (t.size, 6)
    assert np.all(np.isfinite(q)) and np.all(np.isfinite(qd)) and np.all(np.isfinite(qdd))

    # No joint exceeds either limit on dense samples.
    assert np.all(np.max(np.abs(qd), axis=0) <= k_v * (1 + 1e-12))
    assert np.all(np.max(np.abs(qdd), axis=0) <= k_a * (1 + 1e-12))
    # Every joint's sampled peaks match eq. 7 and the first eq. 8 for the common t_f.
    np.testing.assert_allclose(np.max(np.abs(qd), axis=0), peak_velocity(d, t_f), rtol=1e-9)
    np.testing.assert_allclose(np.max(np.abs(qdd), axis=0), peak_acceleration(d, t_f), rtol=1e-9)

    # The constraining joint reaches the limit of the term that sets its minimum time (eq. 9).
    j = int(np.argmax(joint_minimum_times(d, k_v, k_a)))
    velocity_bound = 15 * abs(d[j]) / (8 * k_v[j]) >= math.sqrt(10 * abs(d[j]) / (SQRT3 * k_a[j]))
    if velocity_bound:
        assert np.max(np.abs(qd[:, j])) == pytest.approx(k_v[j], rel=1e-9)
        assert abs(plan.sample(t_f / 2)[1][j]) == pytest.approx(k_v[j], rel=1e-9)
    else:
        assert np.max(np.abs(qdd[:, j])) == pytest.approx(k_a[j], rel=1e-9)
        for s_peak in S_ACC_PEAKS:
            assert abs(plan.sample(s_peak * t_f)[2][j]) == pytest.approx(k_a[j], rel=1e-9)

    # All joints start and stop together: each moving joint moves in the direction of D at every
    # interior sample, and every joint is at rest at both ends.
    moving = d != 0.0
    interior = qd[1:-1][:, moving]
    assert np.all(np.sign(interior) == np.sign(d[moving]))
    for t_end in (0.0, t_f):
        _, qd_end, qdd_end = plan.sample(t_end)
        np.testing.assert_allclose(qd_end, 0.0, atol=1e-15)
        np.testing.assert_allclose(qdd_end, 0.0, atol=1e-15)
    np.testing.assert_array_equal(q[0], q0)
    np.testing.assert_allclose(plan.sample(t_f)[0], qf, atol=1e-12, rtol=0)
    np.testing.assert_array_equal(plan.sample(t_f)[0], qf)  # eq. 3 makes it exact

    # At rest outside [0, t_f].
    q_out, qd_out, qdd_out = plan.sample(np.array([-1.0, t_f + 1.0]))
    np.testing.assert_array_equal(q_out, [q0, qf])
    np.testing.assert_array_equal(qd_out, 0.0)
    np.testing.assert_array_equal(qdd_out, 0.0)

    # Non-zero end jerk 60 D / t_f^3 (docs/papers.md); 0 outside the move.
    np.testing.assert_allclose(plan.jerk(t_f), 60 * d / t_f**3, rtol=1e-12)
    np.testing.assert_allclose(plan.jerk(0.0), 60 * d / t_f**3, rtol=1e-12)
    np.testing.assert_array_equal(plan.jerk(t_f + 1e-3), 0.0)
    np.testing.assert_allclose(plan.jerk(t_f / 2), -30 * d / t_f**3, rtol=1e-12)

    # Independent consistency: integrating sampled qd gives q - q0, integrating qdd gives qd.
    np.testing.assert_allclose(cumulative_trapezoid(qd, t, axis=0, initial=0.0), q - q0, atol=1e-6)
    np.testing.assert_allclose(cumulative_trapezoid(qdd, t, axis=0, initial=0.0), qd, atol=1e-6)
    jerk = plan.jerk(t)
    np.testing.assert_allclose(cumulative_trapezoid(jerk, t, axis=0, initial=0.0), qdd, atol=1e-6)


def test_scalar_and_vector_sampling_agree():
    rng = np.random.default_rng(7)
    q0, qf, k_v, k_a = _random_move(rng)
    plan = plan_synchronized_quintic(q0, qf, k_v, k_a)
    t = np.linspace(-0.5, plan.duration + 0.5, 37)
    q, qd, qdd = plan.sample(t)
    for i, ti in enumerate(t):
        qi, qdi, qddi = plan.sample(float(ti))
        assert qi.shape == (6,)
        np.testing.assert_array_equal(qi, q[i])
        np.testing.assert_array_equal(qdi, qd[i])
        np.testing.assert_array_equal(qddi, qdd[i])
    assert plan.sample(t.reshape(1, -1))[0].shape == (1, 37, 6)


# ---------------------------------------------------------------------------------------------
# Which limit binds.
# ---------------------------------------------------------------------------------------------


def test_long_move_is_velocity_limited_short_move_acceleration_limited():
    k_v, k_a = 1.0, 1.0
    # Crossover where both terms of eq. 9 are equal: D* = (8 K_v / 15)^2 * 10 / (sqrt(3) K_a).
    d_star = (8 * k_v / 15) ** 2 * 10 / (SQRT3 * k_a)
    assert d_star == pytest.approx(1.64225, rel=1e-5)

    long_d = 3.0
    t_long = synchronized_duration([long_d], k_v, k_a)
    assert t_long == pytest.approx(15 * long_d / (8 * k_v), rel=1e-15)  # 5.625 s
    assert t_long == 5.625
    assert peak_velocity(long_d, t_long) == pytest.approx(k_v, rel=1e-15)
    assert peak_acceleration(long_d, t_long) < 0.6 * k_a

    short_d = 0.5
    t_short = synchronized_duration([short_d], k_v, k_a)
    assert t_short == pytest.approx(math.sqrt(10 * short_d / (SQRT3 * k_a)), rel=1e-15)
    assert peak_acceleration(short_d, t_short) == pytest.approx(k_a, rel=1e-15)
    assert peak_velocity(short_d, t_short) < 0.6 * k_v

    t_star = synchronized_duration([d_star], k_v, k_a)
    assert peak_velocity(d_star, t_star) == pytest.approx(k_v, rel=1e-12)
    assert peak_acceleration(d_star, t_star) == pytest.approx(k_a, rel=1e-12)


def test_constraining_joint_can_be_the_one_with_the_smaller_move():
    # Joint 0 moves further but joint 1 is much slower: joint 1 sets t_f;
    # joint 0 stays below its limits.
    d = np.array([2.0, 0.5])
    k_v = np.array([2.0, 0.1])
    k_a = np.array([5.0, 5.0])
    t_f = synchronized_duration(d, k_v, k_a)
    assert t_f == pytest.approx(15 * 0.5 / (8 * 0.1), rel=1e-15)
    assert peak_velocity(d[0], t_f) < k_v[0]
    assert peak_velocity(d[1], t_f) == pytest.approx(k_v[1], rel=1e-15)


# ---------------------------------------------------------------------------------------------
# Degenerate moves, direction, several goals.
# ---------------------------------------------------------------------------------------------


def test_zero_displacement_is_no_motion_and_no_nan():
    assert joint_minimum_times(0.0, 1.0, 1.0) == 0.0
    np.testing.assert_array_equal(joint_minimum_times(np.zeros(3), 1.0, 1.0), np.zeros(3))
    assert synchronized_duration(np.zeros(6), 1.0, 1.0) == 0.0
    assert peak_velocity(0.0, 0.0) == 0.0
    assert peak_acceleration(0.0, 0.0) == 0.0

    q0 = np.array([0.1, -0.2, 0.3, 0.0, 1.0, -1.0])
    plan = plan_synchronized_quintic(q0, q0, 1.0, 1.0)
    assert plan.duration == 0.0
    t = np.array([-1.0, 0.0, 0.5, 2.0])
    q, qd, qdd = plan.sample(t)
    jerk = plan.jerk(t)
    for array in (q, qd, qdd, jerk):
        assert np.all(np.isfinite(array))
    np.testing.assert_array_equal(q, np.tile(q0, (4, 1)))
    np.testing.assert_array_equal(qd, 0.0)
    np.testing.assert_array_equal(qdd, 0.0)
    np.testing.assert_array_equal(jerk, 0.0)


def test_joints_with_zero_displacement_stay_put():
    q0 = np.array([0.0, 1.0, 2.0])
    qf = np.array([1.5, 1.0, 2.0])
    plan = plan_synchronized_quintic(q0, qf, [1.0, 1e-3, 1e-3], [1.0, 1e-3, 1e-3])
    q, qd, qdd = plan.sample(dense_times(plan.duration, 2001))
    np.testing.assert_array_equal(q[:, 1:], np.tile(q0[1:], (q.shape[0], 1)))
    np.testing.assert_array_equal(qd[:, 1:], 0.0)
    np.testing.assert_array_equal(qdd[:, 1:], 0.0)


def test_tiny_displacement_gives_finite_samples():
    plan = plan_synchronized_quintic(np.zeros(2), [1e-300, 0.0], 1.0, 1.0)
    assert plan.duration > 0.0
    t = np.linspace(0.0, plan.duration, 11)
    for array in (*plan.sample(t), plan.jerk(t)):
        assert np.all(np.isfinite(array))


def test_negative_displacement_mirrors_positive():
    d = np.array([1.2, -0.4, 2.5, 0.0, -3.0, 0.7])
    k_v = np.array([1.0, 0.5, 2.0, 1.0, 1.5, 0.8])
    k_a = np.array([2.0, 1.0, 4.0, 1.0, 3.0, 0.9])
    np.testing.assert_array_equal(
        joint_minimum_times(-d, k_v, k_a), joint_minimum_times(d, k_v, k_a)
    )
    plan_pos = plan_synchronized_quintic(np.zeros(6), d, k_v, k_a)
    plan_neg = plan_synchronized_quintic(np.zeros(6), -d, k_v, k_a)
    assert plan_neg.duration == plan_pos.duration
    t = dense_times(plan_pos.duration, 501)
    for a_pos, a_neg in zip(plan_pos.sample(t), plan_neg.sample(t)):
        np.testing.assert_array_equal(a_neg, -a_pos)
    np.testing.assert_array_equal(plan_neg.jerk(t), -plan_pos.jerk(t))


def test_several_goals_stop_at_each():
    rng = np.random.default_rng(1234)
    q0 = rng.uniform(-1.0, 1.0, 6)
    goals = rng.uniform(-2.0, 2.0, (4, 6))
    goals = np.insert(goals, 2, goals[1], axis=0)  # repeated goal: zero move, skipped
    k_v = rng.uniform(0.5, 2.0, 6)
    k_a = rng.uniform(1.0, 5.0, 6)
    plan = plan_synchronized_quintic(q0, goals, k_v, k_a, position_lower=-2.0, position_upper=2.0)

    assert len(plan.segments) == 4
    starts = [q0, goals[0], goals[1], goals[3]]
    ends = [goals[0], goals[1], goals[3], goals[4]]
    t = 0.0
    for segment, qs, qg in zip(plan.segments, starts, ends):
        np.testing.assert_array_equal(segment.q_start, qs)
        np.testing.assert_array_equal(segment.q_goal, qg)
        assert segment.t_start == t
        assert segment.duration == synchronized_duration(qg - qs, k_v, k_a)
        t = segment.t_end
    assert plan.duration == t
    np.testing.assert_allclose(plan.duration, sum(s.duration for s in plan.segments), rtol=1e-15)

    # At rest, exactly on the goal, at every boundary; positions continuous across it.
    breakpoints = plan.breakpoints
    q_b, qd_b, qdd_b = plan.sample(breakpoints)
    np.testing.assert_array_equal(q_b, np.array([q0, *ends]))
    np.testing.assert_allclose(qd_b, 0.0, atol=1e-15)
    np.testing.assert_allclose(qdd_b, 0.0, atol=1e-15)
    eps = 1e-7
    q_left = plan.sample(breakpoints[1:-1] - eps)[0]
    q_right = plan.sample(breakpoints[1:-1] + eps)[0]
    np.testing.assert_allclose(q_left, q_right, atol=1e-12)

    # Limits on dense samples of the whole plan, and the integral checks across boundaries.
    t = np.unique(
        np.concatenate([dense_times(s.duration, 5001) + s.t_start for s in plan.segments])
    )
    q, qd, qdd = plan.sample(t)
    assert np.all(np.max(np.abs(qd), axis=0) <= k_v * (1 + 1e-12))
    assert np.all(np.max(np.abs(qdd), axis=0) <= k_a * (1 + 1e-12))
    assert np.all(q >= -2.0) and np.all(q <= 2.0)
    np.testing.assert_allclose(cumulative_trapezoid(qd, t, axis=0, initial=0.0), q - q0, atol=1e-6)
    np.testing.assert_allclose(cumulative_trapezoid(qdd, t, axis=0, initial=0.0), qd, atol=1e-6)

    # Jerk at a boundary is the value of the segment starting there.
    second = plan.segments[1]
    np.testing.assert_allclose(
        plan.jerk(second.t_start), 60 * second.displacement / second.duration**3, rtol=1e-12
    )
    # Before the plan: at rest on q_start; after: at rest on the last goal.
    np.testing.assert_array_equal(plan.sample(-3.0)[0], q0)
    np.testing.assert_array_equal(plan.sample(plan.duration + 3.0)[0], goals[-1])


def test_single_goal_as_vector_equals_one_row_matrix():
    q0 = np.zeros(6)
    goal = np.array([0.5, -0.5, 1.0, 0.0, 0.2, -0.1])
    a = plan_synchronized_quintic(q0, goal, 1.0, 2.0)
    b = plan_synchronized_quintic(q0, goal[None, :], 1.0, 2.0)
    assert a.duration == b.duration
    np.testing.assert_array_equal(a.q_goal, b.q_goal)


def test_plan_is_immutable():
    plan = plan_synchronized_quintic(np.zeros(2), [1.0, 1.0], 1.0, 1.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        plan.segments = ()
    with pytest.raises(dataclasses.FrozenInstanceError):
        plan.segments[0].duration = 1.0
    with pytest.raises(ValueError):
        plan.segments[0].q_goal[0] = 3.0  # read-only array


# ---------------------------------------------------------------------------------------------
# Input validation.
# ---------------------------------------------------------------------------------------------

Q0 = np.zeros(6)
GOALS = np.array([[0.5, 0.2, -0.3, 0.0, 0.1, 0.4], [1.0, -0.5, 0.3, 0.2, 0.0, -0.4]])


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"goals": np.zeros((2, 5))}, r"goals must have shape \(m, 6\) or \(6,\).*\(2, 5\)"),
        ({"goals": np.zeros((2, 3, 6))}, r"goals must have shape .*\(2, 3, 6\)"),
        ({"goals": np.zeros((0, 6))}, r"goals must contain at least one goal"),
        ({"goals": [[0.1, 0.2, np.nan, 0, 0, 0]]}, r"goals\[0, 2\] must be finite"),
        ({"goals": "abc"}, r"goals"),
        ({"q_start": np.zeros((1, 6))}, r"q_start must have shape \(n,\)"),
        ({"q_start": [0, 0, np.inf, 0, 0, 0]}, r"q_start\[2\] must be finite"),
        ({"velocity_limit": [1, 1, 1, 0.0, 1, 1]}, r"velocity_limit\[3\] \(joint 4\) must be > 0"),
        ({"velocity_limit": -1.0}, r"velocity_limit\[0\] \(joint 1\) must be > 0"),
        ({"velocity_limit": np.ones(5)}, r"velocity_limit must be a scalar or have shape \(6,\)"),
        ({"velocity_limit": np.nan}, r"velocity_limit\[0\] must be finite"),
        ({"acceleration_limit": [1, 1, 1, 1, 1, -2.0]}, r"acceleration_limit\[5\] \(joint 6\)"),
        ({"acceleration_limit": np.inf}, r"acceleration_limit\[0\] must be finite"),
        ({"position_upper": 0.9}, r"goals\[1\]\[0\] \(joint 1\) = 1.0 rad is above position_upper\[0\]"),
        ({"position_lower": -0.4}, r"goals\[1\]\[1\] \(joint 2\) = -0.5 rad is below position_lower\[1\]"),
        ({"position_lower": 0.05}, r"q_start\[0\] \(joint 1\) = 0.0 rad is below position_lower\[0\]"),
        (
            {"position_lower": [-1, -1, 2, -1, -1, -1], "position_upper": 1.0},
            r"position_lower\[2\] = 2.0 is above position_upper\[2\]",
        ),
        ({"position_upper": [1.0] * 5}, r"position_upper must be a scalar or have shape \(6,\)"),
    ],
)
def test_plan_rejects_bad_inputs(kwargs, pattern):
    args = {"q_start": Q0, "goals": GOALS, "velocity_limit": 1.0, "acceleration_limit": 1.0}
    args.update(kwargs)
    with pytest.raises(ValueError, match=pattern):
        plan_synchronized_quintic(**args)


def test_functions_reject_bad_inputs():
    with pytest.raises(ValueError, match=r"velocity_limit\[1\] \(joint 2\) must be > 0"):
        joint_minimum_times([1.0, 1.0], [1.0, 0.0], 1.0)
    with pytest.raises(ValueError, match=r"acceleration_limit must be > 0"):
        joint_minimum_times(1.0, 1.0, 0.0)
    with pytest.raises(ValueError, match=r"displacement\[1\] must be finite"):
        synchronized_duration([1.0, np.nan], 1.0, 1.0)
    with pytest.raises(ValueError, match=r"broadcastable"):
        joint_minimum_times([1.0, 2.0], [1.0, 2.0, 3.0], 1.0)
    with pytest.raises(ValueError, match=r"duration must be > 0"):
        peak_velocity(1.0, 0.0)
    with pytest.raises(ValueError, match=r"duration must be >= 0"):
        peak_acceleration(1.0, -1.0)
    with pytest.raises(ValueError, match=r"segments must contain at least one"):
        QuinticLaw(())
    with pytest.raises(ValueError, match=r"duration must be finite and >= 0"):
        QuinticSegment(np.zeros(2), np.ones(2), 0.0, -1.0)
    with pytest.raises(ValueError, match=r"duration must be > 0 .* q_goal differs"):
        QuinticSegment(np.zeros(2), np.ones(2), 0.0, 0.0)
    with pytest.raises(ValueError, match=r"q_goal must have the shape of q_start"):
        QuinticSegment(np.zeros(2), np.ones(3), 0.0, 1.0)
    with pytest.raises(ValueError, match=r"segments\[1\] starts at t = 0.5 s"):
        QuinticLaw(
            (
                QuinticSegment(np.zeros(1), np.ones(1), 0.0, 1.0),
                QuinticSegment(np.ones(1), np.zeros(1), 0.5, 1.0),
            )
        )
    plan = plan_synchronized_quintic(np.zeros(2), [1.0, 1.0], 1.0, 1.0)
    with pytest.raises(ValueError, match=r"t must be finite"):
        plan.sample(np.nan)
    with pytest.raises(ValueError, match=r"t\[1\] must be finite"):
        plan.jerk([0.0, np.inf])


def test_random_set_covers_both_binding_limits():
    """The seeded moves above exercise both branches of eq. 9 for the constraining joint."""
    bound = []
    for seed in range(40):
        q0, qf, k_v, k_a = _random_move(np.random.default_rng(4000 + seed))
        d = qf - q0
        j = int(np.argmax(joint_minimum_times(d, k_v, k_a)))
        bound.append(15 * abs(d[j]) / (8 * k_v[j]) >= math.sqrt(10 * abs(d[j]) / (SQRT3 * k_a[j])))
    assert 5 <= sum(bound) <= 35


def test_scalar_rates_match_the_vectorised_sample():
    plan = plan_synchronized_quintic(np.zeros(6), [[1.0, -0.5, 0.2, 0.0, 2.0, -1.0], [0.5, 0.5, 0.5, 0.5, 0.5, 0.5]], 1.05, 1.4)
    times = np.concatenate([[-1.0, 0.0], np.linspace(0.0, plan.duration, 997), [plan.duration, plan.duration + 1.0]])
    _, qd, qdd = plan.sample(times)
    for row, t in enumerate(times):
        rate, acceleration = plan.rates_at(float(t))
        np.testing.assert_allclose(rate, qd[row], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(acceleration, qdd[row], rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("limit, field, pattern", [
    (dict(velocity_limit=[1e-9, 1, 1, 1, 1, 1]), ("velocity_limit", 0),
     r"^velocity_limit\[0\] = 1e-09 rad/s \(joint 1\) makes the move to goal 0 \(0\.5 rad on that joint\) last "
     r"9\.375e\+08 s, ending at t = 9\.375e\+08 s, after the 600 s a run may last"),
    (dict(acceleration_limit=[1, 1, 1e-9, 1, 1, 1]), ("acceleration_limit", 2),
     r"^acceleration_limit\[2\] = 1e-09 rad/s\^2 \(joint 3\) makes the move to goal 1"),
])
def test_a_plan_longer_than_a_run_is_refused_at_the_limit_that_makes_it(limit, field, pattern):
    """Was "MemoryError: Unable to allocate 698. GiB" where the duration set an array's length."""
    from drake_traj.errors import Cause, DrakeTrajError

    start = np.zeros(6)
    goals = [[0.5, 0.0, 0.0, 0.0, 0.0, 0.0], [0.5, 0.0, 0.5, 0.0, 0.0, 0.0]]
    limits = dict(velocity_limit=[1.0] * 6, acceleration_limit=[1.0] * 6) | limit
    with pytest.raises(DrakeTrajError, match=pattern) as caught:
        plan_synchronized_quintic(start, goals, **limits)
    assert caught.value.field == field and caught.value.cause is Cause.INFEASIBLE
    plan_synchronized_quintic(start, goals, velocity_limit=[5e-3] * 6, acceleration_limit=[1.0] * 6)  # 375 s: planned


def test_a_scenarios_limit_too_small_for_a_run_is_refused_at_its_line(tmp_path):
    from drake_traj import cli, load_scenario
    from drake_traj.scenario import make_planner

    text = (DIAGRAMS / "quintic_ptp.yaml").read_text()
    path = tmp_path / "slow.yaml"
    path.write_text(text.replace("velocity_limit: [1.05,", "velocity_limit: [1.0e-9,", 1))
    with pytest.raises(ValueError, match=r"line 12, column \d+: planner.velocity_limit\[0\] = 1e-09 rad/s \(joint 1\)"):
        make_planner(load_scenario(path))
    assert cli.main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
