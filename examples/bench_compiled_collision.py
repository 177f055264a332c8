"""Benchmark: the compiled collision model (drake_traj.cell.CompiledCollisionModel) against the
free-motion search's SceneGraph queries (drake_traj.planners.free.Scene), and its distances
against SceneGraph's on every shipped arm.

    python examples/bench_compiled_collision.py [--part all|speed|conservative] [--configurations 2000]
        [--edges 60] [--repeats 5] [--count 100000] [--seed 0]

1. Speed, in one process, the UR10e on its table in three cells (open; cluttered: 12 boxes; a
   shelf of 2 x 3 cubbies in front of it), on the same seeded configurations: configurations a
   second of ``Scene.valid`` (one call each) against the model's batch ``valid``, of
   ``Scene.distance`` against the batch ``distances``, and edges a second of
   ``Scene.segment_valid`` against the model's ``segment_valid`` (edges between valid
   configurations, 5 to 50 % of the way to another one), each the median of ``--repeats``;
   the ratios, and how often the two agree.
2. Conservativeness, ``--count`` seeded configurations of each shipped arm (the six UR e-Series
   on their table, the example arm description with its mesh hulls): the model's smallest
   distance against SceneGraph's (``ComputeSignedDistancePairwiseClosestPoints`` within the 0.07 m
   look-ahead, negative distances taken as 0): the most it is above SceneGraph's (over-estimate:
   must stay under 1e-6 m) and below it (under-estimate), and below the true distance, bounded
   from above by the model's witness points (two points of the two shapes) where SceneGraph
   reports the pair farther apart than they are: how often it does.

Prints Markdown tables. A benchmark, not a test: times depend on the machine.
"""

import argparse
import statistics
import time

import numpy as np

from drake_traj import get_robot
from drake_traj.cell import Box, Cell, CellChecker
from drake_traj.data import data_directory
from drake_traj.planners.free import Scene
from drake_traj.robots.chain_arm import ChainArm

LOOK_AHEAD = 0.07  # [m] the search's look-ahead, the model's default
UR_ARMS = ("ur3e", "ur5e", "ur10e", "ur16e", "ur20", "ur30")


def cluttered(rng) -> list:
    """12 boxes (0.1-0.3 m) around the UR10e, 0.5-1.1 m from its base, 0-0.9 m up."""
    boxes = []
    for k in range(12):
        yaw, radius = rng.uniform(-np.pi, np.pi), rng.uniform(0.5, 1.1)
        size = rng.uniform(0.1, 0.3, 3)
        xyz = [radius * np.cos(yaw), radius * np.sin(yaw), rng.uniform(0.0, 0.9) + 0.5 * size[2]]
        boxes.append(Box(name=f"box_{k}", size=size.tolist(), xyz=xyz, rpy=[0.0, 0.0, rng.uniform(-np.pi, np.pi)]))
    return boxes


def shelf() -> list:
    """A shelf of 2 x 3 cubbies (0.3 m wide and tall, 0.35 m deep) 0.8 m in front of the base."""
    boards = [Box(name=f"board_{k}", size=[0.35, 0.92, 0.02], xyz=[0.8, 0.0, z]) for k, z in enumerate((0.25, 0.55, 0.85))]
    dividers = [Box(name=f"divider_{k}", size=[0.35, 0.02, 0.62], xyz=[0.8, y, 0.55])
                for k, y in enumerate((-0.46, -0.15, 0.15, 0.46))]
    return boards + dividers + [Box(name="back", size=[0.02, 0.92, 0.62], xyz=[0.985, 0.0, 0.55])]


def timed(function, repeats: int) -> float:
    """The median wall time [s] of ``repeats`` calls of ``function``."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def edges(scene: Scene, configurations: np.ndarray, count: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """``count`` edges (starts, ends) between valid configurations, each 5-50 % of the way to another."""
    valid = configurations[[scene.valid(q) for q in configurations]]
    starts = valid[rng.integers(0, len(valid), count)]
    others = valid[rng.integers(0, len(valid), count)]
    return starts, starts + rng.uniform(0.05, 0.5, (count, 1)) * (others - starts)


def speed(args) -> None:
    rng = np.random.default_rng(args.seed)
    robot = get_robot("ur10e")
    cells = {"open": Cell(), "cluttered (12 boxes)": Cell(obstacles=cluttered(rng)), "shelf": Cell(obstacles=shelf())}
    print("| cell | pairs | Scene.valid [1/s] | valid [1/s] | ratio | agree | Scene.distance [1/s] | distances [1/s] | "
          "ratio | Scene.segment_valid [edges/s] | segment_valid [edges/s] | ratio | edges agree |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for label, cell in cells.items():
        checker = CellChecker(robot, cell)
        scene, model = Scene(checker, robot.lower_limits, robot.upper_limits), checker.compiled_model()
        q = rng.uniform(robot.lower_limits, robot.upper_limits, (args.configurations, robot.num_joints))
        model.valid(q[:2]), model.distances(q[:2])  # compiled (or loaded from numba's cache) before timing
        theirs = timed(lambda: [scene.valid(row) for row in q], args.repeats)
        ours = timed(lambda: model.valid(q), args.repeats)
        agree = np.mean(model.valid(q) == np.array([scene.valid(row) for row in q]))
        theirs_d = timed(lambda: [scene.distance(row) for row in q], args.repeats)
        ours_d = timed(lambda: model.distances(q), args.repeats)
        starts, ends = edges(scene, q, args.edges, rng)
        model.segment_valid(starts[0], ends[0])
        theirs_e = timed(lambda: [scene.segment_valid(a, b) for a, b in zip(starts, ends)], args.repeats)
        ours_e = timed(lambda: [model.segment_valid(a, b) for a, b in zip(starts, ends)], args.repeats)
        agree_e = np.mean([scene.segment_valid(a, b) == model.segment_valid(a, b) for a, b in zip(starts, ends)])
        n, m = len(q), len(starts)
        print(f"| {label} | {len(model.pairs)} | {n / theirs:,.0f} | {n / ours:,.0f} | {theirs / ours:.0f} | {agree:.3f} | "
              f"{n / theirs_d:,.0f} | {n / ours_d:,.0f} | {theirs_d / ours_d:.0f} | {m / theirs_e:,.1f} | "
              f"{m / ours_e:,.0f} | {theirs_e / ours_e:.0f} | {agree_e:.2f} |")


def example_arm() -> ChainArm:
    description = data_directory("models") / "example_arm_description"
    return ChainArm.from_model_file(description / "urdf" / "example_arm.urdf", base_frame="base", tool_frame="tool0",
                                    name="example_arm", acceleration_limits=1.4)


def conservative(args) -> None:
    print(f"| arm | configurations | over SceneGraph [mm] | under SceneGraph [mm] | under the truth [mm] | "
          "SceneGraph farther than the witness |")
    print("|---|---|---|---|---|---|")
    for robot in [get_robot(name) for name in UR_ARMS] + [example_arm()]:
        checker = CellChecker(robot)
        model = checker.compiled_model()
        q = np.random.default_rng(args.seed).uniform(robot.lower_limits, robot.upper_limits,
                                                     (args.count, robot.num_joints))
        ours = model.distances(q)
        over = under = short = -np.inf
        wrong = 0
        for row, least in zip(q, ours):
            pairs = checker.pose_query(row).ComputeSignedDistancePairwiseClosestPoints(LOOK_AHEAD)
            scene_graph = min(max(min((pair.distance for pair in pairs), default=LOOK_AHEAD), 0.0), LOOK_AHEAD)
            witness = min(max(float(model.pair_bounds(row)[:, 1].min()), 0.0), LOOK_AHEAD)  # two points this far apart
            over, under = max(over, least - scene_graph), max(under, scene_graph - least)
            short = max(short, min(scene_graph, witness) - least)
            wrong += scene_graph > witness + 1e-6
        print(f"| {robot.name} | {args.count:,} | {over * 1e3:+.6f} | {under * 1e3:.4f} | {short * 1e3:.6f} | "
              f"{wrong:,} ({wrong / args.count:.2%}) |")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--part", choices=("all", "speed", "conservative"), default="all")
    parser.add_argument("--configurations", type=int, default=2000, help="configurations per cell for the speed")
    parser.add_argument("--edges", type=int, default=60, help="edges per cell for the speed")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--count", type=int, default=100_000, help="configurations per arm for the conservativeness")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    if args.part in ("all", "speed"):
        speed(args)
    if args.part in ("all", "conservative"):
        conservative(args)


if __name__ == "__main__":
    main()
