"""Benchmark: what the closed loop costs beside the plant it drives, and what the planners cost.

    python examples/bench_planner_cost.py [--repeats 3] [--time-step 0.001] [--pajak-law-only]

All in one process; for each shipped scenario, ``--repeats`` times in turn (and the floor once more
at the end, so that every station run has a floor measured just before and just after it):

1. the floor: the same discrete robot plant (SAP, PD actuators, gravity compensation, three
   loggers) driven by a ``ConstantVectorSource`` at the start configuration, simulated for 5 s;
2. the moving floor: the same plant following the scenario's own reference motion from Drake's
   C++ ``TrajectorySource`` (one step ahead, inverse dynamics): what the motion costs the plant;
3. the scenario's station under its own ``SimulatorConfig`` (``run_station``).

It prints the medians of the real-time factors (simulated seconds per wall-clock second), the
median (and range) of the station's ratio to the mean of the floors measured just before and
after it, the moving floor's ratio to the floor, and the station's ratio to the moving floor:
what the planner and its Python calls cost. Then the planner's cost per evaluation of its law at mid-motion (``evaluate`` at a
new time per call; median of 7 batches of 500) and, for the Pająk planner, its law integrated
alone (``preflight``: RK4 at 1 ms) against the floor's wall time for the same simulated time.

Last, the Pająk law (Pająk 2024, sim 3): one evaluation of q̈ and c from Python
(``PajakLaw.acceleration``, median of 9 batches of 2000 calls), ``integrate`` of the whole task
(best of ``--repeats``) against the floor simulating the same time (best of ``--repeats``), and
the compiled kernels' first-call cost: a fresh process with an empty numba cache (compiles and
writes the cache), then a second one reading it.

The machine is shared and its speed drifts: ratios are taken between runs made next to each
other. Prints Markdown tables. A benchmark, not a test: numbers depend on the machine.
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
from pydrake.multibody.plant import AddMultibodyPlant
from pydrake.multibody.tree import PdControllerGains
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.controllers import InverseDynamics
from pydrake.systems.framework import DiagramBuilder, TriggerType
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput, MatrixGain, TrajectorySource

from drake_traj.planners import pajak
from drake_traj.scenario import default_scenario_path, load_scenario
from drake_traj.station import build_station, run_station, simulate

SCENARIOS = (("quintic_ptp.yaml", None), ("pajak.yaml", "sim3"), ("boryga_loop.yaml", "ur10e"),
             ("li_closed_path.yaml", "ur10e"), ("li_closed_path.yaml", "4dof"))
FLOOR_DURATION = 5.0  # [s] simulated


def floor_real_time_factor(scenario, duration: float = FLOOR_DURATION, reference=None) -> float:
    """Real-time factor of the plant alone: the scenario's robot, plant config and gains, three
    loggers, ``duration`` [s] simulated. Held at its start by a constant desired state with
    gravity compensation; or, given ``reference`` (a PiecewisePolynomial of q), moving along it:
    Drake's C++ ``TrajectorySource`` gives q, q̇, q̈, one step ahead, with inverse dynamics, as
    the station does (the arm's motion costs the plant's solver too)."""
    robot = scenario.base_robot()
    gains = scenario.controller.for_robot(robot)
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlant(scenario.plant, builder)
    instance = robot.add_to_plant(plant)
    for joint_name, kp, kd in zip(robot.joint_names, gains.kp, gains.kd):
        plant.GetJointActuatorByName(f"{joint_name}_actuator", instance).set_controller_gains(PdControllerGains(p=kp, d=kd))
    plant.Finalize()
    q0 = scenario.start_configuration()
    plant.SetDefaultPositions(instance, q0)
    n = robot.num_joints
    if reference is None:
        source = builder.AddSystem(ConstantVectorSource(np.concatenate([q0, np.zeros_like(q0)])))
        builder.Connect(source.get_output_port(), plant.get_desired_state_input_port(instance))
        feedforward = builder.AddSystem(InverseDynamics(plant, InverseDynamics.InverseDynamicsMode.kGravityCompensation))
    else:
        source = builder.AddSystem(TrajectorySource(reference, output_derivative_order=2))  # [q; q̇; q̈]
        h, eye, zero = scenario.plant.time_step, np.eye(n), np.zeros((n, n))
        lookahead = builder.AddSystem(MatrixGain(np.block([[eye, h * eye, 0.5 * h * h * eye], [zero, eye, h * eye]])))
        builder.Connect(source.get_output_port(), lookahead.get_input_port())
        builder.Connect(lookahead.get_output_port(), plant.get_desired_state_input_port(instance))
        acceleration = builder.AddSystem(MatrixGain(np.hstack([zero, zero, eye])))
        builder.Connect(source.get_output_port(), acceleration.get_input_port())
        feedforward = builder.AddSystem(InverseDynamics(plant, InverseDynamics.InverseDynamicsMode.kInverseDynamics))
        builder.Connect(acceleration.get_output_port(), feedforward.get_input_port_desired_acceleration())
    builder.Connect(plant.get_state_output_port(instance), feedforward.get_input_port_estimated_state())
    builder.Connect(feedforward.get_output_port_generalized_force(), plant.get_actuation_input_port(instance))
    for port in (source.get_output_port(), plant.get_state_output_port(instance),
                 plant.get_net_actuation_output_port(instance)):
        LogVectorOutput(port, builder, {TriggerType.kPeriodic}, scenario.logging_period())
    simulator = Simulator(builder.Build())
    ApplySimulatorConfig(scenario.simulator, simulator)
    start = time.perf_counter()
    simulator.AdvanceTo(duration)
    return duration / (time.perf_counter() - start)


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
    root = simulator.get_mutable_context()
    context = planner.GetMyContextFromRoot(root)
    batches = []
    for batch in range(7):
        # a new time for every call: time-law planners keep their last evaluation by value
        times = 2.0 + 1e-7 * np.arange(batch * 500, (batch + 1) * 500)
        start = time.perf_counter()
        for t in times:
            root.SetTime(t)
            planner.evaluate(context)
        batches.append((time.perf_counter() - start) / 500 * 1e6)
    return statistics.median(batches)


_FIRST_CALL = """
import time
start = time.perf_counter()
from drake_traj.planners import pajak
imported = time.perf_counter()
pajak.integrate(pajak.PajakLaw(pajak.paper_parameters(3)), pajak.paper_initial_configuration())
print(imported - start, time.perf_counter() - imported)
"""


def pajak_first_call_s() -> tuple[float, float]:
    """(compile, cached) [s]: the first integrate of sim 3 in a fresh process with an empty numba
    cache (it compiles the kernels and writes the cache), then in a second process reading it
    (imports excluded)."""
    with tempfile.TemporaryDirectory() as cache:
        environment = dict(os.environ, NUMBA_CACHE_DIR=cache)
        runs = [subprocess.run([sys.executable, "-c", _FIRST_CALL], env=environment, check=True, capture_output=True,
                               text=True).stdout.split() for _ in range(2)]
    return float(runs[0][1]), float(runs[1][1])


def pajak_law_cost(scenario, repeats: int) -> None:
    """Print the Pająk law's cost (the last table of the module docstring) on the scenario's task."""
    law = pajak.PajakLaw(scenario.planner)
    q0 = scenario.start_configuration()
    run = pajak.integrate(law, q0)
    k = len(run["t"]) // 2
    arguments = (run["t"][k], run["q"][k].copy(), run["qd"][k].copy(), run["discrete"][k].copy())
    batches = []
    for _ in range(9):
        start = time.perf_counter()
        for _ in range(2000):
            law.acceleration(*arguments)
        batches.append((time.perf_counter() - start) / 2000 * 1e6)
    walls = []
    for _ in range(repeats):
        start = time.perf_counter()
        pajak.integrate(law, q0)
        walls.append(time.perf_counter() - start)
    floor = max(floor_real_time_factor(scenario, run["T"]) for _ in range(repeats))
    compile_s, cached_s = pajak_first_call_s()
    rows = (
        ("evaluation (q̈, c) from Python, median [µs]", f"{statistics.median(batches):.1f}"),
        (f"integrate, {run['T']:.3f} s of motion, best [s]", f"{min(walls):.3f}"),
        ("the plant floor, same simulated time, best [s]", f"{run['T'] / floor:.3f}"),
        ("integrate / floor", f"{min(walls) * floor / run['T']:.2f}"),
        ("first integrate, empty numba cache (compiles) [s]", f"{compile_s:.1f}"),
        ("first integrate, cache written [s]", f"{cached_s:.2f}"),
    )
    print(f"\n| Pająk law ({scenario.name}) | |\n|---|---|")
    for name, value in rows:
        print(f"| {name} | {value} |", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="runs per measurement (their median is kept)")
    parser.add_argument("--time-step", type=float, default=None, help="plant time step [s] (default: the scenario's)")
    parser.add_argument("--pajak-law-only", action="store_true", help="only the last table, the Pająk law's cost")
    args = parser.parse_args()
    scenarios = [load_scenario(default_scenario_path().parent / path, variant) for path, variant in SCENARIOS]
    if args.time_step is not None:
        for scenario in scenarios:
            scenario.plant.time_step = args.time_step
            scenario.simulator.max_step_size = args.time_step
    pajak_scenario = next(s for s in scenarios if isinstance(s.planner, pajak.PajakConfig))
    if args.pajak_law_only:
        pajak_law_cost(pajak_scenario, args.repeats)
        return
    print("| scenario | floor, arm at rest | station | station / floor | moving floor / floor | station / moving floor "
          "| planner evaluation [µs] | law alone / floor |")
    print("|---|---|---|---|---|---|---|---|")
    for scenario in scenarios:
        arguments = scenario.station_arguments()
        reference = simulate(arguments.pop("planner"), simulator_config=scenario.simulator, settle_time=scenario.settle_time,
                             max_duration=scenario.max_duration, **arguments).reference_trajectory()
        # floor, moving floor and station measured in turn, ``repeats`` times, and a last floor:
        # each station against the mean of the floors just before and just after it
        floors, movings, stations = [], [], []
        for _ in range(args.repeats):
            floors.append(floor_real_time_factor(scenario))
            movings.append(floor_real_time_factor(scenario, reference.end_time(), reference))
            stations.append(station_real_time_factor(scenario))
        floors.append(floor_real_time_factor(scenario))
        floor, moving = statistics.median(floors), statistics.median(movings)
        station = statistics.median(rate for rate, _ in stations)
        ratios = [rate / (0.5 * (before + after)) for (rate, _), before, after in zip(stations, floors, floors[1:])]
        cost = evaluation_cost_us(scenario)
        law = "–"
        planner = build_station(**scenario.station_arguments()).GetSubsystemByName("planner")
        if planner.plans_online:  # its preflight integrates the law over the whole task
            walls = []
            for _ in range(args.repeats):
                start = time.perf_counter()
                planner.preflight()
                walls.append(time.perf_counter() - start)
            law = f"{statistics.median(walls) / (stations[0][1] / floor):.2f}"
        print(f"| {scenario.name} | {floor:.2f} | {station:.2f} | {statistics.median(ratios):.2f} ({min(ratios):.2f}-"
              f"{max(ratios):.2f}) | {moving / floor:.2f} | {station / moving:.2f} | {cost:.0f} | {law} |", flush=True)
    pajak_law_cost(pajak_scenario, args.repeats)


if __name__ == "__main__":
    main()
