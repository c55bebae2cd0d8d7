"""Text that leaves the sandbox: what a program said, error messages, skill failures.

It comes from an untrusted process and ends up in logs (JSON lines), terminals (the live table)
and web pages. :func:`clean_text` makes it valid UTF-8 (lone surrogates become U+FFFD), removes
terminal escape sequences and other control or invisible formatting characters (newline and tab
stay), masks memory addresses (``0x7f3a…`` as printed by ``repr``) and caps the length;
:func:`clean_messages` also caps how many messages are kept.
"""

from __future__ import annotations

import re
from typing import Any

MAX_MESSAGES = 100
MAX_MESSAGE_CHARS = 4_000
MAX_TOTAL_CHARS = 4_000
MAX_ERROR_CHARS = 500

# ESC-introduced sequences: CSI (ESC [ … final), OSC/DCS/SOS/PM/APC strings up to BEL or ST, and
# two-character escapes.
_ESCAPES = re.compile(
    r"\x1b\[[0-?]*[ -/]*[@-~]?"
    r"|\x1b[\]PX^_][^\x07\x1b]*(?:\x07|\x1b\\)?"
    r"|\x1b[ -~]?"
)
# C0 controls except tab and newline, DEL and C1 controls, zero-width and bidirectional
# formatting characters, line/paragraph separators, the byte-order mark.
_CONTROLS = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u200b-\u200f\u2028-\u202e\u2060-\u2069\ufeff]")
_SURROGATES = re.compile("[\ud800-\udfff]")
_ADDRESS = re.compile(r"0x[0-9a-fA-F]{8,}")
MASKED_ADDRESS = "0x…"


def clean_text(value: Any, limit: int = MAX_MESSAGE_CHARS) -> str:
    """``value`` as safe, bounded text (never raises)."""
    try:
        text = value if isinstance(value, str) else str(value)
    except Exception:  # noqa: BLE001 - an object whose str() fails
        return "(unprintable)"
    if len(text) > limit * 4 + 1024:  # do not scan megabytes for the few characters kept
        text = text[: limit * 4 + 1024]
    text = _SURROGATES.sub("\ufffd", text)
    text = _ESCAPES.sub("", text)
    text = _CONTROLS.sub("", text)
    text = _ADDRESS.sub(MASKED_ADDRESS, text)
    if len(text) > limit:
        text = text[: max(0, limit - 1)] + "…"
    return text


def clean_messages(values: Any, *, count: int = MAX_MESSAGES, total: int = MAX_TOTAL_CHARS) -> list[str]:
    """At most ``count`` cleaned messages holding at most ``total`` characters together."""
    if not isinstance(values, list):
        return []
    out: list[str] = []
    left = total
    for value in values[:count]:
        if left <= 0:
            break
        text = clean_text(value, limit=min(MAX_MESSAGE_CHARS, left))
        out.append(text)
        left -= len(text)
    return out
