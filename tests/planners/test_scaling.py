"""The scaling coefficient: eq. 18 of Pająk 2024 and the time-law planners' piecewise-quadratic clock."""

import numpy as np
import pytest

from drake_traj import QuinticConfig, get_robot
from drake_traj.planners import make_planner
from drake_traj.planners.laws.scaling import admissible_clock_rate, clock_at, next_clock_rate, relaxed_scaling


def test_relaxed_scaling_is_eq_18_and_its_derivative():
    step = 1e-6
    for t in np.linspace(0.0, 3.0, 7):
        c, rate = relaxed_scaling(t, 0.5, 0.2, 0.8, 2.0)
        assert c == pytest.approx((0.2 - 0.8) * np.exp(-2.0 * (t - 0.5)) + 0.8, rel=1e-12)
        numeric = (relaxed_scaling(t + step, 0.5, 0.2, 0.8, 2.0)[0] - relaxed_scaling(t - step, 0.5, 0.2, 0.8, 2.0)[0]) / (2 * step)
        assert rate == pytest.approx(numeric, rel=1e-6)


def test_clock_is_the_integral_of_a_linear_c():
    tau, c = clock_at(0.01, 2.0, 0.7, -3.0)
    assert c == pytest.approx(0.7 - 0.03)
    assert tau == pytest.approx(2.0 + 0.01 * (0.7 + c) / 2)  # trapezoid: exact for linear c


def test_next_rate_moves_towards_eq_18_by_at_most_jerk_times_period():
    # eq. 18 asks for ċ = 1 x (0.25 - 1) = -0.75 /s; 20 /s² over 1 ms allows a change of 0.02
    assert next_clock_rate(1.0, 0.0, 0.25, rate=1.0, jerk=20.0, period=1e-3) == pytest.approx(-0.02)
    assert next_clock_rate(1.0, -0.74, 0.25, rate=1.0, jerk=20.0, period=1e-3) == pytest.approx(-0.75)
    assert next_clock_rate(0.5, 0.0, 0.5, rate=1.0, jerk=20.0, period=1e-3) == 0.0  # at the goal
    # c stays in [0, cap] at the end of the period
    assert next_clock_rate(0.001, -5.0, 0.0, rate=1.0, jerk=20.0, period=1e-3) == pytest.approx(-1.0)
    assert next_clock_rate(0.999, 5.0, 1.0, rate=1.0, jerk=20.0, period=1e-3, cap=1.0) == pytest.approx(1.0)


def test_admissible_rates_keep_the_limits_and_never_exclude_holding_the_clock():
    rng = np.random.default_rng(3)
    limit = np.full(6, 1.4)
    for _ in range(200):
        c = rng.uniform(0.0, 1.0)
        qd, qdd = rng.uniform(-1.0, 1.0, 6), rng.uniform(-2.0, 2.0, 6)  # the law may break the limit
        low, high = admissible_clock_rate(c, qd, qdd, limit)
        assert low <= 0.0 <= high
        for rate in np.linspace(max(low, -50), min(high, 50), 11):
            q_ddot = c * c * qdd + rate * qd
            assert np.all(np.abs(q_ddot) <= np.maximum(0.999 * limit, np.abs(c * c * qdd)) + 1e-9)
        if np.isfinite(high):  # the bound is tight: just beyond it a joint breaks its bound
            q_ddot = c * c * qdd + (high + 1e-6) * qd
            assert np.any(np.abs(q_ddot) > np.maximum(0.999 * limit, np.abs(c * c * qdd)))
    assert admissible_clock_rate(0.5, np.zeros(6), np.ones(6), limit) == (-np.inf, np.inf)


def test_time_law_evaluation_is_kept_by_time_and_clock_state():
    # the planner keeps its last rates by (time, clock state): contexts that differ in either get
    # their own value, and the kept arrays cannot be changed by a caller
    ur10e = get_robot("ur10e")
    planner = make_planner(QuinticConfig(goals=[(ur10e.home_configuration + 0.3).tolist()]), ur10e,
                           ur10e.home_configuration)
    full, half = planner.CreateDefaultContext(), planner.CreateDefaultContext()
    for context in (full, half):
        context.SetTime(0.5)
    half.get_mutable_discrete_state(planner.clock_state_index).SetFromVector([0.0, 0.0, 0.5, 0.0])  # c = 0.5 since t = 0
    qdd_full = planner.evaluate(full)[0].copy()
    qdd_half, c_half = planner.evaluate(half)
    np.testing.assert_allclose(qdd_full, planner.law.rates_at(0.5)[1], rtol=0, atol=1e-15)
    np.testing.assert_allclose(qdd_half, 0.25 * planner.law.rates_at(0.25)[1], rtol=0, atol=1e-15)  # q_law'' c²
    assert c_half == 0.5 and np.array_equal(planner.evaluate(full)[0], qdd_full)
    full.SetTime(0.6)
    np.testing.assert_allclose(planner.evaluate(full)[0], planner.law.rates_at(0.6)[1], rtol=0, atol=1e-15)
    with pytest.raises(ValueError):
        planner.evaluate(full)[0][0] = 1.0


def test_time_law_derivatives_are_the_laws_rates_on_the_clock():
    # d/dt [q; q̇] = [q_law'(tau) c; q_law''(tau) c² + q_law'(tau) ċ] on the clock of the state
    ur10e = get_robot("ur10e")
    planner = make_planner(QuinticConfig(goals=[(ur10e.home_configuration + 0.3).tolist()]), ur10e,
                           ur10e.home_configuration)
    context = planner.CreateDefaultContext()
    context.SetTime(0.7)
    context.get_mutable_discrete_state(planner.clock_state_index).SetFromVector([0.3, -0.2, 0.6, 0.5])
    elapsed = 0.2
    tau, c = 0.3 + 0.6 * elapsed - 0.1 * elapsed**2, 0.6 - 0.2 * elapsed
    qd_law, qdd_law = planner.law.rates_at(tau)
    derivatives = planner.EvalTimeDerivatives(context).CopyToVector()
    np.testing.assert_allclose(derivatives, np.r_[qd_law * c, qdd_law * c**2 - 0.2 * qd_law], rtol=0, atol=1e-14)
    np.testing.assert_allclose(planner.GetOutputPort("acceleration_and_scaling").Eval(context), np.r_[derivatives[6:], c],
                               rtol=0, atol=1e-15)


def test_a_time_law_planner_that_overrides_evaluate_is_refused():
    # its evaluate would never run (the derivatives and outputs come from the law): say so
    from drake_traj.planners.quintic import QuinticPtpPlanner

    class Custom(QuinticPtpPlanner):
        def evaluate(self, context):
            return super().evaluate(context)

    ur10e = get_robot("ur10e")
    plan = make_planner(QuinticConfig(goals=[(ur10e.home_configuration + 0.3).tolist()]), ur10e,
                        ur10e.home_configuration).law
    with pytest.raises(TypeError, match="Custom overrides evaluate, which a TimeLawPlanner does not use"):
        Custom(plan, 1.05, 1.40)
