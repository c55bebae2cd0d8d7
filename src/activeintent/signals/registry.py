"""The signals by name (a registry: plug-ins add theirs with ``SIGNALS.register``), and the
one word of a stored answer."""

from __future__ import annotations

from pydantic import ValidationError

from activeintent.registry import Registry
from activeintent.signals.base import Signal
from activeintent.signals.preference import PreferenceSignal
from activeintent.signals.stop import StopSignal

SIGNALS: Registry[Signal] = Registry("signal")
SIGNALS.register("preference", PreferenceSignal, help="A / B / can't choose between two trajectories")
SIGNALS.register("stop", StopSignal, help="the time the person pressed stop while the robot worked, or none")


def get_signal(name: str) -> Signal:
    return SIGNALS.make(name)


def answer_kind_from_dump(d: dict) -> str:
    """``Answer.kind`` of an answer as stored (by its signal's answer model; records of a
    signal not registered in this process: new_scene or the signal's name)."""
    if d.get("new_scene"):
        return "new_scene"
    name = d.get("signal")
    if not isinstance(name, str):
        return "?"
    if name in SIGNALS:
        try:
            return get_signal(name).Answer.model_validate(d).kind
        except ValidationError:
            pass
    return name
