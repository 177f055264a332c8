"""What engineers use today, under the same planner contract, for ``drake-traj bench`` and
scenarios: UR-style MoveJ with radius blending (:mod:`.movej`), Ruckig's jerk-limited moves
(:mod:`.ruckig`) and Drake's time-optimal Toppra along a path (:mod:`.toppra`)."""
