"""``results.jsonl`` of a benchmark: read and checked line by line (a line is trusted only if it
validates against the record schema and its episode has no earlier record), untrusted lines set
aside into ``rejected.jsonl``, appends that always start on a new line and reach the disk, and
the lock that makes one process the folder's only writer.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from contextlib import contextmanager
from functools import cache
from pathlib import Path

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from activeintent.protocol import FORMAT_VERSION
from activeintent.records import dumps


class ErrorRecord(BaseModel):
    """A results line of an episode that ended without a result (a crash, a dead worker)."""

    model_config = ConfigDict(strict=True, extra="allow")

    format: int = Field(ge=1)
    method: str = Field(min_length=1)
    intention: str = Field(min_length=1)
    trial: int = Field(ge=0)
    success: None = None
    error: str = Field(min_length=1)


@cache
def _result_model() -> type[BaseModel]:
    """A results line of a finished episode: its EpisodeResult (without the per-scene tests)
    plus the bench's trial. Strict: a number written as a string is not a number."""
    from activeintent.records import EpisodeResult

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


class Loaded(BaseModel):
    records: list[dict]
    rejected: list[Rejected] = Field(default_factory=list)
    raw: list[bytes] = Field(default_factory=list)  # the accepted lines' bytes, as read


def _reject_reason(data: bytes, seen: set) -> tuple[dict | None, str | None]:
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        return None, f"not UTF-8 ({err.reason} at byte {err.start})"
    try:
        rec = json.loads(text, parse_constant=_no_constant)
    except ValueError as err:
        return None, f"not JSON ({err})"
    problem = record_problem(rec)
    if problem:
        return None, f"not a valid record ({problem})"
    key = (rec["method"], rec["intention"], rec["trial"])
    if key in seen:
        return None, f"duplicate of an earlier record of {key[0]} / {key[1]} / trial {key[2]} (the first is kept)"
    seen.add(key)
    return rec, None


def _no_constant(name: str):
    raise ValueError(f"{name} is not a JSON number")


def load_results(path: Path) -> Loaded:
    """Every line of ``results.jsonl`` checked: undecodable, unparsable, invalid (against the
    record schema) and duplicate lines (same method, intention, trial as an earlier valid one)
    are rejected with the reason; the rest are the records. Reads only."""
    if not path.exists():
        return Loaded(records=[])
    out = Loaded(records=[])
    seen: set = set()
    for n, data in enumerate(path.read_bytes().split(b"\n"), start=1):
        if not data.strip():
            continue
        rec, reason = _reject_reason(data, seen)
        if rec is None:
            out.rejected.append(Rejected(line=n, reason=reason or "",
                                         text=data.decode("utf-8", "backslashreplace")))
        else:
            out.records.append(rec)
            out.raw.append(data)
    return out


def read_results(path: Path) -> list[dict]:
    """The valid records of ``results.jsonl`` (see :func:`load_results`); reads only."""
    return load_results(path).records


def set_aside_rejected(path: Path, loaded: Loaded) -> Path | None:
    """Move the rejected lines of ``path`` into ``rejected.jsonl`` beside it (with their reason)
    and keep only the accepted lines, byte for byte. Only the folder's writer (who holds its
    lock) may call this. Returns the rejected file, or None when nothing was rejected."""
    if not loaded.rejected:
        return None
    rejected = path.with_name("rejected.jsonl")
    with rejected.open("ab") as f:
        for r in loaded.rejected:
            f.write((json.dumps({"file": path.name, **r.model_dump()}) + "\n").encode())
        _sync(f)
    rewrite_results(path, loaded.raw)
    return rejected


def rewrite_results(path: Path, lines: list[bytes]) -> None:
    """Replace ``path`` by these lines (atomically: a kill leaves the old or the new file)."""
    tmp = path.with_suffix(".jsonl.tmp")
    with tmp.open("wb") as f:
        f.write(b"".join(line + b"\n" for line in lines))
        _sync(f)
    os.replace(tmp, path)


class FolderBusyError(ValueError):
    """Another process writes this results folder."""


@contextmanager
def hold_results_folder(folder: Path) -> Iterator[None]:
    """One writer per results folder: two benches on one ``--out`` would run every episode twice.
    An advisory lock (flock) on ``folder/.lock``, held while the body runs; the kernel drops it
    when this process ends, however it ends, so a killed bench never leaves a stale lock."""
    import fcntl

    folder.mkdir(parents=True, exist_ok=True)
    fd = os.open(folder / ".lock", os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise FolderBusyError(f"{folder} is being written by another process ({_holder(fd)}); "
                                  "wait for it to finish, or use another --out") from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        yield
    finally:
        os.close(fd)  # releases the lock


def _holder(fd: int) -> str:
    """The process named in a lock file: its pid and, when visible, its command line."""
    pid = os.pread(fd, 32, 0).decode("ascii", "replace").strip()
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
