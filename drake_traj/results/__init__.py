"""What a run leaves: the :class:`SimulationResult` with its arrays and verdict (:mod:`.result`,
:mod:`.arrays`), its metrics (:mod:`.metrics`), its files result.npz and metrics.json
(:mod:`.files`) and its figures (:mod:`.figures`); the reference taken out as a PiecewisePolynomial,
CSV, URScript or ROS 2 (:mod:`.exports`), run folders (:mod:`.rundir`) and the one writer of files
and folders (:mod:`.output`)."""

from drake_traj.results.result import (DEFAULT_TRACKING_TOLERANCE, LOGGERS, SimulationResult)
from drake_traj.results.arrays import (ARRAY_NAMES, LIMIT_NAMES, SHAPES)
from drake_traj.results.metrics import (RENAMED_METRICS, ROUNDING, Metrics, json_ready, metrics_of, round_angle, round_fraction, round_length, round_mass, round_time, round_torque)
from drake_traj.results.files import (ResultFileError, load_result, output_folder, save_result, write_result)
from drake_traj.results.figures import (figures_of, joint_figure, joint_style, save_figures, scaling_figure, tcp_path_figure, tracking_figure)
from drake_traj.results.exports import (FORMATS, ExportError, ExportFormat, ExportOptions, export, reference_trajectory, resample)
from drake_traj.results.rundir import (MANIFEST, REFUSAL, OutputError, add_to_manifest, claim_run_folder, earlier_run, estimated_size, manifest_text, run_files, write_manifest)
from drake_traj.results.output import (FOLDER_KINDS, LOCK, Claim, WriteError, check_folder, check_writable, claim, folder_kind, locked, working_folder, write_file)

__all__ = ['ARRAY_NAMES', 'Claim', 'DEFAULT_TRACKING_TOLERANCE', 'ExportError', 'ExportFormat', 'ExportOptions', 'FOLDER_KINDS', 'FORMATS', 'LIMIT_NAMES', 'LOCK', 'LOGGERS', 'MANIFEST', 'Metrics', 'OutputError', 'REFUSAL', 'RENAMED_METRICS', 'ROUNDING', 'ResultFileError', 'SHAPES', 'SimulationResult', 'WriteError', 'add_to_manifest', 'check_folder', 'check_writable', 'claim', 'claim_run_folder', 'earlier_run', 'estimated_size', 'export', 'figures_of', 'folder_kind', 'joint_figure', 'joint_style', 'json_ready', 'load_result', 'locked', 'manifest_text', 'metrics_of', 'output_folder', 'reference_trajectory', 'resample', 'round_angle', 'round_fraction', 'round_length', 'round_mass', 'round_time', 'round_torque', 'run_files', 'save_figures', 'save_result', 'scaling_figure', 'tcp_path_figure', 'tracking_figure', 'working_folder', 'write_file', 'write_manifest', 'write_result']
