"""The plan a smooth timing runs is the motion its exact check examined: the jerk limit (and the
velocity and acceleration limits) hold at every instant of ``plan()``, sampled densely by Drake,
on Ruckig's moves with phases microseconds long (where a quintic Hermite through the knots' states
turned the round-off of q into jerk 18.7 times the limit on a soak task)."""

import numpy as np
import pytest

from drake_traj.bench.soak_tasks import draw_task
from drake_traj.planners.base import piecewise_trajectory
from drake_traj.planners.free.law import FreeMotionLaw
from drake_traj.planners.laws.hermite import HermiteLaw
from drake_traj.planners.laws.pieces import law_pieces
from drake_traj.planners.smooth import SmoothPlanner
from drake_traj.planners.timing import stop_timing
from drake_traj.scenario import make_planner

TOLERANCE = 1e-6  # relative, the soak's


def _dense_peaks(plan) -> np.ndarray:
    """max |q̇|, |q̈|, |q⃛| per joint (3, n) of Drake's ``plan`` at every 0.1 ms and every 0.1 µs
    within 10 µs of each piece shorter than 0.1 ms (Drake's own evaluation of its derivatives)."""
    breaks = np.asarray(plan.get_segment_times())
    short = np.flatnonzero(np.diff(breaks) < 1e-4)
    times = np.concatenate([np.arange(0.0, plan.end_time(), 1e-4), [plan.end_time()],
                            *(np.arange(breaks[k] - 1e-5, breaks[k + 1] + 1e-5, 1e-7) for k in short)])
    times = np.clip(times, 0.0, plan.end_time())
    return np.stack([np.abs(plan.MakeDerivative(order).vector_values(times)).max(axis=1) for order in (1, 2, 3)])


def _short_move(q_start: float, phase: float, acceleration: float = 1.4, jerk: float = 14.0) -> np.ndarray:
    """One joint's rest-to-rest move from ``q_start`` [rad] whose time-optimal profile holds the
    acceleration limit for ``phase`` [s] (the velocity limit 1.05 rad/s not reached): the distance
    a (a / J + phase)(2 a / J + phase), waypoints (2, 1)."""
    ramp = acceleration / jerk
    return np.array([[q_start], [q_start + acceleration * (ramp + phase) * (2 * ramp + phase)]])


@pytest.mark.parametrize("seed", [485, 972, 329, 126])
def test_soak_tasks_plans_keep_every_limit_at_every_instant(seed):
    # seed 485 reached 18.7 times the jerk limit, 972 1.11 times, 329 and 126 1.006 and 1.004: each
    # passes its goals stopping at every one (Ruckig's moves), with phases 4-60 µs long
    planner = make_planner(draw_task("ur10e", "smooth_waypoints", seed).scenario)
    assert planner.timing.given_path is None  # the stop-at-every-goal moves were the faster
    limits = np.stack([planner.velocity_limit, planner.acceleration_limit, planner.jerk_limit])
    ratio = _dense_peaks(planner.plan()) / limits
    assert ratio.max() <= 1 + TOLERANCE
    assert ratio[2].max() > 0.999  # the jerk limit is reached: the samples see the bang-bang jerk


def test_a_microsecond_phase_far_from_zero_keeps_its_constant_acceleration():
    # one joint from 3 rad, the acceleration limit held for 1 µs: q̈ = a and q⃛ = 0 on that phase;
    # the Hermite quintic through its end states had q⃛ 356 times the limit there
    timing = stop_timing(_short_move(3.0, 1e-6), [1.05], [1.4], [14.0])
    phase = int(np.argmin(np.diff(timing.law.knots)))
    assert np.diff(timing.law.knots)[phase] == pytest.approx(1e-6, rel=1e-6)
    plan = SmoothPlanner(timing, [1.05], [1.4], [14.0]).plan()
    inside = timing.law.knots[phase] + np.linspace(0.1e-6, 0.9e-6, 9)
    assert np.abs(plan.MakeDerivative(2).vector_values(inside)).ravel() == pytest.approx(1.4, rel=1e-8)  # stretch 1 + 1e-9
    assert np.abs(plan.MakeDerivative(3).vector_values(inside)).max() <= 1e-6 * 14.0
    assert (_dense_peaks(plan).ravel() / np.array([1.05, 1.4, 14.0])).max() <= 1 + TOLERANCE


def test_free_motion_legs_run_as_their_own_pieces():
    # there and back, each leg with a 1 µs phase at 3 rad, as the free-motion planner's one law
    there = _short_move(3.0, 1e-6)
    legs = [stop_timing(there, [1.05], [1.4], [14.0]), stop_timing(there[::-1], [1.05], [1.4], [14.0])]
    law = FreeMotionLaw(there[0])
    law.set_legs(legs)
    assert law.duration == pytest.approx(legs[0].duration + legs[1].duration, rel=1e-15)
    for offset, leg, acceleration in zip((0.0, legs[0].duration), legs, (1.4, -1.4)):  # in each first 1 µs phase
        inside = offset + leg.law.knots[1] + np.linspace(0.1e-6, 0.9e-6, 9)
        assert [law.rates_at(tau)[1][0] for tau in inside] == pytest.approx([acceleration] * 9, rel=1e-8)
    plan = piecewise_trajectory(*law_pieces(law))
    assert (_dense_peaks(plan).ravel() / np.array([1.05, 1.4, 14.0])).max() <= 1 + TOLERANCE


def test_pieces_of_the_wrong_shape_are_refused():
    knots, states = np.array([0.0, 1.0]), np.zeros((2, 3, 2))
    with pytest.raises(ValueError, match=r"pieces must have shape \(1, P <= 6, 2\), got shape \(1, 7, 2\)"):
        HermiteLaw(knots, states, states, pieces=np.zeros((1, 7, 2)))
    cubic = np.zeros((1, 4, 2))
    cubic[0, 3] = [1.0, -2.0]  # q = t³, -2 t³
    law = HermiteLaw(knots, states, states, pieces=cubic)
    assert law.rates_at(0.5)[1] == pytest.approx([3.0, -6.0], rel=1e-15)  # q̈ = 6 t c3
