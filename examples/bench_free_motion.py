"""The free-motion planner on seeded cells: a shelf with cubbies, a gate of posts, bins.

Each scene is drawn from the seed (the UR10e on its table; the scene's pieces placed at a random
yaw and distance); queries are collision-free start and goal configurations (inside the joint
ranges, every pair of bodies at least the clearance apart) whose straight joint segment is not
valid. Per query: the planner's planning time (find + shorten + smooth + time + check), the joint
path length, the motion time, Drake's Toppra on the same smoothed path (its time and its planning
time: ratios), and with ``--optimal S`` the same smoothing on the best path an asymptotically
optimal planner (AORRTC, S seconds) finds. With ``--run`` each motion also runs in the closed
loop, its measured motion checked for contact by an independent Drake query
(``SceneGraphCollisionChecker``) at every logged sample.

    python examples/bench_free_motion.py --queries 10 --seed 0
    python examples/bench_free_motion.py --queries 5 --optimal 10 --run
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from tqdm import tqdm

from drake_traj import FreeMotionConfig, get_robot, simulate
from drake_traj.cell import Box, Cell, CellChecker, Cylinder
from drake_traj.errors import PlanningError
from drake_traj.planners import make_planner
from drake_traj.planners.baselines.toppra import time_optimal_along_path
from drake_traj.planners.free import Scene

UR10E = get_robot("ur10e")


def _placed(rng, radius_range):
    yaw = rng.uniform(-np.pi, np.pi)
    radius = rng.uniform(*radius_range)
    return yaw, radius * np.cos(yaw), radius * np.sin(yaw)


def shelf(rng) -> list:
    """A shelf of 2 x 3 cubbies (0.3 m wide, 0.3 m tall, 0.35 m deep) facing the robot."""
    yaw, x, y = _placed(rng, (0.75, 0.95))
    c, s = np.cos(yaw), np.sin(yaw)
    pieces = []
    for k, z in enumerate((0.25, 0.55, 0.85, 1.15)):
        pieces.append(Box(name=f"board_{k}", size=[0.35, 0.92, 0.02], xyz=[x, y, z], rpy=[0, 0, yaw]))
    for k, offset in enumerate((-0.46, -0.15, 0.15, 0.46)):
        pieces.append(Box(name=f"divider_{k}", size=[0.35, 0.02, 0.9], xyz=[x - s * offset, y + c * offset, 0.7],
                          rpy=[0, 0, yaw]))
    back = 0.19
    pieces.append(Box(name="back", size=[0.02, 0.92, 0.9], xyz=[x + c * back, y + s * back, 0.7], rpy=[0, 0, yaw]))
    return pieces


def gate(rng) -> list:
    """Six posts 1.4 m tall in a ring round the robot, gaps of 0.3-0.5 m between them."""
    start = rng.uniform(0, 2 * np.pi)
    radius = rng.uniform(0.65, 0.9)
    return [Cylinder(name=f"post_{k}", radius=0.04, length=1.4,
                     xyz=[radius * np.cos(start + k * np.pi / 3), radius * np.sin(start + k * np.pi / 3), 0.7])
            for k in range(6)]


def bins(rng) -> list:
    """Two open bins (0.4 x 0.3 x 0.25 m, 1 cm walls) on the table, on two sides of the robot."""
    pieces = []
    for k in range(2):
        yaw, x, y = _placed(rng, (0.55, 0.85))
        c, s = np.cos(yaw), np.sin(yaw)
        for name, (dx, dy), size in (("near", (-0.15, 0), [0.01, 0.4, 0.25]), ("far", (0.15, 0), [0.01, 0.4, 0.25]),
                                     ("left", (0, 0.2), [0.3, 0.01, 0.25]), ("right", (0, -0.2), [0.3, 0.01, 0.25])):
            pieces.append(Box(name=f"bin{k}_{name}", size=size, xyz=[x + c * dx - s * dy, y + s * dx + c * dy, 0.125],
                              rpy=[0, 0, yaw]))
    return pieces


SCENES = {"shelf": shelf, "gate": gate, "bins": bins}


def queries(scene: Scene, rng, count: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """``count`` (start, goal) pairs: both valid, their straight segment not."""
    def valid_configuration():
        while True:
            q = rng.uniform(-np.pi, np.pi, 6)
            q[1] = rng.uniform(-np.pi, 0.0)  # the upper arm above the table's plane
            if scene.valid(q):
                return q

    pairs = []
    while len(pairs) < count:
        start, goal = valid_configuration(), valid_configuration()
        if not scene.segment_valid(start, goal):
            pairs.append((start, goal))
    return pairs


def path_length(vertices) -> float:
    return float(np.linalg.norm(np.diff(vertices, axis=0), axis=1).sum())


def independent_contacts(cell: Cell, result) -> int:
    """Logged measured configurations in contact by Drake's SceneGraphCollisionChecker (its own
    plant of the robot and the cell, no padding)."""
    from pydrake.planning import RobotDiagramBuilder, SceneGraphCollisionChecker
    from drake_traj.cell import add_cell
    builder = RobotDiagramBuilder(0.0)
    instance = UR10E.add_to_plant(builder.plant())
    add_cell(builder.plant(), cell, instance)
    checker = SceneGraphCollisionChecker(model=builder.Build(), robot_model_instances=[instance], edge_step_size=0.01,
                                         env_collision_padding=0.0, self_collision_padding=0.0)
    return int(sum(not checker.CheckConfigCollisionFree(q) for q in result.q_meas))


def toppra_duration(path, velocity, acceleration) -> float:
    """Drake's Toppra on ``path``: its default grid, or where its reachability analysis fails
    there, 2000 points evenly spaced in s (NaN where that fails too)."""
    for grid in (None, np.linspace(path.start_time(), path.end_time(), 2000)):
        try:
            return time_optimal_along_path(path, velocity, acceleration, grid_points=grid)[0]
        except ValueError:
            continue
    return float("nan")


def run(scene_names, count: int, seed: int, optimal: float, closed_loop: bool) -> dict:
    rows = []
    rng = np.random.default_rng(seed)
    work = []
    for name in scene_names:
        cell = Cell(obstacles=SCENES[name](rng))
        checker = CellChecker(UR10E, cell)
        scene = Scene(checker, UR10E.lower_limits, UR10E.upper_limits)
        work += [(name, cell, checker, start, goal) for start, goal in queries(scene, rng, count)]
    for k, (name, cell, checker, start, goal) in enumerate(tqdm(work, desc="queries", unit="query")):
        row = {"scene": name, "query": k}
        planner = make_planner(FreeMotionConfig(goals=[goal.tolist()], seed=k), UR10E, start)
        try:
            checker.check_planner(planner)
        except PlanningError as error:
            row |= {"solved": False, "reason": str(error)[:120]}
            rows.append(row)
            continue
        leg = planner.legs[0]
        began = time.perf_counter()
        toppra_time = toppra_duration(leg.timing.path, planner.velocity, planner.acceleration)
        toppra_seconds = time.perf_counter() - began
        row |= {"solved": True, "planning_s": planner.planning_time_s, "search_s": leg.search_seconds,
                "length_rad": path_length(leg.vertices), "found_length_rad": path_length(leg.found),
                "T_s": planner.planned_duration(), "T_over_toppra": planner.planned_duration() / toppra_time,
                "planning_over_toppra": planner.planning_time_s / toppra_seconds, "density": leg.density}
        if optimal:
            best = make_planner(FreeMotionConfig(goals=[goal.tolist()], seed=k, planner="aorrtc",
                                                 planning_time=optimal), UR10E, start)
            try:
                checker.check_planner(best)
                row["T_over_best"] = planner.planned_duration() / best.planned_duration()
            except PlanningError:
                row["T_over_best"] = float("nan")
        if closed_loop:
            result = simulate(planner, cell=cell)
            row |= {"ran": result.succeeded, "contacts": independent_contacts(cell, result)}
        rows.append(row)
    return rows


def summary(rows) -> None:
    solved = [row for row in rows if row["solved"]]
    print(f"\nsolved {len(solved)} of {len(rows)}")
    for row in rows:
        if not row["solved"]:
            print(f"  not solved: {row['scene']} query {row['query']}: {row['reason']}")
    print("\n| scene | solved | planning [s] median / p90 / worst | T / T_toppra median / worst | planning / Toppra's "
          "median | path [rad] median | T / T_best median / worst | closed loop: ran, contacts |")
    print("|---|---|---|---|---|---|---|---|")
    for scene in sorted({row["scene"] for row in rows}) + ["all"]:
        mine = [row for row in rows if scene in ("all", row["scene"])]
        good = [row for row in mine if row["solved"]]
        if not good:
            continue

        def column(key):
            return np.array([row[key] for row in good if key in row], dtype=float)

        planning, ratio, cost, length = column("planning_s"), column("T_over_toppra"), column("planning_over_toppra"), \
            column("length_rad")
        best = column("T_over_best")
        best_text = f"{np.nanmedian(best):.3f} / {np.nanmax(best):.3f}" if len(best) else "-"
        ran = [row for row in good if "ran" in row]
        loop = f"{sum(row['ran'] for row in ran)} / {len(ran)}, {sum(row['contacts'] for row in ran)}" if ran else "-"
        print(f"| {scene} | {len(good)} / {len(mine)} | {np.median(planning):.3f} / {np.percentile(planning, 90):.3f} / "
              f"{planning.max():.3f} | {np.nanmedian(ratio):.3f} / {np.nanmax(ratio):.3f} | {np.nanmedian(cost):.2f} | "
              f"{np.median(length):.2f} | {best_text} | {loop} |")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--queries", type=int, default=10, help="queries per scene")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--scenes", nargs="+", default=sorted(SCENES), choices=sorted(SCENES))
    parser.add_argument("--optimal", type=float, default=0.0, help="seconds of AORRTC for the best path (0: none)")
    parser.add_argument("--run", action="store_true", help="run every motion in the closed loop")
    arguments = parser.parse_args(argv)
    summary(run(arguments.scenes, arguments.queries, arguments.seed, arguments.optimal, arguments.run))


if __name__ == "__main__":
    main()
