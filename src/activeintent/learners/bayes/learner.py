"""Bayesian active learners: an explicit belief over z, queries chosen by information gain.

One learner for every signal plug-in (``bayes-preference``, ``bayes-stop``, ``bayes-<your
signal>``), built APReL-style from separate parts:

- belief.py — w_z over the hypothesis space H, prior from description length (or uniform);
- the signal's observation model P(h | z) (``activeintent.signals``), with the learner's own
  assumed parameters, never the user's;
- candidates.py — the planner: plans of likely hypotheses, predicted on the symbolic env;
- acquisition.py — the query (scene, plans) with the largest expected information gain;
- proposals.py — new hypotheses from a language model, scored on every past answer.

The final answer is the plan with the largest expected success under the belief; z is the
description of the most probable hypothesis.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from pydantic import BaseModel, Field

from activeintent import ranking
from activeintent.goals.facts import facts
from activeintent.learners.base import Estimate, Learner, RoundRecord
from activeintent.learners.bayes.acquisition import (
    Query,
    Scored,
    look_particles,
    particles,
    select_query,
    stack_tables,
    two_step,
)
from activeintent.learners.bayes.belief import Belief, Prior
from activeintent.learners.bayes.candidates import (
    candidate_plans,
    chained_plans,
    predict,
    split_plans,
)
from activeintent.learners.bayes.decision import (
    DecisionTable,
    classes_of,
    decision_table,
    deployment_states,
)
from activeintent.learners.bayes.hypotheses import Hypothesis, hypothesis_space, random_scene
from activeintent.learners.bayes.judge import HypothesisJudge
from activeintent.learners.bayes.needs import Needs, p_answered, p_new_scene
from activeintent.llm.base import ChatModel, ModelError
from activeintent.signals import Answer, Signal, get_signal
from activeintent.world import (
    Scene,
    WorldState,
    describe_plan,
    describe_skill,
    describe_state,
    layout,
)
from activeintent.world.trajectory import Trajectory


def kl_bits(after: np.ndarray, before: np.ndarray) -> float:
    """KL(after ‖ before) in bits: the information one answer gave the belief."""
    m = after > 0
    return float((after[m] * np.log2(after[m] / np.clip(before[m], 1e-300, None))).sum())


class BayesConfig(BaseModel):
    """Settings of the Bayesian learners (none is tuned to particular intentions)."""

    prior: Prior = Field("length", description="length: P(z) ∝ 2^-L(z); uniform: the ablation")
    choose: str = Field("eig", description="eig: largest expected information gain; random: the baseline")
    n_scenes: int = Field(4, ge=1, description="candidate scenes scored per design_scene")
    scenes: Literal["random", "belief", "needs"] = Field(
        "random", description="random: n_scenes random scenes; belief: the n_scenes of scene_candidates random "
        "ones that the belief most expects to show its goals, also after a 'new scene' answer; needs: as belief, "
        "each candidate drawn to also meet a requirement drawn from the needs belief")
    scene_candidates: int = Field(16, ge=1, description="scenes drawn per design_scene when scenes = belief")
    gain: Literal["goal", "shown", "decision", "shown-decision", "value"] = Field(
        "goal", description="goal: EIG about z, the 'new scene' answer included; shown: only what the "
        "answers to the shown trajectories tell (the feasibility part of the EIG left out); decision: "
        "information about which plans to run on scenes of the public test distribution (decision.py); "
        "shown-decision: only what the answers to the shown trajectories tell about that; value: the expected "
        "success of the final answer on those scenes after the answer (decision.decision_value)")
    deploy_scenes: int = Field(8, ge=1, description="gain = decision: the learner's own scenes of the test distribution")
    needs: bool = Field(False, description="also learn what the intention needs of a scene's objects from "
                        "'new scene' answers (needs.py)")
    needs_counts: bool = Field(False, description="the needs belief also has literals counting the blocks a "
                               "selector of the goal language picks ('at least two cool blocks', needs.py)")
    chains: int = Field(0, ge=0, description="stop queries: also offer plans of one of this many likely z "
                        "followed by another's (candidates.chained_plans); 0: none")
    split: int = Field(0, ge=0, description="stop queries: also offer this many plans grown step by step so "
                       "that each step moves away from about half of the likely z left (candidates.split_plans); 0: none")
    lookahead: int = Field(1, ge=1, le=2, description="1: the query whose answer tells most; 2: the one whose "
                           "answer and the best next query's tell most together (acquisition.two_step)")
    top_k: int = Field(16, ge=1, description="plans come from this many most probable hypotheses")
    explore: int = Field(6, ge=0, description="... plus this many random other hypotheses")
    max_plans: int = Field(36, ge=2, description="candidate plans per scene")
    final_top_k: int = Field(10, ge=1, description="the final answer picks among the plans of this many likely z")
    done_threshold: float = Field(0.95, gt=0, le=1, description="says 'done' when top z holds this much belief")
    new_scene_error: float = Field(0.1, gt=0, lt=0.5, description="assumed P(a person's new-scene answer is wrong)")
    surprise: float = Field(0.1, gt=0, lt=1, description="P(h) / max_z P(h|z) below this: ask the model for new z")
    proposal_mass: float = Field(0.05, gt=0, lt=1, description="prior mass given to model-proposed hypotheses")
    max_proposal_calls: int = Field(3, ge=0, description="model calls for new hypotheses per episode")
    hypothesis_seed: int = Field(0, description="seed of the bank that deduplicates H")


@dataclass
class Observation:
    """One answered round, kept so that hypotheses added later can be scored on it."""

    scene: Scene
    answer: Answer
    shown: list[Trajectory]
    texts: list[str] = field(default_factory=list)  # what was shown, in words (for proposals)
    refuse: float = 0.0  # q(s) when answered: the needs belief's P(the scene lacks what is needed)

    @property
    def finals(self):
        return [facts(t.outcome) for t in self.shown]


class BayesLearner(Learner):
    """The Bayesian active learner for any registered signal."""

    def __init__(
        self,
        signal: Signal | str,
        rng: np.random.Generator | int | None = None,
        llm: ChatModel | None = None,
        config: BayesConfig | None = None,
        hypotheses: tuple[Hypothesis, ...] | None = None,
    ):
        self.sig = get_signal(signal) if isinstance(signal, str) else signal
        self.signal = self.sig.name
        self.name = f"bayes-{self.signal}"
        self.model = self.sig.learner_model()  # what the learner assumes of people
        self.rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng or 0)
        self.config = config or BayesConfig()
        self.llm = llm
        self.belief = Belief(tuple(hypotheses or hypothesis_space(self.config.hypothesis_seed)), self.config.prior)
        self.judge = HypothesisJudge(self.belief.hyps)
        self.observations: list[Observation] = []
        self.designed: tuple[Scene, Query] | None = None
        self.proposal_calls = 0
        self.proposal_errors: list[str] = []
        self.log: list[dict] = []
        self.answer_log: list[dict] = []  # diagnostics(): one entry per answer
        self.prior_entropy = self.belief.entropy_bits()
        self._drained = 0
        self._classes: tuple[tuple[int, int], np.ndarray, DecisionTable] | None = None
        self._look_pool: list[np.ndarray] = []  # this round's query tables (lookahead; cleared at each answer)
        self.needs = Needs(self.config.new_scene_error, self.config.needs_counts) if self.config.needs else None
        self.deploy = (deployment_states(int(self.rng.integers(2**31)), self.config.deploy_scenes)
                       if self._deciding() else [])

    @property
    def redesigns_after_new_scene(self) -> bool:  # type: ignore[override]
        return self.config.scenes != "random"

    # ---- belief views ----

    @property
    def hyps(self) -> tuple[Hypothesis, ...]:
        return self.belief.hyps

    @property
    def weights(self) -> np.ndarray:
        return self.belief.weights

    def top(self, n: int = 1) -> list[tuple[Hypothesis, float]]:
        return self.belief.top(n)

    def _snapshot(self) -> dict:
        return {"top": [(h.description, round(p, 4)) for h, p in self.top(3)],
                "entropy_bits": round(self.belief.entropy_bits(), 3)}

    def stats(self) -> dict:
        return {
            "hypotheses": len(self.hyps),
            "prior": self.config.prior,
            "prior_entropy_bits": round(self.prior_entropy, 3),
            "posterior_entropy_bits": round(self.belief.entropy_bits(), 3),
            "top": [(h.name, round(p, 4)) for h, p in self.top(3)],
            "proposal_calls": self.proposal_calls,
            "proposal_errors": self.proposal_errors,
            "proposed_kept": sum(len(e.get("proposed", [])) for e in self.log),
        }

    def diagnostics(self) -> dict:
        return {"answers": list(self.answer_log)}

    def drain_transcript(self) -> list[dict]:
        out = [dict(entry, template="belief") for entry in self.log[self._drained:]]
        self._drained = len(self.log)
        return out

    # ---- queries ----

    def _select(self, state: WorldState, scored: list[Scored] | None = None) -> Query | None:
        c = self.config
        feasible = self.judge.feasible(tuple(state.positions))
        outs = candidate_plans(self.hyps, self.weights, state, self.rng, top_k=c.top_k, explore=c.explore,
                               prefixes=self.sig.shows > 1, limit=c.max_plans, feasible=feasible)
        feasible = self.judge.feasible(tuple(state.positions))  # the planner may have found some z infeasible
        if c.chains and self.sig.shows == 1:
            outs += chained_plans(self.hyps, self.weights, state, feasible, first=c.chains,
                                  seen={o.key for o in outs})
            feasible = self.judge.feasible(tuple(state.positions))
        if c.split and self.sig.shows == 1:
            outs += split_plans(self.hyps, self.weights, state, feasible, self.judge,
                                particles(self.weights, mass=0.99, cap=256), starts=c.split,
                                seen={o.key for o in outs},
                                classes=self.decision_classes() if self._deciding() else None)
            feasible = self.judge.feasible(tuple(state.positions))
        return select_query(self.sig, self.model, self.judge, self.weights, feasible, outs,
                            c.new_scene_error, self.rng, choose=c.choose, gain=c.gain,
                            classes=self.decision_classes() if self._deciding() else None,
                            refuse=self.refuse(tuple(state.positions)), scored=scored,
                            table=self.decision_table() if c.gain == "value" else None)

    def _looking(self) -> bool:
        return self.config.lookahead == 2 and self.config.choose == "eig"

    def _two_step(self, scored: list[Scored], pool: list[np.ndarray]) -> tuple[int, Query]:
        """The two-step lookahead's choice among ``scored`` against the query ``pool`` (acquisition.two_step)."""
        look = look_particles(self.weights)
        classes = self.decision_classes()[look] if self._deciding() else np.arange(len(look))
        i, j, value = two_step(scored, stack_tables(pool), self.weights[look], classes)
        sc = scored[i]
        alternatives = [{"plans": [describe_plan(sc.outs[k].plan) for k in sc.combos[j]], "lookahead_nats": round(value, 4),
                         "note": "chosen by the two-step value; eig_nats is its one-step gain"}]
        return i, Query([sc.outs[k] for k in sc.combos[j]], float(sc.gains[j]), alternatives)

    def refuse(self, objects: tuple[str, ...]) -> float:
        """q(s): P(the scene lacks what the intention needs) under the needs belief (0 without one)."""
        return 0.0 if self.needs is None else self.needs.refuse(objects)

    def _deciding(self) -> bool:
        return self.config.gain.endswith("decision") or self.config.gain == "value"

    def decision_classes(self) -> np.ndarray:
        """z grouped by the plans that satisfy them on the learner's deployment scenes (once per
        belief: the answers so far and the size of H key it)."""
        return self._decision()[0]

    def decision_table(self) -> DecisionTable:
        """Which candidate plans satisfy each z on the learner's deployment scenes (decision.py)."""
        return self._decision()[1]

    def _decision(self) -> tuple[np.ndarray, DecisionTable]:
        key = (len(self.observations), len(self.hyps))
        if self._classes is None or self._classes[0] != key:
            rng = np.random.default_rng(list(key))  # not the learner's stream: a cache must not move it
            table = decision_table(self.hyps, self.weights, self.judge, self.deploy, rng,
                                   top_k=self.config.final_top_k, limit=self.config.max_plans)
            self._classes = (key, classes_of(table, len(self.hyps)), table)
        return self._classes[1], self._classes[2]

    def shown_mass(self, scene: Scene) -> float:
        """Σ_z w_z 1[z can be shown in ``scene``]: the belief's chance that the user answers
        about the trajectories rather than "new scene"."""
        return float(self.weights @ self.judge.feasible(tuple(scene.objects)))

    def _scene_candidates(self) -> Iterator[Scene]:
        """Lazily: with random scenes each draw is followed by its layout's, in the learner's stream.
        ``scenes = belief``: each candidate is a random scene that can show a z drawn from the
        belief (up to 20 draws); kept are the n_scenes that can show the most of the likely z
        (those holding 99 % of the belief, at most 64)."""
        c = self.config
        if c.choose == "random" or c.scenes == "random":
            for _ in range(1 if c.choose == "random" else c.n_scenes):
                yield random_scene(self.rng)
            return
        likely = particles(self.weights, mass=0.99, cap=64)
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
        """The candidate scene (3–5 objects, from the learner's own rng) whose best query has
        the largest information gain (``scenes = belief``: among those the belief most expects
        to be able to show its goals)."""
        best: tuple[Scene, Query] | None = None
        looked: list[tuple[Scene, Scored]] = []
        for scene in self._scene_candidates():
            scored: list[Scored] | None = [] if self._looking() else None
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
        scored: list[Scored] | None = [] if self._looking() else None
        q = self._select(state, scored)  # the real layout: re-select for it
        if scored:  # lookahead: against this layout's queries and those of the round's design
            q = self._two_step(scored, scored[0].tables + self._look_pool)[1]
        top, w = self.top()[0]
        if q is None:
            plan = top.plan(state) or []
            plans = [plan] * self.sig.shows
            why = {"eig_nats": None, "note": "no candidate plan differs from doing nothing"}
        else:
            plans = q.plans
            why = {"eig_nats": None if np.isnan(q.gain) else round(q.gain, 4), "alternatives": q.alternatives,
                   "choose": self.config.choose, "belief_before": self._snapshot()}
        return Estimate(z=top.description, goals=[describe_plan(p) for p in plans], plans=plans,
                        done=w >= self.config.done_threshold, why=why)

    # ---- answers ----

    def _likelihood(self, obs: Observation, hyps: tuple[Hypothesis, ...], judge_) -> np.ndarray:
        feasible = judge_.feasible(obs.scene.objects)
        e = self.config.new_scene_error
        if obs.answer.new_scene:  # with a needs belief that doubts the scene, it says less about z
            return p_new_scene(feasible, e, obs.refuse)
        lik = self.sig.likelihood(obs.answer, obs.shown, judge_, self.model)
        return lik * p_answered(feasible, e, obs.refuse)

    def _log_lik(self, judge: HypothesisJudge) -> np.ndarray:
        """Σ_k log P(h_k | z) over every answer so far, for the hypotheses ``judge`` judges
        (hypotheses that join the belief later are scored on the whole history)."""
        total = np.zeros(judge.size)
        for obs in self.observations:
            total += np.log(np.clip(self._likelihood(obs, judge.hyps, judge), 1e-300, None))
        return total

    def observe(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        answer = record.answer
        if answer is None:
            return None
        texts = ([f"{k}: {describe_state(t.outcome)}" for k, t in zip("AB", trajectories, strict=False)]
                 if self.sig.shows > 1 else
                 [f"step {s.index + 1}: {describe_skill(s.skill)}" for t in trajectories for s in t.steps])
        obs = Observation(record.scene, answer, list(trajectories), texts, self.refuse(tuple(record.scene.objects)))
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
            "kl_bits": round(kl_bits(self.weights, before), 4),  # what this answer taught: KL(w' ‖ w)
            "gain_bits": None if gain is None else round(gain / math.log(2), 4),  # what the query promised
            "shown_mass": round(shown, 4),  # the belief's P(the scene can show z) before the answer
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
        return None

    def final(self, scene: Scene, state: WorldState) -> Estimate:
        """The plan with the largest expected success Σ_z w_z 1[z satisfied by its outcome],
        among the plans of the hypotheses that can be shown in this scene."""
        w, feasible = self.scene_weights(scene)
        outs = self.final_outcomes(state, w, feasible)
        success = self.expected_success(w, outs)
        best = ranking.best_plan(success, [len(o.plan) for o in outs])
        top = self.hyps[ranking.argmax(w, ranking.WEIGHT_DECIMALS)]
        plan = outs[best].plan
        return Estimate(z=top.description, goals=[describe_plan(plan)], plans=[plan], done=True,
                        why={"expected_success": round(float(success[best]), 4)})

    def scene_weights(self, scene: Scene) -> tuple[np.ndarray, np.ndarray]:
        """w_z given that z can be shown in this scene (the belief itself when none can), and
        the feasibility mask."""
        feasible = self.judge.feasible(scene.objects)
        w = self.weights * feasible
        return (w / w.sum() if w.sum() > 0 else self.weights), feasible

    def expected_success(self, w: np.ndarray, outs: list) -> np.ndarray:
        """Σ_z w_z 1[z holds after the plan], per predicted outcome."""
        finals = [facts(o.traj.outcome) for o in outs]
        self.judge.prefetch(finals)
        return np.array([float(w @ self.judge.judge(f)[0]) for f in finals])

    def final_outcomes(self, state: WorldState, w: np.ndarray, feasible: np.ndarray) -> list:
        """What the final answer chooses among: doing nothing and the likely z's plans."""
        return [predict(state, [])] + candidate_plans(
            self.hyps, w, state, self.rng, top_k=self.config.final_top_k, explore=0,
            prefixes=False, limit=self.config.max_plans, feasible=feasible)

    # ---- open-ended hypotheses ----

    def _propose(self) -> list[str]:
        from activeintent.learners.bayes.proposals import propose_hypotheses

        self.proposal_calls += 1
        try:
            new = propose_hypotheses(self.llm, self.top(5), self.observations)  # type: ignore[arg-type]
        except ModelError as err:
            self.proposal_errors.append(str(err)[:300])
            return []
        names = {h.name for h in self.hyps}
        new = [h for h in new if h.name not in names]
        if not new:
            return []
        log_lik = self._log_lik(HypothesisJudge(tuple(new)))
        self.belief.add(new, self.config.proposal_mass, log_lik)
        self.judge = HypothesisJudge(self.belief.hyps)
        return [h.description for h in new]


class ZeroSignalLearner(BayesLearner):
    """Baseline ``zero-signal``: the prior's best guess; it never asks anything."""

    asks = False

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.name = "zero-signal"


class RandomQueryLearner(BayesLearner):
    """Baseline ``random-query``: the same belief and update, queries picked at random."""

    def __init__(self, signal, rng=None, llm=None, config: BayesConfig | None = None, hypotheses=None):
        config = (config or BayesConfig()).model_copy(update={"choose": "random"})
        super().__init__(signal, rng, llm, config, hypotheses)
        self.name = "random-query" if self.signal == "stop" else f"random-query-{self.signal}"  # the CLI names
