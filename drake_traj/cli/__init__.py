"""The command line, ``drake-traj``: the parser and ``main`` (:mod:`.parser`, light: ``--version``,
``--help`` and ``list`` (:mod:`.listing`) without Drake), its exit codes (:mod:`.exit_codes`), the
progress of long commands on stderr (:mod:`.progress`), Ctrl-C and SIGTERM (:mod:`.signals`) and
the other commands (:mod:`.commands`, loaded once one is given)."""

from drake_traj.cli.exit_codes import EXIT_BAD_INPUT, EXIT_INTERRUPTED, EXIT_OK, EXIT_RUN_FAILED, EXIT_TERMINATED
from drake_traj.cli.parser import COMMANDS, build_parser, main

__all__ = ["COMMANDS", "EXIT_BAD_INPUT", "EXIT_INTERRUPTED", "EXIT_OK", "EXIT_RUN_FAILED", "EXIT_TERMINATED", "build_parser", "main"]
