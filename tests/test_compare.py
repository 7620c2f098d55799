"""``compare`` and ``report`` end to end on the toy suite: every method x seed x round in the table,
BC at every budget, every figure written; plus the helpers' arithmetic and bad input."""

from __future__ import annotations

import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tarfile
import time
from pathlib import Path

import pytest

from lerobot_mtdagger.analysis.compare import (
    CompareConfig,
    bc_rounds_for,
    jobs_for,
    split_arguments,
)
from lerobot_mtdagger.analysis.figures import hardest_tasks, seed_reach
from lerobot_mtdagger.analysis.launchers import Job, RunPool, is_finished
from lerobot_mtdagger.analysis.record_saving import compact, save_runs
from lerobot_mtdagger.cli import main
from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir, writer_lock_holder
from lerobot_mtdagger.datasets.migrations import FLAT_OPTION_PATHS
from lerobot_mtdagger.envs import SuiteConfig
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.option_groups import DAggerConfig
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.parent import PARENT_PID_ENV, follow_parent
from tests.helpers import TOY_COMPARE, child_pids, is_running

TINY = TOY_COMPARE
FIGURES = [
    "success_vs_demos.png",
    "success_vs_frames.png",
    "demos_to_reach.png",
    "time_to_reach.png",
    "metrics_vs_success.png",
    "hardest_tasks.png",
    "kalman_ablation.png",
    "headroom.png",
]


@pytest.fixture(scope="module")
def compared(tmp_path_factory):
    folder = tmp_path_factory.mktemp("compare") / "cmp"
    args = ["compare", "--methods=[bc,uniform,need,need_raw,gain]", "--seeds=[0,1]", f"--output_dir={folder}"]
    assert main([*args, "--jobs=2", *TINY]) == 0
    return folder, args


def test_the_table_holds_every_method_seed_and_round_and_bc_at_every_budget(compared):
    folder, _ = compared
    rows = json.loads((folder / "results.json").read_text())
    dagger = {(r["method"], r["seed"], r["round"]) for r in rows if r["method"] != "bc"}
    assert dagger == {
        (m, s, k) for m in ("uniform", "need", "need_raw", "gain") for s in (0, 1) for k in (0, 1, 2)
    }
    bc = {(r["seed"], r["demos_per_task_mean"]) for r in rows if r["method"] == "bc"}
    assert bc == {(s, d) for s in (0, 1) for d in (1.0, 3.0, 5.0)}  # DAgger's demos after each round
    need = [r for r in rows if r["method"] == "need" and r["seed"] == 0]
    assert [r["demos_per_task_mean"] for r in need] == [1.0, 3.0, 5.0]
    frames = [r["expert_frames_per_task_mean"] for r in need]
    assert frames == sorted(frames) and frames[0] > 0
    assert need[0]["kalman_p"] is not None and len(need[0]["eval_success"]) == 3
    with (folder / "results.csv").open() as handle:
        assert len(list(csv.DictReader(handle))) == len(rows)


def test_a_second_compare_skips_finished_runs(compared, monkeypatch):
    """No run process starts at all (resuming a finished run would leave every file as it was)."""
    folder, args = compared
    started, popen = [], subprocess.Popen

    def spy(command, *rest, **options):
        started.append(command)
        return popen(command, *rest, **options)

    monkeypatch.setattr(subprocess, "Popen", spy)
    before = {p.name: p.stat().st_mtime_ns for p in (folder / "runs").glob("*/policies/round-*")}
    assert main([*args, "--jobs=1", *TINY]) == 0
    after = {p.name: p.stat().st_mtime_ns for p in (folder / "runs").glob("*/policies/round-*")}
    assert before == after and started == []


def _compare_in_its_first_run(folder: Path, seeds: str) -> tuple[subprocess.Popen, list[str], list[int]]:
    """Starts ``compare`` (need, 1 500 steps per phase) in a process and returns once its first run has
    committed round 0, with 3 phases to go: (compare, its arguments, the run processes it started)."""
    longer = [
        *(o for o in TINY if not o.startswith("--training.steps_per_round")),
        "--training.steps_per_round=1500",
    ]
    args = ["compare", "--methods=[need]", f"--seeds={seeds}", f"--output_dir={folder}", "--jobs=1", *longer]
    cli = str(Path(sys.executable).parent / "lerobot-mtdagger")
    process = subprocess.Popen(
        [cli, *args],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        # A shell's background job ignores SIGINT, and so would compare: let it hear Ctrl-C.
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    round_zero = folder / "runs" / "need-seed0" / "rounds" / "round-000"
    deadline = time.time() + 120
    while not round_zero.exists() and process.poll() is None and time.time() < deadline:
        time.sleep(0.05)
    assert process.poll() is None, "compare ended before its first run had committed round 0"
    runs = child_pids(process.pid)
    assert runs, "compare should have started its first run"
    return process, args, runs


@pytest.mark.slow  # runs of subprocesses, about 45 s
def test_a_killed_compare_leaves_no_run_writing_on_and_the_next_compare_finishes_it(tmp_path):
    """kill -9 of compare: its run (and the run's env workers) end within seconds; compare resumes it."""
    folder = tmp_path / "cmp"
    process, args, runs = _compare_in_its_first_run(folder, "[0]")
    workers = [worker for run in runs for worker in child_pids(run)]
    os.kill(process.pid, signal.SIGKILL)
    process.wait()
    for pids, seconds, what in ((runs, 3, "the run"), (workers, 20, "the run's env workers")):
        deadline = time.time() + seconds
        while any(is_running(pid) for pid in pids) and time.time() < deadline:
            time.sleep(0.1)
        assert not any(is_running(pid) for pid in pids), f"{what} outlived the compare that started it"
    assert not is_finished(folder / "runs" / "need-seed0", 2)
    assert main(args) == 0
    assert is_finished(folder / "runs" / "need-seed0", 2)
    assert "has ended; ending this run" in (folder / "runs" / "need-seed0.log").read_text()


@pytest.mark.slow  # a compare in a subprocess, about 25 s
def test_ctrl_c_on_compare_ends_its_run_and_starts_no_other(tmp_path):
    folder = tmp_path / "cmp"
    process, _, runs = _compare_in_its_first_run(folder, "[0,1]")
    os.kill(process.pid, signal.SIGINT)  # to compare alone, not to its process group
    process.wait(timeout=20)
    assert not any(is_running(pid) for pid in runs), "the running run was not ended"
    assert not (folder / "runs" / "need-seed1").exists(), "a queued run started after the interrupt"


@pytest.mark.slow  # two runs in subprocesses, about 35 s
def test_one_failed_run_stops_none_of_the_runs_queued_after_it(tmp_path, capsys):
    folder = tmp_path / "cmp"
    blocked = folder / "runs" / "bc-1demos-seed0"
    blocked.mkdir(parents=True)
    (blocked / "notes.txt").write_text("not an experiment")  # run refuses a non-empty folder
    args = ["compare", "--methods=[bc,need]", "--seeds=[0]", "--bc_budgets=[1]", f"--output_dir={folder}"]
    assert main([*args, "--jobs=1", *TINY]) == 2
    error = capsys.readouterr().err
    assert "1 of 2 runs failed; the others finished" in error and "bc-1demos-seed0.log" in error
    assert is_finished(folder / "runs" / "need-seed0", 2)
    assert (blocked / "notes.txt").read_text() == "not an experiment"


def test_a_run_another_process_is_writing_is_skipped_named_and_left_alone(tmp_path, monkeypatch):
    """No run process starts for it, its lock and files stay, and the error says nothing failed."""
    folder = tmp_path / "runs" / "need-seed0"
    started = []
    monkeypatch.setattr(subprocess, "Popen", lambda *args, **options: started.append(args))
    pool = RunPool(tmp_path / "runs", parallel=1, threads=1, workers=None)
    assert writer_lock_holder(folder) is None and not folder.exists(), "probing creates nothing"
    with ExperimentDir(folder).writer_lock():
        assert writer_lock_holder(folder) == str(os.getpid())
        with pytest.raises(UserError) as error:
            pool.run_all([Job("need-seed0", (), 2)])
        assert writer_lock_holder(folder) == str(os.getpid()), "the probe leaves the writer its lock"
    assert started == []
    assert str(error.value) == (
        f"1 of 1 runs are being written by another process (another compare on this folder?) and were "
        f"skipped; nothing failed: need-seed0 (pid {os.getpid()}). Run the same compare again once that "
        "process has ended, to tabulate every run."
    )
    assert writer_lock_holder(folder) is None


@pytest.mark.slow  # two compares of two runs each, about 60 s
def test_two_compares_on_one_folder_share_its_runs_and_a_third_tabulates_them(tmp_path, capsys):
    folder = tmp_path / "cmp"
    first, args, _ = _compare_in_its_first_run(folder, "[0,1]")
    assert main(args) == 2, "the second compare skips the run the first is writing"
    assert "runs are being written by another process" in capsys.readouterr().err
    assert is_finished(folder / "runs" / "need-seed1", 2), "the second compare ran the other run"
    assert first.wait(timeout=300) in (0, 2)
    assert main(args) == 0
    rows = list(csv.DictReader((folder / "results.csv").open()))
    assert {(row["seed"], row["round"]) for row in rows} == {(s, r) for s in "01" for r in "012"}
    for run in ("need-seed0", "need-seed1"):
        assert "being written by another run" not in (folder / "runs" / f"{run}.log").read_text()


def test_a_run_started_by_hand_follows_no_parent(monkeypatch):
    monkeypatch.delenv(PARENT_PID_ENV, raising=False)
    assert follow_parent() is None


def test_report_writes_every_figure_and_the_paired_differences(compared, capsys):
    folder, _ = compared
    assert main(["report", f"--compare_dir={folder}"]) == 0
    report = folder / "report"
    for name in FIGURES:
        assert (report / name).stat().st_size > 10_000, name
    summary = (report / "report.md").read_text()
    for name in FIGURES:
        assert f"]({name})" in summary
    assert "| need | uniform | 3.0 |" in summary and "| gain | bc | 5.0 |" in summary
    assert "mean over 2 seeds, 95% t interval; 2 eval episodes per task" in summary
    assert "## Expert data needed to reach a level" in summary and "## What the runs cost" in summary
    assert "| need | 2 |" in summary and "| bc | 6 |" in summary  # 2 seeds; BC: 3 budgets x 2 seeds
    assert "## The hardest tasks against the others" in summary and "## Stability" in summary
    assert "| need | need_raw | 3.0 |" in summary  # the Kalman filter's own effect, paired
    assert "| need | uniform | 5.0 | " in summary.split("## The hardest tasks")[1]
    printed = capsys.readouterr().out
    assert "bc (1 demos/task)" in printed  # the table keeps BC budgets apart
    assert "Interim" not in summary  # every run finished
    # The headroom of BC's curves (and round 0), in the summary, its file and on the console.
    assert "## Headroom: the best split of the same demos against an even split" in summary
    headroom = json.loads((report / "headroom.json").read_text())
    assert [b["demos_per_task"] for b in headroom["budgets"]] == [1, 3, 5] and headroom["seeds"] == [0, 1]
    assert all(b["gain"] >= 0 and "held_out_gain" in b for b in headroom["budgets"])
    assert "| demos per task | even split | best split | gain |" in printed


def test_report_on_a_study_in_progress_reports_what_is_committed_and_lists_the_rest(
    compared, tmp_path, capsys
):
    folder, _ = compared
    study = tmp_path / "cmp"
    shutil.copytree(folder, study, ignore=shutil.ignore_patterns("report"))
    runs = study / "runs"
    for k in (1, 2):  # need, seed 1: cut off after its first phase
        shutil.rmtree(runs / "need-seed1" / "policies" / f"round-00{k}")
        shutil.rmtree(runs / "need-seed1" / "rounds" / f"round-00{k}")
    for sub in ("policies", "rounds"):  # gain, seed 1: just started (its config, no round yet)
        shutil.rmtree(runs / "gain-seed1" / sub)
        (runs / "gain-seed1" / sub).mkdir()
    shutil.rmtree(runs / "bc-5demos-seed1")  # planned in compare.json, not started

    assert main(["report", f"--compare_dir={study}"]) == 0

    rows = json.loads((study / "report" / "results.json").read_text())
    assert [r["round"] for r in rows if (r["method"], r["seed"]) == ("need", 1)] == [0]
    assert not [r for r in rows if (r["method"], r["seed"]) == ("gain", 1)]
    bc = {r["demos_per_task_mean"] for r in rows if (r["method"], r["seed"]) == ("bc", 1)}
    assert bc == {1.0, 3.0}
    summary = (study / "report" / "report.md").read_text()
    assert "**Interim report: 3 run(s) unfinished**" in summary
    assert "- need-seed1: phases 0-0 of 0-2" in summary
    assert "- gain-seed1: no phase yet of 0-2" in summary
    assert "- bc-5demos-seed1: not started" in summary
    table = capsys.readouterr().out
    assert re.search(r"\| need \| 0 \| 1\.0 \| [0-9.]+ \| [0-9.]+ \| 2 \|", table)  # both seeds
    assert re.search(r"\| need \| 2 \| 5\.0 \| [0-9.]+ \| n/a \| 1 \|", table)  # seed 0 alone


def _saved_table(report: Path, folder: Path) -> Path:
    """A copy of a report's saved table alone (no run folder beside it)."""
    folder.mkdir()
    for name in ("results.json", "results_meta.json"):
        shutil.copy(report / name, folder / name)
    return folder


def test_report_redrawn_from_the_saved_table_alone_equals_the_report_of_the_runs(compared, tmp_path, capsys):
    folder, _ = compared
    assert main(["report", f"--compare_dir={folder}", f"--output_dir={tmp_path / 'of-runs'}"]) == 0
    table_of_runs = capsys.readouterr().out.split("figures and summary")[0]
    saved = _saved_table(tmp_path / "of-runs", tmp_path / "saved")
    rows_before = (saved / "results.json").read_bytes()

    assert main(["report", f"--results=[{saved / 'results.json'}]"]) == 0

    assert capsys.readouterr().out.split("figures and summary")[0] == table_of_runs
    assert (saved / "report.md").read_text() == (tmp_path / "of-runs" / "report.md").read_text()
    for name in FIGURES:
        assert (saved / name).stat().st_size > 10_000, name
    assert (saved / "results.json").read_bytes() == rows_before  # the input is never rewritten
    meta = json.loads((folder / "results_meta.json").read_text())  # compare's own table has it too
    assert meta["task_names"] == ["toy-left", "toy-right", "toy-up-windy"] and meta["unfinished"] == []
    assert sorted(meta["configs"]) == ["bc", "gain", "need", "need_raw", "uniform"]
    assert meta["configs"]["need"]["rollout.eval_episodes"] == 2 and "seed" not in meta["configs"]["need"]


def test_a_table_written_before_the_unseen_columns_joins_a_new_one(compared, tmp_path):
    """Saved seeds of a study outlive the toolkit's new columns: ``report --results`` still joins them."""
    folder, _ = compared
    assert main(["report", f"--compare_dir={folder}", f"--output_dir={tmp_path / 'report'}"]) == 0
    new_columns = ("eval_progress_mean", "unseen_success_mean", "unseen_success", "unseen_progress_mean")
    tables = {}
    for seed in (0, 1):
        table = _saved_table(tmp_path / "report", tmp_path / f"seed{seed}")
        rows = [row for row in json.loads((table / "results.json").read_text()) if row["seed"] == seed]
        assert rows and all(column in row for row in rows for column in new_columns)
        if seed == 0:  # as written before the columns existed
            rows = [{k: v for k, v in row.items() if k not in (*new_columns, "unseen_tasks")} for row in rows]
        (table / "results.json").write_text(json.dumps(rows))
        tables[seed] = table / "results.json"
    joined = tmp_path / "joined"
    assert main(["report", f"--results=[{tables[0]},{tables[1]}]", f"--output_dir={joined}"]) == 0
    report = (joined / "report.md").read_text()
    assert "## In-domain and unseen tasks" not in report  # the toy suite has no unseen tasks
    assert "| need |" in report


def test_a_redrawn_interim_report_still_lists_the_unfinished_runs(compared, tmp_path):
    folder, _ = compared
    study = tmp_path / "cmp"
    shutil.copytree(folder, study, ignore=shutil.ignore_patterns("report"))
    shutil.rmtree(study / "runs" / "bc-5demos-seed1")
    assert main(["report", f"--compare_dir={study}"]) == 0
    saved = _saved_table(study / "report", tmp_path / "saved")

    assert main(["report", f"--results=[{saved}]", "--levels=[0.5]"]) == 0

    summary = (saved / "report.md").read_text()
    assert (
        "**Interim report: 1 run(s) unfinished**" in summary and "- bc-5demos-seed1: not started" in summary
    )
    assert "| need | uniform | 50% |" in summary and "| need | uniform | 60% |" not in summary


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        (lambda saved: (saved / "results_meta.json").unlink(), "results_meta.json does not exist"),
        (lambda saved: (saved / "results.json").write_text("[1, 2"), "results.json is not JSON"),
        (lambda saved: (saved / "results.json").write_text("[]"), "holds no results rows"),
        (
            lambda saved: (saved / "results.json").write_text('[{"method": "bc"}]'),
            r"rows lack the column\(s\) \[.*'demos_per_task_mean'",
        ),
        (
            lambda saved: (saved / "results_meta.json").write_text('{"task_names": ["a"]}'),
            r"must name the \[3\] task\(s\)",
        ),
    ],
)
def test_report_refuses_a_damaged_saved_table_and_names_the_file(compared, tmp_path, capsys, damage, message):
    folder, _ = compared
    saved = _saved_table(folder, tmp_path / "saved")
    damage(saved)
    assert main(["report", f"--results=[{saved}]"]) == 2
    assert re.search(message, capsys.readouterr().err)
    assert not (saved / "report.md").exists()


def test_report_results_goes_alone(compared, tmp_path, capsys):
    folder, _ = compared
    assert main(["report", f"--results=[{folder}]", f"--compare_dir={folder}"]) == 2
    assert "give it alone" in capsys.readouterr().err
    assert main(["report", f"--results=[{tmp_path / 'nowhere'}]"]) == 2
    assert "nowhere does not exist: pass the results.json" in capsys.readouterr().err
    assert main(["report", f"--results=[{folder},{folder}]"]) == 2
    assert "give --output_dir for the joined report" in capsys.readouterr().err


def _save_records(runs: Path, dest: Path) -> Path:
    """The runs' records as a study saves them before its ``outputs/`` is lost (``records --action=save``)."""
    save_runs(runs, dest)
    return dest


def _rows_without_paths(report: Path) -> list[dict]:
    """A saved table's rows less what names the folder they were read from."""
    rows = json.loads((report / "results.json").read_text())
    dropped = ("experiment", "expert_frames_per_task")
    return [{k: v for k, v in row.items() if k not in dropped} for row in rows]


def test_runs_saved_as_records_report_as_their_folders_do(compared, tmp_path, capsys):
    """``outputs/`` lost, the JSON records that ``records --action=save`` kept give the same table."""
    folder, _ = compared
    assert main(["report", f"--compare_dir={folder}", f"--output_dir={tmp_path / 'of-runs'}"]) == 0
    table_of_runs = capsys.readouterr().out.split("figures and summary")[0]
    records = _save_records(folder / "runs", tmp_path / "records")
    assert not list(records.rglob("*.parquet")) and not list(records.rglob("*.safetensors"))

    assert main(["report", f"--records=[{records}]", f"--output_dir={tmp_path / 'of-records'}"]) == 0

    assert capsys.readouterr().out.split("figures and summary")[0] == table_of_runs
    assert _rows_without_paths(tmp_path / "of-records") == _rows_without_paths(tmp_path / "of-runs")
    rows = json.loads((tmp_path / "of-records" / "results.json").read_text())
    assert all(row["expert_frames_per_task"] is None for row in rows)  # saved in total, not per task
    summary = (tmp_path / "of-records" / "report.md").read_text()
    assert summary == (tmp_path / "of-runs" / "report.md").read_text()


def _compact(records: Path) -> Path:
    """``records --action=compact`` on a records folder; its archive."""
    (archive,) = compact(records)
    return archive


def test_records_compacted_into_an_archive_report_as_their_folders_do(compared, tmp_path, capsys):
    """A study keeps its runs' records as one archive; report reads it and names the runs as before."""
    folder, _ = compared
    records = _save_records(folder / "runs", tmp_path / "records")
    assert main(["report", f"--records=[{records}]", f"--output_dir={tmp_path / 'of-folders'}"]) == 0
    table_of_folders = capsys.readouterr().out.split("figures and summary")[0]
    files = sorted(p.relative_to(records) for p in records.rglob("*") if p.is_file())

    archive = _compact(records)

    assert [p.name for p in records.iterdir()] == ["runs-records.tar.gz"]
    with tarfile.open(archive) as tar:
        assert sorted(Path(m.name) for m in tar.getmembers() if m.isfile()) == files
    for given in (records, archive):  # the records folder, or the archive itself
        out = tmp_path / f"of-{given.name}"
        assert main(["report", f"--records=[{given}]", f"--output_dir={out}"]) == 0
        assert capsys.readouterr().out.split("figures and summary")[0] == table_of_folders
        for name in ("results.json", "results.csv", "report.md"):
            assert (out / name).read_text() == (tmp_path / "of-folders" / name).read_text()


def test_compacting_is_byte_stable_and_never_overwrites(compared, tmp_path):
    folder, _ = compared
    first = _compact(_save_records(folder / "runs", tmp_path / "one"))
    second = _compact(_save_records(folder / "runs", tmp_path / "two"))
    assert first.read_bytes() == second.read_bytes()
    (tmp_path / "one" / "late-run").mkdir()
    script = Path(__file__).resolve().parents[1] / "scripts" / "compact_records.sh"
    result = subprocess.run(["bash", str(script), str(tmp_path / "one")], capture_output=True, text=True)
    assert "nothing to compact" in result.stdout  # its subfolder holds no run: left as it is
    assert (tmp_path / "one" / "late-run").is_dir() and first.read_bytes() == second.read_bytes()


def test_a_records_archive_that_is_not_one_is_named(tmp_path, capsys):
    bad = tmp_path / "runs-records.tar.gz"
    bad.write_bytes(b"not a tar archive")
    assert main(["report", f"--records=[{bad}]"]) == 2
    assert f"--records: cannot read {bad} as a tar archive" in capsys.readouterr().err


def test_saved_records_of_some_runs_join_the_folders_of_the_others(compared, tmp_path, capsys):
    folder, _ = compared
    assert main(["report", f"--compare_dir={folder}"]) == 0
    table_of_runs = capsys.readouterr().out
    records = _save_records(folder / "runs", tmp_path / "records")
    study = tmp_path / "cmp"
    shutil.copytree(folder, study, ignore=shutil.ignore_patterns("report"))
    lost = sorted(run.name for run in (study / "runs").glob("bc-*-seed0") if run.is_dir())
    for name in lost:  # BC seed 0 finished, then outputs/ was lost; the study goes on without them
        shutil.rmtree(study / "runs" / name)
        (study / "runs" / f"{name}.log").unlink()
    kept = ",".join(str(records / name) for name in lost)

    assert main(["report", f"--compare_dir={study}", f"--records=[{kept}]"]) == 0

    out = capsys.readouterr().out
    assert out.split("figures and summary")[0] == table_of_runs.split("figures and summary")[0]


def test_a_run_in_its_folder_and_in_saved_records_is_refused(compared, tmp_path, capsys):
    folder, _ = compared
    records = _save_records(folder / "runs", tmp_path / "records")
    assert main(["report", f"--compare_dir={folder}", f"--records=[{records / 'need-seed0'}]"]) == 2
    assert "Two need experiments with seed 0" in capsys.readouterr().err


def test_report_records_names_the_script_that_saves_them(compared, tmp_path, capsys):
    folder, _ = compared
    (tmp_path / "empty").mkdir()
    for where in (tmp_path / "empty", tmp_path / "nowhere"):
        assert main(["report", f"--records=[{where}]"]) == 2
        assert f"--records: {where} holds no run's records" in capsys.readouterr().err
    assert main(["report", f"--records=[{folder / 'runs'}]", f"--results=[{folder}]"]) == 2
    assert "without --experiments, --compare_dir, --variants or --records" in capsys.readouterr().err


def test_saved_records_of_a_restarted_run_are_replaced_whole(compared, tmp_path):
    """A run restarted from nothing (its folder lost) must not mix with its earlier records."""
    folder, _ = compared
    runs = tmp_path / "runs"
    shutil.copytree(folder / "runs" / "need-seed0", runs / "need-seed0")
    records = _save_records(folder / "runs", tmp_path / "records")
    for late in ("rounds/round-002", "rounds/round-001", "policies/round-002", "policies/round-001"):
        shutil.rmtree(runs / "need-seed0" / late)  # the restarted run has reached phase 0 so far

    _save_records(runs, records)

    assert sorted(p.name for p in (records / "need-seed0" / "policies").iterdir()) == ["round-000"]
    assert sorted(p.name for p in (records / "need-seed0" / "rounds").iterdir()) == ["round-000"]
    assert (records / "gain-seed0" / "policies" / "round-002" / "training.json").is_file()  # untouched


@pytest.fixture(scope="module")
def seed_tables(compared, tmp_path_factory):
    """The comparison saved as two tables, one per seed, as if each seed ran on its own machine."""
    folder, _ = compared
    tables = tmp_path_factory.mktemp("seed-tables")
    for seed in (0, 1):
        runs = ",".join(str(run) for run in sorted((folder / "runs").glob(f"*-seed{seed}")) if run.is_dir())
        assert main(["report", f"--experiments=[{runs}]", f"--output_dir={tables / f'seed{seed}'}"]) == 0
        for name in ("report.md", "headroom.json", *FIGURES):  # keep the saved table alone
            (tables / f"seed{seed}" / name).unlink()
    return tables


def test_tables_of_seeds_run_apart_join_into_the_report_of_all_runs(compared, seed_tables, tmp_path, capsys):
    folder, _ = compared
    assert main(["report", f"--compare_dir={folder}", f"--output_dir={tmp_path / 'of-runs'}"]) == 0
    table_of_runs = capsys.readouterr().out.split("figures and summary")[0]
    joined = tmp_path / "joined"

    assert (
        main(
            [
                "report",
                f"--results=[{seed_tables / 'seed0'},{seed_tables / 'seed1'}]",
                f"--output_dir={joined}",
            ]
        )
        == 0
    )

    table = capsys.readouterr().out.split("figures and summary")[0]
    assert (joined / "report.md").read_text() == (tmp_path / "of-runs" / "report.md").read_text()
    with (joined / "results.csv").open() as handle:  # the joined table, saved beside its figures
        rows = list(csv.DictReader(handle))
    assert {(row["method"], row["seed"], row["round"]) for row in rows} == {
        (row["method"], row["seed"], row["round"]) for row in csv.DictReader((folder / "results.csv").open())
    }
    assert main(["report", f"--results=[{joined}]", f"--output_dir={tmp_path / 'again'}"]) == 0
    assert (tmp_path / "again" / "report.md").read_text() == (joined / "report.md").read_text()
    assert table == table_of_runs
    assert re.search(r"\| need \| 2 \| 5\.0 \| [0-9.]+ \| [0-9.]+ \| 2 \|", table)  # both seeds in each point
    assert sorted(p.name for p in seed_tables.glob("seed0/*")) == [
        "results.csv",
        "results.json",
        "results_meta.json",
    ]


def _as_flat_config(shared: dict) -> dict:
    """A method's shared options as a table written before the options were grouped stored them."""
    old_names = {new: old for old, new in FLAT_OPTION_PATHS.items()}
    flat: dict = {}
    for path, value in shared.items():
        if path in old_names:
            flat[old_names[path]] = value
        elif "." in path:
            group, name = path.split(".", 1)
            if group in ("policy", "scheduler"):  # nested then too; other new options did not exist
                flat.setdefault(group, {})[name] = value
        else:
            flat[path] = value
    return flat


def test_a_table_saved_before_the_options_were_grouped_joins_a_new_one(seed_tables, tmp_path):
    def to_old_layout(meta):
        meta["configs"] = {method: _as_flat_config(shared) for method, shared in meta["configs"].items()}

    old = _with_meta(seed_tables / "seed1", tmp_path / "old", to_old_layout)
    assert "eval_episodes" in json.loads((old / "results_meta.json").read_text())["configs"]["need"]
    out = tmp_path / "joined"
    assert main(["report", f"--results=[{seed_tables / 'seed0'},{old}]", f"--output_dir={out}"]) == 0
    changed = _with_meta(
        old, tmp_path / "changed", lambda meta: meta["configs"]["need"].update(eval_episodes=20)
    )
    assert main(["report", f"--results=[{seed_tables / 'seed0'},{changed}]", f"--output_dir={out}-2"]) == 2


def _with_meta(table: Path, folder: Path, change) -> Path:
    """A copy of a saved table whose results_meta.json is changed by ``change(meta)``."""
    shutil.copytree(table, folder)
    meta = json.loads((folder / "results_meta.json").read_text())
    change(meta)
    (folder / "results_meta.json").write_text(json.dumps(meta))
    return folder


@pytest.mark.parametrize(
    ("other_table", "message"),
    [
        (
            lambda tables, copy: tables / "seed0",
            r"seed0/results.json both hold bc seed 0 at 1 demos per task",
        ),
        (
            lambda tables, copy: _with_meta(
                tables / "seed1",
                copy,
                lambda meta: meta["configs"]["need"].update({"rollout.eval_episodes": 20}),
            ),
            r"Refusing to join need runs with different configs \(rollout.eval_episodes: 2 vs 20\)",
        ),
        (
            lambda tables, copy: _with_meta(tables / "seed1", copy, lambda meta: meta.pop("configs")),
            "was written without the methods' configs",
        ),
        (
            lambda tables, copy: _with_meta(
                tables / "seed1", copy, lambda meta: meta.update(task_names=["a", "b", "c"])
            ),
            "name different tasks",
        ),
    ],
)
def test_tables_that_would_mislead_are_not_joined(seed_tables, tmp_path, capsys, other_table, message):
    other = other_table(seed_tables, tmp_path / "other")
    out = tmp_path / "joined"
    assert main(["report", f"--results=[{seed_tables / 'seed0'},{other}]", f"--output_dir={out}"]) == 2
    assert re.search(message, capsys.readouterr().err)
    assert not out.exists()


def test_bc_budgets_map_to_rounds_and_bad_ones_are_refused():
    config = RunConfig(
        suite=SuiteConfig(name="toy"), dagger=DAggerConfig(rounds=2, initial_demos=1, budget_per_task=2)
    )
    assert bc_rounds_for(config, [], 3) == {1: 0, 3: 1, 5: 2}
    assert bc_rounds_for(config, [7], 3) == {7: 3}
    with pytest.raises(ValueError, match="not initial_demos \\+ k"):
        bc_rounds_for(config, [4], 3)


def test_every_method_gets_the_same_seeds_and_run_options():
    own, passed = split_arguments(["--methods=[need,bc]", "--seeds=[3]", *TINY])
    assert own == ["--methods=[need,bc]", "--seeds=[3]"] and passed == TINY
    jobs = jobs_for(CompareConfig(methods=["need", "bc"], seeds=[3], bc_budgets=[3]), passed, 3)
    assert [job.name for job in jobs] == ["need-seed3", "bc-3demos-seed3"]
    assert all("--seed=3" in job.args and set(TINY) <= set(job.args) for job in jobs)
    with pytest.raises(ValueError, match="set per run by compare"):
        jobs_for(CompareConfig(), [*TINY, "--seed=1"], 3)


@pytest.mark.slow
def test_compare_with_more_rounds_extends_dagger_runs_and_adds_bc_budgets(tmp_path):
    folder = tmp_path / "cmp"
    args = ["compare", "--methods=[bc,uniform]", "--seeds=[0]", f"--output_dir={folder}", "--jobs=1"]
    short = [arg for arg in TINY if not arg.startswith("--dagger.rounds")]
    assert main([*args, *short, "--dagger.rounds=1"]) == 0
    policies = folder / "runs" / "uniform-seed0" / "policies"

    def weights_written() -> dict[str, int]:
        return {p.parent.name: p.stat().st_mtime_ns for p in policies.glob("round-*/model.safetensors")}

    before = weights_written()
    assert sorted(before) == ["round-000", "round-001"]
    assert main([*args, *short, "--dagger.rounds=2"]) == 0
    after = weights_written()
    assert sorted(after) == ["round-000", "round-001", "round-002"]
    assert {name: after[name] for name in before} == before  # the rounds made are kept as they were
    rows = json.loads((folder / "results.json").read_text())
    assert sorted(r["round"] for r in rows if r["method"] == "uniform") == [0, 1, 2]
    assert sorted(r["demos_per_task_mean"] for r in rows if r["method"] == "bc") == [1.0, 3.0, 5.0]


def test_reach_interpolates_along_dagger_and_takes_the_cheapest_bc_run():
    curve = [{"eval_success_mean": s, "x": x} for x, s in [(1, 0.2), (3, 0.6), (5, 0.9)]]
    assert seed_reach(curve, 0.5, lambda c: [r["x"] for r in c]) == pytest.approx(2.5)
    times = [10.0, 8.0, 12.0]  # BC runs at growing budgets need not take growing times
    assert seed_reach(curve, 0.5, lambda c: times) == 8.0
    assert seed_reach(curve, 0.95, lambda c: times) is None


def test_hardest_tasks_are_those_bc_fails_most_at_its_largest_budget():
    rows = [
        {"method": "bc", "demos_per_task_mean": 1.0, "round": 0, "eval_success": [0.0, 0.0, 0.0]},
        {"method": "bc", "demos_per_task_mean": 5.0, "round": 0, "eval_success": [0.9, 0.2, 0.5]},
        {"method": "need", "demos_per_task_mean": 5.0, "round": 2, "eval_success": [0.0, 1.0, 1.0]},
    ]
    assert hardest_tasks(rows) == [1, 2]


def test_report_shows_a_labelled_bc_variant_as_a_second_baseline(compared, tmp_path, capsys):
    """BC trained differently (balanced sampling) is reported beside ``bc`` under its own name."""
    folder, _ = compared
    balanced = tmp_path / "bc-balanced"
    args = ["compare", "--methods=[bc]", "--seeds=[0,1]", "--bc_budgets=[1,3]", f"--output_dir={balanced}"]
    assert main([*args, "--jobs=2", *TINY, "--training.sampling=balanced"]) == 0
    capsys.readouterr()
    runs = sorted((balanced / "runs").glob("bc-*"))
    runs = [run for run in runs if run.is_dir()]
    # Grouped with the other BC runs without a label, they are refused (their configs differ).
    experiments = ",".join(str(p) for p in [*runs, *(folder / "runs").glob("bc-1demos-seed*")] if p.is_dir())
    assert main(["report", f"--experiments=[{experiments}]"]) == 2
    assert "--variants" in capsys.readouterr().err
    out = tmp_path / "report"
    command = ["report", f"--compare_dir={folder}", f"--variants={{bc-balanced: {balanced}}}"]
    assert main([*command, f"--output_dir={out}"]) == 0
    assert "bc-balanced (3 demos/task)" in capsys.readouterr().out
    summary = (out / "report.md").read_text()
    for pair in (
        "| need | bc-balanced | 3.0 |",
        "| uniform | bc-balanced | 1.0 |",
        "| bc-balanced | bc | 3.0 |",
    ):
        assert pair in summary, pair
    assert "| need | bc | 3.0 |" in summary  # the plain BC stays a baseline
    rows = json.loads((out / "results.json").read_text())
    assert {(r["method"], r["bc"]) for r in rows if r["bc"]} == {("bc", True), ("bc-balanced", True)}


def test_report_refuses_a_variant_folder_that_holds_no_runs(compared, tmp_path, capsys):
    folder, _ = compared
    (tmp_path / "empty").mkdir()
    assert main(["report", f"--compare_dir={folder}", f"--variants={{x: {tmp_path / 'empty'}}}"]) == 2
    assert "neither a compare folder" in capsys.readouterr().err


def test_reach_table_gives_demos_and_frames_at_the_first_crossing():
    from lerobot_mtdagger.analysis.summary import reach_lines

    def curve(seed, successes):
        return [
            {
                "method": "need",
                "seed": seed,
                "round": k,
                "demos_per_task_mean": demos,
                "expert_frames_per_task_mean": 100.0 * demos,
                "eval_success_mean": success,
            }
            for k, (demos, success) in enumerate(zip((1.0, 3.0, 5.0), successes, strict=True))
        ]

    rows = curve(0, (0.2, 0.6, 0.9)) + curve(1, (0.2, 0.4, 0.6))
    table = "\n".join(reach_lines(rows, [0.5, 0.95]))
    # seed 0 crosses 0.5 at 2.5 demos (250 frames), seed 1 at 4.0 (400): mean 3.25 and 325.
    assert "| need | 50% | 3.2" in table and "| 325 [" in table and "| 2/2 |" in table
    assert "| need | 95% | never | never | 0/2 |" in table


def hand_built_table(folder: Path, need: dict, bc: dict, tasks: int = 2) -> Path:
    """A saved results table of known per-seed success (every task alike): ``need`` gives per seed the
    success after rounds 0, 1, ... (1, 2, ... demos per task), ``bc`` per seed its success at 1, 2, ..."""
    rows = []

    def row(method: str, seed: int, round_index: int, demos: int, success: float) -> dict:
        return {
            "experiment": f"runs/{method}-seed{seed}", "method": method, "bc": method == "bc", "seed": seed,
            "round": round_index, "preset": "small", "demos_per_task_mean": float(demos),
            "demos_per_task": [demos] * tasks, "expert_frames_per_task_mean": 100.0 * demos,
            "expert_frames_per_task": [100 * demos] * tasks, "eval_success_mean": success,
            "eval_success": [success] * tasks, "eval_episodes_per_task": 20, "metric": None, "kalman_p": None,
            "raw_success": None, "gain": None, "collect_s": 1.0, "write_s": 0.1, "load_s": 0.1,
            "train_s": 2.0, "eval_s": 1.0,
        }  # fmt: skip

    for seed, values in need.items():
        rows += [row("need", seed, index, index + 1, value) for index, value in enumerate(values)]
    for seed, values in bc.items():
        rows += [row("bc", seed, 0, index + 1, value) for index, value in enumerate(values)]
    folder.mkdir(parents=True)
    (folder / "results.json").write_text(json.dumps(rows))
    names = [f"task-{i}" for i in range(tasks)]
    (folder / "results_meta.json").write_text(json.dumps({"task_names": names, "unfinished": []}))
    return folder


def test_the_report_s_paired_differences_and_reach_ratios_are_the_hand_computed_ones(tmp_path, capsys):
    """Differences are method - baseline per seed, then a 95% t interval (t = 4.303 for 3 seeds)."""
    table = hand_built_table(
        tmp_path / "table",
        need={0: [0.5, 0.9], 1: [0.4, 0.8], 2: [0.3, 0.7]},
        bc={0: [0.5, 0.6], 1: [0.4, 0.6], 2: [0.3, 0.6]},
    )
    assert main(["report", f"--results=[{table}]", f"--output_dir={tmp_path / 'report'}"]) == 0
    summary = (tmp_path / "report" / "report.md").read_text()
    # At 2 demos: need - bc = 0.3, 0.2, 0.1 -> mean 0.2, sd 0.1, half-width 4.303 * 0.1 / sqrt(3) = 0.248.
    assert "| need | bc | 2.0 | +0.200 [-0.048, +0.448] |" in summary
    assert "| need | bc | 1.0 | +0.000 [+0.000, +0.000] |" in summary
    # 60%: need crosses it at 1.25, 1.5, 1.75 demos, BC at 2, 2, 2 -> ratios 0.625, 0.75, 0.875.
    assert "| need | bc | 60% | 0.75 | 3/3 |" in summary
    assert "Not shown: with 2 task(s), no task is left besides the hardest." in summary


def test_a_saved_table_without_phase_timings_is_refused_naming_the_column(tmp_path, capsys):
    table = hand_built_table(tmp_path / "table", need={0: [0.5, 0.9]}, bc={0: [0.5, 0.6]})
    rows = json.loads((table / "results.json").read_text())
    (table / "results.json").write_text(
        json.dumps([{k: v for k, v in r.items() if k != "train_s"} for r in rows])
    )
    assert main(["report", f"--results=[{table}]", f"--output_dir={tmp_path / 'report'}"]) == 2
    assert "lack the column(s) ['train_s']" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("cores", "jobs", "environ", "run_args", "expected"),
    [
        (None, None, {}, [], (2, 1, 0)),  # default: one run per core of this process, in-process envs
        (None, 1, {}, [], (1, 2, 2)),  # one run gets both cores: 2 threads, 2 env workers
        (1, 1, {}, [], (1, 1, 0)),  # --cores=1 leaves the other core to other work
        (None, 1, {"OMP_NUM_THREADS": "1"}, [], (1, 1, 0)),  # compare's OMP_NUM_THREADS caps each run
        (None, 1, {}, ["--rollout.workers=1"], (1, 2, None)),  # the run options' workers hold
    ],
)
def test_runs_get_the_cores_they_are_given_and_no_more(monkeypatch, cores, jobs, environ, run_args, expected):
    """Two threads per run beside another job trained point clouds over 10x slower (1.4 vs 16.5 steps/s)."""
    from lerobot_mtdagger.analysis import compare as compare_module

    monkeypatch.setattr(compare_module, "default_worker_count", lambda: 2)
    config = CompareConfig(cores=cores, jobs=jobs)
    assert compare_module.run_resources(config, run_args, environ) == expected


def test_a_run_launched_with_the_run_options_workers_keeps_them(tmp_path):
    from lerobot_mtdagger.analysis.launchers import Job, job_command

    job = Job("uniform-seed0", ("--rollout.workers=1",), last_phase=1)
    command, variables = job_command(job, tmp_path / "uniform-seed0", threads=1, workers=None)
    assert [arg for arg in command if arg.startswith("--rollout.workers")] == ["--rollout.workers=1"]
    assert variables == {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    command, _ = job_command(job, tmp_path / "uniform-seed0", threads=2, workers=2)
    assert command[-2:] == ["--rollout.workers=2", "--progress=false"]


@pytest.mark.parametrize(
    ("option", "environ", "message"),
    [
        ("--cores=0", {}, "--cores must be >= 1, got 0."),
        ("--jobs=1", {"OMP_NUM_THREADS": "two"}, "OMP_NUM_THREADS='two' is not a positive whole number"),
    ],
)
def test_bad_core_or_thread_counts_are_refused_naming_the_fix(
    tmp_path, monkeypatch, capsys, option, environ, message
):
    for name, value in environ.items():
        monkeypatch.setenv(name, value)
    code = main(["compare", option, "--methods=[bc]", "--seeds=[0]", f"--output_dir={tmp_path}", *TINY])
    assert code != 0
    assert message in capsys.readouterr().err
    assert not (tmp_path / "runs").exists()
