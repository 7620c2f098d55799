"""Configuration of the multitask DAgger policy (LeRobot policy type ``mtdagger``).

The paper's appendix "Multitask Policy Architecture": an encoder per input, a learned task
embedding, fusion by concatenation and an MLP head trained with MSE on the experts' actions.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.configs.policies import PreTrainedConfig
from lerobot.configs.types import FeatureType, NormalizationMode, PolicyFeature
from lerobot.optim.optimizers import AdamWConfig
from lerobot.utils.constants import ACTION

POINTCLOUD_MARKER = "pointcloud"


def is_pointcloud_feature(key: str, feature: PolicyFeature) -> bool:
    """A point cloud is an ``observation.*pointcloud*`` feature of shape (num_points, channels)."""
    return POINTCLOUD_MARKER in key and len(feature.shape) == 2


@PreTrainedConfig.register_subclass("mtdagger")
@dataclass
class MTDAggerConfig(PreTrainedConfig):
    """Multitask policy: per-input encoders + learned task embedding -> MLP action head.

    1-D STATE/ENV inputs go through one MLP, each VISUAL input through a small CNN, and
    ``observation.*pointcloud*`` inputs of shape (N, C) through a PointNet.

    Attributes:
        task_names: The task vocabulary in a fixed order (task index i = task_names[i]), saved with the
            model and filled from the training dataset when empty; LeRobot hands the policy the task string.
        task_embedding_dim: Size of the learned task embedding z_i.
        state_hidden_dims: Hidden layer sizes of the state MLP encoder.
        state_embedding_dim: Output size of the state encoder.
        image_channels: Output channels of the CNN's convolution layers (kernel 3, stride 2 each).
        image_embedding_dim: Output size of the image encoder.
        pointnet_dims: Sizes of PointNet's shared per-point MLP; the last is the max-pooled feature size.
        pointcloud_embedding_dim: Output size of the point-cloud encoder (after the max-pool projection).
        pointnet_layer_norm: LayerNorm after every per-point layer and after the projection, as DP3's
            encoder; without it, ReLU between the layers and before the projection.
        head_hidden_dims: Hidden layer sizes of the action head.
        dropout: Dropout in the action head.
        task_dropout: Probability, per training sample, of replacing its task embedding by a shared
            "any task" embedding, which then acts on tasks outside ``task_names`` (0: such tasks fail).
        optimizer_lr: AdamW learning rate (the paper: 3e-4 on MetaWorld, 1e-4 on the drawers).
        optimizer_weight_decay: AdamW weight decay.
        optimizer_grad_clip_norm: Gradient clipping norm.
        normalization_mapping: Normalisation per feature type (point clouds, typed STATE, are normalised
            per channel: ``processor_mtdagger``).
    """

    n_obs_steps: int = 1
    task_names: list[str] = field(default_factory=list)
    task_embedding_dim: int = 32
    state_hidden_dims: tuple[int, ...] = (256, 256)
    state_embedding_dim: int = 256
    image_channels: tuple[int, ...] = (32, 64, 64, 64)
    image_embedding_dim: int = 128
    pointnet_dims: tuple[int, ...] = (64, 128, 256)
    pointcloud_embedding_dim: int = 256
    pointnet_layer_norm: bool = False
    head_hidden_dims: tuple[int, ...] = (256, 256)
    dropout: float = 0.0
    task_dropout: float = 0.0
    optimizer_lr: float = 3e-4
    optimizer_weight_decay: float = 0.0
    optimizer_grad_clip_norm: float = 10.0
    normalization_mapping: dict[str, NormalizationMode] = field(
        default_factory=lambda: {
            "VISUAL": NormalizationMode.IDENTITY,
            "STATE": NormalizationMode.MEAN_STD,
            "ENV": NormalizationMode.MEAN_STD,
            "ACTION": NormalizationMode.MEAN_STD,
        }
    )
    if "pretrained_revision" not in PreTrainedConfig.__dataclass_fields__:
        # LeRobot >= 0.5 writes this base field into every policy config; declared here on LeRobot 0.4
        # (which lacks it and refuses unknown fields), so a policy saved on either line loads on both
        pretrained_revision: str | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.n_obs_steps != 1:
            raise ValueError(f"n_obs_steps must be 1 (no observation history), got {self.n_obs_steps}.")
        self.task_names = list(self.task_names)
        duplicates = sorted({t for t in self.task_names if self.task_names.count(t) > 1})
        if duplicates:
            raise ValueError(f"task_names must be unique; repeated: {duplicates}.")
        for name in (
            "task_embedding_dim",
            "state_embedding_dim",
            "image_embedding_dim",
            "pointcloud_embedding_dim",
        ):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name} must be > 0, got {getattr(self, name)}.")
        for name in ("state_hidden_dims", "image_channels", "pointnet_dims", "head_hidden_dims"):
            dims = tuple(getattr(self, name))
            if any(d <= 0 for d in dims):
                raise ValueError(f"{name} must hold positive sizes, got {dims}.")
            setattr(self, name, dims)
        if not self.image_channels or not self.pointnet_dims:
            raise ValueError("image_channels and pointnet_dims need at least one layer each.")
        if not 0.0 <= self.dropout < 1.0:
            raise ValueError(f"dropout must be in [0, 1), got {self.dropout}.")
        if not 0.0 <= self.task_dropout < 1.0:
            raise ValueError(f"task_dropout must be in [0, 1), got {self.task_dropout}.")
        if self.optimizer_lr <= 0:
            raise ValueError(f"optimizer_lr must be > 0, got {self.optimizer_lr}.")

    def get_optimizer_preset(self) -> AdamWConfig:
        """AdamW with the configured learning rate, weight decay and clipping."""
        return AdamWConfig(
            lr=self.optimizer_lr,
            weight_decay=self.optimizer_weight_decay,
            grad_clip_norm=self.optimizer_grad_clip_norm,
        )

    def get_scheduler_preset(self) -> None:
        """Constant learning rate."""
        return None

    @property
    def vector_features(self) -> dict[str, PolicyFeature]:
        """1-D STATE/ENV inputs, encoded together by the state MLP."""
        return {
            key: ft
            for key, ft in (self.input_features or {}).items()
            if ft.type in (FeatureType.STATE, FeatureType.ENV) and not is_pointcloud_feature(key, ft)
        }

    @property
    def pointcloud_features(self) -> dict[str, PolicyFeature]:
        """(N, C) point-cloud inputs, encoded by PointNet."""
        return {key: ft for key, ft in (self.input_features or {}).items() if is_pointcloud_feature(key, ft)}

    def validate_features(self) -> None:
        """Checks inputs and outputs (``ValueError``: no input, no ``action``, a state not 1-D, no tasks)."""
        if not (self.vector_features or self.image_features or self.pointcloud_features):
            raise ValueError(
                "MTDAggerConfig has no input feature: give it observation.state, an observation.image* or an "
                "observation.*pointcloud* feature (they come from the dataset's features)."
            )
        if not self.output_features or ACTION not in self.output_features:
            raise ValueError("MTDAggerConfig needs an 'action' output feature; the dataset has no 'action'.")
        for key, ft in self.vector_features.items():
            if len(ft.shape) != 1:
                raise ValueError(f"State feature {key!r} must be 1-D, got shape {ft.shape}.")
        if not self.task_names:
            raise ValueError(
                "MTDAggerConfig.task_names is empty: pass --policy.task_names='[...]' or train on a dataset "
                "whose tasks give the vocabulary."
            )

    @property
    def observation_delta_indices(self) -> None:
        """Only the current observation."""
        return None

    @property
    def action_delta_indices(self) -> None:
        """Only the current action."""
        return None

    @property
    def reward_delta_indices(self) -> None:
        """Rewards are not used."""
        return None
