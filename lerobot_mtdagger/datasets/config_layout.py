"""The layout of a stored run config: its options by dotted path.

``lerobot-mtdagger run`` groups its options (``RunConfig``): ``suite`` (the suite and its
observations, shared with ``eval``, ``shift`` and the LeRobot env plugin), ``dagger`` (rounds, demo
budgets, beta), ``rollout`` (episode cuts, evaluation episodes, env workers), ``training``
(steps, sampling, held-out split), ``policy`` and ``scheduler``. A config stored by an earlier
version is first read through ``migrations.migrate_run_config`` (``migrations.stored_option`` reads one
option of a stored config in either layout), so every reader (resume, results, the Hub card) sees one
layout; this module knows only today's.
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
    """A run config's leaves by dotted path, without the options in ``ignore`` (compared on resume).

    ``config`` is in today's layout (a stored one through ``migrations.migrate_run_config`` first).
    """
    return {key: value for key, value in flatten(config).items() if key not in ignore}
