"""planner.plan(): the planned reference before the run, as a Drake PiecewisePolynomial, equals
what the planner system outputs in the simulation (an independent computation: the Simulator
integrates the planner's rates), ends at the logged finish, and drives a diagram of one's own."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput, TrajectorySource

import drake_traj
from drake_traj import MovejConfig, PlanningError, RuckigConfig, ToppraConfig, get_robot, simulate
from drake_traj.planners import make_planner
from drake_traj.planners.laws.pieces import law_pieces, merged_breaks

STEP = 1e-3  # the shipped scenarios' integrator step and log period [s]


def quintic_task_planner(config):
    """A baseline on quintic_ptp's task (its start and joint goals), with that scenario."""
    scenario = drake_traj.load_scenario("quintic_ptp")
    return scenario, make_planner(config(scenario.planner.goals), get_robot(scenario.robot), scenario.start_configuration())


def shipped(name):
    scenario = drake_traj.load_scenario(name)
    return scenario, drake_traj.make_planner(scenario)


# name: (scenario and planner, bounds on |plan - simulated reference| for q [rad], q̇ [rad/s], q̈ [rad/s²]).
# Time-law planners: the Simulator integrates q from the law's velocity (a function of time only)
# with fixed-step RK2, the trapezoid rule: q is off by up to T h²/12 max|q'''| (4.5e-6 rad on
# quintic_ptp) and less where errors cancel. q̇ and q̈ are the law's own at the same clock (the
# reference's q̇ is not the integrated one): round-off, also at the steps where q̈ jumps (MoveJ's
# ramps, Boryga's arc ends; the integrated q̇ was off there by up to h |Δq̈| / 2, 5.6e-4 rad/s on
# movej). Pająk: the reference is the plan (the preflight's RK4 samples joined by quintic Hermite
# pieces) on the planner's clock, as every time law's.
CASES = {
    "quintic": (lambda: shipped("quintic_ptp"), (1e-6, 1e-9, 1e-9)),
    "boryga": (lambda: shipped("boryga_loop_ur10e"), (1e-6, 1e-9, 1e-9)),
    "li": (lambda: shipped("li_closed_path_4dof"), (1e-6, 1e-9, 1e-9)),
    "pajak": (lambda: shipped("pajak_sim3"), (1e-6, 1e-9, 1e-9)),
    "movej": (lambda: quintic_task_planner(lambda goals: MovejConfig(goals=goals, blend_radius=0.05)), (1e-6, 1e-9, 1e-9)),
    "ruckig": (lambda: quintic_task_planner(lambda goals: RuckigConfig(goals=goals)), (1e-6, 1e-9, 1e-9)),
    "toppra": (lambda: quintic_task_planner(lambda goals: ToppraConfig(path=goals, grid_points=1000)), (1e-6, 1e-9, 1e-9)),
}


def values(trajectory, times) -> np.ndarray:
    return np.array([trajectory.value(t).ravel() for t in times])


@pytest.mark.parametrize("name", sorted(CASES))
def test_plan_equals_the_simulated_reference(name):
    build, (q_bound, qd_bound, qdd_bound) = CASES[name]
    scenario, planner = build()
    plan = planner.plan()
    arguments = {key: value for key, value in scenario.station_arguments().items() if key != "planner"}
    result = simulate(planner, **(arguments | scenario.run_settings() | {"settle_time": 0.0}))
    assert result.succeeded, result.failure
    assert plan.start_time() == 0.0
    # the logged finish; Pająk's plan goes on while the law settles to rest after its task's finish
    assert planner.planned_duration() == pytest.approx(result.duration, abs=STEP)
    if not planner.plans_online:
        assert plan.end_time() == pytest.approx(planner.planned_duration(), abs=1e-12)
    else:  # at rest at its end (sim 3: 2.6 s later, 1 mrad on)
        assert plan.end_time() > planner.planned_duration()
        assert np.abs(plan.derivative(1).value(plan.end_time())).max() <= 1e-6
    logged = result.t <= plan.end_time()
    times = result.t[logged]
    differences = [np.abs(values(trajectory, times) - reference[logged]).max()
                   for trajectory, reference in ((plan, result.q_ref), (plan.derivative(1), result.qd_ref),
                                                 (plan.derivative(2), result.qdd_ref))]
    # measured [rad, rad/s, rad/s²]: boryga 1.8e-7, 4.1e-16, 6.2e-15; li 5.2e-8, 5.6e-16, 2.5e-14;
    # movej 1.9e-7, 1.1e-15, 5.6e-15; pajak 1.2e-7, 1.1e-16, 2.2e-16; quintic 1.2e-7, 1.0e-14, 1.4e-14;
    # ruckig 1.2e-7, 6.7e-16, 9.1e-15; toppra 1.2e-7, 1.1e-12, 1.9e-12
    print(f"{name}: max |plan - simulated reference| q {differences[0]:.2e} rad, q̇ {differences[1]:.2e} rad/s, "
          f"q̈ {differences[2]:.2e} rad/s²")
    assert differences[0] < q_bound
    assert differences[1] < qd_bound
    assert differences[2] < qdd_bound


def test_plan_is_kept_and_returned_as_a_copy():
    _, planner = shipped("quintic_ptp")
    first = planner.plan()
    first.shiftRight(1.0)  # the caller's copy
    second = planner.plan()
    assert second.start_time() == 0.0


def test_law_pieces_are_the_law_on_the_clock():
    """At a speed cap c, q(t) = q_law(c t): q̇ scales by c and q̈ by c² (boryga_loop_ur10e is
    slowed to its limits, c = 0.30)."""
    _, planner = shipped("boryga_loop_ur10e")
    assert planner.speed_cap < 0.5
    plan = planner.plan()
    c = planner.speed_cap
    times = np.random.default_rng(0).uniform(0.0, plan.end_time(), 300)
    law = np.array([np.concatenate(planner.law.sample(c * t)) for t in times])
    n = planner.num_joints
    np.testing.assert_allclose(values(plan, times), law[:, :n], atol=1e-12)
    np.testing.assert_allclose(values(plan.derivative(1), times), c * law[:, n:2 * n], atol=1e-11)
    np.testing.assert_allclose(values(plan.derivative(2), times), c * c * law[:, 2 * n:], atol=1e-9)


class _OneTimeAtATime:
    """A law seen without its batched ``rates_along``: law_pieces asks it one time at a time."""

    def __init__(self, law):
        self.law = law
        self.q_start, self.duration, self.polynomial_breaks = law.q_start, law.duration, law.polynomial_breaks
        self.rates_at, self.sample = law.rates_at, law.sample


@pytest.mark.parametrize("name", ["boryga_loop_ur10e", "toppra"])
def test_a_batched_law_gives_what_it_gives_one_time_at_a_time(name):
    """rates_along and an array sample (HermiteLaw's, ToppraLaw's) equal rates_at and sample at
    each time: rates_along within the law and at its ends (what it promises), sample outside it
    too; law_pieces from them equals law_pieces
    asking one time at a time (to round-off: q̈'s, amplified by 1/h³ in the jerk)."""
    if name == "toppra":
        _, planner = quintic_task_planner(ToppraConfig)
    else:
        _, planner = shipped(name)
    law = planner.law
    taus = np.concatenate([np.random.default_rng(1).uniform(-0.1, law.duration + 0.1, 400),
                           law.polynomial_breaks, [0.0, law.duration]])
    batched = law.rates_along(np.clip(taus, 0.0, law.duration)), law.sample(taus)
    for k, tau in enumerate(taus):
        for mine, theirs in zip((*batched[0], *batched[1]), (*law.rates_at(min(max(tau, 0.0), law.duration)),
                                                                *law.sample(tau))):
            np.testing.assert_allclose(mine[k], theirs, rtol=1e-14, atol=1e-14 * (1 + np.max(np.abs(theirs))))
    breaks, coefficients = law_pieces(law)
    one_at_a_time = law_pieces(_OneTimeAtATime(law))
    np.testing.assert_array_equal(breaks, one_at_a_time[0])
    times = np.linspace(0.0, 1.0, 7)[:, None] * np.diff(breaks)[None, :]  # (7, K) within each piece
    for order in range(4):
        mine, theirs = coefficients, one_at_a_time[1]
        for _ in range(order):
            mine, theirs = (c[:, 1:] * np.arange(1, c.shape[1])[None, :, None] for c in (mine, theirs))
        at = [sum(c[:, i] * times[..., None] ** i for i in range(c.shape[1])) for c in (mine, theirs)]
        scale = np.max(np.abs(at[1]))
        assert np.max(np.abs(at[0] - at[1])) <= (1e-12 if order < 3 else 1e-9) * scale, order


def test_merged_breaks_keep_the_ends():
    np.testing.assert_array_equal(merged_breaks([0.5, 0.5 + 1e-12, 1.0 - 1e-12], 1.0), [0.0, 0.5, 1.0])
    np.testing.assert_array_equal(merged_breaks([2.0], 1.0), [0.0, 1.0])


def test_a_motion_of_no_length_has_no_plan():
    scenario = drake_traj.load_scenario("quintic_ptp")
    planner = make_planner(type(scenario.planner)(goals=[scenario.start_configuration().tolist()]),
                           get_robot(scenario.robot), scenario.start_configuration())
    with pytest.raises(PlanningError, match="no trajectory to plan"):
        planner.plan()
    with pytest.raises(ValueError, match="no pieces"):
        law_pieces(planner.law)


def test_pajak_plan_raises_what_its_preflight_raises():
    scenario = drake_traj.load_scenario("pajak_sim3")
    axis = [[0.0, 0.0, 0.1, np.pi, 0.0, 0.75 * np.pi]]  # on the base's axis: no inverse kinematics
    planner = make_planner(type(scenario.planner)(waypoints=axis), get_robot(scenario.robot), scenario.start_configuration())
    with pytest.raises(PlanningError) as preflight:
        planner.preflight()
    with pytest.raises(PlanningError) as plan:
        planner.plan()
    assert (plan.value.cause, str(plan.value)) == (preflight.value.cause, str(preflight.value))


def test_plan_drives_a_diagram_of_ones_own():
    """TrajectorySource(planner.plan()) in a diagram with a logger: the logged [q; q̇] is the
    planner's law (independent of the plan's pieces) at every logged time."""
    _, planner = shipped("quintic_ptp")
    builder = DiagramBuilder()
    source = builder.AddSystem(TrajectorySource(planner.plan(), output_derivative_order=1))
    logger = LogVectorOutput(source.get_output_port(), builder, 0.01)
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(planner.planned_duration())
    log = logger.FindLog(simulator.get_context())
    law = np.array([np.concatenate(planner.law.sample(t)[:2]) for t in log.sample_times()])
    assert len(log.sample_times()) == int(planner.planned_duration() / 0.01) + 1
    np.testing.assert_allclose(log.data().T, law, atol=1e-12)
