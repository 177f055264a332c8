"""Is a planned motion possible in the cell? Joint ranges, self-collision and collision with the
cell, checked on the planned reference before the arm moves.

:class:`CellChecker` holds a plant of its own with the robot, its tool and its cell
(:func:`drake_traj.cell.add_cell`: the same geometry as the simulated station) and asks Drake's
SceneGraph for signed distances (``ComputeSignedDistancePairwiseClosestPoints``) between every
pair of collision geometries that Drake does not filter: the arm's non-adjacent links, the tool
and the cell (bodies joined by a joint, and everything welded to the world, are filtered by the
plant; the robot model may declare more, with its reasons, in its URDF).

Sampling (:meth:`CellChecker.check`): conservative advancement on the arm's travel bounds
(:mod:`~drake_traj.cell.reach`, where the argument is): from a sample where two links are d apart,
the next sample is at most ``d - clearance + spacing`` of their travel bound further, so no
distance falls below ``clearance - spacing`` between two samples; with the default ``spacing =
clearance / 2``, a motion accepted at ``clearance`` keeps at least ``clearance / 2`` everywhere
between the samples, and where the arm is far from everything the samples are far apart. d is the
smaller of SceneGraph's signed distance and the compiled model's certified lower bound
(:class:`~drake_traj.cell.compiled_model.CompiledCollisionModel`), SceneGraph asked for every pair
within the distance that covers the step: SceneGraph's own distances prove every step.
"""

import hashlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydrake.geometry import Role
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder
from pydrake.trajectories import Trajectory

from drake_traj.cell.cell import Cell, add_cell
from drake_traj.cell.compiled_model import DEFAULT_LOOK_AHEAD, CompiledCollisionModel, UnsupportedShapeError
from drake_traj.cell.directives import refuse_free_bodies
from drake_traj.cell.reach import Advancement, joint_reach, link_reach, pair_travel
from drake_traj.errors import Cause, DrakeTrajError, Field, PlanningError, joint_label
from drake_traj.robots import Robot, exclude_self_contact, srdf_hint, touching_shapes
from drake_traj.validation import MAX_RUN_DURATION

__all__ = ["CellChecker", "CollisionError", "Contact", "JointRangeError", "MotionCheck", "geometry_owner",
           "planner_target_word"]

RANGE_GRID = 1e-3  # [s] joint ranges are checked at the log's period
# The most samples the cell check takes of one motion (checked before it takes them): 1000 m of
# the arm's travel bound at the default 10 mm clearance, about 8 s of distance queries (UR10e,
# measured); the shipped scenarios take at most 3000.
MAX_SAMPLES = 200_000


class CollisionError(PlanningError):
    """The planned motion brings two bodies closer than the clearance (or into contact).

    Attributes (besides :class:`PlanningError`'s; ``time`` and ``configuration`` are those of
    the first checked sample closer than the clearance):
        bodies: the two bodies' names at ``time``, e.g. ``("forearm_link", "table")``.
        distance: their signed distance [m] at ``time`` (negative: penetration).
        clearance: the clearance asked for [m].
        segment: which part of the task, e.g. ``"on the way to goal 2"`` (None if unknown).
        depth: how deep [m] the motion then goes into the same body of the cell (or the arm
            into itself), the deepest sample of the first stretch where it does; None if it
            does not (a near miss) or if not known.
        depth_time: the time [s] of that sample (None with ``depth``).
    """

    default_cause = Cause.COLLISION

    def __init__(self, message: str, *, bodies, distance: float, clearance: float, segment=None, depth=None,
                 depth_time=None, **kwargs):
        super().__init__(message, **kwargs)
        self.bodies, self.distance, self.clearance, self.segment = tuple(bodies), float(distance), float(clearance), segment
        self.depth = None if depth is None else float(depth)
        self.depth_time = None if depth_time is None else float(depth_time)


class JointRangeError(PlanningError):
    """The planned motion takes a joint past its range.

    Attributes (besides :class:`PlanningError`'s): ``joint`` (0-based index), ``value`` and
    ``limit`` [rad or m]."""

    default_cause = Cause.JOINT_RANGE

    def __init__(self, message: str, *, joint: int, value: float, limit: float, **kwargs):
        super().__init__(message, **kwargs)
        self.joint, self.value, self.limit = int(joint), float(value), float(limit)


@dataclass(frozen=True)
class Contact:
    """Two bodies within the clearance: their names, signed distance [m], the names of the two
    geometries (the cell's geometry names an obstacle, the mounting or a tool shape), their
    closest points (2, 3) [m] in the world (base) frame, and whether each body is the arm's (its
    links, its tool and what is welded to them: both for a self-collision)."""

    distance: float
    bodies: tuple[str, str]
    geometries: tuple[str, str]
    points: np.ndarray
    on_arm: tuple[bool, bool] = (False, False)


def planner_target_word(planner) -> str:
    """The planner's own word for the targets of its task (its ``target_word``: ``"goal"`` for
    the planners through joint goals, ``"point"`` for Li's and Boryga's); ``"waypoint"`` where it
    names none (Pająk's). A refusal says "on the way to goal 2"."""
    return str(getattr(planner, "target_word", "waypoint"))


def unprotected_links(plant, instance, joint_names) -> list[str]:
    """The links of a finalized plant's arm (each joint's child and the bodies welded to it) that
    have no collision geometry: the self and cell checks cannot see them."""
    missing = []
    for name in joint_names:
        link = plant.GetJointByName(name, instance).child_body()
        if not any(plant.GetCollisionGeometriesForBody(body) for body in plant.GetBodiesWeldedTo(link)):
            missing.append(link.name())
    return missing


def refuse_unprotected_links(robot, missing: list[str]) -> None:
    """DrakeTrajError (at ``robot.unchecked_links``) unless every link in ``missing`` (no
    collision shapes) is one the robot says may run unprotected (its ``unchecked_links``; "all":
    every link)."""
    allowed = set(getattr(robot, "unchecked_links", ()))
    uncovered = [link for link in missing if "all" not in allowed and link not in allowed]
    if uncovered:
        listed = ", ".join(uncovered)
        raise DrakeTrajError(
            f"the {robot.name} model's links {listed} have no collision shapes: the self and cell checks would not see "
            "them, and a motion through the table would pass. Give them collision geometry (a mesh is checked as its "
            f"convex hull), or say that they run unprotected: robot.unchecked_links: [{listed}] (or [all]; the run's "
            "metrics then name them)", field=("robot", "unchecked_links"), cause=Cause.COLLISION)


def geometry_owner(plant, inspector, geometry, robot_instance) -> tuple[str, str]:
    """(body, geometry) names of a collision geometry as messages give them: the robot's links
    by name (``forearm_link``), the cell's geometry on the world by its own name (``table``, an
    obstacle's name), other models' bodies by their scoped name (``bin::base``)."""
    body = plant.GetBodyFromFrameId(inspector.GetFrameId(geometry))
    geometry_name = inspector.GetName(geometry).split("::")[-1]
    if body.index() == plant.world_body().index():
        return geometry_name, geometry_name
    if body.model_instance() == robot_instance:
        return body.name(), geometry_name
    return str(body.scoped_name()), geometry_name


def _grid(trajectory: Trajectory) -> np.ndarray:
    """Times [s] spanning ``trajectory`` at :data:`RANGE_GRID` (at least its two ends); a
    trajectory longer than :data:`~drake_traj.validation.MAX_RUN_DURATION` is refused (at
    ``planner``) before its grid is allocated."""
    start, end = trajectory.start_time(), trajectory.end_time()
    if not end - start <= MAX_RUN_DURATION:  # NaN too
        raise DrakeTrajError(f"the planned motion lasts {end - start:.4g} s, longer than the {MAX_RUN_DURATION:g} s a run "
                             "may last: raise the planner's limits or give fewer targets", field=("planner",),
                             cause=Cause.INFEASIBLE)
    return np.linspace(start, end, max(2, int(np.ceil((end - start) / RANGE_GRID)) + 1))


def scene_fingerprint(plant, inspector) -> str:
    """A digest of a finalized plant's collision scene: every geometry with a proximity role (its
    body's scoped name, its shape and its pose in the body, 1e-9 m) and the pairs SceneGraph
    checks (its collision filters). Two plants built from the same robot, cell and added bodies
    have the same one; a body added to one, moved or filtered differently changes it."""
    def body_name(frame_id) -> str:
        body = plant.GetBodyFromFrameId(frame_id)
        return body.scoped_name().get_full() if body is not None else inspector.GetName(frame_id)

    def name(geometry) -> str:
        return f"{body_name(inspector.GetFrameId(geometry))}/{inspector.GetName(geometry)}"

    rows = sorted((name(geometry), repr(inspector.GetShape(geometry)),
                   np.round(inspector.GetPoseInFrame(geometry).GetAsMatrix34(), 9).tolist())
                  for geometry in inspector.GetAllGeometryIds(Role.kProximity))
    pairs = sorted(tuple(sorted((name(a), name(b)))) for a, b in inspector.GetCollisionCandidates())
    return hashlib.sha256(repr((rows, pairs)).encode()).hexdigest()


@dataclass(frozen=True)
class MotionCheck:
    """An accepted motion: the configurations checked at its sample times [s], the least distance
    [m] the check took at each (at most the look-ahead) and ``spacing`` [m]: no distance falls more
    than ``spacing`` below the clearance between two samples (module docstring)."""

    times: np.ndarray
    spacing: float
    distances: np.ndarray


class CellChecker:
    """Signed distances between the robot (with its tool) and itself and its cell.

    Args:
        robot: the robot; its model, as the station adds it.
        cell: the cell (default: :class:`~drake_traj.cell.Cell`, a table flush with the base).
        directory: the folder relative model files of ``cell.directives`` are taken from.
        before_finalize: ``before_finalize(plant, scene_graph)``, a station's own bodies and
            geometry (:func:`~drake_traj.station.add_station`'s), added before the plant is
            finalized.

    ``fingerprint`` names the collision scene (:func:`scene_fingerprint`): a station whose plant
    has the same one runs the motions this checker accepted (:meth:`check_planner` records it on
    the planner).
    """

    def __init__(self, robot: Robot, cell: Cell | None = None, directory: Path | None = None, *,
                 before_finalize=None):
        self.robot = robot
        self.cell = cell or Cell()
        builder = DiagramBuilder()
        self.plant, self.scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
        self.instance = robot.add_to_plant(self.plant)
        self.cell_fields = add_cell(self.plant, self.cell, self.instance, robot=robot,
                                    directory=directory)
        if before_finalize is not None:  # a station's own bodies (add_station's before_finalize)
            before_finalize(self.plant, self.scene_graph)
        self.plant.Finalize()
        self.unchecked_pairs = exclude_self_contact(self.plant, self.scene_graph, self.instance, robot)  # before contexts
        self.unprotected_links = unprotected_links(self.plant, self.instance, robot.joint_names)
        refuse_unprotected_links(robot, self.unprotected_links)
        self._diagram = builder.Build()
        self._context = self._diagram.CreateDefaultContext()
        self._plant_context = self.plant.GetMyMutableContextFromRoot(self._context)
        self._query = self.scene_graph.get_query_output_port()
        self._scene_context = self.scene_graph.GetMyContextFromRoot(self._context)
        self._inspector = self.scene_graph.model_inspector()
        self.reach = joint_reach(self.plant, self.scene_graph, self._plant_context, self.instance, robot.joint_names)
        self.fingerprint = scene_fingerprint(self.plant, self._inspector)
        self._compiled_model = None  # built on first use (compiled_model)
        self.compiled_unavailable: str | None = None  # why the compiled model cannot take this scene

    @property
    def clearance(self) -> float:
        """The cell's clearance [m]."""
        return float(self.cell.clearance)

    def link_reach(self) -> tuple[np.ndarray, dict]:
        """:func:`link_reach` of the robot in this checker's plant (per-link travel bounds)."""
        return link_reach(self.plant, self.scene_graph, self.instance, self.robot.joint_names)

    def pair_travel(self) -> tuple[np.ndarray, dict]:
        """(T [m/rad or m/m] (n + 1, n + 1, n), {GeometryId: link}): how far link b moves relative
        to link a per |Δq_j| (:func:`~drake_traj.cell.reach.pair_travel` of :meth:`link_reach`),
        for the conservative advancement of the check and of the free-motion search; made once."""
        if getattr(self, "_pair_travel", None) is None:
            reach, links = self.link_reach()
            self._pair_travel = (pair_travel(reach), links)
        return self._pair_travel

    def compiled_model(self) -> CompiledCollisionModel:
        """The compiled collision model of this checker's scene (the robot, its tool and the cell at
        this clearance: :class:`~drake_traj.cell.compiled_model.CompiledCollisionModel`), built at
        the first call and kept: batches of configurations checked 100 times faster and more than
        by SceneGraph, each distance a certified lower bound of SceneGraph's."""
        if self._compiled_model is None:
            self._compiled_model = CompiledCollisionModel(self)
        return self._compiled_model

    def owner(self, geometry) -> tuple[str, str]:
        """(body, geometry) names of a geometry id, as messages give them (:func:`geometry_owner`)."""
        return geometry_owner(self.plant, self._inspector, geometry, self.instance)

    def pose_query(self, q):
        """SceneGraph's QueryObject with the robot at joint positions ``q``."""
        self.plant.SetPositions(self._plant_context, self.instance, np.asarray(q, dtype=float))
        return self._query.Eval(self._scene_context)

    def contacts(self, q, within: float | None = None) -> list[Contact]:
        """The pairs of bodies closer than ``within`` [m] (default the clearance) at joint
        positions ``q``, nearest first, one entry per pair of bodies (a larger ``within`` costs
        more: 53 µs per configuration of the UR10e at 10 mm, 380 µs at 0.1 m, measured)."""
        query = self.pose_query(q)
        nearest = {}
        for pair in query.ComputeSignedDistancePairwiseClosestPoints(self.clearance if within is None else within):
            (body_a, geometry_a), (body_b, geometry_b) = self.owner(pair.id_A), self.owner(pair.id_B)
            key = tuple(sorted((body_a, body_b)))
            if key not in nearest or pair.distance < nearest[key].distance:
                points = np.array([query.GetPoseInWorld(pair.id_A) @ pair.p_ACa, query.GetPoseInWorld(pair.id_B) @ pair.p_BCb])
                nearest[key] = Contact(pair.distance, (body_a, body_b), (geometry_a, geometry_b), points,
                                       (self._on_arm(pair.id_A), self._on_arm(pair.id_B)))
        return sorted(nearest.values(), key=lambda contact: contact.distance)

    def _second_opinion(self) -> CompiledCollisionModel | None:
        """The compiled model for the checks' second opinion, or None where the scene has a shape
        it does not take (:class:`~drake_traj.cell.compiled_model.UnsupportedShapeError`; then
        SceneGraph alone checks, and :attr:`compiled_unavailable` says why)."""
        if self.compiled_unavailable is not None:
            return None
        try:
            return self.compiled_model()
        except UnsupportedShapeError as error:
            self.compiled_unavailable = str(error)
            return None

    def _missed_contacts(self, q) -> list[Contact]:
        """The nearest pair closer than the clearance at ``q`` by the compiled model's certified
        lower bound where SceneGraph's signed distance put it further (SceneGraph's distance of a
        cylinder or box pair can be above the true one by millimetres:
        :mod:`~drake_traj.cell.compiled_model`), as a one-entry list (its points SceneGraph's
        closest points of the pair); empty where the model finds none."""
        model = self._second_opinion()
        if model is None or model.distances(q) >= self.clearance:  # the broad phase first: most are clear
            return []
        bounds = model.pair_bounds(q)
        p = int(np.argmin(bounds[:, 0])) if len(bounds) else -1
        if p < 0 or bounds[p, 0] >= self.clearance:
            return []
        pair_ids = {model.geometries[model.pairs[p, 0]], model.geometries[model.pairs[p, 1]]}
        query = self.pose_query(q)
        points = np.full((2, 3), np.nan)
        for pair in query.ComputeSignedDistancePairwiseClosestPoints(self.clearance + 0.1):
            if {pair.id_A, pair.id_B} == pair_ids:
                points = np.array([query.GetPoseInWorld(pair.id_A) @ pair.p_ACa,
                                   query.GetPoseInWorld(pair.id_B) @ pair.p_BCb])
                ids = (pair.id_A, pair.id_B)
                break
        else:
            ids = tuple(pair_ids)
        (body_a, geometry_a), (body_b, geometry_b) = self.owner(ids[0]), self.owner(ids[1])
        return [Contact(float(bounds[p, 0]), (body_a, body_b), (geometry_a, geometry_b), points,
                        (self._on_arm(ids[0]), self._on_arm(ids[1])))]

    def _on_arm(self, geometry) -> bool:
        """Whether the geometry's body moves with the arm: a body of the robot's model (its
        links, its tool) or one welded to a link that is not welded to the world."""
        arm = getattr(self, "_arm_bodies", None)
        if arm is None:
            plant = self.plant
            fixed = {int(body.index()) for body in plant.GetBodiesWeldedTo(plant.world_body())}
            arm = set()
            for index in plant.GetBodyIndices(self.instance):
                arm.add(int(index))
                if int(index) not in fixed:
                    arm.update(int(body.index()) for body in plant.GetBodiesWeldedTo(plant.get_body(index)))
            self._arm_bodies = arm = frozenset(arm)
        return int(self.plant.GetBodyFromFrameId(self._inspector.GetFrameId(geometry)).index()) in arm

    def _advancement(self, grid, q, spacing: float) -> Advancement:
        """The travel bounds along ``q`` (the trajectory on its ``grid``); a motion whose travel
        takes more than :data:`MAX_SAMPLES` samples ``spacing`` [m] apart (an arm of absurd reach, a
        long motion at a small clearance) is refused before any is taken: DrakeTrajError at
        ``cell.clearance`` (cause INFEASIBLE) naming the travel and the clearance."""
        advancement = Advancement(grid, q, self.reach, self.pair_travel()[0])
        travel = float(advancement.travel[-1])
        if not travel / spacing <= MAX_SAMPLES:  # NaN too
            raise DrakeTrajError(
                f"the motion is too long to check in the cell: its points travel up to {travel:.4g} m (the joints' "
                f"turns times the arm's reach outboard of each, {float(np.max(self.reach)):.4g} m at most), which at "
                f"cell.clearance = {self.clearance * 1e3:g} mm (samples {spacing * 1e3:g} mm of travel apart) takes "
                f"{travel / spacing:.3g} samples, more than the {MAX_SAMPLES} the check takes: split the motion, "
                "raise cell.clearance, or check the arm's lengths", field=("cell", "clearance"),
                cause=Cause.INFEASIBLE)
        return advancement

    def sample_times(self, trajectory: Trajectory, spacing: float | None = None, *, grid=None, q=None) -> np.ndarray:
        """Times [s] of ``trajectory`` (q(t)) every ``spacing`` [m] (default half the clearance, at
        least 1 mm) of the arm's travel bound, its ends included (module docstring): the samples of
        :meth:`check` where every pair is at the clearance, the most it takes (too many refused:
        :meth:`_advancement`). ``grid`` (the trajectory's 1 ms grid) and ``q`` (on it) when known."""
        spacing = self.default_spacing() if spacing is None else float(spacing)
        grid = _grid(trajectory) if grid is None else grid
        travel = self._advancement(grid, trajectory.vector_values(grid).T if q is None else q, spacing).travel
        count = int(np.ceil(travel[-1] / spacing))
        times = np.interp(np.linspace(0.0, travel[-1], count + 1), travel, grid) if count else grid[:1]
        return np.unique(np.concatenate([times, grid[[0, -1]]]))

    def check(self, trajectory: Trajectory, *, waypoints=None, spacing: float | None = None,
              target_word: str = "waypoint") -> MotionCheck:
        """Check the joint reference ``trajectory`` (a Drake Trajectory of q(t), e.g.
        ``planner.plan()``): every joint inside its range on a 1 ms grid, then no two bodies
        closer than the clearance at samples placed by conservative advancement (module
        docstring: none ``spacing`` [m] closer between two, default half the clearance, at least
        1 mm), by SceneGraph's signed distances and the compiled model's certified lower bounds
        (:meth:`compiled_model`), whichever is smaller.

        ``waypoints`` (m, 3) [m], the task's tool points in order, name the segment of a
        collision ("on the way to waypoint k", ``target_word`` the planner's word for them:
        :func:`planner_target_word`). Raises :class:`JointRangeError` or
        :class:`CollisionError` (time, bodies, distance, segment, configuration) for the first
        sample that is too close: a motion that goes on into the same body (or the arm into
        itself) is said to go through it, how deep and when (the samples after it, every
        ``spacing`` of travel, are scanned); returns a :class:`MotionCheck`."""
        grid = _grid(trajectory)
        q = trajectory.vector_values(grid).T
        self._check_ranges(trajectory, grid, q, waypoints, target_word)
        spacing = self.default_spacing() if spacing is None else float(spacing)
        advancement = self._advancement(grid, q, spacing)
        model = self._second_opinion()
        pair_rows = None if model is None else advancement.row(*np.sort(model.pairs[:, 2:4], axis=1).T)
        times, distances, t = [], [], float(grid[0])
        while True:
            q_t = trajectory.value(t).ravel()
            distance, after = self._advance(advancement, t, q_t, model, pair_rows, spacing)
            if distance < self.clearance:
                contacts = self.contacts(q_t) or self._missed_contacts(q_t)
                if contacts:
                    later = self.sample_times(trajectory, spacing, grid=grid, q=q)
                    later = np.concatenate([[t], later[later > t]])
                    through = self._through(contacts[0], later, trajectory.vector_values(later).T)
                    raise self._collision(contacts[0], t, q_t, trajectory, waypoints, target_word, through)
                # the model's bound, run pair by pair to its tolerance, is not below the clearance: every pair at it
                distance, after = self.clearance, advancement.after(t, [advancement.ANY], [spacing])
            times.append(t)
            distances.append(distance)
            if t >= grid[-1]:
                return MotionCheck(np.array(times), spacing, np.array(distances))
            t = after

    def _advance(self, advancement: Advancement, t: float, q, model, pair_rows, spacing: float) -> tuple[float, float]:
        """:meth:`~drake_traj.cell.reach.Advancement.step` at ``q`` (time ``t`` [s]): the compiled
        ``model``'s bounds (None: none; ``pair_rows`` its pairs' rows) first, then SceneGraph's."""
        if model is None:
            rows, bounds, look_ahead = np.zeros(0, dtype=np.int64), np.zeros(0), DEFAULT_LOOK_AHEAD
        else:
            bounds, chosen = model.near_pairs(q)
            rows, look_ahead = pair_rows[chosen], model.look_ahead
        links = self._geometry_links()

        def scenegraph(within: float):
            rows, distances = [], []
            for found in self.pose_query(q).ComputeSignedDistancePairwiseClosestPoints(within):
                a, b = links[found.id_A], links[found.id_B]
                rows.append(advancement.ANY if a is None or b is None else advancement.row(min(a, b), max(a, b)))
                distances.append(found.distance)
            return rows, distances

        return advancement.step(t, rows, bounds, scenegraph, self.clearance, spacing, look_ahead)

    def _geometry_links(self) -> dict:
        """{GeometryId: link} of every proximity geometry for the check's travel bounds: the arm's
        (:meth:`pair_travel`'s), 0 fixed in the world or apart from the arm, None moving with it on
        no link of its chain (any pair's bound then)."""
        if getattr(self, "_links", None) is None:
            links, plant = self.pair_travel()[1], self.plant
            fixed = {body.index() for body in plant.GetBodiesWeldedTo(plant.world_body())}
            self._links = {geometry: links.get(geometry, 0 if plant.GetBodyFromFrameId(self._inspector.GetFrameId(
                geometry)).index() in fixed or not self._on_arm(geometry) else None)
                for geometry in self._inspector.GetAllGeometryIds(Role.kProximity)}
        return self._links

    def _check_ranges(self, trajectory: Trajectory, grid, q, waypoints, target_word: str) -> None:
        """:class:`JointRangeError` at the first time of ``grid`` where ``q`` leaves a joint's range."""
        lower, upper = self.robot.lower_limits, self.robot.upper_limits
        outside = (q < lower) | (q > upper)
        if outside.any():
            k, j = np.argwhere(outside)[0]
            limit = lower[j] if q[k, j] < lower[j] else upper[j]
            unit = self.robot.joint_unit(j)
            raise JointRangeError(
                f"the planned motion takes {joint_label(j, self.robot.joint_names)} to {q[k, j]:.4f} {unit}, past its "
                f"range [{lower[j]:.4f}, {upper[j]:.4f}] {unit}{self._segment_text(trajectory, grid[k], waypoints, target_word)}",
                joint=j, value=q[k, j], limit=limit, time=grid[k], configuration=q[k], cause=Cause.JOINT_RANGE)

    def _through(self, contact: Contact, times, samples) -> tuple[Contact, float] | None:
        """(the deepest contact, its time [s]) of the same kind as ``contact`` (the arm in the
        same body of the cell, or the arm in itself) in the first stretch of ``samples`` (at
        ``times``, from ``contact``'s) where the bodies are in each other; None if they never are."""
        kind, deepest = self._kind(contact), None
        for t, q in zip(times, samples):
            inside = [c for c in self.contacts(q, within=0.0) if c.distance < 0 and self._kind(c) == kind]
            if inside and (deepest is None or inside[0].distance < deepest[0].distance):
                deepest = (inside[0], float(t))
            elif not inside and deepest is not None:
                break
        return deepest

    @staticmethod
    def _kind(contact: Contact):
        """What a contact is with: "itself" (the arm with the arm), the cell's body (the arm with
        it), or both bodies (neither is the arm's)."""
        if all(contact.on_arm):
            return "itself"
        if any(contact.on_arm):
            return contact.bodies[contact.on_arm.index(False)]
        return tuple(sorted(contact.bodies))

    def default_spacing(self) -> float:
        """Half the clearance, at least 1 mm [m] (module docstring)."""
        return max(0.5 * self.clearance, 1e-3)

    def check_configuration(self, q, what: str = "the start configuration", field: Field = ("q_initial",)) -> None:
        """CollisionError (naming the two bodies, at ``field``) when ``q`` is in contact or
        closer than the clearance. First, once, a body of the cell that is joined to nothing
        (:func:`~drake_traj.cell.refuse_free_bodies`: a DrakeTrajError at its directive)."""
        if not getattr(self, "_free_bodies_refused", False):
            refuse_free_bodies(self.plant, self.instance, self.cell_fields)
            self._free_bodies_refused = True
        contacts = self.contacts(q) or self._missed_contacts(q)
        if contacts:
            contact = contacts[0]
            if contact.distance < 0 and all(contact.on_arm):
                text = (f"in {what} the arm would hit itself ({' and '.join(contact.bodies)}, {self._mm(contact)} deep"
                        f"{touching_shapes(self, contact)})")
            elif contact.distance < 0:
                text = f"{what} puts {' into '.join(self._arm_first(contact))} ({self._mm(contact)} deep)"
            else:
                text = f"{what} {self._near_miss(contact)}"
            text += srdf_hint(self, contact) if all(contact.on_arm) else ""  # a pair that is so in most poses
            raise CollisionError(text, bodies=contact.bodies, distance=contact.distance, clearance=self.clearance,
                                 time=0.0, configuration=q, field=field, cause=Cause.COLLISION)

    def field_of(self, contact: Contact) -> Field:
        """The scenario field of the cell's part in ``contact``: an obstacle, the mounting or a
        tool shape (by its geometry's name), a body of a ``cell.directives`` model (by its
        scoped name: its entry ``("cell", "directives", k)``); () when there is none (the arm
        with itself)."""
        for geometry in contact.geometries:
            if geometry in self.cell_fields:
                return self.cell_fields[geometry]
        for body, on_arm in zip(contact.bodies, contact.on_arm):
            if not on_arm and body in self.cell_fields:
                return self.cell_fields[body]
        return ()

    @staticmethod
    def _mm(contact: Contact) -> str:
        return f"{abs(contact.distance) * 1000:.1f} mm"

    @staticmethod
    def _arm_first(contact: Contact) -> tuple[str, str]:
        """The two bodies, the arm's first (as given when both or neither are)."""
        a, b = contact.bodies
        return (b, a) if contact.on_arm == (False, True) else (a, b)

    def _near_miss(self, contact: Contact) -> str:
        """"brings A and B within d mm of each other, closer than the clearance of c mm
        (cell.clearance)", or "brings the arm within d mm of itself (A and B), ..."."""
        closer = f"closer than the clearance of {self.clearance * 1000:g} mm (cell.clearance)"
        if all(contact.on_arm):
            return (f"brings the arm within {self._mm(contact)} of itself ({' and '.join(contact.bodies)}"
                    f"{touching_shapes(self, contact)}), {closer}")
        return f"brings {' and '.join(self._arm_first(contact))} within {self._mm(contact)} of each other, {closer}"

    def _collision(self, contact: Contact, t: float, q, trajectory, waypoints, target_word: str = "waypoint",
                   through: tuple[Contact, float] | None = None) -> CollisionError:
        """The refusal of the first sample closer than the clearance (``contact`` at time ``t``,
        configuration ``q``); ``through``, from :meth:`_through`: how deep the motion then goes.
        The time is said once, by :class:`PlanningError` ("(at t = ..., q = ...)")."""
        segment = self._segment(trajectory, t, waypoints, target_word)
        where = f" {segment}" if segment else ""
        if through is None:
            text = f"the planned motion {self._near_miss(contact)}"
        else:
            deepest, deepest_t = through
            when = f" at t = {deepest_t:.3f} s" if deepest_t != t else ""
            if all(deepest.on_arm):
                text = (f"in the planned motion the arm would hit itself ({' and '.join(deepest.bodies)}, "
                        f"{self._mm(deepest)} deep{when}{touching_shapes(self, deepest)})")
            elif any(deepest.on_arm):
                arm, other = self._arm_first(deepest)
                text = f"the planned motion goes through {other} ({arm} {self._mm(deepest)} deep{when})"
            else:
                text = f"the planned motion puts {' and '.join(deepest.bodies)} into each other ({self._mm(deepest)} deep{when})"
            if contact.distance >= 0:  # the error's time is that of the first sample closer than the clearance
                text += f", first closer than the clearance of {self.clearance * 1000:g} mm (cell.clearance)"
        return CollisionError(text + where, bodies=contact.bodies, distance=contact.distance, clearance=self.clearance,
                              segment=segment, time=t, configuration=q, field=self.field_of(contact),
                              depth=None if through is None else -through[0].distance,
                              depth_time=None if through is None else through[1], cause=Cause.COLLISION)

    def _segment_text(self, trajectory, t: float, waypoints, word: str = "waypoint") -> str:
        segment = self._segment(trajectory, t, waypoints, word)
        return f" {segment}" if segment else ""

    def _segment(self, trajectory, t: float, waypoints, word: str = "waypoint") -> str | None:
        """"on the way to waypoint k" (0-based, as the scenario's lists count; ``word`` the
        planner's word for its targets, :func:`planner_target_word`) for the time ``t``: the
        first target the tool has not yet passed (its closest approach, taken in order along a
        10 ms grid)."""
        if waypoints is None or not len(waypoints):
            return None
        points = np.asarray(waypoints, dtype=float).reshape(-1, 3)
        grid = np.arange(trajectory.start_time(), trajectory.end_time() + 1e-9, 0.01)
        tool = self.robot.tool_position(trajectory.vector_values(grid).T)
        start = 0
        for k, point in enumerate(points):
            passed = start + int(np.argmin(np.linalg.norm(tool[start:] - point, axis=1)))
            if grid[passed] >= t:
                return f"on the way to {word} {k}"
            start = passed
        return f"after the last {word}"

    def check_planner(self, planner, start_field: Field = ("q_initial",)) -> MotionCheck:
        """:meth:`check_configuration` of the planner's start (errors at ``start_field``), then
        :meth:`check` of its planned reference (``planner.plan()``, a
        :class:`~drake_traj.planners.base.PlannerSystem`) through its task waypoints."""
        if getattr(planner, "needs_cell", False):  # it plans in the cell: its search, timing and this check
            return planner.plan_in(self)
        self.check_configuration(planner.initial_positions(), field=start_field)
        accepted = self.check(planner.plan(), waypoints=planner.task_waypoints(),
                              target_word=planner_target_word(planner))
        planner.checked_scenes.add(self.fingerprint)  # a station of this scene may run it (drake_traj.cell.guard)
        return accepted
