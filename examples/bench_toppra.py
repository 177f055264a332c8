"""Benchmark: the Toppra baseline on the paper task's pajak_blend path (medians).

    python examples/bench_toppra.py [--repeats 7]

Plans Toppra along the path ``drake-traj bench`` gives it on the paper task (pajak_blend's
planned joint path, 2000 grid points) and prints, each the median of ``repeats`` runs: the
planning time and its stages (the path spline from the samples, Toppra's solve, the law's table)
against the target of 0.5 s per path; the time-optimal T* and the law's duration; and the
closed loop's T and real-time factor. A benchmark, not a test: times depend on the machine.
"""

import argparse
import statistics
import time

from drake_traj.bench import optimum, task_sets, units
from drake_traj.station import simulate
from drake_traj.planners import ToppraConfig, make_planner
from drake_traj.planners.baselines.toppra import ToppraLaw, geometric_path_from_samples, time_optimal_along_path
from drake_traj.planners.base import start_and_goals
from drake_traj.robots import UR10E

PLANNING_TARGET_S = 0.5


def paper_path():
    """pajak_blend's planned joint path on the paper task, as the bench computes it."""
    task = task_sets.tasks(count=0, repeats=1)[0]
    output = units.run_planner(task, units.REFERENCE, units.CONFIG_BUILDERS[units.REFERENCE], keep_path=True)
    return output["path"]


def stages(path) -> dict:
    """Wall time [s] of each planning stage, as ``toppra.make`` runs them."""
    times = {}
    start = time.perf_counter()
    spline = geometric_path_from_samples(start_and_goals(path[0], path[1:], 6))
    times["path spline"] = time.perf_counter() - start
    start = time.perf_counter()
    optimal, trajectory = time_optimal_along_path(spline, optimum.VELOCITY, optimum.ACCELERATION,
                                                  grid_points=units.TOPPRA_GRID_POINTS)
    times["Toppra solve"] = time.perf_counter() - start
    start = time.perf_counter()
    law = ToppraLaw(trajectory)
    times["law table"] = time.perf_counter() - start
    times["T* [s]"], times["law duration [s]"] = optimal, law.duration
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    path = paper_path()
    config = ToppraConfig(path=path[1:].tolist(), grid_points=units.TOPPRA_GRID_POINTS)
    runs = [stages(path) for _ in range(args.repeats)]
    planning = []
    for _ in range(args.repeats):
        start = time.perf_counter()
        make_planner(config, UR10E, path[0])
        planning.append(time.perf_counter() - start)
    loops = [simulate(make_planner(config, UR10E, path[0]), name="toppra", settle_time=units.SETTLE_TIME)
             for _ in range(args.repeats)]
    print(f"| quantity | median of {args.repeats} |")
    print("|---|---|")
    print(f"| planning (make_planner) [s] | {statistics.median(planning):.3f} (target < {PLANNING_TARGET_S}) |")
    for key in runs[0]:
        print(f"| {key} | {statistics.median(run[key] for run in runs):.4f} |")
    print(f"| closed-loop T [s] | {statistics.median(result.duration for result in loops):.4f} |")
    print(f"| closed-loop real-time factor | "
          f"{statistics.median(result.metrics().real_time_factor for result in loops):.2f} |")


if __name__ == "__main__":
    main()
