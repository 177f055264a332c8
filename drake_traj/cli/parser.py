"""``drake-traj``: run scenarios, list them, benchmark the planners.

    drake-traj run [SCENARIO] [--variant NAME] [--out DIR] [--overwrite] [--no-preflight]
                   [--meshcat [--port P] [--rate R] [--no-wait] [--wait-timeout S] [--serve-after S]]
    drake-traj list [-v]
    drake-traj robots
    drake-traj show [SCENARIO] [--variant NAME] [--where]
    drake-traj export RUN_DIR --format csv|urscript|ros2 [--period 0.002] [--out FILE]
    drake-traj bench [--suite planners|free|soak] [--out DIR] [--overwrite] [--count N] [--seed S] [--repeats R]
                     [--workers W | --scheduler ADDRESS] [--arms ARM ...] [--planners PLANNER ...] [--merge DIR ...]

``run`` writes DIR/result.npz, metrics.json, *.png, meshcat.html and run.json (the manifest);
SCENARIO is a YAML file or the name of a shipped scenario (``drake-traj list``: the shipped
scenarios under their files, with their robots; ``-v``: which copy of the files runs, and where);
``robots`` tabulates the known robots
(joints, reach, rated payload, speeds and torques, where the data come from); ``show`` prints the
file of one scenario, to copy. ``export``
writes a run's reference for a robot or another tool (drake_traj.results.exports). ``bench`` runs
every planner and baseline on Pająk 2024's task and N seeded tasks and writes DIR/bench.csv,
bench.md and bench.png; ``--suite free`` the free-motion planner on seeded scenes; ``--suite soak``
N seeded random tasks of every planner on every shipped arm, each plan checked independently
(DIR/soak.csv, soak.md, soak.png; exit 1 if any is wrong).

Exit codes: 0 success; 1 the run failed (its log is kept in the output folder), or its files could
not be written (disk full, a permission lost: the message names the file; the folder's earlier
content is kept); 2 bad input (nothing was run, nothing written); 130 interrupted by Ctrl-C, 143
stopped by SIGTERM (in both, what was logged is kept). Text the terminal's encoding cannot show
is printed as escapes (``\u0105``), never an error.

Global options go before or after the command (``drake-traj run typo.yaml --debug``): ``--debug``
shows the traceback of an error, ``--quiet`` silences the progress ``run`` and ``bench`` print on
stderr (on a terminal a bar; elsewhere, a log or CI, a line at least every 10 s:
:mod:`drake_traj.cli.progress`). Ctrl-C at any moment ends the command with one line and exit
130; a run stopped while it simulates keeps its files so far.

This module is light: ``--version``, ``--help``, a command's name and ``list``
(:mod:`drake_traj.cli.listing`) are answered without importing Drake or numpy; the other
commands are in :mod:`drake_traj.cli.commands`, loaded once one is given. Ctrl-C and SIGTERM are
handled from the first moment of :func:`main`, before Drake is imported.
"""

import argparse
import contextlib
import importlib
import os
import shlex
import signal
import sys
import traceback
from types import SimpleNamespace

import drake_traj
from drake_traj.cli import listing
from drake_traj.cli.exit_codes import EXIT_BAD_INPUT, EXIT_INTERRUPTED, EXIT_OK, EXIT_RUN_FAILED, EXIT_TERMINATED
from drake_traj.cli.progress import Progress
from drake_traj.cli.signals import signals_as_interrupts, signals_held

__all__ = ["COMMANDS", "EXIT_BAD_INPUT", "EXIT_INTERRUPTED", "EXIT_OK", "EXIT_RUN_FAILED", "EXIT_TERMINATED", "build_parser", "main"]
# each command and its one-line help (``drake-traj --help``); its options are in drake_traj.cli.commands
# (list's in drake_traj.cli.listing)
COMMANDS = {
    "run": "simulate a scenario and write its results",
    "list": "list the shipped scenarios under their files",
    "robots": "list the known robots: joints, reach, payload, limits, data source",
    "show": "print a shipped scenario's file, to copy and edit",
    "export": "write a run's reference as CSV, URScript or ROS 2",
    "bench": "compare every planner and baseline on UR10e tasks",
}
LONG_COMMANDS = ("run", "bench")  # they say what they are doing from the start (drake_traj.cli.progress)


def _add_global_options(parser: argparse.ArgumentParser, *, default) -> None:
    """The options every command takes, before or after its name: the top parser's defaults are
    False, each command's ``argparse.SUPPRESS`` (not given after the command: the value given
    before it, or the top parser's default, stays)."""
    parser.add_argument("--debug", action="store_true", default=default, help="show the traceback of an error")
    parser.add_argument("--quiet", "-q", action="store_true", default=default,
                        help="no progress on stderr (run, bench); errors are still said")


def build_parser(options: dict | None = None) -> argparse.ArgumentParser:
    """The parser of ``drake-traj``. ``options``: per command of :data:`COMMANDS`, the function
    that adds its options and its handler (:data:`drake_traj.cli.commands.OPTIONS`,
    :data:`drake_traj.cli.listing.OPTIONS`); a command without one takes anything, which is
    enough to answer ``--version`` and ``--help``, to check the command's name and to read the
    global options (``--debug``, ``--quiet``), given before or after the command."""
    parser = argparse.ArgumentParser(prog="drake-traj", description=__doc__.splitlines()[0],
                                     epilog="exit codes: 0 success, 1 run failed (log kept), 2 bad input, 130 interrupted (Ctrl-C), "
                                            "143 terminated (SIGTERM)")
    parser.add_argument("--version", action="version", version=f"drake-traj {drake_traj.__version__}")
    _add_global_options(parser, default=False)
    shared = argparse.ArgumentParser(add_help=False)
    _add_global_options(shared, default=argparse.SUPPRESS)
    subparsers = parser.add_subparsers(dest="command", required=True)
    for name, text in COMMANDS.items():
        known = options is not None and name in options
        command = subparsers.add_parser(name, help=text, add_help=known, parents=[shared])
        if known:
            options[name](command)
    return parser


def main(argv=None) -> int:
    """``drake-traj`` with the arguments ``argv`` (default: the command line's); returns the exit
    code. Ctrl-C (and SIGTERM, as Ctrl-C) at any moment, Drake's import included, ends it with one
    line on stderr and exit 130 (143); an unforeseen error is one line too, its traceback with
    ``--debug``. Without ``argv`` (the console script, ``python -m drake_traj.cli``) this is the
    process's own command line, which Ctrl-C during Drake's import ends at once (``os._exit``);
    given ``argv``, the KeyboardInterrupt waits until the import is done."""
    state = SimpleNamespace(debug=False, interrupted=False, terminated=False, own_process=argv is None)
    argv = sys.argv[1:] if argv is None else list(argv)
    with signals_as_interrupts(state):
        try:
            _prepare_streams()
            return _main(argv, state)
        except KeyboardInterrupt:
            return _interrupted(state)
        except BrokenPipeError:  # stdout's reader stopped early (drake-traj list | head): nothing more to say
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # Python's last flush of stdout goes nowhere
            return EXIT_OK
        except Exception as error:  # a bug, or the machine: one line, the traceback only when asked
            if state.interrupted or state.terminated:  # e.g. Ctrl-C in an extension module's import: an ImportError
                return _interrupted(state)
            print(f"drake-traj: internal error: {type(error).__name__}: {error} (--debug shows where)", file=sys.stderr)
            if state.debug:
                traceback.print_exception(error)
            return EXIT_RUN_FAILED


def _leave_at_once(signum: int) -> None:
    """Ctrl-C (or SIGTERM) while Drake is imported, in the command line's own process: one line,
    and the process ends at once (nothing is written yet; a KeyboardInterrupt inside an
    extension module's initialization would print a traceback of its own)."""
    _interrupted(SimpleNamespace(terminated=signum == signal.SIGTERM))
    os._exit(EXIT_TERMINATED if signum == signal.SIGTERM else EXIT_INTERRUPTED)


def _interrupted(state: SimpleNamespace) -> int:
    """Say that Ctrl-C or SIGTERM stopped the command (one line); its exit code."""
    with signals_held():  # a second Ctrl-C while saying so adds nothing
        print("drake-traj: terminated (SIGTERM)" if state.terminated else "drake-traj: interrupted",
              file=sys.stderr, flush=True)
    return EXIT_TERMINATED if state.terminated else EXIT_INTERRUPTED


def _main(argv: list[str], state: SimpleNamespace) -> int:
    """Parse ``argv`` and run its command: ``list`` here, the others by
    :func:`drake_traj.cli.commands.execute` once Drake is loaded (the progress of a long command
    started before that)."""
    try:
        given, _ = build_parser().parse_known_args(argv)  # --version, --help, no command or an unknown one
        state.debug = given.debug
        if given.command in listing.OPTIONS:  # without Drake
            args = build_parser(listing.OPTIONS).parse_args(argv)
            return args.handler(args)
    except SystemExit as done:  # --help, --version, or a usage error argparse printed (code 2)
        return done.code
    progress = Progress(given.command, enabled=given.command in LONG_COMMANDS and not given.quiet)
    try:
        progress.stage("loading Drake and the planners")
        # the commands import Drake: only now. Ctrl-C is not raised meanwhile (an extension module
        # stopped while it initializes prints a traceback of its own): the command line's own
        # process ends at once, a caller of main(argv) gets the KeyboardInterrupt after the import
        with signals_held(_leave_at_once if state.own_process else None) as received:
            commands = importlib.import_module("drake_traj.cli.commands")
        if received:
            state.terminated = signal.SIGTERM in received
            raise KeyboardInterrupt
        try:
            args = build_parser(commands.OPTIONS).parse_args(argv)
        except SystemExit as done:
            return done.code
        args.command_line = shlex.join(["drake-traj", *argv])  # names this process to another writing the same folder
        args.progress = progress
        return commands.execute(args)
    finally:
        progress.close()


def _prepare_streams() -> None:
    """Text that stdout's or stderr's encoding cannot show (PYTHONIOENCODING=ascii) printed as
    escapes (``\u0105``), never an error."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, ValueError):
            stream.reconfigure(errors="backslashreplace")
