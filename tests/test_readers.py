"""Every reader checks what it reads: ``merge``, ``report``, ``push``, ``eval``, ``shift`` and ``plan``.

Each reader verifies an experiment as ``verify`` does (``datasets.verify.check_before_reading``) and
refuses one that fails in one line (or, for ``report``, leaves that run out and goes on), unless given
``--unverified=true``, which its output then says. A policy folder carries its checksums wherever it lives.
"""

from __future__ import annotations

import json
import logging
import shutil
from pathlib import Path

import pytest

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.datasets.ledger import LEDGER_FILE, entry_hash
from lerobot_mtdagger.datasets.verify import check_before_reading
from lerobot_mtdagger.utils.errors import CorruptExperimentError
from tests.helpers import edit_info_mirror
from tests.test_hub import FakeHfApi
from tests.test_ledger import TOY

DATA = Path(__file__).parent / "data"
EVAL = ["--suite.name=toy", "--episodes=1", "--workers=0"]


@pytest.fixture(scope="module")
def finished(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("readers") / "run"
    assert main(["run", *TOY, f"--output_dir={out}"]) == 0
    return out


@pytest.fixture
def run(finished, tmp_path) -> Path:
    copy = tmp_path / "run"
    shutil.copytree(finished, copy)
    return copy


def _edit_json(path: Path, edit) -> None:
    values = json.loads(path.read_text())
    edit(values)
    path.write_text(json.dumps(values, indent=2))


def edit_round_success(run: Path) -> None:
    """Round 1's ``eval_success`` edited in its record and its mirror alike (the consistent edit)."""

    def perfect(values):
        values["eval_success"] = [1.0 for _ in values["eval_success"]]

    root = run / "rounds" / "round-001"
    _edit_json(root / "meta" / "mtdagger.json", perfect)
    _edit_json(root / "meta" / "info.json", lambda v: edit_info_mirror(v, perfect))


def edit_phase_eval(run: Path) -> None:
    """Phase 1's evaluation in ``training.json`` edited."""
    _edit_json(run / "policies" / "round-001" / "training.json", lambda v: v["eval"].__setitem__("mean", 1.0))


def truncate_data_file(run: Path) -> Path:
    path = next((run / "rounds" / "round-001" / "data").rglob("*.parquet"))
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    return path


def _refused(capsys, args: list[str]) -> str:
    """Runs a command that must be refused in one line (exit 2); returns the line."""
    capsys.readouterr()
    assert main(args) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1 and "Traceback" not in error
    return error


def folder_bytes(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


# -------------------------------------------------------------------------------------------------
# merge
# -------------------------------------------------------------------------------------------------


def test_merge_refuses_a_round_record_edited_with_its_mirror_and_writes_nothing(run, tmp_path, capsys):
    edit_round_success(run)
    merged = tmp_path / "merged"
    error = _refused(capsys, ["merge", f"--experiment_dir={run}", f"--output={merged}"])
    assert (
        "rounds/round-001/meta/mtdagger.json changed after commit" in error and "--unverified=true" in error
    )
    assert not merged.exists()


def test_merge_unverified_merges_and_its_record_says_so(run, tmp_path, capsys):
    edit_round_success(run)
    merged = tmp_path / "merged"
    assert main(["merge", f"--experiment_dir={run}", f"--output={merged}", "--unverified=true"]) == 0
    assert "Reading unverified records" in capsys.readouterr().err
    record = json.loads((merged / "meta" / "mtdagger.json").read_text())
    assert any("round-001/meta/mtdagger.json changed after commit" in line for line in record["unverified"])


def test_merge_refuses_a_truncated_data_file(run, tmp_path, capsys):
    path = truncate_data_file(run)
    error = _refused(capsys, ["merge", f"--experiment_dir={run}", f"--output={tmp_path / 'merged'}"])
    assert f"{path} changed after commit" in error


# -------------------------------------------------------------------------------------------------
# report
# -------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("damage", [edit_phase_eval, truncate_data_file], ids=["edited", "truncated"])
def test_report_leaves_out_a_damaged_run_names_it_and_goes_on(finished, tmp_path, capsys, damage):
    damaged = tmp_path / "damaged"
    shutil.copytree(finished, damaged)
    damage(damaged)
    out = tmp_path / "report"
    capsys.readouterr()
    assert main(["report", f"--experiments=[{finished},{damaged}]", f"--output_dir={out}"]) == 0
    assert f"Report: {damaged}: left out, {damaged} fails verification" in capsys.readouterr().err
    report = (out / "report.md").read_text()
    assert "Records not verified: 1 run(s)" in report and f"{damaged}: left out" in report
    meta = json.loads((out / "results_meta.json").read_text())
    assert len(meta["verification"]) == 1
    error = _refused(capsys, ["report", f"--experiments=[{damaged}]"])
    assert "None of the 1 run(s) can be reported" in error and f"{damaged} fails verification" in error


def test_report_unverified_reads_the_edited_run_and_says_so(run, tmp_path):
    edit_phase_eval(run)
    out = tmp_path / "report"
    assert main(["report", f"--experiments=[{run}]", f"--output_dir={out}", "--unverified=true"]) == 0
    report = (out / "report.md").read_text()
    assert f"{run}: read from unverified records" in report and "training.json changed after commit" in report
    redrawn = tmp_path / "redrawn"
    assert main(["report", f"--results=[{out}]", f"--output_dir={redrawn}"]) == 0
    assert (redrawn / "report.md").read_text() == report  # the saved table keeps the note


# -------------------------------------------------------------------------------------------------
# push
# -------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("damage", [edit_round_success, truncate_data_file], ids=["edited", "truncated"])
def test_push_refuses_a_damaged_experiment_before_sending_anything(run, tmp_path, damage):
    from lerobot_mtdagger.datasets.hub import push_experiment

    damage(run)
    api = FakeHfApi(tmp_path / "hub")
    with pytest.raises(CorruptExperimentError, match="fails verification"):
        push_experiment(run, "tester/rounds", "tester/policies", api=api)
    assert api.calls == [] and api.repos == {}


def test_pushed_policy_folders_carry_their_checksums_and_are_checked_when_pulled_back(run, tmp_path, capsys):
    from lerobot_mtdagger.datasets.hub import push_experiment

    api = FakeHfApi(tmp_path / "hub")
    push_experiment(run, "tester/rounds", "tester/policies", api=api)
    pulled = tmp_path / "pulled"
    shutil.copytree(api.snapshot("tester/policies", "round-001", repo_type="model"), pulled)
    assert json.loads((pulled / "training.json").read_text())["files"]
    (pulled / ".cache" / "huggingface").mkdir(parents=True)  # what a download adds beside the files
    (pulled / ".cache" / "huggingface" / "model.safetensors.metadata").write_text("x")
    assert main(["eval", f"--policy_path={pulled}", *EVAL]) == 0
    _flip_a_byte(pulled / "model.safetensors")
    assert "model.safetensors changed after commit" in _refused(
        capsys, ["eval", f"--policy_path={pulled}", *EVAL]
    )


# -------------------------------------------------------------------------------------------------
# eval, shift and plan
# -------------------------------------------------------------------------------------------------


def _flip_a_byte(path: Path) -> None:
    data = bytearray(path.read_bytes())
    data[-1] ^= 0x01  # the last weight's last byte: the file still loads
    path.write_bytes(bytes(data))


@pytest.mark.parametrize("command", ["eval", "shift"])
def test_eval_and_shift_refuse_a_policy_of_an_edited_experiment(run, capsys, command):
    edit_round_success(run)
    error = _refused(capsys, [command, f"--policy_path={run / 'policies' / 'round-001'}", *EVAL])
    assert "rounds/round-001/meta/mtdagger.json changed after commit" in error


def test_eval_unverified_evaluates_and_its_output_says_so(run, tmp_path):
    edit_phase_eval(run)
    output = tmp_path / "eval.json"
    policy = run / "policies" / "round-001"
    assert main(["eval", f"--policy_path={policy}", *EVAL, f"--output={output}", "--unverified=true"]) == 0
    assert any(
        "training.json changed after commit" in line for line in json.loads(output.read_text())["unverified"]
    )


@pytest.mark.parametrize("command", ["eval", "shift"])
def test_a_copied_out_policy_with_a_changed_weight_is_refused(run, tmp_path, capsys, command):
    copied = tmp_path / "copied"
    shutil.copytree(run / "policies" / "round-001", copied)
    assert main([command, f"--policy_path={copied}", *EVAL]) == 0
    _flip_a_byte(copied / "model.safetensors")
    error = _refused(capsys, [command, f"--policy_path={copied}", *EVAL])
    assert f"{copied} differs from the checksums its training.json carries" in error
    assert "model.safetensors changed after commit" in error


def test_a_policy_without_checksums_is_evaluated_and_the_log_says_so(run, tmp_path):
    plain = tmp_path / "plain"
    shutil.copytree(run / "policies" / "round-001", plain)
    (plain / "training.json").unlink()  # a LeRobot policy folder carries none
    records = []
    handler = logging.Handler(logging.INFO)
    handler.emit = records.append
    logging.getLogger("lerobot_mtdagger").addHandler(handler)
    try:
        assert main(["eval", f"--policy_path={plain}", *EVAL]) == 0
    finally:
        logging.getLogger("lerobot_mtdagger").removeHandler(handler)
    assert any(f"{plain} carries no checksums" in record.getMessage() for record in records)


def test_plan_refuses_a_round_and_a_policy_of_an_edited_experiment(run, tmp_path, capsys):
    edit_round_success(run)
    rounds = f"--datasets=[{run / 'rounds' / 'round-001'}]"
    output = tmp_path / "plan.json"
    error = _refused(capsys, ["plan", rounds, "--budget=4", f"--output={output}"])
    assert "rounds/round-001/meta/mtdagger.json changed after commit" in error and not output.exists()
    assert main(["plan", rounds, "--budget=4", f"--output={output}", "--unverified=true"]) == 0
    assert json.loads(output.read_text())["unverified"]


# -------------------------------------------------------------------------------------------------
# The ledger: missing, replaced, never made
# -------------------------------------------------------------------------------------------------


def test_a_missing_ledger_is_named_by_verify_every_reader_and_resume(run, tmp_path, capsys):
    (run / LEDGER_FILE).unlink()
    capsys.readouterr()
    with pytest.raises(SystemExit):
        main(["verify", f"--experiment_dir={run}"])
    assert f"PROBLEM {run / LEDGER_FILE} is missing (deleted or moved)" in capsys.readouterr().out
    for args in (
        ["merge", f"--experiment_dir={run}", f"--output={tmp_path / 'merged'}"],
        ["eval", f"--policy_path={run / 'policies' / 'round-000'}", *EVAL],
        ["run", *TOY, f"--output_dir={run}", "--resume=true"],
    ):
        assert f"{LEDGER_FILE} is missing" in _refused(capsys, args)
    assert not (run / LEDGER_FILE).exists()  # the refused resume did not start a new one


def test_a_replaced_ledger_is_named(run):
    entries, previous = [], None
    for entry in json.loads((run / LEDGER_FILE).read_text())["entries"]:
        entries.append({"record": entry["record"], "sha256": "0" * 64, "previous": previous})
        previous = entry_hash(entries[-1])
    (run / LEDGER_FILE).write_text(json.dumps({"entries": entries}))
    with pytest.raises(CorruptExperimentError, match=f"{LEDGER_FILE} was replaced"):
        check_before_reading(ExperimentDir(run))


def test_an_experiment_made_before_ledgers_is_told_apart_and_read(tmp_path, capsys):
    old = tmp_path / "old"
    shutil.copytree(DATA / "experiment-lerobot-0.4.4", old)
    capsys.readouterr()
    assert main(["verify", f"--experiment_dir={old}"]) == 0
    out = capsys.readouterr().out
    assert "NOTE" in out and "made before experiments had a ledger" in out and "0 problem(s)" in out
    assert main(["merge", f"--experiment_dir={old}", f"--output={tmp_path / 'merged'}"]) == 0
    assert main(["report", f"--experiments=[{old}]"]) == 0
    assert main(["eval", f"--policy_path={old / 'policies' / 'round-001'}", *EVAL]) == 0
    assert not (old / LEDGER_FILE).exists()  # reading starts no ledger


# -------------------------------------------------------------------------------------------------
# Resume of a finished run
# -------------------------------------------------------------------------------------------------


def test_resuming_a_finished_run_leaves_its_folder_byte_identical(run, capsys):
    before = folder_bytes(run)
    capsys.readouterr()
    assert main(["run", *TOY, f"--output_dir={run}", "--resume=true"]) == 0
    assert capsys.readouterr().out.count("round ") >= 2  # it still prints the summary lines
    assert folder_bytes(run) == before
