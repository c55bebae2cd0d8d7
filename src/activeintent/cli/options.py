"""The options of a run's spec, made from the pydantic fields that declare them: the spec's
sections (:func:`activeintent.spec.option_fields`) and every registered method's config class
(``Method.settings``). `run`, `bench` and `serve` take them through :func:`spec_options`, so a
setting is declared once, in its class, and a plug-in learner's new field is an option too."""

from __future__ import annotations

import inspect
import os
import types
import typing
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any, Literal

import typer
from pydantic.fields import FieldInfo
from pydantic_core import PydanticUndefined

from activeintent.learners.registry import get_method, method_names
from activeintent.spec import option_fields
from activeintent.web.basics import parse_video_size


def check_only() -> bool:
    """ACTIVEINTENT_CHECK_ONLY=1: commands validate their options and inputs, then stop before
    the work (the docs test runs every documented command this way)."""
    return os.environ.get("ACTIVEINTENT_CHECK_ONLY") == "1"


_PANELS = {"protocol": "Protocol", "models": "Models", "learner": "Learner", "act": "Learner", "env": "World",
           "user": "World", None: "World"}


def _cli_type(annotation: Any) -> Any:
    """The type the command line parses a field as (pydantic judges the value afterwards)."""
    origin = typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        return _cli_type(args[0]) if len(args) == 1 else str
    if origin is Literal:
        return str
    if origin is list:
        return list[str]
    return annotation if annotation in (bool, int, float, str) else str


def _shown(value: Any) -> str:
    return "none" if value is None else str(value).lower() if isinstance(value, bool) else str(value)


def _help(info: FieldInfo, default: str | None) -> str:
    text = (info.description or "").rstrip(".")
    return f"{text} (default: {default})" if default else text


def _families(names: list[str]) -> str:
    """Method names, those sharing a first word as one ``word-*``."""
    heads: dict[str, list[str]] = {}
    for n in names:
        heads.setdefault(n.split("-")[0], []).append(n)
    return ", ".join(f"{h}-*" if len(v) > 1 else v[0] for h, v in heads.items())


def setting_fields() -> dict[str, list[tuple[str, FieldInfo]]]:
    """Every registered method's settings: field name → [(method, its FieldInfo)], in the order the
    methods are listed."""
    out: dict[str, list[tuple[str, FieldInfo]]] = {}
    for name in method_names():
        for field, info in get_method(name).settings.model_fields.items():
            out.setdefault(field, []).append((name, info))
    return out


def _parameter(name: str, kind: Any, help_text: str, panel: str, info: FieldInfo) -> inspect.Parameter:
    decl = f"--{name.replace('_', '-')}"
    if kind is bool:
        decl = f"{decl}/--no-{name.replace('_', '-')}"
    extra = info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}
    option = typer.Option(decl, help=help_text, rich_help_panel=panel, show_default=False,
                          envvar=extra.get("envvar"))
    return inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=None,
                             annotation=Annotated[kind | None, option])


def spec_parameters(exclude: frozenset[str] = frozenset()) -> list[inspect.Parameter]:
    """The spec's options as command parameters, each None unless given."""
    params = []
    for name, (section, _, info) in option_fields().items():
        if name in exclude:
            continue
        default = None if info.default is PydanticUndefined else info.default
        params.append(_parameter(name, _cli_type(info.annotation), _help(info, _shown(default) if default is not None
                                 else None), _PANELS[section], info))
    for name, owners in setting_fields().items():
        if name in exclude:
            continue
        defaults: dict[str, list[str]] = {}
        texts: dict[str, list[str]] = {}
        for method, info in owners:
            defaults.setdefault(_shown(info.default), []).append(method)
            texts.setdefault((info.description or "").rstrip("."), []).append(method)
        shown = (next(iter(defaults)) if len(defaults) == 1 else
                 "; ".join(f"{_families(ms)}: {d}" for d, ms in defaults.items()))
        described = (next(iter(texts)) if len(texts) == 1 else
                     "; ".join(f"{_families(ms)}: {t}" for t, ms in texts.items()))
        text = f"{described} (default: {shown}) [{_families([m for m, _ in owners])}]"
        params.append(_parameter(name, _cli_type(owners[0][1].annotation), text.replace("[", "\\["),
                                 "Learner settings", owners[0][1]))
    return params


class SpecCommand:
    """A command whose options are its own parameters plus the spec's, the latter made when the
    command line is built (after plug-ins registered their learners). The command receives the
    spec's given values as ``given`` (option name → value; options not given are absent)."""

    def __init__(self, func: Callable[..., Any], exclude: frozenset[str] = frozenset()):
        self.func = func
        self.exclude = exclude
        self.__name__ = func.__name__
        self.__qualname__ = func.__qualname__
        self.__doc__ = func.__doc__
        self.__module__ = func.__module__

    def _own(self) -> list[inspect.Parameter]:
        own = inspect.signature(self.func, eval_str=True).parameters.values()
        return [p for p in own if p.name != "given"]

    @property
    def __signature__(self) -> inspect.Signature:  # read by typer when it builds the command
        own = self._own()
        names = {p.name for p in own}
        spec = [p for p in spec_parameters(self.exclude) if p.name not in names]
        return inspect.Signature([p.replace(kind=inspect.Parameter.KEYWORD_ONLY) for p in own] + spec)

    @property
    def __annotations__(self) -> dict[str, Any]:  # type: ignore[override]
        return {p.name: p.annotation for p in self.__signature__.parameters.values()}

    def __call__(self, **values: Any) -> Any:
        own = {p.name for p in self._own()}
        given = {k: v for k, v in values.items() if k not in own and v is not None}
        return self.func(given=given, **{k: v for k, v in values.items() if k in own})


def spec_command(exclude: tuple[str, ...] = ()) -> Callable[[Callable[..., Any]], SpecCommand]:
    """Decorator: the command takes the spec's options (but ``exclude``), see :class:`SpecCommand`."""
    return lambda func: SpecCommand(func, frozenset(exclude))


def _video_size(text: str) -> tuple[int, int]:
    try:
        return parse_video_size(text)
    except ValueError as err:
        raise typer.BadParameter(str(err)) from None


VideoSize = Annotated[str, typer.Option(
    "--video-size", callback=_video_size,
    help="Videos' WIDTHxHEIGHT in pixels (64-2048 each), or one number for a square; at the default every "
    "block is at least 40 px wide, larger takes longer to render before each round")]
Out = Annotated[Path | None, typer.Option("--out", help="Output folder")]
UnsafeNoIsolation = Annotated[bool, typer.Option("--unsafe-no-isolation", envvar="ACTIVEINTENT_UNSAFE_NO_ISOLATION", help="Run model-written code (--executor cap, proposed predicates) even without the bubblewrap sandbox (docs/security.md)")]
