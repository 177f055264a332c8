"""Scenarios: the typed description of a run, loaded from YAML with pydrake's ``yaml_load_typed``
(files in ``diagrams/``), and the types it is made of.

A scenario names the robot, its start configuration, the planner and its parameters (one of the
planners' config dataclasses, chosen by a YAML tag such as ``planner: !PajakConfig``), the PD
controller (:class:`ControllerGains`), a speed-override profile (:class:`SpeedOverride`) and the
simulation settings (Drake's ``MultibodyPlantConfig`` and ``SimulatorConfig``). A file holds
either one scenario or several named variants (top-level keys; keys starting with ``_`` hold
shared YAML anchors and are not variants). Unknown keys, wrong lengths and non-finite or
out-of-range numbers raise :class:`ScenarioError` naming the file, the line and the field (its
``field`` attribute holds the field's path).

:func:`load_scenario` takes a file or a shipped scenario's name, as ``drake-traj run`` does;
:func:`make_planner` builds its planner and :func:`preflight` checks the whole task before the
motion, both with errors located in the file. The station (``drake_traj.station``) is built from
these types.
"""

import functools
from dataclasses import dataclass, field, fields
from pathlib import Path

import numbers
import re

import numpy as np
from pydrake.common.yaml import yaml_load_typed
from pydrake.math import RollPitchYaw, RotationMatrix
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlantConfig
from pydrake.systems.analysis import GetIntegrationSchemes, SimulatorConfig
from pydrake.systems.framework import DiagramBuilder
from pydrake.trajectories import PiecewisePolynomial

from drake_traj.cell import Cell, CellChecker
from drake_traj.data import data_directory
from drake_traj.errors import Cause, DrakeTrajError, Field, field_text, joint_label
from drake_traj.planners import PLANNER_CONFIGS, PlannerConfig, PlannerSystem, QuinticConfig, make_planner as make_planner_from_config
from drake_traj.results import DEFAULT_TRACKING_TOLERANCE
from drake_traj.robots import Robot
from drake_traj.robots.base import joint_actuators
from drake_traj.robots.custom import CustomArm, DhArm, RobotChoice, resolve_robot, robot_label
from drake_traj.validation import (MAX_RUN_DURATION, flag, instance_of, invalid, log_period_check, path_argument,
                                   real_array, realtime_rate, run_duration, settle_duration, step_size,
                                   tracking_tolerance_check)
from drake_traj.scenario.yaml_schema import ScenarioError, checked_document, locate

__all__ = [
    "ControllerGains", "Scenario", "ScenarioError", "ScenarioSource", "ShippedScenario", "SpeedOverride",
    "default_plant_config", "default_scenario_path", "default_simulator_config", "find_scenario", "load_scenario",
    "check_cell_tcp", "check_planned_duration", "check_start_torques", "locate_in_scenario", "make_planner", "preflight", "scenario_variants",
    "shipped_copy", "shipped_scenarios",
]

DEFAULT_SCENARIO = ("pajak.yaml", "sim3")  # what ``drake-traj run`` runs when given no scenario
_PLAIN_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,99}")
# The coarsest plant step and log period a run is checked with [s]: the UR controller runs at
# 2 ms, and the limits and the continuity of q̈ are checked at the logged samples.
MAX_TIME_STEP = MAX_LOG_PERIOD = 0.01


def default_plant_config() -> MultibodyPlantConfig:
    """The plant we simulate: discrete at 1 ms, SAP (implicit PD actuators)."""
    return MultibodyPlantConfig(time_step=1e-3, discrete_contact_approximation="sap")


def default_simulator_config() -> SimulatorConfig:
    """Fixed-step second-order Runge-Kutta at 1 ms for the planner's continuous reference.

    Chosen by measurement (docs/benchmarks.md, "Speed"): it evaluates the planner twice per millisecond (the
    error-controlled default RK3 3.75-4.2 times), keeps every Table 2 duration of Pająk 2024 to the
    millisecond and the reference within 2e-6 rad of RK3 at accuracy 1e-8; semi-explicit Euler
    (one evaluation) moved sim 3's T by 5 ms and the reference by 2.3e-4 rad.
    """
    return SimulatorConfig(integration_scheme="runge_kutta2", max_step_size=1e-3, use_error_control=False)


@dataclass
class ControllerGains:
    """PD gains of the simulated joint controller and the feed-forward choice.

    Empty ``kp`` / ``kd`` take the robot's defaults (:attr:`Robot.default_gains`).
    """

    kp: list[float] = field(default_factory=list)
    kd: list[float] = field(default_factory=list)
    feedforward_acceleration: bool = True

    _UNITS = {"kp": "N m/rad or N/m", "kd": "N m s/rad or N s/m"}

    def for_robot(self, robot: Robot) -> "ControllerGains":
        """These gains with empty lists filled from ``robot``'s defaults, validated for its joint count."""
        given = {name: real_array(getattr(self, name), f"controller.{name}", unit).tolist()
                 for name, unit in self._UNITS.items()}
        kp, kd = (given[name] if np.size(given[name]) else list(default)
                  for name, default in zip(("kp", "kd"), robot.default_gains))
        gains = ControllerGains(kp, kd, self.feedforward_acceleration)
        gains.validate(robot.num_joints)
        return gains

    def validate(self, num_joints: int) -> None:
        """Raise ValueError naming the gain that is not numbers, of the wrong length, non-finite or
        negative, or a feed-forward choice that is not True or False."""
        flag(self.feedforward_acceleration, "controller.feedforward_acceleration")
        for name, unit in self._UNITS.items():
            gains = real_array(getattr(self, name), f"controller.{name}", unit)
            if gains.shape != (num_joints,):
                raise invalid(f"controller.{name}", f"controller.{name} must have {num_joints} entries, got shape {gains.shape}")
            if not np.all(np.isfinite(gains)) or np.any(gains < 0):
                raise invalid(f"controller.{name}", f"controller.{name} must be finite and non-negative, got {gains.tolist()}")
        if not np.all(np.asarray(self.kp) > 0):
            raise invalid("controller.kp", f"controller.kp must be positive, got {self.kp}")


@dataclass
class SpeedOverride:
    """A speed-override profile, like a UR pendant's speed slider: ``values[k]`` in [0, 1] from
    ``times[k]`` [s] on (held until the next time), 1 before the first time. Empty: no override.
    """

    times: list[float] = field(default_factory=list)
    values: list[float] = field(default_factory=list)

    def validate(self) -> None:
        """Raise ValueError naming the field that is malformed."""
        times, values = real_array(self.times, "speed_override.times", "s"), real_array(self.values, "speed_override.values", "-")
        if times.shape != values.shape or times.ndim != 1:
            raise invalid("speed_override.values", f"speed_override.times and speed_override.values must be two lists of equal length, "
                             f"got {len(self.times)} and {len(self.values)} entries")
        if not np.all(np.isfinite(times)) or np.any(times < 0) or np.any(np.diff(times) <= 0):
            raise invalid("speed_override.times", f"speed_override.times must be finite, >= 0 and increasing [s], got {self.times}")
        if not np.all(np.isfinite(values)) or np.any((values < 0) | (values > 1)):
            raise invalid("speed_override.values", f"speed_override.values must be in [0, 1], got {self.values}")

    def trajectory(self) -> PiecewisePolynomial:
        """The profile as a zero-order hold (1 before the first time)."""
        self.validate()
        breaks = [0.0] + [t for t in self.times if t > 0.0]
        values = ([1.0] if self.times[0] > 0.0 else []) + list(self.values)
        breaks.append(breaks[-1] + 1.0)  # a zero-order hold ignores its last sample: repeat the last value
        values.append(values[-1])
        return PiecewisePolynomial.ZeroOrderHold(breaks, np.array([values]))


@dataclass
class Scenario:
    """One experiment: robot, start, planner, controller and simulation settings (times in seconds).

    Attributes:
        name: a plain name (letters, digits, ``_``, ``-``, ``.``): the default output folder.
        description: one line on what the scenario runs.
        robot: a name of :data:`drake_traj.robots.ROBOT_NAMES` ("ur10e", "li_4dof" of Li et al.
            2019, or Boryga's "anthropomorphic", "scara", "cartesian"), or an arm of one's own:
            ``!CustomArm`` (a model file) or ``!DhArm`` (a DH table), see
            :mod:`drake_traj.robots.custom`.
        q_initial: the robot's start [rad or m]; empty: its home configuration (the UR10e's is the
            start of Pająk 2024's task). Planners that follow a tool path on the papers' robots
            start from the inverse kinematics of the path instead.
        planner: the planner's config (see :data:`drake_traj.planners.PLANNER_CONFIGS`).
        cell: what the robot stands on, the obstacles around it, the user's own models and the
            tool (:class:`~drake_traj.cell.Cell`; default a table flush with the base).
        controller: PD gains (empty: the robot's defaults) and the feed-forward choice.
        plant: Drake's ``MultibodyPlantConfig`` of the robot plant (default: discrete at 1 ms,
            SAP); ``plant: {time_step: 0.002}`` runs at the UR controller's 500 Hz.
        simulator: Drake's ``SimulatorConfig`` (integration scheme, step, accuracy, real-time
            rate: 0, as fast as it goes, or 0.1-1000; default fixed-step RK2 at 1 ms, see
            ``station.default_simulator_config``).
        log_period: the loggers' period [s], a whole multiple of ``plant.time_step``; 0 (the
            default): the plant's time step.
        speed_override: a speed-override profile (times [s], values in [0, 1]), like a pendant's
            speed slider; empty: none.
        tracking_tolerance: the run fails if the measured TCP is ever further than this from the
            reference [m] (default 5 mm: 40x the shipped scenarios' worst, 0.13 mm); at most half
            ``cell.clearance`` (the margin the cell check keeps along the reference).
        settle_time: how long the run goes on after the planner finishes [s], at most 60 s.
        max_duration: the run stops with a failure if the planner has not finished by then [s],
            at most 600 s; the preflight integrates an online planner's law this far ahead.
    """

    name: str = "unnamed"
    description: str = ""
    robot: RobotChoice = "ur10e"
    q_initial: list[float] = field(default_factory=list)
    planner: PlannerConfig = field(default_factory=QuinticConfig)
    cell: Cell = field(default_factory=Cell)
    controller: ControllerGains = field(default_factory=ControllerGains)
    plant: MultibodyPlantConfig = field(default_factory=default_plant_config)
    simulator: SimulatorConfig = field(default_factory=default_simulator_config)
    log_period: float = 0.0
    speed_override: SpeedOverride = field(default_factory=SpeedOverride)
    tracking_tolerance: float = DEFAULT_TRACKING_TOLERANCE
    settle_time: float = 0.5
    max_duration: float = 120.0

    def __post_init__(self) -> None:
        # where the scenario was read from (set by load_scenario; not a YAML field): locates errors
        self.source: ScenarioSource | None = None
        self._robot: tuple | None = None  # ((repr of the robot field, folder), the robot it resolved to)

    def start_configuration(self) -> np.ndarray:
        """``q_initial``, or the robot's home configuration when it is empty."""
        q = real_array(self.q_initial, "q_initial", "rad or m")
        return self.base_robot().home_configuration if q.size == 0 else q

    def base_robot(self) -> Robot:
        """The robot of the ``robot`` field with its flange as the tool (every use of the field goes
        through here: :func:`~drake_traj.robots.custom.resolve_robot`, a custom arm's model file
        taken from the scenario's folder); DrakeTrajError naming the field otherwise."""
        key = (repr(self.robot), self.directory())
        if self._robot is None or self._robot[0] != key:
            self._robot = (key, resolve_robot(self.robot, self.directory(), None if self.source is None else
                                              self.source.path))
        return self._robot[1]

    def validate(self) -> None:
        """Raise ValueError naming the first field that is malformed (the message starts with
        the field's path), or a ``tracking_tolerance`` above half ``cell.clearance``
        (:func:`~drake_traj.validation.tracking_tolerance_check`)."""
        if not _PLAIN_NAME.fullmatch(self.name) or ".." in self.name:
            raise invalid("name", f"name must be a plain name (letters, digits, _ . -; no path; at most 100 characters), "
                             f"got {self.name[:120]!r}: it names the default output folder out/<name>")
        robot = self.base_robot()
        n = robot.num_joints
        q = self.start_configuration()
        if q.shape != (n,):
            raise invalid("q_initial", f"q_initial must have {n} entries for robot {robot.name}, got shape {q.shape}")
        if not np.all(np.isfinite(q)):
            raise invalid("q_initial", f"q_initial must be finite, got {self.q_initial}")
        lower, upper = robot.lower_limits, robot.upper_limits
        outside = np.flatnonzero((q < lower) | (q > upper))
        if len(outside):
            j = outside[0]
            unit = robot.joint_unit(j)
            raise invalid("q_initial", f"q_initial[{j}] = {q[j]} {unit} is outside the joint range "
                                       f"[{lower[j]:.6f}, {upper[j]:.6f}] {unit} of {joint_label(j, robot.joint_names)}", j)
        for label, value in (("plant.time_step", self.plant.time_step), ("log_period", self.logging_period()),
                             ("max_duration", self.max_duration), ("settle_time", self.settle_time),
                             ("simulator.max_step_size", self.simulator.max_step_size),
                             ("tracking_tolerance", self.tracking_tolerance)):
            smallest_allowed = 0.0 if label == "settle_time" else np.nextafter(0.0, 1.0)
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise invalid(label, f"{label} must be a number, got {type(value).__name__} {value!r:.40}")
            if not np.isfinite(value) or value < smallest_allowed:
                unit = "metres" if label == "tracking_tolerance" else "seconds"
                raise invalid(label, f"{label} must be a finite, positive number of {unit}, got {value}")
        run_duration(self.max_duration)
        settle_duration(self.settle_time)
        step_size(self.plant.time_step, "plant.time_step")
        step_size(self.simulator.max_step_size, "simulator.max_step_size")
        realtime_rate(self.simulator.target_realtime_rate, "simulator.target_realtime_rate")
        for label, value, largest in (("plant.time_step", self.plant.time_step, MAX_TIME_STEP),
                                      ("log_period", self.logging_period(), MAX_LOG_PERIOD)):
            if value > largest:
                raise invalid(label, f"{label} must be at most {largest:g} s (the UR controller's cycle is 0.002 s, and "
                                 f"limits are checked at the logged samples), got {value:g} s")
        log_period_check(self.logging_period(), self.plant.time_step)
        if self.logging_period() > self.max_duration:
            raise invalid("max_duration", f"max_duration ({self.max_duration:g} s) must be longer than log_period "
                             f"({self.logging_period():g} s): the run would log one sample")
        if self.simulator.integration_scheme not in GetIntegrationSchemes():
            raise invalid("simulator.integration_scheme", f"simulator.integration_scheme must be one of {GetIntegrationSchemes()}, "
                             f"got {self.simulator.integration_scheme!r}")
        try:  # Drake checks the plant's options (contact model, approximation, ...) when it adds the plant
            AddMultibodyPlant(self.plant, DiagramBuilder())
        except RuntimeError as error:
            raise invalid("plant", f"plant: {error}") from None
        self.controller.for_robot(robot)
        self.speed_override.validate()
        self.checked_cell().validate(robot)
        tracking_tolerance_check(self.tracking_tolerance, self.cell.clearance)
        self.robot_with_tool()

    def station_arguments(self) -> dict:
        """The keyword arguments of :func:`drake_traj.station.build_station` for this scenario
        (its planner made by :func:`make_planner`)."""
        return dict(planner=make_planner(self), robot=self.robot_with_tool(), gains=self.controller,
                    plant_config=self.plant, log_period=self.logging_period(), cell=self.cell,
                    cell_directory=self.directory())

    def robot_with_tool(self) -> Robot:
        """The scenario's robot whose tool point is ``cell.tool``'s TCP (:meth:`Robot.with_tcp`):
        every task pose of the planner, the station's TCP and the result's are the TCP's. A
        refusal (a point robot given an offset) names ``cell.tool.tcp_xyz``; the robot's own errors
        name its field (``robot.dh``), a ``cell`` that is not a Cell names ``cell``."""
        robot = self.base_robot()  # its errors at the robot's field, not the tool's
        tool = self.checked_cell().tool
        try:
            return robot.with_tcp(tool.tcp_xyz, tool.tcp_rpy)
        except DrakeTrajError as error:
            field = ("cell", "tool", "tcp_" + str(error.field[0])) if error.field else ("cell", "tool", "tcp_xyz")
            raise error.relocated(field, f"{field_text(field)}: {error}") from None

    def checked_cell(self) -> Cell:
        """``cell``, or a TypeError naming ``cell`` and the expected type when it is not a Cell
        (``scenario.cell = "table"``), located in the scenario's file when read from one."""
        if not isinstance(self.cell, Cell):
            raise TypeError(locate_in_scenario(self, ("cell",), f"cell must be a drake_traj.cell.Cell (a table, obstacles, "
                                                                f"the tool: Cell(mounting=Table(), ...)), got "
                                                                f"{type(self.cell).__name__}: {self.cell!r:.80}"))
        return self.cell

    def directory(self) -> Path | None:
        """The folder of the scenario's file (relative model files of ``cell.directives`` are
        taken from it); None for a scenario made in Python (the working directory)."""
        return None if self.source is None else self.source.path.parent

    def cell_checker(self) -> CellChecker:
        """The :class:`~drake_traj.clearance.CellChecker` of this scenario's robot in its cell;
        a malformed directive raises a ScenarioError at its line."""
        try:
            return CellChecker(self.robot_with_tool(), self.cell, self.directory())
        except DrakeTrajError as error:
            raise ScenarioError(locate_in_scenario(self, error.field, str(error)), field=error.field,
                                cause=error.cause) from None

    def run_settings(self) -> dict:
        """The keyword arguments of :func:`drake_traj.station.simulate` that this scenario sets
        besides :meth:`station_arguments`: the run's name, integrator, times, speed override and
        tracking tolerance."""
        return dict(name=self.name, simulator_config=self.simulator, settle_time=self.settle_time,
                    max_duration=self.max_duration, speed_override=self.speed_override,
                    tracking_tolerance=self.tracking_tolerance)

    def logging_period(self) -> float:
        """``log_period``, or the plant's time step where it is 0 [s]."""
        return self.log_period if self.log_period != 0 else self.plant.time_step


@dataclass(frozen=True)
class ScenarioSource:
    """Where a :class:`Scenario` was read from: its file, variant (None for a file of one
    scenario) and the YAML node of each field path, for locating later errors."""

    path: Path
    variant: str | None
    marks: dict


def shipped_directory() -> Path:
    """The folder of the scenario files shipped with the package (``diagrams/``)."""
    return data_directory("diagrams")


def default_scenario_path() -> Path:
    """The scenario file ``drake-traj run`` uses when none is given (its variant: ``sim3``)."""
    return shipped_directory() / DEFAULT_SCENARIO[0]


@dataclass(frozen=True)
class ShippedScenario:
    """A scenario shipped with the package: its name, file, variant (None for a file of one
    scenario), one-line description and robot (:func:`~drake_traj.robots.custom.robot_label`)."""

    name: str
    path: Path
    variant: str | None
    description: str
    robot: str


def shipped_scenarios() -> list[ShippedScenario]:
    """Every scenario of the shipped files, in file order. Read once per version of the files
    (each file's modification time and size): a shipped name is looked up on every
    :func:`load_scenario` by name, and loading every shipped scenario takes about 20 ms each."""
    versions = tuple((path, path.stat().st_mtime_ns, path.stat().st_size)
                     for path in sorted(shipped_directory().glob("*.yaml")))
    return list(_shipped_entries(versions))


@functools.lru_cache(maxsize=4)
def _shipped_entries(versions: tuple[tuple[Path, int, int], ...]) -> tuple[ShippedScenario, ...]:
    """The :class:`ShippedScenario` entries of the files ``versions`` ((path, mtime, size), in order)."""
    entries = []
    for path, _, _ in versions:
        for variant in scenario_variants(path) or [None]:
            scenario = load_scenario(path, variant)
            entries.append(ShippedScenario(scenario.name, path, variant, scenario.description, robot_label(scenario.robot)))
    return tuple(entries)


def find_scenario(reference: str, variant: str | None = None) -> tuple[Path, str | None]:
    """(file, variant) of a scenario given as a path, or as the name of a shipped scenario
    (``pajak_sim3``; with ``variant``, that variant of its file: ``pajak_sim3``, ``"sim1"`` is
    ``pajak_sim1``) or of a shipped file (``pajak``, with ``variant``)."""
    path = Path(reference)
    try:
        return _find_scenario(path, reference, variant)
    except OSError as error:  # a name too long, ...
        raise ScenarioError(f"scenario file {str(path)[:80]}{'...' if len(str(path)) > 80 else ''} cannot be "
                            f"used: {error.strerror}") from None


def _find_scenario(path: Path, reference: str, variant: str | None) -> tuple[Path, str | None]:
    if path.is_file():
        return path, variant
    if path.is_symlink() and not path.exists():
        raise ScenarioError(f"scenario file {path} is a broken link or a loop of links")
    if path.exists() and not path.is_dir():
        raise ScenarioError(f"scenario file {path} is not a regular file (a device or a pipe)")
    # a bare name is looked up among the shipped scenarios even when a folder of that name is
    # here (e.g. an earlier run's --out quintic_ptp)
    bare_name = path.suffix not in (".yaml", ".yml") and len(path.parts) == 1
    if path.is_dir() and not (bare_name and _is_shipped_name(reference)):
        raise ScenarioError(f"scenario file {path} is a folder, not a scenario file")
    if not bare_name:
        where = "" if path.is_absolute() else _in_working_folder()
        raise ScenarioError(f"scenario file {path} not found{where}{_shipped_alternative(path, variant)}")
    shipped = shipped_scenarios()
    for entry in shipped:
        if entry.name == reference:  # with a variant: that variant of the scenario's file
            return entry.path, entry.variant if variant is None else variant
    stem = shipped_directory() / f"{reference}.yaml"
    if stem.is_file():
        return stem, variant
    names = ", ".join(entry.name for entry in shipped)
    raise ScenarioError(f"no scenario file {reference!r} and no shipped scenario of that name; "
                     f"shipped: {names} (drake-traj list)")


def _in_working_folder() -> str:
    """`` in <the working folder>``, where a relative path was looked for ("" if it is gone)."""
    try:
        return f" in {Path.cwd()}"
    except OSError:  # the working folder was deleted
        return ""


def _shipped_alternative(path: Path, variant: str | None) -> str:
    """For a scenario ``path`` that is not there (``diagrams/pajak.yaml`` outside the checkout): how
    to run the shipped file of that name (by its file name, ``.yaml`` or not), or ""."""
    file = shipped_directory() / (path.name if path.suffix in (".yaml", ".yml") else f"{path.name}.yaml")
    entries = [entry for entry in shipped_scenarios() if entry.path.name == file.name]
    if not entries:
        return ""
    chosen = [entry for entry in entries if variant is None or entry.variant == variant]
    if len(chosen) == 1:
        name = chosen[0].name
        return f"; the shipped scenario of that name runs as `drake-traj run {name}` (Python: load_scenario({name!r}))"
    name = next((entry.name for entry in entries if (file.name, entry.variant) == DEFAULT_SCENARIO), entries[0].name)
    return (f"; the shipped file of that name holds {', '.join(entry.name for entry in entries)}: run one by its "
            f"name, e.g. `drake-traj run {name}` (Python: load_scenario({name!r}))")


def shipped_copy() -> str:
    """Which copy of the shipped scenario files runs, said by ``drake-traj list`` and ``show``: a
    source tree's ``diagrams/`` (a checkout, an editable install), where an edit changes what
    runs, or the installed package's, which a checkout's ``diagrams/`` does not change."""
    directory = shipped_directory()
    if (directory.parent / "pyproject.toml").is_file():
        return f"this source tree's diagrams/ ({directory}; an edit there changes what runs)"
    return (f"the installed package ({directory}; a checkout's diagrams/ is not read: copy a scenario with "
            "drake-traj show NAME > my_task.yaml, edit the copy and run it by its path)")


def _is_shipped_name(reference: str) -> bool:
    """True when ``reference`` names a shipped scenario or a shipped file."""
    return (shipped_directory() / f"{reference}.yaml").is_file() or any(
        entry.name == reference for entry in shipped_scenarios())


def scenario_variants(path) -> list[str]:
    """The variant names of a scenario file; empty when the file is one scenario."""
    return list(checked_document(Path(path), Scenario)[1])


def load_scenario(name_or_path, variant: str | None = None) -> Scenario:
    """Read and validate a scenario: a YAML file, or the name of a shipped scenario
    (``"quintic_ptp"``, ``"pajak_sim3"``) or of a shipped file (``"pajak"``, with ``variant``),
    as ``drake-traj run`` takes it (:func:`find_scenario`). ``variant``: the named child of a file
    of variants; it may be left out when the file is one scenario or has a single variant.

    Raises :class:`ScenarioError` (a ValueError) naming the file, the line and the field (its
    ``field`` attribute holds the field's path).
    """
    reference = path_argument(name_or_path, "name_or_path")
    if variant is not None:
        instance_of(variant, str, "variant")
    path, variant = find_scenario(str(reference), variant)
    root, variants, check = checked_document(path, Scenario)
    if variants:
        if variant is None and len(variants) == 1:
            variant = next(iter(variants))
        if variant not in variants:
            asked = "no variant was given" if variant is None else f"there is no variant {variant!r}"
            raise ScenarioError(f"{path}: {asked}; its variants are {list(variants)}")
        marks = check(variants[variant])
    elif variant is not None:
        raise ScenarioError(f"{path} holds one scenario, not variants; got variant {variant!r}")
    else:
        marks = check(root)
    try:
        scenario = yaml_load_typed(schema=Scenario, data=path.read_text(), child_name=variant)
    except RuntimeError as error:  # not expected after the check above; still one clear message
        raise ScenarioError(f"{path}: {error}") from None
    scenario.source = ScenarioSource(path, variant, marks)  # before validate(): a custom arm's file is found from it
    try:
        scenario.validate()
    except ValueError as error:
        field = error.field if isinstance(error, DrakeTrajError) else ()
        raise ScenarioError(locate(marks, path, field, str(error)), field=field) from None
    return scenario


def make_planner(scenario: Scenario, *others) -> PlannerSystem:
    """The planner system the scenario describes, its limits checked against the robot's rated
    joint speeds (errors name the scenario and the ``planner`` field; their ``field`` starts
    with ``"planner"``).

    This is ``drake_traj.make_planner``; a planner from a planner config (``QuinticConfig``, ...)
    is :func:`drake_traj.planners.make_planner` ``(config, robot, q_initial)`` (given a config or
    more arguments, this one raises a TypeError saying so).
    """
    if others or isinstance(scenario, PLANNER_CONFIGS):
        more = f" and {len(others)} more argument{'s' * (len(others) > 1)}" if others else ""
        raise TypeError(f"scenario must be a Scenario, got {type(scenario).__name__}{more}: drake_traj.make_planner(scenario) "
                        "makes a scenario's planner; make one from a planner config with "
                        "drake_traj.planners.make_planner(config, robot, q_initial)")
    instance_of(scenario, Scenario, "scenario", hint=" (load one with drake_traj.load_scenario(name_or_path, variant))")
    robot = scenario.robot_with_tool()
    q_initial = scenario.start_configuration()  # its errors name q_initial, not the planner
    try:
        planner = make_planner_from_config(scenario.planner, robot, q_initial)
    except ValueError as error:
        raise _in_planner_field(scenario, error, message_leads_with_field=True) from error
    velocity = np.broadcast_to(planner.velocity_limit, (robot.num_joints,))
    above = np.flatnonzero(velocity > robot.velocity_limits * (1 + 1e-9))
    if len(above):
        j = int(above[0])
        unit = robot.joint_unit(j)
        field = ("planner", "velocity_limit", j)
        raise DrakeTrajError(locate_in_scenario(scenario, field,
            f"planner.velocity_limit[{j}] = {velocity[j]:g} {unit}/s is above the rated "
            f"speed of the {robot.name}'s {joint_label(j, robot.joint_names)}, {robot.velocity_limits[j]:g} {unit}/s: "
            "the arm could not follow"), field=field, cause=Cause.INFEASIBLE)
    return planner


def preflight(scenario: Scenario, planner: PlannerSystem, horizon: float | None = None) -> np.ndarray | None:
    """``planner.preflight(horizon)`` (the whole task checked before t = 0, up to ``horizon`` [s],
    default the scenario's ``max_duration``), its errors located in the scenario as
    :func:`make_planner`'s are (e.g. at ``planner.waypoints[2]``'s line; a task that does not
    finish within the horizon at ``max_duration``'s); then the planned motion in the scenario's
    cell (:func:`check_in_cell`).

    Returns the planned tool path [m], shape (N, 3) in the base frame, where the planner
    computes one (a planner that plans in the cell, the free-motion one: once it has), else None."""
    try:
        path = planner.preflight(scenario.max_duration if horizon is None else horizon)
    except DrakeTrajError as error:
        if error.cause is not Cause.TIMEOUT:
            raise _in_planner_field(scenario, error, message_leads_with_field=False) from error
        field = ("max_duration",)
        raise error.relocated(field, locate_in_scenario(
            scenario, field, f"max_duration: {error}; raise max_duration (at most {MAX_RUN_DURATION:g} s) or the "
                             "planner's limits")) from error
    except ValueError as error:
        raise _in_planner_field(scenario, error, message_leads_with_field=False) from error
    check_in_cell(scenario, planner)
    if path is None and getattr(planner, "needs_cell", False):  # it planned in the cell just now
        path = planner.tool_path()
    return path


def check_in_cell(scenario: Scenario, planner: PlannerSystem, checker: CellChecker | None = None):
    """The start configuration and the planned motion (``planner.plan()``) in the scenario's
    cell: joint ranges, self-collision and collision with the cell, with its clearance
    (:meth:`CellChecker.check <drake_traj.clearance.CellChecker.check>`). A refusal is a
    :class:`~drake_traj.clearance.CollisionError` or
    :class:`~drake_traj.clearance.JointRangeError` located at the cell's obstacle, the start
    configuration or the planner in the scenario file. Returns the
    :class:`~drake_traj.clearance.MotionCheck`."""
    checker = checker or scenario.cell_checker()
    try:
        check_start_torques(checker, planner.initial_positions(), field=lambda j: _torque_field(scenario, j))
    except DrakeTrajError as error:
        raise error.relocated(error.field, locate_in_scenario(scenario, error.field, str(error))) from None
    try:
        return checker.check_planner(planner, start_field=("q_initial",) if len(scenario.q_initial) else ("planner",))
    except DrakeTrajError as error:
        field = error.field or ("planner",)
        if field[0] in {item.name for item in fields(scenario.planner)}:  # a planner that plans in the cell: its goals
            field = ("planner", *field)
        raise error.relocated(field, locate_in_scenario(scenario, field, str(error))) from None


def check_cell_tcp(robot: Robot, cell: Cell) -> None:
    """A DrakeTrajError at ``cell.tool.tcp_xyz`` (or ``tcp_rpy``) when ``cell``'s tool has another
    TCP than ``robot`` (:attr:`Robot.tcp_offset`, set by :meth:`Robot.with_tcp`): the planner
    plans, and the station logs, the robot's TCP, so the cell's would be ignored without a word.
    Both TCPs named, and how to make them one."""
    tool = cell.tool
    given = tool.tcp().GetAsMatrix4()
    if np.allclose(given, robot.tcp_offset, rtol=0.0, atol=1e-12):
        return
    xyz = np.asarray(robot.tcp_offset)[:3, 3]
    rpy = RollPitchYaw(RotationMatrix(np.asarray(robot.tcp_offset)[:3, :3])).vector()
    field = ("cell", "tool", "tcp_xyz" if not np.allclose(given[:3, 3], xyz, rtol=0.0, atol=1e-12) else "tcp_rpy")

    def numbers(values) -> str:
        return "[" + ", ".join(f"{float(value) + 0.0:.6g}" for value in values) + "]"  # + 0.0: no -0

    raise DrakeTrajError(
        f"{field_text(field)}: the cell's tool has its TCP at tcp_xyz {numbers(tool.tcp_xyz)} m, tcp_rpy "
        f"{numbers(tool.tcp_rpy)} rad, but the planner's robot {robot.name} has its TCP at xyz {numbers(xyz)} m, rpy "
        f"{numbers(rpy)} rad (robot.tcp_offset) in the flange frame: the planner plans and the run logs the robot's "
        "TCP. Make the planner for robot.with_tcp(cell.tool.tcp_xyz, cell.tool.tcp_rpy) (make_planner(config, "
        "robot.with_tcp(...), q_initial); a scenario's: scenario.robot_with_tool()), or give the cell the robot's TCP",
        field=field)


def check_start_torques(checker: CellChecker, q, field=None) -> None:
    """A DrakeTrajError (cause SATURATION) when a joint's drive cannot hold the start
    configuration ``q`` against gravity: the gravity torque there (Drake's
    ``CalcGravityGeneralizedForces`` in ``checker``'s plant: the robot, its tool and payload) above
    the joint's effort limit, the first such joint named with both numbers. The drive would
    saturate from t = 0 and the arm sag, a failure the run would report later as whatever the
    falling arm hits. ``field(j)`` gives the error's field for joint ``j`` (default: the
    payload's ``cell.tool.mass`` when there is one, else ``robot``)."""
    plant, instance, robot = checker.plant, checker.instance, checker.robot
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, instance, np.asarray(q, dtype=float))
    gravity = plant.CalcGravityGeneralizedForces(context)
    actuators = joint_actuators(plant, instance)
    mass = float(checker.cell.tool.mass)
    for j, name in enumerate(robot.joint_names):
        actuator = actuators.get(name)
        if actuator is None:
            continue
        needed = -float(gravity[actuator.joint().velocity_start()])
        limit = float(actuator.effort_limit())
        if abs(needed) <= limit:
            continue
        unit = "N m" if robot.joint_unit(j) == "rad" else "N"
        where = field(j) if field is not None else (("cell", "tool", "mass") if mass > 0 else ("robot",))
        payload = f" with the tool's {mass:g} kg payload" if mass > 0 else ""
        raise DrakeTrajError(
            f"{field_text(where)}: {joint_label(j, robot.joint_names)} of the {robot.name} cannot hold the start "
            f"configuration against gravity{payload}: it needs {needed:.4g} {unit} there, beyond its effort limit of "
            f"±{limit:.4g} {unit}, so its drive saturates from t = 0 and the arm falls; raise the effort limit, lighten "
            "the payload or bring its centre of mass closer to the flange, or start in another configuration",
            field=where, cause=Cause.SATURATION)


def _torque_field(scenario: Scenario, j: int) -> Field:
    """The field a start that the drives cannot hold is refused at: the arm's own effort limit
    where the scenario gives it, else the payload where there is one, else the start."""
    arm = scenario.robot
    if isinstance(arm, (DhArm, CustomArm)) and len(arm.effort_limits):
        return ("robot", "effort_limits", j)
    if scenario.cell.tool.mass > 0:
        return ("cell", "tool", "mass")
    return ("q_initial",) if len(scenario.q_initial) else ("robot",)


def check_planned_duration(scenario: Scenario, planner: PlannerSystem) -> None:
    """A :class:`ScenarioError` (cause INFEASIBLE) at ``max_duration`` when it is shorter than
    the motion ``planner`` plans (at its limits), which the run could never finish."""
    duration = planner.planned_duration()
    if np.isfinite(duration) and duration > scenario.max_duration:
        field = ("max_duration",)
        raise ScenarioError(locate_in_scenario(
            scenario, field, f"max_duration ({scenario.max_duration:g} s) is shorter than the planned motion "
                             f"({duration:.3f} s at the planner's limits); raise max_duration or the limits"),
            field=field, cause=Cause.INFEASIBLE)


def _in_planner_field(scenario: Scenario, error: ValueError, *, message_leads_with_field: bool) -> DrakeTrajError:
    """``error`` from the scenario's planner, located at the planner field it names (a field of
    the planner's config) or at ``planner``. ``message_leads_with_field``: the error's text
    begins with its field's name (the config checks: "waypoints[2] must ...") and is continued
    from ``planner.``; otherwise (the preflight's "waypoint 2 cannot be reached ...") the field
    is written before it."""
    if not isinstance(error, DrakeTrajError):
        error = DrakeTrajError(str(error))
    inside = bool(error.field) and error.field[0] in {item.name for item in fields(scenario.planner)}
    field = ("planner",) + (error.field if inside else ())
    text = f"planner.{error}" if inside and message_leads_with_field else f"{field_text(field)}: {error}"
    return error.relocated(field, locate_in_scenario(scenario, field, text))


def locate_in_scenario(scenario: Scenario, field: Field, message: str) -> str:
    """``message`` located in the scenario's file at the line of ``field`` (a path such as
    ``("planner", "waypoints", 1)``) when it was loaded from one, else naming the scenario."""
    if scenario.source is None:
        return f"scenario {scenario.name!r}: {message}"
    return locate(scenario.source.marks, scenario.source.path, field, message)
