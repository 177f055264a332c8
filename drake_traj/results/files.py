"""A :class:`~drake_traj.results.result.SimulationResult` on disk: ``result.npz`` (its arrays and
metadata) and ``metrics.json`` written into a run folder (:func:`save_result`, :func:`write_result`)
and read back (:func:`load_result`, :class:`ResultFileError`), and the folder figures go into
(:func:`output_folder`)."""

from __future__ import annotations

import json
import zipfile
from dataclasses import fields
from pathlib import Path

import numpy as np

from drake_traj.errors import DrakeTrajError, Failure
from drake_traj.results.arrays import ARRAY_NAMES, LIMIT_NAMES
from drake_traj.results.metrics import json_ready, metrics_of
from drake_traj.results.output import OutputError, check_writable
from drake_traj.results.rundir import claim_run_folder
from drake_traj.validation import path_argument

__all__ = ["ResultFileError", "load_result", "output_folder", "save_result", "write_result"]


class ResultFileError(DrakeTrajError):
    """A saved result cannot be read: names the file and what is wrong with it."""


def output_folder(directory) -> Path:
    """``directory`` (the argument of that name) created if needed, or TypeError/ValueError naming it."""
    directory = path_argument(directory, "directory", "folder")
    try:
        check_writable(directory)
        directory.mkdir(parents=True, exist_ok=True)
    except OutputError as error:
        raise OutputError(f"directory: {error}") from None
    except OSError as error:
        raise OutputError(f"directory: output folder {directory} cannot be created: {error.strerror}") from None
    return directory


def save_result(result, directory, *, overwrite: bool = False) -> Path:
    """Write ``result.npz`` (arrays) and ``metrics.json`` of ``result`` into ``directory``; returns it.
    A folder that holds another run is refused (:class:`~drake_traj.results.rundir.OutputError`) unless
    ``overwrite``, which replaces that run once the new files are complete on disk
    (:mod:`drake_traj.results.output`); so is a bench's folder or one of other files."""
    directory = path_argument(directory, "directory", "folder")
    with claim_run_folder(directory, overwrite=overwrite, samples=len(result.t), options=("directory", "overwrite=True")) \
            as claimed, claimed.replace() as staging:
        write_result(result, staging)
    return directory


def write_result(result, staging) -> None:
    """Write ``result.npz`` and ``metrics.json`` of ``result`` into ``staging``, the new content of a
    claimed run folder (:meth:`drake_traj.results.output.Claim.replace`); :func:`save_result` is the way from
    Python."""
    arrays = {name: getattr(result, name) for name in ARRAY_NAMES + LIMIT_NAMES + ("goal",)}
    failure = None if result.failure is None else result.failure.to_dict()
    meta = {"name": result.name, "duration": result.duration, "failure": failure, "wall_time": result.wall_time,
            "joint_types": list(result.joint_types), "robot": result.robot,
            "waypoint_neighbourhood": result.waypoint_neighbourhood, "planning_time": result.planning_time,
            "unchecked_links": list(result.unchecked_links),
            "unchecked_collision_pairs": [list(pair) for pair in result.unchecked_collision_pairs],
            "estimated_inertia": dict(result.estimated_inertia), "inertia_density": result.inertia_density,
            "locked_joints": dict(result.locked_joints)}
    staging.write("result.npz", lambda path: np.savez_compressed(
        path, meta=json.dumps(json_ready(meta), allow_nan=False), **arrays))
    staging.write("metrics.json", lambda path: path.write_text(
        json.dumps(metrics_of(result).to_dict(), indent=2, allow_nan=False)))


def load_result(cls, directory):
    """The ``cls`` (:class:`~drake_traj.results.result.SimulationResult`) written by
    :func:`save_result` into ``directory``; raises :class:`ResultFileError` naming the file when it
    is missing, truncated, corrupted or inconsistent."""
    path = path_argument(directory, "directory", "folder") / "result.npz"
    if not path.is_file():
        raise ResultFileError(f"no result file at {path}")
    names = {f.name for f in fields(cls)}
    try:
        with np.load(path, allow_pickle=False) as data:
            missing = [name for name in ("meta",) + ARRAY_NAMES + LIMIT_NAMES if name not in data.files]
            if missing:
                raise ResultFileError(f"{path} is not a complete result: it has no {missing[0]!r}")
            meta = json.loads(str(data["meta"]))
            arrays = {name: np.array(data[name]) for name in ARRAY_NAMES + LIMIT_NAMES}
            if "goal" in data.files:  # runs saved before the goal was
                arrays["goal"] = np.array(data["goal"])
    except ResultFileError:
        raise
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as error:
        raise ResultFileError(f"{path} cannot be read (truncated or not a result file): {error}") from None
    if not isinstance(meta, dict) or not {"name", "duration", "failure", "wall_time"} <= set(meta) or set(meta) - names:
        raise ResultFileError(f"{path}: its metadata is not a result's: {meta!r}"[:300])
    samples = len(arrays["t"])
    for name in ARRAY_NAMES:
        if len(arrays[name]) != samples or not np.issubdtype(arrays[name].dtype, np.floating):
            raise ResultFileError(f"{path}: the array {name!r} has {len(arrays[name])} rows of "
                                  f"{arrays[name].dtype}, the log {samples} rows of numbers")
    if arrays["t"].ndim != 1 or not np.all(np.diff(arrays["t"]) > 0):
        raise ResultFileError(f"{path}: the log's times 't' do not increase from sample to sample")
    try:
        if meta["failure"] is not None:
            meta["failure"] = Failure.from_dict(meta["failure"])
        meta["joint_types"] = tuple(meta.get("joint_types", ()))
        meta["unchecked_links"] = tuple(meta.get("unchecked_links", ()))
        meta["unchecked_collision_pairs"] = tuple(tuple(pair) for pair in meta.get("unchecked_collision_pairs", ()))
        for key in ("duration", "wall_time", "waypoint_neighbourhood", "planning_time", "inertia_density"):  # NaN: null
            if key in meta:  # (a result saved before the neighbourhood was has none)
                meta[key] = float("nan") if meta[key] is None else float(meta[key])
    except (KeyError, TypeError, ValueError) as error:
        raise ResultFileError(f"{path}: its metadata is damaged: {error}") from None
    try:
        return cls(**meta, **arrays)
    except (TypeError, ValueError) as error:
        raise ResultFileError(f"{path}: {error}") from None
