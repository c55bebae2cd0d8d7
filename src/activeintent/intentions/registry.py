"""Finding intentions by name, and loading user-defined ones from a Python file.

Commands accept ``--intention NAME`` (a built-in) or ``--intention-file path.py:NAME`` (your
own); both go through :func:`resolve_intention`.
"""

from __future__ import annotations

import difflib
import inspect
import re
from pathlib import Path

from activeintent.intentions.arrangements import (
    Align,
    AlignVertical,
    Stack,
    TwoTowers,
    WarmInBowlsCoolStacked,
)
from activeintent.intentions.base import Intention
from activeintent.intentions.bowls import (
    ColorMatch,
    ColorMismatch,
    NextToSameColorBowl,
    OneBlockPerBowl,
    OneBowl,
)
from activeintent.intentions.regions import BlocksInCorners, BlocksLeftHalf, WarmLeftCoolRight
from activeintent.registry import Registry, load_plugin

PAPER_INTENTIONS: tuple[str, ...] = ("align", "stack", "color-match", "color-mismatch")

# Intentions by name (a registry: a plug-in file adds its own with ``INTENTIONS.register``).
INTENTIONS: Registry[Intention] = Registry("intention")
for _cls in (Align, Stack, ColorMatch, ColorMismatch, AlignVertical, TwoTowers, WarmInBowlsCoolStacked, OneBowl,
             OneBlockPerBowl, NextToSameColorBowl, BlocksInCorners, BlocksLeftHalf, WarmLeftCoolRight):
    INTENTIONS.register(_cls.name, _cls, help=_cls.description)
# the built-in ones (the library suite: fixed, whatever plug-ins add)
INTENTION_NAMES: tuple[str, ...] = tuple(INTENTIONS.names())


class IntentionError(ValueError):
    """An unknown intention name or an intention file that does not define a valid intention."""


def _normalise(name: str) -> str:
    return "-".join(name.strip().lower().replace("_", " ").replace("-", " ").split())


def get_intention(name: str) -> Intention:
    """A fresh instance of the built-in intention called ``name`` (e.g. ``color-match``)."""
    key = _normalise(name)
    if key not in INTENTIONS:
        close = difflib.get_close_matches(key, INTENTIONS.names(), n=2)
        hint = f" Did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
        raise IntentionError(
            f"Unknown intention {name!r}.{hint} Valid intentions: {', '.join(INTENTIONS.names())}. "
            "To use your own, pass --intention-file path.py:NAME (see docs/intentions.md)."
        )
    return INTENTIONS.make(key)


def all_intentions() -> list[Intention]:
    """One instance of every built-in intention, the paper's four first."""
    return [INTENTIONS.make(name) for name in INTENTION_NAMES]


def is_paper_intention(intention: Intention) -> bool:
    return intention.name in PAPER_INTENTIONS


def _kebab(identifier: str) -> str:
    out = []
    for i, ch in enumerate(identifier):
        if ch.isupper() and i and (identifier[i - 1].islower() or identifier[i - 1].isdigit()):
            out.append("-")
        out.append(ch.lower())
    return "".join(out).replace("_", "-")


def _split_spec(spec: str) -> tuple[Path, str | None]:
    path, sep, attr = spec.rpartition(":")
    # NAME: a Python name in the file, or an intention's registered name (kebab-case)
    if sep and path and (attr.isidentifier() or re.fullmatch(r"[A-Za-z_][A-Za-z0-9_-]*", attr)):
        return Path(path), attr
    return Path(spec), None


def _candidates(module: object) -> list[str]:
    """Names in a loaded file that look like intentions (subclasses or instances)."""
    found = []
    for key, value in vars(module).items():
        if key.startswith("_"):
            continue
        if isinstance(value, Intention) or (
            inspect.isclass(value)
            and issubclass(value, Intention)
            and value is not Intention
            and not inspect.isabstract(value)
            and value.__module__ == getattr(module, "__name__", None)
        ):
            found.append(key)
    return found


def _describe(value: object) -> str:
    if inspect.isclass(value):
        return f"the class {value.__name__} (not a subclass of activeintent.intentions.base.Intention)"
    return f"a {type(value).__name__} ({value!r:.60})"


_EXPECTED = (
    "expected a subclass of activeintent.intentions.base.Intention, an instance of one, "
    "or a function that takes no arguments and returns one"
)


def load_intention_file(spec: str) -> Intention:
    """Load ``path.py:NAME`` — NAME is an Intention subclass, an instance, or a factory.

    Without ``:NAME`` the file must define exactly one intention. Every problem (missing file,
    syntax error, missing or invalid NAME, empty description) raises IntentionError saying
    what was found and what is expected.
    """
    path, attr = _split_spec(spec)
    if path.suffix != ".py":
        raise IntentionError(f"--intention-file {spec!r}: expected a Python file, written path.py:NAME.")
    if not path.is_file():
        raise IntentionError(f"--intention-file {spec!r}: no such file {str(path)!r}.")
    try:
        module = load_plugin(path)  # the one loader of researchers' files (imported once)
    except Exception as exc:  # the user's code: report, never crash
        raise IntentionError(
            f"--intention-file {spec!r}: running {path.name} failed: {type(exc).__name__}: {exc}"
        ) from exc

    candidates = _candidates(module)
    if attr is None:
        if len(candidates) != 1:
            found = ", ".join(candidates) or "none"
            raise IntentionError(
                f"--intention-file {spec!r}: say which intention to use, as {path}:NAME "
                f"(intentions found in the file: {found})."
            )
        attr = candidates[0]
    if not hasattr(module, attr):
        # the intention's registered name (what `intentions` prints), e.g. rightmost-bowl
        named = [c for c in candidates if _name_of(getattr(module, c), c) == attr]
        if len(named) == 1:
            attr = named[0]
    if not hasattr(module, attr):
        found = ", ".join(candidates) or "none"
        raise IntentionError(
            f"--intention-file {spec!r}: {path.name} defines no {attr!r} "
            f"(intentions found in the file: {found})."
        )
    value = getattr(module, attr)
    intention = _instantiate(spec, attr, value)
    if not intention.name:
        intention.name = _kebab(attr)
    if not isinstance(intention.description, str) or not intention.description.strip():
        raise IntentionError(
            f"--intention-file {spec!r}: {attr} has no description; set description = "
            "'one sentence saying what the user wants'."
        )
    return intention


def _name_of(value: object, attr: str) -> str | None:
    """The name an intention of the file goes by (its ``name``, else the kebab-case of ``attr``),
    without running a factory."""
    if isinstance(value, Intention):
        return value.name or _kebab(attr)
    if inspect.isclass(value):
        name = getattr(value, "name", None)
        return name if isinstance(name, str) and name else _kebab(attr)
    return None


def _instantiate(spec: str, attr: str, value: object) -> Intention:
    if isinstance(value, Intention):
        return value
    if inspect.isclass(value):
        if not issubclass(value, Intention):
            raise IntentionError(f"--intention-file {spec!r}: {attr} is {_describe(value)}; {_EXPECTED}.")
        if inspect.isabstract(value):
            missing = ", ".join(sorted(value.__abstractmethods__))
            raise IntentionError(
                f"--intention-file {spec!r}: {attr} does not implement {missing}; {_EXPECTED}."
            )
        try:
            return value()
        except Exception as exc:
            raise IntentionError(f"--intention-file {spec!r}: {attr}() failed: {exc}") from exc
    if callable(value):
        try:
            made = value()
        except Exception as exc:
            raise IntentionError(f"--intention-file {spec!r}: calling {attr}() failed: {exc}") from exc
        if isinstance(made, Intention):
            return made
        raise IntentionError(f"--intention-file {spec!r}: {attr}() returned {_describe(made)}; {_EXPECTED}.")
    raise IntentionError(f"--intention-file {spec!r}: {attr} is {_describe(value)}; {_EXPECTED}.")


def resolve_intention(name: str | None, intention_file: str | None) -> Intention:
    """The intention for ``--intention NAME`` or ``--intention-file path.py:NAME`` (exactly one)."""
    if name and intention_file:
        raise IntentionError(
            "Give either --intention NAME or --intention-file path.py:NAME, not both."
        )
    if intention_file:
        return load_intention_file(intention_file)
    if name:
        return get_intention(name)
    raise IntentionError(
        f"No intention given: pass --intention NAME ({', '.join(INTENTIONS.names())}) "
        "or --intention-file path.py:NAME."
    )
