"""How much could better question choice alone buy? A clairvoyant bound for ``decide-stop``.

NOT A LEARNER: the chooser below reads the hidden intention. It is a diagnostic of where the
loss is (issue "Questions worth a person's answer"), never a method of the benchmark.

``decide-stop`` unchanged (same belief, same growth, same candidate scenes and plans, same final
answer), except which candidate query is asked: among the candidates of each round, the one
whose *actual* answer (the exact user's, known here from the hidden intention) leaves the most
posterior mass on goals that would act right. A goal z acts right on one of the learner's own
deployment scenes when the first candidate plan that satisfies z also satisfies the intention;
its score is the share of those scenes (where the intention can be shown) on which it does.
So the chooser knows every answer before asking, one step ahead. If even it cannot reach a
success target, the questions on offer cannot, and the loss is elsewhere (what the answers can
say, which goals the belief holds).

    .venv/bin/python experiments/decide/clairvoyant_bound.py --records docs/results/truth-goals-exact/results.jsonl \\
        --out runs/clairvoyant-exact.jsonl

It re-runs the episodes of ``decide-stop`` in those records (same seeds, exact users) with the
clairvoyant chooser, and prints success@k beside the records' decide-stop, paired. With
``--pool 50`` and the records of ``decide-pool-stop`` (docs/results/truth-goals-pool-exact) the
belief also grows from the one-clause pool.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
from pathlib import Path

import numpy as np

from activeintent.act.executors import make_executor
from activeintent.bench.legacy import migrated
from activeintent.envs.symbolic import SymbolicEnv
from activeintent.episode import Episode
from activeintent.goals.facts import facts
from activeintent.learners.bayes.acquisition import Query
from activeintent.learners.bayes.candidates import candidate_plans
from activeintent.provenance import provenance
from activeintent.registry import load_plugin
from activeintent.spec import ProtocolConfig
from activeintent.suites import resolve
from activeintent.users.simulated import IntentionJudge, SimulatedUser, user_profile

decide = load_plugin(Path(__file__).resolve().with_name("learner.py"))
Scored, look_particles = decide.acquisition.Scored, decide.acquisition.look_particles


class ClairvoyantChooser(decide.DecideLearner):
    """decide-stop whose query choice reads the hidden intention (a bound, not a learner)."""

    def __init__(self, intention, rng, pool: int = 0, language: int = 1):
        config = decide.DecideConfig(**decide.DECIDE, pool=pool, language=language, prior="length")  # as measured
        super().__init__("stop", rng=rng, config=config)
        self.name = "clairvoyant-decide-stop"
        self.intention = intention
        self.truth = IntentionJudge(intention)
        self._scores: tuple[tuple, np.ndarray] | None = None

    def acts_right(self, look: np.ndarray) -> np.ndarray:
        """Per look particle: share of the deployment scenes where acting on it is right."""
        key = (len(self.observations), len(self.hyps), look.tobytes())
        if self._scores is not None and self._scores[0] == key:
            return self._scores[1]
        rng = np.random.default_rng(0)
        right, scenes = np.zeros(len(look)), 0
        for state in self.deploy:
            if not self.intention.feasible(state.scene):
                continue
            feasible = self.judge.feasible(tuple(state.scene.objects))
            outs = candidate_plans(self.hyps, self.weights * feasible, state, rng, top_k=self.config.final_top_k,
                                   explore=0, prefixes=False, limit=self.config.max_plans, feasible=feasible)
            scenes += 1
            if not outs:
                right += float(self.intention.satisfied(state))
                continue
            holds = np.array([self.judge.judge(facts(o.traj.outcome))[0][look] for o in outs])  # [O, Z]
            good = np.array([self.intention.satisfied(o.traj.outcome) for o in outs])
            first = holds.argmax(axis=0)
            right += np.where(holds.any(axis=0), good[first], float(self.intention.satisfied(state)))
        score = right / max(scenes, 1)
        self._scores = (key, score)
        return score

    def _select(self, state, scored=None):
        kept: list[Scored] = []
        q = super()._select(state, kept)
        if not kept:
            return q
        sc = kept[0]
        look = look_particles(self.weights)
        w = self.weights[look] / self.weights[look].sum()
        score = self.acts_right(look)
        shown = self.intention.feasible(state.scene)
        values = np.empty(len(sc.combos))
        for n, (combo, table) in enumerate(zip(sc.combos, sc.tables, strict=True)):
            traj = sc.outs[combo[0]].traj
            if not shown:
                a = table.shape[1] - 1
            else:
                k = int(self.truth.first_away(traj)[0])
                a = k if k >= 0 else max(len(traj.steps), 1)
            post = w * table[:, a]
            post = post / post.sum() if post.sum() > 0 else w
            values[n] = float(post @ score) + 1e-3 * sc.gains[n]  # ties: the larger one-step gain
        best = int(np.argmax(values))
        return Query([sc.outs[i] for i in sc.combos[best]], float(values[best]), [])


POOL = 0  # --pool: with decide-pool-stop's growth (LangConfig.pool)


def run_one(record: dict) -> dict:
    intention = resolve(record["intention"])
    protocol = ProtocolConfig(**record["config"]["episode"])  # the record's episode, seeds included
    seeds = protocol.seeds
    user = SimulatedUser(intention, "stop", user_profile("exact"), rng=seeds.user)
    # the record's goal language (a record of an older shape: bench.legacy gives the one it ran in)
    language = migrated(record)["config"]["spec"]["learner"]["settings"]["language"]
    learner = ClairvoyantChooser(intention, seeds.learner, POOL, language)
    res = Episode(learner, intention, user, make_executor("plan"), SymbolicEnv(), protocol).run()
    return {"intention": record["intention"], "seed": record["seed"], "user_preset": "exact",
            "budget": protocol.budget, "pool": POOL, "success_at": res.success_at,
            "baseline": record["method"], "baseline_success_at": record["success_at"],
            "answers": res.answers, "provenance": provenance()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--records", required=True, help="a results.jsonl with decide-stop episodes (exact users)")
    ap.add_argument("--out", required=True)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--pool", type=int, default=0, help="grow the belief as decide-pool-stop does (its 50)")
    args = ap.parse_args()
    global POOL
    POOL = args.pool
    method = "decide-pool-stop" if args.pool else "decide-stop"
    records = [r for r in map(json.loads, Path(args.records).read_text().splitlines())
               if r["method"] == method and r.get("success_at")]
    if any(r["user_preset"] != "exact" for r in records):
        raise SystemExit("the clairvoyant chooser knows the exact user's answer: give records of exact users")
    with multiprocessing.Pool(args.jobs) as pool:
        rows = []
        with open(args.out, "w") as fh:
            for row in pool.imap(run_one, records):
                rows.append(row)
                fh.write(json.dumps(row) + "\n")
                print(row["intention"], [round(x, 2) for x in row["success_at"]], flush=True)
    a = np.array([r["success_at"] for r in rows], float)
    b = np.array([r["baseline_success_at"] for r in rows], float)
    d = a.mean(1) - b.mean(1)
    half = 1.96 * d.std(ddof=1) / np.sqrt(len(d))
    print(f"n = {len(rows)}: clairvoyant chooser success@5 {a[:, 5].mean():.2f}, @10 {a[:, 10].mean():.2f}; "
          f"{method} (the records') {b[:, 5].mean():.2f} / {b[:, 10].mean():.2f}; "
          f"area difference {d.mean():+.3f} [{d.mean() - half:+.3f}, {d.mean() + half:+.3f}]")


if __name__ == "__main__":
    main()
