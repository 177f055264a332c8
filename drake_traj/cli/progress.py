"""What a long command (``drake-traj run``, the start of ``bench``) is doing, on stderr, however
its output is kept: :class:`Progress`. On a terminal a tqdm bar (the stage, then the simulated
time); elsewhere (``drake-traj run ... > log 2>&1``, CI, a job scheduler) a line whenever
:data:`LOG_INTERVAL` seconds went by without one: the stage, the time elapsed and, while
simulating, the simulated time of the total and the time left. A background thread keeps it
going while the command is busy in one long step (loading Drake, compiling the numba kernels on
a first run, the cell check). This module is light: no Drake, no numpy."""

import sys
import threading
import time

from tqdm import tqdm

__all__ = ["LOG_INTERVAL", "Progress"]

LOG_INTERVAL = 8.0  # [s] the longest silence where stderr is not a terminal (under 10 s with the thread's delays)
TERMINAL_REFRESH = 1.0  # [s] how often the terminal's bar is redrawn while nothing else changes it
SIMULATING = "simulating"


class Progress:
    """The stage of ``command`` and how far it is, on ``stream`` (default stderr): a tqdm bar on a
    terminal, else a line after ``interval`` seconds of silence (default :data:`LOG_INTERVAL`);
    nothing when not ``enabled`` (``--quiet``). ``clock`` gives the time [s] (a fake one in tests:
    the thread is started only with the real one). Call :meth:`close` at the end (again: no-op)."""

    def __init__(self, command: str, *, stream=None, enabled: bool = True, interval: float | None = None,
                 clock=time.monotonic):
        self._stream = sys.stderr if stream is None else stream
        self._command, self._clock = command, clock
        self._interval = LOG_INTERVAL if interval is None else interval
        self.enabled = enabled
        terminal = enabled and getattr(self._stream, "isatty", lambda: False)()
        self._lines = enabled and not terminal
        self._stage, self._total, self._t, self._since = "starting", None, 0.0, None
        self._start = self._said = clock()
        self._lock = threading.Lock()
        self._bar = tqdm(total=None, desc="starting", file=self._stream, disable=not terminal, bar_format="{desc} [{elapsed}]")
        self._stop = threading.Event()
        self._thread = None
        if enabled and clock is time.monotonic:
            self._thread = threading.Thread(target=self._tick_until_closed, name="drake-traj progress", daemon=True)
            self._thread.start()

    def stage(self, name: str) -> None:
        """The command now does ``name`` ("checking the task in the cell")."""
        with self._lock:
            self._stage = name
            self._bar.set_description_str(name, refresh=True)

    def expect(self, total: float) -> None:
        """The simulation to come takes ``total`` seconds of simulated time."""
        with self._lock:
            self._total, self._t = float(total), 0.0
            self._bar.bar_format = "{desc}: {percentage:3.0f}%|{bar}| {n:.2f}/{total:.2f} s simulated [{elapsed}]"
            self._bar.reset(total=round(total, 3))

    def simulated(self, t: float) -> None:
        """The simulation has reached ``t`` [s] of simulated time (the first call starts the stage
        "simulating"); a ``progress(t)`` of :func:`drake_traj.station.simulate`."""
        with self._lock:
            if self._stage != SIMULATING:
                self._stage, self._since = SIMULATING, self._clock()
                self._bar.set_description_str(SIMULATING, refresh=False)
            self._t = t
            self._bar.n = min(round(t, 3), self._bar.total or 0.0)
            self._bar.update(0)  # redrawn at most every tqdm's mininterval (0.1 s)

    def line(self) -> str:
        """The progress as one line: the stage and the time elapsed; while simulating, the
        simulated time of the total and the time left, estimated at the pace so far."""
        now = self._clock()
        elapsed = f"{_duration(now - self._start)} elapsed"
        if self._stage != SIMULATING or not self._total:
            return f"drake-traj {self._command}: {self._stage}, {elapsed}"
        done = min(self._t / self._total, 1.0)
        left = ""
        if self._t > 0:
            remaining = (now - self._since) / self._t * max(self._total - self._t, 0.0)
            left = f", about {_duration(remaining)} left"
        return (f"drake-traj {self._command}: simulating, {self._t:.2f} of {self._total:.2f} s simulated "
                f"({100 * done:.0f} %), {elapsed}{left}")

    def tick(self) -> None:
        """One step of the background thread: a line where the last was ``interval`` seconds ago
        (not on a terminal), a redraw of the bar on a terminal."""
        with self._lock:
            if self._lines and self._clock() - self._said >= self._interval:
                print(self.line(), file=self._stream, flush=True)
                self._said = self._clock()
            elif not self._lines and self.enabled:
                self._bar.refresh()

    def _tick_until_closed(self) -> None:
        period = self._interval / 8 if self._lines else TERMINAL_REFRESH
        while not self._stop.wait(period):
            try:
                self.tick()
            except (OSError, ValueError):  # the stream was closed under us (a reader that stopped)
                return

    def close(self) -> None:
        """Stop the thread and leave the bar as it is."""
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join()
        with self._lock:
            self._bar.close()


def _duration(seconds: float) -> str:
    """``seconds`` as a line says it: ``7 s`` under 100 s, else ``12:05`` (minutes:seconds) or
    ``1:02:05``."""
    return f"{seconds:.0f} s" if seconds < 99.5 else tqdm.format_interval(seconds)
