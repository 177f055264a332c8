"""Ctrl-C and SIGTERM in ``drake-traj``: both stop a command as a KeyboardInterrupt, noted so that
the exit code tells them apart (:func:`signals_as_interrupts`, from the first moment of
:func:`drake_traj.cli.main`), and are held where stopping would cut something in half: a run's
files being written, an extension module of Drake being imported (:func:`signals_held`). Light:
the parser uses it before Drake is imported."""

import contextlib
import signal
import threading

__all__ = ["signals_as_interrupts", "signals_held"]


@contextlib.contextmanager
def signals_as_interrupts(state):
    """Ctrl-C raises KeyboardInterrupt, as Python's own handler does, and is noted in
    ``state.interrupted`` (an extension module interrupted while it is imported turns it into an
    ImportError); SIGTERM (a job scheduler, ``kill``) stops the command as Ctrl-C does, noted in
    ``state.terminated``, the run's log kept. A Ctrl-C ignored by the caller (SIG_IGN) stays
    ignored; the earlier handlers are restored after. Outside the main thread, signals are not
    ours to handle."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def interrupt(signum, frame):
        setattr(state, "terminated" if signum == signal.SIGTERM else "interrupted", True)
        raise KeyboardInterrupt

    numbers = [signal.SIGTERM] + [signal.SIGINT] * (signal.getsignal(signal.SIGINT) is signal.default_int_handler)
    previous = {number: signal.signal(number, interrupt) for number in numbers}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


@contextlib.contextmanager
def signals_held(on_signal=None):
    """Ctrl-C and SIGTERM held while the block runs (writing a run's files, importing Drake):
    noted, not raised, and ``on_signal(signum)`` called when one comes (e.g. to leave the process
    at once); yields the list of the signals received meanwhile. A signal the process ignores
    stays ignored; outside the main thread, signals are not ours to handle."""
    received = []
    if threading.current_thread() is not threading.main_thread():
        yield received
        return

    def hold(signum, frame):
        received.append(signum)
        if on_signal is not None:
            on_signal(signum)

    numbers = [number for number in (signal.SIGINT, signal.SIGTERM) if signal.getsignal(number) is not signal.SIG_IGN]
    previous = {number: signal.signal(number, hold) for number in numbers}
    try:
        yield received
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
