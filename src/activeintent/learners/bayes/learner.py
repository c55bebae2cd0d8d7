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
from dataclasses import dataclass, field

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator

from activeintent import ranking
from activeintent.goals.facts import facts
from activeintent.learners.base import Estimate, Learner, RoundRecord
from activeintent.learners.bayes.acquisition import Query, p_answered, p_new_scene, select_query
from activeintent.learners.bayes.belief import Belief, Prior
from activeintent.learners.bayes.candidates import candidate_plans, predict
from activeintent.learners.bayes.hypotheses import Hypothesis, hypothesis_space
from activeintent.learners.bayes.judge import HypothesisJudge
from activeintent.learners.bayes.proposals import propose_hypotheses
from activeintent.learners.bayes.scenes import SCENE_DESIGNS
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


class BayesSettings(BaseModel):
    """What a person running the Bayesian learners chooses (the rest of BayesConfig is fixed)."""

    model_config = ConfigDict(extra="forbid")

    prior: Prior = Field("length", description="P(z): length (description length, 2^-L(z)) | uniform (the ablation)")
    scenes: str = Field(
        "sampled", description="Scenes to ask in (SCENE_DESIGNS): sampled (n_scenes random ones) | belief (the "
        "n_scenes of scene_candidates random ones that the belief most expects to show its goals, also after a "
        "'new scene' answer) | a plug-in's")

    @field_validator("scenes")
    @classmethod
    def _known_design(cls, name: str) -> str:
        return SCENE_DESIGNS.check(name)


class BayesConfig(BayesSettings):
    """Settings of the Bayesian learners (none is tuned to particular intentions)."""

    choose: str = Field("eig", description="eig: largest expected information gain; random: the baseline")
    n_scenes: int = Field(4, ge=1, description="candidate scenes scored per design_scene")
    scene_candidates: int = Field(16, ge=1, description="scenes drawn per design_scene when scenes = belief")
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

    @property
    def redesigns_after_new_scene(self) -> bool:  # type: ignore[override]
        return SCENE_DESIGNS[self.config.scenes].after_new_scene

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

    def _select(self, state: WorldState) -> Query | None:
        c = self.config
        feasible = self.judge.feasible(tuple(state.positions))
        outs = candidate_plans(self.hyps, self.weights, state, self.rng, top_k=c.top_k, explore=c.explore,
                               prefixes=self.sig.shows > 1, limit=c.max_plans, feasible=feasible)
        feasible = self.judge.feasible(tuple(state.positions))  # the planner may have found some z infeasible
        return select_query(self.sig, self.model, self.judge, self.weights, feasible, outs,
                            c.new_scene_error, self.rng, choose=c.choose)

    def shown_mass(self, scene: Scene) -> float:
        """Σ_z w_z 1[z can be shown in ``scene``]: the belief's chance that the user answers
        about the trajectories rather than "new scene"."""
        return float(self.weights @ self.judge.feasible(tuple(scene.objects)))

    def design_scene(self) -> Scene | None:
        """The candidate scene (3–5 objects, from the learner's own rng) whose best query has
        the largest information gain; the candidates come from the ``scenes`` strategy."""
        best: tuple[Scene, Query] | None = None
        for scene in SCENE_DESIGNS[self.config.scenes].candidates(self):
            q = self._select(WorldState(positions=layout(scene, int(self.rng.integers(2**31)))))
            if q is not None and (best is None or ranking.greater(q.gain, best[1].gain)):
                best = (scene, q)
        self.designed = best
        return best[0] if best else None

    def estimate(self, scene: Scene, state: WorldState) -> Estimate:
        q = self._select(state)  # the real layout: re-select for it
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
        if obs.answer.new_scene:
            return p_new_scene(feasible, e)
        lik = self.sig.likelihood(obs.answer, obs.shown, judge_, self.model)
        return lik * p_answered(feasible, e)

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
        obs = Observation(record.scene, answer, list(trajectories), texts)
        lik = self._likelihood(obs, self.hyps, self.judge)
        before = self.weights
        shown = self.shown_mass(record.scene)
        evidence = self.belief.update(lik)
        gain = record.estimate.why.get("eig_nats") if record.estimate is not None else None
        self.answer_log.append({
            "answer": answer.kind,
            "kl_bits": round(kl_bits(self.weights, before), 4),  # what this answer taught: KL(w' ‖ w)
            "gain_bits": None if gain is None else round(gain / math.log(2), 4),  # what the query promised
            "shown_mass": round(shown, 4),  # the belief's P(the scene can show z) before the answer
            "top": [(h.name, round(p, 4)) for h, p in self.top(3)],
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
