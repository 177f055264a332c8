"""Benchmark: the compiled Pająk 2024 law on the UR10e's closed form against the same arm as a
generic serial chain (its standard DH table, ``drake_traj.robots.chain``), in one process.

    python examples/bench_generic_kinematics.py [--repeats 7]

The task is the Pająk simulation 3 (``diagrams/pajak.yaml``, variant sim3) from the UR10e's home
configuration. Three measurements, each as the median of ``--repeats`` runs, the two arms run
one after the other within each repeat:

1. the kinematics alone: k(q), J, J̇q̇ and the singularity measure at 20000 random states, in a
   compiled loop (``compiled_kinematics.kinematics_many`` on each arm's model), per call;
2. the law: ``evaluate_kernel`` (q̈ and c, what the simulation calls every step) from Python at
   the states of the closed form's own motion (one every 10 ms), per call;
3. the law integrated: the compiled ``integrate_kernel`` of the whole task (RK4 at 1 ms, four
   evaluations a step), per step;
4. the reach check before a run (``PajakLaw.reach_failure``: every IK solution of the four
   waypoints; closed form against the chain's numerical IK), per waypoint;
5. point IK as Boryga's loop law calls it (``point_ik`` of a whole path in one call, the
   reference's orientation and branch) at 200 points of a smooth path near the home
   configuration: the closed form (compiled over the points) against the chain's IK, each point
   warm-started from the one before, per point.

Prints the times and the ratios chain / closed form (our bound: at most 2 for the law),
and the two motions' finish times. A benchmark, not a test: numbers depend on the machine.
"""

import argparse
import statistics
import time

import numpy as np

from drake_traj.data import data_directory
from drake_traj.planners.pajak import PajakLaw
from drake_traj.planners.pajak.integration import integrate
from drake_traj.planners.pajak.kernel import Discrete, Evaluation, Log, evaluate_kernel
from drake_traj.planners.pajak.stepping import integrate_kernel
from drake_traj.robots import chain, ur10e
from drake_traj.robots.compiled_kinematics import kinematics_many
from drake_traj.robots.chain_arm import ChainArm
from drake_traj.scenario import load_scenario

UR_DH = np.column_stack([ur10e.DH_D, ur10e.DH_A, ur10e.DH_ALPHA, np.zeros(6)])


def kinematics_seconds(kernel, model, q, qd) -> float:
    """Wall time per call [s] of the compiled loop ``kernel`` over the states (q, qd)."""
    count = len(q)
    out = (np.empty((count, 6)), np.empty((count, 6, 6)), np.empty((count, 6)), np.empty(count), np.empty(count))
    start = time.perf_counter()
    kernel(model, q, qd, ur10e.FLANGE, *out)
    return (time.perf_counter() - start) / count


def law_seconds(law: PajakLaw, states) -> float:
    """Wall time per ``evaluate_kernel`` call [s] at ``states`` (t, q, q̇, discrete)."""
    out = np.zeros_like(law._out)
    start = time.perf_counter()
    for t, q, qd, discrete in states:
        evaluate_kernel(t, q, qd, discrete, law.vector, law.model, law.tool, law.waypoints, out)
    return (time.perf_counter() - start) / len(states)


def integrate_seconds(law: PajakLaw, q0, t_max: float = 30.0, dt: float = 1e-3):
    """(wall time per RK4 step [s], finish time T [s]) of the whole task in the compiled loop
    (the arguments :func:`~drake_traj.planners.pajak.integration.integrate` passes it)."""
    steps = int(round(t_max / dt))
    log, peak = np.empty((steps + 1, Log.SIZE)), np.zeros((2, 6))
    out, final = np.zeros(Evaluation.SIZE), np.zeros(12 + Discrete.SIZE)
    start = time.perf_counter()
    count, _, finish = integrate_kernel(q0, law.initial_discrete(), dt, steps, 0, law.vector, law.model, law.tool,
                                        law.waypoints, law.remaining, log, peak, out, final)
    return (time.perf_counter() - start) / count, float(log[finish, Log.T])


def reach_seconds(law: PajakLaw, q0) -> float:
    """Wall time per waypoint [s] of the reach check (every IK solution of each waypoint)."""
    start = time.perf_counter()
    assert law.reach_failure(q0) is None
    return (time.perf_counter() - start) / len(law.waypoints)


def point_ik_seconds(robot, points, reference) -> float:
    """Wall time per point [s] of ``robot.point_ik`` of all ``points`` in one call."""
    start = time.perf_counter()
    robot.point_ik(points, reference)
    return (time.perf_counter() - start) / len(points)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    config = load_scenario(data_directory("diagrams") / "pajak.yaml", "sim3").planner
    arm = ChainArm.from_dh("ur10e_dh", UR_DH, model_file=ur10e.model_path(), acceleration_limits=1.4, home=ur10e.HOME)
    closed_law, chain_law = PajakLaw(config, ur10e.UR10E), PajakLaw(config, arm)
    q0 = np.array(ur10e.HOME)
    motion = integrate(closed_law, q0)
    states = [(float(t), np.ascontiguousarray(q), np.ascontiguousarray(qd), np.ascontiguousarray(d))
              for t, q, qd, d in zip(motion["t"], motion["q"], motion["qd"], motion["discrete"])][::10]
    rng = np.random.default_rng(0)
    q, qd = rng.uniform(-np.pi, np.pi, (20000, 6)), rng.uniform(-1.0, 1.0, (20000, 6))
    # warm up (compilation or the numba cache)
    kinematics_seconds(kinematics_many, ur10e.MODEL, q[:10], qd[:10])
    kinematics_seconds(kinematics_many, arm.model, q[:10], qd[:10])
    law_seconds(closed_law, states[:5])
    law_seconds(chain_law, states[:5])
    path = ur10e.task_pose(q0)[:3] + np.cumsum(rng.normal(scale=4e-4, size=(200, 3)), axis=0)  # 2 ms of 0.2 m/s
    point_ik_seconds(arm, path[:2], q0)
    times = {key: ([], []) for key in ("kinematics", "law", "integrate", "reach check", "point IK")}
    finish = []
    for _ in range(args.repeats):
        times["kinematics"][0].append(kinematics_seconds(kinematics_many, ur10e.MODEL, q, qd))
        times["kinematics"][1].append(kinematics_seconds(kinematics_many, arm.model, q, qd))
        times["law"][0].append(law_seconds(closed_law, states))
        times["law"][1].append(law_seconds(chain_law, states))
        for k, law in enumerate((closed_law, chain_law)):
            seconds, T = integrate_seconds(law, q0)
            times["integrate"][k].append(seconds)
            finish.append((k, T))
            times["reach check"][k].append(reach_seconds(law, q0))
        times["point IK"][0].append(point_ik_seconds(ur10e.UR10E, path, q0))
        times["point IK"][1].append(point_ik_seconds(arm, path, q0))
    print(f"Pająk 2024 sim 3, {len(states)} law states, {args.repeats} repeats (medians; ratio range)\n")
    print("| measurement | UR closed form [µs] | DH chain [µs] | ratio chain / closed |")
    print("|---|---|---|---|")
    for key, (closed, generic) in times.items():
        ratios = [g / c for c, g in zip(closed, generic)]
        print(f"| {key} | {1e6 * statistics.median(closed):.2f} | {1e6 * statistics.median(generic):.2f} | "
              f"{statistics.median(ratios):.2f} ({min(ratios):.2f}-{max(ratios):.2f}) |")
    closed_T = {T for k, T in finish if k == 0}
    chain_T = {T for k, T in finish if k == 1}
    print(f"\nfinish time T: closed form {sorted(closed_T)} s, chain {sorted(chain_T)} s")


if __name__ == "__main__":
    main()
