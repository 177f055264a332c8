"""Tests for the planning law of Pająk 2024, drake_traj.planners.pajak.

Paper numbers are checked against the recomputed values of ``docs/papers.md`` (Pająk 2024);
where the paper printed something else, the comment says what it printed. The trajectories come
from the module's own fixed-step RK4 integrator (``integrate``, dt = 1 ms, the discrete state
updated every step), so no Drake system is involved here.
"""

from __future__ import annotations

import dataclasses
import inspect

import numpy as np
import pytest
from numba.core.registry import CPUDispatcher

from drake_traj.robots import task_space
from drake_traj.robots import ur10e as robot
from drake_traj.planners import pajak as P
from drake_traj.planners.pajak import kernel
from drake_traj.planners.pajak.kernel import PENALTY_SPAN, PENALTY_STIFFNESS, VIABILITY_MARGIN, Parameter, viability_bound

Q0 = P.paper_initial_configuration()
# Every improvement off: the paper's method as printed (with the corrections of docs/papers.md).
LITERAL = P.PAPER_METHOD
VMAX, AMAX = 1.05, 1.40  # [rad/s], [rad/s^2]: the paper's limits
TOL = 1e-9  # floating-point slack on "limit held"

_RUNS: dict = {}


def run(sim: int, *, dt: float = 1e-3, t_max: float = 15.0, settle_time: float = 2.0, **overrides) -> dict:
    """integrate() of the paper's task for simulation ``sim``, cached for the module; full runs
    go on for ``settle_time`` after the finish (to see an overshoot), shorter ones (t_max < 15 s)
    return what they computed by t_max."""
    key = (sim, dt, t_max, settle_time, tuple(sorted(overrides.items())))
    if key not in _RUNS:
        law = P.PajakLaw(P.paper_parameters(sim, **overrides))
        full = t_max >= 15.0
        _RUNS[key] = P.integrate(
            law, Q0, dt=dt, t_max=t_max, settle_time=settle_time if full else 0.0, raise_on_timeout=full
        )
    return _RUNS[key]


def until_finish(result: dict, name: str) -> np.ndarray:
    k = result["finish_index"]
    return result[name][: k + 1]


def overshoot_past_goal(result: dict, law_params: P.PajakConfig) -> float:
    """Largest distance [m] the TCP gets past p_w along the approach direction (negative: never).

    The approach direction is p_{w-1} -> p_w, or start -> p_w for a single waypoint; only samples
    where p_w is the active target count.
    """
    waypoints = law_params.waypoints
    goal = waypoints[-1, :3]
    start = waypoints[-2, :3] if len(waypoints) > 1 else result["tcp"][0, :3]
    u = (goal - start) / np.linalg.norm(goal - start)
    final = result["waypoint"] == len(waypoints) - 1
    return float(np.max((result["tcp"][final, :3] - goal) @ u))


# ---------------------------------------------------------------------------------------------
# Kinematics
# ---------------------------------------------------------------------------------------------


def test_closed_form_kinematics_match_robot_module():
    rng = np.random.default_rng(7)
    q = rng.uniform(-np.pi, np.pi, (40, 6))
    qd = rng.uniform(-2.0, 2.0, (40, 6))
    pose_b, jac_b, bias_b, cos_pitch_b, _ = robot.ur10e_kinematics(q, qd)  # batch path
    for k in range(len(q)):
        jac_ref, bias_ref = robot.analytic_jacobian_and_bias(q[k], qd[k])
        pose_ref = robot.task_pose(q[k])
        pose, jac, bias, cos_pitch, _ = robot.ur10e_kinematics(q[k], qd[k])  # single (float) path
        for p, j, b in ((pose, jac, bias), (pose_b[k], jac_b[k], bias_b[k])):
            np.testing.assert_allclose(task_space.task_pose_error(p, pose_ref), 0.0, atol=1e-12)
            np.testing.assert_allclose(j, jac_ref, atol=1e-9, rtol=1e-9)
            np.testing.assert_allclose(b, bias_ref, atol=1e-9, rtol=1e-9)
        assert cos_pitch == pytest.approx(np.cos(pose_ref[4]), abs=1e-12)
        assert cos_pitch_b[k] == pytest.approx(cos_pitch, abs=1e-15)


def test_pose_error_is_the_distance_and_the_angle_left():
    rng = np.random.default_rng(5)
    poses, goals = rng.uniform(-3, 3, (30, 6)), rng.uniform(-3, 3, (30, 6))
    position, orientation = robot.pose_error(poses, goals)
    for k in range(30):
        turn = robot.rotation_from_zyx_euler(goals[k, 3:]).T @ robot.rotation_from_zyx_euler(poses[k, 3:])
        assert orientation[k] == pytest.approx(np.arccos(np.clip((np.trace(turn) - 1) / 2, -1, 1)), abs=1e-9)
        assert position[k] == pytest.approx(np.linalg.norm(poses[k, :3] - goals[k, :3]))
    # not a difference of Euler angles: φ_X = π and -π are the same orientation
    goal = np.array([0.1, 0.2, 0.3, np.pi, 0.0, 0.7])
    same = goal.copy()
    same[3] = -np.pi
    assert robot.pose_error(same, goal) == (0.0, pytest.approx(0.0, abs=1e-15))
    tilted = goal.copy()
    tilted[4] = 1e-7
    assert robot.pose_error(tilted, goal)[1] == pytest.approx(1e-7, rel=1e-6)  # accurate for small angles
    with pytest.raises(ValueError, match="pose must have shape"):
        robot.pose_error(np.zeros(5), goal)


def test_singularity_measure_vanishes_with_det_j():
    rng = np.random.default_rng(3)
    q = rng.uniform(-np.pi, np.pi, (20, 6))
    det = np.array([np.linalg.det(robot.geometric_jacobian(x)) for x in q])
    measure = robot.singularity_measure(q)
    assert np.all(measure > 0) and np.all(measure <= 1)
    # det J_g = a2 a3 s3 s5 (a2 c2 + a3 c23 + d5 s234): each factor bounds the determinant
    assert np.all(np.abs(det) <= 0.6127 * 0.57155 * 1.2 * measure + 1e-12)
    for joint in (2, 4):  # elbow straight, wrist axes aligned
        singular = q[0].copy()
        singular[joint] = 0.0
        assert robot.singularity_measure(singular) == pytest.approx(0.0, abs=1e-15)
        assert abs(np.linalg.det(robot.geometric_jacobian(singular))) < 1e-12


# ---------------------------------------------------------------------------------------------
# Parameters
# ---------------------------------------------------------------------------------------------


def test_paper_parameters_validate():
    params = P.paper_parameters(3).validate()
    assert params.waypoints.shape == (4, 6)
    np.testing.assert_array_equal(params.velocity_limit, np.full(6, VMAX))
    np.testing.assert_array_equal(params.acceleration_limit, np.full(6, AMAX))
    with pytest.raises(ValueError, match="simulation"):
        P.paper_parameters(4)


@pytest.mark.parametrize(
    "change, field",
    [
        (dict(waypoints=[[0.3, -0.5, np.nan, np.pi, 0.0, 0.0]]), "waypoints\\[0\\] must be finite"),
        (dict(waypoints=np.zeros((2, 5))), "waypoints must have shape"),
        (dict(waypoints=[[0.3, -0.5, 0.5, 0.0, np.pi / 2, 0.0]]), "waypoints\\[0\\] phi_Y"),
        (dict(waypoints=[[0.3, -0.5, 0.5, 0, 0, 0], [0.31, -0.5, 0.5, 0, 0, 0]]), "closer than the neighbourhood"),
        (dict(position_gain=0.0), "position_gain"),
        (dict(velocity_gain=-9.0), "velocity_gain"),
        (dict(velocity_limit=[1.0] * 5), "velocity_limit must be a scalar or have shape"),
        (dict(velocity_limit=np.nan), "velocity_limit"),
        (dict(acceleration_limit=0.0), "acceleration_limit"),
        (dict(vartheta=0.5), "vartheta"),
        (dict(vartheta=0.0), "vartheta"),
        (dict(rho=-0.03), "rho"),
        (dict(accuracy=0.06), "accuracy .* must not be larger than neighbourhood"),
        (dict(neighbourhood=float("nan")), "neighbourhood"),
        (dict(stall_time=0.0), "stall_time"),
        (dict(orientation_accuracy=0.0), "orientation_accuracy"),
        (dict(scaling_slew=-1.0), "scaling_slew"),
        (dict(limit_velocity="yes"), "limit_velocity"),
    ],
)
def test_validate_names_the_field(change, field):
    params = dataclasses.replace(P.paper_parameters(3), **change)
    with pytest.raises(ValueError, match=field):
        params.validate()
    with pytest.raises(ValueError, match=field):
        P.PajakLaw(params)


# ---------------------------------------------------------------------------------------------
# The pieces of the law
# ---------------------------------------------------------------------------------------------


def test_velocity_penalty_is_the_gradient_of_eq_14():
    rho, vartheta, span = 0.03, 0.1, 2 * VMAX
    qd = np.linspace(-1.04, 1.04, 2001)

    def kappa(v, smooth):
        d = np.minimum(v + VMAX, VMAX - v) / span
        value = rho * (1 / d - 1 / vartheta)
        if smooth:
            value = value + rho * (d - vartheta) / vartheta**2
        return np.where(d < vartheta, value, 0.0)

    h = 1e-7
    def penalty_of(v, smooth):
        return np.array([P.velocity_penalty(x, VMAX, rho, vartheta, smooth) for x in np.atleast_1d(v)])

    # the smooth penalty's stiffness |∂Δq̈/∂q̇| = 2ρ/(d³ span²) is capped: linear below this d
    knee = (2 * rho / (PENALTY_STIFFNESS * span**2)) ** (1 / 3)
    for smooth in (False, True):
        penalty = penalty_of(qd, smooth)
        gradient = (kappa(qd + h, smooth) - kappa(qd - h, smooth)) / (2 * h)
        inside = np.abs(np.abs(qd) - VMAX * (1 - 2 * vartheta)) > 1e-4  # away from the kink
        if smooth:
            inside &= VMAX - np.abs(qd) > knee * span
        np.testing.assert_allclose(penalty[inside], -gradient[inside], rtol=1e-5, atol=1e-6)  # eq. 15
        assert np.all(penalty[qd > 0.9] < 0) and np.all(penalty[qd < -0.9] > 0)  # pushes away
        assert np.all(penalty[np.abs(qd) < 0.84] == 0.0)  # only inside the threshold d < ϑ
    # at the threshold |q̇| = 0.84 the literal penalty jumps by ρ/(span ϑ²) = 1.43 rad/s²,
    # the smooth one starts from 0
    edge = VMAX * (1 - 2 * vartheta) + 1e-9
    assert penalty_of(edge, False)[0] == pytest.approx(-rho / (span * vartheta**2), rel=1e-6)
    assert abs(penalty_of(edge, True)[0]) < 1e-6
    # below the knee (d < 0.045 here) the smooth penalty goes on with the capped slope, continuous
    # at the knee; the literal one steepens as 1/d³ (2ρ/(d³ span²) = 19 000 1/s at d = 0.009)
    near = VMAX - span * np.array([knee * 0.2, knee * 0.6, knee - 1e-9, knee + 1e-9])
    smooth_near, literal_near = penalty_of(near, True), penalty_of(near, False)
    assert np.diff(smooth_near[:2])[0] / np.diff(near[:2])[0] == pytest.approx(-PENALTY_STIFFNESS, rel=1e-9)
    assert abs(smooth_near[3] - smooth_near[2]) <= 1.01 * PENALTY_STIFFNESS * span * 2e-9  # the slope times the gap
    assert np.diff(literal_near[:2])[0] / np.diff(near[:2])[0] < -10 * PENALTY_STIFFNESS


def test_the_velocity_viability_bound_is_jerk_limited():
    # improvement 2 with improvement 1's jerk budget J: q̈ riding the bound f(q̇_max - q̇) changes
    # at f f' <= J; its slope at the limit is K (q̇ approaches the limit exponentially, never past it)
    task = P.PajakLaw(P.paper_parameters(3, velocity_limit=1.0, acceleration_limit=2.6))  # the sweep's limits
    p, k = task.vector, 0
    gain, jerk = p[Parameter.VIABILITY_GAIN + k], p[Parameter.JERK_BUDGET]
    limit, speed = p[Parameter.QDD_MAX + k], p[Parameter.QD_MAX + k]
    gap = np.linspace(0.0, speed * (1 - VIABILITY_MARGIN) - p[Parameter.VIABILITY_ONSET + k], 20001)  # aimed below
    bound = np.array([viability_bound(x, gain, jerk) for x in gap])
    assert bound[0] == 0.0 and np.all(np.diff(bound) > 0)
    assert bound[-1] == pytest.approx(limit, rel=1e-9)  # it meets q̈_max where the box narrows
    rate = np.gradient(bound, gap) * bound  # d(q̈)/dt = f'(x) ẋ = -f'(x) f(x) riding the bound
    assert rate.max() <= jerk
    assert rate[-1] == pytest.approx(jerk * limit / (limit + jerk / gain), rel=1e-3)  # J (1 - (J/K) / (f + J/K))
    assert np.gradient(bound, gap)[0] == pytest.approx(gain, rel=1e-3)
    # the linear bound K x of the same slope changed q̈ at K q̈_max where it set in
    assert gain * limit > 2 * jerk
    # beyond the limit it goes on linearly (braking back), continuous at 0
    assert viability_bound(-1e-3, gain, jerk) == pytest.approx(-gain * 1e-3)


def test_the_penalty_cap_scales_with_low_velocity_limits():
    """Below a span of PENALTY_SPAN the cap grows as 1/span², so the knee stays at one d: an
    absolute cap put the knee above ϑ at 0.06 rad/s, where the penalty jumped at the threshold
    and pushed towards the limit, and the law stalled with c held near 0 by the velocity limit."""
    rho, vartheta = 0.03, 0.1
    knee = (2 * rho / (PENALTY_STIFFNESS * PENALTY_SPAN**2)) ** (1 / 3)  # 0.074
    for vmax in (0.06, 0.3, PENALTY_SPAN / 2):
        span = 2 * vmax
        d = np.array([vartheta + 1e-9, vartheta - 1e-9, 0.08, knee * (1 + 1e-9), knee * (1 - 1e-9), 0.02, 0.01])
        penalty = np.array([P.velocity_penalty(vmax - x * span, vmax, rho, vartheta, True) for x in d])
        assert penalty[0] == 0.0 and -1e-6 < penalty[1] < 0.0  # continuous at the threshold
        assert np.all(np.diff(penalty) < 0)  # away from the limit, harder the nearer
        np.testing.assert_allclose(penalty[2], -rho / span * (1 / 0.08**2 - 1 / vartheta**2), rtol=1e-12)
        assert penalty[4] - penalty[3] == pytest.approx(0.0, abs=1e-6 * abs(penalty[3]))  # continuous at the knee
        slope = (penalty[6] - penalty[5]) / (0.01 * span)  # ∂Δq̈/∂q̇ below the knee [1/s]
        assert slope == pytest.approx(-PENALTY_STIFFNESS * (PENALTY_SPAN / span) ** 2, rel=1e-9)
    # the paper's task at 1/20 of its limits finishes (it stalled at waypoint 1), q̇ held off the limit
    task = P.paper_parameters(3, velocity_limit=0.05 * VMAX, acceleration_limit=0.05 * AMAX)
    result = P.integrate(P.PajakLaw(task), Q0, t_max=60.0)
    assert 30.0 < result["T"] < 60.0
    assert np.abs(result["qd"]).max() < 0.9 * 0.05 * VMAX
    assert np.abs(result["qdd"]).max() <= 0.05 * AMAX * (1 + TOL)
    assert np.abs(np.diff(result["qdd"][1:], axis=0)).max() < 0.1  # no chatter at the 1 ms step [rad/s²]


def test_scaling_interval_cases_1_to_4():
    def box(n):
        return np.full(n, -1.4), np.full(n, 1.4)

    # (1) q̈ > max, b > 0: c <= (max - a)/b          (2) q̈ < min, b < 0: c <= (min - a)/b
    # (3) q̈ > max, b < 0: c >= (max - a)/b          (4) q̈ < min, b > 0: c >= (min - a)/b
    cases = [
        (0.4, 2.0, None, (1.4 - 0.4) / 2.0),
        (-0.4, -2.0, None, (-1.4 + 0.4) / -2.0),
        (3.0, -4.0, (1.4 - 3.0) / -4.0, None),
        (-3.0, 4.0, (-1.4 + 3.0) / 4.0, None),
    ]
    for a, b, low, high in cases:
        c_lo, c_hi = P.scaling_interval(np.array([a]), np.array([b]), *box(1))
        if low is not None:
            assert c_lo == pytest.approx(low)
        if high is not None:
            assert c_hi == pytest.approx(high)
    # several joints: (a) min of the upper bounds, (b) max of the lower bounds
    a = np.array([0.4, -0.4, 3.0, -3.0, 0.0, 0.0])
    b = np.array([2.0, -2.0, -4.0, 4.0, 0.0, 1e-3])
    c_lo, c_hi = P.scaling_interval(a, b, *box(6))
    assert c_lo == pytest.approx(0.4) and c_hi == pytest.approx(0.5)
    # b_i = 0 with a_i outside the box: empty
    c_lo, c_hi = P.scaling_interval(np.array([2.0, 0.0]), np.array([0.0, 1.0]), *box(2))
    assert c_lo > c_hi


def test_choose_scaling_cases_a_b_c_and_bounds():
    # admissible c_r is kept
    assert P.choose_scaling(0.7, 0.2, 0.9)[0] == pytest.approx(0.7)
    # (a) only upper bounds active: ĉ = ĉ_max; (b) only lower: ĉ = ĉ_min
    assert P.choose_scaling(0.7, -np.inf, 0.3)[0] == pytest.approx(0.3)
    assert P.choose_scaling(0.1, 0.3, np.inf)[0] == pytest.approx(0.3)
    # (c) both: the point of [ĉ_min, ĉ_max] closest to c_r (= the previous c after an update)
    assert P.choose_scaling(0.95, 0.2, 0.6)[0] == pytest.approx(0.6)
    # improvement 2: c stays in [0, 1]; an empty interval is reported
    c, ok = P.choose_scaling(0.5, -np.inf, -0.2)
    assert c == 0.0 and not ok
    c, ok = P.choose_scaling(0.5, 1.3, np.inf)
    assert c == 1.0 and not ok
    c, ok = P.choose_scaling(0.5, -np.inf, -0.2, bounded=False)  # literal: c < 0
    assert c == pytest.approx(-0.2) and ok


def test_blend_progress_and_target():
    # σ = (path through the ball) / length, continuous, 0 on entry
    sigma, step = P.blend_progress(np.array([0.0, 0.0, 0.03]), np.array([0.0, 0.0, 0.0]), 0.02, 0.0625)
    assert step == pytest.approx(0.03) and sigma == pytest.approx(0.05 / 0.0625)
    assert P.blend_progress(np.zeros(3), np.zeros(3), 0.0, 0.0625)[0] == 0.0
    assert P.blend_progress(np.zeros(3), np.zeros(3), 1.0, 0.0625)[0] == 1.0
    # eq. 19 target, orientation along the wrapped difference
    p_i = np.array([0.0, 0.0, 0.0, 3.1, 0.0, 0.0])
    p_next = np.array([1.0, 0.0, 0.0, -3.1, 0.0, 0.0])
    target = P.blended_target(p_i, p_next, 0.5)
    np.testing.assert_allclose(target, [0.5, 0.0, 0.0, 3.1 + (2 * np.pi - 6.2) / 2, 0.0, 0.0])


def test_start_of_the_motion_eq_18():
    # sims 1-2 (no scaling): q̈(0) is eq. 13; joint 4 has -22.63 rad/s² (Table 2's minimum)
    law = P.PajakLaw(P.paper_parameters(1))
    qdd, c = law.acceleration(0.0, Q0, np.zeros(6), law.initial_discrete())
    assert c == 1.0
    assert qdd[3] == pytest.approx(-22.63, abs=0.005)
    # sim 3: c(0) = 0 with the anchor (t0, c0) = (0, 0), so q̈(0) = 0 and c then follows eq. 18
    law = P.PajakLaw(P.paper_parameters(3))
    d = law.initial_discrete()
    assert d[P.Discrete.C] == 0.0 and d[P.Discrete.T0] == 0.0 and d[P.Discrete.C0] == 0.0
    qdd, c = law.acceleration(0.0, Q0, np.zeros(6), d)
    assert c == 0.0 and np.all(qdd == 0.0)
    _, c = law.acceleration(0.01, Q0, np.zeros(6), d)
    assert c == pytest.approx(1 - np.exp(-0.01))  # eq. 18 with c0 = 0, t0 = 0


# ---------------------------------------------------------------------------------------------
# Reproduction of Table 2
# ---------------------------------------------------------------------------------------------

# (T [s], max q̇, min q̇ [rad/s]) of Table 2
TABLE2 = {1: (4.98, 0.91, -1.62), 2: (5.22, 0.86, -0.97), 3: (5.32, 0.69, -0.93)}


# T [s] of our runs (docs/papers.md, recomputed Table 2): the paper method, and ours
TABLE2_RECOMPUTED = {"literal": {1: 5.116, 2: 5.074, 3: 5.351}, "improved": {1: 5.116, 2: 5.069, 3: 5.332}}


@pytest.mark.parametrize("sim", [1, 2, 3])
@pytest.mark.parametrize("method", ["improved", "literal"])
def test_table_2(sim, method):
    overrides = {} if method == "improved" else LITERAL
    result = run(sim, **overrides)
    t_paper, qd_max_paper, qd_min_paper = TABLE2[sim]
    qd, qdd = until_finish(result, "qd"), until_finish(result, "qdd")
    # paper: 4.98 / 5.22 / 5.32 s; docs/papers.md recomputed 4.95-5.17 / 5.20-5.42 / 5.26-5.43. Sim 3
    # improved: 5.332 s, passing p_f by 0.17 mm (literal: 5.351 s, 0.76 mm past p_f and back)
    assert result["T"] == pytest.approx(t_paper, rel=0.05)
    assert result["T"] == pytest.approx(TABLE2_RECOMPUTED[method][sim], abs=1.5e-3)
    assert qd.max() == pytest.approx(qd_max_paper, abs=0.06)
    assert qd.min() == pytest.approx(qd_min_paper, abs=0.06)
    if sim in (1, 2):
        # Table 2 prints max q̈ = 19.77 for sims 1-2; Corrected (docs/papers.md): not reproducible, the equations
        # give 14.89 (at t = 0, where joints 2-4 sum to zero). -22.63 (joint 4 at t = 0) is.
        assert qdd.max() == pytest.approx(14.89, abs=0.05)
        assert qdd.min() == pytest.approx(-22.63, abs=0.05)
    else:
        assert np.all(np.abs(qdd) <= AMAX + TOL)  # at every sample
        assert np.all(result["stage_peak"] <= AMAX + TOL)  # and every RK4 stage
        assert qdd.max() == pytest.approx(AMAX, abs=0.01) and qdd.min() == pytest.approx(-AMAX, abs=0.01)
    if sim in (2, 3):
        assert np.all(np.abs(qd) <= VMAX)
    # Table 2: 5.81e-4 / 5.68e-4 / 6.26e-4 m; Corrected (docs/papers.md): below the 1 mm stop threshold checked
    # every step, reproductions land just under 1 mm
    assert result["error"] < 1e-3
    # the TCP passes through every waypoint's 5 cm neighbourhood
    waypoints = P.paper_parameters(sim).waypoints[:, :3]
    tcp = until_finish(result, "tcp")[:, :3]
    closest = np.min(np.linalg.norm(tcp[:, None, :] - waypoints[None], axis=2), axis=0)
    assert np.all(closest < 0.05)
    assert list(np.unique(result["waypoint"])) == [0, 1, 2, 3]


def test_c_stays_in_unit_interval_and_anchor_is_recorded():
    result = run(3)
    c = until_finish(result, "c")
    assert np.all((c >= 0.0) & (c <= 1.0))
    # c changes by at most scaling_slew = 3/s; twice the limits would need it to fall faster (16
    # and 165 ms, 181 updates): there q̈ is clipped to the box and the updates are counted
    assert np.abs(np.diff(c)).max() <= 3e-3 + 1e-12
    counted = result["discrete"][result["finish_index"], P.Discrete.SATURATED]
    assert until_finish(result, "saturated").sum() == counted == 181
    # while the limits set c the anchor is (t, c) of the last update
    d = result["discrete"]
    active = np.flatnonzero(d[1:, P.Discrete.T0] == result["t"][1:]) + 1
    assert active.size > 100
    np.testing.assert_allclose(d[active, P.Discrete.C0], d[active, P.Discrete.C])


def test_acceleration_limit_holds_between_samples():
    # acceleration() evaluates c(t) = min(eq. 18 relaxation, admissible ĉ) itself, so the limit
    # holds at any time and state between updates, not only at the update instants
    result = run(3)
    law = P.PajakLaw(P.paper_parameters(3))
    rng = np.random.default_rng(0)
    worst = 0.0
    for k in rng.integers(0, result["finish_index"], 300):
        t = result["t"][k] + rng.uniform(0.0, 1e-3)
        q = result["q"][k] + rng.normal(0.0, 1e-4, 6)
        qd = result["qd"][k] + rng.normal(0.0, 1e-2, 6)
        qdd, c = law.acceleration(t, q, qd, result["discrete"][k])
        worst = max(worst, np.abs(qdd).max())
        assert 0.0 <= c <= 1.0
    assert worst <= AMAX + TOL


def test_stop_at_each_waypoint():
    params = P.paper_parameters(3, blend_waypoints=False)
    law = P.PajakLaw(params)
    result = P.integrate(law, Q0, dt=2e-3, t_max=20.0)
    switches = np.flatnonzero(np.diff(result["waypoint"]) > 0) + 1
    assert len(switches) == 3
    for k in switches:
        reached = params.waypoints[result["waypoint"][k] - 1, :3]
        jac = robot.analytic_jacobian(result["q"][k])
        assert np.linalg.norm(result["tcp"][k, :3] - reached) < params.accuracy  # within ε
        assert np.linalg.norm(jac[:3] @ result["qd"][k]) < params.stop_speed  # nearly at rest
        assert result["c"][k] == 0.0  # the next elementary task starts with c = 0 (eq. 18)
    assert np.all(np.abs(result["qdd"]) <= AMAX + TOL) and np.all(np.abs(result["qd"]) <= VMAX)
    assert result["error"] < 1e-3


def test_finished_and_update_api():
    law = P.PajakLaw(P.paper_parameters(1))
    d = law.initial_discrete()
    assert not law.finished(Q0, np.zeros(6), d)
    result = run(1)
    k = result["finish_index"]
    assert law.finished(result["q"][k], result["qd"][k], result["discrete"][k])
    assert not law.finished(result["q"][k - 50], result["qd"][k - 50], result["discrete"][k - 50])
    new = law.update(0.0, Q0, np.zeros(6), d)
    assert new.shape == (P.Discrete.SIZE,) and len(P.DISCRETE_NAMES) == P.Discrete.SIZE


# ---------------------------------------------------------------------------------------------
# Improvement 1: q̈ continuous after t = 0
# ---------------------------------------------------------------------------------------------

# [s]: windows containing the literal method's first jump (penalty onset in sims 2-3, the
# switch at the second waypoint in sim 1)
WINDOW = {1: 2.2, 2: 0.6, 3: 1.2}


def largest_step(result: dict, window: float) -> float:
    keep = result["t"] <= window + 1e-9
    return float(np.abs(np.diff(result["qdd"][keep], axis=0)).max())


@pytest.mark.parametrize("sim", [1, 2, 3])
def test_acceleration_is_continuous(sim):
    # a continuous q̈ changes by O(dt) per step: the largest change halves with dt; a jump
    # does not. The literal method jumps where the penalty switches on (slope -ρ/ϑ² at the
    # threshold) and where the target switches as the TCP leaves a ball with σ < 1.
    ratios = {}
    for name, overrides in (("improved", {}), ("literal", LITERAL)):
        coarse = largest_step(run(sim, dt=1e-3, **overrides), WINDOW[sim])
        fine = largest_step(run(sim, dt=5e-4, t_max=WINDOW[sim], **overrides), WINDOW[sim])
        ratios[name] = fine / coarse
    assert ratios["improved"] < 0.6
    assert ratios["literal"] > 0.85


def test_jerk_budget_rates():
    # improvement 1: the rate limits that keep c (and σ, the approach rate) from changing q̈ faster
    # than the budget: budget / max |∂q̈_i/∂x|
    from drake_traj.planners.pajak.terms import budgeted_rate
    from drake_traj.planners.pajak.limits import scaling_slew

    b = np.array([1.0, -200.0, 0.5, 0.0, 0.0, 0.0])
    assert scaling_slew(b, 3.0, 40.0) == pytest.approx(0.2)  # 200 rad/s² per unit of c
    assert scaling_slew(b / 100.0, 3.0, 40.0) == 3.0  # the budget is not reached below the slew
    jac = np.diag([1.0, 2.0, 0.5, 1.0, 1.0, 1.0])
    direction = np.array([0.0, 0.0, 2.0, 0.0, 0.0, 1.0])  # J⁻¹ direction = (0, 0, 4, 0, 0, 1)
    assert budgeted_rate(jac, 0.0, False, direction, 0.5, 40.0) == pytest.approx(40.0 / (0.5 * 4.0))
    still = budgeted_rate(jac, 0.0, False, np.zeros(6), 0.5, 40.0)  # x does not move q̈
    assert np.isfinite(still) and still * 0.0 == 0.0 and still > 1e100


def test_target_does_not_jump_at_the_switch():
    for overrides, continuous in (({}, True), (LITERAL, False)):
        result = run(1, **overrides)
        law = P.PajakLaw(P.paper_parameters(1, **overrides))
        jumps = []
        for k in np.flatnonzero(np.diff(result["waypoint"]) > 0) + 1:
            before = law.evaluate(result["t"][k], result["q"][k], result["qd"][k], result["discrete"][k - 1])
            after = law.evaluate(result["t"][k], result["q"][k], result["qd"][k], result["discrete"][k])
            jumps.append(np.linalg.norm(after["target"] - before["target"]))
        if continuous:
            assert max(jumps) < 1e-12  # σ = 1 exactly when the target becomes p_{i+1}
        else:
            assert max(jumps) > 1e-3  # the literal switch (TCP leaves the ball) moves the target


# ---------------------------------------------------------------------------------------------
# Improvement 3: singularities and clean failures
# ---------------------------------------------------------------------------------------------


def test_damped_inverse_keeps_motion_bounded_through_a_wrist_singularity():
    q_start = np.array([0.3, -1.2, 1.5, -1.9, 0.4, 0.2])
    q_goal = q_start.copy()
    q_goal[4] = -0.4  # the straight task-space path crosses q5 = 0 (wrist singular)
    goal = robot.task_pose(q_goal)
    peaks = {}
    for damped in (True, False):
        law = P.PajakLaw(P.PajakConfig(waypoints=goal[None], damped_inverse=damped, limit_velocity=False, limit_acceleration=False))
        try:
            result = P.integrate(law, q_start, t_max=10.0)
        except P.PlanningError as exc:
            result = exc.partial
        peaks[damped] = np.abs(result["qd"]).max()
        if damped:
            assert robot.singularity_measure(result["q"]).min() < 1e-3  # it did pass the singularity
            assert result["error"] < 1e-3
    assert peaks[True] < 3.0
    assert peaks[False] > 20 * peaks[True]


def test_unreachable_goal_fails_cleanly():
    pose = robot.task_pose(Q0)
    goal = pose.copy()
    shoulder = np.array([0.0, 0.0, robot.DH_D[0]])
    direction = (pose[:3] - shoulder) / np.linalg.norm(pose[:3] - shoulder)
    goal[:3] = shoulder + 1.29 * direction  # inside 1.3 m, but not with this orientation
    law = P.PajakLaw(P.PajakConfig(waypoints=goal[None], limit_velocity=True, limit_acceleration=False, stall_time=1.0))
    # known before integrating (the inverse kinematics of every waypoint): time 0, the waypoint
    with pytest.raises(P.PlanningError) as info:
        P.integrate(law, Q0, t_max=20.0)
    error = info.value
    assert isinstance(error, ValueError)
    assert error.cause == "unreachable" and error.time == 0.0 and error.partial is None
    assert "waypoint 0 cannot be reached" in str(error) and "t = " in str(error) and "q = " in str(error)
    # a goal beyond any configuration's flange is refused the same way: by the inverse kinematics
    goal[:3] = shoulder + 1.4 * direction
    with pytest.raises(P.PlanningError, match="waypoint 0 cannot be reached.*out of reach") as info:
        P.integrate(P.PajakLaw(P.PajakConfig(waypoints=goal[None], limit_velocity=False, limit_acceleration=False)),
                    Q0, t_max=20.0)
    assert info.value.cause == "unreachable"


@pytest.mark.parametrize("q", [[0, 0, 0, 0, np.pi / 2, 0], [0, -0.2, 0, -0.3, np.pi / 2, 0.3],
                               [0.3, -0.5, 0.05, -1.2, 1.0, 0.2]])
def test_the_flange_pose_of_any_configuration_is_reachable_beyond_the_brochures_1_3_m(q):
    """UR's 1.3 m is a round figure: these flange poses lie 1.318, 1.345 and 1.354 m from the
    shoulder, and inverse kinematics reaches each (the law's reach check accepts them)."""
    pose = robot.task_pose(np.array(q, dtype=float))
    assert np.linalg.norm(pose[:3] - [0.0, 0.0, robot.DH_D[0]]) > 1.3
    law = P.PajakLaw(P.PajakConfig(waypoints=pose[None], limit_velocity=False, limit_acceleration=False))
    assert law.reach_failure(Q0) is None


def test_gimbal_lock_and_timeout_raise_planning_error():
    law = P.PajakLaw(P.paper_parameters(1))
    q_lock = np.array([0.0, -1.0, 1.0, 0.0, np.pi / 2, np.pi / 2])  # φ_Y = ±π/2
    with pytest.raises(P.PlanningError, match="gimbal lock") as info:
        law.acceleration(0.0, q_lock, np.zeros(6), law.initial_discrete())
    assert info.value.cause == "singular"
    with pytest.raises(P.PlanningError, match="did not finish within t_max") as info:
        P.integrate(law, Q0, t_max=0.5)
    assert info.value.cause == "timeout" and len(info.value.partial["t"]) == 501


# ---------------------------------------------------------------------------------------------
# Improvement 4: condition (11) with c < 1, no overshoot
# ---------------------------------------------------------------------------------------------


def test_approach_damping_holds_the_approach_rate():
    K, D0 = 0.5 * 20.0, 0.5 * 9.392  # c = 0.5: the literal damping breaks (11)
    root = np.sqrt(K)
    rate = np.linspace(0.0, 6.0 * root, 4001)
    damping = np.array([P.approach_damping(r, K, D0) for r in rate])
    # the literal damping while the TCP closes slower than the critically damped rate
    assert np.all(damping[rate <= root] == D0)
    # D = r + K/r from r = 2 sqrt(K) on: dr/dt = r² - D r + K = 0, ė = -r e is invariant
    held = rate >= 2.0 * root
    np.testing.assert_allclose(damping[held], rate[held] + K / rate[held], rtol=1e-12)
    np.testing.assert_allclose(rate[held] ** 2 - damping[held] * rate[held] + K, 0.0, atol=1e-9)
    # continuous and never below the literal damping; moving away (r < 0): nothing added
    assert np.abs(np.diff(damping)).max() < 0.01 and np.all(damping >= D0)
    assert P.approach_damping(-3.0, K, D0) == D0


def test_approach_rate_is_the_rate_of_the_whole_pose():
    # e and ė = -r e: the rate r whatever the direction; orientation rows weighted by 0.1 m/rad
    error = np.array([0.02, -0.01, 0.005, 0.1, -0.05, 0.02])
    assert P.approach_rate(error, -3.0 * error, 0.0) == pytest.approx(3.0)
    # sweeping past the goal sideways: one component crosses 0 at speed, the rate stays bounded
    # by |ė| / |e| (a rate per component would spike to ±∞)
    sideways = np.array([0.0, 0.01, 0, 0, 0, 0])
    assert P.approach_rate(sideways, np.array([-0.1, 0, 0, 0, 0, 0]), 0.0) == 0.0
    assert P.approach_rate(np.zeros(6), np.ones(6), 1e-7) == 0.0  # finite at the goal


def test_condition_11_threshold():
    params = P.paper_parameters(3)
    assert 4 * params.position_gain / params.velocity_gain**2 == pytest.approx(0.907, abs=5e-4)
    # the scaled gains c Λ_V, c Λ_P break (11) below it
    c = 0.9
    assert c * 9.392 < 2 * np.sqrt(c * 20)


@pytest.mark.parametrize("task", ["paper", "direct"])
def test_overshoot_of_the_final_goal(task):
    overshoot = {}
    for fix in (False, True):
        if task == "paper":  # sim 3, literal method against the default
            params = P.paper_parameters(3, **({} if fix else LITERAL))
            result = run(3, **({} if fix else LITERAL))
        else:  # straight to p_f: a long approach with c low; only improvement 4 toggled
            params = P.paper_parameters(3, preserve_damping=fix, waypoints=P.paper_parameters(3).waypoints[-1:])
            result = P.integrate(P.PajakLaw(params), Q0, t_max=15.0, settle_time=2.0)
        overshoot[fix] = overshoot_past_goal(result, params)
        if fix:
            # the distance to p_w never grows once p_w is the only target
            final = result["waypoint"] == len(params.waypoints) - 1
            error = np.linalg.norm(result["tcp"][final, :3] - params.waypoints[-1, :3], axis=1)
            assert np.all(np.diff(error) <= 1e-9)
    # Measured: sim 3, literal 0.76 mm past p_f (then back), ours 0.17 mm (y passes 0 while x is
    # still 1.6 mm off); direct move, without improvement 4 57 mm, with it 1.1 mm
    if task == "paper":
        assert overshoot[False] > 7e-4 and overshoot[True] < 2e-4
    else:
        assert overshoot[False] > 0.05 and overshoot[True] < 1.5e-3


def test_the_cached_law_follows_an_edit_of_every_module_it_calls():
    # numba checks a cached function against its own file only: the law's compiled functions that
    # call compiled code of another module close over the digest of those modules' sources
    # (kernel.DEPENDENCY_SOURCES), so that an edit of any of them (terms.py, limits.py, ...)
    # recompiles the law in the next process
    hashed = {str(path) for path in kernel.DEPENDENCY_SOURCES}
    called = {inspect.getsourcefile(value.py_func) for value in vars(kernel).values()
              if isinstance(value, CPUDispatcher)} - {kernel.__file__}
    assert called and called <= hashed
