"""Tests of ``lerobot_mtdagger.datasets.hub`` against a LOCAL STAND-IN for the Hugging Face Hub API.

``FakeHfApi`` implements the ``HfApi`` methods the push uses (create_repo, upload_folder, create_tag)
with the Hub's semantics as read in huggingface_hub's source: ``delete_patterns`` are fnmatch patterns
on the remote paths (``*`` also matches ``/``) that never remove ``.gitattributes``, an upload that changes
nothing makes no commit and returns the head, and ``create_tag(exist_ok=True)`` leaves an existing tag in
place. Every commit is stored as a snapshot folder, so tests read a revision's files. Nothing here contacts
the Hub, except ``test_live_push_to_the_hub``, which is skipped unless ``MTDAGGER_HUB_TEST_REPO`` and
``HF_TOKEN`` are set.
"""

from __future__ import annotations

import filecmp
import hashlib
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from types import SimpleNamespace

import httpx
import pyarrow.parquet as pq
import pytest
import requests
from huggingface_hub.errors import LocalTokenNotFoundError
from huggingface_hub.utils import filter_repo_objects

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.datasets import hub
from lerobot_mtdagger.datasets.experiment_dir import RECORD_FILES, ExperimentDir
from lerobot_mtdagger.datasets.hub import PushConfig, push_command, push_experiment, render_dataset_card
from lerobot_mtdagger.datasets.integrity import folder_digests
from lerobot_mtdagger.utils.errors import CorruptExperimentError, UserError
from lerobot_mtdagger.utils.hub import check_hub_repo, in_hub_cache, is_hub_id, lerobot_dataset_cache
from tests.helpers import edit_round_record

TASKS = ["toy-left", "toy-right"]
DATASET_REPO = "tester/mtdagger-rounds"
POLICY_REPO = "tester/mtdagger-policy"


# -------------------------------------------------------------------------------------------------
# A local stand-in for HfApi
# -------------------------------------------------------------------------------------------------


@dataclass
class FakeRepo:
    private: bool
    commits: list[str] = field(default_factory=list)
    messages: dict[str, str] = field(default_factory=dict)
    tags: dict[str, str] = field(default_factory=dict)


def tree_files(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


class FakeHfApi:
    """Commits are snapshot folders under ``root``; the head of ``main`` is the last commit."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self.repos: dict[tuple[str, str], FakeRepo] = {}
        self.calls: list[str] = []
        self.num_commits = 0
        self.access = "ok"  # or "no token", "offline": what whoami() meets

    def whoami(self) -> dict:
        self.calls.append("whoami")
        if self.access == "no token":
            raise LocalTokenNotFoundError("Token is required (`token=True`), but no token found.")
        if self.access == "offline":  # huggingface_hub 0.x sends with requests
            raise requests.ConnectionError("Failed to resolve 'huggingface.co'")
        if self.access == "offline (httpx)":  # 1.x sends with httpx
            raise httpx.ConnectError("[Errno -2] Name or service not known")
        return {"name": "tester"}

    def _repo(self, repo_id: str, repo_type: str | None) -> FakeRepo:
        key = (repo_type or "model", repo_id)
        if key not in self.repos:
            raise LookupError(f"404: {key} does not exist (create_repo first)")
        return self.repos[key]

    def snapshot(self, repo_id: str, revision: str, repo_type: str = "dataset") -> Path:
        repo = self._repo(repo_id, repo_type)
        oid = repo.tags.get(revision, repo.commits[-1] if revision == "main" else revision)
        assert oid in repo.commits, f"unknown revision {revision}"
        return self.root / oid

    def create_repo(self, repo_id, *, repo_type=None, private=None, exist_ok=False, **kwargs):
        self.calls.append("create_repo")
        key = (repo_type or "model", repo_id)
        if key in self.repos and not exist_ok:
            raise FileExistsError(f"409: {key} exists")
        if key not in self.repos:
            self.repos[key] = FakeRepo(private=bool(private))
            # The Hub creates every repo with one commit holding .gitattributes.
            self._commit(self.repos[key], {".gitattributes": b"*.parquet filter=lfs\n"}, "initial commit")
        return SimpleNamespace(repo_id=repo_id)

    def _commit(self, repo: FakeRepo, files: dict[str, bytes], message: str) -> str:
        self.num_commits += 1
        oid = hashlib.sha1(f"commit {self.num_commits}: {message}".encode()).hexdigest()
        for path, content in files.items():
            (self.root / oid / path).parent.mkdir(parents=True, exist_ok=True)
            (self.root / oid / path).write_bytes(content)
        repo.commits.append(oid)
        repo.messages[oid] = message
        return oid

    def upload_folder(
        self, *, repo_id, folder_path, repo_type=None, commit_message=None, delete_patterns=None, **kwargs
    ):
        self.calls.append("upload_folder")
        assert not kwargs.get("path_in_repo"), "the push uploads to the repo root"
        repo = self._repo(repo_id, repo_type)
        files = tree_files(self.root / repo.commits[-1])
        if delete_patterns:
            doomed = set(filter_repo_objects(list(files), allow_patterns=delete_patterns))
            files = {p: c for p, c in files.items() if p not in doomed or p == ".gitattributes"}
        files |= tree_files(Path(folder_path))  # read_bytes follows symlinks, like the real upload
        if files == tree_files(self.root / repo.commits[-1]):
            return SimpleNamespace(oid=repo.commits[-1], commit_message=commit_message)
        return SimpleNamespace(oid=self._commit(repo, files, commit_message), commit_message=commit_message)

    def create_tag(self, repo_id, *, tag, revision=None, repo_type=None, exist_ok=False, **kwargs):
        self.calls.append("create_tag")
        repo = self._repo(repo_id, repo_type)
        assert revision in repo.commits, f"tag {tag} names unknown commit {revision}"
        if tag in repo.tags:
            if not exist_ok:
                raise FileExistsError(f"409: tag {tag} exists")
            return
        repo.tags[tag] = revision


# -------------------------------------------------------------------------------------------------
# Fixtures
# -------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def experiment_dir(tmp_path_factory) -> Path:
    """A real two-round experiment (rounds 0 and 1, two training phases), made once per module."""
    output = tmp_path_factory.mktemp("hub") / "experiment"
    subprocess.run(
        [
            str(Path(sys.executable).parent / "lerobot-mtdagger"),
            "run",
            "--suite.name=toy",
            f"--suite.tasks=[{','.join(TASKS)}]",
            "--dagger.rounds=1",
            "--training.steps_per_round=20",
            "--rollout.eval_episodes=1",
            f"--output_dir={output}",
        ],
        check=True,
        capture_output=True,
    )
    return output


@pytest.fixture
def fake_api(tmp_path) -> FakeHfApi:
    return FakeHfApi(tmp_path / "hub")


def dir_digest(root: Path) -> dict[str, str]:
    return {path: hashlib.sha256(content).hexdigest() for path, content in tree_files(root).items()}


# -------------------------------------------------------------------------------------------------
# Pushing
# -------------------------------------------------------------------------------------------------


def test_each_round_is_a_tagged_commit_holding_exactly_that_round(experiment_dir, fake_api):
    experiment = ExperimentDir(experiment_dir)
    before = dir_digest(experiment.rounds)
    pushed = push_experiment(experiment_dir, DATASET_REPO, api=fake_api)

    repo = fake_api.repos[("dataset", DATASET_REPO)]
    assert list(pushed["dataset"]) == ["round-000", "round-001"]
    assert pushed["policy"] == {}
    assert repo.tags == pushed["dataset"]
    assert fake_api.calls[:2] == ["whoami", "create_repo"]
    for k in (0, 1):
        snapshot = fake_api.snapshot(DATASET_REPO, f"round-{k:03d}")
        assert json.loads((snapshot / "meta" / "mtdagger.json").read_text())["round"] == k
        expected = set(tree_files(experiment.round_root(k))) | {"README.md", ".gitattributes"}
        assert set(tree_files(snapshot)) == expected, "a revision holds exactly its round's files"
        assert not filecmp.dircmp(snapshot / "data", experiment.round_root(k) / "data").diff_files
        assert repo.messages[pushed["dataset"][f"round-{k:03d}"]].startswith(f"round {k}: 6 episodes")
    assert fake_api.snapshot(DATASET_REPO, "main") == fake_api.snapshot(DATASET_REPO, "round-001")
    assert dir_digest(experiment.rounds) == before, "committed rounds are never written to"


def test_stale_files_of_an_earlier_round_vanish_but_user_files_stay(experiment_dir, fake_api, tmp_path):
    copy = tmp_path / "experiment"
    shutil.copytree(experiment_dir, copy)
    stale = ["data/chunk-001/file-000.parquet", "meta/episodes/chunk-001/file-000.parquet"]
    for name in stale:  # round 0 (of this copy) has files that round 1 does not have (no frames)
        path = ExperimentDir(copy).round_root(0) / name
        path.parent.mkdir(parents=True)
        frames = pq.read_table(ExperimentDir(copy).round_root(0) / "data/chunk-000/file-000.parquet")
        pq.write_table(frames.slice(0, 0), path)
    files = folder_digests(ExperimentDir(copy).round_root(0), exclude=RECORD_FILES)
    edit_round_record(ExperimentDir(copy).round_root(0), lambda record: record.update(files=files))
    fake_api.create_repo(DATASET_REPO, repo_type="dataset")
    user_file = {".gitattributes": b"*.parquet filter=lfs\n", "images/plot.png": b"png"}
    fake_api._commit(fake_api.repos[("dataset", DATASET_REPO)], user_file, "a file the user added")

    push_experiment(copy, DATASET_REPO, api=fake_api)

    round0 = set(tree_files(fake_api.snapshot(DATASET_REPO, "round-000")))
    round1 = set(tree_files(fake_api.snapshot(DATASET_REPO, "round-001")))
    assert set(stale) <= round0
    assert not set(stale) & round1
    assert "images/plot.png" in round1, "delete patterns only cover the dataset's folders"


def test_policies_are_pushed_and_tagged_per_phase(experiment_dir, fake_api):
    experiment = ExperimentDir(experiment_dir)
    pushed = push_experiment(experiment_dir, DATASET_REPO, POLICY_REPO, private=True, api=fake_api)

    repo = fake_api.repos[("model", POLICY_REPO)]
    assert repo.private
    assert list(pushed["policy"]) == ["round-000", "round-001"]
    assert repo.tags == pushed["policy"]
    for k in (0, 1):
        snapshot = fake_api.snapshot(POLICY_REPO, f"round-{k:03d}", repo_type="model")
        assert set(tree_files(snapshot)) == set(tree_files(experiment.policy_root(k))) | {".gitattributes"}
        training = json.loads((snapshot / "training.json").read_text())
        assert training == experiment.read_phase_record(k).to_dict()
        assert (snapshot / "model.safetensors").read_bytes() == (
            experiment.policy_root(k) / "model.safetensors"
        ).read_bytes()


def test_repushing_keeps_existing_tags_and_adds_nothing_stale(experiment_dir, fake_api):
    first = push_experiment(experiment_dir, DATASET_REPO, api=fake_api)
    second = push_experiment(experiment_dir, DATASET_REPO, api=fake_api)

    repo = fake_api.repos[("dataset", DATASET_REPO)]
    assert repo.tags == first["dataset"], "create_tag(exist_ok=True) leaves existing tags in place"
    for name, oid in second["dataset"].items():
        assert tree_files(fake_api.root / oid) == tree_files(fake_api.root / first["dataset"][name])


def test_nothing_is_sent_for_a_directory_that_is_not_an_experiment(tmp_path, fake_api):
    with pytest.raises(UserError, match="not a lerobot-mtdagger experiment"):
        push_experiment(tmp_path / "missing", DATASET_REPO, api=fake_api)
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "config.json").write_text("{}")
    with pytest.raises(ValueError, match="no committed round"):
        push_experiment(tmp_path / "empty", DATASET_REPO, api=fake_api)
    assert fake_api.calls == []


@pytest.mark.parametrize(
    ("access", "message"),
    [
        ("no token", "No Hugging Face token"),
        ("offline", "Cannot reach the Hub"),
        ("offline (httpx)", "Cannot reach the Hub"),
    ],
)
def test_the_token_and_network_are_checked_before_anything_is_sent(experiment_dir, fake_api, access, message):
    fake_api.access = access
    with pytest.raises(UserError, match=message):
        push_experiment(experiment_dir, DATASET_REPO, POLICY_REPO, api=fake_api)
    assert fake_api.calls == ["whoami"] and not fake_api.repos


def test_push_without_a_token_is_one_error_line(experiment_dir, fake_api, monkeypatch, capsys):
    fake_api.access = "no token"
    monkeypatch.setattr(hub, "HfApi", lambda: fake_api)
    status = main(["push", f"--experiment_dir={experiment_dir}", f"--repo_id={DATASET_REPO}"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1
    assert err[0].startswith("lerobot-mtdagger push: error: No Hugging Face token: log in with")


def test_a_round_changed_after_commit_is_never_pushed(experiment_dir, fake_api, tmp_path):
    copy = tmp_path / "copy"
    shutil.copytree(experiment_dir, copy)
    parquet = next((copy / "rounds" / "round-001" / "data").rglob("*.parquet"))
    parquet.write_bytes(parquet.read_bytes()[:-100])
    with pytest.raises(CorruptExperimentError, match=f"{parquet} changed after commit"):
        push_experiment(copy, DATASET_REPO, api=fake_api)
    assert fake_api.calls == []


# -------------------------------------------------------------------------------------------------
# Dataset card
# -------------------------------------------------------------------------------------------------


def test_card_in_each_revision_covers_rounds_up_to_it(experiment_dir, fake_api):
    push_experiment(experiment_dir, DATASET_REPO, api=fake_api)
    card0 = (fake_api.snapshot(DATASET_REPO, "round-000") / "README.md").read_text()
    card1 = (fake_api.snapshot(DATASET_REPO, "round-001") / "README.md").read_text()

    assert "| task | round 0 | round 1 |" in card1
    assert "| toy-left | 3 | 3 |" in card1
    assert "| toy-right | 3 | 3 |" in card1
    assert "| task | round 0 |\n" in card0 and "round 1 |" not in card0
    assert f'LeRobotDataset("{DATASET_REPO}", revision="round-001")' in card1
    assert f'LeRobotDataset("{DATASET_REPO}", revision="round-000")' in card0


def test_rendered_card_has_metadata_tasks_and_eval(experiment_dir):
    from huggingface_hub import DatasetCard

    experiment = ExperimentDir(experiment_dir)
    text = render_dataset_card(experiment, DATASET_REPO)
    assert "{{" not in text
    data = DatasetCard(text).data.to_dict()
    assert data["license"] == "apache-2.0"
    assert data["task_categories"] == ["robotics"]
    assert data["tags"] == ["LeRobot", "mtdagger", "dagger", "multitask"]
    assert data["configs"] == [{"config_name": "default", "data_files": "data/*/*.parquet"}]
    assert "Suite: `toy`, observation mode `state`" in text
    assert "Scheduling method: `need`" in text
    assert "| 0 | toy-left |\n| 1 | toy-right |" in text
    assert "| 1 | `round-001` | 6 |" in text
    evals = [experiment.read_phase_record(k).eval for k in (0, 1)]
    assert "| **mean** | " + " | ".join(f"{e['mean']:.3f}" for e in evals) + " |" in text
    with pytest.raises(ValueError, match="Round 5 is not committed"):
        render_dataset_card(experiment, DATASET_REPO, up_to_round=5)


# -------------------------------------------------------------------------------------------------
# Command config
# -------------------------------------------------------------------------------------------------


def test_push_config_names_the_missing_option():
    with pytest.raises(ValueError, match="--experiment_dir is required"):
        PushConfig(repo_id=DATASET_REPO)
    with pytest.raises(ValueError, match="--repo_id is required"):
        PushConfig(experiment_dir=Path("outputs/mt10"))


def test_push_command_pushes_with_the_default_client(experiment_dir, fake_api, monkeypatch):
    monkeypatch.setattr(hub, "HfApi", lambda: fake_api)
    config = PushConfig(experiment_dir=experiment_dir, repo_id=DATASET_REPO, policy_repo_id=POLICY_REPO)
    pushed = push_command(config)
    assert list(pushed["dataset"]) == list(pushed["policy"]) == ["round-000", "round-001"]
    assert not fake_api.repos[("dataset", DATASET_REPO)].private


# -------------------------------------------------------------------------------------------------
# Looking a repo id up before loading it (utils/hub.py), against a local stand-in for the Hub's API
# -------------------------------------------------------------------------------------------------


class _HubStandIn(BaseHTTPRequestHandler):
    """Answers every request with the server's ``status`` (404: the Hub's "repository not found")."""

    def do_GET(self) -> None:  # noqa: N802 (http.server's name)
        body = b'{"error": "Repository Not Found"}'
        self.send_response(self.server.status)
        if self.server.status == 404:
            self.send_header("X-Error-Code", "RepoNotFound")
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args: object) -> None:
        del args


@pytest.fixture
def hub_answering(monkeypatch):
    """``hub_answering(status)``: points huggingface_hub at a local server answering ``status``."""
    import huggingface_hub.constants

    servers = []

    def start(status: int | None) -> None:
        if status is None:  # nothing listens: the connection is refused at once
            with socket.socket() as probe:
                probe.bind(("127.0.0.1", 0))
                port = probe.getsockname()[1]
        else:
            server = ThreadingHTTPServer(("127.0.0.1", 0), _HubStandIn)
            server.status = status
            threading.Thread(target=server.serve_forever, daemon=True).start()
            servers.append(server)
            port = server.server_address[1]
        monkeypatch.setattr(huggingface_hub.constants, "ENDPOINT", f"http://127.0.0.1:{port}")
        monkeypatch.setattr(huggingface_hub.constants, "HF_HUB_OFFLINE", False)

    yield start
    for server in servers:
        server.shutdown()


@pytest.mark.parametrize(
    ("status", "message"),
    [
        (404, "the Hub has no model repo of that id (or it is private or gated"),
        (500, "the Hub cannot be asked about a model repo of that id (HTTP 500)"),
        (None, "the Hub cannot be asked about a model repo of that id (Connect"),
    ],
    ids=["no such repo", "server error", "unreachable"],
)
def test_a_repo_id_the_hub_does_not_confirm_is_refused_in_one_line(hub_answering, status, message):
    hub_answering(status)
    start = time.perf_counter()
    with pytest.raises(UserError, match=re.escape(message)) as refused:
        check_hub_repo("nobody/not-a-policy", "model", "--policy_path", cached=False)
    assert str(refused.value).startswith("--policy_path=nobody/not-a-policy is not a local path")
    assert time.perf_counter() - start < 5  # one request, no retries


def test_a_cached_repo_is_read_when_the_hub_is_out_of_reach_but_not_when_it_is_gone(hub_answering, caplog):
    hub_answering(None)
    check_hub_repo("me/policy", "model", "--policy_path", cached=True)
    assert "reading the cached copy" in caplog.text
    hub_answering(404)
    with pytest.raises(UserError, match="the Hub has no model repo"):
        check_hub_repo("me/policy", "model", "--policy_path", cached=True)


def test_offline_only_the_cache_is_asked(monkeypatch, tmp_path):
    import huggingface_hub.constants

    monkeypatch.setattr(huggingface_hub.constants, "HF_HUB_OFFLINE", True)
    monkeypatch.setattr(huggingface_hub.constants, "HF_HUB_CACHE", str(tmp_path))
    with pytest.raises(UserError, match="not in the cache while HF_HUB_OFFLINE is set"):
        check_hub_repo("me/policy", "model", "--policy_path", cached=in_hub_cache("me/policy", "model"))
    (tmp_path / "models--me--policy" / "snapshots" / "0123abc").mkdir(parents=True)
    check_hub_repo("me/policy", "model", "--policy_path", cached=in_hub_cache("me/policy", "model"))


def test_lerobots_dataset_cache_follows_its_environment_variables(monkeypatch, tmp_path):
    monkeypatch.setenv("HF_LEROBOT_HOME", str(tmp_path / "home"))
    assert lerobot_dataset_cache("me/rollouts") == tmp_path / "home" / "me" / "rollouts"
    monkeypatch.delenv("HF_LEROBOT_HOME")
    import huggingface_hub.constants

    assert (
        lerobot_dataset_cache("me/rollouts")
        == Path(huggingface_hub.constants.HF_HOME) / "lerobot/me/rollouts"
    )


@pytest.mark.parametrize(
    ("text", "is_id"),
    [("me/policy", True), ("data/sesion1", True), ("policy", False), ("/abs/path", False), ("a/b/c", False)],
)
def test_a_hub_id_is_owner_slash_name(text, is_id):
    assert is_hub_id(text) is is_id


# -------------------------------------------------------------------------------------------------
# Opt-in: the real Hub
# -------------------------------------------------------------------------------------------------


@pytest.mark.skipif(
    not os.environ.get("MTDAGGER_HUB_TEST_REPO") or not os.environ.get("HF_TOKEN"),
    reason="pushes to the real Hub: set MTDAGGER_HUB_TEST_REPO=<user>/<dataset repo> and HF_TOKEN",
)
def test_live_push_to_the_hub(experiment_dir, tmp_path):
    from huggingface_hub import HfApi

    api = HfApi()
    repo_id = os.environ["MTDAGGER_HUB_TEST_REPO"]
    policy_repo_id = os.environ.get("MTDAGGER_HUB_TEST_POLICY_REPO")
    pushed = push_experiment(experiment_dir, repo_id, policy_repo_id, private=True, api=api)

    tags = {ref.name for ref in api.list_repo_refs(repo_id, repo_type="dataset").tags}
    assert {"round-000", "round-001"} <= tags
    for k in (0, 1):
        record = api.hf_hub_download(
            repo_id, "meta/mtdagger.json", repo_type="dataset", revision=f"round-{k:03d}", cache_dir=tmp_path
        )
        assert json.loads(Path(record).read_text())["round"] == k
    if policy_repo_id:
        model_tags = {ref.name for ref in api.list_repo_refs(policy_repo_id).tags}
        assert set(pushed["policy"]) <= model_tags
