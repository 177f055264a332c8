"""models/ur10e.urdf's collision geometry: it bounds the real UR10e and checks self-collision.

docs/ur10e.md, "Collision geometry", lists the shapes, the real dimension each one bounds, its source
and its margin. Here:

- every collision shape, read from the file with xml.etree, contains that dimension (the constants
  below are the documented ones), and its visual twin is the same shape;
- Drake's SceneGraph reports every pair of non-adjacent links (self-collision is on; only bodies
  joined by a joint are filtered) and no such pair touches at every configuration;
- the start configurations and the whole planned motions of the shipped UR10e scenarios are free of
  self-contact and stay above a table top flush with the base (z = 0);
- folding the arm onto itself is a collision between the expected bodies, with a penetration depth
  computed independently with numpy from the DH frames.

Units: m, rad. Frames: the base frame (UR's DH frame 0, z up, welded to the world).
"""

import itertools
import xml.etree.ElementTree as ET
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from pydrake.geometry import Box, CollisionFilterDeclaration, GeometrySet, ProximityProperties, Role
from pydrake.math import RigidTransform
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from drake_traj import FreeMotionConfig, load_scenario, simulate
from drake_traj.robots import UR10E
from drake_traj.robots.ur10e import DH_A, DH_D, dh_frames
from drake_traj.scenario import shipped_scenarios

MODEL_FILE = Path(__file__).resolve().parents[2] / "models" / "ur10e.urdf"
BODIES = ("base", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link", "wrist_3_link")
ADJACENT = {frozenset(pair) for pair in zip(BODIES, BODIES[1:])}  # joined by a joint: Drake filters these
TABLE = "table_top"  # our test box, top face at z = 0 (a table flush with the base)

# The real dimension each collision shape bounds (docs/ur10e.md, "Collision geometry"): outer radius
# [m] and the margin we require on it. The base radius is UR's published footprint (Ø190 mm, UR10e
# data sheet), so no margin; the other radii are estimated outer radii of the real parts, so 5 mm.
BOUNDED_RADIUS = {
    "base_foot": (0.095, 0.0),
    "joint1_housing": (0.076, 0.005),
    "joint2_housing": (0.077, 0.005),
    "upper_arm_tube": (0.075, 0.005),  # the tube tapers from 0.075 to 0.060
    "joint3_housing": (0.077, 0.005),
    "forearm_tube": (0.058, 0.005),  # the tube tapers from 0.058 to 0.043
    "joint4_housing": (0.047, 0.005),
    "joint5_housing": (0.047, 0.005),
    "joint6_housing": (0.045, 0.005),
    "flange": (0.045, 0.005),
}
WRIST_MODULE_LENGTH = 0.12  # joint-4 and joint-5 housings, estimated length of the real modules [m]
FLANGE_LENGTH = 0.05  # wrist 3 and tool flange, estimated [m]
ISO_9409_50_BOLT_CIRCLE = 0.050  # tool flange ISO 9409-1-50-4-M6 (UR10e data sheet): pitch circle Ø50 mm
UPPER_ARM_PLANE = 0.176  # upper-arm tube's plane along the joint-2 axis (UR's ROS 2 description) [m]
FOREARM_PLANE = 0.176 - 0.137  # forearm tube's plane (the elbow is 0.137 m back along the axis) [m]

# Measured with this model (see docs/ur10e.md): the joint-5 housing and the flange keep a constant
# 14.55 mm gap (the closest pair of the arm at any configuration), so start configurations and the
# shipped motions can be no closer than that; the table top is 98.7 mm under the joint-2 housing.
MIN_SELF_DISTANCE = 0.0145
MIN_TABLE_DISTANCE = 0.098


# --- the file ------------------------------------------------------------------------------------


def rotation_rpy(rpy):
    """URDF rpy: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    return rz @ ry @ rx


def read_shapes(role):
    """{name: shape} of the file's <collision> or <visual> elements: link, kind ("cylinder" or
    "capsule"), radius, length (a capsule's: its cylindrical part), pose in the link frame (4x4)
    and axis end points in the link frame (the shape's z axis, ± length / 2)."""
    shapes = {}
    for link in ET.parse(MODEL_FILE).getroot().iter("link"):
        for element in link.iter(role):
            origin = element.find("origin")
            pose = np.eye(4)
            pose[:3, :3] = rotation_rpy([float(v) for v in origin.get("rpy").split()])
            pose[:3, 3] = [float(v) for v in origin.get("xyz").split()]
            (geometry,) = list(element.find("geometry"))
            kind = geometry.tag.split("}")[-1].replace("drake:", "")
            radius, length = float(geometry.get("radius")), float(geometry.get("length"))
            ends = [pose[:3, 3] + s * 0.5 * length * pose[:3, 2] for s in (-1.0, 1.0)]
            shapes[element.get("name")] = SimpleNamespace(
                link=link.get("name"), kind=kind, radius=radius, length=length, pose=pose, ends=ends)
    return shapes


COLLISION = read_shapes("collision")


def test_every_shape_contains_the_dimension_it_bounds():
    assert set(COLLISION) == set(BOUNDED_RADIUS)
    for name, (radius, margin) in BOUNDED_RADIUS.items():
        assert COLLISION[name].radius >= radius + margin - 1e-12, name
    tubes = {name for name, shape in COLLISION.items() if shape.kind == "capsule"}
    assert tubes == {"upper_arm_tube", "forearm_tube"}
    # The tubes run joint to joint: |a2| and |a3| of UR's DH table, in their planes.
    upper, fore = COLLISION["upper_arm_tube"], COLLISION["forearm_tube"]
    np.testing.assert_allclose(sorted(e[0] for e in upper.ends), [DH_A[1], 0.0], atol=1e-12)
    np.testing.assert_allclose([e[2] for e in upper.ends], [UPPER_ARM_PLANE] * 2, atol=1e-12)
    np.testing.assert_allclose(sorted(e[0] for e in fore.ends), [DH_A[2], 0.0], atol=1e-12)
    np.testing.assert_allclose([e[2] for e in fore.ends], [FOREARM_PLANE] * 2, atol=1e-12)
    # The joint-2 and elbow housings reach past the upper-arm tube's outer side (plane + 0.075) and,
    # the elbow's, under the forearm tube (plane - 0.058), by the margin.
    assert min(e[1] for e in COLLISION["joint2_housing"].ends) <= -(UPPER_ARM_PLANE + 0.075 + 0.005)
    elbow_z = sorted(e[2] for e in COLLISION["joint3_housing"].ends)
    assert elbow_z[0] <= FOREARM_PLANE - 0.058 - 0.005 and elbow_z[1] >= UPPER_ARM_PLANE + 0.075 + 0.005
    # Wrist modules: at least their length plus 5 mm at each end.
    for name in ("joint4_housing", "joint5_housing"):
        assert COLLISION[name].length >= WRIST_MODULE_LENGTH + 0.010 - 1e-12, name
    # Wrist 3 and the flange: the ISO 9409-1-50 bolt circle inside, the face exactly at tool0 (d6).
    flange = COLLISION["flange"]
    assert flange.radius > ISO_9409_50_BOLT_CIRCLE / 2
    assert flange.length >= FLANGE_LENGTH
    assert max(e[2] for e in flange.ends) == pytest.approx(DH_D[5], abs=1e-12)


def test_visuals_equal_the_collision_shapes():
    visual = read_shapes("visual")
    assert set(visual) == set(COLLISION)
    for name, shape in COLLISION.items():
        twin = visual[name]
        assert (twin.link, twin.kind, twin.radius, twin.length) == (shape.link, shape.kind, shape.radius, shape.length)
        np.testing.assert_allclose(twin.pose, shape.pose, atol=1e-15)


def test_nothing_of_base_and_shoulder_below_the_mounting_surface():
    # Both links' shapes turn only about the vertical joint-1 axis, so their lowest points are fixed:
    # the base foot stands on z = 0, the joint-2 housing's underside is d1 - r = 0.1807 - 0.082.
    lowest = {}
    for name, shape in COLLISION.items():
        if shape.link in ("base", "shoulder_link"):
            axis = shape.pose[:3, 2]
            lowest[name] = min(e[2] for e in shape.ends) - shape.radius * np.sqrt(1.0 - axis[2] ** 2)
    assert lowest == pytest.approx({"base_foot": 0.0, "joint1_housing": 0.1, "joint2_housing": DH_D[0] - 0.082})


# --- Drake's view ----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def arm():
    return build_arm()


def build_arm():
    """The UR10e as add_station builds it (UR10E.add_to_plant, base welded), plus a table-top box on
    the world body whose top face is z = 0. Continuous plant (time_step 0), finalized."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    instance = UR10E.add_to_plant(plant)
    plant.RegisterCollisionGeometry(plant.world_body(), RigidTransform([0.0, 0.0, -0.5]), Box(4.0, 4.0, 1.0),
                                    TABLE, ProximityProperties())
    plant.Finalize()
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    return SimpleNamespace(plant=plant, scene_graph=scene_graph, instance=instance, context=context,
                           plant_context=plant.GetMyContextFromRoot(context),
                           scene_context=scene_graph.GetMyContextFromRoot(context))


CONSTANT_GAP = frozenset(("wrist_1_link", "wrist_3_link"))  # filtered in the URDF: a constant 14.55 mm


def arm_without_the_wrist_filter():
    """:func:`arm` with the URDF's one filter, wrist 1 against wrist 3, lifted."""
    unfiltered = build_arm()
    geometries = [GeometrySet(unfiltered.plant.GetCollisionGeometriesForBody(unfiltered.plant.GetBodyByName(name)))
                  for name in sorted(CONSTANT_GAP)]
    unfiltered.scene_graph.collision_filter_manager(unfiltered.scene_context).Apply(
        CollisionFilterDeclaration().AllowBetween(*geometries))
    return unfiltered


def distances(arm, q, max_distance=np.inf):
    """Every unfiltered geometry pair at q, closest first: (distance [m], body A, body B, geometry A,
    geometry B), each pair in the order of BODIES (the table's body is "world")."""
    arm.plant.SetPositions(arm.plant_context, arm.instance, np.asarray(q, dtype=float))
    query = arm.scene_graph.get_query_output_port().Eval(arm.scene_context)
    inspector = arm.scene_graph.model_inspector()
    order = {name: k for k, name in enumerate(("world",) + BODIES)}
    pairs = []
    for pair in query.ComputeSignedDistancePairwiseClosestPoints(max_distance):
        ends = []
        for geometry_id in (pair.id_A, pair.id_B):
            body = arm.plant.GetBodyFromFrameId(inspector.GetFrameId(geometry_id)).name()
            ends.append((body, inspector.GetName(geometry_id).split("::")[-1]))
        ends.sort(key=lambda end: order[end[0]])
        pairs.append((pair.distance, ends[0][0], ends[1][0], ends[0][1], ends[1][1]))
    return sorted(pairs)


def self_pairs(pairs):
    return [p for p in pairs if p[1] != "world"]


def table_pairs(pairs):
    return [p for p in pairs if p[1] == "world"]


def test_self_collision_is_on_between_every_pair_of_non_adjacent_links(arm):
    reported = {frozenset(p[1:3]) for p in self_pairs(distances(arm, UR10E.home_configuration))}
    expected = {frozenset(pair) for pair in itertools.combinations(BODIES, 2)} - ADJACENT - {CONSTANT_GAP}
    assert len(expected) == 14
    assert reported == expected
    # Only the arm's links see the table: the base is welded to the world, so Drake filters it.
    seen = {p[2] for p in table_pairs(distances(arm, UR10E.home_configuration))}
    assert seen == set(BODIES[1:])


def test_no_pair_of_non_adjacent_shapes_overlaps_at_every_configuration(arm):
    # Why the URDF filters no pair for overlapping: each geometry pair Drake checks is apart at some
    # configuration (300 random ones cover all).
    rng = np.random.default_rng(21)
    apart, seen = set(), set()
    for _ in range(300):
        for distance, _, _, a, b in self_pairs(distances(arm, rng.uniform(-np.pi, np.pi, 6))):
            seen.add((a, b))
            if distance > 0.0:
                apart.add((a, b))
    assert len(seen) == 27
    assert apart == seen


def test_the_wrist_2_housing_and_the_flange_keep_a_constant_gap(arm):
    # ... which is why the URDF filters the pair (wrist_1_link, wrist_3_link): lifted here
    unfiltered = arm_without_the_wrist_filter()
    # The flange starts (along the joint-6 axis) at s0 = 0.06655 from the joint-5 axis, which it
    # crosses; the joint-5 housing is a cylinder of radius r5 about that axis, and both turn about
    # their own axes only. So the gap is s0 - r5 at every configuration (independent of q5, q6).
    flange, housing = COLLISION["flange"], COLLISION["joint5_housing"]
    gap = min(e[2] for e in flange.ends) - housing.radius
    assert gap == pytest.approx(0.01455, abs=1e-12)
    rng = np.random.default_rng(5)
    reported = []
    for q in rng.uniform(-2 * np.pi, 2 * np.pi, (50, 6)):
        (pair,) = [p for p in distances(unfiltered, q) if p[3:] == ("joint5_housing", "flange")]
        assert not [p for p in distances(arm, q) if p[3:] == ("joint5_housing", "flange")]
        reported.append(pair[0])
    # Drake's distance between these two cylinders (a flat face against a curved side) comes from an
    # iterative convex solver: measured 0 to +0.55 mm above the exact gap, never below it.
    assert gap - 1e-6 < min(reported) < gap + 1e-4
    assert max(reported) < gap + 1e-3


def start_configurations():
    """{name: q} of the home configuration and the start of every shipped UR10e scenario [rad] but
    the free-motion one (see UR10E_SCENARIOS)."""
    starts = {"home": UR10E.home_configuration}
    for entry in shipped_scenarios():
        scenario = load_scenario(entry.path, entry.variant)
        if scenario.robot == "ur10e" and not isinstance(scenario.planner, FreeMotionConfig):
            starts[entry.name] = np.asarray(scenario.q_initial) if scenario.q_initial else UR10E.home_configuration
    return starts


def test_start_configurations_have_no_self_contact(arm):
    starts = start_configurations()
    assert len(starts) == 10  # home + boryga_loop_ur10e, fixture_cell, li_closed_path_ur10e, pajak_sim1..3,
    # pajak_retimed, quintic_ptp, smooth_waypoints
    for name, q in starts.items():
        pairs = distances(arm, q)
        closest = self_pairs(pairs)[0]
        # Measured: 14.55 mm, joint-5 housing to flange, at every start.
        assert closest[0] > MIN_SELF_DISTANCE, (name, closest)
        assert table_pairs(pairs)[0][0] > MIN_TABLE_DISTANCE, (name, table_pairs(pairs)[0])


# The papers' and the baselines' shipped UR10e motions. The free-motion scenario's start and motion
# are placed in a tight cell by the planner, which promises the cell's clearance (10 mm), not these
# tasks' margins: tests/planners/test_free_motion.py checks it at every millisecond.
UR10E_SCENARIOS = [entry for entry in shipped_scenarios()
                   if (scenario := load_scenario(entry.path, entry.variant)).robot == "ur10e"
                   and not isinstance(scenario.planner, FreeMotionConfig)]


@pytest.mark.parametrize("entry", UR10E_SCENARIOS, ids=[entry.name for entry in UR10E_SCENARIOS])
def test_shipped_motions_are_self_collision_free_and_above_the_table(arm, entry):
    result = simulate(load_scenario(entry.path, entry.variant))
    assert result.succeeded
    samples = result.q_ref[::10]  # every 10th 1 ms sample of the planner's reference
    closest_self, closest_table, closest_moving = [], [], []
    for q in samples:
        pairs = distances(arm, q)
        closest_self.append(self_pairs(pairs)[0])
        table = table_pairs(pairs)
        closest_table.append(table[0])
        # The shoulder's shapes only turn about the vertical axis: their height is fixed.
        closest_moving.append(next(p for p in table if p[2] != "shoulder_link"))
    self_min, table_min, moving_min = min(closest_self), min(closest_table), min(closest_moving)
    # Measured on every shipped UR10e scenario: 14.55 mm (joint-5 housing to flange, constant), the
    # joint-2 housing 98.7 mm above the table, the upper-arm tube at least 100.7 mm (at the start).
    assert self_min[0] > MIN_SELF_DISTANCE, self_min
    assert table_min[0] > MIN_TABLE_DISTANCE, table_min
    assert moving_min[0] > 0.1, moving_min
    # Pairs whose distance depends on the configuration come no closer than 28 mm (measured: 28.4 mm
    # in quintic_ptp, forearm's joint-4 housing to wrist 2's joint-6 housing; 30.9 mm elsewhere).
    varying = [min((p for p in self_pairs(distances(arm, q)) if p[3:] != ("joint5_housing", "flange")))
               for q in samples]
    assert min(varying)[0] > 0.028, min(varying)


# --- folding the arm onto itself ------------------------------------------------------------------


def test_folded_elbow_drives_the_wrist_into_the_upper_arm(arm):
    q = np.array(UR10E.home_configuration, dtype=float)
    q[2], q[3] = np.radians(165.0), 0.0  # elbow folded to 165°, wrist 1 at 0
    contacts = [p for p in self_pairs(distances(arm, q)) if p[0] < 0.0]
    assert {frozenset(p[1:3]) for p in contacts} == {
        frozenset(pair) for pair in [
            ("shoulder_link", "forearm_link"), ("shoulder_link", "wrist_1_link"), ("shoulder_link", "wrist_2_link"),
            ("shoulder_link", "wrist_3_link"), ("upper_arm_link", "wrist_1_link"),
            ("upper_arm_link", "wrist_2_link"), ("upper_arm_link", "wrist_3_link")]}
    deepest = contacts[0]
    assert deepest[1:] == ("upper_arm_link", "wrist_2_link", "upper_arm_tube", "joint6_housing")
    assert deepest[0] == pytest.approx(-0.1095, abs=5e-4)  # measured: the wrist-3 housing inside the tube


def link_pose(q, link):
    """Pose of a URDF link frame in the base frame: link i is DH frame i-1 turned by q_i about z."""
    i = BODIES.index(link)
    turn = np.eye(4)
    turn[:2, :2] = [[np.cos(q[i - 1]), -np.sin(q[i - 1])], [np.sin(q[i - 1]), np.cos(q[i - 1])]]
    return dh_frames(q)[i - 1] @ turn


def test_forearm_folded_down_through_the_shoulder_has_the_depth_of_two_parallel_axes(arm):
    # Upper arm straight up (q2 = -π/2), elbow at π: the forearm hangs straight down beside the
    # upper arm, through the joint-1 housing. Both axes are vertical, so the penetration is, with
    # d the axes' distance and the capsule's segment [s0, s1] and the housing [z0, z1] along z,
    # r_capsule + min(r_housing - d, z1 - s0, s1 - z0) (the overlap of a rounded cylinder).
    q = np.array([0.3, -np.pi / 2, np.pi, 0.4, 0.5, 0.6])
    housing, tube = COLLISION["joint1_housing"], COLLISION["forearm_tube"]
    h_ends = [(link_pose(q, "shoulder_link") @ np.append(e, 1.0))[:3] for e in housing.ends]
    t_ends = [(link_pose(q, "forearm_link") @ np.append(e, 1.0))[:3] for e in tube.ends]
    h_axis, t_axis = np.subtract(*h_ends), np.subtract(*t_ends)
    assert np.linalg.norm(np.cross(h_axis, t_axis)) < 1e-12 and abs(h_axis[2]) == pytest.approx(housing.length)
    d = np.linalg.norm(t_ends[0][:2] - h_ends[0][:2])
    assert d == pytest.approx(FOREARM_PLANE, abs=1e-12)  # the forearm's plane, 0.039 m off the z axis
    (z0, z1), (s0, s1) = sorted(e[2] for e in h_ends), sorted(e[2] for e in t_ends)
    depth = tube.radius + min(housing.radius - d, z1 - s0, s1 - z0)
    assert depth == pytest.approx(0.063 + 0.081 - 0.039)  # the side, not the housing's top, is nearest
    (pair,) = [p for p in distances(arm, q) if p[3:] == ("joint1_housing", "forearm_tube")]
    assert pair[1:3] == ("shoulder_link", "forearm_link")
    assert pair[0] == pytest.approx(-depth, abs=1e-4)
