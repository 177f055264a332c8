"""The smooth timing (docs/smooth_timing.md) against the bang-bang optimum on the same
path (Drake's Toppra), on seeded random tasks: T / T_opt, planning time and its CPU against
Toppra's, limits and path deviation.

Sets (each at moves of up to 0.7 and 1.0 rad per joint):

- ``waypoints``: the smooth path through 1-4 joint waypoints (``SmoothWaypointsConfig``'s path),
  limits 0.5-1.5 × the UR joint-move limits per joint;
- ``pajak``: the joint path of the Pająk 2024 preflight through the flange poses of the same
  kind of waypoints (``RetimedPajakConfig``'s path), for the tasks the Pająk law finishes;
- ``vertices``: the free-motion planner's kind of path, the spline through 3-8 joint vertices
  (``waypoint_path``), the UR10e's joint-move limits and the default jerk limit
  (``jerk_limited_limits``).

Run: ``python examples/bench_smooth_timing.py [--count 20] [--seed 0] [--repeats 3]``. Prints one
line per set and scale: median, p90 and worst of T / T_opt, of the planning time [s] (wall, and
this process's CPU: the machine may be shared), of the CPU over Drake's Toppra's on the same path
(both timed in this process, each the median of ``--repeats`` runs), of the repair's stretch, the
largest exact peak over each limit and the largest path deviation [rad].
"""

import argparse
import time

import numpy as np

from drake_traj import PajakConfig, get_robot
from drake_traj.errors import DrakeTrajError
from drake_traj.planners.baselines.toppra import time_optimal_along_path
from drake_traj.planners.pajak import paper_initial_configuration
from drake_traj.planners.smooth import pajak_joint_path
from drake_traj.planners.timing import jerk_limited_limits, time_path, waypoint_path
from drake_traj.robots import ur10e

ROBOT = get_robot("ur10e")


def random_task(rng, scale: float):
    """(joint waypoints (m + 1, 6) from the Pająk start, velocity, acceleration limits): 1-4
    waypoints, each up to ``scale`` rad per joint from the previous one, away from singularities
    and inside the joint ranges; limits uniform in [0.5, 1.5] × the UR joint-move limits."""
    velocity, acceleration = ROBOT.joint_move_limits
    while True:
        q = [paper_initial_configuration()]
        for _ in range(rng.integers(1, 5)):
            q.append(q[-1] + rng.uniform(-scale, scale, 6))
        q = np.array(q)
        if all(ur10e.singularity_measure(c) > 0.15 for c in q[1:]) and np.all((q >= ROBOT.lower_limits) & (q <= ROBOT.upper_limits)):
            return q, velocity * rng.uniform(0.5, 1.5, 6), acceleration * rng.uniform(0.5, 1.5, 6)


def vertex_task(rng, scale: float):
    """(joint vertices (m, 6), velocity, acceleration, jerk limits): 3-8 vertices from the UR10e's
    home, each up to ``scale`` rad per joint from the last (as a free-motion search's path), and
    the UR10e's joint-move limits with the default jerk limit [rad/s, rad/s², rad/s³]."""
    q = [ROBOT.home_configuration]
    for _ in range(rng.integers(3, 9) - 1):
        q.append(q[-1] + rng.uniform(-scale, scale, 6))
    return (np.array(q), *jerk_limited_limits(ROBOT, [], [], []))


def timed(call, repeats: int):
    """(``call()``'s result, the median wall and CPU time of this process [s] over ``repeats`` calls)."""
    walls, cpus = [], []
    for _ in range(repeats):
        start, cpu = time.perf_counter(), time.process_time()
        result = call()
        walls.append(time.perf_counter() - start)
        cpus.append(time.process_time() - cpu)
    return result, float(np.median(walls)), float(np.median(cpus))


def measure(path, limits, grid_points, iterations, repeats):
    """(T / T_opt, planning wall time [s], peaks over the limits (3,), path deviation [rad], planning
    CPU time of this process [s], the repair's stretch, CPU over Toppra's) of one path (``limits``:
    velocity, acceleration and jerk, None for the default); None where Drake's Toppra finds no
    T_opt on its default grid nor on 500 or 2000 points evenly spaced in s."""
    velocity, acceleration, jerk = limits
    timing, planning, cpu = timed(lambda: time_path(path, velocity, acceleration, jerk, grid_points=grid_points,
                                                    iterations=iterations), repeats)
    for grid in (None, 500, 2000):  # Drake's Toppra fails now and then on a grid of a path with tight turns
        try:
            optimal, _, toppra = timed(lambda: time_optimal_along_path(timing.path, velocity, acceleration,
                                                                       grid_points=grid)[0], repeats)
            break
        except ValueError:
            continue
    else:
        return None  # no T_opt to compare with: counted, not summarised
    return (timing.duration / optimal, planning, timing.peaks.max(axis=1), timing.deviation, cpu, timing.stretch,
            cpu / toppra)


def summary(name, rows):
    unmeasured = sum(r is None for r in rows)
    rows = [r for r in rows if r is not None]
    ratio, planning = np.array([r[0] for r in rows]), np.array([r[1] for r in rows])
    peaks, deviation = np.array([r[2] for r in rows]), max(r[3] for r in rows)
    cpu, stretch, toppra = np.array([r[4] for r in rows]), np.array([r[5] for r in rows]), np.array([r[6] for r in rows])
    quantiles = lambda v: f"{np.median(v):.3f} / {np.percentile(v, 90):.3f} / {v.max():.3f}"  # noqa: E731
    print(f"{name:<18} n={len(rows):<3} T/T_opt {quantiles(ratio)}  planning wall [s] {quantiles(planning)}  "
          f"CPU [s] {quantiles(cpu)}  CPU/Toppra's {quantiles(toppra)}  stretch {quantiles(stretch)}  "
          f"peak/limit v {peaks[:, 0].max():.4f} a {peaks[:, 1].max():.4f} j {peaks[:, 2].max():.4f}  "
          f"deviation {deviation:.1e} rad" + (f"  ({unmeasured} without T_opt: Toppra failed)" if unmeasured else ""))


def pajak_rows(tasks, grid_points, iterations, repeats):
    """The rows of the Pająk set and how many tasks the Pająk law did not finish."""
    rows, refused = [], 0
    for q, v, a in tasks:
        poses = np.array([ur10e.task_pose(c) for c in q[1:]])
        config = PajakConfig(waypoints=poses, velocity_limit=v, acceleration_limit=a)
        try:
            samples = pajak_joint_path(config, ROBOT, q[0])
        except DrakeTrajError:
            refused += 1  # the Pająk law does not finish this task: no path to re-time
            continue
        rows.append(measure(samples, (v, a, None), grid_points, iterations, repeats))
    return rows, refused


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--sets", nargs="+", default=["waypoints", "pajak", "vertices"])
    parser.add_argument("--grid-points", type=int, default=250)
    parser.add_argument("--iterations", type=int, default=8)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    warm_up = waypoint_path(np.linspace(np.zeros(6), np.ones(6), 3))
    time_path(warm_up, 1.0, 1.0)  # imports, first calls
    time_optimal_along_path(warm_up, 1.0, 1.0)
    timing = (args.grid_points, args.iterations, args.repeats)
    for scale in (0.7, 1.0):
        rng = np.random.default_rng([args.seed, int(scale * 10)])
        tasks = [random_task(rng, scale) for _ in range(args.count)]
        if "waypoints" in args.sets:
            summary(f"waypoints {scale} rad", [measure(waypoint_path(q), (v, a, None), *timing) for q, v, a in tasks])
        if "pajak" in args.sets:
            rows, refused = pajak_rows(tasks, *timing)
            summary(f"pajak {scale} rad", rows)
            print(f"{'':<22} ({refused} of {len(tasks)} tasks not finished by the Pająk law)")
        if "vertices" in args.sets:
            rng = np.random.default_rng([args.seed, int(scale * 10), 1])
            vertices = [vertex_task(rng, scale) for _ in range(args.count)]
            summary(f"vertices {scale} rad", [measure(waypoint_path(q), limits, *timing) for q, *limits in vertices])


if __name__ == "__main__":
    main()
