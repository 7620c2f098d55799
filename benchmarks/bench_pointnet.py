"""What the point-cloud encoder's size costs in training: bare PyTorch loops of three PointNets.

Run: ``.venv/bin/python benchmarks/bench_pointnet.py [--threads 2] [--batch 64] [--rounds 3]``.

Each network is a PointNet (shared per-point MLP, max-pool over points, projection) joined to a
7-d state encoder and a 32-d task embedding, with the action head of the ``mtdagger`` policy
(2 x 256), trained with AdamW on fixed random batches:

- ``today 1024``: the policy's default encoder (3-64-128-256, projection 256-256) on 1 024 points;
- ``today 512``: the same on 512 points;
- ``dp3 512``: DP3's encoder size (3-64-128-256 with LayerNorm after each layer, projection to 64
  with LayerNorm; about 59 k parameters) on 512 points.

The loops run in interleaved rounds and the medians are compared, so the ratios are side by side;
the absolute samples/s depend on the machine and on what else runs on it.
"""

from __future__ import annotations

import argparse
import statistics
import time

import torch
from torch import nn

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
        self.state = nn.Sequential(nn.Linear(STATE_DIM, 64), nn.ReLU())
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


NETWORKS = {
    "today 1024": ((64, 128, 256), False, 256, 1024),
    "today 512": ((64, 128, 256), False, 256, 512),
    "dp3 512": ((64, 128, 256), True, 64, 512),
}


def samples_per_second(net: StudentNet, points: int, batch: int, steps: int, seed: int) -> float:
    """AdamW steps on one fixed random batch (3 warm-up steps not timed)."""
    generator = torch.Generator().manual_seed(seed)
    cloud = torch.randn(batch, points, 3, generator=generator)
    state = torch.randn(batch, STATE_DIM, generator=generator)
    task = torch.randint(0, TASKS, (batch,), generator=generator)
    target = torch.randn(batch, ACTION_DIM, generator=generator)
    optimizer = torch.optim.AdamW(net.parameters(), lr=1e-3)

    def step() -> None:
        loss = ((net(cloud, state, task) - target) ** 2).mean()
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        optimizer.step()

    for _ in range(3):
        step()
    start = time.perf_counter()
    for _ in range(steps):
        step()
    return steps * batch / (time.perf_counter() - start)


def main() -> None:
    """Prints samples/s per network and the ratio to today's encoder on 1 024 points."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--batch", type=int, default=64)
    parser.add_argument("--steps", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    torch.manual_seed(args.seed)
    nets = {name: StudentNet(dims, norm, out) for name, (dims, norm, out, _) in NETWORKS.items()}
    rates: dict[str, list[float]] = {name: [] for name in NETWORKS}
    for _ in range(args.rounds):
        for name, (_, _, _, points) in NETWORKS.items():
            rates[name].append(samples_per_second(nets[name], points, args.batch, args.steps, args.seed))
    base = statistics.median(rates["today 1024"])
    print(f"| network | encoder params | samples/s (batch {args.batch}, {args.threads} threads) | ratio |")
    print("|---|---:|---:|---:|")
    for name, values in rates.items():
        rate = statistics.median(values)
        print(f"| {name} | {nets[name].encoder_parameters()} | {rate:.0f} | {rate / base:.2f}x |")


if __name__ == "__main__":
    main()
