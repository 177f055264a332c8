"""The soak's seeded random tasks: for an arm, a planner and a seed, one scenario as a user would
write it (the arm, a random cell, a random start, random goals and limits within the arm's
ratings) and the parameters drawn, for the row.

Every draw comes from ``numpy.random.default_rng([crc32(arm), crc32(planner), seed])``: a task
depends on its arm, its planner and its seed only, so any row reruns alone, and adding an arm or
a planner changes no other task.

- **Arms** (:data:`ARMS`): the shipped UR e-Series arms by name, the PUMA 560 (a ``!DhArm``) and
  the example ROS-style description (a ``!CustomArm``), each as its shipped scenario gives it.
- **Cells** (:func:`draw_cell`): a table (most tasks), a pedestal or nothing under the base; 0-4
  obstacles (boxes, cylinders, spheres) in the arm's reach; a tool on the flange in 3 tasks of 5
  (a cylinder 30-150 mm long, its TCP at the tip, a payload up to the arm's rating; on the PUMA,
  whose flange is its wrist centre, 75 mm out); a clearance of 5-20 mm.
- **Starts** (:func:`draw_start`): the arm's home configuration moved up to 0.6 rad per joint,
  drawn again (up to 20 times) until it is clear of the cell and of the arm itself by twice the
  clearance; joint goals and the configurations of pose goals are drawn again the same way.
- **Limits**: per joint (or one value for all, by a fair coin) 0.3-1 times the arm's joint-move
  limits (:attr:`Robot.joint_move_limits <drake_traj.robots.Robot.joint_move_limits>`); jerk
  limits, where a planner takes them, 2-10 times the acceleration limit [1/s] in half the tasks
  (else the planner's default).
- **Goals** per planner (:data:`DRAWS`): joint goals 0.2-1 rad per joint from the last
  (1-3 of them), clipped into the joint ranges; Pająk's waypoints the TCP poses of such a walk;
  Boryga's B, M, E two straight strokes from the TCP at the start with a corner of 20-160 degrees;
  Li's tool path a polyline of 2-4 strokes from the TCP at the start, points every 10 mm; the free
  motion's goal joints or (one task in four) a TCP pose, in a cell of 2-6 obstacles.

Nothing else is filtered for feasibility: a draw whose motion meets the cell, or whose start or
goals stayed in contact after 20 draws or are out of reach, is a task the planner must refuse,
with the right cause.
"""

import dataclasses
import functools
import zlib
from dataclasses import dataclass

import numpy as np

from drake_traj.cell import Box, Cell, Cylinder, NoMounting, Pedestal, Sphere, Table, Tool
from drake_traj.data import data_directory
from drake_traj.planners import (BorygaConfig, FreeMotionConfig, LiConfig, MovejConfig, PajakConfig, QuinticConfig,
                                 RetimedPajakConfig, RuckigConfig, SmoothWaypointsConfig, ToppraConfig)
from drake_traj.scenario import Scenario, load_scenario

__all__ = ["ARMS", "DRAWS", "SoakTask", "arm_setup", "draw_task"]

ARMS = {  # soak arm -> the shipped scenario whose robot it is
    "ur10e": "quintic_ptp", "ur3e": "quintic_ptp_ur3e", "ur5e": "quintic_ptp_ur5e", "ur16e": "quintic_ptp_ur16e",
    "ur20": "quintic_ptp_ur20", "ur30": "quintic_ptp_ur30", "puma560": "puma560_quintic",
    "example_arm": "example_arm_quintic",
}
TOOL_MOUNT = {"puma560": 0.075}  # [m] along the flange's z where a tool starts: the PUMA's flange is its wrist centre
START_SPREAD = 0.6  # [rad] per joint, from the home configuration
ATTEMPTS = 20  # draws of a start or a goal until one is clear of the cell
STEP_RANGE = (0.2, 1.0)  # [rad] per joint between two joint goals
RANGE_MARGIN = 0.02  # [rad] goals are clipped this far inside the joint ranges
LIMIT_SHARE = (0.3, 1.0)  # of the joint-move limits
FREE_PLANNING_TIME = 2.0  # [s] the free-motion planner's budget in the soak
MAX_DURATION = 120.0  # [s] the scenario's max_duration (the preflight integrates Pająk's law this far)


@dataclass(frozen=True)
class ArmSetup:
    """A soak arm: its scenario ``robot`` field (absolute paths), the robot it resolves to (flange
    as tool), and its reach [m] (the largest TCP distance from the base over 200 seeded poses)."""

    name: str
    field: object
    robot: object
    reach: float


@functools.cache
def arm_setup(name: str) -> ArmSetup:
    """The :class:`ArmSetup` of soak arm ``name`` (one of :data:`ARMS`), made once per process."""
    template = load_scenario(ARMS[name])
    field = template.robot
    if hasattr(field, "model_file"):  # a !CustomArm: its files from the shipped scenario's folder
        folder = template.directory() or data_directory("diagrams")
        field = dataclasses.replace(field, model_file=str((folder / field.model_file).resolve()),
                                    packages={package: str((folder / path).resolve())
                                              for package, path in field.packages.items()})
    robot = template.base_robot()
    rng = np.random.default_rng(0)
    poses = [robot.tcp_pose(rng.uniform(robot.lower_limits, robot.upper_limits)) for _ in range(200)]
    return ArmSetup(name, field, robot, float(max(np.linalg.norm(pose[:3]) for pose in poses)))


@dataclass(frozen=True, eq=False)
class SoakTask:
    """One task: ``arm``, ``planner`` and ``seed`` that drew it, the ``scenario`` and the
    parameters drawn (``params``: plain numbers and strings, for the row)."""

    arm: str
    planner: str
    seed: int
    scenario: Scenario
    params: dict


def task_rng(arm: str, planner: str, seed: int) -> np.random.Generator:
    """The generator of one task's draws (module docstring)."""
    return np.random.default_rng([zlib.crc32(arm.encode()), zlib.crc32(planner.encode()), seed])


def draw_cell(rng, arm: ArmSetup, obstacles: tuple[int, int] = (0, 4)) -> tuple[Cell, dict]:
    """A random cell round ``arm`` (module docstring), with ``obstacles`` (least, most) obstacles."""
    mounting = rng.choice(["table", "table", "table", "pedestal", "none"])
    reach = arm.reach
    shapes = []
    for k in range(int(rng.integers(obstacles[0], obstacles[1] + 1))):
        angle, distance = rng.uniform(0, 2 * np.pi), rng.uniform(0.4, 1.1) * reach
        xyz = [distance * np.cos(angle), distance * np.sin(angle), rng.uniform(0.05, 0.9) * reach]
        rpy = rng.uniform(-np.pi, np.pi, 3).tolist()
        kind = rng.choice(["box", "cylinder", "sphere"])
        size = rng.uniform(0.05, 0.25, 3) * reach
        if kind == "box":
            shapes.append(Box(name=f"box_{k}", size=size.tolist(), xyz=xyz, rpy=rpy))
        elif kind == "cylinder":
            shapes.append(Cylinder(name=f"cylinder_{k}", radius=float(size[0] / 2), length=float(size[1]), xyz=xyz, rpy=rpy))
        else:
            shapes.append(Sphere(name=f"sphere_{k}", radius=float(size[0] / 2), xyz=xyz))
    tool, tool_params = _draw_tool(rng, arm)
    clearance = float(rng.uniform(0.005, 0.02))
    cell = Cell(mounting={"table": Table, "pedestal": Pedestal, "none": NoMounting}[mounting](),
                obstacles=shapes, tool=tool, clearance=clearance)
    return cell, {"mounting": str(mounting), "obstacles": len(shapes), "clearance_m": clearance} | tool_params


def _draw_tool(rng, arm: ArmSetup) -> tuple[Tool, dict]:
    """No tool (2 tasks in 5), or a cylinder on the flange with its TCP at the tip and a payload."""
    if rng.uniform() < 0.4:
        return Tool(), {"tool_length_m": 0.0, "payload_kg": 0.0}
    length, radius = float(rng.uniform(0.03, 0.15)), float(rng.uniform(0.015, 0.035))
    mass = float(rng.uniform(0.0, arm.robot.rated_payload or 0.0))
    mount = TOOL_MOUNT.get(arm.name, 0.0)
    tool = Tool(tcp_xyz=[0.0, 0.0, mount + length], shapes=[Cylinder(name="tool_body", radius=radius, length=length,
                                                                     xyz=[0.0, 0.0, mount + length / 2])],
                mass=mass, center_of_mass=[0.0, 0.0, mount + length / 2])
    return tool, {"tool_length_m": length, "payload_kg": mass}


def draw_start(rng, arm: ArmSetup, clear) -> np.ndarray:
    """A start near home for which ``clear(q)`` holds (the last of 20 draws where none does)."""
    robot = arm.robot
    for _ in range(ATTEMPTS):
        q = _clip(robot, robot.home_configuration + rng.uniform(-START_SPREAD, START_SPREAD, robot.num_joints))
        if clear(q):
            break
    return q


def _clip(robot, q) -> np.ndarray:
    return np.clip(q, robot.lower_limits + RANGE_MARGIN, robot.upper_limits - RANGE_MARGIN)


def _walk(rng, robot, start, count: int, clear) -> np.ndarray:
    """``count`` joint goals (count, n), each 0.2-1 rad per joint (either sign) from the last and
    drawn again (up to 20 times) until ``clear(goal)``."""
    goals, q = [], start
    for _ in range(count):
        for _ in range(ATTEMPTS):
            step = rng.choice([-1.0, 1.0], robot.num_joints) * rng.uniform(*STEP_RANGE, robot.num_joints)
            goal = _clip(robot, q + step)
            if clear(goal):
                break
        goals.append(q := goal)
    return np.array(goals)


def _limits(rng, robot) -> tuple[list[float], list[float], dict]:
    """Velocity and acceleration limits within the joint-move limits (module docstring)."""
    velocity, acceleration = robot.joint_move_limits
    n = robot.num_joints
    shares = (rng.uniform(*LIMIT_SHARE, n), rng.uniform(*LIMIT_SHARE, n)) if rng.integers(2) else \
        (np.full(n, rng.uniform(*LIMIT_SHARE)), np.full(n, rng.uniform(*LIMIT_SHARE)))
    velocity, acceleration = velocity * shares[0], acceleration * shares[1]
    return velocity.tolist(), acceleration.tolist(), {"velocity_share": float(shares[0].min()),
                                                      "acceleration_share": float(shares[1].min())}


def _jerk(rng, acceleration) -> tuple[list[float], dict]:
    if rng.integers(2):
        return [], {"jerk_factor": 0.0}
    factor = float(rng.uniform(2.0, 10.0))
    return (factor * np.asarray(acceleration)).tolist(), {"jerk_factor": factor}


def _joint_goals(rng, arm, start, clear):
    goals = _walk(rng, arm.robot, start, int(rng.integers(1, 4)), clear)
    return goals.tolist(), {"goals": len(goals)}


def _quintic(rng, arm, robot, start, clear):
    goals, params = _joint_goals(rng, arm, start, clear)
    velocity, acceleration, limits = _limits(rng, robot)
    return QuinticConfig(goals=goals, velocity_limit=velocity, acceleration_limit=acceleration), params | limits


def _movej(rng, arm, robot, start, clear):
    goals, params = _joint_goals(rng, arm, start, clear)
    velocity, acceleration, limits = _limits(rng, robot)
    radius = float(rng.choice([0.0, rng.uniform(0.01, 0.1)]))
    return (MovejConfig(goals=goals, blend_radius=radius, velocity_limit=velocity, acceleration_limit=acceleration),
            params | limits | {"blend_radius_m": radius})


def _ruckig(rng, arm, robot, start, clear):
    goals, params = _joint_goals(rng, arm, start, clear)
    velocity, acceleration, limits = _limits(rng, robot)
    jerk, jerk_params = _jerk(rng, acceleration)
    return (RuckigConfig(goals=goals, velocity_limit=velocity, acceleration_limit=acceleration, jerk_limit=jerk),
            params | limits | jerk_params)


def _smooth(rng, arm, robot, start, clear):
    goals, params = _joint_goals(rng, arm, start, clear)
    velocity, acceleration, limits = _limits(rng, robot)
    jerk, jerk_params = _jerk(rng, acceleration)
    return (SmoothWaypointsConfig(goals=goals, velocity_limit=velocity, acceleration_limit=acceleration,
                                  jerk_limit=jerk), params | limits | jerk_params)


def _toppra(rng, arm, robot, start, clear):
    goals, params = _joint_goals(rng, arm, start, clear)
    velocity, acceleration, limits = _limits(rng, robot)
    return ToppraConfig(path=goals, velocity_limit=velocity, acceleration_limit=acceleration), params | limits


def _pajak_config(rng, arm, robot, start, clear) -> tuple[PajakConfig, dict]:
    """Pająk's waypoints: the TCP poses of a joint walk of 1-3 steps (:func:`_walk`)."""
    walk = [start, *_walk(rng, arm.robot, start, int(rng.integers(1, 4)), clear)]
    velocity, acceleration, limits = _limits(rng, robot)
    blend = bool(rng.integers(2))
    config = PajakConfig(waypoints=[robot.tcp_pose(q).tolist() for q in walk[1:]], velocity_limit=float(min(velocity)),
                         acceleration_limit=float(min(acceleration)), blend_waypoints=blend)
    return config, {"goals": len(walk) - 1, "blend": blend} | limits


def _pajak_retimed(rng, arm, robot, start, clear):
    pajak, params = _pajak_config(rng, arm, robot, start, clear)
    jerk, jerk_params = _jerk(rng, np.full(robot.num_joints, pajak.acceleration_limit))
    return RetimedPajakConfig(pajak=pajak, jerk_limit=jerk), params | jerk_params


def _direction(rng) -> np.ndarray:
    vector = rng.normal(size=3)
    return vector / np.linalg.norm(vector)


def _boryga(rng, arm, robot, start, clear):
    """B at the TCP, M a stroke of 0.1-0.3 reach away, E another from M turning 20-160 degrees."""
    b = robot.tcp_pose(start)[:3]
    first = _direction(rng)
    other = _direction(rng)
    other -= other.dot(first) * first
    other /= np.linalg.norm(other)
    turn = np.radians(rng.uniform(20.0, 160.0))
    second = np.cos(np.pi - turn) * first + np.sin(np.pi - turn) * other  # the angle at M between MB and ME is `turn`
    m = b + rng.uniform(0.1, 0.3) * arm.reach * first
    e = m + rng.uniform(0.1, 0.3) * arm.reach * second
    velocity, acceleration, limits = _limits(rng, robot)
    delta, speed = float(rng.uniform(0.005, 0.04)), float(rng.uniform(0.05, 0.4))
    config = BorygaConfig(B=b.tolist(), M=m.tolist(), E=e.tolist(), delta=delta, v_max=speed,
                          velocity_limit=velocity, acceleration_limit=acceleration)
    return config, {"corner_deg": float(np.degrees(turn)), "delta_m": delta, "v_max": speed} | limits


def _li(rng, arm, robot, start, clear):
    """A polyline of 2-4 strokes of 0.05-0.25 reach from the TCP, a point every 10 mm."""
    corners = [robot.tcp_pose(start)[:3]]
    for _ in range(int(rng.integers(2, 5))):
        corners.append(corners[-1] + rng.uniform(0.05, 0.25) * arm.reach * _direction(rng))
    points = [corners[0]]
    for a, b in zip(corners[:-1], corners[1:]):
        steps = max(1, int(np.ceil(np.linalg.norm(b - a) / 0.01)))
        points.extend(a + (b - a) * k / steps for k in range(1, steps + 1))
    velocity, acceleration, limits = _limits(rng, robot)
    tool_speed, tool_acceleration = float(rng.uniform(0.05, 0.3)), float(rng.uniform(0.05, 0.5))
    config = LiConfig(points=np.array(points).tolist(), tool_velocity_limit=tool_speed,
                      tool_acceleration_limit=tool_acceleration, velocity_limit=velocity, acceleration_limit=acceleration)
    return config, {"goals": len(corners) - 1, "tool_velocity_limit": tool_speed,
                    "tool_acceleration_limit": tool_acceleration} | limits


def _free(rng, arm, robot, start, clear, seed):
    velocity, acceleration, limits = _limits(rng, robot)
    jerk, jerk_params = _jerk(rng, acceleration)
    goal = _walk(rng, arm.robot, start, 1, clear)[0]
    common = dict(velocity_limit=velocity, acceleration_limit=acceleration, jerk_limit=jerk,
                  planning_time=FREE_PLANNING_TIME, seed=seed % 2**31)
    if rng.uniform() < 0.25:
        return (FreeMotionConfig(poses=[robot.tcp_pose(goal).tolist()], **common),
                {"goals": 1, "goal_kind": "pose"} | limits | jerk_params)
    return FreeMotionConfig(goals=[goal.tolist()], **common), {"goals": 1, "goal_kind": "joints"} | limits | jerk_params


DRAWS = {  # soak planner -> its draw (rng, arm, robot with the tool, start, clear) -> (config, params)
    "quintic": _quintic, "pajak": _pajak_config, "boryga": _boryga, "li": _li, "smooth_waypoints": _smooth,
    "pajak_retimed": _pajak_retimed, "free_motion": _free, "movej": _movej, "ruckig": _ruckig, "toppra": _toppra,
}
OBSTACLES = {"free_motion": (2, 6)}  # the planners whose cells have more obstacles than (0, 4)


def draw_task(arm: str, planner: str, seed: int) -> SoakTask:
    """The task of ``planner`` on ``arm`` drawn from ``seed`` (module docstring)."""
    setup = arm_setup(arm)
    rng = task_rng(arm, planner, seed)
    cell, params = draw_cell(rng, setup, OBSTACLES.get(planner, (0, 4)))
    scenario = Scenario(name=f"soak_{arm}_{planner}_{seed}", robot=setup.field, cell=cell,
                        tracking_tolerance=min(0.005, cell.clearance / 2), max_duration=MAX_DURATION, settle_time=0.2)
    checker = scenario.cell_checker()

    def clear(q) -> bool:  # twice the clearance from the cell and the arm itself
        return not checker.contacts(q, within=2 * cell.clearance)

    start = draw_start(rng, setup, clear)
    robot = scenario.robot_with_tool()
    extra = (seed,) if planner == "free_motion" else ()
    config, drawn = DRAWS[planner](rng, setup, robot, start, clear, *extra)
    scenario.q_initial = start.tolist()
    scenario.planner = config
    return SoakTask(arm, planner, seed, scenario, params | drawn)
