"""Run one episode from Python: a simulated user, a learner, an executor and an env.

    .venv/bin/python examples/python_api.py            # bayes-stop, no model, symbolic env
    .venv/bin/python examples/python_api.py mllm-llm   # the paper's best method on the embedded model
"""

import sys

from activeintent.act.executors import make_executor
from activeintent.envs import make_env
from activeintent.episode import Episode
from activeintent.learners.registry import LearnerContext, get_method
from activeintent.spec import ProtocolConfig
from activeintent.suites import resolve
from activeintent.users.simulated import SimulatedUser, user_profile

method = get_method(sys.argv[1] if len(sys.argv) > 1 else "bayes-stop")
protocol = ProtocolConfig(budget=3, seed=7)
seeds = protocol.seeds  # the episode's one seed split into streams: the user's and the learner's come from it
intention = resolve("stack")  # hidden from the learner; only the user holds it
user = SimulatedUser(intention, method.signal, user_profile("human"), rng=seeds.user)
llm = None
if method.needs_llm:
    from activeintent.llm.registry import load_model

    llm = load_model("embedded")  # or "openai:gpt-4o" with OPENAI_API_KEY set
learner = method(LearnerContext(llm=llm, learner_seed=seeds.learner))


def usage():  # the episode reports the model calls it caused
    if llm is None:
        return 0, 0, 0
    t = llm.usage.snapshot()
    return t.calls, t.prompt_tokens, t.completion_tokens


env = make_env("symbolic")  # or "pybullet" for physics and videos
episode = Episode(learner, intention, user, make_executor("plan", model=llm), env,
                  protocol, out_dir="runs/example", usage=usage)
result = episode.run()
env.close()
print(f"success@3={result.success} success_at={result.success_at} z={result.final_z!r} "
      f"signals={result.signals_used} model calls={result.llm_calls}")
