#!/usr/bin/env bash
# The checks that need an NVIDIA GPU, in one script (about 5 minutes), from the repository root of an
# installed checkout (the README's install; `PYTHON=...` names another interpreter that has the
# packages): which renderer MuJoCo's EGL gets, the GPU tests (`--policy.device=cuda` end to end on
# the point-cloud drawers, FrameParts on the device), the policy's training and inference on the GPU
# beside the CPU (batch 256 as the drawer presets, in float32, TF32 and bf16 autocast; 1 024 as the
# paper's pixel preset), and the render rates with MuJoCo's EGL on the GPU. Every check runs even
# when one before it fails; the script names the failed ones at the end and exits 1. Record what it
# prints in docs/benchmarks.md.
set -uo pipefail
export MUJOCO_GL=egl PYTHONUNBUFFERED=1
PYTHON=${PYTHON:-.venv/bin/python}
failed=()

check() {
    echo "== $*"
    "$@" || failed+=("$*")
}

gl_renderer='import mujoco, OpenGL.GL as gl
context = mujoco.GLContext(64, 64)
context.make_current()
print("GL vendor / renderer:", gl.glGetString(gl.GL_VENDOR).decode(), "/", gl.glGetString(gl.GL_RENDERER).decode())
context.free()'

check nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv
check "$PYTHON" -c "$gl_renderer"
check "$PYTHON" -m pytest -q -m gpu -n 0 -p no:cacheprovider tests/test_gpu.py  # one process: one GPU
check "$PYTHON" benchmarks/bench_policy.py --device=cuda --batch-size 256 --steps 20 --rounds 3 --precisions fp32,tf32,bf16
check "$PYTHON" benchmarks/bench_policy.py --device=cuda --batch-size 1024 --steps 10 --rounds 2
check "$PYTHON" benchmarks/bench_policy.py --device=cpu --batch-size 256 --steps 5 --rounds 1
check "$PYTHON" benchmarks/bench_envs.py --suite drawers --rounds 2 --render-steps 80 --steps 300
if ((${#failed[@]})); then
    printf 'FAILED: %s\n' "${failed[@]}"
    exit 1
fi
echo "all GPU checks passed"
