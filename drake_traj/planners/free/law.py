"""The free-motion planner's motion: its legs (:class:`Leg`, one per goal: the path found, shortened,
timed and checked) and the timed legs one after the other as a time law (:class:`FreeMotionLaw`).
Joint positions in rad, times in s."""

from dataclasses import dataclass

import numpy as np

from drake_traj.errors import Cause, PlanningError
from drake_traj.planners.laws.hermite import HermiteLaw

__all__ = ["FreeMotionLaw", "Leg"]


class FreeMotionLaw:
    """The found and timed motion as a time law (:class:`~drake_traj.planners.laws.TimeLaw`):
    each leg's :class:`~drake_traj.planners.timing.SmoothTiming` in turn, at rest between
    them, as one :class:`HermiteLaw` of their checked pieces. Until the planner has planned
    (:meth:`~drake_traj.planners.free.system.FreeMotionPlanner.plan_in`), asking for it raises a
    :class:`PlanningError`."""

    acceleration_jumps = np.zeros(0)  # the legs meet at rest, each leg C2

    def __init__(self, q_start: np.ndarray):
        self.q_start = q_start
        self._law = None

    def set_legs(self, timings) -> None:
        """The motion of the timed legs (each a SmoothTiming from the previous leg's end)."""
        knots, samples, offset = [], [], 0.0
        for k, timing in enumerate(timings):
            own, table = np.asarray(timing.law.knots), _knot_samples(timing)
            first = 0 if k == 0 else 1  # a leg's first knot is the previous leg's last
            knots.append(own[first:] + offset)
            samples.append(table[first:])
            offset += timing.duration
        samples = np.concatenate(samples)
        pieces = np.concatenate([timing.coefficients for timing in timings])  # the legs' checked pieces themselves
        law = HermiteLaw(np.concatenate(knots), samples, samples, pieces=pieces)
        self._law = law
        self.rates_at, self.sample = law.rates_at, law.sample  # the hot path, without this wrapper

    def _planned(self) -> HermiteLaw:
        if self._law is None:
            raise PlanningError("the free-motion planner has not planned its path yet: it plans in its cell when the "
                                "preflight or the station's check gives it one (FreeMotionPlanner.plan_in)",
                                cause=Cause.PLANNING)
        return self._law

    @property
    def duration(self) -> float:
        return self._planned().duration

    @property
    def polynomial_breaks(self) -> np.ndarray:
        return self._planned().polynomial_breaks

    def rates_at(self, tau: float):
        return self._planned().rates_at(tau)

    def sample(self, tau: float):
        return self._planned().sample(tau)


@dataclass(frozen=True)
class Leg:
    """One goal's path: the found vertices, the shortened ones, the timed spline, what it took."""

    found: np.ndarray  # (k, n) [rad] OMPL's path (two rows where the straight segment was free)
    vertices: np.ndarray  # (k', n) [rad] after shortcutting
    timing: object  # SmoothTiming
    check: object  # the cell check's MotionCheck of the timed leg
    density: float | None  # [rad] the spline's points along the segments (None: the vertices only)
    search_seconds: float
    samples: int


def _knot_samples(timing) -> np.ndarray:
    """(q, q̇, q̈) [rad, rad/s, rad/s²] at every knot of a timed leg (a SmoothTiming), (K, 3, n), as
    its own law gives them: each quintic piece's start (its monomial coefficients c0, c1, 2 c2),
    and the leg's end, at rest."""
    c = timing.coefficients
    end = np.stack(timing.law.sample(timing.duration))[None]
    return np.concatenate([np.stack([c[:, 0], c[:, 1], 2.0 * c[:, 2]], axis=1), end])
