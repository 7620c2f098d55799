"""A training phase's progress, saved every few minutes so that a cut phase resumes where it was.

``StepLoop`` saves what the remaining steps depend on (weights, optimiser, scheduler, generators,
steps and draws) to ``policies/.progress/round-XXX.pt`` atomically; the file is deleted when its
phase commits, and discarded with a warning if its key or contents do not fit. A resumed phase equals
the uninterrupted one. A ``plateau`` phase is never saved part-way.
"""

from __future__ import annotations

import logging
import os
import pickle
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import torch

from lerobot_mtdagger.datasets.experiment_files import PARTIAL_SUFFIX

logger = logging.getLogger(__name__)

FORMAT = 1
"""Version of the saved progress; a file of another version is discarded."""


@dataclass
class SavedProgress:
    """What a phase's remaining steps need, as loaded (``PhaseProgress.load``).

    Attributes:
        done: Steps taken.
        state: The rest, for ``restore_loop``.
        steps_s: Seconds the earlier processes spent in these steps.
    """

    done: int
    state: dict[str, Any]
    steps_s: float


class PhaseProgress:
    """Saves and loads one training phase's progress at ``path`` every ``every_s`` seconds (0: never).

    A saved file of another ``key`` (``phase_key``) is discarded.
    """

    def __init__(self, path: Path, key: dict[str, Any], every_s: float) -> None:
        """Starts the clock of the first save now."""
        self.path = Path(path)
        self.key = key
        self.every_s = every_s
        self.last_save = time.perf_counter()

    def due(self) -> bool:
        """Whether ``every_s`` seconds have passed since the last save (or the start)."""
        return self.every_s > 0 and time.perf_counter() - self.last_save >= self.every_s

    def save(self, done: int, state: dict[str, Any], steps_s: float) -> None:
        """Writes the progress after ``done`` steps (a temporary file, then an atomic rename)."""
        self.path.parent.mkdir(parents=True, exist_ok=True)
        partial = self.path.with_name(self.path.name + PARTIAL_SUFFIX)
        torch.save({"format": FORMAT, "key": self.key, "done": done, "steps_s": steps_s, **state}, partial)
        os.replace(partial, self.path)
        self.last_save = time.perf_counter()
        logger.info("Saved the phase's progress after %d steps to %s", done, self.path)

    def load(self) -> SavedProgress | None:
        """The saved progress of this phase, or None (a file of another phase or unreadable is discarded)."""
        if not self.path.exists():
            return None
        try:
            saved = torch.load(self.path, map_location="cpu", weights_only=True)
        except (OSError, RuntimeError, EOFError, pickle.UnpicklingError, zipfile.BadZipFile) as error:
            self._discard(f"it cannot be read ({error})")
            return None
        if not isinstance(saved, dict) or saved.get("format") != FORMAT:
            self._discard(f"it is not progress of format {FORMAT}")
            return None
        if saved.get("key") != self.key:
            self._discard(f"it belongs to another phase ({saved.get('key')}, this one: {self.key})")
            return None
        done, steps_s = saved.pop("done"), saved.pop("steps_s")
        for name in ("format", "key"):
            saved.pop(name)
        logger.info("Resuming the phase after %d steps from %s", done, self.path)
        return SavedProgress(done=int(done), state=saved, steps_s=float(steps_s))

    def discard(self) -> None:
        """Deletes the saved progress (the phase is committed, or the file is of no use)."""
        self.path.unlink(missing_ok=True)
        self.path.with_name(self.path.name + PARTIAL_SUFFIX).unlink(missing_ok=True)

    def _discard(self, why: str) -> None:
        logger.warning("Discarding %s: %s; the phase starts over.", self.path, why)
        self.discard()


def phase_key(round_index: int, policy_type: str, options: Any, train_index: torch.Tensor) -> dict[str, Any]:
    """What a saved progress must match: the round, policy type, options, and a fingerprint of the frames."""
    index = train_index.cpu().long()
    return {
        "round": round_index,
        "policy_type": policy_type,
        "steps": options.steps,
        "batch_size": options.batch_size,
        "lr": float(options.lr),
        "seed": options.seed,
        "sampling": options.sampling,
        "lr_schedule": options.lr_schedule,
        "frames": [len(index), int(index.sum()), int((index * index).sum())],
    }


def loop_state(loop: Any) -> dict[str, Any]:
    """What a ``steps.StepLoop``'s remaining steps depend on, at the start of an interval."""
    ops = loop.ops
    seam_rngs = {name: g for name, g in vars(ops).items() if isinstance(g, torch.Generator)}
    return {
        "policy": ops.policy.state_dict(),
        "optimizer": loop.optimizer.state_dict(),
        "scheduler": None if loop.scheduler is None else loop.scheduler.state_dict(),
        "sampler": loop.generator.get_state(),
        "torch_rng": torch.get_rng_state(),
        "cuda_rng": torch.cuda.get_rng_state_all() if loop.data.device.type == "cuda" else None,
        "seam_rngs": {name: generator.get_state() for name, generator in seam_rngs.items()},
        "drawn": loop.draws.drawn.clone(),
        "tail": loop.losses.tail.clone(),
        "resumed_after_steps": list(loop.resumed_after_steps),
    }


def restore_loop(loop: Any, saved: SavedProgress | None) -> int:
    """Gives a ``steps.StepLoop`` a saved progress (``loop_state``); the steps it had taken (0: none)."""
    if saved is None:
        return 0
    state = saved.state
    loop.ops.policy.load_state_dict(state["policy"])
    loop.optimizer.load_state_dict(state["optimizer"])
    if loop.scheduler is not None:
        loop.scheduler.load_state_dict(state["scheduler"])
    loop.generator.set_state(state["sampler"])
    torch.set_rng_state(state["torch_rng"])
    if state["cuda_rng"] is not None:
        torch.cuda.set_rng_state_all(state["cuda_rng"])
    for name, generator_state in state["seam_rngs"].items():
        getattr(loop.ops, name).set_state(generator_state)
    loop.draws.drawn = state["drawn"]
    loop.losses.tail = state["tail"]
    loop.earlier_steps_s = saved.steps_s
    loop.resumed_after_steps = [*state["resumed_after_steps"], saved.done]
    return saved.done
