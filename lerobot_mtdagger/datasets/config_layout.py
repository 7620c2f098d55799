"""The layout of a stored run config: its options by dotted path.

A config stored by an earlier version is first read through ``migrations.migrate_run_config``, so
every reader sees today's layout, the only one this module knows.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any


def flatten(config: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Every leaf option of a (nested) config by its dotted path (``{"suite.obs_mode": "rgb", ...}``)."""
    leaves: dict[str, Any] = {}
    for key, value in config.items():
        path = f"{prefix}{key}"
        if isinstance(value, Mapping) and value:
            leaves |= flatten(value, prefix=f"{path}.")
        else:
            leaves[path] = value
    return leaves


RESULT_NEUTRAL_OPTIONS: tuple[str, ...] = (
    "preset",  # a config stores every option the preset filled, resolved: those are compared
    "resume",
    "progress",
    "output_dir",
    "rollout.workers",
    "rollout.worker_backend",
    "rollout.ray_address",
    "policy.device",
    "training.progress_every_s",  # a resumed phase ends as it would have (runner.training.phase_progress)
)
"""Options (dotted paths) that never change a result, free to differ on resume."""


def result_options(config: Mapping[str, Any], ignore: Sequence[str]) -> dict[str, Any]:
    """A run config's leaves by dotted path (today's layout), without the options in ``ignore``."""
    return {key: value for key, value in flatten(config).items() if key not in ignore}
