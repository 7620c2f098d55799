"""Tests of the ``mtdagger`` LeRobot policy: modalities, per-task loss, save/load, bad configs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.policies.factory import get_policy_class, make_policy_config

from lerobot_mtdagger.policies import MTDAggerConfig, MTDAggerPolicy, make_mtdagger_pre_post_processors
from lerobot_mtdagger.policies.mtdagger.modeling_mtdagger import max_pool_of_winners, per_task_means
from lerobot_mtdagger.policies.mtdagger.processor_mtdagger import pool_pointcloud_stats

TASKS = ["reach-v3", "push-v3", "door-open-v3"]
STATE = PolicyFeature(type=FeatureType.STATE, shape=(7,))
IMAGE = PolicyFeature(type=FeatureType.VISUAL, shape=(3, 32, 32))
CLOUD = PolicyFeature(type=FeatureType.STATE, shape=(64, 3))
ACTION = PolicyFeature(type=FeatureType.ACTION, shape=(4,))

MODALITIES = {
    "state": {"observation.state": STATE},
    "rgb": {"observation.image": IMAGE},
    "pointcloud": {"observation.pointcloud": CLOUD},
    "state+rgb": {"observation.state": STATE, "observation.image": IMAGE},
    "state+pointcloud": {"observation.state": STATE, "observation.pointcloud": CLOUD},
    "all": {"observation.state": STATE, "observation.image": IMAGE, "observation.pointcloud": CLOUD},
}


def make_config(inputs, **kwargs) -> MTDAggerConfig:
    small = {
        "state_hidden_dims": (32,),
        "head_hidden_dims": (32,),
        "image_channels": (8, 8),
        "pointnet_dims": (16, 32),
    }
    defaults = {"device": "cpu", "task_names": list(TASKS), "output_features": {"action": ACTION}, **small}
    return MTDAggerConfig(input_features=dict(inputs), **{**defaults, **kwargs})


def make_batch(inputs, batch_size=6, seed=0):
    generator = torch.Generator().manual_seed(seed)
    batch = {k: torch.randn((batch_size, *ft.shape), generator=generator) for k, ft in inputs.items()}
    batch["action"] = torch.randn((batch_size, 4), generator=generator)
    batch["task"] = [TASKS[i % 2] for i in range(batch_size)]  # door-open absent
    batch["task_index"] = torch.tensor([i % 2 for i in range(batch_size)])
    return batch


def test_policy_type_is_registered_with_lerobot():
    assert isinstance(make_policy_config("mtdagger", device="cpu"), MTDAggerConfig)
    assert get_policy_class("mtdagger") is MTDAggerPolicy


@pytest.mark.parametrize("modality", list(MODALITIES))
def test_forward_backward_for_each_modality(modality):
    torch.manual_seed(0)
    inputs = MODALITIES[modality]
    policy = MTDAggerPolicy(make_config(inputs))
    batch = make_batch(inputs)
    loss, info = policy.forward(batch)
    loss.backward()
    assert torch.isfinite(loss)
    assert set(info["per_task_loss"]) == {"reach-v3", "push-v3"}

    # The modality builds exactly its encoders, one per input keyed by it, and the loss trains every
    # parameter of all of them.
    parameters = dict(policy.named_parameters())
    assert {name.split(".")[0] for name in parameters} == {"task_embedding", "head", "encoders"}
    assert set(policy.encoders) == {key.replace(".", "_") for key in inputs}
    for name, parameter in parameters.items():
        grad = parameter.grad
        assert grad is not None, f"{name} gets no gradient"
        finite, non_zero = bool(torch.isfinite(grad).all()), bool(grad.abs().sum() > 0)
        assert finite and non_zero, f"{name}: finite gradient {finite}, non-zero gradient {non_zero}"
    # Only the embeddings of the tasks in the batch move (door-open-v3 is absent).
    embedding_grad_norms = policy.task_embedding.weight.grad.norm(dim=1)
    assert embedding_grad_norms[0] > 0 and embedding_grad_norms[1] > 0 and embedding_grad_norms[2] == 0
    assert policy.training
    assert policy.select_action(batch).shape == (6, 4)
    assert not any(module.training for module in policy.modules()), "select_action leaves eval mode on"


@pytest.mark.parametrize("layer_norm", [False, True])
def test_max_pool_of_winners_gives_the_dense_max_pool_and_its_gradient(layer_norm):
    torch.manual_seed(0)
    norm = [torch.nn.LayerNorm(16)] if layer_norm else []
    per_point = torch.nn.Sequential(torch.nn.Linear(3, 16), *norm, torch.nn.ReLU(), torch.nn.Linear(16, 32))
    points = torch.randn(5, 40, 3)
    points[:, 20:] = points[:, :20]  # duplicated points: ties go to one winner, as with max
    points.requires_grad_(True)
    weights = torch.randn(32)

    def gradients(pool):
        pooled = pool()
        return pooled.detach(), torch.autograd.grad(
            (pooled * weights).sum(), [points, *per_point.parameters()]
        )

    dense, dense_grads = gradients(lambda: per_point(points).max(dim=1).values)
    sparse, sparse_grads = gradients(lambda: max_pool_of_winners(per_point, points))
    torch.testing.assert_close(sparse, dense)
    for got, expected in zip(sparse_grads, dense_grads, strict=True):
        torch.testing.assert_close(got, expected, rtol=1e-5, atol=1e-6)
    assert bool(dense_grads[0][:, 20:].eq(0).all()), "a tie's gradient goes to its first point only"


def test_clouds_are_searched_in_chunks_on_a_cpu_only():
    """Chunks keep a CPU's cache; on a GPU (here the meta device, which has no data) one pass."""
    from lerobot_mtdagger.policies.mtdagger.modeling_mtdagger import SEARCH_CHUNK_POINTS, cloud_chunks

    on_cpu = cloud_chunks(torch.zeros(256, 1024, 3))
    assert len(on_cpu) == 256 * 1024 // SEARCH_CHUNK_POINTS and torch.cat(on_cpu).shape == (256, 1024, 3)
    elsewhere = cloud_chunks(torch.empty(256, 1024, 3, device="meta"))
    assert len(elsewhere) == 1 and elsewhere[0].shape == (256, 1024, 3)


def test_the_dp3_encoder_has_dp3s_size_and_round_trips(tmp_path):
    cloud = PolicyFeature(type=FeatureType.STATE, shape=(512, 3))
    inputs = {"observation.state": STATE, "observation.pointcloud": cloud}
    dp3 = {"pointnet_dims": (64, 128, 256), "pointcloud_embedding_dim": 64, "pointnet_layer_norm": True}
    policy = MTDAggerPolicy(make_config(inputs, **dp3))
    encoder = policy.encoders["observation_pointcloud"]
    assert sum(p.numel() for p in encoder.parameters()) == 59_072  # DP3's PointNet with LayerNorm
    assert sum(isinstance(m, torch.nn.LayerNorm) for m in encoder.modules()) == 4
    batch = make_batch(inputs, batch_size=4)
    loss, _ = policy.forward(batch)
    loss.backward()
    policy.save_pretrained(tmp_path)
    loaded = MTDAggerPolicy.from_pretrained(tmp_path).eval()
    with torch.no_grad():
        expected = policy.eval().predict(batch, task_index=batch["task_index"])
        torch.testing.assert_close(loaded.predict(batch, task_index=batch["task_index"]), expected)


def test_pointnet_trains_through_the_winners_and_infers_densely(monkeypatch):
    from lerobot_mtdagger.policies.mtdagger import modeling_mtdagger

    calls = []
    original = modeling_mtdagger.max_pool_of_winners
    monkeypatch.setattr(
        modeling_mtdagger, "max_pool_of_winners", lambda *args: calls.append(1) or original(*args)
    )
    inputs = MODALITIES["state+pointcloud"]
    policy = MTDAggerPolicy(make_config(inputs))
    batch = make_batch(inputs)
    loss, _ = policy.forward(batch)
    loss.backward()
    assert calls == [1]
    with torch.no_grad():
        policy.predict(batch, task_index=batch["task_index"])
    assert calls == [1]


def test_per_task_loss_equals_hand_computed_means():
    torch.manual_seed(0)
    inputs = MODALITIES["state"]
    policy = MTDAggerPolicy(make_config(inputs))
    batch = make_batch(inputs, batch_size=7)
    loss, info = policy.forward(batch)
    prediction = policy.predict(batch)
    per_sample = ((prediction - batch["action"]) ** 2).mean(dim=1)
    for name in TASKS[:2]:
        mask = torch.tensor([t == name for t in batch["task"]])
        assert info["per_task_loss"][name] == pytest.approx(per_sample[mask].mean().item(), rel=1e-5)
        assert info["per_task_count"][name] == int(mask.sum())
    assert loss.item() == pytest.approx(per_sample.mean().item(), rel=1e-6)


def test_per_task_means_helper():
    means, counts = per_task_means(torch.tensor([1.0, 3.0, 5.0]), torch.tensor([0, 0, 2]), 3)
    assert means.tolist() == [2.0, 0.0, 5.0] and counts.tolist() == [2.0, 0.0, 1.0]


def test_task_strings_take_precedence_over_dataset_indices():
    torch.manual_seed(0)
    inputs = MODALITIES["state"]
    policy = MTDAggerPolicy(make_config(inputs))
    batch = make_batch(inputs)
    by_string = policy.task_indices(batch)
    batch["task_index"] = torch.zeros(6, dtype=torch.long)  # a dataset that numbered tasks differently
    assert torch.equal(policy.task_indices(batch), by_string)
    del batch["task"]
    assert policy.task_indices(batch).tolist() == [0] * 6


def test_unknown_task_string_is_a_clear_error():
    inputs = MODALITIES["state"]
    policy = MTDAggerPolicy(make_config(inputs))
    batch = make_batch(inputs, batch_size=1)
    batch["task"] = ["pick-place-v3"]
    with pytest.raises(
        ValueError, match=r"Unknown task\(s\) \['pick-place-v3'\]: this policy was trained on.*task_dropout"
    ):
        policy.select_action(batch)


def test_task_dropout_gives_unseen_tasks_the_shared_embedding(tmp_path):
    inputs = MODALITIES["state"]
    torch.manual_seed(0)
    policy = MTDAggerPolicy(make_config(inputs, task_dropout=0.5))
    assert policy.task_embedding.num_embeddings == len(TASKS) + 1
    batch = make_batch(inputs, batch_size=2)
    batch["task"] = ["pick-place-v3", "reach-v3"]
    assert policy.task_indices(batch).tolist() == [len(TASKS), 0]
    unseen = policy.select_action(batch)
    assert unseen.shape == (2, 4)

    # The shared row learns from the dropped samples of every task; evaluation drops nothing.
    policy.train()
    loss, info = policy.forward(make_batch(inputs, batch_size=64))
    loss.backward()
    assert policy.task_embedding.weight.grad[len(TASKS)].abs().sum() > 0
    assert set(info["per_task_loss"]) == {"reach-v3", "push-v3"}
    policy.eval()
    again = make_batch(inputs, batch_size=2)
    again["task"] = ["pick-place-v3", "reach-v3"]
    torch.testing.assert_close(policy.select_action(again), policy.select_action(again), rtol=0, atol=0)

    policy.save_pretrained(tmp_path / "model")
    loaded = MTDAggerPolicy.from_pretrained(tmp_path / "model")
    torch.testing.assert_close(loaded.select_action(again), policy.select_action(again), rtol=0, atol=0)


def test_a_policy_without_task_dropout_keeps_its_checkpoint_layout():
    policy = MTDAggerPolicy(make_config(MODALITIES["state"]))
    assert policy.task_embedding.num_embeddings == len(TASKS)


def test_save_and_load_round_trip_gives_identical_actions(tmp_path):
    torch.manual_seed(0)
    inputs = MODALITIES["all"]
    policy = MTDAggerPolicy(make_config(inputs))
    policy.save_pretrained(tmp_path / "model")
    loaded = MTDAggerPolicy.from_pretrained(tmp_path / "model")
    assert loaded.config.task_names == TASKS
    batch = make_batch(inputs)
    torch.testing.assert_close(loaded.select_action(batch), policy.select_action(batch), rtol=0, atol=0)


def test_task_vocabulary_comes_from_dataset_meta_when_not_given():
    import pandas as pd

    class Meta:
        tasks = pd.DataFrame({"task_index": [1, 0]}, index=["push-v3", "reach-v3"])

    config = make_config(MODALITIES["state"], task_names=[])
    policy = MTDAggerPolicy(config, dataset_meta=Meta())
    assert policy.config.task_names == ["reach-v3", "push-v3"]


def test_pointcloud_stats_are_pooled_per_channel():
    config = make_config(MODALITIES["state+pointcloud"])
    mean = torch.stack([torch.tensor([0.0, 1.0, 2.0]), torch.tensor([2.0, 3.0, 4.0])])  # 2 points
    std = torch.ones(2, 3)
    stats = {
        "observation.pointcloud": {"mean": mean, "std": std, "min": mean - 1, "max": mean + 1},
        "observation.state": {"mean": torch.zeros(7), "std": torch.ones(7)},
    }
    pooled = pool_pointcloud_stats(config, stats)["observation.pointcloud"]
    assert pooled["mean"].tolist() == [[1.0, 2.0, 3.0]] * 2
    # pooled variance = mean of (std^2 + mean^2) - pooled mean^2 = 1 + 1 = 2 on every channel
    np.testing.assert_allclose(pooled["std"], np.full((2, 3), 2**0.5), rtol=1e-6)
    assert pooled["min"].tolist() == [[-1.0, 0.0, 1.0]] * 2
    assert pooled["max"].tolist() == [[3.0, 4.0, 5.0]] * 2
    assert stats["observation.pointcloud"]["mean"] is mean, "the input stats must not be modified"


def test_processors_normalise_and_unnormalise():
    config = make_config(MODALITIES["state"])
    stats = {
        "observation.state": {"mean": torch.full((7,), 2.0), "std": torch.full((7,), 4.0)},
        "action": {"mean": torch.full((4,), 1.0), "std": torch.full((4,), 2.0)},
    }
    pre, post = make_mtdagger_pre_post_processors(config, dataset_stats=stats)
    out = pre({"observation.state": torch.full((7,), 6.0), "task": "reach-v3"})
    assert out["observation.state"].shape == (1, 7)
    torch.testing.assert_close(out["observation.state"], torch.ones(1, 7))
    torch.testing.assert_close(post(torch.zeros(1, 4)), torch.ones(1, 4))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"inputs": {}}, "has no input feature"),
        ({"outputs": {}}, "needs an 'action' output feature"),
        ({"task_names": []}, "task_names is empty"),
    ],
)
def test_bad_feature_configs_are_clear_errors(kwargs, match):
    config = MTDAggerConfig(
        device="cpu",
        task_names=kwargs.get("task_names", TASKS),
        input_features=kwargs.get("inputs", MODALITIES["state"]),
        output_features=kwargs.get("outputs", {"action": ACTION}),
    )
    with pytest.raises(ValueError, match=match):
        MTDAggerPolicy(config)


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        ("task_names", ["a", "a"], "unique"),
        ("task_embedding_dim", 0, "task_embedding_dim must be > 0"),
        ("pointnet_dims", (16, -1), "pointnet_dims must hold positive sizes"),
        ("dropout", 1.0, "dropout"),
        ("task_dropout", 1.0, r"task_dropout must be in \[0, 1\)"),
        ("task_dropout", -0.1, "task_dropout"),
        ("n_obs_steps", 2, "n_obs_steps"),
    ],
)
def test_bad_config_values_are_rejected(field, value, match):
    with pytest.raises(ValueError, match=match):
        MTDAggerConfig(device="cpu", **{field: value})


LEGACY = Path(__file__).parent / "data" / "legacy-policy-v1"


def test_a_checkpoint_written_before_encoders_were_keyed_by_input_still_loads():
    """tests/data/legacy-policy-v1: state_encoder / image_encoder / pointcloud_encoders.0 weights."""
    policy = MTDAggerPolicy.from_pretrained(LEGACY)
    assert set(policy.encoders) == {"observation_state", "observation_image", "observation_pointcloud"}
    expected = torch.load(LEGACY / "expected_actions.pt")
    # Not bit-exact across CPUs (another machine's kernels differ by ~1e-8); a weight left at its
    # initial value or loaded into the wrong encoder moves the actions by ~0.1.
    torch.testing.assert_close(
        policy.select_action(dict(expected["batch"])), expected["actions"], rtol=0, atol=1e-5
    )
