"""Running a planner, or a scenario's, in a station: :func:`simulate`, a straight sequence of
steps over :class:`RunSettings` (the target's own settings with the caller's replacements):
check them, check the task before the motion, build the station (:mod:`drake_traj.station.loop`)
and its simulator, run it (:func:`~drake_traj.station.run_station`) and make the result
(:meth:`SimulationResult.from_station <drake_traj.results.result.SimulationResult.from_station>`)."""

import dataclasses
import time
from dataclasses import dataclass
from pathlib import Path

from pydrake.geometry import Meshcat
from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator, SimulatorConfig
from pydrake.systems.framework import Diagram, DiagramBuilder

from drake_traj.cell import Cell
from drake_traj.cell.clearance import CellChecker
from drake_traj.planners.base import PlannerSystem
from drake_traj.results import DEFAULT_TRACKING_TOLERANCE, SimulationResult
from drake_traj.robots import Robot
from drake_traj.robots.custom import robot_label
from drake_traj.scenario import (ControllerGains, Scenario, SpeedOverride, check_cell_tcp, check_planned_duration,
                                 check_start_torques, default_simulator_config)
from drake_traj.scenario import preflight as scenario_preflight
from drake_traj.station.loop import add_speed_override, build_station, speed_override_source, station_robot
from drake_traj.station.run import run_station
from drake_traj.validation import (callable_or_none, flag, instance_of, positive_scalar, realtime_rate, run_duration,
                                   settle_duration, step_size, tracking_tolerance_check)

__all__ = ["RunSettings", "simulate"]


@dataclass(frozen=True)
class RunSettings:
    """What :func:`simulate` runs a planner with, each field one of its keyword arguments. The
    defaults are a planner's (:meth:`for_planner`); a scenario sets its own (:meth:`from_scenario`).

    Fields:
        name: the run's name (the result's).
        robot: the robot (None: the one the planner was made for, else the UR10e;
            :func:`~drake_traj.station.loop.station_robot`).
        gains: PD gains and feed-forward choice (None: the robot's gains, with feed-forward).
        plant_config: the plant's configuration (None: :func:`~drake_traj.scenario.default_plant_config`).
        simulator_config: integration scheme, step, accuracy and real-time rate (None:
            :func:`~drake_traj.scenario.default_simulator_config`).
        log_period: the loggers' period [s].
        settle_time: how long the run goes on after the planner has finished [s].
        max_duration: where the run stops if the planner has not finished [s].
        speed_override: a constant in [0, 1] or a :class:`~drake_traj.scenario.SpeedOverride`
            profile (None: unconnected, 1).
        tracking_tolerance: the largest TCP distance from the reference [m] (None: no such check).
        cell: the robot's cell and tool (None: :class:`~drake_traj.cell.Cell`, a table flush with
            the base).
        cell_directory: the folder relative model files of ``cell.directives`` are taken from
            (None: the working directory).
    """

    name: str = "run"
    robot: Robot | None = None
    gains: ControllerGains | None = None
    plant_config: MultibodyPlantConfig | None = None
    simulator_config: SimulatorConfig | None = None
    log_period: float = 1e-3
    settle_time: float = 0.5
    max_duration: float = 120.0
    speed_override: float | SpeedOverride | None = None
    tracking_tolerance: float | None = DEFAULT_TRACKING_TOLERANCE
    cell: Cell | None = None
    cell_directory: Path | None = None

    @classmethod
    def for_planner(cls, planner: PlannerSystem) -> "RunSettings":
        """A planner system's defaults; TypeError unless ``planner`` is a PlannerSystem."""
        instance_of(planner, PlannerSystem, "planner", hint=" or a Scenario")
        return cls()

    @classmethod
    def from_scenario(cls, scenario: Scenario) -> tuple[PlannerSystem, "RunSettings"]:
        """A new planner of ``scenario`` (:func:`~drake_traj.scenario.make_planner`) and the
        scenario's settings (:meth:`Scenario.station_arguments` and :meth:`Scenario.run_settings`)."""
        arguments = scenario.station_arguments() | scenario.run_settings()
        return arguments.pop("planner"), cls(**arguments)

    def station_arguments(self) -> dict:
        """The keyword arguments of :func:`~drake_traj.station.build_station` these settings give."""
        return dict(robot=self.robot, gains=self.gains, plant_config=self.plant_config, log_period=self.log_period,
                    cell=self.cell, cell_directory=self.cell_directory)


RUN_SETTINGS = tuple(field.name for field in dataclasses.fields(RunSettings))


def run_target(target: PlannerSystem | Scenario, overrides: dict) -> tuple[PlannerSystem, Scenario | None, RunSettings]:
    """The planner to run, the scenario it comes from (None for a planner given as such) and the
    run's settings: the target's, each replaced by one of ``overrides``. TypeError for a key that
    is not a :class:`RunSettings` field (as for any unknown keyword argument), for ``robot``
    beside a scenario (it names its own) and for a target that is neither."""
    unknown = [key for key in overrides if key not in RUN_SETTINGS]
    if unknown:
        raise TypeError(f"simulate() got an unexpected keyword argument {unknown[0]!r}")
    if isinstance(target, Scenario):
        if "robot" in overrides:
            raise TypeError(f"robot must not be given with a scenario: scenario {target.name!r} names its robot "
                            f"({robot_label(target.robot)})")
        planner, settings = RunSettings.from_scenario(target)
        return planner, target, dataclasses.replace(settings, **overrides)
    return target, None, dataclasses.replace(RunSettings.for_planner(target), **overrides)


def checked_settings(planner: PlannerSystem, settings: RunSettings, *, meshcat, progress, add_systems, before_run,
                     preflight) -> RunSettings:
    """``settings`` with the robot the planner runs on (:func:`station_robot`), once every
    argument of :func:`simulate` is checked (TypeError or ValueError naming the first one that is
    wrong), before the planner goes into a diagram (a planner is used in one diagram only)."""
    robot = station_robot(planner, settings.robot)
    if settings.cell is not None:
        instance_of(settings.cell, Cell, "cell")
        check_cell_tcp(robot, settings.cell)  # the cell's TCP is the robot's, or it would be ignored
    instance_of(settings.name, str, "name")
    simulator_config = settings.simulator_config
    if simulator_config is not None:
        instance_of(simulator_config, SimulatorConfig, "simulator_config")
    if meshcat is not None:
        instance_of(meshcat, Meshcat, "meshcat")
    if simulator_config is not None:
        realtime_rate(simulator_config.target_realtime_rate, "simulator_config.target_realtime_rate")
        step_size(simulator_config.max_step_size, "simulator_config.max_step_size")
    run_duration(settings.max_duration)
    settle_duration(settings.settle_time)
    if settings.tracking_tolerance is not None:
        positive_scalar(settings.tracking_tolerance, "tracking_tolerance", "m")
        tracking_tolerance_check(settings.tracking_tolerance, (settings.cell or Cell()).clearance)
    speed_override_source(settings.speed_override)
    callable_or_none(progress, "progress", "progress(t)")
    callable_or_none(add_systems, "add_systems", "add_systems(builder, station)")
    callable_or_none(before_run, "before_run", "before_run(simulator)")
    flag(preflight, "preflight")
    return dataclasses.replace(settings, robot=robot)


def check_task(planner: PlannerSystem, scenario: Scenario | None, settings: RunSettings, preflight: bool) -> None:
    """With ``preflight``, the whole task checked before the motion as ``drake-traj run`` checks
    it: a scenario's in its own cell by :func:`drake_traj.scenario.preflight` (refusals located
    in its file), else :meth:`PlannerSystem.preflight`, the drives at the start and the planned
    motion in the run's cell. A scenario's ``max_duration`` shorter than the planned motion is
    refused either way."""
    if preflight and scenario is not None and settings.cell is scenario.cell \
            and settings.cell_directory == scenario.directory():
        scenario_preflight(scenario, planner, settings.max_duration)  # its errors located in the scenario file
    elif preflight:
        planner.preflight(settings.max_duration)
        checker = CellChecker(settings.robot, settings.cell, settings.cell_directory)
        check_start_torques(checker, planner.initial_positions())  # drives that cannot hold the start
        checker.check_planner(planner)
    if scenario is not None:
        check_planned_duration(scenario, planner)


def station_simulator(planner: PlannerSystem, settings: RunSettings, *, meshcat: Meshcat | None, add_systems,
                      check_motion: bool) -> tuple[Simulator, Diagram]:
    """The simulator (its integrator ``settings.simulator_config``) of a diagram of the
    planner's station, its speed override source and the systems of ``add_systems``; and the
    station."""
    builder = DiagramBuilder()
    station = builder.AddSystem(build_station(planner, meshcat=meshcat, check_motion=check_motion,
                                              **settings.station_arguments()))
    add_speed_override(builder, station, settings.speed_override)
    if add_systems is not None:
        add_systems(builder, station)
    simulator = Simulator(builder.Build())
    ApplySimulatorConfig(settings.simulator_config or default_simulator_config(), simulator)
    return simulator, station


def run_recorded(simulator: Simulator, station: Diagram, settings: RunSettings, *, before_run,
                 progress) -> SimulationResult:
    """Initialize ``simulator``, call ``before_run(simulator)``, run the station
    (:func:`run_station`; recorded in Meshcat where it has a visualizer) and return its result.
    Ctrl-C while it runs: the KeyboardInterrupt goes on, carrying the result so far (``result``)."""
    visualizer = station.GetSubsystemByName("visualizer") if station.HasSubsystemNamed("visualizer") else None
    if visualizer is not None:
        visualizer.StartRecording(True)  # and draw live
    simulator.Initialize()
    if before_run is not None:
        before_run(simulator)
        simulator.ResetStatistics()  # the real-time rate counts from here, not from Initialize()
    start = time.perf_counter()
    stopped = None
    try:
        failure = run_station(simulator, station, settle_time=settings.settle_time, max_duration=settings.max_duration,
                              progress=progress)
    except KeyboardInterrupt as interrupted:  # stopped while it ran: run_station says where (``failure``)
        failure, stopped = interrupted.failure, interrupted
    wall_time = time.perf_counter() - start
    if visualizer is not None:
        visualizer.StopRecording()
        visualizer.PublishRecording()
    result = SimulationResult.from_station(station, station.GetMyContextFromRoot(simulator.get_context()),
                                           name=settings.name, failure=failure, wall_time=wall_time,
                                           tracking_tolerance=settings.tracking_tolerance)
    if stopped is not None:
        stopped.result = result
        stopped.add_note(f"{failure}: the run so far is this KeyboardInterrupt's .result (a failed run; "
                         ".result.save(folder) keeps it)")
        raise stopped
    return result


def simulate(planner: PlannerSystem | Scenario, *, meshcat: Meshcat | None = None, progress=None, add_systems=None,
             before_run=None, preflight: bool = True, **overrides) -> SimulationResult:
    """Run a planner, or a scenario's, in a station until it finishes, plus ``settle_time`` [s].

    Given a :class:`~drake_traj.scenario.Scenario` (``simulate(load_scenario("quintic_ptp"))``),
    this is ``drake-traj run`` without the files: the scenario's planner, robot, gains, plant,
    log period, integrator, speed override, tolerance and times, each replaced by an argument
    given here (except ``robot``: the scenario names its own), and a ``max_duration`` shorter
    than the planned motion refused before the run as the command line refuses it. Given a
    planner system, the defaults are the robot it was made for (else the UR10e;
    :func:`~drake_traj.station.loop.station_robot`), the robot's gains, our plant and integrator
    (None: the same), 1 ms logs, 0.5 s settle time, 120 s at most, no speed override and a 5 mm
    tracking tolerance (:class:`RunSettings`).

    The run stops at ``max_duration`` [s] (at most 600 s; the preflight looks as far ahead) if
    the planner has not finished; ``settle_time`` is at most 60 s. Whatever stops the run
    early (an exception from a planner, a timeout) is caught: the result holds everything logged
    up to that point and ``failure`` gives the reason. Ctrl-C while it simulates stops the script
    as any Ctrl-C does (the KeyboardInterrupt goes on), with the run so far kept in the
    exception's ``result`` attribute: a failed run, ``failure.cause`` "interrupted" (``except
    KeyboardInterrupt as stop: partial = getattr(stop, "result", None)``; None where Ctrl-C came
    before the motion). With
    ``meshcat``, the run is recorded there (see :func:`drake_traj.station.meshcat.export_html`).

    Args (the rest as :func:`~drake_traj.station.add_station`):
        progress: called with the simulated time [s] as the run goes (see :func:`run_station`).
        add_systems: ``add_systems(builder, station)`` adds systems around the station before the
            diagram is built (e.g. a speed-override source of one's own).
        before_run: ``before_run(simulator)`` is called once the simulator is initialized (the
            robot drawn at its start), before the motion (e.g. to wait for a browser).
        preflight: check the whole task before the motion, as ``drake-traj run`` does
            (:meth:`PlannerSystem.preflight`, then the planned motion in the cell:
            :meth:`CellChecker.check_planner <drake_traj.cell.clearance.CellChecker.check_planner>`;
            a :class:`~drake_traj.errors.PlanningError`, e.g. a
            :class:`~drake_traj.cell.clearance.CollisionError`, is raised before the run, not
            recorded as a failed run; False: an unchecked run, said explicitly, where the run
            finds what fails: the station's ``check_motion=False``).
        overrides: any field of :class:`RunSettings`, replacing the planner's default or the
            scenario's own: ``name``, ``robot``, ``gains``, ``plant_config``,
            ``simulator_config`` (integration scheme, step, accuracy and real-time rate),
            ``log_period``, ``settle_time``, ``max_duration``, ``speed_override`` (a constant in
            [0, 1] or a :class:`SpeedOverride` profile on the station's ``speed_override`` input),
            ``tracking_tolerance`` (the run fails if the TCP strays further from the reference
            [m], or if a joint's torque saturates; None: no such check; see
            :meth:`SimulationResult.execution_failure`), ``cell`` (a scenario's own by default;
            for a planner, a table flush with the base: :class:`~drake_traj.cell.Cell`) and
            ``cell_directory`` (a scenario's: its file's folder; else the working directory).

    Every argument is checked before the run (TypeError or ValueError naming it; TypeError for a
    keyword that is none of these).
    """
    planner, scenario, run = run_target(planner, overrides)
    run = checked_settings(planner, run, meshcat=meshcat, progress=progress, add_systems=add_systems,
                           before_run=before_run, preflight=preflight)
    check_task(planner, scenario, run, preflight)
    simulator, station = station_simulator(planner, run, meshcat=meshcat, add_systems=add_systems,
                                           check_motion=preflight)
    return run_recorded(simulator, station, run, before_run=before_run, progress=progress)
