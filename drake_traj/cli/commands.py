"""The commands of ``drake-traj`` but ``list`` (:mod:`drake_traj.cli` has the usage and the exit
codes, :mod:`drake_traj.cli.listing` the list): each command's options (:data:`OPTIONS`) and what
it does; :func:`execute` runs one, turning bad input and failed writes into a message and an exit
code. :mod:`drake_traj.cli` imports this module (and with it Drake) only once a command is given;
Ctrl-C, SIGTERM and unforeseen errors are :func:`drake_traj.cli.main`'s.
"""

import contextlib
import json
import signal
import sys
import traceback
from pathlib import Path
from time import sleep

import numpy as np
from tqdm import tqdm

from drake_traj.version import __version__
from drake_traj.cli.exit_codes import EXIT_BAD_INPUT, EXIT_INTERRUPTED, EXIT_OK, EXIT_RUN_FAILED, EXIT_TERMINATED
from drake_traj.cli.signals import signals_held
from drake_traj.bench import SOAK_ARMS, SOAK_PLANNERS, bench, free_bench, merge_soaks, soak_bench
from drake_traj.cell import CollisionError, refusal_figure
from drake_traj.errors import DrakeTrajError, Failure, PlanningError
from drake_traj.results.exports import FORMATS, UR_CYCLE, ExportError
from drake_traj.station import (add_live_view, draw_refusal, draw_task, draw_tcp_path, export_html, frame_task, simulate,
                                start_meshcat, wait_for_browser)
from drake_traj.results import SimulationResult, WriteError, locked, working_folder
from drake_traj.robots import ROBOT_NAMES, get_robot, self_contact, setup_note
from drake_traj.results import (MANIFEST, REFUSAL, add_to_manifest, claim_run_folder, earlier_run, run_files,
                               write_manifest)
from drake_traj.scenario import (DEFAULT_SCENARIO, check_planned_duration, default_scenario_path, find_scenario,
                                 load_scenario, preflight, scenario_variants, shipped_copy, shipped_directory,
                                 shipped_scenarios)
from drake_traj.validation import REALTIME_RATES

# [s] how long the live view's recording stays served after the run when no terminal is attached
# (on a terminal: until Ctrl-C); --serve-after sets it
DEFAULT_SERVE_AFTER = 60.0
SUMMARY = ("name", "succeeded", "failure", "failure_cause", "duration_s", "peak_velocity_fraction", "peak_acceleration_fraction",
           "tracking_error_joint_max_rad", "tracking_error_tcp_max_m", "real_time_factor")


def _scenario_reference(args) -> tuple[Path, str | None]:
    if args.scenario is None:
        return default_scenario_path(), args.variant or DEFAULT_SCENARIO[1]
    return find_scenario(args.scenario, args.variant)


def run(args) -> int:
    """``drake-traj run``: simulate one scenario and write its outputs; returns the exit code. Its
    stages are said on ``args.progress`` (:class:`~drake_traj.cli.progress.Progress`). Ctrl-C (or
    SIGTERM) while it simulates: the run's files so far are written as a failed run's, then the
    interrupt goes on (exit 130, 143)."""
    progress = args.progress
    progress.stage("reading the scenario")
    scenario = load_scenario(*_scenario_reference(args))
    if args.out == "":
        raise DrakeTrajError("--out must name a folder, got empty text")
    claimed = stopped = None
    try:
        progress.stage("planning")
        arguments = scenario.station_arguments() | scenario.run_settings()
        planner = arguments.pop("planner")
        planned_path = None
        if args.preflight:
            progress.stage("checking the task in the cell")
            try:
                planned_path = preflight(scenario, planner)
            except CollisionError as error:
                progress.close()
                raise with_refusal_picture(error, scenario, args) from None
        check_planned_duration(scenario, planner)
        _say_unchecked_pairs(arguments["robot"])
        if setup_note(arguments["robot"]):
            tqdm.write(f"drake-traj: {setup_note(arguments['robot'])}", file=sys.stderr)
        duration = planner.planned_duration()
        expected = duration + scenario.settle_time if np.isfinite(duration) else scenario.max_duration
        progress.stage("building the station")
        # checked and locked before the simulation; written (an earlier run replaced, with
        # --overwrite) only once the new run's files are complete on disk
        claimed = claim_run_folder(_run_folder(args, scenario), overwrite=args.overwrite,
                                   samples=expected / scenario.logging_period(), command=args.command_line)
        progress.expect(expected)
        meshcat, add_systems, before_run = _live_view(args, arguments, planner, planned_path)
        try:
            result = simulate(planner, meshcat=meshcat, progress=progress.simulated, add_systems=add_systems,
                              before_run=before_run, preflight=False, **arguments)
        except KeyboardInterrupt as interrupted:  # while it simulated: the result so far is written as a failed run's
            if getattr(interrupted, "result", None) is None:
                raise
            result, stopped = interrupted.result, interrupted
        progress.stage("writing the run's files")
        files, interrupts = _write_run(claimed, result, planner, scenario, meshcat)
    finally:
        progress.close()
        if claimed is not None:
            claimed.release()
    metrics = result.metrics().to_dict()
    print(json.dumps({key: metrics[key] for key in SUMMARY}, indent=2))
    print(f"wrote {claimed.directory}: {', '.join(sorted(files))}")
    if stopped is not None:
        print(f"drake-traj: the run stopped at t = {stopped.failure.time:.3f} s; what it logged is in {claimed.directory}",
              file=sys.stderr)
        raise stopped
    if args.meshcat:
        serve_recording(meshcat.web_url(), args.serve_after)
    if interrupts:
        print("drake-traj: interrupted while writing; the run's files were completed first", file=sys.stderr)
        return EXIT_TERMINATED if signal.SIGTERM in interrupts else EXIT_INTERRUPTED
    return EXIT_OK if result.succeeded else EXIT_RUN_FAILED


def _live_view(args, arguments: dict, planner, planned_path):
    """The run's Meshcat, the task (and the planned path) drawn; with ``--meshcat``, the live
    view's systems and the wait for a browser (:func:`simulate`'s ``add_systems`` and
    ``before_run``, else None), the real-time rate set in ``arguments`` and its speed override
    taken out of them (the live view's slider scales it)."""
    meshcat = start_meshcat(args.port, announce=args.meshcat)
    draw_task(meshcat, planner.task_waypoints(), neighbourhood=planner.waypoint_neighbourhood(), planned_path=planned_path)
    frame_task(meshcat, np.vstack([planner.task_waypoints().reshape(-1, 3),
                                   planned_path if planned_path is not None else np.zeros((0, 3))]))
    if not args.meshcat:
        return meshcat, None, None
    arguments["simulator_config"].target_realtime_rate = args.rate
    profile = arguments.pop("speed_override")
    print(f"Meshcat: {meshcat.web_url()}", file=sys.stderr, flush=True)

    def add_systems(builder, station):
        add_live_view(builder, station, meshcat, arguments["robot"], speed_override=profile)

    def before_run(simulator):
        if args.wait:
            args.progress.stage("waiting for a browser")
            print(f"waiting up to {args.wait_timeout:g} s for a browser at {meshcat.web_url()} "
                  "(--no-wait starts at once)", file=sys.stderr, flush=True)
            if not wait_for_browser(meshcat, args.wait_timeout):
                print(f"no browser connected within {args.wait_timeout:g} s; starting the motion",
                      file=sys.stderr, flush=True)

    return meshcat, add_systems, before_run


def _write_run(claimed, result: SimulationResult, planner, scenario, meshcat) -> tuple[list[str], list]:
    """Write the run's files into the ``claimed`` folder (an earlier run replaced only once they
    are complete); returns their names and the signals received meanwhile (a second Ctrl-C must
    not leave half a run)."""
    with signals_held() as interrupts, claimed.replace() as staging:
        result.write_into(staging)
        for stem, figure in (result.figures() | planner.figures()).items():
            staging.write(f"{stem}.png", lambda path: figure.savefig(path, dpi=110))
        draw_tcp_path(meshcat, result.tcp)
        staging.write("meshcat.html", lambda path: export_html(meshcat, path))
        files = list(staging.files)
        write_manifest(staging, files, scenario=scenario.name, drake_traj=__version__,
                       failure=None if result.failure is None else result.failure.to_dict(),
                       unchecked_collision_pairs=[list(pair) for pair in result.unchecked_collision_pairs],
                       estimated_inertia_links=dict(result.estimated_inertia), locked_joints=dict(result.locked_joints))
    return files, interrupts


def _say_unchecked_pairs(robot) -> None:
    """Say once, on stderr, the pairs of the arm's links the self and cell checks leave out and
    why (:func:`~drake_traj.robots.self_contact`; none on the shipped arms)."""
    pairs = self_contact(robot).rows()
    if pairs:
        tqdm.write("drake-traj: the checks leave out these pairs of the arm's links (metrics.json: "
                   f"unchecked_collision_pairs): {'; '.join(f'{a} and {b}, {reason}' for a, b, reason in pairs)}",
                   file=sys.stderr)


def _run_folder(args, scenario) -> Path:
    """The run's output folder: --out, or out/<scenario name>."""
    return Path(args.out) if args.out else Path("out") / scenario.name


def with_refusal_picture(error: CollisionError, scenario, args) -> CollisionError:
    """``error`` with the path of ``refusal.png`` (:func:`drake_traj.cell.refusal.refusal_figure`), written
    with a ``run.json`` naming the refusal into the run's output folder when it may be written
    (as a run's files: an earlier run there needs --overwrite); else the reason there is none.
    With --meshcat, the refused configuration is drawn there and served as after a run."""
    checker = scenario.cell_checker()
    if args.meshcat:
        meshcat = start_meshcat(args.port)
        draw_refusal(meshcat, checker, error)
        print(f"drake-traj: the refused configuration is drawn at {meshcat.web_url()}", file=sys.stderr, flush=True)
        serve_recording(meshcat.web_url(), args.serve_after)
    failure = Failure(error.cause, str(error), error.time, tuple(error.configuration.tolist())).to_dict()
    try:
        with claim_run_folder(_run_folder(args, scenario), overwrite=args.overwrite, command=args.command_line) as claimed:
            earlier = earlier_run(claimed.directory)  # kept: a refusal never replaces a run
            with claimed.replace(keep_earlier=earlier is not None) as staging:
                picture = staging.write(REFUSAL, lambda path: refusal_figure(checker, error).savefig(path, dpi=100))
                if earlier is None:
                    write_manifest(staging, [picture.name], scenario=scenario.name, drake_traj=__version__,
                                   failure=failure)
                else:  # the earlier run's manifest, listing the picture too (replacing the run removes it)
                    details = {key: value for key, value in earlier.items() if key != "files"}
                    details["refusal"] = {"scenario": scenario.name, "drake_traj": __version__, "failure": failure}
                    write_manifest(staging, [*earlier["files"], picture.name], **details)
    except DrakeTrajError as reason:
        return error.relocated(error.field, f"{error}\n(no picture of the refused configuration: {reason})")
    kept = "" if earlier is None else f"; the earlier run in {claimed.directory} is kept, the picture beside it"
    return error.relocated(error.field, f"{error}\n(picture of the refused configuration: {picture}{kept})")


def serve_recording(url: str, seconds: float | None) -> None:
    """After a live run, keep Meshcat serving the recording at ``url``: for ``seconds`` [s]; when
    None, until Ctrl-C on a terminal and for :data:`DEFAULT_SERVE_AFTER` without one (a script,
    CI, an IDE's run button). Ctrl-C ends it sooner."""
    if seconds is None and not sys.stdin.isatty():
        seconds = DEFAULT_SERVE_AFTER
    try:
        if seconds is None:
            print(f"Meshcat is serving the recording at {url}; press Ctrl-C to quit.", file=sys.stderr)
            while True:
                input()
        elif seconds > 0:
            print(f"Meshcat is serving the recording at {url} for {seconds:g} s (--serve-after S sets how long; "
                  "Ctrl-C quits sooner)", file=sys.stderr, flush=True)
            sleep(seconds)
    except (KeyboardInterrupt, EOFError):
        pass


ROBOT_COLUMNS = ("robot", "joints", "reach [m]", "payload [kg]", "rated speeds [rad/s | m/s]", "torque limits [N m | N]",
                 "data source")


def robot_rows() -> list[tuple[str, ...]]:
    """One row of :data:`ROBOT_COLUMNS` per known robot (``-``: not given)."""
    def numbers(values) -> str:
        return " ".join(f"{value:.4g}" for value in values)

    rows = []
    for name in ROBOT_NAMES:
        robot = get_robot(name)
        rows.append((name, str(robot.num_joints), "-" if robot.reach is None else f"{robot.reach:g}",
                     "-" if robot.rated_payload is None else f"{robot.rated_payload:g}",
                     numbers(robot.velocity_limits), numbers(robot.effort_limits), robot.data_source or "-"))
    return rows


def list_robots(args) -> int:
    """``drake-traj robots``: a table of the known robots, the names a scenario's ``robot:`` takes
    (an arm of one's own: ``robot: !CustomArm`` or ``!DhArm``, with the shipped examples of one)."""
    rows = [ROBOT_COLUMNS] + robot_rows()
    widths = [max(len(row[k]) for row in rows) for k in range(len(ROBOT_COLUMNS) - 1)]
    for row in rows:
        print("  ".join(f"{cell:{width}}" for cell, width in zip(row, widths)) + "  " + row[-1])
    print("an arm of one's own in a scenario: robot: !CustomArm {model_file: ...} or robot: !DhArm {dh: ...} "
          "(drake_traj.robots.custom)")
    own = {}  # an arm of one's own in the shipped scenarios -> (its file, its scenarios)
    for entry in shipped_scenarios():
        if entry.robot not in ROBOT_NAMES:
            own.setdefault(entry.robot, (entry.path, []))[1].append(entry.name)
    for label, (path, names) in own.items():
        print(f"  e.g. {label} in {path.name} ({', '.join(names)}; drake-traj show {names[0]})")
    return EXIT_OK


def show_scenario(args) -> int:
    """``drake-traj show``: the text of a scenario's file (a shipped one by its name), to copy
    and edit; on stderr, which file it is and how to run the copy. ``--where``: the file's path
    instead (and, for a shipped file, which copy of the shipped files it is, on stderr)."""
    path, variant = _scenario_reference(args)
    variants = scenario_variants(path)
    if variant is not None and variant not in variants:
        load_scenario(path, variant)  # refuses it, naming the file's variants as ``run`` does
    shipped = path.parent == shipped_directory()
    if args.where:
        print(path.resolve())
        if shipped:
            print(f"drake-traj: from {shipped_copy()}", file=sys.stderr)
        return EXIT_OK
    print(path.read_text(), end="")
    option = f" --variant {variant or '|'.join(variants)}" if variants else ""
    which = f"the shipped file {path.name} (--where: its path)" if shipped else str(path)
    print(f"drake-traj: that is {which}; run a copy with: drake-traj run my_copy.yaml{option}", file=sys.stderr)
    return EXIT_OK


def export_run(args) -> int:
    """``drake-traj export``: a run's reference as CSV, URScript or a ROS 2 JointTrajectory."""
    run_dir = Path(args.run_dir)
    result = SimulationResult.load(run_dir)
    out = Path(args.out) if args.out else run_dir / f"reference{FORMATS[args.format].suffix}"
    into_run = out.parent.resolve() == run_dir.resolve()
    if into_run and out.name in {"result.npz", "metrics.json", MANIFEST} | set(run_files(run_dir)) - set(_exports()):
        raise ExportError(f"--out {out} is one of the run's own files; give another file name")
    if out.is_dir():  # before the advice to overwrite: a folder is never replaced by a file
        raise ExportError(f"--out {out} is a folder; give a file name, e.g. --out {out / f'reference{FORMATS[args.format].suffix}'}")
    if out.exists() and not args.overwrite:
        raise ExportError(f"--out {out} exists; pass --overwrite to replace it")
    # into the run's own folder: locked, so that no run replaces the folder meanwhile
    with locked(run_dir, args.command_line) if into_run else contextlib.nullcontext():
        path = result.export(out, args.format, period=args.period, lookahead_time=args.lookahead_time, gain=args.gain,
                             approach_speed=args.approach_speed, allow_failed=args.allow_failed,
                             run_folder=run_dir if into_run else None)
        if into_run and (run_dir / MANIFEST).is_file():
            add_to_manifest(run_dir, path.name)  # replacing the run (--overwrite) removes its exports too
    print(f"wrote {path}")
    return EXIT_OK


def _exports() -> list[str]:
    """The default export file names (reference.csv, ...), which an export may replace."""
    return [f"reference{form.suffix}" for form in FORMATS.values()]


def run_bench(args) -> int:
    """``drake-traj bench``; bad arguments, ``--out`` or ``--scheduler`` are refused before any run.
    ``--suite free``: the free-motion suite (:func:`drake_traj.bench.free_bench`) instead. The
    bench says its own progress (``--quiet``: none)."""
    args.progress.close()
    stream = None if args.quiet else sys.stderr
    if args.suite == "free":
        free_bench(args.out or "out/free", count=5 if args.count is None else args.count, seed=args.seed,
                   workers=args.workers, scheduler=args.scheduler, progress=stream, overwrite=args.overwrite,
                   command=args.command_line)
        return EXIT_OK
    if args.suite == "soak":
        return _soak(args, stream)
    bench(args.out or "out/bench", count=20 if args.count is None else args.count, seed=args.seed, repeats=args.repeats,
          workers=args.workers, scheduler=args.scheduler, progress=stream, overwrite=args.overwrite,
          command=args.command_line)
    return EXIT_OK


def _soak(args, stream) -> int:
    """``drake-traj bench --suite soak`` (or ``--merge`` of its parts); exit 1 where any task went
    wrong, the first ten named with the command that reruns each."""
    if args.merge:
        rows = merge_soaks(args.out or "out/soak", args.merge, progress=stream, overwrite=args.overwrite,
                           command=args.command_line)
    else:
        rows = soak_bench(args.out or "out/soak", count=10 if args.count is None else args.count, seed=args.seed,
                          arms=args.arms or SOAK_ARMS, planners=args.planners or SOAK_PLANNERS,
                          workers=args.workers, scheduler=args.scheduler, progress=stream, overwrite=args.overwrite,
                          command=args.command_line)
    wrong = [row for row in rows if row["wrong"]]
    for row in wrong[:10]:
        print(f"wrong: {row['arm']} {row['planner']} seed {row['seed']}: {row['message'][:200]}\n  rerun: {row['rerun']}",
              file=sys.stderr)
    return EXIT_RUN_FAILED if wrong else EXIT_OK


def check_options(args) -> None:
    """Options argparse cannot check by type: an error (exit 2) names the option and the value."""
    checks = []
    if args.command == "run":
        checks = [("--port", args.port is None or 1 <= args.port <= 65535, args.port, "a port number 1-65535"),
                  ("--rate", REALTIME_RATES[0] <= args.rate <= REALTIME_RATES[1], args.rate,
                   "a positive real-time rate from {:g} to {:g}".format(*REALTIME_RATES)),
                  ("--wait-timeout", np.isfinite(args.wait_timeout) and args.wait_timeout >= 0, args.wait_timeout,
                   "a number of seconds >= 0"),
                  ("--serve-after", args.serve_after is None or (np.isfinite(args.serve_after) and args.serve_after >= 0),
                   args.serve_after, "a number of seconds >= 0")]
        live_only = [option for option, given in (("--rate", args.rate != 1.0), ("--port", args.port is not None),
                                                  ("--no-wait", not args.wait),
                                                  ("--serve-after", args.serve_after is not None)) if given]
        if live_only and not args.meshcat:
            raise DrakeTrajError(f"{live_only[0]} sets up the live view; add --meshcat (or leave {live_only[0]} out)")
    if args.command == "bench" and args.suite != "soak":
        soak_only = [option for option, value in (("--arms", args.arms), ("--planners", args.planners),
                                                  ("--merge", args.merge)) if value is not None]
        if soak_only:
            raise DrakeTrajError(f"{soak_only[0]} applies to --suite soak only (this is --suite {args.suite})")
    for option, ok, value, expected in checks:
        if not ok:
            raise DrakeTrajError(f"{option} must be {expected}, got {value}")


def _add_scenario_arguments(parser, what: str, verb: str) -> None:
    """SCENARIO and --variant, which ``run`` and ``show`` resolve alike (:func:`_scenario_reference`)."""
    parser.add_argument("scenario", nargs="?", default=None,
                        help=f"{what} (default: {DEFAULT_SCENARIO[0]}, variant {DEFAULT_SCENARIO[1]}; see drake-traj list)")
    parser.add_argument("--variant", default=None, help=f"the variant to {verb}, in a file of several")


def _run_options(parser) -> None:
    parser.set_defaults(handler=run)
    _add_scenario_arguments(parser, "a scenario YAML file or a shipped scenario's name", "run")
    parser.add_argument("--out", default=None, help="output folder (default: out/<scenario name>)")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run in the output folder")
    parser.add_argument("--no-preflight", dest="preflight", action="store_false",
                        help="do not check the whole task before the motion (online planners)")
    live = parser.add_argument_group("live view")
    live.add_argument("--meshcat", action="store_true", help="show the run live in Meshcat, in real time")
    live.add_argument("--port", type=int, default=None, help="Meshcat's port (default: the first free from 7000)")
    live.add_argument("--rate", type=float, default=1.0,
                      help="real-time rate of the live run, {:g}-{:g} (default 1)".format(*REALTIME_RATES))
    live.add_argument("--no-wait", dest="wait", action="store_false", help="start the motion without waiting for a browser")
    live.add_argument("--wait-timeout", type=float, default=60.0, help="how long to wait for a browser [s] (default 60)")
    live.add_argument("--serve-after", type=float, default=None, metavar="S",
                      help="keep serving the recording S seconds after the run (default: until Ctrl-C on a terminal, "
                           f"{DEFAULT_SERVE_AFTER:g} s without one)")


def _show_options(parser) -> None:
    parser.set_defaults(handler=show_scenario)
    _add_scenario_arguments(parser, "a shipped scenario's name", "show")
    parser.add_argument("--where", action="store_true",
                        help="print the file's path instead of its text (and which copy of the shipped files it is)")


def _export_options(parser) -> None:
    parser.set_defaults(handler=export_run)
    parser.add_argument("run_dir", help="a run's output folder (drake-traj run --out)")
    parser.add_argument("--format", required=True, choices=sorted(FORMATS))
    parser.add_argument("--period", type=float, default=UR_CYCLE, help="sampling period [s] (default 0.002)")
    parser.add_argument("--out", default=None, help="the file to write (default: RUN_DIR/reference.<ext>)")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing --out file")
    parser.add_argument("--allow-failed", action="store_true",
                        help="export the reference of a run that failed (marked as failed in the file)")
    parser.add_argument("--lookahead-time", type=float, default=0.1, help="URScript servoj lookahead [s], 0.03-0.2")
    parser.add_argument("--gain", type=float, default=300.0, help="URScript servoj gain, 100-2000")
    parser.add_argument("--approach-speed", type=float, default=0.3,
                        help="URScript movej to the start [rad/s, rad/s^2] (default 0.3)")


def _bench_options(parser) -> None:
    parser.set_defaults(handler=run_bench)
    parser.add_argument("--suite", choices=("planners", "free", "soak"), default="planners",
                        help="planners: every planner and baseline on UR10e tasks (default); free: the free-motion "
                             "planner on seeded scenes of every kind; soak: seeded random tasks for every planner on "
                             "every shipped arm, each plan checked independently (exit 1 on any wrong result)")
    parser.add_argument("--out", default=None,
                        help="output directory (default: out/bench; --suite free: out/free; --suite soak: out/soak)")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier bench in the output directory")
    parser.add_argument("--count", type=int, default=None,
                        help="seeded random tasks besides the paper's (default 20); --suite free: queries per scene "
                             "kind (default 5); --suite soak: tasks per arm and planner (default 10)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--repeats", type=int, default=5, help="planning-time repeats on the paper task (--suite planners)")
    parser.add_argument("--workers", type=int, default=None,
                        help="processes of the local Dask cluster (default: one per core; 1: no Dask, in order)")
    parser.add_argument("--scheduler", default=None, metavar="ADDRESS",
                        help="run on the existing Dask cluster of this scheduler (e.g. tcp://host:8786)")
    parser.add_argument("--arms", nargs="+", default=None, metavar="ARM",
                        help=f"--suite soak: the arms (default all: {' '.join(SOAK_ARMS)})")
    parser.add_argument("--planners", nargs="+", default=None, metavar="PLANNER",
                        help=f"--suite soak: the planners (default all: {' '.join(SOAK_PLANNERS)})")
    parser.add_argument("--merge", nargs="+", default=None, metavar="DIR",
                        help="--suite soak: write one report (into --out) of soaks run in parts into these folders")


# each command of drake_traj.cli.COMMANDS but list (drake_traj.cli.listing) -> the function adding its
# options and handler to its parser
OPTIONS = {
    "run": _run_options,
    "robots": lambda parser: parser.set_defaults(handler=list_robots),
    "show": _show_options,
    "export": _export_options,
    "bench": _bench_options,
}


def execute(args) -> int:
    """Run the command ``args`` (parsed by :func:`drake_traj.cli.build_parser` with :data:`OPTIONS`,
    with ``command_line`` and ``progress`` set); returns the exit code. Bad input is one message
    on stderr (exit 2), a failed write exit 1; ``--debug`` adds the traceback."""
    try:
        if args.command in ("run", "export", "bench"):
            working_folder()  # named when it was deleted, before Drake fails on it
        check_options(args)
        return args.handler(args)
    except WriteError as error:  # disk full, a permission lost, ...: the earlier content is intact
        failure, code, kind = error, EXIT_RUN_FAILED, "error"
    except (DrakeTrajError, ValueError) as error:  # bad input: one paragraph, no traceback
        kind = "the task cannot be done" if isinstance(error, PlanningError) else "error"
        failure, code = error, EXIT_BAD_INPUT
    args.progress.close()  # before the message
    print(f"drake-traj: {kind}: {failure}", file=sys.stderr)
    if args.debug:
        traceback.print_exception(failure)
    return code
