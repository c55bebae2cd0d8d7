"""Instruction to action, τ = f(y): deterministic parser, structured plans, Code as Policies in a sandbox."""
