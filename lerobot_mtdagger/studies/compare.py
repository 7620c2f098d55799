"""``lerobot-mtdagger compare``: every method over many seeds, as ordinary runs in a process pool.

Every (method, seed) and every (bc, seed, budget) is one ``lerobot-mtdagger run`` with the same run
options, in its own folder under the compare folder::

    <output_dir>/
        runs/need-seed0/          an ordinary experiment folder (verify, merge, report work on it)
        runs/bc-12demos-seed0/    BC with 12 expert demos per task
        compare.json              what was asked (methods, seeds, budgets, run options)
        results.csv, results.json one row per run x evaluated round (``results.py``)

BC budgets are expert demos per task. The default is the cumulative demos per task of DAgger after
each round (``initial_demos + k * budget_per_task``, k = 0..rounds), so BC has a point at every x
where DAgger has one; BC at the budget of round k is ``run --mode=bc --rounds=k``, which also
trains it by the same rule as DAgger's phase k (``RunConfig.phase_steps``).

Runs are independent processes (``--jobs`` at once, default one per core); each gets
``cores / jobs`` torch threads and env workers so the jobs do not oversubscribe the cores. A
finished run is skipped, a cut-off run is resumed (``--resume=true``), so ``compare`` itself resumes.
A run started by ``compare`` ends itself within a second of ``compare`` ending (``follow_parent``), so a
``compare`` that is killed leaves no run writing on into its folder.
Asked again with more ``--rounds``, it extends the finished DAgger runs by the new rounds and adds BC
at the new budgets; the rounds already made are kept as they are.
"""

from __future__ import annotations

import json
import logging
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

from lerobot_mtdagger.runner.configs import RunConfig, default_worker_count
from lerobot_mtdagger.scheduler import scheduling_methods
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.parsing import parse_options

logger = logging.getLogger(__name__)

RUNS_DIR = "runs"
COMPARE_FILE = "compare.json"
PARENT_PID_ENV = "LEROBOT_MTDAGGER_PARENT_PID"
"""Set by ``compare`` in each run's environment: the process id the run must not outlive."""
PARENT_POLL_S = 0.5


@dataclass
class CompareConfig:
    """Options of ``lerobot-mtdagger compare`` (any other ``--option`` is passed to every run).

    Attributes:
        methods: Scheduling methods and ``bc``.
        seeds: Seeds; every method runs every seed.
        bc_budgets: BC expert demos per task (empty: DAgger's cumulative demos after each round).
        jobs: Runs at once (None: one per core).
        output_dir: The compare folder.
    """

    methods: list[str] = field(default_factory=lambda: ["bc", "uniform", "need", "gain"])
    seeds: list[int] = field(default_factory=lambda: [0, 1, 2])
    bc_budgets: list[int] = field(default_factory=list)
    jobs: int | None = None
    output_dir: Path = Path("outputs/compare")


@dataclass(frozen=True)
class Job:
    """One run of the comparison."""

    name: str
    args: tuple[str, ...]
    last_phase: int


def split_arguments(argv: Sequence[str]) -> tuple[list[str], list[str]]:
    """Separates ``compare``'s own options from the run options passed through to every run."""
    own_names = {f"--{name}" for name in CompareConfig.__dataclass_fields__}
    own, passed = [], []
    for arg in argv:
        (own if arg.split("=", 1)[0] in own_names else passed).append(arg)
    return own, passed


def base_run_config(run_args: Sequence[str]) -> RunConfig:
    """The run options every job shares, parsed once to check them and read the preset.

    Raises:
        ValueError: If the run options set what ``compare`` decides per job.
    """
    for arg in run_args:
        if arg.split("=", 1)[0] in ("--seed", "--mode", "--scheduler.type", "--output_dir", "--resume"):
            raise UserError(f"{arg} is set per run by compare: use --methods/--seeds/--output_dir.")
    return parse_options(RunConfig, run_args, "lerobot-mtdagger run")


def bc_rounds_for(config: RunConfig, budgets: Sequence[int], num_tasks: int) -> dict[int, int]:
    """BC budget (demos per task) -> the ``--rounds`` that gives it.

    Raises:
        ValueError: On a budget that no whole number of rounds gives.
    """
    per_round = config.budget_for(num_tasks) / num_tasks
    if not budgets:
        return {int(config.initial_demos + k * per_round): k for k in range(config.rounds + 1)}
    mapping = {}
    for budget in budgets:
        k = (budget - config.initial_demos) / per_round
        if k < 0 or k != int(k):
            valid = [int(config.initial_demos + j * per_round) for j in range(config.rounds + 4)]
            raise UserError(
                f"BC budget {budget} demos per task is not initial_demos + k * budget per task "
                f"({config.initial_demos} + k * {per_round:g}); choose among {valid}..."
            )
        mapping[int(budget)] = int(k)
    return mapping


def jobs_for(compare: CompareConfig, run_args: Sequence[str], num_tasks: int) -> list[Job]:
    """Every run of the comparison, with the same seeds and run options for every method."""
    config = base_run_config(run_args)
    jobs = []
    for seed in compare.seeds:
        for method in compare.methods:
            if method != "bc":
                name = f"{method}-seed{seed}"
                args = (*run_args, f"--scheduler.type={method}", f"--seed={seed}")
                jobs.append(Job(name, args, last_phase=config.rounds))
                continue
            for budget, rounds in sorted(bc_rounds_for(config, compare.bc_budgets, num_tasks).items()):
                name = f"bc-{budget}demos-seed{seed}"
                args = (*run_args, "--mode=bc", f"--rounds={rounds}", f"--seed={seed}")
                jobs.append(Job(name, args, last_phase=0))
    return jobs


def is_finished(folder: Path, last_phase: int) -> bool:
    """Whether the run in ``folder`` committed its training phases up to ``last_phase``.

    A DAgger run finished at fewer rounds than asked is not: resuming it with more ``--rounds``
    extends it (``ExperimentDir.check_resumable``).
    """
    from lerobot_mtdagger.datasets.rounds import (  # LeRobot: loaded only when needed
        CONFIG_FILE,
        ExperimentDir,
    )

    if not (folder / CONFIG_FILE).exists():
        return False
    return last_phase in ExperimentDir(folder).committed_phases()


def runs_not_started(compare_dir: Path) -> list[str]:
    """The runs ``compare_dir/compare.json`` plans that have no folder under ``runs/`` yet, in its order.

    Empty for a folder without ``compare.json``.

    Raises:
        UserError: If ``compare.json`` is not a compare plan.
    """
    path = Path(compare_dir) / COMPARE_FILE
    if not path.is_file():
        return []
    try:
        jobs = json.loads(path.read_text())["jobs"]
    except (json.JSONDecodeError, KeyError, TypeError) as error:
        raise UserError(f"{path} is not a compare plan ({error!r}); rerun compare to rewrite it.") from None
    return [name for name in jobs if not (Path(compare_dir) / RUNS_DIR / name).is_dir()]


def job_command(job: Job, folder: Path, threads: int, workers: int) -> tuple[list[str], dict[str, str]]:
    """The command line and environment of one job's ``lerobot-mtdagger run`` (resumed if started)."""
    from lerobot_mtdagger.datasets.rounds import CONFIG_FILE

    resume = ["--resume=true"] if (folder / CONFIG_FILE).exists() else []
    command = [
        sys.executable,
        "-m",
        "lerobot_mtdagger.cli",
        "run",
        *job.args,
        f"--output_dir={folder}",
        f"--workers={workers}",
        "--progress=false",
        *resume,
    ]
    env = {
        **os.environ,
        "OMP_NUM_THREADS": str(threads),
        "MKL_NUM_THREADS": str(threads),
        PARENT_PID_ENV: str(os.getpid()),
    }
    return command, env


class RunPool:
    """The runs of one ``compare``, ``parallel`` at once, each in its own process.

    One failed run stops none of the others. An interrupt (Ctrl-C, or any exception in the waiting
    thread) starts no further run and ends the running ones, which the next ``compare`` resumes.
    """

    def __init__(self, runs_dir: Path, parallel: int, threads: int, workers: int) -> None:
        """Prepares the pool; nothing runs before ``run_all``.

        Args:
            runs_dir: The compare folder's ``runs/``.
            parallel: Runs at once.
            threads: Torch threads per run.
            workers: Env worker processes per run.
        """
        self.runs_dir = runs_dir
        self.parallel = parallel
        self.threads = threads
        self.workers = workers
        self._lock = threading.Lock()
        self._live: set[subprocess.Popen] = set()
        self._stopping = False

    def run_all(self, jobs: Sequence[Job]) -> list[Path]:
        """Runs (or resumes, or skips) every job; returns the run folders in the order of ``jobs``.

        Raises:
            UserError: Once every job has ended, if any run failed; each failed run and its log are named.
        """
        executor = ThreadPoolExecutor(max_workers=self.parallel)
        futures = [executor.submit(self.run_one, job) for job in jobs]
        try:
            wait(futures)
        except BaseException:
            executor.shutdown(wait=False, cancel_futures=True)
            self._end_running()
            raise
        finally:
            executor.shutdown(wait=True)
        errors = [future.exception() for future in futures if future.exception() is not None]
        for error in errors:
            if not isinstance(error, UserError):
                raise error  # a fault of this code rather than of one run: keep its traceback
        if errors:
            raise UserError(
                f"{len(errors)} of {len(jobs)} runs failed; the others finished. Fix the cause and run the "
                "same compare again to resume: " + " ".join(str(error) for error in errors)
            )
        return [future.result() for future in futures]

    def run_one(self, job: Job) -> Path:
        """Runs (or resumes, or skips) one job in its own process; returns its folder.

        Raises:
            UserError: If the run fails, or the pool was interrupted before it started (its log is named).
        """
        folder = self.runs_dir / job.name
        if is_finished(folder, job.last_phase):
            logger.info("%s: finished, skipped", job.name)
            return folder
        command, env = job_command(job, folder, self.threads, self.workers)
        log_path = self.runs_dir / f"{job.name}.log"
        with log_path.open("a") as log:
            with self._lock:
                if self._stopping:
                    raise UserError(f"Run {job.name} not started: compare was interrupted.")
                process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT, env=env)
                self._live.add(process)
            try:
                returncode = process.wait()
            finally:
                with self._lock:
                    self._live.discard(process)
        if returncode != 0:
            raise UserError(f"Run {job.name} failed (exit {returncode}); see {log_path}.")
        return folder

    def _end_running(self) -> None:
        """Starts no further run and ends (SIGTERM) every running one."""
        with self._lock:
            self._stopping = True
            for process in self._live:
                process.terminate()
        logger.warning("compare interrupted: no further run starts; the running ones were ended.")


def follow_parent(poll_s: float = PARENT_POLL_S) -> threading.Thread | None:
    """Ends this process (SIGTERM) once the ``compare`` that started it has ended.

    Called by ``lerobot-mtdagger run`` at start. Without it, a ``compare`` killed by ``kill`` or
    ``kill -9`` leaves its runs going on in the background, writing into run folders that a new
    ``compare`` then resumes at the same time. The run ends as a killed run does: committed rounds and
    phases stay, the next ``compare`` resumes it. Does nothing when ``PARENT_PID_ENV`` is not set
    (a run started by hand).

    Args:
        poll_s: Seconds between two checks of the parent process.

    Returns:
        The daemon thread that watches the parent, or None when there is no parent to follow.
    """
    expected = os.environ.get(PARENT_PID_ENV)
    if not expected:
        return None
    parent = int(expected)
    watcher = threading.Thread(
        target=_end_when_orphaned, args=(parent, poll_s), name="follow-parent", daemon=True
    )
    watcher.start()
    return watcher


def _end_when_orphaned(parent: int, poll_s: float) -> None:
    """Waits until this process's parent is no longer ``parent`` (it ended), then ends this process."""
    while os.getppid() == parent:
        time.sleep(poll_s)
    logger.error("compare (pid %d) has ended; ending this run, which compare resumes when run again.", parent)
    os.kill(os.getpid(), signal.SIGTERM)


def compare(compare_config: CompareConfig, run_args: Sequence[str]) -> list[dict]:
    """Runs every job and writes the results table; returns its rows.

    Raises:
        ValueError: On a bad option (nothing is run).
        UserError: If a run fails, once every other run has finished (rerun to resume); every failed
            run and its log are named.
    """
    if compare_config.jobs is not None and compare_config.jobs < 1:
        raise UserError(f"--jobs must be >= 1, got {compare_config.jobs}.")
    if not compare_config.methods or not compare_config.seeds:
        raise UserError("--methods and --seeds must not be empty.")
    known = ("bc", *scheduling_methods())
    unknown = [method for method in compare_config.methods if method not in known]
    if unknown:
        raise UserError(f"Unknown method(s) {unknown} in --methods; choose among {list(known)}.")
    from lerobot_mtdagger.envs import suite_from_config
    from lerobot_mtdagger.studies.results import check_comparable, results_rows, write_results

    task_names = suite_from_config(base_run_config(run_args)).task_names
    jobs = jobs_for(compare_config, run_args, len(task_names))
    cores = default_worker_count()
    parallel = compare_config.jobs or cores
    threads = max(1, cores // parallel)
    workers = 0 if threads < 2 else threads
    runs_dir = compare_config.output_dir / RUNS_DIR
    runs_dir.mkdir(parents=True, exist_ok=True)
    (compare_config.output_dir / COMPARE_FILE).write_text(
        json.dumps(
            {
                "methods": compare_config.methods,
                "seeds": compare_config.seeds,
                "jobs": [job.name for job in jobs],
                "run_args": list(run_args),
            },
            indent=1,
        )
    )
    folders = RunPool(runs_dir, parallel, threads, workers).run_all(jobs)
    rows = results_rows(folders)
    write_results(rows, compare_config.output_dir, task_names, configs=check_comparable(folders))
    return rows
