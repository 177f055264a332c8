"""Benchmark: what the closed loop costs beside the plant it drives, and what the planners cost.

    python examples/bench_planner_cost.py [--repeats 3] [--time-step 0.001]

All in one process, floor first:

1. the floor: the same discrete robot plant (SAP, PD actuators, gravity compensation, three
   loggers) driven by a ``ConstantVectorSource`` at the start configuration, simulated for 5 s;
2. each shipped scenario's station under its own ``SimulatorConfig`` (``simulate``): the
   real-time factor (simulated seconds per wall-clock second) and its ratio to the floor of the
   same robot;
3. the planner's cost per evaluation of its law at mid-motion (``evaluate``, uncached; median of
   7 batches of 500) and, for the Pająk planner, its law integrated alone (``preflight``: RK4 at
   1 ms) against the floor's wall time for the same simulated time.

Best of ``--repeats`` runs for the real-time factors (the machine is shared; the best run is the
one least disturbed). Prints Markdown tables. A benchmark, not a test: numbers depend on the
machine.
"""

import argparse
import statistics
import time

import numpy as np
from pydrake.multibody.plant import AddMultibodyPlant
from pydrake.multibody.tree import PdControllerGains
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.controllers import InverseDynamics
from pydrake.systems.framework import DiagramBuilder, TriggerType
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput

from drake_traj.robots import get_robot
from drake_traj.scenario import default_scenario_path, load_scenario
from drake_traj.station import build_station, run_station

SCENARIOS = (("quintic_ptp.yaml", None), ("pajak.yaml", "sim3"), ("boryga_loop.yaml", "ur10e"),
             ("li_closed_path.yaml", "ur10e"), ("li_closed_path.yaml", "4dof"))
FLOOR_DURATION = 5.0  # [s] simulated


def floor_real_time_factor(scenario) -> float:
    """Real-time factor of the plant alone: the scenario's robot, plant config and gains, held at
    its start by a constant desired state, gravity compensation, three loggers."""
    robot = get_robot(scenario.robot)
    gains = scenario.controller.for_robot(robot)
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlant(scenario.plant, builder)
    instance = robot.add_to_plant(plant)
    for joint_name, kp, kd in zip(robot.joint_names, gains.kp, gains.kd):
        plant.GetJointActuatorByName(f"{joint_name}_actuator", instance).set_controller_gains(PdControllerGains(p=kp, d=kd))
    plant.Finalize()
    q0 = scenario.start_configuration()
    plant.SetDefaultPositions(instance, q0)
    source = builder.AddSystem(ConstantVectorSource(np.concatenate([q0, np.zeros_like(q0)])))
    builder.Connect(source.get_output_port(), plant.get_desired_state_input_port(instance))
    gravity = builder.AddSystem(InverseDynamics(plant, InverseDynamics.InverseDynamicsMode.kGravityCompensation))
    builder.Connect(plant.get_state_output_port(instance), gravity.get_input_port_estimated_state())
    builder.Connect(gravity.get_output_port_generalized_force(), plant.get_actuation_input_port(instance))
    for port in (source.get_output_port(), plant.get_state_output_port(instance),
                 plant.get_net_actuation_output_port(instance)):
        LogVectorOutput(port, builder, {TriggerType.kPeriodic}, scenario.log_period)
    simulator = Simulator(builder.Build())
    ApplySimulatorConfig(scenario.simulator, simulator)
    start = time.perf_counter()
    simulator.AdvanceTo(FLOOR_DURATION)
    return FLOOR_DURATION / (time.perf_counter() - start)


def station_real_time_factor(scenario) -> tuple[float, float]:
    """(real-time factor, simulated time [s]) of the scenario's station run to its finish."""
    station = build_station(**scenario.station_arguments())
    simulator = Simulator(station)
    ApplySimulatorConfig(scenario.simulator, simulator)
    start = time.perf_counter()
    failure = run_station(simulator, station, settle_time=scenario.settle_time, max_duration=scenario.max_duration)
    wall = time.perf_counter() - start
    if failure is not None:
        raise RuntimeError(f"{scenario.name}: {failure}")
    simulated = simulator.get_context().get_time()
    return simulated / wall, simulated


def evaluation_cost_us(scenario) -> float:
    """Median µs of one uncached evaluation of the planner (q̈ and c) at the middle of the motion."""
    station = build_station(**scenario.station_arguments())
    simulator = Simulator(station)
    ApplySimulatorConfig(scenario.simulator, simulator)
    planner = station.GetSubsystemByName("planner")
    simulator.AdvanceTo(2.0)
    context = planner.GetMyContextFromRoot(simulator.get_context())
    batches = []
    for _ in range(7):
        start = time.perf_counter()
        for _ in range(500):
            planner.evaluate(context)
        batches.append((time.perf_counter() - start) / 500 * 1e6)
    return statistics.median(batches)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="runs per measurement (the best is kept)")
    parser.add_argument("--time-step", type=float, default=None, help="plant time step [s] (default: the scenario's)")
    args = parser.parse_args()
    scenarios = [load_scenario(default_scenario_path().parent / path, variant) for path, variant in SCENARIOS]
    if args.time_step is not None:
        for scenario in scenarios:
            scenario.plant.time_step = args.time_step
            scenario.simulator.max_step_size = args.time_step
    floors = {}
    print("| robot | floor real-time factor |\n|---|---|")
    for scenario in scenarios:
        if scenario.robot not in floors:
            floors[scenario.robot] = max(floor_real_time_factor(scenario) for _ in range(args.repeats))
            print(f"| {scenario.robot} | {floors[scenario.robot]:.2f} |", flush=True)
    print("\n| scenario | real-time factor | ratio to the floor | planner evaluation [µs] | law alone / floor |")
    print("|---|---|---|---|---|")
    for scenario in scenarios:
        runs = [station_real_time_factor(scenario) for _ in range(args.repeats)]
        rtf = max(rate for rate, _ in runs)
        cost = evaluation_cost_us(scenario)
        law = "–"
        planner = build_station(**scenario.station_arguments()).GetSubsystemByName("planner")
        if planner.plans_online:  # its preflight integrates the law over the whole task
            walls = []
            for _ in range(args.repeats):
                start = time.perf_counter()
                planner.preflight()
                walls.append(time.perf_counter() - start)
            law = f"{min(walls) / (runs[0][1] / floors[scenario.robot]):.2f}"
        print(f"| {scenario.name} | {rtf:.2f} | {rtf / floors[scenario.robot]:.2f} | {cost:.0f} | {law} |", flush=True)


if __name__ == "__main__":
    main()
