"""Frames rendered on demand from a trajectory log (no video is recorded while simulating).

A renderer rebuilds the scene with visual-only bodies in its own PyBullet DIRECT client
(cached per scene), poses objects and joints from the logged tick and draws with the CPU
TinyRenderer, so I_0, I_b and I_s can be produced for any time t.

The table never moves and covers the whole image, and TinyRenderer's time goes by covered
pixels: it is drawn once per image size in a client of its own (colour and depth), and each
frame draws only the objects and the arm and keeps, per pixel, whichever is nearer — what one
z-buffer over both would keep, at a third of the time.
"""

from __future__ import annotations

import threading

import numpy as np
import pybullet as p
import pybullet_data

from activeintent.memo import BoundedCache
from activeintent.sim.assets import color_panda, create_object, create_table, light_panda_urdf
from activeintent.sim.robot import BASE_POSITION, BASE_YAW, REST_POSE
from activeintent.world.state import WorldState
from activeintent.world.trajectory import Trajectory

# A telephoto view from the front, 40 degrees above the table: nearly orthographic, so blocks at
# the back look almost as large as at the front; the whole 60 cm workspace spans the image width,
# and the arm at rest (hand 40-55 cm above the workspace's middle) falls behind the back edge.
# The top of the image is the side near the robot, x grows to the right.
CAMERA_TARGET = (0.0, -0.45, 0.0)
CAMERA_ELEVATION = 40.0  # degrees above the table
CAMERA_DISTANCE = 3.0  # metres from the target
CAMERA_HFOV = 14.0  # degrees, horizontal: every image shows the same width, whatever its aspect
CAMERA_UP = (0.0, 0.0, 1.0)
LIGHT_DIRECTION = (0.3, -0.6, 1.0)
_el = np.radians(CAMERA_ELEVATION)
CAMERA_EYE = (CAMERA_TARGET[0], CAMERA_TARGET[1] - CAMERA_DISTANCE * float(np.cos(_el)),
              CAMERA_TARGET[2] + CAMERA_DISTANCE * float(np.sin(_el)))


def projection(size: tuple[int, int]) -> list[float]:
    """The camera's projection for a ``(width, height)`` image: fixed horizontal field of view."""
    w, h = size
    vfov = 2.0 * np.degrees(np.arctan(np.tan(np.radians(CAMERA_HFOV) / 2.0) * h / w))
    return p.computeProjectionMatrixFOV(float(vfov), w / h, 0.5, 6.0)


_MAX_CACHED = 4


def _camera(client: int, size: tuple[int, int], view, flags: int):
    w, h = size
    return p.getCameraImage(w, h, view, projection(size), shadow=0, lightDirection=LIGHT_DIRECTION,
                            renderer=p.ER_TINY_RENDERER, flags=flags, physicsClientId=client)


def _camera_image(client: int, size: tuple[int, int], view) -> tuple[np.ndarray, np.ndarray]:
    """RGB (H, W, 3) and depth (H, W) of what ``client`` holds, from the one camera."""
    w, h = size
    _, _, rgba, depth, _ = _camera(client, size, view, p.ER_NO_SEGMENTATION_MASK)
    rgb = np.asarray(rgba, dtype=np.uint8).reshape(h, w, 4)[:, :, :3]
    return rgb, np.asarray(depth, dtype=np.float32).reshape(h, w)


def camera_segmentation(client: int, size: tuple[int, int], view) -> tuple[np.ndarray, np.ndarray]:
    """RGB (H, W, 3) and the body id of every pixel (H, W; -1: none), from the same camera
    (for checks of what a video shows, e.g. how many pixels each block gets)."""
    w, h = size
    _, _, rgba, _, seg = _camera(client, size, view, 0)
    return np.asarray(rgba, dtype=np.uint8).reshape(h, w, 4)[:, :, :3], np.asarray(seg).reshape(h, w)


class TableBackdrop:
    """The table alone, drawn once per image size (shared by every scene's renderer)."""

    def __init__(self):
        self.client = p.connect(p.DIRECT)
        create_table(self.client, collide=False)
        self.view = p.computeViewMatrix(CAMERA_EYE, CAMERA_TARGET, CAMERA_UP)
        self._images: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}

    def image(self, size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
        if size not in self._images:
            self._images[size] = _camera_image(self.client, size, self.view)
        return self._images[size]


_backdrop: TableBackdrop | None = None


def table_backdrop() -> TableBackdrop:
    global _backdrop
    if _backdrop is None:
        _backdrop = TableBackdrop()
    return _backdrop


class SceneRenderer:
    """Visual copy of one scene (objects in a fixed order, no table) in its own client."""

    def __init__(self, object_names: list[str]):
        self.client = p.connect(p.DIRECT)
        c = self.client
        p.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=c)
        self.robot = p.loadURDF(
            light_panda_urdf(), BASE_POSITION, p.getQuaternionFromEuler([0, 0, BASE_YAW]),
            useFixedBase=True, physicsClientId=c,
        )
        color_panda(c, self.robot)
        n = p.getNumJoints(self.robot, physicsClientId=c)
        self.movable = [
            j for j in range(n) if p.getJointInfo(self.robot, j, physicsClientId=c)[2] != p.JOINT_FIXED
        ]
        self.object_names = list(object_names)
        self.bodies = [create_object(c, name, (0.0, 0.0, -1.0), collide=False) for name in object_names]
        self.view = p.computeViewMatrix(CAMERA_EYE, CAMERA_TARGET, CAMERA_UP)

    def close(self) -> None:
        if self.client >= 0:
            p.disconnect(physicsClientId=self.client)
            self.client = -1

    def draw(self, poses: np.ndarray, joints: np.ndarray | None, size: tuple[int, int]) -> np.ndarray:
        """``poses`` [N, 7] (xyz + quaternion) in object order; ``joints`` for the arm."""
        c = self.client
        for body, pose in zip(self.bodies, poses, strict=True):
            p.resetBasePositionAndOrientation(body, pose[:3].tolist(), pose[3:7].tolist(), physicsClientId=c)
        if joints is None:
            joints = np.array([*REST_POSE, 0.04, 0.04])
        p.resetJointStatesMultiDof(self.robot, self.movable, [[float(v)] for v in joints], physicsClientId=c)
        rgb, depth = _camera_image(c, size, self.view)
        table_rgb, table_depth = table_backdrop().image(size)
        return np.where((depth < table_depth)[:, :, None], rgb, table_rgb)


# by the scene's objects in order; an evicted renderer's PyBullet client is closed
_cache: BoundedCache[tuple[str, ...], SceneRenderer] = BoundedCache(_MAX_CACHED, on_evict=SceneRenderer.close)
_HERE = threading.Lock()  # this process's PyBullet clients draw for one thread at a time


def renderer_for(object_names: list[str]) -> SceneRenderer:
    """The cached renderer of a scene (least recently used ones are closed)."""
    return _cache.get_or_make(tuple(object_names), lambda: SceneRenderer(list(object_names)))


def _check_size(size: tuple[int, int]) -> tuple[int, int]:
    w, h = int(size[0]), int(size[1])
    if not (16 <= w <= 2048 and 16 <= h <= 2048):
        raise ValueError(f"image size must be between 16 and 2048 pixels per side, got {size}")
    return w, h


def render_frame(traj: Trajectory, t: float, size: tuple[int, int] = (240, 240)) -> np.ndarray:
    """RGB image (H, W, 3) uint8 of τ at time t seconds (clipped to the trajectory)."""
    return next(render_frames(traj, np.array([t]), size))


def render_state(state: WorldState, size: tuple[int, int] = (240, 240)) -> np.ndarray:
    """RGB image of a world state (objects upright, arm in its rest pose), e.g. a scene's I_0."""
    size = _check_size(size)
    names = state.names
    poses = np.array([[*state.positions[n], 0.0, 0.0, 0.0, 1.0] for n in names])
    with _HERE:
        return renderer_for(names).draw(poses, None, size)


# -- frames of a video in worker processes ---------------------------------------------------
# TinyRenderer holds the GIL while it draws, so frames are drawn in parallel only in processes.
CHUNK_FRAMES = 8  # frames per task: small enough that the writer starts early
_pool = None
_pool_workers = 0
_pool_unstartable = False  # the processes could not start once: they will not start later either
_pool_delivered = False  # the pool has drawn frames at least once


def _draw_chunk(names: list[str], poses: np.ndarray, joints: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    renderer = renderer_for(names)
    return np.stack([renderer.draw(poses[i], joints[i], size) for i in range(len(poses))])


def _exit_with(parent: int) -> None:
    """In a render process: leave as soon as the process that started it is gone (killed
    servers must not leave their render processes behind)."""
    import os
    import threading
    import time

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(0)

    threading.Thread(target=watch, name="parent-watch", daemon=True).start()


def _render_pool(workers: int):
    """The shared pool of ``workers`` render processes (started once, on first use)."""
    global _pool, _pool_workers
    if _pool is None or _pool_workers != workers:
        import multiprocessing as mp
        import os
        from concurrent.futures import ProcessPoolExecutor

        if _pool is not None:
            _pool.shutdown(wait=False, cancel_futures=True)
        _pool = ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn"),
                                    initializer=_exit_with, initargs=(os.getpid(),))
        _pool_workers = workers
    return _pool


def _mark_delivered() -> None:
    global _pool_delivered
    _pool_delivered = True


def _forget_pool(unstartable: bool = False) -> None:
    global _pool, _pool_unstartable
    _pool = None
    _pool_unstartable = _pool_unstartable or unstartable


def warm_render_pool(workers: int) -> bool:
    """Start the render processes now (each takes ~1 s to import PyBullet), not at the first video.
    False when they cannot start (e.g. a script without ``if __name__ == "__main__":``, which
    spawned processes need): videos are then drawn in this process."""
    if workers <= 1 or _pool_unstartable:
        return False
    from concurrent.futures.process import BrokenProcessPool

    pool = _render_pool(workers)
    try:
        for f in [pool.submit(_check_size, (16, 16)) for _ in range(workers)]:
            f.result()
    except (BrokenProcessPool, RuntimeError, OSError):
        _forget_pool(unstartable=True)  # remembered: no video pays for another failed start
        return False
    return True


def _draw_here(traj: Trajectory, ticks: list[int], size: tuple[int, int]):
    for k in ticks:
        with _HERE:
            frame = renderer_for(traj.object_names).draw(traj.object_poses[k], traj.joint_positions[k], size)
        yield frame


def render_frames(traj: Trajectory, times: np.ndarray, size: tuple[int, int] = (240, 240),
                  workers: int = 1):
    """The frames of τ at ``times``, in order, drawn by ``workers`` processes (1: this one).
    Identical whatever ``workers`` is: each frame depends on its logged tick only."""
    size = _check_size(size)
    if traj.n_ticks == 0:
        raise ValueError("the trajectory has no ticks to render")
    ticks = [traj.tick_at(float(t)) for t in times]
    if workers <= 1 or len(ticks) <= CHUNK_FRAMES or _pool_unstartable:
        yield from _draw_here(traj, ticks, size)
        return
    from concurrent.futures.process import BrokenProcessPool

    pool = _render_pool(workers)
    chunks = [ticks[i:i + CHUNK_FRAMES] for i in range(0, len(ticks), CHUNK_FRAMES)]

    def submit(c: list[int]):
        return pool.submit(_draw_chunk, list(traj.object_names), traj.object_poses[c], traj.joint_positions[c], size)

    # The first chunk alone, then at most ``workers`` at a time: videos drawn at once share the
    # processes, and each one's first frames come first (a round's videos all start soon).
    futures = [submit(chunks[0])]
    for n in range(len(chunks)):
        try:
            frames = futures[n].result()
        except BrokenProcessPool:  # a worker died: the rest in this process, the pool restarted next time
            _forget_pool(unstartable=n == 0 and not _pool_delivered)  # never drew a frame: it cannot start
            yield from _draw_here(traj, [k for c in chunks[n:] for k in c], size)
            return
        _mark_delivered()
        while len(futures) < min(len(chunks), n + 1 + workers):
            futures.append(submit(chunks[len(futures)]))
        yield from frames
