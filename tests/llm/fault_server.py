"""A local OpenAI-compatible HTTP server that misbehaves on cue (for retry/error tests).

Each POST to /v1/chat/completions takes the next scripted behaviour; the JSON bodies it received
are kept in ``requests`` so tests can check how messages were encoded.
"""

from __future__ import annotations

import json
import threading
from collections import deque
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any


def completion_body(content: str, *, model: str = "fake") -> dict[str, Any]:
    return {
        "id": "chatcmpl-fake",
        "object": "chat.completion",
        "created": 0,
        "model": model,
        "choices": [
            {
                "index": 0,
                "message": {"role": "assistant", "content": content},
                "finish_reason": "stop",
            }
        ],
        "usage": {"prompt_tokens": 11, "completion_tokens": 7, "total_tokens": 18},
    }


class Ok:
    def __init__(self, content: str) -> None:
        self.content = content


class Status:
    def __init__(self, code: int, message: str = "injected failure", headers: dict[str, str] | None = None) -> None:
        self.code, self.message, self.headers = code, message, headers or {}


class Raw:
    """A 200 with exactly these body bytes (not UTF-8, not JSON, the wrong shape, NaN...)."""

    def __init__(self, body: bytes) -> None:
        self.body = body


class Drip:
    """A valid answer, headers included, one byte every ``interval`` seconds."""

    def __init__(self, interval: float, content: str = "dripped") -> None:
        self.interval, self.content = interval, content


class Huge:
    """A 200 promising ``total`` bytes and sending them for as long as the client reads."""

    def __init__(self, total: int) -> None:
        self.total = total


class Hang:
    """Never answer (until the server shuts down): the client's timeout must fire."""


class Truncated:
    """Send the first half of a valid JSON body with a matching Content-Length."""

    def __init__(self, content: str = "{}") -> None:
        self.content = content


class Dropped:
    """Promise a full body, send half, close the connection."""

    def __init__(self, content: str = "{}") -> None:
        self.content = content


class Gzip:
    """A 200 whose body is ``body`` gzip-compressed (``Content-Encoding: gzip``), whatever the
    client asked for: a bomb when ``body`` is large and repetitive."""

    def __init__(self, compressed: bytes) -> None:
        self.compressed = compressed


class Redirect:
    """A redirect (307 by default) to ``location``."""

    def __init__(self, location: str, code: int = 307) -> None:
        self.location, self.code = location, code


class FaultServer:
    def __init__(self) -> None:
        self.script: deque[Any] = deque()
        self.requests: list[dict[str, Any]] = []
        self.headers: list[dict[str, str]] = []  # each POST's request headers
        self.default: Any = Ok("default answer")
        self.bytes_sent = 0  # by Huge
        self._release = threading.Event()
        server = self

        class Handler(BaseHTTPRequestHandler):
            protocol_version = "HTTP/1.1"

            def log_message(self, *args: Any) -> None:  # keep pytest output clean
                pass

            def do_GET(self) -> None:
                self._send(200, json.dumps({"object": "list", "data": [{"id": "fake"}]}).encode())

            def do_POST(self) -> None:
                length = int(self.headers.get("Content-Length", 0))
                body = json.loads(self.rfile.read(length) or b"{}")
                server.requests.append(body)
                server.headers.append({k.lower(): v for k, v in self.headers.items()})
                action = server.script.popleft() if server.script else server.default
                if isinstance(action, Ok):
                    payload = json.dumps(completion_body(action.content, model=body.get("model", "")))
                    self._send(200, payload.encode())
                elif isinstance(action, Status):
                    err = {"error": {"message": action.message, "type": "injected", "code": action.code}}
                    self._send(action.code, json.dumps(err).encode(), action.headers)
                elif isinstance(action, Raw):
                    self._send(200, action.body)
                elif isinstance(action, Drip):
                    body = json.dumps(completion_body(action.content)).encode()
                    head = (f"HTTP/1.1 200 OK\r\nContent-Type: application/json\r\n"
                            f"Content-Length: {len(body)}\r\n\r\n").encode()
                    self.close_connection = True
                    try:
                        for i in range(len(head + body)):
                            if server._release.wait(action.interval):
                                return
                            self.wfile.write((head + body)[i:i + 1])
                            self.wfile.flush()
                    except OSError:  # the client gave up
                        return
                elif isinstance(action, Huge):
                    self.send_response(200)
                    self.send_header("Content-Type", "application/json")
                    self.send_header("Content-Length", str(action.total))
                    self.end_headers()
                    self.close_connection = True
                    chunk = b" " * 65536
                    try:
                        while server.bytes_sent < action.total and not server._release.is_set():
                            self.wfile.write(chunk)
                            server.bytes_sent += len(chunk)
                    except OSError:  # the client stopped reading and closed
                        return
                elif isinstance(action, Gzip):
                    self._send(200, action.compressed, {"Content-Encoding": "gzip"})
                elif isinstance(action, Redirect):
                    self._send(action.code, b"", {"Location": action.location})
                elif isinstance(action, Hang):
                    server._release.wait()
                    self.close_connection = True
                elif isinstance(action, Truncated):
                    full = json.dumps(completion_body(action.content)).encode()
                    self._send(200, full[: len(full) // 2])
                elif isinstance(action, Dropped):
                    full = json.dumps(completion_body(action.content)).encode()
                    self.send_response(200)
                    self.send_header("Content-Type", "application/json")
                    self.send_header("Content-Length", str(len(full)))
                    self.end_headers()
                    self.wfile.write(full[: len(full) // 2])
                    self.wfile.flush()
                    self.close_connection = True
                else:
                    raise AssertionError(f"unknown action {action!r}")

            def _send(self, code: int, payload: bytes, headers: dict[str, str] | None = None) -> None:
                self.send_response(code)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(payload)))
                for name, value in (headers or {}).items():
                    self.send_header(name, value)
                self.end_headers()
                self.wfile.write(payload)

        self.httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.httpd.daemon_threads = True
        self.thread = threading.Thread(target=self.httpd.serve_forever, args=(0.02,), daemon=True)

    @property
    def base_url(self) -> str:
        return f"http://127.0.0.1:{self.httpd.server_address[1]}/v1"

    def __enter__(self) -> FaultServer:
        self.thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._release.set()
        self.httpd.shutdown()
        self.httpd.server_close()
        self.thread.join(timeout=5)
