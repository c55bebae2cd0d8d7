"""Scene specs: which objects are on the table, and where they start (from a seed).

Coordinates follow the Code-as-Policies tabletop: metres, table top at z = 0,
workspace x ∈ [-0.3, 0.3] (left → right), y ∈ [-0.8, -0.2] (bottom → top).
"""

from __future__ import annotations

import difflib
from typing import Literal, NamedTuple

import numpy as np
from pydantic import BaseModel, field_validator

from activeintent.memo import memoized
from activeintent.world.colors import COLOR_NAMES

BOUNDS = ((-0.3, 0.3), (-0.8, -0.2))
BLOCK_SIZE = 0.04
BOWL_RADIUS = 0.065  # outer rim
BOWL_INNER_RADIUS = 0.055
BOWL_HEIGHT = 0.04
BOWL_FLOOR = 0.006  # thickness of the bowl's bottom
ROW_PITCH = 0.052  # centre spacing of blocks set next to each other (PutNextTo, world.predict)
MIN_SPACING = 0.03  # two blocks on one surface closer than this would overlap
KINDS = ("block", "bowl")
ALL_OBJECTS: tuple[str, ...] = tuple(f"{c} {k}" for k in KINDS for c in COLOR_NAMES)
MIN_OBJECTS, MAX_OBJECTS = 3, 10


class SceneError(ValueError):
    """A scene that cannot exist: unknown or duplicate names, too few or too many objects."""


class ObjectName(NamedTuple):
    color: str
    kind: Literal["block", "bowl"]

    @property
    def name(self) -> str:
        return f"{self.color} {self.kind}"

    @classmethod
    def parse(cls, text: str) -> ObjectName:
        """Parse "red block" (also "The Red Block", "grey bowl"); unknown names list valid ones."""
        norm = " ".join(text.lower().replace("grey", "gray").split())
        if norm.startswith("the "):
            norm = norm[4:]
        parts = norm.split(" ")
        if len(parts) == 2 and parts[0] in COLOR_NAMES and parts[1] in KINDS:
            return cls(parts[0], parts[1])  # type: ignore[arg-type]
        close = difflib.get_close_matches(norm, ALL_OBJECTS, n=3)
        hint = f" Did you mean {', '.join(repr(c) for c in close)}?" if close else ""
        raise SceneError(
            f"Unknown object {text!r}.{hint} Valid objects are a colour "
            f"({', '.join(COLOR_NAMES)}) followed by 'block' or 'bowl', e.g. 'red block'."
        )


@memoized(size=4096, why="an object's name (a pure function): asked millions of times about the same few names")
def kind_of(name: str) -> str:
    return name.rsplit(" ", 1)[-1]


@memoized(size=4096, why="an object's name (a pure function): asked millions of times about the same few names")
def color_of(name: str) -> str:
    return name.split(" ", 1)[0]


def own_bowl(block: str) -> str:
    """The bowl of ``block``'s colour."""
    return f"{color_of(block)} bowl"


def footprint_radius(name: str) -> float:
    return BOWL_RADIUS if kind_of(name) == "bowl" else BLOCK_SIZE / 2


class Scene(BaseModel):
    """The objects on the table, e.g. ["red block", "blue bowl", "green block"]."""

    model_config = {"frozen": True}

    objects: tuple[str, ...]

    @field_validator("objects", mode="before")
    @classmethod
    def _check(cls, value: object) -> tuple[str, ...]:
        if isinstance(value, str):
            value = [v for v in value.split(",") if v.strip()]
        names = [ObjectName.parse(str(v)).name for v in value]  # type: ignore[union-attr]
        dupes = sorted({n for n in names if names.count(n) > 1})
        if dupes:
            raise SceneError(f"Duplicate objects in scene: {', '.join(dupes)}. Each object may appear once.")
        if not MIN_OBJECTS <= len(names) <= MAX_OBJECTS:
            raise SceneError(
                f"A scene holds {MIN_OBJECTS} to {MAX_OBJECTS} objects; got {len(names)}: {names}."
            )
        return tuple(names)

    @property
    def blocks(self) -> list[str]:
        return [o for o in self.objects if kind_of(o) == "block"]

    @property
    def bowls(self) -> list[str]:
        return [o for o in self.objects if kind_of(o) == "bowl"]

    def __str__(self) -> str:
        return ", ".join(self.objects)


def sample_scene(
    rng: np.random.Generator,
    n_blocks: int | tuple[int, int] = (2, 3),
    n_bowls: int | tuple[int, int] = (1, 2),
    matching: bool | None = None,
) -> Scene:
    """Sample blocks and bowls of distinct colours.

    ``matching=True`` makes every block's colour also appear as a bowl where possible;
    ``False`` forbids it; ``None`` leaves it to chance.
    """

    def count(spec: int | tuple[int, int]) -> int:
        return spec if isinstance(spec, int) else int(rng.integers(spec[0], spec[1] + 1))

    nb, nw = count(n_blocks), count(n_bowls)
    block_colors = list(rng.choice(COLOR_NAMES, size=nb, replace=False))
    if matching is True:
        shared = block_colors[: min(nb, nw)]
        rest = [c for c in COLOR_NAMES if c not in shared]
        bowl_colors = shared + list(rng.choice(rest, size=nw - len(shared), replace=False))
    elif matching is False:
        rest = [c for c in COLOR_NAMES if c not in block_colors]
        bowl_colors = list(rng.choice(rest, size=nw, replace=False))
    else:
        bowl_colors = list(rng.choice(COLOR_NAMES, size=nw, replace=False))
    return Scene(objects=[f"{c} block" for c in block_colors] + [f"{c} bowl" for c in bowl_colors])


def layout(scene: Scene, seed: int, max_tries: int = 2000) -> dict[str, tuple[float, float, float]]:
    """Initial positions (object centres) without overlap, reproducible from ``seed``.

    Bowls are placed first (they are large); a clearance of 3 cm is kept between footprints
    so that a block can later be set next to anything.
    """
    rng = np.random.default_rng(seed)
    order = sorted(scene.objects, key=lambda n: (kind_of(n) != "bowl", scene.objects.index(n)))
    placed: dict[str, tuple[float, float, float]] = {}
    margin = 0.03
    for name in order:
        r = footprint_radius(name)
        for _ in range(max_tries):
            x = rng.uniform(BOUNDS[0][0] + r + margin, BOUNDS[0][1] - r - margin)
            y = rng.uniform(BOUNDS[1][0] + r + margin, BOUNDS[1][1] - r - margin)
            if all(
                np.hypot(x - p[0], y - p[1]) >= r + footprint_radius(o) + 0.03
                for o, p in placed.items()
            ):
                z = 0.0 if kind_of(name) == "bowl" else BLOCK_SIZE / 2
                placed[name] = (float(x), float(y), z)
                break
        else:
            raise SceneError(
                f"Could not place {len(scene.objects)} objects on the 60 cm × 60 cm table without "
                f"overlap ({', '.join(scene.objects)}); use fewer or smaller objects (bowls take most room)."
            )
    return {name: placed[name] for name in scene.objects}
