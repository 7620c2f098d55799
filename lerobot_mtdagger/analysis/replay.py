"""A replay bench: measured learning curves as the environment of a scheduler.

Each replicate runs a DAgger study's scheduling loop without training: each round the scheduler is
fed each task's success drawn binomially from its curve at the demos of the policy measured (the
runner's one-round lag), and its allocation adds demos. A replicate's outcome is the curves'
expected mean success after each phase, averaged over the phases after round 0. Two oracles know
every curve: the online one allocates round by round by true gain per demo, the static one takes the
best split of all demos at each budget (the ceiling). A scheduler's share of the headroom is
``(scheduler - uniform) / (online oracle - uniform)``. ``docs/scheduler.md`` says what a replay
leaves out and how curves are extended past the measured demos (``flat`` or ``slope``).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from lerobot_mtdagger.analysis.headroom import LearningCurves, best_splits
from lerobot_mtdagger.analysis.stats import Interval, mean_interval
from lerobot_mtdagger.learning_curve import greedy_split
from lerobot_mtdagger.scheduler import GAIN, make_scheduler, scheduler_config_class, scheduling_methods
from lerobot_mtdagger.utils.errors import UserError

logger = logging.getLogger(__name__)

EXTRAPOLATIONS = ("flat", "slope")
UNIFORM, ONLINE_ORACLE, STATIC_ORACLE = "uniform", "oracle (online)", "oracle (static)"
STATIC_ORACLE_SHARE = 4.0
"""The static oracle gives a task at most this many times the last phase's even demos (its DP's width)."""


@dataclass(frozen=True)
class ReplaySetting:
    """The study a replay stands for.

    Attributes:
        initial_demos: Expert demos per task in round 0.
        rounds: DAgger rounds after round 0.
        budget_per_round: Episodes handed out per round (over all tasks).
        eval_episodes: Episodes behind each measured success rate.
        n_min: Minimum episodes per task per round (schedulers and the online oracle).
        lag: Rounds between a policy and the allocation its success informs (1: the runner's timing).
        extrapolation: Beyond the measured demos: ``flat`` or ``slope`` (capped at 1).
        replicates: Replicate runs per scheduler.
        seed: Seed of the replicates (replicate r of every scheduler draws from the same stream).
    """

    initial_demos: int = 3
    rounds: int = 9
    budget_per_round: int = 129
    eval_episodes: int = 20
    n_min: int = 1
    lag: int = 1
    extrapolation: str = "flat"
    replicates: int = 2000
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("initial_demos", "n_min", "lag"):
            if getattr(self, name) < 0:
                raise UserError(f"--{name} must be >= 0, got {getattr(self, name)}.")
        for name in ("rounds", "budget_per_round", "eval_episodes", "replicates"):
            if getattr(self, name) < 1:
                raise UserError(f"--{name} must be >= 1, got {getattr(self, name)}.")
        if self.extrapolation not in EXTRAPOLATIONS:
            raise UserError(
                f"--extrapolation must be one of {list(EXTRAPOLATIONS)}, got {self.extrapolation!r}."
            )

    @property
    def max_demos(self) -> int:
        """The most demos one task can reach."""
        return self.initial_demos + self.rounds * self.budget_per_round


@dataclass(frozen=True)
class ReplayCurves:
    """Curves on every integer demos from ``low`` (column 0) to the most a task can reach.

    ``success`` has shape (num_tasks, width); beyond ``measured_high`` demos it is extrapolated.
    """

    low: int
    success: np.ndarray
    measured_high: int

    @property
    def num_tasks(self) -> int:
        """Number of tasks."""
        return int(self.success.shape[0])

    def at(self, demos: np.ndarray) -> np.ndarray:
        """Success at integer demos, broadcast as ``demos`` (tasks on the first axis)."""
        index = np.asarray(demos, dtype=np.int64) - self.low
        rows = np.arange(self.num_tasks).reshape((-1,) + (1,) * (index.ndim - 1))
        return self.success[rows, index]


def extend_curves(curves: LearningCurves, setting: ReplaySetting) -> ReplayCurves:
    """The measured curves extended to every demos a replay can reach (``UserError`` if it starts below)."""
    if setting.initial_demos < curves.low:
        raise UserError(
            f"--initial_demos={setting.initial_demos} is below the smallest demos every task was measured at "
            f"({curves.low}): the bench does not extrapolate downwards; start at {curves.low} or measure "
            "lower."
        )
    beyond = np.arange(1, max(setting.max_demos - curves.high, 0) + 1)
    last = curves.success[:, -1:]
    if setting.extrapolation == "slope":
        slope = _last_measured_slope(curves)
        tail = np.minimum(last + slope[:, None] * beyond[None, :], 1.0)
    else:
        tail = np.repeat(last, beyond.size, axis=1)
    success = np.concatenate([curves.success, tail], axis=1)[:, setting.initial_demos - curves.low :]
    return ReplayCurves(setting.initial_demos, success, curves.high)


def _last_measured_slope(curves: LearningCurves) -> np.ndarray:
    """Each task's slope per demo between its last two measured knots (>= 0)."""
    slopes = []
    for task, knots in enumerate(curves.measured):
        inside = [k for k in knots if curves.low <= k <= curves.high]
        a, b = (inside[-2], inside[-1]) if len(inside) >= 2 else (curves.low, curves.high)
        slopes.append((curves.success[task, b - curves.low] - curves.success[task, a - curves.low]) / (b - a))
    return np.maximum(np.array(slopes), 0.0)


def synthetic_curves(num_tasks: int, easiest: float, hardest: float, setting: ReplaySetting) -> ReplayCurves:
    """The ``demo`` command's synthetic tasks (``1 - exp(-n / d)``, ``d`` spread geometrically)."""
    from lerobot_mtdagger.analysis.simulate import SyntheticTasks

    difficulty = SyntheticTasks.spread(num_tasks, easiest, hardest).difficulty
    demos = np.arange(setting.initial_demos, setting.max_demos + 1)
    success = 1.0 - np.exp(-demos[None, :] / difficulty[:, None])
    return ReplayCurves(setting.initial_demos, success, setting.max_demos)


# --------------------------------------------------------------------------------------------------
# One arm over every replicate
# --------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ArmSpec:
    """A scheduler to replay: a registered method and its options (``need:temperature=0.25``)."""

    method: str
    options: dict[str, float | str] = field(default_factory=dict)

    @property
    def label(self) -> str:
        """``method`` or ``method:key=value,...``."""
        extra = ",".join(f"{k}={v}" for k, v in self.options.items())
        return f"{self.method}:{extra}" if extra else self.method

    @classmethod
    def parse(cls, text: str) -> ArmSpec:
        """Reads ``method`` or ``method:key=value,key=value`` (``UserError`` on a bad method or option)."""
        method, _, rest = text.partition(":")
        try:
            config_class = scheduler_config_class(method)
        except ValueError as error:
            raise UserError(str(error)) from None
        if GAIN in config_class.measurements:
            raise UserError(
                f"{method!r} reads the per-task loss drop, which a success curve does not give: the replay "
                "bench cannot replay it. Leave it out of --methods."
            )
        options: dict[str, float | str] = {}
        for item in filter(None, rest.split(",")):
            key, equals, value = item.partition("=")
            if not equals:
                raise UserError(f"Scheduler option {item!r} in {text!r} is not key=value.")
            options[key] = _number_or_text(value)
        try:
            make_scheduler(method, 1, **options)
        except (ValueError, TypeError) as error:
            raise UserError(f"{text}: {error}") from None
        return cls(method, options)


def _number_or_text(value: str) -> float | str:
    try:
        number = float(value)
    except ValueError:
        return value
    return int(number) if number.is_integer() and "." not in value else number


@dataclass(frozen=True)
class ArmOutcome:
    """What one arm did over the replicates.

    Attributes:
        success: Expected mean success after each phase, shape (replicates, rounds + 1).
        demos: Demos per task after each phase, shape (replicates, rounds + 1, num_tasks).
    """

    label: str
    success: np.ndarray
    demos: np.ndarray
    seconds: float

    @property
    def over_budgets(self) -> np.ndarray:
        """Each replicate's mean success over the phases after round 0, shape (replicates,)."""
        return self.success[:, 1:].mean(axis=1)


def replay_arm(arm: ArmSpec, curves: ReplayCurves, setting: ReplaySetting) -> ArmOutcome:
    """Runs one scheduler over every replicate."""
    start = time.perf_counter()
    success = np.zeros((setting.replicates, setting.rounds + 1))
    demos = np.zeros((setting.replicates, setting.rounds + 1, curves.num_tasks))
    for replicate in range(setting.replicates):
        rng = np.random.default_rng([setting.seed, replicate])
        scheduler = make_scheduler(arm.method, curves.num_tasks, n_min=setting.n_min, **arm.options)

        def allocate(path: list[np.ndarray], round_index: int, scheduler=scheduler, rng=rng) -> np.ndarray:
            _feed(scheduler, path, round_index, curves, setting, rng)
            return np.asarray(scheduler.allocate(setting.budget_per_round).episodes_per_task)

        path = _run_rounds(allocate, curves, setting)
        success[replicate] = [curves.at(n).mean() for n in path]
        demos[replicate] = path
    return ArmOutcome(arm.label, success, demos, time.perf_counter() - start)


def _feed(scheduler, path: list[np.ndarray], round_index: int, curves, setting, rng) -> None:
    """Gives the scheduler the success of the policy ``lag`` rounds back, as the runner does."""
    measured = round_index - 1 - setting.lag
    if measured < 0:
        scheduler.update(demos_so_far=path[-1])
        return
    behind = path[measured]
    successes = rng.binomial(setting.eval_episodes, curves.at(behind))
    episodes = np.full(curves.num_tasks, setting.eval_episodes)
    scheduler.update(
        success_rate=successes / setting.eval_episodes, episodes=episodes, demos=behind, demos_so_far=path[-1]
    )


def _run_rounds(allocate, curves: ReplayCurves, setting: ReplaySetting) -> list[np.ndarray]:
    """Demos per task after round 0 and after each DAgger round."""
    path = [np.full(curves.num_tasks, setting.initial_demos, dtype=np.int64)]
    for round_index in range(1, setting.rounds + 1):
        path.append(path[-1] + allocate(path, round_index))
    return path


def replay_online_oracle(curves: ReplayCurves, setting: ReplaySetting) -> ArmOutcome:
    """Round by round, the budget where the true curves rise most per demo (deterministic)."""
    start = time.perf_counter()
    steps = np.arange(setting.budget_per_round + 1)

    def allocate(path: list[np.ndarray], round_index: int) -> np.ndarray:
        ahead = np.minimum(path[-1][:, None] + steps[None, :], curves.low + curves.success.shape[1] - 1)
        return greedy_split(curves.at(ahead), setting.budget_per_round, setting.n_min)[0]

    path = _run_rounds(allocate, curves, setting)
    return _constant(ONLINE_ORACLE, path, curves, setting, start)


def replay_uniform(curves: ReplayCurves, setting: ReplaySetting) -> ArmOutcome:
    """An even split every round (the uniform scheduler's rounding)."""
    start = time.perf_counter()
    scheduler = make_scheduler(UNIFORM, curves.num_tasks, n_min=setting.n_min)
    share = np.asarray(scheduler.allocate(setting.budget_per_round).episodes_per_task)
    path = _run_rounds(lambda path, k: share, curves, setting)
    return _constant(UNIFORM, path, curves, setting, start)


def replay_static_oracle(curves: ReplayCurves, setting: ReplaySetting) -> ArmOutcome:
    """At each phase, the best split of all demos so far (the ceiling; not reachable round by round).

    A task gets at most ``STATIC_ORACLE_SHARE`` times the last phase's even demos.
    """
    start = time.perf_counter()
    even_last = setting.initial_demos + setting.rounds * setting.budget_per_round / curves.num_tasks
    cap = min(int(STATIC_ORACLE_SHARE * even_last), setting.max_demos)
    if setting.extrapolation == "flat":
        cap = min(cap, max(curves.measured_high, curves.low + 1))
    grid = LearningCurves(
        tuple(str(i) for i in range(curves.num_tasks)),
        curves.low,
        cap,
        curves.success[:, : cap - curves.low + 1],
        (),
        (),
    )
    splits = best_splits(grid)
    values = []
    for round_index in range(setting.rounds + 1):
        total = curves.num_tasks * setting.initial_demos + round_index * setting.budget_per_round
        values.append(float(splits.value[min(total, int(splits.totals[-1])) - int(splits.totals[0])]))
    success = np.tile(values, (setting.replicates, 1))
    demos = np.full((1, setting.rounds + 1, curves.num_tasks), np.nan)
    return ArmOutcome(STATIC_ORACLE, success, demos, time.perf_counter() - start)


def _constant(label, path, curves, setting, start) -> ArmOutcome:
    success = np.tile([curves.at(n).mean() for n in path], (setting.replicates, 1))
    return ArmOutcome(label, success, np.asarray(path, dtype=np.float64)[None], time.perf_counter() - start)


# --------------------------------------------------------------------------------------------------
# The comparison
# --------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ArmSummary:
    """One arm against uniform and the online oracle.

    Attributes:
        mean_success: Mean success over the budgets, mean over replicates.
        vs_uniform: ``(mean, low, high)`` of the arm - uniform (95% t interval over replicates).
        share: ``(mean, low, high)`` share of the online oracle's headroom (bootstrap 95%).
        replicate_sd: SD over replicates of arm - uniform, evaluation noise included (no training noise).
        demos_to_reach: Demos per task at which the mean success first reaches each level (None: never).
    """

    label: str
    mean_success: float
    vs_uniform: tuple[float, float, float]
    share: tuple[float, float, float]
    replicate_sd: float
    demos_to_reach: dict[float, float | None]
    seconds: float


def summarise(
    outcomes: Sequence[ArmOutcome],
    setting: ReplaySetting,
    levels: Sequence[float],
    curves: ReplayCurves,
) -> list[ArmSummary]:
    """Each arm's mean success, difference from uniform, share of the headroom and demos to a level."""
    by_label = {o.label: o for o in outcomes}
    uniform, oracle = by_label[UNIFORM].over_budgets, by_label[ONLINE_ORACLE].over_budgets
    rng = np.random.default_rng(setting.seed)
    resample = rng.integers(0, setting.replicates, size=(1000, setting.replicates))
    budgets = (
        setting.initial_demos + np.arange(setting.rounds + 1) * setting.budget_per_round / curves.num_tasks
    )
    summaries = []
    for outcome in outcomes:
        values = outcome.over_budgets
        difference = values - uniform
        noise = _evaluation_noise_sd(outcome, by_label[UNIFORM], curves, setting)
        path = outcome.success.mean(axis=0)
        summaries.append(
            ArmSummary(
                outcome.label,
                float(values.mean()),
                _interval(mean_interval(difference)),
                _share_of_headroom(values, uniform, oracle, resample),
                float(np.sqrt(difference.var(ddof=1) + noise**2)) if setting.replicates > 1 else float("nan"),
                {level: _demos_to_reach(budgets, path, level) for level in levels},
                outcome.seconds,
            )
        )
    return summaries


def _interval(interval: Interval) -> tuple[float, float, float]:
    return interval.mean, interval.low, interval.high


def _share_of_headroom(
    values: np.ndarray, uniform: np.ndarray, oracle: np.ndarray, resample: np.ndarray
) -> tuple[float, float, float]:
    """``(arm - uniform) / (oracle - uniform)`` with a bootstrap 95% interval (NaN: no headroom)."""
    headroom = float(oracle.mean() - uniform.mean())
    if abs(headroom) < 1e-9:
        return (float("nan"),) * 3
    shares = (values[resample].mean(1) - uniform[resample].mean(1)) / (
        oracle[resample].mean(1) - uniform[resample].mean(1)
    )
    low, high = np.percentile(shares, [2.5, 97.5]).tolist()
    return float((values.mean() - uniform.mean()) / headroom), low, high


def _evaluation_noise_sd(outcome: ArmOutcome, uniform: ArmOutcome, curves, setting: ReplaySetting) -> float:
    """SD of the difference of two arms' measured (binomial) mean success over the budgets."""
    variance = 0.0
    for arm in (outcome, uniform):
        if np.isnan(arm.demos).any():
            return 0.0
        for phase in range(1, setting.rounds + 1):
            p = curves.at(np.round(arm.demos[:, phase].mean(axis=0)).astype(np.int64))
            variance += float((p * (1 - p)).sum()) / setting.eval_episodes / curves.num_tasks**2
    return float(np.sqrt(variance)) / setting.rounds


def _demos_to_reach(budgets: np.ndarray, path: np.ndarray, level: float) -> float | None:
    above = np.flatnonzero(path >= level)
    if above.size == 0:
        return None
    k = int(above[0])
    if k == 0:
        return float(budgets[0])
    fraction = (level - path[k - 1]) / (path[k] - path[k - 1])
    return float(budgets[k - 1] + fraction * (budgets[k] - budgets[k - 1]))


def run_bench(
    curves: ReplayCurves, setting: ReplaySetting, arms: Sequence[ArmSpec], levels: Sequence[float] = ()
) -> list[ArmSummary]:
    """Replays uniform, every arm and both oracles; returns their summaries (uniform first)."""
    outcomes = [replay_uniform(curves, setting)]
    for arm in arms:
        logger.info("replaying %s over %d replicates", arm.label, setting.replicates)
        outcomes.append(replay_arm(arm, curves, setting))
    outcomes += [replay_online_oracle(curves, setting), replay_static_oracle(curves, setting)]
    return summarise(outcomes, setting, levels, curves)


def seeds_for_half_width(effect: float, sd: float, most: int = 100) -> int | None:
    """Fewest seeds whose 95% t half-width on a paired difference of SD ``sd`` is at most ``effect / 2``."""
    from scipy import stats as scipy_stats

    for seeds in range(2, most + 1):
        if scipy_stats.t.ppf(0.975, seeds - 1) * sd / np.sqrt(seeds) <= abs(effect) / 2:
            return seeds
    return None


def default_arms() -> list[ArmSpec]:
    """Every registered scheduler that a success curve can drive (all but those reading the loss)."""
    return [
        ArmSpec(method)
        for method in scheduling_methods()
        if method != UNIFORM and GAIN not in scheduler_config_class(method).measurements
    ]
