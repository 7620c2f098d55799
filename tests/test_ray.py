"""Ray: compare's grid as Ray tasks, env workers as Ray actors; the same results as on this machine.

Every test runs a local Ray of this machine's cores (started once per test module, never a remote
cluster). Results are compared option by option, frame by frame and weight by weight against the
local launcher and the local env workers.
"""

from __future__ import annotations

import csv
import hashlib
import json
import os
import signal
import time
from pathlib import Path

import draccus
import pyarrow.parquet as pq
import pytest
from safetensors.numpy import load_file

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.datasets.verify import verify_experiment
from lerobot_mtdagger.envs import SuiteConfig, suite_from_config
from lerobot_mtdagger.runner import dagger
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.rollout.ray_workers import RayEnvWorkers
from lerobot_mtdagger.runner.rollout.workers import WorkerDiedError
from lerobot_mtdagger.utils.errors import UserError

ray = pytest.importorskip("ray")

TOY = [
    "--suite.name=toy",
    "--dagger.rounds=2",
    "--dagger.initial_demos=2",
    "--dagger.budget_per_task=3",
    "--training.steps_per_round=40",
    "--rollout.eval_episodes=3",
    "--policy.batch_size=32",
    "--policy.state_hidden_dims=[32]",
    "--policy.head_hidden_dims=[32]",
    "--progress=false",
    "--seed=5",
]


@pytest.fixture(scope="module", autouse=True)
def local_ray():
    """One local Ray for the module (what ``connect(None)`` starts), shut down after it."""
    from lerobot_mtdagger.utils.ray_session import connect

    connect(None)
    yield
    ray.shutdown()


def fingerprint(root: Path) -> dict[str, str]:
    """Digest of every round's frames and every phase's weights and records (timings left out)."""
    experiment = ExperimentDir(root)
    prints = {}
    for k in experiment.committed_rounds():
        for path in sorted((experiment.round_root(k) / "data").rglob("*.parquet")):
            table = pq.read_table(path).to_pandas().to_json()
            prints[f"round {k} {path.name}"] = hashlib.sha256(table.encode()).hexdigest()
        record = experiment.read_round_record(k)
        prints[f"round {k} allocation"] = repr(record.episodes_per_task)
        prints[f"round {k} rollout success"] = repr(record.rollout_success)
    for k in experiment.committed_phases():
        weights = load_file(str(experiment.policy_root(k) / "model.safetensors"))
        prints[f"phase {k} weights"] = hashlib.sha256(
            b"".join(w.tobytes() for w in weights.values())
        ).hexdigest()
        prints[f"phase {k} eval"] = repr(experiment.read_phase_record(k).eval)
    return prints


def run_toy(root: Path, *extra: str) -> list[str]:
    return dagger.run(draccus.parse(RunConfig, args=[*TOY, f"--output_dir={root}", *extra]))


@pytest.mark.parametrize("workers", [pytest.param(1, marks=pytest.mark.slow), 2])  # 1: the slow set
def test_ray_env_workers_give_the_same_rounds_and_evaluations_as_local_ones(tmp_path, workers):
    local = run_toy(tmp_path / "local", "--rollout.workers=2")
    remote = run_toy(tmp_path / "ray", f"--rollout.workers={workers}", "--rollout.worker_backend=ray")
    strip = [line.split(" | collect_s")[0].split(" | load_s")[0] for line in local]
    assert [line.split(" | collect_s")[0].split(" | load_s")[0] for line in remote] == strip
    assert fingerprint(tmp_path / "ray") == fingerprint(tmp_path / "local")
    assert verify_experiment(ExperimentDir(tmp_path / "ray"))[2] == []


@pytest.mark.slow  # CI runs it with the slow set
def test_a_ray_actor_killed_mid_round_is_named_nothing_is_committed_and_resume_gives_the_same_run(
    tmp_path, monkeypatch
):
    reference = tmp_path / "reference"
    run_toy(reference, "--rollout.workers=2")
    collect = dagger.run_episodes

    def killing_collect(workers, episodes_per_task, options, **kwargs):
        if options.round_index == 1 and isinstance(workers, RayEnvWorkers):
            progress = kwargs.get("progress")

            def kill_after_first(episode):
                pid = int(workers._places[1].rsplit(":", 1)[1])
                os.kill(pid, signal.SIGKILL)
                if progress is not None:
                    progress(episode)

            kwargs["progress"] = kill_after_first
        return collect(workers, episodes_per_task, options, **kwargs)

    monkeypatch.setattr(dagger, "run_episodes", killing_collect)
    root = tmp_path / "killed"
    with pytest.raises(WorkerDiedError, match=r"Env worker 1 \(Ray actor on .+ \(node \w+\):\d+\) died"):
        run_toy(root, "--rollout.workers=2", "--rollout.worker_backend=ray")
    assert ExperimentDir(root).committed_rounds() == [0] and ExperimentDir(root).committed_phases() == [0]
    monkeypatch.undo()
    run_toy(root, "--rollout.workers=2", "--rollout.worker_backend=ray", "--resume=true")
    assert fingerprint(root) == fingerprint(reference)


def test_an_exception_in_a_ray_actor_is_raised_with_its_traceback(tmp_path):
    suite = suite_from_config(SuiteConfig(name="toy"))
    with RayEnvWorkers(suite, 1) as workers:
        workers._connections[0].send(("no-such-command", None))
        with pytest.raises(ValueError, match="Unknown worker command") as raised:
            workers._receive(0)
        assert "in handle" in str(raised.value.__cause__)


@pytest.mark.slow  # CI runs it with the slow set
def test_a_pool_reserving_no_cpu_starts_beside_actors_holding_every_cpu_and_a_full_cluster_is_named(
    monkeypatch,
):
    """The unseen drawers' pool runs while the run's own actors hold every CPU (a cluster sized to
    ``--rollout.workers`` used to wait on itself forever); actors that cannot be placed are an error."""
    from lerobot_mtdagger.runner.rollout import ray_workers

    suite = suite_from_config(SuiteConfig(name="toy"))
    cpus = int(ray.cluster_resources()["CPU"])
    with RayEnvWorkers(suite, cpus) as holding:
        monkeypatch.setattr(ray_workers, "ACTOR_START_TIMEOUT_S", 180.0)
        with RayEnvWorkers(suite, 2, reserve_cpus=False) as sharing:
            assert len(sharing._places) == 2
        monkeypatch.setattr(ray_workers, "ACTOR_START_TIMEOUT_S", 5.0)
        with pytest.raises(UserError, match=f"the cluster has {cpus} CPUs, 0 free. Lower --rollout.workers"):
            RayEnvWorkers(suite, 1)
        assert len(holding._places) == cpus
    deadline = time.time() + 30  # the actor that was never placed is gone: every CPU comes back
    while ray.available_resources().get("CPU", 0) < cpus and time.time() < deadline:
        time.sleep(0.5)
    assert ray.available_resources().get("CPU", 0) == cpus


@pytest.mark.parametrize("command", ["eval", "shift"])
def test_eval_and_shift_on_ray_actors_give_the_local_workers_results(tmp_path, capsys, monkeypatch, command):
    started, start = [], RayEnvWorkers._start_processes
    spy = lambda self, n: started.append(n) or start(self, n)  # noqa: E731
    monkeypatch.setattr(RayEnvWorkers, "_start_processes", spy)
    run_toy(tmp_path / "run", "--dagger.rounds=0")
    policy = ExperimentDir(tmp_path / "run").policy_root(0)
    results = {}
    for backend in ("local", "ray"):
        output = tmp_path / f"{backend}.json"
        args = [command, f"--policy_path={policy}", "--suite.name=toy", "--episodes=3", "--workers=2"]
        assert main([*args, f"--worker_backend={backend}", f"--output={output}"]) == 0
        results[backend] = json.loads(output.read_text())
    assert results["ray"] == results["local"] and started == [2]  # two actors, for the ray pass only
    assert main([command, f"--policy_path={policy}", "--suite.name=toy", "--worker_backend=slurm"]) == 2
    assert "worker_backend must be one of ['local', 'ray'], got 'slurm'" in capsys.readouterr().err


def results_without_timings(folder: Path) -> list[dict[str, str]]:
    """``results.csv`` rows without wall times and experiment paths (what may differ between launchers)."""
    with (folder / "results.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    return [{k: v for k, v in row.items() if k != "experiment" and not k.endswith("_s")} for row in rows]


@pytest.mark.slow  # CI runs it with the slow set
def test_compare_on_ray_writes_the_same_results_as_the_local_launcher_and_skips_finished_runs(tmp_path):
    grid = ["compare", "--methods=[need,bc]", "--seeds=[5]", *(a for a in TOY if not a.startswith("--seed"))]
    assert main([*grid, f"--output_dir={tmp_path / 'local'}", "--jobs=2"]) == 0
    assert main([*grid, f"--output_dir={tmp_path / 'ray'}", "--launcher=ray"]) == 0
    assert results_without_timings(tmp_path / "ray") == results_without_timings(tmp_path / "local")
    logs = {path: path.stat().st_mtime_ns for path in (tmp_path / "ray" / "runs").glob("*.log")}
    assert len(logs) == 4  # need, and BC at each of DAgger's 3 budgets
    assert main([*grid, f"--output_dir={tmp_path / 'ray'}", "--launcher=ray"]) == 0
    assert {path: path.stat().st_mtime_ns for path in logs} == logs  # every run skipped, none rerun


def test_ray_options_are_checked_before_anything_runs(tmp_path, capsys):
    assert main(["compare", "--launcher=slurm", f"--output_dir={tmp_path / 'c'}", "--suite.name=toy"]) == 2
    assert "launcher must be one of ['local', 'ray']" in capsys.readouterr().err
    assert main(["run", "--rollout.worker_backend=mpi", f"--output_dir={tmp_path / 'r'}"]) == 2
    assert "rollout.worker_backend must be one of ['local', 'ray']" in capsys.readouterr().err
    assert not (tmp_path / "c").exists() and not (tmp_path / "r").exists()
