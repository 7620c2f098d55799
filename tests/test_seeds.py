"""The run's random streams: named in one place, distinct, and the seeds runs were made with."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np

import lerobot_mtdagger
from lerobot_mtdagger.runner.rollout.collect import episode_seed
from lerobot_mtdagger.utils import seeds

PACKAGE = Path(lerobot_mtdagger.__file__).parent


def test_streams_are_distinct():
    streams = {name: value for name, value in vars(seeds).items() if name.endswith("_STREAM")}
    assert len(streams) == 7
    assert len(set(streams.values())) == len(streams)


def test_stream_seeds_are_those_earlier_runs_were_made_with():
    """A phase's seed was ``SeedSequence([seed, 3, round])``; an episode's the same with its keys."""
    for seed, round_index in [(0, 0), (100, 4), (7, 12)]:
        expected = int(np.random.SeedSequence([seed, 3, round_index]).generate_state(1)[0])
        assert seeds.stream_seed(seed, seeds.TRAINING_STREAM, round_index) == expected
    expected = int(np.random.SeedSequence([5, 0, 2, 1, 3]).generate_state(1)[0]) % 2**31
    assert episode_seed(5, seeds.COLLECT_STREAM, 2, 1, 3) == expected
    assert episode_seed(5, seeds.EVAL_STREAM, 2, 1, 3) >= 2**31


def test_no_module_numbers_a_stream_itself():
    """Every ``SeedSequence([seed, stream, ...])`` names its stream (a literal is a stream in hiding)."""
    offenders = []
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and getattr(node.func, "attr", "") == "SeedSequence":
                entropy = node.args[0] if node.args else None
                numbered = (
                    isinstance(entropy, ast.List)
                    and len(entropy.elts) > 1
                    and isinstance(entropy.elts[1], ast.Constant)
                )
                if numbered and path.name != "seeds.py":
                    offenders.append(f"{path.relative_to(PACKAGE)}:{node.lineno}")
    assert offenders == []
