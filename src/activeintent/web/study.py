"""A study file for `activeintent serve --study FILE`: the consent text, the completion code and
redirect, and the study's conditions (method × rule × guess display), with participants
assigned to the conditions in a balanced way.

The file is JSON (``.json``) or TOML (``.toml``)::

    consent = "You are invited to take part in a study …"
    completion_code = "C1A2B3"
    redirect_url = "https://app.prolific.com/submissions/complete?cc=C1A2B3"

    [[conditions]]
    name = "pref-hidden"
    method = "bayes-preference"
    intention = "color-match"

Assignment (:class:`Assigner`): each new participant gets the condition with the fewest
participants so far; ties go by an order shuffled once with ``assignment_seed``. The counts are
kept in ``OUT/assignment.json``, so a restarted server goes on where it stopped, and a
participant ID seen before gets its condition again (and is not counted twice).
"""

from __future__ import annotations

import json
import random
import re
import threading
import tomllib
from pathlib import Path

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from activeintent.learners.registry import check_method
from activeintent.signals import get_signal
from activeintent.suites import resolve
from activeintent.web.basics import ESTIMATE_MODES, EstimateMode, write_json

# Participant IDs come from a link (Prolific and similar put 24 hex digits there): short, and
# only characters that are safe in a file, a CSV cell and a URL.
PID_PATTERN = re.compile(r"^[A-Za-z0-9_-]{1,64}$")
PID_RULE = "1 to 64 characters: letters, digits, '_' and '-' only"
URL_PARAMETERS = ("pid", "PROLIFIC_PID", "STUDY_ID", "SESSION_ID")


def check_pid(value: str, what: str = "participant ID") -> str:
    """``value`` if it is a valid ID, else ValueError saying what a valid one looks like."""
    if not isinstance(value, str) or not PID_PATTERN.fullmatch(value):
        shown = value[:20] + "…" if isinstance(value, str) and len(value) > 20 else value
        raise ValueError(f"the {what} {shown!r} is not valid: {PID_RULE}")
    return value


class StudyFileError(ValueError):
    """A study file that cannot be read or does not describe a study (the message says why)."""


class Condition(BaseModel):
    """One cell of the design: the learner, the rule (assigned or free) and the guess display."""

    model_config = ConfigDict(extra="forbid")

    name: str = Field(pattern=r"^[A-Za-z0-9_.-]{1,40}$", description="a short name, stored with every session")
    method: str = Field(description="the learner, as `serve --method`")
    intention: str | None = Field(None, description="the assigned rule (None and no intention_file: free rule)")
    intention_file: str | None = Field(None, description="an assigned rule of your own: path.py:NAME")
    show_estimate: EstimateMode = Field("hidden", description=f"the learner's guess: {', '.join(ESTIMATE_MODES)}")

    @field_validator("method")
    @classmethod
    def _known_method(cls, v: str) -> str:
        check_method(v)  # its error lists the methods there are
        return v

    @model_validator(mode="after")
    def _known_rule(self) -> Condition:
        if self.intention or self.intention_file:
            try:
                resolve(None if self.intention_file else self.intention, self.intention_file)
            except Exception as err:  # the resolver's message lists the rules there are
                raise ValueError(str(err)) from None
        return self


class StudyFile(BaseModel):
    """What participants read and get beyond the rounds, and the conditions they are assigned."""

    model_config = ConfigDict(extra="forbid")

    consent: str = Field(min_length=1, max_length=20_000,
                         description="the consent text (paragraphs separated by blank lines)")
    completion_code: str | None = Field(None, pattern=r"^[A-Za-z0-9_-]{1,64}$",
                                        description="shown once the questionnaire is sent")
    redirect_url: str | None = Field(None, max_length=2000, pattern=r"^https?://\S+$",
                                     description="where the browser goes after the questionnaire")
    redirect_after_s: float | None = Field(
        5.0, ge=0, le=600, description="seconds before the automatic redirect (None: a link only)")
    require_pid: bool = Field(True, description="refuse sessions without a participant ID from the URL")
    rounds: int | None = Field(None, ge=1, le=100, description="K (default: serve --budget)")
    assignment_seed: int = Field(0, ge=0, description="orders the conditions for ties")
    counterbalance_buttons: bool = Field(True, description="rotate the answer buttons' order across participants")
    conditions: list[Condition] = Field(min_length=1, max_length=64)

    @model_validator(mode="after")
    def _unique_names(self) -> StudyFile:
        names = [c.name for c in self.conditions]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise ValueError(f"condition names must differ; given more than once: {', '.join(twice)}")
        return self

    def condition(self, name: str) -> Condition:
        for c in self.conditions:
            if c.name == name:
                return c
        raise ValueError(f"unknown condition {name!r}; the study's conditions: "
                         f"{', '.join(c.name for c in self.conditions)}")


def load_study(path: Path) -> StudyFile:
    """The study in ``path`` (.json or .toml); StudyFileError with the file's problems."""
    suffix = path.suffix.lower()
    if suffix not in (".json", ".toml"):
        raise StudyFileError(f"{path.name}: a study file is .json or .toml")
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise StudyFileError(f"{path}: {err.strerror or err}") from None
    try:
        data = json.loads(text) if suffix == ".json" else tomllib.loads(text)
    except (ValueError, tomllib.TOMLDecodeError) as err:
        raise StudyFileError(f"{path.name} is not valid {suffix[1:].upper()}: {err}") from None
    try:
        return StudyFile.model_validate(data)
    except ValidationError as err:
        problems = "; ".join(f"{'.'.join(str(p) for p in e['loc']) or 'file'}: {e['msg']}" for e in err.errors())
        raise StudyFileError(f"{path.name}: {problems}") from None


class Assignment(BaseModel):
    condition: str
    slot: int = Field(description="participants of this condition before this one (counterbalances the buttons)")
    number: int = Field(description="participants of the study before this one")
    again: bool = Field(False, description="a participant ID seen before: its earlier condition")


class Assigner:
    """Balanced, deterministic assignment to conditions, persisted in ``path`` (if given)."""

    def __init__(self, conditions: list[str], seed: int = 0, path: Path | None = None):
        if not conditions:
            raise ValueError("an assignment needs at least one condition")
        self.path = path
        self.tie_order = list(conditions)
        random.Random(seed).shuffle(self.tie_order)
        self.counts = dict.fromkeys(conditions, 0)
        self.participants: dict[str, dict] = {}
        self.total = 0
        self._lock = threading.Lock()
        if path is not None and path.exists():
            self._load(path)

    def _load(self, path: Path) -> None:
        try:
            saved = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError) as err:
            raise ValueError(f"{path} cannot be read ({err}); move it away to start the counts afresh") from None
        for name, n in saved.get("counts", {}).items():
            if name in self.counts:  # a condition dropped from the study keeps no count
                self.counts[name] = int(n)
        self.participants = {p: a for p, a in saved.get("participants", {}).items() if a.get("condition") in self.counts}
        self.total = int(saved.get("total", sum(self.counts.values())))

    def _save(self) -> None:
        if self.path is None:
            return
        self.path.parent.mkdir(parents=True, exist_ok=True)
        write_json(self.path, {"counts": self.counts, "tie_order": self.tie_order, "total": self.total,
                               "participants": self.participants})

    def peek(self, pid: str | None = None) -> str:
        """The condition :meth:`assign` would give now, counting nothing (a participant who has
        agreed but not pressed Start yet holds no place in the counts)."""
        with self._lock:
            if pid is not None and pid in self.participants:
                return self.participants[pid]["condition"]
            return min(self.tie_order, key=lambda c: (self.counts[c], self.tie_order.index(c)))

    def assign(self, pid: str | None = None, condition: str | None = None) -> Assignment:
        """Count a participant in: a participant ID seen before gets its earlier condition;
        else ``condition`` (the one :meth:`peek` told them of) or the least filled one."""
        with self._lock:
            if pid is not None and pid in self.participants:
                return Assignment(**self.participants[pid], again=True)
            # least filled first; among equals, the seeded order
            name = condition if condition in self.counts else min(
                self.tie_order, key=lambda c: (self.counts[c], self.tie_order.index(c)))
            got = Assignment(condition=name, slot=self.counts[name], number=self.total)
            self.counts[name] += 1
            self.total += 1
            if pid is not None:
                self.participants[pid] = got.model_dump(exclude={"again"})
            self._save()
            return got


def button_order(signal: str, slot: int, counterbalance: bool = True) -> list[str]:
    """The answer buttons of participant ``slot`` (the signal's counterbalanced order)."""
    return get_signal(signal).button_order(slot, counterbalance)


