"""Benchmark: the cell check before the motion, what a scene costs the closed loop, and what the
check finds on seeded random tasks.

    python examples/bench_cell.py [--tasks 40] [--repeats 3] [--part all|cost|scene|tasks]

1. The check's cost (``CellChecker.check_planner``: the start, the joint ranges, the sampled
   configurations) per 5 s of planned motion, beside the planning itself (the planner's
   preflight and ``plan()``) and as a fraction of the closed-loop run that follows it (wall
   times measured in turn), on the shipped UR10e scenarios, median of ``--repeats``.
2. The closed loop with 10 obstacles (boxes and cylinders around the table's edge, clear of the
   arm) against the default cell, on ``quintic_ptp``: wall-time ratio of runs made in turn.
3. Seeded random Pająk 2024 tasks (a joint-space walk of 1-4 waypoints from the paper's q(0), up
   to 0.7 and 1.0 rad per joint per waypoint, the UR joint-move limits): how many the check
   refuses and why; every task it accepts is simulated and checked collision-free at every logged
   sample by Drake's own ``SceneGraphCollisionChecker`` on the measured configuration.

Prints Markdown tables. A benchmark, not a test: times depend on the machine.
"""

import argparse
import statistics
import time
from collections import Counter

import numpy as np
from pydrake.planning import RobotDiagramBuilder, SceneGraphCollisionChecker

from drake_traj import load_scenario, make_planner, simulate
from drake_traj.cell import Box, Cell, CellChecker, CollisionError, Cylinder, JointRangeError, add_cell
from drake_traj.errors import PlanningError
from drake_traj.planners import pajak
from drake_traj.robots import UR10E, ur10e as robot

UR10E_SCENARIOS = ("pajak_sim3", "quintic_ptp", "boryga_loop_ur10e", "li_closed_path_ur10e", "fixture_cell")


def check_cost(repeats: int) -> None:
    print("| scenario | motion [s] | samples | check [s] | per 5 s of motion [s] | preflight + plan [s] | "
          "check / closed-loop run |")
    print("|---|---|---|---|---|---|---|")
    for name in UR10E_SCENARIOS:
        scenario = load_scenario(name)
        checker = scenario.cell_checker()
        checks, plans, ratios = [], [], []
        for _ in range(repeats):
            planner = make_planner(scenario)
            start = time.perf_counter()
            planner.preflight()
            planner.plan()
            plans.append(time.perf_counter() - start)
            start = time.perf_counter()
            result = checker.check_planner(planner)
            checks.append(time.perf_counter() - start)
            run = simulate(scenario, preflight=False)
            assert run.succeeded, run.failure
            ratios.append(checks[-1] / run.wall_time)
        duration = planner.plan().end_time()
        check = statistics.median(checks)
        print(f"| {name} | {duration:.2f} | {len(result.times)} | {check:.3f} | {check / duration * 5:.3f} | "
              f"{statistics.median(plans):.3f} | {statistics.median(ratios):.3f} |")


def ten_obstacles() -> list:
    """Five boxes and five cylinders on the table's edge, 1.25-1.35 m from the base."""
    angles = np.linspace(0.0, 2 * np.pi, 10, endpoint=False)
    shapes = []
    for k, angle in enumerate(angles):
        xyz = [1.3 * np.cos(angle), 1.3 * np.sin(angle), 0.15]
        shapes.append(Box(name=f"box_{k}", size=[0.1, 0.1, 0.3], xyz=xyz) if k % 2 else
                      Cylinder(name=f"cylinder_{k}", radius=0.05, length=0.3, xyz=xyz))
    return shapes


def scene_cost(repeats: int) -> None:
    scenario = load_scenario("quintic_ptp")
    cells = {"default": Cell(), "10 obstacles": Cell(obstacles=ten_obstacles())}
    times = {label: [] for label in cells}
    for _ in range(repeats):
        for label, cell in cells.items():
            result = simulate(scenario, cell=cell)
            assert result.succeeded, result.failure
            times[label].append(result.wall_time)
    ratios = [scene / plain for scene, plain in zip(times["10 obstacles"], times["default"])]
    print(f"\nquintic_ptp, wall time with 10 obstacles / default cell: median {statistics.median(ratios):.3f} "
          f"(runs: {', '.join(f'{ratio:.3f}' for ratio in ratios)})")


def random_task(rng, step: float) -> pajak.PajakConfig:
    configurations = [pajak.paper_initial_configuration()]
    for _ in range(int(rng.integers(1, 5))):
        configurations.append(configurations[-1] + rng.uniform(-step, step, 6))
    return pajak.PajakConfig(waypoints=np.array([robot.task_pose(q) for q in configurations[1:]]))


def independent_checker():
    builder = RobotDiagramBuilder(time_step=0.0)
    instance = UR10E.add_to_plant(builder.plant())
    add_cell(builder.plant(), Cell(), instance)
    return SceneGraphCollisionChecker(model=builder.Build(), robot_model_instances=[instance], edge_step_size=0.01,
                                      env_collision_padding=0.0, self_collision_padding=0.0)


def random_tasks(count: int) -> None:
    checker, independent = CellChecker(UR10E), independent_checker()
    print("\n| step [rad] | tasks | refused: table | refused: self | refused: joint range | not plannable | ran | "
          "runs in contact (independent check) | check per 5 s: median / p90 / worst [s] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for step, seed in ((0.7, 21), (1.0, 22)):
        rng = np.random.default_rng(seed)
        outcome, in_contact, costs = Counter(), 0, []
        tasks = 0
        while tasks < count:
            config = random_task(rng, step)
            try:
                config.validate()
            except ValueError:
                continue
            tasks += 1
            planner = pajak.PajakPlanner(config, pajak.paper_initial_configuration())
            try:
                planner.preflight()
                planner.plan()  # built once and kept: the check below times the check alone
            except PlanningError:
                outcome["not plannable"] += 1
                continue
            start = time.perf_counter()
            try:
                checker.check_planner(planner)
            except CollisionError as error:
                kind = "table" if "table" in error.bodies else "self"
                outcome[f"refused: {kind}"] += 1
                continue
            except JointRangeError:
                outcome["refused: joint range"] += 1
                continue
            finally:
                costs.append((time.perf_counter() - start) / planner.plan().end_time() * 5)
            result = simulate(planner, preflight=False, max_duration=60.0)
            outcome["ran"] += 1
            in_contact += not all(independent.CheckConfigCollisionFree(q) for q in result.q_meas)
        print(f"| {step} | {count} | {outcome['refused: table']} | {outcome['refused: self']} | "
              f"{outcome['refused: joint range']} | {outcome['not plannable']} | {outcome['ran']} | {in_contact} | "
              f"{np.median(costs):.3f} / {np.percentile(costs, 90):.3f} / {max(costs):.3f} |")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", type=int, default=40)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--part", choices=("all", "cost", "scene", "tasks"), default="all")
    args = parser.parse_args(argv)
    if args.part in ("all", "cost"):
        check_cost(args.repeats)
    if args.part in ("all", "scene"):
        scene_cost(args.repeats)
    if args.part in ("all", "tasks"):
        random_tasks(args.tasks)


if __name__ == "__main__":
    main()
