"""Times single-process env steps of a suite in every observation mode against its raw env.

Run: ``.venv/bin/python benchmarks/bench_envs.py`` (options: ``--suite metaworld-mt10|drawers``,
``--tasks``, ``--steps``, ``--render-steps``, ``--rounds``). Modes, all fed the same pre-drawn random
actions (``np.random.default_rng(0).uniform(-1, 1, (n, 4))``, float32):

- ``raw``: the underlying ``SawyerXYZEnv.step`` (MetaWorld's env, or the drawer scene), no wrapper;
- ``state``: our env in ``state`` mode;
- ``rgb``: our env in ``rgb`` mode, 84 x 84 pixels;
- ``pointcloud``: our env in ``pointcloud`` mode, 1024 points from the two default depth cameras;
- ``pointcloud-1cam`` (reference line): the same with ``pointcloud_cameras=("corner",)``.
- ``rgb-simple`` and ``pointcloud-simple`` (reference lines): ``rgb`` and ``pointcloud`` rendered with
  ``mesh_detail=0.2`` (the arm's visual meshes simplified to a fifth of their faces).

Only the step calls are timed (env construction and resets are not). The machine may be noisy, so
the modes are interleaved: for each task, every mode is measured back to back, and the whole sweep
is repeated ``--rounds`` times. Steps/s is total steps over total step time of a mode (one process,
so it is a per-core rate); the paired ratio is the median over (task, round) of mode rate / raw
rate measured right before it.

Targets checked (PASS/FAIL printed at the end):

- state mode within 10% of raw MetaWorld: paired ratio to raw >= 0.9;
- point-cloud mode (1024 points, 2 cameras) >= 50 steps/s per core.
- (the visual-speed issue) point-cloud steps/s at least 0.25x and RGB at least 0.1x the state
  mode's, per core; printed for the exact and the simplified render.

"""

from __future__ import annotations

import argparse
import statistics
import time
from collections import defaultdict

import numpy as np

from lerobot_mtdagger.envs import ObservationConfig, make_suite
from lerobot_mtdagger.envs.drawers.catalogue import VARIANTS
from lerobot_mtdagger.envs.drawers.scene import DrawerSceneEnv
from lerobot_mtdagger.envs.metaworld import _make_raw_env

DEFAULT_TASKS = {
    "metaworld-mt10": ["reach-v3", "push-v3", "door-open-v3", "drawer-open-v3"],
    "drawers": ["drawer-bar-wide", "drawer-knob-large", "drawer-lip-wide", "drawer-kitchen"],
}
MESH_DETAIL = 0.2
MODES = ["raw", "state", "rgb", "pointcloud", "pointcloud-1cam", "rgb-simple", "pointcloud-simple"]
RENDER_MODES = {"rgb", "pointcloud", "pointcloud-1cam", "rgb-simple", "pointcloud-simple"}
STEP_TARGETS = {"pointcloud": 0.25, "rgb": 0.1}
"""The visual-speed issue's targets: steps/s of a mode over the state mode's, per core."""
STATE_TARGET_RATIO = 0.9
POINTCLOUD_TARGET_RATE = 50.0


def make_raw_env(suite: str, task: str):
    """The raw ``SawyerXYZEnv`` of a task of ``suite``."""
    return DrawerSceneEnv(VARIANTS[task]) if suite == "drawers" else _make_raw_env(task)


def time_raw(suite: str, task: str, actions: np.ndarray) -> float:
    """Seconds spent in ``raw.step`` for all ``actions`` (resets before the step limit, untimed)."""
    raw = make_raw_env(suite, task)
    try:
        raw.seed(0)
        raw.reset()
        total = 0.0
        for action in actions:
            if raw.curr_path_length >= raw.max_path_length:
                raw.reset()
            start = time.perf_counter()
            raw.step(action)
            total += time.perf_counter() - start
        return total
    finally:
        raw.close()


def make_env(suite_name: str, task: str, mode: str, num_points: int, image_size: int):
    """Our env of ``task`` in ``mode``.

    ``pointcloud-1cam`` is point-cloud mode with one camera; ``-simple`` modes render with
    ``mesh_detail=MESH_DETAIL`` (the arm's meshes simplified).
    """
    obs_mode, cameras = ("pointcloud", ("corner",)) if mode == "pointcloud-1cam" else (mode, None)
    detail = MESH_DETAIL if mode.endswith("-simple") else 1.0
    suite = make_suite(
        suite_name,
        observation=ObservationConfig(
            obs_mode=obs_mode.removesuffix("-simple"),
            num_points=num_points,
            image_size=image_size,
            pointcloud_cameras=cameras,
            mesh_detail=detail,
        ),
    )
    return suite.make_env(task, seed=0)


def time_wrapped(args, task: str, mode: str, actions: np.ndarray) -> float:
    """Seconds spent in ``env.step`` of our env for all ``actions`` (resets untimed)."""
    env = make_env(args.suite, task, mode, args.num_points, args.image_size)
    try:
        env.reset()
        total = 0.0
        for action in actions:
            start = time.perf_counter()
            _, _, terminated, truncated, _ = env.step(action)
            total += time.perf_counter() - start
            if terminated or truncated:
                env.reset()
        return total
    finally:
        env.close()


def run_sweep(args, actions: np.ndarray):
    """Per-mode lists of (steps, seconds, paired ratio to raw) over rounds x tasks."""
    samples: dict[str, list[tuple[int, float, float]]] = defaultdict(list)
    for round_index in range(args.rounds):
        for task in args.tasks:
            raw_rate = None
            for mode in MODES:
                n = args.render_steps if mode in RENDER_MODES else args.steps
                if mode == "raw":
                    seconds = time_raw(args.suite, task, actions[: args.steps])
                    raw_rate = args.steps / seconds
                else:
                    seconds = time_wrapped(args, task, mode, actions[:n])
                samples[mode].append((n, seconds, n / seconds / raw_rate))
            print(f"  round {round_index + 1}/{args.rounds} {task}: done", flush=True)
    return samples


def summarize(samples) -> dict[str, tuple[int, float, float]]:
    """Per mode: total steps, steps/s (total steps / total seconds), median paired ratio to raw."""
    summary = {}
    for mode, rows in samples.items():
        steps = sum(r[0] for r in rows)
        seconds = sum(r[1] for r in rows)
        summary[mode] = (steps, steps / seconds, statistics.median(r[2] for r in rows))
    return summary


def print_table(summary, num_points: int, image_size: int) -> None:
    labels = {
        "raw": "raw step",
        "state": "state",
        "rgb": f"rgb {image_size} px",
        "pointcloud": f"pointcloud {num_points} pts, 2 cams",
    }
    print(f"| {'mode':<28} | {'steps':>6} | {'steps/s per core':>16} | {'ratio to raw':>12} |")
    print(f"|{'-' * 30}|{'-' * 7}:|{'-' * 17}:|{'-' * 13}:|")
    for mode, label in labels.items():
        steps, rate, ratio = summary[mode]
        print(f"| {label:<28} | {steps:>6} | {rate:>16.1f} | {ratio:>12.3f} |")
    steps, rate, ratio = summary["pointcloud-1cam"]
    print(
        f"Reference: pointcloud {num_points} pts, 1 cam (corner): {rate:.1f} steps/s per core "
        f"(ratio to raw {ratio:.3f}, {steps} steps)"
    )
    for mode in ("rgb-simple", "pointcloud-simple"):
        steps, rate, ratio = summary[mode]
        print(
            f"Reference: {mode.removesuffix('-simple')} with mesh_detail={MESH_DETAIL}: {rate:.1f} steps/s "
            f"per core (ratio to raw {ratio:.3f}, {steps} steps)"
        )


def print_targets(summary) -> bool:
    """Prints PASS/FAIL for the two targets; True when both pass."""
    state_ratio = summary["state"][2]
    cloud_rate = summary["pointcloud"][1]
    state_ok = state_ratio >= STATE_TARGET_RATIO
    cloud_ok = cloud_rate >= POINTCLOUD_TARGET_RATE
    print(
        f"{'PASS' if state_ok else 'FAIL'}: state mode ratio to raw {state_ratio:.3f} >= {STATE_TARGET_RATIO}"
    )
    print(
        f"{'PASS' if cloud_ok else 'FAIL'}: pointcloud mode {cloud_rate:.1f} steps/s per core "
        f">= {POINTCLOUD_TARGET_RATE:.0f}"
    )
    state_rate = summary["state"][1]
    for mode, target in STEP_TARGETS.items():
        for variant in (mode, f"{mode}-simple"):
            share = summary[variant][1] / state_rate
            verdict = "PASS" if share >= target else "FAIL"
            print(f"{verdict}: {variant} steps/s / state steps/s = {share:.3f} (target >= {target})")
    return state_ok and cloud_ok


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--suite", choices=sorted(DEFAULT_TASKS), default="metaworld-mt10")
    parser.add_argument("--tasks", nargs="+", default=None, help="default: four tasks of the suite")
    parser.add_argument("--steps", type=int, default=300, help="steps per task per round, raw and state")
    parser.add_argument(
        "--render-steps", type=int, default=150, help="steps per task per round, rgb/pointcloud"
    )
    parser.add_argument("--rounds", type=int, default=3, help="repeats of the whole interleaved sweep")
    parser.add_argument("--num-points", type=int, default=1024)
    parser.add_argument("--image-size", type=int, default=84)
    args = parser.parse_args()
    args.tasks = args.tasks or DEFAULT_TASKS[args.suite]
    if args.steps <= 0 or args.render_steps <= 0 or args.rounds <= 0:
        parser.error("--steps, --render-steps and --rounds must be positive.")
    actions = (
        np.random.default_rng(0).uniform(-1, 1, (max(args.steps, args.render_steps), 4)).astype(np.float32)
    )
    start = time.perf_counter()
    summary = summarize(run_sweep(args, actions))
    print(
        f"suite: {args.suite}; tasks: {' '.join(args.tasks)}; rounds: {args.rounds}; "
        f"wall time {time.perf_counter() - start:.0f} s"
    )
    print("steps/s = total steps / total step time; ratio to raw = median over (task, round) pairs")
    print_table(summary, args.num_points, args.image_size)
    print_targets(summary)


if __name__ == "__main__":
    main()
