"""The translation check: each sampled translation scored against an independent checker.

    .venv/bin/python data/requests/check_translations.py [--pass 2] [--scenes 100] [--jobs 2]
    .venv/bin/python data/requests/check_translations.py --writers [--scenes 100]

Pass 1: translations.jsonl (language 1), check_sample.json → check_results.json; pass 2:
translations-2.jsonl (language 2), check_sample_2.json → check_results_2.json; pass 3:
translations-3.jsonl (language 2 again, the brief's second lesson), check_sample_3.json (an order
drawn before pass 3 was read: its first 40 translated and first 20 marked requests) →
check_results_3.json.
For the 40 translated requests of the sample: the translator's goal against the checker a
second writer wrote from the request alone (checkers/*.py, class R<id>), both ways on test
scenes where the checker is feasible (`coverage --goal`); they agree when both shares are
≥ 0.9. For the 20 marked "not expressible": the language's best goal for the checker
(`coverage`), confirmed when its plan success is < 0.8. Writes the results file beside this one.

``--writers`` (pass 2's 40 translated requests): how far two independent readings of the same
request agree — the first checker against a second one written blind by another writer
(checkers/second/, class R<id>), both ways by the same measure — and the translated goal
against the second checker. Writes check_writers_2.json.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
from pathlib import Path

HERE = Path(__file__).resolve().parent
AGREE = 0.9


def _checker(rid: str, folder: Path = HERE / "checkers"):
    from activeintent.intentions.registry import load_intention_file

    name = "R" + rid[1:]
    for path in sorted(folder.glob("*.py")):
        if f"class {name}(" in path.read_text():
            return load_intention_file(f"{path}:{name}")
    raise SystemExit(f"no checker class {name} in {folder}")


PASSES = {1: ("translations.jsonl", "check_sample.json", "check_results.json"),
          2: ("translations-2.jsonl", "check_sample_2.json", "check_results_2.json"),
          3: ("translations-3.jsonl", "check_sample_3.json", "check_results_3.json")}
LANGUAGE = {1: 1, 2: 2, 3: 2}  # the language each pass translated into


def drawn(sample: dict, rows: dict[str, dict]) -> dict[str, list[str]]:
    """The sample's translated and "not expressible" requests: listed, or the first 40 / 20 of
    its drawn order."""
    if "order" not in sample:
        return sample
    return {"translated": [i for i in sample["order"] if rows[i]["expressible"]][:40],
            "not_expressible": [i for i in sample["order"] if not rows[i]["expressible"]][:20]}


def _translated(args: tuple[str, str, int, int]) -> dict:
    from activeintent.bench.coverage import agreement
    from activeintent.goals.language import parse_goal, speaking

    rid, key, scenes, language = args
    with speaking(language):
        row = agreement(parse_goal(key), _checker(rid), scenes)
    both = min(row["goal_plan_satisfies_checker"], row["checker_plan_satisfies_goal"])
    return {"id": rid, **row, "agree": both >= AGREE}


def _not_expressible(args: tuple[str, int, int]) -> dict:
    from activeintent.bench.coverage import EXPRESSIBLE, coverage
    from activeintent.goals.language import speaking

    rid, scenes, language = args
    with speaking(language):
        row = coverage(_checker(rid), test_scenes=scenes)
    return {"id": rid, "best_goal": row.goal, "best_success": row.success, "confirmed": row.success < EXPRESSIBLE}


def _writers(args: tuple[str, str, int]) -> dict:
    """The first checker against the second (plans both ways, on scenes where both are feasible),
    and the translated goal against the second checker."""
    from activeintent.bench.coverage import agreement, feasible_scenes, plan_satisfies
    from activeintent.goals.language import parse_goal, speaking

    rid, key, n = args
    first, second = _checker(rid), _checker(rid, HERE / "checkers" / "second")
    scenes = [(sc, seed) for sc, seed in feasible_scenes(first, 3 * n, 0, "agreement") if second.feasible(sc)][:n]
    ways = {name: round(plan_satisfies(a, b.satisfied, scenes), 4)
            for name, a, b in (("first_plan_satisfies_second", first, second), ("second_plan_satisfies_first", second, first))}
    with speaking(2):
        goal = agreement(parse_goal(key), second, n)
    return {"id": rid, "scenes": len(scenes), **ways, "writers_agree": min(ways.values()) >= AGREE,
            "goal_plan_satisfies_second": goal["goal_plan_satisfies_checker"],
            "second_plan_satisfies_goal": goal["checker_plan_satisfies_goal"],
            "goal_agrees_with_second": min(goal["goal_plan_satisfies_checker"], goal["checker_plan_satisfies_goal"]) >= AGREE}


def writers(scenes: int, jobs: int) -> None:
    translations, sample_file, _ = PASSES[2]
    sample = json.loads((HERE / sample_file).read_text())
    goals = {r["id"]: r["goal"] for r in map(json.loads, (HERE / translations).read_text().splitlines())}
    first = {r["id"]: r for r in json.loads((HERE / PASSES[2][2]).read_text())["translated_rows"]}
    with multiprocessing.get_context("spawn").Pool(jobs) as pool:
        rows = pool.map(_writers, [(i, goals[i], scenes) for i in sample["translated"]])
    for r in rows:
        r["goal_agrees_with_first"] = first[r["id"]]["agree"]
    counts = {k: sum(r[k] for r in rows) for k in ("writers_agree", "goal_agrees_with_first", "goal_agrees_with_second")}
    counts["goal_agrees_with_either"] = sum(r["goal_agrees_with_first"] or r["goal_agrees_with_second"] for r in rows)
    out = {"pass": 2, "requests": len(rows), "threshold": AGREE, "scenes": scenes, **counts, "rows": rows}
    (HERE / "check_writers_2.json").write_text(json.dumps(out, indent=1) + "\n")
    print(f"two independent checkers agree ≥ {AGREE} both ways on {counts['writers_agree']} of {len(rows)}; "
          f"the translated goal agrees with the first {counts['goal_agrees_with_first']}, the second "
          f"{counts['goal_agrees_with_second']}, either {counts['goal_agrees_with_either']}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pass", dest="which", type=int, choices=sorted(PASSES), default=max(PASSES),
                    help="which translation pass")
    ap.add_argument("--translated-only", action="store_true",
                    help="score the translations only (the marks' coverage search is the long part)")
    ap.add_argument("--writers", action="store_true",
                    help="pass 2: two independent checkers of each translated request against each other")
    ap.add_argument("--scenes", type=int, default=100)
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    if args.writers:
        return writers(args.scenes, args.jobs)
    translations, sample_file, results = PASSES[args.which]
    language = LANGUAGE[args.which]
    rows = {r["id"]: r for r in map(json.loads, (HERE / translations).read_text().splitlines())}
    goals = {i: r["goal"] for i, r in rows.items()}
    sample = drawn(json.loads((HERE / sample_file).read_text()), rows)
    with multiprocessing.get_context("spawn").Pool(args.jobs) as pool:
        translated = pool.map(_translated, [(i, goals[i], args.scenes, language) for i in sample["translated"]])
        marked = [] if args.translated_only else pool.map(
            _not_expressible, [(i, args.scenes, language) for i in sample["not_expressible"]])
    agree = sum(r["agree"] for r in translated)
    confirmed = sum(r["confirmed"] for r in marked)
    out = {"pass": args.which, "language": language, "agree": agree, "translated": len(translated),
           "confirmed": confirmed, "not_expressible": len(marked),
           "threshold": AGREE, "scenes": args.scenes, "translated_rows": translated, "not_expressible_rows": marked}
    (HERE / results).write_text(json.dumps(out, indent=1) + "\n")
    print(f"translations: {agree} of {len(translated)} agree ≥ {AGREE} both ways; "
          f"not expressible: {confirmed} of {len(marked)} confirmed (best goal < 0.8)")


if __name__ == "__main__":
    main()
