"""The closed loop: planner -> PD controller with gravity compensation -> discrete UR10e plant.

The PD loop uses the plant's own PD-controlled actuators (``JointActuator.set_controller_gains``):
the discrete solver treats the PD terms implicitly, so stiff gains stay stable at the 1 ms step
even on the light wrist links, and the total torque saturates at each joint's effort limit like a
real drive. The feed-forward, added on the actuation input, is gravity compensation g(q) or, with
``feedforward_acceleration``, the full inverse dynamics M(q) qdd_ref + C(q, qd) qd - tau_g(q).

Loggers sample every ``log_period`` (periodic events only, so every logger has the same uniform
time grid starting at t = 0).
"""


import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pydrake.geometry import (
    CollisionFilterDeclaration,
    Meshcat,
    MeshcatVisualizer,
    MeshcatVisualizerParams,
)
from pydrake.multibody.plant import (
    AddMultibodyPlant,
    MultibodyPlant,
    MultibodyPlantConfig,
)
from pydrake.multibody.tree import PdControllerGains
from pydrake.systems.analysis import Simulator
from pydrake.systems.controllers import InverseDynamics
from pydrake.systems.framework import DiagramBuilder, EventStatus, LeafSystem, TriggerType
from pydrake.systems.primitives import LogVectorOutput

from drake_traj.errors import Failure
from drake_traj.planners.base import PlannerSystem
from drake_traj.result import SimulationResult
from drake_traj.robots import UR10E, Robot

@dataclass
class ControllerGains:
    """PD gains of the simulated joint controller and the feed-forward choice.

    Empty ``kp`` / ``kd`` take the robot's defaults (:attr:`Robot.default_gains`).
    """

    kp: list[float] = field(default_factory=list)
    kd: list[float] = field(default_factory=list)
    feedforward_acceleration: bool = True

    def for_robot(self, robot: Robot) -> "ControllerGains":
        """These gains with empty lists filled from ``robot``'s defaults, validated for its joint count."""
        kp, kd = robot.default_gains
        gains = ControllerGains(list(self.kp) or list(kp), list(self.kd) or list(kd), self.feedforward_acceleration)
        gains.validate(robot.num_joints)
        return gains

    def validate(self, num_joints: int) -> None:
        """Raise ValueError naming the gain that is of the wrong length, non-finite or negative."""
        for name in ("kp", "kd"):
            gains = np.asarray(getattr(self, name), dtype=float)
            if gains.shape != (num_joints,):
                raise ValueError(f"controller.{name} must have {num_joints} entries, got shape {gains.shape}")
            if not np.all(np.isfinite(gains)) or np.any(gains < 0):
                raise ValueError(f"controller.{name} must be finite and non-negative, got {gains.tolist()}")
        if not np.all(np.asarray(self.kp) > 0):
            raise ValueError(f"controller.kp must be positive, got {self.kp}")


class TcpPose(LeafSystem):
    """Measured TCP pose from the plant state [q; qd], by ``tcp_pose(q)`` (6 values)."""

    def __init__(self, tcp_pose, num_joints: int):
        super().__init__()
        self._state = self.DeclareVectorInputPort("state", 2 * num_joints)
        self.DeclareVectorOutputPort(
            "pose", 6, lambda context, out: out.SetFromVector(tcp_pose(self._state.Eval(context)[:num_joints]))
        )


class OneStepLookahead(LeafSystem):
    """The reference one plant step ahead: [q + h qd + h^2/2 qdd; qd + h qdd].

    The plant's implicit PD compares the desired state sampled at t_k with the state it computes
    for t_k + h; without this lookahead the arm lags the reference by one step (about
    |qd| h, i.e. 1 mrad at 1 rad/s and h = 1 ms).
    """

    def __init__(self, time_step: float, num_joints: int):
        super().__init__()
        n = self._n = num_joints
        self._h = time_step
        self._state = self.DeclareVectorInputPort("desired_state", 2 * n)
        self._acceleration = self.DeclareVectorInputPort("desired_acceleration", n)
        self.DeclareVectorOutputPort("state", 2 * n, self._calc)

    def _calc(self, context, output):
        n = self._n
        state = self._state.Eval(context)
        qdd = self._acceleration.Eval(context)
        q, qd, h = state[:n], state[n:], self._h
        output.SetFromVector(np.concatenate([q + h * qd + 0.5 * h * h * qdd, qd + h * qdd]))


@dataclass
class ClosedLoop:
    """The built diagram and handles to its parts."""

    diagram: object
    plant: MultibodyPlant
    planner: PlannerSystem
    loggers: dict
    visualizer: MeshcatVisualizer | None


def build_closed_loop(
    planner: PlannerSystem,
    *,
    robot: Robot = UR10E,
    gains: ControllerGains | None = None,
    time_step: float = 1e-3,
    log_period: float = 1e-3,
    meshcat: Meshcat | None = None,
) -> ClosedLoop:
    """Wire ``planner`` to a PD-controlled discrete UR10e plant with loggers (and Meshcat).

    Args:
        planner: any system under the planner contract.
        robot: the robot (default the UR10e).
        gains: PD gains and feed-forward choice (defaults: the robot's gains, with feed-forward).
        time_step: plant discrete step [s].
        log_period: uniform logging period [s].
        meshcat: when given, the robot is drawn there (``MeshcatVisualizer``).
    """
    gains = (gains or ControllerGains()).for_robot(robot)
    n = robot.num_joints
    if planner.num_joints != n:
        raise ValueError(f"the planner has {planner.num_joints} joints, robot {robot.name} has {n}")
    for name, value in (("time_step", time_step), ("log_period", log_period)):
        if not np.isfinite(value) or value <= 0:
            raise ValueError(f"{name} must be a positive number of seconds, got {value}")

    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(
        MultibodyPlantConfig(time_step=time_step, discrete_contact_approximation="sap"), builder
    )
    instance = robot.add_to_plant(plant)
    for joint_name, kp, kd in zip(robot.joint_names, gains.kp, gains.kd):
        actuator = plant.GetJointActuatorByName(f"{joint_name}_actuator", instance)
        actuator.set_controller_gains(PdControllerGains(p=kp, d=kd))
    plant.Finalize()
    # The arm's own links never touch in the tasks we plan; keep the solver free of self-contact.
    bodies = [plant.get_body(index) for index in plant.GetBodyIndices(instance)]
    scene_graph.collision_filter_manager().Apply(
        CollisionFilterDeclaration().ExcludeWithin(plant.CollectRegisteredGeometries(bodies))
    )

    builder.AddSystem(planner)
    lookahead = builder.AddSystem(OneStepLookahead(time_step, n))
    builder.Connect(planner.GetOutputPort("desired_state"), lookahead.GetInputPort("desired_state"))
    builder.Connect(planner.GetOutputPort("desired_acceleration"), lookahead.GetInputPort("desired_acceleration"))
    builder.Connect(lookahead.get_output_port(), plant.get_desired_state_input_port(instance))
    mode = (
        InverseDynamics.InverseDynamicsMode.kInverseDynamics
        if gains.feedforward_acceleration
        else InverseDynamics.InverseDynamicsMode.kGravityCompensation
    )
    feedforward = builder.AddSystem(InverseDynamics(plant, mode))
    builder.Connect(plant.get_state_output_port(instance), feedforward.get_input_port_estimated_state())
    if gains.feedforward_acceleration:
        builder.Connect(
            planner.GetOutputPort("desired_acceleration"), feedforward.get_input_port_desired_acceleration()
        )
    builder.Connect(feedforward.get_output_port_generalized_force(), plant.get_actuation_input_port(instance))

    tcp = builder.AddSystem(TcpPose(robot.tcp_pose, n))
    builder.Connect(plant.get_state_output_port(instance), tcp.get_input_port())

    def log(port):
        return LogVectorOutput(port, builder, {TriggerType.kPeriodic}, log_period)

    loggers = {
        "reference": log(planner.GetOutputPort("desired_state")),
        "acceleration": log(planner.GetOutputPort("desired_acceleration")),
        "scaling": log(planner.GetOutputPort("scaling")),
        "measured": log(plant.get_state_output_port(instance)),
        "torque": log(plant.get_net_actuation_output_port(instance)),
        "tcp": log(tcp.get_output_port()),
    }
    visualizer = None
    if meshcat is not None:
        visualizer = MeshcatVisualizer.AddToBuilder(
            builder, scene_graph, meshcat, MeshcatVisualizerParams(publish_period=1 / 30)
        )
    return ClosedLoop(builder.Build(), plant, planner, loggers, visualizer)


def simulate(
    planner: PlannerSystem,
    *,
    name: str = "run",
    robot: Robot = UR10E,
    gains: ControllerGains | None = None,
    time_step: float = 1e-3,
    log_period: float = 1e-3,
    settle_time: float = 0.5,
    max_duration: float = 120.0,
    meshcat: Meshcat | None = None,
    realtime_rate: float = 0.0,
) -> SimulationResult:
    """Run ``planner`` in the closed loop until it finishes, plus ``settle_time`` [s].

    The run stops at ``max_duration`` [s] if the planner has not finished. Whatever stops the run
    early (an exception from a planner, a timeout) is caught: the result holds everything logged
    up to that point and ``failure`` gives the reason. With ``meshcat``, the run is recorded there
    (see :func:`drake_traj.meshcat.export_html`).

    The planner must provide ``velocity_limit`` and ``acceleration_limit`` attributes [rad/s,
    rad/s^2], the limits it promises; the result's metrics are taken against them.
    """
    for label, value in (("settle_time", settle_time), ("max_duration", max_duration)):
        if not np.isfinite(value) or value < 0:
            raise ValueError(f"{label} must be a non-negative number of seconds, got {value}")
    loop = build_closed_loop(
        planner, robot=robot, gains=gains, time_step=time_step, log_period=log_period, meshcat=meshcat
    )
    simulator = Simulator(loop.diagram)
    simulator.set_target_realtime_rate(realtime_rate)
    integrator = simulator.get_mutable_integrator()
    integrator.set_maximum_step_size(time_step)
    integrator.set_target_accuracy(1e-8)
    context = simulator.get_mutable_context()
    plant_context = loop.plant.GetMyMutableContextFromRoot(context)
    loop.plant.SetPositions(plant_context, planner.initial_positions())
    planner_context = planner.GetMyContextFromRoot(context)

    finish_time = [float("nan")]

    def monitor(root_context):
        now = root_context.get_time()
        if np.isnan(finish_time[0]) and planner.finished(planner_context):
            finish_time[0] = now
        if now >= finish_time[0] + settle_time:  # False while finish_time is nan
            return EventStatus.ReachedTermination(planner, "planner finished")
        return EventStatus.DidNothing()

    simulator.set_monitor(monitor)
    if loop.visualizer is not None:
        loop.visualizer.StartRecording(False)
    failure = None
    start = time.perf_counter()
    try:
        simulator.AdvanceTo(max_duration)
        if np.isnan(finish_time[0]):
            failure = Failure("timeout", f"planner did not finish within max_duration = {max_duration} s",
                              context.get_time())
    except Exception as error:  # keep the log up to the failure; the reason goes in the result
        failure = Failure.from_exception(error, context.get_time())
    wall_time = time.perf_counter() - start
    if loop.visualizer is not None:
        loop.visualizer.StopRecording()
        loop.visualizer.PublishRecording()

    logs = {key: logger.FindLog(context) for key, logger in loop.loggers.items()}
    count = min(log.num_samples() for log in logs.values())
    data = {key: log.data()[:, :count].T for key, log in logs.items()}
    n = robot.num_joints
    return SimulationResult(
        name=name,
        t=logs["reference"].sample_times()[:count].copy(),
        q_ref=data["reference"][:, :n],
        qd_ref=data["reference"][:, n:],
        qdd_ref=data["acceleration"],
        q_meas=data["measured"][:, :n],
        qd_meas=data["measured"][:, n:],
        tau=data["torque"],
        scaling=data["scaling"][:, 0],
        tcp=data["tcp"],
        tcp_ref=np.array([robot.tcp_pose(q) for q in data["reference"][:, :n]]).reshape(-1, 6),
        velocity_limit=np.broadcast_to(planner.velocity_limit, (n,)).astype(float),
        acceleration_limit=np.broadcast_to(planner.acceleration_limit, (n,)).astype(float),
        effort_limit=robot.effort_limits,
        waypoints=planner.task_waypoints(),
        duration=finish_time[0],
        failure=failure,
        wall_time=wall_time,
    )
