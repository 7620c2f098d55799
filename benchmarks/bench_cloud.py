"""What a point-cloud observation costs besides its renders: back-projection, crop and sampling.

Run: ``.venv/bin/python benchmarks/bench_cloud.py [--suite drawers] [--steps 300] [--rounds 3]``.

On one env's real depth renders (the suite's default two cameras, 84 x 84, 1 024 points), times
``PointCloudCamera.capture``'s work after the renders in two ways, interleaved over ``--rounds``:

- ``former``: each camera's (H * W, 3) points as ``(rays * depth) @ R.T + p``, cropped row by row
  (``former_cloud``, the code before the per-plane back-projection; also the tests' reference);
- ``planes``: ``PointCloudCamera.cloud_from_renders``, what ``capture`` does after its renders
  (``rendering.depth_to_world``: one (H, W) plane per world axis; ``CropBox.contains_planes``).

Both sample the same points from the same generator state. The depth renders are taken once and
reused, so only the CPU-side work is timed; on a GPU renderer that work is a large share of a
cloud step (docs/benchmarks.md, "On a GPU"). Target: planes / former <= 0.5.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from lerobot_mtdagger.envs import ObservationConfig, make_suite

TARGET = 0.5


def former_cloud(camera, data, rng: np.random.Generator, depths: dict | None = None) -> np.ndarray:
    """The cloud as ``PointCloudCamera.capture`` made it before the per-plane back-projection.

    Each camera's (H * W, 3) points as ``(rays * depth) @ R.T + p``, cropped row by row, then the
    same sampling. ``depths`` (camera name -> depth image) skips the renders.
    """
    parts = []
    for name, camera_id, rays in zip(camera.cameras, camera._ids, camera._rays, strict=True):
        depth = camera.renderer.depth(data, name) if depths is None else depths[name]
        rotation = data.cam_xmat[camera_id].reshape(3, 3)
        points = (rays * depth[..., None]).reshape(-1, 3) @ rotation.T + data.cam_xpos[camera_id]
        low, high = np.asarray(camera.crop.low), np.asarray(camera.crop.high)
        keep = np.all((points >= low) & (points <= high), axis=1)
        if camera.with_color:
            colors = camera.renderer.rgb(data, name).reshape(-1, 3) / 255.0
            points = np.concatenate([points, colors], axis=1)
        parts.append(points[keep])
    cloud = np.concatenate(parts)
    index = rng.choice(len(cloud), size=camera.num_points, replace=len(cloud) < camera.num_points)
    return cloud[index].astype(np.float32)


def planes_cloud(camera, data, rng: np.random.Generator, depths: dict) -> np.ndarray:
    """``capture`` after its renders (xyz clouds), on the given depth images."""
    return camera.cloud_from_renders(data, depths, rng)


def time_per_call(function, camera, data, depths: dict, steps: int) -> float:
    """Mean seconds per call over ``steps`` calls, each with a fresh seeded generator."""
    start = time.perf_counter()
    for step in range(steps):
        function(camera, data, np.random.default_rng(step), depths)
    return (time.perf_counter() - start) / steps


def main() -> None:
    """Prints the per-step cost of each way and the ratio, and checks the target."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--suite", default="drawers", choices=["drawers", "metaworld-mt10"])
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    suite = make_suite(args.suite, observation=ObservationConfig(obs_mode="pointcloud", num_points=1024))
    env = suite.make_env(suite.task_names[0], seed=0)
    env.reset(seed=0)
    camera, data = env.unwrapped._cloud, env.unwrapped._env.data
    depths = {name: camera.renderer.depth(data, name) for name in camera.cameras}
    render_s = time_per_call(lambda c, d, r, _: c.capture(d, r), camera, data, depths, 20)
    times = {"former": [], "planes": []}
    for _ in range(args.rounds):
        times["former"].append(time_per_call(former_cloud, camera, data, depths, args.steps))
        times["planes"].append(time_per_call(planes_cloud, camera, data, depths, args.steps))
    env.close()
    former, planes = statistics.median(times["former"]), statistics.median(times["planes"])
    size = camera.renderer.height
    print(f"suite {args.suite}, cameras {camera.cameras}, {size} px, median of {args.rounds} rounds")
    print(f"whole capture with its renders: {render_s * 1e3:.2f} ms per step")
    print(f"former (rows):  {former * 1e6:8.1f} us per step")
    print(f"planes (now):   {planes * 1e6:8.1f} us per step")
    ratio = planes / former
    print(f"{'PASS' if ratio <= TARGET else 'FAIL'}: planes / former = {ratio:.3f} (target <= {TARGET})")


if __name__ == "__main__":
    main()
