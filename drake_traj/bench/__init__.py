"""``drake-traj bench``: every planner and baseline on the Pająk 2024 task and seeded random
tasks through the same closed loop, on Dask distributed: the tasks (:mod:`.task_sets`), T_opt
along a planner's path (:mod:`.optimum`), the planner configs and the work unit of one run
(:mod:`.units`), where the units run and their progress (:mod:`.engine`), the CSV, Markdown and
figure (:mod:`.report`) and the entry point :func:`bench` (:mod:`.run`); the free-motion suite
(``--suite free``): its seeded scenes (:mod:`.free_scenes`) and its runner :func:`free_bench`
(:mod:`.free_suite`); the soak (``--suite soak``): seeded random tasks of every planner on every
shipped arm (:mod:`.soak_tasks`), the checks of a plan written for it (:mod:`.soak_checks`), one
task's run (:mod:`.soak_suite`) and the entry point :func:`soak_bench` with its report
(:mod:`.soak_report`)."""

from drake_traj.bench.task_sets import (Task, joint_waypoints, pajak_walk_tasks, paper_task, random_tasks, tasks)
from drake_traj.bench.optimum import (converged_optimum, optimal_duration)
from drake_traj.bench.units import (COLUMNS, CONFIG_BUILDERS, PLANNERS, run_planner, run_toppra)
from drake_traj.bench.engine import (BenchSetupError)
from drake_traj.bench.report import (bench_figure, medians)
from drake_traj.bench.run import (bench)
from drake_traj.bench.free_scenes import (FreeQuery, FreeScene, SCENE_KINDS, generate)
from drake_traj.bench.free_suite import (ClearanceProbe, free_bench, run_free_query)
from drake_traj.bench.soak_suite import (SOAK_COLUMNS, run_soak_task)
from drake_traj.bench.soak_report import (SOAK_ARMS, SOAK_PLANNERS, merge_soaks, read_soak_csv, soak_bench, soak_summary)

__all__ = ['BenchSetupError', 'ClearanceProbe', 'FreeQuery', 'FreeScene', 'SCENE_KINDS', 'COLUMNS', 'CONFIG_BUILDERS', 'PLANNERS', 'Task', 'bench', 'bench_figure', 'converged_optimum', 'free_bench', 'generate', 'joint_waypoints', 'medians', 'optimal_duration', 'pajak_walk_tasks', 'paper_task', 'random_tasks', 'run_free_query', 'run_planner', 'run_toppra', 'tasks', 'SOAK_ARMS', 'SOAK_COLUMNS', 'SOAK_PLANNERS', 'merge_soaks', 'read_soak_csv', 'run_soak_task', 'soak_bench', 'soak_summary']
