"""Content-addressed response cache in SQLite.

The key is the sha256 of backend, model name, the server's base URL (model servers only),
messages (images by their sha256), sampling parameters, schema and the caller's prompt-template
version, so two runs with the same seed
and a warm cache make identical calls and get identical answers. Several processes on one
machine may write to one file (WAL journal, busy timeout). WAL needs every process on the
same host: workers on several machines use one cache file each on a local disk, merged
afterwards (docs/scaling.md).
"""

from __future__ import annotations

import hashlib
import json
import os
import sqlite3
import threading
import time
from pathlib import Path
from typing import Literal, get_args

from activeintent.llm.backend import ChatRequest, Completion
from activeintent.llm.base import ImagePart

CacheMode = Literal["record", "replay", "off"]
CACHE_MODES: tuple[str, ...] = get_args(CacheMode)


def default_cache_path() -> Path:
    return Path.home() / ".cache" / "activeintent" / "responses.sqlite"


def check_mode(mode: str) -> CacheMode:
    if mode not in CACHE_MODES:
        raise ValueError(f"unknown cache mode {mode!r}; valid modes: {', '.join(CACHE_MODES)}")
    return mode  # type: ignore[return-value]


# Set to 1: also read entries recorded before keys named the server (see ResponseCache).
ENV_LEGACY_KEYS = "ACTIVEINTENT_CACHE_LEGACY_KEYS"


def request_fingerprint(backend: str, model: str, request: ChatRequest, prompt_version: str,
                        server: str | None = None) -> dict:
    """The canonical, JSON-able content the key hashes (images replaced by their sha256).
    ``server``: the base URL of a model server (None for an in-process model: its keys are as
    they always were); two servers serving a model of one name are two models."""
    messages = []
    for m in request.messages:
        if isinstance(m.content, str):
            content: object = m.content
        else:
            content = [
                {"image_sha256": hashlib.sha256(p.png).hexdigest()}
                if isinstance(p, ImagePart)
                else {"text": p.text}
                for p in m.content
            ]
        messages.append({"role": m.role, "content": content})
    server_part = {} if server is None else {"server": server}
    return {
        **server_part,
        "backend": backend,
        "model": model,
        "messages": messages,
        "params": {
            "temperature": request.temperature,
            "max_tokens": request.max_tokens,
            "seed": request.seed,
        },
        "schema": request.json_schema,
        "prompt_version": prompt_version,
    }


_SCHEMA = """
CREATE TABLE IF NOT EXISTS responses (
    key TEXT PRIMARY KEY,
    backend TEXT NOT NULL,
    model TEXT NOT NULL,
    text TEXT NOT NULL,
    prompt_tokens INTEGER NOT NULL,
    completion_tokens INTEGER NOT NULL,
    finish_reason TEXT,
    created REAL NOT NULL
)
"""


class ResponseCache:
    """``record`` (default): answer from the cache, call the model on a miss and store it;
    ``replay``: a miss is a :class:`CacheMissError`; ``off``: neither read nor write.

    Keys of a model server's answers name its base URL. Entries recorded before that (keys
    without a server) are not read, since they may come from any server serving a model of that
    name; ``legacy_keys`` (default: the environment variable ACTIVEINTENT_CACHE_LEGACY_KEYS=1)
    reads them when no entry of the server is found. They are never written."""

    def __init__(self, path: str | Path | None = None, mode: str = "record", *, legacy_keys: bool | None = None) -> None:
        self.mode: CacheMode = check_mode(mode)
        self.legacy_keys = os.environ.get(ENV_LEGACY_KEYS, "") == "1" if legacy_keys is None else legacy_keys
        self.path = Path(path).expanduser() if path is not None else default_cache_path()
        self._lock = threading.Lock()
        self._conn: sqlite3.Connection | None = None
        self._pid = -1

    def _connection(self) -> sqlite3.Connection:
        # One connection per process: a forked child must not reuse its parent's.
        if self._conn is None or self._pid != os.getpid():
            self.path.parent.mkdir(parents=True, exist_ok=True)
            conn = sqlite3.connect(self.path, timeout=30.0, check_same_thread=False)
            conn.execute("PRAGMA busy_timeout = 30000")
            conn.execute("PRAGMA journal_mode = WAL")
            conn.execute("PRAGMA synchronous = NORMAL")
            conn.execute(_SCHEMA)
            conn.commit()
            self._conn, self._pid = conn, os.getpid()
        return self._conn

    @staticmethod
    def key(backend: str, model: str, request: ChatRequest, prompt_version: str = "", server: str | None = None) -> str:
        blob = json.dumps(
            request_fingerprint(backend, model, request, prompt_version, server),
            sort_keys=True,
            separators=(",", ":"),
            ensure_ascii=False,
        )
        return hashlib.sha256(blob.encode("utf-8")).hexdigest()

    def get(self, key: str) -> Completion | None:
        if self.mode == "off":
            return None
        with self._lock:
            row = self._connection().execute(
                "SELECT text, prompt_tokens, completion_tokens, finish_reason"
                " FROM responses WHERE key = ?",
                (key,),
            ).fetchone()
        if row is None:
            return None
        return Completion(
            text=row[0], prompt_tokens=row[1], completion_tokens=row[2], finish_reason=row[3]
        )

    def put(self, key: str, completion: Completion, *, backend: str, model: str) -> None:
        if self.mode != "record":
            return
        with self._lock:
            conn = self._connection()
            conn.execute(
                "INSERT OR REPLACE INTO responses VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
                (
                    key,
                    backend,
                    model,
                    completion.text,
                    completion.prompt_tokens,
                    completion.completion_tokens,
                    completion.finish_reason,
                    time.time(),
                ),
            )
            conn.commit()

    def __len__(self) -> int:
        with self._lock:
            return self._connection().execute("SELECT COUNT(*) FROM responses").fetchone()[0]

    def describe_miss(self, key: str, request: ChatRequest) -> str:
        last_user = next((m for m in reversed(request.messages) if m.role == "user"), None)
        excerpt = last_user.text[:200] if last_user is not None else ""
        return (
            f"replay mode: no cached answer in {self.path} for request {key} "
            f"(last user message starts: {excerpt!r}); run once with --cache-mode record"
        )

    def close(self) -> None:
        with self._lock:
            if self._conn is not None and self._pid == os.getpid():
                self._conn.close()
            self._conn = None
