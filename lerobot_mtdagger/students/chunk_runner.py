"""The evaluation runner of LeRobot's students: an action queue and an observation history per episode."""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import torch

from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner

ChunkPredictor = Callable[[Any, dict[str, torch.Tensor]], torch.Tensor]
"""``(policy, batch) -> (B, n, action_dim)``: a policy's normalised action chunks for a batch."""


def predict_action_chunk(policy: Any, batch: dict[str, torch.Tensor]) -> torch.Tensor:
    """LeRobot's ``predict_action_chunk`` of ``policy`` for ``batch``."""
    return policy.predict_action_chunk(batch)


class ChunkRunner(PolicyRunner):
    """A LeRobot policy that acts in chunks (ACT, Diffusion Policy), one action queue PER EPISODE.

    LeRobot's ``select_action`` keeps one queue for the whole batch, but a rollout's episodes start and
    end at different steps. Each running episode (lane) keeps its own observation history and queue of
    ``n_action_steps`` actions; the policy is queried, batched, for the lanes whose queue is empty.
    Without lanes every row is a fresh episode.
    """

    tracks_episodes = True

    @property
    def acts_on_unseen_tasks(self) -> bool:
        """Always: a task outside ``task_names`` gets the all-zero one-hot vector."""
        return True

    def __init__(
        self,
        policy: Any,
        preprocessor: Any,
        postprocessor: Any,
        predict_chunk: ChunkPredictor | None = None,
    ) -> None:
        """Wraps a LeRobot policy in eval mode with its processors.

        ``predict_chunk`` gives normalised chunks (B, n, action_dim) for batches of current observations or
        of histories (B, n_obs_steps, ...); None: LeRobot's ``predict_action_chunk``.
        """
        super().__init__(policy, preprocessor, postprocessor)
        self.predict_chunk = predict_chunk or predict_action_chunk
        deltas = policy.config.observation_delta_indices
        self.history_length = 1 if deltas is None else len(deltas)
        self.action_steps = int(policy.config.n_action_steps)
        self.histories: dict[int, deque[dict[str, torch.Tensor]]] = {}
        self.queues: dict[int, deque[torch.Tensor]] = {}

    def __call__(
        self,
        observations: list[dict[str, np.ndarray]],
        tasks: list[str],
        lanes: Sequence[int] | None = None,
        starts: Sequence[bool] | None = None,
    ) -> np.ndarray:
        """Actions for a batch of running episodes.

        ``lanes`` are the rows' running episodes (None: every row a fresh episode); ``starts`` mark an
        episode's first observation, which restarts its lane's queue.
        """
        inputs = {
            key: torch.from_numpy(np.stack([observation[key] for observation in observations]))
            for key in self.input_keys
        }
        if lanes is None:
            return self.predict(inputs, tasks).numpy()
        batch = self.preprocess(inputs, tasks)
        keys = [key for key in batch if key.startswith("observation.")]
        for row, (lane, start) in enumerate(
            zip(lanes, starts if starts is not None else [False] * len(lanes), strict=True)
        ):
            self._remember(lane, start, {key: batch[key][row] for key in keys})
        self._refill([lane for lane in lanes if not self.queues[lane]])
        return np.stack([self.queues[lane].popleft().numpy() for lane in lanes])

    def predict(self, inputs: dict[str, torch.Tensor], tasks: Sequence[str]) -> torch.Tensor:
        """Unnormalised actions (B, action_dim), each row a fresh episode (its chunk's first action)."""
        batch = self.preprocess(inputs, tasks)
        keys = [key for key in batch if key.startswith("observation.")]
        if self.history_length > 1:  # a fresh episode's history repeats its first observation
            batch = {
                key: batch[key][:, None].expand(-1, self.history_length, *batch[key].shape[1:])
                for key in keys
            }
        else:
            batch = {key: batch[key] for key in keys}
        with torch.inference_mode():
            return self.postprocessor(self._predict_chunk(batch)[:, 0]).cpu()

    def reset(self) -> None:
        """Forgets every episode's history and queue."""
        self.histories.clear()
        self.queues.clear()

    def _remember(self, lane: int, start: bool, observation: dict[str, torch.Tensor]) -> None:
        """Adds an episode's newest observation to its history (a new episode restarts it)."""
        if start or lane not in self.histories:
            self.histories[lane] = deque([observation] * self.history_length, maxlen=self.history_length)
            self.queues[lane] = deque()
        else:
            self.histories[lane].append(observation)

    def _refill(self, lanes: Sequence[int]) -> None:
        """Queries the policy, batched, for the next chunk of the episodes in ``lanes``."""
        if not lanes:
            return
        keys = list(self.histories[lanes[0]][0])
        if self.history_length == 1:
            batch = {key: torch.stack([self.histories[lane][0][key] for lane in lanes]) for key in keys}
        else:
            batch = {
                key: torch.stack(
                    [torch.stack([frame[key] for frame in self.histories[lane]]) for lane in lanes]
                )
                for key in keys
            }
        with torch.inference_mode():
            chunk = self._predict_chunk(batch)[:, : self.action_steps]
            actions = self.postprocessor(chunk).cpu()
        for lane, lane_actions in zip(lanes, actions, strict=True):
            self.queues[lane].extend(lane_actions)

    def _history(self, lane: int, key: str) -> torch.Tensor:
        """An episode's history of one input, (n_obs_steps, ...)."""
        return torch.stack([frame[key] for frame in self.histories[lane]])

    def _predict_chunk(self, batch: dict[str, torch.Tensor]) -> torch.Tensor:
        """The policy's normalised action chunk (B, n, action_dim) for current observations or histories."""
        return self.predict_chunk(self.policy, batch)
