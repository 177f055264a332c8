"""The cell's obstacle shapes and the geometry of Drake's shapes.

An obstacle (in ``cell.obstacles``, posed in the world frame, or a tool shape in
``cell.tool.shapes``, posed in the flange frame) is a subclass of :class:`Obstacle` that gives its
Drake shape (:meth:`Obstacle.shape`) and its outline for the picture of a refusal
(:meth:`Obstacle.outline`); its pose (from ``xyz``, ``rpy``) and its bounding radius (that of its
Drake shape) the base class gives. The shipped ones are
:class:`Box`, :class:`Cylinder` and :class:`Sphere`, read from YAML with the tags ``!Box``,
``!Cylinder`` and ``!Sphere`` (:data:`ObstacleShape`). Adding a shape is one class here, and its
name in :data:`ObstacleShape` for a scenario to give it.

:func:`shape_radius` and :func:`shape_outline` are the bounding radius and the outline of any
Drake shape (the robot's links, the mounting, the models of ``cell.directives``); an unknown
shape is an error, never a default.
"""

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import Union, get_args

import numpy as np
from pydrake.geometry import Box as BoxShape
from pydrake.geometry import Capsule, Convex, Ellipsoid, HalfSpace, Mesh, Shape
from pydrake.geometry import Cylinder as CylinderShape
from pydrake.geometry import Sphere as SphereShape
from pydrake.math import RigidTransform, RollPitchYaw

from drake_traj.errors import Cause, DrakeTrajError, Field, field_text
from drake_traj.validation import real_array

__all__ = ["Box", "Cylinder", "Obstacle", "ObstacleShape", "Sphere", "shape_outline", "shape_radius"]

_CIRCLE = np.linspace(0.0, 2.0 * np.pi, 33)
_RING = np.column_stack([np.cos(_CIRCLE), np.sin(_CIRCLE), np.zeros_like(_CIRCLE)])  # the unit circle in x-y


def field_vector(values, name: Field, size: int, unit: str) -> np.ndarray:
    """``values`` as a finite float vector of ``size`` entries, or DrakeTrajError naming ``name``."""
    label = field_text(name)
    array = real_array(values, label, unit)
    if array.shape != (size,):
        raise DrakeTrajError(f"{label} must have {size} entries [{unit}], got shape {array.shape}", field=name,
                             cause=Cause.INVALID)
    if not np.all(np.isfinite(array)):
        raise DrakeTrajError(f"{label} must be finite, got {np.asarray(values).tolist()}", field=name, cause=Cause.INVALID)
    return array


def field_size(value, name: Field, unit: str = "m") -> float:
    """A finite, positive size, or DrakeTrajError naming ``name``."""
    label = field_text(name)
    number = field_vector([value], name, 1, unit)[0]
    if number <= 0:
        raise DrakeTrajError(f"{label} must be positive [{unit}], got {value}", field=name, cause=Cause.INVALID)
    return float(number)


def field_pose(xyz, rpy, name: Field) -> RigidTransform:
    """The pose of position ``xyz`` [m] and roll-pitch-yaw ``rpy`` [rad] (fields ``name.xyz``,
    ``name.rpy``), or DrakeTrajError naming the one that is malformed."""
    return RigidTransform(RollPitchYaw(field_vector(rpy, name + ("rpy",), 3, "rad")),
                          field_vector(xyz, name + ("xyz",), 3, "m"))


def _box_outline(size) -> list[np.ndarray]:
    """A box's 12 edges [m] about its centre, edge lengths ``size`` [m] along x, y, z."""
    half = 0.5 * np.asarray(size, dtype=float)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
    edges = [(a, b) for a in range(8) for b in range(a + 1, 8) if np.sum(np.abs(corners[a] - corners[b]) > 0) == 1]
    return [corners[[a, b]] for a, b in edges]


def _cylinder_outline(radius: float, length: float, caps: bool = False) -> list[np.ndarray]:
    """A cylinder's (``caps``: a capsule's) end circles and four sides [m] about its centre, its
    axis z; a capsule adds the circles at the tips of its caps."""
    half = 0.5 * length
    lines = [_RING * radius + [0, 0, z] for z in (-half, half)]
    lines += [np.array([[radius * np.cos(a), radius * np.sin(a), -half], [radius * np.cos(a), radius * np.sin(a), half]])
              for a in (0, 0.5 * np.pi, np.pi, 1.5 * np.pi)]
    if caps:
        lines += [_RING * radius + [0, 0, z] for z in (-half - radius, half + radius)]
    return lines


def _sphere_outline(radius: float) -> list[np.ndarray]:
    """A sphere's three great circles [m] about its centre."""
    return [_RING[:, order] * radius for order in ([0, 1, 2], [0, 2, 1], [2, 0, 1])]


def shape_radius(shape: Shape) -> float:
    """The radius [m] of a sphere about the Drake shape's frame origin that contains it;
    TypeError naming a shape it does not know."""
    if isinstance(shape, SphereShape):
        return shape.radius()
    if isinstance(shape, BoxShape):
        return 0.5 * float(np.linalg.norm([shape.width(), shape.depth(), shape.height()]))
    if isinstance(shape, CylinderShape):
        return float(np.hypot(shape.radius(), 0.5 * shape.length()))
    if isinstance(shape, Capsule):
        return shape.radius() + 0.5 * shape.length()
    if isinstance(shape, Ellipsoid):
        return max(shape.a(), shape.b(), shape.c())
    if isinstance(shape, (Mesh, Convex)):  # checked as its convex hull (Drake's): the hull's farthest vertex
        hull = shape.GetConvexHull()
        return max(float(np.linalg.norm(hull.vertex(k))) for k in range(hull.num_vertices()))
    raise TypeError(f"no bounding radius for a {type(shape).__name__} on the robot: use primitive shapes or meshes")


def shape_outline(shape: Shape) -> list[np.ndarray]:
    """Polylines (k, 3) [m] in the Drake shape's frame that outline it: a box's edges, a
    cylinder's or capsule's end circles and four sides, a sphere's three great circles; none for
    the shapes the picture does not draw (meshes, convex hulls, ellipsoids, half spaces);
    TypeError naming any other shape."""
    if isinstance(shape, BoxShape):
        return _box_outline([shape.width(), shape.depth(), shape.height()])
    if isinstance(shape, (CylinderShape, Capsule)):
        return _cylinder_outline(shape.radius(), shape.length(), caps=isinstance(shape, Capsule))
    if isinstance(shape, SphereShape):
        return _sphere_outline(shape.radius())
    if isinstance(shape, (Mesh, Convex, Ellipsoid, HalfSpace)):
        return []
    raise TypeError(f"no outline for a {type(shape).__name__}: the refusal picture draws Drake's Box, Cylinder, "
                    "Capsule and Sphere")


class Obstacle(ABC):
    """An obstacle shape: a subclass is a dataclass with the fields ``name`` (the geometry's name;
    "": one is made up), ``xyz`` [m] and ``rpy`` [rad] (its pose in the frame it is given in: the
    world for ``cell.obstacles``, the flange for ``cell.tool.shapes``; roll-pitch-yaw is Drake's,
    fixed-axis X, Y, Z) and its own sizes, and gives its Drake shape and its outline."""

    @abstractmethod
    def shape(self, name: Field) -> Shape:
        """The Drake shape registered in the plant, about its frame (:meth:`pose`); DrakeTrajError
        naming the field (``name`` + its own) of a malformed size."""

    @abstractmethod
    def outline(self) -> list[np.ndarray]:
        """Polylines (k, 3) [m] in the shape's frame that the picture of a refusal draws."""

    def pose(self, name: Field) -> RigidTransform:
        """The shape's frame in the frame it is given in, from ``xyz`` and ``rpy``; DrakeTrajError
        naming the field (``name.xyz``, ``name.rpy``) that is malformed."""
        return field_pose(self.xyz, self.rpy, name)

    def bounding_radius(self, name: Field) -> float:
        """The radius [m] of a sphere about the shape's frame origin that contains it: that of its
        Drake shape (:func:`shape_radius`)."""
        return shape_radius(self.shape(name))


@dataclass
class Box(Obstacle):
    """A box of edge lengths ``size`` [m] centred at ``xyz`` [m], turned by ``rpy`` [rad] (Drake's
    roll-pitch-yaw: fixed-axis X, Y, Z)."""

    name: str = ""
    size: list[float] = field(default_factory=lambda: [0.1, 0.1, 0.1])
    xyz: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    rpy: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])

    def shape(self, name: Field) -> BoxShape:
        size = field_vector(self.size, name + ("size",), 3, "m")
        return BoxShape(*(field_size(edge, name + ("size", k)) for k, edge in enumerate(size)))

    def outline(self) -> list[np.ndarray]:
        return _box_outline(self.size)


@dataclass
class Cylinder(Obstacle):
    """A cylinder of ``radius`` and ``length`` [m] along its z axis, centred at ``xyz`` [m],
    turned by ``rpy`` [rad]."""

    name: str = ""
    radius: float = 0.05
    length: float = 0.1
    xyz: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    rpy: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])

    def shape(self, name: Field) -> CylinderShape:
        return CylinderShape(field_size(self.radius, name + ("radius",)), field_size(self.length, name + ("length",)))

    def outline(self) -> list[np.ndarray]:
        return _cylinder_outline(float(self.radius), float(self.length))


@dataclass
class Sphere(Obstacle):
    """A sphere of ``radius`` [m] centred at ``xyz`` [m]."""

    name: str = ""
    radius: float = 0.05
    xyz: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    rpy: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])

    def shape(self, name: Field) -> SphereShape:
        return SphereShape(field_size(self.radius, name + ("radius",)))

    def outline(self) -> list[np.ndarray]:
        return _sphere_outline(float(self.radius))


ObstacleShape = Union[Box, Cylinder, Sphere]
"""The obstacle shapes a scenario gives (YAML tags ``!Box``, ``!Cylinder``, ``!Sphere``): the type
of ``cell.obstacles`` and ``cell.tool.shapes`` entries."""


def checked_obstacle(shape, name: Field) -> Obstacle:
    """``shape`` if it is an :class:`Obstacle`, else DrakeTrajError (cause INVALID) at ``name``
    naming it and the shapes there are."""
    if isinstance(shape, Obstacle):
        return shape
    shapes = ", ".join(kind.__name__ for kind in get_args(ObstacleShape))
    raise DrakeTrajError(f"{field_text(name)}: {shape!r:.80} is not an obstacle shape ({shapes}, or a subclass of "
                         "drake_traj.cell.Obstacle)", field=name, cause=Cause.INVALID)
