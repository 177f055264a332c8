"""The limits a timing keeps: per joint velocity, acceleration and jerk, the default jerk limit,
a config's limits with the robot's defaults (:func:`jerk_limited_limits`) and the least
durations they allow (:func:`check_least_durations`). Joint positions in rad, limits in rad/s,
rad/s² and rad/s³.

Jerk limit: the UR10e publishes no joint jerk limit. The default here is
``DEFAULT_JERK_FACTOR`` = 10 [1/s] times the acceleration limit, i.e. the acceleration ramps
from 0 to its limit in 0.1 s (14 rad/s^3 for 1.40 rad/s^2)."""

import numpy as np

from drake_traj.errors import joint_label
from drake_traj.planners.base import joint_move_limits
from drake_traj.planners.timing.motion import InfeasibleTimingError
from drake_traj.robots import Robot
from drake_traj.validation import limit_or_default, positive_vector

__all__ = ["DEFAULT_JERK_FACTOR", "check_least_durations", "default_jerk_limit", "jerk_limited_limits", "joint_limits"]

DEFAULT_JERK_FACTOR = 10.0
"""Default jerk limit = DEFAULT_JERK_FACTOR [1/s] * acceleration limit (UR10e publishes none)."""


def default_jerk_limit(acceleration_limit):
    """The default jerk limit [rad/s^3]: 10 [1/s] times ``acceleration_limit`` [rad/s^2]."""
    return DEFAULT_JERK_FACTOR * np.asarray(acceleration_limit, dtype=float)


def jerk_limited_limits(robot: Robot, velocity_limit, acceleration_limit, jerk_limit):
    """(velocity [rad/s], acceleration [rad/s^2], jerk [rad/s^3]) per joint from a config's
    entries, each empty for its default: the robot's joint-move limits, and
    :func:`default_jerk_limit` of the acceleration limit."""
    velocity, acceleration = joint_move_limits(robot, velocity_limit, acceleration_limit)
    return velocity, acceleration, limit_or_default(jerk_limit, default_jerk_limit(acceleration), "jerk_limit",
                                                    robot.num_joints)


def joint_limits(n: int, velocity_limit, acceleration_limit, jerk_limit):
    """(velocity [rad/s], acceleration [rad/s²], jerk [rad/s³]) per joint of n, checked; a jerk
    limit of None is 10 /s × the acceleration limit."""
    velocity = positive_vector(velocity_limit, "velocity_limit", n)
    acceleration = positive_vector(acceleration_limit, "acceleration_limit", n)
    jerk = default_jerk_limit(acceleration) if jerk_limit is None else positive_vector(jerk_limit, "jerk_limit", n)
    return velocity, acceleration, jerk


def check_least_durations(distance: np.ndarray, limits, max_duration: float, verb: str) -> None:
    """An InfeasibleTimingError naming the joint and the limit where one limit alone makes a
    rest-to-rest move of ``distance`` [rad] per joint last longer than ``max_duration`` [s]: it
    lasts at least d / v, 2 sqrt(d / a) and (32 d / J)^(1/3)."""
    velocity, acceleration, jerk = limits
    bounds = {"velocity_limit": (distance / velocity, velocity, "rad/s"),
              "acceleration_limit": (2 * np.sqrt(distance / acceleration), acceleration, "rad/s²"),
              "jerk_limit": (np.cbrt(32 * distance / jerk), jerk, "rad/s³")}
    for name, (least, limit, unit) in bounds.items():
        if not np.max(least) <= max_duration:
            j = int(np.argmax(least))
            raise InfeasibleTimingError(
                f"the limits are too small for the path: {joint_label(j)} {verb} {distance[j]:.4g} rad with at most "
                f"{limit[j]:.4g} {unit} ({name}): at least {least[j]:.4g} s, longer than max_duration {max_duration:g} s",
                field=("path",))
