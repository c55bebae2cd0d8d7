"""Every `bin/activeintent` command quoted in README.md and docs/*.md parses and validates as a
newcomer would type it (ACTIVEINTENT_CHECK_ONLY=1: options and inputs are checked, the work is
skipped). Commands that need a remote model server (openai:, --base-url) are left out."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
NEEDS_SERVER = ("openai:", "--base-url", "OPENAI_")


def documented_commands() -> list[tuple[str, str]]:
    out = []
    for path in DOCS:
        for block in re.findall(r"```(?:bash|sh|shell)\n(.*?)```", path.read_text(), flags=re.S):
            text = re.sub(r"\\\n\s*", " ", block)  # join continued lines
            for line in text.splitlines():
                line = line.split(" #", 1)[0].strip()
                if line.startswith("bin/activeintent ") and not any(k in line for k in NEEDS_SERVER):
                    out.append((path.name, line))
    return out


COMMANDS = documented_commands()


def test_the_docs_quote_commands():
    assert len(COMMANDS) >= 10
    assert ("README.md", "bin/activeintent run") in COMMANDS


@pytest.mark.parametrize("doc,command", COMMANDS, ids=[f"{d}:{c[:60]}" for d, c in COMMANDS])
def test_documented_command_validates(doc, command, tmp_path):
    args = shlex.split(command)[1:]
    env = {**os.environ, "ACTIVEINTENT_CHECK_ONLY": "1"}
    # A newcomer's checkout: the repository's folders, plus an (empty) study folder to export.
    for name in ("examples", "experiments", "data", "docs", "src"):
        (tmp_path / name).symlink_to(ROOT / name)
    (tmp_path / "runs" / "study").mkdir(parents=True)
    res = subprocess.run([sys.executable, "-m", "activeintent.cli", *args], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=240)
    assert res.returncode == 0, f"{doc}: {command}\n{res.stdout[-1500:]}\n{res.stderr[-1500:]}"
