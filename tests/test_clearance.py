"""The check before the motion: joint ranges, self-collision and collision with the cell, on the
planned reference; and contact in the closed loop. Collision-free runs are confirmed by an
independent query (Drake's SceneGraphCollisionChecker) at every logged sample."""

import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from pydrake.geometry import Meshcat
from pydrake.planning import RobotDiagramBuilder, SceneGraphCollisionChecker
from pydrake.trajectories import PiecewisePolynomial

from drake_traj import load_scenario, make_planner, simulate
from drake_traj.cell import Box, Cell, CellChecker, CollisionError, JointRangeError, planner_target_word
from drake_traj.errors import Cause
from drake_traj.station import draw_refusal
from drake_traj.planners import QuinticConfig, make_planner as planner_from_config
from drake_traj.robots import UR10E
from drake_traj.scenario import check_in_cell, preflight, shipped_scenarios

from conftest import DIAGRAMS

HOME = UR10E.home_configuration


@pytest.fixture(scope="module")
def checker():
    return CellChecker(UR10E)


def independent_checker(cell: Cell):
    """Drake's own collision checker on the same robot and cell (padding 0): contact or not."""
    from drake_traj.cell import add_cell

    builder = RobotDiagramBuilder(time_step=0.0)
    instance = UR10E.add_to_plant(builder.plant())
    add_cell(builder.plant(), cell, instance)
    return SceneGraphCollisionChecker(model=builder.Build(), robot_model_instances=[instance], edge_step_size=0.01,
                                      env_collision_padding=0.0, self_collision_padding=0.0)


def quintic(goals, q0=HOME):
    return planner_from_config(QuinticConfig(goals=[list(goal) for goal in goals]), UR10E, np.asarray(q0))


def test_the_reach_bounds_every_point_speed(checker):
    """Σ_j |q̇_j| R_j bounds the speed of every point of every collision shape (Drake's body
    velocities, the shapes' bounding spheres), over random states."""
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.systems.framework import DiagramBuilder

    from drake_traj.cell.shapes import shape_radius as _bounding_radius

    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    instance = UR10E.add_to_plant(plant)
    plant.Finalize()
    context = plant.CreateDefaultContext()
    inspector = scene_graph.model_inspector()
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(200):
        qd = rng.uniform(-1, 1, 6) * rng.uniform(0, 3)
        plant.SetPositions(context, instance, rng.uniform(-np.pi, np.pi, 6))
        plant.SetVelocities(context, instance, qd)
        bound = np.abs(qd) @ checker.reach
        for body_index in plant.GetBodyIndices(instance):
            body = plant.get_body(body_index)
            velocity = body.EvalSpatialVelocityInWorld(context)
            X_WB = body.EvalPoseInWorld(context)
            for geometry in plant.GetCollisionGeometriesForBody(body):
                X_BG = inspector.GetPoseInFrame(geometry)
                offset = X_WB.rotation() @ X_BG.translation()
                speed = np.linalg.norm(velocity.translational() + np.cross(velocity.rotational(), offset))
                speed += np.linalg.norm(velocity.rotational()) * _bounding_radius(inspector.GetShape(geometry))
                worst = max(worst, speed / bound)
    assert 0.3 < worst <= 1.0  # a bound, and not a loose one


def test_a_motion_through_the_table_is_refused_naming_the_time_the_bodies_and_the_waypoint(checker):
    # the shoulder lifts the arm down past the horizontal: the forearm and wrist go through the table
    planner = quintic([[-1.2, -1.6, -2.0, -0.9, 1.57, 0.8], [-1.2, 0.6, -0.3, -0.9, 1.57, 0.8]])
    with pytest.raises(CollisionError) as caught:
        checker.check_planner(planner)
    error = caught.value
    assert "table" in error.bodies and error.cause is Cause.COLLISION
    assert error.distance < checker.clearance
    assert error.segment.startswith("on the way to ") and error.segment.endswith(" 1")
    assert 0 < error.time < planner.plan().end_time()
    assert "table" in str(error)
    # the reported configuration is the plan's at that time, and really that close to the table
    assert np.allclose(error.configuration, planner.plan().value(error.time).ravel())
    contact = [c for c in checker.contacts(error.configuration) if "table" in c.bodies][0]
    assert contact.distance == pytest.approx(error.distance)


def test_a_motion_that_goes_through_the_table_says_so_how_deep_and_when_with_its_time_once(checker):
    planner = quintic([[-1.2, -1.6, -2.0, -0.9, 1.57, 0.8], [-1.2, 0.6, -0.3, -0.9, 1.57, 0.8]])
    with pytest.raises(CollisionError) as caught:
        checker.check_planner(planner)
    error, message = caught.value, str(caught.value)
    # the first sample under the clearance is a near miss; the motion then goes on into the table
    assert 0 <= error.distance < checker.clearance and error.time < error.depth_time and error.depth > 0.1
    arm_link = next(body for body in checker.contacts(planner.plan().value(error.depth_time).ravel(), 0.0)[0].bodies
                    if body != "table")
    assert message.startswith(f"the planned motion goes through table ({arm_link} {error.depth * 1000:.1f} mm deep at "
                              f"t = {error.depth_time:.3f} s), first closer than the clearance of 10 mm")
    assert "within" not in message
    # each time once: the depth's, then the error's (the first sample under the clearance)
    assert re.findall(r"t = ([0-9.]+) s", message) == [f"{error.depth_time:.3f}", f"{error.time:.4f}"]
    # the deepest sample of that stretch, really that deep
    contact = [c for c in checker.contacts(planner.plan().value(error.depth_time).ravel()) if "table" in c.bodies][0]
    assert -contact.distance == pytest.approx(error.depth)


def test_a_motion_through_the_arm_itself_is_refused(checker):
    # the elbow folds the forearm back onto the upper arm, high above the table
    planner = quintic([[-1.57, -1.57, 2.9, -1.57, 1.57, 0.0]], q0=[-1.57, -1.57, 0.0, -1.57, 1.57, 0.0])
    with pytest.raises(CollisionError) as caught:
        checker.check_planner(planner)
    error = caught.value
    assert "table" not in error.bodies
    links = {"base", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link", "wrist_3_link"}
    assert set(error.bodies) <= links
    # said as such, with the two links that go into each other
    hit = re.search(r"^in the planned motion the arm would hit itself \((\w+) and (\w+), ([0-9.]+) mm deep at t = ", str(error))
    assert hit and {hit[1], hit[2]} <= links and float(hit[3]) == pytest.approx(error.depth * 1000, abs=0.05)
    # and in a start configuration, with the two shapes (the UR10e's are cylinders and capsules); no
    # hint to leave the pair out (they touch in few poses)
    q = planner.plan().value(error.depth_time).ravel()
    shape = r"'s \w+ (cylinder|capsule) of radius [0-9.]+ mm, [0-9.]+ mm long"
    with pytest.raises(CollisionError, match=rf"^in the start configuration the arm would hit itself \({hit[1]} and "
                                             rf"{hit[2]}, [0-9.]+ mm deep: {hit[1]}{shape} and {hit[2]}{shape}\) \(at t = 0.0000 s"):
        checker.check_configuration(q)


def test_a_self_collision_with_the_tool_is_the_arm_hitting_itself():
    """The tool is part of the arm: its shape in a link is a self-collision, not an obstacle."""
    from drake_traj.cell import Cylinder, NoMounting, Tool

    tool = Tool(tcp_xyz=[0, 0, 0.3], shapes=[Cylinder(name="gripper", radius=0.04, length=0.3, xyz=[0, 0, 0.15])])
    tooled = CellChecker(UR10E, Cell(mounting=NoMounting(), tool=tool))
    q = [0.0, -1.57, -2.71, 1.88, 2.48, 0.0]  # the elbow folded: the gripper in the forearm
    contact = tooled.contacts(q)[0]
    assert contact.on_arm == (True, True) and set(contact.bodies) == {"tool", "forearm_link"}, contact
    with pytest.raises(CollisionError, match=r"^in the start configuration the arm would hit itself "
                                             r"\((tool and forearm_link|forearm_link and tool), [0-9.]+ mm deep: .*"
                                             r"tool's gripper cylinder of radius 40 mm, 300 mm long"):
        tooled.check_configuration(q)


def test_refusals_use_the_planners_word_for_its_targets(checker):
    from drake_traj.planners.baselines.movej import MovejPlanner
    from drake_traj.planners.baselines.ruckig import RuckigPlanner
    from drake_traj.planners.boryga.system import BorygaLoopPlanner
    from drake_traj.planners.li.system import LiPathPlanner
    from drake_traj.planners.pajak.system import PajakPlanner
    from drake_traj.planners.quintic.system import QuinticPtpPlanner
    from drake_traj.planners.smooth import SmoothPlanner

    words = {cls: planner_target_word(cls) for cls in (QuinticPtpPlanner, RuckigPlanner, MovejPlanner, SmoothPlanner,
                                                       LiPathPlanner, BorygaLoopPlanner, PajakPlanner)}
    assert words == {QuinticPtpPlanner: "goal", RuckigPlanner: "goal", MovejPlanner: "goal", SmoothPlanner: "goal",
                     LiPathPlanner: "point", BorygaLoopPlanner: "point", PajakPlanner: "waypoint"}
    planner = quintic([[-1.2, -1.6, -2.0, -0.9, 1.57, 0.8], [-1.2, 0.6, -0.3, -0.9, 1.57, 0.8]])
    with pytest.raises(CollisionError, match=r" on the way to goal 1 \(at t = ") as caught:
        checker.check(planner.plan(), waypoints=planner.task_waypoints(), target_word=planner_target_word(planner))
    assert caught.value.segment == "on the way to goal 1"


def test_a_reference_past_the_joint_range_is_refused(checker):
    times = [0.0, 2.0]
    q = np.column_stack([HOME, HOME + [0, 0, 0, 0, 0, 2 * np.pi]])  # wrist 3 from π/4 to π/4 + 2π > 2π
    with pytest.raises(JointRangeError, match=r"joint 6 \(wrist_3_joint\) to 6\.28") as caught:
        checker.check(PiecewisePolynomial.CubicShapePreserving(times, q, zero_end_point_derivatives=True))
    error = caught.value
    assert error.joint == 5 and error.limit == pytest.approx(2 * np.pi) and error.cause is Cause.JOINT_RANGE
    # the first sample past the range, on the 1 ms grid
    assert error.value > 2 * np.pi and error.value - 2 * np.pi < 0.01


def test_each_pair_of_links_moves_apart_no_faster_than_its_travel_bound():
    """T[a, b] Σ_j |q̇_j| (pair_travel, 1.1 margin) bounds how fast every point of link b's shapes
    moves relative to link a (Drake's body velocities, the shapes' bounding spheres), the tool's
    link included, over random states; and each T[a, b, j] is at most the dense bound 1.1 R_j."""
    from drake_traj.cell import Cylinder, NoMounting, Tool
    from drake_traj.cell.shapes import shape_radius

    tool = Tool(tcp_xyz=[0, 0, 0.2], shapes=[Cylinder(name="gripper", radius=0.04, length=0.2, xyz=[0, 0, 0.1])])
    tooled = CellChecker(UR10E.with_tcp([0, 0, 0.2], [0, 0, 0]), Cell(mounting=NoMounting(), tool=tool))
    travel, links = tooled.pair_travel()
    assert np.all(travel <= 1.1 * tooled.reach[None, None, :] + 1e-12)
    plant, inspector = tooled.plant, tooled.scene_graph.model_inspector()
    context = plant.CreateDefaultContext()
    by_link = {}
    for geometry, link in links.items():
        by_link.setdefault(link, []).append(geometry)
    rng = np.random.default_rng(11)
    worst = 0.0
    for _ in range(100):
        qd = rng.uniform(-1, 1, 6) * rng.uniform(0, 3)
        plant.SetPositions(context, tooled.instance, rng.uniform(-np.pi, np.pi, 6))
        plant.SetVelocities(context, tooled.instance, qd)
        for a in range(7):
            frame_a = plant.world_body() if a == 0 else plant.GetJointByName(
                UR10E.joint_names[a - 1], tooled.instance).child_body()
            X_WA, V_WA = frame_a.EvalPoseInWorld(context), frame_a.EvalSpatialVelocityInWorld(context)
            for b in range(a + 1, 7):
                bound = np.abs(qd) @ travel[a, b]
                for geometry in by_link.get(b, []):
                    body = plant.GetBodyFromFrameId(inspector.GetFrameId(geometry))
                    X_WB, V_WB = body.EvalPoseInWorld(context), body.EvalSpatialVelocityInWorld(context)
                    point = X_WB @ inspector.GetPoseInFrame(geometry).translation()
                    relative = (V_WB.translational() + np.cross(V_WB.rotational(), point - X_WB.translation())
                                - V_WA.translational() - np.cross(V_WA.rotational(), point - X_WA.translation()))
                    turning = np.linalg.norm(V_WB.rotational() - V_WA.rotational())
                    speed = np.linalg.norm(relative) + turning * shape_radius(inspector.GetShape(geometry))
                    worst = max(worst, speed / bound)
    assert 0.3 < worst <= 1.0 / 1.1 + 1e-9  # a bound, with its margin, and not a loose one


def test_the_advancement_follows_each_pairs_travel_to_its_allowance():
    """Advancement on a motion of joint 1 alone at 0.5 rad/s, against the closed form: a pair with
    rate r [m/rad] may go allowed / (0.5 r) s; the first pair to use its allowance sets the time;
    SceneGraph's distances (``measure``) that are nearer than the model's bounds shorten the step,
    and it is asked for the distance that covers the first step on the bound of any two bodies."""
    from drake_traj.cell.reach import Advancement

    grid = np.linspace(0.0, 2.0, 2001)
    q = np.zeros((len(grid), 6))
    q[:, 0] = 0.5 * grid
    reach = np.array([1.0, 0.8, 0.5, 0.2, 0.1, 0.1])
    travel = np.zeros((7, 7, 6))
    travel[0, 6, 0], travel[0, 3, 0] = 0.9, 0.4  # [m/rad] two pairs of links, the rest never move apart
    advancement = Advancement(grid, q, reach, travel)
    far, near, anything = advancement.row(0, 6), advancement.row(0, 3), advancement.ANY
    assert advancement.after(0.3, [far], [0.045]) == pytest.approx(0.3 + 0.045 / (0.5 * 0.9))
    assert advancement.after(0.3, [far, near], [0.045, 0.01]) == pytest.approx(0.3 + 0.01 / (0.5 * 0.4))
    assert advancement.after(1.9, [far], [1.0]) == 2.0  # the motion's end
    assert advancement.after(0.3, [advancement.row(1, 2)], [1e-3]) == 2.0  # a pair that never moves apart
    c, s, look_ahead = 0.01, 0.005, 0.07
    asked = []

    def measure(found):
        def scenegraph(within):
            asked.append(within)
            return found
        return scenegraph

    # the model's bound alone: 40 mm for (0, 6); the rest at most the look-ahead on any pair's bound (1.1 m/rad)
    least, after = advancement.step(0.3, [far], [0.04], measure(([], [])), c, s, look_ahead)
    first = min(0.3 + (0.04 - c + s) / (0.5 * 0.9), 0.3 + (look_ahead - c + s) / (0.5 * 1.1))
    assert after == pytest.approx(first) and asked[-1] == pytest.approx(0.5 * 1.1 * (first - 0.3) + c - s)
    assert least == pytest.approx(min(0.04, asked[-1]))
    # SceneGraph finds (0, 3) 15 mm apart: its own allowance sets the time
    least, after = advancement.step(0.3, [far], [0.04], measure(([near], [0.015])), c, s, look_ahead)
    assert least == 0.015 and after == pytest.approx(0.3 + (0.015 - c + s) / (0.5 * 0.4))
    # a pair closer than the clearance: no step
    assert advancement.step(0.3, [far], [0.04], measure(([near], [0.008])), c, s, look_ahead) == (0.008, 0.3)


def test_the_check_samples_far_apart_where_the_arm_is_far_from_everything(checker):
    """Conservative advancement: a motion in the open cell takes a few of the samples every
    ``spacing`` of the arm's travel, each pair the step its distance allows; and the clearance
    less the spacing holds at every millisecond, between the samples too."""
    planner = quintic([HOME + np.array([1.2, -0.4, 0.6, -0.8, 0.9, 1.5])])
    check = checker.check_planner(planner)
    plan = planner.plan()
    dense = checker.sample_times(plan)
    assert len(check.times) < len(dense) / 4 and check.times[0] == 0.0 and check.times[-1] == plan.end_time()
    assert np.all(check.distances >= checker.clearance) and check.spacing == 0.5 * checker.clearance
    every = np.arange(0.0, plan.end_time(), 1e-3)
    least = min(min((pair.distance for pair in checker.pose_query(q).ComputeSignedDistancePairwiseClosestPoints(
        checker.clearance)), default=checker.clearance) for q in plan.vector_values(every).T)
    assert least >= checker.clearance - check.spacing


def test_scenegraph_alone_advances_where_the_compiled_model_cannot_take_the_scene():
    """A half space below the table: no compiled model (UnsupportedShapeError), SceneGraph's own
    distances place the samples; the clearance less the spacing holds at every millisecond."""
    from pydrake.geometry import HalfSpace, ProximityProperties
    from pydrake.math import RigidTransform

    def ground(plant, scene_graph):
        plant.RegisterCollisionGeometry(plant.world_body(), RigidTransform([0, 0, -0.3]), HalfSpace(), "ground",
                                        ProximityProperties())

    grounded = CellChecker(UR10E, before_finalize=ground)
    planner = quintic([HOME + np.array([1.2, -0.4, 0.6, -0.8, 0.9, 1.5])])
    check = grounded.check(planner.plan())
    assert grounded.compiled_unavailable is not None and "HalfSpace" in grounded.compiled_unavailable
    plan = planner.plan()
    assert len(check.times) < len(grounded.sample_times(plan)) and np.all(check.distances >= grounded.clearance)
    least = min(min((pair.distance for pair in grounded.pose_query(q).ComputeSignedDistancePairwiseClosestPoints(
        grounded.clearance)), default=grounded.clearance) for q in plan.vector_values(np.arange(0.0, plan.end_time(),
                                                                                                1e-3)).T)
    assert least >= grounded.clearance - check.spacing


def test_the_samples_are_dense_enough_that_the_clearance_holds_between_them(checker):
    """Accepted motions keep half the clearance at every millisecond, not only at the samples."""
    rng = np.random.default_rng(3)
    accepted = 0
    for _ in range(6):
        goal = HOME + rng.uniform(-1.0, 1.0, 6)
        planner = quintic([goal])
        try:
            check = checker.check_planner(planner)
        except (CollisionError, JointRangeError):
            continue
        accepted += 1
        plan = planner.plan()
        dense = np.arange(0.0, plan.end_time(), 1e-3)
        assert len(check.times) < len(dense)
        assert not any(checker.contacts(q, within=0.5 * checker.clearance) for q in plan.vector_values(dense).T)
    assert accepted >= 2


def blocking_box_scenario(tmp_path):
    """quintic_ptp with a 10 cm box where its tool passes at t = 2 s."""
    scenario = load_scenario("quintic_ptp")
    plan = make_planner(scenario).plan()
    centre = UR10E.tool_position(plan.value(2.0).ravel())
    text = (scenario.source.path.read_text() + textwrap.dedent(f"""\
        cell:
          obstacles:
          - !Box {{name: fixture, size: [0.1, 0.1, 0.1], xyz: [{centre[0]:.4f}, {centre[1]:.4f}, {centre[2]:.4f}]}}
        """))
    path = tmp_path / "blocked.yaml"
    path.write_text(text)
    return path, text.splitlines().index("  obstacles:") + 2  # 1-based line of the box


def test_a_users_box_that_blocks_a_shipped_task_is_refused_at_its_line(tmp_path):
    path, line = blocking_box_scenario(tmp_path)
    scenario = load_scenario(path)
    with pytest.raises(CollisionError) as caught:
        preflight(scenario, make_planner(scenario))
    error = caught.value
    assert "fixture" in error.bodies and error.field == ("cell", "obstacles", 0)
    assert str(error).startswith(f"{path}, line {line}")
    assert len(re.findall(rf"t = {error.time:.3f}", str(error))) == 1  # the time once
    # the command line: exit 2, nothing simulated, the picture of the refused configuration
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "drake_traj.cli", "run", str(path), "--out", str(out)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr
    assert "fixture" in done.stderr and f"line {line}" in done.stderr and "refusal.png" in done.stderr
    assert len(re.findall(rf"t = {error.time:.3f}", done.stderr)) == 1
    assert (out / "refusal.png").stat().st_size > 10_000 and not (out / "result.npz").exists()


def test_in_the_closed_loop_touching_the_box_fails_the_run_as_a_collision(tmp_path):
    path, _ = blocking_box_scenario(tmp_path)
    result = simulate(load_scenario(path), preflight=False)
    assert result.failure is not None and result.failure.cause is Cause.COLLISION, result.failure
    assert "fixture" in result.failure.message and result.failure.time < 2.5
    assert not result.succeeded


@pytest.mark.parametrize("scale", [0.7, 1.0])
def test_random_walks_are_refused_or_run_collision_free(scale):
    """Seeded random joint walks (1-3 goals, steps up to ``scale`` rad per joint): each is refused
    with a collision or joint-range reason, or runs, and the run is then collision-free at
    every logged sample by Drake's SceneGraphCollisionChecker on the measured configuration."""
    rng = np.random.default_rng(int(scale * 10))
    independent = independent_checker(Cell())
    outcomes = {"refused": 0, "ran": 0}
    for _ in range(4):
        goals = HOME + np.cumsum(rng.uniform(-scale, scale, (rng.integers(1, 4), 6)), axis=0)
        planner = quintic(goals)
        try:
            result = simulate(planner, max_duration=40.0)
        except (CollisionError, JointRangeError) as error:
            assert error.cause in (Cause.COLLISION, Cause.JOINT_RANGE)
            outcomes["refused"] += 1
            continue
        assert result.succeeded, result.failure
        assert all(independent.CheckConfigCollisionFree(q) for q in result.q_meas)
        outcomes["ran"] += 1
    assert outcomes["ran"] >= 1, outcomes


@pytest.mark.parametrize("entry", shipped_scenarios(), ids=lambda entry: entry.name)
def test_every_shipped_task_is_possible_in_its_cell(entry):
    """Each shipped scenario's start and plan clear its cell (the default table, or the Li 4-DOF
    task's none) and the arm itself by the clearance: the checks change none of their numbers."""
    scenario = load_scenario(entry.path, entry.variant)
    check = check_in_cell(scenario, make_planner(scenario))
    assert len(check.times) >= 2 and check.spacing == pytest.approx(0.5 * scenario.cell.clearance)
    assert np.all(check.distances >= scenario.cell.clearance) and np.all(np.diff(check.times) > 0)


def test_meshcat_draws_the_refused_configuration_with_the_two_bodies(checker):
    planner = quintic([[-1.2, -1.6, -2.0, -0.9, 1.57, 0.8], [-1.2, 0.6, -0.3, -0.9, 1.57, 0.8]])
    with pytest.raises(CollisionError) as caught:
        checker.check_planner(planner)
    meshcat = Meshcat()
    draw_refusal(meshcat, checker, caught.value)
    arm_body = next(body for body in caught.value.bodies if body != "table")
    assert meshcat.HasPath(f"/drake_traj/refusal/{arm_body}") and meshcat.HasPath("/drake_traj/refusal/table/table")
    assert meshcat.HasPath("/drake_traj/refusal/closest_points")
    # every link is drawn, not only the two
    for link in ("base", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link",
                 "wrist_3_link"):
        assert meshcat.HasPath(f"/drake_traj/refusal/{link}"), link


def test_a_failure_from_a_planning_error_says_its_time_once():
    from drake_traj.errors import Failure, PlanningError

    failure = Failure.from_exception(PlanningError("the law stalled", time=1.25, configuration=HOME), 1.25)
    assert failure.message.count("t = 1.2500 s") == 1 and failure.message.startswith("PlanningError: the law stalled")
    other = Failure.from_exception(ValueError("singular"), 0.4)  # an error that gives no time: the run's
    assert other.message == "ValueError at t = 0.4000 s: singular"


def test_a_motion_too_long_to_sample_is_refused_before_it_is_sampled():
    """The samples are spaced by the arm's travel: 150 rad of joint 1 (about 1.5 m of reach) at a
    zero clearance (1 mm apart) needs over 200 000 of them; refused naming the travel and the
    clearance, at once."""
    import time

    from drake_traj.cell.clearance import MAX_SAMPLES
    from drake_traj.errors import DrakeTrajError

    checker = CellChecker(UR10E, Cell(clearance=0.0))
    end = HOME + np.array([150.0, 0, 0, 0, 0, 0])
    motion = PiecewisePolynomial.FirstOrderHold([0.0, 100.0], np.column_stack([HOME, end]))
    start = time.perf_counter()
    with pytest.raises(DrakeTrajError, match=rf"the motion is too long to check in the cell: its points travel up to "
                                             rf"[\d.]+ m .*cell.clearance = 0 mm .*more than the {MAX_SAMPLES} the check "
                                             r"takes") as caught:
        checker.sample_times(motion)
    assert time.perf_counter() - start < 2.0
    assert caught.value.field == ("cell", "clearance") and caught.value.cause is Cause.INFEASIBLE
    short = PiecewisePolynomial.FirstOrderHold([0.0, 1.0], np.column_stack([HOME, HOME + 0.05]))
    assert 2 < len(checker.sample_times(short)) < 1000


def test_a_motion_longer_than_a_run_is_refused_before_its_grid_is_made():
    from drake_traj.errors import DrakeTrajError

    motion = PiecewisePolynomial.FirstOrderHold([0.0, 1e9], np.column_stack([HOME, HOME + 0.5]))
    with pytest.raises(DrakeTrajError, match=r"the planned motion lasts 1e\+09 s, longer than the 600 s") as caught:
        CellChecker(UR10E).check(motion)
    assert caught.value.field == ("planner",)


def test_an_arm_of_absurd_reach_is_refused_in_an_instant(tmp_path):
    """A !DhArm with d1 = 1e6 m took 141 s in the cell check of a 0.05 rad move: refused at its
    length, in the scenario and from Python (ChainArm.from_dh)."""
    import time

    from drake_traj.errors import DrakeTrajError
    from drake_traj.robots.chain_arm import ChainArm

    puma = load_scenario(DIAGRAMS / "puma560.yaml", "quintic")
    table = [list(row) for row in puma.robot.dh]
    table[0][0] = 1e6
    with pytest.raises(ValueError, match=r"the links reach 1e\+06 m end to end .* above the 20 m a model may reach; the "
                                         r"longest is table\[0\]\[0\] = 1e\+06 m \(d\)") as caught:
        ChainArm.from_dh("huge", table, masses=puma.robot.masses, lower_limits=puma.robot.lower,
                         upper_limits=puma.robot.upper, velocity_limits=1.0, acceleration_limits=2.0,
                         effort_limits=100.0)
    assert caught.value.field == ("table", 0, 0)
    text = (DIAGRAMS / "puma560.yaml").read_text().replace("- [0.672, 0.0,", "- [1.0e6, 0.0,", 1)
    (tmp_path / "huge.yaml").write_text(text)
    start = time.perf_counter()
    with pytest.raises(DrakeTrajError, match=r"robot.dh: the links reach 1e\+06 m") as caught:
        load_scenario(tmp_path / "huge.yaml", "quintic")
    assert time.perf_counter() - start < 2.0
    assert caught.value.field == ("robot", "dh", 0, 0)
    assert str(caught.value).startswith(f"{tmp_path / 'huge.yaml'}, line 13")
