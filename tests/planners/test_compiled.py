"""drake_traj.compiled: numba's on-disk cache where it can write one, compilation in each process
where it cannot (the kernels of the UR10e and of the Pająk 2024 law use it)."""

import importlib.util
import warnings

SOURCE = "from drake_traj.compiled import compiled\n\n\n@compiled\ndef twice(x):\n    return 2.0 * x\n"


def load(path):
    spec = importlib.util.spec_from_file_location(f"kernel_{abs(hash(str(path)))}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_cached_where_a_cache_directory_is_writable(tmp_path):
    (tmp_path / "kernel.py").write_text(SOURCE)
    twice = load(tmp_path / "kernel.py").twice
    assert twice(1.5) == 3.0
    assert twice.stats.cache_path == str(tmp_path / "__pycache__")
    assert list((tmp_path / "__pycache__").glob("kernel.twice-*.nbi"))


def test_compiled_without_a_cache_when_no_directory_is_writable(tmp_path):
    # numba finds no cache directory for a function whose source file it cannot see, as for a
    # read-only installation without a writable user cache: compiled anyway, not cached
    (tmp_path / "kernel.py").write_text(SOURCE)
    module = load(tmp_path / "kernel.py")
    (tmp_path / "kernel.py").unlink()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        twice = module.compiled(module.twice.py_func)
    assert twice(1.5) == 3.0
    assert twice.stats.cache_path is None
