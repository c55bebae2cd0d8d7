"""The one episode loop under the honest protocol: every answer counts, a fixed budget,
success after every signal on test scenes independent of the hidden intention."""

from __future__ import annotations

import json

import pytest

from activeintent.act.executors import make_executor
from activeintent.envs.symbolic import SymbolicEnv
from activeintent.episode import Episode
from activeintent.learners.paper.structured import PaperSettings
from activeintent.learners.registry import LearnerContext, get_method
from activeintent.llm.scripted import ScriptedModel
from activeintent.protocol import FORMAT_VERSION, trial_seeds
from activeintent.records import read_rounds
from activeintent.runner import RunSpec, build_episode
from activeintent.signals import get_signal
from activeintent.spec import ProtocolConfig
from activeintent.suites import resolve
from activeintent.users.simulated import SimulatedUser, user_profile


class ScriptedUser:
    """Gives the answers it is handed, in order (then repeats the last)."""

    def __init__(self, signal: str, answers: list[dict]):
        self.sig = get_signal(signal)
        self.answers = [self.sig.parse(a) for a in answers]
        self.asked = 0

    def respond(self, scene, trajectories):
        self.asked += 1
        return self.answers[min(self.asked - 1, len(self.answers) - 1)]


def bayes_episode(method: str, user, budget: int, new_scene: str = "counted", seed: int = 4, out=None) -> Episode:
    learner = get_method(method)(LearnerContext(learner_seed=seed))
    return Episode(learner, resolve("stack"), user, make_executor("parse"), SymbolicEnv(),
                   ProtocolConfig(budget=budget, seed=seed, test_scenes=10, new_scene=new_scene), out_dir=out)


@pytest.mark.parametrize("method,answers", [
    ("bayes-stop", [{"new_scene": True}, {"stop_time": 1.5}, {"stop_time": None}, {"new_scene": True}]),
    ("bayes-preference", [{"choice": "A"}, {"new_scene": True}, {"choice": "B"}, {"choice": "cant_choose"}]),
])
def test_every_answer_is_one_signal(method, answers):
    user = ScriptedUser("stop" if method == "bayes-stop" else "preference", answers)
    result = bayes_episode(method, user, budget=4).run()
    assert result.error is None
    assert user.asked == result.rounds_used == result.signals_used == 4
    assert sum(result.answers.values()) == 4 and result.answers["new_scene"] == sum(a.get("new_scene", False) for a in answers)
    assert len(result.success_at) == 5 and all(s is not None for s in result.success_at)


def test_free_rule_does_not_count_new_scene_answers_and_says_so():
    answers = [{"new_scene": True}, {"new_scene": True}, {"stop_time": None}, {"stop_time": None}]
    result = bayes_episode("bayes-stop", ScriptedUser("stop", answers), budget=2, new_scene="free").run()
    assert result.rounds_used == 4 and result.signals_used == 2 and result.new_scene == "free"
    assert len(result.success_at) == 3


def test_budget_is_fixed_even_when_the_learner_says_done():
    result = build_episode(RunSpec.from_options(method="bayes-stop", intention="stack", env="symbolic", llm="none",
                                      user="exact", video="none", budget=6, seed=2)).run()
    assert result.signals_used == result.rounds_used == 6


def test_test_scenes_are_the_same_for_every_method_and_intention_of_a_trial():
    scenes = {}
    for intention in ("stack", "color-match", "one-bowl"):
        seed, test_seed = trial_seeds(7, intention, trial=1)
        for method in ("bayes-stop", "zero-signal"):
            r = build_episode(RunSpec.from_options(method=method, intention=intention, env="symbolic", llm="none",
                                         video="none", budget=1, seed=seed, test_seed=test_seed)).run()
            scenes[(intention, method)] = [(t.scene, t.layout_seed) for t in r.tests]
    first = next(iter(scenes.values()))
    assert len(first) >= 10 and all(v == first for v in scenes.values())
    assert trial_seeds(7, "stack", 1)[1] != trial_seeds(7, "stack", 2)[1]


def test_the_test_scenes_tell_a_learner_nothing_about_the_intention():
    """Same trial, two intentions: a learner that asks nothing answers identically on every
    test scene — nothing of the hidden intention reached it through the scenes."""
    answers = {}
    for intention in ("stack", "color-match"):
        _, test_seed = trial_seeds(0, intention, trial=0)
        r = build_episode(RunSpec.from_options(method="zero-signal", intention=intention, env="symbolic", llm="none",
                                     video="none", seed=11, test_seed=test_seed)).run()
        answers[intention] = [(t.scene, t.plan, t.z) for t in r.tests]
        assert r.test_excluded == sum(not t.feasible for t in r.tests)
    assert answers["stack"] == answers["color-match"]


def test_infeasible_test_scenes_are_excluded_from_scoring_only():
    r = build_episode(RunSpec.from_options(method="bayes-stop", intention="color-match", env="symbolic", llm="none",
                                 video="none", budget=1, seed=5)).run()
    feasible = [t for t in r.tests if t.feasible]
    assert 0 < r.test_excluded < r.test_scenes + r.test_pool == len(r.tests)
    assert r.test_scored == len(feasible) == len(r.tests) - r.test_excluded
    assert r.success == pytest.approx(sum(t.success for t in feasible) / len(feasible))


def test_same_seed_same_episode(tmp_path):
    def once(out):
        build_episode(RunSpec.from_options(method="bayes-preference", intention="color-mismatch", env="symbolic", llm="none",
                                 video="none", budget=3, seed=9), out).run()
        rounds = read_rounds(out / "rounds.jsonl")
        for r in rounds:
            r.pop("timing")
        return rounds, json.loads((out / "summary.json").read_text())["success_at"]

    assert once(tmp_path / "a") == once(tmp_path / "b")


def test_round_records_explain_the_query(tmp_path):
    build_episode(RunSpec.from_options(method="bayes-preference", intention="stack", env="symbolic", llm="none",
                             video="none", budget=2, seed=1), tmp_path).run()
    rounds = read_rounds(tmp_path / "rounds.jsonl")
    for r in rounds:
        assert r["format"] == FORMAT_VERSION and r["labels"] == ["A", "B"]
        if not r["answer"]["new_scene"]:
            assert r["why"]["eig_nats"] > 0 and len(r["why"]["alternatives"]) == 3
            assert all(a["eig_nats"] <= r["why"]["eig_nats"] + 1e-3 for a in r["why"]["alternatives"])
            assert r["why"]["belief_before"]["entropy_bits"] > 0


def scripted_answers(messages, schema):
    """A model that states colour-match and names goals that cannot be grounded in round 1."""
    title = (schema or {}).get("title", "")
    if title == "IntentionAnswer":
        return {"preference": "Each block goes into the bowl of its own colour.", "done": False}
    if title == "SceneChoice":
        return {"objects": ["red block", "blue block", "red bowl", "blue bowl"]}
    if title == "GoalsAnswer":
        return dict.fromkeys(schema["properties"], "put the red block in the blue bowl")
    if title == "RetrievalAnswer":
        return {"retrieved": "the robot put a block in a bowl of another colour"}
    if title == "Plan":
        return {"steps": []}
    raise AssertionError(title)


def test_an_ungroundable_goal_then_no_stop_is_a_failed_execution_not_approval(tmp_path):
    model = ScriptedModel(respond=scripted_answers, accepts_images=False)
    learner = get_method("mllm-llm")(LearnerContext(llm=model, settings=PaperSettings(variant="structured")))
    user = ScriptedUser("stop", [{"stop_time": None}])
    # An executor that can ground nothing: every y fails to become motion.
    executor = make_executor("parse")
    learner_goal = "make the table look nice"
    episode = Episode(learner, resolve("color-match"), user, executor, SymbolicEnv(),
                      ProtocolConfig(budget=1, test_scenes=1, max_goal_retries=0), out_dir=tmp_path)
    learner._goals = lambda *a, **k: [learner_goal]  # noqa: SLF001 - force an ungroundable y
    episode.run()
    (r,) = read_rounds(tmp_path / "rounds.jsonl")
    assert r["executed"] == [False] and r["failures"][0]
    assert "accepted" not in (r["retrieved"] or "") and "nothing moved" in r["retrieved"]


def test_model_calls_are_counted_when_built_from_python():
    model = ScriptedModel(respond=scripted_answers, accepts_images=False)
    learner = get_method("preference")(LearnerContext(llm=model, settings=PaperSettings(variant="structured")))
    user = SimulatedUser(resolve("color-match"), "preference", user_profile("exact"), rng=0)

    def usage():
        t = model.usage.snapshot()
        return t.calls, t.prompt_tokens, t.completion_tokens

    result = Episode(learner, resolve("color-match"), user, make_executor("parse"), SymbolicEnv(),
                     ProtocolConfig(budget=1, test_scenes=2), usage=usage).run()
    assert result.llm_calls == model.usage.snapshot().calls > 0


@pytest.mark.slow
def test_physics_scoring_at_the_end_reports_agreement(tmp_path):
    r = build_episode(RunSpec.from_options(method="bayes-stop", intention="stack", env="pybullet", llm="none",
                                 video="final", budget=1, seed=3, test_scenes=3), tmp_path).run()
    curve, pool = r.tests[:3], r.tests[3:]  # physics runs on the curve's scenes; the pool is symbolic only
    assert len(pool) == 60 and all(t.success_physics is None for t in pool)
    scored = [t for t in curve if t.feasible]
    assert scored and all(t.success_physics is not None for t in scored)
    assert r.physics_disagreements == sum(t.success != t.success_physics for t in scored)
    assert r.env == "pybullet" and (tmp_path / "final.gif").stat().st_size > 0


def test_the_final_answer_reported_is_on_the_first_scene_that_can_show_the_intention():
    """final_z / final_goal (what `run` prints and the final video shows) come from the first test
    scene the hidden intention can be shown on, not from scene 0 when that one cannot."""
    for seed in range(12):
        r = build_episode(RunSpec.from_options(method="zero-signal", intention="two-towers", env="symbolic", llm="none",
                                     budget=0, seed=seed, test_scenes=4, test_pool=4, video="none")).run()
        if not r.tests[0].feasible:
            break
    else:
        pytest.fail("no seed in 0..11 puts an infeasible scene first")
    i = r.final_scene
    assert i is not None and i > 0 and r.tests[i].feasible and not any(t.feasible for t in r.tests[:i])
    assert (r.final_z, r.final_goal) == (r.tests[i].z, r.tests[i].goal)
    assert r.final_goal != r.tests[0].goal or r.tests[0].scene != r.tests[i].scene


def test_a_free_rule_final_attempt_is_on_the_first_scene_the_learners_belief_can_show():
    """show_final = learner-showable reads the learner's own P(shown), never the hidden rule."""
    from activeintent.protocol import draw_test_scenes

    tests = draw_test_scenes(3, 4)
    episode = build_episode(RunSpec.from_options(method="bayes-stop", intention="stack", env="symbolic", llm="none",
                                       budget=0, seed=0, test_scenes=2, test_pool=2, video="none"),
                            show_final="learner-showable")
    episode.learner.shown_mass = lambda scene: 0.9 if scene is tests[2][0] else 0.1
    assert episode.scoring.final_shown_index(tests) == 2
    episode.learner.shown_mass = lambda scene: 0.1
    assert episode.scoring.final_shown_index(tests) == 0
    episode.show_final = "first"
    episode.learner.shown_mass = lambda scene: 0.9 if scene is tests[2][0] else 0.1
    assert episode.scoring.final_shown_index(tests) == 0
