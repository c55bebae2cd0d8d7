"""The sandbox's boundary without a worker: result parsing that never raises, text cleaning,
the guard's new refusals, the trimmed numpy and the seccomp program itself."""

from __future__ import annotations

import json
import struct

import numpy as np
import pytest

from activeintent.act import seccomp
from activeintent.act.guard import GuardError, check_program
from activeintent.act.robot_api import MAX_SAID_MESSAGES, SAFE_NUMPY, RobotAPI
from activeintent.act.sandbox import Sandbox
from activeintent.act.sanitize import clean_messages, clean_text


# ---- result parsing -----------------------------------------------------------------------------
@pytest.mark.parametrize(
    "raw",
    [
        "[" * 100_000 + "]" * 100_000,  # RecursionError inside json
        '{"said": ' + "[" * 50_000 + "]" * 50_000 + "}",
        "not json",
        "",
        "[]",
        "null",
        '{"skills": "x"}',
        '{"skills": [{"skill": "fly", "block": "red block"}]}',
        '{"skills": [' + ",".join(['{"skill": "put_in", "block": "red block", "bowl": "blue bowl"}'] * 60) + "]}",
        '{"skills": [{"skill": "put_in", "block": "red block", "bowl": "gold bowl"}]}',
        '{"skills": [{"skill": "put_at", "block": "red block", "position": "\\u001b[2Jmoon"}]}',
        '{"skills": [{"skill": "put_at", "block": "red block", "position": [NaN, 0.1]}]}',
        '{"skills": [{"skill": "put_at", "block": "red block", "position": [1e308, 1e308]}]}',
        '{"skill_failures": {"a": 1}}',
        '{"error": "just a string"}',
        '{"error": {"type": ["x"], "message": {"a": 1}, "line": "7"}}',
        '{"said": "not a list"}',
    ],
)
def test_malformed_results_never_raise(raw, state):
    result = Sandbox._parse_result(raw, state, 0.0)
    assert isinstance(result.error, (str, type(None)))
    if result.error is not None:
        assert result.error_kind in ("sandbox", "runtime")
    assert len(result.skills) <= 50


def test_result_strings_are_cleaned_and_capped(state):
    raw = json.dumps({
        "skills": [{"skill": "put_in", "block": "red block", "bowl": "blue bowl"}],
        "skill_failures": ["\x1b[31mblocked\x1b[0m at 0x7f3a2b1c4d5e"],
        "said": ["\ud800 lone", "\x1b]0;title\x07ok", "x" * 10_000] + ["y"] * 500,
        "error": {"type": "ValueError\x1b[2J", "message": "\u202eevil\r" + "z" * 5000, "line": True},
    })
    result = Sandbox._parse_result(raw, state, 0.0)
    assert result.said[0] == "\ufffd lone" and result.said[1] == "ok"
    assert sum(len(s) for s in result.said) <= 4000 and len(result.said) <= 100
    assert result.skill_failures == ["blocked at 0x…"]
    assert result.error.startswith("ValueError: evil") and len(result.error) < 600
    assert result.line is None and result.error_kind == "runtime"
    json.dumps(result.model_dump()).encode("utf-8")


def test_worker_reply_that_is_not_json_is_a_sandbox_failure(state):
    class FakeProc:
        def __init__(self, data: bytes) -> None:
            import os

            self.read_fd, write_fd = os.pipe()
            os.write(write_fd, data)
            os.close(write_fd)
            self.stdout = open(self.read_fd, "rb")  # noqa: SIM115

    sb = Sandbox(isolation="none", unsafe_no_isolation=True)
    for payload in (b"\xff\xfe", b"[" * 5000, b"[1, 2]"):
        sb._proc = FakeProc(struct.pack(">I", len(payload)) + payload)
        assert sb._read(timeout=5.0) is None
        sb._proc.stdout.close()
    sb._proc = FakeProc(struct.pack(">I", 1 << 31))  # absurd size: refused before reading
    assert sb._read(timeout=5.0) is None
    sb._proc.stdout.close()
    sb._proc = None


# ---- text cleaning -------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("text", "clean"),
    [
        ("plain\ttext\nline two", "plain\ttext\nline two"),
        ("\x1b[31mred\x1b[0m", "red"),
        ("\x1b]8;;http://x\x07link\x1b]8;;\x07", "link"),
        ("a\x1bPdevice\x1b\\b", "ab"),
        ("over\rwrite\x08\x07\x00", "overwrite"),
        ("\x9b31mC1", "31mC1"),
        ("bidi\u202eevil\u2066x\u200b", "bidievilx"),
        ("surrogate \udc80", "surrogate \ufffd"),
        ("<object at 0x7ffd1234abcd>", "<object at 0x…>"),
        ("small hex 0xff stays", "small hex 0xff stays"),
    ],
)
def test_clean_text(text, clean):
    assert clean_text(text) == clean


def test_the_cleaners_table_is_unicodes_format_and_control_characters():
    """S2: the cleaner kept U+061C, U+00AD, U+FFF9–FFFB and the tag characters U+E0000–E007F.
    Its one table must now remove exactly what Unicode calls a control, format, line or
    paragraph separator character (and the tag block), every code point checked."""
    from act_helpers import unclean

    from activeintent.act.sanitize import REMOVED

    table = {cp for a, b in REMOVED for cp in range(a, b + 1)}
    by_unicode = {cp for cp in range(0x110000) if not 0xD800 <= cp <= 0xDFFF and unclean(chr(cp))}
    assert table == by_unicode, (sorted(table - by_unicode)[:10], sorted(by_unicode - table)[:10])
    assert clean_text("a\u061cb\u00adc\ufff9d\U000e0041\U000e0000e") == "abcde"
    for cp in sorted(by_unicode - {0x1B}):  # ESC takes the character after it along (an escape sequence)
        assert clean_text(f"x{chr(cp)}y") == "xy", hex(cp)


def test_clean_text_caps_and_never_raises():
    class Unprintable:
        def __str__(self) -> str:
            raise RuntimeError("no")

    assert clean_text(Unprintable()) == "(unprintable)"
    assert len(clean_text("x" * 100_000, limit=50)) == 50
    assert clean_messages("not a list") == []
    assert len(clean_messages(["m"] * 1000)) == 100


# ---- guard ---------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "program",
    [
        "g = (x async for x in objects)",
        "l = [x async for x in objects]",
        "s = {x async for x in objects}",
        "a = np.zeros(2).astype(object)",
        "a = np.zeros(2).astype('O')",
        "a = np.zeros(2).astype()",
        "t = float\na = np.zeros(2, dtype=t)",
        "a = np.zeros(2, dtype='V8')",
        "a = np.zeros(2, dtype=[('f', 'O')])",
        "say(np.zeros(2).strides)",
        "say(np.zeros(2).view(float))",
        "say(np.zeros(2).data)",
        # object dtypes by any route: array methods, positions, unpacking, aliases, rebinding
        "a = np.zeros(3).cumsum(0, 'O')",
        "a = np.zeros(3).cumprod(0, '=O')",
        "a = np.ones((2, 2)).sum(None, 'object')",
        "a = np.ones((2, 2)).prod(0, 'O')",
        "a = np.ones((2, 2)).mean(0, '|O')",
        "a = np.ones((2, 2)).std(0, 'V8')",
        "a = np.ones((2, 2)).var(0, [('f', 'O')])",
        "a = np.ones((2, 2, 2)).trace(0, 0, 1, 'O')",
        "a = np.zeros(3).cumsum(0, b'O')",
        "t = 'O'\na = np.zeros(3).cumsum(0, t)",
        "a = np.zeros(3).cumsum(*[0, 'O'])",
        "a = np.zeros(3).cumsum(**{'dtype': 'O'})",
        "a = np.zeros(3).astype(**{'dtype': 'O'})",
        "f = np.zeros(3).cumsum",
        "a = list(map(np.zeros(3).astype, ['O']))",
        "a = np.zeros(3, 'O')",
        "a = np.array([1], 'O')",
        "a = np.full(3, 0, 'O')",
        "a = np.arange(0, 3, 1, 'O')",
        "a = np.linspace(0, 1, 3, True, False, 'O')",
        "a = np.eye(2, 2, 0, 'O')",
        "a = np.sum(np.zeros(2), None, 'O')",
        "a = np.zeros(3, *['O'])",
        "a = np.zeros(3).astype(np.zeros(1).dtype)",
        "a = np.zeros(3, dtype=np.object_)",
        "d = {}\na = np.zeros(3, dtype=d.float64)",
        "np = np.zeros(3)",
        "np.float64 = 'O'",
        "np.linalg.norm = say",
        "del np",
        "for np in [1]:\n    pass",
        "def f(np):\n    return np",
        "g = lambda np: np",
        "try:\n    pass\nexcept Exception as np:\n    pass",
        "float = 'O'",
        "[0 for int in [1]]",
        "def bool():\n    return 'O'",
    ],
)
def test_guard_refuses(program):
    with pytest.raises(GuardError):
        check_program(program)


@pytest.mark.parametrize(
    "program",
    [
        "a = np.zeros(2, dtype=float)",
        "a = np.array([1, 2], dtype=np.int64)",
        "a = np.round(get_obj_pos('red block') * 100).astype(int)",
        "a = np.ones(3).astype('f8')",
        "a = np.arange(3, dtype='<i8')",
        "a = np.array([1.5]).astype(dtype=np.float32)",
        "a = np.array([[1.0, 2.0]], float).cumsum(0, np.float64).sum(0)",
        "a = np.ones((2, 2)).mean(0)\nb = np.ones((2, 2)).trace()",
        "a = np.zeros(3, 'f8').std(0, 'f4')",
        "a = sorted([np.zeros(2)], key=np.sum)",
        "p = max(objects, key=lambda o: np.linalg.norm(get_obj_pos(o)))",
        "a = np.arange(0, 1, 0.25)\nb = np.linspace(0, 1, 5)\nc = np.full(3, 0.5)",
        "def f(**kw):\n    return kw\nf(**{'a': 1})",
    ],
)
def test_guard_accepts_numeric_dtypes(program):
    check_program(program)


# ---- the numpy programs see ------------------------------------------------------------------------
def test_safe_numpy_refuses_object_and_void_arrays():
    for make in (lambda: SAFE_NUMPY.zeros(3, "O"), lambda: SAFE_NUMPY.array([1, "a", None]),
                 lambda: SAFE_NUMPY.zeros(2, [("f", "f8")]), lambda: SAFE_NUMPY.asarray([object()])):
        with pytest.raises(TypeError, match="not available"):
            make()
    with pytest.raises(TypeError, match="np.ndarray"):
        SAFE_NUMPY.ndarray((2,), buffer=np.zeros(2))


def test_safe_numpy_still_does_cap_math():
    assert isinstance(SAFE_NUMPY.zeros(2), SAFE_NUMPY.ndarray)
    assert not isinstance([1, 2], SAFE_NUMPY.ndarray)
    names = SAFE_NUMPY.array(["red block", "blue bowl"])
    assert names.dtype.kind == "U"
    assert SAFE_NUMPY.linalg.norm(SAFE_NUMPY.array([3.0, 4.0])) == 5.0
    assert SAFE_NUMPY.mean([[0.0, 1.0], [2.0, 3.0]], axis=0).tolist() == [1.0, 2.0]
    assert not hasattr(SAFE_NUMPY, "frombuffer") and not hasattr(SAFE_NUMPY, "lib")


def test_say_count_is_limited(state):
    api = RobotAPI(state)
    for i in range(MAX_SAID_MESSAGES):
        api.say(i)
    with pytest.raises(RuntimeError, match="at most"):
        api.say("one more")


# ---- seccomp program ---------------------------------------------------------------------------------
AUDIT_ARCH = {"x86_64": 0xC000003E, "aarch64": 0xC00000B7}
# Calls the program's process must never make, by number on each architecture.
NEVER = {
    "x86_64": {"openat": 257, "socket": 41, "connect": 42, "clone": 56, "execve": 59, "kill": 62, "ptrace": 101,
               "mkdirat": 258, "unlinkat": 263, "mount": 165, "unshare": 272, "setns": 308, "bpf": 321,
               "io_uring_setup": 425, "inotify_init": 253, "inotify_init1": 294, "inotify_add_watch": 254,
               "fanotify_init": 300, "timer_create": 222, "timerfd_create": 283, "setitimer": 38, "ioctl": 16,
               "read": 0, "dup": 32, "pipe2": 293, "eventfd2": 290, "memfd_create": 319, "setrlimit": 160,
               "prctl": 157, "setsid": 112, "futex": 202},
    "aarch64": {"openat": 56, "socket": 198, "connect": 203, "clone": 220, "execve": 221, "kill": 129,
                "ptrace": 117, "mkdirat": 34, "unlinkat": 35, "mount": 40, "unshare": 97, "setns": 268, "bpf": 280,
                "inotify_init1": 26, "inotify_add_watch": 27, "fanotify_init": 262, "timer_create": 107,
                "timerfd_create": 85, "ioctl": 29, "read": 63, "dup": 23, "pipe2": 59, "memfd_create": 279,
                "setrlimit": 164, "prctl": 167, "setsid": 157, "futex": 98},
}
# Added to Linux 6.6-6.17 after the deny-list was written (same numbers on both architectures):
# statmount, listmount, setxattrat, getxattrat, listxattrat, removexattrat, open_tree_attr,
# file_getattr, file_setattr, and numbers not used yet.
NEW_CALLS = [457, 458, 463, 464, 465, 466, 467, 468, 469, *range(470, 600)]
EPERM = 0x00050000 | 1
ALLOW = 0x7FFF0000
KILL = 0x80000000


def run_filter(prog: bytes, arch: int, nr: int, args: tuple[int, ...] = ()) -> int:
    """Evaluate a classic BPF seccomp program over one seccomp_data (the opcodes it uses)."""
    data = struct.pack("<iIQ6Q", nr, arch, 0, *(list(args) + [0] * (6 - len(args))))
    insns = [struct.unpack("=HBBI", prog[i:i + 8]) for i in range(0, len(prog), 8)]
    pc, acc = 0, 0
    while True:
        code, jt, jf, k = insns[pc]
        if code == 0x20:  # ld w abs
            acc = struct.unpack_from("<I", data, k)[0]
        elif code == 0x15:  # jeq k
            pc += jt if acc == k else jf
        elif code == 0x35:  # jge k
            pc += jt if acc >= k else jf
        elif code == 0x06:  # ret k
            return k
        else:
            raise AssertionError(f"unexpected opcode {code:#x}")
        pc += 1


@pytest.mark.parametrize("machine", ["x86_64", "aarch64"])
def test_seccomp_program_is_an_allow_list(machine):
    prog = seccomp.build_filter(machine)
    assert prog is not None and len(prog) % 8 == 0 and len(prog) // 8 < 256
    arch = AUDIT_ARCH[machine]
    allowed = seccomp.allowed_syscalls(machine)
    assert len(set(allowed.values())) == len(allowed), "two names share a number"
    assert not set(allowed) & set(NEVER[machine])
    for name, nr in allowed.items():
        if name not in ("fcntl", "prlimit64"):
            assert run_filter(prog, arch, nr) == ALLOW, name
    for name, nr in NEVER[machine].items():
        assert run_filter(prog, arch, nr) == EPERM, name
    for nr in NEW_CALLS:
        assert run_filter(prog, arch, nr) == EPERM, nr
    assert run_filter(prog, arch, 435) == 0x00050000 | 38  # clone3: ENOSYS, libc falls back to clone
    assert run_filter(prog, 0x40000003, allowed["write"]) == KILL  # another architecture's ABI
    if machine == "x86_64":
        assert run_filter(prog, arch, 0x40000000 | allowed["write"]) == KILL  # x32
    assert seccomp.build_filter("sparc64") is None


@pytest.mark.parametrize("machine", ["x86_64", "aarch64"])
def test_seccomp_program_checks_arguments(machine):
    prog, arch = seccomp.build_filter(machine), AUDIT_ARCH[machine]
    table = seccomp.allowed_syscalls(machine)
    fcntl, prlimit = table["fcntl"], table["prlimit64"]
    for cmd in seccomp.FCNTL_ALLOWED.values():
        assert run_filter(prog, arch, fcntl, (3, cmd)) == ALLOW
        assert run_filter(prog, arch, fcntl, (3, cmd | (1 << 32))) == ALLOW  # the kernel reads 32 bits
    # F_SETLK, F_SETOWN, F_GETOWN, F_SETSIG, F_SETOWN_EX, F_SETLEASE, F_NOTIFY, F_SETPIPE_SZ, F_ADD_SEALS
    for cmd in (6, 8, 9, 10, 15, 1024, 1026, 1031, 1033):
        assert run_filter(prog, arch, fcntl, (3, cmd)) == EPERM, cmd
    assert run_filter(prog, arch, prlimit, (0, 7, 0, 0x7FFF0000)) == ALLOW  # reading a limit
    assert run_filter(prog, arch, prlimit, (0, 7, 0x7FFF0000, 0)) == EPERM  # setting one
    assert run_filter(prog, arch, prlimit, (0, 7, 1 << 40, 0)) == EPERM
    # issue 58, S1: another pid, existing or not, is refused alike (EPERM against ESRCH told them apart)
    for pid in (1, 4242, 0x3FFFFF, 0xFFFFFFFF):
        assert run_filter(prog, arch, prlimit, (pid, 7, 0, 0x7FFF0000)) == EPERM, pid
    assert run_filter(prog, arch, prlimit, (1 << 32, 7, 0, 0x7FFF0000)) == ALLOW  # a pid_t: the kernel reads 32 bits
