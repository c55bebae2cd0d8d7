"""Operating-system isolation of the sandbox worker: Linux namespaces through bubblewrap.

The worker that runs model-written programs is started inside ``bwrap`` (Debian package
``bubblewrap``) with fresh user, mount, PID, network, IPC, UTS and (where possible) cgroup
namespaces. Inside, it is uid/gid 65534 without capabilities, sees an empty read-only file
system holding only the Python installation, the virtualenv and this package (all read-only),
a private ``/proc`` that lists only the sandbox's own processes, a minimal ``/dev``, a network
with nothing but its own loopback, and an environment built from scratch. It dies with its
parent. See ``docs/security.md`` for the whole threat model.

When bubblewrap is missing or cannot create namespaces (for instance in a container that
forbids user namespaces), :func:`isolation_status` says so and why; the sandbox then refuses to
run generated code unless the user explicitly accepted running without isolation
(``--unsafe-no-isolation`` or ``ACTIVEINTENT_UNSAFE_NO_ISOLATION=1``).
"""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import sys
import sysconfig
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from activeintent.memo import memoized

UNSAFE_ENV = "ACTIVEINTENT_UNSAFE_NO_ISOLATION"
SANDBOX_UID = 65534  # "nobody" inside the user namespace
# Non-secret settings the worker needs; nothing else of the parent's environment is passed on.
WORKER_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "LC_ALL": "C.UTF-8"}
PASSED_THROUGH = ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE")  # CPU quirks of old OpenBLAS builds
# Top-level system folders that merged-/usr systems keep as symlinks into /usr.
_SYSTEM_LINKS = ("/bin", "/sbin", "/lib", "/lib32", "/lib64", "/libx32")

Mode = Literal["bwrap", "none"]

_unsafe_allowed = False


def allow_unsafe_no_isolation(allowed: bool = True) -> None:
    """The user's explicit consent (``--unsafe-no-isolation``) to run generated code without
    namespaces. Also exported to the environment so that worker processes inherit it."""
    global _unsafe_allowed
    _unsafe_allowed = allowed
    if allowed:
        os.environ[UNSAFE_ENV] = "1"
    else:
        os.environ.pop(UNSAFE_ENV, None)


def unsafe_allowed() -> bool:
    return _unsafe_allowed or os.environ.get(UNSAFE_ENV, "").strip().lower() in ("1", "true", "yes", "on")


@dataclass(frozen=True)
class IsolationStatus:
    mode: Mode
    detail: str  # what is used, or why nothing is

    @property
    def available(self) -> bool:
        return self.mode != "none"


def worker_env() -> dict[str, str]:
    env = dict(WORKER_ENV)
    env.update({k: os.environ[k] for k in PASSED_THROUGH if os.environ.get(k)})
    return env


def bwrap_executable() -> str | None:
    return shutil.which("bwrap") or next((p for p in ("/usr/bin/bwrap", "/bin/bwrap") if os.access(p, os.X_OK)), None)


def readonly_paths(package_root: str) -> list[str]:
    """What the worker must read: the interpreter's prefixes, its library folders and this
    package. Folders inside another listed folder are dropped."""
    candidates = {sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix, package_root,
                  os.path.dirname(os.path.realpath(sys.executable))}
    for key in ("stdlib", "platstdlib", "purelib", "platlib"):
        path = sysconfig.get_paths().get(key)
        if path:
            candidates.add(path)
    paths: set[str] = set()
    for p in candidates:
        if p and os.path.exists(p):
            paths.add(os.path.abspath(p))
            paths.add(os.path.realpath(p))
    paths.discard("/")
    ordered = sorted(paths, key=lambda p: (p.count("/"), p))
    kept: list[str] = []
    for p in ordered:
        if not any(p == k or p.startswith(k.rstrip("/") + "/") for k in kept):
            kept.append(p)
    return kept


def _root_tools() -> tuple[str, str, str] | None:
    tools = tuple(shutil.which(t, path="/usr/bin:/bin:/usr/sbin:/sbin") for t in ("unshare", "mount", "setpriv"))
    return tools if all(tools) else None  # type: ignore[return-value]


def _stage_dir(paths: list[str]) -> str | None:
    """An existing folder to cover with the staging tmpfs: one that holds none of ``paths``."""
    for candidate in ("/mnt", "/media", "/srv", "/opt", "/tmp", "/var/tmp", "/run"):
        if os.path.isdir(candidate) and not os.path.islink(candidate) and not any(
            p == candidate or p.startswith(candidate + "/") for p in paths
        ):
            return candidate
    return None


def bwrap_command(bwrap: str, argv: list[str], package_root: str, drop_root: bool = False) -> list[str]:
    """The command line that runs ``argv`` isolated (see the module docstring).

    Run by root, bubblewrap would map the sandbox's uid to root outside the namespaces (without
    capabilities, but still uid 0 to the kernel's checks and exempt from RLIMIT_NPROC). With
    ``drop_root`` it is started as ``nobody`` instead: a private mount namespace first exposes
    the folders the worker needs under a fresh tmpfs (they may sit below folders that nobody
    cannot enter, like /root), then ``setpriv`` drops to 65534 and runs bubblewrap from there.
    """
    paths = [p for p in readonly_paths(package_root) if not (p == "/usr" or p.startswith("/usr/"))]
    sources = {p: p for p in paths}
    tools = _root_tools() if drop_root else None
    stage = _stage_dir(paths) if tools is not None else None
    if stage is not None:
        sources = {p: f"{stage}/{i}" for i, p in enumerate(paths)}
    cmd = [
        bwrap,
        "--unshare-user", "--unshare-pid", "--unshare-net", "--unshare-ipc", "--unshare-uts",
        "--unshare-cgroup-try", "--disable-userns",
        "--uid", str(SANDBOX_UID), "--gid", str(SANDBOX_UID), "--hostname", "sandbox",
        "--die-with-parent", "--new-session", "--clearenv", "--cap-drop", "ALL",
    ]
    for name, value in worker_env().items():
        cmd += ["--setenv", name, value]
    cmd += ["--ro-bind", "/usr", "/usr"]
    for top in _SYSTEM_LINKS:
        if os.path.islink(top):
            cmd += ["--symlink", os.readlink(top), top]
        elif os.path.isdir(top):
            cmd += ["--ro-bind", top, top]
    for path in paths:
        cmd += ["--ro-bind", sources[path], path]
    cmd += ["--proc", "/proc", "--dev", "/dev", "--remount-ro", "/dev", "--chdir", "/", "--remount-ro", "/"]
    cmd += list(argv)
    if tools is None or stage is None:
        return cmd
    unshare, mount, setpriv = tools
    q = shlex.quote
    script = [f"set -e; {q(mount)} -t tmpfs -o mode=0755,size=64k activeintent-stage {q(stage)}"]
    for path in paths:
        script.append(f"mkdir {q(sources[path])}; {q(mount)} --bind {q(path)} {q(sources[path])}")
    script.append(
        f"exec {q(setpriv)} --reuid={SANDBOX_UID} --regid={SANDBOX_UID} --clear-groups --inh-caps=-all "
        f"--bounding-set=-all -- " + " ".join(q(c) for c in cmd)
    )
    return [unshare, "--mount", "--propagation", "private", "--", "/bin/sh", "-c", "; ".join(script)]


def _try(cmd: list[str]) -> str | None:
    try:
        done = subprocess.run(cmd, stdin=subprocess.DEVNULL, capture_output=True, timeout=60, env={})
    except (OSError, subprocess.SubprocessError) as e:
        return f"{type(e).__name__}: {e}"
    if done.returncode != 0:
        return (done.stderr.decode("utf-8", "replace").strip() or f"exit code {done.returncode}")[-300:]
    return None


@memoized(size=4, why="(bwrap, package root, python, root): wrong only if the sandbox tools change while the process runs")
def _probe(bwrap: str, package_root: str, python: str, root: bool) -> tuple[bool, str | None, str | None]:
    """(drop_root, problem, note): whether bwrap can start this interpreter isolated."""
    check = [python, "-I", "-S", "-c", "import os; assert os.getuid() == 65534"]
    note = None
    if root:
        if _root_tools() is None:
            note = "unshare, mount or setpriv missing"
        elif _stage_dir(readonly_paths(package_root)) is None:
            note = "no folder to stage the read-only paths in"
        elif (problem := _try(bwrap_command(bwrap, check, package_root, drop_root=True))) is None:
            return True, None, None
        else:
            note = problem
    return False, _try(bwrap_command(bwrap, check, package_root)), note


def root_drop(package_root: str) -> bool:
    """Whether the sandbox, started by root, runs bubblewrap as nobody (see bwrap_command)."""
    bwrap = bwrap_executable()
    if bwrap is None or os.geteuid() != 0:
        return False
    return _probe(bwrap, package_root, sys.executable, True)[0]


def isolation_status(package_root: str | None = None) -> IsolationStatus:
    """Whether the worker can run in namespaces here (probed once per process)."""
    root = package_root or str(Path(__file__).resolve().parents[2])
    if not sys.platform.startswith("linux"):
        return IsolationStatus("none", f"namespaces need Linux (this is {sys.platform})")
    bwrap = bwrap_executable()
    if bwrap is None:
        return IsolationStatus("none", "bubblewrap (bwrap) is not installed; on Debian: apt-get install bubblewrap")
    drop, problem, note = _probe(bwrap, root, sys.executable, os.geteuid() == 0)
    if problem is not None:
        return IsolationStatus("none", f"bubblewrap cannot create the sandbox's namespaces here: {problem}")
    detail = f"bubblewrap ({bwrap}): user, mount, PID, network, IPC and UTS namespaces"
    if os.geteuid() == 0:
        detail += ", started as nobody" if drop else f", run as root without the drop to nobody ({note})"
    return IsolationStatus("bwrap", detail)


def refusal_message(status: IsolationStatus) -> str:
    return (
        f"refused to run generated code: no isolation is available ({status.detail}). "
        "Install bubblewrap, or pass --unsafe-no-isolation (environment "
        f"{UNSAFE_ENV}=1) to run it with only the allow-list, seccomp and resource limits."
    )


class SandboxUnavailable(ValueError):
    """Generated code may not run here: no isolation, and the user did not accept running
    without it. The message says why and what to do."""


def require_isolation() -> IsolationStatus:
    """Raise :class:`SandboxUnavailable` unless programs can run isolated (or the user
    accepted running them without isolation)."""
    status = isolation_status()
    if not status.available and not unsafe_allowed():
        raise SandboxUnavailable(refusal_message(status))
    return status
