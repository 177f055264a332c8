"""A scenario's ``robot:``: a known robot's name, or a 6-axis arm of one's own.

Three YAML forms (:data:`RobotChoice`)::

    robot: ur10e                     # a name of drake_traj.robots.ROBOT_NAMES

    robot: !CustomArm                # a URDF/SDF model file of one's own
      model_file: my_arm.urdf        # relative to the scenario file's folder
      base_frame: base
      tool_frame: tool0
      acceleration_limits: [2.5, 2.5, 3.0, 3.0, 3.0, 3.0]
      payload: 5.0

    robot: !DhArm                    # a DH table and the data a model is made from
      name: my_dh_arm
      convention: standard           # or modified (Craig)
      dh: [[0.1807, 0.0, 1.5708, 0.0], ...]   # six rows [d m, a m, alpha rad, theta offset rad]
      lower: [...]                   # and upper, velocity_limits, acceleration_limits,
      masses: [...]                  # effort_limits, centres_of_mass, inertias, ...

:func:`resolve_robot` turns any of them into a :class:`~drake_traj.robots.base.Robot`; the two
arms are built by :func:`build_chain_arm`, the one place that calls
:class:`drake_traj.robots.chain_arm.ChainArm` (a ``!DhArm``'s model is written from its table as
URDF text, :func:`drake_traj.robots.urdf_writer.dh_table_urdf`).
"""

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional, Union

from drake_traj.errors import DrakeTrajError, field_text
from drake_traj.robots import arm_checks
from drake_traj.robots import Robot, get_robot
from drake_traj.robots.arm_checks import ARM_JOINTS, arm_name, inertia_rows, joint_vector, link_radius, matrix, payload, ranges
from drake_traj.robots.chain import CONVENTIONS, plant_chain
from drake_traj.robots.chain_arm import ChainArm
from drake_traj.robots.inertia_estimate import DEFAULT_DENSITY, DENSITY_RANGE
from drake_traj.robots.model_setup import read_model
from drake_traj.robots.self_contact import srdf_file
from drake_traj.validation import invalid

__all__ = ["ARM_JOINTS", "CustomArm", "DhArm", "InertiaEstimate", "RobotChoice", "build_chain_arm", "resolve_robot",
           "robot_label"]

def _joint_data(arm, prefix: str, *, required: bool) -> dict:
    """The joint ranges, speeds, accelerations (always required), torques and payload of a
    CustomArm or DhArm, checked (``required``: the model carries none of them)."""
    lower = joint_vector(arm.lower, f"{prefix}.lower", "rad", required=required)
    upper = joint_vector(arm.upper, f"{prefix}.upper", "rad", required=required)
    ranges(lower, upper, f"{prefix}.lower", f"{prefix}.upper")
    return dict(
        lower=lower, upper=upper,
        velocity_limits=joint_vector(arm.velocity_limits, f"{prefix}.velocity_limits", "rad/s", required=required,
                                     positive=True),
        acceleration_limits=joint_vector(arm.acceleration_limits, f"{prefix}.acceleration_limits", "rad/s^2",
                                         required=True, positive=True),
        effort_limits=joint_vector(arm.effort_limits, f"{prefix}.effort_limits", "N m", required=required,
                                   positive=True),
        payload=payload(arm.payload, f"{prefix}.payload"))


@dataclass
class InertiaEstimate:
    """``robot.inertia``: the moving links a description gives no inertia get one estimated from
    their shapes (collision, else visual; a mesh as its convex hull), a solid of this density.

    Attributes:
        density: [kg/m³]; default :data:`~drake_traj.robots.inertia_estimate.DEFAULT_DENSITY`
            (1370, the median over descriptions that publish their inertia).
    """

    density: float = DEFAULT_DENSITY


def _xacro_text(value, field: tuple) -> str:
    """A xacro argument as xacro takes it: text as it is, a number as Python writes it, true or
    false for a boolean; DrakeTrajError at ``field`` for anything else."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return repr(value)
    if isinstance(value, str) and value:
        return value
    raise DrakeTrajError(f"{field_text(field)} must be text, a number or true/false, got {value!r:.80}", field=field)


def _inertia_density(choice, field: str) -> float | None:
    """The density [kg/m³] of ``robot.inertia`` (an :class:`InertiaEstimate`, or ``estimate``),
    None for ``refuse``; DrakeTrajError at ``field`` otherwise."""
    if choice in ("estimate", "refuse"):
        return DEFAULT_DENSITY if choice == "estimate" else None
    if not isinstance(choice, InertiaEstimate):
        raise invalid(field, f"{field} must be estimate, refuse or {{density: kg/m^3}}, got {choice!r:.80}")
    density = choice.density
    if not (isinstance(density, (int, float)) and DENSITY_RANGE[0] <= density <= DENSITY_RANGE[1]):
        raise invalid(f"{field}.density", f"{field}.density must be a density within {DENSITY_RANGE[0]:g} and "
                                          f"{DENSITY_RANGE[1]:g} kg/m^3, got {density!r:.40}")
    return float(density)


@dataclass
class CustomArm:
    """A 6-axis arm from one's own URDF or SDF model file (six actuated revolute joints).

    Attributes:
        model_file: the model file; relative: from the scenario file's folder.
        base_frame: the model's frame welded to the world (the base frame of every pose).
        tool_frame: the flange frame (a cell's tool is welded there).
        name: the arm's name in results and exports (not a known robot's name).
        lower, upper: joint ranges [rad]; empty: the model's.
        velocity_limits: rated joint speeds [rad/s]; empty: the model's.
        acceleration_limits: joint accelerations a planner keeps [rad/s²]; required (model files
            carry none).
        effort_limits: joint torque limits [N m]; empty: the model's.
        payload: the rated payload [kg]; absent: not rated (then the arm takes no tool mass).
        packages: {package name: folder} for the model's ``package://`` URLs (folders relative to
            the scenario file's; with those on ``ROS_PACKAGE_PATH``).
        xacro_args: a ``.xacro`` model file's arguments ({name: value}: text, a number, true or
            false).
        locked_joints: {joint name: position [rad or m]} of joints held there (welded); the
            joints off the base-to-tool path not named are held at 0 clipped into their range.
        inertia: links a description gives no inertia (no ``<inertial>``, or a mass of 0):
            estimated from their shapes (``{density: kg/m^3}``, default
            :class:`InertiaEstimate`'s), or ``refuse``.
        unchecked_links: links without collision shapes that may run without the self and cell
            checks, said explicitly (``[all]``: every link); otherwise such an arm is refused.
        srdf: the arm's MoveIt configuration (a ``.srdf`` file; relative: from the scenario
            file's folder), whose ``<disable_collisions>`` pairs the checks leave out; empty: none.
    """

    model_file: str = ""
    base_frame: str = "base"
    tool_frame: str = "tool0"
    name: str = "custom_arm"
    lower: list[float] = field(default_factory=list)
    upper: list[float] = field(default_factory=list)
    velocity_limits: list[float] = field(default_factory=list)
    acceleration_limits: list[float] = field(default_factory=list)
    effort_limits: list[float] = field(default_factory=list)
    payload: Optional[float] = None
    packages: dict[str, str] = field(default_factory=dict)
    xacro_args: dict[str, Union[str, int, float, bool]] = field(default_factory=dict)
    unchecked_links: list[str] = field(default_factory=list)
    locked_joints: dict[str, float] = field(default_factory=dict)
    inertia: Union[InertiaEstimate, str] = field(default_factory=InertiaEstimate)
    srdf: str = ""

    def validate(self, prefix: str = "robot") -> dict:
        """The checked values as ChainArm's keyword arguments (arrays, None where not given);
        DrakeTrajError naming the field (``robot.acceleration_limits``) otherwise."""
        for key, mapping in (("packages", self.packages), ("xacro_args", self.xacro_args),
                             ("locked_joints", self.locked_joints)):
            if not isinstance(mapping, dict) or not all(isinstance(k, str) and k for k in mapping):
                raise invalid(f"{prefix}.{key}", f"{prefix}.{key} must map names to values, got {mapping!r:.200}")
        if not all(isinstance(v, str) and v for v in self.packages.values()):
            raise invalid(f"{prefix}.packages", f"{prefix}.packages must map names to folders, got {self.packages!r:.200}")
        xacro_args = {k: _xacro_text(v, (prefix, "xacro_args", k)) for k, v in self.xacro_args.items()}
        for joint, position in self.locked_joints.items():
            if isinstance(position, bool) or not isinstance(position, (int, float)) or not math.isfinite(position):
                raise DrakeTrajError(f"{prefix}.locked_joints.{joint} must be a finite position [rad or m], got "
                                     f"{position!r:.40}", field=(prefix, "locked_joints", joint))
        if not all(isinstance(link, str) and link for link in self.unchecked_links):
            raise invalid(f"{prefix}.unchecked_links", f"{prefix}.unchecked_links must be link names (or all), got "
                                                       f"{self.unchecked_links!r:.200}")
        for key in ("model_file", "base_frame", "tool_frame"):
            value = getattr(self, key)
            if not isinstance(value, str) or not value.strip():
                raise invalid(f"{prefix}.{key}", f"{prefix}.{key} is missing: give the model's "
                                                 f"{'file' if key == 'model_file' else key.replace('_', ' ')}")
        return dict(name=arm_name(self.name, f"{prefix}.name"), base_frame=self.base_frame, tool_frame=self.tool_frame,
                    xacro_args=xacro_args, unchecked_links=tuple(self.unchecked_links),
                    locked_joints={k: float(v) for k, v in self.locked_joints.items()},
                    inertia_density=_inertia_density(self.inertia, f"{prefix}.inertia"),
                    **_joint_data(self, prefix, required=False))


@dataclass
class DhArm:
    """A 6-axis arm from its Denavit-Hartenberg table, joint data and link inertias.

    Attributes:
        name: the arm's name in results and exports (not a known robot's name).
        convention: "standard" (DH frame i on joint i+1's axis) or "modified" (Craig: on joint i's).
        dh: six rows [d [m], a [m], alpha [rad], theta offset [rad]], joint 1 first.
        lower, upper: joint ranges [rad].
        velocity_limits, acceleration_limits: [rad/s], [rad/s²].
        effort_limits: joint torque limits [N m].
        masses: link masses [kg], links 1-6.
        centres_of_mass: each link's centre of mass in its DH frame [m], six rows of 3; empty:
            at the frame's origin.
        inertias: each link's inertia about its centre of mass in its DH frame, six rows [Ixx,
            Iyy, Izz, Ixy, Ixz, Iyz] [kg m²]; empty: the arm's default.
        link_radius: the radius of the links' collision capsules [m].
        payload: the rated payload [kg]; absent: not rated (then the arm takes no tool mass).
        source: where the numbers come from (a paper, a document): the arm's ``data_source``,
            with the scenario file.
    """

    name: str = ""
    convention: str = "standard"
    dh: list[list[float]] = field(default_factory=list)
    lower: list[float] = field(default_factory=list)
    upper: list[float] = field(default_factory=list)
    velocity_limits: list[float] = field(default_factory=list)
    acceleration_limits: list[float] = field(default_factory=list)
    effort_limits: list[float] = field(default_factory=list)
    masses: list[float] = field(default_factory=list)
    centres_of_mass: list[list[float]] = field(default_factory=list)
    inertias: list[list[float]] = field(default_factory=list)
    link_radius: float = 0.05
    payload: Optional[float] = None
    source: str = ""

    def validate(self, prefix: str = "robot") -> dict:
        """The checked values as ChainArm's keyword arguments; DrakeTrajError naming the field
        (``robot.dh[2][1]``) otherwise."""
        if self.convention not in CONVENTIONS:
            raise invalid(f"{prefix}.convention", f"{prefix}.convention must be one of {CONVENTIONS}, "
                                                  f"got {self.convention!r:.40}")
        table = matrix(self.dh, f"{prefix}.dh", "m, m, rad, rad", 4, required=True)
        arm_checks.dh_reach(table, f"{prefix}.dh")
        return dict(
            name=arm_name(self.name, f"{prefix}.name"), convention=self.convention, table=table,
            **_joint_data(self, prefix, required=True),
            masses=joint_vector(self.masses, f"{prefix}.masses", "kg", required=True, positive=True),
            centres_of_mass=matrix(self.centres_of_mass, f"{prefix}.centres_of_mass", "m", 3, required=False),
            inertias=inertia_rows(self.inertias, f"{prefix}.inertias"),
            link_radius=link_radius(self.link_radius, f"{prefix}.link_radius"))


RobotChoice = Union[str, CustomArm, DhArm]
"""A scenario's ``robot:`` field: a known robot's name, ``!CustomArm`` or ``!DhArm``."""


def robot_label(choice: RobotChoice) -> str:
    """The robot's name as a list shows it, without building it (a custom arm's own name)."""
    return choice if isinstance(choice, str) else f"{choice.name} ({type(choice).__name__})"


def resolve_robot(choice: RobotChoice, directory: Path | None = None, scenario_file: Path | None = None) -> Robot:
    """The robot of a scenario's ``robot:`` field: :func:`get_robot` for a name, or the arm a
    :class:`CustomArm` or :class:`DhArm` describes (a relative ``model_file`` from ``directory``,
    default the working directory; its ``data_source`` names the model file or the DH arm's
    ``source``, and ``scenario_file``). Raises DrakeTrajError naming the field (``robot``,
    ``robot.effort_limits``, ...)."""
    if isinstance(choice, str):
        try:
            return get_robot(choice)
        except ValueError as error:
            raise invalid("robot", f"robot: {error}") from None
    if not isinstance(choice, (CustomArm, DhArm)):
        raise invalid("robot", f"robot must be a robot's name, a CustomArm or a DhArm, got {type(choice).__name__}")
    try:
        arguments = choice.validate("robot")
    except DrakeTrajError as error:
        if isinstance(choice, CustomArm) and error.field[:2] in {("robot", key) for key in JOINT_LISTS}:
            _refuse_other_chain(choice, directory)
        raise
    if isinstance(choice, CustomArm):
        path, arguments["packages"] = _model_paths(choice, directory)
        arguments["model_file"] = path
        if choice.srdf:
            srdf = Path(choice.srdf)
            arguments["srdf"] = srdf_file(srdf if srdf.is_absolute() or directory is None else Path(directory) / srdf,
                                          ("robot", "srdf"))
    origin = f"the model file {path}" if isinstance(choice, CustomArm) else (choice.source or "its DH table")
    return build_chain_arm(choice, arguments, origin if scenario_file is None else f"{origin} (scenario {scenario_file})")


def _model_paths(choice: CustomArm, directory: Path | None) -> tuple[Path, dict[str, Path]]:
    """The model file and the package folders of a checked :class:`CustomArm`, relative ones from
    ``directory``; DrakeTrajError at ``robot.model_file`` or ``robot.packages.NAME`` for one that
    is not there."""
    path = Path(choice.model_file)
    path = path if path.is_absolute() or directory is None else Path(directory) / path
    if not path.is_file():
        raise invalid("robot.model_file", f"robot.model_file {str(path)[:200]} is not a file")
    packages = {}
    for name, folder in choice.packages.items():
        folder = Path(folder) if Path(folder).is_absolute() or directory is None else Path(directory) / folder
        if not folder.is_dir():
            raise DrakeTrajError(f"robot.packages.{name}: {str(folder)[:200]} is not a folder",
                                 field=("robot", "packages", name))
        packages[name] = folder
    return path, packages


JOINT_LISTS = ("lower", "upper", "velocity_limits", "acceleration_limits", "effort_limits")  # six values each


def _refuse_other_chain(choice: CustomArm, directory: Path | None) -> None:
    """For a custom arm refused for one of its :data:`JOINT_LISTS` (its other fields sound): the
    model's own refusal at ``robot.model_file`` where its chain between the frames is not six
    revolute joints (a 7-axis arm: naming its joints, and ``locked_joints``), which says more than
    the length of a list of seven values; nothing where the model reads as six joints, or the
    lists hold six values (the list's own refusal then says what is wrong)."""
    if all(not isinstance(values, list) or len(values) in (0, ARM_JOINTS)
           for values in (getattr(choice, key) for key in JOINT_LISTS)):
        return
    try:
        path, packages = _model_paths(choice, directory)
        plant, _ = read_model(path, base_frame=choice.base_frame, tool_frame=choice.tool_frame, packages=packages,
                              xacro_args={k: _xacro_text(v, ()) for k, v in choice.xacro_args.items()},
                              locked_joints=choice.locked_joints)
        plant_chain(plant, choice.base_frame, choice.tool_frame)
    except DrakeTrajError as error:
        if error.field == ("plant",):
            raise error.relocated(("robot", "model_file"), f"robot.model_file: {error}") from None


# ChainArm's argument and error fields -> the scenario's fields of a custom arm
_ARGUMENTS = dict(lower="lower_limits", upper="upper_limits", payload="rated_payload")
_FIELDS = {"lower_limits": "lower", "upper_limits": "upper", "rated_payload": "payload", "table": "dh",
           "fixed": "dh", "axes": "dh", "plant": "model_file"}


def build_chain_arm(choice: CustomArm | DhArm, arguments: dict, data_source: str = "") -> Robot:
    """The one call into :class:`drake_traj.robots.chain_arm.ChainArm`: ``arguments`` are the
    checked values of ``choice.validate()`` (numpy arrays [rad, rad/s, rad/s², N m, kg, m, kg m²],
    None where not given; ``name``, frames, ``convention``, ``link_radius``, ``payload``), plus
    ``model_file`` (an existing Path) for a :class:`CustomArm`. A :class:`CustomArm` is
    :meth:`ChainArm.from_model_file`; a :class:`DhArm` is :meth:`ChainArm.from_dh` with its
    model written from the table (URDF text, no file). ``data_source``: where the numbers come
    from. An error of the arm is raised at the choice's field (``robot.model_file`` for a model
    without six revolute joints between its frames)."""
    arguments = {_ARGUMENTS.get(key, key): value for key, value in arguments.items()}
    try:
        if isinstance(choice, CustomArm):
            return ChainArm.from_model_file(arguments.pop("model_file"), data_source=data_source, **arguments)
        return ChainArm.from_dh(arguments.pop("name"), arguments.pop("table"), arguments.pop("convention"),
                                data_source=data_source, **arguments)
    except DrakeTrajError as error:
        head = _FIELDS.get(error.field[0], error.field[0]) if error.field else "model_file"
        field = ("robot", head, *error.field[1:])
        message = arm_checks.scenario_message(error, lambda key: field_text(("robot", _FIELDS.get(key, key))))
        raise error.relocated(field, f"{field_text(field)}: {message}") from None
