"""The option groups of ``run``: ``--dagger.*``, ``--rollout.*``, ``--expert.*`` and ``--training.*``.

The env workers' options (``WorkerOptions``) are shared with ``eval`` and ``shift``.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lerobot_mtdagger.experts.noise import ExpertNoise
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.ray_session import check_ray_address, import_ray

RUN_MODES: tuple[str, ...] = ("dagger", "bc")
"""``dagger``: Algorithm 1 with the chosen scheduler; ``bc``: the one-round behaviour-cloning baseline."""


MIXING_MODES: tuple[str, ...] = ("episode", "step")
"""``episode``: one beta coin per episode; ``step``: a coin at every step (classic DAgger)."""


NORMALISATIONS: tuple[str, ...] = ("fixed", "recompute")
"""``fixed``: statistics of round 0's training frames, kept for every phase; ``recompute``: of D(k)."""


STEPS_RULES: tuple[str, ...] = ("fixed", "epochs", "plateau")
"""``fixed`` steps, ``epochs`` passes over the frames, or until the held-out loss stops (``plateau``)."""


SAMPLINGS: tuple[str, ...] = ("uniform", "balanced")
"""``uniform``: frames uniformly; ``balanced``: a task uniformly, then one of its frames."""


LR_SCHEDULES: tuple[str, ...] = ("constant", "cosine")
"""``constant``, or ``cosine``: decayed to 0 over each phase's steps."""


WORKER_BACKENDS: tuple[str, ...] = ("local", "ray")
"""``local``: env workers forked on this machine; ``ray``: Ray actors on a Ray cluster."""


GAIN_SPLITS: tuple[str, ...] = ("train", "heldout")
"""Where the performance-gain scheduler measures per-task loss: the training data or held-out episodes."""


def _require_positive(owner: Any, group: str, names: Sequence[str]) -> None:
    """Refuses an option of ``names`` that is set and not a finite number > 0."""
    for name in names:
        value = getattr(owner, name)
        if value is not None and not (math.isfinite(value) and value > 0):
            raise ValueError(f"{group}.{name} must be > 0, got {value}.")


def _require_choice(value: str | None, option: str, choices: Sequence[str]) -> None:
    """Refuses a ``value`` of ``option`` outside ``choices``."""
    if value not in choices:
        raise ValueError(f"{option} must be one of {list(choices)}, got {value!r}.")


@dataclass
class DAggerConfig:
    """The DAgger loop: how many rounds, how many expert episodes, who acts (``--dagger.*``).

    Attributes:
        rounds: DAgger rounds after round 0 (None: the preset's).
        initial_demos: Round-0 expert episodes per task (None: the preset's).
        budget: Expert episodes per DAgger round over all tasks (None: budget_per_task * tasks).
        budget_per_task: Used when ``budget`` is None (None: the preset's).
        beta: Probability of executing the expert's action in the first DAgger round.
        beta_decay: Subtracted from beta after every DAgger round.
        beta_min: Floor of beta.
        mixing: ``episode`` (one beta coin per episode) or ``step`` (a coin at every step). Task need
            reads learner-only episodes, so ``step`` with beta > 0 measures nothing.
    """

    rounds: int | None = None
    initial_demos: int | None = None
    budget: int | None = None
    budget_per_task: int | None = None
    beta: float = 0.5
    beta_decay: float = 0.5
    beta_min: float = 0.0
    mixing: str = "episode"

    def check(self) -> None:
        """Refuses impossible values (one line naming the option)."""
        assert self.rounds is not None and self.initial_demos is not None  # filled by RunConfig's preset
        if self.rounds < 0:
            raise ValueError(f"dagger.rounds must be >= 0, got {self.rounds}.")
        if self.initial_demos <= 0:
            raise ValueError(
                f"dagger.initial_demos must be > 0, got {self.initial_demos}: round 0 trains the first "
                "policy on expert demos."
            )
        _require_positive(self, "dagger", ("budget", "budget_per_task"))
        _require_choice(self.mixing, "dagger.mixing", MIXING_MODES)
        if not 0.0 <= self.beta_min <= self.beta <= 1.0 or self.beta_decay < 0:
            raise ValueError(
                f"Need 0 <= dagger.beta_min <= dagger.beta <= 1 and dagger.beta_decay >= 0, got "
                f"beta={self.beta}, beta_min={self.beta_min}, beta_decay={self.beta_decay}."
            )

    def budget_for(self, num_tasks: int) -> int:
        """Expert episodes per DAgger round."""
        if self.budget is not None:
            return self.budget
        assert self.budget_per_task is not None  # filled by RunConfig's preset
        return self.budget_per_task * num_tasks


@dataclass
class WorkerOptions:
    """Env workers: how many, and where they run (``run``'s ``--rollout.*``, ``eval``'s and ``shift``'s own).

    Attributes:
        workers: Env worker processes for collection and evaluation (None: one per core; 0: in the main
            process). Never changes a result.
        worker_backend: ``local`` (forked processes) or ``ray`` (Ray actors on a cluster). Never changes
            a result.
        ray_address: The Ray cluster of ``worker_backend=ray`` (``auto``: the one ``ray start`` left on
            this machine; ``ray://host:10001``; None: start a local Ray).
    """

    workers: int | None = None
    worker_backend: str = "local"
    ray_address: str | None = None

    def check_workers(self, prefix: str = "") -> None:
        """Refuses a negative count, an unknown backend or a missing Ray, before anything runs.

        ``prefix`` is the options' group as the messages name it (``rollout.`` for ``run``).
        """
        resolve_workers(self.workers)
        _require_choice(self.worker_backend, f"{prefix}worker_backend", WORKER_BACKENDS)
        if self.worker_backend == "ray":
            import_ray()
            check_ray_address(self.ray_address, f"--{prefix}ray_address")

    @property
    def worker_count(self) -> int:
        """Env worker processes to start (``workers``, or one per core)."""
        return resolve_workers(self.workers)

    def env_workers(self, suite: Any, reserve_cpus: bool = True) -> Any:
        """The ``EnvWorkers`` of ``suite`` on this config's backend (a context manager).

        ``reserve_cpus=False``: a pool that runs only while the run's own workers wait (no Ray CPUs).
        """
        from lerobot_mtdagger.runner.rollout.ray_workers import make_env_workers

        return make_env_workers(suite, self.worker_count, self.worker_backend, self.ray_address, reserve_cpus)


@dataclass
class RolloutEpisodes:
    """Where a DAgger rollout is cut, and the evaluation episodes (``RolloutConfig`` without its workers).

    Attributes:
        eval_episodes: Evaluation episodes per task after each training phase (None: the preset's).
        max_steps: Steps after which a DAgger rollout is cut (None: the env's own horizon).
        expert_multiple: Cut a DAgger rollout at this multiple of the steps the expert alone takes to
            succeed from the same reset (no cut where it fails). None: no such cut.
        steps_after_success: Steps recorded after the first success before an episode ends.
        eval_phases: The phases whose policy is evaluated (0: round 0's, a BC run's only one); None: every
            phase. Allocations do not depend on it.
    """

    eval_episodes: int | None = None
    max_steps: int | None = None
    expert_multiple: float | None = None
    steps_after_success: int = 10
    eval_phases: list[int] | None = None


@dataclass
class RolloutConfig(WorkerOptions, RolloutEpisodes):
    """Episodes: where a DAgger rollout is cut, evaluation, env workers (``--rollout.*``).

    A dataclass takes its last base's fields first: ``RolloutEpisodes``' options come before the workers'.
    """

    def check(self) -> None:
        """Refuses impossible values (one line naming the option)."""
        for name in ("eval_episodes", "steps_after_success"):
            if getattr(self, name) < 0:
                raise ValueError(f"rollout.{name} must be >= 0, got {getattr(self, name)}.")
        _require_positive(self, "rollout", ("max_steps", "expert_multiple"))
        if self.eval_phases is not None and any(
            isinstance(k, bool) or not isinstance(k, int) or k < 0 for k in self.eval_phases
        ):
            raise ValueError(
                f"rollout.eval_phases must list phase indices >= 0 (0: round 0's BC), got {self.eval_phases}."
            )
        self.check_workers("rollout.")

    def evaluates(self, phase: int) -> bool:
        """Whether phase ``phase``'s policy is evaluated."""
        return self.eval_episodes != 0 and (self.eval_phases is None or phase in self.eval_phases)


@dataclass
class ExpertConfig:
    """How far the experts are from perfect (``--expert.*``; ``experts/noise.py`` gives the formula).

    Attributes:
        noise: Standard deviation of the noise on each action component, in action units (actions lie
            in [-1, 1]); 0: no noise.
        noise_by_task: Some tasks' own noise instead of ``noise``, by task name, e.g.
            ``'{assembly-v3: 0.05, reach-v3: 0.6}'``. None: ``noise`` for every task.
        noise_correlation: Step-to-step correlation of the noise, in [0, 1) (0: white noise).
        noise_seed: Seed of the noise, apart from ``--seed``.
        labels: What a frame stores as the expert's label: ``noisy`` (the executed action) or ``clean``
            (the expert's own action: DART-style).
        path: LeRobot policy folders acting on the privileged state: one multitask policy folder, or one
            policy folder per task (``experts/command_line.py``). None: the registered experts.
        type: An expert factory ``factory(suite, task) -> Expert``: a registered name or an importable
            ``module:attribute``. None: the registered experts.
        min_success: Keep only the tasks whose expert succeeds at least this often, measured before
            round 0 (``rollout/expert_check.py``). None: every task.
        success_episodes: Episodes per task that ``min_success`` is measured on.
    """

    noise: float = 0.0
    noise_correlation: float = 0.0
    noise_seed: int = 0
    labels: str = "noisy"
    noise_by_task: dict[str, float] | None = None
    path: str | None = None
    type: str | None = None
    min_success: float | None = None
    success_episodes: int = 20

    def check(self) -> None:
        """Refuses impossible values (one line naming the option)."""
        self.settings()
        if self.min_success is not None and not (0.0 < self.min_success <= 1.0):
            raise ValueError(f"expert.min_success must be in (0, 1], got {self.min_success}.")
        if self.success_episodes <= 0:
            raise ValueError(f"expert.success_episodes must be > 0, got {self.success_episodes}.")
        if self.path is not None and self.type is not None:
            raise ValueError("--expert.path and --expert.type both name the experts: give one of them.")
        if self.path is not None and not Path(self.path).is_dir():
            raise ValueError(
                f"--expert.path={self.path} is not a folder: give a policy folder (one multitask expert) "
                "or a folder with one policy folder per task."
            )

    def suite_with_experts(self, suite: Any) -> Any:
        """``suite`` with these experts (``path``, ``type``) and their noise (``UserError`` on a bad one)."""
        unknown = sorted(set(self.noise_by_task or {}) - set(suite.task_names))
        if unknown:
            raise UserError(
                f"--expert.noise_by_task names {', '.join(unknown)}, not a task of suite {suite.name} "
                f"(its tasks: {', '.join(suite.task_names)}): fix the names or --suite.tasks."
            )
        from lerobot_mtdagger.experts.command_line import command_line_experts  # LeRobot and torch

        named = command_line_experts(suite, self.path, self.type)
        return named.with_expert_noise(self.settings())

    def settings(self) -> ExpertNoise:
        """The ``ExpertNoise`` these options describe."""
        return ExpertNoise(
            scale=self.noise,
            correlation=self.noise_correlation,
            seed=self.noise_seed,
            labels=self.labels,
            task_scales=tuple(sorted((self.noise_by_task or {}).items())),
        )


@dataclass
class TrainingConfig:
    """How each phase trains the student (``--training.*``; the optimiser is the policy's).

    Attributes:
        steps_per_round: Training steps after each round (``steps_rule=fixed``; None: the preset's).
        warm_start: Continue from the previous round's weights (else retrain from scratch).
        steps_rule: ``fixed`` (``steps_per_round`` per phase), ``epochs`` (``epochs`` passes over the
            phase's frames) or ``plateau`` (until the held-out loss stops improving, at most
            ``plateau_max_steps``; the best weights are kept). None: from the preset.
        epochs: Passes over the training frames per phase when ``steps_rule=epochs``; None: the preset's.
        plateau_every: Steps between two held-out loss measurements when ``steps_rule=plateau``.
        plateau_patience: Measurements without a new minimum that end a ``plateau`` phase.
        plateau_max_steps: Most steps of a ``plateau`` phase.
        normalisation: ``fixed`` (statistics of round 0's training frames for every phase) or
            ``recompute`` (of D(k) each phase).
        sampling: ``uniform`` (frames uniformly) or ``balanced`` (a task uniformly, then one of its
            frames); None: from the preset.
        lr_schedule: ``constant`` or ``cosine`` (``mtdagger`` only; a LeRobot student follows its config's
            scheduler preset).
        gain_split: ``train`` (per-task loss on the training data) or ``heldout`` (on held-out episodes).
        heldout_fraction: Fraction of each task's episodes held out when ``gain_split=heldout`` or
            ``steps_rule=plateau`` (an episode never changes side; a task's first is always trained on).
        seed: Seed of the phases' initial weights, batch order and task dropout, if it is to differ from
            ``--seed`` (which keeps the episodes collected, evaluated and held out). None: ``--seed``.
        progress_every_s: Seconds of training between two saves of a phase's progress, from which a cut
            phase resumes with ``--resume=true``; 0: never saved. Changes no result.
    """

    steps_per_round: int | None = None
    warm_start: bool = True
    steps_rule: str | None = None
    epochs: float | None = None
    plateau_every: int = 200
    plateau_patience: int = 5
    plateau_max_steps: int = 20_000
    normalisation: str = "fixed"
    sampling: str | None = None
    lr_schedule: str = "constant"
    gain_split: str = "train"
    heldout_fraction: float = 0.2
    seed: int | None = None
    progress_every_s: float = 600.0

    def check(self) -> None:
        """Refuses impossible values (one line naming the option)."""
        positive = ("steps_per_round", "epochs", "plateau_every", "plateau_patience", "plateau_max_steps")
        _require_positive(self, "training", positive)
        if self.progress_every_s < 0:
            raise ValueError(
                f"training.progress_every_s must be >= 0 (0: never save a phase's progress), got "
                f"{self.progress_every_s}."
            )
        if self.seed is not None and self.seed < 0:
            raise ValueError(
                f"training.seed must be >= 0 (or left unset: the run's --seed), got {self.seed}."
            )
        _require_choice(self.steps_rule, "training.steps_rule", STEPS_RULES)
        _require_choice(self.normalisation, "training.normalisation", NORMALISATIONS)
        _require_choice(self.sampling, "training.sampling", SAMPLINGS)
        _require_choice(self.lr_schedule, "training.lr_schedule", LR_SCHEDULES)
        _require_choice(self.gain_split, "training.gain_split", GAIN_SPLITS)
        if not 0.0 < self.heldout_fraction < 1.0:
            raise ValueError(f"training.heldout_fraction must be in (0, 1), got {self.heldout_fraction}.")

    @property
    def holds_out_episodes(self) -> bool:
        """Whether each task's episodes are split into training and held-out ones."""
        return self.gain_split == "heldout" or self.steps_rule == "plateau"


def check_device(device: str) -> None:
    """Refuses a torch device this machine lacks, before anything runs (``ValueError`` naming its devices)."""
    import torch

    try:
        parsed = torch.device(device)
    except RuntimeError:
        raise ValueError(f"policy.device={device!r} is not a torch device: use cpu or cuda:N.") from None
    if parsed.type == "cuda":
        count = torch.cuda.device_count() if torch.cuda.is_available() else 0
        if count == 0 or (parsed.index is not None and parsed.index >= count):
            raise ValueError(
                f"policy.device={device!r} is not available here ({count} CUDA device(s)); "
                "pass --policy.device=cpu."
            )
    elif parsed.type == "mps" and not torch.backends.mps.is_available():
        raise ValueError(f"policy.device={device!r} is not available here; pass --policy.device=cpu.")
    elif parsed.type == "cpu" and parsed.index not in (None, 0):
        raise ValueError(
            f"policy.device={device!r} names a CPU that does not exist: pass --policy.device=cpu."
        )


def resolve_workers(workers: int | None) -> int:
    """The env worker count an option asks for: one per core for None (``ValueError`` if negative)."""
    if workers is not None and workers < 0:
        raise ValueError(f"workers must be >= 0 (0: envs in the main process), got {workers}.")
    return default_worker_count() if workers is None else workers


def default_worker_count() -> int:
    """One env worker per core this process may run on."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1
