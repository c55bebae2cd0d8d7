"""The worker's life around one program (audit findings S1 and S2): a worker that a program
stops or kills costs at most the run's deadline and is reported, never silently re-run; and
every program starts from a template whose memory holds no earlier program.

These run without guard and seccomp (the namespaces-only sandbox), where a program can still
signal its worker and read its own memory: what is checked is the worker's design, not the
filter that now also refuses the signals."""

from __future__ import annotations

import re
import textwrap
import threading
import time
import uuid
from pathlib import Path

import pytest
from act_helpers import TEST_LIMITS, descendants

from activeintent.act.sandbox import ACK_TIMEOUT_S, REPLY_GRACE_S

DEADLINE_S = TEST_LIMITS.wall_seconds + REPLY_GRACE_S
BENIGN = "put_first_on_second('red block', 'blue bowl')"
SIGIO = textwrap.dedent("""
    import ctypes, os, signal
    libc = ctypes.CDLL(None)
    libc.fcntl(3, 8, os.getppid())  # F_SETOWN: the runner
    libc.fcntl(3, 10, signal.{sig})  # F_SETSIG
    libc.fcntl(3, 4, os.O_ASYNC)
    os.write(3, b' ')  # the runner's read of this sends the signal...
    import time
    t = time.monotonic()
    while time.monotonic() - t < 1.0:  # ...while this end is still open
        pass
""")


def _counting_sends(sandbox, mp) -> list[int]:
    sends: list[int] = []
    real = sandbox._ensure_started
    mp.setattr(sandbox, "_ensure_started", lambda: (sends.append(1), real())[1])
    return sends


def test_a_stopped_worker_is_killed_at_the_deadline_and_frees_the_sandbox(namespaces_only_sandbox, state):
    sandbox = namespaces_only_sandbox
    assert sandbox.run(BENIGN, state).ok
    out: dict = {}

    def attack() -> None:
        out["attack"] = sandbox.run(SIGIO.format(sig="SIGSTOP"), state)
        out["attack_done"] = time.monotonic()

    thread = threading.Thread(target=attack)
    thread.start()
    time.sleep(0.3)  # the attack holds the sandbox; this program waits for it
    waiting = sandbox.run(BENIGN, state)
    done = time.monotonic()
    thread.join()
    attack = out["attack"]
    assert attack.error_kind == "sandbox" and "stopped or stuck" in attack.error, attack
    assert "not run again" in attack.error
    assert attack.elapsed_s <= DEADLINE_S + 1.0, f"a stopped worker held the sandbox {attack.elapsed_s:.1f} s"
    assert waiting.ok, waiting
    # The waiting program only paid for the new worker's start once the attack's run was over.
    assert done - out["attack_done"] <= (sandbox.startup_s or 0.0) + 2.0


@pytest.mark.parametrize("program", [
    "import os, signal\nos.kill(os.getppid(), signal.SIGKILL)",
    SIGIO.format(sig="SIGKILL"),
], ids=["kill", "sigio-kill"])
def test_a_program_that_kills_its_worker_is_reported_not_run_again(program, namespaces_only_sandbox, state):
    with pytest.MonkeyPatch.context() as mp:
        sends = _counting_sends(namespaces_only_sandbox, mp)
        result = namespaces_only_sandbox.run(program, state)
    assert sends == [1], "the program was sent to a second worker"
    assert result.error_kind == "sandbox" and "not run again" in result.error, result
    assert "SIGKILL" in result.error or "died" in result.error
    assert namespaces_only_sandbox.run(BENIGN, state).ok


def test_a_stopped_template_is_replaced_before_the_next_program(namespaces_only_sandbox, state):
    """The template (the runner's parent) stopped between programs: the next request is not
    taken, so the worker is replaced and the program sent once more — it had not run."""
    stop_template = textwrap.dedent("""
        import os, signal
        os.close(0)
        template = int(open(f'/proc/{os.getppid()}/stat').read().rsplit(')', 1)[1].split()[1])
        os.kill(template, signal.SIGSTOP)
    """)
    assert namespaces_only_sandbox.run(stop_template, state).ok
    started = time.monotonic()
    result = namespaces_only_sandbox.run(BENIGN, state)
    assert result.ok and len(result.skills) == 1, result
    assert time.monotonic() - started <= ACK_TIMEOUT_S + (namespaces_only_sandbox.startup_s or 0.0) + 2.0


# ---- S2: no earlier program in a later program's memory ---------------------------------------
def _marked_program(marker: str) -> str:
    return f"# {marker}\nnote = '{marker}'\nsay(note)\n{BENIGN}\n"


def _scan_program(marker: str) -> str:
    """Counts the marker in the writable memory of its own process (heap, arenas, data) without
    ever holding the whole marker: it looks for the first half followed by the second. A second
    marker, built at run time, shows the scan finds what is there."""
    half = len(marker) // 2
    control = uuid.uuid4().hex
    return textwrap.dedent(f"""
        import os
        os.close(0)
        os.close(1)
        def count(head, tail):
            hits = 0
            with open('/proc/self/maps') as f:
                maps = f.read().splitlines()
            with open('/proc/self/mem', 'rb', buffering=0) as mem:
                for line in maps:
                    span, perms = line.split()[:2]
                    if not perms.startswith('rw'):
                        continue
                    lo, hi = (int(x, 16) for x in span.split('-'))
                    for start in range(lo, hi, 1 << 22):
                        try:
                            mem.seek(start)
                            data = mem.read(min(hi, start + (1 << 22) + 64) - start)
                        except OSError:
                            break
                        i = data.find(head)
                        while i >= 0:
                            hits += data[i + len(head):i + len(head) + len(tail)] == tail
                            i = data.find(head, i + 1)
            return hits
        built = ''.join(['{control[:16]}', '{control[16:]}'])
        say([count(b'{marker[:half]}', b'{marker[half:]}'), count(b'{control[:16]}', b'{control[16:]}')])
    """)


def test_a_later_program_finds_no_earlier_program_in_its_memory(namespaces_only_sandbox, state):
    """The audit's S2: a program found 25 copies of an earlier one's source in its heap."""
    marker = f"MARK{uuid.uuid4().hex}"
    first = namespaces_only_sandbox.run(_marked_program(marker), state)
    assert first.ok and first.said == [marker]
    scan = namespaces_only_sandbox.run(_scan_program(marker), state)
    assert scan.ok, scan.error
    earlier, control = eval(scan.said[0])  # noqa: S307 - a list of two ints written by the test's own program
    assert control >= 1, "the scan does not find what is in memory"
    assert earlier == 0, f"{earlier} copies of the earlier program in the later one's memory"


def _comm(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/comm").read_text().strip()
    except OSError:
        return ""


def _ppid(pid: int) -> int:
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])
    except (OSError, IndexError, ValueError):
        return -1


def _state(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return "gone"


def _started(pid: int) -> int:
    """Start time of a process, in clock ticks since boot (-1 when it is gone)."""
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[19])
    except (OSError, IndexError, ValueError):
        return -1


def _after_program(sandbox, started_after: int = -1) -> tuple[int, list[int]]:
    """The template and its live runners started after tick ``started_after`` (host pids)."""
    deadline = time.monotonic() + 10.0
    template, fresh = -1, []
    while time.monotonic() < deadline:
        pythons = [pid for pid in descendants(sandbox.worker_pid) if _comm(pid).startswith("python")]
        templates = [p for p in pythons if _ppid(p) not in pythons]
        if len(templates) == 1:
            template = templates[0]
            fresh = [p for p in pythons if _ppid(p) == template and _state(p) not in ("Z", "gone")
                     and _started(p) > started_after]
            if fresh:
                return template, fresh
        time.sleep(0.05)  # the template forks the next runner once the last one has replied
    assert template > 0, "no template below the sandbox"
    return template, fresh


def _memory_holds(pid: int, needle: bytes) -> int:
    hits = 0
    spans = [line.split()[:2] for line in Path(f"/proc/{pid}/maps").read_text().splitlines()]
    with open(f"/proc/{pid}/mem", "rb", buffering=0) as mem:
        for span, perms in spans:
            if not perms.startswith("rw"):
                continue
            lo, hi = (int(x, 16) for x in span.split("-"))
            try:
                mem.seek(lo)
                hits += len(re.findall(re.escape(needle), mem.read(hi - lo)))
            except (OSError, OverflowError, ValueError):
                continue
    return hits


def test_the_template_holds_no_program(sandbox, state):
    """Read from outside (the test's own process): after a guarded program has run, no byte of
    it is in the memory of the template every later program is forked from, nor in the runner
    waiting for the next request."""
    assert sandbox.run(BENIGN, state).ok
    marker = f"MARK{uuid.uuid4().hex}"
    result = sandbox.run(_marked_program(marker), state)
    assert result.ok and result.said == [marker]
    # One runner at a time (the template waits for each): once another program has been taken,
    # the runner of the marked one has exited; every runner alive now was forked after it.
    assert sandbox.run(BENIGN, state).ok
    template, runners = _after_program(sandbox)
    assert runners, "no runner below the template"
    scanned = []
    for pid in [template, *runners]:
        try:
            hits = _memory_holds(pid, marker.encode())
            readable = _memory_holds(pid, b"activeintent.act.sandbox_worker")
        except PermissionError as e:
            pytest.skip(f"this user may not read the worker's memory: {e}")
        except (FileNotFoundError, ProcessLookupError):
            continue  # a runner that took the last program exited while being read: it holds nothing now
        assert hits == 0, f"{hits} copies of the program in the memory of {_comm(pid)} {pid}"
        assert readable > 0, "the scan reads nothing"
        scanned.append(pid)
    assert template in scanned
