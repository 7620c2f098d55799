"""What a run settles before its rounds: kept and unseen tasks, the budget check, scheduler and beta.

``dagger.run`` reads them once; each is a function of the run's options (and, for the kept tasks,
of a measurement stored with the experiment so a resume reads it back).
"""

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
    """Refuses a round budget that cannot give every task n_min episodes, before anything runs.

    Raises:
        UserError: With the numbers and the fix.
    """
    budget = config.dagger.budget_for(num_tasks)
    n_min = config.scheduler.min_episodes
    if not config.is_bc and budget < n_min * num_tasks:
        raise UserError(
            f"budget={budget} is smaller than n_min * num_tasks = {n_min} * {num_tasks} = "
            f"{n_min * num_tasks}: raise --dagger.budget to at least {n_min * num_tasks} or lower "
            "--scheduler.n_min."
        )


def kept_tasks_check(config: RunConfig, suite: TaskSuite, experiment: ExperimentDir) -> ExpertCheck | None:
    """The tasks ``--expert.min_success`` keeps: read back on a resume, else measured (None: no rule).

    Raises:
        UserError: If no task is kept, or a resumed experiment's ``expert_check.json`` is unreadable.
    """
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
    """The held-out tasks every phase is also evaluated on.

    None where the suite has none, the policy has no shared task embedding to act on them with
    (``--policy.task_dropout=0``), or nothing is evaluated.
    """
    heldout = suite.heldout_suite()
    if heldout is None or config.rollout.eval_episodes == 0:
        return None
    if config.policy.resolved_task_dropout(True) == 0.0:
        logger.info(
            "Unseen tasks are not evaluated: --policy.task_dropout=0 gives no embedding to act on them."
        )
        return None
    return heldout
