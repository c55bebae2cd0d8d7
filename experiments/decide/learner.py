"""``decide-<signal>``: ``lang-<signal>`` with questions about what the robot will do.

Three parts on top of the goal-language learner (each switchable, ablations.py):
- scenes designed from the belief, each candidate also drawn to meet a requirement from
- a belief over what the intention needs of a scene's objects, learned from "new scene"
  answers (needs.py), which also softens what such an answer says about z;
- queries scored by the information their answer gives about the decision (decision.py: z
  grouped by which plans satisfy them on the learner's own deployment scenes), optionally with
  a two-step lookahead, longer stop queries (plans.py) and a wider final answer.

Load it with ``--plugin experiments/decide/learner.py``; it registers decide-stop and
decide-preference. The finding is in README.md beside this file.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from itertools import combinations
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import Field, field_validator

from activeintent import ranking
from activeintent.goals import planner
from activeintent.goals.language import Goal, all_clauses, speaking
from activeintent.learners.base import Estimate, LearnerContext, Method, RoundRecord
from activeintent.learners.bayes.candidates import candidate_plans, predict
from activeintent.learners.bayes.hypotheses import random_scene
from activeintent.learners.bayes.learner import Observation, kl_bits
from activeintent.learners.lang.hypotheses import LangSpace
from activeintent.learners.lang.learner import (
    KEEP,
    LangConfig,
    LangJudge,
    LangLearner,
    LangPriorSettings,
)
from activeintent.learners.registry import METHODS
from activeintent.registry import load_plugin
from activeintent.world import (
    Scene,
    WorldState,
    describe_plan,
    describe_skill,
    describe_state,
    layout,
)
from activeintent.world.trajectory import Trajectory

_here = Path(__file__).resolve().parent
acquisition = load_plugin(_here / "acquisition.py")
decision = load_plugin(_here / "decision.py")
needs_mod = load_plugin(_here / "needs.py")
plans = load_plugin(_here / "plans.py")

DECIDE = {"scenes": "belief", "gain": "decision", "needs": True}
_POOLS: dict[tuple[float, int], LangSpace] = {}


def one_clause_pool(cut: float, language: int) -> LangSpace:
    """Every one-clause goal of language ``language``, with and without "every other block
    stays", that is longer than ``cut`` bits (built once per process; learners reset its planner
    verdicts)."""
    key = (round(cut, 6), language)
    if key not in _POOLS:
        with speaking(language):
            goals = [g for c in all_clauses() for g in (Goal((c,)), Goal((c,), True)) if g.bits > cut]
        _POOLS[key] = LangSpace(goals, language=language)
    return _POOLS[key]


class DecideConfig(LangConfig):
    """lang's settings plus the parts of decide (DECIDE switches them on)."""

    scenes: Literal["random", "belief", "needs"] = Field(  # type: ignore[assignment]
        "random", description="random: n_scenes random scenes; belief: from the belief, also after a 'new "
        "scene' answer; needs: as belief, each candidate also meeting a requirement drawn from the needs belief")
    gain: Literal["goal", "shown", "decision", "shown-decision", "value"] = Field(
        "goal", description="what a query's answer is scored by (acquisition.py)")
    deploy_scenes: int = Field(8, ge=1, description="the learner's own scenes of the test distribution")
    needs: bool = Field(False, description="learn what the intention needs of a scene's objects (needs.py)")
    needs_counts: bool = Field(False, description="the needs belief also counts blocks a selector picks")
    chains: int = Field(0, ge=0, description="stop queries: plans of one likely z followed by another's")
    split: int = Field(0, ge=0, description="stop queries: plans grown to split the belief")
    lookahead: int = Field(1, ge=1, le=2, description="2: a query valued with the best next one")
    final_joint: int = Field(0, ge=0, le=8, description="the final answer may run a plan for two likely goals")
    pool: int = Field(0, ge=0, description="after each answer, this many one-clause goals above the cut join")

    @field_validator("scenes")
    @classmethod
    def _known_design(cls, name: str) -> str:  # decide's own designs, above; not SCENE_DESIGNS
        return name


@dataclass
class DecideObservation(Observation):
    refuse: float = 0.0  # q(s) when answered: the needs belief's P(the scene lacks what is needed)


class DecideLearner(LangLearner):
    """LangLearner with decide's scene design, needs belief, decision gains and variants."""

    def __init__(self, signal, rng=None, llm=None, config: DecideConfig | None = None, hypotheses=None,
                 keep: int = KEEP):
        config = config or DecideConfig()
        super().__init__(signal, rng, llm, config, hypotheses, keep)
        self.config: DecideConfig = config
        if config.pool:  # every one-clause goal above the cut, scored on each answer as it comes
            self.pool = one_clause_pool(self.cut, self.language)
            self.pool.reset()
            self.pool_judge = LangJudge(self.pool)
            self.pool_log_post = -np.array([h.bits for h in self.pool.hypotheses]) * np.log(2)  # up to a constant
            self.growth["pool"] = 0
        self._classes = None
        self._look_pool: list[np.ndarray] = []  # this round's query tables (lookahead; cleared at each answer)
        self.needs = (needs_mod.Needs(config.new_scene_error, config.needs_counts, self.language)
                      if config.needs else None)
        self.deploy = (decision.deployment_states(int(self.rng.integers(2**31)), config.deploy_scenes)
                       if self._deciding() else [])

    @property
    def redesigns_after_new_scene(self) -> bool:  # type: ignore[override]
        return self.config.scenes != "random"

    # ---- queries ----

    def _select(self, state: WorldState, scored=None):
        c = self.config
        feasible = self.judge.feasible(tuple(state.positions))
        outs = candidate_plans(self.hyps, self.weights, state, self.rng, top_k=c.top_k, explore=c.explore,
                               prefixes=self.sig.shows > 1, limit=c.max_plans, feasible=feasible)
        feasible = self.judge.feasible(tuple(state.positions))  # the planner may have found some z infeasible
        if c.chains and self.sig.shows == 1:
            outs += plans.chained_plans(self.hyps, self.weights, state, feasible, first=c.chains,
                                        seen={o.key for o in outs})
            feasible = self.judge.feasible(tuple(state.positions))
        if c.split and self.sig.shows == 1:
            outs += plans.split_plans(self.hyps, self.weights, state, feasible, self.judge,
                                      acquisition.particles(self.weights, mass=0.99, cap=256), starts=c.split,
                                      seen={o.key for o in outs},
                                      classes=self.decision_classes() if self._deciding() else None)
            feasible = self.judge.feasible(tuple(state.positions))
        return acquisition.select_query(self.sig, self.model, self.judge, self.weights, feasible, outs,
                                        c.new_scene_error, self.rng, choose=c.choose, gain=c.gain,
                                        classes=self.decision_classes() if self._deciding() else None,
                                        refuse=self.refuse(tuple(state.positions)), scored=scored,
                                        table=self.decision_table() if c.gain == "value" else None)

    def _looking(self) -> bool:
        return self.config.lookahead == 2 and self.config.choose == "eig"

    def _two_step(self, scored, pool):
        """The two-step lookahead's choice among ``scored`` against the query ``pool``."""
        look = acquisition.look_particles(self.weights)
        classes = self.decision_classes()[look] if self._deciding() else np.arange(len(look))
        i, j, value = acquisition.two_step(scored, acquisition.stack_tables(pool), self.weights[look], classes)
        sc = scored[i]
        alternatives = [{"plans": [describe_plan(sc.outs[k].plan) for k in sc.combos[j]], "lookahead_nats": round(value, 4),
                         "note": "chosen by the two-step value; eig_nats is its one-step gain"}]
        return i, acquisition.Query([sc.outs[k] for k in sc.combos[j]], float(sc.gains[j]), alternatives)

    def refuse(self, objects: tuple[str, ...]) -> float:
        """q(s): P(the scene lacks what the intention needs) under the needs belief (0 without one)."""
        return 0.0 if self.needs is None else self.needs.refuse(objects)

    def _deciding(self) -> bool:
        return self.config.gain.endswith("decision") or self.config.gain == "value"

    def decision_classes(self) -> np.ndarray:
        return self._decision()[0]

    def decision_table(self):
        return self._decision()[1]

    def _decision(self):
        key = (len(self.observations), len(self.hyps))
        if self._classes is None or self._classes[0] != key:
            rng = np.random.default_rng(list(key))  # not the learner's stream: a cache must not move it
            table = decision.decision_table(self.hyps, self.weights, self.judge, self.deploy, rng,
                                            top_k=self.config.final_top_k, limit=self.config.max_plans)
            self._classes = (key, decision.classes_of(table, len(self.hyps)), table)
        return self._classes[1], self._classes[2]

    def _scene_candidates(self) -> Iterator[Scene]:
        c = self.config
        if c.choose == "random" or c.scenes == "random":
            for _ in range(1 if c.choose == "random" else c.n_scenes):
                yield random_scene(self.rng)
            return
        likely = acquisition.particles(self.weights, mass=0.99, cap=64)
        w = self.weights[likely] / self.weights[likely].sum()
        drawn = []
        for _ in range(c.scene_candidates):
            z = self.hyps[likely[int(self.rng.choice(len(likely), p=w))]]
            need = self.needs.draw(self.rng) if c.scenes == "needs" and self.needs is not None else None
            for _ in range(20):
                scene = random_scene(self.rng)
                objects = tuple(scene.objects)
                if z.can_show(objects) and (need is None or not self.needs.fails(objects)[need]):  # type: ignore[union-attr]
                    break
            drawn.append(scene)
        mass = np.array([(1 - self.refuse(tuple(s.objects)))
                         * sum(w[j] for j, i in enumerate(likely) if self.hyps[i].can_show(tuple(s.objects)))
                         for s in drawn])
        keep = ranking.order(mass)[:c.n_scenes]  # most likely to be shown; ties to the first drawn
        yield from (drawn[i] for i in sorted(keep))

    def design_scene(self) -> Scene | None:
        best = None
        looked = []
        for scene in self._scene_candidates():
            scored = [] if self._looking() else None
            q = self._select(WorldState(positions=layout(scene, int(self.rng.integers(2**31)))), scored)
            if scored:
                looked.append((scene, scored[0]))
            if q is not None and (best is None or ranking.greater(q.gain, best[1].gain)):
                best = (scene, q)
        if looked:  # lookahead: the next query may come from any scene of this round
            pool = [t for _, sc in looked for t in sc.tables]
            self._look_pool = pool
            i, q = self._two_step([sc for _, sc in looked], pool)
            best = (looked[i][0], q)
        self.designed = best
        return best[0] if best else None

    def estimate(self, scene: Scene, state: WorldState) -> Estimate:
        scored = [] if self._looking() else None
        q = self._select(state, scored)  # the real layout: re-select for it
        if scored:  # lookahead: against this layout's queries and those of the round's design
            q = self._two_step(scored, scored[0].tables + self._look_pool)[1]
        top, w = self.top()[0]
        if q is None:
            plan = top.plan(state) or []
            plans_ = [plan] * self.sig.shows
            why = {"eig_nats": None, "note": "no candidate plan differs from doing nothing"}
        else:
            plans_ = q.plans
            why = {"eig_nats": None if np.isnan(q.gain) else round(q.gain, 4), "alternatives": q.alternatives,
                   "choose": self.config.choose, "belief_before": self._snapshot()}
        return Estimate(z=top.description, goals=[describe_plan(p) for p in plans_], plans=plans_,
                        done=w >= self.config.done_threshold, why=why)

    # ---- answers ----

    def _likelihood(self, obs, hyps, judge_) -> np.ndarray:
        feasible = judge_.feasible(obs.scene.objects)
        e = self.config.new_scene_error
        refuse = getattr(obs, "refuse", 0.0)
        if obs.answer.new_scene:  # with a needs belief that doubts the scene, it says less about z
            return needs_mod.p_new_scene(feasible, e, refuse)
        lik = self.sig.likelihood(obs.answer, obs.shown, judge_, self.model)
        return lik * needs_mod.p_answered(feasible, e, refuse)

    def observe(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        answer = record.answer
        if answer is None:
            return None
        texts = ([f"{k}: {describe_state(t.outcome)}" for k, t in zip("AB", trajectories, strict=False)]
                 if self.sig.shows > 1 else
                 [f"step {s.index + 1}: {describe_skill(s.skill)}" for t in trajectories for s in t.steps])
        obs = DecideObservation(record.scene, answer, list(trajectories), texts,
                                self.refuse(tuple(record.scene.objects)))
        self._look_pool = []  # the round is over: its queries are not the next round's
        lik = self._likelihood(obs, self.hyps, self.judge)
        before = self.weights
        shown = self.shown_mass(record.scene)
        evidence = self.belief.update(lik)
        if self.needs is not None:
            self.needs.update(tuple(record.scene.objects), answer.new_scene, shown)
        gain = record.estimate.why.get("eig_nats") if record.estimate is not None else None
        self.answer_log.append({
            "answer": answer.kind,
            "kl_bits": round(kl_bits(self.weights, before), 4),
            "gain_bits": None if gain is None else round(gain / math.log(2), 4),
            "shown_mass": round(shown, 4),
            "top": [(h.name, round(p, 4)) for h, p in self.top(3)],
            **({} if self.needs is None else {"refuse": round(obs.refuse, 4), "needs": self.needs.top(2)}),
        })
        self.observations.append(obs)
        surprised = not answer.new_scene and evidence < self.config.surprise * float(lik.max())
        proposed: list[str] = []
        if self.llm is not None and self.proposal_calls < self.config.max_proposal_calls and (
            surprised or len(self.observations) == 1
        ):
            proposed = self._propose()
        self.log.append({"round": record.index, "answer": answer.model_dump(mode="json"), "evidence": round(evidence, 6),
                         "surprised": surprised, "proposed": proposed, **self._snapshot()})
        n = self._rejuvenate()
        if self.log:
            self.log[-1]["neighbours_added"] = n
        if self.config.pool:
            pooled = self._from_pool()
            if self.log:
                self.log[-1]["pool_added"] = pooled
        return None

    def _from_pool(self) -> int:
        lik = self._likelihood(self.observations[-1], self.pool_judge.hyps, self.pool_judge)
        self.pool_log_post = self.pool_log_post + np.log(np.clip(lik, 1e-300, None))
        best = ranking.order(self.pool_log_post)[:self.config.pool]
        added = self._admit([self.pool.goals[i] for i in best])
        self.growth["pool"] += len(added)
        return len(added)

    def final_outcomes(self, state: WorldState, w: np.ndarray, feasible: np.ndarray) -> list:
        outs = super().final_outcomes(state, w, feasible)
        m = self.config.final_joint
        if m < 2:
            return outs
        likely = [self.hyps[i].goal for i in ranking.order(w, ranking.WEIGHT_DECIMALS)[:m] if w[i] > 0]
        planned = {repr(o.plan) for o in outs}
        for a, b in combinations(likely, 2):
            joint = Goal(tuple(dict.fromkeys(a.clauses + b.clauses)), a.stays or b.stays)
            plan = planner.plan(joint, state)
            if plan and repr(plan) not in planned:
                planned.add(repr(plan))
                outs.append(predict(state, plan))
        return outs


def decide_method(signal: str, name: str | None = None, keep: int = KEEP, description: str | None = None,
                  **settings) -> Method:
    """A registry entry: decide-<signal> with ``settings`` over DECIDE."""
    name = name or f"decide-{signal}"

    def build(ctx: LearnerContext) -> DecideLearner:
        config = DecideConfig(**ctx.settings.model_dump(), **{**DECIDE, **settings})
        learner = DecideLearner(signal, rng=ctx.learner_seed, llm=ctx.llm, config=config, keep=keep)
        learner.name = name
        return learner

    main = name == f"decide-{signal}"  # its ablations and variants are compared in their own README
    return Method(signal, False, build, description or f"experiment: the goal-language belief, scenes designed "
                  f"from it, {signal} queries by information about the decision", goal_language=True,
                  colour={"stop": "#d62728", "preference": "#ff9896"}[signal] if main else None,
                  compared_with=f"lang-{signal}" if main else None, settings=LangPriorSettings)


for _signal in ("stop", "preference"):
    if f"decide-{_signal}" not in METHODS:
        METHODS.register(f"decide-{_signal}", lambda s=_signal: decide_method(s))
