"""DAgger's mixing rules: who acts at a step of a rollout, and when an episode ends.

Pure functions of a round's ``RolloutRules`` and an episode's state, used by the env workers. The
executed action is the expert's with probability beta, per step or once per episode.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lerobot_mtdagger.utils.sampling import systematic_picks


@dataclass(frozen=True)
class RolloutRules:
    """How the episodes of one ``run_episodes`` call behave (the same for every episode).

    Attributes:
        beta: Probability of executing the expert's action (at a step, or for a whole episode).
        learner: Whether a learner acts at all (False: the expert always acts).
        record: Keep the frames (observation, expert label, executed action, learner flag).
        round_index: DAgger round written into the recorded frames.
        max_steps: Longest episode (None: the env's own truncation).
        steps_after_success: Steps kept after the first success.
        mixing: ``step`` (a beta coin at every step) or ``episode`` (one coin per episode).
        expert_multiple: Cut a learner's episode at ``ceil(expert_multiple * L)`` steps, ``L`` being
            the expert's own steps to success from the same reset (None, or a failing expert: no cut).
    """

    beta: float
    learner: bool
    record: bool
    round_index: int
    max_steps: int | None
    steps_after_success: int
    mixing: str = "step"
    expert_multiple: float | None = None

    @property
    def need_expert(self) -> bool:
        """The expert is queried when its labels are stored or it may act."""
        return self.record or self.beta > 0.0 or not self.learner or self.expert_multiple is not None


def expert_episode_coin(beta_seed: tuple[int, ...], beta: float) -> bool:
    """Whether the expert acts throughout an episode under episode mixing (systematic sampling).

    ``beta_seed`` is ``(seed, BETA_STREAM, round, task, episode)``. With one uniform offset ``u`` per
    (seed, round, task), episode ``e`` goes to the expert when ``floor(beta * e + u)`` steps up at
    ``e + 1``: any ``n`` consecutive episodes hold ``floor(beta * n)`` or ``ceil(beta * n)`` expert ones.
    """
    *task_entropy, episode = beta_seed
    offset = float(np.random.default_rng(np.random.SeedSequence(list(task_entropy))).random())
    return bool(systematic_picks(beta, episode + 1, offset)[episode])


def expert_acts_now(
    rules: RolloutRules, learner_acts: bool, expert_episode: bool, rng: np.random.Generator
) -> bool:
    """Whether the expert's action is executed at this step.

    ``learner_acts`` is False when no learner action was given; ``expert_episode`` is the episode's
    coin; ``rng`` draws one uniform per step, and only under step mixing.
    """
    if not learner_acts or rules.mixing == "episode":
        return not learner_acts or expert_episode
    return rules.beta > 0.0 and rng.random() < rules.beta


def step_limit(rules: RolloutRules, expert_steps: int | None) -> int | None:
    """An episode's step cap (None: none): ``max_steps``, and ``expert_multiple`` times the expert's steps."""
    limits = [rules.max_steps]
    if expert_steps is not None and rules.expert_multiple is not None:
        limits.append(math.ceil(rules.expert_multiple * expert_steps))
    return min((limit for limit in limits if limit is not None), default=None)


def episode_ends(rules: RolloutRules, steps: int, max_steps: int | None, steps_since_success: int) -> bool:
    """Whether an episode ends after ``steps`` steps, besides the env's own end.

    ``max_steps`` is the episode's cap (``step_limit``); ``steps_since_success`` is -1 before a success.
    """
    if max_steps is not None and steps >= max_steps:
        return True
    return steps_since_success >= 0 and steps_since_success >= rules.steps_after_success
