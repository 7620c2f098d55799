"""The ``lerobot-mtdagger`` command.

Usage: ``lerobot-mtdagger <command> [--option=value ...]``. Options are parsed by draccus, so nested
configs are set with dots, for example ``--scheduler.type=need --scheduler.temperature=0.5``.

Commands:
    run: one Multitask DAgger experiment (``--preset``, ``--suite.name``, ``--suite.tasks``,
        ``--scheduler.type``, ``--dagger.rounds``, ``--dagger.budget``, ``--output_dir``, ``--resume``,
        ...; see ``RunConfig``), or the one-round behaviour-cloning baseline with ``--mode=bc``.
    eval: success per task of a pretrained policy (``--policy_path``, ``--suite.name``, ``--episodes``).
    shift: covariate shift of a pretrained policy: its action error on the states of its own rollouts
        against on the expert's, per task (the options of ``eval``); tells whether DAgger's
        relabelled rollouts have much to add over more demonstrations.
    verify: recompute every round's allocation from its record (``--experiment_dir``).
    merge: rounds 0..k as one LeRobotDataset (``--experiment_dir``, ``--output``).
    compare: every method over every seed, and BC at every budget, as runs in a process pool, then
        the results table (``--methods``, ``--seeds``, ``--bc_budgets``, ``--jobs``, ``--output_dir``;
        any other option goes to every run).
    report: eval success against expert demos per method, mean and std over seeds (``--experiments``
        or ``--compare_dir``); with ``--output_dir`` (default for a compare folder) also the figures
        and a summary with paired differences.
    push: round datasets (tag ``round-{k:03d}`` each) and round policies to the Hub
        (``--experiment_dir``, ``--repo_id``, ``--policy_repo_id``).
    plan: the next collection session's episodes per task from LeRobot datasets of the policy's
        episodes (``--datasets``, ``--budget`` or ``--budget_minutes``, ``--output``, ``--previous``);
        ``--verify=PLAN`` recomputes a plan from its recorded inputs (``planning/plan.py``).
    demo: run the performance-aware scheduler on synthetic tasks and print each round's allocation
        (no simulator, no policy; shows how the methods split a budget).
"""

from __future__ import annotations

import dataclasses
import json
import logging
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from lerobot_mtdagger.datasets.push_config import PushConfig
from lerobot_mtdagger.envs.config import DEFAULT_IMAGE_SIZE, DEFAULT_NUM_POINTS, SuiteConfig
from lerobot_mtdagger.planning.plan import PlanConfig
from lerobot_mtdagger.runner.configs import (
    RUN_OPTION_RENAMES,
    SUITE_OPTION_RENAMES,
    WORKER_BACKENDS,
    RunConfig,
    renamed_option_error,
    resolve_workers,
)
from lerobot_mtdagger.scheduler import NeedSchedulerConfig, Scheduler, SchedulerConfig
from lerobot_mtdagger.studies.compare import CompareConfig, follow_parent, split_arguments
from lerobot_mtdagger.studies.simulate import SyntheticTasks, simulate
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.parsing import parse_options
from lerobot_mtdagger.utils.paths import check_output_dir, check_output_file
from lerobot_mtdagger.utils.ray_session import check_ray_address, import_ray

HELDOUT_TASKS = "heldout"
"""``--suite.tasks='[heldout]'``: the suite's unseen tasks (``eval``, ``shift``)."""
UNSEEN_RULES: tuple[str, ...] = ("shared", "nearest")
"""``eval --unseen_rule``: how a policy acts on a task it was not trained on (``EvalConfig``)."""

if TYPE_CHECKING:
    from lerobot_mtdagger.envs.base import TaskSuite
    from lerobot_mtdagger.runner.evaluate import PolicyRunner
    from lerobot_mtdagger.studies.shift import ShiftResult

logger = logging.getLogger(__name__)


@dataclass
class DemoConfig:
    """Options of ``lerobot-mtdagger demo``.

    Attributes:
        scheduler: Scheduling method and its hyperparameters (``--scheduler.type=need|gain|...``).
        num_tasks: Number of synthetic tasks, difficulties spread from easy to hard.
        rounds: DAgger rounds after round 0.
        budget: Episodes per round; 0 means 3 per task (the paper's MetaWorld state setting).
        initial_demos: Round-0 expert episodes per task.
        seed: Seed of the simulated rollout noise.
        output: Optional path of a JSON file receiving every round's full allocation record.
    """

    scheduler: SchedulerConfig = field(default_factory=NeedSchedulerConfig)
    num_tasks: int = 10
    rounds: int = 6
    budget: int = 0
    initial_demos: int = 3
    seed: int = 0
    output: Path | None = None

    def __post_init__(self) -> None:
        if self.num_tasks < 1:
            raise ValueError(f"num_tasks must be >= 1, got {self.num_tasks}.")
        if self.rounds < 1:
            raise ValueError(f"rounds must be >= 1, got {self.rounds}.")
        if self.budget == 0:
            self.budget = 3 * self.num_tasks


def run_demo(config: DemoConfig) -> list[dict]:
    """Runs the scheduler demo and prints one line per round.

    Args:
        config: The demo options.

    Returns:
        The JSON-ready round records.
    """
    scheduler = Scheduler(config.scheduler, config.num_tasks)
    tasks = SyntheticTasks.spread(config.num_tasks)
    history = simulate(scheduler, tasks, config.rounds, config.budget, config.initial_demos, config.seed)
    print(
        f"scheduler={config.scheduler.type} tasks={config.num_tasks} budget={config.budget}/round "
        f"T={config.scheduler.temperature} n_min={config.scheduler.min_episodes}"
    )
    print("task difficulty (easy -> hard):", np.round(tasks.difficulty, 1).tolist())
    for record in history:
        print(
            f"round {record.round}: allocation {record.allocation.episodes_per_task} "
            f"mean true success {np.mean(record.true_success):.3f}"
        )
    records = [record.to_dict() for record in history]
    if config.output is not None:
        config.output.parent.mkdir(parents=True, exist_ok=True)
        config.output.write_text(json.dumps(records, indent=2))
        print(f"wrote {config.output}")
    return records


def run_experiment(config: RunConfig) -> list[str]:
    """Runs ``lerobot-mtdagger run`` and prints the per-round summary."""
    from lerobot_mtdagger.runner.dagger import run

    follow_parent()
    header = f"experiment {config.output_dir} ({config.method}, seed {config.seed}):"
    return run(
        config, on_summary=lambda line: print(line, flush=True), on_start=lambda: print(header, flush=True)
    )


@dataclass
class VerifyConfig:
    """Options of ``lerobot-mtdagger verify``.

    Attributes:
        experiment_dir: The experiment's output directory.
    """

    experiment_dir: Path | None = None

    def __post_init__(self) -> None:
        if self.experiment_dir is None:
            raise ValueError("--experiment_dir is required (the output_dir of a run).")


def verify_command(config: VerifyConfig) -> list[str]:
    """Checks every committed round and policy against its files and record; exits 1 on a problem."""
    from lerobot_mtdagger.datasets.rounds import ExperimentDir
    from lerobot_mtdagger.datasets.verify import verify_experiment

    experiment = ExperimentDir(config.experiment_dir)
    num_rounds, num_policies, problems = verify_experiment(experiment, RunConfig.option_defaults())
    for problem in problems:
        print(f"PROBLEM {problem}")
    print(
        f"verified {num_rounds} round(s) and {num_policies} policy folder(s) in {config.experiment_dir}: "
        f"{len(problems)} problem(s)"
    )
    if problems:
        raise SystemExit(1)
    return problems


@dataclass
class MergeConfig:
    """Options of ``lerobot-mtdagger merge``: D(k) = rounds 0..k as ONE LeRobotDataset.

    Attributes:
        experiment_dir: The experiment's output directory.
        output: Folder of the merged dataset (must not exist).
        up_to_round: Last round to merge (None: the last committed one).
        repo_id: Repo id written into the merged dataset's metadata.
    """

    experiment_dir: Path | None = None
    output: Path | None = None
    up_to_round: int | None = None
    repo_id: str = "local/merged"

    def __post_init__(self) -> None:
        if self.experiment_dir is None or self.output is None:
            raise ValueError("--experiment_dir and --output are required.")
        check_output_dir(self.output, "--output")


def merge_command(config: MergeConfig) -> Path:
    """Merges rounds 0..k with LeRobot's aggregation; the result trains with stock lerobot-train."""
    from lerobot_mtdagger.datasets.rounds import ExperimentDir, merge_rounds

    experiment = ExperimentDir(config.experiment_dir)
    experiment.read_config()  # refuses a folder that is not an experiment
    rounds = experiment.committed_rounds()
    if not rounds:
        raise UserError(f"{config.experiment_dir} has no committed round to merge yet.")
    last = rounds[-1] if config.up_to_round is None else config.up_to_round
    if last not in rounds:
        raise UserError(f"Round {last} is not committed in {config.experiment_dir}; committed: {rounds}.")
    output = merge_rounds(experiment, list(range(last + 1)), config.output, config.repo_id)
    print(f"merged rounds 0..{last} into {output}")
    return output


def _eval_suite() -> SuiteConfig:
    """``eval``'s default suite: MT10, its observations those the policy was trained on."""
    return SuiteConfig(name="metaworld-mt10")


@dataclass
class EvalConfig:
    """Options of ``lerobot-mtdagger eval``: success per task of a policy (mtdagger, ACT, Diffusion).

    Attributes:
        policy_path: Pretrained model folder or Hub id (with its processors).
        suite: The suite (``SuiteConfig``, spelt as for ``run``: ``--suite.name=drawers``).
            ``--suite.tasks='[heldout]'`` evaluates the suite's unseen tasks, which a policy trained
            with ``task_dropout > 0`` acts on with its shared embedding. ``suite.tasks``,
            ``suite.obs_mode``, ``suite.num_points`` and ``suite.image_size`` default to what the
            policy was trained on (its tasks that the suite has, else all the suite's).
        episodes: Episodes per task.
        seed: Seed of the evaluation episodes.
        output: Optional JSON file for the results.
        workers: Env worker processes (None: one per core; 0: in this process).
        worker_backend: ``local`` (forked processes) or ``ray`` (Ray actors, as ``run``'s
            ``--rollout.worker_backend``; the same episodes either way).
        ray_address: The Ray cluster of ``worker_backend=ray`` (None: start a local Ray).
        trust_checkpoint: Let the policy's processor configs name Python classes, which LeRobot's
            loader imports and calls (default: only LeRobot registry names are accepted).
        unseen_rule: How the policy acts on a task it was not trained on (an unseen drawer):
            ``shared`` with its shared "any task" embedding (a policy trained with task dropout;
            what a run's unseen-drawer evaluation does), ``nearest`` with the task input of the
            training task most like it (the drawers: the same handle type, the nearest handle size
            and height; ``docs/drawers.md``).
        allow_changed_policy: Evaluate a policy folder of an experiment even if its files differ from
            the checksums committed with it (said in the output); by default such a folder is refused.
    """

    policy_path: str | None = None
    suite: SuiteConfig = field(default_factory=_eval_suite)
    episodes: int = 10
    seed: int = 0
    output: Path | None = None
    workers: int | None = None
    worker_backend: str = "local"
    ray_address: str | None = None
    trust_checkpoint: bool = False
    unseen_rule: str = "shared"
    allow_changed_policy: bool = False

    @property
    def worker_count(self) -> int:
        """Env worker processes to start."""
        return resolve_workers(self.workers)

    def env_workers(self, suite: TaskSuite) -> Any:
        """The env workers of ``suite`` on ``worker_backend`` (a context manager)."""
        from lerobot_mtdagger.runner.ray_workers import make_env_workers

        return make_env_workers(suite, self.worker_count, self.worker_backend, self.ray_address)

    def __post_init__(self) -> None:
        resolve_workers(self.workers)  # refuses a negative count before anything runs
        if self.worker_backend not in WORKER_BACKENDS:
            raise ValueError(
                f"worker_backend must be one of {list(WORKER_BACKENDS)}, got {self.worker_backend!r}."
            )
        if self.worker_backend == "ray":
            import_ray()  # refuses a missing Ray before anything runs
            check_ray_address(self.ray_address, "--ray_address")
        if self.policy_path is None:
            raise ValueError("--policy_path is required (a pretrained model folder or a Hub id).")
        if self.output is not None:  # before evaluating, not after: the results would be lost
            check_output_file(self.output, "--output")
        if self.episodes <= 0:
            raise ValueError(f"episodes must be > 0, got {self.episodes}.")
        if self.unseen_rule not in UNSEEN_RULES:
            raise ValueError(f"unseen_rule must be one of {list(UNSEEN_RULES)}, got {self.unseen_rule!r}.")
        if self.suite.name is None:  # draccus builds a SuiteConfig of class defaults when one field is given
            self.suite.name = _eval_suite().name
        self.suite.check()


def check_committed_policy(folder: Path, allow_changed: bool) -> None:
    """Refuses a policy folder of an experiment whose files changed after commit (unless allowed).

    A folder ``<experiment>/policies/round-XXX`` is checked against the checksums in its
    ``training.json`` and the experiment's ledger; any other folder (or a Hub id) is not.

    Raises:
        UserError: Naming the changed files and ``--allow_changed_policy=true``.
    """
    from lerobot_mtdagger.datasets.rounds import CONFIG_FILE, TRAINING_FILE, ExperimentDir

    experiment_root = folder.parent.parent
    if folder.parent.name != "policies" or not (experiment_root / CONFIG_FILE).is_file():
        return
    if not (folder / TRAINING_FILE).is_file() or not folder.name.startswith("round-"):
        return
    experiment = ExperimentDir(experiment_root)
    record = experiment.read_phase_record(int(folder.name.split("-")[1]))
    record_path = str(folder / TRAINING_FILE)
    problems = experiment.phase_file_problems(record)
    problems += [p for p in experiment.ledger_problems(resuming=True) if record_path in p]
    if not problems:
        return
    if not allow_changed:
        raise UserError(
            f"{folder} changed after it was committed ({'; '.join(problems)}): restore it, or pass "
            "--allow_changed_policy=true to evaluate it as it is."
        )
    print(f"warning: evaluating {folder} although it changed after commit: {'; '.join(problems)}")


def _suite_and_policy(config: EvalConfig) -> tuple[TaskSuite, PolicyRunner]:
    """The suite the config names and its pretrained policy, checked to take the suite's observations."""
    from lerobot_mtdagger.envs import suite_from_config
    from lerobot_mtdagger.runner.evaluate import PolicyRunner

    check_committed_policy(Path(config.policy_path), config.allow_changed_policy)
    runner = PolicyRunner.from_pretrained(config.policy_path, trust_checkpoint=config.trust_checkpoint)
    suite_config = dataclasses.replace(config.suite, **observation_options(runner, config.suite))
    if list(suite_config.tasks) == [HELDOUT_TASKS]:
        suite = suite_from_config(suite_config, tasks=None).heldout_suite()
        if suite is None:
            raise UserError(
                f"Suite {suite_config.name!r} has no held-out tasks: --suite.tasks='[heldout]' is for the "
                "drawers."
            )
    else:
        suite = suite_from_config(suite_config)
        trained = [name for name in suite.task_names if name in runner.task_names]
        if not suite_config.tasks and runner.task_names and not trained and not runner.acts_on_unseen_tasks:
            shown = ", ".join(runner.task_names[:4]) + (", ..." if len(runner.task_names) > 4 else "")
            raise UserError(
                f"The policy was trained on {shown}, none of which --suite.name={suite_config.name} has "
                "(eval's default suite is metaworld-mt10): pass the --suite.name it was trained on."
            )
        if not suite_config.tasks and trained and len(trained) < len(suite.task_names):
            logger.info("Evaluating the %d tasks of %s the policy knows", len(trained), suite_config.name)
            suite = suite_from_config(suite_config, tasks=trained)
    runner.check_inputs(suite.features, suite_config.obs_mode)
    if config.unseen_rule == "nearest":
        unseen = [name for name in suite.task_names if name not in runner.task_names]
        runner.act_as({name: suite.nearest_training_task(name, runner.task_names) for name in unseen})
        for name, proxy in runner.task_aliases.items():
            logger.info("Unseen task %r: the policy acts with the task input of %r.", name, proxy)
    runner.check_tasks(suite.task_names)
    return suite, runner


def observation_options(runner: PolicyRunner, suite: SuiteConfig) -> dict[str, Any]:
    """``obs_mode``, ``num_points`` and ``image_size``: the suite config's, else the policy's.

    A policy with a point-cloud input was trained on clouds of its input's point count, one with an
    image input on images of its side, any other on state.
    """
    from lerobot_mtdagger.policies.mtdagger.configuration_mtdagger import is_pointcloud_feature

    features = runner.policy.config.input_features
    clouds = [f for key, f in features.items() if is_pointcloud_feature(key, f)]
    images = [f for key, f in features.items() if key.startswith("observation.image")]
    trained = "pointcloud" if clouds else "rgb" if images else "state"
    return {
        "obs_mode": suite.obs_mode or trained,
        "num_points": suite.num_points or (clouds[0].shape[0] if clouds else DEFAULT_NUM_POINTS),
        "image_size": suite.image_size or (images[0].shape[-1] if images else DEFAULT_IMAGE_SIZE),
    }


def eval_command(config: EvalConfig) -> dict:
    """Evaluates a pretrained policy per task with the pure policy acting."""
    from lerobot_mtdagger.runner.evaluate import evaluate

    suite, runner = _suite_and_policy(config)
    with config.env_workers(suite) as workers:
        result, _ = evaluate(workers, runner, config.episodes, config.seed)
    progress = result.progress or [None] * len(result.task_names)
    for task, success, score in zip(result.task_names, result.success, progress, strict=True):
        line = f"{task:<32} {success:.3f}" + ("" if score is None else f"  progress {score:.2f}/3")
        proxy = runner.task_aliases.get(task)
        print(line + ("" if proxy is None else f"  (acting as {proxy})"))
    mean_progress = "" if result.progress is None else f"  progress {np.mean(result.progress):.2f}/3"
    print(f"{'mean':<32} {result.mean:.3f}{mean_progress}")
    values = result.to_dict() | {"unseen_rule": config.unseen_rule}
    if runner.task_aliases:
        values["acted_as"] = dict(runner.task_aliases)
    if config.output is not None:
        config.output.write_text(json.dumps(values, indent=2))
    return values


@dataclass
class ShiftConfig(EvalConfig):
    """Options of ``lerobot-mtdagger shift``: a policy's action error on its own states vs the expert's.

    The attributes are ``EvalConfig``'s; ``episodes`` episodes per task are run by the policy and
    again by the expert from the same reset seeds (``shift.measure_shift``).
    """

    episodes: int = 5


def shift_command(config: ShiftConfig) -> dict:
    """Measures a pretrained policy's covariate shift per task and prints it."""
    from lerobot_mtdagger.studies.shift import measure_shift

    suite, runner = _suite_and_policy(config)
    with config.env_workers(suite) as workers:
        result = measure_shift(workers, runner, config.episodes, config.seed)
    print(shift_table(result))
    if config.output is not None:
        config.output.write_text(json.dumps(result.to_dict(), indent=2))
    return result.to_dict()


def shift_table(result: ShiftResult) -> str:
    """One line per task: success, mean squared action error on own and expert states, their ratio."""
    lines = [f"{'task':<32} {'success':>7} {'own states':>10} {'expert states':>13} {'own/expert':>10}"]
    rows = zip(
        result.task_names, result.success, result.own_error, result.expert_error, result.ratio, strict=True
    )
    for task, success, own, expert, ratio in rows:
        lines.append(f"{task:<32} {success:7.3f} {own:10.4f} {expert:13.4f} {ratio:10.2f}")
    own, expert = float(np.mean(result.own_error)), float(np.mean(result.expert_error))
    lines.append(
        f"{'mean':<32} {np.mean(result.success):7.3f} {own:10.4f} {expert:13.4f} {result.mean_ratio:10.2f}"
    )
    lines.append(f"median task's own/expert ratio: {result.median_ratio:.2f}")
    own_by_dimension = np.mean(result.own_error_by_dimension, axis=0)
    expert_by_dimension = np.mean(result.expert_error_by_dimension, axis=0)
    lines.append(
        f"mean error per action dimension, own states:    {np.array2string(own_by_dimension, precision=4)}"
    )
    lines.append(
        f"mean error per action dimension, expert states: {np.array2string(expert_by_dimension, precision=4)}"
    )
    return "\n".join(lines)


@dataclass
class ReportConfig:
    """Options of ``lerobot-mtdagger report``: success against expert demos, method by method.

    Attributes:
        experiments: Experiment directories (several seeds of several methods).
        compare_dir: A ``compare`` folder (its runs are the experiments); instead of ``experiments``.
        output_dir: Folder for the figures and ``report.md`` (default ``<compare_dir>/report``; with
            ``experiments`` only, no figures unless given).
        output: Optional markdown file for the table.
        levels: Success levels of the "demos to reach" and "time to reach" figures.
        variants: More runs reported under a method name of their own, by name: a ``compare`` folder
            or one experiment each, e.g. ``--variants='{bc-balanced: outputs/bc-balanced}'`` for BC
            trained with balanced sampling beside the ``bc`` of ``compare_dir``. A BC variant is a
            baseline like ``bc``.
        results: Saved results tables instead of run folders: each a ``results.json`` that ``report
            --output_dir`` or ``compare`` wrote, or its folder. Draws the figures and ``report.md`` from
            the tables alone, e.g. after the run folders are gone, with other ``--levels``, or joining
            seeds run on other machines (each point in one table only; the methods' configs must
            agree). Default ``output_dir`` for one table: its folder.
        records: Runs' saved records (``scripts/save_run_records.sh``: config, round and training
            records, no frames or weights), each a run's records folder, a folder of them, or a
            study's ``runs-records.tar.gz`` (or a folder holding them: ``studies.saved_records``), reported
            beside ``experiments`` and ``compare_dir`` as their runs are: a study whose ``outputs/`` was
            lost keeps its finished runs. Their frames per task are known only on average.
    """

    experiments: list[Path] = field(default_factory=list)
    compare_dir: Path | None = None
    results: list[Path] = field(default_factory=list)
    output_dir: Path | None = None
    output: Path | None = None
    levels: list[float] = field(default_factory=lambda: [0.5, 0.6, 0.7, 0.8])
    variants: dict[str, Path] = field(default_factory=dict)
    records: list[Path] = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.results:
            self._check_results_options()
            return
        if not self.experiments and self.compare_dir is None and not self.records:
            raise ValueError(
                "--experiments, --compare_dir, --records or --results is required, e.g. "
                "--experiments='[outputs/need-s0,outputs/bc-s0]', --compare_dir=outputs/compare, "
                "--records='[experiments/pixels-eval/records]' or "
                "--results='[experiments/mt10-state-eval/report]'."
            )
        for folder in self.records:
            _saved_records_runs(Path(folder))  # refuses a folder without records now, not mid-report
        if self.compare_dir is not None and not (self.compare_dir / "runs").is_dir():
            raise ValueError(f"{self.compare_dir} is not a compare folder (no runs/ in it).")
        if self.compare_dir is not None and self.output_dir is None:
            self.output_dir = self.compare_dir / "report"
        self._check_outputs()
        from lerobot_mtdagger.datasets.rounds import CONFIG_FILE

        for name, folder in self.variants.items():
            if not (Path(folder) / "runs").is_dir() and not (Path(folder) / CONFIG_FILE).is_file():
                raise ValueError(
                    f"--variants: {folder} (for {name!r}) is neither a compare folder (runs/) nor an "
                    "experiment: give the folder compare or run wrote."
                )

    def _check_results_options(self) -> None:
        """``--results`` goes without run folders; several tables need an ``--output_dir``."""
        if self.experiments or self.compare_dir is not None or self.variants or self.records:
            raise ValueError(
                "--results draws saved tables: give it alone, without --experiments, --compare_dir, "
                "--variants or --records (their runs are tabulated afresh instead)."
            )
        if self.output_dir is None and len(self.results) > 1:
            raise ValueError(
                f"--results joins {len(self.results)} tables: give --output_dir for the joined report "
                "(it is never written into one of the tables' folders unasked)."
            )
        if self.output_dir is None:
            table = Path(self.results[0])
            self.output_dir = table if table.is_dir() else table.parent
        self._check_outputs()

    def _check_outputs(self) -> None:
        """Refuses an output folder or file that cannot be written, before any table is made."""
        if self.output_dir is not None:
            check_output_dir(self.output_dir, "--output_dir")
        if self.output is not None:
            check_output_file(self.output, "--output")

    @property
    def experiment_dirs(self) -> list[Path]:
        """The experiments to report on (the variants' last)."""
        mine = list(self.experiments)
        if self.compare_dir is not None:
            mine += _compare_runs(self.compare_dir)
        for folder in self.records:
            mine += _saved_records_runs(Path(folder))
        return mine + list(self.labels)

    @property
    def labels(self) -> dict[Path, str]:
        """The method name of each variant's experiments."""
        return {
            run: name
            for name, folder in self.variants.items()
            for run in (_compare_runs(Path(folder)) if (Path(folder) / "runs").is_dir() else [Path(folder)])
        }

    @property
    def runs_not_started(self) -> list[str]:
        """The runs the compare folders plan (``compare.json``) that have no folder yet."""
        from lerobot_mtdagger.studies.compare import runs_not_started

        folders = [self.compare_dir] if self.compare_dir is not None else []
        folders += [Path(folder) for folder in self.variants.values() if (Path(folder) / "runs").is_dir()]
        return [f"{name}: not started" for folder in folders for name in runs_not_started(folder)]


def _compare_runs(compare_dir: Path) -> list[Path]:
    """The run folders of a ``compare`` folder."""
    return sorted(p for p in (compare_dir / "runs").iterdir() if p.is_dir())


def _saved_records_runs(folder: Path) -> list[Path]:
    """The runs' records at ``folder`` (``studies.saved_records``: folders or archives)."""
    from lerobot_mtdagger.studies.saved_records import saved_records_runs

    return saved_records_runs(folder)


def report_command(config: ReportConfig) -> str:
    """Prints the learning curves (mean and std over seeds); writes the figures and summary.

    Runs still being written (or cut off) are reported as far as they got: a run without a committed
    round is left out, and the report says which runs are unfinished. With ``--results``, the same
    from a saved results table.
    """
    if config.results:
        return _report_saved_tables(config)
    from lerobot_mtdagger.studies.report import curves_table
    from lerobot_mtdagger.studies.results import check_comparable, learning_curves, run_progress

    all_roots, labels = config.experiment_dirs, config.labels  # each lists the run folders once
    configs = check_comparable(all_roots, labels)
    progress = [run_progress(root) for root in all_roots]
    unfinished = [run.describe() for run in progress if not run.finished] + config.runs_not_started
    if unfinished:
        logger.warning(
            "Interim report: %d run(s) unfinished (running, cut off or not started), reported as far "
            "as they got: %s",
            len(unfinished),
            "; ".join(unfinished),
        )
    roots = [run.root for run in progress if run.rounds > 0]
    if not roots:
        raise UserError(
            f"None of the {len(progress)} run(s) has a committed round yet: report once the first "
            "round is written."
        )
    table = _print_table(curves_table(learning_curves(roots, labels)), config)
    if config.output_dir is not None:
        from lerobot_mtdagger.datasets.rounds import open_run
        from lerobot_mtdagger.studies.results import results_rows, write_results
        from lerobot_mtdagger.studies.saved_records import shown_name

        rows = results_rows(roots, labels)
        for row in rows:
            row["experiment"] = shown_name(Path(row["experiment"]))
        task_names = open_run(roots[0]).read_round_record(0).task_names
        write_results(rows, config.output_dir, task_names, configs, unfinished)
        _write_figures(rows, task_names, config, unfinished)
    return table


def _report_saved_tables(config: ReportConfig) -> str:
    """``report --results``: the table, figures and summary of saved results tables, joined.

    Several tables joined are also saved as one (``results.csv``, ``results.json``, beside the figures),
    as ``report`` saves the table of the runs it reads; one table is where it was read from.
    """
    from lerobot_mtdagger.studies.report import curves_from_rows, curves_table
    from lerobot_mtdagger.studies.results import merge_tables, read_results, write_results

    saved = merge_tables([read_results(path) for path in config.results])
    if len(config.results) > 1:
        assert saved.configs is not None  # merge_tables refuses tables without them
        write_results(saved.rows, config.output_dir, saved.task_names, saved.configs, saved.unfinished)
    table = _print_table(curves_table(curves_from_rows(saved.rows)), config)
    _write_figures(saved.rows, saved.task_names, config, saved.unfinished)
    return table


def _print_table(table: str, config: ReportConfig) -> str:
    """Prints the learning-curve table and writes it to ``--output`` when given; returns it."""
    print(table)
    if config.output is not None:
        config.output.write_text(table + "\n")
    return table


def _write_figures(
    rows: list[dict], task_names: list[str], config: ReportConfig, unfinished: list[str]
) -> None:
    """Writes every figure and ``report.md`` into ``--output_dir`` and prints where."""
    from lerobot_mtdagger.studies.figures import write_report

    path = write_report(rows, task_names, config.output_dir, levels=config.levels, unfinished=unfinished)
    print(f"figures and summary: {path}")


def compare_command(config: CompareConfig, run_args: list[str]) -> list[dict]:
    """Runs every method over every seed (and BC at every budget) and writes the results table."""
    from lerobot_mtdagger.studies.compare import compare

    rows = compare(config, run_args)
    runs = len({row["experiment"] for row in rows})
    print(f"{runs} runs, {len(rows)} evaluated rounds: {config.output_dir / 'results.csv'}")
    return rows


def push_command(config: PushConfig) -> dict[str, dict[str, str]]:
    """Pushes an experiment's rounds (and policies) to the Hub (``datasets/hub.py``)."""
    from lerobot_mtdagger.datasets.hub import push_command as push

    return push(config)


def plan_command(config: PlanConfig) -> dict | list[str]:
    """Prints and writes the next session's plan, or (``--verify``) checks a plan; exits 1 on a problem."""
    from lerobot_mtdagger.planning.plan import make_plan, plan_table, verify_plan, write_plan

    if config.verify is not None:
        problems = verify_plan(config.verify)
        for problem in problems:
            print(f"PROBLEM {problem}")
        print(f"verified plan {config.verify}: {len(problems)} problem(s)")
        if problems:
            raise SystemExit(1)
        return problems
    plan = make_plan(config)
    write_plan(plan, config.output)
    print(plan_table(plan))
    print(f"plan file: {config.output}")
    return plan


COMMANDS: dict[str, tuple[type, Callable]] = {
    "run": (RunConfig, run_experiment),
    "compare": (CompareConfig, compare_command),
    "eval": (EvalConfig, eval_command),
    "shift": (ShiftConfig, shift_command),
    "verify": (VerifyConfig, verify_command),
    "merge": (MergeConfig, merge_command),
    "push": (PushConfig, push_command),
    "report": (ReportConfig, report_command),
    "plan": (PlanConfig, plan_command),
    "demo": (DemoConfig, run_demo),
}


def _usage() -> str:
    names = ", ".join(COMMANDS)
    return f"usage: lerobot-mtdagger <command> [--option=value ...]\ncommands: {names}\n" + (__doc__ or "")


HUB_LOGGER = "huggingface_hub"
"""huggingface_hub's logger (its own console handler): errors only, not a warning per HTTP retry."""


def configure_console_logging() -> None:
    """Warnings and errors on the console; INFO records still reach file handlers (``run.log``).

    The console shows what the commands print (one summary line per round for ``run``), never the
    INFO chatter of the libraries underneath, nor huggingface_hub's warning at each HTTP retry (a
    Hub that cannot be reached is one error line of ours).
    """
    console = logging.StreamHandler()
    console.setLevel(logging.WARNING)
    console.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    # force: a library may have configured the root logger already (LeRobot logs at import time).
    logging.basicConfig(level=logging.INFO, handlers=[console], force=True)
    logging.getLogger(HUB_LOGGER).setLevel(logging.ERROR)


OPTION_RENAMES: dict[str, dict[str, str]] = {
    "run": RUN_OPTION_RENAMES,
    "compare": RUN_OPTION_RENAMES,
    "eval": SUITE_OPTION_RENAMES,
    "shift": SUITE_OPTION_RENAMES,
}
"""Each command's options that moved into a group (refused with the new spelling named)."""

DEBUG_FLAG = "--debug"
"""Shows the traceback of a user error (for reporting a problem)."""


def error_line(command: str, message: object) -> str:
    """The one line printed for a user error: ``lerobot-mtdagger <command>: error: <message>``."""
    return f"lerobot-mtdagger {command}: error: {' '.join(str(message).split())}"


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the console script.

    A user error (``errors.UserError``: a bad option, path or file) prints one line
    ``lerobot-mtdagger <command>: error: <what and how to fix>`` and returns 2; with ``--debug`` it
    raises, with its traceback. Any other exception is a bug and raises.

    Args:
        argv: Arguments after the program name; ``sys.argv[1:]`` when None.

    Returns:
        The process exit status.
    """
    args = list(sys.argv[1:] if argv is None else argv)
    debug = DEBUG_FLAG in args
    args = [arg for arg in args if arg != DEBUG_FLAG]
    if not args or args[0] in ("-h", "--help", "help"):
        print(_usage())
        return 0
    command, options = args[0], args[1:]
    if command not in COMMANDS:
        print(f"unknown command {command!r}\n{_usage()}", file=sys.stderr)
        return 2
    renamed = renamed_option_error(options)
    if renamed is not None:
        print(error_line(command, renamed), file=sys.stderr)
        return 2
    configure_console_logging()
    try:
        run_command(command, options)
    except UserError as error:
        if debug:
            raise
        print(error_line(command, error), file=sys.stderr)
        return 2
    return 0


def run_command(command: str, options: list[str]) -> None:
    """Parses a command's options and runs it.

    Raises:
        UserError: On a bad option, path or file.
    """
    config_class, function = COMMANDS[command]
    passed: list[str] = []
    if command == "compare" and ("--help" in options or "-h" in options):
        options = ["--help"]  # compare's own options; `run --help` lists those passed to each run
    elif command == "compare":  # compare's own options; every other option goes to each run
        options, passed = split_arguments(options)
    renamed = renamed_option_error(passed if command == "compare" else options, OPTION_RENAMES.get(command))
    if renamed is not None:
        raise UserError(renamed)
    config = parse_options(config_class, options, f"lerobot-mtdagger {command}")
    function(config, passed) if command == "compare" else function(config)


if __name__ == "__main__":
    sys.exit(main())
