"""How a policy acts on a drawer it was not trained on: the ``nearest`` rule beside the shared embedding."""

from __future__ import annotations

import json

import draccus
import numpy as np
import pytest
import torch
from lerobot.configs.types import FeatureType, PolicyFeature

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.commands.configs.eval import EvalConfig
from lerobot_mtdagger.commands.eval import eval_command
from lerobot_mtdagger.envs import make_suite
from lerobot_mtdagger.envs.drawers.catalogue import HELDOUT_DRAWERS, TRAINING_DRAWERS, VARIANTS
from lerobot_mtdagger.envs.drawers.variants import nearest_variant
from lerobot_mtdagger.policies import MTDAggerConfig, MTDAggerPolicy, make_mtdagger_pre_post_processors
from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner
from lerobot_mtdagger.utils.errors import UserError

TRAINED = ["drawer-kitchen", "drawer-lip-shallow"]
STATE_DIM = 18  # the drawers' privileged state


def test_each_unseen_drawer_has_the_documented_nearest_training_drawer():
    nearest = {v.name: nearest_variant(v, TRAINING_DRAWERS).name for v in HELDOUT_DRAWERS}
    assert nearest == {  # docs/drawers.md, "The unseen drawers"
        "drawer-bar-angled": "drawer-kitchen",
        "drawer-knob-tall": "drawer-knob-large",
        "drawer-vbar-short": "drawer-vbar-tall",
        "drawer-lip-heavy": "drawer-lip-shallow",
    }
    for variant in HELDOUT_DRAWERS:
        chosen = nearest[variant.name]
        assert VARIANTS[chosen].handle == variant.handle
        same_handle = [v for v in TRAINING_DRAWERS if v.handle == variant.handle]
        assert variant.handle_distance(VARIANTS[chosen]) == min(map(variant.handle_distance, same_handle))


def test_no_nearest_drawer_across_handle_types():
    knob = VARIANTS["drawer-knob-tall"]
    assert knob.handle_distance(VARIANTS["drawer-kitchen"]) == float("inf")
    assert nearest_variant(knob, [VARIANTS["drawer-kitchen"], VARIANTS["drawer-lip-wide"]]) is None
    assert nearest_variant(knob, []) is None
    suite = make_suite("drawers")
    with pytest.raises(UserError, match=r"No training drawer has a knob handle.*--unseen_rule=shared"):
        suite.nearest_training_task("drawer-knob-tall", TRAINED)


def test_a_suite_without_task_likeness_names_the_shared_rule():
    suite = make_suite("toy")
    with pytest.raises(UserError, match="has no rule for the training task most like.*--unseen_rule=shared"):
        suite.nearest_training_task("anything", suite.task_names)


def save_drawer_policy(folder) -> MTDAggerPolicy:
    """An untrained state policy for TRAINED with a shared embedding, saved with identity statistics."""
    torch.manual_seed(0)
    config = MTDAggerConfig(
        input_features={"observation.state": PolicyFeature(type=FeatureType.STATE, shape=(STATE_DIM,))},
        output_features={"action": PolicyFeature(type=FeatureType.ACTION, shape=(4,))},
        task_names=list(TRAINED),
        task_dropout=0.1,
        state_hidden_dims=(32,),
        head_hidden_dims=(32,),
        device="cpu",
    )
    policy = MTDAggerPolicy(config)
    torch.nn.init.normal_(policy.task_embedding.weight, std=3.0)  # tasks that clearly act differently
    stats = {
        "observation.state": {"mean": np.zeros(STATE_DIM), "std": np.ones(STATE_DIM)},
        "action": {"mean": np.zeros(4), "std": np.ones(4)},
    }
    preprocessor, postprocessor = make_mtdagger_pre_post_processors(config, stats)
    for part in (policy, preprocessor, postprocessor):
        part.save_pretrained(folder)
    return policy


def test_acting_as_a_training_drawer_gives_exactly_its_actions(tmp_path):
    save_drawer_policy(tmp_path / "policy")
    runner = PolicyRunner.from_pretrained(tmp_path / "policy")
    observations = [{"observation.state": np.linspace(-1, 1, STATE_DIM, dtype=np.float32)}] * 2
    kitchen = runner(observations, ["drawer-kitchen"] * 2)
    shared = runner(observations, ["drawer-bar-angled"] * 2)
    assert not np.allclose(kitchen, shared)

    runner.act_as({"drawer-bar-angled": "drawer-kitchen"})
    np.testing.assert_array_equal(runner(observations, ["drawer-bar-angled"] * 2), kitchen)
    np.testing.assert_array_equal(runner(observations, ["drawer-kitchen"] * 2), kitchen)
    runner.check_tasks(["drawer-bar-angled", "drawer-kitchen"])

    with pytest.raises(UserError, match=r"Cannot act as \['drawer-bar-wide'\]: the policy was trained on"):
        runner.act_as({"drawer-bar-angled": "drawer-bar-wide"})
    assert runner.task_aliases == {"drawer-bar-angled": "drawer-kitchen"}  # unchanged by the refusal


def eval_args(policy, *extra: str) -> EvalConfig:
    args = [f"--policy_path={policy}", "--suite.name=drawers", "--episodes=1", "--workers=0", *extra]
    return draccus.parse(EvalConfig, args=args)


def test_eval_acts_on_unseen_drawers_as_their_nearest_training_drawer(tmp_path, capsys):
    save_drawer_policy(tmp_path / "policy")
    output = tmp_path / "eval.json"
    tasks = "--suite.tasks=[drawer-bar-angled,drawer-lip-heavy]"
    nearest = eval_args(tmp_path / "policy", tasks, "--unseen_rule=nearest", f"--output={output}")
    result = eval_command(nearest)
    assert result["task_names"] == ["drawer-bar-angled", "drawer-lip-heavy"]
    expected = {"drawer-bar-angled": "drawer-kitchen", "drawer-lip-heavy": "drawer-lip-shallow"}
    assert result["acted_as"] == expected
    assert result["unseen_rule"] == "nearest"
    assert json.loads(output.read_text()) == result
    assert "(acting as drawer-kitchen)" in capsys.readouterr().out

    shared = eval_command(eval_args(tmp_path / "policy", tasks))
    assert shared["unseen_rule"] == "shared" and "acted_as" not in shared


def test_eval_refuses_the_nearest_rule_where_no_training_drawer_is_alike(tmp_path, capsys):
    save_drawer_policy(tmp_path / "policy")
    output = tmp_path / "eval.json"
    rule = "--unseen_rule=nearest"
    args = eval_args(tmp_path / "policy", "--suite.tasks=[heldout]", rule, f"--output={output}")
    with pytest.raises(UserError, match=r"No training drawer has a knob handle like 'drawer-knob-tall'"):
        eval_command(args)
    assert not output.exists()
    assert main(["eval", f"--policy_path={tmp_path / 'policy'}", "--unseen_rule=closest"]) == 2
    assert "unseen_rule must be one of ['shared', 'nearest'], got 'closest'" in capsys.readouterr().err
