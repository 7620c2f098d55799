"""``--policy.device=cuda`` end to end: training, batched action selection, evaluation, on a GPU.

Skipped without a CUDA device (the development machines have none); `scripts/gpu_check.sh` runs
them, with the GPU benchmarks, on a machine that has one. GPU arithmetic need not match the CPU's to
the last bit, so results are compared with a tolerance.
"""

from __future__ import annotations

import draccus
import pytest
import torch

from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.datasets.verify import verify_experiment
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.dagger import run
from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner
from lerobot_mtdagger.runner.training.frame_parts import FrameParts
from lerobot_mtdagger.runner.training.round_data import load_round
from tests.helpers import small_drawer_cloud_args

pytestmark = [
    pytest.mark.gpu,
    pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device (scripts/gpu_check.sh)"),
]


def test_frame_parts_on_cuda_gather_as_on_the_cpu():
    generator = torch.Generator().manual_seed(0)
    parts = [torch.randn(n, 16, 3, generator=generator) for n in (5, 9, 4)]
    index = torch.randint(-18, 18, (700,), generator=generator)
    expected = torch.cat(parts)[index]
    on_cuda = FrameParts([part.cuda() for part in parts])
    for where in ("cpu", "cuda"):
        gathered = on_cuda[index.to(where)]
        assert gathered.device.type == "cuda"
        assert torch.equal(gathered.cpu(), expected), where
        assert torch.equal(on_cuda[index[:40].to(where)].cpu(), expected[:40]), where


def test_a_point_cloud_drawer_run_trains_collects_and_evaluates_on_cuda(tmp_path):
    args = [*small_drawer_cloud_args(tmp_path / "drawers"), "--policy.device=cuda"]
    run(draccus.parse(RunConfig, args=args))
    experiment = ExperimentDir(tmp_path / "drawers")
    assert experiment.committed_phases() == [0, 1]
    assert verify_experiment(experiment) == (2, 2, [])
    for phase in (0, 1):  # evaluated on the training and on the unseen drawers, on the GPU policy
        record = experiment.read_phase_record(phase)
        assert record.eval["episodes"] == [1, 1] and record.heldout_eval is not None

    # The checkpoint acts the same on the GPU and, loaded there, on the CPU (to float tolerance).
    on_gpu = PolicyRunner.from_pretrained(experiment.policy_root(1), "cuda")
    on_cpu = PolicyRunner.from_pretrained(experiment.policy_root(1), "cpu")
    frames = load_round(experiment.round_root(1), 1, list(on_cpu.policy.config.input_features))
    inputs = {key: tensor[:32] for key, tensor in frames.inputs.items()}
    tasks = [on_cpu.policy.config.task_names[i] for i in frames.task_index[:32].tolist()]
    assert next(on_gpu.policy.parameters()).device.type == "cuda"
    torch.testing.assert_close(
        on_gpu.predict(inputs, tasks), on_cpu.predict(inputs, tasks), atol=1e-4, rtol=1e-4
    )


@pytest.mark.parametrize("student", ["act", "diffusion"])
def test_a_lerobot_student_run_trains_collects_and_evaluates_on_cuda(tmp_path, student):
    """The learner seam on the GPU: LeRobot's ACT and Diffusion Policy as the student, every round."""
    from tests.test_students import TINY_ACT, TINY_DIFFUSION, TOY_STUDENT_RUN

    tiny = {"act": TINY_ACT, "diffusion": TINY_DIFFUSION}[student]
    args = [*TOY_STUDENT_RUN, *tiny, f"--output_dir={tmp_path / 'run'}", "--policy.device=cuda"]
    run(draccus.parse(RunConfig, args=args))
    experiment = ExperimentDir(tmp_path / "run")
    assert experiment.committed_phases() == [0, 1, 2]
    assert verify_experiment(experiment) == (3, 3, [])
    phase = experiment.read_phase_record(2)
    assert phase.eval is not None and len(phase.eval["success"]) == 3
    assert all(loss is not None and torch.isfinite(torch.tensor(loss)) for loss in phase.loss_end)
    loaded = PolicyRunner.from_pretrained(experiment.policy_root(2), "cuda")
    assert next(loaded.policy.parameters()).device.type == "cuda"
