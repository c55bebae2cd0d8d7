"""The translation check: each sampled translation scored against an independent checker.

    .venv/bin/python data/requests/check_translations.py [--pass 2] [--scenes 100] [--jobs 2]

Pass 1: translations.jsonl (language 1), check_sample.json → check_results.json; pass 2:
translations-2.jsonl (language 2), check_sample_2.json → check_results_2.json.
For the 40 translated requests of the sample: the translator's goal against the checker a
second writer wrote from the request alone (checkers/*.py, class R<id>), both ways on test
scenes where the checker is feasible (`coverage --goal`); they agree when both shares are
≥ 0.9. For the 20 marked "not expressible": the language's best goal for the checker
(`coverage`), confirmed when its plan success is < 0.8. Writes the results file beside this one.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
from pathlib import Path

HERE = Path(__file__).resolve().parent
AGREE = 0.9


def _checker(rid: str):
    from activeintent.intentions.registry import load_intention_file

    name = "R" + rid[1:]
    for path in sorted((HERE / "checkers").glob("*.py")):
        if f"class {name}(" in path.read_text():
            return load_intention_file(f"{path}:{name}")
    raise SystemExit(f"no checker class {name} in {HERE / 'checkers'}")


PASSES = {1: ("translations.jsonl", "check_sample.json", "check_results.json"),
          2: ("translations-2.jsonl", "check_sample_2.json", "check_results_2.json")}


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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pass", dest="which", type=int, choices=sorted(PASSES), default=max(PASSES),
                    help="which translation pass (its language is the pass's number)")
    ap.add_argument("--translated-only", action="store_true",
                    help="score the translations only (the marks' coverage search is the long part)")
    ap.add_argument("--scenes", type=int, default=100)
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    translations, sample_file, results = PASSES[args.which]
    sample = json.loads((HERE / sample_file).read_text())
    goals = {r["id"]: r["goal"] for r in map(json.loads, (HERE / translations).read_text().splitlines())}
    with multiprocessing.get_context("spawn").Pool(args.jobs) as pool:
        translated = pool.map(_translated, [(i, goals[i], args.scenes, args.which) for i in sample["translated"]])
        marked = [] if args.translated_only else pool.map(
            _not_expressible, [(i, args.scenes, args.which) for i in sample["not_expressible"]])
    agree = sum(r["agree"] for r in translated)
    confirmed = sum(r["confirmed"] for r in marked)
    out = {"pass": args.which, "language": args.which, "agree": agree, "translated": len(translated),
           "confirmed": confirmed, "not_expressible": len(marked),
           "threshold": AGREE, "scenes": args.scenes, "translated_rows": translated, "not_expressible_rows": marked}
    (HERE / results).write_text(json.dumps(out, indent=1) + "\n")
    print(f"translations: {agree} of {len(translated)} agree ≥ {AGREE} both ways; "
          f"not expressible: {confirmed} of {len(marked)} confirmed (best goal < 0.8)")


if __name__ == "__main__":
    main()
