"""The ``mtdagger`` student: the package's own policy (``--policy.type=mtdagger``, the default).

Options ``PolicyOptions``; policy ``MTDAggerPolicy`` with its processors; training seam
``MTDAggerOps``; per-task loss the action MSE (``per_task_loss``, and ``per_task_loss_of`` for the
previous phase's policy); evaluation runner ``evaluate.PolicyRunner``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import torch
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.policies.pretrained import PreTrainedPolicy
from lerobot.processor import PolicyProcessorPipeline

from lerobot_mtdagger.policies import MTDAggerConfig, MTDAggerPolicy, make_mtdagger_pre_post_processors
from lerobot_mtdagger.policies.mtdagger.modeling_mtdagger import per_task_means
from lerobot_mtdagger.runner.policy_options import PolicyOptions
from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner
from lerobot_mtdagger.runner.student import Stats, Student
from lerobot_mtdagger.runner.training.normalise import NormalisedData
from lerobot_mtdagger.runner.training.steps import StepOptions
from lerobot_mtdagger.utils.lerobot_compat import dataset_to_policy_features

logger = logging.getLogger(__name__)


def policy_config(
    suite_features: dict[str, Any],
    task_names: Sequence[str],
    options: Any,
    device: str = "cpu",
    task_dropout: float = 0.0,
) -> MTDAggerConfig:
    """The ``mtdagger`` config for a suite's features and the run's policy options."""
    features = dataset_to_policy_features(suite_features)
    return MTDAggerConfig(
        device=device,
        task_names=list(task_names),
        input_features={k: f for k, f in features.items() if f.type is not FeatureType.ACTION},
        output_features={"action": PolicyFeature(type=FeatureType.ACTION, shape=features["action"].shape)},
        optimizer_lr=options.lr,
        state_hidden_dims=tuple(options.state_hidden_dims),
        head_hidden_dims=tuple(options.head_hidden_dims),
        pointnet_dims=tuple(options.pointnet_dims),
        pointnet_layer_norm=options.pointnet_layer_norm,
        pointcloud_embedding_dim=options.pointcloud_embedding_dim,
        task_embedding_dim=options.task_embedding_dim,
        task_dropout=task_dropout,
        push_to_hub=False,
    )


def build_processors(config: MTDAggerConfig, stats: dict[str, dict[str, np.ndarray]]) -> tuple[Any, Any]:
    """The policy's LeRobot pre- and post-processors for ``stats``."""
    return make_mtdagger_pre_post_processors(config, dataset_stats=stats)


def make_optimizer(policy: MTDAggerPolicy, lr: float) -> torch.optim.AdamW:
    """AdamW over the policy's parameters with its weight decay, one fused kernel per step."""
    fused = policy.task_embedding.weight.device.type in ("cpu", "cuda")
    return torch.optim.AdamW(
        policy.parameters(), lr=lr, weight_decay=policy.config.optimizer_weight_decay, fused=fused or None
    )


class MTDAggerOps:
    """The training seam for the ``mtdagger`` policy.

    A step's loss is ``policy.imitation_loss`` (the first of each log interval calls ``policy.forward``
    to log per-task losses); the per-task loss is the action MSE of ``policy.predict``.
    """

    def __init__(
        self, policy: MTDAggerPolicy, data: NormalisedData, lr: float, lr_schedule: str = "constant"
    ) -> None:
        """Remembers the policy, its frames, the learning rate and its schedule over a phase."""
        self.policy = policy
        self.data = data
        self.lr = lr
        self.lr_schedule = lr_schedule

    def step_loss(self, index: torch.Tensor, first_of_interval: bool) -> torch.Tensor:
        """The imitation loss on the frames at ``index``."""
        batch = self.data.batch(index)
        if not first_of_interval:
            return self.policy.imitation_loss(batch, task_index=batch["task_index"])
        loss, info = self.policy.forward(batch)
        info = info or {}
        logger.debug("loss %s, per task %s", info.get("loss"), info.get("per_task_loss"))
        return loss

    def task_losses(self, index: torch.Tensor, num_tasks: int) -> tuple[list[float | None], list[int]]:
        """Mean action MSE per task (``per_task_loss``)."""
        return per_task_loss(self.policy, self.data, index, num_tasks)

    def optimizer(
        self, steps: int
    ) -> tuple[torch.optim.Optimizer, torch.optim.lr_scheduler.LRScheduler | None, float]:
        """Fused AdamW, its schedule over ``steps`` (none, or ``cosine`` to 0), the gradient clip norm."""
        optimizer = make_optimizer(self.policy, self.lr)
        scheduler: torch.optim.lr_scheduler.LRScheduler | None = None
        if self.lr_schedule == "cosine":
            scheduler = torch.optim.lr_scheduler.CosineAnnealingLR(optimizer, T_max=max(steps, 1))
        return optimizer, scheduler, self.policy.config.optimizer_grad_clip_norm


@torch.no_grad()
def per_task_loss(
    policy: MTDAggerPolicy, data: NormalisedData, index: torch.Tensor, num_tasks: int
) -> tuple[list[float | None], list[int]]:
    """Mean MSE per task over the frames at ``index`` (None where a task has none) and the counts."""
    policy.eval()
    sums = torch.zeros(num_tasks, dtype=torch.float64, device=data.device)
    counts = torch.zeros(num_tasks, dtype=torch.float64, device=data.device)
    for chunk in torch.split(index, data.measure_chunk):
        batch = data.batch(chunk)
        prediction = policy.predict(batch, task_index=batch["task_index"])
        errors = ((prediction - batch["action"]) ** 2).mean(dim=1).double()
        means, chunk_counts = per_task_means(errors, batch["task_index"], num_tasks)
        sums += means * chunk_counts
        counts += chunk_counts
    sums, counts = sums.cpu(), counts.cpu()
    losses = [float(sums[i] / counts[i]) if counts[i] > 0 else None for i in range(num_tasks)]
    return losses, [int(c) for c in counts.tolist()]


@torch.no_grad()
def per_task_loss_of(
    predict: Callable[[dict[str, torch.Tensor], list[str]], torch.Tensor],
    data: NormalisedData,
    index: torch.Tensor,
    num_tasks: int,
) -> list[float | None]:
    """Mean MSE per task of another policy's actions, in ``data``'s normalisation (None where no frame).

    ``predict`` (raw inputs, task names -> unnormalised actions, e.g. the previous phase's
    ``PolicyRunner.predict``) acts on the raw frames; its actions are normalised like ``data``'s labels,
    so the loss compares with ``per_task_loss``.
    """
    sums = torch.zeros(num_tasks, dtype=torch.float64)
    counts = torch.zeros(num_tasks, dtype=torch.float64)
    for chunk in torch.split(index, data.measure_chunk):
        inputs = {key: tensor[chunk] for key, tensor in data.data.inputs.items()}
        task_index = data.data.task_index[chunk]
        raw = predict(inputs, [data.task_names[i] for i in task_index.tolist()])
        prediction = data.normalise_actions(raw, chunk).cpu()
        errors = ((prediction - data.vector["action"][chunk.to(data.device)].cpu()) ** 2).mean(dim=1).double()
        means, chunk_counts = per_task_means(errors, task_index, num_tasks)
        sums += means * chunk_counts
        counts += chunk_counts
    return [float(sums[i] / counts[i]) if counts[i] > 0 else None for i in range(num_tasks)]


class MTDAggerStudent(Student[PolicyOptions, MTDAggerConfig]):
    """The ``mtdagger`` policy as the DAgger student (see the module docstring)."""

    lr_option = "lr"

    def options_class(self) -> type:
        """``PolicyOptions``."""
        return PolicyOptions

    def policy_config(
        self, options: PolicyOptions, suite_features: dict[str, Any], task_names: Sequence[str], unseen: bool
    ) -> MTDAggerConfig:
        """An ``MTDAggerConfig`` (task dropout ``options.resolved_task_dropout(unseen)``)."""
        return policy_config(
            suite_features, task_names, options, options.device, self.task_dropout(options, unseen)
        )

    def task_dropout(self, options: PolicyOptions, unseen: bool) -> float:
        """``options.resolved_task_dropout(unseen)``."""
        return options.resolved_task_dropout(unseen)

    def make_policy(
        self, policy_cfg: MTDAggerConfig, stats: Stats
    ) -> tuple[MTDAggerPolicy, PolicyProcessorPipeline, PolicyProcessorPipeline]:
        """An ``MTDAggerPolicy`` moved to its config's device, and its processors for ``stats``."""
        return MTDAggerPolicy(policy_cfg).to(policy_cfg.device), *build_processors(policy_cfg, stats)

    def phase_ops(self, policy: PreTrainedPolicy, data: NormalisedData, options: StepOptions) -> MTDAggerOps:
        """``MTDAggerOps`` with the phase's learning rate and schedule."""
        if not isinstance(policy, MTDAggerPolicy):
            raise TypeError(f"The mtdagger student trains an MTDAggerPolicy, got {type(policy).__name__}.")
        return MTDAggerOps(policy, data, options.lr, options.lr_schedule)

    def previous_losses(
        self, runner: PolicyRunner, data: NormalisedData, index: torch.Tensor, options: StepOptions
    ) -> list[float | None]:
        """The MSE of its actions (through its own processors) in this phase's normalisation."""
        del options
        return per_task_loss_of(runner.predict, data, index, len(data.task_names))

    def make_runner(
        self,
        policy: PreTrainedPolicy,
        preprocessor: PolicyProcessorPipeline,
        postprocessor: PolicyProcessorPipeline,
    ) -> PolicyRunner:
        """``evaluate.PolicyRunner``: one action per observation."""
        return PolicyRunner(policy, preprocessor, postprocessor)
