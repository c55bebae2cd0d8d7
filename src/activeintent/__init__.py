"""activeintent: large models as active learners of human intention from sparse signals.

Symbols follow the paper (see docs/architecture.md): x task prompt, z intention estimate,
y instruction(s), τ = f(y) trajectory, h the user's sparse signal, r retrieved text,
ε seconds before a stop for the image I_b.
"""

__version__ = "0.1.0"
