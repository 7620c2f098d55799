"""DAgger's mixing rules: who acts at a step of a rollout, and when an episode ends.

Pure functions of a round's ``RolloutRules`` and an episode's state, used by the env workers
(``workers.RolloutWorker``) and unit-tested without processes. Paper, Algorithm 1: at round k the
executed action is the expert's with probability beta_k and the learner's otherwise; here per step
(``mixing="step"``) or once per episode (``mixing="episode"``, spread evenly over a task's episodes by
``expert_episode_coin``).
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
        mixing: ``step`` (a beta coin at every step) or ``episode`` (one coin when the episode
            starts: the expert or the learner acts throughout).
        expert_multiple: Cut an episode where the learner acts at ``ceil(expert_multiple * L)``
            steps, ``L`` being the steps the expert alone takes to its first success from the same
            reset seed (run first, unrecorded; no cut where the expert does not succeed). None: no
            such cut. ``max_steps`` still applies.
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

    ``beta_seed`` is ``(seed, BETA_STREAM, round, task, episode)``. One uniform offset ``u`` per
    (seed, round, task) is drawn, and episode ``e`` goes to the expert when ``floor(beta * e + u)``
    steps up at ``e + 1``: any ``n`` consecutive episodes of a task hold ``floor(beta * n)`` or
    ``ceil(beta * n)`` expert episodes, so even a task given 3 episodes gets both kinds at beta 0.5
    (independent coins would give it none of the learner's one time in eight).
    """
    *task_entropy, episode = beta_seed
    offset = float(np.random.default_rng(np.random.SeedSequence(list(task_entropy))).random())
    return bool(systematic_picks(beta, episode + 1, offset)[episode])


def expert_acts_now(
    rules: RolloutRules, learner_acts: bool, expert_episode: bool, rng: np.random.Generator
) -> bool:
    """Whether the expert's action is executed at this step.

    Args:
        rules: The round's rules.
        learner_acts: Whether a learner action was given for this step (False: the expert acts).
        expert_episode: Under episode mixing, the episode's coin (``expert_episode_coin``).
        rng: The episode's beta generator (step mixing draws one uniform per step, and only then).
    """
    if not learner_acts or rules.mixing == "episode":
        return not learner_acts or expert_episode
    return rules.beta > 0.0 and rng.random() < rules.beta


def step_limit(rules: RolloutRules, expert_steps: int | None) -> int | None:
    """An episode's step cap (None: no cap).

    ``max_steps``, and ``ceil(expert_multiple * expert_steps)`` where the expert alone reached
    success in ``expert_steps`` from the same reset.
    """
    limits = [rules.max_steps]
    if expert_steps is not None and rules.expert_multiple is not None:
        limits.append(math.ceil(rules.expert_multiple * expert_steps))
    return min((limit for limit in limits if limit is not None), default=None)


def episode_ends(rules: RolloutRules, steps: int, max_steps: int | None, steps_since_success: int) -> bool:
    """Whether an episode ends after ``steps`` steps, besides the env's own end.

    Args:
        rules: The round's rules (``steps_after_success``).
        steps: Steps taken.
        max_steps: The episode's cap (``step_limit``; None: none).
        steps_since_success: Steps since its first success (-1: no success yet).
    """
    if max_steps is not None and steps >= max_steps:
        return True
    return steps_since_success >= 0 and steps_since_success >= rules.steps_after_success
