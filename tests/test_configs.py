"""``RunConfig``: every option a preset fills has one home, and the command line always wins."""

from __future__ import annotations

import draccus
import pytest

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.runner.configs import PRESET_FIELDS, PRESETS, RunConfig


def parse(*args: str) -> RunConfig:
    return draccus.parse(RunConfig, args=list(args))


def value_of(config: RunConfig, path: str):
    owner = config
    for part in path.split("."):
        owner = getattr(owner, part)
    return owner


def another_value(path: str, value):
    """A valid command-line value that differs from the preset's ``value``."""
    if path == "suite":
        return "drawers" if value != "drawers" else "metaworld-mt25"
    if path == "obs_mode":
        return "rgb" if value != "rgb" else "state"
    if isinstance(value, float):
        return value * 3
    return value + 2


def test_every_preset_fills_the_same_options():
    assert all(tuple(preset) == PRESET_FIELDS for preset in PRESETS.values())


@pytest.mark.parametrize("preset", list(PRESETS))
def test_presets_fill_every_option_left_unset(preset):
    config = parse(f"--preset={preset}")
    assert {path: value_of(config, path) for path in PRESET_FIELDS} == PRESETS[preset]


@pytest.mark.parametrize("index", range(len(PRESET_FIELDS)))
def test_a_command_line_value_wins_over_the_preset(index):
    path = PRESET_FIELDS[index]
    preset = list(PRESETS)[index % len(PRESETS)]  # every field once, every preset in turn
    wanted = another_value(path, PRESETS[preset][path])
    config = parse(f"--preset={preset}", f"--{path}={wanted}")
    assert value_of(config, path) == wanted
    others = {p: value_of(config, p) for p in PRESET_FIELDS if p != path}
    assert others == {p: v for p, v in PRESETS[preset].items() if p != path}


@pytest.mark.parametrize("preset", list(PRESETS))
def test_every_preset_option_set_at_once_wins(preset):
    wanted = {path: another_value(path, value) for path, value in PRESETS[preset].items()}
    config = parse(f"--preset={preset}", *(f"--{path}={value}" for path, value in wanted.items()))
    assert {path: value_of(config, path) for path in PRESET_FIELDS} == wanted


def test_scheduler_n_min_typed_by_the_user_is_kept_whatever_the_method():
    for method in ("uniform", "gain"):
        config = parse("--scheduler.n_min=5", f"--scheduler.type={method}", "--budget_per_task=5")
        assert config.scheduler.n_min == 5 and config.to_dict()["scheduler"]["n_min"] == 5
    assert parse("--preset=drawers-pointcloud", "--scheduler.n_min=2").scheduler.n_min == 2


def test_python_construction_applies_presets_the_same_way():
    config = RunConfig(preset="drawers-pointcloud", rounds=1)
    assert config.rounds == 1 and config.scheduler.n_min == 5 and config.policy.lr == 1e-4


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
