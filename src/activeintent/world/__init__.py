"""The tabletop world without physics: names, scenes, states, skills, relations.

Everything here is pure Python + numpy so that intentions, users, learners and the
symbolic world model can reason about the table without a simulator.
"""

from activeintent.world.colors import COLOR_NAMES, COLORS, COOL_COLORS, WARM_COLORS
from activeintent.world.predict import SkillFailure, apply_plan, apply_skill, target_position
from activeintent.world.relations import Relations, describe_state, relations, table_position_name
from activeintent.world.scene import (
    ALL_OBJECTS,
    BLOCK_SIZE,
    BOUNDS,
    BOWL_INNER_RADIUS,
    BOWL_RADIUS,
    ObjectName,
    Scene,
    SceneError,
    layout,
    sample_scene,
)
from activeintent.world.skills import (
    Plan,
    PutAt,
    PutIn,
    PutNextTo,
    PutOn,
    Skill,
    describe_plan,
    describe_skill,
)
from activeintent.world.state import WorldState

__all__ = [
    "ALL_OBJECTS", "BLOCK_SIZE", "BOUNDS", "BOWL_INNER_RADIUS", "BOWL_RADIUS", "COLORS",
    "COLOR_NAMES", "COOL_COLORS", "WARM_COLORS", "ObjectName", "Plan", "PutAt", "PutIn",
    "PutNextTo", "PutOn", "Relations", "Scene", "SceneError", "Skill", "SkillFailure",
    "WorldState", "apply_plan", "apply_skill", "describe_plan", "describe_skill",
    "describe_state", "layout", "relations", "sample_scene", "table_position_name",
    "target_position",
]
