from __future__ import annotations

import os
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


@pytest.fixture(scope="session")
def secret_env():
    """A fake secret in the parent's environment before any sandbox worker starts."""
    os.environ[SECRET_NAME] = SECRET_VALUE
    yield SECRET_VALUE
    os.environ.pop(SECRET_NAME, None)


def _sandbox(**kwargs):
    sb = Sandbox(TEST_LIMITS, **kwargs)
    sb.start()
    return sb


@pytest.fixture(scope="session")
def sandbox(secret_env):
    """What `--executor cap` uses: namespaces, seccomp and the AST guard."""
    require_namespaces()
    sb = _sandbox(isolation="bwrap")
    yield sb
    sb.close()


@pytest.fixture(scope="session")
def unguarded_sandbox(secret_env):
    """No AST allow-list and all builtins: what is left is the OS layer (namespaces, seccomp,
    limits)."""
    require_namespaces()
    sb = _sandbox(isolation="bwrap", guard=False)
    yield sb
    sb.close()


@pytest.fixture(scope="session")
def namespaces_only_sandbox(secret_env):
    """No guard and no seccomp: the namespaces and resource limits alone."""
    require_namespaces()
    sb = _sandbox(isolation="bwrap", guard=False, seccomp=False)
    yield sb
    sb.close()


@pytest.fixture(scope="session")
def seccomp_only_sandbox(secret_env):
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
