"""Videos that can be played while they are still being drawn.

A round's videos are written by a background thread each (frames from the shared render
processes, encoded to WebM in clusters of half a second); the round is shown as soon as every
video holds its first complete cluster, and the browser receives the file as it grows (a
chunked response that follows the file until the export has ended). Frames are drawn faster
than they play, so the participant waits for the learner, the physics and half a second of
frames instead of whole videos (docs/webapp.md, "How long participants wait").
"""

from __future__ import annotations

import asyncio
import threading
import time
from collections.abc import AsyncIterator
from pathlib import Path
from typing import Any

from activeintent.sim.video import export_video

CLUSTER_ID = b"\x1f\x43\xb6\x75"  # a Matroska/WebM Cluster element: frames the browser can play
POLL_S = 0.02
READ_BYTES = 1 << 16


class LiveExport:
    """One WebM video written in its own thread (``activeintent.sim.video.export_video``).

    ``done`` is set when the file is complete or the export failed (``error`` says why);
    :meth:`wait_playable` returns once the file holds frames a browser can start playing."""

    def __init__(self, traj: Any, path: Path, fps: int, size: tuple[int, int], workers: int):
        self.path = path
        self.done = threading.Event()
        self.error: str | None = None
        self._thread = threading.Thread(target=self._run, args=(traj, fps, size, workers),
                                        name=f"export-{path.stem}", daemon=True)
        self._thread.start()

    def _run(self, traj: Any, fps: int, size: tuple[int, int], workers: int) -> None:
        try:
            # the MP4 from the same frames; the file is complete when both are
            export_video(traj, self.path, fps=fps, size=size, workers=workers, also=(self.path.with_suffix(".mp4"),))
        except Exception as err:  # reported by wait_playable / finish, never lost in the thread
            self.error = f"{type(err).__name__}: {err}"
        finally:
            self.done.set()

    def _has_frames(self) -> bool:
        try:
            with self.path.open("rb") as f:
                return CLUSTER_ID in f.read()
        except OSError:
            return False

    def wait_playable(self, timeout: float = 300.0) -> None:
        """Block until the file holds its first cluster of frames (or is complete)."""
        deadline = time.monotonic() + timeout
        while not self.done.is_set() and not self._has_frames():
            if time.monotonic() > deadline:
                raise TimeoutError(f"{self.path.name}: no frames within {timeout:.0f} s")
            time.sleep(POLL_S)
        self._raise_if_failed()

    def finish(self, timeout: float | None = None) -> None:
        """Block until the file is complete; raise if the export failed."""
        self._thread.join(timeout)
        self._raise_if_failed()

    def _raise_if_failed(self) -> None:
        if self.error:
            raise RuntimeError(f"the video {self.path.name} could not be made: {self.error}")


async def follow(export: LiveExport, timeout: float = 300.0) -> AsyncIterator[bytes]:
    """The bytes of ``export``'s file as they are written, until the export has ended.

    The encoder rewrites a few header bytes when it closes the file (duration, sizes); a
    follower has sent the first version of them, which marks the length as unknown: a valid
    WebM that browsers play as it arrives."""
    deadline = time.monotonic() + timeout
    with export.path.open("rb") as f:
        while True:
            chunk = f.read(READ_BYTES)
            if chunk:
                yield chunk
                continue
            if export.done.is_set():
                while chunk := f.read(READ_BYTES):  # what was written after the last read
                    yield chunk
                return
            if time.monotonic() > deadline:
                return
            await asyncio.sleep(POLL_S)
