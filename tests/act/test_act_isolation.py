"""Each isolation layer is really in place: probes from inside the sandbox (guard off) that fail
as soon as a layer is skipped, the refusal without isolation, and the clean-up on every exit."""

from __future__ import annotations

import json
import os
import platform
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from act_helpers import SECRET_VALUE, TEST_LIMITS, descendants, require_namespaces

from activeintent.act import isolation, seccomp
from activeintent.act.cap import CapExecutor
from activeintent.act.executors import make_executor
from activeintent.act.isolation import (
    IsolationStatus,
    SandboxUnavailable,
    allow_unsafe_no_isolation,
)
from activeintent.act.sandbox import WORKDIR_PREFIX, Sandbox, sweep_stale_workdirs
from activeintent.llm.scripted import ScriptedModel

SRC = str(Path(__file__).resolve().parents[2] / "src")
ALLOWED_ENV = {"OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "LC_ALL", "LC_CTYPE", "PWD",
               "OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE"}


def _facts(sandbox, program: str, state) -> dict:
    result = sandbox.run(program + "\nsay(json.dumps(facts))", state)
    assert result.ok, result.error
    return json.loads(result.said[-1])


def test_worker_runs_in_its_own_namespaces(namespaces_only_sandbox, state, tmp_path):
    """Fails when the worker is started without bubblewrap (or with fewer namespaces). Without
    seccomp, whose allow-list would refuse stat and uname by itself."""
    facts = _facts(namespaces_only_sandbox, textwrap.dedent(f"""
        import json, os, socket
        os.close(0)  # room under the open-files limit to list /proc
        facts = {{
            "procs": [p for p in os.listdir("/proc") if p.isdigit()], "uid": os.getuid(), "gid": os.getgid(), "host": socket.gethostname(),
            "passwd": os.path.exists("/etc/passwd"), "home": os.path.exists("/home"),
            "tmp_path": os.path.exists({str(tmp_path)!r}), "parent": os.path.exists("/proc/{os.getpid()}"),
            "env": sorted(os.environ), "net": os.path.exists("/sys/class/net"),
        }}"""), state)
    # bubblewrap's init, the template, the program's runner and the program itself
    assert len(facts["procs"]) <= 5, f"no PID namespace: /proc lists {len(facts['procs'])} processes"
    assert facts["uid"] == facts["gid"] == 65534
    assert facts["host"] == "sandbox", "no UTS namespace"
    assert not facts["passwd"] and not facts["home"] and not facts["net"], "the host file system is visible"
    assert not facts["tmp_path"], "the test's folder is visible"
    assert not facts["parent"], "the parent's /proc entry is visible"
    assert set(facts["env"]) <= ALLOWED_ENV, facts["env"]
    assert namespaces_only_sandbox.isolation == "bwrap" and namespaces_only_sandbox.workdir is None


def test_network_namespace_has_no_route_out(namespaces_only_sandbox, state, listener):
    """Without seccomp a socket can be made, but the listener on the host is not reachable."""
    port = listener.getsockname()[1]
    facts = _facts(namespaces_only_sandbox, textwrap.dedent(f"""
        import json, os, socket
        os.close(0)  # room under the open-files limit
        s = socket.socket()
        try:
            s.connect(("127.0.0.1", {port}))
            outcome = "connected"
        except OSError as e:
            outcome = type(e).__name__
        s.close()
        facts = {{"outcome": outcome, "interfaces": [n for _, n in socket.if_nameindex()]}}"""), state)
    assert facts["outcome"] != "connected"
    assert facts["interfaces"] == ["lo"], "not a fresh network namespace"


def test_seccomp_refuses_system_calls(unguarded_sandbox, state):
    """Fails when the seccomp filter is not installed: each call would then work or fail with
    another error (read-only file system, no such file, network unreachable, and ENOSYS for a
    number no kernel has yet)."""
    if platform.machine().lower() not in ("x86_64", "amd64", "aarch64", "arm64"):
        pytest.skip("no seccomp filter for this architecture")
    assert unguarded_sandbox.seccomp_active
    facts = _facts(unguarded_sandbox, textwrap.dedent("""
        import ctypes, errno, json, os, socket
        libc = ctypes.CDLL(None, use_errno=True)
        def attempt(fn):
            try:
                fn()
                return "allowed"
            except OSError as e:
                return errno.errorcode.get(e.errno, str(e.errno))
        def call(*args):
            if libc.syscall(*args) == -1:
                raise OSError(ctypes.get_errno(), "")
        facts = {
            "stat": attempt(lambda: os.stat("/")),
            "future": attempt(lambda: call(600)),
            "socket": attempt(lambda: socket.socket()),
            "open": attempt(lambda: open("/usr/lib/os-release").close()),
            "mkdir": attempt(lambda: os.mkdir("/made")),
            "kill": attempt(lambda: os.kill(os.getpid(), 0)),
            "fork": attempt(lambda: os.fork()),
            "exec": attempt(lambda: os.execv("/bin/true", ["true"])),
        }"""), state)
    assert facts == dict.fromkeys(facts, "EPERM")


def test_prlimit64_names_no_other_process(seccomp_only_sandbox, state):
    """S1 (--unsafe-no-isolation, where the program sees host pids): prlimit64 on another pid
    answered EPERM for a process that exists and ESRCH for one that does not, a map of the
    host's pids. Now only pid 0 (itself) passes the filter. Run as root and, in CI, as an
    unprivileged user (tests/act/run_unprivileged.py)."""
    nr = seccomp.allowed_syscalls()["prlimit64"]
    facts = _facts(seccomp_only_sandbox, textwrap.dedent(f"""
        import ctypes, errno, json, os
        libc = ctypes.CDLL(None, use_errno=True)
        old = ctypes.create_string_buffer(16)
        def probe(pid):
            if libc.syscall({nr}, ctypes.c_long(pid), 7, None, old) == -1:
                return errno.errorcode.get(ctypes.get_errno(), "?")
            return "allowed"
        facts = {{"self": probe(0), "parent": probe(os.getppid()), "init": probe(1),
                  "absent": probe(4194303)}}"""), state)
    assert facts == {"self": "allowed", "parent": "EPERM", "init": "EPERM", "absent": "EPERM"}, facts


def test_resource_limits_in_the_child(unguarded_sandbox, state):
    facts = _facts(unguarded_sandbox, textwrap.dedent("""
        import json, resource
        facts = {name: resource.getrlimit(getattr(resource, name))
                 for name in ("RLIMIT_CPU", "RLIMIT_FSIZE", "RLIMIT_NOFILE", "RLIMIT_NPROC", "RLIMIT_CORE")}"""),
        state)
    assert facts["RLIMIT_CPU"][0] == TEST_LIMITS.cpu_seconds
    assert facts["RLIMIT_FSIZE"] == facts["RLIMIT_NPROC"] == facts["RLIMIT_CORE"] == [0, 0]
    assert facts["RLIMIT_NOFILE"] == [4, 4]


def test_sandbox_processes_are_not_root(sandbox):
    """Seen from the host: everything below bubblewrap runs as an unprivileged user, also when
    the tests run as root."""
    inner = descendants(sandbox.worker_pid)
    assert inner, "no process below bubblewrap"
    for pid in inner:
        uids = [line for line in Path(f"/proc/{pid}/status").read_text().splitlines() if line.startswith("Uid:")]
        assert uids and all(int(u) != 0 for u in uids[0].split()[1:]), (pid, uids)


# ---- without isolation ------------------------------------------------------------------------
def test_refuses_without_isolation(state):
    sb = Sandbox(TEST_LIMITS, isolation="none", unsafe_no_isolation=False)
    result = sb.run("put_first_on_second('red block', 'blue bowl')", state)
    assert result.error_kind == "sandbox" and not result.skills
    assert "no isolation" in result.error and "--unsafe-no-isolation" in result.error
    assert sb.worker_pid is None, "a worker was started although nothing may run"
    with pytest.raises(SandboxUnavailable):
        sb.start()


def test_unsafe_mode_runs_with_seccomp_and_limits(state, monkeypatch):
    monkeypatch.setenv(isolation.UNSAFE_ENV, "1")
    with Sandbox(TEST_LIMITS, isolation="none") as sb:
        result = sb.run("put_first_on_second('red block', 'blue bowl')", state)
        assert result.ok and len(result.skills) == 1
        assert sb.workdir is not None and Path(sb.workdir).name.startswith(f"{WORKDIR_PREFIX}{os.getpid()}-")
        workdir = sb.workdir
    assert not Path(workdir).exists()


@pytest.mark.skipif(os.geteuid() != 0, reason="the chroot is only used when the tests run as root")
def test_unsafe_mode_as_root_chroots_and_drops_to_nobody(state):
    """Fails when the root child keeps its uid or the host file system (seccomp off: its
    allow-list would refuse stat by itself)."""
    with Sandbox(TEST_LIMITS, isolation="none", unsafe_no_isolation=True, guard=False, seccomp=False) as sb:
        facts = _facts(sb, "import json, os\nfacts = {'uid': os.getuid(), "
                       "'passwd': os.path.exists('/etc/passwd'), 'root': os.path.exists('/usr')}", state)
    assert facts == {"uid": 65534, "passwd": False, "root": False}


def _no_isolation(monkeypatch) -> None:
    monkeypatch.setattr("activeintent.act.isolation.isolation_status",
                        lambda package_root=None: IsolationStatus("none", "bubblewrap (bwrap) is not installed"))
    monkeypatch.delenv(isolation.UNSAFE_ENV, raising=False)
    monkeypatch.setattr(isolation, "_unsafe_allowed", False)


def test_cap_executor_refuses_without_isolation_and_says_why(monkeypatch):
    _no_isolation(monkeypatch)
    with pytest.raises(SandboxUnavailable, match="bubblewrap.*--unsafe-no-isolation"):
        make_executor("cap", model=ScriptedModel([]))
    assert isinstance(SandboxUnavailable("x"), ValueError)  # `run` reports ValueErrors as option errors
    make_executor("cap", model=None)  # without a model no program is ever run
    try:
        allow_unsafe_no_isolation()
        assert isinstance(make_executor("cap", model=ScriptedModel([])), CapExecutor)
        assert os.environ[isolation.UNSAFE_ENV] == "1"
    finally:
        allow_unsafe_no_isolation(False)


def test_missing_bwrap_is_reported(monkeypatch):
    monkeypatch.setattr(isolation, "bwrap_executable", lambda: None)
    status = isolation.isolation_status()
    assert not status.available and "not installed" in status.detail


def test_isolation_is_available_in_ci():
    """In CI (CI set) bubblewrap must work: a missing one fails here instead of skipping."""
    require_namespaces()
    assert isolation.isolation_status().mode == "bwrap"


def test_worker_failure_becomes_an_execution_failure(state, monkeypatch):
    monkeypatch.setattr("activeintent.act.sandbox._BOOT", "import sys; sys.exit(3)")
    sb = Sandbox(TEST_LIMITS, isolation="none", unsafe_no_isolation=True)
    executor = CapExecutor(ScriptedModel(["put_first_on_second('red block', 'blue bowl')"]), sandbox=sb)
    plan = executor.to_plan("do it in an odd way", state)
    assert plan.failure is not None and plan.failure.stage == "program"
    assert plan.failure.details["kind"] == "sandbox" and "did not start" in plan.failure.message
    sb.close()


# ---- clean-up -----------------------------------------------------------------------------------
def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_stale_workdirs_are_swept(tmp_path):
    dead = tmp_path / f"{WORKDIR_PREFIX}{_dead_pid()}-abc123"
    (dead / "jail").mkdir(parents=True)
    (dead / "jail").chmod(0o555)
    alive = tmp_path / f"{WORKDIR_PREFIX}{os.getpid()}-def456"
    (alive / "jail").mkdir(parents=True)
    legacy = tmp_path / f"{WORKDIR_PREFIX}k2j3h4"
    (legacy / "jail").mkdir(parents=True)
    foreign = tmp_path / f"{WORKDIR_PREFIX}x9y8z7"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("not a sandbox folder")
    removed = sweep_stale_workdirs(str(tmp_path))
    assert sorted(removed) == sorted([str(dead), str(legacy)])
    assert alive.exists() and foreign.exists() and not dead.exists() and not legacy.exists()


_HOLDER = """
import sys
sys.path.insert(0, {src!r})
from activeintent.act.sandbox import Sandbox
sb = Sandbox(isolation={isolation!r}, unsafe_no_isolation=True)
sb.start()
print(sb.workdir or "", sb.worker_pid, flush=True)
sys.stdin.read()
"""


@pytest.mark.parametrize("isolation_mode", ["none", "bwrap"])
def test_sigterm_leaves_no_worker_and_no_folder(isolation_mode, tmp_path):
    if isolation_mode == "bwrap":
        require_namespaces()
    env = {**os.environ, "TMPDIR": str(tmp_path)}
    proc = subprocess.Popen([sys.executable, "-c", _HOLDER.format(src=SRC, isolation=isolation_mode)],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env)
    line = proc.stdout.readline().split()
    workdir, worker = (line[0], int(line[1])) if len(line) == 2 else (None, int(line[0]))
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(timeout=60) == -signal.SIGTERM  # the default action still happens
    proc.stdin.close()
    proc.stdout.close()
    if workdir:
        assert not Path(workdir).exists()
    assert list(tmp_path.iterdir()) == []
    try:
        state = Path(f"/proc/{worker}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except FileNotFoundError:
        state = "gone"
    assert state in ("gone", "Z")


def test_sigkill_leftovers_are_swept_at_the_next_start(tmp_path):
    env = {**os.environ, "TMPDIR": str(tmp_path)}
    proc = subprocess.Popen([sys.executable, "-c", _HOLDER.format(src=SRC, isolation="none")],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env)
    workdir = proc.stdout.readline().split()[0]
    proc.kill()
    proc.wait()
    proc.stdin.close()
    proc.stdout.close()
    assert Path(workdir).exists()  # nothing can run on SIGKILL...
    assert str(workdir) in sweep_stale_workdirs(str(tmp_path))  # ...so the next start sweeps it
    assert not Path(workdir).exists()


def test_secret_not_in_worker_environment(unguarded_sandbox, state):
    result = unguarded_sandbox.run("import os\nsay(sorted(os.environ.items()))", state)
    assert result.ok and SECRET_VALUE not in result.said[0]
