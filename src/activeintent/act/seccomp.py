"""A seccomp filter for the sandbox's program processes (no libseccomp needed).

Installed in each program's process right before the untrusted program runs, after its own
set-up (imports, limits, descriptors). It is an **allow-list**: only the system calls that
CPython and numpy make while running an already-compiled program in a warm process pass. Every
other call, including those added to Linux after this file was written, answers ``EPERM``
(``clone3`` answers ``ENOSYS`` so that libc falls back to ``clone``, which is refused too).
Calls through another ABI (32-bit or x32 on x86-64) kill the process.

What passes, and why the program needs it:

- memory: ``brk``, ``mmap``, ``munmap``, ``mremap``, ``mprotect`` (malloc, pymalloc's arenas,
  numpy's buffers) and ``madvise`` (numpy asks for huge pages for big arrays);
- ``write`` (the result goes to the pipe on fd 3; stray stderr output goes to /dev/null) and
  ``close``;
- ``fcntl`` with the descriptor-flag and duplication commands only (``F_DUPFD``, ``F_GETFD``,
  ``F_SETFD``, ``F_GETFL``, ``F_SETFL``, ``F_DUPFD_CLOEXEC``): never ``F_SETOWN``,
  ``F_SETOWN_EX``, ``F_SETSIG``, ``F_SETLEASE`` or ``F_NOTIFY``, with which a program could have
  the kernel signal another process (the worker, or without namespaces any process of the
  user) when its pipe is read;
- ending: ``exit``, ``exit_group``; signals to itself only: ``rt_sigaction``,
  ``rt_sigprocmask``, ``rt_sigreturn``, ``restart_syscall``;
- reading (never setting) clocks, its own ids and its resource limits: ``clock_gettime``,
  ``clock_getres``, ``gettimeofday``, ``time``, ``getpid``, ``getppid``, ``gettid``,
  ``getuid``, ``geteuid``, ``getgid``, ``getegid``, ``getrlimit`` and ``prlimit64`` on pid 0
  (itself) with no new limit (libc's abort path reads the pid; a clock without a vDSO fast path
  is a real call).

That list was checked with ``strace -f`` on the worker running the test suite's programs: after
the filter, a program process made only ``brk``, ``mmap``, ``munmap``, ``write`` and
``exit_group``. Nothing else — no file, socket, process, signal to another process, timer,
inotify, mount listing, extended attribute or namespace call — is reachable.

The filter is written as classic BPF by hand for x86-64 and aarch64; on any other architecture
:func:`build_filter` returns None and the sandbox reports that it runs without seccomp.
"""

from __future__ import annotations

import ctypes
import errno
import platform
import struct

# The allowed system calls, by name, and their numbers on each supported architecture
# (from the Linux UAPI headers: asm/unistd_64.h and asm-generic/unistd.h).
_X86_64 = {
    "brk": 12, "mmap": 9, "munmap": 11, "mremap": 25, "mprotect": 10, "madvise": 28,
    "write": 1, "close": 3, "fcntl": 72,
    "exit": 60, "exit_group": 231, "rt_sigaction": 13, "rt_sigprocmask": 14, "rt_sigreturn": 15,
    "restart_syscall": 219,
    "clock_gettime": 228, "clock_getres": 229, "gettimeofday": 96, "time": 201,
    "getpid": 39, "getppid": 110, "gettid": 186, "getuid": 102, "geteuid": 107, "getgid": 104, "getegid": 108,
    "getrlimit": 97, "prlimit64": 302,
}
_AARCH64 = {
    "brk": 214, "mmap": 222, "munmap": 215, "mremap": 216, "mprotect": 226, "madvise": 233,
    "write": 64, "close": 57, "fcntl": 25,
    "exit": 93, "exit_group": 94, "rt_sigaction": 134, "rt_sigprocmask": 135, "rt_sigreturn": 139,
    "restart_syscall": 128,
    "clock_gettime": 113, "clock_getres": 114, "gettimeofday": 169,
    "getpid": 172, "getppid": 173, "gettid": 178, "getuid": 174, "geteuid": 175, "getgid": 176, "getegid": 177,
    "getrlimit": 163, "prlimit64": 261,
}
# clone3 answers ENOSYS so that libc falls back to clone (refused with EPERM like the rest).
_ENOSYS = {"x86_64": 435, "aarch64": 435}
# fcntl commands that only read or set the descriptor's own flags or duplicate it (the new
# descriptor still counts against RLIMIT_NOFILE).
FCNTL_ALLOWED = {"F_DUPFD": 0, "F_GETFD": 1, "F_SETFD": 2, "F_GETFL": 3, "F_SETFL": 4, "F_DUPFD_CLOEXEC": 1030}
# (AUDIT_ARCH_* value, allowed calls, lowest number of a foreign ABI to refuse or None)
_ARCHES = {
    "x86_64": (0xC000003E, _X86_64, 0x40000000, "x86_64"),  # x32 calls carry bit 30
    "amd64": (0xC000003E, _X86_64, 0x40000000, "x86_64"),
    "aarch64": (0xC00000B7, _AARCH64, None, "aarch64"),
    "arm64": (0xC00000B7, _AARCH64, None, "aarch64"),
}

# classic BPF opcodes
_LD_W_ABS = 0x20
_JEQ_K = 0x15
_JGE_K = 0x35
_RET_K = 0x06
_RET_KILL_PROCESS = 0x80000000
_RET_ERRNO = 0x00050000
_RET_ALLOW = 0x7FFF0000
_ARG_LOW = [16 + 8 * i for i in range(6)]  # seccomp_data: nr, arch, ip, then args[6] (little-endian)
_PR_SET_NO_NEW_PRIVS = 38
_PR_SET_SECCOMP = 22
_SECCOMP_MODE_FILTER = 2


def _insn(code: int, jt: int, jf: int, k: int) -> bytes:
    return struct.pack("=HBBI", code, jt, jf, k & 0xFFFFFFFF)


def allowed_syscalls(machine: str | None = None) -> dict[str, int]:
    """The system calls a program's process may make on ``machine`` (empty if unsupported)."""
    arch = _ARCHES.get((machine or platform.machine()).lower())
    return dict(arch[1]) if arch else {}


def _allow_if_arg_in(arg: int, values: list[int]) -> list[bytes]:
    """Allow when the low 32 bits of argument ``arg`` are one of ``values``, else EPERM; then
    reload the call number. (fcntl's command is an ``unsigned int``: the kernel ignores the
    upper half, so the filter must too.)"""
    prog = [_insn(_LD_W_ABS, 0, 0, _ARG_LOW[arg])]
    for i, value in enumerate(values):
        prog.append(_insn(_JEQ_K, len(values) - i, 0, value))
    prog += [_insn(_RET_K, 0, 0, _RET_ERRNO | errno.EPERM), _insn(_RET_K, 0, 0, _RET_ALLOW)]
    return prog


def build_filter(machine: str | None = None) -> bytes | None:
    """The BPF program for this machine (None if the architecture is not supported)."""
    arch = _ARCHES.get((machine or platform.machine()).lower())
    if arch is None:
        return None
    audit_arch, table, foreign_from, key = arch
    prog = [
        _insn(_LD_W_ABS, 0, 0, 4),  # seccomp_data.arch
        _insn(_JEQ_K, 1, 0, audit_arch),
        _insn(_RET_K, 0, 0, _RET_KILL_PROCESS),
        _insn(_LD_W_ABS, 0, 0, 0),  # seccomp_data.nr
    ]
    if foreign_from is not None:
        prog += [_insn(_JGE_K, 0, 1, foreign_from), _insn(_RET_K, 0, 0, _RET_KILL_PROCESS)]
    # fcntl: only the commands in FCNTL_ALLOWED.
    fcntl_check = _allow_if_arg_in(1, sorted(FCNTL_ALLOWED.values()))
    prog += [_insn(_JEQ_K, 0, len(fcntl_check), table["fcntl"]), *fcntl_check]
    # prlimit64 may read its own limits (pid, the first argument, 0: a pid_t, so its low 32 bits;
    # new_limit, the third, NULL) but never set any, nor name another process: EPERM for every
    # other pid, so EPERM against ESRCH cannot tell which host pids exist.
    prog += [
        _insn(_JEQ_K, 0, 8, table["prlimit64"]),
        _insn(_LD_W_ABS, 0, 0, _ARG_LOW[0]),
        _insn(_JEQ_K, 0, 5, 0),
        _insn(_LD_W_ABS, 0, 0, _ARG_LOW[2]),
        _insn(_JEQ_K, 0, 3, 0),
        _insn(_LD_W_ABS, 0, 0, _ARG_LOW[2] + 4),
        _insn(_JEQ_K, 0, 1, 0),
        _insn(_RET_K, 0, 0, _RET_ALLOW),
        _insn(_RET_K, 0, 0, _RET_ERRNO | errno.EPERM),
    ]
    prog += [_insn(_JEQ_K, 0, 1, _ENOSYS[key]), _insn(_RET_K, 0, 0, _RET_ERRNO | errno.ENOSYS)]
    for name, nr in sorted(table.items(), key=lambda item: item[1]):
        if name in ("fcntl", "prlimit64"):
            continue
        prog += [_insn(_JEQ_K, 0, 1, nr), _insn(_RET_K, 0, 0, _RET_ALLOW)]
    prog.append(_insn(_RET_K, 0, 0, _RET_ERRNO | errno.EPERM))  # everything else, new calls included
    return b"".join(prog)


class _SockFprog(ctypes.Structure):
    _fields_ = [("len", ctypes.c_ushort), ("filter", ctypes.c_void_p)]


class Seccomp:
    """Prepared before forking (libc loaded, program built); :meth:`install` in the child."""

    def __init__(self) -> None:
        self.program = build_filter()
        self._libc = ctypes.CDLL(None, use_errno=True) if self.program else None
        self._buffer = ctypes.create_string_buffer(self.program) if self.program else None

    @property
    def available(self) -> bool:
        return self.program is not None

    def install(self) -> None:
        """Apply the filter to this process (irreversible); raises OSError if the kernel refuses."""
        if self.program is None or self._libc is None or self._buffer is None:
            raise OSError(errno.ENOSYS, f"no seccomp filter for {platform.machine()}")
        prctl = self._libc.prctl
        prctl.argtypes = [ctypes.c_int, ctypes.c_ulong, ctypes.c_void_p, ctypes.c_ulong, ctypes.c_ulong]
        if prctl(_PR_SET_NO_NEW_PRIVS, 1, None, 0, 0) != 0:
            raise OSError(ctypes.get_errno(), "prctl(PR_SET_NO_NEW_PRIVS) failed")
        fprog = _SockFprog(len(self.program) // 8, ctypes.addressof(self._buffer))
        if prctl(_PR_SET_SECCOMP, _SECCOMP_MODE_FILTER, ctypes.addressof(fprog), 0, 0) != 0:
            raise OSError(ctypes.get_errno(), "prctl(PR_SET_SECCOMP) failed")
