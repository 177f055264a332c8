"""Check 6-axis arm descriptions as their vendors publish them: each arm of a manifest runs the
quintic, smooth-waypoints, Pająk and free-motion planners, and a straight move through the table
must be refused (docs/arm.md, "A description as published").

    python examples/check_descriptions.py MANIFEST [--out DIR] [--only LABEL ...] [--jobs N]
                                          [--json FILE] [--markdown FILE]

The manifest (YAML; every path relative to the manifest's folder)::

    arms:
      - label: irb2400                  # a plain name, unique: the row and its scenario file
        vendor: ABB
        repository: ros-industrial/abb  # optional, shown in --markdown: where the files come from
        package: abb_irb2400_support    # optional, the same
        licence: Apache-2.0             # optional, the same
        robot:                          # a !CustomArm's fields exactly as a scenario takes them
          model_file: abb/abb_irb2400_support/urdf/irb2400.xacro
          packages: {abb_irb2400_support: abb/abb_irb2400_support, abb_resources: abb/abb_resources}
          base_frame: base_link
          tool_frame: tool0
          name: irb2400
          acceleration_limits: [2.0, 2.0, 2.0, 2.0, 2.0, 2.0]
        variants: [quintic, smooth, pajak, free, table]   # optional: these only (default: all five)

``robot`` takes any field of ``!CustomArm`` (drake_traj/robots/custom.py); its paths
(``model_file``, ``srdf``, the folders of ``packages``) are made absolute, the rest is written as
given. For each arm:

1. The arm is read as a scenario reads it (``robot`` through the scenario's own YAML reader:
   :func:`~drake_traj.robots.custom.resolve_robot`), with the default cell (a table flush with
   the base) in a :class:`~drake_traj.cell.CellChecker`. An error here is every variant's.
2. The task is placed from the arm's reach R (the chain's bound): a level square of side 0.24 R
   whose first corner is 0.35-0.6 R from the base axis and 0.15-0.7 R above the table, the
   tool's z axis down (turned about it, or tilted by 0.5 rad); the first placement whose start
   (an IK solution of the first corner: the one furthest from the table and the arm itself,
   then nearest the middle of the ranges) keeps 40 mm from the table, and the other corners' IK
   on its branch and the joint-space lines between any two corners 25 mm; each keeps 20 mm
   between the arm's own links (a pair closer than that in the zero pose: 3 mm less than there,
   and left out when within the cell check's clearance there, which then judges it) and 0.2 rad
   inside the joint ranges.
3. A scenario file of five variants is written to ``OUT/<label>.yaml`` (``drake-traj run
   OUT/<label>.yaml --variant quintic`` runs one again), each from the start: ``quintic``
   (Benotsmane et al.'s moves to the joint solutions of corners 3 and 2 and back), ``smooth``
   (smooth waypoints through corners 2, 3, 4 and back), ``pajak`` (Pająk 2024's law round the
   square's corners 2, 3, 4 and back to 1), ``free`` (the free-motion planner to the first
   corner turned 90° about the base axis, round a post on the way whose top is 0.06 R above the
   tool) and ``table`` (a quintic move of the shoulder and the elbow, the least turn that puts
   the tool 0.1 R below the table top). The planners keep each joint at min(its speed, 1.05
   rad/s) and min(its acceleration limit, 1.4 rad/s²) (Pająk's law: the least over the joints).
4. Each variant is read with :func:`drake_traj.load_scenario` and run with
   :func:`drake_traj.simulate` (the preflight and the cell check first, as ``drake-traj run``).

A motion variant passes when it runs to the end (``ok`` with the motion's time); ``table`` passes
when the cell check refuses it, naming the table. Anything else fails with its error's text.
The table of outcomes is printed (and written with ``--markdown``; ``--json`` keeps every
message). With ``--jobs N`` (default 1) each arm runs in a process of its own, N at a time (an
arm that crashes its process fails alone); ``--jobs 0`` runs them in this process.

Exit codes: 0 every arm passed, 1 something failed, 2 a bad manifest or argument.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import yaml

VARIANTS = ("quintic", "smooth", "pajak", "free", "table")
TITLES = {"quintic": "quintic", "smooth": "smooth", "pajak": "Pająk", "free": "free motion", "table": "through the table"}
PATH_FIELDS = ("model_file", "srdf")  # robot fields naming a file, relative to the manifest
TASK_SPEED, TASK_ACCELERATION = 1.05, 1.4  # the planners' caps [rad/s, rad/s²]
CENTRES = [(rho, eta) for eta in (0.3, 0.2, 0.4, 0.5, 0.15, 0.6, 0.7) for rho in (0.5, 0.45, 0.55, 0.4, 0.6, 0.35)]
ORIENTATIONS = [[math.pi, 0.0, yaw] for yaw in (0.0, math.pi / 2, -math.pi / 2, math.pi)] + \
    [[math.pi, tilt, 0.0] for tilt in (0.5, -0.5)]  # tool z down, turned about it; tilted 0.5 rad [rad]
RANGE_MARGIN = 0.2  # the start's and the corners' joint positions keep this from their ranges [rad]
HALF_SIDE = 0.12  # the square's half side [R]
START_CLEARANCE, CORNER_CLEARANCE = 0.04, 0.025  # [m] from the table
SELF_CLEARANCE = 0.02  # [m] between the arm's own links (the cell check's clearance is 10 mm)
SEARCH_WITHIN = 0.15  # distances beyond this count as equal when a start is chosen [m]
BELOW_TABLE = 0.1  # the table move's goal puts the tool this far below the table top [R]
ARM_TIMEOUT = 3600.0  # one arm's process at most [s]
_PLAIN = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,60}")


class ManifestError(ValueError):
    """The manifest is malformed: names the arm and the field."""


@dataclass
class Entry:
    """One arm of the manifest: its row's data and its ``robot`` fields (paths absolute)."""

    label: str
    vendor: str
    robot: dict
    variants: tuple[str, ...] = VARIANTS
    repository: str = ""
    package: str = ""
    licence: str = ""


@dataclass
class Outcome:
    """One variant's outcome: ``status`` ok, refused, failed (the run stopped), error (refused
    before the run where a run was expected, or any exception) or skipped; ``passed`` whether it
    is what the variant expects; ``time`` the motion's [s]; ``message`` the error's text."""

    variant: str
    status: str
    passed: bool
    time: float | None = None
    message: str = ""


@dataclass
class ArmReport:
    """An arm's row: its entry's data and each variant's outcome."""

    label: str
    vendor: str
    repository: str = ""
    package: str = ""
    licence: str = ""
    model_file: str = ""
    fields: list[str] = field(default_factory=list)
    outcomes: list[Outcome] = field(default_factory=list)

    @property
    def passed(self) -> bool:
        return bool(self.outcomes) and all(outcome.passed for outcome in self.outcomes)


# ---- the manifest ------------------------------------------------------------------------------
def read_manifest(path: Path) -> list[Entry]:
    """The arms of a manifest file (module docstring), their paths made absolute; ManifestError
    naming the arm and the field otherwise."""
    try:
        document = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError) as error:
        raise ManifestError(f"{path}: {error}") from None
    arms = document.get("arms") if isinstance(document, dict) else None
    if not isinstance(arms, list) or not arms:
        raise ManifestError(f"{path}: the manifest must be a mapping with a non-empty list 'arms'")
    entries, labels = [], set()
    for k, item in enumerate(arms):
        where = f"{path}: arms[{k}]"
        if not isinstance(item, dict) or not isinstance(item.get("robot"), dict):
            raise ManifestError(f"{where} must be a mapping with a mapping 'robot' (the !CustomArm's fields)")
        unknown = set(item) - {"label", "vendor", "robot", "variants", "repository", "package", "licence"}
        if unknown:
            raise ManifestError(f"{where} has unknown keys {sorted(unknown)}")
        label = str(item.get("label") or item["robot"].get("name") or "")
        if not _PLAIN.fullmatch(label) or label in labels:
            raise ManifestError(f"{where}.label must be a plain unique name (letters, digits, _ . -), got {label!r}")
        labels.add(label)
        variants = tuple(item.get("variants") or VARIANTS)
        if not set(variants) <= set(VARIANTS):
            raise ManifestError(f"{where}.variants must be among {list(VARIANTS)}, got {list(variants)}")
        entries.append(Entry(label, str(item.get("vendor", "")), _absolute(item["robot"], path.parent, where),
                             variants, *(str(item.get(key, "")) for key in ("repository", "package", "licence"))))
    return entries


def _absolute(robot: dict, folder: Path, where: str) -> dict:
    """``robot`` with its file fields and package folders taken from ``folder``."""
    robot = dict(robot)
    for key in PATH_FIELDS:
        if isinstance(robot.get(key), str):
            robot[key] = str((folder / robot[key]).resolve())
    if "packages" in robot:
        if not isinstance(robot["packages"], dict):
            raise ManifestError(f"{where}.robot.packages must map package names to folders")
        robot["packages"] = {name: str((folder / str(value)).resolve()) for name, value in robot["packages"].items()}
    return robot


# ---- the task ----------------------------------------------------------------------------------
@dataclass
class Task:
    """Where an arm's variants go: the start [rad], the square's corners (4, 6) [m, rad] with
    their joint solutions (4, 6) [rad], the free motion's goal pose and post, and the table
    move's goal [rad]."""

    start: np.ndarray
    corners: np.ndarray
    corner_q: np.ndarray
    free_pose: np.ndarray
    post: dict
    table_goal: np.ndarray


def read_arm(entry: Entry):
    """The entry's arm as a scenario reads its ``robot`` field, and its cell checker (the
    default cell: a table flush with the base)."""
    from pydrake.common.yaml import yaml_load_typed

    from drake_traj.cell import CellChecker
    from drake_traj.robots.custom import CustomArm, resolve_robot

    arm = resolve_robot(yaml_load_typed(schema=CustomArm, data=json.dumps(entry.robot)))
    return arm, CellChecker(arm)


def self_floors(checker, home) -> dict:
    """{pair of the arm's links: the least distance [m] a start or corner must keep, None: left
    out} for the pairs closer than SELF_CLEARANCE at ``home`` [rad] (the zero pose), close by the
    description's meshes, not by the pose: within the cell check's clearance there, left out (the
    cell check judges them); else 3 mm less than there. Every other pair: SELF_CLEARANCE."""
    floors = {}
    for contact in checker.contacts(home, SELF_CLEARANCE):
        if all(contact.on_arm):
            close = contact.distance < checker.clearance
            floors[contact.bodies] = None if close else float(contact.distance) - 0.003
    return floors


def clearance(checker, q, floors: dict) -> tuple[float, float]:
    """(the least distance [m] of the arm at ``q`` to the cell, the least margin [m] of its own
    pairs over their floors (:func:`self_floors`)), each at most :data:`SEARCH_WITHIN`."""
    cell = own = SEARCH_WITHIN
    for contact in checker.contacts(q, SEARCH_WITHIN):
        if not all(contact.on_arm):
            cell = min(cell, float(contact.distance))
        elif floors.get(contact.bodies, SELF_CLEARANCE) is not None:
            own = min(own, float(contact.distance) - floors.get(contact.bodies, SELF_CLEARANCE))
    return cell, own


def clear(checker, q, floors: dict, from_cell: float) -> bool:
    """Whether the arm at ``q`` keeps ``from_cell`` [m] from the cell and its pairs' floors."""
    cell, own = clearance(checker, q, floors)
    return cell >= from_cell and own >= 0


def square(reach: float, rho: float, eta: float, rpy) -> np.ndarray:
    """The four corners (4, 6) of a horizontal square of side 2 HALF_SIDE R, the first at
    distance rho R from the base axis (on its x axis, at height eta R), in order round it."""
    a = HALF_SIDE * reach
    x0, z = rho * reach, eta * reach
    offsets = [(0.0, 0.0), (2 * a, 0.0), (2 * a, 2 * a), (0.0, 2 * a)]
    return np.array([[x0 - a + dx, -a + dy, z, *rpy] for dx, dy in offsets])


def _start_order(arm, checker, solutions, floors) -> list[np.ndarray]:
    """The IK solutions clear by START_CLEARANCE (and SELF_CLEARANCE), furthest from the cell
    and from the arm itself first (the smaller of the two; distances beyond SEARCH_WITHIN equal),
    then nearest the middle of the ranges."""
    middle = 0.5 * (arm.lower_limits + np.minimum(arm.upper_limits, arm.lower_limits + 4 * np.pi))
    scored = [(clearance(checker, q, floors), q) for q in solutions]
    kept = [(min(cell, own + SELF_CLEARANCE), q) for (cell, own), q in scored
            if cell >= START_CLEARANCE and own >= 0 and inside_ranges(arm, q)]
    return [q for least, q in sorted(kept, key=lambda item: (-round(item[0], 3), float(np.sum((item[1] - middle) ** 2))))]


def inside_ranges(arm, q) -> bool:
    """Whether every joint of ``q`` [rad] keeps RANGE_MARGIN from its range's ends."""
    return bool(np.all(q >= arm.lower_limits + RANGE_MARGIN) and np.all(q <= arm.upper_limits - RANGE_MARGIN))


def clear_between(checker, corner_q, floors, samples: int = 8) -> bool:
    """Whether the joint-space polygon through the corners' solutions (4, 6) [rad], round and
    across, keeps CORNER_CLEARANCE from the cell and SELF_CLEARANCE from itself at ``samples``
    points a side (the planners' paths pass near it)."""
    sides = [(a, b) for a in range(4) for b in range(a + 1, 4)]
    points = [corner_q[a] + s * (corner_q[b] - corner_q[a]) for a, b in sides for s in np.linspace(0, 1, samples)]
    return all(clear(checker, q, floors, CORNER_CLEARANCE) for q in points)


def place_square(arm, checker, floors) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(start [rad], corners (4, 6), their joint solutions (4, 6)): the first placement of
    :data:`CENTRES` and :data:`ORIENTATIONS` whose start and corners keep their clearances
    (module docstring, 2). ValueError when none does."""
    for rho, eta in CENTRES:
        for rpy in ORIENTATIONS:
            corners = square(arm.reach, rho, eta, rpy)
            try:
                solutions = arm.inverse_kinematics_all(corners[0])
            except ValueError:  # out of reach, or only beyond the joint ranges
                continue
            for start in _start_order(arm, checker, solutions, floors):
                try:
                    rest = arm.point_ik(corners[1:, :3], start)
                except ValueError:  # a corner without a solution
                    break
                poses = np.array([arm.tcp_pose(q) for q in rest])
                corner_q = np.vstack([start, rest])
                if (np.allclose(poses[:, :3], corners[1:, :3], atol=1e-4) and np.all(np.abs(rest - start) < 2.0)
                        and all(inside_ranges(arm, q) for q in rest) and clear_between(checker, corner_q, floors)):
                    return start, corners, corner_q
    raise ValueError(f"no square of the placements tried (distance 0.35-0.6 R, height 0.15-0.7 R, R = {arm.reach:.3f} m, "
                     f"tool z down or tilted) has a start {START_CLEARANCE * 1000:.0f} mm and corners "
                     f"{CORNER_CLEARANCE * 1000:.0f} mm clear of the table, {SELF_CLEARANCE * 1000:.0f} mm of the arm "
                     f"from itself and {RANGE_MARGIN} rad inside the joint ranges")


def free_goal(arm, start, corner) -> tuple[np.ndarray, dict]:
    """The free motion's goal pose (the corner turned 90° about the base axis, the way joint 1's
    range allows) and the post between (a !Box's fields), its top 0.06 R above the corner."""
    turn = math.pi / 2 if start[0] + math.pi / 2 <= arm.upper_limits[0] else -math.pi / 2
    c, s = math.cos(turn), math.sin(turn)
    goal = corner.copy()
    goal[:2] = [c * corner[0] - s * corner[1], s * corner[0] + c * corner[1]]
    goal[5] = corner[5] + turn
    radius, angle = math.hypot(*corner[:2]), math.atan2(corner[1], corner[0]) + turn / 2
    top = corner[2] + 0.06 * arm.reach
    post = dict(name="post", size=[round(0.1 * arm.reach, 4), round(0.06 * arm.reach, 4), round(top, 4)],
                xyz=[round(radius * math.cos(angle), 4), round(radius * math.sin(angle), 4), round(top / 2, 4)],
                rpy=[0.0, 0.0, round(angle, 6)])
    return goal, post


def table_goal(arm, start) -> np.ndarray:
    """The goal of a straight joint move into the table: the start with the shoulder and the
    elbow turned, each by a multiple of 0.1 rad within its range, the least turn (the larger of
    the two, then their sum) that puts the tool BELOW_TABLE R below the table top. ValueError
    when none does."""
    steps = np.round(np.arange(-3.1, 3.15, 0.1), 1)
    turns = sorted(((a, b) for a in steps for b in steps), key=lambda t: (max(abs(t[0]), abs(t[1])), abs(t[0]) + abs(t[1])))
    for shoulder, elbow in turns:
        goal = start.copy()
        goal[1:3] += [shoulder, elbow]
        inside = np.all(goal >= arm.lower_limits) and np.all(goal <= arm.upper_limits)
        if inside and arm.tcp_pose(goal)[2] < -BELOW_TABLE * arm.reach:
            return goal
    raise ValueError(f"no turn of the shoulder and the elbow within their ranges puts the tool {BELOW_TABLE} R below the table")


def place_task(arm, checker) -> Task:
    """The arm's :class:`Task` (module docstring, 2)."""
    floors = self_floors(checker, np.clip(np.zeros(6), arm.lower_limits, arm.upper_limits))
    start, corners, corner_q = place_square(arm, checker, floors)
    pose, post = free_goal(arm, start, corners[0])
    return Task(start, corners, corner_q, pose, post, table_goal(arm, start))


# ---- the scenario file -------------------------------------------------------------------------
def _flow(value) -> str:
    """A value as YAML flow text (JSON is YAML), numbers rounded to 1e-6."""
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, float):
        return json.dumps(round(value, 6))
    if isinstance(value, list):
        return "[" + ", ".join(_flow(item) for item in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{json.dumps(str(key))}: {_flow(item)}" for key, item in value.items()) + "}"
    return json.dumps(value)


def task_limits(arm) -> tuple[list[float], list[float]]:
    """The planners' joint limits: min(the arm's, TASK_SPEED) [rad/s], min(its, TASK_ACCELERATION) [rad/s²]."""
    speeds, accelerations = arm.joint_move_limits
    return np.minimum(speeds, TASK_SPEED).tolist(), np.minimum(accelerations, TASK_ACCELERATION).tolist()


def scenario_text(entry: Entry, arm, task: Task) -> str:
    """The arm's scenario file: the variants of ``entry.variants`` (module docstring, 3)."""
    speeds, accelerations = task_limits(arm)
    limits = f"    velocity_limit: {_flow(speeds)}\n    acceleration_limit: {_flow(accelerations)}\n"
    q = task.corner_q
    planners = {
        "quintic": f"!QuinticConfig\n    goals: {_flow([q[2], q[1], task.start])}\n{limits}",
        "smooth": f"!SmoothWaypointsConfig\n    goals: {_flow([q[1], q[2], q[3], task.start])}\n{limits}",
        "pajak": (f"!PajakConfig\n    waypoints: {_flow(np.roll(task.corners, -1, axis=0))}\n"
                  f"    velocity_limit: {_flow(min(speeds))}\n    acceleration_limit: {_flow(min(accelerations))}\n"
                  "    limit_velocity: true\n    limit_acceleration: true\n"),
        "free": f"!FreeMotionConfig\n    poses: {_flow([task.free_pose])}\n{limits}    seed: 0\n",
        "table": f"!QuinticConfig\n    goals: {_flow([task.table_goal])}\n{limits}",
    }
    what = {"quintic": "quintic moves through two corners' joint solutions and back",
            "smooth": "smooth waypoints through three corners' joint solutions and back",
            "pajak": "Pająk 2024's law round the square, back to the start", "free": "free motion round a post",
            "table": "a straight joint move through the table: must be refused"}
    lines = [f"# {entry.label} ({entry.vendor}): written by examples/check_descriptions.py",
             f"_arm: &arm {_flow(entry.robot)}", ""]
    for variant in entry.variants:
        lines += [f"{variant}:", f"  name: {entry.label}_{variant}", f"  description: {json.dumps(entry.label + ', ' + what[variant])}",
                  "  robot: !CustomArm", "    <<: *arm", f"  q_initial: {_flow(task.start)}",
                  f"  planner: {planners[variant]}".rstrip("\n")]
        if variant == "free":
            lines.append(f"  cell:\n    obstacles:\n      - !Box {_flow(task.post)}")
        lines += ["  settle_time: 0.5", ""]
    return "\n".join(lines)


# ---- running -----------------------------------------------------------------------------------
def _text(error: BaseException) -> str:
    return " ".join(str(error).split()) or type(error).__name__


def run_variant(path: Path, variant: str) -> Outcome:
    """One variant of the arm's scenario file read with load_scenario and run with simulate."""
    from drake_traj import load_scenario, simulate
    from drake_traj.cell import CollisionError

    expect_refusal = variant == "table"
    try:
        result = simulate(load_scenario(path, variant))
    except CollisionError as error:
        return Outcome(variant, "refused", expect_refusal and "table" in error.bodies, message=_text(error))
    except Exception as error:  # noqa: BLE001 - every error is the outcome, with its text
        return Outcome(variant, "error", False, message=f"{type(error).__name__}: {_text(error)}")
    if result.failure is not None:
        return Outcome(variant, "failed", False, result.duration, f"{result.failure.cause}: {_text(result.failure.message)}")
    return Outcome(variant, "ok", not expect_refusal, result.duration,
                   "" if not expect_refusal else "the move through the table was not refused")


def check_arm(entry: Entry, out: Path) -> ArmReport:
    """Read the entry's arm, place its task, write its scenario file to ``out`` and run each
    variant; an error before the runs is every variant's outcome."""
    report = ArmReport(entry.label, entry.vendor, entry.repository, entry.package, entry.licence,
                       entry.robot.get("model_file", ""), sorted(entry.robot))
    try:
        arm, checker = read_arm(entry)
        task = place_task(arm, checker)
    except Exception as error:  # noqa: BLE001
        stage = "placing the task" if "arm" in locals() else "reading the arm"
        message = f"{stage}: {type(error).__name__}: {_text(error)}"
        report.outcomes = [Outcome(variant, "error", False, message=message) for variant in entry.variants]
        return report
    path = out / f"{entry.label}.yaml"
    path.write_text(scenario_text(entry, arm, task))
    report.outcomes = [run_variant(path, variant) for variant in entry.variants]
    return report


def check_in_child(manifest: Path, label: str, out: Path) -> ArmReport:
    """:func:`check_arm` of one arm in a process of its own (this script with ``--only LABEL
    --jobs 0``): a crash or a timeout fails that arm alone."""
    entry = next(entry for entry in read_manifest(manifest) if entry.label == label)
    with tempfile.TemporaryDirectory() as folder:
        part = Path(folder) / "part.json"
        command = [sys.executable, str(Path(__file__).resolve()), str(manifest), "--only", label, "--jobs", "0",
                   "--out", str(out), "--json", str(part), "--quiet"]
        try:
            done = subprocess.run(command, capture_output=True, text=True, timeout=ARM_TIMEOUT)
            if part.is_file():
                return report_from_json(json.loads(part.read_text())[0])
            why = f"its process ended with code {done.returncode}: {(done.stderr or done.stdout).strip()[-600:]}"
        except subprocess.TimeoutExpired:
            why = f"its process ran over {ARM_TIMEOUT:.0f} s"
    return ArmReport(entry.label, entry.vendor, entry.repository, entry.package, entry.licence,
                     entry.robot.get("model_file", ""), sorted(entry.robot),
                     [Outcome(variant, "error", False, message=why) for variant in entry.variants])


def report_from_json(data: dict) -> ArmReport:
    """An :class:`ArmReport` from its ``--json`` form."""
    outcomes = [Outcome(**outcome) for outcome in data.pop("outcomes")]
    data.pop("passed", None)
    return ArmReport(**data, outcomes=outcomes)


# ---- the table ---------------------------------------------------------------------------------
REQUIRED_FIELDS = {"model_file", "base_frame", "tool_frame", "name", "acceleration_limits"}


def cell_text(outcome: Outcome | None, note: int | None) -> str:
    """A variant's cell of the table: ``ok 3.21 s``, ``refused (table)``, or ``FAIL [n]``."""
    if outcome is None:
        return "-"
    if outcome.passed:
        return f"ok {outcome.time:.2f} s" if outcome.status == "ok" else "refused (table)"
    return f"FAIL [{note}]"


def _common(message: str) -> str:
    """A message without its place in the scenario file and with -0 as 0: the same failure of an
    arm's variants reads alike."""
    return re.sub(r"-0\.0+\b", lambda m: m.group(0)[1:], re.sub(r"^\S+, line \d+, column \d+: ", "", message))


def table(reports: list[ArmReport], details: bool = False) -> str:
    """The outcomes as a Markdown table (``details``: with each arm's source, licence and the
    fields its scenario needed beyond the five every arm needs), then the failures' messages,
    each once (an arm's variants that failed alike share one)."""
    head = ["arm", "vendor"] + (["repository", "package, file", "licence", "fields needed"] if details else [])
    lines = ["| " + " | ".join(head + [TITLES[v] for v in VARIANTS]) + " |", "|" + "---|" * (len(head) + len(VARIANTS))]
    notes: dict[tuple[str, str], int] = {}
    for report in reports:
        by_variant = {outcome.variant: outcome for outcome in report.outcomes}
        cells = []
        for variant in VARIANTS:
            outcome = by_variant.get(variant)
            failure = None if outcome is None or outcome.passed else (report.label, f"{outcome.status}: {_common(outcome.message)}")
            if failure is not None:
                notes.setdefault(failure, len(notes) + 1)
            cells.append(cell_text(outcome, notes.get(failure)))
        extra = []
        if details:
            needed = ", ".join(f"`{name}`" for name in report.fields if name not in REQUIRED_FIELDS) or "-"
            extra = [report.repository, f"{report.package}, `{Path(report.model_file).name}`", report.licence, needed]
        lines.append("| " + " | ".join([report.label, report.vendor] + extra + cells) + " |")
    return "\n".join(lines + [""] + [f"[{n}] {label}: {text}" for (label, text), n in notes.items()])


def main(argv=None) -> int:
    """Check the manifest's arms; print the table. Exit 0 when all pass, 1 otherwise, 2 for bad input."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("manifest", type=Path)
    parser.add_argument("--out", type=Path, default=Path("out/check_descriptions"), help="the scenario files' folder")
    parser.add_argument("--only", nargs="+", metavar="LABEL", help="these arms only")
    parser.add_argument("--jobs", type=int, default=1, help="arms at a time, each in its own process; 0: in this process")
    parser.add_argument("--json", type=Path, help="write every outcome, with its whole message, here")
    parser.add_argument("--markdown", type=Path, help="write the table with each arm's source and fields here")
    parser.add_argument("--quiet", action="store_true", help="print nothing")
    args = parser.parse_args(argv)
    try:
        entries = read_manifest(args.manifest.resolve())
        if args.only:
            unknown = set(args.only) - {entry.label for entry in entries}
            if unknown:
                raise ManifestError(f"--only: no arm {sorted(unknown)} in {args.manifest}")
            entries = [entry for entry in entries if entry.label in args.only]
        if args.jobs < 0:
            raise ManifestError(f"--jobs must be 0 or more, got {args.jobs}")
        args.out.mkdir(parents=True, exist_ok=True)
    except (ManifestError, OSError) as error:
        print(f"check_descriptions.py: {error}", file=sys.stderr)
        return 2
    if args.jobs == 0:
        reports = []
        for entry in entries:
            reports.append(check_arm(entry, args.out.resolve()))
            if not args.quiet:
                print(f"{entry.label}: " + ", ".join(f"{o.variant} {o.status}" for o in reports[-1].outcomes), flush=True)
    else:
        with ThreadPoolExecutor(args.jobs) as pool:
            reports = list(pool.map(lambda entry: check_in_child(args.manifest.resolve(), entry.label, args.out.resolve()),
                                    entries))
    if args.json:
        args.json.write_text(json.dumps([{**asdict(report), "passed": report.passed} for report in reports], indent=1))
    if args.markdown:
        args.markdown.write_text(table(reports, details=True) + "\n")
    if not args.quiet:
        print(table(reports))
    return 0 if all(report.passed for report in reports) else 1


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit(130)
