"""The station's closed loop as Drake parts: a planner driving a PD-controlled robot plant, with
loggers, as one Drake Diagram.

Built the way Drake's own examples build a station: :func:`add_station` adds the parts to a
``DiagramBuilder`` and returns handles; :func:`build_station` wraps them in a Diagram named
``station`` with exported ports; :func:`make_station` does that for a scenario.
:func:`drake_traj.station.simulate` runs one over these pieces (:mod:`drake_traj.station.run`
advances it); a user's own ``Simulator`` over a station gives the same result.

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

Subsystems by name: ``planner``, ``plant``, ``scene_graph``, ``reference_and_scaling`` (a
``Demultiplexer`` of the planner's [q; q̇; q̈; c] port: one Python call per step serves the plant,
the loggers and the exported ports), ``lookahead_mux`` and ``lookahead`` (the one-step lookahead),
``feedforward`` (inverse dynamics), ``tcp_pose``, the loggers of
:data:`drake_traj.results.result.LOGGERS` and, with Meshcat, ``visualizer``. The station's exported ports
are declared in :func:`build_station`'s docstring.
"""

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydrake.geometry import Meshcat, MeshcatVisualizer, MeshcatVisualizerParams
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlant, MultibodyPlantConfig
from pydrake.multibody.tree import PdControllerGains
from pydrake.systems.controllers import InverseDynamics
from pydrake.systems.framework import Diagram, DiagramBuilder, LeafSystem, OutputPort, TriggerType
from pydrake.systems.primitives import (ConstantVectorSource, Demultiplexer, LogVectorOutput, MatrixGain,
                                        Multiplexer, TrajectorySource)

from drake_traj.cell import Cell, MotionGuard, add_cell, refuse_free_bodies
from drake_traj.cell.clearance import scene_fingerprint, unprotected_links
from drake_traj.planners.base import PlannerSystem
from drake_traj.results import LOGGERS
from drake_traj.robots import UR10E, Robot, exclude_self_contact
from drake_traj.robots.base import joint_actuators
from drake_traj.scenario import ControllerGains, Scenario, SpeedOverride, default_plant_config
from drake_traj.scenario import preflight as scenario_preflight
from drake_traj.validation import (callable_or_none, flag, instance_of, invalid, log_period_check, positive_scalar,
                                   real_scalar, step_size)

__all__ = ["Station", "add_speed_override", "add_station", "build_station", "make_station"]


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
    loggers: dict  # name (see drake_traj.results.result.LOGGERS) -> VectorLogSink
    visualizer: MeshcatVisualizer | None


@dataclass(frozen=True)
class StationConfig:
    """:func:`add_station`'s arguments, checked: what one station is made of."""

    robot: Robot
    gains: ControllerGains  # the robot's own (ControllerGains.for_robot)
    plant_config: MultibodyPlantConfig
    time_step: float  # the plant's step h [s]
    log_period: float  # [s], a whole multiple of time_step
    meshcat: Meshcat | None
    cell: Cell
    cell_directory: Path | None
    before_finalize: Callable | None
    check_motion: bool


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


def station_config(builder, planner, *, robot, gains, plant_config, log_period, meshcat, cell, cell_directory,
                   before_finalize, check_motion) -> StationConfig:
    """:func:`add_station`'s arguments checked in the order they are documented (TypeError or
    ValueError naming the first one that is wrong), with their defaults filled in."""
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
    time_step = step_size(plant_config.time_step, "plant.time_step")
    log_period = positive_scalar(log_period, "log_period", "s")
    log_period_check(log_period, time_step)
    return StationConfig(robot, gains, plant_config, time_step, log_period, meshcat, cell or Cell(), cell_directory,
                         before_finalize, check_motion)


def add_robot_plant(builder: DiagramBuilder, planner: PlannerSystem, config: StationConfig):
    """The finalized plant (and its scene graph, and the robot's model instance): the robot with
    its PD-controlled actuators, the cell and tool (contact with them, and between the arm's
    non-adjacent links, is simulated and ends the run: :func:`~drake_traj.station.run_station`;
    the pairs of links the checks leave out, :func:`~drake_traj.robots.exclude_self_contact`, are
    filtered here too),
    the bodies of ``before_finalize``; its default positions are the planner's start. Gives the
    planner the :class:`~drake_traj.cell.MotionGuard` of this scene."""
    plant, scene_graph = AddMultibodyPlant(config.plant_config, builder)
    robot = config.robot
    instance = robot.add_to_plant(plant)
    actuators = joint_actuators(plant, instance)  # by joint: a model names its actuators as it likes
    if list(actuators) != list(robot.joint_names):  # the plant's desired-state and actuation ports go by actuator
        raise invalid("robot", f"the {robot.name} model's actuators drive the joints {list(actuators)} in this order; the "
                               f"station drives {list(robot.joint_names)}: one actuator per joint, in the joints' order")
    for joint_name, kp, kd in zip(robot.joint_names, config.gains.kp, config.gains.kd):
        actuators[joint_name].set_controller_gains(PdControllerGains(p=kp, d=kd))
    fields = add_cell(plant, config.cell, instance, robot=robot, directory=config.cell_directory)
    if config.before_finalize is not None:
        config.before_finalize(plant, scene_graph)
    plant.Finalize()
    unchecked_pairs = exclude_self_contact(plant, scene_graph, instance, robot)  # as the cell check's plant
    refuse_free_bodies(plant, instance, fields)  # the controller drives the robot's joints only
    plant.SetDefaultPositions(instance, planner.initial_positions())
    planner.guard = MotionGuard(robot, config.cell, config.cell_directory, config.before_finalize,
                                scene_fingerprint(plant, scene_graph.model_inspector()), config.check_motion,
                                unprotected_links=tuple(unprotected_links(plant, instance, robot.joint_names)),
                                unchecked_pairs=unchecked_pairs)
    return plant, scene_graph, instance


def add_planner_with_lookahead(builder: DiagramBuilder, planner: PlannerSystem, plant: MultibodyPlant, instance,
                               time_step: float) -> tuple[OutputPort, OutputPort, OutputPort]:
    """The planner, named ``planner``, its [q; q̇; q̈; c] split (one Python call per step, split in
    C++ for the plant and the loggers) and its reference one plant step ``time_step`` [s] ahead on
    the plant's desired-state input. Returns the split's [q; q̇] [rad, rad/s], q̈ [rad/s²] and c
    ports."""
    n = planner.num_joints
    planner.set_name("planner")
    builder.AddSystem(planner)
    mux = builder.AddNamedSystem("lookahead_mux", Multiplexer([2 * n, n]))
    h, eye = time_step, np.eye(n)
    zero = np.zeros((n, n))
    lookahead = builder.AddNamedSystem("lookahead", MatrixGain(np.block([[eye, h * eye, 0.5 * h * h * eye],
                                                                           [zero, eye, h * eye]])))
    split = builder.AddNamedSystem("reference_and_scaling", Demultiplexer([2 * n, n, 1]))
    builder.Connect(planner.GetOutputPort("reference_and_scaling"), split.get_input_port())
    reference, acceleration, scaling = (split.get_output_port(k) for k in range(3))
    builder.Connect(reference, mux.get_input_port(0))
    builder.Connect(acceleration, mux.get_input_port(1))
    builder.Connect(mux.get_output_port(), lookahead.get_input_port())
    builder.Connect(lookahead.get_output_port(), plant.get_desired_state_input_port(instance))
    return reference, acceleration, scaling


def add_feedforward(builder: DiagramBuilder, plant: MultibodyPlant, instance, gains: ControllerGains,
                    acceleration: OutputPort) -> None:
    """The feed-forward on the plant's actuation input, named ``feedforward``: gravity
    compensation, or with ``gains.feedforward_acceleration`` the inverse dynamics of the
    planner's ``acceleration`` q̈ [rad/s²]."""
    mode = (InverseDynamics.InverseDynamicsMode.kInverseDynamics if gains.feedforward_acceleration
            else InverseDynamics.InverseDynamicsMode.kGravityCompensation)
    feedforward = builder.AddNamedSystem("feedforward", InverseDynamics(plant, mode))
    builder.Connect(plant.get_state_output_port(instance), feedforward.get_input_port_estimated_state())
    if gains.feedforward_acceleration:
        builder.Connect(acceleration, feedforward.get_input_port_desired_acceleration())
    builder.Connect(feedforward.get_output_port_generalized_force(), plant.get_actuation_input_port(instance))


def add_tcp_pose(builder: DiagramBuilder, robot: Robot, plant: MultibodyPlant, instance) -> TcpPose:
    """The measured tool pose of the plant's state, named ``tcp_pose``."""
    tcp = builder.AddNamedSystem("tcp_pose", TcpPose(robot))
    builder.Connect(plant.get_state_output_port(instance), tcp.get_input_port())
    return tcp


def add_loggers(builder: DiagramBuilder, sources: dict[str, OutputPort], log_period: float) -> dict:
    """A periodic logger of each port of ``sources`` ({name of :data:`~drake_traj.results.LOGGERS`:
    port}), named by its key, sampling at k * ``log_period`` [s] from t = 0."""
    assert set(sources) == set(LOGGERS)
    loggers = {}
    for name, port in sources.items():
        loggers[name] = LogVectorOutput(port, builder, {TriggerType.kPeriodic}, log_period)
        loggers[name].set_name(name)
    return loggers


def add_visualizer(builder: DiagramBuilder, scene_graph, meshcat: Meshcat | None) -> MeshcatVisualizer | None:
    """A Meshcat visualizer of ``scene_graph`` at 30 Hz, named ``visualizer``; None without ``meshcat``."""
    if meshcat is None:
        return None
    visualizer = MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat, MeshcatVisualizerParams(publish_period=1 / 30))
    visualizer.set_name("visualizer")
    return visualizer


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
            is initialized and refused with the check's error (:mod:`drake_traj.cell.guard`). False
            runs an unchecked plan (the run's in-loop watch stays on).

    A planner system is part of one diagram only (Drake owns it there): a second station needs a
    new planner (``make_planner`` again); ValueError otherwise.
    """
    config = station_config(builder, planner, robot=robot, gains=gains, plant_config=plant_config,
                            log_period=log_period, meshcat=meshcat, cell=cell, cell_directory=cell_directory,
                            before_finalize=before_finalize, check_motion=check_motion)
    plant, scene_graph, instance = add_robot_plant(builder, planner, config)
    reference, acceleration, scaling = add_planner_with_lookahead(builder, planner, plant, instance, config.time_step)
    add_feedforward(builder, plant, instance, config.gains, acceleration)
    tcp = add_tcp_pose(builder, config.robot, plant, instance)
    loggers = add_loggers(builder, {
        "reference_logger": reference,
        "acceleration_logger": acceleration,
        "scaling_logger": scaling,
        "measured_logger": plant.get_state_output_port(instance),
        "torque_logger": plant.get_net_actuation_output_port(instance),
    }, config.log_period)
    visualizer = add_visualizer(builder, scene_graph, config.meshcat)
    return Station(planner, config.robot, plant, scene_graph, instance, tcp, loggers, visualizer)


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
    split = builder.GetSubsystemByName("reference_and_scaling")
    for k, name in enumerate(("desired_state", "desired_acceleration", "scaling")):
        builder.ExportOutput(split.get_output_port(k), name)
    builder.ExportOutput(parts.plant.get_state_output_port(parts.instance), "measured_state")
    builder.ExportOutput(parts.plant.get_net_actuation_output_port(parts.instance), "torque")
    builder.ExportOutput(parts.tcp_pose.get_output_port(), "tcp_pose")
    station = builder.Build()
    station.set_name("station")
    return station


def make_station(scenario: Scenario, meshcat: Meshcat | None = None) -> Diagram:
    """The station of a :class:`~drake_traj.scenario.Scenario`: its planner, robot, gains, plant
    configuration and log period. Its motion is checked before it starts, as
    :func:`~drake_traj.station.simulate` checks it (:func:`drake_traj.scenario.preflight`: the
    task, then the motion in the cell, refusals located in the scenario's file), when the
    simulator is initialized or by :func:`~drake_traj.station.run_station`, whichever comes first.

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
