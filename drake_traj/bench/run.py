"""``drake-traj bench``'s entry point: :func:`bench` checks its arguments and claims its output
folder before any run, runs every (planner, task) unit (:mod:`drake_traj.bench.engine`) and writes
the report (:mod:`drake_traj.bench.report`)."""

import numbers
import sys
from pathlib import Path

from drake_traj.bench.engine import BenchSetupError, _default_workers, _engine, _Progress, run_on, run_serial, where
from drake_traj.bench.report import BENCH_FILES, BENCH_SIZE, write_report
from drake_traj.bench.task_sets import tasks
from drake_traj.bench.units import CONFIG_BUILDERS, PLANNERS, REFERENCE
from drake_traj.results import OutputError, claim

__all__ = ["bench"]

MAX_COUNT = 10_000  # seeded tasks per bench: each costs about 10 s of one core here (all planners)


def _whole_number(value, name, option, least, most=2**32 - 1, why="") -> None:
    """BenchSetupError unless ``value`` (the argument ``name``, option ``option``) is a whole number
    from ``least`` to ``most`` (``why``: what bounds it)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not least <= value <= most:
        raise BenchSetupError(f"{name} ({option}) must be a whole number from {least} to {most}{why}, got {value!r}")


def _check_where(workers, scheduler) -> None:
    """BenchSetupError for ``workers`` or ``scheduler`` (where the runs go) that cannot work."""
    if workers is not None:
        _whole_number(workers, "workers", "--workers", 1, _default_workers(),
                     " (this machine's cores, a process each; for more, a Dask cluster: --scheduler)")
        if scheduler is not None:
            raise BenchSetupError(
                f"workers (--workers {workers}) sizes the local cluster; with --scheduler {scheduler} the runs go "
                "to that cluster's workers: give one of the two")
    if scheduler is not None and (not isinstance(scheduler, str) or not scheduler.strip()):
        raise BenchSetupError(f"scheduler (--scheduler) must be an address such as tcp://host:8786, got {scheduler!r}")


def _check_arguments(count, seed, repeats, workers, scheduler, planners, extra_planners) -> None:
    """BenchSetupError naming the option of the first of :func:`bench`'s arguments that cannot work."""
    _whole_number(count, "count", "--count", 0, MAX_COUNT)
    _whole_number(seed, "seed", "--seed", 0)
    _whole_number(repeats, "repeats", "--repeats", 1, 1000)
    _check_where(workers, scheduler)
    unknown = [name for name in planners if name not in PLANNERS]
    if unknown or not planners:
        raise BenchSetupError(f"planners must be some of {list(PLANNERS)}, got {list(planners)}")
    if "toppra" in planners and REFERENCE not in planners:
        raise BenchSetupError(f"planners: toppra parameterises the path of {REFERENCE}; select both")
    for name, build in extra_planners.items():
        if name in PLANNERS or not callable(build):
            raise BenchSetupError(
                f"extra_planners[{name!r}] must be a new planner name with a config builder, got {build!r}")


def _claim_output_directory(out_dir, overwrite: bool, command: str | None):
    """``out_dir`` claimed for this bench (:func:`drake_traj.results.output.claim`): created, writable,
    not a run's folder, not an earlier bench's unless ``overwrite``, locked; BenchSetupError if
    not (if it is or lies below a file, say)."""
    out_dir = Path(out_dir)
    try:
        return claim(out_dir, "bench", overwrite=overwrite, estimate=BENCH_SIZE, command=command)
    except OutputError as error:
        raise BenchSetupError(f"--out {out_dir}: {error}") from None


def bench(out_dir, *, count: int = 20, seed: int = 0, repeats: int = 5, workers: int | None = None,
          scheduler: str | None = None, planners=PLANNERS, extra_planners: dict | None = None,
          progress=sys.stderr, overwrite: bool = False, command: str | None = None) -> list[dict]:
    """Run the benchmark; writes bench.csv, bench.md and bench.png into ``out_dir``.

    Args:
        out_dir: output directory (created; must not be or lie below a file, nor hold a run, an
            earlier bench or other files). The files are written whole beside the earlier ones
            and replace them only once complete on disk (:mod:`drake_traj.results.output`).
        count: seeded random tasks besides the paper task (>= 0).
        seed: seed of the random tasks (>= 0).
        repeats: planning-time repeats on the paper task (>= 1).
        workers: processes of the local Dask cluster (1 to the machine's cores; default one per
            core); 1 runs every unit in this process, in order, without Dask. The cluster's
            processes are spawned and import the main module: from a script, call ``bench`` under
            ``if __name__ == "__main__":``.
        scheduler: address of an existing Dask scheduler (e.g. ``tcp://host:8786``) to run the
            units on instead of a local cluster; its workers need the same drake_traj. An address
            that does not answer as a Dask scheduler within
            :data:`~drake_traj.bench.engine.SCHEDULER_TIMEOUT` (10 s) is refused.
        planners: the names of :data:`~drake_traj.bench.units.PLANNERS` to run (toppra needs
            pajak_blend).
        extra_planners: more planners to run on every task: name -> ``build(poses, joints)``
            returning a planner config (poses (m, 6) [m, rad], joint waypoints (m + 1, 6)
            [rad]). On Dask, ``build`` must be a top-level function of a module the workers
            can import. A build or planner that raises gives failed rows.
        progress: stream of the progress (stderr by default; None: none): a first line with the
            number of runs and where they run, then on a terminal a bar with the runs done, failed
            and the time left, elsewhere (a log, CI) a line of the same once
            :data:`~drake_traj.bench.engine.LOG_INTERVAL` (8 s) have passed, as a run ends, and at the end. ``print``s
            bench.md's tables and a last line naming the files written.
        overwrite: replace an earlier bench in ``out_dir``.
        command: names this process to another writer of ``out_dir`` (default its command line).

    Returns:
        The rows (one per run, tasks in order, planners in the order of ``planners``, then the
        extra ones) followed by the medians over the random tasks.

    Raises:
        BenchSetupError: a bad argument, output directory or scheduler, before any run.
        drake_traj.results.output.WriteError: the files could not be written (disk full, ...); the
            earlier content of ``out_dir`` is intact.
    """
    planners, extra_planners = tuple(planners), dict(extra_planners or {})
    _check_arguments(count, seed, repeats, workers, scheduler, planners, extra_planners)
    if workers is None and scheduler is None:
        workers = _default_workers()
    builders = {name: CONFIG_BUILDERS[name] for name in planners if name != "toppra"} | extra_planners
    toppra = "toppra" in planners
    with _claim_output_directory(out_dir, overwrite, command) as claimed:
        table, text = _bench(claimed, count, seed, repeats, workers, scheduler, (*planners, *extra_planners), builders,
                             toppra, progress)
    print(text)
    print(f"wrote {out_dir}: {', '.join(BENCH_FILES)}")
    return table


def _bench(claimed, count, seed, repeats, workers, scheduler, names, builders, toppra, progress):
    """The bench of :func:`bench` into its ``claimed`` folder (rows of the planners ``names`` in
    order); returns the table and bench.md's text."""
    with _engine(workers, scheduler) as client:
        bar = _Progress((count + 1) * (len(builders) + toppra), progress, where(workers, scheduler))
        try:
            work = tasks(count, seed, repeats)
            if client is None:
                by_run = run_serial(work, builders, toppra, bar)
            else:
                by_run = run_on(client, work, builders, toppra, bar)
        finally:
            bar.close()
    rows = [by_run[task.label, name] for task in work for name in names]
    failed = sum(not row["succeeded"] for row in rows)
    if failed:
        print(f"{failed} of {len(rows)} runs failed (see the failure column)", file=sys.stderr)
    return write_report(claimed, rows, count)
