"""The options of ``lerobot-mtdagger run`` (``RunConfig``, draccus), their checks and their older names.

An option a preset fills (``presets.PRESET_FIELDS``) is None until the preset fills it, so a value
given on the command line always wins. The groups live in ``option_groups`` and ``policy_options``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast

from lerobot_mtdagger.datasets.migrations import FLAT_OPTION_PATHS, former_option_values
from lerobot_mtdagger.envs.config import SuiteConfig
from lerobot_mtdagger.runner.option_groups import (
    RUN_MODES,
    DAggerConfig,
    ExpertConfig,
    RolloutConfig,
    TrainingConfig,
    check_device,
)
from lerobot_mtdagger.runner.policy_options import (
    PolicyOptions,
    StudentOptions,
    names_lerobot_student,
    policy_options_dict,
    students_for,
)
from lerobot_mtdagger.runner.presets import PRESETS, preset_values
from lerobot_mtdagger.runner.student import Student, student_names, student_of_options
from lerobot_mtdagger.scheduler import NeedSchedulerConfig, SchedulerConfig
from lerobot_mtdagger.utils.parsing import cache_dataclass_sources
from lerobot_mtdagger.utils.paths import check_output_dir

cache_dataclass_sources()  # draccus.parse(RunConfig) in 0.1 s instead of 2-3 s (utils/parsing.py)


@dataclass
class RunConfig:
    """Options of ``lerobot-mtdagger run`` (one Multitask DAgger experiment, or the BC baseline).

    A flat config of an older layout is migrated on reading (``datasets/migrations.py``); the old
    spellings are refused with the new one named.

    Attributes:
        preset: One of ``PRESETS``; fills every option of ``PRESET_FIELDS`` left unset (None).
        mode: ``dagger`` (Algorithm 1 with ``scheduler``) or ``bc``: ONE round of expert demonstrations
            with the same data budget (``initial_demos + rounds * budget / num_tasks`` per task), trained
            like a DAgger phase; the scheduler is unused.
        suite: The suite and its observations (``SuiteConfig``).
        dagger: Rounds, demo budgets and beta (``DAggerConfig``).
        rollout: Episode cuts, evaluation episodes and env workers (``RolloutConfig``).
        training: Steps per phase, sampling, held-out split (``TrainingConfig``).
        scheduler: The allocation method (``--scheduler.type``) and its hyperparameters.
        expert: The experts' quality: noise on their actions, which action is the label (``ExpertConfig``).
        policy: The student and its options: ``--policy.type=mtdagger`` (default; ``PolicyOptions``) or a
            LeRobot policy (``act``, ``diffusion``) with LeRobot's own options plus ``batch_size``.
        output_dir: Experiment directory (refused if it exists, unless ``resume``); default
            ``outputs/mtdagger/<preset>-<method>-seed<seed>``.
        seed: Seed of everything (collection, evaluation, training).
        resume: Continue the experiment in ``output_dir`` from its last committed round.
        progress: Show progress bars (only on a terminal); each round's summary line is always printed.
    """

    preset: str = "small"
    mode: str = "dagger"
    suite: SuiteConfig = field(default_factory=SuiteConfig)
    dagger: DAggerConfig = field(default_factory=DAggerConfig)
    rollout: RolloutConfig = field(default_factory=RolloutConfig)
    training: TrainingConfig = field(default_factory=TrainingConfig)
    scheduler: SchedulerConfig = field(default_factory=NeedSchedulerConfig)
    policy: StudentOptions = field(default_factory=cast("Callable[[], StudentOptions]", PolicyOptions))
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
            return {**dict.fromkeys(student_names()), "mtdagger": PolicyOptions}

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
        for path, value in preset_values(self.preset, self.mode).items():
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
        lr_name = self.student.lr_option
        lr = getattr(self.policy, lr_name)
        if self.policy.batch_size <= 0 or not (math.isfinite(lr) and lr > 0):
            raise ValueError(
                f"policy.batch_size and policy.{lr_name} must be finite and > 0, "
                f"got {self.policy.batch_size}, {lr}."
            )
        check_device(self.policy.device)
        assert self.output_dir is not None  # __post_init__ fills it
        check_output_dir(self.output_dir, "--output_dir")
        self.student.check_run(self)

    @property
    def student(self) -> Student:
        """The student of ``--policy.type`` (``runner.student``)."""
        return student_of_options(self.policy)

    @property
    def student_type(self) -> str:
        """``--policy.type``: ``mtdagger``, a LeRobot policy type or another registered student."""
        return self.student.name

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
        """Optimiser steps of one training phase on ``frames`` training frames (by ``steps_rule``).

        BC trains once, on its final data, by the same rule; with fixed steps and a warm start it takes
        ``(rounds + 1) * steps_per_round`` steps, as the final DAgger policy has in all.
        """
        training = self.training
        if training.steps_rule == "plateau":
            return training.plateau_max_steps
        if training.steps_rule == "epochs":
            assert training.epochs is not None  # filled by the preset
            return max(1, math.ceil(training.epochs * frames / self.policy.batch_size))
        assert training.steps_per_round is not None  # filled by the preset
        if self.is_bc and training.warm_start:
            assert self.dagger.rounds is not None  # filled by the preset
            return training.steps_per_round * (self.dagger.rounds + 1)
        return training.steps_per_round

    @classmethod
    def option_defaults(cls) -> dict[str, Any]:
        """Each option's value for runs stored without it, by dotted path (``training.plateau_every: 200``).

        Its plain default, unless a migration names another (``migrations.former_option_values``).
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
        return top | defaults | former_option_values()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (stored in every round's record; ``migrate_run_config``'s layout)."""
        record = dataclasses.asdict(self)
        record["policy"] = policy_options_dict(self.policy)
        record["output_dir"] = str(self.output_dir)
        record["scheduler"] = {"type": self.scheduler.type, **self.scheduler.hyperparameters()}
        return record


RUN_OPTION_RENAMES: dict[str, str] = FLAT_OPTION_PATHS
"""``run``'s (and ``compare``'s) ungrouped option names, and their grouped spelling."""


SUITE_OPTION_RENAMES: dict[str, str] = {
    old: new for old, new in FLAT_OPTION_PATHS.items() if new.startswith("suite.")
}
"""``eval``'s and ``shift``'s ungrouped suite option names, and their ``--suite.*`` spelling."""


def renamed_option_error(args: Sequence[str], renames: Mapping[str, str] | None = None) -> str | None:
    """A message naming the new spelling when ``args`` use a renamed option (else None).

    Covers ``--scheduler.type=bc`` (now ``--mode=bc``), ``--n_min`` (now ``--scheduler.n_min``) and
    each option of ``renames``.
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
