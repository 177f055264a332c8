"""Plan synchronised quintic moves (Benotsmane et al.) and run them on the simulated UR10e.

    python examples/quintic_ptp.py [OUT_DIR]
"""

import sys

from drake_traj import QuinticConfig, get_robot, simulate
from drake_traj.planners import make_planner

GOALS = [[-0.9, -1.9, -1.9, -0.9, 1.2, 1.4], [-0.3, -1.2, -1.5, -1.9, 1.8, 0.2]]  # [rad]

ur10e = get_robot("ur10e")
config = QuinticConfig(goals=GOALS, velocity_limit=[1.05] * 6, acceleration_limit=[1.40] * 6)  # rad/s, rad/s^2
result = simulate(make_planner(config, ur10e, ur10e.home_configuration), name="example")
metrics = result.metrics()
print(f"T = {metrics.duration_s:.3f} s, max TCP tracking error = {1e3 * metrics.tracking_error_tcp_max_m:.3f} mm")
out = sys.argv[1] if len(sys.argv) > 1 else "out/example"
result.save(out, overwrite=True)  # this script's own folder: a rerun replaces its run
result.save_figures(out)
