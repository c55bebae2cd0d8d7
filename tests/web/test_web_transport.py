"""The study server's HTTP transport against a real uvicorn server: what reaches the app, what is
refused before it, and what a client that misbehaves on the connection itself can do.

The connection limits run in a server process of their own with a lowered file-descriptor
limit, so that a flood of idle sockets meets the limit here instead of the machine's."""

from __future__ import annotations

import http.client
import json
import os
import resource
import socket
import subprocess
import sys
import time
from pathlib import Path
from urllib.parse import urlsplit

import httpx
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


# -- header and body timeouts --------------------------------------------------------------------
def test_a_head_or_body_that_trickles_in_is_cut_off_with_a_408(live_server):
    srv = live_server("bayes-stop", rounds=1, limits={"header_timeout": 1.0, "body_timeout": 1.0})
    host, port = host_port(srv.url)

    def answered_within(sock: socket.socket, seconds: float) -> tuple[int, bytes]:
        started = time.monotonic()
        status, _, text = read_response(sock)
        assert time.monotonic() - started < seconds
        assert sock.recv(1) == b""  # and closed
        return status, text

    # a request head that never ends (one header line, then nothing)
    with socket.create_connection((host, port), timeout=20) as sock:
        sock.sendall(f"GET /api/config HTTP/1.1\r\nHost: {host}:{port}\r\nX-Slow: 1".encode())
        status, text = answered_within(sock, 10)
    assert status == 408 and error_code(text) == "request_timeout"
    # a body that stops after ten of its hundred bytes
    with socket.create_connection((host, port), timeout=20) as sock:
        sock.sendall(f"POST /api/sessions HTTP/1.1\r\nHost: {host}:{port}\r\nContent-Type: application/json\r\n"
                     "Content-Length: 100\r\n\r\n{\"partici".encode())
        status, text = answered_within(sock, 10)
    assert status == 408 and error_code(text) == "request_timeout"
    # a kept-alive connection gets the header timeout again after each answer
    with socket.create_connection((host, port), timeout=20) as sock:
        for _ in range(2):
            sock.sendall(f"GET /api/config HTTP/1.1\r\nHost: {host}:{port}\r\n\r\n".encode())
            status, _, _ = read_response(sock, "GET")
            assert status == 200
        sock.sendall(b"GET /api/config HTTP/1.1\r\n")
        status, text = answered_within(sock, 10)
    assert status == 408
    assert srv.manager.all() == []


# -- W2: idle connections, per address and up to the file-descriptor limit ---------------------------
NOFILE = 256  # the server process's RLIMIT_NOFILE in this test


def _lower_nofile() -> None:
    resource.setrlimit(resource.RLIMIT_NOFILE, (NOFILE, NOFILE))


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _idle_socket(address: str, port: int) -> socket.socket | None:
    """A connection from ``address`` that sends nothing (None when the connect itself fails)."""
    s = socket.socket()
    s.settimeout(10)
    try:
        s.bind((address, 0))
        s.connect(("127.0.0.1", port))
    except OSError:
        s.close()
        return None
    return s


def _closed_by_server(s: socket.socket, wait: float) -> bytes | None:
    """What the server sent before closing ``s`` within ``wait`` s (None: still open)."""
    s.settimeout(wait)
    data = b""
    try:
        while True:
            got = s.recv(65536)
            if not got:
                return data
            data += got
    except TimeoutError:
        return None
    except ConnectionResetError:
        return data


def _get(address: str, url: str, timeout: float = 20.0) -> httpx.Response:
    with httpx.Client(transport=httpx.HTTPTransport(local_address=address), timeout=timeout) as c:
        return c.get(url)


def test_idle_connections_from_one_address_neither_lock_others_out_nor_flood_the_log(tmp_path):
    port = _free_port()
    log_path = tmp_path / "serve.log"
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2] / "src")}
    with log_path.open("wb") as log:
        proc = subprocess.Popen(
            [sys.executable, "-m", "activeintent.cli", "serve", "--port", str(port), "--method", "bayes-stop",
             "--llm", "none", "--budget", "1", "--video-size", "64", "--out", str(tmp_path / "study")],
            stdout=log, stderr=subprocess.STDOUT, preexec_fn=_lower_nofile, env=env)
    url = f"http://127.0.0.1:{port}"
    idle: list[socket.socket] = []
    try:
        deadline = time.monotonic() + 120
        while True:
            assert proc.poll() is None, log_path.read_text()[-3000:]
            try:
                if httpx.get(f"{url}/api/config", timeout=5).status_code == 200:
                    break
            except httpx.TransportError:
                pass
            assert time.monotonic() < deadline, "the server did not start"
            time.sleep(0.2)

        # 1. one address opens more idle connections than the server has descriptors
        for _ in range(NOFILE + 150):
            s = _idle_socket("127.0.0.2", port)
            if s is not None:
                idle.append(s)
        assert len(idle) > NOFILE, "the flood did not get its connections"
        started = time.monotonic()
        for path in ("/api/config", "/"):  # "/" opens a file: a descriptor must be left for it
            res = _get("127.0.0.3", url + path)
            assert res.status_code == 200, (path, res.status_code, res.text[:300])
        assert time.monotonic() - started < 15, "the normal requests were not answered promptly"
        # the address's connections beyond its share were refused with an answer, not left hanging
        time.sleep(1)
        answers = [_closed_by_server(s, 0.05) for s in idle]
        refused = [a for a in answers if a]
        assert len(refused) >= len(idle) - 100, f"{len(refused)} of {len(idle)} refused"
        assert all(a.startswith(b"HTTP/1.1 503 ") and b'"too_many_connections"' in a for a in refused), refused[0]
        # and the ones it kept are closed once they have not sent a request head in time
        kept = [s for s, a in zip(idle, answers, strict=True) if a is None]
        assert all(_closed_by_server(s, 30) is not None for s in kept)

        # 2. many addresses together: the server stays below its descriptor limit by refusing
        # connections (503) instead of failing on every file it opens
        idle += [s for a in range(10, 20) for _ in range(30) if (s := _idle_socket(f"127.0.1.{a}", port))]
        deadline = time.monotonic() + 60
        while True:  # refused while the others' idle connections are open, then served again
            try:
                res = _get("127.0.0.4", url + "/", timeout=10)
                if res.status_code == 200:
                    break
                assert res.status_code == 503 and res.json()["error"]["code"] == "server_busy", res.text[:300]
            except httpx.TransportError:
                pass
            assert time.monotonic() < deadline, "the server was not served again after the flood"
            time.sleep(0.5)
        assert proc.poll() is None
    finally:
        for s in idle:
            s.close()
        proc.terminate()
        try:
            proc.wait(30)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(30)
    text = log_path.read_text(errors="replace")
    assert len(text) < 20_000, f"the log grew to {len(text)} characters: {text[:2000]}"
    assert "Traceback" not in text, text[:3000]
    assert text.count("Too many open files") <= 3, text[:3000]


# -- issue 58, W1: the request-head limit counts the whole head, however it arrives -------------------
@pytest.mark.parametrize("pieces", [1, 4, 60])
def test_a_head_over_the_limit_is_refused_in_one_send_or_in_pieces(live_server, pieces):
    """Before, the 16 KiB limit held only when the head arrived in pieces: a 60,000-byte header
    sent in one send got 200."""
    srv = live_server("bayes-stop", rounds=1)
    host, port = host_port(srv.url)
    head = (f"GET / HTTP/1.1\r\nHost: {host}:{port}\r\nX-Pad: {'a' * 60_000}\r\n\r\n").encode()
    step = -(-len(head) // pieces)
    with socket.create_connection((host, port), timeout=10) as sock:
        try:
            for i in range(0, len(head), step):
                sock.sendall(head[i:i + step])
                if pieces > 1:
                    time.sleep(0.005)
        except OSError:  # the server may close while the rest is still being sent
            pass
        status, headers, text = read_response(sock, "GET")
    assert status == 431, (status, text[:200])
    assert error_code(text) == "head_too_large" and headers["connection"] == "close"
    ok = httpx.get(srv.url + "/", headers={"X-Pad": "a" * 8000}, timeout=10)  # a head under the limit
    assert ok.status_code == 200
