"""Every check of a scenario's task before the motion, its errors located in the scenario's file:
:func:`preflight` (the planner's own check of the whole task, then :func:`check_in_cell`: the start
and the planned motion in the cell, the drives holding the start), and the checks the station
makes of any planner (:func:`check_cell_tcp`, :func:`check_start_torques`,
:func:`check_planned_duration`)."""

from dataclasses import fields

import numpy as np
from pydrake.math import RollPitchYaw, RotationMatrix

from drake_traj.cell import Cell, CellChecker
from drake_traj.errors import Cause, DrakeTrajError, Field, field_text, joint_label
from drake_traj.planners import PlannerSystem
from drake_traj.robots import Robot, estimated_torque_note
from drake_traj.robots.base import joint_actuators
from drake_traj.robots.custom import CustomArm, DhArm
from drake_traj.validation import MAX_RUN_DURATION
from drake_traj.scenario.scenario import Scenario, in_planner_field, locate_in_scenario
from drake_traj.scenario.yaml_schema import ScenarioError

__all__ = ["check_cell_tcp", "check_in_cell", "check_planned_duration", "check_start_torques", "preflight"]


def preflight(scenario: Scenario, planner: PlannerSystem, horizon: float | None = None) -> np.ndarray | None:
    """``planner.preflight(horizon)`` (the whole task checked before t = 0, up to ``horizon`` [s],
    default the scenario's ``max_duration``), its errors located in the scenario as
    :func:`~drake_traj.scenario.scenario.make_planner`'s are (e.g. at ``planner.waypoints[2]``'s
    line; a task that does not finish within the horizon at ``max_duration``'s); then the planned
    motion in the scenario's cell (:func:`check_in_cell`).

    Returns the planned tool path [m], shape (N, 3) in the base frame, where the planner
    computes one (a planner that plans in the cell, the free-motion one: once it has), else None."""
    try:
        path = planner.preflight(scenario.max_duration if horizon is None else horizon)
    except DrakeTrajError as error:
        if error.cause is not Cause.TIMEOUT:
            raise in_planner_field(scenario, error, message_leads_with_field=False) from error
        field = ("max_duration",)
        raise error.relocated(field, locate_in_scenario(
            scenario, field, f"max_duration: {error}; raise max_duration (at most {MAX_RUN_DURATION:g} s) or the "
                             "planner's limits")) from error
    except ValueError as error:
        raise in_planner_field(scenario, error, message_leads_with_field=False) from error
    check_in_cell(scenario, planner)
    if path is None and getattr(planner, "needs_cell", False):  # it planned in the cell just now
        path = planner.tool_path()
    return path


def check_in_cell(scenario: Scenario, planner: PlannerSystem, checker: CellChecker | None = None):
    """The start configuration and the planned motion (``planner.plan()``) in the scenario's
    cell: joint ranges, self-collision and collision with the cell, with its clearance
    (:meth:`CellChecker.check <drake_traj.cell.clearance.CellChecker.check>`). A refusal is a
    :class:`~drake_traj.cell.clearance.CollisionError` or
    :class:`~drake_traj.cell.clearance.JointRangeError` located at the cell's obstacle, the start
    configuration or the planner in the scenario file. Returns the
    :class:`~drake_traj.cell.clearance.MotionCheck`."""
    checker = checker or scenario.cell_checker()
    try:
        check_start_torques(checker, planner.initial_positions(), field=lambda j: _torque_field(scenario, j))
    except DrakeTrajError as error:
        raise error.relocated(error.field, locate_in_scenario(scenario, error.field, str(error))) from None
    try:
        return checker.check_planner(planner, start_field=("q_initial",) if len(scenario.q_initial) else ("planner",))
    except DrakeTrajError as error:
        if error.field and error.field[0] in {item.name for item in fields(scenario.planner)}:
            # a planner that plans in the cell: its goals, written as the preflight's ("planner.poses[0]: pose 0 ...")
            raise in_planner_field(scenario, error, message_leads_with_field=False) from None
        field = error.field or ("planner",)
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
            "the payload or bring its centre of mass closer to the flange, or start in another configuration"
            f"{estimated_torque_note(getattr(robot, 'estimated_inertia', {}), getattr(robot, 'inertia_density', None))}",
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
