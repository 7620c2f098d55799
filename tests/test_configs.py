"""``RunConfig``: every option a preset fills has one home, and the command line always wins."""

from __future__ import annotations

import contextlib
import dataclasses
import inspect
import io
import json
import shutil
from pathlib import Path

import draccus
import pytest

from lerobot_mtdagger.analysis.results import results_rows
from lerobot_mtdagger.cli import main
from lerobot_mtdagger.datasets.config_layout import flatten
from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.datasets.migrations import FLAT_OPTION_PATHS, is_flat, migrate_run_config, stored_option
from lerobot_mtdagger.datasets.verify import verify_experiment
from lerobot_mtdagger.envs import suite_from_config
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.dagger import run
from lerobot_mtdagger.runner.option_groups import DAggerConfig, TrainingConfig
from lerobot_mtdagger.runner.presets import PRESET_FIELDS, PRESETS
from lerobot_mtdagger.runner.run_setup import unseen_task_suite
from lerobot_mtdagger.utils import parsing
from lerobot_mtdagger.utils.errors import UserError


def parse(*args: str) -> RunConfig:
    return draccus.parse(RunConfig, args=list(args))


def value_of(config: RunConfig, path: str):
    owner = config
    for part in path.split("."):
        owner = getattr(owner, part)
    return owner


def another_value(path: str, value):
    """A valid command-line value that differs from the preset's ``value``."""
    if path == "suite.name":
        return "drawers" if value != "drawers" else "metaworld-mt25"
    if path == "suite.obs_mode":
        return "rgb" if value != "rgb" else "state"
    if path == "training.sampling":
        return "balanced" if value != "balanced" else "uniform"
    if path == "training.steps_rule":
        return "epochs" if value != "epochs" else "fixed"
    if isinstance(value, float):
        return value * 3
    return value + 2


def preset_values(preset: str, mode: str = "dagger") -> dict:
    """What ``preset`` fills in a run of ``mode`` (a mapping value is keyed by the run mode)."""
    values = PRESETS[preset].items()
    return {path: value[mode] if isinstance(value, dict) else value for path, value in values}


def test_every_preset_fills_the_same_options():
    assert all(tuple(preset) == PRESET_FIELDS for preset in PRESETS.values())


@pytest.mark.parametrize("preset", list(PRESETS))
def test_presets_fill_every_option_left_unset(preset):
    for mode in ("dagger", "bc"):
        config = parse(f"--preset={preset}", f"--mode={mode}")
        assert {path: value_of(config, path) for path in PRESET_FIELDS} == preset_values(preset, mode)


@pytest.mark.parametrize("index", range(len(PRESET_FIELDS)))
def test_a_command_line_value_wins_over_the_preset(index):
    path = PRESET_FIELDS[index]
    preset = list(PRESETS)[index % len(PRESETS)]  # every field once, every preset in turn
    wanted = another_value(path, preset_values(preset)[path])
    config = parse(f"--preset={preset}", f"--{path}={wanted}")
    assert value_of(config, path) == wanted
    others = {p: value_of(config, p) for p in PRESET_FIELDS if p != path}
    assert others == {p: v for p, v in preset_values(preset).items() if p != path}


@pytest.mark.parametrize("preset", list(PRESETS))
def test_every_preset_option_set_at_once_wins(preset):
    wanted = {path: another_value(path, value) for path, value in preset_values(preset).items()}
    config = parse(f"--preset={preset}", *(f"--{path}={value}" for path, value in wanted.items()))
    assert {path: value_of(config, path) for path in PRESET_FIELDS} == wanted


def test_scheduler_n_min_typed_by_the_user_is_kept_whatever_the_method():
    for method in ("uniform", "gain"):
        config = parse("--scheduler.n_min=5", f"--scheduler.type={method}", "--dagger.budget_per_task=5")
        assert config.scheduler.n_min == 5 and config.to_dict()["scheduler"]["n_min"] == 5
    assert parse("--preset=drawers-pointcloud", "--scheduler.n_min=2").scheduler.n_min == 2


def test_python_construction_applies_presets_the_same_way():
    config = RunConfig(preset="drawers-pointcloud-paper", dagger=DAggerConfig(rounds=1))
    assert config.dagger.rounds == 1 and config.scheduler.n_min == 5 and config.policy.lr == 1e-4
    assert config.dagger.initial_demos == 30 and config.suite.name == "drawers"
    assert config.suite.num_points == 1024


def test_the_cpu_visual_presets_keep_the_papers_rounds_with_less_data_and_compute():
    for name in ("metaworld-pixels", "drawers-pointcloud"):
        cpu, paper = RunConfig(preset=name), RunConfig(preset=f"{name}-paper")
        assert cpu.dagger.rounds == paper.dagger.rounds and cpu.suite.name == paper.suite.name
        assert cpu.suite.obs_mode == paper.suite.obs_mode
        assert cpu.dagger.initial_demos < paper.dagger.initial_demos
        cpu_samples = cpu.training.steps_per_round * cpu.policy.batch_size
        assert cpu_samples < paper.training.steps_per_round * paper.policy.batch_size
    assert RunConfig(preset="drawers-pointcloud").suite.num_points == 512


def test_presets_sample_uniformly_except_pixel_runs_and_an_explicit_choice_wins():
    assert RunConfig(preset="metaworld-pixels").training.sampling == "balanced"
    assert RunConfig(preset="metaworld-pixels", mode="bc").training.sampling == "balanced"
    for name in ("small", "metaworld-state", "metaworld-pixels-paper", "drawers-pointcloud"):
        assert RunConfig(preset=name).training.sampling == "uniform", name
    assert parse("--preset=metaworld-pixels", "--training.sampling=uniform").training.sampling == "uniform"
    bc_uniform = parse("--preset=metaworld-pixels", "--mode=bc", "--training.sampling=uniform")
    assert bc_uniform.training.sampling == "uniform"
    with pytest.raises(ValueError, match=r"training.sampling must be one of \['uniform', 'balanced'\]"):
        RunConfig(preset="metaworld-pixels", training=TrainingConfig(sampling="per-task"))


def test_bc_is_a_run_mode():
    config = parse("--mode=bc")
    assert config.is_bc and config.method == "bc"
    assert config.output_dir.name == "small-bc-seed0"
    with pytest.raises(draccus.utils.ParsingError):
        parse("--mode=behaviour-cloning")


@pytest.mark.parametrize(
    ("old", "new"), [("--scheduler.type=bc", "--mode=bc"), ("--n_min=5", "--scheduler.n_min=5")]
)
def test_old_spellings_fail_naming_the_new_one(capsys, tmp_path, old, new):
    assert main(["run", old, f"--output_dir={tmp_path / 'out'}"]) == 2
    assert new in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


# -------------------------------------------------------------------------------------------------
# Composed options: groups, renames, the migration of experiments stored with the flat layout
# -------------------------------------------------------------------------------------------------

OLD_EXPERIMENT = Path(__file__).parent / "data" / "experiment-flat-config-v1"
"""A toy run written with the flat config (``HOW.md`` there has its command)."""

OLD_RUN_OPTIONS = [
    "--suite.name=toy",
    "--dagger.initial_demos=1",
    "--dagger.budget_per_task=1",
    "--training.steps_per_round=5",
    "--rollout.eval_episodes=1",
    "--rollout.workers=0",
    "--seed=3",
    "--progress=false",
    "--policy.batch_size=8",
    "--policy.state_hidden_dims=[16]",
    "--policy.head_hidden_dims=[16]",
    "--policy.task_embedding_dim=4",
]
"""``OLD_EXPERIMENT``'s options in today's spelling (its --rounds=1 aside)."""


def help_text() -> str:
    output = io.StringIO()
    with contextlib.redirect_stdout(output), pytest.raises(SystemExit):
        parse("--help")
    return output.getvalue()


def test_draccus_reads_each_config_class_source_once_and_the_help_is_unchanged(monkeypatch):
    """Without the cache every parse of ``RunConfig`` re-read a class's module once per field (2-3 s)."""
    read, getsource = [], inspect.getsource
    monkeypatch.setattr(inspect, "getsource", lambda obj: read.append(obj) or getsource(obj))
    parsing._class_source.cache_clear()
    # draccus >= 0.11 (LeRobot 0.6's) also caches class sources itself: start it empty too, or a class
    # read by an earlier test in this process is never read again here
    draccus_cache = getattr(parsing.draccus_docstring, "_get_class_source", None)
    if hasattr(draccus_cache, "cache_clear"):
        draccus_cache.cache_clear()
    cached_help = help_text()
    classes = [obj for obj in read if isinstance(obj, type)]
    assert RunConfig in classes and len(classes) == len(set(classes)), classes  # once, not per field
    assert any(cls.__name__ == "ACTConfigStudent" for cls in classes)  # no source: found out once too
    monkeypatch.setattr(parsing.draccus_docstring, "inspect", inspect)  # draccus as it comes
    assert help_text() == cached_help


def test_a_learning_rate_schedule_is_checked_and_refused_for_a_lerobot_student(capsys, tmp_path):
    assert parse("--training.lr_schedule=cosine").training.lr_schedule == "cosine"
    out = tmp_path / "out"
    assert main(["run", "--training.lr_schedule=linear", f"--output_dir={out}"]) == 2
    assert "training.lr_schedule" in capsys.readouterr().err and not out.exists()
    assert main(["run", "--policy.type=act", "--training.lr_schedule=cosine", f"--output_dir={out}"]) == 2
    assert "follows its own scheduler preset" in capsys.readouterr().err and not out.exists()


@pytest.mark.parametrize(
    ("option", "message"),
    [
        ("--policy.use_amp=true", "--policy.use_amp is not supported by run: its training, collection"),
        ("--policy.use_peft=true", "--policy.use_peft is not supported by run"),
        ("--policy.push_to_hub=true", "`lerobot-mtdagger push` uploads"),
        ("--policy.pretrained_path=outputs/some/policy", "--policy.pretrained_path is not supported"),
    ],
)
def test_lerobot_options_the_runner_would_ignore_are_refused(capsys, tmp_path, option, message):
    """A LeRobot student's config has them (read by lerobot-train and lerobot-eval); run does not."""
    out = tmp_path / "out"
    # A toy BC run, so that a refusal that went missing fails in seconds, not after a whole experiment.
    tiny = ["--suite.name=toy", "--dagger.rounds=0", "--dagger.initial_demos=1", "--rollout.eval_episodes=1"]
    tiny += ["--rollout.max_steps=10", "--training.steps_per_round=2", "--policy.batch_size=8"]
    assert main(["run", *tiny, "--policy.type=act", option, f"--output_dir={out}"]) == 2
    assert message in capsys.readouterr().err and not out.exists()


def test_mixed_precision_is_no_option_of_mtdagger_and_off_is_accepted(capsys, tmp_path):
    out = tmp_path / "out"
    assert main(["run", "--policy.use_amp=true", f"--output_dir={out}"]) == 2  # mtdagger has no such option
    error = capsys.readouterr().err
    assert "unrecognized arguments: --policy.use_amp=true" in error and "run --help" in error
    assert not out.exists()
    assert parse("--policy.type=act", "--policy.use_amp=false").policy.use_amp is False


def test_the_run_config_has_at_most_thirteen_top_level_options():
    # seven groups (suite, dagger, rollout, training, scheduler, policy, expert) and six plain options
    assert len(dataclasses.fields(RunConfig)) <= 13


@pytest.mark.parametrize("old", sorted(FLAT_OPTION_PATHS))
def test_every_flat_option_names_its_grouped_spelling_and_writes_nothing(capsys, tmp_path, old):
    new = FLAT_OPTION_PATHS[old]
    assert value_of(parse(), new) == value_of(RunConfig(), new)  # the new path exists
    assert main(["run", f"--{old}=1", f"--output_dir={tmp_path / 'out'}"]) == 2
    error = capsys.readouterr().err
    assert f"--{new}=1" in error and len(error.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", ["eval", "shift"])
def test_eval_and_shift_name_the_grouped_suite_options(capsys, command):
    assert main([command, "--policy_path=unused", "--obs_mode=rgb"]) == 2
    assert "--suite.obs_mode=rgb" in capsys.readouterr().err
    assert main([command, "--policy_path=unused", "--suite=toy"]) == 2
    assert "--suite.name=toy" in capsys.readouterr().err


def test_compare_names_the_grouped_spelling_of_the_run_options_it_passes_on(capsys, tmp_path):
    assert main(["compare", "--methods=[need]", f"--output_dir={tmp_path / 'c'}", "--rounds=2"]) == 2
    assert "--dagger.rounds=2" in capsys.readouterr().err
    assert not (tmp_path / "c").exists()


def test_a_flat_config_migrates_into_the_groups():
    flat = json.loads((OLD_EXPERIMENT / "config.json").read_text())
    migrated = migrate_run_config(flat)
    assert not is_flat(migrated) and migrate_run_config(migrated) == migrated
    assert migrated["suite"]["name"] == "toy" and migrated["dagger"]["rounds"] == 1
    assert migrated["rollout"]["max_steps"] is None and migrated["training"]["steps_per_round"] == 5
    assert migrated["policy"] == flat["policy"] and migrated["scheduler"] == flat["scheduler"]
    leaves = flatten(migrated)
    assert {path for old, path in FLAT_OPTION_PATHS.items() if old in flat} <= set(leaves)
    assert (
        stored_option(flat, "training.sampling") == stored_option(migrated, "training.sampling") == "uniform"
    )
    # Every option of today's config is either a migrated one or one added since (with its default).
    today = flatten(parse("--suite.name=toy").to_dict())
    added = set(today) - set(leaves)
    expected = {"suite.episode_length", "suite.module", "rollout.worker_backend", "rollout.ray_address"}
    expected |= {"training.lr_schedule", "training.seed", "training.progress_every_s"}
    expected |= {"expert.noise", "expert.noise_correlation", "expert.noise_seed", "expert.labels"}
    expected |= {"expert.path", "expert.type", "expert.min_success", "expert.success_episodes"}
    expected |= {"expert.noise_by_task", "rollout.eval_phases"}
    assert added == expected, added
    assert all(today[path] == RunConfig.option_defaults()[path] for path in added)


def test_an_experiment_stored_with_the_flat_config_resumes_and_grows(tmp_path):
    root = tmp_path / "old"
    shutil.copytree(OLD_EXPERIMENT, root)
    before = {p.relative_to(root): p.read_bytes() for p in (root / "rounds").rglob("*") if p.is_file()}
    args = [*OLD_RUN_OPTIONS, f"--output_dir={root}", "--resume=true"]
    lines = run(parse(*args, "--dagger.rounds=2"))
    assert [line.split(":")[0] for line in lines] == ["round 0", "round 1", "round 2"]
    assert verify_experiment(ExperimentDir(root)) == (3, 3, [])
    for path, content in before.items():  # the rounds written before are kept as they were
        assert (root / path).read_bytes() == content, path
    stored = json.loads((root / "config.json").read_text())
    assert stored["dagger"]["rounds"] == 2 and stored["suite"]["name"] == "toy"  # rewritten grouped
    rows = results_rows([root])
    assert [row["round"] for row in rows] == [0, 1, 2]
    assert {row["eval_episodes_per_task"] for row in rows} == {1}  # read from old and new records


def test_a_result_changing_option_differing_from_a_flat_stored_config_is_refused(tmp_path):
    root = tmp_path / "old"
    shutil.copytree(OLD_EXPERIMENT, root)
    args = [*OLD_RUN_OPTIONS, f"--output_dir={root}", "--resume=true", "--dagger.rounds=1"]
    with pytest.raises(UserError, match=r"training.sampling: 'uniform' -> 'balanced'"):
        run(parse(*args, "--training.sampling=balanced"))
    assert json.loads((root / "config.json").read_text()) == json.loads(
        (OLD_EXPERIMENT / "config.json").read_text()
    )


def test_the_migrations_are_one_ordered_list_of_known_options():
    """Oldest first, named once; each former value is an option of today's config with a plain default."""
    from lerobot_mtdagger.datasets.migrations import MIGRATIONS, former_option_values

    assert [m.since for m in MIGRATIONS] == sorted(m.since for m in MIGRATIONS)
    assert len({m.name for m in MIGRATIONS}) == len(MIGRATIONS)
    today = flatten(parse("--suite.name=toy").to_dict())
    former = former_option_values()
    assert former == {
        "suite.placement": "narrow",
        "training.sampling": "uniform",
        "training.steps_rule": "fixed",
        "training.epochs": 100.0,
    }
    assert set(former) <= set(today)
    assert {path: RunConfig.option_defaults()[path] for path in former} == former
    # A migration's rewrite leaves today's layout as it is.
    grouped = parse("--suite.name=toy").to_dict()
    assert migrate_run_config(grouped) == grouped and migrate_run_config(grouped) is not grouped


def test_options_parsed_in_many_threads_at_once_leave_stderr_as_it_was():
    """``compare``'s pool parses each run's options in its own thread; a parse swaps ``sys.stderr``."""
    import sys
    import threading

    before = sys.stderr
    options = ["--suite.name=toy", "--scheduler.type=need", "--output_dir=/tmp/unused"]

    def parse_many() -> None:
        for _ in range(30):
            parsing.parse_options(RunConfig, options, "lerobot-mtdagger run")

    threads = [threading.Thread(target=parse_many) for _ in range(6)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert sys.stderr is before


@pytest.mark.parametrize(
    ("policy_options", "evaluated"),
    [
        (["--policy.type=act"], True),  # LeRobot's students hide the task of some frames with held-out tasks
        (["--policy.type=mtdagger"], True),
        (["--policy.type=mtdagger", "--policy.task_dropout=0"], False),  # no task-free embedding to act with
    ],
)
def test_each_student_says_whether_its_run_evaluates_unseen_drawers(policy_options, evaluated):
    """A LeRobot student on drawers once failed here (its options have no ``resolved_task_dropout``)."""
    config = parse(
        "--suite.name=drawers", "--suite.obs_mode=state", "--rollout.eval_episodes=1", *policy_options
    )
    suite = suite_from_config(config.suite)
    assert (unseen_task_suite(config, suite) is not None) is evaluated
