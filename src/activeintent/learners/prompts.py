"""Prompt templates (package data), one file per equation of the paper.

Templates use ``$name`` placeholders (string.Template). Each template's version is the hash of
its text, so the response cache never serves an answer made for an older prompt.
"""

from __future__ import annotations

import hashlib
from string import Template

from activeintent.llm.backend import prompt_template as template_text


def render(name: str, **values: object) -> str:
    """Fill template ``name``; a missing value is an error (never a silently empty prompt)."""
    return Template(template_text(name)).substitute({k: str(v) for k, v in values.items()}).strip()


def version(*names: str) -> str:
    return hashlib.sha256("".join(template_text(n) for n in names).encode()).hexdigest()[:12]


def sections(name: str) -> dict[str, str]:
    """Split a template with ``[section]`` headers (eq. 3 holds x_n, x_s and x_b)."""
    out: dict[str, str] = {}
    key = None
    for line in template_text(name).splitlines():
        if line.startswith("[") and line.endswith("]"):
            key = line[1:-1]
            out[key] = ""
        elif key is not None:
            out[key] += line + "\n"
    return {k: v.strip() for k, v in out.items()}
