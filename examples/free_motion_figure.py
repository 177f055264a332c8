"""The free-motion picture of docs/free-motion.md: diagrams/free_motion_shelf.yaml's shelf seen from the robot, the
TCP path of the planned motion round the boards, and the straight joint move it replaces (which
the cell check refuses), with the configurations where the straight move comes into the shelf.

    python examples/free_motion_figure.py [out.png]
"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from drake_traj import load_scenario  # noqa: E402
from drake_traj.planners.free import Scene  # noqa: E402
from drake_traj.scenario import make_planner  # noqa: E402


def main(argv=None) -> Path:
    argv = sys.argv[1:] if argv is None else argv
    out = Path(argv[0]) if argv else Path(__file__).parent / "figures" / "free_motion_shelf.png"
    scenario = load_scenario("free_motion_shelf")
    checker = scenario.cell_checker()
    planner = make_planner(scenario)
    checker.check_planner(planner)
    robot = scenario.robot_with_tool()
    plan = planner.plan()
    times = np.linspace(0.0, plan.end_time(), 600)
    path = robot.tool_position(plan.vector_values(times).T)
    start, goal = plan.value(0.0).ravel(), plan.value(plan.end_time()).ravel()
    straight_q = start + np.linspace(0.0, 1.0, 600)[:, None] * (goal - start)
    straight = robot.tool_position(straight_q)
    scene = Scene(checker, robot.lower_limits, robot.upper_limits)
    hits = np.array([scene.distance(q) < checker.clearance for q in straight_q])

    figure, (front, side) = plt.subplots(1, 2, figsize=(11, 5), constrained_layout=True)
    for ax, (i, j), label in ((front, (1, 2), "y [m]"), (side, (0, 2), "x [m]")):
        for obstacle in scenario.cell.obstacles:
            centre, size = np.asarray(obstacle.xyz), np.asarray(obstacle.size)
            ax.add_patch(plt.Rectangle((centre[i] - size[i] / 2, centre[j] - size[j] / 2), size[i], size[j],
                                       color="saddlebrown", alpha=0.35, lw=0))
        ax.plot(straight[:, i], straight[:, j], color="grey", ls="--", label="straight joint move (refused)")
        ax.plot(straight[hits, i], straight[hits, j], "x", color="crimson", ms=3,
                label="straight move: arm within the clearance")
        ax.plot(path[:, i], path[:, j], color="tab:blue", lw=2, label="free motion (planned, checked)")
        ax.plot(*path[0, [i, j]], "o", color="tab:green", label="start")
        ax.plot(*path[-1, [i, j]], "s", color="tab:red", label="goal")
        ax.set_xlabel(label)
        ax.set_ylabel("z [m]")
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
    front.set_title("seen from the robot (shelf in brown)")
    side.set_title("seen from the side")
    front.legend(loc="lower left", fontsize=8)
    figure.suptitle(f"free_motion_shelf: {len(planner.legs[0].vertices)} path vertices, T = {plan.end_time():.2f} s, "
                    f"planning {planner.planning_time_s:.2f} s")
    out.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(out, dpi=110)
    print(f"wrote {out}")
    return out


if __name__ == "__main__":
    main()
