"""The time-law contract: what :class:`~drake_traj.planners.base.TimeLawPlanner` reads from a law.

A time law is a joint motion q_law(tau) on its own clock, law time tau [s] from 0 to
``duration``, at rest before 0 and after ``duration``. Joint positions are in rad (m for
prismatic joints), rates per second of law time. The planner runs the law on a scaled clock
(dτ/dt = c) and asks for nothing else, so any object with these members is a law: the contract
is a :class:`typing.Protocol` (structural, no base class to inherit), checked at run time by
:func:`missing_members` with ``isinstance``. Every class in the package that satisfies it is
named ``...Law``.

A law may also be batched over law times (not a member of the contract): ``rates_along(taus)``
gives ``rates_at`` at an array of law times in [0, duration], each taus.shape + (n,), and its
``sample`` then takes an array too. :func:`~drake_traj.planners.laws.pieces.law_pieces` uses both
where ``rates_along`` is present.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

__all__ = ["MEMBERS", "TimeLaw", "missing_members"]


@runtime_checkable
class TimeLaw(Protocol):
    """A joint time law for :class:`~drake_traj.planners.base.TimeLawPlanner`.

    Attributes:
        q_start: q_law(0) [rad or m], (n,): where the planner's reference starts.
        duration: the law's length in law time [s]; the task is finished when tau reaches it.
        acceleration_jumps: the law times [s] where q_law'' jumps, (J,) (empty: q_law'' is
            continuous), or None: it may jump anywhere. Where it jumps, the planner's next update
            sets the reference back on the law (a fixed integrator step integrates a jump with an
            error that would stay).
        polynomial_breaks: increasing law times [s] from 0 to ``duration`` between which q_law is
            one polynomial of degree <= 5, (B,): the pieces of the planner's ``plan()``
            (:func:`~drake_traj.planners.laws.pieces.law_pieces`), exact on them. A law that is
            not piecewise polynomial gives breaks dense enough for its quintic interpolation.
    """

    q_start: np.ndarray
    duration: float
    acceleration_jumps: np.ndarray | None
    polynomial_breaks: np.ndarray

    def rates_at(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """(q_law'(tau) [rad/s], q_law''(tau) [rad/s²]), each (n,), at one law time tau [s]: the
        planner's hot path, called once per integrator step."""

    def sample(self, tau: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q_law, q_law', q_law'') at law time tau [s], each (n,): where the planner sets the
        reference back on the law."""


def missing_members(law) -> list[str]:
    """The members of :class:`TimeLaw` that ``law`` lacks (empty for a time law: what the
    Protocol's ``isinstance`` checks, named). A member its class defines (a property of a law
    made at its first use) is looked up on the class, without evaluating it."""
    return [name for name in MEMBERS if not (hasattr(type(law), name) or hasattr(law, name))]


MEMBERS = tuple(TimeLaw.__annotations__) + tuple(
    name for name, value in vars(TimeLaw).items() if callable(value) and not name.startswith("_"))
