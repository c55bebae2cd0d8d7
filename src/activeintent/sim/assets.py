"""Bodies of the tabletop: the table, 4 cm blocks and concave bowls (generated in code).

Both the physics world (:mod:`activeintent.sim.env`) and the renderer
(:mod:`activeintent.sim.render`) build their objects here, so they look the same; the
renderer asks for visual-only bodies, which are cheaper.
"""

from __future__ import annotations

import numpy as np
import pybullet as p

from activeintent.memo import memoized
from activeintent.world.colors import COLORS
from activeintent.world.scene import (
    BLOCK_SIZE,
    BOUNDS,
    BOWL_FLOOR,
    BOWL_HEIGHT,
    BOWL_INNER_RADIUS,
    BOWL_RADIUS,
    color_of,
    kind_of,
)

BLOCK_MASS = 0.05  # kg
TABLE_RGBA = (0.80, 0.74, 0.64, 1.0)
WORKSPACE_RGBA = (0.90, 0.86, 0.78, 1.0)  # the 60 cm square, a shade lighter than the table
TABLE_HALF = (0.6, 0.6, 0.02)
TABLE_CENTER = (0.0, -0.45, -TABLE_HALF[2])  # top surface at z = 0
BOWL_BASE_RADIUS = 0.045  # outer radius where the bowl touches the table
BOWL_FLAT_RADIUS = 0.035  # inner floor is flat out to here (a block's half diagonal is 2.8 cm)
BOWL_SEGMENTS = 32


@memoized(size=1, why="no arguments: a pure function of the bowl's constants")
def bowl_mesh() -> tuple[np.ndarray, np.ndarray]:
    """Vertices [V, 3] and triangle indices [F*3] of a closed bowl (surface of revolution).

    Profile: outer wall from the base (radius 4.5 cm, z = 0) to the rim (6.5 cm, BOWL_HEIGHT);
    rim ring; inner wall down to a flat floor of thickness BOWL_FLOOR. The origin is the centre
    of the base, as in :class:`~activeintent.world.state.WorldState`.
    """
    # (radius, z) along the profile, walked outside-bottom -> rim -> inside -> floor centre.
    profile = [
        (0.0, 0.0),
        (BOWL_BASE_RADIUS, 0.0),
        (BOWL_RADIUS, BOWL_HEIGHT),
        (BOWL_INNER_RADIUS, BOWL_HEIGHT),
        (BOWL_FLAT_RADIUS, BOWL_FLOOR),
        (0.0, BOWL_FLOOR),
    ]
    n = BOWL_SEGMENTS
    angles = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    verts: list[tuple[float, float, float]] = []
    rings: list[list[int]] = []
    for r, z in profile:
        if r == 0.0:  # pole: one vertex
            rings.append([len(verts)] * n)
            verts.append((0.0, 0.0, z))
            continue
        ring = []
        for a in angles:
            ring.append(len(verts))
            verts.append((r * np.cos(a), r * np.sin(a), z))
        rings.append(ring)
    tris: list[int] = []
    for lower, upper in zip(rings[:-1], rings[1:], strict=True):
        for i in range(n):
            j = (i + 1) % n
            a, b, c, d = lower[i], lower[j], upper[j], upper[i]
            # (around × along the profile) points outwards: counter-clockwise seen from outside.
            if a != b:
                tris += [a, b, c]
            if c != d:
                tris += [a, c, d]
    return np.asarray(verts, dtype=float), np.asarray(tris, dtype=np.int32)


def _rgba(name: str) -> tuple[float, float, float, float]:
    return (*COLORS[color_of(name)], 1.0)


def create_table(client: int, collide: bool = True) -> int:
    """The table top (z = 0) plus a lighter visual square marking the 60 cm workspace."""
    col = (
        p.createCollisionShape(p.GEOM_BOX, halfExtents=TABLE_HALF, physicsClientId=client)
        if collide
        else -1
    )
    vis = p.createVisualShape(p.GEOM_BOX, halfExtents=TABLE_HALF, rgbaColor=TABLE_RGBA, physicsClientId=client)
    table = p.createMultiBody(0, col, vis, TABLE_CENTER, physicsClientId=client)
    (x0, x1), (y0, y1) = BOUNDS
    half = ((x1 - x0) / 2, (y1 - y0) / 2, 0.0005)
    area = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=WORKSPACE_RGBA, physicsClientId=client)
    p.createMultiBody(0, -1, area, ((x0 + x1) / 2, (y0 + y1) / 2, -0.0004), physicsClientId=client)
    p.changeDynamics(table, -1, lateralFriction=0.8, physicsClientId=client)
    return table


def create_block(client: int, name: str, position: tuple[float, float, float], collide: bool = True) -> int:
    half = (BLOCK_SIZE / 2,) * 3
    vis = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=_rgba(name), physicsClientId=client)
    if not collide:
        return p.createMultiBody(0, -1, vis, position, physicsClientId=client)
    col = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    body = p.createMultiBody(BLOCK_MASS, col, vis, position, physicsClientId=client)
    p.changeDynamics(
        body, -1, lateralFriction=0.8, spinningFriction=0.001, rollingFriction=0.0001,
        restitution=0.0, physicsClientId=client,
    )
    return body


def create_bowl(client: int, name: str, position: tuple[float, float, float], collide: bool = True) -> int:
    """A static concave bowl: triangle-mesh collision (static bodies only) and the same visual."""
    verts, idx = bowl_mesh()
    vis = p.createVisualShape(
        p.GEOM_MESH, vertices=verts.tolist(), indices=idx.tolist(), rgbaColor=_rgba(name),
        physicsClientId=client,
    )
    col = -1
    if collide:
        col = p.createCollisionShape(
            p.GEOM_MESH, vertices=verts.tolist(), indices=idx.tolist(),
            flags=p.GEOM_FORCE_CONCAVE_TRIMESH, physicsClientId=client,
        )
    body = p.createMultiBody(0, col, vis, position, physicsClientId=client)
    if collide:
        p.changeDynamics(body, -1, lateralFriction=0.8, physicsClientId=client)
    return body


def create_object(client: int, name: str, position: tuple[float, float, float], collide: bool = True) -> int:
    """A block or a bowl, by name ("red block", "blue bowl")."""
    if kind_of(name) == "bowl":
        return create_bowl(client, name, position, collide)
    return create_block(client, name, position, collide)


def light_panda_urdf() -> str:
    """Path of a copy of pybullet_data's Panda whose visuals are its collision meshes.

    The original visual meshes have ~100k triangles, which makes CPU rendering (and loading)
    several times slower; the collision meshes keep the arm's shape at a fraction of that.
    Written once to a cache directory (~/.cache/activeintent, or the temp dir).
    """
    import hashlib
    import os
    import tempfile
    from pathlib import Path

    import pybullet_data

    data = Path(pybullet_data.getDataPath()) / "franka_panda"
    text = (data / "panda.urdf").read_text()
    text = text.replace("package://meshes/visual/", f"{data}/meshes/collision/")
    text = text.replace("package://meshes/collision/", f"{data}/meshes/collision/")
    for base in (Path.home() / ".cache" / "activeintent", Path(tempfile.gettempdir()) / "activeintent"):
        try:
            base.mkdir(parents=True, exist_ok=True)
            path = base / f"panda_light_{hashlib.sha256(text.encode()).hexdigest()[:16]}.urdf"  # hash() is salted per process
            if not path.exists() or path.read_text() != text:
                tmp = base / f".{path.name}.{os.getpid()}"
                tmp.write_text(text)
                tmp.replace(path)  # atomic: parallel benchmark processes may race here
            return str(path)
        except OSError:
            continue
    raise OSError("no writable cache directory for the Panda model")


ARM_RGBA = (0.93, 0.93, 0.93, 1.0)
HAND_RGBA = (0.30, 0.30, 0.32, 1.0)


def color_panda(client: int, body: int) -> None:
    """White arm, dark hand and fingers (the collision meshes carry no materials)."""
    for link in range(-1, p.getNumJoints(body, physicsClientId=client)):
        name = p.getJointInfo(body, link, physicsClientId=client)[12].decode() if link >= 0 else "base"
        rgba = HAND_RGBA if ("hand" in name or "finger" in name) else ARM_RGBA
        p.changeVisualShape(body, link, rgbaColor=rgba, physicsClientId=client)
