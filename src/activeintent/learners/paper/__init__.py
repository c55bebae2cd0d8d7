"""The paper's learners (Large Models as an Active Learner): ``faithful`` — the paper's own
methods (``--variant faithful``, the default) — and ``structured`` — the same equations with
structured outputs; ``retrievers`` turn prompt(h) into text r (eq. 4), ``schemas`` the answers
the models must give."""
