"""The Pająk 2024 planner as a Drake system: the motion of :class:`PajakLaw` at speed override 1
(the preflight's), run on a scaled clock so that an override re-times it along the same path."""

from __future__ import annotations

from bisect import bisect_right

import numpy as np

from drake_traj.errors import Cause, PlanningError
from drake_traj.planners.base import DEFAULT_PREFLIGHT_HORIZON, TimeLawPlanner
from drake_traj.planners.laws.hermite import HermiteLaw, joint_speed_cap, quintic_hermite_coefficients
from drake_traj.planners.pajak.integration import integrate
from drake_traj.planners.pajak.law import PajakLaw
from drake_traj.planners.pajak.config import PajakConfig
from drake_traj.robots import UR10E, Robot
from drake_traj.validation import finite_array, invalid, run_duration

__all__ = ["MAX_PREFLIGHT_STEPS", "PajakPlanLaw", "PajakPlanner", "coming_to_rest", "make", "stop_duration"]

# The preflight's integration steps at most: its log holds Log.SIZE values a step (60: 480 MB at
# this bound; 600 s, the longest run, at the default 1 ms update period is 6e5 steps)
MAX_PREFLIGHT_STEPS = 1_000_000
SETTLE_TIME = 4.0  # [s] the law integrated on after the finish, while it settles (sim 3: 1e-6 rad/s after 2.6 s)
REST_SPEED = 1e-6  # [rad/s] the planned motion ends where every joint is slower: at rest
GOAL_MARGIN = 0.5  # the stop after a wandering law ends within this fraction of accuracy and orientation_accuracy
STOP_STRETCH = 1.02  # the stop's duration grows by this factor until its piece keeps the limits
GOAL_STEP = 0.25  # [rad] the largest joint change of one Gauss-Newton step towards the goal at the stop
GOAL_REACH = 0.5  # [rad] the stop's end is sought within this of each joint's position at the stop's free end


def coming_to_rest(qd: np.ndarray, qdd: np.ndarray, jerk: float, qdd_max: np.ndarray) -> tuple[float, np.ndarray]:
    """(T [s], displacement [rad]): the stop from q̇, q̈ [rad/s, rad/s²] (n,) to rest (q̇ = q̈ = 0)
    in T, the quartic of least ∫ jerk² with its end position free (a quintic's natural condition
    there is a zero fifth derivative). With x = s/T and |q̈| <= ``qdd_max`` at the start:

        q̈ = q̈(0) (1 - x)(1 - 3x) - (6 q̇(0)/T) x (1 - x),  jerk -(4 q̈(0) T + 6 q̇(0))/T² at the
        start, (2 q̈(0) T + 6 q̇(0))/T² at the end (linear in s),

    so T is the shortest with (4 |q̈(0)| T + 6 |q̇(0)|)/T² <= ``jerk`` [rad/s³] (q̈ goes on
    continuously from the law's) and T >= 4 |q̇(0)|/q̈_max on every joint, which keeps |q̈| <= q̈_max
    (|(1 - x)(1 - 3x)| + 1.5 x (1 - x) <= 1 on [0, 1]); |q̇| stays below |q̇(0)| + (4/27) |q̈(0)| T."""
    speed, acceleration = np.abs(qd), np.abs(qdd)
    duration = float(max(np.max((4.0 * acceleration + np.sqrt(16.0 * acceleration ** 2 + 24.0 * jerk * speed))
                                / (2.0 * jerk)), np.max(4.0 * speed / qdd_max)))
    c4 = (qd + 0.5 * qdd * duration) / (2.0 * duration ** 3)
    c3 = -(qdd + 12.0 * c4 * duration ** 2) / (6.0 * duration)
    return duration, duration * (qd + duration * (0.5 * qdd + duration * (c3 + duration * c4)))


def stop_duration(qd: np.ndarray, qdd: np.ndarray, displacement: np.ndarray, shortest: float, jerk: float,
                  qd_max: np.ndarray, qdd_max: np.ndarray) -> float:
    """The shortest T [s] >= ``shortest`` (on a grid of ratio :data:`STOP_STRETCH`) of the quintic
    Hermite piece from (0, q̇, q̈) [rad, rad/s, rad/s²] (n,) to (``displacement``, 0, 0) [rad]
    that keeps |q̇| <= ``qd_max``, |q̈| <= ``qdd_max`` (exact peaks, :meth:`HermiteLaw.peak_rates`)
    and its jerk (a quadratic in time) within ``jerk`` [rad/s³]. From :func:`coming_to_rest`'s T:
    a stop whose end is moved off that quartic's free end needs longer (0.15-0.77 s on the soak
    tasks, up to 0.13 rad moved on a walk task that was almost at rest: 0.016 s to 0.85 s).
    PlanningError (cause INFEASIBLE) where no T up to 4e8 ``shortest`` keeps them (a q̈ that the
    stop must hold on over a long way, so that q̇ grows with T)."""
    start = np.stack([np.zeros_like(qd), qd, qdd])
    end = np.stack([displacement, np.zeros_like(qd), np.zeros_like(qd)])
    duration = shortest
    for _ in range(1000):  # T up to 4e8 times ``shortest``
        samples = np.stack([start, end])
        velocity_peak, acceleration_peak = HermiteLaw(np.array([0.0, duration]), samples, samples).peak_rates()
        c = quintic_hermite_coefficients(np.array([0.0, duration]), samples, samples)[0]
        times = [0.0, duration]
        vertex = np.divide(-24.0 * c[4], 120.0 * c[5], out=np.full_like(c[5], -1.0), where=c[5] != 0.0)
        jerk_peak = max(np.abs(6.0 * c[3] + 24.0 * c[4] * s + 60.0 * c[5] * s * s).max()
                        for s in (*times, np.clip(vertex, 0.0, duration)))
        if np.all(velocity_peak <= qd_max) and np.all(acceleration_peak <= qdd_max) and jerk_peak <= jerk:
            return float(duration)
        duration *= STOP_STRETCH
    raise PlanningError(f"the stop after the finish finds no duration up to {duration:g} s within the limits "
                        f"(from q̇ = {np.round(qd, 6).tolist()} rad/s, q̈ = {np.round(qdd, 6).tolist()} rad/s², "
                        f"{np.round(displacement, 6).tolist()} rad to go)", cause=Cause.INFEASIBLE)


class PajakPlanLaw:
    """The Pająk law's motion at speed override 1, as a time law (:class:`~drake_traj.planners.laws.TimeLaw`):
    the preflight's RK4 samples (t, q, q̇, q̈), one per update period up to the finish, joined by
    quintic Hermite pieces (:class:`~drake_traj.planners.laws.HermiteLaw`; q̈ continuous), and
    the law's scaling coefficient c (eq. 17-18) held over each period (``scaling_at``); slowed by
    a constant clock rate where the pieces would pass the law's limits between the samples
    (:meth:`PajakPlanner._within_limits`; law time is then the slowed clock's).

    Made at its first use from the planner's preflight (run then with the default horizon where
    none was run). Where the task fails (a run without a preflight: ``preflight=False``) it is
    the motion up to the failure, and :attr:`failure` is the :class:`PlanningError` the planner
    raises when its clock gets there.
    """

    acceleration_jumps = np.zeros(0)  # the Hermite pieces meet in q, q̇ and q̈

    def __init__(self, planner: "PajakPlanner", q_start: np.ndarray):
        self._planner = planner
        self.q_start = q_start
        self._table = None  # (HermiteLaw, times [s], c per sample, failure or None, finish [s]): at the first use

    def _made(self):
        if self._table is None:
            self._table = self._planner._motion_table()
            hermite = self._table[0]
            self.rates_at, self.sample = hermite.rates_at, hermite.sample  # the hot path, without this wrapper
        return self._table

    @property
    def duration(self) -> float:
        """Law time [s] of the finish (of the failure, where the task fails)."""
        return self._made()[0].duration

    @property
    def polynomial_breaks(self) -> np.ndarray:
        return self._made()[0].polynomial_breaks

    def finish_time(self) -> float:
        """Law time [s] at which the task is complete (eq. 19's last neighbourhood reached with the
        orientation): the motion goes on after it while the law settles to rest."""
        return self._made()[4]

    @property
    def failure(self) -> PlanningError | None:
        """The law's failure at the end of this motion, None where it finishes its task."""
        return self._made()[3]

    def rates_at(self, tau: float):
        return self._made()[0].rates_at(tau)

    def sample(self, tau: float):
        return self._made()[0].sample(tau)

    def scaling_at(self, tau: float) -> float:
        """c of the law [-] over the update period that contains law time ``tau`` [s]."""
        _, times, scaling, _, _ = self._made()
        return float(scaling[min(max(bisect_right(times, tau) - 1, 0), len(scaling) - 1)])


class PajakPlanner(TimeLawPlanner):
    """Pająk 2024's planner as a LeafSystem: the law's motion at speed override 1, run on the
    scaled clock of every time-law planner (:class:`~drake_traj.planners.base.TimeLawPlanner`).

    The law (:class:`PajakLaw`, eq. 13-19) is integrated before the motion by the preflight
    (:func:`integrate`, RK4 at ``update_period``, the motion the cell check examines); the
    reference is that motion, :class:`PajakPlanLaw`. The ``speed_override`` input re-times it
    along the same path, as a UR controller's speed slider does (q̈ continuous, the limits held):
    the motion that runs is the motion that was checked, whatever the override. At override 1
    the reference is the law's own motion (Table 2's times), slowed by a constant rate where its
    pieces would pass the limits between the law's samples (:meth:`_within_limits`: the limits hold
    at every instant of the reference, not only at the samples); the ``scaling`` output is the
    law's c (eq. 17-18) times the clock's rate.

    Without a preflight (``simulate(..., preflight=False)``) the law is integrated when the run
    starts, with the reach check left to the law: a task that fails is run up to its failure and
    the planner raises the law's :class:`PlanningError` there (the run's failure, with its log).

    Args:
        parameters: the task and the law's settings.
        q_initial: joint positions at t = 0 [rad].
        robot: the robot, a 6-axis arm with task-space kinematics (:class:`PajakLaw`; default the
            UR10e); the planner's :attr:`robot`.
    """

    plans_online = True

    def __init__(self, parameters: PajakConfig, q_initial, *, robot: Robot = UR10E):
        self.pajak_law = PajakLaw(parameters, robot)
        self.robot = self.pajak_law.robot
        q_initial = finite_array(q_initial, "q_initial", "rad", shape=(robot.num_joints,))
        self._run = None  # the preflight's integration (:func:`integrate`), kept once it finished
        self._planned = None  # :meth:`_planned_samples` of that integration, made at its first use
        super().__init__(PajakPlanLaw(self, q_initial), self.pajak_law.qd_max, self.pajak_law.qdd_max,
                         update_period=self.pajak_law.parameters.update_period)

    def _motion_table(self):
        """(HermiteLaw, sample times [s], c per sample, failure, finish [s]) of
        :class:`PajakPlanLaw`: the preflight's integration up to rest (:meth:`_rest_index`);
        where none was run, one with the default horizon, and where that fails, the motion up to
        the failure with the error."""
        failure = None
        if self._run is None:
            try:
                self.preflight()
            except PlanningError:
                try:
                    integrate(self.pajak_law, self.initial_positions(), dt=self.pajak_law.parameters.update_period,
                              t_max=DEFAULT_PREFLIGHT_HORIZON, check_reach=False)
                except PlanningError as error:
                    failure = error
        if failure is None:
            times, samples, scaling, rate = self._planned_samples()
        else:
            run = getattr(failure, "partial", None) or {}
            if len(run.get("t", ())) < 2:  # failed at the first step: stand still for one period
                period, start = self.pajak_law.parameters.update_period, self.initial_positions()
                zeros = np.zeros((2, len(start)))
                run = {"t": np.array([0.0, period]), "q": np.stack([start, start]), "qd": zeros, "qdd": zeros,
                       "c": np.zeros(2)}
            samples = np.stack([run["q"], run["qd"], run["qdd"]], axis=1)
            times, samples, scaling, _ = self._within_limits(np.asarray(run["t"]), samples, np.asarray(run["c"]))
        law = HermiteLaw(times, samples, samples)
        finish = law.duration if failure is not None else float(self._run["T"]) / rate
        return law, times, scaling, failure, finish

    def _planned_samples(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """(times [s] (K,), (q, q̇, q̈) (K, 3, n), c (K,), rate) of the planned motion: the
        preflight's samples up to rest after the finish (:meth:`_rest_index`), slowed into the
        limits (:meth:`_within_limits`; ``rate`` is the clock rate, 1 where nothing was slowed).
        Where the law has not come to rest SETTLE_TIME after its finish (it may wander on at a
        goal near a singular J, where the damped least squares leave a direction of the joints
        undamped: 2 of 250 tasks of moves of 1 rad per joint), the motion ends with a stop from
        its last sample (:func:`coming_to_rest`, within the jerk and acceleration limits), one
        more sample: cut there, q̇ and q̈ jumped to 0 (q̈ by up to 0.2 rad/s² on those tasks).
        The stop ends at the goal (:meth:`_goal_configuration`): with its end free it moved on along
        the wandering and came to rest up to 2.9 mm from the last waypoint (soak seeds 97-249)."""
        if self._planned is None:
            end = self._rest_index() + 1
            times = self._run["t"][:end]
            samples = np.stack([self._run[name][:end] for name in ("q", "qd", "qdd")], axis=1)
            scaling = self._run["c"][:end]
            q, qd, qdd = samples[-1]
            if np.abs(qd).max() > REST_SPEED:
                law = self.pajak_law
                shortest, displacement = coming_to_rest(qd, qdd, law.parameters.jerk_limit, law.qdd_max)
                rest = self._goal_configuration(q + displacement)
                duration = stop_duration(qd, qdd, rest - q, shortest, law.parameters.jerk_limit,
                                         law.qd_max if law.parameters.limit_velocity else np.full(len(q), np.inf),
                                         law.qdd_max)
                times = np.append(times, times[-1] + duration)
                samples = np.concatenate([samples, [[rest, np.zeros_like(q), np.zeros_like(q)]]])
                scaling = np.append(scaling, scaling[-1])
            self._planned = self._within_limits(times, samples, scaling)
        return self._planned

    def _goal_configuration(self, q: np.ndarray) -> np.ndarray:
        """The joint positions [rad] where the stop ends, its TCP at the last waypoint: near ``q``
        (the stop's free end), within :data:`GOAL_MARGIN` of accuracy and orientation_accuracy, by
        Gauss-Newton steps on the pose error with J of eq. 13 (undamped: its least singular value,
        0.01-0.03 on the wandering tasks, is the direction the error lies in, which the damping of
        improvement 3 would hold back), each at most :data:`GOAL_STEP` per joint and all within
        :data:`GOAL_REACH` of ``q`` (undamped and unbounded, the steps near a singular J once led
        49 rad away, to another solution: ``draw_task("ur3e", "pajak", 544)``); ``q`` where it is
        there already. Where the steps do not get within accuracy (1.66 and 3.57 mm on soak seeds
        ur10e 336 and 1400, accuracy 1 mm): the law's configuration at its finish, within accuracy
        by the finish's own test, from which the law wandered on."""
        law, kinematics = self.pajak_law, self.pajak_law.kinematics
        parameters, goal = law.parameters, law.waypoints[-1]
        pose, jac, bias = np.empty(6), np.empty((6, 6)), np.empty(6)
        best, best_error = q, np.inf
        start = q
        for _ in range(20):
            kinematics.kinematics_into(kinematics.model, q, np.zeros(6), kinematics.tool, pose, jac, bias)
            position, orientation = kinematics.pose_error(pose, goal)
            error = max(position / parameters.accuracy, orientation / parameters.orientation_accuracy)
            if error < best_error:
                best, best_error = q, error
            if error <= GOAL_MARGIN:
                break
            offset = pose - goal
            offset[3:] = kinematics.wrap_angle(offset[3:])
            step = np.linalg.lstsq(jac, offset, rcond=None)[0]
            step *= min(1.0, GOAL_STEP / max(float(np.max(np.abs(step))), 1e-300))  # near a singular J: a short step
            if np.max(np.abs(q - step - start)) > GOAL_REACH:  # the steps lead away (another IK solution): stop
                break
            q = q - step
        return best if best_error <= 1.0 else self._run["q"][self._run["finish_index"]]

    def _within_limits(self, times, samples, scaling) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """(times [s], samples, c, rate): the law's samples (t, (q, q̇, q̈) (K, 3, n), c (K,)) on a
        clock slowed by the constant rate (:func:`~drake_traj.planners.laws.joint_speed_cap`, at
        most 1) that keeps the quintic Hermite pieces joining them within the limits the law keeps
        (velocity where ``limit_velocity``, acceleration where ``limit_acceleration``) at every
        instant: t / rate, q̇ rate, q̈ rate², c rate (the speed relative to the law's unscaled
        motion, eq. 17-18).

        The law holds its limits at every evaluation, the samples included, but its q̈ has kinks
        (where it reaches its box within a step) and jumps at the updates (where the eq. 18 anchor
        is recorded, the approach damping of improvement 4, sized for c_r, changes: up to 3.4 % of
        q̈_max on ``draw_task("ur10e", "pajak", 5)``), which the quintic pieces (q̈ continuous)
        round off, passing q̈_max between the samples: on 122 of 126 random UR10e tasks of the soak
        that pass their preflight (``draw_task("ur10e", "pajak", seed)``, seeds 1-100, two
        versions of the draw), by up to 1.3 % (median 0.07-0.17 %; measured). Slowed, the motion
        takes half the excess longer (median 0.04-0.08 %, at most 0.63 %)."""
        parameters = self.pajak_law.parameters
        unlimited = np.full(len(self.pajak_law.qd_max), np.inf)
        rate, _ = joint_speed_cap(HermiteLaw(times, samples, samples),
                                  self.pajak_law.qd_max if parameters.limit_velocity else unlimited,
                                  self.pajak_law.qdd_max if parameters.limit_acceleration else unlimited)
        powers = np.array([1.0, rate, rate * rate])[None, :, None]
        return times / rate, samples * powers, scaling * rate, rate

    def _rest_index(self) -> int:
        """The preflight's last sample of the motion: the first after the finish where every
        joint is slower than :data:`REST_SPEED` (the law settles after its task is done, its
        reference creeping on by 1 mrad over a second on sim 3), else the last integrated."""
        finish = self._run["finish_index"]
        resting = np.flatnonzero(np.abs(self._run["qd"][finish:]).max(axis=1) <= REST_SPEED)
        return finish + int(resting[0]) if len(resting) else len(self._run["t"]) - 1

    def finished(self, context) -> bool:
        return self.law.failure is None and super().finished(context)

    def limit_conflicts(self) -> int:
        """Update periods of the planned motion at which the limits overruled the law (q̈
        clipped to the box, or the fallback braking, improvement 2; or held to the jerk limit,
        improvement 1); the preflight's."""
        if self._run is None:
            self.preflight()
        return int(np.count_nonzero(self._run["saturated"][: self._run["finish_index"] + 1]))

    def preflight(self, horizon: float = DEFAULT_PREFLIGHT_HORIZON) -> np.ndarray:
        """Run the whole task ahead of time (:func:`integrate`, the law alone) before t = 0, up
        to ``horizon`` [s] (a run's ``max_duration``; at most :data:`MAX_PREFLIGHT_STEPS` update
        periods).

        Raises the :class:`PlanningError` that the motion would end with: a waypoint out of
        reach (before integrating), a task done at the start (at ``waypoints``, cause INVALID: no
        motion to plan), a stall, gimbal lock, non-finite values or no finish within
        ``horizon`` (cause TIMEOUT), naming the time, the configuration and the cause (the stall
        message names the waypoint). A run that finishes has reached the whole pose (position
        within ε, orientation within ``orientation_accuracy``).

        The integration is kept once it finished (the law does not change): a second preflight,
        :meth:`plan` and the run reuse it; one that failed is run again and raises again.

        Returns:
            The planned TCP path [m], (N, 3), up to the finish.
        """
        horizon = run_duration(horizon, "horizon")
        update_period = self.pajak_law.parameters.update_period
        if horizon / update_period > MAX_PREFLIGHT_STEPS:
            raise invalid("update_period", f"update_period = {update_period:g} s would take {horizon / update_period:.3g} "
                                           f"steps to look {horizon:g} s ahead (max_duration); at most "
                                           f"{MAX_PREFLIGHT_STEPS:.0e}: raise update_period or lower max_duration")
        if self._run is None:
            try:
                run = integrate(self.pajak_law, self.initial_positions(), dt=update_period, t_max=horizon,
                                settle_time=SETTLE_TIME)
            except PlanningError as error:
                if error.cause is not Cause.TIMEOUT:
                    raise
                raise PlanningError(f"the task did not finish within {horizon:g} s, the preflight's horizon (the run's "
                                    "max_duration)", time=error.time, configuration=error.configuration,
                                    cause=Cause.TIMEOUT, partial=error.partial) from None
            if run["finish_index"] == 0:  # done at t = 0: no motion to plan, check or run
                count = len(self.pajak_law.waypoints)
                which = "the only waypoint" if count == 1 else f"every one of the {count} waypoints"
                raise PlanningError(f"the task has nothing to do: the start pose is already {which} (within "
                                    "accuracy and orientation_accuracy); give a waypoint the tool moves to",
                                    field=("waypoints",), cause=Cause.INVALID)
            self._run = run
        elif self._run["T"] > horizon:
            raise PlanningError(f"the task takes {self._run['T']:.3f} s, longer than {horizon:g} s, the preflight's "
                                "horizon (the run's max_duration)", cause=Cause.TIMEOUT)
        return self._run["tcp"][: self._run["finish_index"] + 1, :3]

    def planned_duration(self) -> float:
        """The law's finish time at override 1 [s] once the preflight ran, on the clock slowed into
        the limits (:meth:`_within_limits`), else NaN."""
        return float("nan") if self._run is None else float(self._run["T"]) / self._planned_samples()[3]

    def _plan_pieces(self) -> tuple[np.ndarray, np.ndarray]:
        """The preflight's samples (t, q, q̇, q̈) up to rest after the finish (the law settling:
        :meth:`_rest_index`; :meth:`planned_duration` is the finish), one every update period,
        joined by quintic Hermite pieces (:func:`quintic_hermite_coefficients`; q̈ the law's
        after each step's update on both sides of its sample), slowed into the limits
        (:meth:`_within_limits`): the reference the planner runs.
        The preflight's own integration when one was run (with the run's horizon), else one
        with the default horizon."""
        if self._run is None:
            self.preflight()
        times, samples, _, _ = self._planned_samples()
        return times, quintic_hermite_coefficients(times, samples, samples)

    def goal_pose(self) -> np.ndarray:
        """p_f, the last waypoint [m, rad]."""
        return self.pajak_law.waypoints[-1].copy()

    def task_waypoints(self) -> np.ndarray:
        return self.pajak_law.tcp_positions()

    def waypoint_neighbourhood(self) -> float:
        """ϵ [m] when the planner blends its waypoints (eq. 19), else NaN (it stops at each)."""
        parameters = self.pajak_law.parameters
        return float(parameters.neighbourhood) if parameters.blend_waypoints else float("nan")

    def _update(self, context, state):
        failure = self.law.failure
        if failure is not None and self._clock(context)[0] >= self.law.duration:
            raise failure
        return super()._update(context, state)


def make(config: PajakConfig, robot: Robot, q_initial) -> PajakPlanner:
    """The planner of ``config`` on ``robot`` (a 6-axis arm with the task kinematics the compiled
    law is bound to, :class:`PajakLaw`), starting at rest at ``q_initial`` [rad]. The law checks
    the robot, then calls :meth:`PajakConfig.validate` (so a config on a robot it cannot run on
    is refused for the robot)."""
    return PajakPlanner(config, q_initial, robot=robot)
