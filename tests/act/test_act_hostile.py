"""The hostile corpus (hostile_corpus.py): each program refused by the allow-list or contained
— with the guard, without it (the OS layer alone), and for the programs that go for the OS,
with only the namespaces and with only seccomp. Nothing may leak out in any of these runs, no
run may hold the sandbox longer than its deadline, and no program is ever sent twice."""

from __future__ import annotations

import contextlib
import os
import stat
from collections import Counter
from pathlib import Path

import pytest
from act_helpers import (
    SECRET_NAME,
    SECRET_VALUE,
    TEST_LIMITS,
    assert_clean_text,
    assert_no_connection,
    assert_no_datagram,
    process_state,
)
from hostile_corpus import CONTAINED, CORPUS, HARMLESS, REFUSED, SYSCALL_ALLOWED

from activeintent.act.cap import CapExecutor
from activeintent.act.sandbox import ACK_TIMEOUT_S, REPLY_GRACE_S, SandboxResult
from activeintent.llm.scripted import ScriptedModel

CONTAINED_KINDS = {"cpu", "wall", "memory", "runtime", "output", "crash"}
ALL_KINDS = CONTAINED_KINDS | {"refused", "sandbox", None}
IDS = [h.name for h in CORPUS]
OS_PROGRAMS = [h for h in CORPUS if "os" in h.tags]
VICTIM_TEXT = "precious"
# The longest a run may take once the worker is up: taking the request, the wall-time limit and
# the parent's grace for the reply (a stopped worker used to hold the sandbox for 15 s).
MAX_RUN_S = ACK_TIMEOUT_S + TEST_LIMITS.wall_seconds + REPLY_GRACE_S + 1.0


def _xattrs(path: Path) -> list[str]:
    with contextlib.suppress(OSError):
        return sorted(os.listxattr(path))
    return []


def test_corpus_size_and_outcomes():
    assert len(CORPUS) >= 80
    assert len(set(IDS)) == len(IDS)
    counts = Counter(h.guarded for h in CORPUS)
    assert set(counts) <= {REFUSED, CONTAINED, HARMLESS}
    assert counts[REFUSED] and counts[CONTAINED] and counts[HARMLESS]
    assert len(OS_PROGRAMS) >= 30


def _env() -> dict[str, str]:
    return {k: v for k, v in os.environ.items() if k != "PYTEST_CURRENT_TEST"}


class Scene:
    """The test's side of one run: the paths, processes and listeners a program goes for."""

    def __init__(self, tmp_path: Path, listener, udp_listener, victim) -> None:
        self.tmp = tmp_path
        self.canary = tmp_path / "canary"
        self.open_dir = tmp_path / "open"
        self.open_dir.mkdir()
        self.open_dir.chmod(0o777)
        self.victim_file = tmp_path / "victim.txt"
        self.victim_file.write_text(VICTIM_TEXT)
        self.victim_file.chmod(0o666)
        self.victim_stat = self.victim_file.stat()
        self.victim_xattrs = _xattrs(self.victim_file)
        self.listener, self.udp_listener, self.victim = listener, udp_listener, victim
        self.env_before, self.pid_before = _env(), os.getpid()

    def fill(self, program: str) -> str:
        for key, value in (
            ("OPEN_DIR", self.open_dir), ("VICTIM_FILE", self.victim_file), ("VICTIM_PID", self.victim.pid),
            ("PARENT_PID", os.getpid()), ("UDP_PORT", self.udp_listener.getsockname()[1]),
            ("PORT", self.listener.getsockname()[1]), ("SECRET_NAME", SECRET_NAME), ("CANARY", self.canary),
        ):
            program = program.replace(key, str(value))
        return program

    def assert_untouched(self, result: SandboxResult) -> None:
        dump = result.model_dump_json()
        assert SECRET_VALUE not in dump, "the parent's secret came back"
        assert "root:x:0:0" not in dump, "/etc/passwd came back"
        assert not self.canary.exists(), "a file was written outside the jail"
        assert sorted(p.name for p in self.tmp.iterdir()) == ["open", "victim.txt"]
        assert list(self.open_dir.iterdir()) == [], "something was created in a world-writable folder"
        now = self.victim_file.stat()
        assert self.victim_file.read_text() == VICTIM_TEXT
        assert stat.S_IMODE(now.st_mode) == 0o666 and now.st_mtime_ns == self.victim_stat.st_mtime_ns
        assert _xattrs(self.victim_file) == self.victim_xattrs, "an extended attribute was set or removed"
        assert_no_connection(self.listener)
        assert_no_datagram(self.udp_listener)
        assert os.getpid() == self.pid_before and _env() == self.env_before
        assert self.victim.poll() is None, "the victim process was killed"
        assert process_state(self.victim.pid) not in ("T", "t"), "the victim process was stopped or traced"
        # Whatever comes back is clean, bounded text.
        assert result.error_kind in ALL_KINDS
        assert len(result.said) <= 100 and sum(len(s) for s in result.said) <= 4000
        for text in result.said:
            assert_clean_text(text)
        assert_clean_text(result.error, limit=600)
        for failure in result.skill_failures:
            assert_clean_text(failure)


@pytest.fixture
def scene(tmp_path, listener, udp_listener, victim) -> Scene:
    return Scene(tmp_path, listener, udp_listener, victim)


def _still_works(sandbox, state) -> None:
    after = sandbox.run("put_first_on_second('red block', 'blue bowl')", state)
    assert after.ok and len(after.skills) == 1, after


@pytest.mark.parametrize("hostile", CORPUS, ids=IDS)
def test_guarded(hostile, sandbox, state, scene):
    """With the guard, as `--executor cap` runs programs: each has its expected outcome, and
    every failure reaches the learner as a 'program' ExecutionFailure."""
    executor = CapExecutor(ScriptedModel([scene.fill(hostile.program)]), sandbox=sandbox)
    plan = executor.to_plan("do something tricky for the hostile test", state)
    result = sandbox.run(scene.fill(hostile.program), state) if hostile.guarded == HARMLESS else None
    if hostile.guarded != HARMLESS:
        assert plan.failure is not None and plan.failure.stage == "program", plan
        assert plan.failure.message.strip()
        kind = plan.failure.details["kind"]
        if hostile.guarded == REFUSED:
            assert kind == "refused", plan.failure.message
        else:
            assert kind in CONTAINED_KINDS, plan.failure.message
        result = SandboxResult(said=plan.said, error=plan.failure.message, error_kind=kind)
    assert SECRET_VALUE not in plan.model_dump_json()
    scene.assert_untouched(result)
    _still_works(sandbox, state)


def _run(sandbox, hostile, state, scene, seccomp: bool) -> SandboxResult:
    """One run, checked for what every mode must guarantee: sent to a worker once, within the
    deadline, and (with seccomp) no probed system call got past the filter."""
    sends = []
    real = sandbox._ensure_started
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(sandbox, "_ensure_started", lambda: (sends.append(1), real())[1])
        result = sandbox.run(scene.fill(hostile.program), state)
    scene.assert_untouched(result)
    assert len(sends) == 1, f"the program was sent {len(sends)} times: {result.error}"
    assert result.elapsed_s <= MAX_RUN_S, f"the run held the sandbox {result.elapsed_s:.1f} s: {result.error}"
    if seccomp and "seccomp" in hostile.tags:
        assert SYSCALL_ALLOWED not in result.said, result.said
    return result


@pytest.mark.parametrize("hostile", CORPUS, ids=IDS)
def test_unguarded(hostile, unguarded_sandbox, state, scene):
    """Without the guard (all builtins, imports allowed): the OS layer contains every program."""
    _run(unguarded_sandbox, hostile, state, scene, seccomp=True)
    _still_works(unguarded_sandbox, state)


@pytest.mark.parametrize("hostile", OS_PROGRAMS, ids=[h.name for h in OS_PROGRAMS])
def test_namespaces_alone(hostile, namespaces_only_sandbox, state, scene):
    """No guard, no seccomp: the namespaces (and limits) alone contain what goes for the OS."""
    _run(namespaces_only_sandbox, hostile, state, scene, seccomp=False)
    _still_works(namespaces_only_sandbox, state)


@pytest.mark.parametrize("hostile", OS_PROGRAMS, ids=[h.name for h in OS_PROGRAMS])
def test_seccomp_alone(hostile, seccomp_only_sandbox, state, scene):
    """No guard, no namespaces (--unsafe-no-isolation): seccomp and limits alone contain it."""
    _run(seccomp_only_sandbox, hostile, state, scene, seccomp=True)
    _still_works(seccomp_only_sandbox, state)
