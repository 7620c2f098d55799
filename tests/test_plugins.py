"""Students, suites and expert types from an installed package: its entry points put them on the command line.

The package here is a folder on ``PYTHONPATH`` with a ``.dist-info`` that declares the entry points,
as ``pip install`` leaves one; a fresh process runs ``lerobot-mtdagger run`` with its names.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from lerobot_mtdagger.experts import command_line
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.plugins import (
    EXPERT_ENTRY_POINTS,
    STUDENT_ENTRY_POINTS,
    SUITE_ENTRY_POINTS,
    register_installed,
)
from lerobot_mtdagger.utils.registry import Registry, resolve
from tests.helpers import TINY_ROUND

PLUGIN_MODULE = '''
from dataclasses import dataclass

from lerobot_mtdagger.envs.toy import TOY_TASKS, ToySuite
from lerobot_mtdagger.students.mtdagger import MTDAggerStudent
from lerobot_mtdagger.runner.policy_options import PolicyOptions


@dataclass
class PluginOptions(PolicyOptions):
    """The mtdagger options, under the plugin's own type."""


class PluginStudent(MTDAggerStudent):
    """The mtdagger student, installed under another --policy.type."""

    def options_class(self):
        return PluginOptions


class TwoTaskSuite(ToySuite):
    name = "toy-two"


def plugin_expert(suite, task):
    """The toy suite's scripted expert, installed as an expert type."""
    from lerobot_mtdagger.experts import make_expert

    return make_expert(suite.with_experts({}), task).expert


def two_task_suite(options):
    """The toy suite's first two tasks, installed as a suite of its own."""
    options.refuse_placement()
    tasks = list(TOY_TASKS.values())[:2]
    return TwoTaskSuite(options.task_list([t.name for t in tasks]), options.observation,
                        options.max_episode_steps, tasks=tasks)
'''


def install_plugin(root: Path, entry_points: str) -> dict[str, str]:
    """Writes the plugin package and its ``.dist-info`` under ``root``; the environment that finds it."""
    (root / "mtdagger_plugin_demo.py").write_text(PLUGIN_MODULE)
    info = root / "mtdagger_plugin_demo-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: mtdagger-plugin-demo\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(textwrap.dedent(entry_points))
    path = os.pathsep.join([str(root), str(Path.cwd()), os.environ.get("PYTHONPATH", "")])
    return {**os.environ, "PYTHONPATH": path}


def lerobot_mtdagger(env: dict[str, str], *args: str) -> subprocess.CompletedProcess:
    """``lerobot-mtdagger ARGS`` in a fresh process."""
    code = "import sys; from lerobot_mtdagger.cli import main; sys.exit(main(sys.argv[1:]))"
    return subprocess.run(
        [sys.executable, "-c", code, *args], env=env, capture_output=True, text=True, timeout=600, check=False
    )


def test_an_installed_student_and_suite_run_from_the_command_line(tmp_path):
    env = install_plugin(
        tmp_path,
        f"""
        [{STUDENT_ENTRY_POINTS}]
        plugin-student = mtdagger_plugin_demo:PluginStudent

        [{SUITE_ENTRY_POINTS}]
        toy-two = mtdagger_plugin_demo:two_task_suite

        [{EXPERT_ENTRY_POINTS}]
        plugin-expert = mtdagger_plugin_demo:plugin_expert
        """,
    )
    out = tmp_path / "run"
    done = lerobot_mtdagger(
        env,
        "run",
        "--suite.name=toy-two",
        "--policy.type=plugin-student",
        "--expert.type=plugin-expert",
        *TINY_ROUND,
        f"--output_dir={out}",
    )
    assert done.returncode == 0, done.stderr[-3000:]
    config = json.loads((out / "config.json").read_text())
    assert config["suite"]["name"] == "toy-two" and config["policy"]["type"] == "plugin-student"
    assert config["expert"]["type"] == "plugin-expert"
    record = json.loads((out / "policies" / "round-001" / "training.json").read_text())
    assert len(record["eval"]["success"]) == 2  # the suite's two tasks
    verified = lerobot_mtdagger(env, "verify", f"--experiment_dir={out}")
    assert verified.returncode == 0, verified.stderr[-3000:]
    # Without the package, the names are unknown, and the refusal lists what is registered.
    bare = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path.cwd()), os.environ.get("PYTHONPATH", "")])}
    missing = tmp_path / "x"
    refused = lerobot_mtdagger(bare, "run", "--suite.name=toy-two", *TINY_ROUND, f"--output_dir={missing}")
    assert refused.returncode != 0 and "Unknown suite 'toy-two'" in refused.stderr, refused.stderr[-2000:]
    assert not missing.exists()


def test_an_installed_name_that_is_taken_is_skipped_with_a_warning(caplog, monkeypatch, tmp_path):
    install_plugin(tmp_path, f"[{STUDENT_ENTRY_POINTS}]\nact = mtdagger_plugin_demo:PluginStudent\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    registered: dict[str, str] = {}
    added = register_installed(STUDENT_ENTRY_POINTS, ["act"], registered.__setitem__)
    assert added == [] and registered == {}
    assert "act = mtdagger_plugin_demo:PluginStudent" in caplog.text and "rename it" in caplog.text


def test_an_installed_expert_type_is_found_by_name(monkeypatch, tmp_path):
    """A fake installed package's ``lerobot_mtdagger.experts`` entry point names an ``--expert.type``."""
    install_plugin(tmp_path, f"[{EXPERT_ENTRY_POINTS}]\nplugin-expert = mtdagger_plugin_demo:plugin_expert\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(command_line, "EXPERT_TYPES", command_line.EXPERT_TYPES.copy())
    assert command_line.EXPERT_TYPES.load_entry_points() == ["plugin-expert"]
    assert command_line.expert_type_factory("plugin-expert").__module__ == "mtdagger_plugin_demo"


def test_a_registry_resolves_module_attribute_once_and_refuses_bad_ones_in_one_line():
    things: Registry[str, object] = Registry("thing")
    things.register("json", "json:dumps")

    @things.register("mine")
    def mine():
        return 1

    assert things.get("json") is json.dumps and things.get("mine") is mine
    assert things.names() == ["json", "mine"]
    for bad, message in [
        ("no-colon", "is not a 'module:attribute' string"),
        ("no_such_module_xyz:f", "module 'no_such_module_xyz' cannot be imported"),
        ("json:nothing", "module 'json' has no attribute 'nothing'"),
    ]:
        with pytest.raises(UserError, match=message):
            resolve(bad)
    with pytest.raises(UserError, match="Unknown thing 'other'; registered: json, mine"):
        things.get("other")
    with pytest.raises(UserError, match="already registered"):
        things.register("json", "json:loads")
    with pytest.raises(TypeError, match="must be callable or a 'module:attribute' string"):
        things.register("number", 3)
