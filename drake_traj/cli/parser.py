"""``drake-traj``: run scenarios, list them, benchmark the planners.

    drake-traj run [SCENARIO] [--variant NAME] [--out DIR] [--overwrite] [--no-preflight]
                   [--meshcat [--port P] [--rate R] [--no-wait] [--wait-timeout S] [--serve-after S]]
    drake-traj list
    drake-traj robots
    drake-traj show [SCENARIO] [--variant NAME]
    drake-traj export RUN_DIR --format csv|urscript|ros2 [--period 0.002] [--out FILE]
    drake-traj bench [--out DIR] [--overwrite] [--count N] [--seed S] [--repeats R]

``run`` writes DIR/result.npz, metrics.json, *.png, meshcat.html and run.json (the manifest);
SCENARIO is a YAML file or the name of a shipped scenario (``drake-traj list``: the shipped
scenarios under their files' paths, with their robots); ``robots`` tabulates the known robots
(joints, reach, rated payload, speeds and torques, where the data come from); ``show`` prints the
file of one scenario, to copy. ``export``
writes a run's reference for a robot or another tool (drake_traj.results.exports). ``bench`` runs
every planner and baseline on Pająk 2024's task and N seeded tasks and writes DIR/bench.csv,
bench.md and bench.png.

Exit codes: 0 success; 1 the run failed (its log is kept in the output folder), or its files could
not be written (disk full, a permission lost: the message names the file; the folder's earlier
content is kept); 2 bad input (nothing was run, nothing written); 130 interrupted by Ctrl-C, 143
stopped by SIGTERM (in both, what was logged is kept). ``--debug`` shows the traceback of an error. Text the terminal's encoding cannot show is
printed as escapes (``\u0105``), never an error.

This module is light: ``--version``, ``--help`` and a command's name are answered without importing
Drake or numpy; the commands themselves are in :mod:`drake_traj.cli.commands`, loaded once one is given.
"""

import argparse
import importlib
import shlex
import sys

from drake_traj.version import __version__

from drake_traj.cli.exit_codes import EXIT_BAD_INPUT, EXIT_INTERRUPTED, EXIT_OK, EXIT_RUN_FAILED, EXIT_TERMINATED

__all__ = ["COMMANDS", "EXIT_BAD_INPUT", "EXIT_INTERRUPTED", "EXIT_OK", "EXIT_RUN_FAILED", "EXIT_TERMINATED", "build_parser", "main"]
# each command and its one-line help (``drake-traj --help``); its options are in drake_traj.cli.commands
COMMANDS = {
    "run": "simulate a scenario and write its results",
    "list": "list the shipped scenarios under their files' paths",
    "robots": "list the known robots: joints, reach, payload, limits, data source",
    "show": "print a shipped scenario's file, to copy and edit",
    "export": "write a run's reference as CSV, URScript or ROS 2",
    "bench": "compare every planner and baseline on UR10e tasks",
}


def build_parser(options: dict | None = None) -> argparse.ArgumentParser:
    """The parser of ``drake-traj``. ``options``: per command of :data:`COMMANDS`, the function
    that adds its options and its handler (:data:`drake_traj.cli.commands.OPTIONS`); without them each
    command takes anything, which is enough to answer ``--version`` and ``--help`` and to check
    the command's name."""
    parser = argparse.ArgumentParser(prog="drake-traj", description=__doc__.splitlines()[0],
                                     epilog="exit codes: 0 success, 1 run failed (log kept), 2 bad input, 130 interrupted (Ctrl-C), "
                                            "143 terminated (SIGTERM)")
    parser.add_argument("--version", action="version", version=f"drake-traj {__version__}")
    parser.add_argument("--debug", action="store_true", help="show the traceback of an error")
    subparsers = parser.add_subparsers(dest="command", required=True)
    for name, text in COMMANDS.items():
        command = subparsers.add_parser(name, help=text, add_help=options is not None)
        if options is not None:
            options[name](command)
    return parser


def main(argv=None) -> int:
    """``drake-traj`` with the arguments ``argv`` (default: the command line's); returns the exit code."""
    try:
        build_parser().parse_known_args(argv)  # --version, --help, no command or an unknown one: Drake not imported
        commands = importlib.import_module("drake_traj.cli.commands")  # the commands import Drake: only now
        args = build_parser(commands.OPTIONS).parse_args(argv)
    except SystemExit as done:  # --help, --version, or a usage error argparse printed (code 2)
        return done.code
    # names this process to another that would write the same folder
    args.command_line = shlex.join(["drake-traj", *(sys.argv[1:] if argv is None else argv)])
    return commands.execute(args)

