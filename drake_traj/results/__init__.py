"""What a run leaves: the :class:`SimulationResult` with its metrics and figures (:mod:`.result`),
the reference taken out as a PiecewisePolynomial, CSV, URScript or ROS 2 (:mod:`.exports`),
run folders (:mod:`.rundir`) and the one writer of files and folders (:mod:`.output`)."""

from drake_traj.results.result import (ARRAY_NAMES, DEFAULT_TRACKING_TOLERANCE, LOGGERS, Metrics, ResultFileError, SimulationResult, joint_style)
from drake_traj.results.exports import (FORMATS, ExportError, export, reference_trajectory, resample)
from drake_traj.results.rundir import (MANIFEST, REFUSAL, OutputError, add_to_manifest, claim_run_folder, earlier_run, estimated_size, manifest_text, run_files, write_manifest)
from drake_traj.results.output import (FOLDER_KINDS, LOCK, Claim, WriteError, check_folder, check_writable, claim, folder_kind, locked, working_folder, write_file)

__all__ = ['ARRAY_NAMES', 'Claim', 'DEFAULT_TRACKING_TOLERANCE', 'ExportError', 'FOLDER_KINDS', 'FORMATS', 'LOCK', 'LOGGERS', 'MANIFEST', 'Metrics', 'OutputError', 'REFUSAL', 'ResultFileError', 'SimulationResult', 'WriteError', 'add_to_manifest', 'check_folder', 'check_writable', 'claim', 'claim_run_folder', 'earlier_run', 'estimated_size', 'export', 'folder_kind', 'joint_style', 'locked', 'manifest_text', 'reference_trajectory', 'resample', 'run_files', 'working_folder', 'write_file', 'write_manifest']
