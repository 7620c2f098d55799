"""Command-line configs of ``lerobot-mtdagger run`` (draccus dataclasses) and the paper's presets.

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
preset samples batches ``uniform``ly except ``metaworld-pixels``, whose runs (DAgger and BC) sample
``balanced``: ``PIXELS_SAMPLING``.)

The DAgger mixing coefficient ``beta`` is the probability that the EXPERT's action is executed at
a step (classic DAgger; the paper's text is ambiguous): 0.5 in the first DAgger round, decayed by
0.5 per round to 0. ``--mode=bc`` runs the one-round behaviour-cloning baseline instead.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import functools
import math
import os
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lerobot_mtdagger.datasets.config_layout import FLAT_OPTION_PATHS
from lerobot_mtdagger.envs.config import DEFAULT_NUM_POINTS, SuiteConfig
from lerobot_mtdagger.envs.drawers.variants import LEGACY_PLACEMENT
from lerobot_mtdagger.experts.noise import ExpertNoise
from lerobot_mtdagger.scheduler import NeedSchedulerConfig, SchedulerConfig
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.parsing import cache_dataclass_sources
from lerobot_mtdagger.utils.paths import check_output_dir
from lerobot_mtdagger.utils.ray_session import check_ray_address, import_ray

cache_dataclass_sources()  # draccus.parse(RunConfig) in 0.1 s instead of 2-3 s (utils/parsing.py)


@dataclass
class PolicyOptions:
    """Options of the ``mtdagger`` policy and its training (None: from the preset).

    Attributes:
        batch_size: Training batch size.
        lr: AdamW learning rate.
        state_hidden_dims: Hidden sizes of the state MLP.
        head_hidden_dims: Hidden sizes of the action head.
        pointnet_dims: PointNet per-point MLP sizes.
        pointnet_layer_norm: LayerNorm after every PointNet layer and its projection (DP3's encoder;
            with ``pointcloud_embedding_dim=64`` and 512 points, DP3's size).
        pointcloud_embedding_dim: Output size of the point-cloud encoder.
        task_embedding_dim: Task embedding size.
        task_dropout: Probability of training a sample on the shared "any task" embedding instead of
            its own (``MTDAggerConfig.task_dropout``: what lets the policy act on unseen tasks). None:
            ``UNSEEN_TASK_DROPOUT`` for a suite with held-out tasks (the drawers), else 0.
        device: Torch device.
    """

    batch_size: int | None = None
    lr: float | None = None
    state_hidden_dims: list[int] = field(default_factory=lambda: [256, 256])
    head_hidden_dims: list[int] = field(default_factory=lambda: [256, 256])
    pointnet_dims: list[int] = field(default_factory=lambda: [64, 128, 256])
    pointnet_layer_norm: bool = False
    pointcloud_embedding_dim: int = 256
    task_embedding_dim: int = 32
    task_dropout: float | None = None
    device: str = "cpu"

    def resolved_task_dropout(self, has_heldout_tasks: bool) -> float:
        """``task_dropout``, with None resolved for a suite with or without held-out tasks."""
        if self.task_dropout is not None:
            return self.task_dropout
        return UNSEEN_TASK_DROPOUT if has_heldout_tasks else 0.0


UNSEEN_TASK_DROPOUT = 0.1
"""Task dropout of runs on suites with held-out tasks: one sample in ten trains the shared embedding."""


def _lerobot_student(config_class: type) -> type:
    """``config_class`` (a LeRobot policy config) with the run's training batch size added.

    Every option is LeRobot's own (``--policy.type=act --policy.chunk_size=20``); the learning rate
    is the policy's ``optimizer_lr`` (its optimiser preset), so a preset's ``policy.lr`` does not
    apply. Defaults that differ from LeRobot's: ``device=cpu`` (as ``mtdagger``), ``push_to_hub=False``
    (``push`` uploads), and no pretrained vision backbone (nothing is downloaded during a run; pass
    ``--policy.pretrained_backbone_weights=...`` where the weights are cached).
    """
    extra: list[tuple[str, Any, Any]] = [
        ("batch_size", int | None, field(default=None)),
        ("device", str | None, field(default="cpu")),
        ("push_to_hub", bool, field(default=False)),
    ]
    if any(f.name == "pretrained_backbone_weights" for f in dataclasses.fields(config_class)):
        extra.append(("pretrained_backbone_weights", str | None, field(default=None)))
    student = dataclasses.make_dataclass(f"{config_class.__name__}Student", extra, bases=(config_class,))
    student.__doc__ = f"{config_class.__doc__ or config_class.__name__}\n\n{_lerobot_student.__doc__}"
    return student


UNSUPPORTED_STUDENT_OPTIONS: dict[str, str] = {
    "use_amp": "its training, collection and evaluation run in float32 (lerobot-eval honours it for a "
    "saved policy)",
    "use_peft": "the student is trained in full",
    "push_to_hub": "`lerobot-mtdagger push` uploads a run's rounds and policies",
    "pretrained_path": "each phase starts from the previous phase's policy (training.warm_start) or afresh",
}
"""Options of LeRobot's policy configs that ``run`` would otherwise ignore: refused, naming why."""


LEROBOT_STUDENT_TYPES: tuple[str, ...] = ("act", "diffusion")
"""``--policy.type`` values other than ``mtdagger``: LeRobot's own policies as the student."""


@functools.cache
def lerobot_students() -> dict[str, type]:
    """The options class of each LeRobot student type (LeRobot's policies imported on first use)."""
    from lerobot.policies.act.configuration_act import ACTConfig
    from lerobot.policies.diffusion.configuration_diffusion import DiffusionConfig

    return {"act": _lerobot_student(ACTConfig), "diffusion": _lerobot_student(DiffusionConfig)}


_LEROBOT_STUDENTS_PARSED: contextvars.ContextVar[bool] = contextvars.ContextVar(
    "lerobot_students_parsed", default=True
)
"""Whether the option parser offers LeRobot's students (building it for them imports LeRobot and torch)."""


def names_lerobot_student(options: Sequence[str]) -> bool:
    """Whether command-line options may choose a LeRobot student.

    They may with a ``--policy.type`` other than ``mtdagger``, or a ``--config_path`` file.
    """
    for position, option in enumerate(options):
        name, separator, value = option.partition("=")
        if name == "--config_path":
            return True
        if name == "--policy.type":
            if not separator:
                value = options[position + 1] if position + 1 < len(options) else ""
            return value != "mtdagger"
    return False


@contextlib.contextmanager
def students_for(options: Sequence[str]) -> Iterator[None]:
    """Offers LeRobot's students to the parser only if ``options`` may name one.

    ``--help`` and a refused option then answer without importing LeRobot and torch (seconds on a
    small machine).
    """
    token = _LEROBOT_STUDENTS_PARSED.set(names_lerobot_student(options))
    try:
        yield
    finally:
        _LEROBOT_STUDENTS_PARSED.reset(token)


class StudentOptions:
    """The student policy and its options: ``--policy.type`` (draccus choice type; default ``mtdagger``).

    ``mtdagger`` takes ``PolicyOptions``; ``act`` and ``diffusion`` take LeRobot's own config of that
    policy (``lerobot_students()``) plus ``batch_size``. A stored config without ``type`` is ``mtdagger``.
    """

    @classmethod
    def get_choice_class(cls, name: str) -> type:
        """The options class of a ``--policy.type``."""
        return cls.get_known_choices()[name]

    @classmethod
    def get_known_choices(cls) -> dict[str, type]:
        """Every ``--policy.type`` and its options class.

        ``mtdagger`` alone while options that name no LeRobot student are parsed (``students_for``).
        """
        if not _LEROBOT_STUDENTS_PARSED.get():
            return {"mtdagger": PolicyOptions}
        return {"mtdagger": PolicyOptions, **lerobot_students()}

    @classmethod
    def get_choice_name(cls, subcls: type) -> str:
        """The ``--policy.type`` of an options class.

        Raises:
            ValueError: If ``subcls`` is not a student's options class.
        """
        for name, choice in cls.get_known_choices().items():
            if choice is subcls:
                return name
        raise ValueError(f"{subcls} is not a student policy's options class.")

    @classmethod
    def default_choice_name(cls) -> str:
        """``mtdagger``."""
        return "mtdagger"


def student_type(options: Any) -> str:
    """The ``--policy.type`` of a run's policy options."""
    if isinstance(options, PolicyOptions):
        return "mtdagger"
    return StudentOptions.get_choice_name(type(options))


def lerobot_policy_config(options: Any) -> Any:
    """The plain LeRobot config of a LeRobot student's options (without ``batch_size``)."""
    base = type(options).__mro__[1]
    values = {f.name: getattr(options, f.name) for f in dataclasses.fields(base) if f.init}
    return base(**values)


RUN_MODES: tuple[str, ...] = ("dagger", "bc")
"""``dagger``: Algorithm 1 with the chosen scheduler; ``bc``: the one-round behaviour-cloning baseline."""
MIXING_MODES: tuple[str, ...] = ("episode", "step")
"""``episode``: one beta coin per episode (the expert or the learner acts throughout); ``step``: a coin
at every step (classic DAgger)."""
NORMALISATIONS: tuple[str, ...] = ("fixed", "recompute")
"""``fixed``: statistics of round 0's training frames, kept for every phase; ``recompute``: of D(k)."""
STEPS_RULES: tuple[str, ...] = ("fixed", "epochs", "plateau")
"""``fixed``: ``steps_per_round`` per phase; ``epochs``: ``epochs`` passes over the phase's frames;
``plateau``: until the loss on held-out episodes stops improving."""
SAMPLINGS: tuple[str, ...] = ("uniform", "balanced")
"""``uniform``: frames uniformly; ``balanced``: a task uniformly, then one of its frames."""
LR_SCHEDULES: tuple[str, ...] = ("constant", "cosine")
"""``constant``: the learning rate throughout a phase; ``cosine``: decayed to 0 over the phase's steps
(each phase starts again at the full rate)."""
WORKER_BACKENDS: tuple[str, ...] = ("local", "ray")
"""``local``: env workers forked on this machine; ``ray``: Ray actors on a Ray cluster."""
GAIN_SPLITS: tuple[str, ...] = ("train", "heldout")
"""Where the performance-gain scheduler measures per-task loss: the training data or held-out episodes."""

PIXELS_SAMPLING = "balanced"
"""``metaworld-pixels``' batch sampling, DAgger and BC, chosen on development seeds 100-102. DAgger
(200 evaluation episodes per phase, ``experiments/visual-collapse-dev`` 6c): with uniform sampling
the rounds lowered success (0.680 -> 0.678 -> 0.630), with balanced sampling they raised it (0.627 ->
0.678 -> 0.685). BC (``experiments/pixels-bc-dev``, a rule fixed before its runs): uniform BC is
ahead at 10 demos per task (0.670 against 0.600) but loses success from 10 to 30 (0.645); balanced
BC rises (0.762 at 30, 0.795 at 60 against uniform's 0.755) and has the higher mean."""

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
    },
}
"""Preset values by option path (the command-line spelling without ``--``). Each option filled by a
preset has ONE home: its field (None there means "from the preset"); a value given on the command
line or in Python always wins. A value that is a mapping is keyed by ``RunConfig.mode``."""

PRESET_FIELDS: tuple[str, ...] = tuple(PRESETS["small"])
"""The options every preset fills."""


def _require_positive(owner: Any, group: str, names: Sequence[str]) -> None:
    """Refuses an option of ``names`` that is set and not a finite number > 0."""
    for name in names:
        value = getattr(owner, name)
        if value is not None and not (math.isfinite(value) and value > 0):
            raise ValueError(f"{group}.{name} must be > 0, got {value}.")


def _require_choice(value: str, option: str, choices: Sequence[str]) -> None:
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
        mixing: ``episode`` (one beta coin per episode: the expert or the learner acts throughout)
            or ``step`` (a coin at every step). Task need is measured on the episodes where only the
            learner acted, so under ``step`` mixing with beta > 0 a round measures nothing.
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
        return self.budget if self.budget is not None else self.budget_per_task * num_tasks


@dataclass
class WorkerOptions:
    """Env workers: how many, and where they run (``run``'s ``--rollout.*``, ``eval``'s and ``shift``'s own).

    One definition of the options, their checks and the workers they start, for every command that
    steps envs; each command keeps its spelling (``--rollout.workers`` for ``run``, ``--workers``
    for ``eval``).

    Attributes:
        workers: Env worker processes for collection and evaluation (None: one per core; 0: step
            the envs in the main process; with ``worker_backend=ray``, at least one actor). Never
            changes a result.
        worker_backend: ``local`` (forked processes on this machine) or ``ray`` (Ray actors spread
            over a Ray cluster, ``runner/ray_workers.py``). Never changes a result.
        ray_address: The Ray cluster of ``worker_backend=ray`` (``auto``: the one ``ray start`` left
            on this machine; ``ray://host:10001``; None: start a local Ray).
    """

    workers: int | None = None
    worker_backend: str = "local"
    ray_address: str | None = None

    def check_workers(self, prefix: str = "") -> None:
        """Refuses a negative count, an unknown backend or a missing Ray, before anything runs.

        Args:
            prefix: The options' group on the command line (``rollout.`` for ``run``), as the
                messages name them.
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

        ``reserve_cpus=False``: a pool that runs only while the run's own workers wait (on Ray its
        actors reserve no CPU, so a cluster the size of ``workers`` does not wait on itself).
        """
        from lerobot_mtdagger.runner.ray_workers import make_env_workers

        return make_env_workers(suite, self.worker_count, self.worker_backend, self.ray_address, reserve_cpus)


@dataclass
class RolloutEpisodes:
    """Where a DAgger rollout is cut, and the evaluation episodes (``RolloutConfig`` without its workers).

    Attributes:
        eval_episodes: Evaluation episodes per task after each training phase (None: the preset's).
        max_steps: Steps after which a DAgger rollout is cut (None: the env's own horizon, the one
            evaluation runs to).
        expert_multiple: Cut a DAgger rollout at this multiple of the steps the expert alone takes
            to succeed from the same reset seed (the expert runs that episode first, unrecorded; no
            cut where it fails). None: no such cut. ``max_steps`` still applies.
        steps_after_success: Steps recorded after the first success before an episode ends.
    """

    eval_episodes: int | None = None
    max_steps: int | None = None
    expert_multiple: float | None = None
    steps_after_success: int = 10


@dataclass
class RolloutConfig(WorkerOptions, RolloutEpisodes):
    """Episodes: where a DAgger rollout is cut, evaluation, env workers (``--rollout.*``).

    The options of ``RolloutEpisodes``, then the env workers (``WorkerOptions``): a dataclass takes
    the fields of its last base first, which keeps their order in ``config.json`` and ``--help``.
    """

    def check(self) -> None:
        """Refuses impossible values (one line naming the option)."""
        for name in ("eval_episodes", "steps_after_success"):
            if getattr(self, name) < 0:
                raise ValueError(f"rollout.{name} must be >= 0, got {getattr(self, name)}.")
        _require_positive(self, "rollout", ("max_steps", "expert_multiple"))
        self.check_workers("rollout.")


@dataclass
class ExpertConfig:
    """How far the experts are from perfect (``--expert.*``; ``experts/noise.py`` gives the formula).

    Off by default: the experts act as they are. With ``noise > 0`` every action an expert executes
    gets temporally correlated Gaussian noise, the way a stochastic RL policy acts (the paper's SAC
    and PPO experts succeed on 80-95% of episodes; MetaWorld's scripted ones on about 98%).

    Attributes:
        noise: Standard deviation of the noise on each action component, in action units (actions
            lie in [-1, 1]); 0: no noise.
        noise_by_task: Some tasks' own noise instead of ``noise``, by task name, e.g.
            ``'{assembly-v3: 0.05, reach-v3: 0.6}'`` (one level cannot put every expert at the same
            success). None: ``noise`` for every task.
        noise_correlation: Step-to-step correlation of the noise, in [0, 1) (0: white noise).
        noise_seed: Seed of the noise, apart from ``--seed``.
        labels: What a frame stores as the expert's label: ``noisy`` (the executed action: the
            expert is a stochastic policy) or ``clean`` (the expert's own action: DART-style).
        path: LeRobot policy folders acting on the privileged state (``observation.state``): one
            multitask policy folder, or a folder with one policy folder per task named after it
            (``experts/command_line.py``). None: the registered experts.
        type: An expert factory ``factory(suite, task) -> Expert``: a name registered with
            ``register_expert_type``, or an importable ``module:attribute``. None: the registered experts.
        min_success: Keep only the tasks whose expert (as the run uses it, noise included) succeeds at
            least this often over ``success_episodes`` episodes, measured before round 0 (the paper kept
            the MT50 tasks its SAC experts passed at 80%; ``runner/expert_check.py``). None: every task.
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
        """``suite`` with these experts: the named ones (``path``, ``type``) and their noise.

        Raises:
            UserError: On a path or type that gives no valid expert for every task (one line).
        """
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
        steps_rule: ``fixed`` (``steps_per_round`` steps per phase), ``epochs`` (``epochs`` passes
            over the phase's training frames, at least one step) or ``plateau`` (until the loss on
            held-out episodes stops improving, at most ``plateau_max_steps``; the weights of its
            minimum are kept). ``plateau`` holds ``heldout_fraction`` of each task's episodes out of
            training, BC's and DAgger's alike.
        epochs: Passes over the training frames per phase when ``steps_rule=epochs``.
        plateau_every: Steps between two held-out loss measurements when ``steps_rule=plateau``.
        plateau_patience: Measurements without a new minimum that end a ``plateau`` phase.
        plateau_max_steps: Most steps of a ``plateau`` phase.
        normalisation: ``fixed`` (statistics of round 0's training frames for every phase: a warm
            start sees inputs normalised as before) or ``recompute`` (statistics of D(k) each phase).
        sampling: ``uniform`` (frames uniformly) or ``balanced`` (a task uniformly, then one of its
            frames); None: from the preset (``uniform`` except ``metaworld-pixels``: ``balanced``).
        lr_schedule: ``constant`` or ``cosine`` (the ``mtdagger`` policy's learning rate decayed to 0
            over each phase's steps; a LeRobot student follows its config's scheduler preset).
        gain_split: ``train`` (per-task loss on the training data) or ``heldout`` (on held-out episodes).
        heldout_fraction: Fraction of each task's episodes held out of training when
            ``gain_split=heldout`` or ``steps_rule=plateau`` (decided once per episode, so an
            episode never changes side; a task's first episode is always trained on).
        seed: Seed of the phases' initial weights, batch order and task dropout, where it is to
            differ from the run's ``--seed`` (which keeps every other draw: the episodes collected,
            evaluated and held out). A BC run repeated with other training seeds trains on the very
            same data: the spread between trainings, apart from the data's. None: ``--seed``.
    """

    steps_per_round: int | None = None
    warm_start: bool = True
    steps_rule: str = "fixed"
    epochs: float = 100.0
    plateau_every: int = 200
    plateau_patience: int = 5
    plateau_max_steps: int = 20_000
    normalisation: str = "fixed"
    sampling: str | None = None
    lr_schedule: str = "constant"
    gain_split: str = "train"
    heldout_fraction: float = 0.2
    seed: int | None = None

    def check(self) -> None:
        """Refuses impossible values (one line naming the option)."""
        positive = ("steps_per_round", "epochs", "plateau_every", "plateau_patience", "plateau_max_steps")
        _require_positive(self, "training", positive)
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


@dataclass
class RunConfig:
    """Options of ``lerobot-mtdagger run`` (one Multitask DAgger experiment, or the BC baseline).

    Thirteen top-level options; the rest sit in their group (``--suite.obs_mode``, ``--dagger.rounds``,
    ``--rollout.eval_episodes``, ``--training.steps_rule``, ``--policy.lr``, ``--scheduler.n_min``).
    A flat config stored before the groups existed is migrated on reading
    (``datasets/config_layout.py``), and the old spellings are refused with the new one named.

    Attributes:
        preset: One of ``PRESETS``; fills every option of ``PRESET_FIELDS`` left unset (None).
        mode: ``dagger`` (Algorithm 1 with ``scheduler``) or ``bc``: ONE round of expert
            demonstrations with the same data budget (``initial_demos + rounds * budget / num_tasks``
            per task, split uniformly), trained like a DAgger phase (``phase_steps``); the scheduler
            is unused.
        suite: The suite and its observations (``SuiteConfig``; shared with ``eval``, ``shift`` and
            the LeRobot env plugin).
        dagger: Rounds, demo budgets and beta (``DAggerConfig``).
        rollout: Episode cuts, evaluation episodes and env workers (``RolloutConfig``).
        training: Steps per phase, sampling, held-out split (``TrainingConfig``).
        scheduler: ``--scheduler.type=uniform|need|need_raw|gain`` and its hyperparameters
            (``scheduler.n_min`` from the preset when unset).
        expert: The experts' quality: noise on their actions, and which action is the label
            (``ExpertConfig``; off by default).
        policy: The student and its options: ``--policy.type=mtdagger`` (default; ``PolicyOptions``)
            or a LeRobot policy (``act``, ``diffusion``) with LeRobot's own options plus
            ``batch_size`` (``StudentOptions``). ``policy.batch_size`` (and for ``mtdagger``
            ``policy.lr``) come from the preset when unset.
        output_dir: Experiment directory (refused if it exists, unless ``resume``); default
            ``outputs/mtdagger/<preset>-<method>-seed<seed>``.
        seed: Seed of everything (collection, evaluation, training).
        resume: Continue the experiment in ``output_dir`` from its last committed round.
        progress: Show progress bars (only on a terminal); the summary line of each round is
            always printed.
    """

    preset: str = "small"
    mode: str = "dagger"
    suite: SuiteConfig = field(default_factory=SuiteConfig)
    dagger: DAggerConfig = field(default_factory=DAggerConfig)
    rollout: RolloutConfig = field(default_factory=RolloutConfig)
    training: TrainingConfig = field(default_factory=TrainingConfig)
    scheduler: SchedulerConfig = field(default_factory=NeedSchedulerConfig)
    policy: StudentOptions = field(default_factory=PolicyOptions)
    expert: ExpertConfig = field(default_factory=ExpertConfig)
    output_dir: Path | None = None
    seed: int = 0
    resume: bool = False
    progress: bool = True

    @staticmethod
    def help_choices(options: Sequence[str]) -> Any:
        """``--help``'s view of the student choices: LeRobot's named, described only when asked for."""
        asked = names_lerobot_student(options)

        def choices(group_class: type) -> dict[str, type | None] | None:
            if group_class is not StudentOptions:
                return None
            if asked:
                return dict(StudentOptions.get_known_choices())
            return {"mtdagger": PolicyOptions, **dict.fromkeys(LEROBOT_STUDENT_TYPES)}

        return choices

    @staticmethod
    def parsing_context(options: Sequence[str]) -> contextlib.AbstractContextManager[None]:
        """What ``parse_options`` parses these options under (``students_for``)."""
        return students_for(options)

    def __post_init__(self) -> None:
        if self.preset not in PRESETS:
            raise ValueError(f"Unknown preset {self.preset!r}; presets: {list(PRESETS)}.")
        if self.mode not in RUN_MODES:
            raise ValueError(f"Unknown mode {self.mode!r}; choose one of {list(RUN_MODES)}.")
        for path, value in PRESETS[self.preset].items():
            owner, name = self._field_owner(path)
            if not hasattr(owner, name):  # policy.lr: a LeRobot student's is its optimizer_lr
                continue
            if getattr(owner, name) is None:
                setattr(owner, name, value)
        if self.output_dir is None:
            self.output_dir = Path("outputs") / "mtdagger" / f"{self.preset}-{self.method}-seed{self.seed}"
        self.suite.fill_defaults()
        self._check()

    def _field_owner(self, path: str) -> tuple[Any, str]:
        """The object holding the option ``path`` (``policy.lr`` -> (self.policy, "lr"))."""
        *parents, name = path.split(".")
        owner: Any = self
        for parent in parents:
            owner = getattr(owner, parent)
        return owner, name

    def _check(self) -> None:
        if self.seed < 0:
            raise ValueError(f"seed must be >= 0, got {self.seed}.")
        self.suite.check()
        self.dagger.check()
        self.rollout.check()
        self.training.check()
        self.expert.check()
        lr_name = "lr" if isinstance(self.policy, PolicyOptions) else "optimizer_lr"
        lr = getattr(self.policy, lr_name)
        if self.policy.batch_size <= 0 or not (math.isfinite(lr) and lr > 0):
            raise ValueError(
                f"policy.batch_size and policy.{lr_name} must be finite and > 0, "
                f"got {self.policy.batch_size}, {lr}."
            )
        check_device(self.policy.device)
        check_output_dir(self.output_dir, "--output_dir")
        self._check_student()

    def _check_student(self) -> None:
        """Refuses what a LeRobot student cannot do here: point clouds, temporal ensembling, ignored options.

        The options are those of its LeRobot config the runner would ignore (``UNSUPPORTED_STUDENT_OPTIONS``).
        """
        if self.student_type == "mtdagger":
            return
        for name, reason in UNSUPPORTED_STUDENT_OPTIONS.items():
            if getattr(self.policy, name, None) not in (None, False):
                raise ValueError(f"--policy.{name} is not supported by run: {reason}; drop the option.")
        if self.training.lr_schedule != "constant":
            raise ValueError(
                f"--training.lr_schedule={self.training.lr_schedule} is for the mtdagger policy; "
                f"--policy.type={self.student_type} follows its own scheduler preset: drop the option."
            )
        if self.suite.obs_mode == "pointcloud":
            raise ValueError(
                f"--policy.type={self.student_type} cannot read point clouds (a LeRobot policy takes "
                "state and images): use --policy.type=mtdagger or --suite.obs_mode=state|rgb."
            )
        if getattr(self.policy, "temporal_ensemble_coeff", None) is not None:
            raise ValueError(
                "--policy.temporal_ensemble_coeff is not supported for a DAgger student (its action "
                "queue is kept per episode): drop it and set --policy.n_action_steps instead."
            )

    @property
    def student_type(self) -> str:
        """``--policy.type``: ``mtdagger`` or a LeRobot policy type."""
        return student_type(self.policy)

    @property
    def is_bc(self) -> bool:
        """Whether this run is the one-round behaviour-cloning baseline."""
        return self.mode == "bc"

    @property
    def method(self) -> str:
        """The experiment's method as reports name it: ``bc`` or the scheduling method."""
        return "bc" if self.is_bc else self.scheduler.type

    @property
    def training_seed(self) -> int:
        """The seed of every training draw: ``--training.seed``, or the run's ``--seed`` when unset."""
        return self.seed if self.training.seed is None else self.training.seed

    def phase_steps(self, frames: int) -> int:
        """Optimiser steps of one training phase on ``frames`` training frames.

        A DAgger phase takes ``steps_per_round`` steps (``steps_rule=fixed``) or ``epochs`` passes
        over its frames (``steps_rule=epochs``), or at most ``plateau_max_steps`` (``steps_rule=plateau``:
        the held-out loss ends it sooner). BC trains once, on its final data, by the same rule,
        except with fixed steps and a warm start: the final DAgger policy has then taken
        ``(rounds + 1) * steps_per_round`` steps in all, and so does BC.
        """
        training = self.training
        if training.steps_rule == "plateau":
            return training.plateau_max_steps
        if training.steps_rule == "epochs":
            return max(1, math.ceil(training.epochs * frames / self.policy.batch_size))
        if self.is_bc and training.warm_start:
            return training.steps_per_round * (self.dagger.rounds + 1)
        return training.steps_per_round

    @classmethod
    def option_defaults(cls) -> dict[str, Any]:
        """What each option was before it existed, by dotted path (e.g. ``training.plateau_every: 200``).

        Its plain default, except ``suite.placement`` (drawer runs made before it existed used
        ``narrow``) and ``training.sampling`` (``uniform`` before presets filled it). Policy options
        are those of ``mtdagger`` (the only student then).
        """
        defaults: dict[str, Any] = {}
        for group, options in (
            ("suite", SuiteConfig),
            ("dagger", DAggerConfig),
            ("rollout", RolloutConfig),
            ("training", TrainingConfig),
            ("policy", PolicyOptions),
            ("expert", ExpertConfig),
        ):
            for option in dataclasses.fields(options):
                if option.default is not dataclasses.MISSING:
                    defaults[f"{group}.{option.name}"] = option.default
        top = {f.name: f.default for f in dataclasses.fields(cls) if f.default is not dataclasses.MISSING}
        return top | defaults | {"suite.placement": LEGACY_PLACEMENT, "training.sampling": "uniform"}

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (stored in every round's record; ``migrate_run_config``'s layout)."""
        record = dataclasses.asdict(self)
        record["policy"] = policy_options_dict(self.policy)
        record["output_dir"] = str(self.output_dir)
        record["scheduler"] = {"type": self.scheduler.type, **self.scheduler.hyperparameters()}
        return record


def policy_options_dict(options: Any) -> dict[str, Any]:
    """JSON-ready policy options: ``mtdagger``'s fields as before (no ``type``), else type + LeRobot's."""
    if isinstance(options, PolicyOptions):
        return dataclasses.asdict(options)
    import draccus

    encoded = draccus.encode(lerobot_policy_config(options))
    return {"type": student_type(options), "batch_size": options.batch_size, **encoded}


def check_device(device: str) -> None:
    """Refuses a torch device this machine does not have, before anything runs.

    Raises:
        ValueError: Naming the device and the devices there are.
    """
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
    """The env worker count an option asks for: one per core for None, else ``workers``.

    Raises:
        ValueError: If ``workers`` is negative.
    """
    if workers is not None and workers < 0:
        raise ValueError(f"workers must be >= 0 (0: envs in the main process), got {workers}.")
    return default_worker_count() if workers is None else workers


def default_worker_count() -> int:
    """One env worker per core this process may run on."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


RUN_OPTION_RENAMES: dict[str, str] = FLAT_OPTION_PATHS
"""``run``'s (and ``compare``'s run) options before they were grouped, and their spelling today."""
SUITE_OPTION_RENAMES: dict[str, str] = {
    old: new for old, new in FLAT_OPTION_PATHS.items() if new.startswith("suite.")
}
"""``eval``'s and ``shift``'s suite options before ``SuiteConfig``, and their spelling today."""


def renamed_option_error(args: Sequence[str], renames: Mapping[str, str] | None = None) -> str | None:
    """A message naming the new spelling when ``args`` use an option that was renamed (else None).

    ``--scheduler.type=bc`` became ``--mode=bc`` (BC is a run mode, not a scheduler), ``--n_min``
    became ``--scheduler.n_min`` (one home per option), and each option of ``renames`` (the
    command's grouped options: ``--obs_mode`` became ``--suite.obs_mode``) its new path.
    """
    for arg in args:
        name, _, value = arg.partition("=")
        if name == "--scheduler.type" and value == "bc":
            return (
                "--scheduler.type=bc is no longer accepted: behaviour cloning is a run mode, "
                "use --mode=bc (the scheduler is then unused)."
            )
        if name == "--n_min":
            return f"--n_min is no longer accepted: use --scheduler.n_min={value or '<n>'}."
        new = (renames or {}).get(name.removeprefix("--")) if name.startswith("--") else None
        if new is not None:
            given = f"={value}" if value else ""
            return (
                f"{name} is now --{new} (options are grouped: suite, dagger, rollout, training; the "
                f"README's changelog lists every rename): use --{new}{given}."
            )
    return None
