"""``reward-preference`` / ``reward-stop``: the field's standard peer — preference-based
reward learning over state features (APReL-style; Sadigh et al. 2017, Bıyık et al.), with
stops read as reward-rational implicit choices among prefixes (Jeon, Milli & Dragan 2020).

r(s) = w · φ(s) with φ the general state features of ``features.py``; a particle belief over w
on the unit sphere (``belief.py``); each query chosen by mutual information between the answer
and w over candidate plans (``candidates.py``); the final answer on a test scene is the
candidate plan whose predicted outcome has the largest posterior expected reward E[w] · φ.
The learner never sees the hidden intention, its scene sampler or feasibility, or the user's
parameters; the hypothesis prior of the Bayesian learners is used only to propose plans
(experiments/reward-variants/noplanner.py measures the peer without them).
"""

from __future__ import annotations

import hashlib
import itertools

import numpy as np
from pydantic import BaseModel, Field

from activeintent import ranking
from activeintent.learners.base import Estimate, Learner, RoundRecord
from activeintent.learners.bayes.candidates import Outcome
from activeintent.learners.bayes.hypotheses import random_scene
from activeintent.learners.reward import candidates as cand
from activeintent.learners.reward.belief import RewardBelief
from activeintent.learners.reward.features import FEATURE_NAMES, phi, present
from activeintent.learners.reward.models import (
    RewardModel,
    RewardObservation,
    assumed,
    p_new_scene,
    preference_probs,
    prefix_probs,
    stop_step_weights,
)
from activeintent.signals import Answer, get_signal
from activeintent.world import Scene, WorldState, describe_plan, layout
from activeintent.world.trajectory import Trajectory


class RewardConfig(BaseModel):
    """Settings of the reward learners (none tuned to particular intentions)."""

    n_scenes: int = Field(3, ge=1, description="candidate scenes scored per design_scene")
    n_random: int = Field(12, ge=0, description="random skill sequences per scene")
    feature_depth: int = Field(2, ge=0, description="steps of the greedy one-feature plans (0: none)")
    planner_limit: int = Field(24, ge=1, description="plans taken from the planner per scene")
    max_candidates: int = Field(48, ge=2, description="candidate outcomes per scene (a seeded subset beyond)")
    particles: int = Field(512, ge=8)
    moves: int = Field(24, ge=0, description="Metropolis–Hastings moves after each answer")
    final_depth: int = Field(4, ge=0, description="steps of greedy ascent on E[w]·φ for the final answer")
    features: tuple[int, ...] | None = Field(None, description="indices of FEATURE_NAMES to use (None: all)")
    prior: str = Field("uniform", description="prior over w: uniform on the sphere (APReL's) | heavy-tailed "
                       "(few heavily weighted features as likely as many light ones; experiments/reward-variants/heavy_tailed.py)")
    model: RewardModel = Field(default_factory=RewardModel)


def _entropy(p: np.ndarray) -> np.ndarray:
    return -(p * np.log(np.clip(p, 1e-300, None))).sum(axis=-1)


def mutual_information(weights: np.ndarray, probs: np.ndarray) -> np.ndarray:
    """I(h; w) per query from probs [M, Q, O] and particle weights [M]."""
    marg = np.einsum("m,mqo->qo", weights, probs)
    return _entropy(marg) - np.einsum("m,mq->q", weights, _entropy(probs))


class RewardLearner(Learner):
    def __init__(self, signal: str, rng: np.random.Generator | int | None = None,
                 config: RewardConfig | None = None):
        if signal not in ("preference", "stop"):
            raise ValueError(f"reward learners read preference or stop; got {signal!r}")
        self.signal = signal
        self.config = c = config or RewardConfig()
        self.name = f"reward-{signal}" + ("" if c.prior == "uniform" else f"-{c.prior}")
        self.rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng or 0)
        self.idx = np.arange(len(FEATURE_NAMES)) if c.features is None else np.array(c.features, int)
        self.names = [FEATURE_NAMES[i] for i in self.idx]
        # What people are assumed to do is the signal's learner model (never a user's parameters):
        # its lapse and, for stops, its reaction delay and false / missed stops; β and the weak-
        # comparison threshold are on the reward scale and the reward learner's own (config.model).
        self.model = get_signal(signal).learner_model()
        self.reward_model = assumed(c.model, self.model)
        self.belief = RewardBelief(len(self.idx), self.rng, self.reward_model, c.particles, c.moves, c.prior)
        # Final answers are scored on the same test scenes at every k: what does not depend on
        # the answers (the planner's plans on its prior, successors' φ) is computed once per
        # scene, from a generator of its own (the scene's exact layout and one seed drawn here).
        self._final_seed = int(self.rng.integers(2**63))
        self._final_outs: dict[tuple, list[Outcome]] = {}
        self._final_phi: dict[tuple, np.ndarray] = {}
        self._pending: tuple[tuple, np.ndarray] | None = None  # (layout key, gains) of the last estimate
        self.answer_log: list[dict] = []
        self.rounds = 0

    # ---- features ----

    def phi(self, state: WorldState) -> np.ndarray:
        return phi(state)[self.idx]

    def _gains(self, state: WorldState, outs: list[Outcome]) -> np.ndarray:
        base = self.phi(state)
        if not outs:
            return np.zeros((0, len(self.idx)))
        return np.unique(np.array([self.phi(o.traj.outcome) for o in outs]) - base, axis=0)

    # ---- candidates ----

    uses_planner = True  # the peer's candidates include the Bayesian planner's plans on its prior

    def planner_candidates(self, pool, rng: np.random.Generator, limit: int, prefixes: bool) -> None:
        """The Bayesian learners' plans on their prior alone join the candidates."""
        cand.planner_plans(pool, rng, limit=limit, prefixes=prefixes)

    def candidates(self, state: WorldState) -> list[Outcome]:
        c = self.config
        pool = cand.Pool(state)
        self.planner_candidates(pool, self.rng, c.planner_limit, prefixes=self.signal == "preference")
        if c.feature_depth:
            mask = np.zeros(len(FEATURE_NAMES), bool)
            mask[self.idx] = True
            feats = np.flatnonzero(mask & present(state.positions))
            cand.feature_plans(pool, feats, depth=c.feature_depth)
        cand.random_plans(pool, self.rng, c.n_random)
        outs = pool.outs
        if len(outs) > c.max_candidates:
            keep = np.sort(self.rng.choice(len(outs), size=c.max_candidates, replace=False))
            outs = [outs[i] for i in keep]
        return outs

    # ---- queries ----

    def _select(self, state: WorldState, outs: list[Outcome]) -> tuple[list[Outcome], float, np.ndarray] | None:
        """The query with the largest I(h; w), the answer "new scene" included."""
        b = self.belief
        W, w = b.W, b.weights
        gains = self._gains(state, outs)
        pns = p_new_scene(W, gains, self.reward_model)[:, None, None]
        if self.signal == "preference":
            combos = list(itertools.combinations(range(len(outs)), 2))
            if not combos:
                return None
            R = W @ np.array([self.phi(o.traj.outcome) for o in outs]).T
            ia, ib = (np.array(x) for x in zip(*combos, strict=True))
            P = preference_probs(R[:, ia], R[:, ib], self.reward_model)
            full = np.concatenate([P * (1 - pns), np.broadcast_to(pns, P.shape[:2] + (1,))], axis=-1)
            mi = mutual_information(w, full)
            lengths = np.array([len(outs[i].plan) + len(outs[j].plan) for i, j in combos])
        else:
            combos = [(i,) for i in range(len(outs))]
            if not combos:
                return None
            mi = np.empty(len(outs))
            for k, o in enumerate(outs):
                P = prefix_probs(W @ self._prefix_vectors(o.traj).T, self.reward_model)[:, None, :]
                full = np.concatenate([P * (1 - pns), np.broadcast_to(pns, (len(W), 1, 1))], axis=-1)
                mi[k] = mutual_information(w, full)[0]
            lengths = np.array([len(o.plan) for o in outs])
        score = mi - 1e-4 * lengths  # among near-equal gains, shorter plans are quicker to watch
        best = ranking.argmax(score)
        return [outs[i] for i in combos[best]], float(score[best]), gains

    def _prefix_vectors(self, traj: Trajectory) -> np.ndarray:
        states = [traj.initial_state] + [s.state_after for s in traj.steps]
        return np.array([self.phi(s) for s in states])

    def design_scene(self) -> Scene | None:
        best: tuple[Scene, float] | None = None
        for _ in range(self.config.n_scenes):
            scene = random_scene(self.rng)
            state = WorldState(positions=layout(scene, int(self.rng.integers(2**31))))
            q = self._select(state, self.candidates(state))
            if q is not None and (best is None or ranking.greater(q[1], best[1])):
                best = (scene, q[1])
        return best[0] if best else None

    def describe(self, k: int = 3) -> str:
        """z: the reward's largest posterior-mean weights, in words."""
        m = self.belief.direction()
        top = ranking.order(np.abs(m))[:k]
        return "reward " + ", ".join(f"{m[i]:+.2f}·{self.names[i]}" for i in top)

    def estimate(self, scene: Scene, state: WorldState) -> Estimate:
        outs = self.candidates(state)
        q = self._select(state, outs)
        shows = 2 if self.signal == "preference" else 1
        if q is None:
            plans, why = [[]] * shows, {"eig_nats": None, "note": "no candidate plan changes the scene"}
            gains = self._gains(state, outs)
        else:
            plans = [o.plan for o in q[0]]
            gains = q[2]
            why = {"eig_nats": round(q[1], 4), "candidates": len(outs), "ess": round(self.belief.ess(), 1)}
        self._pending = (cand._key(state), gains)
        return Estimate(z=self.describe(), goals=[describe_plan(p) for p in plans], plans=plans, why=why)

    # ---- answers ----

    def _observation(self, answer: Answer, trajectories: list[Trajectory], gains: np.ndarray) -> RewardObservation:
        d = len(self.idx)
        if answer.new_scene:
            return RewardObservation("new_scene", np.zeros((0, d)), gains)
        if self.signal == "preference":
            choice = ("A", "B", "cant_choose").index(answer.choice)  # type: ignore[attr-defined]
            V = np.array([self.phi(t.outcome) for t in trajectories])
            return RewardObservation("preference", V, gains, choice=choice)
        traj = trajectories[0]
        V = self._prefix_vectors(traj)
        n = len(traj.steps)
        mix = np.zeros(n + 1)
        t = answer.stop_time  # type: ignore[attr-defined]
        if t is None or n == 0:
            mix[n] = 1.0
        else:
            reveal = np.array([traj.time_of(s.reveal_tick) for s in traj.steps], float)
            start = np.array([traj.time_of(s.start_tick) for s in traj.steps], float)
            mix[:n] = stop_step_weights(float(t), reveal, start, self.reward_model)  # stop in step j keeps prefix j
        return RewardObservation("stop", V, gains, mix=mix)

    def observe(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        answer = record.answer
        if answer is None:
            return None
        state = trajectories[0].initial_state if trajectories else None
        if self._pending is not None and state is not None and self._pending[0] == cand._key(state):
            gains = self._pending[1]
        elif state is not None:
            gains = self._gains(state, self.candidates(state))
        else:
            gains = np.zeros((0, len(self.idx)))
        obs = self._observation(answer, trajectories, gains)
        evidence = self.belief.update(obs)
        self.rounds += 1
        self.answer_log.append({"answer": obs.kind if obs.kind == "new_scene" else
                                (("A", "B", "cant_choose")[obs.choice] if obs.kind == "preference" else
                                 ("no_stop" if obs.mix[-1] == 1.0 else "stop")),
                                "evidence": round(evidence, 6), "ess": round(self.belief.ess(), 1),
                                "accept": round(self.belief.accept[-1], 3) if self.belief.accept else None,
                                "z": self.describe()})
        return None

    def final(self, scene: Scene, state: WorldState) -> Estimate:
        """The candidate plan whose predicted outcome has the largest E[w] · φ (doing nothing
        included); candidates: the planner's (if on), greedy ascent on E[w] · φ."""
        mean = self.belief.mean()
        outs = self.final_outcomes(state)
        values = np.array([mean @ self.phi(o.traj.outcome) for o in outs])
        best = ranking.best_plan(values, [len(o.plan) for o in outs])
        plan = outs[best].plan
        return Estimate(z=self.describe(), goals=[describe_plan(plan)], plans=[plan], done=True,
                        why={"expected_reward": round(float(values[best]), 4), "candidates": len(outs)})

    def final_outcomes(self, state: WorldState) -> list[Outcome]:
        """What the final answer chooses among: doing nothing, the planner's plans (if on) and
        every prefix of a greedy ascent on E[w] · φ."""
        pool = cand.Pool(state, keep_nothing=True)
        pool.extend(self._final_base(state))
        w_full = np.zeros(len(FEATURE_NAMES))
        w_full[self.idx] = self.belief.mean()
        cand.reward_plans(pool, w_full, depth=self.config.final_depth, memo=self._final_phi)
        return pool.outs

    def p_best(self, outs: list[Outcome]) -> np.ndarray:
        """P(the outcome has the largest reward w · φ among ``outs``) under the belief, per
        outcome (outcomes of equal reward share a particle's mass in full: each is a best)."""
        R = self.belief.W @ np.array([self.phi(o.traj.outcome) for o in outs]).T  # [M, C]
        best = ranking.quantised(R) >= ranking.quantised(R.max(axis=1, keepdims=True))
        return self.belief.weights @ best

    def _final_base(self, state: WorldState) -> list[Outcome]:
        """Doing nothing and (if on) the planner's plans on its prior, once per exact layout."""
        key = cand._key(state)
        got = self._final_outs.get(key)
        if got is None:
            pool = cand.Pool(state, keep_nothing=True)
            pool.add([])
            digest = int.from_bytes(hashlib.sha256(repr(key).encode()).digest()[:8], "little")
            rng = np.random.default_rng([self._final_seed, digest])
            self.planner_candidates(pool, rng, self.config.planner_limit, prefixes=False)
            got = self._final_outs[key] = pool.outs
        return got

    # ---- records ----

    def stats(self) -> dict:
        b = self.belief
        return {"features": len(self.idx), "particles": len(b.W), "ess": round(b.ess(), 1),
                "mean_norm": round(float(np.linalg.norm(b.mean())), 4),
                "accept": [round(a, 3) for a in b.accept], "planner": self.uses_planner,
                "z": self.describe(5)}

    def diagnostics(self) -> dict:
        return {"reward_answers": list(self.answer_log)}  # not "answers": the report reads those as bits of a z belief
