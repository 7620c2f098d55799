"""Imperfect experts: temporally correlated Gaussian noise on an expert's actions.

At step ``t`` of an episode the expert executes::

    a_t = clip(mu(s_t) + e_t, low, high)
    e_0 = sigma * z_0,   e_t = rho * e_(t-1) + sqrt(1 - rho^2) * sigma * z_t,   z_t ~ N(0, I)

``mu`` is the wrapped expert, ``sigma`` the noise scale (per task: ``task_scales``) and ``rho`` its
step-to-step correlation (an AR(1) process, DDPG's discretised Ornstein-Uhlenbeck noise). The label
is ``a_t`` (``labels="noisy"``: a stochastic policy's demonstrations) or ``clip(mu(s_t))``
(``"clean"``: DART, Laskey et al. 2017). Each episode draws from its own generator, seeded by
``(seed, NOISE_STREAM, round, task, episode)``; ``scale = 0`` draws nothing.
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
        scale: Standard deviation ``sigma`` of the noise on each action component, in action units;
            0 turns noise off.
        correlation: Step-to-step correlation ``rho``, in [0, 1) (0.9 keeps a perturbation about ten steps).
        seed: Seed of the noise, apart from the run's seed.
        labels: ``noisy`` (the executed action) or ``clean`` (the expert's own action).
        task_scales: ``(task, scale)`` pairs: these tasks' own scale instead of ``scale``.
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

        ``episode_key`` is ``(round, task, episode)``, which seeds the episode's generator; ``low``/``high``
        are the action bounds; ``task`` picks its own scale (None: ``scale``).
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
        """Starts the process with the episode's generator; the first ``perturb`` draws ``e_0``."""
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
        """The executed action and the label for the expert's ``action``, both float32 within the bounds."""
        action = np.asarray(action, dtype=np.float32)
        noisy = np.clip(action + self.sample(action.size).astype(np.float32), self.low, self.high)
        if self.noise.labels == "clean":
            return noisy, np.clip(action, self.low, self.high)
        return noisy, noisy
