"""A physics-free episode for fast checks: trajectories built from world.predict.

:func:`symbolic_trajectory` makes a :class:`Trajectory` (the same pure-data log the
simulator writes) from the symbolic world model, with fixed step timing; the simulated users
read it like a real one. :func:`run_symbolic_episode` is the episode loop of design.md §2
without the simulator, used by tests and by ``activeintent bayes-bench``.
"""

from __future__ import annotations

import time

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.learners.base import Learner, RoundRecord
from activeintent.sim.trajectory import StepRecord, Trajectory
from activeintent.world import Scene, Skill, WorldState, apply_plan, layout

STEP_SECONDS = 3.0  # simulated time per skill
REVEAL_FRACTION = 0.35  # the destination becomes evident this far into a skill
DT = 0.05


def symbolic_trajectory(scene: Scene, state: WorldState, plan: list[Skill], seed: int = 0) -> Trajectory:
    """τ for ``plan`` from ``state`` on the symbolic world model (blocks jump at step ends)."""
    states, fails = apply_plan(state, plan)
    names = list(state.positions)
    per = int(round(STEP_SECONDS / DT))
    n_ticks = per * len(plan) + 1
    poses = np.zeros((n_ticks, len(names), 7))
    poses[..., 6] = 1.0
    step_index = np.full(n_ticks, -1)
    records = []
    current = state
    poses[:, :, :3] = np.array([state.positions[n] for n in names])
    for k, (step, after, fail) in enumerate(zip(plan, states, fails, strict=True)):
        start, end = k * per, (k + 1) * per
        step_index[start:end] = k
        poses[end:, :, :3] = np.array([after.positions[n] for n in names])
        records.append(
            StepRecord(
                index=k,
                skill=step,
                start_tick=start,
                reveal_tick=start + int(round(REVEAL_FRACTION * per)),
                end_tick=end,
                ok=fail is None,
                reason=None if fail is None else fail.reason,
                state_before=current,
                state_after=after,
            )
        )
        current = after
    return Trajectory(
        scene=scene,
        seed=seed,
        dt=DT,
        object_names=names,
        object_poses=poses,
        joint_positions=np.zeros((n_ticks, 7)),
        ee_pose=np.zeros((n_ticks, 7)),
        gripper_closed=np.zeros(n_ticks, dtype=bool),
        step_index=step_index,
        steps=records,
        initial_state=state,
        final_state=current,
    )


def run_symbolic_episode(
    learner: Learner,
    intention: Intention,
    user,
    rounds: int = 5,
    seed: int = 0,
    test_scenes: int = 1,
) -> dict:
    """One episode without physics; returns success, signals used and per-query timings."""
    rng = np.random.default_rng(seed)
    signals, select_s = 0, []
    for r in range(rounds):
        t0 = time.perf_counter()
        scene = learner.design_scene(rng)
        if scene is None:
            scene = intention.sample_scene(rng)
        state = WorldState(positions=layout(scene, int(rng.integers(2**31))))
        est = learner.estimate(scene, state)
        select_s.append(time.perf_counter() - t0)
        if est.done:
            break
        plans = est.plans or []
        trajs = [symbolic_trajectory(scene, state, p, seed) for p in plans]
        feedback = user.respond(scene, trajs)
        record = RoundRecord(index=r, scene=scene, estimate=est, plans=plans, feedback=feedback)
        learner.observe(record, trajs)
        signals += 1
    wins = []
    for _ in range(test_scenes):
        scene = intention.sample_scene(rng)
        state = WorldState(positions=layout(scene, int(rng.integers(2**31))))
        est = learner.final(scene, state)
        states, _ = apply_plan(state, (est.plans or [[]])[0])
        wins.append(intention.satisfied(states[-1] if states else state))
    return {
        "success": float(np.mean(wins)),
        "signals": signals,
        "preference": est.preference,
        "select_s": select_s,
    }


def make_learner(signal: str, seed: int, config=None):
    from activeintent.learners.bayes.learner import BayesPreferenceLearner, BayesStopLearner

    if signal not in ("preference", "stop"):
        raise ValueError(f"unknown signal {signal!r}; valid: preference, stop")
    cls = BayesPreferenceLearner if signal == "preference" else BayesStopLearner
    return cls(rng=np.random.default_rng(seed), config=config)


def grammar_only_intentions(n: int, seed: int = 0) -> list[Intention]:
    """``n`` hypotheses of H (seeded draw) that agree with none of the named intentions."""
    from activeintent.intentions.registry import all_intentions
    from activeintent.learners.bayes.hypotheses import hypothesis_space

    hyps = list(hypothesis_space())
    named = [matching_hypothesis(it, hyps) for it in all_intentions()]
    pool = [h for h in hyps if h not in named]
    rng = np.random.default_rng(seed)
    return [pool[i] for i in rng.choice(len(pool), size=min(n, len(pool)), replace=False)]


def agreement_states(
    intention: Intention, hyps, n_scenes: int = 6, seed: int = 0, others: int | None = None
) -> list[WorldState]:
    """States to compare an intention with hypotheses: initial layouts of scenes feasible for
    it, its own plan's outcome, and the outcomes of the plans of the hypotheses feasible there
    (of ``others`` random ones of them, if given)."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n_scenes):
        scene = intention.sample_scene(rng)
        state = WorldState(positions=layout(scene, seed * 100 + i))
        out.append(state)
        feasible = [h for h in hyps if h.feasible(scene)]
        if others is not None and len(feasible) > others:
            feasible = [feasible[j] for j in rng.choice(len(feasible), size=others, replace=False)]
        plans = [intention.plan(state)] + [h.plan(state) for h in feasible]
        for p in plans:
            if p:
                states, _ = apply_plan(state, p)
                out.append(states[-1])
    return out


def matching_hypothesis(intention: Intention, hyps, n_scenes: int = 8, others: int | None = 40):
    """The first hypothesis whose ``satisfied`` equals the intention's on every agreement state."""
    states = agreement_states(intention, hyps, n_scenes, others=others)
    truth = [intention.satisfied(s) for s in states]
    for h in hyps:
        if all(h.satisfied(s) == t for s, t in zip(states, truth, strict=True)):
            return h
    return None


def benchmark(
    signal: str,
    intentions: list[Intention],
    seeds: list[int],
    user_config=None,
    rounds: int = 5,
    test_scenes: int = 1,
    progress=None,
) -> dict:
    """Success and signals over intentions × seeds with simulated users (no physics)."""
    from activeintent.users.simulated import make_user

    rows = []
    for it in intentions:
        for seed in seeds:
            learner = make_learner(signal, seed)
            user = make_user(signal, it, user_config, seed=seed + 1000)
            r = run_symbolic_episode(learner, it, user, rounds=rounds, seed=seed, test_scenes=test_scenes)
            rows.append({"intention": it.name, "seed": seed, **r})
            if progress:
                progress()
    times = [t for r in rows for t in r["select_s"]]
    per: dict[str, list[float]] = {}
    for r in rows:
        per.setdefault(r["intention"], []).append(r["success"])
    return {
        "signal": signal,
        "episodes": len(rows),
        "success": float(np.mean([r["success"] for r in rows])) if rows else 0.0,
        "per_intention": {k: float(np.mean(v)) for k, v in per.items()},
        "mean_signals": float(np.mean([r["signals"] for r in rows])) if rows else 0.0,
        "select_s_mean": float(np.mean(times)) if times else 0.0,
        "select_s_max": float(np.max(times)) if times else 0.0,
        "rows": [{k: v for k, v in r.items() if k != "select_s"} for r in rows],
    }


def selection_benchmark(queries: int = 4, seed: int = 0) -> dict:
    """Per-query selection time (design_scene + estimate) for both learners, mid-episode:
    the belief is updated by an exact user of a paper intention between queries."""
    from activeintent.intentions.registry import get_intention
    from activeintent.users.simulated import make_user

    out = {}
    for signal in ("preference", "stop"):
        learner = make_learner(signal, seed)
        intention = get_intention("color-match")
        user = make_user(signal, intention, seed=seed)
        rng = np.random.default_rng(seed)
        times = []
        for r in range(queries):
            t0 = time.perf_counter()
            scene = learner.design_scene(rng)
            state = WorldState(positions=layout(scene, int(rng.integers(2**31))))
            est = learner.estimate(scene, state)
            times.append(time.perf_counter() - t0)
            trajs = [symbolic_trajectory(scene, state, p) for p in est.plans or []]
            fb = user.respond(scene, trajs)
            learner.observe(RoundRecord(index=r, scene=scene, estimate=est, plans=est.plans or [], feedback=fb), trajs)
        out[signal] = {
            "queries": queries,
            "mean_s": float(np.mean(times)),
            "max_s": float(np.max(times)),
            "per_query_s": [round(t, 3) for t in times],
        }
    return out
