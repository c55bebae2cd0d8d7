"""What each executor costs apart from the model call (``activeintent act-bench``)."""

from __future__ import annotations

from activeintent.act.failures import check_plan
from activeintent.act.parse import parse_instruction
from activeintent.act.plan import answer_to_plan, plan_schema
from activeintent.act.robot_api import RobotAPI, safe_builtins
from activeintent.act.sandbox import Sandbox
from activeintent.world import PutIn, PutOn, WorldState, describe_plan, layout, sample_scene

# Programs in the Code-as-Policies style, used to measure the sandbox's cost per program.
BENCH_PROGRAMS = (
    "say('Ok')\nput_first_on_second(BLOCKS[0], BOWLS[0])",
    "for b in BLOCKS:\n    put_first_on_second(b, BOWLS[-1])",
    "stack_objects_in_order(object_names=BLOCKS)",
    "y = parse_position('middle')[1]\nfor x, b in zip(np.linspace(-0.15, 0.15, len(BLOCKS)), BLOCKS):\n"
    "    put_first_on_second(b, [x, y])",
    "pos = get_obj_pos(BLOCKS[0])\nput_first_on_second(BLOCKS[0], get_corner_name(pos))",
    "def dist(a, b):\n    return float(np.linalg.norm(get_obj_pos(a) - get_obj_pos(b)))\n"
    "closest = min(BLOCKS[1:], key=lambda b: dist(b, BLOCKS[0]))\nput_first_on_second(closest, BLOCKS[0])",
    "names = [n for n in get_obj_names() if n.endswith('block')]\n"
    "say(f'{len(names)} blocks: ' + ', '.join(names))\nput_first_on_second(names[-1], denormalize_xy([0.5, 0.9]))",
)


def run_bench(n_programs: int = 20, seed: int = 0) -> dict:
    """Mean per-item cost of each executor's own work (no model call), in seconds."""
    import statistics
    import time

    import numpy as np

    rng = np.random.default_rng(seed)
    states = []
    while len(states) < n_programs:
        scene = sample_scene(rng, n_blocks=(2, 4), n_bowls=(1, 2))
        states.append(WorldState(positions=layout(scene, int(rng.integers(1 << 30)))))

    def plan_for(state: WorldState) -> list:
        blocks, bowls = state.blocks, state.bowls
        return [PutIn(block=blocks[0], bowl=bowls[0]), PutOn(block=blocks[1], target=blocks[0])]

    def timed(fn, items) -> list[float]:
        out = []
        for item in items:
            t = time.perf_counter()
            fn(item)
            out.append(time.perf_counter() - t)
        return out

    texts = [(describe_plan(plan_for(s)), s) for s in states]
    parse_s = timed(lambda ts: check_plan(parse_instruction(ts[0], ts[1].names), ts[1]), texts)
    answers = [({"steps": [p.model_dump() for p in plan_for(s)]}, s) for s in states]
    plan_s = timed(lambda a: check_plan(answer_to_plan(plan_schema(a[1]).model_validate(a[0]), a[1]), a[1]), answers)

    def program(i: int, state: WorldState) -> str:
        header = f"BLOCKS = {state.blocks!r}\nBOWLS = {state.bowls!r}\n"
        return header + BENCH_PROGRAMS[i % len(BENCH_PROGRAMS)]

    programs = [(program(i, s), s) for i, s in enumerate(states)]

    def in_process(ps) -> None:
        api = RobotAPI(ps[1])
        ns = api.namespace()
        ns["__builtins__"] = safe_builtins(api)
        exec(compile(ps[0], "<program>", "exec"), ns)  # noqa: S102 - trusted bench programs

    direct_s = timed(in_process, programs)
    sandbox = Sandbox()
    t = time.perf_counter()
    sandbox.start()
    startup = time.perf_counter() - t
    failures = []

    def sandboxed(ps) -> None:
        result = sandbox.run(ps[0], ps[1])
        if not result.ok:
            failures.append(result.error)

    sandbox_s = timed(sandboxed, programs)
    refused_s = timed(lambda ps: sandbox.run("import os\n" + ps[0], ps[1]), programs)
    sandbox.close()

    def stats(xs: list[float]) -> dict:
        return {"mean_s": statistics.fmean(xs), "max_s": max(xs), "n": len(xs)}

    overhead = [s - d for s, d in zip(sandbox_s, direct_s, strict=True)]
    return {
        "parse": stats(parse_s),
        "plan_validation": stats(plan_s),
        "cap_in_process": stats(direct_s),
        "cap_sandboxed": stats(sandbox_s),
        "cap_sandbox_overhead": stats(overhead),
        "cap_refused_by_guard": stats(refused_s),
        "sandbox_startup_s": startup,
        "sandbox_overhead_target_s": 0.2,
        "meets_target": statistics.fmean(overhead) < 0.2,
        "program_errors": failures,
    }
