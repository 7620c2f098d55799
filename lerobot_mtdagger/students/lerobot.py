"""LeRobot's own policies (ACT, Diffusion Policy) as the DAgger student: config, batches, losses.

``LeRobotOps`` implements the runner's training seam for any LeRobot ``PreTrainedPolicy``: frame
windows as ``delta_timestamps`` give them (history and action chunk within the episode, with
``action_is_pad``), the task as a one-hot ``observation.environment_state`` (zeroed by task dropout),
the policy's own ``forward`` loss (per task under a fixed seed) and its config's optimiser presets.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import torch
from lerobot.configs.policies import PreTrainedConfig
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.policies.factory import get_policy_class, make_pre_post_processors
from lerobot.policies.pretrained import PreTrainedPolicy
from lerobot.processor import PolicyProcessorPipeline
from lerobot.utils.constants import OBS_IMAGES

from lerobot_mtdagger.policies.task_conditioning import (
    TASK_FEATURE,
    TaskOneHotProcessorStep,
    task_feature,
    task_one_hot,
)
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.policy_options import UNSEEN_TASK_DROPOUT
from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner
from lerobot_mtdagger.runner.student import Stats, Student
from lerobot_mtdagger.runner.training.normalise import NormalisedData
from lerobot_mtdagger.runner.training.steps import StepOptions
from lerobot_mtdagger.students.chunk_runner import ChunkRunner
from lerobot_mtdagger.students.options import (
    UNSUPPORTED_STUDENT_OPTIONS,
    lerobot_options_class,
    lerobot_policy_config,
)
from lerobot_mtdagger.utils.lerobot_compat import dataset_to_policy_features

LOSS_CHUNK = 256
"""Frames per forward pass when measuring a LeRobot student's per-task loss."""


@dataclass
class LeRobotStudentConfig:
    """A LeRobot student: its LeRobot policy config and the run's tasks.

    Attributes:
        policy: The LeRobot policy config; its inputs include the one-hot task vector.
        task_names: The training tasks, in the order of the one-hot positions.
        task_dropout: Probability of zeroing a training frame's task vector.
    """

    policy: Any
    task_names: list[str]
    task_dropout: float

    @property
    def input_features(self) -> dict[str, PolicyFeature]:
        """The observations the student reads from the suite (without the task vector)."""
        return {k: f for k, f in self.policy.input_features.items() if k != TASK_FEATURE}

    @property
    def image_features(self) -> dict[str, PolicyFeature]:
        """The image inputs."""
        return dict(self.policy.image_features)


def lerobot_student_config(
    options: Any, suite_features: dict[str, Any], task_names: Sequence[str], task_dropout: float
) -> LeRobotStudentConfig:
    """The LeRobot student of a run's options for a suite (``ValueError`` if the policy refuses them)."""
    config = lerobot_policy_config(options)
    features = dataset_to_policy_features(suite_features)
    config.input_features = {k: f for k, f in features.items() if f.type is not FeatureType.ACTION}
    config.input_features[TASK_FEATURE] = task_feature(len(task_names))
    config.output_features = {
        "action": PolicyFeature(type=FeatureType.ACTION, shape=features["action"].shape)
    }
    config.validate_features()
    return LeRobotStudentConfig(policy=config, task_names=list(task_names), task_dropout=task_dropout)


def make_lerobot_student(spec: LeRobotStudentConfig) -> Any:
    """A freshly initialised LeRobot policy of ``spec`` on its device (seed torch first: same weights)."""
    return get_policy_class(spec.policy.type)(spec.policy).to(spec.policy.device)


def make_lerobot_processors(spec: LeRobotStudentConfig, stats: dict[str, dict[str, Any]]) -> tuple[Any, Any]:
    """LeRobot's processors of the policy type, with the one-hot task step first in the pre-processor."""
    preprocessor, postprocessor = make_pre_post_processors(spec.policy, dataset_stats=stats)
    preprocessor.steps.insert(0, TaskOneHotProcessorStep(spec.task_names))
    return preprocessor, postprocessor


class EpisodeWindows:
    """Frame indices of each frame's observation history and action chunk (episodes' frames consecutive)."""

    def __init__(
        self, episode_id: torch.Tensor, observation_deltas: Sequence[int] | None, action_deltas: Sequence[int]
    ) -> None:
        """Finds each frame's episode bounds (``ValueError`` if an episode's frames are not consecutive)."""
        count = len(episode_id)
        starts_here = torch.ones(count, dtype=torch.bool)
        if count:
            starts_here[1:] = episode_id[1:] != episode_id[:-1]
        first = torch.nonzero(starts_here).flatten()
        if len(torch.unique(episode_id[first])) != len(first):
            raise ValueError("An episode's frames are not consecutive; windows need them in order.")
        lengths = torch.diff(torch.cat([first, torch.tensor([count])]))
        self.start = torch.repeat_interleave(first, lengths)
        self.end = torch.repeat_interleave(first + lengths - 1, lengths)
        self.observation_deltas = (
            None if observation_deltas is None else torch.tensor(list(observation_deltas))
        )
        self.action_deltas = torch.tensor(list(action_deltas))

    def observations(self, index: torch.Tensor) -> torch.Tensor | None:
        """(B, n_obs) history indices, clamped to the episode (None: the policy reads one frame)."""
        if self.observation_deltas is None:
            return None
        return self._clamped(index, self.observation_deltas)[0]

    def actions(self, index: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """(B, H) chunk indices clamped to the episode, and where they ran past it (``action_is_pad``)."""
        return self._clamped(index, self.action_deltas)

    def _clamped(self, index: torch.Tensor, deltas: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        wanted = index[:, None] + deltas[None, :]
        low, high = self.start[index][:, None], self.end[index][:, None]
        clamped = torch.minimum(torch.maximum(wanted, low), high)
        return clamped, (wanted < low) | (wanted > high)


class LeRobotOps:
    """The training seam for a LeRobot policy on a phase's normalised frames (see the module docstring)."""

    def __init__(
        self, policy: PreTrainedPolicy, data: NormalisedData, task_dropout: float, seed: int
    ) -> None:
        """Prepares the frame windows; ``seed`` seeds the task dropout and the loss measurements."""
        self.policy = policy
        self.data = data
        self.task_dropout = task_dropout
        self.seed = seed
        self.generator = torch.Generator().manual_seed(seed)
        config = policy.config
        self.windows = EpisodeWindows(
            data.data.episode_id, config.observation_delta_indices, config.action_delta_indices
        )
        self.observation_keys = [k for k in config.input_features if k != TASK_FEATURE]
        self.num_tasks = int(config.input_features[TASK_FEATURE].shape[0])

    def batch(self, index: torch.Tensor, dropout: bool = True) -> dict[str, torch.Tensor]:
        """The training batch at frames ``index``: windows of normalised inputs, chunk, task vector."""
        index = index.cpu()
        history = self.windows.observations(index)
        rows = index if history is None else history
        batch: dict[str, torch.Tensor] = {}
        for key in self.observation_keys:
            if key in self.data.image_keys:
                images = self.data.data.inputs[key][rows].to(self.data.device)
                batch[key] = images.movedim(-1, -3).float() / 255.0
            else:
                batch[key] = self.data.vector[key][rows.to(self.data.device)]
        tasks = self.data.data.task_index[index].clone()
        if dropout and self.task_dropout > 0:
            tasks[torch.rand(len(tasks), generator=self.generator) < self.task_dropout] = -1
        vector = task_one_hot(tasks, self.num_tasks).to(self.data.device)
        batch[TASK_FEATURE] = vector if history is None else vector[:, None].expand(-1, history.shape[1], -1)
        chunk, pad = self.windows.actions(index)
        batch["action"] = self.data.vector["action"][chunk.to(self.data.device)]
        batch["action_is_pad"] = pad.to(self.data.device)
        return batch

    def step_loss(self, index: torch.Tensor, first_of_interval: bool) -> torch.Tensor:
        """The policy's own training loss on the frames at ``index``."""
        del first_of_interval  # LeRobot's forward is the only loss
        loss, _ = self.policy.forward(self.batch(index))
        return loss

    @torch.no_grad()
    def task_losses(self, index: torch.Tensor, num_tasks: int) -> tuple[list[float | None], list[int]]:
        """The policy's loss per task over frames ``index`` (None where none) and the frame counts."""
        was_training = self.policy.training
        self.policy.train()  # ACT's loss needs its VAE encoder, which runs in training mode only
        sums = torch.zeros(num_tasks, dtype=torch.float64)
        counts = torch.zeros(num_tasks, dtype=torch.float64)
        index = index.cpu()
        task_of = self.data.data.task_index[index]
        device = next(self.policy.parameters()).device
        with torch.random.fork_rng(devices=[device] if device.type == "cuda" else []):
            torch.manual_seed(self.seed)
            for task in torch.unique(task_of).tolist():
                frames = index[task_of == task]
                for chunk in torch.split(frames, LOSS_CHUNK):
                    loss, _ = self.policy.forward(self.batch(chunk, dropout=False))
                    sums[task] += float(loss) * len(chunk)
                    counts[task] += len(chunk)
        self.policy.train(was_training)
        losses = [float(sums[i] / counts[i]) if counts[i] > 0 else None for i in range(num_tasks)]
        return losses, [int(c) for c in counts.tolist()]

    def optimizer(
        self, steps: int
    ) -> tuple[torch.optim.Optimizer, torch.optim.lr_scheduler.LRScheduler | None, float]:
        """The policy config's optimiser and scheduler presets (over ``steps``) and gradient clip norm."""
        preset = self.policy.config.get_optimizer_preset()
        optimizer = preset.build(self.policy.get_optim_params())
        schedule = self.policy.config.get_scheduler_preset()
        scheduler = None if schedule is None else schedule.build(optimizer, steps)
        return optimizer, scheduler, float(preset.grad_clip_norm)


class LeRobotStudent(Student[PreTrainedConfig, "LeRobotStudentConfig"]):
    """A LeRobot policy as the DAgger student, for LeRobot's ``--policy.type`` (``act``, ``diffusion``).

    Options: LeRobot's config plus ``batch_size``; training: ``LeRobotOps``; evaluation: ``ChunkRunner``.
    """

    lr_option = "optimizer_lr"

    def options_class(self) -> type:
        """LeRobot's config of the policy type, with ``batch_size`` (``lerobot_options_class``)."""
        return lerobot_options_class(self.saved_type)

    def options_dict(self, options: PreTrainedConfig) -> dict[str, Any]:
        """``type``, ``batch_size`` and LeRobot's own encoding of its config."""
        import draccus

        encoded = draccus.encode(lerobot_policy_config(options))
        return {"type": self.name, "batch_size": options.batch_size, **encoded}

    def check_run(self, config: RunConfig) -> None:
        """Refuses point clouds, temporal ensembling, ``lr_schedule``, unsupported options: ``ValueError``."""
        for name, reason in UNSUPPORTED_STUDENT_OPTIONS.items():
            if getattr(config.policy, name, None) not in (None, False):
                raise ValueError(f"--policy.{name} is not supported by run: {reason}; drop the option.")
        if config.training.lr_schedule != "constant":
            raise ValueError(
                f"--training.lr_schedule={config.training.lr_schedule} is for the mtdagger policy; "
                f"--policy.type={self.name} follows its own scheduler preset: drop the option."
            )
        if config.suite.obs_mode == "pointcloud":
            raise ValueError(
                f"--policy.type={self.name} cannot read point clouds (a LeRobot policy takes "
                "state and images): use --policy.type=mtdagger or --suite.obs_mode=state|rgb."
            )
        if getattr(config.policy, "temporal_ensemble_coeff", None) is not None:
            raise ValueError(
                "--policy.temporal_ensemble_coeff is not supported for a DAgger student (its action "
                "queue is kept per episode): drop it and set --policy.n_action_steps instead."
            )

    def policy_config(
        self,
        options: PreTrainedConfig,
        suite_features: dict[str, Any],
        task_names: Sequence[str],
        unseen: bool,
    ) -> LeRobotStudentConfig:
        """``lerobot_student_config`` (task dropout ``UNSEEN_TASK_DROPOUT`` with held-out tasks, else 0)."""
        return lerobot_student_config(options, suite_features, task_names, self.task_dropout(options, unseen))

    def task_dropout(self, options: PreTrainedConfig, unseen: bool) -> float:
        """``UNSEEN_TASK_DROPOUT`` with held-out tasks, else 0."""
        del options
        return UNSEEN_TASK_DROPOUT if unseen else 0.0

    def make_policy(
        self, policy_cfg: LeRobotStudentConfig, stats: Stats
    ) -> tuple[PreTrainedPolicy, PolicyProcessorPipeline, PolicyProcessorPipeline]:
        """``make_lerobot_student`` and ``make_lerobot_processors``."""
        return make_lerobot_student(policy_cfg), *make_lerobot_processors(policy_cfg, stats)

    def phase_ops(self, policy: PreTrainedPolicy, data: NormalisedData, options: StepOptions) -> LeRobotOps:
        """``LeRobotOps`` with the phase's task dropout and seed."""
        return LeRobotOps(policy, data, options.task_dropout, options.seed)

    def previous_losses(
        self, runner: PolicyRunner, data: NormalisedData, index: torch.Tensor, options: StepOptions
    ) -> list[float | None]:
        """Its own training loss per task on this phase's normalised frames (``LeRobotOps.task_losses``)."""
        return self.phase_ops(runner.policy, data, options).task_losses(index, len(data.task_names))[0]

    def make_runner(
        self,
        policy: PreTrainedPolicy,
        preprocessor: PolicyProcessorPipeline,
        postprocessor: PolicyProcessorPipeline,
    ) -> ChunkRunner:
        """``ChunkRunner``: an action queue per running episode, chunks from ``predict_chunk``."""
        return ChunkRunner(policy, preprocessor, postprocessor, predict_chunk=self.predict_chunk)

    def predict_chunk(self, policy: PreTrainedPolicy, batch: dict[str, torch.Tensor]) -> torch.Tensor:
        """Normalised action chunks (B, n, action_dim) from LeRobot's ``predict_action_chunk``.

        ``batch`` holds current observations, or histories (B, n_obs_steps, ...) for ``DiffusionStudent``.
        """
        return policy.predict_action_chunk(batch)


class DiffusionStudent(LeRobotStudent):
    """Diffusion Policy: its observation history goes to the denoiser directly.

    LeRobot's ``predict_action_chunk`` reads the history from one queue for the whole batch; the runner
    keeps one per episode, so the images are stacked as ``forward`` does and ``generate_actions`` called.
    """

    def predict_chunk(self, policy: PreTrainedPolicy, batch: dict[str, torch.Tensor]) -> torch.Tensor:
        """Normalised action chunks (B, horizon, action_dim) for current observations or histories."""
        if policy.config.n_obs_steps == 1:
            return policy.predict_action_chunk(batch)
        image_keys = list(policy.config.image_features)
        if image_keys:
            batch = {**batch, OBS_IMAGES: torch.stack([batch[key] for key in image_keys], dim=-4)}
        return policy.diffusion.generate_actions(batch)
