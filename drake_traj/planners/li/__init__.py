"""Li, Zhang, Zhou 2019: the Cartesian stage (:mod:`.cartesian`: break-point limits, look-ahead,
seven-case cubic ACC/DEC), the joint stage (:mod:`.joint`: re-timing, quintic B-spline, exact
joint-limit check), our limit repair (:mod:`.repair`: tool check through FK, smooth time warp), the
whole pipeline (:mod:`.plan`) and the planner system with its config (:mod:`.system`)."""
