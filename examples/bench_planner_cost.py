"""Benchmark: planner cost per derivative evaluation and real-time factors (medians).

    python examples/bench_planner_cost.py [--repeats 5]

For each scenario: the planner's cost per derivative evaluation [µs] at mid-motion (its
``evaluate``, which the cached derivatives call once per new context; median of 7 batches of 500), the real-time factor of the planner alone under the Simulator, and of the
closed-loop diagram (planner + PD-controlled plant + loggers), each the median of ``repeats``
runs. Prints a Markdown table. A benchmark, not a test: numbers depend on the machine.
"""

import argparse
import statistics
import time

from pydrake.systems.analysis import Simulator

from drake_traj.diagram import simulate
from drake_traj.scenario import DEFAULT_SCENARIO, default_scenario_path, load_scenario, make_planner

SCENARIOS = ((default_scenario_path().parent / "quintic_ptp.yaml", None), (default_scenario_path(), DEFAULT_SCENARIO[1]))


def derivative_cost_us(scenario) -> float:
    """Median µs of one uncached evaluation (qdd and c) at the middle of the motion."""
    planner = make_planner(scenario)
    simulator = Simulator(planner)
    simulator.get_mutable_integrator().set_maximum_step_size(scenario.time_step)
    simulator.AdvanceTo(2.0)
    context = simulator.get_context()
    batches = []
    for _ in range(7):
        start = time.perf_counter()
        for _ in range(500):
            planner.evaluate(context)
        batches.append((time.perf_counter() - start) / 500 * 1e6)
    return statistics.median(batches)


def planner_alone_rtf(scenario) -> float:
    planner = make_planner(scenario)
    simulator = Simulator(planner)
    simulator.get_mutable_integrator().set_maximum_step_size(scenario.time_step)
    simulator.get_mutable_integrator().set_target_accuracy(1e-8)
    start = time.perf_counter()
    simulator.AdvanceTo(5.0)
    return 5.0 / (time.perf_counter() - start)


def closed_loop_rtf(scenario) -> float:
    result = simulate(make_planner(scenario), name=scenario.name, gains=scenario.controller,
                      settle_time=scenario.settle_time, max_duration=scenario.max_duration)
    return result.metrics().real_time_factor


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print("| scenario | derivative [µs] | RTF planner alone | RTF closed loop |")
    print("|---|---|---|---|")
    for path, variant in SCENARIOS:
        scenario = load_scenario(path, variant)
        cost = derivative_cost_us(scenario)
        alone = statistics.median(planner_alone_rtf(scenario) for _ in range(args.repeats))
        loop = statistics.median(closed_loop_rtf(scenario) for _ in range(args.repeats))
        print(f"| {scenario.name} | {cost:.0f} | {alone:.2f} | {loop:.2f} |", flush=True)


if __name__ == "__main__":
    main()
