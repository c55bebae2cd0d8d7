"""Run the sandbox tests (tests/act) as an unprivileged user; CI runs them as root first.

Usage, as root: ``.venv/bin/python tests/act/run_unprivileged.py [pytest arguments]``.

The user (``activeintent-test``, created with ``useradd`` when missing; ``nobody`` if that
fails) must read the repository, the virtualenv and the Python installation it points to. When
one of these sits below a folder that user may not enter (pyenv's Python under /root, say),
the tests run in a private mount namespace in which that folder is covered by a tmpfs holding
only the needed entries, bind-mounted from the real ones. Nothing on the machine changes:
permissions stay as they are and the mounts vanish with the run.
"""

from __future__ import annotations

import os
import shutil
import stat
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
USER = os.environ.get("ACTIVEINTENT_TEST_USER", "activeintent-test")
INNER = "--inside-private-mounts"
# PYTHONPATH: a work tree tested with another checkout's virtualenv points it at its own src.
KEPT_ENV = ("CI", "OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE", "LANG", "TERM", "PYTHONPATH")


def _ids(user: str) -> tuple[int, int] | None:
    try:
        out = subprocess.run(["id", "-u", user], capture_output=True, text=True, check=True).stdout
        group = subprocess.run(["id", "-g", user], capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    return int(out), int(group)


def choose_user() -> tuple[str, int, int]:
    ids = _ids(USER)
    if ids is None:
        subprocess.run(["useradd", "--system", "--no-create-home", "--home-dir", "/nonexistent",
                        "--shell", "/usr/sbin/nologin", USER], capture_output=True)
        ids = _ids(USER)
    if ids is None:
        return "nobody", 65534, 65534
    return USER, ids[0], ids[1]



def _may_enter(path: Path, uid: int, gid: int) -> bool:
    st = path.stat()
    mode = stat.S_IMODE(st.st_mode)
    if st.st_uid == uid:
        return bool(mode & stat.S_IXUSR)
    if st.st_gid == gid:
        return bool(mode & stat.S_IXGRP)
    return bool(mode & stat.S_IXOTH)


def _needed() -> list[Path]:
    python = Path(sys.executable)
    return sorted({ROOT, Path(sys.prefix), Path(os.path.realpath(sys.base_prefix)),
                   Path(os.path.realpath(python)).parent})


def _first_closed(path: Path, uid: int, gid: int) -> Path | None:
    """The shallowest folder on the way to ``path`` (itself included) the user cannot enter."""
    for folder in [*reversed(path.parents), path]:
        if not _may_enter(folder, uid, gid):
            return folder
    return None


def _mount(*args: str) -> None:
    subprocess.run(["mount", *args], check=True)


def open_paths(uid: int, gid: int) -> None:
    """Cover every closed folder on the way to the needed paths with a tmpfs that holds only
    the entries on those ways (bind mounts of the real ones); repeat for deeper closed folders."""
    hold = Path(tempfile.mkdtemp(prefix="activeintent-hold-"))
    for _round in range(32):
        closed: dict[Path, set[str]] = {}
        for path in _needed():
            folder = _first_closed(path, uid, gid)
            if folder is None:
                continue
            if folder == path:
                raise SystemExit(f"{path} itself is closed to uid {uid}; cannot run the tests as that user")
            closed.setdefault(folder, set()).add(path.relative_to(folder).parts[0])
        if not closed:
            return
        for folder, names in closed.items():
            for name in names:
                (hold / name).mkdir(exist_ok=True)
                _mount("--bind", str(folder / name), str(hold / name))
            _mount("-t", "tmpfs", "-o", "mode=0755", "activeintent-open", str(folder))
            for name in names:
                (folder / name).mkdir()
                _mount("--move", str(hold / name), str(folder / name))
    raise SystemExit("too many closed folders")


def main() -> None:
    args = sys.argv[1:]
    if os.geteuid() != 0:  # already unprivileged: just run the tests
        os.execv(sys.executable, [sys.executable, "-m", "pytest", str(ROOT / "tests" / "act"), "-p",
                                  "no:cacheprovider", *args])
    user, uid, gid = choose_user()
    if not args or args[0] != INNER:
        unshare = shutil.which("unshare") or "/usr/bin/unshare"
        os.execv(unshare, [unshare, "--mount", "--propagation", "private", "--", sys.executable,
                           os.path.abspath(__file__), INNER, *args])
    args = args[1:]
    open_paths(uid, gid)
    home = Path(tempfile.mkdtemp(prefix="activeintent-test-home-"))
    os.chown(home, uid, gid)
    env = {"HOME": str(home), "PATH": "/usr/local/bin:/usr/bin:/bin", "PYTHONDONTWRITEBYTECODE": "1"}
    env.update({k: os.environ[k] for k in KEPT_ENV if k in os.environ})
    print(f"activeintent: sandbox tests as {user} (uid {uid})", flush=True)
    os.chdir(ROOT)
    setpriv = shutil.which("setpriv") or "/usr/bin/setpriv"
    command = [setpriv, f"--reuid={uid}", f"--regid={gid}", "--clear-groups", "--inh-caps=-all", "--",
               sys.executable, "-m", "pytest", "tests/act", "-p", "no:cacheprovider", *args]
    sys.stdout.flush()
    code = subprocess.run(command, env=env).returncode
    shutil.rmtree(home, ignore_errors=True)
    sys.exit(code)


if __name__ == "__main__":
    main()
