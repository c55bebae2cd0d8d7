"""A study session's videos: each round's drawn while it is shown (``web.live``: playable before
the file is complete), the final attempt's written whole; what the pages need to know of each
(VideoInfo). Frame k of a video shows trajectory time k / fps."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import BaseModel, Field

from activeintent.sim.video import export_video, frame_times
from activeintent.web.live import LiveExport


def video_frames(traj: Any, fps: int) -> int:
    """Frames of the exported video of τ: one per 1/fps s from 0, plus the last tick when the
    duration is not a whole number of frames (``activeintent.sim.video.frame_times``)."""
    return len(frame_times(traj, fps))


def video_duration(traj: Any, fps: int) -> float:
    """Media length in seconds of the exported video: each frame is shown for 1/fps s."""
    return video_frames(traj, fps) / fps


class VideoInfo(BaseModel):
    label: str
    url: str = Field(description="the WebM (VP9), playable while it is drawn")
    mp4_url: str = Field(description="the same frames as H.264 MP4, complete with the WebM")
    file: str
    fps: int
    frames: int
    duration: float = Field(description="media length in seconds (frames / fps)")
    trajectory_duration: float


class SessionVideos:
    """The videos of one session (folder ``folder``, served under /api/sessions/<sid>/files/)."""

    def __init__(self, sid: str, folder: Path, fps: int, size: tuple[int, int], workers: int):
        self.sid, self.dir, self.fps, self.size, self.workers = sid, folder, fps, size, workers
        self._live: dict[str, LiveExport] = {}  # file name -> its export (the rounds' videos)

    def info(self, traj: Any, name: str, label: str) -> VideoInfo:
        return VideoInfo(
            label=label,
            file=f"{name}.webm",
            url=f"/api/sessions/{self.sid}/files/{name}.webm",
            mp4_url=f"/api/sessions/{self.sid}/files/{name}.mp4",
            fps=self.fps,
            frames=video_frames(traj, self.fps),
            duration=video_duration(traj, self.fps),
            trajectory_duration=traj.duration,
        )

    def export_whole(self, traj: Any, name: str, label: str) -> VideoInfo:
        """The whole video, written before this returns (the final attempt)."""
        export_video(traj, self.dir / f"{name}.webm", fps=self.fps, size=self.size, workers=self.workers,
                     also=(self.dir / f"{name}.mp4",))
        return self.info(traj, name, label)

    def finish(self) -> None:
        """Wait until every round video is complete (a failed one raises)."""
        for export in list(self._live.values()):
            export.finish()

    def settle(self, timeout: float = 60) -> None:
        """Wait a while for exports still writing (a session ending leaves no file half written)."""
        for export in list(self._live.values()):
            export.done.wait(timeout)

    def live(self, name: str) -> LiveExport | None:
        """The export still writing the file ``name``, or None (absent or complete)."""
        export = self._live.get(name)
        return export if export is not None and not export.done.is_set() else None

    def round(self, round: int, trajectories: list[Any]) -> list[VideoInfo]:
        """A round's videos, drawn at once; returns as soon as each can start playing."""
        names = ([(f"round{round}_a", "A"), (f"round{round}_b", "B")] if len(trajectories) == 2
                 else [(f"round{round}_y", "robot")])
        self.finish()  # the previous round's videos first: two rounds never compete
        exports = []
        for traj, (name, _) in zip(trajectories, names, strict=True):
            export = LiveExport(traj, self.dir / f"{name}.webm", self.fps, self.size, self.workers)
            self._live[f"{name}.webm"] = export
            exports.append(export)
        for export in exports:
            export.wait_playable()
        return [self.info(t, n, label) for t, (n, label) in zip(trajectories, names, strict=True)]
