"""Memory of an observation env's renderer with and without a shadow map, and the frames' equality.

Run: ``.venv/bin/python benchmarks/bench_renderer_memory.py [--envs 4] [--rounds 2]``.

Each measurement is a fresh process (memory is not given back to the system reliably within one):
it builds ``--envs`` envs of a suite, resets each (which renders its first observation), and reports
the growth of the process's unique memory (USS) per env. Two ways, interleaved over ``--rounds``:

- ``former``: the renderer as it was made before, ``mujoco.Renderer`` with the model's shadow map
  (MetaWorld's ``shadowsize`` 4096: a 4096 x 4096 depth texture per OpenGL context);
- ``now``: ``rendering.renderer_without_shadow_map``, what ``SceneRenderer`` makes now.

For the drawer suite's point clouds and MetaWorld MT10's RGB frames. Then, in one process, the same
env state rendered both ways: RGB and depth must be bit-identical (shadows are never drawn).
Target: now / former <= 0.75 of the memory an env adds.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np

TARGET = 0.75
CASES = {"drawers pointcloud": ("drawers", "pointcloud"), "mt10 rgb": ("metaworld-mt10", "rgb")}


def unique_mib() -> float:
    """This process's unique set size in MiB (its private pages, from ``/proc/self/smaps_rollup``)."""
    private_kb = 0
    for line in Path("/proc/self/smaps_rollup").read_text().splitlines():
        if line.startswith(("Private_Clean:", "Private_Dirty:")):
            private_kb += int(line.split()[1])
    return private_kb / 1024


def make_envs(suite_name: str, obs_mode: str, count: int) -> list:
    """``count`` reset envs of the suite's first tasks (each reset renders an observation)."""
    from lerobot_mtdagger.envs import ObservationConfig, make_suite

    suite = make_suite(suite_name, observation=ObservationConfig(obs_mode=obs_mode, num_points=512))
    envs = []
    for index, task in enumerate(suite.task_names[:count]):
        env = suite.make_env(task)
        env.reset(seed=index)
        envs.append(env)
    return envs


def child(way: str, suite_name: str, obs_mode: str, count: int) -> None:
    """Prints the USS growth per env, in MiB, for one way of making renderers."""
    from lerobot_mtdagger.envs import rendering

    if way == "former":
        rendering.renderer_without_shadow_map = mujoco.Renderer
    make_envs(suite_name, obs_mode, 1)  # imports, the EGL display and the first context's one-off costs
    before = unique_mib()
    envs = make_envs(suite_name, obs_mode, count)
    print(json.dumps({"per_env_mib": (unique_mib() - before) / len(envs)}))


def measure(way: str, case: str, count: int) -> float:
    """Runs one child process and returns its USS growth per env."""
    suite_name, obs_mode = CASES[case]
    command = [sys.executable, __file__, "--child", way, suite_name, obs_mode, "--envs", str(count)]
    output = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    return float(json.loads(output.strip().splitlines()[-1])["per_env_mib"])


def frames_identical(suite_name: str, obs_mode: str) -> bool:
    """RGB and depth of one stepped env state, rendered with and without the shadow map."""
    from lerobot_mtdagger.envs.rendering import SceneRenderer, renderer_without_shadow_map

    env = make_envs(suite_name, obs_mode, 1)[0]
    for _ in range(10):
        env.step(np.full(4, 0.5, dtype=np.float32))
    model, data = env._env.model, env._env.data
    camera = env.observation_config.camera or env.default_camera
    frames = []
    for make in (mujoco.Renderer, renderer_without_shadow_map):
        scene = SceneRenderer(model, 84, 84)
        scene._renderer = make(model, 84, 84)
        frames.append((scene.rgb(data, camera), scene.depth(data, camera)))
        scene.close()
    return all(np.array_equal(a, b) for a, b in zip(*frames, strict=True))


def main() -> None:
    """Prints the side-by-side table and the target's verdict."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--envs", type=int, default=4)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--child", nargs=3, metavar=("WAY", "SUITE", "OBS_MODE"))
    args = parser.parse_args()
    if args.child:
        child(*args.child, args.envs)
        return
    print(f"USS added per env (MiB, median of {args.rounds} fresh processes of {args.envs} envs each):")
    print("| envs | former | now | now / former | frames bit-identical |")
    print("|---|---:|---:|---:|---|")
    verdicts = []
    for case, (suite_name, obs_mode) in CASES.items():
        former, now = [], []
        for _ in range(args.rounds):
            former.append(measure("former", case, args.envs))
            now.append(measure("now", case, args.envs))
        ratio = statistics.median(now) / statistics.median(former)
        identical = frames_identical(suite_name, obs_mode)
        verdicts.append((case, ratio, identical))
        print(
            f"| {case} | {statistics.median(former):.0f} | {statistics.median(now):.0f} | {ratio:.2f} "
            f"| {'yes' if identical else 'NO'} |"
        )
    for case, ratio, identical in verdicts:
        verdict = "PASS" if ratio <= TARGET and identical else "FAIL"
        target = f"(target <= {TARGET})"
        print(f"{verdict}: {case}: now / former = {ratio:.2f} {target}, frames identical: {identical}")


if __name__ == "__main__":
    main()
