"""Export τ as a GIF, WebM (VP9) or MP4 (H.264), frames sampled from the log at ``fps``."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from activeintent.sim.render import render_frames
from activeintent.world.trajectory import Trajectory

FORMATS = (".gif", ".webm", ".mp4")


def frame_times(traj: Trajectory, fps: float) -> np.ndarray:
    """Times of the exported frames: every 1/fps seconds, always including the last tick."""
    if fps <= 0:
        raise ValueError(f"fps must be positive, got {fps}")
    times = np.arange(0.0, traj.duration + 1e-9, 1.0 / fps)
    if traj.duration - times[-1] > 1e-6:
        times = np.append(times, traj.duration)
    return times


def export_video(
    traj: Trajectory, path: str | Path, fps: float = 10, size: tuple[int, int] = (240, 240),
    progress: Callable[[int, int], None] | None = None, stop_time: float | None = None, workers: int = 1,
    also: tuple[str | Path, ...] = (),
) -> Path:
    """Write ``path`` (.gif, .webm or .mp4, by suffix); ``progress(done, total)`` per frame.
    With ``stop_time`` the video ends at the person's stop, its last frame held and framed in
    red, so a record shows what was seen when the stop came. ``workers`` > 1: frames drawn in
    that many processes (the same frames, sooner). ``also``: more files of other formats made
    from the same frames in the same pass (e.g. an MP4 beside a WebM)."""
    paths = [Path(p) for p in (path, *also)]
    for p in paths:
        if p.suffix.lower() not in FORMATS:
            raise ValueError(f"unsupported video format {p.suffix.lower()!r}; use one of {', '.join(FORMATS)}")
        p.parent.mkdir(parents=True, exist_ok=True)
    times = frame_times(traj, fps)
    if stop_time is not None:
        times = np.append(times[times < stop_time], [stop_time] * max(1, int(fps)))  # hold 1 s
    writers = []
    try:
        for p in paths:
            writers.append(_writer(p, fps))
        for i, (t, frame) in enumerate(zip(times, render_frames(traj, times, size, workers), strict=True)):
            if stop_time is not None and t >= stop_time:
                frame = stop_marked(frame)
            for writer in writers:
                writer.append_data(frame)
            if progress:
                progress(i + 1, len(times))
    finally:
        for writer in writers:
            writer.close()
    return paths[0]


def _writer(path: Path, fps: float):
    import imageio.v2 as iio

    suffix = path.suffix.lower()
    if suffix == ".gif":
        return iio.get_writer(path, mode="I", duration=1000.0 / fps, loop=0)
    if suffix == ".webm":
        # written in half-second clusters as the frames come (no look-ahead), so a browser can
        # play the file while it grows (activeintent.web.live)
        codec, extra = "libvpx-vp9", ["-b:v", "0", "-crf", "34", "-deadline", "realtime", "-cpu-used", "8",
                                      "-lag-in-frames", "0", "-cluster_time_limit", "500", "-flush_packets", "1"]
    else:
        # H.264 baseline-compatible, index at the front: plays in every common browser, Safari included
        codec, extra = "libx264", ["-preset", "veryfast", "-crf", "23", "-movflags", "+faststart"]
    return iio.get_writer(path, format="FFMPEG", mode="I", fps=fps, codec=codec, pixelformat="yuv420p",
                          macro_block_size=2, output_params=extra, ffmpeg_log_level="error")


def stop_marked(frame: np.ndarray, width: int = 4) -> np.ndarray:
    """The frame with a red border: the moment the person pressed stop."""
    out = frame.copy()
    out[:width, :] = out[-width:, :] = out[:, :width] = out[:, -width:] = (220, 30, 30)
    return out
