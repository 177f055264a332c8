"""A compiled collision model of a cell: the free-motion search's distances, 100 times and more
faster than SceneGraph's, with SceneGraph kept as the proof.

:class:`CompiledCollisionModel` reads a :class:`~drake_traj.cell.clearance.CellChecker`'s plant
and SceneGraph once (duck-typed: its ``plant``, ``scene_graph``, ``instance``, ``robot``,
``clearance`` and ``pair_travel()``):

- the kinematic tree of the bodies that carry collision geometry, as data for the compiled
  forward kinematics (:func:`~drake_traj.cell.collision_kernels.link_poses`): each moving body's
  joint (revolute, prismatic or weld: frames on parent and child, axis, position index); bodies
  fixed in the world, and joints of other models at their default positions, as constants;
- every proximity geometry as a convex shape with a support function
  (:mod:`~drake_traj.cell.convex_distance`): Sphere, Capsule, Box, Cylinder, Ellipsoid, and a Mesh
  or Convex as the convex hull of its vertices (Drake's own, ``GetConvexHull()``: what SceneGraph
  checks); any other shape is refused by name (:class:`UnsupportedShapeError`);
- the pairs SceneGraph checks (``GetCollisionCandidates()``: not filtered), less those of two
  geometries fixed in the world.

Every distance it returns is a certified lower bound of max(SceneGraph's signed distance, 0) [m]
(GJK's supporting-plane bound; ``tests/test_compiled_collision.py`` holds it to SceneGraph within
1e-6 m and states how far below it may be). Joint positions q [rad, m for prismatic joints] in the
robot model instance's order (``plant.SetPositions(context, instance, q)``: the checker's), poses in
the world frame (the robot's base frame).
"""

import numpy as np
from pydrake.geometry import Box, Capsule, Convex, Cylinder, Ellipsoid, Mesh, Sphere
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.tree import PrismaticJoint, RevoluteJoint

from drake_traj.cell import collision_kernels as kernels
from drake_traj.cell import convex_distance as convex
from drake_traj.errors import Cause, DrakeTrajError

__all__ = ["CompiledCollisionModel", "DEFAULT_LOOK_AHEAD", "TOLERANCE", "UnsupportedShapeError"]

DEFAULT_LOOK_AHEAD = 0.07
"""[m] how far :meth:`CompiledCollisionModel.distances` and :meth:`~CompiledCollisionModel.pair_distances`
look (the free-motion search's ``LOOK_AHEAD``): a farther distance is reported as this."""

TOLERANCE = 1e-6
"""[m] GJK stops once its upper and lower bounds of a distance are this close: the lower bound
returned is at most this below the true distance where GJK converges (every polytope pair,
and the curved ones within :data:`~drake_traj.cell.convex_distance.MAX_ITERATIONS` steps)."""


class UnsupportedShapeError(DrakeTrajError):
    """A proximity geometry of a shape the compiled model has no support function for (a
    HalfSpace, ...): never ignored. Attributes: ``geometry`` (its name), ``shape`` (its type's name)."""

    def __init__(self, geometry: str, shape: str):
        super().__init__(f"the compiled collision model cannot check the geometry {geometry!r}: a {shape} (it takes "
                         "Sphere, Capsule, Box, Cylinder, Ellipsoid, and Mesh or Convex as their convex hull)",
                         field=(), cause=Cause.INVALID)
        self.geometry, self.shape = geometry, shape


def _row(pose: RigidTransform) -> np.ndarray:
    """A pose as the kernels' row (12,): [R row-major, p]."""
    return np.concatenate([pose.rotation().matrix().ravel(), pose.translation()])


def shape_core(shape, name: str) -> tuple[int, list, float, np.ndarray, np.ndarray]:
    """(core kind, its sizes (3) [m], margin [m], hull vertices (k, 3) [m], a bounding capsule
    [centre (3), half axis (3), radius] [m]) of a Drake shape in its own frame
    (:mod:`~drake_traj.cell.convex_distance`); :class:`UnsupportedShapeError` naming ``name`` for
    any other shape. The capsule holds the whole shape (the segment centre ± half axis, grown by
    the radius): a box's and an ellipsoid's along their longest axis, a hull's along its vertices'
    principal axis with the radius its farthest vertex's distance from the segment."""
    none, zero = np.zeros((0, 3)), np.zeros(3)
    if isinstance(shape, Sphere):
        return convex.POINT, [0.0, 0.0, 0.0], shape.radius(), none, np.r_[zero, zero, shape.radius()]
    if isinstance(shape, (Capsule, Cylinder)):
        half = 0.5 * shape.length()
        kind, margin = (convex.SEGMENT, shape.radius()) if isinstance(shape, Capsule) else (convex.CYLINDER, 0.0)
        size = [half, 0.0, 0.0] if kind == convex.SEGMENT else [shape.radius(), half, 0.0]
        return kind, size, margin, none, np.r_[zero, 0.0, 0.0, half, shape.radius()]
    if isinstance(shape, (Box, Ellipsoid)):
        boxed = isinstance(shape, Box)
        half = 0.5 * np.array([shape.width(), shape.depth(), shape.height()]) if boxed else np.array(
            [shape.a(), shape.b(), shape.c()])
        longest = int(np.argmax(half))
        others = np.delete(half, longest)
        axis = np.zeros(3)
        axis[longest] = half[longest]
        radius = float(np.linalg.norm(others)) if boxed else float(others.max())
        return convex.BOX if boxed else convex.ELLIPSOID, half.tolist(), 0.0, none, np.r_[zero, axis, radius]
    if isinstance(shape, (Mesh, Convex)):  # checked as its convex hull, as SceneGraph does
        hull = shape.GetConvexHull()
        points = np.array([hull.vertex(k) for k in range(hull.num_vertices())], dtype=float).reshape(-1, 3)
        return convex.HULL, [0.0, 0.0, 0.0], 0.0, points, _hull_capsule(points)
    raise UnsupportedShapeError(name, type(shape).__name__)


def _hull_capsule(points: np.ndarray) -> np.ndarray:
    """[centre, half axis, radius] [m] of a capsule holding ``points`` (k, 3): along their principal
    axis, from the least to the largest projection, the radius the farthest point's distance from
    that segment (so it holds them, and their convex hull)."""
    mean = points.mean(axis=0)
    axis = np.linalg.svd(points - mean, full_matrices=False)[2][0]
    along = (points - mean) @ axis
    low, high = along.min(), along.max()
    centre, half = mean + 0.5 * (low + high) * axis, 0.5 * (high - low) * axis
    t = np.clip((points - centre) @ half / max(float(half @ half), 1e-300), -1.0, 1.0)
    radius = float(np.linalg.norm(points - centre - t[:, None] * half, axis=1).max())
    return np.r_[centre, half, radius]


def _world_box(shape, x_wg: RigidTransform, capsule: np.ndarray) -> np.ndarray:
    """Half sizes [m] of a world-aligned box about the (world) capsule centre holding a geometry
    fixed in the world at ``x_wg``: a box's own (Σ_j |R_ij| h_j, exact), else its capsule's
    (|s_W| + r)."""
    if isinstance(shape, Box):
        half = 0.5 * np.array([shape.width(), shape.depth(), shape.height()])
        return np.abs(x_wg.rotation().matrix()) @ half
    return np.abs(x_wg.rotation() @ capsule[3:6]) + capsule[6]


class _Tree:
    """The moving bodies of a finalized plant as the kernels' link tables (module docstring of
    :mod:`~drake_traj.cell.collision_kernels`), from the default context."""

    def __init__(self, plant, instance):
        self.plant, self.context = plant, plant.CreateDefaultContext()
        every = np.arange(plant.num_positions(), dtype=float)
        self.q_index = {int(i): k for k, i in enumerate(plant.GetPositionsFromArray(instance, every))}
        self.inboard = {}
        for index in plant.GetJointIndices():
            joint = plant.get_joint(index)
            self.inboard[int(joint.child_body().index())] = joint
        self.order: list[int] = []  # body indices of the moving links, parents first
        self._moving: dict[int, bool] = {}

    def moving(self, body_index: int) -> bool:
        """Whether the body's pose depends on the robot's joint positions."""
        if body_index not in self._moving:
            joint = self.inboard.get(body_index)
            if joint is None:  # the world, or a body Drake joined to nothing
                self._moving[body_index] = False
            else:
                own = joint.num_positions() > 0 and int(joint.position_start()) in self.q_index
                self._moving[body_index] = own or self.moving(int(joint.parent_body().index()))
        return self._moving[body_index]

    def add(self, body_index: int) -> int:
        """The link row of a moving body (its moving ancestors added first)."""
        if body_index in self.order:
            return self.order.index(body_index)
        parent = int(self.inboard[body_index].parent_body().index())
        if self.moving(parent):
            self.add(parent)
        self.order.append(body_index)
        return len(self.order) - 1

    def tables(self) -> tuple[np.ndarray, np.ndarray]:
        """(links_i (L, 4), links_f (L, 24)) of the links added."""
        links_i = np.zeros((len(self.order), kernels.LINK_INTS), dtype=np.int64)
        links_f = np.zeros((len(self.order), kernels.LINK_FLOATS))
        for k, body_index in enumerate(self.order):
            links_i[k], links_f[k] = self._link(body_index)
        return links_i, links_f

    def _link(self, body_index: int) -> tuple[list, np.ndarray]:
        """One link's row (:func:`~drake_traj.cell.collision_kernels.link_poses`): X_WB = X_WP X_PF
        X_FM(q) X_MB (Drake's joint frames F on the parent, M on the child), the joint's axis turned
        onto z; a fixed parent's pose folded into X_PF', a weld's (or another model's joint's, at
        its default position) X_FM X_MB too."""
        plant, joint = self.plant, self.inboard[body_index]
        parent = joint.parent_body()
        x_pf = joint.frame_on_parent().GetFixedPoseInBodyFrame()
        x_mb = joint.frame_on_child().GetFixedPoseInBodyFrame().inverse()
        parent_row = self.order.index(int(parent.index())) if self.moving(int(parent.index())) else -1
        if parent_row < 0:
            x_pf = plant.EvalBodyPoseInWorld(self.context, parent) @ x_pf
        own = joint.num_positions() > 0 and int(joint.position_start()) in self.q_index
        if not own:
            kind = kernels.FIXED
            x_pf = x_pf @ joint.frame_on_child().CalcPose(self.context, joint.frame_on_parent()) @ x_mb
            x_mb = RigidTransform()
        elif isinstance(joint, (RevoluteJoint, PrismaticJoint)):
            revolute = isinstance(joint, RevoluteJoint)
            kind = kernels.REVOLUTE if revolute else kernels.PRISMATIC
            turn = RigidTransform(_z_onto(joint.revolute_axis() if revolute else joint.translation_axis()), np.zeros(3))
            x_pf, x_mb = x_pf @ turn, turn.inverse() @ x_mb
        else:
            raise DrakeTrajError(f"the compiled collision model takes revolute, prismatic and weld joints on the robot, "
                                 f"not the {joint.type_name()} joint {joint.name()!r}", field=("robot",),
                                 cause=Cause.INVALID)
        position = self.q_index[int(joint.position_start())] if own else 0
        moved = not np.array_equal(x_mb.GetAsMatrix34(), np.eye(4)[:3])
        return [parent_row, kind, position, int(moved)], np.concatenate([_row(x_pf), _row(x_mb)])


def _z_onto(axis) -> RotationMatrix:
    """A rotation A with A z = ``axis`` (a unit vector): the identity for z itself."""
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    if np.array_equal(axis, [0.0, 0.0, 1.0]):
        return RotationMatrix()
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, axis)
    x /= np.linalg.norm(x)
    return RotationMatrix(np.column_stack([x, np.cross(axis, x), axis]))


class CompiledCollisionModel:
    """The robot, its tool and its cell as compiled collision data (module docstring).

    Args:
        checker: the cell check of the robot in its cell (a :class:`~drake_traj.cell.clearance.CellChecker`).
        look_ahead: [m] how far :meth:`distances` and :meth:`pair_distances` look (:data:`DEFAULT_LOOK_AHEAD`).
        tolerance: [m] GJK's stopping gap (:data:`TOLERANCE`).

    Attributes: ``clearance`` [m] (the checker's), ``lower``, ``upper`` (n,) the joint ranges,
    ``bodies`` the BodyIndex of each moving link row (:meth:`body_poses`), ``geometries`` the
    GeometryId of each geometry row, ``pairs`` (P, 4) [geometry a, geometry b, link a, link b] rows.
    """

    def __init__(self, checker, *, look_ahead: float = DEFAULT_LOOK_AHEAD, tolerance: float = TOLERANCE):
        self.clearance, self.look_ahead, self.tolerance = float(checker.clearance), float(look_ahead), float(tolerance)
        robot = checker.robot
        self.lower = np.ascontiguousarray(robot.lower_limits, dtype=float)
        self.upper = np.ascontiguousarray(robot.upper_limits, dtype=float)
        plant, inspector = checker.plant, checker.scene_graph.model_inspector()
        self.n = plant.num_positions(checker.instance)
        self.pair_travel, links = checker.pair_travel()
        tree = _Tree(plant, checker.instance)
        candidates = [(a, b) for a, b in inspector.GetCollisionCandidates()]
        body_of = {g: int(plant.GetBodyFromFrameId(inspector.GetFrameId(g)).index()) for pair in candidates for g in pair}
        candidates = [(a, b) for a, b in candidates if tree.moving(body_of[a]) or tree.moving(body_of[b])]
        self.geometries = sorted({g for pair in candidates for g in pair}, key=lambda g: g.get_value())
        rows = {g: k for k, g in enumerate(self.geometries)}
        for g in self.geometries:  # every moving link, parents first, before the geometry tables
            if tree.moving(body_of[g]):
                tree.add(body_of[g])
        self.links_i, self.links_f = tree.tables()
        self.bodies = list(tree.order)
        self.geo_i, self.geo_f, self.vertices = self._geometry_tables(plant, inspector, tree, body_of)
        self.pairs = np.zeros((len(candidates), 4), dtype=np.int64)
        for p, (a, b) in enumerate(sorted(candidates, key=lambda pair: (rows[pair[0]], rows[pair[1]]))):
            for g in (a, b):
                if tree.moving(body_of[g]) and g not in links:
                    raise DrakeTrajError(f"the geometry {inspector.GetName(g)!r} moves with the arm but on no link of its "
                                         "chain (a joint of its own): the travel bounds do not cover it",
                                         field=("cell",), cause=Cause.INVALID)
            self.pairs[p] = [rows[a], rows[b], links.get(a, 0), links.get(b, 0)]
        self.model = (self.links_i, self.links_f, self.geo_i, self.geo_f, self.vertices, self.pairs)

    def _geometry_tables(self, plant, inspector, tree, body_of) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(geo_i (G, 4), geo_f (G, 27), vertices (V, 3)) of :attr:`geometries`
        (:mod:`~drake_traj.cell.convex_distance`'s layout): X_BG, the bounding capsule in B (for a
        geometry fixed in the world, X_WG and the capsule in the world)."""
        geo_i = np.zeros((len(self.geometries), 4), dtype=np.int64)
        geo_f = np.zeros((len(self.geometries), convex.GEOMETRY_FLOATS))
        vertices = []
        start = 0
        for k, g in enumerate(self.geometries):
            kind, size, margin, points, capsule = shape_core(inspector.GetShape(g), inspector.GetName(g))
            x_bg = inspector.GetPoseInFrame(g)
            row = tree.order.index(body_of[g]) if tree.moving(body_of[g]) else -1
            if row < 0:
                x_bg = plant.EvalBodyPoseInWorld(tree.context, plant.GetBodyFromFrameId(inspector.GetFrameId(g))) @ x_bg
            geo_i[k] = [kind, row, start, len(points)]
            geo_f[k, convex.X_BG:convex.X_BG + 12] = _row(x_bg)
            geo_f[k, convex.SIZE:convex.SIZE + 3] = size
            geo_f[k, convex.MARGIN] = margin
            geo_f[k, convex.CAPSULE:convex.CAPSULE + 3] = x_bg @ capsule[:3]
            geo_f[k, convex.CAPSULE + 3:convex.CAPSULE + 6] = x_bg.rotation() @ capsule[3:6]
            geo_f[k, convex.CAPSULE_RADIUS] = capsule[6]
            geo_f[k, convex.RADIUS] = float(np.linalg.norm(capsule[3:6])) + capsule[6]
            if row < 0:  # fixed in the world: the world-aligned box about the capsule's centre
                geo_f[k, convex.AABB:convex.AABB + 3] = _world_box(inspector.GetShape(g), x_bg, capsule)
            vertices.append(points)
            start += len(points)
        return geo_i, geo_f, np.ascontiguousarray(np.concatenate(vertices + [np.zeros((1, 3))]))

    def _configurations(self, q) -> tuple[np.ndarray, bool]:
        """(q as a contiguous (m, n) float array, whether one configuration was given)."""
        array = np.asarray(q, dtype=float)
        single = array.ndim == 1
        array = np.ascontiguousarray(array.reshape(-1, self.n) if single else array)
        if array.ndim != 2 or array.shape[1] != self.n:
            raise ValueError(f"configurations must have shape (m, {self.n}) [rad], got {np.shape(q)}")
        return array, single

    def body_poses(self, q) -> np.ndarray:
        """X_WB (L, 4, 4) of each moving link (:attr:`bodies`) at one configuration ``q`` (n,)."""
        configuration, _ = self._configurations(q)
        rows = np.empty((len(self.bodies) + 1, 12))
        kernels.link_poses(configuration[0], self.links_i, self.links_f, rows)
        rows = rows[:-1]
        poses = np.tile(np.eye(4), (len(self.bodies), 1, 1))
        poses[:, :3, :3] = rows[:, :9].reshape(-1, 3, 3)
        poses[:, :3, 3] = rows[:, 9:]
        return poses

    def distances(self, q):
        """The smallest distance [m] between two checked geometries of each configuration of ``q``
        (m, n) [rad] (a float for one configuration (n,)), at most :attr:`look_ahead`; 0 where two
        touch or overlap. A lower bound of SceneGraph's (module docstring)."""
        configurations, single = self._configurations(q)
        out = np.empty(len(configurations))
        kernels.distances_many(configurations, self.model, self.look_ahead, self.tolerance, out)
        return float(out[0]) if single else out

    def near_pairs(self, q) -> tuple[np.ndarray, np.ndarray]:
        """(distances [m], rows of :attr:`pairs`) of the pairs closer than :attr:`look_ahead` at one
        configuration ``q`` (n,) [rad]."""
        configuration, _ = self._configurations(q)
        distances = np.empty(len(self.pairs))
        indices = np.empty(len(self.pairs), dtype=np.int64)
        count = kernels.pair_distances_into(configuration[0], self.model, self.look_ahead, self.tolerance, distances,
                                            indices)
        return distances[:count], indices[:count]

    def pair_distances(self, q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(distances [m], link a, link b) of the pairs closer than :attr:`look_ahead` at one
        configuration ``q`` (n,) [rad] (:meth:`near_pairs`); the links are
        :func:`~drake_traj.cell.clearance.link_reach`'s (0 the base and the world), as the
        conservative advancements need them."""
        distances, chosen = self.near_pairs(q)
        return distances, self.pairs[chosen, 2], self.pairs[chosen, 3]

    def valid(self, q):
        """Per configuration of ``q`` (m, n) [rad] (a bool for one (n,)): inside the joint ranges
        and no two checked geometries closer than the clearance (nor touching at a clearance of 0)."""
        configurations, single = self._configurations(q)
        out = np.empty(len(configurations), dtype=np.bool_)
        kernels.valid_many(configurations, self.lower, self.upper, self.model, self.clearance, self.tolerance, out)
        return bool(out[0]) if single else out

    def segment_valid(self, a, b) -> bool:
        """Whether the straight joint segment from ``a`` to ``b`` (n,) [rad] keeps the clearance c at
        every configuration checked and c/2 between them, by the free-motion search's conservative
        advancement per pair of links, compiled (:func:`~drake_traj.cell.collision_kernels.segment_valid`)."""
        start, _ = self._configurations(a)
        end, _ = self._configurations(b)
        return bool(kernels.segment_valid(start[0], end[0], self.lower, self.upper, self.model, self.pair_travel,
                                          self.clearance, self.tolerance))

    def pair_bounds(self, q) -> np.ndarray:
        """(P, 2) [m]: every pair's (lower, upper) distance bounds at one configuration ``q`` (n,),
        GJK run to :attr:`tolerance` (no broad phase): the upper bound is the distance of two
        points of the two shapes (at most 0 for touching or overlapping shapes), a witness of how
        far apart they are at most."""
        configuration, _ = self._configurations(q)
        out = np.empty((len(self.pairs), 2))
        kernels.pair_bounds_into(configuration[0], self.model, self.tolerance, out)
        return out
