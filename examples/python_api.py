"""Run one episode from Python: a simulated user, a learner, an executor and the simulator.

    .venv/bin/python examples/python_api.py
"""

from activeintent.act.base import make_executor
from activeintent.episode import Episode, EpisodeConfig, EpisodeSeeds
from activeintent.intentions.registry import get_intention
from activeintent.learners.registry import make_learner
from activeintent.llm.registry import load_model
from activeintent.sim.env import TabletopEnv
from activeintent.users.simulated import UserConfig, make_user

seeds = EpisodeSeeds.from_seed(7)
intention = get_intention("stack")  # hidden from the learner; only the user knows it
user = make_user("stop", intention, UserConfig(), seed=seeds.user)
llm = load_model("embedded")  # or "openai:gpt-4o" with OPENAI_API_KEY set
learner = make_learner("mllm-llm", llm=llm, retriever="symbolic", seed=seeds.learner)
with TabletopEnv() as env:
    episode = Episode(learner, intention, user, make_executor("plan", model=llm), env,
                      EpisodeConfig(rounds=3, seed=7), out_dir="runs/example")
    result = episode.run()
print(f"success={result.success} z={result.final_preference!r} signals={result.signals_used}")
