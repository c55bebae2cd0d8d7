"""``hybrid-<signal>``: the goal-language belief with a reward-feature component (soft goals).

Two model classes of what the person wants, equally likely before any answer (no reason to
prefer either): M_L, a goal z of the language (``lang-<signal>``'s growing belief, prior
2^-L(z)), and M_R, a linear reward r(s) = w · φ(s) over the general state features
(``reward-<signal>``'s particle belief). Both read every answer h_k; each keeps its marginal
likelihood P(h_1..k | M) (the language belief's normaliser; the reward particles' sequential
estimate Π_k Σ_m w_m P(h_k | w_m)), so

    P(M_R | h_1..k) = P(h_1..k | M_R) / (P(h_1..k | M_L) + P(h_1..k | M_R)).

Queries are the language learner's (EIG over its belief): with the same seed the hybrid asks
exactly what ``lang-<signal>`` asks, so the two differ only in their final answers. The final
answer (``decision="mixture"``) is Bayes' decision over both classes: among the language's
and the reward's candidate plans, the one with the largest

    P(M_L | h) Σ_z w_z 1[z holds after it] + P(M_R | h) P_w(no candidate has a larger w · φ),

so when no goal of the language fits the answers, the reward term still ranks plans.
``decision="map"`` is the ablation: the more probable class answers alone. The reward component draws from a stream of its own (derived from the
learner's seed), so it never changes the language learner's queries.

Stops: the language model gives a density over the press time t, the reward model a
probability over which prefix the press kept; for one scale the reward's is multiplied by the
density of t given the step reacted to (Σ_j π_j(t) of ``reward.models.stop_step_weights``,
before it normalises), the same lognormal delay both models assume.
"""

from __future__ import annotations

import math

import numpy as np

from activeintent import ranking
from activeintent.learners.base import Estimate, Learner, LearnerContext, Method, RoundRecord
from activeintent.learners.lang.learner import LangConfig, LangLearner, LangPriorSettings
from activeintent.learners.registry import METHODS
from activeintent.learners.reward.learner import RewardConfig, RewardLearner
from activeintent.learners.reward.models import lognormal_density
from activeintent.world import Scene, WorldState, describe_plan
from activeintent.world.trajectory import Trajectory

DECISIONS = ("mixture", "map")  # the final answer: Bayes' decision over both classes | the likelier class's
REWARD_STREAM = 1  # the reward component's generator: default_rng([learner_seed, REWARD_STREAM])


class HybridLearner(Learner):
    """``lang-<signal>`` asking, both model classes learning, the more probable one answering."""

    def __init__(self, signal: str, learner_seed: int = 0, lang: LangConfig | None = None,
                 reward: RewardConfig | None = None, llm=None, decision: str = "mixture"):
        if decision not in DECISIONS:
            raise ValueError(f"unknown hybrid decision {decision!r}; valid: {', '.join(DECISIONS)}")
        self.signal = signal
        self.decision = decision
        self.name = f"hybrid-{signal}" + ("" if decision == "mixture" else f"-{decision}")
        self.lang = LangLearner(signal, rng=learner_seed, llm=llm, config=lang)
        self.reward = RewardLearner(signal, rng=np.random.default_rng([learner_seed, REWARD_STREAM]), config=reward)
        self.redesigns_after_new_scene = self.lang.redesigns_after_new_scene
        self.stop_log_density = 0.0  # Σ_k log density of the press times (stops only), see above
        self.answer_log: list[dict] = []

    @property
    def model(self):
        """What both classes assume of people: the signal's learner model (never a user's)."""
        return self.lang.model

    # ---- the classes' posterior ----

    def log_evidence(self) -> tuple[float, float]:
        """log P(h_1..k | M_L), log P(h_1..k | M_R)."""
        return self.lang.belief.log_evidence, self.reward.belief.log_evidence + self.stop_log_density

    def p_reward(self) -> float:
        """P(M_R | h_1..k) with P(M_L) = P(M_R) = 1/2."""
        lang, reward = self.log_evidence()
        return 1.0 / (1.0 + math.exp(max(min(lang - reward, 700.0), -700.0)))

    def _stop_density(self, record: RoundRecord, trajectories: list[Trajectory]) -> float:
        """Density of the press time t given the step the press reacted to, summed over steps
        (1 / span when no step was revealed early enough: a lapse)."""
        t = getattr(record.answer, "stop_time", None)
        if t is None or not trajectories or not trajectories[0].steps:
            return 1.0
        traj = trajectories[0]
        m = self.reward.reward_model
        reveal = np.array([traj.time_of(s.reveal_tick) for s in traj.steps], float)
        dens = float(lognormal_density(float(t) - reveal, m.delay_mean, m.delay_sd).sum())
        span = max(traj.duration, 1e-3) + m.delay_mean + 3 * m.delay_sd
        return dens if dens > 0 else 1.0 / span

    # ---- the episode's calls ----

    def design_scene(self) -> Scene | None:
        return self.lang.design_scene()

    def estimate(self, scene: Scene, state: WorldState) -> Estimate:
        return self.lang.estimate(scene, state)

    def execution_failed(self, goal: str, reason: str) -> None:
        self.lang.execution_failed(goal, reason)

    def observe(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        out = self.lang.observe(record, trajectories)
        answer = record.answer
        if answer is None:
            return out
        self.reward.observe(record, trajectories)
        if self.signal == "stop" and not answer.new_scene:
            self.stop_log_density += math.log(self._stop_density(record, trajectories))
        lang, reward = self.log_evidence()
        self.answer_log.append({"p_reward": round(self.p_reward(), 4),
                                "log_evidence": {"lang": round(lang, 4), "reward": round(reward, 4)}})
        return out

    def final(self, scene: Scene, state: WorldState) -> Estimate:
        p = self.p_reward()
        if self.decision == "map":
            est = (self.reward if p > 0.5 else self.lang).final(scene, state)
            est.why = {**est.why, "answered_by": "reward" if p > 0.5 else "lang", "p_reward": round(p, 4)}
            return est
        # Bayes' decision over both classes: P(the outcome is what the person wants) is, under
        # M_L, Σ_z w_z 1[z holds]; under M_R, P(no candidate has a larger reward w · φ).
        w, feasible = self.lang.scene_weights(scene)
        outs = self.lang.final_outcomes(state, w, feasible) + self.reward.final_outcomes(state)
        score = (1 - p) * self.lang.expected_success(w, outs) + p * self.reward.p_best(outs)
        best = ranking.best_plan(score, [len(o.plan) for o in outs])
        plan = outs[best].plan
        z = self.lang.top()[0][0].description if p <= 0.5 else self.reward.describe()
        return Estimate(z=z, goals=[describe_plan(plan)], plans=[plan], done=True,
                        why={"p_success": round(float(score[best]), 4), "p_reward": round(p, 4),
                             "candidates": len(outs)})

    # ---- records ----

    def mass_of(self, key: str) -> float:
        return self.lang.mass_of(key)

    def stats(self) -> dict:
        return {**self.lang.stats(), "p_reward": round(self.p_reward(), 4), "reward": self.reward.stats()}

    def diagnostics(self) -> dict:
        return {**self.lang.diagnostics(), "hybrid": list(self.answer_log)}

    def drain_transcript(self) -> list[dict]:
        return self.lang.drain_transcript()


def hybrid_method(signal: str, decision: str = "mixture") -> Method:
    def build(ctx: LearnerContext) -> HybridLearner:
        return HybridLearner(signal, ctx.learner_seed, lang=LangConfig(**ctx.settings.model_dump()), llm=ctx.llm,
                             decision=decision)

    return Method(signal, False, build, f"ours: lang-{signal}'s belief and queries with a reward-feature "
                  "component that answers when it explains the answers better", goal_language=True,
                  compared_with=f"lang-{signal}", settings=LangPriorSettings)


for _signal in ("preference", "stop"):
    if f"hybrid-{_signal}" not in METHODS:
        METHODS.register(f"hybrid-{_signal}", lambda s=_signal: hybrid_method(s))
        METHODS.register(f"hybrid-{_signal}-map", lambda s=_signal: hybrid_method(s, "map"))
