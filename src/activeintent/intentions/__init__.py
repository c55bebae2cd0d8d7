"""Intention library: predicates over world states, per-step violation, feasible scenes."""
