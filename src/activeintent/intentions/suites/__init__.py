"""Benchmark suites of hidden intentions written as modules of their own (``heldout2``, ...)."""
