"""What the web modules share (the session and the study file both read these): the modes of
showing the learner's guess, the videos' size, and the atomic JSON writer of session files."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Literal

from activeintent.records import dumps

EstimateMode = Literal["hidden", "after-answer", "always"]
ESTIMATE_MODES: tuple[str, ...] = ("hidden", "after-answer", "always")

# With the renderer's camera every block is at least 40 px wide at this size (tests/sim/test_camera.py).
VIDEO_SIZE: tuple[int, int] = (800, 600)
VIDEO_SIZE_TEXT = f"{VIDEO_SIZE[0]}x{VIDEO_SIZE[1]}"


def parse_video_size(text: str) -> tuple[int, int]:
    """``"800x600"`` (width x height) or ``"480"`` (a square) in pixels, each 64-2048."""
    parts = str(text).lower().replace("×", "x").split("x")
    try:
        w, h = (int(parts[0]), int(parts[0])) if len(parts) == 1 else (int(parts[0]), int(parts[1]))
        if len(parts) > 2:
            raise ValueError
    except ValueError:
        raise ValueError(f"video size {text!r}: give WIDTHxHEIGHT in pixels (e.g. {VIDEO_SIZE_TEXT}) or one "
                         "number for a square") from None
    if not (64 <= w <= 2048 and 64 <= h <= 2048):
        raise ValueError(f"video size {text!r}: each side must be 64-2048 pixels")
    return w, h


def write_json(path: Path, value: Any) -> None:
    """Write strict JSON atomically (a reader never sees half a file)."""
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(json.dumps(json.loads(dumps(value)), indent=2))
    os.replace(tmp, path)
