"""DAgger's mixing rules without env workers: who acts at a step, when an episode ends."""

from __future__ import annotations

import numpy as np
import pytest

from lerobot_mtdagger.runner.rollout.mixing import RolloutRules, episode_ends, expert_acts_now, step_limit


def rules(**changes) -> RolloutRules:
    base = {"beta": 0.5, "learner": True, "record": True, "round_index": 1, "max_steps": None}
    return RolloutRules(**(base | {"steps_after_success": 10} | changes))


def test_step_mixing_executes_the_expert_at_rate_beta_from_the_episodes_generator():
    for beta in (0.0, 0.3, 1.0):
        rng = np.random.default_rng(0)
        share = np.mean(
            [expert_acts_now(rules(beta=beta, mixing="step"), True, False, rng) for _ in range(4000)]
        )
        assert share == pytest.approx(beta, abs=0.03)
    rng, reference = np.random.default_rng(1), np.random.default_rng(1)
    acts = [expert_acts_now(rules(beta=0.5, mixing="step"), True, False, rng) for _ in range(50)]
    assert acts == [u < 0.5 for u in reference.random(50)], "one uniform per step, in order"


def test_episode_mixing_follows_the_episodes_coin_and_draws_nothing():
    rng = np.random.default_rng(0)
    state = rng.bit_generator.state
    assert expert_acts_now(rules(mixing="episode"), True, True, rng)
    assert not expert_acts_now(rules(mixing="episode"), True, False, rng)
    assert rng.bit_generator.state == state


def test_without_a_learner_action_the_expert_acts():
    for mixing in ("step", "episode"):
        assert expert_acts_now(rules(beta=0.0, mixing=mixing), False, False, np.random.default_rng(0))


@pytest.mark.parametrize(
    ("max_steps", "multiple", "expert_steps", "expected"),
    [
        (None, None, 40, None),
        (300, None, 40, 300),
        (300, 2.0, 40, 80),
        (50, 2.0, 40, 50),
        (300, 1.5, 41, 62),  # ceil(61.5)
        (300, 2.0, None, 300),  # the expert never succeeded: no cut
        (None, 2.0, None, None),
    ],
)
def test_the_step_limit_is_the_tighter_of_the_cap_and_the_experts_multiple(
    max_steps, multiple, expert_steps, expected
):
    assert step_limit(rules(max_steps=max_steps, expert_multiple=multiple), expert_steps) == expected


def test_an_episode_ends_at_its_cap_or_some_steps_after_success():
    round_rules = rules(steps_after_success=3)
    assert not episode_ends(round_rules, steps=10, max_steps=None, steps_since_success=-1)
    assert episode_ends(round_rules, steps=10, max_steps=10, steps_since_success=-1)
    assert not episode_ends(round_rules, steps=10, max_steps=11, steps_since_success=2)
    assert episode_ends(round_rules, steps=10, max_steps=None, steps_since_success=3)
    assert episode_ends(rules(steps_after_success=0), steps=5, max_steps=None, steps_since_success=0)
