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
# The one table of what is removed: every control character (Unicode category Cc) but tab and
# newline, every format character (Cf: zero-width and bidirectional controls, the Arabic letter
# mark U+061C, the soft hyphen U+00AD, the interlinear annotation marks U+FFF9–FFFB, the
# byte-order mark, the tag characters), the line and paragraph separators (Zl, Zp), and the whole
# tag block U+E0000–E007F (its unassigned U+E0000 too). Inclusive ranges, from Unicode 14
# (Python 3.11); tests/act compares them with ``unicodedata`` code point by code point.
REMOVED = (
    (0x0000, 0x0008), (0x000B, 0x001F), (0x007F, 0x009F), (0x00AD, 0x00AD), (0x0600, 0x0605), (0x061C, 0x061C),
    (0x06DD, 0x06DD), (0x070F, 0x070F), (0x0890, 0x0891), (0x08E2, 0x08E2), (0x180E, 0x180E), (0x200B, 0x200F),
    (0x2028, 0x202E), (0x2060, 0x2064), (0x2066, 0x206F), (0xFEFF, 0xFEFF), (0xFFF9, 0xFFFB), (0x110BD, 0x110BD),
    (0x110CD, 0x110CD), (0x13430, 0x13438), (0x1BCA0, 0x1BCA3), (0x1D173, 0x1D17A), (0xE0000, 0xE007F),
)
_CONTROLS = re.compile("[" + "".join(f"\\U{a:08x}-\\U{b:08x}" for a, b in REMOVED) + "]")
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
