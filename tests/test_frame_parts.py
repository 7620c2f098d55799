"""Rounds' images and point clouds are held once: ``FrameParts`` reads them as one tensor.

A phase trains on all committed rounds. Their images and point clouds stay in their rounds' tensors
(``TrainingData.concat`` joins them as ``FrameParts``) instead of being copied into one; a phase on
them must train exactly as on the concatenated tensors.
"""

from __future__ import annotations

import pytest
import torch
from lerobot.configs.types import FeatureType, PolicyFeature

from lerobot_mtdagger.policies import MTDAggerConfig, MTDAggerPolicy
from lerobot_mtdagger.runner.training import normalise
from lerobot_mtdagger.runner.training.frame_parts import FrameParts, join_frames, materialise
from lerobot_mtdagger.runner.training.normalise import NormalisedData, compute_stats
from lerobot_mtdagger.runner.training.round_data import EPISODE_ID_STRIDE, TrainingData
from lerobot_mtdagger.runner.training.steps import StepOptions, train_phase
from lerobot_mtdagger.students.mtdagger import build_processors, per_task_loss, per_task_loss_of

TASKS = ["task-a", "task-b", "task-c"]
IMAGE_SHAPE = (8, 8, 3)
CLOUD_SHAPE = (16, 3)


def random_parts(sizes: list[int], seed: int = 0) -> list[torch.Tensor]:
    generator = torch.Generator().manual_seed(seed)
    return [torch.randn(size, 4, 2, generator=generator) for size in sizes]


@pytest.mark.parametrize(
    "index",
    [
        torch.tensor([0, 4, 5, 11, 3, 3]),
        torch.tensor([[11, 0, 7], [2, 9, 5]]),
        torch.tensor([-1, -12, 6], dtype=torch.int32),
        torch.tensor([], dtype=torch.long),
        torch.randint(-12, 12, (40, 20), generator=torch.Generator().manual_seed(0)),
    ],
    ids=["flat", "2-d", "negative-int32", "empty", "more-than-the-row-copy-limit"],
)
def test_frame_parts_index_like_the_concatenated_tensor(index):
    parts = random_parts([5, 0, 4, 3])
    joined = FrameParts(parts)
    whole = torch.cat(parts)
    assert len(joined) == 12 and joined.shape == whole.shape and joined.dtype == whole.dtype
    assert torch.equal(joined[index], whole[index.long()])
    assert torch.equal(joined.materialise(), whole)


def test_frame_parts_refuse_mismatched_parts_and_bad_indices():
    with pytest.raises(ValueError, match="at least one"):
        FrameParts([])
    with pytest.raises(ValueError, match=r"Cannot join a torch.float32 \(2, 4, 3\)"):
        FrameParts([torch.zeros(2, 4, 2), torch.zeros(2, 4, 3)])
    with pytest.raises(ValueError, match="torch.uint8"):
        FrameParts([torch.zeros(2, 4, 2), torch.zeros(2, 4, 2, dtype=torch.uint8)])
    joined = FrameParts(random_parts([2, 3]))
    with pytest.raises(TypeError, match="integer tensor"):
        joined[1:3]
    with pytest.raises(TypeError, match="integer tensor"):
        joined[torch.tensor([0.0])]
    with pytest.raises(IndexError, match="out of range for 5 frames"):
        joined[torch.tensor([5])]
    with pytest.raises(IndexError, match="out of range"):
        joined[torch.tensor([-6])]


def test_join_frames_keeps_a_single_tensor_and_drops_empty_parts():
    parts = random_parts([0, 4, 0])
    assert join_frames(parts) is parts[1]
    joined = join_frames(random_parts([3, 0, 2]))
    assert isinstance(joined, FrameParts) and [len(p) for p in joined.parts] == [3, 2]
    assert materialise(parts[1]) is parts[1]
    nested = join_frames([joined, *random_parts([2], seed=1)])
    assert [len(p) for p in nested.parts] == [3, 2, 2], "the parts of a FrameParts are taken as they are"


def test_statistics_read_in_chunks_equal_those_of_all_the_frames_at_once(monkeypatch):
    monkeypatch.setattr(normalise, "STATS_CHUNK", 7)  # 40 frames: six chunks, the last one short
    generator = torch.Generator().manual_seed(0)
    parts = [torch.randn(n, 5, 3, generator=generator) * (1 + n) + n for n in (12, 20, 18)]
    frames = torch.randperm(50, generator=generator)[:40]
    stats = normalise.channel_stats(FrameParts(parts), frames)
    flat = torch.cat(parts)[frames].reshape(-1, 3).double()
    assert stats["mean"] == pytest.approx(flat.mean(0).float().numpy(), rel=1e-6)
    assert stats["std"] == pytest.approx(flat.std(0, unbiased=False).float().numpy(), rel=1e-6)
    assert (stats["min"] == flat.min(0).values.float().numpy()).all()
    assert (stats["max"] == flat.max(0).values.float().numpy()).all()


# ---------------------------------------------------------------------------------------------
# A phase on rounds kept apart
# ---------------------------------------------------------------------------------------------


def visual_round(position: int, episodes: int, seed: int) -> TrainingData:
    generator = torch.Generator().manual_seed(seed)
    frames = episodes * 10
    episode = torch.arange(frames) // 10
    task = episode % len(TASKS)
    state = torch.randn(frames, 3, generator=generator)
    cloud = torch.randn(frames, *CLOUD_SHAPE, generator=generator) + task[:, None, None]
    image = torch.randint(0, 256, (frames, *IMAGE_SHAPE), generator=generator, dtype=torch.uint8)
    action = torch.tanh(state[:, :2] + cloud[:, 0, :2] + image[:, 0, 0, :2].float() / 255)
    return TrainingData(
        inputs={"observation.state": state, "observation.pointcloud": cloud, "observation.image": image},
        action=action,
        task_index=task,
        episode_id=episode + position * EPISODE_ID_STRIDE,
    )


def visual_policy(seed: int) -> MTDAggerPolicy:
    config = MTDAggerConfig(
        device="cpu",
        task_names=list(TASKS),
        input_features={
            "observation.state": PolicyFeature(type=FeatureType.STATE, shape=(3,)),
            "observation.pointcloud": PolicyFeature(type=FeatureType.STATE, shape=CLOUD_SHAPE),
            "observation.image": PolicyFeature(type=FeatureType.VISUAL, shape=(3, 8, 8)),
        },
        output_features={"action": PolicyFeature(type=FeatureType.ACTION, shape=(2,))},
        state_hidden_dims=(16,),
        head_hidden_dims=(16,),
        image_channels=(4, 4),
        pointnet_dims=(8, 16),
        push_to_hub=False,
    )
    torch.manual_seed(seed)
    return MTDAggerPolicy(config)


def materialised(data: TrainingData) -> TrainingData:
    inputs = {key: materialise(tensor).clone() for key, tensor in data.inputs.items()}
    return TrainingData(inputs, data.action.clone(), data.task_index.clone(), data.episode_id.clone())


def phase(data: TrainingData, train_index: torch.Tensor, sampling: str):
    """Statistics, normalisation, a short phase and the per-task losses of another policy."""
    policy = visual_policy(seed=0)
    stats = compute_stats(data, ["observation.image"], train_index)
    preprocessor, postprocessor = build_processors(policy.config, stats)
    normalised = NormalisedData(data, preprocessor, ["observation.image"], TASKS)
    options = StepOptions(steps=25, batch_size=16, lr=1e-3, seed=3, sampling=sampling, log_interval=10)
    result = train_phase(policy, normalised, train_index, torch.arange(0, len(data), 4), options)
    other = visual_policy(seed=1)

    def predict(inputs, task_names):
        batch = preprocessor({**inputs, "action": torch.zeros(len(task_names), 2)})
        batch["observation.image"] = inputs["observation.image"].permute(0, 3, 1, 2).float() / 255
        index = torch.tensor([TASKS.index(name) for name in task_names])
        return postprocessor(other.predict(batch, task_index=index))

    others = per_task_loss_of(predict, normalised, torch.arange(len(data)), len(TASKS))
    losses, _ = per_task_loss(policy, normalised, torch.arange(len(data)), len(TASKS))
    return stats, normalised, result, policy.state_dict(), others, losses


@pytest.mark.parametrize("sampling", ["uniform", "balanced"])
def test_a_phase_on_rounds_kept_apart_trains_exactly_as_on_their_concatenation(sampling):
    rounds = [visual_round(0, 6, seed=0), visual_round(1, 3, seed=1), visual_round(2, 4, seed=2)]
    joined = TrainingData.concat(rounds)
    for key in ("observation.image", "observation.pointcloud"):
        parts = joined.inputs[key]
        assert isinstance(parts, FrameParts), key
        assert [p.data_ptr() for p in parts.parts] == [r.inputs[key].data_ptr() for r in rounds], (
            f"{key}: the rounds' tensors must be shared, not copied"
        )
    assert isinstance(joined.inputs["observation.state"], torch.Tensor)
    train_index = torch.arange(len(joined))[torch.arange(len(joined)) % 7 != 0]
    kept_apart = phase(joined, train_index, sampling)
    concatenated = phase(materialised(joined), train_index, sampling)
    stats, normalised, result, weights, others, losses = kept_apart
    stats_ref, normalised_ref, result_ref, weights_ref, others_ref, losses_ref = concatenated
    for key in stats_ref:
        for name in stats_ref[key]:
            assert (stats[key][name] == stats_ref[key][name]).all(), (key, name)
        # ... and they are the statistics of the training frames (float64 over all of them at once).
        tensor = joined.action if key == "action" else materialise(joined.inputs[key])
        flat = tensor[train_index].reshape(-1, tensor.shape[-1]).double()
        expected = {"mean": flat.mean(0), "std": flat.std(0, unbiased=False)}
        expected |= {"min": flat.min(0).values, "max": flat.max(0).values}
        for name, value in expected.items():
            assert stats[key][name] == pytest.approx(value.float().numpy(), rel=1e-6, abs=1e-7), (key, name)
    assert isinstance(normalised.vector["observation.pointcloud"], FrameParts)
    for key, tensor in normalised_ref.vector.items():
        assert torch.equal(materialise(normalised.vector[key]), tensor), key
    assert result.train_loss == result_ref.train_loss and result.loss_end == result_ref.loss_end
    for key, tensor in weights_ref.items():
        assert torch.equal(weights[key], tensor), key
    assert others == others_ref and losses == losses_ref
