"""drake_traj: published trajectory planners as Drake systems on a simulated UR10e."""

__version__ = "0.1.0"
