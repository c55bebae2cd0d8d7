"""Structured model outputs (pydantic). Goal schemas are built per scene.

``structured`` variant: a goal y must be written in the canonical phrasing the `parse`
executor reads; the schema carries that as a regular expression over the scene's objects, so
grammar-constrained models (the embedded default) can only produce executable goals and
remote models get a repair round.

``faithful`` variant (the paper's): z and y are free text, written after the model's own
reasoning (the first field); y goes to the instruction-to-action module as it is.
"""

from __future__ import annotations

import re
from typing import Literal

from pydantic import BaseModel, Field, create_model

from activeintent.world import ALL_OBJECTS, Scene
from activeintent.world.skills import TABLE_POSITIONS

MAX_STEPS = 5


class IntentionAnswer(BaseModel):
    """z: the estimated user intention (eq. 1 / eq. 5)."""

    preference: str = Field(min_length=8, max_length=160, description="one sentence: the user's preference z")
    done: bool = Field(description="true only when sure of the preference")


class RetrievalAnswer(BaseModel):
    """r: what the vision-language model retrieved from the images around a stop (eq. 4)."""

    retrieved: str = Field(min_length=8, max_length=300)


def _escape(text: str) -> str:
    # Only regex metacharacters: llama.cpp's pattern-to-grammar converter rejects "\ ".
    return re.sub(r"([.^$*+?()\[\]{}|\\])", r"\\\1", text)


def _alt(options: list[str]) -> str:
    return "(" + "|".join(_escape(o) for o in options) + ")"


def goal_pattern(scene: Scene) -> str:
    """Regular expression of canonical goals over the scene's objects (1–5 steps)."""
    blocks, objects = _alt(scene.blocks), _alt(list(scene.objects))
    where = [f"on the {blocks}", f"next to the {objects}", f"left of the {objects}",
             f"right of the {objects}", f"in front of the {objects}", f"behind the {objects}",
             f"at the {_alt(list(TABLE_POSITIONS))}"]
    if scene.bowls:
        where.insert(0, f"in the {_alt(scene.bowls)}")
    step = f"put the {blocks} ({'|'.join(where)})"
    extra = max(0, min(MAX_STEPS, len(scene.blocks)) - 1)  # no more steps than blocks
    return f"^{step}(, then {step}){{0,{extra}}}$"


def goals_schema(scene: Scene, n_goals: int) -> type[BaseModel]:
    """y (eq. 2 / eq. 6): ``goal`` or ``goal_a``/``goal_b`` in canonical phrasing."""
    pattern = goal_pattern(scene)
    names = ["goal"] if n_goals == 1 else ["goal_a", "goal_b"]
    fields = {n: (str, Field(pattern=pattern, max_length=400)) for n in names}
    return create_model("GoalsAnswer", **fields)  # type: ignore[call-overload]


def scene_schema() -> type[BaseModel]:
    """The learner's choice of 3–5 objects for the next scene."""
    Obj = Literal[tuple(ALL_OBJECTS)]  # type: ignore[valid-type]
    return create_model("SceneChoice", objects=(list[Obj], Field(min_length=3, max_length=5)))  # type: ignore[call-overload]


# -- the faithful variant: free-form z and y, the model's reasoning first --------------------------
# Field order is the order a grammar-constrained model writes them in: reasoning, then z, then y.

def _reasoning():
    return Field(min_length=1, max_length=1200, description="your reasoning, before the answer")


def faithful_answer_schema(n_goals: int, with_done: bool = False) -> type[BaseModel]:
    """The answer of one round (eq. 1–2 or 5–6) or of a test scene: reasoning, z, y (free text)."""
    fields: dict = {
        "reasoning": (str, _reasoning()),
        "preference": (str, Field(min_length=1, max_length=300, description="the person's preference z, as you now see it")),
    }
    if n_goals == 1:
        fields["goal"] = (str, Field(min_length=1, max_length=400, description="the goal y for the robot, one sentence"))
    else:
        fields["goal_a"] = (str, Field(min_length=1, max_length=400, description="goal A, one sentence"))
        fields["goal_b"] = (str, Field(min_length=1, max_length=400, description="goal B, one sentence"))
    if with_done:
        fields["done"] = (bool, Field(description="true only when you are sure of the preference"))
    name = "FaithfulAnswer" if n_goals == 1 else "FaithfulPairAnswer"
    return create_model(name, **fields)  # type: ignore[call-overload]


class FaithfulRetrieval(BaseModel):
    """r (eq. 4): what the pictures around a stop show about the person's objection."""

    reasoning: str = _reasoning()
    retrieved: str = Field(min_length=1, max_length=600, description="at most three sentences")


def faithful_scene_schema() -> type[BaseModel]:
    """The learner's choice of 3–5 objects (2–4 blocks, 1–3 bowls: a scene where blocks can
    move somewhere), with its reasoning first."""
    Block = Literal[tuple(o for o in ALL_OBJECTS if o.endswith("block"))]  # type: ignore[valid-type]
    Bowl = Literal[tuple(o for o in ALL_OBJECTS if o.endswith("bowl"))]  # type: ignore[valid-type]
    return create_model("FaithfulScene", reasoning=(str, _reasoning()),  # type: ignore[call-overload]
                        blocks=(list[Block], Field(min_length=2, max_length=4)),
                        bowls=(list[Bowl], Field(min_length=1, max_length=3)))
