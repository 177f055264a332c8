"""Li, Zhang, Zhou 2019: the Cartesian stage (:mod:`.cartesian`: break-point limits, look-ahead,
seven-case cubic ACC/DEC), the joint stage (:mod:`.joint`: IK samples, re-timing, quintic
B-spline, limit repairs) and the planner system with its config (:mod:`.system`)."""
