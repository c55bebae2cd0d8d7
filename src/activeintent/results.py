"""``results.jsonl`` of a benchmark: read and checked line by line (a line is trusted only if it
validates against the record schema and its episode has no earlier record), untrusted lines set
aside into ``rejected.jsonl``, appends that always start on a new line and reach the disk, and
the lock that makes one process the folder's only writer.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from activeintent.memo import memoized
from activeintent.protocol import FORMAT_VERSION
from activeintent.records import EpisodeResult, dumps


class ErrorRecord(BaseModel):
    """A results line of an episode that ended without a result (a crash, a dead worker)."""

    model_config = ConfigDict(strict=True, extra="allow")

    format: int = Field(ge=1)
    method: str = Field(min_length=1)
    intention: str = Field(min_length=1)
    trial: int = Field(ge=0)
    success: None = None
    error: str = Field(min_length=1)


@memoized(size=1, why="no arguments: the model class is built once (a pure function of EpisodeResult)")
def _result_model() -> type[BaseModel]:
    """A results line of a finished episode: its EpisodeResult (without the per-scene tests)
    plus the bench's trial. Strict: a number written as a string is not a number."""
    class ResultRecord(EpisodeResult):
        model_config = ConfigDict(strict=True, extra="allow")

        format: int = Field(ge=1)
        method: str = Field(min_length=1)
        intention: str = Field(min_length=1)
        trial: int = Field(ge=0)
        success: float | None = Field(ge=0, le=1)

    return ResultRecord


def record_problem(rec: object) -> str | None:
    """Why a parsed results line is not a record this code wrote (None: it is one)."""
    if not isinstance(rec, dict):
        return f"not a JSON object but {type(rec).__name__}"
    model = ErrorRecord if rec.get("error") else _result_model()
    try:
        model.model_validate(rec)
    except ValidationError as err:
        return "; ".join(f"{'.'.join(map(str, e['loc'])) or 'record'}: {e['msg']}" for e in err.errors()[:3])
    return None


class Rejected(BaseModel):
    """A line of ``results.jsonl`` that is not trusted: set aside, never counted."""

    line: int  # 1-based, in the file as it was read
    reason: str
    text: str  # the line as read (undecodable bytes as \x escapes)
    kind: str = "invalid"  # one of REJECT_KINDS: what the report counts by


# Why a line is set aside, as the report counts them.
REJECT_KINDS = {
    "undecodable": "not UTF-8 or not JSON",
    "invalid": "not a valid record (schema)",
    "plan": "not of this folder's plan (method, intention, trial, settings, seeds)",
    "inconsistent": "inconsistent with itself (format, curve, provenance)",
    "duplicate": "more than one record of one episode",
}

Key = tuple[str, str, int]


@dataclass
class Candidate:
    """A valid line of ``results.jsonl``: its line number, record and bytes as read."""

    line: int
    record: dict
    raw: bytes

    @property
    def key(self) -> Key:
        return (self.record["method"], self.record["intention"], self.record["trial"])


@dataclass
class Loaded:
    lines: list[Candidate] = field(default_factory=list)  # the valid lines, in file order (duplicates included)
    rejected: list[Rejected] = field(default_factory=list)

    @property
    def duplicates(self) -> dict[Key, list[Candidate]]:
        """Episodes with more than one valid record."""
        by_key: dict[Key, list[Candidate]] = {}
        for c in self.lines:
            by_key.setdefault(c.key, []).append(c)
        return {k: v for k, v in by_key.items() if len(v) > 1}

    @property
    def records(self) -> list[dict]:
        """One per episode: the records of episodes recorded once."""
        dup = self.duplicates
        return [c.record for c in self.lines if c.key not in dup]

    @property
    def raw(self) -> list[bytes]:
        """The lines kept in the file (duplicates included), as read."""
        return [c.raw for c in self.lines]

    def set_aside_duplicates(self) -> Loaded:
        """What a reader that runs no episode does with an episode recorded more than once: it
        cannot tell the real record from a forged one, so it sets every one of them aside."""
        dup = self.duplicates
        for key, cands in dup.items():
            lines = ", ".join(str(c.line) for c in cands)
            self.rejected += [Rejected(
                line=c.line, kind="duplicate", text=c.raw.decode("utf-8", "backslashreplace"),
                reason=f"one of {len(cands)} records of {key[0]} / {key[1]} / trial {key[2]} (lines {lines}); "
                       "without re-running the episode none can be trusted") for c in cands]
        self.lines = [c for c in self.lines if c.key not in dup]
        self.rejected.sort(key=lambda r: r.line)
        return self


Check = Callable[[dict], "tuple[str, str] | None"]  # a record → (kind, reason) when it does not belong


def _reject_reason(data: bytes, check: Check | None) -> tuple[dict | None, str, str]:
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        return None, "undecodable", f"not UTF-8 ({err.reason} at byte {err.start})"
    try:
        rec = json.loads(text, parse_constant=_no_constant)
    except (ValueError, RecursionError) as err:
        return None, "undecodable", f"not JSON ({str(err)[:200]})"
    problem = record_problem(rec)
    if problem:
        return None, "invalid", f"not a valid record ({problem})"
    if check is not None:
        found = check(rec)
        if found is not None:
            return None, found[0], found[1]
    return rec, "", ""


def _no_constant(name: str):
    raise ValueError(f"{name} is not a JSON number")


def load_results(path: Path, check: Check | None = None) -> Loaded:
    """Every line of ``results.jsonl`` checked: undecodable, unparsable and invalid (against the
    record schema) lines, and lines ``check`` refuses (against the folder's plan: see
    bench/checks.py), are rejected with the reason; an episode with several valid records is
    in ``duplicates`` (the resume re-runs it, a reader sets them all aside); the rest are the
    records. Reads only."""
    if not path.exists():
        return Loaded()
    out = Loaded()
    for n, data in enumerate(path.read_bytes().split(b"\n"), start=1):
        if not data.strip():
            continue
        rec, kind, reason = _reject_reason(data, check)
        if rec is None:
            out.rejected.append(Rejected(line=n, kind=kind, reason=reason,
                                         text=data.decode("utf-8", "backslashreplace")))
        else:
            out.lines.append(Candidate(line=n, record=rec, raw=data))
    return out


def read_results(path: Path, check: Check | None = None) -> list[dict]:
    """The trusted records of ``results.jsonl`` (see :func:`load_results`), an episode recorded
    more than once left out; reads only."""
    return load_results(path, check).set_aside_duplicates().records


def append_rejected(path: Path, rejected: list[Rejected]) -> Path | None:
    """Append these lines to ``rejected.jsonl`` beside ``path`` (with their reason), fsynced.
    Only the folder's writer (who holds its lock) may call this."""
    if not rejected:
        return None
    where = path.with_name("rejected.jsonl")
    with where.open("ab") as f:
        for r in rejected:
            f.write((json.dumps({"file": path.name, **r.model_dump()}) + "\n").encode())
        _sync(f)
    return where


def set_aside_rejected(path: Path, loaded: Loaded) -> Path | None:
    """Move the rejected lines of ``path`` into ``rejected.jsonl`` beside it (with their reason)
    and keep only the other lines, byte for byte. Only the folder's writer (who holds its
    lock) may call this. Returns the rejected file, or None when nothing was rejected."""
    where = append_rejected(path, loaded.rejected)
    if where is not None:
        rewrite_results(path, loaded.raw)
    return where


def rejected_counts(folder: Path) -> dict[str, int]:
    """How many lines ``folder/rejected.jsonl`` holds, by kind (REJECT_KINDS; "other" for lines
    of older code, which did not say)."""
    path = folder / "rejected.jsonl"
    counts: dict[str, int] = {}
    if not path.exists():
        return counts
    for line in path.read_bytes().splitlines():
        try:
            kind = json.loads(line).get("kind") or "other"
        except (ValueError, AttributeError, RecursionError):
            kind = "other"
        kind = kind if kind in REJECT_KINDS else "other"
        counts[kind] = counts.get(kind, 0) + 1
    return counts


def rewrite_results(path: Path, lines: list[bytes]) -> None:
    """Replace ``path`` by these lines (atomically: a kill leaves the old or the new file)."""
    tmp = path.with_suffix(".jsonl.tmp")
    with tmp.open("wb") as f:
        f.write(b"".join(line + b"\n" for line in lines))
        _sync(f)
    os.replace(tmp, path)


class FolderBusyError(ValueError):
    """Another process writes this results folder."""


LOCK_NOTE = ".lock"  # the holder's pid, for the message of a refused second writer; not the lock


@contextmanager
def hold_results_folder(folder: Path) -> Iterator[None]:
    """One writer per results folder: two benches on one ``--out`` would run every episode twice.
    An advisory lock (flock) on an open descriptor of the folder itself, held while the body
    runs: removing or replacing any file in it (``rm OUT/.lock``) cannot release it, since the
    lock belongs to the folder's inode. The kernel drops it when this process ends, however it
    ends, so a killed bench never leaves a stale lock. ``OUT/.lock`` only names the holder."""
    import fcntl

    folder.mkdir(parents=True, exist_ok=True)
    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise FolderBusyError(f"{folder} is being written by another process ({_holder(folder)}); "
                                  "wait for it to finish, or use another --out") from None
        note = folder / LOCK_NOTE
        tmp = note.with_name(f"{LOCK_NOTE}.{os.getpid()}.tmp")
        tmp.write_text(f"{os.getpid()}\n")
        os.replace(tmp, note)
        yield
    finally:
        os.close(fd)  # releases the lock


def _holder(folder: Path) -> str:
    """The process named in the folder's lock note: its pid and, when visible, its command line."""
    try:
        pid = (folder / LOCK_NOTE).read_text(encoding="ascii", errors="replace")[:32].strip()
    except OSError:
        pid = ""
    if not pid.isdigit():
        return "pid unknown"
    try:
        cmd = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode("utf-8", "replace").strip()
    except OSError:
        cmd = ""
    return f"pid {pid}" + (f": {cmd[:200]}" if cmd else "")


def _sync(f) -> None:
    f.flush()
    os.fsync(f.fileno())


def append_result(path: Path, record: dict) -> None:
    """One line per finished episode, flushed and fsynced: a kill loses at most what is in flight.
    A file whose last line has no newline (a torn write, an edit) gets one first, so the new
    record never glues onto it."""
    line = (dumps({"format": FORMAT_VERSION, **record}) + "\n").encode()
    with path.open("a+b") as f:  # a+: the last byte must be readable
        size = f.seek(0, os.SEEK_END)
        if size and os.pread(f.fileno(), 1, size - 1) != b"\n":
            line = b"\n" + line
        f.write(line)
        _sync(f)
