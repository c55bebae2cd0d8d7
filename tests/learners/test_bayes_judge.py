"""The clause-vectorised judge of bayes/judge.py gives, state for state, what every hypothesis's
own holds_f / score_f / moved_off gives (the per-hypothesis definition is the reference)."""

import numpy as np

from activeintent.goals.facts import facts
from activeintent.learners.bayes.hypotheses import (
    enumerate_hypotheses,
    hypothesis_space,
    random_scene,
)
from activeintent.learners.bayes.judge import first_away, judge
from activeintent.world import PutAt, PutIn, PutOn, WorldState, apply_skill, layout


def _walks(n: int, seed: int = 3) -> list[list[WorldState]]:
    rng = np.random.default_rng(seed)
    walks = []
    for _ in range(n):
        scene = random_scene(rng)
        state = WorldState(positions=layout(scene, int(rng.integers(2**31))))
        walk = [state]
        for _ in range(4):
            block = str(rng.choice(state.blocks))
            target = str(rng.choice([o for o in state.names if o != block]))
            if rng.random() < 0.3:
                step = PutAt(block=block, position=(float(rng.uniform(-0.25, 0.25)), float(rng.uniform(-0.75, -0.2))))
            elif target.endswith("bowl"):
                step = PutIn(block=block, bowl=target)
            else:
                step = PutOn(block=block, target=target)
            new, fail = apply_skill(state, step)
            if fail is None:
                walk.append(new)
                state = new
        walks.append(walk)
    return walks


def _reference_first_away(hyps, steps) -> np.ndarray:
    out = np.full(len(hyps), -1)
    for k, (fb, fa, block, ok) in enumerate(steps):
        if fb is fa:  # a step that changed nothing moves away from nothing
            continue
        for i, h in enumerate(hyps):
            if out[i] < 0 and (h.score_f(fa) < h.score_f(fb) - 1e-9 or (ok and h.moved_off(fb, fa, block))):
                out[i] = k
    return out


def test_vectorised_judge_equals_each_hypothesis():
    rng = np.random.default_rng(0)
    for hyps in (tuple(enumerate_hypotheses()), hypothesis_space()):
        token = object()
        for walk in _walks(40):
            fs = [facts(s) for s in walk]
            for f in fs:
                sat, score = judge(hyps, f, token)
                assert np.array_equal(sat, [h.holds_f(f) for h in hyps])
                assert np.array_equal(score, [h.score_f(f) for h in hyps])  # the same floats, exactly
            steps = []
            for before, after, fb, fa in zip(walk, walk[1:], fs, fs[1:], strict=False):
                moved = next((b for b in before.blocks if before.positions[b] != after.positions[b]), before.blocks[0])
                steps.append((fb, fa, moved, bool(rng.random() < 0.8)))
            assert np.array_equal(first_away(hyps, steps, token), _reference_first_away(hyps, steps))


def test_vectorised_feasibility_equals_each_hypothesis():
    """HypothesisJudge.feasible (clause by clause, once per distinct clause) says what every
    hypothesis's own feasible(scene) says, scene for scene."""
    from activeintent.learners.bayes.judge import HypothesisJudge

    rng = np.random.default_rng(5)
    for hyps in (tuple(enumerate_hypotheses()), hypothesis_space()):
        judge_ = HypothesisJudge(hyps)
        kinds = set()
        for _ in range(60):
            scene = random_scene(rng)
            want = np.array([h.feasible(scene) for h in hyps])
            assert np.array_equal(judge_.feasible(scene.objects), want)
            kinds.add((bool(want.all()), bool(want.any())))
        assert (False, True) in kinds  # scenes that show some hypotheses and not others
