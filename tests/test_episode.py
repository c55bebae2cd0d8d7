"""Full episodes: real simulator, real simulated users, scripted and embedded models."""

from __future__ import annotations

import json

import pytest

from activeintent.act.base import make_executor
from activeintent.episode import Episode, EpisodeConfig, EpisodeSeeds, read_rounds
from activeintent.intentions.registry import get_intention
from activeintent.learners.registry import SIGNAL, make_learner
from activeintent.llm.scripted import ScriptedModel
from activeintent.sim.env import TabletopEnv
from activeintent.users.simulated import UserConfig, make_user


@pytest.fixture(scope="module")
def env():
    with TabletopEnv() as e:
        yield e


def scripted_answers(messages, schema):
    """A plausible model: always the colour-match intention, goals built from the scene's objects."""
    title = (schema or {}).get("title", "")
    text = messages[-1].text
    if title == "IntentionAnswer":
        return {"preference": "Each block goes into the bowl of its own colour.", "done": False}
    if title == "SceneChoice":
        return {"objects": ["red block", "blue block", "red bowl", "blue bowl"]}
    if title == "GoalsAnswer":
        objects = text.split("Objects you may use: ")[1].split(".\n")[0].split(", ")
        blocks = [o for o in objects if o.endswith("block")]
        bowls = [o for o in objects if o.endswith("bowl")]
        same = [f"put the {b} in the {b.replace('block', 'bowl')}" for b in blocks if b.replace("block", "bowl") in bowls]
        other = [f"put the {b} in the {bowls[0]}" for b in blocks[:1]]
        goals = [", then ".join(same or other), ", then ".join(other)]
        return dict(zip(schema["properties"], goals, strict=False))
    if title == "RetrievalAnswer":
        return {"retrieved": "The user stopped the robot as it moved a block into a bowl of another colour."}
    raise AssertionError(title)


def run(method, env, tmp_path, model, intention="color-match", rounds=2, seed=3, track_progress=True,
        design_scenes=True, goal_retries=1):
    seeds = EpisodeSeeds.from_seed(seed)
    it = get_intention(intention)
    user = make_user(SIGNAL[method], it, UserConfig(), seed=seeds.user)
    learner = make_learner(method, llm=model, seed=seeds.learner, design_scenes=design_scenes)
    def usage():
        t = model.usage.snapshot()
        return t.calls, t.prompt_tokens, t.completion_tokens

    episode = Episode(learner, it, user, make_executor("plan", model=model), env,
                      EpisodeConfig(rounds=rounds, seed=seed, save_videos=False, track_progress=track_progress,
                                    max_goal_retries=goal_retries), tmp_path,
                      usage=usage)
    return episode.run()


@pytest.mark.parametrize("method", ["preference", "mllm", "mllm-llm"])
def test_paper_learner_full_episode_with_scripted_model(method, env, tmp_path):
    model = ScriptedModel(respond=scripted_answers, accepts_images=False)
    result = run(method, env, tmp_path, model)
    assert result.error is None
    assert result.signals_used == 2
    assert result.success  # the scripted model states the hidden intention
    summary = json.loads((tmp_path / "summary.json").read_text())
    for key in ("method", "intention", "seed", "success", "rounds_used", "final_preference", "final_goal",
                "llm_calls", "prompt_tokens", "completion_tokens", "wall_s", "retriever"):
        assert key in summary
    rounds = read_rounds(tmp_path / "rounds.jsonl")
    assert len(rounds) == result.rounds_used
    assert all(r["calls"] and r["feedback"]["kind"] == SIGNAL[method] for r in rounds)
    # Round 2's intention prompt conditions on round 1's z, y and h (and r for mllm-llm).
    eq = "eq1_intention" if method == "preference" else "eq5_intention"
    second = next(c for c in rounds[1]["calls"] if c["template"] == eq and not c.get("probe"))["prompt"]
    first = rounds[0]
    assert first["preference"] in second and first["goals"][0] in second and "h_1:" in second
    if method == "mllm-llm":
        assert first["retrieved"] and first["retrieved"] in second
    assert result.retriever == (None if method == "preference" else "symbolic")
    assert len(result.per_round_success) == len(rounds)


def test_same_seed_same_episode_with_scripted_model(env, tmp_path):
    a = run("mllm-llm", env, tmp_path / "a", ScriptedModel(respond=scripted_answers, accepts_images=False))
    b = run("mllm-llm", env, tmp_path / "b", ScriptedModel(respond=scripted_answers, accepts_images=False))
    assert strip_timing(read_rounds(tmp_path / "a" / "rounds.jsonl")) == strip_timing(read_rounds(tmp_path / "b" / "rounds.jsonl"))
    assert [t.model_dump(exclude={"calls"}) for t in a.tests] == [t.model_dump(exclude={"calls"}) for t in b.tests]
    assert a.llm_calls == b.llm_calls > 0


def strip_timing(rounds: list[dict]) -> list[dict]:
    out = []
    for r in rounds:
        r = dict(r)
        r.pop("timing", None)
        r["calls"] = [{k: v for k, v in c.items() if k != "s"} for c in r["calls"]]
        out.append(r)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("method", ["preference", "mllm", "mllm-llm"])
def test_paper_learner_full_episode_with_embedded_model(method, env, tmp_path):
    from activeintent.llm.registry import load_model

    model = load_model("embedded", cache_path=tmp_path / "cache.sqlite", cache_mode="record")
    # One round; only mllm-llm designs its scene (the other two save that call on this slow model).
    fast = dict(rounds=1, track_progress=False, design_scenes=method == "mllm-llm", goal_retries=0)
    result = run(method, env, tmp_path / "run", model, **fast)
    assert result.error is None, result.error
    assert result.llm_calls > 0 and result.rounds_used >= 1
    rounds = read_rounds(tmp_path / "run" / "rounds.jsonl")
    assert rounds and all(c.get("answer") or c.get("unusable") for r in rounds for c in r["calls"])
    if method != "mllm-llm":
        return
    # Warm cache: the same seed makes identical calls and gets identical answers, no model work.
    before = model.usage.snapshot()
    again = run(method, env, tmp_path / "again", model, **fast)
    assert model.usage.diff(before).cache_misses == 0
    assert strip_timing(read_rounds(tmp_path / "again" / "rounds.jsonl")) == strip_timing(rounds)
    assert again.final_goal == result.final_goal
