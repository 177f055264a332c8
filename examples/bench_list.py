"""Benchmark: how long ``drake-traj list`` takes, against Python importing the package.

    python examples/bench_list.py [--runs 5]

Runs ``drake-traj list`` (as ``python -m drake_traj.cli list``, output discarded) and ``python -c
'import drake_traj'`` ``runs`` times each, alternately, in fresh processes, and prints the median
wall time of each, their ratio and the conditions (the load average and the cores): ``list``
reads the shipped scenario files as plain YAML (``drake_traj.catalogue``) without importing
Drake, so it should stay within a few times a bare import and well under the target of 1 s. A
benchmark, not a test: times depend on the machine and on what else it runs.
"""

import argparse
import os
import statistics
import subprocess
import sys
import time

TARGET_S = 1.0  # drake-traj list at once


def wall_time(command: list[str]) -> float:
    """Wall time [s] of one run of ``command`` in a fresh process; its failure raised."""
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="runs of each command (default 5)")
    runs = parser.parse_args().runs
    commands = {"drake-traj list": [sys.executable, "-m", "drake_traj.cli", "list"],
                "import drake_traj": [sys.executable, "-c", "import drake_traj"]}
    for command in commands.values():  # warm the file cache and Python's bytecode cache
        wall_time(command)
    times = {name: [] for name in commands}
    for _ in range(runs):
        for name, command in commands.items():
            times[name].append(wall_time(command))
    medians = {name: statistics.median(values) for name, values in times.items()}
    load = ", ".join(f"{value:.2f}" for value in os.getloadavg())
    print(f"conditions: load average {load} (1, 5, 15 min) on {os.cpu_count()} cores; median of {runs} runs")
    for name, median in medians.items():
        print(f"{name:18} {median:6.3f} s   (runs: {', '.join(f'{value:.3f}' for value in times[name])})")
    ratio = medians["drake-traj list"] / medians["import drake_traj"]
    verdict = "within" if medians["drake-traj list"] < TARGET_S else "over"
    print(f"list / import ratio {ratio:.1f}; list is {verdict} the {TARGET_S:g} s target")


if __name__ == "__main__":
    main()
