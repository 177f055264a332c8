"""The free-motion planner: goals reached on a path found through the cell (OMPL), shortened,
smoothed, timed, checked; its refusals; its reproducibility; its motion checked independently."""

import re
import sys

import numpy as np
import pytest
from pydrake.planning import RobotDiagramBuilder, SceneGraphCollisionChecker

from drake_traj import FreeMotionConfig, get_robot, load_scenario, make_station, run_station, simulate
from drake_traj.cell import Box, Cell, CellChecker, CollisionError, add_cell
from drake_traj.errors import Cause, DrakeTrajError, PlanningError
from drake_traj.planners import make_planner
from drake_traj.bench.free_scenes import generate
from drake_traj.planners.free import Scene, SearchResult, search
from drake_traj.planners.free import system as free_system
from drake_traj.scenario import make_planner as scenario_planner
from pydrake.systems.analysis import Simulator

UR10E = get_robot("ur10e")
SHELF = load_scenario("free_motion_shelf")


def shelf_checker() -> CellChecker:
    return SHELF.cell_checker()


def independent_checker(cell: Cell) -> SceneGraphCollisionChecker:
    """Drake's own collision checker of the UR10e in ``cell``: no padding, its own plant."""
    builder = RobotDiagramBuilder(0.0)
    instance = UR10E.add_to_plant(builder.plant())
    add_cell(builder.plant(), cell, instance)
    return SceneGraphCollisionChecker(model=builder.Build(), robot_model_instances=[instance], edge_step_size=0.01,
                                      env_collision_padding=0.0, self_collision_padding=0.0)


@pytest.fixture(scope="module")
def shelf_run():
    planner = scenario_planner(SHELF)
    result = simulate(SHELF)
    return planner, result


def test_the_shelf_task_goes_round_the_boards_and_its_straight_move_would_not(shelf_run):
    _, result = shelf_run
    checker = shelf_checker()
    scene = Scene(checker, UR10E.lower_limits, UR10E.upper_limits)
    assert result.succeeded, result.failure
    # the straight joint move between the same two configurations hits the shelf
    assert not scene.segment_valid(result.q_ref[0], result.q_ref[-1])
    goal = np.asarray(SHELF.planner.poses[0])
    assert np.linalg.norm(result.tcp[-1, :3] - goal[:3]) < 1e-4  # measured at the end: the pose's position
    assert 0.0 < result.metrics().planning_time_s < 30.0
    metrics = result.metrics()
    assert metrics.max_velocity_over_limit <= 1.0 + 1e-6 and metrics.max_acceleration_over_limit <= 1.0 + 1e-6


def test_the_planned_motion_is_collision_free_at_every_millisecond_by_an_independent_query():
    planner = scenario_planner(SHELF)
    shelf_checker().check_planner(planner)
    plan = planner.plan()
    independent = independent_checker(SHELF.cell)
    times = np.arange(plan.start_time(), plan.end_time(), 1e-3)
    q = plan.vector_values(times).T
    assert all(independent.CheckConfigCollisionFree(qk) for qk in q)
    # and our clearance holds at every millisecond up to the check's between-sample bound (half of it)
    nearest = min(shelf_checker().contacts(qk, within=0.02)[0].distance if shelf_checker().contacts(qk, within=0.02)
                  else 0.02 for qk in q[::20])
    assert nearest >= 0.5 * SHELF.cell.clearance


def test_the_measured_motion_touches_nothing(shelf_run):
    _, result = shelf_run
    independent = independent_checker(SHELF.cell)
    assert all(independent.CheckConfigCollisionFree(q) for q in result.q_meas)


def test_a_seed_reproduces_its_path_and_another_seed_may_not():
    def found(seed):
        planner = make_planner(FreeMotionConfig(poses=SHELF.planner.poses, seed=seed), UR10E, SHELF.q_initial)
        shelf_checker().check_planner(planner)
        return planner.legs[0].found

    first, again = found(3), found(3)
    np.testing.assert_array_equal(first, again)
    others = [found(seed) for seed in (4, 5, 6)]
    assert any(other.shape != first.shape or not np.array_equal(other, first) for other in others)


def test_the_search_alone_is_reproducible_in_one_process():
    checker = shelf_checker()
    scene = Scene(checker, UR10E.lower_limits, UR10E.upper_limits)
    goal = np.atleast_2d(UR10E.task_kinematics().inverse_kinematics_all(SHELF.planner.poses[0]))
    goal = next(q for q in goal if scene.valid(q) and not scene.segment_valid(SHELF.q_initial, q))
    first = search(scene, SHELF.q_initial, goal, planning_time=5.0, seed=11)
    other = search(scene, SHELF.q_initial, goal, planning_time=5.0, seed=12)  # OMPL seeded again in between
    again = search(scene, SHELF.q_initial, goal, planning_time=5.0, seed=11)
    assert first.vertices is not None and first.runs >= 1
    np.testing.assert_array_equal(first.vertices, again.vertices)
    assert other.vertices.shape != first.vertices.shape or not np.array_equal(other.vertices, first.vertices)


def test_rrt_connect_starts_over_and_its_runs_end_by_states_not_the_clock(monkeypatch):
    """Runs of 40, 48, 58, ... states: the search starts over until one finds the path; each run
    ends by the states it sampled, so the path is the same within any budget that reaches it; a
    path's every segment keeps the clearance; an error in a validity callback reaches the caller."""
    checker, robot, query = slot_query("slot_60", 4)
    scene = Scene(checker, robot.lower_limits, robot.upper_limits)
    monkeypatch.setattr(sys.modules[Scene.__module__], "RESTART", 40)  # the search module (shadowed by its function)
    found = search(scene, query.start, query.goal, planning_time=20.0, seed=5)
    assert found.vertices is not None and found.runs > 1 and found.samples > 40
    again = search(scene, query.start, query.goal, planning_time=60.0, seed=5)
    np.testing.assert_array_equal(found.vertices, again.vertices)
    assert again.runs == found.runs and again.samples == found.samples
    assert all(scene.segment_valid(a, b) for a, b in zip(found.vertices, found.vertices[1:]))

    def refuse(q):
        raise KeyboardInterrupt

    monkeypatch.setattr(scene, "valid", refuse)
    with pytest.raises(KeyboardInterrupt):
        search(scene, query.start, query.goal, planning_time=5.0, seed=5)


def test_a_start_in_collision_is_refused_naming_the_bodies():
    q = np.array(SHELF.q_initial)
    q[1] += 0.35  # the forearm down into the lower board
    planner = make_planner(FreeMotionConfig(poses=SHELF.planner.poses), UR10E, q)
    with pytest.raises(CollisionError, match="start configuration") as refused:
        shelf_checker().check_planner(planner)
    assert refused.value.cause is Cause.COLLISION


def test_a_goal_inside_an_obstacle_is_refused_at_the_goal():
    goal = [-0.5, -1.2, 1.6, -1.9, -1.57, 0.0]
    box = Box(name="crate", size=[0.2, 0.2, 0.2], xyz=UR10E.tool_position(np.array(goal)[None])[0].tolist())
    checker = CellChecker(UR10E, Cell(obstacles=[box]))
    nearest = checker.contacts(goal)[0]
    assert nearest.distance < 0 and "crate" in nearest.bodies  # the wrist inside the crate
    planner = make_planner(FreeMotionConfig(goals=[goal]), UR10E, UR10E.home_configuration)
    with pytest.raises(CollisionError, match="goal 0") as refused:
        checker.check_planner(planner)
    assert refused.value.field == ("goals", 0)


def test_a_goal_outside_the_joint_ranges_is_refused():
    planner = make_planner(FreeMotionConfig(goals=[[0.0, -1.57, 0.0, -1.57, 0.0, 7.0]]), UR10E,
                           UR10E.home_configuration)
    with pytest.raises(DrakeTrajError, match=r"^goal 0: joint 6 \(wrist_3_joint\) = 7 rad is outside its range") as refused:
        CellChecker(UR10E).check_planner(planner)
    assert refused.value.cause is Cause.JOINT_RANGE and refused.value.field == ("goals", 0)


def test_an_unreachable_pose_is_refused():
    planner = make_planner(FreeMotionConfig(poses=[[2.5, 0.0, 0.5, 0.0, 1.57, 0.0]]), UR10E, UR10E.home_configuration)
    with pytest.raises(DrakeTrajError, match=r"^pose 0 cannot be reached: .* is out of reach") as refused:
        CellChecker(UR10E).check_planner(planner)
    assert refused.value.cause is Cause.UNREACHABLE and refused.value.field == ("poses", 0)
    # the IK's reason once, the wrist-1 joint's distances over its branches as one range
    assert str(refused.value).count("the wrist-1 joint would be") == 1


def test_a_pose_inside_an_obstacle_names_the_obstacle():
    pose = [0.9, 0.0, 0.5, 0.0, 1.5707963267948966, 0.0]  # the TCP, tool level, in the middle of the crate
    crate = Box(name="crate", size=[0.3, 0.3, 0.3], xyz=pose[:3])
    planner = make_planner(FreeMotionConfig(poses=[pose]), UR10E, UR10E.home_configuration)
    with pytest.raises(PlanningError, match=r"^pose 0: none of its 8 inverse-kinematics solutions is inside the joint "
                                            r"ranges and clear of the cell \(.*closer than cell.clearance: \d+ to crate") as refused:
        CellChecker(UR10E, Cell(obstacles=[crate])).check_planner(planner)
    assert refused.value.cause is Cause.COLLISION and refused.value.field == ("poses", 0)


def slot_query(kind: str, seed: int):
    """A seeded query of the free-motion bench (drake_traj.bench.free_scenes): its scene's checker and query."""
    scene = generate(kind, seed)
    return CellChecker(scene.robot, cell=scene.cell), scene.robot, scene.queries[0]


def test_no_path_within_the_budget_says_what_was_tried_and_what_would_help():
    # a slot 40 mm taller than the forearm, 2 rad edges (3 of 5 such found in 5 s), 40 ms of search
    checker, robot, query = slot_query("slot_40", 1)
    planner = make_planner(query.config(planning_time=0.05, max_step=2.0), robot, query.start)
    with pytest.raises(PlanningError, match=r"no collision-free path to goal 0 found within planning_time = 0.05 s "
                                            r"\(RRTConnect, 1 configuration tried, \d+ states sampled in 0.0\d s of "
                                            r"search\); a path may need more time: give planning_time = 0.2") as refused:
        checker.check_planner(planner)
    assert refused.value.cause is Cause.PLANNING and refused.value.field == ("goals", 0)
    assert "Approximate" not in str(refused.value) and "Timeout" not in str(refused.value)  # not OMPL's words


def test_a_path_no_smooth_motion_keeps_clear_is_searched_again_while_the_budget_lasts(monkeypatch):
    """The first path's spline refused at every density: the planner searches again (the next
    seed) and times that one; refused every time, it says how many paths it found, by the budget."""
    checker, robot, query = slot_query("slot_60", 4)
    real = free_system.FreeMotionPlanner._smooth_and_time
    tried = []

    def first_refused(self, scene, checker, vertices, density):
        tried.append(len(vertices))
        return None if len(tried) <= len(free_system.DENSITIES) else real(self, scene, checker, vertices, density)

    monkeypatch.setattr(free_system.FreeMotionPlanner, "_smooth_and_time", first_refused)
    planner = make_planner(query.config(planning_time=5.0), robot, query.start)
    checker.check_planner(planner)
    assert len(tried) > len(free_system.DENSITIES) and planner.planning_time_s < 5.0 + 0.2
    np.testing.assert_allclose(planner.plan().value(planner.plan().end_time()).ravel(), query.goal, atol=1e-9)
    monkeypatch.setattr(free_system.FreeMotionPlanner, "_smooth_and_time", lambda *args: None)
    planner = make_planner(query.config(planning_time=2.0), robot, query.start)
    with pytest.raises(PlanningError, match=r"^goal 0: (\d+) paths were found \(\d+(, \d+)* vertices\) but no smooth "
                                            r"motion along any kept the clearance") as refused:
        checker.check_planner(planner)
    assert int(re.match(r"goal 0: (\d+)", str(refused.value))[1]) >= 2 and refused.value.cause is Cause.PLANNING


def test_a_narrow_passage_is_found_and_the_budget_covers_all_of_planning():
    checker, robot, query = slot_query("slot_60", 4)  # a slot 60 mm taller than the forearm
    planner = make_planner(query.config(planning_time=2.0), robot, query.start)
    checker.check_planner(planner)  # found, timed and checked in the cell
    np.testing.assert_allclose(planner.plan().value(planner.plan().end_time()).ravel(), query.goal, atol=1e-9)
    # search, shortening, smoothing, timing and the check together: within the budget (0.2 s of slack
    # for a busy machine's timing and check, which cannot be cut short)
    assert 0.0 < planner.planning_time_s < 2.0 + 0.2


def test_a_scenario_refusal_is_at_the_goals_line(tmp_path, monkeypatch):
    text = SHELF.source.path.read_text()
    path = tmp_path / "tight.yaml"
    path.write_text(text)
    line = 1 + text.splitlines().index(next(row for row in text.splitlines() if row.strip().startswith("- [0.70")))
    # a search that finds nothing (the shelf's own is found within milliseconds)
    monkeypatch.setattr(free_system, "search", lambda *args, **kwargs: SearchResult(None, "rrt_connect", 0.01, 7, 7, ""))
    with pytest.raises(PlanningError, match=rf"tight.yaml, line {line}, column 7: planner.poses\[0\]: no collision-free "
                                            "path to pose 0"):
        simulate(load_scenario(path))


def test_a_scenario_pose_out_of_reach_is_at_its_planner_field(tmp_path):
    text = SHELF.source.path.read_text()
    row = next(row for row in text.splitlines() if row.strip().startswith("- [0.70"))
    path = tmp_path / "far.yaml"
    path.write_text(text.replace(row, "    - [2.70, -0.305, 0.40, 0.0, 1.5707963267948966, 0.0]"))
    line = 1 + text.splitlines().index(row)
    with pytest.raises(DrakeTrajError, match=rf"far.yaml, line {line}, column 7: planner.poses\[0\]: pose 0 cannot be "
                                             r"reached: .* the wrist-1 joint would be [\d.]+ to [\d.]+ m \(by IK branch\)") as refused:
        simulate(load_scenario(path))
    assert refused.value.field == ("planner", "poses", 0)


def test_several_goals_stop_at_each_and_a_station_of_ones_own_plans_in_its_cell():
    goals = [[-0.3, -1.2, -1.5, -1.9, 1.8, 0.2], [-0.9, -1.9, -1.9, -0.9, 1.2, 1.4]]
    scenario = load_scenario("quintic_ptp")
    scenario.planner = FreeMotionConfig(goals=goals)
    station = make_station(scenario)
    simulator = Simulator(station)
    assert run_station(simulator, station) is None  # planned and checked when the run starts
    planner = station.GetSubsystemByName("planner")
    assert len(planner.legs) == 2
    plan = planner.plan()
    middle = planner.legs[0].timing.duration
    np.testing.assert_allclose(plan.value(middle).ravel(), goals[0], atol=1e-9)
    np.testing.assert_allclose(plan.derivative(1).value(middle).ravel(), 0.0, atol=1e-9)  # at rest at the goal
    for leg, offset in zip(planner.legs, (0.0, middle)):  # the joined law is each leg's own, knot by knot
        for knot in leg.timing.law.knots[::7]:
            np.testing.assert_allclose(np.stack(planner.law.sample(offset + knot)), np.stack(leg.timing.law.sample(knot)),
                                       rtol=0.0, atol=1e-12)


@pytest.mark.parametrize("config, field", [
    (FreeMotionConfig(), "goals"),
    (FreeMotionConfig(goals=[[0.0] * 6], poses=[[0.5, 0, 0.5, 0, 0, 0]]), "goals"),
    (FreeMotionConfig(goals=[[0.0] * 5]), "goals"),
    (FreeMotionConfig(goals=[[0.0] * 6], planning_time=-1.0), "planning_time"),
    (FreeMotionConfig(goals=[[0.0] * 6], planning_time=1e6), "planning_time"),
    (FreeMotionConfig(goals=[[0.0] * 6], planner="prm"), "planner"),
    (FreeMotionConfig(goals=[[0.0] * 6], seed=-3), "seed"),
    (FreeMotionConfig(goals=[[np.nan] * 6]), "goals"),
])
def test_a_malformed_config_is_refused_naming_its_field(config, field):
    with pytest.raises(ValueError, match=field) as refused:
        make_planner(config, UR10E, UR10E.home_configuration)
    assert refused.value.field[0] == field


def test_the_plan_before_planning_says_so():
    planner = make_planner(FreeMotionConfig(goals=[[0.0, -1.57, 0.0, -1.57, 0.0, 0.0]]), UR10E, UR10E.home_configuration)
    with pytest.raises(PlanningError, match="has not planned its path yet"):
        planner.plan()
