"""Deterministic parser for instructions y in the canonical phrasing (no model call).

Reads back what :func:`activeintent.world.skills.describe_skill` writes — "put the red block in
the blue bowl", "… on the green block", "… next to / left of / right of / in front of / behind
the X", "… at the top left corner", "… at (0.10, -0.50)" — joined by ", then", ",", ";", "and"
or sentences. Also tolerated: the verbs place/move/stack/set/drop (or none: "put the red block
in the blue bowl, the green block on the red block"), "into", "onto", "on top of", "to",
missing "the", capitals, a trailing period, "grey", "cube".
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Literal

from activeintent.act.failures import ExecutionFailure
from activeintent.act.robot_api import position_key
from activeintent.world.scene import kind_of
from activeintent.world.skills import PutAt, PutIn, PutNextTo, PutOn, Skill
from activeintent.world.state import WorldState

_POINT_RE = re.compile(r"\(\s*(-?\d+(?:\.\d*)?|-?\.\d+)\s*,\s*(-?\d+(?:\.\d*)?|-?\.\d+)\s*\)")
_SPLIT_RE = re.compile(
    r"\s*(?:;|,|\.(?:\s+|$)|\bthen\b|\band\b|\bafter that\b|\bnext\b(?!\s+to)|\bfinally\b|\bfirst\b|\blastly\b)\s*"
)
# Longest phrases first, so "in front of" wins over "in" and "on top of" over "on".
_RELATIONS: list[tuple[str, str]] = [
    (r"on top of", "on"),
    (r"(?:on |to )?the left (?:side )?of", "left"),
    (r"(?:on |to )?the right (?:side )?of", "right"),
    (r"left of", "left"),
    (r"right of", "right"),
    (r"in front of", "front"),
    (r"behind|in back of", "behind"),
    (r"next to|beside|by|near", "nearest"),
    (r"into|inside of|inside|in", "in"),
    (r"onto|on|upon", "on"),
    (r"at|to", "at"),
]
_VERBS = r"(?:put|place|move|stack|set|drop|bring|transfer)"
_CLAUSE_RE = re.compile(
    rf"^(?:(?:please|now|also)\s+)*(?:{_VERBS}\s+)?(?:the\s+)?(?P<obj>[a-z]+\s+(?:block|cube|bowl))\s+"
    rf"(?P<rel>{'|'.join(f'(?:{p})' for p, _ in _RELATIONS)})\s+(?P<rest>.+)$"
)
_OBJECT_RE = re.compile(r"^(?:the\s+)?(?P<name>[a-z]+\s+(?:block|cube|bowl))$")
_NOTHING = {"do nothing", "nothing", "none", "no action", "stay"}


class ParseError(ValueError):
    """y is not in the canonical phrasing (``syntax``) or names objects not on the table."""

    def __init__(self, message: str, *, kind: Literal["syntax", "unknown_object"], details: dict) -> None:
        super().__init__(message)
        self.kind = kind
        self.details = details

    def failure(self) -> ExecutionFailure:
        return ExecutionFailure(stage="parse", message=str(self), details={"kind": self.kind, **self.details})


def _relation(phrase: str) -> str:
    for pattern, rel in _RELATIONS:
        if re.fullmatch(pattern, phrase):
            return rel
    raise AssertionError(phrase)  # the clause regex only matches listed phrases


def _normalize(text: str) -> str:
    text = text.lower().replace("grey", "gray").replace("\u2019", "'").replace("\u2013", "-")
    text = " ".join(text.split()).strip().rstrip(".!").strip()
    return text


def _object(text: str) -> str:
    name = " ".join(text.split())
    return name[: -len("cube")] + "block" if name.endswith(" cube") else name


def _clause(
    clause: str, points: list[tuple[float, float]], scene: frozenset[str], unknown: list[str]
) -> Skill | None:
    """One skill, or None if the clause is not in the canonical phrasing."""
    m = _CLAUSE_RE.match(clause)
    if not m:
        return None
    block = _object(m["obj"])
    rel = _relation(m["rel"])
    rest = m["rest"].strip()
    if (pm := re.fullmatch(r"(?:the\s+)?(?:point\s+)?xy(\d+)", rest)) and rel in ("at", "in", "on"):
        return PutAt(block=block, position=points[int(pm[1])])
    if (key := position_key(rest)) is not None and rel in ("at", "in", "on"):
        return PutAt(block=block, position=key)
    om = _OBJECT_RE.match(rest)
    if not om:
        return None
    target = _object(om["name"])
    unknown.extend(n for n in (block, target) if n not in scene)
    if rel in ("left", "right", "front", "behind", "nearest"):
        return PutNextTo(block=block, target=target, side=rel)  # type: ignore[arg-type]
    if kind_of(target) == "bowl":
        return PutIn(block=block, bowl=target)
    return PutOn(block=block, target=target)


def parse_instruction(text: str, objects: Sequence[str] | WorldState) -> list[Skill]:
    """The plan for y over ``objects`` (the scene's object names); raises :class:`ParseError`."""
    names = list(objects.names) if isinstance(objects, WorldState) else list(objects)
    listing = ", ".join(names)
    norm = _normalize(str(text))
    if norm in _NOTHING:
        return []
    points: list[tuple[float, float]] = []

    def protect(m: re.Match) -> str:
        points.append((float(m[1]), float(m[2])))
        return f" xy{len(points) - 1} "

    protected = _POINT_RE.sub(protect, norm)
    clauses = [c.strip() for c in _SPLIT_RE.split(protected) if c and c.strip()]
    if not clauses:
        raise ParseError("the instruction is empty", kind="syntax", details={"objects": names})
    plan: list[Skill] = []
    unknown: list[str] = []
    scene = frozenset(names)
    for clause in clauses:
        step = _clause(clause, points, scene, unknown)
        if step is None:
            raise ParseError(
                f"cannot read {clause!r} as 'put the <colour> block in/on/next to/left of/right of/"
                f"in front of/behind the <object>' or '... at the <table position>'",
                kind="syntax", details={"clause": clause, "objects": names},
            )
        plan.append(step)
    if unknown:
        missing = list(dict.fromkeys(unknown))
        raise ParseError(
            f"not on the table: {', '.join(missing)}; the objects are: {listing}",
            kind="unknown_object", details={"unknown": missing, "objects": names},
        )
    return plan
