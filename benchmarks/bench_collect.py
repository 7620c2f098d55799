"""DAgger collection and evaluation throughput with env workers, against raw MetaWorld steps.

Run: ``.venv/bin/python benchmarks/bench_collect.py`` (options: ``--workers 1 2``, ``--episodes``,
``--eval-episodes``, ``--repeats``). On MetaWorld MT10 with state observations, in ONE run:

- ``raw``: the single-env step rate of MetaWorld's own env (``SawyerXYZEnv.step``, random actions,
  one process), the per-core reference;
- ``collect``: a DAgger round as the runner collects it: the learner acting at every step
  (``beta = 0``; an untrained ``mtdagger`` policy with its LeRobot processors, batched in the main
  process), the expert labelling every step, frames recorded, rollouts to the env's 500-step
  horizon (the runner's default), with each worker count; recorded steps per second of wall time;
- ``eval``: evaluation episodes per second (the pure policy, to the env's 500-step truncation);
- ``raw, N processes at once``: N processes stepping raw MetaWorld at the same time, the machine's
  own ceiling for N workers (two cores that slow each other down cap it below N x raw);
- ``raw along the trajectories``: MetaWorld's own step replaying, from the same reset seeds, the
  actions executed in the collection (the same for every worker count; one process), to check
  that the learner's trajectories do not cost more than random actions (measured: they do not).

The workers (and their envs) are started and warmed up before the clock starts: in a run they live
for the whole experiment. Raw and collection measurements are interleaved over ``--repeats`` and
the medians are compared. Target: collection with N workers >= 0.7 x N x the raw single-env rate.
"""

from __future__ import annotations

import argparse
import multiprocessing
import statistics
import time

import numpy as np

from lerobot_mtdagger.datasets.records import EXECUTED_ACTION
from lerobot_mtdagger.envs import make_suite
from lerobot_mtdagger.envs.metaworld import _make_raw_env
from lerobot_mtdagger.policies import MTDAggerPolicy
from lerobot_mtdagger.runner.policy_options import PolicyOptions
from lerobot_mtdagger.runner.rollout.collect import EpisodeOptions, run_episodes
from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner, evaluate
from lerobot_mtdagger.runner.rollout.workers import EnvWorkers
from lerobot_mtdagger.students.mtdagger import build_processors, policy_config
from lerobot_mtdagger.utils.seeds import COLLECT_STREAM

TARGET = 0.7
RAW_STEPS = 2000


def raw_rate(tasks: list[str], steps: int) -> float:
    """Single-process raw MetaWorld steps/s over ``tasks`` (construction and resets untimed)."""
    rng = np.random.default_rng(0)
    total_time, total_steps = 0.0, 0
    for task in tasks:
        env = _make_raw_env(task)
        env.seed(0)
        env.reset()
        actions = rng.uniform(-1, 1, (steps // len(tasks), 4)).astype(np.float32)
        for index, action in enumerate(actions):
            if index and index % 400 == 0:
                env.reset()
            start = time.perf_counter()
            env.step(action)
            total_time += time.perf_counter() - start
        total_steps += len(actions)
        env.close()
    return total_steps / total_time


def replay_rate(suite, episodes: list) -> float:
    """Single-process raw MetaWorld steps/s replaying the executed actions of recorded episodes."""
    envs: dict[int, object] = {}
    total_time, total_steps = 0.0, 0
    for episode in episodes:
        env = envs.get(episode.task_index) or envs.setdefault(
            episode.task_index, suite.make_env(suite.task_names[episode.task_index])
        )
        env.reset(seed=episode.seed)
        raw_env = env._env  # MetaWorld's SawyerXYZEnv under the state wrapper
        actions = [np.clip(frame[EXECUTED_ACTION], -1.0, 1.0) for frame in episode.frames]
        start = time.perf_counter()
        for action in actions:
            raw_env.step(action)
        total_time += time.perf_counter() - start
        total_steps += len(actions)
    for env in envs.values():
        env.close()
    return total_steps / total_time


def _raw_child(tasks: list[str], steps: int, queue: multiprocessing.Queue) -> None:
    queue.put(raw_rate(tasks, steps))


def parallel_raw_rate(tasks: list[str], steps: int, processes: int) -> float:
    """Total raw MetaWorld steps/s of ``processes`` processes stepping at the same time.

    The machine's own ceiling for N workers: N x the single-process rate only if the cores do not
    slow each other down (shared caches, memory bandwidth, SMT siblings on the host).
    """
    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    children = [context.Process(target=_raw_child, args=(tasks, steps, queue)) for _ in range(processes)]
    for child in children:
        child.start()
    rates = [queue.get() for _ in children]
    for child in children:
        child.join()
    return sum(rates)


def untrained_runner(suite) -> PolicyRunner:
    """An untrained default-size policy with its processors (identity normalisation)."""
    options = PolicyOptions(batch_size=256, lr=3e-4)
    config = policy_config(suite.features, suite.task_names, options)
    stats = {
        key: {
            "mean": np.zeros(shape, np.float32),
            "std": np.ones(shape, np.float32),
            "min": -np.ones(shape, np.float32),
            "max": np.ones(shape, np.float32),
        }
        for key, shape in (("observation.state", 39), ("action", 4))
    }
    preprocessor, postprocessor = build_processors(config, stats)
    return PolicyRunner(MTDAggerPolicy(config), preprocessor, postprocessor)


def collect_rate(workers: EnvWorkers, runner: PolicyRunner, episodes: int, seed: int) -> tuple[float, list]:
    """Recorded steps per second of a DAgger round with the learner acting, and its episodes."""
    start = time.perf_counter()
    options = EpisodeOptions(
        beta=0.0,
        seed=seed,
        round_index=1,
        stream=COLLECT_STREAM,
        record=True,
        max_steps=None,  # the runner's default: the env's own 500-step horizon
        steps_after_success=10,
    )
    result = run_episodes(workers, [episodes] * len(workers.suite.task_names), options, policy=runner)
    return sum(e.steps for e in result) / (time.perf_counter() - start), result


def eval_rate(workers: EnvWorkers, runner: PolicyRunner, episodes: int) -> float:
    """Evaluation episodes per second."""
    start = time.perf_counter()
    _, result = evaluate(workers, runner, episodes, seed=0)
    return len(result) / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--episodes", type=int, default=2, help="collection episodes per task")
    parser.add_argument("--eval-episodes", type=int, default=1, help="evaluation episodes per task")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()

    suite = make_suite("metaworld-mt10")
    runner = untrained_runner(suite)
    raw: list[float] = []
    replay: list[float] = []
    parallel_raw: dict[int, list[float]] = {n: [] for n in args.workers}
    collect: dict[int, list[float]] = {n: [] for n in args.workers}
    evals: dict[int, list[float]] = {n: [] for n in args.workers}
    started = time.perf_counter()
    pools = {n: EnvWorkers(suite, n) for n in args.workers}
    try:
        for pool in pools.values():  # warm-up: every worker builds its envs
            collect_rate(pool, runner, 1, seed=999)
        for repeat in range(args.repeats):
            raw.append(raw_rate(list(suite.task_names), RAW_STEPS))
            for n in args.workers:
                parallel_raw[n].append(parallel_raw_rate(list(suite.task_names), RAW_STEPS, n))
            for n, pool in pools.items():
                rate, episodes = collect_rate(pool, runner, args.episodes, seed=repeat)
                collect[n].append(rate)
                evals[n].append(eval_rate(pool, runner, args.eval_episodes))
            replay.append(replay_rate(suite, episodes))  # the same trajectories for every worker count
    finally:
        for pool in pools.values():
            pool.close()
    raw_median = statistics.median(raw)
    replay_median = statistics.median(replay)
    print(f"MetaWorld MT10, state; repeats: {args.repeats}; wall time {time.perf_counter() - started:.0f} s")
    print(f"raw single-env MetaWorld step rate (one process, random actions): {raw_median:.0f} steps/s")
    print(
        f"raw MetaWorld step rate along the collected trajectories (one process): {replay_median:.0f} steps/s"
    )
    print(
        "| workers | raw steps/s, N processes at once | collect steps/s | ratio to N x raw | "
        "ratio to N processes' raw | ratio to N x raw along the trajectories | eval episodes/s | "
        "eval speed-up |"
    )
    print("|--------:|------:|------:|------:|------:|------:|------:|------:|")
    base_eval = statistics.median(evals[args.workers[0]])
    ratios = {}
    for n in args.workers:
        rate = statistics.median(collect[n])
        ratios[n] = rate / (n * raw_median)
        eval_median = statistics.median(evals[n])
        ceiling = statistics.median(parallel_raw[n])
        print(
            f"| {n} | {ceiling:.0f} | {rate:.0f} | {ratios[n]:.3f} | {rate / ceiling:.3f} | "
            f"{rate / (n * replay_median):.3f} | {eval_median:.2f} | {eval_median / base_eval:.2f} |"
        )
    for n, ratio in ratios.items():
        verdict = "PASS" if ratio >= TARGET else "FAIL"
        print(f"{verdict}: collection with {n} worker(s) at {ratio:.3f} x {n} x raw (target >= {TARGET})")


if __name__ == "__main__":
    main()
