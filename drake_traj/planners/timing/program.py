"""The timing's linear programs on one grid (Palleschi et al. 2019's sequential linearisation of
the jerk, the TOPP-RA velocity and acceleration constraints of Pham & Pham 2018), solved by
HiGHS: :func:`solve_on_grid`, the best of a sequence of programs, each linearised at the one
before. x = ṡ² and p = x' = 2 s̈ at the nodes [rad²/s², rad/s²] (s in rad)."""

from __future__ import annotations

import numpy as np
import scipy.sparse
import highspy

from drake_traj.planners.timing.grid import node_times
from drake_traj.planners.timing.motion import InfeasibleTimingError

__all__ = ["END_JERK_MARGIN", "LIMIT_MARGIN", "NEAR_BOUND", "TRUST_REGION", "solve_on_grid"]

LIMIT_MARGIN = 0.99
"""The linear programs aim at this share of each limit; the exact check and the repair do the rest."""
END_JERK_MARGIN = 0.93
"""The share of the jerk limit the programs aim at on the first and last 3 nodes."""
TRUST_REGION = 1.3
"""x may grow by at most this factor from one linear program to the next (where √x is frozen)."""
NEAR_BOUND = 0.85
"""A row of the acceleration, the jerk or the path speed mid-interval enters HiGHS's model once its
value at the last iterate (or at the bang-bang estimate) reaches this share of its bound, or once a
solution breaks it; the others (about 5 in 6 on a 200-node grid) cannot bind at the optimum and
only slowed every simplex iteration."""


_STATUS = (highspy.HighsBasisStatus.kLower, highspy.HighsBasisStatus.kBasic, highspy.HighsBasisStatus.kUpper)


class _QuietHighs(highspy.Highs):
    """highspy's HiGHS with its log off from the start: ``Highs.__init__`` registers its callbacks
    (``enableCallbacks``), which writes HiGHS's banner to stdout unless ``output_flag`` is already
    false by then."""

    def enableCallbacks(self):
        self.setOptionValue("output_flag", False)
        super().enableCallbacks()


def _acceleration_rows(N, h, d1, d2, m1, m2):
    """q̈ = q'' x + q' p / 2 of every joint (a group of :func:`_matrix`) at the interior nodes, then
    mid-interval (x_mid = x_k + h (3 p_k + p_{k+1}) / 8, p_mid = (p_k + p_{k+1}) / 2 on the interior
    intervals k = 1..N-3): ``h`` the spacing [rad], ``d1``, ``d2`` q', q'' at the nodes and ``m1``,
    ``m2`` mid-interval ((N, n) and (N-3, n), [1] and [1/rad])."""
    node, k, hm = np.arange(1, N - 1), np.arange(1, N - 2), h[1:-1, None]
    at_nodes = np.stack([d2[1:-1], 0.5 * d1[1:-1]], axis=2)  # (N-2, n, 2)
    mid = np.stack([m2, m2 * (hm / 8 * 3) + 0.25 * m1, m2 * (hm / 8) + 0.25 * m1], axis=2)  # (N-3, n, 3)
    columns = [np.stack([node, N + node], axis=1), np.stack([k, N + k, N + k + 1], axis=1)]
    return (np.concatenate([np.full(N - 2, 2), np.full(N - 3, 3)]), np.concatenate([c.ravel() for c in columns]),
            np.concatenate([block.transpose(1, 0, 2).reshape(d1.shape[1], -1) for block in (at_nodes, mid)], axis=1))


def _path_speed_rows(N, h):
    """The rows on x alone (a group of :func:`_matrix`): x_mid, x_mid - (x_k + x_{k+1}) / 4 on the
    interior intervals k, the continuity of x on them, p = 4 x / (3 h) next to the start and
    p = -4 x / (3 h) next to the end (``h`` the spacing [rad])."""
    k, hm = np.arange(1, N - 2), h[1:-1]
    ones = np.ones_like(hm)
    around = np.stack([k, k + 1, N + k, N + k + 1], axis=1).ravel()
    values = [np.stack([ones, hm / 8 * 3, hm / 8], axis=1),
              np.stack([0.75 * ones, -0.25 * ones, hm / 8 * 3, hm / 8], axis=1),
              np.stack([-ones, ones, -0.5 * hm, -0.5 * hm], axis=1),
              [[-4 / (3 * h[0]), 1.0], [4 / (3 * h[-1]), 1.0]]]
    columns = [np.stack([k, N + k, N + k + 1], axis=1).ravel(), around, around, [1, N + 1, N - 2, 2 * N - 2]]
    return (np.concatenate([np.full(N - 3, 3), np.full(2 * (N - 3), 4), [2, 2]]), np.concatenate(columns),
            np.concatenate([np.ravel(value) for value in values])[None, :])


def _jerk_rows(N, h, d1, d2, after, before):
    """q⃛ / √x = q''' x + 1.5 q'' p + 0.5 q' x'' of every joint (a group of :func:`_matrix`): at
    every interior node i on interval i (its left end, q''' ``after`` the node), then on interval
    i - 1 (its right end, q''' ``before`` it); x'' = (p_{k+1} - p_k) / h inside, 4 x / (9 h²) on the
    end intervals (``h`` the spacing [rad]; q', q'', q''' at the nodes (N, n) [1, 1/rad, 1/rad²])."""
    i = np.arange(1, N - 2)  # nodes 1..N-3 on the interval to their right; nodes i + 1 on the one to their left
    slope, bend, hi = 0.5 * d1, 1.5 * d2, h[i, None]
    left = np.stack([after[i], bend[i] - slope[i] / hi, slope[i] / hi], axis=2)  # (N-3, n, 3)
    right = np.stack([before[i + 1], -slope[i + 1] / hi, bend[i + 1] + slope[i + 1] / hi], axis=2)
    left_end = np.stack([after[N - 2] + slope[N - 2] * (4 / (9 * h[-1] ** 2)), bend[N - 2]], axis=1)  # (n, 2)
    right_end = np.stack([before[1] + slope[1] * (4 / (9 * h[0] ** 2)), bend[1]], axis=1)
    columns = [np.stack([i, N + i, N + i + 1], axis=1).ravel(), [N - 2, 2 * N - 2, 1, N + 1],
               np.stack([i + 1, N + i, N + i + 1], axis=1).ravel()]
    n = d1.shape[1]
    return (np.concatenate([np.full(N - 3, 3), [2, 2], np.full(N - 3, 3)]), np.concatenate(columns),
            np.concatenate([left.transpose(1, 0, 2).reshape(n, -1), left_end, right_end,
                            right.transpose(1, 0, 2).reshape(n, -1)], axis=1))


def _matrix(groups, num_columns: int):
    """The CSR matrix of row ``groups`` in order, each (entries per row (R,), their columns (E,),
    their values (g, E)): g copies of the same R rows, values of their own (a joint's rows, joint
    after joint)."""
    counts = np.concatenate([np.tile(count, len(values)) for count, _, values in groups])
    starts = np.zeros(len(counts) + 1, dtype=np.int32)
    np.cumsum(counts, out=starts[1:])
    indices = np.concatenate([np.tile(columns, len(values)) for _, columns, values in groups]).astype(np.int32)
    values = np.concatenate([values.ravel() for _, _, values in groups])
    return scipy.sparse.csr_matrix((values, indices, starts), shape=(len(counts), num_columns))


class _Program:
    """The linear program of one iteration, in z = [x (N), p (N)], x = ṡ² and p = x' = 2 s̈ at the
    nodes, x quadratic in s between interior nodes (so s̈ is continuous): maximise the sum of x
    weighted by the grid spacing subject to the velocity bound, the acceleration at the nodes and
    between them, and the jerk at both ends of every interval with √x frozen at the previous
    iterate (the linearisation of Palleschi et al. 2019).

    The rows, in ``matrix``'s order: the acceleration per joint (nodes, then mid-interval), the
    path speed mid-interval (its velocity bound, x_mid >= (x_i + x_{i+1}) / 4), the equalities
    (continuity of x, the end laws), the jerk per joint. HiGHS's model holds the equalities and the
    rows near their bounds or broken by a solution (``rows``, :data:`NEAR_BOUND`): each program's
    solution is the one of all its rows."""

    def __init__(self, values, s, velocity, acceleration, jerk, guess=None):
        N, n = len(s), len(velocity)
        h = np.diff(s)
        self.s, self.num_nodes, self.num_joints, self.values, self.guess = s, N, n, values, guess
        d1, d2 = values(s, 1, 2)
        # q''' on each side of the nodes (it jumps at the breaks of a cubic spline)
        offset = 1e-9 * (s[-1] - s[0])
        after, before = (values(side, 3)[0] for side in (np.minimum(s + offset, s[-1]), np.maximum(s - offset, s[0])))
        m1, m2 = values(0.5 * (s[1:-2] + s[2:-1]), 1, 2)  # interior intervals 1..N-3
        jerk_rows = _jerk_rows(N, h, d1, d2, after, before)
        num_accel = n * (2 * N - 5)
        self.num_fixed_rows = num_accel + 3 * (N - 3) + 2
        num_jerk = 2 * (N - 2) * n
        self.matrix = _matrix([_acceleration_rows(N, h, d1, d2, m1, m2), _path_speed_rows(N, h), jerk_rows], 2 * N)
        self.jerk = _matrix([jerk_rows], 2 * N)
        # the jerk ramps at the ends are where the pieces' jerk exceeds the nodes' most (by up to 8 %
        # on the seeded sweeps, through the frozen √x): aim lower on the first and last 3 nodes
        margin = np.full(N - 2, LIMIT_MARGIN)
        margin[:3] = margin[-3:] = END_JERK_MARGIN
        self.jerk_bound = np.concatenate([np.tile(margin, 2) * jerk[j] for j in range(n)])
        self.jerk_limits = np.repeat(jerk, 2 * (N - 2))
        with np.errstate(divide="ignore"):
            bound = np.min(velocity**2 / np.maximum(d1**2, 1e-300), axis=1)
            mid_bound = np.min(velocity**2 / np.maximum(m1**2, 1e-300), axis=1)
        self.velocity_bound = LIMIT_MARGIN**2 * bound
        self.velocity_bound[[0, -1]] = 0.0
        accel_bound = LIMIT_MARGIN * np.repeat(acceleration, 2 * N - 5)
        # x_mid <= the velocity bound, and x_mid >= (x_i + x_{i+1}) / 4, which keeps the quadratic
        # x >= x_i (1 - w)² + x_{i+1} w² > 0 across the interval (w in [0, 1]): a finite time
        infinite, zeros = np.full(N - 3, np.inf), np.zeros(N - 1)
        self.row_low = np.concatenate([-accel_bound, -infinite, np.zeros(N - 3), zeros, np.full(num_jerk, -np.inf)])
        self.row_high = np.concatenate([accel_bound, LIMIT_MARGIN**2 * mid_bound, infinite, zeros,
                                        np.full(num_jerk, np.inf)])
        w = np.zeros(N)
        w[:-1] += 0.5 * h
        w[1:] += 0.5 * h
        self.weights = w
        self._set_rows(np.arange(num_accel + 2 * (N - 3), self.num_fixed_rows))  # the equalities
        self.solver, self.scale, self.jerk_programs, self.status = None, np.ones(2 * N), 0, ""

    def solve(self, previous, growth: float) -> tuple[np.ndarray, np.ndarray]:
        """(x, p) of the LP; without ``previous`` (x, p) the jerk is left out (a bang-bang profile
        with continuous s̈); with it, x grows by at most the factor ``growth`` (the trust region).

        HiGHS now and then stops short of the optimum on a program it has warm-started (status
        "Unknown": numerical trouble, never infeasibility: x = 0 meets every row but the floor at
        the ends); the program is then solved again from a fresh start, then without the floor
        (at once where HiGHS found the program infeasible), and only a last failure is an error
        (naming the rows in the program and what to change)."""
        N = self.num_nodes
        upper = self.velocity_bound.copy()
        if previous is not None:
            upper = np.minimum(upper, growth * previous[0])
        lower = np.concatenate([np.zeros(N), np.full(N, -np.inf)])
        high = np.concatenate([upper, np.full(N, np.inf)])
        lower[[N, 2 * N - 1]] = high[[N, 2 * N - 1]] = 0.0
        if previous is None:  # the bang-bang program: the rows near their bounds at the guess, else all but the jerk's
            if self.guess is None:
                self._set_rows(np.arange(self.num_fixed_rows))
            self._start(np.ones(2 * N))
            if self.guess is not None:
                self._admit(np.concatenate(self.guess), NEAR_BOUND)
        else:
            fresh = self.solver is None  # a grid started from a coarser grid's solution
            if not self.jerk_programs:
                self._begin_jerk_programs(previous)
            self.jerk_programs += 1
            ends = [1, 2, N - 3, N - 2]  # the nodes next to the ends weigh nothing in the sum but their time,
            lower[ends] = np.minimum(previous[0][ends] / growth, high[ends])  # 3 h / √x, is long: they fall by the trust region's factor at most
            self._set_jerk_rows(previous[0] * growth)
            self._set_time_weights(previous[0])
            self._admit(np.concatenate(previous), NEAR_BOUND)
            if fresh:
                self.solver.setBasis(self._crash(np.concatenate(previous), lower, high))
        z = self._run(lower, high)
        if z is None and previous is not None and self.status != "Infeasible":
            self._start(self._scale(*previous))  # from a fresh start, scaled to the last iterate
            self.jerk_programs = 1
            self._set_jerk_rows(previous[0] * growth)
            self._set_time_weights(previous[0])
            z = self._run(lower, high)
        if z is None and previous is not None and lower[1] > 0:  # without the floor at the ends
            lower[[1, 2, N - 3, N - 2]] = 0.0
            z = self._run(lower, high)
        if z is None:
            rows = ("velocity_limit and acceleration_limit" if previous is None else
                    "velocity_limit, acceleration_limit and jerk_limit (the jerk linearised at the last iterate)")
            raise InfeasibleTimingError(
                f"the timing's linear program on {N} nodes ({rows}) failed: HiGHS reports {self.status!r} (numerical "
                f"trouble: x = 0 meets every row); give fewer grid_points (e.g. {max(20, N // 2)}), or limits closer "
                "to each other in size across the joints", field=("path",))
        z = z * self.scale
        return np.maximum(z[:N], 0.0), z[N:]

    def _begin_jerk_programs(self, previous) -> None:
        """The HiGHS model of the jerk programs, its columns scaled to ``previous`` (x, p) (x spans
        1e-6 near the ends to 1 mid-path, beyond HiGHS's absolute tolerances): from the bang-bang
        program's rows and basis, or on a grid started from a coarser grid's solution ``previous``,
        of the equalities alone (the rows near their bounds there come next, :meth:`_admit`, and
        the basis, :meth:`_crash`)."""
        if self.solver is None:
            self._start(self._scale(*previous))
        else:
            self._start(self._scale(*previous), self.solver.getBasis())

    def _set_time_weights(self, x_previous: np.ndarray) -> None:
        """The objective of a jerk program: the time's decrease to first order at the last iterate,
        Σ h / (2 x^(3/2)) δx (the plain Σ h x let a program stop the path at a node, x = 0, to
        speed up its neighbours: an infinite time)."""
        x = np.maximum(x_previous, 1e-6 * x_previous.max())
        weights = self.weights / x**1.5
        weights = weights / weights[1:-1].max()
        columns = np.arange(self.num_nodes, dtype=np.int32)
        self.solver.changeColsCost(self.num_nodes, columns, -weights * self.scale[:self.num_nodes])

    def _set_jerk_rows(self, x_previous: np.ndarray) -> None:
        """The jerk rows' bounds: the jerk limit over √x frozen at the last iterate (in the model
        and for the rows :meth:`_admit` may add)."""
        with np.errstate(divide="ignore"):
            bound = self.jerk_bound / np.tile(np.sqrt(np.maximum(x_previous[1:-1], 0.0)), 2 * self.num_joints)
        self.row_low[self.num_fixed_rows:], self.row_high[self.num_fixed_rows:] = -bound, bound
        position = np.flatnonzero(self.rows >= self.num_fixed_rows).astype(np.int32)
        jerk = self.rows[position]
        self.solver.changeRowsBounds(len(position), position, self.row_low[jerk], self.row_high[jerk])

    def _admit(self, z: np.ndarray, share: float) -> int:
        """Adds to HiGHS's model the rows outside it whose value at ``z`` (unscaled) exceeds ``share``
        of their bounds (by a relative 1e-9 at ``share`` 1: a broken row); how many."""
        value = self.matrix @ z
        reach = share * (1 + 1e-9 * (share >= 1))
        new = np.flatnonzero(((value > reach * self.row_high) | (value < reach * self.row_low)) & self._outside)
        if len(new):
            starts, indices, values = self._scaled_rows(new)
            self.solver.addRows(len(new), self.row_low[new], self.row_high[new], len(values), starts[:-1], indices,
                                values)
            self._set_rows(np.concatenate([self.rows, new]))
        return len(new)

    def _set_rows(self, rows: np.ndarray) -> None:
        """The rows of HiGHS's model, in its order (``rows``), and the others (``_outside``)."""
        self.rows = rows
        self._outside = np.ones(self.matrix.shape[0], dtype=bool)
        self._outside[rows] = False

    def _scaled_rows(self, rows: np.ndarray):
        """(starts, column indices, values) of ``rows`` of ``matrix``, its columns scaled by ``scale``
        (HiGHS's row-wise format)."""
        begin, count = self.matrix.indptr[rows], np.diff(self.matrix.indptr)[rows]
        starts = np.zeros(len(rows) + 1, dtype=np.int32)
        np.cumsum(count, out=starts[1:])
        entries = np.repeat(begin - starts[:-1], count) + np.arange(starts[-1])
        indices = self.matrix.indices[entries].astype(np.int32)
        return starts, indices, self.matrix.data[entries] * self.scale[indices]

    def _crash(self, z: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> highspy.HighsBasis:
        """A starting basis for the program near the point ``z`` (unscaled, a coarser grid's
        solution interpolated; column bounds ``lower``, ``upper``): the equalities, then the rows
        and the bounds of x closest to binding at ``z`` (relative to their size), as many as there
        are free columns, at their bounds; HiGHS repairs it where singular. From HiGHS's own start
        the first program of a 200-node grid took 1.4 times as long."""
        value = self.matrix[self.rows] @ z
        low, high = self.row_low[self.rows], self.row_high[self.rows]
        size = np.abs(value) + np.where(np.isfinite(high), np.abs(high), 0.0)
        size += np.where(np.isfinite(low), np.abs(low), 0.0)
        above = high - value <= value - low
        row_gap = np.where(low == high, -np.inf, np.minimum(high - value, value - low) / np.maximum(size, 1e-300))
        N = self.num_nodes
        x, x_low, x_high = z[:N], lower[:N], upper[:N]
        with np.errstate(invalid="ignore"):
            column_gap = np.minimum(x_high - x, x - x_low) / np.maximum(np.abs(x) + np.abs(x_high), 1e-300)
        column_gap[x_low == x_high] = np.inf  # the ends, fixed: nonbasic anyway
        picked = np.argsort(np.concatenate([row_gap, column_gap]), kind="stable")[:2 * N - 4]
        rows = np.ones(len(self.rows), dtype=int)  # basic
        columns = np.ones(2 * N, dtype=int)
        columns[[0, N - 1, N, 2 * N - 1]] = 0  # lower = upper
        chosen = picked[picked < len(rows)]
        rows[chosen] = np.where(above[chosen], 2, 0)
        chosen = picked[picked >= len(rows)] - len(rows)
        columns[chosen] = np.where(x_high[chosen] - x[chosen] <= x[chosen] - x_low[chosen], 2, 0)
        basis = highspy.HighsBasis()
        basis.col_status = [_STATUS[k] for k in columns.tolist()]
        basis.row_status = [_STATUS[k] for k in rows.tolist()]
        basis.valid = True
        return basis

    def jerk_ratio(self, x: np.ndarray, p: np.ndarray) -> float:
        """The largest |q⃛| over its limit at the nodes of the iterate (x, p), with its own √x."""
        rates = np.tile(np.sqrt(np.maximum(x[1:-1], 0.0)), 2 * self.num_joints)
        return float(np.max(np.abs(self.jerk @ np.concatenate([x, p])) * rates / self.jerk_limits))

    def _start(self, scale: np.ndarray, basis=None) -> None:
        """A HiGHS model of the programs' ``rows`` with columns scaled by ``scale``, from ``basis``
        (None: HiGHS's own start)."""
        self.scale = scale
        starts, indices, values = self._scaled_rows(self.rows)
        cost = np.concatenate([-self.weights, np.zeros(self.num_nodes)]) * scale
        lp = highspy.HighsLp()
        lp.num_col_, lp.num_row_ = len(cost), len(self.rows)
        lp.col_cost_, lp.col_lower_, lp.col_upper_ = cost, np.zeros(len(cost)), np.zeros(len(cost))
        lp.row_lower_, lp.row_upper_ = self.row_low[self.rows], self.row_high[self.rows]
        lp.a_matrix_.format_ = highspy.MatrixFormat.kRowwise
        lp.a_matrix_.num_col_, lp.a_matrix_.num_row_ = len(cost), len(self.rows)
        lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = starts, indices, values
        self.solver = _QuietHighs()
        # Devex pricing, no presolve: the same solutions in 0.8 of the time (the dual steepest
        # edge's weights cost more per iteration than they save here; presolve found nothing)
        self.solver.setOptionValue("simplex_dual_edge_weight_strategy", 1)
        self.solver.setOptionValue("presolve", "off")
        self.solver.passModel(lp)
        if basis is not None:
            self.solver.setBasis(basis)
        self.jerk_programs = 0

    def _run(self, lower: np.ndarray, upper: np.ndarray) -> np.ndarray | None:
        """The solution (scaled columns) of the program with these column bounds, None if HiGHS
        does not find it optimal (``status`` says why). The rows outside the model that a solution
        breaks are added and the program solved again (from its last basis) until none is."""
        columns = np.arange(len(lower), dtype=np.int32)
        self.solver.changeColsBounds(len(columns), columns, lower / self.scale, upper / self.scale)
        while True:
            self.solver.run()
            status = self.solver.getModelStatus()
            if status != highspy.HighsModelStatus.kOptimal:
                self.status = self.solver.modelStatusToString(status)
                return None
            z = np.asarray(self.solver.getSolution().col_value)
            if not self._admit(z * self.scale, 1.0):
                return z

    def _scale(self, x: np.ndarray, p: np.ndarray) -> np.ndarray:
        """Column scales: x at the given iterate, p at the larger of its value and x / h."""
        h = np.diff(self.s)
        spacing = np.minimum(np.append(h, h[-1]), np.insert(h, 0, h[0]))
        x_scale = np.maximum(x, 1e-9 * x.max())
        return np.concatenate([x_scale, np.maximum(np.abs(p), x_scale / spacing)])


def _iterate(program: _Program, iterations: int, start=None) -> tuple[np.ndarray, np.ndarray, int]:
    """(x, p, the programs with the jerk solved) of the best of the sequential linear programs:
    the first without the jerk (or the given ``start`` (x, p) instead), then up to
    ``iterations`` with it, each linearised at the one before, with √x frozen at the most the
    trust region lets x grow to (so an iterate keeps the jerk at the nodes). An iterate is judged
    by its time stretched until the jerk at the nodes holds with its own √x; where one is longer
    than the best so far, the trust region is halved. They stop once the best shortens by < 0.2 %
    (after 4), at an iterate equal to the one before, or at a degenerate iterate or a failing
    program after the first (the best so far is kept). From a ``start``, an InfeasibleTimingError
    where no program succeeds."""
    x, p = best = program.solve(None, np.inf) if start is None else start
    best_time, growth, solved = np.inf, TRUST_REGION, 0
    while solved < iterations:
        last = (x, p)
        try:
            x, p = program.solve((x, p), growth)
        except InfeasibleTimingError:
            if not solved:
                raise
            break
        solved += 1
        if not np.all(x[1:-1] > 0):  # a degenerate iterate: keep the best
            break
        if solved > 1 and np.array_equal(x, last[0]) and np.array_equal(p, last[1]):
            # the program kept its basis though the trust region and the jerk rows' bounds moved:
            # none of those binds, and the next programs (a smaller trust region, looser jerk rows,
            # the same objective) keep it too: they would return this iterate again
            break
        estimate = node_times(program.s, x, p)[-1] * max(1.0, program.jerk_ratio(x, p)) ** (1 / 3)
        if estimate < best_time:
            shorter = 1 - estimate / best_time
            best, best_time = (x, p), estimate
            if solved >= 4 and shorter < 2e-3:
                break
        else:
            growth = 1 + 0.5 * (growth - 1)
    if start is not None and best is start:
        raise InfeasibleTimingError("no program from the coarse grid's solution gave a motion", field=("path",))
    return (*best, solved)


def solve_on_grid(values, s: np.ndarray, limits, iterations: int, start=None, guess=None):
    """(program, x, p, the programs with the jerk solved): the best solution of the sequential
    linear programs on the grid nodes ``s`` of a path (``values``: its
    :class:`~drake_traj.planners.timing.paths.PathValues`) under ``limits`` (velocity,
    acceleration, jerk per joint [rad/s, rad/s², rad/s³]), from the bang-bang program or from
    ``start`` (x, p) (:func:`_iterate`); ``guess`` (x, p), an estimate of the bang-bang program's
    solution, picks the rows it starts with. ``program`` holds the grid (``s``) and ``values``. An
    InfeasibleTimingError where the programs fail."""
    program = _Program(values, s, *limits, guess=guess)
    return (program, *_iterate(program, iterations, start=start))
