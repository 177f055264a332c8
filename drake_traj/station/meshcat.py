"""Meshcat: the task drawn before the motion, a live view (TCP trail, speed slider, waiting for a
browser), and the standalone HTML recording.

Paths in the Meshcat scene tree: ``/drake_traj/waypoints/<k>`` (each waypoint's neighbourhood,
orange), ``/drake_traj/planned_path`` (the path a planner computed before moving, grey),
``/drake_traj/trail`` (the measured TCP, growing live, red), ``/drake_traj/tcp_path`` (the
measured TCP path of a finished run, red) and ``/drake_traj/refusal`` (a refused configuration:
every collision shape, the two bodies in red, their closest points joined).
"""

import errno
import logging
import socket
import time
from pathlib import Path

import numpy as np
from pydrake.geometry import Meshcat, MeshcatParams, Rgba, Role, Sphere
from pydrake.math import RigidTransform
from pydrake.systems.framework import DiagramBuilder, LeafSystem

from drake_traj.cell import CellChecker, CollisionError
from drake_traj.errors import DrakeTrajError
from drake_traj.robots import Robot
from drake_traj.scenario import SpeedOverride
from drake_traj.validation import instance_of

__all__ = [
    "SPEED_SLIDER", "SpeedSlider", "TcpTrail", "add_live_view", "draw_refusal", "draw_task", "draw_tcp_path", "export_html", "frame_task",
    "start_meshcat", "wait_for_browser",
]

WAYPOINT_COLOUR = Rgba(1.0, 0.55, 0.0, 0.5)
MARKER_RADIUS = 0.015  # [m] a waypoint the planner passes through or stops at
PATH_COLOUR = Rgba(0.9, 0.1, 0.1, 1.0)
PLANNED_COLOUR = Rgba(0.35, 0.35, 0.35, 1.0)
SPEED_SLIDER = "speed override"
REFUSED_COLOUR = Rgba(0.9, 0.1, 0.1, 0.9)
OTHER_COLOUR = Rgba(0.7, 0.7, 0.7, 0.35)


def draw_refusal(meshcat: Meshcat, checker: CellChecker, error: CollisionError) -> None:
    """The configuration of ``error`` in ``checker``'s cell under ``/drake_traj/refusal``: every
    collision shape at its pose, the two bodies of the error in red, the rest translucent grey,
    and their closest points joined by a black line."""
    meshcat.Delete("/drake_traj/refusal")
    inspector = checker.scene_graph.model_inspector()
    query = checker.pose_query(error.configuration)
    for geometry in inspector.GetAllGeometryIds(Role.kProximity):
        body, name = checker.owner(geometry)
        path = f"/drake_traj/refusal/{body.replace('::', '/')}/{name}"
        meshcat.SetObject(path, inspector.GetShape(geometry), REFUSED_COLOUR if body in error.bodies else OTHER_COLOUR)
        meshcat.SetTransform(path, query.GetPoseInWorld(geometry))
    for contact in checker.contacts(error.configuration):
        if set(contact.bodies) == set(error.bodies):
            meshcat.SetLine("/drake_traj/refusal/closest_points", contact.points.T.copy(), 4.0, Rgba(0, 0, 0, 1))
            break


def start_meshcat(port: int | None = None, *, announce: bool = True) -> Meshcat:
    """A Meshcat server (on ``port``, or the first free one from 7000). Drake announces its URL on
    the console; ``announce=False`` keeps it quiet (a server used only to write a recording).
    A port that cannot be opened raises a DrakeTrajError naming it and why (in use, reserved)."""
    drake_log = logging.getLogger("drake")
    level = drake_log.level
    if not announce:
        drake_log.setLevel(logging.WARNING)
    try:
        return Meshcat(MeshcatParams(port=port)) if port is not None else Meshcat()
    except RuntimeError as error:  # Drake: "Meshcat failed to open a websocket port."
        if port is None:
            raise DrakeTrajError(f"Meshcat found no free port from 7000 ({error}); give one with --port",
                                 field=("port",)) from None
        raise DrakeTrajError(f"port {port} (--port) cannot be opened for Meshcat: {_port_problem(port)}; choose "
                             "another port, or leave --port out for the first free one from 7000",
                             field=("port",)) from None
    finally:
        drake_log.setLevel(level)


def _port_problem(port: int) -> str:
    """Why the TCP ``port`` cannot be listened on, as found by binding it."""
    with socket.socket() as probe:
        try:
            probe.bind(("", port))
        except OSError as error:
            if error.errno == errno.EADDRINUSE:
                return "another program is listening there"
            if error.errno == errno.EACCES:
                return "this user may not open it (ports below 1024 are reserved)"
            return error.strerror or str(error)
    return "Meshcat could not open it"


def draw_task(meshcat: Meshcat, waypoints, *, neighbourhood: float = float("nan"), planned_path=None) -> None:
    """The ``waypoints`` (m, 3) [m]: each but the last as its neighbourhood, a sphere of radius
    ``neighbourhood`` [m] (the planner's :meth:`~drake_traj.planners.base.PlannerSystem.waypoint_neighbourhood`,
    Pająk 2024's ϵ), the last, and every one where it is NaN, as a marker of :data:`MARKER_RADIUS`;
    and the ``planned_path`` (N, 3) [m] where a planner computed it before moving. Replaces what
    an earlier call drew."""
    meshcat.Delete("/drake_traj")
    points = np.asarray(waypoints, dtype=float).reshape(-1, 3)
    for index, point in enumerate(points):
        path = f"/drake_traj/waypoints/{index}"
        turns_here = index < len(points) - 1 and np.isfinite(neighbourhood)
        meshcat.SetObject(path, Sphere(neighbourhood if turns_here else MARKER_RADIUS), WAYPOINT_COLOUR)
        meshcat.SetTransform(path, RigidTransform(point))
    if planned_path is not None and len(planned_path) > 1:
        meshcat.SetLine("/drake_traj/planned_path", np.asarray(planned_path, dtype=float).T.copy(), 2.0, PLANNED_COLOUR)


def draw_tcp_path(meshcat: Meshcat, points) -> None:
    """The measured TCP path (N, 3) [m] of a run, red."""
    if len(points) > 1:
        meshcat.SetLine("/drake_traj/tcp_path", np.asarray(points, dtype=float)[:, :3].T.copy(), 3.0, PATH_COLOUR)


def frame_task(meshcat: Meshcat, points) -> None:
    """Point the camera at the task: from the front, above and to the side of the box around
    ``points`` (N, 3) [m] and the robot's base (base frame, z up), far enough to see it all."""
    points = np.vstack([np.asarray(points, dtype=float).reshape(-1, 3), np.zeros((1, 3))])
    low, high = points.min(axis=0), points.max(axis=0)
    target = 0.5 * (low + high)
    size = max(float(np.linalg.norm(high - low)), 0.5)
    direction = np.array([0.55, -0.7, 0.45])  # in front of the UR10e (its workspace is at -y), above
    meshcat.SetCameraPose(camera_in_world=target + 1.2 * size * direction / np.linalg.norm(direction),
                          target_in_world=target)


def export_html(meshcat: Meshcat, path) -> Path:
    """Write the scene and its recording as one self-contained HTML file (no server needed)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(meshcat.StaticHtml())
    return path


def wait_for_browser(meshcat: Meshcat, timeout: float, *, poll: float = 0.1) -> bool:
    """Wait until a browser has the page open, at most ``timeout`` [s]; True if one connected."""
    deadline = time.monotonic() + timeout
    while meshcat.GetNumActiveConnections() == 0:
        if time.monotonic() >= deadline:
            return False
        time.sleep(poll)
    return True


class TcpTrail(LeafSystem):
    """Draws the measured TCP as a growing line in Meshcat (``/drake_traj/trail``), ``rate`` times
    per second of simulated time, from the plant state input [q; q̇]. Live view only: it is a
    Python publish event, outside the per-step path at 1 ms."""

    def __init__(self, meshcat: Meshcat, robot: Robot, *, rate: float = 20.0):
        super().__init__()
        self._meshcat = meshcat
        self._robot = robot
        self._points: list[np.ndarray] = []
        self._state = self.DeclareVectorInputPort("state", 2 * robot.num_joints)
        self.DeclarePeriodicPublishEvent(1.0 / rate, 0.0, self._draw)

    def _draw(self, context):
        q = self._state.Eval(context)[: self._robot.num_joints]
        self._points.append(self._robot.tool_position(q))
        if len(self._points) > 1:
            self._meshcat.SetLine("/drake_traj/trail", np.array(self._points).T, 3.0, PATH_COLOUR)


class SpeedSlider(LeafSystem):
    """A Meshcat slider ``speed override`` (0 to 1) as a source for a station's speed_override.
    With a ``profile`` (a scenario's :class:`~drake_traj.scenario.SpeedOverride`, not empty), the
    slider scales it: the output is the slider's value times the profile's at that time."""

    def __init__(self, meshcat: Meshcat, *, initial: float = 1.0, profile: SpeedOverride | None = None):
        super().__init__()
        self._meshcat = meshcat
        if profile is not None:
            instance_of(profile, SpeedOverride, "profile")
        self._profile = profile.trajectory() if profile is not None and np.size(profile.times) else None
        meshcat.AddSlider(SPEED_SLIDER, 0.0, 1.0, 0.01, initial)
        self.DeclareVectorOutputPort("speed_override", 1, self._output)

    def _output(self, context, out):
        value = self._meshcat.GetSliderValue(SPEED_SLIDER)
        if self._profile is not None:
            value *= float(self._profile.value(context.get_time())[0, 0])
        out.SetAtIndex(0, value)


def add_live_view(builder: DiagramBuilder, station, meshcat: Meshcat, robot: Robot, *,
                  speed_override: SpeedOverride | None = None) -> None:
    """Add a :class:`TcpTrail` on the station's measured state and a :class:`SpeedSlider` on its
    ``speed_override`` input, scaling the scenario's ``speed_override`` profile where given."""
    trail = builder.AddNamedSystem("tcp_trail", TcpTrail(meshcat, robot))
    builder.Connect(station.GetOutputPort("measured_state"), trail.get_input_port())
    slider = builder.AddNamedSystem("speed_slider", SpeedSlider(meshcat, profile=speed_override))
    builder.Connect(slider.get_output_port(), station.GetInputPort("speed_override"))
