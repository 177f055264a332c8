"""Compiled kernels: :func:`compiled`, numba's nopython compilation with an on-disk cache.

The hot paths that run thousands of times per simulated second (the UR10e's closed-form
kinematics, the Pająk 2024 law and its integrator) are compiled by numba. The first call in a
fresh installation compiles them (seconds); numba then stores the machine code and later
processes load it (``cache=True``). Where the cache lives, in numba's order:

1. ``$NUMBA_CACHE_DIR`` when set;
2. ``__pycache__`` next to the module's source, when writable (a development checkout, a user's
   virtual environment);
3. the user-wide cache directory (``~/.cache/numba`` on Linux), e.g. for a read-only
   system-wide installation;

and when none of them is writable, the kernels are compiled in every process instead of failing
at import. IEEE semantics hold (no fastmath): a division by zero gives ±inf or NaN as in numpy
(``error_model="numpy"``), never an exception.

numba checks a cached function against its own source file only (numba issue #1833): a cached
function that calls compiled code of another module would go on running the old code after an
edit of that module. Such a function is made in a closure over :func:`sources_digest` of the
modules it reaches (numba hashes a function's closure into its cache key): the pattern of
``drake_traj.planners.pajak.kernel``, ``drake_traj.robots.compiled_kinematics``,
``drake_traj.robots.ur_closed_form``, ``drake_traj.robots.chain_kinematics`` and
``drake_traj.robots.ur_ik``.
"""

import hashlib
from pathlib import Path

import numba

__all__ = ["compiled", "sources_digest"]


def compiled(function):
    """``function`` compiled by numba in nopython mode, cached on disk where possible (see the
    module docstring). The result is called like the function, from Python or from other
    compiled functions."""
    try:
        return numba.njit(cache=True, error_model="numpy")(function)
    except RuntimeError:  # numba found no writable cache directory: compile in each process
        return numba.njit(error_model="numpy")(function)


def sources_digest(*files) -> str:
    """sha256 of the source ``files`` (each once, in sorted order): the value a compiled function
    that reaches compiled code of those files closes over (see the module docstring)."""
    digest = hashlib.sha256()
    for file in sorted(set(map(str, files))):
        digest.update(Path(file).read_bytes())
    return digest.hexdigest()
