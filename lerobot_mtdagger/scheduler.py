"""Performance-aware scheduling of expert demonstrations across tasks.

Implements the paper's Method section "Performance-Aware Scheduling via Adaptive Filtering and
Allocation", its appendix "Two important techniques of Performance-aware Scheduling" and the softmax
allocation of "Implementation details": per task, a metric from the last round (Kalman-filtered
success for Task Need, the imitation-loss drop for Performance Gain) is rank-normalised to [0, 1] and
turned into a split of the budget by a temperature softmax with at least ``n_min`` episodes per task.
Each method is one ``SchedulerConfig`` subclass (``--scheduler.type``); the rest is shared. Pure numpy.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, cast

import draccus
import numpy as np

from lerobot_mtdagger.learning_curve import CurvePrior, FittedCurves, fit_logistic_curves, greedy_split

ArrayLike = Sequence[float] | np.ndarray


# --------------------------------------------------------------------------------------------------
# Input checks
# --------------------------------------------------------------------------------------------------


def _as_vector(values: ArrayLike, name: str, num_tasks: int | None = None) -> np.ndarray:
    """``values`` as a new non-empty 1-D float64 array, ``num_tasks`` long if given (else ValueError)."""
    array = np.array(values, dtype=np.float64, copy=True)
    if array.ndim != 1:
        raise ValueError(f"{name} must be a 1-D sequence with one value per task, got shape {array.shape}.")
    if array.size == 0:
        raise ValueError(f"{name} is empty: give one value per task.")
    if num_tasks is not None and array.size != num_tasks:
        raise ValueError(f"{name} has {array.size} values but the scheduler has num_tasks={num_tasks}.")
    return array


def _require_finite(array: np.ndarray, name: str) -> None:
    """Raises a ValueError naming the first non-finite entry of ``array``."""
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        index = int(bad[0])
        raise ValueError(
            f"{name}[{index}] = {array[index]} is not finite; every task needs a finite value "
            f"({bad.size} bad value(s) at indices {bad[:10].tolist()})."
        )


def _require_integer(value: Any, name: str, minimum: int) -> int:
    """Returns ``value`` as an int, raising a ValueError unless it is an integer >= ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name} must be an integer, got {value!r} ({type(value).__name__}).")
    if value < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {value}.")
    return int(value)


def _require_positive(value: float, name: str) -> float:
    """Returns ``value`` as a float, raising a ValueError unless it is finite and > 0."""
    value = float(value)
    if not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a finite number > 0, got {value}.")
    return value


# --------------------------------------------------------------------------------------------------
# Kalman filter of success probabilities
# --------------------------------------------------------------------------------------------------


class KalmanSuccessEstimator:
    """One scalar Kalman filter per task over the policy's success probability ``p`` (variance ``P``).

    Each round predicts ``P <- P + Q``; a task with ``n > 0`` rollouts of success rate ``s`` is then
    updated with ``R = R0 / (n + 1)``, ``K = P / (P + R)``, ``p <- p + K (s - p)``, ``P <- (1 - K) P``.

    Args:
        num_tasks: Number of tasks (>= 1).
        p0: Initial success estimate, in [0, 1].
        P0: Initial variance (>= 0).
        Q: Process noise added at every predict step (>= 0).
        R0: Measurement noise scale (> 0).
    """

    def __init__(
        self, num_tasks: int, p0: float = 0.5, P0: float = 0.25, Q: float = 0.03, R0: float = 0.5
    ) -> None:
        self.num_tasks = _require_integer(num_tasks, "num_tasks", 1)
        if not (math.isfinite(p0) and 0.0 <= p0 <= 1.0):
            raise ValueError(f"p0 must be a success probability in [0, 1], got {p0}.")
        for name, value in (("P0", P0), ("Q", Q)):
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f"{name} must be a finite variance >= 0, got {value}.")
        self.p0, self.P0, self.Q = float(p0), float(P0), float(Q)
        self.R0 = _require_positive(R0, "R0")
        self.p: np.ndarray = np.full(self.num_tasks, self.p0)
        self.P: np.ndarray = np.full(self.num_tasks, self.P0)

    def update(self, success_rate: ArrayLike, episodes: ArrayLike) -> None:
        """Runs one predict and one update step per task (ValueError on a bad measurement).

        Args:
            success_rate: Measured success rate per task in [0, 1] (ignored, may be NaN, at 0 episodes).
            episodes: Number of rollouts behind each measurement (integers >= 0).
        """
        rate, counts = check_measurements(success_rate, episodes, self.num_tasks)
        measured = counts > 0
        predicted_P = self.P + self.Q
        noise = self.R0 / (counts + 1.0)
        gain = predicted_P / (predicted_P + noise)
        self.p = np.where(measured, self.p + gain * (np.where(measured, rate, 0.0) - self.p), self.p)
        self.P = np.where(measured, (1.0 - gain) * predicted_P, predicted_P)

    def snapshot(self) -> dict[str, list[float]]:
        """Returns the current estimate as a JSON-ready ``{"p": [...], "P": [...]}``."""
        return {"p": self.p.tolist(), "P": self.P.tolist()}

    def load_snapshot(self, snapshot: Mapping[str, Sequence[float]]) -> None:
        """Restores a ``snapshot`` (ValueError on a wrong length or non-finite values)."""
        p = _as_vector(snapshot["p"], "kalman p", self.num_tasks)
        P = _as_vector(snapshot["P"], "kalman P", self.num_tasks)
        _require_finite(p, "kalman p")
        _require_finite(P, "kalman P")
        self.p, self.P = p, P


def check_measurements(
    success_rate: ArrayLike, episodes: ArrayLike, num_tasks: int
) -> tuple[np.ndarray, np.ndarray]:
    """``(success_rate, episodes)`` checked and as float64 arrays (NaN success only at 0 episodes).

    Raises:
        ValueError: With the offending task index and value.
    """
    rate = _as_vector(success_rate, "success_rate", num_tasks)
    counts = _as_vector(episodes, "episodes", num_tasks)
    _require_finite(counts, "episodes")
    if np.any(counts < 0) or np.any(counts != np.round(counts)):
        index = int(np.flatnonzero((counts < 0) | (counts != np.round(counts)))[0])
        raise ValueError(f"episodes[{index}] = {counts[index]} is not a non-negative integer count.")
    measured = counts > 0
    bad = measured & ~(np.isfinite(rate) & (rate >= 0.0) & (rate <= 1.0))
    if np.any(bad):
        index = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"success_rate[{index}] = {rate[index]} is not a rate in [0, 1] although the task had "
            f"{int(counts[index])} rollout(s)."
        )
    return rate, counts


# --------------------------------------------------------------------------------------------------
# Rank normalisation and softmax allocation
# --------------------------------------------------------------------------------------------------


def rank_normalize(values: ArrayLike) -> np.ndarray:
    """Rank-normalises a metric to [0, 1]: ``(rank - 1) / (N - 1)``, shape (N,).

    Rank 1 is the lowest value; tied values share their average rank; a single task gets 0. Raises a
    ValueError if ``values`` is empty, not 1-D or not finite.
    """
    array = _as_vector(values, "values")
    _require_finite(array, "values")
    n = array.size
    if n == 1:
        return np.zeros(1)
    order = np.argsort(array, kind="stable")
    sorted_values = array[order]
    # Start index of each run of equal values in sorted order.
    run_starts = np.flatnonzero(np.r_[True, sorted_values[1:] != sorted_values[:-1]])
    run_ends = np.r_[run_starts[1:], n]  # exclusive
    # 1-based average rank of a run covering positions [start, end): (start + 1 + end) / 2.
    run_ranks = (run_starts + 1 + run_ends) / 2.0
    ranks = np.empty(n)
    ranks[order] = np.repeat(run_ranks, run_ends - run_starts)
    return (ranks - 1.0) / (n - 1.0)


def softmax(scores: ArrayLike, temperature: float) -> np.ndarray:
    """``exp(score / T) / sum(exp(score / T))``, computed stably (ValueError on a non-finite input)."""
    temperature = _require_positive(temperature, "temperature")
    array = _as_vector(scores, "scores")
    _require_finite(array, "scores")
    logits = array / temperature
    weights = np.exp(logits - logits.max())
    return weights / weights.sum()


def allocate(scores: ArrayLike, budget: int, temperature: float, n_min: int) -> np.ndarray:
    """Splits ``budget`` episodes across tasks by ``softmax(scores / T)``, at least ``n_min`` each.

    Every task, including the lowest-ranked one (score 0), gets ``n_min``, by water-filling: the
    lowest-probability tasks whose share would fall below ``n_min`` get exactly ``n_min``, the others
    share the rest in proportion to their probability, and largest-remainder rounding makes the total
    exactly ``budget``. A higher score never gets fewer episodes; where no floor binds, every task is
    within 1 of ``softmax * budget``. ``docs/scheduler.md`` explains this reading of the paper.

    Args:
        scores: One finite priority score per task (higher = more episodes).
        budget: Episodes to hand out, an integer >= n_min * num_tasks.
        temperature: Softmax temperature T > 0 (lower = sharper).
        n_min: Minimum episodes per task, an integer >= 0.

    Returns:
        Episodes per task, int64 array of shape (num_tasks,).
    """
    probability = softmax(scores, temperature)
    return allocate_probabilities(probability, budget, n_min, np.asarray(scores, dtype=np.float64))


def allocate_probabilities(
    probability: np.ndarray, budget: int, n_min: int, scores: np.ndarray | None = None
) -> np.ndarray:
    """Turns probabilities (shape (num_tasks,), summing to 1) into episode counts (see ``allocate``).

    ``scores`` break ties between probabilities equal in floating point, so a higher score never gets
    fewer episodes; without them ties go to the lower task index.
    """
    budget = _require_integer(budget, "budget", 0)
    n_min = _require_integer(n_min, "n_min", 0)
    num_tasks = probability.size
    if budget < n_min * num_tasks:
        raise ValueError(
            f"budget={budget} is smaller than n_min * num_tasks = {n_min} * {num_tasks} = "
            f"{n_min * num_tasks}: raise the budget to at least {n_min * num_tasks} or lower n_min."
        )
    tie_break = np.zeros(num_tasks) if scores is None else scores
    ascending = np.lexsort((tie_break, probability))
    sorted_probability = probability[ascending]
    num_floored = _num_floored_tasks(sorted_probability, budget, n_min)

    counts = np.full(num_tasks, n_min, dtype=np.int64)
    free = ascending[num_floored:]
    free_budget = budget - n_min * num_floored
    share = probability[free] / probability[free].sum() * free_budget
    base = np.floor(share).astype(np.int64)
    leftover = free_budget - int(base.sum())
    # Hand the leftover units to the largest remainders; ties go to higher probability, then to
    # higher score, then to the lower task index.
    priority = np.lexsort((free, -tie_break[free], -probability[free], -(share - base)))
    base[priority[:leftover]] += 1
    counts[free] = base
    return counts


def _num_floored_tasks(sorted_probability: np.ndarray, budget: int, n_min: int) -> int:
    """Number k in [0, N - 1] of lowest-probability tasks that water-filling pins to ``n_min``.

    Pinning a task whose share is below ``n_min`` only shrinks the others' shares, so k is the smallest
    count at which the lowest unpinned task's share of ``budget - k * n_min`` reaches ``n_min``.
    """
    n = sorted_probability.size
    if n_min == 0:
        return 0
    k = np.arange(n)
    # Probability mass of tasks k..N-1, summed from the largest for accuracy.
    remaining_mass = np.cumsum(sorted_probability[::-1])[::-1]
    lowest_share = sorted_probability * (budget - n_min * k) / remaining_mass
    fits = lowest_share >= n_min * (1.0 - 1e-12)
    fits[-1] = True  # the largest task always gets budget - (N - 1) * n_min >= n_min
    return int(np.argmax(fits))


# --------------------------------------------------------------------------------------------------
# Scheduling methods: one registered config class each
# --------------------------------------------------------------------------------------------------

SUCCESS = "success"
"""Measurement: the raw success rate of the learner's rollouts per task (and their count)."""

GAIN = "gain"
"""Measurement: the per-task imitation-loss drop of the round's training."""

DEMOS = "demos"
"""Measurement: the expert demos per task behind each success measurement (a learning-curve history)."""

DEFAULT_N_MIN = 1
"""The paper's minimum episodes per task per round on MetaWorld (a run's preset may set another)."""


@dataclass(frozen=True)
class CurveHistory:
    """Success measurements with the expert demos behind them, one row per measured round.

    Attributes:
        demos: Expert demos per task behind each measurement, shape (rounds, num_tasks).
        success: Measured success rate (NaN where a task had no episode), shape (rounds, num_tasks).
        episodes: Episodes behind each rate, shape (rounds, num_tasks).
    """

    demos: np.ndarray
    success: np.ndarray
    episodes: np.ndarray

    @classmethod
    def empty(cls, num_tasks: int) -> CurveHistory:
        """No measurement yet."""
        return cls(*(np.zeros((0, num_tasks)) for _ in range(3)))

    @property
    def rounds(self) -> int:
        """Number of measured rounds."""
        return int(self.demos.shape[0])

    def appended(self, demos: np.ndarray, success: np.ndarray, episodes: np.ndarray) -> CurveHistory:
        """A new history with one more measured round."""
        return CurveHistory(
            np.vstack([self.demos, demos]),
            np.vstack([self.success, success]),
            np.vstack([self.episodes, episodes]),
        )

    def to_dict(self) -> dict[str, list[list[float | None]]]:
        """JSON-ready rows (NaN success rates become None)."""
        success = [[None if math.isnan(v) else v for v in row] for row in self.success.tolist()]
        return {"demos": self.demos.tolist(), "success": success, "episodes": self.episodes.tolist()}

    @classmethod
    def from_dict(cls, record: Mapping[str, Any], num_tasks: int) -> CurveHistory:
        """Reads ``to_dict`` output (ValueError unless every row has one value per task)."""
        arrays = []
        for key in ("demos", "success", "episodes"):
            rows = [[math.nan if v is None else float(v) for v in row] for row in record[key]]
            array = (
                np.array(rows, dtype=np.float64).reshape(len(rows), -1) if rows else np.zeros((0, num_tasks))
            )
            if array.shape[1] != num_tasks:
                raise ValueError(
                    f"history.{key} has {array.shape[1]} values per round, expected {num_tasks}."
                )
            arrays.append(array)
        return cls(*arrays)


NORMALIZATIONS = ("rank", "none")
"""How a metric becomes softmax scores: the paper's ranks in [0, 1], or the metric itself."""


@dataclass(frozen=True)
class SchedulerState:
    """What a scheduler knows about the tasks: the inputs of every method's metric.

    Attributes:
        kalman_p: Kalman-filtered success probability per task (``p0`` before any measurement).
        raw_success: Latest raw measured success rate per task (``p0`` for a task never measured).
        gain: Latest performance gain ``max(0, L_start - L_end)`` per task (0 before any training).
        history: Every success measurement with the demos behind it (methods that read ``DEMOS``).
        demos_so_far: Expert demos per task collected so far (None: not given).
    """

    kalman_p: np.ndarray
    raw_success: np.ndarray
    gain: np.ndarray
    history: CurveHistory | None = None
    demos_so_far: np.ndarray | None = None

    @property
    def num_tasks(self) -> int:
        """Number of tasks."""
        return int(self.kalman_p.size)


@dataclass
class SchedulerConfig(draccus.ChoiceRegistry):
    """A scheduling method and its hyperparameters; select it with ``--scheduler.type=<method>``.

    Each method is one registered subclass that declares the measurements its metric needs
    (``measurements``, from ``SUCCESS``, ``GAIN``, ``DEMOS``) and computes the metric from the
    scheduler's state (higher = more episodes). ``make_scheduler``, the runner and ``verify`` all go
    through that class, so adding a method is::

        @SchedulerConfig.register_subclass("my_method")
        @dataclass
        class MyMethodConfig(SchedulerConfig):
            measurements: ClassVar[tuple[str, ...]] = (SUCCESS,)

            def metric(self, state: SchedulerState) -> np.ndarray:
                return 1.0 - state.raw_success ** 2

    Defaults are the paper's (hyperparameter table, MetaWorld column).

    Attributes:
        temperature: Softmax temperature T > 0.
        n_min: Minimum episodes per task per round; None: the run preset's, or ``DEFAULT_N_MIN``.
        p0: Initial Kalman success estimate.
        P0: Initial Kalman variance.
        Q: Kalman process noise per round.
        R0: Kalman measurement noise scale; a round of n rollouts has noise R0 / (n + 1).
        normalization: How the metric becomes softmax scores: ``rank`` (the paper's ranks in [0, 1]) or
            ``none`` (the metric itself, so a wider spread of difficulty gives a wider split).
    """

    measurements: ClassVar[tuple[str, ...]] = ()

    temperature: float = 0.5
    n_min: int | None = None
    p0: float = 0.5
    P0: float = 0.25
    Q: float = 0.03
    R0: float = 0.5
    normalization: str = "rank"

    def __post_init__(self) -> None:
        _require_positive(self.temperature, "scheduler.temperature")
        if self.normalization not in NORMALIZATIONS:
            raise ValueError(
                f"scheduler.normalization must be one of {list(NORMALIZATIONS)}, got {self.normalization!r}."
            )
        if self.n_min is not None:
            _require_integer(self.n_min, "scheduler.n_min", 0)
        self.new_kalman(1)  # the Kalman filter checks p0, P0, Q and R0 with named errors

    @property
    def kalman_options(self) -> dict[str, float]:
        """The Kalman filter's hyperparameters, as an allocation records them."""
        return {"p0": self.p0, "P0": self.P0, "Q": self.Q, "R0": self.R0}

    def new_kalman(self, num_tasks: int) -> KalmanSuccessEstimator:
        """A Kalman filter over ``num_tasks`` success rates with this config's hyperparameters."""
        return KalmanSuccessEstimator(num_tasks, **self.kalman_options)

    @classmethod
    def default_choice_name(cls) -> str:
        """Method used when the command line sets scheduler options but no ``type``: task need."""
        return "need"

    @property
    def type(self) -> str:
        """The method name this config is registered under."""
        return self.get_choice_name(self.__class__)

    @property
    def min_episodes(self) -> int:
        """``n_min``, or ``DEFAULT_N_MIN`` when it was left to a preset and no preset filled it."""
        return DEFAULT_N_MIN if self.n_min is None else int(self.n_min)

    def metric(self, state: SchedulerState) -> np.ndarray:
        """The method's metric per task (higher = more episodes), shape (num_tasks,)."""
        raise NotImplementedError(f"{type(self).__name__} must implement metric(state).")

    def split(self, state: SchedulerState, metric: np.ndarray, budget: int) -> tuple[np.ndarray, ...]:
        """Scores, probabilities and episodes per task: the normalised metric, softmax, ``allocate``."""
        if self.normalization == "rank":
            score = rank_normalize(metric)
        else:
            score = _as_vector(metric, "metric")
            _require_finite(score, "metric")
        probability = softmax(score, self.temperature)
        counts = allocate_probabilities(probability, budget, self.min_episodes, score)
        return score, probability, counts

    def hyperparameters(self) -> dict[str, Any]:
        """The fields as ``make_scheduler`` arguments (n_min resolved; ``normalization`` only if not rank)."""
        values = {**dataclasses.asdict(self), "n_min": self.min_episodes}
        if values["normalization"] == "rank":
            del values["normalization"]
        return values

    def options(self) -> dict[str, Any]:
        """The hyperparameters beyond the shared ones (an ``Allocation`` stores them to rebuild this)."""
        shared = {"temperature", "n_min", "p0", "P0", "Q", "R0"}
        return {k: v for k, v in self.hyperparameters().items() if k not in shared}


@SchedulerConfig.register_subclass("uniform")
@dataclass
class UniformSchedulerConfig(SchedulerConfig):
    """Uniform DAgger: the same number of episodes for every task (leftovers to low task indices)."""

    measurements: ClassVar[tuple[str, ...]] = ()

    def metric(self, state: SchedulerState) -> np.ndarray:
        """Zeros: every task ranks equal."""
        return np.zeros(state.num_tasks)


@SchedulerConfig.register_subclass("need")
@dataclass
class NeedSchedulerConfig(SchedulerConfig):
    """MTDAgger-TN: task need ``1 - p_hat`` with ``p_hat`` the Kalman-filtered success rate."""

    measurements: ClassVar[tuple[str, ...]] = (SUCCESS,)

    def metric(self, state: SchedulerState) -> np.ndarray:
        """``1 - p_hat``."""
        return 1.0 - state.kalman_p


@SchedulerConfig.register_subclass("need_raw")
@dataclass
class NeedRawSchedulerConfig(SchedulerConfig):
    """Task need on the last raw measured success rate (the paper's "TN without Kalman filter")."""

    measurements: ClassVar[tuple[str, ...]] = (SUCCESS,)

    def metric(self, state: SchedulerState) -> np.ndarray:
        """``1 - s`` (``p0`` for a task never measured)."""
        return 1.0 - state.raw_success


@SchedulerConfig.register_subclass("gain")
@dataclass
class GainSchedulerConfig(SchedulerConfig):
    """MTDAgger-PG: performance gain ``max(0, L_start - L_end)`` per task (0 before any training)."""

    measurements: ClassVar[tuple[str, ...]] = (GAIN,)

    def metric(self, state: SchedulerState) -> np.ndarray:
        """The clipped loss drop of the last training phase."""
        return state.gain.copy()


@SchedulerConfig.register_subclass("learnability")
@dataclass
class LearnabilitySchedulerConfig(SchedulerConfig):
    """Learnability ``p_hat (1 - p_hat)``: most episodes to tasks near even odds (curriculum baseline).

    The score of prioritised level replay and "learnability" curricula (Tzannetos et al. 2023).
    """

    measurements: ClassVar[tuple[str, ...]] = (SUCCESS,)

    def metric(self, state: SchedulerState) -> np.ndarray:
        """``p_hat (1 - p_hat)`` of the Kalman-filtered success."""
        return state.kalman_p * (1.0 - state.kalman_p)


@SchedulerConfig.register_subclass("curve")
@dataclass
class CurveSchedulerConfig(SchedulerConfig):
    """Learning curves fitted online: the round's demos go where success is expected to rise most.

    Fits each task's success against its demos (``learning_curve``), then splits the budget greedily
    by expected gain per demo after ``n_min`` each; ``temperature`` and ``normalization`` play no part.

    Attributes:
        prior_scale: Scale of a task's intercept around the common one (logits, > 0).
        slope_mean: Prior mean of the tasks' common slope on log demos.
        slope_scale: Prior scale of that slope (> 0).
        task_slope_scale: Scale of a task's slope around the common one (> 0; small: one slope).
    """

    measurements: ClassVar[tuple[str, ...]] = (SUCCESS, DEMOS)

    prior_scale: float = 1.5
    slope_mean: float = 1.0
    slope_scale: float = 1.0
    task_slope_scale: float = 0.1

    def __post_init__(self) -> None:
        super().__post_init__()
        _require_positive(self.prior_scale, "scheduler.prior_scale")
        _require_positive(self.slope_scale, "scheduler.slope_scale")
        _require_positive(self.task_slope_scale, "scheduler.task_slope_scale")
        if not math.isfinite(self.slope_mean):
            raise ValueError(f"scheduler.slope_mean must be finite, got {self.slope_mean}.")

    def fitted(self, state: SchedulerState) -> FittedCurves | None:
        """The curves fitted to the state's history (None before any measurement); the last fit is cached."""
        if state.history is None or state.history.rounds == 0:
            return None
        history = state.history
        key = (history.demos.tobytes(), history.success.tobytes(), history.episodes.tobytes())
        cached = getattr(self, "_last_fit", None)
        if cached is not None and cached[0] == key:
            return cached[1]
        prior = CurvePrior(self.prior_scale, self.slope_mean, self.slope_scale, self.task_slope_scale)
        curves = fit_logistic_curves(history.demos, history.success, history.episodes, prior)
        self._last_fit = (key, curves)
        return curves

    def metric(self, state: SchedulerState) -> np.ndarray:
        """The fitted success at each task's demos so far (``p0`` before any measurement)."""
        curves = self.fitted(state)
        if curves is None:
            return np.full(state.num_tasks, self.p0)
        return curves.success(_current_demos(state))

    def split(self, state: SchedulerState, metric: np.ndarray, budget: int) -> tuple[np.ndarray, ...]:
        """Greedy by expected gain per demo; score = that gain at the start, probability = share."""
        budget = _require_integer(budget, "budget", self.min_episodes * state.num_tasks)
        curves = self.fitted(state)
        if curves is None:
            even = np.full(state.num_tasks, 1.0 / state.num_tasks)
            return np.zeros(state.num_tasks), even, allocate_probabilities(even, budget, self.min_episodes)
        demos = _current_demos(state)[:, None] + np.arange(budget + 1)[None, :]
        counts, rate = greedy_split(curves.success(demos), budget, self.min_episodes)
        return rate, counts / max(budget, 1), counts


def _current_demos(state: SchedulerState) -> np.ndarray:
    """Demos per task now: ``demos_so_far``, else those behind the last measurement."""
    if state.demos_so_far is not None:
        return np.asarray(state.demos_so_far, dtype=np.float64)
    assert state.history is not None  # called only once curves were fitted to it
    return state.history.demos[-1]


def scheduling_methods() -> tuple[str, ...]:
    """Names of the registered scheduling methods, in registration order."""
    return tuple(SchedulerConfig.get_known_choices())


def scheduler_config_class(method: str) -> type[SchedulerConfig]:
    """The registered config class of ``method`` (ValueError naming the known ones, and ``bc``'s run mode)."""
    known = scheduling_methods()
    if method == "bc":
        raise ValueError(
            "'bc' is not a scheduling method: behaviour cloning is a run mode, run it with --mode=bc "
            f"(scheduling methods: {list(known)})."
        )
    if method not in known:
        raise ValueError(f"Unknown scheduling method {method!r}; known methods: {list(known)}.")
    return SchedulerConfig.get_choice_class(method)


STATE_FORMAT_VERSION = 1


@dataclass
class Allocation:
    """One allocation and everything it was computed from (JSON-ready through ``to_dict``).

    Lists are in task order; a measurement is None until the scheduler has received it.

    Attributes:
        success_rate: Last measured raw success rate per task (NaN where a task had no rollouts).
        episodes: Rollouts behind ``success_rate``.
        raw_success: Latest raw success rate per task over all updates (``p0`` if never measured).
        kalman_prior: Kalman state ``{"p", "P"}`` before the last success update.
        kalman_posterior: Kalman state after it (the one ``need`` uses).
        metric: The method's metric per task; ``score`` is it as softmax scores (ranks by default).
        probability: ``softmax(score / T)``; ``episodes_per_task`` is the allocation.
        kalman: The Kalman filter's hyperparameters ``{"p0", "P0", "Q", "R0"}``.
        notes: Human-readable remarks (for example "no rollouts measured yet: the prior decides").
        options: The method's hyperparameters beyond the shared ones (``SchedulerConfig.options``).
        history: The learning-curve history of a method that reads ``DEMOS``.
        demos_so_far: Expert demos per task when the allocation was made (methods that read ``DEMOS``).
    """

    method: str
    budget: int
    temperature: float
    n_min: int
    success_rate: list[float] | None
    episodes: list[int] | None
    gain: list[float] | None
    raw_success: list[float]
    kalman_prior: dict[str, list[float]]
    kalman_posterior: dict[str, list[float]]
    metric: list[float]
    score: list[float]
    probability: list[float]
    episodes_per_task: list[int]
    kalman: dict[str, float]
    notes: list[str] = dataclasses.field(default_factory=list)
    options: dict[str, Any] = dataclasses.field(default_factory=dict)
    history: dict[str, Any] | None = None
    demos_so_far: list[float] | None = None

    def to_dict(self) -> dict[str, Any]:
        """Returns the record as JSON-ready builtins (NaN success rates become None)."""
        record = dataclasses.asdict(self)
        for name in OPTIONAL_ALLOCATION_FIELDS:
            if not record[name]:
                del record[name]
        if record["success_rate"] is not None:
            record["success_rate"] = [None if math.isnan(v) else v for v in record["success_rate"]]
        return record

    @classmethod
    def from_dict(cls, record: Mapping[str, Any]) -> Allocation:
        """Reads ``to_dict`` output (extra keys ignored; ValueError if a required key is missing)."""
        names = [f.name for f in dataclasses.fields(cls)]
        missing = [n for n in names if n not in record and n not in ("notes", *OPTIONAL_ALLOCATION_FIELDS)]
        if missing:
            raise ValueError(f"Allocation record is missing keys {missing}.")
        values = {n: record[n] for n in names if n in record}
        if values["success_rate"] is not None:
            values["success_rate"] = [math.nan if v is None else float(v) for v in values["success_rate"]]
        return cls(**values)

    def config(self) -> SchedulerConfig:
        """The scheduler config this allocation was made with (ValueError if the method is not registered)."""
        kalman: Mapping[str, Any] = self.kalman
        return scheduler_config_class(self.method)(
            temperature=self.temperature, n_min=self.n_min, **kalman, **self.options
        )


OPTIONAL_ALLOCATION_FIELDS = ("options", "history", "demos_so_far")
"""``Allocation`` fields a record leaves out when empty (a record may lack them)."""


def _allocation_notes(config: SchedulerConfig, measured: set[str]) -> list[str]:
    """Remarks on measurements the method needs but has not received yet."""
    notes = []
    if SUCCESS in config.measurements and SUCCESS not in measured:
        notes.append("no rollouts measured yet: the prior decides (uniform allocation)")
    if GAIN in config.measurements and GAIN not in measured:
        notes.append("no training gain measured yet: uniform allocation")
    return notes


class Scheduler:
    """Allocates each DAgger round's demonstration budget across tasks.

    Every method tracks the same measurements (Kalman and raw success from rollouts, gain from training);
    only the metric, from the method's ``config``, differs. Before any measurement every metric is
    constant, so the first allocation is uniform.

    Raises:
        ValueError: On a bad hyperparameter or ``num_tasks`` < 1.
        TypeError: If ``config`` is not a ``SchedulerConfig`` (``make_scheduler`` builds one by name).
    """

    def __init__(self, config: SchedulerConfig, num_tasks: int) -> None:
        if not isinstance(config, SchedulerConfig):
            raise TypeError(
                f"Scheduler needs a SchedulerConfig, got {type(config).__name__}; build one by name with "
                "make_scheduler(method, num_tasks)."
            )
        self.config = config
        self.method = config.type
        self.kalman = config.new_kalman(num_tasks)
        self.num_tasks = self.kalman.num_tasks
        self.raw_success: np.ndarray = np.full(self.num_tasks, config.p0)
        self.gain: np.ndarray = np.zeros(self.num_tasks)
        self.last_success_rate: np.ndarray | None = None
        self.last_episodes: np.ndarray | None = None
        self.last_gain: np.ndarray | None = None
        self.kalman_prior = self.kalman.snapshot()
        self.num_updates = 0
        self.history = CurveHistory.empty(self.num_tasks)
        self.demos_so_far: np.ndarray | None = None

    def update(
        self,
        *,
        success_rate: ArrayLike | None = None,
        episodes: ArrayLike | None = None,
        gain: ArrayLike | None = None,
        demos: ArrayLike | None = None,
        demos_so_far: ArrayLike | None = None,
    ) -> None:
        """Feeds one round's measurements; on a bad one, raises ValueError and changes nothing.

        Args:
            success_rate: Raw success rate per task (NaN where a task had 0 rollouts); with ``episodes``.
            episodes: Rollouts per task behind ``success_rate``.
            gain: Per-task loss drop ``L_start - L_end`` of the round's training, clipped to >= 0.
            demos: Expert demos per task behind ``success_rate`` (required by methods that read ``DEMOS``).
            demos_so_far: Expert demos per task collected so far (the next allocation adds to them).
        """
        if (success_rate is None) != (episodes is None):
            raise ValueError("success_rate and episodes go together: pass both or neither.")
        checked_gain = None
        if gain is not None:
            checked_gain = _as_vector(gain, "gain", self.num_tasks)
            _require_finite(checked_gain, "gain")
        checked_demos = self._checked_demos(demos, demos_so_far, success_rate is not None)
        if success_rate is not None:
            assert episodes is not None  # refused above: success_rate and episodes go together
            rate, counts = check_measurements(success_rate, episodes, self.num_tasks)
            if checked_demos[0] is not None:
                self.history = self.history.appended(checked_demos[0], rate, counts)
            self.kalman_prior = self.kalman.snapshot()
            self.kalman.update(rate, counts)
            self.raw_success = np.where(counts > 0, rate, self.raw_success)
            self.last_success_rate, self.last_episodes = rate, counts
        if checked_gain is not None:
            self.gain = np.maximum(checked_gain, 0.0)
            self.last_gain = self.gain.copy()
        if checked_demos[1] is not None:
            self.demos_so_far = checked_demos[1]
        self.num_updates += 1

    def _checked_demos(
        self, demos: ArrayLike | None, demos_so_far: ArrayLike | None, has_success: bool
    ) -> tuple[np.ndarray | None, np.ndarray | None]:
        """``(demos, demos_so_far)`` as checked vectors (None where not given or not read)."""
        reads_demos = DEMOS in self.config.measurements
        if reads_demos and has_success and demos is None:
            raise ValueError(
                f"The {self.method!r} scheduler fits learning curves: pass demos= (the expert demos per "
                "task behind success_rate) with every success measurement."
            )
        if demos is not None and not has_success:
            raise ValueError("demos describes a success measurement: pass it with success_rate and episodes.")
        checked: list[np.ndarray | None] = []
        for name, values in (("demos", demos), ("demos_so_far", demos_so_far)):
            if values is None or not reads_demos:
                checked.append(None)
                continue
            array = _as_vector(values, name, self.num_tasks)
            _require_finite(array, name)
            if np.any(array < 0):
                raise ValueError(f"{name} must be demo counts >= 0, got {array.tolist()}.")
            checked.append(array)
        return checked[0], checked[1]

    @property
    def state(self) -> SchedulerState:
        """The current inputs of the metric."""
        return SchedulerState(
            kalman_p=self.kalman.p.copy(),
            raw_success=self.raw_success.copy(),
            gain=self.gain.copy(),
            history=self.history,
            demos_so_far=None if self.demos_so_far is None else self.demos_so_far.copy(),
        )

    @property
    def measured(self) -> set[str]:
        """The measurements received so far (``SUCCESS``, ``GAIN``)."""
        return {
            name
            for name, last in ((SUCCESS, self.last_success_rate), (GAIN, self.last_gain))
            if last is not None
        }

    def metric(self) -> np.ndarray:
        """The method's current metric per task (higher = more episodes)."""
        return np.asarray(self.config.metric(self.state), dtype=np.float64)

    def allocate(self, budget: int) -> Allocation:
        """Allocates ``budget`` episodes (an integer >= n_min * num_tasks) and returns the full record."""
        metric = self.metric()
        score, probability, counts = self.config.split(self.state, metric, budget)
        reads_demos = DEMOS in self.config.measurements
        return Allocation(
            method=self.method,
            budget=int(budget),
            temperature=self.config.temperature,
            n_min=self.config.min_episodes,
            success_rate=None if self.last_success_rate is None else self.last_success_rate.tolist(),
            episodes=None if self.last_episodes is None else [int(n) for n in self.last_episodes],
            gain=None if self.last_gain is None else self.last_gain.tolist(),
            raw_success=self.raw_success.tolist(),
            kalman_prior=self.kalman_prior,
            kalman_posterior=self.kalman.snapshot(),
            metric=metric.tolist(),
            score=score.tolist(),
            probability=probability.tolist(),
            episodes_per_task=counts.tolist(),
            kalman=self.config.kalman_options,
            notes=_allocation_notes(self.config, self.measured),
            options=self.config.options(),
            history=self.history.to_dict() if reads_demos and self.history.rounds else None,
            demos_so_far=None
            if not reads_demos or self.demos_so_far is None
            else [float(n) for n in self.demos_so_far],
        )

    def state_dict(self) -> dict[str, Any]:
        """Returns the full state as JSON-ready builtins (round-trips exactly through ``json``)."""

        def optional(array: np.ndarray | None) -> list[float | None] | None:
            if array is None:
                return None
            return [None if math.isnan(v) else v for v in array.tolist()]

        state = {
            "format_version": STATE_FORMAT_VERSION,
            "method": self.method,
            "num_tasks": self.num_tasks,
            "config": self.config.hyperparameters(),
            "kalman": self.kalman.snapshot(),
            "kalman_prior": self.kalman_prior,
            "raw_success": self.raw_success.tolist(),
            "gain": self.gain.tolist(),
            "last_success_rate": optional(self.last_success_rate),
            "last_episodes": optional(self.last_episodes),
            "last_gain": optional(self.last_gain),
            "num_updates": self.num_updates,
        }
        if DEMOS in self.config.measurements:
            state["history"] = self.history.to_dict()
            state["demos_so_far"] = None if self.demos_so_far is None else self.demos_so_far.tolist()
        return state

    def load_state_dict(self, state: Mapping[str, Any]) -> None:
        """Restores a ``state_dict`` (ValueError if of another method, task count or format version)."""
        if state.get("format_version") != STATE_FORMAT_VERSION:
            raise ValueError(
                f"Scheduler state has format_version={state.get('format_version')!r}; this version "
                f"reads {STATE_FORMAT_VERSION}."
            )
        if state["method"] != self.method or state["num_tasks"] != self.num_tasks:
            raise ValueError(
                f"Scheduler state is for method={state['method']!r} with num_tasks={state['num_tasks']}, "
                f"but this scheduler is method={self.method!r} with num_tasks={self.num_tasks}."
            )

        def optional(values: Sequence[float | None] | None) -> np.ndarray | None:
            if values is None:
                return None
            return np.array([math.nan if v is None else v for v in values], dtype=np.float64)

        self.config = type(self.config)(**state["config"])
        self.kalman = self.config.new_kalman(self.num_tasks)
        self.kalman.load_snapshot(state["kalman"])
        self.kalman_prior = {"p": list(state["kalman_prior"]["p"]), "P": list(state["kalman_prior"]["P"])}
        self.raw_success = _as_vector(state["raw_success"], "raw_success", self.num_tasks)
        self.gain = _as_vector(state["gain"], "gain", self.num_tasks)
        self.last_success_rate = optional(state["last_success_rate"])
        self.last_episodes = optional(state["last_episodes"])
        self.last_gain = optional(state["last_gain"])
        self.num_updates = int(state["num_updates"])
        if state.get("history") is not None:
            self.history = CurveHistory.from_dict(state["history"], self.num_tasks)
        so_far = state.get("demos_so_far")
        self.demos_so_far = None if so_far is None else _as_vector(so_far, "demos_so_far", self.num_tasks)


def make_scheduler(method: str, num_tasks: int, **hyperparameters: Any) -> Scheduler:
    """Creates a scheduler by method name and ``SchedulerConfig`` fields (ValueError on a bad one)."""
    config_class = scheduler_config_class(method)
    known = {f.name for f in dataclasses.fields(config_class)}
    unknown = sorted(set(hyperparameters) - known)
    if unknown:
        raise ValueError(f"Unknown scheduler hyperparameter(s) {unknown}; known: {sorted(known)}.")
    return Scheduler(config_class(**hyperparameters), num_tasks)


def recompute_allocation(record: Mapping[str, Any]) -> Allocation:
    """Recomputes an ``Allocation.to_dict()`` record from its inputs alone, through the method's config.

    The Kalman posterior too, from the stored prior and measurements, so a tampered Kalman state is
    detected. Raises a ValueError on an incomplete or inconsistent record or an unknown method.
    """
    stored = Allocation.from_dict(record)
    config = stored.config()
    num_tasks = len(stored.episodes_per_task)
    kalman = config.new_kalman(num_tasks)
    kalman.load_snapshot(stored.kalman_prior)
    if stored.success_rate is not None:
        # a record's episodes go with its success rate (a null one is refused as not 1-D by update)
        kalman.update(stored.success_rate, cast("list[int]", stored.episodes))
    gain = (
        np.zeros(num_tasks)
        if stored.gain is None
        else np.maximum(np.asarray(stored.gain, dtype=np.float64), 0.0)
    )
    state = SchedulerState(
        kalman_p=kalman.p.copy(),
        raw_success=np.asarray(stored.raw_success, dtype=np.float64),
        gain=gain,
        history=None if stored.history is None else CurveHistory.from_dict(stored.history, num_tasks),
        demos_so_far=None
        if stored.demos_so_far is None
        else np.asarray(stored.demos_so_far, dtype=np.float64),
    )
    metric = np.asarray(config.metric(state), dtype=np.float64)
    score, probability, counts = config.split(state, metric, stored.budget)
    return dataclasses.replace(
        stored,
        kalman_posterior=kalman.snapshot(),
        metric=metric.tolist(),
        score=score.tolist(),
        probability=probability.tolist(),
        episodes_per_task=counts.tolist(),
    )


def allocation_mismatches(record: Mapping[str, Any], rtol: float = 1e-9) -> list[str]:
    """Messages on the fields of an ``Allocation.to_dict()`` record its inputs do not reproduce."""
    recomputed = recompute_allocation(record)
    problems = []
    for name in ("metric", "score", "probability"):
        if not np.allclose(record[name], getattr(recomputed, name), rtol=rtol, atol=1e-12):
            problems.append(f"{name}: stored {record[name]} != recomputed {getattr(recomputed, name)}")
    if record.get("success_rate") is not None:
        for key in ("p", "P"):
            stored, again = record["kalman_posterior"][key], recomputed.kalman_posterior[key]
            if not np.allclose(stored, again, rtol=rtol, atol=1e-12):
                problems.append(f"kalman_posterior.{key}: stored {stored} != recomputed {again}")
        measured = np.asarray(record["episodes"]) > 0
        rate = np.asarray(recomputed.success_rate)[measured]
        if not np.array_equal(np.asarray(record["raw_success"])[measured], rate):
            problems.append("raw_success does not hold the measured success_rate of the measured tasks")
    if list(record["episodes_per_task"]) != recomputed.episodes_per_task:
        problems.append(
            f"episodes_per_task: stored {record['episodes_per_task']} != "
            f"recomputed {recomputed.episodes_per_task}"
        )
    if sum(record["episodes_per_task"]) != record["budget"]:
        total = sum(record["episodes_per_task"])
        problems.append(f"episodes_per_task sums to {total}, budget is {record['budget']}")
    return problems
