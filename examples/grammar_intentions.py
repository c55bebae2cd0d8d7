"""Hidden intentions that the Bayesian learners' grammar can express but that are not among the
named intentions, for checking that the learners generalise beyond the benchmark's four:

    bin/activeintent bench --methods bayes-preference,bayes-stop --intentions "" --llm none \\
        --intention-file examples/grammar_intentions.py:PINK_BOWL \\
        --intention-file examples/grammar_intentions.py:NEXT_TO_YELLOW ...
"""

from activeintent.learners.bayes.hypotheses import hypothesis_space

_BY_NAME = {h.name: h for h in hypothesis_space()}

PINK_BOWL = _BY_NAME["all:in-bowl[pink]"]  # every block in the pink bowl
NEXT_TO_YELLOW = _BY_NAME["all:next-to-block[yellow]"]  # the other blocks next to the yellow block
LEFT_SIDE = _BY_NAME["all:region[left side]"]  # every block on the left side of the table
WARM_LEFT_COOL_RIGHT = _BY_NAME["warm:region[left half]+cool:region[right half]"]
