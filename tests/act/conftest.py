from __future__ import annotations

import socket

import pytest
from act_helpers import SECRET_NAME, SECRET_VALUE

from activeintent.act.sandbox import Sandbox, SandboxLimits
from activeintent.world import Scene, WorldState, layout


@pytest.fixture
def state() -> WorldState:
    scene = Scene(objects=["red block", "green block", "blue block", "blue bowl", "red bowl"])
    return WorldState(positions=layout(scene, 3))


@pytest.fixture
def secret_env(monkeypatch):
    """A fake secret in the parent's environment during one test; monkeypatch takes it out after."""
    monkeypatch.setenv(SECRET_NAME, SECRET_VALUE)
    return SECRET_VALUE


def _limits() -> SandboxLimits:
    return SandboxLimits(cpu_seconds=1, wall_seconds=4.0, memory_mb=128)


def _started_with_secret(**kwargs) -> Sandbox:
    """A sandbox whose worker started while the fake secret was in the environment; the
    variable is restored as soon as the worker is up, not at the end of the session."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(SECRET_NAME, SECRET_VALUE)
        sb = Sandbox(_limits(), **kwargs)
        sb.start()
    return sb


@pytest.fixture(scope="session")
def _shared_sandbox():
    sb = _started_with_secret()
    yield sb
    sb.close()


@pytest.fixture(scope="session")
def _shared_unguarded_sandbox():
    sb = _started_with_secret(guard=False)
    yield sb
    sb.close()


@pytest.fixture
def sandbox(_shared_sandbox, secret_env):
    """The session's sandbox; the secret is in the parent's environment while the test runs
    (a worker restarted after a crash starts with it too)."""
    return _shared_sandbox


@pytest.fixture
def unguarded_sandbox(_shared_unguarded_sandbox, secret_env):
    """No AST allow-list and all builtins: what is left is the OS-level containment."""
    return _shared_unguarded_sandbox


@pytest.fixture(scope="session")
def listener():
    """A TCP server nobody should reach from inside the sandbox."""
    srv = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    srv.setblocking(False)
    yield srv
    srv.close()

