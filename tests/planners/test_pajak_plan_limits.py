"""The Pająk planner's plan keeps the joint limits at every instant, not only at the law's samples:
random UR10e tasks of the soak (``draw_task("ur10e", "pajak", seed)``, seeds the soak found
0.01-0.7 % over q̈_max between the 1 ms samples of the preflight, where the quintic Hermite
pieces round off the kinks and jumps of the law's q̈), checked by Drake's own evaluation of the
plan every 0.1 ms."""

import numpy as np
import pytest

from drake_traj.bench.soak_tasks import draw_task
from drake_traj.planners.laws import HermiteLaw
from drake_traj.scenario.scenario import make_planner

DENSE = 1e-4  # [s] between the samples of the plan
RELATIVE = 1e-6  # round-off allowed over a limit, relative to it

SEEDS = (1, 3, 4, 5, 6)


@pytest.fixture(scope="module", params=SEEDS)
def planned(request):
    planner = make_planner(draw_task("ur10e", "pajak", request.param).scenario)
    return planner, planner.plan()


def test_the_plan_keeps_the_limits_between_the_law_samples(planned):
    planner, plan = planned
    law = planner.pajak_law
    times = np.append(np.arange(plan.start_time(), plan.end_time(), DENSE), plan.end_time())
    qd = plan.MakeDerivative(1).vector_values(times)
    qdd = plan.MakeDerivative(2).vector_values(times)
    assert np.max(np.abs(qd) / law.qd_max[:, None]) <= 1.0 + RELATIVE
    peak = np.max(np.abs(qdd) / law.qdd_max[:, None])
    assert peak <= 1.0 + RELATIVE
    assert peak > 1.0 - 1e-3  # the limit is used


def test_the_plan_is_the_law_motion_slowed_by_its_excess(planned):
    planner, plan = planned
    law, run = planner.pajak_law, planner._run
    # the law keeps its box at every evaluation (RK4 stages included), at the limit on these tasks
    assert np.all(run["stage_peak"] <= law.qdd_max * (1.0 + 1e-12))
    assert np.max(np.abs(run["qdd"]) / law.qdd_max) == pytest.approx(1.0, abs=1e-12)
    # the quintic pieces through its samples pass the limit between them
    end = planner._rest_index() + 1
    samples = np.stack([run[name][:end] for name in ("q", "qd", "qdd")], axis=1)
    _, unslowed = HermiteLaw(run["t"][:end], samples, samples).peak_rates()
    excess = np.max(unslowed / law.qdd_max)
    assert excess > 1.0 + 1e-5
    # the plan: the same samples on a clock slower by sqrt(excess) (acceleration binds here)
    rate = 1.0 / np.sqrt(excess)
    assert planner.planned_duration() == pytest.approx(run["T"] / rate, rel=1e-12)
    knots = run["t"][:end] / rate
    np.testing.assert_allclose(plan.vector_values(knots).T, samples[:, 0], atol=1e-12)
    np.testing.assert_allclose(plan.MakeDerivative(1).vector_values(knots).T, samples[:, 1] * rate, atol=1e-9)
