"""The replay bench: schedulers run against measured learning curves, beside uniform and the oracles."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lerobot_mtdagger.analysis.headroom import TaskPoint, fit_curves, points_from_rows
from lerobot_mtdagger.analysis.replay import (
    ONLINE_ORACLE,
    STATIC_ORACLE,
    UNIFORM,
    ArmSpec,
    ReplaySetting,
    extend_curves,
    run_bench,
    seeds_for_half_width,
    synthetic_curves,
)
from lerobot_mtdagger.utils.errors import UserError
from tests.test_headroom import PAPER_REGIME, _paper_regime_rows


def _by_label(summaries):
    return {summary.label: summary for summary in summaries}


def test_identical_tasks_leave_no_headroom_for_any_scheduler():
    setting = ReplaySetting(initial_demos=3, rounds=3, budget_per_round=6, replicates=20)
    curve = {3: 0.2, 6: 0.6, 12: 0.9}
    task_points = [TaskPoint(t, 0, n, p, 20) for t in range(3) for n, p in curve.items()]
    curves = extend_curves(fit_curves(task_points, ["a", "b", "c"]), setting)
    summaries = _by_label(run_bench(curves, setting, [ArmSpec.parse("need"), ArmSpec.parse("curve")]))
    uniform = summaries[UNIFORM].mean_success
    for label in (ONLINE_ORACLE, STATIC_ORACLE):
        assert summaries[label].mean_success == pytest.approx(uniform, abs=1e-9)
    # A scheduler can only lose here: measurement noise tilts its split of concave curves.
    for label in ("need", "curve"):
        assert summaries[label].mean_success <= uniform + 1e-9
        assert np.isnan(summaries[label].share[0])


def test_the_oracles_bound_the_schedulers_on_synthetic_tasks():
    setting = ReplaySetting(initial_demos=3, rounds=6, budget_per_round=30, replicates=50)
    curves = synthetic_curves(10, 1.0, 60.0, setting)
    summaries = _by_label(run_bench(curves, setting, [ArmSpec.parse("need"), ArmSpec.parse("curve")], [0.8]))
    online, static = summaries[ONLINE_ORACLE].mean_success, summaries[STATIC_ORACLE].mean_success
    assert static >= online > summaries[UNIFORM].mean_success
    for label in ("need", "curve"):
        summary = summaries[label]
        assert summary.vs_uniform[1] > 0  # both use the spread of these tasks
        assert 0 < summary.share[0] < 1 and summary.mean_success <= online
    reach = {label: summaries[label].demos_to_reach[0.8] for label in (ONLINE_ORACLE, UNIFORM)}
    assert reach[ONLINE_ORACLE] is not None and (
        reach[UNIFORM] is None or reach[ONLINE_ORACLE] < reach[UNIFORM]
    )


def test_replicates_are_repeatable_and_seeded():
    setting = ReplaySetting(initial_demos=3, rounds=3, budget_per_round=20, replicates=10, seed=7)
    curves = synthetic_curves(5, 1.0, 30.0, setting)
    first = run_bench(curves, setting, [ArmSpec.parse("need")])
    again = run_bench(curves, setting, [ArmSpec.parse("need")])
    other = run_bench(curves, ReplaySetting(**{**setting.__dict__, "seed": 8}), [ArmSpec.parse("need")])
    assert first[1].mean_success == again[1].mean_success != other[1].mean_success


def test_the_paper_regime_replay_gives_need_a_small_lead_over_uniform():
    """Seeds 0-2's BC curves, flat past 30 demos: the lead the real study measured was +0.007."""
    task_points = points_from_rows(_paper_regime_rows(), "bc")
    setting = ReplaySetting(replicates=100)
    curves = extend_curves(fit_curves(task_points, [str(i) for i in range(43)]), setting)
    summaries = _by_label(run_bench(curves, setting, [ArmSpec.parse("need")]))
    need = summaries["need"]
    assert 0.0 < need.vs_uniform[0] < 0.02 and need.vs_uniform[1] > 0
    assert summaries[ONLINE_ORACLE].vs_uniform[0] < 0.06


@pytest.mark.parametrize(
    "text, match",
    [
        ("gain", "cannot replay it"),
        ("greedy", "Unknown scheduling method 'greedy'"),
        ("need:temperature=0", "temperature must be a finite number > 0"),
        ("need:colour=red", "unexpected keyword|colour"),
        ("need:temperature", "is not key=value"),
    ],
)
def test_a_bad_scheduler_is_refused_in_one_line(text, match):
    with pytest.raises(UserError, match=match):
        ArmSpec.parse(text)


@pytest.mark.parametrize(
    "options, match",
    [
        ({"rounds": 0}, "--rounds must be >= 1"),
        ({"extrapolation": "cubic"}, "--extrapolation must be one of"),
        ({"lag": -1}, "--lag must be >= 0"),
    ],
)
def test_a_bad_setting_is_refused(options, match):
    with pytest.raises(UserError, match=match):
        ReplaySetting(**options)


def test_a_study_starting_below_the_measured_curves_is_refused():
    task_points = [TaskPoint(0, 0, n, p, 20) for n, p in ((6, 0.3), (12, 0.6))]
    with pytest.raises(UserError, match="below the smallest demos"):
        extend_curves(fit_curves(task_points, ["a"]), ReplaySetting(initial_demos=3))


def test_slope_extrapolation_continues_the_last_measured_rise_up_to_one():
    task_points = [TaskPoint(0, 0, n, p, 20) for n, p in ((3, 0.2), (6, 0.5))]
    setting = ReplaySetting(initial_demos=3, rounds=1, budget_per_round=10, extrapolation="slope")
    curves = extend_curves(fit_curves(task_points, ["a"]), setting)
    assert curves.at(np.array([7]))[0] == pytest.approx(0.6) and curves.at(np.array([13]))[0] == 1.0
    flat = extend_curves(
        fit_curves(task_points, ["a"]), ReplaySetting(**{**setting.__dict__, "extrapolation": "flat"})
    )
    assert flat.at(np.array([13]))[0] == pytest.approx(0.5)


def test_seeds_for_a_half_width_of_half_the_effect():
    # Half-width t(0.975, n - 1) * 0.01 / sqrt(n) <= 0.01: 6 seeds give 1.05, 7 give 0.92.
    assert seeds_for_half_width(0.02, 0.01) == 7
    assert seeds_for_half_width(0.001, 0.05, most=30) is None


def test_the_replay_command_prints_the_comparison_and_writes_it(tmp_path, capsys):
    from lerobot_mtdagger.cli import main

    out = tmp_path / "replay.json"
    options = [
        "--synthetic_tasks=6",
        "--replicates=20",
        "--rounds=3",
        "--methods=[need,curve]",
        f"--output={out}",
    ]
    assert main(["replay", *options]) == 0
    printed = capsys.readouterr().out
    assert "| need |" in printed and "| oracle (online) |" in printed and "power:" in printed
    saved = json.loads(out.read_text())
    assert [arm["label"] for arm in saved["arms"]] == [
        "uniform",
        "need",
        "curve",
        ONLINE_ORACLE,
        STATIC_ORACLE,
    ]
    assert saved["setting"]["budget_per_round"] == 18


def test_the_replay_command_reads_a_studys_saved_records(capsys):
    from lerobot_mtdagger.cli import main

    records = PAPER_REGIME / "cosine-seed0" / "runs-records.tar.gz"
    assert main(["replay", f"--records=[{records}]", "--replicates=5", "--methods=[need]"]) == 0
    assert "43 tasks' curves from bc runs (seeds 0), measured 3-30 demos per task" in capsys.readouterr().out


@pytest.mark.parametrize(
    "options, match",
    [
        ([], "Give one source of curves"),
        (["--synthetic_tasks=4", "--methods=[gain]"], "cannot replay it"),
        (["--synthetic_tasks=4", "--rounds=0"], "--rounds must be >= 1"),
        (["--synthetic_tasks=4", "--levels=[1.5]"], "--levels must be success levels"),
    ],
)
def test_the_replay_command_refuses_bad_input_in_one_line(tmp_path, capsys, options, match):
    from lerobot_mtdagger.cli import main

    assert main(["replay", *options, f"--output={tmp_path / 'out.json'}"]) == 2
    err = capsys.readouterr().err
    assert match in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out.json").exists()
