#!/usr/bin/env bash
# The checks that need an NVIDIA GPU, in one script (about 5 minutes), from the repository root of an
# installed checkout (the README's install): the GPU tests (`--policy.device=cuda` end to end on the
# point-cloud drawers, FrameParts on the device), the policy's training and inference on the GPU beside
# the CPU, and the render rates with MuJoCo's EGL on the GPU. Record what it prints in docs/benchmarks.md.
set -euo pipefail
export MUJOCO_GL=egl PYTHONUNBUFFERED=1
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv
.venv/bin/python -m pytest -q -m gpu -p no:cacheprovider tests/test_gpu.py
.venv/bin/python benchmarks/bench_policy.py --device=cuda --batch-size 256 --steps 20 --rounds 3
.venv/bin/python benchmarks/bench_policy.py --device=cpu --batch-size 256 --steps 5 --rounds 1
.venv/bin/python benchmarks/bench_envs.py --suite drawers --rounds 2 --render-steps 80 --steps 300
