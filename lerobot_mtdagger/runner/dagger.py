"""Algorithm 1 of the paper (appendix "Algorithm Details"): Multitask DAgger, end to end, resumable.

The loop, with round k's dataset committed before the policy trained on it::

    round 0       n0 expert demonstrations per task (the expert acts)         -> rounds/round-000
    phase 0       train pi_1 on D(0); per-task losses; evaluate pi_1           -> policies/round-000
    round k >= 1  scheduler.update(success of round k-1's rollouts, gain of phase k-1)
                  allocate the budget B; roll out pi_k n_i times on task i, executing the expert's
                  action with probability beta_k and always storing its label -> rounds/round-k
    phase k       train pi_{k+1} on D(k) (warm start from pi_k); losses; evaluate -> policies/round-k
                  beta_{k+1} = max(beta_k - delta, beta_min)

``--mode=bc`` runs round 0 only, with the whole budget. Task need is the success of the episodes
where only the learner acted; performance gain is ``max(0, L_previous - L_end)`` per task, the
previous phase's policy against the new one on the same frames (``docs/dagger.md``, "The protocol").
Committed rounds and phases are immutable: a resumed run restarts at the first uncommitted step and,
as every random choice derives from the seed and the round, makes the same allocations.
"""

from __future__ import annotations

import logging
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from tqdm import tqdm

from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.datasets.records import RoundRecord, allocation_view
from lerobot_mtdagger.envs import suite_from_config
from lerobot_mtdagger.envs.base import TaskSuite
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.rollout.collect import (
    Episode,
    EpisodeOptions,
    learner_success_by_task,
    run_episodes,
    success_by_task,
)
from lerobot_mtdagger.runner.rollout.evaluate import EvalResult, PolicyRunner, evaluate
from lerobot_mtdagger.runner.rollout.expert_check import EXPERT_CHECK_FILE
from lerobot_mtdagger.runner.rollout.workers import EnvWorkers
from lerobot_mtdagger.runner.run_setup import (
    beta_for_round,
    check_budget,
    kept_tasks_check,
    unseen_task_suite,
)
from lerobot_mtdagger.runner.run_summary import finished_summary, is_finished, last_round, summary_line
from lerobot_mtdagger.runner.training.train import RoundCache, check_heldout, student_config, train_on_rounds

if TYPE_CHECKING:
    from lerobot_mtdagger.runner.training.train import TrainedPhase
from lerobot_mtdagger.scheduler import Allocation, Scheduler, allocate_probabilities
from lerobot_mtdagger.utils.quiet import quiet_third_party
from lerobot_mtdagger.utils.seeds import COLLECT_STREAM

logger = logging.getLogger(__name__)


@dataclass
class RunContext:
    """Everything one experiment run holds open."""

    config: RunConfig
    suite: TaskSuite
    experiment: ExperimentDir
    workers: EnvWorkers
    show_progress: bool
    heldout_suite: TaskSuite | None = None
    timings: dict[int, dict[str, float]] = field(default_factory=dict)
    rounds: RoundCache = field(default_factory=RoundCache)

    @property
    def task_names(self) -> list[str]:
        """The experiment's task vocabulary."""
        return self.suite.task_names

    @property
    def last_round(self) -> int:
        """Index of the last round of the experiment."""
        return last_round(self.config)


# -------------------------------------------------------------------------------------------------
# Rounds
# -------------------------------------------------------------------------------------------------


def initial_allocation(ctx: RunContext) -> list[int]:
    """Round-0 episodes per task: n0, plus the DAgger rounds' budget for BC (split uniformly)."""
    num_tasks = len(ctx.task_names)
    assert ctx.config.dagger.initial_demos is not None  # filled by RunConfig's preset
    if not ctx.config.is_bc:
        return [ctx.config.dagger.initial_demos] * num_tasks
    assert ctx.config.dagger.rounds is not None  # filled by RunConfig's preset
    extra = ctx.config.dagger.rounds * ctx.config.dagger.budget_for(num_tasks)
    uniform = allocate_probabilities(np.full(num_tasks, 1.0 / num_tasks), extra, 0)
    return [ctx.config.dagger.initial_demos + int(n) for n in uniform]


def schedule_round(ctx: RunContext, round_index: int) -> tuple[Scheduler, Allocation]:
    """Feeds the scheduler round k-1's rollout success and phase k-1's gain, then allocates."""
    experiment = ctx.experiment
    previous = experiment.read_round_record(round_index - 1)
    scheduler = Scheduler(ctx.config.scheduler, len(ctx.task_names))
    if previous.scheduler_state is not None:
        scheduler.load_state_dict(previous.scheduler_state)
    phase = experiment.read_phase_record(round_index - 1)
    measurements: dict[str, Any] = {}
    if phase.gain is not None:
        measurements["gain"] = phase.gain
    if previous.learner_success is not None and round_index - 1 > 0:
        rates = [np.nan if r is None else r for r in previous.learner_success]
        # Round k-1's rollouts ran the policy of phase k-2: trained on the demos before round k-1's.
        behind = np.subtract(previous.demos_so_far, previous.episodes_per_task).tolist()
        measurements |= {"success_rate": rates, "episodes": previous.learner_episodes, "demos": behind}
    measurements["demos_so_far"] = list(previous.demos_so_far)
    scheduler.update(**measurements)
    allocation = scheduler.allocate(ctx.config.dagger.budget_for(len(ctx.task_names)))
    if round_index == 1:
        allocation.notes.append(
            "round 1: no learner rollout and no warm-started phase measured yet, the prior decides"
        )
    return scheduler, allocation


def collect_round(ctx: RunContext, round_index: int) -> None:
    """Collects, records and commits one round."""
    start = time.perf_counter()
    config = ctx.config
    if round_index == 0:
        scheduler, allocation = None, None
        # Expert demonstrations run to the env's own truncation (they end soon after success).
        counts, runner, beta, max_steps = initial_allocation(ctx), None, 1.0, None
    else:
        scheduler, allocation = schedule_round(ctx, round_index)
        counts = allocation.episodes_per_task
        with quiet_third_party():  # LeRobot prints "Loading weights from local directory"
            runner = PolicyRunner.from_pretrained(
                ctx.experiment.policy_root(round_index - 1), config.policy.device
            )
        beta, max_steps = beta_for_round(config, round_index), config.rollout.max_steps
    with tqdm(
        total=sum(counts), desc=f"round {round_index} collect", leave=False, disable=not ctx.show_progress
    ) as bar:
        options = EpisodeOptions(
            beta=beta,
            seed=config.seed,
            round_index=round_index,
            stream=COLLECT_STREAM,
            record=True,
            max_steps=max_steps,
            steps_after_success=config.rollout.steps_after_success,
            mixing=config.dagger.mixing,
            expert_multiple=config.rollout.expert_multiple,
        )
        episodes = run_episodes(ctx.workers, counts, options, policy=runner, progress=lambda _: bar.update(1))
    collected = time.perf_counter()
    dataset = ctx.experiment.write_round(
        round_index,
        ctx.experiment.round_features(ctx.suite.features),
        ctx.task_names,
        [(ctx.task_names[episode.task_index], episode.frames) for episode in episodes],
    )
    record = round_record(ctx, round_index, counts, beta, episodes, scheduler, allocation)
    ctx.experiment.commit_round(round_index, dataset, record)
    ctx.timings.setdefault(round_index, {}).update(
        collect_s=collected - start, write_s=time.perf_counter() - collected
    )


def round_record(
    ctx: RunContext,
    round_index: int,
    counts: list[int],
    beta: float,
    episodes: list[Episode],
    scheduler: Scheduler | None,
    allocation: Allocation | None,
) -> RoundRecord:
    """The round's record for meta/info.json (lists aligned with task_names)."""
    config = ctx.config
    num_tasks = len(ctx.task_names)
    rollout_success, rollout_episodes = success_by_task(episodes, num_tasks)
    learner_success, learner_episodes = learner_success_by_task(episodes, num_tasks)
    previous_demos = (
        [0] * num_tasks
        if round_index == 0
        else ctx.experiment.read_round_record(round_index - 1).demos_so_far
    )
    common: dict[str, Any] = {
        "task_names": ctx.task_names,
        "round": round_index,
        "method": config.method,
        "beta": beta,
        "seed": config.seed,
        "budget": int(sum(counts)),
        "temperature": config.scheduler.temperature,
        "n_min": config.scheduler.min_episodes,
        "episodes_per_task": [int(n) for n in counts],
        "demos_so_far": [int(a + b) for a, b in zip(previous_demos, counts, strict=True)],
        "rollout_success": rollout_success if round_index > 0 else None,
        "rollout_episodes": rollout_episodes,
        "expert_success": rollout_success if round_index == 0 else None,
        "learner_success": learner_success if round_index > 0 else None,
        "learner_episodes": learner_episodes if round_index > 0 else None,
        "learner_steps": int(sum(e.learner_steps for e in episodes)),
        "frames": int(sum(e.steps for e in episodes)),
        "config": config.to_dict(),
    }
    if allocation is None:
        notes = ["round 0: expert demonstrations only, no scheduling and no policy yet"]
        if config.is_bc:
            notes.append("bc: the whole data budget in one round of expert demonstrations")
        return RoundRecord(
            **common,
            **allocation_view(None),
            eval_success=None,
            allocation=None,
            scheduler_state=None,
            notes=notes,
        )
    assert scheduler is not None  # it gave the allocation
    phase = ctx.experiment.read_phase_record(round_index - 1)
    alloc = allocation.to_dict()
    return RoundRecord(
        **common,
        **allocation_view(alloc),
        eval_success=phase.eval["success"] if phase.eval else None,
        allocation=alloc,
        scheduler_state=scheduler.state_dict(),
        notes=alloc["notes"],
    )


# -------------------------------------------------------------------------------------------------
# Training phases
# -------------------------------------------------------------------------------------------------


def train_round(ctx: RunContext, round_index: int) -> None:
    """Trains on D(round_index), evaluates the student on the training and the unseen tasks, commits."""
    start = time.perf_counter()
    unseen = bool(ctx.suite.heldout_task_names)
    policy_cfg = student_config(ctx.config, ctx.suite.features, ctx.task_names, unseen)
    roots = [ctx.experiment.round_root(k) for k in range(round_index + 1)]
    data = ctx.rounds.load(roots, list(policy_cfg.input_features))
    previous = ctx.experiment.policy_root(round_index - 1) if round_index > 0 else None
    loaded = time.perf_counter()
    saved = ctx.experiment.phase_progress_path(round_index)
    trained = train_on_rounds(ctx.config, policy_cfg, data, round_index, previous, ctx.show_progress, saved)
    trained_at = time.perf_counter()
    staging = ctx.experiment.staging_policy_root(round_index)
    trained.save(staging)
    evaluations = evaluate_student(ctx, trained, round_index)
    timing = {
        "load_s": loaded - start + trained.prepare_s,
        "train_s": trained.train_s,
        "steps_s": trained.result.steps_s,  # the bare optimiser steps within train_s
        "task_loss_s": trained.result.task_loss_s,  # the per-task loss before and after them
        "eval_s": time.perf_counter() - trained_at,
    }
    ctx.timings.setdefault(round_index, {}).update(timing)
    demos = ctx.experiment.read_round_record(round_index).demos_so_far
    record = trained.record(round_index, ctx.config.training.gain_split, demos, ctx.timings[round_index])
    record.eval, record.heldout_eval = evaluations
    ctx.experiment.commit_phase(round_index, staging, record)


def evaluate_student(
    ctx: RunContext, trained: TrainedPhase, round_index: int
) -> tuple[dict | None, dict | None]:
    """``EvalResult.to_dict()`` on the training and the unseen tasks (None: the phase is not evaluated)."""
    if not ctx.config.rollout.evaluates(round_index):
        return None, None
    runner = ctx.config.student.make_runner(trained.policy, trained.preprocessor, trained.postprocessor)
    results = [evaluate_phase(ctx, runner, ctx.workers), None]
    if ctx.heldout_suite is not None:
        # Workers of their own, only while they evaluate: each holds its drawers' envs and renderers.
        # They run while the run's own workers wait, on the CPUs those hold (Ray: no reservation).
        with ctx.config.rollout.env_workers(ctx.heldout_suite, reserve_cpus=False) as heldout_workers:
            results[1] = evaluate_phase(ctx, runner, heldout_workers)
    both = tuple(None if result is None else result.to_dict() for result in results)
    return cast("tuple[dict | None, dict | None]", both)  # results: the training and the unseen tasks'


def evaluate_phase(ctx: RunContext, runner: PolicyRunner, workers: EnvWorkers) -> EvalResult | None:
    """Evaluates the freshly trained policy on the tasks of ``workers`` (None when eval_episodes is 0).

    The unseen tasks' result is recorded beside the training tasks' and never reaches the scheduler.
    """
    if ctx.config.rollout.eval_episodes == 0:
        return None
    assert ctx.config.rollout.eval_episodes is not None  # filled by RunConfig's preset
    episodes = ctx.config.rollout.eval_episodes * len(workers.suite.task_names)
    with tqdm(total=episodes, desc="eval", leave=False, disable=not ctx.show_progress) as bar:
        result, _ = evaluate(
            workers,
            runner,
            ctx.config.rollout.eval_episodes,
            ctx.config.seed,
            progress=lambda _: bar.update(1),
        )
    return result


# -------------------------------------------------------------------------------------------------
# The experiment
# -------------------------------------------------------------------------------------------------


def run(
    config: RunConfig,
    on_summary: Callable[[str], None] | None = None,
    on_start: Callable[[], None] | None = None,
) -> list[str]:
    """Runs (or resumes) one experiment; returns the per-round summary lines.

    ``on_summary`` gets each round's line as soon as the round is done; ``on_start`` is called once
    every check has passed and the experiment is locked.

    Raises:
        UserError: If the output directory exists and ``resume`` is false, on a bad config, on a
            foreign or altered output directory, and (``ExperimentLockedError``) if another run writes
            into it.
        FloatingPointError: If training diverges.
        WorkerDiedError: If an env worker process dies.
    """
    assert config.output_dir is not None  # RunConfig.__post_init__ fills it
    experiment = ExperimentDir(config.output_dir)
    if config.resume:
        experiment.check_resumable(config.to_dict(), added_defaults=RunConfig.option_defaults())
    with quiet_third_party():  # importing MetaWorld's renderer logs an OpenGL INFO line
        suite = config.expert.suite_with_experts(suite_from_config(config.suite))
        check = kept_tasks_check(config, suite, experiment)
        if check is not None:
            suite = config.expert.suite_with_experts(suite_from_config(config.suite, tasks=check.kept))
    check_budget(config, len(suite.task_names))
    check_heldout(config, len(suite.task_names))
    if not config.resume:
        extra = {EXPERT_CHECK_FILE: check.to_dict()} if check is not None else None
        experiment.initialise(config.to_dict(), extra)
    finished = config.resume and is_finished(experiment, last_round(config))
    with experiment.writer_lock(record_pid=not finished):  # a finished run's folder is left as it is
        if config.resume:
            experiment.check_committed_files()  # refuses foreign, corrupt or changed rounds and policies
            experiment.update_ledger()  # a record committed just before a cut-off, and older experiments
            experiment.clear_staging()
            assert config.dagger.rounds is not None  # filled by RunConfig's preset
            experiment.extend_rounds(config.dagger.rounds)  # a DAgger run resumed with more rounds
        if on_start is not None:
            on_start()
        if finished:
            return finished_summary(experiment, last_round(config), on_summary)
        return _run_locked(config, suite, experiment, on_summary)


def _run_locked(
    config: RunConfig, suite: TaskSuite, experiment: ExperimentDir, on_summary: Callable[[str], None] | None
) -> list[str]:
    """The rounds and phases of ``run``, with the experiment's writer lock held."""
    handler = logging.FileHandler(experiment.root / "run.log")
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    logging.getLogger("lerobot_mtdagger").addHandler(handler)
    show = config.progress and sys.stderr.isatty()
    lines = []
    rounds_done, phases_done = set(experiment.committed_rounds()), set(experiment.committed_phases())
    try:
        with config.rollout.env_workers(suite) as workers:
            heldout = unseen_task_suite(config, suite)
            ctx = RunContext(config, suite, experiment, workers, show, heldout_suite=heldout)
            for round_index in range(ctx.last_round + 1):
                if round_index not in rounds_done:
                    collect_round(ctx, round_index)
                if round_index not in phases_done:
                    train_round(ctx, round_index)
                lines.append(summary_line(experiment, round_index))
                logger.info(lines[-1])
                if on_summary is not None:
                    on_summary(lines[-1])
    finally:
        logging.getLogger("lerobot_mtdagger").removeHandler(handler)
        handler.close()
    return lines
