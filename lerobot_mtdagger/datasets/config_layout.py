"""The layout of a stored run config: its options by dotted path.

``lerobot-mtdagger run`` groups its options (``RunConfig``): ``suite`` (the suite and its
observations, shared with ``eval``, ``shift`` and the LeRobot env plugin), ``dagger`` (rounds, demo
budgets, beta), ``rollout`` (episode cuts, evaluation episodes, env workers), ``training``
(steps, sampling, held-out split), ``policy`` and ``scheduler``. A config stored by an earlier
version is read through ``migrations.migrate_run_config``, so every reader (resume, results, the
Hub card) sees one layout.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from lerobot_mtdagger.datasets.migrations import is_flat, migrate_run_config


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


def option(config: Mapping[str, Any], path: str, default: Any = None) -> Any:
    """The option at dotted ``path`` of a stored config in either layout (``default`` when absent)."""
    node: Any = migrate_run_config(config) if is_flat(config) else config
    for part in path.split("."):
        if not isinstance(node, Mapping) or part not in node:
            return default
        node = node[part]
    return node


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
    """A run config's leaves by dotted path, without the options in ``ignore`` (compared on resume)."""
    return {key: value for key, value in flatten(migrate_run_config(config)).items() if key not in ignore}
