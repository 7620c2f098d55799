"""Where a drawer student's own rollouts take it, by the scripted expert's branch.

Rolls out a policy (the learner acts at every step, as in a beta = 0 DAgger round or an evaluation)
on every training drawer, asks the expert about every state it visits, and tallies the expert's
branch (``DrawerScriptedExpert.decide``), the learner's squared error to the label per branch, and
where the hand is per branch: its median offset from the grasp pose across the pull axis (absolute),
along it (signed: > 0 towards the robot) and vertically (signed: > 0 above), and the gripper reading.

    .venv/bin/python experiments/visual-collapse-dev/branches.py POLICY_FOLDER [EPISODES] [SEED] [DRAWER]

Prints one table; the same seed gives the same episodes for every policy.
"""

from __future__ import annotations

import sys
from collections import Counter, defaultdict

import numpy as np

from lerobot_mtdagger.envs import ObservationConfig, make_suite
from lerobot_mtdagger.envs.drawers.variants import STATE_INDEX
from lerobot_mtdagger.experts import make_expert
from lerobot_mtdagger.experts.drawers import BRANCHES
from lerobot_mtdagger.runner.rollout.collect import EVAL_STREAM, episode_seed
from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner


def misalignment(state: np.ndarray) -> tuple[float, float, float]:
    """Lateral, along-axis and vertical offset of the grasp pose from the hand, metres."""
    hand = np.array([state[STATE_INDEX[f"hand_{a}"]] for a in "xyz"])
    grasp = np.array([state[STATE_INDEX[f"grasp_{a}"]] for a in "xyz"])
    axis = np.array([state[STATE_INDEX[f"axis_{a}"]] for a in "xyz"])
    lateral_axis = np.array([-axis[1], axis[0], 0.0])
    error = grasp - hand
    return float(error @ lateral_axis), float(-(error @ axis)), float(error[2])


def main(policy_path: str, episodes: int = 5, seed: int = 0, drawer: str | None = None) -> None:
    """Prints the branch table of one policy (module docstring)."""
    runner = PolicyRunner.from_pretrained(policy_path)
    num_points = runner.policy.config.input_features["observation.pointcloud"].shape[0]
    suite = make_suite("drawers", observation=ObservationConfig(obs_mode="pointcloud", num_points=num_points))
    names = suite.task_names if drawer is None else [drawer]
    counts: Counter[str] = Counter()
    errors: dict[str, list[float]] = defaultdict(list)
    offsets: dict[str, list[tuple[float, ...]]] = defaultdict(list)
    successes, lengths = [], []
    envs = [suite.make_env(name) for name in names]
    experts = [make_expert(suite, name) for name in names]
    for episode in range(episodes):
        observations, privileged, done = [], [], [False] * len(names)
        for task, env in enumerate(envs):
            index = suite.task_index(names[task])
            observation, info = env.reset(seed=episode_seed(seed, EVAL_STREAM, 0, index, episode))
            observations.append(observation)
            privileged.append(info["privileged_state"])
        success, steps = [False] * len(names), [0] * len(names)
        while not all(done):
            running = [t for t in range(len(names)) if not done[t]]
            actions = runner([observations[t] for t in running], [names[t] for t in running])
            for action, task in zip(actions, running, strict=True):
                branch, label = experts[task].expert.decide(privileged[task])
                counts[branch] += 1
                errors[branch].append(float(((action - label) ** 2).mean()))
                lateral, along, vertical = misalignment(privileged[task])
                gripper = privileged[task][STATE_INDEX["gripper"]]
                offsets[branch].append((abs(lateral), along, -vertical, gripper))
                observations[task], _, _, truncated, info = envs[task].step(action)
                privileged[task] = info["privileged_state"]
                steps[task] += 1
                if info["success"]:
                    success[task] = True
                done[task] = bool(info["success"] or truncated)
        successes += success
        lengths += steps
    total = sum(counts.values())
    print(
        f"policy {policy_path}: success {np.mean(successes):.3f} over {len(successes)} episodes, "
        f"{total} learner steps (mean episode {np.mean(lengths):.0f})"
    )
    print(
        "| branch | share of steps | learner MSE to label | median abs lateral cm | median along cm "
        "| median vertical cm | median gripper |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|")
    for branch in BRANCHES:
        if counts[branch]:
            lateral, along, vertical, gripper = np.median(np.array(offsets[branch]), axis=0)
            print(
                f"| {branch} | {counts[branch] / total:.3f} | {np.mean(errors[branch]):.3f} | "
                f"{100 * lateral:.1f} | {100 * along:+.1f} | {100 * vertical:+.1f} | {gripper:.2f} |"
            )
    for env in envs:
        env.close()


if __name__ == "__main__":
    main(sys.argv[1], *(int(a) for a in sys.argv[2:4]), *sys.argv[4:5])
