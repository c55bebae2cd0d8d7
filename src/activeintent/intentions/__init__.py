"""Hidden user intentions: named predicates over world states, with scenes and plans.

The built-in library (the paper's four first) is in the family modules
(arrangements, bowls, regions), registered in :data:`INTENTIONS` (a plug-in file adds its own
with ``INTENTIONS.register``); find one by name with :func:`get_intention`.
"""

from activeintent.intentions.base import Intention
from activeintent.intentions.registry import (
    INTENTION_NAMES,
    INTENTIONS,
    PAPER_INTENTIONS,
    IntentionError,
    all_intentions,
    get_intention,
    load_intention_file,
    resolve_intention,
)

__all__ = [
    "INTENTION_NAMES", "INTENTIONS", "PAPER_INTENTIONS", "Intention", "IntentionError", "all_intentions",
    "get_intention", "load_intention_file", "resolve_intention",
]
