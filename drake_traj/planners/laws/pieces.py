"""A time law as exact polynomial pieces in simulation time (:func:`law_pieces`), the planned
reference of a :class:`~drake_traj.planners.base.TimeLawPlanner` before its run.

Every law in the package is a polynomial of degree <= 5 between its ``polynomial_breaks``
(quintic moves, quintic Hermite tables, a quintic B-spline, trapezoids, Ruckig's cubics, Toppra's
averaged table). On each piece q̈ at four interior points (Chebyshev nodes, the law's
``rates_at``, or its batched ``rates_along`` where the law has one) fixes the cubic q̈, and q̇ and
q at the first node (``sample``) fix the two integration constants. For
a law of degree <= 5 this is the law's own polynomial, to round-off, whatever the piece's length:
no difference of two positions enters (a fit through q at both ends loses eps |q| / h² in q̈).
Joint positions in rad (m for prismatic joints), times in s.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MIN_PIECE", "law_pieces", "merged_breaks"]

MIN_PIECE = 1e-9
"""The shortest piece [s]: breaks closer than this are merged (Drake's trajectories refuse pieces
shorter than 1e-10 s). A law whose q̈ jumps at two instants closer than 1 ns gets its q̈ wrong
on that nanosecond only (q by the jump × 1e-18 s²)."""

_NODES = 0.5 - 0.5 * np.cos((2 * np.arange(4) + 1) * np.pi / 8)  # sigma in (0, 1), the cubic's samples
_VANDERMONDE_INVERSE = np.linalg.inv(_NODES[:, None] ** np.arange(4))


def merged_breaks(breaks, duration: float, min_piece: float = MIN_PIECE) -> np.ndarray:
    """The increasing breaks [s] from 0 to ``duration``, those closer than ``min_piece`` to the
    previous one dropped (the last one moved to ``duration`` where it is the one too close)."""
    candidates = np.unique(np.clip(np.append(np.asarray(breaks, dtype=float), (0.0, duration)), 0.0, duration))
    kept = [candidates[0]]
    for value in candidates[1:]:
        if value - kept[-1] >= min_piece:
            kept.append(value)
    if kept[-1] != duration:
        kept[-1] = duration
    return np.array(kept)


def _antiderivative(coefficients: np.ndarray, anchor: float, value: np.ndarray) -> np.ndarray:
    """The antiderivative of sum_k coefficients[k] sigma^k (coefficients (P, K, n)) that equals
    ``value`` (K, n) at sigma = ``anchor``: coefficients (P + 1, K, n)."""
    raised = coefficients / np.arange(1, len(coefficients) + 1)[:, None, None]
    constant = value - np.tensordot(anchor ** np.arange(1, len(coefficients) + 1), raised, axes=1)
    return np.concatenate([constant[None], raised])


def law_pieces(law, rate: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The reference q(t) = q_law(rate t) of a time law run on a clock of constant rate, as
    polynomial pieces.

    Args:
        law: a :class:`~drake_traj.planners.laws.TimeLaw` of positive duration.
        rate: the clock rate c (tau = c t), > 0: a planner's ``speed_cap``.

    Returns:
        (breaks [s] (K + 1,) from 0 to ``law.duration / rate``, coefficients (K, 6, n)) with
        q(t) = sum_j coefficients[k, j] (t - breaks[k])^j [rad] on piece k: the law's
        ``polynomial_breaks`` (:func:`merged_breaks`) in simulation time.

    Raises:
        ValueError: the law lasts 0 s: no piece to make.
    """
    duration = float(law.duration)
    if not duration > 0.0:
        raise ValueError(f"the law lasts {duration} s: there are no pieces to make")
    breaks = merged_breaks(law.polynomial_breaks, duration)
    lengths = np.diff(breaks)  # h, law time [s]
    nodes = breaks[:-1, None] + lengths[:, None] * _NODES  # (K, 4) law times [s]
    if hasattr(law, "rates_along"):  # a law batched over law times (the contract's module docstring)
        acceleration = law.rates_along(nodes)[1]  # (K, 4, n)
        anchor = np.stack(law.sample(nodes[:, 0])[:2], axis=1)  # (K, q/q̇, n)
    else:
        acceleration = np.array([[law.rates_at(tau)[1] for tau in row] for row in nodes])
        anchor = np.array([law.sample(tau)[:2] for tau in nodes[:, 0]])
    h = lengths[:, None]
    # in sigma = (tau - break) / h: Q'' = h² q̈_law (a cubic), Q' = h q̇_law, Q = q_law
    second = np.einsum("ik,pin->kpn", _VANDERMONDE_INVERSE.T, acceleration * h[:, None] ** 2)
    first = _antiderivative(second, _NODES[0], anchor[:, 1] * h)
    position = _antiderivative(first, _NODES[0], anchor[:, 0])  # (6, K, n) in sigma
    span = (lengths / rate)[:, None, None]  # the piece in simulation time [s]: sigma = (t - break) / span
    coefficients = np.moveaxis(position, 0, 1) / span ** np.arange(6)[None, :, None]
    return breaks / rate, coefficients
