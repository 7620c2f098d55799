"""What an experiment writes about itself: DAgger frame columns, round records and phase records.

A committed round carries a ``RoundRecord`` in ``meta/mtdagger.json`` (the truth; mirrored under
``"mtdagger"`` in ``meta/info.json``), a committed training phase a ``PhaseRecord`` in
``policies/round-XXX/training.json``. Both are written and read only through these classes, so their
fields are the on-disk format::

    rounds/round-002/meta/mtdagger.json
        {"round": 2, "method": "need", "episodes_per_task": [...], "allocation": {...},
         "scheduler_state": {...}, ..., "format_version": 1, "committed": true}
    policies/round-002/training.json
        {"round": 2, "loss_start": [...], "loss_end": [...], "gain": [...], "eval": {...}, ...}

Lists are aligned with ``task_names`` (the experiment's task vocabulary, in task-index order).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from lerobot_mtdagger.datasets.migrations import migrate_run_config

RECORD_KEY = "mtdagger"
"""Key of the round record's mirror in a round dataset's ``meta/info.json``."""

FORMAT_VERSION = 1
"""Version of the round record format."""

# -------------------------------------------------------------------------------------------------
# DAgger frame columns
# -------------------------------------------------------------------------------------------------

EXECUTED_ACTION = "executed_action"
"""Per frame: the action the env executed (the expert's or the learner's); ``action`` is the label."""

LEARNER_ACTED = "learner_acted"
"""Per frame: whether the learner's action was executed (bool, shape (1,))."""

DAGGER_ROUND = "dagger_round"
"""Per frame: the DAgger round the frame was collected in (int64, shape (1,))."""

INTERVENTION = "intervention"
"""Per frame, in LeRobot's name for it: the expert's action was executed (bool, ``not learner_acted``)."""

NEXT_REWARD = "next.reward"
"""Per frame, as ``lerobot-eval`` records it: the env's reward for this frame's executed action."""

NEXT_SUCCESS = "next.success"
"""Per frame, as ``lerobot-eval`` records it: the env reported success after this frame's action."""

NEXT_DONE = "next.done"
"""Per frame, as ``lerobot-eval`` records it: the episode ended after this frame's action."""

EPISODE_SUCCESS = "success"
"""Per episode, in ``meta/episodes``: whether the env reported success at any step of the episode."""

# The names avoid the "action" and "observation" prefixes, which LeRobot would turn into policy
# outputs and inputs.
_FLAG_FEATURES: dict[str, dict[str, Any]] = {
    LEARNER_ACTED: {"dtype": "bool", "shape": (1,), "names": None},
    DAGGER_ROUND: {"dtype": "int64", "shape": (1,), "names": None},
}

_PROVENANCE_FEATURES: dict[str, dict[str, Any]] = {
    INTERVENTION: {"dtype": "bool", "shape": (1,), "names": None},
    NEXT_REWARD: {"dtype": "float32", "shape": (1,), "names": None},
    NEXT_SUCCESS: {"dtype": "bool", "shape": (1,), "names": None},
    NEXT_DONE: {"dtype": "bool", "shape": (1,), "names": None},
}


def round_features(
    suite_features: dict[str, dict[str, Any]], provenance: bool = True
) -> dict[str, dict[str, Any]]:
    """The features of a round dataset: the suite's, ``executed_action``, the DAgger flags, provenance.

    The provenance columns are LeRobot's ``intervention`` and ``next.*``; ``provenance=False`` leaves
    them out, so that every round of an experiment whose round 0 lacks them shares one schema.
    """
    action = suite_features["action"]
    executed = {"dtype": action["dtype"], "shape": tuple(action["shape"]), "names": action["names"]}
    extra = _PROVENANCE_FEATURES if provenance else {}
    return {**suite_features, EXECUTED_ACTION: executed, **_FLAG_FEATURES, **extra}


@dataclass(frozen=True)
class StepOutcome:
    """What the env returned for a frame's executed action: ``reward``, ``success``, ``done``."""

    reward: float
    success: bool
    done: bool


def dagger_columns(
    executed_action: np.ndarray, learner_acted: bool, round_index: int, outcome: StepOutcome
) -> dict[str, Any]:
    """The DAgger and provenance columns of one frame (beside the observation and the expert's ``action``)."""
    return {
        EXECUTED_ACTION: np.asarray(executed_action, dtype=np.float32),
        LEARNER_ACTED: np.array([learner_acted]),
        DAGGER_ROUND: np.array([round_index], dtype=np.int64),
        INTERVENTION: np.array([not learner_acted]),
        NEXT_REWARD: np.array([outcome.reward], dtype=np.float32),
        NEXT_SUCCESS: np.array([outcome.success]),
        NEXT_DONE: np.array([outcome.done]),
    }


def has_provenance(features: Mapping[str, Any]) -> bool:
    """Whether a round's features hold the provenance columns."""
    return INTERVENTION in features


# -------------------------------------------------------------------------------------------------
# Records
# -------------------------------------------------------------------------------------------------


def _from_mapping(cls: type, values: Mapping[str, Any], where: str) -> Any:
    """Builds dataclass ``cls`` from ``values``, naming missing keys; unknown keys are ignored."""
    fields = dataclasses.fields(cls)
    required = [
        f.name
        for f in fields
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    ]
    missing = [name for name in required if name not in values]
    if missing:
        raise ValueError(f"{where} is missing the field(s) {missing}; it was not written by this version.")
    return cls(**{f.name: values[f.name] for f in fields if f.name in values})


ALLOCATION_VIEW = (
    "success_rate",
    "episodes",
    "gain",
    "kalman_prior",
    "kalman_posterior",
    "metric",
    "score",
    "probability",
)
"""The allocation's fields a round record also holds at its top level, for readers of the record."""


def allocation_view(allocation: dict[str, Any] | None) -> dict[str, Any]:
    """A round record's ``ALLOCATION_VIEW`` fields from its allocation (blank in an unscheduled round)."""
    if allocation is not None:
        return {key: allocation[key] for key in ALLOCATION_VIEW}
    blank = {"p": None, "P": None}
    return {**dict.fromkeys(ALLOCATION_VIEW), "kalman_prior": blank, "kalman_posterior": dict(blank)}


@dataclass
class RoundRecord:
    """The record of one committed round (``meta/mtdagger.json``).

    An optional field is None (``ledger`` False) where the record does not hold it.

    Attributes:
        task_names: The experiment's task vocabulary (task index i is ``task_names[i]``).
        round: Round index k (0: expert demonstrations).
        method: ``bc`` or the scheduling method.
        beta: Probability of executing the expert's action at a step (1 in round 0).
        budget: Episodes collected in the round.
        episodes_per_task: Episodes collected per task.
        demos_so_far: Expert-labelled episodes per task in rounds 0..k.
        rollout_success: Success rate per task of this round's rollouts, whoever acted (None in
            round 0 and where a task had no episode); ``rollout_episodes``: the episodes behind it.
        expert_success: Round 0 only: the experts' success rate per task.
        learner_steps: Steps where the learner's action was executed.
        config: The run config (``RunConfig.to_dict``).
        success_rate: Scheduler input: the measured success rate (the previous round's); ``episodes``:
            the rollouts behind it; ``gain``: the previous training phase's performance gain.
        kalman_prior: Kalman state before this round's update (``{"p": None, "P": None}`` in round 0);
            ``kalman_posterior``: after it.
        metric: The method's metric per task (None in round 0); ``score``: as softmax scores;
            ``probability``: the softmax.
        eval_success: Evaluation success per task of the policy that collected this round.
        allocation: The full ``Allocation.to_dict()`` (None in round 0); ``verify`` recomputes it.
        scheduler_state: ``Scheduler.state_dict()`` after this round's allocation (resume restores it).
        committed: True once the round is committed (a record without it is never read).
        learner_success: Success rate per task of this round's episodes where only the learner acted
            (the next round's task need measurement); ``learner_episodes``: the episodes behind it.
        files: sha256 of every file of the round dataset but ``meta/info.json``, by relative path.
        ledger: True once committed into the experiment's ``ledger.json`` (``datasets/ledger.py``).
    """

    task_names: list[str]
    round: int
    method: str
    beta: float
    seed: int
    budget: int
    temperature: float
    n_min: int
    episodes_per_task: list[int]
    demos_so_far: list[int]
    rollout_success: list[float | None] | None
    rollout_episodes: list[int]
    expert_success: list[float | None] | None
    learner_steps: int
    frames: int
    config: dict[str, Any]
    success_rate: list[float | None] | None
    episodes: list[int] | None
    gain: list[float] | None
    kalman_prior: dict[str, Any]
    kalman_posterior: dict[str, Any]
    metric: list[float] | None
    score: list[float] | None
    probability: list[float] | None
    eval_success: list[float] | None
    allocation: dict[str, Any] | None
    scheduler_state: dict[str, Any] | None
    notes: list[str]
    format_version: int = FORMAT_VERSION
    committed: bool = False
    learner_success: list[float | None] | None = None
    learner_episodes: list[int] | None = None
    files: dict[str, str] | None = None
    ledger: bool = False

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form, as stored in ``meta/info.json``."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, values: Mapping[str, Any], where: str = "round record") -> RoundRecord:
        """Reads a stored record, its config migrated (ValueError naming a missing field and ``where``)."""
        if isinstance(values.get("config"), Mapping):
            values = {**values, "config": migrate_run_config(values["config"])}
        return _from_mapping(cls, values, where)


@dataclass
class PhaseRecord:
    """The record of one committed training phase (``policies/round-XXX/training.json``).

    An optional field is None (``ledger`` False) where the record does not hold it.

    Attributes:
        round: k: the policy was trained on rounds 0..k (``trained_on_rounds``).
        frames: Frames of D(k) (held-out episodes included).
        steps: Optimiser steps taken (with ``steps_rule=plateau``, up to where the phase stopped).
        gain_split: Where the per-task loss was measured (``train`` or ``heldout``).
        loss_start: Per-task loss of the initial weights (None where a task had no sample).
        loss_end: Per-task loss after training.
        gain: ``max(0, loss_previous - loss_end)`` per task, the next round's performance gain (None in
            phase 0: a loss drop from random weights measures the scale of the actions, not learning).
        loss_samples: Frames per task behind the losses.
        final_train_loss: The last training losses.
        eval: ``EvalResult.to_dict()`` of the trained policy (None when not evaluated).
        demos_per_task: Expert-labelled episodes per task in D(k).
        timings: Seconds per part of the round (collect_s, write_s, load_s, train_s, eval_s).
        loss_previous: Per-task loss of the policy that collected round k on the same frames, in this
            phase's normalisation (None in phase 0).
        files: sha256 of every file of the policy folder but ``training.json``, by relative path.
        best_step: With ``steps_rule=plateau``, the step whose weights were kept (0: the initial ones).
        heldout_loss: With ``steps_rule=plateau``, ``[step, mean held-out loss]`` at every measurement.
        heldout_eval: ``EvalResult.to_dict()`` on the suite's unseen tasks; never given to the scheduler.
        environment: Where the phase trained (package versions, CPU, torch threads, device): the same
            data and seeds give the same weights bit for bit only in the same environment.
        passes_per_task: Per task, the passes the phase's steps made over its training frames.
        resumed_after_steps: The steps after which a cut phase was resumed from its saved progress
            (empty: trained in one go); its ``steps_s`` and ``train_s`` count every process's steps.
        ledger: True once committed into the experiment's ``ledger.json``.
    """

    round: int
    trained_on_rounds: list[int]
    frames: int
    steps: int
    gain_split: str
    loss_start: list[float | None]
    loss_end: list[float | None]
    gain: list[float] | None
    loss_samples: list[int]
    final_train_loss: list[float]
    eval: dict[str, Any] | None
    demos_per_task: list[int]
    timings: dict[str, float]
    loss_previous: list[float | None] | None = None
    files: dict[str, str] | None = None
    best_step: int | None = None
    heldout_loss: list[list[float]] | None = None
    heldout_eval: dict[str, Any] | None = None
    environment: dict[str, Any] | None = None
    passes_per_task: list[float | None] | None = None
    resumed_after_steps: list[int] | None = None
    ledger: bool = False

    @property
    def eval_mean(self) -> float | None:
        """Average evaluation success over tasks (None when not evaluated)."""
        return None if self.eval is None else float(self.eval["mean"])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form, as stored in ``training.json``."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, values: Mapping[str, Any], where: str = "training record") -> PhaseRecord:
        """Reads a stored record (ValueError naming a missing field and ``where``)."""
        return _from_mapping(cls, values, where)
