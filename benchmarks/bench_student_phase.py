"""What a training phase costs besides its steps, per student: the phase against its bare steps.

Each configuration is one ``run --mode=bc --dagger.rounds=0`` (one phase on the round-0 demonstrations,
one evaluation episode per task) in its own process under ``/usr/bin/time``; the phase's record
(``training.json``, ``timings``) splits its ``train_s`` into the bare optimiser steps (``steps_s``),
the per-task loss measured before and after them (``task_loss_s``) and the rest (setup, saving). The
table puts them side by side with the process's peak memory (max RSS).

Usage::

    MUJOCO_GL=egl .venv/bin/python benchmarks/bench_student_phase.py            # toy, 5 steps
    MUJOCO_GL=egl .venv/bin/python benchmarks/bench_student_phase.py --suite metaworld-mt10 --steps 5

Configurations: ``mtdagger``; ACT and Diffusion Policy with LeRobot's defaults (at the preset's batch
size) and with the small options of ``docs/policy.md``. ``--only NAME`` runs one of them.
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

CONFIGS: dict[str, list[str]] = {
    "mtdagger": [],
    "act (docs' small options)": [
        "--policy.type=act",
        "--policy.chunk_size=10",
        "--policy.n_action_steps=5",
        "--policy.optimizer_lr=1e-4",
    ],
    "act (LeRobot defaults)": ["--policy.type=act"],
    "diffusion (docs' small options)": [
        "--policy.type=diffusion",
        "--policy.horizon=16",
        "--policy.n_action_steps=8",
        "--policy.num_inference_steps=10",
    ],
    "diffusion (LeRobot defaults)": ["--policy.type=diffusion"],
}


def run_phase(suite: str, steps: int, options: list[str], timeout: int) -> dict:
    """One phase in its own process: its timings and the process's peak memory (None on a timeout)."""
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "run"
        command = [
            "/usr/bin/time",
            "-f",
            "maxrss_kb=%M",
            sys.executable,
            "-m",
            "lerobot_mtdagger.cli",
            "run",
            f"--suite.name={suite}",
            "--mode=bc",
            "--dagger.rounds=0",
            f"--training.steps_per_round={steps}",
            "--rollout.eval_episodes=1",
            "--rollout.workers=0",
            "--progress=false",
            f"--output_dir={out}",
            *options,
        ]
        try:
            done = subprocess.run(command, capture_output=True, text=True, timeout=timeout, check=True)
        except subprocess.TimeoutExpired:
            return {"timeout": timeout}
        timings = json.loads((out / "policies" / "round-000" / "training.json").read_text())["timings"]
        rss = re.search(r"maxrss_kb=(\d+)", done.stderr)
        timings["maxrss_gb"] = int(rss.group(1)) / 1e6 if rss else None
        return timings


def row(name: str, measured: dict) -> str:
    """One table row: steps, per-task loss, phase, phase / steps, evaluation, peak memory."""
    if "timeout" in measured:
        return f"| {name} | - | - | > {measured['timeout']} s (cut) | - | - | - |"
    steps, loss, phase = measured["steps_s"], measured["task_loss_s"], measured["train_s"]
    return (
        f"| {name} | {steps:.2f} | {loss:.2f} | {phase:.2f} | {phase / steps:.1f} | "
        f"{measured['eval_s']:.1f} | {measured['maxrss_gb']:.1f} |"
    )


def main() -> None:
    """Runs every configuration and prints the table."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--suite", default="toy")
    parser.add_argument("--steps", type=int, default=5)
    parser.add_argument("--timeout", type=int, default=600, help="seconds a configuration may take")
    parser.add_argument("--only", default=None, help="one configuration's name")
    parser.add_argument(
        "--extra", nargs="*", default=[], help="options added to every run, e.g. --policy.batch_size=8"
    )
    options = parser.parse_args()
    batch = " ".join(options.extra) or "the preset's batch size"
    print(f"{options.suite}, one BC phase of {options.steps} steps, {batch}:\n")
    print("| student | steps_s | task_loss_s | phase train_s | phase / steps | eval_s | max RSS (GB) |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name, extra in CONFIGS.items():
        if options.only is not None and name != options.only:
            continue
        measured = run_phase(options.suite, options.steps, [*extra, *options.extra], options.timeout)
        print(row(name, measured), flush=True)


if __name__ == "__main__":
    main()
