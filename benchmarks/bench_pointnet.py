"""What a point-cloud training step costs: bare PyTorch loops against the policy's own step.

Run: ``.venv/bin/python benchmarks/bench_pointnet.py [--threads 2] [--batch 64] [--rounds 3]``.

Each network is a PointNet (shared per-point MLP, max-pool over points, projection) joined to a
7-d state encoder (one linear layer to 64) and a 32-d task embedding, with the action head of the
``mtdagger`` policy (2 x 256), trained with AdamW on fixed random batches. Two encoder sizes:

- ``today``: the policy's default encoder (3-64-128-256, ReLU, projection 256);
- ``dp3``: DP3's encoder (3-64-128-256 with LayerNorm after each layer, projection to 64 with
  LayerNorm; 59 072 parameters), ``--policy.pointnet_layer_norm=true
  --policy.pointcloud_embedding_dim=64``.

Two ways to train each:

- ``bare``: a plain PyTorch loop (forward with ``max`` over points, MSE, backward, AdamW step);
- ``policy``: the ``mtdagger`` policy of the same layers, trained as ``train.train_phase`` trains it
  (``imitation_loss``, gradient clipping, the fused AdamW of ``make_optimizer``); its PointNet
  back-propagates through the winning points of the max-pool only (``max_pool_of_winners``).

The loops run in interleaved rounds and the medians are compared, so the ratios are side by side;
the absolute samples/s depend on the machine and on what else runs on it. Targets (the visual-speed
issue): the policy's step at DP3's size on 512 points trains at least 3x the bare loop of today's
encoder on 1 024 points, and within 1.3x of (here: not slower than 1.3x) the bare loop of its own
network.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import torch
from lerobot.configs.types import FeatureType, PolicyFeature
from torch import nn

from lerobot_mtdagger.policies import MTDAggerConfig, MTDAggerPolicy
from lerobot_mtdagger.students.mtdagger import make_optimizer

STATE_DIM, TASKS, TASK_DIM, ACTION_DIM = 7, 11, 32, 4


def point_encoder(dims: tuple[int, ...], layer_norm: bool, output_dim: int) -> nn.Sequential:
    """Per-point MLP (ReLU between layers; LayerNorm + ReLU after each with ``layer_norm``)."""
    layers: list[nn.Module] = []
    previous = 3
    for index, width in enumerate(dims):
        layers.append(nn.Linear(previous, width))
        if layer_norm:
            layers += [nn.LayerNorm(width), nn.ReLU()]
        elif index < len(dims) - 1:
            layers.append(nn.ReLU())
        previous = width
    return nn.Sequential(*layers)


class StudentNet(nn.Module):
    """PointNet + state encoder + task embedding + action head."""

    def __init__(self, dims: tuple[int, ...], layer_norm: bool, output_dim: int) -> None:
        super().__init__()
        self.points = point_encoder(dims, layer_norm, output_dim)
        projection: list[nn.Module] = [nn.Linear(dims[-1], output_dim)]
        self.projection = nn.Sequential(
            *(projection + [nn.LayerNorm(output_dim)] if layer_norm else [nn.ReLU(), *projection])
        )
        self.state = nn.Linear(STATE_DIM, 64)
        self.task = nn.Embedding(TASKS, TASK_DIM)
        self.head = nn.Sequential(
            nn.Linear(output_dim + 64 + TASK_DIM, 256),
            nn.ReLU(),
            nn.Linear(256, 256),
            nn.ReLU(),
            nn.Linear(256, ACTION_DIM),
        )

    def forward(self, points: torch.Tensor, state: torch.Tensor, task: torch.Tensor) -> torch.Tensor:
        """(B, N, 3), (B, 7), (B,) -> (B, 4)."""
        cloud = self.projection(self.points(points).max(dim=1).values)
        return self.head(torch.cat([cloud, self.state(state), self.task(task)], dim=-1))

    def encoder_parameters(self) -> int:
        """Parameters of the point-cloud encoder (per-point MLP and projection)."""
        return sum(p.numel() for p in [*self.points.parameters(), *self.projection.parameters()])


ENCODERS = {"today": ((64, 128, 256), False, 256), "dp3": ((64, 128, 256), True, 64)}
"""Encoder name -> (per-point sizes, LayerNorm, projection size)."""

CASES = [
    ("bare", "today", 1024),
    ("bare", "today", 512),
    ("bare", "dp3", 512),
    ("policy", "today", 1024),
    ("policy", "today", 512),
    ("policy", "dp3", 512),
]
"""(training loop, encoder, points) measured; the first is the baseline of every ratio."""

SPEED_TARGET = 3.0
OVERHEAD_TARGET = 1.3


def policy_of(encoder: str, points: int) -> MTDAggerPolicy:
    """The ``mtdagger`` policy with the layers of ``StudentNet`` for ``encoder``."""
    dims, layer_norm, output_dim = ENCODERS[encoder]
    config = MTDAggerConfig(
        device="cpu",
        task_names=[f"task-{i}" for i in range(TASKS)],
        input_features={
            "observation.state": PolicyFeature(type=FeatureType.STATE, shape=(STATE_DIM,)),
            "observation.pointcloud": PolicyFeature(type=FeatureType.STATE, shape=(points, 3)),
        },
        output_features={"action": PolicyFeature(type=FeatureType.ACTION, shape=(ACTION_DIM,))},
        state_hidden_dims=(),
        state_embedding_dim=64,
        task_embedding_dim=TASK_DIM,
        pointnet_dims=dims,
        pointcloud_embedding_dim=output_dim,
        pointnet_layer_norm=layer_norm,
        head_hidden_dims=(256, 256),
        push_to_hub=False,
    )
    return MTDAggerPolicy(config)


def random_batch(points: int, batch: int, seed: int) -> dict[str, torch.Tensor]:
    """One fixed random batch."""
    generator = torch.Generator().manual_seed(seed)
    return {
        "observation.pointcloud": torch.randn(batch, points, 3, generator=generator),
        "observation.state": torch.randn(batch, STATE_DIM, generator=generator),
        "task_index": torch.randint(0, TASKS, (batch,), generator=generator),
        "action": torch.randn(batch, ACTION_DIM, generator=generator),
    }


def timed(step: Callable[[], None], steps: int, batch: int) -> float:
    """Samples/s of ``steps`` calls of ``step`` (3 warm-up calls not timed)."""
    for _ in range(3):
        step()
    start = time.perf_counter()
    for _ in range(steps):
        step()
    return steps * batch / (time.perf_counter() - start)


def bare_step(net: StudentNet, data: dict[str, torch.Tensor]) -> Callable[[], None]:
    """A plain PyTorch training step of ``net`` on ``data``."""
    optimizer = torch.optim.AdamW(net.parameters(), lr=1e-3)

    def step() -> None:
        prediction = net(data["observation.pointcloud"], data["observation.state"], data["task_index"])
        loss = ((prediction - data["action"]) ** 2).mean()
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        optimizer.step()

    return step


def policy_step(policy: MTDAggerPolicy, data: dict[str, torch.Tensor]) -> Callable[[], None]:
    """The policy's training step as ``train.train_phase`` takes it."""
    optimizer = make_optimizer(policy, 1e-3)
    parameters = [p for p in policy.parameters() if p.requires_grad]
    policy.train()

    def step() -> None:
        loss = policy.imitation_loss(data, task_index=data["task_index"])
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(parameters, policy.config.optimizer_grad_clip_norm, foreach=True)
        optimizer.step()

    return step


def case_name(case: tuple[str, str, int]) -> str:
    """``bare today 1024`` and so on."""
    return " ".join(str(part) for part in case)


def main() -> None:
    """Prints samples/s per case, the ratios to the baseline and the targets' verdicts."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--batch", type=int, default=64)
    parser.add_argument("--steps", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    torch.manual_seed(args.seed)
    steps, params = {}, {}
    for case in CASES:
        kind, encoder, points = case
        data = random_batch(points, args.batch, args.seed)
        if kind == "bare":
            net = StudentNet(*ENCODERS[encoder])
            steps[case], params[case] = bare_step(net, data), net.encoder_parameters()
        else:
            policy = policy_of(encoder, points)
            encoder_module = policy.encoders["observation_pointcloud"]
            steps[case] = policy_step(policy, data)
            params[case] = sum(p.numel() for p in encoder_module.parameters())
    rates: dict[tuple[str, str, int], list[float]] = {case: [] for case in CASES}
    for _ in range(args.rounds):
        for case in CASES:
            rates[case].append(timed(steps[case], args.steps, args.batch))
    median = {case: statistics.median(values) for case, values in rates.items()}
    base = median[CASES[0]]
    print(f"| case | encoder params | samples/s (batch {args.batch}, {args.threads} threads) | ratio |")
    print("|---|---:|---:|---:|")
    for case in CASES:
        print(f"| {case_name(case)} | {params[case]} | {median[case]:.0f} | {median[case] / base:.2f}x |")
    speed = median[("policy", "dp3", 512)] / base
    overhead = median[("bare", "dp3", 512)] / median[("policy", "dp3", 512)]
    verdict = "PASS" if speed >= SPEED_TARGET else "FAIL"
    print(f"{verdict}: policy dp3 512 trains at {speed:.2f}x bare today 1024 (target >= {SPEED_TARGET})")
    verdict = "PASS" if overhead <= OVERHEAD_TARGET else "FAIL"
    print(
        f"{verdict}: step time policy dp3 512 / bare dp3 512 = {overhead:.2f} (target <= {OVERHEAD_TARGET})"
    )


if __name__ == "__main__":
    main()
