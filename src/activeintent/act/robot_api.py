"""The Code-as-Policies tabletop API over a symbolic world state.

This is what a `cap` program sees (inside the sandbox child): ``get_obj_names``,
``get_obj_pos``, ``put_first_on_second``, ``stack_objects_in_order``, ``say``,
``is_obj_visible``, ``get_corner_name``, ``get_side_name``, ``denormalize_xy``,
``parse_position`` and ``np``. Robot calls do not move anything: each is recorded as a skill and
applied to a copy of the state with the symbolic world model, so later ``get_obj_pos`` calls see
earlier moves. The recorded skills leave the sandbox as data.
"""

from __future__ import annotations

import functools
import math
import re
from types import SimpleNamespace
from typing import Any

import numpy as np

from activeintent.world.colors import COLORS
from activeintent.world.predict import apply_skill
from activeintent.world.scene import BLOCK_SIZE, BOUNDS, BOWL_INNER_RADIUS
from activeintent.world.skills import TABLE_POSITIONS, PutAt, PutIn, PutOn, Skill
from activeintent.world.state import WorldState

MAX_SKILLS = 50
MAX_SAID_CHARS = 4_000
MAX_SAID_MESSAGES = 100

CORNERS = ("top left corner", "top right corner", "bottom left corner", "bottom right corner")
SIDES = ("top side", "right side", "bottom side", "left side")

# Spellings of the named table positions a program (or a model) may use.
_POSITION_ALIASES = {
    "center": "middle", "centre": "middle", "middle": "middle",
    "top": "top side", "bottom": "bottom side", "left": "left side", "right": "right side",
    "upper left": "top left corner", "upper right": "top right corner",
    "lower left": "bottom left corner", "lower right": "bottom right corner",
    "top left": "top left corner", "top right": "top right corner",
    "bottom left": "bottom left corner", "bottom right": "bottom right corner",
}
_DIRECTIONS = {
    "left": (-1.0, 0.0), "right": (1.0, 0.0), "above": (0.0, 1.0), "up": (0.0, 1.0),
    "behind": (0.0, 1.0), "below": (0.0, -1.0), "down": (0.0, -1.0), "in front": (0.0, -1.0),
}
_OFFSET_RE = re.compile(
    r"^(?:a point )?(?P<num>\d+(?:\.\d+)?)\s*(?P<unit>cm|mm|m)\s+(?:to the\s+)?"
    r"(?P<dir>left|right|above|below|up|down|behind|in front)\s+(?:of|from)\s+(?P<ref>.+)$"
)
_BETWEEN_RE = re.compile(r"^(?:(?:a point|the (?:midpoint|middle|point))\s+)?(?:in\s+)?between\s+(?P<a>.+?)\s+and\s+(?P<b>.+)$")


def normalize_name(text: str) -> str:
    """'The_Red_Block' -> 'red block' ('grey' is read as 'gray')."""
    norm = " ".join(str(text).lower().replace("_", " ").replace("grey", "gray").split())
    return norm[4:] if norm.startswith("the ") else norm


def position_key(text: str) -> str | None:
    """The TABLE_POSITIONS key for a description such as 'the top-left corner of the table'."""
    norm = normalize_name(text).replace("-", " ")
    for suffix in (" of the table", " of table", " on the table"):
        norm = norm.removesuffix(suffix)
    norm = norm.removeprefix("a point on the ").removeprefix("a point at the ").removeprefix("the ")
    norm = norm.removesuffix(" edge").removesuffix(" of the table")
    if norm in TABLE_POSITIONS:
        return norm
    if norm in _POSITION_ALIASES:
        return _POSITION_ALIASES[norm]
    if norm.endswith(" corner") and norm[: -len(" corner")] in _POSITION_ALIASES:
        return _POSITION_ALIASES[norm[: -len(" corner")]]
    if norm.endswith(" side") and norm[: -len(" side")] in _POSITION_ALIASES:
        return _POSITION_ALIASES[norm[: -len(" side")]]
    return None


class RobotAPI:
    """The CaP functions bound to one symbolic state; ``skills``/``said`` record what was done."""

    def __init__(self, state: WorldState) -> None:
        self.state = state
        self.skills: list[Skill] = []
        self.skill_failures: list[str | None] = []
        self.said: list[str] = []
        self._said_chars = 0

    # ---- names and positions ------------------------------------------------------------
    def _object(self, name: Any) -> str:
        if not isinstance(name, str):
            raise TypeError(f"an object name must be a string like 'red block', not {type(name).__name__}")
        norm = normalize_name(name)
        if norm not in self.state.positions:
            raise ValueError(f"unknown object {name!r}; objects on the table: {', '.join(self.state.names)}")
        return norm

    def get_obj_names(self) -> list[str]:
        return list(self.state.names)

    def is_obj_visible(self, obj_name: str) -> bool:
        return isinstance(obj_name, str) and normalize_name(obj_name) in self.state.positions

    def get_obj_pos(self, obj_name: str) -> np.ndarray:
        if isinstance(obj_name, str) and (key := position_key(obj_name)) is not None:
            return np.array(TABLE_POSITIONS[key], dtype=float)
        return self.state.pos(self._object(obj_name))[:2].copy()

    def get_color(self, obj_name: str) -> np.ndarray:
        return np.array(COLORS[self.state.color(self._object(obj_name))], dtype=float)

    def get_bbox(self, obj_name: str) -> tuple[float, float, float, float]:
        x, y = self.get_obj_pos(obj_name)
        h = BLOCK_SIZE / 2 if self.state.kind(self._object(obj_name)) == "block" else BOWL_INNER_RADIUS
        return (float(x - h), float(y - h), float(x + h), float(y + h))

    @staticmethod
    def denormalize_xy(pos_normalized: Any) -> np.ndarray:
        """[0, 1]^2 (x left → right, y bottom → top) to table coordinates in metres."""
        p = np.asarray(pos_normalized, dtype=float).reshape(-1)
        (x0, x1), (y0, y1) = BOUNDS
        return np.array([x0 + p[0] * (x1 - x0), y0 + p[1] * (y1 - y0)])

    @staticmethod
    def get_corner_positions() -> np.ndarray:
        return np.array([TABLE_POSITIONS[c] for c in CORNERS], dtype=float)

    @staticmethod
    def get_side_positions() -> np.ndarray:
        return np.array([TABLE_POSITIONS[s] for s in SIDES], dtype=float)

    @staticmethod
    def _nearest(pos: Any, names: tuple[str, ...]) -> str:
        p = np.asarray(pos, dtype=float).reshape(-1)[:2]
        return min(names, key=lambda n: float(np.hypot(*(np.array(TABLE_POSITIONS[n]) - p))))

    def get_corner_name(self, pos: Any) -> str:
        return self._nearest(pos, CORNERS)

    def get_side_name(self, pos: Any) -> str:
        return self._nearest(pos, SIDES)

    def parse_position(self, description: Any) -> np.ndarray:
        """A table point from a description: a named position ('top left corner', 'middle'),
        an object ('blue bowl'), '10cm left of the red block', 'between the red block and the
        blue bowl', or an (x, y) point."""
        if not isinstance(description, str):
            return self._point(description)
        if (key := position_key(description)) is not None:
            return np.array(TABLE_POSITIONS[key], dtype=float)
        norm = normalize_name(description)
        if norm in self.state.positions:
            return self.state.pos(norm)[:2].copy()
        if m := _OFFSET_RE.match(norm):
            scale = {"cm": 0.01, "mm": 0.001, "m": 1.0}[m["unit"]]
            return self.parse_position(m["ref"]) + float(m["num"]) * scale * np.array(_DIRECTIONS[m["dir"]])
        if m := _BETWEEN_RE.match(norm):
            return (self.parse_position(m["a"]) + self.parse_position(m["b"])) / 2
        raise ValueError(
            f"cannot parse position {description!r}; use a named position "
            f"({', '.join(TABLE_POSITIONS)}), an object ({', '.join(self.state.names)}), "
            "'<n>cm left of/right of/above/below <object>' or 'between <a> and <b>'"
        )

    @staticmethod
    def _point(value: Any) -> np.ndarray:
        try:
            p = np.asarray(value, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise TypeError(f"expected an object name or an (x, y) point, got {value!r:.80}") from None
        if p.size < 2 or not np.all(np.isfinite(p[:2])):
            raise ValueError(f"expected a finite (x, y) point, got {value!r:.80}")
        return p[:2]

    # ---- actions ------------------------------------------------------------------------
    def _top_block_at(self, xy: np.ndarray, exclude: str | None = None) -> str | None:
        """The highest block whose footprint contains ``xy``."""
        hits = [
            b for b in self.state.blocks
            if b != exclude and np.hypot(*(self.state.pos(b)[:2] - xy)) <= BLOCK_SIZE * 0.75
        ]
        return max(hits, key=lambda b: self.state.pos(b)[2]) if hits else None

    def _target_skill(self, block: str, target: Any) -> Skill:
        if isinstance(target, str):
            if (key := position_key(target)) is not None and normalize_name(target) not in self.state.positions:
                return PutAt(block=block, position=key)
            name = self._object(target)
            if self.state.kind(name) == "bowl":
                return PutIn(block=block, bowl=name)
            return PutOn(block=block, target=name)
        xy = self._point(target)
        # A point inside a bowl or on a block means "there", as the real robot would drop it.
        for bowl in self.state.bowls:
            if np.hypot(*(self.state.pos(bowl)[:2] - xy)) <= BOWL_INNER_RADIUS:
                return PutIn(block=block, bowl=bowl)
        if (under := self._top_block_at(xy, exclude=block)) is not None:
            return PutOn(block=block, target=under)
        return PutAt(block=block, position=(round(float(xy[0]), 4), round(float(xy[1]), 4)))

    def put_first_on_second(self, arg1: Any, arg2: Any) -> None:
        """Pick ``arg1`` (a block name, or a point on a block) and place it on/in ``arg2``
        (a bowl, a block, a named table position, or an (x, y) point)."""
        if isinstance(arg1, str):
            block = self._object(arg1)
        else:
            block = self._top_block_at(self._point(arg1))
            if block is None:
                raise ValueError(f"no block at {self._point(arg1).round(3).tolist()} to pick up")
        if self.state.kind(block) != "block":
            raise ValueError(f"the robot can only pick up blocks, not the {block}")
        if len(self.skills) >= MAX_SKILLS:
            raise RuntimeError(f"too many robot actions (limit {MAX_SKILLS})")
        step = self._target_skill(block, arg2)
        self.state, failure = apply_skill(self.state, step)
        self.skills.append(step)
        self.skill_failures.append(failure.reason if failure else None)

    def stack_objects_in_order(self, object_names: Any) -> None:
        """Stack the objects bottom-up: each one goes on the previous one."""
        names = list(object_names)
        for below, above in zip(names, names[1:], strict=False):
            self.put_first_on_second(above, below)

    def say(self, msg: Any) -> None:
        text = str(msg)
        if self._said_chars + len(text) > MAX_SAID_CHARS:
            raise RuntimeError(f"too much output: say() may print at most {MAX_SAID_CHARS} characters in all")
        if len(self.said) >= MAX_SAID_MESSAGES:
            raise RuntimeError(f"too much output: say() may be called at most {MAX_SAID_MESSAGES} times")
        self._said_chars += len(text)
        self.said.append(text)

    def print(self, *args: Any, sep: str = " ", end: str = "\n") -> None:  # noqa: A003 - CaP name
        self.say(str(sep).join(str(a) for a in args))

    def namespace(self) -> dict[str, Any]:
        """The functions a program may call, by their Code-as-Policies names."""
        names = (
            "get_obj_names", "get_obj_pos", "is_obj_visible", "get_color", "get_bbox",
            "denormalize_xy", "get_corner_positions", "get_side_positions", "get_corner_name",
            "get_side_name", "parse_position", "put_first_on_second", "stack_objects_in_order",
            "say",
        )
        ns: dict[str, Any] = {n: getattr(self, n) for n in names}
        ns["np"] = SAFE_NUMPY
        ns["objects"] = list(self.state.names)  # CaP prompts list the scene as `objects = [...]`
        return ns


# Only these numpy names are visible as ``np``: math and array building, no files, no ctypes, no
# raw buffers. Every function is wrapped so that it cannot hand out object, void or structured
# arrays (which, with raw memory access, reach any Python object), and ``np.ndarray`` is only a
# type for ``isinstance``: it cannot build arrays over buffers with chosen strides.
_NUMPY_NAMES = (
    "array", "asarray", "zeros", "ones", "full", "zeros_like", "ones_like", "arange", "linspace",
    "eye", "mean", "median", "sum", "prod", "min", "max", "amin", "amax", "argmin", "argmax",
    "argsort", "sort", "sqrt", "abs", "absolute", "hypot", "cos", "sin", "tan", "arccos",
    "arcsin", "arctan", "arctan2", "pi", "e", "inf", "nan", "deg2rad", "rad2deg", "radians",
    "degrees", "clip", "round", "around", "floor", "ceil", "rint", "stack", "vstack", "hstack",
    "concatenate", "cross", "dot", "matmul", "outer", "float32", "float64", "int32", "int64",
    "isclose", "allclose", "where", "unique", "cumsum", "diff", "std", "var", "isnan", "isfinite",
    "mod", "sign", "maximum", "minimum", "percentile", "all", "any", "transpose", "reshape",
    "squeeze", "expand_dims", "tile", "repeat", "flip", "roll", "interp", "exp", "log", "power",
    "square", "nonzero", "count_nonzero", "meshgrid", "array_equal", "newaxis",
    "ptp", "average", "fabs", "floor_divide", "lexsort",
)
_SAFE_KINDS = frozenset("biufcUS")  # bool, integers, floats, complex, text; not object/void/time


def _check_arrays(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in _SAFE_KINDS or value.dtype.fields is not None:
            raise TypeError(f"arrays of dtype {value.dtype.str!r} are not available in robot programs")
    elif isinstance(value, (tuple, list)):
        for item in value:
            _check_arrays(item)
    return value


def _safe_numpy_function(fn: Any) -> Any:
    if not callable(fn) or isinstance(fn, type):
        return fn

    @functools.wraps(fn, assigned=("__name__", "__qualname__", "__doc__"))
    def checked(*args: Any, **kwargs: Any) -> Any:
        return _check_arrays(fn(*args, **kwargs))

    return checked


class _ArrayTypeMeta(type):
    def __instancecheck__(cls, obj: Any) -> bool:
        return isinstance(obj, np.ndarray)

    def __call__(cls, *args: Any, **kwargs: Any) -> Any:
        raise TypeError("np.ndarray(...) is not available in robot programs; use np.array or np.zeros")


class ndarray(metaclass=_ArrayTypeMeta):  # noqa: N801 - stands in for np.ndarray
    """For ``isinstance(x, np.ndarray)`` only."""


SAFE_NUMPY = SimpleNamespace(
    **{n: _safe_numpy_function(getattr(np, n)) for n in _NUMPY_NAMES if hasattr(np, n)},
    ndarray=ndarray,
    linalg=SimpleNamespace(
        norm=_safe_numpy_function(np.linalg.norm),
        det=_safe_numpy_function(np.linalg.det),
        inv=_safe_numpy_function(np.linalg.inv),
    ),
)

SAFE_BUILTIN_NAMES = (
    "range", "len", "enumerate", "zip", "min", "max", "sum", "abs", "round", "sorted",
    "reversed", "list", "dict", "tuple", "set", "frozenset", "str", "int", "float", "bool",
    "any", "all", "isinstance", "map", "filter", "repr", "divmod", "pow", "iter", "next",
    "chr", "ord", "Exception", "ValueError", "KeyError", "IndexError", "TypeError",
    "ZeroDivisionError", "RuntimeError", "AssertionError", "StopIteration", "ArithmeticError",
    "LookupError", "NotImplementedError",
)


def safe_builtins(api: RobotAPI) -> dict[str, Any]:
    import builtins

    table: dict[str, Any] = {n: getattr(builtins, n) for n in SAFE_BUILTIN_NAMES}
    table["print"] = api.print
    table["math"] = SimpleNamespace(
        **{n: getattr(math, n) for n in ("pi", "e", "sqrt", "cos", "sin", "tan", "atan2", "hypot",
                                          "floor", "ceil", "radians", "degrees", "isclose", "inf")}
    )
    return table
