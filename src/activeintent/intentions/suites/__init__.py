"""Benchmark suites of hidden intentions written as modules of their own: ``dev`` (for developing
learners), ``heldout`` and ``heldout2`` (written blind, never tuned on; see ``activeintent.suites``)."""
