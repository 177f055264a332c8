"""The Pająk law ("ours", every improvement on) on seeded random tasks at two scales.

    python examples/pajak_sweep.py [--count 200] [--seed 9] [--steps 0.7 1.0] [--json out.json]

Tasks: :func:`drake_traj.bench.pajak_walk_tasks` (the set of tests/planners/test_pajak_random.py
at 0.7 rad, seed 9): 1-4 waypoints, each the flange pose of a configuration up to ``step`` rad per
joint from the previous one, random limits. The law runs alone under its own RK4 integrator at
1 ms, 0.5 s past its finish. Its progress (tasks done, time left) goes to stderr; per scale it prints:

- finished tasks, and the failures by cause with the stall's reason;
- the q̈-continuity share of the finished tasks, two ways: strictly, no change of q̈ between 1 ms
  samples (after t = 0, through the finish and 0.5 s past it) exceeds ``STEP`` = 0.1 rad/s² (a
  jerk of 100 rad/s³); and continuous, where a larger change is at most ``LIMIT_STEP`` and
  shrinks below 0.7 of itself when the task is integrated again at 0.5 ms (steep, not a jump: a
  jump keeps its size at any step);
- the largest 1 ms change of q̈ over every finished task (at most 0.5 rad/s²);
- T / T_opt (median, p90, max) over the finished tasks, T_opt Drake's Toppra time-optimal
  duration along the law's own joint path (its log up to the finish) under the task's limits
  (:func:`drake_traj.bench.optimal_duration`); tasks Toppra cannot parameterise are counted.

A benchmark: run it to measure; no assertion here (the tests assert a small seeded set).
"""

import argparse
import json
import math
import sys

import numpy as np
from tqdm import tqdm

from drake_traj.bench import optimal_duration, pajak_walk_tasks
from drake_traj.planners import pajak as P

STEP = 0.1  # [rad/s²] between 1 ms samples: the largest change of q̈ that counts as continuous
LIMIT_STEP = 0.5  # [rad/s²] in 1 ms: the bound on every finished task
SETTLE = 0.5  # [s] integrated past the finish (the station keeps the law running while the arm settles)
Q0 = P.paper_initial_configuration()


def largest_step(qdd: np.ndarray) -> float:
    """The largest change of q̈ between consecutive samples after t = 0 [rad/s²] (0 for one sample)."""
    return float(np.abs(np.diff(qdd[1:], axis=0)).max()) if len(qdd) > 2 else 0.0


def run(task: P.PajakConfig, **kwargs) -> tuple[dict, P.PlanningError | None]:
    """(the integrated log, the PlanningError it ended with or None)."""
    try:
        return P.integrate(P.PajakLaw(task), Q0, **kwargs), None
    except P.PlanningError as error:
        return error.partial, error


def measure(task: P.PajakConfig) -> dict:
    """One task's figures (see the module docstring)."""
    result, error = run(task, settle_time=SETTLE)
    if error is not None:
        return {"finished": False, "cause": str(error.cause), "message": str(error),
                "step": largest_step(result["qdd"])}
    finish = result["finish_index"]
    end = finish + 1 + round(SETTLE / 1e-3)
    step = largest_step(result["qdd"][:end])
    figures = {"finished": True, "T": result["T"], "step": step, "fine_step": None}
    if step > STEP:  # steep or a jump: a jump keeps its size at half the step
        fine, _ = run(task, dt=5e-4, t_max=result["T"] + SETTLE, raise_on_timeout=False)
        figures["fine_step"] = largest_step(fine["qdd"])
    optimal, reason = optimal_duration(result["q"][: finish + 1], result["qd"][: finish + 1],
                                       task.velocity_limit, task.acceleration_limit)
    figures |= {"T_opt": optimal, "T_opt_failure": reason}
    return figures


def summary(step: float, figures: list[dict]) -> str:
    finished = [f for f in figures if f["finished"]]
    failed = [f for f in figures if not f["finished"]]
    causes = {}
    for f in failed:
        causes[f["cause"]] = causes.get(f["cause"], 0) + 1
    continuous = sum(f["step"] <= STEP for f in finished)
    steep = [f for f in finished if f["step"] > STEP]
    halves = sum(f["fine_step"] < 0.7 * f["step"] for f in steep)
    smooth = continuous + sum(f["fine_step"] < 0.7 * f["step"] and f["step"] <= LIMIT_STEP for f in steep)
    ratios = np.array([f["T"] / f["T_opt"] for f in finished if math.isfinite(f["T_opt"])])
    no_optimum = sum(not math.isfinite(f["T_opt"]) for f in finished)
    worst = max((f["step"] for f in finished), default=float("nan"))
    lines = [
        f"## moves of up to {step} rad per joint: {len(figures)} tasks",
        f"- finished: {len(finished)} ({len(finished) / len(figures):.1%}); failures: {causes or 'none'}",
        f"- q̈ continuous (no 1 ms change above {STEP} rad/s²): {continuous} of {len(finished)} finished "
        f"({continuous / max(len(finished), 1):.1%}); of the {len(steep)} others, the largest change shrinks "
        f"below 0.7x at a 0.5 ms step on {halves} (steep, not a jump)",
        f"- q̈ continuous (at most {STEP} rad/s² in 1 ms, or steep, not a jump, and at most {LIMIT_STEP}): "
        f"{smooth} of {len(finished)} finished ({smooth / max(len(finished), 1):.1%})",
        f"- largest 1 ms change of q̈ over the finished tasks: {worst:.3f} rad/s² "
        f"({sum(f['step'] > LIMIT_STEP for f in finished)} above {LIMIT_STEP}); "
        f"median {np.median([f['step'] for f in finished]):.3f}",
        f"- T/T_opt over {len(ratios)} finished tasks: median {np.median(ratios):.3f}, "
        f"p90 {np.percentile(ratios, 90):.3f}, max {ratios.max():.3f}"
        + (f" ({no_optimum} without a Toppra optimum)" if no_optimum else ""),
    ]
    for f in failed:
        lines.append(f"  - {f['cause']}: {f['message']}")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=200, help="tasks per scale")
    parser.add_argument("--seed", type=int, default=9)
    parser.add_argument("--steps", type=float, nargs="+", default=[0.7, 1.0], help="largest move per joint [rad]")
    parser.add_argument("--json", help="write every task's figures here")
    args = parser.parse_args()
    everything = {}
    for step in args.steps:
        tasks = tqdm(pajak_walk_tasks(args.count, args.seed, step), desc=f"moves of up to {step} rad", unit="task",
                     file=sys.stderr)
        figures = [measure(task) for task in tasks]
        everything[str(step)] = figures
        print(summary(step, figures), flush=True)
    if args.json:
        with open(args.json, "w") as handle:
            json.dump(everything, handle, indent=1)


if __name__ == "__main__":
    main()
