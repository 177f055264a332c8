"""Run folders: where ``drake-traj run`` writes, checked before any work, never mixed.

A run folder holds the files of one run and ``run.json``, the manifest that lists them (exports
written into the folder are added to it). A folder that holds an earlier run (a manifest, or the
``result.npz`` / ``metrics.json`` of a run written before manifests) is not written into unless
asked to overwrite, which removes that run's files only when the new run's files are about to be
written, so bad input or an interrupted start never costs the earlier run, and nothing of two
runs is ever mixed. A folder that holds other files, not a run, is never written into.
"""

import json
import os
from pathlib import Path

from drake_traj.errors import DrakeTrajError

__all__ = ["MANIFEST", "OutputError", "add_to_manifest", "begin_output", "check_output", "check_writable", "clear_run",
           "create_folder", "holds_a_run", "run_files", "write_manifest"]

MANIFEST = "run.json"
_RUN_FILES = ("result.npz", "metrics.json")  # a run written before manifests is recognised by these


class OutputError(DrakeTrajError):
    """An output folder cannot be used: names the folder and the reason."""


def holds_a_run(directory: Path) -> bool:
    """Whether ``directory`` holds the files of an earlier run."""
    return any((directory / name).exists() for name in (MANIFEST,) + _RUN_FILES)


def check_writable(directory: Path) -> None:
    """The folder exists as a writable folder, or can be created: not a file, not below a file."""
    if directory.is_symlink() and not directory.exists():
        raise OutputError(f"output folder {directory} is a broken link or a loop of links")
    if directory.exists() and not directory.is_dir():
        raise OutputError(f"output folder {directory} is a file, not a folder")
    ancestor = directory
    while not ancestor.exists():
        if ancestor.parent == ancestor:
            break
        ancestor = ancestor.parent
    if ancestor.exists() and not ancestor.is_dir():
        raise OutputError(f"output folder {directory} cannot be created: {ancestor} is a file")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise OutputError(f"output folder {directory} cannot be written: {ancestor} is not writable")


def check_output(directory, *, overwrite: bool = False) -> Path:
    """Check ``directory`` before a run, creating and removing nothing: writable or creatable, not
    a file, not holding files other than a run's, and not holding an earlier run unless
    ``overwrite``. Raises :class:`OutputError`."""
    directory = Path(directory)
    try:
        check_writable(directory)
        if directory.is_dir():
            if holds_a_run(directory) and not overwrite:
                raise OutputError(f"output folder {directory} holds an earlier run (its {MANIFEST} or result.npz); "
                                  "choose another --out, or pass --overwrite to replace that run")
            run = set(run_files(directory)) if holds_a_run(directory) else set()
            others = sorted(path.name for path in directory.iterdir() if path.name not in run | {MANIFEST})
            if others:
                raise OutputError(f"output folder {directory} holds files that are not a drake-traj run "
                                  f"({', '.join(others[:3])}{', ...' if len(others) > 3 else ''}); choose a new or "
                                  "empty folder")
    except OSError as error:  # a name too long, a loop of links, ...
        raise OutputError(f"output folder {directory} cannot be used: {error.strerror}") from None
    return directory


def begin_output(directory, *, overwrite: bool = False) -> Path:
    """Right before a run's files are written: check ``directory`` again (:func:`check_output`),
    remove the earlier run's files when ``overwrite``, and create the folder; returns it."""
    directory = check_output(directory, overwrite=overwrite)
    if directory.is_dir() and holds_a_run(directory):
        clear_run(directory)
    return create_folder(directory)


def create_folder(directory: Path) -> Path:
    """``directory`` created if needed (:func:`check_writable` first); OutputError naming it."""
    try:
        check_writable(directory)
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputError(f"output folder {directory} cannot be created: {error.strerror}") from None
    return directory


def run_files(directory: Path) -> list[str]:
    """The names of the files of the run in ``directory`` (manifest not included): those its
    manifest lists, or for a run without a manifest, its result, metrics, figures and recording."""
    manifest = directory / MANIFEST
    if manifest.is_file():
        try:
            names = json.loads(manifest.read_text())["files"]
            return [Path(str(name)).name for name in names]  # never outside the folder
        except (ValueError, KeyError, TypeError):
            raise OutputError(f"{manifest} is damaged: cannot tell which files belong to the earlier run; "
                              "remove them by hand") from None
    return [path.name for path in directory.iterdir()
            if path.name in _RUN_FILES or path.suffix == ".png" or path.name == "meshcat.html"]


def clear_run(directory: Path) -> None:
    """Remove the files of the run in ``directory`` (:func:`run_files`) and its manifest."""
    for name in run_files(directory) + [MANIFEST]:
        path = directory / name
        if path.is_file():
            path.unlink()


def write_manifest(directory: Path, files, **details) -> Path:
    """Write ``run.json``: the run's file names and ``details`` (scenario, failure, ...)."""
    path = Path(directory) / MANIFEST
    path.write_text(json.dumps({"files": sorted(Path(name).name for name in files), **details}, indent=2))
    return path


def add_to_manifest(directory: Path, name: str) -> None:
    """List the file ``name`` (e.g. an export) in the manifest of the run in ``directory``, so that
    replacing the run removes it too."""
    path = Path(directory) / MANIFEST
    details = json.loads(path.read_text())
    details["files"] = sorted(set(details["files"]) | {Path(name).name})
    path.write_text(json.dumps(details, indent=2))
