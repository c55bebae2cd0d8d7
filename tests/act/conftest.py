from __future__ import annotations

import os
import socket

import pytest
from act_helpers import SECRET_NAME, SECRET_VALUE

from activeintent.act.sandbox import Sandbox, SandboxLimits
from activeintent.world import Scene, WorldState, layout


@pytest.fixture
def state() -> WorldState:
    scene = Scene(objects=["red block", "green block", "blue block", "blue bowl", "red bowl"])
    return WorldState(positions=layout(scene, 3))


@pytest.fixture(scope="session")
def secret_env():
    """A fake secret in the parent's environment before any sandbox worker starts."""
    os.environ[SECRET_NAME] = SECRET_VALUE
    yield SECRET_VALUE
    os.environ.pop(SECRET_NAME, None)


def _limits() -> SandboxLimits:
    return SandboxLimits(cpu_seconds=1, wall_seconds=4.0, memory_mb=128)


@pytest.fixture(scope="session")
def sandbox(secret_env):
    with Sandbox(_limits()) as sb:
        yield sb


@pytest.fixture(scope="session")
def unguarded_sandbox(secret_env):
    """No AST allow-list and all builtins: what is left is the OS-level containment."""
    with Sandbox(_limits(), guard=False) as sb:
        yield sb


@pytest.fixture(scope="session")
def listener():
    """A TCP server nobody should reach from inside the sandbox."""
    srv = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    srv.setblocking(False)
    yield srv
    srv.close()

