"""The station: a planner driving a PD-controlled robot plant, with loggers, as one Drake Diagram.

Built the way Drake's own examples build a station: :func:`add_station` adds the parts to a
``DiagramBuilder`` and returns handles; :func:`build_station` wraps them in a Diagram named
``station`` with exported ports; :func:`make_station` does that for a scenario. :func:`simulate`
is a thin function over these pieces and :meth:`SimulationResult.from_station
<drake_traj.result.SimulationResult.from_station>`; a user's own ``Simulator`` over a station
gives the same result.

The loop: the planner's reference one plant step ahead, [q + h q̇ + h²/2 q̈; q̇ + h q̈] (a
``Multiplexer`` and a ``MatrixGain``: the plant's implicit PD compares the desired state sampled
at t_k with the state it computes for t_k + h; without this lookahead the arm lags the reference by
|q̇| h, 1 mrad at 1 rad/s), is the target of the plant's own PD-controlled actuators
(``JointActuator.set_controller_gains``: the discrete SAP solver treats the PD terms implicitly, so
stiff gains stay stable at the 1 ms step even on the light wrist links, and the total torque
saturates at each joint's effort limit like a real drive). The feed-forward on the actuation
input is gravity compensation g(q) or, with ``feedforward_acceleration``, the full inverse
dynamics M(q) q̈_ref + C(q, q̇) q̇ - τ_g(q) (Drake's ``InverseDynamics``). Only the planner is a
Python system in the per-step path; the TCP pose is an output computed when asked for, and the
result computes it from the logged states after the run.

Subsystems by name: ``planner``, ``plant``, ``scene_graph``, ``acceleration_and_scaling`` (a
``Demultiplexer`` of the planner's [q̈; c] port: one Python call per step serves the plant, the
loggers and the exported ports), ``lookahead_mux`` and ``lookahead`` (the one-step lookahead),
``feedforward`` (inverse dynamics), ``tcp_pose``, the loggers of
:data:`drake_traj.result.LOGGERS` and, with Meshcat, ``visualizer``. The station's exported ports
are declared in :func:`build_station`'s docstring.
"""

import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydrake.geometry import Meshcat, MeshcatVisualizer, MeshcatVisualizerParams
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlant, MultibodyPlantConfig
from pydrake.multibody.tree import PdControllerGains
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator, SimulatorConfig
from pydrake.systems.controllers import InverseDynamics
from pydrake.systems.framework import Diagram, DiagramBuilder, LeafSystem, TriggerType
from pydrake.systems.primitives import (ConstantVectorSource, Demultiplexer, LogVectorOutput, MatrixGain,
                                        Multiplexer, TrajectorySource)

from drake_traj.cell import Cell, MotionGuard, add_cell, refuse_free_bodies
from drake_traj.cell.clearance import CellChecker, geometry_owner, scene_fingerprint, unprotected_links
from drake_traj.errors import Cause, Failure
from drake_traj.planners.base import PlannerSystem
from drake_traj.results import DEFAULT_TRACKING_TOLERANCE, LOGGERS, SimulationResult
from drake_traj.robots import UR10E, Robot
from drake_traj.robots.base import joint_actuators
from drake_traj.robots.custom import robot_label
from drake_traj.scenario import (ControllerGains, Scenario, SpeedOverride, check_cell_tcp, check_planned_duration,
                                 check_start_torques, default_plant_config, default_simulator_config)
from drake_traj.scenario import preflight as scenario_preflight
from drake_traj.validation import (callable_or_none, flag, instance_of, invalid, log_period_check, positive_scalar,
                                   real_scalar, realtime_rate, run_duration, settle_duration, step_size,
                                   tracking_tolerance_check)

__all__ = [
    "Station", "add_speed_override", "add_station", "build_station", "make_station", "run_station", "simulate",
]


def speed_override_source(speed_override) -> LeafSystem | None:
    """The source of a constant speed override in [0, 1] or of a :class:`SpeedOverride` profile;
    None for None or an empty profile. Raises ValueError naming ``speed_override``."""
    if speed_override is None or (isinstance(speed_override, SpeedOverride) and not np.size(speed_override.times)):
        return None
    if isinstance(speed_override, SpeedOverride):
        return TrajectorySource(speed_override.trajectory())
    value = real_scalar(speed_override, "speed_override", "a constant in [0, 1] or a SpeedOverride")
    if not 0.0 <= value <= 1.0:
        raise invalid("speed_override", f"speed_override must be in [0, 1], got {speed_override}")
    return ConstantVectorSource([value])


def add_speed_override(builder: DiagramBuilder, station: Diagram, speed_override) -> None:
    """Drive ``station``'s ``speed_override`` input from a constant in [0, 1] or a
    :class:`SpeedOverride` profile; None or an empty profile leaves it unconnected (1)."""
    source = speed_override_source(speed_override)
    if source is None:
        return
    builder.AddNamedSystem("speed_override", source)
    builder.Connect(source.get_output_port(), station.GetInputPort("speed_override"))


class TcpPose(LeafSystem):
    """The measured tool pose from the plant state [q; q̇] (``robot.tcp_pose``), 6 values."""

    def __init__(self, robot: Robot):
        super().__init__()
        self.robot = robot
        n = robot.num_joints
        self._state = self.DeclareVectorInputPort("state", 2 * n)
        self.DeclareVectorOutputPort(
            "pose", 6, lambda context, out: out.SetFromVector(robot.tcp_pose(self._state.Eval(context)[:n])))


@dataclass
class Station:
    """Handles to the parts :func:`add_station` added to a builder."""

    planner: PlannerSystem
    robot: Robot
    plant: MultibodyPlant
    scene_graph: object
    instance: object  # the robot's ModelInstanceIndex
    tcp_pose: TcpPose
    loggers: dict  # name (see drake_traj.result.LOGGERS) -> VectorLogSink
    visualizer: MeshcatVisualizer | None


def station_robot(planner: PlannerSystem, robot: Robot | None = None) -> Robot:
    """The robot a station runs ``planner`` on: ``robot``, or where None the one the planner was
    made for (:attr:`PlannerSystem.robot`), else the UR10e. TypeError or ValueError naming
    ``robot`` when it is not a Robot, has another joint count than the planner, or is another
    robot than the one the planner was made for (its motion is that robot's)."""
    made_for = planner.robot
    robot = made_for or UR10E if robot is None else instance_of(robot, Robot, "robot")
    if planner.num_joints != robot.num_joints:
        raise invalid("robot", f"the planner has {planner.num_joints} joints, robot {robot.name} has {robot.num_joints}")
    if made_for is not None and made_for.name != robot.name:
        raise invalid("robot", f"the planner was made for the {made_for.name} robot, not for robot {robot.name}: make it "
                               f"for {robot.name} (make_planner(config, robot, q_initial)) or run it on {made_for.name}")
    return robot


def add_station(
    builder: DiagramBuilder,
    planner: PlannerSystem,
    *,
    robot: Robot | None = None,
    gains: ControllerGains | None = None,
    plant_config: MultibodyPlantConfig | None = None,
    log_period: float = 1e-3,
    meshcat: Meshcat | None = None,
    cell: Cell | None = None,
    cell_directory: Path | None = None,
    before_finalize=None,
    check_motion: bool = True,
) -> Station:
    """Add ``planner``, the PD-controlled ``robot`` plant, the feed-forward, the loggers (and a
    Meshcat visualizer) to ``builder`` (see the module docstring for the wiring and the names).

    The plant's default positions are the planner's start, so a fresh context is consistent.

    Args:
        planner: any system under the planner contract, with n = ``robot.num_joints`` joints.
        robot: the robot (default: the one the planner was made for, else the UR10e;
            :func:`station_robot`).
        gains: PD gains and feed-forward choice (default: the robot's gains, with feed-forward).
        plant_config: the plant's configuration (default :func:`default_plant_config`).
        log_period: the loggers' period [s]: they sample at k * log_period from t = 0.
        meshcat: when given, the robot and its cell are drawn there.
        cell: the robot's cell and tool (default :class:`~drake_traj.cell.Cell`: a table flush
            with the base, no tool), added to the plant (:func:`~drake_traj.cell.add_cell`).
        cell_directory: the folder relative model files of ``cell.directives`` are taken from.
        before_finalize: ``before_finalize(plant, scene_graph)`` adds one's own bodies and
            geometry to the plant before it is finalized (the station finalizes it). The cell
            check calls it too, on the plant it checks in: it must add the same bodies to any
            plant it is given.
        check_motion: True (default): the motion starts only once the planner's plan was
            accepted by the cell check in this station's own scene (robot, tool, cell and the
            bodies of ``before_finalize``); where it was not, it is checked when the simulator
            is initialized and refused with the check's error (:mod:`drake_traj.guard`). False
            runs an unchecked plan (the run's in-loop watch stays on).

    A planner system is part of one diagram only (Drake owns it there): a second station needs a
    new planner (``make_planner`` again); ValueError otherwise.
    """
    instance_of(builder, DiagramBuilder, "builder", hint=" (pydrake.systems.framework.DiagramBuilder())")
    instance_of(planner, PlannerSystem, "planner")
    if planner.GetSystemPathname().count("::") > 1:  # "::parent::planner" once built into a diagram
        raise invalid("planner", f"planner is already part of a diagram ({planner.GetSystemPathname()}): a planner system "
                         "can be used in one diagram (one run) only; make a new one for this run (make_planner again)")
    robot = station_robot(planner, robot)
    if meshcat is not None:
        instance_of(meshcat, Meshcat, "meshcat")
    if cell is not None:
        instance_of(cell, Cell, "cell")
    callable_or_none(before_finalize, "before_finalize", "before_finalize(plant, scene_graph)")
    check_motion = flag(check_motion, "check_motion")
    instance_of(gains or ControllerGains(), ControllerGains, "gains")
    gains = (gains or ControllerGains()).for_robot(robot)
    plant_config = instance_of(plant_config or default_plant_config(), MultibodyPlantConfig, "plant_config")
    n = robot.num_joints
    time_step = step_size(plant_config.time_step, "plant.time_step")
    log_period = positive_scalar(log_period, "log_period", "s")
    log_period_check(log_period, time_step)

    plant, scene_graph = AddMultibodyPlant(plant_config, builder)
    instance = robot.add_to_plant(plant)
    actuators = joint_actuators(plant, instance)  # by joint: a model names its actuators as it likes
    if list(actuators) != list(robot.joint_names):  # the plant's desired-state and actuation ports go by actuator
        raise invalid("robot", f"the {robot.name} model's actuators drive the joints {list(actuators)} in this order; the "
                               f"station drives {list(robot.joint_names)}: one actuator per joint, in the joints' order")
    for joint_name, kp, kd in zip(robot.joint_names, gains.kp, gains.kd):
        actuators[joint_name].set_controller_gains(PdControllerGains(p=kp, d=kd))
    # the cell's geometry, the tool's body and payload: contact with them, and between the arm's
    # non-adjacent links, is simulated (and ends the run: run_station)
    fields = add_cell(plant, cell or Cell(), instance, robot=robot, directory=cell_directory)
    if before_finalize is not None:
        before_finalize(plant, scene_graph)
    plant.Finalize()
    refuse_free_bodies(plant, instance, fields)  # the controller drives the robot's joints only
    plant.SetDefaultPositions(instance, planner.initial_positions())
    planner.guard = MotionGuard(robot, cell or Cell(), cell_directory, before_finalize,
                                scene_fingerprint(plant, scene_graph.model_inspector()), check_motion,
                                unprotected_links=tuple(unprotected_links(plant, instance, robot.joint_names)))

    planner.set_name("planner")
    builder.AddSystem(planner)
    mux = builder.AddNamedSystem("lookahead_mux", Multiplexer([2 * n, n]))
    h, eye = time_step, np.eye(n)
    zero = np.zeros((n, n))
    lookahead = builder.AddNamedSystem("lookahead", MatrixGain(np.block([[eye, h * eye, 0.5 * h * h * eye],
                                                                           [zero, eye, h * eye]])))
    # q̈ and c from one Python call per step, split in C++ for the plant and the loggers
    split = builder.AddNamedSystem("acceleration_and_scaling", Demultiplexer([n, 1]))
    builder.Connect(planner.GetOutputPort("acceleration_and_scaling"), split.get_input_port())
    acceleration, scaling = split.get_output_port(0), split.get_output_port(1)
    builder.Connect(planner.GetOutputPort("desired_state"), mux.get_input_port(0))
    builder.Connect(acceleration, mux.get_input_port(1))
    builder.Connect(mux.get_output_port(), lookahead.get_input_port())
    builder.Connect(lookahead.get_output_port(), plant.get_desired_state_input_port(instance))
    mode = (InverseDynamics.InverseDynamicsMode.kInverseDynamics if gains.feedforward_acceleration
            else InverseDynamics.InverseDynamicsMode.kGravityCompensation)
    feedforward = builder.AddNamedSystem("feedforward", InverseDynamics(plant, mode))
    builder.Connect(plant.get_state_output_port(instance), feedforward.get_input_port_estimated_state())
    if gains.feedforward_acceleration:
        builder.Connect(acceleration, feedforward.get_input_port_desired_acceleration())
    builder.Connect(feedforward.get_output_port_generalized_force(), plant.get_actuation_input_port(instance))
    tcp = builder.AddNamedSystem("tcp_pose", TcpPose(robot))
    builder.Connect(plant.get_state_output_port(instance), tcp.get_input_port())

    sources = {
        "reference_logger": planner.GetOutputPort("desired_state"),
        "acceleration_logger": acceleration,
        "scaling_logger": scaling,
        "measured_logger": plant.get_state_output_port(instance),
        "torque_logger": plant.get_net_actuation_output_port(instance),
    }
    assert set(sources) == set(LOGGERS)
    loggers = {}
    for name, port in sources.items():
        loggers[name] = LogVectorOutput(port, builder, {TriggerType.kPeriodic}, log_period)
        loggers[name].set_name(name)
    visualizer = None
    if meshcat is not None:
        visualizer = MeshcatVisualizer.AddToBuilder(
            builder, scene_graph, meshcat, MeshcatVisualizerParams(publish_period=1 / 30))
        visualizer.set_name("visualizer")
    return Station(planner, robot, plant, scene_graph, instance, tcp, loggers, visualizer)


def build_station(planner: PlannerSystem, **kwargs) -> Diagram:
    """The Diagram ``station`` of :func:`add_station` (same keyword arguments) with these exported
    ports (``tests/test_station.py`` checks this list against the built diagram):

    .. pydrake_system::

        name: station
        input_ports:
        - speed_override (optional)
        - applied_generalized_force (optional)
        output_ports:
        - desired_state
        - desired_acceleration
        - scaling
        - measured_state
        - torque
        - tcp_pose

    With n the robot's joint count:

    - ``speed_override`` (1): the planner's speed override in [0, 1]; unconnected means 1.
    - ``applied_generalized_force`` (n): generalized forces added on the joints [N m or N], e.g. a
      disturbance; unconnected means none.
    - ``desired_state`` (2n): the planner's reference [q; q̇] [rad, rad/s].
    - ``desired_acceleration`` (n): the planner's q̈ [rad/s²].
    - ``scaling`` (1): the planner's scaling coefficient c.
    - ``measured_state`` (2n): the plant's [q; q̇].
    - ``torque`` (n): the net actuation of the drives (PD + feed-forward, saturated at the effort
      limits) [N m or N].
    - ``tcp_pose`` (6): the measured tool pose [x, y, z, φ_X, φ_Y, φ_Z] [m, rad], base frame,
      computed only when asked for.
    """
    builder = DiagramBuilder()
    parts = add_station(builder, planner, **kwargs)
    builder.ExportInput(planner.GetInputPort("speed_override"), "speed_override")
    builder.ExportInput(parts.plant.get_applied_generalized_force_input_port(), "applied_generalized_force")
    builder.ExportOutput(planner.GetOutputPort("desired_state"), "desired_state")
    split = builder.GetSubsystemByName("acceleration_and_scaling")
    builder.ExportOutput(split.get_output_port(0), "desired_acceleration")
    builder.ExportOutput(split.get_output_port(1), "scaling")
    builder.ExportOutput(parts.plant.get_state_output_port(parts.instance), "measured_state")
    builder.ExportOutput(parts.plant.get_net_actuation_output_port(parts.instance), "torque")
    builder.ExportOutput(parts.tcp_pose.get_output_port(), "tcp_pose")
    station = builder.Build()
    station.set_name("station")
    return station


def make_station(scenario: Scenario, meshcat: Meshcat | None = None) -> Diagram:
    """The station of a :class:`~drake_traj.scenario.Scenario`: its planner, robot, gains, plant
    configuration and log period. Its motion is checked before it starts, as :func:`simulate`
    checks it (:func:`drake_traj.scenario.preflight`: the task, then the motion in the cell,
    refusals located in the scenario's file), when the simulator is initialized or by
    :func:`run_station`, whichever comes first.

    Simulate it with ``ApplySimulatorConfig(scenario.simulator, simulator)``: a Diagram cannot
    carry its integrator, and a plain ``Simulator`` uses Drake's default (error-controlled RK3),
    not the scenario's (the reference then differs by up to 1.2e-7 rad on ``quintic_ptp`` and
    1.5e-6 rad on ``pajak_sim3``, measured).

    TypeError unless ``scenario`` is a Scenario (load one from a file or a shipped name with
    :func:`~drake_traj.scenario.load_scenario`)."""
    hint = " (load one with drake_traj.load_scenario(name_or_path, variant))"
    instance_of(scenario, Scenario, "scenario", hint=hint if isinstance(scenario, (str, os.PathLike)) else "")
    if meshcat is not None:
        instance_of(meshcat, Meshcat, "meshcat")
    from_scenario = scenario.station_arguments()
    planner = from_scenario.pop("planner")
    station = build_station(planner, meshcat=meshcat, **from_scenario)
    planner.guard.preflight = lambda planner, horizon: scenario_preflight(scenario, planner, horizon)
    return station


def run_station(simulator: Simulator, station: Diagram, *, settle_time: float = 0.5,
                max_duration: float = 120.0, progress=None) -> Failure | None:
    """Advance ``simulator`` (over ``station``, possibly inside a larger diagram) until the
    planner has finished plus ``settle_time`` [s], or ``max_duration`` [s].

    The motion starts only where the planner's plan was accepted by the cell check in the
    station's own scene; where it was not, it is checked first, and a refusal is raised (a
    :class:`~drake_traj.errors.PlanningError`, e.g. a
    :class:`~drake_traj.clearance.CollisionError`) before anything moves, unless the station was
    built with ``check_motion=False`` (:mod:`drake_traj.guard`). While it runs, the measured
    motion is watched (:class:`~drake_traj.guard.ClearanceWatch`): closer than half the clearance
    to anything, between logged samples included, it fails the run naming the bodies and the
    time (cause "collision"), as contact reported by the plant does.

    Any exception from the simulation, and Ctrl-C (KeyboardInterrupt), is caught: the state and
    logs stay as they were when it happened. ``progress(t)`` is called with the simulated time
    every 10 ms of it. Returns None when the planner finished, else the :class:`Failure`
    (cause "interrupted" for Ctrl-C).

    TypeError unless ``simulator`` is a ``Simulator`` and ``station`` a station Diagram in its
    diagram; ValueError for a ``max_duration`` outside (0, 600] s or a ``settle_time`` outside
    [0, 60] s (:data:`~drake_traj.validation.MAX_RUN_DURATION`, ``MAX_SETTLE_TIME``).
    """
    instance_of(simulator, Simulator, "simulator")
    instance_of(station, Diagram, "station", hint=" (make_station(scenario) or build_station(planner))")
    max_duration = run_duration(max_duration)
    settle_time = settle_duration(settle_time)
    callable_or_none(progress, "progress", "progress(t)")
    if not station.HasSubsystemNamed("planner"):
        raise invalid("station", f"station must be a station (make_station, build_station): {station.get_name()!r} has no "
                                 "subsystem named 'planner'")
    planner = station.GetSubsystemByName("planner")
    root = simulator.get_mutable_context()
    try:
        planner_context = planner.GetMyContextFromRoot(root)
    except RuntimeError:
        raise invalid("station", f"station {station.get_name()!r} is not part of the simulator's diagram "
                                 f"({simulator.get_system().get_name()!r})") from None
    guard = planner.guard
    watch = None
    if guard is not None:
        guard.ensure_checked(planner, max_duration)  # a refusal raised before the motion
        watch = guard.watch(station.GetSubsystemByName("measured_logger"), root, planner.num_joints)
    chunk = min(0.01, max(settle_time, 1e-3))  # the finish and contact are checked between chunks
    end = max_duration
    try:
        while root.get_time() < end:
            simulator.AdvanceTo(min(root.get_time() + chunk, end))
            if progress is not None:
                progress(root.get_time())
            touching = (watch.feed() if watch is not None else None) or contact_failure(station, root)
            if touching is not None:
                return touching
            finish = planner.finish_time(planner_context)
            if np.isfinite(finish) and end == max_duration:
                end = min(max(finish + settle_time, root.get_time()), max_duration)
        if np.isfinite(planner.finish_time(planner_context)):
            return None
        return Failure(Cause.TIMEOUT, f"planner did not finish within max_duration = {max_duration} s", root.get_time(),
                       tuple(planner.reference_state(planner_context)[: planner.num_joints].tolist()))
    except KeyboardInterrupt:
        return Failure(Cause.INTERRUPTED, f"interrupted at t = {root.get_time():.4f} s", root.get_time())
    except Exception as error:  # keep the log up to the failure; the reason goes in the result
        return Failure.from_exception(error, root.get_time())


def contact_failure(station: Diagram, root_context) -> Failure | None:
    """A COLLISION :class:`Failure` when the station's plant reports contact (the arm with
    itself, its tool or its cell) in ``root_context``, naming the two bodies, the depth and the
    time; None without contact. Read from the plant's contact results (point pairs and
    hydroelastic surfaces), so a touch shorter than a check's interval may pass unseen."""
    plant = station.GetSubsystemByName("plant")
    plant_context = plant.GetMyContextFromRoot(root_context)
    results = plant.get_contact_results_output_port().Eval(plant_context)
    pairs = [(info.point_pair().id_A, info.point_pair().id_B, -info.point_pair().depth)
             for info in map(results.point_pair_contact_info, range(results.num_point_pair_contacts()))]
    pairs += [(info.contact_surface().id_M(), info.contact_surface().id_N(), float("nan"))
              for info in map(results.hydroelastic_contact_info, range(results.num_hydroelastic_contacts()))]
    if not pairs:
        return None
    inspector = station.GetSubsystemByName("scene_graph").model_inspector()
    robot_instance = plant.get_joint_actuator(plant.GetJointActuatorIndices()[0]).model_instance()  # the robot's drives
    id_a, id_b, distance = min(pairs, key=lambda pair: pair[2] if np.isfinite(pair[2]) else 0.0)
    (body_a, _), (body_b, _) = (geometry_owner(plant, inspector, geometry, robot_instance) for geometry in (id_a, id_b))
    t = root_context.get_time()
    depth = f", {-distance * 1000:.1f} mm deep" if np.isfinite(distance) else ""
    q = plant.GetPositions(plant_context, robot_instance)
    return Failure(Cause.COLLISION, f"collision between {body_a} and {body_b} at t = {t:.3f} s{depth}", t,
                   tuple(q.tolist()))


_UNSET = object()  # an argument not given: the scenario's value, or for a planner its default


def simulate(
    planner: PlannerSystem | Scenario,
    *,
    name: str = _UNSET,
    robot: Robot = _UNSET,
    gains: ControllerGains | None = _UNSET,
    plant_config: MultibodyPlantConfig | None = _UNSET,
    simulator_config: SimulatorConfig | None = _UNSET,
    log_period: float = _UNSET,
    settle_time: float = _UNSET,
    max_duration: float = _UNSET,
    speed_override=_UNSET,
    meshcat: Meshcat | None = None,
    progress=None,
    add_systems=None,
    before_run=None,
    tracking_tolerance: float | None = _UNSET,
    preflight: bool = True,
    cell: Cell | None = _UNSET,
    cell_directory: Path | None = _UNSET,
) -> SimulationResult:
    """Run a planner, or a scenario's, in a station until it finishes, plus ``settle_time`` [s].

    Given a :class:`~drake_traj.scenario.Scenario` (``simulate(load_scenario("quintic_ptp"))``),
    this is ``drake-traj run`` without the files: the scenario's planner, robot, gains, plant,
    log period, integrator, speed override, tolerance and times, each replaced by an argument
    given here (except ``robot``: the scenario names its own), and a ``max_duration`` shorter
    than the planned motion refused before the run as the command line refuses it. Given a
    planner system, the defaults are the robot it was made for (else the UR10e;
    :func:`station_robot`), the robot's gains, our plant and integrator (None: the same), 1 ms
    logs, 0.5 s settle time, 120 s at most, no speed override and a 5 mm tracking tolerance.

    The run stops at ``max_duration`` [s] (at most 600 s; the preflight looks as far ahead) if
    the planner has not finished; ``settle_time`` is at most 60 s. Whatever stops the run
    early (an exception from a planner, a timeout, Ctrl-C) is caught: the result holds everything
    logged up to that point and ``failure`` gives the reason. With ``meshcat``, the run is recorded
    there (see :func:`drake_traj.meshcat.export_html`).

    Args (the rest as :func:`add_station`):
        simulator_config: integration scheme, step, accuracy and real-time rate (default
            :func:`~drake_traj.scenario.default_simulator_config`).
        speed_override: a constant in [0, 1] or a :class:`SpeedOverride` profile on the
            station's ``speed_override`` input (None: unconnected, 1).
        progress: called with the simulated time [s] as the run goes (see :func:`run_station`).
        add_systems: ``add_systems(builder, station)`` adds systems around the station before the
            diagram is built (e.g. a speed-override source of one's own).
        before_run: ``before_run(simulator)`` is called once the simulator is initialized (the
            robot drawn at its start), before the motion (e.g. to wait for a browser).
        tracking_tolerance: the run fails if the TCP strays further from the reference [m], or
            if a joint's torque saturates (None: no such check; see
            :meth:`SimulationResult.execution_failure`).
        preflight: check the whole task before the motion, as ``drake-traj run`` does
            (:meth:`PlannerSystem.preflight`, then the planned motion in the cell:
            :meth:`CellChecker.check_planner <drake_traj.clearance.CellChecker.check_planner>`;
            a :class:`~drake_traj.errors.PlanningError`, e.g. a
            :class:`~drake_traj.clearance.CollisionError`, is raised before the run, not
            recorded as a failed run; False: an unchecked run, said explicitly, where the run
            finds what fails: the station's ``check_motion=False``).
        cell: the robot's cell and tool (a scenario's own by default; for a planner, a table
            flush with the base: :class:`~drake_traj.cell.Cell`).
        cell_directory: the folder relative model files of ``cell.directives`` are taken from
            (a scenario's: its file's folder; else the working directory).

    Every argument is checked before the run (TypeError or ValueError naming it).
    """
    given = dict(name=name, robot=robot, gains=gains, plant_config=plant_config, simulator_config=simulator_config,
                 log_period=log_period, settle_time=settle_time, max_duration=max_duration,
                 speed_override=speed_override, tracking_tolerance=tracking_tolerance, cell=cell,
                 cell_directory=cell_directory)
    if isinstance(planner, Scenario):
        scenario = planner
        if robot is not _UNSET:
            raise TypeError(f"robot must not be given with a scenario: scenario {scenario.name!r} names its robot "
                            f"({robot_label(scenario.robot)})")
        defaults = scenario.station_arguments() | scenario.run_settings()
        planner = defaults.pop("planner")
    else:
        scenario = None
        defaults = dict(name="run", robot=None, gains=None, plant_config=None, simulator_config=None, log_period=1e-3,
                        settle_time=0.5, max_duration=120.0, speed_override=None,
                        tracking_tolerance=DEFAULT_TRACKING_TOLERANCE, cell=None, cell_directory=None)
        instance_of(planner, PlannerSystem, "planner", hint=" or a Scenario")
    (name, robot, gains, plant_config, simulator_config, log_period, settle_time, max_duration, speed_override,
     tracking_tolerance, cell, cell_directory) = (defaults[key] if value is _UNSET else value
                                                  for key, value in given.items())
    robot = station_robot(planner, robot)
    if cell is not None:
        instance_of(cell, Cell, "cell")
        check_cell_tcp(robot, cell)  # the cell's TCP is the robot's, or it would be ignored
    # checked before the planner goes into a diagram (a planner is used in one diagram only)
    instance_of(name, str, "name")
    if simulator_config is not None:
        instance_of(simulator_config, SimulatorConfig, "simulator_config")
    if meshcat is not None:
        instance_of(meshcat, Meshcat, "meshcat")
    if simulator_config is not None:
        realtime_rate(simulator_config.target_realtime_rate, "simulator_config.target_realtime_rate")
        step_size(simulator_config.max_step_size, "simulator_config.max_step_size")
    run_duration(max_duration)
    settle_duration(settle_time)
    if tracking_tolerance is not None:
        positive_scalar(tracking_tolerance, "tracking_tolerance", "m")
        tracking_tolerance_check(tracking_tolerance, (cell or Cell()).clearance)
    speed_override_source(speed_override)
    callable_or_none(progress, "progress", "progress(t)")
    callable_or_none(add_systems, "add_systems", "add_systems(builder, station)")
    callable_or_none(before_run, "before_run", "before_run(simulator)")
    if flag(preflight, "preflight") and scenario is not None and cell is scenario.cell and cell_directory == scenario.directory():
        scenario_preflight(scenario, planner, max_duration)  # its errors located in the scenario file
    elif preflight:
        planner.preflight(max_duration)
        checker = CellChecker(robot, cell, cell_directory)
        check_start_torques(checker, planner.initial_positions())  # drives that cannot hold the start
        checker.check_planner(planner)
    if scenario is not None:
        check_planned_duration(scenario, planner)
    builder = DiagramBuilder()
    station = builder.AddSystem(build_station(planner, robot=robot, gains=gains, plant_config=plant_config,
                                              log_period=log_period, meshcat=meshcat, cell=cell,
                                              cell_directory=cell_directory, check_motion=preflight))
    add_speed_override(builder, station, speed_override)
    if add_systems is not None:
        add_systems(builder, station)
    simulator = Simulator(builder.Build())
    ApplySimulatorConfig(simulator_config or default_simulator_config(), simulator)
    visualizer = station.GetSubsystemByName("visualizer") if meshcat is not None else None
    if visualizer is not None:
        visualizer.StartRecording(True)  # and draw live
    simulator.Initialize()
    if before_run is not None:
        before_run(simulator)
        simulator.ResetStatistics()  # the real-time rate counts from here, not from Initialize()
    start = time.perf_counter()
    failure = run_station(simulator, station, settle_time=settle_time, max_duration=max_duration, progress=progress)
    wall_time = time.perf_counter() - start
    if visualizer is not None:
        visualizer.StopRecording()
        visualizer.PublishRecording()
    return SimulationResult.from_station(station, station.GetMyContextFromRoot(simulator.get_context()), name=name,
                                         failure=failure, wall_time=wall_time, tracking_tolerance=tracking_tolerance)
