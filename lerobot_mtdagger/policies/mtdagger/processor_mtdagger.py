"""Pre- and post-processing pipelines of the ``mtdagger`` policy.

As LeRobot's own policies: rename, add a batch dimension, move to the device, normalise inputs and
the action; unnormalise the predicted action and move it to the CPU.

Point clouds: LeRobot types an (N, C) feature as STATE, so its normaliser applies the feature's
statistics elementwise. Points are unordered samples: point k of one frame is not the same quantity
as point k of the next, so per-point statistics would be meaningless. LeRobot 0.4.4's
``compute_episode_stats`` already reduces an (N, C) feature to per-channel (C,) statistics (checked on
a recorded point-cloud dataset); statistics that arrive per point, (N, C) (other writers, hand-made
stats), are pooled by ``pool_pointcloud_stats`` into per-channel ones (mean, pooled std, min, max;
quantiles averaged) broadcast back to (N, C). Either way every point is normalised by the same
per-channel transform, saved with the processor like any other statistics.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from lerobot.processor import (
    AddBatchDimensionProcessorStep,
    DeviceProcessorStep,
    NormalizerProcessorStep,
    PolicyAction,
    PolicyProcessorPipeline,
    RenameObservationsProcessorStep,
    UnnormalizerProcessorStep,
)
from lerobot.processor.converters import policy_action_to_transition, transition_to_policy_action
from lerobot.utils.constants import POLICY_POSTPROCESSOR_DEFAULT_NAME, POLICY_PREPROCESSOR_DEFAULT_NAME

from lerobot_mtdagger.policies.mtdagger.configuration_mtdagger import MTDAggerConfig

Stats = dict[str, dict[str, Any]]


def _pool_channel_stats(stats: dict[str, Any]) -> dict[str, Any]:
    """Pools (N, C) per-point statistics into per-channel ones broadcast to (N, C)."""
    pooled: dict[str, Any] = {}
    arrays = {
        name: np.asarray(torch.as_tensor(value).cpu(), dtype=np.float64) for name, value in stats.items()
    }
    mean = arrays["mean"].mean(axis=0) if "mean" in arrays else None
    for name, value in arrays.items():
        if value.ndim != 2:
            pooled[name] = stats[name]
            continue
        if name == "mean":
            channel = mean
        elif name == "std" and mean is not None:
            second_moment = (value**2 + arrays["mean"] ** 2).mean(axis=0)
            channel = np.sqrt(np.maximum(second_moment - mean**2, 0.0))
        elif name == "min":
            channel = value.min(axis=0)
        elif name == "max":
            channel = value.max(axis=0)
        else:  # quantiles and anything else per point: average over points
            channel = value.mean(axis=0)
        pooled[name] = np.broadcast_to(channel, value.shape).astype(np.float32).copy()
    return pooled


def pool_pointcloud_stats(config: MTDAggerConfig, dataset_stats: Stats | None) -> Stats | None:
    """Returns ``dataset_stats`` with every point-cloud feature's statistics pooled per channel.

    Args:
        config: The policy config (tells which features are point clouds).
        dataset_stats: LeRobot dataset statistics, or None.

    Returns:
        A new stats dict (the input is not modified), or None.
    """
    if dataset_stats is None:
        return None
    pooled = dict(dataset_stats)
    for key in config.pointcloud_features:
        if key in pooled:
            pooled[key] = _pool_channel_stats(pooled[key])
    return pooled


def make_mtdagger_pre_post_processors(
    config: MTDAggerConfig,
    dataset_stats: Stats | None = None,
) -> tuple[
    PolicyProcessorPipeline[dict[str, Any], dict[str, Any]],
    PolicyProcessorPipeline[PolicyAction, PolicyAction],
]:
    """Creates the pre- and post-processing pipelines of the ``mtdagger`` policy.

    Args:
        config: The policy configuration.
        dataset_stats: Dataset statistics for normalisation (point-cloud statistics get pooled).

    Returns:
        ``(preprocessor, postprocessor)``.
    """
    stats = pool_pointcloud_stats(config, dataset_stats)
    input_steps = [
        RenameObservationsProcessorStep(rename_map={}),
        AddBatchDimensionProcessorStep(),
        DeviceProcessorStep(device=config.device),
        NormalizerProcessorStep(
            features={**config.input_features, **config.output_features},
            norm_map=config.normalization_mapping,
            stats=stats,
            device=config.device,
        ),
    ]
    output_steps = [
        UnnormalizerProcessorStep(
            features=config.output_features, norm_map=config.normalization_mapping, stats=stats
        ),
        DeviceProcessorStep(device="cpu"),
    ]
    return (
        PolicyProcessorPipeline[dict[str, Any], dict[str, Any]](
            steps=input_steps, name=POLICY_PREPROCESSOR_DEFAULT_NAME
        ),
        PolicyProcessorPipeline[PolicyAction, PolicyAction](
            steps=output_steps,
            name=POLICY_POSTPROCESSOR_DEFAULT_NAME,
            to_transition=policy_action_to_transition,
            to_output=transition_to_policy_action,
        ),
    )
