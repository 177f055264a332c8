"""The logged reference keeps the limits its planner promises at every logged sample: a time-law
planner's q̇ is its law's on the clock, not the q̇ the Simulator integrates from q̈ (which a
logger samples before the update that puts it back on the law, so a step's integration error
was logged: MoveJ's ramps ending at the velocity limit, Ruckig's jerk phases)."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from drake_traj import make_planner, simulate
from drake_traj.bench.soak_tasks import draw_task
from drake_traj.planners.base import PlannerSystem

LIMIT_TOLERANCE = 1e-6  # relative: the soak's


@pytest.mark.parametrize("planner_name, seed", [("movej", 50), ("ruckig", 800)])
def test_logged_reference_keeps_the_promised_limits(planner_name, seed):
    """UR10e soak tasks whose logged q̇ passed the velocity limit (movej seed 50 by 1.08e-3 of
    it, ruckig seed 800 by 2.6e-6) while their plan kept it."""
    scenario = draw_task("ur10e", planner_name, seed).scenario
    result = simulate(scenario)
    assert result.succeeded, result.failure
    metrics = result.metrics()
    assert metrics.peak_velocity_fraction <= 1 + LIMIT_TOLERANCE
    assert metrics.peak_acceleration_fraction <= 1 + LIMIT_TOLERANCE
    assert metrics.peak_velocity_fraction > 0.99  # the motion runs at its velocity limit
    # at every logged sample the reference is the law at tau = c t (c the speed cap: no override),
    # evaluated here by the law's own sample(), not by the planner's rates
    planner = make_planner(scenario)
    c = planner.speed_cap
    moving = result.t <= planner.planned_duration()
    q_law, qd_law, qdd_law = planner.law.sample(c * result.t[moving])
    np.testing.assert_allclose(result.qd_ref[moving], c * qd_law, rtol=0, atol=1e-12)
    np.testing.assert_allclose(result.qdd_ref[moving], c * c * qdd_law, rtol=0, atol=1e-9)
    np.testing.assert_allclose(result.q_ref[moving], q_law, rtol=0, atol=1e-6)  # integrated: RK2's error


class _ConstantAcceleration(PlannerSystem):
    """A planner of the bare contract: q̈ = 0.5 rad/s² on every joint, c = 0.8."""

    def evaluate(self, context):
        return np.full(self.num_joints, 0.5), 0.8

    def finished(self, context):
        return False


def test_reference_and_scaling_is_the_state_the_acceleration_and_c():
    """The station's one port [q; q̇; q̈; c]: a plain PlannerSystem's reference is its continuous
    state (here integrated exactly: q = q0 + a t²/2, q̇ = a t)."""
    q0 = np.linspace(-1.0, 1.0, 6)
    planner = _ConstantAcceleration(q0)
    simulator = Simulator(planner)
    simulator.AdvanceTo(0.4)
    context = simulator.get_context()
    expected = np.concatenate((q0 + 0.5 * 0.5 * 0.4**2, np.full(6, 0.5 * 0.4), np.full(6, 0.5), [0.8]))
    np.testing.assert_allclose(planner.GetOutputPort("reference_and_scaling").Eval(context), expected, atol=1e-12)
    np.testing.assert_allclose(planner.GetOutputPort("desired_state").Eval(context), expected[:12], atol=1e-12)


def test_time_law_reference_is_the_law_between_updates():
    """Mid-step (no update since the last one) a time-law planner's desired_state q̇ is the law's
    on the clock, q_law'(tau) c, and q is the integrated state; reference_and_scaling carries the
    same [q; q̇] with its q̈ and c."""
    scenario = draw_task("ur10e", "movej", 50).scenario
    planner = make_planner(scenario)
    simulator = Simulator(planner)
    simulator.AdvanceTo(1.0)
    context = simulator.get_context()
    context.SetTime(1.0004)  # between two updates (1 ms period)
    c = planner.speed_cap
    _, qd_law, qdd_law = planner.law.sample(c * 1.0004)
    reference = planner.GetOutputPort("desired_state").Eval(context)
    np.testing.assert_allclose(reference[6:], c * qd_law, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(reference[:6], context.get_continuous_state_vector().CopyToVector()[:6])
    np.testing.assert_allclose(planner.GetOutputPort("reference_and_scaling").Eval(context),
                               np.concatenate((reference, c * c * qdd_law, [c])), rtol=0, atol=1e-9)
