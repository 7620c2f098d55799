"""Peak memory of a run's training phases: this checkout against another one, side by side.

Replays the training side of ``lerobot-mtdagger run`` on the rounds an experiment folder already
holds (for example the one ``bench_run.py --preset=metaworld-pixels`` leaves): for each round k, the
rounds 0..k are read through ``RoundCache`` as the run reads them, and ``train_on_rounds`` builds
the phase (statistics, normalisation, the previous policy's per-task losses) warm-started from the
experiment's stored policy of round k-1 and trains ``--steps`` steps. Collection and evaluation are
not replayed (their env workers are other processes).

Each checkout runs in a fresh process of its own (``PYTHONPATH``), one after the other; printed: per
phase the process's resident memory after it, and the peak (``ru_maxrss``) of each checkout, with
the ratio. Target: the peak of this checkout at most ``TARGET`` x the baseline's on the pixel preset
(the baseline: the code before the rounds' images were held once, 2026-11-26).

Usage::

    git worktree add --detach ../baseline-code b8ed0e7
    .venv/bin/python benchmarks/bench_memory.py --experiment outputs/bench/metaworld-pixels \\
        --baseline ../baseline-code -- --preset=metaworld-pixels

Options after ``--`` are the run's own (those it was started with, but ``--output_dir``).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_run import _rss_kb  # noqa: E402

TARGET = 0.7
REPO = Path(__file__).resolve().parents[1]


def replay(experiment: Path, run_options: list[str], steps: int, rounds: int | None) -> dict:
    """The training phases of ``experiment`` in this process; their memory and load times."""
    import lerobot_mtdagger
    from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
    from lerobot_mtdagger.envs import suite_from_config
    from lerobot_mtdagger.runner.configs import RunConfig
    from lerobot_mtdagger.runner.training.train import RoundCache, student_config, train_on_rounds
    from lerobot_mtdagger.utils.parsing import parse_options

    options = [*run_options, f"--output_dir={experiment}", f"--training.steps_per_round={steps}"]
    config = parse_options(RunConfig, options, "bench_memory")
    suite = suite_from_config(config.suite)
    policy_cfg = student_config(config, suite.features, suite.task_names, bool(suite.heldout_task_names))
    store = ExperimentDir(experiment)
    committed = store.committed_rounds()
    last = len(committed) if rounds is None else min(rounds, len(committed))
    cache = RoundCache()
    phases = []
    for k in range(last):
        start = time.perf_counter()
        data = cache.load([store.round_root(i) for i in range(k + 1)], list(policy_cfg.input_features))
        previous = store.policy_root(k - 1) if k > 0 else None
        trained = train_on_rounds(config, policy_cfg, data, k, previous)
        phases.append(
            {
                "round": k,
                "frames": len(data),
                "load_and_prepare_s": round(time.perf_counter() - start - trained.train_s, 1),
                "rss_after_mib": round(_rss_kb(os.getpid()) / 1024),
                "peak_so_far_mib": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024),
            }
        )
        del data, trained
    return {"code": str(Path(lerobot_mtdagger.__file__).parents[1]), "phases": phases}


def run_checkout(code: Path, args: argparse.Namespace) -> dict:
    """``replay`` in a fresh process importing ``lerobot_mtdagger`` from ``code``."""
    command = [
        sys.executable,
        __file__,
        "--worker",
        "--experiment",
        str(args.experiment),
        "--steps",
        str(args.steps),
    ]
    if args.rounds is not None:
        command += ["--rounds", str(args.rounds)]
    env = {**os.environ, "PYTHONPATH": str(code), "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    output = subprocess.run(
        [*command, "--", *args.run_options], env=env, check=True, capture_output=True, text=True
    ).stdout
    return json.loads(output.strip().splitlines()[-1])


def report(results: dict[str, dict]) -> bool:
    """Prints the per-phase table and the peak ratio; True when the target holds."""
    names = list(results)
    columns = " | ".join(f"{n} RSS after (MiB) | {n} load+prepare (s)" for n in names)
    print(f"| round | frames | {columns} |")
    print("|---:|---:|" + "---:|---:|" * len(names))
    for row in zip(*(results[n]["phases"] for n in names), strict=True):
        cells = " | ".join(f"{p['rss_after_mib']} | {p['load_and_prepare_s']}" for p in row)
        print(f"| {row[0]['round']} | {row[0]['frames']} | {cells} |")
    peaks = {n: results[n]["phases"][-1]["peak_so_far_mib"] for n in names}
    for name in names:
        print(f"{name} ({results[name]['code']}): peak RSS {peaks[name]} MiB")
    if "baseline" not in peaks:
        return True
    ratio = peaks["this"] / peaks["baseline"]
    verdict = "PASS" if ratio <= TARGET else "FAIL"
    print(f"{verdict}: peak this / baseline = {ratio:.2f} (target <= {TARGET})")
    return ratio <= TARGET


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--experiment", type=Path, required=True, help="An experiment folder with rounds.")
    parser.add_argument("--baseline", type=Path, help="A checkout of the code to compare with.")
    parser.add_argument("--steps", type=int, default=20, help="Optimiser steps per phase.")
    parser.add_argument("--rounds", type=int, help="Replay the first ROUNDS rounds only (default all).")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("run_options", nargs="*", help="The run's options, after --.")
    args = parser.parse_args()
    if args.worker:
        print(json.dumps(replay(args.experiment, args.run_options, args.steps, args.rounds)))
        return
    results = {}
    if args.baseline is not None:
        results["baseline"] = run_checkout(args.baseline.resolve(), args)
    results["this"] = run_checkout(REPO, args)
    sys.exit(0 if report(results) else 1)


if __name__ == "__main__":
    main()
