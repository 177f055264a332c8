"""Is a planned motion possible in the cell? Joint ranges, self-collision and collision with the
cell, checked on the planned reference before the arm moves.

:class:`CellChecker` holds a plant of its own with the robot, its tool and its cell
(:func:`drake_traj.cell.add_cell`: the same geometry as the simulated station) and asks Drake's
SceneGraph for signed distances (``ComputeSignedDistancePairwiseClosestPoints``) between every
pair of collision geometries that Drake does not filter: the arm's non-adjacent links, the tool
and the cell (bodies joined by a joint, and everything welded to the world, are filtered by the
plant; the robot model may declare more, with its reasons, in its URDF).

Sampling (:meth:`CellChecker.sample_times`). No point of the arm moves faster than
``Σ_j |q̇_j| R_j``, where ``R_j`` bounds the distance of any collision geometry outboard of joint
j from that joint's axis (:func:`joint_reach`, from the plant's fixed joint and geometry poses:
for a serial chain R_j = max(geometry of link j, |offset to joint j+1| + R_{j+1})). The samples
are spaced so that this bound integrates to at most ``spacing`` between neighbours; between two
samples every point is then within ``spacing / 2`` of where it was at the nearer one, and a
signed distance (1-Lipschitz in each body's displacement) is at least the sampled one minus
``spacing`` (both bodies moving) or minus ``spacing / 2`` (arm against the cell). With the
default ``spacing = clearance / 2``, a motion accepted at ``clearance`` keeps at least
``clearance / 2`` everywhere between the samples.
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydrake.geometry import Box, Capsule, Cylinder, Ellipsoid, Sphere
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder
from pydrake.trajectories import Trajectory

from drake_traj.cell import Cell, add_cell
from drake_traj.errors import Cause, Field, PlanningError, joint_label
from drake_traj.robots import Robot

__all__ = ["CellChecker", "CollisionError", "Contact", "JointRangeError", "MotionCheck", "geometry_owner", "joint_reach"]

RANGE_GRID = 1e-3  # [s] joint ranges are checked at the log's period


class CollisionError(PlanningError):
    """The planned motion brings two bodies closer than the clearance (or into contact).

    Attributes (besides :class:`PlanningError`'s):
        bodies: the two bodies' names, e.g. ``("forearm_link", "table")``.
        distance: their signed distance [m] (negative: penetration).
        clearance: the clearance asked for [m].
        segment: which part of the task, e.g. ``"on the way to waypoint 2"`` (None if unknown).
    """

    default_cause = Cause.COLLISION

    def __init__(self, message: str, *, bodies, distance: float, clearance: float, segment=None, **kwargs):
        super().__init__(message, **kwargs)
        self.bodies, self.distance, self.clearance, self.segment = tuple(bodies), float(distance), float(clearance), segment


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
    geometries (the cell's geometry names an obstacle, the mounting or a tool shape) and their
    closest points (2, 3) [m] in the world (base) frame."""

    distance: float
    bodies: tuple[str, str]
    geometries: tuple[str, str]
    points: np.ndarray


def _bounding_radius(shape) -> float:
    """The radius [m] of a sphere about the shape's frame origin that contains it."""
    if isinstance(shape, Sphere):
        return shape.radius()
    if isinstance(shape, Box):
        return 0.5 * float(np.linalg.norm([shape.width(), shape.depth(), shape.height()]))
    if isinstance(shape, Cylinder):
        return float(np.hypot(shape.radius(), 0.5 * shape.length()))
    if isinstance(shape, Capsule):
        return shape.radius() + 0.5 * shape.length()
    if isinstance(shape, Ellipsoid):
        return max(shape.a(), shape.b(), shape.c())
    raise TypeError(f"no bounding radius for a {type(shape).__name__} on the robot: use primitive shapes")


def joint_reach(plant, scene_graph, plant_context, instance, joint_names) -> np.ndarray:
    """R_j [m] per joint of a serial chain: a bound on the distance of any collision geometry
    outboard of joint j (on its child link or on bodies welded to it, such as the tool) from
    joint j's origin, which lies on its axis; 1 for a prismatic joint (a point moves at |q̇_j|).
    Poses are fixed in each link, so any ``plant_context`` gives them."""
    inspector = scene_graph.model_inspector()
    joints = [plant.GetJointByName(name, instance) for name in joint_names]
    reach = np.zeros(len(joints))
    outboard = 0.0  # R_{j+1}, added to the offset from joint j to joint j+1
    for j in reversed(range(len(joints))):
        joint = joints[j]
        origin = joint.frame_on_child().CalcPoseInWorld(plant_context)
        link = joint.child_body()
        bound = 0.0
        for body in plant.GetBodiesWeldedTo(link):
            X_OB = origin.InvertAndCompose(body.body_frame().CalcPoseInWorld(plant_context))
            for geometry in plant.GetCollisionGeometriesForBody(body):
                X_OG = X_OB @ inspector.GetPoseInFrame(geometry)
                bound = max(bound, float(np.linalg.norm(X_OG.translation())) + _bounding_radius(inspector.GetShape(geometry)))
        if j + 1 < len(joints):
            following = joints[j + 1]
            offset = origin.InvertAndCompose(following.frame_on_parent().CalcPoseInWorld(plant_context)).translation()
            stroke = (max(abs(following.position_lower_limits()[0]), abs(following.position_upper_limits()[0]))
                      if following.type_name() == "prismatic" else 0.0)
            bound = max(bound, float(np.linalg.norm(offset)) + stroke + outboard)
        reach[j] = 1.0 if joint.type_name() == "prismatic" else bound
        outboard = bound
    return reach


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
    """Times [s] spanning ``trajectory`` at :data:`RANGE_GRID` (at least its two ends)."""
    start, end = trajectory.start_time(), trajectory.end_time()
    return np.linspace(start, end, max(2, int(np.ceil((end - start) / RANGE_GRID)) + 1))


@dataclass(frozen=True)
class MotionCheck:
    """An accepted motion: the configurations checked at its sample times [s], and the bound
    [m] on any point's travel between two of them."""

    times: np.ndarray
    spacing: float


class CellChecker:
    """Signed distances between the robot (with its tool) and itself and its cell.

    Args:
        robot: the robot; its model, as the station adds it.
        cell: the cell (default: :class:`~drake_traj.cell.Cell`, a table flush with the base).
        directory: the folder relative model files of ``cell.directives`` are taken from.
    """

    def __init__(self, robot: Robot, cell: Cell | None = None, directory: Path | None = None):
        self.robot = robot
        self.cell = cell or Cell()
        builder = DiagramBuilder()
        self.plant, self.scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
        self.instance = robot.add_to_plant(self.plant)
        self.cell_fields = add_cell(self.plant, self.cell, self.instance, robot=robot,
                                    directory=directory)
        self.plant.Finalize()
        self._diagram = builder.Build()
        self._context = self._diagram.CreateDefaultContext()
        self._plant_context = self.plant.GetMyMutableContextFromRoot(self._context)
        self._query = self.scene_graph.get_query_output_port()
        self._scene_context = self.scene_graph.GetMyContextFromRoot(self._context)
        self._inspector = self.scene_graph.model_inspector()
        self.reach = joint_reach(self.plant, self.scene_graph, self._plant_context, self.instance, robot.joint_names)

    @property
    def clearance(self) -> float:
        """The cell's clearance [m]."""
        return float(self.cell.clearance)

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
                nearest[key] = Contact(pair.distance, (body_a, body_b), (geometry_a, geometry_b), points)
        return sorted(nearest.values(), key=lambda contact: contact.distance)

    def sample_times(self, trajectory: Trajectory, spacing: float | None = None, *, grid=None, q=None) -> np.ndarray:
        """Times [s] at which to check ``trajectory`` (q(t)) so that no point of the arm moves
        more than ``spacing`` [m] (default half the clearance, at least 1 mm) between two
        samples (module docstring). The speed bound is integrated on a 1 ms grid, each step's
        |Δq_j| standing for ∫|q̇_j| dt (exact where no joint turns back inside the millisecond;
        a 10 % margin covers the rest). ``grid`` and ``q`` (the trajectory on it) when known."""
        spacing = self.default_spacing() if spacing is None else float(spacing)
        grid = _grid(trajectory) if grid is None else grid
        q = trajectory.vector_values(grid).T if q is None else q
        travel = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(q, axis=0)) @ self.reach)]) * 1.1
        count = int(np.ceil(travel[-1] / spacing))
        times = np.interp(np.linspace(0.0, travel[-1], count + 1), travel, grid) if count else grid[:1]
        return np.unique(np.concatenate([times, grid[[0, -1]]]))

    def check(self, trajectory: Trajectory, *, waypoints=None, spacing: float | None = None) -> MotionCheck:
        """Check the joint reference ``trajectory`` (a Drake Trajectory of q(t), e.g.
        ``planner.plan()``): every joint inside its range on a 1 ms grid, then no two bodies
        closer than the clearance at :meth:`sample_times`.

        ``waypoints`` (m, 3) [m], the task's tool points in order, name the segment of a
        collision ("on the way to waypoint k"). Raises :class:`JointRangeError` or
        :class:`CollisionError` (time, bodies, distance, segment, configuration) for the first
        sample that is too close; returns a :class:`MotionCheck`."""
        grid = _grid(trajectory)
        q = trajectory.vector_values(grid).T
        lower, upper = self.robot.lower_limits, self.robot.upper_limits
        outside = (q < lower) | (q > upper)
        if outside.any():
            k, j = np.argwhere(outside)[0]
            limit = lower[j] if q[k, j] < lower[j] else upper[j]
            unit = self.robot.joint_unit(j)
            raise JointRangeError(
                f"the planned motion takes {joint_label(j, self.robot.joint_names)} to {q[k, j]:.4f} {unit}, past its "
                f"range [{lower[j]:.4f}, {upper[j]:.4f}] {unit}{self._segment_text(trajectory, grid[k], waypoints)}",
                joint=j, value=q[k, j], limit=limit, time=grid[k], configuration=q[k], cause=Cause.JOINT_RANGE)
        spacing = self.default_spacing() if spacing is None else float(spacing)
        times = self.sample_times(trajectory, spacing, grid=grid, q=q)
        for t, q_t in zip(times, trajectory.vector_values(times).T):
            contacts = self.contacts(q_t)
            if contacts:
                raise self._collision(contacts[0], t, q_t, trajectory, waypoints)
        return MotionCheck(times, spacing)

    def default_spacing(self) -> float:
        """Half the clearance, at least 1 mm [m] (module docstring)."""
        return max(0.5 * self.clearance, 1e-3)

    def check_configuration(self, q, what: str = "the start configuration", field: Field = ("q_initial",)) -> None:
        """CollisionError (naming the two bodies, at ``field``) when ``q`` is in contact or
        closer than the clearance."""
        contacts = self.contacts(q)
        if contacts:
            contact = contacts[0]
            raise CollisionError(f"{what} {self._describe(contact)}", bodies=contact.bodies, distance=contact.distance,
                                 clearance=self.clearance, time=0.0, configuration=q, field=field, cause=Cause.COLLISION)

    def field_of(self, contact: Contact) -> Field:
        """The scenario field of the cell geometry in ``contact`` (an obstacle, the mounting, a
        tool shape), or () when both bodies are the arm's."""
        for geometry in contact.geometries:
            if geometry in self.cell_fields:
                return self.cell_fields[geometry]
        return ()

    def _describe(self, contact: Contact) -> str:
        a, b = contact.bodies
        if contact.distance < 0:
            return f"puts {a} and {b} into each other ({-contact.distance * 1000:.1f} mm deep)"
        return (f"brings {a} and {b} within {contact.distance * 1000:.1f} mm of each other, closer than the clearance "
                f"of {self.clearance * 1000:g} mm (cell.clearance)")

    def _collision(self, contact: Contact, t: float, q, trajectory, waypoints) -> CollisionError:
        segment = self._segment(trajectory, t, waypoints)
        where = f" {segment}" if segment else ""
        return CollisionError(f"the planned motion {self._describe(contact)} at t = {t:.3f} s{where}",
                              bodies=contact.bodies, distance=contact.distance, clearance=self.clearance,
                              segment=segment, time=t, configuration=q, field=self.field_of(contact),
                              cause=Cause.COLLISION)

    def _segment_text(self, trajectory, t: float, waypoints) -> str:
        segment = self._segment(trajectory, t, waypoints)
        return f" {segment}" if segment else ""

    def _segment(self, trajectory, t: float, waypoints) -> str | None:
        """"on the way to waypoint k" (0-based, as the scenario's lists count) for the time
        ``t``: the first waypoint the tool has not yet passed (its closest approach, taken in
        order along a 10 ms grid)."""
        if waypoints is None or not len(waypoints):
            return None
        points = np.asarray(waypoints, dtype=float).reshape(-1, 3)
        grid = np.arange(trajectory.start_time(), trajectory.end_time() + 1e-9, 0.01)
        tool = self.robot.tool_position(trajectory.vector_values(grid).T)
        start = 0
        for k, point in enumerate(points):
            passed = start + int(np.argmin(np.linalg.norm(tool[start:] - point, axis=1)))
            if grid[passed] >= t:
                return f"on the way to waypoint {k}"
            start = passed
        return "after the last waypoint"

    def check_planner(self, planner, start_field: Field = ("q_initial",)) -> MotionCheck:
        """:meth:`check_configuration` of the planner's start (errors at ``start_field``), then
        :meth:`check` of its planned reference (``planner.plan()``, a
        :class:`~drake_traj.planners.base.PlannerSystem`) through its task waypoints."""
        self.check_configuration(planner.initial_positions(), field=start_field)
        return self.check(planner.plan(), waypoints=planner.task_waypoints())
