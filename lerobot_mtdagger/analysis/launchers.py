"""Launchers of a ``compare`` grid: each planned run as a process on this machine, or as a Ray task.

Both skip finished runs, resume cut-off ones, let one failed run stop none of the others, and on
Ctrl-C end the running ones. Several ``compare`` processes may share one folder: each skips the runs
another has finished or is writing, and then ends with an error naming those, having written no table.
"""

from __future__ import annotations

import logging
import os
import subprocess
import sys
import threading
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor, wait
from dataclasses import dataclass
from pathlib import Path
from typing import Any, cast

from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.parent import PARENT_PID_ENV
from lerobot_mtdagger.utils.ray_session import connect

logger = logging.getLogger(__name__)


class RunHeldError(UserError):
    """Another process is writing the run (a second ``compare`` on the same folder): it was skipped."""


def check_not_held(folder: Path, name: str) -> None:
    """Refuses to start a run another process is writing (``RunHeldError`` naming its pid)."""
    from lerobot_mtdagger.datasets.experiment_dir import writer_lock_holder

    holder = writer_lock_holder(folder)
    if holder is not None:
        logger.info("%s: being written by another process (pid %s), skipped", name, holder)
        raise RunHeldError(f"{name} (pid {holder})")


def raise_for_errors(errors: Sequence[UserError], total: int) -> None:
    """Raises the ``UserError`` a pool ends with, naming each failed run first, else each held one."""
    held = [str(error) for error in errors if isinstance(error, RunHeldError)]
    failed = [str(error) for error in errors if not isinstance(error, RunHeldError)]
    skipped = f" Skipped, being written by another process: {', '.join(held)}." if held else ""
    if failed:
        raise UserError(
            f"{len(failed)} of {total} runs failed; the others finished. Fix the cause and run the same "
            "compare again to resume: " + " ".join(failed) + skipped
        )
    if held:
        raise UserError(
            f"{len(held)} of {total} runs are being written by another process (another compare on this "
            f"folder?) and were skipped; nothing failed: {', '.join(held)}. Run the same compare again "
            "once that process has ended, to tabulate every run."
        )


@dataclass(frozen=True)
class Job:
    """One run of the comparison."""

    name: str
    args: tuple[str, ...]
    last_phase: int


def is_finished(folder: Path, last_phase: int) -> bool:
    """Whether the run in ``folder`` committed its phases up to ``last_phase`` (else a resume extends it)."""
    from lerobot_mtdagger.datasets.experiment_dir import (  # LeRobot: loaded only when needed
        CONFIG_FILE,
        ExperimentDir,
    )

    if not (folder / CONFIG_FILE).exists():
        return False
    return last_phase in ExperimentDir(folder).committed_phases()


def job_command(
    job: Job, folder: Path, threads: int, workers: int | None
) -> tuple[list[str], dict[str, str]]:
    """One job's ``run`` command (resumed if started) and thread variables (``workers`` None: the job's)."""
    from lerobot_mtdagger.datasets.experiment_dir import CONFIG_FILE

    resume = ["--resume=true"] if (folder / CONFIG_FILE).exists() else []
    arguments = run_arguments(job, folder, workers)
    command = [sys.executable, "-m", "lerobot_mtdagger.cli", "run", *arguments, *resume]
    return command, {"OMP_NUM_THREADS": str(threads), "MKL_NUM_THREADS": str(threads)}


def run_arguments(job: Job, folder: Path, workers: int | None) -> list[str]:
    """The ``lerobot-mtdagger run`` options of one job in ``folder`` (``--resume`` aside)."""
    return [
        *job.args,
        f"--output_dir={folder}",
        *([] if workers is None else [f"--rollout.workers={workers}"]),
        "--progress=false",
    ]


def start_from_shared_round_zero(job: Job, folder: Path, workers: int | None) -> None:
    """Copies into a job not started yet a shared round 0 and phase 0 (``analysis/round_zero.py``).

    Raises:
        UserError: On bad run options, or if another process started writing ``folder`` meanwhile.
    """
    from lerobot_mtdagger.analysis.round_zero import share_round_zero  # LeRobot: loaded only when needed

    share_round_zero(folder, run_arguments(job, folder, workers))


class RunPool:
    """The runs of one ``compare``, ``parallel`` at once, each in its own process (``--launcher=local``).

    Args:
        runs_dir: The compare folder's ``runs/``.
        parallel: Runs at once.
        threads: Torch threads per run.
        workers: Env worker processes per run (None: the run options choose).
        share_round0: Start a DAgger run from a shared round 0 (``start_from_shared_round_zero``).
    """

    def __init__(
        self, runs_dir: Path, parallel: int, threads: int, workers: int | None, share_round0: bool = True
    ) -> None:
        self.runs_dir = runs_dir
        self.parallel = parallel
        self.threads = threads
        self.workers = workers
        self.share_round0 = share_round0
        self._lock = threading.Lock()
        self._live: set[subprocess.Popen] = set()
        self._stopping = False

    def run_all(self, jobs: Sequence[Job]) -> list[Path]:
        """Runs (or resumes, or skips) every job; returns the run folders in the order of ``jobs``.

        Raises:
            UserError: Once every job has ended, if any run failed, naming each and its log.
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
        errors = [error for error in (future.exception() for future in futures) if error is not None]
        for error in errors:
            if not isinstance(error, UserError):
                raise error  # a fault of this code rather than of one run: keep its traceback
        raise_for_errors(cast("list[UserError]", errors), len(jobs))  # the others were raised above
        return [future.result() for future in futures]

    def run_one(self, job: Job) -> Path:
        """Runs (or resumes, or skips) one job in its own process; returns its folder.

        Raises:
            UserError: If the run fails, or the pool was interrupted before it started.
            RunHeldError: If another process is writing the run.
        """
        folder = self.runs_dir / job.name
        if is_finished(folder, job.last_phase):
            logger.info("%s: finished, skipped", job.name)
            return folder
        check_not_held(folder, job.name)
        if self.share_round0 and not self._stopping:
            start_from_shared_round_zero(job, folder, self.workers)
        command, variables = job_command(job, folder, self.threads, self.workers)
        env = {**os.environ, **variables, PARENT_PID_ENV: str(os.getpid())}
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


def run_job_process(command: list[str], variables: dict[str, str], log_path: str) -> int:
    """Runs one job's command, output appended to ``log_path``, ending with it; returns its exit code."""
    env = {**os.environ, **variables, PARENT_PID_ENV: str(os.getpid())}
    with open(log_path, "a") as log:
        process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT, env=env)
        try:
            return process.wait()
        finally:
            if process.poll() is None:  # cancelled (KeyboardInterrupt in the task): end the run
                process.terminate()
                process.wait()


class RayRunPool:
    """The runs of one ``compare`` as Ray tasks (``--launcher=ray``), as many at once as the cluster allows.

    Every node must see the compare folder and this package's interpreter at the same paths.

    Args:
        runs_dir: The compare folder's ``runs/``.
        cpus: CPUs per run (its torch threads and, from 2, its env workers).
        gpus: GPUs per run (0: none; a fraction shares one).
        address: The Ray cluster (None: a local Ray; ``UserError`` if there is none).
        share_round0: Start a DAgger run from a shared round 0 committed before this ``compare``.
    """

    def __init__(
        self, runs_dir: Path, cpus: int, gpus: float, address: str | None, share_round0: bool = True
    ) -> None:
        self.runs_dir = runs_dir
        self.share_round0 = share_round0
        self.cpus = cpus
        self.gpus = gpus
        self.ray = connect(address)

    def run_all(self, jobs: Sequence[Job]) -> list[Path]:
        """Runs (or resumes, or skips) every job; returns the run folders in the order of ``jobs``.

        Raises:
            UserError: Once every job has ended, if any run failed, naming each and its log.
        """
        ray = self.ray
        task = ray.remote(num_cpus=self.cpus, num_gpus=self.gpus, max_retries=0)(run_job_process)
        workers = 0 if self.cpus < 2 else self.cpus
        submitted: dict[Any, Job] = {}
        held: list[UserError] = []
        for job in jobs:
            folder = self.runs_dir / job.name
            if is_finished(folder, job.last_phase):
                logger.info("%s: finished, skipped", job.name)
                continue
            try:
                check_not_held(folder, job.name)
            except RunHeldError as error:
                held.append(error)
                continue
            if self.share_round0:
                start_from_shared_round_zero(job, folder, workers)
            command, variables = job_command(job, folder, self.cpus, workers)
            log_path = str(self.runs_dir / f"{job.name}.log")
            submitted[task.remote(command, variables, log_path)] = job
        try:
            outcomes = [self._outcome(reference, job) for reference, job in submitted.items()]
        except BaseException:
            for reference in submitted:
                ray.cancel(reference)
            logger.warning("compare interrupted: the Ray tasks were cancelled; the running runs ended.")
            raise
        errors = [UserError(error) for error in outcomes if error is not None]
        raise_for_errors([*errors, *held], len(jobs))
        return [self.runs_dir / job.name for job in jobs]

    def _outcome(self, reference: Any, job: Job) -> str | None:
        """None when the run of ``job`` succeeded, else what went wrong (naming its log)."""
        log_path = self.runs_dir / f"{job.name}.log"
        try:
            returncode = self.ray.get(reference)
        except self.ray.exceptions.RayError as error:
            kind = type(error).__name__
            return f"Run {job.name} lost its Ray task ({kind}: node or worker gone?); see {log_path}."
        if returncode != 0:
            return f"Run {job.name} failed (exit {returncode}); see {log_path}."
        return None
