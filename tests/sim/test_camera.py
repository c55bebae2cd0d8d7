"""What a person sees in the videos: every block large enough, not hidden by the arm at rest,
inside the image, and of the colour its name says."""

from __future__ import annotations

import colorsys

import numpy as np
import pybullet as p
import pytest

from activeintent.sim.render import SceneRenderer, camera_segmentation
from activeintent.sim.robot import REST_POSE
from activeintent.web.basics import VIDEO_SIZE
from activeintent.world import BLOCK_SIZE, BOUNDS, COLOR_NAMES, WorldState, layout, sample_scene

MIN_BLOCK_PX = 40
REST = np.array([*REST_POSE, 0.04, 0.04])


AWAY = ((0.0, 5.0, -5.0), (0.0, 0.0, 0.0, 1.0))  # the arm's base out of the picture


def shot(renderer: SceneRenderer, state: WorldState, base) -> tuple[np.ndarray, np.ndarray]:
    """RGB and segmentation of ``state``, the arm at rest with its base at ``base``."""
    c = renderer.client
    poses = np.array([[*state.positions[n], 0.0, 0.0, 0.0, 1.0] for n in renderer.object_names])
    renderer.draw(poses, REST, VIDEO_SIZE)  # poses the bodies and the joints
    p.resetBasePositionAndOrientation(renderer.robot, *base, physicsClientId=c)
    return camera_segmentation(c, VIDEO_SIZE, renderer.view)


@pytest.fixture(scope="module")
def rest_base():
    r = SceneRenderer(["red block"])
    base = p.getBasePositionAndOrientation(r.robot, physicsClientId=r.client)
    r.close()
    return base


def block_boxes(renderer: SceneRenderer, state: WorldState, base) -> dict[str, tuple[int, int, int, bool]]:
    """Per block: visible pixels, width and height of its box, and whether it is inside the image."""
    _, seg = shot(renderer, state, base)
    h, w = seg.shape
    out = {}
    for name, body in zip(renderer.object_names, renderer.bodies, strict=True):
        ys, xs = np.nonzero(seg == body)
        if not len(xs):
            out[name] = (0, 0, 0, False)
            continue
        inside = xs.min() > 0 and ys.min() > 0 and xs.max() < w - 1 and ys.max() < h - 1
        out[name] = (len(xs), int(xs.max() - xs.min() + 1), int(ys.max() - ys.min() + 1), bool(inside))
    return out


def test_every_block_is_at_least_40_px_inside_the_image_and_not_hidden_by_the_arm_at_rest(rest_base):
    # blocks on a grid over the whole workspace (centres as far out as a layout puts them) and in
    # 40 random scenes' layouts
    (x0, x1), (y0, y1) = BOUNDS
    m = BLOCK_SIZE / 2 + 0.03
    grid = [(x, y) for x in np.linspace(x0 + m, x1 - m, 5) for y in np.linspace(y0 + m, y1 - m, 5)]
    states = [WorldState(positions={"red block": (float(x), float(y), BLOCK_SIZE / 2)}) for x, y in grid]
    rng = np.random.default_rng(0)
    for k in range(40):
        scene = sample_scene(rng, n_blocks=(2, 6), n_bowls=(1, 3))
        states.append(WorldState(positions=layout(scene, k)))
    smallest, checked = 10**9, 0
    for state in states:
        renderer = SceneRenderer(state.names)
        try:
            seen = block_boxes(renderer, state, rest_base)
            alone = block_boxes(renderer, state, AWAY)
        finally:
            renderer.close()
        for name in state.blocks:
            pixels, width, height, inside = seen[name]
            assert inside, f"{name} at {state.positions[name]} is not wholly inside the image"
            assert pixels == alone[name][0], f"the arm at rest hides part of {name} at {state.positions[name]}"
            smallest = min(smallest, width, height)
            checked += 1
    assert checked > 100
    assert smallest >= MIN_BLOCK_PX, f"a block is only {smallest} px across at {VIDEO_SIZE}"


# Hue windows (degrees) and lightness rules of the colour words; pink is a light, pale red,
# brown a dark orange, gray has almost no saturation.
def colour_word(rgb: np.ndarray) -> str:
    h, s, v = colorsys.rgb_to_hsv(*(np.asarray(rgb, float) / 255))
    hue = h * 360
    if s < 0.15:
        return "gray"
    if (hue >= 330 or hue < 15) and s < 0.5 and v > 0.8:
        return "pink"
    if hue >= 340 or hue < 15:
        return "red"
    if hue < 45:
        return "brown" if v < 0.65 else "orange"
    for word, top in (("yellow", 70), ("green", 160), ("cyan", 200), ("blue", 250), ("purple", 300)):
        if hue < top:
            return word
    return "pink"


def test_each_block_looks_like_the_colour_it_is_named():
    names = [f"{c} block" for c in COLOR_NAMES]
    xs = np.linspace(-0.22, 0.22, 5)
    state = WorldState(positions={n: (float(xs[i % 5]), -0.35 - 0.25 * (i // 5), BLOCK_SIZE / 2)
                                  for i, n in enumerate(names)})
    renderer = SceneRenderer(names)
    try:
        rgb, seg = shot(renderer, state, AWAY)
    finally:
        renderer.close()
    seen = {}
    for name, body in zip(names, renderer.bodies, strict=True):
        px = rgb[seg == body].astype(float)
        lit = px[px.sum(axis=1) >= np.quantile(px.sum(axis=1), 0.6)]  # the top face, lit from above
        seen[name] = colour_word(np.median(lit, axis=0))
    assert seen == {n: n.split()[0] for n in names}
