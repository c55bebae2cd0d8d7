"""An open-ended active learner: a goal language, one generic planner, a large belief.

- the language and its planner are the package ``activeintent.goals``;
- space.py — enumeration, behavioural de-duplication on probe scenes, a vectorised judge;
- hypotheses.py — goals as hypotheses of the Bayesian learner and as hidden intentions;
- proposals.py — new goals while learning: neighbours of likely goals, a model's goals;
- learner.py — ``lang-<signal>``; explain.py — sentences to goals (``hypotheses --explain``).
"""
