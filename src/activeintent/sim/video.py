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
) -> Path:
    """Write ``path`` (.gif, .webm or .mp4, by suffix); ``progress(done, total)`` per frame.
    With ``stop_time`` the video ends at the person's stop, its last frame held and framed in
    red, so a record shows what was seen when the stop came. ``workers`` > 1: frames drawn in
    that many processes (the same frames, sooner)."""
    import imageio.v2 as iio

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise ValueError(f"unsupported video format {suffix!r}; use one of {', '.join(FORMATS)}")
    path.parent.mkdir(parents=True, exist_ok=True)
    times = frame_times(traj, fps)
    if stop_time is not None:
        times = np.append(times[times < stop_time], [stop_time] * max(1, int(fps)))  # hold 1 s
    if suffix == ".gif":
        writer = iio.get_writer(path, mode="I", duration=1000.0 / fps, loop=0)
    else:
        codec = "libvpx-vp9" if suffix == ".webm" else "libx264"
        # WebM: written in half-second clusters as the frames come (no look-ahead), so a browser
        # can play the file while it grows (activeintent.web.live)
        extra = ["-b:v", "0", "-crf", "34", "-deadline", "realtime", "-cpu-used", "8", "-lag-in-frames", "0",
                 "-cluster_time_limit", "500", "-flush_packets", "1"] if suffix == ".webm" else [
            "-preset", "veryfast", "-crf", "23"
        ]
        writer = iio.get_writer(
            path, format="FFMPEG", mode="I", fps=fps, codec=codec, pixelformat="yuv420p",
            macro_block_size=2, output_params=extra, ffmpeg_log_level="error",
        )
    try:
        for i, (t, frame) in enumerate(zip(times, render_frames(traj, times, size, workers), strict=True)):
            if stop_time is not None and t >= stop_time:
                frame = stop_marked(frame)
            writer.append_data(frame)
            if progress:
                progress(i + 1, len(times))
    finally:
        writer.close()
    return path


def stop_marked(frame: np.ndarray, width: int = 4) -> np.ndarray:
    """The frame with a red border: the moment the person pressed stop."""
    out = frame.copy()
    out[:width, :] = out[-width:, :] = out[:, :width] = out[:, -width:] = (220, 30, 30)
    return out
