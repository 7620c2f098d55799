"""The paper's presets of ``lerobot-mtdagger run`` and the values each fills.

Every option a preset fills (``PRESET_FIELDS``) has one home, its own field; None there means "from
the preset" (``--preset``, default ``small``: MT10 state, a few rounds, minutes on a 2-core CPU), so
a value given on the command line always wins. The ``*-paper`` presets follow the paper's "Setup"
and hyperparameter table (n_min is ``scheduler.n_min``; lr and batch are ``policy.lr`` and
``policy.batch_size``; points is ``suite.num_points``) and are sized for a GPU; ``metaworld-pixels``
and ``drawers-pointcloud`` keep the paper's rounds and scale the demonstrations, steps and batch down
to a 2-core CPU (the visual-collapse study's reduced run, ``experiments/visual-collapse-dev``):

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

(initial and per round: expert demonstrations per task; steps: ``training.steps_per_round``. Every
preset samples batches ``uniform``ly and trains each phase for its fixed steps except
``metaworld-pixels``, whose runs (DAgger and BC) sample ``balanced`` (``PIXELS_SAMPLING``) and whose
DAgger phases make 10 passes over their frames (``PIXELS_STEPS_RULE``, ``PIXELS_EPOCHS``; its BC
keeps fixed steps, and its ``steps`` applies to DAgger only with ``--training.steps_rule=fixed``).)

The DAgger mixing coefficient ``beta`` is the probability that the EXPERT's action is executed at
a step (classic DAgger; the paper's text is ambiguous): 0.5 in the first DAgger round, decayed by
0.5 per round to 0. ``--mode=bc`` runs the one-round behaviour-cloning baseline instead.
"""

from __future__ import annotations

from typing import Any

from lerobot_mtdagger.envs.config import DEFAULT_NUM_POINTS

PIXELS_SAMPLING = "balanced"
"""``metaworld-pixels``' batch sampling, for DAgger and BC: chosen on development seeds, where
balanced sampling let the DAgger rounds raise success and BC keep rising with more data while uniform
sampling did neither (the numbers: ``docs/results.md``, "MT10 pixels")."""

PIXELS_STEPS_RULE: dict[str, str] = {"dagger": "epochs", "bc": "fixed"}
PIXELS_EPOCHS: dict[str, float] = {"dagger": 10.0, "bc": 100.0}
"""``metaworld-pixels``' training per phase by run mode. A DAgger phase makes 10 passes over its
frames, chosen on development seeds 100-102 by a rule fixed before the runs
(``experiments/pixels-dagger-epochs-dev``): at 60 demonstrations per task, 10 passes per phase beat
1 500 fixed steps per phase (under one pass over the last phase's frames) by +0.077 [+0.002, +0.152],
the three hard tasks by +0.194. BC keeps its fixed steps (``(rounds + 1) * steps_per_round``, which
made 10.3-10.7 passes at 60 demos per task): the rule decided the DAgger phases only, and BC's
sampling and budgets were chosen under fixed steps (``experiments/pixels-bc-dev``). Its ``epochs``
stays 100, the value stored runs have (unused under ``fixed``)."""


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
"""Preset values by option path (the command-line spelling without ``--``). Each option filled by a
preset has ONE home: its field (None there means "from the preset"); a value given on the command
line or in Python always wins. A value that is a mapping is keyed by ``RunConfig.mode``."""


PRESET_FIELDS: tuple[str, ...] = tuple(PRESETS["small"])
"""The options every preset fills."""


def preset_values(preset: str, mode: str) -> dict[str, Any]:
    """What ``preset`` fills in a run of ``mode`` (``dagger`` or ``bc``), by option path.

    A value keyed by run mode (``PIXELS_STEPS_RULE``) gives that mode's.
    """
    values = PRESETS[preset].items()
    return {path: value[mode] if isinstance(value, dict) else value for path, value in values}
