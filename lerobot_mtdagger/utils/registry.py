"""One registry idiom for the parts found by name: suites, experts and students.

A ``Registry`` maps names to objects, or to ``"module:attribute"`` strings imported when first asked
for, so registering the built-in parts imports none of them; installed packages add theirs through an
entry-point group (``utils.plugins``)::

    SUITES: Registry[str, SuiteFactory] = Registry("suite", accepts=callable)
    SUITES.register("my-suite", "my_package.suites:make_my_suite")
    factory = SUITES.get("my-suite")  # imports my_package.suites
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Hashable, Iterator
from typing import Any, Generic, TypeVar, cast

from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.plugins import register_installed

K = TypeVar("K", bound=Hashable)
T = TypeVar("T")


class EntryPointError(UserError):
    """A ``"module:attribute"`` string that names nothing importable.

    ``cause`` is the error behind it (``ImportError``, ``AttributeError``), or None for a malformed string.
    """

    def __init__(self, message: str, cause: Exception | None = None) -> None:
        super().__init__(message)
        self.cause = cause


def is_entry_point(value: object) -> bool:
    """Whether ``value`` is a ``"module:attribute"`` string (not yet checked to import)."""
    return isinstance(value, str) and ":" in value


def resolve(spec: str) -> Any:
    """The attribute a ``"module:attribute"`` string names, its module imported.

    Raises:
        EntryPointError: If the string is malformed, its module cannot be imported or lacks the attribute.
    """
    module_name, _, attribute = spec.partition(":")
    if not module_name or not attribute:
        raise EntryPointError(f"{spec!r} is not a 'module:attribute' string (e.g. 'my_package.module:name').")
    try:
        module = importlib.import_module(module_name)
    except ImportError as error:
        raise EntryPointError(
            f"{spec!r}: module {module_name!r} cannot be imported ({type(error).__name__}: {error}); install "
            "the package that provides it or fix the name.",
            error,
        ) from None
    try:
        return getattr(module, attribute)
    except AttributeError as error:
        raise EntryPointError(
            f"{spec!r}: module {module_name!r} has no attribute {attribute!r}; fix the name after the ':'.",
            error,
        ) from None


class Registry(Generic[K, T]):
    """Objects by name, each given as itself or as a ``"module:attribute"`` string imported on first use.

    Names (``K``) are strings, or tuples such as the experts' ``(suite family, task)``.

    Args:
        kind: What is registered, for messages ("suite", "student").
        accepts: Whether an object (not an entry-point string) may be registered.
        entry_point_group: The entry-point group installed packages register into (None: none).
        refusal: The ``TypeError`` message for an object refused under a name (None: a generic one).
    """

    def __init__(
        self,
        kind: str,
        accepts: Callable[[object], bool] = callable,
        entry_point_group: str | None = None,
        refusal: Callable[[K, object], str] | None = None,
    ) -> None:
        self.kind = kind
        self.accepts = accepts
        self.refusal = refusal
        self.entry_point_group = entry_point_group
        self._entries: dict[K, T | str] = {}
        self._resolved: dict[K, T] = {}

    def register(self, name: K, obj: T | str | None = None, replace: bool = False) -> Any:
        """Registers ``obj`` (or its ``"module:attribute"``) under ``name``; without ``obj``, a decorator.

        Raises:
            UserError: If ``name`` is taken and ``replace`` is false.
            TypeError: If ``obj`` is neither accepted nor an entry-point string.
        """
        if obj is None:

            def decorator(target: T) -> T:
                self.register(name, target, replace)
                return target

            return decorator
        if name in self._entries and not replace:
            raise UserError(
                f"A {self.kind} named {name!r} is already registered; register yours under another name."
            )
        if not (is_entry_point(obj) or (not isinstance(obj, str) and self.accepts(obj))):
            what = f"The {self.kind} {name!r}"
            message = f"{what} must be callable or a 'module:attribute' string, got {obj!r}."
            raise TypeError(self.refusal(name, obj) if self.refusal else message)
        self._entries[name] = obj
        self._resolved.pop(name, None)
        return obj

    def __contains__(self, name: object) -> bool:
        """Whether ``name`` is registered."""
        return name in self._entries

    def __iter__(self) -> Iterator[K]:
        """The registered names, in order of registration."""
        return iter(list(self._entries))

    def names(self) -> list[K]:
        """The registered names, in order of registration (the built-in ones first)."""
        return list(self._entries)

    def entry(self, name: K) -> T | str | None:
        """What ``name`` was registered with (an object or an entry-point string), or None."""
        return self._entries.get(name)

    def get(self, name: K, unknown: str | None = None) -> T:
        """The object registered under ``name``, its entry point imported once.

        ``unknown`` is the message for a name not registered (None: one listing the registered names).

        Raises:
            UserError: If ``name`` is not registered, or its entry point does not import.
        """
        if name not in self._entries:
            raise UserError(unknown or self.unknown_message(name))
        if name not in self._resolved:
            entry = self._entries[name]
            self._resolved[name] = resolve(entry) if isinstance(entry, str) else entry
        return self._resolved[name]

    def copy(self) -> Registry[K, T]:
        """A registry with the same entries (registering into it leaves this one as it is)."""
        twin: Registry[K, T] = Registry(self.kind, self.accepts, self.entry_point_group, self.refusal)
        twin._entries = dict(self._entries)
        twin._resolved = dict(self._resolved)
        return twin

    def unknown_message(self, name: K) -> str:
        """One line naming the registered names and how to add one."""
        where = f", or installed by a package's entry point in the group {self.entry_point_group!r}"
        return (
            f"Unknown {self.kind} {name!r}; registered: {', '.join(map(str, self._entries)) or 'none'} "
            f"(register one by name{where if self.entry_point_group else ''})."
        )

    def load_entry_points(self, register: Callable[[str, str], None] | None = None) -> list[str]:
        """Registers the group's entry points whose names are not taken (built-ins win); returns the names.

        ``register(name, "module:attribute")`` registers one (None: ``self.register``); entry points are
        named by strings, so only a registry keyed by ``str`` has a group.
        """
        if self.entry_point_group is None:
            return []
        register = register or cast("Callable[[str, str], None]", self.register)
        return register_installed(self.entry_point_group, self._entries, register)
