"""Training step cost: ``train_phase`` against a bare PyTorch loop of the same network.

Both loops train the default-size ``mtdagger`` network (39-d state, 10 tasks, 4-d actions, task
embedding 32, state MLP 2x256, head 2x256) on the same in-memory frames with batch 256, AdamW with the
same settings and the same gradient clipping. The bare loop samples random indices from in-memory
tensors and calls the modules directly; ``train_phase`` runs on ``NormalisedData``. The runs are
interleaved (the order alternates per repeat) and the medians compared; the target is
``train_phase <= 1.3 x bare``.

Per-step times are steady state: measured from the end of the first log interval to the end of the
run (the bare loop: after the same number of warm-up steps). The whole ``train_phase`` call (with its
start/end per-task loss measurement and setup) is shown as well.

With ``--experiment PATH`` it also times reading each committed round of that experiment, with
``load_round`` (pyarrow) and with ``LeRobotDataset`` (the former path), and the in-memory
concatenation a phase does.

The step is compute-bound on a CPU (about 0.4 GFLOP of matmuls per step), so one torch thread gives
the steadiest comparison on a shared machine; ``--threads 0`` keeps torch's default.

Usage::

    MUJOCO_GL=egl .venv/bin/python benchmarks/bench_train.py --steps 300 --repeats 5
    MUJOCO_GL=egl .venv/bin/python benchmarks/bench_train.py --experiment outputs/toy-run
"""

from __future__ import annotations

import argparse
import json
import logging
import statistics
import time
from pathlib import Path

import numpy as np
import torch
from lerobot.configs.types import FeatureType, PolicyFeature

from lerobot_mtdagger.policies import MTDAggerConfig, MTDAggerPolicy
from lerobot_mtdagger.runner.training.normalise import NormalisedData, compute_stats
from lerobot_mtdagger.runner.training.round_data import TrainingData, load_round
from lerobot_mtdagger.runner.training.steps import LOG_INTERVAL, StepOptions, train_phase
from lerobot_mtdagger.students.mtdagger import build_processors

FRAMES = 12_000
STATE_DIM = 39
ACTION_DIM = 4
NUM_TASKS = 10
BATCH_SIZE = 256
LR = 3e-4
TARGET = 1.3


def synthetic_data(seed: int = 0) -> TrainingData:
    """12 000 frames of a 39-d state and a 4-d action over 10 tasks, 40 episodes of 300 frames."""
    generator = torch.Generator().manual_seed(seed)
    episode = torch.arange(FRAMES) // 300
    return TrainingData(
        inputs={"observation.state": torch.randn(FRAMES, STATE_DIM, generator=generator)},
        action=torch.rand(FRAMES, ACTION_DIM, generator=generator) * 2 - 1,
        task_index=episode % NUM_TASKS,
        episode_id=episode,
    )


def make_policy(seed: int) -> MTDAggerPolicy:
    """The default-size network with fresh weights drawn from ``seed``."""
    config = MTDAggerConfig(
        device="cpu",
        task_names=[f"task-{i}" for i in range(NUM_TASKS)],
        input_features={"observation.state": PolicyFeature(type=FeatureType.STATE, shape=(STATE_DIM,))},
        output_features={"action": PolicyFeature(type=FeatureType.ACTION, shape=(ACTION_DIM,))},
        optimizer_lr=LR,
        push_to_hub=False,
    )
    torch.manual_seed(seed)
    return MTDAggerPolicy(config)


def bare_loop(data: NormalisedData, steps: int, warmup: int, seed: int) -> tuple[float, float]:
    """A plain PyTorch loop over the same modules; returns (steady ms/step, whole-run ms/step)."""
    policy = make_policy(seed)
    embedding, encoder, head = policy.task_embedding, policy.encoders["observation_state"], policy.head
    state, action, task = data.vector["observation.state"], data.vector["action"], data.task_index
    parameters = list(policy.parameters())
    optimizer = torch.optim.AdamW(
        parameters, lr=LR, weight_decay=policy.config.optimizer_weight_decay, fused=True
    )
    clip = policy.config.optimizer_grad_clip_norm
    generator = torch.Generator().manual_seed(seed)
    start = time.perf_counter()
    steady = start
    for step in range(steps):
        if step == warmup:
            steady = time.perf_counter()
        index = torch.randint(len(state), (BATCH_SIZE,), generator=generator)
        prediction = head(torch.cat([embedding(task[index]), encoder(state[index])], dim=1))
        loss = torch.nn.functional.mse_loss(prediction, action[index])
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(parameters, clip, foreach=True)
        optimizer.step()
    end = time.perf_counter()
    return 1e3 * (end - steady) / (steps - warmup), 1e3 * (end - start) / steps


def ours(data: NormalisedData, steps: int, seed: int) -> tuple[float, float]:
    """``train_phase``; returns (steady ms/step, whole-call ms/step)."""
    policy = make_policy(seed)
    train_index = torch.arange(len(data.data))
    loss_index = torch.arange(0, len(data.data), 12)  # 1000 frames: the start/end measurement
    marks: list[tuple[int, float]] = []
    start = time.perf_counter()
    train_phase(
        policy,
        data,
        train_index,
        loss_index,
        StepOptions(steps=steps, batch_size=BATCH_SIZE, lr=LR, seed=seed),
        on_step=lambda done, loss: marks.append((done, time.perf_counter())),
    )
    end = time.perf_counter()
    (first_done, first_time), (last_done, last_time) = marks[0], marks[-1]
    return 1e3 * (last_time - first_time) / (last_done - first_done), 1e3 * (end - start) / steps


def bench_training(steps: int, repeats: int) -> bool:
    """Runs both loops interleaved and prints the table; True when the ratio meets the target."""
    if steps < 2 * LOG_INTERVAL:
        raise SystemExit(f"--steps must be >= {2 * LOG_INTERVAL} (two log intervals).")
    data = synthetic_data()
    policy = make_policy(0)
    stats = compute_stats(data, [])
    preprocessor, _ = build_processors(policy.config, stats)
    normalised = NormalisedData(data, preprocessor, [], policy.config.task_names)
    results: dict[str, list[tuple[float, float]]] = {"bare": [], "train_phase": []}
    for repeat in range(repeats):
        order = ["bare", "train_phase"] if repeat % 2 == 0 else ["train_phase", "bare"]
        for name in order:
            if name == "bare":
                results[name].append(bare_loop(normalised, steps, LOG_INTERVAL, seed=repeat))
            else:
                results[name].append(ours(normalised, steps, seed=repeat))
    print(
        f"frames {FRAMES}, state {STATE_DIM}-d, {NUM_TASKS} tasks, action {ACTION_DIM}-d, "
        f"batch {BATCH_SIZE}, "
        f"AdamW(lr={LR}, fused) + clip_grad_norm_(foreach), {steps} steps x {repeats} repeats, "
        f"torch {torch.__version__}, {torch.get_num_threads()} threads"
    )
    print(f"{'loop':<14}{'steady ms/step':>16}{'whole ms/step':>16}   steady per repeat")
    medians = {}
    for name, values in results.items():
        steady = [v[0] for v in values]
        whole = [v[1] for v in values]
        medians[name] = statistics.median(steady)
        per_repeat = " ".join(f"{v:.3f}" for v in steady)
        print(f"{name:<14}{medians[name]:>16.3f}{statistics.median(whole):>16.3f}   {per_repeat}")
    ratio = medians["train_phase"] / medians["bare"]
    passed = ratio <= TARGET
    print(f"ratio train_phase / bare = {ratio:.3f} (target <= {TARGET}): {'PASS' if passed else 'FAIL'}")
    return passed


def bench_loading(experiment: Path) -> None:
    """Times reading each committed round of ``experiment`` and the per-phase concatenation."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    roots = sorted(p for p in (experiment / "rounds").glob("round-*") if p.is_dir())
    if not roots:
        print(f"no committed round under {experiment / 'rounds'}")
        return
    features = json.loads((roots[0] / "meta" / "info.json").read_text())["features"]
    keys = [k for k in features if k.startswith("observation.")]
    print(f"\nround loading, {experiment}, inputs {keys}")
    print(f"{'round':<12}{'frames':>8}{'load_round ms':>15}{'LeRobotDataset ms':>19}{'concat 0..k ms':>16}")
    parts: list[TrainingData] = []
    for position, root in enumerate(roots):
        start = time.perf_counter()
        part = load_round(root, position, keys)
        loaded = time.perf_counter()
        dataset = LeRobotDataset(f"local/{root.name}", root=root)
        table = dataset.hf_dataset.with_format("numpy")
        for key in [*keys, "action", "task_index", "episode_index"]:
            np.asarray(table[key])  # the former path also decodes every column
        former = time.perf_counter()
        parts.append(part)
        TrainingData.concat(parts)
        concat = time.perf_counter()
        print(
            f"{root.name:<12}{len(part):>8}{1e3 * (loaded - start):>15.1f}"
            f"{1e3 * (former - loaded):>19.1f}{1e3 * (concat - former):>16.2f}"
        )


def main() -> None:
    """Parses the arguments and runs the benchmarks."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=300, help="training steps per run")
    parser.add_argument("--repeats", type=int, default=5, help="interleaved runs of each loop")
    parser.add_argument(
        "--threads",
        type=int,
        default=1,
        help="torch threads (1: steady on a shared machine; 0: torch's default)",
    )
    parser.add_argument("--experiment", type=Path, default=None, help="experiment to time round loads")
    args = parser.parse_args()
    logging.basicConfig(level=logging.WARNING)
    if args.threads > 0:
        torch.set_num_threads(args.threads)
    passed = bench_training(args.steps, args.repeats)
    if args.experiment is not None:
        bench_loading(args.experiment)
    raise SystemExit(0 if passed else 1)


if __name__ == "__main__":
    main()
