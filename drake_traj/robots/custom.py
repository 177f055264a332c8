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

import numpy as np

from drake_traj.errors import DrakeTrajError, field_text
from drake_traj.robots import ROBOT_NAMES, Robot, get_robot
from drake_traj.robots.chain_arm import ChainArm
from drake_traj.validation import finite_array, invalid, real_array

__all__ = ["ARM_JOINTS", "CustomArm", "DhArm", "RobotChoice", "build_chain_arm", "resolve_robot", "robot_label"]

ARM_JOINTS = 6  # a custom arm has six revolute joints
_NAME_CHARACTERS = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-")


def _joint_vector(value, name: str, unit: str, *, required: bool, positive: bool = False) -> np.ndarray | None:
    """``value`` as ARM_JOINTS finite numbers (positive if asked), None when empty and not
    ``required``; DrakeTrajError naming the field ``name`` otherwise."""
    array = real_array(value, name, unit)
    if array.size == 0:
        if required:
            raise invalid(name, f"{name} is missing: a custom arm needs {ARM_JOINTS} values [{unit}]")
        return None
    array = finite_array(array, name, unit, shape=(ARM_JOINTS,))
    if positive and np.any(array <= 0):
        j = int(np.flatnonzero(array <= 0)[0])
        raise invalid(name, f"{name}[{j}] must be positive [{unit}], got {array[j]:g}", j)
    return array


def _matrix(value, name: str, unit: str, columns: int, *, required: bool) -> np.ndarray | None:
    """``value`` as a finite (ARM_JOINTS, columns) array, None when empty and not ``required``."""
    rows = real_array(value, name, unit, "a list of rows of numbers")
    if rows.size == 0:
        if required:
            raise invalid(name, f"{name} is missing: a custom arm needs {ARM_JOINTS} rows of {columns} numbers [{unit}]")
        return None
    if rows.shape != (ARM_JOINTS, columns):
        raise invalid(name, f"{name} must be {ARM_JOINTS} rows of {columns} numbers [{unit}], got shape {rows.shape}")
    bad = np.argwhere(~np.isfinite(rows))
    if len(bad):
        i, k = (int(v) for v in bad[0])
        raise invalid(name, f"{name}[{i}][{k}] must be finite [{unit}], got {rows[i, k]}", i, k)
    return rows


def _arm_name(value, name: str) -> str:
    if not isinstance(value, str) or not value or len(value) > 64 or not set(value) <= _NAME_CHARACTERS:
        raise invalid(name, f"{name} must be a plain name (letters, digits, _ and -; at most 64 characters), got {value!r:.80}")
    if value in ROBOT_NAMES:
        raise invalid(name, f"{name} {value!r} is a known robot's name (runs and exports are told apart by it); "
                            "choose another")
    return value


def _payload(value, name: str) -> float | None:
    if value is None:
        return None
    payload = finite_array(value, name, "kg", shape=())
    if payload < 0:
        raise invalid(name, f"{name} must be >= 0 kg, got {float(payload):g}")
    return float(payload)


def _ranges(lower: np.ndarray | None, upper: np.ndarray | None, prefix: str) -> None:
    if lower is not None and upper is not None and np.any(lower >= upper):
        j = int(np.flatnonzero(lower >= upper)[0])
        raise invalid(f"{prefix}.upper", f"{prefix}.upper[{j}] = {upper[j]:g} rad must be above {prefix}.lower[{j}] = "
                                          f"{lower[j]:g} rad", j)


def _inertias(value, name: str) -> np.ndarray | None:
    """``value`` as (ARM_JOINTS, 6) rows [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] [kg m²] of physical
    inertias (principal moments >= 0 meeting the triangle inequality), None when empty."""
    rows = _matrix(value, name, "kg m^2", 6, required=False)
    for i, (ixx, iyy, izz, ixy, ixz, iyz) in enumerate([] if rows is None else rows):
        moments = np.linalg.eigvalsh([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        tolerance = 1e-9 * max(float(np.max(np.abs(moments))), 1e-12)
        if moments[0] < -tolerance or moments[2] > moments[0] + moments[1] + tolerance:
            raise invalid(name, f"{name}[{i}] is not a rigid body's inertia: its principal moments "
                                f"{', '.join(f'{m:.6g}' for m in moments)} kg m^2 must be >= 0 and each at most the sum "
                                "of the other two", i)
    return rows


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

    def validate(self, prefix: str = "robot") -> dict:
        """The checked values as ChainArm's keyword arguments (arrays, None where not given);
        DrakeTrajError naming the field (``robot.acceleration_limits``) otherwise."""
        for key in ("model_file", "base_frame", "tool_frame"):
            value = getattr(self, key)
            if not isinstance(value, str) or not value.strip():
                raise invalid(f"{prefix}.{key}", f"{prefix}.{key} is missing: give the model's "
                                                 f"{'file' if key == 'model_file' else key.replace('_', ' ')}")
        lower = _joint_vector(self.lower, f"{prefix}.lower", "rad", required=False)
        upper = _joint_vector(self.upper, f"{prefix}.upper", "rad", required=False)
        _ranges(lower, upper, prefix)
        return dict(
            name=_arm_name(self.name, f"{prefix}.name"), base_frame=self.base_frame, tool_frame=self.tool_frame,
            lower=lower, upper=upper,
            velocity_limits=_joint_vector(self.velocity_limits, f"{prefix}.velocity_limits", "rad/s", required=False,
                                          positive=True),
            acceleration_limits=_joint_vector(self.acceleration_limits, f"{prefix}.acceleration_limits", "rad/s^2",
                                              required=True, positive=True),
            effort_limits=_joint_vector(self.effort_limits, f"{prefix}.effort_limits", "N m", required=False,
                                        positive=True),
            payload=_payload(self.payload, f"{prefix}.payload"))


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

    CONVENTIONS = ("standard", "modified")

    def validate(self, prefix: str = "robot") -> dict:
        """The checked values as ChainArm's keyword arguments; DrakeTrajError naming the field
        (``robot.dh[2][1]``) otherwise."""
        if self.convention not in self.CONVENTIONS:
            raise invalid(f"{prefix}.convention", f"{prefix}.convention must be one of {self.CONVENTIONS}, "
                                                  f"got {self.convention!r:.40}")
        table = _matrix(self.dh, f"{prefix}.dh", "m, m, rad, rad", 4, required=True)
        lower = _joint_vector(self.lower, f"{prefix}.lower", "rad", required=True)
        upper = _joint_vector(self.upper, f"{prefix}.upper", "rad", required=True)
        _ranges(lower, upper, prefix)
        radius = finite_array(self.link_radius, f"{prefix}.link_radius", "m", shape=())
        if radius <= 0:
            raise invalid(f"{prefix}.link_radius", f"{prefix}.link_radius must be positive [m], got {float(radius):g}")
        return dict(
            name=_arm_name(self.name, f"{prefix}.name"), convention=self.convention, table=table,
            lower=lower, upper=upper,
            velocity_limits=_joint_vector(self.velocity_limits, f"{prefix}.velocity_limits", "rad/s", required=True,
                                          positive=True),
            acceleration_limits=_joint_vector(self.acceleration_limits, f"{prefix}.acceleration_limits", "rad/s^2",
                                              required=True, positive=True),
            effort_limits=_joint_vector(self.effort_limits, f"{prefix}.effort_limits", "N m", required=True,
                                        positive=True),
            masses=_joint_vector(self.masses, f"{prefix}.masses", "kg", required=True, positive=True),
            centres_of_mass=_matrix(self.centres_of_mass, f"{prefix}.centres_of_mass", "m", 3, required=False),
            inertias=_inertias(self.inertias, f"{prefix}.inertias"),
            link_radius=float(radius), payload=_payload(self.payload, f"{prefix}.payload"))


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
        raise error.relocated(field, f"{field_text(field)}: {error}") from None
