"""The bench's tasks: Pająk 2024's task (q(0), p1..pf) and ``count`` seeded random reachable tasks
(three waypoints, each the flange pose of a random configuration near the previous one), the joint
waypoints (IK) the joint-space planners go through, and the seeded Pająk walks of the law's random
sweep. Poses are task poses (m, 6) [m, rad] of the UR10e's flange in its base frame."""

import functools
from dataclasses import dataclass

import numpy as np

from drake_traj.cell import CellChecker
from drake_traj.planners import PajakConfig
from drake_traj.planners import pajak
from drake_traj.robots import UR10E, ur10e as robot

__all__ = ["Task", "joint_waypoints", "pajak_walk_tasks", "paper_task", "random_tasks", "tasks"]


@dataclass(frozen=True, eq=False)
class Task:
    """A bench task: start configuration q0 [rad] (6,), task poses (m, 6) [m, rad], and how many
    times to repeat the planning-time measurement."""

    label: str
    q0: np.ndarray
    poses: np.ndarray
    repeats: int = 1


def paper_task():
    """(q0, task poses (4, 6)) of Pająk 2024."""
    return pajak.paper_initial_configuration(), pajak.paper_parameters(3).waypoints


def random_tasks(count: int, seed: int = 0):
    """``count`` reachable tasks: three waypoints, each the flange pose of a configuration at most
    0.6 rad per joint from the previous one, at least 0.15 m apart, away from singularities, and
    each configuration inside the default cell (a table flush with the base) with its clearance
    and free of self-collision. The motions between them are checked by each run."""
    rng = np.random.default_rng(seed)
    q0 = pajak.paper_initial_configuration()
    cell = default_cell_checker()
    tasks = []
    while len(tasks) < count:
        configurations = [q0]
        for _ in range(3):
            configurations.append(configurations[-1] + rng.uniform(-0.6, 0.6, 6))
        poses = np.array([robot.task_pose(q) for q in configurations])
        far_enough = np.all(np.linalg.norm(np.diff(poses[:, :3], axis=0), axis=1) > 0.15)
        regular = all(robot.singularity_measure(q) > 0.15 and abs(np.cos(p[4])) > 0.3
                      for q, p in zip(configurations, poses))
        if far_enough and regular and not any(cell.contacts(q) for q in configurations[1:]):
            tasks.append((q0, poses[1:]))
    return tasks


def pajak_walk_tasks(count: int, seed: int = 9, step: float = 0.7) -> list[PajakConfig]:
    """``count`` seeded Pająk tasks of the law's random sweep (tests/planners/test_pajak_random.py):
    walks in joint space from the paper's q(0), each of 1-4 waypoints the flange pose of a
    configuration up to ``step`` [rad] per joint from the previous one, limits drawn from
    0.5-2 rad/s and 0.7-3 rad/s² (one value for every joint or one per joint, by a fair coin).
    Tasks that ``validate()`` refuses (two waypoints closer than the neighbourhood) are drawn
    again. Not filtered for collisions or singularities: the law alone is what they measure."""
    rng = np.random.default_rng(seed)
    q0 = pajak.paper_initial_configuration()
    drawn = []
    while len(drawn) < count:
        configurations = [q0]
        for _ in range(int(rng.integers(1, 5))):
            configurations.append(configurations[-1] + rng.uniform(-step, step, 6))
        if rng.integers(0, 2):
            velocity, acceleration = rng.uniform(0.5, 2.0, 6), rng.uniform(0.7, 3.0, 6)
        else:
            velocity, acceleration = np.full(6, rng.uniform(0.5, 2.0)), np.full(6, rng.uniform(0.7, 3.0))
        task = PajakConfig(waypoints=np.array([robot.task_pose(q) for q in configurations[1:]]),
                           velocity_limit=velocity, acceleration_limit=acceleration)
        try:
            task.validate()
        except ValueError:  # e.g. two waypoints closer than the neighbourhood
            continue
        drawn.append(task)
    return drawn


def tasks(count: int, seed: int = 0, repeats: int = 5) -> list[Task]:
    """The paper task (planning timed ``repeats`` times) and ``count`` seeded random tasks (once)."""
    return [Task("paper", *paper_task(), repeats)] + [
        Task(f"random_{k}", q0, poses) for k, (q0, poses) in enumerate(random_tasks(count, seed))]


def joint_waypoints(q0, poses) -> np.ndarray:
    """q0 and the IK of each pose, each nearest the previous configuration, shape (m + 1, 6)."""
    return np.vstack([q0, robot.inverse_kinematics_path(poses, q0, max_step=np.inf)])


@functools.cache
def default_cell_checker() -> CellChecker:
    """The default cell's checker, one per process (a Dask worker builds its own)."""
    return CellChecker(UR10E)
