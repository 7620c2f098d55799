"""The ledger (``datasets/ledger.py``): every number ``report``, ``compare`` and a resume read is covered.

Each edit here was once invisible: ``verify`` said 0 problems and ``report`` printed the edited mean.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.datasets.ledger import LEDGER_FILE
from tests.helpers import edit_info_mirror

TOY = ["--suite.name=toy", "--dagger.rounds=1", "--dagger.initial_demos=2", "--dagger.budget_per_task=2"]
TOY += ["--rollout.eval_episodes=2", "--training.steps_per_round=5", "--policy.batch_size=16"]
TOY += ["--rollout.workers=0", "--progress=false"]
OLD_EXPERIMENT = Path(__file__).parent / "data" / "experiment-flat-config-v1"


@pytest.fixture(scope="module")
def committed(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("ledger") / "run"
    assert main(["run", *TOY, f"--output_dir={out}"]) == 0
    return out


@pytest.fixture
def run(committed, tmp_path) -> Path:
    copy = tmp_path / "run"
    shutil.copytree(committed, copy)
    return copy


def _verify(capsys, root: Path) -> tuple[int, str]:
    capsys.readouterr()
    try:
        status = main(["verify", f"--experiment_dir={root}"])
    except SystemExit as exited:
        status = exited.code
    return status, capsys.readouterr().out


def _edit_json(path: Path, edit) -> None:
    values = json.loads(path.read_text())
    edit(values)
    path.write_text(json.dumps(values, indent=2))


def test_the_ledger_lists_every_record_in_commit_order_as_a_chain(committed, capsys):
    entries = json.loads((committed / LEDGER_FILE).read_text())["entries"]
    assert [e["record"] for e in entries] == [
        "rounds/round-000/meta/mtdagger.json",
        "policies/round-000/training.json",
        "rounds/round-001/meta/mtdagger.json",
        "policies/round-001/training.json",
    ]
    assert entries[0]["previous"] is None and all(e["previous"] for e in entries[1:])
    status, out = _verify(capsys, committed)
    assert status == 0 and "0 problem(s)" in out


def test_an_edited_evaluation_in_training_json_is_named(run, capsys):
    _edit_json(
        run / "policies" / "round-000" / "training.json", lambda v: v["eval"]["success"].__setitem__(0, 0.0)
    )
    status, out = _verify(capsys, run)
    assert status == 1 and "policies/round-000/training.json changed after commit" in out
    assert main(["run", *TOY, f"--output_dir={run}", "--resume=true"]) == 2  # refused before any work


def test_a_round_record_edited_with_its_mirror_is_named(run, capsys):
    def halve(values):
        values["eval_success"] = [0.5 for _ in values["eval_success"]]

    root = run / "rounds" / "round-001"
    _edit_json(root / "meta" / "mtdagger.json", halve)
    _edit_json(root / "meta" / "info.json", lambda v: edit_info_mirror(v, halve))
    status, out = _verify(capsys, run)
    assert status == 1 and "rounds/round-001/meta/mtdagger.json changed after commit" in out


def test_an_edited_ledger_breaks_the_chain(run, capsys):
    _edit_json(run / LEDGER_FILE, lambda v: v["entries"][1].__setitem__("sha256", "0" * 64))
    status, out = _verify(capsys, run)
    assert status == 1 and "entry 2 (rounds/round-001/meta/mtdagger.json) breaks the chain" in out


def test_a_record_cut_off_before_the_ledger_is_added_by_the_resume(run, capsys):
    _edit_json(run / LEDGER_FILE, lambda v: v["entries"].pop())
    status, out = _verify(capsys, run)
    assert status == 1 and "training.json is committed but not in ledger.json (a resume adds it)" in out
    assert main(["run", *TOY, "--dagger.rounds=2", f"--output_dir={run}", "--resume=true"]) == 0
    assert _verify(capsys, run)[0] == 0
    assert len(json.loads((run / LEDGER_FILE).read_text())["entries"]) == 6


def test_an_experiment_made_before_the_ledger_verifies_and_gets_one_on_resume(tmp_path, capsys):
    from tests.test_configs import OLD_RUN_OPTIONS

    old = tmp_path / "old"
    shutil.copytree(OLD_EXPERIMENT, old)
    assert not (old / LEDGER_FILE).exists() and _verify(capsys, old)[0] == 0
    assert main(["run", *OLD_RUN_OPTIONS, "--dagger.rounds=2", f"--output_dir={old}", "--resume=true"]) == 0
    assert len(json.loads((old / LEDGER_FILE).read_text())["entries"]) == 6
    assert _verify(capsys, old)[0] == 0


def test_eval_refuses_a_changed_policy_of_an_experiment_unless_told(run, capsys, tmp_path):
    policy = run / "policies" / "round-001"
    args = ["eval", f"--policy_path={policy}", "--suite.name=toy", "--episodes=1", "--workers=0"]
    assert main(args) == 0
    _edit_json(policy / "training.json", lambda v: v.__setitem__("steps", 1))
    capsys.readouterr()
    assert main(args) == 2
    error = capsys.readouterr().err
    assert "policies/round-001/training.json changed after commit" in error and "--unverified=true" in error
    assert main([*args, "--allow_changed_policy=true"]) == 0  # the former spelling of --unverified
    assert "Reading unverified records" in capsys.readouterr().err


def test_the_last_rounds_deleted_to_be_redone_leave_the_ledger_on_resume(run, capsys):
    shutil.rmtree(run / "rounds" / "round-001")
    shutil.rmtree(run / "policies" / "round-001")
    status, out = _verify(capsys, run)
    assert status == 1 and "round-001/meta/mtdagger.json is in the ledger but missing" in out
    assert main(["run", *TOY, f"--output_dir={run}", "--resume=true"]) == 0
    assert _verify(capsys, run)[0] == 0
    assert len(json.loads((run / LEDGER_FILE).read_text())["entries"]) == 4


def test_a_record_deleted_in_the_middle_is_refused_on_resume(run, capsys):
    (run / "policies" / "round-000" / "training.json").unlink()
    (run / "policies" / "round-000").rename(run / "policies" / "round-000-gone")
    assert main(["run", *TOY, f"--output_dir={run}", "--resume=true"]) == 2
    assert "policies/round-000/training.json is in the ledger but missing" in capsys.readouterr().err
