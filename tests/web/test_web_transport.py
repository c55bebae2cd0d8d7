"""The study server's HTTP transport against a real uvicorn server: what reaches the app, what is
refused before it, and what a client that misbehaves on the connection itself can do.

The connection limits run in a server process of their own with a lowered file-descriptor
limit, so that a flood of idle sockets meets the limit here instead of the machine's."""

from __future__ import annotations

import http.client
import json
import socket
from urllib.parse import urlsplit

import pytest

pytestmark = pytest.mark.slow  # real servers


def host_port(url: str) -> tuple[str, int]:
    parts = urlsplit(url)
    return parts.hostname, parts.port


def read_response(sock: socket.socket, method: str = "POST") -> tuple[int, dict, bytes]:
    res = http.client.HTTPResponse(sock, method=method)
    res.begin()
    return res.status, {k.lower(): v for k, v in res.getheaders()}, res.read()


def error_code(body: bytes) -> str:
    err = json.loads(body)["error"]
    assert isinstance(err["message"], str) and err["message"]
    return err["code"]


# -- W1: a body over the limit, sent in full before the client reads -------------------------------
def test_a_body_over_the_limit_sent_before_reading_gets_its_413(live_server):
    srv = live_server("bayes-stop", rounds=1)
    host, port = host_port(srv.url)
    body = b" " * (10 * 2**20)  # 10 MB, far over the 128 KiB limit
    chunk = 64 * 1024
    chunked = b"".join(b"%x\r\n" % len(body[i:i + chunk]) + body[i:i + chunk] + b"\r\n"
                       for i in range(0, len(body), chunk)) + b"0\r\n\r\n"
    for framing, payload in ((f"Content-Length: {len(body)}", body), ("Transfer-Encoding: chunked", chunked)):
        with socket.create_connection((host, port), timeout=60) as sock:
            head = (f"POST /api/sessions HTTP/1.1\r\nHost: {host}:{port}\r\nContent-Type: application/json\r\n"
                    f"{framing}\r\n\r\n").encode()
            # every byte goes out before a single one is read: a server that answers and closes
            # without reading the rest makes this a connection reset instead of the 413
            sock.sendall(head + payload)
            status, headers, text = read_response(sock)
        assert status == 413, (framing, status, text[:200])
        assert error_code(text) == "body_too_large" and headers["connection"] == "close"
    assert srv.manager.all() == []


# -- ambiguous framing --------------------------------------------------------------------------
def test_a_request_with_both_content_length_and_transfer_encoding_is_refused(live_server):
    srv = live_server("bayes-stop", rounds=1)
    host, port = host_port(srv.url)
    body = b'{"participant": "smuggled"}'
    chunked = b"%x\r\n" % len(body) + body + b"\r\n0\r\n\r\n"
    for headers in ([f"Content-Length: {len(chunked)}", "Transfer-Encoding: chunked"],
                    ["Transfer-Encoding: chunked", f"Content-Length: {len(body)}"],
                    ["Content-Length: 0", "Transfer-Encoding: chunked"]):
        with socket.create_connection((host, port), timeout=30) as sock:
            head = "\r\n".join(["POST /api/sessions HTTP/1.1", f"Host: {host}:{port}",
                                "Content-Type: application/json", *headers]) + "\r\n\r\n"
            sock.sendall(head.encode() + chunked)
            status, res_headers, text = read_response(sock)
        assert status == 400, (headers, status, text[:200])
        assert error_code(text) == "ambiguous_framing" and res_headers["connection"] == "close"
    assert srv.manager.all() == [], "a request with ambiguous framing started a session"
    # one framing header alone is fine: the body reaches the app (here: an unknown session)
    events = b'{"events": [{"type": "x", "client_ts": 1}]}'
    with socket.create_connection((host, port), timeout=30) as sock:
        sock.sendall(f"POST /api/sessions/{'0' * 16}/events HTTP/1.1\r\nHost: {host}:{port}\r\n"
                     "Content-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n".encode()
                     + b"%x\r\n" % len(events) + events + b"\r\n0\r\n\r\n")
        status, _, text = read_response(sock)
    assert status == 404 and error_code(text) == "unknown_session", text[:300]
