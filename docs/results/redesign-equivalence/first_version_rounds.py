"""Run the first version's bayes learners in a symbolic loop and record every round."""
import json, sys
import numpy as np
from activeintent.intentions.registry import get_intention
from activeintent.learners.base import RoundRecord
from activeintent.learners.bayes.learner import BayesPreferenceLearner, BayesStopLearner
from activeintent.learners.bayes.symbolic import symbolic_trajectory
from activeintent.users.simulated import make_user
from activeintent.world import WorldState, describe_plan, layout

out = []
for signal in ("preference", "stop"):
    for intention in ("stack", "color-match", "color-mismatch", "align"):
        for seed in (0, 1, 2):
            cls = BayesPreferenceLearner if signal == "preference" else BayesStopLearner
            learner = cls(rng=np.random.default_rng(seed))
            user = make_user(signal, get_intention(intention), None, seed=seed + 1000)
            rng = np.random.default_rng(seed)
            rounds = []
            for r in range(5):
                scene = learner.design_scene(rng)
                if scene is None:
                    scene = get_intention(intention).sample_scene(rng)
                state = WorldState(positions=layout(scene, int(rng.integers(2**31))))
                est = learner.estimate(scene, state)
                trajs = [symbolic_trajectory(scene, state, p, seed) for p in est.plans]
                fb = user.respond(scene, trajs)
                learner.observe(RoundRecord(index=r, scene=scene, estimate=est, plans=est.plans, feedback=fb), trajs)
                rounds.append({"scene": list(scene.objects), "state": {k: list(v) for k, v in state.positions.items()},
                               "plans": [describe_plan(p) for p in est.plans], "answer": fb.model_dump(),
                               "top": [(h.name, round(w, 6)) for h, w in learner.top(5)]})
            out.append({"signal": signal, "intention": intention, "seed": seed, "rounds": rounds})
json.dump(out, open(sys.argv[1], "w"))
