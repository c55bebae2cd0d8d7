"""Bayesian active learners: an explicit belief over z, queries chosen by information gain.

``bayes-preference`` shows two plans y^a, y^b per round; ``bayes-stop`` shows one plan y and
reads the stop time h. Both keep a posterior over the hypothesis space H (hypotheses.py),
update it with the likelihood of the user's answer on the *executed* trajectories (the real
outcome, failed steps included), and pick the next (scene, plans) by expected information
gain on the symbolic world model. The final answer is the plan with the largest expected
success under the belief; z is the description of the most probable hypothesis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from pydantic import BaseModel, Field

from activeintent.learners.base import Estimate, Learner, RoundRecord
from activeintent.learners.bayes.facts import Facts, facts
from activeintent.learners.bayes.hypotheses import (
    Hypothesis,
    hypothesis_space,
    log_prior,
    random_scene,
)
from activeintent.learners.bayes.likelihood import (
    PreferenceModel,
    StopModel,
    preference_likelihood,
    stop_likelihood,
    utility,
)
from activeintent.learners.bayes.query import (
    NEW_SCENE_LAPSE,
    Outcome,
    Query,
    best_preference_query,
    best_stop_query,
    candidate_plans,
    first_away,
    judge,
    predict,
    scene_state,
    similarity,
)
from activeintent.llm.base import ChatModel
from activeintent.signals import PreferenceFeedback, StopFeedback
from activeintent.sim.trajectory import Trajectory
from activeintent.world import Scene, WorldState, describe_plan, describe_skill, describe_state


class BayesConfig(BaseModel):
    """Settings of the Bayesian learners (none is tuned to particular intentions)."""

    n_scenes: int = Field(4, ge=1, description="candidate scenes scored per design_scene")
    top_k: int = Field(16, ge=1, description="plans come from this many most probable hypotheses")
    explore: int = Field(6, ge=0, description="... plus this many random other hypotheses")
    max_plans: int = Field(36, ge=2, description="candidate plans per scene")
    done_threshold: float = Field(0.95, gt=0, le=1, description="stop early when top z holds this much belief")
    preference: PreferenceModel = Field(default_factory=PreferenceModel)
    stop: StopModel = Field(default_factory=StopModel)
    collapse_ratio: float = Field(
        3.0, gt=1, description="belief collapse: no hypothesis explains h better than this × the lapse floor"
    )
    proposal_mass: float = Field(0.05, gt=0, lt=1, description="prior mass given to model-proposed hypotheses")
    max_proposal_calls: int = Field(3, ge=0, description="model calls for new hypotheses per episode")
    hypothesis_seed: int = Field(0, description="seed of the bank that deduplicates H")


@dataclass
class Observation:
    """One answered round, kept so that hypotheses added later can be scored on it."""

    kind: str
    scene: Scene
    feedback: PreferenceFeedback | StopFeedback
    finals: list[Facts]
    similarity: float = 0.0
    steps: list[tuple[Facts, Facts, str, bool]] | None = None
    reveal: np.ndarray | None = None
    start: np.ndarray | None = None
    duration: float = 0.0
    texts: list[str] = field(default_factory=list)  # what was shown, in words (for proposals)
    log_evidence: float = 0.0  # log Σ_z w_z P(h | z) when it was observed (the normaliser)


def _final_state(traj: Trajectory) -> WorldState:
    if traj.final_state is not None:
        return traj.final_state
    if traj.steps:
        return traj.steps[-1].state_after
    if traj.n_ticks:
        return traj.state_at(traj.duration)
    if traj.initial_state is not None:
        return traj.initial_state
    raise ValueError("trajectory without any state")


class BayesLearner(Learner):
    """Shared belief, update and final answer; subclasses choose and read the signal."""

    name = "bayes"

    def __init__(
        self,
        rng: np.random.Generator | int | None = None,
        llm: ChatModel | None = None,
        config: BayesConfig | None = None,
        hypotheses: tuple[Hypothesis, ...] | None = None,
    ):
        self.rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng or 0)
        self.config = config or BayesConfig()
        self.llm = llm
        self.hyps: tuple[Hypothesis, ...] = tuple(hypotheses or hypothesis_space(self.config.hypothesis_seed))
        self.log_w = log_prior(self.hyps)
        self.observations: list[Observation] = []
        self.designed: tuple[Scene, Query] | None = None
        self.collapses = 0
        self.proposal_calls = 0
        self.log: list[dict] = []  # per round: top hypotheses, gain, collapse, proposals
        self.prior_entropy = self.entropy_bits()
        self._drained = 0

    # ---- belief ----

    @property
    def weights(self) -> np.ndarray:
        return np.exp(self.log_w - np.logaddexp.reduce(self.log_w))

    def top(self, n: int = 1) -> list[tuple[Hypothesis, float]]:
        w = self.weights
        return [(self.hyps[i], float(w[i])) for i in np.argsort(-w, kind="stable")[:n]]

    def stats(self) -> dict:
        """Information gained: prior minus posterior entropy of the belief, per signal given."""
        signals = sum(1 for entry in self.log if not entry.get("new_scene"))
        gained = self.prior_entropy - self.entropy_bits()
        return {
            "hypotheses": len(self.hyps),
            "prior_entropy_bits": round(self.prior_entropy, 3),
            "posterior_entropy_bits": round(self.entropy_bits(), 3),
            "bits_per_signal": round(gained / signals, 3) if signals else None,
            "top": [(h.name, round(p, 4)) for h, p in self.top(3)],
            "collapses": self.collapses,
        }

    def drain_transcript(self) -> list[dict]:
        """The belief after each update (top hypotheses, entropy), for rounds.jsonl."""
        out = [dict(entry, template="belief") for entry in self.log[self._drained:]]
        self._drained = len(self.log)
        return out

    def entropy_bits(self) -> float:
        w = self.weights
        return float(-(w * np.log2(np.clip(w, 1e-300, None))).sum())

    def update(self, likelihood: np.ndarray) -> None:
        """Bayes' rule: w_z ← w_z · P(h | z) (in logs)."""
        self.log_w = self.log_w + np.log(np.clip(likelihood, 1e-300, None))
        self.log_w -= np.logaddexp.reduce(self.log_w)

    def add_hypotheses(self, new: list[Hypothesis]) -> None:
        """Add hypotheses with ``proposal_mass`` of prior, scored on every past observation."""
        if not new:
            return
        new = [h for h in new if h.name not in {g.name for g in self.hyps}]
        if not new:
            return
        old = len(self.hyps)
        self.hyps = self.hyps + tuple(new)
        each = math.log(self.config.proposal_mass / len(new))
        log_new = np.full(len(new), each)
        sub = tuple(new)
        for obs in self.observations:
            log_new += np.log(np.clip(self._likelihood(obs, sub), 1e-300, None))
        # Past evidence for the old hypotheses is already in log_w (normalised); rescale it
        # to the prior mass it had.
        base = self.log_w[:old] + math.log(1 - self.config.proposal_mass)
        # The old posterior is P(z | h) = P(h | z) P(z) / P(h): multiply back the evidence.
        log_ev = sum(o.log_evidence for o in self.observations)
        self.log_w = np.concatenate([base + log_ev, log_new])
        self.log_w -= np.logaddexp.reduce(self.log_w)

    # ---- likelihood of one observation under a set of hypotheses ----

    def _likelihood(self, obs: Observation, hyps: tuple[Hypothesis, ...]) -> np.ndarray:
        fb = obs.feedback
        feasible = np.array([h.feasible(obs.scene) for h in hyps])
        if (isinstance(fb, PreferenceFeedback) and fb.choice == "new_scene") or (
            isinstance(fb, StopFeedback) and fb.new_scene
        ):
            return np.where(feasible, NEW_SCENE_LAPSE, 1 - NEW_SCENE_LAPSE)
        for h in hyps:
            h.prefetch([*obs.finals, *(s for st in obs.steps or [] for s in st[:2])])
        if isinstance(fb, PreferenceFeedback):
            ua = utility(*judge(hyps, obs.finals[0])[::-1])
            ub = utility(*judge(hyps, obs.finals[1])[::-1])
            lik = preference_likelihood(fb.choice, ua, ub, obs.similarity, self.config.preference)
        else:
            away = first_away(hyps, obs.steps or [])
            lik = stop_likelihood(
                fb.stop_time, away, obs.reveal, obs.start, obs.duration, self.config.stop
            )
        return lik * np.where(feasible, 1 - NEW_SCENE_LAPSE, NEW_SCENE_LAPSE)

    def _floor(self, obs: Observation) -> float:
        """The likelihood a hypothesis gets from the lapse alone (to detect a collapse)."""
        if obs.kind == "preference":
            return self.config.preference.lapse / 3
        m = self.config.stop
        if obs.feedback.stop_time is None:  # type: ignore[union-attr]
            return min(m.missed_stop, m.false_stop) + m.lapse / 2
        span = max(obs.duration, 1e-3) + m.delay_mean + 3 * m.delay_sd
        return (m.false_stop + m.lapse / 2) / span

    # ---- Learner API ----

    def design_scene(self, rng: np.random.Generator) -> Scene | None:
        """The candidate scene (3–5 objects, sampled from the learner's rng) whose best query
        has the largest information gain."""
        best: tuple[Scene, Query] | None = None
        for _ in range(self.config.n_scenes):
            scene = random_scene(self.rng)
            state = scene_state(scene, int(self.rng.integers(2**31)))
            q = self._select(state)
            if q is not None and (best is None or q.gain > best[1].gain):
                best = (scene, q)
        self.designed = best
        return best[0] if best else None

    def estimate(self, scene: Scene, state: WorldState) -> Estimate:
        q = self._select(state)  # the real layout: re-select for it
        top, w = self.top()[0]
        if q is None:
            plan = top.plan(state) or []
            q = Query([plan] * self.n_goals, 0.0)
        return Estimate(
            preference=top.description,
            goals=[describe_plan(p) for p in q.plans],
            plans=q.plans,
            done=w >= self.config.done_threshold,
        )

    def observe(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        fb = record.feedback
        if fb is None:
            return None
        obs = self._observation(record.scene, fb, trajectories)
        lik = self._likelihood(obs, self.hyps)
        w = self.weights
        evidence = float(w @ lik)
        obs.log_evidence = math.log(max(evidence, 1e-300))
        collapsed = bool(lik.max() <= self.config.collapse_ratio * self._floor(obs)) and not (
            isinstance(fb, PreferenceFeedback) and fb.choice == "new_scene"
        )
        self.observations.append(obs)
        self.update(lik)
        proposed: list[str] = []
        if collapsed:
            self.collapses += 1
        if self.llm is not None and self.proposal_calls < self.config.max_proposal_calls and (
            collapsed or len(self.observations) == 1
        ):
            proposed = self._propose()
        self.log.append(
            {
                "round": record.index,
                "new_scene": (isinstance(fb, PreferenceFeedback) and fb.choice == "new_scene")
                or bool(getattr(fb, "new_scene", False)),
                "evidence": evidence,
                "collapsed": collapsed,
                "proposed": proposed,
                "top": [(h.name, round(p, 4)) for h, p in self.top(3)],
                "entropy_bits": round(self.entropy_bits(), 3),
            }
        )
        return None

    def final(self, scene: Scene, state: WorldState) -> Estimate:
        """The plan with the largest expected success Σ_z w_z 1[z satisfied by its outcome],
        among the plans of the hypotheses that can be shown in this scene."""
        feasible = np.array([h.feasible(scene) for h in self.hyps])
        w = self.weights * feasible
        if w.sum() <= 0:
            w = self.weights
        w = w / w.sum()
        outs = [predict(state, [])] + candidate_plans(
            self.hyps, w, state, self.rng, top_k=2 * self.config.top_k, explore=0,
            prefixes=False, limit=3 * self.config.max_plans,
        )
        plans = [o.plan for o in outs]
        for h in self.hyps:
            h.prefetch([o.final for o in outs])
        success = np.array([float(w @ judge(self.hyps, o.final)[0]) for o in outs])
        best = int(np.argmax(success - 1e-6 * np.array([len(p) for p in plans])))
        top = self.hyps[int(np.argmax(w))]
        return Estimate(
            preference=top.description,
            goals=[describe_plan(plans[best])],
            plans=[plans[best]],
            done=True,
        )

    # ---- subclass hooks ----

    n_goals = 1

    def _select(self, state: WorldState) -> Query | None:
        raise NotImplementedError

    def _observation(self, scene: Scene, fb, trajectories: list[Trajectory]) -> Observation:
        raise NotImplementedError

    def _candidates(self, state: WorldState, prefixes: bool) -> list[Outcome]:
        return candidate_plans(
            self.hyps, self.weights, state, self.rng, top_k=self.config.top_k,
            explore=self.config.explore, prefixes=prefixes, limit=self.config.max_plans,
        )

    # ---- open-ended hypotheses ----

    def _propose(self) -> list[str]:
        from activeintent.learners.bayes.proposals import propose_hypotheses

        self.proposal_calls += 1
        new = propose_hypotheses(self.llm, self.top(5), self.observations)  # type: ignore[arg-type]
        self.add_hypotheses(new)
        return [h.description for h in new]


class BayesPreferenceLearner(BayesLearner):
    """bayes-preference: two plans per round, the answer A / B / can't choose."""

    name = "bayes-preference"
    signal = "preference"
    n_goals = 2

    def _select(self, state: WorldState) -> Query | None:
        plans = self._candidates(state, prefixes=True)
        return best_preference_query(self.hyps, self.weights, state, plans, self.config.preference)

    def _observation(self, scene, fb, trajectories):
        if not isinstance(fb, PreferenceFeedback):
            raise TypeError(f"bayes-preference reads preference answers, got {type(fb).__name__}")
        if fb.choice == "new_scene":
            return Observation("preference", scene, fb, [])
        if len(trajectories) != 2:
            raise ValueError(f"a preference round has two trajectories τ^a, τ^b; got {len(trajectories)}")
        finals = [_final_state(t) for t in trajectories]
        common = [b for b in finals[0].blocks if b in finals[1].positions]
        pos = np.stack([[s.pos(b) for b in common] for s in finals])
        sim = float(similarity(pos)[0, 1]) if common else 0.0
        texts = [f"{k}: {describe_state(s)}" for k, s in zip("AB", finals, strict=True)]
        return Observation("preference", scene, fb, [facts(s) for s in finals], similarity=sim, texts=texts)


class BayesStopLearner(BayesLearner):
    """bayes-stop: one plan per round, the answer a stop time (or none)."""

    name = "bayes-stop"
    signal = "stop"
    n_goals = 1

    def _select(self, state: WorldState) -> Query | None:
        plans = self._candidates(state, prefixes=False)
        return best_stop_query(self.hyps, self.weights, state, plans, self.config.stop)

    def _observation(self, scene, fb, trajectories):
        if not isinstance(fb, StopFeedback):
            raise TypeError(f"bayes-stop reads stop answers, got {type(fb).__name__}")
        if fb.new_scene:
            return Observation("stop", scene, fb, [])
        if len(trajectories) != 1:
            raise ValueError(f"a stop round has one trajectory τ; got {len(trajectories)}")
        traj = trajectories[0]
        steps = [
            (facts(s.state_before), facts(s.state_after), s.skill.block, s.ok) for s in traj.steps
        ]
        return Observation(
            "stop",
            scene,
            fb,
            [facts(_final_state(traj))],
            steps=steps,
            reveal=np.array([traj.time_of(s.reveal_tick) for s in traj.steps]),
            start=np.array([traj.time_of(s.start_tick) for s in traj.steps]),
            duration=traj.duration,
            texts=[f"step {s.index + 1}: {describe_skill(s.skill)}" for s in traj.steps],
        )
