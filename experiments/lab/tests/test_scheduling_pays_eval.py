"""``scheduling-pays-eval``: decide.py's setting rule and bench_check.py's table, on stand-in replays."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pytest

STUDY = Path(__file__).resolve().parents[2] / "scheduling-pays-eval"


def load(name):
    spec = importlib.util.spec_from_file_location(name, STUDY / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def arm(label, effect, share, sd=0.006, half=0.0001):
    return {
        "label": label,
        "vs_uniform": [effect, effect - half, effect + half],
        "share": [share, share, share],
        "replicate_sd": sd,
    }


def replay(best_effect, best_share, oracle=0.07):
    return {
        "source": "stand-in curves",
        "setting": {"replicates": 500},
        "arms": [
            arm("uniform", 0.0, 0.0),
            arm("need", best_effect, best_share),
            arm("curve", best_effect / 2, best_share / 2),
            arm("need:temperature=0.25", 0.9 * oracle, 0.9),  # a variant: shown, never chosen
            arm("oracle (online)", oracle, 1.0),
            arm("oracle (static)", oracle * 1.2, 1.2),
        ],
    }


@pytest.mark.parametrize(
    ("effect", "share", "qualifies", "why"),
    [
        (0.040, 0.57, True, ""),
        (0.028, 0.40, False, "captures 40% < 50%"),
        (0.008, 0.55, False, "more than the 11 affordable"),
    ],
)
def test_a_setting_qualifies_only_with_half_the_headroom_and_affordable_seeds(effect, share, qualifies, why):
    ok, lines = load("decide").judge("paper", replay(effect, share))
    assert ok is qualifies
    assert why in lines[-1]
    assert "best scheduler need" in lines[1]  # the variant with a larger effect is not eligible


def test_no_qualifying_setting_decides_none(tmp_path, capsys):
    (tmp_path / "replay-paper.json").write_text(json.dumps(replay(0.028, 0.40)))
    (tmp_path / "replay-pixels.json").write_text(json.dumps(replay(0.009, 0.32, oracle=0.028)))
    load("decide").main(tmp_path)
    assert capsys.readouterr().out.splitlines()[-1] == "setting: none"


def test_the_bench_check_sets_the_prediction_beside_the_measured_interval(tmp_path):
    (tmp_path / "replay-paper.json").write_text(json.dumps(replay(0.060, 0.5)))
    (tmp_path / "replay-pixels.json").write_text(json.dumps(replay(0.009, 0.32)))
    rows = load("bench_check").lines(tmp_path)[2:]
    assert rows[0].startswith("| paper | +0.060 [+0.060, +0.060]") and rows[0].endswith("| no |")
    assert rows[1].startswith("| pixels | +0.009") and rows[1].endswith("| yes |")
