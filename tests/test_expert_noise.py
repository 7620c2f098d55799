"""Imperfect experts (``experts/noise.py``, ``--expert.*``): the noise process, and a run's frames."""

from __future__ import annotations

import hashlib
import json

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.envs import make_suite
from lerobot_mtdagger.experts import ExpertNoise, make_expert, run_expert_episode

LOW, HIGH = -np.ones(4, dtype=np.float32), np.ones(4, dtype=np.float32)
TOY = ["--suite.name=toy", "--dagger.rounds=1", "--dagger.initial_demos=2", "--dagger.budget_per_task=2"]
TOY += ["--rollout.eval_episodes=2", "--training.steps_per_round=5", "--policy.batch_size=16"]
TOY += ["--rollout.workers=0", "--progress=false"]

# sha256 of round 0's frames (observation.state, action, executed_action, learner_acted, in file order)
# of a run with TOY, made at the commit before expert noise existed, on both LeRobot lines (round 0 is
# the expert's alone, so torch plays no part): a run with the noise off must still write exactly these.
ROUND0_FRAMES_BEFORE_NOISE = "ea48d4e6f8db13f78d955d54bb80e2282633647d3f919d6472159af5590de2ac"


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"scale": -0.1}, r"expert.noise must be a finite number >= 0, got -0.1"),
        ({"scale": float("nan")}, r"expert.noise must be a finite number >= 0"),
        ({"correlation": 1.0}, r"expert.noise_correlation must be in \[0, 1\), got 1.0"),
        ({"correlation": -0.5}, r"expert.noise_correlation must be in \[0, 1\)"),
        ({"seed": -1}, r"expert.noise_seed must be >= 0"),
        ({"labels": "mean"}, r"expert.labels must be one of \['noisy', 'clean'\], got 'mean'"),
    ],
)
def test_expert_noise_refuses_impossible_values(options, message):
    with pytest.raises(ValueError, match=message):
        ExpertNoise(**options)


def test_no_noise_draws_nothing():
    assert ExpertNoise().episode_process((0, 0, 0), LOW, HIGH) is None
    assert (
        ExpertNoise(scale=0.0, correlation=0.9, labels="clean").episode_process((0, 0, 0), LOW, HIGH) is None
    )


@pytest.mark.parametrize("correlation", [0.0, 0.5, 0.9])
def test_the_noise_has_the_given_scale_and_step_correlation(correlation):
    process = ExpertNoise(scale=0.2, correlation=correlation, seed=3).episode_process((1, 2, 3), LOW, HIGH)
    noise = np.stack([process.sample(4).copy() for _ in range(20_000)])  # (T, 4)
    assert noise.std() == pytest.approx(0.2, rel=0.05)  # stationary from the first step
    lag1 = np.mean([np.corrcoef(noise[:-1, i], noise[1:, i])[0, 1] for i in range(4)])
    assert lag1 == pytest.approx(correlation, abs=0.03)


def test_each_episode_has_its_own_reproducible_noise():
    noise = ExpertNoise(scale=0.3, correlation=0.5, seed=1)

    def draws(key, seed_noise=noise):
        process = seed_noise.episode_process(key, LOW, HIGH)
        return np.stack([process.sample(4).copy() for _ in range(5)])

    np.testing.assert_array_equal(draws((1, 0, 0)), draws((1, 0, 0)))
    assert not np.allclose(draws((1, 0, 0)), draws((1, 0, 1)))  # another episode
    assert not np.allclose(draws((1, 0, 0)), draws((2, 0, 0)))  # another round
    other_seed = ExpertNoise(scale=0.3, correlation=0.5, seed=2)
    assert not np.allclose(draws((1, 0, 0)), draws((1, 0, 0), other_seed))


def test_a_task_of_its_own_gets_its_own_scale_and_a_zero_scale_draws_nothing():
    noise = ExpertNoise(scale=0.2, correlation=0.5, seed=1, task_scales=(("hard", 0.0), ("easy", 0.6)))
    assert noise.active and noise.scale_for("easy") == 0.6 and noise.scale_for("other") == 0.2
    assert noise.episode_process((0, 0, 0), LOW, HIGH, task="hard") is None
    easy = noise.episode_process((0, 0, 0), LOW, HIGH, task="easy")
    assert np.stack([easy.sample(4).copy() for _ in range(20_000)]).std() == pytest.approx(0.6, rel=0.05)
    # the same episode's draws, scaled: a task's scale changes no other random draw
    other = noise.episode_process((0, 0, 0), LOW, HIGH, task="other")
    np.testing.assert_allclose(
        other.sample(4) * 3.0, noise.episode_process((0, 0, 0), LOW, HIGH, "easy").sample(4)
    )
    assert (
        ExpertNoise(task_scales=(("easy", 0.1),)).active and not ExpertNoise(task_scales=(("a", 0.0),)).active
    )
    with pytest.raises(ValueError, match="expert.noise_by_task: easy's noise must be finite, >= 0, got -1"):
        ExpertNoise(task_scales=(("easy", -1.0),))


@pytest.mark.parametrize("labels", ["noisy", "clean"])
def test_perturb_clips_to_the_bounds_and_labels_as_asked(labels):
    process = ExpertNoise(scale=5.0, seed=0, labels=labels).episode_process((0, 0, 0), LOW, HIGH)
    action = np.array([0.9, -0.9, 0.0, 1.5], dtype=np.float32)
    executed, label = process.perturb(action)
    assert executed.dtype == np.float32 and np.all(np.abs(executed) <= 1.0)
    assert not np.allclose(executed, np.clip(action, -1, 1))
    expected = executed if labels == "noisy" else np.array([0.9, -0.9, 0.0, 1.0], dtype=np.float32)
    np.testing.assert_array_equal(label, expected)


def test_noise_lowers_a_perfect_experts_success():
    suite = make_suite("toy")
    env, expert = suite.make_env("toy-up-windy"), make_expert(suite, "toy-up-windy")
    episodes = range(30)
    clean = [run_expert_episode(env, expert, seed).success for seed in episodes]
    noise = ExpertNoise(scale=1.5, correlation=0.9, seed=0)
    noisy = [
        run_expert_episode(
            env, expert, seed, noise=noise.episode_process((0, 0, seed), LOW[:2], HIGH[:2])
        ).success
        for seed in episodes
    ]
    assert np.mean(clean) == 1.0 and np.mean(noisy) < 0.9


def _frames(run_dir, rounds: str = "round-*") -> dict[str, np.ndarray]:
    """The DAgger columns of the ``rounds`` (a glob), in file order."""
    tables = [pq.read_table(path) for path in sorted(run_dir.glob(f"rounds/{rounds}/data/*/*.parquet"))]
    table = pa.concat_tables(tables)
    names = ["observation.state", "action", "executed_action", "learner_acted"]
    return {name: np.array(table.column(name).to_pylist(), dtype=np.float64) for name in names}


def _digest(frames: dict[str, np.ndarray]) -> str:
    hasher = hashlib.sha256()
    for name in sorted(frames):
        hasher.update(name.encode() + np.ascontiguousarray(frames[name]).tobytes())
    return hasher.hexdigest()


def _run(tmp_path, name: str, *options: str):
    out = tmp_path / name
    assert main(["run", *TOY, *options, f"--output_dir={out}"]) == 0
    return out


def test_a_run_with_the_noise_off_is_the_run_without_it(tmp_path):
    plain = _run(tmp_path, "plain")
    off = _run(tmp_path, "off", "--expert.noise=0", "--expert.noise_seed=9", "--expert.labels=clean")
    assert _digest(_frames(plain)) == _digest(_frames(off))
    assert _digest(_frames(off, "round-000")) == ROUND0_FRAMES_BEFORE_NOISE
    for round_dir in ("round-000", "round-001"):
        weights = [(run / "policies" / round_dir / "model.safetensors").read_bytes() for run in (plain, off)]
        assert weights[0] == weights[1]


@pytest.mark.parametrize("labels", ["noisy", "clean"])
def test_a_noisy_run_records_its_noise_and_labels_as_asked(tmp_path, labels):
    noisy = ["--expert.noise=0.5", "--expert.noise_correlation=0.8", "--expert.noise_seed=4"]
    out = _run(tmp_path, labels, *noisy, f"--expert.labels={labels}")
    config = json.loads((out / "config.json").read_text())
    expected = {"noise": 0.5, "noise_correlation": 0.8, "noise_seed": 4, "labels": labels, "path": None}
    expected |= {"type": None, "min_success": None, "success_episodes": 20, "noise_by_task": None}
    assert config["expert"] == expected
    record = json.loads((out / "rounds" / "round-001" / "meta" / "mtdagger.json").read_text())
    assert record["config"]["expert"] == expected
    frames = _frames(out)
    expert_acted = frames["learner_acted"].reshape(-1) == 0
    same = np.all(frames["action"] == frames["executed_action"], axis=1)
    if labels == "noisy":  # the label is what the expert executed
        assert np.all(same[expert_acted])
    else:  # the label is the expert's own action; it executed that plus the noise
        # (equal only where the noise pushed an action already at its bound past it: clipped back)
        on_bounds = np.all(np.abs(frames["action"]) == 1.0, axis=1)
        assert np.all(on_bounds[expert_acted & same]) and np.mean(same[expert_acted]) < 0.25
    plain = _frames(_run(tmp_path, "plain"))
    assert not np.array_equal(plain["observation.state"], frames["observation.state"])


def test_a_noisy_run_resumes_only_with_its_noise(tmp_path, capsys):
    out = _run(tmp_path, "run", "--expert.noise=0.3")
    assert main(["run", *TOY, "--expert.noise=0.4", f"--output_dir={out}", "--resume=true"]) == 2
    assert "expert.noise: 0.3 -> 0.4" in capsys.readouterr().err
    assert main(["run", *TOY, f"--output_dir={out}", "--resume=true"]) == 2
    assert main(["run", *TOY, "--expert.noise=0.3", f"--output_dir={out}", "--resume=true"]) == 0


def test_bad_expert_options_are_refused_before_anything_is_written(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", *TOY, "--expert.noise_correlation=1.2", f"--output_dir={out}"]) == 2
    assert "expert.noise_correlation must be in [0, 1)" in capsys.readouterr().err
    assert not out.exists()


def test_verify_refuses_a_round_whose_recorded_experts_differ_from_the_run(tmp_path, capsys):
    out = _run(tmp_path, "run", "--expert.noise=0.3")
    assert main(["verify", f"--experiment_dir={out}"]) == 0
    capsys.readouterr()
    path = out / "rounds" / "round-001" / "meta" / "mtdagger.json"
    record = json.loads(path.read_text())
    record["config"]["expert"]["noise"] = 0.0  # as if round 1 had been collected with perfect experts
    path.write_text(json.dumps(record))
    with pytest.raises(SystemExit) as exited:
        main(["verify", f"--experiment_dir={out}"])
    assert exited.value.code == 1
    assert "round-001: collected with other experts: expert.noise: 0.0 (the run's config.json: 0.3)" in (
        capsys.readouterr().out
    )


def test_compare_gives_every_arm_the_same_experts():
    from lerobot_mtdagger.analysis.compare import CompareConfig, jobs_for

    noisy = ["--expert.noise=0.3", "--expert.noise_correlation=0.9", "--expert.labels=clean"]
    jobs = jobs_for(
        CompareConfig(methods=["need", "uniform", "bc"], seeds=[3], bc_budgets=[2, 4]), [*TOY, *noisy], 3
    )
    assert len(jobs) == 4 and all(set(noisy) <= set(job.args) for job in jobs)


NOISY_08 = ["--expert.noise=0.8", "--expert.noise_correlation=0.9", "--expert.success_episodes=10"]


def test_min_success_keeps_the_tasks_whose_noisy_expert_passes_and_records_them(
    tmp_path, capsys, monkeypatch
):
    from lerobot_mtdagger.runner import run_setup
    from lerobot_mtdagger.runner.rollout.expert_check import expert_success

    suite = make_suite("toy").with_expert_noise(ExpertNoise(scale=0.8, correlation=0.9))
    rates = {task: expert_success(suite, i, 10, seed=0) for i, task in enumerate(suite.task_names)}
    assert len(set(rates.values())) > 1, rates  # the threshold below keeps some tasks and drops others
    threshold = max(rates.values())
    kept = [task for task, rate in rates.items() if rate >= threshold]
    out = _run(tmp_path, "kept", *NOISY_08, f"--expert.min_success={threshold}")
    check = json.loads((out / "expert_check.json").read_text())
    assert check["success"] == rates and check["kept"] == kept
    assert check["dropped"] == [task for task in rates if task not in kept]
    record = json.loads((out / "rounds" / "round-001" / "meta" / "mtdagger.json").read_text())
    assert record["task_names"] == kept and record["config"]["expert"]["min_success"] == threshold
    # a resume reads the measurement back and measures nothing
    monkeypatch.setattr(run_setup, "measure_expert_check", lambda *args: pytest.fail("measured again"))
    args = [*TOY, *NOISY_08, f"--expert.min_success={threshold}", "--dagger.rounds=2"]
    assert main(["run", *args, f"--output_dir={out}", "--resume=true"]) == 0
    assert main(["verify", f"--experiment_dir={out}"]) == 0
    check["kept"] = list(rates)
    (out / "expert_check.json").write_text(json.dumps(check))
    capsys.readouterr()
    with pytest.raises(SystemExit):
        main(["verify", f"--experiment_dir={out}"])
    assert "expert_check.json kept" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--expert.min_success=0"], "expert.min_success must be in (0, 1], got 0.0"),
        (["--expert.min_success=1.5"], "expert.min_success must be in (0, 1]"),
        (["--expert.success_episodes=0"], "expert.success_episodes must be > 0"),
        ([*NOISY_08[:2], "--expert.noise=3", "--expert.min_success=1"], "No task's expert reaches"),
    ],
)
def test_bad_or_unmet_task_rules_are_refused_before_anything_is_written(tmp_path, capsys, options, message):
    out = tmp_path / "out"
    assert main(["run", *TOY, *options, f"--output_dir={out}"]) == 2
    error = capsys.readouterr().err
    assert message in error and len(error.strip().splitlines()) == 1 and not out.exists()


def test_noise_by_task_perturbs_only_the_named_tasks_and_is_recorded(tmp_path):
    by_task = ["--expert.noise_by_task={toy-right: 0.5}", "--expert.noise_correlation=0.9"]
    out = _run(tmp_path, "by-task", *by_task)
    config = json.loads((out / "config.json").read_text())
    assert config["expert"]["noise_by_task"] == {"toy-right": 0.5} and config["expert"]["noise"] == 0.0
    record = json.loads((out / "rounds" / "round-001" / "meta" / "mtdagger.json").read_text())
    assert record["config"]["expert"]["noise_by_task"] == {"toy-right": 0.5}
    plain = _run(tmp_path, "plain")
    frames = {name: _frames(run, "round-000") for name, run in (("by-task", out), ("plain", plain))}
    right = {name: _task_index(run) == 1 for name, run in (("by-task", out), ("plain", plain))}  # toy-right
    assert make_suite("toy").task_names[1] == "toy-right"
    for name in ("observation.state", "executed_action"):  # round 0: the experts' episodes alone
        others = [frames[run][name][~right[run]] for run in frames]
        np.testing.assert_array_equal(*others)
        named = [frames[run][name][right[run]] for run in frames]
        assert named[0].shape != named[1].shape or not np.allclose(*named)
    # the other tasks' experts are the plain ones, so the named task's noise is the whole difference
    assert main(["verify", f"--experiment_dir={out}"]) == 0


def test_noise_by_task_resumes_only_with_the_same_tasks_and_scales(tmp_path, capsys):
    out = _run(tmp_path, "run", "--expert.noise_by_task={toy-right: 0.5}")
    args = [*TOY, f"--output_dir={out}", "--resume=true"]
    assert main(["run", *args, "--expert.noise_by_task={toy-right: 0.4}"]) == 2
    assert "expert.noise_by_task" in capsys.readouterr().err
    assert main(["run", *args]) == 2
    assert main(["run", *args, "--expert.noise_by_task={toy-right: 0.5}"]) == 0


@pytest.mark.parametrize(
    ("option", "message"),
    [
        (
            "{toy-middle: 0.3}",
            "--expert.noise_by_task names toy-middle, not a task of suite toy (its tasks: ",
        ),
        ("{toy-right: -0.3}", "expert.noise_by_task: toy-right's noise must be finite, >= 0, got -0.3"),
    ],
)
def test_bad_noise_by_task_is_refused_in_one_line_before_anything_is_written(
    tmp_path, capsys, option, message
):
    out = tmp_path / "out"
    assert main(["run", *TOY, f"--expert.noise_by_task={option}", f"--output_dir={out}"]) == 2
    error = capsys.readouterr().err
    assert message in error and len(error.strip().splitlines()) == 1 and not out.exists()


def _task_index(run_dir) -> np.ndarray:
    tables = [pq.read_table(path) for path in sorted(run_dir.glob("rounds/round-000/data/*/*.parquet"))]
    return np.array(pa.concat_tables(tables).column("task_index").to_pylist())
