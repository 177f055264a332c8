"""Tests for the loop path geometry and time law (Boryga, Boryga, section 2, eq. 1-14).

Numbers from the paper's numerical example (section 3, Table 1) are checked against the corrected
values of ``docs/papers.md``; where the paper printed something else, the comment says
what it printed. Printed values rounded to three decimals are checked to 5e-4.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from numpy.polynomial import Polynomial
from scipy.integrate import cumulative_trapezoid

from drake_traj.planners.boryga import (
    PHASES,
    LoopGeometry,
    LoopPath,
    loop_geometry,
    loop_timing,
    plan_loop_path,
    poly7_profile,
    poly7_timing,
)

# Section 3 inputs.
B = np.array([0.5, 0.5, 1.0])
M = np.array([0.54, 0.53, 1.0])
E = np.array([0.54, 0.5, 1.0])
DELTA = 0.02  # [m]
V_MAX = 0.25  # [m/s]

# Table 1 as printed [m].
TABLE1 = {
    "B": (0.5, 0.5, 1.0),
    "M": (0.54, 0.53, 1.0),
    "E": (0.54, 0.5, 1.0),
    "T1": (0.554, 0.541, 1.0),
    "T2": (0.54, 0.548, 1.0),
    "O1": (0.549, 0.548, 1.0),
}
PRINTED_TOL = 5e-4  # the paper prints three decimals


@pytest.fixture(scope="module")
def plan() -> LoopPath:
    return plan_loop_path(B, M, E, V_MAX, delta=DELTA)


@pytest.fixture(scope="module")
def dense(plan):
    """Uniform samples over [0, t_e] plus every junction time, sorted."""
    t = np.unique(np.concatenate([np.linspace(0.0, plan.duration, 40001), plan.breakpoints]))
    return (t,) + plan.sample(t)


def point_line_distance(point, a, b) -> float:
    """Distance from ``point`` to the line through ``a`` and ``b`` (independent of the module)."""
    u = (b - a) / np.linalg.norm(b - a)
    w = point - a
    return float(np.linalg.norm(w - (w @ u) * u))


# ---------------------------------------------------------------------------------------------
# The 7th-degree profile (section 1, eq. 1-6).
# ---------------------------------------------------------------------------------------------


def test_eq2_and_eq3_are_the_integrals_of_eq1():
    t_f, p = 0.7, 3.0e3
    h = 0.5 * t_f
    # eq. 1 built from its roots, integrated twice with zero initial values.
    a = -p * Polynomial.fromroots([0.0, 0.0, h, h, h, t_f, t_f])
    v = a.integ()
    s = v.integ()
    t = np.linspace(0.0, t_f, 101)
    s_mod, v_mod, a_mod, j_mod = poly7_profile(t, t_f, p)
    scale_a = np.max(np.abs(a(t)))
    np.testing.assert_allclose(a_mod, a(t), rtol=0, atol=1e-12 * scale_a)
    np.testing.assert_allclose(v_mod, v(t), rtol=0, atol=1e-12 * np.max(np.abs(v(t))))
    np.testing.assert_allclose(s_mod, s(t), rtol=0, atol=1e-12 * np.max(np.abs(s(t))))
    np.testing.assert_allclose(j_mod, a.deriv()(t), rtol=0, atol=1e-12 * scale_a / t_f * 10)


def test_eq6_peak_speed_and_distance():
    t_f, p = 0.5, 2.0e4
    s, v, a, j = poly7_profile(np.array([0.0, 0.5 * t_f, t_f]), t_f, p)
    np.testing.assert_allclose(v[1], p * t_f**8 / 6144.0, rtol=1e-13)  # eq. 6, first row
    np.testing.assert_allclose(s[2], p * t_f**9 / 10080.0, rtol=1e-13)  # eq. 6, second row
    np.testing.assert_allclose(s[1], 0.5 * s[2], rtol=1e-13)  # symmetric halves
    v_peak = v[1]
    # Rounding: eq. 2's terms at t_f are ~1000 v_peak and cancel to 0.
    np.testing.assert_allclose([v[0], v[2]], 0.0, atol=1e-12 * v_peak)
    # Tangential to the time axis at 0, t_f/2, t_f: zero acceleration and jerk.
    np.testing.assert_allclose(a, 0.0, atol=1e-12 * v_peak / t_f)
    np.testing.assert_allclose(j, 0.0, atol=1e-12 * v_peak / t_f**2)


def test_poly7_timing_gives_eq7_and_eq9_for_the_half_profile():
    ds_bm, v_max = 0.05, 0.25
    t_f, p = poly7_timing(2.0 * ds_bm, v_max)  # substitutions t_f = 2 t_BM, ds = 2 ds_BM
    np.testing.assert_allclose(0.5 * t_f, 105.0 / 64.0 * ds_bm / v_max, rtol=1e-15)  # eq. 7
    np.testing.assert_allclose(p, 315.0 * ds_bm / (8.0 * (0.5 * t_f) ** 9), rtol=1e-13)  # eq. 9
    s, v, _, _ = poly7_profile(np.array([0.5 * t_f]), t_f, p)
    np.testing.assert_allclose(v, v_max, rtol=1e-13)
    np.testing.assert_allclose(s, ds_bm, rtol=1e-13)


# ---------------------------------------------------------------------------------------------
# The numerical example (section 3, Table 1).
# ---------------------------------------------------------------------------------------------


def test_table1_points(plan):
    g = plan.geometry
    computed = {"B": g.B, "M": g.M, "E": g.E, "T1": g.T1, "T2": g.T2, "O1": g.O1}
    for name, printed in TABLE1.items():
        np.testing.assert_allclose(computed[name], printed, rtol=0, atol=PRINTED_TOL, err_msg=name)


def test_example_geometry_numbers(plan):
    g = plan.geometry
    assert g.delta == DELTA
    assert g.R == pytest.approx(8.944e-3, abs=PRINTED_TOL)
    assert g.R == pytest.approx(0.02 / math.sqrt(5.0), rel=1e-12)  # sin(angle/2) = 1/sqrt(5)
    assert g.beta == pytest.approx(4.069, abs=PRINTED_TOL)
    assert g.beta_b == pytest.approx(1.107, abs=PRINTED_TOL)  # printed as beta_p in section 3
    assert g.ds_BM == pytest.approx(0.05, abs=1e-15)
    assert g.ds_MT1 == pytest.approx(0.0179, abs=PRINTED_TOL)
    assert g.ds_T2M == pytest.approx(0.0179, abs=PRINTED_TOL)
    assert g.ds_ME == pytest.approx(0.03, abs=1e-15)
    # Corrected (docs/papers.md): total path 0.15217 m (paper: 0.152); 0.036 m is the arc alone (paper: "on the loop"),
    # the whole M -> T1 -> T2 -> M loop is 0.07217 m.
    assert g.path_length == pytest.approx(0.15217, abs=5e-6)
    assert plan.path_length == g.path_length
    assert g.ds_arc == pytest.approx(0.036, abs=PRINTED_TOL)
    assert g.ds_loop == pytest.approx(0.07217, abs=5e-6)


def test_example_time_law_numbers(plan):
    tl = plan.timing
    assert tl.v_max == V_MAX
    assert tl.t_BM == pytest.approx(0.328, abs=PRINTED_TOL)
    assert tl.t_MT1 == pytest.approx(0.072, abs=PRINTED_TOL)
    assert tl.t_A == pytest.approx(0.146, abs=PRINTED_TOL)
    assert tl.t_T2M == pytest.approx(0.072, abs=PRINTED_TOL)
    assert tl.t_ME == pytest.approx(0.197, abs=PRINTED_TOL)
    assert tl.tau == pytest.approx(0.42, abs=PRINTED_TOL)
    # Corrected (docs/papers.md): p_BM = 4.46516e4 m/s^9 (the paper prints 4.46156e4, digits transposed).
    assert tl.p_BM == pytest.approx(4.46516e4, rel=1e-5)
    assert tl.p_ME == pytest.approx(2.65844e6, rel=1e-5)
    # Corrected (docs/papers.md): t_e = 0.81368 s (the paper prints 0.815, the sum of its rounded parts).
    assert tl.t_e == pytest.approx(0.81368, abs=5e-6)
    assert plan.duration == tl.t_e
    # Eq. 13 and 14 as sums, and the second pass through M at tau + t_ME.
    assert tl.t_e == pytest.approx(tl.t_BM + tl.t_MT1 + tl.t_A + tl.t_T2M + tl.t_ME, rel=1e-15)
    assert tl.t_M2 == pytest.approx(tl.tau + tl.t_ME, rel=1e-15)
    assert tl.loop_time == pytest.approx(tl.t_M2 - tl.t_M1, rel=1e-14)


def test_acceleration_jump_at_t1_and_t2(plan):
    # Corrected (docs/papers.md): v_max^2 / R = 6.99 m/s^2 in the example.
    jump = V_MAX**2 / plan.geometry.R
    assert jump == pytest.approx(6.99, abs=5e-3)
    for name in ("T1", "T2"):
        t = plan.junctions[name]
        _, _, acc_left, _ = plan.sample(t, side="left")
        _, _, acc_right, _ = plan.sample(t, side="right")
        assert np.linalg.norm(acc_right - acc_left) == pytest.approx(jump, rel=1e-12), name
        # On the arc side it is centripetal: towards O1 from the tangent point.
        arc_side = acc_right if name == "T1" else acc_left
        point = getattr(plan.geometry, name)
        toward_centre = (plan.geometry.O1 - point) / plan.geometry.R
        np.testing.assert_allclose(arc_side, jump * toward_centre, atol=1e-12 * jump)


def test_construction_matches_section_2_2_independently(plan):
    g = plan.geometry
    # O1 on the bisector of angle BME, at distance Delta from M.
    assert np.linalg.norm(g.O1 - M) == pytest.approx(DELTA, rel=1e-14)
    u_b = (B - M) / np.linalg.norm(B - M)
    u_e = (E - M) / np.linalg.norm(E - M)
    w = (g.O1 - M) / DELTA
    assert w @ u_b == pytest.approx(w @ u_e, abs=1e-14)
    # R is the distance from O1 to the line BM and to the line EM.
    assert point_line_distance(g.O1, B, M) == pytest.approx(g.R, rel=1e-12)
    assert point_line_distance(g.O1, E, M) == pytest.approx(g.R, rel=1e-12)
    # T1 and T2 on those lines, beyond M, at the Pythagorean distance; radii perpendicular there.
    l_tangent = math.sqrt(DELTA**2 - g.R**2)
    for point, line_start in ((g.T1, B), (g.T2, E)):
        assert point_line_distance(point, line_start, M) == pytest.approx(0.0, abs=1e-15)
        assert np.linalg.norm(point - M) == pytest.approx(l_tangent, rel=1e-12)
        assert np.linalg.norm(point - line_start) > np.linalg.norm(M - line_start)
        assert np.linalg.norm(point - g.O1) == pytest.approx(g.R, rel=1e-12)
        assert (point - g.O1) @ (M - line_start) == pytest.approx(0.0, abs=1e-15)
    # beta = pi + angle between a_hat and d_hat.
    angle_ad = math.acos(np.clip(g.a_hat @ g.d_hat, -1.0, 1.0))
    assert g.beta == pytest.approx(math.pi + angle_ad, rel=1e-14)
    assert g.corner_angle == pytest.approx(angle_ad, rel=1e-14)


def test_frame_and_transform_of_eq12(plan):
    g = plan.geometry
    frame = np.column_stack([g.xi, g.eta, g.zeta])
    np.testing.assert_allclose(frame.T @ frame, np.eye(3), atol=1e-15)
    assert np.linalg.det(frame) == pytest.approx(1.0, abs=1e-14)
    np.testing.assert_allclose(g.xi, (M - g.O1) / DELTA, atol=1e-15)
    np.testing.assert_allclose(g.zeta, [0.0, 0.0, 1.0], atol=1e-15)  # the path lies in z = 1
    T = g.transform
    for angle, point in ((g.beta_b, g.T1), (g.beta_b + g.beta, g.T2)):
        xi_arc = np.array([g.R * math.cos(angle), g.R * math.sin(angle), 0.0, 1.0])  # Xi^A
        np.testing.assert_allclose((T @ xi_arc)[:3], point, atol=1e-15)  # S^A = T Xi^A
        np.testing.assert_allclose(g.arc_point(angle), point, atol=1e-15)


def test_geometry_is_frozen_and_read_only(plan):
    g = plan.geometry
    with pytest.raises(dataclasses.FrozenInstanceError):
        g.R = 1.0
    with pytest.raises(ValueError):
        g.O1[0] = 0.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        plan.timing.t_e = 1.0


def test_radius_input_gives_the_same_loop():
    g_delta = loop_geometry(B, M, E, delta=DELTA)
    g_radius = loop_geometry(B, M, E, radius=g_delta.R)
    g_both = loop_geometry(B, M, E, delta=DELTA, radius=g_delta.R)
    for g in (g_radius, g_both):
        assert g.delta == pytest.approx(DELTA, rel=1e-14)
        for name in ("O1", "T1", "T2", "xi", "eta", "zeta"):
            np.testing.assert_allclose(getattr(g, name), getattr(g_delta, name), atol=1e-15)


# ---------------------------------------------------------------------------------------------
# Invariants on dense samples.
# ---------------------------------------------------------------------------------------------


def test_speed_bounded_and_constant_on_the_loop(plan, dense):
    t, _, vel, _, _ = dense
    speed = np.linalg.norm(vel, axis=1)
    assert np.max(speed) <= V_MAX * (1.0 + 1e-12)
    on_loop = (t >= plan.junctions["M1"]) & (t <= plan.junctions["M2"])
    np.testing.assert_allclose(speed[on_loop], V_MAX, rtol=1e-12)
    np.testing.assert_allclose(plan.speed(t), speed, rtol=0, atol=1e-15)
    # Monotone start-up on BM and braking on ME (eq. 4-5: v_max reached, never exceeded).
    on_bm = t <= plan.junctions["M1"]
    on_me = t >= plan.junctions["M2"]
    assert np.all(np.diff(speed[on_bm]) >= -1e-13 * V_MAX)  # up to rounding near the peak
    assert np.all(np.diff(speed[on_me]) <= 1e-13 * V_MAX)


def test_acceleration_zero_only_on_straight_constant_parts(plan, dense):
    t, _, _, acc, _ = dense
    a_norm = np.linalg.norm(acc, axis=1)
    tl = plan.timing
    straight = ((t >= tl.t_M1) & (t < tl.t_T1)) | ((t >= tl.t_T2) & (t < tl.t_M2))
    arc = (t >= tl.t_T1) & (t < tl.t_T2)
    np.testing.assert_array_equal(a_norm[straight], 0.0)
    np.testing.assert_allclose(a_norm[arc], V_MAX**2 / plan.geometry.R, rtol=1e-12)


def test_continuity_at_every_junction(plan):
    scale = {"position": 1.0, "velocity": V_MAX}
    for name, t in plan.junctions.items():
        left = plan.sample(t, side="left")
        right = plan.sample(t, side="right")
        for k, what in enumerate(("position", "velocity")):
            np.testing.assert_allclose(
                right[k], left[k], rtol=0, atol=1e-14 * scale[what], err_msg=f"{what} at {name}"
            )
    # And near each junction (a tiny step either side).
    eps = 1e-9
    for name, t in plan.junctions.items():
        before = plan.sample(t - eps)
        after = plan.sample(t + eps)
        np.testing.assert_allclose(after[0], before[0], atol=3 * V_MAX * eps, err_msg=name)


def test_positions_at_junctions_are_the_characteristic_points(plan):
    g = plan.geometry
    expected = {"B": B, "M1": M, "T1": g.T1, "T2": g.T2, "M2": M, "E": E}
    for name, t in plan.junctions.items():
        for side in ("left", "right"):
            np.testing.assert_allclose(
                plan.sample(t, side=side)[0], expected[name], atol=1e-15, err_msg=f"{name} {side}"
            )


def test_zero_acceleration_and_jerk_at_b_m_and_e(plan):
    # Section 4 and conclusion 2: the acceleration profile is tangential to the time axis at
    # B, M (both passes, both sides) and E: zero acceleration and zero jerk there.
    for name in ("B", "M1", "M2", "E"):
        t = plan.junctions[name]
        for side in ("left", "right"):
            _, _, acc, jerk = plan.sample(t, side=side)
            np.testing.assert_allclose(acc, 0.0, atol=1e-12, err_msg=f"acc {name} {side}")
            np.testing.assert_allclose(jerk, 0.0, atol=1e-9, err_msg=f"jerk {name} {side}")


def test_end_state_at_rest_at_e_and_rest_outside(plan):
    pos, vel, acc, jerk = plan.sample(np.array([plan.duration, plan.duration + 1.0]))
    np.testing.assert_array_equal(pos, [E, E])
    np.testing.assert_array_equal(vel, 0.0)
    np.testing.assert_array_equal(acc, 0.0)
    np.testing.assert_array_equal(jerk, 0.0)
    pos, vel, acc, _ = plan.sample(-0.5)
    np.testing.assert_array_equal(pos, B)
    np.testing.assert_array_equal(vel, 0.0)
    assert plan.arc_length(-1.0) == 0.0
    assert plan.arc_length(plan.duration + 1.0) == plan.path_length


def test_integrated_velocity_reproduces_position(plan, dense):
    t, pos, vel, _, _ = dense
    integrated = B + cumulative_trapezoid(vel, t, axis=0, initial=0.0)
    np.testing.assert_allclose(integrated, pos, rtol=0, atol=1e-6)
    # The arc-length helper is the integral of the speed.
    s = cumulative_trapezoid(np.linalg.norm(vel, axis=1), t, initial=0.0)
    np.testing.assert_allclose(plan.arc_length(t), s, rtol=0, atol=1e-6)
    np.testing.assert_allclose(
        plan.arc_length(plan.breakpoints), plan.breakpoint_arc_lengths, atol=1e-15
    )


def test_jerk_and_acceleration_are_derivatives_inside_each_phase(plan):
    h = 1e-6
    bp = plan.breakpoints
    for k, phase in enumerate(PHASES):
        t = np.linspace(bp[k], bp[k + 1], 9)[1:-1]
        _, vel, acc, jerk = plan.sample(t)
        _, vel_p, acc_p, _ = plan.sample(t + h)
        _, vel_m, acc_m, _ = plan.sample(t - h)
        np.testing.assert_allclose((vel_p - vel_m) / (2 * h), acc, atol=1e-5, err_msg=phase)
        np.testing.assert_allclose((acc_p - acc_m) / (2 * h), jerk, atol=1e-3, err_msg=phase)


def test_me_phase_equals_the_literal_shifted_profile(plan):
    # Section 2.4 (second): the ME profile is eq. 1-3 with t_f = 2 t_ME, p = p_ME, shifted by tau
    # (eq. 13), second half, starting at M.
    tl = plan.timing
    t = np.linspace(tl.t_M2, tl.t_e, 201)
    s, v, a, _ = poly7_profile(t - tl.tau, 2.0 * tl.t_ME, tl.p_ME)
    direction = (E - M) / np.linalg.norm(E - M)
    pos, vel, acc, _ = plan.sample(t)
    np.testing.assert_allclose(pos, M + (s - plan.geometry.ds_ME)[:, None] * direction, atol=1e-14)
    np.testing.assert_allclose(vel, v[:, None] * direction, atol=1e-13)
    np.testing.assert_allclose(acc, a[:, None] * direction, atol=1e-10)


def test_samples_stay_on_the_path(plan, dense):
    g = plan.geometry
    t, pos, _, _, _ = dense
    phase = plan.phase_index(t)
    np.testing.assert_allclose(pos[:, 2], 1.0, atol=1e-15)
    on_arc = phase == 2
    np.testing.assert_allclose(np.linalg.norm(pos[on_arc] - g.O1, axis=1), g.R, rtol=1e-12)
    for k, (start, end) in {0: (B, M), 1: (B, M), 3: (E, M), 4: (E, M)}.items():
        distances = [point_line_distance(p, start, end) for p in pos[phase == k][::50]]
        assert max(distances) < 1e-15, PHASES[k]


def test_sample_shapes(plan):
    pos, vel, acc, jerk = plan.sample(0.3)
    assert pos.shape == vel.shape == acc.shape == jerk.shape == (3,)
    grid = np.linspace(0.0, plan.duration, 12).reshape(3, 4)
    out = plan.sample(grid)
    assert all(x.shape == (3, 4, 3) for x in out)
    np.testing.assert_array_equal(out[0][1, 2], plan.sample(grid[1, 2])[0])
    assert np.shape(plan.arc_length(grid)) == (3, 4)
    assert np.ndim(plan.arc_length(0.2)) == 0


def test_random_geometries_keep_the_invariants():
    rng = np.random.default_rng(1)
    for case in range(40):
        B_, M_, E_ = rng.uniform(-1.0, 1.0, size=(3, 3))
        v_max = rng.uniform(0.05, 2.0)
        delta = rng.uniform(0.01, 0.5)
        p = plan_loop_path(B_, M_, E_, v_max, delta=delta)
        g = p.geometry
        label = f"case {case}"
        for name, t in p.junctions.items():
            left, right = p.sample(t, side="left"), p.sample(t, side="right")
            where = f"{label} {name}"
            np.testing.assert_allclose(right[0], left[0], atol=1e-13, err_msg=where)
            np.testing.assert_allclose(right[1], left[1], atol=1e-12 * v_max, err_msg=where)
        for name in ("T1", "T2"):
            _, _, a_l, _ = p.sample(p.junctions[name], side="left")
            _, _, a_r, _ = p.sample(p.junctions[name], side="right")
            assert np.linalg.norm(a_r - a_l) == pytest.approx(v_max**2 / g.R, rel=1e-10), label
        t = np.linspace(0.0, p.duration, 4001)
        pos, vel, _, _ = p.sample(t)
        assert np.max(np.linalg.norm(vel, axis=1)) <= v_max * (1.0 + 1e-12), label
        np.testing.assert_allclose(pos[-1], E_, atol=1e-15, err_msg=label)
        np.testing.assert_allclose(vel[[0, -1]], 0.0, atol=1e-15, err_msg=label)
        # The whole path lies in the plane of B, M, E.
        np.testing.assert_allclose((pos - M_) @ g.zeta, 0.0, atol=1e-13, err_msg=label)
        assert p.arc_length(p.duration) == pytest.approx(g.path_length, rel=1e-14)


# ---------------------------------------------------------------------------------------------
# Bad input.
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("points", "match"),
    [
        ((M, M, E), "B and M coincide"),
        ((B, M, M), "E and M coincide"),
        ((B, M, 2 * M - B), "M between B and E"),  # straight through M
        ((B, M, 0.5 * (B + M)), "same side of M"),  # E on segment BM: the path reverses
        ((B, M, B), "same side of M"),  # B and E coincide
        ((B, M, 2 * M - B + np.array([0.0, 0.0, 1e-12])), "collinear"),  # numerically collinear
    ],
)
def test_collinear_or_coincident_points_are_rejected(points, match):
    with pytest.raises(ValueError, match=match):
        loop_geometry(*points, delta=DELTA)
    with pytest.raises(ValueError, match=match):
        plan_loop_path(*points, V_MAX, delta=DELTA)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({}, "delta or radius must be given"),
        ({"delta": 0.0}, r"delta must be > 0"),
        ({"delta": -0.02}, r"delta must be > 0"),
        ({"delta": float("nan")}, "delta must be finite"),
        ({"delta": "wide"}, "delta must be a real number"),
        ({"radius": 0.0}, r"radius must be > 0"),
        ({"radius": float("inf")}, "radius must be finite"),
        ({"delta": 0.02, "radius": 0.01}, "radius = 0.01 m does not fit delta = 0.02 m"),
    ],
)
def test_bad_loop_size_is_rejected(kwargs, match):
    with pytest.raises(ValueError, match=match):
        loop_geometry(B, M, E, **kwargs)


@pytest.mark.parametrize(
    ("v_max", "match"),
    [
        (0.0, "v_max must be > 0"),
        (-0.25, "v_max must be > 0"),
        (float("inf"), "v_max must be finite"),
    ],
)
def test_bad_v_max_is_rejected(v_max, match):
    with pytest.raises(ValueError, match=match):
        plan_loop_path(B, M, E, v_max, delta=DELTA)


@pytest.mark.parametrize(
    ("points", "match"),
    [
        (([0.5, 0.5], M, E), r"B must have shape \(3,\)"),
        ((B, [0.54, np.nan, 1.0], E), r"M\[1\] must be finite"),
        ((B, M, "E"), r"E must be a real number or an array of real numbers \[m\], found str 'E'"),
    ],
)
def test_bad_points_are_rejected(points, match):
    with pytest.raises(ValueError, match=match):
        loop_geometry(*points, delta=DELTA)


def test_bad_arguments_to_the_time_law_and_sampler(plan):
    with pytest.raises(ValueError, match="geometry must be a LoopGeometry"):
        loop_timing({"R": 1.0}, V_MAX)
    with pytest.raises(ValueError, match="timing must be a LoopTiming"):
        LoopPath(plan.geometry, None)
    with pytest.raises(ValueError, match="side must be 'left' or 'right'"):
        plan.sample(0.1, side="middle")
    with pytest.raises(ValueError, match="t must be finite"):
        plan.sample([0.1, np.nan])
    assert isinstance(plan.geometry, LoopGeometry)
