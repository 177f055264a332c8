"""Plan synchronised quintic moves (seed 004) and run them on the simulated UR10e.

    python examples/quintic_ptp.py [OUT_DIR]
"""

import sys

from drake_traj.diagram import simulate
from drake_traj.planners.quintic import QuinticPtpPlanner, plan_synchronized_quintic
from drake_traj.scenario import PAJAK_Q0

GOALS = [[-0.9, -1.9, -1.9, -0.9, 1.2, 1.4], [-0.3, -1.2, -1.5, -1.9, 1.8, 0.2]]  # [rad]
VELOCITY_LIMIT, ACCELERATION_LIMIT = 1.05, 1.40  # [rad/s], [rad/s^2], every joint

plan = plan_synchronized_quintic(PAJAK_Q0, GOALS, VELOCITY_LIMIT, ACCELERATION_LIMIT)
result = simulate(QuinticPtpPlanner(plan, VELOCITY_LIMIT, ACCELERATION_LIMIT), name="example")
metrics = result.metrics()
print(f"T = {metrics['duration_s']:.3f} s, max TCP tracking error = {1e3 * metrics['tracking_error_tcp_max_m']:.3f} mm")
result.save(sys.argv[1] if len(sys.argv) > 1 else "out/example")
result.save_figures(sys.argv[1] if len(sys.argv) > 1 else "out/example")
