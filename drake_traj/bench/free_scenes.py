"""Seeded free-motion scenes of increasing difficulty round a UR e-Series arm (the UR10e by
default), each a :class:`~drake_traj.cell.Cell` and queries that are feasible by construction.

Every scene is built round a known joint path, its *witness*: straight joint segments from the
query's start to its goal (through an opening, in steps of 5-10 mm of the wrist), checked with :class:`~drake_traj.cell.CellChecker` at every
:data:`WITNESS_SPACING` (1 mm) of the arm's travel bound (the check's own bound, Σ_j R_j |Δq_j|)
and kept at least :data:`WITNESS_CLEARANCE` + 1 mm from the cell and from the arm itself at every
sample, so at least 12 mm between them. The witness is kept with its query; the starts and goals
are inside the joint ranges and clear of the cell by its clearance (the default 10 mm, which the
planner keeps). The kinds (:data:`SCENE_KINDS`):

- ``open``: the table alone, random start and goal configurations;
- ``clutter``: 10-15 random boxes on and above the table, some across the straight joint move;
- ``shelf``: a shelf of cubbies (boards as boxes, 0.45 m deep) and a 0.12 m tool; the goal has
  the wrist inside a cubby;
- ``gate``: a fence 1.6 m tall with a gate; the start on the robot's side, the goal reaching
  through the gate;
- ``slot_40``, ``slot_60``: a wall with a horizontal slot 40 (60) mm taller than the forearm's
  diameter (its capsule's, read from the robot's model), the goal's forearm reaching through;
- ``pose_in_cubby``: the shelf and tool, the goal a TCP pose 0.4 m inside a cubby.

Frames: the world is the robot's base frame (z up, the table top z = 0). The structures of a
scene are built in the vertical plane of the arm at its base angle θ (q1): ``along`` [m] away
from the base (the arm's outward direction, −x at q1 = 0), ``lateral`` [m] along the joint-2
axis, ``z`` [m] up. Joint positions in rad.
"""

import functools
import zlib
from dataclasses import dataclass, field, replace

import numpy as np
from pydrake.geometry import Capsule
from pydrake.geometry import Cylinder as CylinderShape

from drake_traj.cell import Box, Cell, CellChecker, Cylinder, DEFAULT_CLEARANCE, NoMounting, Tool
from drake_traj.planners import FreeMotionConfig
from drake_traj.robots import UR10E

__all__ = ["FreeQuery", "FreeScene", "SCENE_KINDS", "WITNESS_CLEARANCE", "WITNESS_SPACING", "dense_path",
           "forearm_radius", "generate"]

WITNESS_CLEARANCE = 0.012  # [m] every witness keeps at least this from the cell and the arm itself
WITNESS_SPACING = 0.001  # [m] of the arm's travel bound between two checked samples of a witness
COARSE_SPACING = 0.01  # [m] the quick first look at a candidate witness
TOOL_LENGTH, TOOL_RADIUS = 0.12, 0.025  # [m] the shelf scenes' tool: a cylinder on the flange, TCP at its tip
CUBBY_DEPTH = 0.45  # [m]
POSE_DEPTH = 0.40  # [m] how far inside its cubby a pose goal's TCP is
BOARD = 0.02  # [m] the shelf's boards
WALL_HEIGHT = 1.6  # [m] the fence's and the wall's: out of the arm's reach over them at their distance
WALL_SPAN = 3.2  # [m] their width: out of the arm's reach round their ends
ATTEMPTS = 400  # random draws of a scene's parameters before giving up (a bug, not bad luck)


@dataclass(frozen=True, eq=False)
class FreeQuery:
    """One planning query: from ``start`` to ``goal`` (joint positions [rad], (n,)), or to the TCP
    pose ``pose`` [x, y, z m, φ_X, φ_Y, φ_Z rad] (Z-Y-X Euler angles, as
    :attr:`FreeMotionConfig.poses <drake_traj.planners.FreeMotionConfig.poses>` takes) that
    ``goal`` reaches; ``witness`` (k, n) [rad] the vertices of a joint path from ``start`` to
    ``goal`` that keeps :data:`WITNESS_CLEARANCE` (straight joint segments between them)."""

    start: np.ndarray
    goal: np.ndarray
    witness: np.ndarray
    pose: np.ndarray | None = None

    def config(self, **fields) -> FreeMotionConfig:
        """The free-motion planner's task for this query (``fields``: the other settings)."""
        if self.pose is not None:
            return FreeMotionConfig(poses=[self.pose.tolist()], **fields)
        return FreeMotionConfig(goals=[self.goal.tolist()], **fields)


@dataclass(frozen=True, eq=False)
class FreeScene:
    """A generated scene: its ``kind`` and ``seed``, the ``cell`` (clearance: the planner's), the
    ``robot`` (its TCP the cell tool's) and the ``queries``."""

    kind: str
    seed: int
    cell: Cell
    robot: object
    queries: tuple = field(default_factory=tuple)


@functools.cache
def forearm_radius(robot=UR10E) -> float:
    """The radius [m] of the forearm's tube in ``robot``'s model: the longest capsule or cylinder
    of its ``forearm_link`` (the UR10e's: 0.063 m); read once per robot (a plant of its own)."""
    checker = CellChecker(robot, Cell(mounting=NoMounting()))
    inspector = checker.scene_graph.model_inspector()
    body = checker.plant.GetBodyByName("forearm_link", checker.instance)
    tubes = [inspector.GetShape(g) for g in checker.plant.GetCollisionGeometriesForBody(body)]
    tubes = [shape for shape in tubes if isinstance(shape, (Capsule, CylinderShape))]
    return float(max(tubes, key=lambda shape: shape.length()).radius())


def dense_path(vertices, reach, spacing: float) -> np.ndarray:
    """The joint path ``vertices`` (k, n) [rad] sampled so that no point of the arm moves more
    than ``spacing`` [m] between two samples: per segment, the travel bound 1.1 Σ_j R_j |Δq_j|
    with ``reach`` R (n,) [m] (the cell check's :func:`~drake_traj.cell.joint_reach`)."""
    vertices = np.asarray(vertices, dtype=float)
    points = [vertices[:1]]
    for a, b in zip(vertices, vertices[1:]):
        pieces = max(1, int(np.ceil(1.1 * float(np.abs(b - a) @ reach) / spacing)))
        points.append(a + (b - a) * (np.arange(1, pieces + 1) / pieces)[:, None])
    return np.concatenate(points)


class _Witness:
    """The cell check of candidate witnesses in ``cell`` (at :data:`WITNESS_CLEARANCE`)."""

    def __init__(self, robot, cell: Cell):
        self.checker = CellChecker(robot, replace(cell, clearance=WITNESS_CLEARANCE))

    def nearest(self, vertices, within: float = 0.15, spacing: float = COARSE_SPACING) -> dict:
        """{the cell's geometry name ("self": the arm itself): its least distance [m] to the arm
        along the path ``vertices``}, pairs within ``within`` [m] only."""
        found = {}
        for q in dense_path(vertices, self.checker.reach, spacing):
            for contact in self.checker.contacts(q, within=within):
                name = "self" if all(contact.on_arm) else contact.geometries[contact.on_arm.index(False)]
                found[name] = min(found.get(name, within), contact.distance)
        return found

    def clear(self, vertices, spacing: float = WITNESS_SPACING) -> bool:
        """Whether every sample ``spacing`` [m] of travel apart along ``vertices`` keeps
        :data:`WITNESS_CLEARANCE` + :data:`WITNESS_SPACING` (a quick look first, then densely)."""
        for step in dict.fromkeys((COARSE_SPACING, spacing)):
            for q in dense_path(vertices, self.checker.reach, step):
                if self.checker.contacts(q, within=WITNESS_CLEARANCE + WITNESS_SPACING):
                    return False
        return True

    def connect(self, a, b, spacing: float = COARSE_SPACING, straight: bool = True) -> np.ndarray | None:
        """Vertices from ``a`` to ``b`` clear at ``spacing``: the straight segment (if
        ``straight``), or through the arm raised above both (upper arm and forearm upright), or None."""
        up = np.array([-np.pi / 2, 0.0])
        for path in ([a, b], [a, np.r_[a[0], up, a[3:]], np.r_[b[0], up, b[3:]], b])[not straight:]:
            if self.clear(path, spacing):
                return np.array(path)
        return None


class _Plane:
    """The vertical plane of a UR arm at base angle ``theta`` [rad]: points and boxes placed in it
    (module docstring), and the arm's configurations in it (closed form of the e-Series chain:
    elbow E = S + a2 (cos q2, -sin q2), wrist W = E + a3 (cos(q2 + q3), -sin(q2 + q3)) in
    (along, z), S the shoulder at height d1)."""

    def __init__(self, robot, theta: float):
        d, a = robot.data.d, robot.data.a
        self.d1, self.upper, self.fore = d[0], -a[1], -a[2]
        self.theta = float(theta)
        self.out = np.array([-np.cos(theta), -np.sin(theta), 0.0])
        self.side = np.array([np.sin(theta), -np.cos(theta), 0.0])

    def point(self, along: float, lateral: float, z: float) -> np.ndarray:
        return along * self.out + lateral * self.side + np.array([0.0, 0.0, z])

    def box(self, name: str, along: float, lateral: float, z: float, size) -> Box:
        """A box centred at (along, lateral, z) [m], edges ``size`` [m] along those directions."""
        return Box(name=name, size=[float(s) for s in size], xyz=self.point(along, lateral, z).tolist(),
                   rpy=[0.0, 0.0, self.theta + np.pi])

    def insertion(self, pivot, wrist_from: float, wrist_to: float, forward: bool, max_tilt: float,
                  step: float = 0.01) -> np.ndarray | None:
        """Configurations whose forearm's axis passes through ``pivot`` (along, z) [m] while the
        wrist point W moves out from ``wrist_from`` to ``wrist_to`` along [m], every ``step``
        [m] of W (elbow up; the upper arm swinging forward); None where W cannot or the forearm
        tilts more than ``max_tilt`` [rad]. The wrist lies flat (every wrist axis horizontal, the
        flange sideways) or, ``forward``, with the flange facing out of the plane's end (the tool
        horizontal, the wrist below the forearm)."""
        q2 = np.linspace(-np.pi / 2 - 0.9, 0.2, 3000)
        elbow = np.stack([self.upper * np.cos(q2), self.d1 - self.upper * np.sin(q2)], axis=1)
        towards = np.asarray(pivot, dtype=float) - elbow
        tilt = np.arctan2(-towards[:, 1], towards[:, 0])  # the forearm's angle below the horizontal
        wrist = elbow[:, 0] + self.fore * np.cos(tilt)
        first = int(np.argmax(wrist >= wrist_from))
        last = first + int(np.argmax(wrist[first:] >= wrist_to))
        if wrist[first] < wrist_from or wrist[last] < wrist_to or np.any(np.diff(wrist[first:last + 1]) <= 0):
            return None
        if np.max(np.abs(tilt[first:last + 1])) > max_tilt:
            return None
        targets = np.append(np.arange(wrist_from, wrist_to, step), wrist_to)
        q2s = np.interp(targets, wrist[first:last + 1], q2[first:last + 1])
        betas = np.interp(targets, wrist[first:last + 1], tilt[first:last + 1])
        wrist_1, wrist_2 = (-betas, np.full_like(betas, np.pi / 2)) if forward else (-np.pi / 2 - betas, 0 * betas)
        return np.stack([np.full_like(q2s, self.theta), q2s, betas - q2s, wrist_1, wrist_2, 0 * q2s], axis=1)


def _random_start(rng, goal) -> np.ndarray:
    """A configuration on the robot's side of a structure the arm reaches into at ``goal``: the
    base turned 0.5-1.6 rad away, the elbow up, each wrist joint within 3 rad of the goal's (so
    that a pose goal's solution nearest the start is ``goal`` itself)."""
    return np.array([goal[0] + rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 1.6), rng.uniform(-2.1, -1.0),
                     rng.uniform(0.6, 2.3), *(goal[3:] + rng.uniform(-3.0, 3.0, 3))])


def _random_configuration(rng) -> np.ndarray:
    """Any configuration with the upper arm above the table's plane."""
    return np.array([rng.uniform(-np.pi, np.pi), rng.uniform(-2.7, -0.45), rng.uniform(-2.6, 2.6),
                     *rng.uniform(-np.pi, np.pi, 3)])


def _balanced(build, vertices, robot, pairs, rounds: int = 2) -> np.ndarray:
    """The shift [m] (one per entry of ``pairs``) of a structure ``build(shift) -> Cell`` that puts
    the witness ``vertices`` midway between each pair of its obstacles (lower, upper names: each
    side's least distance, equal)."""
    shift = np.zeros(len(pairs))
    for _ in range(rounds):
        near = _Witness(robot, build(shift)).nearest(vertices)
        for k, (low, high) in enumerate(pairs):
            shift[k] += 0.5 * (near.get(low, 0.15) - near.get(high, 0.15))
    return shift


def _query(check: _Witness, rng, inserted: np.ndarray, robot, pose: bool) -> FreeQuery | None:
    """A query to the end of the ``inserted`` path from a random start on the robot's side
    (:func:`_random_start`), its witness checked densely; None where no start joins it."""
    for _ in range(40):
        start = _random_start(rng, inserted[-1])
        joined = check.connect(start, inserted[0])
        if joined is None:
            continue
        witness = np.concatenate([joined, inserted[1:]])
        if not check.clear(witness):
            return None
        goal = inserted[-1]
        return FreeQuery(start, goal, witness, robot.tcp_pose(goal) if pose else None)
    return None


def _open(rng, robot, count: int, straight: bool = True) -> list[FreeQuery] | None:
    """``count`` random start-goal pairs in the table's cell, their witnesses the straight joint
    move where it is clear (if ``straight``), else through the arm raised upright."""
    check = _Witness(robot, Cell())
    queries = []
    for _ in range(ATTEMPTS):
        start, goal = _random_configuration(rng), _random_configuration(rng)
        if not (check.clear([start]) and check.clear([goal])):
            continue
        witness = check.connect(start, goal, straight=straight)
        if witness is not None and check.clear(witness):
            queries.append(FreeQuery(start, goal, witness))
            if len(queries) == count:
                return queries
    return None


def open_scene(rng, robot, count: int) -> tuple[Cell, list[FreeQuery]] | None:
    """The table alone: random start and goal configurations (the upper arm above the table)."""
    queries = _open(rng, robot, count)
    return None if queries is None else (Cell(), queries)


def _clutter_boxes(rng, robot, queries) -> list[Box]:
    """Candidate boxes [m]: random ones on and above the table (at least 0.15 m from the base's
    axis), and some where the arm is on the straight joint move of a query (so that it is blocked)."""
    boxes = []
    for k in range(30):  # clear of the robot's base (which the cell check does not test against the cell)
        angle, size = rng.uniform(-np.pi, np.pi), rng.uniform(0.06, 0.3, 3)
        radius = rng.uniform(0.15 + 0.5 * np.hypot(size[0], size[1]), 1.15)
        z = 0.5 * size[2] if rng.uniform() < 0.5 else rng.uniform(0.2, 1.2)
        boxes.append(Box(name=f"box_{k}", size=size.tolist(), xyz=[radius * np.cos(angle), radius * np.sin(angle), z],
                         rpy=[0.0, 0.0, rng.uniform(-np.pi, np.pi)]))
    for k, query in enumerate(queries * 8):
        q = query.start + rng.uniform(0.25, 0.75) * (query.goal - query.start)
        centre = robot.tool_position(q) if k % 2 else robot.dh_frames(q)[2][:3, 3]  # the TCP or the elbow
        if centre[2] > 0.1 and np.hypot(*centre[:2]) > 0.3:
            boxes.append(Box(name=f"blocker_{k}", size=rng.uniform(0.06, 0.18, 3).tolist(), xyz=centre.tolist()))
    return boxes


def clutter_scene(rng, robot, count: int) -> tuple[Cell, list[FreeQuery]] | None:
    """10-15 boxes on and above the table, none within 13 mm of the queries' witnesses, the ones
    across their straight joint moves first."""
    queries = _open(rng, robot, count, straight=False)
    if queries is None:
        return None
    candidates = _clutter_boxes(rng, robot, queries)
    near = {}
    for query in queries:
        found = _Witness(robot, Cell(obstacles=candidates)).nearest(query.witness, within=0.03)
        near = {name: min(near.get(name, 1.0), distance) for name, distance in (near | found).items()}
    free = [box for box in candidates if near.get(box.name, 1.0) > WITNESS_CLEARANCE + 0.008]
    free.sort(key=lambda box: not box.name.startswith("blocker"))
    number = int(rng.integers(10, 16))
    if len(free) < number:
        return None
    cell = Cell(obstacles=free[:number])
    check = _Witness(robot, cell)
    return (cell, queries) if all(check.clear(query.witness) for query in queries) else None


def _tool_robot(robot):
    return robot.with_tcp([0.0, 0.0, TOOL_LENGTH], [0.0, 0.0, 0.0])


def _tool() -> Tool:
    return Tool(tcp_xyz=[0.0, 0.0, TOOL_LENGTH],
                shapes=[Cylinder(name="tool", radius=TOOL_RADIUS, length=TOOL_LENGTH, xyz=[0.0, 0.0, 0.5 * TOOL_LENGTH])])


def _shelf_boxes(plane: _Plane, front: float, lateral: float, z: float, width: float, height: float) -> list[Box]:
    """A shelf of 3 columns and up to 3 rows of cubbies (``width`` x ``height`` [m], 0.45 m deep,
    open towards the robot at ``front`` along): the target cubby, the middle column's middle
    row where it fits, centred at (``lateral``, ``z``); rows that would go into the table left
    out. Board names: ``floor`` and ``ceiling`` of the target, ``left``, ``right`` its sides."""
    pitch_side, pitch_up = width + BOARD, height + BOARD
    rows = [k for k in (-1, 0, 1) if z + (k - 0.5) * pitch_up > 0.05]
    levels = [z + (k - 0.5) * pitch_up for k in rows] + [z + (rows[-1] + 0.5) * pitch_up]
    top, centre = levels[-1] + 0.5 * BOARD, front + 0.5 * CUBBY_DEPTH
    names = {z - 0.5 * pitch_up: "floor", z + 0.5 * pitch_up: "ceiling"}
    boxes = [plane.box(names.get(level, f"board_{k}"), centre, lateral, level, [CUBBY_DEPTH, 3 * pitch_side + BOARD, BOARD])
             for k, level in enumerate(levels)]
    for k, name in enumerate(("side_0", "left", "right", "side_3")):
        boxes.append(plane.box(name, centre, lateral + (k - 1.5) * pitch_side, 0.5 * top, [CUBBY_DEPTH, BOARD, top]))
    boxes.append(plane.box("back", front + CUBBY_DEPTH + 0.5 * BOARD, lateral, 0.5 * top,
                           [BOARD, 3 * pitch_side + BOARD, top]))
    return boxes


def _cubby(rng, robot, count: int, deep: bool) -> tuple[Cell, list[FreeQuery]] | None:
    """The shelf scenes: the tool's TCP 0.4 m inside the cubby (``deep``: a pose goal) or the
    wrist 0.02-0.1 m inside (a joint goal)."""
    plane = _Plane(robot, rng.uniform(-np.pi, np.pi))
    tooled = _tool_robot(robot)
    front, pivot_z = rng.uniform(0.55, 0.8), rng.uniform(0.5, 0.95)
    width, height = rng.uniform(0.38, 0.46), rng.uniform(0.33, 0.4)
    hand = robot.data.d[5] + TOOL_LENGTH  # [m] from W to the TCP along the tool
    inside = POSE_DEPTH - hand if deep else rng.uniform(0.02, 0.1)
    approach = front - hand - 0.08  # [m] W where the TCP is 8 cm outside the cubby
    inserted = plane.insertion([front, pivot_z], approach, front + inside + 0.03 * deep, True, np.radians(10))
    if inserted is not None and deep:  # W where the TCP is exactly POSE_DEPTH inside
        depth = tooled.tool_position(inserted) @ plane.out - front
        wrist = np.interp(POSE_DEPTH, depth, _wrist_along(plane, inserted), right=np.nan)
        inserted = None if np.isnan(wrist) else plane.insertion([front, pivot_z], approach, wrist, True, np.radians(10))
    if inserted is None:
        return None

    def build(shift):
        return Cell(obstacles=_shelf_boxes(plane, front, 0.1 + shift[1], pivot_z - 0.05 + shift[0], width, height),
                    tool=_tool())

    shift = _balanced(build, inserted, tooled, [("floor", "ceiling"), ("left", "right")])
    cell = build(shift)
    return _queries(rng, tooled, cell, plane, inserted, count, pose=deep)


def _wrist_along(plane: _Plane, configurations) -> np.ndarray:
    """The wrist point W's distance along the plane [m] of each configuration (k, n)."""
    q2, q3 = configurations[:, 1], configurations[:, 2]
    return plane.upper * np.cos(q2) + plane.fore * np.cos(q2 + q3)


def _queries(rng, robot, cell: Cell, plane: _Plane, inserted, count: int, pose: bool = False):
    """``count`` queries to the end of ``inserted`` in ``cell`` from random starts; None if any fails."""
    check = _Witness(robot, cell)
    queries = [_query(check, rng, inserted, robot, pose) for _ in range(count)]
    return None if any(query is None for query in queries) else (cell, queries)


def shelf_scene(rng, robot, count: int):
    """A shelf of cubbies and a 0.12 m tool; the goal has the wrist inside a cubby."""
    return _cubby(rng, robot, count, deep=False)


def pose_in_cubby_scene(rng, robot, count: int):
    """The shelf and tool; the goal a TCP pose 0.4 m inside a cubby, the tool level."""
    return _cubby(rng, robot, count, deep=True)


def gate_scene(rng, robot, count: int):
    """A fence 1.6 m tall 0.55-0.8 m from the base, a gate 0.36-0.5 m wide and 0.95-1.3 m tall
    in it; the start on the robot's side, the goal with the forearm through the gate."""
    plane = _Plane(robot, rng.uniform(-np.pi, np.pi))
    fence, pivot_z = rng.uniform(0.55, 0.8), rng.uniform(0.4, 0.85)
    width, tall, thick = rng.uniform(0.36, 0.5), rng.uniform(0.95, 1.3), 0.04
    inserted = plane.insertion([fence, pivot_z], fence - 0.35, fence + rng.uniform(0.1, 0.25), False, np.radians(30))
    if inserted is None:
        return None

    def build(shift):
        centre, half = 0.1 + shift[0], 0.5 * WALL_SPAN
        left, right = centre - 0.5 * width, centre + 0.5 * width
        return Cell(obstacles=[
            plane.box("left", fence, 0.5 * (left - half), 0.5 * WALL_HEIGHT, [thick, left + half, WALL_HEIGHT]),
            plane.box("right", fence, 0.5 * (right + half), 0.5 * WALL_HEIGHT, [thick, half - right, WALL_HEIGHT]),
            plane.box("lintel", fence, centre, 0.5 * (tall + WALL_HEIGHT), [thick, width, WALL_HEIGHT - tall])])

    cell = build(_balanced(build, inserted, robot, [("left", "right")]))
    return _queries(rng, robot, cell, plane, inserted, count)


def _slot(rng, robot, count: int, extra: float):
    """A wall 0.65-0.9 m from the base with a slot ``extra`` [m] taller than the forearm's
    diameter and 0.5-0.8 m wide; the goal's forearm through the slot, the wrist 0.06-0.15 m past it."""
    plane = _Plane(robot, rng.uniform(-np.pi, np.pi))
    wall, centre_z = rng.uniform(0.65, 0.9), rng.uniform(0.6, 0.85)
    thick, width = rng.uniform(0.02, 0.03), rng.uniform(0.5, 0.8)
    inserted = plane.insertion([wall, centre_z], wall - 0.3, wall + 0.5 * thick + rng.uniform(0.06, 0.15), False,
                               np.radians(8), step=0.005)
    if inserted is None:
        return None
    tall = 2 * forearm_radius(robot) + extra

    def build(shift):
        low, high = centre_z + shift[0] - 0.5 * tall, centre_z + shift[0] + 0.5 * tall
        lateral, half = 0.13 + shift[1], 0.5 * WALL_SPAN
        left, right = lateral - 0.5 * width, lateral + 0.5 * width
        return Cell(obstacles=[
            plane.box("below", wall, 0.0, 0.5 * low, [thick, WALL_SPAN, low]),
            plane.box("above", wall, 0.0, 0.5 * (high + WALL_HEIGHT), [thick, WALL_SPAN, WALL_HEIGHT - high]),
            plane.box("left", wall, 0.5 * (left - half), 0.5 * (low + high), [thick, left + half, tall]),
            plane.box("right", wall, 0.5 * (right + half), 0.5 * (low + high), [thick, half - right, tall])])

    cell = build(_balanced(build, inserted, robot, [("below", "above"), ("left", "right")]))
    return _queries(rng, robot, cell, plane, inserted, count)


SCENE_KINDS = {
    "open": open_scene,
    "clutter": clutter_scene,
    "gate": gate_scene,
    "shelf": shelf_scene,
    "slot_60": lambda rng, robot, count: _slot(rng, robot, count, 0.06),
    "slot_40": lambda rng, robot, count: _slot(rng, robot, count, 0.04),
    "pose_in_cubby": pose_in_cubby_scene,
}
"""The scene kinds, easiest first: name -> ``make(rng, robot, count)``, (cell, queries) or None
where the draw did not give a feasible scene (:func:`generate` draws again)."""


def generate(kind: str, seed: int, *, count: int = 1, robot=UR10E) -> FreeScene:
    """The scene of ``kind`` (:data:`SCENE_KINDS`) drawn from ``seed`` (a whole number: the same
    seed, the same scene) with ``count`` queries, round ``robot`` (a UR e-Series arm: the
    witnesses use its closed-form chain). Raises ValueError for an unknown kind or a robot that
    is not a UR e-Series arm, RuntimeError where no feasible scene was drawn."""
    if kind not in SCENE_KINDS:
        raise ValueError(f"kind must be one of {list(SCENE_KINDS)}, got {kind!r}")
    if not hasattr(robot, "data") or not hasattr(robot, "dh_frames"):
        raise ValueError(f"the free-motion scenes are built round a UR e-Series arm, got {robot.name}")
    rng = np.random.default_rng([int(seed), zlib.crc32(kind.encode())])
    for _ in range(ATTEMPTS):
        made = SCENE_KINDS[kind](rng, robot, count)
        if made is not None:
            cell, queries = made
            tooled = _tool_robot(robot) if cell.tool.shapes else robot
            return FreeScene(kind, int(seed), replace(cell, clearance=DEFAULT_CLEARANCE), tooled, tuple(queries))
    raise RuntimeError(f"no feasible {kind} scene in {ATTEMPTS} draws from seed {seed}")
