"""Every experiment's plug-in loads and runs one short episode (experiments/<name>/): the
findings in their READMEs stay reproducible with the product as it is now."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from activeintent.registry import load_plugin
from activeintent.results import read_results
from activeintent.runner import build_episode, for_method
from activeintent.spec import RunSpec

EXPERIMENTS = Path(__file__).resolve().parents[2] / "experiments"
GRAMMAR = EXPERIMENTS / "grammar-intentions" / "grammar_intentions.py"
# plug-in file → (method, intention, intention file) of its one short episode
EPISODES = {
    "decide/learner.py": ("decide-preference", "stack", None),
    "decide/ablations.py": ("decide-split-stop", "color-match", None),
    "hybrid/hybrid.py": ("hybrid-stop", "align", None),
    "naturalness/naturalness.py": ("lang-natural-stop", "stack", None),
    "lang-fixed/lang_fixed.py": ("lang-fixed-preference", "color-mismatch", None),
    "reward-variants/coarse.py": ("reward-preference-coarse", "stack", None),
    "reward-variants/heavy_tailed.py": ("reward-stop-heavy-tailed", "align", None),
    "reward-variants/noplanner.py": ("reward-stop-noplanner", "color-match", None),
    "grammar-intentions/grammar_intentions.py": ("bayes-stop", None, f"{GRAMMAR}:PINK_BOWL"),
}
SCRIPTS = {"decide/clairvoyant_bound.py", "defaults/compare.py", "defaults/compare_bayes.py",
           "answered-scenes/compare.py", "prior-pass3/compare.py"}  # their own command line
DESIGNS = {"answered-scenes/answered.py": "answered"}  # plug-in file → the scene design it registers
HELPERS = {"decide/acquisition.py", "decide/decision.py", "decide/needs.py", "decide/plans.py"}  # loaded by the above


def test_every_experiment_file_is_run_here():
    files = {str(p.relative_to(EXPERIMENTS)) for p in EXPERIMENTS.glob("*/*.py")}
    assert files == set(EPISODES) | SCRIPTS | HELPERS | set(DESIGNS)
    for folder in {p.parent for p in EXPERIMENTS.glob("*/*.py")}:
        assert (folder / "README.md").is_file(), f"{folder.name} has no README with its finding"


@pytest.mark.parametrize("plugin", sorted(EPISODES))
def test_the_experiment_runs_one_episode(plugin, tmp_path):
    method, intention, intention_file = EPISODES[plugin]
    spec = for_method(RunSpec.from_options(intention=intention, intention_file=intention_file,
                                           plugin=[str(EXPERIMENTS / plugin)], env="symbolic", llm="none", budget=2,
                                           test_scenes=3, test_pool=0, video="none", seed=1,
                                           language=1, prior="length"), method)  # what the findings were measured in
    result = build_episode(spec, tmp_path).run()
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["method"] == method and summary["signals_used"] == 2
    assert len(result.success_at) == 3 and all(0.0 <= s <= 1.0 for s in result.success_at if s is not None)


def test_the_clairvoyant_bound_replays_a_decide_stop_record(tmp_path):
    """The diagnostic re-runs a recorded decide-stop episode of exact users with its chooser."""
    bound = load_plugin(EXPERIMENTS / "decide" / "clairvoyant_bound.py")
    spec = RunSpec.from_options(method="decide-stop", intention="color-match", plugin=[str(EXPERIMENTS / "decide" / "learner.py")],
                                env="symbolic", llm="none", budget=2, test_scenes=3, test_pool=0, video="none",
                                user="exact", seed=2)
    build_episode(spec, tmp_path).run()
    summary = json.loads((tmp_path / "summary.json").read_text())
    record = {"intention": "color-match", "seed": 2, "method": "decide-stop", "success_at": summary["success_at"],
              "config": summary["config"]}
    row = bound.run_one(record)
    assert len(row["success_at"]) == 3 and row["baseline_success_at"] == summary["success_at"]


def test_the_defaults_comparison_pairs_arms_and_applies_the_rule(tmp_path):
    """Arms that are today's episodes again differ by 0 and may become the default; an arm that
    loses on one signal may not."""
    compare = load_plugin(EXPERIMENTS / "defaults" / "compare.py")
    peer = [r for r in read_results(compare.REPO / "docs" / "results" / "peer" / "results.jsonl")
            if r["method"] in compare.LEARNERS and r["intention"].startswith("dev-") and r["trial"] < compare.TRIALS]
    dev = sorted({r["intention"] for r in peer})
    for arm in compare.ARMS[1:]:
        folder = tmp_path / f"dev-{arm}"
        folder.mkdir()
        (folder / "bench.json").write_text(json.dumps({"intentions": dev}))
        worse = arm == "fitted-belief"
        lines = [{**r, "success_at": [0.0] * len(r["success_at"])} if worse and r["method"] == "lang-stop" else r
                 for r in peer]
        (folder / "results.jsonl").write_text("".join(json.dumps(r) + "\n" for r in lines))
    s = compare.summary(compare.arm_records(tmp_path))
    by = {(p["arm"], p["method"]): p for p in s["paired"]}
    assert by[("length-belief", "lang-stop")]["mean"] == 0 and by[("length-belief", "lang-stop")]["n"] == 100
    assert by[("fitted-belief", "lang-stop")]["mean"] < 0
    assert s["eligible"] == ["length-belief", "fitted-sampled"] and s["default"] == "length-belief"
    assert "Default: length-belief" in compare.markdown(s)

    # an arm not run yet: the others are reported, no default is chosen
    (tmp_path / "dev-fitted-sampled" / "results.jsonl").unlink()
    s = compare.summary(compare.arm_records(tmp_path))
    assert s["missing"] == ["fitted-sampled"] and s["default"] is None
    assert "No default chosen yet" in compare.markdown(s)


@pytest.mark.parametrize("plugin", sorted(DESIGNS))
def test_the_scene_design_runs_one_episode(plugin, tmp_path):
    spec = RunSpec.from_options(method="lang-stop", intention="stack", plugin=[str(EXPERIMENTS / plugin)],
                                scenes=DESIGNS[plugin], env="symbolic", llm="none", budget=3, test_scenes=3,
                                test_pool=0, video="none", seed=1, language=1)
    build_episode(spec, tmp_path).run()
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["config"]["spec"]["learner"]["settings"]["scenes"] == DESIGNS[plugin] and summary["signals_used"] == 3


def test_answered_scenes_ask_again_on_answered_tables_and_not_on_refused_ones():
    from activeintent.goals.language import parse_goal
    from activeintent.learners.bayes.learner import Observation
    from activeintent.learners.lang.hypotheses import LangSpace
    from activeintent.learners.lang.learner import LangConfig, LangLearner
    from activeintent.signals.base import Answer
    from activeintent.world import Scene

    load_plugin(EXPERIMENTS / "answered-scenes" / "answered.py")
    space = LangSpace([parse_goal(k) for k in ["every colour:red on-the-block:blue", "form tower:any all:"]])
    learner = LangLearner("stop", rng=0, config=LangConfig(scenes="answered"), hypotheses=space.hypotheses)
    assert learner.redesigns_after_new_scene
    answered = Scene(objects=["green block", "yellow block", "pink bowl"])
    refused = Scene(objects=["cyan block", "purple block", "gray bowl"])
    first = learner.design_scene()  # nothing answered yet: the belief's candidates
    learner.observations += [Observation(answered, Answer(signal="stop"), []),
                             Observation(refused, Answer(signal="stop", new_scene=True), [])]
    assert [learner.design_scene().objects for _ in range(3)] == [answered.objects] * 3
    learner.observations.append(Observation(answered, Answer(signal="stop", new_scene=True), []))  # refused later
    again = learner.design_scene().objects
    assert again not in (answered.objects, refused.objects) and first is not None
