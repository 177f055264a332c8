"""The nodes of the timing's linear programs and the motion of a solution between them.

A solution is x = ṡ² and p = x' = 2 s̈ at the nodes s of the grid, x quadratic in s between
interior nodes; at the ends the motion starts (and stops) with a constant path jerk, x ∝
distance^(4/3) (:mod:`.path_timing`). Here: the first grid, evenly in the time of a bang-bang
estimate (:func:`initial_grid`), a finer grid started from a coarser one's solution
(:func:`refined_grid`), the time at the nodes (:func:`node_times`) and the samples (t, q, q̇, q̈)
at the nodes and the middle of every interval (:func:`node_samples`). Joint positions in rad,
t in s."""

from __future__ import annotations

import numpy as np

__all__ = ["initial_grid", "node_samples", "node_times", "refined_grid"]


def initial_grid(values, velocity, acceleration, points: int):
    """(grid nodes s, the estimate's x and p = x' there [rad²/s², rad/s²]): ``points`` nodes evenly
    spaced in the time of an estimate of the bang-bang optimum,
    so the nodes crowd where the path is slow and near the ends, plus the path's breaks (on a path
    through hundreds of dense goals the breaks alone left a hairpin turn two nodes, where the
    program stopped the path: "the path speed falls to 0"). The estimate, on 4001 samples: the
    path speed ṡ² = x at most min_j (v_j² / q'_j², a_j / |q''_j|) (the velocity limits, and the
    accelerations at constant ṡ), reached from rest and brought to rest at the path acceleration
    min_j a_j / |q'_j| (x' = 2 s̈), each a running minimum; t from ds / ṡ with ṡ linear in t
    between samples. Drake's Toppra gave the same T within 0.2 % on seeded tasks at 5 times the
    time, and fails on some paths with tight turns. ``values``: the path's
    :class:`~drake_traj.planners.timing.paths.PathValues`. The estimate's (x, p) at the nodes picks
    the rows the bang-bang program starts with (:mod:`.program`)."""
    path = values.path
    s = np.linspace(path.start_time(), path.end_time(), 4001)
    d1, d2 = (np.abs(value).T for value in values(s, 1, 2))
    with np.errstate(divide="ignore"):
        cap = np.min(np.minimum(velocity[:, None] ** 2 / d1**2, acceleration[:, None] / d2), axis=0)
        path_acceleration = np.min(acceleration[:, None] / d1, axis=0)
    cap[[0, -1]] = 0.0
    ramp = np.concatenate([[0.0], np.cumsum(np.diff(s) * 0.5 * (path_acceleration[1:] + path_acceleration[:-1]))])
    # x(s) <= x(s') + 2 (A(s) - A(s')) for every s' before s, and the same towards the end
    forward = 2 * ramp + np.minimum.accumulate(cap - 2 * ramp)
    backward = 2 * (ramp[-1] - ramp) + np.minimum.accumulate((cap - 2 * (ramp[-1] - ramp))[::-1])[::-1]
    estimate = np.maximum(np.minimum(forward, backward), 0.0)
    rate = np.sqrt(estimate)
    times = np.concatenate([[0.0], np.cumsum(2 * np.diff(s) / np.maximum(rate[1:] + rate[:-1], 1e-300))])
    nodes = _with_breaks(path, np.interp(np.linspace(0.0, times[-1], points), times, s))
    x = np.interp(nodes, s, estimate)
    return nodes, x, np.gradient(x, nodes)


def refined_grid(path, coarse: np.ndarray, x: np.ndarray, p: np.ndarray, points: int):
    """(nodes s, x, p) of a finer grid of ``points`` nodes evenly spaced in the time of the coarse
    grid's solution (x, p) at its nodes ``coarse``, plus the path's breaks, with x and p
    interpolated there: the start of the finer grid's programs. On the end intervals x follows
    the end law, x ∝ distance^(4/3)."""
    times = node_times(coarse, x, p)
    s = _with_breaks(path, np.interp(np.linspace(0.0, times[-1], points), times, coarse))
    x_fine, p_fine = np.interp(s, coarse, x), np.interp(s, coarse, p)
    first, last = s < coarse[1], s > coarse[-2]
    x_fine[first] = x[1] * ((s[first] - coarse[0]) / (coarse[1] - coarse[0])) ** (4 / 3)
    x_fine[last] = x[-2] * ((coarse[-1] - s[last]) / (coarse[-1] - coarse[-2])) ** (4 / 3)
    return s, x_fine, p_fine


def _with_breaks(path, s: np.ndarray) -> np.ndarray:
    """Grid nodes ``s`` in order within the path, with the path's own breaks as nodes (q⃛ may
    jump there) and the nodes too close to one dropped."""
    breaks = np.asarray(path.get_segment_times(), dtype=float)[1:-1]
    s = np.maximum.accumulate(np.clip(s, path.start_time(), path.end_time()))
    s[0], s[-1] = path.start_time(), path.end_time()
    if len(breaks):
        spacing = np.interp(breaks, s[1:], np.diff(s))
        near = (np.abs(s[:, None] - breaks[None, :]) < 0.3 * spacing[None, :]).any(axis=1)
        near[[0, -1]] = False
        s = np.sort(np.concatenate([s[~near], breaks]))
    keep = np.concatenate([[True], np.diff(s) > 1e-9 * (s[-1] - s[0])])
    s = s[keep]
    s[-1] = path.end_time()
    return s


_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(8)


def node_times(s: np.ndarray, x: np.ndarray, p: np.ndarray) -> np.ndarray:
    """t at the nodes [s]: on the end intervals 3 h / √x (constant path jerk, x ∝ distance^(4/3));
    between interior nodes the integral of ds / √x with x the quadratic of (x, x') at both ends
    (8-point Gauss-Legendre)."""
    h = np.diff(s)
    u = 0.5 * (1 + _GAUSS_NODES)[None, :] * h[:, None]  # (N-1, 8)
    curvature = (p[1:] - p[:-1]) / h
    inside = x[:-1, None] + p[:-1, None] * u + 0.5 * curvature[:, None] * u**2
    dt = 0.5 * h * (_GAUSS_WEIGHTS / np.sqrt(np.maximum(inside, 1e-300))).sum(axis=1)
    dt[0] = 3 * h[0] / np.sqrt(x[1])
    dt[-1] = 3 * h[-1] / np.sqrt(x[-2])
    return np.concatenate([[0.0], np.cumsum(dt)])


def _midpoints(s: np.ndarray, x: np.ndarray, p: np.ndarray):
    """(s, x, p, time from the interval's start [s]) at the middle (in s) of every interval: x
    quadratic inside, x ∝ distance^(4/3) on the end intervals."""
    h = np.diff(s)
    half = 0.5 * h
    curvature = (p[1:] - p[:-1]) / h
    x_mid = x[:-1] + p[:-1] * half + 0.5 * curvature * half**2
    p_mid = p[:-1] + curvature * half
    u = 0.5 * (1 + _GAUSS_NODES)[None, :] * half[:, None]
    inside = x[:-1, None] + p[:-1, None] * u + 0.5 * curvature[:, None] * u**2
    dt = 0.5 * half * (_GAUSS_WEIGHTS / np.sqrt(np.maximum(inside, 1e-300))).sum(axis=1)
    x_mid[0], x_mid[-1] = x[1] * 2 ** (-4 / 3), x[-2] * 2 ** (-4 / 3)
    p_mid[0], p_mid[-1] = 8 * x_mid[0] / (3 * h[0]), -8 * x_mid[-1] / (3 * h[-1])
    dt[0] = 3 * h[0] * 2 ** (-1 / 3) / np.sqrt(x[1])
    dt[-1] = 3 * h[-1] * (1 - 2 ** (-1 / 3)) / np.sqrt(x[-2])
    return s[:-1] + half, x_mid, p_mid, dt


def node_samples(program, x: np.ndarray, p: np.ndarray):
    """(t, [q, q̇, q̈] (K, 3, n), [s, ṡ, s̈] (K, 3)) of the solution (x, p) of ``program`` (its grid
    ``s`` and the path's ``values``) at the nodes and the middle of every interval (the knots of
    the pieces), at rest at both ends."""
    nodes = node_times(program.s, x, p)
    s_mid, x_mid, p_mid, dt_mid = _midpoints(program.s, x, p)
    order = np.argsort(np.concatenate([program.s, s_mid]), kind="stable")
    s = np.concatenate([program.s, s_mid])[order]
    x = np.concatenate([x, x_mid])[order]
    p = np.concatenate([p, p_mid])[order]
    t = np.concatenate([nodes, nodes[:-1] + dt_mid])[order]
    q, d1, d2 = program.values(s, 0, 1, 2)
    rate = np.sqrt(np.maximum(x, 0.0))
    qd = d1 * rate[:, None]
    qdd = d1 * (0.5 * p)[:, None] + d2 * x[:, None]
    return t, np.stack([q, qd, qdd], axis=1), np.stack([s, rate, 0.5 * p], axis=1)
