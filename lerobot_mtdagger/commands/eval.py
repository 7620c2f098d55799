"""``lerobot-mtdagger eval``: success per task of a pretrained policy (mtdagger, ACT, Diffusion).

Its options are ``EvalConfig`` (``configs/eval.py``). The suite's observations default to those the
policy was trained on; ``shift`` (``commands/shift.py``) loads its suite and policy the same way
(``suite_and_policy``).
"""

from __future__ import annotations

import dataclasses
import json
import logging
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lerobot_mtdagger.commands.configs.eval import HELDOUT_TASKS, EvalConfig
from lerobot_mtdagger.datasets.verify import check_policy_folder
from lerobot_mtdagger.envs import suite_from_config
from lerobot_mtdagger.envs.base import TaskSuite
from lerobot_mtdagger.envs.config import DEFAULT_IMAGE_SIZE, DEFAULT_NUM_POINTS, SuiteConfig
from lerobot_mtdagger.policies.mtdagger.configuration_mtdagger import is_pointcloud_feature
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner, evaluate
from lerobot_mtdagger.utils.errors import UserError

__all__ = ["EvalConfig", "check_policy", "eval_command", "observation_options", "suite_and_policy"]

logger = logging.getLogger(__name__)


def check_policy(config: EvalConfig) -> list[str]:
    """Checks the policy folder before it is loaded (``datasets.verify.check_policy_folder``).

    A folder is checked against the checksums its ``training.json`` carries wherever it lives, and with
    its experiment when it is one's; a Hub id is loaded by LeRobot unchecked (said at info level).

    Returns:
        The problems read past with ``--unverified=true`` (else empty).

    Raises:
        CorruptExperimentError: In one line naming what changed and the fix.
    """
    assert config.policy_path is not None  # EvalConfig refuses None
    folder = Path(config.policy_path)
    if not folder.is_dir():
        logger.info("%s is not a local folder: its files are not checked against checksums", folder)
        return []
    unverified = config.unverified or config.allow_changed_policy
    return check_policy_folder(folder, unverified, RunConfig.option_defaults())


def suite_and_policy(config: EvalConfig) -> tuple[TaskSuite, PolicyRunner]:
    """The suite the config names and its pretrained policy, checked to take the suite's observations.

    The policy folder's files are checked first (``check_policy``) by the command.
    """
    assert config.policy_path is not None  # EvalConfig refuses None
    runner = PolicyRunner.from_pretrained(config.policy_path, trust_checkpoint=config.trust_checkpoint)
    suite_config = dataclasses.replace(config.suite, **observation_options(runner, config.suite))
    if list(suite_config.tasks) == [HELDOUT_TASKS]:
        suite = suite_from_config(suite_config, tasks=None).heldout_suite()
        if suite is None:
            raise UserError(
                f"Suite {suite_config.name!r} has no held-out tasks: --suite.tasks='[heldout]' is for the "
                "drawers."
            )
    else:
        suite = suite_from_config(suite_config)
        trained = [name for name in suite.task_names if name in runner.task_names]
        if not suite_config.tasks and runner.task_names and not trained and not runner.acts_on_unseen_tasks:
            shown = ", ".join(runner.task_names[:4]) + (", ..." if len(runner.task_names) > 4 else "")
            raise UserError(
                f"The policy was trained on {shown}, none of which --suite.name={suite_config.name} has "
                "(eval's default suite is metaworld-mt10): pass the --suite.name it was trained on."
            )
        if not suite_config.tasks and trained and len(trained) < len(suite.task_names):
            logger.info("Evaluating the %d tasks of %s the policy knows", len(trained), suite_config.name)
            suite = suite_from_config(suite_config, tasks=trained)
    assert suite_config.obs_mode is not None  # observation_options gives one
    runner.check_inputs(suite.features, suite_config.obs_mode)
    if config.unseen_rule == "nearest":
        unseen = [name for name in suite.task_names if name not in runner.task_names]
        runner.act_as({name: suite.nearest_training_task(name, runner.task_names) for name in unseen})
        for name, proxy in runner.task_aliases.items():
            logger.info("Unseen task %r: the policy acts with the task input of %r.", name, proxy)
    runner.check_tasks(suite.task_names)
    return suite, runner


def observation_options(runner: PolicyRunner, suite: SuiteConfig) -> dict[str, Any]:
    """``obs_mode``, ``num_points`` and ``image_size``: the suite config's, else the policy's.

    A policy with a point-cloud input was trained on clouds of its input's point count, one with an
    image input on images of its side, any other on state.
    """
    features = runner.policy.config.input_features
    clouds = [f for key, f in features.items() if is_pointcloud_feature(key, f)]
    images = [f for key, f in features.items() if key.startswith("observation.image")]
    trained = "pointcloud" if clouds else "rgb" if images else "state"
    return {
        "obs_mode": suite.obs_mode or trained,
        "num_points": suite.num_points or (clouds[0].shape[0] if clouds else DEFAULT_NUM_POINTS),
        "image_size": suite.image_size or (images[0].shape[-1] if images else DEFAULT_IMAGE_SIZE),
    }


def eval_command(config: EvalConfig) -> dict:
    """Evaluates a pretrained policy per task with the pure policy acting."""
    unverified = check_policy(config)
    suite, runner = suite_and_policy(config)
    with config.env_workers(suite) as workers:
        result, _ = evaluate(workers, runner, config.episodes, config.seed)
    progress: Sequence[float | None] = result.progress or [None] * len(result.task_names)
    for task, success, score in zip(result.task_names, result.success, progress, strict=True):
        line = f"{task:<32} {success:.3f}" + ("" if score is None else f"  progress {score:.2f}/3")
        proxy = runner.task_aliases.get(task)
        print(line + ("" if proxy is None else f"  (acting as {proxy})"))
    mean_progress = "" if result.progress is None else f"  progress {np.mean(result.progress):.2f}/3"
    print(f"{'mean':<32} {result.mean:.3f}{mean_progress}")
    values = result.to_dict() | {"unseen_rule": config.unseen_rule}
    if runner.task_aliases:
        values["acted_as"] = dict(runner.task_aliases)
    if unverified:
        values["unverified"] = unverified
    if config.output is not None:
        config.output.write_text(json.dumps(values, indent=2))
    return values
