"""Pre- and post-processing pipelines of the ``mtdagger`` policy, as LeRobot's own policies have.

Point clouds: LeRobot types an (N, C) feature as STATE and normalises elementwise, but points are
unordered, so per-point statistics mean nothing. Statistics that arrive per point are pooled per
channel (``pool_pointcloud_stats``), so every point is normalised by the same transform.
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
            assert mean is not None  # set whenever "mean" is among the arrays
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
    """A copy of ``dataset_stats`` (or None) with each point-cloud feature's statistics pooled per channel."""
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
    """``(preprocessor, postprocessor)`` of the ``mtdagger`` policy (point-cloud statistics pooled)."""
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
