"""Shared constants and checks for the act tests."""

from __future__ import annotations

import socket

SECRET_NAME = "ACTIVEINTENT_FAKE_API_KEY"
SECRET_VALUE = "sk-fake-7f3a9c1e2b4d6f8a0c2e4a6b8d0f"


def assert_no_connection(srv: socket.socket) -> None:
    """Fail if anything connected to the (non-blocking) test server."""
    try:
        conn, addr = srv.accept()
    except BlockingIOError:
        return
    conn.close()
    raise AssertionError(f"the sandbox reached the test server from {addr}")
