from __future__ import annotations

import socket
import subprocess

import pytest
from act_helpers import SECRET_NAME, SECRET_VALUE, TEST_LIMITS, require_namespaces

from activeintent.act.sandbox import Sandbox
from activeintent.world import Scene, WorldState, layout


@pytest.fixture
def state() -> WorldState:
    scene = Scene(objects=["red block", "green block", "blue block", "blue bowl", "red bowl"])
    return WorldState(positions=layout(scene, 3))


@pytest.fixture
def secret_env(monkeypatch):
    """A fake secret in the parent's environment for this test only."""
    monkeypatch.setenv(SECRET_NAME, SECRET_VALUE)
    return SECRET_VALUE


def _sandbox(**kwargs):
    # The worker starts while the parent's environment holds the fake secret, which is removed
    # straight after, so it cannot leak into the rest of the test session.
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(SECRET_NAME, SECRET_VALUE)
        sb = Sandbox(TEST_LIMITS, **kwargs)
        sb.start()
    return sb


@pytest.fixture(scope="session")
def sandbox():
    """What `--executor cap` uses: namespaces, seccomp and the AST guard."""
    require_namespaces()
    sb = _sandbox(isolation="bwrap")
    yield sb
    sb.close()


@pytest.fixture(scope="session")
def unguarded_sandbox():
    """No AST allow-list and all builtins: what is left is the OS layer (namespaces, seccomp,
    limits)."""
    require_namespaces()
    sb = _sandbox(isolation="bwrap", guard=False)
    yield sb
    sb.close()


@pytest.fixture(scope="session")
def namespaces_only_sandbox():
    """No guard and no seccomp: the namespaces and resource limits alone."""
    require_namespaces()
    sb = _sandbox(isolation="bwrap", guard=False, seccomp=False)
    yield sb
    sb.close()


@pytest.fixture(scope="session")
def seccomp_only_sandbox():
    """No guard and no namespaces (the --unsafe-no-isolation mode): seccomp and resource limits
    alone (plus chroot and the drop to nobody when the tests run as root)."""
    sb = _sandbox(isolation="none", unsafe_no_isolation=True, guard=False)
    if not sb.seccomp_active:
        sb.close()
        pytest.skip("no seccomp filter for this architecture")
    yield sb
    sb.close()


@pytest.fixture(scope="session")
def listener():
    """A TCP server nobody should reach from inside the sandbox."""
    srv = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    srv.setblocking(False)
    yield srv
    srv.close()


@pytest.fixture(scope="session")
def udp_listener():
    """A UDP socket no datagram from the sandbox should reach."""
    srv = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    srv.bind(("127.0.0.1", 0))
    srv.setblocking(False)
    yield srv
    srv.close()


@pytest.fixture(scope="session")
def victim():
    """A process of the test's own user that sandboxed programs try to signal or trace."""
    proc = subprocess.Popen(["sleep", "3600"], stdin=subprocess.DEVNULL)
    yield proc
    proc.kill()
    proc.wait()
