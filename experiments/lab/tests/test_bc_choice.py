"""The rule that picks a BC baseline's training on development seeds, on records laid out as saved."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from lab.bc_choice import (
    choice_report,
    choose_bc_training,
    read_bc_records,
    success_table,
)

BUDGETS = (33, 45, 63)
SEEDS = (100, 101)


def write_record(folder: Path, training: str, budget: int, seed: int, success: float) -> None:
    """One BC run's record as ``scripts/save_run_records.sh`` saves it."""
    phase = folder / training / f"bc-{budget}demos-seed{seed}" / "policies" / "round-000"
    phase.mkdir(parents=True)
    (phase / "training.json").write_text(json.dumps({"eval": {"mean": success, "per_task": [success]}}))


def results_of(by_training: dict[str, dict[int, float]]) -> dict[str, dict[tuple[int, int], float]]:
    """Every seed of a training gets its budget's success."""
    return {
        training: {(budget, seed): success for budget, success in curve.items() for seed in SEEDS}
        for training, curve in by_training.items()
    }


def test_records_are_read_by_training_budget_and_seed(tmp_path):
    write_record(tmp_path, "plain", 33, 100, 0.9)
    write_record(tmp_path, "plain", 63, 101, 0.8)
    write_record(tmp_path, "cosine", 45, 100, 0.7)
    (tmp_path / "cosine" / "need-seed100" / "policies" / "round-000").mkdir(parents=True)  # not BC
    (tmp_path / "plain" / "bc-45demos-seed100").mkdir()  # started, no finished phase
    assert read_bc_records(tmp_path) == {
        "plain": {(33, 100): 0.9, (63, 101): 0.8},
        "cosine": {(45, 100): 0.7},
    }


def test_records_compacted_per_training_read_as_their_folders(tmp_path):
    write_record(tmp_path, "plain", 33, 100, 0.9)
    write_record(tmp_path, "cosine", 45, 100, 0.7)
    write_record(tmp_path, "cosine", 63, 101, 0.6)
    for run in tmp_path.glob("*/bc-*"):
        (run / "config.json").write_text("{}")  # what marks a run's records folder
    folders = read_bc_records(tmp_path)
    script = Path(__file__).resolve().parents[3] / "scripts" / "compact_records.sh"
    subprocess.run(["bash", str(script), str(tmp_path)], check=True, capture_output=True)
    assert sorted(p.name for p in (tmp_path / "cosine").iterdir()) == ["runs-records.tar.gz"]
    assert (
        read_bc_records(tmp_path)
        == folders
        == {"plain": {(33, 100): 0.9}, "cosine": {(45, 100): 0.7, (63, 101): 0.6}}
    )


def test_a_training_that_drops_with_more_data_is_passed_over_for_a_lower_mean():
    results = results_of(
        {
            "plain": {33: 0.98, 45: 0.95, 63: 0.94},  # highest mean, but -0.04 from 33 to 63
            "plateau": {33: 0.93, 45: 0.94, 63: 0.95},
            "cosine": {33: 0.90, 45: 0.91, 63: 0.92},
        }
    )
    choice = choose_bc_training(results, ("plain", "plateau", "cosine"), BUDGETS, SEEDS)
    assert choice.chosen == "plateau" and choice.qualified
    assert choice.lines[0] == "plain: mean over budgets 0.957; 63 - 33 demos -0.040 (drops: does not qualify)"


def test_a_drop_within_the_allowance_still_qualifies():
    results = results_of({"plain": {33: 0.950, 45: 0.96, 63: 0.945}, "cosine": {33: 0.9, 45: 0.9, 63: 0.9}})
    choice = choose_bc_training(results, ("plain", "cosine"), BUDGETS, SEEDS, drop_allowed=0.01)
    assert choice.chosen == "plain" and choice.qualified


def test_when_every_training_drops_the_highest_mean_is_taken_and_said_so():
    results = results_of({"plain": {33: 0.98, 45: 0.9, 63: 0.9}, "cosine": {33: 0.99, 45: 0.95, 63: 0.9}})
    choice = choose_bc_training(results, ("plain", "cosine"), BUDGETS, SEEDS)
    assert choice.chosen == "cosine" and not choice.qualified


def test_no_choice_until_every_run_has_finished():
    results = results_of({"plain": {33: 0.9, 45: 0.9, 63: 0.95}, "cosine": {33: 0.9, 45: 0.9, 63: 0.9}})
    del results["cosine"][(63, 101)]
    choice = choose_bc_training(results, ("plain", "cosine", "plateau"), BUDGETS, SEEDS)
    assert choice.chosen is None
    assert choice.lines == ("not yet: 7 runs unfinished (every training needs all 6)",)


def test_the_table_shows_missing_runs_and_the_mean_of_those_done():
    table = success_table({"plain": {(33, 100): 0.9, (33, 101): 0.8}}, (33, 45), SEEDS)
    assert table[2] == "| plain | 33 | 0.900 | 0.800 | 0.850 |"
    assert table[3] == "| plain | 45 | - | - | - |"


@pytest.mark.parametrize("missing_seed", SEEDS)
def test_the_mean_is_over_seeds_not_over_runs_of_one_seed(missing_seed):
    results = results_of({"plain": {33: 0.9, 45: 0.9, 63: 0.9}})
    results["plain"][(63, missing_seed)] = 0.5  # one seed falls: the mean at 63 is 0.7
    choice = choose_bc_training(results, ("plain",), BUDGETS, SEEDS)
    assert choice.chosen == "plain" and not choice.qualified
    assert "63 - 33 demos -0.200" in choice.lines[0]


def test_the_report_ends_with_the_decision_line_the_evaluation_scripts_read():
    results = results_of({"plain": {33: 0.98, 45: 0.9, 63: 0.9}, "cosine": {33: 0.99, 45: 0.95, 63: 0.9}})
    options = dict(label="training", decision="the best BC is {}", none_word="none")
    lines = choice_report(results, ("plain", "cosine"), BUDGETS, SEEDS, **options)
    assert lines[-1] == (
        "Decision: the best BC is cosine (none qualified: the highest mean; BC's training needs more study)."
    )
    del results["plain"][(63, 101)]
    lines = choice_report(results, ("plain", "cosine"), BUDGETS, SEEDS, **options)
    assert lines[-1] == "Decision: not yet: 1 runs unfinished (every training needs all 6)."
