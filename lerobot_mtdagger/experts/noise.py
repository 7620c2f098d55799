"""Imperfect experts: temporally correlated Gaussian noise on an expert's actions.

The paper's experts are SAC and PPO policies trained on the privileged state: stochastic, and
successful on 80-95% of episodes. MetaWorld's scripted experts are deterministic and succeed on about
98%, a regime where behaviour cloning saturates at a few demonstrations. ``ExpertNoise`` makes any
expert act the way a stochastic RL policy acts: at step ``t`` of an episode the expert executes

    a_t = clip(mu(s_t) + e_t, low, high)
    e_0 = sigma * z_0,   e_t = rho * e_(t-1) + sqrt(1 - rho^2) * sigma * z_t,   z_t ~ N(0, I)

where ``mu`` is the wrapped expert, ``low``/``high`` the env's action bounds, ``sigma`` the noise
scale (one for every task, or a task's own: ``task_scales``) and ``rho`` its step-to-step
correlation: every ``e_t`` has standard deviation ``sigma`` (an AR(1) process, the discretised
Ornstein-Uhlenbeck noise of DDPG; ``rho = 0`` is white noise).

The stored label is, by ``labels``:

- ``noisy``: the executed action ``a_t``: the expert is a stochastic policy and its samples are its
  demonstrations (what the paper's SAC/PPO experts give);
- ``clean``: the expert's intended action ``clip(mu(s_t))``: noise only perturbs the states the
  expert visits (DART, Laskey et al. 2017).

Each episode's noise is drawn from its own generator, seeded by ``(seed, NOISE_STREAM, round, task,
episode)``: it does not depend on workers, lanes or any other random draw, and a run with
``scale = 0`` draws nothing and is the run without noise, frame for frame.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from lerobot_mtdagger.utils.seeds import NOISE_STREAM

LABEL_CHOICES = ("noisy", "clean")
"""What a frame stores as the expert's label: the executed noisy action, or the expert's own."""


@dataclass(frozen=True)
class ExpertNoise:
    """How far experts are from perfect (``--expert.noise*``, ``--expert.labels``).

    Attributes:
        scale: Standard deviation ``sigma`` of the noise added to each action component, in action
            units (MetaWorld's and the drawers' actions lie in [-1, 1]); 0 turns noise off.
        correlation: Step-to-step correlation ``rho`` of the noise, in [0, 1): 0 is white noise, 0.9
            keeps a perturbation for about ten steps.
        seed: Seed of the noise, apart from the run's seed (the same demonstrations' noise can be
            redrawn, or kept while the run's seed changes).
        labels: ``noisy`` (the label is the executed action) or ``clean`` (the expert's own action).
        task_scales: ``(task, scale)`` pairs: these tasks' own noise scale instead of ``scale`` (one
            scale cannot put every expert at the same success: easy tasks' experts shrug off a noise
            that breaks a grasping task's).
    """

    scale: float = 0.0
    correlation: float = 0.0
    seed: int = 0
    labels: str = "noisy"
    task_scales: tuple[tuple[str, float], ...] = ()

    def __post_init__(self) -> None:
        if not (math.isfinite(self.scale) and self.scale >= 0):
            raise ValueError(f"expert.noise must be a finite number >= 0, got {self.scale}.")
        if not (0.0 <= self.correlation < 1.0):
            raise ValueError(f"expert.noise_correlation must be in [0, 1), got {self.correlation}.")
        if self.seed < 0:
            raise ValueError(f"expert.noise_seed must be >= 0, got {self.seed}.")
        if self.labels not in LABEL_CHOICES:
            raise ValueError(f"expert.labels must be one of {list(LABEL_CHOICES)}, got {self.labels!r}.")
        for task, scale in self.task_scales:
            if not (math.isfinite(scale) and scale >= 0):
                raise ValueError(f"expert.noise_by_task: {task}'s noise must be finite, >= 0, got {scale}.")

    @property
    def active(self) -> bool:
        """Whether any task's expert gets noise."""
        return self.scale > 0.0 or any(scale > 0.0 for _, scale in self.task_scales)

    def scale_for(self, task: str | None) -> float:
        """The noise scale of ``task``'s expert: its own (``task_scales``), else ``scale``."""
        return dict(self.task_scales).get(task, self.scale) if task is not None else self.scale

    def episode_process(
        self, episode_key: Sequence[int], low: np.ndarray, high: np.ndarray, task: str | None = None
    ) -> ActionNoise | None:
        """The noise of one episode (None when this task's expert gets none).

        Args:
            episode_key: ``(round, task, episode)``: which episode, for its own generator.
            low: The env's lower action bounds.
            high: The env's upper action bounds.
            task: The task's name, for its own scale (``task_scales``); None: ``scale``.
        """
        scale = self.scale_for(task)
        if scale <= 0.0:
            return None
        entropy = [self.seed, NOISE_STREAM, *(int(part) for part in episode_key)]
        return ActionNoise(self, np.random.default_rng(np.random.SeedSequence(entropy)), low, high, scale)


class ActionNoise:
    """One episode's correlated noise process (``ExpertNoise`` gives the formula)."""

    def __init__(
        self,
        noise: ExpertNoise,
        rng: np.random.Generator,
        low: np.ndarray,
        high: np.ndarray,
        scale: float | None = None,
    ) -> None:
        """Starts the process; the first ``perturb`` draws ``e_0``.

        Args:
            noise: The noise's settings.
            rng: The episode's own generator.
            low: The env's lower action bounds.
            high: The env's upper action bounds.
            scale: This task's ``sigma`` (``ExpertNoise.scale_for``); None: ``noise.scale``.
        """
        self.noise = noise
        self.scale = noise.scale if scale is None else scale
        self.rng = rng
        self.low = np.asarray(low, dtype=np.float32)
        self.high = np.asarray(high, dtype=np.float32)
        self._state: np.ndarray | None = None

    def sample(self, size: int) -> np.ndarray:
        """The next noise vector ``e_t`` (float64, standard deviation ``scale`` per component)."""
        sigma, rho = self.scale, self.noise.correlation
        draw = self.rng.standard_normal(size)
        if self._state is None:
            self._state = sigma * draw
        else:
            self._state = rho * self._state + math.sqrt(1.0 - rho * rho) * sigma * draw
        return self._state

    def perturb(self, action: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The executed action and the label for the expert's ``action`` at this step.

        Returns:
            ``(executed, label)``, both float32 and within the action bounds: the noisy action, and
            the noisy action again (``labels="noisy"``) or the clipped expert action (``clean``).
        """
        action = np.asarray(action, dtype=np.float32)
        noisy = np.clip(action + self.sample(action.size).astype(np.float32), self.low, self.high)
        if self.noise.labels == "clean":
            return noisy, np.clip(action, self.low, self.high)
        return noisy, noisy
