"""``--help`` for every command: its own options, one line each, from the configs' docstrings.

Each option shows as ``--group.name=TYPE``, the first sentence of its entry in its class's
``Attributes:`` (or ``Args:``) section, and its default. A choice group (``--scheduler.type``,
``--policy.type``) lists its choices, then the options of the chosen one (or the default).
"""

from __future__ import annotations

import dataclasses
import inspect
import re
import sys
import textwrap
from collections.abc import Callable, Iterator, Sequence
from typing import Any

SECTION = re.compile(r"^(Attributes|Args):\s*$")
ENTRY = re.compile(r"^(\w+)(?: \([^)]*\))?:\s*(.*)$")
HELP_WIDTH = 110
NAME_WIDTH = 38


def attribute_docs(cls: type) -> dict[str, str]:
    """Each documented attribute's text (continuation lines joined) from a class's Google docstring."""
    docs: dict[str, str] = {}
    for klass in reversed(cls.__mro__):
        lines = (inspect.getdoc(klass) or "").splitlines() if klass.__dict__.get("__doc__") else []
        docs.update(_section_entries(lines))
    return docs


def _section_entries(lines: Sequence[str]) -> dict[str, str]:
    """The ``name: text`` entries of the ``Attributes:``/``Args:`` sections of docstring lines."""
    entries: dict[str, str] = {}
    inside, indent, current = False, None, None
    for line in lines:
        if SECTION.match(line):
            inside, indent, current = True, None, None
            continue
        if not inside:
            continue
        if line.strip() and not line.startswith(" "):
            inside = False  # the next section or paragraph
            continue
        stripped = line.strip()
        depth = len(line) - len(line.lstrip())
        match = ENTRY.match(stripped)
        if match and (indent is None or depth == indent):
            indent, current = depth, match.group(1)
            entries[current] = match.group(2)
        elif current is not None and stripped:
            entries[current] += " " + stripped
    return entries


ABBREVIATIONS = ("e.g", "i.e", "etc", "vs", "cf")


def first_sentence(text: str) -> str:
    """The text up to its first full stop (abbreviations kept, Markdown backticks simplified)."""
    text = " ".join(text.replace("``", "`").split())
    for match in re.finditer(r"\.(\s|$)", text):
        word = text[: match.start()].rsplit(" ", 1)[-1].lstrip("(`")
        if word.lower() not in ABBREVIATIONS:
            return text[: match.start() + 1]
    return text


def option_lines(
    cls: type,
    options: Sequence[str],
    prefix: str = "",
    choices: Callable[[type], dict[str, type | None] | None] | None = None,
) -> Iterator[tuple[str, str]]:
    """``(--option=TYPE, help)`` for every option of the dataclass ``cls``, groups flattened.

    Args:
        cls: The config dataclass.
        options: The command line (which choice of a group to describe).
        prefix: The group's dotted path.
        choices: ``group class -> {choice name: class or None}`` for choices costly to import (None:
            not described); default ``get_known_choices``.
    """
    docs = attribute_docs(cls)
    for field in dataclasses.fields(cls):
        if not field.init or field.name.startswith("_"):
            continue
        path = f"{prefix}{field.name}"
        default = _default(field)
        help_text = first_sentence(docs.get(field.name, ""))
        if dataclasses.is_dataclass(default) and not isinstance(default, type):
            yield from _group_lines(cls, field, default, path, help_text, options, choices)
            continue
        shown = "" if default is dataclasses.MISSING else f" (default: {_shown(default)})"
        yield f"--{path}={_type_name(field)}", f"{help_text}{shown}".strip()


def _group_lines(
    owner: type,
    field: dataclasses.Field,
    default: Any,
    path: str,
    help_text: str,
    options: Sequence[str],
    choices: Callable[[type], dict[str, type | None] | None] | None,
) -> Iterator[tuple[str, str]]:
    """A group's options: its choices first when it is a choice group."""
    group_class = _declared_class(owner, field, default)
    known = _choices(group_class, choices)
    if known is None:
        yield from option_lines(type(default), options, f"{path}.", choices)
        return
    asked = _asked_choice(options, path)
    current = _choice_name(type(default), known)
    yield f"--{path}.type={{{','.join(known)}}}", f"{help_text} (default: {current})".strip()
    chosen = known[asked] if asked in known else type(default)
    if chosen is None:  # a choice whose class needs heavy imports: named, not described
        yield f"--{path}.*", f"the options of --{path}.type={asked}: `--{path}.type={asked} --help`"
        return
    yield from option_lines(chosen, options, f"{path}.", choices)


def _declared_class(owner: type, field: dataclasses.Field, default: Any) -> type:
    """The group's declared class (looked up in ``owner``'s module), else its default's class."""
    name = field.type if isinstance(field.type, str) else getattr(field.type, "__name__", "")
    declared = getattr(sys.modules.get(owner.__module__), str(name).strip(), None)
    return declared if isinstance(declared, type) else type(default)


def _choices(
    group_class: type, choices: Callable[[type], dict[str, type | None] | None] | None
) -> dict[str, Any] | None:
    """The choices of a choice group (None: a plain group)."""
    if choices is not None:
        named = choices(group_class)
        if named is not None:
            return named
    if hasattr(group_class, "get_known_choices"):
        return dict(group_class.get_known_choices())
    return None


def _choice_name(chosen: type, known: dict[str, Any]) -> str:
    """The name the default choice is registered under."""
    return next((name for name, klass in known.items() if klass is chosen), "?")


def _asked_choice(options: Sequence[str], path: str) -> str | None:
    """The ``--<path>.type`` the command line names, if any."""
    for position, option in enumerate(options):
        name, separator, value = option.partition("=")
        if name == f"--{path}.type":
            return value if separator else (options[position + 1] if position + 1 < len(options) else None)
    return None


def _default(field: dataclasses.Field) -> Any:
    """A field's default value (calling its factory), or ``MISSING``."""
    if field.default is not dataclasses.MISSING:
        return field.default
    if field.default_factory is not dataclasses.MISSING:
        return field.default_factory()
    return dataclasses.MISSING


def _type_name(field: dataclasses.Field) -> str:
    """The field's type as written (``int | None`` shown as ``int``: every option may be left unset)."""
    name = field.type if isinstance(field.type, str) else getattr(field.type, "__name__", str(field.type))
    parts = [part.strip() for part in str(name).split("|") if part.strip() != "None"]
    shown = re.sub(r"\b(?:\w+\.)+(\w+)", r"\1", " | ".join(parts))  # module paths dropped
    return shown.upper() if shown.isidentifier() else shown or "VALUE"


def _shown(value: Any) -> str:
    """A default as it would be typed."""
    if isinstance(value, bool):
        return str(value).lower()
    if value is None:
        return "unset"
    return str(value)


def render_help(prog: str, summary: str, lines: Sequence[tuple[str, str]], footer: str = "") -> str:
    """The help page: usage, the summary paragraph, one line per option, an optional footer."""
    out = [f"usage: {prog} [--option=value ...]", "", textwrap.fill(summary, HELP_WIDTH), "", "options:"]
    for name, text in lines:
        out.append(_option_line(name, text))
    if footer:
        out += ["", textwrap.fill(footer, HELP_WIDTH)]
    return "\n".join(out)


def _option_line(name: str, text: str) -> str:
    """One option on one line: its name, padded, and its help."""
    return f"  {name:<{NAME_WIDTH}} {text}".rstrip()


def summary_of(cls: type) -> str:
    """The first paragraph of a class's docstring."""
    doc = inspect.getdoc(cls) or cls.__name__
    return " ".join(doc.split("\n\n", 1)[0].split()).replace("``", "`")
