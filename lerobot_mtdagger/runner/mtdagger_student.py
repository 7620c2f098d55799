"""The ``mtdagger`` student: the package's own policy (``--policy.type=mtdagger``, the default).

Its options are ``PolicyOptions``; its policy ``MTDAggerPolicy`` with its own processors; its
training seam ``steps.MTDAggerOps`` (fused AdamW on the imitation loss); the previous phase's loss
the MSE of that policy's actions; its evaluation runner ``evaluate.PolicyRunner`` (one action per
observation). Reading this module imports no torch and no LeRobot: they are imported on first use.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from lerobot_mtdagger.runner.student import Student
from lerobot_mtdagger.runner.student_options import PolicyOptions


class MTDAggerStudent(Student):
    """The ``mtdagger`` policy as the DAgger student (see the module docstring)."""

    lr_option = "lr"

    def options_class(self) -> type:
        """``PolicyOptions``."""
        return PolicyOptions

    def policy_config(
        self, options: Any, suite_features: dict[str, Any], task_names: Sequence[str], unseen: bool
    ) -> Any:
        """An ``MTDAggerConfig`` (task dropout ``options.resolved_task_dropout(unseen)``)."""
        from lerobot_mtdagger.runner.training.train import policy_config

        task_dropout = options.resolved_task_dropout(unseen)
        return policy_config(suite_features, task_names, options, options.device, task_dropout)

    def make_policy(self, policy_cfg: Any, stats: dict[str, dict[str, Any]]) -> tuple[Any, Any, Any]:
        """An ``MTDAggerPolicy`` moved to its config's device, and its processors for ``stats``."""
        from lerobot_mtdagger.policies import MTDAggerPolicy
        from lerobot_mtdagger.runner.training.train import build_processors

        return MTDAggerPolicy(policy_cfg).to(policy_cfg.device), *build_processors(policy_cfg, stats)

    def phase_ops(self, policy: Any, data: Any, options: Any) -> Any:
        """``steps.MTDAggerOps`` with the phase's learning rate and schedule."""
        from lerobot_mtdagger.runner.training.steps import MTDAggerOps

        return MTDAggerOps(policy, data, options.lr, options.lr_schedule)

    def previous_losses(self, runner: Any, data: Any, index: Any, options: Any) -> list[float | None]:
        """The MSE of its actions (through its own processors) in this phase's normalisation."""
        from lerobot_mtdagger.runner.training.task_loss import per_task_loss_of

        del options
        return per_task_loss_of(runner.predict, data, index, len(data.task_names))

    def make_runner(self, policy: Any, preprocessor: Any, postprocessor: Any) -> Any:
        """``evaluate.PolicyRunner``: one action per observation."""
        from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner

        return PolicyRunner(policy, preprocessor, postprocessor)
