"""The sandbox's worker process (runs in its own interpreter, never in the caller's).

The parent starts it once (see ``sandbox``): normally inside bubblewrap namespaces, always with
``python -I``, an environment built from scratch and no inherited descriptors. It imports numpy
and the world model and warms every code path a program may touch. From then on it is a
*template* that never reads a request: for each program it forks a fresh *runner*, which reads
one request (length-prefixed JSON on stdin), tells the parent it took it, forks the program's
child, collects its result (capped) within the wall-time limit, kills the child, replies and
exits. Every program therefore starts from the template's clean heap: no earlier program's
source, positions or output can be found in its memory, and nothing a program did outlives its
runner. The template reports a runner that died without replying (killed by its program, say),
so the parent never has to guess whether a program ran.

The child, before running untrusted code: starts a new session (own process group), dies with
its runner (``PR_SET_PDEATHSIG``), points stdin/stdout/stderr at /dev/null, keeps only the
result pipe (fd 3); if it runs as root (only possible without namespaces), chroots into an
empty read-only directory and drops to ``nobody``; sets RLIMIT_CPU, RLIMIT_AS,
RLIMIT_FSIZE = 0, RLIMIT_NOFILE = 4, RLIMIT_NPROC = 0 and RLIMIT_CORE = 0; and last installs
the seccomp allow-list of ``seccomp`` (memory, writing to open descriptors, exiting, clocks and
little else).
"""

from __future__ import annotations

import ast
import builtins
import ctypes
import json
import os
import resource
import select
import signal
import struct
import sys
import time
import traceback
from typing import Any

import numpy as np  # noqa: F401 - imported before forking so that children start warm

from activeintent.act.guard import GuardError, check_program
from activeintent.act.robot_api import RobotAPI, safe_builtins
from activeintent.act.seccomp import Seccomp
from activeintent.world.state import WorldState

RESULT_FD = 3
JAIL = os.path.abspath("jail")  # without namespaces, as root: empty (0555) in the worker's temp dir
NOBODY = 65534
MAX_MESSAGE_CHARS = 500
MAX_REQUEST_BYTES = 64 << 20
SECCOMP = Seccomp()  # built (and libc loaded) before any child is forked
_LIBC = ctypes.CDLL(None, use_errno=True)
_PR_SET_PDEATHSIG = 1
# Exit codes of a runner that the template reads (a runner never exits 0 without replying).
RUNNER_REPLIED, RUNNER_EOF = 0, 3


def _read_exactly(fd: int, size: int) -> bytes:
    """Unbuffered, so that a runner takes exactly one request off the shared stdin."""
    chunks, left = [], size
    while left:
        chunk = os.read(fd, min(left, 1 << 20))
        if not chunk:
            break
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)


def read_message(fd: int) -> dict | None:
    header = _read_exactly(fd, 4)
    if len(header) < 4:
        return None
    (size,) = struct.unpack(">I", header)
    if size > MAX_REQUEST_BYTES:
        raise ValueError(f"request of {size} bytes")
    data = _read_exactly(fd, size)
    if len(data) < size:
        return None
    message = json.loads(data)
    if not isinstance(message, dict):
        raise ValueError("request is not an object")
    return message


def write_message(fd: int, message: dict) -> None:
    data = json.dumps(message).encode()
    view = memoryview(struct.pack(">I", len(data)) + data)
    while view:
        view = view[os.write(fd, view):]


def _die_with_parent(parent: int) -> None:
    """SIGKILL this process when its parent ends (and end now if it already has)."""
    _LIBC.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:
        os._exit(70)


def _vm_bytes() -> int:
    """This process's current virtual memory size (the child's memory limit starts above it)."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmSize:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 1 << 30


def _error(e: BaseException) -> dict:
    line = None
    for frame, lineno in traceback.walk_tb(e.__traceback__):
        if frame.f_code.co_filename == "<program>":
            line = lineno
    try:
        message = str(e)[:MAX_MESSAGE_CHARS]
    except Exception:  # noqa: BLE001 - a message that cannot even be printed
        message = "(unprintable)"
    return {"type": type(e).__name__, "message": message, "line": line}


def run_program(source: str, positions: dict, guard: bool) -> dict:
    """Run one program against a RobotAPI over ``positions``; return what it did, as data."""
    api = RobotAPI(WorldState(positions=positions))
    namespace: dict[str, Any] = {}
    error = None
    try:
        tree = check_program(source) if guard else ast.parse(source)
        code = compile(tree, "<program>", "exec")
        namespace = api.namespace()
        namespace["__builtins__"] = safe_builtins(api) if guard else builtins.__dict__
        exec(code, namespace)  # noqa: S102 - the sandboxed execution itself
    except GuardError as e:
        error = {"type": "GuardError", "message": str(e), "line": None}
    except BaseException as e:  # noqa: BLE001 - MemoryError, RecursionError, anything the program raises
        error = _error(e)
    namespace.clear()  # free what the program allocated before serialising the result
    return {
        "skills": [s.model_dump() for s in api.skills],
        "skill_failures": api.skill_failures,
        "said": api.said,
        "error": error,
    }


def _confine(limits: dict, vm_bytes: int, use_seccomp: bool, runner: int) -> None:
    os.setsid()
    devnull = os.open(os.devnull, os.O_RDWR)
    for fd in (0, 1, 2):
        os.dup2(devnull, fd)
    os.closerange(RESULT_FD + 1, 1 << 16)
    if os.getuid() == 0:
        # An empty, read-only root: even code that got past the allow-list sees no files.
        os.chroot(JAIL)
        os.chdir("/")
        os.setgroups([])
        os.setgid(NOBODY)
        os.setuid(NOBODY)
    # After the uid change (which clears it): a program that outlived its runner (which it might
    # kill without seccomp) would be free of the wall-time limit; the filter keeps it set.
    _die_with_parent(runner)
    cpu = int(limits["cpu_seconds"])
    memory = vm_bytes + int(limits["memory_mb"]) * (1 << 20)
    resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 1))
    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    resource.setrlimit(resource.RLIMIT_FSIZE, (0, 0))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    resource.setrlimit(resource.RLIMIT_NOFILE, (RESULT_FD + 1, RESULT_FD + 1))
    resource.setrlimit(resource.RLIMIT_NPROC, (0, 0))
    if use_seccomp and SECCOMP.available:
        SECCOMP.install()  # last: it forbids setrlimit, chroot, open, ...


def _child(request: dict, write_fd: int, vm_bytes: int, runner: int) -> None:
    os.dup2(write_fd, RESULT_FD)
    if not request.get("guard", True):
        # Test mode without the allow-list: the usual attack modules are loaded before the
        # confinement, so that the OS layer (not a failed import) is what stops them.
        import ctypes  # noqa: F401
        import socket  # noqa: F401
        import subprocess  # noqa: F401
    _confine(request["limits"], vm_bytes, bool(request.get("seccomp", True)), runner)
    result = run_program(request["program"], request["positions"], request.get("guard", True))
    data = json.dumps(result).encode()
    cap = int(request["limits"]["max_output_bytes"])
    if len(data) > cap:
        data = json.dumps({
            "skills": [], "skill_failures": [], "said": [],
            "error": {"type": "OutputLimit", "message": f"result larger than {cap} bytes", "line": None},
        }).encode()
    view = memoryview(data)
    while view:
        view = view[os.write(RESULT_FD, view):]


def _describe_exit(status: int, timed_out: bool, too_big: bool, limits: dict) -> tuple[str, str]:
    if timed_out:
        return "wall", f"wall-time limit of {limits['wall_seconds']} s exceeded; the program was killed"
    if too_big:
        return "output", f"output larger than {limits['max_output_bytes']} bytes; the program was killed"
    if os.WIFSIGNALED(status):
        sig = os.WTERMSIG(status)
        if sig in (signal.SIGXCPU, signal.SIGKILL):
            return "cpu", f"CPU-time limit of {limits['cpu_seconds']} s exceeded; the program was killed"
        name = signal.Signals(sig).name
        return "crash", f"the program crashed ({name}), most likely by exceeding the memory limit"
    return "crash", f"the program ended without a result (exit code {os.WEXITSTATUS(status)})"


def handle(request: dict, vm_bytes: int) -> dict:
    limits = request["limits"]
    read_fd, write_fd = os.pipe()
    started = time.perf_counter()
    runner = os.getpid()
    pid = os.fork()
    if pid == 0:  # child: never returns
        try:
            os.close(read_fd)
            _child(request, write_fd, vm_bytes, runner)
        except BaseException:  # noqa: BLE001 - confinement failed: report no result
            os._exit(70)
        os._exit(0)
    os.close(write_fd)
    deadline = time.monotonic() + float(limits["wall_seconds"])
    cap = int(limits["max_output_bytes"]) + 1024
    chunks: list[bytes] = []
    size, timed_out, too_big = 0, False, False
    while True:
        remaining = deadline - time.monotonic()
        ready = select.select([read_fd], [], [], max(0.0, remaining))[0] if remaining > 0 else []
        if not ready:
            timed_out = True
            break
        data = os.read(read_fd, 1 << 16)
        if not data:
            break
        size += len(data)
        if size > cap:
            too_big = True
            break
        chunks.append(data)
    os.close(read_fd)
    # Wait (without reaping) until the child exits or the deadline passes, then kill its group.
    if not (timed_out or too_big):
        while os.waitid(os.P_PID, pid, os.WEXITED | os.WNOHANG | os.WNOWAIT) is None:
            if time.monotonic() >= deadline:
                timed_out = True
                break
            time.sleep(0.0005)
    for kill in (os.killpg, os.kill):
        try:
            kill(pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
    _, status = os.waitpid(pid, 0)
    elapsed = time.perf_counter() - started
    raw = b"".join(chunks)
    if raw and not too_big and os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0:
        return {"status": "done", "result": raw.decode("utf-8", "replace"), "elapsed_s": elapsed}
    kind, message = _describe_exit(status, timed_out, too_big, limits)
    return {"status": "killed", "kind": kind, "message": message, "elapsed_s": elapsed}


def run_one(stdout: int, template: int) -> int:
    """A runner: take one request, acknowledge it, run it in a confined child, reply."""
    _die_with_parent(template)
    request = read_message(0)
    if request is None:
        return RUNNER_EOF
    # From here on the parent knows the program may have run: it will not send it again.
    write_message(stdout, {"accepted": True})
    write_message(stdout, handle(request, _vm_bytes()))
    return RUNNER_REPLIED


def _lost_runner(status: int) -> dict:
    how = (f"was killed by {signal.Signals(os.WTERMSIG(status)).name}" if os.WIFSIGNALED(status)
           else f"ended with exit code {os.WEXITSTATUS(status)}")
    return {"status": "lost", "message": f"the sandbox's runner {how} before replying; the program was not run again"}


def serve(stdout: int) -> None:
    """The template's loop: one fresh runner per request, forked from this clean process."""
    template = os.getpid()
    while True:
        pid = os.fork()
        if pid == 0:
            code = 70
            try:
                code = run_one(stdout, template)
            except BaseException:  # noqa: BLE001 - a malformed request: reported by the template
                pass
            os._exit(code)
        _, status = os.waitpid(pid, 0)
        if os.WIFEXITED(status) and os.WEXITSTATUS(status) == RUNNER_EOF:
            return
        if not (os.WIFEXITED(status) and os.WEXITSTATUS(status) == RUNNER_REPLIED):
            write_message(stdout, _lost_runner(status))


def main() -> None:
    if os.getuid() == 0:  # only without namespaces: the children chroot into an empty folder
        os.mkdir(JAIL, 0o555)
    stdout = os.dup(sys.stdout.fileno())
    sys.stdout = sys.stderr  # nothing but protocol messages may reach the parent's pipe
    os.dup2(sys.stderr.fileno(), 1)
    # Warm up every code path a program may touch, so children import nothing after forking.
    run_program(
        "p = get_obj_pos('red block')\nput_first_on_second('red block', 'blue bowl')\n"
        "put_first_on_second('red block', p + np.array([0.1, 0.0]))\nsay(f'{np.linalg.norm(p):.2f}')\n"
        "parse_position('10cm left of the blue bowl')\n",
        {"red block": (0.0, -0.5, 0.02), "blue bowl": (0.1, -0.6, 0.0), "green block": (-0.1, -0.4, 0.02)},
        True,
    )
    write_message(stdout, {"ready": True, "pid": os.getpid(), "uid": os.getuid(), "seccomp": SECCOMP.available})
    serve(stdout)


if __name__ == "__main__":
    main()
