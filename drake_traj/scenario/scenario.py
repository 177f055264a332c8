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

This module holds the types, where a scenario was read from (:class:`ScenarioSource`,
:func:`locate_in_scenario`) and the scenario's planner (:func:`make_planner`, which
:meth:`Scenario.station_arguments` uses). :func:`~drake_traj.scenario.shipped.load_scenario` takes
a file or a shipped scenario's name, as ``drake-traj run`` does (:mod:`.shipped`, reading the file
with :mod:`.loading`); :func:`~drake_traj.scenario.checks.preflight` checks the whole task before
the motion (:mod:`.checks`), with errors located in the file. The station (``drake_traj.station``)
is built from these types.
"""

import numbers
import re
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlantConfig
from pydrake.systems.analysis import GetIntegrationSchemes, SimulatorConfig
from pydrake.systems.framework import DiagramBuilder
from pydrake.trajectories import PiecewisePolynomial

from drake_traj.cell import Cell, CellChecker
from drake_traj.errors import Cause, DrakeTrajError, Field, field_text, joint_label
from drake_traj.planners import PLANNER_CONFIGS, PlannerConfig, PlannerSystem, QuinticConfig, make_planner as make_planner_from_config
from drake_traj.results import DEFAULT_TRACKING_TOLERANCE
from drake_traj.robots import Robot
from drake_traj.robots.custom import RobotChoice, resolve_robot
from drake_traj.validation import (flag, instance_of, invalid, log_period_check, real_array, realtime_rate,
                                   run_duration, settle_duration, step_size, tracking_tolerance_check)
from drake_traj.scenario.yaml_schema import ScenarioError, locate

__all__ = [
    "ControllerGains", "Scenario", "ScenarioSource", "SpeedOverride", "default_plant_config", "default_simulator_config",
    "locate_in_scenario", "make_planner",
]

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
        """The :class:`~drake_traj.cell.clearance.CellChecker` of this scenario's robot in its cell;
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
        raise in_planner_field(scenario, error, message_leads_with_field=True) from error
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


def in_planner_field(scenario: Scenario, error: ValueError, *, message_leads_with_field: bool) -> DrakeTrajError:
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
