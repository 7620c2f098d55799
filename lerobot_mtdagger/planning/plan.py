"""``lerobot-mtdagger plan``: the next collection session's episodes per task, from LeRobot datasets.

One ``plan`` is one scheduler round: this session's measurements (each task's success over the
episodes where the policy acted alone, ``episodes.py``) update the scheduler carried over from the
previous plan file, and the budget is split across tasks with the run's own code
(``lerobot_mtdagger.scheduler``). The plan file keeps:

- ``tasks``: the task set, in order (fixed by the first plan; every later plan must have the same);
- ``inputs``: every dataset read (source, local root, revision, a checksum of its files) and each of
  its episodes' task, success and whether the policy acted alone;
- ``previous``: the previous plan file's path and sha256 (None for the first plan);
- ``state_before`` and ``state``: the scheduler before and after this session's measurements;
- ``budget`` and ``allocation`` (``Allocation.to_dict``: measurements, Kalman state, scores, counts).

``plan --verify=PLAN`` re-reads the recorded datasets (naming any that changed since), recomputes the
measurements and the allocation from ``state_before``, and checks the previous plan's hash.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast

import numpy as np

from lerobot_mtdagger.planning.episodes import (
    INTERVENTION_KEY,
    DatasetEpisodes,
    check_dataset_source,
    dataset_checksum,
    read_dataset,
)
from lerobot_mtdagger.scheduler import (
    DEMOS,
    GAIN,
    NeedSchedulerConfig,
    Scheduler,
    SchedulerConfig,
    allocation_mismatches,
)
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.paths import check_input_path, check_output_file

PLAN_FORMAT = "lerobot-mtdagger-plan"
PLAN_VERSION = 1
PLAN_FILE_TAKES = "the plan file an earlier `plan --output` wrote"
"""What ``--previous`` and ``--verify`` take, for messages."""


@dataclass
class PlanConfig:
    """Options of ``lerobot-mtdagger plan``: the next session's episodes per task, from LeRobot datasets.

    Attributes:
        datasets: LeRobot datasets of this session's policy episodes: local folders or Hub repo ids
            (``lerobot-rollout``/``lerobot-eval``/``lerobot-record`` datasets, or a run's rounds).
        output: The plan file to write (never overwritten).
        previous: The previous session's plan file: its scheduler state is continued and its task set
            kept. None: the first plan.
        tasks: The tasks to plan, in order (first plan only); empty: every task in the datasets, sorted.
        budget: Episodes to hand out.
        budget_minutes: Operator minutes to hand out instead (with each task's episode length).
        episode_seconds: Seconds per episode (every task) for ``budget_minutes``; None: each task's
            mean episode duration in the datasets.
        success_key: The success column (a frame column, or one of ``meta/episodes``); None:
            ``next.success`` in the frames, else ``success`` in ``meta/episodes``.
        success_labels: A JSON file of the operator's success labels, ``{dataset: {episode: true|false}}``
            (keyed by the dataset as given in ``--datasets``): LeRobot's rollouts on a real robot record
            no success. Datasets it does not name are read from their columns.
        intervention_key: The column marking frames a person controlled (episodes with any are not
            counted as the policy's); a dataset without it has only policy episodes.
        scheduler: ``--scheduler.type=need|need_raw|gain|uniform|learnability|curve`` and its
            hyperparameters (as ``run``).
        policy_path: The policy trained since the last session (a LeRobot pretrained folder): with
            ``previous_policy_path``, each task's performance gain, ``max(0, L_previous - L_policy)``
            over ``loss_datasets`` (``planning/loss.py``); needed by ``--scheduler.type=gain``.
        previous_policy_path: The policy before that training (the one that collected the session).
        loss_datasets: The training datasets the losses are measured on (empty: ``datasets``).
        verify: A plan file to check instead: recomputed from its recorded inputs.
        initial_demos: Expert demos per task the first session's policy was trained on (first plan of a
            scheduler that fits learning curves, ``--scheduler.type=curve``; later plans add each plan's
            episodes to it).
        unverified: Read rounds and policies of an experiment that fails verification, or a policy
            folder that differs from the checksums its ``training.json`` carries, as they are (with a
            warning; the plan lists the problems under ``unverified``); by default they are refused.
    """

    datasets: list[str] = field(default_factory=list)
    output: Path | None = None
    previous: Path | None = None
    tasks: list[str] = field(default_factory=list)
    budget: int | None = None
    budget_minutes: float | None = None
    episode_seconds: float | None = None
    success_key: str | None = None
    success_labels: Path | None = None
    intervention_key: str = INTERVENTION_KEY
    scheduler: SchedulerConfig = field(default_factory=NeedSchedulerConfig)
    policy_path: Path | None = None
    previous_policy_path: Path | None = None
    loss_datasets: list[str] = field(default_factory=list)
    verify: Path | None = None
    initial_demos: int | None = None
    unverified: bool = False

    def __post_init__(self) -> None:
        if self.verify is not None:
            return
        if not self.datasets:
            raise ValueError(
                "--datasets is required: the LeRobot datasets of this session's policy episodes."
            )
        if self.output is None:
            raise ValueError(
                "--output is required: the plan file to write (e.g. --output=plans/session-03.json)."
            )
        if self.output.exists():
            raise ValueError(f"--output={self.output} exists: plans are never overwritten; give a new path.")
        check_output_file(self.output, "--output")
        if (self.budget is None) == (self.budget_minutes is None):
            raise ValueError("Give one budget: --budget=<episodes> or --budget_minutes=<operator minutes>.")
        if self.budget is not None and self.budget <= 0:
            raise ValueError(f"--budget must be > 0 episodes, got {self.budget}.")
        if self.budget_minutes is not None and not (
            math.isfinite(self.budget_minutes) and self.budget_minutes > 0
        ):
            raise ValueError(f"--budget_minutes must be > 0, got {self.budget_minutes}.")
        if self.episode_seconds is not None and not (self.episode_seconds > 0):
            raise ValueError(f"--episode_seconds must be > 0, got {self.episode_seconds}.")
        if self.previous is not None and self.tasks:
            raise ValueError(
                "--tasks is for a first plan; a later plan keeps --previous's tasks: drop --tasks."
            )
        if (self.policy_path is None) != (self.previous_policy_path is None):
            raise ValueError(
                "The performance gain compares two policies: give --policy_path (trained since the last "
                "session) and --previous_policy_path (the one before), or neither."
            )
        if self.initial_demos is not None and self.initial_demos < 0:
            raise ValueError(f"--initial_demos must be >= 0 expert demos per task, got {self.initial_demos}.")
        if DEMOS in self.scheduler.measurements and self.previous is None and self.initial_demos is None:
            raise ValueError(
                f"--scheduler.type={self.scheduler.type} fits each task's learning curve: give "
                "--initial_demos (the expert demos per task the policy of this first session was trained on)."
            )
        if GAIN in self.scheduler.measurements and self.policy_path is None:
            raise ValueError(
                f"--scheduler.type={self.scheduler.type} needs each task's loss drop: give --policy_path, "
                "--previous_policy_path and --loss_datasets (the data the policy was trained on)."
            )

    def check_paths(self) -> None:
        """Refuses an input that is not there: a plan file, the labels, a policy folder, a dataset.

        A dataset given by repo id is looked up on the Hub unless LeRobot's cache holds it
        (``episodes.check_dataset_source``).

        Raises:
            UserError: In one line naming the option, the path and the fix.
        """
        if self.verify is not None:
            check_input_path(self.verify, "--verify", PLAN_FILE_TAKES)
            return
        for option, path, takes in (
            ("--previous", self.previous, PLAN_FILE_TAKES),
            ("--success_labels", self.success_labels, "the JSON file of success labels"),
            ("--policy_path", self.policy_path, "the policy folder trained since the last session"),
            ("--previous_policy_path", self.previous_policy_path, "the policy folder of the last session"),
        ):
            if path is not None:
                check_input_path(path, option, takes)
        for option, sources in (("--datasets", self.datasets), ("--loss_datasets", self.loss_datasets)):
            for source in sources:
                check_dataset_source(source, option)


@dataclass(frozen=True)
class Measurements:
    """One session's per-task counts (aligned with the plan's tasks)."""

    episodes: list[int]
    policy_episodes: list[int]
    successes: list[int]
    seconds: list[float | None]

    @property
    def success_rate(self) -> list[float]:
        """Success over the policy's own episodes (NaN where it had none)."""
        return [s / n if n else math.nan for s, n in zip(self.successes, self.policy_episodes, strict=True)]


def measure(read: Sequence[DatasetEpisodes], tasks: Sequence[str]) -> Measurements:
    """Counts each task's episodes, the policy's own, their successes and mean duration."""
    position = {task: i for i, task in enumerate(tasks)}
    episodes, policy, successes = [0] * len(tasks), [0] * len(tasks), [0] * len(tasks)
    seconds: list[list[float]] = [[] for _ in tasks]
    for dataset in read:
        for task, success, alone, duration in zip(
            dataset.tasks, dataset.success, dataset.policy_only, dataset.seconds, strict=True
        ):
            i = position[task]
            episodes[i] += 1
            seconds[i].append(duration)
            if alone:
                policy[i] += 1
                successes[i] += int(success)
    mean_seconds = [float(np.mean(s)) if s else None for s in seconds]
    return Measurements(episodes, policy, successes, mean_seconds)


def read_labels(path: Path | None, sources: Sequence[str]) -> dict[str, dict[int, bool]]:
    """The operator's success labels by dataset (empty without a file); refuses a bad file (one line)."""
    if path is None:
        return {}
    if not path.is_file():
        raise UserError(f"--success_labels={path} does not exist: give the JSON file of success labels.")
    try:
        raw = json.loads(path.read_text())
        labels = {
            str(source): {int(episode): _label(value) for episode, value in episodes.items()}
            for source, episodes in raw.items()
        }
    except (json.JSONDecodeError, AttributeError, TypeError, ValueError):
        raise UserError(
            f"--success_labels={path} is not {{dataset: {{episode: true|false}}}} JSON: write one object per "
            "dataset (as given in --datasets) mapping each episode index to true or false."
        ) from None
    unknown = sorted(set(labels) - set(sources))
    if unknown:
        raise UserError(
            f"--success_labels={path} labels {', '.join(unknown)}, not one of --datasets: key each dataset "
            "as --datasets gives it."
        )
    return labels


def _label(value: object) -> bool:
    """One success label: true or false (1 and 0 accepted)."""
    if isinstance(value, bool) or value in (0, 1):
        return bool(value)
    raise ValueError(f"not a success label: {value!r}")


def read_all(config: PlanConfig) -> list[DatasetEpisodes]:
    """Every dataset's episodes, with the operator's labels where given."""
    labels = read_labels(config.success_labels, config.datasets)
    return [
        read_dataset(source, config.success_key, config.intervention_key, labels.get(source))
        for source in config.datasets
    ]


def plan_tasks(config: PlanConfig, read: Sequence[DatasetEpisodes], previous: dict | None) -> list[str]:
    """The plan's tasks; refuses a task set that does not match the datasets (one line)."""
    seen = sorted({task for dataset in read for task in dataset.tasks})
    tasks = list(previous["tasks"]) if previous is not None else (list(config.tasks) or seen)
    foreign = [task for task in seen if task not in tasks]
    if foreign:
        where = f"the previous plan {config.previous}" if previous is not None else "--tasks"
        raise UserError(
            f"The datasets have episodes of {', '.join(foreign)}, not a task of {where} "
            f"({', '.join(tasks)}): start a new plan for this task set (no --previous), or leave those "
            "datasets out."
        )
    empty = [task for task in tasks if task not in seen]
    if empty:
        raise UserError(
            f"No episodes of {', '.join(empty)} in the datasets: the plan needs this session's policy "
            "episodes on every task (roll the policy out on it), or a new plan without it (--tasks)."
        )
    return tasks


def measure_gain(config: PlanConfig, tasks: Sequence[str]) -> dict | None:
    """Each task's loss before and after training and their drop (None without the two policies)."""
    if config.policy_path is None or config.previous_policy_path is None:
        return None
    from lerobot_mtdagger.planning.loss import dataset_inputs, per_task_loss, policy_inputs

    sources = list(config.loss_datasets) or list(config.datasets)
    before, frames = per_task_loss(config.previous_policy_path, sources, tasks)
    after, _ = per_task_loss(config.policy_path, sources, tasks)
    return {
        "previous_policy": policy_inputs(config.previous_policy_path),
        "policy": policy_inputs(config.policy_path),
        "loss_datasets": dataset_inputs(sources),
        "loss_previous": before,
        "loss": after,
        "frames": frames,
        "gain": loss_drop(before, after),
    }


def loss_drop(before: Sequence[float | None], after: Sequence[float | None]) -> list[float]:
    """``max(0, before - after)`` per task (0 where a task has no frame)."""
    return [
        max(0.0, b - a) if b is not None and a is not None else 0.0
        for b, a in zip(before, after, strict=True)
    ]


def episode_budget(config: PlanConfig, scheduler: Scheduler, seconds: Sequence[float]) -> int:
    """``--budget``, or the most episodes whose allocation fits in ``--budget_minutes``."""
    if config.budget is not None:
        return int(config.budget)
    assert config.budget_minutes is not None  # PlanConfig refuses neither budget given
    available = float(config.budget_minutes) * 60.0
    n_min = scheduler.config.min_episodes
    if n_min * sum(seconds) > available:
        raise UserError(
            f"--budget_minutes={config.budget_minutes} does not cover n_min={n_min} episode(s) per task "
            f"({n_min * sum(seconds) / 60:.1f} min): raise it or lower --scheduler.n_min."
        )
    budget = max(n_min * len(seconds), 1)
    most = int(available // min(seconds))  # no allocation of more episodes can fit
    while budget < most and _minutes(scheduler, budget + 1, seconds) * 60.0 <= available:
        budget += 1
    return budget


def _minutes(scheduler: Scheduler, budget: int, seconds: Sequence[float]) -> float:
    """Operator minutes of the allocation of ``budget`` episodes."""
    counts = scheduler.allocate(budget).episodes_per_task
    return sum(n * s for n, s in zip(counts, seconds, strict=True)) / 60.0


def task_seconds(config: PlanConfig, measured: Measurements) -> list[float]:
    """Seconds per episode of each task: ``--episode_seconds`` or the datasets' mean duration."""
    if config.episode_seconds is not None:
        return [float(config.episode_seconds)] * len(measured.seconds)
    # plan_tasks guarantees episodes on every task, so no mean duration is None
    return [float(s) for s in cast("list[float]", measured.seconds)]


def file_sha256(path: Path) -> str:
    """sha256 of a file's bytes."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def read_plan(path: Path) -> dict:
    """A plan file's contents; refuses a file that is not one (one line)."""
    if not path.is_file():
        raise UserError(f"{path} does not exist: give {PLAN_FILE_TAKES}.")
    try:
        plan = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError):
        plan = None
    if not isinstance(plan, dict) or plan.get("format") != PLAN_FORMAT:
        raise UserError(f"{path} is not a plan file (written by `lerobot-mtdagger plan --output`).")
    if plan.get("version") != PLAN_VERSION:
        raise UserError(
            f"{path} is a plan of version {plan.get('version')}; this version reads {PLAN_VERSION}."
        )
    return plan


def continued_scheduler(config: PlanConfig, tasks: Sequence[str], previous: dict | None) -> Scheduler:
    """The scheduler: the previous plan's, continued, or a new one from ``--scheduler``."""
    if previous is None:
        return Scheduler(config.scheduler, len(tasks))
    state = previous["state"]
    if state["method"] != config.scheduler.type:
        raise UserError(
            f"The previous plan used --scheduler.type={state['method']}; this one asks for "
            f"{config.scheduler.type}: keep the method, or start a new plan (no --previous)."
        )
    scheduler = Scheduler(config.scheduler, len(tasks))
    scheduler.load_state_dict(state)
    return scheduler


def checked_inputs(config: PlanConfig) -> list[str]:
    """Checks the experiment rounds and policy folders the plan reads, as every reader checks them.

    A round dataset or policy folder of an experiment checks its experiment once
    (``check_before_reading``); a policy folder elsewhere checks the checksums it carries
    (``check_policy_folder``). Other datasets (LeRobot's, Hub ids) are read as they are.

    Returns:
        The problems read past with ``--unverified=true`` (else empty).

    Raises:
        CorruptExperimentError: In one line naming what changed and the fix.
    """
    from lerobot_mtdagger.datasets.verify import check_before_reading, check_policy_folder, experiment_of
    from lerobot_mtdagger.runner.configs import RunConfig

    defaults = RunConfig.option_defaults()
    policies = [Path(p) for p in (config.policy_path, config.previous_policy_path) if p is not None]
    datasets = [Path(source) for source in [*config.datasets, *config.loss_datasets]]
    problems, seen = [], set()
    for folder in [path for path in [*datasets, *policies] if path.is_dir()]:
        experiment = experiment_of(folder)
        key = (experiment.root if experiment is not None else folder).resolve()
        if key in seen:
            continue
        seen.add(key)
        if experiment is not None:
            problems += check_before_reading(experiment, config.unverified, defaults)
        elif folder in policies:
            problems += check_policy_folder(folder, config.unverified, defaults)
    return problems


def make_plan(config: PlanConfig) -> dict:
    """Reads the datasets, updates the scheduler, allocates; returns the plan (not yet written)."""
    unverified = checked_inputs(config)
    previous = read_plan(config.previous) if config.previous is not None else None
    read = read_all(config)
    tasks = plan_tasks(config, read, previous)
    scheduler = continued_scheduler(config, tasks, previous)
    state_before = scheduler.state_dict()
    measured = measure(read, tasks)
    gain_record = measure_gain(config, tasks)
    demos = session_demos(config, len(tasks), previous)
    if demos is None and DEMOS in scheduler.config.measurements:
        raise UserError(
            f"The previous plan {config.previous} records no expert demos per task, which "
            f"--scheduler.type={scheduler.method} needs: start a new plan (no --previous) with "
            "--initial_demos."
        )
    scheduler.update(
        success_rate=measured.success_rate,
        episodes=measured.policy_episodes,
        gain=None if gain_record is None else gain_record["gain"],
        **_demos_measurement(demos),
    )
    seconds = task_seconds(config, measured)
    budget = episode_budget(config, scheduler, seconds)
    allocation = scheduler.allocate(budget)
    minutes = [n * s / 60.0 for n, s in zip(allocation.episodes_per_task, seconds, strict=True)]
    plan = {
        "format": PLAN_FORMAT,
        "version": PLAN_VERSION,
        "tasks": list(tasks),
        "session": 0 if previous is None else int(previous["session"]) + 1,
        "previous": None
        if config.previous is None
        else {"path": str(config.previous), "sha256": file_sha256(config.previous)},
        "options": {
            "success_key": config.success_key,
            "success_labels": None
            if config.success_labels is None
            else {"path": str(config.success_labels), "sha256": file_sha256(config.success_labels)},
            "intervention_key": config.intervention_key,
            "budget": config.budget,
            "budget_minutes": config.budget_minutes,
            "episode_seconds": config.episode_seconds,
        },
        "inputs": [dataset.to_dict() for dataset in read],
        "measurements": {
            "episodes": measured.episodes,
            "policy_episodes": measured.policy_episodes,
            "successes": measured.successes,
            "episode_seconds": seconds,
        },
        "gain": gain_record,
        "state_before": state_before,
        "state": scheduler.state_dict(),
        "budget": {"episodes": budget, "minutes": float(sum(minutes)), "minutes_per_task": minutes},
        "allocation": allocation.to_dict(),
    } | ({} if demos is None else {"demos": demos})
    if unverified:
        plan["unverified"] = unverified
    return plan


def session_demos(config: PlanConfig, num_tasks: int, previous: dict | None) -> list[float] | None:
    """Expert demos per task behind this session's policy (None where they are not known).

    ``--initial_demos`` on a first plan, else the previous plan's demos plus the episodes it allocated.
    """
    if previous is None:
        return None if config.initial_demos is None else [float(config.initial_demos)] * num_tasks
    before = previous.get("demos")
    if before is None:
        return None
    return [float(d + n) for d, n in zip(before, previous["allocation"]["episodes_per_task"], strict=True)]


def _demos_measurement(demos: list[float] | None) -> dict[str, list[float]]:
    """The scheduler's ``demos``/``demos_so_far`` arguments (none when the demos are unknown)."""
    return {} if demos is None else {"demos": demos, "demos_so_far": demos}


def plan_table(plan: dict) -> str:
    """The plan as a Markdown table, one row per task, and the totals."""
    allocation, measured = plan["allocation"], plan["measurements"]
    lines = [
        f"plan session {plan['session']} ({allocation['method']}): {plan['budget']['episodes']} episodes, "
        f"about {plan['budget']['minutes']:.1f} operator minutes",
        "| task | episodes read | policy alone | success | Kalman p | metric | plan: episodes | minutes |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for i, task in enumerate(plan["tasks"]):
        alone = measured["policy_episodes"][i]
        rate = f"{measured['successes'][i] / alone:.2f}" if alone else "-"
        lines.append(
            f"| {task} | {measured['episodes'][i]} | {alone} | {rate} | "
            f"{allocation['kalman_posterior']['p'][i]:.3f} | {allocation['metric'][i]:.3f} | "
            f"{allocation['episodes_per_task'][i]} | {plan['budget']['minutes_per_task'][i]:.1f} |"
        )
    if plan.get("gain") is not None:
        drops = ", ".join(
            f"{task} {drop:.4f}" for task, drop in zip(plan["tasks"], plan["gain"]["gain"], strict=True)
        )
        lines.append(f"loss drop per task (previous policy - policy, on the training datasets): {drops}")
    lines += [f"note: {note}" for note in allocation.get("notes", [])]
    return "\n".join(lines)


def write_plan(plan: dict, path: Path) -> None:
    """Writes the plan file; never overwrites one (one line)."""
    if path.exists():
        raise UserError(f"{path} exists: plans are never overwritten; give a new --output.")
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(path.name + ".tmp")
    temporary.write_text(json.dumps(plan, indent=1))
    temporary.replace(path)


def verify_plan(path: Path) -> list[str]:
    """Recomputes a plan from its recorded inputs; returns the problems (empty: it checks out)."""
    plan = read_plan(path)
    problems = _previous_problems(plan, path)
    labels, label_problems = _recorded_labels(plan)
    problems += label_problems
    for dataset in plan["inputs"]:
        root = Path(dataset["root"])
        if not (root / "meta" / "info.json").is_file():
            problems.append(f"dataset {dataset['source']}: {root} is gone (cannot re-read it)")
        elif dataset_checksum(root) != dataset["checksum"]:
            problems.append(
                f"dataset {dataset['source']}: its files changed since the plan (checksum differs)"
            )
        elif dataset["success_key"].startswith("labels:") and labels is None:
            continue  # the labels file is gone or changed: named above
        else:
            own = labels.get(dataset["source"]) if labels is not None else None
            again = read_dataset(
                str(root), _success_option(dataset), plan["options"]["intervention_key"], own
            )
            for name in ("episodes", "tasks", "success", "policy_only"):
                if list(getattr(again, name)) != list(dataset[name]):
                    problems.append(f"dataset {dataset['source']}: recorded {name} differ from its files")
    problems += _gain_input_problems(plan)
    problems += _allocation_problems(plan)
    return problems


def _gain_input_problems(plan: dict) -> list[str]:
    """Whether the policies and datasets the losses were measured with are still those files."""
    if plan.get("gain") is None:
        return []
    from lerobot_mtdagger.planning.loss import policy_checksum

    problems = []
    for role in ("previous_policy", "policy"):
        inputs = plan["gain"][role]
        path = Path(inputs["policy"])
        if not path.is_dir():
            problems.append(f"{role} {path} is gone: its losses cannot be checked")
        elif policy_checksum(path) != inputs["policy_sha256"]:
            problems.append(f"{role} {path} changed since the plan (checksum differs)")
    for dataset in plan["gain"]["loss_datasets"]:
        root = Path(dataset["source"])
        if root.is_dir() and dataset_checksum(root) != dataset["checksum"]:
            problems.append(f"loss dataset {dataset['source']} changed since the plan (checksum differs)")
    return problems


def _recorded_labels(plan: dict) -> tuple[dict[str, dict[int, bool]] | None, list[str]]:
    """The plan's success labels file, re-read (None and a problem if it is gone or changed)."""
    recorded = plan["options"].get("success_labels")
    if recorded is None:
        return {}, []
    path = Path(recorded["path"])
    if not path.is_file():
        return None, [f"success labels {path} are gone: the labelled datasets cannot be re-read"]
    if file_sha256(path) != recorded["sha256"]:
        return None, [f"success labels {path} changed since the plan (sha256 differs)"]
    return read_labels(path, [dataset["source"] for dataset in plan["inputs"]]), []


def _success_option(dataset: dict) -> str:
    """The success column a dataset was read with (``frames:x`` / ``episodes:x`` -> ``x``)."""
    return dataset["success_key"].split(":", 1)[1]


def _previous_problems(plan: dict, path: Path) -> list[str]:
    """Whether the previous plan file is still the one this plan continued."""
    previous = plan.get("previous")
    if previous is None:
        return []
    where = Path(previous["path"])
    where = where if where.is_absolute() or where.exists() else path.parent / where.name
    if not where.is_file():
        return [f"previous plan {previous['path']} is gone: its state cannot be checked"]
    problems = []
    if file_sha256(where) != previous["sha256"]:
        problems.append(f"previous plan {where} changed since this plan read it (sha256 differs)")
    elif read_plan(where)["state"] != plan["state_before"]:
        problems.append(f"state_before is not the state of the previous plan {where}")
    return problems


def _allocation_problems(plan: dict) -> list[str]:
    """Recomputes the measurements and the allocation from the recorded inputs and ``state_before``."""
    tasks = plan["tasks"]
    read = [_recorded_episodes(dataset) for dataset in plan["inputs"]]
    measured = measure(read, tasks)
    problems = []
    for name in ("episodes", "policy_episodes", "successes"):
        if getattr(measured, name) != plan["measurements"][name]:
            problems.append(f"measurements.{name}: recorded {plan['measurements'][name]} != recomputed")
    state = plan["state_before"]
    scheduler = Scheduler(_config_of(state), len(tasks))
    scheduler.load_state_dict(state)
    gain = None
    if plan.get("gain") is not None:
        gain = loss_drop(plan["gain"]["loss_previous"], plan["gain"]["loss"])
        if gain != plan["gain"]["gain"]:
            problems.append(
                f"gain: recorded {plan['gain']['gain']} != the drop of the recorded losses {gain}"
            )
    scheduler.update(
        success_rate=measured.success_rate,
        episodes=measured.policy_episodes,
        gain=gain,
        **_demos_measurement(plan.get("demos")),
    )
    again = scheduler.allocate(int(plan["budget"]["episodes"])).to_dict()
    if again["episodes_per_task"] != plan["allocation"]["episodes_per_task"]:
        problems.append(
            f"allocation: recorded {plan['allocation']['episodes_per_task']} != recomputed "
            f"{again['episodes_per_task']}"
        )
    problems += [f"allocation: {problem}" for problem in allocation_mismatches(plan["allocation"])]
    if scheduler.state_dict() != plan["state"]:
        problems.append("state: the recorded scheduler state is not the one the inputs give")
    return problems


def _recorded_episodes(dataset: dict) -> DatasetEpisodes:
    """A dataset's episodes as the plan recorded them."""
    fields: dict[str, Any] = {
        name: tuple(dataset[name]) for name in ("episodes", "tasks", "success", "policy_only", "seconds")
    }
    scalars = ("source", "root", "checksum", "revision", "fps", "success_key", "intervention_key")
    return DatasetEpisodes(**{name: dataset[name] for name in scalars}, **fields)


def _config_of(state: dict[str, Any]) -> SchedulerConfig:
    """The scheduler config a state was made with."""
    return SchedulerConfig.get_choice_class(state["method"])(**state["config"])
