"""Time-optimal baseline: Drake's TOPP-RA along a fixed geometric joint-space path.

Given the joint path another planner followed (e.g. its logged ``q_ref``), this module answers
"how fast could that same geometric path be traversed under the same joint velocity and
acceleration limits?". The answer T* is the time-optimal path parameterisation (TOPP) computed by
Drake's :class:`pydrake.multibody.optimization.Toppra` (Pham & Pham 2018, reachability analysis),
starting and ending at rest.

Pipeline:

1. :func:`geometric_path_from_samples`: samples (N, n) -> a C^2 cubic spline q(s), s the
   cumulative joint-space arc length [rad] (so |dq/ds| ~= 1 and Toppra's path velocity s_dot is
   close to the joint-space speed).
2. :func:`time_optimal_along_path`: Toppra with per-joint velocity and acceleration limits ->
   (T*, q(t) = q(s(t))) as a :class:`PathParameterizedTrajectory`. Toppra keeps the limits at its
   grid points only, and not over its last grid interval; its trajectory exceeds them (up to
   1.0004 times the velocity limit and 1.053 times the acceleration limit on 100 seeded soak tasks
   on the UR10e, Drake's default grid; 1.2 times the acceleration limit on the bench's paths), most
   at the path's end.
3. :func:`within_limits`: the baseline planner's timing: Toppra's on its grid refined at the path's
   end (where Drake's Toppra exceeds the limits most: ``refine_end``), slowed uniformly in time by
   the least factor that keeps the limits at every instant (its exact peaks,
   :func:`exact_peak_fractions`). T* of step 2 on the grid as given stays the time-optimal
   reference (the bench's T_opt, converged in its grid).
4. :class:`ToppraLaw` / :class:`ToppraPlanner`: the result as a time law for
   :class:`drake_traj.planners.base.TimeLawPlanner`, so it runs in the same closed loop.

Why a C^2 cubic (``CubicWithContinuousSecondDerivatives``) and not ``CubicShapePreserving``:
the joint acceleration along the path is qdd = q'(s) s_ddot + q''(s) s_dot^2, so Toppra's
acceleration constraints involve q''(s). A shape-preserving (Fritsch-Carlson) cubic is only C^1:
q'' jumps at every knot, and Toppra, which evaluates q'' at discrete grid points, sees one side of
each jump only, so the sampled time law could exceed the limit on the other side. The C^2 spline
has continuous q''; its weakness (overshoot between unevenly spaced or noisy knots) is avoided by
decimating the samples to knots roughly evenly spaced in arc length, on a dense, smooth log.
"""

import contextlib
import logging
from dataclasses import dataclass, field

import numpy as np
from pydrake.multibody.optimization import CalcGridPointsOptions, Toppra, ToppraDiscretization
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import RevoluteJoint, SpatialInertia, UnitInertia
from pydrake.trajectories import PathParameterizedTrajectory, PiecewisePolynomial

from drake_traj.planners.base import TimeLawPlanner, joint_goals, joint_move_limits, start_and_goals
from drake_traj.robots import UR10E, Robot
from drake_traj.validation import invalid, positive_vector, real_array, whole_number

__all__ = ["ToppraConfig", "ToppraLaw", "ToppraPlanner", "exact_peak_fractions", "geometric_path_from_samples", "make",
           "time_optimal_along_path", "within_limits"]


# --------------------------------------------------------------------------------------------
# 1. Geometric path from samples.
# --------------------------------------------------------------------------------------------


def geometric_path_from_samples(
    q_samples, *, max_knots: int = 200, repeat_tolerance: float = 1e-9
) -> PiecewisePolynomial:
    """A smooth joint-space path q(s) through ``q_samples``, s the joint-space arc length [rad].

    Consecutive samples closer than ``repeat_tolerance`` [rad, Euclidean in joint space] to the
    last kept one are dropped (the planner standing still, before the start or while settling).
    The kept samples are parameterised by their cumulative arc length, decimated to at most
    ``max_knots`` knots evenly spaced in arc length (always keeping the first and the last), and
    interpolated by a not-a-knot C^2 cubic spline (see the module docstring for why C^2).
    Two distinct samples give the straight segment between them (first-order hold: q'' = 0).

    Args:
        q_samples: joint positions [rad], shape (N, n), in path order.
        max_knots: the largest number of spline knots (>= 3).
        repeat_tolerance: samples this close to the previous kept one are repeats [rad].

    Returns:
        PiecewisePolynomial of n rows, on s in [0, L], L the arc length of the kept polyline [rad].

    Raises:
        ValueError: wrong shape, non-finite values, or fewer than two distinct samples.
    """
    q = np.asarray(q_samples, dtype=float)
    if q.ndim != 2 or q.shape[1] == 0:
        raise ValueError(f"q_samples must have shape (N, n), got shape {q.shape}")
    if not np.all(np.isfinite(q)):
        raise ValueError("q_samples must be finite")
    if max_knots < 3:
        raise ValueError(f"max_knots must be >= 3, got {max_knots}")
    keep = [0]
    for k in range(1, len(q)):
        if np.linalg.norm(q[k] - q[keep[-1]]) > repeat_tolerance:
            keep.append(k)
    q = q[keep]
    if len(q) < 2:
        raise ValueError(
            f"q_samples must contain at least 2 distinct configurations (more than {repeat_tolerance} rad "
            f"apart) to define a path, got {len(q)} after dropping repeats"
        )
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(q, axis=0), axis=1))])
    if len(q) == 2:
        return PiecewisePolynomial.FirstOrderHold(arc, q.T)
    if len(q) > max_knots:
        # Knots: the samples nearest to evenly spaced arc lengths (kept on the true path).
        index = np.unique(np.searchsorted(arc, np.linspace(0.0, arc[-1], max_knots)))
        index = np.unique(np.concatenate([[0], np.minimum(index, len(q) - 1), [len(q) - 1]]))
        q, arc = q[index], arc[index]
    # Re-measure arc length on the kept knots so the breaks are strictly increasing.
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(q, axis=0), axis=1))])
    return PiecewisePolynomial.CubicWithContinuousSecondDerivatives(arc, q.T, periodic_end_condition=False)


# --------------------------------------------------------------------------------------------
# 2. Toppra.
# --------------------------------------------------------------------------------------------


def _joint_chain_plant(num_joints: int) -> MultibodyPlant:
    """A finalized plant of ``num_joints`` revolute joints (q = v), only to size Toppra's problem.

    Joint velocity and acceleration limits do not depend on the dynamics, so any plant with the
    right number of positions will do; this avoids parsing a URDF for every call.
    """
    plant = MultibodyPlant(0.0)
    parent = plant.world_body()
    inertia = SpatialInertia(1.0, np.zeros(3), UnitInertia(0.01, 0.01, 0.01))
    for j in range(num_joints):
        body = plant.AddRigidBody(f"link{j}", inertia)
        plant.AddJoint(RevoluteJoint(f"joint{j}", parent.body_frame(), body.body_frame(), [0.0, 0.0, 1.0]))
        parent = body
    plant.Finalize()
    return plant


@contextlib.contextmanager
def _drake_log():
    """Collect what Drake logs (pydrake's ``logging`` logger "drake", fed by its C++ spdlog) in
    the block into the yielded list of messages instead of printing it: Toppra reports why it
    failed there ("Toppra failed to find the maximum path acceleration at knot 324/362"), and
    :func:`time_optimal_along_path` puts that into its ValueError."""
    logger = logging.getLogger("drake")
    said = []
    handler = logging.Handler(logging.WARNING)
    handler.emit = lambda record: said.append(record.getMessage())
    propagate = logger.propagate
    logger.addHandler(handler)
    logger.propagate = False
    try:
        yield said
    finally:
        logger.removeHandler(handler)
        logger.propagate = propagate


# time_optimal_along_path's refine_end: extra grid points this far before the path's end, as
# fractions of the last grid interval (one point at 1e-6 of it made Toppra fail on 4 of 5 paths tried)
END_REFINEMENT = np.array([1e-1, 1e-2, 1e-3])


def _grid(path, grid_points, refine_end: bool) -> np.ndarray:
    """Toppra's grid [path parameter s] for :func:`time_optimal_along_path`'s ``grid_points`` and
    ``refine_end`` (see there); ValueError for a bad ``grid_points``."""
    s0, s1 = path.start_time(), path.end_time()
    if grid_points is None:
        options = CalcGridPointsOptions(max_err=1e-4, max_iter=100, max_seg_length=(s1 - s0) / 200, min_points=200)
        grid = np.asarray(Toppra.CalcGridPoints(path, options), dtype=float).ravel()
    elif np.ndim(grid_points) == 0:
        # two points (the path's ends) leave Toppra no interval to move in: an infinite duration
        grid = np.linspace(s0, s1, whole_number(grid_points, "grid_points", minimum=3))
    else:
        grid = real_array(grid_points, "grid_points", "path parameter s").ravel()
        if len(grid) < 3 or np.any(np.diff(grid) <= 0) or not np.isclose(grid[0], s0) or not np.isclose(grid[-1], s1):
            raise ValueError(
                f"grid_points must be at least 3 points increasing strictly from the path start {s0} to its end {s1}, "
                f"got {len(grid)} points from {grid[0] if len(grid) else None} to {grid[-1] if len(grid) else None}"
            )
        grid[0], grid[-1] = s0, s1
    if refine_end:
        grid = np.concatenate([grid[:-1], grid[-1] - END_REFINEMENT * (grid[-1] - grid[-2]), grid[-1:]])
    return grid


def time_optimal_along_path(
    path,
    velocity_limit,
    acceleration_limit,
    plant: MultibodyPlant | None = None,
    grid_points=None,
    *,
    discretization: ToppraDiscretization = ToppraDiscretization.kInterpolation,
    refine_end: bool = False,
) -> tuple[float, PathParameterizedTrajectory]:
    """Time-optimal traversal of ``path`` from rest to rest under joint limits (Drake's Toppra).

    Constraints |qd_j| <= velocity_limit_j and |qdd_j| <= acceleration_limit_j hold at Toppra's
    grid points (``kInterpolation`` by default: the acceleration constraint of each grid interval
    is also imposed at its far end, the more conservative of Drake's two schemes); between grid
    points they hold approximately (see the module docstring for the measured worst ratio, and
    :func:`within_limits` for a timing that keeps them everywhere).

    Args:
        path: joint path q(s) (any Drake Trajectory of n rows, e.g. from
            :func:`geometric_path_from_samples`).
        velocity_limit, acceleration_limit: per joint [rad/s, rad/s^2], > 0 (scalar or (n,)).
        plant: a finalized MultibodyPlant with n positions (q = v); default a plain n-joint chain.
        grid_points: None (Drake's ``CalcGridPoints`` with max_err 1e-4, at least 200 points and
            segments <= L / 200), an int >= 3 (that many points evenly spaced in s) or an increasing
            array from path.start_time() to path.end_time().
        discretization: Toppra's constraint discretisation.
        refine_end: add grid points :data:`END_REFINEMENT` of the last grid interval before the
            path's end. Drake's Toppra does not keep the acceleration limit over its last grid
            interval: the path's end is where its trajectory exceeds the limit most (measured: by up
            to 20 % on the bench's paths and 5 % on seeded soak tasks, on grids of 2000 points and
            Drake's default alike: a finer grid does not shrink it), and a short last interval
            shrinks the excess with it (on 100 soak tasks what was left over needed a stretch of
            0.04 % at most, :func:`within_limits`; T* grew by 0.07 % in the median).

    Returns:
        (T* [s], trajectory): the optimal duration and q(t) = path(s(t)) on t in [0, T*]
        (rows n, with derivatives via ``EvalDerivative`` / ``MakeDerivative``).

    Raises:
        ValueError: bad limits or grid, a plant of the wrong size, or Toppra finding no
            parameterisation (the message says why that can happen).
    """
    n = path.rows()
    kv = positive_vector(velocity_limit, "velocity_limit", n)
    ka = positive_vector(acceleration_limit, "acceleration_limit", n)
    s0, s1 = path.start_time(), path.end_time()
    if not s1 > s0:
        raise invalid("path", f"path must have a positive length in s, got [{s0}, {s1}]")
    if plant is None:
        plant = _joint_chain_plant(n)
    elif plant.num_positions() != n or plant.num_velocities() != n:
        raise ValueError(
            f"plant must have {n} positions and velocities to match the path, got "
            f"{plant.num_positions()} and {plant.num_velocities()}"
        )
    grid = _grid(path, grid_points, refine_end)
    toppra = Toppra(path, plant, grid)
    toppra.AddJointVelocityLimit(-kv, kv)
    toppra.AddJointAccelerationLimit(-ka, ka, discretization)
    with _drake_log() as said:
        s_of_t = toppra.SolvePathParameterization()
    if s_of_t is None:
        raise ValueError(
            f"Toppra found no feasible time parameterisation of the path ({'; '.join(said) or 'no reason given'}). "
            "The reachability analysis failed: usually the path's curvature q''(s) is so large somewhere that no "
            "path speed keeps every joint acceleration within its limit while starting and stopping at rest, "
            "e.g. a kink left by noisy or badly decimated samples; try a smoother path or more grid points"
        )
    duration = float(s_of_t.end_time() - s_of_t.start_time())
    if not np.isfinite(duration) or duration <= 0.0:
        raise ValueError(f"Toppra returned an invalid duration {duration} s")
    return duration, PathParameterizedTrajectory(path, s_of_t)


# --------------------------------------------------------------------------------------------
# 3. Within the limits at every instant.
# --------------------------------------------------------------------------------------------


ROUND_OFF = 1e-9  # relative: peaks this little over a limit are round-off, left unstretched


def exact_peak_fractions(trajectory: PathParameterizedTrajectory, velocity_limit, acceleration_limit):
    """(max over t and j of |qd_j| / velocity_limit_j, the same of |qdd_j| / acceleration_limit_j),
    exact to round-off, of a trajectory of :func:`time_optimal_along_path`.

    Toppra's s(t) is piecewise quadratic in t (s_ddot = u constant between grid points), so on each
    grid interval x = s_dot^2 is linear in s; and the path is a cubic spline, so between its knots
    qdd_j = q_j'(s) u + q_j''(s) x(s) is a quadratic in s. On every grid interval split at the
    path's knots: |qdd_j| peaks at the ends or at the quadratic's vertex, and |qd_j| = |q_j'(s)|
    sqrt(x(s)) at the ends or where qdd_j = 0 (the quadratic's roots). Each quadratic is fitted to
    three interior points of its interval, so a path whose q'' jumps at its knots is exact too.

    Args:
        trajectory: q(t) = path(s(t)), its path a PiecewisePolynomial of pieces of degree <= 3 and
            its time scaling a PiecewisePolynomial of degree <= 2 (as Toppra returns it).
        velocity_limit, acceleration_limit: per joint [rad/s, rad/s^2], > 0 (scalar or (n,)).

    Raises:
        ValueError: bad limits, or a trajectory not of that kind.
    """
    path, s_of_t = trajectory.path(), trajectory.time_scaling()
    n = path.rows()
    kv = positive_vector(velocity_limit, "velocity_limit", n)
    ka = positive_vector(acceleration_limit, "acceleration_limit", n)
    for name, curve, degree in (("path", path, 3), ("time scaling", s_of_t, 2)):
        if not isinstance(curve, PiecewisePolynomial) or max(
                curve.getSegmentPolynomialDegree(k) for k in range(curve.get_number_of_segments())) > degree:
            raise invalid("trajectory", f"trajectory's {name} must be a PiecewisePolynomial of degree <= {degree}")
    times = np.asarray(s_of_t.get_segment_times())
    grid = s_of_t.vector_values(times).ravel()  # s at Toppra's grid points, increasing
    s_dot = s_of_t.MakeDerivative(1).vector_values(times[:-1]).ravel()
    s_ddot = s_of_t.MakeDerivative(2).vector_values((times[:-1] + times[1:]) / 2).ravel()
    knots = np.asarray(path.get_segment_times())
    edges = np.union1d(grid, knots[(knots > grid[0]) & (knots < grid[-1])])
    start, width = edges[:-1], np.diff(edges)
    interval = np.clip(np.searchsorted(grid, start + width / 2) - 1, 0, len(s_dot) - 1)

    def squared_speed(s, k):  # x = s_dot^2 at path parameter s in grid interval k
        return np.maximum(s_dot[k] ** 2 + 2.0 * s_ddot[k] * (s - grid[k]), 0.0)

    # qdd_j at the interval's quarter points (z = -1/4, 0, 1/4 of z = (s - mid) / width): (n, M, 3)
    points = (start + width / 2)[:, None] + width[:, None] * np.array([-0.25, 0.0, 0.25])
    u = s_ddot[interval][:, None]
    slope = path.MakeDerivative(1).vector_values(points.ravel()).reshape(n, *points.shape)
    bend = path.MakeDerivative(2).vector_values(points.ravel()).reshape(n, *points.shape)
    qdd = slope * u + bend * squared_speed(points, interval[:, None])
    # qdd_j(z) = c + b z + a z^2 on z in [-1/2, 1/2]
    c, b, a = qdd[..., 1], 2.0 * (qdd[..., 2] - qdd[..., 0]), 8.0 * (qdd[..., 0] - 2.0 * qdd[..., 1] + qdd[..., 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = np.nan_to_num(-b / (2.0 * a))
        root = np.sqrt(b * b - 4.0 * a * c)
        big = -(b + np.copysign(root, b)) / 2.0  # the roots big / a and c / big, stably
        roots = np.nan_to_num(np.stack([big / a, c / big]))
    # points outside the interval or not roots (NaN) are moved into it: extra samples, no harm
    vertex, roots = np.clip(vertex, -0.5, 0.5), np.clip(roots, -0.5, 0.5)
    acceleration = np.max(np.abs(np.stack([c - b / 2 + a / 4, c + b / 2 + a / 4, c + b * vertex + a * vertex**2])),
                          axis=(0, 2))
    # qd_j at the edges (every joint) and at qdd_j's roots (joint j only)
    speed_at_edges = np.abs(path.MakeDerivative(1).vector_values(edges)) * np.sqrt(
        squared_speed(edges, np.minimum(np.searchsorted(grid, edges, side="right") - 1, len(s_dot) - 1)))
    at_roots = (start + width / 2) + width * roots  # (2, n, M)
    slope_at_roots = path.MakeDerivative(1).vector_values(at_roots.ravel()).reshape(n, *at_roots.shape)
    speed_at_roots = np.abs(np.stack([slope_at_roots[j, :, j] for j in range(n)], axis=1)) * np.sqrt(
        squared_speed(at_roots, interval))
    velocity = np.maximum(speed_at_edges.max(axis=1), speed_at_roots.max(axis=(0, 2)))
    return float(np.max(velocity / kv)), float(np.max(acceleration / ka))


def within_limits(trajectory: PathParameterizedTrajectory, velocity_limit, acceleration_limit):
    """(stretch, trajectory): Toppra's ``trajectory`` slowed uniformly in time by the least factor
    ``stretch`` >= 1 that keeps |qd_j| <= velocity_limit_j and |qdd_j| <= acceleration_limit_j at
    every instant, not only at Toppra's grid points: q(t / stretch), its velocity divided by
    stretch and its acceleration by stretch^2, so stretch = max(peak velocity fraction,
    sqrt(peak acceleration fraction)) (:func:`exact_peak_fractions`). Where that is within
    :data:`ROUND_OFF` of 1 (a straight path: there Toppra keeps the limits between its grid points
    too) the stretch is 1 and ``trajectory`` itself is returned.

    Why a uniform stretch: the timing stays Toppra's, its duration ``stretch`` times Toppra's T*,
    for one solve and one exact measure of its peaks (a few ms); tightening the limits given to
    Toppra until its trajectory keeps the true ones costs a solve per try.
    """
    velocity, acceleration = exact_peak_fractions(trajectory, velocity_limit, acceleration_limit)
    stretch = max(velocity, float(np.sqrt(acceleration)))
    if stretch <= 1.0 + ROUND_OFF:
        return 1.0, trajectory
    s_of_t = trajectory.time_scaling().Clone()
    s_of_t.ScaleTime(stretch)
    return stretch, PathParameterizedTrajectory(trajectory.path(), s_of_t)


# --------------------------------------------------------------------------------------------
# 4. Time law and planner.
# --------------------------------------------------------------------------------------------


class ToppraLaw:
    """A Toppra trajectory as a time law for :class:`TimeLawPlanner` (law time tau in [0, T* + h]).

    The trajectory's joint velocity is sampled once into a table V at t_k = k h (h =
    ``sample_period``; V = 0 at t = 0 and from the first node at or after T* on: rest to rest),
    and the law is that table, linearly interpolated, averaged over the last period::

        qd(tau) = (1/h) integral of V over [tau - h, tau],    qdd(tau) = (V(tau) - V(tau - h)) / h.

    Why the average: Toppra's s_ddot is piecewise constant, so the trajectory's qdd jumps at each
    of its grid points (by 1e-3 to 2.7 rad/s^2 on the paper task's path). The simulator's
    error-controlled integrator shrinks its step around every jump: replaying the trajectory's
    qdd as a step function cost 57 000 derivative evaluations per simulated second (real-time
    factor 0.4, against 4 500 for the smooth planners). The averaged law's qdd is continuous and
    linear between nodes; with h the closed loop's 1 ms step (the default) the nodes fall on the
    integrator's step boundaries, so every step integrates a polynomial exactly (4 700
    evaluations per simulated second). What it costs: the law is the trajectory delayed by h/2
    and smoothed over h. It lasts T* + h to T* + 2 h (T* rounded up to a node, plus h); its
    |qd| and |qdd| never exceed the table's (an average does not overshoot), a step of Toppra's
    qdd becomes a ramp over h, and q ends within O(h^2) of the path's end. ``rates_at`` is the
    simulator's hot path: a table look-up, no pybind round trip. Outside [0, duration] the law
    rests (zero rates).

    Args:
        trajectory: q(t) on [t0, t0 + T*] (e.g. from :func:`time_optimal_along_path`), starting
            and ending at rest.
        sample_period: h, the table's spacing [s]; keep it the closed loop's plant step.
    """

    # the average's q̈ is continuous (linear between nodes): no law time where it jumps
    acceleration_jumps = np.empty(0)

    def __init__(self, trajectory, *, sample_period: float = 1e-3):
        if not sample_period > 0:
            raise ValueError(f"sample_period must be > 0 s, got {sample_period}")
        self.trajectory = trajectory
        t0 = float(trajectory.start_time())
        optimal = float(trajectory.end_time()) - t0
        if not optimal > 0:
            raise ValueError(f"trajectory must have a positive duration, got {optimal} s")
        self.q_start = np.asarray(trajectory.value(t0), dtype=float).ravel()
        self.q_end = np.asarray(trajectory.value(t0 + optimal), dtype=float).ravel()
        self.num_joints = len(self.q_start)
        self.sample_period = h = float(sample_period)
        last = max(1, int(np.ceil(optimal / h - 1e-9)))  # the first node at or after T*
        self.duration = (last + 1) * h
        velocity = np.zeros((last + 1, self.num_joints))
        velocity[1:last] = [trajectory.EvalDerivative(t0 + k * h, 1).ravel() for k in range(1, last)]
        step = np.diff(velocity, axis=0)
        # Q (displacement) = integral of V, R (swept) = integral of Q, at the nodes (V linear per cell).
        displacement = np.zeros_like(velocity)
        displacement[1:] = np.cumsum(h * (velocity[:-1] + step / 2), axis=0)
        swept = np.zeros_like(velocity)
        swept[1:] = np.cumsum(h * (displacement[:-1] + h * (velocity[:-1] / 2 + step / 6)), axis=0)
        # the velocity's step over each cell, and 0 past the last node (at rest)
        self._velocity, self._step = velocity, np.append(step, np.zeros((1, self.num_joints)), axis=0)
        self._displacement, self._swept = displacement, swept
        # the table's nodes [s]: q is one cubic between them (tau and tau - h cross nodes together)
        self.polynomial_breaks = np.arange(last + 2) * h
        self._zero = np.zeros(self.num_joints)

    def _table(self, u):
        """(V, Q, R) at table time ``u`` [s], a float (the simulator's hot path, no array
        arithmetic) or an array (each u.shape + (n,)): V interpolated, Q and R its first and
        second integrals; zero before 0, at rest from the last node on."""
        h, last = self.sample_period, len(self._step) - 1
        if np.ndim(u) == 0:
            if u <= 0.0:
                return self._zero, self._zero, self._zero
            k = min(int(u / h), last)
            return self._cell(k, u / h - k)
        u = np.asarray(u, dtype=float)
        x = np.maximum(u / h, 0.0)
        k = np.minimum(x.astype(int), last)
        before = (u <= 0.0)[..., None]
        return tuple(np.where(before, 0.0, value) for value in self._cell(k, (x - k)[..., None]))

    def _cell(self, k, w):
        """(V, Q, R) a fraction ``w`` of the sample period into table cell ``k`` (an int and a
        float, or arrays k (...) and w (..., 1)); from the last node on (k = last: V and its step
        zero) the law rests, Q constant and R growing by Q h w."""
        h = self.sample_period
        v, dv, q = self._velocity[k], self._step[k], self._displacement[k]
        return (v + w * dv, q + h * (w * v + w * w / 2 * dv),
                self._swept[k] + h * (w * q + h * (w * w / 2 * v + w**3 / 6 * dv)))

    def rates_at(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """(qd [rad/s], qdd [rad/s^2]) of the law at law time ``tau`` [s] (rest outside)."""
        if not 0.0 <= tau <= self.duration:
            return self._zero.copy(), self._zero.copy()
        return self.rates_along(tau)

    def rates_along(self, taus) -> tuple[np.ndarray, np.ndarray]:
        """(qd [rad/s], qdd [rad/s^2]) at law times ``taus`` [s] in [0, duration], a float or an
        array (each taus.shape + (n,)): :meth:`rates_at` at many times in one call."""
        h = self.sample_period
        taus = taus if np.ndim(taus) == 0 else np.asarray(taus, dtype=float)
        v1, q1, _ = self._table(taus)
        v0, q0, _ = self._table(taus - h)
        return (q1 - q0) / h, (v1 - v0) / h

    def sample(self, t):
        """(q, qd, qdd) of the law at law times ``t`` [s] (clipped to [0, duration]): what the
        planner integrates. The trajectory itself is ``trajectory`` (at t - h/2, approximately).

        Returns arrays of shape t.shape + (n,).
        """
        t_arr = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        h = self.sample_period
        v1, q1, r1 = self._table(t_arr)
        v0, q0, r0 = self._table(t_arr - h)
        return self.q_start + (r1 - r0) / h, (q1 - q0) / h, (v1 - v0) / h


class ToppraPlanner(TimeLawPlanner):
    """Planner system replaying a :class:`ToppraLaw` (the time-optimal baseline) in the closed loop.

    Args:
        law: the Toppra law.
        velocity_limit, acceleration_limit: the limits Toppra was given [rad/s, rad/s^2].
        time_stretch: how many times Toppra's T* the law's trajectory lasts (:func:`within_limits`:
            1 where Toppra kept the limits between its grid points too), kept as ``time_stretch``.
        speed_cap, update_period: as :class:`TimeLawPlanner`.
    """

    def __init__(self, law: ToppraLaw, velocity_limit, acceleration_limit, *, time_stretch: float = 1.0,
                 speed_cap: float = 1.0, update_period: float = 0.001):
        if not time_stretch >= 1.0:
            raise invalid("time_stretch",
                          f"time_stretch must be >= 1 (a uniform slow-down of Toppra's timing), got {time_stretch}")
        self.time_stretch = float(time_stretch)
        n = law.num_joints
        super().__init__(
            law,
            positive_vector(velocity_limit, "velocity_limit", n),
            positive_vector(acceleration_limit, "acceleration_limit", n),
            speed_cap=speed_cap,
            update_period=update_period,
        )


@dataclass
class ToppraConfig:
    """The time-optimal baseline along a joint path (Drake's Toppra): the scenario's
    ``planner: !ToppraConfig`` entry.

    Attributes:
        path: joint samples after the start [rad], one row of n per sample, dense enough to
            define the path (:func:`geometric_path_from_samples` smooths and decimates them).
        velocity_limit, acceleration_limit: per joint; empty: the robot's joint-move limits.
        grid_points: Toppra grid points evenly spaced in arc length, at least 3; 0: Drake's
            CalcGridPoints.
    """

    path: list[list[float]] = field(default_factory=list)
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)
    grid_points: int = 0

    def validate(self, robot: Robot = UR10E) -> "ToppraConfig":
        """The config, its own fields checked for ``robot`` as :func:`make` checks them first: the
        limits (the robot's where empty), then the path's rows of n joint positions [rad] (named
        ``goals`` in the message, as the start and goals of every joint task); ValueError naming
        the field (``grid_points`` is checked with the path)."""
        joint_move_limits(robot, self.velocity_limit, self.acceleration_limit)
        joint_goals(self.path, robot.num_joints)
        return self


def _grid_points(value):
    """The config's ``grid_points`` for :func:`time_optimal_along_path`: 0 is None (Drake's
    CalcGridPoints); anything else is checked there."""
    return None if not isinstance(value, bool) and isinstance(value, (int, float)) and value == 0 else value


def make(config: ToppraConfig, robot: Robot, q_initial) -> ToppraPlanner:
    """The baseline of ``config`` on ``robot``: time-optimal along the path from ``q_initial`` (the
    config checked first: :meth:`ToppraConfig.validate`), within its limits at every instant:
    Toppra on the config's grid refined at the path's end (``refine_end`` of
    :func:`time_optimal_along_path`; the grid alone where Toppra finds no parameterisation on the
    refined one), its timing stretched where it still exceeds them between grid points
    (:func:`within_limits`; the planner's ``time_stretch``)."""
    config.validate(robot)
    velocity, acceleration = joint_move_limits(robot, config.velocity_limit, config.acceleration_limit)
    path = geometric_path_from_samples(start_and_goals(q_initial, config.path, robot.num_joints))
    grid = _grid_points(config.grid_points)
    try:
        _, trajectory = time_optimal_along_path(path, velocity, acceleration, grid_points=grid, refine_end=True)
    except ValueError:  # where Toppra fails on the refined grid (not seen on 100 soak tasks), its own
        _, trajectory = time_optimal_along_path(path, velocity, acceleration, grid_points=grid)
    stretch, trajectory = within_limits(trajectory, velocity, acceleration)
    return ToppraPlanner(ToppraLaw(trajectory), velocity, acceleration, time_stretch=stretch)
