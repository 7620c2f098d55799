"""Fast tests of the training phase: the lean loss, round loading, determinism and the NaN check."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.datasets.lerobot_dataset import LeRobotDataset

from lerobot_mtdagger.envs import make_suite
from lerobot_mtdagger.policies import MTDAggerConfig, MTDAggerPolicy
from lerobot_mtdagger.runner.training.frame_parts import materialise
from lerobot_mtdagger.runner.training.normalise import NormalisedData, compute_stats
from lerobot_mtdagger.runner.training.plateau import PlateauStop
from lerobot_mtdagger.runner.training.round_data import (
    EPISODE_ID_STRIDE,
    TrainingData,
    load_round,
)
from lerobot_mtdagger.runner.training.steps import StepOptions, train_phase
from lerobot_mtdagger.students.mtdagger import MTDAggerOps, build_processors, per_task_loss
from tests.conftest import record_expert_dataset

TASKS = ["task-a", "task-b", "task-c"]
STATE_DIM = 5
ACTION_DIM = 2


# ---------------------------------------------------------------------------------------------
# Factories
# ---------------------------------------------------------------------------------------------


def small_policy(seed: int = 0, tasks: list[str] | None = None, **options) -> MTDAggerPolicy:
    """A small ``mtdagger`` policy over the synthetic frames (``options``: more config fields)."""
    config = MTDAggerConfig(
        device="cpu",
        task_names=list(tasks or TASKS),
        input_features={"observation.state": PolicyFeature(type=FeatureType.STATE, shape=(STATE_DIM,))},
        output_features={"action": PolicyFeature(type=FeatureType.ACTION, shape=(ACTION_DIM,))},
        state_hidden_dims=(32,),
        state_embedding_dim=32,
        head_hidden_dims=(32,),
        task_embedding_dim=8,
        push_to_hub=False,
        **options,
    )
    torch.manual_seed(seed)
    return MTDAggerPolicy(config)


def synthetic_data(frames: int = 600, seed: int = 0) -> TrainingData:
    generator = torch.Generator().manual_seed(seed)
    episode = torch.arange(frames) // 50
    state = torch.randn(frames, STATE_DIM, generator=generator)
    task = episode % len(TASKS)
    action = torch.tanh(state[:, :ACTION_DIM] + task[:, None].float())
    return TrainingData(
        inputs={"observation.state": state}, action=action, task_index=task, episode_id=episode
    )


def normalised(data: TrainingData, policy: MTDAggerPolicy) -> NormalisedData:
    preprocessor, _ = build_processors(policy.config, compute_stats(data, []))
    return NormalisedData(data, preprocessor, [], policy.config.task_names)


def train(seed: int = 0, steps: int = 40, log_interval: int = 100, on_step=None):
    data = synthetic_data()
    policy = small_policy()
    result = train_phase(
        policy,
        normalised(data, policy),
        torch.arange(len(data)),
        torch.arange(0, len(data), 3),
        StepOptions(steps=steps, batch_size=64, lr=1e-3, seed=seed, log_interval=log_interval),
        on_step=on_step,
    )
    return policy, result


def former_load_rounds(roots, input_keys) -> TrainingData:
    """The loader before ``load_round``: through ``LeRobotDataset`` (the reference)."""
    parts = {k: [] for k in [*input_keys, "action", "task_index", "episode_id"]}
    for position, root in enumerate(roots):
        dataset = LeRobotDataset(f"local/{root.name}", root=root)
        table = dataset.hf_dataset.with_format("numpy")
        for key in input_keys:
            column = table[key]
            if dataset.features[key]["dtype"] == "image":
                parts[key].append(torch.from_numpy(np.stack([np.asarray(i, dtype=np.uint8) for i in column])))
            else:
                parts[key].append(torch.from_numpy(np.asarray(column, dtype=np.float32)))
        parts["action"].append(torch.from_numpy(np.asarray(table["action"], dtype=np.float32)))
        parts["task_index"].append(torch.from_numpy(np.asarray(table["task_index"], dtype=np.int64)))
        episode = np.asarray(table["episode_index"], dtype=np.int64)
        parts["episode_id"].append(torch.from_numpy(episode + position * EPISODE_ID_STRIDE))
    merged = {k: torch.cat(v) for k, v in parts.items()}
    return TrainingData(
        inputs={k: merged[k] for k in input_keys},
        action=merged["action"],
        task_index=merged["task_index"],
        episode_id=merged["episode_id"],
    )


def assert_same_data(first: TrainingData, second: TrainingData) -> None:
    assert set(first.inputs) == set(second.inputs)
    for key in first.inputs:
        assert first.inputs[key].dtype == second.inputs[key].dtype, key
        assert torch.equal(materialise(first.inputs[key]), materialise(second.inputs[key])), key
    for name in ("action", "task_index", "episode_id"):
        assert getattr(first, name).dtype == getattr(second, name).dtype, name
        assert torch.equal(getattr(first, name), getattr(second, name)), name


# ---------------------------------------------------------------------------------------------
# The lean loss
# ---------------------------------------------------------------------------------------------


def test_imitation_loss_equals_the_former_forward_loss_and_gradient():
    policy = small_policy()
    generator = torch.Generator().manual_seed(1)
    task_index = torch.tensor([0, 1, 1, 0, 1, 0, 0, 1])
    batch = {
        "observation.state": torch.randn(8, STATE_DIM, generator=generator),
        "action": torch.randn(8, ACTION_DIM, generator=generator),
        "task": [TASKS[i] for i in task_index.tolist()],
    }
    former = ((policy.predict(batch) - batch["action"]) ** 2).mean(dim=1).mean()
    lean = policy.imitation_loss({k: v for k, v in batch.items() if k != "task"}, task_index=task_index)
    torch.testing.assert_close(lean, former, rtol=1e-6, atol=0)

    loss, info = policy.forward(batch)
    assert torch.equal(loss, lean), "forward's loss is imitation_loss's"
    assert set(info["per_task_loss"]) == {"task-a", "task-b"} and info["loss"] == pytest.approx(lean.item())
    loss.backward()
    forward_grads = [p.grad.clone() for p in policy.parameters()]
    policy.zero_grad()
    policy.imitation_loss(batch).backward()
    for forward_grad, parameter in zip(forward_grads, policy.parameters(), strict=True):
        assert torch.equal(forward_grad, parameter.grad)


def test_normalised_batches_carry_task_indices_not_strings():
    data = synthetic_data()
    policy = small_policy()
    batch = normalised(data, policy).batch(torch.tensor([0, 60, 120, 599]))
    assert set(batch) == {"observation.state", "action", "task_index"}
    assert batch["task_index"].tolist() == data.task_index[[0, 60, 120, 599]].tolist()


def test_normalised_data_refuses_task_indices_outside_the_vocabulary():
    data = synthetic_data()
    policy = small_policy()
    data.task_index[5] = len(TASKS)
    with pytest.raises(ValueError, match="fall outside the 3 tasks"):
        normalised(data, policy)


# ---------------------------------------------------------------------------------------------
# Round loading
# ---------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def toy_rounds(tmp_path_factory):
    """Two toy-suite datasets in the round format (LeRobot v3.0, task vocabulary fixed)."""
    suite = make_suite("toy")
    folder = tmp_path_factory.mktemp("rounds")
    roots = [folder / "round-000", folder / "round-001"]
    record_expert_dataset(roots[0], suite, episodes_per_task=2, steps=12, repo_id="local/round-000")
    record_expert_dataset(roots[1], suite, episodes_per_task=1, steps=9, repo_id="local/round-001")
    return roots


def test_load_round_and_concat_give_the_former_loader(toy_rounds):
    keys = ["observation.state"]
    parts = [load_round(root, position, keys) for position, root in enumerate(toy_rounds)]
    assert [len(p) for p in parts] == [3 * 2 * 12, 3 * 1 * 9]
    assert parts[1].episode_id.min() == EPISODE_ID_STRIDE
    joined = TrainingData.concat(parts)
    assert_same_data(joined, former_load_rounds(toy_rounds, keys))
    assert joined.inputs["observation.state"].is_contiguous()
    joined.action[0] = 0.0  # owned, writable memory (not a read-only Arrow buffer)


def test_load_round_reads_images_and_point_clouds_as_lerobot_dataset_does(tmp_path):
    features = {
        "observation.image": {"dtype": "image", "shape": (6, 8, 3), "names": ["height", "width", "channels"]},
        "observation.pointcloud": {"dtype": "float32", "shape": (5, 3), "names": None},
        "observation.state": {"dtype": "float32", "shape": (1,), "names": None},
        "action": {"dtype": "float32", "shape": (2,), "names": None},
    }
    root = tmp_path / "round-000"
    dataset = LeRobotDataset.create(
        repo_id="local/round-000", fps=10, features=features, root=root, use_videos=False
    )
    dataset.meta.save_episode_tasks(TASKS)
    rng = np.random.default_rng(0)
    for episode in range(3):
        for _ in range(4):
            dataset.add_frame(
                {
                    "observation.image": rng.integers(0, 256, (6, 8, 3), dtype=np.uint8),
                    "observation.pointcloud": rng.standard_normal((5, 3)).astype(np.float32),
                    "observation.state": rng.standard_normal(1).astype(np.float32),
                    "action": rng.standard_normal(2).astype(np.float32),
                    "task": TASKS[2 - episode],
                }
            )
        dataset.save_episode()
    dataset.finalize()
    keys = ["observation.image", "observation.pointcloud", "observation.state"]
    loaded = load_round(root, 0, keys)
    assert loaded.inputs["observation.image"].shape == (12, 6, 8, 3)
    assert loaded.inputs["observation.pointcloud"].shape == (12, 5, 3)
    assert loaded.inputs["observation.state"].shape == (12, 1)
    assert loaded.task_index.tolist() == [2] * 4 + [1] * 4 + [0] * 4
    former = former_load_rounds([root], keys)
    # A shape-(1,) feature is a plain scalar column in the parquet file: the former loader returned
    # it as (N,); load_round keeps the feature's shape, which the policy and compute_stats need.
    assert former.inputs["observation.state"].shape == (12,)
    former.inputs["observation.state"] = former.inputs["observation.state"][:, None]
    assert_same_data(loaded, former)


def test_load_round_names_a_missing_feature(toy_rounds):
    with pytest.raises(KeyError, match="observation.image"):
        load_round(toy_rounds[0], 0, ["observation.image"])


def test_concat_refuses_no_parts_and_mismatched_inputs():
    with pytest.raises(ValueError, match="at least one part"):
        TrainingData.concat([])
    data = synthetic_data(frames=10)
    other = TrainingData(
        {"observation.other": torch.zeros(2, 1)}, data.action[:2], data.task_index[:2], data.episode_id[:2]
    )
    with pytest.raises(ValueError, match="Cannot concatenate"):
        TrainingData.concat([data, other])


# ---------------------------------------------------------------------------------------------
# The training loop
# ---------------------------------------------------------------------------------------------


def test_training_is_deterministic_for_a_seed_and_does_not_depend_on_log_interval():
    runs = [train(seed=0), train(seed=0), train(seed=0, log_interval=7), train(seed=1)]
    reference_weights, reference = runs[0][0].state_dict(), runs[0][1]
    assert reference.loss_end != reference.loss_start and len(reference.train_loss) == 10
    for policy, result in runs[1:3]:
        for name, tensor in policy.state_dict().items():
            assert torch.equal(tensor, reference_weights[name]), name
        assert result == reference
    other_weights = runs[3][0].state_dict()
    assert not all(torch.equal(t, other_weights[n]) for n, t in reference_weights.items())


@pytest.mark.parametrize("sampling", ["uniform", "balanced"])
def test_a_phase_records_the_passes_it_made_over_each_tasks_frames(sampling):
    data = synthetic_data()
    # an unequal split: task 0 has 3x the training frames of the others
    keep = torch.cat(
        [torch.nonzero(data.task_index == 0).flatten()] * 1
        + [torch.nonzero(data.task_index == t).flatten()[:50] for t in range(1, len(TASKS))]
    )
    policy = small_policy()
    options = StepOptions(steps=300, batch_size=64, lr=1e-3, seed=0, sampling=sampling, log_interval=7)
    result = train_phase(policy, normalised(data, policy), keep, torch.arange(9), options)
    frames = torch.bincount(data.task_index[keep], minlength=len(TASKS)).tolist()
    draws = [p * f for p, f in zip(result.passes_per_task, frames, strict=True)]
    assert sum(draws) == pytest.approx(300 * 64)  # every drawn frame of the steps taken, no more
    if sampling == "uniform":  # every frame equally likely: the same passes for every task
        assert np.allclose(result.passes_per_task, 300 * 64 / len(keep), rtol=0.1)
    else:  # every task the same share of the draws: fewer passes over the larger task's frames
        assert np.allclose(draws, 300 * 64 / len(TASKS), rtol=0.1)
        assert result.passes_per_task[0] < 0.5 * min(result.passes_per_task[1:])


def test_a_cosine_schedule_takes_each_phase_from_the_full_rate_to_zero(monkeypatch):
    rates: dict[str, list[float]] = {}
    build = MTDAggerOps.optimizer

    def recording(self, steps):
        optimizer, scheduler, clip = build(self, steps)
        seen = rates.setdefault(self.lr_schedule, [])
        optimizer.register_step_pre_hook(lambda opt, *_: seen.append(opt.param_groups[0]["lr"]))
        return optimizer, scheduler, clip

    monkeypatch.setattr(MTDAggerOps, "optimizer", recording)
    data = synthetic_data()
    weights = {}
    for schedule in ("constant", "cosine"):
        policy = small_policy()
        options = StepOptions(steps=40, batch_size=64, lr=1e-3, seed=0, lr_schedule=schedule)
        train_phase(policy, normalised(data, policy), torch.arange(len(data)), torch.arange(9), options)
        weights[schedule] = policy.state_dict()
    assert rates["constant"] == [1e-3] * 40
    cosine = rates["cosine"]
    assert len(cosine) == 40 and cosine[0] == 1e-3 and cosine == sorted(cosine, reverse=True)
    assert cosine[20] == pytest.approx(5e-4) and cosine[-1] < 2e-6  # 0 after the last step
    assert any(not torch.equal(t, weights["cosine"][n]) for n, t in weights["constant"].items())


def test_on_step_reports_progress_at_log_intervals_and_at_the_end():
    calls = []
    _, result = train(steps=25, log_interval=10, on_step=lambda done, loss: calls.append((done, loss)))
    assert [done for done, _ in calls] == [10, 20, 25]
    assert all(isinstance(loss, float) and math.isfinite(loss) for _, loss in calls)
    assert calls[-1][1] == pytest.approx(float(np.mean(result.train_loss[-5:])), rel=1e-6)


@pytest.mark.parametrize(("bad_step", "value"), [(13, math.nan), (10, math.inf), (0, math.nan)])
def test_a_non_finite_loss_raises_naming_the_step(monkeypatch, bad_step, value):
    terms = MTDAggerPolicy._imitation_terms
    calls = []

    def poisoned(self, batch, task_index):
        loss, prediction = terms(self, batch, task_index)
        calls.append(None)
        return (loss * value if len(calls) - 1 == bad_step else loss), prediction

    monkeypatch.setattr(MTDAggerPolicy, "_imitation_terms", poisoned)
    with pytest.raises(FloatingPointError, match=f"Training loss became {value} at step {bad_step};"):
        train(steps=30, log_interval=10)


HELD_OUT = torch.arange(450, 600)  # the last three episodes (one per task)


def plateau_train(held_out_sign: float, steps: int, log_interval: int = 100, held_out=HELD_OUT):
    """Trains on frames 0-449 with a plateau stop on the held-out frames 450-599.

    ``held_out_sign=-1`` flips the held-out labels: the better the policy fits the training frames,
    the worse it does on them, so the held-out loss soon stops improving.
    """
    data = synthetic_data()
    data.action[HELD_OUT] *= held_out_sign
    policy = small_policy()
    prepared = normalised(data, policy)
    result = train_phase(
        policy,
        prepared,
        torch.arange(450),
        torch.arange(0, 450, 3),
        StepOptions(
            steps=steps,
            batch_size=64,
            lr=1e-3,
            seed=0,
            log_interval=log_interval,
            plateau=PlateauStop(index=held_out, every=20, patience=3),
        ),
    )
    return policy, prepared, result


def mean_loss(policy, data, index) -> float:
    return float(np.mean(per_task_loss(policy, data, index, len(TASKS))[0]))


def test_a_plateau_stop_ends_the_phase_and_keeps_the_weights_of_the_lowest_held_out_loss():
    policy, data, result = plateau_train(held_out_sign=-1.0, steps=2000)
    steps, losses = zip(*result.heldout_loss, strict=True)
    assert steps[0] == 0 and all(b - a == 20 for a, b in zip(steps[:-1], steps[1:], strict=True))
    best = int(np.argmin(losses))
    assert result.best_step == steps[best] and len(steps) == best + 1 + 3, "stops 3 measurements later"
    assert result.steps == steps[-1] < 2000
    assert mean_loss(policy, data, HELD_OUT) == pytest.approx(losses[best], rel=1e-6)
    assert mean_loss(policy, data, HELD_OUT) < losses[-1], "the last weights were not kept"
    _, _, same = plateau_train(held_out_sign=-1.0, steps=2000, log_interval=7)
    assert same == result, "the stop does not depend on the log interval"


def test_a_plateau_stop_trains_to_the_cap_while_the_held_out_loss_falls():
    _, _, result = plateau_train(held_out_sign=1.0, steps=100)
    assert result.steps == 100 and result.best_step == 100
    assert [step for step, _ in result.heldout_loss] == [0, 20, 40, 60, 80, 100]


def test_a_plateau_stop_without_held_out_frames_is_refused():
    with pytest.raises(ValueError, match="plateau stop needs held-out frames"):
        plateau_train(held_out_sign=1.0, steps=5, held_out=torch.empty(0, dtype=torch.long))


def test_a_policy_with_another_task_vocabulary_is_refused():
    data = synthetic_data()
    policy = small_policy(tasks=["task-c", "task-b", "task-a"])
    normalised_data = normalised(data, small_policy())
    with pytest.raises(ValueError, match="differ from the data's"):
        train_phase(
            policy,
            normalised_data,
            torch.arange(10),
            torch.arange(10),
            StepOptions(steps=1, batch_size=4, lr=1e-3, seed=0),
        )
