"""Benchmark: runs every (method, intention, trial) episode, resumable; reports and plots."""
