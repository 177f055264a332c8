"""Tests for the Cartesian stage of Li et al. 2019 (Li, Zhang, Zhou): break-point limits, the
velocity look-ahead and the cubic ACC/DEC profile.

The paper's OCR text is checked against the corrected forms of ``docs/papers.md`` (seed
002); where the paper printed something else, the comment says what it printed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from drake_traj.planners.li.acc_dec import AccDecCase, acc_dec_profile, average_acceleration, classify_acc_dec
from drake_traj.planners.li.cartesian import (
    break_point_geometry,
    break_point_limits,
    forward_backward_pass,
    look_ahead,
    plan_cartesian_path,
)

# Table 4 of the paper: Sup |V_m| = 200 mm/s, Sup |a_m| = 100 mm/s^2.
V_M = 0.2
A_M = 0.1


def random_rotation(rng) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.diag(r))


def arc_points(radius, angle, num, rng=None, center=(0.3, 0.1, 0.05)):
    """``num`` points at equal angles on an arc of ``radius`` [m] spanning ``angle`` [rad]."""
    theta = np.linspace(0.0, angle, num)
    local = np.stack([radius * np.cos(theta), radius * np.sin(theta), np.zeros(num)], axis=1)
    rotation = np.eye(3) if rng is None else random_rotation(rng)
    return local @ rotation.T + np.asarray(center)


def rounded_rectangle(width, height, radius, step) -> np.ndarray:
    """Closed path in the XY plane (Z = 0) like the paper's Fig. 6: straight sides sampled every
    ``step`` and quarter arcs of ``radius``; starts and ends at the middle of the bottom side."""
    x0, y0 = 0.25, 0.15
    pieces = []

    def line(a, b):
        n = max(int(math.ceil(np.linalg.norm(np.subtract(b, a)) / step)), 1)
        return np.linspace(a, b, n + 1)[:-1]

    def arc(center, start_angle):
        theta = start_angle + np.linspace(0.0, np.pi / 2, int(math.ceil(radius * np.pi / 2 / step)) + 1)
        return np.stack([center[0] + radius * np.cos(theta), center[1] + radius * np.sin(theta)], 1)[:-1]

    w, h, r = width / 2, height / 2, radius
    pieces += [line((x0, y0 - h), (x0 + w - r, y0 - h)), arc((x0 + w - r, y0 - h + r), -np.pi / 2)]
    pieces += [line((x0 + w, y0 - h + r), (x0 + w, y0 + h - r)), arc((x0 + w - r, y0 + h - r), 0.0)]
    pieces += [line((x0 + w - r, y0 + h), (x0 - w + r, y0 + h)), arc((x0 - w + r, y0 + h - r), np.pi / 2)]
    pieces += [line((x0 - w, y0 + h - r), (x0 - w, y0 - h + r)), arc((x0 - w + r, y0 - h + r), np.pi)]
    pieces += [line((x0 - w + r, y0 - h), (x0, y0 - h)), np.array([[x0, y0 - h]])]
    xy = np.concatenate(pieces)
    return np.column_stack([xy, np.zeros(len(xy))])


def random_polyline(rng, num) -> np.ndarray:
    """A random walk with segment lengths spanning two decades and arbitrary turns."""
    steps = rng.normal(size=(num - 1, 3))
    steps *= (10.0 ** rng.uniform(-3.0, -1.0, size=num - 1) / np.linalg.norm(steps, axis=1))[:, None]
    # Some straight runs, so that v_m is reached.
    straight = rng.random(num - 1) < 0.3
    for i in np.flatnonzero(straight[1:]) + 1:
        steps[i] = steps[i - 1] / np.linalg.norm(steps[i - 1]) * np.linalg.norm(steps[i])
    return np.concatenate([[[0.0, 0.0, 0.0]], np.cumsum(steps, axis=0)])


# ---------------------------------------------------------------------------------------------
# Break-point limits (eq. 1-7, corrected).
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("radius", [0.005, 0.02, 0.15])
@pytest.mark.parametrize("num", [5, 40])
def test_arc_limit_is_sqrt_a_m_r(radius, num):
    rng = np.random.default_rng(int(radius * 1e4) + num)
    points = arc_points(radius, 1.5 * np.pi, num, rng)
    geometry = break_point_geometry(points)
    chord = 2.0 * radius * math.sin(1.5 * np.pi / (num - 1) / 2.0)
    np.testing.assert_allclose(geometry.lengths, chord, rtol=1e-12)
    # Corrected eq. 6: K_i = |u_{i+1} - u_i| = 2 sin(phi / 2) = chord / R on an equal-chord arc.
    np.testing.assert_allclose(geometry.direction_change[1:-1], chord / radius, rtol=1e-9)
    np.testing.assert_allclose(geometry.curvature[1:-1], 1.0 / radius, rtol=1e-9)
    assert geometry.direction_change[0] == geometry.direction_change[-1] == 0.0

    v_m = 10.0  # well above sqrt(a_m R): the arc sets the limit
    limits = break_point_limits(points, v_m, A_M)
    assert limits[0] == limits[-1] == 0.0  # v_0 = v_n = 0
    np.testing.assert_allclose(limits[1:-1], math.sqrt(A_M * radius), rtol=1e-9)
    # A step length at least the chord changes nothing (dl_i = min{l_step, l_i} = l_i) ...
    np.testing.assert_allclose(break_point_limits(points, v_m, A_M, step_length=2 * chord), limits)
    # ... a shorter one lowers the limit to sqrt(a_m l_step / K_i) (eq. 4 with dl_i = l_step).
    short = break_point_limits(points, v_m, A_M, step_length=chord / 4)
    np.testing.assert_allclose(short[1:-1], math.sqrt(A_M * radius / 4), rtol=1e-9)
    # v_m caps it (eq. 4: min{v_m, ...}).
    capped = break_point_limits(points, 0.5 * math.sqrt(A_M * radius), A_M)
    np.testing.assert_array_equal(capped[1:-1], 0.5 * math.sqrt(A_M * radius))


def test_straight_line_and_corner_limits():
    line = np.outer(np.linspace(0.0, 0.3, 7), [1.0, 2.0, 2.0]) / 3.0
    limits = break_point_limits(line, V_M, A_M)
    np.testing.assert_array_equal(limits, [0.0] + [V_M] * 5 + [0.0])  # K_i = 0: v_m
    # A 90-degree corner after 10 mm: K = sqrt(2), v = sqrt(a_m * 0.01 / sqrt(2)).
    corner = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.01, 0.02, 0.0], [0.01, 0.03, 0.0]])
    geometry = break_point_geometry(corner)
    np.testing.assert_allclose(geometry.direction_change, [0.0, math.sqrt(2.0), 0.0, 0.0], atol=1e-15)
    limits = break_point_limits(corner, V_M, A_M)
    # dl_1 = l_1 = 0.01 m: the incoming segment (Corrected (docs/papers.md): dl_i = min{l_step, l_i}).
    np.testing.assert_allclose(limits, [0.0, math.sqrt(A_M * 0.01 / math.sqrt(2.0)), V_M, 0.0])
    # The index fix (docs/papers.md): the turn is charged to P_1 (from P_0P_1 to P_1P_2), not P_2.
    assert limits[2] == V_M


# ---------------------------------------------------------------------------------------------
# Look-ahead (Fig. 2, eq. 8-10 with A = (2/3) a_m).
# ---------------------------------------------------------------------------------------------


def assert_look_ahead_properties(v, limits, lengths, a_max):
    acc = average_acceleration(a_max)
    assert acc == pytest.approx(2.0 / 3.0 * a_max, rel=1e-15)
    assert v[0] == 0.0 and v[-1] == 0.0
    assert np.all(v >= 0.0)
    assert np.all(v <= limits)
    # eq. 8 holds everywhere: |v_i^2 - v_{i-1}^2| <= 2 A l_i (to round-off).
    jump = np.abs(np.diff(v**2))
    assert np.all(jump <= 2.0 * acc * lengths * (1.0 + 1e-12) + 1e-300)


def test_look_ahead_properties_and_equals_forward_backward_on_random_paths():
    rng = np.random.default_rng(2019)
    forward_only_fails = 0
    for trial in range(60):
        points = random_polyline(rng, int(rng.integers(2, 120)))
        v_max = rng.uniform(0.05, 1.0)
        a_max = rng.uniform(0.05, 5.0)
        step = None if trial % 2 else rng.uniform(1e-3, 5e-2)
        limits = break_point_limits(points, v_max, a_max, step)
        lengths = break_point_geometry(points).lengths
        multi = look_ahead(limits, lengths, a_max)
        single = forward_backward_pass(limits, lengths, a_max)
        assert_look_ahead_properties(multi, limits, lengths, a_max)
        assert_look_ahead_properties(single, limits, lengths, a_max)
        # Both end on the same chains of eq. 9 / eq. 10 from the same binding limits: bit-equal.
        np.testing.assert_array_equal(multi, single)
        # Largest feasible: every speed is at its limit or pinned by a neighbour through eq. 9/10.
        acc = average_acceleration(a_max)
        reach = np.sqrt(np.minimum(
            np.append(multi[1:] ** 2 + 2 * acc * lengths, np.inf),
            np.insert(multi[:-1] ** 2 + 2 * acc * lengths, 0, np.inf),
        ))
        np.testing.assert_allclose(multi, np.minimum(limits, reach), rtol=1e-12)
        # A forward pass alone (the "traditional" single adjustment) is not enough here.
        forward = limits.copy()
        for i in range(1, forward.size):
            forward[i] = min(forward[i], math.sqrt(forward[i - 1] ** 2 + 2 * acc * lengths[i - 1]))
        forward_only_fails += np.any(np.abs(np.diff(forward**2)) > 2 * acc * lengths * (1 + 1e-12))
    assert forward_only_fails > 40


def test_look_ahead_steps_back_where_one_forward_pass_is_not_enough():
    # Every point allows 1 m/s except the last; stopping needs several segments: eq. 10 must be
    # applied backwards through the chain (the "i = i - 1" branch of Fig. 2).
    a_max = 1.5  # A = 1
    limits = np.array([0.0, 1.0, 1.0, 1.0, 1.0, 0.0])
    lengths = np.full(5, 0.02)  # 2 A l = 0.04 per segment
    v = look_ahead(limits, lengths, a_max)
    expected = np.sqrt(0.04 * np.array([0, 1, 2, 2, 1, 0]))
    np.testing.assert_allclose(v, expected, rtol=1e-14)
    np.testing.assert_allclose(forward_backward_pass(limits, lengths, a_max), expected, rtol=1e-14)
    # The input is not modified.
    np.testing.assert_array_equal(limits, [0.0, 1.0, 1.0, 1.0, 1.0, 0.0])


# ---------------------------------------------------------------------------------------------
# The cubic ACC/DEC profile (eq. 11-13, Tables 1-2).
# ---------------------------------------------------------------------------------------------


def corrected_time(case, length, v_s, v_e, v_m, acc) -> float:
    """Table 2 as corrected in docs/papers.md (A = (2/3) a_m). The paper's Table 2 uses a_m; see docs/papers.md."""
    v_a = math.sqrt((2 * acc * length + v_s**2 + v_e**2) / 2)  # eq. 13 (corrected)
    return {
        AccDecCase.I: length / v_m,
        AccDecCase.II: (v_e - v_s) / acc,
        AccDecCase.III: (v_s - v_e) / acc,
        AccDecCase.IV: (2 * acc * length + (v_m - v_e) ** 2) / (2 * acc * v_m),
        AccDecCase.V: (2 * acc * length + (v_m - v_s) ** 2) / (2 * acc * v_m),
        AccDecCase.VI: (2 * v_a - v_s - v_e) / acc,
        AccDecCase.VII: (2 * acc * length + (v_m - v_s) ** 2 + (v_m - v_e) ** 2) / (2 * acc * v_m),
    }[case]


def expected_case(length, v_s, v_e, v_m, acc) -> AccDecCase:
    """Table 1's boundary conditions, written out independently of the module."""
    l_min = abs(v_e**2 - v_s**2) / (2 * acc)
    l_e = (2 * v_m**2 - v_s**2 - v_e**2) / (2 * acc)  # eq. 13 (corrected: A, not a_m)
    if v_s == v_e == v_m:
        return AccDecCase.I
    if v_s != v_e and abs(length - l_min) <= 1e-12 * l_min:
        return AccDecCase.II if v_e > v_s else AccDecCase.III
    if v_s == v_m:
        return AccDecCase.IV
    if v_e == v_m:
        return AccDecCase.V
    return AccDecCase.VI if length < l_e else AccDecCase.VII


def random_segment(rng):
    v_m = rng.uniform(0.05, 2.0)
    a_max = rng.uniform(0.05, 5.0)
    acc = 2.0 / 3.0 * a_max

    def speed():
        u = rng.random()
        return 0.0 if u < 0.2 else v_m if u < 0.5 else rng.uniform(0.0, v_m)

    v_s, v_e = speed(), speed()
    l_min = abs(v_e**2 - v_s**2) / (2 * acc)
    l_e = (2 * v_m**2 - v_s**2 - v_e**2) / (2 * acc)
    u = rng.random()
    if u < 0.3 and l_min > 0.0:
        length = l_min
    elif u < 0.6 and l_e > l_min:
        length = rng.uniform(l_min, l_e)
    else:
        length = l_min + rng.uniform(0.0, 2.0) * max(l_e - l_min, 0.0) + rng.uniform(1e-3, 1.0)
    return length, v_s, v_e, v_m, a_max


def test_acc_dec_random_segments_cover_all_seven_cases():
    rng = np.random.default_rng(11)
    counts = dict.fromkeys(AccDecCase, 0)
    tau = np.linspace(0.0, 1.0, 41)
    for _ in range(4000):
        length, v_s, v_e, v_m, a_max = random_segment(rng)
        acc = 2.0 / 3.0 * a_max
        profile = acc_dec_profile(length, v_s, v_e, v_m, a_max)
        case = profile.case
        counts[case] += 1
        assert case == expected_case(length, v_s, v_e, v_m, acc)
        assert classify_acc_dec(length, v_s, v_e, v_m, a_max) == case
        # Table 2 (docs/papers.md) times.
        assert profile.duration == pytest.approx(corrected_time(case, length, v_s, v_e, v_m, acc), rel=1e-9)
        # Dense samples plus both ramp midpoints (where the bell peaks).
        t = np.concatenate([tau * profile.duration, [0.5 * profile.t_acc],
                            [profile.duration - 0.5 * profile.t_dec]])
        s, v, a = profile.sample(t)
        s_end, v_end, a_end = profile.sample(profile.duration)
        s0, v0, a0 = profile.sample(0.0)
        assert s0 == 0.0 and v0 == pytest.approx(v_s, abs=1e-15) and a0 == 0.0
        assert s_end == length and v_end == pytest.approx(v_e, abs=1e-15)
        # The distance is covered by the speed law itself, not only by the end value of s: v is a
        # cubic in t on each phase, so Simpson's rule per phase integrates it exactly.
        edges = np.cumsum([0.0, profile.t_acc, profile.t_uniform, profile.t_dec])
        _, v_edges, _ = profile.sample(edges)
        _, v_mids, _ = profile.sample(0.5 * (edges[1:] + edges[:-1]))
        covered = np.sum(np.diff(edges) * (v_edges[1:] + 4 * v_mids + v_edges[:-1]) / 6)
        assert covered == pytest.approx(length, rel=1e-9)
        s_edges, _, _ = profile.sample(edges[1:3])  # s is continuous at the phase boundaries
        np.testing.assert_allclose(s_edges, np.cumsum(
            np.diff(edges) * (v_edges[1:] + 4 * v_mids + v_edges[:-1]) / 6)[:2], rtol=1e-9,
            atol=1e-12 * length)
        assert a_end == 0.0
        assert np.all(np.diff(s[:len(tau)]) >= 0.0)  # never backwards
        assert np.all(v >= -1e-15) and np.all(v <= v_m * (1.0 + 1e-12))
        assert np.all(np.abs(a) <= a_max * (1.0 + 1e-9))
        if case == AccDecCase.I:
            assert np.all(a == 0.0) and np.all(v == v_m)
        else:
            # Every ramp peaks at exactly a_m (mean A = 2/3 a_m); the paper's eq. 8-13 with a_m
            # would peak at 1.5 a_m (docs/papers.md).
            assert np.max(np.abs(a)) == pytest.approx(a_max, rel=1e-9)
            assert profile.peak_acceleration == pytest.approx(a_max, rel=1e-9)
    # All seven cases are hit; all but I (uniform) reach a_m.
    assert all(count > 0 for count in counts.values()), counts


@pytest.mark.parametrize(
    "args, case, phases",
    [
        # (L, V_s, V_e, V_m, a_m) with a_m = 1.5, so A = 1.
        ((2.0, 1.0, 1.0, 1.0, 1.5), AccDecCase.I, (0.0, 2.0, 0.0)),
        ((0.5, 0.0, 1.0, 1.0, 1.5), AccDecCase.II, (1.0, 0.0, 0.0)),
        ((0.375, 1.0, 0.5, 1.0, 1.5), AccDecCase.III, (0.0, 0.0, 0.5)),
        ((1.0, 1.0, 0.0, 1.0, 1.5), AccDecCase.IV, (0.0, 0.5, 1.0)),
        ((1.0, 0.0, 1.0, 1.0, 1.5), AccDecCase.V, (1.0, 0.5, 0.0)),
        ((0.25, 0.0, 0.0, 1.0, 1.5), AccDecCase.VI, (0.5, 0.0, 0.5)),
        ((2.0, 0.0, 0.0, 1.0, 1.5), AccDecCase.VII, (1.0, 1.0, 1.0)),
    ],
)
def test_acc_dec_hand_cases_and_derivatives(args, case, phases):
    profile = acc_dec_profile(*args)
    assert profile.case == case
    np.testing.assert_allclose((profile.t_acc, profile.t_uniform, profile.t_dec), phases, atol=1e-15)
    # s, v, a are consistent (v = ds/dt, a = dv/dt): the law is C^2 in s.
    t = np.linspace(0.0, profile.duration, 200001)
    h = t[1] - t[0]
    s, v, a = profile.sample(t)
    np.testing.assert_allclose(np.gradient(s, h, edge_order=2), v, atol=1e-8)
    # (atol: central differences straddle the jerk steps at the phase ends, error ~ h * jerk)
    np.testing.assert_allclose(np.gradient(v, h, edge_order=2), a, atol=2e-5)
    # Eq. 11 at the ramp's mid-time: v = (V_0 + V_1) / 2 and a = 1.5 (V_1 - V_0) / T_r.
    if profile.t_acc > 0:
        _, v_mid, a_mid = profile.sample(profile.t_acc / 2)
        assert v_mid == pytest.approx((profile.v_start + profile.v_cruise) / 2, rel=1e-14)
        assert a_mid == pytest.approx(1.5, rel=1e-14)  # = a_m


def test_look_ahead_output_is_classified_without_error():
    # After the look-ahead, L and L_min agree only to round-off: such segments are II or III.
    v = forward_backward_pass([0.0, 1.0, 1.0, 0.0], [0.1, 0.1, 0.1], 1.5)
    cases = [classify_acc_dec(0.1, v[k], v[k + 1], 1.0, 1.5) for k in range(3)]
    assert cases == [AccDecCase.II, AccDecCase.VI, AccDecCase.III]


# ---------------------------------------------------------------------------------------------
# The whole path.
# ---------------------------------------------------------------------------------------------


def test_two_point_path_is_one_case_vi_segment():
    # L = 0.1 m < L_e = 2 v_m^2 / (2A) = 0.6 m: accelerate to V_a = sqrt(A L), decelerate to rest.
    plan = plan_cartesian_path([[0.0, 0.0, 0.0], [0.06, 0.0, 0.08]], V_M, A_M)
    acc = 2 / 3 * A_M
    assert plan.cases.tolist() == [AccDecCase.VI]
    assert plan.profiles[0].v_cruise == pytest.approx(math.sqrt(acc * 0.1), rel=1e-14)
    assert plan.duration == pytest.approx(2 * math.sqrt(acc * 0.1) / acc, rel=1e-14)
    middle = plan.sample(plan.duration / 2)
    np.testing.assert_allclose(middle.position[0], [0.03, 0.0, 0.04], rtol=1e-12)


@pytest.fixture(scope="module")
def closed_path_plan():
    # Fig. 6-like closed path: 200 x 120 mm, 20 mm corner radius, 1 mm points; Table 4 limits.
    points = rounded_rectangle(0.2, 0.12, 0.02, 0.001)
    return plan_cartesian_path(points, V_M, A_M)


def test_whole_path_time_law(closed_path_plan):
    plan = closed_path_plan
    n = len(plan.points) - 1
    assert len(plan.profiles) == n
    # On the arcs the limit is sqrt(a_m R) = 44.7 mm/s.
    assert np.min(plan.limits[1:-1]) == pytest.approx(math.sqrt(A_M * 0.02), rel=1e-3)
    # Break points are reached at the segment joints with the look-ahead speeds.
    joints = plan.sample(plan.segment_times)
    np.testing.assert_allclose(joints.position, plan.points, atol=1e-15)
    np.testing.assert_allclose(joints.speed, plan.velocities, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(joints.s, plan.cumulative_length, rtol=1e-12)
    # Dense sampling: within the limits, starts and ends at rest at the end points.
    dense = plan.sample_uniform(1e-3)
    assert dense.t[-1] == plan.duration
    np.testing.assert_array_equal(dense.position[0], plan.points[0])
    np.testing.assert_allclose(dense.position[-1], plan.points[-1], atol=1e-15)
    assert dense.speed[0] == 0.0 and dense.speed[-1] == 0.0
    assert np.all(dense.speed <= V_M * (1 + 1e-12))
    assert np.all(np.abs(dense.acceleration) <= A_M * (1 + 1e-9))
    assert np.max(np.abs(dense.acceleration)) > 0.99 * A_M
    assert np.all(np.diff(dense.s) >= 0.0)
    # s advances at the sampled speed; the position moves along the polyline by s (a chord across
    # a break point is at most the arc length between the samples).
    h = np.diff(dense.t)
    mid = plan.sample(0.5 * (dense.t[1:] + dense.t[:-1]))
    simpson = (dense.speed[1:] + 4.0 * mid.speed + dense.speed[:-1]) / 6.0
    # (atol: Simpson is exact for the cubic ramps but not across the jerk steps at phase ends)
    np.testing.assert_allclose(np.diff(dense.s) / h, simpson, atol=1e-6)
    step = np.linalg.norm(np.diff(dense.position, axis=0), axis=1)
    assert np.all(step <= np.diff(dense.s) * (1 + 1e-9) + 1e-15)
    same = dense.segment[1:] == dense.segment[:-1]
    np.testing.assert_allclose(step[same], np.diff(dense.s)[same], rtol=1e-6, atol=1e-15)
    offset = dense.position - plan.points[dense.segment]
    along = dense.s - plan.cumulative_length[dense.segment]
    directions = np.diff(plan.points, axis=0)[dense.segment] / plan.lengths[dense.segment, None]
    np.testing.assert_allclose(offset, along[:, None] * directions, atol=1e-15)
    # Paper's Fig. 7: faster on the straight sides than on the arcs. The 160 mm long sides are too
    # short to reach v_m from the arc speed: the peak is sqrt(a_m R + 2 A * 80 mm), mid-side.
    v_arc_sq = A_M * 0.02
    assert np.max(dense.speed) == pytest.approx(math.sqrt(v_arc_sq + 2 * (2 / 3 * A_M) * 0.08), rel=1e-2)


def test_whole_path_speed_and_acceleration_continuous_at_joints(closed_path_plan):
    plan = closed_path_plan
    t_joint = plan.segment_times[1:-1]
    eps = 1e-9
    before = plan.sample(t_joint - eps)
    after = plan.sample(t_joint + eps)
    assert np.all(before.segment == np.arange(len(t_joint)))
    assert np.all(after.segment == np.arange(1, len(t_joint) + 1))
    # Speed is continuous: across 2 eps it changes by at most a_m * 2 eps.
    np.testing.assert_allclose(after.speed, before.speed, atol=2.0 * A_M * eps * (1 + 1e-6))
    # Exactly at each joint, the left limit (segment k at its end) equals the right limit (segment
    # k + 1 at its start), for speed and for tangential acceleration (zero at every ramp end).
    for k in range(len(plan.profiles) - 1):
        left, right = plan.profiles[k], plan.profiles[k + 1]
        assert left.v_end == right.v_start == plan.velocities[k + 1]
        _, v_left, a_left = left.sample(left.duration)
        _, v_right, a_right = right.sample(0.0)
        assert v_left == pytest.approx(v_right, rel=1e-14, abs=1e-15)
        assert a_left == a_right == 0.0


def test_whole_path_on_random_polylines():
    rng = np.random.default_rng(7)
    seen = set()
    for _ in range(20):
        points = random_polyline(rng, int(rng.integers(2, 60)))
        v_max, a_max = rng.uniform(0.05, 1.0), rng.uniform(0.05, 5.0)
        plan = plan_cartesian_path(points, v_max, a_max)
        seen.update(int(c) for c in plan.cases)
        dense = plan.sample(np.linspace(0.0, plan.duration, 5001))
        assert np.all(dense.speed <= v_max * (1 + 1e-12))
        assert np.all(np.abs(dense.acceleration) <= a_max * (1 + 1e-9))
        end = plan.sample(plan.duration)
        np.testing.assert_allclose(end.position[0], points[-1], atol=1e-12)
        assert plan.velocities[0] == plan.velocities[-1] == 0.0
    assert seen >= {2, 3}


# ---------------------------------------------------------------------------------------------
# Bad input.
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "points, match",
    [
        ([[0.0, 0.0, 0.0]], "at least two distinct points"),
        ([[0.1, 0.2, 0.3]] * 4, "at least two distinct points"),
        ([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.0, 0.0], [0.2, 0.0, 0.0]],
         r"points\[2\] repeats points\[1\]"),
        ([[0.0, 0.0], [1.0, 0.0]], r"shape \(N, 3\)"),
        ([[0.0, 0.0, 0.0], [np.nan, 0.0, 0.0]], r"points\[1, 0\] must be finite"),
        ("abc", "points must be an"),
    ],
)
def test_bad_points(points, match):
    with pytest.raises(ValueError, match=match):
        plan_cartesian_path(points, V_M, A_M)
    with pytest.raises(ValueError, match=match):
        break_point_limits(points, V_M, A_M)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"v_max": 0.0}, r"v_max must be > 0"),
        ({"v_max": -1.0}, r"v_max must be > 0"),
        ({"a_max": 0.0}, r"a_max must be > 0"),
        ({"a_max": np.inf}, r"a_max must be finite"),
        ({"step_length": 0.0}, r"step_length must be > 0"),
    ],
)
def test_bad_limits(kwargs, match):
    points = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.1, 0.0]])
    arguments = {"v_max": V_M, "a_max": A_M, **kwargs}
    with pytest.raises(ValueError, match=match):
        plan_cartesian_path(points, **arguments)


@pytest.mark.parametrize(
    "args, match",
    [
        ((0.0, 0.0, 0.0, 1.0, 1.0), r"length must be > 0"),
        ((1.0, 0.0, 0.0, 0.0, 1.0), r"v_max must be > 0"),
        ((1.0, 0.0, 0.0, 1.0, -1.0), r"a_max must be > 0"),
        ((1.0, -0.1, 0.0, 1.0, 1.0), r"v_start must be >= 0"),
        ((1.0, 0.0, 1.5, 1.0, 1.0), r"v_end = 1.5 m/s must be <= v_max"),
        ((0.1, 0.0, 1.0, 1.0, 1.5), r"too short to change speed"),  # needs 0.5 m
    ],
)
def test_bad_segment(args, match):
    with pytest.raises(ValueError, match=match):
        acc_dec_profile(*args)
    with pytest.raises(ValueError, match=match):
        classify_acc_dec(*args)


def test_bad_look_ahead_inputs():
    with pytest.raises(ValueError, match=r"lengths must have shape \(2,\)"):
        look_ahead([0.0, 1.0, 0.0], [0.1], 1.0)
    with pytest.raises(ValueError, match=r"limits\[1\] must be >= 0"):
        look_ahead([0.0, -1.0, 0.0], [0.1, 0.1], 1.0)
    with pytest.raises(ValueError, match=r"lengths\[0\] must be > 0"):
        forward_backward_pass([0.0, 1.0, 0.0], [0.0, 0.1], 1.0)
    with pytest.raises(ValueError, match=r"at least two entries"):
        look_ahead([0.0], [], 1.0)
    with pytest.raises(ValueError, match=r"a_max must be > 0"):
        look_ahead([0.0, 0.0], [0.1], 0.0)
