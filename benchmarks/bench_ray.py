"""Env workers as Ray actors against forked local workers: collection and evaluation throughput.

Run: ``.venv/bin/python benchmarks/bench_ray.py`` (options: ``--workers``, ``--episodes``,
``--repeats``, ``--obs_mode``, ``--nodes``). On three point-cloud drawers (512 points, the drawer
expert labelling every step, an untrained ``mtdagger`` policy batched in the main process, as in a
DAgger round) it measures, in ONE run with the two kinds interleaved over ``--repeats``:

- ``collect``: recorded steps per second of a DAgger round (beta 0, frames recorded) with
  ``--workers`` local processes and with as many Ray actors;
- ``eval``: evaluation episodes per second, the same way;
- that both give the same episodes (frames compared one by one).

Target: Ray actors >= 0.8 x the local workers' collection rate on point clouds. With ``--nodes=2``
the actors run on a Ray cluster of two nodes started on this machine (``ray.cluster_utils.Cluster``,
one raylet and object store each, ``--workers / 2`` CPUs each), and the actors' nodes are printed.
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np
from bench_collect import collect_rate, eval_rate  # the same round and evaluation, timed

from lerobot_mtdagger.envs import ObservationConfig, make_suite
from lerobot_mtdagger.policies import MTDAggerPolicy
from lerobot_mtdagger.runner.policy_options import PolicyOptions
from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner
from lerobot_mtdagger.runner.rollout.ray_workers import RayEnvWorkers
from lerobot_mtdagger.runner.rollout.workers import EnvWorkers
from lerobot_mtdagger.students.mtdagger import build_processors, policy_config

TARGET = 0.8
DRAWERS = ["drawer-bar-wide", "drawer-knob-large", "drawer-lip-wide"]


def untrained_runner(suite) -> PolicyRunner:
    """An untrained default-size policy for ``suite`` with identity normalisation of state and action."""
    config = policy_config(suite.features, suite.task_names, PolicyOptions(batch_size=256, lr=3e-4))
    stats = {}
    for key in ("observation.state", "action"):
        shape = tuple(suite.features[key]["shape"])
        ones = np.ones(shape, np.float32)
        stats[key] = {"mean": 0 * ones, "std": ones, "min": -ones, "max": ones}
    preprocessor, postprocessor = build_processors(config, stats)
    return PolicyRunner(MTDAggerPolicy(config), preprocessor, postprocessor)


def same_episodes(first: list, second: list) -> bool:
    """Whether two collections recorded the same frames, episode by episode."""
    if len(first) != len(second):
        return False
    for a, b in zip(first, second, strict=True):
        if a.steps != b.steps or len(a.frames) != len(b.frames):
            return False
        for frame_a, frame_b in zip(a.frames, b.frames, strict=True):
            if any(not np.array_equal(frame_a[k], frame_b[k]) for k in frame_a if k != "task"):
                return False
    return True


def ray_address(nodes: int, cpus: int) -> tuple[str | None, object | None]:
    """A local Ray (None) or a cluster of ``nodes`` nodes on this machine, ``cpus`` CPUs in all."""
    if nodes <= 1:
        return None, None
    from ray.cluster_utils import Cluster

    cluster = Cluster(initialize_head=True, head_node_args={"num_cpus": max(1, cpus // nodes)})
    for _ in range(nodes - 1):
        cluster.add_node(num_cpus=max(1, cpus // nodes))
    cluster.wait_for_nodes()
    return cluster.address, cluster


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--episodes", type=int, default=1, help="collection episodes per drawer")
    parser.add_argument("--eval-episodes", type=int, default=1, help="evaluation episodes per drawer")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--obs_mode", default="pointcloud")
    parser.add_argument("--nodes", type=int, default=1, help="Ray nodes started on this machine")
    args = parser.parse_args()
    suite = make_suite(
        "drawers", tasks=DRAWERS, observation=ObservationConfig(obs_mode=args.obs_mode, num_points=512)
    )
    runner = untrained_runner(suite)
    address, cluster = ray_address(args.nodes, args.workers)
    local, remote = EnvWorkers(suite, args.workers), RayEnvWorkers(suite, args.workers, address)
    print(f"ray actors on: {remote._places}")
    rates: dict[str, list[float]] = {"collect local": [], "collect ray": [], "eval local": [], "eval ray": []}
    identical = True
    try:
        for pool in (local, remote):  # warm-up: every env built, every renderer initialised
            collect_rate(pool, runner, 1, seed=99)
        for repeat in range(args.repeats):
            local_rate, local_episodes = collect_rate(local, runner, args.episodes, seed=repeat)
            ray_rate, ray_episodes = collect_rate(remote, runner, args.episodes, seed=repeat)
            identical &= same_episodes(local_episodes, ray_episodes)
            rates["collect local"].append(local_rate)
            rates["collect ray"].append(ray_rate)
            rates["eval local"].append(eval_rate(local, runner, args.eval_episodes))
            rates["eval ray"].append(eval_rate(remote, runner, args.eval_episodes))
    finally:
        local.close()
        remote.close()
        if cluster is not None:
            import ray

            ray.shutdown()  # the driver leaves the cluster first, then its nodes go
            cluster.shutdown()
    medians = {name: statistics.median(values) for name, values in rates.items()}
    for name, value in medians.items():
        unit = "recorded steps/s" if name.startswith("collect") else "episodes/s"
        print(f"{name:<14} {value:9.2f} {unit}  (runs: {', '.join(f'{v:.2f}' for v in rates[name])})")
    collect_ratio = medians["collect ray"] / medians["collect local"]
    eval_ratio = medians["eval ray"] / medians["eval local"]
    verdict = "PASS" if collect_ratio >= TARGET else "FAIL"
    print(
        f"ray / local: collect {collect_ratio:.2f}x ({verdict}, target >= {TARGET}), eval {eval_ratio:.2f}x"
    )
    print(f"same episodes on both: {identical}")


if __name__ == "__main__":
    main()
