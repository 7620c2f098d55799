"""``compare``'s shared round 0 on the toy suite, with real runs: a DAgger method starts from the round 0
and phase 0 another method of its seed made, says so, passes ``verify``, and ends as the same run that
made its own does; runs that would make another round 0 are never sources."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from lerobot_mtdagger.analysis.round_zero import round_zero_differences, round_zero_source
from lerobot_mtdagger.cli import main
from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.utils.lerobot_compat import INFO_KEEPS_OTHER_KEYS
from lerobot_mtdagger.utils.parsing import parse_options
from tests.helpers import TOY_COMPARE

TINY = TOY_COMPARE
COPIED_NOTE = "copied from the run uniform-seed0"


def compare(folder: Path, methods: str, *extra: str) -> Path:
    """The runs folder of a ``compare`` of ``methods`` on seed 0, one run at a time."""
    args = ["compare", f"--methods={methods}", "--seeds=[0]", "--jobs=1", f"--output_dir={folder}"]
    assert main([*args, *extra, *TINY]) == 0
    return folder / "runs"


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> tuple[Path, Path]:
    """uniform then need in one compare (need copies uniform's round 0), and need alone in another."""
    root = tmp_path_factory.mktemp("round_zero")
    return compare(root / "both", "[uniform,need]"), compare(root / "alone", "[need]")


def round_zero_files(run: Path) -> dict[str, Path]:
    """Round 0's data files and phase 0's policy files (not the records), by relative path."""
    experiment = ExperimentDir(run)
    files = {}
    for root in (experiment.round_root(0), experiment.policy_root(0)):
        for path in root.rglob("*"):
            if path.is_file() and path.name not in ("info.json", "mtdagger.json"):
                files[str(path.relative_to(run))] = path
    return files


def test_a_method_starts_from_the_round_zero_another_made_and_its_record_says_so(runs):
    both, _ = runs
    uniform, need = ExperimentDir(both / "uniform-seed0"), ExperimentDir(both / "need-seed0")
    record = need.read_round_record(0)
    assert record.method == "need" and record.config["scheduler"]["type"] == "need"
    assert record.config["output_dir"] == str(both / "need-seed0")
    assert any(COPIED_NOTE in note for note in record.notes)
    assert not any("copied" in note for note in uniform.read_round_record(0).notes)
    theirs, ours = round_zero_files(uniform.root), round_zero_files(need.root)
    assert sorted(theirs) == sorted(ours) and any("model.safetensors" in name for name in ours)
    assert all(ours[name].samefile(theirs[name]) for name in ours)  # hard links: no second copy
    assert need.committed_phases() == [0, 1, 2]
    info = json.loads((need.round_root(0) / "meta" / "info.json").read_text())
    record = json.loads((need.round_root(0) / "meta" / "mtdagger.json").read_text())
    assert info["mtdagger"] == record if INFO_KEEPS_OTHER_KEYS else "mtdagger" not in info


def test_the_run_with_a_copied_round_zero_ends_as_the_one_that_made_its_own(runs):
    both, alone = runs
    copied, made = ExperimentDir(both / "need-seed0"), ExperimentDir(alone / "need-seed0")
    assert not any("copied" in note for note in made.read_round_record(0).notes)
    for k in (0, 1, 2):
        assert copied.read_phase_record(k).eval == made.read_phase_record(k).eval
        assert copied.read_phase_record(k).loss_end == made.read_phase_record(k).loss_end
        weights = [run.policy_root(k) / "model.safetensors" for run in (copied, made)]
        assert weights[0].read_bytes() == weights[1].read_bytes()
    for k in (1, 2):
        assert copied.read_round_record(k).allocation == made.read_round_record(k).allocation
    tables = [json.loads((folder.parent / "results.json").read_text()) for folder in (both, alone)]
    rows = [[(r["round"], r["eval_success"]) for r in table if r["method"] == "need"] for table in tables]
    assert rows[0] == rows[1] and len(rows[0]) == 3


def test_verify_accepts_a_run_with_a_copied_round_zero(runs):
    both, _ = runs
    assert main(["verify", f"--experiment_dir={both / 'need-seed0'}"]) == 0


def test_share_round0_false_makes_every_run_its_own(runs, tmp_path):
    both, _ = runs
    shutil.copytree(both / "uniform-seed0", tmp_path / "own" / "runs" / "uniform-seed0")  # a source there
    runs = compare(tmp_path / "own", "[gain]", "--share_round0=false")
    gain = ExperimentDir(runs / "gain-seed0")
    assert not any("copied" in note for note in gain.read_round_record(0).notes)
    theirs, ours = round_zero_files(runs / "uniform-seed0"), round_zero_files(gain.root)
    assert not any(ours[name].samefile(theirs[name]) for name in ours)


def config_of(*options: str) -> dict:
    return parse_options(
        RunConfig, [*TINY, "--output_dir=/tmp/x", *options], "lerobot-mtdagger run"
    ).to_dict()


@pytest.mark.parametrize(
    ("options", "differing"),
    [
        (["--scheduler.type=gain"], []),
        (["--scheduler.type=need", "--scheduler.temperature=0.5"], []),
        (["--dagger.rounds=5"], []),  # no round depends on how many follow it
        (["--rollout.workers=2", "--progress=false"], []),  # never change a result
        (["--policy.lr=0.001"], ["policy.lr"]),
        (["--seed=1"], ["seed"]),
        (["--rollout.eval_episodes=3"], ["rollout.eval_episodes"]),
        (["--mode=bc"], ["mode"]),  # BC's round 0 holds its whole budget
    ],
)
def test_only_the_scheduler_rounds_and_neutral_options_may_differ(options, differing):
    assert round_zero_differences(config_of("--scheduler.type=uniform"), config_of(*options)) == differing


def test_a_run_without_phase_zero_or_with_other_options_or_foreign_is_no_source(runs, tmp_path):
    both, _ = runs
    target = f"--output_dir={tmp_path / 'gain'}"
    config = parse_options(RunConfig, [*TINY, "--scheduler.type=gain", target], "run")
    assert round_zero_source(both, config, exclude=tmp_path / "gain") == both / "need-seed0"  # first by name
    cut = tmp_path / "cut"
    shutil.copytree(both / "uniform-seed0", cut / "uniform-seed0")
    shutil.rmtree(cut / "uniform-seed0" / "policies")  # round 0 committed, phase 0 not
    (cut / "foreign" / "policies" / "round-000").mkdir(parents=True)  # a phase 0, as far as names go
    (cut / "foreign" / "policies" / "round-000" / "training.json").write_text("{}")
    (cut / "foreign" / "config.json").write_text("not json")
    assert round_zero_source(cut, config, exclude=cut / "gain") is None
    other = parse_options(RunConfig, [*TINY, "--policy.lr=0.001", target], "run")
    assert round_zero_source(both, other, exclude=tmp_path / "gain") is None
