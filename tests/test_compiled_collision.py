"""The compiled collision model (drake_traj.cell.compiled_model) against SceneGraph, its proof:
forward kinematics, distances that are never above SceneGraph's (conservative) and never far below
the true distance (tight: GJK's own witness points bound it from above), the configurations it
accepts, the pairs it lists, a shape it cannot check refused, and segments it accepts that keep
half the clearance under dense sampling.

SceneGraph's own distances are not exact: on cylinders, boxes and meshes (FCL's GJK) it reports
pairs up to tens of mm farther apart than they are (a 29.3 mm UR10e cylinder pair reported at 98.5
mm, checked by sampling both surfaces). Tightness is therefore measured against the true distance,
bounded from above by the model's witness (``pair_bounds``: the distance of two points of the two
shapes) and by SceneGraph where that is lower.
"""

import numpy as np
import pytest
from pydrake.geometry import Ellipsoid, HalfSpace, ProximityProperties
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.tree import BodyIndex
from pydrake.trajectories import PiecewisePolynomial
from scipy.spatial import cKDTree

from drake_traj import get_robot
from drake_traj.cell import Box, Cell, CellChecker, CollisionError, Cylinder, Sphere, Tool, UnsupportedShapeError
from drake_traj.cell.convex_distance import segment_distance
from drake_traj.data import data_directory
from drake_traj.planners.free import Scene
from drake_traj.robots.chain_arm import ChainArm

UR10E = get_robot("ur10e")

LOOK_AHEAD = 0.07  # [m] the free-motion search's look-ahead (the model's default)
CONSERVATIVE = 1e-6  # [m] the most a compiled distance may be above SceneGraph's
TIGHT = 1e-5  # [m] the most a compiled distance may be below the true one (GJK stops within 1e-6 m)
COUNT = 2500  # seeded configurations per cell


def _egg(plant, scene_graph):
    """An ellipsoid in the cell (no obstacle of a scenario is one: a station's own geometry)."""
    plant.RegisterCollisionGeometry(plant.world_body(), RigidTransform(RollPitchYaw(0.3, 0.2, 0.1), [0.4, 0.2, 0.5]),
                                    Ellipsoid(0.15, 0.08, 0.25), "egg", ProximityProperties())


def _ur5e_cell() -> CellChecker:
    """The UR5e with a tool of three shapes among boxes, cylinders, spheres and an ellipsoid on its table."""
    tool = Tool(tcp_xyz=[0, 0, 0.15], shapes=[Cylinder(radius=0.04, length=0.15, xyz=[0, 0, 0.075]),
                                             Box(size=[0.1, 0.04, 0.03], xyz=[0, 0, 0.16], rpy=[0, 0, 0.3]),
                                             Sphere(radius=0.03, xyz=[0.05, 0, 0.1])])
    obstacles = [Box(name="fixture", size=[0.3, 0.2, 0.25], xyz=[0.5, -0.3, 0.125], rpy=[0, 0, 0.4]),
                 Cylinder(name="post", radius=0.08, length=0.6, xyz=[-0.4, 0.4, 0.3]),
                 Sphere(name="ball", radius=0.1, xyz=[0.3, 0.4, 0.5]),
                 Box(name="panel", size=[0.05, 0.6, 0.4], xyz=[-0.5, -0.3, 0.6], rpy=[0.3, 0.2, 0.1]),
                 Cylinder(name="pipe", radius=0.05, length=0.3, xyz=[0.2, 0.5, 0.2], rpy=[1.2, 0, 0.3])]
    return CellChecker(get_robot("ur5e"), Cell(obstacles=obstacles, tool=tool), before_finalize=_egg)


def _example_arm() -> CellChecker:
    """The example arm description (every shape a mesh, checked as its convex hull)."""
    description = data_directory("models") / "example_arm_description"
    arm = ChainArm.from_model_file(description / "urdf" / "example_arm.urdf", base_frame="base", tool_frame="tool0",
                                   name="example_arm", acceleration_limits=1.4)
    return CellChecker(arm)


def _two_boxes() -> Cell:
    """A table with two turned boxes."""
    return Cell(obstacles=[Box(name="block", size=[0.2, 0.2, 0.3], xyz=[0.45, -0.3, 0.15], rpy=[0, 0, 0.4]),
                           Box(name="shelf", size=[0.1, 0.5, 0.2], xyz=[-0.4, 0.2, 0.5], rpy=[0.2, 0.1, 0.5])])


def _boryga_cell() -> CellChecker:
    """Boryga's anthropomorphic robot among two boxes."""
    return CellChecker(get_robot("anthropomorphic"), _two_boxes())


def _li_cell() -> CellChecker:
    """The 4-DOF robot of Li et al. 2019 (boxes and cylinders) among the same two boxes."""
    return CellChecker(get_robot("li_4dof"), _two_boxes())


CELLS = {"ur10e": lambda: CellChecker(get_robot("ur10e")), "ur5e_cell": _ur5e_cell, "example_arm": _example_arm,
         "boryga": _boryga_cell, "li": _li_cell}


@pytest.fixture(scope="module", params=sorted(CELLS))
def checker(request) -> CellChecker:
    return CELLS[request.param]()


def _configurations(checker, count: int, seed: int = 0) -> np.ndarray:
    robot = checker.robot
    return np.random.default_rng(seed).uniform(robot.lower_limits, robot.upper_limits, (count, len(robot.lower_limits)))


def _scene_graph(checker, q) -> list:
    """SceneGraph's pairs within the look-ahead at q."""
    return checker.pose_query(q).ComputeSignedDistancePairwiseClosestPoints(LOOK_AHEAD)


def test_forward_kinematics_is_drakes(checker):
    model = checker.compiled_model()
    assert checker.compiled_model() is model  # built once and kept
    context = checker.plant.CreateDefaultContext()
    for q in _configurations(checker, 50, seed=1):
        checker.plant.SetPositions(context, checker.instance, q)
        poses = model.body_poses(q)
        for body, pose in zip(model.bodies, poses):
            expected = checker.plant.EvalBodyPoseInWorld(context, checker.plant.get_body(BodyIndex(body)))
            np.testing.assert_allclose(pose, expected.GetAsMatrix4(), rtol=0, atol=1e-12)


def test_distances_are_conservative_and_tight(checker):
    model = checker.compiled_model()
    inspector = checker.scene_graph.model_inspector()
    rows = {geometry: k for k, geometry in enumerate(model.geometries)}
    pair_of = {}
    for p, (a, b, _, _) in enumerate(model.pairs):
        pair_of[a, b] = pair_of[b, a] = p
    configurations = _configurations(checker, COUNT)
    nearest = model.distances(configurations)
    worst = {}  # pair type: (most above SceneGraph, most below SceneGraph, most below the truth) [m]
    for q, least in zip(configurations, nearest):
        bounds = model.pair_bounds(q)  # (lower, upper): upper the distance of two points of the shapes
        truth_above = np.minimum(bounds[:, 1], LOOK_AHEAD)
        pairs = _scene_graph(checker, q)
        for pair in pairs:
            p = pair_of[rows[pair.id_A], rows[pair.id_B]]
            scene_graph = max(pair.distance, 0.0)
            truth_above[p] = min(truth_above[p], scene_graph)
            kind = tuple(sorted(type(inspector.GetShape(g)).__name__ for g in (pair.id_A, pair.id_B)))
            above, below, short = worst.get(kind, (-np.inf, -np.inf, -np.inf))
            worst[kind] = (max(above, bounds[p, 0] - scene_graph), max(below, scene_graph - bounds[p, 0]),
                           max(short, min(scene_graph, bounds[p, 1]) - bounds[p, 0]))
        scene_graph_least = min((max(pair.distance, 0.0) for pair in pairs), default=LOOK_AHEAD)
        assert least <= scene_graph_least + CONSERVATIVE
        assert least >= min(truth_above.min(), LOOK_AHEAD) - TIGHT  # the nearest pair, whichever it is
        assert least == pytest.approx(min(bounds[:, 0].min(), LOOK_AHEAD), abs=TIGHT)
    for kind, (above, below, short) in sorted(worst.items()):
        print(f"{checker.robot.name} {kind}: {above * 1e3:+.6f} mm above SceneGraph at most, {below * 1e3:.4f} mm "
              f"below it, {short * 1e3:.6f} mm below the truth")
        assert above <= CONSERVATIVE, kind
        assert short <= TIGHT, kind


@pytest.mark.parametrize("name", ["ur10e", "ur5e_cell"])
def test_valid_is_the_checkers_test_away_from_the_clearance(name):
    checker = CELLS[name]()
    model = checker.compiled_model()
    configurations = _configurations(checker, COUNT, seed=2)
    configurations[:10, 0] = checker.robot.upper_limits[0] + 0.1  # out of range
    configurations[10, 1] = np.nan
    accepted = model.valid(configurations)
    c = checker.clearance
    assert not accepted[:11].any()
    for q, ours in zip(configurations[11:], accepted[11:]):
        bounds = model.pair_bounds(q)
        scene_graph = min((pair.distance for pair in _scene_graph(checker, q)), default=LOOK_AHEAD)
        truth_above = min(scene_graph, bounds[:, 1].min())  # SceneGraph may say farther than two points are
        if ours:
            assert scene_graph >= c - CONSERVATIVE  # never accepted where SceneGraph refuses
        elif scene_graph >= c + TIGHT:  # refused where SceneGraph accepts: within the tightness, or SceneGraph wrong
            assert truth_above < c + TIGHT, (q, scene_graph, bounds[:, 0].min())
    assert 0.1 < accepted.mean() < 0.9


def test_pair_distances_are_the_near_pairs_with_their_links():
    checker = _ur5e_cell()
    model = checker.compiled_model()
    _, links = checker.link_reach()
    for q in _configurations(checker, 300, seed=3):
        distances, link_a, link_b = model.pair_distances(q)
        assert np.all(distances < LOOK_AHEAD) and len(distances) == len(link_a) == len(link_b)
        listed = sorted(zip(np.round(distances, 7), link_a, link_b))
        for pair in _scene_graph(checker, q):
            if pair.distance > LOOK_AHEAD - TIGHT:
                continue
            expected = (links.get(pair.id_A, 0), links.get(pair.id_B, 0))
            matches = [d for d, a, b in listed if {a, b} == set(expected) and d <= max(pair.distance, 0.0) + CONSERVATIVE]
            assert matches, (q, pair.distance, expected)


def test_a_shape_it_cannot_check_is_refused_by_name():
    def ground(plant, scene_graph):
        plant.RegisterCollisionGeometry(plant.world_body(), RigidTransform([0, 0, -0.2]), HalfSpace(), "ground",
                                        ProximityProperties())

    checker = CellChecker(get_robot("ur5e"), before_finalize=ground)
    with pytest.raises(UnsupportedShapeError, match="'ground'.*HalfSpace") as refused:
        checker.compiled_model()
    assert refused.value.geometry == "ground" and refused.value.shape == "HalfSpace"


def test_segment_distance_is_the_least_distance_of_two_segments():
    # against the least over the square's four edges and its interior stationary point, enumerated
    rng = np.random.default_rng(5)
    for k in range(2000):
        a, u, b, v = rng.normal(size=(4, 3)) * np.array([[1.0], [0.5], [1.0], [0.5]])
        if k % 3 == 0:  # (nearly) parallel
            v = u * rng.uniform(-2, 2) + rng.normal(size=3) * 10.0 ** rng.uniform(-12, -3)
        if k % 7 == 0:
            u = np.zeros(3)  # a point
        r, candidates = a - b, []
        for s in (-1.0, 1.0):
            t = np.clip((u @ v * s + v @ r) / max(v @ v, 1e-300), -1, 1) if v @ v else 0.0
            candidates.append((s, t))
        for t in (-1.0, 1.0):
            candidates.append((np.clip((u @ v * t - u @ r) / max(u @ u, 1e-300), -1, 1) if u @ u else 0.0, t))
        system = np.array([[u @ u, -(u @ v)], [-(u @ v), v @ v]])
        if abs(np.linalg.det(system)) > 1e-14:
            s, t = np.linalg.solve(system, [-(u @ r), v @ r])
            if abs(s) <= 1 and abs(t) <= 1:
                candidates.append((s, t))
        least = min(np.linalg.norm(r + s * u - t * v) for s, t in candidates)
        assert segment_distance(*a, *u, *b, *v)[0] <= least + 1e-12


def _cartesian_cell() -> CellChecker:
    """Boryga's Cartesian robot (three prismatic joints) beside a box."""
    return CellChecker(get_robot("cartesian"), Cell(obstacles=[Box(name="crate", size=[0.3, 0.3, 0.3], xyz=[0.3, 0.3, 0.4])]))


@pytest.mark.parametrize("name", ["ur5e_cell", "cartesian"])
def test_accepted_segments_keep_half_the_clearance(name):
    # the Cartesian robot's travel is |Δq| per prismatic joint (link_reach had read it as a turn: the
    # search's Scene accepted segments there that come closer than c/2); both the compiled segment
    # check and the SceneGraph one of the search's Scene
    checker = _ur5e_cell() if name == "ur5e_cell" else _cartesian_cell()
    model = checker.compiled_model()
    reference = Scene(checker, checker.robot.lower_limits, checker.robot.upper_limits, collision_check="scenegraph")
    robot = checker.robot
    rng = np.random.default_rng(4)
    c = checker.clearance
    accepted = tried = 0
    needed = 12 if name == "ur5e_cell" else 150  # SceneGraph is cheap on the Cartesian robot's four boxes
    while accepted < needed and tried < 20 * needed:
        tried += 1
        a = rng.uniform(robot.lower_limits, robot.upper_limits)
        b = np.clip(a + rng.normal(0.0, 0.25 if name == "ur5e_cell" else 1.0, len(a)) * (robot.upper_limits
                                                                                    - robot.lower_limits) / 4,
                    robot.lower_limits, robot.upper_limits)
        if not (model.valid(a) and (model.segment_valid(a, b) if accepted % 2 else reference.segment_valid(a, b))):
            continue
        accepted += 1
        travel = 1.1 * np.abs(b - a) @ checker.reach  # [m] any point's travel bound over the segment
        samples = np.linspace(0.0, 1.0, int(np.ceil(travel / (0.1 * c))) + 2)
        for u in samples:  # no sample closer than c/2 (the bound guarantees it at every point)
            pairs = checker.pose_query(a + u * (b - a)).ComputeSignedDistancePairwiseClosestPoints(0.5 * c)
            assert not [pair.distance for pair in pairs if pair.distance < 0.5 * c], (a, b, u)
    assert accepted == needed


def _cylinder_surface(query, geometry, spacing: float = 5e-4) -> np.ndarray:
    """Points on a cylinder geometry's surface (side and both caps) about ``spacing`` [m] apart, in the world."""
    shape = query.inspector().GetShape(geometry)
    r, h = shape.radius(), shape.length() / 2
    angles = np.linspace(0.0, 2 * np.pi, int(2 * np.pi * r / spacing), endpoint=False)
    heights = np.linspace(-h, h, int(2 * h / spacing) + 1)
    side = [(r * np.cos(a), r * np.sin(a), z) for a in angles for z in heights]
    caps = [(rho * np.cos(a), rho * np.sin(a), z) for z in (-h, h) for rho in np.linspace(0.0, r, int(r / spacing) + 1)
            for a in angles]
    X = query.GetPoseInWorld(geometry)
    return (X.rotation().matrix() @ np.array(side + caps).T).T + X.translation()


def test_the_cell_check_takes_the_smaller_of_scenegraph_and_the_certified_distance():
    """SceneGraph's signed distance between two of the UR10e's cylinders (the forearm's joint 4
    housing and the wrist 2 link's joint 6 housing) is 2.3 mm above the true one in this
    configuration: with a clearance between the two, the check refuses what SceneGraph alone let through."""
    q = np.array([0.38625543, -2.28754037, -1.34318407, 2.33710291, 0.47260968, -1.52009363])
    probe = CellChecker(UR10E)
    query = probe.pose_query(q)
    inspector = query.inspector()
    (reported,) = [pair for pair in query.ComputeSignedDistancePairwiseClosestPoints(0.1)
                   if {inspector.GetName(pair.id_A), inspector.GetName(pair.id_B)}
                   == {"ur10e::joint4_housing", "ur10e::joint6_housing"}]
    # an upper bound of the true distance, independently: two points of the two surfaces
    tree = cKDTree(_cylinder_surface(query, reported.id_B))
    # only pairs closer than SceneGraph's distance matter (the others come back as inf): the same
    # minimum, in 0.1 s instead of 13 s of nearest neighbours of far-apart points
    witness = float(tree.query(_cylinder_surface(query, reported.id_A), distance_upper_bound=reported.distance)[0].min())
    nearest = min(pair.distance for pair in query.ComputeSignedDistancePairwiseClosestPoints(0.1))
    assert nearest == reported.distance and reported.distance - witness > 2e-3  # SceneGraph: 2 mm further
    clearance = 0.5 * (reported.distance + witness)
    checker = CellChecker(UR10E, cell=Cell(clearance=clearance))
    assert not checker.contacts(q)  # SceneGraph alone would let it through
    with pytest.raises(CollisionError, match="forearm_link") as refused:
        checker.check_configuration(q)
    assert refused.value.distance <= witness
    with pytest.raises(CollisionError, match="wrist_2_link"):
        checker.check(PiecewisePolynomial.ZeroOrderHold([0.0, 1.0], np.column_stack([q, q])))
