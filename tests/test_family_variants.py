"""The shipped e-Series variants (diagrams/pajak.yaml ur3e..ur30, diagrams/quintic.yaml
ptp_ur3e..ptp_ur30): each on its own arm with that arm's limits and default gains, its task
accepted by the preflight (the Pająk law integrated, the cell check), and one closed-loop run per
arm with the limits held at every logged sample and the goal reached; and the README's "Your
arm" Python (a user's URDF in the station and beside the user's plant)."""

import numpy as np
import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from drake_traj import PajakConfig
from drake_traj.data import data_directory
from drake_traj.planners import make_planner as make_planner_for
from drake_traj.robots import get_robot, ur_eseries
from drake_traj.robots.chain_arm import ChainArm
from drake_traj.robots.task_space import wrap_angle
from drake_traj.scenario import load_scenario, make_planner, preflight, shipped_scenarios
from drake_traj.station import simulate

ARMS = ("ur3e", "ur5e", "ur16e", "ur20", "ur30")
VARIANTS = [f"pajak_{arm}" for arm in ARMS] + [f"quintic_ptp_{arm}" for arm in ARMS]


def test_every_arm_has_both_variants_shipped():
    shipped = {entry.name: entry.robot for entry in shipped_scenarios()}
    assert {name: shipped.get(name) for name in VARIANTS} == {name: name.rsplit("_", 1)[1] for name in VARIANTS}


@pytest.mark.parametrize("name", VARIANTS)
def test_variant_runs_its_own_arm_and_passes_the_preflight(name):
    scenario = load_scenario(name)
    arm = get_robot(scenario.robot)
    assert scenario.controller.for_robot(arm).kp == list(arm.default_gains[0])
    planner = make_planner(scenario)
    velocity, acceleration = arm.joint_move_limits
    np.testing.assert_array_equal(planner.velocity_limit, velocity)
    np.testing.assert_array_equal(planner.acceleration_limit, acceleration)
    np.testing.assert_array_equal(velocity, np.minimum(1.05, arm.velocity_limits))
    path = preflight(scenario, planner)
    if name.startswith("pajak"):  # the law's motion ends within 1 mm of the last waypoint, inside the arm's reach
        waypoints = np.array(scenario.planner.waypoints)[:, :3]
        assert np.linalg.norm(path[-1] - waypoints[-1]) < 1e-3
        assert np.all(np.linalg.norm(waypoints - arm.tcp_pose(arm.home_configuration)[:3], axis=1) < arm.reach)


@pytest.mark.parametrize("name", ["pajak_ur3e", "quintic_ptp_ur5e", "pajak_ur16e", "quintic_ptp_ur20", "pajak_ur30"])
def test_closed_loop_holds_the_arms_limits_and_reaches_the_goal(name):
    scenario = load_scenario(name)
    arm = get_robot(scenario.robot)
    result = simulate(scenario)
    assert result.succeeded, result.failure
    assert result.robot == arm.name
    velocity, acceleration = arm.joint_move_limits
    np.testing.assert_array_equal(result.effort_limit, arm.effort_limits)
    # every logged 1 ms sample of the reference within the planner's limits; torques within the arm's
    assert np.all(np.abs(result.qd_ref) <= velocity + 1e-9) and np.all(np.abs(result.qdd_ref) <= acceleration + 1e-9)
    assert np.all(np.abs(result.tau) <= arm.effort_limits + 1e-9)
    if name.startswith("pajak"):
        goal = np.array(scenario.planner.waypoints[-1])
        final = arm.tcp_pose(result.q_meas[-1])
        assert np.linalg.norm(final[:3] - goal[:3]) < scenario.planner.accuracy  # 1 mm
        assert np.max(np.abs(wrap_angle(final[3:] - goal[3:]))) < scenario.planner.orientation_accuracy
    else:
        assert np.max(np.abs(result.q_meas[-1] - scenario.planner.goals[-1])) < 1e-3


def test_readme_your_arm_python_a_users_urdf_in_the_station_and_beside_a_users_plant():
    """README "Your arm": the UR5e's URDF read as a user's model (ChainArm.from_model_file) runs
    a Pająk task in the station to the analytic UR5e's finish time; read from a user's plant
    (ChainArm.from_plant), its planner in the user's diagram reaches the last waypoint."""
    model = str(data_directory("models") / "ur5e.urdf")
    start = ur_eseries.HOME
    down = [np.pi, 0.0, 3 * np.pi / 4]
    task = PajakConfig(waypoints=[[-0.134, -0.378, 0.51, *down], [0.16, -0.378, 0.51, *down]],
                       velocity_limit=1.05, acceleration_limit=1.4)
    arm = ChainArm.from_model_file(model, name="my_arm", base_frame="base", tool_frame="tool0", acceleration_limits=1.4,
                                   home=start)
    result = simulate(make_planner_for(task, arm, start))
    analytic = make_planner_for(task, get_robot("ur5e"), start)
    analytic.preflight()
    assert result.succeeded and result.robot == "my_arm"
    assert result.duration == pytest.approx(analytic.planned_duration(), abs=1e-3)  # the law's finish

    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.001)
    Parser(plant).AddModels(model)
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("base"))
    plant.Finalize()
    arm = ChainArm.from_plant(plant, name="my_arm", base_frame="base", tool_frame="tool0", acceleration_limits=1.4)
    planner = builder.AddSystem(make_planner_for(task, arm, start))
    planner.preflight()
    log = LogVectorOutput(planner.GetOutputPort("desired_state"), builder)
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(planner.plan().end_time())
    q_end = log.FindLog(simulator.get_context()).data()[:6, -1]
    # the law finishes within its accuracy (1 mm); 0.1 mm for Drake's default integrator against the plan
    assert np.linalg.norm(arm.tcp_pose(q_end)[:3] - task.waypoints[-1][:3]) < task.accuracy + 1e-4
