"""Free motion as a Drake system: :class:`FreeMotionPlanner` and its ``make``, from goals to a
motion that avoids the cell (:class:`~drake_traj.planners.free.config.FreeMotionConfig`).

For each goal in turn: OMPL finds a collision-free joint path from the previous one
(:func:`~.search.search`), our shortcutting shortens it (:func:`~.search.shortcut`), the
centripetal C2 spline through its vertices (more points along its segments where the spline
strays into the cell, so the spline hugs the checked segments) is checked with the cell check's
guarantee, then timed jerk-limited and near time-optimal by
:func:`~drake_traj.planners.timing.time_path`; the arm stops at each goal. The timed
motion is what the planner runs, and it is checked in the cell like every plan before anything
moves. The search needs the cell: the planner is made without it and plans when it is given one
(:meth:`FreeMotionPlanner.plan_in`, which the preflight and the station's check call).
"""

import time
from dataclasses import replace

import numpy as np

from drake_traj.errors import Cause, DrakeTrajError, PlanningError, joint_label
from drake_traj.planners.base import TimeLawPlanner
from drake_traj.planners.free.config import MAX_PLANNING_TIME, FreeMotionConfig
from drake_traj.planners.free.law import FreeMotionLaw, Leg
from drake_traj.planners.free.search import PLANNERS, Scene, search, shortcut
from drake_traj.planners.timing import jerk_limited_limits, time_path, waypoint_path
from drake_traj.robots import Robot
from drake_traj.validation import finite_array

__all__ = ["DENSITIES", "SEARCH_SHARE", "FreeMotionPlanner", "make"]

SEARCH_SHARE = 0.8
"""The share of a leg's budget its search may take; the rest is for shortening, smoothing, timing
and checking the path found (on the free-motion bench these take 0.02-0.15 s together)."""

DENSITIES = (None, 0.3, 0.1, 0.03)
"""[rad] the spline's repair: its points along the found segments at most this far apart (None:
the vertices only), tried in turn until the spline keeps the clearance."""


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
        config.validate(robot)
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
        :class:`~drake_traj.cell.clearance.CellChecker`; what its ``check_planner`` calls for this
        planner); nothing to do where it planned there already. Returns the cell check's
        :class:`~drake_traj.cell.clearance.MotionCheck` of the timed motion.

        Raises:
            CollisionError: the start or a goal too close to something (naming the bodies).
            DrakeTrajError: a goal outside the joint ranges, a pose out of reach (at its field).
            PlanningError: no path within the budget (what was tried), or none that could be
                smoothed clear of the cell.
        """
        if self._planned_in is not None and self._planned_in[0] == checker.fingerprint:
            return self._planned_in[1]
        scene = Scene(checker, self.robot.lower_limits, self.robot.upper_limits,  # the model compiled once a process
                      collision_check=self.config.collision_check)
        began = time.perf_counter()
        deadline = began + self.config.planning_time  # the whole budget: every leg, all of planning
        rng = np.random.default_rng(self.config.seed)
        checker.check_configuration(self.initial_positions())
        goals = list(self._goal_candidates(checker))  # joint goals checked, poses solved, before any search
        legs, current = [], self.initial_positions()
        for k, candidates in enumerate(goals):
            now = time.perf_counter()
            leg_deadline = now + max(deadline - now, 0.0) / (len(goals) - k)  # a share of what is left
            leg, current = self._leg(scene, checker, rng, k, current, candidates, leg_deadline)
            legs.append(leg)
        self.law.set_legs([leg.timing for leg in legs])
        self._plan = None  # plan() is made again from the new law
        # the plan is the checked legs one after the other (the same quintic pieces): their checks joined
        offsets = np.concatenate([[0.0], np.cumsum([leg.timing.duration for leg in legs])[:-1]])
        accepted = replace(legs[0].check, times=np.concatenate([leg.check.times + offset
                                                                 for leg, offset in zip(legs, offsets)]),
                           spacing=max(leg.check.spacing for leg in legs),
                           distances=np.concatenate([leg.check.distances for leg in legs]))
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
                raise DrakeTrajError(f"pose {k} cannot be reached: {error}", field=("poses", k),
                                     cause=Cause.UNREACHABLE) from error
            yield solutions

    def _check_range(self, q, field_: tuple) -> None:
        low, high = self.robot.lower_limits, self.robot.upper_limits
        outside = np.flatnonzero((q < low) | (q > high))
        if len(outside):
            j = int(outside[0])
            raise DrakeTrajError(f"goal {field_[1]}: {joint_label(j, self.robot.joint_names)} = {q[j]:.4g} rad "
                                 f"is outside its range [{low[j]:.4g}, {high[j]:.4g}] rad", field=field_,
                                 cause=Cause.JOINT_RANGE)

    def _pose_goals(self, scene: Scene, solutions, previous) -> list[np.ndarray]:
        """A pose's IK solutions, each moved by whole turns towards ``previous`` within the ranges,
        those inside the ranges and clear of the cell, nearest ``previous`` first."""
        goals = [q for q in (_turned(scene, q, previous) for q in solutions) if scene.valid(q)]
        return sorted(goals, key=lambda q: float(np.linalg.norm(q - previous)))

    @staticmethod
    def _in_the_way(scene: Scene, checker, solutions, previous) -> str:
        """Why none of a pose's IK ``solutions`` is a goal: how many leave the joint ranges, and
        what the others come closer than the clearance to (the cell's parts by name, or the arm
        itself), nearest first per solution."""
        outside, names = 0, {}
        for q in (_turned(scene, q, previous) for q in solutions):
            if np.any(q < scene.lower) or np.any(q > scene.upper):
                outside += 1
                continue
            nearest = checker.contacts(q, within=np.inf)[0]  # SceneGraph's nearest pair (the error path only)
            name = "the arm itself" if all(nearest.on_arm) else nearest.bodies[nearest.on_arm.index(False)]
            names[name] = names.get(name, 0) + 1
        parts = [f"{outside} outside the joint ranges"] if outside else []
        if names:
            counts = sorted(names.items(), key=lambda item: -item[1])
            parts.append(f"of the {sum(names.values())} inside them, closer than cell.clearance: " + ", ".join(
                f"{count} to {name}" for name, count in counts))
        return "; ".join(parts)

    def _leg(self, scene: Scene, checker, rng, k: int, start, candidates, deadline: float) -> "tuple[Leg, np.ndarray]":
        """The timed leg from ``start`` to whichever of ``candidates`` one search reaches first,
        planned by ``deadline`` (a ``time.perf_counter()`` value) where it can be; where no smooth
        motion along the path found keeps the clearance, another search (the next seed) while the
        budget lasts."""
        word, field_ = ("goal", ("goals", k)) if len(self.config.goals) else ("pose", ("poses", k))
        goals = candidates if len(self.config.goals) else self._pose_goals(scene, candidates, start)
        if not goals:
            raise PlanningError(f"{word} {k}: none of its {len(candidates)} inverse-kinematics solutions is inside the "
                                f"joint ranges and clear of the cell ({self._in_the_way(scene, checker, candidates, start)})",
                                field=field_, cause=Cause.COLLISION)
        unsmooth = []  # vertices of the paths found along which no smooth motion kept the clearance
        while not unsmooth or time.perf_counter() < deadline:  # another search while the budget lasts
            budget = SEARCH_SHARE * max(deadline - time.perf_counter(), 0.0)
            found = search(scene, start, np.array(goals), planning_time=max(budget, 1e-3),
                           seed=int(rng.integers(2**31 - 1)), planner=self.config.planner, max_step=self.config.max_step)
            if found.vertices is None and not unsmooth:
                raise PlanningError(self._not_found(word, k, len(goals), found), field=field_, cause=Cause.PLANNING)
            if found.vertices is None:
                break
            vertices = shortcut(scene, found.vertices, rng, rounds=self.config.shortcut_rounds, deadline=deadline)
            for density in DENSITIES:
                timed = self._smooth_and_time(scene, checker, vertices, density)
                if timed is not None:
                    return Leg(found.vertices, vertices, *timed, density, found.seconds, found.samples), vertices[-1]
            unsmooth.append(len(vertices))
        found_text = (f"a path was found ({unsmooth[0]} vertices)" if len(unsmooth) == 1 else
                      f"{len(unsmooth)} paths were found ({', '.join(map(str, unsmooth))} vertices)")
        raise PlanningError(f"{word} {k}: {found_text} but no smooth motion along {'it' if len(unsmooth) == 1 else 'any'} "
                            f"kept the clearance (points along it down to {DENSITIES[-1]} rad apart)",
                            field=field_, cause=Cause.PLANNING)

    def _not_found(self, word: str, k: int, goals: int, found) -> str:
        """The refusal of a search that found no path in its budget: what it tried, and what to change."""
        budget = self.config.planning_time
        return (f"no collision-free path to {word} {k} found within planning_time = {budget:g} s "
                f"({PLANNERS[self.config.planner]}, {goals} configuration{'s' * (goals > 1)} tried, {found.samples} "
                f"states sampled in {found.seconds:.2f} s of search); " + (
                    f"a path may need more time: give planning_time = {min(4 * budget, MAX_PLANNING_TIME):g} (or another "
                    "seed), or " if budget < MAX_PLANNING_TIME else "try another seed, or ") +
                f"move the {word} further from the obstacles")

    def _smooth_and_time(self, scene: Scene, checker, vertices, density):
        """(the timed spline through ``vertices`` (points ``density`` [rad] apart along the
        segments), its cell check's MotionCheck), or None where the spline leaves the ranges or
        the timed motion comes closer than the clearance. A spline that leaves the ranges, or comes
        closer than the clearance at one of 2001 points along it by the compiled model (the timed
        motion keeps to it within 1e-4 rad), is not timed: 2 ms where a timing and a refused
        check took 60-100 ms."""
        path = waypoint_path(_densified(vertices, density))
        q = path.vector_values(np.linspace(path.start_time(), path.end_time(), 2001)).T
        if np.any(q < self.robot.lower_limits) or np.any(q > self.robot.upper_limits):
            return None
        if scene.model is not None and not scene.model.valid(q).all():
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


def _turned(scene: Scene, q, previous) -> np.ndarray:
    """``q`` [rad] moved by whole turns towards ``previous`` where that keeps it within the
    scene's joint ranges."""
    shifted = q + 2 * np.pi * np.round((previous - q) / (2 * np.pi))
    return np.where((shifted < scene.lower) | (shifted > scene.upper), q, shifted)


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
