"""The command line, ``drake-traj``: the parser and ``main`` (:mod:`.parser`, light: ``--version``
and ``--help`` without Drake), its exit codes (:mod:`.exit_codes`) and the commands
(:mod:`.commands`, loaded once a command is given)."""

from drake_traj.cli.exit_codes import EXIT_BAD_INPUT, EXIT_INTERRUPTED, EXIT_OK, EXIT_RUN_FAILED, EXIT_TERMINATED
from drake_traj.cli.parser import COMMANDS, build_parser, main

__all__ = ["COMMANDS", "EXIT_BAD_INPUT", "EXIT_INTERRUPTED", "EXIT_OK", "EXIT_RUN_FAILED", "EXIT_TERMINATED", "build_parser", "main"]
