"""Hostile robot programs and what must happen to each.

Every program runs twice per user (root and unprivileged in CI): with the AST guard, where it
must be ``refused`` by the guard, ``contained`` (stopped with an error by a limit, the
restricted namespace or the OS layer) or ``harmless`` (it runs, and reaches nothing); and
without the guard, with all builtins and imports, where only the OS layer (namespaces, seccomp,
resource limits) stands between it and the machine. Programs tagged ``os`` also run with only
the namespaces and with only seccomp, to show each OS layer holds on its own. Programs tagged
``seccomp`` probe system calls the filter must refuse: they say SYSCALL_ALLOWED when a call got
past it, which no run with seccomp may show.

In every run, whatever the outcome: no file appears, changes (extended attributes included) or
disappears outside the jail, no connection reaches the test's listener, no secret of the parent's environment comes back, the
parent and the victim process live, the output is clean text, and the sandbox keeps working.

Placeholders, filled in by the test: CANARY (a file that must never exist), OPEN_DIR (a
world-writable folder that must stay empty), VICTIM_FILE (a world-writable file that must stay
as it is), VICTIM_PID (a process of the test's user that must survive), PARENT_PID (the test
process), PORT and UDP_PORT (the listeners), SECRET_NAME (a variable of the parent's environment).
"""

from __future__ import annotations

from typing import NamedTuple


class Hostile(NamedTuple):
    name: str
    program: str
    guarded: str  # "refused" | "contained" | "harmless"
    tags: frozenset[str] = frozenset()


REFUSED, CONTAINED, HARMLESS = "refused", "contained", "harmless"
OS = frozenset({"os"})
SLOW = frozenset({"slow"})  # runs into the CPU or wall-time limit
SECCOMP = frozenset({"os", "seccomp"})
SYSCALL_ALLOWED = "SYSCALL-ALLOWED"

# Programs that call libc through ctypes (loaded already, so no file is opened): errno 1 (EPERM)
# is the filter's answer; anything else means the call reached the kernel.
_LIBC = "import ctypes, os, signal\nlibc = ctypes.CDLL(None, use_errno=True)\n"


def _reached(*calls: str, before: str = "") -> str:
    """A program that says SYSCALL_ALLOWED if any of ``calls`` got past seccomp."""
    lines = [_LIBC + before, "reached = []"]
    for call in calls:
        lines.append(f"r = {call}\nif r >= 0 or ctypes.get_errno() != 1:\n    reached.append({call!r})")
    lines.append(f"if reached:\n    say('{SYSCALL_ALLOWED}')\n    say(reached)")
    return "\n".join(lines)


def _sigio(owner: str, signum: str) -> str:
    """Ask the kernel to send ``signum`` to ``owner`` whenever the result pipe is read (the
    audit's S1: the worker reads it), then write to it."""
    return _LIBC + (
        f"ok = [libc.fcntl(3, 8, {owner}), libc.fcntl(3, 10, {signum}), libc.fcntl(3, 4, os.O_ASYNC)]\n"
        f"if min(ok) >= 0:\n    say('{SYSCALL_ALLOWED}')\n"
        "os.write(3, b' ')\n"
        # The signal is sent when the runner reads, as long as this end is open: stay a moment.
        "import time\nt = time.monotonic()\nwhile time.monotonic() - t < 0.5:\n    pass\n"
    )


# struct xattr_args {u64 value; u32 size; u32 flags} for setxattrat (Linux 6.13)
_XATTR_ARGS = "v = ctypes.create_string_buffer(b'owned')\nxa = (ctypes.c_uint64 * 2)(ctypes.addressof(v), 5)\n"


def _h(name: str, program: str, guarded: str, tags: frozenset[str] = frozenset()) -> Hostile:
    return Hostile(name, program, guarded, tags)


CORPUS: list[Hostile] = [
    # ---- imports and builtins that reach the interpreter -------------------------------------
    _h("import", "import os\nos.system('touch CANARY')", REFUSED, OS),
    _h("import-as", "import os.path as p\nsay(p.exists('/'))", REFUSED),
    _h("from-import", "from os import system\nsystem('touch CANARY')", REFUSED, OS),
    _h("relative-import", "from . import sandbox", REFUSED),
    _h("dunder-import", "__import__('os').system('touch CANARY')", REFUSED, OS),
    _h("builtins-subscript", "__builtins__['__import__']('os').system('touch CANARY')", REFUSED, OS),
    _h("builtins-attr", "__builtins__.__import__('os')", REFUSED),
    _h("importlib", "importlib.import_module('os').system('touch CANARY')", REFUSED),
    _h("builtins-module", "builtins.__import__('os')", REFUSED),
    _h("lambda-import", "(lambda: __import__('subprocess'))().run(['touch', 'CANARY'])", REFUSED, OS),
    _h("exec", "exec('import os')", REFUSED),
    _h("eval", "eval(\"__import__('os')\")", REFUSED),
    _h("compile", "compile('import os', 'x', 'exec')", REFUSED),
    _h("globals", "say(globals()['__builtins__'])", REFUSED),
    _h("locals", "say(locals())", REFUSED),
    _h("vars", "say(vars(say))", REFUSED),
    _h("getattr", "say(getattr(say, '__glo' + 'bals__'))", REFUSED),
    _h("breakpoint", "breakpoint()", REFUSED),
    _h("input", "say(input())", REFUSED),
    _h("help", "help()", REFUSED),
    _h("memoryview", "memoryview(b'abc')", REFUSED),
    _h("super", "super()", REFUSED),
    _h("exit", "exit()", REFUSED),
    _h("system-exit", "raise SystemExit(3)", CONTAINED),
    _h("keyboard-interrupt", "raise KeyboardInterrupt", CONTAINED),
    # ---- object-graph escapes: dunders, attribute chains, formatting ------------------------
    _h("subclasses", "().__class__.__bases__[0].__subclasses__()", REFUSED),
    _h("mro", "''.__class__.__mro__[1].__subclasses__()", REFUSED),
    _h("mro-method", "str.mro()", REFUSED),
    _h("func-globals", "say(say.__globals__['RobotAPI'])", REFUSED),
    _h("bound-self", "say(get_obj_pos.__self__.state)", REFUSED),
    _h("wrapped", "say(np.sqrt.__wrapped__)", REFUSED),
    _h(
        "catch-warnings",
        "[c for c in ().__class__.__base__.__subclasses__() if c.__name__ == 'catch_warnings'][0]()"
        "._module.__builtins__['__import__']('os')",
        REFUSED,
    ),
    _h("type", "say(type(say))", REFUSED),
    _h("object", "say(object.__subclasses__())", REFUSED),
    _h("numpy-dict", "say(np.__dict__)", REFUSED),
    _h("ndarray-mro", "say(np.ndarray.mro())", REFUSED),
    _h("walrus-dunder", "(f := __import__)", REFUSED),
    _h("kwarg-dunder", "dict(__builtins__=1)", REFUSED),
    _h("param-dunder", "def f(__x):\n    return __x\nf(1)", REFUSED),
    _h("except-dunder", "try:\n    1 / 0\nexcept Exception as __e:\n    pass", REFUSED),
    _h("exception-context", "try:\n    1 / 0\nexcept Exception as e:\n    say(e.__context__)", REFUSED),
    _h("str-format", "say('{0.__class__.__bases__}'.format(1))", REFUSED),
    _h("str-format-globals", "say('{0.__globals__}'.format(say))", REFUSED),
    _h("str-format-unbound", "say(str.format('{0.__class__}', 1))", REFUSED),
    _h("format-map", "say('{a.__class__}'.format_map({'a': 1}))", REFUSED),
    _h("fstring-dunder", "say(f'{say.__globals__}')", REFUSED),
    _h("class", "class A:\n    pass", REFUSED),
    _h("global", "def f():\n    global x\n    x = 1\nf()", REFUSED),
    _h("nonlocal", "def f():\n    x = 1\n    def g():\n        nonlocal x\n    g()\nf()", REFUSED),
    _h("name-error", "say(RobotAPI)", CONTAINED),
    # ---- numpy: raw memory, strides, buffers, object and structured arrays -------------------
    _h("np-ndarray-buffer", "a = np.ndarray((1 << 20,), dtype=np.int64, buffer=np.zeros(1), strides=(8,))\nsay(a[1000])",
       CONTAINED),
    _h("np-ndarray-offset", "a = np.ndarray((1,), buffer=np.zeros(1), offset=1 << 40)\nsay(a)", CONTAINED),
    _h("np-strides-set", "a = np.zeros(4)\na.strides = (0,)", REFUSED),
    _h("np-strides-read", "say(np.zeros(4).strides)", REFUSED),
    _h("np-as-strided", "a = np.lib.stride_tricks.as_strided(np.zeros(1), shape=(1 << 30,), strides=(8,))", REFUSED),
    _h("np-frombuffer", "say(np.frombuffer(bytes(8), dtype=np.float64))", REFUSED),
    _h("np-data", "m = np.zeros(4).data\nsay(m.cast('B')[0])", REFUSED),
    _h("np-base", "say(np.zeros(4)[1:].base)", REFUSED),
    _h("np-view", "say(np.zeros(4).view(np.int64))", REFUSED),
    _h("np-getfield", "say(np.zeros(2).getfield(np.int64, 8))", REFUSED),
    _h("np-setflags", "a = get_obj_pos('red block')\na.setflags(write=True)", REFUSED),
    _h("np-tobytes", "say(np.zeros(2).tobytes())", REFUSED),
    _h("np-dlpack", "say(np.from_dlpack(np.zeros(2)))", REFUSED),
    _h("np-object-kw", "a = np.array([say], dtype=object)\nsay(a)", REFUSED),
    _h("np-object-str", "a = np.zeros(3, dtype='O')", REFUSED),
    _h("np-object-positional", "a = np.zeros(3, 'O')\nsay(a)", REFUSED),
    _h("np-object-variable", "t = 'O'\na = np.array([1], dtype=t)", REFUSED),
    _h("np-astype-object", "a = np.zeros(2).astype('O')", REFUSED),
    _h("np-astype-variable", "t = 'O'\na = np.zeros(2).astype(t)", REFUSED),
    _h("np-mixed-object", "a = np.array([1, 'a', None])\nsay(a)", CONTAINED),
    _h("np-structured", "a = np.zeros(2, [('f', 'O')])\nsay(a)", REFUSED),
    # Object arrays through array methods and other ways of naming a dtype (audit S5).
    _h("np-method-object", "a = np.zeros(3).cumsum(0, 'O')\na[0] = say\na[1] = a\nsay(a)", REFUSED),
    _h("np-method-sum-object", "a = np.ones((2, 2)).sum(0, object)\na[0] = say", REFUSED),
    _h("np-method-trace-object", "a = np.ones((2, 2, 2)).trace(0, 0, 1, 'O')\na[0] = say", REFUSED),
    _h("np-method-mean-object", "a = np.ones((2, 2)).mean(0, '|O')\na[0] = say", REFUSED),
    _h("np-method-variable", "t = 'O'\na = np.zeros(3).cumprod(0, t)\na[0] = say", REFUSED),
    _h("np-method-alias", "f = np.zeros(3).cumsum\na = f(0, 'O')\na[0] = say", REFUSED),
    _h("np-method-map", "a = list(map(np.zeros(3).cumsum, [0], ['O']))[0]\na[0] = say", REFUSED),
    _h("np-method-star", "a = np.zeros(3).cumsum(*[0, 'O'])\na[0] = say", REFUSED),
    _h("np-method-kwargs", "a = np.zeros(3).cumsum(**{'dtype': 'O'})\na[0] = say", REFUSED),
    _h("np-rebind", "np = np.zeros(3)\na = np.cumsum(0, 'O')\na[0] = say", REFUSED),
    _h("np-param-rebind", "def f(np):\n    return np.cumsum(0, 'O')\na = f(np.zeros(3))\na[0] = say", REFUSED),
    _h("np-float-rebind", "float = 'O'\na = np.zeros(3).astype(float)\na[0] = say", REFUSED),
    _h("np-attribute-set", "np.float64 = 'O'\na = np.zeros(3).astype(np.float64)\na[0] = say", REFUSED),
    _h("np-dtype-object", "a = np.zeros(3).astype(np.zeros(1).dtype)", REFUSED),
    _h("np-dtype-elsewhere", "d = {}\na = np.zeros(3, dtype=d.float64)", REFUSED),
    _h("np-object-bytes", "a = np.zeros(3).cumsum(0, b'O')", REFUSED),
    _h("np-full-object", "a = np.full(3, say)\na[0] = a", CONTAINED),
    # Still possible: an object array numpy makes by itself for a number beyond 64 bits. It is
    # only a list then (no raw memory can be reached); what contains a program is the OS layer.
    _h("np-implicit-object", "a = np.zeros(1) + [10 ** 30]\na[0] = say\nsay(len(a))", HARMLESS),
    # The real numpy, reached by import when the guard is off: raw memory in the child only.
    _h("real-numpy-as-strided", "import numpy\na = numpy.lib.stride_tricks.as_strided(numpy.zeros(1), shape=(1 << 26,), "
       "strides=(64,))\nsay(float(a.sum()))", REFUSED),
    _h("real-numpy-stride-setter", "import numpy\na = numpy.zeros(2)\na.strides = (1 << 40,)\nsay(a[1])", REFUSED),
    _h("real-numpy-object-view", "import numpy\nb = numpy.array([0x41414141], dtype=numpy.int64)\n"
       "o = numpy.ndarray((1,), dtype=object, buffer=b)\nsay(o[0])", REFUSED),
    _h("real-numpy-frombuffer-write", "import numpy\nb = bytearray(8)\na = numpy.frombuffer(b, dtype=numpy.int64)\n"
       "a.setflags(write=True)\na[0] = 1\nsay(b)", REFUSED),
    _h("numpy-ctypeslib", "np.ctypeslib.load_library('libc', '/lib')", REFUSED),
    _h("numpy-load", "say(np.load('/etc/passwd'))", REFUSED),
    _h("numpy-tofile", "np.array([1.0]).tofile('CANARY')", REFUSED),
    _h("numpy-lib", "np.lib.npyio.savetxt('CANARY', [1])", REFUSED),
    _h("numpy-ctypes", "say(np.zeros(3).ctypes.data)", REFUSED),
    # ---- generators, frames, tracebacks, async ----------------------------------------------
    _h("gi-frame", "g = (x for x in [1])\nsay(g.gi_frame.f_back.f_globals)", REFUSED),
    _h("yield", "def f():\n    yield 1\ng = f()\nsay(g.gi_code)", REFUSED),
    _h("yield-from", "def f():\n    yield from [1]\nsay(list(f()))", REFUSED),
    _h("tb-frame", "try:\n    1 / 0\nexcept Exception as e:\n    say(e.__traceback__.tb_frame.f_globals)", REFUSED),
    _h("with-traceback", "try:\n    1 / 0\nexcept Exception as e:\n    say(e.with_traceback(None))", REFUSED),
    _h("async-def", "async def f():\n    pass", REFUSED),
    _h("async-genexp", "g = (x async for x in y)\nsay(g.ag_frame)", REFUSED),
    _h("async-genexp-plain", "g = (x async for x in objects)", REFUSED),
    _h("async-listcomp", "say([x async for x in objects])", REFUSED),
    _h("await", "await say('x')", REFUSED),
    _h("aiter", "say(aiter(objects))", REFUSED),
    _h("genexp-throw", "g = (x for x in [1, 2])\nnext(g)\ng.throw(ValueError('thrown in'))", CONTAINED),
    # ---- the OS: environment, files, network, processes --------------------------------------
    _h("environ", "import os\nsay(os.environ['SECRET_NAME'])", REFUSED, OS),
    _h("proc-self-environ", "say(open('/proc/self/environ').read())", REFUSED, OS),
    _h("proc-parent-environ", "say(open('/proc/PARENT_PID/environ').read())", REFUSED, OS),
    _h("proc-parent-cmdline", "say(open('/proc/PARENT_PID/cmdline').read())", REFUSED, OS),
    _h("read-passwd", "say(open('/etc/passwd').read())", REFUSED, OS),
    _h("write-file", "open('CANARY', 'w').write('pwned')", REFUSED, OS),
    _h("with-open", "with open('CANARY', 'w') as f:\n    f.write('x')", REFUSED, OS),
    _h("write-open-dir", "open('OPEN_DIR/dropped', 'w').write('x')", REFUSED, OS),
    _h("socket", "import socket\ns = socket.socket()\ns.connect(('127.0.0.1', PORT))", REFUSED, OS),
    _h("socket-dunder", "__import__('socket').socket().connect(('127.0.0.1', PORT))", REFUSED, OS),
    _h("socket-udp", "import socket\ns = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)\ns.sendto(b'x', ('127.0.0.1', UDP_PORT))",
       REFUSED, OS),
    _h("fork", "import os\nif os.fork() == 0:\n    open('CANARY', 'w').write('child')", REFUSED, OS),
    _h("fork-bomb", "import os\nwhile True:\n    os.fork()", REFUSED, OS),
    _h("subprocess", "import subprocess\nsubprocess.run(['touch', 'CANARY'])", REFUSED, OS),
    _h("exec-shell", "import os\nos.execv('/bin/sh', ['sh', '-c', 'touch CANARY'])", REFUSED, OS),
    # ctypes is loaded already (numpy uses it) and needs no file; system() needs fork and exec.
    _h("ctypes-system", "import ctypes\nstatus = ctypes.CDLL(None).system(b'touch CANARY')\nassert status == 0, status",
       REFUSED, OS),
    _h("ctypes-socket", "import ctypes\nfd = ctypes.CDLL(None).socket(2, 1, 0)\nsay(fd)", REFUSED, OS),
    _h("ctypes-null", "import ctypes\nsay(ctypes.string_at(0, 8))", REFUSED, OS),
    _h("ctypes-ptrace", "import ctypes\nsay(ctypes.CDLL(None).ptrace(16, VICTIM_PID, 0, 0))", REFUSED, OS),
    _h("ctypes-unshare", "import ctypes\nsay(ctypes.CDLL(None).unshare(0x10000000 | 0x40000000))", REFUSED, OS),
    # Closing a descriptor first makes room under the open-files limit.
    _h("close-then-read", "import os\nos.close(0)\nsay(open('/etc/passwd').read())", REFUSED, OS),
    _h("close-then-environ", "import os\nos.close(0)\nsay(open('/proc/PARENT_PID/environ').read())", REFUSED, OS),
    _h("close-then-write", "import os\nos.close(0)\nopen('CANARY', 'w').write('x')", REFUSED, OS),
    _h("close-then-socket", "import os, socket\nos.close(0)\nos.close(1)\ns = socket.socket()\n"
       "s.connect(('127.0.0.1', PORT))", REFUSED, OS),
    _h("listdir-root", "import os\nsay(os.listdir('/'))", REFUSED, OS),
    # Operations that need no new descriptor at all.
    _h("mkdir", "import os\nos.mkdir('OPEN_DIR/made')", REFUSED, OS),
    _h("unlink", "import os\nos.unlink('VICTIM_FILE')", REFUSED, OS),
    _h("rename", "import os\nos.rename('VICTIM_FILE', 'OPEN_DIR/moved')", REFUSED, OS),
    _h("chmod", "import os\nos.chmod('VICTIM_FILE', 0)", REFUSED, OS),
    _h("symlink", "import os\nos.symlink('/etc/passwd', 'OPEN_DIR/link')", REFUSED, OS),
    _h("hardlink", "import os\nos.link('VICTIM_FILE', 'OPEN_DIR/hard')", REFUSED, OS),
    _h("truncate", "import os\nos.truncate('VICTIM_FILE', 0)", REFUSED, OS),
    _h("utime", "import os\nos.utime('VICTIM_FILE', (0, 0))", REFUSED, OS),
    _h("mkfifo", "import os\nos.mkfifo('OPEN_DIR/fifo')", REFUSED, OS),
    _h("kill-victim", "import os, signal\nos.kill(VICTIM_PID, signal.SIGKILL)", REFUSED, OS),
    _h("kill-parent", "import os, signal\nos.kill(PARENT_PID, signal.SIGTERM)", REFUSED, OS),
    _h("stop-victim", "import os, signal\nos.kill(VICTIM_PID, signal.SIGSTOP)", REFUSED, OS),
    _h("kill-worker", "import os, signal\nos.kill(os.getppid(), signal.SIGKILL)", REFUSED, OS),
    _h("chroot-escape", "import os\nos.chroot('/')\nsay(os.listdir('/'))", REFUSED, OS),
    _h("setrlimit", "import resource\nresource.setrlimit(resource.RLIMIT_NOFILE, (64, 64))\n"
       "say(open('/etc/passwd').read())", REFUSED, OS),
    _h("hostname", "import socket\nsay(socket.gethostname())", REFUSED, OS),
    _h("secret-in-memory", "import gc\nsay([o for o in gc.get_objects() if isinstance(o, str) and 'sk-fake' in o])",
       REFUSED, OS),
    # Signals by proxy: the kernel signals a descriptor's owner when the result pipe is read
    # (audit S1). Stopping or killing the worker must neither stall the parent nor re-run the
    # program; without namespaces (as a normal user) the victim is the user's own process.
    _h("sigio-stop-worker", _sigio("os.getppid()", "signal.SIGSTOP"), REFUSED, SECCOMP),
    _h("sigio-stop-worker-group", _sigio("-os.getpgid(os.getppid())", "signal.SIGSTOP"), REFUSED, SECCOMP),
    _h("sigio-kill-worker", _sigio("os.getppid()", "signal.SIGKILL"), REFUSED, SECCOMP),
    _h("sigio-kill-worker-group", _sigio("-os.getpgid(os.getppid())", "signal.SIGKILL"), REFUSED, SECCOMP),
    _h("sigio-kill-victim", _sigio("VICTIM_PID", "signal.SIGKILL"), REFUSED, SECCOMP),
    _h("sigio-owner-ex", _reached("libc.fcntl(3, 15, (ctypes.c_int * 2)(1, os.getppid()))",
                                  "libc.fcntl(3, 10, signal.SIGSTOP)"), REFUSED, SECCOMP),
    _h("fcntl-lease-notify", _reached("libc.fcntl(3, 1024, 0)", "libc.fcntl(3, 1026, 0x80000001)",
                                      "libc.fcntl(3, 9, 0)", "libc.fcntl(3, 1031, 1 << 20)"), REFUSED, SECCOMP),
    # What the host does, its mounts and kernel memory outside RLIMIT_AS (audit S3).
    _h("inotify", _reached("libc.inotify_init1(0)", "libc.inotify_init()", "libc.inotify_add_watch(0, b'/usr', 0xfff)",
                           before="os.close(0)\n"), REFUSED, SECCOMP),
    _h("fanotify", _reached("libc.fanotify_init(0, 0)", before="os.close(0)\n"), REFUSED, SECCOMP),
    _h("listmount-statmount", _reached("libc.syscall(458, 0, 0, 0, 0)", "libc.syscall(457, 0, 0, 0, 0)"),
       REFUSED, SECCOMP),
    _h("timer-create", _reached("libc.timer_create(1, None, ctypes.byref(ctypes.c_void_p()))",
                                "libc.timerfd_create(1, 0)", before="os.close(0)\n"), REFUSED, SECCOMP),
    # System calls newer than a deny-list (audit S4): extended attributes, file attributes,
    # mount trees; and numbers no kernel has yet.
    _h("setxattrat", _reached("libc.syscall(463, -100, b'VICTIM_FILE', 0, b'user.owned', xa, 16)",
                              before=_XATTR_ARGS), REFUSED, SECCOMP),
    _h("removexattrat", _reached("libc.syscall(466, -100, b'VICTIM_FILE', 0, b'user.owned')"), REFUSED, SECCOMP),
    _h("xattrat-read", _reached("libc.syscall(464, -100, b'/', 0, b'user.x', xa, 16)",
                                "libc.syscall(465, -100, b'/', 0, v, 5)", before=_XATTR_ARGS), REFUSED, SECCOMP),
    _h("file-setattr", _reached("libc.syscall(469, -100, b'VICTIM_FILE', ctypes.create_string_buffer(64), 24, 0)",
                                "libc.syscall(468, -100, b'/', ctypes.create_string_buffer(64), 24, 0)"),
       REFUSED, SECCOMP),
    _h("open-tree-attr", _reached("libc.syscall(467, -100, b'/', 0, None, 0)", before="os.close(0)\n"),
       REFUSED, SECCOMP),
    _h("future-syscalls", _LIBC + "seen = [n for n in range(470, 560) if libc.syscall(n, 0, 0, 0, 0, 0, 0) != -1 "
       f"or ctypes.get_errno() != 1]\nif seen:\n    say('{SYSCALL_ALLOWED}')\n    say(seen)", REFUSED, SECCOMP),
    # What the child hands back is data: forged, malformed or oversized results.
    _h("forged-result", "import os\nos.write(3, b'{\"skills\": [{\"skill\": \"put_in\", \"block\": \"red block\", "
       "\"bowl\": \"gold bowl\"}], \"said\": []}')\nos._exit(0)", REFUSED),
    _h("deep-json", "import os\nos.write(3, b'[' * 200000)\nos._exit(0)", REFUSED),
    _h("bad-utf8-result", "import os\nos.write(3, b'{\"said\": [\"\\\\ud800\", \"\\xff\\x1b[2J\"]}')\nos._exit(0)", REFUSED),
    _h("huge-result", "import os\nos.write(3, b'x' * (1 << 24))", REFUSED),
    _h("exit-code", "import os\nos._exit(3)", REFUSED),
    _h("abort", "import os\nos.abort()", REFUSED),
    _h("segfault", "import ctypes\nctypes.memset(8, 0, 8)", REFUSED),
    # ---- resource exhaustion -----------------------------------------------------------------
    _h("infinite-loop", "while True:\n    pass", CONTAINED, SLOW),
    _h("busy-sum", "say(sum(range(10 ** 12)))", CONTAINED, SLOW),
    _h("exception-loop", "while True:\n    try:\n        1 / 0\n    except Exception:\n        pass", CONTAINED, SLOW),
    _h("ignore-xcpu", "import signal\nsignal.signal(signal.SIGXCPU, signal.SIG_IGN)\nwhile True:\n    pass",
       REFUSED, SLOW),
    _h("sleep", "import time\ntime.sleep(10 ** 6)", REFUSED, SLOW),
    _h("list-bomb", "x = [0] * 10 ** 10", CONTAINED),
    _h("string-bomb", "s = 'a' * 10 ** 11", CONTAINED),
    _h("doubling", "l = [1]\nwhile True:\n    l = l + l", CONTAINED),
    _h("dict-bomb", "d = {}\ni = 0\nwhile True:\n    d[i] = 'x' * 10000\n    i += 1", CONTAINED),
    _h("numpy-bomb", "a = np.zeros((10 ** 6, 10 ** 6))", CONTAINED),
    _h("numpy-arange-bomb", "a = np.arange(10 ** 12)", CONTAINED),
    _h("bigint", "say(len(str(7 ** 10 ** 6)))", CONTAINED),
    _h("recursion", "def f(n):\n    return f(n + 1)\nf(0)", CONTAINED),
    _h("lambda-recursion", "f = lambda n: f(n + 1)\nf(0)", CONTAINED),
    _h("nested-repr", "x = []\nfor i in range(100000):\n    x = [x]\nsay(x)", CONTAINED),
    _h("too-many-moves", "while True:\n    put_first_on_second('red block', 'blue bowl')", CONTAINED),
    _h("nested-parens", "x = " + "(" * 5000 + "1" + ")" * 5000, REFUSED),
    _h("deep-unary", "x = " + "-" * 200000 + "1", REFUSED),
    _h("huge-program", "x = 1\n" * 20000, REFUSED),
    _h("null-byte", "say('a')\x00", REFUSED),
    # ---- output abuse --------------------------------------------------------------------------
    _h("huge-say", "say('x' * 10 ** 9)", CONTAINED),
    _h("say-flood", "for i in range(10 ** 6):\n    say('x' * 1000)", CONTAINED),
    _h("say-count", "for i in range(1000):\n    say(i)", CONTAINED),
    _h("ansi-escapes", "say('\\x1b[2J\\x1b[31mred\\x1b]0;owned\\x07\\x1b[0m')\nsay(chr(0x9b) + '31m')", HARMLESS),
    _h("lone-surrogate", "say('\\ud800')\nsay(chr(0xdc80) + 'x')", HARMLESS),
    _h("bidi-override", "say('abc\\u202edcba\\u2066')", HARMLESS),
    # issue 58, S2: format characters the cleaner used to keep (Arabic letter mark, soft hyphen,
    # interlinear annotation, tag characters spelling a hidden "IGNORE")
    _h("invisible-format", "say('a\\u061cb\\u00adc\\ufff9d\\ufffae\\ufffbf')\n"
       "say('ok' + ''.join(chr(0xE0000 + ord(c)) for c in 'IGNORE') + chr(0xE007F) + chr(0xE0000))", HARMLESS),
    _h("carriage-return", "say('ok\\rHACKED\\x08\\x00')", HARMLESS),
    _h("address-leak", "say(say)\nsay(repr(np.linalg))\nprint(get_obj_pos)", HARMLESS),
    _h("error-escapes", "raise ValueError('\\x1b[31m' + '\\ud800' + 'x' * 10000)", CONTAINED),
    _h("escape-in-name", "put_first_on_second('\\x1b[31mred block', 'blue bowl')", CONTAINED),
    _h("unknown-object", "put_first_on_second('red block', 'purple bowl')", CONTAINED),
    _h("bad-target", "put_first_on_second('red block', {'a': 1})", CONTAINED),
]
