"""Hostile programs: each is refused by the allow-list or contained by the process limits —
no file created, no network, no secret read, the parent unharmed, a clear 'program' failure."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from act_helpers import SECRET_NAME, SECRET_VALUE, assert_no_connection

from activeintent.act.cap import CapExecutor
from activeintent.llm.scripted import ScriptedModel

REFUSED, CONTAINED = "refused", "contained"
CONTAINED_KINDS = {"cpu", "wall", "memory", "runtime", "output", "crash"}

# (id, program, expectation). CANARY is a path that must never exist; PORT a test server.
HOSTILE: list[tuple[str, str, str]] = [
    # imports in all spellings
    ("import", "import os\nos.system('touch CANARY')", REFUSED),
    ("import-as", "import os.path as p\nsay(p.exists('/'))", REFUSED),
    ("from-import", "from os import system\nsystem('touch CANARY')", REFUSED),
    ("relative-import", "from . import sandbox", REFUSED),
    ("dunder-import", "__import__('os').system('touch CANARY')", REFUSED),
    ("builtins-subscript", "__builtins__['__import__']('os')", REFUSED),
    ("builtins-attr", "__builtins__.__import__('os')", REFUSED),
    ("importlib", "importlib.import_module('os').system('touch CANARY')", REFUSED),
    ("builtins-module", "builtins.__import__('os')", REFUSED),
    ("lambda-import", "(lambda: __import__('subprocess'))().run(['touch', 'CANARY'])", REFUSED),
    ("exec", "exec('import os')", REFUSED),
    ("eval", "eval(\"__import__('os')\")", REFUSED),
    ("compile", "compile('import os', 'x', 'exec')", REFUSED),
    ("globals", "say(globals()['__builtins__'])", REFUSED),
    ("locals", "say(locals())", REFUSED),
    ("vars", "say(vars(say))", REFUSED),
    ("getattr", "say(getattr(say, '__glo' + 'bals__'))", REFUSED),
    # dunder and attribute-chain escapes
    ("subclasses", "().__class__.__bases__[0].__subclasses__()", REFUSED),
    ("mro", "''.__class__.__mro__[1].__subclasses__()", REFUSED),
    ("mro-method", "str.mro()", REFUSED),
    ("func-globals", "say(say.__globals__['RobotAPI'])", REFUSED),
    ("bound-self", "say(get_obj_pos.__self__.state)", REFUSED),
    (
        "catch-warnings",
        "[c for c in ().__class__.__base__.__subclasses__() if c.__name__ == 'catch_warnings'][0]()"
        "._module.__builtins__['__import__']('os')",
        REFUSED,
    ),
    ("type", "say(type(say))", REFUSED),
    ("object", "say(object.__subclasses__())", REFUSED),
    ("numpy-dict", "say(np.__dict__)", REFUSED),
    ("numpy-ctypeslib", "np.ctypeslib.load_library('libc', '/lib')", REFUSED),
    ("numpy-load", "say(np.load('/etc/passwd'))", REFUSED),
    ("numpy-tofile", "np.array([1.0]).tofile('CANARY')", REFUSED),
    ("numpy-lib", "np.lib.npyio.savetxt('CANARY', [1])", REFUSED),
    ("numpy-ctypes", "say(np.zeros(3).ctypes.data)", REFUSED),
    ("walrus-dunder", "(f := __import__)", REFUSED),
    ("kwarg-dunder", "dict(__builtins__=1)", REFUSED),
    ("param-dunder", "def f(__x):\n    return __x\nf(1)", REFUSED),
    ("except-dunder", "try:\n    1 / 0\nexcept Exception as __e:\n    pass", REFUSED),
    # format-string attribute access
    ("str-format", "say('{0.__class__.__bases__}'.format(1))", REFUSED),
    ("str-format-globals", "say('{0.__globals__}'.format(say))", REFUSED),
    ("str-format-unbound", "say(str.format('{0.__class__}', 1))", REFUSED),
    ("format-map", "say('{a.__class__}'.format_map({'a': 1}))", REFUSED),
    ("fstring-dunder", "say(f'{say.__globals__}')", REFUSED),
    # generator / frame / traceback tricks
    ("gi-frame", "g = (x for x in [1])\nsay(g.gi_frame.f_back.f_globals)", REFUSED),
    ("yield", "def f():\n    yield 1\ng = f()\nsay(g.gi_code)", REFUSED),
    ("tb-frame", "try:\n    1 / 0\nexcept Exception as e:\n    say(e.__traceback__.tb_frame.f_globals)", REFUSED),
    ("with-traceback", "try:\n    1 / 0\nexcept Exception as e:\n    say(e.with_traceback(None))", REFUSED),
    ("class", "class A:\n    pass", REFUSED),
    ("async", "async def f():\n    pass", REFUSED),
    ("global", "def f():\n    global x\n    x = 1\nf()", REFUSED),
    ("nonlocal", "def f():\n    x = 1\n    def g():\n        nonlocal x\n    g()\nf()", REFUSED),
    # environment, files, sockets
    ("environ", "import os\nsay(os.environ['SECRET_NAME'])", REFUSED),
    ("proc-environ", "say(open('/proc/self/environ').read())", REFUSED),
    ("read-passwd", "say(open('/etc/passwd').read())", REFUSED),
    ("write-file", "open('CANARY', 'w').write('pwned')", REFUSED),
    ("with-open", "with open('CANARY', 'w') as f:\n    f.write('x')", REFUSED),
    ("socket", "import socket\nsocket.create_connection(('127.0.0.1', PORT))", REFUSED),
    ("socket-dunder", "__import__('socket').socket().connect(('127.0.0.1', PORT))", REFUSED),
    # interpreter tricks
    ("breakpoint", "breakpoint()", REFUSED),
    ("input", "say(input())", REFUSED),
    ("help", "help()", REFUSED),
    ("memoryview", "memoryview(b'abc')", REFUSED),
    ("super", "super()", REFUSED),
    ("exit", "exit()", REFUSED),
    ("fork-bomb", "import os\nwhile True:\n    os.fork()", REFUSED),
    ("signal", "import signal\nsignal.signal(signal.SIGXCPU, signal.SIG_IGN)\nwhile True:\n    pass", REFUSED),
    ("sleep", "import time\ntime.sleep(10 ** 6)", REFUSED),
    ("nested-parens", "x = " + "(" * 5000 + "1" + ")" * 5000, REFUSED),
    ("deep-unary", "x = " + "-" * 200000 + "1", REFUSED),
    ("huge-program", "x = 1\n" * 20000, REFUSED),
    ("null-byte", "say('a')\x00", REFUSED),
    # resource exhaustion: contained by the limits
    ("infinite-loop", "while True:\n    pass", CONTAINED),
    ("busy-sum", "say(sum(range(10 ** 12)))", CONTAINED),
    ("list-bomb", "x = [0] * 10 ** 10", CONTAINED),
    ("string-bomb", "s = 'a' * 10 ** 11", CONTAINED),
    ("doubling", "l = [1]\nwhile True:\n    l = l + l", CONTAINED),
    ("numpy-bomb", "a = np.zeros((10 ** 6, 10 ** 6))", CONTAINED),
    ("recursion", "def f(n):\n    return f(n + 1)\nf(0)", CONTAINED),
    ("huge-say", "say('x' * 10 ** 9)", CONTAINED),
    ("say-flood", "for i in range(10 ** 6):\n    say('x' * 1000)", CONTAINED),
    ("unknown-object", "put_first_on_second('red block', 'purple bowl')", CONTAINED),
    ("bad-target", "put_first_on_second('red block', {'a': 1})", CONTAINED),
    ("name-error", "say(RobotAPI)", CONTAINED),
    ("too-many-moves", "while True:\n    put_first_on_second('red block', 'blue bowl')", CONTAINED),
]


def test_corpus_is_large_enough():
    assert len(HOSTILE) >= 40
    assert len({name for name, _, _ in HOSTILE}) == len(HOSTILE)


@pytest.mark.parametrize(("name", "program", "expect"), HOSTILE, ids=[h[0] for h in HOSTILE])
def test_hostile_program(name, program, expect, sandbox, listener, state, tmp_path):
    canary = tmp_path / "canary"
    program = (
        program.replace("CANARY", str(canary))
        .replace("PORT", str(listener.getsockname()[1]))
        .replace("SECRET_NAME", SECRET_NAME)
    )
    env_before, pid_before = dict(os.environ), os.getpid()
    executor = CapExecutor(ScriptedModel([program]), sandbox=sandbox)
    result = executor.to_plan("do something tricky for the hostile test", state)

    assert result.failure is not None and result.failure.stage == "program", result
    kind = result.failure.details["kind"]
    if expect == REFUSED:
        assert kind == "refused", result.failure.message
    else:
        assert kind in CONTAINED_KINDS, result.failure.message
    assert result.failure.message.strip()
    assert SECRET_VALUE not in result.model_dump_json()
    assert not canary.exists() and list(tmp_path.iterdir()) == []
    assert_no_connection(listener)
    assert os.getpid() == pid_before and dict(os.environ) == env_before
    # The sandbox still works after every hostile program.
    after = sandbox.run("put_first_on_second('red block', 'blue bowl')", state)
    assert after.ok and len(after.skills) == 1


# Without the allow-list (all builtins, imports allowed), the OS layer still contains them.
UNGUARDED: list[tuple[str, str]] = [
    ("env-secret", "import os\nsay(os.environ.get('SECRET_NAME', 'none'))\nsay(len(os.environ))"),
    ("read-passwd", "say(open('/etc/passwd').read())"),
    ("parent-environ", "import os\nsay(open(f'/proc/{os.getppid()}/environ').read())"),
    ("write-file", "open('CANARY', 'w').write('pwned')"),
    ("socket", "import socket\ns = socket.create_connection(('127.0.0.1', PORT))"),
    ("fork", "import os\nos.fork()"),
    ("subprocess", "import subprocess\nsubprocess.run(['touch', 'CANARY'])"),
    # ctypes is loaded already (numpy uses it) and needs no file; system() cannot fork.
    ("ctypes", "import ctypes\nstatus = ctypes.CDLL(None).system(b'touch CANARY')\nassert status == 0, status"),
]


@pytest.mark.parametrize(("name", "program"), UNGUARDED, ids=[u[0] for u in UNGUARDED])
def test_os_layer_contains_unguarded_programs(name, program, unguarded_sandbox, listener, state, tmp_path):
    canary = tmp_path / "canary"
    program = (
        program.replace("CANARY", str(canary))
        .replace("PORT", str(listener.getsockname()[1]))
        .replace("SECRET_NAME", SECRET_NAME)
    )
    result = unguarded_sandbox.run(program, state)
    dump = result.model_dump_json()
    assert SECRET_VALUE not in dump and "root:" not in dump
    assert not canary.exists()
    assert_no_connection(listener)
    if name == "env-secret":  # the worker's environment is empty except thread settings
        assert result.ok and result.said[0] == "none" and int(result.said[1]) <= 4
    else:
        assert not result.ok, result


@pytest.mark.skipif(os.geteuid() != 0, reason="the empty chroot is only set up when running as root")
def test_os_layer_hides_the_filesystem(unguarded_sandbox, state, tmp_path):
    target = tmp_path / "made-by-sandbox"
    result = unguarded_sandbox.run(f"import os\nos.mkdir({str(target)!r})\nsay(os.listdir('/'))", state)
    assert not result.ok and not Path(target).exists()
