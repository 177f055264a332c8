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
(:mod:`drake_traj.clearance`) and the contact of the simulated arm (:mod:`drake_traj.station`).
"""

from dataclasses import dataclass, field
from pathlib import Path
from typing import Union

import numpy as np
import yaml
from pydrake.geometry import Box as BoxShape
from pydrake.geometry import Cylinder as CylinderShape
from pydrake.geometry import AddContactMaterial, ProximityProperties, Rgba
from pydrake.geometry import Sphere as SphereShape
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.parsing import ModelDirective, ModelDirectives, ProcessModelDirectives
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, CoulombFriction, MultibodyPlant
from pydrake.multibody.tree import RotationalInertia, SpatialInertia
from pydrake.systems.framework import DiagramBuilder

from drake_traj.errors import Cause, DrakeTrajError, Field, field_text
from drake_traj.robots.model_files import missing_package, model_parser
from drake_traj.robots import UR10E, PointRobot, Robot
from drake_traj.validation import invalid, real_array

__all__ = [
    "Box", "Cell", "Cylinder", "DEFAULT_CLEARANCE", "NoMounting", "Obstacle", "Pedestal", "Sphere",
    "Table", "Tool", "add_cell", "refuse_free_bodies",
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


def _vector(values, name: Field, size: int, unit: str) -> np.ndarray:
    """``values`` as a finite float vector of ``size`` entries, or DrakeTrajError naming ``name``."""
    label = field_text(name)
    array = real_array(values, label, unit)
    if array.shape != (size,):
        raise DrakeTrajError(f"{label} must have {size} entries [{unit}], got shape {array.shape}", field=name,
                             cause=Cause.INVALID)
    if not np.all(np.isfinite(array)):
        raise DrakeTrajError(f"{label} must be finite, got {np.asarray(values).tolist()}", field=name, cause=Cause.INVALID)
    return array


def _size(value, name: Field, unit: str = "m") -> float:
    """A finite, positive size, or DrakeTrajError naming ``name``."""
    label = field_text(name)
    number = _vector([value], name, 1, unit)[0]
    if number <= 0:
        raise DrakeTrajError(f"{label} must be positive [{unit}], got {value}", field=name, cause=Cause.INVALID)
    return float(number)


def _pose(xyz, rpy, name: Field) -> RigidTransform:
    return RigidTransform(RollPitchYaw(_vector(rpy, name + ("rpy",), 3, "rad")), _vector(xyz, name + ("xyz",), 3, "m"))


@dataclass
class Box:
    """A box of edge lengths ``size`` [m] centred at ``xyz`` [m], turned by ``rpy`` [rad] (Drake's
    roll-pitch-yaw: fixed-axis X, Y, Z)."""

    name: str = ""
    size: list[float] = field(default_factory=lambda: [0.1, 0.1, 0.1])
    xyz: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    rpy: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])

    def shape(self, name: Field) -> BoxShape:
        size = _vector(self.size, name + ("size",), 3, "m")
        return BoxShape(*(_size(edge, name + ("size", k)) for k, edge in enumerate(size)))


@dataclass
class Cylinder:
    """A cylinder of ``radius`` and ``length`` [m] along its z axis, centred at ``xyz`` [m],
    turned by ``rpy`` [rad]."""

    name: str = ""
    radius: float = 0.05
    length: float = 0.1
    xyz: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    rpy: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])

    def shape(self, name: Field) -> CylinderShape:
        return CylinderShape(_size(self.radius, name + ("radius",)), _size(self.length, name + ("length",)))


@dataclass
class Sphere:
    """A sphere of ``radius`` [m] centred at ``xyz`` [m]."""

    name: str = ""
    radius: float = 0.05
    xyz: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    rpy: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])

    def shape(self, name: Field) -> SphereShape:
        return SphereShape(_size(self.radius, name + ("radius",)))


Obstacle = Union[Box, Cylinder, Sphere]


@dataclass
class Table:
    """A table top flush with the robot's base: its top face is z = 0, ``size`` = [length x,
    width y, thickness] [m], centred on the base."""

    size: list[float] = field(default_factory=lambda: [*TABLE_TOP_SIZE, 0.05])


@dataclass
class Pedestal:
    """A cylindrical pedestal of ``radius`` [m] under the base, ``height`` [m] tall, standing on a
    floor (z = -height) of ``floor_size`` [m] (x, y)."""

    radius: float = 0.1
    height: float = 0.6
    floor_size: list[float] = field(default_factory=lambda: list(TABLE_TOP_SIZE))


@dataclass
class NoMounting:
    """Nothing under or around the base (the papers' free-standing arm)."""


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
    shapes: list[Obstacle] = field(default_factory=list)
    mass: float = 0.0
    center_of_mass: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    inertia: list[float] = field(default_factory=list)

    def tcp(self) -> RigidTransform:
        """X_FT: the TCP frame in the flange frame; DrakeTrajError naming the field if not finite."""
        return RigidTransform(RollPitchYaw(_vector(self.tcp_rpy, ("cell", "tool", "tcp_rpy"), 3, "rad")),
                              _vector(self.tcp_xyz, ("cell", "tool", "tcp_xyz"), 3, "m"))

    def extent(self) -> float:
        """The radius [m] about the flange origin that holds the TCP and every tool shape."""
        reach = [float(np.linalg.norm(self.tcp_xyz))]
        for index, shape in enumerate(self.shapes):
            reach.append(float(np.linalg.norm(shape.xyz)) + _bounding_radius(shape, ("cell", "tool", "shapes", index)))
        return max(reach)

    def spatial_inertia(self) -> SpatialInertia | None:
        """The payload about the flange origin, in the flange frame (None without a payload)."""
        mass = _vector([self.mass], ("cell", "tool", "mass"), 1, "kg")[0]
        if mass < 0:
            raise invalid("cell.tool.mass", f"cell.tool.mass must be >= 0 kg, got {self.mass}")
        com = _vector(self.center_of_mass, ("cell", "tool", "center_of_mass"), 3, "m")
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
        moments = _vector(self.inertia, ("cell", "tool", "inertia"), 6, "kg m^2")
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
        mass = _vector([self.mass], ("cell", "tool", "mass"), 1, "kg")[0]
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
        obstacles: boxes, cylinders and spheres posed in the world (base) frame.
        directives: Drake ``ModelDirective``s (``add_model``, ``add_weld``, ...) for the user's own
            model files; a relative ``file`` is taken from the scenario file's folder. Offline
            only: a ``package://`` URL resolves through ``packages`` and ``ROS_PACKAGE_PATH``.
        packages: {package name: folder} for the directives' ``package://`` URLs (folders
            relative to the scenario file's; :mod:`drake_traj.model_files`).
        tool: the tool on the flange.
        clearance: the distance [m] a planned motion keeps from the cell and from the arm itself
            (default :data:`DEFAULT_CLEARANCE`).
    """

    mounting: Mounting = field(default_factory=Table)
    obstacles: list[Obstacle] = field(default_factory=list)
    directives: list[ModelDirective] = field(default_factory=list)
    packages: dict[str, str] = field(default_factory=dict)
    tool: Tool = field(default_factory=Tool)
    clearance: float = DEFAULT_CLEARANCE

    def validate(self, robot: Robot = UR10E) -> None:
        """Raise DrakeTrajError naming the first field that is malformed (sizes, poses, the tool,
        the payload, the clearance), or a payload above ``robot``'s rating
        (:meth:`Tool.check_payload`); directives are checked when they are loaded."""
        clearance = _vector([self.clearance], ("cell", "clearance"), 1, "m")[0]
        if clearance < 0:
            raise invalid("cell.clearance", f"cell.clearance must be >= 0 m, got {self.clearance}")
        _mounting_shapes(self.mounting)
        for index, obstacle in enumerate(self.obstacles):
            name = ("cell", "obstacles", index)
            obstacle.shape(name)
            _pose(obstacle.xyz, obstacle.rpy, name)
        self.tool.tcp()
        for index, shape in enumerate(self.tool.shapes):
            shape.shape(("cell", "tool", "shapes", index))
            _pose(shape.xyz, shape.rpy, ("cell", "tool", "shapes", index))
        self.tool.spatial_inertia()
        self.tool.check_payload(robot)

    def obstacle_name(self, index: int) -> str:
        """The geometry name of obstacle ``index`` (its ``name``, or ``obstacle_<index>``)."""
        return self.obstacles[index].name or f"obstacle_{index}"


def _bounding_radius(shape: Obstacle, name: Field) -> float:
    """The radius [m] of a sphere about the shape's centre that contains it."""
    if isinstance(shape, Box):
        return 0.5 * float(np.linalg.norm(_vector(shape.size, name + ("size",), 3, "m")))
    if isinstance(shape, Cylinder):
        return float(np.hypot(shape.radius, 0.5 * shape.length))
    return float(shape.radius)


def _mounting_shapes(mounting: Mounting) -> list[tuple[str, object, RigidTransform]]:
    """(name, shape, pose in the world) of the mounting's parts; their tops are z = 0."""
    name = ("cell", "mounting")
    if isinstance(mounting, Table):
        length, width, thickness = _vector(mounting.size, name + ("size",), 3, "m")
        for k, edge in enumerate((length, width, thickness)):
            _size(edge, name + ("size", k))
        return [("table", BoxShape(length, width, thickness), RigidTransform([0.0, 0.0, -0.5 * thickness]))]
    if isinstance(mounting, Pedestal):
        radius, height = _size(mounting.radius, name + ("radius",)), _size(mounting.height, name + ("height",))
        length, width = _vector(mounting.floor_size, name + ("floor_size",), 2, "m")
        for k, edge in enumerate((length, width)):
            _size(edge, name + ("floor_size", k))
        floor_thickness = 0.05
        return [("pedestal", CylinderShape(radius, height), RigidTransform([0.0, 0.0, -0.5 * height])),
                ("floor", BoxShape(length, width, floor_thickness),
                 RigidTransform([0.0, 0.0, -height - 0.5 * floor_thickness]))]
    return []


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
    <drake_traj.clearance.CellChecker.field_of>`, :func:`refuse_free_bodies`). Raises
    DrakeTrajError naming the field of a malformed part, a model file that is missing or cannot
    be parsed, or a directive naming an unknown frame or model.
    """
    cell.validate(robot)
    world = plant.world_body()
    fields = {}
    for name, shape, pose in _mounting_shapes(cell.mounting):
        _register(plant, world, pose, shape, name, MOUNTING_COLOUR)
        fields[name] = ("cell", "mounting")
    for index, obstacle in enumerate(cell.obstacles):
        name = cell.obstacle_name(index)
        if name in fields:
            raise invalid(f"cell.obstacles[{index}].name", f"cell.obstacles[{index}].name {name!r} is used twice", index)
        location = ("cell", "obstacles", index)
        _register(plant, world, _pose(obstacle.xyz, obstacle.rpy, location), obstacle.shape(location), name,
                  OBSTACLE_COLOUR)
        fields[name] = location
    fields.update(_add_directives(plant, cell.directives, directory, _packages(cell.packages, directory)))
    inertia = cell.tool.spatial_inertia()
    if inertia is not None or cell.tool.shapes:
        tool = plant.AddRigidBody(TOOL_BODY, robot_instance, inertia or SpatialInertia.Zero())
        plant.WeldFrames(plant.GetFrameByName(robot.tool_frame, robot_instance), tool.body_frame())
        for index, shape in enumerate(cell.tool.shapes):
            location = ("cell", "tool", "shapes", index)
            name = shape.name or f"tool_{index}"
            _register(plant, tool, _pose(shape.xyz, shape.rpy, location), shape.shape(location), name, TOOL_COLOUR)
            fields[name] = location
    return fields


def _packages(packages: dict, directory: Path | None) -> dict[str, Path]:
    """``cell.packages`` as {name: folder}, relative folders from ``directory``; DrakeTrajError
    naming ``cell.packages.NAME`` for a folder that does not exist."""
    found = {}
    for name, folder in packages.items():
        path = Path(folder) if Path(folder).is_absolute() else Path(directory or ".") / folder
        if not isinstance(name, str) or not name or not path.is_dir():
            raise DrakeTrajError(f"cell.packages.{name}: {str(path)[:200]} is not a folder", field=("cell", "packages", name),
                                 cause=Cause.INVALID)
        found[name] = path
    return found


def _missing_package_of(url: str, parser, field: tuple, label: str) -> DrakeTrajError | None:
    """:func:`~drake_traj.model_files.missing_package` of a directive's model file: its own URL's
    package, then the ``package://`` URLs inside the file."""
    refusal = missing_package(url, parser, field, label)
    if refusal is not None:
        return refusal
    if url.startswith("package://") or url.startswith("file://"):
        try:
            path = Path(parser.package_map().ResolveUrl(url)) if url.startswith("package://") else Path(url[len("file://"):])
            return missing_package(path.read_text(errors="replace"), parser, field, label) if path.is_file() else None
        except RuntimeError:
            return None
    return None


def _add_directives(plant: MultibodyPlant, directives: list[ModelDirective], directory: Path | None,
                    packages: dict[str, Path] | None = None) -> dict:
    """Process Drake model directives in one call (Drake resolves a weld's frames among the
    models of the same call), each checked first so that an error names its entry of
    ``cell.directives``: a model file that is missing or cannot be parsed, a weld or frame
    naming a frame that is neither the plant's (the world, the robot) nor an earlier entry's.
    Returns {body scoped name: ``("cell", "directives", k)``} of the bodies the entries add."""
    base = Path(directory or ".").resolve()
    known = {}  # model instance name -> its frame names, for the models the entries add
    for index, directive in enumerate(directives):
        name = ("cell", "directives", index)
        if directive.add_model is not None:
            model = directive.add_model
            if "://" not in model.file:
                path = base / model.file
                if not path.is_file():  # False for a symbolic link that loops or leads nowhere
                    what = " (a symbolic link that loops or leads nowhere)" if path.is_symlink() else ""
                    raise DrakeTrajError(f"cell.directives[{index}].add_model.file: no model file {model.file!r} "
                                         f"(looked for {path}{what})", field=name + ("add_model", "file"),
                                         cause=Cause.INVALID)
                model.file = path.resolve().as_uri()
            scratch_builder = DiagramBuilder()  # with SceneGraph: its meshes' package:// URLs are resolved here
            scratch, _ = AddMultibodyPlantSceneGraph(scratch_builder, 0.0)
            parser = model_parser(scratch, packages)
            refusal = _missing_package_of(model.file, parser, name + ("add_model", "file"),
                                          f"cell.directives[{index}].add_model.file")
            if refusal is not None:
                raise refusal
            try:
                (instance,) = parser.AddModels(url=model.file)
            except (RuntimeError, ValueError) as error:
                raise DrakeTrajError(f"cell.directives[{index}].add_model: {model.file} cannot be used: "
                                     f"{str(error).strip()}", field=name + ("add_model", "file"), cause=Cause.INVALID) from None
            known[model.name] = {scratch.get_frame(frame).name() for frame in scratch.GetFrameIndices(instance)}
        for kind, frames in (("add_weld", ("parent", "child")), ("add_frame", ())):
            entry = getattr(directive, kind)
            if entry is None:
                continue
            names = [getattr(entry, frame) for frame in frames] if frames else [entry.X_PF.base_frame or "world"]
            for frame in names:
                if not _frame_known(plant, known, frame):
                    models = sorted(known) + ["world"]
                    raise DrakeTrajError(f"cell.directives[{index}].{kind}: unknown frame {frame!r} (scoped as "
                                         f"model::frame; models: {', '.join(models)} and the robot's)",
                                         field=name + (kind,), cause=Cause.INVALID)
            if kind == "add_frame":
                known.setdefault("", set()).add(entry.name)
        if directive.add_directives is not None:
            _refuse_include_cycle(directive.add_directives.file, name + ("add_directives", "file"), packages, base)
    try:
        added = ProcessModelDirectives(ModelDirectives(directives=directives), plant, model_parser(plant, packages))
    except (RuntimeError, ValueError) as error:
        raise DrakeTrajError(f"cell.directives: {str(error).strip()}", field=("cell", "directives"),
                             cause=Cause.INVALID) from None
    fields = {}
    for info in added:
        name = ("cell", "directives") + _directive_index(directives, info.model_name)
        for body in plant.GetBodyIndices(info.model_instance):
            fields[str(plant.get_body(body).scoped_name())] = name
    return fields


MAX_DIRECTIVES_DEPTH = 100  # add_directives files included in one another, at most this deep


def _directives_path(url: str, packages: dict[str, Path] | None, base: Path) -> Path | None:
    """The file of an ``add_directives`` URL (``file://``, ``package://`` through ``packages``
    and ``ROS_PACKAGE_PATH``, or a plain path from ``base``), None where it cannot be found
    (Drake then says why)."""
    try:
        if url.startswith("package://"):
            scratch = MultibodyPlant(0.0)
            return Path(model_parser(scratch, packages).package_map().ResolveUrl(url))
        path = Path(url[len("file://"):]) if url.startswith("file://") else Path(url)
        return path if path.is_absolute() else base / path
    except (RuntimeError, ValueError):
        return None


def _refuse_include_cycle(url: str, field: Field, packages: dict[str, Path] | None, base: Path) -> None:
    """Follow the ``add_directives`` includes from ``url`` (the files read here, before Drake
    reads them: Drake recurses without end on a cycle, until it crashes) and refuse a file that
    includes itself, directly or through others, naming the chain of files at ``field``; also a
    file that is a symbolic link loop, and includes nested deeper than
    :data:`MAX_DIRECTIVES_DEPTH`. A file that cannot be read or is not a directives file is left
    to Drake's own message."""
    label = field_text(field)

    def follow(url: str, chain: list[str], seen: list[Path]) -> None:
        path = _directives_path(url, packages, base)
        if path is None:
            return
        if path.is_symlink() and not path.is_file():
            raise DrakeTrajError(f"{label}: the directives file {url!r} is a symbolic link that loops or leads nowhere "
                                 f"({path})", field=field, cause=Cause.INVALID)
        try:
            real = path.resolve(strict=True)
            text = real.read_text(errors="replace")
        except (OSError, RuntimeError):
            return
        chain = chain + [url]
        if real in seen:
            raise DrakeTrajError(f"{label}: the directives files include each other in a cycle: "
                                 f"{' -> '.join(chain)} (a file must not include itself, directly or through others)",
                                 field=field, cause=Cause.INVALID)
        if len(chain) > MAX_DIRECTIVES_DEPTH:
            raise DrakeTrajError(f"{label}: the directives files are included more than {MAX_DIRECTIVES_DEPTH} deep "
                                 f"({' -> '.join(chain[:3])} -> ...)", field=field, cause=Cause.INVALID)
        if real in done:  # its includes were followed already, without a cycle
            return
        try:
            document = yaml.safe_load(text)
        except yaml.YAMLError:
            return
        entries = document.get("directives") if isinstance(document, dict) else None
        for entry in entries if isinstance(entries, list) else []:
            nested = entry.get("add_directives") if isinstance(entry, dict) else None
            if isinstance(nested, dict) and isinstance(nested.get("file"), str):
                follow(nested["file"], chain, seen + [real])
        done.add(real)

    done = set()
    follow(url, [], [])


def _directive_index(directives: list[ModelDirective], model: str) -> tuple:
    """``(k,)`` of the entry of ``directives`` that adds the model instance ``model`` (its
    ``add_model``, or the ``add_directives`` whose namespace it is in); () if none is known."""
    for index, directive in enumerate(directives):
        if directive.add_model is not None and directive.add_model.name == model:
            return (index,)
        if directive.add_model_instance is not None and directive.add_model_instance.name == model:
            return (index,)
        nested = directive.add_directives
        if nested is not None and nested.model_namespace and model.startswith(f"{nested.model_namespace}::"):
            return (index,)
    return ()


def refuse_free_bodies(plant: MultibodyPlant, robot_instance, fields: dict | None = None) -> None:
    """Refuse a body of the finalized ``plant`` that is not the robot's (model instance
    ``robot_instance``) and is joined to nothing: a floating base body, which the simulation
    lets fall and the cell check would take for an obstacle at its model's default pose. A
    model of ``cell.directives`` (its bodies in ``fields``, :func:`add_cell`'s return) is
    named by its entry (``field`` ``("cell", "directives", k)``; the remedy an ``add_weld``),
    any other (a station's ``before_finalize`` bodies) by its model (the remedy a weld before
    the plant is finalized). DrakeTrajError, cause INVALID; the first such body in index order.

    Then a model other than the robot's with joints that move (a second arm welded beside the
    robot): the station drives and feeds forward the robot's joints only (its controller sees
    the robot's state, not the plant's), nothing would drive those joints, and the cell check
    would take the model for an obstacle at its default pose. Refused naming the model and its
    joints, at its directive where it has one."""
    fields = fields or {}
    _refuse_floating(plant, robot_instance, fields)
    moving = {}  # model instance -> its joints with a degree of freedom, in index order
    for index in plant.GetJointIndices():
        joint = plant.get_joint(index)
        if joint.model_instance() != robot_instance and joint.num_velocities() > 0:
            moving.setdefault(joint.model_instance(), []).append(joint)
    for instance, joints in sorted(moving.items(), key=lambda item: int(item[0])):
        model = plant.GetModelInstanceName(instance)
        names = ", ".join(repr(joint.name()) for joint in joints)
        what = (f"model {model!r} has joints that move ({names}): the station drives the robot's joints only, nothing "
                "would hold these, and the cell check would take the model for an obstacle at its default pose")
        field = next((fields[str(plant.get_body(body).scoped_name())] for body in plant.GetBodyIndices(instance)
                      if str(plant.get_body(body).scoped_name()) in fields), None)
        if field is not None and field[:2] == ("cell", "directives"):
            raise DrakeTrajError(f"{field_text(field)}: {what}: give a model whose joints are fixed (URDF type "
                                 "\"fixed\") for a second arm that stands still", field=field, cause=Cause.INVALID)
        raise DrakeTrajError(f"{what}: add it with fixed joints (URDF type \"fixed\", or weld its bodies) before the "
                             "plant is finalized", cause=Cause.INVALID)


def _refuse_floating(plant: MultibodyPlant, robot_instance, fields: dict) -> None:
    """:func:`refuse_free_bodies`' floating base bodies."""
    for index in sorted(plant.GetFloatingBaseBodies(), key=int):
        body = plant.get_body(index)
        if body.model_instance() == robot_instance:
            continue
        model, scoped = plant.GetModelInstanceName(body.model_instance()), str(body.scoped_name())
        what = f"model {model!r} is not welded to anything (its body {body.name()!r} would fall freely)"
        field = fields.get(scoped)
        if field is not None and field[:2] == ("cell", "directives"):
            raise DrakeTrajError(f"{field_text(field)}: {what}: add an add_weld {{parent: world, child: {scoped}}} "
                                 "after it (X_PC: where it stands), or weld it to another model's frame",
                                 field=field, cause=Cause.INVALID)
        raise DrakeTrajError(f"{what}: weld it before the plant is finalized (in before_finalize: "
                             f"plant.WeldFrames(plant.world_frame(), plant.GetBodyByName({body.name()!r}, "
                             f"plant.GetModelInstanceByName({model!r})).body_frame(), X_WB))",
                             cause=Cause.INVALID)


def _frame_known(plant: MultibodyPlant, known: dict, frame: str) -> bool:
    """Whether ``frame`` (``model::frame`` or a plain name) is the world, a frame of the plant
    or of a model in ``known`` ({instance name: frame names})."""
    if frame == "world":
        return True
    model, _, element = frame.rpartition("::")
    if model in known:
        return element in known[model]
    if model and plant.HasModelInstanceNamed(model):
        return plant.HasFrameNamed(element, plant.GetModelInstanceByName(model))
    return not model and (element in known.get("", set()) or plant.HasFrameNamed(element))
