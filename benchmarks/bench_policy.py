"""Training throughput and batch-1 inference latency of the ``mtdagger`` policy (CPU, or ``--device``).

Run: ``.venv/bin/python benchmarks/bench_policy.py`` (``--device=cuda`` on a GPU; the timings then
wait for the device after each timed loop). Default model sizes; inputs as the suites emit
them: state (39-d), RGB 84 px + 7-d state, point cloud 1024 x 3 + 7-d state. The modes are measured
in interleaved rounds in one run, so their ratios are side by side. The DAgger loop queries the
policy every step, so the batch-1 latency bounds the collection rate.

``--precisions fp32,tf32,bf16`` measures each input at each arithmetic, interleaved in the same
rounds: ``fp32`` (the default), ``tf32`` (float32 tensors, TensorFloat-32 matrix products and
convolutions: ``torch.backends.cuda.matmul.allow_tf32`` and ``torch.backends.cudnn.allow_tf32``) and
``bf16`` (the forward pass under ``torch.autocast(dtype=torch.bfloat16)``, float32 weights and
optimiser). The ``vs fp32`` column is each input's rate over its rate at the first precision listed.
"""

from __future__ import annotations

import argparse
import contextlib
import statistics
import time
from collections.abc import Iterator

import torch
from lerobot.configs.types import FeatureType, PolicyFeature

from lerobot_mtdagger.policies import MTDAggerConfig, MTDAggerPolicy

TASKS = [f"task-{i}" for i in range(10)]
PROPRIO = PolicyFeature(type=FeatureType.STATE, shape=(7,))
MODES = {
    "state": {"observation.state": PolicyFeature(type=FeatureType.STATE, shape=(39,))},
    "rgb 84 px": {
        "observation.state": PROPRIO,
        "observation.image": PolicyFeature(FeatureType.VISUAL, (3, 84, 84)),
    },
    "pointcloud 1024": {
        "observation.state": PROPRIO,
        "observation.pointcloud": PolicyFeature(type=FeatureType.STATE, shape=(1024, 3)),
    },
}


PRECISIONS = ("fp32", "tf32", "bf16")


@contextlib.contextmanager
def precision(name: str, device: str) -> Iterator[None]:
    """Runs the block at the arithmetic ``name`` (one of ``PRECISIONS``, checked by ``parse_precisions``);
    restores the TF32 flags."""
    flags = torch.backends.cuda.matmul.allow_tf32, torch.backends.cudnn.allow_tf32
    torch.backends.cuda.matmul.allow_tf32 = torch.backends.cudnn.allow_tf32 = name == "tf32"
    autocast = (
        torch.autocast(torch.device(device).type, dtype=torch.bfloat16)
        if name == "bf16"
        else contextlib.nullcontext()
    )
    try:
        with autocast:
            yield
    finally:
        torch.backends.cuda.matmul.allow_tf32, torch.backends.cudnn.allow_tf32 = flags


def make_policy(inputs, device: str = "cpu") -> MTDAggerPolicy:
    config = MTDAggerConfig(
        device=device,
        task_names=TASKS,
        input_features=inputs,
        output_features={"action": PolicyFeature(type=FeatureType.ACTION, shape=(4,))},
    )
    return MTDAggerPolicy(config).to(device)


def make_batch(inputs, batch_size: int, device: str = "cpu") -> dict:
    batch = {k: torch.randn(batch_size, *ft.shape, device=device) for k, ft in inputs.items()}
    batch["action"] = torch.randn(batch_size, 4, device=device)
    batch["task"] = [TASKS[i % len(TASKS)] for i in range(batch_size)]
    return batch


def train_rate(policy, optimizer, batch, steps: int, arithmetic: str = "fp32") -> float:
    device = str(batch["action"].device)
    start = time.perf_counter()
    for _ in range(steps):
        with precision(arithmetic, device):
            loss, _ = policy.forward(batch)
        optimizer.zero_grad()
        loss.backward()
        optimizer.step()
    synchronize(batch["action"].device)
    return steps * len(batch["task"]) / (time.perf_counter() - start)


def synchronize(device: torch.device) -> None:
    """Waits for the device's queued work (CUDA runs asynchronously)."""
    if device.type == "cuda":
        torch.cuda.synchronize(device)


def latency_ms(policy, batch, repeats: int, arithmetic: str = "fp32") -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        with precision(arithmetic, str(batch["action"].device)):  # select_action is no_grad itself
            policy.select_action(batch)
        synchronize(batch["action"].device)
        times.append(time.perf_counter() - start)
    return statistics.median(times) * 1e3


def parse_precisions(text: str) -> list[str]:
    """``fp32,bf16`` -> ``["fp32", "bf16"]``, each checked against ``PRECISIONS``."""
    names = [name.strip() for name in text.split(",") if name.strip()]
    unknown = [name for name in names if name not in PRECISIONS]
    if not names or unknown:
        raise argparse.ArgumentTypeError(f"--precisions takes a comma list of {', '.join(PRECISIONS)}")
    return names


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--batch-size", type=int, default=256)
    parser.add_argument("--steps", type=int, default=10)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--threads", type=int, default=torch.get_num_threads())
    parser.add_argument("--device", default="cpu", help="cpu, cuda or cuda:N")
    parser.add_argument("--precisions", type=parse_precisions, default=["fp32"], help="e.g. fp32,tf32,bf16")
    args = parser.parse_args()
    torch.manual_seed(0)
    torch.set_num_threads(args.threads)
    setups = {}
    for name, inputs in MODES.items():
        for arithmetic in args.precisions:
            policy = make_policy(inputs, args.device)
            optimizer = torch.optim.AdamW(policy.parameters(), lr=3e-4)
            batches = make_batch(inputs, args.batch_size, args.device), make_batch(inputs, 1, args.device)
            setups[name, arithmetic] = (policy, optimizer, *batches)
            train_rate(policy, optimizer, batches[0], 1, arithmetic)  # warm-up
    rates = {key: [] for key in setups}
    latencies = {key: [] for key in setups}
    for _ in range(args.rounds):
        for (name, arithmetic), (policy, optimizer, batch, single) in setups.items():
            policy.train()
            rates[name, arithmetic].append(train_rate(policy, optimizer, batch, args.steps, arithmetic))
            latencies[name, arithmetic].append(latency_ms(policy, single, 50, arithmetic))
    print(
        f"torch {torch.__version__}, {args.device}, {args.threads} threads, batch {args.batch_size}, "
        f"median of {args.rounds} rounds"
    )
    header = ["input", "precision", "params", "train samples/s", "vs state", "vs fp32", "batch-1 latency ms"]
    print("| " + " | ".join(header) + " |")
    print("|" + "|".join("---" for _ in header) + "|")
    first = args.precisions[0]
    reference = statistics.median(rates["state", first])
    for (name, arithmetic), (policy, *_rest) in setups.items():
        params = sum(p.numel() for p in policy.parameters())
        rate = statistics.median(rates[name, arithmetic])
        own = statistics.median(rates[name, first])
        latency = statistics.median(latencies[name, arithmetic])
        print(
            f"| {name:<16} | {arithmetic:<9} | {params:>8} | {rate:>15.0f} | {rate / reference:>8.3f} "
            f"| {rate / own:>7.3f} | {latency:>18.3f} |"
        )


if __name__ == "__main__":
    main()
