"""The Pająk law ("ours") at several scales of the limits: the paper's simulation 3 and seeded walks.

    python examples/pajak_limit_scales.py [--count 12] [--seed 9] [--scales 0.05 0.2 0.5 1]

Tasks: Pająk 2024's simulation 3 and ``count`` walks of :func:`drake_traj.bench.pajak_walk_tasks`
(steps up to 0.7 rad per joint), each with every joint's limits set to ``scale`` times the UR10e's
joint-move limits (1.05 rad/s, 1.40 rad/s²). The law runs alone under its RK4 integrator at 1 ms.
Per task: T [s] or the failure, the largest |q̇| and |q̈| relative to the limits, and the largest
change of q̈ between 1 ms samples after t = 0 [rad/s²]. A benchmark: no assertion here
(tests/planners/test_pajak_law.py asserts simulation 3 at the scale 0.05).
"""

import argparse
from dataclasses import replace

import numpy as np

from drake_traj.bench import pajak_walk_tasks
from drake_traj.planners import pajak as P
from drake_traj.robots import ur10e as robot


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=12, help="walks per scale")
    parser.add_argument("--seed", type=int, default=9)
    parser.add_argument("--scales", type=float, nargs="+", default=[0.05, 0.2, 0.5, 1.0],
                        help="limits as a multiple of the joint-move limits")
    args = parser.parse_args()
    tasks = [("sim3", P.paper_parameters(3))] + [
        (f"walk {k}", task) for k, task in enumerate(pajak_walk_tasks(args.count, args.seed, 0.7))]
    q0 = P.paper_initial_configuration()
    for scale in args.scales:
        velocity, acceleration = scale * robot.DEFAULT_JOINT_MOVE_VELOCITY, scale * robot.DEFAULT_JOINT_MOVE_ACCELERATION
        finished = 0
        print(f"## limits {velocity:.4g} rad/s, {acceleration:.4g} rad/s² (scale {scale})")
        for name, task in tasks:
            task = replace(task, velocity_limit=np.full(6, velocity), acceleration_limit=np.full(6, acceleration))
            try:
                result = P.integrate(P.PajakLaw(task), q0, t_max=600.0)
            except P.PlanningError as error:
                print(f"- {name}: {error.cause}: {error}")
                continue
            finished += 1
            step = np.abs(np.diff(result["qdd"][1:], axis=0)).max()
            print(f"- {name}: T {result['T']:.3f} s, max |q̇|/limit {np.abs(result['qd']).max() / velocity:.3f}, "
                  f"max |q̈|/limit {np.abs(result['qdd']).max() / acceleration:.3f}, largest 1 ms change of q̈ "
                  f"{step:.3f} rad/s²")
        print(f"finished {finished} of {len(tasks)}", flush=True)


if __name__ == "__main__":
    main()
