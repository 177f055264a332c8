"""The exit codes of ``drake-traj``, shared by its parser and its commands."""

__all__ = ["EXIT_BAD_INPUT", "EXIT_INTERRUPTED", "EXIT_OK", "EXIT_RUN_FAILED", "EXIT_TERMINATED"]

EXIT_OK = 0  # success
EXIT_RUN_FAILED = 1  # the run failed (its log kept), or its files could not be written
EXIT_BAD_INPUT = 2  # nothing was run, nothing written
EXIT_INTERRUPTED = 130  # Ctrl-C (128 + SIGINT)
EXIT_TERMINATED = 143  # SIGTERM (128 + SIGTERM)
