"""The cubic ACC/DEC profile of one straight segment (Li et al. 2019, Li, Zhang, Zhou: section 2, eq. 11-13,
Tables 1-2): the speed law from V_s to V_e over a length L, one of seven cases.

Each ramp follows eq. 11 with the average ACC/DEC acceleration A = (2/3) a_m of eq. 12, so its peak
is exactly a_m; :mod:`drake_traj.planners.li.cartesian` lays these profiles end to end along the
polyline after its look-ahead. Equation numbers in comments are the paper's; the corrections in
docs/papers.md are followed and win where they differ:

- eq. 13 uses A = (2/3) a_m, not a_m: the cubic ramp's peak acceleration is 1.5 times its
  average, so with A = (2/3) a_m the peak is exactly a_m;
- eq. 13: L_e = (2 V_m^2 - V_s^2 - V_e^2) / (2A), V_a = sqrt((2 A L + V_s^2 + V_e^2) / 2);
- the seven cases and their times are the list of docs/papers.md (see :class:`AccDecCase`).

Everything here is plain numpy; tests call the functions directly. Units: metres, seconds.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

import numpy as np

from drake_traj.validation import invalid, nonnegative_scalar, positive_scalar

__all__ = ["AccDecCase", "AccDecProfile", "acc_dec_profile", "acc_dec_state", "average_acceleration", "classify_acc_dec"]

# Relative tolerance of the ACC/DEC classification: a segment whose length is within this fraction
# of the minimum length |V_e^2 - V_s^2| / (2A) is the pure ACC (II) or DEC (III) case, and start or
# end speeds this little above V_m count as V_m. Covers the round-off of the look-ahead (eq. 9-10),
# which leaves L and L_min equal to a few ulps.
_RTOL = 1e-9


def average_acceleration(a_max: float) -> float:
    """Average ACC/DEC acceleration A = (2/3) a_m [m/s^2] (eq. 12).

    The cubic ramp (eq. 11) has its peak acceleration at mid-ramp, 1.5 times its average, so a
    ramp planned with A = (2/3) a_m peaks at exactly a_m.
    """
    return 2.0 / 3.0 * positive_scalar(a_max, "a_max", "m/s^2")


class AccDecCase(IntEnum):
    """The seven velocity profiles of Fig. 3 / Table 1 (numbering and times as corrected in docs/papers.md).

    With A = (2/3) a_m, L_min = |V_e^2 - V_s^2| / (2A) and L_e, V_a from eq. 13:

    - I: uniform, V_s = V_e = V_m; T = L / V_m.
    - II: accelerate only, V_s < V_e, L = L_min; T = (V_e - V_s) / A.
    - III: decelerate only, V_s > V_e, L = L_min; T = (V_s - V_e) / A.
    - IV: uniform then decelerate, V_s = V_m > V_e, L > L_e; T = (2AL + (V_m - V_e)^2) / (2 A V_m).
    - V: accelerate then uniform, V_s < V_e = V_m, L > L_e; T = (2AL + (V_m - V_s)^2) / (2 A V_m).
    - VI: accelerate to V_a < V_m then decelerate, L_min < L < L_e; T = (2 V_a - V_s - V_e) / A.
    - VII: accelerate, uniform, decelerate, V_s, V_e < V_m, L >= L_e;
      T = (2AL + (V_m - V_s)^2 + (V_m - V_e)^2) / (2 A V_m).

    Every ramp peaks at a_m, so all cases but I reach a_m; I has zero acceleration.
    """

    I = 1  # noqa: E741 (the paper's roman numeral)
    II = 2
    III = 3
    IV = 4
    V = 5
    VI = 6
    VII = 7


def _segment_inputs(length, v_start, v_end, v_max, a_max):
    length = positive_scalar(length, "length", "m")
    v_m = positive_scalar(v_max, "v_max", "m/s")
    acc = average_acceleration(a_max)
    v_s = nonnegative_scalar(v_start, "v_start", "m/s")
    v_e = nonnegative_scalar(v_end, "v_end", "m/s")
    for name, value in (("v_start", v_s), ("v_end", v_e)):
        if value > v_m * (1.0 + _RTOL):
            raise invalid(name, f"{name} = {value} m/s must be <= v_max = {v_m} m/s")
    v_s, v_e = min(v_s, v_m), min(v_e, v_m)
    l_min = abs(v_e**2 - v_s**2) / (2.0 * acc)  # eq. 8 with A
    if length < l_min * (1.0 - _RTOL):
        raise ValueError(
            f"length = {length} m is too short to change speed from v_start = {v_s} m/s to "
            f"v_end = {v_e} m/s with average acceleration A = (2/3) a_max = {acc} m/s^2: it needs "
            f"|v_end^2 - v_start^2| / (2A) = {l_min} m (eq. 8); run the look-ahead first"
        )
    return length, v_s, v_e, v_m, acc, l_min


def _classify(length, v_s, v_e, v_m, acc, l_min) -> AccDecCase:
    if v_s == v_m and v_e == v_m:
        return AccDecCase.I
    if length <= l_min * (1.0 + _RTOL):  # L = L_min: the whole segment is one ramp
        return AccDecCase.II if v_e > v_s else AccDecCase.III
    if v_s == v_m:
        return AccDecCase.IV
    if v_e == v_m:
        return AccDecCase.V
    l_e = (2.0 * v_m**2 - v_s**2 - v_e**2) / (2.0 * acc)  # eq. 13 (with A)
    return AccDecCase.VI if length < l_e else AccDecCase.VII


def classify_acc_dec(length, v_start, v_end, v_max, a_max) -> AccDecCase:
    """Which of the seven ACC/DEC profiles (Table 1) a segment follows.

    Args:
        length: L [m], > 0.
        v_start, v_end: V_s, V_e [m/s], in [0, v_max] (up to 1e-9 relative above v_max is clipped).
        v_max: V_m [m/s], > 0.
        a_max: a_m [m/s^2], > 0 (A = (2/3) a_m).

    Returns:
        :class:`AccDecCase`. A length within 1e-9 relative of L_min counts as L = L_min (II or III).

    Raises:
        ValueError: non-positive length or limits, negative or too-high speeds, or L < L_min.
    """
    return _classify(*_segment_inputs(length, v_start, v_end, v_max, a_max))


def _smoothstep(tau):
    """The shape of eq. 11 on tau = (t - T_0) / (T_1 - T_0) in [0, 1]: 3 tau^2 - 2 tau^3."""
    return tau * tau * (3.0 - 2.0 * tau)


def acc_dec_state(t, length, v_s, v_c, v_e, t_acc, t_uni, t_dec):
    """s(t) [m], v(t) [m/s], a(t) [m/s^2] of ramp (v_s -> v_c, t_acc) + uniform (v_c, t_uni) + ramp
    (v_c -> v_e, t_dec) along a segment of ``length`` [m] (speeds [m/s], durations [s]).

    All arguments broadcast (:meth:`AccDecProfile.sample` for one segment,
    :meth:`~drake_traj.planners.li.cartesian.CartesianPlan.sample` for many at once). t is the time
    since the segment start [s]; it is clipped to [0, T]. The deceleration ramp is evaluated
    backwards from the segment end, so s(T) = L exactly.
    """
    duration = t_acc + t_uni + t_dec
    t = np.clip(t, 0.0, duration)
    in_acc = t < t_acc
    in_dec = t > t_acc + t_uni
    # Acceleration ramp, eq. 11 with T_0 = 0, T_1 = t_acc:
    # v = v_s + (v_c - v_s) S(tau), s = integral of v, a = (v_c - v_s) / t_acc * 6 tau (1 - tau).
    tau = np.where(in_acc, t / np.where(t_acc > 0.0, t_acc, 1.0), 1.0)
    dv1 = v_c - v_s
    s_acc = v_s * t + dv1 * np.where(in_acc, t_acc, 0.0) * tau**3 * (1.0 - 0.5 * tau)
    v_acc = v_s + dv1 * _smoothstep(tau)
    a_acc = 6.0 * dv1 / np.where(t_acc > 0.0, t_acc, 1.0) * tau * (1.0 - tau)
    # Uniform phase.
    d_acc = 0.5 * (v_s + v_c) * t_acc
    s_uni = d_acc + v_c * (t - t_acc)
    # Deceleration ramp, seen backwards from the end: over the remaining time r = T - t it is an
    # eq. 11 ramp from v_e up to v_c (S(1 - x) = 1 - S(x)), and s = L - (distance still to go).
    r = duration - t
    sigma = np.where(in_dec, r / np.where(t_dec > 0.0, t_dec, 1.0), 0.0)
    dv2 = v_c - v_e
    s_dec = length - (v_e * r + dv2 * np.where(in_dec, t_dec, 0.0) * sigma**3 * (1.0 - 0.5 * sigma))
    v_dec = v_e + dv2 * _smoothstep(sigma)
    a_dec = -6.0 * dv2 / np.where(t_dec > 0.0, t_dec, 1.0) * sigma * (1.0 - sigma)

    s = np.where(in_acc, s_acc, np.where(in_dec, s_dec, s_uni))
    v = np.where(in_acc, v_acc, np.where(in_dec, v_dec, v_c))
    a = np.where(in_acc, a_acc, np.where(in_dec, a_dec, 0.0))
    s = np.where(t >= duration, length, np.clip(s, 0.0, length))
    v = np.where(t >= duration, v_e, v)
    return s, v, a + 0.0


@dataclass(frozen=True)
class AccDecProfile:
    """One segment's cubic ACC/DEC speed law (eq. 11): ramp up, cruise, ramp down.

    Ramps follow eq. 11, v = V_0 + (V_1 - V_0)(3 tau^2 - 2 tau^3), whose acceleration
    6 (V_1 - V_0) tau (1 - tau) / T_r is a smooth bell: zero at both ends, peak 1.5 times the
    average at mid-ramp. Every ramp has average A = (2/3) a_m, so its peak is a_m. Speed and
    acceleration are continuous, also between phases.

    Attributes:
        case: the profile (:class:`AccDecCase`).
        length: L [m].
        v_start, v_end: V_s, V_e [m/s].
        v_cruise: the speed between the ramps [m/s]: V_m (I, IV, V, VII), V_a (VI), V_e (II) or
            V_s (III).
        v_max: V_m [m/s].
        a_max: a_m [m/s^2] (peak of every ramp).
        t_acc, t_uniform, t_dec: durations of the acceleration, uniform and deceleration phases
            [s], each >= 0.
    """

    case: AccDecCase
    length: float
    v_start: float
    v_end: float
    v_cruise: float
    v_max: float
    a_max: float
    t_acc: float
    t_uniform: float
    t_dec: float

    @property
    def duration(self) -> float:
        """T = t_acc + t_uniform + t_dec [s] (Table 2)."""
        return self.t_acc + self.t_uniform + self.t_dec

    @property
    def peak_acceleration(self) -> float:
        """Largest |a(t)| [m/s^2]: 1.5 times the ramp average (the mid-ramp value), 0 in case I."""
        peaks = [0.0]
        if self.t_acc > 0.0:
            peaks.append(1.5 * (self.v_cruise - self.v_start) / self.t_acc)
        if self.t_dec > 0.0:
            peaks.append(1.5 * (self.v_cruise - self.v_end) / self.t_dec)
        return max(peaks)

    def sample(self, t):
        """Distance s [m], speed v [m/s] and tangential acceleration a [m/s^2] at time ``t``.

        Args:
            t: time since the segment start [s], scalar or array; clipped to [0, duration].

        Returns:
            (s, v, a), each with the shape of ``t``. s(0) = 0, s(T) = L exactly.
        """
        t = np.asarray(t, dtype=float)
        s, v, a = acc_dec_state(
            t, self.length, self.v_start, self.v_cruise, self.v_end,
            self.t_acc, self.t_uniform, self.t_dec,
        )
        return s[()], v[()], a[()]


def acc_dec_profile(length, v_start, v_end, v_max, a_max) -> AccDecProfile:
    """The cubic ACC/DEC profile that covers ``length`` from V_s to V_e in minimum time.

    Classifies the segment (Table 1, :func:`classify_acc_dec`) and sets the phases so that every
    ramp has the average acceleration A = (2/3) a_m (eq. 12) and so peaks at a_m, and the total
    time is Table 2's (docs/papers.md). Cases II and III (L = L_min to 1e-9) use T = 2 L / (V_s + V_e),
    which equals (V_e - V_s) / A there and makes the distance covered exactly L.

    Args:
        length: L [m], > 0.
        v_start, v_end: V_s, V_e [m/s], in [0, v_max].
        v_max: V_m [m/s], > 0.
        a_max: a_m [m/s^2], > 0.

    Returns:
        :class:`AccDecProfile`.

    Raises:
        ValueError: as :func:`classify_acc_dec`.
    """
    length, v_s, v_e, v_m, acc, l_min = inputs = _segment_inputs(
        length, v_start, v_end, v_max, a_max
    )
    case = _classify(*inputs)
    t_acc = t_uni = t_dec = 0.0
    if case == AccDecCase.I:
        v_c = v_m
        t_uni = length / v_m  # Table 2, I: L / V_m
    elif case in (AccDecCase.II, AccDecCase.III):
        # Table 2, II / III: |V_e - V_s| / A; written as 2 L / (V_s + V_e) (equal when L = L_min)
        # so the ramp covers L exactly.
        ramp = 2.0 * length / (v_s + v_e)
        if case == AccDecCase.II:
            v_c, t_acc = v_e, ramp
        else:
            v_c, t_dec = v_s, ramp
    else:
        if case == AccDecCase.VI:
            v_c = np.sqrt((2.0 * acc * length + v_s**2 + v_e**2) / 2.0)  # eq. 13, V_a
            v_c = float(min(max(v_c, v_s, v_e), v_m))
        else:  # IV, V, VII reach V_m
            v_c = v_m
        t_acc = (v_c - v_s) / acc
        t_dec = (v_c - v_e) / acc
        d_ramps = (v_c**2 - v_s**2 + v_c**2 - v_e**2) / (2.0 * acc)
        # Table 2, IV / V / VII: the cruise covers what the ramps leave; VI has none (L = d_ramps).
        t_uni = max(length - d_ramps, 0.0) / v_c if case != AccDecCase.VI else 0.0
    return AccDecProfile(
        case=case, length=length, v_start=v_s, v_end=v_e, v_cruise=float(v_c), v_max=v_m,
        a_max=float(a_max), t_acc=float(t_acc), t_uniform=float(t_uni), t_dec=float(t_dec),
    )

