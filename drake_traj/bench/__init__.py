"""``drake-traj bench``: every planner and baseline on the Pająk 2024 task and seeded random
tasks through the same closed loop, on Dask distributed (:mod:`.suite`)."""

from drake_traj.bench.suite import (COLUMNS, CONFIG_BUILDERS, PLANNERS, BenchSetupError, Task, bench, bench_figure, medians, optimal_duration, pajak_walk_tasks, paper_task, random_tasks, run_planner, run_toppra, tasks)

__all__ = ['BenchSetupError', 'COLUMNS', 'CONFIG_BUILDERS', 'PLANNERS', 'Task', 'bench', 'bench_figure', 'medians', 'optimal_duration', 'pajak_walk_tasks', 'paper_task', 'random_tasks', 'run_planner', 'run_toppra', 'tasks']
