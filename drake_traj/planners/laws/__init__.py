"""Pure time laws, apart from the Drake systems (numpy and numba only, no pydrake): the time-law
contract (:mod:`.contract`), the tabulated Hermite law (:mod:`.hermite`), the exact rate peaks of
polynomial laws (:mod:`.polynomials`) and the scaled clock with eq. 18 of Pająk 2024
(:mod:`.scaling`)."""

from drake_traj.planners.laws.contract import TimeLaw, missing_members
from drake_traj.planners.laws.hermite import HermiteLaw, joint_speed_cap

__all__ = ["HermiteLaw", "TimeLaw", "joint_speed_cap", "missing_members"]
