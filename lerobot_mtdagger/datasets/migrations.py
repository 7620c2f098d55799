"""The rules about runs stored by earlier versions of the toolkit: one ordered list of migrations.

Every change to what a stored run config holds or means is one ``Migration`` in ``MIGRATIONS``,
oldest first (``docs/changes.md`` describes each); no other module keeps rules about older runs.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ConfigRewrite = Callable[[Mapping[str, Any]], dict[str, Any]]
ResumeHint = Callable[[Mapping[str, Any], Sequence[str], Mapping[str, Any]], str]


@dataclass(frozen=True)
class Migration:
    """One change to what a stored run config holds or means.

    Attributes:
        name: A short identifier.
        since: The date of the change (``docs/changes.md`` has the entry).
        summary: What changed, in one sentence.
        rewrite: Turns a config stored before the change into the newer layout (a copy), or None.
        former_values: Options the change added, by dotted path, and the value runs made before had.
        resume_hint: ``hint(stored_config, differing, stored_options)`` as for ``resume_hint``: how to
            resume a run made before the change, or ``""`` when the change does not explain ``differing``.
    """

    name: str
    since: str
    summary: str
    rewrite: ConfigRewrite | None = None
    former_values: Mapping[str, Any] = field(default_factory=dict)
    resume_hint: ResumeHint | None = None


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
"""Each option of the flat run config (before the groups) -> its path today."""

RESCALED_PRESETS: dict[str, str] = {
    "metaworld-pixels": "metaworld-pixels-paper",
    "drawers-pointcloud": "drawers-pointcloud-paper",
}
"""Presets whose values were scaled to a 2-core CPU -> the preset that keeps the former values."""

PIXELS_FORMER_VALUES: tuple[tuple[str, dict[str, Any]], ...] = (
    ("2026-11-27", {"training.sampling": "uniform"}),
    ("2026-11-29", {"training.steps_rule": "fixed", "training.epochs": 100.0}),
)
"""``metaworld-pixels``' changed values, by the date they changed -> what runs made before had."""


def is_flat(config: Mapping[str, Any]) -> bool:
    """Whether ``config`` was stored before the options were grouped (its ``suite`` is a name)."""
    return not isinstance(config.get("suite"), Mapping)


def group_flat_options(config: Mapping[str, Any]) -> dict[str, Any]:
    """A flat stored config's options moved into their groups (a grouped config: a copy)."""
    if not is_flat(config):
        return copy.deepcopy(dict(config))
    grouped: dict[str, Any] = {}
    for key, value in config.items():
        path = FLAT_OPTION_PATHS.get(key)
        if path is None:
            grouped[key] = copy.deepcopy(value)
            continue
        group, name = path.split(".")
        grouped.setdefault(group, {})[name] = copy.deepcopy(value)
    return grouped


def placement_hint(
    stored_config: Mapping[str, Any], differing: Sequence[str], stored: Mapping[str, Any]
) -> str:
    """Names ``--suite.placement=narrow`` for a drawer run stored before the option existed."""
    if "suite.placement" in differing and "suite.placement" not in stored:
        return " (drawer runs made before --suite.placement existed used --suite.placement=narrow)"
    return ""


def rescaled_preset_hint(
    stored_config: Mapping[str, Any], differing: Sequence[str], stored: Mapping[str, Any]
) -> str:
    """Names the ``-paper`` preset that keeps a rescaled preset's former values."""
    name = stored_config.get("preset")
    if name not in RESCALED_PRESETS or any(key not in stored for key in differing):
        return ""  # an option the run lacked is a later addition, not a rescaled value
    return (
        f" (a run made before 2026-11-26 with --preset={name} has the values of today's "
        f"--preset={RESCALED_PRESETS[name]}: resume it with that preset)"
    )


def pixels_preset_hint(
    stored_config: Mapping[str, Any], differing: Sequence[str], stored: Mapping[str, Any]
) -> str:
    """Names the options (and the earliest date) that keep a ``metaworld-pixels`` run made before a change."""
    if stored_config.get("preset") != "metaworld-pixels" or not differing:
        return ""
    former = {key: value for _, values in PIXELS_FORMER_VALUES for key, value in values.items()}
    if not set(differing) <= set(former):
        return ""
    since = min(date for date, values in PIXELS_FORMER_VALUES if set(values) & set(differing))
    options = " ".join(f"--{key}={former[key]}" for key in differing)
    return f" (a run made before {since} with --preset=metaworld-pixels used {options}: add it)"


LEDGER_RECORDS_SINCE = "2026-12-04"
"""Since when every committed record says it was committed into the ledger (``ledger: true``)."""


MIGRATIONS: tuple[Migration, ...] = (
    Migration(
        name="drawer-placement",
        since="2026-11-25",
        summary="Drawer runs draw their placement by --suite.placement (default kitchen); before: narrow.",
        former_values={"suite.placement": "narrow"},
        resume_hint=placement_hint,
    ),
    Migration(
        name="grouped-options",
        since="2026-11-26",
        summary="Run options are grouped (suite, dagger, rollout, training); before: one flat config.",
        rewrite=group_flat_options,
    ),
    Migration(
        name="rescaled-presets",
        since="2026-11-26",
        summary="metaworld-pixels and drawers-pointcloud scaled to a 2-core CPU; -paper keeps the values.",
        resume_hint=rescaled_preset_hint,
    ),
    Migration(
        name="sampling-option",
        since="2026-11-26",
        summary="Presets fill --training.sampling; runs stored before the option sampled uniform.",
        former_values={"training.sampling": "uniform"},
    ),
    Migration(
        name="balanced-pixels",
        since="2026-11-27",
        summary="metaworld-pixels samples balanced (DAgger runs, then BC runs); before: uniform.",
        resume_hint=pixels_preset_hint,
    ),
    Migration(
        name="pixels-epochs",
        since="2026-11-29",
        summary=(
            "Presets fill --training.steps_rule and --training.epochs; metaworld-pixels' DAgger phases "
            "make 10 passes (epochs) where they took fixed steps; runs stored without them: fixed, 100."
        ),
        former_values={"training.steps_rule": "fixed", "training.epochs": 100.0},
        resume_hint=pixels_preset_hint,
    ),
    Migration(
        name="ledger-records",
        since=LEDGER_RECORDS_SINCE,
        summary=(
            "Round and phase records say they were committed into the ledger (ledger: true), so a deleted "
            "ledger is named; a run with no ledger and no such record is read as one made before ledgers "
            "(pre_ledger_note)."
        ),
    ),
)
"""Every change to what stored runs hold or mean, oldest first."""


def pre_ledger_note(root: Path, ledger_file: str) -> str:
    """What ``verify`` and every reader say of an experiment made before ledgers (its resume starts one)."""
    return (
        f"{root} was made before experiments had a ledger ({ledger_file}; or before "
        f"{LEDGER_RECORDS_SINCE}, when records began to say they were committed into one): its records are "
        "checked against their files only; a resume starts its ledger"
    )


def migrate_run_config(config: Mapping[str, Any]) -> dict[str, Any]:
    """``config`` in today's layout: every migration's rewrite applied in order (always a copy)."""
    migrated = copy.deepcopy(dict(config))
    for migration in MIGRATIONS:
        if migration.rewrite is not None:
            migrated = migration.rewrite(migrated)
    return migrated


def stored_option(config: Mapping[str, Any], path: str, default: Any = None) -> Any:
    """The option at dotted ``path`` of a stored config in either layout (``default`` when absent)."""
    node: Any = migrate_run_config(config) if is_flat(config) else config
    for part in path.split("."):
        if not isinstance(node, Mapping) or part not in node:
            return default
        node = node[part]
    return node


def former_option_values() -> dict[str, Any]:
    """What each option a migration added was before it existed, by dotted path."""
    values: dict[str, Any] = {}
    for migration in MIGRATIONS:
        values |= dict(migration.former_values)
    return values


def resume_hint(stored_config: Mapping[str, Any], differing: Sequence[str], stored: Mapping[str, Any]) -> str:
    """The newest migration's hint that accounts for ``differing`` (``""`` when none does).

    Args:
        stored_config: The stored run config, in today's layout.
        differing: Dotted paths of the options where the stored and the given config differ.
        stored: The stored config's options by dotted path.
    """
    for migration in reversed(MIGRATIONS):
        hint = migration.resume_hint(stored_config, differing, stored) if migration.resume_hint else ""
        if hint:
            return hint
    return ""
