"""``lab.passes``: a compare folder's runs and their passes, from ``outputs/`` or a saved archive."""

from __future__ import annotations

import json
import tarfile

from lab.passes import compare_runs, phase_passes


def write_run(runs, name, phases):
    """A run's records: config.json and one training.json per phase with its passes per task."""
    run = runs / name
    run.mkdir(parents=True)
    (run / "config.json").write_text("{}")
    for index, per_task in enumerate(phases):
        phase = run / "policies" / f"round-{index:03d}"
        phase.mkdir(parents=True)
        (phase / "training.json").write_text(json.dumps({"passes_per_task": per_task}))


def test_a_run_gives_one_cell_per_phase_with_the_mean_and_range_over_tasks(tmp_path):
    write_run(tmp_path, "uniform-seed0", [[130, 132], [54, None, 56], []])
    assert phase_passes(tmp_path / "uniform-seed0") == ["131 [130-132]", "55 [54-56]"]


def test_an_archived_compare_folder_gives_the_same_runs_and_passes_as_outputs(tmp_path):
    outputs = tmp_path / "outputs" / "cosine-seed0"
    write_run(outputs / "runs", "bc-6demos-seed0", [[138, 140]])
    write_run(outputs / "runs", "need-seed0", [[131, 129], [55, 56]])
    saved = tmp_path / "records" / "cosine-seed0"
    saved.mkdir(parents=True)
    with tarfile.open(saved / "runs-records.tar.gz", "w:gz") as tar:
        tar.add(outputs / "runs", arcname=".")

    def table(compare):
        return {run.name: phase_passes(run) for run in compare_runs(compare)}

    assert table(outputs) == {
        "bc-6demos-seed0": ["139 [138-140]"],
        "need-seed0": ["130 [129-131]", "56 [55-56]"],
    }
    assert table(saved) == table(outputs)
    assert compare_runs(tmp_path / "records" / "plain-seed0") == []  # neither: no runs
