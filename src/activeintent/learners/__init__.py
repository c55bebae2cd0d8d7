"""Learners that estimate z and y from sparse signals: the paper's three and our Bayesian ones."""
