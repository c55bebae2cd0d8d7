"""Shared constants and checks for the act tests."""

from __future__ import annotations

import os
import re
import socket
import unicodedata
from pathlib import Path

import pytest

from activeintent.act.isolation import isolation_status
from activeintent.act.sandbox import SandboxLimits

SECRET_NAME = "ACTIVEINTENT_FAKE_API_KEY"
SECRET_VALUE = "sk-fake-7f3a9c1e2b4d6f8a0c2e4a6b8d0f"
TEST_LIMITS = SandboxLimits(cpu_seconds=1, wall_seconds=3.0, memory_mb=128)

_UNCLEAN = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u200b-\u200f\u2028-\u202e\u2060-\u2069\ufeff\ud800-\udfff]")
_ADDRESS = re.compile(r"0x[0-9a-fA-F]{8,}")


def require_namespaces() -> None:
    """Skip a test that needs bubblewrap namespaces where there are none — but fail in CI
    (environment CI set), where a missing bubblewrap is a broken set-up, not a reason to skip."""
    status = isolation_status()
    if status.available:
        return
    message = f"sandbox namespaces unavailable: {status.detail}"
    if os.environ.get("CI"):
        pytest.fail(message + " (CI is set: bubblewrap must be installed and working)")
    pytest.skip(message)


def assert_no_connection(srv: socket.socket) -> None:
    """Fail if anything connected to the (non-blocking) test server."""
    try:
        conn, addr = srv.accept()
    except BlockingIOError:
        return
    conn.close()
    raise AssertionError(f"the sandbox reached the test server from {addr}")


def assert_no_datagram(srv: socket.socket) -> None:
    try:
        data, addr = srv.recvfrom(4096)
    except BlockingIOError:
        return
    raise AssertionError(f"the sandbox sent a datagram {data[:40]!r} from {addr}")


def unclean(c: str) -> bool:
    """A character cleaned text must not hold, by Unicode's categories (not the cleaner's table):
    controls but tab and newline, format characters (bidi, zero-width, soft hyphen, tags,
    interlinear annotation...), line and paragraph separators, surrogates, the tag block."""
    return ((unicodedata.category(c) in ("Cc", "Cf", "Zl", "Zp", "Cs") and c not in "\t\n")
            or 0xE0000 <= ord(c) <= 0xE007F)


def assert_clean_text(text: str | None, limit: int = 4000) -> None:
    """Valid UTF-8, no control or formatting characters but newline and tab, no addresses."""
    if text is None:
        return
    text.encode("utf-8")  # raises on lone surrogates
    assert not _UNCLEAN.search(text), repr(text[:200])
    assert not any(unclean(c) for c in text), repr(text[:200])
    assert not _ADDRESS.search(text), repr(text[:200])
    assert len(text) <= limit


def process_state(pid: int) -> str:
    """The one-letter state of a process ('T' stopped, 't' traced, 'Z' zombie...)."""
    with open(f"/proc/{pid}/stat") as f:
        return f.read().rsplit(")", 1)[1].split()[0]


def descendants(pid: int) -> list[int]:
    """Every process below ``pid`` (host pids), from /proc."""
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                ppid = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(ppid, []).append(int(entry.name))
    out, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            out.append(child)
            todo.append(child)
    return out
