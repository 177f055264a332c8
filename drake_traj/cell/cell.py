"""The robot's cell: what it is mounted on, the obstacles around it, the user's own models, and
its tool (TCP offset, collision shape, payload), as scenario data and as geometry in a plant.

A :class:`Cell` is the ``cell:`` section of a scenario (read with pydrake's ``yaml_load_typed``)::

    cell:
      mounting: !Table {size: [2.8, 2.8, 0.05]}     # or !Pedestal {radius: 0.1, height: 0.6}, or !NoMounting {}
      obstacles:
      - !Box {name: fixture, size: [0.3, 0.2, 0.25], xyz: [0.6, -0.4, 0.125]}
      directives:                                   # Drake's ModelDirectives; files relative to the scenario
      - add_model: {name: bin, file: models/bin.sdf}
      - add_weld: {parent: world, child: bin::base}
      tool:
        tcp_xyz: [0, 0, 0.15]
        shapes: [!Cylinder {radius: 0.04, length: 0.15, xyz: [0, 0, 0.075]}]
        mass: 2.0
        center_of_mass: [0, 0, 0.06]
      clearance: 0.01

Frames: the world frame is the robot's base frame (the UR10e's DH frame 0, z up; the base stands
on z = 0). Obstacles and the mounting are posed in it; the tool's shapes, TCP and centre of
mass in the flange frame (``tool0``). :func:`add_cell` registers all of it in a
``MultibodyPlant`` before it is finalized: the same geometry serves the check before the motion
(:mod:`drake_traj.cell.clearance`) and the contact of the simulated arm (:mod:`drake_traj.station`).
The obstacle shapes are :mod:`drake_traj.cell.shapes`'s, the directives are checked and added
by :mod:`drake_traj.cell.directives`.
"""

from dataclasses import dataclass, field
from pathlib import Path
from typing import Union

import numpy as np
from pydrake.geometry import Box as BoxShape
from pydrake.geometry import Cylinder as CylinderShape
from pydrake.geometry import AddContactMaterial, ProximityProperties, Rgba
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.parsing import ModelDirective
from pydrake.multibody.plant import CoulombFriction, MultibodyPlant
from pydrake.multibody.tree import RotationalInertia, SpatialInertia

from drake_traj.cell.directives import add_directives, package_folders
from drake_traj.cell.shapes import ObstacleShape, checked_obstacle, field_size, field_vector
from drake_traj.errors import Cause, DrakeTrajError, Field
from drake_traj.robots import UR10E, PointRobot, Robot
from drake_traj.validation import invalid

__all__ = [
    "Cell", "DEFAULT_CLEARANCE", "NoMounting", "Pedestal", "Table", "Tool", "add_cell",
]

# [m] The clearance a planned motion keeps from the cell and from the arm itself. The collision
# shapes already contain the real links (docs/ur10e.md), the check samples the reference so that
# no point moves more than half the clearance between samples (so at least 5 mm is guaranteed
# between them), and the shipped scenarios track their reference within 0.13 mm (tolerance 5 mm).
DEFAULT_CLEARANCE = 0.01
TABLE_TOP_SIZE = (2.8, 2.8)  # [m] covers the UR10e's 1.3 m reach on every side of the base
OBSTACLE_COLOUR = Rgba(0.55, 0.45, 0.35, 1.0)
MOUNTING_COLOUR = Rgba(0.62, 0.62, 0.6, 1.0)
TOOL_COLOUR = Rgba(0.3, 0.3, 0.3, 1.0)
TOOL_BODY = "tool"  # the body welded to the flange that carries the tool's shapes and payload


_MOUNTING = ("cell", "mounting")  # the field of the mounting's errors


@dataclass
class Table:
    """A table top flush with the robot's base: its top face is z = 0, ``size`` = [length x,
    width y, thickness] [m], centred on the base."""

    size: list[float] = field(default_factory=lambda: [*TABLE_TOP_SIZE, 0.05])

    def shapes(self) -> list[tuple[str, object, RigidTransform]]:
        """(name, Drake shape, pose in the world) of the table top; its top is z = 0."""
        length, width, thickness = field_vector(self.size, _MOUNTING + ("size",), 3, "m")
        for k, edge in enumerate((length, width, thickness)):
            field_size(edge, _MOUNTING + ("size", k))
        return [("table", BoxShape(length, width, thickness), RigidTransform([0.0, 0.0, -0.5 * thickness]))]


@dataclass
class Pedestal:
    """A cylindrical pedestal of ``radius`` [m] under the base, ``height`` [m] tall, standing on a
    floor (z = -height) of ``floor_size`` [m] (x, y)."""

    radius: float = 0.1
    height: float = 0.6
    floor_size: list[float] = field(default_factory=lambda: list(TABLE_TOP_SIZE))

    def shapes(self) -> list[tuple[str, object, RigidTransform]]:
        """(name, Drake shape, pose in the world) of the pedestal and the floor; the pedestal's top is z = 0."""
        radius, height = field_size(self.radius, _MOUNTING + ("radius",)), field_size(self.height, _MOUNTING + ("height",))
        length, width = field_vector(self.floor_size, _MOUNTING + ("floor_size",), 2, "m")
        for k, edge in enumerate((length, width)):
            field_size(edge, _MOUNTING + ("floor_size", k))
        floor_thickness = 0.05
        return [("pedestal", CylinderShape(radius, height), RigidTransform([0.0, 0.0, -0.5 * height])),
                ("floor", BoxShape(length, width, floor_thickness),
                 RigidTransform([0.0, 0.0, -height - 0.5 * floor_thickness]))]


@dataclass
class NoMounting:
    """Nothing under or around the base (the papers' free-standing arm)."""

    def shapes(self) -> list[tuple[str, object, RigidTransform]]:
        """No shapes."""
        return []


Mounting = Union[Table, Pedestal, NoMounting]


@dataclass
class Tool:
    """The tool on the flange (frame ``tool0``), as UR's ``set_tcp`` and ``set_payload`` give it.

    Attributes:
        tcp_xyz: the tool centre point in the flange frame [m]; every task pose is the TCP's.
        tcp_rpy: the TCP frame's roll-pitch-yaw in the flange frame [rad].
        shapes: the tool's collision shapes, posed in the flange frame.
        mass: the payload [kg] (tool and workpiece), at most the robot's rated payload
            (:attr:`Robot.rated_payload <drake_traj.robots.base.Robot.rated_payload>`: the
            UR10e's 12.5 kg).
        center_of_mass: the payload's centre of mass in the flange frame [m].
        inertia: the payload's rotational inertia about its centre of mass, [Ixx, Iyy, Izz, Ixy,
            Ixz, Iyz] [kg m²] in the flange frame; empty: a point mass.
    """

    tcp_xyz: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    tcp_rpy: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    shapes: list[ObstacleShape] = field(default_factory=list)
    mass: float = 0.0
    center_of_mass: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    inertia: list[float] = field(default_factory=list)

    def tcp(self) -> RigidTransform:
        """X_FT: the TCP frame in the flange frame; DrakeTrajError naming the field if not finite."""
        return RigidTransform(RollPitchYaw(field_vector(self.tcp_rpy, ("cell", "tool", "tcp_rpy"), 3, "rad")),
                              field_vector(self.tcp_xyz, ("cell", "tool", "tcp_xyz"), 3, "m"))

    def extent(self) -> float:
        """The radius [m] about the flange origin that holds the TCP and every tool shape."""
        reach = [float(np.linalg.norm(self.tcp_xyz))]
        for index, shape in enumerate(self.shapes):
            reach.append(float(np.linalg.norm(shape.xyz)) + shape.bounding_radius(("cell", "tool", "shapes", index)))
        return max(reach)

    def spatial_inertia(self) -> SpatialInertia | None:
        """The payload about the flange origin, in the flange frame (None without a payload)."""
        mass = field_vector([self.mass], ("cell", "tool", "mass"), 1, "kg")[0]
        if mass < 0:
            raise invalid("cell.tool.mass", f"cell.tool.mass must be >= 0 kg, got {self.mass}")
        com = field_vector(self.center_of_mass, ("cell", "tool", "center_of_mass"), 3, "m")
        if mass == 0:
            return None
        extent = self.extent()
        if np.linalg.norm(com) > extent + 1e-9:
            raise DrakeTrajError(
                f"cell.tool.center_of_mass {com.tolist()} m is {np.linalg.norm(com):.3f} m from the flange, beyond the "
                f"tool (its TCP and shapes reach {extent:.3f} m): give the tool's shapes or its TCP, or the payload's "
                "real centre of mass", field=("cell", "tool", "center_of_mass"), cause=Cause.INFEASIBLE)
        if not len(self.inertia):  # a point mass: welded to the flange, the arm's inertia stays valid
            return SpatialInertia.MakeFromCentralInertia(mass, com, RotationalInertia(0.0, 0.0, 0.0))
        moments = field_vector(self.inertia, ("cell", "tool", "inertia"), 6, "kg m^2")
        rotational = RotationalInertia(*moments)
        if not rotational.CouldBePhysicallyValid():
            raise DrakeTrajError(f"cell.tool.inertia {moments.tolist()} kg m^2 is not a physical inertia (its moments "
                                 "must be positive and satisfy the triangle inequality)", field=("cell", "tool", "inertia"),
                                 cause=Cause.INVALID)
        return SpatialInertia.MakeFromCentralInertia(mass, com, rotational)

    def check_payload(self, robot: Robot) -> None:
        """Refuse a ``mass`` above ``robot``'s rated payload (field ``cell.tool.mass``, naming the
        robot and its rating). A robot with no rating takes no payload unless it is a point
        robot of the papers (no maker rates them; their tool is a point)."""
        mass = field_vector([self.mass], ("cell", "tool", "mass"), 1, "kg")[0]
        rating = robot.rated_payload
        if rating is None and (mass == 0 or isinstance(robot, PointRobot)):
            return
        if rating is None:
            raise DrakeTrajError(f"cell.tool.mass = {mass:g} kg: the {robot.name} robot has no rated payload, so it takes "
                                 "no tool mass (give the arm's rated payload)", field=("cell", "tool", "mass"),
                                 cause=Cause.INFEASIBLE)
        if mass > rating:
            raise DrakeTrajError(f"cell.tool.mass = {mass:g} kg is above the {robot.name} robot's rated payload of "
                                 f"{rating:g} kg", field=("cell", "tool", "mass"), cause=Cause.INFEASIBLE)


@dataclass
class Cell:
    """The robot's cell (see the module docstring). The default is a table flush with the base,
    no obstacles and no tool: every shipped scenario runs in it unchanged.

    Attributes:
        mounting: ``!Table`` (default), ``!Pedestal`` or ``!NoMounting``.
        obstacles: boxes, cylinders and spheres (:class:`~drake_traj.cell.shapes.Obstacle`)
            posed in the world (base) frame.
        directives: Drake ``ModelDirective``s (``add_model``, ``add_weld``, ...) for the user's own
            model files; a relative ``file`` is taken from the scenario file's folder. Offline
            only: a ``package://`` URL resolves through ``packages`` and ``ROS_PACKAGE_PATH``.
        packages: {package name: folder} for the directives' ``package://`` URLs (folders
            relative to the scenario file's; :mod:`drake_traj.robots.model_files`).
        tool: the tool on the flange.
        clearance: the distance [m] a planned motion keeps from the cell and from the arm itself
            (default :data:`DEFAULT_CLEARANCE`).
    """

    mounting: Mounting = field(default_factory=Table)
    obstacles: list[ObstacleShape] = field(default_factory=list)
    directives: list[ModelDirective] = field(default_factory=list)
    packages: dict[str, str] = field(default_factory=dict)
    tool: Tool = field(default_factory=Tool)
    clearance: float = DEFAULT_CLEARANCE

    def validate(self, robot: Robot = UR10E) -> None:
        """Raise DrakeTrajError naming the first field that is malformed (sizes, poses, the tool,
        the payload, the clearance), or a payload above ``robot``'s rating
        (:meth:`Tool.check_payload`); directives are checked when they are loaded."""
        clearance = field_vector([self.clearance], ("cell", "clearance"), 1, "m")[0]
        if clearance < 0:
            raise invalid("cell.clearance", f"cell.clearance must be >= 0 m, got {self.clearance}")
        self.mounting.shapes()
        _validate_shapes(self.obstacles, ("cell", "obstacles"))
        self.tool.tcp()
        _validate_shapes(self.tool.shapes, ("cell", "tool", "shapes"))
        self.tool.spatial_inertia()
        self.tool.check_payload(robot)

    def obstacle_name(self, index: int) -> str:
        """The geometry name of obstacle ``index`` (its ``name``, or ``obstacle_<index>``)."""
        return self.obstacles[index].name or f"obstacle_{index}"


def _validate_shapes(shapes: list, where: Field) -> None:
    """DrakeTrajError at ``where + (k, ...)`` for the first entry ``k`` of ``shapes`` that is not an
    :class:`~drake_traj.cell.shapes.Obstacle` or whose size or pose is malformed."""
    for index, shape in enumerate(shapes):
        name = where + (index,)
        checked_obstacle(shape, name).shape(name)
        shape.pose(name)


def _proximity() -> ProximityProperties:
    properties = ProximityProperties()
    AddContactMaterial(friction=CoulombFriction(0.5, 0.5), properties=properties)
    return properties


def _register(plant: MultibodyPlant, body, pose: RigidTransform, shape, name: str, colour: Rgba) -> None:
    plant.RegisterCollisionGeometry(body, pose, shape, name, _proximity())
    plant.RegisterVisualGeometry(body, pose, shape, name, colour.rgba)


def add_cell(plant: MultibodyPlant, cell: Cell, robot_instance, *, robot: Robot = UR10E,
             directory: Path | None = None) -> dict:
    """Register ``cell`` in ``plant`` (not finalized) around ``robot`` (its model instance
    ``robot_instance``; the tool goes on its flange ``robot.tool_frame``).

    The mounting and the obstacles are geometry of the world body (collision and visual); the
    directives add the user's models (relative files from ``directory``, the scenario's folder;
    default the working directory); the tool is a body ``tool`` welded to ``flange_frame`` that
    carries the payload's inertia and the tool's shapes (added only when there is either); the
    payload is checked against ``robot``'s rating.

    Returns {geometry name: field path in the scenario} of the cell's own geometry (the
    mounting's parts, the obstacles, the tool's shapes) and {body scoped name
    (``bin::base``): ``("cell", "directives", k)``} of the bodies each directive ``k`` adds, for
    errors that name an obstacle (:meth:`CellChecker.field_of
    <drake_traj.cell.clearance.CellChecker.field_of>`, :func:`refuse_free_bodies`). Raises
    DrakeTrajError naming the field of a malformed part, a model file that is missing or cannot
    be parsed, or a directive naming an unknown frame or model.
    """
    cell.validate(robot)
    world = plant.world_body()
    fields = {}
    for name, shape, pose in cell.mounting.shapes():
        _register(plant, world, pose, shape, name, MOUNTING_COLOUR)
        fields[name] = ("cell", "mounting")
    for index, obstacle in enumerate(cell.obstacles):
        name = cell.obstacle_name(index)
        if name in fields:
            raise invalid(f"cell.obstacles[{index}].name", f"cell.obstacles[{index}].name {name!r} is used twice", index)
        location = ("cell", "obstacles", index)
        _register(plant, world, obstacle.pose(location), obstacle.shape(location), name, OBSTACLE_COLOUR)
        fields[name] = location
    fields.update(add_directives(plant, cell.directives, directory, package_folders(cell.packages, directory)))
    inertia = cell.tool.spatial_inertia()
    if inertia is not None or cell.tool.shapes:
        tool = plant.AddRigidBody(TOOL_BODY, robot_instance, inertia or SpatialInertia.Zero())
        plant.WeldFrames(plant.GetFrameByName(robot.tool_frame, robot_instance), tool.body_frame())
        for index, shape in enumerate(cell.tool.shapes):
            location = ("cell", "tool", "shapes", index)
            name = shape.name or f"tool_{index}"
            _register(plant, tool, shape.pose(location), shape.shape(location), name, TOOL_COLOUR)
            fields[name] = location
    return fields
