"""The defaults experiment for bayes-*: scenes designed from the belief (``--scenes belief``)
against random scenes (``sampled``, the default until then) on the same dev episodes: success@10,
paired difference in area under success@k (k = 0..10), and the "new scene" share of all answers.
The sampled arm is docs/results/peer's bayes-* dev episodes of trials 0-9 (same seeds). Run from
the repository's root:

    .venv/bin/python experiments/defaults/compare_bayes.py [ARM_FOLDER]

ARM_FOLDER: the belief arm (default: this experiment's results/dev-bayes-belief). Writes
comparison_bayes.md and comparison_bayes.json beside this file.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from activeintent.bench.report import arm_row, paired_comparison
from activeintent.results import read_results

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
LEARNERS = ("bayes-stop", "bayes-preference")
TRIALS = 10


def summary(folder: Path) -> dict:
    belief = list(read_results(folder / "results.jsonl"))
    dev = {r["intention"] for r in belief}
    sampled = [r for r in read_results(REPO / "docs" / "results" / "peer" / "results.jsonl")
               if r["method"] in LEARNERS and r["intention"] in dev and r["trial"] < TRIALS]
    arms = {"sampled": sampled, "belief": belief}
    pooled = [{**r, "method": f"{r['method']}@{arm}"} for arm, rs in arms.items() for r in rs]
    rows, paired = [], []
    for arm, rs in arms.items():
        for method in LEARNERS:
            rows.append({"arm": arm, **arm_row(rs, method)})
    for method in LEARNERS:
        c = paired_comparison(pooled, f"{method}@belief", f"{method}@sampled")
        if c is not None:
            paired.append({"method": method, **c})
    eligible = len(paired) == len(LEARNERS) and all(p["mean"] >= 0 for p in paired)
    return {"rows": rows, "paired": paired, "default": "belief" if eligible else "sampled"}


def markdown(s: dict) -> str:
    lines = ["# bayes-* on dev: belief against sampled scenes", "",
             "success@10, mean over episodes [95 % Wilson interval] (n = episodes); area: mean area under "
             "success@k, k = 0..10; new scene: share of all answers (count / answers).", "",
             "| scenes | method | success@10 | area | new scene |", "|---|---|---|---|---|"]
    for r in s["rows"]:
        lines.append(f"| {r['arm']} | {r['method']} | {r['success']:.2f} [{r['lo']:.2f}, {r['hi']:.2f}] (n = {r['n']}) "
                     f"| {r['area']:.3f} | {100 * r['new_scene'] / r['answers']:.0f} % ({r['new_scene']} / {r['answers']}) |")
    lines += ["", "Paired on the same (intention, trial): difference in area, mean [95 % normal interval]; wins / "
              "ties / losses; success@10 difference [paired bootstrap].", "",
              "| method | Δ area | w / t / l | Δ success@10 |", "|---|---|---|---|"]
    for p in s["paired"]:
        lines.append(f"| {p['method']} | {p['mean']:+.3f} [{p['lo']:+.3f}, {p['hi']:+.3f}] (n = {p['n']}) | "
                     f"{p['wins']} / {p['ties']} / {p['losses']} | {p['final_mean']:+.3f} [{p['final_lo']:+.3f}, {p['final_hi']:+.3f}] |")
    lines += ["", "Rule (the lang-* rule, fixed before the run): belief becomes bayes-*'s default only if its paired "
              f"mean is ≥ 0 for both signals. **Default: {s['default']}**.", ""]
    return "\n".join(lines)


def main() -> None:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else HERE / "results" / "dev-bayes-belief"
    s = summary(folder)
    (HERE / "comparison_bayes.json").write_text(json.dumps(s, indent=1) + "\n")
    (HERE / "comparison_bayes.md").write_text(markdown(s))
    print(markdown(s))


if __name__ == "__main__":
    main()
