"""Typed scenarios, loaded from YAML with pydrake's ``yaml_load_typed`` (files in ``diagrams/``).

A scenario names the robot, its start configuration, the planner and its parameters (one of the
planners' config dataclasses, chosen by a YAML tag such as ``planner: !PajakConfig``), the PD
controller and the simulation settings. A file holds either one scenario or several named
variants (top-level keys; keys starting with ``_`` hold shared YAML anchors and are not variants).
Unknown keys, wrong lengths and non-finite or out-of-range numbers raise ValueError naming the
file and the field.
"""

from dataclasses import dataclass, field, fields
from pathlib import Path

import numbers
import re

import numpy as np
from pydrake.common.yaml import yaml_load_typed
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlantConfig
from pydrake.systems.analysis import GetIntegrationSchemes, SimulatorConfig
from pydrake.systems.framework import DiagramBuilder

from drake_traj.station import ControllerGains, SpeedOverride, default_plant_config, default_simulator_config
from drake_traj.data import data_directory
from drake_traj.planners import PLANNER_CONFIGS, PlannerConfig, PlannerSystem, QuinticConfig
from drake_traj.planners import make_planner as make_planner_from_config
from drake_traj.result import DEFAULT_TRACKING_TOLERANCE
from drake_traj.robots import get_robot
from drake_traj.validation import instance_of, log_period_check, path_argument, real_array
from drake_traj.yaml_schema import ScenarioError, checked_document, locate

__all__ = [
    "Scenario", "ScenarioError", "ShippedScenario", "default_scenario_path", "find_scenario", "load_scenario",
    "locate_in_scenario", "make_planner", "scenario_variants", "shipped_scenarios",
]

DEFAULT_SCENARIO = ("pajak.yaml", "sim3")  # what ``drake-traj run`` runs when given no scenario
_PLAIN_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,99}")
# The coarsest plant step and log period a run is checked with [s]: the UR controller runs at
# 2 ms, and the limits and the continuity of q̈ are checked at the logged samples.
MAX_TIME_STEP = MAX_LOG_PERIOD = 0.01


@dataclass
class Scenario:
    """One experiment: robot, start, planner, controller and simulation settings (times in seconds).

    Attributes:
        name: a plain name (letters, digits, ``_``, ``-``, ``.``): the default output folder.
        description: one line on what the scenario runs.
        robot: a name of :data:`drake_traj.robots.ROBOT_NAMES` ("ur10e", "li_4dof" of Li et al.
            2019, or Boryga's "anthropomorphic", "scara", "cartesian").
        q_initial: the robot's start [rad or m]; empty: its home configuration (the UR10e's is the
            start of Pająk 2024's task). Planners that follow a tool path on the papers' robots
            start from the inverse kinematics of the path instead.
        planner: the planner's config (see :data:`drake_traj.planners.PLANNER_CONFIGS`).
        controller: PD gains (empty: the robot's defaults) and the feed-forward choice.
        plant: Drake's ``MultibodyPlantConfig`` of the robot plant (default: discrete at 1 ms,
            SAP); ``plant: {time_step: 0.002}`` runs at the UR controller's 500 Hz.
        simulator: Drake's ``SimulatorConfig`` (integration scheme, step, accuracy, real-time
            rate; default fixed-step RK2 at 1 ms, see ``station.default_simulator_config``).
        log_period: the loggers' period [s], a whole multiple of ``plant.time_step``; 0 (the
            default): the plant's time step.
        speed_override: a speed-override profile (times [s], values in [0, 1]), like a pendant's
            speed slider; empty: none.
        tracking_tolerance: the run fails if the measured TCP is ever further than this from the
            reference [m] (default 5 mm: 40x the shipped scenarios' worst, 0.13 mm).
        settle_time: how long the run goes on after the planner finishes [s].
        max_duration: the run stops with a failure if the planner has not finished by then [s].
    """

    name: str = "unnamed"
    description: str = ""
    robot: str = "ur10e"
    q_initial: list[float] = field(default_factory=list)
    planner: PlannerConfig = field(default_factory=QuinticConfig)
    controller: ControllerGains = field(default_factory=ControllerGains)
    plant: MultibodyPlantConfig = field(default_factory=default_plant_config)
    simulator: SimulatorConfig = field(default_factory=default_simulator_config)
    log_period: float = 0.0
    speed_override: SpeedOverride = field(default_factory=SpeedOverride)
    tracking_tolerance: float = DEFAULT_TRACKING_TOLERANCE
    settle_time: float = 0.5
    max_duration: float = 120.0

    def start_configuration(self) -> np.ndarray:
        """``q_initial``, or the robot's home configuration when it is empty."""
        q = real_array(self.q_initial, "q_initial", "rad or m")
        return get_robot(self.robot).home_configuration if q.size == 0 else q

    def validate(self) -> None:
        """Raise ValueError naming the first field that is malformed (the message starts with
        the field's path)."""
        if not _PLAIN_NAME.fullmatch(self.name) or ".." in self.name:
            raise ValueError(f"name must be a plain name (letters, digits, _ . -; no path; at most 100 characters), "
                             f"got {self.name[:120]!r}: it names the default output folder out/<name>")
        try:
            robot = get_robot(self.robot)
        except ValueError as error:
            raise ValueError(f"robot: {error}") from None
        n = robot.num_joints
        q = self.start_configuration()
        if q.shape != (n,):
            raise ValueError(f"q_initial must have {n} entries for robot {robot.name}, got shape {q.shape}")
        if not np.all(np.isfinite(q)):
            raise ValueError(f"q_initial must be finite, got {self.q_initial}")
        lower, upper = robot.lower_limits, robot.upper_limits
        outside = np.flatnonzero((q < lower) | (q > upper))
        if len(outside):
            j = outside[0]
            unit = robot.joint_unit(j)
            raise ValueError(
                f"q_initial[{j}] = {q[j]} {unit} is outside the joint range [{lower[j]:.6f}, {upper[j]:.6f}] {unit}"
            )
        for label, value in (("plant.time_step", self.plant.time_step), ("log_period", self.logging_period()),
                             ("max_duration", self.max_duration), ("settle_time", self.settle_time),
                             ("simulator.max_step_size", self.simulator.max_step_size),
                             ("tracking_tolerance", self.tracking_tolerance)):
            smallest_allowed = 0.0 if label == "settle_time" else np.nextafter(0.0, 1.0)
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise ValueError(f"{label} must be a number, got {type(value).__name__} {value!r:.40}")
            if not np.isfinite(value) or value < smallest_allowed:
                unit = "metres" if label == "tracking_tolerance" else "seconds"
                raise ValueError(f"{label} must be a finite, positive number of {unit}, got {value}")
        for label, value, largest in (("plant.time_step", self.plant.time_step, MAX_TIME_STEP),
                                      ("log_period", self.logging_period(), MAX_LOG_PERIOD)):
            if value > largest:
                raise ValueError(f"{label} must be at most {largest:g} s (the UR controller's cycle is 0.002 s, and "
                                 f"limits are checked at the logged samples), got {value:g} s")
        log_period_check(self.logging_period(), self.plant.time_step)
        if self.logging_period() > self.max_duration:
            raise ValueError(f"max_duration ({self.max_duration:g} s) must be longer than log_period "
                             f"({self.logging_period():g} s): the run would log one sample")
        if self.simulator.integration_scheme not in GetIntegrationSchemes():
            raise ValueError(f"simulator.integration_scheme must be one of {GetIntegrationSchemes()}, "
                             f"got {self.simulator.integration_scheme!r}")
        try:  # Drake checks the plant's options (contact model, approximation, ...) when it adds the plant
            AddMultibodyPlant(self.plant, DiagramBuilder())
        except RuntimeError as error:
            raise ValueError(f"plant: {error}") from None
        self.controller.for_robot(robot)
        self.speed_override.validate()

    def station_arguments(self) -> dict:
        """The keyword arguments of :func:`drake_traj.station.build_station` for this scenario
        (its planner made by :func:`make_planner`)."""
        return dict(planner=make_planner(self), robot=get_robot(self.robot), gains=self.controller,
                    plant_config=self.plant, log_period=self.logging_period())

    def logging_period(self) -> float:
        """``log_period``, or the plant's time step where it is 0 [s]."""
        return self.log_period if self.log_period != 0 else self.plant.time_step


def shipped_directory() -> Path:
    """The folder of the scenario files shipped with the package (``diagrams/``)."""
    return data_directory("diagrams")


def default_scenario_path() -> Path:
    """The scenario file ``drake-traj run`` uses when none is given (its variant: ``sim3``)."""
    return shipped_directory() / DEFAULT_SCENARIO[0]


@dataclass(frozen=True)
class ShippedScenario:
    """A scenario shipped with the package: its name, file, variant (None for a file of one
    scenario) and one-line description."""

    name: str
    path: Path
    variant: str | None
    description: str


def shipped_scenarios() -> list[ShippedScenario]:
    """Every scenario of the shipped files, in file order."""
    entries = []
    for path in sorted(shipped_directory().glob("*.yaml")):
        for variant in scenario_variants(path) or [None]:
            scenario = load_scenario(path, variant)
            entries.append(ShippedScenario(scenario.name, path, variant, scenario.description))
    return entries


def find_scenario(reference: str, variant: str | None = None) -> tuple[Path, str | None]:
    """(file, variant) of a scenario given as a path, or as the name of a shipped scenario
    (``pajak_sim3``) or of a shipped file (``pajak``, with ``variant``)."""
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
        raise ValueError(f"scenario file {path} not found")
    shipped = shipped_scenarios()
    for entry in shipped:
        if entry.name == reference and variant in (None, entry.variant):
            return entry.path, entry.variant
    stem = shipped_directory() / f"{reference}.yaml"
    if stem.is_file():
        return stem, variant
    names = ", ".join(entry.name for entry in shipped)
    raise ValueError(f"no scenario file {reference!r} and no shipped scenario of that name; "
                     f"shipped: {names} (drake-traj list)")


def _is_shipped_name(reference: str) -> bool:
    """True when ``reference`` names a shipped scenario or a shipped file."""
    return (shipped_directory() / f"{reference}.yaml").is_file() or any(
        entry.name == reference for entry in shipped_scenarios())


def scenario_variants(path) -> list[str]:
    """The variant names of a scenario file; empty when the file is one scenario."""
    return list(checked_document(Path(path), Scenario)[1])


def load_scenario(path, variant: str | None = None) -> Scenario:
    """Read and validate a scenario YAML file (``variant``: the named child of a file of
    variants; it may be left out when the file is one scenario or has a single variant).

    Raises :class:`ScenarioError` (a ValueError) naming the file, the line and the field.
    """
    path = path_argument(path, "path")
    if variant is not None:
        instance_of(variant, str, "variant")
    if not path.is_file():
        what = "is a folder, not a scenario file" if path.is_dir() else "not found"
        raise ScenarioError(f"scenario file {path} {what}")
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
    try:
        scenario.validate()
    except ValueError as error:
        raise ScenarioError(locate(marks, path, str(error))) from None
    scenario.source = (path, marks)  # for later messages (make_planner); not a YAML field
    return scenario


def make_planner(scenario: Scenario, *others) -> PlannerSystem:
    """The planner system the scenario describes, its limits checked against the robot's rated
    joint speeds (errors name the scenario and the ``planner`` field).

    This is ``drake_traj.make_planner``; a planner from a planner config (``QuinticConfig``, ...)
    is :func:`drake_traj.planners.make_planner` ``(config, robot, q_initial)`` (given a config or
    more arguments, this one raises a TypeError saying so).
    """
    if others or isinstance(scenario, PLANNER_CONFIGS):
        more = f" and {len(others)} more argument{'s' * (len(others) > 1)}" if others else ""
        raise TypeError(f"scenario must be a Scenario, got {type(scenario).__name__}{more}: drake_traj.make_planner(scenario) "
                        "makes a scenario's planner; make one from a planner config with "
                        "drake_traj.planners.make_planner(config, robot, q_initial)")
    instance_of(scenario, Scenario, "scenario", hint=" (load one with drake_traj.load_scenario(path, variant))")
    robot = get_robot(scenario.robot)
    q_initial = scenario.start_configuration()  # its errors name q_initial, not the planner
    try:
        planner = make_planner_from_config(scenario.planner, robot, q_initial)
    except ValueError as error:
        first_word = re.match(r"[A-Za-z_]\w*", str(error))
        field = first_word is not None and first_word.group(0) in {item.name for item in fields(scenario.planner)}
        raise type(error)(locate_in_scenario(scenario, f"planner{'.' if field else ': '}{error}")) from error
    velocity = np.broadcast_to(planner.velocity_limit, (robot.num_joints,))
    above = np.flatnonzero(velocity > robot.velocity_limits * (1 + 1e-9))
    if len(above):
        j = int(above[0])
        unit = robot.joint_unit(j)
        raise ValueError(locate_in_scenario(scenario,
            f"planner.velocity_limit[{j}] = {velocity[j]:g} {unit}/s is above the rated "
            f"speed of the {robot.name}'s joint {j + 1} ({robot.joint_names[j]}), {robot.velocity_limits[j]:g} {unit}/s: "
            "the arm could not follow"))
    return planner


def locate_in_scenario(scenario: Scenario, message: str) -> str:
    """``message`` located in the scenario's file (and the line of the field it starts with, e.g.
    ``planner.waypoints[1]: ...``) when it was loaded from one."""
    source = getattr(scenario, "source", None)
    return locate(source[1], source[0], message) if source else f"scenario {scenario.name!r}: {message}"
