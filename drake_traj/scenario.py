"""Typed scenarios, loaded from YAML with pydrake's ``yaml_load_typed`` (files in ``diagrams/``).

A scenario names the start configuration, the planner and its parameters, the PD controller and
the simulation settings. Unknown keys, wrong lengths and non-finite or out-of-range numbers raise
ValueError naming the file and the field.
"""


from dataclasses import dataclass, field
from typing import Union
from importlib import resources
from pathlib import Path

import numpy as np
from pydrake.common.yaml import yaml_load_typed

from drake_traj import robot
from drake_traj.diagram import ControllerGains, robot_model

# Seed 000's start configuration q(0) [rad]; its flange pose is p0 = [-0.174, -0.524, 0.273, pi, 0, 3pi/4].
PAJAK_Q0 = [-np.pi / 2, -np.pi / 2, -3 * np.pi / 4, -np.pi / 4, np.pi / 2, np.pi / 4]


@dataclass
class QuinticPtp:
    """Synchronised quintic point-to-point moves through joint goals (seed 004), a stop at each.

    goals [rad], one row of 6 per goal; velocity_limit [rad/s] and acceleration_limit [rad/s^2]
    per joint (defaults: the UR controller's joint-move defaults used by seed 000).
    """

    goals: list[list[float]] = field(default_factory=list)
    velocity_limit: list[float] = field(default_factory=lambda: [robot.DEFAULT_JOINT_MOVE_VELOCITY] * 6)
    acceleration_limit: list[float] = field(default_factory=lambda: [robot.DEFAULT_JOINT_MOVE_ACCELERATION] * 6)


@dataclass
class PajakTask:
    """Seed 000's acceleration-level task-space planner (Pająk 2024) through task-space waypoints.

    waypoints: rows [x, y, z, phi_X, phi_Y, phi_Z] [m, rad] in the base frame, the last is p_f.
    Gains Λ_P [1/s^2], Λ_V [1/s], limits [rad/s, rad/s^2], accuracy ε and neighbourhood ϵ [m] as
    in the paper; the improvement flags are those of
    :class:`drake_traj.planners.pajak.PajakParameters` (all off: the paper's method).
    """

    waypoints: list[list[float]] = field(default_factory=list)
    position_gain: float = 20.0
    velocity_gain: float = 9.392
    velocity_limit: float = robot.DEFAULT_JOINT_MOVE_VELOCITY
    acceleration_limit: float = robot.DEFAULT_JOINT_MOVE_ACCELERATION
    vartheta: float = 0.1
    rho: float = 0.03
    accuracy: float = 0.001
    neighbourhood: float = 0.05
    limit_velocity: bool = True
    limit_acceleration: bool = True
    blend_waypoints: bool = True
    smooth_penalty: bool = True
    continuous_switching: bool = True
    bounded_scaling: bool = True
    damped_inverse: bool = True
    preserve_damping: bool = True
    update_period: float = 0.001


@dataclass
class BorygaLoop:
    """Seed 001's loop path B -> M -> loop -> M -> E (Boryga), then inverse kinematics on the
    scenario's robot.

    B, M, E [m] in the robot's base frame; left empty, the paper's example (Table 1) is placed in
    the robot's workspace: by :func:`drake_traj.paper_robots.paper_loop_placement` for seed 001's
    robots, and for the UR10e translated so that B is the flange at ``q_initial`` (the loop then
    lies in the horizontal plane through it, traced at the flange orientation of ``q_initial``).
    delta [m] and v_max [m/s] as in the paper. velocity_limit / acceleration_limit per joint;
    empty: the robot's published velocity limits and no acceleration limit.
    """

    B: list[float] = field(default_factory=list)
    M: list[float] = field(default_factory=list)
    E: list[float] = field(default_factory=list)
    delta: float = 0.02
    v_max: float = 0.25
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)


@dataclass
class LiClosedPath:
    """Seed 002 (Li, Zhang, Zhou): look-ahead and cubic ACC/DEC on a tool path, IK, joint
    re-timing, quintic B-spline, and our repairs so every limit holds.

    points [m]: the tool path in the robot's base frame; left empty, the closed path like Fig. 6
    (:func:`drake_traj.li_robot.li_closed_path`), for the UR10e translated so that it starts at the
    flange at ``q_initial`` (horizontal plane, fixed flange orientation). Tool limits default to
    Table 4 (0.2 m/s, 0.1 m/s^2); joint limits empty: Table 5 for the 4-DOF robot, the UR
    joint-move defaults (1.05 rad/s, 1.40 rad/s^2) for the UR10e.
    """

    points: list[list[float]] = field(default_factory=list)
    tool_velocity_limit: float = 0.2
    tool_acceleration_limit: float = 0.1
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)


@dataclass
class Scenario:
    """One experiment: robot, start, planner, controller and simulation settings (times in seconds).

    ``robot`` is "ur10e", "li_4dof" (seed 002) or one of seed 001's robots ("anthropomorphic",
    "scara", "cartesian").
    ``q_initial`` is the UR10e's start (the task-space planners start there; planners of the
    other robots start from the inverse kinematics of their path). Empty controller gains take
    the robot's defaults.
    """

    name: str = "unnamed"
    robot: str = "ur10e"
    q_initial: list[float] = field(default_factory=lambda: list(PAJAK_Q0))
    planner: Union[QuinticPtp, PajakTask, BorygaLoop, LiClosedPath] = field(default_factory=QuinticPtp)
    controller: ControllerGains = field(default_factory=ControllerGains)
    time_step: float = 0.001
    log_period: float = 0.001
    settle_time: float = 0.5
    max_duration: float = 120.0

    def validate(self) -> None:
        """Raise ValueError naming the first field that is malformed."""
        model = robot_model(self.robot)
        q = np.asarray(self.q_initial, dtype=float)
        if q.shape != (robot.NUM_JOINTS,):
            raise ValueError(f"q_initial must have {robot.NUM_JOINTS} entries, got shape {q.shape}")
        if not np.all(np.isfinite(q)):
            raise ValueError(f"q_initial must be finite, got {self.q_initial}")
        outside = np.flatnonzero(np.abs(q) > robot.POSITION_LIMIT)
        if len(outside):
            j = outside[0]
            raise ValueError(
                f"q_initial[{j}] = {q[j]} rad is outside the joint limit +-{robot.POSITION_LIMIT[j]:.6f} rad"
            )
        for label in ("time_step", "log_period", "max_duration", "settle_time"):
            value = getattr(self, label)
            smallest_allowed = 0.0 if label == "settle_time" else np.nextafter(0.0, 1.0)
            if not np.isfinite(value) or value < smallest_allowed:
                raise ValueError(f"{label} must be a finite, positive number of seconds, got {value}")
        self.controller.for_robot(model)


def default_scenario_path() -> Path:
    """The scenario ``drake-traj run`` uses when none is given."""
    return Path(str(resources.files("drake_traj.diagrams").joinpath("pajak_sim3.yaml")))


def load_scenario(path) -> Scenario:
    """Read and validate a scenario YAML file."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"scenario file not found: {path}")
    try:
        scenario = yaml_load_typed(schema=Scenario, data=path.read_text())
    except RuntimeError as error:  # unknown keys, wrong types
        raise ValueError(f"{path}: {error}") from error
    try:
        scenario.validate()
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from error
    return scenario


def make_planner(scenario: Scenario):
    """The planner system the scenario describes (errors name the ``planner`` field)."""
    from drake_traj.planners.pajak import PajakParameters, PajakPlanner
    from drake_traj.planners.quintic import QuinticPtpPlanner, plan_synchronized_quintic

    config = scenario.planner
    try:
        if isinstance(config, BorygaLoop):
            return _make_boryga_planner(scenario, config)
        if isinstance(config, LiClosedPath):
            return _make_li_planner(scenario, config)
        if isinstance(config, PajakTask):
            settings = {name: value for name, value in vars(config).items() if name != "update_period"}
            return PajakPlanner(PajakParameters(**settings), scenario.q_initial, update_period=config.update_period)
        plan = plan_synchronized_quintic(
            scenario.q_initial,
            config.goals,
            config.velocity_limit,
            config.acceleration_limit,
            position_lower=-robot.POSITION_LIMIT,
            position_upper=robot.POSITION_LIMIT,
        )
        return QuinticPtpPlanner(plan, config.velocity_limit, config.acceleration_limit)
    except ValueError as error:
        raise ValueError(f"scenario {scenario.name!r}, planner: {error}") from error


def _make_boryga_planner(scenario: Scenario, config: BorygaLoop):
    from drake_traj import paper_robots
    from drake_traj.planners.boryga import BorygaLoopPlanner, PaperRobotLoopLaw, Ur10eLoopLaw, plan_loop_path

    points = [np.asarray(getattr(config, name), dtype=float) for name in ("B", "M", "E")]
    if any(len(point) for point in points):
        if not all(point.shape == (3,) for point in points):
            raise ValueError(f"B, M and E must all be 3-vectors [m] or all empty, got {[p.tolist() for p in points]}")
    elif scenario.robot == "ur10e":
        offset = robot.flange_pose(scenario.q_initial)[:3, 3] - np.asarray(paper_robots.PAPER_LOOP["B"])
        points = [np.asarray(paper_robots.PAPER_LOOP[name]) + offset for name in ("B", "M", "E")]
    else:
        placement = paper_robots.paper_loop_placement(scenario.robot)
        points = [placement.B, placement.M, placement.E]
    plan = plan_loop_path(*points, config.v_max, delta=config.delta)
    if scenario.robot == "ur10e":
        q_initial = np.asarray(scenario.q_initial, dtype=float)
        law = Ur10eLoopLaw(plan, robot.task_pose(q_initial)[3:], robot.ik_branch(q_initial))
        default_velocity = robot.VELOCITY_LIMIT
    else:
        arm = paper_robots.get_robot(scenario.robot)
        law = PaperRobotLoopLaw(plan, arm)
        default_velocity = np.asarray(arm.velocity_limit, dtype=float)
    count = len(law.q_start)
    velocity = np.asarray(config.velocity_limit or default_velocity, dtype=float)
    acceleration = np.asarray(config.acceleration_limit or [np.inf] * count, dtype=float)
    for name, limit in (("velocity_limit", velocity), ("acceleration_limit", acceleration)):
        if limit.shape != (count,) or np.any(~(limit > 0)):
            raise ValueError(f"{name} must have {count} positive entries, got {limit.tolist()}")
    return BorygaLoopPlanner(law, velocity, acceleration)


def _make_li_planner(scenario: Scenario, config: LiClosedPath):
    from drake_traj import li_robot
    from drake_traj.planners.li_joint import LiPathPlanner, plan_li_path

    points = np.asarray(config.points, dtype=float).reshape(-1, 3) if config.points else li_robot.li_closed_path()
    if scenario.robot == "ur10e":
        q_initial = np.asarray(scenario.q_initial, dtype=float)
        start = robot.task_pose(q_initial)
        if not config.points:
            points = points - points[0] + start[:3]

        def ik(path):
            poses = np.hstack([path, np.tile(start[3:], (len(path), 1))])
            return robot.inverse_kinematics_path(poses, q_initial)

        def tool_motion(q, qd, qdd):
            _, jacobian, bias, _, _ = robot.ur10e_kinematics(q, qd)
            return (np.einsum("nij,nj->ni", jacobian[:, :3], qd),
                    np.einsum("nij,nj->ni", jacobian[:, :3], qdd) + bias[:, :3])

        default_velocity = [robot.DEFAULT_JOINT_MOVE_VELOCITY] * robot.NUM_JOINTS
        default_acceleration = [robot.DEFAULT_JOINT_MOVE_ACCELERATION] * robot.NUM_JOINTS
    elif scenario.robot == "li_4dof":
        arm = li_robot.LI_4DOF

        def ik(path):
            return arm.ik(path)

        def tool_motion(q, qd, qdd):
            jacobians = np.array([arm.jacobian(row) for row in q])
            biases = np.array([arm.bias(row, rate) for row, rate in zip(q, qd)])
            return np.einsum("nij,nj->ni", jacobians, qd), np.einsum("nij,nj->ni", jacobians, qdd) + biases

        default_velocity, default_acceleration = arm.velocity_limits, arm.acceleration_limits
    else:
        raise ValueError(f"planner LiClosedPath runs on robot ur10e or li_4dof, not {scenario.robot!r}")
    velocity = np.asarray(config.velocity_limit or default_velocity, dtype=float)
    acceleration = np.asarray(config.acceleration_limit or default_acceleration, dtype=float)
    tool_limits = (config.tool_velocity_limit, config.tool_acceleration_limit)
    plan = plan_li_path(points, ik, tool_motion, velocity, acceleration, *tool_limits)
    return LiPathPlanner(plan, velocity, acceleration, tool_motion, tool_limits)
