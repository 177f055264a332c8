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
"""

import numba

__all__ = ["compiled"]


def compiled(function):
    """``function`` compiled by numba in nopython mode, cached on disk where possible (see the
    module docstring). The result is called like the function, from Python or from other
    compiled functions."""
    try:
        return numba.njit(cache=True, error_model="numpy")(function)
    except RuntimeError:  # numba found no writable cache directory: compile in each process
        return numba.njit(error_model="numpy")(function)
