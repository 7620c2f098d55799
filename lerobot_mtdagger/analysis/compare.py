"""``lerobot-mtdagger compare``: every method over many seeds, as ordinary runs in a process pool.

Every (method, seed) and every (bc, seed, budget) is one ``lerobot-mtdagger run`` with the same run
options, in its own folder::

    <output_dir>/
        runs/need-seed0/          an ordinary experiment folder (verify, merge, report work on it)
        runs/bc-12demos-seed0/    BC with 12 expert demos per task
        compare.json              what was asked (methods, seeds, budgets, run options)
        results.csv, results.json one row per run x evaluated round (``results.py``)

Finished runs are skipped and cut-off ones resumed; with more ``--dagger.rounds`` the DAgger runs
are extended and BC added at the new budgets.
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

from lerobot_mtdagger.analysis.launchers import Job, RayRunPool, RunPool
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.option_groups import default_worker_count
from lerobot_mtdagger.scheduler import scheduling_methods
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.parsing import parse_options
from lerobot_mtdagger.utils.ray_session import import_ray

logger = logging.getLogger(__name__)

RUNS_DIR = "runs"
COMPARE_FILE = "compare.json"


@dataclass
class CompareConfig:
    """Options of ``lerobot-mtdagger compare`` (any other ``--option`` is passed to every run).

    Attributes:
        methods: Scheduling methods and ``bc``.
        seeds: Seeds; every method runs every seed.
        bc_budgets: BC expert demos per task (empty: DAgger's cumulative demos after each round).
        jobs: Runs at once with ``launcher=local`` (None: one per core).
        cores: Cores the local runs share (None: those this process may run on, e.g. under ``taskset``).
        output_dir: The compare folder (on storage every Ray node sees, with ``launcher=ray``).
        launcher: ``local`` (each run a process on this machine) or ``ray`` (each run a Ray task).
        ray_address: The Ray cluster of ``launcher=ray`` (``auto``, ``ray://host:10001``; None: a local Ray).
        ray_cpus_per_run: CPUs each run holds with ``launcher=ray`` (its threads and env workers).
        ray_gpus_per_run: GPUs each run holds with ``launcher=ray`` (0: none; with ``--policy.device=cuda``).
        share_round0: A DAgger run copies round 0 and phase 0 from a run of its seed that differs only in
            the scheduler (they are the same to the bit); false: every run makes its own.
    """

    HELP_FOOTER: ClassVar[str] = (
        "Every other option goes to each run (`lerobot-mtdagger run --help` lists them), except --seed, "
        "--mode, --scheduler.type, --output_dir and --resume, which compare sets per run."
    )

    methods: list[str] = field(default_factory=lambda: ["bc", "uniform", "need", "gain"])
    seeds: list[int] = field(default_factory=lambda: [0, 1, 2])
    bc_budgets: list[int] = field(default_factory=list)
    jobs: int | None = None
    cores: int | None = None
    output_dir: Path = Path("outputs/compare")
    launcher: str = "local"
    ray_address: str | None = None
    ray_cpus_per_run: int = 1
    ray_gpus_per_run: float = 0.0
    share_round0: bool = True

    def __post_init__(self) -> None:
        if self.launcher not in LAUNCHERS:
            raise ValueError(f"launcher must be one of {list(LAUNCHERS)}, got {self.launcher!r}.")
        if self.ray_cpus_per_run < 1 or self.ray_gpus_per_run < 0:
            raise ValueError(
                f"ray_cpus_per_run must be >= 1 and ray_gpus_per_run >= 0, got {self.ray_cpus_per_run}, "
                f"{self.ray_gpus_per_run}."
            )
        if self.launcher == "ray":
            import_ray()  # refuses a missing Ray before anything runs
        negative = [seed for seed in self.seeds if seed < 0]
        if negative or not self.seeds or len(set(self.seeds)) != len(self.seeds):
            raise ValueError(f"--seeds must be distinct seeds >= 0, got {self.seeds}.")


LAUNCHERS: tuple[str, ...] = ("local", "ray")
"""``local``: runs as processes on this machine; ``ray``: runs as Ray tasks on a Ray cluster."""


def split_arguments(argv: Sequence[str]) -> tuple[list[str], list[str]]:
    """Separates ``compare``'s own options from the run options passed through to every run."""
    own_names = {f"--{name}" for name in CompareConfig.__dataclass_fields__}
    own: list[str] = []
    passed: list[str] = []
    for arg in argv:
        (own if arg.split("=", 1)[0] in own_names else passed).append(arg)
    return own, passed


def base_run_config(run_args: Sequence[str]) -> RunConfig:
    """The run options every job shares, parsed once (ValueError if they set what ``compare`` decides)."""
    for arg in run_args:
        if arg.split("=", 1)[0] in ("--seed", "--mode", "--scheduler.type", "--output_dir", "--resume"):
            raise UserError(f"{arg} is set per run by compare: use --methods/--seeds/--output_dir.")
    return parse_options(RunConfig, run_args, "lerobot-mtdagger run")


def bc_rounds_for(config: RunConfig, budgets: Sequence[int], num_tasks: int) -> dict[int, int]:
    """BC budget (demos per task) -> the ``--dagger.rounds`` that gives it (ValueError if none does)."""
    dagger = config.dagger
    # RunConfig fills both from its preset
    assert dagger.rounds is not None and dagger.initial_demos is not None
    per_round = dagger.budget_for(num_tasks) / num_tasks
    if not budgets:
        return {int(dagger.initial_demos + k * per_round): k for k in range(dagger.rounds + 1)}
    mapping = {}
    for budget in budgets:
        k = (budget - dagger.initial_demos) / per_round
        if k < 0 or k != int(k):
            valid = [int(dagger.initial_demos + j * per_round) for j in range(dagger.rounds + 4)]
            raise UserError(
                f"BC budget {budget} demos per task is not initial_demos + k * budget per task "
                f"({dagger.initial_demos} + k * {per_round:g}); choose among {valid}..."
            )
        mapping[int(budget)] = int(k)
    return mapping


def jobs_for(compare: CompareConfig, run_args: Sequence[str], num_tasks: int) -> list[Job]:
    """Every run of the comparison, with the same seeds and run options for every method."""
    config = base_run_config(run_args)
    assert config.dagger.rounds is not None  # RunConfig fills it from its preset
    jobs = []
    for seed in compare.seeds:
        for method in compare.methods:
            if method != "bc":
                name = f"{method}-seed{seed}"
                args = (*run_args, f"--scheduler.type={method}", f"--seed={seed}")
                jobs.append(Job(name, args, last_phase=config.dagger.rounds))
                continue
            for budget, rounds in sorted(bc_rounds_for(config, compare.bc_budgets, num_tasks).items()):
                name = f"bc-{budget}demos-seed{seed}"
                args = (*run_args, "--mode=bc", f"--dagger.rounds={rounds}", f"--seed={seed}")
                jobs.append(Job(name, args, last_phase=0))
    return jobs


def runs_not_started(compare_dir: Path) -> list[str]:
    """The runs ``compare.json`` plans without a folder under ``runs/`` (``UserError`` if not a plan)."""
    path = Path(compare_dir) / COMPARE_FILE
    if not path.is_file():
        return []
    try:
        jobs = json.loads(path.read_text())["jobs"]
    except (json.JSONDecodeError, KeyError, TypeError) as error:
        raise UserError(f"{path} is not a compare plan ({error!r}); rerun compare to rewrite it.") from None
    return [name for name in jobs if not (Path(compare_dir) / RUNS_DIR / name).is_dir()]


def run_resources(
    compare_config: CompareConfig, run_args: Sequence[str], environ: Mapping[str, str]
) -> tuple[int, int, int | None]:
    """Runs at once, torch threads and env workers per run of a local ``compare``.

    The cores (``--cores``, else those ``taskset`` allows) are split among the ``--jobs``, fewer threads
    if ``OMP_NUM_THREADS`` says so (a ``UserError`` if it is not a positive whole number): more threads
    than cores train many times slower. Returns ``(parallel, threads, workers)``; workers match the
    threads (0 below 2), None where the run options set ``--rollout.workers``.
    """
    cores = compare_config.cores or default_worker_count()
    parallel = compare_config.jobs or cores
    threads = max(1, cores // parallel)
    asked = environ.get("OMP_NUM_THREADS", "").strip()
    if asked:
        if not asked.isdigit() or int(asked) < 1:
            raise UserError(f"OMP_NUM_THREADS={asked!r} is not a positive whole number; unset it or fix it.")
        threads = min(threads, int(asked))
    chosen = any(arg.split("=", 1)[0] == "--rollout.workers" for arg in run_args)
    workers = None if chosen else (0 if threads < 2 else threads)
    logger.info(
        "%d run(s) at once on %d core(s): %d torch thread(s) and %s env worker(s) each",
        parallel,
        cores,
        threads,
        "the run options'" if workers is None else workers,
    )
    return parallel, threads, workers


def compare(compare_config: CompareConfig, run_args: Sequence[str]) -> list[dict]:
    """Runs every job and writes the results table; returns its rows.

    Raises:
        ValueError: On a bad option (nothing is run).
        UserError: If a run fails, once every other run has finished, naming each and its log.
    """
    if compare_config.jobs is not None and compare_config.jobs < 1:
        raise UserError(f"--jobs must be >= 1, got {compare_config.jobs}.")
    if compare_config.cores is not None and compare_config.cores < 1:
        raise UserError(f"--cores must be >= 1, got {compare_config.cores}.")
    if not compare_config.methods or not compare_config.seeds:
        raise UserError("--methods and --seeds must not be empty.")
    known = ("bc", *scheduling_methods())
    unknown = [method for method in compare_config.methods if method not in known]
    if unknown:
        raise UserError(f"Unknown method(s) {unknown} in --methods; choose among {list(known)}.")
    from lerobot_mtdagger.analysis.results import check_comparable, results_rows, write_results
    from lerobot_mtdagger.envs import suite_from_config

    task_names = suite_from_config(base_run_config(run_args).suite).task_names
    jobs = jobs_for(compare_config, run_args, len(task_names))
    parallel, threads, workers = run_resources(compare_config, run_args, os.environ)
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
    pool: RunPool | RayRunPool
    if compare_config.launcher == "ray":
        pool = RayRunPool(
            runs_dir,
            compare_config.ray_cpus_per_run,
            compare_config.ray_gpus_per_run,
            compare_config.ray_address,
            compare_config.share_round0,
        )
    else:
        pool = RunPool(runs_dir, parallel, threads, workers, compare_config.share_round0)
    folders = pool.run_all(jobs)
    rows = results_rows(folders)
    write_results(rows, compare_config.output_dir, task_names, configs=check_comparable(folders))
    return rows
