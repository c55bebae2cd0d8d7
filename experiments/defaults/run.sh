#!/usr/bin/env bash
# The three new arms of the defaults experiment (README.md); the fourth, (length, sampled), is
# docs/results/peer's lang-* dev episodes, trials 0-9 (the same seeds). Then the comparison.
set -euo pipefail
cd "$(dirname "$0")/../.."
for arm in length-belief fitted-sampled fitted-belief; do
  prior="${arm%-*}" scenes="${arm#*-}"
  bin/activeintent bench --methods lang-stop,lang-preference,lang-zero-signal --suite dev --trials 10 --budget 10 \
    --user human --env symbolic --llm none --prior "$prior" --scenes "$scenes" --jobs 2 --no-oracle \
    --out "runs/defaults/dev-$arm"
done
