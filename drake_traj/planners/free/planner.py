"""Free motion: from goals to a motion that avoids the cell (:class:`FreeMotionConfig`).

For each goal in turn: OMPL finds a collision-free joint path from the previous one
(:func:`~.search.search`), our shortcutting shortens it (:func:`~.search.shortcut`), the
centripetal C2 spline through its vertices (more points along its segments where the spline
strays into the cell, so the spline hugs the checked segments) is checked with the cell check's
guarantee, then timed jerk-limited and near time-optimal by
:func:`~drake_traj.planners.smooth.timing.time_path`; the arm stops at each goal. The timed
motion is what the planner runs, and it is checked in the cell like every plan before anything
moves. The search needs the cell: the planner is made without it and plans when it is given one
(:meth:`FreeMotionPlanner.plan_in`, which the preflight and the station's check call).
"""


import time
from dataclasses import dataclass, field, replace

import numpy as np

from drake_traj.errors import Cause, DrakeTrajError, PlanningError, joint_label
from drake_traj.planners.base import TimeLawPlanner
from drake_traj.planners.baselines.ruckig import jerk_limited_limits
from drake_traj.planners.free.search import PLANNERS, Scene, search, shortcut
from drake_traj.planners.laws.hermite import HermiteLaw
from drake_traj.planners.smooth.planners import waypoint_path
from drake_traj.planners.smooth.timing import time_path
from drake_traj.robots import Robot
from drake_traj.validation import finite_array, invalid, positive_scalar, whole_number

__all__ = ["FreeMotionConfig", "FreeMotionPlanner", "make"]

MAX_GOALS = 100  # goals (or poses) of one task at most
MAX_PLANNING_TIME = 120.0  # [s] the longest search budget
DENSITIES = (None, 0.3, 0.1, 0.03)
"""[rad] the spline's repair: its points along the found segments at most this far apart (None:
the vertices only), tried in turn until the spline keeps the clearance."""


@dataclass
class FreeMotionConfig:
    """Goals reached through the cell on a path found for them: the scenario's
    ``planner: !FreeMotionConfig`` entry.

    Attributes:
        goals: joint configurations [rad] reached in order, one row of n each; the arm stops at each.
        poses: TCP poses [x, y, z, φ_X, φ_Y, φ_Z] [m, rad] instead of goals (Z-Y-X Euler angles as
            Pająk's waypoints): each reached by the inverse-kinematics solution nearest the
            previous configuration that is inside the joint ranges, clear of the cell and reached
            by a path.
        velocity_limit, acceleration_limit, jerk_limit: per joint (or one value); empty: the
            robot's joint-move limits, and 10 /s × the acceleration limit.
        planning_time: the search's budget per goal [s].
        seed: the random numbers' seed: the same seed finds the same path.
        planner: the OMPL planner, one of :data:`~.search.PLANNERS` (``rrt_connect``: the first
            path found, then shortened).
        shortcut_rounds: random shortcuts tried on each found path.
        grid_points: nodes of the timing's linear programs.
    """

    goals: list[list[float]] = field(default_factory=list)
    poses: list[list[float]] = field(default_factory=list)
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)
    jerk_limit: list[float] = field(default_factory=list)
    planning_time: float = 5.0
    seed: int = 0
    planner: str = "rrt_connect"
    shortcut_rounds: int = 60
    grid_points: int = 200

    def validate(self, num_joints: int = 6) -> None:
        """ValueError naming the field for a malformed config (the geometry is the planner's)."""
        if bool(len(self.goals)) == bool(len(self.poses)):
            raise invalid("goals", "give either goals (joint configurations) or poses (TCP poses), one of the two")
        name, width = ("goals", num_joints) if len(self.goals) else ("poses", 6)
        rows = finite_array(getattr(self, name), name, "rad" if name == "goals" else "m and rad")
        if rows.ndim != 2 or rows.shape[1] != width:
            raise invalid(name, f"{name} must be rows of {width} values, got shape {rows.shape}")
        if len(rows) > MAX_GOALS:
            raise invalid(name, f"{name} has {len(rows)} rows, at most {MAX_GOALS}")
        budget = positive_scalar(self.planning_time, "planning_time", "s")
        if budget > MAX_PLANNING_TIME:
            raise invalid("planning_time", f"planning_time = {budget:g} s is above {MAX_PLANNING_TIME:g} s")
        if self.planner not in PLANNERS:
            raise invalid("planner", f"planner must be one of {sorted(PLANNERS)}, got {self.planner!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or not 0 <= self.seed < 2**31:
            raise invalid("seed", f"seed must be a whole number in [0, 2^31), got {self.seed!r}")
        whole_number(self.shortcut_rounds, "shortcut_rounds", minimum=0)
        whole_number(self.grid_points, "grid_points", minimum=20)


class FreeMotionLaw:
    """The found and timed motion as a time law (:class:`~drake_traj.planners.laws.TimeLaw`):
    each leg's :class:`~drake_traj.planners.smooth.timing.SmoothTiming` in turn, at rest between
    them, as one :class:`HermiteLaw` on their knots. Until the planner has planned
    (:meth:`FreeMotionPlanner.plan_in`), asking for it raises a :class:`PlanningError`."""

    acceleration_jumps = np.zeros(0)  # the legs meet at rest, each leg C2

    def __init__(self, q_start: np.ndarray):
        self.q_start = q_start
        self._law = None

    def set_legs(self, timings) -> None:
        """The motion of the timed legs (each a SmoothTiming from the previous leg's end)."""
        knots, samples, offset = [], [], 0.0
        for k, timing in enumerate(timings):
            own = np.asarray(timing.law.knots)
            own = own if k == 0 else own[1:]  # a leg's first knot is the previous leg's last
            knots.append(own + offset)
            samples.append(np.array([np.stack(timing.law.sample(t)) for t in own]))
            offset += timing.duration
        samples = np.concatenate(samples)
        law = HermiteLaw(np.concatenate(knots), samples, samples)
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


class FreeMotionPlanner(TimeLawPlanner):
    """:class:`FreeMotionConfig`'s planner (module docstring): a time law made when the planner is
    given its cell (:meth:`plan_in`).

    Args:
        config: the task.
        robot: the robot (its joint ranges; poses by its task kinematics' IK).
        q_initial: joint positions at t = 0 [rad].
    """

    target_word = "goal"
    needs_cell = True  # the preflight and the station's check call plan_in(checker) first

    def __init__(self, config: FreeMotionConfig, robot: Robot, q_initial):
        config.validate(robot.num_joints)
        self.config = config
        self.robot = robot
        self.velocity, self.acceleration, self.jerk = jerk_limited_limits(
            robot, config.velocity_limit, config.acceleration_limit, config.jerk_limit)
        q_initial = finite_array(q_initial, "q_initial", "rad", shape=(robot.num_joints,))
        super().__init__(FreeMotionLaw(q_initial), self.velocity, self.acceleration)
        self.legs: list[Leg] = []
        self.planning_time_s = float("nan")  # [s] find + shorten + smooth + time + check, once planned
        self._planned_in = None  # (fingerprint of the cell it planned in, its MotionCheck)

    # --- planning ---------------------------------------------------------------------------
    def plan_in(self, checker):
        """Find, shorten, smooth, time and check the motion in ``checker``'s cell (a
        :class:`~drake_traj.clearance.CellChecker`; what its ``check_planner`` calls for this
        planner); nothing to do where it planned there already. Returns the cell check's
        :class:`~drake_traj.clearance.MotionCheck` of the timed motion.

        Raises:
            CollisionError: the start or a goal too close to something (naming the bodies).
            DrakeTrajError: a goal outside the joint ranges, a pose out of reach (at its field).
            PlanningError: no path within the budget (what was tried), or none that could be
                smoothed clear of the cell.
        """
        if self._planned_in is not None and self._planned_in[0] == checker.fingerprint:
            return self._planned_in[1]
        began = time.perf_counter()
        scene = Scene(checker, self.robot.lower_limits, self.robot.upper_limits)
        rng = np.random.default_rng(self.config.seed)
        checker.check_configuration(self.initial_positions())
        legs, current = [], self.initial_positions()
        for k, candidates in enumerate(self._goal_candidates(checker)):
            leg, current = self._leg(scene, checker, rng, k, current, candidates)
            legs.append(leg)
        self.law.set_legs([leg.timing for leg in legs])
        self._plan = None  # plan() is made again from the new law
        # the plan is the checked legs one after the other (the same quintic pieces): their checks joined
        offsets = np.concatenate([[0.0], np.cumsum([leg.timing.duration for leg in legs])[:-1]])
        accepted = replace(legs[0].check, times=np.concatenate([leg.check.times + offset
                                                                 for leg, offset in zip(legs, offsets)]),
                           spacing=max(leg.check.spacing for leg in legs))
        self.checked_scenes.add(checker.fingerprint)  # the timed motion checked as every plan is
        self.legs = legs
        self._planned_in = (checker.fingerprint, accepted)
        self.planning_time_s = time.perf_counter() - began
        return accepted

    def _goal_candidates(self, checker):
        """Per goal, the configurations [rad] that may reach it, preferred first: a joint goal
        itself (checked: inside the ranges, clear of the cell); a pose's IK solutions."""
        if len(self.config.goals):
            for k, goal in enumerate(np.asarray(self.config.goals, dtype=float)):
                self._check_range(goal, ("goals", k))
                checker.check_configuration(goal, what=f"goal {k}", field=("goals", k))
                yield [goal]
            return
        kinematics = self.robot.task_kinematics()
        for k, pose in enumerate(np.asarray(self.config.poses, dtype=float)):
            try:
                solutions = np.atleast_2d(kinematics.inverse_kinematics_all(pose))
            except ValueError as error:
                raise DrakeTrajError(f"poses[{k}] cannot be reached: {error}", field=("poses", k),
                                     cause=Cause.UNREACHABLE) from None
            yield solutions

    def _check_range(self, q, field_: tuple) -> None:
        low, high = self.robot.lower_limits, self.robot.upper_limits
        outside = np.flatnonzero((q < low) | (q > high))
        if len(outside):
            j = int(outside[0])
            raise DrakeTrajError(f"{field_[0]}[{field_[1]}]: {joint_label(j, self.robot.joint_names)} = {q[j]:.4g} rad "
                                 f"is outside its range [{low[j]:.4g}, {high[j]:.4g}] rad", field=field_,
                                 cause=Cause.JOINT_RANGE)

    def _pose_goals(self, scene: Scene, solutions, previous) -> list[np.ndarray]:
        """A pose's IK solutions, each moved by whole turns towards ``previous`` within the ranges,
        those inside the ranges and clear of the cell, nearest ``previous`` first."""
        goals = []
        for q in solutions:
            turns = np.round((previous - q) / (2 * np.pi))
            shifted = q + 2 * np.pi * turns
            shifted = np.where((shifted < scene.lower) | (shifted > scene.upper), q, shifted)
            if scene.valid(shifted):
                goals.append(shifted)
        return sorted(goals, key=lambda q: float(np.linalg.norm(q - previous)))

    def _leg(self, scene: Scene, checker, rng, k: int, start, candidates) -> "tuple[Leg, np.ndarray]":
        """The timed leg from ``start`` to the first of ``candidates`` a path reaches."""
        word, field_ = ("goal", ("goals", k)) if len(self.config.goals) else ("pose", ("poses", k))
        goals = candidates if len(self.config.goals) else self._pose_goals(scene, candidates, start)
        if not goals:
            raise PlanningError(f"{word} {k}: none of its {len(candidates)} inverse-kinematics solutions is inside the "
                                "joint ranges and clear of the cell", field=field_, cause=Cause.COLLISION)
        tried = []
        for goal in goals:
            budget = self.config.planning_time / len(goals)
            found = search(scene, start, goal, planning_time=budget, seed=int(rng.integers(2**31 - 1)),
                           planner=self.config.planner)
            tried.append(found)
            if found.vertices is None:
                continue
            vertices = shortcut(scene, found.vertices, rng, rounds=self.config.shortcut_rounds)
            for density in DENSITIES:
                timed = self._smooth_and_time(checker, vertices, density)
                if timed is not None:
                    return Leg(found.vertices, vertices, *timed, density, found.seconds, found.samples), goal
            raise PlanningError(f"{word} {k}: a path was found ({len(vertices)} vertices) but no smooth motion along it "
                                f"kept the clearance (points along it down to {DENSITIES[-1]} rad apart)",
                                field=field_, cause=Cause.PLANNING)
        samples = sum(result.samples for result in tried)
        statuses = "; ".join(sorted({result.status for result in tried}))
        raise PlanningError(f"no collision-free path to {word} {k} found within planning_time = "
                            f"{self.config.planning_time:g} s ({PLANNERS[self.config.planner]}, {len(tried)} "
                            f"configuration{'s' * (len(tried) > 1)} tried, {samples} states sampled: {statuses}); raise "
                            f"planning_time, or move the {word} away from the obstacles", field=field_, cause=Cause.PLANNING)

    def _smooth_and_time(self, checker, vertices, density):
        """(the timed spline through ``vertices`` (points ``density`` [rad] apart along the
        segments), its cell check's MotionCheck), or None where the spline leaves the ranges or
        the timed motion comes closer than the clearance."""
        path = waypoint_path(_densified(vertices, density))
        q = path.vector_values(np.linspace(path.start_time(), path.end_time(), 2001)).T
        if np.any(q < self.robot.lower_limits) or np.any(q > self.robot.upper_limits):
            return None
        timing = time_path(path, self.velocity, self.acceleration, self.jerk, grid_points=self.config.grid_points)
        try:
            return timing, checker.check(timing.trajectory, target_word=self.target_word)
        except PlanningError:
            return None

    # --- the planner contract ----------------------------------------------------------------
    def preflight(self, horizon: float = 120.0):
        """The motion's length against ``horizon`` [s] once planned (the search is
        :meth:`plan_in`'s, in the cell)."""
        super().preflight(horizon)
        if self.law._law is not None and self.law.duration > horizon:
            raise PlanningError(f"the motion takes {self.law.duration:.3f} s, longer than {horizon:g} s (the run's "
                                "max_duration)", cause=Cause.TIMEOUT)
        return None

    def planned_duration(self) -> float:
        return float("nan") if self.law._law is None else self.law.duration

    def task_waypoints(self) -> np.ndarray:
        """The goals' TCP positions [m] (the poses', or the joint goals')."""
        if len(self.config.poses):
            return np.asarray(self.config.poses, dtype=float)[:, :3]
        return self.robot.tool_position(np.asarray(self.config.goals, dtype=float))

    def tool_path(self) -> np.ndarray:
        """The planned motion's TCP positions [m] (N, 3) every 10 ms (for drawing)."""
        plan = self.plan()
        times = np.append(np.arange(plan.start_time(), plan.end_time(), 0.01), plan.end_time())
        return self.robot.tool_position(plan.vector_values(times).T)

    def found_path(self) -> np.ndarray:
        """The shortened joint paths of every leg, joined (k, n) [rad] (empty before planning)."""
        if not self.legs:
            return np.zeros((0, self.num_joints))
        return np.concatenate([self.legs[0].vertices] + [leg.vertices[1:] for leg in self.legs[1:]])


def _densified(vertices, density: float | None) -> np.ndarray:
    """``vertices`` (k, n) with points inserted along each segment at most ``density`` [rad]
    apart (None: the vertices alone)."""
    if density is None:
        return np.asarray(vertices, dtype=float)
    points = [vertices[0]]
    for a, b in zip(vertices, vertices[1:]):
        pieces = max(1, int(np.ceil(np.linalg.norm(b - a) / density)))
        points.extend(a + (b - a) * (np.arange(1, pieces + 1) / pieces)[:, None])
    return np.array(points)


def make(config: FreeMotionConfig, robot: Robot, q_initial) -> FreeMotionPlanner:
    """The planner of ``config`` on ``robot`` from ``q_initial`` [rad] (it plans in its cell:
    :meth:`FreeMotionPlanner.plan_in`)."""
    return FreeMotionPlanner(config, robot, q_initial)
