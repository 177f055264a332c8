"""The timing's linear programs on one grid (Palleschi et al. 2019's sequential linearisation of
the jerk, the TOPP-RA velocity and acceleration constraints of Pham & Pham 2018), solved by
HiGHS: :func:`solve_on_grid`, the best of a sequence of programs, each linearised at the one
before. x = ṡ² and p = x' = 2 s̈ at the nodes [rad²/s², rad/s²] (s in rad)."""

from __future__ import annotations

import numpy as np
import scipy.sparse
import highspy

from drake_traj.planners.timing.grid import node_times, path_derivatives
from drake_traj.planners.timing.motion import InfeasibleTimingError

__all__ = ["END_JERK_MARGIN", "LIMIT_MARGIN", "TRUST_REGION", "solve_on_grid"]

LIMIT_MARGIN = 0.99
"""The linear programs aim at this share of each limit; the exact check and the repair do the rest."""
END_JERK_MARGIN = 0.93
"""The share of the jerk limit the programs aim at on the first and last 3 nodes."""
TRUST_REGION = 1.3
"""x may grow by at most this factor from one linear program to the next (where √x is frozen)."""


class _QuietHighs(highspy.Highs):
    """highspy's HiGHS with its log off from the start: ``Highs.__init__`` registers its callbacks
    (``enableCallbacks``), which writes HiGHS's banner to stdout unless ``output_flag`` is already
    false by then."""

    def enableCallbacks(self):
        self.setOptionValue("output_flag", False)
        super().enableCallbacks()


class _Program:
    """The linear program of one iteration, in z = [x (N), p (N)], x = ṡ² and p = x' = 2 s̈ at the
    nodes, x quadratic in s between interior nodes (so s̈ is continuous): maximise the sum of x
    weighted by the grid spacing subject to the velocity bound, the acceleration at the nodes and
    between them, and the jerk at both ends of every interval with √x frozen at the previous
    iterate (the linearisation of Palleschi et al. 2019)."""

    def __init__(self, path, s, velocity, acceleration, jerk):
        N, n = len(s), path.rows()
        h = np.diff(s)
        self.s, self.num_nodes, self.num_joints = s, N, n
        self.derivatives = [path.MakeDerivative(k) for k in (1, 2, 3)]
        d1, d2, _ = path_derivatives(self.derivatives, s)
        # q''' on each side of the nodes (it jumps at the breaks of a cubic spline)
        offset = 1e-9 * (s[-1] - s[0])
        after = path_derivatives(self.derivatives, np.minimum(s + offset, s[-1]))[2]
        before = path_derivatives(self.derivatives, np.maximum(s - offset, s[0]))[2]
        sp = scipy.sparse
        X = sp.hstack([sp.identity(N), sp.csr_matrix((N, N))], format="csr")
        P = sp.hstack([sp.csr_matrix((N, N)), sp.identity(N)], format="csr")
        inner = slice(1, N - 1)
        # x'' on every interval: (p_{i+1} - p_i) / h inside, 4 x / (9 h²) at the node next to an end
        curvature = sp.diags(1 / h) @ (P[1:] - P[:-1])
        curvature = sp.vstack([X[1] * (4 / (9 * h[0] ** 2)), curvature[1:-1], X[N - 2] * (4 / (9 * h[-1] ** 2))],
                              format="csr")
        # continuity of x (interior intervals) and the end laws p = ±4 x / (3 h)
        continuity = (X[2:N - 1] - X[1:N - 2]) - sp.diags(0.5 * h[1:-1]) @ (P[1:N - 2] + P[2:N - 1])
        self.equality = sp.vstack([continuity, P[1] - X[1] * (4 / (3 * h[0])), P[N - 2] + X[N - 2] * (4 / (3 * h[-1]))],
                                  format="csr")
        mid = 0.5 * (s[1:-2] + s[2:-1])  # interior intervals 1..N-3
        m1, m2 = path_derivatives(self.derivatives, mid)[:2]
        hm = h[1:-1]
        x_mid = X[1:N - 2] + sp.diags(hm / 8) @ (3 * P[1:N - 2] + P[2:N - 1])
        p_mid = 0.5 * (P[1:N - 2] + P[2:N - 1])

        def per_joint(coefficients, block):
            """The rows diag(coefficients[:, j]) @ block for every joint j, joint after joint."""
            return sp.diags(coefficients.T.ravel()) @ sp.vstack([block] * n, format="csr")

        # per joint: the acceleration at the nodes, then mid-interval
        self.accel = (per_joint(np.concatenate([d2[inner], m2]), sp.vstack([X[inner], x_mid]))
                      + per_joint(0.5 * np.concatenate([d1[inner], m1]), sp.vstack([P[inner], p_mid]))).tocsr()
        self.accel_bound = LIMIT_MARGIN * np.concatenate([np.full(N - 2 + len(mid), acceleration[j]) for j in range(n)])
        # per joint: node i on interval i (its left end), then on interval i - 1 (its right end)
        self.jerk = (per_joint(1.5 * np.concatenate([d2[inner], d2[inner]]), sp.vstack([P[inner], P[inner]]))
                     + per_joint(0.5 * np.concatenate([d1[inner], d1[inner]]), sp.vstack([curvature[1:], curvature[:-1]]))
                     + per_joint(np.concatenate([after[inner], before[inner]]), sp.vstack([X[inner], X[inner]]))).tocsr()
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
        # x_mid <= the velocity bound, and x_mid >= (x_i + x_{i+1}) / 4, which keeps the quadratic
        # x >= x_i (1 - w)² + x_{i+1} w² > 0 across the interval (w in [0, 1]): a finite time
        self.mid = sp.vstack([x_mid, x_mid - 0.25 * (X[1:N - 2] + X[2:N - 1])], format="csr")
        self.mid_low = np.concatenate([np.full(len(mid), -np.inf), np.zeros(len(mid))])
        self.mid_bound = np.concatenate([LIMIT_MARGIN**2 * mid_bound, np.full(len(mid), np.inf)])
        w = np.zeros(N)
        w[:-1] += 0.5 * h
        w[1:] += 0.5 * h
        self.weights = w
        # every program has the same rows (the first with the jerk rows unbounded) and the jerk
        # programs the same matrix (√x frozen divides the jerk rows' bounds), so HiGHS keeps its
        # factorisation and basis from one jerk program to the next and only the bounds change:
        # its dual simplex then takes tens of iterations, not thousands
        self.matrix = sp.vstack([self.accel, self.mid, self.equality, self.jerk], format="csr")
        self.num_fixed_rows = self.matrix.shape[0] - self.jerk.shape[0]
        zeros = np.zeros(self.equality.shape[0])
        self.row_low = np.concatenate([-self.accel_bound, self.mid_low, zeros, np.full(self.jerk.shape[0], -np.inf)])
        self.row_high = np.concatenate([self.accel_bound, self.mid_bound, zeros, np.full(self.jerk.shape[0], np.inf)])
        self.solver, self.scale, self.jerk_programs, self.status = None, np.ones(2 * N), 0, ""

    def solve(self, previous, growth: float) -> tuple[np.ndarray, np.ndarray]:
        """(x, p) of the LP; without ``previous`` (x, p) the jerk is left out (a bang-bang profile
        with continuous s̈); with it, x grows by at most the factor ``growth`` (the trust region).

        HiGHS now and then stops short of the optimum on a program it has warm-started (status
        "Unknown": numerical trouble, never infeasibility: x = 0 meets every row); the program is
        then solved again from a fresh start, and only a second failure is an error (naming the
        rows in the program and what to change)."""
        N = self.num_nodes
        upper = self.velocity_bound.copy()
        if previous is not None:
            upper = np.minimum(upper, growth * previous[0])
        lower = np.concatenate([np.zeros(N), np.full(N, -np.inf)])
        high = np.concatenate([upper, np.full(N, np.inf)])
        lower[[N, 2 * N - 1]] = high[[N, 2 * N - 1]] = 0.0
        if previous is None:
            self._start(np.ones(2 * N))
        else:
            if not self.jerk_programs:
                # columns scaled to the first program's solution (x spans 1e-6 near the ends to 1
                # mid-path, beyond HiGHS's absolute tolerances)
                self._start(self._scale(*previous), None if self.solver is None else self.solver.getBasis())
            self.jerk_programs += 1
            ends = [1, 2, N - 3, N - 2]  # the nodes next to the ends weigh nothing in the sum but their time,
            lower[ends] = np.minimum(previous[0][ends] / growth, high[ends])  # 3 h / √x, is long: they fall by the trust region's factor at most
            self._set_jerk_rows(previous[0] * growth)
            self._set_time_weights(previous[0])
        z = self._run(lower, high)
        if z is None and previous is not None:  # from a fresh start, scaled to the last iterate
            self._start(self._scale(*previous))
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
        """The jerk rows' bounds: the jerk limit over √x frozen at the last iterate."""
        with np.errstate(divide="ignore"):
            bound = self.jerk_bound / np.tile(np.sqrt(np.maximum(x_previous[1:-1], 0.0)), 2 * self.num_joints)
        rows = np.arange(self.num_fixed_rows, self.matrix.shape[0], dtype=np.int32)
        self.solver.changeRowsBounds(len(rows), rows, -bound, bound)

    def jerk_ratio(self, x: np.ndarray, p: np.ndarray) -> float:
        """The largest |q⃛| over its limit at the nodes of the iterate (x, p), with its own √x."""
        rates = np.tile(np.sqrt(np.maximum(x[1:-1], 0.0)), 2 * self.num_joints)
        return float(np.max(np.abs(self.jerk @ np.concatenate([x, p])) * rates / self.jerk_limits))

    def _start(self, scale: np.ndarray, basis=None) -> None:
        """A HiGHS model of the programs with columns scaled by ``scale``, from ``basis`` (None:
        HiGHS's own start)."""
        matrix = self.matrix @ scipy.sparse.diags(scale)
        cost = np.concatenate([-self.weights, np.zeros(self.num_nodes)]) * scale
        lp = highspy.HighsLp()
        lp.num_col_, lp.num_row_ = len(cost), matrix.shape[0]
        lp.col_cost_, lp.col_lower_, lp.col_upper_ = cost, np.zeros(len(cost)), np.zeros(len(cost))
        lp.row_lower_, lp.row_upper_ = self.row_low, self.row_high
        lp.a_matrix_.format_ = highspy.MatrixFormat.kRowwise
        lp.a_matrix_.num_col_, lp.a_matrix_.num_row_ = matrix.shape[1], matrix.shape[0]
        lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = matrix.indptr, matrix.indices, matrix.data
        self.solver = _QuietHighs()
        self.solver.passModel(lp)
        if basis is not None:
            self.solver.setBasis(basis)
        self.scale, self.jerk_programs = scale, 0

    def _run(self, lower: np.ndarray, upper: np.ndarray) -> np.ndarray | None:
        """The solution (scaled columns) of the program with these column bounds, None if HiGHS
        does not find it optimal (``status`` says why)."""
        columns = np.arange(len(lower), dtype=np.int32)
        self.solver.changeColsBounds(len(columns), columns, lower / self.scale, upper / self.scale)
        self.solver.run()
        status = self.solver.getModelStatus()
        if status != highspy.HighsModelStatus.kOptimal:
            self.status = self.solver.modelStatusToString(status)
            return None
        return np.asarray(self.solver.getSolution().col_value)

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
    (after 4), or at a degenerate iterate or a failing program after the first (the best so far
    is kept). From a ``start``, an InfeasibleTimingError where no program succeeds."""
    x, p = best = program.solve(None, np.inf) if start is None else start
    best_time, growth, solved = np.inf, TRUST_REGION, 0
    while solved < iterations:
        try:
            x, p = program.solve((x, p), growth)
        except InfeasibleTimingError:
            if not solved:
                raise
            break
        solved += 1
        if not np.all(x[1:-1] > 0):  # a degenerate iterate: keep the best
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


def solve_on_grid(path, s: np.ndarray, limits, iterations: int, start=None):
    """(program, x, p, the programs with the jerk solved): the best solution of the sequential
    linear programs on the grid nodes ``s`` of ``path`` under ``limits`` (velocity, acceleration,
    jerk per joint [rad/s, rad/s², rad/s³]), from the bang-bang program or from ``start`` (x, p)
    (:func:`_iterate`); ``program`` holds the grid (``s``) and the path's derivatives
    (``derivatives``) that made it. An InfeasibleTimingError where the programs fail."""
    program = _Program(path, s, *limits)
    return (program, *_iterate(program, iterations, start=start))
