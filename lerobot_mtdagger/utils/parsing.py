"""Command-line options into configs, with one clear message per mistake.

draccus surfaces a bad value as a YAML traceback, an unknown option as argparse's usage block and a
config's own check as a ``ParsingError``; ``parse_options`` turns each into a ``UserError`` naming
the option and the fix. ``cache_dataclass_sources`` makes draccus read each class's source once per
process instead of once per field (2-3 s for every parse of ``RunConfig`` on Python 3.11).
"""

from __future__ import annotations

import contextlib
import functools
import inspect
import io
import threading
import types
from collections.abc import Sequence
from pathlib import Path
from typing import Any, TypeVar, cast

import draccus
import yaml
from draccus.wrappers import docstring as draccus_docstring

from lerobot_mtdagger.utils.errors import UserError

T = TypeVar("T")

PARSING = threading.RLock()
"""One parse at a time per process (a parse swaps ``sys.stderr``); reentrant within a thread."""


@functools.cache
def _class_source(cls: type) -> str | OSError | TypeError:
    """The source of ``cls``, or the error ``inspect.getsource`` raised for it, found once.

    A class made by ``dataclasses.make_dataclass`` has no source; finding that out parses a module too.
    """
    try:
        return inspect.getsource(cls)
    except (OSError, TypeError) as error:
        return error


class _InspectWithClassSourceCache:
    """The ``inspect`` module as draccus' docstring reader sees it, with class sources cached."""

    def getsource(self, obj: Any) -> str:
        """``inspect.getsource``, cached for classes (raising its ``OSError`` or ``TypeError`` alike)."""
        if not isinstance(obj, type):
            return inspect.getsource(obj)
        source = _class_source(obj)
        if isinstance(source, Exception):
            raise type(source)(*source.args)
        return source

    def __getattr__(self, name: str) -> object:
        return getattr(inspect, name)


def cache_dataclass_sources() -> None:
    """Makes draccus read each config class's source once per process, not once per field."""
    # not a module, but it answers every name of ``inspect`` that draccus reads
    draccus_docstring.inspect = cast(types.ModuleType, _InspectWithClassSourceCache())


def unparsable_option(options: Sequence[str]) -> str | None:
    """A message naming the first option whose value is not valid YAML (draccus reads values as YAML)."""
    for option in options:
        name, separator, value = option.partition("=")
        if not separator:
            continue
        try:
            yaml.safe_load(value)
        except yaml.YAMLError as error:
            problem = getattr(error, "problem", None) or type(error).__name__
            return (
                f"{name}={value!r} is not a valid value ({problem}); lists are written "
                f"{name}='[a,b]', strings with special characters are quoted."
            )
    return None


def missing_config_file(options: Sequence[str]) -> None:
    """Refuses a ``--config_path`` that is not a readable file, with a ``UserError`` naming it and the fix."""
    for option in options:
        name, separator, value = option.partition("=")
        if name == "--config_path" and separator and not Path(value).is_file():
            raise UserError(
                f"--config_path={value} is not a file: give a YAML or JSON config file, or drop the option."
            )


def command_help(config_class: type, options: Sequence[str], prog: str) -> str:
    """The ``--help`` page of a command, with a config's ``help_choices`` and ``HELP_FOOTER``."""
    from lerobot_mtdagger.utils.help import option_lines, render_help, summary_of

    chooser = getattr(config_class, "help_choices", None)
    choices = chooser(options) if chooser is not None else None
    lines = list(option_lines(config_class, options, choices=choices))
    return render_help(prog, summary_of(config_class), lines, getattr(config_class, "HELP_FOOTER", ""))


def parse_options(config_class: type[T], options: Sequence[str], prog: str) -> T:
    """Parses command-line options into a config, every failure a ``UserError`` naming the option at fault.

    Raises:
        SystemExit: With status 0 after ``--help``.
    """
    if "--help" in options or "-h" in options:
        print(command_help(config_class, options, prog))
        raise SystemExit(0)
    unparsable = unparsable_option(options)
    if unparsable is not None:
        raise UserError(unparsable)
    missing_config_file(options)
    cache_dataclass_sources()
    argparse_output = io.StringIO()
    # a config may narrow what its parser offers for these options (RunConfig: no LeRobot student
    # unless one may be named), so that --help and refusals import no heavy library
    narrowing = getattr(config_class, "parsing_context", None)
    try:
        with (
            PARSING,
            contextlib.redirect_stderr(argparse_output),
            narrowing(options) if narrowing is not None else contextlib.nullcontext(),
        ):
            return draccus.parse(config_class=config_class, args=list(options), prog=prog)
    except draccus.utils.ParsingError as error:
        # draccus hides the config's own ValueError (which names the field and the fix) as the cause.
        cause = error.__cause__ if error.__cause__ is not None else error
        raise UserError(str(cause)) from error
    except SystemExit as exit_:
        if exit_.code in (0, None):
            raise
        # argparse printed its usage and "<prog>: error: <message>"; keep the message only.
        message = argparse_output.getvalue().strip().splitlines()[-1].partition("error: ")[2]
        raise UserError(f"{message}; the options are listed by `{prog} --help`.") from None
