"""The paper's presets of ``lerobot-mtdagger run`` and the values each fills.

A preset fills only the options left unset (``PRESET_FIELDS``). The ``*-paper`` presets follow the
paper's "Setup" and hyperparameter table and are sized for a GPU; ``metaworld-pixels`` and
``drawers-pointcloud`` keep the paper's rounds with less data, steps and batch for a 2-core CPU:

=========================  ==========  ======  =======  ==========  =====  =====  ====  =====  ======
preset                     obs_mode    rounds  initial  per round   steps  n_min  lr    batch  points
=========================  ==========  ======  =======  ==========  =====  =====  ====  =====  ======
small                      state       3       3        3           1500   1      3e-4  256
metaworld-state            state       10      3        3           3000   1      3e-4  1024
metaworld-pixels           rgb         5       10       10          1500   2      3e-4  64
metaworld-pixels-paper     rgb         5       40       20          3000   1      3e-4  1024
drawers-pointcloud         pointcloud  10      10       5           1500   2      3e-4  64     512
drawers-pointcloud-paper   pointcloud  10      30       30          3000   5      1e-4  256    1024
=========================  ==========  ======  =======  ==========  =====  =====  ====  =====  ======

(initial, per round: expert demonstrations per task.) Every preset samples ``uniform`` and trains
fixed steps, except ``metaworld-pixels``: ``balanced`` sampling and, for DAgger, 10 passes per phase.
Beta is 0.5 in the first DAgger round, decayed by 0.5 per round to 0.
"""

from __future__ import annotations

from typing import Any

from lerobot_mtdagger.envs.config import DEFAULT_NUM_POINTS

PIXELS_SAMPLING = "balanced"
"""``metaworld-pixels``' batch sampling, for DAgger and BC (``docs/dagger.md``, ``docs/changes.md``)."""

PIXELS_STEPS_RULE: dict[str, str] = {"dagger": "epochs", "bc": "fixed"}
PIXELS_EPOCHS: dict[str, float] = {"dagger": 10.0, "bc": 100.0}
"""``metaworld-pixels``' training per phase by run mode: DAgger 10 passes over its frames, BC fixed steps.

BC's ``epochs`` (100) is unused under ``fixed``. The evidence: ``docs/dagger.md``, "MT10 pixels".
"""


PRESETS: dict[str, dict[str, Any]] = {
    "small": {
        "suite.name": "metaworld-mt10",
        "suite.obs_mode": "state",
        "suite.num_points": DEFAULT_NUM_POINTS,
        "dagger.rounds": 3,
        "dagger.initial_demos": 3,
        "dagger.budget_per_task": 3,
        "training.steps_per_round": 1500,
        "rollout.eval_episodes": 5,
        "scheduler.n_min": 1,
        "policy.lr": 3e-4,
        "policy.batch_size": 256,
        "training.sampling": "uniform",
        "training.steps_rule": "fixed",
        "training.epochs": 100.0,
    },
    "metaworld-state": {
        "suite.name": "metaworld-mt50",
        "suite.obs_mode": "state",
        "suite.num_points": DEFAULT_NUM_POINTS,
        "dagger.rounds": 10,
        "dagger.initial_demos": 3,
        "dagger.budget_per_task": 3,
        "training.steps_per_round": 3000,
        "rollout.eval_episodes": 10,
        "scheduler.n_min": 1,
        "policy.lr": 3e-4,
        "policy.batch_size": 1024,
        "training.sampling": "uniform",
        "training.steps_rule": "fixed",
        "training.epochs": 100.0,
    },
    "metaworld-pixels": {
        "suite.name": "metaworld-mt10",
        "suite.obs_mode": "rgb",
        "suite.num_points": DEFAULT_NUM_POINTS,
        "dagger.rounds": 5,
        "dagger.initial_demos": 10,
        "dagger.budget_per_task": 10,
        "training.steps_per_round": 1500,
        "rollout.eval_episodes": 5,
        "scheduler.n_min": 2,
        "policy.lr": 3e-4,
        "policy.batch_size": 64,
        "training.sampling": PIXELS_SAMPLING,
        "training.steps_rule": PIXELS_STEPS_RULE,
        "training.epochs": PIXELS_EPOCHS,
    },
    "metaworld-pixels-paper": {
        "suite.name": "metaworld-mt10",
        "suite.obs_mode": "rgb",
        "suite.num_points": DEFAULT_NUM_POINTS,
        "dagger.rounds": 5,
        "dagger.initial_demos": 40,
        "dagger.budget_per_task": 20,
        "training.steps_per_round": 3000,
        "rollout.eval_episodes": 10,
        "scheduler.n_min": 1,
        "policy.lr": 3e-4,
        "policy.batch_size": 1024,
        "training.sampling": "uniform",
        "training.steps_rule": "fixed",
        "training.epochs": 100.0,
    },
    "drawers-pointcloud": {
        "suite.name": "drawers",
        "suite.obs_mode": "pointcloud",
        "suite.num_points": 512,
        "dagger.rounds": 10,
        "dagger.initial_demos": 10,
        "dagger.budget_per_task": 5,
        "training.steps_per_round": 1500,
        "rollout.eval_episodes": 5,
        "scheduler.n_min": 2,
        "policy.lr": 3e-4,
        "policy.batch_size": 64,
        "training.sampling": "uniform",
        "training.steps_rule": "fixed",
        "training.epochs": 100.0,
    },
    "drawers-pointcloud-paper": {
        "suite.name": "drawers",
        "suite.obs_mode": "pointcloud",
        "suite.num_points": DEFAULT_NUM_POINTS,
        "dagger.rounds": 10,
        "dagger.initial_demos": 30,
        "dagger.budget_per_task": 30,
        "training.steps_per_round": 3000,
        "rollout.eval_episodes": 10,
        "scheduler.n_min": 5,
        "policy.lr": 1e-4,
        "policy.batch_size": 256,
        "training.sampling": "uniform",
        "training.steps_rule": "fixed",
        "training.epochs": 100.0,
    },
}
"""Preset values by option path (as on the command line); a mapping value is keyed by ``RunConfig.mode``."""


PRESET_FIELDS: tuple[str, ...] = tuple(PRESETS["small"])
"""The options every preset fills."""


def preset_values(preset: str, mode: str) -> dict[str, Any]:
    """What ``preset`` fills in a run of ``mode`` (``dagger`` or ``bc``), by option path."""
    values = PRESETS[preset].items()
    return {path: value[mode] if isinstance(value, dict) else value for path, value in values}
