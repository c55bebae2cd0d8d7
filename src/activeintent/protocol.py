"""The evaluation protocol every number comes from (docs/protocol.md).

- Every user answer is a signal: A / B / can't choose, a stop, "watched to the end", and
  "new scene" each count one (``new_scene="counted"``; ``"free"`` reproduces the old rule of
  up to 3 uncounted new-scene answers and is labelled so in every report; ``"off"`` hides
  the option).
- A fixed budget of K signals; a learner's "done" is recorded but does not end a benchmark
  episode.
- After every signal k = 0..K the learner's current estimate acts on the episode's test
  scenes: ``success_at[k]``; at k = K on a larger pool (the curve's scenes and
  ``test_pool`` more), so that narrow intentions are scored on enough scenes. The headline
  is success@K.
- Test scenes come from one distribution that does not depend on the hidden intention, seeded
  by the trial only, so every method and every intention of a trial gets the same scenes.
  Scenes where the hidden intention cannot be satisfied are dropped from scoring only after
  the learner answered, and counted; nothing about feasibility reaches the learner.
"""

from __future__ import annotations

import hashlib
from typing import Literal

import numpy as np

from activeintent.world import Scene, sample_scene

NewSceneRule = Literal["counted", "free", "off"]
FREE_NEW_SCENES = 3  # the old rule: this many new-scene answers did not count
DEFAULT_TEST_SCENES = 10  # scored after every signal k (the curve)
# ... plus this many more scored at k = K (the headline): an intention feasible in one test scene
# out of six (two-towers: 0.16) still gets ≥ 5 scored scenes in ~99 % of trials (binomial, 70 scenes).
DEFAULT_TEST_POOL = 60
DEFAULT_BUDGET = 5
FORMAT_VERSION = 3  # 3: the test pool at k = K, provenance; of summary.json, rounds.jsonl and results.jsonl lines


def sample_test_scene(rng: np.random.Generator) -> Scene:
    """A test scene of 3–5 objects (as in the paper), from a mixture fixed in advance:
    half "paired" scenes (two blocks and the bowls of their colours, sometimes one more
    bowl), half free scenes (2–4 blocks, 1–2 bowls, colours by chance). The mixture lets
    colour-, bowl- and arrangement-rules all be shown without looking at the hidden one."""
    if rng.random() < 0.5:
        return sample_scene(rng, n_blocks=2, n_bowls=(2, 3), matching=True)
    n_blocks = int(rng.integers(2, 5))
    n_bowls = int(rng.integers(1, min(2, 5 - n_blocks) + 1))
    return sample_scene(rng, n_blocks=n_blocks, n_bowls=n_bowls, matching=None)


def draw_test_scenes(seed: int, n: int) -> list[tuple[Scene, int]]:
    """An episode's ``n`` test scenes with their layout seeds, drawn in order from ``seed``: the
    curve's scenes come first and do not depend on the pool's size."""
    rng = np.random.default_rng(seed)
    return [(sample_test_scene(rng), int(rng.integers(2**31))) for _ in range(n)]


def sample_round_scene(rng: np.random.Generator) -> Scene:
    """A query scene when the learner designs none: two or three blocks and two bowls whose
    colours match blocks' where possible — scenes that can show most intentions, chosen
    without knowing which one is hidden."""
    return sample_scene(rng, n_blocks=(2, 3), n_bowls=2, matching=True)


def stable_seed(*parts: object) -> int:
    """A seed from any values, stable across processes (not Python's salted hash)."""
    digest = hashlib.sha256("|".join(str(p) for p in parts).encode()).digest()
    return int.from_bytes(digest[:4], "little")


def trial_seeds(bench_seed: int, intention: str, trial: int) -> tuple[int, int]:
    """(episode seed, test seed): the episode seed varies with the intention (user noise, query
    scenes); the test seed only with the trial (same test scenes for every intention)."""
    return stable_seed(bench_seed, intention, trial), stable_seed(bench_seed, "test-scenes", trial)
