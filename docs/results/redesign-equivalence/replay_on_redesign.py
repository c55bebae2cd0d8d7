"""Replay the first version's rounds through the redesigned learner, configured with the first
version's assumptions; report whether queries and beliefs are identical."""
import json, sys
import numpy as np
from activeintent.envs.symbolic import symbolic_trajectory
from activeintent.learners.base import RoundRecord
from activeintent.learners.bayes.learner import BayesConfig, BayesLearner
from activeintent.signals.preference import PreferenceAnswer, PreferenceModel
from activeintent.signals.stop import StopAnswer, StopModel, StopSignal
from activeintent.world import Scene, WorldState, describe_plan


def old_predictive(self, shown, judge, model):  # the first version's discretisation
    traj = shown[0]
    away = np.asarray(judge.first_away(traj))
    n = max(len(traj.steps), 1)
    p = np.zeros((len(away), n + 1))
    has = away >= 0
    p[:, :n] = model.false_stop / n
    p[has, away[has]] += 1 - model.false_stop - model.missed_stop
    p[has, n] += model.missed_stop
    p[~has, n] += 1 - model.false_stop
    return (1 - model.lapse) * p + model.lapse / (n + 1)


StopSignal.predictive = old_predictive
old = json.load(open(sys.argv[1]))
same_plans = same_top = total = 0
episodes_identical = 0
for ep in old:
    learner = BayesLearner(ep["signal"], rng=np.random.default_rng(ep["seed"]),
                           config=BayesConfig(new_scene_error=0.02, final_top_k=32, max_plans=36))
    learner.model = PreferenceModel(beta=12, lapse=0.03) if ep["signal"] == "preference" else StopModel()
    rng = np.random.default_rng(ep["seed"])
    ok = True
    for r, rec in enumerate(ep["rounds"]):
        learner.design_scene(rng)
        scene = Scene(objects=rec["scene"])
        state = WorldState(positions={k: tuple(v) for k, v in rec["state"].items()})
        est = learner.estimate(scene, state)
        plans_ok = [describe_plan(p) for p in est.plans] == rec["plans"]
        a = rec["answer"]
        if a["kind"] == "preference":
            ans = PreferenceAnswer(new_scene=True) if a["choice"] == "new_scene" else PreferenceAnswer(choice=a["choice"])
        else:
            ans = StopAnswer(new_scene=a["new_scene"], stop_time=a["stop_time"])
        trajs = [symbolic_trajectory(scene, state, p, ep["seed"]) for p in est.plans]
        learner.observe(RoundRecord(index=r, scene=scene, estimate=est, plans=est.plans, answer=ans), trajs)
        top = [(h.name, round(w, 6)) for h, w in learner.top(5)]
        top_ok = [n for n, _ in top] == [n for n, _ in rec["top"]] and np.allclose(
            [w for _, w in top], [w for _, w in rec["top"]], atol=1e-5)
        total += 1
        same_plans += plans_ok
        same_top += top_ok
        ok &= plans_ok and top_ok
    episodes_identical += ok
print(json.dumps({"episodes": len(old), "episodes_identical": episodes_identical, "rounds": total,
                  "same_query": same_plans, "same_posterior_top5": same_top}))
