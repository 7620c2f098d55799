"""Silencing the third-party console noise of LeRobot calls, narrowly and only around our calls.

While :func:`quiet_third_party` is active (all restored on exit):

- the ``datasets`` "Map" progress bars of ``save_episode`` are disabled (LeRobot's
  ``SuppressProgressBars`` re-enables them after every load, so a switch at start-up does not hold);
- LeRobot's "Using video codec" line and ``aggregate_datasets``' step messages are dropped by a
  :class:`logging.Filter` on the root logger (LeRobot 0.4) and on the named loggers (0.6);
- PyOpenGL's "No OpenGL_accelerate module loaded" INFO line: its logger is raised to WARNING;
- numpy's "Converting input from bool" ``RuntimeWarning`` (LeRobot 0.4's statistics of our bool
  ``learner_acted``) is ignored by message, category and module;
- the "Loading weights from local directory" print of ``from_pretrained`` is dropped from stdout.

Example::

    with quiet_third_party():
        dataset = LeRobotDataset(repo_id, root=root)
"""

from __future__ import annotations

import contextlib
import importlib
import logging
import sys
import warnings
from collections.abc import Iterable, Iterator, Mapping
from typing import Any, TextIO

logger = logging.getLogger(__name__)

AGGREGATE_MESSAGES = (
    "Start aggregate_datasets",
    "Find all tasks",
    "write tasks",
    "write info",
    "write stats",
    "Aggregation complete.",
)
"""The step messages of ``lerobot.datasets.aggregate.aggregate_datasets`` (``merge_rounds``)."""

CODEC_MESSAGES = ("Using video codec: ",)
"""What LeRobot logs on every dataset creation and load."""

ROOT_MESSAGES: dict[str, tuple[str, ...]] = {"video_utils": CODEC_MESSAGES, "aggregate": AGGREGATE_MESSAGES}
"""LeRobot 0.4's root-logger messages dropped while quiet: module (``LogRecord.module``) -> message starts."""

NAMED_MESSAGES: dict[str, tuple[str, ...]] = {
    "lerobot.configs.video": CODEC_MESSAGES,
    "lerobot.datasets.aggregate": AGGREGATE_MESSAGES,
}
"""LeRobot 0.6's named-logger messages dropped while quiet: logger name -> message starts."""

QUIETED_LOGGERS: dict[str, int] = {"OpenGL.acceleratesupport": logging.WARNING}
"""Named third-party loggers and the level they get while quiet."""

STDOUT_LINES: tuple[str, ...] = ("Loading weights from local directory",)
"""Whole lines that third-party code prints to stdout and that are dropped while quiet."""

IGNORED_WARNINGS: tuple[tuple[str, type[Warning], str], ...] = (
    (
        r"Converting input from bool to <class 'numpy\.uint8'> for compatibility\.",
        RuntimeWarning,
        r"lerobot\.datasets\.compute_stats",
    ),
)
"""(message regex, category, module regex) of the warnings ignored while quiet."""


class RootMessageFilter(logging.Filter):
    """Drops root-logger records of given modules whose message starts with given prefixes."""

    def __init__(self, messages: Mapping[str, Iterable[str]]) -> None:
        super().__init__()
        self.messages = {module: tuple(prefixes) for module, prefixes in messages.items()}

    def filter(self, record: logging.LogRecord) -> bool:
        """False (drop) for a matching record, True otherwise."""
        prefixes = self.messages.get(record.module) if record.name == "root" else None
        return not prefixes or not record.getMessage().startswith(prefixes)


class LineDroppingStream:
    r"""A text stream proxy that drops exact lines written by ``print`` and forwards everything else.

    ``print`` writes the text and the newline in two calls: a dropped line's newline is swallowed too.
    """

    def __init__(self, stream: TextIO, lines: Iterable[str]) -> None:
        """Wraps ``stream``; ``lines`` are the dropped lines, without their newline."""
        self.stream = stream
        self.lines = frozenset(lines)
        self._swallow_newline = False

    def write(self, text: str) -> int:
        """Forwards ``text`` unless it is (the rest of) a dropped line."""
        if self._swallow_newline:
            self._swallow_newline = False
            if text == "\n":
                return len(text)
        if text in self.lines:
            self._swallow_newline = True
            return len(text)
        if text.endswith("\n") and text[:-1] in self.lines:
            return len(text)
        return self.stream.write(text)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.stream, name)


@contextlib.contextmanager
def warnings_ignored(
    specs: Iterable[tuple[str, type[Warning], str]] = IGNORED_WARNINGS,
) -> Iterator[None]:
    """Ignores warnings given as (message regex, category, module regex) while active.

    The filters are restored on exit, except those other code added inside the block (a module imported
    there runs its import-time ``warnings.filterwarnings`` only once).
    """
    added: list[tuple] = []
    try:
        with warnings.catch_warnings():
            for message, category, module in specs:
                warnings.filterwarnings("ignore", message=message, category=category, module=module)
            ours = list(warnings.filters)
            try:
                yield
            finally:
                added = [item for item in warnings.filters if item not in ours]
    finally:
        for action, message, category, module, lineno in reversed(added):
            warnings.filterwarnings(
                action,
                message=message.pattern if message is not None else "",
                category=category,
                module=module.pattern if module is not None else "",
                lineno=lineno,
            )


@contextlib.contextmanager
def datasets_progress_bars_disabled() -> Iterator[None]:
    """Disables the ``datasets`` progress bars while active (unless ``HF_DATASETS_DISABLE_PROGRESS_BARS``)."""
    # The module: the attribute ``datasets.utils.tqdm`` is the tqdm class.
    hf_tqdm = importlib.import_module("datasets.utils.tqdm")
    forced = hf_tqdm.HF_DATASETS_DISABLE_PROGRESS_BARS
    was_disabled = hf_tqdm.are_progress_bars_disabled()
    if forced is None and not was_disabled:
        hf_tqdm.disable_progress_bars()
    try:
        yield
    finally:
        if forced is None and hf_tqdm.are_progress_bars_disabled() != was_disabled:
            if was_disabled:
                hf_tqdm.disable_progress_bars()
            else:
                hf_tqdm.enable_progress_bars()


class PrefixFilter(logging.Filter):
    """Drops every record whose message starts with one of given prefixes (for one named logger)."""

    def __init__(self, prefixes: Iterable[str]) -> None:
        super().__init__()
        self.prefixes = tuple(prefixes)

    def filter(self, record: logging.LogRecord) -> bool:
        """False (drop) for a matching record, True otherwise."""
        return not record.getMessage().startswith(self.prefixes)


@contextlib.contextmanager
def root_messages_filtered(
    messages: Mapping[str, Iterable[str]] = ROOT_MESSAGES,
    named: Mapping[str, Iterable[str]] = NAMED_MESSAGES,
) -> Iterator[RootMessageFilter]:
    """Drops LeRobot records while active: root ``messages`` by module, ``named`` by logger name."""
    root = logging.getLogger()
    message_filter = RootMessageFilter(messages)
    root.addFilter(message_filter)
    added = [(logging.getLogger(name), PrefixFilter(prefixes)) for name, prefixes in named.items()]
    for named_logger, prefix_filter in added:
        named_logger.addFilter(prefix_filter)
    try:
        yield message_filter
    finally:
        root.removeFilter(message_filter)
        for named_logger, prefix_filter in added:
            named_logger.removeFilter(prefix_filter)


@contextlib.contextmanager
def logger_levels(levels: dict[str, int]) -> Iterator[None]:
    """Raises (never lowers) the level of the named loggers while active, then restores them."""
    previous: dict[str, int] = {}
    for name, level in levels.items():
        named = logging.getLogger(name)
        if named.getEffectiveLevel() < level:
            previous[name] = named.level
            named.setLevel(level)
    try:
        yield
    finally:
        for name, level in previous.items():
            logging.getLogger(name).setLevel(level)


@contextlib.contextmanager
def stdout_lines_dropped(lines: Iterable[str] = STDOUT_LINES) -> Iterator[None]:
    """Drops the given whole lines from ``sys.stdout`` while active (everything else passes)."""
    original = sys.stdout
    if original is None:  # no stdout at all (pythonw): nothing to drop
        yield
        return
    proxy = LineDroppingStream(original, lines)
    sys.stdout = proxy
    try:
        yield
    finally:
        if sys.stdout is proxy:
            sys.stdout = original
        else:  # someone replaced stdout inside the block: leave theirs in place
            logger.debug("sys.stdout was replaced inside stdout_lines_dropped(); not restoring it")


@contextlib.contextmanager
def quiet_third_party() -> Iterator[None]:
    """Silences the known per-call noise of LeRobot, ``datasets``, numpy and PyOpenGL while active.

    Restored on exit, also when the block raises; nesting is fine. Like :func:`warnings.catch_warnings`,
    it changes process-wide state: other threads' matching noise is silenced too.
    """
    with contextlib.ExitStack() as stack:
        stack.enter_context(warnings_ignored())
        stack.enter_context(datasets_progress_bars_disabled())
        stack.enter_context(root_messages_filtered())
        stack.enter_context(logger_levels(QUIETED_LOGGERS))
        stack.enter_context(stdout_lines_dropped())
        yield
