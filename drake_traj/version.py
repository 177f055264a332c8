"""The installed package's version (pyproject.toml is its one source)."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("drake_traj")
except PackageNotFoundError:  # run from a source tree that is not installed
    __version__ = "unknown"
