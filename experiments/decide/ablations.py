"""Ablations of ``decide-<signal>``: each part of it switched back to ``lang-<signal>``'s.

    bin/activeintent bench --plugin experiments/decide/ablations.py \\
        --methods decide-stop,decide-random-scenes-stop,decide-goal-gain-stop,decide-shown-gain-stop,lang-stop ...

- ``decide-random-scenes-<signal>``: random candidate scenes, and the protocol's sampler after a
  "new scene" answer (lang's), with the decision gain;
- ``decide-goal-gain-<signal>``: scenes from the belief, queries by EIG about z (lang's gain);
- ``decide-shown-gain-<signal>``: scenes from the belief, EIG about z without what the scene's
  feasibility tells;
- ``decide-no-needs-<signal>``: no belief over what the intention needs of a scene's objects;
- ``decide-shown-decision-gain-<signal>``: the decision gain without what the scene's
  feasibility tells (only the answers to the shown trajectories);
- ``decide-needs-scenes-<signal>`` (a variant, not an ablation): each candidate scene also meets a
  requirement drawn from the needs belief;
- ``decide-chains-stop`` (a variant): stop queries may also show one likely goal's plan followed by
  another's (``DecideConfig.chains = 4``);
- ``decide-split-stop`` (a variant): stop queries may also show plans grown step by step, each
  step moving away from about half of the likely goals left (``DecideConfig.split = 3``);
- ``decide-joint-<signal>`` (a variant): the final answer may also run a plan for both goals of a
  pair of the 4 likeliest goals (``DecideConfig.final_joint = 4``);
- ``decide-wide-<signal>`` (a variant): a wider query search, twice the candidate scenes kept and
  drawn, plans from the 32 likeliest goals, up to 64 plans per scene;
- ``decide-keep10000-<signal>`` (a variant): the belief starts from the 10,000 shortest goals of the
  language instead of ``learner.KEEP`` = 3,000 (the cut rises from 15.8 to 17.9 bits);
- ``decide-counts-<signal>`` (a variant): the needs belief also has literals that count the blocks a
  selector of the language picks ("at least two cool blocks"; ``DecideConfig.needs_counts``);
- ``decide-pool-<signal>`` (a variant): after each answer the 50 one-clause goals above the start
  cut with the largest prior × likelihood join the belief (``DecideConfig.pool``); ``decide-pool500-<signal>``
  the same with 500;
- ``decide-look-<signal>`` (a variant): two-step lookahead, a query valued by what its answer and
  the best next query of the round tell together (``DecideConfig.lookahead = 2``);
- ``decide-value-<signal>`` (a variant): queries scored by the expected success of the final
  answer on the learner's deployment scenes after the answer (``gain = "value"``), not by
  information about the decision classes;
- ``decide-deploy32-<signal>`` (a variant): decision classes from 32 deployment scenes instead of 8.
"""

from pathlib import Path

from activeintent.learners.registry import METHODS
from activeintent.registry import load_plugin

decide = load_plugin(Path(__file__).resolve().with_name("learner.py"))  # registers decide-<signal>

ABLATIONS = {
    "random-scenes": {"scenes": "random"},
    "goal-gain": {"gain": "goal"},
    "shown-gain": {"gain": "shown"},
    "no-needs": {"needs": False},
    "shown-decision-gain": {"gain": "shown-decision"},
    "needs-scenes": {"scenes": "needs"},
    "chains": {"chains": 4},
    "joint": {"final_joint": 4},
    "split": {"split": 3},
    "wide": {"n_scenes": 8, "scene_candidates": 32, "max_plans": 64, "top_k": 32},
    "keep10000": {"keep": 10000},  # not a config field: the goals the belief starts from
    "counts": {"needs_counts": True},
    "pool": {"pool": 50},
    "pool500": {"pool": 500},
    "look": {"lookahead": 2},
    "value": {"gain": "value"},
    "deploy32": {"deploy_scenes": 32},
}
VARIANTS = ("needs-scenes", "chains", "joint", "split", "wide", "keep10000", "counts", "pool", "pool500", "look", "value", "deploy32")


def _ablation(part: str, signal: str):
    settings = dict(ABLATIONS[part])
    keep = settings.pop("keep", decide.KEEP)
    kind = "variant" if part in VARIANTS else "ablation"
    return decide.decide_method(signal, f"decide-{part}-{signal}", keep=keep,
                                description=f"{kind}: decide-{signal} with {ABLATIONS[part]}", **settings)


for _part in ABLATIONS:
    for _signal in ("stop",) if _part in ("chains", "split") else ("stop", "preference"):  # stop queries only
        METHODS.register(f"decide-{_part}-{_signal}", lambda p=_part, s=_signal: _ablation(p, s))
