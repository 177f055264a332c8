"""``drake-traj list``: the shipped scenarios, a line each (name, robot, description) under the
name of their file; ``-v`` first says which copy of the files runs and gives the files' paths.
Read from :mod:`drake_traj.catalogue`, without Drake, so the list comes at once (this module is
as light as :mod:`drake_traj.cli.parser`, which runs it)."""

from drake_traj.catalogue import shipped_copy, shipped_scenarios
from drake_traj.cli.exit_codes import EXIT_OK

__all__ = ["OPTIONS", "list_scenarios"]


def list_scenarios(args) -> int:
    """``drake-traj list``: the shipped scenarios under their file's name (``-v``: under its path,
    after a line saying which copy of the files runs, :func:`~drake_traj.catalogue.shipped_copy`)."""
    entries = shipped_scenarios()
    if args.verbose:
        print(f"shipped scenarios, from {shipped_copy()}")
    else:
        print("shipped scenarios, by file (drake-traj list -v: which copy of the files runs, and where)")
    width = max(len(entry.name) for entry in entries)
    robot_width = max(len(entry.robot) for entry in entries)
    for path in dict.fromkeys(entry.path for entry in entries):
        print(path if args.verbose else path.name)
        for entry in entries:
            if entry.path == path:
                print(f"  {entry.name:{width}}  {entry.robot:{robot_width}}  {entry.description}")
    return EXIT_OK


def _list_options(parser) -> None:
    parser.set_defaults(handler=list_scenarios)
    parser.add_argument("-v", "--verbose", action="store_true",
                        help="say which copy of the shipped files runs (a source tree's or the installed package's), "
                             "with the files' paths")


# list's options and handler, for drake_traj.cli.build_parser (the other commands': drake_traj.cli.commands.OPTIONS)
OPTIONS = {"list": _list_options}
