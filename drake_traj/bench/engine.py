"""Where the bench's work units run: in this process, in order, or on Dask distributed; and the
progress of the runs.

One unit is one (planner, task) run: :func:`~drake_traj.bench.units.run_planner` for the
planners a config describes, :func:`~drake_traj.bench.units.run_toppra` for Toppra. Toppra's row
parameterises ``pajak_blend``'s path, so its unit takes that run's
output as an argument: on Dask, the ``pajak_blend`` future itself, which makes the dependency
explicit to the scheduler (Toppra starts as soon as that one run ends, on whichever worker is
free, while the task's other runs go on elsewhere). We chose runs over whole tasks as the unit
because the runs of a task differ in cost by 10-50x (Pająk's law against a quintic), so
small units keep every worker busy to the end of a sweep, and a failure stays the failure of
one run. ``workers=1`` calls the same functions in this process, in order; otherwise the
runs go to a Dask ``LocalCluster`` of ``workers`` processes, or to the existing cluster whose
scheduler is at ``scheduler`` (its workers need the same drake_traj installed). A run that
raises, or whose worker dies, is a row with ``succeeded`` false, NaN metrics and the reason in
``failure``, never a lost task.
"""

import asyncio
import concurrent.futures
import contextlib
import importlib.metadata
import logging
import os
import sys
import time

from distributed import Client, LocalCluster, as_completed
from distributed.comm import connect as dask_connect
from tqdm import tqdm

from drake_traj.bench.units import REFERENCE, failed_row, failure_reason, run_planner, run_toppra
from drake_traj.errors import DrakeTrajError

__all__ = ["BenchSetupError"]

LOG_INTERVAL = 8.0  # [s] where the progress is not a terminal: a line at the first run to end this long after the last line
SCHEDULER_TIMEOUT = 10.0  # [s] a --scheduler address answers as a Dask scheduler within this, or is refused


class BenchSetupError(DrakeTrajError):
    """A bench argument, output directory or scheduler that cannot work, found before any run."""


def run_serial(work, builders, toppra, bar) -> dict:
    """The rows by (task label, planner name) of every run of the tasks ``work`` in this
    process, in order: the planners ``builders`` (name -> config builder), then Toppra if
    ``toppra``; each row counted by the progress ``bar``."""
    rows = {}
    for task in work:
        for name, build in builders.items():
            output = run_planner(task, name, build, keep_path=toppra and name == REFERENCE)
            rows[task.label, name] = bar.done(output["row"])
            if name == REFERENCE:
                reference = output
        if toppra:
            rows[task.label, "toppra"] = bar.done(run_toppra(task, reference)["row"])
    return rows


def run_on(client, work, builders, toppra, bar) -> dict:
    """:func:`run_serial`'s rows, the runs submitted to the Dask ``client`` and collected as
    they complete; a run whose worker died or could not load it is a failed row."""
    runs = {}  # future -> (task, planner name)
    for task in work:
        for name, build in builders.items():
            future = client.submit(run_planner, task, name, build, toppra and name == REFERENCE, pure=False)
            runs[future] = (task, name)
            if name == REFERENCE:
                reference = future
        if toppra:
            runs[client.submit(run_toppra, task, reference, pure=False)] = (task, "toppra")
    rows = _collect(runs, bar, lambda output: output["row"],
                    lambda unit, reason: failed_row(unit[0].label, unit[1], reason))
    return {(task.label, name): row for (task, name), row in rows.items()}


def _collect(runs: dict, bar, row_of, failed, rows: dict | None = None) -> dict:
    """{unit: row} of the Dask futures ``runs`` ({future: unit}) as they complete: ``row_of`` of
    each one's output, counted by the progress ``bar``; a unit whose worker died or could not load
    it is ``failed(unit, reason)``. Rows go into ``rows`` (a new dict if None) as they come, so a
    caller's dict keeps those done when an interrupt stops the collection."""
    rows = {} if rows is None else rows
    for future in as_completed(runs):
        unit = runs.pop(future)
        try:
            row = row_of(future.result())
        except Exception as error:  # the worker died, or could not load the unit
            row = failed(unit, failure_reason(error))
        rows[unit] = bar.done(row)
        future.release()
    return rows


class _Progress:
    """Runs done, failed and the time left: a tqdm bar on a terminal; on another stream (a log
    file, CI) a line at the first run to end :data:`LOG_INTERVAL` after the last line (a run
    takes seconds: a log is never silent much longer); nothing when the stream is None. A first
    line says how many runs there are and where they run. ``unit`` names a run, ``bad`` what a row
    that did not succeed is, and ``failed(row)`` tells one (the soak: "task", "wrong", a wrong row;
    the free suite: a query not solved)."""

    def __init__(self, total: int, stream, where: str, unit: str = "run", bad: str = "failed",
                 failed=lambda row: not row["succeeded"]):
        self._stream, self._closed = stream, False
        self._unit, self._bad, self._failed = unit, bad, failed
        terminal = stream is not None and getattr(stream, "isatty", lambda: False)()
        self._lines = stream is not None and not terminal
        if stream is not None:
            print(f"bench: {total} {unit}s {where}", file=stream, flush=True)
        self._bar = tqdm(total=total, unit=unit, desc="bench", file=stream or sys.stderr, disable=not terminal,
                         dynamic_ncols=True)
        self.total, self.count, self.failed = total, 0, 0
        self._start = self._said = time.monotonic()

    def done(self, row) -> dict:
        """Count ``row``'s run; returns the row."""
        self.count += 1
        self.failed += bool(self._failed(row))
        self._bar.set_postfix({self._bad: self.failed}, refresh=False)
        self._bar.update()
        if self._lines and time.monotonic() - self._said >= LOG_INTERVAL and self.count < self.total:
            self._say(self.line())
        return row

    def line(self) -> str:
        """The progress after a run as one line: runs done of all, failed, elapsed and the time
        left estimated as the mean time per run so far times the runs left."""
        elapsed = time.monotonic() - self._start
        left = elapsed / self.count * (self.total - self.count)
        return (f"bench: {self.count}/{self.total} {self._unit}s ({100 * self.count / self.total:.0f} %), "
                f"{self.failed} {self._bad}, "
                f"{tqdm.format_interval(elapsed)} elapsed, about {tqdm.format_interval(left)} left")

    def _say(self, text: str) -> None:
        print(text, file=self._stream, flush=True)
        self._said = time.monotonic()

    def close(self):
        """The bar closed and, on a log, the last line; once (a second call does nothing)."""
        if self._closed:
            return
        self._closed = True
        self._bar.close()
        if self._lines:
            self._say(f"bench: {self.count}/{self.total} {self._unit}s in "
                      f"{tqdm.format_interval(time.monotonic() - self._start)}, {self.failed} {self._bad}")


def where(workers: int | None, scheduler: str | None) -> str:
    """Where the runs go, for the progress's first line."""
    if scheduler is not None:
        return f"on the Dask cluster at {scheduler}"
    if workers == 1:
        return "in this process, one after another"
    return f"on a local Dask cluster of {workers} processes"


def _default_workers() -> int:
    """The cores this process may run on: the local cluster's processes by default, and at most."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


async def _dask_handshake(address: str, timeout: float) -> None:
    """Open a Dask connection to ``address`` and close it; raises unless a Dask peer answers
    Dask's handshake within ``timeout`` [s] (Dask's own connect waits for the handshake without
    a time limit: a listener that is not Dask would hold it forever)."""
    # Dask retries a refused connection for 0.8 of the time, so that a refusal is told from silence
    comm = await asyncio.wait_for(dask_connect(address, timeout=0.8 * timeout), timeout)
    await comm.close()


def _connect(scheduler: str) -> Client:
    """A client of the Dask scheduler at ``scheduler`` whose workers have our drake_traj; a
    BenchSetupError naming the address within :data:`SCHEDULER_TIMEOUT` otherwise."""
    advice = ("Give the address a running scheduler prints (e.g. tcp://host:8786), or leave --scheduler out to run "
              "on this machine.")
    try:  # in a thread of its own: bench may be called where an event loop runs (a notebook)
        with concurrent.futures.ThreadPoolExecutor(1) as pool:
            pool.submit(asyncio.run, _dask_handshake(scheduler, SCHEDULER_TIMEOUT)).result()
    except TimeoutError:  # asyncio's since Python 3.11
        raise BenchSetupError(f"--scheduler {scheduler}: something accepts connections there but did not answer as a "
                              f"Dask scheduler within {SCHEDULER_TIMEOUT:g} s. {advice}") from None
    except OSError as error:  # refused (Dask retries until the timeout), unreachable, closed at once
        raise BenchSetupError(f"--scheduler {scheduler}: no Dask scheduler answered there ({failure_reason(error)}; "
                              f"waited at most {SCHEDULER_TIMEOUT:g} s). {advice}") from None
    except ValueError as error:  # a malformed address
        raise BenchSetupError(f"--scheduler {scheduler}: not an address Dask can connect to ({failure_reason(error)}). "
                              f"{advice}") from None
    except Exception as error:  # e.g. MemoryError: a peer's bytes read as a Dask message length
        raise BenchSetupError(f"--scheduler {scheduler}: what answers there does not speak Dask's protocol (reading "
                              f"its reply as Dask's gave {type(error).__name__}). {advice}") from None
    try:
        client = Client(scheduler, timeout=SCHEDULER_TIMEOUT)
    except Exception as error:  # a Dask peer that is not a scheduler (a worker), ...
        raise BenchSetupError(f"--scheduler {scheduler}: cannot connect to a Dask scheduler there "
                              f"({failure_reason(error)}). {advice}") from None
    ours = importlib.metadata.version("drake_traj")
    try:
        theirs = set(client.run(importlib.metadata.version, "drake_traj").values())
    except Exception as error:
        client.close()
        raise BenchSetupError(
            f"--scheduler {scheduler}: a worker of that cluster cannot load drake_traj ({failure_reason(error)}); "
            f"install drake_traj {ours} on every worker."
        ) from None
    if theirs - {ours}:
        client.close()
        raise BenchSetupError(
            f"--scheduler {scheduler}: that cluster's workers have drake_traj {sorted(theirs)}, this is {ours}; "
            "install the same version on every worker."
        )
    if not theirs:
        print(f"--scheduler {scheduler}: the cluster has no workers yet; the runs wait for them", file=sys.stderr)
    return client


@contextlib.contextmanager
def _engine(workers, scheduler):
    """A Dask client of the cluster at ``scheduler`` or of a new local cluster of ``workers``
    processes; None (run in this process) for one local worker."""
    if scheduler is None and workers == 1:
        yield None
        return
    if scheduler is not None:
        with _connect(scheduler) as client:
            yield client
        return
    # no dashboard; the scheduler's HTTP server (health, metrics) on a free local port: on Dask's
    # default 8787 a second cluster (another bench, a notebook) warned "Port 8787 is already in use"
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                      scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}, silence_logs=logging.ERROR) as cluster, \
            Client(cluster) as client:
        yield client

