"""The pass-3 prior against the packaged one (fitted to pass 2's translations) on the same dev
episodes: success@10 of lang-stop, lang-preference and lang-zero-signal, and the paired difference
in area under success@k (k = 0..10). The packaged prior's arm is docs/results/dev-lang2 (same
seeds). Run from the repository's root:

    .venv/bin/python experiments/prior-pass3/compare.py [ARM_FOLDER]

ARM_FOLDER: the pass-3 arm (default: this experiment's results/dev-prior-pass3). Writes
comparison.md and comparison.json beside this file.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from activeintent.bench.report import arm_row, paired_comparison
from activeintent.results import read_results

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
METHODS = ("lang-stop", "lang-preference", "lang-zero-signal")
LEARNERS = METHODS[:2]


def summary(folder: Path) -> dict:
    arms = {"pass 2 (packaged)": list(read_results(REPO / "docs" / "results" / "dev-lang2" / "results.jsonl")),
            "pass 3": list(read_results(folder / "results.jsonl"))}
    pooled = [{**r, "method": f"{r['method']}@{arm}"} for arm, rs in arms.items() for r in rs]
    rows, paired = [], []
    for arm, rs in arms.items():
        for method in METHODS:
            rows.append({"arm": arm, **arm_row(rs, method)})
    for method in METHODS:
        c = paired_comparison(pooled, f"{method}@pass 3", f"{method}@pass 2 (packaged)")
        if c is not None:
            paired.append({"method": method, **c})
    learners = [p for p in paired if p["method"] in LEARNERS]
    eligible = len(learners) == len(LEARNERS) and all(p["mean"] >= 0 for p in learners)
    return {"rows": rows, "paired": paired, "packaged": "pass 3" if eligible else "pass 2"}


def markdown(s: dict) -> str:
    lines = ["# The pass-3 prior against the packaged (pass-2) prior on dev", "",
             "success@10, mean over episodes [95 % Wilson interval] (n = episodes); area: mean area under "
             "success@k, k = 0..10; new scene: share of all answers.", "",
             "| prior | method | success@10 | area | new scene |", "|---|---|---|---|---|"]
    for r in s["rows"]:
        share = f"{100 * r['new_scene'] / r['answers']:.0f} %" if r["answers"] else "–"
        lines.append(f"| {r['arm']} | {r['method']} | {r['success']:.2f} [{r['lo']:.2f}, {r['hi']:.2f}] (n = {r['n']}) "
                     f"| {r['area']:.3f} | {share} |")
    lines += ["", "Paired on the same (intention, trial): difference in area, mean [95 % normal interval]; wins / "
              "ties / losses; success@10 difference [paired bootstrap].", "",
              "| method | Δ area | w / t / l | Δ success@10 |", "|---|---|---|---|"]
    for p in s["paired"]:
        lines.append(f"| {p['method']} | {p['mean']:+.3f} [{p['lo']:+.3f}, {p['hi']:+.3f}] (n = {p['n']}) | "
                     f"{p['wins']} / {p['ties']} / {p['losses']} | {p['final_mean']:+.3f} [{p['final_lo']:+.3f}, {p['final_hi']:+.3f}] |")
    lines += ["", "Rule (fixed before the run): the pass-3 prior replaces the packaged one only if its paired mean "
              f"is ≥ 0 for both lang-stop and lang-preference. **Packaged: {s['packaged']}**.", ""]
    return "\n".join(lines)


def main() -> None:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else HERE / "results" / "dev-prior-pass3"
    s = summary(folder)
    (HERE / "comparison.json").write_text(json.dumps(s, indent=1) + "\n")
    (HERE / "comparison.md").write_text(markdown(s))
    print(markdown(s))


if __name__ == "__main__":
    main()
