"""A seccomp filter for the sandbox's program processes (no libseccomp needed).

Installed in each forked child right before the untrusted program runs, after its own
set-up. It refuses (EPERM) every system call that opens a file or creates a socket, starts a
process or a thread, executes a file, signals or inspects another process, changes the file
system, mounts, creates namespaces, uses System V / POSIX IPC, loads kernel code or sets a
resource limit (reading limits stays possible). Everything else (memory, reading and writing
descriptors already open, time) stays allowed. Calls through another ABI (32-bit or x32 on
x86-64) kill the process.

The filter is written as classic BPF by hand for x86-64 and aarch64; on any other architecture
:func:`build_filter` returns None and the sandbox reports that it runs without seccomp.
"""

from __future__ import annotations

import ctypes
import errno
import platform
import struct

# The denied system calls, by name, and their numbers on each supported architecture
# (from the Linux UAPI headers: asm/unistd_64.h and asm-generic/unistd.h).
_X86_64 = {
    "open": 2, "creat": 85, "openat": 257, "openat2": 437, "open_by_handle_at": 304, "name_to_handle_at": 303,
    "socket": 41, "socketpair": 53, "connect": 42, "bind": 49, "listen": 50, "accept": 43, "accept4": 288,
    "fork": 57, "vfork": 58, "clone": 56, "clone3": 435, "execve": 59, "execveat": 322,
    "kill": 62, "tkill": 200, "tgkill": 234, "rt_sigqueueinfo": 129, "rt_tgsigqueueinfo": 297,
    "pidfd_open": 434, "pidfd_send_signal": 424, "pidfd_getfd": 438,
    "ptrace": 101, "process_vm_readv": 310, "process_vm_writev": 311, "kcmp": 312, "process_madvise": 440,
    "move_pages": 279, "migrate_pages": 256,
    "mkdir": 83, "mkdirat": 258, "rmdir": 84, "unlink": 87, "unlinkat": 263, "rename": 82, "renameat": 264,
    "renameat2": 316, "link": 86, "linkat": 265, "symlink": 88, "symlinkat": 266, "mknod": 133, "mknodat": 259,
    "chmod": 90, "fchmod": 91, "fchmodat": 268, "fchmodat2": 452, "chown": 92, "fchown": 93, "lchown": 94,
    "fchownat": 260, "truncate": 76, "ftruncate": 77, "utime": 132, "utimes": 235, "futimesat": 261,
    "utimensat": 280, "setxattr": 188, "lsetxattr": 189, "fsetxattr": 190, "removexattr": 197,
    "lremovexattr": 198, "fremovexattr": 199,
    "mount": 165, "umount2": 166, "pivot_root": 155, "chroot": 161, "unshare": 272, "setns": 308,
    "open_tree": 428, "move_mount": 429, "fsopen": 430, "fsconfig": 431, "fsmount": 432, "fspick": 433,
    "mount_setattr": 442,
    "bpf": 321, "perf_event_open": 298, "userfaultfd": 323, "io_uring_setup": 425, "io_uring_enter": 426,
    "io_uring_register": 427, "keyctl": 250, "add_key": 248, "request_key": 249,
    "personality": 135, "modify_ldt": 154, "iopl": 172, "ioperm": 173, "uselib": 134, "_sysctl": 156,
    "acct": 163, "swapon": 167, "swapoff": 168, "reboot": 169, "sethostname": 170, "setdomainname": 171,
    "init_module": 175, "finit_module": 313, "delete_module": 176, "kexec_load": 246, "kexec_file_load": 320,
    "syslog": 103, "vhangup": 153, "quotactl": 179, "lookup_dcookie": 212,
    "msgget": 68, "msgsnd": 69, "msgrcv": 70, "msgctl": 71, "semget": 64, "semop": 65, "semctl": 66,
    "semtimedop": 220, "shmget": 29, "shmat": 30, "shmctl": 31, "shmdt": 67,
    "mq_open": 240, "mq_unlink": 241, "mq_timedsend": 242, "mq_timedreceive": 243, "mq_notify": 244,
    "mq_getsetattr": 245, "fanotify_init": 300, "fanotify_mark": 301,
    "setrlimit": 160, "prlimit64": 302, "setpgid": 109, "setsid": 112, "prctl": 157, "capset": 126,
    "settimeofday": 164, "adjtimex": 159, "clock_settime": 227, "clock_adjtime": 305,
}
_AARCH64 = {
    "openat": 56, "openat2": 437, "open_by_handle_at": 265, "name_to_handle_at": 264,
    "socket": 198, "socketpair": 199, "connect": 203, "bind": 200, "listen": 201, "accept": 202, "accept4": 242,
    "clone": 220, "clone3": 435, "execve": 221, "execveat": 281,
    "kill": 129, "tkill": 130, "tgkill": 131, "rt_sigqueueinfo": 138, "rt_tgsigqueueinfo": 240,
    "pidfd_open": 434, "pidfd_send_signal": 424, "pidfd_getfd": 438,
    "ptrace": 117, "process_vm_readv": 270, "process_vm_writev": 271, "kcmp": 272, "process_madvise": 440,
    "move_pages": 239, "migrate_pages": 238,
    "mkdirat": 34, "unlinkat": 35, "renameat": 38, "renameat2": 276, "linkat": 37, "symlinkat": 36,
    "mknodat": 33, "fchmod": 52, "fchmodat": 53, "fchmodat2": 452, "fchown": 55, "fchownat": 54,
    "truncate": 45, "ftruncate": 46, "utimensat": 88,
    "setxattr": 5, "lsetxattr": 6, "fsetxattr": 7, "removexattr": 14, "lremovexattr": 15, "fremovexattr": 16,
    "mount": 40, "umount2": 39, "pivot_root": 41, "chroot": 51, "unshare": 97, "setns": 268,
    "open_tree": 428, "move_mount": 429, "fsopen": 430, "fsconfig": 431, "fsmount": 432, "fspick": 433,
    "mount_setattr": 442,
    "bpf": 280, "perf_event_open": 241, "userfaultfd": 282, "io_uring_setup": 425, "io_uring_enter": 426,
    "io_uring_register": 427, "keyctl": 219, "add_key": 217, "request_key": 218,
    "personality": 92, "acct": 89, "swapon": 224, "swapoff": 225, "reboot": 142, "sethostname": 161,
    "setdomainname": 162, "init_module": 105, "finit_module": 273, "delete_module": 106, "kexec_load": 104,
    "kexec_file_load": 294, "syslog": 116, "vhangup": 58, "quotactl": 60, "lookup_dcookie": 18,
    "msgget": 186, "msgsnd": 189, "msgrcv": 188, "msgctl": 187, "semget": 190, "semop": 193, "semctl": 191,
    "semtimedop": 192, "shmget": 194, "shmat": 196, "shmctl": 195, "shmdt": 197,
    "mq_open": 180, "mq_unlink": 181, "mq_timedsend": 182, "mq_timedreceive": 183, "mq_notify": 184,
    "mq_getsetattr": 185, "fanotify_init": 262, "fanotify_mark": 263,
    "setrlimit": 164, "prlimit64": 261, "setpgid": 154, "setsid": 157, "prctl": 167, "capset": 91,
    "settimeofday": 170, "adjtimex": 171, "clock_settime": 112, "clock_adjtime": 266,
}
# (AUDIT_ARCH_* value, syscall table, lowest number of a foreign ABI to refuse or None)
_ARCHES = {
    "x86_64": (0xC000003E, _X86_64, 0x40000000),  # x32 calls carry bit 30
    "amd64": (0xC000003E, _X86_64, 0x40000000),
    "aarch64": (0xC00000B7, _AARCH64, None),
    "arm64": (0xC00000B7, _AARCH64, None),
}
# clone3 answers ENOSYS so that libc falls back to clone, which is refused with EPERM.
_ERRNO = {"clone3": errno.ENOSYS}

# classic BPF opcodes
_LD_W_ABS = 0x20
_JEQ_K = 0x15
_JGE_K = 0x35
_RET_K = 0x06
_RET_KILL_PROCESS = 0x80000000
_RET_ERRNO = 0x00050000
_RET_ALLOW = 0x7FFF0000
_ARG2_LOW = 16 + 2 * 8  # seccomp_data: nr, arch, instruction_pointer, then args[6] (little-endian)
_PR_SET_NO_NEW_PRIVS = 38
_PR_SET_SECCOMP = 22
_SECCOMP_MODE_FILTER = 2


def _insn(code: int, jt: int, jf: int, k: int) -> bytes:
    return struct.pack("=HBBI", code, jt, jf, k & 0xFFFFFFFF)


def denied_syscalls(machine: str | None = None) -> dict[str, int]:
    arch = _ARCHES.get((machine or platform.machine()).lower())
    return dict(arch[1]) if arch else {}


def build_filter(machine: str | None = None) -> bytes | None:
    """The BPF program for this machine (None if the architecture is not supported)."""
    arch = _ARCHES.get((machine or platform.machine()).lower())
    if arch is None:
        return None
    audit_arch, table, foreign_from = arch
    prog = [
        _insn(_LD_W_ABS, 0, 0, 4),  # seccomp_data.arch
        _insn(_JEQ_K, 1, 0, audit_arch),
        _insn(_RET_K, 0, 0, _RET_KILL_PROCESS),
        _insn(_LD_W_ABS, 0, 0, 0),  # seccomp_data.nr
    ]
    if foreign_from is not None:
        prog += [_insn(_JGE_K, 0, 1, foreign_from), _insn(_RET_K, 0, 0, _RET_KILL_PROCESS)]
    # prlimit64 may read limits (new_limit, the third argument, NULL) but never set them.
    prog += [
        _insn(_JEQ_K, 0, 6, table["prlimit64"]),
        _insn(_LD_W_ABS, 0, 0, _ARG2_LOW),
        _insn(_JEQ_K, 0, 3, 0),
        _insn(_LD_W_ABS, 0, 0, _ARG2_LOW + 4),
        _insn(_JEQ_K, 0, 1, 0),
        _insn(_RET_K, 0, 0, _RET_ALLOW),
        _insn(_RET_K, 0, 0, _RET_ERRNO | errno.EPERM),
        _insn(_LD_W_ABS, 0, 0, 0),
    ]
    for name, nr in sorted(table.items(), key=lambda item: item[1]):
        if name == "prlimit64":
            continue
        code = _ERRNO.get(name, errno.EPERM)
        prog += [_insn(_JEQ_K, 0, 1, nr), _insn(_RET_K, 0, 0, _RET_ERRNO | code)]
    prog.append(_insn(_RET_K, 0, 0, _RET_ALLOW))
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
