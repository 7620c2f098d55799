"""Command-line options into configs, with one clear message per mistake.

draccus reads every value as YAML and parses with argparse; a bad value surfaces as a YAML traceback
that does not name the option, an unknown option as argparse's usage block and a ``SystemExit``, and
a config's own check as a ``ParsingError`` hiding it. ``parse_options`` turns each into a
``UserError`` naming the option and the fix.
"""

from __future__ import annotations

import contextlib
import io
from collections.abc import Sequence
from typing import TypeVar

import draccus
import yaml

from lerobot_mtdagger.utils.errors import UserError

T = TypeVar("T")


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


def parse_options(config_class: type[T], options: Sequence[str], prog: str) -> T:
    """Parses command-line options into a config, every failure a ``UserError``.

    Raises:
        UserError: Naming the option at fault (draccus' own message, or the config's check).
        SystemExit: With status 0 after ``--help``.
    """
    unparsable = unparsable_option(options)
    if unparsable is not None:
        raise UserError(unparsable)
    argparse_output = io.StringIO()
    try:
        with contextlib.redirect_stderr(argparse_output):
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
