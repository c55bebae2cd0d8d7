"""What the web modules share (the session and the study file both read these): the modes of
showing the learner's guess, and the atomic JSON writer of session files."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Literal

from activeintent.records import dumps

EstimateMode = Literal["hidden", "after-answer", "always"]
ESTIMATE_MODES: tuple[str, ...] = ("hidden", "after-answer", "always")


def write_json(path: Path, value: Any) -> None:
    """Write strict JSON atomically (a reader never sees half a file)."""
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(json.dumps(json.loads(dumps(value)), indent=2))
    os.replace(tmp, path)
