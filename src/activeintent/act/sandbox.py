"""Run untrusted robot programs (Code as Policies) in an isolated process.

Layers, outermost first (``docs/security.md`` has the threat model):

1. Isolation (``isolation``): the pre-warmed worker interpreter runs inside bubblewrap with
   fresh user, mount, PID, network, IPC and UTS namespaces, as uid 65534 without capabilities,
   over an empty read-only file system holding only Python, the virtualenv and this package,
   with an environment built from scratch; it dies with its parent. Without bubblewrap (or
   where namespaces are forbidden) the sandbox refuses to run programs unless the user passed
   ``--unsafe-no-isolation``; then, run as root, the program's process still chroots into an
   empty folder and drops to ``nobody``.
2. Per program (``sandbox_worker``): a fresh runner forked from a template that never sees a
   program (no earlier program is in its memory), which forks the program's child: its own
   session, CPU-time, memory, file-size, open-file and process limits, killed at the wall-time
   limit, and a seccomp allow-list (``seccomp``) of the few calls the runtime needs. A program
   is sent to a worker at most once (the runner acknowledges it), and the parent waits for it
   no longer than its wall-time limit plus a grace: a stopped or stuck worker is killed then.
3. ``guard.check_program``: an AST allow-list, checked here before anything runs and again in
   the child, and a restricted namespace (the robot API, a numpy subset as ``np``, safe
   builtins) — the first thing a program meets, but not what contains it.

Robot calls cross the process boundary as data; everything the worker sends back is parsed
defensively: whatever goes wrong becomes a result with an ``error_kind``, never an exception,
and every string is cleaned (``sanitize``).
"""

from __future__ import annotations

import atexit
import contextlib
import json
import math
import os
import re
import select
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import time
import weakref
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, Field, TypeAdapter

from activeintent.act.guard import GuardError, check_program
from activeintent.act.isolation import (
    IsolationStatus,
    SandboxUnavailable,
    bwrap_command,
    bwrap_executable,
    isolation_status,
    refusal_message,
    root_drop,
    unsafe_allowed,
    worker_env,
)
from activeintent.act.robot_api import MAX_SKILLS
from activeintent.act.sanitize import MAX_ERROR_CHARS, clean_messages, clean_text
from activeintent.world.skills import TABLE_POSITIONS, PutAt, Skill
from activeintent.world.state import WorldState

__all__ = ["ErrorKind", "Sandbox", "SandboxError", "SandboxLimits", "SandboxResult", "SandboxUnavailable",
           "default_sandbox", "sweep_stale_workdirs"]

_SKILLS = TypeAdapter(list[Skill])
_PACKAGE_ROOT = str(Path(__file__).resolve().parents[2])  # the directory holding `activeintent`
_BOOT = "import sys; sys.path.insert(0, sys.argv[1]); from activeintent.act.sandbox_worker import main; main()"
WORKDIR_PREFIX = "activeintent-sandbox-"
_WORKDIR_RE = re.compile(rf"^{WORKDIR_PREFIX}(?:(?P<pid>\d+)-)?[A-Za-z0-9_]+$")
_MAX_REPLY_EXTRA = 1 << 16
# A live worker forks a runner that acknowledges a request within milliseconds; past this the
# worker is taken for dead or stopped (the program has not run) and is replaced once.
ACK_TIMEOUT_S = 3.0
# How long past the wall-time limit the parent waits for a reply: the runner only kills the
# program, reaps it and writes. The sandbox's lock is never held longer for one program.
REPLY_GRACE_S = 2.0

ErrorKind = Literal["refused", "runtime", "cpu", "wall", "memory", "output", "crash", "sandbox"]
_KILL_KINDS = frozenset({"cpu", "wall", "memory", "output", "crash"})
Isolation = Literal["auto", "bwrap", "none"]


class SandboxLimits(BaseModel):
    cpu_seconds: int = Field(2, ge=1, le=60)
    wall_seconds: float = Field(5.0, gt=0, le=120)
    memory_mb: int = Field(256, ge=16, le=8192)  # above the worker's own footprint
    max_output_bytes: int = Field(256_000, ge=1024, le=16 << 20)


class SandboxResult(BaseModel):
    """What a program did: the skills it asked for (validated), what it said, and any error."""

    skills: list[Skill] = Field(default_factory=list)
    skill_failures: list[str | None] = Field(default_factory=list)
    said: list[str] = Field(default_factory=list)
    error: str | None = None
    error_kind: ErrorKind | None = None
    line: int | None = None
    elapsed_s: float = 0.0

    @property
    def ok(self) -> bool:
        return self.error is None


class SandboxError(RuntimeError):
    """The worker process could not be started or answered nonsense (not the program's fault)."""


# ---- clean-up of every worker and work folder, on any exit ---------------------------------
_live: weakref.WeakSet[Sandbox] = weakref.WeakSet()
_hooks_lock = threading.Lock()
_hooks_installed = False
_swept = False


def _close_all() -> None:
    for sandbox in list(_live):
        with contextlib.suppress(Exception):
            sandbox._stop()  # no lock: the process is exiting, a program may be running


def _on_signal(signum: int, frame: Any, previous: Any) -> None:
    _close_all()
    if callable(previous):
        previous(signum, frame)
        return
    # The default action (terminate): restore it and deliver the signal again.
    signal.signal(signum, signal.SIG_DFL)
    os.kill(os.getpid(), signum)


def _install_exit_hooks() -> None:
    """atexit for normal exits; SIGTERM/SIGHUP handlers (chaining to any handler already set)
    so that ``kill`` leaves no worker or folder behind. Only the main thread may set handlers:
    elsewhere the atexit hook and the sweep at the next start remain."""
    global _hooks_installed
    with _hooks_lock:
        if _hooks_installed:
            return
        _hooks_installed = True
        atexit.register(_close_all)
        if threading.current_thread() is not threading.main_thread():
            return
        for signum in (signal.SIGTERM, signal.SIGHUP):
            try:
                previous = signal.getsignal(signum)
                if previous in (signal.SIG_IGN, None):
                    continue
                signal.signal(signum, lambda n, f, p=previous: _on_signal(n, f, p))
            except (ValueError, OSError):
                pass


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def sweep_stale_workdirs(tmpdir: str | None = None) -> list[str]:
    """Remove work folders (with their ``jail``) left by sandboxes whose process is gone —
    killed with SIGKILL, say. Folders of living processes and of other users stay."""
    base = Path(tmpdir or tempfile.gettempdir())
    removed: list[str] = []
    try:
        entries = list(base.iterdir())
    except OSError:
        return removed
    uid = os.getuid()
    for entry in entries:
        m = _WORKDIR_RE.match(entry.name)
        if not m:
            continue
        try:
            st = entry.lstat()
            if not entry.is_dir() or entry.is_symlink() or st.st_uid != uid:
                continue
            if m["pid"] is not None:
                if int(m["pid"]) == os.getpid() or _pid_alive(int(m["pid"])):
                    continue
            else:  # older folders carry no pid: only an empty jail shows it is one of ours
                names = [p.name for p in entry.iterdir()]
                if names not in ([], ["jail"]) or (names and any((entry / "jail").iterdir())):
                    continue
        except OSError:
            continue
        shutil.rmtree(entry, ignore_errors=True)
        if not entry.exists():
            removed.append(str(entry))
    return removed


def _sweep_once() -> None:
    global _swept
    with _hooks_lock:
        if _swept:
            return
        _swept = True
    sweep_stale_workdirs()


class Sandbox:
    """One pre-warmed worker; ``run`` is thread-safe (programs run one at a time).

    ``isolation``: "auto" uses bubblewrap when it works here and runs nothing otherwise
    (unless ``unsafe_no_isolation``); "bwrap" requires it; "none" never uses it (then programs
    run only with ``unsafe_no_isolation``). ``unsafe_no_isolation=None`` reads the
    ``ACTIVEINTENT_UNSAFE_NO_ISOLATION`` environment variable (set by ``--unsafe-no-isolation``).
    """

    def __init__(
        self,
        limits: SandboxLimits | None = None,
        *,
        guard: bool = True,
        isolation: Isolation = "auto",
        unsafe_no_isolation: bool | None = None,
        seccomp: bool = True,
    ) -> None:
        """``guard=False`` skips the AST allow-list and gives programs all builtins, and
        ``seccomp=False`` leaves out the system-call filter: both only for tests that show what
        the other layers contain on their own."""
        if isolation not in ("auto", "bwrap", "none"):
            raise ValueError(f"unknown isolation {isolation!r}: auto, bwrap or none")
        self.limits = limits or SandboxLimits()
        self.guard = guard
        self.isolation_request: Isolation = isolation
        self.unsafe_no_isolation = unsafe_no_isolation
        self.use_seccomp = seccomp
        self.status: IsolationStatus | None = None
        self.seccomp_active: bool | None = None  # known once the worker runs
        self.worker_uid: int | None = None
        self._proc: subprocess.Popen | None = None
        self._workdir: str | None = None
        self._stderr = None
        self._lock = threading.Lock()
        self.startup_s: float | None = None
        _live.add(self)

    # ---- isolation -----------------------------------------------------------------------
    def _unsafe(self) -> bool:
        return unsafe_allowed() if self.unsafe_no_isolation is None else bool(self.unsafe_no_isolation)

    def resolve_isolation(self) -> IsolationStatus:
        """What this sandbox uses ("bwrap" or "none") and why; probed once."""
        if self.status is None:
            if self.isolation_request == "none":
                self.status = IsolationStatus("none", "isolation switched off for this sandbox")
            else:
                status = isolation_status(_PACKAGE_ROOT)
                if self.isolation_request == "bwrap" and not status.available:
                    raise SandboxUnavailable(f"bubblewrap isolation was required: {status.detail}")
                self.status = status
        return self.status

    @property
    def isolation(self) -> str:
        return self.resolve_isolation().mode

    def refusal(self) -> str | None:
        """Why programs may not run here, or None when they may."""
        status = self.resolve_isolation()
        if status.available or self._unsafe():
            return None
        return refusal_message(status)

    # ---- worker lifecycle ----------------------------------------------------------------
    def start(self) -> None:
        """Start the worker now; raises SandboxUnavailable when programs may not run here and
        SandboxError when the worker does not start."""
        with self._lock:
            reason = self.refusal()
            if reason is not None:
                raise SandboxUnavailable(reason)
            self._ensure_started()

    def _command(self, status: IsolationStatus) -> tuple[list[str], dict[str, str], str]:
        argv = [sys.executable, "-I", "-c", _BOOT, _PACKAGE_ROOT]
        if status.mode == "bwrap":
            bwrap = bwrap_executable()
            if bwrap is None:
                raise SandboxError("bubblewrap disappeared")
            return bwrap_command(bwrap, argv, _PACKAGE_ROOT, drop_root=root_drop(_PACKAGE_ROOT)), {}, "/"
        self._workdir = tempfile.mkdtemp(prefix=f"{WORKDIR_PREFIX}{os.getpid()}-")
        return argv, worker_env(), self._workdir

    def _ensure_started(self) -> None:
        if self._proc is not None and self._proc.poll() is None:
            return
        self._stop()
        _install_exit_hooks()
        _sweep_once()
        status = self.resolve_isolation()
        started = time.perf_counter()
        cmd, env, cwd = self._command(status)
        self._stderr = tempfile.TemporaryFile()
        self._proc = subprocess.Popen(
            cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self._stderr,
            env=env, cwd=cwd, close_fds=True, start_new_session=True,
        )
        ready = self._read(timeout=60.0)
        if not ready or ready.get("ready") is not True:
            detail = self._worker_stderr()
            self._stop()
            raise SandboxError(f"the sandbox worker did not start: {detail or 'no output'}")
        self.seccomp_active = bool(ready.get("seccomp")) and self.use_seccomp
        uid = ready.get("uid")
        self.worker_uid = uid if isinstance(uid, int) else None
        self.startup_s = time.perf_counter() - started

    def _worker_stderr(self) -> str:
        if self._stderr is None:
            return ""
        try:
            self._stderr.seek(0)
            return clean_text(self._stderr.read()[-2000:].decode("utf-8", "replace").strip(), 2000)
        except (OSError, ValueError):
            return ""

    def _stop(self) -> None:
        proc, self._proc = self._proc, None
        if proc is not None:
            if proc.poll() is None:
                for kill in (os.killpg, os.kill):
                    with contextlib.suppress(ProcessLookupError, PermissionError):
                        kill(proc.pid, signal.SIGKILL)
            with contextlib.suppress(Exception):
                proc.wait(timeout=10)
            for stream in (proc.stdin, proc.stdout):
                if stream is not None:
                    with contextlib.suppress(OSError):
                        stream.close()
        stderr, self._stderr = self._stderr, None
        if stderr is not None:
            with contextlib.suppress(OSError):
                stderr.close()
        workdir, self._workdir = self._workdir, None
        if workdir is not None:
            shutil.rmtree(workdir, ignore_errors=True)

    def close(self) -> None:
        with self._lock:
            self._stop()

    def __enter__(self) -> Sandbox:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        with contextlib.suppress(Exception):
            self._stop()

    @property
    def worker_pid(self) -> int | None:
        """The pid of the started process (bwrap's, when isolated)."""
        return self._proc.pid if self._proc is not None else None

    @property
    def workdir(self) -> str | None:
        return self._workdir

    # ---- protocol ------------------------------------------------------------------------
    def _read(self, timeout: float) -> dict | None:
        """One length-prefixed JSON message from the worker, or None (timeout, EOF, nonsense)."""
        if self._proc is None or self._proc.stdout is None:
            return None
        fd = self._proc.stdout.fileno()
        deadline = time.monotonic() + timeout
        limit = self.limits.max_output_bytes * 8 + _MAX_REPLY_EXTRA
        buf = b""
        need = 4
        size = None
        while len(buf) < need:
            remaining = deadline - time.monotonic()
            if remaining <= 0 or not select.select([fd], [], [], remaining)[0]:
                return None
            chunk = os.read(fd, min(need - len(buf), 1 << 20))
            if not chunk:
                return None
            buf += chunk
            if size is None and len(buf) == 4:
                (size,) = struct.unpack(">I", buf)
                if size > limit:
                    return None
                need = 4 + size
        try:
            message = json.loads(buf[4:])
        except Exception:  # noqa: BLE001 - malformed, too deep, not UTF-8: all the same to us
            return None
        return message if isinstance(message, dict) else None

    def _send(self, data: bytes) -> dict | None:
        """Send one request; the first message back: the runner's receipt, or the template's
        report of a runner that failed before it (None: nothing answered in time)."""
        assert self._proc is not None and self._proc.stdin is not None
        try:
            self._proc.stdin.write(struct.pack(">I", len(data)) + data)
            self._proc.stdin.flush()
        except (OSError, ValueError):
            return None
        return self._read(timeout=ACK_TIMEOUT_S)

    # ---- running programs ----------------------------------------------------------------
    def run(self, program: str, state: WorldState) -> SandboxResult:
        """Run ``program`` against the CaP robot API over ``state``. Never raises: a refused or
        failing program, a dead worker, missing isolation all come back as ``error``/``error_kind``."""
        started = time.perf_counter()
        try:
            return self._run(program, state, started)
        except SandboxUnavailable as e:
            return SandboxResult(error=clean_text(e, MAX_ERROR_CHARS), error_kind="sandbox",
                                 elapsed_s=time.perf_counter() - started)
        except Exception as e:  # noqa: BLE001 - the boundary: nothing escapes into the episode
            return SandboxResult(
                error=clean_text(f"the sandbox failed: {type(e).__name__}: {e}", MAX_ERROR_CHARS),
                error_kind="sandbox", elapsed_s=time.perf_counter() - started,
            )

    def _run(self, program: str, state: WorldState, started: float) -> SandboxResult:
        if self.guard:
            try:
                check_program(program)
            except GuardError as e:
                return SandboxResult(error=clean_text(f"refused: {e}", MAX_ERROR_CHARS), error_kind="refused")
        request = {
            "program": program,
            "positions": {k: list(v) for k, v in state.positions.items()},
            "limits": self.limits.model_dump(),
            "guard": self.guard,
            "seccomp": self.use_seccomp,
        }
        data = json.dumps(request).encode()
        with self._lock:
            reason = self.refusal()
            if reason is not None:
                return SandboxResult(error=reason, error_kind="sandbox")
            taken = None
            for _attempt in range(2):
                self._ensure_started()
                taken = self._send(data)
                if taken is not None:
                    break
                # No runner took the program (the worker died or stopped between programs), so
                # it has not run: replace the worker and send it once more.
                self._stop()
            if taken is None or taken.get("accepted") is not True:
                why = taken.get("message") if taken is not None else None
                self._stop()
                return SandboxResult(
                    error=clean_text(f"the sandbox worker did not take the program: {why or 'no answer'}",
                                     MAX_ERROR_CHARS),
                    error_kind="sandbox", elapsed_s=time.perf_counter() - started,
                )
            # The program may have run from here on: whatever happens, it is not sent again.
            wait = self.limits.wall_seconds + REPLY_GRACE_S
            waited = time.monotonic()
            reply = self._read(timeout=wait)
            if reply is None:
                timed_out = time.monotonic() - waited >= wait
                self._stop()  # a stopped or stuck worker is killed now, before the lock is let go
                how = (f"did not answer within {wait:g} s (stopped or stuck) and was killed" if timed_out
                       else "died or answered nonsense while running the program")
                return SandboxResult(
                    error=f"the sandbox worker {how}; the program was not run again",
                    error_kind="sandbox", elapsed_s=time.perf_counter() - started,
                )
            if reply.get("status") == "lost":
                self._stop()  # the runner may have left half a message in the pipe
                return SandboxResult(
                    error=clean_text(reply.get("message") or "the sandbox's runner was lost", MAX_ERROR_CHARS),
                    error_kind="sandbox", elapsed_s=time.perf_counter() - started,
                )
        elapsed = time.perf_counter() - started
        if reply.get("status") != "done":
            kind = reply.get("kind")
            return SandboxResult(
                error=clean_text(reply.get("message") or "killed", MAX_ERROR_CHARS),
                error_kind=kind if kind in _KILL_KINDS else "crash", elapsed_s=elapsed,
            )
        raw = reply.get("result")
        return self._parse_result(raw if isinstance(raw, str) else "", state, elapsed)

    @staticmethod
    def _parse_result(raw: str, state: WorldState, elapsed: float) -> SandboxResult:
        """Validate the child's output: it is data from an untrusted process. Never raises."""
        try:
            return _parse_result(raw, state, elapsed)
        except Exception as e:  # noqa: BLE001 - RecursionError, MemoryError, ValidationError, ...
            return SandboxResult(
                error=clean_text(f"the program's result is malformed: {type(e).__name__}: {str(e)[:200]}",
                                 MAX_ERROR_CHARS),
                error_kind="sandbox", elapsed_s=elapsed,
            )


def _malformed(why: str, elapsed: float) -> SandboxResult:
    return SandboxResult(error=f"the program's result is malformed: {why}", error_kind="sandbox", elapsed_s=elapsed)


def _parse_result(raw: str, state: WorldState, elapsed: float) -> SandboxResult:
    out = json.loads(raw)
    if not isinstance(out, dict):
        return _malformed("not an object", elapsed)
    raw_skills = out.get("skills", [])
    if not isinstance(raw_skills, list) or len(raw_skills) > MAX_SKILLS:
        return _malformed(f"skills must be a list of at most {MAX_SKILLS}", elapsed)
    skills = _SKILLS.validate_python(raw_skills)
    raw_failures = out.get("skill_failures", [])
    if not isinstance(raw_failures, list):
        return _malformed("skill_failures must be a list", elapsed)
    failures = [None if f is None else clean_text(f, MAX_ERROR_CHARS) for f in raw_failures[: len(skills)]]
    failures += [None] * (len(skills) - len(failures))
    said = clean_messages(out.get("said", []))
    unknown = sorted({n for s in skills for n in _names(s) if n not in state.positions})
    if unknown:
        return SandboxResult(
            error=clean_text(f"the program used unknown objects {unknown}", MAX_ERROR_CHARS),
            error_kind="sandbox", elapsed_s=elapsed,
        )
    for step in skills:
        if isinstance(step, PutAt) and not _valid_position(step.position):
            return _malformed(f"invalid table position {clean_text(step.position, 80)!r}", elapsed)
    result = SandboxResult(skills=skills, skill_failures=failures, said=said, elapsed_s=elapsed)
    error = out.get("error")
    if error is not None:
        if not isinstance(error, dict):
            return _malformed("error must be an object", elapsed)
        etype = clean_text(error.get("type", "Error"), 60)
        kind: ErrorKind = (
            "refused" if etype == "GuardError" else "memory" if etype == "MemoryError"
            else "output" if etype == "OutputLimit" else "runtime"
        )
        result.error = f"{etype}: {clean_text(error.get('message', ''), MAX_ERROR_CHARS)}"
        result.error_kind = kind
        line = error.get("line")
        result.line = line if isinstance(line, int) and not isinstance(line, bool) and 0 < line < 1_000_000 else None
    return result


def _valid_position(position: Any) -> bool:
    if isinstance(position, str):
        return position in TABLE_POSITIONS
    return all(math.isfinite(v) and abs(v) < 100.0 for v in position)


def _names(step: Skill) -> list[str]:
    return [v for k, v in step.model_dump().items() if k in ("block", "bowl", "target")]


_default: Sandbox | None = None
_default_lock = threading.Lock()


def default_sandbox() -> Sandbox:
    """The process-wide sandbox (started on first use, stopped at exit)."""
    global _default
    with _default_lock:
        if _default is None:
            _default = Sandbox()
        return _default
