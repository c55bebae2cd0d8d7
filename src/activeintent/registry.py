"""One registry pattern for every plug-in point: methods, signals, envs, intentions, models.

A researcher adds their own with ``REGISTRY.register("name", factory)`` in a Python file and
passes that file with ``--plugin path.py`` (or imports it before calling the API). Unknown
names are refused with the list of valid ones.
"""

from __future__ import annotations

import hashlib
import importlib.util
import sys
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Generic, TypeVar

T = TypeVar("T")


class UnknownName(ValueError):
    """A name that no plug-in registered; the message lists the valid ones."""


class Registry(Generic[T]):
    """Named entries of one kind (``kind`` is used in messages, e.g. "signal"): factories, made
    with :meth:`make`, or objects used as they are (the goal language's node types), read with
    ``registry[name]``. Entries keep the order they were registered in."""

    def __init__(self, kind: str):
        self.kind = kind
        self._factories: dict[str, Callable[..., T]] = {}
        self._help: dict[str, str] = {}

    def register(self, name: str, factory: Callable[..., T] | None = None, help: str = ""):
        """Register ``factory`` under ``name``; usable as a decorator when ``factory`` is None."""

        def add(f: Callable[..., T]) -> Callable[..., T]:
            if not name or name != name.strip():
                raise ValueError(f"a {self.kind} name must be a non-empty word, got {name!r}")
            self._factories[name] = f
            self._help[name] = help or (f.__doc__ or "").strip().split("\n")[0]
            return f

        return add(factory) if factory is not None else add

    def names(self) -> list[str]:
        return list(self._factories)

    def help(self, name: str) -> str:
        return self._help.get(self.check(name), "")

    def check(self, name: str) -> str:
        if name not in self._factories:
            valid = ", ".join(self._factories) or "(none registered)"
            raise UnknownName(f"Unknown {self.kind} {name!r}; valid {self.kind}s: {valid}.")
        return name

    def factory(self, name: str) -> Callable[..., T]:
        return self._factories[self.check(name)]

    def make(self, name: str, *args, **kwargs) -> T:
        return self.factory(name)(*args, **kwargs)

    def __contains__(self, name: object) -> bool:
        return name in self._factories

    def __getitem__(self, name: str) -> Callable[..., T]:
        """The entry registered as ``name`` itself (not called); unknown names list the valid ones."""
        try:  # the goal language reads its node types here about a million times per episode
            return self._factories[name]
        except KeyError:
            return self.factory(name)

    def __iter__(self):
        return iter(self._factories)

    def __len__(self) -> int:
        return len(self._factories)

    def items(self):
        return self._factories.items()


def load_plugin(path: str | Path) -> ModuleType:
    """Import a researcher's Python file once (its ``register`` calls take effect); the module.
    The one loader of researchers' files: ``--plugin`` files and ``--intention-file`` files."""
    path = Path(path).resolve()
    if not path.is_file():
        raise FileNotFoundError(f"plug-in file not found: {path}")
    name = "activeintent_plugin_" + hashlib.sha256(str(path).encode()).hexdigest()[:12]
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ValueError(f"cannot import {path} as Python")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module
