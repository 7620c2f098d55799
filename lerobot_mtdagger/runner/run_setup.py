"""What a run settles before its rounds: kept and unseen tasks, the budget check, scheduler and beta."""

from __future__ import annotations

import logging

from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.envs.base import TaskSuite
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.rollout.expert_check import EXPERT_CHECK_FILE, ExpertCheck, measure_expert_check
from lerobot_mtdagger.utils.errors import UserError

logger = logging.getLogger(__name__)


def beta_for_round(config: RunConfig, round_index: int) -> float:
    """Probability of executing the expert's action in a round (1 in round 0)."""
    if round_index == 0:
        return 1.0
    dagger = config.dagger
    return max(dagger.beta - (round_index - 1) * dagger.beta_decay, dagger.beta_min)


def check_budget(config: RunConfig, num_tasks: int) -> None:
    """Refuses a round budget that cannot give every task n_min episodes (``UserError`` with the numbers)."""
    budget = config.dagger.budget_for(num_tasks)
    n_min = config.scheduler.min_episodes
    if not config.is_bc and budget < n_min * num_tasks:
        raise UserError(
            f"budget={budget} is smaller than n_min * num_tasks = {n_min} * {num_tasks} = "
            f"{n_min * num_tasks}: raise --dagger.budget to at least {n_min * num_tasks} or lower "
            "--scheduler.n_min."
        )


def kept_tasks_check(config: RunConfig, suite: TaskSuite, experiment: ExperimentDir) -> ExpertCheck | None:
    """The tasks ``--expert.min_success`` keeps: read back on a resume, else measured (None: no rule)."""
    options = config.expert
    if options.min_success is None:
        return None
    stored = experiment.root / EXPERT_CHECK_FILE
    if config.resume:
        return ExpertCheck.read(stored)
    logger.info(
        "Measuring each task's expert on %d episodes (--expert.min_success)", options.success_episodes
    )
    return measure_expert_check(suite, options.min_success, options.success_episodes, config.seed)


def unseen_task_suite(config: RunConfig, suite: TaskSuite) -> TaskSuite | None:
    """The held-out tasks each phase is also evaluated on (None: none, no shared embedding, no evaluation)."""
    heldout = suite.heldout_suite()
    if heldout is None or config.rollout.eval_episodes == 0:
        return None
    if config.student.task_dropout(config.policy, True) == 0.0:
        logger.info(
            "Unseen tasks are not evaluated: --policy.task_dropout=0 gives no embedding to act on them."
        )
        return None
    return heldout
