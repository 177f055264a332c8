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

from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional, Union

from drake_traj.errors import DrakeTrajError, field_text
from drake_traj.robots import arm_checks
from drake_traj.robots import Robot, get_robot
from drake_traj.robots.arm_checks import ARM_JOINTS, arm_name, inertia_rows, joint_vector, link_radius, matrix, payload, ranges
from drake_traj.robots.chain import CONVENTIONS
from drake_traj.robots.chain_arm import ChainArm
from drake_traj.validation import invalid

__all__ = ["ARM_JOINTS", "CustomArm", "DhArm", "RobotChoice", "build_chain_arm", "resolve_robot", "robot_label"]

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
        xacro_args: a ``.xacro`` model file's arguments ({name: value}).
        unchecked_links: links without collision shapes that may run without the self and cell
            checks, said explicitly (``[all]``: every link); otherwise such an arm is refused.
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
    xacro_args: dict[str, str] = field(default_factory=dict)
    unchecked_links: list[str] = field(default_factory=list)

    def validate(self, prefix: str = "robot") -> dict:
        """The checked values as ChainArm's keyword arguments (arrays, None where not given);
        DrakeTrajError naming the field (``robot.acceleration_limits``) otherwise."""
        for key, mapping in (("packages", self.packages), ("xacro_args", self.xacro_args)):
            if not all(isinstance(k, str) and k and isinstance(v, str) and v for k, v in mapping.items()):
                raise invalid(f"{prefix}.{key}", f"{prefix}.{key} must map names to non-empty texts, got {mapping!r:.200}")
        if not all(isinstance(link, str) and link for link in self.unchecked_links):
            raise invalid(f"{prefix}.unchecked_links", f"{prefix}.unchecked_links must be link names (or all), got "
                                                       f"{self.unchecked_links!r:.200}")
        for key in ("model_file", "base_frame", "tool_frame"):
            value = getattr(self, key)
            if not isinstance(value, str) or not value.strip():
                raise invalid(f"{prefix}.{key}", f"{prefix}.{key} is missing: give the model's "
                                                 f"{'file' if key == 'model_file' else key.replace('_', ' ')}")
        return dict(name=arm_name(self.name, f"{prefix}.name"), base_frame=self.base_frame, tool_frame=self.tool_frame,
                    xacro_args=dict(self.xacro_args), unchecked_links=tuple(self.unchecked_links),
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
    arguments = choice.validate("robot")
    if isinstance(choice, CustomArm):
        path = Path(choice.model_file)
        path = path if path.is_absolute() or directory is None else Path(directory) / path
        if not path.is_file():
            raise invalid("robot.model_file", f"robot.model_file {str(path)[:200]} is not a file")
        arguments["model_file"] = path
        packages = {}
        for name, folder in choice.packages.items():
            folder = Path(folder) if Path(folder).is_absolute() or directory is None else Path(directory) / folder
            if not folder.is_dir():
                raise DrakeTrajError(f"robot.packages.{name}: {str(folder)[:200]} is not a folder",
                                     field=("robot", "packages", name))
            packages[name] = folder
        arguments["packages"] = packages
    origin = f"the model file {path}" if isinstance(choice, CustomArm) else (choice.source or "its DH table")
    return build_chain_arm(choice, arguments, origin if scenario_file is None else f"{origin} (scenario {scenario_file})")


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
