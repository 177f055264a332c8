"""A joint time law tabulated at knots and interpolated by quintic Hermite polynomials
(:class:`HermiteLaw`), for laws that are costly to evaluate (Boryga's inverse kinematics at every
instant). Joint positions in rad (m for prismatic joints), law time tau in s."""

from __future__ import annotations

from bisect import bisect_right
from math import comb

import numpy as np

from drake_traj.planners.laws.polynomials import rate_peaks

__all__ = ["HermiteLaw", "joint_speed_cap", "quintic_hermite_coefficients", "sigma_derivatives"]


def quintic_hermite_coefficients(knots, right, left) -> np.ndarray:
    """The quintic Hermite polynomial on each knot interval that meets (q, q̇, q̈) at both ends.

    Args:
        knots: increasing times [s], (K,).
        right: (q, q̇, q̈) just after each knot [rad, rad/s, rad/s²], (K, 3, n); row K-1 unused.
        left: (q, q̇, q̈) just before each knot, (K, 3, n); row 0 unused.

    Returns:
        Monomial coefficients c0..c5 in s = t - knots[k] on interval k, (K-1, 6, n): q(s) =
        sum_j c_j s^j. The end values enter through q1 - q0, so the round-off of q [rad] reaches
        q̈ as eps |q| / h² (6e-10 rad/s² at |q| = 3 rad, h = 1 ms).
    """
    knots = np.asarray(knots, dtype=float)
    right, left = np.asarray(right, dtype=float), np.asarray(left, dtype=float)
    h = np.diff(knots)[:, None]
    (q0, v0, a0), (q1, v1, a1) = np.moveaxis(right[:-1], 1, 0), np.moveaxis(left[1:], 1, 0)
    delta = q1 - q0
    return np.stack([
        q0, v0, 0.5 * a0,
        (20 * delta - (8 * v1 + 12 * v0) * h - (3 * a0 - a1) * h**2) / (2 * h**3),
        (-30 * delta + (14 * v1 + 16 * v0) * h + (3 * a0 - 2 * a1) * h**2) / (2 * h**4),
        (12 * delta - 6 * (v1 + v0) * h + (a1 - a0) * h**2) / (2 * h**5),
    ], axis=1)


def sigma_derivatives(knots, coefficients, orders: int):
    """Piecewise quintics (monomial ``coefficients`` (K-1, 6, n) in tau - knots[k]) on each knot
    interval as polynomials in sigma in [-1, 1] (tau = mid + sigma half): (mid [s] (K-1,), half [s]
    (K-1,), [first, ..., ``orders``-th derivative in tau], the j-th with coefficients (6 - j, K-1, n)),
    for :mod:`~drake_traj.planners.laws.polynomials`'s peak finders."""
    knots = np.asarray(knots, dtype=float)
    half = 0.5 * np.diff(knots)
    scale = half[:, None]
    # q(sigma) = sum_k e_k sigma^k with tau - knot = half (1 + sigma): e_k = sum_j C(j, k) c_j half^j
    polynomial = np.stack([sum(comb(j, k) * coefficients[:, j] * scale**j for j in range(k, 6)) for k in range(6)])
    derivatives = []
    for _ in range(orders):
        polynomial = np.stack([(k + 1) * polynomial[k + 1] / scale for k in range(len(polynomial) - 1)])
        derivatives.append(polynomial)
    return knots[:-1] + half, half, derivatives


def _as_quintics(pieces, shape: tuple[int, int]) -> np.ndarray:
    """Monomial coefficients ``pieces`` (K-1, P <= 6, n) padded with zeros to (K-1, 6, n); a
    ValueError naming ``pieces`` where they are not (K-1, P, n) = ``shape`` with 1 <= P <= 6."""
    pieces = np.asarray(pieces, dtype=float)
    if pieces.ndim != 3 or (pieces.shape[0], pieces.shape[2]) != shape or not 1 <= pieces.shape[1] <= 6:
        raise ValueError(f"pieces must have shape ({shape[0]}, P <= 6, {shape[1]}), got shape {pieces.shape}")
    return np.pad(pieces, ((0, 0), (0, 6 - pieces.shape[1]), (0, 0)))


class HermiteLaw:
    """A joint time law tabulated at knots, between them the quintic Hermite polynomial that meets
    q, q̇ and q̈ at both ends (so q̈ is continuous except where the samples on both sides of a
    knot differ, the law's ``acceleration_jumps``). ``rates_at`` costs a bisection and two small
    polynomial evaluations, whatever the tabulated law cost.

    Args:
        knots: increasing law times [s], (K,), from 0 to the law's duration.
        right: (q, q̇, q̈) just after each knot, (K, 3, n); row K-1 is not used.
        left: (q, q̇, q̈) just before each knot, (K, 3, n); row 0 is not used. Where the law is
            continuous it equals ``right``.
        acceleration_jumps: the knots where q̈ jumps (for :class:`TimeLawPlanner`).
        pieces: the law's own pieces where they are known, monomial coefficients (K-1, P <= 6, n)
            in tau - knots[k] (a timed motion whose pieces were checked): the law is then exactly
            them, and ``right`` and ``left`` give only its start and end. The Hermite
            interpolation through the knots' states brings the round-off of q (eps |q|) into q⃛
            as up to 60 eps |q| / h³: hundreds of rad/s³ on a 4 µs piece.
    """

    def __init__(self, knots, right, left, acceleration_jumps=(), *, pieces=None):
        knots = np.asarray(knots, dtype=float)
        right, left = np.asarray(right, dtype=float), np.asarray(left, dtype=float)
        if knots.ndim != 1 or len(knots) < 2 or np.any(np.diff(knots) <= 0) or knots[0] != 0.0:
            raise ValueError(f"knots must increase from 0, got {len(knots)} knots")
        self.knots = knots
        self.duration = float(knots[-1])
        self.q_start = right[0, 0].copy()
        self.acceleration_jumps = np.asarray(acceleration_jumps, dtype=float)
        self._coefficients = quintic_hermite_coefficients(knots, right, left) if pieces is None else _as_quintics(
            pieces, (len(knots) - 1, right.shape[2]))
        # (q̇, q̈) at s as one product, powers (1, s, s², s³, s⁴) @ [j c_j | j (j - 1) c_j]: (K-1, 5, 2n)
        first = np.arange(1, 6)[None, :, None] * self._coefficients[:, 1:]
        second = np.arange(1, 5)[None, :, None] * first[:, 1:]
        self._rate_coefficients = np.concatenate([first, np.pad(second, ((0, 0), (0, 1), (0, 0)))], axis=2)
        self._end = left[-1].copy()

    @property
    def polynomial_breaks(self) -> np.ndarray:
        """The knots [s]: the law is one quintic between them."""
        return self.knots

    def interval_polynomials(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """q̇ and q̈ on each knot interval as polynomials in sigma in [-1, 1] (tau = mid + sigma
        half): (mid [s] (K-1,), half [s] (K-1,), q̇ coefficients (5, K-1, n), q̈ coefficients
        (4, K-1, n)), for :func:`~drake_traj.planners.laws.polynomials.rate_peaks`."""
        mid, half, (velocity, acceleration) = sigma_derivatives(self.knots, self._coefficients, 2)
        return mid, half, velocity, acceleration

    def peak_rates(self) -> tuple[np.ndarray, np.ndarray]:
        """(max |q̇|, max |q̈|) over the whole law per joint, exact to round-off (interval ends,
        both sides of every jump, and the extrema inside each interval)."""
        _, _, velocity, acceleration = self.interval_polynomials()
        v_peak, _, a_peak, _ = rate_peaks(velocity, acceleration)
        return v_peak.max(axis=0), a_peak.max(axis=0)

    def _interval(self, tau: float) -> tuple[int, float]:
        k = min(max(bisect_right(self.knots, tau) - 1, 0), len(self.knots) - 2)
        return k, tau - self.knots[k]

    def sample(self, tau) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, q̇, q̈) at law time ``tau`` [s], a float or an array, each tau.shape + (n,); at rest
        at the ends outside [0, duration]."""
        taus = np.asarray(tau, dtype=float)
        k, s = self._intervals(np.clip(taus, 0.0, self.duration))
        c = self._coefficients[k]  # (..., 6, n)
        powers = s[..., None] ** np.arange(6)
        q = np.einsum("...p,...pn->...n", powers, c)
        moving = ((taus >= 0.0) & (taus < self.duration))[..., None]
        q = np.where(taus[..., None] >= self.duration, self._end[0], q)
        qd = np.einsum("...p,...pn->...n", np.arange(1, 6) * powers[..., :5], c[..., 1:, :])
        qdd = np.einsum("...p,...pn->...n", np.array([2, 6, 12, 20]) * powers[..., :4], c[..., 2:, :])
        return q, np.where(moving, qd, 0.0), np.where(moving, qdd, 0.0)

    def _intervals(self, taus: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(the knot interval of each law time in ``taus`` [s], the time since its knot [s])."""
        k = np.clip(np.searchsorted(self.knots, taus, side="right") - 1, 0, len(self.knots) - 2)
        return k, taus - self.knots[k]

    def rates_at(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """(q̇, q̈) at law time ``tau`` [s] (the planner's hot path: one 5 × 2n product)."""
        n = self._end.shape[1]
        if tau >= self.duration or tau < 0.0:
            return np.zeros(n), np.zeros(n)
        k, s = self._interval(tau)
        s2 = s * s
        rates = np.array((1.0, s, s2, s2 * s, s2 * s2)) @ self._rate_coefficients[k]
        return rates[:n], rates[n:]

    def rates_along(self, taus) -> tuple[np.ndarray, np.ndarray]:
        """(q̇, q̈) at law times ``taus`` [s], each taus.shape + (n,): :meth:`rates_at` at many
        times in one call (zero outside [0, duration])."""
        taus = np.asarray(taus, dtype=float)
        n = self._end.shape[1]
        k, s = self._intervals(taus)
        s2 = s * s
        powers = np.stack([np.ones_like(s), s, s2, s2 * s, s2 * s2], axis=-1)
        rates = np.einsum("...p,...pm->...m", powers, self._rate_coefficients[k])
        rates = np.where(((taus >= 0.0) & (taus < self.duration))[..., None], rates, 0.0)
        return rates[..., :n], rates[..., n:]


def joint_speed_cap(law: HermiteLaw, velocity_limit, acceleration_limit) -> tuple[float, dict]:
    """The largest constant clock rate c <= 1 that keeps ``law`` within the joint limits.

    With a constant c, joint velocity scales by c and acceleration by c^2, so
    c = min(1, min_j v_lim_j / peak|qd_j|, sqrt(min_j a_lim_j / peak|qdd_j|)), with the law's
    exact peaks (:meth:`HermiteLaw.peak_rates`: on each knot interval the law is a polynomial;
    a sampled peak missed up to 0.07 % of the limit on seeded random loops).

    Returns:
        (c, peaks) with peaks = {"qd": per-joint peak |qd|, "qdd": per-joint peak |qdd|} at c = 1.
    """
    peak_qd, peak_qdd = law.peak_rates()
    with np.errstate(divide="ignore"):
        cap = min(
            1.0,
            float(np.min(np.asarray(velocity_limit) / peak_qd)),
            float(np.sqrt(np.min(np.asarray(acceleration_limit) / peak_qdd))),
        )
    return cap, {"qd": peak_qd, "qdd": peak_qdd}
