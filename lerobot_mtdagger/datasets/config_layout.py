"""The layout of a stored run config, and the migration of configs stored before it was composed.

``lerobot-mtdagger run`` groups its options (``RunConfig``): ``suite`` (the suite and its
observations, shared with ``eval``, ``shift`` and the LeRobot env plugin), ``dagger`` (rounds, demo
budgets, beta), ``rollout`` (episode cuts, evaluation episodes, env workers), ``training``
(steps, sampling, held-out split), ``policy`` and ``scheduler``. Experiments written before that
store a flat ``config.json`` (``obs_mode``, ``rounds``, ...); ``migrate_run_config`` turns such
a config into today's layout, so every reader (resume, results, the Hub card) sees one layout.
``FLAT_OPTION_PATHS`` is the single list of those renames: the command line names the new spelling
of an old one from it (``renamed_option_error``) and the README's changelog lists it.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from typing import Any

FLAT_OPTION_PATHS: dict[str, str] = {
    "suite": "suite.name",
    "tasks": "suite.tasks",
    "obs_mode": "suite.obs_mode",
    "num_points": "suite.num_points",
    "image_size": "suite.image_size",
    "mesh_detail": "suite.mesh_detail",
    "placement": "suite.placement",
    "rounds": "dagger.rounds",
    "initial_demos": "dagger.initial_demos",
    "budget": "dagger.budget",
    "budget_per_task": "dagger.budget_per_task",
    "beta": "dagger.beta",
    "beta_decay": "dagger.beta_decay",
    "beta_min": "dagger.beta_min",
    "mixing": "dagger.mixing",
    "eval_episodes": "rollout.eval_episodes",
    "max_rollout_steps": "rollout.max_steps",
    "rollout_expert_multiple": "rollout.expert_multiple",
    "steps_after_success": "rollout.steps_after_success",
    "workers": "rollout.workers",
    "steps_per_round": "training.steps_per_round",
    "warm_start": "training.warm_start",
    "steps_rule": "training.steps_rule",
    "epochs": "training.epochs",
    "plateau_every": "training.plateau_every",
    "plateau_patience": "training.plateau_patience",
    "plateau_max_steps": "training.plateau_max_steps",
    "normalisation": "training.normalisation",
    "sampling": "training.sampling",
    "gain_split": "training.gain_split",
    "heldout_fraction": "training.heldout_fraction",
}
"""Each option of the flat run config (before the groups) and its path today."""


RESCALED_PRESETS: dict[str, str] = {
    "metaworld-pixels": "metaworld-pixels-paper",
    "drawers-pointcloud": "drawers-pointcloud-paper",
}
"""Presets whose values changed (scaled to a 2-core CPU on 2026-11-26) -> the preset that keeps the
former values. A stored config holds the values themselves, so only resuming is affected."""

PRESET_VALUE_CHANGES: dict[str, dict[str, Any]] = {
    "metaworld-pixels": {"training.sampling": "uniform"},
}
"""Options a preset set differently later (after its rescaling) -> the value runs made before had:
``metaworld-pixels``' DAgger runs sample ``balanced`` since 2026-11-26, its BC runs since 2026-11-27
(a resume names the fix)."""


def later_preset_values(preset: str | None, differing: list[str]) -> dict[str, Any]:
    """The former values of ``preset`` when they explain every differing option, else empty.

    Args:
        preset: The preset a stored run config names (None for a config without one).
        differing: Dotted paths of the options where the stored and the given config differ.

    Returns:
        ``PRESET_VALUE_CHANGES[preset]`` restricted to ``differing`` when every differing option
        is one the preset changed, else ``{}``.
    """
    changed = PRESET_VALUE_CHANGES.get(preset or "", {})
    if not differing or not set(differing) <= set(changed):
        return {}
    return {key: changed[key] for key in differing}


def is_flat(config: Mapping[str, Any]) -> bool:
    """Whether ``config`` was stored before the options were grouped (its ``suite`` is a name)."""
    return not isinstance(config.get("suite"), Mapping)


def migrate_run_config(config: Mapping[str, Any]) -> dict[str, Any]:
    """``config`` in today's layout: a flat stored config's options moved into their groups.

    A config already in today's layout is returned as a copy; an option the flat config lacks (it
    was added later) stays absent, as it was absent before.
    """
    if not is_flat(config):
        return copy.deepcopy(dict(config))
    migrated: dict[str, Any] = {}
    for key, value in config.items():
        path = FLAT_OPTION_PATHS.get(key)
        if path is None:
            migrated[key] = copy.deepcopy(value)
            continue
        group, name = path.split(".")
        migrated.setdefault(group, {})[name] = copy.deepcopy(value)
    return migrated


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
