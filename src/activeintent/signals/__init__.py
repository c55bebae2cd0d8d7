"""Signals h as plug-ins: what a query shows, which answers a person can give, how a simulated
user gives one, how likely an answer is under a hypothesis, and how the web page reads it.

Every signal also allows the answer "new scene" (this scene cannot show what I want); it is
one signal like any other answer. Built in: ``preference`` (A / B / can't choose between two
trajectories) and ``stop`` (the time the person pressed stop, or none). Add your own with
``SIGNALS.register("name", YourSignal)`` — see ``examples/my_signal.py`` (with its web page,
``examples/my_signal.html``).
"""

from activeintent.signals.base import Answer, AnswerRejected, Judge, ShownRound, Signal, WebForm
from activeintent.signals.registry import SIGNALS, answer_kind_from_dump, get_signal

__all__ = ["SIGNALS", "Answer", "AnswerRejected", "Judge", "ShownRound", "Signal", "WebForm", "answer_kind_from_dump",
           "get_signal"]
