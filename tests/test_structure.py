"""The package's structure: no import cycle anywhere, every module importable alone, envs free of experts."""

from __future__ import annotations

import ast
import functools
import pkgutil
import re
import subprocess
import sys
from pathlib import Path

import pytest

import lerobot_mtdagger

PACKAGE_ROOT = Path(lerobot_mtdagger.__file__).parent
# Third-party packages the modules import; loaded once in the parent so that each forked child
# imports only our module (and the parts of our package it needs) from scratch.
THIRD_PARTY = [
    "numpy",
    "torch",
    "gymnasium",
    "mujoco",
    "metaworld",
    "draccus",
    "datasets",
    "lerobot.policies.factory",
]


@functools.cache
def package_modules() -> list[str]:
    """Every module of the package, by dotted name."""
    names = ["lerobot_mtdagger"]
    for info in pkgutil.walk_packages([str(PACKAGE_ROOT)], prefix="lerobot_mtdagger."):
        names.append(info.name)
    return sorted(names)


def module_path(name: str) -> Path:
    relative = Path(*name.split(".")[1:])
    package = PACKAGE_ROOT / relative / "__init__.py"
    return package if package.exists() else (PACKAGE_ROOT / relative).with_suffix(".py")


def module_level_imports(name: str) -> set[str]:
    """Our modules imported at module level by ``name`` (function bodies are not module level)."""
    return imports_of(name, everywhere=False)


def _is_type_checking_block(node: ast.AST) -> bool:
    return isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING"


def _run_time_nodes(tree: ast.Module) -> list[ast.AST]:
    """Every node but those under ``if TYPE_CHECKING:`` (imports for the type checker, never run)."""
    nodes: list[ast.AST] = []
    pending: list[ast.AST] = [tree]
    while pending:
        node = pending.pop()
        nodes.append(node)
        pending.extend(child for child in ast.iter_child_nodes(node) if not _is_type_checking_block(child))
    return nodes


def type_checking_imports(name: str) -> set[str]:
    """Our modules ``name`` imports for the type checker only (under ``if TYPE_CHECKING:``)."""
    tree = ast.parse(module_path(name).read_text())
    blocks = [node for node in tree.body if _is_type_checking_block(node)]
    modules = {
        node.module for block in blocks for node in ast.walk(block) if isinstance(node, ast.ImportFrom)
    }
    return {module for module in modules if module and module.startswith("lerobot_mtdagger")}


def imports_of(name: str, everywhere: bool = True) -> set[str]:
    """Our modules imported at run time by ``name``: anywhere in it, or at module level only."""
    tree = ast.parse(module_path(name).read_text())
    imported: set[str] = set()
    is_package = module_path(name).name == "__init__.py"
    for node in _run_time_nodes(tree) if everywhere else tree.body:
        targets = []
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = name.split(".")
                parent = parts if is_package else parts[:-1]
                base = ".".join(parent[: len(parent) - node.level + 1] + ([base] if base else []))
            targets = [base] + [f"{base}.{alias.name}" for alias in node.names]
        imported |= {t for t in targets if t.startswith("lerobot_mtdagger")}
    modules = set(package_modules())
    return {t for t in imported if t in modules and t != name}


@pytest.mark.parametrize("everywhere", [False, True], ids=["module-level", "function-level-too"])
def test_imports_have_no_cycle(everywhere):
    """Not even through an import inside a function: such a cycle still couples the modules."""
    graph = {name: imports_of(name, everywhere) for name in package_modules()}
    # A package's __init__ imported by its own submodules is not a cycle we can avoid: Python imports
    # the parent package first; cycles between distinct modules are what break.
    for name, targets in graph.items():
        targets -= {p for p in targets if name.startswith(p + ".")}
    visiting, done, cycles = set(), set(), []

    def visit(node: str, path: list[str]) -> None:
        visiting.add(node)
        for target in sorted(graph[node]):
            if target in visiting:
                cycles.append(path[path.index(target) :] + [target])
            elif target not in done:
                visit(target, [*path, target])
        visiting.discard(node)
        done.add(node)

    for name in sorted(graph):
        if name not in done:
            visit(name, [name])
    assert cycles == [], cycles


def test_envs_never_import_experts_at_module_level():
    envs = [name for name in package_modules() if name.startswith("lerobot_mtdagger.envs")]
    offending = {name: sorted(t for t in module_level_imports(name) if ".experts" in t) for name in envs}
    assert {k: v for k, v in offending.items() if v} == {}


@pytest.mark.parametrize("module", ["variants", "catalogue"])
def test_drawer_variants_and_catalogue_do_not_import_a_simulator(module):
    tree = ast.parse(module_path(f"lerobot_mtdagger.envs.drawers.{module}").read_text())
    roots = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            roots |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            roots.add(node.module.split(".")[0])
    assert not roots & {"mujoco", "metaworld", "gymnasium"}, roots


IMPORT_EACH_ALONE = """
import importlib, os, sys, traceback
for third_party in sys.argv[1].split(","):
    importlib.import_module(third_party)
assert not any(m.startswith("lerobot_mtdagger") for m in sys.modules), "imported ours too early"
failed = 0
for name in sys.argv[2:]:
    pid = os.fork()
    if pid == 0:  # the child imports one module first, with none of ours loaded
        try:
            importlib.import_module(name)
        except BaseException:
            print(f"FAILED {name}:", traceback.format_exc(limit=4), flush=True)
            os._exit(1)
        os._exit(0)
    _, status = os.waitpid(pid, 0)
    failed += status != 0
print(f"{failed} failed")
"""


@pytest.mark.skipif(sys.platform != "linux", reason="forks a child per module")
def test_every_module_imports_alone_in_a_fresh_process():
    """A fresh interpreter loads the third-party packages, then forks one child per module of ours,
    which imports that module first (so an import-order cycle fails there)."""
    modules = package_modules()
    result = subprocess.run(
        [sys.executable, "-c", IMPORT_EACH_ALONE, ",".join(THIRD_PARTY), *modules],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert result.returncode == 0 and result.stdout.strip().endswith("0 failed"), (
        result.stdout + result.stderr
    )
    assert {"lerobot_mtdagger.envs.drawers.variants", "lerobot_mtdagger.experts.drawers"} <= set(modules)


WIDE_FUNCTIONS: set[str] = set()
"""Functions allowed more than MAX_PARAMETERS: none (their options belong in a dataclass)."""

MAX_PARAMETERS = 8


def parameter_counts() -> dict[str, int]:
    """Parameters of every function of the package (``self``/``cls`` not counted), by ``module.name``."""
    counts = {}
    for name in package_modules():
        short = name.removeprefix("lerobot_mtdagger").lstrip(".") or "__init__"
        for node in ast.walk(ast.parse(module_path(name).read_text())):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                args = node.args
                named = [*args.posonlyargs, *args.args, *args.kwonlyargs]
                count = len(named) + (args.vararg is not None) + (args.kwarg is not None)
                if named and named[0].arg in ("self", "cls"):
                    count -= 1
                counts[f"{short}.{node.name}"] = max(count, counts.get(f"{short}.{node.name}", 0))
    return counts


def test_no_function_takes_more_than_eight_parameters():
    wide = {name for name, count in parameter_counts().items() if count > MAX_PARAMETERS}
    assert wide == WIDE_FUNCTIONS, "fold options into a dataclass"


MAX_RUNNER_FILE_LINES = 450
"""A room of ``runner/`` does one job; past this it is doing several (split it by what it does)."""

MAX_TRAIN_PHASE_LINES = 60


def test_every_room_of_the_runner_is_small():
    runner = [name for name in package_modules() if name.startswith("lerobot_mtdagger.runner.")]
    lines = {name: len(module_path(name).read_text().splitlines()) for name in runner}
    assert {name: n for name, n in lines.items() if n > MAX_RUNNER_FILE_LINES} == {}
    assert len(runner) >= 20  # the rooms exist (a rename would otherwise pass this test vacuously)


def test_a_training_phase_reads_in_one_screen():
    """``steps.train_phase`` measures, hands the steps to ``StepLoop`` and records: one screen."""
    tree = ast.parse(module_path("lerobot_mtdagger.runner.training.steps").read_text())
    (train_phase,) = [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "train_phase"]
    assert train_phase.end_lineno - train_phase.lineno + 1 <= MAX_TRAIN_PHASE_LINES


def test_the_dagger_loop_hands_each_training_phase_to_train():
    """``dagger.train_round`` is short and takes at most four names from ``train``."""
    tree = ast.parse(module_path("lerobot_mtdagger.runner.dagger").read_text())
    from_train = [
        alias.name
        for node in tree.body
        if isinstance(node, ast.ImportFrom) and node.module == "lerobot_mtdagger.runner.training.train"
        for alias in node.names
    ]
    assert len(from_train) <= 4, from_train
    (train_round,) = [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "train_round"]
    assert train_round.end_lineno - train_round.lineno + 1 <= 30


def test_verify_loads_policies_without_the_rollout_stack():
    """``verify`` checks rounds and loads policies; it never imports env workers or rollouts."""
    seen, todo = set(), ["lerobot_mtdagger.datasets.verify"]
    while todo:
        name = todo.pop()
        if name not in seen:
            seen.add(name)
            todo.extend(imports_of(name))
    assert not seen & {
        "lerobot_mtdagger.runner.rollout.workers",
        "lerobot_mtdagger.runner.rollout.collect",
        "lerobot_mtdagger.runner.rollout.evaluate",
    }


RUNNER = "lerobot_mtdagger.runner"
RUNNER_ROOMS = {f"{RUNNER}.rollout": 1, f"{RUNNER}.training": 2}
"""The runner's sub-wings, below its root (the loop, its configs, the ``Student`` contract): training
may use rollout (the previous phase's ``PolicyRunner``), rollout never uses training."""

LOOP_MODULES = {f"{RUNNER}.dagger", f"{RUNNER}.run_setup"}


def runner_room(name: str) -> str | None:
    """The runner sub-wing a module belongs to (None: the runner's root or outside the runner)."""
    return next((room for room in RUNNER_ROOMS if name == room or name.startswith(room + ".")), None)


def runner_room_violations(graph: dict[str, set[str]]) -> list[str]:
    """Imports from a runner sub-wing up to the loop, or to a sub-wing of a higher rank."""
    wrong = []
    for name, targets in graph.items():
        source = runner_room(name)
        if source is None:
            continue
        for target in sorted(targets):
            destination = runner_room(target)
            upward = destination is not None and RUNNER_ROOMS[destination] > RUNNER_ROOMS[source]
            if target in LOOP_MODULES or upward:
                wrong.append(f"{name} -> {target}")
    return wrong


def test_the_runner_s_rooms_rank_below_the_loop():
    """Function-level imports included: rollout and training never import the loop, rollout never training."""
    graph = {name: imports_of(name) for name in package_modules()}
    assert runner_room_violations(graph) == []
    assert len([name for name in graph if runner_room(name)]) >= 18  # the rooms exist
    assert runner_room_violations({f"{RUNNER}.rollout.collect": {f"{RUNNER}.training.steps"}}) != []
    assert runner_room_violations({f"{RUNNER}.training.train": {f"{RUNNER}.dagger"}}) != []


WING_RANKS = {
    "lerobot_mtdagger.cli": 7,
    "lerobot_mtdagger.commands": 7,
    "lerobot_mtdagger.analysis": 6,
    "lerobot_mtdagger.planning": 6,
    "lerobot_mtdagger.students": 5,
    "lerobot_mtdagger.runner": 4,
    "lerobot_mtdagger.envs": 3,
    "lerobot_mtdagger.experts": 3,
    "lerobot_mtdagger.datasets": 2,
    "lerobot_mtdagger.policies": 2,
    "lerobot_mtdagger.scheduler": 1,
    "lerobot_mtdagger.learning_curve": 1,
    "lerobot_mtdagger.utils": 0,
}
"""Imports run one way: cli and commands -> analysis -> students -> runner -> envs and experts -> datasets
and policies -> scheduler -> utils (the runner finds a student by name, ``runner.student``). Within a
rank, cli may use commands, experts may use envs, datasets may use policies and the scheduler its
learning curves (not the reverse)."""

SAME_RANK_ALLOWED = {
    ("lerobot_mtdagger.cli", "lerobot_mtdagger.commands"),
    ("lerobot_mtdagger.experts", "lerobot_mtdagger.envs"),
    ("lerobot_mtdagger.datasets", "lerobot_mtdagger.policies"),
    ("lerobot_mtdagger.scheduler", "lerobot_mtdagger.learning_curve"),
}


def wing(name: str) -> str | None:
    """The wing a module belongs to (None: the package itself or a loose module)."""
    return next((w for w in WING_RANKS if name == w or name.startswith(w + ".")), None)


def test_every_module_sits_in_a_wing():
    data_only = ("lerobot_mtdagger", "lerobot_mtdagger.datasets_cards")  # the package, the card template
    loose = [n for n in package_modules() if wing(n) is None and n not in data_only]
    assert loose == [], f"modules outside the wings {sorted(WING_RANKS)}: {loose}"


def test_imports_run_one_way_between_wings():
    """Function-level imports included: no import from a lower wing to a higher one."""
    wrong = []
    for name in package_modules():
        source = wing(name)
        for target in imports_of(name):
            destination = wing(target)
            if source is None or destination is None or source == destination:
                continue
            higher = WING_RANKS[destination] > WING_RANKS[source]
            sideways = (
                WING_RANKS[destination] == WING_RANKS[source]
                and (source, destination) not in SAME_RANK_ALLOWED
            )
            if higher or sideways:
                wrong.append(f"{name} -> {target}")
    assert wrong == [], wrong


MAX_CLI_LINES = 150
"""``cli.py`` parses the command line and dispatches; the commands live in ``commands/``."""

COMMANDS_WING = "lerobot_mtdagger.commands"
CONFIGS_PACKAGE = f"{COMMANDS_WING}.configs"
"""Each command's options, one module per command (imports neither torch nor LeRobot: ``test_cli.py``)."""

SHARED_CONFIGS = {
    "run": "lerobot_mtdagger.runner.configs",
    "compare": "lerobot_mtdagger.analysis.compare",
    "push": "lerobot_mtdagger.datasets.push_config",
    "plan": "lerobot_mtdagger.planning.plan",
}
"""Commands whose config a lower wing reads too: it is defined there, and the command's config module
names it."""

NOT_COMMANDS = {f"{COMMANDS_WING}.console", CONFIGS_PACKAGE}
"""Modules of the commands wing that are no command's body: the console helpers, the options package."""


def command_parts() -> dict[str, tuple[type, object]]:
    """Each command of ``cli.COMMANDS`` with its config class and body function, resolved."""
    from lerobot_mtdagger.cli import COMMANDS, command_part

    return {name: (command_part(config), command_part(body)) for name, (config, body) in COMMANDS.items()}


def test_cli_names_one_options_module_and_one_body_module_per_command():
    """``cli.COMMANDS`` names ``configs/<command>.py``'s dataclass and ``<command>.py``'s function."""
    import dataclasses

    from lerobot_mtdagger.cli import COMMANDS

    assert len(module_path("lerobot_mtdagger.cli").read_text().splitlines()) <= MAX_CLI_LINES
    for name, (config_class, function) in command_parts().items():
        config_module, body_module = (f"{COMMANDS_WING}.{spec.partition(':')[0]}" for spec in COMMANDS[name])
        assert (config_module, body_module) == (f"{CONFIGS_PACKAGE}.{name}", f"{COMMANDS_WING}.{name}"), name
        assert dataclasses.is_dataclass(config_class), (name, config_class)
        assert config_class.__module__ == SHARED_CONFIGS.get(name, config_module), name
        assert vars(sys.modules[config_module]).get(config_class.__name__) is config_class, name
        assert callable(function) and function.__module__ == body_module, (name, function)
    bodies = submodules(COMMANDS_WING) - {m.rpartition(".")[2] for m in NOT_COMMANDS}
    assert submodules(CONFIGS_PACKAGE) == set(COMMANDS) == bodies, (submodules(CONFIGS_PACKAGE), bodies)


def submodules(package: str) -> set[str]:
    """The names of the modules and packages directly in ``package``."""
    prefix = package + "."
    return {
        m.removeprefix(prefix)
        for m in package_modules()
        if m.startswith(prefix) and "." not in m[len(prefix) :]
    }


def function_level_imports(name: str) -> list[str]:
    """The import statements inside the functions of module ``name``, as ``line N``."""
    tree = ast.parse(module_path(name).read_text())
    functions = [node for node in ast.walk(tree) if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)]
    return sorted(
        {
            f"line {node.lineno}"
            for function in functions
            for node in ast.walk(function)
            if isinstance(node, ast.Import | ast.ImportFrom)
        }
    )


def test_command_bodies_import_what_they_use_at_their_top():
    """The CLI imports a body only after its options parsed, so a body hides no import in a function."""
    from lerobot_mtdagger.cli import COMMANDS

    hidden = {name: function_level_imports(f"{COMMANDS_WING}.{name}") for name in COMMANDS}
    assert {name: found for name, found in hidden.items() if found} == {}


WORKER_FIELDS = {"workers", "worker_backend"}
"""The env worker options, defined once (``option_groups.WorkerOptions``)."""


def option_groups(config_class: type) -> list[type]:
    """``config_class`` and every dataclass among its fields' types, recursively."""
    import dataclasses
    import typing

    groups, pending = [], [config_class]
    while pending:
        group = pending.pop()
        if group in groups:
            continue
        groups.append(group)
        hints = typing.get_type_hints(group)
        pending += [hints[f.name] for f in dataclasses.fields(group) if isinstance(hints[f.name], type)]
        pending = [candidate for candidate in pending if dataclasses.is_dataclass(candidate)]
    return groups


def test_every_command_takes_its_worker_options_from_one_group():
    """A command's option group with env worker options inherits them from ``WorkerOptions``."""
    import dataclasses

    from lerobot_mtdagger.runner.option_groups import WorkerOptions

    own, with_workers = [], []
    for name, (config_class, _) in command_parts().items():
        for group in option_groups(config_class):
            fields = {field.name for field in dataclasses.fields(group)} & WORKER_FIELDS
            if fields:
                with_workers.append(name)
                if not issubclass(group, WorkerOptions):
                    own.append(f"{name}: {group.__qualname__} {sorted(fields)}")
    assert own == [], own
    assert {"run", "eval", "shift"} <= set(with_workers), with_workers  # compare passes run's on


STUDENT_CLASSES = {"MTDAggerPolicy", "MTDAggerConfig", "PolicyOptions"}
"""Classes of one student: the runner asks the student (``runner/student.py``) instead of testing for them."""

STUDENTS_WING = "lerobot_mtdagger.students"
"""The student implementations: the only modules that may test a value for a student's class."""

STUDENT_MODULES = {name for name in package_modules() if name.startswith(STUDENTS_WING + ".")}


def student_type_forks(source: str) -> list[int]:
    """Lines of ``isinstance(value, C)`` in ``source`` where ``C`` names a class of ``STUDENT_CLASSES``."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "isinstance":
            names = {
                getattr(part, "id", getattr(part, "attr", None))
                for argument in node.args[1:]
                for part in ast.walk(argument)
            }
            if names & STUDENT_CLASSES:
                lines.append(node.lineno)
    return lines


def test_only_the_students_fork_on_a_student_type():
    """Everywhere else the runner asks the run's ``Student`` (``get_student``, ``student_of_policy``)."""
    forks = {
        name: student_type_forks(module_path(name).read_text())
        for name in package_modules()
        if name not in STUDENT_MODULES
    }
    assert {name: lines for name, lines in forks.items() if lines} == {}
    reaching_in = [  # a LeRobot policy's internals (Diffusion's denoiser) are its student's business
        name
        for name in package_modules()
        if name not in STUDENT_MODULES and ".generate_actions(" in module_path(name).read_text()
    ]
    assert reaching_in == []
    assert student_type_forks("isinstance(policy, (int, MTDAggerPolicy))") == [1]
    assert student_type_forks("isinstance(options, policy_options.PolicyOptions)") == [1]


def runner_imports_of_students(graph: dict[str, set[str]]) -> list[str]:
    """Module-level imports of the students' wing by the runner's modules."""
    return [
        f"{name} -> {target}"
        for name, targets in graph.items()
        if name == RUNNER or name.startswith(RUNNER + ".")
        for target in sorted(targets)
        if target == STUDENTS_WING or target.startswith(STUDENTS_WING + ".")
    ]


def test_the_runner_finds_students_by_name_only():
    """The runner imports no student module at module level: ``runner.student``'s registry names them."""
    graph = {name: module_level_imports(name) for name in package_modules()}
    assert runner_imports_of_students(graph) == []
    assert runner_imports_of_students({f"{RUNNER}.dagger": {f"{STUDENTS_WING}.mtdagger"}}) != []


def student_classes(sources: dict[str, str]) -> dict[str, str]:
    """Class name -> module of every class that derives from ``Student`` (through any of ours)."""
    bases: dict[str, tuple[str, set[str]]] = {}
    for module, source in sources.items():
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, ast.ClassDef):
                plain = [base.value if isinstance(base, ast.Subscript) else base for base in node.bases]
                names = {getattr(base, "id", getattr(base, "attr", None)) for base in plain}
                bases[node.name] = (module, names)
    students = {"Student"}
    while True:
        more = {name for name, (_, names) in bases.items() if names & students} - students
        if not more:
            break
        students |= more
    return {name: bases[name][0] for name in students - {"Student"}}


def test_every_student_lives_in_the_students_wing():
    """Adding a student touches ``students/`` only: every ``Student`` subclass of the package is there."""
    sources = {name: module_path(name).read_text() for name in package_modules()}
    found = student_classes(sources)
    assert {"MTDAggerStudent", "LeRobotStudent", "DiffusionStudent"} <= set(found)
    elsewhere = {name: module for name, module in found.items() if not module.startswith(STUDENTS_WING)}
    assert elsewhere == {}
    stray = student_classes({**sources, f"{RUNNER}.dagger": "class Mine(LeRobotStudent): ..."})
    assert stray["Mine"] == f"{RUNNER}.dagger"


MIGRATIONS_MODULE = "lerobot_mtdagger.datasets.migrations"
"""The one module that keeps the rules about runs stored by earlier versions (``MIGRATIONS``)."""

OLDER_RUN_PHRASE = re.compile(r"(made|stored) before|before \d{4}-\d{2}-\d{2}")
"""How a user-facing message about an older run reads ("a run made before ...")."""


def older_run_messages(source: str) -> list[int]:
    """Lines of string literals (docstrings aside) in ``source`` that speak of older runs."""
    tree = ast.parse(source)
    docstrings = {
        id(body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
        and (body := node.body)
        and isinstance(body[0], ast.Expr)
        and isinstance(body[0].value, ast.Constant)
    }
    return [
        node.lineno
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant)
        and isinstance(node.value, str)
        and id(node) not in docstrings
        and OLDER_RUN_PHRASE.search(node.value)
    ]


def test_the_rules_about_older_runs_live_in_the_migrations():
    """Hints and rewrites for runs of earlier versions are migrations, not scattered conditions."""
    messages = {
        name: older_run_messages(module_path(name).read_text())
        for name in package_modules()
        if name != MIGRATIONS_MODULE
    }
    assert {name: lines for name, lines in messages.items() if lines} == {}
    assert older_run_messages(module_path(MIGRATIONS_MODULE).read_text())  # the hints are there
    assert older_run_messages('x = f" (a run made before {date})"') == [1]
    assert older_run_messages('def f():\n    """A config stored before the groups."""\n') == []


def untyped_contract_annotations(source: str, class_name: str) -> list[str]:
    """``method: annotation`` of ``class_name``'s parameters and returns that are ``Any`` or unannotated."""
    tree = ast.parse(source)
    klass = next(node for node in tree.body if isinstance(node, ast.ClassDef) and node.name == class_name)
    loose = []
    for method in (node for node in klass.body if isinstance(node, ast.FunctionDef)):
        arguments = [a for a in method.args.args if a.arg not in ("self", "cls")]
        for label, annotation in [(a.arg, a.annotation) for a in arguments] + [("return", method.returns)]:
            text = "" if annotation is None else ast.unparse(annotation)
            if text in ("", "Any", "object") or text.startswith("tuple[Any"):
                loose.append(f"{method.name}.{label}: {text or 'unannotated'}")
    return loose


def test_the_student_contract_names_its_types():
    """``Student`` takes and returns LeRobot's and the runner's named types (mypy checks them in CI)."""
    source = module_path(f"{RUNNER}.student").read_text()
    assert untyped_contract_annotations(source, "Student") == []
    assert untyped_contract_annotations(source, "TrainingOps") == []
    loose = "class Student:\n    def phase_ops(self, policy: Any, data) -> Any: ...\n"
    assert untyped_contract_annotations(loose, "Student") == [
        "phase_ops.policy: Any",
        "phase_ops.data: unannotated",
        "phase_ops.return: Any",
    ]


def test_type_only_imports_leave_the_run_time_graph():
    """``runner.student`` names the runner's types for mypy only: at run time it imports none of them."""
    student = f"{RUNNER}.student"
    assert f"{RUNNER}.training.steps" in type_checking_imports(student)
    assert f"{RUNNER}.training.steps" not in imports_of(student)
