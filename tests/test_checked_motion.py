"""Every motion that runs is the motion that was checked: every route into a station checks the
plan against the station's own scene before anything moves, and the measured motion is watched
while it runs (drake_traj.cell.guard)."""

import numpy as np
import pytest
from pydrake.geometry import Box as DrakeBox
from pydrake.math import RigidTransform
from pydrake.multibody.plant import CoulombFriction
from pydrake.multibody.tree import SpatialInertia
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from drake_traj import QuinticConfig, get_robot, load_scenario, make_station, run_station, simulate
from drake_traj.cell import Box, Cell, CellChecker, CollisionError, UncheckedMotionError
from drake_traj.errors import Cause
from drake_traj.planners import make_planner
from drake_traj.results import SimulationResult
from drake_traj.scenario import default_simulator_config
from drake_traj.station import build_station

UR10E = get_robot("ur10e")
START = np.array([0.0, -1.9, 1.9, -1.57, -1.57, 0.0])
GOAL = np.array([1.2, -1.9, 1.9, -1.57, -1.57, 0.0])  # the base turns 1.2 rad: the arm sweeps round


def sweep():
    return make_planner(QuinticConfig(goals=[GOAL.tolist()]), UR10E, START)


def wall_in_the_sweep() -> Box:
    """A wall 5 cm thick across the forearm's sweep, half way (the plan goes through it)."""
    middle = UR10E.tool_position(0.5 * (START + GOAL))
    return Box(name="wall", size=[0.05, 0.6, 1.2], xyz=[float(middle[0]), float(middle[1]), 0.6],
               rpy=[0.0, 0.0, float(np.arctan2(middle[1], middle[0]))])


def own_run(station_diagram, *, initialize_only=False):
    builder = DiagramBuilder()
    station = builder.AddSystem(station_diagram)
    simulator = Simulator(builder.Build())
    ApplySimulatorConfig(default_simulator_config(), simulator)
    if initialize_only:
        simulator.Initialize()
        return None
    return run_station(simulator, station, settle_time=0.1, max_duration=20.0)


def test_a_plan_through_the_cell_is_refused_on_every_route_into_a_station():
    cell = Cell(obstacles=[wall_in_the_sweep()])
    with pytest.raises(CollisionError, match="wall"):  # simulate: the preflight
        simulate(sweep(), cell=cell)
    with pytest.raises(CollisionError, match="wall") as refused:  # one's own Simulator and run_station
        own_run(build_station(sweep(), cell=cell))
    assert refused.value.cause is Cause.COLLISION and "wall" in refused.value.bodies
    with pytest.raises(CollisionError, match="wall"):  # one's own Simulator, initialized without run_station
        own_run(build_station(sweep(), cell=cell), initialize_only=True)


def test_a_scenario_station_refuses_at_the_obstacles_line(tmp_path):
    text = load_scenario("quintic_ptp").source.path.read_text()
    path = tmp_path / "blocked.yaml"
    # the first move turns the base from 0 to -0.9 rad with the forearm out: a post in its way
    path.write_text(text + "\ncell:\n  obstacles:\n    - !Cylinder {name: post, radius: 0.05, length: 1.5, "
                           "xyz: [0.55, -0.55, 0.75]}\n")
    scenario = load_scenario(path)
    with pytest.raises(CollisionError, match=r"blocked.yaml, line \d+.*post") as refused:
        own_run(make_station(scenario))
    assert refused.value.field[:2] == ("cell", "obstacles")


def test_bodies_added_before_finalize_are_in_the_check():
    middle = UR10E.tool_position(0.5 * (START + GOAL))

    def add_block(plant, scene_graph):
        block = plant.AddRigidBody("block", plant.AddModelInstance("mine"),
                                   SpatialInertia.SolidBoxWithMass(1.0, 0.1, 0.1, 0.1))
        plant.WeldFrames(plant.world_frame(), block.body_frame(), RigidTransform([middle[0], middle[1], middle[2]]))
        plant.RegisterCollisionGeometry(block, RigidTransform(), DrakeBox(0.1, 0.1, 0.1), "block", CoulombFriction(0.5, 0.5))

    with pytest.raises(CollisionError, match="block"):
        own_run(build_station(sweep(), before_finalize=add_block))


def test_a_before_finalize_that_adds_other_bodies_each_call_is_refused():
    calls = []

    def add_a_new_body_each_time(plant, scene_graph):
        calls.append(1)
        body = plant.AddRigidBody(f"block{len(calls)}", plant.AddModelInstance("mine"),
                                  SpatialInertia.SolidBoxWithMass(1.0, 0.1, 0.1, 0.1))
        plant.WeldFrames(plant.world_frame(), body.body_frame(), RigidTransform([3.0 + len(calls), 0, 0.5]))
        plant.RegisterCollisionGeometry(body, RigidTransform(), DrakeBox(0.1, 0.1, 0.1), "block", CoulombFriction(0.5, 0.5))

    with pytest.raises(UncheckedMotionError, match="could not be built again"):
        own_run(build_station(sweep(), before_finalize=add_a_new_body_each_time))


def test_a_checked_plan_is_not_checked_again_and_runs():
    planner = sweep()
    CellChecker(UR10E, Cell()).check_planner(planner)
    assert len(planner.checked_scenes) == 1
    assert own_run(build_station(planner)) is None


def test_an_explicitly_unchecked_run_is_caught_by_the_watch_naming_the_bodies():
    cell = Cell(obstacles=[wall_in_the_sweep()])
    for result in (simulate(sweep(), cell=cell, preflight=False),):
        assert not result.succeeded and result.failure.cause == "collision"
        assert "wall" in result.failure.message and "not checked" in result.failure.message
        # caught at half the clearance, before the plant's contact: 5 mm away at the failure
        q = np.array(result.failure.configuration)
        distance = CellChecker(UR10E, cell).contacts(q, within=0.1)[0].distance
        assert 0.0 < distance < 0.005 + 1e-9
    failure = own_run(build_station(sweep(), cell=cell, check_motion=False))
    assert failure.cause == "collision" and "wall" in failure.message


@pytest.mark.parametrize("log_period", [1e-3, 0.01, 0.05])
def test_the_watch_sees_a_thin_plate_between_logged_samples(log_period):
    """A 2 mm plate the arm sweeps through in less than a log period: the watch's bound between
    samples finds it where no sample is inside it."""
    middle = UR10E.tool_position(0.5 * (START + GOAL))
    plate = Box(name="plate", size=[0.002, 0.3, 0.3], xyz=[float(middle[0]), float(middle[1]), float(middle[2])],
                rpy=[0.0, 0.0, float(np.arctan2(middle[1], middle[0]))])
    result = simulate(sweep(), cell=Cell(obstacles=[plate]), preflight=False, log_period=log_period)
    assert result.failure is not None and result.failure.cause == "collision", result.failure
    assert "plate" in result.failure.message


def test_a_valid_run_is_watched_without_a_failure_and_its_distance_holds():
    scenario = load_scenario("fixture_cell")
    result = simulate(scenario)
    assert result.succeeded
    checker = scenario.cell_checker()
    nearest = min(checker.contacts(q, within=0.02)[0].distance if checker.contacts(q, within=0.02) else 0.02
                  for q in result.q_meas[::5])
    assert nearest >= 0.5 * checker.clearance  # measured 31.1 mm to the fixture, 14 mm arm to arm


def test_a_pushed_arm_fails_the_run_naming_the_bodies_and_the_time():
    """A sustained push (a person leaning on the forearm) drives the arm off its checked motion into
    the table: the run fails with the bodies and the time, not a success."""
    planner = sweep()
    builder = DiagramBuilder()
    station = builder.AddSystem(build_station(planner))
    push = builder.AddSystem(ConstantVectorSource([0.0, 900.0, 400.0, 0.0, 0.0, 0.0]))  # [N m]
    builder.Connect(push.get_output_port(), station.GetInputPort("applied_generalized_force"))
    simulator = Simulator(builder.Build())
    ApplySimulatorConfig(default_simulator_config(), simulator)
    failure = run_station(simulator, station, settle_time=0.1, max_duration=5.0)
    assert failure is not None and failure.cause == "collision", failure
    assert "left the checked motion" in failure.message and "t = " in failure.message
    result = SimulationResult.from_station(station, station.GetMyContextFromRoot(simulator.get_context()),
                                           failure=failure)
    assert result.t[-1] == pytest.approx(failure.time, abs=0.011)
