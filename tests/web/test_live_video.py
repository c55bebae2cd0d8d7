"""Round videos shown while they are drawn (activeintent.web.live): the round starts once every
video holds its first frames, and what a browser receives while the file grows is a whole,
playable video with every frame."""

from __future__ import annotations

import asyncio
import threading
from types import SimpleNamespace

import imageio.v2 as iio
import pytest

import activeintent.sim.video as video
from activeintent.sim.video import frame_times
from activeintent.web.live import CLUSTER_ID, LiveExport, follow
from activeintent.world import PutIn, Scene
from helpers import kinematic_trajectory

SCENE = Scene(objects=["red block", "blue block", "red bowl", "blue bowl"])
TRAJ = kinematic_trajectory(SCENE, 1, [PutIn(block="red block", bowl="red bowl"),
                                       PutIn(block="blue block", bowl="blue bowl")])
FPS, SIZE = 10, (64, 48)


def frames_of(path) -> int:
    with iio.get_reader(path, format="FFMPEG") as reader:
        return sum(1 for _ in reader)


async def collect(export, out: list[bytes], on_first=None) -> None:
    async for chunk in follow(export):
        out.append(chunk)
        if on_first is not None and len(out) == 1:
            on_first()


def test_follow_sends_what_is_written_until_the_export_ends(tmp_path):
    path = tmp_path / "v.webm"
    path.write_bytes(b"first")
    export = SimpleNamespace(path=path, done=threading.Event())
    got: list[bytes] = []

    def grow():  # written while the follower waits, then the end
        with path.open("ab") as f:
            f.write(b"-second")
        export.done.set()

    asyncio.run(collect(export, got, on_first=lambda: threading.Timer(0.05, grow).start()))
    assert b"".join(got) == b"first-second"


def test_a_video_followed_while_it_is_drawn_is_whole_and_playable(tmp_path, monkeypatch):
    """The export is held after its first frames until the follower has read them, so the
    bytes it sends come partly from before the encoder rewrote the file's header."""
    held, release = threading.Event(), threading.Event()
    draw = video.render_frames

    def slow_frames(traj, times, size, workers):
        for n, frame in enumerate(draw(traj, times, size, 1)):
            if n == 12:  # more than the first cluster is written; the rest waits
                held.set()
                assert release.wait(60)
            yield frame

    monkeypatch.setattr(video, "render_frames", slow_frames)
    export = LiveExport(TRAJ, tmp_path / "round1_y.webm", FPS, SIZE, workers=1)
    export.wait_playable()
    assert held.wait(60) and not export.done.is_set()
    assert CLUSTER_ID in export.path.read_bytes()  # playable: frames are on disk already
    got: list[bytes] = []
    asyncio.run(collect(export, got, on_first=release.set))
    export.finish()
    streamed, whole = b"".join(got), export.path.read_bytes()
    assert streamed != whole  # the header the follower sent is the first one
    (tmp_path / "streamed.webm").write_bytes(streamed)
    n = len(frame_times(TRAJ, FPS))
    assert frames_of(tmp_path / "streamed.webm") == frames_of(export.path) == n


def test_a_failed_export_is_reported_not_lost(tmp_path, monkeypatch):
    def broken(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(video, "render_frames", broken)
    export = LiveExport(TRAJ, tmp_path / "round1_y.webm", FPS, SIZE, workers=1)
    with pytest.raises(RuntimeError, match="disk full"):
        export.wait_playable()
    with pytest.raises(RuntimeError, match="round1_y.webm could not be made"):
        export.finish()
    assert export.done.is_set()

