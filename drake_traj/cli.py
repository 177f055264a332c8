"""``drake-traj``: run scenarios from the command line.

    drake-traj run [SCENARIO.yaml] [--variant NAME] [--out DIR] [--meshcat]
    drake-traj bench [--out DIR] [--count N] [--seed S] [--repeats R]

``run`` writes DIR/result.npz, DIR/metrics.json, DIR/*.png and DIR/meshcat.html; ``bench`` runs
every planner and baseline on Pająk 2024's task and N seeded tasks and writes DIR/bench.csv,
DIR/bench.md and DIR/bench.png.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from pydrake.geometry import Meshcat

from drake_traj.bench import BenchSetupError, bench
from drake_traj.diagram import simulate
from drake_traj.meshcat import draw_task, export_html
from drake_traj.robots import get_robot
from drake_traj.scenario import DEFAULT_SCENARIO, default_scenario_path, load_scenario, make_planner


def run(scenario_path, out_dir, *, variant: str | None = None, live_meshcat: bool = False) -> int:
    """Simulate one scenario and write its outputs; returns the process exit code."""
    scenario = load_scenario(scenario_path, variant)
    out_dir = Path(out_dir) if out_dir else Path("out") / scenario.name
    meshcat = Meshcat()
    if live_meshcat:
        print(f"Meshcat: {meshcat.web_url()}", flush=True)
    planner = make_planner(scenario)
    result = simulate(
        planner,
        name=scenario.name,
        robot=get_robot(scenario.robot),
        gains=scenario.controller,
        time_step=scenario.time_step,
        log_period=scenario.log_period,
        settle_time=scenario.settle_time,
        max_duration=scenario.max_duration,
        meshcat=meshcat,
        realtime_rate=1.0 if live_meshcat else 0.0,
    )
    result.save(out_dir)
    result.save_figures(out_dir)
    for stem, figure in planner.figures().items():
        figure.savefig(out_dir / f"{stem}.png", dpi=110)
    draw_task(meshcat, result)
    export_html(meshcat, out_dir / "meshcat.html")
    metrics = result.metrics().to_dict()
    print(json.dumps({key: metrics[key] for key in (
        "name", "succeeded", "failure", "duration_s", "max_velocity_over_limit",
        "max_acceleration_over_limit", "tracking_error_joint_max_rad", "tracking_error_tcp_max_m",
        "real_time_factor")}, indent=2))
    print(f"wrote {out_dir}/result.npz, metrics.json, *.png, meshcat.html")
    if live_meshcat:
        input("Meshcat is serving the recording; press Enter to quit. ")
    return 0 if result.succeeded else 1


def run_bench(args) -> int:
    """``drake-traj bench``; exit code 2, with the reason, on an argument, ``--out`` or
    ``--scheduler`` that cannot work (checked before any run)."""
    try:
        bench(args.out, count=args.count, seed=args.seed, repeats=args.repeats, workers=args.workers,
              scheduler=args.scheduler)
    except BenchSetupError as error:
        print(f"drake-traj bench: error: {error}", file=sys.stderr)
        return 2
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="drake-traj", description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    run_parser = commands.add_parser("run", help="simulate a scenario and write its results")
    run_parser.add_argument("scenario", nargs="?", default=None,
                            help=f"scenario YAML (default: {DEFAULT_SCENARIO[0]}, variant {DEFAULT_SCENARIO[1]})")
    run_parser.add_argument("--variant", default=None, help="the variant to run, in a file of several")
    run_parser.add_argument("--out", default=None, help="output directory (default: out/<scenario name>)")
    run_parser.add_argument("--meshcat", action="store_true", help="serve Meshcat live during the run")
    bench_parser = commands.add_parser("bench", help="compare every planner and baseline on UR10e tasks")
    bench_parser.add_argument("--out", default="out/bench", help="output directory (default: out/bench)")
    bench_parser.add_argument("--count", type=int, default=20, help="seeded random tasks besides the paper's")
    bench_parser.add_argument("--seed", type=int, default=0)
    bench_parser.add_argument("--repeats", type=int, default=5, help="planning-time repeats on the paper task")
    bench_parser.add_argument("--workers", type=int, default=None,
                              help="processes of the local Dask cluster (default: one per core; 1: no Dask, in order)")
    bench_parser.add_argument("--scheduler", default=None, metavar="ADDRESS",
                              help="run on the existing Dask cluster of this scheduler (e.g. tcp://host:8786)")
    args = parser.parse_args(argv)
    if args.command == "bench":
        return run_bench(args)
    try:
        if args.scenario is None:
            return run(default_scenario_path(), args.out, variant=args.variant or DEFAULT_SCENARIO[1],
                       live_meshcat=args.meshcat)
        return run(args.scenario, args.out, variant=args.variant, live_meshcat=args.meshcat)
    except ValueError as error:
        print(f"drake-traj: error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
