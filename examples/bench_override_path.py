"""How far the measured TCP strays from the checked plan under speed overrides, per planner.

Seeded random tasks (drake_traj.bench.random_tasks: three waypoints 0.6 rad per joint apart from
Pająk 2024's q(0), each inside the default cell) at two scales (the moves as drawn, and halved),
each planner made for the task, checked in the default cell, then run in the closed loop under
a random override profile: a constant slider (5-100 %) or a light curtain (25 % for 0.3-1.5 s
from a random time). For every run: the largest distance of the measured TCP from the planned
TCP path (the plan sampled every 0.05 ms), and the nearest approach of the measured motion to
anything (Drake's signed distances on every logged sample, the cell check's scene). Prints
median / p90 / worst per planner and scale.

    python examples/bench_override_path.py --count 10 --seed 3
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy.spatial import cKDTree

from drake_traj import PajakConfig, QuinticConfig, RuckigConfig, SmoothWaypointsConfig, get_robot, simulate
from drake_traj.bench.task_sets import joint_waypoints, random_tasks
from drake_traj.cell import CellChecker
from drake_traj.errors import PlanningError
from drake_traj.planners import make_planner
from drake_traj.scenario import SpeedOverride

UR10E = get_robot("ur10e")
CONFIGS = {
    "pajak": lambda poses, joints: PajakConfig(waypoints=poses.tolist()),
    "quintic": lambda poses, joints: QuinticConfig(goals=joints[1:].tolist()),
    "ruckig": lambda poses, joints: RuckigConfig(goals=joints[1:].tolist()),
    "smooth_waypoints": lambda poses, joints: SmoothWaypointsConfig(goals=joints[1:].tolist()),
}


def profile(rng):
    if rng.uniform() < 0.5:
        return float(rng.uniform(0.05, 1.0))
    start = float(rng.uniform(0.2, 2.0))
    return SpeedOverride([start, start + float(rng.uniform(0.3, 1.5))], [0.25, 1.0])


def stray(result, plan) -> float:
    grid = np.linspace(0.0, plan.end_time(), int(plan.end_time() / 5e-5) + 2)
    planned = UR10E.tool_position(plan.vector_values(grid).T)
    return float(cKDTree(planned).query(result.tcp[:, :3])[0].max())


def nearest(checker, result) -> float:
    return min((checker.contacts(q, within=0.05) or [type("far", (), {"distance": 0.05})])[0].distance
               for q in result.q_meas)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=10)
    parser.add_argument("--seed", type=int, default=3)
    arguments = parser.parse_args(argv)
    checker = CellChecker(UR10E)
    rng = np.random.default_rng(arguments.seed)
    print("| scale | planner | runs | refused | TCP off the plan [mm] median / p90 / worst | nearest approach [mm] worst |")
    print("|---|---|---|---|---|---|")
    for scale in (1.0, 0.5):
        rows = {name: ([], [], 0) for name in CONFIGS}
        for q0, poses in random_tasks(arguments.count, seed=arguments.seed):
            joints = joint_waypoints(q0, poses)
            joints = q0 + scale * (joints - q0)
            poses = np.array([UR10E.task_pose(q) for q in joints[1:]])
            for name, build in CONFIGS.items():
                strays, approaches, refused = rows[name]
                try:
                    planner = make_planner(build(poses, joints), UR10E, q0)
                    result = simulate(planner, speed_override=profile(rng), settle_time=0.1, max_duration=200.0)
                except (PlanningError, ValueError):
                    rows[name] = (strays, approaches, refused + 1)
                    continue
                assert result.succeeded, result.failure
                strays.append(stray(result, planner.plan()))
                approaches.append(nearest(checker, result))
        for name, (strays, approaches, refused) in rows.items():
            s = np.array(strays) * 1000
            print(f"| {scale:g} | {name} | {len(s)} | {refused} | {np.median(s):.3f} / {np.percentile(s, 90):.3f} / "
                  f"{s.max():.3f} | {min(approaches) * 1000:.1f} |")


if __name__ == "__main__":
    main()
