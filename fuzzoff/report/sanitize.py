"""Text from a recording is untrusted: make it safe for a terminal before anyone prints it."""

from __future__ import annotations

import re

_UNPRINTABLE = re.compile(r"[\x00-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]")


CI_TEXT_LIMIT = 2000
"""Longest finding text in a CI view (JUnit, SARIF): a recording can make a message any length."""


def printable(text: str, limit: int = 500) -> str:
    """Control characters (ANSI escapes, bidi overrides, line breaks and tabs too: each item
    printed stays on its line) shown as ``\\xNN``; long text cut."""
    safe = _UNPRINTABLE.sub(lambda m: f"\\x{ord(m.group()):02x}", text)
    return safe if len(safe) <= limit else safe[: limit - 1] + "…"
