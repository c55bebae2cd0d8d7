"""A real study server (uvicorn on a free loopback port) and Debian's Chromium via Playwright."""

from __future__ import annotations

import os
import socket
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import httpx
import pytest

from activeintent.learners.registry import get_method
from activeintent.spec import RunSpec, option_fields
from activeintent.web.limits import Limits, SessionLimits
from activeintent.web.server import create_app, runner_builder
from activeintent.web.session import SessionManager, StudyConfig
from activeintent.web.transport import StudyServer, server_config

CHROMIUM = os.environ.get("ACTIVEINTENT_CHROMIUM", "/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--autoplay-policy=no-user-gesture-required",
]


class FakeClock:
    """A clock that only moves when told to (idle timeouts and rate limits without waiting)."""

    def __init__(self, start: float = 1000.0):
        self.now = start

    def __call__(self) -> float:
        return self.now

    def advance(self, seconds: float) -> None:
        self.now += seconds


@pytest.fixture
def fake_clock() -> FakeClock:
    return FakeClock()


@dataclass
class LiveServer:
    url: str
    out: Path
    manager: SessionManager
    config: StudyConfig
    limits: SessionLimits

    def session_dir(self, sid: str) -> Path:
        return self.out / sid


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def study_config(method: str, budget: int, out: Path, **fields) -> StudyConfig:
    """A study of ``method`` (Bayesian methods: no model; 2 test scenes); ``fields`` are the
    spec's options (e.g. intention) or the study's own (e.g. show_estimate)."""
    run = {k: fields.pop(k) for k in list(fields) if k in option_fields()}
    spec = RunSpec.from_options(method=method, budget=budget, llm="none", test_scenes=2, **run)
    return StudyConfig(run=spec, signal=get_method(method).signal, out_dir=out, **fields)


@pytest.fixture
def live_server(tmp_path) -> Iterator:
    """``start(method, rounds=2, limits=None, clock=None, **study)`` serves a study on
    127.0.0.1 for this test (``limits``: a :class:`Limits` or its fields as a dict)."""
    servers: list[tuple[StudyServer, threading.Thread]] = []

    def start(method: str, rounds: int = 2, limits: Limits | dict | None = None, clock=None, study_file=None,
              **study) -> LiveServer:
        out = tmp_path / f"out-{len(servers)}"
        config = study_config(method, rounds, out, **study)
        if isinstance(limits, dict):
            limits = Limits(**limits)
        conditions = None
        if study_file is not None:  # a study file's conditions (method, rule, guess display)
            conditions = {}
            for c in study_file.conditions:
                cfg = study_config(c.method, rounds, out, **{**study, "intention": c.intention,
                                                             "show_estimate": c.show_estimate})
                conditions[c.name] = (cfg, runner_builder(cfg))
        app = create_app(config, runner_builder(config),
                         limits=limits, clock=clock or time.monotonic, study=study_file, conditions=conditions)
        port = _free_port()
        # the server `activeintent serve` runs: uvicorn inside the connection guard
        server = StudyServer(server_config(app, "127.0.0.1", port), app.state.connections)
        thread = threading.Thread(target=server.run, daemon=True)
        thread.start()
        url = f"http://127.0.0.1:{port}"
        for _ in range(200):  # wait until it accepts connections
            if server.started:
                break
            time.sleep(0.05)
        assert server.started, "the study server did not start"
        assert httpx.get(f"{url}/api/config").status_code == 200
        servers.append((server, thread))
        return LiveServer(url=url, out=out, manager=app.state.manager, config=config, limits=app.state.limits)

    yield start
    for server, thread in servers:
        server.should_exit = True
        thread.join(30)


@pytest.fixture
def http() -> Iterator[httpx.Client]:
    """A client that keeps cookies, as a browser does: a session's key comes back as one, and
    only requests that carry it may answer that session."""
    with httpx.Client(timeout=120) as c:
        yield c


@pytest.fixture(scope="module")  # not session: Playwright's sync API keeps an event loop running
def browser():  # in the main thread while it is open, and asyncio.run in later modules would fail
    if not Path(CHROMIUM).exists():
        pytest.skip(f"{CHROMIUM} is missing: apt-get install chromium (bin/test does)")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        yield b
        b.close()


@pytest.fixture
def page(browser):
    context = browser.new_context(viewport={"width": 1100, "height": 900})
    pg = context.new_page()
    pg.set_default_timeout(120_000)
    yield pg
    context.close()
