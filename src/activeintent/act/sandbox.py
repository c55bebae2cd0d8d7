"""Run untrusted robot programs (Code as Policies) safely.

Three layers:
1. ``guard.check_program``: an AST allow-list, checked here before anything runs (and again in
   the child).
2. A restricted namespace: only the robot API, a numpy subset as ``np`` and safe builtins.
3. A separate process (see ``sandbox_worker``): a pre-warmed worker interpreter started with
   ``python -I``, an empty environment and an empty temporary working directory forks one child
   per program under CPU-time, memory, file-size, open-file and process limits, kills it at the
   wall-time limit and caps its output. Robot calls cross the process boundary as data: the
   child returns the recorded skills and said messages as JSON, validated here.
"""

from __future__ import annotations

import atexit
import json
import os
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
from typing import Literal

from pydantic import BaseModel, Field, TypeAdapter, ValidationError

from activeintent.act.guard import GuardError, check_program
from activeintent.world.skills import Skill
from activeintent.world.state import WorldState

_SKILLS = TypeAdapter(list[Skill])
_PACKAGE_ROOT = str(Path(__file__).resolve().parents[2])  # the directory holding `activeintent`
_BOOT = "import sys; sys.path.insert(0, sys.argv[1]); from activeintent.act.sandbox_worker import main; main()"
_WORKER_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "LC_ALL": "C.UTF-8"}

ErrorKind = Literal["refused", "runtime", "cpu", "wall", "memory", "output", "crash", "sandbox"]


class SandboxLimits(BaseModel):
    cpu_seconds: int = Field(2, ge=1, le=60)
    wall_seconds: float = Field(5.0, gt=0, le=120)
    memory_mb: int = Field(256, ge=16, le=8192)  # above the worker's own footprint
    max_output_bytes: int = Field(256_000, ge=1024)


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
    """The worker process itself could not be started (not a problem of the program)."""


class Sandbox:
    """One pre-warmed worker; ``run`` is thread-safe (programs run one at a time)."""

    def __init__(self, limits: SandboxLimits | None = None, *, guard: bool = True) -> None:
        """``guard=False`` skips the AST allow-list and gives programs all builtins: only for
        tests that prove the OS-level layer contains what the allow-list would refuse."""
        self.limits = limits or SandboxLimits()
        self.guard = guard
        self._proc: subprocess.Popen | None = None
        self._workdir: str | None = None
        self._stderr = None
        self._lock = threading.Lock()
        self.startup_s: float | None = None
        ref = weakref.ref(self)
        atexit.register(lambda: (sandbox := ref()) is not None and sandbox.close())  # no stray workers

    # ---- worker lifecycle --------------------------------------------------------------
    def start(self) -> None:
        with self._lock:
            self._ensure_started()

    def _ensure_started(self) -> None:
        if self._proc is not None and self._proc.poll() is None:
            return
        self._stop()
        started = time.perf_counter()
        self._workdir = tempfile.mkdtemp(prefix="activeintent-sandbox-")
        self._stderr = tempfile.TemporaryFile()
        self._proc = subprocess.Popen(
            [sys.executable, "-I", "-c", _BOOT, _PACKAGE_ROOT],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self._stderr,
            env=dict(_WORKER_ENV), cwd=self._workdir, close_fds=True, start_new_session=True,
        )
        ready = self._read(timeout=60.0)
        if not ready or not ready.get("ready"):
            detail = self._worker_stderr()
            self._stop()
            raise SandboxError(f"the sandbox worker did not start: {detail or 'no output'}")
        self.startup_s = time.perf_counter() - started

    def _worker_stderr(self) -> str:
        if self._stderr is None:
            return ""
        self._stderr.seek(0)
        return self._stderr.read()[-2000:].decode("utf-8", "replace").strip()

    def _stop(self) -> None:
        if self._proc is not None:
            if self._proc.poll() is None:
                try:
                    os.killpg(self._proc.pid, signal.SIGKILL)
                except (ProcessLookupError, PermissionError):
                    pass
            self._proc.wait()
            for stream in (self._proc.stdin, self._proc.stdout):
                if stream is not None:
                    stream.close()
            self._proc = None
        if self._stderr is not None:
            self._stderr.close()
            self._stderr = None
        if self._workdir is not None:
            shutil.rmtree(self._workdir, ignore_errors=True)
            self._workdir = None

    def close(self) -> None:
        with self._lock:
            self._stop()

    def __enter__(self) -> Sandbox:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def worker_pid(self) -> int | None:
        return self._proc.pid if self._proc is not None else None

    # ---- protocol ----------------------------------------------------------------------
    def _read(self, timeout: float) -> dict | None:
        assert self._proc is not None and self._proc.stdout is not None
        fd = self._proc.stdout.fileno()
        deadline = time.monotonic() + timeout
        buf = b""
        need = 4
        size = None
        while len(buf) < need:
            remaining = deadline - time.monotonic()
            if remaining <= 0 or not select.select([fd], [], [], remaining)[0]:
                return None
            chunk = os.read(fd, need - len(buf))
            if not chunk:
                return None
            buf += chunk
            if size is None and len(buf) == 4:
                (size,) = struct.unpack(">I", buf)
                need = 4 + size
        return json.loads(buf[4:])

    # ---- running programs --------------------------------------------------------------
    def run(self, program: str, state: WorldState) -> SandboxResult:
        """Run ``program`` against the CaP robot API over ``state``; never raises for a bad
        program (the error is in the result); raises SandboxError if no worker can start."""
        started = time.perf_counter()
        if self.guard:
            try:
                check_program(program)
            except GuardError as e:
                return SandboxResult(error=f"refused: {e}", error_kind="refused")
        request = {
            "program": program,
            "positions": {k: list(v) for k, v in state.positions.items()},
            "limits": self.limits.model_dump(),
            "guard": self.guard,
        }
        data = json.dumps(request).encode()
        with self._lock:
            reply = None
            for _attempt in range(2):  # a worker that died between programs is replaced once
                self._ensure_started()
                assert self._proc is not None and self._proc.stdin is not None
                try:
                    self._proc.stdin.write(struct.pack(">I", len(data)) + data)
                    self._proc.stdin.flush()
                    reply = self._read(timeout=self.limits.wall_seconds + 10.0)
                except (OSError, ValueError):
                    reply = None
                if reply is not None:
                    break
                try:
                    died = self._proc.wait(timeout=0.5) is not None
                except subprocess.TimeoutExpired:
                    died = False
                self._stop()
                if not died:
                    break  # alive but stuck: do not run the program a second time
            if reply is None:
                return SandboxResult(
                    error="the sandbox worker stopped responding; the program was killed",
                    error_kind="sandbox", elapsed_s=time.perf_counter() - started,
                )
        elapsed = time.perf_counter() - started
        if reply.get("status") != "done":
            kind = reply.get("kind", "crash")
            return SandboxResult(error=str(reply.get("message", "killed")), error_kind=kind, elapsed_s=elapsed)
        return self._parse_result(reply.get("result", ""), state, elapsed)

    @staticmethod
    def _parse_result(raw: str, state: WorldState, elapsed: float) -> SandboxResult:
        """Validate the child's output: it is data from an untrusted process."""
        try:
            out = json.loads(raw)
            skills = _SKILLS.validate_python(out.get("skills", []))
            failures = [None if f is None else str(f)[:500] for f in out.get("skill_failures", [])]
            said = [str(s) for s in out.get("said", [])]
            error = out.get("error")
        except (ValueError, ValidationError, AttributeError, TypeError) as e:
            return SandboxResult(
                error=f"the program's result is malformed: {str(e)[:200]}", error_kind="sandbox", elapsed_s=elapsed
            )
        unknown = sorted({n for s in skills for n in _names(s) if n not in state.positions})
        if unknown:
            return SandboxResult(
                error=f"the program used unknown objects {unknown}", error_kind="sandbox", elapsed_s=elapsed
            )
        result = SandboxResult(skills=skills, skill_failures=failures[: len(skills)], said=said, elapsed_s=elapsed)
        if isinstance(error, dict):
            etype = str(error.get("type", "Error"))[:60]
            kind: ErrorKind = "refused" if etype == "GuardError" else "memory" if etype == "MemoryError" else "runtime"
            result.error = f"{etype}: {str(error.get('message', ''))[:500]}"
            result.error_kind = kind
            line = error.get("line")
            result.line = line if isinstance(line, int) else None
        return result


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
            atexit.register(_default.close)
        return _default
