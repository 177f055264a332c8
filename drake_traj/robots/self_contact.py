"""The pairs of an arm's links that its self-collision check leaves out, and why.

Drake's MultibodyPlant already leaves out, when it is finalized, the two bodies of every joint
and the bodies welded together (and everything welded to the world). A published description
often needs more left out: its collision meshes, checked as their convex hulls, overlap at a
joint in every pose (ABB's IRB 2400 and IRB 4600: the hulls of link_4 and link_6 around the
wrist), and every start would be refused as the arm hitting itself. Three more kinds of pairs are
left out (:func:`self_contact`), each named with its reason in a run's ``metrics.json`` and
``run.json`` (``unchecked_collision_pairs``: [link, link, reason]):

- ``"srdf"``: the pairs the arm's MoveIt configuration disables (``robot.srdf``: its
  ``<disable_collisions link1= link2=>``, whatever its ``reason``; the user named the file). A link
  the model does not have is refused, naming the file and the link.
- ``"adjacent through L (no collision shapes)"``: links joined through links without collision
  shapes only (a shapeless fixed flange, a massless link between two joints), which MoveIt's Setup
  Assistant counts as adjacent (it removes the shapeless links from the kinematic graph and joins
  their neighbours); Drake filters only a joint's own two bodies and a welded group.
- ``"in contact in every sampled pose"``: MoveIt's "always in collision", made strict: the arm's
  home configuration and :data:`SAMPLES` configurations drawn uniformly within the joint ranges
  (seed :data:`SEED`; the arm's other joints at their defaults), and a pair of shapes is left out
  only if it is in contact (signed distance below :data:`CONTACT_DISTANCE`) in every one of them.
  A pair of shapes apart in a share p of the joint ranges is kept with probability
  1 - (1 - p)^1000: above 99 % for p >= 0.5 %. MoveIt's "Default" and "Never" (apart in some or
  all samples) are never inferred.

The pairs are found on a plant of the arm alone, once per arm: cached by the arm's description
(its model file's or text's content, packages, frames, joint ranges, home and SRDF content) for
the life of the process. :func:`exclude_self_contact` applies them to any finalized plant holding
the arm (the cell check's, the station's, a benchmark's probe) through its SceneGraph's collision
filter manager, before contexts are made: every query and the simulated contact then leave them
out, and plants made from the same arm and cell keep the same scene fingerprint.

A self-contact refusal names the two shapes (:func:`shape_text`: a primitive's size, a mesh as its
convex hull) and, for a pair that touches in most of the sampled poses but not all
(:func:`contact_share`), says where to leave it out (:func:`touching_shapes`, :func:`srdf_hint`).
"""

from __future__ import annotations

import hashlib
import time
import xml.etree.ElementTree as ElementTree
from collections import deque
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydrake.geometry import (Box, Capsule, CollisionFilterDeclaration, Convex, Cylinder, Ellipsoid, GeometrySet, Mesh,
                              Sphere)
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from drake_traj.errors import Cause, DrakeTrajError
from drake_traj.validation import path_argument

__all__ = ["ALWAYS", "CONTACT_DISTANCE", "SAMPLES", "SEED", "SRDF", "SelfContact", "UncheckedPair", "contact_share",
           "exclude_self_contact", "self_contact", "shape_text", "srdf_file", "srdf_hint", "srdf_pairs",
           "touching_shapes"]

SAMPLES = 1000
"""Random configurations the detection draws (besides the arm's home configuration)."""
SEED = 0
"""The seed of those configurations: the same ones on every run of the same arm."""
CONTACT_DISTANCE = 1e-5
"""[m] two shapes are in contact below this signed distance: SceneGraph's distances of two
shapes that touch by design scatter by a few µm from pose to pose."""
SRDF = "srdf"
"""The reason of a pair the arm's MoveIt configuration disables."""
ALWAYS = "in contact in every sampled pose"
"""The reason of a pair found in contact in every sampled configuration."""
MOSTLY = 0.5
"""A refused pair in contact (or within the clearance) in at least this share of the sampled
poses gets the hint to name it in robot.srdf."""


@dataclass(frozen=True)
class UncheckedPair:
    """Two links of an arm whose collision shapes the checks leave out.

    Attributes:
        links: the two links' names (bodies of the arm's model), in the model's order.
        reason: :data:`SRDF`, ``"adjacent through ... (no collision shapes)"`` or :data:`ALWAYS`.
        shapes: the pairs of shapes left out, (k_a, k_b) indices into each link's collision
            geometries in the model's order (``GetCollisionGeometriesForBody``).
    """

    links: tuple[str, str]
    reason: str
    shapes: tuple[tuple[int, int], ...]

    def row(self) -> list[str]:
        """[link_a, link_b, reason], as ``metrics.json`` and ``run.json`` list it."""
        return [*self.links, self.reason]


@dataclass(frozen=True)
class SelfContact:
    """What :func:`self_contact` found for one arm: the pairs left out, how many configurations
    were sampled (0: no pair was left to sample, fewer than 1 + :data:`SAMPLES`: every pair was
    apart somewhere before the last) and how long finding them took [s] (the plant included)."""

    pairs: tuple[UncheckedPair, ...]
    samples: int
    seconds: float

    def rows(self) -> list[list[str]]:
        """The pairs as [link_a, link_b, reason] rows."""
        return [pair.row() for pair in self.pairs]


# ---- the arm's MoveIt configuration --------------------------------------------------------------
def srdf_file(value, field: tuple = ("srdf",)) -> Path:
    """``value`` as the path of an existing ``.srdf`` file (absolute), else DrakeTrajError at
    ``field`` (a ``.srdf.xacro`` must be expanded first)."""
    path = path_argument(value, field[-1])
    label = ".".join(str(part) for part in field)
    if path.suffix.lower() != ".srdf":
        raise DrakeTrajError(f"{label} must name a MoveIt .srdf file, got {str(path)[:200]}"
                             + (" (expand the xacro first: xacro file.srdf.xacro > file.srdf)"
                                if path.suffix.lower() == ".xacro" else ""), field=field, cause=Cause.INVALID)
    if not path.is_file():
        raise DrakeTrajError(f"{label} {str(path)[:200]} is not a file", field=field, cause=Cause.INVALID)
    return path.resolve()


def srdf_pairs(path: Path, links, field: tuple = ("robot", "srdf")) -> list[tuple[str, str]]:
    """The link pairs of the SRDF file ``path``'s ``<disable_collisions link1= link2=>`` (a link
    with itself skipped), each link one of ``links`` (the model's link names); DrakeTrajError at
    ``field`` naming the file for a file that is not SRDF, an element without its links, or a
    link the model does not have."""
    label = ".".join(str(part) for part in field)
    try:
        root = ElementTree.parse(path).getroot()
    except (ElementTree.ParseError, OSError) as error:
        raise DrakeTrajError(f"{label}: {path} cannot be read as SRDF: {error}", field=field, cause=Cause.INVALID) from None
    if root.tag != "robot":
        raise DrakeTrajError(f"{label}: {path} is not SRDF (its root is <{root.tag}>, not <robot>)", field=field,
                             cause=Cause.INVALID)
    known, pairs = set(links), []
    for element in root.iter("disable_collisions"):
        pair = (element.get("link1"), element.get("link2"))
        if not all(pair):
            raise DrakeTrajError(f"{label}: {path} has a <disable_collisions> without link1 and link2: "
                                 f"{ElementTree.tostring(element, encoding='unicode').strip()[:200]}", field=field,
                                 cause=Cause.INVALID)
        for link in pair:
            if link not in known:
                raise DrakeTrajError(f"{label}: {path} disables collisions of the link {link!r}, which the arm's model "
                                     f"does not have (its links: {', '.join(links)})", field=field, cause=Cause.INVALID)
        if pair[0] != pair[1]:
            pairs.append(pair)
    return pairs


# ---- the arm alone -------------------------------------------------------------------------------
class _ArmScene:
    """A plant and SceneGraph of ``robot`` alone (its :meth:`add_to_plant`), finalized, with a
    context: the shapes of each link and the configurations the detection samples."""

    def __init__(self, robot):
        builder = DiagramBuilder()
        self.plant, self.scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
        self.instance = robot.add_to_plant(self.plant)
        self.plant.Finalize()
        self._diagram = builder.Build()
        context = self._diagram.CreateDefaultContext()
        self._plant_context = self.plant.GetMyMutableContextFromRoot(context)
        self._scene_context = self.scene_graph.GetMyContextFromRoot(context)
        self._query = self.scene_graph.get_query_output_port()
        self.inspector = self.scene_graph.model_inspector()
        self._default = self.plant.GetPositions(self._plant_context).copy()
        self._indices = [self.plant.GetJointByName(name, self.instance).position_start() for name in robot.joint_names]
        bodies = [self.plant.get_body(index) for index in self.plant.GetBodyIndices(self.instance)]
        self.links = [body.name() for body in bodies]
        self.shapes = {body.name(): list(self.plant.GetCollisionGeometriesForBody(body)) for body in bodies}
        self.owner = {geometry: link for link, geometries in self.shapes.items() for geometry in geometries}
        lower, upper = np.asarray(robot.lower_limits, dtype=float), np.asarray(robot.upper_limits, dtype=float)
        lower, upper = np.where(np.isfinite(lower), lower, -np.pi), np.where(np.isfinite(upper), upper, np.pi)
        draws = np.random.default_rng(SEED).uniform(lower, upper, (SAMPLES, len(lower)))
        self.configurations = np.vstack([robot.home_configuration, draws])

    def query(self, q):
        """SceneGraph's QueryObject with the arm's joints at ``q`` (the others at their defaults)."""
        positions = self._default.copy()
        positions[self._indices] = q
        self.plant.SetPositions(self._plant_context, positions)
        return self._query.Eval(self._scene_context)

    def candidates(self) -> set[tuple]:
        """The pairs of the arm's geometries SceneGraph checks (Drake's own filters applied), each
        in the model's order."""
        order = {geometry: k for k, geometry in enumerate(self.owner)}
        return {tuple(sorted(pair, key=order.get)) for pair in self.inspector.GetCollisionCandidates()
                if all(geometry in self.owner for geometry in pair)}

    def shape_pairs(self, link_a: str, link_b: str, among: set) -> tuple[tuple[int, int], ...]:
        """The (k_a, k_b) index pairs of the two links' shapes that are in ``among``."""
        return tuple((ka, kb) for ka, a in enumerate(self.shapes[link_a]) for kb, b in enumerate(self.shapes[link_b])
                     if (a, b) in among or (b, a) in among)


def _adjacent_pairs(scene: _ArmScene) -> dict[tuple[str, str], list[str]]:
    """{(link_a, link_b): the shapeless links between them} for every two links with shapes joined
    through shapeless links only (MoveIt's adjacency once shapeless links are removed), the world
    body counted as a shapeless link."""
    plant = scene.plant
    neighbours: dict[str, set[str]] = {}
    for index in plant.GetJointIndices():
        joint = plant.get_joint(index)
        parent, child = joint.parent_body().name(), joint.child_body().name()
        neighbours.setdefault(parent, set()).add(child)
        neighbours.setdefault(child, set()).add(parent)
    shaped = {link for link, shapes in scene.shapes.items() if shapes}
    found = {}
    for start in sorted(shaped & set(neighbours)):
        paths, queue = {start: []}, deque([start])
        while queue:  # breadth first through shapeless links only
            link = queue.popleft()
            for other in sorted(neighbours.get(link, ())):
                if other in paths:
                    continue
                paths[other] = paths[link] + ([link] if link != start else [])
                if other in shaped:
                    if paths[other]:  # a joint's own two bodies: Drake's filter
                        found[tuple(sorted((start, other), key=scene.links.index))] = paths[other]
                else:
                    queue.append(other)
    return found


def _always_in_contact(scene: _ArmScene, pairs: set) -> tuple[set, int]:
    """The geometry pairs of ``pairs`` in contact at every configuration of ``scene``, and how many
    configurations were looked at (sampling stops once no pair is left)."""
    count = 0
    for q in scene.configurations:
        if not pairs:
            break
        count += 1
        query = scene.query(q)
        if count == 1:  # every pair at once: most are apart at the first pose
            touching = {frozenset((p.id_A, p.id_B)) for p in query.ComputeSignedDistancePairwiseClosestPoints(CONTACT_DISTANCE)
                        if p.distance < CONTACT_DISTANCE}
            pairs = {pair for pair in pairs if frozenset(pair) in touching}
        else:
            pairs = {pair for pair in pairs if query.ComputeSignedDistancePairClosestPoints(*pair).distance < CONTACT_DISTANCE}
    return pairs, count


def _detect(robot, scene: _ArmScene, began: float) -> SelfContact:
    """:func:`self_contact`'s work on the arm alone (``scene``, made from ``began``, a
    ``time.perf_counter()`` [s])."""
    candidates = scene.candidates()
    found: list[UncheckedPair] = []

    def leave_out(link_a: str, link_b: str, reason: str) -> None:
        shapes = scene.shape_pairs(link_a, link_b, candidates)
        if shapes:  # a pair Drake checks
            found.append(UncheckedPair((link_a, link_b), reason, shapes))
            candidates.difference_update({(scene.shapes[link_a][ka], scene.shapes[link_b][kb]) for ka, kb in shapes}
                                         | {(scene.shapes[link_b][kb], scene.shapes[link_a][ka]) for ka, kb in shapes})

    srdf = getattr(robot, "srdf", None)
    if srdf is not None:
        for pair in srdf_pairs(srdf, scene.links):
            leave_out(*sorted(pair, key=scene.links.index), SRDF)
    for (link_a, link_b), between in _adjacent_pairs(scene).items():
        leave_out(link_a, link_b, f"adjacent through {', '.join(between)} (no collision shapes)")
    always, samples = _always_in_contact(scene, candidates)
    by_links: dict[tuple[str, str], set] = {}
    for a, b in always:
        by_links.setdefault((scene.owner[a], scene.owner[b]), set()).add((a, b))
    for (link_a, link_b), pairs in sorted(by_links.items(), key=lambda item: [scene.links.index(k) for k in item[0]]):
        found.append(UncheckedPair((link_a, link_b), ALWAYS, scene.shape_pairs(link_a, link_b, pairs)))
    return SelfContact(tuple(found), samples, time.perf_counter() - began)


# ---- the cache -----------------------------------------------------------------------------------
_FOUND: dict[str, tuple[_ArmScene, SelfContact]] = {}


def _key(robot) -> str:
    """A digest of what the pairs depend on: the arm's class, name, model (its file's or text's
    content, packages, xacro arguments, base weld), joints, held joints, ranges, home and SRDF
    content."""
    text = getattr(robot, "model_text", None)
    srdf = getattr(robot, "srdf", None)
    parts = (type(robot).__name__, robot.name, text if text is not None else robot.model_path().read_bytes(),
             sorted((str(k), str(v)) for k, v in getattr(robot, "packages", {}).items()),
             sorted(getattr(robot, "xacro_args", {}).items()), getattr(robot, "base_frame", ""),
             getattr(robot, "base_welded", None), tuple(robot.joint_names),
             sorted((str(k), float(v)) for k, v in getattr(robot, "locked_joints", {}).items()),
             np.asarray(robot.lower_limits, dtype=float).tobytes(), np.asarray(robot.upper_limits, dtype=float).tobytes(),
             np.asarray(robot.home_configuration, dtype=float).tobytes(),
             None if srdf is None else (str(srdf), Path(srdf).read_bytes()))
    return hashlib.sha256(repr(parts).encode()).hexdigest()


def _arm(robot) -> tuple[_ArmScene, SelfContact]:
    key = _key(robot)
    if key not in _FOUND:
        began = time.perf_counter()
        scene = _ArmScene(robot)
        _FOUND[key] = (scene, _detect(robot, scene, began))
    return _FOUND[key]


def self_contact(robot) -> SelfContact:
    """The pairs of ``robot``'s links its checks leave out besides Drake's own filters (module
    docstring), found once per arm description in a process. Raises DrakeTrajError at
    ``robot.srdf`` for an SRDF the model does not fit."""
    return _arm(robot)[1]


def exclude_self_contact(plant, scene_graph, instance, robot) -> tuple[UncheckedPair, ...]:
    """Leave out :func:`self_contact`'s pairs in a finalized ``plant`` (with ``scene_graph``)
    holding ``robot`` as the model instance ``instance``: a collision filter on the SceneGraph's
    model, so call it before any context is made. Returns the pairs."""
    pairs = self_contact(robot).pairs
    if pairs:
        declaration = CollisionFilterDeclaration()
        for pair in pairs:
            shapes_a, shapes_b = (plant.GetCollisionGeometriesForBody(plant.GetBodyByName(link, instance))
                                  for link in pair.links)
            for ka, kb in pair.shapes:
                declaration.ExcludeBetween(GeometrySet(shapes_a[ka]), GeometrySet(shapes_b[kb]))
        scene_graph.collision_filter_manager().Apply(declaration)
    return pairs


# ---- refusals ------------------------------------------------------------------------------------
def contact_share(robot, link_a: str, link_b: str, below: float = CONTACT_DISTANCE) -> tuple[int, int]:
    """(in how many of the detection's configurations any shape of ``link_a`` is closer than
    ``below`` [m] to any of ``link_b``'s, how many configurations); (0, 0) where either is not a
    link with shapes of the arm alone (a tool, a cell's body)."""
    scene = _arm(robot)[0]
    if not (scene.shapes.get(link_a) and scene.shapes.get(link_b)):
        return 0, 0
    pairs = [(a, b) for a in scene.shapes[link_a] for b in scene.shapes[link_b]]
    count = sum(min(scene.query(q).ComputeSignedDistancePairClosestPoints(a, b).distance for a, b in pairs) < below
                for q in scene.configurations)
    return int(count), len(scene.configurations)


def _mm(value: float) -> str:
    return f"{value * 1000:.4g}"


_DRAKES_SHAPE_NAMES = {"mesh", "convex", "box", "sphere", "cylinder", "capsule", "ellipsoid"}


def shape_text(shape, link: str, name: str = "") -> str:
    """A collision shape as a refusal names it: ``link_4's collision mesh link_4.obj (its convex
    hull)``, ``base_link's box 1000 x 1000 x 100 mm``; ``name``, the geometry's own name, where
    the model gave one (not Drake's ``Box``, ``Mesh_1``, ...)."""
    stem, _, number = name.rpartition("_") if "_" in name else (name, "", "")
    generic = (stem if number.isdigit() else name).lower() in _DRAKES_SHAPE_NAMES
    own = "" if not name or generic else f" {name}"
    if isinstance(shape, (Mesh, Convex)):
        source = shape.source()
        file = Path(source.path()).name if source.is_path() else "(in memory)"
        return f"{link}'s collision{own} mesh {file} (its convex hull)"
    if isinstance(shape, Box):
        return f"{link}'s{own} box {_mm(shape.width())} x {_mm(shape.depth())} x {_mm(shape.height())} mm"
    if isinstance(shape, Sphere):
        return f"{link}'s{own} sphere of radius {_mm(shape.radius())} mm"
    if isinstance(shape, (Cylinder, Capsule)):
        return (f"{link}'s{own} {type(shape).__name__.lower()} of radius {_mm(shape.radius())} mm, "
                f"{_mm(shape.length())} mm long")
    if isinstance(shape, Ellipsoid):
        return f"{link}'s{own} ellipsoid of semi-axes {_mm(shape.a())}, {_mm(shape.b())}, {_mm(shape.c())} mm"
    return f"{link}'s{own} {type(shape).__name__}"


def touching_shapes(checker, contact) -> str:
    """``": A's shape and B's shape"`` (:func:`shape_text`) of ``contact`` (its ``bodies`` and the
    unscoped names of its ``geometries``) between two bodies of the arm's model instance in
    ``checker`` (duck-typed: its ``plant``, ``scene_graph`` and ``instance``); "" for others."""
    plant, inspector = checker.plant, checker.scene_graph.model_inspector()
    shapes = [shape_text(inspector.GetShape(geometry), link, name)
              for link, name in zip(contact.bodies, contact.geometries) if plant.HasBodyNamed(link, checker.instance)
              for geometry in plant.GetCollisionGeometriesForBody(plant.GetBodyByName(link, checker.instance))
              if inspector.GetName(geometry).split("::")[-1] == name]
    return f": {' and '.join(shapes)}" if len(shapes) == 2 else ""


def srdf_hint(checker, contact) -> str:
    """For a refused ``contact`` between two links of the arm (in contact, else closer than
    ``checker.clearance``) that are so in at least :data:`MOSTLY` of the detection's
    configurations, "; their share, and where to leave them out"; "" otherwise."""
    within = CONTACT_DISTANCE if contact.distance < 0 else max(checker.clearance, CONTACT_DISTANCE)
    links = tuple(contact.bodies)
    count, total = contact_share(checker.robot, *links, within)
    if not total or count < MOSTLY * total:
        return ""
    how = "in contact" if contact.distance < 0 else f"closer than {within * 1000:g} mm"
    return (f"; {links[0]} and {links[1]} are {how} in {count} of {total} poses sampled in the joint ranges, not in all "
            "(only a pair in contact in all is left out by itself): if their shapes overlap by design and the links "
            "cannot really collide, name the pair in the arm's MoveIt configuration (robot.srdf: <disable_collisions "
            f"link1=\"{links[0]}\" link2=\"{links[1]}\" reason=\"User\"/>)")
