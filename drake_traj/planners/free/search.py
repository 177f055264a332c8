"""Collision-free joint paths through a cell: the Open Motion Planning Library's planners (the
``ompl`` wheel) search, validity from the cell check's compiled collision model (or SceneGraph's
signed distances, the reference), our shortcutting after.

Validity is the cell check's (:class:`~drake_traj.cell.clearance.CellChecker`, duck-typed here: its
``compiled_model``, ``pose_query``, ``pair_travel`` and ``clearance``): a configuration is valid
inside the joint ranges with no two bodies closer than the clearance c. The compiled model
(:class:`~drake_traj.cell.compiled_model.CompiledCollisionModel`) gives each pair's distance as a
certified lower bound of the true one, about 100 times faster than a SceneGraph query from Python. A straight joint segment is valid by conservative
advancement: from a configuration where the nearest pair is d apart, no two bodies come more
than 2.2 Σ_j R_j |Δq_j| closer (R_j the joint reach bounds, both bodies moving, the check's 1.1
margin), so the next configuration checked is max(d - c, c/2) of that travel further: at least c
at every configuration checked and c/2 between them, the cell check's own guarantee, with long
steps where the arm is far from everything.

The search runs in this process, its random numbers seeded at its start: OMPL's ``RNG.setSeed``
seeds the generator of the seeds of every sampler made after it (OMPL logs an error where some were
made before, which says only that those earlier ones are not reseeded), and each search makes its
own, so a seed reproduces its path in any process, after any other search. It ran in a forked
child process before: 54 ms a search on the free-motion bench's clutter (the child's fork, its
import of OMPL and its exit), 0.3 ms in this process. An exception in a validity callback
(Ctrl-C's KeyboardInterrupt too) ends the search and reaches the caller. Joint positions in rad.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass

import numpy as np

__all__ = ["COLLISION_CHECKS", "DEFAULT_MAX_STEP", "PLANNERS", "SearchResult", "Scene", "search", "shortcut"]

PLANNERS = {"rrt_connect": "RRTConnect", "aorrtc": "AORRTC", "bit_star": "BITstar", "rrt_star": "RRTstar"}
"""The OMPL planners a config may name: RRT-Connect finds a path and stops (our default); the
others are asymptotically optimal and use the whole budget."""

COLLISION_CHECKS = ("compiled", "scenegraph")
"""How the search checks configurations and segments: the compiled collision model (default), or
SceneGraph's signed distances from Python (the reference the compiled model is measured against)."""

DEFAULT_MAX_STEP = 0.25
"""[rad] the longest edge the tree-growing planners add (OMPL's "range"). OMPL's default is 0.2 of
the space's extent, 6.16 rad for joints of ±2π: edges across the whole cell that narrow passages
refuse. Measured on the free-motion bench's seven kinds of scene, 10 seeded queries each, 5 s
budget (docs/free-motion.md): 0.15 rad 69/70 solved, 0.25 and 0.4 rad 70/70, 1 rad 31/35 (the slot
40 mm taller than the forearm 1/5), 2 rad the slot 3/5."""

RESTART, RESTART_GROWTH = 2000, 1.2
"""RRT-Connect starts over (its trees cleared, its random numbers going on) after RESTART states
sampled, each run RESTART_GROWTH times as long as the one before: the states it needs to a path
through a narrow passage are heavy-tailed. Measured on the free-motion bench's 40 mm slots (scene
seeds 0-29, 4 search seeds each, in states sampled, at most 150,000): without restarts 115 of 120
found, mean 19,831; with these 120 of 120, median 3,318, p90 12,010, worst 37,382, mean 5,755
(80 of 80 on scene seeds 100-119, mean 6,327). Runs of a constant 2,000 needed 12 % fewer in the
mean, but would never find a path that needs a larger tree; growth 1.5 (mean 5,969, worst 69,994)
and Luby's sequence of 1,000 or 2,000 (worst 89,839) did worse. The runs end by states sampled, not
by the clock: a seed finds its path on any machine that finds it within the budget."""

GIVE_UP = 15
"""Shortcutting stops after this many shortcuts in a row were refused."""

LOOK_AHEAD = 0.07
"""[m] how far a distance query looks: a pair further away takes at most this less c of travel per
step. Measured on 24 seeded queries round a shelf, a gate and bins with SceneGraph in the search:
0.07 m 0.42 s median planning, 0.1 m 0.45 s, 0.25 m 0.54 s (more pairs per query cost more than the
longer steps save)."""


class Scene:
    """The cell as the search sees it.

    Args:
        checker: the cell check of the robot in its cell (a :class:`~drake_traj.cell.clearance.CellChecker`).
        lower, upper: the joint ranges [rad], (n,).
    """

    def __init__(self, checker, lower, upper, *, collision_check: str = "compiled"):
        if collision_check not in COLLISION_CHECKS:
            raise ValueError(f"collision_check must be one of {COLLISION_CHECKS}, got {collision_check!r}")
        self.checker = checker
        self.collision_check = collision_check
        self.clearance = float(checker.clearance)
        self.lower, self.upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
        self.model = checker.compiled_model() if collision_check == "compiled" else None
        if self.model is not None:  # its kernels compiled (or read from numba's cache) now, not in a search's budget
            middle = 0.5 * (self.lower + self.upper)
            self.model.valid(middle), self.model.distances(middle), self.model.segment_valid(middle, middle + 1e-3)
        else:  # SceneGraph's advancement: [m/rad] (n + 1, n + 1, n) the relative travel of a pair of links
            # per |Δq| (1.1 margin): the joints between them move the outer one about the inner one
            self._pair_travel, self._links = checker.pair_travel()
            self._any_pair = self._pair_travel.max(axis=(0, 1))  # a pair beyond the look-ahead
        _ompl()  # imported now, not in a search's budget
        self.queries = 0

    def _pairs(self, q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(distances [m], inner links, outer links) of the pairs closer than :data:`LOOK_AHEAD` at ``q``."""
        self.queries += 1
        pairs = self.checker.pose_query(q).ComputeSignedDistancePairwiseClosestPoints(LOOK_AHEAD)
        links = self._links
        rows = np.array([(pair.distance, links.get(pair.id_A, 0), links.get(pair.id_B, 0)) for pair in pairs],
                        dtype=float).reshape(-1, 3)
        return rows[:, 0], rows[:, 1].astype(int), rows[:, 2].astype(int)

    def distance(self, q) -> float:
        """The smallest distance [m] between two bodies at ``q``, at most :data:`LOOK_AHEAD` (the
        compiled model's: at most its own look-ahead)."""
        if self.model is not None:
            self.queries += 1
            return self.model.distances(q)
        distances = self._pairs(q)[0]
        return float(distances.min()) if len(distances) else LOOK_AHEAD

    def valid(self, q) -> bool:
        """Inside the joint ranges and no two bodies closer than the clearance."""
        q = np.asarray(q, dtype=float)
        if self.model is not None:
            self.queries += 1
            return self.model.valid(q)
        return bool(np.all(q >= self.lower) and np.all(q <= self.upper)) and self.distance(q) >= self.clearance

    def segment_valid(self, a, b) -> bool:
        """The straight joint segment from ``a`` to ``b`` keeps the clearance c at every
        configuration checked and c/2 between them; ``a`` is taken as checked. Conservative
        advancement per pair of bodies: from a configuration where a pair is d apart, the next
        one checked is max(d - c, c/2) of that pair's travel bound further (the joints between
        its two links only), the least over the pairs (module docstring); compiled where the scene
        checks with the compiled model."""
        if self.model is not None:
            self.queries += 1
            return self.model.segment_valid(a, b)
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        step = b - a
        if not np.any(step):
            return True
        if np.any(np.minimum(a, b) < self.lower) or np.any(np.maximum(a, b) > self.upper):
            return False  # a straight segment between two points inside a box stays inside it
        c = self.clearance
        for u in (1.0, 0.5, 0.25, 0.75):  # a cheap look at the end and inside first: most refusals end here
            if self.distance(a + u * step) < c:
                return False
        travel = self._pair_travel @ np.abs(step)  # (n + 1, n + 1) [m] each pair's travel bound over the segment
        beyond = (LOOK_AHEAD - c) / max(float(self._any_pair @ np.abs(step)), 1e-12)
        u = 0.0
        while u < 1.0:
            distances, inner, outer = self._pairs(a + u * step)
            if len(distances) and distances.min() < c:
                return False
            rates = travel[inner, outer]
            allowed = np.maximum(distances - c, 0.5 * c) / np.maximum(rates, 1e-12)
            u = min(1.0, u + min(float(allowed.min()) if len(allowed) else np.inf, beyond))
        return self.distance(b) >= c


@dataclass(frozen=True)
class SearchResult:
    """A search's outcome: the path's vertices (k, n) [rad] (None: none found), what it took."""

    vertices: np.ndarray | None
    planner: str
    seconds: float  # [s] OMPL's solve
    samples: int  # states OMPL sampled and checked
    queries: int  # distance queries of the search (states and segments)
    status: str  # OMPL's word for the outcome
    runs: int = 1  # OMPL's runs (RRT-Connect's restarts: RESTART); 0 for the straight segment


def search(scene: Scene, start, goals, *, planning_time: float, seed: int, planner: str = "rrt_connect",
           max_step: float = DEFAULT_MAX_STEP) -> SearchResult:
    """A collision-free joint path from ``start`` to any of ``goals`` ((k, n), or one goal (n,))
    by OMPL's ``planner`` within ``planning_time`` [s], random numbers seeded with ``seed`` (the
    same seed, the same path: module docstring), edges at most ``max_step`` [rad] long. Every end must
    be valid (:meth:`Scene.valid`); the straight segment to each goal, in order, is tried first.
    The path ends at the goal it reached."""
    start, goals = np.asarray(start, dtype=float), np.atleast_2d(np.asarray(goals, dtype=float))
    for goal in goals:
        if scene.segment_valid(start, goal):
            return SearchResult(np.array([start, goal]), "straight", 0.0, 0, scene.queries, "straight segment", 0)
    return _ompl_search(scene, start, goals, planning_time, seed, planner, max_step)


def _ompl():
    """OMPL's modules (base, geometric, util), imported at the first call (12 ms, measured)."""
    from ompl import base, geometric, util

    return base, geometric, util


def _ompl_search(scene: Scene, start, goals, planning_time: float, seed: int, planner: str,
                 max_step: float) -> SearchResult:
    """OMPL's search: the goals as one goal region of states (OMPL's GoalStates), so every
    candidate shares one search."""
    ob, og, ou = _ompl()
    ou.setLogLevel(ou.LogLevel.LOG_NONE)  # a second setSeed's error among them (module docstring)
    ou.RNG.setSeed(int(seed) + 1)  # before the planner and its samplers are made; OMPL ignores a seed of 0
    n = len(start)
    space = ob.RealVectorStateSpace(n)
    bounds = ob.RealVectorBounds(n)
    for j in range(n):
        bounds.setLow(j, float(scene.lower[j]))
        bounds.setHigh(j, float(scene.upper[j]))
    space.setBounds(bounds)
    information = ob.SpaceInformation(space)
    samples = [0]

    def as_array(state) -> np.ndarray:
        return np.fromiter((state[j] for j in range(n)), dtype=float, count=n)

    def valid(state) -> bool:
        samples[0] += 1
        return scene.valid(as_array(state))

    class Segments(ob.MotionValidator):
        def checkMotion(self, *states):  # (s1, s2) or (s1, s2, last_valid): OMPL calls both
            return scene.segment_valid(as_array(states[0]), as_array(states[1]))

    information.setStateValidityChecker(valid)
    validator = Segments(information)
    information.setMotionValidator(validator)
    information.setup()
    setup = og.SimpleSetup(information)

    def state_of(values):
        state = information.allocState()
        for j in range(n):
            state[j] = float(values[j])
        return state

    setup.setStartState(state_of(start))
    region = ob.GoalStates(information)
    for goal in goals:
        region.addState(state_of(goal))
    setup.setGoal(region)
    search_planner = getattr(og, PLANNERS[planner])(information)
    if hasattr(search_planner, "setRange"):
        search_planner.setRange(float(max_step))
    setup.setPlanner(search_planner)
    began = time.perf_counter()
    deadline, limit = began + float(planning_time), RESTART if planner == "rrt_connect" else np.inf
    for run in itertools.count(1):  # RRT-Connect starts over after RESTART states, each run longer
        status = setup.solve(ob.PlannerTerminationCondition(
            lambda: samples[0] >= limit or time.perf_counter() >= deadline))
        if setup.haveExactSolutionPath() or time.perf_counter() >= deadline:
            break
        setup.clear()  # the trees; the samplers made for the next run take the next seeds
        limit = samples[0] + RESTART * RESTART_GROWTH ** run
    seconds = time.perf_counter() - began
    vertices = None
    if setup.haveExactSolutionPath():
        path = setup.getSolutionPath()
        vertices = np.array([as_array(path.getState(k)) for k in range(path.getStateCount())])
    return SearchResult(vertices, planner, seconds, samples[0], scene.queries, str(status), run)


def shortcut(scene: Scene, vertices, rng: np.random.Generator, *, rounds: int = 60,
             deadline: float = float("inf")) -> np.ndarray:
    """The path ``vertices`` (k, n) [rad] shortened: up to ``rounds`` random shortcuts between two
    points of the path (by length; :data:`GIVE_UP` refused in a row end them, and so does the
    ``deadline``, a ``time.perf_counter()`` value), each kept where its segment is valid
    (:meth:`Scene.segment_valid`), then every vertex the segment from its predecessor to its
    successor makes unnecessary."""
    path = [np.asarray(v, dtype=float) for v in vertices]
    failures = 0
    for _ in range(rounds):
        if len(path) < 3 or failures >= GIVE_UP or time.perf_counter() > deadline:
            break
        lengths = np.linalg.norm(np.diff(path, axis=0), axis=1)
        ends = np.concatenate([[0.0], np.cumsum(lengths)])
        s0, s1 = np.sort(rng.uniform(0.0, ends[-1], 2))
        i0, i1 = (int(np.clip(np.searchsorted(ends, s, side="right") - 1, 0, len(lengths) - 1)) for s in (s0, s1))
        if i0 == i1:
            continue
        a = path[i0] + (s0 - ends[i0]) / lengths[i0] * (path[i0 + 1] - path[i0])
        b = path[i1] + (s1 - ends[i1]) / lengths[i1] * (path[i1 + 1] - path[i1])
        if scene.valid(a) and scene.valid(b) and scene.segment_valid(a, b):
            path = path[: i0 + 1] + [a, b] + path[i1 + 1:]
            failures = 0
        else:
            failures += 1
    k = 1
    while k < len(path) - 1:  # drop vertices the straight segment past them makes unnecessary
        if scene.segment_valid(path[k - 1], path[k + 1]):
            del path[k]
        else:
            k += 1
    keep = [path[0]] + [q for previous, q in zip(path, path[1:]) if np.linalg.norm(q - previous) > 1e-9]
    return np.array(keep)
