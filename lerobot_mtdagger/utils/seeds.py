"""Every random stream of a run, named in one place.

Each kind of random choice draws from its own stream, seeded with numpy's ``SeedSequence`` from
``(seed, stream, *keys)``, so drawing more from one stream never shifts another. ``--training.seed``
replaces the run's seed in ``TRAINING_STREAM`` alone.

Streams (number; keys; what it decides):

- ``COLLECT_STREAM`` (0; round, task, episode): the env reset of a collected episode.
- ``EVAL_STREAM`` (1; round, task, episode): the env reset of an evaluation episode (offset by 2**31).
- ``BETA_STREAM`` (2; round, task, episode): who acts in an episode of a mixed DAgger round.
- ``TRAINING_STREAM`` (3; round): a phase's initial weights and batch order.
- ``NOISE_STREAM`` (4; round, task, episode): an imperfect expert's action noise (seeded by
  ``--expert.noise_seed``).
- ``EXPERT_CHECK_STREAM`` (5; 0, task, episode): the resets that measure an expert for
  ``--expert.min_success``.
- ``HELDOUT_STREAM`` (7; task): which episodes a run holds out of training.

The frames a phase measures its per-task loss on come from ``np.random.default_rng(seed)``.
"""

from __future__ import annotations

import numpy as np

COLLECT_STREAM = 0
EVAL_STREAM = 1
BETA_STREAM = 2
TRAINING_STREAM = 3
NOISE_STREAM = 4
EXPERT_CHECK_STREAM = 5
HELDOUT_STREAM = 7


def stream_seed(seed: int, stream: int, *keys: int) -> int:
    """A 32-bit seed of ``stream`` for ``keys`` (e.g. a round index), derived from the run's seed."""
    return int(np.random.SeedSequence([seed, stream, *keys]).generate_state(1)[0])
